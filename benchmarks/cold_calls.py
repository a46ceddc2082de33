"""The default against ``rrt:tuned`` call by call, with the caches warm and with them cold.

Why: ``xfuzzy-rrt evaluate`` times each planner between calls of four others (the paper's RRT
grows 10,000-node trees at 3+ joints, OMPL's calls are mostly Python), so a call often starts
with its code and data evicted from the caches -- as a user's does who runs anything between two
plans. A call that is fast warm can be slow cold: on 3-joint problems the default's calls were
level with the tuned RRT's warm and 0.82x cold (docs/peer-measurements.md, tenth and eleventh
sessions). This script measures that setting on its own, in one process, so that a change to
the call path can be judged where the aims are measured.

Per problem and seed the default (``fuzzy-rrt`` with its rulebooks loaded once) and ``rrt:tuned``
(its settings read once) are called in an order shuffled per seed (``bench.protocol.call_order``);
before each timed call ``--evict-mb`` megabytes are written (by default what ``evaluate --caches
cold`` writes: 1.5x the last-level cache the OS reports, at most 512 MB, ``bench/caches.py``; 0:
warm). A fixed size is not cold everywhere: where the L3 is 480 MB, 48 MB written leave most of a
call's code and data in it, and the calls measured 2.5x faster than in ``evaluate``
(docs/peer-measurements.md, fifteenth session). Printed per folder: both planners' median call and
kernel time (``PlanResult.wall_s``) over problems, and the tuned call over the default's, median
and geometric mean of per-problem ratios (a failed run counts as infinitely slow). Run on
problems nobody tuned on, on a quiet machine::

    nice python benchmarks/cold_calls.py /tmp/eval-sample /tmp/eval-dof3 --seeds 30
    nice python benchmarks/cold_calls.py /tmp/eval-dof3 --evict-mb 0      # warm
"""

from __future__ import annotations

import argparse
import math
import statistics
import sys
import time
from pathlib import Path


def measure(scenarios, seeds, evict_mb: float, max_iter: int = 10_000):
    """Per problem ``(default call, tuned call, default kernel, tuned kernel)`` in seconds,
    medians over seeds."""
    import numpy as np

    from xfuzzy_rrt.bench.protocol import call_order
    from xfuzzy_rrt.planners.api import load_shipped_default, load_tuned_rrt, plan_scenario

    calls = (("fuzzy-rrt", load_shipped_default()), ("rrt:tuned", load_tuned_rrt()))
    junk = np.zeros(max(int(evict_mb * 2**20) // 8, 1))
    rows = []
    for sc in scenarios:
        for planner, given in calls:  # warm-up: kernels loaded, set-ups remembered
            plan_scenario(sc, planner, rulebook=given, seed=0, max_iter=max_iter)
        times = [[], []]
        kernels = [[], []]
        for k, seed in enumerate(seeds):
            for i in call_order(len(calls), k):
                planner, given = calls[i]
                if evict_mb > 0:
                    junk += 1.0
                t0 = time.perf_counter()
                r = plan_scenario(sc, planner, rulebook=given, seed=seed, max_iter=max_iter)
                t = time.perf_counter() - t0
                times[i].append(t if r.success else math.inf)
                kernels[i].append(r.wall_s)
        rows.append((statistics.median(times[0]), statistics.median(times[1]),
                     statistics.median(kernels[0]), statistics.median(kernels[1])))
    return rows


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    ap.add_argument("folders", nargs="+", type=Path, help="folders of scenario .toml files")
    ap.add_argument("--count", type=int, default=32, help="problems per folder (first N)")
    ap.add_argument("--seeds", type=int, default=30)
    ap.add_argument("--evict-mb", type=float, default=None,
                    help="megabytes written before every timed call (default: as evaluate "
                         "--caches cold, 1.5x the last-level cache; 0: warm caches)")
    args = ap.parse_args(argv)
    from xfuzzy_rrt.bench.caches import evict_bytes, last_level_cache_bytes
    from xfuzzy_rrt.geometry.scenario import load_scenario

    if args.evict_mb is None:
        args.evict_mb = evict_bytes(last_level_cache_bytes()) / 2**20

    for folder in args.folders:
        files = sorted(folder.glob("*.toml"))[:args.count]
        if not files:
            print(f"{folder}: no scenarios", file=sys.stderr)
            return 2
        rows = measure([load_scenario(f) for f in files], range(args.seeds), args.evict_mb)
        ratios = [tuned / default for default, tuned, _, _ in rows]
        finite = [r for r in ratios if 0.0 < r < math.inf]
        us = [1e6 * statistics.median(col) for col in zip(*rows)]
        geo = math.exp(statistics.fmean(math.log(r) for r in finite)) if finite else math.nan
        print(f"{folder.name}: {len(files)} problems x {args.seeds} seeds, "
              f"{args.evict_mb:g} MB written before each call; median call default "
              f"{us[0]:.1f} us (kernel {us[2]:.1f}), rrt:tuned {us[1]:.1f} us (kernel {us[3]:.1f}); "
              f"rrt:tuned/default median {statistics.median(ratios):.2f}x, geomean {geo:.2f}x",
              flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
