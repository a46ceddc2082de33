"""``xfuzzy-rrt robustness``: Stochastic Robustness Analysis of planned paths and planners.

Parses, calls :mod:`xfuzzy_rrt.robustness` and renders: CSV tables (written atomically, only
after every input has been validated) and a short text summary on stdout.
"""

from __future__ import annotations

from pathlib import Path
from typing import Optional

import typer

from xfuzzy_rrt.cli.common import check_seed_option, check_workers_option, split_planners

app = typer.Typer(
    help="Stochastic Robustness Analysis: how often a planned path (or a planner's paths) "
         "touches an obstacle when the obstacles are not where the model says (--sigma, "
         "metres) and the joints track with an error (--sigma-joint-deg). Prints the "
         "collision probability with a 95 % Clopper-Pearson interval.",
    no_args_is_help=True, add_completion=False, rich_markup_mode=None)

_SIGMA_HELP = ("Obstacle centre offset σ in metres per axis; a comma list sweeps it "
               "(e.g. 0.0005,0.001,0.002,0.005).")


def _floats(text: str, where: str) -> list[float]:
    from xfuzzy_rrt.errors import InputError

    try:
        values = [float(v) for v in text.split(",") if v.strip()]
    except ValueError:
        raise InputError(where, f"must be a comma list of numbers, got {text!r}") from None
    if not values:
        raise InputError(where, "needs at least one value")
    return values


def _perturbation(sigma_size: float, sigma_joint_deg: float, distribution: str):
    from xfuzzy_rrt.robustness.montecarlo import Perturbation

    return Perturbation(0.0, sigma_size, sigma_joint_deg, distribution)


def _check_out(out: Optional[Path]) -> None:
    from xfuzzy_rrt.errors import InputError

    if out is not None and out.exists() and not out.is_dir():
        raise InputError(str(out), "exists and is not a directory")


def _write_csv(frame, path: Path) -> None:
    from xfuzzy_rrt.atomic import write_text_atomic

    write_text_atomic(path, frame.to_csv(index=False, float_format="%.10g"))


def _print_path_table(label: str, table) -> None:
    typer.echo(f"{label}: nominal min clearance "
               f"{table['nominal_clearance_m'].iloc[0] * 1e3:.4g} mm")
    for _, r in table.iterrows():
        hit = (f", most hit: obstacle {int(r['most_hit_obstacle'])} "
               f"({int(r['most_hit_count'])}x)" if r["collisions"] else "")
        typer.echo(f"  sigma {r['sigma_m'] * 1e3:.4g} mm: P(collision) = "
                   f"{r['p_collision']:.4f} [{r['ci_low']:.4f}, {r['ci_high']:.4f}] "
                   f"({int(r['collisions'])}/{int(r['trials'])}); min clearance q01 "
                   f"{r['clearance_q01_m'] * 1e3:.4g} mm, median "
                   f"{r['clearance_q50_m'] * 1e3:.4g} mm{hit}")


def _analyse(paths, sigmas, base, trials, seed, workers, out, html):
    import pandas as pd

    from xfuzzy_rrt.robustness.sweep import path_sweep

    tables, trial_frames, figures = [], [], []
    for pp in paths:
        table, results = path_sweep(pp.scenario.arrays(), pp.path_deg, sigmas, base, trials,
                                    seed, workers)
        table.insert(0, "seed", pp.seed)
        table.insert(0, "planner", pp.planner)
        table.insert(0, "scenario", pp.scenario.name)
        tables.append(table)
        _print_path_table(pp.label, table)
        for sigma, res in zip(table["sigma_m"], results):
            trial_frames.append(pd.DataFrame({
                "scenario": pp.scenario.name, "planner": pp.planner, "seed": pp.seed,
                "sigma_m": sigma, "trial": range(res.trials),
                "min_clearance_m": res.min_clearance_m, "obstacle": res.obstacle,
                "collided": res.min_clearance_m <= 0.0}))
        figures.append((pp, table, results))
    if out is not None:
        _write_csv(pd.concat(tables, ignore_index=True), out / "path_robustness.csv")
        _write_csv(pd.concat(trial_frames, ignore_index=True), out / "trials.csv")
        if html:
            from xfuzzy_rrt.atomic import write_text_atomic
            from xfuzzy_rrt.robustness.figure import robustness_page

            write_text_atomic(out / "robustness.html", robustness_page(figures))
        typer.echo(f"tables written to {out}")


@app.command("path")
def path_cmd(
    scenario: Path = typer.Argument(..., help="Scenario TOML file the path was planned in."),
    result: Path = typer.Argument(..., help="A 'xfuzzy-rrt plan --out' result JSON."),
    sigma: str = typer.Option("0.0005,0.001,0.002,0.005", "--sigma", help=_SIGMA_HELP),
    sigma_size: float = typer.Option(0.0, "--sigma-size", help="Obstacle radius / half-size change σ (m)."),
    sigma_joint_deg: float = typer.Option(0.0, "--sigma-joint-deg", help="Joint tracking error σ per waypoint (degrees)."),
    distribution: str = typer.Option("normal", "--distribution", help="normal, or uniform (bounded, ±√3σ: same σ)."),
    trials: int = typer.Option(10_000, "--trials", help="Monte Carlo trials per σ."),
    seed: int = typer.Option(0, "--seed", callback=check_seed_option, min=0, help="Noise seed: same seed, same numbers, any --workers."),
    workers: Optional[int] = typer.Option(None, "--workers", callback=check_workers_option, help="Threads (default: all cores)."),
    out: Optional[Path] = typer.Option(None, "--out", help="Folder for path_robustness.csv and trials.csv."),
    html: bool = typer.Option(False, "--html", help="Also write robustness.html (needs --out)."),
) -> int:
    """Monte Carlo of one planned path: P(collision) vs σ, clearance distribution, obstacle hit most."""
    from xfuzzy_rrt.cli.common import load_scenario_warn
    from xfuzzy_rrt.robustness.inputs import load_result_path

    from xfuzzy_rrt.errors import InputError

    sigmas = _floats(sigma, "--sigma")
    base = _perturbation(sigma_size, sigma_joint_deg, distribution)
    if html and out is None:
        raise InputError("--html", "needs --out (the page is written beside the tables)")
    _check_out(out)
    s = load_scenario_warn(scenario)
    pp = load_result_path(s, result)
    _analyse([pp], sigmas, base, trials, seed, workers, out, html)
    return 0


@app.command("bench")
def bench_cmd(
    folder: Path = typer.Argument(..., help="A 'xfuzzy-rrt bench' output folder."),
    sigma: str = typer.Option("0.0005,0.001,0.002,0.005", "--sigma", help=_SIGMA_HELP),
    sigma_size: float = typer.Option(0.0, "--sigma-size", help="Obstacle radius / half-size change σ (m)."),
    sigma_joint_deg: float = typer.Option(0.0, "--sigma-joint-deg", help="Joint tracking error σ per waypoint (degrees)."),
    distribution: str = typer.Option("normal", "--distribution", help="normal, or uniform (bounded, ±√3σ: same σ)."),
    trials: int = typer.Option(10_000, "--trials", help="Monte Carlo trials per σ and path."),
    seed: int = typer.Option(0, "--seed", callback=check_seed_option, min=0, help="Noise seed."),
    workers: Optional[int] = typer.Option(None, "--workers", callback=check_workers_option, help="Threads (default: all cores)."),
    out: Optional[Path] = typer.Option(None, "--out", help="Folder for the tables (default: FOLDER/robustness)."),
    html: bool = typer.Option(False, "--html", help="Also write robustness.html."),
) -> int:
    """The same analysis for every example path of a bench folder (one per scenario and planner)."""
    from xfuzzy_rrt.robustness.inputs import load_bench_paths

    sigmas = _floats(sigma, "--sigma")
    base = _perturbation(sigma_size, sigma_joint_deg, distribution)
    paths = load_bench_paths(folder)
    out = out if out is not None else folder / "robustness"
    _check_out(out)
    _analyse(paths, sigmas, base, trials, seed, workers, out, html)
    if out.resolve() == (folder / "robustness").resolve():
        typer.echo(f"add the robustness section to the bench report: xfuzzy-rrt report {folder}")
    return 0


@app.command("planners")
def planners_cmd(
    scenarios: list[Path] = typer.Argument(..., help="Scenario TOML files (a directory: every *.toml)."),
    planners: str = typer.Option("rrt,fuzzy-rrt", "--planners", help="Comma list of planners."),
    sigma: str = typer.Option("0.0005,0.001,0.002,0.005", "--sigma", help=_SIGMA_HELP),
    sigma_size: float = typer.Option(0.0, "--sigma-size", help="Obstacle radius / half-size change σ (m)."),
    sigma_joint_deg: float = typer.Option(0.0, "--sigma-joint-deg", help="Joint tracking error σ (degrees)."),
    distribution: str = typer.Option("normal", "--distribution", help="normal or uniform."),
    runs: int = typer.Option(10, "--runs", min=1, max=10_000, help="Plans per (scenario, planner, σ)."),
    trials: int = typer.Option(2000, "--trials", help="Monte Carlo trials per planned path."),
    seed: int = typer.Option(0, "--seed", callback=check_seed_option, min=0, help="First seed (run k uses seed + k)."),
    max_iter: int = typer.Option(10_000, "--max-iter", min=1, max=1_000_000, help="Iteration budget."),
    clearance: Optional[float] = typer.Option(None, "--clearance", help="Planning clearance (m; default: the scenario's)."),
    margins: Optional[str] = typer.Option(None, "--margins", help="Comma list of clearances (m): find the smallest with P(collision) <= --target at --margin-sigma."),
    margin_sigma: float = typer.Option(0.002, "--margin-sigma", help="σ (m) for --margins."),
    target: float = typer.Option(0.01, "--target", help="Collision probability the margin must keep (upper 95 % bound)."),
    workers: Optional[int] = typer.Option(None, "--workers", callback=check_workers_option, help="Threads (default: all cores)."),
    out: Optional[Path] = typer.Option(None, "--out", help="Folder for planner_robustness.csv (and margin_needed.csv)."),
) -> int:
    """Plan on a perturbed model and execute on the true one (and the reverse), per planner and σ."""
    from xfuzzy_rrt.cli.common import load_scenario_warn
    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.planners.api import check_planner
    from xfuzzy_rrt.robustness.sweep import margin_needed, planner_sweep

    sigmas = _floats(sigma, "--sigma")
    names = split_planners(planners)
    if not names:
        raise InputError("--planners", "needs at least one planner")
    for name in names:
        check_planner(name, "--planners")
    grid = _floats(margins, "--margins") if margins is not None else None
    if not 0.0 < target < 1.0:
        raise InputError("--target", f"must lie in (0, 1), got {target!r}")
    base = _perturbation(sigma_size, sigma_joint_deg, distribution)
    _check_out(out)
    files = []
    for p in scenarios:
        files.extend(sorted(p.glob("*.toml")) if p.is_dir() else [p])
    loaded = [load_scenario_warn(f) for f in files]
    table = planner_sweep(loaded, names, sigmas, base, runs, seed, max_iter, trials,
                          clearance, workers)
    for _, r in table.iterrows():
        typer.echo(f"{r['scenario']} {r['planner']} sigma {r['sigma_m'] * 1e3:.4g} mm "
                   f"{r['mode']}: success {r['success_rate']:.3f}, collision "
                   f"{r['collision_rate']:.4f} [{r['ci_low']:.4f}, {r['ci_high']:.4f}]")
    needed = None
    if grid is not None:
        needed = margin_needed(loaded, names, margin_sigma, grid, base, runs, seed, max_iter,
                               trials, target, workers)
        for planner, rows in needed.groupby("planner", sort=False):
            hit = rows[rows["needed"]]
            what = (f"{hit['clearance_m'].iloc[0] * 1e3:.4g} mm" if len(hit)
                    else f"more than {rows['clearance_m'].max() * 1e3:.4g} mm")
            typer.echo(f"{planner}: clearance needed for P(collision) <= {target:g} at sigma "
                       f"{margin_sigma * 1e3:.4g} mm: {what}")
    if out is not None:
        _write_csv(table, out / "planner_robustness.csv")
        if needed is not None:
            _write_csv(needed, out / "margin_needed.csv")
        typer.echo(f"tables written to {out}")
    return 0


@app.command("moving")
def moving_cmd(
    scenarios: list[Path] = typer.Argument(..., help="Scenario TOML files (a directory: every *.toml)."),
    planners: str = typer.Option("rrt,fuzzy-rrt", "--planners", help="Comma list of planners."),
    speed: str = typer.Option("0.002,0.005,0.01", "--speed", help="Obstacle drift speed(s) in m/s (comma list; a direction per obstacle and run)."),
    joint_speed: float = typer.Option(30.0, "--joint-speed", help="Arm speed along its path, degrees (joint space) per second."),
    rate: float = typer.Option(20.0, "--rate", help="Executor rate (Hz): re-check and collision record per tick."),
    replan: bool = typer.Option(False, "--replan", help="Re-check the remaining path every tick and replan from the current configuration when it is invalidated."),
    runs: int = typer.Option(10, "--runs", min=1, max=10_000, help="Executions per (scenario, planner, speed)."),
    seed: int = typer.Option(0, "--seed", callback=check_seed_option, min=0, help="First seed (run k uses seed + k)."),
    max_iter: int = typer.Option(10_000, "--max-iter", min=1, max=1_000_000, help="Iteration budget per plan."),
    clearance: Optional[float] = typer.Option(None, "--clearance", help="Planning clearance (m; default: the scenario's)."),
    time_limit: float = typer.Option(30.0, "--time-limit", help="Give up after this many simulated seconds."),
    out: Optional[Path] = typer.Option(None, "--out", help="Folder for moving_obstacles.csv."),
) -> int:
    """Obstacles drifting while the arm executes: success, collisions, replans, replanning latency."""
    from xfuzzy_rrt.cli.common import load_scenario_warn
    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.planners.api import check_planner
    from xfuzzy_rrt.robustness.moving import diagnosis, moving_obstacles

    speeds = _floats(speed, "--speed")
    names = split_planners(planners)
    if not names:
        raise InputError("--planners", "needs at least one planner")
    for name in names:
        check_planner(name, "--planners")
    _check_out(out)
    files = []
    for p in scenarios:
        files.extend(sorted(p.glob("*.toml")) if p.is_dir() else [p])
    loaded = [load_scenario_warn(f) for f in files]
    table = moving_obstacles(loaded, names, speeds, joint_speed, rate, replan, runs, seed,
                             max_iter, clearance, time_limit)
    for _, r in table.iterrows():
        typer.echo(f"{r['scenario']} {r['planner']} speed {r['speed_m_s'] * 1e3:.4g} mm/s"
                   f"{' replan' if replan else ''}: success {r['success_rate']:.3f}, collision "
                   f"{r['collision_rate']:.3f}, replans {r['replans_mean']:.2f}/run, latency "
                   f"median {r['latency_median_s'] * 1e3:.3g} ms, max {r['latency_max_s'] * 1e3:.3g} ms")
        why = diagnosis(r)
        if why is not None:
            typer.echo(f"  why: {why}")
    if out is not None:
        _write_csv(table, out / "moving_obstacles.csv")
        typer.echo(f"table written to {out}")
    return 0


def register(app_: typer.Typer) -> None:
    app_.add_typer(app, name="robustness")
