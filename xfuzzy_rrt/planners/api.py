"""One entry point for every planner, used by the CLI, the benchmark runner and the trainer."""

from __future__ import annotations

from pathlib import Path

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.scenario import Scenario
from xfuzzy_rrt.planners.result import PlanResult

PLANNERS = ("rrt", "fuzzy-rrt")
TRACE_SUFFIXES = (".parquet", ".csv")
#: ``ompl:NAME`` runs OMPL's geometric planner NAME (optional extra; see planners/ompl_bridge.py).
OMPL_PREFIX = "ompl:"


def is_known_planner(name: str) -> bool:
    """A built-in planner name, or ``ompl:NAME`` (NAME is checked against OMPL when planning).

    Cheap and import-free, for argument parsing; :func:`check_planner` does the full check.
    """
    return name in PLANNERS or (name.startswith(OMPL_PREFIX) and len(name) > len(OMPL_PREFIX))


def check_planner(name: str, where: str = "--planners") -> str:
    """Validate a planner name fully, before any run: raises one InputError naming ``where``.

    For ``ompl:NAME`` this imports OMPL, so a missing extra or an unknown OMPL planner fails
    here with the same line it would give when planning.
    """
    if name in PLANNERS:
        return name
    if is_known_planner(name):
        from xfuzzy_rrt.planners.ompl_bridge import check_ompl_planner

        check_ompl_planner(name)
        return name
    raise InputError(where, f"unknown planner {name!r} (expected one of "
                     f"{', '.join(PLANNERS)} or {OMPL_PREFIX}NAME)")


def plan_scenario(scenario: Scenario, planner: str = "fuzzy-rrt", rulebook=None, seed: int = 0,
                  max_iter: int = 10_000, step_deg: float = 10.0, goal_bias: float = 0.05,
                  trace: bool = False, clearance_m: float | None = None) -> PlanResult:
    """Plan ``scenario`` with the named planner.

    ``rulebook`` (fuzzy-rrt only) is a loaded rulebook, a directory path, or ``None`` for the
    shipped default. ``step_deg``/``goal_bias`` configure plain RRT and the OMPL planners
    (range and goal bias where they have one); Fuzzy-RRT takes both from its rulebook.
    ``ompl:NAME`` runs OMPL's geometric planner NAME with our collision checker
    (:func:`xfuzzy_rrt.planners.ompl_bridge.plan_ompl`; needs the optional 'ompl' extra).
    """
    if planner == "rrt":
        from xfuzzy_rrt.planners.rrt import plan_rrt

        if trace:
            raise InputError("--trace", "traces record fuzzy decisions; use --planner fuzzy-rrt")
        return plan_rrt(scenario, seed=seed, max_iter=max_iter, step_deg=step_deg,
                        goal_bias=goal_bias, clearance_m=clearance_m)
    if planner == "fuzzy-rrt":
        from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt

        return plan_fuzzy_rrt(scenario, rulebook=rulebook, seed=seed, max_iter=max_iter,
                               trace=trace, clearance_m=clearance_m)
    if is_known_planner(planner):
        from xfuzzy_rrt.planners.ompl_bridge import plan_ompl

        if trace:
            raise InputError("--trace", "traces record fuzzy decisions; use --planner fuzzy-rrt")
        return plan_ompl(scenario, planner, seed=seed, max_iter=max_iter, step_deg=step_deg,
                         goal_bias=goal_bias, clearance_m=clearance_m)
    raise InputError("--planner", f"unknown planner {planner!r} (expected one of {', '.join(PLANNERS)})")


def write_trace_checked(path: Path) -> None:
    """Fail early (before planning) when the trace file's suffix is not supported."""
    if Path(path).suffix.lower() not in TRACE_SUFFIXES:
        raise InputError(str(path), "trace file must end in .parquet or .csv")


def write_trace(result: PlanResult, path: Path) -> None:
    """Write ``result.trace`` (a DataFrame) atomically as Parquet or CSV by suffix."""
    from xfuzzy_rrt.atomic import atomic_path

    write_trace_checked(path)
    if result.trace is None:
        raise InputError(str(path), "this result has no trace")
    with atomic_path(path) as tmp:
        if Path(path).suffix.lower() == ".parquet":
            result.trace.to_parquet(tmp, index=False)
        else:
            result.trace.to_csv(tmp, index=False, float_format="%.17g")
