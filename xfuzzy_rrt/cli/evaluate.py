"""``xfuzzy-rrt evaluate``: the fair protocol (rulebooks vs RRT, common seeds, per problem)."""

from __future__ import annotations

import sys
from pathlib import Path
from typing import List, Optional

import typer

from xfuzzy_rrt.cli.common import check_seed_option


def _rulebook(spec: str):
    """A shipped rulebook's name, or a rulebook directory."""
    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebooks_dir

    path = Path(spec)
    if not path.exists() and "/" not in spec and (rulebooks_dir() / spec).is_dir():
        path = rulebooks_dir() / spec
    if not path.is_dir():
        raise InputError("--rulebook", f"{spec!r} is neither a shipped rulebook nor a directory")
    return load_rulebook(path)


def _fmt(v: float, unit: str = "") -> str:
    if v != v:
        return "-"
    return f"{v:.3g}{unit}"


def evaluate(
    problems: List[Path] = typer.Argument(..., help="Scenario files or folders (a folder: every *.toml in it). Use problems no training or tuning saw."),
    rulebook: List[str] = typer.Option([], "--rulebook", help="Rulebook name or directory to evaluate (repeatable; default: the shipped default rulebook)."),
    peer: List[str] = typer.Option([], "--peer", help="Also run this planner, e.g. ompl:RRTConnect (repeatable; ranked on time)."),
    runs: int = typer.Option(50, "--runs", help="Seeds per problem (seed .. seed + runs - 1, the same for every planner)."),
    seed: int = typer.Option(0, "--seed", callback=check_seed_option, help="First seed."),
    max_iter: int = typer.Option(10_000, "--max-iter", help="Iteration budget per run; a failure counts as this many iterations."),
    out: Optional[Path] = typer.Option(None, "--out", help="Folder for runs.csv, problems.csv and summary.csv."),
    clearance: Optional[float] = typer.Option(None, "--clearance", help="Certified clearance in metres every planner must keep (default: each scenario's [safety] clearance_m, else 0)."),
) -> int:
    """Evaluate rulebooks against RRT on a folder of problems: per-problem median iteration
    ratios summarised as median / geometric mean / worst, success, cost and time ratios."""
    from xfuzzy_rrt.bench.protocol import run_protocol, write_protocol
    from xfuzzy_rrt.bench.runner import scenario_files
    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.planners.api import check_planner
    from xfuzzy_rrt.planners.checks import check_max_iter

    if not 1 <= runs <= 100_000:
        raise InputError("--runs", f"must lie in [1, 100000], got {runs}")
    check_max_iter(max_iter)
    if clearance is not None:
        from xfuzzy_rrt.geometry.collision import check_clearance

        check_clearance(clearance)
    if out is not None and out.exists() and not out.is_dir():
        raise InputError(str(out), "exists and is not a directory")
    if not rulebook:
        from xfuzzy_rrt.fuzzy.rulebook import DEFAULT_RULEBOOK

        rulebook = [DEFAULT_RULEBOOK]
    entries = []
    for spec in rulebook:
        rb = _rulebook(spec)
        entries.append((f"fuzzy-rrt:{rb.name}", "fuzzy-rrt", rb))
    for p in peer:
        entries.append((check_planner(p, "--peer"), p, None))
    labels = [e[0] for e in entries]
    if len(set(labels)) != len(labels):
        raise InputError("--rulebook", "two planners share a name; give each rulebook once")
    scenarios = [load_scenario(f) for f in scenario_files(problems)]
    if clearance is not None:
        # a batch protocol reports problems that no path can solve at this margin (start or
        # goal inside it) and goes on with the others; plan and bench refuse them outright
        from xfuzzy_rrt.geometry.clearance import planning_margin

        kept = []
        for sc in scenarios:
            try:
                planning_margin(sc, clearance)
                kept.append(sc)
            except InputError as exc:
                typer.echo(f"note: skipped {sc.name}: {exc}", err=True)
        if not kept:
            raise InputError("--clearance", "no problem's start and goal keep this clearance")
        scenarios = kept
    names = [s.name for s in scenarios]
    if len(set(names)) != len(names):
        raise InputError("PROBLEMS", "two problems share a scenario name")

    def progress(done: int, total: int) -> None:
        if sys.stderr.isatty():
            sys.stderr.write(f"\r  {done}/{total} (problem, planner) pairs")
            sys.stderr.flush()

    result = run_protocol(scenarios, entries, runs=runs, seed=seed, max_iter=max_iter,
                          progress=progress, clearance_m=clearance)
    if sys.stderr.isatty():
        sys.stderr.write("\n")
    if out is not None:
        write_protocol(result, out)
    typer.echo(f"{len(scenarios)} problems x {runs} seeds ({seed}..{seed + runs - 1}); ratios are "
               "per problem, RRT's median iterations / the planner's (failures count as "
               f"{max_iter}); cost ratio = planner / RRT (median over successful runs)")
    header = ["planner", "median", "geomean", "worst", "best", "lost", "success(min)",
              "success<RRT", "cost", "time ratio", "median time"]
    rows = []
    for r in result.summary.itertuples():
        rows.append([r.planner, _fmt(r.median_ratio, "x"), _fmt(r.geomean_ratio, "x"),
                     _fmt(r.worst_ratio, "x"), _fmt(r.best_ratio, "x"), str(r.problems_lost),
                     f"{100 * r.worst_success_rate:.0f} %", str(r.problems_success_below_rrt),
                     _fmt(r.median_cost_ratio), _fmt(r.median_time_ratio, "x"),
                     _fmt(1000 * r.median_time_s, " ms")])
    widths = [max(len(str(x)) for x in col) for col in zip(header, *rows)]
    for line in [header, *rows]:
        typer.echo("  ".join(str(x).ljust(w) for x, w in zip(line, widths)).rstrip())
    if out is not None:
        typer.echo(f"wrote {out}/runs.csv, problems.csv, summary.csv")
    return 0


def register(app: typer.Typer) -> None:
    app.command("evaluate")(evaluate)
