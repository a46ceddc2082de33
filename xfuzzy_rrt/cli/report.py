"""``xfuzzy-rrt report DIR``: rebuild the report of a bench folder from its tables (no planning)."""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer


def report(
    folder: Path = typer.Argument(..., help="A folder written by 'xfuzzy-rrt bench'."),
    history: Optional[Path] = typer.Option(
        None, "--history", help="A training history.csv to show on its rulebook's page "
                                "(refused when it trained another rulebook)."),
    rulebook: Optional[Path] = typer.Option(
        None, "--rulebook", help="Where the benchmark's rulebook is now (same SHA-256)."),
    pdf: bool = typer.Option(False, "--pdf", help="Also print the overview and the certification "
                             "evidence to DIR/report.pdf (needs Chromium)."),
) -> int:
    """Rebuild report.html and report/ from runs.csv, summary.csv, bench.json and examples/."""
    from xfuzzy_rrt.bench.store import load_bench_dir
    from xfuzzy_rrt.report.site import ENTRY, PDF, attach_history, write_report

    browser = None
    if pdf:
        from xfuzzy_rrt.report.pdf import find_chromium

        browser = find_chromium()  # before any output is written
    result = load_bench_dir(folder, rulebook=rulebook)
    if history is not None:
        attach_history(result, history)
    write_report(result, folder)
    typer.echo(f"wrote {folder / ENTRY} (evidence pages in {folder / 'report'})")
    if pdf:
        from xfuzzy_rrt.report.pdf import print_pdf

        print_pdf(folder / ENTRY, folder / PDF, browser)
        typer.echo(f"wrote {folder / PDF}")
    return 0


def register(app: typer.Typer) -> None:
    app.command("report")(report)
