"""How far apart does a planner land from *itself*? The noise floor of per-problem ratios.

Why: issue 25's aims are per problem ("worst >= 1x on every problem"), and a per-problem ratio
is a ratio of two medians over finite seeds. Splitting one planner's own runs in an
``evaluate`` folder into its even and its odd seeds and taking, per problem, the ratio of the
two medians (and its bootstrap interval, ``bench/interval.py``) shows what worst ratio and how
many "lost" problems a planner would score against an exact copy of itself -- the floor under
which a measured worst case says nothing. Per planner: the median and worst of those ratios
(each taken the way round that is below 1), how many lie below 0.9, and on how many problems
the interval lies wholly below or above 1 (by chance about 2.5 % each way).

    python scripts/noise_floor.py reports/eval/result-sample [more folders]
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd

from xfuzzy_rrt.bench.interval import median_ratio_interval


def noise_floor(runs: pd.DataFrame, planner: str) -> dict:
    """Even-against-odd-seed ratios of *planner*'s median end-to-end time, per problem."""
    mine = runs[runs["planner"] == planner]
    ratios, sure = [], 0
    for scenario, g in mine.groupby("scenario", sort=True):
        t = pd.to_numeric(g["time_total_s"], errors="coerce").to_numpy(dtype=float)
        even, odd = t[g["seed"].to_numpy() % 2 == 0], t[g["seed"].to_numpy() % 2 == 1]
        if even.size == 0 or odd.size == 0:
            continue
        r = np.median(even) / np.median(odd)
        ratios.append(min(r, 1.0 / r))
        lo, hi = median_ratio_interval(even, odd, f"{scenario}\0{planner}\0self")
        sure += int(hi < 1.0) + int(lo > 1.0)
    r = np.asarray(ratios)
    return {"planner": planner, "problems": r.size, "median": float(np.median(r)),
            "worst": float(r.min()), "below_0.9": int((r < 0.9).sum()), "sure": sure}


def main(folders: list[str]) -> int:
    missing = next((f for f in folders if not Path(f, "runs.csv").is_file()), None)
    if missing is not None:
        print(f"error: {missing}: no runs.csv (give an 'xfuzzy-rrt evaluate --out' folder)",
              file=sys.stderr)
        return 2
    for folder in folders:
        runs = pd.read_csv(Path(folder, "runs.csv"))
        for planner in dict.fromkeys(runs["planner"]):
            f = noise_floor(runs, planner)
            print(f"{folder}  {planner:24s} even/odd seeds over {f['problems']} problems: median "
                  f"{f['median']:.2f}x  worst {f['worst']:.2f}x  below 0.9x on "
                  f"{f['below_0.9']}  interval wholly off 1 on {f['sure']}")
    return 0


if __name__ == "__main__":
    if len(sys.argv) < 2:
        sys.exit("usage: python scripts/noise_floor.py EVALUATE_OUT_FOLDER [...]")
    sys.exit(main(sys.argv[1:]))
