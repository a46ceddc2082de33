"""The user's clearance margin: where it comes from, what it forbids, and how much a path keeps.

A surgeon states a clearance (metres): every point of every link capsule must keep at least
that much from every obstacle along the whole motion. It comes from ``--clearance`` when given,
else from the scenario's ``[safety] clearance_m``, else 0 (:func:`resolve_clearance`). The
planners turn it into the one ``margin`` their kernels carry
(:func:`~xfuzzy_rrt.geometry.collision.effective_margin`), which the certified edge check then
holds *between* its stops as well (see ``collision.py``). A start or goal already closer than
the clearance makes the problem unsolvable by definition, so it is refused up front with one
line naming where the clearance came from (:func:`planning_margin`).

:func:`path_min_clearance` measures what a path actually keeps: the exact smallest signed
distance between any link capsule and any obstacle over *every* configuration of the path (not
only its vertices), where it occurs, and a proven lower bound. It is a branch and bound on each
segment with two lower bounds per element (a link against the obstacles, a link pair of two
arms, two non-adjacent links of one arm), the larger of which counts:

- first order (Lipschitz): along ``q(s) = qa + s (qb - qa)`` the element's clearance changes no
  faster than ``V`` per unit ``s`` (how fast the two bodies' points move against each other),
  so on ``[s0, s1]`` with end values ``c0, c1`` nothing is below ``(c0 + c1 - V (s1 - s0)) / 2``
  -- the two-sided form of conservative advancement;
- second order (curvature): while the bodies stay apart the clearance is a minimum of smooth
  point-to-point distances whose second derivative is at most ``K = A + V² / D`` (``A`` bounds
  the points' relative acceleration, ``D`` their distance), so it lies above its chord minus
  ``K/2 (s - s0)(s1 - s)`` (:func:`element_lower_bound`).

The second bound is what closes *flat* minima: two links of a straight arm one link apart stay
exactly ``l`` apart (the two ends of the link between them) while a joint between them turns,
so the clearance is constant over the whole segment; proving that to ``tol`` takes intervals of
``2 tol / V`` with the first bound alone (millions of evaluations at 0.1 µm: the budget ran out
before) but ``sqrt(8 tol / K)`` with the second (thousands). Intervals that cannot beat the
best value seen by more than ``tol`` are dropped, the others halved.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.collision import (
    CERT_MARGIN_M,
    MIN_CLEARANCE_TOL_M,
    check_clearance,
    clearance_kernel,
    effective_margin,
    has_self_pairs,
)
from xfuzzy_rrt.geometry.signed import element_clearances, n_elements

#: Configurations evaluated per path after which the search reports its proven lower bound
#: instead (a safety net: with the curvature bound no known path comes near it).
MIN_CLEARANCE_MAX_EVALS = 2_000_000


def resolve_clearance(scenario, clearance_m: float | None = None) -> float:
    """The clearance in force: ``clearance_m`` when given (``--clearance``), else the scenario's
    ``[safety] clearance_m`` (read with ``getattr`` so older scenario objects mean 0), else 0."""
    if clearance_m is not None:
        return check_clearance(clearance_m, "--clearance")
    own = getattr(scenario, "clearance_m", 0.0)
    where = f"{getattr(scenario, 'source', '') or getattr(scenario, 'name', 'scenario')}: safety.clearance_m"
    return check_clearance(own if own is not None else 0.0, where)


def with_clearance(scenario, clearance_m: float | None):
    """``scenario`` with its clearance set to ``clearance_m`` (``None``: unchanged).

    How ``--clearance`` reaches code that only sees scenarios (the bench runner, training):
    every planner then resolves it from the scenario. Validated here (``--clearance``).
    """
    import dataclasses

    if clearance_m is None:
        return scenario
    c = check_clearance(clearance_m, "--clearance")
    if any(f.name == "clearance_m" for f in dataclasses.fields(scenario)):
        return dataclasses.replace(scenario, clearance_m=c)
    copy = dataclasses.replace(scenario)  # a Scenario without the field (older model)
    object.__setattr__(copy, "clearance_m", c)
    return copy


def planning_margin(scenario, clearance_m: float | None = None,
                    margin: float | None = None) -> float:
    """The kernels' ``margin`` for planning ``scenario`` with the clearance in force.

    ``margin`` (an explicit kernel margin, as tests and older callers pass) wins when given and
    no clearance is asked for. Otherwise the clearance is resolved (:func:`resolve_clearance`)
    and the start and goal must keep more than it: an InputError names ``--clearance`` or the
    scenario file, whichever set the clearance. With no clearance anywhere the result is exactly
    ``CERT_MARGIN_M``, today's margin.
    """
    if margin is not None and clearance_m is None:
        return float(margin)
    c = resolve_clearance(scenario, clearance_m)
    m = effective_margin(c)
    if c > 0.0:
        check_endpoints_keep(scenario, c, m, "--clearance" if clearance_m is not None else
                             f"{scenario.source or scenario.name}: safety.clearance_m")
    return m


def check_endpoints_keep(scenario, clearance_m: float, margin: float, where: str) -> None:
    """Raise one InputError when the start or the goal is within ``margin`` of an obstacle."""
    a = scenario.arrays()
    for label, q in (("start", a.start_deg), ("goal", a.goal_deg)):
        c = float(clearance_kernel(a.problem(margin), q))
        if not c > margin:
            raise InputError(where, f"the {label} configuration is {_mm(c)} from an obstacle "
                             f"or link, closer than the clearance {_mm(clearance_m)}: no path "
                             f"can keep it")


def _mm(x: float) -> str:
    return f"{x * 1e3:.4g} mm"


@dataclass(frozen=True)
class MinClearance:
    """The smallest signed clearance of a path (negative: penetration depth) and where."""

    #: Exact signed distance (m) at ``config_deg``; ``inf`` without obstacles, ``nan`` for an
    #: empty path.
    value_m: float
    #: Segment ``path[i] -> path[i + 1]`` it lies on (0 for a one-point path; -1 for none).
    segment: int
    #: Position on that segment, in [0, 1].
    s: float
    #: The configuration (degrees) where it occurs.
    config_deg: tuple[float, ...]
    #: No configuration on the path is closer than this (``value_m - tol`` unless the
    #: evaluation budget ran out).
    lower_bound_m: float


@nb.njit(cache=True, nogil=True, _nrt=True)
def _chain_speed_accel(links, qa_deg, qb_deg, first, last):
    """``(V, A)`` of the last link of the chain ``first .. last`` measured in the frame the
    chain hangs from (the world for an arm's own base, link ``first - 1`` for a self pair).

    Along ``qa -> qb`` every joint turns at the constant rate ``dq_j`` (radians per unit
    ``s``), so link ``i``'s angle in that frame turns at exactly ``w_i = Σ_{first<=j<=i} dq_j``
    and a point of link ``last`` (``Σ l_i e(θ_i)``, the last term scaled by a fraction) has
    velocity ``Σ l_i w_i e'(θ_i)`` and acceleration ``-Σ l_i w_i² e(θ_i)``: its speed is at
    most ``V = Σ l_i |w_i|`` and its acceleration at most ``A = Σ l_i w_i²``. ``V`` is the
    triangle inequality taken after summing the joint rates, so it never exceeds
    ``collision.link_motion_bound`` (which takes it before) and is the exact speed of the tip
    when one joint turns.
    """
    w = 0.0
    v = 0.0
    acc = 0.0
    for i in range(first, last + 1):
        w += math.radians(qb_deg[i] - qa_deg[i])
        v += links[i] * abs(w)
        acc += links[i] * w * w
    return v, acc


@nb.njit(cache=True, nogil=True, _nrt=True)
def element_speed_accel(P, qa_deg, qb_deg, vel, acc, off):
    """Per element (``signed.element_clearances`` order): ``vel`` bounds how fast its
    clearance changes per unit ``s`` on ``qa -> qb``, ``acc`` how fast the two closest points
    accelerate against each other, ``off`` what to add to a positive clearance to get the
    plain distance the curvature bound divides by (the capsule radii; a circle's radius is
    left out, which only makes that distance smaller, hence the bound safer).

    A link against the obstacles: the link's own ``(V, A)`` (obstacles do not move). Links of
    two arms: the sums (each moves with its own arm). Two non-adjacent links ``k < m`` of one
    arm: link ``m`` in the frame of link ``k``, i.e. the chain ``k + 1 .. m``, since a distance
    is unchanged by a rigid motion of both (``collision.self_pair_motion_bound``).
    """
    n_arms = P.arm_first.shape[0] - 1
    for a in range(n_arms):
        f = P.arm_first[a]
        for k in range(f, P.arm_first[a + 1]):
            v, ac = _chain_speed_accel(P.links, qa_deg, qb_deg, f, k)
            vel[k] = v
            acc[k] = ac
            off[k] = P.radii[a]
    e = P.links.shape[0]
    for a in range(n_arms):
        for b in range(a + 1, n_arms):
            for k in range(P.arm_first[a], P.arm_first[a + 1]):
                for m in range(P.arm_first[b], P.arm_first[b + 1]):
                    vel[e] = vel[k] + vel[m]
                    acc[e] = acc[k] + acc[m]
                    off[e] = P.radii[a] + P.radii[b]
                    e += 1
    for a in range(n_arms):
        for k in range(P.arm_first[a], P.arm_first[a + 1]):
            for m in range(k + 2, P.arm_first[a + 1]):
                v, ac = _chain_speed_accel(P.links, qa_deg, qb_deg, k + 1, m)
                vel[e] = v
                acc[e] = ac
                off[e] = 2.0 * P.radii[a]
                e += 1


@nb.njit(cache=True, nogil=True, _nrt=True)
def element_lower_bound(c0, c1, v, acc, off, width):
    """Nothing on an interval of ``width`` (in ``s``) whose ends have clearance ``c0, c1`` is
    below this, for one element with speed bound ``v``, acceleration bound ``acc`` and radius
    offset ``off`` (:func:`element_speed_accel`).

    First order: ``lb1 = (c0 + c1 - v width) / 2`` (the clearance moves no faster than ``v``).

    Second order, when ``D = lb1 + off > 0``: then every pair of points of the two bodies
    stays at least ``D`` apart on the interval, their distance ``g = |u|`` is smooth and
    ``g'' = (|u'|² - (û·u')²) / g + û·u'' <= v² / D + acc = K``; the clearance is a minimum of
    such ``g`` (over the points of the two bodies, minus constants), so it lies above its
    chord minus ``K/2 x (width - x)`` -- a minimum of functions that each do. The smallest
    value of that parabola over the interval is the bound. It is what closes *flat* minima
    (two links of a straight arm one link apart over a whole segment): a constant clearance
    costs ``sqrt(8 tol / K)`` wide intervals instead of ``2 tol / v`` ones. For a point
    turning on a circle past a fixed point ``K`` is the exact curvature at the closest
    approach, so a weaker constant would not be conservative.
    """
    lb1 = 0.5 * (c0 + c1 - v * width)
    d = lb1 + off
    if not (d > 0.0 and c0 < np.inf and c1 < np.inf):
        return lb1  # touching, penetrating or nothing to touch: first order only
    half_k = 0.5 * (acc + v * v / d) * width * width  # K width² / 2
    delta = c1 - c0
    if abs(delta) >= half_k:
        lb2 = min(c0, c1)
    else:
        lb2 = 0.5 * (c0 + c1) - 0.25 * half_k - delta * delta / (4.0 * half_k)
    return lb2 if lb2 > lb1 else lb1


@nb.njit(cache=True, nogil=True, _nrt=True)
def _interval_bound(c0, c1, vel, acc, off, width):
    """Nothing on the interval is below this: the smallest :func:`element_lower_bound`."""
    lb = np.inf
    for k in range(c0.shape[0]):
        v = element_lower_bound(c0[k], c1[k], vel[k], acc[k], off[k], width)
        if v < lb:
            lb = v
    return lb


@nb.njit(cache=True, nogil=True, _nrt=True)
def min_clearance_kernel(P, path, tol, max_evals, decide_contact):
    """``(value, segment, s, lower bound)`` of the signed clearance along ``path`` (degrees).

    With ``decide_contact`` an interval is also refined while it might hold a contact the
    best value does not show yet (``lb <= 0 < best``), so that ``value <= 0`` (touching) is
    decided exactly even with a coarse ``tol`` (the Monte Carlo's 1 µm): near a smooth
    minimum the work grows like ``1 / sqrt(tol)``, and only the trials that come within
    ``tol`` of touching pay for the sign.

    Branch and bound per segment with a lower bound per element (a link against the
    obstacles, a pair of links of different arms, or two non-adjacent links of one arm; see
    :func:`element_lower_bound`, with :func:`element_speed_accel`'s constants): an element
    that is far from the minimum, even a flat one, is pruned on its own bound; segments are
    visited in the order of their initial bound, so the best value is tight early and prunes
    the rest.
    """
    n = path.shape[0]
    nl = n_elements(P)
    if (P.obstacles.shape[0] == 0 and P.arm_first.shape[0] == 2 and not has_self_pairs(P)) \
            or n == 0:
        return np.inf, -1, 0.0, np.inf
    cv = np.empty((n, nl))
    best = np.inf
    best_seg = 0
    best_s = 0.0
    for i in range(n):
        c = element_clearances(P, path[i], cv[i])
        if c < best:
            best = c
            if i < n - 1 or n == 1:
                best_seg = i
                best_s = 0.0
            else:
                best_seg = n - 2
                best_s = 1.0
    if n == 1:
        return best, best_seg, best_s, best
    mks = np.empty((n - 1, nl))
    acs = np.empty((n - 1, nl))
    off = np.empty(nl)
    first = np.empty(n - 1)
    for i in range(n - 1):
        element_speed_accel(P, path[i], path[i + 1], mks[i], acs[i], off)
        first[i] = _interval_bound(cv[i], cv[i + 1], mks[i], acs[i], off, 1.0)
    order = np.argsort(first)
    floor = np.inf
    evals = n
    cap = 256
    s0s = np.empty(cap)
    s1s = np.empty(cap)
    c0s = np.empty((cap, nl))
    c1s = np.empty((cap, nl))
    cm = np.empty(nl)
    c1_old = np.empty(nl)
    q = np.empty(path.shape[1])
    for oi in range(n - 1):
        i = order[oi]
        if first[i] >= best - tol and (first[i] > 0.0 or best <= 0.0 or not decide_contact):
            break  # sorted: no later segment can do better either
        qa = path[i]
        qb = path[i + 1]
        mk = mks[i]
        ak = acs[i]
        s0s[0] = 0.0
        s1s[0] = 1.0
        c0s[0, :] = cv[i]
        c1s[0, :] = cv[i + 1]
        top = 1
        while top > 0:
            top -= 1
            s0 = s0s[top]
            s1 = s1s[top]
            lb = _interval_bound(c0s[top], c1s[top], mk, ak, off, s1 - s0)
            if lb >= best - tol and (lb > 0.0 or best <= 0.0 or not decide_contact):
                continue
            sm = 0.5 * (s0 + s1)
            if evals >= max_evals or top + 2 > cap or not (s0 < sm < s1):
                if lb < floor:
                    floor = lb
                continue
            for d in range(q.shape[0]):
                q[d] = qa[d] + sm * (qb[d] - qa[d])
            c = element_clearances(P, q, cm)
            evals += 1
            if c < best:
                best = c
                best_seg = i
                best_s = sm
            # Both halves go on the stack; the one with the smaller bound is explored first.
            for k in range(nl):
                c1_old[k] = c1s[top, k]
            left = _interval_bound(c0s[top], cm, mk, ak, off, sm - s0)
            right = _interval_bound(cm, c1_old, mk, ak, off, s1 - sm)
            if left <= right:
                # push right then left (left on top)
                s0s[top + 1] = s0
                s1s[top + 1] = sm
                c0s[top + 1, :] = c0s[top]
                c1s[top + 1, :] = cm
                s0s[top] = sm
                s1s[top] = s1
                c0s[top, :] = cm
                c1s[top, :] = c1_old
            else:
                s0s[top + 1] = sm
                s1s[top + 1] = s1
                c0s[top + 1, :] = cm
                c1s[top + 1, :] = c1_old
                s1s[top] = sm
                c1s[top, :] = cm
            top += 2
    return best, best_seg, best_s, min(best - tol, floor)


def path_min_clearance(arrays, path_deg, tol: float = MIN_CLEARANCE_TOL_M,
                       max_evals: int = MIN_CLEARANCE_MAX_EVALS) -> MinClearance:
    """Exact smallest signed clearance over every configuration of ``path_deg`` ([n, dof]
    degrees) in ``arrays`` (a ``ScenarioArrays``), where it occurs and a proven lower bound.

    ``value_m`` is a real distance at a real configuration on the path; nothing on the path is
    closer than ``lower_bound_m`` (``value_m - tol`` unless ``max_evals`` ran out).
    """
    path = np.ascontiguousarray(np.asarray(path_deg, dtype=np.float64))
    dof = arrays.links.shape[0]
    if path.size == 0:
        return MinClearance(math.nan, -1, 0.0, (), math.nan)
    if path.ndim != 2 or path.shape[1] != dof:
        raise InputError("path", f"must be an array of shape [n, {dof}], got {path.shape}")
    if not np.all(np.isfinite(path)):
        raise InputError("path", "contains non-finite angles")
    if not (tol > 0.0 and math.isfinite(tol)):
        raise InputError("tol", f"must be a positive number of metres, got {tol!r}")
    value, seg, s, lower = min_clearance_kernel(arrays.problem(CERT_MARGIN_M), path,
                                                float(tol), int(max_evals), False)
    seg = int(seg)
    where: tuple[float, ...] = ()
    if seg >= 0:
        qa = path[seg]
        qb = path[min(seg + 1, path.shape[0] - 1)]
        where = tuple(float(v) for v in qa + s * (qb - qa))
    return MinClearance(float(value), seg, float(s), where, float(lower))


__all__ = ["CERT_MARGIN_M", "MIN_CLEARANCE_TOL_M", "MinClearance", "check_endpoints_keep",
           "min_clearance_kernel", "path_min_clearance", "planning_margin", "resolve_clearance",
           "with_clearance"]
