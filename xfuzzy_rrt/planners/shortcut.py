"""Certified random shortcutting: a shorter path whose every new edge is proven free.

Why: RRT-family paths zig-zag, and comparing planners only on raw length hides how good the
route they found is. OMPL reports a simplified length apart from the raw one; we do the same
(``cost_short_deg`` next to ``cost_deg``), with one difference that matters for a surgical arm:
every edge the shortcutter creates is accepted only if the certified check
(:func:`~xfuzzy_rrt.geometry.collision.edge_free`, conservative advancement) proves it free, so
shortening never trades safety for length.

The method (Geraerts & Overmars' random shortcutting, with mid-segment points): ``attempts``
times, draw two arc-length positions ``t1 < t2`` uniformly on the current path (so the points
``p1``, ``p2`` may lie inside segments), and replace the stretch between them by the straight
segment ``p1 -> p2`` when it is strictly shorter and the new edges ``path[i1] -> p1``,
``p1 -> p2`` and ``p2 -> path[i2 + 1]`` are all certified (the two partial edges lie on
existing segments; they are re-certified anyway so that a path from another planner that was
not certified cannot lend its uncertified pieces to the new edges). Consequences:

- the result is never longer than the input (only strictly improving replacements are kept,
  and a final guard returns the input unchanged if floating-point rounding disagreed);
- start and goal are the input's, bit for bit (they are never replaced);
- every edge is either an unchanged input edge or certified;
- deterministic: the draws come from the project's xoshiro256** stream seeded by ``seed``
  (:mod:`xfuzzy_rrt.planners.rng`), exactly two per attempt whatever happens, so the same
  ``(path, seed, attempts)`` gives the same result, byte for byte.

The loop is compiled (numba): it runs on every benchmark path.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M, edge_free, within_limits
from xfuzzy_rrt.planners.result import path_cost_deg
from xfuzzy_rrt.planners.rng import seed_state, uniform

DEFAULT_ATTEMPTS = 200

#: A replacement must shorten the path by more than this (degrees): smaller "gains" are
#: rounding noise and could make the recomputed length grow.
_MIN_GAIN_DEG = 1e-9


@nb.njit(cache=True, nogil=True, _nrt=True)
def _seg_len(path, i):
    s = 0.0
    for d in range(path.shape[1]):
        diff = path[i + 1, d] - path[i, d]
        s += diff * diff
    return math.sqrt(s)


@nb.njit(cache=True, nogil=True, _nrt=True)
def _locate(cum, n, t):
    """Index ``i`` of the segment ``[cum[i], cum[i + 1]]`` holding arc length ``t``."""
    i = 0
    while i < n - 2 and cum[i + 1] <= t:
        i += 1
    return i


@nb.njit(cache=True, nogil=True, _nrt=True)
def _point_on(path, cum, i, t, out):
    """Write the point at arc length ``t`` on segment ``i`` into ``out``."""
    seg = cum[i + 1] - cum[i]
    f = 0.0
    if seg > 0.0:
        f = (t - cum[i]) / seg
        if f < 0.0:
            f = 0.0
        elif f > 1.0:
            f = 1.0
    for d in range(path.shape[1]):
        out[d] = path[i, d] + f * (path[i + 1, d] - path[i, d])
    if f == 1.0:
        out[:] = path[i + 1]


@nb.njit(cache=True, nogil=True, _nrt=True)
def _same(a, b):
    for d in range(a.shape[0]):
        if a[d] != b[d]:
            return False
    return True


@nb.njit(cache=True, nogil=True, _nrt=True)
def _dist(a, b):
    s = 0.0
    for d in range(a.shape[0]):
        s += (b[d] - a[d]) ** 2
    return math.sqrt(s)


@nb.njit(cache=True, nogil=True, _nrt=True)
def shortcut_kernel(P, path, seed, attempts, margin):
    """Return ``(buffer, n)``: the shortened path is ``buffer[:n]`` (see module docstring)."""
    dof = path.shape[1]
    cap = path.shape[0] + 2 * attempts + 2
    cur = np.empty((cap, dof), dtype=np.float64)
    nxt = np.empty((cap, dof), dtype=np.float64)
    cum = np.empty(cap, dtype=np.float64)
    n = path.shape[0]
    cur[:n] = path
    state = np.empty(4, dtype=np.uint64)
    seed_state(seed, state)
    p1 = np.empty(dof, dtype=np.float64)
    p2 = np.empty(dof, dtype=np.float64)
    for _ in range(attempts):
        u1 = uniform(state)
        u2 = uniform(state)
        if n < 3:
            continue
        cum[0] = 0.0
        for i in range(n - 1):
            cum[i + 1] = cum[i] + _seg_len(cur, i)
        total = cum[n - 1]
        t1 = u1 * total
        t2 = u2 * total
        if t1 > t2:
            t1, t2 = t2, t1
        i1 = _locate(cum, n, t1)
        i2 = _locate(cum, n, t2)
        if i1 == i2:
            continue  # both points on one segment: a straight line cannot be shorter
        _point_on(cur, cum, i1, t1, p1)
        _point_on(cur, cum, i2, t2, p2)
        # Length of the stretch p1 -> ... -> p2 along the current path.
        old = (cum[i1 + 1] - t1) + (cum[i2] - cum[i1 + 1]) + (t2 - cum[i2])
        if not _dist(p1, p2) < old - _MIN_GAIN_DEG:
            continue
        if not (within_limits(P.limits, p1) and within_limits(P.limits, p2)):
            continue
        if not edge_free(P, p1, p2, margin):
            continue
        keep1 = not _same(p1, cur[i1])
        keep2 = not _same(p2, cur[i2 + 1])
        if keep1 and not edge_free(P, cur[i1], p1, margin):
            continue
        if keep2 and not edge_free(P, p2, cur[i2 + 1], margin):
            continue
        m = 0
        for i in range(i1 + 1):
            nxt[m] = cur[i]
            m += 1
        if keep1:
            nxt[m] = p1
            m += 1
        if keep2:
            nxt[m] = p2
            m += 1
        for i in range(i2 + 1, n):
            nxt[m] = cur[i]
            m += 1
        cur, nxt = nxt, cur
        n = m
    return cur, n


def shortcut_path(arrays, path_deg, seed: int, attempts: int = DEFAULT_ATTEMPTS,
                  margin: float = CERT_MARGIN_M) -> np.ndarray:
    """Shorten ``path_deg`` (``[n, dof]`` degrees) in ``arrays`` (a ``ScenarioArrays``).

    Returns a new array; paths with fewer than three configurations come back as a copy.
    """
    path = np.ascontiguousarray(np.asarray(path_deg, dtype=np.float64))
    if isinstance(attempts, bool) or not isinstance(attempts, (int, np.integer)) or attempts < 0:
        raise InputError("attempts", f"must be a non-negative integer, got {attempts!r}")
    if path.size == 0:
        return path.reshape(0, arrays.links.shape[0]).copy()
    dof = arrays.links.shape[0]
    if path.ndim != 2 or path.shape[1] != dof:
        raise InputError("path", f"must be an array of shape [n, {dof}], got {path.shape}")
    if not np.all(np.isfinite(path)):
        raise InputError("path", "contains non-finite angles")
    if path.shape[0] < 3 or attempts == 0:
        return path.copy()
    buf, n = shortcut_kernel(arrays.problem(margin), path, int(seed), int(attempts),
                             float(margin))
    out = buf[:n].copy()
    if path_cost_deg(out) > path_cost_deg(path):  # rounding guard: never return a longer path
        return path.copy()
    return out
