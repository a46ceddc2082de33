"""Blocked edges are rejected early, and the probes that do it never change a verdict.

``edge_free`` probes ahead while conservative advancement crawls towards an obstacle
(``collision.probe_point``) and rejects the edge when a probe touches. These tests hold it to
conservative advancement alone (``edge_free_unprobed``) on edges planners meet -- near
obstacles, near another arm, near the arm itself, with and without a surgeon's clearance --
and on edges built to graze an obstacle without touching it, where the probes fire and must
find free space: a probe that rejected on anything but a real touch (say, within a millimetre)
fails them. Work is counted, not timed: blocked edges must cost far fewer distance evaluations,
accepted ones hardly more.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from xfuzzy_rrt.geometry.collision import (
    clearance_of_margin,
    config_free,
    edge_free,
    edge_free_two_link,
    edge_free_unprobed,
    effective_margin,
)
from xfuzzy_rrt.geometry.problem import arms_problem, single_arm_problem

RADIUS = 0.005


def _obstacles(rng, n, reach):
    rows = []
    for _ in range(n):
        r = rng.uniform(0.3, 1.1) * reach
        a = rng.uniform(-math.pi, math.pi)
        cx, cy = r * math.cos(a), r * math.sin(a)
        if rng.random() < 0.6:
            rows.append([0.0, cx, cy, rng.uniform(0.02, 0.06), 0.0])
        else:
            w, h = rng.uniform(0.03, 0.08, 2)
            rows.append([1.0, cx - w / 2, cy - h / 2, cx + w / 2, cy + h / 2])
    return np.array(rows)


def _one_arm(dof, seed, clearance):
    rng = np.random.default_rng(seed)
    links = np.full(dof, 0.3 / dof)
    margin = effective_margin(clearance)
    return single_arm_problem(links, (0.0, 0.0), RADIUS, _obstacles(rng, 6, 0.3),
                              np.tile([-180.0, 180.0], (dof, 1)), margin=margin), margin


def _two_arms(seed, clearance):
    rng = np.random.default_rng(seed)
    arms = [(np.array([0.12, 0.1, 0.08]), (-0.15, 0.0), RADIUS),
            (np.array([0.12, 0.1, 0.08]), (0.15, 0.0), RADIUS)]
    obstacles = []  # 2-6 cm, 12-32 cm in front of the arms: the bases stay clear
    for _ in range(6):
        cx, cy, r = rng.uniform(-0.3, 0.3), rng.uniform(0.12, 0.32), rng.uniform(0.01, 0.03)
        obstacles.append([0.0, cx, cy, r, 0.0] if rng.random() < 0.6
                         else [1.0, cx - r, cy - r, cx + r, cy + r])
    obstacles = np.array(obstacles)
    margin = effective_margin(clearance)
    return arms_problem(arms, obstacles, margin=margin), margin


CASES = [(kind, dof, clearance) for kind, dof in (("arm", 2), ("arm", 3), ("arm", 5),
                                                  ("arm", 7), ("arms", 6))
         for clearance in (0.0, 0.004)]


def _edges(P, margin, seed, count):
    """Free endpoints ``count`` times, 20-90 degrees apart: as a planner's edges near
    obstacles, often blocked."""
    rng = np.random.default_rng(seed)
    dof = P.links.shape[0]
    out = []
    for _ in range(200 * count):
        if len(out) == count:
            break
        qa = rng.uniform(-180.0, 180.0, dof)
        if not config_free(P, qa, margin):
            continue
        d = rng.normal(size=dof)
        qb = np.clip(qa + d / np.linalg.norm(d) * rng.uniform(20.0, 90.0), -180.0, 180.0)
        if config_free(P, qb, margin):
            out.append((qa, qb))
    if len(out) < count:
        raise RuntimeError(f"only {len(out)} of {count} free edges: the scene is too crowded")
    return out


def _problem(kind, dof, seed, clearance):
    return _one_arm(dof, seed, clearance) if kind == "arm" else _two_arms(seed, clearance)


@pytest.mark.parametrize("kind, dof, clearance", CASES)
def test_probes_never_change_a_verdict_of_conservative_advancement(kind, dof, clearance):
    blocked = accepted = 0
    work = {"probed": [0, 0], "plain": [0, 0]}  # [blocked, accepted]
    for seed in range(4):
        P, margin = _problem(kind, dof, seed, clearance)
        for qa, qb in _edges(P, margin, seed, 300):
            w0 = P.work[0]
            probed = edge_free(P, qa, qb, margin)
            w1 = P.work[0]
            plain = edge_free_unprobed(P, qa, qb, margin)
            w2 = P.work[0]
            assert probed == plain, (kind, dof, clearance, seed, qa, qb)
            work["probed"][plain] += w1 - w0
            work["plain"][plain] += w2 - w1
            blocked += not plain
            accepted += plain
    assert blocked >= 40 and accepted >= 40  # both verdicts well represented
    assert work["probed"][0] < 0.6 * work["plain"][0]
    assert work["probed"][1] <= 1.05 * work["plain"][1]


def _sweep_past_circle(gap, clearance=0.0, dof=2):
    """A straight arm of reach 0.35 m swinging its base joint from -30 to +30 degrees past a
    circle whose capsule clearance at 0 degrees is ``clear + gap`` (negative: it touches)."""
    margin = effective_margin(clearance)
    links = np.full(dof, 0.35 / dof)
    r = 0.02
    clear = clearance_of_margin(margin)
    cx = 0.35 + RADIUS + clear + gap + r
    P = single_arm_problem(links, (0.0, 0.0), RADIUS, np.array([[0.0, cx, 0.0, r, 0.0]]),
                           np.tile([-180.0, 180.0], (dof, 1)), margin=margin)
    qa = np.zeros(dof)
    qb = np.zeros(dof)
    qa[0], qb[0] = -30.0, 30.0
    return P, qa, qb, margin


@pytest.mark.parametrize("dof", [2, 3, 5])
@pytest.mark.parametrize("clearance", [0.0, 0.003])
@pytest.mark.parametrize("gap", [2e-4, 1e-5])
def test_an_edge_grazing_an_obstacle_stays_certified(dof, clearance, gap):
    P, qa, qb, margin = _sweep_past_circle(gap, clearance, dof)
    assert edge_free_unprobed(P, qa, qb, margin)
    assert edge_free(P, qa, qb, margin)
    if dof == 2:
        nan = np.nan
        assert edge_free_two_link(P, qa, qb, margin, nan, nan, nan, nan, True)[0]


@pytest.mark.parametrize("dof", [2, 3, 5])
@pytest.mark.parametrize("clearance", [0.0, 0.003])
def test_an_edge_into_an_obstacle_is_rejected_with_a_fraction_of_the_work(dof, clearance):
    P, qa, qb, margin = _sweep_past_circle(-2e-3, clearance, dof)
    w0 = P.work[0]
    assert not edge_free_unprobed(P, qa, qb, margin)
    plain = P.work[0] - w0
    w0 = P.work[0]
    assert not edge_free(P, qa, qb, margin)
    probed = P.work[0] - w0
    assert probed * 2 < plain


def test_the_two_link_check_without_probes_is_plain_advancement():
    P, qa, qb, margin = _sweep_past_circle(-2e-3)
    nan = np.nan
    w0 = P.work[0]
    assert not edge_free_two_link(P, qa, qb, margin, nan, nan, nan, nan, False)[0]
    off = P.work[0] - w0
    w0 = P.work[0]
    assert not edge_free_unprobed(P, qa, qb, margin)
    assert P.work[0] - w0 == off
