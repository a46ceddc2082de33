"""Self-tests of the N-link, multi-arm exact-geometry oracle (tests/exact_geometry.py).

The oracle is what issue 17's planner tests trust, so it is itself checked against brute force
and against shapely (GEOS) on known configurations: the distance primitives on random and
degenerate segments (crossing, parallel, collinear, touching), crossing arms, parallel capsules
touching exactly, a 7-link arm wrapped around an obstacle, two arms whose tips touch exactly
(touching is a collision), the segment bracket against dense sampling, and agreement with the
2-DOF shapely ``Oracle`` on the fixture scenarios. Exact touching cases use binary fractions
(0.125, 0.25, 1.25 ...), so "touching" is exact in float64 too.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely

from conftest import FIXTURES, shared_scenarios
from exact_geometry import (
    Oracle,
    World,
    as_world,
    oracle_clearance,
    oracle_in_collision,
    oracle_path_collides,
    oracle_path_is_free,
    oracle_path_min_clearance,
    oracle_path_problems,
    oracle_segment_min_clearance,
    point_segment_distance,
    segment_box_distance,
    segment_circle_distance,
    segment_segment_distance,
)
from xfuzzy_rrt.geometry.scenario import Arm, Box, Circle, Scenario, load_scenario

SCENARIOS = sorted((FIXTURES / "scenarios").glob("*.toml")) + shared_scenarios()


def dense(a, b, n=4001):
    t = np.linspace(0.0, 1.0, n)[:, None]
    return np.asarray(a, float) + t * (np.asarray(b, float) - np.asarray(a, float))


# ------------------------------------------------------------------------- distance primitives


def test_segment_segment_distance_matches_shapely_on_random_and_degenerate_segments():
    rng = np.random.default_rng(5)
    cases = [rng.uniform(-1, 1, (4, 2)) for _ in range(400)]
    # Degenerate: crossing, T-touching, collinear overlapping, collinear apart, parallel,
    # zero-length, shared endpoint.
    cases += [np.array(c, float) for c in (
        [(0, 0), (1, 1), (0, 1), (1, 0)],
        [(0, 0), (1, 0), (0.5, 0), (0.5, 1)],
        [(0, 0), (1, 0), (0.5, 0), (2, 0)],
        [(0, 0), (1, 0), (1.5, 0), (2, 0)],
        [(0, 0), (1, 0), (0.25, 0.125), (2, 0.125)],
        [(0.3, 0.3), (0.3, 0.3), (0, 0), (1, 1)],
        [(0.3, 0.3), (0.3, 0.3), (0.5, 0.5), (0.5, 0.5)],
        [(0, 0), (1, 0), (1, 0), (1, 1)],
    )]
    for a, b, c, d in cases:
        ours = float(segment_segment_distance(a, b, c, d))
        ref = shapely.LineString([a, b]).distance(shapely.LineString([c, d])) \
            if not (np.array_equal(a, b) or np.array_equal(c, d)) else \
            shapely.MultiPoint([a, b]).convex_hull.distance(shapely.MultiPoint([c, d]).convex_hull)
        assert ours == pytest.approx(ref, abs=1e-14), (a, b, c, d)
    # Brute force on a few: sampled point sets can only be farther apart.
    for a, b, c, d in cases[:40]:
        pa, pc = dense(a, b, 801), dense(c, d, 801)
        brute = np.min(np.linalg.norm(pa[:, None] - pc[None], axis=-1))
        ours = float(segment_segment_distance(a, b, c, d))
        assert ours <= brute + 1e-15
        assert brute - ours <= 2.0 * (np.linalg.norm(b - a) + np.linalg.norm(d - c)) / 800


def test_segment_obstacle_distances_match_shapely():
    rng = np.random.default_rng(6)
    for _ in range(300):
        a, b = rng.uniform(-1, 1, (2, 2))
        center, r = rng.uniform(-1, 1, 2), rng.uniform(0.01, 0.5)
        ref = max(shapely.LineString([a, b]).distance(shapely.Point(center)) - r, 0.0)
        assert float(segment_circle_distance(a, b, center, r)) == pytest.approx(ref, abs=1e-14)
        lo = rng.uniform(-1, 0.5, 2)
        hi = lo + rng.uniform(0.01, 0.8, 2)
        ref = shapely.LineString([a, b]).distance(shapely.box(*lo, *hi))
        assert float(segment_box_distance(a, b, lo, hi)) == pytest.approx(ref, abs=1e-14)
    # Inside a box (no edge crossed), along an edge, through a corner: all 0.
    assert segment_box_distance((0.2, 0.2), (0.3, 0.3), (0, 0), (1, 1)) == 0.0
    assert segment_box_distance((-1, 0), (2, 0), (0, 0), (1, 1)) == 0.0
    assert segment_box_distance((-1, 1), (1, -1), (0, 0), (1, 1)) == 0.0
    assert segment_box_distance((-1, 0.5), (-0.25, 0.5), (0, 0), (1, 1)) == 0.25
    assert point_segment_distance(0, 1, -1, 0, 1, 0) == 1.0


# ------------------------------------------------------------------------- known configurations


def two_arm_world(la, ba, ra, lb, bb, rb, circles=(), boxes=()):
    return World([(la, ba, ra), (lb, bb, rb)], circles, boxes)


def test_crossing_arms_collide_and_separated_arms_do_not():
    # A: along the x axis from the origin; B: comes down from (0.5, 1) across it.
    w = two_arm_world([0.5, 0.5], (0, 0), 0.01, [0.5, 0.75], (0.6, 1.0), 0.01)
    q_cross = [0.0, 0.0, -90.0, 0.0]
    assert oracle_in_collision(w, q_cross)[0]
    assert oracle_clearance(w, q_cross)[0] == pytest.approx(-0.02, abs=1e-15)
    # Pull B's second link up (bend its elbow): the tip now stays above A.
    q_apart = [0.0, 0.0, -90.0, 90.0]
    c = oracle_clearance(w, q_apart)[0]
    pts = w.joint_points(q_apart)
    brute = min(np.min(np.linalg.norm(dense(*pts[0][0, k:k + 2], 801)[:, None]
                                      - dense(*pts[1][0, m:m + 2], 801)[None], axis=-1))
                for k in range(2) for m in range(2)) - 0.02
    assert c == pytest.approx(0.48, abs=1e-12)
    assert c <= brute + 1e-15 and brute - c < 1e-3
    assert not oracle_in_collision(w, q_apart)[0]
    # A swing of B's elbow from apart to crossing: the path collides, and the oracle proves it.
    assert oracle_path_collides(w, [q_apart, q_cross])
    assert not oracle_path_is_free(w, [q_apart, q_cross])


def test_non_adjacent_links_of_one_arm_collide_and_adjacent_ones_never_do():
    w = World([([0.5, 0.5, 0.5], (0, 0), 0.05)])
    folded = [0.0, 180.0, 180.0]  # the arm folds back onto itself: link 2 lies on link 0
    assert oracle_clearance(w, folded)[0] == pytest.approx(-0.1)  # -2 r: the capsules overlap
    assert oracle_in_collision(w, folded)[0]
    assert w.pair_names()[-1] == "arm 0 link 0 / arm 0 link 2"
    # two links share a joint: folded flat they are the joint limits' business, not a contact
    two = World([([0.5, 0.5], (0, 0), 0.05)])
    assert oracle_clearance(two, [0.0, 180.0])[0] == math.inf
    assert not oracle_in_collision(two, [0.0, 180.0])[0]


@pytest.mark.parametrize("gap, colliding", [(0.0, True), (1e-9, False), (-1e-9, True)])
def test_parallel_capsules_touching_exactly_count_as_collision(gap, colliding):
    """Two horizontal arms, one above the other; centre lines 0.25 + gap apart, radii 0.125
    each, so the capsules touch exactly at gap 0."""
    w = two_arm_world([0.5, 0.5], (0.0, 0.0), 0.125, [0.75, 0.5], (0.25, 0.25 + gap), 0.125)
    q = [0.0, 0.0, 0.0, 0.0]
    c = oracle_clearance(w, q)[0]
    assert c == pytest.approx(gap, abs=1e-15)
    assert bool(oracle_in_collision(w, q)[0]) is colliding
    if gap == 0.0:
        assert c == 0.0  # exact: binary fractions


def test_two_arms_whose_tips_touch_exactly():
    """Arm A's tip reaches (1, 0), arm B (base (2.25, 0), pointing back) reaches (1.25, ~0);
    radii 0.125 + 0.125 = 0.25 = the tip gap: touching, hence a collision."""
    w = two_arm_world([0.5, 0.5], (0, 0), 0.125, [0.5, 0.5], (2.25, 0.0), 0.125)
    q_touch = np.array([0.0, 0.0, 180.0, 0.0])
    assert oracle_clearance(w, q_touch)[0] == 0.0
    assert oracle_in_collision(w, q_touch)[0]
    # Both arms turn the same way through it: the tips pass each other tangentially, closest
    # (touching) at s = 0.5 and apart on both sides.
    qa = np.array([-10.0, 0.0, 170.0, 0.0])
    qb = np.array([10.0, 0.0, 190.0, 0.0])
    assert oracle_clearance(w, qa)[0] > 0.0 and oracle_clearance(w, qb)[0] > 0.0
    lo, hi = oracle_path_min_clearance(w, [qa, qb])
    assert hi == 0.0 and lo <= 0.0 and lo > -2e-9
    assert oracle_path_collides(w, [qa, qb])
    assert not oracle_path_is_free(w, [qa, qb])
    problems = oracle_path_problems(w, [qa, qb])
    assert problems and "touches or collides" in problems[0]
    # Move B's base out by 1 µm: free, with the minimum bracketed at 1 µm, the closest at s=0.5.
    w2 = two_arm_world([0.5, 0.5], (0, 0), 0.125, [0.5, 0.5], (2.25 + 1e-6, 0.0), 0.125)
    r = w2.segment_min_clearance(qa, qb, tol=1e-10)
    assert r.lower > 0.0 and r.upper - r.lower <= 1e-10 + w2.slack
    assert r.upper == pytest.approx(1e-6, abs=1e-12)
    np.testing.assert_allclose(r.q_at_upper, [0.0, 0.0, 180.0, 0.0], atol=1e-9)
    assert oracle_path_is_free(w2, [qa, qb])
    assert oracle_path_problems(w2, [qa, qb]) == []


def test_touching_between_grid_points_is_never_called_free():
    """The tips touch at s = 1/3 (not a dyadic point the search evaluates): the oracle must not
    call the segment free; its bracket contains 0 within the float slack."""
    w = two_arm_world([0.5, 0.5], (0, 0), 0.125, [0.5, 0.5], (2.25, 0.0), 0.125)
    qa = np.array([-10.0, 0.0, 170.0, 0.0])
    qb = np.array([20.0, 0.0, 200.0, 0.0])
    lo, hi = oracle_path_min_clearance(w, [qa, qb])
    assert lo <= 0.0 <= hi + 1e-15 and hi - lo < 2e-9
    assert not oracle_path_is_free(w, [qa, qb])


def wrapped_arm():
    """A 7-link arm wrapped around a circle of radius 0.3 at the origin: its joints lie on a
    circle of radius 0.4 (a regular heptagon's sides, as links; the base on the wrap)."""
    n, R = 7, 0.4
    side = 2 * R * math.sin(math.pi / n)
    links = np.full(n, side)
    base = (R, 0.0)
    # The first link leaves the base at 90 + 180/n degrees; every joint turns by 360/n.
    q = np.array([90.0 + 180.0 / n] + [360.0 / n] * (n - 1))
    return links, base, q


def test_seven_link_arm_wrapping_an_obstacle_matches_brute_force():
    links, base, q = wrapped_arm()
    r_link = 0.01
    w = World([(links, base, r_link)], circles=[(0.0, 0.0, 0.3)], boxes=[(0.45, -0.05, 0.6, 0.05)])
    pts = w.joint_points(q)[0][0]
    # The chain closes on itself around the circle (a heptagon).
    np.testing.assert_allclose(pts[-1], pts[0], atol=1e-12)
    np.testing.assert_allclose(np.linalg.norm(pts, axis=1), 0.4, atol=1e-12)
    # Exact: the nearest point of every side to the centre is its midpoint, at 0.4 cos(π/7);
    # the box's left side is at 0.45 while the heptagon's rightmost point is the base (0.4, 0).
    want_circle = 0.4 * math.cos(math.pi / 7) - 0.3 - r_link
    want_box = 0.45 - 0.4 - r_link
    # The closed chain touches itself: the last link ends where the first begins (links 0 and
    # 6 share the base point), a self-collision of depth 2 r_link.
    c = oracle_clearance(w, q)[0]
    assert c == pytest.approx(-2.0 * r_link, abs=1e-12)
    pc = w.pair_clearances(q)[0]
    names = w.pair_names()
    assert names[int(np.argmin(pc))] == "arm 0 link 0 / arm 0 link 6"
    obstacle_cols = [i for i, nm in enumerate(names) if "circle" in nm or "box" in nm]
    assert pc[obstacle_cols].min() == pytest.approx(min(want_circle, want_box), abs=1e-14)
    circle_cols = [i for i, nm in enumerate(names) if "circle" in nm]
    assert pc[circle_cols].min() == pytest.approx(want_circle, abs=1e-14)
    # Brute force over dense link points.
    brute = min(np.min(np.linalg.norm(dense(pts[k], pts[k + 1]), axis=1)) - 0.3 - r_link
                for k in range(7))
    assert pc[circle_cols].min() <= brute + 1e-15 and brute - pc[circle_cols].min() < 1e-6
    # Tighten the wrap (every joint turns a bit more): the arm closes in on the obstacle and
    # along the way touches it; the bracket holds the densely sampled minimum.
    q2 = q.copy()
    q2[1:] += 12.0
    lo, hi = oracle_segment_min_clearance(w, q, q2, tol=1e-8)
    sampled = oracle_clearance(w, dense(q, q2, 3001)).min()
    assert lo <= sampled + 1e-15 and hi <= sampled + 1e-15 and hi - lo <= 1e-8 + w.slack
    assert oracle_path_collides(w, [q, q2]) == (hi <= 0.0)


def test_segment_bracket_holds_the_dense_minimum_on_random_multi_arm_scenes():
    rng = np.random.default_rng(11)
    for trial in range(24):
        na, nb = rng.integers(2, 8, 2)
        w = two_arm_world(rng.uniform(0.05, 0.25, na), (-0.4, 0.0), 0.01,
                          rng.uniform(0.05, 0.25, nb), (0.4, 0.0), 0.01,
                          circles=[(0.0, 0.5, 0.1)], boxes=[(-0.1, -0.7, 0.1, -0.4)])
        qa = rng.uniform(-180, 180, na + nb)
        qb = qa + rng.normal(0.0, 20.0, na + nb)
        r = w.segment_min_clearance(qa, qb, tol=1e-8)
        s = np.linspace(0, 1, 4001)
        sampled = w.clearance(qa + s[:, None] * (qb - qa)).min()
        assert r.lower <= sampled + 1e-15, trial
        assert r.upper <= sampled + 1e-15, trial  # the search finds at least the samples' min
        assert not r.exhausted and r.upper - r.lower <= 1e-8 + w.slack
        # upper is an exact clearance at a real configuration on the segment.
        assert w.clearance(r.q_at_upper)[0] == pytest.approx(r.upper, abs=1e-15)
        assert oracle_path_is_free(w, [qa, qb]) == (r.lower > 0.0) or abs(r.lower) < 1e-8


def test_world_from_a_multi_arm_scenario_model():
    a = Arm(links=(0.5, 0.5), base=(0.0, 0.0), link_radius=0.125,
            joint_limits_deg=((-180.0, 180.0),) * 2)
    b = Arm(links=(0.5, 0.5, 0.25), base=(2.5, 0.0), link_radius=0.125,
            joint_limits_deg=((-180.0, 180.0),) * 3)
    s = Scenario(name="two", arm=a, more_arms=(b,), start_deg=(0.0, 0.0, 180.0, 0.0, 0.0),
                 goal_deg=(0.0, 0.0, 180.0, 0.0, 90.0),
                 obstacles=(Circle((0.0, 1.0), 0.2), Box((1.0, -1.0), (1.5, -0.75))))
    w1, w2 = as_world(s), as_world(s.arrays())
    assert w1.dof == w2.dof == 5
    q = np.array([s.start_deg, s.goal_deg, (0.0, 0.0, 180.0, 0.0, 0.0)])
    np.testing.assert_array_equal(w1.clearance(q), w2.clearance(q))
    # At the start the arms' tips are 0.25 apart (touching: radii 0.125 + 0.125).
    assert w1.clearance(q)[0] == 0.0 and oracle_in_collision(s, q[0])[0]
    assert oracle_in_collision(s, [0.0, 0.0, 180.0, 0.0, 200.0])[0]  # a joint limit


# ------------------------------------------------------------------------- agreement with 2-DOF


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_agrees_with_the_2dof_shapely_oracle(path):
    old = Oracle(path)
    w = old.world
    rng = np.random.default_rng(len(path.stem))
    q = rng.uniform(-180, 180, (400, 2))
    a, b = old.clearance(q), w.clearance(q)
    finite = np.isfinite(a)
    assert np.array_equal(finite, np.isfinite(b))
    np.testing.assert_allclose(a[finite], b[finite], rtol=0, atol=1e-13)
    np.testing.assert_array_equal(old.in_collision(q), w.in_collision(q))
    # Along paths: the old sampled bracket and the new proven one agree.
    for i in range(6):
        path_q = np.array([q[3 * i], q[3 * i + 1], q[3 * i + 2]])
        best, _, old_lower = old.min_distance_along(path_q, resolution_deg=0.05)
        lo, hi = oracle_path_min_clearance(w, path_q, tol=1e-8)
        if not math.isfinite(best):
            assert lo == hi == math.inf
            continue
        # proven below every sample; exact at a real configuration within the bracket's
        # tolerance of the true minimum, hence of the sampled one
        assert lo <= best + 1e-15 and hi <= best + 1e-8
        assert old_lower <= hi + 1e-12
        # Where the new oracle proves a path free, the old sampled check finds nothing; where
        # the old one samples a real collision, the new one never calls the path free.
        old_bad = bool(old.in_collision(old.densify(path_q, 0.05)).any())
        if oracle_path_is_free(w, path_q):
            assert not old_bad
        if old_bad:
            assert not oracle_path_is_free(w, path_q) and oracle_path_collides(w, path_q)
    scenario = load_scenario(path)
    ends = np.array([scenario.start_deg, scenario.goal_deg])
    assert (old.path_problems(ends) == []) == (oracle_path_problems(w, ends, scenario.start_deg,
                                                                  scenario.goal_deg) == [])
