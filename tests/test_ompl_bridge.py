"""OMPL planners run as peers on our checker: by default every motion goes through our certified
edge check (``ompl:NAME``); with ``:sampled`` OMPL samples its motions and the path is certified
afterwards.

These tests need the optional 'ompl' extra and do not skip without it: CI installs it, and a
skipped peer comparison is not a passed one.
"""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest

from conftest import FIXTURES, PROJECT, shared_scenarios, thin_box
from exact_geometry import Oracle
from xfuzzy_rrt.cli.main import main
from xfuzzy_rrt.errors import InputError
from single_arm import config_free
from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M
from xfuzzy_rrt.geometry.path_check import certify_path
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.api import PLANNERS, check_planner, is_known_planner, plan_scenario
from xfuzzy_rrt.planners.ompl_bridge import (COUNTS_WORK, DEFAULT_RANGE_DEG, MISSING_EXTRA,
                                             certified_motion_validator, make_validity_callback,
                                             parse_ompl_label, plan_ompl)
from xfuzzy_rrt.planners.result import path_cost_deg

SCENARIOS = (sorted((FIXTURES / "scenarios").glob("*.toml"))
             + sorted((PROJECT / "xfuzzy_rrt" / "data" / "scenarios").glob("*.toml"))
             + [p for p in shared_scenarios() if p.stem == "paper-reference"])
TWO_CIRCLES = FIXTURES / "scenarios" / "two-circles.toml"
PEERS = ("ompl:RRT", "ompl:RRTConnect", "ompl:RRTstar", "ompl:BITstar")
#: 2 joints, 5 joints, two arms of 3 joints.
ARM_FIXTURES = (TWO_CIRCLES, FIXTURES / "arms" / "five-dof.toml",
                FIXTURES / "arms" / "dual-3dof.toml")


@pytest.fixture
def untuned(monkeypatch):
    """No tuned OMPL range (whatever the shipped files say): the 10-degree default applies."""
    import xfuzzy_rrt.planners.tuned as tuned

    monkeypatch.setattr(tuned, "tuned_params", lambda label, shape=(1, 2): None)
    monkeypatch.setattr(tuned, "tuned_by_shape", lambda label: {})


@pytest.mark.parametrize("path", SCENARIOS, ids=lambda p: p.stem)
def test_ompl_paths_run_start_to_goal_exactly_and_certification_agrees_with_the_oracle(path):
    s = load_scenario(path)
    a = s.arrays()
    oracle = Oracle(path)
    for planner in PEERS + ("ompl:RRTConnect:sampled",):
        for seed in range(4):
            r = plan_scenario(s, planner=planner, seed=seed)
            assert r.planner == planner and r.found, (planner, seed)
            if not planner.endswith(":sampled"):
                assert r.success, ("certified by construction", planner, seed)
            assert np.array_equal(r.path_deg[0], a.start_deg)
            assert np.array_equal(r.path_deg[-1], a.goal_deg)
            assert r.cost_deg == pytest.approx(path_cost_deg(r.path_deg))
            assert r.nodes == len(r.tree_nodes_deg) > 0 and r.iterations > 0
            check = certify_path(a, r.path_deg)
            assert r.certified == r.success == check.certified
            assert r.penetration_m == check.penetration_m
            assert r.min_clearance_m == check.min_clearance_m
            assert r.to_json_dict()["success"] is check.certified
            problems = oracle.path_problems(r.path_deg)
            if check.certified:
                assert problems == [], (planner, seed)  # never silently accepted
            if problems:
                assert not check.certified and check.penetration_m > 0.0, (planner, seed)


def test_a_grazing_edge_that_ompl_samples_past_is_flagged_with_its_depth(tmp_path):
    # One straight motion start -> goal (goal bias 1, huge range), checked by OMPL at 5 % of
    # the extent (~25 deg): its samples at -36, -12, 12, 36 deg miss the box at 0 deg.
    file = thin_box(tmp_path)
    s = load_scenario(file)
    r = plan_ompl(s, "ompl:RRT:sampled", seed=0, step_deg=1000.0, goal_bias=1.0,
                  validity_resolution=0.05)
    assert r.params["motion_validator"] == "sampled"
    assert r.found and r.path_deg.tolist() == [[-60.0, 0.0], [60.0, 0.0]]
    assert not r.success and not r.certified, "a colliding path is never a success"
    assert Oracle(file).path_problems(r.path_deg), "the oracle sees the collision"
    check = certify_path(s.arrays(), r.path_deg)
    assert not check.certified and check.worst_segment == 0
    assert check.penetration_m == pytest.approx(0.007, abs=1e-9)  # 2 mm box half + 5 mm radius
    assert r.penetration_m == check.penetration_m and r.min_clearance_m == -r.penetration_m
    assert r.violation.startswith("segment 0 penetrates an obstacle 7 mm deep at q = (")
    # With a fine motion check OMPL itself refuses that edge and finds another way.
    fine = plan_ompl(s, "ompl:RRT:sampled", seed=0, step_deg=1000.0, goal_bias=1.0,
                     validity_resolution=0.001)
    assert not fine.success or len(fine.path_deg) > 2


def test_the_certified_motion_check_refuses_the_edge_that_sampling_steps_over(tmp_path):
    # The same straight motion, now checked by our certified edge check: refused, so the
    # planner finds another way round or nothing, never the penetrating edge.
    file = thin_box(tmp_path)
    s = load_scenario(file)
    for seed in range(5):
        r = plan_ompl(s, "ompl:RRT", seed=seed, step_deg=1000.0, goal_bias=1.0, max_iter=2000)
        assert r.params["motion_validator"] == "certified"
        assert r.params["motions_checked"] > 0
        assert r.success == r.found, "every path OMPL returns is certified"
        if r.found:
            assert len(r.path_deg) > 2 and Oracle(file).path_problems(r.path_deg) == []


def test_the_certified_motion_validator_agrees_with_segment_free(tmp_path):
    from ompl import base as ob

    from xfuzzy_rrt.geometry.collision import segment_free

    for file in (thin_box(tmp_path), FIXTURES / "arms" / "five-dof.toml",
                 FIXTURES / "arms" / "dual-2dof.toml"):
        a = load_scenario(file).arrays()
        dof = a.links.shape[0]
        space = ob.RealVectorStateSpace(dof)
        bounds = ob.RealVectorBounds(dof)
        for j in range(dof):
            bounds.setLow(j, float(a.limits_deg[j, 0]))
            bounds.setHigh(j, float(a.limits_deg[j, 1]))
        space.setBounds(bounds)
        si = ob.SpaceInformation(space)
        si.setStateValidityChecker(make_validity_callback(a))
        counts = np.zeros(4, dtype=np.int64)
        si.setMotionValidator(certified_motion_validator(si, space, a, CERT_MARGIN_M, counts))
        si.setup()
        s1, s2 = space.allocState(), space.allocState()
        rng = np.random.default_rng(11)
        verdicts = []
        for _ in range(300):
            qa, qb = rng.uniform(a.limits_deg[:, 0], a.limits_deg[:, 1], size=(2, dof))
            qb = qa + rng.uniform(0.0, 1.0) * (qb - qa)  # short and long motions
            for j in range(dof):
                s1[j], s2[j] = float(qa[j]), float(qb[j])
            ours = bool(si.checkMotion(s1, s2))
            assert ours == segment_free(a, qa, qb), (file, qa, qb)
            verdicts.append(ours)
        assert 0 < sum(verdicts) < len(verdicts), file  # both verdicts were exercised
        assert counts[1] == len(verdicts) and counts[2] == len(verdicts) - sum(verdicts)


def test_where_sampling_penetrates_the_certified_validator_returns_only_certified_paths():
    # On two-circles OMPL's sampled motion check lets RRTConnect graze a circle on several
    # seeds; through the certified check every path is certified, on every seed.
    s = load_scenario(TWO_CIRCLES)
    oracle = Oracle(TWO_CIRCLES)
    sampled = [plan_scenario(s, planner="ompl:RRTConnect:sampled:range=10", seed=k)
               for k in range(20)]
    assert any(r.found and not r.certified and r.penetration_m > 0.0 for r in sampled)
    for seed in range(20):
        r = plan_scenario(s, planner="ompl:RRTConnect", seed=seed)
        assert r.found and r.certified and r.success, seed
        assert oracle.path_problems(r.path_deg) == [], seed


@pytest.mark.parametrize("path", ARM_FIXTURES, ids=lambda p: p.stem)
@pytest.mark.parametrize("planner", ["ompl:RRTConnect", "ompl:BITstar"])
def test_rrtconnect_and_bitstar_solve_two_joints_five_joints_and_two_arms(path, planner):
    s = load_scenario(path)
    a = s.arrays()
    for seed in range(5):
        r = plan_scenario(s, planner=planner, seed=seed)
        assert r.success, (planner, seed, r.params.get("stopped_by"))
        assert np.array_equal(r.path_deg[0], a.start_deg)
        assert np.array_equal(r.path_deg[-1], a.goal_deg)
        again = plan_scenario(s, planner=planner, seed=seed)
        assert np.array_equal(again.path_deg, r.path_deg)
        for key in ("motions_checked", "state_checks", "work"):
            assert again.params[key] == r.params[key], key
        if COUNTS_WORK:  # the problem bundle counts distance evaluations (interfaces.md 1)
            assert r.params["work"] > 0
        else:
            assert r.params["work"] is None


def test_the_same_seed_repeats_the_run_and_other_seeds_differ():
    s = load_scenario(TWO_CIRCLES)
    for planner in PEERS:
        runs = [plan_scenario(s, planner=planner, seed=7) for _ in range(2)]
        assert np.array_equal(runs[0].path_deg, runs[1].path_deg)
        assert runs[0].iterations == runs[1].iterations and runs[0].nodes == runs[1].nodes
        others = {plan_scenario(s, planner=planner, seed=k).path_deg.tobytes() for k in range(4)}
        assert len(others) > 1, planner


def test_rrt_iterations_counted_by_the_termination_condition_equal_rrtstar_own_counter():
    # Same seed, same goal bias and range: RRT* draws the same samples and adds the same nodes
    # as RRT until the first solution, and it counts its iterations itself.
    s = load_scenario(TWO_CIRCLES)
    for seed in range(5):
        rrt = plan_scenario(s, planner="ompl:RRT:range=10", seed=seed)
        star = plan_scenario(s, planner="ompl:RRTstar:range=10", seed=seed)
        assert rrt.params["iterations_source"] == "termination-condition evaluations"
        assert star.params["iterations_source"] == "numIterations"
        assert rrt.iterations == star.iterations and rrt.nodes == star.nodes


def test_the_iteration_budget_ends_a_run_as_a_failure():
    s = load_scenario(TWO_CIRCLES)
    r = plan_scenario(s, planner="ompl:RRT", seed=0, max_iter=5)
    assert not r.success and r.iterations == 5 and r.cost_deg is None
    assert r.path_deg.shape == (0, 2) and r.params["stopped_by"] == "max_iter"


def test_settings_are_ours_and_recorded(untuned):
    s = load_scenario(TWO_CIRCLES)
    r = plan_scenario(s, planner="ompl:RRT", seed=1)
    p = r.params
    assert p["range_deg"] == DEFAULT_RANGE_DEG == 10.0 and p["range_source"] == "default"
    assert p["goal_bias"] == 0.05 and p["margin_m"] == CERT_MARGIN_M
    assert p["motion_validator"] == "certified" and p["validity_resolution_deg"] is None
    assert p["motions_checked"] > 0 and p["state_checks"] > 0
    sampled = plan_scenario(s, planner="ompl:RRT:sampled", seed=1).params
    assert sampled["motion_validator"] == "sampled"
    assert sampled["validity_resolution_deg"] == pytest.approx(0.01 * np.hypot(360.0, 360.0))
    bit = plan_scenario(s, planner="ompl:BITstar", seed=1).params
    assert bit["range_deg"] is None and bit["goal_bias"] is None  # BIT* has neither
    assert bit["range_source"] is None
    json.dumps(r.to_json_dict())  # plain types only


def test_the_range_comes_from_the_label_else_the_tuned_file_else_ten_degrees(monkeypatch):
    import xfuzzy_rrt.planners.tuned as tuned

    asked = []

    def fake(label):  # every shipped shape's tuned parameters (planners/tuned.py)
        asked.append(label)
        return {(1, 2): {"range_deg": 42.0}} if label == "ompl:RRTConnect" else {}

    monkeypatch.setattr(tuned, "tuned_by_shape", fake)
    s = load_scenario(TWO_CIRCLES)
    cases = {"ompl:RRTConnect": (42.0, "tuned"), "ompl:RRTConnect:sampled": (42.0, "tuned"),
             "ompl:RRTConnect:range=60": (60.0, "label"),
             "ompl:RRTConnect:sampled:range=60": (60.0, "label"),
             "ompl:RRTConnect:range=7.5:sampled": (7.5, "label"),
             "ompl:RRT": (10.0, "default")}
    for label, (range_deg, source) in cases.items():
        r = plan_scenario(s, planner=label, seed=3)
        assert (r.params["range_deg"], r.params["range_source"]) == (range_deg, source), label
        assert r.planner == label
        assert r.params["motion_validator"] == ("sampled" if ":sampled" in label else
                                                "certified")
    assert "ompl:RRTConnect" in asked and not any(":" in a[len("ompl:"):] for a in asked)
    # The label's range is the range OMPL used: same run as the explicit argument.
    by_label = plan_scenario(s, planner="ompl:RRTConnect:range=60", seed=3)
    by_argument = plan_ompl(s, "ompl:RRTConnect", seed=3, step_deg=60.0)
    assert by_argument.params["range_source"] == "argument"
    assert np.array_equal(by_label.path_deg, by_argument.path_deg)


def test_label_options_parse_in_any_order():
    assert parse_ompl_label("ompl:RRTConnect").sampled is False
    spec = parse_ompl_label("ompl:RRTConnect:sampled:range=60")
    assert (spec.name, spec.sampled, spec.range_deg, spec.base) == (
        "RRTConnect", True, 60.0, "ompl:RRTConnect")
    other = parse_ompl_label("ompl:RRTConnect:range=60:sampled")
    assert (other.name, other.sampled, other.range_deg) == ("RRTConnect", True, 60.0)
    assert parse_ompl_label("RRT:range=1e3").range_deg == 1000.0
    assert check_planner("ompl:BITstar:sampled") == "ompl:BITstar:sampled"


def test_a_planner_that_needs_the_last_valid_state_runs_only_sampled(monkeypatch):
    # PDST reads the last valid state of a refused motion, which a Python motion validator
    # cannot write: certified by construction is impossible, so only ':sampled' is accepted.
    # (The 2.0.1 wheel does not expose PDST; a wheel that does must not run it certified.)
    import xfuzzy_rrt.planners.ompl_bridge as bridge

    names = bridge.ompl_planner_names()
    monkeypatch.setattr(bridge, "ompl_planner_names", lambda where="--planners": names + ("PDST",))
    with pytest.raises(InputError, match=r"'PDST' cannot run with the certified motion check: "
                                         r".*use ompl:PDST:sampled"):
        parse_ompl_label("ompl:PDST")
    assert parse_ompl_label("ompl:PDST:sampled").sampled


@pytest.mark.parametrize("label, message", [
    ("ompl:RRTConnect:fast", r"unknown option 'fast' in 'ompl:RRTConnect:fast' \(options: "
                             r"sampled, range=DEG\)"),
    ("ompl:RRTConnect:", r"unknown option '' in"),
    ("ompl:RRTConnect:sampled=1", r"unknown option 'sampled=1'"),
    ("ompl:RRTConnect:range", r"range must be a positive number of degrees \(range=DEG\)"),
    ("ompl:RRTConnect:range=abc", r"range must be a positive number .* got 'abc'"),
    ("ompl:RRTConnect:range=-5", r"range must be a positive number .* got '-5'"),
    ("ompl:RRTConnect:range=0", r"got '0'"),
    ("ompl:RRTConnect:range=nan", r"got 'nan'"),
    ("ompl:RRTConnect:range=inf", r"got 'inf'"),
    ("ompl:RRTConnect:sampled:sampled", r"option 'sampled' given twice"),
    ("ompl:RRTConnect:range=5:range=6", r"option 'range' given twice"),
    ("ompl:BITstar:range=60", r"OMPL planner 'BITstar' has no range"),
    ("ompl:Nope:sampled", r"unknown OMPL planner 'Nope'"),
])
def test_bad_label_options_are_one_input_error_naming_the_option(label, message, capsys):
    with pytest.raises(InputError, match=message) as info:
        check_planner(label)
    assert info.value.where == "--planners"
    code = main(["plan", str(TWO_CIRCLES), "--planner", label])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert err.startswith("error: --planner: ") and err.count("\n") == 1, err


def test_the_validity_callback_is_our_checker():
    from ompl import base as ob

    a = load_scenario(FIXTURES / "scenarios" / "boxes-and-circle.toml").arrays()
    callback = make_validity_callback(a)
    space = ob.RealVectorStateSpace(2)
    state = space.allocState()
    rng = np.random.default_rng(5)
    qs = rng.uniform(-185.0, 185.0, size=(2000, 2))  # some outside the joint limits too
    ours = []
    for q in qs:
        state[0], state[1] = float(q[0]), float(q[1])
        ours.append(bool(callback(state)))
    expected = [bool(config_free(a.links, a.base, a.link_radius, a.obstacles, a.limits_deg, q,
                                 CERT_MARGIN_M)) for q in qs]
    assert ours == expected and 0 < sum(ours) < len(ours)


def test_unknown_and_unsupported_ompl_planners_are_one_clear_input_error():
    s = load_scenario(TWO_CIRCLES)
    with pytest.raises(InputError, match=r"unknown OMPL planner 'Nope' \(known: .*RRTConnect"):
        plan_scenario(s, planner="ompl:Nope")
    with pytest.raises(InputError, match="PRM' is not supported: .*thread") as info:
        check_planner("ompl:PRM")
    assert info.value.where == "--planners"
    assert is_known_planner("ompl:RRT") and not is_known_planner("ompl:")
    assert PLANNERS == ("rrt", "fuzzy-rrt", "fuzzy-rrt-connect")


def test_without_the_extra_ompl_planners_name_the_extra(monkeypatch, capsys):
    monkeypatch.setitem(sys.modules, "ompl", None)  # `import ompl` now raises ImportError
    s = load_scenario(TWO_CIRCLES)
    with pytest.raises(InputError) as info:
        plan_scenario(s, planner="ompl:RRT")
    assert (info.value.where, info.value.message) == ("--planner", MISSING_EXTRA)
    code = main(["plan", str(TWO_CIRCLES), "--planner", "ompl:RRT"])
    out, err = capsys.readouterr()
    assert code == 2 and out == ""
    assert err == f"error: --planner: {MISSING_EXTRA}\n"
    code = main(["bench", str(TWO_CIRCLES), "--planners", "rrt,ompl:RRT", "--runs", "1"])
    assert code == 2 and capsys.readouterr().err == f"error: --planners: {MISSING_EXTRA}\n"


def test_without_the_extra_the_console_script_prints_one_error_line(tmp_path, monkeypatch):
    # A module named 'ompl' that fails to import shadows the installed wheel.
    (tmp_path / "ompl.py").write_text("raise ImportError('simulated: the ompl extra is missing')\n")
    monkeypatch.setenv("PYTHONPATH", str(tmp_path))
    import subprocess

    from conftest import console_script

    proc = subprocess.run([console_script(), "plan", str(TWO_CIRCLES), "--planner", "ompl:RRT"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr == f"error: --planner: {MISSING_EXTRA}\n"


def test_cli_plan_with_an_ompl_planner_repeats_across_processes(run_cli):
    # Seed 4 grazes an obstacle with OMPL's sampled check: the same uncertified path, exit code
    # and message each time.
    runs = []
    for _ in range(2):
        proc = run_cli("plan", TWO_CIRCLES, "--planner", "ompl:RRTConnect:sampled:range=10",
                       "--seed", "4")
        assert proc.returncode == 1, proc.stderr
        assert proc.stderr == (f"not certified: {TWO_CIRCLES}: ompl:RRTConnect:sampled:range=10 seed 4: "
                               "segment "
                               "38 penetrates an obstacle 0.03163 mm deep at q = (129.994, "
                               "-96.6681) deg\n")
        data = json.loads(proc.stdout)
        assert (data["found"], data["certified"], data["success"]) == (True, False, False)
        assert data["min_clearance_m"] == pytest.approx(-3.163e-5, abs=1e-8)
        data.pop("wall_s")
        runs.append(data)
    assert runs[0] == runs[1]
    assert runs[0]["planner"] == "ompl:RRTConnect:sampled:range=10"
    assert runs[0]["params"]["ompl_seed"] == 5
    assert runs[0]["path_deg"][0] == [-120.0, 30.0] and runs[0]["path_deg"][-1] == [150.0, -60.0]
    # The same seed through the certified check: a certified path, exit 0, twice the same.
    certified = []
    for _ in range(2):
        proc = run_cli("plan", TWO_CIRCLES, "--planner", "ompl:RRTConnect", "--seed", "4")
        assert proc.returncode == 0 and proc.stderr == "", proc.stderr
        data = json.loads(proc.stdout)
        assert data["success"] is True and data["params"]["motion_validator"] == "certified"
        data.pop("wall_s")
        certified.append(data)
    assert certified[0] == certified[1]


def test_a_pytest_run_that_plans_with_bitstar_ends_without_nanobind_leak_lines():
    # BIT*'s getPlannerData keeps its graph (and our SpaceInformation) alive in the ompl 2.0.1
    # wheel; nanobind would list ~36 "leaked" objects when the interpreter exits. conftest.py
    # leaves before that teardown, keeping pytest's exit status.
    import subprocess

    test = f"{__file__}::test_settings_are_ours_and_recorded"  # plans with BIT*
    proc = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider", test],
                          capture_output=True, text=True, timeout=300, cwd=PROJECT)
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "1 passed" in proc.stdout
    assert "leaked" not in proc.stdout + proc.stderr
    failing = subprocess.run([sys.executable, "-m", "pytest", "-q", "-p", "no:cacheprovider",
                              test, "-k", "no_such_test"], capture_output=True, text=True,
                             timeout=300, cwd=PROJECT)
    assert failing.returncode == 5  # "no tests collected": the real exit status survives


def test_the_compiled_checks_are_ready_at_import_not_compiled_inside_a_timed_solve():
    # Compiling inside OMPL's solve() would spend the first plan's wall-clock cap on numba.
    import subprocess

    code = ("import os, xfuzzy_rrt.planners.ompl_bridge as b; "
            "print(len(b.state_free_at.overloads), len(b.motion_free_at.overloads), "
            "len(b.motion_free_logged_at.overloads), flush=True); "
            "os._exit(0)")
    proc = subprocess.run([sys.executable, "-c", code], capture_output=True, text=True,
                          timeout=600, cwd=PROJECT)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.split() == ["1", "1", "1"]


def test_an_ompl_range_read_once_plans_exactly_as_the_label_alone_and_is_not_read_again(
        monkeypatch):
    import xfuzzy_rrt.planners.tuned as tuned
    from xfuzzy_rrt.planners.api import preloaded
    from xfuzzy_rrt.planners.ompl_bridge import TunedRange

    s = load_scenario(TWO_CIRCLES)
    given = preloaded("ompl:RRTConnect", None)
    assert isinstance(given, TunedRange) and given.base == "ompl:RRTConnect"
    alone = [plan_scenario(s, "ompl:RRTConnect", seed=k, max_iter=2000) for k in range(3)]
    monkeypatch.setattr(tuned, "tuned_by_shape", lambda label: pytest.fail("tuned file read"))
    for k, ref in enumerate(alone):
        r = plan_scenario(s, "ompl:RRTConnect", rulebook=given, seed=k, max_iter=2000)
        assert (r.params["range_deg"], r.params["range_source"]) == \
            (ref.params["range_deg"], ref.params["range_source"])
        assert r.iterations == ref.iterations and np.array_equal(r.path_deg, ref.path_deg)
    # the label's own range wins and needs nothing read; another planner's range is not used
    assert preloaded("ompl:RRTConnect:range=30", None) is None
    r = plan_scenario(s, "ompl:RRTConnect:range=30", rulebook=given, seed=0, max_iter=500)
    assert (r.params["range_deg"], r.params["range_source"]) == (30.0, "label")
    monkeypatch.undo()
    other = TunedRange("ompl:RRT", 1.0, "tuned")
    r = plan_scenario(s, "ompl:RRTConnect", rulebook=other, seed=0, max_iter=500)
    assert r.params["range_deg"] == alone[0].params["range_deg"]


def test_the_protocol_reads_each_ompl_peers_tuned_range_once(monkeypatch):
    import xfuzzy_rrt.planners.tuned as tuned
    from xfuzzy_rrt.bench.protocol import run_protocol

    reads = []
    real = tuned.tuned_by_shape
    monkeypatch.setattr(tuned, "tuned_by_shape", lambda label: reads.append(label) or real(label))
    s = load_scenario(TWO_CIRCLES)
    result = run_protocol([s], [("ompl:RRTConnect", "ompl:RRTConnect", None)], runs=3,
                          max_iter=500)
    assert len(result.runs[result.runs["planner"] == "ompl:RRTConnect"]) == 3
    assert reads.count("ompl:RRTConnect") == 1


def test_a_parsed_ompl_label_still_names_the_missing_extra_under_the_callers_option(
        monkeypatch):
    parse_ompl_label("ompl:RRT")  # parsed (and kept) while OMPL imports
    monkeypatch.setitem(sys.modules, "ompl", None)
    with pytest.raises(InputError) as info:
        parse_ompl_label("ompl:RRT", "--peer")
    assert (info.value.where, info.value.message) == ("--peer", MISSING_EXTRA)


def test_a_path_segment_counts_as_certified_only_if_it_is_an_accepted_motion_bit_for_bit():
    from xfuzzy_rrt.planners.ompl_bridge import segments_logged

    log = np.zeros((4, 2, 3))
    log[0] = [[0.0, 0.0, 0.0], [10.0, 5.0, 1.0]]
    log[1] = [[20.0, 5.0, 1.0], [10.0, 5.0, 1.0]]  # accepted the other way round
    path = np.array([[0.0, 0.0, 0.0], [10.0, 5.0, 1.0], [20.0, 5.0, 1.0]])
    assert segments_logged(path, log, 2)
    assert not segments_logged(path, log, 1)  # only the motions logged so far count
    nudged = path.copy()
    nudged[2, 2] = np.nextafter(1.0, 2.0)
    assert not segments_logged(nudged, log, 2)


def test_the_certified_validator_logs_accepted_motions_only_and_stops_when_full():
    ob = pytest.importorskip("ompl.base")
    a = load_scenario(TWO_CIRCLES).arrays()
    space = ob.RealVectorStateSpace(2)
    bounds = ob.RealVectorBounds(2)
    for j in range(2):
        bounds.setLow(j, float(a.limits_deg[j, 0]))
        bounds.setHigh(j, float(a.limits_deg[j, 1]))
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(make_validity_callback(a))
    validator = certified_motion_validator(si, space, a)
    validator.log_meta[1] = 3  # room for three
    si.setMotionValidator(validator)
    si.setup()
    s1, s2 = space.allocState(), space.allocState()
    rng = np.random.default_rng(5)
    accepted = []
    for _ in range(200):
        qa, qb = rng.uniform(-180.0, 180.0, size=(2, 2))
        for j in range(2):
            s1[j], s2[j] = float(qa[j]), float(qb[j])
        if si.checkMotion(s1, s2):
            accepted.append((qa, qb))
    assert len(accepted) > 3 and len(accepted) < 200
    assert validator.log_meta[0] == 3
    for k in range(3):
        assert np.array_equal(validator.log[k, 0], accepted[k][0])
        assert np.array_equal(validator.log[k, 1], accepted[k][1])
    assert validator.certified(np.array(accepted[1]))
    assert not validator.certified(np.array(accepted[3]))  # accepted, but not logged


def test_ompl_paths_of_logged_motions_skip_the_second_certification_others_get_it(
        monkeypatch):
    import xfuzzy_rrt.planners.ompl_bridge as bridge
    import xfuzzy_rrt.geometry.path_check as path_check

    s = load_scenario(TWO_CIRCLES)
    calls = []
    real = path_check.segments_certified
    monkeypatch.setattr(path_check, "segments_certified",
                        lambda *args: calls.append(1) or real(*args))
    r = plan_scenario(s, "ompl:RRTConnect", seed=1)
    assert r.success and r.params["path_check"] == "motions certified in planning"
    assert calls == [] and r.certify_work == 0
    sampled = plan_scenario(s, "ompl:RRTConnect:sampled", seed=1)
    assert sampled.params["path_check"] == "certified after planning" and calls == [1]
    monkeypatch.setattr(bridge, "MOTION_LOG", 0)  # nothing logged: the path is certified after
    again = plan_scenario(s, "ompl:RRTConnect", seed=1)
    assert again.params["path_check"] == "certified after planning" and calls == [1, 1]
    assert again.success and np.array_equal(again.path_deg, r.path_deg)
    assert again.certify_work > 0
