"""Our planners against the best *tuned* peer, problem by problem, from an ``evaluate`` folder.

``xfuzzy-rrt evaluate`` ranks every planner against one baseline (``rrt:tuned``). A user does not
care which peer is fastest on a problem, only how long the fastest one takes, so this takes per
problem the smallest median end-to-end time (``time_total_s``; a failed run counts with the time
it spent) of the peers ``rrt:tuned``, ``ompl:RRTConnect`` and ``ompl:BITstar`` that ran, and
prints for each ``fuzzy-rrt*`` planner that best peer's median over its own: median, geometric
mean and worst over problems, how many problems it loses, on how many its certified success is
below some peer's, its median path cost over the tuned RRT's, and which peer was fastest where.

    python scripts/best_peer.py reports/eval/result-sample
"""

from __future__ import annotations

import sys

import numpy as np
import pandas as pd

PEERS = ("rrt:tuned", "ompl:RRTConnect", "ompl:BITstar")


def main(folder: str) -> None:
    runs = pd.read_csv(f"{folder}/runs.csv")
    peers = [p for p in PEERS if p in set(runs.planner)]
    ours = [p for p in runs.planner.unique() if p.startswith("fuzzy-rrt")]
    med = runs.groupby(["scenario", "planner"]).agg(
        t=("time_total_s", "median"), s=("success", "mean"), c=("cost_deg", "median")).reset_index()
    t = med.pivot(index="scenario", columns="planner", values="t")
    s = med.pivot(index="scenario", columns="planner", values="s")
    c = med.pivot(index="scenario", columns="planner", values="c")
    best = t[peers].min(axis=1)
    for p in ours:
        r = best / t[p]
        below = int((s[p] < s[peers].max(axis=1) - 1e-12).sum())
        cost = float(np.nanmedian(c[p] / c["rrt:tuned"])) if "rrt:tuned" in c else float("nan")
        print(f"{p:28s} vs best peer: median {np.median(r):.2f}x  geomean "
              f"{np.exp(np.log(r).mean()):.2f}x  worst {r.min():.2f}x  lost {int((r < 1).sum())}/"
              f"{len(r)}  success below a peer on {below}  cost/rrt:tuned {cost:.3f}  "
              f"min success {s[p].min():.0%}")
    print("fastest peer per problem:", t[peers].idxmin(axis=1).value_counts().to_dict())


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python scripts/best_peer.py EVALUATE_OUT_FOLDER")
    main(sys.argv[1])
