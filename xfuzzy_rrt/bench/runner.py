"""Run planners over scenarios and seeds; return one row per run and one per (scenario, planner).

Runs are independent and fully determined by ``(scenario, planner, rulebook, seed, max_iter)``,
so they can be spread over worker processes: results are collected by run key and sorted, which
keeps every column except ``wall_s`` identical whatever the number of workers. Column names
are the stable ones of SPEC.md (OMPL-style: one typed row per run).
"""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.scenario import Scenario
from xfuzzy_rrt.planners.api import PLANNERS, plan_scenario
from xfuzzy_rrt.planners.result import PlanResult

RUN_COLUMNS = ["scenario", "planner", "seed", "success", "iterations", "nodes", "cost_deg",
               "wall_s", "rulebook", "rulebook_sha256"]
SUMMARY_COLUMNS = ["scenario", "planner", "runs", "success_rate", "iterations_min",
                   "iterations_median", "iterations_max", "cost_min", "cost_median", "cost_max",
                   "wall_median_s"]


@dataclass(frozen=True)
class BenchResult:
    runs: pd.DataFrame
    summary: pd.DataFrame
    #: For each (scenario, planner), the run whose iteration count is the median (for plots).
    examples: dict[tuple[str, str], PlanResult] = field(default_factory=dict)
    scenarios: dict[str, Scenario] = field(default_factory=dict)
    settings: dict[str, Any] = field(default_factory=dict)
    #: The loaded rulebook Fuzzy-RRT used (``None`` without fuzzy-rrt), for rule sentences.
    rulebook: Any = None


def _one_run(args) -> PlanResult:
    scenario, planner, rulebook, seed, max_iter = args
    return plan_scenario(scenario, planner=planner, rulebook=rulebook, seed=seed,
                         max_iter=max_iter)


def _warm_up(scenario: Scenario, planners: list[str], rulebook) -> None:
    """Compile/load the kernels once so that no timed run pays JIT cost."""
    for planner in planners:
        plan_scenario(scenario, planner=planner, rulebook=rulebook, seed=0, max_iter=5)


def run_benchmark(scenarios: list[Scenario], planners: list[str], runs: int = 50, seed: int = 0,
                  rulebook=None, max_iter: int = 10_000, workers: int = 1) -> BenchResult:
    """Run every planner ``runs`` times (seeds ``seed .. seed + runs - 1``) on every scenario."""
    for p in planners:
        if p not in PLANNERS:
            raise InputError("--planners", f"unknown planner {p!r} (expected one of {', '.join(PLANNERS)})")
    if runs < 1:
        raise InputError("--runs", f"must be >= 1, got {runs}")
    if workers < 1:
        raise InputError("--workers", f"must be >= 1, got {workers}")
    names = [s.name for s in scenarios]
    if len(set(names)) != len(names):
        raise InputError("scenarios", "two scenario files share the same name")
    rulebook_dir = None
    if "fuzzy-rrt" in planners:
        from xfuzzy_rrt.fuzzy.rulebook import default_rulebook_path, load_rulebook

        if rulebook is None:
            rulebook = default_rulebook_path()
        if not hasattr(rulebook, "arrays"):
            rulebook_dir = str(rulebook)
            rulebook = load_rulebook(rulebook)
    jobs = [(s, p, rulebook if p == "fuzzy-rrt" else None, seed + k, max_iter)
            for s in scenarios for p in planners for k in range(runs)]
    _warm_up(scenarios[0], planners, rulebook)
    if workers == 1:
        results = [_one_run(j) for j in jobs]
    else:
        with ProcessPoolExecutor(max_workers=min(workers, os.cpu_count() or 1),
                                 initializer=_warm_up,
                                 initargs=(scenarios[0], planners, rulebook)) as pool:
            results = list(pool.map(_one_run, jobs, chunksize=max(1, len(jobs) // (8 * workers))))
    rows = [{
        "scenario": r.scenario, "planner": r.planner, "seed": r.seed, "success": r.success,
        "iterations": r.iterations, "nodes": r.nodes,
        "cost_deg": np.nan if r.cost_deg is None else r.cost_deg, "wall_s": r.wall_s,
        "rulebook": r.rulebook, "rulebook_sha256": r.rulebook_sha256,
    } for r in results]
    runs_df = pd.DataFrame(rows, columns=RUN_COLUMNS)
    summary = summarise(runs_df)
    by_name = {s.name: s for s in scenarios}
    by_run = {(r.scenario, r.planner, r.seed): r for r in results}
    examples = {}
    for (scen, planner), group in runs_df.groupby(["scenario", "planner"], sort=False):
        ok = group[group["success"]]
        if ok.empty:
            continue
        target = ok["iterations"].median()
        seed_ = int(ok["seed"].iloc[int(np.argmin(np.abs(ok["iterations"].to_numpy() - target)))])
        example = by_run[(scen, planner, seed_)]
        if planner == "fuzzy-rrt":
            # Re-run the example with tracing (deterministic: the same run, plus its trace)
            # so the report can show what the fuzzy systems decided.
            example = plan_scenario(by_name[scen], planner=planner, rulebook=rulebook,
                                    seed=seed_, max_iter=max_iter, trace=True)
        examples[(scen, planner)] = example
    return BenchResult(runs=runs_df, summary=summary, examples=examples,
                       scenarios=by_name,
                       rulebook=rulebook if "fuzzy-rrt" in planners else None,
                       settings={"runs": runs, "seed": seed, "max_iter": max_iter,
                                 "planners": list(planners),
                                 "rulebook": getattr(rulebook, "name", None),
                                 "rulebook_dir": rulebook_dir,
                                 "rulebook_sha256": getattr(rulebook, "sha256", None)})


def summarise(runs: pd.DataFrame) -> pd.DataFrame:
    """One row per (scenario, planner): success rate and min/median/max of iterations and cost.

    Iteration statistics cover all runs (a failure counts as ``max_iter``, as in the paper's
    reward); cost statistics cover successful runs only.
    """
    rows = []
    for (scen, planner), g in runs.groupby(["scenario", "planner"], sort=False):
        ok = g[g["success"]]
        rows.append({
            "scenario": scen, "planner": planner, "runs": len(g),
            "success_rate": float(g["success"].mean()),
            "iterations_min": int(g["iterations"].min()),
            "iterations_median": float(g["iterations"].median()),
            "iterations_max": int(g["iterations"].max()),
            "cost_min": float(ok["cost_deg"].min()) if len(ok) else np.nan,
            "cost_median": float(ok["cost_deg"].median()) if len(ok) else np.nan,
            "cost_max": float(ok["cost_deg"].max()) if len(ok) else np.nan,
            "wall_median_s": float(g["wall_s"].median()),
        })
    return pd.DataFrame(rows, columns=SUMMARY_COLUMNS)


def shipped_scenarios() -> list[Path]:
    """The demo scenarios shipped inside the package."""
    return sorted((Path(__file__).resolve().parent.parent / "data" / "scenarios").glob("*.toml"))
