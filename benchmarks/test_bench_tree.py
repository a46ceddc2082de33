"""Nearest-neighbour cost per query in a 10,000-node tree: grid search vs linear scan.

The grid search must keep long runs from becoming quadratic; each round answers 10,000
queries (uniform samples) against a tree of 10,000 nodes grown like an RRT tree (clustered
random walk), inside compiled code.
"""

from __future__ import annotations

import numba as nb
import numpy as np
import pytest

from xfuzzy_rrt.planners.tree import make_tree, add_node, nearest, nearest_brute

N = 10_000


@nb.njit(cache=True)
def _queries_tree(tree, qs):
    acc = 0
    for j in range(qs.shape[0]):
        acc += nearest(tree, qs[j])
    return acc


@nb.njit(cache=True)
def _queries_brute(nodes, n, qs):
    acc = 0
    for j in range(qs.shape[0]):
        acc += nearest_brute(nodes, n, qs[j])
    return acc


@pytest.fixture(scope="module", params=[2, 5, 7], ids=lambda d: f"dof{d}")
def tree_and_queries(request):
    """A 10,000-node random-walk tree (RRT-like spatial order) and 10,000 uniform queries."""
    dof = request.param
    rng = np.random.default_rng(0)
    steps = rng.normal(0, 6.0, size=(N, dof))
    walk = np.clip(np.cumsum(steps, axis=0) % 360.0 - 180.0, -180, 180)
    tree = make_tree(N, np.tile([-180.0, 180.0], (dof, 1)))
    for p in walk:
        add_node(tree, np.ascontiguousarray(p), -1)
    return tree, rng.uniform(-180, 180, size=(N, dof))


def test_nearest_tree_10k(benchmark, tree_and_queries):
    """Grid (2 joints) or k-d tree (5, 7 joints): exact, and far below the brute-force cost."""
    tree, qs = tree_and_queries
    expected = _queries_brute(tree.nodes, N, qs)
    assert benchmark(_queries_tree, tree, qs) == expected
    benchmark.extra_info["per_query_us"] = benchmark.stats.stats.median / N * 1e6


def test_nearest_brute_10k(benchmark, tree_and_queries):
    tree, qs = tree_and_queries
    benchmark(_queries_brute, tree.nodes, N, qs)
    benchmark.extra_info["per_query_us"] = benchmark.stats.stats.median / N * 1e6
