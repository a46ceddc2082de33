"""Issue 25, "Any arm": the default planner plans any arm out of the box.

Plain ``fuzzy-rrt`` with no rulebook named (the CLI's default, ``plan_scenario(s, "fuzzy-rrt")``)
runs the shipped default of the problem: ``goal-frame`` on one 2-joint arm, Fuzzy-RRT-Connect
with the DOF-free ``goal-frame-any`` on any other (``planners/api.py:shipped_default``). Every
path it returns on 3-7 joints and on two to four arms is proven collision-free by the
independent oracle (tests/exact_geometry.py); the result, ``runs.csv`` and the trace say what
ran; a rulebook the user names that does not fit is still one ``error:`` line.

The problems are built here (small, seeded, quick to solve): an N-link arm that must curl past
a circle and under a box, and 2-4 two-link arms side by side whose straight motions sweep
through their neighbours.
"""

from __future__ import annotations

import json

import numpy as np
import pandas as pd
import pytest

from conftest import FIXTURES
from exact_geometry import as_world, oracle_path_problems
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebooks_dir
from xfuzzy_rrt.geometry.collision import in_collision, segment_free
from xfuzzy_rrt.geometry.scenario import Arm, Box, Circle, Scenario
from xfuzzy_rrt.planners.api import plan_scenario
from xfuzzy_rrt.scenarios.writer import scenario_toml

MAX_ITER = 4_000
SEEDS = (0, 1)
ANY = rulebooks_dir() / "goal-frame-any"
TWO_JOINTS = FIXTURES / "scenarios" / "two-circles.toml"


def _arm(n: int, base=(0.0, 0.0), reach: float = 1.0) -> Arm:
    return Arm(links=tuple([reach / n] * n), base=base, link_radius=0.01,
               joint_limits_deg=((-180.0, 180.0),) * n)


def one_arm(n: int) -> Scenario:
    """An N-link arm (reach 1 m) turning from -60 to +60 degrees: the straight motion hits a
    circle near its reach, and a box above keeps it from swinging wide."""
    rng = np.random.default_rng(2500 + n)
    start = (-60.0,) + tuple(rng.uniform(-5, 5, n - 1))
    goal = (60.0,) + tuple(rng.uniform(-5, 5, n - 1))
    return Scenario(name=f"any-arm{n}", arm=_arm(n), start_deg=start, goal_deg=goal,
                    obstacles=(Circle((0.85, 0.0), 0.06), Box((-0.2, 0.75), (0.2, 0.85))))


def side_by_side(k: int) -> Scenario:
    """``k`` two-link arms (reach 0.4 m) on bases 0.5 m apart, each turning from pointing right
    (10 deg) to pointing left (170 deg) over the top, where a circle sits on its way: each arm
    must fold its elbow to pass, within reach of its neighbours."""
    bases = [((i - (k - 1) / 2) * 0.5, 0.0) for i in range(k)]
    arms = [_arm(2, b, 0.4) for b in bases]
    return Scenario(name=f"any-arms{k}", arm=arms[0], more_arms=tuple(arms[1:]),
                    start_deg=(10.0, 0.0) * k, goal_deg=(170.0, 0.0) * k,
                    obstacles=tuple(Circle((x, 0.3), 0.05) for x, _ in bases))


def dual(n: int) -> Scenario:
    """Two N-link arms (reach 0.5 m, bases 0.9 m apart): arm A swings from up to down through
    the space where arm B points at it."""
    rng = np.random.default_rng(3500 + n)
    a, b = _arm(n, (-0.45, 0.0), 0.5), _arm(n, (0.45, 0.0), 0.5)
    rest = tuple(rng.uniform(-5, 5, n - 1))
    start = (90.0,) + rest + (180.0,) + tuple(rng.uniform(-5, 5, n - 1))
    goal = (-90.0,) + rest + (170.0,) + tuple(rng.uniform(-5, 5, n - 1))
    return Scenario(name=f"any-dual{n}", arm=a, more_arms=(b,), start_deg=start, goal_deg=goal,
                    obstacles=(Circle((0.0, 0.6), 0.08),))


PROBLEMS = [one_arm(3), one_arm(4), one_arm(6), one_arm(7), dual(2), dual(3), side_by_side(3),
            side_by_side(4)]


def run_main(args) -> tuple[int, str, str]:
    """``xfuzzy-rrt ARGS`` in-process (no interpreter start-up): exit code, stdout, stderr."""
    import contextlib
    import io

    from xfuzzy_rrt.cli.main import main

    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main([str(a) for a in args])
    return code, out.getvalue(), err.getvalue()


def _oracle_ok(s: Scenario, path) -> None:
    assert oracle_path_problems(s, np.asarray(path, dtype=float), s.start_deg, s.goal_deg) == []


def _write(s: Scenario, tmp_path):
    path = tmp_path / f"{s.name}.toml"
    path.write_text(scenario_toml(s, "test problem of tests/test_default_plans_any_arm.py"))
    return path


@pytest.mark.parametrize("s", PROBLEMS, ids=lambda s: s.name)
def test_the_fixtures_are_valid_and_not_straight_line_problems(s):
    w = as_world(s)
    ends = np.array([s.start_deg, s.goal_deg])
    assert not w.in_collision(ends).any()
    assert not in_collision(s.arrays(), ends[0]) and not in_collision(s.arrays(), ends[1])
    assert w.path_min_clearance(ends, threshold=0.0).upper <= 0.0  # the oracle: it collides
    assert not segment_free(s.arrays(), s.start_deg, s.goal_deg)


@pytest.mark.parametrize("s", PROBLEMS, ids=lambda s: s.name)
def test_the_default_plans_any_arm_and_the_oracle_agrees(s):
    for seed in SEEDS:
        r = plan_scenario(s, "fuzzy-rrt", seed=seed, max_iter=MAX_ITER)
        assert r.success, (s.name, seed, r.iterations, r.violation)
        assert r.planner == "fuzzy-rrt" and r.planner_used == "fuzzy-rrt-connect"
        assert r.rulebook == "goal-frame-any"
        assert r.rulebook_sha256 == load_rulebook(ANY).sha256
        _oracle_ok(s, r.path_deg)


def test_on_one_two_joint_arm_the_default_is_goal_frame_fuzzy_rrt_as_before():
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt

    s = load_scenario(TWO_JOINTS)
    r = plan_scenario(s, "fuzzy-rrt", seed=3)
    old = plan_fuzzy_rrt(s, seed=3)
    assert (r.planner_used, r.rulebook) == ("fuzzy-rrt", "goal-frame")
    assert r.path_deg.tobytes() == old.path_deg.tobytes() and r.iterations == old.iterations


@pytest.mark.parametrize("s", [one_arm(3), side_by_side(3)], ids=lambda s: s.name)
def test_plan_without_a_rulebook_plans_any_arm_and_its_json_says_what_ran(s, tmp_path):
    path = _write(s, tmp_path)
    out = tmp_path / "r.json"
    code, stdout, err = run_main(["plan", path, "--seed", "1", "--max-iter", str(MAX_ITER),
                                  "--out", out])
    assert code == 0, err
    assert all(x.startswith("warning: ") or x.startswith("compiling ")
               for x in err.splitlines()), err
    data = json.loads(out.read_text())
    assert data["success"] is True
    assert data["planner"] == "fuzzy-rrt" and data["planner_used"] == "fuzzy-rrt-connect"
    assert data["rulebook"] == "goal-frame-any"
    assert data["rulebook_sha256"] == load_rulebook(ANY).sha256
    assert data["rulebook_dir"] == str(ANY.resolve())
    _oracle_ok(s, data["path_deg"])
    # same seed, same bytes (wall-clock fields aside)
    again = tmp_path / "again.json"
    assert run_main(["plan", path, "--seed", "1", "--max-iter", str(MAX_ITER), "--out",
                     again])[0] == 0
    a, b = json.loads(out.read_text()), json.loads(again.read_text())
    for d in (a, b):
        d.pop("wall_s")
        d["params"].pop("time_first_s", None)
    assert json.dumps(a, sort_keys=True) == json.dumps(b, sort_keys=True)


def test_a_named_rulebook_that_does_not_fit_is_still_one_error_line(tmp_path):
    s = one_arm(4)
    path = _write(s, tmp_path)
    for args in (["--rulebook", rulebooks_dir() / "goal-frame"],
                 ["--planner", "fuzzy-rrt:goal-frame"], ["--planner", "fuzzy-rrt:goal-frame-5dof"]):
        out = tmp_path / "never.json"
        code, stdout, err = run_main(["plan", path, *args, "--out", out])
        assert code == 2 and "Traceback" not in err, err
        assert err.count("\n") == 1 and err.startswith(f"error: {path}: rulebook "), err
        assert "name no rulebook: the default plans any arm" in err
        assert not out.exists()
    with pytest.raises(InputError, match="goal-frame rulebook; this problem has 4 joints"):
        plan_scenario(s, "fuzzy-rrt", rulebook=rulebooks_dir() / "goal-frame")
    with pytest.raises(InputError, match="fuzzy-rrt-connect"):
        plan_scenario(s, "fuzzy-rrt", rulebook=load_rulebook(ANY))  # named: not the default


def test_explain_finds_the_rulebook_that_made_a_default_any_arm_trace(tmp_path):
    s = one_arm(4)
    path = _write(s, tmp_path)
    out, trace = tmp_path / "r.json", tmp_path / "t.parquet"
    # a seed whose plan takes several iterations (a lucky one connects at iteration 1)
    seed = next(k for k in range(50)
                if plan_scenario(s, "fuzzy-rrt", seed=k, max_iter=MAX_ITER).iterations >= 3)
    code, _, err = run_main(["plan", path, "--seed", str(seed), "--max-iter", str(MAX_ITER),
                             "--out", out, "--trace", trace])
    assert code == 0, err
    frame = pd.read_parquet(trace)
    assert set(frame["rulebook"]) == {"goal-frame-any"} and "tree" in frame.columns
    for source in (trace, out):  # the trace file, and a replay of the result JSON
        code, text, err = run_main(["explain", source, "--iteration", "2"])
        assert code == 0, err
        assert "rulebook 'goal-frame-any'" in text and "Fuzzy-RRT-Connect" in text


def test_bench_over_two_and_five_joints_runs_both_and_records_what_ran_with_any_workers(tmp_path):
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.geometry.scenario import load_scenario

    two = load_scenario(TWO_JOINTS)
    five = load_scenario(FIXTURES / "arms" / "five-dof.toml")
    res = run_benchmark([two, five], ["rrt", "fuzzy-rrt"], runs=2, max_iter=MAX_ITER)
    runs = res.runs
    fz = runs[runs["planner"] == "fuzzy-rrt"].set_index("scenario")
    assert set(fz.loc[two.name, "planner_used"]) == {"fuzzy-rrt"}
    assert set(fz.loc[two.name, "rulebook"]) == {"goal-frame"}
    assert set(fz.loc[five.name, "planner_used"]) == {"fuzzy-rrt-connect"}
    assert set(fz.loc[five.name, "rulebook"]) == {"goal-frame-any"}
    assert set(fz.loc[five.name, "rulebook_sha256"]) == {load_rulebook(ANY).sha256}
    assert fz["success"].all()
    assert set(runs.loc[runs["planner"] == "rrt", "planner_used"]) == {"rrt"}
    # same seeds, same runs, whatever the number of workers (the wall-clock columns aside)
    two_workers = run_benchmark([two, five], ["rrt", "fuzzy-rrt"], runs=2, max_iter=MAX_ITER,
                                workers=2).runs
    timed = ["wall_s", "time_first_s", "time_total_s"]
    pd.testing.assert_frame_equal(runs.drop(columns=timed), two_workers.drop(columns=timed))
    # one row per planner in the tables, both rulebooks in the benchmark's record
    assert sorted(set(res.summary["planner"])) == ["fuzzy-rrt", "rrt"]
    listed = {e["planner"]: e["name"] for e in res.settings["rulebooks"]}
    assert listed == {"fuzzy-rrt": "goal-frame", "fuzzy-rrt (any arm)": "goal-frame-any"}
    example = res.examples[(five.name, "fuzzy-rrt")]
    assert example.rulebook == "goal-frame-any" and example.trace is not None
    _oracle_ok(five, example.path_deg)
    # the bench folder keeps it (every joint of the example, what ran) and reads back
    from xfuzzy_rrt.bench.store import load_bench_dir, write_bench_dir

    write_bench_dir(res, tmp_path / "b", {"command": "test"})
    back = load_bench_dir(tmp_path / "b")
    assert pd.read_csv(tmp_path / "b" / "runs.csv")["planner_used"].tolist() == \
        runs["planner_used"].tolist()
    again = back.examples[(five.name, "fuzzy-rrt")]
    assert again.planner_used == "fuzzy-rrt-connect"
    assert again.path_deg.tobytes() == example.path_deg.tobytes()
    assert again.tree_nodes_deg.shape[1] == 5
    assert {k: rb.name for k, rb in back.rulebooks.items()} == listed
    # the report's drill-down follows the any-arm run with the rulebook that made it, and its
    # reproduce command is the default's (no --rulebook: the 2-joint one would be refused)
    page = _scenario_page(back, five.name)
    assert "Follow one plan" in page and "goal-frame-any" in page
    assert f"--planner fuzzy-rrt --seed {example.seed} --max-iter {MAX_ITER}" in page
    assert "--rulebook" not in page


def test_evaluate_without_a_rulebook_runs_the_default_of_each_problem(tmp_path):
    out = tmp_path / "ev"
    code, text, err = run_main(["evaluate", TWO_JOINTS, _write(one_arm(3), tmp_path), "--runs",
                                "1", "--no-tuned", "--max-iter", "1000", "--out", out])
    assert code == 0, err
    runs = pd.read_csv(out / "runs.csv")
    fz = runs[runs["planner"] == "fuzzy-rrt"]
    assert dict(zip(fz["scenario"], fz["planner_used"])) == {
        "two-circles": "fuzzy-rrt", "any-arm3": "fuzzy-rrt-connect"}
    assert dict(zip(fz["scenario"], fz["rulebook"])) == {
        "two-circles": "goal-frame", "any-arm3": "goal-frame-any"}
    assert fz["success"].all()


def _scenario_page(result, name: str) -> str:
    """The report's page of one scenario (without the rest of the site)."""
    from xfuzzy_rrt.report import site
    from xfuzzy_rrt.report.plotjson import no_default_template

    books = site.rulebooks_of(result)
    names = list(result.scenarios)
    ctx = dict(result=result, command="test", generated_at="now", prov={},
               settings=dict(result.settings), planners=["fuzzy-rrt"],
               scen_names=names, books=books, names=site.Names(names, list(books)), folder=None)
    with no_default_template():
        return site._scenario_page(ctx, names.index(name), name)


def test_bench_with_a_named_rulebook_that_does_not_fit_fails_before_planning(tmp_path):
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.geometry.scenario import load_scenario

    five = load_scenario(FIXTURES / "arms" / "five-dof.toml")
    with pytest.raises(InputError, match="name no rulebook"):
        run_benchmark([five], ["fuzzy-rrt"], runs=1, rulebook=rulebooks_dir() / "goal-frame")


def test_bench_runs_fuzzy_rrt_connect_by_name_on_any_arm():
    # the pre-run check of every (problem, rulebook) pair checks a fuzzy-rrt-connect label as
    # Fuzzy-RRT-Connect does (a DOF-free rulebook fits every arm), not as Fuzzy-RRT
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.geometry.scenario import load_scenario

    five = load_scenario(FIXTURES / "arms" / "five-dof.toml")
    runs = run_benchmark([five], ["fuzzy-rrt-connect"], runs=1, max_iter=MAX_ITER).runs
    assert runs["success"].all() and list(runs["rulebook"]) == ["goal-frame-any"]
