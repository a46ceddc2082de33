"""The benchmark runner and its tables: recomputable, worker-independent, failures counted.

A benchmark's claims ("2x fewer iterations") must be re-derivable from ``runs.csv`` alone, so
the summary and the ratio table are recomputed here from the file on disk; runs must not depend
on the number of workers (shortcutting and certification included); a directory argument means
every scenario in it; the progress bar degrades to plain lines when stderr is not a terminal.
"""

from __future__ import annotations

import io
import shutil

import numpy as np
import pandas as pd
import pytest

from conftest import FIXTURES, SHARED_SCENARIOS
from exact_geometry import Oracle

TWO_CIRCLES = FIXTURES / "scenarios" / "two-circles.toml"
BOXES = FIXTURES / "scenarios" / "boxes-and-circle.toml"


@pytest.fixture(scope="module")
def scenarios():
    from xfuzzy_rrt.geometry.scenario import load_scenario

    return [load_scenario(TWO_CIRCLES), load_scenario(BOXES)]


@pytest.fixture(scope="module")
def bench_dir(tmp_path_factory, scenarios):
    """A small benchmark with a tight budget (so some runs fail) written to disk."""
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.bench.store import write_bench_dir

    result = run_benchmark(scenarios, ["rrt", "fuzzy-rrt"], runs=8, seed=3, max_iter=600,
                           shortcut=True)
    out = tmp_path_factory.mktemp("bench")
    write_bench_dir(result, out, {"command": "test"})
    return result, out


def test_summary_recomputed_from_runs_csv_matches_summary_csv(bench_dir):
    from xfuzzy_rrt.bench.store import read_runs
    from xfuzzy_rrt.bench.summary import ratio_table, summarise

    result, out = bench_dir
    runs = read_runs(out / "runs.csv")
    assert not runs["success"].all(), "the budget should make some runs fail"
    again = summarise(runs)
    on_disk = pd.read_csv(out / "summary.csv")
    pd.testing.assert_frame_equal(again.reset_index(drop=True), on_disk, check_dtype=False)
    pd.testing.assert_frame_equal(ratio_table(again), pd.read_csv(out / "ratios.csv"),
                                  check_dtype=False)


def test_failed_runs_count_as_max_iter_and_are_never_dropped(bench_dir):
    result, _ = bench_dir
    runs, summary = result.runs, result.summary
    failed = runs[~runs["success"]]
    assert len(failed) > 0
    assert (failed["iterations"] == 600).all()
    for row in summary.itertuples(index=False):
        g = runs[(runs["scenario"] == row.scenario) & (runs["planner"] == row.planner)]
        assert row.runs == len(g) == 8
        assert row.iterations_median == float(np.median(g["iterations"]))
        assert row.success_rate == g["success"].mean()


def test_our_planners_paths_are_all_certified_and_shortcuts_never_longer(bench_dir, scenarios):
    result, _ = bench_dir
    ok = result.runs[result.runs["success"]]
    assert len(ok) > 0
    assert ok["certified"].astype(bool).all()
    assert (ok["penetration_m"] == 0.0).all()
    assert (ok["cost_short_deg"] <= ok["cost_deg"] + 1e-9).all()
    assert ok["cost_short_deg"].lt(ok["cost_deg"] - 1e-6).any(), "shortcutting never shortened"
    failed = result.runs[~result.runs["success"]]
    assert not failed["found"].any() and not failed["certified"].any()
    assert failed["cost_short_deg"].isna().all() and failed["min_clearance_m"].isna().all()
    assert (ok["found"] & ok["certified"]).all() and (ok["min_clearance_m"] > 0.0).all()
    assert (ok["time_first_s"] == ok["wall_s"]).all()
    assert (result.summary["certified_fraction"].dropna() == 1.0).all()


def test_ratio_table_gives_the_distribution_of_per_scenario_median_ratios(bench_dir):
    result, _ = bench_dir
    s = result.summary.set_index(["scenario", "planner"])["iterations_median"]
    per = [s[(n, "rrt")] / s[(n, "fuzzy-rrt")] for n in ("two-circles", "boxes-and-circle")]
    row = result.ratios.query("metric == 'iterations'").set_index("planner").loc["fuzzy-rrt"]
    assert row["scenarios"] == 2
    assert row["ratio_median"] == pytest.approx(np.median(per))
    assert row["ratio_worst"] == pytest.approx(min(per))
    assert row["ratio_best"] == pytest.approx(max(per))
    fz = result.summary[result.summary["planner"] == "fuzzy-rrt"]
    assert sorted(fz["iter_ratio_vs_rrt"]) == pytest.approx(sorted(per))
    assert result.summary.loc[result.summary["planner"] == "rrt", "iter_ratio_vs_rrt"].eq(1.0).all()


def test_results_do_not_depend_on_the_number_of_workers(scenarios):
    from xfuzzy_rrt.bench.runner import run_benchmark

    kw = dict(runs=4, seed=11, max_iter=2000, shortcut=True)
    one = run_benchmark(scenarios[:1], ["rrt", "fuzzy-rrt"], workers=1, **kw)
    two = run_benchmark(scenarios[:1], ["rrt", "fuzzy-rrt"], workers=2, **kw)
    cols = [c for c in one.runs.columns if c not in ("wall_s", "time_first_s", "time_total_s")]
    assert "work" in cols and one.runs["work"].notna().all() and (one.runs["work"] > 0).all()
    assert one.runs[cols].to_csv(index=False) == two.runs[cols].to_csv(index=False)


def test_pooled_jobs_name_their_scenario_and_rulebook_instead_of_carrying_them(scenarios,
                                                                              monkeypatch):
    # a job that carried them would arrive as new objects in the worker and miss every set-up
    # remembered for the ones it planned with, inside each run's time_total_s
    from xfuzzy_rrt.bench import runner

    sent = []
    real = runner._run_pool

    def spy(jobs, workers, init_args, progress):
        sent.append((jobs, init_args))
        return real(jobs, workers, init_args, progress)

    monkeypatch.setattr(runner, "_run_pool", spy)
    kw = dict(runs=3, seed=5, max_iter=2000)
    two = runner.run_benchmark(scenarios[:2], ["rrt", "fuzzy-rrt"], workers=2, **kw)
    (jobs, init_args), = sent
    assert len(jobs) == 12 and all(type(j) is tuple and len(j) == 5 for j in jobs)
    assert {type(v) for j in jobs for v in j} <= {int, str, bool}
    assert init_args[1] == list(scenarios[:2])  # every scenario, once per worker
    one = runner.run_benchmark(scenarios[:2], ["rrt", "fuzzy-rrt"], workers=1, **kw)
    cols = [c for c in one.runs.columns if c not in ("wall_s", "time_first_s", "time_total_s")]
    assert one.runs[cols].to_csv(index=False) == two.runs[cols].to_csv(index=False)


def test_progress_is_reported_for_every_run_in_order(scenarios):
    from xfuzzy_rrt.bench.runner import run_benchmark

    calls = []
    run_benchmark(scenarios[:1], ["rrt"], runs=5, progress=lambda d, t: calls.append((d, t)))
    assert calls == [(k, 5) for k in range(1, 6)]


def test_progress_bar_writes_plain_lines_when_not_a_terminal():
    from xfuzzy_rrt.cli.bench import ProgressBar

    stream = io.StringIO()
    bar = ProgressBar(stream)
    for k in range(1, 101):
        bar(k, 100)
    lines = stream.getvalue().splitlines()
    assert "\r" not in stream.getvalue()
    assert lines[0] == "bench: 1/100 runs (1%)" and lines[-1] == "bench: 100/100 runs (100%)"
    assert len(lines) == 11


def test_unknown_or_repeated_planner_is_rejected_before_any_run(scenarios):
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.errors import InputError

    with pytest.raises(InputError, match="unknown planner 'rrt-star'"):
        run_benchmark(scenarios, ["rrt", "rrt-star"], runs=1)
    with pytest.raises(InputError, match="listed twice"):
        run_benchmark(scenarios, ["rrt", "rrt"], runs=1)


def test_bench_on_a_directory_runs_every_scenario_in_it(run_cli, tmp_path):
    folder = tmp_path / "scen"
    folder.mkdir()
    shutil.copy(TWO_CIRCLES, folder / "a.toml")
    shutil.copy(BOXES, folder / "b.toml")
    (folder / "notes.txt").write_text("not a scenario")
    out = tmp_path / "out"
    proc = run_cli("bench", folder, "--planners", "rrt", "--runs", "2", "--out", out)
    assert proc.returncode == 0, proc.stderr
    runs = pd.read_csv(out / "runs.csv")
    assert sorted(runs["scenario"].unique()) == ["boxes-and-circle", "two-circles"]
    assert "bench: 4/4 runs (100%)" in proc.stderr
    for name in ("summary.csv", "ratios.csv", "bench.json", "report.html",
                 "examples/index.json"):
        assert (out / name).is_file(), name


def test_bench_on_an_empty_directory_is_one_error_line(run_cli, tmp_path):
    empty = tmp_path / "empty"
    empty.mkdir()
    proc = run_cli("bench", empty, "--runs", "1", "--out", tmp_path / "out")
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [f"error: {empty}: directory contains no *.toml "
                                                "scenario file"]
    assert not (tmp_path / "out").exists()


def test_bench_json_records_scenario_hashes_and_rulebook(bench_dir):
    import hashlib
    import json

    _, out = bench_dir
    meta = json.loads((out / "bench.json").read_text())
    by_name = {e["name"]: e for e in meta["scenarios"]}
    assert by_name["two-circles"]["sha256"] == hashlib.sha256(TWO_CIRCLES.read_bytes()).hexdigest()
    assert by_name["two-circles"]["toml"] == TWO_CIRCLES.read_text()
    from xfuzzy_rrt.fuzzy.rulebook import default_rulebook_path, load_rulebook

    assert meta["rulebook"]["sha256"] == load_rulebook(default_rulebook_path()).sha256
    assert meta["settings"]["shortcut"] is True and meta["settings"]["max_iter"] == 600


#: OMPL's RRTConnect checking motions by sampling them, at the range it had before tuning.
SAMPLED = "ompl:RRTConnect:sampled:range=10"


@pytest.fixture(scope="module")
def ompl_bench(scenarios):
    """RRT and OMPL's RRTConnect with OMPL's own sampled motion check at a 10 deg range on
    two-circles, seeds 0-5 (seed 4 grazes a circle)."""
    from xfuzzy_rrt.bench.runner import run_benchmark

    return run_benchmark(scenarios[:1], ["rrt", SAMPLED], runs=6, max_iter=5000,
                         shortcut=True)


def test_ompl_rows_are_certified_exactly_when_the_exact_oracle_finds_no_collision(ompl_bench,
                                                                                 scenarios):
    from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M
    from xfuzzy_rrt.geometry.path_check import MIN_CLEARANCE_TOL_M
    from xfuzzy_rrt.planners.api import plan_scenario

    oracle = Oracle(TWO_CIRCLES)
    rows = ompl_bench.runs[ompl_bench.runs["planner"] == SAMPLED]
    assert rows["found"].all()
    assert not rows["certified"].all(), "fixture: one of these OMPL paths grazes an obstacle"
    for row in rows.itertuples(index=False):
        again = plan_scenario(scenarios[0], SAMPLED, seed=row.seed, max_iter=5000)
        assert again.iterations == row.iterations  # the same run, so the same path
        problems = oracle.path_problems(again.path_deg)
        dense = float(np.min(oracle.clearance(oracle.densify(again.path_deg, 0.02))))
        assert row.success == (row.found and row.certified)
        # The minimum clearance is exact: nothing on the path is closer (0.1 um), and a dense
        # oracle scan finds it to within its 0.02 deg resolution.
        assert dense >= row.min_clearance_m - MIN_CLEARANCE_TOL_M
        assert dense == pytest.approx(row.min_clearance_m, abs=2e-5)
        assert row.penetration_m == max(0.0, -row.min_clearance_m)
        if row.certified:
            assert problems == [] and row.min_clearance_m > CERT_MARGIN_M
            assert row.cost_short_deg <= row.cost_deg + 1e-9
        else:
            assert problems and row.min_clearance_m < 0.0 and not row.success
            assert np.isnan(row.cost_short_deg), "an uncertified path is never shortened"
    worst = ompl_bench.worst_examples[("two-circles", SAMPLED)]
    assert worst.min_clearance_m == rows["min_clearance_m"].min() and not worst.certified
    assert worst.violation.startswith(f"segment ") and "penetrates an obstacle" in worst.violation
    s = ompl_bench.summary.set_index("planner").loc[SAMPLED]
    assert s["success_rate"] == rows["certified"].mean() < s["found_rate"] == 1.0
    assert s["certified_fraction"] == rows["certified"].mean()
    assert s["min_clearance_min_m"] == rows["min_clearance_m"].min() < 0.0


def test_ompl_is_compared_on_time_to_first_path_and_ours_on_iterations(ompl_bench, bench_dir):
    from xfuzzy_rrt.bench.summary import ratio_table

    summary = ompl_bench.summary.set_index("planner")
    runs = ompl_bench.runs

    def time_median(planner):
        g = runs[runs["planner"] == planner]
        return float(np.median(np.where(g["success"], g["time_first_s"], g["wall_s"])))

    assert summary.loc[SAMPLED, "time_first_median_s"] == time_median(SAMPLED)
    expected = time_median("rrt") / time_median(SAMPLED)
    assert np.isnan(summary.loc[SAMPLED, "iter_ratio_vs_rrt"])
    assert summary.loc[SAMPLED, "time_ratio_vs_rrt"] == pytest.approx(expected)
    row = ompl_bench.ratios.query("metric == 'time_first_s'").set_index("planner").loc[
        SAMPLED]
    assert row["metric"] == "time_first_s" and row["ratio_median"] == pytest.approx(expected)
    assert row["ratio_geomean"] == pytest.approx(expected)
    ours = ratio_table(bench_dir[0].summary).query("metric == 'iterations'").set_index(
        "planner").loc["fuzzy-rrt"]
    assert ours["metric"] == "iterations"
    per = bench_dir[0].summary.query("planner == 'fuzzy-rrt'")["iter_ratio_vs_rrt"]
    assert ours["ratio_geomean"] == pytest.approx(float(np.exp(np.mean(np.log(per)))))


def test_several_rulebooks_run_side_by_side_one_row_each(scenarios, tmp_path):
    import json

    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.bench.store import load_bench_dir, write_bench_dir
    from xfuzzy_rrt.fuzzy.rulebook import default_rulebook_path, load_rulebook, rulebooks_dir
    from xfuzzy_rrt.planners.api import plan_scenario

    mine = tmp_path / "mine"
    shutil.copytree(rulebooks_dir() / "expert", mine)
    labels = ["rrt", "fuzzy-rrt", "fuzzy-rrt:paper", f"fuzzy-rrt:{mine}"]
    result = run_benchmark(scenarios[:1], labels, runs=3, max_iter=3000)
    assert list(result.summary["planner"]) == labels
    sha = {"fuzzy-rrt": load_rulebook(default_rulebook_path()).sha256,
           "fuzzy-rrt:paper": load_rulebook(rulebooks_dir() / "paper").sha256,
           f"fuzzy-rrt:{mine}": load_rulebook(mine).sha256}
    assert len(set(sha.values())) == 3
    for label, digest in sha.items():
        rows = result.runs[result.runs["planner"] == label]
        assert len(rows) == 3 and (rows["rulebook_sha256"] == digest).all()
    paper = result.runs[result.runs["planner"] == "fuzzy-rrt:paper"]
    direct = [plan_scenario(scenarios[0], "fuzzy-rrt", rulebook=rulebooks_dir() / "paper",
                            seed=k, max_iter=3000).iterations for k in range(3)]
    assert list(paper["iterations"]) == direct and (paper["rulebook"] == "paper").all()
    assert set(result.ratios["planner"]) == set(sha)
    out = tmp_path / "bench"
    write_bench_dir(result, out, {"command": "test"})
    meta = json.loads((out / "bench.json").read_text())
    assert {e["planner"]: e["sha256"] for e in meta["rulebooks"]} == sha
    assert {e["planner"]: e["dir"] for e in meta["rulebooks"]}[f"fuzzy-rrt:{mine}"] == str(mine)
    back = load_bench_dir(out)
    assert {k: v.sha256 for k, v in back.rulebooks.items()} == sha
    assert set(back.worst_examples) == set(back.examples)
    for key, r in result.worst_examples.items():
        assert back.worst_examples[key].seed == r.seed
        assert back.worst_examples[key].min_clearance_m == r.min_clearance_m
    assert set(back.examples) == {("two-circles", p) for p in labels}
    assert all(back.examples[("two-circles", p)].trace is not None for p in sha)


@pytest.mark.skipif(not (SHARED_SCENARIOS / "paper-reference.toml").is_file(),
                    reason="shared scenarios not present")
def test_ompl_planner_runs_beside_ours_and_its_paths_are_certified_or_flagged(tmp_path):
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.geometry.scenario import load_scenario

    path = SHARED_SCENARIOS / "paper-reference.toml"
    result = run_benchmark([load_scenario(path)], ["rrt", "ompl:RRTConnect"], runs=3,
                           max_iter=5000, shortcut=True)
    oracle = Oracle(path)
    ompl_rows = result.runs[result.runs["planner"] == "ompl:RRTConnect"]
    assert ompl_rows["success"].any()
    for row in ompl_rows[ompl_rows["success"]].itertuples(index=False):
        assert row.certified and row.found and row.min_clearance_m > 0.0
        assert row.cost_short_deg <= row.cost_deg + 1e-9
    example = result.examples[("paper-reference", "ompl:RRTConnect")]
    problems = oracle.path_problems(example.path_deg)
    row = ompl_rows[ompl_rows["seed"] == example.seed].iloc[0]
    # never silently accepted: a path the oracle rejects is not certified
    assert not problems or not bool(row["certified"])
