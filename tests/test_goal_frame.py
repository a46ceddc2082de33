"""The goal-frame rulebook semantics: the same product promises as the paper's semantics.

A goal-frame rulebook lints, round-trips through its text and FLL, plans deterministically with
certified paths, traces every decision and explains it with numbers equal to the trace; its GA
training with the log-ratio and work-cvar fitnesses and held-out validation reproduces across
worker counts and Dask; and the protocol command reports ratios that follow from its own runs table.
"""

from __future__ import annotations

import shutil
import subprocess
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from conftest import FIXTURES, console_script, run_main
from exact_geometry import Oracle
from xfuzzy_rrt.analysis.explain import explain_row, trace_row
from xfuzzy_rrt.errors import RulebookError
from xfuzzy_rrt.fuzzy import semantics
from xfuzzy_rrt.fuzzy.engine import evaluate
from xfuzzy_rrt.fuzzy.fll import export_fll, import_fll
from xfuzzy_rrt.fuzzy.rulebook import Rulebook, load_rulebook, save_rulebook
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt
from xfuzzy_rrt.planners.goal_frame import arm_lever
from xfuzzy_rrt.planners.rrt import plan_rrt
from xfuzzy_rrt.planners.tuned import tuned_params
from xfuzzy_rrt.training.evaluate import TrainingProblem, iterations_for, log_ratio_fitness
from xfuzzy_rrt.training.genome import constant_outputs_genome, decode, encode


@pytest.fixture
def run_cli():
    """The CLI through ``main(argv)`` in this process (``conftest.run_main``): these tests
    check what commands print, return and write, not the process; ~1.5 s less a call."""
    return run_main


SCENARIOS = [FIXTURES / "scenarios" / "two-circles.toml", FIXTURES / "scenarios" / "boxes-and-circle.toml"]
GF = semantics.GOAL_FRAME


def _rulebook(values=(0.3, 0.2, 60.0, 20.0, 45.0, 15.0), jitter: float = 0.0, seed: int = 0) -> Rulebook:
    """A goal-frame rulebook: constant outputs, optionally with per-rule noise (so rules differ)."""
    knots = np.array([[GF.default_knots(n) for n in GF.inputs]] * 6)
    consts = np.array([[v] * 625 for v in values], dtype=float)
    if jitter:
        rng = np.random.default_rng(seed)
        lo = np.array([GF.output_ranges[o][0] for o in GF.outputs])[:, None]
        hi = np.array([GF.output_ranges[o][1] for o in GF.outputs])[:, None]
        consts = np.clip(consts + jitter * (hi - lo) * rng.standard_normal(consts.shape), lo, hi)
    return Rulebook.from_arrays(knots, consts, name="gf", bounds_mode=None, semantics=GF,
                                provenance={"kind": "test"})


def test_goal_frame_rulebook_round_trips_through_text_and_names_its_semantics(tmp_path):
    rb = _rulebook(jitter=0.1)
    save_rulebook(rb, tmp_path / "gf")
    manifest = (tmp_path / "gf" / "rulebook.toml").read_text()
    assert 'semantics = "goal-frame"' in manifest and "bounds_mode" not in manifest
    assert sorted(p.name for p in (tmp_path / "gf").glob("*.fis")) == sorted(f"{o}.fis" for o in GF.outputs)
    back = load_rulebook(tmp_path / "gf")
    assert back.semantics is GF and back.sha256 == rb.sha256
    assert back.inputs == ("joint_dist_to_goal", "stagnation", "clearance_deg", "reject_rate")
    text = (tmp_path / "gf" / "ahead_deg.fis").read_text()
    assert "input joint_dist_to_goal range 0.0 360.0" in text and "then ahead_deg = " in text


def test_paper_rulebooks_keep_their_bytes_without_a_semantics_key(tmp_path):
    from xfuzzy_rrt.fuzzy.rulebook import rulebooks_dir

    rb = load_rulebook(rulebooks_dir() / "paper")
    save_rulebook(rb, tmp_path / "p")
    for f in (rulebooks_dir() / "paper").glob("*.fis"):
        assert (tmp_path / "p" / f.name).read_bytes() == f.read_bytes()
    assert "semantics" not in (tmp_path / "p" / "rulebook.toml").read_text()


def test_mixed_semantics_are_one_clear_lint_error_each(tmp_path, run_cli):
    save_rulebook(_rulebook(), tmp_path / "gf")
    manifest = tmp_path / "gf" / "rulebook.toml"
    manifest.write_text(manifest.read_text().replace('semantics = "goal-frame"\n',
                                                     'semantics = "goal-frame"\nbounds_mode = "relative"\n'))
    proc = run_cli("rules", "lint", tmp_path / "gf")
    assert proc.returncode == 2 and "bounds_mode belongs to the paper's semantics" in proc.stderr
    assert "Traceback" not in proc.stderr
    # a paper input inside a goal-frame file
    save_rulebook(_rulebook(), tmp_path / "gf2")
    fis = tmp_path / "gf2" / "side_deg.fis"
    fis.write_text(fis.read_text().replace("input stagnation range 0.0 200.0",
                                           "input dist_to_goal range 0.0 0.6"))
    with pytest.raises(RulebookError) as err:
        load_rulebook(tmp_path / "gf2")
    assert any("side_deg.fis" in p[0] and p[1] is not None for p in err.value.problems)
    proc = run_cli("rules", "lint", tmp_path / "gf2")
    assert proc.returncode == 2 and "side_deg.fis:" in proc.stderr


def test_manifest_typo_names_the_nearest_key(tmp_path, run_cli):
    save_rulebook(_rulebook(), tmp_path / "gf")
    manifest = tmp_path / "gf" / "rulebook.toml"
    manifest.write_text(manifest.read_text().replace("semantics =", "semantic ="))
    proc = run_cli("rules", "lint", tmp_path / "gf")
    assert proc.returncode == 2
    assert "rulebook.toml:5: unknown key 'semantic' (did you mean 'semantics'?)" in proc.stderr


def test_goal_frame_rulebook_round_trips_through_fll(tmp_path):
    rb = _rulebook(jitter=0.2, seed=3)
    export_fll(rb, tmp_path / "fll")
    back = import_fll(tmp_path / "fll")
    assert back.semantics is GF and back.bounds_mode is None
    X = np.random.default_rng(1).random((50, 4)) * np.array([360, 200, 30, 1])
    np.testing.assert_array_equal(evaluate(*back.compiled, X), evaluate(*rb.compiled, X))


def test_goal_frame_plans_are_deterministic_and_certified_by_the_exact_oracle():
    rb = _rulebook(jitter=0.1)
    for file in SCENARIOS:
        sc = load_scenario(file)
        oracle = Oracle(file)
        for seed in range(5):
            a = plan_fuzzy_rrt(sc, rulebook=rb, seed=seed)
            b = plan_fuzzy_rrt(sc, rulebook=rb, seed=seed)
            assert a.success and a.params["semantics"] == "goal-frame"
            assert np.array_equal(a.path_deg, b.path_deg) and a.iterations == b.iterations
            assert np.array_equal(a.path_deg[0], np.array(sc.start_deg)) and np.array_equal(a.path_deg[-1], np.array(sc.goal_deg))
            assert oracle.path_problems(a.path_deg) == []


def test_goal_frame_trace_explains_every_decision_with_the_traced_numbers():
    rb = _rulebook(jitter=0.15, seed=2)
    sc = load_scenario(SCENARIOS[1])
    res = plan_fuzzy_rrt(sc, rulebook=rb, seed=4, trace=True)
    t = res.trace
    assert list(t.columns[7:11]) == list(GF.inputs)
    assert set(GF.outputs) <= set(t.columns) and "ahead_deg_rule_0" in t.columns
    # the inputs mean what the semantics says
    first = t.iloc[0]
    assert first["joint_dist_to_goal"] == pytest.approx(float(np.hypot(*(np.subtract(sc.goal_deg, sc.start_deg)))))
    assert first["stagnation"] == 0.0 and first["reject_rate"] == 0.0
    assert (t["stagnation"] >= 0).all() and t["reject_rate"].between(0, 1).all()
    for it in (1, len(t) // 2, len(t)):
        e = explain_row(trace_row(t, it), rb)
        assert e.max_discrepancy < 1e-12
        assert [s.output for s in e.systems] == list(GF.outputs)


def test_samples_lie_in_the_goal_frame_box_laid_along_the_direction_to_the_goal():
    rb = _rulebook(values=(0.1, 0.3, 50.0, 10.0, 20.0, 8.0))
    sc = load_scenario(SCENARIOS[0])
    t = plan_fuzzy_rrt(sc, rulebook=rb, seed=2, trace=True).trace
    goal = np.array(sc.goal_deg)
    box = t[~t["goal_sampled"]]
    full = (box["box_q1_lo"] == -180) & (box["box_q1_hi"] == 180) & (box["box_q2_lo"] == -180)
    assert 0 < full.mean() < 1  # uniform samples (whole joint space) and goal-frame boxes
    framed = box[~full]
    q = framed[["from_q1_deg", "from_q2_deg"]].to_numpy()
    s = framed[["sample_q1_deg", "sample_q2_deg"]].to_numpy()
    e = goal - q
    e /= np.linalg.norm(e, axis=1, keepdims=True)
    along = ((s - q) * e).sum(axis=1)
    across = (s - q)[:, 0] * -e[:, 1] + (s - q)[:, 1] * e[:, 0]
    inside = (s > -180) & (s < 180)  # clamping moves a sample onto a limit, out of the frame
    ok = inside.all(axis=1)
    assert ok.mean() > 0.5
    assert (along[ok] >= -10.0 - 1e-9).all() and (along[ok] <= 50.0 + 1e-9).all()
    assert (np.abs(across[ok]) <= 20.0 + 1e-9).all()
    for c, lo, hi in (("sample_q1_deg", "box_q1_lo", "box_q1_hi"), ("sample_q2_deg", "box_q2_lo", "box_q2_hi")):
        assert (framed[c] >= framed[lo] - 1e-9).all() and (framed[c] <= framed[hi] + 1e-9).all()


def test_clearance_input_is_a_certified_free_radius_in_joint_space():
    """Within clearance_deg of a node every configuration is collision-free (sampled check)."""
    rb = _rulebook()
    sc = load_scenario(SCENARIOS[1])
    t = plan_fuzzy_rrt(sc, rulebook=rb, seed=1, trace=True).trace
    a = sc.arrays()
    assert arm_lever(a.links) == pytest.approx(np.hypot(a.links.sum(), a.links[1]))
    rng = np.random.default_rng(0)
    from xfuzzy_rrt.geometry.collision import clearance

    for row in t.sample(20, random_state=0).itertuples():
        q = np.array([row.from_q1_deg, row.from_q2_deg])
        r = min(row.clearance_deg, 30.0)
        for _ in range(20):
            d = rng.standard_normal(2)
            q2 = q + d / np.linalg.norm(d) * r * 0.999
            assert clearance(a, q2) > 0.0


def test_log_ratio_fitness_is_the_mean_log_of_rrt_median_over_iterations():
    its = np.array([[[50, 100], [-1, 400]]])  # 1 individual, 2 problems x 2 runs
    got = log_ratio_fitness(its, np.array([100.0, 400.0]), 1000)
    want = np.mean(np.log([100 / 50, 100 / 100, 400 / 1000, 400 / 400]))
    assert got[0] == pytest.approx(want)


def test_compiled_goal_frame_evaluation_matches_the_planner_run_for_run():
    scenarios = [load_scenario(p) for p in SCENARIOS]
    rng = np.random.default_rng(9)
    base = constant_outputs_genome((0.3, 0.2, 60.0, 20.0, 45.0, 15.0), "goal-frame")
    genes = np.clip(base + 0.1 * rng.standard_normal((3, base.size)), 0, 1)
    knots, consts = decode(genes, "goal-frame")
    seeds = np.array([3, 4])
    its = iterations_for([TrainingProblem.from_scenario(s) for s in scenarios], knots, consts,
                         "goal-frame", seeds, 3000)
    for p in range(3):
        rb = Rulebook.from_arrays(knots[p], consts[p], name="x", bounds_mode=None,
                                  semantics=GF, provenance={"kind": "test"})
        assert np.allclose(encode(*rb.arrays(), "goal-frame"), np.clip(genes[p], 0, 1), atol=1e-12)
        for k, s in enumerate(scenarios):
            for r, seed in enumerate(seeds):
                res = plan_fuzzy_rrt(s, rb, seed=int(seed), max_iter=3000)
                assert its[p, k, r] == (res.iterations if res.success else -1)


def _train(cwd: Path, *extra: str, fitness: str = "log-ratio") -> subprocess.CompletedProcess:
    args = [console_script(), "train", "--scenario", str(SCENARIOS[0]),
            "--validation-scenario", str(SCENARIOS[1]), "--bounds", "goal-frame",
            "--fitness", fitness, "--population", "10", "--generations", "3",
            "--runs-per-eval", "2", "--validation-runs", "2", "--seed", "5", "--out", "rb", *extra]
    return subprocess.run(args, cwd=cwd, capture_output=True, text=True, timeout=600)


@pytest.mark.parametrize("fitness,baseline", [("log-ratio", "baseline_iterations"),
                                              ("work-cvar", "baseline_work"),
                                              ("work-cost-cvar", "baseline_cost_deg")])
def test_training_with_validation_reproduces_across_workers_and_dask(tmp_path, fitness, baseline):
    distributed = pytest.importorskip("distributed")
    outputs = {}

    def collect(label):
        folder = tmp_path / label / "rb"
        files = {p.name: p.read_bytes() for p in folder.iterdir() if p.is_file() and p.name != "history.csv"}
        hist = pd.read_csv(folder / "history.csv").drop(columns=["wall_s", "runs_per_s"])
        return files, hist

    for label, extra in (("one", ["--workers", "1"]), ("two", ["--workers", "2"])):
        (tmp_path / label).mkdir()
        proc = _train(tmp_path / label, *extra, fitness=fitness)
        assert proc.returncode == 0, proc.stderr
        outputs[label] = collect(label)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  protocol="tcp://", host="127.0.0.1", dashboard_address=None) as cluster:
        (tmp_path / "dask").mkdir()
        proc = _train(tmp_path / "dask", "--scheduler", cluster.scheduler_address, fitness=fitness)
        assert proc.returncode == 0, proc.stderr
        outputs["dask"] = collect("dask")
    files, hist = outputs["one"]
    assert hist["validation_fitness"].notna().all()  # the train / validation gap per generation
    manifest = files["rulebook.toml"].decode()
    assert 'semantics = "goal-frame"' in manifest and f'fitness = "{fitness}"' in manifest
    assert baseline in manifest and "validation_scenarios" in manifest
    assert "--validation-scenario" in manifest and f"--fitness {fitness}" in manifest
    for label in ("two", "dask"):
        assert outputs[label][0] == files, label
        pd.testing.assert_frame_equal(outputs[label][1], hist)
    rb = load_rulebook(tmp_path / "one" / "rb")
    assert rb.semantics is GF


def test_protocol_ratios_follow_from_its_own_runs_table(tmp_path, run_cli):
    save_rulebook(_rulebook(), tmp_path / "gf")
    proc = run_cli("evaluate", *SCENARIOS, "--rulebook", tmp_path / "gf", "--runs", "6",
                   "--out", tmp_path / "out")
    assert proc.returncode == 0, proc.stderr
    assert "fuzzy-rrt:gf" in proc.stdout and "geomean" in proc.stdout
    runs = pd.read_csv(tmp_path / "out" / "runs.csv")
    problems = pd.read_csv(tmp_path / "out" / "problems.csv")
    summary = pd.read_csv(tmp_path / "out" / "summary.csv")
    # RRT, the tuned RRT (evaluated by default) and the rulebook
    assert len(runs) == 2 * 3 * 6 and set(runs["seed"]) == set(range(6))
    ratios = []
    for file in SCENARIOS:
        sc = load_scenario(file)
        rrt = np.median([plan_rrt(sc, seed=s).iterations for s in range(6)])
        fz = np.median([plan_fuzzy_rrt(sc, rulebook=tmp_path / "gf", seed=s).iterations for s in range(6)])
        row = problems[(problems["scenario"] == sc.name) & (problems["planner"] == "fuzzy-rrt:gf")]
        assert row["iteration_ratio"].item() == pytest.approx(rrt / fz)
        ratios.append(rrt / fz)
    gf = summary[summary["planner"] == "fuzzy-rrt:gf"].iloc[0]
    assert gf["median_ratio"] == pytest.approx(np.median(ratios))
    assert gf["geomean_ratio"] == pytest.approx(np.exp(np.mean(np.log(ratios))))
    assert gf["worst_ratio"] == pytest.approx(min(ratios))
    # path length against the tuned peer (issue 25's cost aim), from the same runs
    tuned = tuned_params("rrt")
    longer = []
    for file in SCENARIOS:
        sc = load_scenario(file)
        peer = np.median([plan_rrt(sc, seed=s, **tuned).cost_deg for s in range(6)])
        ours = np.median([plan_fuzzy_rrt(sc, rulebook=tmp_path / "gf", seed=s).cost_deg
                          for s in range(6)])
        row = problems[(problems["scenario"] == sc.name) & (problems["planner"] == "fuzzy-rrt:gf")]
        assert row["cost_peer_ratio"].item() == pytest.approx(ours / peer)
        longer.append(ours / peer)
    assert gf["median_cost_peer_ratio"] == pytest.approx(np.median(longer))
    assert gf["worst_cost_peer_ratio"] == pytest.approx(max(longer))
    assert gf["problems_longer_than_peer"] == sum(x > 1 for x in longer)
    assert "cost/peer" in proc.stdout


def test_protocol_rejects_an_unknown_rulebook_with_one_line(run_cli):
    proc = run_cli("evaluate", SCENARIOS[0], "--rulebook", "no-such-rulebook", "--runs", "2")
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [
        "error: --rulebook: 'no-such-rulebook' is neither a shipped rulebook nor a directory"]


def test_rule_analysis_tools_work_on_goal_frame_rulebooks(tmp_path, run_cli):
    save_rulebook(_rulebook(jitter=0.05, seed=8), tmp_path / "gf")
    proc = run_cli("rules", "coverage", tmp_path / "gf", SCENARIOS[0], "--runs", "3",
                   "--out", tmp_path / "cov.csv")
    assert proc.returncode == 0, proc.stderr
    cov = pd.read_csv(tmp_path / "cov.csv")
    assert set(cov["output"]) == set(GF.outputs) and len(cov) == 6 * 625
    proc = run_cli("rules", "simplify", tmp_path / "gf", "--out", tmp_path / "simple")
    assert proc.returncode == 0, proc.stderr
    assert load_rulebook(tmp_path / "simple").semantics is GF
    proc = run_cli("rules", "diff", tmp_path / "gf", tmp_path / "simple")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    proc = run_cli("rules", "show", tmp_path / "gf", "--when", "stagnation=stuck,reject_rate=blocked")
    assert proc.returncode == 0 and "uniform_share" in proc.stdout
    proc = run_cli("rules", "show", tmp_path / "gf", "--when", "dist_to_goal=near")
    assert proc.returncode == 2 and "unknown input 'dist_to_goal'" in proc.stderr


def test_protocol_with_a_clearance_skips_problems_whose_ends_cannot_keep_it(tmp_path, run_cli):
    proc = run_cli("evaluate", *SCENARIOS, "--rulebook", "goal-frame", "--runs", "2",
                   "--clearance", "0.5")
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines()[-1] == (
        "error: --clearance: no problem's start and goal keep this clearance")
    assert "note: skipped two-circles" in proc.stderr
    ok = run_cli("evaluate", *SCENARIOS, "--rulebook", "goal-frame", "--runs", "2",
                 "--clearance", "0.002", "--out", tmp_path / "o")
    assert ok.returncode == 0, ok.stderr
    runs = pd.read_csv(tmp_path / "o" / "runs.csv")
    assert runs["success"].all()


def test_explain_says_what_goal_frame_inputs_measure(tmp_path, run_cli):
    trace = tmp_path / "t.csv"
    assert run_cli("plan", SCENARIOS[0], "--seed", "1", "--trace", trace).returncode == 0
    for extra in ((), ("--exact",)):
        proc = run_cli("explain", trace, "--iteration", "2", *extra)
        assert proc.returncode == 0, proc.stderr
        head = proc.stdout.splitlines()
        assert head[0].endswith("(goal-frame semantics)")
        assert head[2].startswith("Inputs (measured at the current node, in joint space")
        assert "sampling region" in proc.stdout and "end effector" not in proc.stdout


def test_evaluate_without_a_rulebook_evaluates_the_shipped_default(run_cli, tmp_path):
    proc = run_cli("evaluate", SCENARIOS[0], "--runs", "1", "--out", tmp_path / "ev")
    assert proc.returncode == 0, proc.stderr
    assert "fuzzy-rrt:goal-frame " in proc.stdout and "general" not in proc.stdout
