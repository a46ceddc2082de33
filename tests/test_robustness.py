"""Stochastic Robustness Analysis: right against closed forms, reproducible, honest CLI.

The analytic anchor: one link of length L sweeping -90..90 deg past one circle of radius r
whose centre, nominally at distance D beyond the pivot, is offset by a 2-D Gaussian of σ per
axis. The link sweeps the whole half-disc of radius L, so the executed motion touches the
circle exactly when the perturbed centre lies within L + r of the pivot: |C'| follows a Rice
distribution, P(collision) = Rice(ν = D, σ).cdf(L + r) (the half-plane condition fails with
probability Φ(-D/σ) ≈ 0). The Monte Carlo must bracket it with its 95 % interval.
"""

from __future__ import annotations

import json
import math
import types

import numpy as np
import pytest
from scipy import stats

from single_arm import arrays_of
from tests.conftest import FIXTURES
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.rrt import plan_rrt
from xfuzzy_rrt.robustness.inputs import load_bench_paths, load_result_path
from xfuzzy_rrt.robustness.montecarlo import Perturbation, clopper_pearson, path_robustness
from xfuzzy_rrt.robustness.sweep import margin_needed, path_sweep, planner_sweep

L = 0.3
SWEEP = np.array([[-90.0], [90.0]])
TWO = FIXTURES / "scenarios" / "two-circles.toml"


def _one_link(obstacles, radius=0.0):
    return arrays_of(np.array([L]), np.zeros(2), radius, np.array(obstacles, dtype=float))


@pytest.mark.parametrize("gap, r, sigma", [(0.003, 0.002, 0.002), (0.006, 0.004, 0.003),
                                           (0.001, 0.0005, 0.0005)])
def test_collision_probability_matches_the_rice_closed_form_for_a_gaussian_offset(gap, r, sigma):
    D = L + gap + r
    arrays = _one_link([[0.0, D, 0.0, r, 0.0]])
    res = path_robustness(arrays, SWEEP, Perturbation(sigma_obstacle_m=sigma), trials=20_000,
                          seed=11)
    exact = stats.rice(D / sigma, scale=sigma).cdf(L + r)
    assert 0.02 < exact < 0.98  # a case where the interval means something
    assert res.ci_low <= exact <= res.ci_high, (res.p_collision, exact)
    assert res.nominal_clearance_m == pytest.approx(gap, abs=1e-9)


def test_collision_probability_matches_the_closed_form_for_a_radius_change():
    """Size noise alone: touching exactly when the radius grows by the gap or more."""
    gap, r, sigma = 0.002, 0.003, 0.0015
    arrays = _one_link([[0.0, L + gap + r, 0.0, r, 0.0]])
    res = path_robustness(arrays, SWEEP, Perturbation(sigma_size_m=sigma), trials=20_000,
                          seed=3)
    exact = stats.norm.sf(gap / sigma)
    assert res.ci_low <= exact <= res.ci_high


def test_bounded_uniform_noise_never_reaches_beyond_its_bound():
    sigma = 0.001
    reach = math.sqrt(3.0) * sigma * math.sqrt(2.0)  # largest centre displacement
    arrays = _one_link([[0.0, L + reach * 1.01 + 0.002, 0.0, 0.002, 0.0]])
    res = path_robustness(arrays, SWEEP, Perturbation(sigma, distribution="uniform"),
                          trials=5000, seed=0)
    assert res.collisions == 0 and res.min_clearance_m.min() > 0.0
    normal = path_robustness(arrays, SWEEP, Perturbation(sigma), trials=5000, seed=0)
    assert normal.collisions > 0  # the same σ, unbounded, does reach it


def test_without_noise_every_trial_is_the_nominal_path():
    s = load_scenario(TWO)
    path = plan_rrt(s, seed=0).path_deg
    res = path_robustness(s.arrays(), path, Perturbation(), trials=200, seed=0)
    assert res.collisions == 0 and res.most_hit == -1
    v = res.min_clearance_m
    assert np.all(v == v[0])  # every trial the same motion
    assert res.nominal_clearance_m - 1e-9 <= v[0] <= res.nominal_clearance_m + 1e-6
    assert res.ci_high == pytest.approx(1 - 0.025 ** (1 / 200))


def test_the_obstacle_hit_most_is_the_one_the_path_grazes():
    arrays = _one_link([[0.0, 0.0, L + 0.030, 0.010, 0.0],  # far from the sweep
                        [0.0, L + 0.001 + 0.002, 0.0, 0.002, 0.0]])  # 1 mm from the tip
    res = path_robustness(arrays, SWEEP, Perturbation(0.002), trials=4000, seed=5)
    assert res.collisions > 0 and res.most_hit == 1
    assert res.hits_per_obstacle[0] == 0


def test_joint_tracking_error_alone_can_make_a_path_collide():
    arrays = _one_link([[0.0, 0.0, L, 0.01, 0.0]])  # on the tip's arc at 90 deg
    path = np.array([[0.0], [80.0]])  # stops 10 deg short: the tip clears it by ~4 cm
    far = path_robustness(arrays, path, Perturbation(sigma_joint_deg=1.0), trials=2000, seed=1)
    near = path_robustness(arrays, path, Perturbation(sigma_joint_deg=5.0), trials=2000, seed=1)
    assert far.collisions == 0 < near.collisions


def test_same_seed_same_numbers_whatever_the_worker_count():
    s = load_scenario(TWO)
    path = plan_rrt(s, seed=1).path_deg
    p = Perturbation(0.004, 0.001, 0.5)
    one = path_robustness(s.arrays(), path, p, trials=1000, seed=7, workers=1)
    two = path_robustness(s.arrays(), path, p, trials=1000, seed=7, workers=2)
    again = path_robustness(s.arrays(), path, p, trials=1000, seed=7)
    for other in (two, again):
        assert np.array_equal(one.min_clearance_m, other.min_clearance_m)
        assert np.array_equal(one.obstacle, other.obstacle)
        assert (one.collisions, one.ci_low, one.ci_high) == (
            other.collisions, other.ci_low, other.ci_high)
    different = path_robustness(s.arrays(), path, p, trials=1000, seed=8)
    assert not np.array_equal(one.min_clearance_m, different.min_clearance_m)


def test_clopper_pearson_is_scipys_exact_interval():
    lo, hi = clopper_pearson(3, 100)
    assert lo == pytest.approx(stats.beta.ppf(0.025, 3, 98))
    assert hi == pytest.approx(stats.beta.ppf(0.975, 4, 97))


def test_a_sigma_sweep_grows_the_collision_probability():
    arrays = _one_link([[0.0, L + 0.002 + 0.002, 0.0, 0.002, 0.0]])
    table, _ = path_sweep(arrays, SWEEP, [0.0005, 0.002, 0.005], Perturbation(), 4000, 0)
    p = table["p_collision"].to_numpy()
    assert p[0] < p[1] < p[2]
    assert list(table["sigma_m"]) == [0.0005, 0.002, 0.005]


@pytest.mark.parametrize("kwargs, where", [
    ({"sigma_obstacle_m": -0.001}, "--sigma-obstacle-m"),
    ({"sigma_joint_deg": math.nan}, "--sigma-joint-deg"),
    ({"distribution": "cauchy"}, "--distribution"),
])
def test_an_unusable_perturbation_is_one_input_error(kwargs, where):
    with pytest.raises(InputError) as err:
        Perturbation(**kwargs)
    assert err.value.where == where


def test_planner_robustness_rows_and_rates():
    s = load_scenario(TWO)
    table = planner_sweep([s], ["rrt"], [0.001, 0.02], Perturbation(), runs=3, seed=0,
                          max_iter=3000, trials=300)
    assert set(table["mode"]) == {"perturbed-plan", "perturbed-world"}
    assert len(table) == 4
    for col in ("success_rate", "collision_rate", "found_rate"):
        assert table[col].between(0, 1).all()
    world = table[table["mode"] == "perturbed-world"].set_index("sigma_m")
    assert world.loc[0.02, "collision_rate"] >= world.loc[0.001, "collision_rate"]


def test_margin_needed_marks_the_smallest_clearance_meeting_the_target():
    s = load_scenario(TWO)
    table = margin_needed([s], ["rrt"], 0.001, [0.0, 0.006], Perturbation(), runs=3, seed=0,
                          max_iter=3000, trials=600, target=0.05)
    assert list(table["clearance_m"]) == [0.0, 0.006]
    assert table["needed"].sum() <= 1
    if table["needed"].any():
        row = table[table["needed"]].iloc[0]
        assert row["ci_high"] <= 0.05
        earlier = table[table["clearance_m"] < row["clearance_m"]]
        assert not earlier["meets_target"].any()


# ------------------------------------------------------------------------------ inputs, CLI


def test_a_result_planned_in_another_scenario_is_refused(tmp_path):
    s = load_scenario(TWO)
    f = tmp_path / "r.json"
    f.write_text(json.dumps({"scenario": "elsewhere", "path_deg": [[0.0, 0.0]]}))
    with pytest.raises(InputError, match="elsewhere"):
        load_result_path(s, f)
    f.write_text(json.dumps({"scenario": s.name, "path_deg": []}))
    with pytest.raises(InputError, match="path_deg"):
        load_result_path(s, f)


def test_bench_folder_examples_are_read_with_their_scenarios(tmp_path):
    s = load_scenario(TWO)
    r = plan_rrt(s, seed=0)
    (tmp_path / "examples").mkdir()
    (tmp_path / "bench.json").write_text(json.dumps(
        {"scenarios": [{"name": s.name, "file": str(TWO), "toml": TWO.read_text()}]}))
    (tmp_path / "examples" / "index.json").write_text(json.dumps(
        [{"scenario": s.name, "planner": "rrt", "seed": 0, "path_deg": r.path_deg.tolist()}]))
    paths = load_bench_paths(tmp_path)
    assert len(paths) == 1 and np.array_equal(paths[0].path_deg, r.path_deg)


def _cli(args, capsys):
    from xfuzzy_rrt.cli.main import main

    code = main(args)
    out = capsys.readouterr()
    return code, out.out, out.err


def test_cli_path_prints_the_probability_and_writes_the_tables(tmp_path, capsys):
    result = tmp_path / "r.json"
    assert _cli(["plan", str(TWO), "--planner", "rrt", "--out", str(result)], capsys)[0] == 0
    out = tmp_path / "rob"
    code, stdout, err = _cli(["robustness", "path", str(TWO), str(result), "--sigma",
                              "0.001,0.01", "--trials", "500", "--out", str(out), "--html"],
                             capsys)
    assert code == 0, err
    assert stdout.count("P(collision) = ") == 2
    import pandas as pd

    table = pd.read_csv(out / "path_robustness.csv")
    assert list(table["sigma_m"]) == [0.001, 0.01]
    assert len(pd.read_csv(out / "trials.csv")) == 1000
    assert (out / "robustness.html").stat().st_size > 0


@pytest.mark.parametrize("extra, where", [(["--sigma", "-0.001"], "--sigma"),
                                          (["--sigma", "x"], "--sigma"),
                                          (["--trials", "0"], "--trials"),
                                          (["--distribution", "cauchy"], "--distribution")])
def test_cli_bad_input_is_one_line_exit_2_and_no_output(tmp_path, capsys, extra, where):
    result = tmp_path / "r.json"
    assert _cli(["plan", str(TWO), "--planner", "rrt", "--out", str(result)], capsys)[0] == 0
    out = tmp_path / "rob"
    code, _, err = _cli(["robustness", "path", str(TWO), str(result), "--out", str(out),
                         *extra], capsys)
    lines = err.strip().splitlines()
    assert code == 2 and len(lines) == 1 and lines[0].startswith(f"error: {where}"), err
    assert not out.exists()


# ------------------------------------------------------------------------ moving obstacles


def test_still_obstacles_are_executed_without_replanning_or_contact():
    from xfuzzy_rrt.robustness.moving import moving_obstacles

    s = load_scenario(TWO)
    table = moving_obstacles([s], ["rrt"], [0.0], joint_speed_deg_s=90.0, rate_hz=10.0,
                             replan=True, runs=2, max_iter=3000, time_limit_s=20.0)
    row = table.iloc[0]
    assert row["success_rate"] == 1.0 and row["collision_rate"] == 0.0
    assert row["replans_mean"] == 0.0


def test_an_obstacle_drifting_into_a_blind_arm_is_recorded_as_a_collision():
    """A circle parked beside the sweep drifts across it: the blind executor must record the
    contact (the exact per-tick check), and the same seed gives the same record."""
    from xfuzzy_rrt.robustness.moving import execute_once

    s = load_scenario(TWO)
    rows = [execute_once(s, "rrt", seed, 0.05, 20.0, 10.0, False, max_iter=3000,
                         time_limit_s=30.0) for seed in range(4)]
    assert any(r["collided"] for r in rows)
    again = execute_once(s, "rrt", 0, 0.05, 20.0, 10.0, False, max_iter=3000, time_limit_s=30.0)
    assert again == rows[0]
