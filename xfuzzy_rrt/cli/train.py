"""``xfuzzy-rrt train``: genetic training of a rulebook (parses options, renders progress)."""

from __future__ import annotations

import sys
import time
from pathlib import Path
from typing import List, Optional

import typer

from xfuzzy_rrt.cli.common import check_seed_option, check_workers_option, rulebook_arg


class _Progress:
    """One line per generation; on a terminal also a live bar while a generation runs."""

    def __init__(self, generations: int, stream=None):
        self.stream = stream or sys.stderr
        self.tty = self.stream.isatty()
        self.generations = generations
        self.started = time.perf_counter()
        self.done_here = 0  # generations run in this process (for the ETA)
        self.gen = 0

    def start(self, engine: str, generation: int) -> None:
        self.gen = generation
        where = f"resuming after generation {generation}" if generation else "starting"
        self._line(f"training on {engine}: {where}, up to {self.generations} generations")

    def chunk(self, done: int, total: int) -> None:
        if self.tty:
            width = 30
            fill = int(width * done / total)
            self.stream.write(f"\r  generation {self.gen + 1}: [{'#' * fill}{'.' * (width - fill)}] "
                              f"{done}/{total} chunks")
            self.stream.flush()

    def generation(self, row: dict) -> None:
        self.gen = int(row["generation"])
        self.done_here += 1
        elapsed = time.perf_counter() - self.started
        left = self.generations - self.gen
        eta = elapsed / self.done_here * left
        self._line(
            f"gen {self.gen:>3}/{self.generations}  best {row['best_fitness']:9.1f}  "
            f"mean {row['mean_fitness']:9.1f}  median {row['median_fitness']:9.1f}  "
            f"best median iterations {row['best_median_iterations']:7.1f}  "
            + (f"validation {row['validation_fitness']:.4g}  "
               if "validation_fitness" in row else "") +
            f"{row['runs_per_s']:8.0f} runs/s  {row['wall_s']:6.2f} s  ETA <= {eta:5.0f} s")

    def phase(self, text: str) -> None:
        self._line(text)

    def _line(self, text: str) -> None:
        if self.tty:
            self.stream.write("\r\033[K")
        self.stream.write(text + "\n")
        self.stream.flush()


def train(
    scenario: List[Path] = typer.Option(..., "--scenario", help="Training scenario file or directory (repeatable)."),
    population: int = typer.Option(400, "--population", help="Individuals per generation (paper: 400)."),
    generations: int = typer.Option(50, "--generations", help="Maximum generations (paper: 50)."),
    runs_per_eval: int = typer.Option(5, "--runs-per-eval", help="Planner runs per scenario per individual (paper: 5)."),
    target_fitness: Optional[float] = typer.Option(None, "--target-fitness", help="Stop when the best fitness reaches this (default: the paper's 9750 with --fitness paper; never with log-ratio, work-cvar or work-cost-cvar)."),
    seed: int = typer.Option(0, "--seed", callback=check_seed_option, help="Seed: the result depends only on it and the inputs."),
    workers: Optional[int] = typer.Option(None, "--workers", callback=check_workers_option, help="Local worker processes (default: all cores; 1 = in-process)."),
    scheduler: Optional[str] = typer.Option(None, "--scheduler", help="Dask scheduler address (tcp://HOST:PORT): evaluate there."),
    out: Path = typer.Option(..., "--out", help="Rulebook directory to write (also history.csv and checkpoint/)."),
    resume: bool = typer.Option(False, "--resume", help="Continue from OUT/checkpoint after an interruption."),
    bounds: str = typer.Option("absolute", "--bounds", help="Planner semantics: absolute or relative bounds (the paper's semantics), goal-frame, or goal-frame-any (one rulebook for any arm, trained with Fuzzy-RRT-Connect on scenarios of any DOF mixed)."),
    fitness: str = typer.Option("paper", "--fitness", help="paper (mean of 10000 - iterations, -100 on failure), log-ratio (mean log of RRT's median / iterations per problem), work-cvar (goal-frame and goal-frame-any semantics: log of the tuned RRT's median work / work per problem, half its mean plus half the mean of the worst quarter of problems) or work-cost-cvar (goal-frame: work-cvar minus --cost-weight times the mean log of the path cost / the tuned RRT's median path cost per problem)."),
    cost_weight: float = typer.Option(1.0, "--cost-weight", help="work-cost-cvar: weight of the path-cost term (1: one per cent of path length weighs as much as one per cent of work)."),
    validation_scenario: List[Path] = typer.Option([], "--validation-scenario", help="Held-out scenario file or directory (repeatable): picks the final rulebook, gives the train/validation gap."),
    max_iter: int = typer.Option(10_000, "--max-iter", help="Iteration budget per run (reward = max_iter - iterations)."),
    elite: int = typer.Option(8, "--elite", help="Best individuals copied unchanged into the next generation."),
    tournament: int = typer.Option(3, "--tournament", help="Tournament size of the selection."),
    crossover_prob: float = typer.Option(0.9, "--crossover-prob", help="Probability that a mating crosses (SBX)."),
    crossover_eta: float = typer.Option(15.0, "--crossover-eta", help="SBX distribution index."),
    mutation_rate: float = typer.Option(0.01, "--mutation-rate", help="Per-gene polynomial mutation probability."),
    mutation_eta: float = typer.Option(20.0, "--mutation-eta", help="Polynomial mutation distribution index."),
    block_rate: float = typer.Option(0.5, "--block-rate", help="Per-child probability of a term-block mutation."),
    block_sigma: float = typer.Option(0.05, "--block-sigma", help="Scale of term-block mutations (genes are in [0, 1])."),
    init: str = typer.Option("seeded", "--init", help="First generation: seeded (known rulebooks + perturbations) or random."),
    seed_rulebook: Optional[List[Path]] = typer.Option(None, "--seed-rulebook", callback=rulebook_arg, help="Rulebook directory (or a shipped rulebook's name) the seeded first generation starts from (repeatable; default: the shipped expert when its bounds mode matches --bounds). Its SHA-256 is recorded."),
    validation_runs: int = typer.Option(50, "--validation-runs", help="Runs per scenario to choose the final rulebook."),
    name: Optional[str] = typer.Option(None, "--name", help="Rulebook name (default: the --out folder's name)."),
    clearance: Optional[float] = typer.Option(None, "--clearance", help="Certified clearance in metres the planner must keep while training (default: each scenario's, else 0)."),
    dof: Optional[int] = typer.Option(None, "--dof", help="Joints of the rulebook to train, 2..7 (default: the training scenarios' own, which must agree: per arm for the paper's semantics, of all arms together for goal-frame). The genome has (2N+2) x 637 genes for the paper's semantics at N joints, 6 x 637 for goal-frame."),
) -> int:
    """Train the fuzzy systems (six at 2 DOF) with the paper's genetic algorithm; write a rulebook."""
    import dataclasses

    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.training.ga import GAConfig, check_fitness_fits
    from xfuzzy_rrt.training.run import (
        TrainJob,
        load_training_scenarios,
        resolve_seed_rulebooks,
        run_training,
        training_dof,
    )

    if workers is not None and workers < 1:
        raise InputError("--workers", f"must be >= 1, got {workers}")
    from xfuzzy_rrt.training.run import baselines, work_and_cost_baselines

    scenarios = load_training_scenarios(scenario)
    held_out = load_training_scenarios(validation_scenario) if validation_scenario else []
    # before any planning: scenarios of mixed DOF, or a --dof that disagrees, are one line
    dof = training_dof([*scenarios, *held_out], bounds, dof)
    if clearance is not None:
        from xfuzzy_rrt.geometry.clearance import with_clearance

        scenarios = [dataclasses.replace(t, scenario=with_clearance(t.scenario, clearance))
                     for t in scenarios]
        held_out = [dataclasses.replace(t, scenario=with_clearance(t.scenario, clearance))
                    for t in held_out]
    if target_fitness is None:
        target_fitness = 9750.0 if fitness == "paper" else 1e9
    base = v_base = cost = v_cost = ()
    check_fitness_fits(fitness, bounds)  # before the baselines: a mismatch is one line at once
    if not cost_weight >= 0 or cost_weight == float("inf"):
        raise InputError("--cost-weight", f"must be a finite number >= 0, got {cost_weight}")
    from xfuzzy_rrt.training.evaluate import DEFAULT_COST_WEIGHT, FITNESSES

    if fitness not in FITNESSES:  # before what depends on it (GAConfig says it again)
        raise InputError("--fitness", f"must be one of {', '.join(FITNESSES)}, got {fitness!r}")
    if cost_weight != DEFAULT_COST_WEIGHT and fitness != "work-cost-cvar":
        raise InputError("--cost-weight", f"weighs path cost in --fitness work-cost-cvar only, "
                         f"not in {fitness}")
    if fitness in ("log-ratio", "work-cvar", "work-cost-cvar"):
        what = {"log-ratio": "RRT's median iterations",
                "work-cost-cvar": "the tuned RRT's median work and path cost"}.get(
                    fitness, "the tuned RRT's median work")
        typer.echo(f"computing {what} on {len(scenarios) + len(held_out)} "
                   f"scenario(s) (the {fitness} baseline)", err=True)
        if fitness == "work-cost-cvar":  # one set of the tuned RRT's runs gives both
            base, cost = work_and_cost_baselines(scenarios, max_iter)
            v_base, v_cost = work_and_cost_baselines(held_out, max_iter) if held_out else ((), ())
        else:
            base = baselines(scenarios, max_iter, fitness)
            v_base = baselines(held_out, max_iter, fitness) if held_out else ()
    config = GAConfig(
        population=population, generations=generations, runs_per_eval=runs_per_eval,
        target_fitness=target_fitness, seed=seed, bounds=bounds, max_iter=max_iter, elite=elite,
        tournament=tournament, crossover_prob=crossover_prob, crossover_eta=crossover_eta,
        mutation_rate=mutation_rate, mutation_eta=mutation_eta, block_rate=block_rate,
        block_sigma=block_sigma, init=init, validation_runs=validation_runs,
        scenarios=tuple((t.scenario.name, t.sha256) for t in scenarios),
        fitness=fitness, baseline=base,
        validation=tuple((t.scenario.name, t.sha256) for t in held_out), validation_baseline=v_base,
        clearance_m=clearance, dof=dof, baseline_cost=cost, validation_baseline_cost=v_cost,
        cost_weight=cost_weight,
    )
    seeds = resolve_seed_rulebooks(seed_rulebook, config.init, config.bounds, config.dof)
    config = dataclasses.replace(config, seed_rulebooks=tuple((s.rulebook.name, s.sha256)
                                                              for s in seeds))
    job = TrainJob(config=config, scenarios=scenarios, out=out, resume=resume, workers=workers,
                   scheduler=scheduler, name=name, scenario_args=[str(p) for p in scenario],
                   validation=held_out, validation_args=[str(p) for p in validation_scenario],
                   seed_rulebooks=seeds)
    from xfuzzy_rrt.cli.common import test_signal

    progress = _Progress(generations)

    def generation(row: dict) -> None:
        progress.generation(row)
        # test hook (XFUZZY_RRT_TEST_SIGNAL=SIG@generation:K): interrupt right after the
        # checkpoint of generation K, a known point instead of a race with the file writes
        test_signal(f"generation:{int(row['generation'])}")

    def phase(text: str) -> None:
        progress.phase(text)
        test_signal("choice")  # after the last checkpoint, before the rulebook is written

    try:
        result = run_training(job, on_start=progress.start, on_generation=generation,
                              on_chunk=progress.chunk, on_phase=phase)
    except KeyboardInterrupt:
        progress.phase("interrupted; the last complete generation is checkpointed: "
                       "continue with the same command plus --resume")
        raise
    h = result.state.history
    typer.echo(f"generations run: {len(h)}; final best fitness {h[-1]['best_fitness']:.6g}; "
               f"chosen: {result.chosen_from}; validation fitness {result.validation_fitness:.6g}, "
               f"median iterations {result.validation_iterations_median:g}, "
               f"success {100 * result.validation_success_rate:.0f} %")
    typer.echo(f"wrote {out}/ (rulebook), {out / 'history.csv'}, {out / 'checkpoint'}/")
    return 0


def register(app: typer.Typer) -> None:
    app.command("train")(train)
