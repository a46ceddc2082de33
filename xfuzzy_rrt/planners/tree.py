"""The search tree shared by the planners: node storage and nearest-neighbour queries.

Nodes live in preallocated arrays (``nodes[cap, 2]`` in degrees, ``parent[cap]``), so the
compiled planner loop never allocates. Nearest-neighbour search uses a uniform grid over the
joint box with one linked list per cell, searched in Chebyshev rings around the query's cell
and only within the bounding box of occupied cells. A ring search stops once the best distance
found is strictly below the smallest distance any unvisited ring could hold, so the answer is
*exactly* the brute-force one, ties included (lowest node index wins), while the cost per query
stays roughly constant as the tree grows to 10,000 nodes instead of growing linearly.

Integer bookkeeping is an ``int64`` array ``meta``:
``[n_nodes, ncx, ncy, bx0, by0, bx1, by1]`` (grid size and occupied cell bounding box), and the
grid geometry a ``float64`` array ``grid = [lo0, lo1, cell]``.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

#: Grid cell edge in degrees. 10° cells give a 36 x 36 grid over the full joint box.
CELL_DEG = 10.0

N_NODES, NCX, NCY, BX0, BY0, BX1, BY1 = range(7)


class Tree:
    """Preallocated tree arrays (created in Python once per plan, filled by compiled code)."""

    def __init__(self, capacity: int, limits_deg: np.ndarray, cell_deg: float = CELL_DEG):
        limits_deg = np.asarray(limits_deg, dtype=np.float64)
        if limits_deg.shape != (2, 2):
            raise ValueError("the grid tree supports 2 joints")
        self.nodes = np.zeros((capacity, 2), dtype=np.float64)
        self.parent = np.full(capacity, -1, dtype=np.int64)
        self.cell_next = np.full(capacity, -1, dtype=np.int64)
        ncx = max(1, int(math.ceil((limits_deg[0, 1] - limits_deg[0, 0]) / cell_deg)))
        ncy = max(1, int(math.ceil((limits_deg[1, 1] - limits_deg[1, 0]) / cell_deg)))
        self.cell_head = np.full(ncx * ncy, -1, dtype=np.int64)
        self.meta = np.array([0, ncx, ncy, ncx, ncy, -1, -1], dtype=np.int64)
        self.grid = np.array([limits_deg[0, 0], limits_deg[1, 0], cell_deg], dtype=np.float64)


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
def add_node(nodes, parent, cell_next, cell_head, meta, grid, x, y, parent_index):
    """Append node (x, y) with its parent; return its index."""
    i = meta[N_NODES]
    nodes[i, 0] = x
    nodes[i, 1] = y
    parent[i] = parent_index
    cx, cy = _cell_of(grid, meta, x, y)
    c = cy * meta[NCX] + cx
    cell_next[i] = cell_head[c]
    cell_head[c] = i
    meta[N_NODES] = i + 1
    if cx < meta[BX0]:
        meta[BX0] = cx
    if cx > meta[BX1]:
        meta[BX1] = cx
    if cy < meta[BY0]:
        meta[BY0] = cy
    if cy > meta[BY1]:
        meta[BY1] = cy
    return i


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
def nearest(nodes, cell_next, cell_head, meta, grid, x, y):
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
def nearest_brute(nodes, n, x, y):
    """Linear scan; the reference the grid search is tested against."""
    best_d2 = np.inf
    best_i = -1
    for i in range(n):
        dx = nodes[i, 0] - x
        dy = nodes[i, 1] - y
        d2 = dx * dx + dy * dy
        if d2 < best_d2:
            best_d2 = d2
            best_i = i
    return best_i


@nb.njit(cache=True, nogil=True)
def extract_path(nodes, parent, last):
    """Configurations from the root to node ``last`` (``[k, 2]``)."""
    k = 0
    i = last
    while i >= 0:
        k += 1
        i = parent[i]
    out = np.empty((k, 2), dtype=np.float64)
    i = last
    j = k - 1
    while i >= 0:
        out[j, 0] = nodes[i, 0]
        out[j, 1] = nodes[i, 1]
        j -= 1
        i = parent[i]
    return out
