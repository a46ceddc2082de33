"""Collision checking, clearance and the certified edge check.

Obstacles are closed sets and links are capsules (a segment dilated by ``link_radius``), so a
configuration collides when a link segment comes within ``link_radius`` of an obstacle,
touching included. All distances are exact Euclidean distances (segment-to-point for circles,
segment-to-rectangle for boxes) rather than sampled approximations.

**Certified edges (conservative advancement).** A joint-space segment ``qa -> qb`` is declared
free only if *every* configuration on it is free. Along the straight joint segment
``q(s) = qa + s (qb - qa)``, any point of link *k* moves at most ``M_k * |Δs|`` where

    M_k = Σ_{j <= k} |Δq_j| · Σ_{i=j..k} l_i        (Δq in radians)

because the speed of a point on link *k* is at most Σ_i l_i |θ̇_i| with θ_i the absolute link
angles and |θ̇_i| <= Σ_{j<=i} |q̇_j|. If link *k* has clearance ``c_k`` at ``s``, it cannot touch
anything before ``s + c_k / M_k``. We step by ``min_k c_k / M_k`` and re-measure; the check
fails as soon as the clearance drops to ``margin`` or below and succeeds when ``s`` reaches 1.
The margin (default 1e-6 m = 1 µm) absorbs floating-point error and guarantees termination:
every step is at least ``margin / max_k M_k`` long. Nodes are held to the same margin so that
every edge leaving an accepted node can be certified.

**A surgeon's clearance (certified).** A user clearance ``c`` (metres; ``[safety] clearance_m``
or ``--clearance``) travels in the problem bundle as its own field ``P.clearance``, next to
``margin = effective_margin(c) = CERT_MARGIN_M + c`` (the bundle is built by
``ScenarioArrays.problem``, which derives the clearance from the margin in one place,
:func:`clearance_of_margin`). ``edge_free`` reads ``clear = P.clearance`` and treats
``c_k - clear`` as the free distance: it steps by
``min_k (c_k - clear) / M_k`` and fails when a stop has ``c_k <= margin`` (i.e. ``c_k - clear``
at most the 1 µm termination slack). Why this holds the clearance *everywhere* on the segment,
not only at the stops: between two stops ``s`` and ``s + ds`` link *k* keeps at least
``max(c_k(s) - M_k t, c_k(s + ds) - M_k (ds - t))`` at ``s + t``, and with
``M_k ds <= c_k(s) - clear`` and ``c_k(s + ds) > margin`` that is more than
``(clear + margin) / 2 = c + 0.5 µm``. So every point of every link capsule keeps at least ``c``
from every obstacle along every certified segment. With ``c = 0`` (the default), ``clear`` is
exactly ``0.0`` and ``c_k - 0.0 == c_k`` in floating point: the arithmetic, hence every plan, is
bit-for-bit the one without a clearance (tests/test_golden.py). Margins below ``CERT_MARGIN_M``
(tests use them) are treated as a clearance of 0.

**Bodies that count.** Every link capsule against every obstacle; every pair of links of two
different arms (their distance is ``(M_k + M_m)``-Lipschitz: each link moves with its own arm's
joints); and every pair of *non-adjacent* links of one arm, ``|k - m| >= 2`` (self-collision,
:func:`self_pair_motion_bound`). Adjacent links share a joint point, so their capsules always
overlap there: they are never a collision, whatever the joint angle, even folded back at ±180°
onto each other -- how far a joint may fold is what its joint limits say (a real joint's
mechanical stop), not a distance test. A two-link arm has no non-adjacent pair, so every 2-DOF
result is the one without self-collision, bit for bit; a three-link arm has one pair, (0, 2).
The user clearance is held between any two bodies alike.

**Work.** ``P.work[0]`` counts exact element distances (one per link-obstacle pair, per link
pair of two arms, per non-adjacent link pair of one arm) evaluated by :func:`clearance_kernel`
and :func:`edge_free` (so :func:`config_free` too): a deterministic measure of planning work.
It is only ever incremented, never read, by the kernels, so it cannot change a result. It counts
what the algorithm measures, not how: an edge stop whose values a planner already had (the
node check's: :func:`edge_free_two_link` for one two-link arm, a node's stop record
:func:`node_stop_into` / :func:`edge_free_rows` for any other arm) and an obstacle skipped
because it cannot be the nearest (:func:`_link_clearance`) count as before, so counts compare
across versions. A probe
of a blocked edge (:func:`edge_free`, *Blocked edges*) counts like a stop: the probes cut a
blocked edge's count (5-8x on random blocked edges), which is the point of them.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.kinematics import fk_step

#: Minimum clearance (metres) a configuration must keep to count as free for the planners.
CERT_MARGIN_M = 1e-6
#: The exact minimum clearance along a path (``clearance.path_min_clearance``,
#: ``path_check.certify_path``) is bracketed to within this (metres): 0.1 µm, a tenth of
#: ``CERT_MARGIN_M``, so a reported minimum can never hide a violation of the certification
#: margin, yet it is 100x coarser than float64 noise at arm scale (~1e-15 m) and cheap: a tighter
#: 1 nm costs ~8x the distance evaluations near smooth minima, where the Lipschitz bound
#: converges like the square root of the tolerance. One constant for both callers (they
#: used to disagree, 1e-7 and 1e-9).
MIN_CLEARANCE_TOL_M = 1e-7
#: Largest user clearance accepted (metres): beyond 1 m no arm in scope has any free space.
MAX_CLEARANCE_M = 1.0

_TWO_PI = 2.0 * math.pi


def clearance_of_margin(margin: float) -> float:
    """The user clearance a kernel ``margin`` stands for: ``margin - CERT_MARGIN_M``, or exactly
    ``0.0`` when that is not positive (the default margin, and the smaller margins tests use).

    The one place the clearance is recovered from a margin (``ScenarioArrays.problem`` stores it
    in ``P.clearance``; kernels read that field). For ``effective_margin(c)`` it is ``c`` up to
    one rounding of the sum; ``clearance_of_margin(CERT_MARGIN_M)`` is exactly 0.0, so the
    certified step ``(c_k - 0.0) / M_k`` is bit for bit the one without a clearance.
    """
    clear = float(margin) - CERT_MARGIN_M
    return clear if clear > 0.0 else 0.0


@nb.njit(cache=True, nogil=True, inline="always")
def _segment_offset(px, py, ax, ay, bx, by):
    """Vector from point P to the nearest point of segment AB."""
    dx = bx - ax
    dy = by - ay
    den = dx * dx + dy * dy
    t = 0.0
    if den > 0.0:
        t = ((px - ax) * dx + (py - ay) * dy) / den
        if t < 0.0:
            t = 0.0
        elif t > 1.0:
            t = 1.0
    return ax + t * dx - px, ay + t * dy - py


@nb.njit(cache=True, nogil=True, inline="always")
def _point_segment_dist(px, py, ax, ay, bx, by):
    qx, qy = _segment_offset(px, py, ax, ay, bx, by)
    return math.sqrt(qx * qx + qy * qy)


@nb.njit(cache=True, nogil=True, inline="always")
def _point_box_dist(px, py, x0, y0, x1, y1):
    dx = max(x0 - px, 0.0, px - x1)
    dy = max(y0 - py, 0.0, py - y1)
    return math.sqrt(dx * dx + dy * dy)


@nb.njit(cache=True, nogil=True, _nrt=False)
def _segment_hits_box(ax, ay, bx, by, x0, y0, x1, y1):
    """Liang–Barsky: does the closed segment meet the closed rectangle?"""
    t0 = 0.0
    t1 = 1.0
    dx = bx - ax
    dy = by - ay
    for edge in range(4):
        if edge == 0:
            p = -dx
            q = ax - x0
        elif edge == 1:
            p = dx
            q = x1 - ax
        elif edge == 2:
            p = -dy
            q = ay - y0
        else:
            p = dy
            q = y1 - ay
        if p == 0.0:
            if q < 0.0:
                return False
        else:
            r = q / p
            if p < 0.0:
                if r > t1:
                    return False
                if r > t0:
                    t0 = r
            else:
                if r < t0:
                    return False
                if r < t1:
                    t1 = r
    return True


@nb.njit(cache=True, nogil=True, inline="always")
def _segment_offset2(px, py, ax, ay, bx, by):
    """Squared distance from P to segment AB (``_point_segment_dist`` before its square root)."""
    qx, qy = _segment_offset(px, py, ax, ay, bx, by)
    return qx * qx + qy * qy


@nb.njit(cache=True, nogil=True, inline="always")
def _point_box_dist2(px, py, x0, y0, x1, y1):
    """Squared ``_point_box_dist``."""
    dx = max(x0 - px, 0.0, px - x1)
    dy = max(y0 - py, 0.0, py - y1)
    return dx * dx + dy * dy


@nb.njit(cache=True, nogil=True, inline="always")
def _obstacle_dist(ax, ay, bx, by, kind, o1, o2, o3, o4):
    """:func:`segment_obstacle_dist` on an obstacle row's five numbers.

    Why scalars: a row view per obstacle (``obstacles[o]``) cost a fifth of a clearance. For a
    box, the six candidate distances are compared squared and one square root is taken:
    ``sqrt`` is correctly rounded, hence monotonic, so ``sqrt(min(a, b)) == min(sqrt(a),
    sqrt(b))`` bit for bit, the value of taking six roots.
    """
    if kind == 0.0:  # circle
        d = _point_segment_dist(o1, o2, ax, ay, bx, by) - o3
        return d if d > 0.0 else 0.0
    if _segment_hits_box(ax, ay, bx, by, o1, o2, o3, o4):
        return 0.0
    # Disjoint convex sets in the plane: the closest pair involves an endpoint of the segment
    # or a corner of the rectangle.
    d2 = min(_point_box_dist2(ax, ay, o1, o2, o3, o4), _point_box_dist2(bx, by, o1, o2, o3, o4))
    d2 = min(d2, _segment_offset2(o1, o2, ax, ay, bx, by))
    d2 = min(d2, _segment_offset2(o3, o2, ax, ay, bx, by))
    d2 = min(d2, _segment_offset2(o1, o4, ax, ay, bx, by))
    d2 = min(d2, _segment_offset2(o3, o4, ax, ay, bx, by))
    return math.sqrt(d2)


@nb.njit(cache=True, nogil=True, _nrt=False)
def segment_obstacle_dist(ax, ay, bx, by, ob):
    """Exact distance from segment AB to obstacle row ``ob`` (0 when they meet)."""
    return _obstacle_dist(ax, ay, bx, by, ob[0], ob[1], ob[2], ob[3], ob[4])


#: Relative slack of the obstacle pre-filter in :func:`_link_clearance` (times 1 + the
#: largest coordinate involved): a million times the rounding error of a distance.
SKIP_SLACK = 1e-9


@nb.njit(cache=True, nogil=True, inline="always")
def _link_clearance(ax, ay, bx, by, radius, obstacles):
    """Clearance of one link capsule (segment AB dilated by ``radius``) to all obstacles.

    An obstacle whose distance cannot be below the best so far is skipped, its distance not
    computed: the gap between the segment's bounding box and the obstacle's (a circle's
    centre, then its radius subtracted) is a lower bound of the exact distance, and the skip
    needs it to beat the best by ``SKIP_SLACK`` x the coordinates' scale, far above the
    rounding of a computed distance (and, for a box, of its crossing test): a skipped
    obstacle's computed distance would not have replaced the best. So the value is the one of
    computing every distance, bit for bit; only the time changes.
    """
    lox = min(ax, bx)
    hix = max(ax, bx)
    loy = min(ay, by)
    hiy = max(ay, by)
    seg_scale = max(abs(lox), abs(hix), abs(loy), abs(hiy))
    best = np.inf
    for o in range(obstacles.shape[0]):
        kind = obstacles[o, 0]
        o1 = obstacles[o, 1]
        o2 = obstacles[o, 2]
        o3 = obstacles[o, 3]
        o4 = obstacles[o, 4]
        if best < np.inf:
            if kind == 0.0:  # circle: centre (o1, o2), radius o3
                gx = max(lox - o1, 0.0, o1 - hix)
                gy = max(loy - o2, 0.0, o2 - hiy)
                reach = best + radius + o3
                scale = max(seg_scale, abs(o1), abs(o2), abs(o3))
            else:  # box [o1, o3] x [o2, o4]
                gx = max(o1 - hix, 0.0, lox - o3)
                gy = max(o2 - hiy, 0.0, loy - o4)
                reach = best + radius
                scale = max(seg_scale, abs(o1), abs(o2), abs(o3), abs(o4))
            reach += SKIP_SLACK * (1.0 + scale)
            if reach > 0.0 and gx * gx + gy * gy > reach * reach:
                continue
        d = _obstacle_dist(ax, ay, bx, by, kind, o1, o2, o3, o4) - radius
        if d < best:
            best = d
    return best


@nb.njit(cache=True, nogil=True, inline="always")
def _orient(ax, ay, bx, by, cx, cy):
    return (bx - ax) * (cy - ay) - (by - ay) * (cx - ax)


@nb.njit(cache=True, nogil=True, _nrt=False)
def segment_segment_dist(ax, ay, bx, by, cx, cy, dx, dy):
    """Exact distance between the closed segments AB and CD in the plane (0 when they meet).

    Disjoint segments: the closest pair involves an endpoint of one of them, so the distance is
    the smallest of four point-segment distances. Meeting is decided with exact orientation
    signs (collinear overlaps included), so touching segments give 0, not a rounding residue.
    """
    o1 = _orient(ax, ay, bx, by, cx, cy)
    o2 = _orient(ax, ay, bx, by, dx, dy)
    o3 = _orient(cx, cy, dx, dy, ax, ay)
    o4 = _orient(cx, cy, dx, dy, bx, by)
    if ((o1 > 0.0 and o2 < 0.0) or (o1 < 0.0 and o2 > 0.0)) and \
            ((o3 > 0.0 and o4 < 0.0) or (o3 < 0.0 and o4 > 0.0)):
        return 0.0
    d = _point_segment_dist(cx, cy, ax, ay, bx, by)
    d = min(d, _point_segment_dist(dx, dy, ax, ay, bx, by))
    d = min(d, _point_segment_dist(ax, ay, cx, cy, dx, dy))
    d = min(d, _point_segment_dist(bx, by, cx, cy, dx, dy))
    return d


@nb.njit(cache=True, nogil=True, _nrt=False)
def link_segments_into(P, q_deg, seg):
    """Every link of every arm as a segment ``seg[k] = (ax, ay, bx, by)`` (metres)."""
    _segments_into(P, q_deg, seg, False)


@nb.njit(cache=True, nogil=True, inline="always")
def _segments_into(P, q_deg, seg, obstacles_too):
    """Write every link's segment to ``seg``; with ``obstacles_too``, also return the smallest
    link-capsule to obstacle distance (:func:`_obstacle_clearance`'s arithmetic) from the same
    forward-kinematics pass (``inf`` otherwise)."""
    best = np.inf
    for a in range(P.arm_first.shape[0] - 1):
        x = P.bases[a, 0]
        y = P.bases[a, 1]
        theta = 0.0
        for k in range(P.arm_first[a], P.arm_first[a + 1]):
            nx, ny, theta = fk_step(x, y, theta, P.links[k], q_deg[k])
            seg[k, 0] = x
            seg[k, 1] = y
            seg[k, 2] = nx
            seg[k, 3] = ny
            if obstacles_too:
                best = min(best, _link_clearance(x, y, nx, ny, P.radii[a], P.obstacles))
            x = nx
            y = ny
    return best


@nb.njit(cache=True, nogil=True, _nrt=False)
def arm_arm_clearance(P, seg):
    """Smallest capsule-capsule distance between links of different arms (``inf``: one arm)."""
    best = np.inf
    n_arms = P.arm_first.shape[0] - 1
    for a in range(n_arms):
        for b in range(a + 1, n_arms):
            rr = P.radii[a] + P.radii[b]
            for k in range(P.arm_first[a], P.arm_first[a + 1]):
                for m in range(P.arm_first[b], P.arm_first[b + 1]):
                    d = segment_segment_dist(seg[k, 0], seg[k, 1], seg[k, 2], seg[k, 3],
                                             seg[m, 0], seg[m, 1], seg[m, 2], seg[m, 3]) - rr
                    if d < best:
                        best = d
    return best


@nb.njit(cache=True, nogil=True, _nrt=False)
def has_self_pairs(P):
    """Does some arm have two non-adjacent links (three links or more)?"""
    for a in range(P.arm_first.shape[0] - 1):
        if P.arm_first[a + 1] - P.arm_first[a] >= 3:
            return True
    return False


@nb.njit(cache=True, nogil=True, _nrt=False)
def self_clearance(P, seg):
    """Smallest capsule-capsule distance between non-adjacent links of one arm (``inf``: no arm
    has three links). Adjacent links share a joint and never count (module docstring)."""
    best = np.inf
    for a in range(P.arm_first.shape[0] - 1):
        rr = P.radii[a] + P.radii[a]
        for k in range(P.arm_first[a], P.arm_first[a + 1]):
            for m in range(k + 2, P.arm_first[a + 1]):
                d = segment_segment_dist(seg[k, 0], seg[k, 1], seg[k, 2], seg[k, 3],
                                         seg[m, 0], seg[m, 1], seg[m, 2], seg[m, 3]) - rr
                if d < best:
                    best = d
    return best


@nb.njit(cache=True, nogil=True, inline="always")
def n_distance_pairs(P):
    """Exact element distances one configuration costs: links x obstacles, link pairs of two
    arms and non-adjacent link pairs of one arm (the unit of ``P.work``)."""
    return P.links.shape[0] * P.obstacles.shape[0] + n_link_pairs(P)


@nb.njit(cache=True, nogil=True, inline="always")
def n_link_pairs(P):
    """Link pairs that can touch: pairs of links of two arms, and non-adjacent links of one
    arm (shared by the work count and ``signed.n_elements``)."""
    n = 0
    n_arms = P.arm_first.shape[0] - 1
    for a in range(n_arms):
        na = P.arm_first[a + 1] - P.arm_first[a]
        if na >= 3:
            n += (na - 1) * (na - 2) // 2
        for b in range(a + 1, n_arms):
            n += na * (P.arm_first[b + 1] - P.arm_first[b])
    return n


@nb.njit(cache=True, nogil=True, _nrt=True)
def clearance_kernel(P, q_deg):
    """Smallest distance between any link capsule and any obstacle, any other arm's capsule or
    a non-adjacent link of its own arm (<= 0: collision); ``inf`` with nothing to touch. Joint
    limits are not considered. Allocates a segment buffer only when there are link pairs
    (:func:`clearance_into` takes one instead).
    """
    if _has_link_pairs(P):
        best = _clearance_with_pairs(P, q_deg, np.empty((P.links.shape[0], 4)))
    else:
        best = _obstacle_clearance(P, q_deg)
    P.work[0] += n_distance_pairs(P)
    return best


@nb.njit(cache=True, nogil=True, _nrt=False)
def clearance_into(P, q_deg, seg):
    """:func:`clearance_kernel` with the link-segment buffer ``seg`` ``[L, 4]`` given: what the
    planners' loops call with their tree's buffer (:func:`edge_free_into`), allocating nothing.
    Same value, same work."""
    if _has_link_pairs(P):
        best = _clearance_with_pairs(P, q_deg, seg)
    else:
        best = _obstacle_clearance(P, q_deg)
    P.work[0] += n_distance_pairs(P)
    return best


@nb.njit(cache=True, nogil=True, inline="always")
def _has_link_pairs(P):
    """Two arms, or an arm of three links or more: link pairs that can touch."""
    return P.arm_first.shape[0] > 2 or has_self_pairs(P)


@nb.njit(cache=True, nogil=True, inline="always")
def _obstacle_clearance(P, q_deg):
    """Smallest link-capsule to obstacle distance (``inf``: no obstacle)."""
    best = np.inf
    for a in range(P.arm_first.shape[0] - 1):
        x = P.bases[a, 0]
        y = P.bases[a, 1]
        theta = 0.0
        for k in range(P.arm_first[a], P.arm_first[a + 1]):
            nx, ny, theta = fk_step(x, y, theta, P.links[k], q_deg[k])
            best = min(best, _link_clearance(x, y, nx, ny, P.radii[a], P.obstacles))
            x = nx
            y = ny
    return best


@nb.njit(cache=True, nogil=True, inline="always")
def _clearance_with_pairs(P, q_deg, seg):
    """``min(obstacle clearance, link-pair clearance)`` with the forward kinematics done once:
    the link-obstacle pass (:func:`_obstacle_clearance`'s arithmetic) writes each link's
    segment to ``seg`` as it goes (the same ``fk_step`` floats :func:`link_segments_into`
    gives), and the link pairs (:func:`_pair_clearance`) read them. Why:
    the two passes each computed every joint's sine and cosine, a third of a node check's time
    at 5-7 joints. Same value bit for bit (the same distances, combined by the same ``min``s)."""
    return min(_segments_into(P, q_deg, seg, True), _pair_clearance(P, seg))


@nb.njit(cache=True, nogil=True, inline="always")
def _pair_clearance(P, seg):
    """Smallest capsule-capsule distance of links of two arms, then of non-adjacent links of
    one arm (``inf``: none), for the link segments in ``seg``."""
    best = np.inf
    if P.arm_first.shape[0] > 2:
        best = min(best, arm_arm_clearance(P, seg))
    if has_self_pairs(P):
        best = min(best, self_clearance(P, seg))
    return best


@nb.njit(cache=True, nogil=True, inline="always")
def within_limits(limits_deg, q_deg):
    for j in range(q_deg.shape[0]):
        if q_deg[j] < limits_deg[j, 0] or q_deg[j] > limits_deg[j, 1]:
            return False
    return True


@nb.njit(cache=True, nogil=True, _nrt=False)
def config_free(P, q_deg, margin):
    """Within the joint limits and clearance strictly above ``margin``."""
    if not within_limits(P.limits, q_deg):
        return False
    return clearance_kernel(P, q_deg) > margin


@nb.njit(cache=True, nogil=True, _nrt=False)
def link_motion_bound(links, qa_deg, qb_deg, k, first=0):
    """``M_k``: no point of link ``k`` moves faster than this per unit ``s`` on ``qa -> qb``.

    ``M_k = Σ_{first <= j <= k} |Δq_j| · Σ_{i=j..k} l_i`` (Δq in radians; see the module
    docstring), where ``first`` is the index of the first joint of link ``k``'s arm (0 for one
    arm): joints of other arms do not move this link. A function of its own so that the bound
    the certified check relies on can be tested directly (tests/test_safety_bounds.py,
    tests/test_motion_bound_ndof.py): if it ever under-estimates the true motion, even by a few
    per cent, ``edge_free`` could step over an obstacle.
    """
    mk = 0.0
    for j in range(first, k + 1):
        tail = 0.0
        for i in range(j, k + 1):
            tail += links[i]
        mk += abs(math.radians(qb_deg[j] - qa_deg[j])) * tail
    return mk


@nb.njit(cache=True, nogil=True, _nrt=False)
def self_pair_motion_bound(links, qa_deg, qb_deg, k, m):
    """Lipschitz constant (m per unit ``s``) of the distance between links ``k < m`` of ONE arm
    (``m >= k + 2``) along ``qa -> qb``: ``link_motion_bound(links, qa, qb, m, first=k + 1)``.

    Proof. A distance between two sets is unchanged by a rigid motion of the plane applied to
    both, so measure it, at every ``s``, in the frame of link ``k`` (origin at its base, x along
    it). There link ``k`` is the fixed segment ``[0, l_k] x {0}``, and a point at fraction ``t``
    of link ``m`` is ``l_k e(0) + Σ_{k<i<m} l_i e(φ_i) + t l_m e(φ_m)`` with
    ``φ_i = Σ_{k<j<=i} q_j`` (``e(φ) = (cos φ, sin φ)``): only the joints ``k+1 .. m`` between
    the two links move it, each at the constant rate ``Δq_j`` (radians per unit ``s``). Its speed
    is at most ``Σ_{k<i<=m} l_i |φ_i'| <= Σ_{k<j<=m} |Δq_j| Σ_{i=j..m} l_i`` -- the motion bound
    of link ``m`` of the sub-arm that starts at joint ``k + 1``. A point moving that fast changes
    its distance to a fixed set no faster, and the distance between the fixed segment ``k`` and
    the moving segment ``m`` (a minimum over their points) is then Lipschitz with the same
    constant; the capsule radii subtract a constant. The joints before link ``k`` move both links
    rigidly together and do not count -- tighter than ``M_k + M_m`` (the bound for links of two
    arms), which would also be sound. ``edge_free`` steps by ``(d - clear) / this``.
    """
    return link_motion_bound(links, qa_deg, qb_deg, m, k + 1)


#: A blocked edge is rejected by a probe only while conservative advancement crawls: when its
#: next step would cover less than this fraction of what is left of the edge.
PROBE_CRAWL = 0.125
#: Probes an edge may spend that find free space, after which it only advances. Each failure
#: doubles how many stops the next probe waits (1, 3, 7, ...), so an edge that grazes an
#: obstacle without touching it pays a number of probes logarithmic in its crawl.
PROBE_BUDGET = 10


@nb.njit(cache=True, nogil=True, inline="always")
def probe_point(s, f, s1, f1, s0, f0, ds):
    """Where on ``[0, 1]`` to look for a collision ahead of the stop at ``s``, or -1.0 for
    nowhere (see :func:`edge_free`, *Blocked edges*).

    ``f``, ``f1`` and ``f0`` are the free distances (clearance minus the user's) at this stop
    and at the two before, at ``s1`` and ``s0`` (``f0 = inf``: none). Only while the arm
    approaches (``f < f1``) and conservative advancement crawls (``ds`` below ``PROBE_CRAWL``
    of the rest). The parabola through the three stops, when it opens upwards ahead of ``s``,
    predicts the deepest point of a grazing contact: the probe goes there when the parabola
    dips below zero, and nowhere when it predicts a free pass. Otherwise the line through the
    last two stops predicts contact at ``s + reach`` and the probe goes twice as far (into the
    obstacle when the arm heads into it). A probe stays short of the end, which is known free,
    and is only placed where contact is predicted before the end.
    """
    if not (ds < PROBE_CRAWL * (1.0 - s)):
        return -1.0
    if not (f < f1) or not (s > s1):
        return -1.0
    cap = 1.0
    if s1 > s0 and f0 < np.inf:
        d1 = (f1 - f0) / (s1 - s0)
        d2 = (f - f1) / (s - s1)
        curve = (d2 - d1) / (s - s0)
        if curve > 0.0:
            vertex = 0.5 * (s0 + s1) - d1 / (2.0 * curve)
            if vertex > s:
                deepest = f0 + d1 * (vertex - s0) + curve * (vertex - s0) * (vertex - s1)
                if not (deepest < 0.0):
                    return -1.0
                cap = vertex
    reach = f * (s - s1) / (f1 - f)
    if not (s + reach < 1.0):
        return -1.0
    return min(s + 2.0 * reach, 0.5 * (s + reach + 1.0), cap)


@nb.njit(cache=True, nogil=True, inline="always")
def probe_start(probe):
    """A fresh probe schedule for one edge: ``(s1, f1, s0, f0, failed, wait)``, the last two
    stops (none yet), the probes that found free space and the stops to wait before the next.
    ``probe=False`` starts it spent: conservative advancement alone."""
    return 0.0, np.inf, 0.0, np.inf, 0 if probe else PROBE_BUDGET, 0


@nb.njit(cache=True, nogil=True, inline="always")
def probe_next(sched, s, f, ds):
    """At a stop ``s`` with free distance ``f`` and advance ``ds``: where to probe (-1.0:
    nowhere; :func:`probe_point`) and the schedule with this stop remembered."""
    s1, f1, s0, f0, failed, wait = sched
    if failed >= PROBE_BUDGET:
        return -1.0, sched
    at = probe_point(s, f, s1, f1, s0, f0, ds) if wait == 0 else -1.0
    return at, (s, f, s1, f1, failed, max(wait - 1, 0))


@nb.njit(cache=True, nogil=True, inline="always")
def probe_missed(sched):
    """The schedule after a probe found free space: one more failure, and the next probe waits
    ``2 ** failed - 1`` stops."""
    s1, f1, s0, f0, failed, _ = sched
    return s1, f1, s0, f0, failed + 1, (1 << (failed + 1)) - 1


@nb.njit(cache=True, nogil=True, inline="always")
def two_link_clearances(P, q0_deg, q1_deg):
    """Clearance of each link of ONE two-link arm (``P`` has one arm of two links) at the joint
    angles ``(q0_deg, q1_deg)``: :func:`clearance_kernel`'s per-link values, same arithmetic,
    without counting work. ``clearance_kernel`` is ``min(min(inf, c0), c1)`` of them."""
    x = P.bases[0, 0]
    y = P.bases[0, 1]
    nx, ny, theta = fk_step(x, y, 0.0, P.links[0], q0_deg)
    c0 = _link_clearance(x, y, nx, ny, P.radii[0], P.obstacles)
    mx, my, theta = fk_step(nx, ny, theta, P.links[1], q1_deg)
    c1 = _link_clearance(nx, ny, mx, my, P.radii[0], P.obstacles)
    return c0, c1


@nb.njit(cache=True, nogil=True, inline="always")
def _fold(d, mk, clear, cmin, ds):
    """Fold one finite clearance ``d`` (metres, with ``clear`` required) whose bodies move at
    most ``mk`` metres per unit of ``s`` into a stop's running ``(cmin, ds)``. The one place the
    safe advance ``(d - clear) / mk`` is computed: a stop of the one-two-link-arm path
    (:func:`edge_free_two_link`), one measured (:func:`_edge_stop`) and one read from its record
    (:func:`_stored_stop`) go through the very same arithmetic."""
    if d < cmin:
        cmin = d
    if mk > 0.0:
        step = (d - clear) / mk
        if step < ds:
            ds = step
    return cmin, ds


@nb.njit(cache=True, nogil=True, _nrt=False)
def edge_free_two_link(P, qa_deg, qb_deg, margin, ca0, ca1, cb0, cb1, probe=True):
    """:func:`edge_free` for ONE arm of two links (the only single-arm case without self
    pairs: every 2-DOF problem), given the per-link clearances at the ends when known.

    ``(ca0, ca1)`` at ``qa`` and ``(cb0, cb1)`` at ``qb`` (:func:`two_link_clearances`; ``NaN``
    in the first of a pair: not known, measured here). An edge's first stop is ``qa`` and its
    last is ``qb``, both bit for bit (``qa + 0 * (qb - qa) == qa``, and the last stop takes
    ``qb`` itself), so a planner that measured its nodes passes their values instead of having
    them measured again. Same stops, same verdict, same ``P.work`` as :func:`edge_free` (every
    stop counts, measured here or given), and no allocation. It probes blocked edges like
    :func:`edge_free` (``probe=False``: conservative advancement alone, for tests).

    Returns ``(free, c0, c1)``: the verdict and the per-link clearances at ``qa`` (as given,
    or as measured at the first stop; ``NaN`` when the check ended before measuring them).
    """
    if P.obstacles.shape[0] == 0:
        return True, ca0, ca1
    clear = P.clearance
    if margin < clear:
        return False, ca0, ca1
    m0 = link_motion_bound(P.links, qa_deg, qb_deg, 0, 0)
    m1 = link_motion_bound(P.links, qa_deg, qb_deg, 1, 0)
    per_stop = n_distance_pairs(P)
    s = 0.0
    first = True
    sched = probe_start(probe)
    while True:
        P.work[0] += per_stop
        if s >= 1.0 and cb0 == cb0:
            c0 = cb0
            c1 = cb1
        elif first and ca0 == ca0:
            c0 = ca0
            c1 = ca1
        else:
            q0 = qa_deg[0] + s * (qb_deg[0] - qa_deg[0])
            q1 = qa_deg[1] + s * (qb_deg[1] - qa_deg[1])
            if s >= 1.0:
                q0 = qb_deg[0]
                q1 = qb_deg[1]
            c0, c1 = two_link_clearances(P, q0, q1)
            if first:
                ca0 = c0
                ca1 = c1
        first = False
        # edge_free's per-link checks, link 0 then link 1
        if not c0 < np.inf:
            return False, ca0, ca1
        cmin, ds = _fold(c0, m0, clear, np.inf, np.inf)
        if not c1 < np.inf:
            return False, ca0, ca1
        cmin, ds = _fold(c1, m1, clear, cmin, ds)
        if cmin <= margin:
            return False, ca0, ca1
        if s >= 1.0:
            return True, ca0, ca1
        at, sched = probe_next(sched, s, cmin - clear, ds)
        if at > 0.0:
            P.work[0] += per_stop
            p0, p1 = two_link_clearances(P, qa_deg[0] + at * (qb_deg[0] - qa_deg[0]),
                                         qa_deg[1] + at * (qb_deg[1] - qa_deg[1]))
            if p0 <= clear or p1 <= clear:
                return False, ca0, ca1
            sched = probe_missed(sched)
        s += ds
        if s > 1.0:
            s = 1.0


@nb.njit(cache=True, nogil=True, inline="always")
def _edge_stop(P, qa_deg, qb_deg, s, mks, msf, seg, clear, n_arms, need_seg, has_obstacles,
               has_self, rows, r):
    """One stop of :func:`edge_free` at ``q(s)``: ``(finite, cmin, ds)``, the smallest clearance
    of any pair of bodies there and the safe advance it buys (``min (c - clear) / M`` over the
    pairs). ``finite`` is False when a clearance came out infinite or NaN with something to
    touch: the arithmetic overflowed, and an infinite step would skip the segment.

    With ``r >= 0`` every value measured is also written to ``rows[r, 1:]`` in the order
    measured (each link against the obstacles, then the link pairs of two arms, then those of
    one arm: :func:`stop_width`), which is the order :func:`_stored_stop` reads them back in."""
    obstacles = P.obstacles
    cmin = np.inf
    ds = np.inf
    col = 1 + P.links.shape[0]  # the next link pair's column (links take 1 .. L)
    for a in range(n_arms):
        x = P.bases[a, 0]
        y = P.bases[a, 1]
        theta = 0.0
        for k in range(P.arm_first[a], P.arm_first[a + 1]):
            qk = qa_deg[k] + s * (qb_deg[k] - qa_deg[k])
            if s >= 1.0:
                qk = qb_deg[k]
            nx, ny, theta = fk_step(x, y, theta, P.links[k], qk)
            if need_seg:
                seg[k, 0] = x
                seg[k, 1] = y
                seg[k, 2] = nx
                seg[k, 3] = ny
            if has_obstacles:
                ck = _link_clearance(x, y, nx, ny, P.radii[a], obstacles)
                if r >= 0:
                    rows[r, 1 + k] = ck
                if not ck < np.inf:
                    return False, cmin, ds
                cmin, ds = _fold(ck, mks[k], clear, cmin, ds)
            x = nx
            y = ny
    if n_arms > 1:
        for a in range(n_arms):
            for b in range(a + 1, n_arms):
                rr = P.radii[a] + P.radii[b]
                for k in range(P.arm_first[a], P.arm_first[a + 1]):
                    mka = mks[k]
                    for m in range(P.arm_first[b], P.arm_first[b + 1]):
                        d = segment_segment_dist(seg[k, 0], seg[k, 1], seg[k, 2], seg[k, 3],
                                                 seg[m, 0], seg[m, 1], seg[m, 2],
                                                 seg[m, 3]) - rr
                        if r >= 0:
                            rows[r, col] = d
                        col += 1
                        if not d < np.inf:
                            return False, cmin, ds
                        cmin, ds = _fold(d, mka + mks[m], clear, cmin, ds)
    if has_self:
        for a in range(n_arms):
            rr = P.radii[a] + P.radii[a]
            for k in range(P.arm_first[a], P.arm_first[a + 1]):
                for m in range(k + 2, P.arm_first[a + 1]):
                    d = segment_segment_dist(seg[k, 0], seg[k, 1], seg[k, 2], seg[k, 3],
                                             seg[m, 0], seg[m, 1], seg[m, 2], seg[m, 3]) - rr
                    if r >= 0:
                        rows[r, col] = d
                    col += 1
                    if not d < np.inf:
                        return False, cmin, ds
                    cmin, ds = _fold(d, msf[k, m], clear, cmin, ds)
    return True, cmin, ds


@nb.njit(cache=True, nogil=True, inline="always")
def _stored_stop(P, rows, r, mks, msf, clear, n_arms, has_obstacles, has_self):
    """:func:`_edge_stop` from the values it wrote to ``rows[r]`` at the same configuration:
    the same ``(finite, cmin, ds)`` bit for bit (the same floats, met in the same order, go
    through the same comparisons and divisions), without the forward kinematics and the
    distances. Only for a row whose column 0 is 1.0 (complete: :func:`node_stop_into`)."""
    cmin = np.inf
    ds = np.inf
    if has_obstacles:
        for k in range(P.links.shape[0]):
            ck = rows[r, 1 + k]
            if not ck < np.inf:
                return False, cmin, ds
            cmin, ds = _fold(ck, mks[k], clear, cmin, ds)
    col = 1 + P.links.shape[0]
    if n_arms > 1:
        for a in range(n_arms):
            for b in range(a + 1, n_arms):
                for k in range(P.arm_first[a], P.arm_first[a + 1]):
                    mka = mks[k]
                    for m in range(P.arm_first[b], P.arm_first[b + 1]):
                        d = rows[r, col]
                        col += 1
                        if not d < np.inf:
                            return False, cmin, ds
                        cmin, ds = _fold(d, mka + mks[m], clear, cmin, ds)
    if has_self:
        for a in range(n_arms):
            for k in range(P.arm_first[a], P.arm_first[a + 1]):
                for m in range(k + 2, P.arm_first[a + 1]):
                    d = rows[r, col]
                    col += 1
                    if not d < np.inf:
                        return False, cmin, ds
                    cmin, ds = _fold(d, msf[k, m], clear, cmin, ds)
    return True, cmin, ds


@nb.njit(cache=True, nogil=True, inline="always")
def stop_width(P):
    """Columns of one configuration's stop record (:func:`node_stop_into`): a flag (1.0: the
    record is complete), each link's clearance from the obstacles, each link pair's distance
    (pairs of two arms, then non-adjacent pairs of one arm, in :func:`_edge_stop`'s order)."""
    return 1 + P.links.shape[0] + n_link_pairs(P)


@nb.njit(cache=True, nogil=True, _nrt=False)
def stop_record_into(P, q_deg, seg, mks, msf, rows, r):
    """Measure the stop record of ``q_deg`` into ``rows[r]`` (:func:`node_stop_into`) and return
    ``(finite, cmin)``; column 0 becomes 1.0 only when the record is complete. Counts no work:
    the stop it stands for counts where a check takes it (:func:`edge_free_rows`)."""
    n_arms = P.arm_first.shape[0] - 1
    has_self = has_self_pairs(P)
    rows[r, 0] = np.nan
    finite, cmin, _ = _edge_stop(P, q_deg, q_deg, 1.0, mks, msf, seg, 0.0, n_arms,
                                 n_arms > 1 or has_self, P.obstacles.shape[0] > 0, has_self,
                                 rows, r)
    if finite:
        rows[r, 0] = 1.0
    return finite, cmin


@nb.njit(cache=True, nogil=True, _nrt=False)
def node_stop_into(P, q_deg, seg, mks, msf, rows, r):
    """:func:`clearance_into` (the same value, the same work) that also keeps in ``rows[r]``
    what an edge stop at ``q_deg`` measures (:func:`stop_width` columns), so that the certified
    check of an edge that starts or ends at this configuration takes that stop from the record
    (:func:`edge_free_rows`) instead of measuring it again.

    Why: a planner checks a new node, then the edge to it, whose first stop is the node it
    grows from (checked when it was added) and whose last stop is the new node itself; on
    3-7 joints an extension measures ~4-8 stops, so these two are a large share of them. The
    values are measured by :func:`_edge_stop` itself, at ``s = 1`` of the edge ``q -> q`` (the
    last stop takes ``qb`` as given, as every edge's does); their minimum is
    :func:`clearance_into`'s value (a minimum of the same floats). When one came out infinite
    or NaN the record stays incomplete (column 0 NaN) and the value is measured as
    :func:`clearance_into` measures it. ``seg``, ``mks`` and ``msf`` are the tree's scratch
    (:func:`edge_free_into`'s; the advance a stop computes from ``mks``/``msf`` is not used
    here, so their values do not matter).
    """
    finite, cmin = stop_record_into(P, q_deg, seg, mks, msf, rows, r)
    P.work[0] += n_distance_pairs(P)
    if finite:
        return cmin
    if _has_link_pairs(P):
        return _clearance_with_pairs(P, q_deg, seg)
    return _obstacle_clearance(P, q_deg)


@nb.njit(cache=True, nogil=True, _nrt=False)
def edge_free(P, qa_deg, qb_deg, margin):
    """Certified check of the straight joint segment ``qa -> qb`` (conservative advancement).

    Returns True only if every configuration on the segment keeps clearance >= ``P.clearance``
    (the user clearance; > 0 when that is 0) and the sampled stops keep clearance > ``margin``,
    against obstacles, between arms and between non-adjacent links of one arm. Both endpoints
    must be within the joint limits already (the box is convex, so the whole segment then is).
    See the module docstring; for two links of different arms the Lipschitz constant of their
    distance is the sum of the two links' motion bounds, each from its own arm's joints; for two
    links of one arm it is :func:`self_pair_motion_bound`. A ``margin`` below ``P.clearance``
    (an inconsistent call: the steps would go backwards) certifies nothing.

    **Blocked edges** are rejected early. Approaching an obstacle, conservative advancement
    crawls: each step is the clearance over the motion bound, and the clearance shrinks with
    every step, so reaching the margin can take hundreds of stops. While it crawls, a probe
    measures one configuration further on (:func:`probe_point`); a probe whose clearance is at
    most the user's (a link touching, for clearance 0) proves the edge is not free -- a
    certified edge keeps more than that everywhere -- so the edge is rejected there. A probe
    that finds free space changes nothing: the advancement goes on from its own stop. The
    verdict is therefore exactly :func:`edge_free_unprobed`'s (tests/test_blocked_edges.py);
    only the work to reach a rejection shrinks, and ``P.work`` counts the probes too.
    """
    return _edge_free(P, qa_deg, qb_deg, margin, True)


@nb.njit(cache=True, nogil=True, _nrt=False)
def edge_free_unprobed(P, qa_deg, qb_deg, margin):
    """:func:`edge_free` by conservative advancement alone, without probes: the reference its
    verdicts must equal (tests) and the baseline its work is measured against (benchmarks)."""
    return _edge_free(P, qa_deg, qb_deg, margin, False)


@nb.njit(cache=True, nogil=True, _nrt=True)
def _edge_free(P, qa_deg, qb_deg, margin, probe):
    n = P.links.shape[0]
    if n == 2 and P.arm_first.shape[0] == 2:  # one two-link arm: no buffers needed
        nan = np.nan
        return edge_free_two_link(P, qa_deg, qb_deg, margin, nan, nan, nan, nan, probe)[0]
    seg = np.empty((n, 4))
    return _edge_free_into(P, qa_deg, qb_deg, margin, probe, seg, np.empty(n), np.empty((n, n)),
                           seg, -1, -1)


@nb.njit(cache=True, nogil=True, _nrt=False)
def edge_free_into(P, qa_deg, qb_deg, margin, seg, mks, msf):
    """:func:`edge_free` with its buffers given (``seg`` ``[L, 4]``, ``mks`` ``[L]``, ``msf``
    ``[L, L]``, ``L`` links in all; a tree's ``seg``/``mks``/``msf``): the planners' loops call
    it once per extension and allocate nothing. Same verdict, same work."""
    return _edge_free_into(P, qa_deg, qb_deg, margin, True, seg, mks, msf, seg, -1, -1)


@nb.njit(cache=True, nogil=True, inline="always")
def edge_free_rows(P, qa_deg, qb_deg, margin, seg, mks, msf, rows, ra, rb):
    """:func:`edge_free_into` given the stop records of its ends (:func:`node_stop_into`):
    ``rows[ra]`` of ``qa`` and ``rows[rb]`` of ``qb`` (``-1``, or a record whose column 0 is
    not 1.0: not known, measured). The first stop is ``qa`` bit for bit (``qa + 0 (qb - qa)``)
    and the last takes ``qb`` itself, so a known end is taken from its record
    (:func:`_stored_stop`). Same stops, same verdict, same ``P.work`` (a stop counts whether
    measured or taken from a record, as in :func:`edge_free_two_link`)."""
    return _edge_free_into(P, qa_deg, qb_deg, margin, True, seg, mks, msf, rows, ra, rb)


@nb.njit(cache=True, nogil=True, _nrt=False)
def _edge_free_into(P, qa_deg, qb_deg, margin, probe, seg, mks, msf, rows, ra, rb):
    n_arms = P.arm_first.shape[0] - 1
    if n_arms == 1 and P.links.shape[0] == 2:  # one two-link arm: no arrays needed
        nan = np.nan
        return edge_free_two_link(P, qa_deg, qb_deg, margin, nan, nan, nan, nan, probe)[0]
    has_obstacles = P.obstacles.shape[0] > 0
    has_self = has_self_pairs(P)
    if not has_obstacles and n_arms == 1 and not has_self:
        return True
    # The user clearance (exactly 0.0 for the default margin: clearance_of_margin).
    clear = P.clearance
    if margin < clear:
        return False
    need_seg = n_arms > 1 or has_self
    # The motion bounds depend only on the segment: computed once, not at every stop.
    for a in range(n_arms):
        first = P.arm_first[a]
        for k in range(first, P.arm_first[a + 1]):
            mks[k] = link_motion_bound(P.links, qa_deg, qb_deg, k, first)
    # Self pairs (k, m >= k + 2 of one arm): their relative motion bound, in msf[k, m].
    if has_self:
        for a in range(n_arms):
            for k in range(P.arm_first[a], P.arm_first[a + 1]):
                for m in range(k + 2, P.arm_first[a + 1]):
                    msf[k, m] = self_pair_motion_bound(P.links, qa_deg, qb_deg, k, m)
    per_stop = n_distance_pairs(P)
    s = 0.0
    sched = probe_start(probe)
    known_a = ra >= 0 and rows[ra, 0] == 1.0
    known_b = rb >= 0 and rows[rb, 0] == 1.0
    while True:
        P.work[0] += per_stop
        # Per-pair clearance at q(s) and the safe advance it buys.
        if s >= 1.0 and known_b:
            finite, cmin, ds = _stored_stop(P, rows, rb, mks, msf, clear, n_arms,
                                            has_obstacles, has_self)
        elif s == 0.0 and known_a:
            finite, cmin, ds = _stored_stop(P, rows, ra, mks, msf, clear, n_arms,
                                            has_obstacles, has_self)
        else:
            finite, cmin, ds = _edge_stop(P, qa_deg, qb_deg, s, mks, msf, seg, clear, n_arms,
                                          need_seg, has_obstacles, has_self, rows, -1)
        if not finite:
            return False
        if cmin <= margin:
            return False
        if s >= 1.0:
            return True
        at, sched = probe_next(sched, s, cmin - clear, ds)
        if at > 0.0:
            P.work[0] += per_stop
            finite, c_at, _ = _edge_stop(P, qa_deg, qb_deg, at, mks, msf, seg, clear, n_arms,
                                         need_seg, has_obstacles, has_self, rows, -1)
            if finite and c_at <= clear:
                return False
            sched = probe_missed(sched)
        s += ds
        if s > 1.0:
            s = 1.0


@nb.njit(cache=True, nogil=True, _nrt=False)
def nearest_obstacle_from_point(px, py, obstacles):
    """Distance (to the surface, 0 inside) and direction in [0, 2π) of the nearest obstacle.

    Returns ``(inf, 0.0, -1)`` without obstacles. The direction points from the point to the
    nearest surface point (to the centre when the point is inside). Ties go to the first.
    """
    best = np.inf
    angle = 0.0
    index = -1
    for o in range(obstacles.shape[0]):
        ob = obstacles[o]
        if ob[0] == 0.0:
            vx = ob[1] - px
            vy = ob[2] - py
            d = math.sqrt(vx * vx + vy * vy) - ob[3]
            if d < 0.0:
                d = 0.0
        else:
            qx = min(max(px, ob[1]), ob[3])
            qy = min(max(py, ob[2]), ob[4])
            vx = qx - px
            vy = qy - py
            d = math.sqrt(vx * vx + vy * vy)
            if d == 0.0:
                vx = 0.5 * (ob[1] + ob[3]) - px
                vy = 0.5 * (ob[2] + ob[4]) - py
        if d < best:
            best = d
            index = o
            a = math.atan2(vy, vx)
            if a < 0.0:
                a += _TWO_PI
            if a >= _TWO_PI:
                a -= _TWO_PI
            angle = a
    return best, angle, index


@nb.njit(cache=True, nogil=True, _nrt=False)
def nearest_obstacle_for_arm(P, arm, q_deg, px, py):
    """:func:`nearest_obstacle_from_point` for a point of arm ``arm``, where the other arms'
    link capsules count as obstacles too (a second arm is an obstacle to the first).

    Returns ``(distance, angle, index)``; ``index`` is ``-1 - k`` when the nearest thing is
    link ``k`` of another arm. With one arm it is exactly :func:`nearest_obstacle_from_point`.
    """
    best, angle, index = nearest_obstacle_from_point(px, py, P.obstacles)
    n_arms = P.arm_first.shape[0] - 1
    if n_arms == 1:
        return best, angle, index
    for b in range(n_arms):
        if b == arm:
            continue
        x = P.bases[b, 0]
        y = P.bases[b, 1]
        theta = 0.0
        for k in range(P.arm_first[b], P.arm_first[b + 1]):
            nx, ny, theta = fk_step(x, y, theta, P.links[k], q_deg[k])
            vx, vy = _segment_offset(px, py, x, y, nx, ny)
            d = math.sqrt(vx * vx + vy * vy) - P.radii[b]
            if d < 0.0:
                d = 0.0
            if d < best:
                best = d
                index = -1 - k
                a = math.atan2(vy, vx)
                if a < 0.0:
                    a += _TWO_PI
                if a >= _TWO_PI:
                    a -= _TWO_PI
                angle = a
            x = nx
            y = ny
    return best, angle, index


@nb.njit(cache=True, nogil=True, _nrt=False)
def direction_and_distance(px, py, tx, ty):
    """Distance from P to T and the direction of T seen from P, wrapped to [0, 2π)."""
    vx = tx - px
    vy = ty - py
    a = math.atan2(vy, vx)
    if a < 0.0:
        a += _TWO_PI
    if a >= _TWO_PI:
        a -= _TWO_PI
    return math.sqrt(vx * vx + vy * vy), a


# ----------------------------------------------------------------------------------------------
# Python-level conveniences (tests, CLI, reports). Not for hot loops.
# ----------------------------------------------------------------------------------------------

def clearance(arrays, q_deg) -> float:
    """Clearance of configuration ``q_deg`` in a :class:`ScenarioArrays` (<= 0: collision),
    against obstacles, between arms and between non-adjacent links of one arm."""
    return float(clearance_kernel(arrays.problem(CERT_MARGIN_M),
                                  np.asarray(q_deg, dtype=np.float64)))


def self_contact(arrays, q_deg) -> tuple[float, int, int]:
    """``(clearance, k, m)``: the closest pair of non-adjacent links of one arm at ``q_deg``
    (global link indices, ``k < m``; ``(inf, -1, -1)`` when no arm has three links). A
    clearance <= 0 is a self-collision; the scenario loader names the pair with it."""
    P = arrays.problem(CERT_MARGIN_M)
    q = np.asarray(q_deg, dtype=np.float64)
    seg = np.empty((P.links.shape[0], 4))
    link_segments_into(P, q, seg)
    best, bk, bm = math.inf, -1, -1
    for a in range(P.arm_first.shape[0] - 1):
        rr = P.radii[a] + P.radii[a]
        for k in range(P.arm_first[a], P.arm_first[a + 1]):
            for m in range(k + 2, P.arm_first[a + 1]):
                d = float(segment_segment_dist(*seg[k], *seg[m])) - rr
                if d < best:
                    best, bk, bm = d, k, m
    return best, bk, bm


def in_collision(arrays, q_deg) -> bool:
    """True when ``q_deg`` violates a joint limit or a link touches an obstacle, another arm or
    a non-adjacent link of its own arm."""
    q = np.asarray(q_deg, dtype=np.float64)
    if not within_limits(arrays.limits_deg, q):
        return True
    return clearance(arrays, q) <= 0.0


def effective_margin(clearance_m: float = 0.0) -> float:
    """The ``margin`` every kernel takes for a user clearance of ``clearance_m`` metres.

    ``CERT_MARGIN_M + clearance_m``: configurations must keep more than that, and
    :func:`edge_free` certifies at least ``clearance_m`` along every segment (module
    docstring). ``effective_margin(0.0) == CERT_MARGIN_M`` exactly, so the default changes
    nothing. Raises :class:`~xfuzzy_rrt.errors.InputError` (``--clearance``) for a negative,
    non-finite or absurd value.
    """
    check_clearance(clearance_m)
    return CERT_MARGIN_M + float(clearance_m)


def check_clearance(clearance_m, where: str = "--clearance") -> float:
    """``clearance_m`` as a float in ``[0, MAX_CLEARANCE_M]`` or one InputError naming ``where``."""
    if isinstance(clearance_m, bool) or not isinstance(clearance_m, (int, float, np.floating)):
        raise InputError(where, f"must be a number of metres, got {clearance_m!r}")
    c = float(clearance_m)
    if not (math.isfinite(c) and 0.0 <= c <= MAX_CLEARANCE_M):
        raise InputError(where, f"must be a clearance in metres within [0, {MAX_CLEARANCE_M:g}], "
                         f"got {clearance_m!r}")
    return c


def segment_free(arrays, qa_deg, qb_deg, margin: float = CERT_MARGIN_M) -> bool:
    """Certified: True only if the whole joint segment is collision-free."""
    qa = np.asarray(qa_deg, dtype=np.float64)
    qb = np.asarray(qb_deg, dtype=np.float64)
    if not (within_limits(arrays.limits_deg, qa) and within_limits(arrays.limits_deg, qb)):
        return False
    return bool(edge_free(arrays.problem(margin), qa, qb, float(margin)))


def end_effector_obstacle(arrays, q_deg, arm: int = 0) -> tuple[float, float]:
    """``(distance, angle)`` from arm ``arm``'s end effector to the nearest obstacle surface
    (other arms' capsules included): the paper's fuzzy inputs for that arm."""
    from xfuzzy_rrt.geometry.kinematics import arm_end_effector

    problem = arrays.problem(CERT_MARGIN_M)
    q = np.asarray(q_deg, dtype=np.float64)
    ex, ey = arm_end_effector(problem, arm, q)
    d, a, _ = nearest_obstacle_for_arm(problem, arm, q, ex, ey)
    return float(d), float(a)
