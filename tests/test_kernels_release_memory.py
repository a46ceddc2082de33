"""Planning and training leave numba's allocator balanced: every array allocated is freed.

Why this test exists: the planner and training loops, and the geometry and tree helpers they
call, are compiled without numba's reference counting (``_nrt=False``: the atomic increments
and decrements were a third of a 2-joint loop's time). Such a function may not allocate (numba
refuses to compile it), but it could still receive a *new* array from a counted callee and never
release it: a leak nothing else would notice. numba's allocation statistics catch it: after
warm-up, a batch of plans of every kind must free exactly what it allocated.
"""

from __future__ import annotations

import gc

import numpy as np
import pytest

from xfuzzy_rrt.geometry.scenario import Arm, Circle, Scenario
from xfuzzy_rrt.planners.api import plan_scenario


def _arm(n: int, base=(0.0, 0.0), reach: float = 1.0) -> Arm:
    return Arm(links=tuple([reach / n] * n), base=base, link_radius=0.01,
               joint_limits_deg=((-180.0, 180.0),) * n)


def _single(n: int) -> Scenario:
    return Scenario(name=f"arm{n}", arm=_arm(n), start_deg=(-60.0,) + (0.0,) * (n - 1),
                    goal_deg=(60.0,) + (5.0,) * (n - 1),
                    obstacles=(Circle((0.85, 0.0), 0.06),))


def _dual(n: int) -> Scenario:
    a, b = _arm(n, (-0.45, 0.0), 0.5), _arm(n, (0.45, 0.0), 0.5)
    return Scenario(name=f"dual{n}", arm=a, more_arms=(b,),
                    start_deg=(90.0,) + (0.0,) * (n - 1) + (180.0,) + (0.0,) * (n - 1),
                    goal_deg=(-90.0,) + (0.0,) * (n - 1) + (170.0,) + (0.0,) * (n - 1),
                    obstacles=(Circle((0.0, 0.6), 0.08),))


def _stats_around(batch):
    """numba's allocation counters before and after a second ``batch()`` (the first compiles
    and fills the call memos), counted only while the batches run."""
    from numba.core.runtime import _nrt_python as nrt
    from numba.core.runtime import rtsys

    was_on = nrt.memsys_stats_enabled()
    nrt.memsys_enable_stats()
    try:
        batch()
        before = rtsys.get_allocation_stats()
        batch()
        after = rtsys.get_allocation_stats()
    finally:
        if not was_on:
            nrt.memsys_disable_stats()
    return before, after


CASES = [
    (_single(2), "rrt"),
    (_single(2), "fuzzy-rrt"),  # the 2-joint default: goal-frame
    (_single(2), "fuzzy-rrt:expert"),  # the paper's semantics
    (_single(2), "fuzzy-rrt-connect"),
    (_single(5), "rrt"),
    (_single(5), "fuzzy-rrt"),  # any other arm: connect with goal-frame-any
    (_dual(3), "fuzzy-rrt:goal-frame-dual3"),
    (_dual(2), "fuzzy-rrt:expert"),
]


@pytest.mark.parametrize("scenario,planner", CASES, ids=[f"{s.name}-{p}" for s, p in CASES])
def test_planning_frees_every_array_it_allocates(scenario, planner):
    def batch():
        for seed in range(4):
            for trace in (False, True) if planner.startswith("fuzzy-rrt") else (False,):
                plan_scenario(scenario, planner, seed=seed, max_iter=400, trace=trace)
        gc.collect()

    before, after = _stats_around(batch)
    allocated = after.alloc - before.alloc
    freed = after.free - before.free
    assert allocated > 0  # the statistics are live: planning does allocate (trees, results)
    assert freed == allocated
    assert after.mi_free - before.mi_free == after.mi_alloc - before.mi_alloc


def test_training_evaluation_frees_every_array_it_allocates():
    from xfuzzy_rrt.training.evaluate import TrainingProblem
    from xfuzzy_rrt.training.genome import constant_genome
    from xfuzzy_rrt.training.workers import evaluate_chunk

    problems = [TrainingProblem.from_scenario(_single(2))]
    genes = np.repeat(constant_genome(0.1, (-180, 180, -180, 180), 10.0)[None], 3, axis=0)
    seeds = np.arange(3, dtype=np.int64)

    def batch():
        for bounds in ("absolute", "relative"):
            evaluate_chunk(genes, problems, bounds, seeds, 300)
        gc.collect()

    before, after = _stats_around(batch)
    assert after.alloc - before.alloc > 0
    assert after.free - before.free == after.alloc - before.alloc
