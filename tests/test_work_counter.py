"""``Problem.work`` counts exact element distance evaluations, and counting changes nothing.

The unit of the deterministic work count (issue 23): one per link-obstacle pair, per link pair
of two arms and per non-adjacent link pair of one arm, each time ``clearance_kernel`` (hence
``config_free``) or a stop of ``edge_free`` measures them.
"""

from __future__ import annotations

import numpy as np

from xfuzzy_rrt.geometry.collision import (
    CERT_MARGIN_M,
    clearance_kernel,
    config_free,
    edge_free,
    n_distance_pairs,
)
from xfuzzy_rrt.geometry.problem import arms_problem, single_arm_problem
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.geometry.signed import n_elements
from tests.conftest import FIXTURES

OBSTACLES = np.array([[0.0, 0.0, 0.45, 0.05, 0.0], [1.0, -0.05, -0.4, 0.05, -0.3]])
# arm 0: 3 links (one self pair, (0, 2)); arm 1: 2 links (none); arm 2: 4 links ((0,2) (0,3) (1,3))
ARMS = [(np.array([0.1, 0.08, 0.06]), (-0.3, 0.0), 0.005),
        (np.array([0.12, 0.1]), (0.3, 0.0), 0.005),
        (np.array([0.05, 0.05, 0.05, 0.05]), (0.0, -0.2), 0.004)]
PER_CONFIG = 9 * 2 + (3 * 2 + 3 * 4 + 2 * 4) + (1 + 3)


def _problem():
    return arms_problem(ARMS, OBSTACLES)


def test_one_clearance_costs_one_evaluation_per_pair_of_bodies():
    P = _problem()
    assert P.work[0] == 0
    assert n_distance_pairs(P) == PER_CONFIG
    q = np.zeros(9)
    clearance_kernel(P, q)
    assert P.work[0] == PER_CONFIG
    config_free(P, q, CERT_MARGIN_M)
    assert P.work[0] == 2 * PER_CONFIG
    # the exact-minimum search measures the same elements, plus one per link without obstacles
    assert n_elements(P) == 9 + (3 * 2 + 3 * 4 + 2 * 4) + (1 + 3)


def test_an_edge_costs_one_evaluation_per_pair_at_every_stop():
    P = _problem()
    qa = np.zeros(9)
    qb = np.full(9, 20.0)
    edge_free(P, qa, qb, CERT_MARGIN_M)
    stops, rest = divmod(int(P.work[0]), PER_CONFIG)
    assert rest == 0 and stops >= 2


def test_counting_never_changes_a_result():
    rng = np.random.default_rng(5)
    for _ in range(30):
        qa, qb = rng.uniform(-90, 90, 9), rng.uniform(-90, 90, 9)
        P0, P1 = _problem(), _problem()
        P1.work[0] = 10**15
        assert clearance_kernel(P0, qa) == clearance_kernel(P1, qa)
        assert edge_free(P0, qa, qb, CERT_MARGIN_M) == edge_free(P1, qa, qb, CERT_MARGIN_M)
        assert P1.work[0] - 10**15 == P0.work[0] > 0


def test_every_problem_bundle_starts_a_fresh_counter():
    a = load_scenario(FIXTURES / "arms" / "five-dof.toml").arrays()
    P1 = a.problem(CERT_MARGIN_M)
    clearance_kernel(P1, a.start_deg)
    assert P1.work[0] == n_distance_pairs(P1) == 5 * 2 + 6  # 5 links x 2 obstacles + 6 self pairs
    P2 = a.problem(CERT_MARGIN_M)
    assert P2.work[0] == 0 and P2.work is not P1.work
    assert P2.work.dtype == np.int64 and P2.work.shape == (1,)
    one = single_arm_problem(np.array([0.2, 0.1]), np.zeros(2), 0.0, OBSTACLES,
                             np.tile([-180.0, 180.0], (2, 1)))
    assert one.work[0] == 0 and n_distance_pairs(one) == 4


def test_the_clearance_travels_as_its_own_field_next_to_the_margin():
    a = load_scenario(FIXTURES / "arms" / "five-dof.toml").arrays()
    P = a.problem(CERT_MARGIN_M)
    assert P._fields[-3:] == ("margin", "clearance", "work")
    assert P.margin == CERT_MARGIN_M and P.clearance == 0.0
    P = a.problem(CERT_MARGIN_M + 0.002)
    assert P.clearance == (CERT_MARGIN_M + 0.002) - CERT_MARGIN_M
    assert a.problem(CERT_MARGIN_M, clearance=0.001).clearance == 0.001
    assert a.problem(0.5 * CERT_MARGIN_M).clearance == 0.0
