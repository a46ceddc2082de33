"""The search tree shared by the planners: node storage and exact nearest-neighbour queries.

Nodes live in preallocated arrays (``nodes[cap, dof]`` in degrees, ``parent[cap]``), so the
compiled planner loop never allocates. Nearest-neighbour search is *exact* (the brute-force
answer, ties to the lowest node index) and must not make long runs quadratic.

- **Two joints: a uniform grid** with one linked list per cell, searched in Chebyshev rings
  around the query's cell and only within the bounding box of occupied cells. A ring search
  stops once the best distance found is strictly below the smallest distance any unvisited ring
  could hold, so the cost per query stays roughly constant as the tree grows to 10,000 nodes.
- **Three joints and more: a balanced k-d tree plus a small buffer.** The nodes added since the
  last build sit in a buffer scanned linearly; when it outgrows ``max(32, 2 sqrt(n))`` the
  k-d tree is rebuilt over all nodes by median splits (quickselect, split axis = depth mod N),
  so it is balanced whatever order the nodes came in. An *incremental* k-d tree was measured
  slower than a linear scan: an RRT adds nodes in a spatially correlated order and the tree
  degenerates into a chain. A query descends the k-d tree depth first and visits the far side of
  a split only when the split plane is not farther than the best distance found (``<=``: equal
  distances must be seen for the lowest-index tie rule), then scans the buffer. Rebuilds cost
  ``O(n log n)`` about ``sqrt(n) / 2`` times per run; a query costs the tree search plus at most
  ``2 sqrt(n)`` distances.

The arrays travel together as one :class:`TreeArrays` record (a numba named tuple). Integer
grid bookkeeping is ``meta = [n_nodes, ncx, ncy, bx0, by0, bx1, by1]`` (grid size and occupied
cell bounding box) and the grid geometry ``grid = [lo0, lo1, cell]``.
"""

from __future__ import annotations

import math
from typing import NamedTuple

import numba as nb
import numpy as np

#: Grid cell edge in degrees. 10° cells give a 36 x 36 grid over the full joint box.
CELL_DEG = 10.0

N_NODES, NCX, NCY, BX0, BY0, BX1, BY1 = range(7)


class TreeArrays(NamedTuple):
    """Preallocated tree arrays (created in Python once per plan, filled by compiled code)."""

    nodes: np.ndarray
    parent: np.ndarray
    cell_next: np.ndarray
    cell_head: np.ndarray
    meta: np.ndarray
    grid: np.ndarray
    #: k-d tree (3+ joints): node indices in tree order (the subtree of range ``[lo, hi)`` has
    #: its root at ``(lo + hi) // 2``), each position's split axis, and the stack of ranges
    #: ``(lo, hi, depth)`` with the query's lower bound per range.
    kd_perm: np.ndarray
    kd_axis: np.ndarray
    kd_stack: np.ndarray
    kd_stack_lb: np.ndarray


#: ``meta`` slot holding how many nodes the k-d tree covers (the rest are in the buffer).
KD_N = 7
#: ``meta`` slot counting nearest-neighbour node visits: every tree node whose distance to a
#: query is computed adds 1 (part of the deterministic work count, ``PlanResult.work``).
NN_VISITS = 8
#: Entries of the k-d search stack: two per level of a balanced tree of 10^6 nodes, and more.
KD_STACK = 128


def make_tree(capacity: int, limits_deg: np.ndarray, cell_deg: float = CELL_DEG) -> TreeArrays:
    """Empty tree for ``capacity`` nodes in the joint box ``limits_deg`` (``[dof, 2]``)."""
    limits_deg = np.asarray(limits_deg, dtype=np.float64)
    if limits_deg.ndim != 2 or limits_deg.shape[1] != 2 or limits_deg.shape[0] < 2:
        raise ValueError("the tree needs joint limits of shape [dof >= 2, 2]")
    dof = limits_deg.shape[0]
    ncx = max(1, int(math.ceil((limits_deg[0, 1] - limits_deg[0, 0]) / cell_deg)))
    ncy = max(1, int(math.ceil((limits_deg[1, 1] - limits_deg[1, 0]) / cell_deg)))
    kd = capacity if dof > 2 else 1
    return TreeArrays(
        np.zeros((capacity, dof), dtype=np.float64), np.full(capacity, -1, dtype=np.int64),
        np.full(capacity, -1, dtype=np.int64), np.full(ncx * ncy, -1, dtype=np.int64),
        np.array([0, ncx, ncy, ncx, ncy, -1, -1, 0, 0], dtype=np.int64),
        np.array([limits_deg[0, 0], limits_deg[1, 0], cell_deg], dtype=np.float64),
        np.zeros(kd, dtype=np.int64), np.zeros(kd, dtype=np.int64),
        np.zeros((KD_STACK, 3), dtype=np.int64), np.zeros(KD_STACK, dtype=np.float64))



@nb.njit(cache=True, nogil=True, inline="always")
def _cell_of(grid, meta, x, y):
    cx = int(math.floor((x - grid[0]) / grid[2]))
    cy = int(math.floor((y - grid[1]) / grid[2]))
    if cx < 0:
        cx = 0
    elif cx >= meta[NCX]:
        cx = meta[NCX] - 1
    if cy < 0:
        cy = 0
    elif cy >= meta[NCY]:
        cy = meta[NCY] - 1
    return cx, cy


@nb.njit(cache=True, nogil=True)
def _grid_add(cell_next, cell_head, meta, grid, i, x, y):
    """File node ``i`` at (x, y) in its grid cell."""
    cx, cy = _cell_of(grid, meta, x, y)
    c = cy * meta[NCX] + cx
    cell_next[i] = cell_head[c]
    cell_head[c] = i
    if cx < meta[BX0]:
        meta[BX0] = cx
    if cx > meta[BX1]:
        meta[BX1] = cx
    if cy < meta[BY0]:
        meta[BY0] = cy
    if cy > meta[BY1]:
        meta[BY1] = cy


@nb.njit(cache=True, nogil=True, inline="always")
def _scan_cell(nodes, cell_next, cell_head, c, q, best_d2, best_i, meta):
    i = cell_head[c]
    while i >= 0:
        meta[NN_VISITS] += 1
        d2 = _d2(nodes, i, q)
        if d2 < best_d2 or (d2 == best_d2 and i < best_i):
            best_d2 = d2
            best_i = i
        i = cell_next[i]
    return best_d2, best_i


@nb.njit(cache=True, nogil=True)
def _grid_nearest(nodes, cell_next, cell_head, meta, grid, q):
    """Index of the node nearest to ``q`` (Euclidean over every joint, degrees; lowest index on
    ties). Cells are over the first two joints; a ring's distance in those two joints is a
    lower bound of the full distance, so stopping on it stays exact in any dimension."""
    x = q[0]
    y = q[1]
    ncx = meta[NCX]
    cx, cy = _cell_of(grid, meta, x, y)
    bx0 = meta[BX0]
    by0 = meta[BY0]
    bx1 = meta[BX1]
    by1 = meta[BY1]
    # Rings closer than the occupied box are empty; rings beyond its far corner hold nothing.
    r0 = max(bx0 - cx, cx - bx1, by0 - cy, cy - by1, 0)
    r_max = max(cx - bx0, bx1 - cx, cy - by0, by1 - cy)
    best_d2 = np.inf
    best_i = -1
    cell = grid[2]
    for r in range(r0, r_max + 1):
        # Any node in ring r + 1 or beyond is at least r cells away.
        if best_i >= 0:
            bound = r - 1 if r >= 1 else 0
            reach = bound * cell
            if best_d2 < reach * reach:
                break
        y_lo = max(cy - r, by0)
        y_hi = min(cy + r, by1)
        # Left and right columns of the ring.
        for xx in (cx - r, cx + r):
            if bx0 <= xx <= bx1:
                for yy in range(y_lo, y_hi + 1):
                    best_d2, best_i = _scan_cell(nodes, cell_next, cell_head, yy * ncx + xx,
                                                 q, best_d2, best_i, meta)
            if r == 0:
                break
        if r > 0:
            x_lo = max(cx - r + 1, bx0)
            x_hi = min(cx + r - 1, bx1)
            for yy in (cy - r, cy + r):
                if by0 <= yy <= by1:
                    for xx in range(x_lo, x_hi + 1):
                        best_d2, best_i = _scan_cell(nodes, cell_next, cell_head,
                                                     yy * ncx + xx, q, best_d2, best_i, meta)
    return best_i


@nb.njit(cache=True, nogil=True, inline="always")
def _d2(nodes, i, q):
    d2 = 0.0
    for j in range(q.shape[0]):
        dj = nodes[i, j] - q[j]
        d2 += dj * dj
    return d2


@nb.njit(cache=True, nogil=True)
def _select(nodes, perm, lo, hi, k, axis):
    """Reorder ``perm[lo:hi]`` so that position ``k`` holds the node of rank ``k - lo`` along
    ``axis``, smaller-or-equal ones before it and greater-or-equal ones after (quickselect,
    middle pivot: deterministic)."""
    while hi - lo > 1:
        pivot = nodes[perm[(lo + hi) // 2], axis]
        i = lo
        j = hi - 1
        while i <= j:
            while nodes[perm[i], axis] < pivot:
                i += 1
            while nodes[perm[j], axis] > pivot:
                j -= 1
            if i <= j:
                t = perm[i]
                perm[i] = perm[j]
                perm[j] = t
                i += 1
                j -= 1
        if k <= j:
            hi = j + 1
        elif k >= i:
            lo = i
        else:
            return


@nb.njit(cache=True, nogil=True)
def _kd_build(T, n):
    """Balanced k-d tree over nodes ``0 .. n-1`` (median splits, axis = depth mod dof)."""
    dof = T.nodes.shape[1]
    for i in range(n):
        T.kd_perm[i] = i
    stack = T.kd_stack
    stack[0, 0] = 0
    stack[0, 1] = n
    stack[0, 2] = 0
    top = 1
    while top > 0:
        top -= 1
        lo = stack[top, 0]
        hi = stack[top, 1]
        d = stack[top, 2]
        if hi - lo <= 0:
            continue
        mid = (lo + hi) // 2
        axis = d % dof
        _select(T.nodes, T.kd_perm, lo, hi, mid, axis)
        T.kd_axis[mid] = axis
        if mid + 1 < hi:
            stack[top, 0] = mid + 1
            stack[top, 1] = hi
            stack[top, 2] = d + 1
            top += 1
        if lo < mid:
            stack[top, 0] = lo
            stack[top, 1] = mid
            stack[top, 2] = d + 1
            top += 1
    T.meta[KD_N] = n


@nb.njit(cache=True, nogil=True)
def _kd_nearest(T, q):
    """Exact nearest node: k-d tree search, then the buffer (lowest index on ties)."""
    nodes = T.nodes
    best_d2 = np.inf
    best_i = -1
    n_kd = T.meta[KD_N]
    stack = T.kd_stack
    lbs = T.kd_stack_lb
    top = 0
    if n_kd > 0:
        stack[0, 0] = 0
        stack[0, 1] = n_kd
        lbs[0] = 0.0
        top = 1
    while top > 0:
        top -= 1
        lo = stack[top, 0]
        hi = stack[top, 1]
        lb = lbs[top]
        while lo < hi and lb <= best_d2:
            mid = (lo + hi) // 2
            i = T.kd_perm[mid]
            T.meta[NN_VISITS] += 1
            d2 = _d2(nodes, i, q)
            if d2 < best_d2 or (d2 == best_d2 and i < best_i):
                best_d2 = d2
                best_i = i
            axis = T.kd_axis[mid]
            diff = q[axis] - nodes[i, axis]
            far_lb = max(lb, diff * diff)
            if diff < 0.0:  # near side: the left range [lo, mid); far: (mid, hi)
                if mid + 1 < hi and far_lb <= best_d2:
                    stack[top, 0] = mid + 1
                    stack[top, 1] = hi
                    lbs[top] = far_lb
                    top += 1
                hi = mid
            else:
                if lo < mid and far_lb <= best_d2:
                    stack[top, 0] = lo
                    stack[top, 1] = mid
                    lbs[top] = far_lb
                    top += 1
                lo = mid + 1
    T.meta[NN_VISITS] += T.meta[N_NODES] - n_kd
    for i in range(n_kd, T.meta[N_NODES]):
        d2 = _d2(nodes, i, q)
        if d2 < best_d2 or (d2 == best_d2 and i < best_i):
            best_d2 = d2
            best_i = i
    return best_i


@nb.njit(cache=True, nogil=True)
def add_node(T, q, parent_index):
    """Append configuration ``q`` with its parent; return its index."""
    i = T.meta[N_NODES]
    for j in range(q.shape[0]):
        T.nodes[i, j] = q[j]
    T.parent[i] = parent_index
    T.meta[N_NODES] = i + 1
    if T.nodes.shape[1] == 2:
        _grid_add(T.cell_next, T.cell_head, T.meta, T.grid, i, q[0], q[1])
    elif (i + 1 - T.meta[KD_N]) > max(32.0, 2.0 * math.sqrt(i + 1.0)):
        _kd_build(T, i + 1)
    return i


@nb.njit(cache=True, nogil=True)
def nearest(T, q):
    """Index of the node nearest to ``q`` (Euclidean, degrees); lowest index on ties."""
    if T.nodes.shape[1] == 2:
        return _grid_nearest(T.nodes, T.cell_next, T.cell_head, T.meta, T.grid, q)
    return _kd_nearest(T, q)


@nb.njit(cache=True, nogil=True)
def reset_tree(T, meta0):
    """Empty ``T`` for the next run (``meta0``: its ``meta`` when new); no allocation."""
    T.meta[:] = meta0
    T.cell_head[:] = -1


@nb.njit(cache=True, nogil=True)
def nearest_brute(nodes, n, q):
    """Linear scan; the reference the grid and k-d searches are tested against."""
    best_d2 = np.inf
    best_i = -1
    for i in range(n):
        d2 = _d2(nodes, i, q)
        if d2 < best_d2:
            best_d2 = d2
            best_i = i
    return best_i


@nb.njit(cache=True, nogil=True)
def extract_path(nodes, parent, last):
    """Configurations from the root to node ``last`` (``[k, dof]``)."""
    k = 0
    i = last
    while i >= 0:
        k += 1
        i = parent[i]
    out = np.empty((k, nodes.shape[1]), dtype=np.float64)
    i = last
    j = k - 1
    while i >= 0:
        for d in range(nodes.shape[1]):
            out[j, d] = nodes[i, d]
        j -= 1
        i = parent[i]
    return out
