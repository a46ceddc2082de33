"""A node check computes the arm's forward kinematics once (geometry/collision.py,
``_clearance_with_pairs``), and gives bit for bit what the link-obstacle clearance and the
link-pair clearance, each computed on its own, give: the value every tree planner stores for a
node and reads as a fuzzy input, and the verdict of every node check."""

from __future__ import annotations

import numpy as np
import pytest

from xfuzzy_rrt.geometry.collision import (
    _obstacle_clearance,
    arm_arm_clearance,
    clearance_into,
    clearance_kernel,
    link_segments_into,
    n_distance_pairs,
    self_clearance,
)
from xfuzzy_rrt.geometry.problem import arms_problem

CIRCLE, BOX = 0.0, 1.0


def _problem(rng, arm_links):
    arms = [(rng.uniform(0.05, 0.2, n), (0.3 * a, 0.1 * a), 0.01 + 0.01 * a)
            for a, n in enumerate(arm_links)]
    obstacles = [(CIRCLE, *rng.uniform(-0.4, 0.4, 2), rng.uniform(0.02, 0.08), 0.0)
                 for _ in range(3)]
    x0, y0 = rng.uniform(-0.4, 0.3, 2)
    obstacles.append((BOX, x0, y0, x0 + 0.1, y0 + 0.05))
    return arms_problem(arms, obstacles)


def _separately(P, q):
    seg = np.empty((P.links.shape[0], 4))
    link_segments_into(P, q, seg)
    pairs = np.inf
    if P.arm_first.shape[0] > 2:
        pairs = min(pairs, arm_arm_clearance(P, seg))
    pairs = min(pairs, self_clearance(P, seg))
    return min(_obstacle_clearance(P, q), pairs), seg


@pytest.mark.parametrize("arm_links", [(3,), (5,), (7,), (3, 3), (2, 2), (7, 7, 7, 7), (2, 4, 3)])
def test_a_node_check_equals_the_two_clearances_computed_apart_bit_for_bit(arm_links):
    rng = np.random.default_rng(sum(arm_links) * 31 + len(arm_links))
    P = _problem(rng, arm_links)
    seg = np.empty((P.links.shape[0], 4))
    for _ in range(300):
        q = rng.uniform(-180.0, 180.0, P.links.shape[0])
        expected, expected_seg = _separately(P, q)
        w0 = int(P.work[0])
        got = clearance_into(P, q, seg)
        assert int(P.work[0]) - w0 == n_distance_pairs(P)  # the same work as before
        assert got == expected or (np.isinf(got) and np.isinf(expected))
        assert np.array_equal(seg, expected_seg)  # the segments a following edge check reads
        assert clearance_kernel(P, q) == got
