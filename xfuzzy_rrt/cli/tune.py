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
    family: List[str] = typer.Option([], "--family", help="Problem family (repeatable; default: sample, hard and mira)."),
    max_iter: int = typer.Option(10_000, "--max-iter", help="Iteration budget per run."),
    grid: Optional[str] = typer.Option(None, "--grid", help="Values to search, e.g. 'step_deg=10,60;goal_bias=0.1' (default: the documented grid)."),
    workers: int = typer.Option(1, "--workers", help="Worker processes (the result does not depend on them)."),
    out: Path = typer.Option(..., "--out", help="The tuned TOML file to write (e.g. xfuzzy_rrt/data/tuned/rrt.toml)."),
) -> int:
    """Search the planner's parameter grid on generated training problems; write the chosen
    values, the objective table (median work to the first certified path) and the command."""
    from xfuzzy_rrt.atomic import write_text_atomic
    from xfuzzy_rrt.bench.tuning import (DEFAULT_FAMILIES, check_seed, default_grid,
                                         parse_grid, render_tuned_file, run_tuning)
    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.report.numbers import seconds, sig

    default_grid(planner)
    check_seed(seed)
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
                        grid=grid_, workers=workers, progress=progress)
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
    return 0


def register(app: typer.Typer) -> None:
    app.command("tune")(tune)
