"""What one RRT iteration costs as the arm grows: N = 2, 3, 5, 7 joints, and two 3-joint arms.

Each case plans one generated problem of the N-DOF family (``scenarios generate --dof N``) for
a fixed number of iterations on a seed; the figure reported is wall time per iteration
(``extra_info["us_per_iteration"]``). Nearest-neighbour search is a grid at N = 2 and a k-d
tree beyond; the certified edge check grows with links x obstacles (and link pairs between
arms). Run: ``pytest benchmarks/test_bench_ndof.py --benchmark-only``.
"""

from __future__ import annotations

import functools

import pytest

from xfuzzy_rrt.planners.rrt import plan_rrt
from xfuzzy_rrt.scenarios.generate import generate_nd

ITERATIONS = 5_000


@functools.lru_cache(maxsize=None)
def _problem(dof: int, arms: int):
    return generate_nd(9100, 0, dof=dof, arms=arms).scenario


@pytest.mark.parametrize("dof,arms", [(2, 1), (3, 1), (5, 1), (7, 1), (3, 2)],
                         ids=["N2", "N3", "N5", "N7", "dual-N3"])
def test_rrt_time_per_iteration(benchmark, dof, arms):
    s = _problem(dof, arms)
    plan_rrt(s, seed=0, max_iter=10)  # compile outside the timing

    def run():
        # an unreachable goal bias of 0 and a step of 1 deg keep every run at ITERATIONS
        return plan_rrt(s, seed=0, max_iter=ITERATIONS, goal_bias=0.0, step_deg=1.0)

    r = benchmark(run)
    benchmark.extra_info["iterations"] = r.iterations
    benchmark.extra_info["us_per_iteration"] = benchmark.stats.stats.median / r.iterations * 1e6
