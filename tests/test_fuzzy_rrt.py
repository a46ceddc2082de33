"""Fuzzy-RRT follows Algorithm 1, returns only valid paths, and its traces are exact."""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from conftest import FIXTURES, shared_scenarios
from exact_geometry import Oracle
from xfuzzy_rrt.analysis.explain import explain_row, trace_row
from xfuzzy_rrt.fuzzy.rulebook import Rulebook, default_rulebook_path, load_rulebook
from xfuzzy_rrt.fuzzy.variables import INPUTS, MAX_FIRED, OUTPUTS, default_knots
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.fuzzy_rrt import MIN_STEP_DEG, plan_fuzzy_rrt
from xfuzzy_rrt.planners.result import path_cost_deg
from xfuzzy_rrt.planners.rrt import plan_rrt

SCENARIOS = sorted((FIXTURES / "scenarios").glob("*.toml")) + shared_scenarios()
TWO_CIRCLES = FIXTURES / "scenarios" / "two-circles.toml"
KNOTS = np.array([[default_knots(n) for n in INPUTS]] * len(OUTPUTS))


def constant_rulebook(bias, b1, b2, b3, b4, step, mode):
    consts = np.empty((len(OUTPUTS), 625))
    for f, v in enumerate((bias, b1, b2, b3, b4, step)):
        consts[f] = v
    return Rulebook.from_arrays(KNOTS, consts, name=f"constant-{mode}", bounds_mode=mode,
                                provenance={"kind": "test"})


@pytest.fixture(scope="module")
def expert():
    """The default rulebook (whatever its semantics: the tests read names from it)."""
    return load_rulebook(default_rulebook_path())


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_fuzzy_rrt_paths_for_50_seeds_pass_the_exact_geometry_check(path, expert):
    scenario = load_scenario(path)
    oracle = Oracle(path)
    for seed in range(50):
        result = plan_fuzzy_rrt(scenario, expert, seed=seed)
        assert result.success, f"seed {seed} failed"
        assert oracle.path_problems(result.path_deg) == [], f"seed {seed}"
        assert result.cost_deg == pytest.approx(path_cost_deg(result.path_deg))


def test_constant_full_box_rulebook_reproduces_the_rrt_baseline_exactly():
    """With bias 0.05, the full joint box and a 10° step, Algorithm 1 *is* RRT.

    (Up to rounding: the weighted average of 16 equal constants may differ in the last bit.)
    """
    rb = constant_rulebook(0.05, -180, 180, -180, 180, 10.0, "absolute")
    s = load_scenario(TWO_CIRCLES)
    for seed in range(10):
        a, b = plan_fuzzy_rrt(s, rb, seed=seed), plan_rrt(s, seed=seed)
        assert a.iterations == b.iterations and a.nodes == b.nodes
        np.testing.assert_allclose(a.path_deg, b.path_deg, rtol=0, atol=1e-9)


def test_absolute_bounds_are_ordered_and_clipped_to_the_joint_limits():
    # Reversed joint-1 bounds (170 > -30); joint-2 upper bound 180 beyond the 160° limit.
    # (FIS outputs are weighted averages of equal constants: equal up to the last bit.)
    rb = constant_rulebook(0.0, 170.0, -30.0, -20.0, 180.0, 10.0, "absolute")
    s = load_scenario(FIXTURES / "scenarios" / "boxes-and-circle.toml")  # limits ±175/±160
    t = plan_fuzzy_rrt(s, rb, seed=3, max_iter=300, trace=True).trace
    np.testing.assert_allclose(t["box_q1_lo"], -30.0, atol=1e-9)
    np.testing.assert_allclose(t["box_q1_hi"], 170.0, atol=1e-9)
    np.testing.assert_allclose(t["box_q2_lo"], -20.0, atol=1e-9)
    assert (t["box_q2_hi"] == 160.0).all()
    inside = t[~t["goal_sampled"]]
    assert inside["sample_q1_deg"].between(-30 - 1e-9, 170 + 1e-9).all()
    assert inside["sample_q2_deg"].between(-20 - 1e-9, 160).all()


def test_relative_bounds_are_offsets_from_the_current_node():
    from xfuzzy_rrt.fuzzy.rulebook import rulebooks_dir

    relative = load_rulebook(rulebooks_dir() / "general")
    s = load_scenario(TWO_CIRCLES)
    t = plan_fuzzy_rrt(s, relative, seed=5, trace=True).trace
    assert relative.bounds_mode == "relative"
    lo1 = np.clip(t["from_q1_deg"] + np.minimum(t["bound_1"], t["bound_2"]), -180, 180)
    hi1 = np.clip(t["from_q1_deg"] + np.maximum(t["bound_1"], t["bound_2"]), -180, 180)
    np.testing.assert_array_equal(t["box_q1_lo"], lo1)
    np.testing.assert_array_equal(t["box_q1_hi"], hi1)
    inside = t[~t["goal_sampled"]]
    assert (inside["sample_q1_deg"] >= inside["box_q1_lo"]).all()
    assert (inside["sample_q1_deg"] <= inside["box_q1_hi"]).all()
    assert (inside["sample_q2_deg"] >= inside["box_q2_lo"]).all()
    assert (inside["sample_q2_deg"] <= inside["box_q2_hi"]).all()


def test_nearest_node_is_carried_to_the_next_iteration_as_in_the_paper(expert):
    t = plan_fuzzy_rrt(load_scenario(TWO_CIRCLES), expert, seed=1, trace=True).trace
    assert t["from_node"].iloc[0] == 0
    np.testing.assert_array_equal(t["from_node"].to_numpy()[1:], t["nearest_node"].to_numpy()[:-1])


def test_zero_step_rulebook_still_makes_progress_with_the_minimum_step():
    rb = constant_rulebook(0.3, -20, 20, -20, 20, 0.0, "relative")
    s = load_scenario(TWO_CIRCLES)
    r = plan_fuzzy_rrt(s, rb, seed=0, max_iter=400, trace=True)
    t = r.trace
    acc = t[t["outcome"] == "accepted"]
    assert len(acc) > 50 and r.nodes > 50
    assert (t["step_used_deg"] == MIN_STEP_DEG).all()
    nodes = r.tree_nodes_deg
    steps = np.hypot(*(nodes[1:] - nodes[r.tree_parent[1:]]).T)
    assert steps.max() <= MIN_STEP_DEG + 1e-9


def test_trace_has_one_row_per_iteration_and_fired_strengths_sum_to_one(expert):
    r = plan_fuzzy_rrt(load_scenario(TWO_CIRCLES), expert, seed=7, trace=True)
    t = r.trace
    assert len(t) == r.iterations
    assert t["iteration"].tolist() == list(range(1, r.iterations + 1))
    assert t["outcome"].iloc[-1] == "goal_reached"
    assert set(t["outcome"]) <= {"accepted", "node_in_collision", "edge_blocked",
                                 "goal_reached", "no_progress"}
    assert (t["tree_size"].diff().fillna(1) >= 0).all()
    for out in expert.outputs:
        w = t[[f"{out}_strength_{k}" for k in range(MAX_FIRED)]].to_numpy()
        np.testing.assert_allclose(w.sum(axis=1), 1.0, atol=1e-12)
        rules = t[[f"{out}_rule_{k}" for k in range(MAX_FIRED)]].to_numpy()
        assert ((rules >= 0) == (w > 0)).all()
    # The nodes flagged on_path are exactly the path's nodes that were added by an iteration.
    on_path = t.loc[t["on_path"], "new_node"].tolist()
    assert len(on_path) >= 1 and all(n >= 0 for n in on_path)


def test_traced_outputs_equal_the_weighted_average_of_rule_constants_read_from_the_text(tmp_path):
    # Re-read the shipped rulebook from its text files, independently of the planner's copy.
    rb_text = load_rulebook(default_rulebook_path())
    r = plan_fuzzy_rrt(load_scenario(TWO_CIRCLES), default_rulebook_path(), seed=4, trace=True)
    t = r.trace
    for f, out in enumerate(rb_text.outputs):
        consts = np.array(rb_text.systems[f].consts)
        rules = t[[f"{out}_rule_{k}" for k in range(MAX_FIRED)]].to_numpy()
        w = t[[f"{out}_strength_{k}" for k in range(MAX_FIRED)]].to_numpy()
        recomputed = (w * np.where(rules >= 0, consts[np.maximum(rules, 0)], 0.0)).sum(axis=1)
        np.testing.assert_allclose(recomputed, t[out].to_numpy(), rtol=0, atol=1e-12)


def test_same_seed_gives_an_identical_trace(expert):
    s = load_scenario(TWO_CIRCLES)
    a = plan_fuzzy_rrt(s, expert, seed=9, trace=True)
    b = plan_fuzzy_rrt(s, expert, seed=9, trace=True)
    pd.testing.assert_frame_equal(a.trace, b.trace, check_exact=True)
    c = plan_fuzzy_rrt(s, expert, seed=9, trace=False)
    assert (c.iterations, c.nodes) == (a.iterations, a.nodes)
    assert np.array_equal(c.path_deg, a.path_deg)


def test_explain_recomputes_every_traced_number(expert):
    t = plan_fuzzy_rrt(load_scenario(TWO_CIRCLES), expert, seed=2, trace=True).trace
    for it in (1, len(t) // 2, len(t)):
        e = explain_row(trace_row(t, it), expert)
        assert e.max_discrepancy <= 1e-12
        for s in e.systems:
            assert len(s.rules) <= MAX_FIRED
            assert sum(r.strength for r in s.rules) == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("suffix", [".parquet", ".csv"])
def test_cli_trace_and_explain_agree_with_each_other(run_cli, tmp_path, suffix):
    trace_file = tmp_path / f"trace{suffix}"
    result_file = tmp_path / "result.json"
    proc = run_cli("plan", TWO_CIRCLES, "--seed", "3", "--trace", trace_file, "--out", result_file)
    assert proc.returncode == 0, proc.stderr
    result = json.loads(result_file.read_text())
    t = pd.read_parquet(trace_file) if suffix == ".parquet" else pd.read_csv(trace_file)
    assert len(t) == result["iterations"]
    it = max(1, result["iterations"] // 3)
    row = t[t["iteration"] == it].iloc[0]
    for source in (trace_file, result_file):
        proc = run_cli("explain", source, "--iteration", str(it))
        assert proc.returncode == 0, proc.stderr
        for out in load_rulebook(default_rulebook_path()).outputs:
            line = next(l for l in proc.stdout.splitlines() if l.startswith(f"  {out} = "))
            shown = float(line.split("planner recorded ")[1].rstrip(")"))
            assert shown == pytest.approx(row[out], abs=1e-12)
        assert f"Iteration {it}" in proc.stdout


def test_explain_rejects_a_missing_iteration_with_one_line(run_cli, tmp_path):
    trace_file = tmp_path / "trace.csv"
    assert run_cli("plan", TWO_CIRCLES, "--trace", trace_file).returncode == 0
    proc = run_cli("explain", trace_file, "--iteration", "999999")
    assert proc.returncode == 2
    assert proc.stderr.startswith("error: --iteration: iteration 999999 is not in the trace")
    assert len(proc.stderr.strip().splitlines()) == 1


def test_trace_requested_for_plain_rrt_is_a_usage_error(run_cli, tmp_path):
    proc = run_cli("plan", TWO_CIRCLES, "--planner", "rrt", "--trace", tmp_path / "t.csv")
    assert proc.returncode == 2 and "fuzzy-rrt" in proc.stderr
    assert not (tmp_path / "t.csv").exists()
