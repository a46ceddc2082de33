"""Every argument that names a rulebook to read takes a shipped rulebook's name as ``evaluate
--rulebook`` always did: ``rules``, ``plan --rulebook``, ``explain --rulebook``, ``bench
--rulebook`` and ``train --seed-rulebook`` refused ``goal-frame`` anywhere but in the project's
root. A folder of that name in the current directory still wins; a name that is neither stays
the one-line error it was."""

from __future__ import annotations

import json
import shutil

from conftest import run_main
from xfuzzy_rrt.fuzzy.rulebook import rulebook_path, rulebooks_dir

SCENARIO = """name = "stay-near"
[arm]
links = [0.18, 0.12]
[start]
q_deg = [10.0, 20.0]
[goal]
q_deg = [60.0, -20.0]
"""


def test_rules_commands_take_a_shipped_name_from_any_directory(tmp_path):
    proc = run_main("rules", "show", "goal-frame", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert f"({rulebooks_dir() / 'goal-frame'})" in proc.stdout.splitlines()[0]
    assert run_main("rules", "lint", "paper", cwd=tmp_path).returncode == 0
    proc = run_main("rules", "diff", "goal-frame", "goal-frame", cwd=tmp_path)
    assert proc.returncode == 0 and "identical" in proc.stdout


def test_plan_records_the_shipped_directory_a_name_stands_for(tmp_path):
    (tmp_path / "s.toml").write_text(SCENARIO, encoding="utf-8")
    proc = run_main("plan", "s.toml", "--rulebook", "expert", "--max-iter", "2000", cwd=tmp_path)
    assert proc.returncode in (0, 1), proc.stderr
    data = json.loads(proc.stdout)
    assert data["rulebook"] == "expert"
    assert data["rulebook_dir"] == str((rulebooks_dir() / "expert").resolve())


def test_a_folder_in_the_current_directory_wins_over_the_shipped_name(tmp_path):
    shutil.copytree(rulebooks_dir() / "expert", tmp_path / "paper")
    proc = run_main("rules", "show", "paper", cwd=tmp_path)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.splitlines()[0].startswith("rulebook 'expert'")


def test_a_name_that_is_neither_is_still_one_error_line(tmp_path):
    proc = run_main("rules", "show", "no-such-rulebook", cwd=tmp_path)
    assert proc.returncode == 2
    assert proc.stderr.strip() == "error: no-such-rulebook: rulebook directory does not exist"
    # a path-like argument is never looked up among the shipped ones
    assert str(rulebook_path("./goal-frame")) == "goal-frame"


def test_a_typo_of_a_shipped_name_says_which_one_was_meant(tmp_path):
    proc = run_main("rules", "show", "goal-fram", cwd=tmp_path)
    assert proc.returncode == 2
    assert proc.stderr.strip() == ("error: goal-fram: rulebook directory does not exist (did you "
                                   "mean the shipped 'goal-frame'?)")
    assert not (tmp_path / "goal-fram").exists()
