"""The fuzzy inputs of one arm see the other arms' capsules as obstacles (exact values).

``nearest_obstacle_for_arm`` is what the paper's semantics read per arm (distance and direction
to the nearest thing); the mutation run of ``collision.py`` found its several-arm branch
untested. Checked here against hand-computed geometry.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from xfuzzy_rrt.geometry.collision import nearest_obstacle_for_arm, nearest_obstacle_from_point
from xfuzzy_rrt.geometry.problem import arms_problem

# arm 0 at the origin (one link), arm 1 at (1, 0) with two links pointing up: (1,0)-(1,0.2)-(1,0.3)
ARMS = [(np.array([0.3]), (0.0, 0.0), 0.01), (np.array([0.2, 0.1]), (1.0, 0.0), 0.02)]
CIRCLE = np.array([[0.0, 0.5, 0.5, 0.05, 0.0]])
Q = np.array([0.0, 90.0, 0.0])


def test_the_nearest_thing_is_a_link_of_the_other_arm_with_its_exact_distance_and_direction():
    P = arms_problem(ARMS, CIRCLE)
    # a point at (0.8, 0.25): the other arm's second link (x = 1, y in [0.2, 0.3]) is 0.2 away
    # minus its radius 0.02, due east; the circle is sqrt(0.09 + 0.0625) - 0.05 away
    d, angle, index = nearest_obstacle_for_arm(P, 0, Q, 0.8, 0.25)
    assert d == pytest.approx(0.18, abs=1e-12)
    assert angle == pytest.approx(0.0, abs=1e-12)
    assert index == -1 - 2  # link 2 of the problem (arm 1's second link)
    # a point below the first link of arm 1: link 1 (x = 1, y in [0, 0.2]), to the east too
    d, angle, index = nearest_obstacle_for_arm(P, 0, Q, 0.9, 0.1)
    assert (d, index) == (pytest.approx(0.08, abs=1e-12), -1 - 1)
    # from above the tip of arm 1: straight down (3π/2), to the tip (1, 0.3)
    d, angle, index = nearest_obstacle_for_arm(P, 0, Q, 1.0, 0.6)
    assert d == pytest.approx(0.28, abs=1e-12) and angle == pytest.approx(1.5 * math.pi)
    assert index == -1 - 2


def test_an_obstacle_nearer_than_the_other_arm_wins_and_the_arm_never_sees_itself():
    P = arms_problem(ARMS, CIRCLE)
    d, angle, index = nearest_obstacle_for_arm(P, 0, Q, 0.5, 0.38)
    assert index == 0 and d == pytest.approx(0.07, abs=1e-12)
    assert angle == pytest.approx(0.5 * math.pi, abs=1e-12)
    # arm 1 asking about a point on its own link sees arm 0 and the circle, not itself
    d, _, index = nearest_obstacle_for_arm(P, 1, Q, 1.0, 0.1)
    assert index == 0 and d == pytest.approx(math.hypot(0.5, 0.4) - 0.05, abs=1e-12)
    bare = arms_problem(ARMS, np.zeros((0, 5)))
    d, _, index = nearest_obstacle_for_arm(bare, 1, Q, 1.0, 0.1)
    assert index == -1 - 0 and d == pytest.approx(math.hypot(0.7, 0.1) - 0.01, abs=1e-12)


def test_inside_a_link_capsule_of_the_other_arm_the_distance_is_zero():
    P = arms_problem(ARMS, np.zeros((0, 5)))
    d, _, index = nearest_obstacle_for_arm(P, 0, Q, 1.01, 0.1)
    assert d == 0.0 and index == -1 - 1


def test_with_one_arm_it_is_the_nearest_obstacle_from_the_point():
    P = arms_problem(ARMS[:1], CIRCLE)
    assert nearest_obstacle_for_arm(P, 0, np.array([0.0]), 0.2, 0.2) == \
        nearest_obstacle_from_point(0.2, 0.2, CIRCLE)
