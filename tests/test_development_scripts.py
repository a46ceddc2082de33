"""The development scripts that made the shipped rulebook and check plans bit for bit
(``scripts/mine_hard_problems.py``, ``scripts/plan_hash.py``) read folders as the training
command does (``training.run.expand_scenarios``) and refuse a bad one in one line, exit 2."""

from __future__ import annotations

import subprocess
import sys
from pathlib import Path

import pytest

PROJECT = Path(__file__).resolve().parents[1]
SCRIPTS = {"mine": ["mine_hard_problems.py", "OUT"], "hash": ["plan_hash.py"]}


def _run(script, *args, cwd):
    name, *lead = SCRIPTS[script]
    lead = [str(cwd / a) for a in lead]
    return subprocess.run([sys.executable, str(PROJECT / "scripts" / name), *lead, *args],
                          capture_output=True, text=True, cwd=cwd, timeout=300)


@pytest.mark.parametrize("script", sorted(SCRIPTS))
def test_a_missing_folder_is_one_line_and_exit_2(script, tmp_path):
    proc = _run(script, str(tmp_path / "nowhere"), cwd=tmp_path)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "nowhere" in lines[0] and "not a folder" in lines[0]
    assert "Traceback" not in proc.stderr
    assert not (tmp_path / "OUT").exists()


@pytest.mark.parametrize("script", sorted(SCRIPTS))
def test_a_folder_without_scenarios_is_one_line_and_exit_2(script, tmp_path):
    (tmp_path / "empty").mkdir()
    proc = _run(script, str(tmp_path / "empty"), cwd=tmp_path)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "empty" in lines[0] and "no *.toml" in lines[0]
    assert not (tmp_path / "OUT").exists()
