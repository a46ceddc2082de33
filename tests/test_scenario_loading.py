"""Scenarios load into validated models; malformed files fail with one clear line, exit 2."""

from __future__ import annotations

import pytest

from conftest import FIXTURES, shared_scenarios
from xfuzzy_rrt.errors import ScenarioError
from xfuzzy_rrt.geometry.scenario import Box, Circle, load_scenario

OWN = sorted((FIXTURES / "scenarios").glob("*.toml"))
BAD = FIXTURES / "bad-scenarios"


@pytest.mark.parametrize("path", OWN + shared_scenarios(), ids=lambda p: p.stem)
def test_every_scenario_file_loads(path):
    s = load_scenario(path)
    assert s.arm.dof == len(s.start_deg) == len(s.goal_deg) == 2
    assert all(isinstance(o, (Circle, Box)) for o in s.obstacles)


def test_defaults_fill_base_radius_and_joint_limits():
    s = load_scenario(FIXTURES / "scenarios" / "empty.toml")
    assert s.arm.base == (0.0, 0.0)
    assert s.arm.link_radius == 0.0
    assert s.arm.joint_limits_deg == ((-180.0, 180.0), (-180.0, 180.0))
    assert s.obstacles == ()


def test_model_is_frozen():
    s = load_scenario(FIXTURES / "scenarios" / "two-circles.toml")
    with pytest.raises(AttributeError):
        s.name = "other"  # type: ignore[misc]


def _with(tmp_path, old: str, new: str, source: str = "two-circles.toml"):
    text = (FIXTURES / "scenarios" / source).read_text()
    assert old in text
    p = tmp_path / "typo.toml"
    p.write_text(text.replace(old, new, 1))
    return p


# (replace this, by this) -> the line and the message the error must give
UNKNOWN_KEY_CASES = [
    # the case: a typo in an array-of-tables header used to delete every obstacle
    ("[[obstacles]]", "[[obstacle]]", 10,
     "unknown key 'obstacle' (did you mean '[[obstacles]]'?)"),
    ("links = [0.2, 0.1]", "linkz = [0.2, 0.1]", 4,
     "unknown key 'linkz' in [arm] (did you mean 'links'?)"),
    ("radius = 0.05", "raduis = 0.05", 17, "unknown key 'raduis' in [[obstacles]] #2"),
    ("[goal]", "[gaol]", 8, "unknown key 'gaol' (did you mean '[goal]'?)"),
    ("[arm]", "seed = 3\n[arm]", 3, "unknown key 'seed' (known: name, description, [arm]"),
    ("[start]", "[safety]\nclearance = 0.002\n[start]", 7,
     "unknown key 'clearance' in [safety] (did you mean 'clearance_m'?)"),
]


@pytest.mark.parametrize("old,new,line,message", UNKNOWN_KEY_CASES,
                         ids=[c[1].split("\n")[0] for c in UNKNOWN_KEY_CASES])
def test_unknown_key_is_an_error_with_line_and_nearest_name(tmp_path, old, new, line, message):
    p = _with(tmp_path, old, new)
    with pytest.raises(ScenarioError) as info:
        load_scenario(p)
    assert str(info.value).startswith(f"{p}:{line}: "), str(info.value)
    assert message in str(info.value)


def test_unknown_table_fails_plan_with_one_line_exit_2(run_cli, tmp_path):
    p = _with(tmp_path, "[[obstacles]]", "[[obstacle]]")
    out = tmp_path / "result.json"
    proc = run_cli("plan", p, "--planner", "rrt", "--out", out)
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [
        f"error: {p}:10: unknown key 'obstacle' (did you mean '[[obstacles]]'?)"]
    assert not out.exists()


def test_an_explicit_empty_obstacle_list_is_accepted(tmp_path):
    text = (FIXTURES / "scenarios" / "empty.toml").read_text()
    p = tmp_path / "explicit.toml"
    p.write_text("obstacles = []\n" + text)
    assert load_scenario(p).obstacles == ()


def test_safety_clearance_is_validated_and_defaults_to_zero(tmp_path):
    assert load_scenario(FIXTURES / "scenarios" / "two-circles.toml").clearance_m == 0.0
    ok = _with(tmp_path, "[start]", "[safety]\nclearance_m = 0.003\n[start]")
    assert load_scenario(ok).clearance_m == 0.003
    for bad, expected in (("-0.001", "must be >= 0"), ('"3 mm"', "must be a number")):
        p = _with(tmp_path, "[start]", f"[safety]\nclearance_m = {bad}\n[start]")
        with pytest.raises(ScenarioError, match=f"safety.clearance_m: {expected}"):
            load_scenario(p)


# (fixture file, the key or location the one-line error must name)
BAD_CASES = [
    ("missing-goal.toml", ": goal: missing required table"),
    ("links-wrong-type.toml", ": arm.links: must be an array of numbers"),
    ("negative-radius.toml", ": obstacles[0].radius: must be > 0"),
    ("box-max-not-above-min.toml", ": obstacles[0].max: must exceed min"),
    ("start-in-collision.toml", ": start.q_deg: configuration"),
    ("goal-outside-limits.toml", ": goal.q_deg[0]: 190 deg is outside the joint limits"),
    ("toml-syntax-error.toml", ":7: TOML syntax error"),
    ("unknown-obstacle-type.toml", ": obstacles[0].type: unknown obstacle type 'triangle'"),
    ("wrong-number-of-angles.toml", ": start.q_deg: must have one angle per link (2), got 3"),
    ("not-utf8.toml", ": not valid UTF-8"),
    ("circle-missing-center.toml", ": obstacles[0].center: missing required key"),
]


@pytest.mark.parametrize("name,expected", BAD_CASES, ids=[c[0] for c in BAD_CASES])
def test_bad_scenario_is_rejected_by_the_library(name, expected):
    with pytest.raises(ScenarioError) as info:
        load_scenario(BAD / name)
    assert expected in str(info.value)


@pytest.mark.parametrize("name,expected", BAD_CASES, ids=[c[0] for c in BAD_CASES])
def test_bad_scenario_gives_one_error_line_exit_2_and_no_output(run_cli, tmp_path, name, expected):
    out = tmp_path / "result.json"
    proc = run_cli("plan", BAD / name, "--planner", "rrt", "--out", out)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert lines[0].startswith(f"error: {BAD / name}")
    assert expected in lines[0]
    assert "Traceback" not in proc.stderr
    assert not out.exists()
    assert list(tmp_path.iterdir()) == []


def test_missing_scenario_file_is_one_line(run_cli, tmp_path):
    proc = run_cli("plan", tmp_path / "nope.toml", "--planner", "rrt")
    assert proc.returncode == 2
    assert proc.stderr.strip() == f"error: {tmp_path / 'nope.toml'}: no such file"


@pytest.mark.parametrize("args,fragment", [
    (["--planner", "astar"], "--planner"),
    (["--seed", "abc"], "--seed"),
    (["--max-iter", "0"], "--max-iter"),
    (["--max-iter", "10000000000000"], "--max-iter"),
    (["--rulebook", "."], "not a rulebook directory"),
    (["--trace", "t.txt", "--planner", "fuzzy-rrt"], "t.txt"),
])
def test_bad_cli_arguments_give_one_line_exit_2(run_cli, tmp_path, args, fragment):
    scenario = FIXTURES / "scenarios" / "two-circles.toml"
    proc = run_cli("plan", scenario, *args, cwd=tmp_path)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and fragment in lines[0], proc.stderr
    assert "Traceback" not in proc.stderr
    assert list(tmp_path.iterdir()) == []
