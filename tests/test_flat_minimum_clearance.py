"""Issue 22: the exact minimum clearance closes on *flat* minima, and its curvature bound is sound.

Two links of a straight arm that are one link apart stay exactly that far apart while a joint
between them turns (the closest points are the two ends of the link between them, a rigid
distance): the clearance is constant over a whole segment. A Lipschitz bound alone must split
such a segment into ``speed / tol`` pieces to prove it (millions at 0.1 µm); the curvature
bound of ``geometry/clearance.py`` (:func:`element_lower_bound`) proves it with ``sqrt(K / tol)``
pieces. The bound is conservative only if its speed and acceleration constants are: the tight
cases below (a tip turning past a point, for a link against an obstacle, a self pair and two
arms) sit within a few per cent of the true curvature, so a constant 1.05x weaker puts the bound
above the true minimum and fails here.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from exact_geometry import World
from xfuzzy_rrt.geometry.clearance import (
    MIN_CLEARANCE_MAX_EVALS,
    element_lower_bound,
    element_speed_accel,
    min_clearance_kernel,
    path_min_clearance,
)
from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M, MIN_CLEARANCE_TOL_M
from xfuzzy_rrt.geometry.path_check import certify_path
from xfuzzy_rrt.geometry.problem import arms_problem
from xfuzzy_rrt.geometry.signed import element_clearances, n_elements

TOL = MIN_CLEARANCE_TOL_M


class _Arrays:
    """The few ScenarioArrays members path_min_clearance / certify_path read."""

    def __init__(self, arms, obstacles=()):
        self.arms = arms
        self.obstacles = np.asarray(obstacles, dtype=float).reshape(-1, 5)
        self.links = np.concatenate([np.asarray(l, dtype=float) for l, _, _ in arms])
        self.limits_deg = np.tile([-360.0, 360.0], (self.links.shape[0], 1))

    def problem(self, margin):
        return arms_problem(self.arms, self.obstacles, limits=self.limits_deg, margin=margin)


def _straight_arm_path(n: int):
    """An ``n``-link straight arm (link 1 of length 0.1 m, the others longer) turning joint 2
    from -40 to +40 degrees and back to -10 while joint 0 swings the whole arm: links 0 and 2
    stay exactly ``l_1`` apart (the ends of link 1) on both segments, the path's minimum."""
    links = np.array([0.2, 0.1] + [0.15] * (n - 2))
    path = np.zeros((3, n))
    path[:, 0] = (0.0, 25.0, 50.0)
    path[:, 2] = (-40.0, 40.0, -10.0)
    return links, path


@pytest.mark.parametrize("n", [5, 7])
def test_exact_min_clearance_closes_on_two_links_held_one_link_apart(n):
    links, path = _straight_arm_path(n)
    radius = 0.01
    # a circle far from the arm: its elements are never the minimum and must be pruned
    arrays = _Arrays([(links, (0.0, 0.0), radius)], [(0.0, -0.6, -0.6, 0.05, 0.0)])
    expected = links[1] - 2.0 * radius  # the two ends of link 1, minus both capsule radii
    r = path_min_clearance(arrays, path)
    assert r.value_m == pytest.approx(expected, abs=1e-12)
    # proven to the tolerance, not stopped at the evaluation budget
    assert r.lower_bound_m >= r.value_m - TOL * (1.0 + 1e-9)
    assert r.lower_bound_m <= expected
    # the certificate reports the same exact value (it used to report the budget's loose bound)
    check = certify_path(arrays, path)
    assert check.certified and check.min_clearance_m == pytest.approx(expected, abs=1e-12)
    # the independent oracle brackets it too, within its own budget
    b = World([(links, (0.0, 0.0), radius)], circles=[(-0.6, -0.6, 0.05)]).path_min_clearance(
        path, tol=TOL)
    assert not b.exhausted
    assert b.lower - TOL <= r.value_m <= b.upper + TOL
    assert b.upper == pytest.approx(expected, abs=1e-12)


def test_flat_minimum_costs_few_evaluations():
    # the branch and bound's own work, deterministic: a flat minimum over two segments of a
    # seven-link arm takes thousands of configurations, not the budget's millions
    links, path = _straight_arm_path(7)
    P = arms_problem([(links, (0.0, 0.0), 0.01)], limits=np.tile([-360.0, 360.0], (7, 1)))
    value, _seg, _s, lower = min_clearance_kernel(P, path, TOL, MIN_CLEARANCE_MAX_EVALS, False)
    assert lower >= value - TOL * (1.0 + 1e-9)
    per_config = n_elements(P)
    assert P.work[0] < 20_000 * per_config < MIN_CLEARANCE_MAX_EVALS * per_config


# ------------------------------------------------------------------- the bound is conservative


def _bound_at(P, qa, qb, element):
    """``element``'s lower bound over the whole segment ``qa -> qb`` (one interval)."""
    nl = n_elements(P)
    c0, c1 = np.empty(nl), np.empty(nl)
    element_clearances(P, qa, c0)
    element_clearances(P, qb, c1)
    vel, acc, off = np.empty(nl), np.empty(nl), np.empty(nl)
    element_speed_accel(P, qa, qb, vel, acc, off)
    return element_lower_bound(c0[element], c1[element], vel[element], acc[element],
                               off[element], 1.0), c0[element]


def _turning_past(q_mid, joint, closest, radius_of_turn):
    """Joint ``joint`` turning symmetrically about ``q_mid`` through a small angle: the tip
    (``radius_of_turn`` from the joint) moves 0.4 % of the ``closest`` approach, so the
    first-order part of the bound's ``D`` is within that of the true distance."""
    half = math.degrees(0.5 * 0.004 * closest / radius_of_turn)
    qa, qb = np.array(q_mid, dtype=float), np.array(q_mid, dtype=float)
    qa[joint] -= half
    qb[joint] += half
    return qa, qb


@pytest.mark.parametrize("far, ro", [(0.05, 1e-5), (0.2, 1e-5)])
def test_curvature_bound_holds_for_a_link_tip_turning_past_an_obstacle(far, ro):
    # link 1 (0.1 m) turns about the joint at (0.2, 0); a tiny circle sits `far` beyond its tip
    # on the line of the arm: the clearance is smooth with curvature R l w² / (R - l) at the
    # closest approach, exactly the bound's A + V² / D there
    l0, l1, radius = 0.2, 0.1, 0.001
    P = arms_problem([(np.array([l0, l1]), (0.0, 0.0), radius)],
                     [(0.0, l0 + l1 + far + ro, 0.0, ro, 0.0)])
    qa, qb = _turning_past([0.0, 0.0], 1, far, l1)
    lb, c_end = _bound_at(P, qa, qb, 1)
    true_min = far - radius  # at s = 1/2, the link pointing at the circle
    assert lb <= true_min
    # and tight: within a few per cent of the chord's sag, so a weaker constant fails above
    assert true_min - lb < 0.02 * (c_end - true_min)


@pytest.mark.parametrize("gap, radius", [(2e-3, 1e-4), (1e-2, 1e-4), (2e-3, 5e-4)])
def test_curvature_bound_holds_for_a_folded_tip_turning_past_its_own_arm(gap, radius):
    # three links: link 2 folded back over link 1, its tip passing `gap` from the joint
    # between links 0 and 1 while joint 2 turns: self pair (0, 2), only joint 2 moves it; with
    # thick capsules the radii are half the gap, so the distance D must add exactly them
    l0, l1 = 0.2, 0.1
    links = np.array([l0, l1, l1 - gap])
    P = arms_problem([(links, (0.0, 0.0), radius)], limits=np.tile([-360.0, 360.0], (3, 1)))
    qa, qb = _turning_past([0.0, 0.0, 180.0], 2, gap, links[2])
    element = 3  # links 0..2, then the one self pair (0, 2)
    lb, c_end = _bound_at(P, qa, qb, element)
    true_min = gap - 2.0 * radius
    assert lb <= true_min
    assert true_min - lb < 0.02 * (c_end - true_min)


def test_curvature_bound_holds_for_a_tip_turning_past_another_arms_tip():
    # arm B's two-link tip turns about its elbow past the tip of a still arm A
    l1, far, radius = 0.1, 0.03, 1e-4
    arm_a = (np.array([0.3]), (-0.3 - far - 0.2 - l1, 0.0), radius)
    arm_b = (np.array([0.2, l1]), (0.0, 0.0), radius)
    P = arms_problem([arm_a, arm_b])
    qa, qb = _turning_past([0.0, 180.0, 0.0], 2, far, l1)
    # arm A points +x and ends `far` short of arm B's tip when B is stretched along -x
    element = 3  # links 0, 1, 2, then the pairs (0, 1), (0, 2) of arms A and B
    lb, c_end = _bound_at(P, qa, qb, element + 1)
    true_min = far - 2.0 * radius
    assert lb <= true_min
    assert true_min - lb < 0.02 * (c_end - true_min)


def test_curvature_bound_never_exceeds_the_sampled_minimum_on_random_segments():
    # every element, random 5-link segments near a circle and a box, random sub-intervals:
    # the bound is at most the smallest of 400 exact samples (it may not be above any real value)
    rng = np.random.default_rng(22)
    links = np.array([0.2, 0.1, 0.15, 0.1, 0.12])
    P = arms_problem([(links, (0.0, 0.0), 0.01)],
                     [(0.0, 0.45, 0.1, 0.06, 0.0), (1.0, -0.2, 0.3, 0.1, 0.4)],
                     limits=np.tile([-360.0, 360.0], (5, 1)))
    nl = n_elements(P)
    vel, acc, off = np.empty(nl), np.empty(nl), np.empty(nl)
    cs = np.empty((400, nl))
    checked = 0
    for _ in range(60):
        qa = rng.uniform(-120.0, 120.0, 5)
        qb = qa + rng.normal(0.0, rng.choice([3.0, 20.0, 60.0]), 5)
        s = np.linspace(0.0, 1.0, 400)
        for i, si in enumerate(s):
            element_clearances(P, qa + si * (qb - qa), cs[i])
        element_speed_accel(P, qa, qb, vel, acc, off)
        for _ in range(5):
            i0, i1 = sorted(rng.choice(400, 2, replace=False))
            w = s[i1] - s[i0]
            for e in range(nl):
                lb = element_lower_bound(cs[i0, e], cs[i1, e], vel[e], acc[e], off[e], w)
                assert lb <= cs[i0:i1 + 1, e].min() + 1e-12, (qa, qb, e)
                checked += 1
    assert checked == 60 * 5 * nl


def test_chain_speed_is_the_tip_speed_when_one_joint_turns():
    # one joint: the tip circles at exactly l w, the element's speed bound (no slack to lose)
    links = np.array([0.2, 0.1, 0.15])
    P = arms_problem([(links, (0.0, 0.0), 0.01)], [(0.0, 2.0, 2.0, 0.1, 0.0)])
    qa, qb = np.zeros(3), np.array([0.0, 30.0, 0.0])
    nl = n_elements(P)
    vel, acc, off = np.empty(nl), np.empty(nl), np.empty(nl)
    element_speed_accel(P, qa, qb, vel, acc, off)
    w = math.radians(30.0)
    assert vel[2] == pytest.approx((links[1] + links[2]) * w)
    assert acc[2] == pytest.approx((links[1] + links[2]) * w * w)
    assert vel[3] == pytest.approx((links[1] + links[2]) * w)  # self pair (0, 2)
    assert off[2] == 0.01 and off[3] == 0.02
