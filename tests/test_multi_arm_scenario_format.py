"""The ``[[arms]]`` extension of the scenario format (docs/scenarios.md): several arms, each with
its own base, links, radius, limits, start and goal; every old file loads as before.

Bad input is one ``ScenarioError`` line naming the file and the key (``arms[1].links``), or the
file and line for an unknown key, and ``plan`` turns it into one ``error:`` line, exit 2.
"""

from __future__ import annotations

import dataclasses
import tomllib

import pytest

from conftest import FIXTURES, shared_scenarios
from xfuzzy_rrt.errors import ScenarioError
from xfuzzy_rrt.geometry.scenario import load_scenario, scenario_from_dict
from xfuzzy_rrt.scenarios.writer import scenario_toml

ARMS = FIXTURES / "arms"
OLD = sorted((FIXTURES / "scenarios").glob("*.toml")) + shared_scenarios()


def test_a_dual_arm_file_loads_with_each_arm_its_own_angles():
    s = load_scenario(ARMS / "dual-2dof.toml")
    assert len(s.arms) == 2 and s.more_arms == (s.arms[1],)
    assert s.arm_names == ("left", "right")
    assert s.arms[0].base == (-0.15, 0.0) and s.arms[1].base == (0.15, 0.0)
    assert s.arms[1].joint_limits_deg == ((-170.0, 170.0), (-150.0, 150.0))
    assert s.arms[0].joint_limits_deg == ((-180.0, 180.0), (-180.0, 180.0))  # the default
    assert s.dof == 4 and s.start_deg == (120.0, 0.0, 60.0, 0.0)
    assert s.goal_deg == (60.0, 0.0, 120.0, 0.0)
    assert [s.start_deg[sl] for sl in s.arm_slices()] == [(120.0, 0.0), (60.0, 0.0)]
    a = s.arrays()
    assert a.n_arms == 2 and list(a.arm_first) == [0, 2, 4]


def test_unnamed_arms_and_safety_and_three_links_each():
    s = load_scenario(ARMS / "dual-3dof.toml")
    assert s.arm_names == () and s.dof == 6 and s.clearance_m == 0.002
    assert [a.dof for a in s.arms] == [3, 3]


@pytest.mark.parametrize("path", OLD, ids=lambda p: p.stem)
def test_every_old_file_still_means_one_arm_with_top_level_start_and_goal(path):
    s = load_scenario(path)
    raw = tomllib.loads(path.read_text())
    assert s.arms == (s.arm,) and s.more_arms == () and s.arm_names == ()
    assert s.start_deg == tuple(float(v) for v in raw["start"]["q_deg"])
    assert s.goal_deg == tuple(float(v) for v in raw["goal"]["q_deg"])
    assert s.arm.links == tuple(float(v) for v in raw["arm"]["links"])
    assert s.dof == s.arm.dof == len(s.start_deg)


@pytest.mark.parametrize("path", OLD, ids=lambda p: p.stem)
def test_a_single_arms_entry_is_the_same_problem_as_arm(path):
    old = load_scenario(path)
    raw = tomllib.loads(path.read_text())
    arm = dict(raw.pop("arm"))
    arm["start_deg"] = raw.pop("start")["q_deg"]
    arm["goal_deg"] = raw.pop("goal")["q_deg"]
    raw["arms"] = [arm]
    new = scenario_from_dict(raw, str(path))
    assert new == old


@pytest.mark.parametrize("path", OLD + sorted(ARMS.glob("*.toml")), ids=lambda p: p.stem)
def test_written_text_loads_back_equal_and_uses_the_right_form(path):
    s = load_scenario(path)
    text = scenario_toml(s, s.description)
    assert ("[[arms]]" in text) == (len(s.arms) > 1)
    assert ("[arm]" in text) == (len(s.arms) == 1)
    assert scenario_from_dict(tomllib.loads(text), s.source) == s


def test_a_single_arm_is_written_exactly_as_the_format_writes_it():
    s = load_scenario(FIXTURES / "scenarios" / "two-circles.toml")
    assert scenario_toml(s, "d") == (
        'name = "two-circles"\ndescription = "d"\n\n[arm]\nlinks = [0.2, 0.1]\n'
        'link_radius = 0.004\n\n[start]\nq_deg = [-120.0, 30.0]\n\n[goal]\n'
        'q_deg = [150.0, -60.0]\n\n[[obstacles]]\ntype = "circle"\ncenter = [0.26, 0.0]\n'
        'radius = 0.04\n\n[[obstacles]]\ntype = "circle"\ncenter = [-0.06, 0.26]\n'
        'radius = 0.05\n')


# ------------------------------------------------------------------------------ bad input

def _dual(tmp_path, old: str, new: str, count: int = 1):
    text = (ARMS / "dual-2dof.toml").read_text()
    assert old in text, old
    p = tmp_path / "bad.toml"
    p.write_text(text.replace(old, new, count))
    return p


_LEFT = ('links = [0.12, 0.1]\nbase = [-0.15, 0.0]\nlink_radius = 0.005\n'
         'start_deg = [120.0, 0.0]\ngoal_deg = [60.0, 0.0]\n')
_ARM_FORM = "[arm]\nlinks = [0.12, 0.1]\n[start]\nq_deg = [0.0, 0.0]\n[goal]\nq_deg = [1.0, 0.0]\n"

# (replace this, by this) -> the text the one-line error must hold
BAD = [
    ("[[arms]]\nname = \"left\"", _ARM_FORM + "[[arms]]\nname = \"left\"",
     "arms: a file has either [arm] (with [start] and [goal]) or [[arms]], not both"),
    ("[[arms]]\nname = \"left\"", "[start]\nq_deg = [0.0, 0.0]\n[[arms]]\nname = \"left\"",
     "start: [start] is not used with [[arms]]: each arm carries its own start_deg and goal_deg"),
    ("[[obstacles]]", "[goal]\nq_deg = [0.0, 0.0]\n[[obstacles]]",
     "goal: [goal] is not used with [[arms]]: each arm carries its own start_deg and goal_deg"),
    ("links = [0.12, 0.1]\nbase = [0.15", "links = \"long\"\nbase = [0.15",
     ": arms[1].links: must be an array of numbers, got a string"),
    ("links = [0.12, 0.1]\nbase = [0.15", "links = [0.12, -0.1]\nbase = [0.15",
     ": arms[1].links[1]: link length must be > 0"),
    ("start_deg = [60.0, 0.0]", "start_deg = [60.0, 0.0, 5.0]",
     ": arms[1].start_deg: must have one angle per link (2), got 3"),
    ("goal_deg = [120.0, 0.0]\n", "",
     ": arms[1].goal_deg: missing required key"),
    ("base = [0.15, 0.0]", "base = [0.15]", ": arms[1].base: must have 2 numbers, got 1"),
    ("link_radius = 0.005\njoint", "link_radius = -0.005\njoint",
     ": arms[1].link_radius: must be >= 0"),
    ("[[-170.0, 170.0], [-150.0, 150.0]]", "[[-170.0, 170.0]]",
     ": arms[1].joint_limits_deg: must have one [min, max] pair per link (2), got 1"),
    ("goal_deg = [120.0, 0.0]", "goal_deg = [175.0, 0.0]",
     ": arms[1].goal_deg[0]: 175 deg is outside the joint limits [-170, 170]"),
    ("start_deg = [120.0, 0.0]", "start_deg = [-45.0, 0.0]",  # into the box below the bases
     ": arms[0].start_deg: configuration [-45.0, 0.0] is in collision"),
    ('name = "right"', 'name = "left"', ": arms[1].name: 'left' names two arms"),
    ('name = "right"', "name = 3", ": arms[1].name: must be a non-empty string"),
]


@pytest.mark.parametrize("old,new,expected", BAD, ids=[c[2].strip(": ")[:40] for c in BAD])
def test_bad_arms_input_is_one_line_naming_the_key(tmp_path, old, new, expected):
    p = _dual(tmp_path, old, new)
    with pytest.raises(ScenarioError) as info:
        load_scenario(p)
    message = str(info.value)
    assert message.startswith(str(p)) and "\n" not in message
    assert expected in message, message


def test_mixing_the_forms_names_the_line_of_the_arms_table(tmp_path):
    p = _dual(tmp_path, "[[arms]]\nname = \"left\"", _ARM_FORM + "[[arms]]\nname = \"left\"")
    with pytest.raises(ScenarioError) as info:
        load_scenario(p)
    assert str(info.value).startswith(f"{p}:10: arms: ")


def test_unknown_key_in_an_arm_gives_its_line_and_the_nearest_name(tmp_path):
    p = _dual(tmp_path, "start_deg = [60.0, 0.0]", "start_dge = [60.0, 0.0]")
    with pytest.raises(ScenarioError) as info:
        load_scenario(p)
    assert str(info.value) == (f"{p}:18: unknown key 'start_dge' in [[arms]] #2 "
                               "(did you mean 'start_deg'?)")


def test_a_typo_in_the_arms_header_is_caught(tmp_path):
    p = _dual(tmp_path, "[[arms]]", "[[armz]]", 2)
    with pytest.raises(ScenarioError) as info:
        load_scenario(p)
    assert "unknown key 'armz'" in str(info.value) and str(info.value).startswith(f"{p}:4:")


def test_more_than_four_arms_or_seven_links_is_refused(tmp_path):
    base = 'name = "many"\n'
    arms = "".join(f"[[arms]]\nlinks = [0.1, 0.1]\nbase = [{i}.0, 0.0]\nstart_deg = [0.0, 0.0]\n"
                   "goal_deg = [0.0, 0.0]\n" for i in range(5))
    p = tmp_path / "many.toml"
    p.write_text(base + arms)
    with pytest.raises(ScenarioError, match=r": arms: at most 4 arms are supported, got 5"):
        load_scenario(p)
    p.write_text(base + "[[arms]]\nlinks = [0.01, 0.01, 0.01, 0.01, 0.01, 0.01, 0.01, 0.01]\n"
                 "start_deg = [0, 0, 0, 0, 0, 0, 0, 0]\ngoal_deg = [0, 0, 0, 0, 0, 0, 0, 0]\n")
    with pytest.raises(ScenarioError, match=r": arms\[0\].links: at most 7 links per arm are "
                                            r"supported, got 8"):
        load_scenario(p)


@pytest.mark.parametrize("text,expected", [
    ('name = "x"\narms = []\n', "arms: must list at least one arm"),
    ('name = "x"\n[arms]\nlinks = [0.1]\n', "arms: must be an array of tables ([[arms]]), got a table"),
])
def test_an_empty_or_misshapen_arms_value_is_one_line(tmp_path, text, expected):
    p = tmp_path / "x.toml"
    p.write_text(text)
    with pytest.raises(ScenarioError) as info:
        load_scenario(p)
    assert expected in str(info.value)


def test_arms_that_touch_each_other_at_start_are_refused(tmp_path):
    """Each arm alone is clear of the obstacles; together they overlap (both lie along y = 0).

    Needs the arm-arm contact of ``clearance`` (the core branch); fails before it lands."""
    p = _dual(tmp_path, "start_deg = [120.0, 0.0]", "start_deg = [0.0, 0.0]")
    p.write_text(p.read_text().replace("start_deg = [60.0, 0.0]", "start_deg = [180.0, 0.0]")
                 .replace("[[-170.0, 170.0], [-150.0, 150.0]]", "[[-180.0, 180.0], [-180.0, 180.0]]"))
    with pytest.raises(ScenarioError) as info:
        load_scenario(p)
    assert ": arms.start_deg: the arms touch or overlap each other at start" in str(info.value)


def test_plan_turns_a_bad_arms_file_into_one_error_line_exit_2(run_cli, tmp_path):
    p = _dual(tmp_path, "start_deg = [60.0, 0.0]", "start_deg = [60.0]")
    out = tmp_path / "result.json"
    proc = run_cli("plan", p, "--planner", "rrt", "--out", out)
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [
        f"error: {p}: arms[1].start_deg: must have one angle per link (2), got 1"]
    assert not out.exists()


def test_the_model_fields_stay_as_they_are():
    s = load_scenario(ARMS / "dual-2dof.toml")
    fields = [f.name for f in dataclasses.fields(s)]
    assert fields[:2] == ["name", "arm"] and "more_arms" in fields and "arm_names" in fields
