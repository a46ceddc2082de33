"""End-to-end overhead of one ``plan_scenario`` call against the planner's own kernel time.

Why: the kernel (``PlanResult.wall_s``) is what the planner's loop costs; a user waits for the
whole call (parse the planner label, load the rulebook, build the tree, certify the path, build
the result). Issue 24 asks for an overhead of at most 0.1 ms a call, or at most 1.2x the kernel.

For each problem, planner and seed: whole-call time (``perf_counter`` around ``plan_scenario``),
kernel time (``wall_s``), iterations. Printed per planner: the median over problems of the
per-problem medians over seeds of kernel us/iteration, kernel ms, call ms, overhead ms
(call - kernel) and the ratio call/kernel. Problems and seeds are interleaved so that load
changes hit every planner alike. Run on problems nobody tuned on, e.g.::

    xfuzzy-rrt scenarios generate --count 48 --seed 9100 --out /tmp/eval9100
    nice python benchmarks/overhead.py /tmp/eval9100 --seeds 10
    nice python benchmarks/overhead.py /tmp/eval9100 --profile 100    # cProfile of 100 calls

``--min-clearance`` also reads ``result.min_clearance_m`` inside the timed call (what the
``plan`` JSON, ``bench`` runs.csv and the report ask for).
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time
from pathlib import Path

PLANNERS = ("fuzzy-rrt", "rrt", "rrt:tuned")  # the default, the paper's peer, the fair peer


def _load(paths):
    from xfuzzy_rrt.geometry.scenario import load_scenario

    return [load_scenario(p) for p in paths]


def measure(scenarios, planners, seeds, min_clearance=False, max_iter=10_000):
    """``{planner: [(problem, seed, call_s, kernel_s, iterations), ...]}``."""
    from xfuzzy_rrt.planners.api import plan_scenario

    out = {p: [] for p in planners}
    for sc in scenarios:  # warm-up: compile or load kernels, fill caches
        for p in planners:
            plan_scenario(sc, p, seed=0, max_iter=max_iter)
    for seed in seeds:
        for sc in scenarios:
            for p in planners:
                t0 = time.perf_counter()
                r = plan_scenario(sc, p, seed=seed, max_iter=max_iter)
                if min_clearance:
                    _ = r.min_clearance_m
                call = time.perf_counter() - t0
                out[p].append((sc.name, seed, call, r.wall_s, r.iterations))
    return out


def summarise(rows):
    """Medians over problems of per-problem medians."""
    by = {}
    for name, _seed, call, kern, it in rows:
        by.setdefault(name, []).append((call, kern, it))

    def med(f):
        return statistics.median(statistics.median(f(r) for r in rs) for rs in by.values())

    return {
        "kernel_us_per_iter": med(lambda r: r[1] / max(r[2], 1) * 1e6),
        "kernel_ms": med(lambda r: r[1] * 1e3),
        "call_ms": med(lambda r: r[0] * 1e3),
        "overhead_ms": med(lambda r: (r[0] - r[1]) * 1e3),
        "ratio": med(lambda r: r[0] / r[1] if r[1] > 0 else float("nan")),
        "problems": len(by),
    }


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("folder", type=Path, help="folder of scenario .toml files (or one file)")
    ap.add_argument("--seeds", type=int, default=10)
    ap.add_argument("--planners", default=",".join(PLANNERS))
    ap.add_argument("--min-clearance", action="store_true",
                    help="also read result.min_clearance_m inside the timed call")
    ap.add_argument("--profile", type=int, default=0,
                    help="instead: cProfile this many default-planner calls")
    ap.add_argument("--profile-planner", default="fuzzy-rrt")
    ap.add_argument("--sort", default="cumulative", help="pstats sort key of the profile")
    args = ap.parse_args(argv)
    paths = sorted(args.folder.glob("*.toml")) if args.folder.is_dir() else [args.folder]
    scenarios = _load(paths)
    planners = args.planners.split(",")
    if args.profile:
        import cProfile
        import pstats

        from xfuzzy_rrt.planners.api import plan_scenario

        for sc in scenarios:
            plan_scenario(sc, args.profile_planner, seed=0)
        pr = cProfile.Profile()
        pr.enable()
        for i in range(args.profile):
            r = plan_scenario(scenarios[i % len(scenarios)], args.profile_planner, seed=i)
            if args.min_clearance:
                _ = r.min_clearance_m
        pr.disable()
        pstats.Stats(pr, stream=sys.stdout).sort_stats(args.sort).print_stats(25)
        return 0
    res = measure(scenarios, planners, range(args.seeds), args.min_clearance)
    print(f"{'planner':<12} {'problems':>8} {'us/iter':>8} {'kernel ms':>10} {'call ms':>9} "
          f"{'overhead ms':>12} {'call/kernel':>12}")
    for p in planners:
        s = summarise(res[p])
        print(f"{p:<12} {s['problems']:>8} {s['kernel_us_per_iter']:>8.2f} {s['kernel_ms']:>10.3f} "
              f"{s['call_ms']:>9.3f} {s['overhead_ms']:>12.3f} {s['ratio']:>12.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
