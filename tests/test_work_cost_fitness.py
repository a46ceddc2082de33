"""Training on work *and* path length against the tuned peer (``--fitness work-cost-cvar``).

Issue 25 asks the default planner for a median path cost no higher than the tuned RRT's; trained
on work alone, the 2-joint default learnt long steps and paid with paths a few per cent longer.
So a training run can also measure each found path's cost (the planner's own ``cost_deg``), and
the fitness subtracts a weighted mean log ratio of path costs against the tuned RRT's median.
"""

from __future__ import annotations

import numpy as np
import pytest

from conftest import FIXTURES, run_main
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy import semantics
from xfuzzy_rrt.fuzzy.rulebook import Rulebook
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt
from xfuzzy_rrt.planners.rrt import plan_rrt
from xfuzzy_rrt.planners.tuned import tuned_params
from xfuzzy_rrt.training.evaluate import (
    COST_UNIT_DEG,
    TrainingProblem,
    iterations_for,
    median_path_costs,
    tuned_rrt_baselines,
    work_cost_cvar_fitness,
    work_cvar_fitness,
)
from xfuzzy_rrt.training.ga import GAConfig
from xfuzzy_rrt.training.genome import constant_outputs_genome, decode

SCENARIOS = [FIXTURES / "scenarios" / "two-circles.toml",
             FIXTURES / "scenarios" / "boxes-and-circle.toml"]
GF = semantics.GOAL_FRAME


def _runs(its, work, cost_deg):
    cost = np.rint(np.asarray(cost_deg, dtype=float) / COST_UNIT_DEG)
    return np.stack(np.broadcast_arrays(np.asarray(its), np.asarray(work), cost),
                    axis=-1).astype(np.int64)


def _population(seed=4, n=2):
    rng = np.random.default_rng(seed)
    base = constant_outputs_genome((0.2, 0.3, 90.0, 30.0, 60.0, 60.0), "goal-frame")
    genes = np.clip(base + 0.1 * rng.standard_normal((n, base.size)), 0, 1)
    return decode(genes, "goal-frame")


def test_measured_training_runs_report_the_planners_own_path_cost():
    scenarios = [load_scenario(p) for p in SCENARIOS]
    knots, consts = _population()
    seeds = np.array([0, 7, 11])
    problems = [TrainingProblem.from_scenario(s) for s in scenarios]
    runs = iterations_for(problems, knots, consts, "goal-frame", seeds, 3000, measure="cost")
    assert runs.shape == (2, 2, 3, 3)
    work = iterations_for(problems, knots, consts, "goal-frame", seeds, 3000, measure="work")
    np.testing.assert_array_equal(runs[..., :2], work)  # the same runs, one more column
    for p in range(2):
        rb = Rulebook.from_arrays(knots[p], consts[p], name="x", bounds_mode=None,
                                  semantics=GF, provenance={"kind": "test"})
        for k, s in enumerate(scenarios):
            for r, seed in enumerate(seeds):
                res = plan_fuzzy_rrt(s, rb, seed=int(seed), max_iter=3000)
                assert res.success
                assert runs[p, k, r, 2] == round(res.cost_deg / COST_UNIT_DEG) > 0


def test_a_failed_run_has_no_path_cost():
    problems = [TrainingProblem.from_scenario(load_scenario(SCENARIOS[1]))]
    knots, consts = _population()
    runs = iterations_for(problems, knots, consts, "goal-frame", np.arange(4), 1, measure="cost")
    failed = runs[..., 0] < 0
    assert failed.any()
    assert (runs[..., 2][failed] == -1).all()


def test_work_cost_cvar_is_work_cvar_when_every_path_costs_the_peers_median():
    b_work = np.array([100.0, 400.0, 50.0])
    b_cost = np.array([200.0, 350.0, 90.0])
    its = np.full((2, 3, 4), 5)
    work = np.array([[[80, 120, 90, 100]] * 3, [[300, 20, 60, 70]] * 3])
    runs = _runs(its, work, np.broadcast_to(b_cost[None, :, None], its.shape))
    got = work_cost_cvar_fitness(runs, b_work, b_cost, weight=3.0)
    np.testing.assert_allclose(got, work_cvar_fitness(runs[..., :2], b_work), atol=1e-9)


def test_shorter_paths_score_higher_at_the_same_work_and_the_weight_scales_the_term():
    b_work = np.array([100.0, 100.0])
    b_cost = np.array([100.0, 200.0])
    its = np.ones((2, 2, 3))
    work = np.full((2, 2, 3), 100)
    cost = np.stack([np.broadcast_to(np.array([90.0, 180.0])[:, None], (2, 3)),
                     np.broadcast_to(np.array([110.0, 220.0])[:, None], (2, 3))])
    runs = _runs(its, work, cost)
    f = {w: work_cost_cvar_fitness(runs, b_work, b_cost, weight=w) for w in (0.0, 1.0, 2.0)}
    assert f[0.0] == pytest.approx([0.0, 0.0], abs=1e-12)  # same work as the peer
    assert f[1.0][0] > 0.0 > f[1.0][1]
    assert f[1.0][0] == pytest.approx(-np.log(0.9), rel=1e-6)
    np.testing.assert_allclose(f[2.0] - f[0.0], 2 * (f[1.0] - f[0.0]), rtol=1e-9)


def test_the_cost_term_takes_the_median_over_successful_runs_and_skips_unsolved_problems():
    its = np.array([[[3, -1, 4], [-1, -1, -1]]])
    work = np.full((1, 2, 3), 100)
    cost = np.array([[[90.0, 0.0, 130.0], [0.0, 0.0, 0.0]]])
    runs = _runs(its, work, cost)
    runs[..., 2][runs[..., 0] < 0] = -1
    med = median_path_costs(runs)
    assert med[0, 0] == pytest.approx(110.0) and np.isnan(med[0, 1])
    b_work, b_cost = np.array([100.0, 100.0]), np.array([110.0, 50.0])
    got = work_cost_cvar_fitness(runs, b_work, b_cost, weight=1.0)
    # the solved problem's paths cost the peer's median: only the work term (and its failure)
    np.testing.assert_allclose(got, work_cvar_fitness(runs[..., :2], b_work), atol=1e-9)


def test_work_cost_cvar_rejects_runs_without_costs_and_a_bad_weight():
    with pytest.raises(ValueError, match=r"runs \[P, S, R, 3\]"):
        work_cost_cvar_fitness(np.ones((1, 2, 3, 2), dtype=np.int64), np.ones(2), np.ones(2))
    with pytest.raises(ValueError, match="cost weight"):
        work_cost_cvar_fitness(np.ones((1, 2, 3, 3), dtype=np.int64), np.ones(2), np.ones(2),
                               weight=-1.0)


def test_the_cost_baseline_is_the_tuned_rrts_median_path_cost():
    scenarios = [load_scenario(p) for p in SCENARIOS]
    tuned = tuned_params("rrt")
    work, cost = tuned_rrt_baselines([TrainingProblem.from_scenario(s) for s in scenarios],
                                     np.arange(5), 3000)
    for s, w, c in zip(scenarios, work, cost):
        runs = [plan_rrt(s, seed=k, max_iter=3000, **tuned) for k in range(5)]
        assert w == np.median([r.work for r in runs])
        assert c == pytest.approx(np.median([r.cost_deg for r in runs if r.success]), abs=1e-6)


@pytest.mark.parametrize("bounds,reason", [("absolute", "counts the planner's work"),
                                           ("goal-frame-any", "measures path cost")])
def test_work_cost_cvar_is_refused_where_the_evaluation_cannot_measure_cost(bounds, reason):
    with pytest.raises(InputError, match=reason) as err:
        GAConfig(bounds=bounds, fitness="work-cost-cvar", scenarios=(("a", "0"),),
                 baseline=(100.0,), baseline_cost=(100.0,))
    assert err.value.where == "--fitness"


def test_work_cost_cvar_needs_a_positive_cost_baseline_per_scenario():
    with pytest.raises(InputError, match="median path cost") as err:
        GAConfig(bounds="goal-frame", fitness="work-cost-cvar", scenarios=(("a", "0"),),
                 baseline=(100.0,), baseline_cost=(float("nan"),))
    assert err.value.where == "--fitness"


def test_the_cost_weight_enters_the_fingerprint_only_when_not_the_default():
    kw = dict(bounds="goal-frame", fitness="work-cost-cvar", scenarios=(("a", "0"),),
              baseline=(100.0,), baseline_cost=(50.0,))
    one, two = GAConfig(**kw), GAConfig(**kw, cost_weight=2.0)
    assert one.fingerprint() != two.fingerprint()
    plain = GAConfig(bounds="goal-frame", fitness="work-cvar", scenarios=(("a", "0"),),
                     baseline=(100.0,))
    # a run without the cost term keeps the fingerprint (and checkpoints) it had before it
    assert not _fingerprinted(plain) & {"baseline_cost", "validation_baseline_cost",
                                        "cost_weight"}
    assert "cost_weight" in _fingerprinted(two) and "baseline_cost" in _fingerprinted(one)


def _fingerprinted(config):
    from dataclasses import asdict

    return {k for k, v in asdict(config).items() if k not in config.STOPPING
            and not (k in config.LATER and v == config.LATER[k])}


@pytest.mark.parametrize("value", ["-1", "nan", "inf"])
def test_a_bad_cost_weight_is_one_line_and_writes_nothing(tmp_path, value):
    out = tmp_path / "rb"
    proc = run_main("train", "--scenario", SCENARIOS[0], "--bounds", "goal-frame",
                    "--fitness", "work-cost-cvar", "--cost-weight", value,
                    "--generations", "1", "--out", out)
    errors = [ln for ln in proc.stderr.splitlines() if ln.startswith("error")]
    assert proc.returncode == 2 and not out.exists(), proc.stderr
    assert len(errors) == 1 and errors[0].startswith("error: --cost-weight:")
    assert "Traceback" not in proc.stderr


def test_a_non_default_cost_weight_is_in_the_recorded_command(tmp_path):
    out = tmp_path / "rb"
    proc = run_main("train", "--scenario", SCENARIOS[0], "--bounds", "goal-frame",
                    "--fitness", "work-cost-cvar", "--cost-weight", "2.5", "--population", "6",
                    "--elite", "1", "--generations", "1", "--runs-per-eval", "1",
                    "--validation-runs", "1", "--workers", "1", "--out", out)
    assert proc.returncode == 0, proc.stderr
    manifest = (out / "rulebook.toml").read_text()
    assert "--fitness work-cost-cvar --cost-weight 2.5" in manifest
    assert "cost_weight = 2.5" in manifest and "baseline_cost_deg" in manifest


def test_a_cost_weight_without_the_cost_fitness_is_refused_before_any_baseline(tmp_path):
    out = tmp_path / "rb"
    proc = run_main("train", "--scenario", SCENARIOS[0], "--bounds", "goal-frame",
                    "--fitness", "work-cvar", "--cost-weight", "2", "--generations", "1",
                    "--out", out)
    errors = [ln for ln in proc.stderr.splitlines() if ln.startswith("error")]
    assert proc.returncode == 2 and not out.exists(), proc.stderr
    assert errors == ["error: --cost-weight: weighs path cost in --fitness work-cost-cvar only, "
                      "not in work-cvar"]
    assert "computing" not in proc.stderr  # refused before the tuned RRT's baselines
    with pytest.raises(InputError, match="work-cost-cvar only") as err:
        GAConfig(bounds="goal-frame", fitness="work-cvar", scenarios=(("a", "0"),),
                 baseline=(100.0,), cost_weight=2.0)
    assert err.value.where == "--cost-weight"


def test_work_cost_cvar_runs_the_tuned_rrt_once_per_scenario_for_both_baselines(tmp_path,
                                                                                  monkeypatch):
    from xfuzzy_rrt.training import evaluate

    calls = []
    real = evaluate.rrt_runs
    monkeypatch.setattr(evaluate, "rrt_runs", lambda pr, *a: calls.append(pr.name) or real(pr, *a))
    out = tmp_path / "rb"
    proc = run_main("train", "--scenario", SCENARIOS[0], "--validation-scenario", SCENARIOS[1],
                    "--bounds", "goal-frame", "--fitness", "work-cost-cvar", "--population", "6",
                    "--elite", "1", "--generations", "1", "--runs-per-eval", "1",
                    "--validation-runs", "1", "--workers", "1", "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert sorted(calls) == sorted(load_scenario(p).name for p in SCENARIOS)


def test_a_misspelt_fitness_is_named_before_the_cost_weight(tmp_path):
    out = tmp_path / "rb"
    proc = run_main("train", "--scenario", SCENARIOS[0], "--bounds", "goal-frame",
                    "--fitness", "work-cost-cvr", "--cost-weight", "2", "--out", out)
    errors = [ln for ln in proc.stderr.splitlines() if ln.startswith("error")]
    assert proc.returncode == 2 and not out.exists(), proc.stderr
    assert len(errors) == 1 and errors[0].startswith("error: --fitness: must be one of")
