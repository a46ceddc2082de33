"""Self-collision: non-adjacent links of one arm, and the relative motion bound that certifies it.

A real arm of 5-7 links can fold into itself; links ``k`` and ``m >= k + 2`` of one arm count
as bodies to each other, exactly like an obstacle or another arm (configurations, certified
edges, the exact minimum clearance and the independent oracle of ``tests/exact_geometry.py``).
Adjacent links share a joint and never count, even folded flat at ±180°: the joint limits say
how far a joint folds. The certified step for a self pair uses the bound on the *relative*
motion of the two links (only the joints between them move one against the other,
``collision.self_pair_motion_bound``); a tip folding back and grazing an earlier link is the
tight case, where a bound weakened 1.05x certifies a collision
(``scripts/mutation_test.sh --weaken 1.05`` expects this file to fail then).
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from exact_geometry import World
from xfuzzy_rrt.geometry.clearance import path_min_clearance
from xfuzzy_rrt.geometry.collision import (
    CERT_MARGIN_M,
    clearance_kernel,
    config_free,
    edge_free,
    link_motion_bound,
    self_pair_motion_bound,
)
from xfuzzy_rrt.geometry.path_check import certify_path
from xfuzzy_rrt.geometry.problem import arms_problem
from xfuzzy_rrt.geometry.scenario import ScenarioError, load_scenario
from xfuzzy_rrt.geometry.signed import signed_clearance_kernel

SEVEN = np.full(7, 0.05)
RADIUS = 0.004
CURLED = np.array([0.0, 60.0, 60.0, 60.0, 60.0, 60.0, 60.0])  # six links close a hexagon
OPEN = np.array([0.0, 40.0, 40.0, 40.0, 40.0, 40.0, 40.0])
# Joint 5 swings link 5 (and 6) through link 0 and out again: both ends free.
THROUGH_A = np.array([0.0, 50.0, 50.0, 50.0, 50.0, 40.0, 50.0])
THROUGH_B = np.array([0.0, 50.0, 50.0, 50.0, 50.0, 80.0, 50.0])


class _Arrays:
    """The few ScenarioArrays members path_min_clearance / certify_path read."""

    def __init__(self, P):
        self.P = P
        self.links = P.links
        self.limits_deg = P.limits

    def problem(self, margin):
        return arms_problem([(self.links, (0.0, 0.0), RADIUS)], limits=self.limits_deg,
                            margin=margin)


def _seven():
    return arms_problem([(SEVEN, (0.0, 0.0), RADIUS)])


def _world():
    return World([(SEVEN, (0.0, 0.0), RADIUS)])


def test_a_seven_link_arm_curled_into_itself_is_refused():
    P = _seven()
    assert _world().in_collision(CURLED)[0]  # the oracle: links 0 and 5/6 meet
    assert clearance_kernel(P, CURLED) <= 0.0
    assert not config_free(P, CURLED, CERT_MARGIN_M)
    assert signed_clearance_kernel(P, CURLED) < 0.0
    # the open curl is free for both
    assert not _world().in_collision(OPEN)[0]
    assert config_free(P, OPEN, CERT_MARGIN_M)
    assert clearance_kernel(P, OPEN) == pytest.approx(float(_world().clearance(OPEN)[0]), abs=1e-12)


def test_an_edge_folding_a_seven_link_arm_through_itself_is_refused():
    P = _seven()
    w = _world()
    for q in (THROUGH_A, THROUGH_B):
        assert not w.in_collision(q)[0] and config_free(P, q, CERT_MARGIN_M)
    bracket = w.segment_min_clearance(THROUGH_A, THROUGH_B)
    assert bracket.upper < 0.0  # the oracle finds the self-contact between two free ends
    assert not edge_free(P, THROUGH_A, THROUGH_B, CERT_MARGIN_M)
    assert not edge_free(P, OPEN, CURLED, CERT_MARGIN_M)
    # the exact minimum clearance sees it too, and the path check says so
    arrays = _Arrays(P)
    exact = path_min_clearance(arrays, np.array([THROUGH_A, THROUGH_B]))
    assert exact.value_m == pytest.approx(bracket.upper, abs=1e-6)
    check = certify_path(arrays, np.array([THROUGH_A, THROUGH_B]))
    assert not check.certified and check.penetration_m > 0.0


def test_an_edge_that_keeps_the_seven_links_apart_is_certified_and_the_oracle_agrees():
    P = _seven()
    qa, qb = np.zeros(7), OPEN
    # decided against 0 (a proof that nothing touches), not bracketed to 1 nm: much cheaper
    assert _world().segment_min_clearance(qa, qb, threshold=0.0).lower > 0.0
    assert edge_free(P, qa, qb, CERT_MARGIN_M)


def test_adjacent_links_folded_flat_at_180_degrees_are_not_a_self_collision():
    # links 0 and 1 share joint 1: folded back onto each other they are the joint limits'
    # business, not a distance test (two-link arms are unchanged by self-collision)
    P = arms_problem([(np.array([0.1, 0.08]), (0.0, 0.0), 0.005)])
    assert clearance_kernel(P, np.array([0.0, 180.0])) == math.inf
    assert edge_free(P, np.array([0.0, 0.0]), np.array([0.0, 180.0]), CERT_MARGIN_M)
    # the same fold with a third link makes the pair (0, 2) meet
    P3 = arms_problem([(np.array([0.1, 0.08, 0.05]), (0.0, 0.0), 0.005)])
    assert clearance_kernel(P3, np.array([0.0, 180.0, 0.0])) <= 0.0


def _fold_graze(l1: float, gap: float, depth: float):
    """Three links; link 1 straight on link 0, link 2 (``gap`` shorter than link 1) folded back
    at about 180° so its tip passes the joint between links 0 and 1 at ``gap``; capsule radius
    ``gap (1 + depth) / 2`` makes that a collision ``gap depth`` deep between links 0 and 2."""
    links = np.array([0.1, l1, l1 - gap])
    return links, 0.5 * gap * (1.0 + depth)


SELF_CASES = [(l1, gap, depth, alpha, past)
              for l1 in (0.08, 0.15)
              for gap in (5e-5, 2e-4)
              for depth in (0.005, 0.05)
              for alpha, past in ((5.0, 1.0), (10.0, 0.7), (20.0, 1.3))]


@pytest.mark.parametrize("l1, gap, depth, alpha, past", SELF_CASES)
def test_self_pair_bound_refuses_a_folding_tip_grazing_its_own_arm(l1, gap, depth, alpha, past):
    links, radius = _fold_graze(l1, gap, depth)
    qa = np.array([0.0, 0.0, 180.0 - alpha])
    qb = np.array([0.0, 0.0, 180.0 + past * alpha])
    w = World([(links, (0.0, 0.0), radius)])
    bracket = w.segment_min_clearance(qa, qb)
    assert bracket.upper < 0.0 and bracket.lower > -1e-4  # a real, shallow self-collision
    P = arms_problem([(links, (0.0, 0.0), radius)], limits=np.tile([-360.0, 360.0], (3, 1)))
    assert not edge_free(P, qa, qb, CERT_MARGIN_M)


@pytest.mark.parametrize("l1", [0.08, 0.15])
def test_self_pair_bound_certifies_the_same_fold_passing_just_clear(l1):
    links, radius = _fold_graze(l1, 2e-4, -0.2)
    qa, qb = np.array([0.0, 0.0, 170.0]), np.array([0.0, 0.0, 190.0])
    assert World([(links, (0.0, 0.0), radius)]).segment_min_clearance(qa, qb).lower > 0.0
    P = arms_problem([(links, (0.0, 0.0), radius)], limits=np.tile([-360.0, 360.0], (3, 1)))
    assert edge_free(P, qa, qb, CERT_MARGIN_M)


def test_self_pair_bound_counts_only_the_joints_between_the_two_links():
    links = np.array([0.1, 0.08, 0.06, 0.05])
    qa = np.zeros(4)
    qb = np.array([30.0, -10.0, 20.0, 5.0])
    # joint 0 turns links 0..3 rigidly together: it does not move link 2 against link 0
    expected = (math.radians(10.0) * (0.08 + 0.06) + math.radians(20.0) * 0.06)
    assert self_pair_motion_bound(links, qa, qb, 0, 2) == pytest.approx(expected)
    assert self_pair_motion_bound(links, qa, qb, 0, 2) < (link_motion_bound(links, qa, qb, 0, 0)
                                                          + link_motion_bound(links, qa, qb, 2, 0))
    # and it is sound: the oracle's own relative speed never exceeds it, on random segments
    rng = np.random.default_rng(7)
    for _ in range(200):
        a, b = rng.uniform(-180, 180, 4), rng.uniform(-180, 180, 4)
        for k, m in ((0, 2), (0, 3), (1, 3)):
            own = World.self_pair_speed(links, np.radians(b - a), k, m)
            assert own <= self_pair_motion_bound(links, a, b, k, m) * (1.0 + 1e-12)


def test_self_pair_bound_is_the_folding_tips_speed():
    """Tight: the tip of link 2 moves at exactly the bound against link 0 when only joint 2
    turns, so a bound a few per cent lower is below a real speed."""
    links, _ = _fold_graze(0.08, 2e-4, 0.0)
    qa, qb = np.array([0.0, 0.0, 170.0]), np.array([0.0, 0.0, 190.0])
    bound = self_pair_motion_bound(links, qa, qb, 0, 2)
    assert bound == pytest.approx(links[2] * math.radians(20.0))


def test_a_scenario_whose_start_folds_into_itself_is_refused_with_one_line(tmp_path):
    q = ", ".join(f"{v:g}" for v in CURLED)
    f = tmp_path / "curled.toml"
    f.write_text(f'name = "curled"\n[arm]\nlinks = [{", ".join(["0.05"] * 7)}]\n'
                 f"link_radius = 0.004\n[start]\nq_deg = [{q}]\n"
                 f"[goal]\nq_deg = [0, 0, 0, 0, 0, 0, 0]\n")
    with pytest.raises(ScenarioError) as err:
        load_scenario(f)
    message = str(err.value)
    assert "self-collision" in message and "start" in message
    assert "\n" not in message
