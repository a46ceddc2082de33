"""The planner core: N-DOF and multi-arm planning on the one compiled problem bundle, named
parameters with ranges, termination by iterations or wall clock, rulebooks of the wrong DOF.

Paths of every planner on generated N-DOF and dual-arm problems are re-checked by the exact
oracle in tests/test_ndof_paths_oracle.py; here: behaviour of the core itself.
"""

from __future__ import annotations

import functools
import json

import numpy as np
import pytest

from conftest import FIXTURES
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.path_check import certify_path
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.api import plan_scenario
from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt
from xfuzzy_rrt.planners.params import describe, resolve_params
from xfuzzy_rrt.planners.rrt import plan_rrt
from xfuzzy_rrt.scenarios.generate import generate_nd

ARMS = FIXTURES / "arms"
TWO = FIXTURES / "scenarios" / "two-circles.toml"


@functools.lru_cache(maxsize=None)
def generated_with_proof(dof: int, arms: int = 1, k: int = 0):
    """A generated problem of the N-DOF / multi-arm family and the RRT seed that solved it."""
    g = generate_nd(4242, k, dof=dof, arms=arms)
    return g.scenario, g.solved_seed


def generated(dof: int, arms: int = 1, k: int = 0):
    return generated_with_proof(dof, arms, k)[0]


@pytest.mark.parametrize("dof,arms", [(3, 1), (5, 1), (7, 1), (2, 2), (3, 2)])
def test_rrt_plans_certified_paths_in_n_dimensional_joint_space(dof, arms):
    s, seed = generated_with_proof(dof, arms)
    r = plan_rrt(s, seed=seed, max_iter=30_000)  # the generator's proof, re-run
    assert r.success, (s.name, r.iterations)
    assert r.path_deg.shape[1] == s.dof == dof * arms
    np.testing.assert_array_equal(r.path_deg[0], s.start_deg)
    np.testing.assert_array_equal(r.path_deg[-1], s.goal_deg)
    assert certify_path(s.arrays(), r.path_deg, r.params["margin_m"]).certified


def test_the_same_seed_gives_the_same_n_dof_plan_byte_for_byte():
    s = generated(5)
    a = plan_rrt(s, seed=11, max_iter=20_000)
    b = plan_rrt(s, seed=11, max_iter=20_000)
    assert a.iterations == b.iterations and a.path_deg.tobytes() == b.path_deg.tobytes()
    assert a.tree_nodes_deg.tobytes() == b.tree_nodes_deg.tobytes()


def test_paper_semantics_reads_each_arm_with_one_rulebook_of_that_arm_dof():
    """Two 2-DOF arms, the 2-DOF expert rulebook: one fuzzy evaluation per arm per iteration,
    traced with arm-prefixed columns; the plan is certified including arm-arm contact."""
    s = load_scenario(ARMS / "dual-2dof.toml")
    r = plan_fuzzy_rrt(s, rulebook=_shipped("expert"), seed=0, max_iter=20_000, trace=True)
    assert r.success
    cols = set(r.trace.columns)
    assert {"arm1_dist_to_obstacle", "arm2_dist_to_obstacle", "arm1_bound_4", "arm2_step_size",
            "box_q4_hi", "sample_q4_deg", "arm2_goal_bias_rule_0"} <= cols
    assert len(r.trace) == r.iterations
    # each arm's nearest obstacle includes the other arm: it is never farther than the
    # distance to the real obstacles alone, and somewhere strictly nearer
    assert (r.trace["arm1_dist_to_obstacle"] >= 0).all()


def test_a_goal_frame_rulebook_of_the_wrong_dof_is_refused_with_one_line():
    s = generated(5)
    with pytest.raises(InputError) as exc:
        plan_fuzzy_rrt(s, rulebook=_shipped("goal-frame"), max_iter=100)
    assert "2-DOF goal-frame rulebook" in str(exc.value) and "5 joints" in str(exc.value)
    assert "\n" not in str(exc.value)


def test_a_paper_rulebook_of_another_arm_dof_is_refused_with_one_line():
    with pytest.raises(InputError, match="5-DOF rulebook; the arm has 2 joints"):
        plan_fuzzy_rrt(load_scenario(TWO), rulebook=_shipped("expert-5dof"), max_iter=100)


def test_the_cli_names_the_dof_mismatch_in_one_error_line(run_cli, tmp_path):
    out = tmp_path / "p.json"
    proc = run_cli("plan", str(TWO), "--planner", "fuzzy-rrt:expert-5dof", "--out", str(out))
    assert proc.returncode == 2
    lines = [ln for ln in proc.stderr.splitlines() if not ln.startswith("compiling")]
    assert len(lines) == 1 and lines[0].startswith("error: ") and "5-DOF" in lines[0]
    assert not out.exists()


def test_five_dof_fuzzy_rrt_with_the_five_dof_expert_finds_certified_paths():
    s = generated(5)
    r = plan_fuzzy_rrt(s, rulebook=_shipped("expert-5dof"), seed=1, max_iter=20_000, trace=True)
    assert r.found == r.success
    assert {"bound_10", "box_q5_lo", "from_q5_deg"} <= set(r.trace.columns)


def test_named_parameters_have_defaults_ranges_and_one_clear_error():
    names = [p.name for p in describe("rrt")]
    assert names == ["max_iter", "max_time_s", "step_deg", "goal_bias"]
    assert resolve_params("rrt")["step_deg"] == 10.0
    with pytest.raises(InputError, match=r"^goal_bias: must lie in \[0, 1\], got 1.5$"):
        resolve_params("rrt", goal_bias=1.5)
    with pytest.raises(InputError, match=r"^step_deg: must lie in \(0, 1440\] deg, got 0$"):
        resolve_params("rrt", step_deg=0)
    with pytest.raises(InputError, match="is not a parameter of fuzzy-rrt"):
        resolve_params("fuzzy-rrt", step_deg=3.0)
    with pytest.raises(InputError, match="max_time_s: must lie in"):
        resolve_params("rrt", max_time_s=-1.0)


def _walled_in():
    """No path exists: link 1 must cross a ring of circles round the base to get from its window
    at 0 deg to its window at 180 deg."""
    from xfuzzy_rrt.geometry.scenario import Arm, Circle, Scenario

    ring = tuple(Circle(center=(0.05 * np.cos(np.radians(t)), 0.05 * np.sin(np.radians(t))),
                        radius=0.01) for t in [*range(20, 161, 5), *range(200, 341, 5)])
    return Scenario(name="walled-in", arm=Arm(links=(0.1, 0.1),
                                              joint_limits_deg=((-180.0, 180.0),) * 2),
                    start_deg=(0.0, 0.0), goal_deg=(180.0, 0.0), obstacles=ring)


@pytest.mark.parametrize("planner", ["rrt", "fuzzy-rrt:expert", "fuzzy-rrt:goal-frame"])
def test_a_wall_clock_budget_stops_every_planner_before_its_iteration_budget(planner):
    r = plan_scenario(_walled_in(), planner, seed=0, max_iter=1_000_000, max_time_s=0.05)
    assert r.params["stopped_by"] == "time" and r.params["max_time_s"] == 0.05
    assert not r.found and 0 < r.iterations < 1_000_000


def test_a_generous_wall_clock_budget_changes_nothing():
    s = generated(3)
    a = plan_rrt(s, seed=5, max_iter=20_000)
    b = plan_rrt(s, seed=5, max_iter=20_000, max_time_s=3600.0)
    assert a.path_deg.tobytes() == b.path_deg.tobytes() and b.params["stopped_by"] == "goal"


def test_bad_n_dof_input_is_one_error_line(run_cli, tmp_path):
    bad = tmp_path / "bad.toml"
    bad.write_text((ARMS / "dual-2dof.toml").read_text().replace(
        "start_deg = [60.0, 0.0]", "start_deg = [60.0, 0.0, 5.0]"))
    proc = run_cli("plan", str(bad), "--planner", "rrt")
    assert proc.returncode == 2
    lines = [ln for ln in proc.stderr.splitlines() if not ln.startswith("compiling")]
    assert len(lines) == 1 and "arms[1].start_deg" in lines[0], proc.stderr


def _shipped(name):
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook_cached, rulebooks_dir

    return load_rulebook_cached(rulebooks_dir() / name)


def test_explain_shows_each_arm_of_a_dual_arm_trace(run_cli, tmp_path):
    trace = tmp_path / "t.csv"
    proc = run_cli("plan", str(ARMS / "dual-2dof.toml"), "--planner", "fuzzy-rrt:expert",
                   "--trace", str(trace), "--out", str(tmp_path / "p.json"))
    assert proc.returncode == 0, proc.stderr
    out = run_cli("explain", str(trace), "--iteration", "2")
    assert out.returncode == 0, out.stderr
    assert out.stdout.count("### arm ") == 2 and "### arm 2 of 2" in out.stdout
    assert out.stdout.count("== bound_4 ==") == 2
