"""What `plan` and `bench` write, and what they refuse before planning.

Every bad output location fails before any planning, in one line naming the user's path (not
a hidden temporary file); a bench folder is replaced as a whole, so a second bench into the same
folder leaves no stale file of the first; rulebooks are named in planner labels
(``fuzzy-rrt:NAME``), and errors blame the option the user actually typed.
"""

from __future__ import annotations

import json
import os
import shutil
import tempfile
from pathlib import Path

import pandas as pd
import pytest

from conftest import FIXTURES, run_main


@pytest.fixture
def run_cli():
    """The CLI through ``main(argv)`` in this process (``conftest.run_main``): these tests
    check what commands print, return and write, not the process; ~1.5 s less a call."""
    return run_main


TWO_CIRCLES = FIXTURES / "scenarios" / "two-circles.toml"
BOXES = FIXTURES / "scenarios" / "boxes-and-circle.toml"


def _unwritable_dir() -> Path:
    """A directory nobody can create files in, root included (sysfs)."""
    base = Path("/sys")
    try:
        fd, probe = tempfile.mkstemp(dir=base)
    except OSError:
        return base / "xfuzzy-rrt-test"
    os.close(fd)
    os.unlink(probe)
    pytest.skip("no unwritable directory on this machine")


def test_plan_with_a_shipped_rulebook_name_equals_plan_with_its_directory(run_cli):
    from xfuzzy_rrt.fuzzy.rulebook import rulebooks_dir

    by_name = run_cli("plan", TWO_CIRCLES, "--planner", "fuzzy-rrt:paper", "--seed", "2")
    by_dir = run_cli("plan", TWO_CIRCLES, "--planner", "fuzzy-rrt", "--rulebook",
                     rulebooks_dir() / "paper", "--seed", "2")
    assert by_name.returncode == by_dir.returncode == 0, by_name.stderr + by_dir.stderr
    a, b = json.loads(by_name.stdout), json.loads(by_dir.stdout)
    assert a["planner"] == "fuzzy-rrt:paper" and b["planner"] == "fuzzy-rrt"
    assert a["rulebook"] == "paper" and a["rulebook_sha256"] == b["rulebook_sha256"]
    assert a["path_deg"] == b["path_deg"] and a["iterations"] == b["iterations"]
    assert (a["found"], a["certified"], a["success"]) == (True, True, True)
    assert a["min_clearance_m"] == b["min_clearance_m"] > 0.0


@pytest.mark.parametrize("args,where", [
    (["plan", TWO_CIRCLES, "--planner", "ompl:Nope"], "--planner"),
    (["plan", TWO_CIRCLES, "--planner", "fuzzy-rrt:nope"], "--planner"),
    (["bench", TWO_CIRCLES, "--planners", "rrt,fuzzy-rrt:nope"], "--planners"),
    (["bench", TWO_CIRCLES, "--planners", "rrt,ompl:Nope"], "--planners"),
])
def test_unknown_planners_and_rulebooks_blame_the_option_typed(run_cli, tmp_path, args, where):
    out = tmp_path / "out"
    proc = run_cli(*args, *(["--out", out] if args[0] == "bench" else []))
    assert proc.returncode == 2 and proc.stdout == ""
    # (a cold numba cache adds its one first-compile notice: importing OMPL's bridge compiles
    # the certified motion validator)
    lines = [x for x in proc.stderr.splitlines() if x != "compiling planners, first run only…"]
    assert len(lines) == 1 and lines[0].startswith(f"error: {where}: unknown "), proc.stderr
    assert not out.exists()


def test_a_rulebook_directory_needs_a_slash_and_must_exist(run_cli, tmp_path):
    proc = run_cli("plan", TWO_CIRCLES, "--planner", f"fuzzy-rrt:{tmp_path}/missing")
    assert proc.returncode == 2
    assert proc.stderr == (f"error: --planner: rulebook directory '{tmp_path}/missing' does "
                           "not exist\n")
    proc = run_cli("plan", TWO_CIRCLES, "--planner", "fuzzy-rrt:paper", "--rulebook",
                   tmp_path)
    assert proc.returncode == 2 and proc.stderr.startswith("error: --rulebook: conflicts with")


@pytest.mark.parametrize("option", ["--out", "--trace"])
def test_plan_refuses_an_unwritable_output_before_planning(run_cli, option):
    target = _unwritable_dir() / ("result.json" if option == "--out" else "trace.csv")
    proc = run_cli("plan", TWO_CIRCLES, "--seed", "1", "--max-iter", "1000000", option, target)
    assert proc.returncode == 2 and proc.stdout == ""
    assert proc.stderr.startswith(f"error: {target}: cannot write here: "), proc.stderr
    assert len(proc.stderr.splitlines()) == 1


def test_bench_refuses_an_unwritable_out_before_planning(run_cli):
    out = _unwritable_dir() / "bench"
    proc = run_cli("bench", TWO_CIRCLES, "--planners", "rrt", "--runs", "2", "--out", out)
    assert proc.returncode == 2
    assert proc.stderr.startswith(f"error: {out}: cannot write here: "), proc.stderr
    assert len(proc.stderr.splitlines()) == 1 and " runs (" not in proc.stderr


def test_a_second_bench_into_the_same_folder_replaces_it_as_a_set(run_cli, tmp_path):
    out = tmp_path / "bench"
    first = run_cli("bench", TWO_CIRCLES, BOXES, "--planners", "rrt,fuzzy-rrt", "--runs", "2",
                    "--max-iter", "3000", "--out", out)
    assert first.returncode == 0, first.stderr
    index = json.loads((out / "examples" / "index.json").read_text())
    assert {e["scenario"] for e in index} == {"two-circles", "boxes-and-circle"}
    (out / "notes-from-an-old-run.txt").write_text("stale")
    second = run_cli("bench", TWO_CIRCLES, "--planners", "rrt", "--runs", "2", "--max-iter",
                     "3000", "--out", out)
    assert second.returncode == 0, second.stderr
    index = json.loads((out / "examples" / "index.json").read_text())
    assert {(e["scenario"], e["planner"], e["role"]) for e in index} == {
        ("two-circles", "rrt", "median"), ("two-circles", "rrt", "worst")}
    files = sorted(str(p.relative_to(out)) for p in out.rglob("*") if p.is_file())
    examples = sorted({f"examples/{e['tree']}" for e in index})
    assert files == ["bench.json", *examples, "examples/index.json", "ratios.csv",
                     "report.html", "report/plotly.min.js", "report/scenario-00-two-circles.html",
                     "runs.csv", "summary.csv"]
    assert set(pd.read_csv(out / "runs.csv")["scenario"]) == {"two-circles"}
    assert [p.name for p in tmp_path.iterdir()] == ["bench"], "a staging folder was left"


def test_bench_refuses_to_replace_a_folder_it_did_not_write(run_cli, tmp_path):
    out = tmp_path / "mine"
    out.mkdir()
    (out / "thesis.tex").write_text("precious")
    proc = run_cli("bench", TWO_CIRCLES, "--planners", "rrt", "--runs", "1", "--out", out)
    assert proc.returncode == 2
    assert proc.stderr.startswith(f"error: {out}: is not empty and not a bench folder")
    assert [p.name for p in out.iterdir()] == ["thesis.tex"]


def test_bench_refuses_a_scenario_inside_the_folder_it_would_replace(run_cli, tmp_path):
    out = tmp_path / "bench"
    first = run_cli("bench", TWO_CIRCLES, "--planners", "rrt", "--runs", "1", "--out", out)
    assert first.returncode == 0, first.stderr
    inside = out / "two-circles.toml"
    shutil.copy(TWO_CIRCLES, inside)
    proc = run_cli("bench", inside, "--planners", "rrt", "--runs", "1", "--out", out)
    assert proc.returncode == 2
    assert proc.stderr == (f"error: {inside.resolve()}: lies inside --out {out}, which the "
                           "bench replaces; move it or choose another --out\n")
    assert inside.is_file()


def test_an_unwritable_atomic_output_names_the_file_not_its_hidden_temporary():
    from xfuzzy_rrt.atomic import atomic_path

    target = _unwritable_dir().parent / "xfuzzy-rrt-report.html"  # the folder itself exists
    with pytest.raises(OSError) as info:
        with atomic_path(target):
            pass
    assert info.value.filename == str(target)
