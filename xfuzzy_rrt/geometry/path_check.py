"""Certify a whole path after the fact, and measure how deep it goes into obstacles if it fails.

Why this exists: our planners only ever add edges that ``edge_free`` certified, but a path can
come from elsewhere — OMPL's planners check a motion by *sampling* it at a fixed resolution
(``DiscreteMotionValidator``), so an edge that crosses a thin obstacle between two samples is
accepted. A benchmark that puts those planners next to ours must say, per path, whether it is
actually collision-free (``certified``) and, when it is not, how bad it is (``penetration_m``),
so that "faster" is never bought with an unnoticed collision.

Two independent measurements:

- ``certified``: every vertex within the joint limits and every segment accepted by the
  certified check :func:`~xfuzzy_rrt.geometry.collision.edge_free` (conservative advancement,
  same ``margin`` as the planners). This is the yes/no the planners themselves are held to.
- ``min_clearance_m`` / ``penetration_m``: the exact smallest *signed* clearance over every
  configuration on the path (below), and the depth ``max(0, -min_clearance_m)``.

The distance is *signed* so that the depth does not saturate once a link's centre line touches
an obstacle (the unsigned clearance used for planning bottoms out at ``-link_radius``). Inside,
it is the exact penetration depth (minimum translation distance) between the link segment and
the obstacle: for a circle ``dist(centre, segment) - r``; for a box the smallest overlap over the
three separating axes of a segment and a rectangle (x, y and the segment's normal), which is
exact for two convex polygons in the plane (separating axis theorem). Outside, it is the
ordinary exact distance, so the two checks agree on every free configuration.

``min_clearance_m`` is the smallest of these signed clearances over the whole path (negative:
the exact penetration depth), found by branch and bound instead of a scan:
:func:`xfuzzy_rrt.geometry.clearance.min_clearance_kernel` (one implementation, shared with the
robustness Monte Carlo). Per element (a link against the obstacles, a link pair) and interval
``[s0, s1]`` of a segment it bounds the clearance from below twice -- by its speed
(``(c0 + c1 - V (s1 - s0)) / 2``, the motion bound of the certified check, summed after the
joint rates) and by its curvature (the chord minus ``K/2 (s - s0)(s1 - s)``, which is what
proves flat minima such as two links of a straight arm held one link apart) -- and drops the
intervals that cannot beat the best value seen by more than ``MIN_CLEARANCE_TOL_M`` (0.1 um).
The value returned is an exact distance at a real configuration on the path
(``min_config_deg``), and no configuration on the path is closer by more than 0.1 um.
``penetration_m`` is ``max(0, -min_clearance_m)``.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.collision import (  # noqa: F401  (MIN_CLEARANCE_TOL_M: re-exported)
    CERT_MARGIN_M,
    MIN_CLEARANCE_TOL_M,
    edge_free,
    within_limits,
)
# Signed distances live in geometry/signed.py; re-exported here, where callers used to find them.
from xfuzzy_rrt.geometry.signed import (  # noqa: F401
    signed_clearance,
    signed_clearance_kernel,
    signed_segment_obstacle_dist,
)

#: Configurations evaluated per path after which the branch and bound stops refining and
#: reports its proven lower bound instead (a safety net: flat minima, a link turning about the
#: centre of a circle or two links of a straight arm held one link apart, close in thousands
#: with the curvature bound).
MIN_CLEARANCE_MAX_EVALS = 2_000_000


@dataclass(frozen=True)
class PathCheck:
    """The verdict on one path (see the module docstring).

    ``worst_segment`` is the index of the segment (``path[i] -> path[i + 1]``) with the deepest
    penetration; when nothing penetrates but the path is still not certified (a vertex outside
    the joint limits, or clearance within the 1 µm margin) it is the first segment that failed
    certification; ``-1`` when the path is certified and nothing penetrates.
    """

    certified: bool
    penetration_m: float
    worst_segment: int
    #: Exact smallest signed clearance along the path (``inf`` without obstacles, ``nan``
    #: without a path); negative values are penetration depths.
    min_clearance_m: float = math.nan
    #: Where it occurs: the segment (``path[i] -> path[i + 1]``; 0 for a one-point path) and
    #: the configuration in degrees. ``-1`` / ``()`` when there is no such place.
    min_segment: int = -1
    min_config_deg: tuple[float, ...] = ()
    #: First path vertex outside the joint limits (``-1``: none).
    limits_vertex: int = -1
    #: Distance evaluations the check made (``Problem.work``: the exact minimum clearance and
    #: the certified edge check), the deterministic cost of certifying this path.
    work: int = 0

    def describe(self) -> str:
        """One sentence on why the path is not certified (empty string when it is)."""
        if self.certified:
            return ""
        if self.min_segment < 0 and self.limits_vertex < 0 and self.worst_segment < 0:
            return "no path to certify"
        q = ", ".join(f"{v:.6g}" for v in self.min_config_deg)
        if self.penetration_m > 0.0:
            return (f"segment {self.worst_segment} penetrates an obstacle "
                    f"{self.penetration_m * 1e3:.4g} mm deep at q = ({q}) deg")
        if self.limits_vertex >= 0:
            return f"vertex {self.limits_vertex} is outside the joint limits"
        return (f"segment {self.worst_segment} does not pass the certified check (smallest "
                f"clearance {self.min_clearance_m * 1e6:.4g} um at q = ({q}) deg)")


@nb.njit(cache=True, nogil=True, _nrt=True)
def certify_kernel(P, path, margin):
    """``(certified, first uncertified segment, first vertex outside the limits)``."""
    n = path.shape[0]
    certified = True
    first_bad = -1
    first_out = -1
    for i in range(n):
        if first_out < 0 and not within_limits(P.limits, path[i]):
            first_out = i
    for i in range(n - 1):
        qa = path[i]
        qb = path[i + 1]
        ok = within_limits(P.limits, qa) and within_limits(P.limits, qb)
        if ok:
            ok = edge_free(P, qa, qb, margin)
        if not ok:
            certified = False
            first_bad = i
            break
    return certified, first_bad, first_out


def _min_clearance(problem, path) -> tuple[float, int, float]:
    """``(value, segment, s)`` of the exact minimum signed clearance along ``path``."""
    # one branch and bound for the whole project (geometry/clearance.py; the robustness Monte
    # Carlo uses it too), here at the certification's tolerance and without the contact refinement
    from xfuzzy_rrt.geometry.clearance import min_clearance_kernel

    value, seg, s, lower = min_clearance_kernel(problem, path, MIN_CLEARANCE_TOL_M,
                                                MIN_CLEARANCE_MAX_EVALS, False)
    value = float(value)
    if float(lower) < value - MIN_CLEARANCE_TOL_M:
        value = float(lower)  # budget reached: report the proven bound, never an optimistic one
    return value, seg, s


def segments_certified(arrays, path_deg, margin: float = CERT_MARGIN_M) -> int | None:
    """The work (distance evaluations) of certifying every segment of ``path_deg``, or ``None``
    when a segment or vertex fails: :func:`certify_path`'s verdict without its exact minimum
    clearance, for callers that measure the clearance only when asked (``planners/result.py``)."""
    path = np.ascontiguousarray(np.asarray(path_deg, dtype=np.float64))
    problem = arrays.problem(margin)
    certified, _bad, first_out = certify_kernel(problem, path, float(margin))
    if not certified or first_out >= 0:
        return None
    return int(problem.work[0])


def path_min_clearance(arrays, path_deg, margin: float = CERT_MARGIN_M) -> tuple[float, float]:
    """``(min_clearance_m, penetration_m)`` of a *certified* path as :func:`certify_path`
    reports them, without certifying it again: what a result computes only when someone asks
    (the branch and bound costs more than most plans; see ``planners/result.py``)."""
    path = np.ascontiguousarray(np.asarray(path_deg, dtype=np.float64))
    problem = arrays.problem(margin)
    value, _seg, _s = _min_clearance(problem, path)
    # Only certified paths are measured here (planners/result.py), and certification proved
    # that no configuration on them comes closer than the surgeon's clearance
    # (geometry/collision.py). The branch and bound proves its value to 0.1 um, flat minima
    # included, so this changes nothing unless its evaluation budget runs out (no known path
    # does): then ``value`` is its proven lower bound, and the larger of two proven lower
    # bounds is still one -- a true statement, never an optimistic one.
    value = max(value, float(problem.clearance))
    return value, (max(0.0, -value) if math.isfinite(value) else 0.0)


def certify_path(arrays, path_deg, margin: float = CERT_MARGIN_M) -> PathCheck:
    """Certify ``path_deg`` (``[n, dof]`` degrees) in ``arrays`` (a ``ScenarioArrays``) and
    measure its exact minimum clearance.

    An empty path is not certified (there is nothing to vouch for). A single configuration is
    certified when it is within the limits and keeps clearance above ``margin``.
    """
    path = np.ascontiguousarray(np.asarray(path_deg, dtype=np.float64))
    dof = arrays.links.shape[0]  # every arm's angles
    if path.size == 0:
        return PathCheck(certified=False, penetration_m=0.0, worst_segment=-1)
    if path.ndim != 2 or path.shape[1] != dof:
        raise InputError("path", f"must be an array of shape [n, {dof}], got {path.shape}")
    if not np.all(np.isfinite(path)):
        raise InputError("path", "contains non-finite angles")
    problem = arrays.problem(margin)
    value, seg, s = _min_clearance(problem, path)
    where: tuple[float, ...] = ()
    if seg >= 0:
        qa = path[seg]
        qb = path[min(seg + 1, path.shape[0] - 1)]
        where = tuple(float(v) for v in qa + s * (qb - qa))
    penetration = max(0.0, -value) if math.isfinite(value) else 0.0
    if path.shape[0] == 1:
        q = path[0]
        inside = bool(within_limits(arrays.limits_deg, q))
        ok = inside and value > margin
        return PathCheck(certified=ok, penetration_m=penetration,
                         worst_segment=0 if not ok and inside else -1,
                         min_clearance_m=value, min_segment=seg, min_config_deg=where,
                         limits_vertex=-1 if inside else 0, work=int(problem.work[0]))
    certified, first_bad, first_out = certify_kernel(problem, path, float(margin))
    worst = int(seg) if penetration > 0.0 else (-1 if certified else int(first_bad))
    return PathCheck(certified=bool(certified), penetration_m=float(penetration),
                     worst_segment=worst, min_clearance_m=value, min_segment=int(seg),
                     min_config_deg=where, limits_vertex=int(first_out),
                     work=int(problem.work[0]))
