"""A loop of plans that passes the very same objects goes straight to the run bound on its first
call (``api._LANES``), and gets exactly what a fresh call gets; anything that could differ
(another object, a folder or ``None`` as the rulebook, a trace, a time budget) plans as before.
Speed is measured in benchmarks, not here."""

from __future__ import annotations

import dataclasses
import gc
import shutil

import numpy as np
import pytest

from conftest import FIXTURES
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebooks_dir
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners import api, setup_memo
from xfuzzy_rrt.planners.api import (
    load_shipped_default,
    load_tuned_rrt,
    plan_scenario,
    preloaded,
)

TWO_JOINTS = FIXTURES / "scenarios" / "two-circles.toml"
THREE_JOINTS = """
name = "three-joints"
[arm]
links = [0.12, 0.1, 0.08]
link_radius = 0.005
[start]
q_deg = [10.0, 20.0, 30.0]
[goal]
q_deg = [150.0, -60.0, 40.0]
[[obstacles]]
type = "circle"
center = [0.12, 0.12]
radius = 0.03
"""


@pytest.fixture()
def fresh():
    api.clear_lanes()
    setup_memo.clear()
    yield
    api.clear_lanes()
    setup_memo.clear()


@pytest.fixture(scope="module")
def problems(tmp_path_factory):
    path = tmp_path_factory.mktemp("lanes") / "three.toml"
    path.write_text(THREE_JOINTS)
    return load_scenario(TWO_JOINTS), load_scenario(path)


def _same(a, b) -> None:
    """Two results equal in every field that a run decides (``wall_s`` is a clock)."""
    for f in dataclasses.fields(a):
        if f.name in ("wall_s", "trace"):
            continue
        x, y = getattr(a, f.name), getattr(b, f.name)
        if isinstance(x, np.ndarray) or isinstance(y, np.ndarray):
            assert np.array_equal(x, y), f.name
        else:
            assert x == y or (x != x and y != y), f.name


def _fresh_result(scenario, planner, rulebook, seed, **kw):
    """What a call that finds no kept run returns (nothing remembered at all)."""
    api.clear_lanes()
    setup_memo.clear()
    return plan_scenario(scenario, planner, rulebook=rulebook, seed=seed, **kw)


@pytest.mark.parametrize("planner, loader", [
    ("fuzzy-rrt", load_shipped_default),
    ("rrt:tuned", load_tuned_rrt),
    ("rrt", lambda: None),
    ("fuzzy-rrt-connect", lambda: preloaded("fuzzy-rrt-connect", None)),
    ("fuzzy-rrt:goal-frame", lambda: preloaded("fuzzy-rrt:goal-frame", None)),
])
def test_a_loop_of_calls_gets_what_a_fresh_call_gets(problems, fresh, planner, loader):
    rulebook = loader()
    for scenario in problems:
        if planner == "fuzzy-rrt:goal-frame" and not scenario.one_two_joint_arm:
            continue
        kept = [plan_scenario(scenario, planner, rulebook=rulebook, seed=s) for s in range(4)]
        assert (planner, id(scenario)) in api._LANES  # the loop found its run
        for s, r in enumerate(kept):
            _same(r, _fresh_result(scenario, planner, rulebook, s))
        assert kept[0].planner == planner and kept[0].success


def test_an_ompl_peer_in_a_loop_gets_what_a_fresh_call_gets(problems, fresh):
    pytest.importorskip("ompl")
    tuned = preloaded("ompl:RRTConnect", None)
    for scenario in problems:
        kept = [plan_scenario(scenario, "ompl:RRTConnect", rulebook=tuned, seed=s)
                for s in range(3)]
        assert ("ompl:RRTConnect", id(scenario)) in api._LANES
        for s, r in enumerate(kept):
            _same(r, _fresh_result(scenario, "ompl:RRTConnect", tuned, s))
    plan_scenario(problems[0], "ompl:RRTConnect", seed=0)  # the tuned file is read: no run kept
    assert ("ompl:RRTConnect", id(problems[0])) not in api._LANES or \
        api._LANES[("ompl:RRTConnect", id(problems[0]))][1][0] is tuned


def test_the_default_plans_each_arm_with_its_own_run(problems, fresh):
    default = load_shipped_default()
    two, three = (plan_scenario(s, "fuzzy-rrt", rulebook=default, seed=1) for s in problems)
    again = [plan_scenario(s, "fuzzy-rrt", rulebook=default, seed=1) for s in problems]
    assert (two.planner_used, three.planner_used) == ("fuzzy-rrt", "fuzzy-rrt-connect")
    assert (two.rulebook, three.rulebook) == ("goal-frame", "goal-frame-any")
    _same(two, again[0])
    _same(three, again[1])


def test_another_setting_or_object_is_not_served_by_the_kept_run(problems, fresh):
    s = problems[0]
    default = load_shipped_default()
    plan_scenario(s, "fuzzy-rrt", rulebook=default, seed=3, max_iter=10_000)
    short = plan_scenario(s, "fuzzy-rrt", rulebook=default, seed=3, max_iter=1)
    assert short.params["max_iter"] == 1 and short.iterations <= 1
    tuned = load_tuned_rrt()
    plan_scenario(s, "rrt:tuned", rulebook=tuned, seed=3)
    other = api.TunedRRT(step_deg=5.0, goal_bias=0.5)
    assert plan_scenario(s, "rrt:tuned", rulebook=other, seed=3).params["step_deg"] == 5.0
    copy = dataclasses.replace(s, name="renamed")
    assert plan_scenario(copy, "fuzzy-rrt", rulebook=default, seed=3).scenario == "renamed"
    plan_scenario(s, "rrt", seed=3, step_deg=10.0)
    assert plan_scenario(s, "rrt", seed=3, step_deg=20.0).params["step_deg"] == 20.0
    assert plan_scenario(s, "rrt", seed=3, step_deg=20.0, goal_bias=0.5).params["goal_bias"] == 0.5
    wide = plan_scenario(s, "fuzzy-rrt", rulebook=default, seed=3, clearance_m=0.002)
    assert wide.params["margin_m"] > plan_scenario(s, "fuzzy-rrt", rulebook=default,
                                                   seed=3).params["margin_m"]


def test_a_bad_seed_is_refused_on_the_kept_run_too(problems, fresh):
    s = problems[0]
    default = load_shipped_default()
    plan_scenario(s, "fuzzy-rrt", rulebook=default, seed=0)
    for bad in (-1, 2**63, 1.5, True):
        with pytest.raises(InputError, match="--seed"):
            plan_scenario(s, "fuzzy-rrt", rulebook=default, seed=bad)


def test_traces_budgets_and_rulebooks_read_from_folders_plan_as_before(problems, fresh,
                                                                        tmp_path):
    s = problems[0]
    default = load_shipped_default()
    traced = plan_scenario(s, "fuzzy-rrt", rulebook=default, seed=2, trace=True)
    assert traced.trace is not None and len(traced.trace) == traced.iterations
    timed = plan_scenario(s, "fuzzy-rrt", rulebook=default, seed=2, max_time_s=5.0)
    assert "stopped_by" in timed.params
    assert api._LANES == {}  # neither kept a run
    # a folder, or no rulebook, is looked at again on every call: an edit is seen
    folder = tmp_path / "rb"
    shutil.copytree(rulebooks_dir() / "goal-frame", folder)
    plan_scenario(s, "fuzzy-rrt", rulebook=str(folder), seed=2)
    plan_scenario(s, "fuzzy-rrt", seed=2)
    plan_scenario(s, "rrt:tuned", seed=2)
    assert api._LANES == {}
    # a rulebook loaded elsewhere than the folder a label names is compared on every call
    plan_scenario(s, "fuzzy-rrt:goal-frame", rulebook=load_rulebook(folder), seed=2)
    assert api._LANES == {}


def test_a_kept_run_goes_with_its_scenario(problems, fresh):
    copy = dataclasses.replace(problems[0], name="short-lived")
    plan_scenario(copy, "fuzzy-rrt", rulebook=load_shipped_default(), seed=0, max_iter=50)
    plan_scenario(copy, "rrt", seed=0, max_iter=50)
    assert len(api._LANES) == 2
    del copy
    gc.collect()
    assert api._LANES == {} and len(setup_memo._memo) == 0


def _same_but_the_budget(lane, general) -> None:
    """A run through its lane and the same run through the general path (a time budget it
    never reaches): every field and instance entry the same, save the clock and the budget's
    own records in ``params``."""
    _same(dataclasses.replace(lane, params={}), dataclasses.replace(general, params={}))
    extra = {k: v for k, v in general.params.items() if k not in ("max_time_s", "stopped_by")}
    assert lane.params == extra
    assert list(lane.params) == list(extra)  # in the same order too (JSON, CSV columns)
    assert set(lane.__dict__) == set(general.__dict__)
    assert lane.min_clearance_m == general.min_clearance_m
    assert lane.penetration_m == general.penetration_m


@pytest.mark.parametrize("planner, loader", [
    ("fuzzy-rrt", load_shipped_default),
    ("rrt:tuned", load_tuned_rrt),
    ("rrt", lambda: None),
    ("fuzzy-rrt-connect", lambda: preloaded("fuzzy-rrt-connect", None)),
])
@pytest.mark.parametrize("max_iter", [10_000, 2])
def test_a_lane_builds_the_result_the_general_path_builds(problems, fresh, planner, loader,
                                                          max_iter):
    """A lane (its template made once, its entry called its own way) gives the general path's
    result (the time-budgeted run), found or not, field for field."""
    rulebook = loader()
    found = []
    for scenario in problems:
        for seed in range(3):
            lane = plan_scenario(scenario, planner, rulebook=rulebook, seed=seed,
                                 max_iter=max_iter)
            general = plan_scenario(scenario, planner, rulebook=rulebook, seed=seed,
                                    max_iter=max_iter, max_time_s=600.0)
            assert general.params["stopped_by"] != "time"
            _same_but_the_budget(lane, general)
            found.append(lane.found)
    assert any(k[0] == planner for k in api._LANES)
    # both branches of bound_result: every run found with room, some not with two iterations
    assert all(found) if max_iter > 2 else not all(found)


@pytest.mark.parametrize("found", [True, False])
def test_a_result_filled_from_a_template_is_certified_results_own(problems, found):
    """Every compiled planner's run ends in ``bound_result`` (lanes, traces and budgets alike),
    so it is checked here against ``certified_result`` itself, the other way every planner's
    result is made: the same fields, the same instance entries, the same deferred clearance."""
    from xfuzzy_rrt.planners.prepared import scenario_arrays
    from xfuzzy_rrt.planners.result import bound_result, certified_result, certified_template

    scenario = problems[1]
    run = plan_scenario(scenario, "rrt", seed=3, max_iter=10_000 if found else 2)
    assert run.found is found
    arrays, margin = scenario_arrays(scenario), float(run.params["margin_m"])
    fixed = dict(scenario=scenario.name, planner="a-label", planner_used="a-planner",
                 rulebook="a-rulebook", rulebook_sha256="ab" * 32)
    template = certified_template(seed=0, iterations=0, nodes=0, cost_deg=None, wall_s=0.0,
                                  path_deg=None, tree_nodes_deg=None, tree_parent=None, work=0,
                                  params=None, **fixed)
    params = {"max_iter": 17, "margin_m": margin}
    got = bound_result(template, arrays, margin, found, True, 11, 17, 23, 123.25, 0.5,
                       run.path_deg, run.tree_nodes_deg, run.tree_parent, 999, dict(params))
    want = certified_result(arrays, margin, found, edges_certified=True, within_limits=True,
                            seed=11, iterations=17, nodes=23,
                            cost_deg=123.25 if found else None, wall_s=0.5,
                            path_deg=run.path_deg, tree_nodes_deg=run.tree_nodes_deg,
                            tree_parent=run.tree_parent, work=999, params=dict(params),
                            **fixed)
    _same(got, want)
    assert got.wall_s == want.wall_s and got.params == want.params
    assert set(got.__dict__) == set(want.__dict__)
    assert got.min_clearance_m == want.min_clearance_m
    assert got.penetration_m == want.penetration_m
