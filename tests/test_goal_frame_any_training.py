"""Training the DOF-free rulebook (issue 25): ``train --bounds goal-frame-any`` runs
Fuzzy-RRT-Connect, the planner that plans with it, on training problems of any DOF mixed.

The training evaluation is the planner's own kernel (same iterations and work as
``plan_fuzzy_rrt_connect``, run for run); a run's result depends only on its seed (one or two
worker processes, or Dask: the same bytes); what it writes is a ``dof = "any"`` rulebook that
plans arms it never saw and whose paths the independent oracle accepts.
"""

from __future__ import annotations

import subprocess

import numpy as np
import pandas as pd
import pytest

from conftest import console_script
from exact_geometry import oracle_path_problems
from xfuzzy_rrt.fuzzy import semantics as S
from xfuzzy_rrt.fuzzy.rulebook import Rulebook, load_rulebook, rulebooks_dir
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.connect import plan_fuzzy_rrt_connect
from xfuzzy_rrt.scenarios.generate import generate_nd
from xfuzzy_rrt.training.evaluate import TrainingProblem, iterations_for
from xfuzzy_rrt.training.genome import decode, encode


def _write(folder, seed, k, dof, arms):
    folder.mkdir(parents=True, exist_ok=True)
    g = generate_nd(seed, k, dof=dof, arms=arms)
    path = folder / f"{g.scenario.name}.toml"
    path.write_text(g.text, encoding="utf-8")
    return path


def test_the_training_evaluation_is_the_planners_own_run_for_run(tmp_path):
    shipped = load_rulebook(rulebooks_dir() / "goal-frame-any")
    genes = encode(*shipped.arrays(), "goal-frame-any")
    other = genes.copy()
    other[637 * 5 + 12:637 * 6] *= 0.5  # a second individual: half the steps
    knots, consts = decode(np.stack([genes, other]), "goal-frame-any")
    scenarios = [load_scenario(_write(tmp_path, 41, 0, 3, 1)),
                 load_scenario(_write(tmp_path, 41, 1, 2, 2))]
    seeds = np.arange(4)
    runs = iterations_for([TrainingProblem.from_scenario(s) for s in scenarios], knots, consts,
                          "goal-frame-any", seeds, 3000, measure="work")
    assert runs.shape == (2, 2, 4, 2)
    for p in range(2):
        book = Rulebook.from_arrays(knots[p], consts[p], name=f"i{p}", bounds_mode=None,
                                    semantics=S.GOAL_FRAME_ANY)
        for k, s in enumerate(scenarios):
            for r, seed in enumerate(seeds):
                res = plan_fuzzy_rrt_connect(s, book, seed=int(seed), max_iter=3000)
                assert runs[p, k, r, 0] == (res.iterations if res.success else -1), (p, k, r)
                assert runs[p, k, r, 1] == res.work, (p, k, r)
    assert (runs[0, :, :, 1] != runs[1, :, :, 1]).any()  # the individuals did differ


def _train(cwd, scenarios, validation, *extra):
    args = [console_script(), "train", *[a for s in scenarios for a in ("--scenario", str(s))],
            "--validation-scenario", str(validation), "--bounds", "goal-frame-any",
            "--fitness", "work-cvar", "--population", "10", "--elite", "2", "--generations", "2",
            "--runs-per-eval", "2", "--validation-runs", "2", "--max-iter", "1500", "--seed", "7",
            "--seed-rulebook", str(rulebooks_dir() / "goal-frame"), "--out", "rb", *extra]
    return subprocess.run(args, cwd=cwd, capture_output=True, text=True, timeout=900)


def test_a_mixed_dof_training_is_identical_with_one_and_two_workers_and_dask(tmp_path):
    distributed = pytest.importorskip("distributed")
    data = tmp_path / "data"
    scenarios = [_write(data / "train", 43, 0, 3, 1), _write(data / "train", 43, 1, 5, 1),
                 _write(data / "train", 43, 2, 2, 2)]
    validation = _write(data / "val", 44, 0, 4, 1)

    def collect(label):
        folder = tmp_path / label / "rb"
        files = {p.name: p.read_bytes() for p in folder.iterdir()
                 if p.is_file() and p.name != "history.csv"}
        return files, pd.read_csv(folder / "history.csv").drop(columns=["wall_s", "runs_per_s"])

    outputs = {}
    for label, extra in (("one", ["--workers", "1"]), ("two", ["--workers", "2"])):
        (tmp_path / label).mkdir()
        proc = _train(tmp_path / label, scenarios, validation, *extra)
        assert proc.returncode == 0, proc.stderr
        outputs[label] = collect(label)
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False,
                                  protocol="tcp://", host="127.0.0.1",
                                  dashboard_address=None) as cluster:
        (tmp_path / "dask").mkdir()
        proc = _train(tmp_path / "dask", scenarios, validation, "--scheduler",
                      cluster.scheduler_address)
        assert proc.returncode == 0, proc.stderr
        outputs["dask"] = collect("dask")
    files, hist = outputs["one"]
    for label in ("two", "dask"):
        assert outputs[label][0] == files, label
        pd.testing.assert_frame_equal(outputs[label][1], hist)
    manifest = files["rulebook.toml"].decode()
    assert 'semantics = "goal-frame-any"' in manifest and 'dof = "any"' in manifest
    assert "baseline_work" in manifest and "--bounds goal-frame-any" in manifest
    assert hist["validation_fitness"].notna().all()
    # the trained rulebook plans an arm it never saw (7 joints) and two 3-joint arms
    rb = load_rulebook(tmp_path / "one" / "rb")
    assert rb.semantics is S.GOAL_FRAME_ANY
    for dof, arms in ((7, 1), (3, 2)):
        s = load_scenario(_write(data / "unseen", 45, 0, dof, arms))
        r = plan_fuzzy_rrt_connect(s, rb, seed=0, max_iter=20_000)
        assert r.success and r.rulebook == "rb"
        assert oracle_path_problems(s, r.path_deg, s.start_deg, s.goal_deg) == []


def test_dof_is_refused_in_one_line_for_a_dof_free_training(tmp_path):
    scenario = _write(tmp_path, 46, 0, 3, 1)
    proc = subprocess.run([console_script(), "train", "--scenario", str(scenario), "--bounds",
                           "goal-frame-any", "--dof", "3", "--out", str(tmp_path / "rb")],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and "--dof" in lines[0] and "any number of joints" in lines[0]
    assert not (tmp_path / "rb").exists()


@pytest.mark.parametrize("seed_rb,says", [("goal-frame-5dof", "2-joint goal-frame"),
                                          ("expert", "not a goal-frame-any rulebook")])
def test_a_seed_rulebook_it_cannot_start_from_is_refused_in_one_line(tmp_path, seed_rb, says):
    scenario = _write(tmp_path, 46, 0, 3, 1)
    proc = subprocess.run([console_script(), "train", "--scenario", str(scenario), "--bounds",
                           "goal-frame-any", "--seed-rulebook", str(rulebooks_dir() / seed_rb),
                           "--out", str(tmp_path / "rb")], capture_output=True, text=True,
                          timeout=300)
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and seed_rb in lines[0] and says in lines[0], lines
    assert not (tmp_path / "rb").exists()
