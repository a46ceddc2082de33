"""``xfuzzy-rrt bench`` and ``xfuzzy-rrt demo``: benchmark tables plus the HTML audit report."""

from __future__ import annotations

import datetime as _dt
import shlex
import sys
from pathlib import Path
from typing import List, Optional

import typer


class ProgressBar:
    """Runs done / total on stderr: a redrawn bar on a terminal, a few plain lines otherwise
    (logs and CI keep one line per 10%)."""

    def __init__(self, stream=None, width: int = 30) -> None:
        self.stream = stream or sys.stderr
        self.tty = bool(getattr(self.stream, "isatty", lambda: False)())
        self.width = width
        self.last_decile = -1

    def __call__(self, done: int, total: int) -> None:
        if self.tty:
            filled = int(self.width * done / max(total, 1))
            self.stream.write(f"\rbench [{'#' * filled}{'.' * (self.width - filled)}] "
                              f"{done}/{total} runs")
            if done == total:
                self.stream.write("\n")
            self.stream.flush()
            return
        decile = (10 * done) // max(total, 1)
        if decile != self.last_decile:
            self.last_decile = decile
            self.stream.write(f"bench: {done}/{total} runs ({100 * done // max(total, 1)}%)\n")
            self.stream.flush()


def write_outputs(result, out: Path, command: str):
    """Write the tables, bench.json, the example runs and report.html into ``out``."""
    from xfuzzy_rrt.atomic import atomic_path
    from xfuzzy_rrt.bench.provenance import collect
    from xfuzzy_rrt.bench.store import write_bench_dir
    from xfuzzy_rrt.report.bench_report import write_bench_report

    result = write_bench_dir(result, out, collect(command))
    with atomic_path(out / "report.html") as tmp:
        write_bench_report(result, tmp, command=command)
    return result


def _render_summary(summary) -> str:
    cols = ["scenario", "planner", "success_rate", "iterations_min", "iterations_median",
            "iterations_max", "cost_median", "wall_median_s", "certified_fraction"]
    if "cost_short_median" in summary.columns:
        cols.insert(7, "cost_short_median")
    view = summary[[c for c in cols if c in summary.columns]].copy()
    view["wall_median_ms"] = view.pop("wall_median_s") * 1e3
    return view.to_string(index=False, float_format=lambda x: f"{x:.3f}")


def _run(scenarios: List[Path], planners: str, runs: int, seed: int, rulebook: Optional[Path],
         max_iter: int, out: Path, workers: int, shortcut: bool = False,
         clearance: float | None = None) -> int:
    from xfuzzy_rrt.bench.runner import check_planners, run_benchmark, scenario_files
    from xfuzzy_rrt.cli.common import load_scenario_warn

    from xfuzzy_rrt.errors import InputError

    if out.exists() and not out.is_dir():  # fail before planning, not after
        raise InputError(str(out), "exists and is not a directory (--out names a folder)")
    names = check_planners([p.strip() for p in planners.split(",") if p.strip()])
    from xfuzzy_rrt.geometry.clearance import with_clearance

    loaded = [with_clearance(load_scenario_warn(p), clearance) for p in scenario_files(scenarios)]
    result = run_benchmark(loaded, names, runs=runs, seed=seed, rulebook=rulebook,
                           max_iter=max_iter, workers=workers, shortcut=shortcut,
                           progress=ProgressBar())
    command = "xfuzzy-rrt " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    write_outputs(result, out, command)
    typer.echo(_render_summary(result.summary))
    if result.ratios is not None and len(result.ratios):
        typer.echo(result.ratios.to_string(index=False, float_format=lambda x: f"{x:.3f}"))
    typer.echo(f"wrote {out / 'runs.csv'}, {out / 'summary.csv'}, {out / 'ratios.csv'}, "
               f"{out / 'report.html'}")
    return 0


def _default_out(prefix: str) -> Path:
    return Path("reports") / f"{prefix}-{_dt.datetime.now().strftime('%Y%m%d-%H%M%S')}"


def bench(
    scenarios: List[Path] = typer.Argument(..., help="Scenario TOML files or directories of them."),
    planners: str = typer.Option("rrt,fuzzy-rrt", "--planners",
                                 help="Comma list: rrt, fuzzy-rrt, ompl:NAME (e.g. ompl:RRTConnect)."),
    runs: int = typer.Option(50, "--runs", min=1, help="Runs per (scenario, planner)."),
    seed: int = typer.Option(0, "--seed", help="First seed; run k uses seed + k."),
    rulebook: Optional[Path] = typer.Option(None, "--rulebook", help="Rulebook directory."),
    max_iter: int = typer.Option(10_000, "--max-iter", min=1, max=1_000_000, help="Iteration budget per run (at most 1,000,000)."),
    out: Optional[Path] = typer.Option(None, "--out", help="Output folder (default reports/bench-<time>)."),
    workers: int = typer.Option(1, "--workers", min=1, help="Worker processes."),
    shortcut: bool = typer.Option(False, "--shortcut",
                                  help="Also shorten every path by certified shortcutting "
                                       "(cost_short_deg; cost_deg stays the raw cost)."),
    clearance: Optional[float] = typer.Option(
        None, "--clearance", help="Certified clearance in metres (default: each scenario's [safety] clearance_m, else 0)."),
) -> int:
    """Benchmark planners: runs.csv, summary.csv, ratios.csv and report.html in the output folder."""
    return _run(scenarios, planners, runs, seed, rulebook, max_iter, out or _default_out("bench"),
                workers, shortcut, clearance)


def demo(
    out: Path = typer.Option(Path("reports/demo"), "--out", help="Output folder."),
    runs: int = typer.Option(50, "--runs", min=1, help="Runs per (scenario, planner)."),
    workers: int = typer.Option(2, "--workers", min=1, help="Worker processes."),
) -> int:
    """Benchmark RRT vs the trained Fuzzy-RRT and write the reports.

    The default rulebook (``general``, trained on generated problems only) on 24 fresh
    problems of the ``sample-*`` family that no training run saw (generator seed 2000; the
    files are written to OUT/scenarios), into OUT; and, when the shared reference problem sits
    beside the project, the ``paper`` rulebook (the paper's setting) on it, into
    OUT/paper-reference.
    """
    from xfuzzy_rrt.atomic import write_text_atomic
    from xfuzzy_rrt.fuzzy.rulebook import rulebooks_dir
    from xfuzzy_rrt.scenarios.generate import generate_one

    files = []
    for k in range(24):
        problem = generate_one(2000, k)
        path = out / "scenarios" / f"{problem.scenario.name}.toml"
        write_text_atomic(path, problem.text)
        files.append(path)
    code = _run(files, "rrt,fuzzy-rrt", runs, 0, None, 10_000, out, workers)
    reference = rulebooks_dir().parent.parent / "shared" / "scenarios" / "paper-reference.toml"
    paper = rulebooks_dir() / "paper"
    if reference.is_file() and paper.is_dir():
        code = max(code, _run([reference], "rrt,fuzzy-rrt", runs, 0, paper, 10_000,
                              out / "paper-reference", workers))
    return code


def register(app: typer.Typer) -> None:
    app.command("bench")(bench)
    app.command("demo")(demo)
