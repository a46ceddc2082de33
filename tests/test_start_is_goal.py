"""A problem whose start *is* its goal: every tree planner returns ``[start, goal]``, of length
zero, after no iteration -- not a path that goes away and comes back (``fuzzy-rrt`` swung
166 deg, ``fuzzy-rrt-connect`` 153 deg, ``rrt`` 14 deg before the fix) -- and only when the
start keeps the margin; explaining such a run is one line, exit 2. Problems whose start is not
their goal plan as before (the golden tests)."""

from __future__ import annotations

import numpy as np
import pytest

from exact_geometry import oracle_path_problems
from xfuzzy_rrt.geometry.scenario import Scenario, scenario_from_dict
from xfuzzy_rrt.planners.api import plan_scenario

TREE_PLANNERS = ("fuzzy-rrt", "rrt", "rrt:tuned", "fuzzy-rrt:paper", "fuzzy-rrt:general",
                 "fuzzy-rrt-connect")


def _stay(q_deg, links=(0.18, 0.12), arms=1) -> Scenario:
    """One arm (or ``arms`` arms side by side) asked to stay at ``q_deg``, beside a circle:
    the file a user would write, through the loader."""
    q = [float(v) for v in q_deg]
    if arms == 1:
        head = {"arm": {"links": list(links), "link_radius": 0.005},
                "start": {"q_deg": q}, "goal": {"q_deg": q}}
    else:
        head = {"arms": [{"links": list(links), "base": [0.45 * k, 0.0], "link_radius": 0.005,
                          "start_deg": q, "goal_deg": q} for k in range(arms)]}
    return scenario_from_dict({"name": "stay", **head, "obstacles": [
        {"type": "circle", "center": [0.24, 0.15], "radius": 0.045}]}, "stay.toml")


@pytest.mark.parametrize("planner", TREE_PLANNERS)
def test_a_start_that_is_the_goal_is_a_zero_length_path_after_no_iteration(planner):
    s = _stay((10.0, 20.0))
    for seed in (0, 1, 7):
        r = plan_scenario(s, planner, seed=seed)
        assert r.success and r.certified, (planner, seed)
        assert r.iterations == 0
        assert r.cost_deg == 0.0
        np.testing.assert_array_equal(r.path_deg, [s.start_deg, s.goal_deg])
        assert oracle_path_problems(s, r.path_deg, s.start_deg, s.goal_deg) == []
        assert r.work > 0  # the start's clearance was measured: the zero-length edge's check


@pytest.mark.parametrize("links,arms", [((0.12, 0.1, 0.08), 1), ((0.1, 0.08, 0.06, 0.05, 0.04,
                                                                    0.03, 0.02), 1),
                                        ((0.12, 0.1, 0.06), 2)])
def test_the_default_stays_put_on_any_arm(links, arms):
    """The shipped default on 3 and 7 joints and two arms (Fuzzy-RRT-Connect, goal-frame-any)."""
    s = _stay((5.0,) * len(links), links, arms)
    r = plan_scenario(s, "fuzzy-rrt", seed=3)
    assert r.planner_used == "fuzzy-rrt-connect"
    assert r.success and r.iterations == 0 and r.cost_deg == 0.0
    np.testing.assert_array_equal(r.path_deg, [s.start_deg, s.goal_deg])
    assert oracle_path_problems(s, r.path_deg, s.start_deg, s.goal_deg) == []


@pytest.mark.parametrize("planner", ["rrt", "fuzzy-rrt"])
def test_a_start_at_the_goal_inside_the_margin_gets_no_zero_length_path(planner):
    """The zero-length edge is certified as any node: with a kernel margin above the start's
    clearance the planner does not return it (nor any other path: no motion leaves the start)."""
    from xfuzzy_rrt.geometry.collision import clearance

    s = _stay((10.0, 20.0))
    c = float(clearance(s.arrays(), np.asarray(s.start_deg)))
    if planner == "rrt":
        from xfuzzy_rrt.planners.rrt import plan_rrt as plan
    else:
        from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt as plan
    r = plan(s, seed=0, max_iter=50, margin=c * 1.01)
    assert not r.success and r.iterations == 50
    r = plan(s, seed=0, max_iter=50, margin=c * 0.99)
    assert r.success and r.iterations == 0


def test_a_run_of_no_iteration_is_traced_and_explaining_it_is_one_line(tmp_path):
    from conftest import run_main

    from xfuzzy_rrt.geometry.scenario import load_scenario  # noqa: F401  (the file round-trips)
    from xfuzzy_rrt.scenarios.writer import scenario_toml

    path = tmp_path / "stay.toml"
    path.write_text(scenario_toml(_stay((10.0, 20.0)), "asked to stay"), encoding="utf-8")
    r = plan_scenario(load_scenario(path), "fuzzy-rrt", seed=0, trace=True)
    assert r.success and len(r.trace) == 0
    trace, result = tmp_path / "t.csv", tmp_path / "r.json"
    proc = run_main("plan", path, "--trace", trace, "--out", result)
    assert proc.returncode == 0, proc.stderr
    for source, where in ((trace, str(trace)), (result, "--iteration")):
        proc = run_main("explain", source, "--iteration", "1")
        assert proc.returncode == 2
        assert proc.stderr.strip() == (f"error: {where}: the run made no iteration (its start "
                                       "is its goal), so no decision to explain")


@pytest.mark.parametrize("fitness,bounds,message", [
    ("log-ratio", "absolute", "error: --fitness: log-ratio needs RRT's median iterations "
     "(positive) for every training scenario; scenario 'stay' has 0 (is its start its goal?)"),
    ("work-cost-cvar", "goal-frame", "error: {file}: the tuned RRT's paths have length zero (the "
     "start is the goal), so work-cost-cvar has no path cost to compare with: leave this scenario "
     "out"),
])
def test_training_on_a_start_that_is_its_goal_is_refused_naming_it(tmp_path, fitness, bounds,
                                                                    message):
    """Fitnesses that divide by the baseline's iterations or path cost cannot use a problem that
    needs none: one line names it (the paper's and work-cvar fitnesses train on it)."""
    from conftest import run_main

    from xfuzzy_rrt.scenarios.writer import scenario_toml

    path = tmp_path / "stay.toml"
    path.write_text(scenario_toml(_stay((10.0, 20.0)), "asked to stay"), encoding="utf-8")
    out = tmp_path / "rb"
    proc = run_main("train", "--scenario", path, "--population", "12", "--generations", "1",
                    "--runs-per-eval", "1", "--fitness", fitness, "--bounds", bounds,
                    "--workers", "1", "--out", out)
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines()[-1] == message.format(file=path)
    assert not out.exists()
