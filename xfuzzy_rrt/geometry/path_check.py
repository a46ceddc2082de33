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
- ``penetration_m``: a dense scan of every segment with *signed* exact distances. Samples are
  spaced so that no point of the arm moves more than ``scan_step_m`` (0.1 mm) between two of
  them, using the same motion bound ``M = max_k M_k`` as the certified check (see
  ``collision.py``); where the clearance ``c`` exceeds that step the scan jumps by ``c / M``
  instead, which provably skips no contact. At each sample the signed clearance is ``min over
  links and obstacles of (signed distance - link_radius)`` and the penetration is
  ``max(0, -signed clearance)``; the path's value is the maximum over all samples.

The distance is *signed* so that the depth does not saturate once a link's centre line touches
an obstacle (the unsigned clearance used for planning bottoms out at ``-link_radius``). Inside,
it is the exact penetration depth (minimum translation distance) between the link segment and
the obstacle: for a circle ``dist(centre, segment) - r``; for a box the smallest overlap over the
three separating axes of a segment and a rectangle (x, y and the segment's normal), which is
exact for two convex polygons in the plane (separating axis theorem). Outside, it is the
ordinary exact distance, so the two checks agree on every free configuration.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numba as nb
import numpy as np

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.collision import (
    CERT_MARGIN_M,
    edge_free,
    link_motion_bound,
    segment_obstacle_dist,
    within_limits,
)

#: Largest motion (metres) of any point of the arm between two samples of the penetration scan.
SCAN_STEP_M = 1e-4


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


@nb.njit(cache=True, nogil=True)
def signed_segment_obstacle_dist(ax, ay, bx, by, ob):
    """Exact signed distance from segment AB to obstacle row ``ob``; negative = depth inside."""
    if ob[0] == 0.0:  # circle: distance from the centre to the segment, minus the radius
        dx = bx - ax
        dy = by - ay
        den = dx * dx + dy * dy
        t = 0.0
        if den > 0.0:
            t = ((ob[1] - ax) * dx + (ob[2] - ay) * dy) / den
            if t < 0.0:
                t = 0.0
            elif t > 1.0:
                t = 1.0
        qx = ax + t * dx - ob[1]
        qy = ay + t * dy - ob[2]
        return math.sqrt(qx * qx + qy * qy) - ob[3]
    d = segment_obstacle_dist(ax, ay, bx, by, ob)
    if d > 0.0:
        return d
    # Intersecting: minimum translation distance by the separating axis theorem. Candidate
    # axes are the rectangle's normals (x, y) and the segment's normal.
    x0 = ob[1]
    y0 = ob[2]
    x1 = ob[3]
    y1 = ob[4]
    depth = min(max(ax, bx) - x0, x1 - min(ax, bx))
    depth = min(depth, min(max(ay, by) - y0, y1 - min(ay, by)))
    dx = bx - ax
    dy = by - ay
    norm = math.sqrt(dx * dx + dy * dy)
    if norm > 0.0:
        nx = -dy / norm
        ny = dx / norm
        seg = ax * nx + ay * ny  # the whole segment projects to this one value
        lo = np.inf
        hi = -np.inf
        for cx, cy in ((x0, y0), (x1, y0), (x0, y1), (x1, y1)):
            p = cx * nx + cy * ny
            lo = min(lo, p)
            hi = max(hi, p)
        depth = min(depth, min(seg - lo, hi - seg))
    return -max(depth, 0.0)


@nb.njit(cache=True, nogil=True)
def signed_clearance_kernel(links, base, radius, obstacles, q_deg):
    """Smallest signed link-capsule clearance (negative: penetration depth), ``inf`` if empty."""
    best = np.inf
    x = base[0]
    y = base[1]
    theta = 0.0
    for k in range(links.shape[0]):
        theta += math.radians(q_deg[k])
        nx = x + links[k] * math.cos(theta)
        ny = y + links[k] * math.sin(theta)
        for o in range(obstacles.shape[0]):
            d = signed_segment_obstacle_dist(x, y, nx, ny, obstacles[o]) - radius
            if d < best:
                best = d
        x = nx
        y = ny
    return best


@nb.njit(cache=True, nogil=True)
def motion_bound(links, qa_deg, qb_deg):
    """``max_k M_k``: no point of the arm moves more than this per unit of the segment.

    The same bound as ``edge_free`` uses: ``M_k = Σ_{j<=k} |Δq_j| Σ_{i=j..k} l_i`` (radians).
    """
    best = 0.0
    for k in range(links.shape[0]):
        mk = link_motion_bound(links, qa_deg, qb_deg, k)
        if mk > best:
            best = mk
    return best


@nb.njit(cache=True, nogil=True)
def segment_penetration(links, base, radius, obstacles, qa, qb, step_m):
    """Deepest penetration found on ``qa -> qb``, no arm point moving > ``step_m`` per sample.

    Where the signed clearance ``c`` is larger than ``step_m`` the scan jumps ahead by
    ``c / M`` (no point can reach an obstacle sooner, the argument of the certified check), so
    a free segment costs a few dozen distance evaluations instead of thousands; elsewhere it
    advances by ``step_m / M``.
    """
    m = motion_bound(links, qa, qb)
    q = np.empty(qa.shape[0], dtype=np.float64)
    q[:] = qa
    worst = 0.0
    s = 0.0
    while True:
        c = signed_clearance_kernel(links, base, radius, obstacles, q)
        if -c > worst:
            worst = -c
        if s >= 1.0 or m <= 0.0:
            return worst
        s += max(c, step_m) / m
        if s >= 1.0:
            s = 1.0
            q[:] = qb
        else:
            for d in range(qa.shape[0]):
                q[d] = qa[d] + s * (qb[d] - qa[d])


@nb.njit(cache=True, nogil=True)
def certify_kernel(links, base, radius, obstacles, limits, path, margin, step_m):
    """``(certified, worst penetration, its segment, first uncertified segment)``."""
    n = path.shape[0]
    certified = True
    first_bad = -1
    worst = 0.0
    worst_seg = -1
    for i in range(n - 1):
        qa = path[i]
        qb = path[i + 1]
        ok = within_limits(limits, qa) and within_limits(limits, qb)
        if ok:
            ok = edge_free(links, base, radius, obstacles, qa, qb, margin)
        if not ok:
            certified = False
            if first_bad < 0:
                first_bad = i
        if obstacles.shape[0] > 0:
            p = segment_penetration(links, base, radius, obstacles, qa, qb, step_m)
            if p > worst:
                worst = p
                worst_seg = i
    return certified, worst, worst_seg, first_bad


def certify_path(arrays, path_deg, margin: float = CERT_MARGIN_M,
                 scan_step_m: float = SCAN_STEP_M) -> PathCheck:
    """Certify ``path_deg`` (``[n, dof]`` degrees) in ``arrays`` (a ``ScenarioArrays``).

    An empty path is not certified (there is nothing to vouch for). A single configuration is
    certified when it is within the limits and keeps clearance above ``margin``.
    """
    path = np.ascontiguousarray(np.asarray(path_deg, dtype=np.float64))
    dof = arrays.links.shape[0]
    if path.size == 0:
        return PathCheck(certified=False, penetration_m=0.0, worst_segment=-1)
    if path.ndim != 2 or path.shape[1] != dof:
        raise InputError("path", f"must be an array of shape [n, {dof}], got {path.shape}")
    if not np.all(np.isfinite(path)):
        raise InputError("path", "contains non-finite angles")
    if not (scan_step_m > 0.0 and math.isfinite(scan_step_m)):
        raise InputError("scan_step_m", f"must be a positive number, got {scan_step_m!r}")
    if path.shape[0] == 1:
        q = path[0]
        c = float(signed_clearance_kernel(arrays.links, arrays.base, arrays.link_radius,
                                          arrays.obstacles, q))
        ok = bool(within_limits(arrays.limits_deg, q)) and c > margin
        return PathCheck(certified=ok, penetration_m=max(0.0, -c), worst_segment=-1)
    certified, worst, worst_seg, first_bad = certify_kernel(
        arrays.links, arrays.base, arrays.link_radius, arrays.obstacles, arrays.limits_deg,
        path, float(margin), float(scan_step_m))
    if worst <= 0.0:
        worst_seg = first_bad
    return PathCheck(certified=bool(certified), penetration_m=float(worst),
                     worst_segment=int(worst_seg))


def signed_clearance(arrays, q_deg) -> float:
    """Signed clearance of one configuration (negative: exact penetration depth)."""
    return float(signed_clearance_kernel(arrays.links, arrays.base, arrays.link_radius,
                                         arrays.obstacles, np.asarray(q_deg, dtype=np.float64)))
