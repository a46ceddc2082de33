"""The rule-analysis tools plan a DOF-free rulebook with the planner that reads it: ``rules
coverage``, ``rules diff --replay`` and ``rules simplify --budget`` named plain ``fuzzy-rrt``
whatever the rulebook, so ``goal-frame-any`` -- the default's rulebook on every problem but one
2-joint arm -- could not be covered, replayed or budget-checked (one error line: "plans with
--planner fuzzy-rrt-connect"). Issue 25 asks for Connect's coverage and diff like Fuzzy-RRT's."""

from __future__ import annotations

import shutil

from conftest import run_main
from xfuzzy_rrt.analysis.coverage import collect_counts
from xfuzzy_rrt.analysis.simplify import measure_runs
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebooks_dir
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.api import plan_scenario

THREE_JOINTS = """name = "three-joints"
[arm]
links = [0.12, 0.1, 0.08]
link_radius = 0.005
[start]
q_deg = [-60.0, 30.0, 20.0]
[goal]
q_deg = [80.0, -40.0, 10.0]
[[obstacles]]
type = "circle"
center = [0.2, 0.1]
radius = 0.04
"""


def _scenario(tmp_path):
    path = tmp_path / "three.toml"
    path.write_text(THREE_JOINTS, encoding="utf-8")
    return path


def test_each_rulebook_is_planned_with_the_planner_that_reads_it():
    assert load_rulebook(rulebooks_dir() / "goal-frame-any").semantics.planner == \
        "fuzzy-rrt-connect"
    for name in ("goal-frame", "paper", "expert"):
        assert load_rulebook(rulebooks_dir() / name).semantics.planner == "fuzzy-rrt"


def test_coverage_of_the_any_arm_rulebook_counts_connect_runs(tmp_path):
    path = _scenario(tmp_path)
    rb = load_rulebook(rulebooks_dir() / "goal-frame-any")
    counts = collect_counts(rb, [load_scenario(path)], runs=3)
    runs = [plan_scenario(load_scenario(path), "fuzzy-rrt-connect", rulebook=rb, seed=k)
            for k in range(3)]
    assert counts.runs == 3
    assert counts.iterations == sum(r.iterations for r in runs)
    assert counts.successes == sum(r.success for r in runs)
    proc = run_main("rules", "coverage", "goal-frame-any", path, "--runs", "2")
    assert proc.returncode == 0, proc.stderr


def test_replay_diff_and_budget_check_plan_the_any_arm_rulebook(tmp_path):
    path = _scenario(tmp_path)
    shutil.copytree(rulebooks_dir() / "goal-frame-any", tmp_path / "copy")
    proc = run_main("rules", "diff", "goal-frame-any", tmp_path / "copy", "--replay", path)
    assert proc.returncode == 0, proc.stderr
    assert "no divergence" in proc.stdout
    rb = load_rulebook(rulebooks_dir() / "goal-frame-any")
    runs = measure_runs(rb, [load_scenario(path)], seeds=2)
    expected = [plan_scenario(load_scenario(path), "fuzzy-rrt-connect", rulebook=rb, seed=k)
                for k in range(2)]
    assert list(runs["iterations"]) == [r.iterations for r in expected]


def test_evaluate_runs_the_any_arm_rulebook_with_connect(tmp_path):
    """``evaluate --rulebook goal-frame-any`` was refused the same way; it now ranks
    ``fuzzy-rrt-connect:goal-frame-any``."""
    import pandas as pd

    path = _scenario(tmp_path)
    proc = run_main("evaluate", path, "--rulebook", "goal-frame-any", "--runs", "2",
                    "--caches", "warm", "--out", tmp_path / "ev")
    assert proc.returncode == 0, proc.stderr
    runs = pd.read_csv(tmp_path / "ev" / "runs.csv")
    mine = runs[runs["planner"] == "fuzzy-rrt-connect:goal-frame-any"]
    assert len(mine) == 2 and set(mine["planner_used"]) == {"fuzzy-rrt-connect"}
