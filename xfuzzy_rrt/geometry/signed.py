"""Exact *signed* distances: negative values are penetration depths.

Planning only needs to know whether a capsule is clear (``collision.py``: unsigned distances,
0 when touching). Certifying a path someone else made, and measuring how bad a colliding one
is, needs a distance that keeps decreasing inside: here it is the exact minimum translation
distance (separating axis theorem) between a link segment and a convex obstacle, or between
two link segments of different arms. Outside, every function agrees with the unsigned one.

``element_clearances`` is the view the branch and bound of ``clearance.py`` works on: one
signed clearance per *element* -- each link against the obstacles, then each pair of links of
different arms, then each pair of non-adjacent links of one arm (self-collision); the branch
and bound bounds how fast each moves with ``clearance.element_speed_accel`` (a speed and a
curvature constant per element).
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from xfuzzy_rrt.geometry.collision import (
    _point_segment_dist,
    link_segments_into,
    n_link_pairs,
    segment_obstacle_dist,
    segment_segment_dist,
)


@nb.njit(cache=True, nogil=True, _nrt=True)
def signed_segment_obstacle_dist(ax, ay, bx, by, ob):
    """Exact signed distance from segment AB to obstacle row ``ob``; negative = depth inside."""
    if ob[0] == 0.0:  # circle: distance from the centre to the segment, minus the radius
        return _point_segment_dist(ob[1], ob[2], ax, ay, bx, by) - ob[3]
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


@nb.njit(cache=True, nogil=True, _nrt=True)
def signed_segment_segment_dist(ax, ay, bx, by, cx, cy, dx, dy):
    """Exact signed distance between segments AB and CD; negative = penetration depth.

    Apart: the ordinary distance. Crossing: the smallest overlap of their projections on the
    two segment normals (the separating axes of two degenerate convex polygons), i.e. how far
    one must move to clear the other.
    """
    d = segment_segment_dist(ax, ay, bx, by, cx, cy, dx, dy)
    if d > 0.0:
        return d
    depth = np.inf
    for axis in range(2):
        if axis == 0:
            ux = bx - ax
            uy = by - ay
            px = ax
            py = ay
        else:
            ux = dx - cx
            uy = dy - cy
            px = cx
            py = cy
        norm = math.sqrt(ux * ux + uy * uy)
        if norm == 0.0:
            continue
        nx = -uy / norm
        ny = ux / norm
        seg = px * nx + py * ny
        if axis == 0:
            lo = min(cx * nx + cy * ny, dx * nx + dy * ny)
            hi = max(cx * nx + cy * ny, dx * nx + dy * ny)
        else:
            lo = min(ax * nx + ay * ny, bx * nx + by * ny)
            hi = max(ax * nx + ay * ny, bx * nx + by * ny)
        depth = min(depth, min(seg - lo, hi - seg))
    if not depth < np.inf:
        depth = 0.0
    return -max(depth, 0.0)


@nb.njit(cache=True, nogil=True, _nrt=True)
def n_elements(P):
    """Links (each against the obstacles), pairs of links of different arms, and pairs of
    non-adjacent links of one arm."""
    return P.links.shape[0] + n_link_pairs(P)


@nb.njit(cache=True, nogil=True, _nrt=True)
def element_clearances(P, q_deg, out):
    """Signed clearance of every element (see the module docstring) into ``out``; the min.

    Elements ``0 .. L-1`` are the links against all obstacles (``inf`` without obstacles),
    then the link pairs of arms ``a < b`` in order, then per arm its non-adjacent link pairs
    ``(k, m >= k + 2)`` in order. With one arm of two links this is one value per link.
    """
    best = np.inf
    n_arms = P.arm_first.shape[0] - 1
    obstacles = P.obstacles
    nl = P.links.shape[0]
    seg = np.empty((nl, 4))
    link_segments_into(P, q_deg, seg)
    for a in range(n_arms):
        for k in range(P.arm_first[a], P.arm_first[a + 1]):
            ck = np.inf
            for o in range(obstacles.shape[0]):
                d = signed_segment_obstacle_dist(seg[k, 0], seg[k, 1], seg[k, 2], seg[k, 3],
                                                 obstacles[o]) - P.radii[a]
                if d < ck:
                    ck = d
            out[k] = ck
            if ck < best:
                best = ck
    e = nl
    for a in range(n_arms):
        for b in range(a + 1, n_arms):
            rr = P.radii[a] + P.radii[b]
            for k in range(P.arm_first[a], P.arm_first[a + 1]):
                for m in range(P.arm_first[b], P.arm_first[b + 1]):
                    d = signed_segment_segment_dist(seg[k, 0], seg[k, 1], seg[k, 2], seg[k, 3],
                                                    seg[m, 0], seg[m, 1], seg[m, 2],
                                                    seg[m, 3]) - rr
                    out[e] = d
                    if d < best:
                        best = d
                    e += 1
    for a in range(n_arms):
        rr = P.radii[a] + P.radii[a]
        for k in range(P.arm_first[a], P.arm_first[a + 1]):
            for m in range(k + 2, P.arm_first[a + 1]):
                d = signed_segment_segment_dist(seg[k, 0], seg[k, 1], seg[k, 2], seg[k, 3],
                                                seg[m, 0], seg[m, 1], seg[m, 2], seg[m, 3]) - rr
                out[e] = d
                if d < best:
                    best = d
                e += 1
    P.work[0] += nl * obstacles.shape[0] + (e - nl)  # the work counter (geometry/problem.py)
    return best


@nb.njit(cache=True, nogil=True, _nrt=True)
def signed_clearance_kernel(P, q_deg):
    """Smallest signed clearance (negative: penetration depth), ``inf`` if nothing to hit."""
    out = np.empty(n_elements(P))
    return element_clearances(P, q_deg, out)


def signed_clearance(arrays, q_deg) -> float:
    """Signed clearance of one configuration (negative: exact penetration depth)."""
    from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M

    return float(signed_clearance_kernel(arrays.problem(CERT_MARGIN_M),
                                         np.asarray(q_deg, dtype=np.float64)))
