"""Nearest neighbour is exact at every size and dimension: the linear scan below the threshold,
the grid (2 joints) and the k-d tree (3+) above it all give the brute-force answer, ties to the
lowest node index, on random and RRT-like insertion orders; and every distance computed is
counted in ``meta[NN_VISITS]`` (issue 24, interfaces item 1)."""

from __future__ import annotations

import numpy as np
import pytest

from xfuzzy_rrt.planners import tree as tr


def _limits(dof):
    return np.array([[-180.0, 180.0]] * dof)


def _rrt_like(dof, n, rng, step=10.0):
    pts = np.zeros((n, dof))
    for k in range(1, n):
        q = rng.uniform(-180.0, 180.0, dof)
        i = int(np.argmin(((pts[:k] - q) ** 2).sum(axis=1)))
        d = float(np.sqrt(((pts[i] - q) ** 2).sum()))
        pts[k] = pts[i] + (q - pts[i]) * (1.0 if d <= step else step / d)
    return pts


def _points(kind, dof, n, rng):
    if kind == "random":
        return rng.uniform(-180.0, 180.0, (n, dof))
    if kind == "rrt":
        return _rrt_like(dof, n, rng)
    # ties: coarse lattice with repeated points, queries on the lattice too
    return rng.integers(-3, 4, (n, dof)).astype(np.float64) * 20.0


def _queries(kind, dof, rng, m=150):
    if kind == "ties":
        return rng.integers(-3, 4, (m, dof)).astype(np.float64) * 20.0 + \
            rng.choice([0.0, 10.0], (m, dof))
    return rng.uniform(-200.0, 200.0, (m, dof))


def _lowest_brute(pts, n, q):
    d2 = ((pts[:n] - q) ** 2).sum(axis=1)
    return int(np.flatnonzero(d2 == d2.min())[0])


@pytest.mark.parametrize("dof", [2, 3, 4, 5, 6, 7])
@pytest.mark.parametrize("kind", ["random", "rrt", "ties"])
def test_nearest_is_the_lowest_index_brute_force_answer_at_every_size(dof, kind):
    rng = np.random.default_rng(100 * dof + len(kind))
    n = 700 if dof > 2 else 400
    pts = _points(kind, dof, n, rng)
    T = tr.make_tree(n + 1, _limits(dof))
    checkpoints = {1, 2, 5, 31, 64, 65, 130, 257, 300, 511, n}
    for k in range(n):
        tr.add_node(T, pts[k], k - 1)
        if k + 1 in checkpoints:
            for q in _queries(kind, dof, rng, 60):
                want = _lowest_brute(pts, k + 1, q)
                assert tr.nearest(T, q) == want
                assert tr.nearest_brute(T.nodes, k + 1, q) == want


@pytest.mark.parametrize("dof", [3, 5, 7])
@pytest.mark.parametrize("kind", ["random", "rrt", "ties"])
@pytest.mark.parametrize("n", [1, 13, 40, 200])
def test_the_kd_tree_itself_is_exact_below_the_brute_force_threshold(dof, kind, n):
    # nearest() scans small trees linearly; the k-d search must still be right there
    rng = np.random.default_rng(7 * n + dof)
    pts = _points(kind, dof, n, rng)
    T = tr.make_tree(n + 1, _limits(dof))
    for k in range(n):
        tr.add_node(T, pts[k], -1)
    for built in (n, n // 2):  # all nodes in the tree, or half of them in the buffer
        tr._kd_build(T, built)
        for q in _queries(kind, dof, rng):
            assert tr._kd_nearest(T, q) == _lowest_brute(pts, n, q)


@pytest.mark.parametrize("kind", ["random", "rrt", "ties"])
@pytest.mark.parametrize("n", [1, 9, 50, 120])
def test_the_grid_itself_is_exact_below_the_brute_force_threshold(kind, n):
    rng = np.random.default_rng(n)
    pts = _points(kind, 2, n, rng)
    T = tr.make_tree(n + 1, _limits(2))
    for k in range(n):
        tr.add_node(T, pts[k], -1)
    for q in _queries(kind, 2, rng):
        got = tr._grid_nearest(T.nodes, T.cell_next, T.cell_head, T.meta, T.grid, q)
        assert got == _lowest_brute(pts, n, q)


@pytest.mark.parametrize("dof", [2, 3, 7])
def test_every_distance_a_query_computes_is_counted(dof):
    rng = np.random.default_rng(dof)
    T = tr.make_tree(2000, _limits(dof))
    assert T.meta[tr.NN_VISITS] == 0
    for q in rng.uniform(-180, 180, (10, dof)):
        tr.add_node(T, q, -1)
    before = int(T.meta[tr.NN_VISITS])
    tr.nearest(T, np.zeros(dof))
    assert T.meta[tr.NN_VISITS] - before == 10  # a small tree is scanned: every node once
    for q in rng.uniform(-180, 180, (1500, dof)):
        tr.add_node(T, q, -1)
    before = int(T.meta[tr.NN_VISITS])
    tr.nearest(T, np.zeros(dof))
    visited = int(T.meta[tr.NN_VISITS]) - before
    assert 1 <= visited <= 1510  # no node is looked at twice
    if dof <= 3:
        assert visited < 1510  # the structure prunes, and says how much it looked at


def test_a_plan_counts_its_neighbour_visits_and_a_fresh_tree_starts_at_zero():
    from xfuzzy_rrt.planners.prepared import pooled_tree
    from xfuzzy_rrt.planners.tree_arena import emptied_tree_in

    limits = _limits(2)
    arena = pooled_tree(100, limits)  # what the planners take, emptied by their entry
    T = emptied_tree_in(arena.block, arena.layout)
    tr.add_node(T, np.zeros(2), -1)
    tr.nearest(T, np.ones(2))
    assert T.meta[tr.NN_VISITS] == 1
    again = pooled_tree(100, limits)  # the next plan gets the same tree back, emptied
    assert emptied_tree_in(again.block, again.layout).meta[tr.NN_VISITS] == 0


def test_a_plan_that_grows_two_trees_gets_two_distinct_pooled_trees_back_each_time():
    from xfuzzy_rrt.planners.prepared import pooled_tree, pooled_trees

    limits = _limits(3)
    a, b = pooled_trees(100, limits, 2)
    assert a.block is not b.block
    again = pooled_trees(100, limits, 2)  # one entry, found again
    assert again[0] is a and again[1] is b
    single = pooled_tree(100, limits).block
    assert single is not a.block and single is not b.block


def test_pooled_trees_are_found_by_the_limits_array_and_by_equal_values_alike():
    from xfuzzy_rrt.planners.prepared import pooled_trees

    limits = _limits(3)
    first = pooled_trees(64, limits, 1)
    assert pooled_trees(64, limits, 1) is first  # the same array: the identity look-up
    assert pooled_trees(64, limits.copy(), 1) is first  # equal values: the same pooled tree
    other = limits.copy()
    other[0, 1] -= 1.0
    assert pooled_trees(64, other, 1) is not first  # other limits: another tree
    assert pooled_trees(65, limits, 1) is not first and pooled_trees(64, limits, 2) is not first


def test_pooled_trees_keep_no_more_trees_alive_than_the_pool_holds():
    import gc
    import weakref

    from xfuzzy_rrt.planners import prepared

    made = []
    for k in range(prepared._TREES_PER_THREAD + 3):
        limits = _limits(2)
        limits[0, 1] -= k  # distinct values: a new pool entry each
        made.append(weakref.ref(prepared.pooled_trees(32, limits, 1)[0].block))
    gc.collect()
    alive = sum(ref() is not None for ref in made)
    assert alive <= prepared._TREES_PER_THREAD
