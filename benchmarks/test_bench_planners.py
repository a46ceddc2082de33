"""Planner speed: RRT and Fuzzy-RRT on the reference problem, 50 seeds, after JIT warm-up.

Targets (issue tracker): RRT ≤ 1.5 ms median per plan on ``paper-reference`` on a 2-core
machine; Fuzzy-RRT with tracing on ≤ 1.5x the time with tracing off. Each benchmark round plans
all 50 seeds; ``extra_info`` records the medians of iterations, cost and per-plan wall time
(the planner's own timer, which excludes Python set-up), so the figures can be reported.

Uses ``../shared/scenarios/paper-reference.toml`` when present, else the shipped demo scenario.
"""

from __future__ import annotations

import time

import numpy as np
import pytest

from xfuzzy_rrt.fuzzy.rulebook import default_rulebook_path, load_rulebook
from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt
from xfuzzy_rrt.planners.rrt import plan_rrt

SEEDS = range(50)




@pytest.fixture(scope="module")
def rulebook():
    return load_rulebook(default_rulebook_path())


def _record(benchmark, results):
    benchmark.extra_info["scenario"] = results[0].scenario
    benchmark.extra_info["success_rate"] = float(np.mean([r.success for r in results]))
    benchmark.extra_info["iterations_median"] = float(np.median([r.iterations for r in results]))
    benchmark.extra_info["cost_median_deg"] = float(np.median(
        [r.cost_deg for r in results if r.success]))
    benchmark.extra_info["kernel_wall_median_ms"] = float(np.median([r.wall_s for r in results]) * 1e3)


def _end_to_end_median_ms(plan) -> float:
    """Median wall time of whole planner calls (Python set-up and result objects included)."""
    times = []
    for s in SEEDS:
        t0 = time.perf_counter()
        plan(s)
        times.append(time.perf_counter() - t0)
    return float(np.median(times) * 1e3)


def test_rrt_50_seeds(benchmark, scenario):
    plan_rrt(scenario, seed=0)  # warm-up
    results = benchmark(lambda: [plan_rrt(scenario, seed=s) for s in SEEDS])
    _record(benchmark, results)
    benchmark.extra_info["call_median_ms"] = _end_to_end_median_ms(lambda s: plan_rrt(scenario, seed=s))


@pytest.mark.parametrize("trace", [False, True], ids=["trace-off", "trace-on"])
def test_fuzzy_rrt_50_seeds(benchmark, scenario, rulebook, trace):
    plan_fuzzy_rrt(scenario, rulebook, seed=0, trace=trace)  # warm-up
    results = benchmark(lambda: [plan_fuzzy_rrt(scenario, rulebook, seed=s, trace=trace)
                                 for s in SEEDS])
    _record(benchmark, results)
    benchmark.extra_info["call_median_ms"] = _end_to_end_median_ms(
        lambda s: plan_fuzzy_rrt(scenario, rulebook, seed=s, trace=trace))
