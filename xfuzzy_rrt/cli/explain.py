"""``xfuzzy-rrt explain``: show how one Fuzzy-RRT expansion was decided, rule by rule."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from xfuzzy_rrt.cli.common import rulebook_arg


def explain(
    source: Path = typer.Argument(..., help="A trace (.parquet/.csv) or a plan result (.json)."),
    iteration: int = typer.Option(..., "--iteration", min=1, help="Iteration to explain (1-based)."),
    rulebook: Optional[Path] = typer.Option(
        None, "--rulebook", callback=rulebook_arg,
        help="Rulebook that made the trace, a directory or a shipped rulebook's name (default: the one the source names)."),
    exact: bool = typer.Option(False, "--exact", help="Full precision (every digit, to re-derive "
                               "the numbers bit for bit) instead of 4 significant digits."),
) -> int:
    """Print inputs, active terms, fired rules with strengths and contributions, and outputs."""
    from xfuzzy_rrt.analysis.explain import explain_rows, render_text, trace_row
    from xfuzzy_rrt.planners.replay import trace_for

    frame, rb = trace_for(source, rulebook)
    explanations = explain_rows(trace_row(frame, iteration), rb)
    for a, e in enumerate(explanations):
        if len(explanations) > 1:  # several arms: the rulebook read each arm's end effector
            if a:
                typer.echo("")
            typer.echo(f"### arm {a + 1} of {len(explanations)} (its own inputs and outputs; "
                       "the sample, box and outcome are shared)")
        if exact:
            typer.echo(render_text(e), nl=False)
        else:
            from xfuzzy_rrt.report.explain_text import render_readable, units_of

            typer.echo(render_readable(e, units_of(rb)), nl=False)
    return 0


def register(app: typer.Typer) -> None:
    app.command("explain")(explain)
