"""Our planners against the best *tuned* peer, problem by problem, from an ``evaluate`` folder.

``xfuzzy-rrt evaluate`` prints this itself since the nineteenth session (its second table and
the ``*_best_peer_*`` columns of ``summary.csv``); this script recomputes it from a folder's
``runs.csv`` -- older folders included -- with the same code (``bench/protocol.py``,
``problem_table``): per problem the smallest median end-to-end time (``time_total_s``; a failed
run counts with the time it spent) of the peers ``rrt:tuned``, ``ompl:RRTConnect`` and
``ompl:BITstar`` that ran, and for each ``fuzzy-rrt*`` planner that best peer's median over its
own: median, geometric mean and worst over problems, how many problems it loses, on how many
its certified success is below some peer's, its median path cost over the tuned RRT's, and
which peer was fastest where; with each median its 95 % bootstrap interval over problems and
with the losses those that are sure (``bench/interval.py``).

    python scripts/best_peer.py reports/eval/result-sample
"""

from __future__ import annotations

import sys
from pathlib import Path

import pandas as pd

from xfuzzy_rrt.bench.protocol import problem_table, summary_table

PEERS = ("rrt:tuned", "ompl:RRTConnect", "ompl:BITstar")


def main(folder: str) -> int:
    if not Path(folder, "runs.csv").is_file():
        print(f"error: {folder}: no runs.csv (give an 'xfuzzy-rrt evaluate --out' folder)",
              file=sys.stderr)
        return 2
    runs = pd.read_csv(Path(folder, "runs.csv"))
    order = list(dict.fromkeys(runs["planner"]))
    peers = [p for p in PEERS if p in order]
    summary = summary_table(problem_table(runs, order, peers)).set_index("planner")
    for p in (p for p in order if p.startswith("fuzzy-rrt")):
        r = summary.loc[p]
        print(f"{p:28s} vs best peer: median {r.median_best_peer_ratio:.2f}x "
              f"[{r.median_best_peer_ratio_lo:.2f}-{r.median_best_peer_ratio_hi:.2f}]  geomean "
              f"{r.geomean_best_peer_ratio:.2f}x  worst {r.worst_best_peer_ratio:.2f}x  lost "
              f"{r.problems_lost_best_peer}/{r.problems} "
              f"(surely {r.problems_surely_lost_best_peer}; "
              f"surely won {r.problems_surely_won_best_peer})  success below a peer on "
              f"{r.problems_success_below_peer}  cost/rrt:tuned {r.median_cost_peer_ratio:.3f} "
              f"[{r.median_cost_peer_ratio_lo:.3f}-{r.median_cost_peer_ratio_hi:.3f}]  "
              f"min success {r.worst_success_rate:.0%}")
    print("fastest peer per problem:", summary.iloc[0].best_peers)
    return 0


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit("usage: python scripts/best_peer.py EVALUATE_OUT_FOLDER")
    sys.exit(main(sys.argv[1]))
