"""Nearest-neighbour cost per query in a 10,000-node tree: grid search vs linear scan.

The grid search must keep long runs from becoming quadratic; each round answers 10,000
queries (uniform samples) against a tree of 10,000 nodes grown like an RRT tree (clustered
random walk), inside compiled code.
"""

from __future__ import annotations

import numba as nb
import numpy as np
import pytest

from xfuzzy_rrt.planners.tree import Tree, add_node, nearest, nearest_brute

N = 10_000


@nb.njit(cache=True)
def _queries_grid(nodes, cell_next, cell_head, meta, grid, qs):
    acc = 0
    for j in range(qs.shape[0]):
        acc += nearest(nodes, cell_next, cell_head, meta, grid, qs[j, 0], qs[j, 1])
    return acc


@nb.njit(cache=True)
def _queries_brute(nodes, n, qs):
    acc = 0
    for j in range(qs.shape[0]):
        acc += nearest_brute(nodes, n, qs[j, 0], qs[j, 1])
    return acc


@pytest.fixture(scope="module")
def tree_and_queries():
    rng = np.random.default_rng(0)
    steps = rng.normal(0, 6.0, size=(N, 2))
    walk = np.clip(np.cumsum(steps, axis=0) % 360.0 - 180.0, -180, 180)
    tree = Tree(N, np.array([[-180.0, 180.0], [-180.0, 180.0]]))
    for p in walk:
        add_node(tree.nodes, tree.parent, tree.cell_next, tree.cell_head, tree.meta, tree.grid,
                 p[0], p[1], -1)
    return tree, rng.uniform(-180, 180, size=(N, 2))


def test_nearest_grid_10k(benchmark, tree_and_queries):
    tree, qs = tree_and_queries
    args = (tree.nodes, tree.cell_next, tree.cell_head, tree.meta, tree.grid, qs)
    expected = _queries_brute(tree.nodes, N, qs)
    assert benchmark(_queries_grid, *args) == expected
    benchmark.extra_info["per_query_us"] = benchmark.stats.stats.median / N * 1e6


def test_nearest_brute_10k(benchmark, tree_and_queries):
    tree, qs = tree_and_queries
    benchmark(_queries_brute, tree.nodes, N, qs)
    benchmark.extra_info["per_query_us"] = benchmark.stats.stats.median / N * 1e6
