"""A caller that loads a rulebook once and plans with a label naming a folder
(``plan_scenario(s, "fuzzy-rrt:DIR", rulebook=rb)``, as ``bench`` does): a
rulebook read from that very folder is accepted without touching the file system, any other
must have the folder's content, and the record of where a rulebook was read from leaves with
the rulebook."""

import dataclasses
import gc
import shutil
from pathlib import Path

import pytest

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy import rulebook as rulebook_module
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, loaded_from, rulebooks_dir
from xfuzzy_rrt.geometry.scenario import load_scenario
# imported before any test patches the rulebook module (it binds load_rulebook_cached once)
from xfuzzy_rrt.planners import fuzzy_rrt  # noqa: F401
from xfuzzy_rrt.planners.api import plan_scenario

DEMO = Path(__file__).resolve().parents[1] / "xfuzzy_rrt" / "data" / "scenarios" / "demo-gap.toml"


def _copy(tmp_path: Path, name: str) -> Path:
    folder = tmp_path / name
    shutil.copytree(rulebooks_dir() / "goal-frame", folder)
    return folder


def _edit_one_rule(folder: Path) -> None:
    fis = folder / "step_deg.fis"
    text = fis.read_text()
    line = next(x for x in text.splitlines() if x.startswith("r0: "))
    fis.write_text(text.replace(line, line.rsplit("=", 1)[0] + "= 33.0"))


def test_a_rulebook_read_from_the_labels_folder_plans_without_reading_the_folder_again(
        tmp_path, monkeypatch):
    folder = _copy(tmp_path, "gf")
    rb = load_rulebook(folder)
    assert loaded_from(rb) == str(folder.resolve())

    def no_file_checks(path):
        raise AssertionError(f"the folder was read again: {path}")

    monkeypatch.setattr(rulebook_module, "load_rulebook_cached", no_file_checks)
    scenario = load_scenario(DEMO)
    label = f"fuzzy-rrt:{folder}"
    for seed in (1, 2):
        r = plan_scenario(scenario, label, rulebook=rb, seed=seed, max_iter=300)
        assert r.planner == label and r.rulebook_sha256 == rb.sha256


def test_a_rulebook_read_from_the_labels_folder_is_the_one_planned_even_after_an_edit(tmp_path):
    folder = _copy(tmp_path, "gf")
    rb = load_rulebook(folder)
    _edit_one_rule(folder)
    assert load_rulebook(folder).sha256 != rb.sha256
    r = plan_scenario(load_scenario(DEMO), f"fuzzy-rrt:{folder}", rulebook=rb, seed=1,
                      max_iter=300)
    assert r.rulebook_sha256 == rb.sha256  # what the caller loaded, not the edited folder


def test_a_rulebook_from_another_folder_must_have_the_labels_content(tmp_path):
    rb = load_rulebook(_copy(tmp_path, "a"))
    same = _copy(tmp_path, "b")
    scenario = load_scenario(DEMO)
    r = plan_scenario(scenario, f"fuzzy-rrt:{same}", rulebook=rb, seed=1, max_iter=300)
    assert r.rulebook_sha256 == rb.sha256
    edited = _copy(tmp_path, "c")
    _edit_one_rule(edited)
    with pytest.raises(InputError, match="conflicts with --planner"):
        plan_scenario(scenario, f"fuzzy-rrt:{edited}", rulebook=rb, seed=1, max_iter=300)


def test_a_rulebook_changed_in_memory_is_compared_by_content_not_by_where_it_came_from(
        tmp_path):
    folder = _copy(tmp_path, "gf")
    rb = load_rulebook(folder)
    systems = list(rb.systems)
    c0 = systems[0].consts[0]
    systems[0] = dataclasses.replace(systems[0], consts=(c0 / 2 if c0 > 0 else 0.01,)
                                     + systems[0].consts[1:])
    changed = dataclasses.replace(rb, systems=tuple(systems))
    assert loaded_from(changed) is None
    with pytest.raises(InputError, match="conflicts with --planner"):
        plan_scenario(load_scenario(DEMO), f"fuzzy-rrt:{folder}", rulebook=changed, seed=1,
                      max_iter=300)


def test_where_a_rulebook_was_read_from_is_forgotten_with_the_rulebook(tmp_path):
    folder = _copy(tmp_path, "gf")
    rb = load_rulebook(folder)
    key = id(rb)
    assert key in rulebook_module._LOADED_FROM
    del rb
    gc.collect()
    assert key not in rulebook_module._LOADED_FROM
