"""Stop records (geometry/collision.py ``node_stop_into``, ``edge_free_rows``; planners/extend.py).

An N-joint planner's node check measures the new node's clearances into a row of its tree, and
the certified check of the edge to it takes its first stop (the node it grows from) and its
last (the new node) from those rows instead of measuring them again. That is only sound if a
record holds exactly what the stop would measure, and only for the node it was measured at:
these tests hold the check with records to the plain one, edge by edge (verdict and work), and
whole plans to plans made without records; a record that lies must change a verdict (so the
equalities above are not vacuous), and a new run must never read the last run's rows.
"""

from __future__ import annotations

import numpy as np
import pytest

from xfuzzy_rrt.geometry.collision import (
    clearance_into,
    effective_margin,
    edge_free_into,
    edge_free_rows,
    node_stop_into,
    stop_width,
)
from xfuzzy_rrt.geometry.problem import arms_problem, single_arm_problem, stop_record_width
from xfuzzy_rrt.geometry.scenario import ScenarioArrays
from xfuzzy_rrt.planners.api import plan_scenario
from xfuzzy_rrt.planners.tree import add_node, make_tree
from xfuzzy_rrt.scenarios.generate import generate_nd

from test_blocked_edges import RADIUS, _edges, _problem


def _buffers(P):
    n = P.links.shape[0]
    return np.zeros((n, 4)), np.zeros(n), np.zeros((n, n))


def _case(kind, dof, seed, clearance):
    """``_problem``'s scenes, and two without obstacles, where every step is a link pair's:
    one arm's non-adjacent links (``self``) or two arms' links (``pairs``)."""
    if kind == "self":
        return single_arm_problem(np.full(dof, 0.3 / dof), (0.0, 0.0), RADIUS,
                                  np.zeros((0, 5)), np.tile([-180.0, 180.0], (dof, 1)),
                                  margin=effective_margin(clearance)), effective_margin(clearance)
    if kind == "pairs":
        arms = [(np.array([0.12, 0.1, 0.08]), (-0.1, 0.0), RADIUS),
                (np.array([0.12, 0.1, 0.08]), (0.1, 0.0), RADIUS)]
        margin = effective_margin(clearance)
        return arms_problem(arms, np.zeros((0, 5)), margin=margin), margin
    return _problem(kind, dof, seed, clearance)


CASES = [(kind, dof, clearance) for kind, dof in (("arm", 3), ("arm", 5), ("arm", 7),
                                                  ("arms", 6), ("self", 5), ("pairs", 6))
         for clearance in (0.0, 0.004)]


@pytest.mark.parametrize("sizes", [[3], [5], [7], [3, 3], [2, 2, 2], [4, 3], [1, 1], [2]])
def test_the_record_width_is_the_same_in_python_and_in_compiled_code(sizes):
    arms = [(np.full(n, 0.1), (0.3 * a, 0.0), 0.005) for a, n in enumerate(sizes)]
    P = arms_problem(arms, np.array([[0.0, 0.0, 0.5, 0.05, 0.0]]))
    first = np.concatenate([[0], np.cumsum(sizes)])
    expected = stop_width(P) if sum(sizes) > 2 else 0  # two joints keep no stop records
    assert stop_record_width(first) == expected
    if sizes == [3, 3]:  # 1 flag + 6 links + 9 pairs across the arms + 1 per arm within
        assert expected == 1 + 6 + 9 + 2


@pytest.mark.parametrize("kind, dof, clearance", CASES)
def test_a_node_check_that_keeps_a_record_measures_what_the_plain_one_does(kind, dof, clearance):
    P, margin = _case(kind, dof, 11, clearance)
    seg, mks, msf = _buffers(P)
    rows = np.full((4, stop_width(P)), np.nan)
    rng = np.random.default_rng(5)
    for i in range(60):
        q = rng.uniform(-180.0, 180.0, dof)
        before = int(P.work[0])
        plain = clearance_into(P, q, seg)
        plain_work = int(P.work[0]) - before
        kept = node_stop_into(P, q, seg, mks, msf, rows, i % 3)
        assert kept == plain and int(P.work[0]) - before == 2 * plain_work
        assert rows[i % 3, 0] == 1.0  # complete: every value finite
        measured = rows[i % 3, 1:] if P.obstacles.shape[0] else rows[i % 3, 1 + dof:]
        assert measured.min() == plain  # the values the clearance is the minimum of


@pytest.mark.parametrize("kind, dof, clearance", CASES)
def test_an_edge_taking_its_ends_from_records_has_the_plain_verdict_and_work(kind, dof,
                                                                              clearance):
    P, margin = _case(kind, dof, 5, clearance)
    seg, mks, msf = _buffers(P)
    rows = np.full((2, stop_width(P)), np.nan)
    verdicts = []
    for qa, qb in _edges(P, margin, 7, 60):
        w0 = int(P.work[0])
        plain = edge_free_into(P, qa, qb, margin, seg, mks, msf)
        plain_work = int(P.work[0]) - w0
        node_stop_into(P, qa, seg, mks, msf, rows, 0)
        node_stop_into(P, qb, seg, mks, msf, rows, 1)
        for ra, rb in ((0, 1), (0, -1), (-1, 1)):
            w1 = int(P.work[0])
            assert edge_free_rows(P, qa, qb, margin, seg, mks, msf, rows, ra, rb) == plain
            assert int(P.work[0]) - w1 == plain_work
        verdicts.append(plain)
    assert any(verdicts)
    if kind != "self":  # random 20-90 deg moves seldom fold an arm onto itself
        assert not all(verdicts)  # free and blocked edges both met


def test_an_edge_reads_a_complete_record_and_measures_an_incomplete_one():
    P, margin = _problem("arm", 5, 3, 0.0)
    seg, mks, msf = _buffers(P)
    blocked = [(qa, qb) for qa, qb in _edges(P, margin, 7, 40)
               if not edge_free_into(P, qa, qb, margin, seg, mks, msf)]
    qa, qb = blocked[0]
    rows = np.full((2, stop_width(P)), 1e3)  # a lie: a metre of clearance everywhere
    rows[:, 0] = np.nan  # ... in records not marked complete: measured, not read
    assert not edge_free_rows(P, qa, qb, margin, seg, mks, msf, rows, 0, 1)
    rows[:, 0] = 1.0  # marked complete: the first stop is read, and it steps past the block
    assert edge_free_rows(P, qa, qb, margin, seg, mks, msf, rows, 0, -1)


def test_a_new_run_never_reads_the_last_runs_records():
    P, margin = _problem("arm", 5, 3, 0.0)
    w = stop_width(P)
    T = make_tree(16, np.tile([-180.0, 180.0], (5, 1)), stops=w)
    assert T.link_clear.shape == (17, w)
    T.link_clear[:] = 1.0  # every row "complete", as a previous run may leave them
    add_node(T, np.zeros(5), -1)  # the root of a new run
    assert np.isnan(T.link_clear[0, 0]) and np.isnan(T.link_clear[16, 0])  # root and goal
    assert make_tree(16, np.tile([-180.0, 180.0], (5, 1))).link_clear.shape == (1, 2)


def test_a_tree_keeps_no_records_that_would_outgrow_their_memory_cap():
    limits = np.tile([-180.0, 180.0], (21, 1))  # three 7-joint arms: 214 columns
    w = stop_record_width(np.array([0, 7, 14, 21]))
    assert w == 1 + 21 + 3 * 15 + 3 * 49
    assert make_tree(20_008, limits, stops=w).link_clear.shape == (1, 2)  # 34 MB: measured
    assert make_tree(1_000, limits, stops=w).link_clear.shape == (1_001, w)  # 1.7 MB: kept


@pytest.mark.parametrize("dof, arms", [(3, 1), (5, 1), (7, 1), (3, 2)])
def test_plans_with_stop_records_are_the_plans_without_them(monkeypatch, dof, arms):
    scenario = generate_nd(4242, 0, dof=dof, arms=arms).scenario
    assert ScenarioArrays.from_scenario(scenario).stop_width > 0

    def runs():
        out = []
        for planner in ("fuzzy-rrt", "rrt:tuned", "rrt"):
            for seed in range(3):
                r = plan_scenario(scenario, planner, seed=seed)
                out.append((planner, seed, r.success, r.iterations, r.work,
                            np.asarray(r.path_deg).tobytes(),
                            np.asarray(r.tree_nodes_deg).tobytes()))
        return out

    with_records = runs()
    monkeypatch.setattr(ScenarioArrays, "stop_width", property(lambda self: 0))
    assert runs() == with_records

