"""Monte Carlo throughput: 10,000 perturbations of one planned path (issue 18: <= 1 s).

One RRT path on ``paper-reference`` (65 waypoints, 5 obstacles), executed under obstacle
centre offsets (σ 2 mm), radius changes (σ 1 mm) and joint tracking error (σ 0.5°): each
trial's minimum clearance along the continuous motion (1 µm; the contact decided exactly).
Measured, never asserted (``pytest benchmarks/test_bench_robustness.py``); the figure goes in
the note. ``workers`` = numba threads; the numbers are identical for every count.
"""

from __future__ import annotations

import pytest

from xfuzzy_rrt.planners.rrt import plan_rrt
from xfuzzy_rrt.robustness.montecarlo import Perturbation, path_robustness

TRIALS = 10_000


@pytest.fixture(scope="module")
def planned(scenario):
    path = plan_rrt(scenario, seed=0).path_deg
    p = Perturbation(0.002, 0.001, 0.5)
    path_robustness(scenario.arrays(), path, p, trials=100, seed=0)  # compile outside timing
    return scenario.arrays(), path, p


@pytest.mark.parametrize("workers", [1, 2])
def test_monte_carlo_10k_perturbations_of_one_path(benchmark, planned, workers):
    arrays, path, p = planned
    res = benchmark.pedantic(path_robustness, args=(arrays, path, p),
                             kwargs={"trials": TRIALS, "seed": 1, "workers": workers},
                             rounds=3, iterations=1)
    benchmark.extra_info.update({"trials": TRIALS, "waypoints": int(path.shape[0]),
                                 "collisions": res.collisions, "undecided": res.undecided})
