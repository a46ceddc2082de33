"""What a new user tripped on (issue 22, "tried as a new user would"): each test is one trip.

Every bad input is one ``error: ...`` line and exit 2 before any planning; a run that finds
nothing says so on stderr; explain finds the rulebook that made a trace by itself.
"""

from __future__ import annotations

import json
import re
import shutil
from pathlib import Path

import pytest

from tests.conftest import FIXTURES, PROJECT, run_main


@pytest.fixture
def run_cli():
    """The CLI through ``main(argv)`` in this process (``conftest.run_main``): these tests
    check what commands print, return and write, not the process; ~1.5 s less a call."""
    return run_main


SCENARIO = FIXTURES / "scenarios" / "boxes-and-circle.toml"
FIVE_DOF = FIXTURES / "arms" / "five-dof.toml"


def _one_error_line(proc, *needles: str) -> str:
    assert proc.returncode == 2, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: "), proc.stderr
    for needle in needles:
        assert needle in lines[0], lines[0]
    return lines[0]


def _edited_copy(tmp_path: Path, name: str = "e") -> Path:
    """``cp -r rulebooks/goal-frame e`` and change one rule's step: the user's own rulebook
    that still carries the name ``goal-frame``."""
    dest = tmp_path / name
    shutil.copytree(PROJECT / "rulebooks" / "goal-frame", dest)
    fis = dest / "step_deg.fis"
    text = fis.read_text()
    old = re.search(r"then step_deg = [0-9.e+-]+", text).group(0)  # the first rule's step
    new = "then step_deg = 20.0" if old != "then step_deg = 20.0" else "then step_deg = 21.0"
    fis.write_text(text.replace(old, new, 1))
    return dest


# ------------------------------------------------------------------ 1. explain finds its rulebook


def test_explain_finds_the_edited_rulebook_that_made_the_trace(run_cli, tmp_path):
    rb = _edited_copy(tmp_path)
    trace = tmp_path / "t.parquet"
    plan = run_cli("plan", SCENARIO, "--rulebook", rb, "--trace", trace, "--max-iter", "300",
                   "--out", tmp_path / "r.json")
    assert plan.returncode in (0, 1), plan.stderr
    proc = run_cli("explain", trace, "--iteration", "2")
    assert proc.returncode == 0, proc.stderr
    assert "goal-frame" in proc.stdout or proc.stdout.strip()
    # the JSON result finds it too
    proc = run_cli("explain", tmp_path / "r.json", "--iteration", "2")
    assert proc.returncode == 0, proc.stderr


def test_explain_names_the_changed_rulebook_directory_and_accepts_an_override(run_cli, tmp_path):
    rb = _edited_copy(tmp_path)
    trace = tmp_path / "t.csv"
    plan = run_cli("plan", SCENARIO, "--rulebook", rb, "--trace", trace, "--max-iter", "300",
                   "--out", tmp_path / "r.json")
    assert plan.returncode in (0, 1), plan.stderr
    kept = tmp_path / "kept"
    shutil.copytree(rb, kept)  # the version that made the trace, elsewhere
    fis = rb / "step_deg.fis"
    fis.write_text(fis.read_text().replace("then step_deg = 20.0", "then step_deg = 21.0", 1))
    line = _one_error_line(run_cli("explain", trace, "--iteration", "2"), str(rb.resolve()),
                           "changed", "--rulebook")
    assert "--rulebook:" not in line  # the user passed no --rulebook: it is not blamed
    _one_error_line(run_cli("explain", tmp_path / "r.json", "--iteration", "2"),
                    str(rb.resolve()), "changed")
    assert run_cli("explain", trace, "--iteration", "2", "--rulebook", kept).returncode == 0
    shutil.rmtree(rb)
    _one_error_line(run_cli("explain", trace, "--iteration", "2"), str(rb.resolve()),
                    "no longer exists")


# ------------------------------------------------------------------ 2. seeds out of range


@pytest.mark.parametrize("seed", ["18446744073709551616", "99999999999999999999999", "-1"])
@pytest.mark.parametrize("command", [
    ["plan", str(SCENARIO), "--max-iter", "5"],
    ["bench", str(SCENARIO), "--runs", "1", "--max-iter", "5"],
    ["train", "--scenario", str(SCENARIO), "--generations", "1", "--out", "rb"],
    ["rules", "coverage", str(PROJECT / "rulebooks" / "goal-frame"), str(SCENARIO)],
])
def test_a_seed_out_of_range_is_one_line_naming_seed_and_the_range(run_cli, tmp_path, command,
                                                                   seed):
    proc = run_cli(*command, "--seed", seed, cwd=tmp_path)
    _one_error_line(proc, "--seed", "9223372036854775807")
    assert not any(tmp_path.iterdir())


def test_the_seeds_of_a_bench_must_all_fit_in_the_seed_range(run_cli, tmp_path):
    proc = run_cli("bench", SCENARIO, "--runs", "10", "--seed", str(2**63 - 5),
                   "--out", tmp_path / "b")
    _one_error_line(proc, "--seed", "10 run seeds")
    assert not (tmp_path / "b").exists()


def test_the_largest_seed_plans(run_cli):
    proc = run_cli("plan", SCENARIO, "--seed", str(2**63 - 1), "--max-iter", "20",
                   "--planner", "rrt")
    assert proc.returncode in (0, 1), proc.stderr
    assert json.loads(proc.stdout)["seed"] == 2**63 - 1


# ------------------------------------------------------------------ 3. exit 1 says why


def test_plan_that_finds_no_path_says_so_in_one_stderr_line_and_still_writes_out(run_cli, tmp_path):
    out = tmp_path / "o.json"
    proc = run_cli("plan", SCENARIO, "--planner", "rrt", "--max-iter", "2", "--out", out)
    assert proc.returncode == 1
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1, proc.stderr
    assert "no path" in lines[0] and "within 2 iterations" in lines[0] and str(out) in lines[0]
    assert json.loads(out.read_text())["found"] is False


# ------------------------------------------------------------------ 4. lists, workers, rulebook


def test_an_empty_entry_in_planners_is_refused(run_cli, tmp_path):
    proc = run_cli("bench", SCENARIO, "--planners", "rrt,,fuzzy-rrt", "--out", tmp_path / "b")
    _one_error_line(proc, "--planners", "empty")
    assert not (tmp_path / "b").exists()


@pytest.mark.parametrize("command", [["bench", str(SCENARIO), "--runs", "1"],
                                     ["train", "--scenario", str(SCENARIO), "--out", "rb"]])
def test_an_absurd_number_of_workers_is_refused_naming_the_cap(run_cli, tmp_path, command):
    proc = run_cli(*command, "--workers", "100000", cwd=tmp_path)
    _one_error_line(proc, "--workers", "100000", "at most")
    assert not any(tmp_path.iterdir())


def test_a_rulebook_given_to_a_planner_without_rules_is_refused(run_cli, tmp_path):
    broken = tmp_path / "broken"
    broken.mkdir()
    _one_error_line(run_cli("plan", SCENARIO, "--planner", "rrt", "--rulebook", broken),
                    "--rulebook", "rrt")
    _one_error_line(run_cli("bench", SCENARIO, "--planners", "rrt", "--rulebook", broken,
                            "--out", tmp_path / "b"), "--rulebook")
    assert not (tmp_path / "b").exists()


# ------------------------------------------------------------------ 5. DOF mismatch up front


def test_bench_finds_a_rulebook_dof_mismatch_before_any_planning(run_cli, tmp_path):
    # a rulebook the user names (without one, fuzzy-rrt plans the 5-DOF problem with its
    # any-arm default: tests/test_default_plans_any_arm.py)
    proc = run_cli("bench", SCENARIO, FIVE_DOF, "--planners", "rrt,fuzzy-rrt", "--runs", "2",
                   "--rulebook", PROJECT / "rulebooks" / "goal-frame", "--out", tmp_path / "b")
    _one_error_line(proc, "five-dof", "DOF")
    assert "bench:" not in proc.stderr  # no progress line: nothing ran
    assert not (tmp_path / "b").exists()


# ------------------------------------------------------------------ 6. rules diff


def _scale_constants(fis: Path, output: str, factor: float) -> None:
    text = fis.read_text()
    new, n = re.subn(rf"(then {output} = )(\S+)$",
                     lambda m: f"{m.group(1)}{float(m.group(2)) * factor!r}", text, flags=re.M)
    assert n > 0
    fis.write_text(new)


def test_replay_whose_plans_never_differ_says_the_plans_are_identical(run_cli, tmp_path):
    b = tmp_path / "b"
    shutil.copytree(PROJECT / "rulebooks" / "expert", b)
    _scale_constants(b / "goal_bias.fis", "goal_bias", 1 - 1e-9)  # decisions move, plans do not
    proc = run_cli("rules", "diff", PROJECT / "rulebooks" / "expert", b, "--replay",
                   PROJECT / "xfuzzy_rrt" / "data" / "scenarios" / "demo-tissue.toml",
                   "--max-iter", "300")
    assert proc.returncode == 1, proc.stderr
    assert "first divergence at iteration 1" in proc.stdout
    assert "iteration None" not in proc.stdout
    assert "the plans are identical" in proc.stdout


def test_rules_diff_against_the_fll_round_trip_is_a_compact_summary(run_cli, tmp_path):
    a = PROJECT / "rulebooks" / "goal-frame"
    assert run_cli("rules", "export", a, "--out", tmp_path / "fll").returncode == 0
    assert run_cli("rules", "import", tmp_path / "fll", "--out", tmp_path / "rt").returncode == 0
    proc = run_cli("rules", "diff", a, tmp_path / "rt")
    assert proc.returncode == 0, proc.stderr
    assert len(proc.stdout) < 3000, proc.stdout
    assert not re.search(r"\bnan\b", proc.stdout), proc.stdout
    assert "only in a (absent in b)" in proc.stdout


def test_rules_diff_summarises_constants_that_differ_only_by_float_rounding(run_cli, tmp_path):
    b = tmp_path / "b"
    shutil.copytree(PROJECT / "rulebooks" / "expert", b)
    _scale_constants(b / "goal_bias.fis", "goal_bias", 1 - 3e-16)
    proc = run_cli("rules", "diff", PROJECT / "rulebooks" / "expert", b)
    assert "differ only by float rounding" in proc.stdout, proc.stdout
    assert not any(line.startswith("  r") for line in proc.stdout.splitlines()), proc.stdout


# ------------------------------------------------------------------ 8. robustness moving: why


def test_moving_obstacles_with_replanning_say_why_runs_failed():
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.robustness.moving import FAILURE_CAUSES, diagnosis, moving_obstacles

    s = load_scenario(FIXTURES / "scenarios" / "two-circles.toml")
    table = moving_obstacles([s], ["rrt"], [0.02], joint_speed_deg_s=20.0, rate_hz=10.0,
                             replan=True, runs=4, max_iter=500, time_limit_s=10.0)
    row = table.iloc[0]
    assert row["success_rate"] < 1 and row["replan_failures"] > 0  # the case under test
    assert sum(int(row[c]) for c in FAILURE_CAUSES) == row["replan_failures"]
    failed = row["runs"] - round(row["success_rate"] * row["runs"])
    assert row["runs_unplanned"] + row["runs_collided"] + row["runs_timed_out"] == failed
    why = diagnosis(row)
    assert why is not None and f"{failed} of 4 runs failed" in why
    assert f"{int(row['replan_failures'])} replannings found no path" in why
    assert "no path within 500 iterations" in why or "in collision" in why


def test_robustness_moving_prints_the_diagnosis_line(run_cli):
    proc = run_cli("robustness", "moving", FIXTURES / "scenarios" / "two-circles.toml",
                   "--planners", "rrt", "--speed", "0.02", "--replan", "--runs", "2",
                   "--max-iter", "500", "--time-limit", "5", "--joint-speed", "20", "--rate", "10")
    assert proc.returncode == 0, proc.stderr
    why = [line for line in proc.stdout.splitlines() if line.strip().startswith("why:")]
    assert len(why) == 1 and "runs failed" in why[0], proc.stdout


# ------------------------------------------------------------------ 7. generated endpoints


@pytest.mark.parametrize("k", [11, 20])  # the demo's problems that broke it (2.54 mm, 2.6 µm)
def test_generated_problems_keep_five_millimetres_at_start_and_goal(k):
    from xfuzzy_rrt.geometry.collision import clearance
    from xfuzzy_rrt.scenarios.generate import generate_one

    a = generate_one(2000, k).scenario.arrays()
    assert clearance(a, a.start_deg) >= 0.005
    assert clearance(a, a.goal_deg) >= 0.005


# ------------------------------------------------------------------ 9. rules eval, README, figures


def test_rules_eval_warns_once_per_clamped_column_and_still_clamps(run_cli, tmp_path):
    inputs = tmp_path / "in.csv"
    inputs.write_text("angle_to_goal,dist_to_goal,angle_to_obstacle,dist_to_obstacle\n"
                      "45,0.1,-90,0.02\n0.5,0.1,5.5,0.02\n30,0.1,0.2,0.02\n")
    proc = run_cli("rules", "eval", PROJECT / "rulebooks" / "expert", "--input", inputs,
                   "--output", tmp_path / "out.csv")
    assert proc.returncode == 0, proc.stderr
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 2, proc.stderr
    assert "angle_to_goal: 2 of 3 values outside" in lines[0] and "clamped" in lines[0]
    assert "angle_to_obstacle: 1 of 3 values outside" in lines[1]
    assert (tmp_path / "out.csv").exists()


def _readme() -> str:
    return (PROJECT / "README.md").read_text()


def test_readme_rules_eval_example_feeds_inputs_in_their_units():
    import io

    import pandas as pd

    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
    from xfuzzy_rrt.fuzzy.tables import clamped_inputs

    line = next(x for x in _readme().splitlines() if x.startswith("printf 'angle_to_goal"))
    csv = line.split("'")[1].replace("\\n", "\n")
    df = pd.read_csv(io.StringIO(csv))
    assert clamped_inputs(load_rulebook(PROJECT / "rulebooks" / "expert"), df) == []


def test_readme_robustness_examples_name_files_that_exist_in_a_fresh_clone():
    text = _readme()
    assert "/tmp/x " not in text and "XXXX" not in text
    commands = [x.split() for x in text.splitlines()
                if x.strip().startswith("xfuzzy-rrt robustness ")]
    assert commands
    for words in commands:
        target = words[3]
        if target.startswith("reports/"):  # written by a bench command just before it
            assert f"--out {target}" in text, target
        else:
            assert target.startswith("../shared/") or (PROJECT / target).exists(), target
    assert "a fresh clone has none" in text
    assert (PROJECT / "xfuzzy_rrt" / "data" / "reference" / "paper-reference.toml").exists()


def _label_rows_of(fig):
    """{subplot: [(x, y, text)]} of a membership figure's term labels."""
    out: dict[str, list] = {}
    for a in fig.to_dict()["layout"]["annotations"]:
        out.setdefault(a["xref"], []).append((a["x"], a["y"], a["text"]))
    return out


@pytest.mark.parametrize("name", ["goal-frame", "general", "paper"])
def test_membership_labels_that_would_overlap_are_on_different_rows(name):
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
    from xfuzzy_rrt.report import fuzzy_figures as ff

    rb = load_rulebook(PROJECT / "rulebooks" / name)
    for fis in rb.systems:
        fig = ff.membership_figure(fis, [fis.output], rb)
        labels = _label_rows_of(fig)
        axis_px = ff.LABEL_AXIS_PX / len(fis.inputs)
        for c, inp in enumerate(fis.inputs):
            ref = f"x{c + 1}" if c else "x"
            span = inp.peaks[-1] - inp.peaks[0]
            items = labels[ref]
            for i, (x1, y1, t1) in enumerate(items):
                for x2, y2, t2 in items[i + 1:]:
                    gap_px = abs(x1 - x2) / span * axis_px
                    needed = 0.5 * (len(t1) + len(t2)) * ff.LABEL_CHAR_PX
                    if gap_px < needed:
                        assert y1 != y2, (name, fis.output, inp.name, t1, t2)


def test_crowded_goal_frame_clearance_labels_are_not_on_one_row():
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
    from xfuzzy_rrt.report import fuzzy_figures as ff

    rb = load_rulebook(PROJECT / "rulebooks" / "goal-frame")
    fis = rb.systems[0]
    c = [inp.name for inp in fis.inputs].index("clearance_deg")
    items = _label_rows_of(ff.membership_figure(fis, [fis.output], rb))[f"x{c + 1}" if c else "x"]
    ys = [y for _, y, _ in sorted(items)]
    assert ys[0] != ys[1] and ys[0] != ys[2] and ys[1] != ys[2]  # peaks 0, 2.4, 5.6 of 30


def test_training_compiles_before_generation_one_is_timed(tmp_path, monkeypatch):
    """Generation 1 reported "0 runs/s": its clock included numba's first compile. The
    engines are now warmed up (kernels compiled, workers started) before any timed call."""
    from xfuzzy_rrt.cli.main import main
    from xfuzzy_rrt.training import workers

    events: list[str] = []
    real = workers.make_evaluator

    class Recording:
        def __init__(self, engine):
            self.engine = engine
            self.description = engine.description

        def __enter__(self):
            self.engine.__enter__()
            return self

        def __exit__(self, *exc):
            return self.engine.__exit__(*exc)

        def warm_up(self, genes):
            events.append("warm")
            self.engine.warm_up(genes)

        def __call__(self, genes, seeds, progress=None):
            events.append("evaluate")
            return self.engine(genes, seeds, progress)

    monkeypatch.setattr(workers, "make_evaluator", lambda *a, **k: Recording(real(*a, **k)))
    monkeypatch.chdir(tmp_path)
    code = main(["train", "--scenario", str(SCENARIO), "--population", "4", "--generations",
                 "1", "--runs-per-eval", "1", "--elite", "1", "--bounds", "relative", "--workers", "1",
                 "--validation-runs", "1", "--out", "rb"])
    assert code == 0
    assert events and events[0] == "warm", events
