"""Interrupted jobs lose nothing: after SIGINT or SIGKILL every output is complete or absent.

``bench`` and ``train`` are run through the real console script and interrupted at chosen
moments: while planning, as the first output file is being written (a temporary file appears
in the output folder) and while the large HTML report is being written. Afterwards every output
file must be either the previous run's complete file or a complete new one — never truncated
(CSV files parse with the expected rows, JSON parses, the HTML ends with ``</html>``, parquet
files read back, rulebooks lint). A SIGINT must also clean up its temporary files and exit 130
without a traceback; a SIGKILL cannot clean up, so hidden ``.NAME.*.tmp`` files may remain, but
they never carry an output's name. Training additionally resumes from its checkpoint after
the interruption and ends with exactly the rulebook an uninterrupted run writes.
"""

from __future__ import annotations

import json
import os
import shutil
import signal
import subprocess
from pathlib import Path

import pandas as pd
import pytest

from conftest import FIXTURES, console_script

SCENARIO = FIXTURES / "scenarios" / "two-circles.toml"
TIMEOUT_S = 240


# ------------------------------------------------------------------------------ helpers


def temp_files(folder: Path) -> list[Path]:
    """Temporary files of atomic writes (``.NAME.XXXX.tmp`` / ``.NAME.XXXX.SUFFIX.tmp``)."""
    if not folder.is_dir():
        return []
    return [p for p in folder.rglob(".*") if p.is_file() and p.name.endswith(".tmp")]


def snapshot(folder: Path) -> dict[str, bytes]:
    return {str(p.relative_to(folder)): p.read_bytes()
            for p in sorted(folder.rglob("*")) if p.is_file() and not p.name.startswith(".")}


# --------------------------------------------------------------------------------- bench
#
# A bench folder is written into a hidden sibling and swapped in as a whole, so whatever the
# moment of an interruption the folder is byte for byte the previous complete one (or absent).
# The moments are hit deterministically through the CLI's test hook
# (``XFUZZY_RRT_TEST_SIGNAL=SIG@POINT``: after run K, after the tables, after the report), not by
# polling; SIGINT goes to the whole process group, as a terminal's Ctrl-C does, so worker
# processes receive it too.

BENCH_FILES = ["runs.csv", "summary.csv", "ratios.csv", "bench.json", "report.html",
               "examples/index.json"]
BENCH_RUNS = 3


def bench_args(out: Path, runs: int, workers: int = 1) -> list[str]:
    return ["bench", str(SCENARIO), "--planners", "rrt,fuzzy-rrt", "--runs", str(runs),
            "--workers", str(workers), "--max-iter", "3000", "--out", str(out)]


def run_with_hook(args: list[str], hook: str) -> subprocess.CompletedProcess:
    """Run ``xfuzzy-rrt ARGS`` in its own process group with the test hook set."""
    env = dict(os.environ, XFUZZY_RRT_TEST_SIGNAL=hook)
    return subprocess.run([console_script(), *map(str, args)], capture_output=True, text=True,
                          timeout=TIMEOUT_S, env=env, start_new_session=True)


def check_bench_folder(out: Path, runs: int) -> None:
    """Every file present, complete and consistent with the others."""
    from xfuzzy_rrt.bench.store import read_runs
    from xfuzzy_rrt.bench.summary import ratio_table, summarise

    for name in BENCH_FILES:
        assert (out / name).is_file(), f"{name} missing"
    runs_df = read_runs(out / "runs.csv")
    assert len(runs_df) == 2 * runs and (runs_df.groupby("planner").size() == runs).all()
    summary = pd.read_csv(out / "summary.csv")
    pd.testing.assert_frame_equal(summarise(runs_df).reset_index(drop=True), summary,
                                  check_dtype=False)
    ratios = pd.read_csv(out / "ratios.csv")
    assert set(ratios["planner"]) == {"fuzzy-rrt"}, "ratios.csv is incomplete"
    pd.testing.assert_frame_equal(ratio_table(summary), ratios, check_dtype=False)
    meta = json.loads((out / "bench.json").read_text())
    assert meta["settings"]["runs"] == runs
    index = json.loads((out / "examples" / "index.json").read_text())
    assert {e["planner"] for e in index} == {"rrt", "fuzzy-rrt"}
    for e in index:
        pd.read_parquet(out / "examples" / e["tree"])
        if e["trace"]:
            pd.read_parquet(out / "examples" / e["trace"])
    assert (out / "report.html").read_text().rstrip().endswith("</html>")


def staging_dirs(parent: Path) -> list[Path]:
    return [p for p in parent.iterdir() if p.name.endswith((".staging", ".old"))]


@pytest.fixture(scope="module")
def previous_bench(tmp_path_factory):
    """A complete one-run bench folder: the 'previous output' every interruption starts from."""
    out = tmp_path_factory.mktemp("previous") / "bench"
    proc = subprocess.run([console_script(), *bench_args(out, 1)], capture_output=True,
                          text=True, timeout=TIMEOUT_S)
    assert proc.returncode == 0, proc.stderr
    check_bench_folder(out, 1)
    return out


@pytest.mark.parametrize("sig,point,workers", [
    ("INT", "runs:2", 2),
    ("INT", "runs:2", 1),
    ("INT", "tables", 1),
    ("INT", "report", 2),
    ("KILL", "runs:2", 2),
    ("KILL", "tables", 1),
    ("KILL", "report", 1),
])
def test_interrupted_bench_leaves_the_previous_complete_folder_byte_for_byte(
        run_cli, tmp_path, previous_bench, sig, point, workers):
    out = tmp_path / "bench"
    shutil.copytree(previous_bench, out)
    before = snapshot(out)
    proc = run_with_hook(bench_args(out, BENCH_RUNS, workers), f"{sig}@{point}")
    if sig == "INT":
        assert proc.returncode == 130, proc.stderr
        assert "Traceback" not in proc.stderr and "KeyboardInterrupt" not in proc.stderr
        lines = [ln for ln in proc.stderr.splitlines() if "interrupted" in ln]
        assert lines == [f"interrupted: {out}: the previous folder is unchanged"], proc.stderr
        assert staging_dirs(tmp_path) == [], "Ctrl-C left the hidden staging folder"
    else:
        # Returning at all shows the workers died with the parent: an orphan would hold the
        # output pipes open and time this call out.
        assert proc.returncode == -signal.SIGKILL
        # A killed process cannot clean up: its staging folder stays hidden beside ``out``.
        assert all(p.name.startswith(".") for p in staging_dirs(tmp_path))
    assert snapshot(out) == before, "the previous complete folder changed"
    check_bench_folder(out, 1)
    # The next bench into the same folder completes and replaces it as a whole.
    again = run_cli(*bench_args(out, BENCH_RUNS, workers), timeout=TIMEOUT_S)
    assert again.returncode == 0, again.stderr
    check_bench_folder(out, BENCH_RUNS)


def test_interrupted_first_bench_leaves_no_folder(tmp_path):
    out = tmp_path / "new" / "bench"
    proc = run_with_hook(bench_args(out, BENCH_RUNS, 2), "INT@runs:1")
    assert proc.returncode == 130, proc.stderr
    assert proc.stderr.splitlines()[-1] == f"interrupted: {out}: nothing was written"
    assert not (tmp_path / "new").exists() and staging_dirs(tmp_path) == []


# --------------------------------------------------------------------------------- train

RULEBOOK_FILES = ["rulebook.toml", "goal_bias.fis", "bound_1.fis", "bound_2.fis",
                  "bound_3.fis", "bound_4.fis", "step_size.fis"]
MEASURED = ["wall_s", "runs_per_s"]  # the only non-reproducible history columns


def train_args(out: Path, resume: bool = False, validation_runs: int = 2) -> list[str]:
    args = ["train", "--scenario", str(SCENARIO), "--population", "16", "--elite", "2",
            "--generations", "30", "--runs-per-eval", "2", "--validation-runs",
            str(validation_runs), "--workers", "1", "--max-iter", "3000", "--seed", "3",
            "--out", str(out)]
    return args + (["--resume"] if resume else [])


def history_rows(out: Path) -> int:
    try:
        return len((out / "history.csv").read_text().splitlines()) - 1
    except FileNotFoundError:
        return 0


def check_train_folder(out: Path) -> None:
    """History complete row by row; rulebook files each complete (or absent)."""
    if (out / "history.csv").exists():
        h = pd.read_csv(out / "history.csv")
        assert list(h["generation"]) == list(range(1, len(h) + 1))
        assert not h.drop(columns=MEASURED).isna().any().any()
    from xfuzzy_rrt.fuzzy.manifest import parse_manifest
    from xfuzzy_rrt.fuzzy.text_format import parse_fis

    for name in RULEBOOK_FILES:
        path = out / name
        if not path.exists():
            continue
        if name == "rulebook.toml":
            _, problems = parse_manifest(path.read_bytes(), str(path))
        else:
            _, problems = parse_fis(path.read_bytes(), str(path), path.stem)
        assert problems == [], problems


@pytest.fixture(scope="module")
def trained_reference(tmp_path_factory):
    out = tmp_path_factory.mktemp("reference") / "rb"
    proc = subprocess.run([console_script(), *train_args(out)], capture_output=True, text=True,
                          timeout=TIMEOUT_S)
    assert proc.returncode == 0, proc.stderr
    return out


@pytest.mark.slow
@pytest.mark.parametrize("sig,moment", [
    (signal.SIGINT, "generations"),
    (signal.SIGKILL, "generations"),
    (signal.SIGINT, "final-choice"),
    (signal.SIGKILL, "final-choice"),
])
def test_interrupted_training_resumes_to_the_uninterrupted_rulebook(
        run_cli, tmp_path, trained_reference, sig, moment):
    # Interrupted at a known point through the CLI's test hook, not by polling: right after
    # the checkpoint of generation 5, or after the last checkpoint while the final rulebook
    # is being chosen (before it is written).
    out = tmp_path / "rb"
    name = "INT" if sig == signal.SIGINT else "KILL"
    point = "generation:5" if moment == "generations" else "choice"
    proc = run_with_hook(train_args(out), f"{name}@{point}")
    code, err = proc.returncode, proc.stderr
    if sig == signal.SIGINT:
        assert code == 130, err
        assert "Traceback" not in err, err
        assert "--resume" in err
        assert temp_files(out) == []
    else:
        assert code == -signal.SIGKILL
    assert history_rows(out) == (5 if moment == "generations" else history_rows(trained_reference))
    assert not (out / "rulebook.toml").exists()  # interrupted before the rulebook was written
    check_train_folder(out)

    resumed = run_cli(*train_args(out, resume=True), timeout=TIMEOUT_S)
    assert resumed.returncode == 0, resumed.stderr
    check_train_folder(out)
    for name in RULEBOOK_FILES:
        # The manifest records the command, whose --out differs; nothing else may.
        ours = (out / name).read_text().replace(str(out), "OUT")
        assert ours == (trained_reference / name).read_text().replace(str(trained_reference),
                                                                      "OUT"), name
    ours = pd.read_csv(out / "history.csv").drop(columns=MEASURED)
    ref = pd.read_csv(trained_reference / "history.csv").drop(columns=MEASURED)
    pd.testing.assert_frame_equal(ours, ref)
