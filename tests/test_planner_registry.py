"""The planner registry: one registration adds a planner to plan, bench and evaluate.

A toy planner (the straight joint-space line from start to goal, which succeeds only when that
line is certified free) is registered by a fixture and removed afterwards; nothing else in the
code base learns its name.
"""

from __future__ import annotations

import json
import time

import numpy as np
import pandas as pd
import pytest

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners import registry
from xfuzzy_rrt.planners.api import is_known_planner, parse_planner, plan_scenario
from xfuzzy_rrt.planners.params import Param, describe, resolve_params
from xfuzzy_rrt.planners.registry import Planner

ARM = """
[arm]
links = [0.18, 0.12]
link_radius = 0.005

[start]
q_deg = [-120.0, 45.0]

[goal]
q_deg = [75.0, -60.0]
"""
#: On the workspace point the end effector passes halfway along the straight joint-space line.
BLOCKING = """
[[obstacles]]
type = "circle"
center = [0.270, -0.129]
radius = 0.03
"""


def plan_line(scenario, spec, rulebook, *, seed, max_iter, step_deg, goal_bias, trace,
              clearance_m, max_time_s):
    """The straight line from start to goal, when every bit of it is certified free."""
    from xfuzzy_rrt.geometry.clearance import planning_margin
    from xfuzzy_rrt.geometry.path_check import segments_certified
    from xfuzzy_rrt.planners.result import certified_result, path_cost_deg

    margin = planning_margin(scenario, clearance_m)
    arrays = scenario.arrays()
    t0 = time.perf_counter()
    line = np.array([scenario.start_deg, scenario.goal_deg], dtype=np.float64)
    free = segments_certified(arrays, line, margin) is not None
    wall = time.perf_counter() - t0
    path = line if free else np.zeros((0, line.shape[1]))
    return certified_result(
        arrays, margin, free, scenario=scenario.name, planner=spec.label,
        planner_used=spec.kind, seed=int(seed), iterations=1, nodes=2 if free else 1,
        cost_deg=path_cost_deg(line) if free else None, wall_s=wall, path_deg=path,
        tree_nodes_deg=line[: 2 if free else 1].copy(),
        tree_parent=np.array([-1, 0][: 2 if free else 1]), params={"max_iter": int(max_iter)})


LINE_PARAMS = (Param("max_iter", 1, 1, 1, "iterations", "one look at the line", integer=True),)


@pytest.fixture
def line_planner():
    form = registry.register(Planner("line", "line", plan_line, params=LINE_PARAMS))
    try:
        yield form
    finally:
        registry.unregister("line")
    assert not is_known_planner("line")


@pytest.fixture
def problems(tmp_path):
    folder = tmp_path / "problems"
    folder.mkdir()
    (folder / "free.toml").write_text('name = "free"\n' + ARM)
    (folder / "blocked.toml").write_text('name = "blocked"\n' + ARM + BLOCKING)
    return folder


def test_a_registered_planner_plans_through_plan_scenario(line_planner, problems):
    free = plan_scenario(load_scenario(problems / "free.toml"), "line", seed=3)
    blocked = plan_scenario(load_scenario(problems / "blocked.toml"), "line", seed=3)
    assert (free.planner, free.planner_used, free.success, free.certified) == \
        ("line", "line", True, True)
    np.testing.assert_array_equal(free.path_deg, [[-120.0, 45.0], [75.0, -60.0]])
    assert (blocked.found, blocked.success) == (False, False)
    assert parse_planner("line").kind == "line"
    assert [p.name for p in describe("line")] == ["max_iter"]
    assert resolve_params("line") == {"max_iter": 1}


def test_a_registered_planner_is_named_in_the_unknown_planner_line(line_planner):
    with pytest.raises(InputError, match=r"fuzzy-rrt-connect:RULEBOOK, ompl:NAME or line\)$"):
        parse_planner("lines")


def test_a_planner_that_does_not_trace_refuses_a_trace(line_planner, problems):
    with pytest.raises(InputError) as err:
        plan_scenario(load_scenario(problems / "free.toml"), "line", trace=True)
    assert str(err.value) == ("--trace: traces record fuzzy decisions; use --planner fuzzy-rrt "
                              "or fuzzy-rrt-connect")


def test_a_registered_planner_runs_in_plan(line_planner, problems, capsys):
    from xfuzzy_rrt.cli.main import main

    assert main(["plan", str(problems / "free.toml"), "--planner", "line"]) == 0
    out = json.loads(capsys.readouterr().out)
    assert (out["planner"], out["success"], out["rulebook"]) == ("line", True, None)
    assert main(["plan", str(problems / "blocked.toml"), "--planner", "line"]) == 1
    assert main(["plan", str(problems / "free.toml"), "--planner", "line",
                 "--rulebook", "rulebooks/paper"]) == 2
    assert "only fuzzy-rrt and fuzzy-rrt-connect plan with a rulebook; --planner line would " \
           "ignore it" in capsys.readouterr().err


def test_a_registered_planner_runs_in_bench(line_planner, problems):
    from xfuzzy_rrt.bench.runner import run_benchmark

    scenarios = [load_scenario(problems / f) for f in ("free.toml", "blocked.toml")]
    result = run_benchmark(scenarios, ["rrt", "line"], runs=2, max_iter=2000)
    line = result.runs[result.runs["planner"] == "line"].set_index(["scenario", "seed"])
    assert line["success"].to_dict() == {("free", 0): True, ("free", 1): True,
                                          ("blocked", 0): False, ("blocked", 1): False}
    ok = line.loc["free"]
    assert (ok["time_first_s"] == ok["wall_s"]).all()  # first_solution: the run's own time
    assert set(result.summary["planner"]) == {"rrt", "line"}


def test_a_registered_planner_runs_in_evaluate(line_planner, problems, tmp_path, capsys):
    from xfuzzy_rrt.cli.main import main

    out = tmp_path / "eval"
    assert main(["evaluate", str(problems), "--peer", "line", "--runs", "1", "--max-iter", "2000",
                 "--out", str(out)]) == 0
    runs = pd.read_csv(out / "runs.csv")
    line = runs[runs["planner"] == "line"].set_index("scenario")["success"].to_dict()
    assert line == {"free": True, "blocked": False}
    assert "line" in capsys.readouterr().out


def test_the_builtin_forms_keep_their_help_and_error_text():
    assert registry.expected_text() == (
        "rrt, fuzzy-rrt, fuzzy-rrt-connect, rrt:tuned, fuzzy-rrt:RULEBOOK, "
        "fuzzy-rrt-connect:RULEBOOK or ompl:NAME")
    assert registry.planner_help() == (
        "Planner: rrt, fuzzy-rrt (without --rulebook: goal-frame on one 2-joint arm, else "
        "fuzzy-rrt-connect with goal-frame-any; the JSON's planner_used says which ran), "
        "fuzzy-rrt:NAME (a shipped rulebook) or fuzzy-rrt:DIR, "
        "fuzzy-rrt-connect[:NAME|:DIR] (two goal-frame trees; default rulebook goal-frame-any, "
        "any arm), or ompl:NAME (e.g. ompl:RRTConnect; optional 'ompl' extra).")


def test_a_label_cannot_be_registered_twice():
    with pytest.raises(ValueError, match="already registered"):
        registry.register(Planner("fuzzy-rrt:", "x", plan_line, arg="RULEBOOK"))


@pytest.mark.parametrize("label,cli", [("fuzzy-rrt:paper", "fuzzy-rrt"),
                                       ("fuzzy-rrt-connect:./mine", "fuzzy-rrt-connect"),
                                       ("fuzzy-rrt", "fuzzy-rrt"), ("rrt:tuned", "rrt:tuned"),
                                       ("ompl:RRTConnect", "ompl:RRTConnect"),
                                       ("fuzzy-rrt (any arm)", "fuzzy-rrt (any arm)")])
def test_reproduce_commands_name_a_rulebook_label_by_its_kind(label, cli):
    from xfuzzy_rrt.report.evidence import cli_planner

    assert cli_planner(label) == cli


def test_plain_fuzzy_rrt_runs_the_any_arm_core_registered_now(problems, tmp_path):
    # plain fuzzy-rrt on a problem that is not one 2-joint arm runs the core registered as
    # fuzzy-rrt-connect now: nothing may remember a replaced planner's core
    from xfuzzy_rrt.planners.api import plan_scenario as plan

    three = tmp_path / "three.toml"
    three.write_text('name = "three"\n[arm]\nlinks = [0.1, 0.1, 0.1]\nlink_radius = 0.005\n'
                     '[start]\nq_deg = [0.0, 10.0, 0.0]\n[goal]\nq_deg = [60.0, -20.0, 5.0]\n')
    scenario = load_scenario(three)
    assert plan(scenario, "fuzzy-rrt", seed=0).planner_used == "fuzzy-rrt-connect"
    original = registry.lookup("fuzzy-rrt-connect")
    order = registry.planners()  # help and error text list the forms in this order
    calls = []

    def core(scenario, **kw):
        calls.append(kw["label"])
        return original.core_fn(scenario, **kw)

    registry.unregister("fuzzy-rrt-connect")
    try:
        registry.register(Planner("fuzzy-rrt-connect", original.kind, original.plan,
                                  parse=original.parse, takes_rulebook=True, traces=True,
                                  params=original.params, core=core, fits=original.fits))
        plan(scenario, "fuzzy-rrt", seed=0)
        assert calls == ["fuzzy-rrt"]
    finally:
        registry.unregister("fuzzy-rrt-connect")
        registry.register(original)
        registry._ORDER[:] = order
    assert registry.planners() == order
    calls.clear()
    plan(scenario, "fuzzy-rrt", seed=0)
    assert calls == []
