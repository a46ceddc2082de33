"""The search tree shared by the planners: node storage and exact nearest-neighbour queries.

Nodes live in preallocated arrays (``nodes[cap, dof]`` in degrees, ``parent[cap]``), so the
compiled planner loop never allocates. Nearest-neighbour search is *exact* (the brute-force
answer, ties to the lowest node index) and must not make long runs quadratic:

- **2 joints: a uniform grid** over the joint box with one linked list per cell, searched in
  Chebyshev rings around the query's cell and only within the bounding box of occupied cells.
  A ring search stops once the best distance found is strictly below the smallest distance any
  unvisited ring could hold, so the cost per query stays roughly constant as the tree grows to
  10,000 nodes.
- **3 joints and more: an incremental k-d tree.** A grid's cell count grows like 36^N; a k-d
  tree splits on joint ``depth mod N`` as nodes arrive (RRT inserts in a spatially spread
  order, so the tree stays shallow in practice) and a query descends to the query's leaf,
  then visits the far side of a split only when the split plane is not farther than the best
  distance found (``>=``, not ``>``: equal distances must be seen for the lowest-index tie
  rule). Expected cost per query grows like log n instead of n.

The arrays travel together as one :class:`TreeArrays` record (a numba named tuple). Integer
grid bookkeeping is ``meta = [n_nodes, ncx, ncy, bx0, by0, bx1, by1]`` (grid size and occupied
cell bounding box; ``n_nodes`` is used for every dimension) and the grid geometry
``grid = [lo0, lo1, cell]``.
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
    """Preallocated tree arrays (created in Python once per plan, filled by compiled code).

    ``cell_next``/``cell_head``/``grid`` serve the 2-joint grid, ``kd_left``/``kd_right``/
    ``kd_axis``/``stack`` the k-d tree; the unused structure's arrays have length 1.
    """

    nodes: np.ndarray
    parent: np.ndarray
    cell_next: np.ndarray
    cell_head: np.ndarray
    meta: np.ndarray
    grid: np.ndarray
    kd_left: np.ndarray
    kd_right: np.ndarray
    kd_axis: np.ndarray
    stack: np.ndarray
    stack_lb: np.ndarray


def make_tree(capacity: int, limits_deg: np.ndarray, cell_deg: float = CELL_DEG) -> TreeArrays:
    """Empty tree for ``capacity`` nodes in the joint box ``limits_deg`` (``[dof, 2]``)."""
    limits_deg = np.asarray(limits_deg, dtype=np.float64)
    if limits_deg.ndim != 2 or limits_deg.shape[1] != 2 or limits_deg.shape[0] < 2:
        raise ValueError("the tree needs joint limits of shape [dof >= 2, 2]")
    dof = limits_deg.shape[0]
    nodes = np.zeros((capacity, dof), dtype=np.float64)
    parent = np.full(capacity, -1, dtype=np.int64)
    if dof == 2:
        ncx = max(1, int(math.ceil((limits_deg[0, 1] - limits_deg[0, 0]) / cell_deg)))
        ncy = max(1, int(math.ceil((limits_deg[1, 1] - limits_deg[1, 0]) / cell_deg)))
        cell_next = np.full(capacity, -1, dtype=np.int64)
        cell_head = np.full(ncx * ncy, -1, dtype=np.int64)
        kd = 1
    else:
        ncx = ncy = 1
        cell_next = np.full(1, -1, dtype=np.int64)
        cell_head = np.full(1, -1, dtype=np.int64)
        kd = capacity
    meta = np.array([0, ncx, ncy, ncx, ncy, -1, -1], dtype=np.int64)
    grid = np.array([limits_deg[0, 0], limits_deg[1, 0], cell_deg], dtype=np.float64)
    return TreeArrays(nodes, parent, cell_next, cell_head, meta, grid,
                      np.full(kd, -1, dtype=np.int64), np.full(kd, -1, dtype=np.int64),
                      np.zeros(kd, dtype=np.int64), np.zeros(kd, dtype=np.int64),
                      np.zeros(kd, dtype=np.float64))


#: Old name, kept for callers that build a tree by hand.
Tree = make_tree


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
def _scan_cell(nodes, cell_next, cell_head, c, x, y, best_d2, best_i):
    i = cell_head[c]
    while i >= 0:
        dx = nodes[i, 0] - x
        dy = nodes[i, 1] - y
        d2 = dx * dx + dy * dy
        if d2 < best_d2 or (d2 == best_d2 and i < best_i):
            best_d2 = d2
            best_i = i
        i = cell_next[i]
    return best_d2, best_i


@nb.njit(cache=True, nogil=True)
def _grid_nearest(nodes, cell_next, cell_head, meta, grid, x, y):
    """Index of the node nearest to (x, y) (Euclidean, degrees); lowest index on ties."""
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
                                                 x, y, best_d2, best_i)
            if r == 0:
                break
        if r > 0:
            x_lo = max(cx - r + 1, bx0)
            x_hi = min(cx + r - 1, bx1)
            for yy in (cy - r, cy + r):
                if by0 <= yy <= by1:
                    for xx in range(x_lo, x_hi + 1):
                        best_d2, best_i = _scan_cell(nodes, cell_next, cell_head,
                                                     yy * ncx + xx, x, y, best_d2, best_i)
    return best_i


@nb.njit(cache=True, nogil=True)
def _kd_add(T, i):
    """Hang node ``i`` under the k-d tree (split axis = depth mod dof; ties go right)."""
    dof = T.nodes.shape[1]
    T.kd_left[i] = -1  # a reused tree may hold links from an earlier run
    T.kd_right[i] = -1
    if i == 0:
        T.kd_axis[0] = 0
        return
    j = 0
    while True:
        ax = T.kd_axis[j]
        if T.nodes[i, ax] < T.nodes[j, ax]:
            nxt = T.kd_left[j]
            if nxt < 0:
                T.kd_left[j] = i
                break
        else:
            nxt = T.kd_right[j]
            if nxt < 0:
                T.kd_right[j] = i
                break
        j = nxt
    ax = T.kd_axis[j] + 1
    T.kd_axis[i] = ax if ax < dof else 0


@nb.njit(cache=True, nogil=True, inline="always")
def _d2(nodes, i, q):
    d2 = 0.0
    for j in range(q.shape[0]):
        dj = nodes[i, j] - q[j]
        d2 += dj * dj
    return d2


@nb.njit(cache=True, nogil=True)
def _kd_nearest(T, q):
    """Exact nearest node (lowest index on ties) by depth-first k-d search with pruning."""
    nodes = T.nodes
    stack = T.stack
    stack_lb = T.stack_lb
    best_d2 = np.inf
    best_i = -1
    top = 0
    stack[0] = 0
    stack_lb[0] = 0.0
    top = 1
    while top > 0:
        top -= 1
        i = stack[top]
        lb = stack_lb[top]
        if lb > best_d2:
            continue
        while i >= 0:
            d2 = _d2(nodes, i, q)
            if d2 < best_d2 or (d2 == best_d2 and i < best_i):
                best_d2 = d2
                best_i = i
            ax = T.kd_axis[i]
            diff = q[ax] - nodes[i, ax]
            if diff < 0.0:
                near = T.kd_left[i]
                far = T.kd_right[i]
            else:
                near = T.kd_right[i]
                far = T.kd_left[i]
            if far >= 0:
                far_lb = max(lb, diff * diff)
                if far_lb <= best_d2:
                    stack[top] = far
                    stack_lb[top] = far_lb
                    top += 1
            i = near
    return best_i


@nb.njit(cache=True, nogil=True)
def add_node(T, q, parent_index):
    """Append configuration ``q`` with its parent; return its index."""
    i = T.meta[N_NODES]
    for j in range(q.shape[0]):
        T.nodes[i, j] = q[j]
    T.parent[i] = parent_index
    if T.nodes.shape[1] == 2:
        _grid_add(T.cell_next, T.cell_head, T.meta, T.grid, i, q[0], q[1])
    else:
        _kd_add(T, i)
    T.meta[N_NODES] = i + 1
    return i


@nb.njit(cache=True, nogil=True)
def nearest(T, q):
    """Index of the node nearest to ``q`` (Euclidean, degrees); lowest index on ties."""
    if T.nodes.shape[1] == 2:
        return _grid_nearest(T.nodes, T.cell_next, T.cell_head, T.meta, T.grid, q[0], q[1])
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
