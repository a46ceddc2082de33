"""Recording a trace never changes what a planner does: a traced run (which records every
output, the fired rules and the box) plans exactly what the untraced run plans -- same path,
tree, iterations and work -- for goal-frame Fuzzy-RRT at 2 joints and Fuzzy-RRT-Connect, with
the DOF-free rulebook whose lengths are scaled at 3 and 5 joints and with two arms, and the
paper's semantics (one fuzzy evaluation per arm). An untraced run passes no trace arrays
(``None``) and runs a kernel specialisation compiled without trace code (the one the trainer
runs: its runs equal the planner's, tests/test_work_fitness.py and
test_goal_frame_any_training.py); it must decide exactly as the traced one."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import FIXTURES
from test_ndof_paths_oracle import dual_arm, single_arm
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.api import plan_scenario

CASES = [
    (lambda: load_scenario(FIXTURES / "scenarios" / "two-circles.toml"), "fuzzy-rrt:goal-frame"),
    (lambda: load_scenario(FIXTURES / "scenarios" / "boxes-and-circle.toml"),
     "fuzzy-rrt-connect:goal-frame"),
    (lambda: single_arm(3, 0), "fuzzy-rrt"),
    (lambda: single_arm(5, 1), "fuzzy-rrt"),
    (lambda: dual_arm(3, 0), "fuzzy-rrt"),
    (lambda: load_scenario(FIXTURES / "scenarios" / "boxes-and-circle.toml"), "fuzzy-rrt:expert"),
]


@pytest.mark.parametrize("make, label", CASES, ids=["gf-2", "connect-2", "any-3", "any-5",
                                                     "any-dual", "paper-2"])
def test_an_untraced_run_plans_exactly_what_a_traced_run_plans(make, label):
    scenario = make()
    for seed in range(4):
        plain = plan_scenario(scenario, label, seed=seed, max_iter=3000)
        traced = plan_scenario(scenario, label, seed=seed, max_iter=3000, trace=True)
        assert plain.success == traced.success
        assert (plain.iterations, plain.nodes, plain.work) == \
            (traced.iterations, traced.nodes, traced.work)
        assert np.array_equal(plain.path_deg, traced.path_deg)
        assert np.array_equal(plain.tree_nodes_deg, traced.tree_nodes_deg)
        assert np.array_equal(plain.tree_parent, traced.tree_parent)
