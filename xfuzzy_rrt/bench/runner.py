"""Run planners over scenarios and seeds; return one row per run and one per (scenario, planner).

Runs are independent and fully determined by ``(scenario, planner, rulebook, seed, max_iter)``,
so they can be spread over worker processes: results are collected in job order, which keeps
every column except the wall-clock ones identical whatever the number of workers. Column names
are the stable ones of SPEC.md (OMPL-style: one typed row per run).

Every returned path -- ours or an OMPL planner's -- is re-checked with the certified edge
check (``certified``, ``penetration_m``), and with ``shortcut=True`` shortened by the same
certified shortcutting pass seeded with the run's seed (``cost_short_deg``; ``cost_deg`` stays
the raw cost). Both happen inside the worker, so they parallelise with the planning.
"""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pandas as pd

from xfuzzy_rrt.bench.summary import ratio_table, summarise
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.scenario import Scenario
from xfuzzy_rrt.planners.api import plan_scenario
from xfuzzy_rrt.planners.result import PlanResult, path_cost_deg

RUN_COLUMNS = ["scenario", "planner", "seed", "success", "iterations", "nodes", "cost_deg",
               "wall_s", "time_first_s", "certified", "penetration_m", "rulebook",
               "rulebook_sha256"]
#: Our planners stop at their first solution: their time to first path is their wall time.
_FIRST_SOLUTION_PLANNERS = ("rrt", "fuzzy-rrt")
#: Shortcutting attempts per path (the OMPL helper's default).
SHORTCUT_ATTEMPTS = 200

Progress = Callable[[int, int], None]


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
    #: Per planner pair, the distribution over scenarios of median-iteration ratios.
    ratios: pd.DataFrame | None = None
    #: Where the numbers came from (command, date, versions, git, machine, file hashes);
    #: filled when the result is written to or read from a bench folder (``bench.store``).
    provenance: dict[str, Any] = field(default_factory=dict)


@dataclass(frozen=True)
class _Job:
    scenario: Scenario
    planner: str
    rulebook: Any
    seed: int
    max_iter: int
    shortcut: bool


def check_planners(planners: list[str]) -> list[str]:
    """Validate planner names before anything runs, through the planner API (``ompl:NAME``
    names an OMPL planner; without the extra this is one line naming it)."""
    from xfuzzy_rrt.planners.api import check_planner

    if not planners:
        raise InputError("--planners", "name at least one planner")
    for k, p in enumerate(planners):
        if p in planners[:k]:
            raise InputError("--planners", f"planner {p!r} listed twice")
        check_planner(p, "--planners")
    return list(planners)


def _certify(scenario: Scenario, path: np.ndarray) -> tuple[bool, float]:
    from xfuzzy_rrt.geometry.path_check import certify_path

    from xfuzzy_rrt.geometry.clearance import planning_margin

    check = certify_path(scenario.arrays(), path, planning_margin(scenario))
    return bool(check.certified), float(check.penetration_m)


def _one_run(job: _Job) -> tuple[PlanResult, dict[str, Any]]:
    from xfuzzy_rrt.geometry.clearance import planning_margin

    r = plan_scenario(job.scenario, planner=job.planner, rulebook=job.rulebook, seed=job.seed,
                      max_iter=job.max_iter)
    params = r.params if isinstance(r.params, dict) else {}
    time_first = params.get("time_first_s")
    if time_first is None and r.success and (job.planner in _FIRST_SOLUTION_PLANNERS
                                             or params.get("stopped_by") == "solution"):
        time_first = r.wall_s  # the run stopped at its first solution
    row: dict[str, Any] = {
        "scenario": r.scenario, "planner": job.planner, "seed": r.seed, "success": r.success,
        "iterations": r.iterations, "nodes": r.nodes,
        "cost_deg": np.nan if r.cost_deg is None else r.cost_deg, "wall_s": r.wall_s,
        "time_first_s": np.nan if time_first is None else float(time_first),
        "certified": pd.NA, "penetration_m": np.nan,
        "rulebook": r.rulebook, "rulebook_sha256": r.rulebook_sha256,
    }
    if r.success and np.size(r.path_deg):
        if params.get("certified") is not None and params.get("penetration_m") is not None:
            row["certified"] = bool(params["certified"])  # the OMPL bridge already checked
            row["penetration_m"] = float(params["penetration_m"])
        else:
            row["certified"], row["penetration_m"] = _certify(job.scenario, r.path_deg)
        if job.shortcut:
            from xfuzzy_rrt.planners.shortcut import shortcut_path

            short = shortcut_path(job.scenario.arrays(), r.path_deg, seed=job.seed,
                                  attempts=SHORTCUT_ATTEMPTS,
                                  margin=planning_margin(job.scenario))
            row["cost_short_deg"] = path_cost_deg(short)
    elif job.shortcut:
        row["cost_short_deg"] = np.nan
    return r, row


def _warm_up(scenario: Scenario, planners: list[str], rulebook) -> None:
    """Compile/load the kernels once so that no timed run pays JIT cost.

    Also the first call of every planner through the API: an unusable ``ompl:NAME`` fails
    here, before any run.
    """
    for planner in planners:
        plan_scenario(scenario, planner=planner, rulebook=rulebook if planner == "fuzzy-rrt"
                      else None, seed=0, max_iter=5)


def _median_run_seed(group: pd.DataFrame) -> int | None:
    ok = group[group["success"].astype(bool)]
    if ok.empty:
        return None
    target = ok["iterations"].median()
    return int(ok["seed"].iloc[int(np.argmin(np.abs(ok["iterations"].to_numpy() - target)))])


def run_benchmark(scenarios: list[Scenario], planners: list[str], runs: int = 50, seed: int = 0,
                  rulebook=None, max_iter: int = 10_000, workers: int = 1,
                  shortcut: bool = False, progress: Progress | None = None) -> BenchResult:
    """Run every planner ``runs`` times (seeds ``seed .. seed + runs - 1``) on every scenario.

    ``progress(done, total)`` is called after each run (in this process, in job order).
    """
    planners = check_planners(list(planners))
    if runs < 1:
        raise InputError("--runs", f"must be >= 1, got {runs}")
    if workers < 1:
        raise InputError("--workers", f"must be >= 1, got {workers}")
    if not scenarios:
        raise InputError("scenarios", "no scenario to run")
    names = [s.name for s in scenarios]
    if len(set(names)) != len(names):
        dup = sorted({n for n in names if names.count(n) > 1})[0]
        raise InputError("scenarios", f"two scenario files share the name {dup!r}")
    rulebook_dir = None
    if "fuzzy-rrt" in planners:
        from xfuzzy_rrt.fuzzy.rulebook import default_rulebook_path, load_rulebook

        if rulebook is None:
            rulebook = default_rulebook_path()
        if not hasattr(rulebook, "arrays"):
            rulebook_dir = str(Path(rulebook).resolve())
            rulebook = load_rulebook(rulebook)
    else:
        rulebook = None
    jobs = [_Job(s, p, rulebook if p == "fuzzy-rrt" else None, seed + k, max_iter, shortcut)
            for s in scenarios for p in planners for k in range(runs)]
    _warm_up(scenarios[0], planners, rulebook)
    outputs: list[tuple[PlanResult, dict[str, Any]]] = []
    if workers == 1:
        for j in jobs:
            outputs.append(_one_run(j))
            if progress is not None:
                progress(len(outputs), len(jobs))
    else:
        with ProcessPoolExecutor(max_workers=min(workers, os.cpu_count() or 1),
                                 initializer=_warm_up,
                                 initargs=(scenarios[0], planners, rulebook)) as pool:
            chunk = max(1, min(16, len(jobs) // (8 * workers)))
            for out in pool.map(_one_run, jobs, chunksize=chunk):
                outputs.append(out)
                if progress is not None:
                    progress(len(outputs), len(jobs))
    columns = RUN_COLUMNS + (["cost_short_deg"] if shortcut else [])
    runs_df = pd.DataFrame([row for _, row in outputs], columns=columns)
    runs_df["certified"] = runs_df["certified"].astype("boolean")
    summary = summarise(runs_df)
    by_name = {s.name: s for s in scenarios}
    by_run = {(r.scenario, r.planner, r.seed): r for r, _ in outputs}
    examples = {}
    for (scen, planner), group in runs_df.groupby(["scenario", "planner"], sort=False):
        seed_ = _median_run_seed(group)
        if seed_ is None:
            continue
        example = by_run[(scen, planner, seed_)]
        if planner == "fuzzy-rrt":
            # Re-run the example with tracing (deterministic: the same run, plus its trace)
            # so the report can show what the fuzzy systems decided.
            example = plan_scenario(by_name[scen], planner=planner, rulebook=rulebook,
                                    seed=seed_, max_iter=max_iter, trace=True)
        examples[(scen, planner)] = example
    settings = {"runs": runs, "seed": seed, "max_iter": max_iter, "planners": list(planners),
                "shortcut": bool(shortcut), "workers": int(workers),
                "rulebook": getattr(rulebook, "name", None), "rulebook_dir": rulebook_dir,
                "rulebook_sha256": getattr(rulebook, "sha256", None)}
    return BenchResult(runs=runs_df, summary=summary, examples=examples, scenarios=by_name,
                       settings=settings, rulebook=rulebook, ratios=ratio_table(summary))


def scenario_files(paths: list[Path]) -> list[Path]:
    """Expand the command-line arguments: a directory means every ``*.toml`` in it (sorted)."""
    out: list[Path] = []
    for p in paths:
        p = Path(p)
        if p.is_dir():
            found = sorted(q for q in p.glob("*.toml") if q.is_file())
            if not found:
                raise InputError(str(p), "directory contains no *.toml scenario file")
            out.extend(found)
        else:
            out.append(p)
    return out


def shipped_scenarios() -> list[Path]:
    """The demo scenarios shipped inside the package."""
    return sorted((Path(__file__).resolve().parent.parent / "data" / "scenarios").glob("*.toml"))

