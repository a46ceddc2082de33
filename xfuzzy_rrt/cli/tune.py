"""``xfuzzy-rrt tune PLANNER``: choose a peer planner's parameters on training problems.

The search, its objective and its guard against evaluation problems live in
:mod:`xfuzzy_rrt.bench.tuning`; this command parses, reports progress and writes the file.
"""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import List, Optional

import typer


def tune(
    planner: str = typer.Argument(..., help="rrt, or ompl:NAME (range tuned; needs the ompl extra)."),
    problems: int = typer.Option(16, "--problems", help="Training problems generated per family."),
    seed: int = typer.Option(8100, "--seed", help="Generator seed of the training problems (the seeds the project evaluates on are refused)."),
    runs: int = typer.Option(10, "--runs", help="Plan seeds per problem and grid point (0 .. runs - 1)."),
    family: List[str] = typer.Option([], "--family", help="Problem family (repeatable; default: sample, hard and mira; one 2-joint arm only)."),
    dof: int = typer.Option(2, "--dof", help="Joints per arm of the training problems: a peer's best settings depend on the arm's shape, and a problem runs with the settings tuned for its shape (the nearest one tuned)."),
    arms: int = typer.Option(1, "--arms", help="Arms of the training problems (with --dof: the shape tuned)."),
    max_iter: int = typer.Option(10_000, "--max-iter", help="Iteration budget per run."),
    grid: Optional[str] = typer.Option(None, "--grid", help="Values to search, e.g. 'step_deg=10,60;goal_bias=0.1' (default: the documented grid)."),
    workers: int = typer.Option(1, "--workers", help="Worker processes (the result does not depend on them)."),
    out: Path = typer.Option(..., "--out", help="The tuned TOML file to write (e.g. xfuzzy_rrt/data/tuned/rrt.toml; another shape's file is named for it, e.g. rrt.2-arms-6-joints.toml: the name is what the planners look for)."),
) -> int:
    """Search the planner's parameter grid on generated training problems; write the chosen
    values, the objective table (median work to the first certified path) and the command."""
    from xfuzzy_rrt.atomic import write_text_atomic
    from xfuzzy_rrt.bench.tuning import (DEFAULT_FAMILIES, check_seed, check_shape,
                                         default_grid, parse_grid, render_tuned_file,
                                         run_tuning)
    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.report.numbers import seconds, sig

    default_grid(planner)
    check_seed(seed)
    check_shape(dof, arms, tuple(family))
    if out.exists() and out.is_dir():
        raise InputError(str(out), "is a directory; give the tuned file's path")
    grid_ = parse_grid(grid, planner) if grid is not None else None

    def progress(done: int, total: int) -> None:
        if sys.stderr.isatty():
            sys.stderr.write(f"\r  {done}/{total} runs")
            sys.stderr.flush()

    t0 = time.perf_counter()
    result = run_tuning(planner, problems=problems, seed=seed, runs=runs,
                        families=tuple(family) or DEFAULT_FAMILIES, max_iter=max_iter,
                        grid=grid_, workers=workers, progress=progress, dof=dof, arms=arms)
    elapsed = time.perf_counter() - t0
    if sys.stderr.isatty():
        sys.stderr.write("\n")
    names = list(result.grid)
    header = [*names, "end-to-end work", "search work", "success", "worst success",
              "median it", "median time"]
    rows = [[sig(r[n]) for n in names] + [f"{r['objective']:.0f}", f"{r['search_work']:.0f}",
             f"{100 * r['success_rate']:.0f} %",
             f"{100 * r['worst_success_rate']:.0f} %", sig(r["median_iterations"]),
             seconds(r["median_time_s"])] for r in result.table]
    widths = [max(len(str(x)) for x in col) for col in zip(header, *rows)]
    for line in [header, *rows]:
        typer.echo("  ".join(str(x).rjust(w) for x, w in zip(line, widths)))
    chosen = ", ".join(f"{n} = {sig(v)}" for n, v in result.best.items())
    typer.echo(f"chosen: {chosen} ({len(result.settings['scenarios'])} problems x {runs} runs, "
               f"{seconds(elapsed)}; time is shown for information, the objective is end-to-end work)")
    write_text_atomic(out, render_tuned_file(result))
    typer.echo(f"wrote {out}")
    from xfuzzy_rrt.planners.tuned import arm_shape, shape_text, tuned_file_name

    shape = arm_shape(dof, arms)
    if out.name != tuned_file_name(planner, shape):
        typer.echo(f"note: the planners read the settings for {shape_text(shape)} from "
                   f"{tuned_file_name(planner, shape)} in xfuzzy_rrt/data/tuned/")
    return 0


def register(app: typer.Typer) -> None:
    app.command("tune")(tune)
