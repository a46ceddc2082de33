"""``xfuzzy-rrt report DIR``: rebuild DIR/report.html from the tables on disk (no planning)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer


def report(
    folder: Path = typer.Argument(..., help="A folder written by 'xfuzzy-rrt bench'."),
    history: Optional[Path] = typer.Option(None, "--history",
                                           help="A training history.csv to show."),
    rulebook: Optional[Path] = typer.Option(
        None, "--rulebook", help="Where the benchmark's rulebook is now (same SHA-256)."),
) -> int:
    """Rebuild report.html from runs.csv, summary.csv, ratios.csv, bench.json and examples/."""
    from xfuzzy_rrt.atomic import atomic_path
    from xfuzzy_rrt.bench.store import load_bench_dir
    from xfuzzy_rrt.report.bench_report import write_bench_report

    result = load_bench_dir(folder, rulebook=rulebook, history=history)
    with atomic_path(folder / "report.html") as tmp:
        write_bench_report(result, tmp)
    typer.echo(f"wrote {folder / 'report.html'}")
    return 0


def register(app: typer.Typer) -> None:
    app.command("report")(report)
