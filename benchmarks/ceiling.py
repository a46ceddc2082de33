"""How much faster than ``rrt:tuned`` can the default planner be at all, problem by problem?

Why: issue 25 asks for the default to be >= 2x faster than the best tuned peer, end to end
(the whole ``plan_scenario`` call, as a user waits). Every call pays a fixed cost whatever the
search does: the label and set-up checks, the rulebook's freshness check, the kernel dispatch,
the first inference and extension, the certified result. A planner cannot be faster than its
own one-iteration call, so per problem

    ceiling = median call of rrt:tuned / median call of the default with max_iter=1

bounds the default's speed-up (a one-iteration call usually fails, so it skips the path's
result: the bound is, if anything, generous). Where the ceiling is below 2x, the aim cannot
be met on that problem by a better search, only by a cheaper call (which ``rrt:tuned`` shares).

Per problem and seed the three calls (the default, its one-iteration floor, ``rrt:tuned``) run
back to back, their order rotated from seed to seed (a fixed order favours the later calls:
docs/peer-measurements.md, "Measuring: the order of calls"). Printed per folder:
``rrt:tuned``'s median call, the floor, the median and worst ceiling, how many problems have a
ceiling below 2x, and the measured default speed-up (median of per-problem ratios) beside it.
Run on problems nobody tuned on::

    nice python benchmarks/ceiling.py /tmp/eval-sample /tmp/eval-dof5 --seeds 30
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path

CALLS = ("default", "floor", "rrt:tuned")


def measure(scenarios, seeds, max_iter=10_000):
    """Per problem ``(tuned call s, floor call s, default call s)``, medians over seeds (a failed
    run counts as infinitely slow)."""
    from xfuzzy_rrt.planners.api import load_shipped_default, load_tuned_rrt, plan_scenario

    default = load_shipped_default()
    tuned = load_tuned_rrt()  # read once, as the default's rulebooks are (evaluate does both)

    def call(sc, which, seed):
        if which == "rrt:tuned":
            args = ("rrt:tuned", tuned, max_iter)
        else:
            args = ("fuzzy-rrt", default, 1 if which == "floor" else max_iter)
        t0 = time.perf_counter()
        r = plan_scenario(sc, args[0], rulebook=args[1], seed=seed, max_iter=args[2])
        t = time.perf_counter() - t0
        return t if (r.success or which == "floor") else math.inf

    rows = []
    for sc in scenarios:
        for which in CALLS:  # warm-up: kernels loaded, set-ups remembered
            call(sc, which, 0)
        times = {w: [] for w in CALLS}
        for k, seed in enumerate(seeds):
            for which in CALLS[k % 3:] + CALLS[:k % 3]:
                times[which].append(call(sc, which, seed))
        rows.append(tuple(statistics.median(times[w]) for w in ("rrt:tuned", "floor", "default")))
    return rows


def summarise(rows) -> dict:
    ceiling = [t / f for t, f, _ in rows]
    speedup = [t / d for t, _, d in rows]
    return {"problems": len(rows),
            "tuned_us": statistics.median(t for t, _, _ in rows) * 1e6,
            "floor_us": statistics.median(f for _, f, _ in rows) * 1e6,
            "ceiling": statistics.median(ceiling), "worst_ceiling": min(ceiling),
            "below_2x": sum(c < 2.0 for c in ceiling), "speedup": statistics.median(speedup)}


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("folders", type=Path, nargs="+", help="folders of scenario .toml files")
    ap.add_argument("--seeds", type=int, default=30)
    args = ap.parse_args(argv)
    from xfuzzy_rrt.geometry.scenario import load_scenario

    print(f"{'problems':<22} {'n':>3} {'rrt:tuned us':>12} {'floor us':>9} {'ceiling':>8} "
          f"{'worst':>6} {'<2x':>4} {'measured':>9}")
    for folder in args.folders:
        scenarios = [load_scenario(p) for p in sorted(folder.glob("*.toml"))]
        s = summarise(measure(scenarios, range(args.seeds)))
        print(f"{folder.name:<22} {s['problems']:>3} {s['tuned_us']:>12.1f} {s['floor_us']:>9.1f} "
              f"{s['ceiling']:>7.2f}x {s['worst_ceiling']:>5.2f}x {s['below_2x']:>4} "
              f"{s['speedup']:>8.2f}x", flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
