"""The per-link obstacle bound of the certified edge check: ``M_k`` and the step ``c_k / M_k``.

A link's tip sweeping *at* a small obstacle and grazing past it is the tight case: its distance
to the obstacle falls at almost exactly ``M_k`` and climbs again as fast, a V a few
micrometres deep at the bottom. A step even 5 % too long (``M_k`` divided by 1.05, or the
advance ``c_k / M_k`` multiplied by 1.05) jumps from one side of the V to the other and
certifies a colliding edge; ``scripts/mutation_test.sh --weaken 1.05`` expects this file to
fail then. Every case is a real collision for the independent oracle first.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from exact_geometry import World
from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M, edge_free, link_motion_bound
from xfuzzy_rrt.geometry.problem import single_arm_problem


def _graze(links, shape: str, gap: float, depth: float):
    """A straight arm along +x whose tip, turning about the base through 0°, passes a tiny
    obstacle (circle of radius 0.1 mm, or a 20 µm square) ``gap`` beyond it; the capsule radius
    ``gap (1 + depth)`` makes that a collision ``gap depth`` deep."""
    reach = float(np.sum(links))
    if shape == "circle":
        rho = 1e-4
        ob = [0.0, reach + gap + rho, 0.0, rho, 0.0]
    else:
        w = 2e-5
        ob = [1.0, reach + gap, -0.5 * w, reach + gap + w, 0.5 * w]
    return np.array([ob]), gap * (1.0 + depth)


CASES = [(links, shape, gap, depth, alpha, past)
         # one, two and three links: a two-link arm (every 2-DOF problem) is checked by its
         # own allocation-free path, edge_free_two_link, which must be pinned as tightly
         for links in ((0.3,), (0.17, 0.13), (0.12, 0.1, 0.08))
         for shape in ("circle", "box")
         for gap in (5e-5, 3e-4)
         for depth in (0.005, 0.05)
         for alpha, past in ((4.0, 1.0), (9.0, 0.6), (15.0, 1.4))]


@pytest.mark.parametrize("links, shape, gap, depth, alpha, past", CASES)
def test_link_obstacle_bound_refuses_a_tip_grazing_a_small_obstacle(links, shape, gap, depth,
                                                                    alpha, past):
    links = np.array(links)
    obstacles, radius = _graze(links, shape, gap, depth)
    n = links.shape[0]
    qa = np.zeros(n)
    qb = np.zeros(n)
    qa[0], qb[0] = -alpha, past * alpha  # the first joint swings the straight arm through 0°
    w = World.from_obstacle_rows([(links, (0.0, 0.0), radius)], obstacles)
    bracket = w.segment_min_clearance(qa, qb)
    assert bracket.upper < 0.0 and bracket.lower > -1e-4  # a real, shallow collision
    P = single_arm_problem(links, np.zeros(2), radius, obstacles, np.tile([-180.0, 180.0], (n, 1)))
    assert not edge_free(P, qa, qb, CERT_MARGIN_M)


@pytest.mark.parametrize("links", [(0.17, 0.13), (0.12, 0.1, 0.08)])
@pytest.mark.parametrize("shape", ["circle", "box"])
def test_link_obstacle_bound_certifies_the_same_sweep_passing_just_clear(shape, links):
    links = np.array(links)
    n = links.shape[0]
    obstacles, radius = _graze(links, shape, 3e-4, -0.2)
    qa, qb = np.zeros(n), np.zeros(n)
    qa[0], qb[0] = -9.0, 9.0
    w = World.from_obstacle_rows([(links, (0.0, 0.0), radius)], obstacles)
    assert w.segment_min_clearance(qa, qb).lower > CERT_MARGIN_M
    P = single_arm_problem(links, np.zeros(2), radius, obstacles, np.tile([-180.0, 180.0], (n, 1)))
    assert edge_free(P, qa, qb, CERT_MARGIN_M)


def test_link_obstacle_bound_matches_the_tip_speed_of_a_straight_arm():
    """``M_k`` of the last link is the tip's speed when the straight arm turns about its base
    (tight: a weaker bound would be below a real speed) and every joint's share adds up."""
    links = np.array([0.12, 0.1, 0.08])
    qa, qb = np.zeros(3), np.array([10.0, 0.0, 0.0])
    assert link_motion_bound(links, qa, qb, 2, 0) == pytest.approx(0.3 * math.radians(10.0))
    qb2 = np.array([10.0, -4.0, 6.0])
    expected = math.radians(10.0) * 0.3 + math.radians(4.0) * 0.18 + math.radians(6.0) * 0.08
    assert link_motion_bound(links, qa, qb2, 2, 0) == pytest.approx(expected)


@pytest.mark.parametrize("links", [(0.3,), (0.17, 0.13), (0.12, 0.1, 0.08)])
def test_an_edge_check_asked_for_less_than_the_clearance_certifies_nothing(links):
    """A margin below the problem's clearance is an inconsistent call (the steps
    ``(c_k - clear) / M_k`` would be measured against more than the stops are checked for):
    nothing is certified, on a free edge far from the only obstacle, on every path of the
    check (the two-link one too: a mutant that certified here survived the suite once)."""
    links = np.array(links)
    n = links.shape[0]
    far = np.array([[0.0, 5.0, 5.0, 0.01, 0.0]])
    P = single_arm_problem(links, np.zeros(2), 0.005, far, np.tile([-180.0, 180.0], (n, 1)),
                           margin=0.01)
    qa, qb = np.zeros(n), np.full(n, 10.0)
    assert edge_free(P, qa, qb, 0.01)  # consistent: free and certified
    assert not edge_free(P, qa, qb, CERT_MARGIN_M)


@pytest.mark.parametrize("links", [(0.17, 0.13), (0.12, 0.1, 0.08)])
@pytest.mark.parametrize("end", ["start", "goal"])
@pytest.mark.parametrize("bad", [math.nan, math.inf])
def test_an_edge_with_a_nan_outer_joint_angle_is_never_certified(links, end, bad):
    """A NaN (or infinite) outer joint angle puts the outer link's far end nowhere: its
    distance must count as touching, so the edge is refused, whichever end carries it. (The
    survivor of mutation testing in the two-link path's ``not c1 < inf`` guard is equivalent:
    such a link measures ``-radius``, never ``inf`` or NaN, and an all-NaN obstacle list trips
    the first link's guard before it; this pins what makes it so.)"""
    links = np.array(links)
    n = links.shape[0]
    box = np.array([[1.0, 0.25, -0.05, 0.35, 0.05]])
    P = single_arm_problem(links, np.zeros(2), 0.005, box, np.tile([-180.0, 180.0], (n, 1)))
    qa, qb = np.zeros(n), np.zeros(n)
    qa[0], qb[0] = 90.0, 80.0
    (qa if end == "start" else qb)[n - 1] = bad
    assert not edge_free(P, qa, qb, CERT_MARGIN_M)


@pytest.mark.parametrize("links", [(0.3,), (0.17, 0.13), (0.12, 0.1, 0.08)])
def test_an_obstacle_with_a_nan_coordinate_is_never_certified_past(links):
    """A NaN clearance (a NaN obstacle row) is not a free stop, on every path of the check."""
    links = np.array(links)
    n = links.shape[0]
    nan_box = np.array([[1.0, math.nan, -1.0, 3.0, 1.0]])
    P = single_arm_problem(links, np.zeros(2), 0.005, nan_box, np.tile([-180.0, 180.0], (n, 1)))
    qa, qb = np.zeros(n), np.zeros(n)
    qa[0], qb[0] = 45.0, -45.0
    assert not edge_free(P, qa, qb, CERT_MARGIN_M)
