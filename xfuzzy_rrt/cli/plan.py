"""``xfuzzy-rrt plan``: plan one scenario and print (or write) the SPEC.md JSON result."""

from __future__ import annotations

import enum
from pathlib import Path
from typing import Optional

import typer

from xfuzzy_rrt.cli.common import check_seed_option, rulebook_arg
from xfuzzy_rrt.planners import registry as _registry

#: What the help says takes a rulebook / records a trace (the planner registry's exact labels).
_RULEBOOK_PLANNERS = ", ".join(_registry.exact_labels(takes_rulebook=True))
_TRACING_PLANNERS = ", ".join(_registry.exact_labels(traces=True))


class PlannerName(str, enum.Enum):
    rrt = "rrt"
    fuzzy_rrt = "fuzzy-rrt"


def plan(
    scenario: Path = typer.Argument(..., help="Scenario TOML file."),
    planner: str = typer.Option(
        PlannerName.fuzzy_rrt.value, "--planner",
        help=_registry.planner_help()),
    rulebook: Optional[Path] = typer.Option(
        None, "--rulebook", callback=rulebook_arg, help=f"Rulebook directory or a shipped rulebook's name ({_RULEBOOK_PLANNERS}; default: the shipped default of the problem: goal-frame for one 2-joint arm, else fuzzy-rrt-connect with goal-frame-any, as the JSON's planner_used and rulebook say)."),
    seed: int = typer.Option(0, "--seed", callback=check_seed_option, help="Random seed."),
    max_iter: int = typer.Option(10_000, "--max-iter", min=1, max=1_000_000, help="Iteration budget (at most 1,000,000)."),
    out: Optional[Path] = typer.Option(None, "--out", help="Write the JSON here (default: stdout)."),
    trace: Optional[Path] = typer.Option(
        None, "--trace", help=f"Write the per-iteration trace (.parquet or .csv; {_TRACING_PLANNERS})."),
    step_deg: float = typer.Option(10.0, "--step-deg", help="RRT step size in degrees."),
    goal_bias: float = typer.Option(0.05, "--goal-bias", help="RRT goal bias in [0, 1]."),
    clearance: Optional[float] = typer.Option(
        None, "--clearance", help="Certified clearance in metres every link keeps from every obstacle (default: the scenario's [safety] clearance_m, else 0)."),
    max_time: Optional[float] = typer.Option(
        None, "--max-time", help="Wall-clock budget in seconds on top of --max-iter (whichever ends first; the result's params say which)."),
) -> int:
    """Plan a path from the scenario's start to its goal.

    Exit 1 when no path is found within --max-iter, or when the path found is not certified
    collision-free (one line on stderr says where it penetrates and how deep).
    """
    from xfuzzy_rrt.cli.common import check_output_file, emit_json, load_scenario_warn
    from xfuzzy_rrt.planners.api import parse_planner, plan_scenario, write_trace_checked
    from xfuzzy_rrt.planners.termination import check_max_time

    spec = parse_planner(planner, "--planner")
    if rulebook is not None and not spec.planner.takes_rulebook:
        from xfuzzy_rrt.errors import InputError

        takers = _registry.either(_registry.exact_labels(takes_rulebook=True), "and")
        raise InputError("--rulebook", f"only {takers} plan with a "
                         f"rulebook; --planner {planner} would ignore it (drop --rulebook or "
                         "use --planner fuzzy-rrt)")
    if trace is not None:
        write_trace_checked(trace)  # reject a bad suffix before any work is done
    check_output_file(out, "--out")
    check_output_file(trace, "--trace")
    s = load_scenario_warn(scenario)
    rulebook_dir = None
    rulebook_obj = None
    if spec.planner.takes_rulebook:
        from xfuzzy_rrt.errors import InputError
        from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
        from xfuzzy_rrt.planners.api import default_rulebook_dir, shipped_default

        if spec.rulebook_dir is not None and rulebook is not None:
            raise InputError("--rulebook", f"conflicts with --planner {planner} (which names "
                             "its own rulebook); give only one")
        rulebook_dir = spec.rulebook_dir or rulebook
        if rulebook_dir is None and spec.kind == "fuzzy-rrt":
            # No rulebook named: this problem's shipped default (goal-frame for one 2-joint
            # arm, else fuzzy-rrt-connect with goal-frame-any). plan_scenario applies the same
            # rule to rulebook=None; the JSON's planner_used and rulebook say which ran.
            rulebook_dir = shipped_default(s)[1]
        else:
            rulebook_dir = rulebook_dir or default_rulebook_dir(spec.kind)
            rulebook_obj = load_rulebook(rulebook_dir)
    result = plan_scenario(
        s, planner=planner, rulebook=rulebook_obj, seed=seed, max_iter=max_iter,
        step_deg=step_deg, goal_bias=goal_bias, trace=trace is not None, clearance_m=clearance,
        max_time_s=None if max_time is None else check_max_time(max_time),
    )
    if trace is not None:
        from xfuzzy_rrt.planners.api import write_trace

        write_trace(result, trace, rulebook_dir=rulebook_dir)
    data = result.to_json_dict()
    # Where the inputs came from, so that 'xfuzzy-rrt explain RESULT.json' can replay the run.
    data["scenario_file"] = str(scenario.resolve())
    data["rulebook_dir"] = str(Path(rulebook_dir).resolve()) if rulebook_dir is not None else None
    emit_json(data, out)
    if result.found and not result.certified:
        import sys

        sys.stderr.write(f"not certified: {scenario}: {result.planner} seed {seed}: "
                         f"{result.violation}\n")
    if not result.found:
        import sys

        sys.stderr.write(no_path_line(scenario, result, max_iter, max_time, out) + "\n")
    return 0 if result.success else 1


def no_path_line(scenario: Path, result, max_iter: int, max_time: float | None,
                 out: Path | None) -> str:
    """Why exit 1 without a path, in one line: the budget that ran out and where the (still
    valid, SPEC.md) JSON result went, so a silent exit 1 is never the whole answer."""
    stopped = (result.params or {}).get("stopped_by")
    if stopped == "time" and max_time is not None:
        budget = f"within --max-time {max_time:g} s ({result.iterations} iterations)"
    else:
        budget = f"within {max_iter} iterations (--max-iter)"
    where = f"the result was written to {out}" if out is not None else "the result is on stdout"
    return (f"no path: {scenario}: {result.planner} seed {result.seed} found no path {budget}; "
            f"{where}")


def register(app: typer.Typer) -> None:
    app.command("plan")(plan)
