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
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebook_path

    path = rulebook_path(spec)
    if not path.is_dir():
        raise InputError("--rulebook", f"{spec!r} is neither a shipped rulebook nor a directory")
    return load_rulebook(path)


def _fmt(v: float, unit: str = "") -> str:
    if v != v:
        return "-"
    return f"{v:.3g}{unit}"


def evaluate(
    problems: List[Path] = typer.Argument(..., help="Scenario files or folders (a folder: every *.toml in it). Use problems no training or tuning saw."),
    rulebook: List[str] = typer.Option([], "--rulebook", help="Rulebook name or directory to evaluate (repeatable; default: the shipped default, fuzzy-rrt:goal-frame when every problem is one 2-joint arm, else fuzzy-rrt: goal-frame on such problems and fuzzy-rrt-connect with goal-frame-any on the others)."),
    peer: List[str] = typer.Option([], "--peer", help="Also run this planner, e.g. ompl:RRTConnect (repeatable; ranked on time)."),
    tuned: bool = typer.Option(True, "--tuned/--no-tuned", help="Run the tuned RRT (rrt:tuned) beside the paper's RRT and rank time and work against it (default: yes)."),
    runs: int = typer.Option(50, "--runs", help="Seeds per problem (seed .. seed + runs - 1, the same for every planner)."),
    seed: int = typer.Option(0, "--seed", callback=check_seed_option, help="First seed."),
    max_iter: int = typer.Option(10_000, "--max-iter", help="Iteration budget per run; a failure counts as this many iterations."),
    out: Optional[Path] = typer.Option(None, "--out", help="Folder for runs.csv, problems.csv and summary.csv."),
    clearance: Optional[float] = typer.Option(None, "--clearance", help="Certified clearance in metres every planner must keep (default: each scenario's [safety] clearance_m, else 0)."),
    caches: str = typer.Option("cold", "--caches", help="The state every timed call starts from: cold (the caches evicted before each call: a plan made between other work), warm (each planner's seeds of a problem in a row, in blocks of 10 seeds, each after 3 untimed calls, the planners' blocks interleaved: plans made in a loop) or shuffled (planners shuffled per seed, nothing evicted: the tenth and eleventh sessions' figures). Only timings depend on it; cold writes 1.5x the last-level cache before each call (~2 ms here), so a run of 2-joint problems takes ~5x as long, 3-7 joints 1.1-2x."),
) -> int:
    """Evaluate rulebooks against RRT on a folder of problems: planners ranked on end-to-end
    time to the first certified path and on work against the tuned RRT (rrt:tuned), and on
    iterations against the paper's RRT, per problem, summarised as median / worst / lost."""
    from xfuzzy_rrt.bench.protocol import run_protocol, write_protocol
    from xfuzzy_rrt.bench.runner import scenario_files
    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.planners.api import check_planner
    from xfuzzy_rrt.planners.checks import check_max_iter

    from xfuzzy_rrt.bench.caches import check_cache_mode

    if not 1 <= runs <= 100_000:
        raise InputError("--runs", f"must lie in [1, 100000], got {runs}")
    check_max_iter(max_iter)
    check_cache_mode(caches)
    if clearance is not None:
        from xfuzzy_rrt.geometry.collision import check_clearance

        check_clearance(clearance)
    if out is not None and out.exists() and not out.is_dir():
        raise InputError(str(out), "exists and is not a directory")
    named = bool(rulebook)
    if not rulebook:
        from xfuzzy_rrt.fuzzy.rulebook import DEFAULT_RULEBOOK

        rulebook = [DEFAULT_RULEBOOK]
    entries = []
    if tuned and "rrt:tuned" not in peer:
        entries.append((check_planner("rrt:tuned", "--tuned"), "rrt:tuned", None))
    for spec in rulebook:
        rb = _rulebook(spec)
        # with the planner its semantics names (goal-frame-any: Fuzzy-RRT-Connect)
        kind = rb.semantics.planner
        entries.append((f"{kind}:{rb.name}", kind, rb))
    for p in peer:
        entries.append((check_planner(p, "--peer"), p, None))
    labels = [e[0] for e in entries]
    if len(set(labels)) != len(labels):
        raise InputError("--rulebook", "two planners share a name; give each rulebook once")
    scenarios = [load_scenario(f) for f in scenario_files(problems)]
    from xfuzzy_rrt.planners.api import load_shipped_default

    if not named and not all(sc.one_two_joint_arm for sc in scenarios):
        # No rulebook named and not every problem is one 2-joint arm: the shipped default per
        # problem (goal-frame there, fuzzy-rrt-connect with goal-frame-any elsewhere), under
        # the label plain fuzzy-rrt; runs.csv's planner_used and rulebook say which ran.
        k = next(i for i, e in enumerate(entries) if e[1] == "fuzzy-rrt")
        entries[k] = ("fuzzy-rrt", "fuzzy-rrt", load_shipped_default())
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

    peers = [e[0] for e in entries if e[0] == "rrt:tuned" or e[1] in peer]
    result = run_protocol(scenarios, entries, runs=runs, seed=seed, max_iter=max_iter,
                          progress=progress, clearance_m=clearance, caches=caches, peers=peers)
    if sys.stderr.isatty():
        sys.stderr.write("\n")
    if out is not None:
        write_protocol(result, out)
    base = str(result.summary["time_work_baseline"].iloc[0])
    typer.echo(f"{len(scenarios)} problems x {runs} seeds ({seed}..{seed + runs - 1}); ratios are "
               f"per problem, the baseline's median / the planner's (> 1: better). Ranked on "
               f"end-to-end time to the first certified path (the whole call) and on end-to-end "
               f"work (search + certification of the path), "
               f"against {_describe(base, scenarios)}; iterations (the paper's measure) against "
               f"RRT (step 10 deg, goal bias 0.05). Times measured with {caches} caches "
               f"({_CACHES[caches]}). A failed run counts with the time, work and "
               f"iterations ({max_iter}) it spent; cost = median path cost / RRT's, "
               f"cost/{'peer' if base != 'rrt' else 'RRT'} = / {base}'s (< 1: shorter; medians "
               "over successful runs)")
    header = ["rank", "planner", "time", "worst", "lost", "e2e work", "worst", "lost",
              "iterations", "geomean", "worst", "best", "lost", "success(min)", "success<RRT",
              "cost", f"cost/{'peer' if base != 'rrt' else 'RRT'}", "median time",
              "median e2e work"]
    rows = []
    for r in result.summary.sort_values("time_rank", kind="stable").itertuples():
        rows.append([str(r.time_rank), r.planner, _fmt(r.median_time_total_ratio, "x"),
                     _fmt(r.worst_time_total_ratio, "x"), str(r.problems_lost_time),
                     _fmt(r.median_work_total_ratio, "x"), _fmt(r.worst_work_total_ratio, "x"),
                     str(r.problems_lost_work_total),
                     _fmt(r.median_ratio, "x"), _fmt(r.geomean_ratio, "x"),
                     _fmt(r.worst_ratio, "x"), _fmt(r.best_ratio, "x"), str(r.problems_lost),
                     f"{100 * r.worst_success_rate:.0f} %", str(r.problems_success_below_rrt),
                     _fmt(r.median_cost_ratio), _fmt(r.median_cost_peer_ratio),
                     _fmt(1000 * r.median_time_total_s, " ms"),
                     "-" if r.median_work_total != r.median_work_total
                     else f"{r.median_work_total:.0f}"])
    _table(header, rows)
    ours = result.summary[~result.summary["planner"].isin([*peers, "rrt"])]
    if peers and len(ours):
        typer.echo(f"Against the fastest of {', '.join(peers)} on each problem (its median "
                   "end-to-end time / the planner's; [a-b]: 95 % bootstrap interval of the median "
                   "over problems; surely lost/won: the ratio's interval over the seeds lies "
                   "wholly below/above 1; success below: problems where some peer's certified "
                   "success is higher):")
        _table(["planner", "median", "geomean", "worst", "lost", "surely lost", "surely won",
                "success below", "fastest peer"],
               [[r.planner, _fmt(r.median_best_peer_ratio, "x")
                 + f" [{_fmt(r.median_best_peer_ratio_lo)}-{_fmt(r.median_best_peer_ratio_hi)}]",
                 _fmt(r.geomean_best_peer_ratio, "x"), _fmt(r.worst_best_peer_ratio, "x"),
                 f"{r.problems_lost_best_peer}/{r.problems}",
                 str(r.problems_surely_lost_best_peer), str(r.problems_surely_won_best_peer),
                 str(r.problems_success_below_peer), r.best_peers] for r in ours.itertuples()])
    if out is not None:
        typer.echo(f"wrote {out}/runs.csv, problems.csv, summary.csv")
    return 0


def _table(header: list[str], rows: list[list[str]]) -> None:
    widths = [max(len(str(x)) for x in col) for col in zip(header, *rows)]
    for line in [header, *rows]:
        typer.echo("  ".join(str(x).ljust(w) for x, w in zip(line, widths)).rstrip())


_CACHES = {"cold": "evicted before every timed call",
           "warm": "each planner's seeds of a problem in a row, in interleaved blocks of 10 seeds, "
                   "each block after 3 untimed calls",
           "shuffled": "planners shuffled per seed, nothing evicted"}


def _describe(label: str, scenarios) -> str:
    """``rrt:tuned (step 60 deg, goal bias 0.1)``: a baseline with its settings (per tuned
    shape when the problems run with several shapes' settings:
    :func:`~xfuzzy_rrt.planners.tuned.describe_tuned_rrt`)."""
    if label == "rrt:tuned":
        from xfuzzy_rrt.planners.tuned import describe_tuned_rrt, shape_of

        return f"rrt:tuned ({describe_tuned_rrt(shape_of(s) for s in scenarios)})"
    return "rrt (step 10 deg, goal bias 0.05)"


def register(app: typer.Typer) -> None:
    app.command("evaluate")(evaluate)
