"""Tuning a peer planner's parameters on training problems: the search behind ``rrt:tuned``.

Why: the paper compares Fuzzy-RRT with RRT at a fixed 10° step, but RRT's step and goal bias
are free parameters and a larger step alone makes it several times faster. A claim against a
peer only means something against the peer *at its best*, found by a documented search that
never sees the problems the project reports on. So:

- **Problems**: generated on the spot by the scenario generator (the ``sample-*`` family and
  the ``hard`` and ``mira`` families by default, ``--problems`` of each) from a *training*
  generator seed (default 8100). The generator seeds the README and ``rulebooks/README.md``
  evaluate on (:data:`EVALUATION_SEEDS`) are refused.
- **Grid**: every combination of the planner's parameter values (:func:`default_grid`; for
  RRT ``step_deg`` x ``goal_bias``, for an OMPL planner ``range_deg``, run as the label
  ``ompl:NAME:range=R``).
- **Objective**: the median over problems of the median over runs (plan seeds ``0 ..
  runs - 1``, the same for every grid point) of the *end-to-end work* to the first certified
  path: ``PlanResult.work`` (the search: distance evaluations plus nearest-neighbour visits)
  plus ``PlanResult.certify_work`` (certifying the returned path: the exact minimum clearance
  and the certified edge check). It stands in for the end-to-end time a user waits, and the
  certification must be in it: long edges make the search cheaper but their exact check
  dearer (measured: from a 10° to a 90° step the search's work falls about 6x while the
  certification's time grows about 5x), so the search's work alone would pick steps that
  are slower end to end. A run without a
  certified path counts with the work it spent until its iteration budget ran out -- the
  project's convention for every measure (``iterations`` counts ``max_iter``, time the time
  spent), so a grid point that often fails pays for it; its success rates stand beside it in
  the table. Work, not time: it is
  deterministic, so the search -- and the file it writes -- is reproducible byte for byte on
  any machine, while wall-clock time on a shared machine is not. Time is printed beside it
  for information only. Ties go to the higher worst-problem success rate, then to the first
  grid point.

The result is written as a small TOML file (:func:`render_tuned_file`) with the chosen values,
the whole objective table and the provenance (the command, generator seed, families, plan
seeds, version and a SHA-256 of the planner code the numbers depend on).
:mod:`xfuzzy_rrt.planners.tuned` reads it.
"""

from __future__ import annotations

import hashlib
import math
import os
import time
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass
from pathlib import Path
from typing import Any, Callable

import numpy as np

from xfuzzy_rrt.errors import InputError

#: Generator seeds whose problems the README and rulebooks/README.md report on: never tuned on.
EVALUATION_SEEDS = (2000, 7100, 7200, 7500, 7600, 9800)
DEFAULT_SEED = 8100
DEFAULT_FAMILIES = ("sample", "hard", "mira")
DEFAULT_PROBLEMS = 16
DEFAULT_RUNS = 10
DEFAULT_MAX_ITER = 10_000
#: Values searched: steps/ranges from half the paper's 10° to twice a turn. (Up to 120° until
#: blocked edges became cheap to reject, issue 24: RRT's best step then moved to 120°, the edge
#: of that grid, so the grid grew past it; up to 240° until the thirty-first session, when 300°
#: needed 16 % less work than the 180° chosen on one 2-joint arm, and 480° was best with two
#: 3-joint arms: the joint-space diameter is 360° x sqrt(joints).)
STEPS_DEG = (5.0, 10.0, 20.0, 30.0, 45.0, 60.0, 90.0, 120.0, 180.0, 240.0, 300.0, 360.0,
             480.0, 720.0)
GOAL_BIASES = (0.0, 0.05, 0.1, 0.2, 0.3)
#: Planner code the tuning numbers depend on (hashed into the provenance).
CODE_FILES = ("planners/rrt.py", "planners/extend.py", "planners/tree.py", "planners/rng.py",
              "planners/ompl_bridge.py", "planners/result.py", "geometry/collision.py",
              "geometry/problem.py", "geometry/kinematics.py", "geometry/signed.py",
              "geometry/clearance.py", "geometry/path_check.py", "scenarios/generate.py")

Progress = Callable[[int, int], None]


def default_grid(label: str) -> dict[str, tuple[float, ...]]:
    """The parameter values searched for planner ``label`` (``rrt`` or ``ompl:NAME``)."""
    if label == "rrt":
        return {"step_deg": STEPS_DEG, "goal_bias": GOAL_BIASES}
    if label.startswith("ompl:") and label.count(":") == 1 and len(label) > 5:
        return {"range_deg": STEPS_DEG}
    raise InputError("PLANNER", f"cannot tune {label!r}: tunable planners are rrt and "
                     "ompl:NAME (Fuzzy-RRT takes its settings from its rulebook)")


def grid_points(grid: dict[str, tuple[float, ...]]) -> list[dict[str, float]]:
    """Every combination, the first parameter varying slowest (a fixed, documented order)."""
    points: list[dict[str, float]] = [{}]
    for name, values in grid.items():
        points = [{**p, name: float(v)} for p in points for v in values]
    return points


def parse_grid(text: str, label: str) -> dict[str, tuple[float, ...]]:
    """``"step_deg=10,60;goal_bias=0.1"`` -> a grid over the planner's own parameter names."""
    known = default_grid(label)
    grid: dict[str, tuple[float, ...]] = {}
    for part in [p.strip() for p in text.split(";") if p.strip()]:
        name, eq, values = part.partition("=")
        name = name.strip()
        if not eq or name not in known:
            raise InputError("--grid", f"expected NAME=V1,V2;... with NAME one of "
                             f"{', '.join(known)}, got {part!r}")
        try:
            vals = tuple(float(v) for v in values.split(","))
        except ValueError:
            raise InputError("--grid", f"values of {name} must be numbers, got {values!r}") from None
        if not vals or not all(math.isfinite(v) for v in vals):
            raise InputError("--grid", f"values of {name} must be finite numbers")
        grid[name] = vals
    for name, values in known.items():
        grid.setdefault(name, values)
    return {name: grid[name] for name in known}


def planner_call(label: str, point: dict[str, float]) -> tuple[str, dict[str, float]]:
    """The ``plan_scenario`` planner label and keyword arguments of one grid point."""
    if label == "rrt":
        return "rrt", {"step_deg": point["step_deg"], "goal_bias": point["goal_bias"]}
    return f"{label}:range={point['range_deg']:g}", {}


@dataclass(frozen=True)
class TuningResult:
    label: str
    grid: dict[str, tuple[float, ...]]
    #: One row per grid point: its parameters, ``objective`` (median work, a failed run
    #: counting the work it spent), ``success_rate`` (all runs),
    #: ``worst_success_rate`` (over problems), ``median_iterations`` (per-problem medians,
    #: failures counting ``max_iter``), ``search_work`` (the same median of the search's work
    #: alone, without certifying the path) and ``median_time_s`` (information only: not
    #: written).
    table: list[dict[str, Any]]
    best: dict[str, float]
    settings: dict[str, Any]


def check_seed(seed: int) -> int:
    if seed < 0:
        raise InputError("--seed", f"must be >= 0, got {seed}")
    if seed in EVALUATION_SEEDS:
        raise InputError("--seed", f"generator seed {seed} makes problems the project reports "
                         f"on ({', '.join(map(str, EVALUATION_SEEDS))}); tune on training "
                         f"seeds only, e.g. {DEFAULT_SEED}")
    return seed


#: The "family" of problems with another shape than one 2-joint arm: the N-DOF / multi-arm
#: generator (:func:`xfuzzy_rrt.scenarios.generate.generate_nd`), which has no families.
ND_FAMILY = "nd"


def check_shape(dof: int, arms: int, families: tuple[str, ...] = ()) -> None:
    """``--dof`` and ``--arms`` as the generator takes them; ``--family`` only for one 2-joint
    arm (the other shapes have one generator)."""
    from xfuzzy_rrt.scenarios.generate import MAX_ARMS, MAX_DOF, MIN_ARMS, MIN_DOF

    if not MIN_DOF <= dof <= MAX_DOF:
        raise InputError("--dof", f"must be {MIN_DOF} to {MAX_DOF} joints per arm, got {dof}")
    if not MIN_ARMS <= arms <= MAX_ARMS:
        raise InputError("--arms", f"must be {MIN_ARMS} to {MAX_ARMS}, got {arms}")
    if (dof, arms) != (2, 1) and tuple(families) not in ((), DEFAULT_FAMILIES, (ND_FAMILY,)):
        raise InputError("--family", "families exist for one 2-joint arm only; with --dof or "
                         "--arms the problems come from the N-joint generator")


def training_problems(seed: int, problems: int, families: tuple[str, ...], dof: int = 2,
                      arms: int = 1) -> list:
    """``problems`` generated problems of each family from generator ``seed`` (one 2-joint
    arm), or ``problems`` problems of ``arms`` arms of ``dof`` joints each."""
    from xfuzzy_rrt.scenarios.generate import FAMILIES, generate_one

    check_shape(dof, arms, families)
    if (dof, arms) != (2, 1):
        return [generate_one(seed, k, f"tune-{arms}x{dof}", dof=dof, arms=arms).scenario
                for k in range(problems)]
    for f in families:
        if f not in FAMILIES:
            raise InputError("--family", f"must be one of {', '.join(FAMILIES)}, got {f!r}")
    return [generate_one(seed, k, f"tune-{f}", f).scenario
            for f in families for k in range(problems)]


def _run(job) -> tuple[bool, int | None, int, float, int | None]:
    """``(certified success, end-to-end work, iterations, end-to-end seconds, search work)``
    of one run (work ``None`` when the planner does not count)."""
    scenario, planner, kwargs, seed, max_iter = job
    from xfuzzy_rrt.planners.api import plan_scenario

    t0 = time.perf_counter()
    r = plan_scenario(scenario, planner=planner, seed=seed, max_iter=max_iter, **kwargs)
    total = time.perf_counter() - t0
    work = None if r.work is None else int(r.work) + int(r.certify_work)
    return bool(r.success), work, int(r.iterations), total, r.work


def _worker_init(warm) -> None:
    for job in warm:
        _run(job)


def run_tuning(label: str, problems: int = DEFAULT_PROBLEMS, seed: int = DEFAULT_SEED,
               runs: int = DEFAULT_RUNS, families: tuple[str, ...] = DEFAULT_FAMILIES,
               max_iter: int = DEFAULT_MAX_ITER, grid: dict | None = None, workers: int = 1,
               progress: Progress | None = None, dof: int = 2, arms: int = 1) -> TuningResult:
    """Search ``grid`` (default :func:`default_grid`) for planner ``label`` (module docstring)
    on problems of ``arms`` arms of ``dof`` joints each (one 2-joint arm: ``families``).

    Every grid point runs on every problem with plan seeds ``0 .. runs - 1``; the result does
    not depend on ``workers``.
    """
    grid = default_grid(label) if grid is None else grid
    check_seed(seed)
    if problems < 1:
        raise InputError("--problems", f"must be >= 1, got {problems}")
    if runs < 1:
        raise InputError("--runs", f"must be >= 1, got {runs}")
    if workers < 1:
        raise InputError("--workers", f"must be >= 1, got {workers}")
    from xfuzzy_rrt.planners.api import parse_planner
    from xfuzzy_rrt.planners.checks import check_max_iter

    check_max_iter(max_iter)
    families = tuple(families)
    check_shape(dof, arms, families)
    if (dof, arms) != (2, 1):
        families = (ND_FAMILY,)
    points = grid_points(grid)
    for p in points:  # every label and value is checked before any run
        planner, kwargs = planner_call(label, p)
        parse_planner(planner, "PLANNER")
        if kwargs:
            from xfuzzy_rrt.planners.params import resolve_params

            resolve_params("rrt", **kwargs)
    scenarios = training_problems(seed, problems, families, dof, arms)
    jobs = [(sc, *planner_call(label, p), s, max_iter)
            for p in points for sc in scenarios for s in range(runs)]
    warm = [(scenarios[0], *planner_call(label, points[0]), 0, 5)]
    _worker_init(warm)
    if workers == 1:
        out = []
        for j in jobs:
            out.append(_run(j))
            if progress is not None:
                progress(len(out), len(jobs))
    else:
        out = []
        with ProcessPoolExecutor(max_workers=min(workers, os.cpu_count() or 1),
                                 initializer=_worker_init, initargs=(warm,)) as pool:
            for r in pool.map(_run, jobs, chunksize=max(1, min(32, len(jobs) // (8 * workers)))):
                out.append(r)
                if progress is not None:
                    progress(len(out), len(jobs))
    n_p, n_s = len(scenarios), runs
    table = []
    for i, p in enumerate(points):
        block = out[i * n_p * n_s:(i + 1) * n_p * n_s]
        ok = np.array([b[0] for b in block], dtype=bool).reshape(n_p, n_s)
        if any(b[1] is None for b in block):
            raise InputError("PLANNER", f"{planner_call(label, p)[0]} does not count its work "
                             "(PlanResult.work is None), so it cannot be tuned reproducibly")
        work = np.array([b[1] for b in block], dtype=np.float64).reshape(n_p, n_s)
        its = np.array([b[2] if b[0] else max_iter for b in block],
                       dtype=np.float64).reshape(n_p, n_s)
        secs = np.array([b[3] for b in block]).reshape(n_p, n_s)
        search = np.array([b[4] for b in block], dtype=np.float64).reshape(n_p, n_s)
        table.append({**p,
                      "objective": float(np.median(np.median(work, axis=1))),
                      "success_rate": float(ok.mean()),
                      "worst_success_rate": float(ok.mean(axis=1).min()),
                      "median_iterations": float(np.median(np.median(its, axis=1))),
                      "search_work": float(np.median(np.median(search, axis=1))),
                      "median_time_s": float(np.median(np.median(secs, axis=1)))})
    order = sorted(range(len(table)), key=lambda k: (table[k]["objective"],
                                                     -table[k]["worst_success_rate"], k))
    best = {name: table[order[0]][name] for name in grid}
    settings = {"problems": problems, "seed": seed, "runs": runs, "families": list(families),
                "max_iter": max_iter, "scenarios": [s.name for s in scenarios], "dof": dof,
                "arms": arms}
    return TuningResult(label=label, grid={k: tuple(v) for k, v in grid.items()}, table=table,
                        best=best, settings=settings)


def tune_command(result: TuningResult) -> str:
    """The command that reproduces ``result`` (``--out FILE`` aside: the output is the same
    wherever it is written, and ``--workers`` changes nothing)."""
    s = result.settings
    parts = ["xfuzzy-rrt", "tune", result.label, "--problems", str(s["problems"]), "--seed",
             str(s["seed"]), "--runs", str(s["runs"])]
    if (s.get("dof", 2), s.get("arms", 1)) != (2, 1):
        parts += ["--dof", str(s["dof"]), "--arms", str(s["arms"])]
    elif tuple(s["families"]) != DEFAULT_FAMILIES:
        for f in s["families"]:
            parts += ["--family", f]
    if s["max_iter"] != DEFAULT_MAX_ITER:
        parts += ["--max-iter", str(s["max_iter"])]
    if result.grid != default_grid(result.label):
        text = ";".join(f"{k}={','.join(f'{v:g}' for v in vs)}" for k, vs in result.grid.items())
        parts += ["--grid", f"'{text}'"]
    return " ".join(parts)


def code_sha256() -> str:
    """SHA-256 over the planner and generator sources the tuning numbers depend on."""
    root = Path(__file__).resolve().parent.parent
    h = hashlib.sha256()
    for rel in CODE_FILES:
        path = root / rel
        h.update(rel.encode() + b"\0")
        h.update(path.read_bytes() if path.is_file() else b"")
    return h.hexdigest()


def _num(x: float) -> str:
    """A TOML number: ``inf`` for infinity, else Python's shortest round-trip repr."""
    if math.isinf(x):
        return "inf" if x > 0 else "-inf"
    return repr(float(x))


def render_tuned_file(result: TuningResult) -> str:
    """The TOML text of the tuned file: deterministic (no dates, no times, no paths)."""
    from xfuzzy_rrt import __version__
    from xfuzzy_rrt.planners.tuned import arm_shape, shape_text

    s = result.settings
    names = list(result.grid)
    best_row = next(r for r in result.table if all(r[n] == result.best[n] for n in names))
    families = ", ".join(f'"{f}"' for f in s["families"])
    grid_text = " x ".join(n + " in {" + ", ".join(f"{v:g}" for v in result.grid[n]) + "}"
                           for n in names)
    lines = [
        f"# Tuned parameters of {result.label}, written by `xfuzzy-rrt tune` (do not edit by hand:",
        "# re-run the command below). Read by xfuzzy_rrt.planners.tuned.tuned_params.",
        f'planner = "{result.label}"',
        "",
        "[params]",
        *[f"{n} = {_num(result.best[n])}" for n in names],
        "",
        "[objective]",
        'measure = "end-to-end work"',
        ('unit = "distance evaluations plus nearest-neighbour node visits: PlanResult.work + '
         'PlanResult.certify_work"'),
        ('statistic = "median over problems of the median over runs of the end-to-end work to '
         'the first certified path; a run without one counts with the work it spent until '
         'max_iter"'),
        f"value = {_num(best_row['objective'])}",
        f"success_rate = {_num(best_row['success_rate'])}",
        f"worst_success_rate = {_num(best_row['worst_success_rate'])}",
        f"median_iterations = {_num(best_row['median_iterations'])}",
        f"search_work = {_num(best_row['search_work'])}",
        "",
        "[provenance]",
        f'command = "{tune_command(result)}"',
        f"generator_seed = {s['seed']}",
        f"families = [{families}]",
        f"problems_per_family = {s['problems']}",
        f'shape = "{shape_text(arm_shape(s.get("dof", 2), s.get("arms", 1)))}"',
        f"joints_per_arm = {s.get('dof', 2)}",
        f"arms = {s.get('arms', 1)}",
        f'plan_seeds = "0..{s["runs"] - 1}"',
        f"max_iter = {s['max_iter']}",
        f'grid = "{grid_text}"',
        f'version = "{__version__}"',
        f'code_sha256 = "{code_sha256()}"',
        ('note = "training problems only: the generator seeds the project reports on '
         f'({", ".join(map(str, EVALUATION_SEEDS))}) are refused by the tuner"'),
    ]
    for row in result.table:
        lines += ["", "[[table]]", *[f"{n} = {_num(row[n])}" for n in names],
                  f"objective = {_num(row['objective'])}",
                  f"success_rate = {_num(row['success_rate'])}",
                  f"worst_success_rate = {_num(row['worst_success_rate'])}",
                  f"median_iterations = {_num(row['median_iterations'])}",
                  f"search_work = {_num(row['search_work'])}"]
    return "\n".join(lines) + "\n"
