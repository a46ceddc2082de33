"""Collision and clearance agree with an independent shapely oracle; edge checks are certified."""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import FIXTURES, shared_scenarios
from exact_geometry import Oracle
from xfuzzy_rrt.geometry.collision import (
    CERT_MARGIN_M,
    clearance,
    end_effector_obstacle,
    in_collision,
    segment_free,
)
from xfuzzy_rrt.geometry.scenario import load_scenario, scenario_from_dict

SCENARIOS = sorted((FIXTURES / "scenarios").glob("*.toml")) + shared_scenarios()


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_collision_agrees_with_shapely_on_random_configurations(path):
    s = load_scenario(path)
    a = s.arrays()
    oracle = Oracle(path)
    rng = np.random.default_rng(1234)
    qs = rng.uniform(-180.0, 180.0, size=(3000, 2))
    ours = np.array([clearance(a, q) for q in qs])
    theirs = oracle.clearance(qs)
    np.testing.assert_allclose(ours, theirs, rtol=0, atol=1e-12)
    ours_hit = np.array([in_collision(a, q) for q in qs])
    assert np.array_equal(ours_hit, oracle.in_collision(qs))
    if s.obstacles:
        assert 0 < ours_hit.sum() < len(qs) or s.name == "empty"


def test_joint_limits_count_as_collision():
    s = load_scenario(FIXTURES / "scenarios" / "boxes-and-circle.toml")
    a = s.arrays()
    assert in_collision(a, [178.0, 0.0])  # joint 1 limit is 175
    assert not segment_free(a, [170.0, 0.0], [178.0, 0.0])


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_end_effector_obstacle_distance_and_direction_match_shapely(path):
    s = load_scenario(path)
    a = s.arrays()
    oracle = Oracle(path)
    rng = np.random.default_rng(7)
    for q in rng.uniform(-180, 180, size=(300, 2)):
        d, ang = end_effector_obstacle(a, q)
        ee = shapely.Point(oracle.points(q)[0, -1])
        if not s.obstacles:
            assert d == math.inf and ang == 0.0
            continue
        best = (math.inf, None)
        for center, r in oracle.circles:
            dist = max(ee.distance(center) - r, 0.0)
            direction = math.atan2(center.y - ee.y, center.x - ee.x)
            best = min(best, (dist, direction), key=lambda t: t[0])
        for b in oracle.boxes:
            dist = ee.distance(b)
            p = shapely.shortest_line(ee, b).coords[-1]
            direction = math.atan2(p[1] - ee.y, p[0] - ee.x) if dist > 0 else None
            best = min(best, (dist, direction), key=lambda t: t[0])
        assert d == pytest.approx(best[0], abs=1e-12)
        assert 0.0 <= ang < 2 * math.pi
        if best[1] is not None and best[0] > 1e-9:
            diff = (ang - best[1]) % (2 * math.pi)
            assert min(diff, 2 * math.pi - diff) < 1e-9


def _grazing_scenario(penetration_m: float, obstacle: str = "circle"):
    """A straight arm (joint 2 = 0) swept from 44° to 46°; the obstacle sits on the 45.5° ray.

    With ``penetration_m > 0`` the link capsule overlaps the obstacle only around 45.5°, between
    the 1° samples 44°, 45°, 46°, and by at most ``penetration_m``. The box variant presents a
    corner to the tip (its sides are axis-aligned, the ray is diagonal).
    """
    links, r = (0.18, 0.12), 0.005
    reach = sum(links)
    phi = math.radians(45.5)
    if obstacle == "circle":
        radius = 0.03
        dist = reach + r + radius - penetration_m
        obs = {"type": "circle", "center": [dist * math.cos(phi), dist * math.sin(phi)],
               "radius": radius}
    else:
        dist = reach + r - penetration_m
        cx, cy = dist * math.cos(phi), dist * math.sin(phi)
        obs = {"type": "box", "min": [cx, cy], "max": [cx + 0.04, cy + 0.04]}
    data = {"name": "graze", "arm": {"links": list(links), "link_radius": r},
            "start": {"q_deg": [44.0, 0.0]}, "goal": {"q_deg": [46.0, 0.0]}, "obstacles": [obs]}
    return scenario_from_dict(data, "graze")


@pytest.mark.parametrize("obstacle", ["circle", "box"])
@pytest.mark.parametrize("penetration", [1e-4, 1e-6, 1e-8, 1e-11])
def test_edge_that_grazes_between_samples_is_rejected(obstacle, penetration):
    s = _grazing_scenario(penetration, obstacle)
    a = s.arrays()
    # A 1° sampled check sees nothing wrong ...
    for q1 in (44.0, 45.0, 46.0):
        assert clearance(a, [q1, 0.0]) > 0.0
    # ... but the arm does touch at 45.5°, and the certified check knows it.
    assert clearance(a, [45.5, 0.0]) <= 0.0
    assert not segment_free(a, [44.0, 0.0], [46.0, 0.0])
    assert not segment_free(a, [46.0, 0.0], [44.0, 0.0])


@pytest.mark.parametrize("obstacle", ["circle", "box"])
def test_edge_that_clears_by_a_hair_is_accepted(obstacle):
    s = _grazing_scenario(-20 * CERT_MARGIN_M, obstacle)  # 20 µm of clearance at the closest
    assert segment_free(s.arrays(), [44.0, 0.0], [46.0, 0.0])


def test_edge_within_the_margin_is_rejected_conservatively():
    s = _grazing_scenario(-0.5 * CERT_MARGIN_M)  # free by 0.5 µm: too close to certify
    assert not segment_free(s.arrays(), [44.0, 0.0], [46.0, 0.0])


ORACLES = {p.stem: (load_scenario(p).arrays(), Oracle(p)) for p in SCENARIOS}


@settings(max_examples=300, deadline=None)
@given(
    name=st.sampled_from(sorted(ORACLES)),
    qa=st.tuples(st.floats(-179, 179), st.floats(-179, 179)),
    delta=st.tuples(st.floats(-25, 25), st.floats(-25, 25)),
)
def test_certified_edges_never_contain_a_collision(name, qa, delta):
    arrays, oracle = ORACLES[name]
    qa = np.array(qa)
    qb = np.clip(qa + np.array(delta), -180, 180)
    dense = oracle.densify(np.array([qa, qb]), 0.01)
    colliding = oracle.in_collision(dense).any()
    free = segment_free(arrays, qa, qb)
    if colliding:
        assert not free
    if free:
        assert oracle.clearance(dense).min() > 0.0
