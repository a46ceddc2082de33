"""A plan's result keeps its own arrays: the compiled entries see the pooled trees and the
problem through borrowed views (planners/tree_arena.py, "Borrowed views"), so nothing a result
holds may point into those blocks, and the next plan, which reuses and empties the same pooled
trees, must leave an earlier result untouched."""

from __future__ import annotations

import numpy as np
import pytest

from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners import prepared
from xfuzzy_rrt.planners.api import plan_scenario

from conftest import FIXTURES

CASES = [
    ("scenarios/boxes-and-circle.toml", "rrt"),
    ("scenarios/boxes-and-circle.toml", "rrt:tuned"),
    ("scenarios/boxes-and-circle.toml", "fuzzy-rrt"),  # goal-frame
    ("scenarios/two-circles.toml", "fuzzy-rrt:paper"),  # the paper's rulebook fails boxes-and-circle
    ("scenarios/boxes-and-circle.toml", "fuzzy-rrt-connect"),
    ("arms/five-dof.toml", "fuzzy-rrt"),  # Fuzzy-RRT-Connect, goal-frame-any
    ("arms/dual-3dof.toml", "fuzzy-rrt"),
]

_ARRAYS = ("path_deg", "tree_nodes_deg", "tree_parent")


def _pool_blocks() -> list[np.ndarray]:
    """Every block of this thread's pooled trees (what the entries borrowed)."""
    blocks = []
    for arenas in getattr(prepared._local, "trees", {}).values():
        blocks.extend(arena.block for arena in arenas)
    return blocks


@pytest.mark.parametrize("relative, planner", CASES)
def test_a_result_shares_no_memory_with_the_pooled_trees_and_survives_the_next_plan(
        relative, planner):
    scenario = load_scenario(FIXTURES / relative)
    first = plan_scenario(scenario, planner, seed=3)
    assert first.success
    kept = {name: getattr(first, name).copy() for name in _ARRAYS}
    blocks = _pool_blocks()
    assert blocks, "the plan used no pooled tree: the test no longer sees what it guards"
    for name in _ARRAYS:
        arr = getattr(first, name)
        for block in blocks:
            assert not np.shares_memory(arr, block), f"{name} points into a pooled tree"
    for seed in (4, 5, 6):  # the same pooled trees, emptied and refilled
        assert plan_scenario(scenario, planner, seed=seed).success
    for name in _ARRAYS:
        np.testing.assert_array_equal(getattr(first, name), kept[name], err_msg=name)
