"""An untraced goal-frame iteration infers only the outputs its draws read (goal bias and step
first; the uniform share unless the goal was drawn; the box only for a box sample:
planners/goal_frame.py, ``infer_first`` and ``sample_goal_frame``), yet it plans exactly what
a traced run (which infers all six) plans: same path, tree, iterations and work, for
goal-frame Fuzzy-RRT at 2 joints and Fuzzy-RRT-Connect with the DOF-free rulebook, whose box
outputs are scaled."""

from __future__ import annotations

import numpy as np
import pytest

from conftest import FIXTURES
from test_ndof_paths_oracle import dual_arm, single_arm
from xfuzzy_rrt.fuzzy.engine import infer, infer_output
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebooks_dir
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.api import plan_scenario

CASES = [
    (lambda: load_scenario(FIXTURES / "scenarios" / "two-circles.toml"), "fuzzy-rrt:goal-frame"),
    (lambda: load_scenario(FIXTURES / "scenarios" / "boxes-and-circle.toml"),
     "fuzzy-rrt-connect:goal-frame"),
    (lambda: single_arm(3, 0), "fuzzy-rrt"),
    (lambda: single_arm(5, 1), "fuzzy-rrt"),
    (lambda: dual_arm(3, 0), "fuzzy-rrt"),
]


@pytest.mark.parametrize("make, label", CASES, ids=["gf-2", "connect-2", "any-3", "any-5",
                                                     "any-dual"])
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


@pytest.mark.parametrize("name", ["goal-frame", "goal-frame-any"])
def test_one_output_inferred_alone_is_bit_for_bit_the_full_inference(name):
    knots, consts = load_rulebook(rulebooks_dir() / name).compiled
    rng = np.random.default_rng(7)
    lo, hi = knots[:, :, 0].min(axis=0), knots[:, :, 4].max(axis=0)
    out = np.empty(knots.shape[0])
    rule = np.empty((knots.shape[0], 16), dtype=np.int32)
    w = np.empty((knots.shape[0], 16))
    for x in rng.uniform(lo - 1.0, hi + 1.0, size=(200, 4)):
        infer(knots, consts, x, out, rule, w, False)
        alone = [infer_output(knots, consts, f, x) for f in range(knots.shape[0])]
        assert np.array_equal(np.array(alone), out)
