"""Quick, indicative comparison of Fuzzy-RRT-Connect with Fuzzy-RRT and a tuned RRT (issue 25).

Usage: ``python benchmarks/connect_quick.py DIR [SEEDS] [OUT.csv] [--preload]`` over every ``*.toml`` in DIR
(e.g. ``xfuzzy-rrt scenarios generate --count 24 --seed 9300 --out DIR``). Times the whole
``plan_scenario`` call (failures count as infinite), records iterations and certified success,
and prints per planner the median over problems of the per-problem median time (whole call, and
the planning loop alone: ``wall_s``) and iterations,
and the median/worst per-problem ratio of each peer's median time to Fuzzy-RRT-Connect's.
One process, one run: indicative only (the machine's load changes the times).
"""

from __future__ import annotations

import sys
import time
from pathlib import Path

import numpy as np
import pandas as pd

from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.api import plan_scenario

PLANNERS = {
    "fuzzy-rrt-connect": {},
    "fuzzy-rrt": {},
    "rrt-60-0.1": {"planner": "rrt", "step_deg": 60.0, "goal_bias": 0.1},
}


def run(folder: Path, seeds: int, preload: bool = False) -> pd.DataFrame:
    """``preload``: pass each Fuzzy planner its rulebook loaded once (as ``bench`` does) instead
    of letting every call resolve (and re-hash) the shipped default."""
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
    from xfuzzy_rrt.planners.api import default_rulebook_dir, parse_planner

    rows = []
    files = sorted(folder.glob("*.toml"))
    for f in files:
        s = load_scenario(f)
        for label, kw in PLANNERS.items():
            kw = dict(kw)
            planner = kw.pop("planner", label)
            kind = parse_planner(planner).kind
            if preload and kind != "rrt":
                kw["rulebook"] = load_rulebook(default_rulebook_dir(kind))
            plan_scenario(s, planner, seed=10_000, max_iter=10, **kw)  # compile/load first
            for seed in range(seeds):
                t0 = time.perf_counter()
                r = plan_scenario(s, planner, seed=seed, **kw)
                t = time.perf_counter() - t0
                rows.append({"scenario": s.name, "planner": label, "seed": seed,
                             "success": r.success, "iterations": r.iterations,
                             "time_s": t if r.success else np.inf,
                             "kernel_s": r.wall_s if r.success else np.inf})
    return pd.DataFrame(rows)


def summary(df: pd.DataFrame) -> str:
    per = df.groupby(["scenario", "planner"]).agg(
        time_s=("time_s", "median"), kernel_s=("kernel_s", "median"),
        iterations=("iterations", "median"),
        success=("success", "mean")).reset_index()
    lines = []
    ref = per[per.planner == "fuzzy-rrt-connect"].set_index("scenario")
    for label in PLANNERS:
        p = per[per.planner == label].set_index("scenario")
        line = (f"{label:18s} median time {p.time_s.median() * 1e3:8.2f} ms (planning loop "
                f"{p.kernel_s.median() * 1e3:.3f} ms)  median iterations "
                f"{p.iterations.median():7.1f}  success {df[df.planner == label].success.mean():.3f}"
                f"  problems below 100 % success {int((p.success < 1).sum())}")
        if label != "fuzzy-rrt-connect":
            ratio = (p.time_s / ref.time_s).replace([np.inf, -np.inf], np.nan)
            it_ratio = p.iterations / ref.iterations
            k_ratio = (p.kernel_s / ref.kernel_s).replace([np.inf, -np.inf], np.nan)
            line += (f"\n{'':18s} time ratio {label}/connect: median {ratio.median():.2f}x, "
                     f"worst {ratio.min():.2f}x; iteration ratio median {it_ratio.median():.2f}x, "
                     f"worst {it_ratio.min():.2f}x; planning-loop time ratio median "
                     f"{k_ratio.median():.2f}x, worst {k_ratio.min():.2f}x")
        lines.append(line)
    return "\n".join(lines)


if __name__ == "__main__":
    args = [a for a in sys.argv[1:] if a != "--preload"]
    df = run(Path(args[0]), int(args[1]) if len(args) > 1 else 20, "--preload" in sys.argv)
    if len(args) > 2:
        df.to_csv(args[2], index=False)
    print(summary(df))
