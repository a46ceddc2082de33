"""A problem handed to compiled code as one block is the very problem: every field, every value,
every type numba gives it, with a fresh work counter per call."""

from __future__ import annotations

import numba as nb
import numpy as np
import pytest

from xfuzzy_rrt.geometry.collision import clearance_kernel
from xfuzzy_rrt.geometry.problem import Problem, arms_problem
from xfuzzy_rrt.planners.problem_arena import make_problem_arena, problem_in


@nb.njit(cache=False)
def _unpacked(block, layout, q):
    P = problem_in(block, layout)
    c = clearance_kernel(P, q)
    return (P.links.copy(), P.arm_first.copy(), P.bases.copy(), P.radii.copy(),
            P.obstacles.copy(), P.limits.copy(), P.start.copy(), P.goal.copy(), P.margin,
            P.clearance, P.work.copy(), c)


def _problems():
    circle = [[0.0, 0.1, 0.1, 0.03, 0.0]]
    one = arms_problem([([0.1, 0.1], [0.0, 0.0], 0.005)], circle, margin=0.003)
    none = arms_problem([([0.1, 0.1, 0.08], [0.0, 0.0], 0.005)], (), margin=1e-6)
    two = arms_problem([([0.1, 0.1], [0.0, 0.0], 0.005), ([0.12, 0.09, 0.05], [0.3, 0.0], 0.004)],
                       circle * 3, margin=1e-6)
    return [one, none, two._replace(start=np.arange(5.0), goal=-np.arange(5.0))]


@pytest.mark.parametrize("problem", _problems(), ids=["one-arm", "no-obstacle", "two-arms"])
def test_the_block_gives_back_every_field_and_the_same_clearance(problem):
    arena = make_problem_arena(problem)
    q = np.linspace(-40.0, 60.0, problem.start.shape[0])
    fresh = problem._replace(work=np.zeros(1, dtype=np.int64))
    expected = clearance_kernel(fresh, q)
    compiled = len(clearance_kernel.signatures)
    out = _unpacked(arena.block, arena.layout, q)
    # numba types the block's views as it types the separate arrays: the kernel called with the
    # rebuilt problem needed no second specialisation
    assert len(clearance_kernel.signatures) == compiled
    for name, got in zip(Problem._fields, out):
        want = getattr(problem, name)
        if name == "work":
            assert got.dtype == np.int64 and got.shape == (1,)
            assert got[0] > 0  # the clearance was counted in the fresh counter, not the source's
            assert problem.work[0] == 0
        else:
            assert np.array_equal(got, want) and np.asarray(got).dtype == np.asarray(want).dtype, name
            assert np.shape(got) == np.shape(want), name
    assert out[-1] == expected


def test_a_problem_field_of_the_wrong_shape_is_refused():
    good = _problems()[0]
    with pytest.raises(TypeError, match="bases"):
        make_problem_arena(good._replace(bases=good.bases.reshape(-1)))
