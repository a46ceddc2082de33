"""The search tree shared by the planners: node storage and exact nearest-neighbour queries.

Nodes live in preallocated arrays (``nodes[cap, dof]`` in degrees, ``parent[cap]``), so the
compiled planner loop never allocates. Nearest-neighbour search is *exact* (the brute-force
answer, ties to the lowest node index) and must not make long runs quadratic.

- **Small trees: a linear scan.** Below a measured size (``BRUTE_MAX_2D``, ``BRUTE_MAX_KD``;
  ``benchmarks/nn_scaling.py``) scanning every node beats any structure's bookkeeping.
- **Two joints: a uniform grid** with one linked list per cell, searched in Chebyshev rings
  around the query's cell and only within the bounding box of occupied cells. A ring search
  stops once the best distance found is strictly below the smallest distance any unvisited ring
  could hold, so the cost per query stays roughly constant as the tree grows to 10,000 nodes.
- **Three joints and more: a balanced k-d tree plus a small buffer.** The nodes added since the
  last build sit in a buffer scanned linearly; when it outgrows ``max(32, 2 sqrt(n))`` the
  k-d tree is rebuilt over all nodes by median splits (quickselect) along each range's widest
  axis, down to buckets of ``KD_LEAF`` nodes, so it is balanced whatever order the nodes came
  in. An *incremental* k-d tree was measured slower than a linear scan: an RRT adds nodes in a
  spatially correlated order and the tree degenerates into a chain. A query descends the k-d
  tree depth first and visits a far side only when the squared distance from the query to its
  cell, summed over every axis (not just the split axis: that is what keeps 5-7 joints
  pruning), is not above the best distance found (``<=``: equal distances must be seen for
  the lowest-index tie rule), then scans the buffer. Rebuilds cost ``O(n log n)`` about
  ``sqrt(n) / 2`` times per run; a query costs the tree search plus at most ``2 sqrt(n)``
  distances. At 7 joints a whole RRT-like run of N nodes costs about N^1.4 distance
  evaluations (measured, benchmarks/nn_scaling.py), not N^2.

Every distance a query computes adds 1 to ``meta[NN_VISITS]`` (the deterministic work count).

The arrays travel together as one :class:`TreeArrays` record (a numba named tuple). Integer
grid bookkeeping is ``meta = [n_nodes, ncx, ncy, bx0, by0, bx1, by1, kd_n, nn_visits]`` (grid
size, occupied cell bounding box, nodes in the k-d tree, distances computed) and the grid geometry ``grid = [lo0, lo1, cell]``.
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
    #: per stack entry (and one more row for the range being searched), the query's offset
    #: from the range's cell along every axis
    kd_off: np.ndarray
    #: each node's clearance (m) as measured when it was accepted (NaN where it was not:
    #: a goal joined by the connection step); planners read it instead of measuring again
    clear: np.ndarray
    #: what the certified edge check measures at an edge's ends, per node, so that an edge
    #: leaving or reaching a measured node does not measure it again
    #: (:func:`xfuzzy_rrt.planners.extend.extend`); the last row holds the goal's. One two-link
    #: arm: each node's clearance per link (``[capacity + 1, 2]``; ``NaN`` in column 0: not
    #: measured in this run, which :func:`add_node` writes for every new node, and for the goal
    #: row when a run adds its root). Any other arm, in a tree made with ``stops``: each
    #: node's stop record (``[capacity + 1, stops]``,
    #: :func:`~xfuzzy_rrt.geometry.collision.node_stop_into`; column 0 is 1.0 once complete,
    #: written by the node check before the node is added; :func:`add_node` marks the root's
    #: and the goal's rows not measured when a run adds its root). Otherwise ``[1, 2]``, unused.
    link_clear: np.ndarray
    #: two joints, grids of at most 64 x 64 cells (``[ncy + ncx]``; ``[1]`` otherwise, unused):
    #: occupied cells as bits, row ``y`` in ``occ[y]`` (bit ``x``) and column ``x`` in
    #: ``occ[ncy + x]`` (bit ``y``), so that a ring search skips empty cells without reading
    #: them (:func:`_grid_nearest_occ`); zeroed with ``cell_head``
    occ: np.ndarray
    #: scratch of the certified checks of any other arm (:func:`~xfuzzy_rrt.geometry.collision.
    #: edge_free_into`, ``clearance_into``; ``L`` joints in all): link segments ``[L, 4]``,
    #: motion bounds ``[L]`` and self-pair bounds ``[L, L]``. Here, not in the shared problem
    #: record, because a tree belongs to one run at a time and Dask threads share problems.
    seg: np.ndarray
    mks: np.ndarray
    msf: np.ndarray


#: ``meta`` slot holding how many nodes the k-d tree covers (the rest are in the buffer).
KD_N = 7
#: ``meta`` slot counting the tree nodes whose distance to a nearest-neighbour query was
#: computed (the tree's share of the deterministic work count, docs: interfaces item 1).
NN_VISITS = 8
#: Trees up to this many nodes answer a query by a linear scan, which beats the grid (two
#: joints) or the k-d tree there (benchmarks/nn_scaling.py measures the crossover).
BRUTE_MAX_2D = 128
#: The same for the k-d tree, by number of joints (3, 4, 5, 6, 7+).
BRUTE_MAX_KD = (192, 256, 384, 640, 768)
#: The k-d cell bound is multiplied by this before it may prune (1e-9 below exact: rounding in
#: the bound can never hide a node as close as the best one).
KD_SLACK = 1.0 - 1e-9
#: Largest k-d bucket (a range this small is scanned, not split).
KD_LEAF = 12
#: Entries of the k-d search stack: two per level of a balanced tree of 10^6 nodes, and more.
KD_STACK = 128


#: Largest stop-record table a tree keeps (bytes): 16 MB holds a 7-joint arm's records for a
#: Fuzzy-RRT-Connect tree of 20,008 nodes (3.7 MB) and two 7-joint arms' (15 MB); three arms of
#: 7 joints would need 34 MB per tree and measure both ends of each edge instead.
RECORDS_MAX_BYTES = 16 * 2**20


def make_tree(capacity: int, limits_deg: np.ndarray, cell_deg: float = CELL_DEG,
              stops: int = 0) -> TreeArrays:
    """Empty tree for ``capacity`` nodes in the joint box ``limits_deg`` (``[dof, 2]``).

    ``stops``: the width of one node's stop record for the problem it will grow in
    (:func:`~xfuzzy_rrt.geometry.collision.stop_width`,
    :attr:`~xfuzzy_rrt.geometry.scenario.ScenarioArrays.stop_width`; 0 for one two-link arm,
    which keeps its per-link values instead). With 0, or a width that is not the problem's,
    every edge measures both its ends (the same results, more time), as it does when the
    records would take more than :data:`RECORDS_MAX_BYTES` (many arms of many joints: the width
    grows with the square of the links)."""
    limits_deg = np.asarray(limits_deg, dtype=np.float64)
    if limits_deg.ndim != 2 or limits_deg.shape[1] != 2 or limits_deg.shape[0] < 2:
        raise ValueError("the tree needs joint limits of shape [dof >= 2, 2]")
    dof = limits_deg.shape[0]
    ncx = max(1, int(math.ceil((limits_deg[0, 1] - limits_deg[0, 0]) / cell_deg)))
    ncy = max(1, int(math.ceil((limits_deg[1, 1] - limits_deg[1, 0]) / cell_deg)))
    kd = capacity if dof > 2 else 1
    if int(stops) * (capacity + 1) * 8 > RECORDS_MAX_BYTES:
        stops = 0
    # ``nodes``, ``parent`` and ``cell_next`` are written before they are read (add_node), so
    # they are left uninitialised: filling 10,000-entry arrays cost more than a short plan.
    return TreeArrays(
        np.empty((capacity, dof), dtype=np.float64), np.empty(capacity, dtype=np.int64),
        np.empty(capacity if dof == 2 else 1, dtype=np.int64),
        np.full(ncx * ncy if dof == 2 else 1, -1, dtype=np.int64),
        np.array([0, ncx, ncy, ncx, ncy, -1, -1, 0, 0], dtype=np.int64),
        np.array([limits_deg[0, 0], limits_deg[1, 0], cell_deg], dtype=np.float64),
        np.zeros(kd, dtype=np.int64), np.zeros(kd, dtype=np.int64),
        np.zeros((KD_STACK, 3), dtype=np.int64), np.zeros(KD_STACK, dtype=np.float64),
        np.zeros((KD_STACK + 1 if dof > 2 else 1, dof), dtype=np.float64),
        np.empty(capacity, dtype=np.float64),
        np.full((capacity + 1, int(stops)) if stops > 0 else
                (capacity + 1 if dof == 2 else 1, 2), np.nan, dtype=np.float64),
        np.zeros(ncy + ncx if dof == 2 and ncx <= 64 and ncy <= 64 else 1, dtype=np.uint64),
        np.zeros((dof, 4), dtype=np.float64), np.zeros(dof, dtype=np.float64),
        np.zeros((dof, dof), dtype=np.float64))



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


@nb.njit(cache=True, nogil=True, _nrt=False)
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
    return cx, cy


@nb.njit(cache=True, nogil=True, inline="always")
def _scan_cell(nodes, cell_next, cell_head, c, q, best_d2, best_i, visits):
    i = cell_head[c]
    while i >= 0:
        d2 = _d2(nodes, i, q)
        visits += 1
        if d2 < best_d2 or (d2 == best_d2 and i < best_i):
            best_d2 = d2
            best_i = i
        i = cell_next[i]
    return best_d2, best_i, visits


@nb.njit(cache=True, nogil=True, _nrt=False)
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
    visits = 0
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
                    best_d2, best_i, visits = _scan_cell(nodes, cell_next, cell_head,
                                                         yy * ncx + xx, q, best_d2, best_i,
                                                         visits)
            if r == 0:
                break
        if r > 0:
            x_lo = max(cx - r + 1, bx0)
            x_hi = min(cx + r - 1, bx1)
            for yy in (cy - r, cy + r):
                if by0 <= yy <= by1:
                    for xx in range(x_lo, x_hi + 1):
                        best_d2, best_i, visits = _scan_cell(nodes, cell_next, cell_head,
                                                             yy * ncx + xx, q, best_d2, best_i,
                                                             visits)
    meta[NN_VISITS] += visits
    return best_i


@nb.njit(cache=True, nogil=True, _nrt=False)
def _grid_nearest_occ(nodes, cell_next, cell_head, meta, grid, occ, q):
    """:func:`_grid_nearest` reading the occupied-cell bits ``occ`` (``T.occ``): the same rings,
    the same cells and nodes visited (so the same answer and ``NN_VISITS``), but an empty cell
    costs a bit test instead of a memory read, and a ring side stops at its last occupied cell.

    Takes the arrays it reads, not the tree: a call passes a tree record as some hundred
    machine words, which cost as much as a small search."""
    ncx = meta[NCX]
    ncy = meta[NCY]
    cx, cy = _cell_of(grid, meta, q[0], q[1])
    bx0 = meta[BX0]
    by0 = meta[BY0]
    bx1 = meta[BX1]
    by1 = meta[BY1]
    r0 = max(bx0 - cx, cx - bx1, by0 - cy, cy - by1, 0)
    r_max = max(cx - bx0, bx1 - cx, cy - by0, by1 - cy)
    best_d2 = np.inf
    best_i = -1
    visits = 0
    cell = grid[2]
    one = np.uint64(1)
    for r in range(r0, r_max + 1):
        if best_i >= 0:
            bound = r - 1 if r >= 1 else 0
            reach = bound * cell
            if best_d2 < reach * reach:
                break
        y_lo = max(cy - r, by0)
        y_hi = min(cy + r, by1)
        for xx in (cx - r, cx + r):
            if bx0 <= xx <= bx1 and y_lo <= y_hi:
                bits = occ[ncy + xx] >> np.uint64(y_lo)
                yy = y_lo
                while bits != 0 and yy <= y_hi:
                    if bits & one:
                        best_d2, best_i, visits = _scan_cell(nodes, cell_next, cell_head,
                                                             yy * ncx + xx, q, best_d2, best_i,
                                                             visits)
                    bits >>= one
                    yy += 1
            if r == 0:
                break
        if r > 0:
            x_lo = max(cx - r + 1, bx0)
            x_hi = min(cx + r - 1, bx1)
            for yy in (cy - r, cy + r):
                if by0 <= yy <= by1 and x_lo <= x_hi:
                    bits = occ[yy] >> np.uint64(x_lo)
                    xx = x_lo
                    while bits != 0 and xx <= x_hi:
                        if bits & one:
                            best_d2, best_i, visits = _scan_cell(nodes, cell_next, cell_head,
                                                                 yy * ncx + xx, q, best_d2,
                                                                 best_i, visits)
                        bits >>= one
                        xx += 1
    meta[NN_VISITS] += visits
    return best_i


@nb.njit(cache=True, nogil=True, inline="always")
def _d2(nodes, i, q):
    if q.shape[0] == 2:  # the same sum, unrolled (0.0 + a == a for a >= 0)
        dx = nodes[i, 0] - q[0]
        dy = nodes[i, 1] - q[1]
        return dx * dx + dy * dy
    d2 = 0.0
    for j in range(q.shape[0]):
        dj = nodes[i, j] - q[j]
        d2 += dj * dj
    return d2


@nb.njit(cache=True, nogil=True, _nrt=False)
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


@nb.njit(cache=True, nogil=True, inline="always")
def _kd_build(T, n):
    """Balanced k-d tree over nodes ``0 .. n-1``: median splits along the range's widest axis,
    down to buckets of at most ``KD_LEAF`` nodes (:func:`_kd_build_arrays` on ``T``'s arrays)."""
    _kd_build_arrays(T.nodes, T.kd_perm, T.kd_axis, T.kd_stack, T.meta, n)


@nb.njit(cache=True, nogil=True, _nrt=False)
def _kd_build_arrays(nodes, kd_perm, kd_axis, kd_stack, meta, n):
    """:func:`_kd_build` given the arrays it touches, not the whole tree record. Why: a record
    passed to a compiled call travels as every one of its arrays (~130 machine words), and a
    loop that chooses between two trees (Fuzzy-RRT-Connect's) then has to choose all of them,
    every iteration, just in case this rare call happens."""
    dof = nodes.shape[1]
    for i in range(n):
        kd_perm[i] = i
    stack = kd_stack
    stack[0, 0] = 0
    stack[0, 1] = n
    stack[0, 2] = 0
    top = 1
    while top > 0:
        top -= 1
        lo = stack[top, 0]
        hi = stack[top, 1]
        d = stack[top, 2]
        if hi - lo <= KD_LEAF:
            continue  # a bucket: scanned linearly by the query
        mid = (lo + hi) // 2
        # split the widest extent (median of that axis): cells stay compact in any dimension
        axis = 0
        widest = -1.0
        for j in range(dof):
            a_min = np.inf
            a_max = -np.inf
            for k in range(lo, hi):
                v = nodes[kd_perm[k], j]
                if v < a_min:
                    a_min = v
                if v > a_max:
                    a_max = v
            if a_max - a_min > widest:
                widest = a_max - a_min
                axis = j
        _select(nodes, kd_perm, lo, hi, mid, axis)
        kd_axis[mid] = axis
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
    meta[KD_N] = n


@nb.njit(cache=True, nogil=True, inline="always")
def _kd_nearest(T, q):
    """Exact nearest node: k-d tree search, then the buffer (lowest index on ties)
    (:func:`_kd_nearest_arrays` on ``T``'s arrays)."""
    return _kd_nearest_arrays(T.nodes, T.kd_perm, T.kd_axis, T.kd_stack, T.kd_stack_lb,
                              T.kd_off, T.meta, q)


@nb.njit(cache=True, nogil=True, _nrt=False)
def _kd_nearest_arrays(nodes, kd_perm, kd_axis, kd_stack, kd_stack_lb, kd_off, meta, q):
    """:func:`_kd_nearest` given the arrays it touches, not the whole tree record (why: see
    :func:`_kd_build_arrays`).

    A range is skipped when a lower bound of the squared distance from ``q`` to its cell
    exceeds the best found: the sum over axes of the squared offset from ``q`` to the cell
    (Arya and Mount's incremental distance), which in 5-7 joints prunes far more than the largest
    single-axis offset. The bound is relaxed by ``KD_SLACK`` so that rounding (the bound and
    a node's distance sum their terms in different orders) can never prune a node as close as
    the best: only the speed depends on the bound, never the answer.
    """
    dof = q.shape[0]
    best_d2 = np.inf
    best_i = -1
    visits = 0
    n_kd = meta[KD_N]
    stack = kd_stack
    lbs = kd_stack_lb
    off = kd_off
    cur = KD_STACK  # the row of ``off`` holding the current range's offsets
    top = 0
    if n_kd > 0:
        stack[0, 0] = 0
        stack[0, 1] = n_kd
        lbs[0] = 0.0
        for j in range(dof):
            off[0, j] = 0.0
        top = 1
    while top > 0:
        top -= 1
        lo = stack[top, 0]
        hi = stack[top, 1]
        lb = lbs[top]
        if lb * KD_SLACK > best_d2:
            continue
        for j in range(dof):
            off[cur, j] = off[top, j]
        while lo < hi and lb * KD_SLACK <= best_d2:
            if hi - lo <= KD_LEAF:
                for k in range(lo, hi):
                    i = kd_perm[k]
                    d2 = _d2(nodes, i, q)
                    if d2 < best_d2 or (d2 == best_d2 and i < best_i):
                        best_d2 = d2
                        best_i = i
                visits += hi - lo
                break
            mid = (lo + hi) // 2
            i = kd_perm[mid]
            d2 = _d2(nodes, i, q)
            visits += 1
            if d2 < best_d2 or (d2 == best_d2 and i < best_i):
                best_d2 = d2
                best_i = i
            axis = kd_axis[mid]
            diff = q[axis] - nodes[i, axis]
            old = off[cur, axis]
            far_lb = lb - old * old + diff * diff
            if far_lb * KD_SLACK <= best_d2 and ((diff < 0.0 and mid + 1 < hi) or
                                                 (diff >= 0.0 and lo < mid)):
                if diff < 0.0:  # near side: the left range [lo, mid); far: (mid, hi)
                    stack[top, 0] = mid + 1
                    stack[top, 1] = hi
                else:
                    stack[top, 0] = lo
                    stack[top, 1] = mid
                for j in range(dof):
                    off[top, j] = off[cur, j]
                off[top, axis] = diff
                lbs[top] = far_lb
                top += 1
            if diff < 0.0:
                hi = mid
            else:
                lo = mid + 1
    n = meta[N_NODES]
    for i in range(n_kd, n):
        d2 = _d2(nodes, i, q)
        if d2 < best_d2 or (d2 == best_d2 and i < best_i):
            best_d2 = d2
            best_i = i
    meta[NN_VISITS] += visits + (n - n_kd)
    return best_i


@nb.njit(cache=True, nogil=True, inline="always")
def add_node(T, q, parent_index):
    """Append configuration ``q`` with its parent; return its index."""
    i = T.meta[N_NODES]
    for j in range(q.shape[0]):
        T.nodes[i, j] = q[j]
    T.parent[i] = parent_index
    T.meta[N_NODES] = i + 1
    dof = T.nodes.shape[1]
    if dof == 2:
        # not measured yet (extend writes the values after adding a node it measured); a new
        # run starts with its root, and its goal is not measured yet either
        T.link_clear[i, 0] = np.nan
        if i == 0:
            T.link_clear[T.link_clear.shape[0] - 1, 0] = np.nan
        cx, cy = _grid_add(T.cell_next, T.cell_head, T.meta, T.grid, i, q[0], q[1])
        if T.occ.shape[0] > 1:
            T.occ[cy] |= np.uint64(1) << np.uint64(cx)
            T.occ[T.meta[NCY] + cx] |= np.uint64(1) << np.uint64(cy)
    else:
        if i == 0 and T.link_clear.shape[0] > 1:  # a new run: no stop record measured yet
            T.link_clear[0, 0] = np.nan
            T.link_clear[T.link_clear.shape[0] - 1, 0] = np.nan
        if i + 1 > _brute_max(dof) and (i + 1 - T.meta[KD_N]) > max(32.0,
                                                                    2.0 * math.sqrt(i + 1.0)):
            _kd_build(T, i + 1)
    return i


@nb.njit(cache=True, nogil=True, inline="always")
def _brute_max(dof):
    if dof == 2:
        return BRUTE_MAX_2D
    return BRUTE_MAX_KD[min(dof, 7) - 3]


@nb.njit(cache=True, nogil=True, _nrt=False)
def _scan_nodes(nodes, meta, q):
    """Linear scan of every node (lowest index on ties: only a strictly smaller distance
    replaces the best); the arrays, not the tree (see :func:`_grid_nearest_occ`)."""
    n = meta[N_NODES]
    best_d2 = np.inf
    best_i = -1
    for i in range(n):
        d2 = _d2(nodes, i, q)
        if d2 < best_d2:
            best_d2 = d2
            best_i = i
    meta[NN_VISITS] += n
    return best_i


@nb.njit(cache=True, nogil=True, inline="always")
def nearest(T, q):
    """Index of the node nearest to ``q`` (Euclidean, degrees); lowest index on ties."""
    dof = T.nodes.shape[1]
    if T.meta[N_NODES] <= _brute_max(dof):
        return _scan_nodes(T.nodes, T.meta, q)
    if dof == 2:
        if T.occ.shape[0] > 1:
            return _grid_nearest_occ(T.nodes, T.cell_next, T.cell_head, T.meta, T.grid, T.occ,
                                     q)
        return _grid_nearest(T.nodes, T.cell_next, T.cell_head, T.meta, T.grid, q)
    return _kd_nearest(T, q)


@nb.njit(cache=True, nogil=True, _nrt=True)
def reset_tree(T, meta0):
    """Empty ``T`` for the next run (``meta0``: its ``meta`` when new); no allocation.

    Only the grid cells in the occupied bounding box (``meta[BX0:BY1 + 1]``) can hold a node:
    every node is filed by :func:`_grid_add`, which widens the box to its cell. So only those
    cells and their occupancy words are cleared, not the whole grid: a 36 x 36 grid is 10 KB,
    a short 2-joint plan fills a few of its cells, and clearing all of it wrote 162 cache lines
    per call, each one a miss when the call starts cold. A tree with more joints has no grid
    (its box stays empty, so nothing is cleared), while a 2-joint grid of one cell (joint
    limits narrower than a cell) is cleared like any other. The occupancy words exist only for
    grids of at most 64 x 64 cells (the test is :func:`add_node`'s)."""
    ncx = T.meta[NCX]
    ncy = T.meta[NCY]
    x0 = T.meta[BX0]
    x1 = T.meta[BX1]
    occ = T.occ.shape[0] > 1
    for y in range(T.meta[BY0], T.meta[BY1] + 1):
        for x in range(x0, x1 + 1):
            T.cell_head[y * ncx + x] = -1
        if occ:
            T.occ[y] = 0
    if occ:
        for x in range(x0, x1 + 1):
            T.occ[ncy + x] = 0
    T.meta[:] = meta0


@nb.njit(cache=True, nogil=True, _nrt=False)
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


@nb.njit(cache=True, nogil=True, _nrt=True)
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
