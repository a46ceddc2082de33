"""One paper-scale GA generation: 400 individuals x 5 runs on paper-reference, 2 workers.

What it prints: the wall time of one generation through the trainer's evaluator (warm: the
workers are started and their kernels loaded by a first small call), next to the same 2,000
runs evaluated serially in this process (the pure kernel work), so the difference shows what
process hand-over costs (pickling genes and results, scheduling) against planning itself.
The population is the benchmark's (benchmarks/test_bench_training.py): half drawn like the
GA's first generation, half near the shipped ``paper`` rulebook, as late in training.

    nice python benchmarks/generation.py --rounds 3
"""

from __future__ import annotations

import argparse
import statistics
import sys
import time

import numpy as np


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--workers", type=int, default=2)
    ap.add_argument("--rounds", type=int, default=3)
    ap.add_argument("--population", type=int, default=400)
    args = ap.parse_args(argv)

    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebooks_dir
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.resources import paper_reference_scenario
    from xfuzzy_rrt.training import evaluate as ev
    from xfuzzy_rrt.training.ga import GAConfig, generation_seeds, initial_population
    from xfuzzy_rrt.training.genome import encode
    from xfuzzy_rrt.training.workers import evaluate_chunk, make_evaluator

    # the training problem class (renamed TrainingProblem on another branch)
    problem_cls = getattr(ev, "TrainingProblem", None) or ev.Problem
    scenario = load_scenario(paper_reference_scenario())
    config = GAConfig(population=args.population, scenarios=(("paper-reference", "-"),))
    rng = np.random.default_rng(0)
    pop = initial_population(config, rng)
    pop[::2] = np.clip(encode(*load_rulebook(rulebooks_dir() / "paper").arrays())
                       + 0.01 * rng.standard_normal(pop[::2].shape), 0, 1)
    seeds = generation_seeds(0, 0, 5)
    problems = [problem_cls.from_scenario(scenario)]

    evaluate_chunk(pop[:4], problems, "absolute", seeds, 10_000)  # compile / load here
    t0 = time.perf_counter()
    its = evaluate_chunk(pop, problems, "absolute", seeds, 10_000)
    serial = time.perf_counter() - t0
    walls = []
    with make_evaluator(problems, "absolute", 10_000, workers=args.workers) as evaluate:
        evaluate(pop[:8], seeds)  # start the workers
        for _ in range(args.rounds):
            t0 = time.perf_counter()
            evaluate(pop, seeds)
            walls.append(time.perf_counter() - t0)
    its = np.asarray(its)
    failed = int((its < 0).sum())
    print(f"{len(pop)} individuals x {len(seeds)} runs: median iterations "
          f"{float(np.median(np.where(its < 0, 10_000, its))):.0f}, failed runs {failed}, "
          f"total iterations {int(np.where(its < 0, 10_000, its).sum())}")
    print(f"serial in-process (kernel work): {serial:.3f} s")
    print(f"one generation, {args.workers} workers: median {statistics.median(walls):.3f} s "
          f"(rounds: {', '.join(f'{w:.3f}' for w in walls)})")
    return 0


if __name__ == "__main__":
    sys.exit(main())
