"""P(collision) as the obstacle uncertainty σ grows, for planned paths and for planners.

- :func:`path_sweep`: one planned path executed under growing obstacle-centre σ (the size and
  joint σ held fixed): one row per σ with the collision probability, its 95 % Clopper–Pearson
  interval, the clearance quantiles and the obstacle hit most. The same seed is used at every σ
  (common random numbers): with normal noise the trials are the same draws scaled, so the curve
  is monotone in expectation and differences between σ are not sampling noise.
- :func:`planner_sweep`: *plan on a perturbed model, execute on the true one* (``mode =
  "perturbed-plan"``: the model the planner saw was wrong by σ; collision = the exact minimum
  clearance of the path in the true scenario is <= 0) and *the reverse* (``mode =
  "perturbed-world"``: plan on the true model, execute where the obstacles really are, i.e.
  the path's Monte Carlo collision probability, averaged over runs).
- :func:`margin_needed`: the smallest clearance of a grid for which paths planned with it
  keep P(collision) <= a target (upper end of the interval) at a given σ.
"""

from __future__ import annotations

import dataclasses
import math

import numpy as np
import pandas as pd

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.robustness.montecarlo import (
    Perturbation,
    clopper_pearson,
    path_robustness,
)

QUANTILES = (0.01, 0.05, 0.5)


def check_sigmas(sigmas, where: str = "--sigma") -> list[float]:
    out = []
    for v in sigmas:
        if isinstance(v, bool) or not isinstance(v, (int, float)) or not (
                math.isfinite(v) and v >= 0.0):
            raise InputError(where, f"must be non-negative metres, got {v!r}")
        out.append(float(v))
    if not out:
        raise InputError(where, "needs at least one value")
    return out


def summary_row(res) -> dict:
    """The table row of one :class:`~xfuzzy_rrt.robustness.montecarlo.PathRobustness`."""
    v = res.min_clearance_m
    row = {"trials": res.trials, "collisions": res.collisions,
           "p_collision": res.p_collision, "ci_low": res.ci_low, "ci_high": res.ci_high,
           "nominal_clearance_m": res.nominal_clearance_m}
    for q in QUANTILES:
        row[f"clearance_q{int(round(q * 100)):02d}_m"] = float(np.quantile(v, q))
    row["clearance_min_m"] = float(v.min())
    row["most_hit_obstacle"] = res.most_hit
    row["most_hit_count"] = int(res.hits_per_obstacle.max()) if res.collisions else 0
    row["undecided"] = res.undecided
    return row


def path_sweep(arrays, path_deg, sigmas, base: Perturbation, trials: int, seed: int,
               workers: int | None = None):
    """``(table, results)``: one row per σ (obstacle centre offset), and the raw results."""
    rows, results = [], []
    for sigma in check_sigmas(sigmas):
        p = dataclasses.replace(base, sigma_obstacle_m=sigma)
        res = path_robustness(arrays, path_deg, p, trials=trials, seed=seed, workers=workers)
        rows.append({"sigma_m": sigma, "sigma_size_m": p.sigma_size_m,
                     "sigma_joint_deg": p.sigma_joint_deg, "distribution": p.distribution,
                     **summary_row(res)})
        results.append(res)
    return pd.DataFrame(rows), results


def perturbed_scenario(scenario, perturbation: Perturbation, rng: np.random.Generator):
    """A copy of ``scenario`` with its obstacles moved and resized by one draw."""
    from xfuzzy_rrt.geometry.scenario import Box, Circle
    from xfuzzy_rrt.robustness.montecarlo import perturb_obstacles

    obs = perturb_obstacles(scenario.arrays().obstacles, 1, perturbation, rng)[0]
    new = []
    for row in obs:
        if row[0] == 0.0:
            new.append(Circle(center=(float(row[1]), float(row[2])), radius=float(row[3])))
        else:
            new.append(Box(min=(float(row[1]), float(row[2])), max=(float(row[3]), float(row[4]))))
    return dataclasses.replace(scenario, obstacles=tuple(new))


def _plan(scenario, planner: str, seed: int, max_iter: int, clearance_m):
    from xfuzzy_rrt.planners.api import plan_scenario

    return plan_scenario(scenario, planner=planner, seed=seed, max_iter=max_iter,
                         clearance_m=clearance_m)


def planner_sweep(scenarios, planners, sigmas, base: Perturbation, runs: int, seed: int,
                  max_iter: int = 10_000, trials: int = 2000, clearance_m: float | None = None,
                  workers: int | None = None) -> pd.DataFrame:
    """Per (scenario, planner, σ, mode): runs, found, success and collision rates.

    ``perturbed-plan``: run *k* plans (seed ``seed + k``) on the scenario with obstacles
    perturbed by draw *k* (the same draws for every planner), and executes on the true one.
    ``perturbed-world``: run *k* plans on the true scenario and its path is executed under
    ``trials`` perturbations (P(collision) averaged over runs; ``success_rate`` counts runs
    whose path was found and whose Monte Carlo saw no collision).
    """
    from xfuzzy_rrt.geometry.clearance import path_min_clearance

    rows = []
    for scenario in scenarios:
        a = scenario.arrays()
        for planner in planners:
            true_runs = [_plan(scenario, planner, seed + k, max_iter, clearance_m)
                         for k in range(runs)]
            for sigma in check_sigmas(sigmas):
                p = dataclasses.replace(base, sigma_obstacle_m=sigma)
                # Plan on a perturbed model, execute on the true one.
                rng = np.random.default_rng([int(seed), int(round(sigma * 1e9))])
                found = collided = ok = 0
                for k in range(runs):
                    model = perturbed_scenario(scenario, p, rng)
                    try:
                        r = _plan(model, planner, seed + k, max_iter, clearance_m)
                    except InputError:
                        continue  # the perturbed model swallowed the start or the goal
                    if not r.path_deg.size:
                        continue
                    found += 1
                    c = path_min_clearance(a, r.path_deg).value_m
                    if c <= 0.0:
                        collided += 1
                    else:
                        ok += 1
                lo, hi = clopper_pearson(collided, runs)
                rows.append({"scenario": scenario.name, "planner": planner, "sigma_m": sigma,
                             "mode": "perturbed-plan", "runs": runs, "found_rate": found / runs,
                             "success_rate": ok / runs, "collision_rate": collided / runs,
                             "ci_low": lo, "ci_high": hi})
                # Plan on the true model, execute in perturbed worlds.
                ps, found, ok = [], 0, 0
                for k, r in enumerate(true_runs):
                    if not r.path_deg.size:
                        continue
                    found += 1
                    res = path_robustness(a, r.path_deg, p, trials=trials, seed=seed + k,
                                          workers=workers)
                    ps.append(res.p_collision)
                    ok += res.collisions == 0
                mean_p = float(np.mean(ps)) if ps else math.nan
                k_all = int(round(sum(ps) * trials))
                lo, hi = clopper_pearson(k_all, trials * len(ps)) if ps else (math.nan, math.nan)
                rows.append({"scenario": scenario.name, "planner": planner, "sigma_m": sigma,
                             "mode": "perturbed-world", "runs": runs, "found_rate": found / runs,
                             "success_rate": ok / runs, "collision_rate": mean_p,
                             "ci_low": lo, "ci_high": hi})
    return pd.DataFrame(rows)


def margin_needed(scenarios, planners, sigma: float, margins, base: Perturbation, runs: int,
                  seed: int, max_iter: int = 10_000, trials: int = 2000, target: float = 0.01,
                  workers: int | None = None) -> pd.DataFrame:
    """Per (planner, clearance): pooled P(collision) at ``sigma`` of paths planned with that
    clearance, its interval, and ``meets_target`` (interval's upper end <= ``target``). The
    clearance needed is the smallest one that meets it (``needed`` marks that row)."""
    sigma = check_sigmas([sigma])[0]
    p = dataclasses.replace(base, sigma_obstacle_m=sigma)
    rows = []
    for planner in planners:
        first = True
        for c in check_sigmas(margins, "--margins"):
            k_all = n_all = found = 0
            for scenario in scenarios:
                a = scenario.arrays()
                for k in range(runs):
                    try:
                        r = _plan(scenario, planner, seed + k, max_iter, c)
                    except InputError:
                        continue  # start or goal inside this clearance: not plannable
                    if not r.success:
                        continue
                    found += 1
                    res = path_robustness(a, r.path_deg, p, trials=trials, seed=seed + k,
                                          workers=workers)
                    k_all += res.collisions
                    n_all += res.trials
            lo, hi = clopper_pearson(k_all, n_all) if n_all else (math.nan, math.nan)
            meets = bool(n_all) and hi <= target
            rows.append({"planner": planner, "sigma_m": sigma, "clearance_m": c,
                         "paths": found, "runs": runs * len(scenarios),
                         "p_collision": k_all / n_all if n_all else math.nan,
                         "ci_low": lo, "ci_high": hi, "meets_target": meets,
                         "needed": bool(meets and first)})
            first = first and not meets
    return pd.DataFrame(rows)


__all__ = ["margin_needed", "path_sweep", "perturbed_scenario", "planner_sweep"]
