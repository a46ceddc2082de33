"""certify_path vouches only for paths that are free everywhere and measures how deep bad ones go."""

from __future__ import annotations

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import FIXTURES, PROJECT, thin_box
from exact_geometry import Oracle
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.collision import clearance
from xfuzzy_rrt.geometry.path_check import (
    MIN_CLEARANCE_TOL_M,
    certify_path,
    signed_clearance,
    signed_segment_obstacle_dist,
)
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.rrt import plan_rrt

SCENARIOS = sorted((FIXTURES / "scenarios").glob("*.toml")) + sorted(
    (PROJECT / "xfuzzy_rrt" / "data" / "scenarios").glob("*.toml"))
PAPERISH = FIXTURES / "scenarios" / "two-circles.toml"


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_rrt_paths_are_certified_with_zero_penetration_and_the_oracle_agrees(path):
    s = load_scenario(path)
    oracle = Oracle(path)
    for seed in range(5):
        r = plan_rrt(s, seed=seed)
        check = certify_path(s.arrays(), r.path_deg)
        assert (check.certified, check.penetration_m, check.worst_segment) == (True, 0.0, -1)
        assert oracle.path_problems(r.path_deg) == []
        if not oracle.circles and not oracle.boxes:
            assert check.min_clearance_m == np.inf
            continue
        # The exact minimum: attained where it says, and nothing on the path comes closer.
        assert oracle.clearance(np.array(check.min_config_deg))[0] == pytest.approx(
            check.min_clearance_m, abs=1e-12)
        assert float(np.min(oracle.clearance(oracle.densify(r.path_deg, 0.02)))) >= \
            check.min_clearance_m - MIN_CLEARANCE_TOL_M
        assert r.min_clearance_m == check.min_clearance_m


def test_a_straight_path_through_obstacles_is_flagged_with_its_depth():
    s = load_scenario(PAPERISH)
    oracle = Oracle(PAPERISH)
    path = np.array([s.start_deg, s.goal_deg])
    assert oracle.path_problems(path), "fixture: the straight line must collide"
    check = certify_path(s.arrays(), path)
    assert not check.certified
    assert check.penetration_m > 0.0 and check.worst_segment == 0


def test_the_worst_segment_is_the_one_that_goes_deepest(tmp_path):
    file = thin_box(tmp_path)
    s = load_scenario(file)
    # Unfold away from the box, sweep straight through it, fold again: only segment 1 collides.
    path = np.array([[-60.0, 150.0], [-60.0, 0.0], [60.0, 0.0], [60.0, 150.0]])
    oracle = Oracle(file)
    assert [bool(oracle.path_problems(path[i:i + 2])[-1:] and "colliding" in
                 oracle.path_problems(path[i:i + 2])[-1]) for i in range(3)] == [False, True, False]
    check = certify_path(s.arrays(), path)
    assert not check.certified and check.worst_segment == 1


def test_shallow_penetration_matches_the_oracle_clearance(tmp_path):
    # The box face sits 3 mm from the arm's centre line at 0 deg: a 5 mm capsule goes 2 mm in.
    file = thin_box(tmp_path, ylo=0.003, yhi=0.007)
    s = load_scenario(file)
    oracle = Oracle(file)
    path = np.array([[-1.0, 0.0], [0.0, 0.0]])  # deepest at 0 deg, on the face side only
    check = certify_path(s.arrays(), path)
    dense = oracle.densify(path, 0.001)
    deepest = -float(np.min(oracle.clearance(dense)))
    assert not check.certified
    assert check.penetration_m == pytest.approx(0.002, abs=1e-4)
    assert check.penetration_m == pytest.approx(deepest, abs=1e-4)


def test_deep_penetration_does_not_saturate_at_the_link_radius(tmp_path):
    # Unsigned clearance bottoms out at -link_radius once the centre line touches; the signed
    # depth keeps going: centre line through the middle of a 4 mm box -> 2 mm + 5 mm.
    file = thin_box(tmp_path)
    s = load_scenario(file)
    a = s.arrays()
    assert clearance(a, [0.0, 0.0]) == pytest.approx(-0.005)
    assert signed_clearance(a, [0.0, 0.0]) == pytest.approx(-0.007)
    check = certify_path(a, np.array([[-60.0, 0.0], [60.0, 0.0]]))
    assert check.penetration_m == pytest.approx(0.007, abs=1e-4)


def test_a_vertex_outside_the_joint_limits_is_not_certified_even_without_penetration():
    s = load_scenario(FIXTURES / "scenarios" / "boxes-and-circle.toml")  # joint 1 up to 175
    inside = np.array([[160.0, 90.0], [170.0, 90.0]])
    check = certify_path(s.arrays(), inside)
    assert (check.certified, check.penetration_m, check.worst_segment) == (True, 0.0, -1)
    path = np.array([[160.0, 90.0], [170.0, 90.0], [178.0, 90.0]])
    check = certify_path(s.arrays(), path)
    assert not check.certified and check.penetration_m == 0.0 and check.worst_segment == 1
    assert check.limits_vertex == 2 and check.describe() == "vertex 2 is outside the joint limits"


def test_an_empty_path_is_not_certified_and_a_malformed_one_is_rejected():
    a = load_scenario(PAPERISH).arrays()
    empty = certify_path(a, np.zeros((0, 2)))
    assert (empty.certified, empty.penetration_m, empty.worst_segment) == (False, 0.0, -1)
    assert np.isnan(empty.min_clearance_m) and empty.describe() == "no path to certify"
    with pytest.raises(InputError):
        certify_path(a, np.zeros((3, 3)))
    with pytest.raises(InputError):
        certify_path(a, np.array([[0.0, np.nan], [1.0, 1.0]]))


def _minkowski_signed_distance(a, b, poly):
    """Independent: signed distance of segment AB to a convex polygon via shapely.

    Translating AB by t hits ``poly`` iff t lies in ``poly ⊕ (-AB)``, the convex hull of the
    polygon's corners shifted by -A and -B. The segment meets the polygon iff the origin is in
    it; the distance (or the penetration depth) is the distance from the origin to its boundary.
    """
    corners = np.asarray(poly.exterior.coords)[:-1]
    hull = shapely.MultiPoint(np.vstack([corners - a, corners - b])).convex_hull
    origin = shapely.Point(0.0, 0.0)
    d = hull.exterior.distance(origin)
    return -d if hull.contains(origin) or hull.exterior.distance(origin) == 0.0 else d


# Micrometre grid: shapely mis-measures segments of subnormal length, which are not our concern.
COORD = st.floats(-1.0, 1.0, allow_nan=False).map(lambda v: round(v, 6))


@settings(max_examples=300, deadline=None)
@given(
    coords=st.lists(COORD, min_size=8, max_size=8),
)
def test_signed_box_distance_equals_the_minkowski_difference_oracle(coords):
    ax, ay, bx, by, x0, y0, w, h = coords
    w, h = abs(w) + 0.05, abs(h) + 0.05
    row = np.array([1.0, x0, y0, x0 + w, y0 + h])
    ours = signed_segment_obstacle_dist(ax, ay, bx, by, row)
    theirs = _minkowski_signed_distance(np.array([ax, ay]), np.array([bx, by]),
                                        shapely.box(x0, y0, x0 + w, y0 + h))
    assert ours == pytest.approx(theirs, abs=1e-9)


@settings(max_examples=200, deadline=None)
@given(coords=st.lists(COORD, min_size=6, max_size=6))
def test_signed_circle_distance_is_centre_distance_minus_radius(coords):
    ax, ay, bx, by, cx, cy = coords
    r = 0.3
    row = np.array([0.0, cx, cy, r, 0.0])
    seg = shapely.LineString([(ax, ay), (bx, by)]) if (ax, ay) != (bx, by) else shapely.Point(ax, ay)
    expected = seg.distance(shapely.Point(cx, cy)) - r
    assert signed_segment_obstacle_dist(ax, ay, bx, by, row) == pytest.approx(expected, abs=1e-12)


CIRCLE_ON_THE_SWEEP = """
name = "circle-on-the-sweep"
[arm]
links = [0.18, 0.12]
link_radius = 0.005
joint_limits_deg = [[-180.0, 180.0], [-180.0, 180.0]]
[start]
q_deg = [0.0, 0.0]
[goal]
q_deg = [6.0, 0.0]
[[obstacles]]
type = "circle"
center = [0.25, 0.01]
radius = 0.002
"""


def test_min_clearance_is_exact_between_samples_and_says_where(tmp_path):
    # The straight arm sweeps 0 -> 6 deg; its centre line crosses the circle's centre at
    # atan2(0.01, 0.25) = 2.2906 deg (s = 0.382, no dyadic point of the segment): the exact
    # signed clearance there is -(radius + link radius) = -7 mm. A scan at 0.1 mm of arm motion
    # is only good to ~0.05 mm; the branch and bound proves its value to 0.1 um.
    file = tmp_path / "sweep.toml"
    file.write_text(CIRCLE_ON_THE_SWEEP)
    s = load_scenario(file)
    check = certify_path(s.arrays(), np.array([s.start_deg, s.goal_deg]))
    assert not check.certified and check.worst_segment == 0 and check.min_segment == 0
    assert check.min_clearance_m == pytest.approx(-0.007, abs=MIN_CLEARANCE_TOL_M)
    assert check.penetration_m == -check.min_clearance_m
    assert check.min_config_deg[0] == pytest.approx(np.degrees(np.arctan2(0.01, 0.25)), abs=1e-5)
    assert check.min_config_deg[1] == 0.0
    assert check.describe() == ("segment 0 penetrates an obstacle 7 mm deep at q = "
                                f"({check.min_config_deg[0]:.6g}, 0) deg")


def test_min_clearance_of_a_free_path_is_the_oracle_minimum(tmp_path):
    # Same sweep, circle moved 2 cm off the arm's reach: free, and the minimum lies at the
    # sweep's end (the closest approach); nothing the oracle samples comes closer.
    file = tmp_path / "far.toml"
    file.write_text(CIRCLE_ON_THE_SWEEP.replace("center = [0.25, 0.01]", "center = [0.25, 0.04]"))
    s = load_scenario(file)
    oracle = Oracle(file)
    path = np.array([[0.0, 0.0], [3.7, 0.0], [3.7, -20.0], [-10.0, 5.0]])
    check = certify_path(s.arrays(), path)
    dense = float(np.min(oracle.clearance(oracle.densify(path, 0.001))))
    assert check.certified and check.penetration_m == 0.0
    assert dense >= check.min_clearance_m - MIN_CLEARANCE_TOL_M
    assert check.min_clearance_m == pytest.approx(dense, abs=1e-7)
    assert oracle.clearance(np.array(check.min_config_deg))[0] == pytest.approx(
        check.min_clearance_m, abs=1e-12)
