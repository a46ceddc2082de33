"""The fair protocol behind every "N x fewer iterations than RRT" this project states.

Why a protocol of its own: a ratio claimed for a rulebook means nothing unless it is measured the
same way every time — on problems no training or tuning saw, against RRT run with the *same*
seeds, with failures counted (as ``max_iter`` iterations, never dropped), per problem first and
only then summarised, because a handful of hard problems dominate any pooled mean. So:

1. Every planner runs on every problem with seeds ``seed .. seed + runs - 1`` (common random
   numbers across planners).
2. Per problem and planner: median iterations (failures = ``max_iter``), success rate (a run
   succeeds only with a path that passed the certified check), median cost of the successful
   paths, median wall time to the first path.
3. Per problem, ratios to RRT: ``rrt_median_iterations / planner_median_iterations`` (> 1: the
   planner needs fewer), ``planner_median_cost / rrt_median_cost`` (< 1: shorter paths) and
   ``rrt_median_time / planner_median_time``.
4. Per planner over problems: median, geometric mean, worst and best iteration ratio, how many
   problems it loses (ratio < 1), worst success rate and how often it falls below RRT's, median
   cost ratio, median time ratio.

OMPL planners count iterations differently, so they are ranked on time only (their iteration
ratio is left empty).
"""

from __future__ import annotations

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

PROBLEM_COLUMNS = ["scenario", "planner", "runs", "success_rate", "median_iterations",
                   "median_cost_deg", "median_time_s", "iteration_ratio", "cost_ratio",
                   "time_ratio"]
SUMMARY_COLUMNS = ["planner", "problems", "median_ratio", "geomean_ratio", "worst_ratio",
                   "best_ratio", "problems_lost", "worst_success_rate",
                   "problems_success_below_rrt", "median_cost_ratio", "median_time_ratio",
                   "median_time_s"]


@dataclass(frozen=True)
class ProtocolResult:
    runs: pd.DataFrame  # one row per run: scenario, planner, seed, success, iterations, cost_deg, wall_s
    problems: pd.DataFrame  # PROBLEM_COLUMNS
    summary: pd.DataFrame  # SUMMARY_COLUMNS


def _one(scenario, planner: str, rulebook, seed: int, max_iter: int, clearance_m) -> dict:
    from xfuzzy_rrt.planners.api import plan_scenario

    r = plan_scenario(scenario, planner=planner, rulebook=rulebook, seed=seed, max_iter=max_iter,
                      clearance_m=clearance_m)
    ok = bool(getattr(r, "success", False))
    return {"success": ok, "iterations": int(r.iterations) if ok else int(max_iter),
            "cost_deg": float(r.cost_deg) if ok and r.cost_deg is not None else np.nan,
            "wall_s": float(r.wall_s)}


def run_protocol(scenarios: list, planners: list[tuple[str, str, object]], runs: int = 50,
                 seed: int = 0, max_iter: int = 10_000, progress=None,
                 clearance_m: float | None = None) -> ProtocolResult:
    """Run RRT and every ``(label, planner, rulebook)`` of *planners* on every scenario.

    ``clearance_m`` is the certified margin every planner must keep (``None``: each scenario's).

    ``planner`` is a name :func:`~xfuzzy_rrt.planners.api.plan_scenario` takes (``fuzzy-rrt``
    with a loaded ``rulebook``, or ``ompl:NAME``); ``label`` names it in the tables.
    """
    entries = [("rrt", "rrt", None), *planners]
    rows = []
    total = len(scenarios) * len(entries)
    done = 0
    for sc in scenarios:
        for label, planner, rb in entries:
            for k in range(runs):
                rows.append({"scenario": sc.name, "planner": label, "seed": seed + k,
                             **_one(sc, planner, rb, seed + k, max_iter, clearance_m)})
            done += 1
            if progress:
                progress(done, total)
    frame = pd.DataFrame(rows, columns=["scenario", "planner", "seed", "success", "iterations",
                                        "cost_deg", "wall_s"])
    problems = problem_table(frame, [e[0] for e in entries])
    return ProtocolResult(runs=frame, problems=problems, summary=summary_table(problems))


def problem_table(runs: pd.DataFrame, order: list[str]) -> pd.DataFrame:
    """Per (scenario, planner) medians and ratios to RRT (see the module docstring)."""
    g = runs.groupby(["scenario", "planner"], sort=False)
    per = g.agg(runs=("seed", "size"), success_rate=("success", "mean"),
                median_iterations=("iterations", "median"),
                median_cost_deg=("cost_deg", "median"),
                median_time_s=("wall_s", "median")).reset_index()
    rrt = per[per["planner"] == "rrt"].set_index("scenario")
    base_it = per["scenario"].map(rrt["median_iterations"])
    base_cost = per["scenario"].map(rrt["median_cost_deg"])
    base_time = per["scenario"].map(rrt["median_time_s"])
    is_ompl = per["planner"].str.startswith("ompl:")
    per["iteration_ratio"] = np.where(is_ompl, np.nan, base_it / per["median_iterations"])
    per["cost_ratio"] = per["median_cost_deg"] / base_cost
    per["time_ratio"] = base_time / per["median_time_s"]
    per["planner"] = pd.Categorical(per["planner"], categories=order, ordered=True)
    per = per.sort_values(["planner", "scenario"], kind="stable").reset_index(drop=True)
    per["planner"] = per["planner"].astype(str)
    return per[PROBLEM_COLUMNS]


def summary_table(problems: pd.DataFrame) -> pd.DataFrame:
    """One row per planner (RRT included, whose ratios are 1 by construction)."""
    rows = []
    rrt_success = problems[problems["planner"] == "rrt"].set_index("scenario")["success_rate"]
    for planner, g in problems.groupby("planner", sort=False):
        r = g["iteration_ratio"].to_numpy(dtype=float)
        has = np.isfinite(r).any()
        below = (g["success_rate"].to_numpy() < g["scenario"].map(rrt_success).to_numpy()).sum()
        rows.append({
            "planner": planner, "problems": len(g),
            "median_ratio": float(np.nanmedian(r)) if has else np.nan,
            "geomean_ratio": float(np.exp(np.nanmean(np.log(r)))) if has else np.nan,
            "worst_ratio": float(np.nanmin(r)) if has else np.nan,
            "best_ratio": float(np.nanmax(r)) if has else np.nan,
            "problems_lost": int((r < 1.0).sum()) if has else 0,
            "worst_success_rate": float(g["success_rate"].min()),
            "problems_success_below_rrt": int(below),
            "median_cost_ratio": float(np.nanmedian(g["cost_ratio"])),
            "median_time_ratio": float(np.nanmedian(g["time_ratio"])),
            "median_time_s": float(np.nanmedian(g["median_time_s"])),
        })
    return pd.DataFrame(rows, columns=SUMMARY_COLUMNS)


def write_protocol(result: ProtocolResult, out: Path) -> None:
    """``runs.csv``, ``problems.csv`` and ``summary.csv`` into *out* (each written atomically)."""
    from xfuzzy_rrt.atomic import atomic_path

    out.mkdir(parents=True, exist_ok=True)
    for name, frame in (("runs.csv", result.runs), ("problems.csv", result.problems),
                        ("summary.csv", result.summary)):
        with atomic_path(out / name) as tmp:
            frame.to_csv(tmp, index=False, float_format="%.10g")
