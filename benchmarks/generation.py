"""One paper-scale GA generation: 400 individuals x 5 runs on paper-reference, 2 workers.

What it prints, all from one run (so the ratios hold whatever the machine's load, which is
printed too):

- the same 2,000 runs evaluated serially in this process, wall and CPU seconds, through the
  planner's own kernel loop (``run_population``: how training evaluated before) and through
  the loop training uses now (``paper_population``: per-node work remembered, same numbers);
- the kernel floor: CPU seconds per generation / workers, with the iterations behind it and
  the CPU microseconds per iteration — no engine can beat it without a faster kernel;
- one generation through the trainer's evaluator (warm: the workers are started and their
  kernels loaded by a first small call), wall seconds and the CPU the workers spent, so the
  difference shows what process hand-over and imbalance cost against planning itself;
- breeding the next generation from this one (``training.operators``: pymoo's operators
  written again, in the main process while the workers wait): the rest of a generation's time;
- the whole generation, evaluation plus breeding (medians of the rounds): the figure the
  trainer's loop sees.

The population is the benchmark's (benchmarks/test_bench_training.py): half drawn like the
GA's first generation, half near the shipped ``paper`` rulebook, as late in training.

    nice python benchmarks/generation.py --rounds 3
"""

from __future__ import annotations

import argparse
import os
import statistics
import sys
import time

import numpy as np


def _cpu_of(pids) -> float:
    """CPU seconds (user + system) the processes *pids* have used so far (Linux; else nan)."""
    tick = os.sysconf("SC_CLK_TCK") if hasattr(os, "sysconf") else 100
    total = 0.0
    for pid in pids:
        try:
            with open(f"/proc/{pid}/stat") as f:
                fields = f.read().rsplit(")", 1)[1].split()
        except OSError:
            return float("nan")
        total += (int(fields[11]) + int(fields[12])) / tick
    return total


def _timed(fn):
    w0, c0 = time.perf_counter(), time.process_time()
    out = fn()
    return out, time.perf_counter() - w0, time.process_time() - c0


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--population", type=int, default=400)
    args = ap.parse_args(argv)

    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebooks_dir
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.planners.fuzzy_rrt import BOUNDS_ABSOLUTE, MIN_STEP_DEG
    from xfuzzy_rrt.planners.tree import make_tree
    from xfuzzy_rrt.resources import paper_reference_scenario
    from xfuzzy_rrt.training.evaluate import TrainingProblem, run_population
    from xfuzzy_rrt.training.ga import GAConfig, generation_seeds, initial_population
    from xfuzzy_rrt.training.genome import decode, encode
    from xfuzzy_rrt.training.workers import evaluate_chunk, make_evaluator

    scenario = load_scenario(paper_reference_scenario())
    config = GAConfig(population=args.population, scenarios=(("paper-reference", "-"),))
    rng = np.random.default_rng(0)
    pop = initial_population(config, rng)
    pop[::2] = np.clip(encode(*load_rulebook(rulebooks_dir() / "paper").arrays())
                       + 0.01 * rng.standard_normal(pop[::2].shape), 0, 1)
    seeds = generation_seeds(0, 0, 5)
    problems = [TrainingProblem.from_scenario(scenario)]
    pr = problems[0]

    def planner_kernel_loop(genes):
        knots, consts = decode(genes)
        return run_population(pr.bundle, make_tree(10_002, pr.limits), knots, consts,
                              BOUNDS_ABSOLUTE, seeds, 10_000, MIN_STEP_DEG,
                              np.zeros(1, dtype=np.int64))

    load0 = os.getloadavg()
    planner_kernel_loop(pop[:2])  # compile / load both loops here
    evaluate_chunk(pop[:2], problems, "absolute", seeds, 10_000)
    before, before_wall, before_cpu = _timed(lambda: planner_kernel_loop(pop))
    its, serial_wall, serial_cpu = _timed(
        lambda: evaluate_chunk(pop, problems, "absolute", seeds, 10_000))
    if not np.array_equal(before, its[:, 0, :]):
        print("error: the training loop and the planner kernel disagree", file=sys.stderr)
        return 1
    walls, cpus = [], []
    with make_evaluator(problems, "absolute", 10_000, workers=args.workers) as evaluate:
        evaluate(pop[:8], seeds)  # start the workers
        pids = list(getattr(getattr(evaluate, "_pool", None), "_processes", None) or [])
        for _ in range(args.rounds):
            c0 = _cpu_of(pids) if pids else float("nan")
            t0 = time.perf_counter()
            got = evaluate(pop, seeds)
            walls.append(time.perf_counter() - t0)
            cpus.append((_cpu_of(pids) if pids else float("nan")) - c0)
            assert np.array_equal(got, its)
    from xfuzzy_rrt.training.evaluate import fitness
    from xfuzzy_rrt.training.ga import breed

    fit = fitness(its, 10_000)
    bred = [_timed(lambda: breed(pop, fit, config, np.random.default_rng(k)))
            for k in range(args.rounds)]
    breed_wall = statistics.median(b[1] for b in bred)
    breed_cpu = statistics.median(b[2] for b in bred)
    load1 = os.getloadavg()
    done = np.where(its < 0, 10_000, its)
    n_it = int(done.sum())
    print(f"load average {load0[0]:.2f} at start, {load1[0]:.2f} at end ({os.cpu_count()} cores)")
    print(f"{len(pop)} individuals x {len(seeds)} runs: median iterations "
          f"{float(np.median(done)):.0f}, failed runs {int((its < 0).sum())}, "
          f"total iterations {n_it}")
    print(f"serial, planner kernel loop (before): {before_wall:.3f} s wall, {before_cpu:.3f} s CPU")
    print(f"serial, training loop (now):          {serial_wall:.3f} s wall, {serial_cpu:.3f} s CPU"
          f"  ({before_cpu / serial_cpu:.2f}x less CPU)")
    print(f"kernel floor at {args.workers} workers: {serial_cpu / args.workers:.3f} s "
          f"({serial_cpu / n_it * 1e6:.2f} us CPU per iteration)")
    print(f"one generation, {args.workers} workers: median {statistics.median(walls):.3f} s wall "
          f"(rounds: {', '.join(f'{w:.3f}' for w in walls)}); worker CPU median "
          f"{statistics.median(cpus):.3f} s")
    print(f"breeding the next generation (main process, serial): median {breed_wall:.3f} s wall, "
          f"{breed_cpu:.3f} s CPU")
    print(f"one whole generation (evaluation + breeding): {statistics.median(walls) + breed_wall:.3f} s")
    return 0


if __name__ == "__main__":
    sys.exit(main())
