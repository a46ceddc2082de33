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


def test_unknown_keys_are_recorded_not_fatal(tmp_path):
    text = (FIXTURES / "scenarios" / "empty.toml").read_text().replace(
        "[arm]", "seed = 3\n[arm]\nlinkz = 1")
    p = tmp_path / "typo.toml"
    p.write_text(text)
    assert set(load_scenario(p).unknown_keys) == {"seed", "arm.linkz"}


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
