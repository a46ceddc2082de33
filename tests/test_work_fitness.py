"""Training on work against the tuned peer (``--fitness work-cvar``).

The fair protocol ranks planners on the time (and the deterministic work) to a certified path
against the tuned RRT, so the default rulebook is trained on that measure: each training run
reports its work as well as its iterations, the work is the planner's own count, and the fitness
weighs the worst quarter of problems as much as all of them.
"""

from __future__ import annotations

import numpy as np
import pytest

from conftest import FIXTURES
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy import semantics
from xfuzzy_rrt.fuzzy.rulebook import Rulebook
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt
from xfuzzy_rrt.planners.rrt import plan_rrt
from xfuzzy_rrt.planners.tuned import tuned_params
from xfuzzy_rrt.training.evaluate import (
    FAILED_WORK_FACTOR,
    TrainingProblem,
    iterations_for,
    iterations_of,
    tuned_rrt_baseline,
    work_cvar_fitness,
)
from xfuzzy_rrt.training.ga import GAConfig
from xfuzzy_rrt.training.genome import constant_outputs_genome, decode

SCENARIOS = [FIXTURES / "scenarios" / "two-circles.toml",
             FIXTURES / "scenarios" / "boxes-and-circle.toml"]
GF = semantics.GOAL_FRAME


def _runs(its, work):
    return np.stack([np.asarray(its), np.asarray(work)], axis=-1).astype(np.int64)


def test_work_cvar_is_zero_when_every_run_costs_the_peers_median_work():
    b = np.array([100.0, 400.0, 50.0, 900.0])
    work = np.broadcast_to(b[None, :, None], (1, 4, 3))
    assert work_cvar_fitness(_runs(np.full((1, 4, 3), 7), work), b)[0] == pytest.approx(0.0)


def test_work_cvar_is_half_the_mean_plus_half_the_worst_quarter_of_problems():
    b = np.ones(8) * 1000.0
    ratios = np.array([4.0, 2.0, 2.0, 2.0, 1.0, 1.0, 0.5, 0.25])  # peer work / our work
    work = (b / ratios)[None, :, None]
    got = work_cvar_fitness(_runs(np.ones((1, 8, 1)), work), b)[0]
    per = np.log(ratios)
    assert got == pytest.approx(0.5 * per.mean() + 0.5 * np.sort(per)[:2].mean())


def test_work_cvar_prefers_no_bad_tail_at_the_same_mean_log_ratio():
    b = np.ones(8) * 1000.0
    even = np.full(8, np.exp(0.25))
    tail = np.array([np.exp(1.0)] * 6 + [np.exp(-2.0)] * 2)
    assert np.log(even).mean() == pytest.approx(np.log(tail).mean())
    work = np.stack([(b / even)[:, None], (b / tail)[:, None]])  # [2, 8, 1]
    fit = work_cvar_fitness(_runs(np.ones((2, 8, 1)), work), b)
    assert fit[0] > fit[1]


def test_a_failed_run_counts_at_least_the_failure_factor_times_the_peer():
    b = np.array([100.0])
    cheap_failure = work_cvar_fitness(_runs([[[-1]]], [[[5]]]), b)[0]
    costly_failure = work_cvar_fitness(_runs([[[-1]]], [[[10**6]]]), b)[0]
    assert cheap_failure == pytest.approx(-np.log(FAILED_WORK_FACTOR))
    assert costly_failure == pytest.approx(np.log(100.0 / 10**6))


def test_work_cvar_rejects_iterations_without_work_and_a_wrong_baseline():
    with pytest.raises(ValueError, match=r"runs \[P, S, R, 2\]"):
        work_cvar_fitness(np.ones((1, 2, 3), dtype=np.int64), np.ones(2))
    with pytest.raises(ValueError, match="one baseline per problem"):
        work_cvar_fitness(_runs(np.ones((1, 2, 3)), np.ones((1, 2, 3))), np.ones(3))


def test_measured_training_runs_report_the_planners_own_iterations_and_work():
    scenarios = [load_scenario(p) for p in SCENARIOS]
    rng = np.random.default_rng(4)
    base = constant_outputs_genome((0.2, 0.3, 90.0, 30.0, 60.0, 60.0), "goal-frame")
    genes = np.clip(base + 0.1 * rng.standard_normal((2, base.size)), 0, 1)
    knots, consts = decode(genes, "goal-frame")
    seeds = np.array([0, 7])
    problems = [TrainingProblem.from_scenario(s) for s in scenarios]
    runs = iterations_for(problems, knots, consts, "goal-frame", seeds, 3000, measure="work")
    assert runs.shape == (2, 2, 2, 2)
    plain = iterations_for(problems, knots, consts, "goal-frame", seeds, 3000)
    np.testing.assert_array_equal(iterations_of(runs), plain)
    for p in range(2):
        rb = Rulebook.from_arrays(knots[p], consts[p], name="x", bounds_mode=None,
                                  semantics=GF, provenance={"kind": "test"})
        for k, s in enumerate(scenarios):
            for r, seed in enumerate(seeds):
                res = plan_fuzzy_rrt(s, rb, seed=int(seed), max_iter=3000)
                assert runs[p, k, r, 0] == (res.iterations if res.success else -1)
                assert runs[p, k, r, 1] == res.work > 0


def test_measured_work_is_the_same_when_threads_share_the_problems():
    # Dask's threaded workers evaluate chunks of one population at once on the same problem
    # objects; each run must still count only its own work.
    from concurrent.futures import ThreadPoolExecutor

    problems = [TrainingProblem.from_scenario(load_scenario(p)) for p in SCENARIOS]
    rng = np.random.default_rng(9)
    base = constant_outputs_genome((0.1, 0.6, 90.0, 30.0, 60.0, 40.0), "goal-frame")
    genes = np.clip(base + 0.1 * rng.standard_normal((8, base.size)), 0, 1)
    knots, consts = decode(genes, "goal-frame")
    seeds = np.arange(6)
    alone = iterations_for(problems, knots, consts, "goal-frame", seeds, 3000, measure="work")
    with ThreadPoolExecutor(4) as pool:
        parts = list(pool.map(
            lambda i: iterations_for(problems, knots[i:i + 1], consts[i:i + 1], "goal-frame",
                                     seeds, 3000, measure="work"), range(8)))
    np.testing.assert_array_equal(np.concatenate(parts), alone)
    assert all(int(pr.bundle.work[0]) == 0 for pr in problems)  # the shared counter untouched


def test_the_work_baseline_is_the_tuned_rrts_median_work():
    scenarios = [load_scenario(p) for p in SCENARIOS]
    tuned = tuned_params("rrt")
    got = tuned_rrt_baseline([TrainingProblem.from_scenario(s) for s in scenarios],
                             np.arange(5), 3000)
    for s, b in zip(scenarios, got):
        work = [plan_rrt(s, seed=k, max_iter=3000, **tuned).work for k in range(5)]
        assert b == np.median(work)


def test_work_cvar_is_refused_for_the_papers_semantics_with_one_line():
    with pytest.raises(InputError, match="work-cvar counts the planner's work") as err:
        GAConfig(bounds="absolute", fitness="work-cvar", scenarios=(("a", "0"),),
                 baseline=(100.0,))
    assert err.value.where == "--fitness"


def test_the_paper_semantics_evaluation_refuses_to_measure_work():
    problems = [TrainingProblem.from_scenario(load_scenario(SCENARIOS[0]))]
    knots, consts = decode(constant_outputs_genome((0.1, -180, 180, -180, 180, 10.0), "absolute")[None],
                           "absolute")
    with pytest.raises(ValueError, match="counts iterations only"):
        iterations_for(problems, knots, consts, "absolute", np.array([0]), 100, measure="work")


def test_train_refuses_work_cvar_for_the_papers_semantics_before_computing_baselines(tmp_path):
    from conftest import run_main

    out = tmp_path / "rb"
    proc = run_main("train", "--scenario", SCENARIOS[0], "--bounds", "absolute",
                    "--fitness", "work-cvar", "--generations", "1", "--out", out)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and not out.exists()
    assert lines == [lines[0]] and lines[0].startswith("error: --fitness: work-cvar counts")


def test_work_cvar_without_the_tuned_file_is_one_line(monkeypatch, tmp_path):
    from conftest import run_main
    from xfuzzy_rrt.planners import tuned

    monkeypatch.setattr(tuned, "tuned_dir", lambda: tmp_path)
    out = tmp_path / "rb"
    proc = run_main("train", "--scenario", SCENARIOS[0], "--bounds", "goal-frame",
                    "--fitness", "work-cvar", "--generations", "1", "--out", out)
    errors = [ln for ln in proc.stderr.splitlines() if ln.startswith("error")]
    assert proc.returncode == 2 and not out.exists(), proc.stderr
    assert len(errors) == 1 and "work-cvar needs the tuned RRT" in errors[0]
    assert "Traceback" not in proc.stderr
