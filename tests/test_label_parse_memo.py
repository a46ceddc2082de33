"""A planner label with an argument is parsed once per process (planners/api.py), yet a
rulebook folder that goes away still fails with one clear error, and a shipped name follows
$XFUZZY_RRT_RULEBOOKS."""

import shutil
from pathlib import Path

import pytest

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.rulebook import RULEBOOKS_ENV, rulebooks_dir
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.api import parse_planner, plan_scenario

DEMO = Path(__file__).resolve().parents[1] / "xfuzzy_rrt" / "data" / "scenarios" / "demo-gap.toml"


def test_a_rulebook_folder_removed_after_its_label_was_parsed_fails_with_one_clear_error(
        tmp_path):
    folder = tmp_path / "gf"
    shutil.copytree(rulebooks_dir() / "goal-frame", folder)
    label = f"fuzzy-rrt:{folder}"
    scenario = load_scenario(DEMO)
    assert plan_scenario(scenario, label, seed=1, max_iter=200).planner == label
    assert parse_planner(label) is parse_planner(label)  # remembered
    shutil.rmtree(folder)
    with pytest.raises(InputError, match=str(folder)):
        plan_scenario(scenario, label, seed=1, max_iter=200)


def test_a_shipped_rulebook_name_follows_the_rulebooks_variable(tmp_path, monkeypatch):
    before = parse_planner("fuzzy-rrt:goal-frame").rulebook_dir
    shutil.copytree(rulebooks_dir() / "goal-frame", tmp_path / "goal-frame")
    monkeypatch.setenv(RULEBOOKS_ENV, str(tmp_path))
    assert parse_planner("fuzzy-rrt:goal-frame").rulebook_dir == tmp_path / "goal-frame"
    monkeypatch.delenv(RULEBOOKS_ENV)
    assert parse_planner("fuzzy-rrt:goal-frame").rulebook_dir == before


def test_an_unknown_rulebook_name_is_refused_every_time():
    for _ in range(2):
        with pytest.raises(InputError, match="unknown rulebook 'no-such-book'"):
            parse_planner("fuzzy-rrt:no-such-book")


def test_rrt_tuned_checks_its_file_on_every_call_though_its_label_is_parsed_once(
        tmp_path, monkeypatch):
    from xfuzzy_rrt.planners import tuned

    monkeypatch.setattr(tuned, "tuned_dir", lambda: tmp_path)
    f = tmp_path / "rrt.toml"
    f.write_text("[params]\nstep_deg = 60.0\ngoal_bias = 0.1\n")
    scenario = load_scenario(DEMO)
    first = plan_scenario(scenario, "rrt:tuned", seed=1, max_iter=300)
    assert first.params["step_deg"] == 60.0
    assert parse_planner("rrt:tuned") is parse_planner("rrt:tuned")  # one spec
    f.write_text("[params]\nstep_deg = 45.0\ngoal_bias = 0.1\n")  # seen at the next call
    assert plan_scenario(scenario, "rrt:tuned", seed=1, max_iter=300).params["step_deg"] == 45.0
    f.write_text("[params]\nstep_deg = 45.0\n")  # broken: refused, not the last good values
    with pytest.raises(InputError, match="needs the tuned file"):
        plan_scenario(scenario, "rrt:tuned", seed=1, max_iter=300)
    f.unlink()
    for _ in range(2):
        with pytest.raises(InputError, match="needs the tuned file"):
            parse_planner("rrt:tuned")


def test_a_plan_with_rrt_tuned_reads_its_tuned_file_once(monkeypatch):
    from xfuzzy_rrt.planners import api, tuned

    scenario = load_scenario(DEMO)
    plan_scenario(scenario, "rrt:tuned", seed=1, max_iter=300)  # the label accepted once
    calls = []
    real = tuned.tuned_record
    monkeypatch.setattr(api, "tuned_record",
                        lambda label, *a, **k: calls.append(label) or real(label, *a, **k))
    for seed in range(3):
        plan_scenario(scenario, "rrt:tuned", seed=seed, max_iter=300)
    assert calls == ["rrt"] * 3  # one look-up (one stat) a call, like the default's rulebook
    parse_planner("rrt:tuned")  # parsing alone still checks the file
    assert len(calls) == 4
