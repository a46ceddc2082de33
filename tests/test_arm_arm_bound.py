"""The arm-arm motion bound of the certified edge check: ``M_k + M_m`` for links of two arms.

Two links of different arms close in on each other at up to the sum of their speeds, each from
its own arm's joints. The case that pins it: two arms' tips meeting *head-on* along an edge
(each tip moving straight at the other at its full bound speed) and grazing past each other by
a hair. The distance then falls at almost exactly ``M_k + M_m`` and climbs again just as fast,
a V whose bottom is a few micrometres deep: an edge check whose step is even 5 % too long (a
bound weakened 1.05x, or ``max(M_k, M_m)`` instead of the sum) steps over the bottom from one
side to the other and certifies a colliding edge. Every case is checked to collide by the
independent oracle (``tests/exact_geometry.py``) first, so the refusals are of real
collisions. ``scripts/mutation_test.sh --weaken 1.05`` weakens this bound alone and expects
this file to fail.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from exact_geometry import World
from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M, edge_free, link_motion_bound
from xfuzzy_rrt.geometry.problem import arms_problem


def _head_on(la: float, lb: float, h: float, depth: float, past: float):
    """Arm A (one link ``la``) at ``(-la, 0)`` pointing +x, arm B (one link ``lb``) at
    ``(lb, h)`` pointing -x: their tips start ``h`` apart, one above the other, and both
    joints turn by ``past`` times the angle at which the tips are level, so that A's tip rises
    and B's falls, straight at each other, and they pass.
    They pass with a horizontal gap ``g``; capsule radii ``(g / 2)(1 + depth)`` make that a
    collision ``g depth`` deep. Returns (arms, qa, qb)."""
    # The angle where the tips are level: la sin(p) + lb sin(p) = h.
    p = math.asin(h / (la + lb))
    gap = la * (1.0 - math.cos(p)) + lb * (1.0 - math.cos(p))
    radius = 0.5 * gap * (1.0 + depth)
    end_deg = past * math.degrees(p)
    arms = [(np.array([la]), np.array([-la, 0.0]), radius),
            (np.array([lb]), np.array([lb, h]), radius)]
    return arms, np.array([0.0, 180.0]), np.array([end_deg, 180.0 + end_deg])


CASES = [(la, lb, h, depth, end)
         for la, lb in ((0.3, 0.3), (0.3, 0.15), (0.12, 0.25))
         for h in (0.006, 0.01, 0.02, 0.035)
         for depth in (0.002, 0.02)
         for end in (1.7, 2.6)]


def _world(arms):
    return World([(l, b, r) for l, b, r in arms])


@pytest.mark.parametrize("la, lb, h, depth, end", CASES)
def test_arm_arm_bound_refuses_two_tips_meeting_head_on(la, lb, h, depth, end):
    arms, qa, qb = _head_on(la, lb, h, depth, end)
    bracket = _world(arms).segment_min_clearance(qa, qb)
    lower, upper = bracket.lower, bracket.upper
    assert upper < 0.0  # the oracle finds the contact: a real collision
    assert lower > -1e-3  # and a grazing one (the hard case for a step)
    P = arms_problem(arms)
    assert not edge_free(P, qa, qb, CERT_MARGIN_M)


@pytest.mark.parametrize("la, lb, h, depth, end", CASES[:8])
def test_arm_arm_bound_certifies_the_same_tips_passing_just_clear(la, lb, h, depth, end):
    # The bound is not refusal by default: with radii leaving a gap of 10 % the same motions
    # are free (oracle) and certified.
    arms, qa, qb = _head_on(la, lb, h, -0.1, end)
    assert _world(arms).segment_min_clearance(qa, qb).lower > CERT_MARGIN_M
    assert edge_free(arms_problem(arms), qa, qb, CERT_MARGIN_M)


def test_arm_arm_bound_is_what_the_head_on_tips_need():
    """The closing speed of the head-on tips reaches 99 % of ``M_k + M_m`` (so a bound even
    a few per cent lower is below the true speed) and never exceeds it (soundness)."""
    arms, qa, qb = _head_on(0.3, 0.15, 0.02, 0.02, 2.6)
    w = _world(arms)
    P = arms_problem(arms)
    bound = (link_motion_bound(P.links, qa, qb, 0, 0) + link_motion_bound(P.links, qa, qb, 1, 1))
    s = np.linspace(0.0, 0.15, 3001)
    q = qa[None, :] + s[:, None] * (qb - qa)[None, :]
    pts = w.joint_points(q)
    tips = np.linalg.norm(pts[0][:, -1] - pts[1][:, -1], axis=1)
    speed = np.abs(np.diff(tips)) / np.diff(s)
    assert speed.max() <= bound * (1.0 + 1e-9)
    assert speed.max() >= 0.99 * bound
