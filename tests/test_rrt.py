"""The RRT baseline finds valid paths, is deterministic, and its parts are exact."""

from __future__ import annotations

import json

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import FIXTURES, shared_scenarios
from exact_geometry import Oracle
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.result import path_cost_deg
from xfuzzy_rrt.planners.rng import new_state, reference_stream, uniform
from xfuzzy_rrt.planners.rrt import plan_rrt
from xfuzzy_rrt.planners.tree import make_tree, add_node, nearest, nearest_brute

SCENARIOS = sorted((FIXTURES / "scenarios").glob("*.toml")) + shared_scenarios()


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_rrt_paths_for_50_seeds_pass_the_exact_geometry_check(path):
    scenario = load_scenario(path)
    oracle = Oracle(path)
    for seed in range(50):
        result = plan_rrt(scenario, seed=seed)
        assert result.success, f"seed {seed} failed"
        assert result.iterations <= 10_000
        assert oracle.path_problems(result.path_deg) == [], f"seed {seed}"
        assert result.cost_deg == pytest.approx(path_cost_deg(result.path_deg))
        assert result.nodes == len(result.tree_nodes_deg) >= len(result.path_deg)


def test_same_seed_gives_the_same_json_except_wall_time(run_cli):
    scenario = FIXTURES / "scenarios" / "two-circles.toml"
    runs = []
    for _ in range(2):
        proc = run_cli("plan", scenario, "--planner", "rrt", "--seed", "11")
        assert proc.returncode == 0, proc.stderr
        data = json.loads(proc.stdout)
        data.pop("wall_s")
        runs.append(data)
    assert runs[0] == runs[1]
    assert runs[0]["path_deg"][0] == [-120.0, 30.0] and runs[0]["path_deg"][-1] == [150.0, -60.0]


def test_different_seeds_explore_differently():
    s = load_scenario(FIXTURES / "scenarios" / "two-circles.toml")
    assert len({plan_rrt(s, seed=k).iterations for k in range(8)}) > 1


def test_failure_within_budget_exits_1_with_a_json_result(run_cli):
    proc = run_cli("plan", FIXTURES / "scenarios" / "two-circles.toml", "--planner", "rrt",
                   "--max-iter", "3")
    assert proc.returncode == 1
    data = json.loads(proc.stdout)
    assert data["success"] is False and data["iterations"] == 3 and data["path_deg"] == []


def test_open_space_with_goal_near_the_start_connects_within_a_few_iterations():
    from xfuzzy_rrt.geometry.scenario import scenario_from_dict

    s = scenario_from_dict({"name": "near", "arm": {"links": [0.2, 0.1]},
                            "start": {"q_deg": [0.0, 0.0]}, "goal": {"q_deg": [3.0, 4.0]}})
    r = plan_rrt(s, seed=0)
    assert r.success and r.iterations <= 5
    assert r.path_deg.tolist()[0] == [0.0, 0.0] and r.path_deg.tolist()[-1] == [3.0, 4.0]


def test_rng_matches_its_pure_python_replay():
    state = new_state(2024)
    assert [uniform(state) for _ in range(1000)] == reference_stream(2024, 1000)


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32), n=st.integers(1, 3000), clustered=st.booleans(),
       dof=st.sampled_from([2, 3, 5, 7]))
def test_nearest_neighbour_equals_brute_force_in_any_dimension(seed, n, clustered, dof):
    """The 2-joint grid and the k-d tree (3+ joints) give the brute-force answer, ties to the
    lowest index included (rounded clustered points make many exact ties)."""
    rng = np.random.default_rng(seed)
    limits = np.tile([-180.0, 180.0], (dof, 1))
    tree = make_tree(n, limits)
    if clustered:
        pts = rng.normal(rng.uniform(-150, 150, dof), 8.0, size=(n, dof)).clip(-180, 180)
        pts = np.round(pts)  # many exact ties
    else:
        pts = rng.uniform(-180, 180, size=(n, dof))
    for p in pts:
        add_node(tree, p, -1)
    for q in np.vstack([rng.uniform(-180, 180, size=(50, dof)), pts[:5],
                        np.full((1, dof), 180.0)]):
        got = nearest(tree, q)
        want = nearest_brute(tree.nodes, n, q)
        assert got == want
