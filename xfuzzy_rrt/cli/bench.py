"""``xfuzzy-rrt bench`` and ``xfuzzy-rrt demo``: benchmark tables plus the HTML audit report."""

from __future__ import annotations

import datetime as _dt
import shlex
import sys
from pathlib import Path
from typing import List, Optional

import typer


def _write_outputs(result, out: Path, command: str) -> None:
    """Write runs.csv, summary.csv and report.html into ``out`` without leaving partial files."""
    from xfuzzy_rrt.atomic import atomic_path
    from xfuzzy_rrt.report.bench_report import write_bench_report

    out.mkdir(parents=True, exist_ok=True)
    with atomic_path(out / "runs.csv") as tmp:
        result.runs.to_csv(tmp, index=False, float_format="%.17g")
    with atomic_path(out / "summary.csv") as tmp:
        result.summary.to_csv(tmp, index=False, float_format="%.17g")
    with atomic_path(out / "report.html") as tmp:
        write_bench_report(result, tmp, command=command)


def _render_summary(summary) -> str:
    cols = ["scenario", "planner", "success_rate", "iterations_min", "iterations_median",
            "iterations_max", "cost_median", "wall_median_s"]
    view = summary[cols].copy()
    view["wall_median_ms"] = view.pop("wall_median_s") * 1e3
    return view.to_string(index=False, float_format=lambda x: f"{x:.3f}")


def _run(scenarios: List[Path], planners: str, runs: int, seed: int, rulebook: Optional[Path],
         max_iter: int, out: Path, workers: int) -> int:
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.cli.common import load_scenario_warn
    from xfuzzy_rrt.errors import InputError

    names = [p.strip() for p in planners.split(",") if p.strip()]
    if not names:
        raise InputError("--planners", "name at least one planner")
    loaded = [load_scenario_warn(p) for p in scenarios]
    result = run_benchmark(loaded, names, runs=runs, seed=seed, rulebook=rulebook,
                           max_iter=max_iter, workers=workers)
    command = "xfuzzy-rrt " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    _write_outputs(result, out, command)
    typer.echo(_render_summary(result.summary))
    typer.echo(f"wrote {out / 'runs.csv'}, {out / 'summary.csv'}, {out / 'report.html'}")
    return 0


def _default_out(prefix: str) -> Path:
    return Path("reports") / f"{prefix}-{_dt.datetime.now().strftime('%Y%m%d-%H%M%S')}"


def bench(
    scenarios: List[Path] = typer.Argument(..., help="Scenario TOML files."),
    planners: str = typer.Option("rrt,fuzzy-rrt", "--planners", help="Comma list of planners."),
    runs: int = typer.Option(50, "--runs", min=1, help="Runs per (scenario, planner)."),
    seed: int = typer.Option(0, "--seed", help="First seed; run k uses seed + k."),
    rulebook: Optional[Path] = typer.Option(None, "--rulebook", help="Rulebook directory."),
    max_iter: int = typer.Option(10_000, "--max-iter", min=1, max=1_000_000, help="Iteration budget per run (at most 1,000,000)."),
    out: Optional[Path] = typer.Option(None, "--out", help="Output folder (default reports/bench-<time>)."),
    workers: int = typer.Option(1, "--workers", min=1, help="Worker processes."),
) -> int:
    """Benchmark planners: runs.csv, summary.csv and report.html in the output folder."""
    return _run(scenarios, planners, runs, seed, rulebook, max_iter, out or _default_out("bench"),
                workers)


def demo(
    out: Path = typer.Option(Path("reports/demo"), "--out", help="Output folder."),
    runs: int = typer.Option(50, "--runs", min=1, help="Runs per (scenario, planner)."),
    workers: int = typer.Option(2, "--workers", min=1, help="Worker processes."),
) -> int:
    """Plan and benchmark RRT vs Fuzzy-RRT on the shipped demo scenarios; write the report."""
    from xfuzzy_rrt.bench.runner import shipped_scenarios

    return _run(shipped_scenarios(), "rrt,fuzzy-rrt", runs, 0, None, 10_000, out, workers)


def register(app: typer.Typer) -> None:
    app.command("bench")(bench)
    app.command("demo")(demo)
