"""The two numbers the certified edge check rests on are conservative, for any arm.

``edge_free`` (conservative advancement) is only as sound as its two ingredients:

- the **motion bound** ``M_k`` (:func:`link_motion_bound`): no point of link *k* may move
  further than ``M_k * |Δs|`` while the joints travel ``Δs`` of the segment ``qa -> qb``;
- the **clearance**: it may never report more room than there is (the exact distance, here
  measured independently with shapely).

If either over-promises, even by a few per cent, the check can step over a thin obstacle. These
properties are checked on random arms (1-4 links, with a base offset and a link radius), random
joint segments and random sub-intervals, with the displacement measured densely by an
independent numpy forward kinematics. The bound is *tight* for a single link and for a straight
arm turning rigidly, so a bound scaled down by 1/1.05 fails here (see the explicit examples),
and ``edge_free`` itself is checked end to end with obstacles planted on the swept path.
"""

from __future__ import annotations

import math

import numpy as np
import pytest
import shapely
from hypothesis import HealthCheck, event, example, given, settings
from hypothesis import strategies as st

from single_arm import clearance_kernel, edge_free
from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M, link_motion_bound

SETTINGS = settings(max_examples=150, deadline=None,
                    suppress_health_check=[HealthCheck.too_slow])


# ------------------------------------------------------------------ independent geometry


def joint_points(links, base, q_deg):
    """``[m, n + 1, 2]`` base, joints and tip for configurations ``[m, n]`` (plain numpy)."""
    q = np.radians(np.atleast_2d(np.asarray(q_deg, dtype=float)))
    theta = np.cumsum(q, axis=1)
    links = np.asarray(links, dtype=float)
    steps = np.stack([links * np.cos(theta), links * np.sin(theta)], axis=-1)
    pts = np.concatenate([np.zeros((q.shape[0], 1, 2)), np.cumsum(steps, axis=1)], axis=1)
    return pts + np.asarray(base, dtype=float)


def link_point_paths(links, base, qa, qb, k, s, us):
    """Positions ``[len(s), len(us), 2]`` of the points at fractions ``us`` along link ``k``."""
    qs = qa[None, :] + np.asarray(s)[:, None] * (qb - qa)[None, :]
    pts = joint_points(links, base, qs)
    a = pts[:, k][:, None, :]
    b = pts[:, k + 1][:, None, :]
    return a + np.asarray(us)[None, :, None] * (b - a)


def exact_clearance(links, base, radius, obstacles, q_deg) -> float:
    """Clearance by shapely: min over links and obstacles of distance minus ``radius``, and
    over non-adjacent link pairs of distance minus ``2 radius`` (self-collision)."""
    pts = joint_points(links, base, q_deg)[0]
    best = math.inf
    for k in range(len(links)):
        seg = shapely.LineString([pts[k], pts[k + 1]])
        for ob in obstacles:
            if ob[0] == 0.0:
                d = max(seg.distance(shapely.Point(ob[1], ob[2])) - ob[3], 0.0)
            else:
                d = seg.distance(shapely.box(ob[1], ob[2], ob[3], ob[4]))
            best = min(best, d - radius)
        for m in range(k + 2, len(links)):
            other = shapely.LineString([pts[m], pts[m + 1]])
            best = min(best, seg.distance(other) - 2.0 * radius)
    return best


# ----------------------------------------------------------------------------- strategies

lengths = st.floats(1e-3, 0.5)
angles = st.floats(-180.0, 180.0)


@st.composite
def arms(draw, max_links=4):
    n = draw(st.integers(1, max_links))
    links = np.array(draw(st.lists(lengths, min_size=n, max_size=n)))
    base = np.array([draw(st.floats(-0.2, 0.2)), draw(st.floats(-0.2, 0.2))])
    return links, base


@st.composite
def arm_segments(draw, max_links=4, max_delta=120.0):
    """``(links, base, qa, qb)``: a random arm and a random joint segment for it."""
    links, base = draw(arms(max_links))
    n = len(links)
    qa = np.array(draw(st.lists(angles, min_size=n, max_size=n)))
    delta = np.array(draw(st.lists(st.floats(-max_delta, max_delta), min_size=n, max_size=n)))
    return links, base, qa, qa + delta


@st.composite
def sub_intervals(draw):
    s0 = draw(st.floats(0.0, 0.999))
    s1 = draw(st.floats(s0 + 1e-3, 1.0))
    return s0, s1


# ----------------------------------------------------------------------- the motion bound

#: Dense sampling: 401 configurations on the sub-interval, 11 points along the link.
N_S = 401
US = np.linspace(0.0, 1.0, 11)


def _measured_motion(links, base, qa, qb, k, s0, s1):
    """(largest path length, largest displacement from ``q(s0)``) of any sampled link point.

    The path length is a sum of chords, so it never exceeds the true length: a measured value
    above the bound is a real violation.
    """
    s = np.linspace(s0, s1, N_S)
    p = link_point_paths(links, base, qa, qb, k, s, US)
    chords = np.linalg.norm(np.diff(p, axis=0), axis=-1)  # [N_S - 1, len(US)]
    length = chords.sum(axis=0).max()
    displacement = np.linalg.norm(p - p[:1], axis=-1).max()
    return length, displacement


def _check_bound(links, base, qa, qb, s0, s1):
    for k in range(len(links)):
        mk = link_motion_bound(links, qa, qb, k)
        allowed = mk * (s1 - s0)
        length, displacement = _measured_motion(links, base, qa, qb, k, s0, s1)
        slack = 1e-12 * (1.0 + float(np.sum(links)))  # float rounding of the positions only
        assert displacement <= allowed + slack, (
            f"link {k}: a point moved {displacement!r} m, bound allows {allowed!r} m")
        assert length <= allowed + slack, (
            f"link {k}: a point travelled {length!r} m, bound allows {allowed!r} m "
            f"(ratio {length / allowed if allowed else math.inf:.6f})")


# A single link: the tip moves at exactly M_1, so any bound below it is caught.
@example(case=(np.array([0.3]), np.zeros(2), np.array([10.0]), np.array([100.0])),
         interval=(0.0, 1.0))
# A straight arm turning rigidly: the tip moves at exactly M_2 = (l1 + l2) |Δq1|.
@example(case=(np.array([0.18, 0.12]), np.array([0.05, -0.02]), np.array([-30.0, 0.0]),
               np.array([30.0, 0.0])), interval=(0.25, 0.5))
# A straight three-link arm, all joints turning the same way (tip speed equals M_3 at s = 0).
@example(case=(np.array([0.1, 0.1, 0.1]), np.zeros(2), np.zeros(3), np.array([2.0, 2.0, 2.0])),
         interval=(0.0, 0.01))
@SETTINGS
@given(case=arm_segments(), interval=sub_intervals())
def test_motion_bound_covers_the_densely_measured_motion_of_every_link(case, interval):
    _check_bound(*case, *interval)


@pytest.mark.parametrize("n_links", [1, 2, 3, 4])
def test_motion_bound_is_attained_by_a_straight_arm_turning_at_the_base(n_links):
    """Tightness: the bound is exact here, so it cannot be weakened without tripping the
    property above. Turning only joint 1 keeps the arm straight; its tip speed is the bound."""
    links = np.linspace(0.05, 0.2, n_links)
    qa = np.zeros(n_links)
    qb = np.zeros(n_links)
    qb[0] = 1.0
    k = n_links - 1
    mk = link_motion_bound(links, qa, qb, k)
    length, _ = _measured_motion(links, np.zeros(2), qa, qb, k, 0.0, 1.0)
    assert mk == pytest.approx(math.radians(1.0) * links.sum(), rel=1e-15)
    assert length == pytest.approx(mk, rel=1e-6)


def test_motion_bound_is_zero_only_when_the_link_cannot_move():
    links = np.array([0.2, 0.1])
    qa = np.array([10.0, 20.0])
    qb = np.array([10.0, 25.0])
    assert link_motion_bound(links, qa, qb, 0) == 0.0  # joint 1 still: link 1 still
    assert link_motion_bound(links, qa, qb, 1) == pytest.approx(math.radians(5.0) * 0.1)
    assert link_motion_bound(links, qb, qa, 1) == link_motion_bound(links, qa, qb, 1)


# --------------------------------------------------------------------------- clearance


@st.composite
def obstacle_sets(draw, links, base, q):
    """1-6 obstacles: random ones plus ones planted at or near a point of the arm."""
    pts = joint_points(links, base, q)[0]
    reach = float(np.sum(links))
    out = []
    for _ in range(draw(st.integers(1, 6))):
        if draw(st.booleans()):
            k = draw(st.integers(0, len(links) - 1))
            u = draw(st.floats(0.0, 1.0))
            gap = draw(st.floats(-0.01, 0.05))
            direction = draw(st.floats(0.0, 2 * math.pi))
            c = pts[k] + u * (pts[k + 1] - pts[k]) + gap * np.array(
                [math.cos(direction), math.sin(direction)])
        else:
            c = base + np.array([draw(st.floats(-1.5, 1.5)), draw(st.floats(-1.5, 1.5))]) * reach
        if draw(st.booleans()):
            out.append([0.0, c[0], c[1], draw(st.floats(1e-6, 0.1)), 0.0])
        else:
            w = draw(st.floats(1e-6, 0.1))
            h = draw(st.floats(1e-6, 0.1))
            ox = draw(st.floats(0.0, 1.0)) * w
            oy = draw(st.floats(0.0, 1.0)) * h
            out.append([1.0, c[0] - ox, c[1] - oy, c[0] - ox + w, c[1] - oy + h])
    return np.array(out, dtype=float)


@SETTINGS
@given(data=st.data(), arm=arms(), radius=st.floats(0.0, 0.02))
def test_clearance_never_exceeds_the_exact_shapely_distance(data, arm, radius):
    links, base = arm
    q = np.array(data.draw(st.lists(angles, min_size=len(links), max_size=len(links))))
    obstacles = data.draw(obstacle_sets(links, base, q))
    ours = clearance_kernel(links, base, radius, obstacles, q)
    exact = exact_clearance(links, base, radius, obstacles, q)
    assert ours <= exact + 1e-12, f"clearance {ours!r} promises more than the exact {exact!r}"
    # ... and it is the exact distance, not merely a lower bound (else planning degrades).
    assert ours == pytest.approx(exact, abs=1e-9)


def test_clearance_is_infinite_without_obstacles_and_zero_minus_radius_on_contact():
    links, base = np.array([0.2, 0.1]), np.zeros(2)
    assert clearance_kernel(links, base, 0.01, np.zeros((0, 5)), np.zeros(2)) == math.inf
    on_link = np.array([[0.0, 0.1, 0.0, 0.02, 0.0]])  # circle centred on link 1
    assert clearance_kernel(links, base, 0.01, on_link, np.zeros(2)) == -0.01
    box_on_tip = np.array([[1.0, 0.3, -0.01, 0.4, 0.01]])  # box touching the tip
    assert clearance_kernel(links, base, 0.0, box_on_tip, np.zeros(2)) == 0.0


# ------------------------------------------------------------------- edge_free end to end


def _dense_min_clearance(links, base, radius, obstacles, qa, qb, resolution_deg=0.02):
    n = max(1, int(math.ceil(np.max(np.abs(qb - qa)) / resolution_deg)))
    best = math.inf
    for s in np.linspace(0.0, 1.0, n + 1):
        best = min(best, exact_clearance(links, base, radius, obstacles, qa + s * (qb - qa)))
    return best


def _planted_obstacle(links, base, qa, qb, k, u, s_hit, rho):
    """A circle of radius ``rho`` centred on the point ``u`` of link ``k`` at ``q(s_hit)``."""
    p = link_point_paths(links, base, qa, qb, k, [s_hit], [u])[0, 0]
    return np.array([[0.0, p[0], p[1], rho, 0.0]])


# Thin obstacles on the path of a link tip where the bound is tight. A single link turning
# through 2α towards an obstacle at α has clearance L sin α, so an advance f times too long
# lands at f sin α > α + rho / L, clean over the obstacle, whenever f > α / sin α (+ rho):
# α = 20° catches f = 1.05, α = 8° catches f = 1.01, α = 2° catches f = 1.001.
@example(case=(np.array([0.3]), np.zeros(2), np.array([0.0]), np.array([40.0])),
         where=(0, 1.0, 0.5), rho=1e-4, radius=0.0)
@example(case=(np.array([0.3]), np.zeros(2), np.array([0.0]), np.array([16.0])),
         where=(0, 1.0, 0.5), rho=1e-5, radius=0.0)
@example(case=(np.array([0.3]), np.zeros(2), np.array([0.0]), np.array([4.0])),
         where=(0, 1.0, 0.5), rho=1e-7, radius=0.0)
@example(case=(np.array([0.18, 0.12]), np.zeros(2), np.array([-20.0, 0.0]),
               np.array([20.0, 0.0])), where=(1, 1.0, 0.5), rho=1e-4, radius=0.0)
@example(case=(np.array([0.18, 0.12]), np.zeros(2), np.array([-20.0, 0.0]),
               np.array([20.0, 0.0])), where=(1, 1.0, 0.5), rho=1e-4, radius=0.002)
@SETTINGS
@given(case=arm_segments(max_links=3),
       where=st.tuples(st.integers(0, 3), st.floats(0.0, 1.0), st.floats(0.0, 1.0)),
       rho=st.floats(1e-6, 1e-2), radius=st.floats(0.0, 0.01))
def test_edge_free_never_certifies_an_edge_through_an_obstacle_on_the_swept_path(
        case, where, rho, radius):
    links, base, qa, qb = case
    k, u, s_hit = where
    k = min(k, len(links) - 1)
    obstacles = _planted_obstacle(links, base, qa, qb, k, u, s_hit, rho)
    assert exact_clearance(links, base, radius, obstacles, qa + s_hit * (qb - qa)) <= 0.0
    assert not edge_free(links, base, radius, obstacles, qa, qb, CERT_MARGIN_M)


@settings(max_examples=60, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data(), arm=arms(max_links=3), radius=st.floats(0.0, 0.01))
def test_edges_certified_free_keep_positive_exact_clearance_everywhere(data, arm, radius):
    links, base = arm
    qa = np.array(data.draw(st.lists(angles, min_size=len(links), max_size=len(links))))
    delta = np.array(data.draw(st.lists(st.floats(-20.0, 20.0), min_size=len(links),
                                        max_size=len(links))))
    qb = qa + delta
    obstacles = data.draw(obstacle_sets(links, base, qa + 0.5 * delta))
    free = edge_free(links, base, radius, obstacles, qa, qb, CERT_MARGIN_M)
    event("certified" if free else "rejected")
    if not free:
        return
    assert _dense_min_clearance(links, base, radius, obstacles, qa, qb) > 0.0


def test_edge_free_accepts_an_edge_that_passes_a_thin_obstacle_by_a_clear_gap():
    """The check is not trivially 'always reject': 1 mm of room over a 40° sweep is certified."""
    links, base = np.array([0.3]), np.zeros(2)
    obstacles = np.array([[0.0, 0.3 + 1e-3 + 1e-4, 0.0, 1e-4, 0.0]])  # just beyond the tip
    assert edge_free(links, base, 0.0, obstacles, np.array([-20.0]), np.array([20.0]),
                     CERT_MARGIN_M)


# ------------------------------------------------ one extension, path extraction, path cost
#
# The planners' loop is compiled around ``extend``; these tests call it directly on small
# trees so that every branch (steering, the two safety checks, joining the goal) is pinned,
# and so that they stay fast with NUMBA_DISABLE_JIT=1 (scripts/mutation_test.sh).

from xfuzzy_rrt.planners.extend import extend  # noqa: E402
from xfuzzy_rrt.planners.result import (  # noqa: E402
    ACCEPTED,
    EDGE_BLOCKED,
    GOAL_REACHED,
    NO_PROGRESS,
    NODE_IN_COLLISION,
    path_cost_deg,
)
from xfuzzy_rrt.geometry.problem import single_arm_problem  # noqa: E402
from xfuzzy_rrt.planners.tree import make_tree, add_node, extract_path  # noqa: E402

ARM2 = np.array([0.2, 0.1])
LIMITS2 = np.array([[-170.0, 170.0], [-150.0, 150.0]])


class _Ext:
    """A tree rooted at ``root`` plus the scratch arrays ``extend`` writes into."""

    def __init__(self, root, obstacles=None, radius=0.0, goal=(150.0, 140.0), capacity=16):
        self.obstacles = np.zeros((0, 5)) if obstacles is None else np.asarray(obstacles, float)
        self.radius = radius
        self.goal = np.asarray(goal, dtype=float)
        self.tree = make_tree(capacity, LIMITS2)
        t = self.tree
        add_node(t, np.array([float(root[0]), float(root[1])]), -1)
        self.q_near = np.empty(2)
        self.q_new = np.empty(2)

    @property
    def n(self) -> int:
        return int(self.tree.meta[0])

    def extend(self, near, sample, step):
        t = self.tree
        problem = single_arm_problem(ARM2, np.zeros(2), self.radius, self.obstacles, LIMITS2,
                                     goal=self.goal, margin=CERT_MARGIN_M)
        return extend(problem, t, near, np.array([float(sample[0]), float(sample[1])]),
                      float(step), self.q_near, self.q_new)


def _thin_circle_on_tip_path(q_from, q_to, s_hit=0.5, rho=1e-4):
    """A circle of radius ``rho`` on the arm tip at ``q(s_hit)`` of the joint segment."""
    return _planted_obstacle(ARM2, np.zeros(2), np.asarray(q_from, float),
                             np.asarray(q_to, float), 1, 1.0, s_hit, rho)


def test_extend_steers_exactly_one_step_towards_a_far_sample():
    e = _Ext((0.0, 0.0))
    outcome, k = e.extend(0, (30.0, 40.0), 10.0)
    assert (outcome, k) == (ACCEPTED, 1)
    np.testing.assert_allclose(e.tree.nodes[1], [6.0, 8.0], rtol=0, atol=1e-12)
    assert e.tree.parent[1] == 0 and e.n == 2
    np.testing.assert_array_equal(e.q_near, [0.0, 0.0])
    np.testing.assert_array_equal(e.q_new, e.tree.nodes[1])


@pytest.mark.parametrize("sample", [(3.0, 4.0), (6.0, 8.0)])
def test_extend_reaches_a_sample_within_one_step_exactly(sample):
    e = _Ext((0.0, 0.0))
    outcome, k = e.extend(0, sample, 10.0)
    assert (outcome, k) == (ACCEPTED, 1)
    assert tuple(e.tree.nodes[1]) == sample  # no rounding through the steering formula


def test_extend_makes_no_progress_towards_the_node_itself():
    e = _Ext((5.0, 5.0))
    assert e.extend(0, (5.0, 5.0), 10.0) == (NO_PROGRESS, -1)
    assert e.n == 1


def test_extend_rejects_a_new_node_in_collision_and_leaves_the_tree_alone():
    # A circle around the tip at q = (6, 8).
    tip = joint_points(ARM2, np.zeros(2), [6.0, 8.0])[0, -1]
    e = _Ext((0.0, 0.0), obstacles=[[0.0, tip[0], tip[1], 0.01, 0.0]])
    assert e.extend(0, (30.0, 40.0), 10.0) == (NODE_IN_COLLISION, -1)
    assert e.n == 1


def test_extend_rejects_a_new_node_outside_the_joint_limits():
    e = _Ext((165.0, 0.0))
    assert e.extend(0, (180.0, 0.0), 10.0) == (NODE_IN_COLLISION, -1)
    assert e.n == 1


def test_extend_rejects_a_new_node_within_the_certification_margin():
    tip = joint_points(ARM2, np.zeros(2), [6.0, 8.0])[0, -1]
    # Clearance at q_new is 0.5 µm: free, but not by the margin.
    e = _Ext((0.0, 0.0), obstacles=[[0.0, tip[0] + 0.01 + 5e-7, tip[1], 0.01, 0.0]])
    assert clearance_kernel(ARM2, np.zeros(2), 0.0, e.obstacles, np.array([6.0, 8.0])) > 0.0
    assert e.extend(0, (30.0, 40.0), 10.0) == (NODE_IN_COLLISION, -1)


def test_extend_rejects_an_edge_that_crosses_a_thin_obstacle_between_free_ends():
    e = _Ext((0.0, 0.0), obstacles=_thin_circle_on_tip_path((0.0, 0.0), (6.0, 8.0)))
    for q in ((0.0, 0.0), (6.0, 8.0)):
        assert clearance_kernel(ARM2, np.zeros(2), 0.0, e.obstacles, np.array(q)) > 1e-3
    assert e.extend(0, (30.0, 40.0), 10.0) == (EDGE_BLOCKED, -1)
    assert e.n == 1


def test_extend_joins_the_goal_when_it_is_within_one_step_and_the_edge_is_free():
    e = _Ext((0.0, 0.0), goal=(12.0, 16.0))
    outcome, k = e.extend(0, (30.0, 40.0), 10.0)
    assert (outcome, k) == (GOAL_REACHED, 2)
    assert tuple(e.tree.nodes[2]) == (12.0, 16.0) and e.tree.parent[2] == 1
    np.testing.assert_allclose(extract_path(e.tree.nodes, e.tree.parent, k),
                               [[0.0, 0.0], [6.0, 8.0], [12.0, 16.0]], atol=1e-12)


def test_extend_joins_a_goal_exactly_one_step_away():
    e = _Ext((0.0, 0.0), goal=(12.0, 16.0))
    e.extend(0, (6.0, 8.0), 10.0)  # new node exactly 10° from the goal
    assert e.n == 3 and e.tree.parent[2] == 1


def test_extend_does_not_join_a_goal_beyond_one_step():
    e = _Ext((0.0, 0.0), goal=(12.0, 16.5))
    assert e.extend(0, (30.0, 40.0), 10.0) == (ACCEPTED, 1)
    assert e.n == 2


def test_extend_does_not_join_the_goal_through_a_blocked_edge():
    e = _Ext((0.0, 0.0), goal=(12.0, 16.0),
             obstacles=_thin_circle_on_tip_path((6.0, 8.0), (12.0, 16.0)))
    assert e.extend(0, (30.0, 40.0), 10.0) == (ACCEPTED, 1)
    assert e.n == 2


def test_extend_that_lands_on_the_goal_adds_it_once():
    e = _Ext((0.0, 0.0), goal=(3.0, 4.0))
    assert e.extend(0, (3.0, 4.0), 10.0) == (GOAL_REACHED, 1)
    assert e.n == 2


@settings(max_examples=80, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(root=st.tuples(st.floats(-160, 160), st.floats(-140, 140)),
       sample=st.tuples(st.floats(-170, 170), st.floats(-150, 150)),
       goal=st.tuples(st.floats(-170, 170), st.floats(-150, 150)),
       step=st.floats(0.5, 40.0),
       circles=st.lists(st.tuples(st.floats(-0.3, 0.3), st.floats(-0.3, 0.3),
                                  st.floats(1e-4, 0.05)), min_size=1, max_size=4),
       radius=st.floats(0.0, 0.01))
def test_every_edge_extend_adds_is_collision_free_and_at_most_one_step_long(
        root, sample, goal, step, circles, radius):
    obstacles = np.array([[0.0, x, y, r, 0.0] for x, y, r in circles])
    if clearance_kernel(ARM2, np.zeros(2), radius, obstacles, np.array(root)) <= CERT_MARGIN_M:
        return
    e = _Ext(root, obstacles=obstacles, radius=radius, goal=goal)
    outcome, k = e.extend(0, sample, step)
    event(f"outcome {outcome}")
    nodes, parent = e.tree.nodes, e.tree.parent
    assert e.n == {NO_PROGRESS: 1, NODE_IN_COLLISION: 1, EDGE_BLOCKED: 1, ACCEPTED: 2}.get(
        outcome, e.n)
    for i in range(1, e.n):
        a, b = nodes[parent[i]], nodes[i]
        assert np.hypot(*(b - a)) <= step * (1 + 1e-12)
        assert np.all((b >= LIMITS2[:, 0]) & (b <= LIMITS2[:, 1]))
        assert _dense_min_clearance(ARM2, np.zeros(2), radius, obstacles, a, b, 0.05) > 0.0
    if outcome == GOAL_REACHED:
        assert tuple(nodes[k]) == goal
        path = extract_path(nodes, parent, k)
        assert tuple(path[0]) == root and tuple(path[-1]) == goal


def _chain_tree(points, parents):
    t = make_tree(len(points) + 1, LIMITS2)
    for (x, y), p in zip(points, parents):
        add_node(t, np.array([float(x), float(y)]), p)
    return t


def test_extract_path_follows_parents_from_the_root_to_the_node():
    # 0 -> 1 -> 3 -> 4 and a side branch 0 -> 2
    t = _chain_tree([(0, 0), (1, 1), (9, 9), (2, 3), (4, 4)], [-1, 0, 0, 1, 3])
    np.testing.assert_array_equal(extract_path(t.nodes, t.parent, 4),
                                  [[0, 0], [1, 1], [2, 3], [4, 4]])
    np.testing.assert_array_equal(extract_path(t.nodes, t.parent, 2), [[0, 0], [9, 9]])
    np.testing.assert_array_equal(extract_path(t.nodes, t.parent, 0), [[0, 0]])
    assert extract_path(t.nodes, t.parent, -1).shape == (0, 2)


def test_add_node_records_position_parent_and_count():
    t = _chain_tree([(0.5, -0.5)], [-1])
    i = add_node(t, np.array([7.25, -3.5]), 0)
    assert i == 1 and t.meta[0] == 2
    assert tuple(t.nodes[1]) == (7.25, -3.5) and t.parent[1] == 0


@pytest.mark.parametrize("path,cost", [
    ([[0.0, 0.0], [3.0, 4.0]], 5.0),
    ([[0.0, 0.0], [3.0, 4.0], [3.0, 4.0], [0.0, 0.0]], 10.0),
    ([[1.0, 1.0], [1.0, -2.0], [-3.0, -2.0]], 7.0),
    ([[2.0, 2.0]], 0.0),
    (np.zeros((0, 2)), 0.0),
])
def test_path_cost_is_the_euclidean_joint_space_length(path, cost):
    assert path_cost_deg(np.array(path, dtype=float)) == pytest.approx(cost, abs=1e-12)


def test_rrt_paths_pass_the_exact_oracle_on_a_fixture_scenario():
    """End to end through the compiled loop (kept to a few seeds: fast without the JIT too)."""
    from conftest import FIXTURES
    from exact_geometry import Oracle
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.planners.rrt import plan_rrt

    path = FIXTURES / "scenarios" / "two-circles.toml"
    scenario, oracle = load_scenario(path), Oracle(path)
    for seed in range(3):
        r = plan_rrt(scenario, seed=seed, step_deg=20.0, goal_bias=0.2)
        assert r.success
        assert oracle.path_problems(r.path_deg) == []
        assert r.cost_deg == pytest.approx(path_cost_deg(r.path_deg))


# ------------------------------------------------- boundaries pinned by mutation testing
#
# Each test below was written for a mutant that survived scripts/mutation_test.sh: they pin
# the exact boundaries of the checks (strict margins, the exact end configuration, no
# division by a zero motion bound) and the fuzzy geometry inputs computed next to them.

import warnings  # noqa: E402

from single_arm import config_free  # noqa: E402
from xfuzzy_rrt.geometry.collision import (  # noqa: E402
    direction_and_distance,
    nearest_obstacle_from_point,
)

NO_OBSTACLES = np.zeros((0, 5))


def test_a_configuration_with_clearance_exactly_the_margin_is_not_free():
    obstacles = np.array([[0.0, 0.35, 0.02, 0.02, 0.0]])
    q = np.array([10.0, 5.0])
    c = clearance_kernel(ARM2, np.zeros(2), 0.0, obstacles, q)
    assert c > 0.0
    assert not config_free(ARM2, np.zeros(2), 0.0, obstacles, LIMITS2, q, c)
    assert config_free(ARM2, np.zeros(2), 0.0, obstacles, LIMITS2, q, np.nextafter(c, 0.0))


def test_an_edge_starting_with_clearance_exactly_the_margin_is_not_certified():
    obstacles = np.array([[0.0, 0.35, 0.02, 0.02, 0.0]])
    qa, qb = np.array([10.0, 5.0]), np.array([60.0, 5.0])  # turning away from the obstacle
    c = clearance_kernel(ARM2, np.zeros(2), 0.0, obstacles, qa)
    assert not edge_free(ARM2, np.zeros(2), 0.0, obstacles, qa, qb, c)
    assert edge_free(ARM2, np.zeros(2), 0.0, obstacles, qa, qb, 0.5 * c)


def test_the_last_stop_of_the_check_is_exactly_the_end_configuration():
    """At s = 1 the check measures ``qb`` itself, not ``qa + 1 * (qb - qa)`` (which can differ
    in the last bit): an edge whose end keeps exactly the margin must be rejected."""
    rng = np.random.default_rng(5)
    obstacles = np.array([[0.0, 0.0, 0.33, 0.02, 0.0]])  # above the base: approached at the end
    n = 20_000
    qa = rng.uniform(-1.0, 1.0, (n, 2)) * 10.0 ** rng.uniform(-3.0, 0.0, (n, 2))
    qb = np.column_stack([rng.uniform(30.0, 80.0, n), rng.uniform(-30.0, 30.0, n)])
    inexact = np.any(qa + 1.0 * (qb - qa) != qb, axis=1)  # where the round trip loses a bit
    checked = distinguishing = 0
    for a, b in zip(qa[inexact][:150], qb[inexact][:150]):
        c_end = clearance_kernel(ARM2, np.zeros(2), 0.0, obstacles, b)
        path = [clearance_kernel(ARM2, np.zeros(2), 0.0, obstacles, a + s * (b - a))
                for s in np.linspace(0.0, 0.99, 12)]
        if not (c_end > 0.0 and min(path) > c_end):
            continue  # only edges that get closest at their end
        checked += 1
        near_end = clearance_kernel(ARM2, np.zeros(2), 0.0, obstacles, a + 1.0 * (b - a))
        distinguishing += near_end > c_end
        assert not edge_free(ARM2, np.zeros(2), 0.0, obstacles, a, b, c_end)
    assert checked > 20 and distinguishing > 0


def test_an_edge_without_obstacles_is_free():
    assert edge_free(ARM2, np.zeros(2), 0.01, NO_OBSTACLES, np.array([-170.0, 0.0]),
                     np.array([170.0, 150.0]), CERT_MARGIN_M)


def test_an_edge_that_moves_only_the_second_joint_never_divides_by_a_zero_bound():
    far = np.array([[0.0, -0.5, -0.5, 0.05, 0.0]])
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # numpy warns on x / 0.0 where numba would raise
        assert edge_free(ARM2, np.zeros(2), 0.0, far, np.array([10.0, 0.0]),
                         np.array([10.0, 40.0]), CERT_MARGIN_M)
        blocked = _planted_obstacle(ARM2, np.zeros(2), np.array([10.0, 0.0]),
                                    np.array([10.0, 40.0]), 1, 1.0, 0.5, 1e-4)
        assert not edge_free(ARM2, np.zeros(2), 0.0, blocked, np.array([10.0, 0.0]),
                             np.array([10.0, 40.0]), CERT_MARGIN_M)


def test_extend_without_progress_reports_the_node_itself_as_the_new_configuration():
    e = _Ext((5.0, -7.0))
    e.q_new[:] = np.nan
    assert e.extend(0, (5.0, -7.0), 10.0) == (NO_PROGRESS, -1)
    assert tuple(e.q_new) == (5.0, -7.0) and tuple(e.q_near) == (5.0, -7.0)


def test_a_sample_exactly_one_step_away_becomes_the_new_node_bit_for_bit():
    rng = np.random.default_rng(11)
    differs = 0
    for _ in range(300):
        near = rng.uniform(-150.0, 150.0, 2)
        sample = rng.uniform(-150.0, 150.0, 2)
        dx, dy = float(sample[0] - near[0]), float(sample[1] - near[1])
        step = math.sqrt(dx * dx + dy * dy)  # the distance exactly as extend measures it
        # Steering by step / d == 1 could round: near + (sample - near) need not be sample.
        differs += tuple(near + (sample - near)) != tuple(sample)
        e = _Ext(near)
        outcome, _ = e.extend(0, sample, step)
        assert outcome in (ACCEPTED, GOAL_REACHED)
        assert tuple(e.tree.nodes[1]) == tuple(sample)
    assert differs > 0


def test_path_cost_of_an_empty_path_given_as_a_list_is_zero():
    assert path_cost_deg([]) == 0.0
    assert path_cost_deg([[1.0, 2.0]]) == 0.0


def test_nearest_obstacle_without_obstacles_is_at_infinity_with_no_index():
    assert nearest_obstacle_from_point(0.1, 0.2, NO_OBSTACLES) == (math.inf, 0.0, -1)


def test_nearest_obstacle_index_is_the_closest_and_the_first_on_ties():
    obstacles = np.array([[0.0, 1.0, 0.0, 0.1, 0.0],    # 0.9 away (east)
                          [0.0, 0.0, 0.5, 0.1, 0.0],    # 0.4 away (north)
                          [1.0, -0.5, -0.1, -0.4, 0.1],  # 0.4 away (west), a tie
                          [0.0, 0.0, -2.0, 0.1, 0.0]])
    d, angle, index = nearest_obstacle_from_point(0.0, 0.0, obstacles)
    assert index == 1 and d == pytest.approx(0.4) and angle == pytest.approx(math.pi / 2)


def test_nearest_obstacle_direction_from_inside_a_box_points_at_its_centre():
    box = np.array([[1.0, 0.1, -0.05, 0.5, 0.25]])  # centre (0.3, 0.1), all corners distinct
    d, angle, index = nearest_obstacle_from_point(0.45, 0.02, box)
    assert (d, index) == (0.0, 0)
    assert angle == math.atan2(0.5 * (-0.05 + 0.25) - 0.02, 0.5 * (0.1 + 0.5) - 0.45)
    d, angle, _ = nearest_obstacle_from_point(0.15, 0.2, box)
    assert angle == math.atan2(0.5 * (-0.05 + 0.25) - 0.2, 0.5 * (0.1 + 0.5) - 0.15) + 2 * math.pi


@pytest.mark.parametrize("vx,vy", [(1.0, 0.5), (1.0, 1e-3), (0.2, 0.15), (-1.0, 0.3)])
def test_directions_in_the_upper_half_plane_are_atan2_exactly(vx, vy):
    """No round trip through +2π and -2π: the angle is ``atan2`` to the last bit."""
    cx, cy = 0.1 + 3 * vx, 0.2 + 3 * vy
    _, angle, _ = nearest_obstacle_from_point(0.1, 0.2, np.array([[0.0, cx, cy, 0.01, 0.0]]))
    assert angle == math.atan2(cy - 0.2, cx - 0.1)
    d, angle2 = direction_and_distance(0.1, 0.2, 0.1 + vx, 0.2 + vy)
    assert angle2 == math.atan2((0.2 + vy) - 0.2, (0.1 + vx) - 0.1)
    assert d == pytest.approx(math.hypot(vx, vy), rel=1e-12)


def test_directions_a_hair_below_east_wrap_to_zero_not_two_pi():
    """atan2 of -1e-300 is -1e-300; adding 2π rounds to exactly 2π, which must wrap to 0."""
    circle = np.array([[0.0, 2.0, -1e-300, 0.5, 0.0]])
    _, angle, _ = nearest_obstacle_from_point(0.0, 0.0, circle)
    assert angle == 0.0
    _, angle = direction_and_distance(0.0, 0.0, 2.0, -1e-300)
    assert angle == 0.0
    _, angle = direction_and_distance(0.0, 0.0, 0.0, -1.0)
    assert angle == pytest.approx(1.5 * math.pi) and 0.0 <= angle < 2 * math.pi


def test_distance_to_a_circle_containing_the_point_is_zero():
    d, _, _ = nearest_obstacle_from_point(0.0, 0.0, np.array([[0.0, 0.01, 0.0, 0.05, 0.0]]))
    assert d == 0.0


def test_an_edge_whose_clearance_overflows_is_never_certified():
    """1e160 m links overflow the squared distances to inf; one infinite step would then
    'certify' a sweep straight through the box (scenario files cap geometry at 1e6 m too)."""
    links, base = np.array([1e160]), np.zeros(2)
    box = np.array([[1.0, 2e159, -1.0, 3e159, 1.0]])  # on the x axis, crossed at q = 0
    assert clearance_kernel(links, base, 0.0, box, np.array([45.0])) == math.inf
    assert not edge_free(links, base, 0.0, box, np.array([45.0]), np.array([-45.0]),
                         CERT_MARGIN_M)
    nan_box = np.array([[1.0, math.nan, -1.0, 3e159, 1.0]])
    assert not edge_free(np.array([0.3]), base, 0.0, nan_box, np.array([45.0]),
                         np.array([-45.0]), CERT_MARGIN_M)


from types import SimpleNamespace  # noqa: E402

from xfuzzy_rrt.geometry.collision import (  # noqa: E402
    in_collision,
    segment_obstacle_dist,
    within_limits,
)

UNIT_BOX = np.array([1.0, 0.0, 0.0, 1.0, 1.0])


def _shapely_segment_dist(a, b, ob) -> float:
    seg = shapely.LineString([a, b]) if tuple(a) != tuple(b) else shapely.Point(a)
    if ob[0] == 0.0:
        return max(seg.distance(shapely.Point(ob[1], ob[2])) - ob[3], 0.0)
    return seg.distance(shapely.box(ob[1], ob[2], ob[3], ob[4]))


@pytest.mark.parametrize("a,b,ob", [
    # a zero-length segment is a point (a link can round to nothing)
    ((0.3, 0.4), (0.3, 0.4), [0.0, 1.0, 1.0, 0.2, 0.0]),
    ((1.5, 0.5), (1.5, 0.5), UNIT_BOX),
    # axis-parallel segments: through the box, beside it, along an edge line past a corner
    ((0.5, -1.0), (0.5, 2.0), UNIT_BOX),
    ((-1.0, 0.25), (3.0, 0.25), UNIT_BOX),
    ((2.0, -1.0), (2.0, 2.0), UNIT_BOX),
    ((-1.0, 1.5), (3.0, 1.5), UNIT_BOX),
    ((-1.0, 1.0), (3.0, 1.0), UNIT_BOX),
    # |dx| or |dy| exactly 1: the Liang–Barsky ratios divide by exactly 1.0
    ((0.0, 0.0), (1.0, 0.5), [1.0, 0.2, 0.3, 0.4, 0.6]),
    ((0.0, 0.0), (0.5, 1.0), [1.0, 0.3, 0.2, 0.6, 0.4]),
    ((1.0, 0.5), (0.0, 0.0), [1.0, 0.2, 0.3, 0.4, 0.6]),
    ((0.0, 0.0), (1.0, 0.5), [1.0, 0.5, 0.1, 0.7, 0.3]),
])
def test_segment_distance_is_exact_for_points_and_axis_parallel_segments(a, b, ob):
    ob = np.asarray(ob, dtype=float)
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        d = segment_obstacle_dist(a[0], a[1], b[0], b[1], ob)
    assert d == pytest.approx(_shapely_segment_dist(a, b, ob), abs=1e-15)


def _arrays(obstacles, limits=LIMITS2, radius=0.0):
    obstacles = np.asarray(obstacles, dtype=float).reshape(-1, 5)
    limits = np.asarray(limits, dtype=float)
    return SimpleNamespace(
        links=ARM2, base=np.zeros(2), link_radius=radius, obstacles=obstacles,
        limits_deg=limits,
        problem=lambda margin: single_arm_problem(ARM2, np.zeros(2), radius, obstacles, limits,
                                                  margin=margin))


def test_touching_counts_as_a_collision():
    a = _arrays([[1.0, 0.3, -0.1, 0.5, 0.1]])  # the tip at q = 0 lies on the box's left edge
    assert clearance_kernel(ARM2, np.zeros(2), 0.0, a.obstacles, np.zeros(2)) == 0.0
    assert in_collision(a, [0.0, 0.0])
    assert not in_collision(a, [1.0, 0.0])


def test_configurations_exactly_on_the_joint_limits_are_within_them():
    assert within_limits(LIMITS2, np.array([-170.0, 150.0]))
    assert within_limits(LIMITS2, np.array([170.0, -150.0]))
    assert not within_limits(LIMITS2, np.array([np.nextafter(170.0, 200.0), 0.0]))
    assert not within_limits(LIMITS2, np.array([0.0, np.nextafter(-150.0, -200.0)]))
    assert not in_collision(_arrays(NO_OBSTACLES), [-170.0, 150.0])
