"""Run planners over scenarios and seeds; return one row per run and one per (scenario, planner).

Runs are independent and fully determined by ``(scenario, planner, rulebook, seed, max_iter)``,
so they can be spread over worker processes: results are collected in job order, which keeps
every column except the wall-clock ones identical whatever the number of workers. Column names
are the stable ones of SPEC.md (OMPL-style: one typed row per run).

Beside the planner's own ``wall_s`` (the compiled search alone) each row has
``time_total_s``, the whole :func:`plan_scenario` call as a user waits for it (set-up, planning
and the certification of the path), and ``work``, the planner's deterministic work count
(``PlanResult.work``; empty for a planner that does not count): the same in every run of the
same seed, whatever the machine or the number of workers; ``certify_work`` counts the
certification of the path the same way and ``work_total`` is their sum, the end-to-end work
(the deterministic twin of ``time_total_s``).

Every returned path -- ours or an OMPL planner's -- is certified by the planner API itself
(``found``, ``certified``, ``min_clearance_m``, ``penetration_m``; ``success`` is ``found and
certified``), and with ``shortcut=True`` a *certified* path is shortened by the same certified
shortcutting pass seeded with the run's seed (``cost_short_deg``; ``cost_deg`` stays the raw
cost; an uncertified path gets no shortened cost, since shortening would keep its bad edges).
Both happen inside the worker, so they parallelise with the planning.

Several rulebooks can run side by side: ``fuzzy-rrt:NAME`` (a shipped rulebook) or
``fuzzy-rrt:DIR`` is its own planner label, with its own rows; plain ``fuzzy-rrt`` is the
``rulebook`` argument or the shipped default. Every label is validated (and every rulebook
loaded) before the first run.

**The shipped default plans any arm.** Plain ``fuzzy-rrt`` without a ``rulebook`` runs, per
problem, :func:`~xfuzzy_rrt.planners.api.shipped_default`'s choice: ``goal-frame`` on one
2-joint arm, Fuzzy-RRT-Connect with ``goal-frame-any`` on any other. Its rows keep the label
``fuzzy-rrt`` (one row per planner, whatever the mix of problems); ``planner_used``,
``rulebook`` and ``rulebook_sha256`` in each row say what ran, and the benchmark lists both
rulebooks (the any-arm one under :data:`~xfuzzy_rrt.planners.api.ANY_ARM_KEY` when both ran).
"""

from __future__ import annotations

import contextlib
import os
import signal
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any, Callable

import numpy as np
import pandas as pd

from xfuzzy_rrt.bench.summary import ratio_table, summarise
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.scenario import Scenario
from xfuzzy_rrt.planners import registry
from xfuzzy_rrt.planners.api import plan_scenario
from xfuzzy_rrt.planners.result import PlanResult, path_cost_deg

RUN_COLUMNS = ["scenario", "planner", "seed", "success", "iterations", "nodes", "cost_deg",
               "wall_s", "time_first_s", "found", "certified", "min_clearance_m",
               "penetration_m", "rulebook", "rulebook_sha256", "time_total_s", "work",
               "certify_work", "work_total", "planner_used"]
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
    #: The loaded rulebook of the first Fuzzy-RRT planner (``None`` without one), for rule
    #: sentences; ``rulebooks`` has every Fuzzy-RRT planner label's rulebook.
    rulebook: Any = None
    #: Per planner pair, the distribution over scenarios of median-iteration ratios.
    ratios: pd.DataFrame | None = None
    #: Where the numbers came from (command, date, versions, git, machine, file hashes);
    #: filled when the result is written to or read from a bench folder (``bench.store``).
    provenance: dict[str, Any] = field(default_factory=dict)
    #: Planner label (``fuzzy-rrt``, ``fuzzy-rrt:paper``, ...) -> the loaded rulebook it ran.
    rulebooks: dict[str, Any] = field(default_factory=dict)
    #: For each (scenario, planner), the returned path that came closest to an obstacle (or went
    #: deepest into one): what a safety audit looks at, next to the median run.
    worst_examples: dict[tuple[str, str], PlanResult] = field(default_factory=dict)


@dataclass(frozen=True)
class _Job:
    scenario: Scenario
    planner: str
    rulebook: Any
    seed: int
    max_iter: int
    shortcut: bool


def check_planners(planners: list[str]) -> list[str]:
    """Validate planner labels before anything runs, through the planner API (``ompl:NAME``
    names an OMPL planner, ``fuzzy-rrt:NAME`` a rulebook; each error is one line naming
    ``--planners``)."""
    from xfuzzy_rrt.planners.api import check_planner

    if not planners:
        raise InputError("--planners", "name at least one planner")
    for k, p in enumerate(planners):
        if p in planners[:k]:
            raise InputError("--planners", f"planner {p!r} listed twice")
        check_planner(p, "--planners")
    return list(planners)


def load_rulebooks(planners: list[str], rulebook=None) -> tuple[dict[str, Any], dict[str, str]]:
    """Load the rulebook of every Fuzzy-RRT label: ``({label: Rulebook}, {label: directory})``.

    Plain ``fuzzy-rrt`` uses ``rulebook`` (a loaded rulebook or a directory) or the shipped
    default; ``fuzzy-rrt:NAME``/``fuzzy-rrt:DIR`` its own. Loading validates every rule, so a
    broken rulebook fails here, before any planning.
    """
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
    from xfuzzy_rrt.planners.api import label_rulebook_dir, parse_planner

    books: dict[str, Any] = {}
    dirs: dict[str, str] = {}
    for label in planners:
        spec = parse_planner(label, "--planners")
        if not spec.planner.takes_rulebook:
            continue
        # the label's own folder first, then the caller's rulebook, then the shipped default
        source = rulebook if spec.rulebook_dir is None and rulebook is not None \
            else label_rulebook_dir(spec)
        if hasattr(source, "arrays"):
            books[label] = source
            dirs[label] = None
        else:
            dirs[label] = str(Path(source).resolve())
            books[label] = load_rulebook(source)
    return books, dirs


def _one_run(job: _Job) -> tuple[PlanResult, dict[str, Any]]:
    t0 = time.perf_counter()  # end to end, as a user waits: set-up, planning, certification
    r = plan_scenario(job.scenario, planner=job.planner, rulebook=job.rulebook, seed=job.seed,
                      max_iter=job.max_iter)
    time_total = time.perf_counter() - t0
    params = r.params if isinstance(r.params, dict) else {}
    time_first = params.get("time_first_s")
    first_solution = (registry.lookup(job.planner).first_solution
                      or params.get("stopped_by") == "solution")
    if time_first is None and r.found and first_solution:
        time_first = r.wall_s  # the run stopped at its first solution
    row: dict[str, Any] = {
        "scenario": r.scenario, "planner": job.planner, "seed": r.seed, "success": r.success,
        "iterations": r.iterations, "nodes": r.nodes,
        "cost_deg": np.nan if r.cost_deg is None else r.cost_deg, "wall_s": r.wall_s,
        "time_first_s": np.nan if time_first is None else float(time_first),
        "found": r.found, "certified": r.certified,
        "min_clearance_m": np.nan if r.min_clearance_m is None else float(r.min_clearance_m),
        "penetration_m": np.nan if r.penetration_m is None else float(r.penetration_m),
        "rulebook": r.rulebook, "rulebook_sha256": r.rulebook_sha256,
        "time_total_s": time_total, "work": np.nan if r.work is None else int(r.work),
        "certify_work": int(r.certify_work),
        "work_total": np.nan if r.work is None else int(r.work) + int(r.certify_work),
        "planner_used": r.planner_used or r.planner,
    }
    if job.shortcut:
        row["cost_short_deg"] = np.nan
        if r.success:  # only a certified path: shortening keeps unchanged input edges
            from xfuzzy_rrt.planners.shortcut import shortcut_path

            from xfuzzy_rrt.geometry.clearance import planning_margin

            short = shortcut_path(job.scenario.arrays(), r.path_deg, seed=job.seed,
                                  attempts=SHORTCUT_ATTEMPTS,
                                  margin=planning_margin(job.scenario))
            row["cost_short_deg"] = path_cost_deg(short)
    return r, row


def check_pairs(scenarios: list[Scenario], rulebooks: dict[str, Any]) -> None:
    """Every (scenario, Fuzzy-RRT rulebook) pair fits -- the rulebook's DOF drives the arms --
    checked before the first run, so a 5-DOF problem among 2-DOF ones fails at once rather
    than after the runs before it (one line naming the scenario file and the rulebook).

    ``rulebooks``: label -> what its jobs get (:func:`job_rulebooks`); the shipped default of
    plain ``fuzzy-rrt`` fits every problem by construction, a ``fuzzy-rrt-connect`` label is
    checked as Fuzzy-RRT-Connect checks it (a DOF-free rulebook fits every arm): each label's
    registration's ``fits`` (:mod:`xfuzzy_rrt.planners.registry`)."""
    from xfuzzy_rrt.planners.api import ShippedDefault
    from xfuzzy_rrt.planners.checks import check_dof

    fits = {label: registry.lookup(label).fits_fn for label in rulebooks}
    for s in scenarios:
        check_dof(s)
        for label, rb in rulebooks.items():
            if isinstance(rb, ShippedDefault) or fits[label] is None:
                continue
            fits[label](rb, s)


def job_rulebooks(planners: list[str], rulebooks: dict[str, Any], rulebook=None) -> dict[str, Any]:
    """Label -> what :func:`plan_scenario` gets as ``rulebook`` in that label's jobs: the loaded
    rulebook, or for plain ``fuzzy-rrt`` without a ``rulebook`` the shipped default with both
    its rulebooks loaded once (:class:`~xfuzzy_rrt.planners.api.ShippedDefault`), so that each
    problem runs its own default and no run re-reads a rulebook; ``rrt:tuned`` gets its tuned
    settings read once (:class:`~xfuzzy_rrt.planners.api.TunedRRT`), so that no run of the
    peer re-reads its file either."""
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
    from xfuzzy_rrt.planners.api import (ANY_ARM_PLANNER, ShippedDefault, default_rulebook_dir,
                                         preloaded)

    out = dict(rulebooks)
    for planner in planners:
        if planner not in out:
            given = preloaded(planner, None)
            if given is not None:
                out[planner] = given
    if "fuzzy-rrt" in planners and rulebook is None and "fuzzy-rrt" in rulebooks:
        out["fuzzy-rrt"] = ShippedDefault(rulebooks["fuzzy-rrt"],
                                          load_rulebook(default_rulebook_dir(ANY_ARM_PLANNER)))
    return out


def ran_rulebooks(scenarios: list[Scenario], rulebooks: dict[str, Any],
                  dirs: dict[str, str | None], jobs_rb: dict[str, Any]
                  ) -> tuple[dict[str, Any], dict[str, str | None]]:
    """The rulebooks the benchmark ran, for its tables and report: ``rulebooks`` as loaded,
    except that the shipped default of plain ``fuzzy-rrt`` lists what the problems used --
    ``goal-frame`` under ``fuzzy-rrt`` when a problem is one 2-joint arm, ``goal-frame-any``
    under :data:`~xfuzzy_rrt.planners.api.ANY_ARM_KEY` when another problem is not (under
    ``fuzzy-rrt`` itself when no problem is)."""
    from xfuzzy_rrt.planners.api import (ANY_ARM_KEY, ANY_ARM_PLANNER, ShippedDefault,
                                         default_rulebook_dir)

    shipped = jobs_rb.get("fuzzy-rrt")
    if not isinstance(shipped, ShippedDefault):
        return dict(rulebooks), dict(dirs)
    two = any(s.one_two_joint_arm for s in scenarios)
    other = not all(s.one_two_joint_arm for s in scenarios)
    any_dir = str(default_rulebook_dir(ANY_ARM_PLANNER).resolve())
    books, where = {}, {}
    for label, rb in rulebooks.items():
        if label != "fuzzy-rrt":
            books[label], where[label] = rb, dirs.get(label)
        elif two:
            books[label], where[label] = rb, dirs.get(label)
            if other:
                books[ANY_ARM_KEY], where[ANY_ARM_KEY] = shipped.any_arm, any_dir
        else:
            books[label], where[label] = shipped.any_arm, any_dir
    return books, where


def _warm_up(scenarios: list[Scenario], planners: list[str], rulebooks: dict[str, Any]) -> None:
    """Compile/load the kernels once so that no timed run pays JIT cost.

    Also the first call of every planner through the API: an unusable ``ompl:NAME`` fails
    here, before any run. ``scenarios``: the first problem, and the first one that is not
    like it (one 2-joint arm or not), since plain ``fuzzy-rrt`` runs another planner there.
    """
    for scenario in scenarios:
        for planner in planners:
            plan_scenario(scenario, planner=planner, rulebook=rulebooks.get(planner), seed=0,
                          max_iter=5)


def _warm_up_scenarios(scenarios: list[Scenario]) -> list[Scenario]:
    first = scenarios[0].one_two_joint_arm
    other = next((s for s in scenarios if s.one_two_joint_arm != first), None)
    return [scenarios[0]] + ([other] if other is not None else [])


def _die_with_parent(parent: int) -> None:
    """Ask Linux to kill this worker when its parent dies (``kill -9`` included), so a killed
    bench leaves no orphan holding its pipes; elsewhere a no-op."""
    import ctypes
    import sys

    if not sys.platform.startswith("linux"):
        return
    with contextlib.suppress(OSError, AttributeError):
        libc = ctypes.CDLL(None, use_errno=True)
        libc.prctl(1, signal.SIGKILL, 0, 0, 0)  # PR_SET_PDEATHSIG
    if os.getppid() != parent:  # the parent died before the request took effect
        os._exit(1)


#: A worker's scenarios and rulebooks, received once at start-up (:func:`_worker_init`).
_WORKER: dict[str, Any] = {}


def _worker_init(parent: int, scenarios: list[Scenario], planners: list[str],
                 rulebooks: dict[str, Any], warm: list[int]) -> None:
    """Worker start-up: die with the parent, leave Ctrl-C to it (it cancels the pool and
    reports once; a worker's KeyboardInterrupt traceback is noise), keep the scenarios and
    rulebooks the jobs name (:func:`_pooled_run`), then warm up."""
    _die_with_parent(parent)
    signal.signal(signal.SIGINT, signal.SIG_IGN)
    with contextlib.suppress(AttributeError, ValueError):
        signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
    _WORKER.update(scenarios=scenarios, rulebooks=rulebooks)
    _warm_up([scenarios[k] for k in warm], planners, rulebooks)


def _pooled_run(key: tuple[int, str, int, int, bool]) -> tuple[PlanResult, dict[str, Any]]:
    """One job on a worker, named by ``(scenario index, planner, seed, max_iter, shortcut)``.

    Why not the job itself: a pickled job arrives as new scenario and rulebook objects, which
    miss every set-up remembered for the ones the worker already planned with (~50 us a call
    for a scenario, milliseconds for a rulebook), inside the ``time_total_s`` a bench reports;
    a worker keeps one object of each for all its jobs."""
    k, planner, seed, max_iter, shortcut = key
    return _one_run(_Job(_WORKER["scenarios"][k], planner, _WORKER["rulebooks"].get(planner),
                         seed, max_iter, shortcut))


def _median_run_seed(group: pd.DataFrame) -> int | None:
    ok = group[group["success"].astype(bool)]
    if ok.empty:
        return None
    target = ok["iterations"].median()
    return int(ok["seed"].iloc[int(np.argmin(np.abs(ok["iterations"].to_numpy() - target)))])


def _worst_run_seed(group: pd.DataFrame) -> int | None:
    """Seed of the found run with the smallest minimum clearance (the first on ties)."""
    found = group[group["found"].astype(bool)]
    if found.empty:
        return None
    clearance = pd.to_numeric(found["min_clearance_m"], errors="coerce").fillna(np.inf)
    return int(found["seed"].iloc[int(np.argmin(clearance.to_numpy()))])


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
    from xfuzzy_rrt.planners.rng import check_seed

    check_seed(seed, runs)
    if not scenarios:
        raise InputError("scenarios", "no scenario to run")
    names = [s.name for s in scenarios]
    if len(set(names)) != len(names):
        dup = sorted({n for n in names if names.count(n) > 1})[0]
        raise InputError("scenarios", f"two scenario files share the name {dup!r}")
    loaded, loaded_dirs = load_rulebooks(planners, rulebook)
    jobs_rb = job_rulebooks(planners, loaded, rulebook)
    check_pairs(scenarios, jobs_rb)
    rulebooks, rulebook_dirs = ran_rulebooks(scenarios, loaded, loaded_dirs, jobs_rb)
    jobs = [_Job(s, p, jobs_rb.get(p), seed + k, max_iter, shortcut)
            for s in scenarios for p in planners for k in range(runs)]
    warm = _warm_up_scenarios(scenarios)
    _warm_up(warm, planners, jobs_rb)
    outputs: list[tuple[PlanResult, dict[str, Any]]] = []
    if workers == 1:
        for j in jobs:
            outputs.append(_one_run(j))
            if progress is not None:
                progress(len(outputs), len(jobs))
    else:
        index = {id(s): k for k, s in enumerate(scenarios)}
        keys = [(index[id(j.scenario)], j.planner, j.seed, j.max_iter, j.shortcut) for j in jobs]
        outputs = _run_pool(keys, workers, (os.getpid(), scenarios, planners, jobs_rb,
                                            [index[id(s)] for s in warm]), progress)
    columns = RUN_COLUMNS + (["cost_short_deg"] if shortcut else [])
    runs_df = pd.DataFrame([row for _, row in outputs], columns=columns)
    for col in ("success", "found", "certified"):
        runs_df[col] = runs_df[col].astype(bool)
    for col in ("work", "work_total"):  # integers; empty when not counted
        runs_df[col] = runs_df[col].astype("Int64")
    summary = summarise(runs_df)
    by_name = {s.name: s for s in scenarios}
    by_run = {(r.scenario, row["planner"], r.seed): r for r, row in outputs}
    examples = {}
    for (scen, planner), group in runs_df.groupby(["scenario", "planner"], sort=False):
        seed_ = _median_run_seed(group)
        if seed_ is None:
            continue
        example = by_run[(scen, planner, seed_)]
        if planner in jobs_rb and registry.lookup(planner).traces:
            # Re-run the example with tracing (deterministic: the same run, plus its trace)
            # so the report can show what the fuzzy systems decided.
            example = plan_scenario(by_name[scen], planner=planner, rulebook=jobs_rb[planner],
                                    seed=seed_, max_iter=max_iter, trace=True)
        examples[(scen, planner)] = example
    worst = {}
    for (scen, planner), group in runs_df.groupby(["scenario", "planner"], sort=False):
        seed_ = _worst_run_seed(group)
        if seed_ is not None:
            same = examples.get((scen, planner))
            worst[(scen, planner)] = (same if same is not None and same.seed == seed_
                                      else by_run[(scen, planner, seed_)])
    first = next(iter(rulebooks), None)
    main_label = "fuzzy-rrt" if "fuzzy-rrt" in rulebooks else first
    main_rb = rulebooks.get(main_label) if main_label else None
    settings = {"runs": runs, "seed": seed, "max_iter": max_iter, "planners": list(planners),
                "shortcut": bool(shortcut), "workers": int(workers),
                "rulebook": getattr(main_rb, "name", None),
                "rulebook_dir": rulebook_dirs.get(main_label) if main_label else None,
                "rulebook_sha256": getattr(main_rb, "sha256", None),
                "rulebooks": [{"planner": label, "name": rb.name, "dir": rulebook_dirs[label],
                               "sha256": rb.sha256} for label, rb in rulebooks.items()]}
    if "rrt:tuned" in planners:  # the settings the tuned label resolved to (the report names them)
        from xfuzzy_rrt.planners.tuned import shape_of, shape_text, tuned_for_shapes

        rows = tuned_for_shapes("rrt", {shape_of(sc) for sc in by_name.values()})
        # one tuned shape: its two settings, as before; several: each shape's (tuned.py)
        settings["tuned"] = {"rrt:tuned": rows[0][1] if len(rows) == 1 else
                             {"by_shape": {shape_text(s): p for s, p in rows}} if rows else None}
    return BenchResult(runs=runs_df, summary=summary, examples=examples, scenarios=by_name,
                       settings=settings, rulebook=main_rb, ratios=ratio_table(summary),
                       rulebooks=dict(rulebooks), worst_examples=worst)


def _run_pool(jobs: list[tuple], workers: int, init_args: tuple, progress: Progress | None):
    """Run ``jobs`` (:func:`_pooled_run`'s keys) on worker processes, results in job order.

    Ctrl-C: workers ignore SIGINT (:func:`_worker_init`; SIGINT is also blocked while they are
    forked, so none can catch it before it runs), the parent cancels what has not started and
    re-raises, so the user sees one line from the CLI and no worker traceback.
    """
    outputs = []
    blocked = False
    with contextlib.suppress(AttributeError, ValueError):
        signal.pthread_sigmask(signal.SIG_BLOCK, {signal.SIGINT})
        blocked = True
    pool = ProcessPoolExecutor(max_workers=min(workers, os.cpu_count() or 1),
                               initializer=_worker_init, initargs=init_args)
    try:
        try:
            chunk = max(1, min(16, len(jobs) // (8 * workers)))
            results = pool.map(_pooled_run, jobs, chunksize=chunk)  # forks the workers now
        finally:
            if blocked:
                signal.pthread_sigmask(signal.SIG_UNBLOCK, {signal.SIGINT})
        for out in results:
            outputs.append(out)
            if progress is not None:
                progress(len(outputs), len(jobs))
    except BaseException:
        pool.shutdown(wait=True, cancel_futures=True)
        raise
    pool.shutdown(wait=True)
    return outputs


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

