"""``xfuzzy-rrt bench`` and ``xfuzzy-rrt demo``: benchmark tables plus the HTML audit report."""

from __future__ import annotations

import datetime as _dt
import shlex
import sys
from pathlib import Path
from typing import List, Optional

import typer

from xfuzzy_rrt.cli.common import (check_seed_option, check_workers_option, rulebook_arg,
                                    split_planners)


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
    """Write the tables, bench.json, the example runs, report.html and report/ into ``out``
    (the staged folder; :func:`xfuzzy_rrt.bench.store.staged_folder` swaps it in)."""
    from xfuzzy_rrt.bench.provenance import collect
    from xfuzzy_rrt.bench.store import write_bench_dir
    from xfuzzy_rrt.cli.common import test_signal
    from xfuzzy_rrt.report.site import write_report

    result = write_bench_dir(result, out, collect(command))
    test_signal("tables")
    write_report(result, out, command=command)
    test_signal("report")
    return result


def _render_summary(summary) -> str:
    cols = ["scenario", "planner", "success_rate", "found_rate", "iterations_min",
            "iterations_median", "iterations_max", "cost_median", "wall_median_s",
            "certified_fraction", "min_clearance_min_m"]
    if "cost_short_median" in summary.columns:
        cols.insert(8, "cost_short_median")
    view = summary[[c for c in cols if c in summary.columns]].copy()
    view["wall_median_ms"] = view.pop("wall_median_s") * 1e3
    if "min_clearance_min_m" in view:
        view["min_clearance_mm"] = view.pop("min_clearance_min_m") * 1e3
    return view.to_string(index=False, float_format=lambda x: f"{x:.3f}")


def _run(scenarios: List[Path], planners: str, runs: int, seed: int, rulebook: Optional[Path],
         max_iter: int, out: Path, workers: int, shortcut: bool = False,
         keep: tuple[str, ...] = (), clearance: float | None = None) -> int:
    """Plan and write one bench folder, replaced as a set (``keep``: entries of an existing
    folder to carry over, e.g. the demo's scenarios). Ctrl-C: one line, the previous folder
    (or none) stays, exit 130."""
    from xfuzzy_rrt.bench.runner import check_planners, run_benchmark, scenario_files
    from xfuzzy_rrt.bench.store import check_out_dir, staged_folder
    from xfuzzy_rrt.cli.common import load_scenario_warn, test_signal

    names = check_planners(split_planners(planners))
    if rulebook is not None and "fuzzy-rrt" not in names:
        from xfuzzy_rrt.errors import InputError

        raise InputError("--rulebook", "is the rulebook of plain fuzzy-rrt, which --planners does "
                         "not list (add fuzzy-rrt, or name it as fuzzy-rrt:DIR)")
    files = scenario_files(scenarios)
    check_out_dir(out, files, keep)  # fail before planning, not after
    from xfuzzy_rrt.geometry.clearance import with_clearance

    loaded = [with_clearance(load_scenario_warn(p), clearance) for p in files]
    bar = ProgressBar()

    def progress(done: int, total: int) -> None:
        bar(done, total)
        test_signal(f"runs:{done}")

    command = "xfuzzy-rrt " + " ".join(shlex.quote(a) for a in sys.argv[1:])
    try:
        with staged_folder(out, keep) as stage:
            result = run_benchmark(loaded, names, runs=runs, seed=seed, rulebook=rulebook,
                                   max_iter=max_iter, workers=workers, shortcut=shortcut,
                                   progress=progress)
            write_outputs(result, stage, command)
    except KeyboardInterrupt:
        state = "the previous folder is unchanged" if out.exists() else "nothing was written"
        sys.stderr.write(f"\ninterrupted: {out}: {state}\n")
        sys.stderr.flush()
        raise
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
    planners: str = typer.Option(
        "rrt,fuzzy-rrt", "--planners",
        help="Comma list: rrt, fuzzy-rrt (the --rulebook, else the default of each problem: "
             "goal-frame on one 2-joint arm, fuzzy-rrt-connect with goal-frame-any on others; "
             "runs.csv's planner_used says which ran), "
             "fuzzy-rrt:NAME (a shipped rulebook) or fuzzy-rrt:DIR (a rulebook directory; "
             "several side by side), ompl:NAME (e.g. ompl:RRTConnect)."),
    runs: int = typer.Option(50, "--runs", min=1, help="Runs per (scenario, planner)."),
    seed: int = typer.Option(0, "--seed", callback=check_seed_option, help="First seed; run k uses seed + k."),
    rulebook: Optional[Path] = typer.Option(None, "--rulebook", callback=rulebook_arg,
                                            help="Rulebook directory (or a shipped rulebook's "
                                                 "name) of plain fuzzy-rrt."),
    max_iter: int = typer.Option(10_000, "--max-iter", min=1, max=1_000_000, help="Iteration budget per run (at most 1,000,000)."),
    out: Optional[Path] = typer.Option(None, "--out", help="Output folder (default reports/bench-<time>)."),
    workers: int = typer.Option(1, "--workers", callback=check_workers_option, min=1, help="Worker processes."),
    shortcut: bool = typer.Option(False, "--shortcut",
                                  help="Also shorten every path by certified shortcutting "
                                       "(cost_short_deg; cost_deg stays the raw cost)."),
    clearance: Optional[float] = typer.Option(
        None, "--clearance", help="Certified clearance in metres (default: each scenario's [safety] clearance_m, else 0)."),
) -> int:
    """Benchmark planners: runs.csv, summary.csv, ratios.csv and report.html in the output folder."""
    return _run(scenarios, planners, runs, seed, rulebook, max_iter, out or _default_out("bench"),
                workers, shortcut, clearance=clearance)


def demo(
    out: Path = typer.Option(Path("reports/demo"), "--out", help="Output folder."),
    runs: int = typer.Option(50, "--runs", min=1, help="Runs per (scenario, planner)."),
    workers: int = typer.Option(2, "--workers", callback=check_workers_option, min=1, help="Worker processes."),
    problems: int = typer.Option(24, "--problems", min=1, max=1000,
                                 help="Generated problems to benchmark (generator seed 2000)."),
) -> int:
    """Benchmark RRT vs the trained Fuzzy-RRT and write the reports.

    Two benchmarks, everything shipped in the package: (1) the paper's RRT, the tuned RRT
    (``rrt:tuned``, the baseline the report's verdict names) and Fuzzy-RRT with the default
    rulebook (``goal-frame``, trained on generated problems only) on the shipped demo scenarios
    and PROBLEMS fresh problems of the ``sample-*`` family that no training run saw (generator
    seed 2000; the files are written to OUT/scenarios), into OUT; (2) on the paper's reference
    problem, RRT, the default rulebook and the ``paper`` rulebook (the paper's setting) side by
    side, into OUT/paper-reference.
    """
    from xfuzzy_rrt.atomic import write_text_atomic
    from xfuzzy_rrt.bench.runner import shipped_scenarios
    from xfuzzy_rrt.resources import paper_reference_scenario
    from xfuzzy_rrt.scenarios.generate import generate_one

    files = list(shipped_scenarios())
    for k in range(problems):
        problem = generate_one(2000, k)
        path = out / "scenarios" / f"{problem.scenario.name}.toml"
        write_text_atomic(path, problem.text)
        files.append(path)
    code = _run(files, "rrt,rrt:tuned,fuzzy-rrt", runs, 0, None, 10_000, out, workers,
                keep=("scenarios", "paper-reference"))
    for stale in sorted((out / "scenarios").glob("*.toml")):
        if stale not in files:  # from an earlier demo with more --problems
            stale.unlink()
    code = max(code, _run([paper_reference_scenario()], "rrt,fuzzy-rrt,fuzzy-rrt:paper", runs, 0,
                          None, 10_000, out / "paper-reference", workers))
    return code


def register(app: typer.Typer) -> None:
    app.command("bench")(bench)
    app.command("demo")(demo)
