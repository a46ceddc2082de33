"""The generational genetic algorithm of the paper, with fair fitness, seeding and checkpoints.

One generation, read top to bottom in :meth:`Trainer.step`:

1. **Evaluate** every individual on the same run seeds (common random numbers, so a better
   fitness means a better rulebook, not a luckier draw) — ``runs_per_eval`` seeds per scenario,
   fresh each generation (so no rulebook is fitted to a fixed set of seeds).
   Fitness = mean paper reward (see :mod:`.evaluate`). Elites are re-evaluated on the fresh
   seeds like everyone else.
2. **Record** best / mean / median fitness, the generation's best individual (hall of fame).
3. **Stop** after ``generations`` generations or as soon as the best fitness reaches
   ``target_fitness`` (the paper's 9750).
4. **Breed**: the ``elite`` best individuals pass unchanged; the rest are children of
   tournament selection, simulated binary crossover and polynomial mutation (pymoo's
   operators, written again number for number in :mod:`.operators`; see the package
   docstring).
5. **Checkpoint**: the bred population, the generator state and the history go to one file,
   written atomically, so that resuming after a crash continues exactly where it stopped.

The rulebook returned at the end is not simply the last generation's luckiest individual: the
hall of fame (each generation's best) and the final top individuals are re-evaluated on a
separate set of validation seeds and the best mean reward wins. Five runs are a noisy estimate;
choosing among ~55 candidates on five runs each would mostly pick noise (the winner's curse).

Initialisation (``init="seeded"``, the default): a population of uniformly random genomes is
flat — measured on ``paper-reference``, random rule constants average out to a tiny sampling
box and fail every run, so every individual scores -100 and selection has nothing to select.
So the first generation holds rulebooks that already solve problems — the RRT-equivalent one
(full box, bias 0.05, step 10°), goal-biased variants of it, the seed rulebooks (``train
--seed-rulebook``; by default the shipped ``expert`` when its bounds meaning matches), whose
SHA-256 are part of the configuration — and perturbations of them at several scales: small per-rule noise and
whole-output shifts (which move a bound or the bias everywhere at once, the coarse direction a
per-rule mutation cannot take). ``init="random"`` gives the paper-style uniform start for
comparison.
"""

from __future__ import annotations

import hashlib
import json
import time
from dataclasses import asdict, dataclass, field
from typing import Callable

import numpy as np

from xfuzzy_rrt.fuzzy import semantics as _sem
from xfuzzy_rrt.fuzzy.variables import N_RULES
from xfuzzy_rrt.training.evaluate import DEFAULT_COST_WEIGHT, FITNESSES, iterations_of, score
from xfuzzy_rrt.training.operators import polynomial_mutation, sbx, tournament
from xfuzzy_rrt.training.genome import (
    GENES_PER_FIS,
    MF_GENES,
    MODES,
    constant_genome,
    constant_outputs_genome,
    encode,
    n_genes,
)

HISTORY_COLUMNS = ["generation", "best_fitness", "mean_fitness", "median_fitness", "wall_s",
                   "best_median_iterations", "success_rate", "runs", "runs_per_s",
                   "validation_fitness"]


@dataclass(frozen=True)
class GAConfig:
    """Everything that determines a training run's result (workers and engine do not)."""

    population: int = 400
    generations: int = 50
    runs_per_eval: int = 5
    target_fitness: float = 9750.0
    seed: int = 0
    bounds: str = "absolute"
    max_iter: int = 10_000
    elite: int = 8
    tournament: int = 3
    crossover_prob: float = 0.9
    crossover_eta: float = 15.0
    mutation_rate: float = 0.01
    mutation_eta: float = 20.0
    block_rate: float = 0.5
    block_sigma: float = 0.05
    init: str = "seeded"
    validation_runs: int = 50
    scenarios: tuple[tuple[str, str], ...] = ()  # (name, sha256) of each training scenario
    fitness: str = "paper"  # or "log-ratio", "work-cvar", "work-cost-cvar" (see .evaluate.score)
    # per training scenario: RRT's median iterations (log-ratio) or the tuned RRT's median work (work-cvar)
    baseline: tuple[float, ...] = ()
    validation: tuple[tuple[str, str], ...] = ()  # held-out scenarios that pick the final rulebook
    validation_baseline: tuple[float, ...] = ()
    #: ``--clearance``: the certified margin (m) every training run must keep; ``None``: each
    #: scenario's own ``[safety] clearance_m``. A run that cannot keep it fails (reward as for
    #: any failure), so a rulebook can be trained for a margin.
    clearance_m: float | None = None
    #: (name, sha256) of each seed rulebook of a seeded first generation, in order: the first
    #: generation depends on them, so they are part of the fingerprint and of the provenance.
    seed_rulebooks: tuple[tuple[str, str], ...] = ()
    #: ``--dof``: joints of the rulebook trained (paper: per arm; goal-frame: of all arms
    #: together). It sizes the genome (:func:`~.genome.n_genes`).
    dof: int = _sem.DEFAULT_DOF
    #: ``work-cost-cvar``: the tuned RRT's median path cost (degrees) per training and per
    #: validation scenario, and ``--cost-weight``, the weight of the path-cost term
    #: (:func:`~.evaluate.work_cost_cvar_fitness`).
    baseline_cost: tuple[float, ...] = ()
    validation_baseline_cost: tuple[float, ...] = ()
    cost_weight: float = DEFAULT_COST_WEIGHT

    @property
    def n_genes(self) -> int:
        """Genes of one individual at this configuration's bounds mode and DOF."""
        return n_genes(self.bounds, self.dof)

    def __post_init__(self) -> None:
        from xfuzzy_rrt.errors import InputError

        def need(ok: bool, option: str, message: str) -> None:
            if not ok:
                raise InputError(option, message)

        need(2 <= self.population <= 100_000, "--population", f"must lie in [2, 100000], got {self.population}")
        need(1 <= self.generations <= 100_000, "--generations", f"must lie in [1, 100000], got {self.generations}")
        need(1 <= self.runs_per_eval <= 10_000, "--runs-per-eval", f"must lie in [1, 10000], got {self.runs_per_eval}")
        need(np.isfinite(self.target_fitness), "--target-fitness", "must be a finite number")
        need(0 <= self.seed < 2**63, "--seed", f"must lie in [0, 2^63), got {self.seed}")
        need(self.bounds in MODES, "--bounds", f"must be one of {', '.join(MODES)}, got {self.bounds!r}")
        need(self.fitness in FITNESSES, "--fitness", f"must be one of {', '.join(FITNESSES)}, got {self.fitness!r}")
        if self.fitness in ("log-ratio", "work-cvar", "work-cost-cvar"):
            what = "RRT's median iterations" if self.fitness == "log-ratio" else "the tuned RRT's median work"
            need(len(self.baseline) == len(self.scenarios), "--fitness",
                 f"{self.fitness} needs {what} for every training scenario")
            _refuse_nonpositive(self.baseline, self.scenarios, self.fitness, what)
            need(len(self.validation_baseline) == len(self.validation), "--validation-scenario",
                 f"{self.fitness} needs {what} for every validation scenario")
        if self.fitness == "work-cost-cvar":
            what = "the tuned RRT's median path cost"
            need(len(self.baseline_cost) == len(self.scenarios), "--fitness",
                 f"work-cost-cvar needs {what} for every training scenario")
            _refuse_nonpositive(self.baseline_cost, self.scenarios, self.fitness, what)
            need(len(self.validation_baseline_cost) == len(self.validation)
                 and all(np.isfinite(b) and b > 0 for b in self.validation_baseline_cost),
                 "--validation-scenario",
                 f"work-cost-cvar needs {what} (positive) for every validation scenario")
        need(isinstance(self.cost_weight, (int, float)) and np.isfinite(self.cost_weight)
             and self.cost_weight >= 0, "--cost-weight",
             f"must be a finite number >= 0, got {self.cost_weight!r}")
        need(self.fitness == "work-cost-cvar" or self.cost_weight == DEFAULT_COST_WEIGHT,
             "--cost-weight", f"weighs path cost in --fitness work-cost-cvar only, not in "
                              f"{self.fitness}")
        check_fitness_fits(self.fitness, self.bounds)
        need(1 <= self.max_iter <= 1_000_000, "--max-iter", f"must lie in [1, 1000000], got {self.max_iter}")
        need(0 <= self.elite < self.population, "--elite", f"must lie in [0, population), got {self.elite}")
        need(2 <= self.tournament <= self.population, "--tournament", f"must lie in [2, population], got {self.tournament}")
        need(0.0 <= self.crossover_prob <= 1.0, "--crossover-prob", "must lie in [0, 1]")
        need(0.0 <= self.mutation_rate <= 1.0, "--mutation-rate", "must lie in [0, 1]")
        need(self.crossover_eta > 0 and self.mutation_eta > 0, "--eta", "distribution indices must be > 0")
        need(self.init in ("seeded", "random"), "--init", f"must be seeded or random, got {self.init!r}")
        need(0 <= self.validation_runs <= 10_000, "--validation-runs", "must lie in [0, 10000]")
        need(len(self.scenarios) >= 1, "--scenario", "give at least one training scenario")
        need(self.init == "seeded" or not self.seed_rulebooks, "--seed-rulebook",
             "seed rulebooks are only used with --init seeded")
        problem = _sem.dof_problem(self.dof)
        need(problem is None, "--dof", problem or "")

    #: Options that only say when to stop or how to choose at the end: a checkpoint may be
    #: resumed with other values (e.g. more generations), and the result is then exactly that
    #: of a run asked for with those values from the start.
    STOPPING = ("generations", "target_fitness", "validation_runs")
    #: Options added after the first checkpoints were written: left out of the fingerprint
    #: while they keep their default, so older checkpoints still resume.
    LATER = {"fitness": "paper", "baseline": (), "validation": (), "validation_baseline": (),
             "seed_rulebooks": (), "clearance_m": None, "dof": _sem.DEFAULT_DOF,
             "baseline_cost": (), "validation_baseline_cost": (),
             "cost_weight": DEFAULT_COST_WEIGHT}

    def fingerprint(self) -> str:
        """SHA-256 of the options that shape the search (identifies a checkpoint's run),
        including the training scenarios' and the seed rulebooks' SHA-256. Options added later
        are left out while they keep their default (absent rather than empty), so a run that
        does not use them keeps the fingerprint it had before they existed and still resumes."""
        fields = {k: v for k, v in asdict(self).items() if k not in self.STOPPING
                  and not (k in self.LATER and v == self.LATER[k])}
        blob = json.dumps(fields, sort_keys=True, separators=(",", ":"))
        return hashlib.sha256(blob.encode()).hexdigest()


# ------------------------------------------------------------------------------ seeds


def _refuse_nonpositive(baseline, scenarios, fitness: str, what: str) -> None:
    """One InputError naming the first training scenario whose baseline (``what``, per
    scenario) is not a positive number: the fitness divides by it. A start that is its goal
    needs no iteration and has a path of length zero (``scenarios``: ``(name, sha256)`` pairs;
    its position when the names are not recorded)."""
    from xfuzzy_rrt.errors import InputError

    for i, b in enumerate(baseline):
        if not b > 0:  # (NaN too: no path found)
            name = f"scenario {scenarios[i][0]!r}" if i < len(scenarios) else f"scenario {i + 1}"
            raise InputError("--fitness", f"{fitness} needs {what} (positive) for every "
                             f"training scenario; {name} has {b:g} (is its start its goal?)")


def check_fitness_fits(fitness: str, bounds: str) -> None:
    """``--fitness work-cvar`` needs a semantics whose training evaluation counts the
    planner's work (:attr:`~xfuzzy_rrt.fuzzy.semantics.Semantics.measures`), ``work-cost-cvar``
    one that also measures path cost: one line, which ``train`` reports before it spends
    minutes on the baselines."""
    if bounds not in MODES:
        return
    measures = _sem.of_mode(bounds).measures
    from xfuzzy_rrt.errors import InputError

    if fitness in ("work-cvar", "work-cost-cvar") and "work" not in measures:
        raise InputError("--fitness", f"{fitness} counts the planner's work, which only the "
                         "planner's own kernel spends: train it with --bounds goal-frame, not "
                         f"{bounds}")
    if fitness == "work-cost-cvar" and "cost" not in measures:
        raise InputError("--fitness", "work-cost-cvar measures path cost, which only the "
                         "single-tree goal-frame evaluation reports: train it with --bounds "
                         f"goal-frame, not {bounds}")


def generation_seeds(seed: int, generation: int, runs: int) -> np.ndarray:
    """Planner seeds of one generation (shared by all its individuals), from ``(seed, gen)``."""
    state = np.random.SeedSequence([int(seed), 1, int(generation)]).generate_state(runs, np.uint64)
    return (state >> np.uint64(1)).astype(np.int64)


def validation_seeds(seed: int, runs: int) -> np.ndarray:
    """Seeds for choosing the final rulebook, disjoint in purpose from every generation's."""
    state = np.random.SeedSequence([int(seed), 2]).generate_state(runs, np.uint64)
    return (state >> np.uint64(1)).astype(np.int64)


# ------------------------------------------------------------------------------ initial population


#: Constant goal-frame rulebooks that already beat RRT on the generated family (measured on
#: training problems only): (goal_bias, uniform_share, ahead, behind, side, step).
GOAL_FRAME_SEEDS = (
    (0.05, 1.0, 0.0, 0.0, 0.0, 10.0),  # plain RRT expressed in the goal-frame semantics
    (0.3, 0.2, 60.0, 20.0, 45.0, 15.0),
    (0.2, 0.3, 90.0, 30.0, 60.0, 15.0),
    (0.2, 0.2, 120.0, 40.0, 90.0, 10.0),
    (0.3, 0.5, 60.0, 20.0, 45.0, 20.0),
    # long steps: blocked edges are rejected cheaply (geometry.collision's probes), so the
    # tuned RRT plans fastest at 180°; these start the search where the step range now reaches
    (0.05, 1.0, 0.0, 0.0, 0.0, 90.0),  # the tuned RRT's kind of search, capped at 90°
    (0.2, 0.3, 90.0, 30.0, 60.0, 60.0),
    (0.3, 0.2, 120.0, 40.0, 90.0, 100.0),
)


def seed_genomes(bounds: str, rulebooks=(), dof: int = _sem.DEFAULT_DOF) -> list[tuple[str, np.ndarray]]:
    """Named genomes that already solve problems (see the module docstring): the built-in
    constant ones, then each of ``rulebooks`` (which must mean what the training means:
    the same bounds, or the goal-frame semantics, and the same DOF). At N joints the paper's
    built-in boxes give every joint the same interval (the 2-DOF ones repeated)."""
    for rb in rulebooks:
        if rb.dof != dof:
            raise ValueError(f"seed rulebook {rb.name!r} is for dof {rb.dof}, the training "
                             f"for dof {dof}")
    sem = _sem.of_mode(bounds)
    if sem.outputs == _sem.GOAL_FRAME.outputs:  # goal-frame and the semantics sharing its outputs
        out = [(f"goal-frame-{i}", constant_outputs_genome(v, bounds, dof))
               for i, v in enumerate(GOAL_FRAME_SEEDS)]
        for rb in rulebooks:
            if not sem.can_seed_from(rb.semantics.name):
                raise ValueError(f"seed rulebook {rb.name!r} is not a {sem.name} rulebook")
            out.append((rb.name, encode(*rb.arrays(), bounds, dof)))
        return out
    full = (-180.0, 180.0) * dof
    out = [("rrt-equivalent", constant_genome(0.05, full, 10.0))]
    for bias in (0.1, 0.2, 0.35, 0.5):
        out.append((f"rrt-bias-{bias}", constant_genome(bias, full, 10.0)))
    if bounds == "relative":
        for half in (30.0, 60.0, 90.0):
            out.append((f"window-{half:g}", constant_genome(0.2, (-half, half) * dof, 10.0)))
    for rb in rulebooks:
        if rb.semantics.name != "paper" or rb.bounds_mode != bounds:
            raise ValueError(f"seed rulebook {rb.name!r} has {rb.bounds_mode} bounds, the "
                             f"training {bounds}")
        knots, consts = rb.arrays()
        out.append((rb.name, encode(knots, consts, "absolute", dof)))
    return out


def initial_population(config: GAConfig, rng: np.random.Generator, rulebooks=()) -> np.ndarray:
    """The first generation ``[population, n_genes]`` (deterministic given ``rng``; 3,822 genes
    at 2 DOF).

    ``rulebooks`` are the seed rulebooks; they must be exactly those ``config.seed_rulebooks``
    names (same order, same SHA-256), so the population depends only on what is recorded.
    """
    n = config.population
    given = tuple((rb.name, rb.sha256) for rb in rulebooks)
    if given != tuple(tuple(x) for x in config.seed_rulebooks):
        raise ValueError(f"seed rulebooks {given} are not the configuration's "
                         f"{config.seed_rulebooks}")
    size = config.n_genes
    n_fis = size // GENES_PER_FIS
    if config.init == "random":
        return rng.random((n, size))
    seeds = [g for _, g in seed_genomes(config.bounds, rulebooks, config.dof)]
    pop = np.empty((n, size))
    k = min(len(seeds), n)
    pop[:k] = np.array(seeds[:k])
    scales = (0.02, 0.05, 0.1, 0.2)
    for i in range(k, n):
        base = seeds[int(rng.integers(len(seeds)))]
        sigma = scales[int(rng.integers(len(scales)))]
        g = base + 0.25 * sigma * rng.standard_normal(size)
        g = g.reshape(n_fis, GENES_PER_FIS)
        g[:, MF_GENES:] += term_blocks(rng, sigma, n_fis)
        pop[i] = np.clip(g.reshape(size), 0.0, 1.0)
    return pop


def term_blocks(rng: np.random.Generator, sigma: float, n_fis: int) -> np.ndarray:
    """Random *separable* changes of rule constants: ``[n_fis, 625]``.

    For each FIS, ``Δc[t0, t1, t2, t3] = s + Σ_i u_i[t_i]`` with a whole-output shift ``s`` and a
    per-term offset ``u_i`` for each input (all normal with scale ``sigma``). A rule grid
    changed this way moves its output coherently — "more goal bias wherever the goal is
    near", "the joint-1 interval shifts when the goal is to the west" — which a per-rule
    mutation could only reach by many independent, individually neutral steps.
    """
    s = sigma * rng.standard_normal((n_fis, 1, 1, 1, 1))
    u = sigma * rng.standard_normal((n_fis, 4, 5))
    grid = (s + u[:, 0, :, None, None, None] + u[:, 1, None, :, None, None]
            + u[:, 2, None, None, :, None] + u[:, 3, None, None, None, :])
    return grid.reshape(n_fis, N_RULES)


# ------------------------------------------------------------------------------ breeding


def breed(pop: np.ndarray, fit: np.ndarray, config: GAConfig, rng: np.random.Generator) -> np.ndarray:
    """The next generation: elites unchanged, then selected, crossed and mutated children
    (:mod:`.operators`: pymoo's operators, number for number)."""
    n, n_var = pop.shape
    order = np.lexsort((np.arange(n), -fit))  # best first, stable
    elites = pop[order[: config.elite]]
    n_children = n - config.elite
    if n_children == 0:
        return elites.copy()
    n_matings = (n_children + 1) // 2
    parents = tournament(fit, n_matings, config.tournament, rng)
    off = sbx(pop[parents[:, 0]], pop[parents[:, 1]], config.crossover_prob,
              config.crossover_eta, rng)
    off = polynomial_mutation(off, config.mutation_rate, config.mutation_eta, rng)
    children = off[:n_children].copy()
    if config.block_rate > 0:
        # term-block mutation (see term_blocks): one random FIS per chosen child
        hit = np.flatnonzero(rng.random(n_children) < config.block_rate)
        n_fis = n_var // GENES_PER_FIS  # the genome's own FIS count (6 at 2 DOF)
        fis = rng.integers(n_fis, size=hit.size)
        blocks = term_blocks(rng, config.block_sigma, hit.size)
        view = children.reshape(n_children, n_fis, GENES_PER_FIS)
        view[hit, fis, MF_GENES:] += blocks
    return np.vstack([elites, np.clip(children, 0.0, 1.0)])


# ------------------------------------------------------------------------------ state + loop


@dataclass
class TrainState:
    """What a checkpoint holds: enough to continue exactly where training stopped."""

    generation: int  # generations evaluated so far
    population: np.ndarray  # the population to evaluate next (or the last one when done)
    rng_state: dict
    history: list[dict] = field(default_factory=list)
    hall_of_fame: list[np.ndarray] = field(default_factory=list)  # best genome per generation
    last_fitness: np.ndarray | None = None  # fitness of the last evaluated generation
    last_population: np.ndarray | None = None
    done: bool = False


@dataclass(frozen=True)
class TrainResult:
    genes: np.ndarray  # the chosen genome
    validation_fitness: float
    validation_iterations_median: float
    validation_success_rate: float
    chosen_from: str  # e.g. "hall of fame, generation 37"
    state: TrainState


def new_state(config: GAConfig, rulebooks=()) -> TrainState:
    rng = np.random.Generator(np.random.PCG64(np.random.SeedSequence([config.seed, 0])))
    pop = initial_population(config, rng, rulebooks)
    return TrainState(generation=0, population=pop, rng_state=rng.bit_generator.state)


class Trainer:
    """Runs generations on an evaluator; callbacks let the CLI show progress and checkpoint."""

    def __init__(self, config: GAConfig, evaluator,
                 on_generation: Callable[[dict, TrainState], None] | None = None,
                 on_chunk: Callable[[int, int], None] | None = None,
                 validator=None):
        """*validator* (optional) evaluates on the held-out ``config.validation`` scenarios:
        each generation's best is scored there (the train / validation gap in the history),
        and the final rulebook is chosen there instead of on fresh seeds of the training set."""
        self.config = config
        self.evaluator = evaluator
        self.on_generation = on_generation
        self.on_chunk = on_chunk
        self.validator = validator

    def _fitness(self, runs: np.ndarray, held_out: bool = False) -> np.ndarray:
        c = self.config
        baseline = c.validation_baseline if held_out else c.baseline
        cost = c.validation_baseline_cost if held_out else c.baseline_cost
        return score(runs, c.fitness, c.max_iter, np.asarray(baseline, dtype=np.float64),
                     np.asarray(cost, dtype=np.float64), c.cost_weight)

    def step(self, state: TrainState) -> TrainState:
        """Evaluate ``state.population``, record, stop or breed; return the next state."""
        c = self.config
        t0 = time.perf_counter()
        seeds = generation_seeds(c.seed, state.generation, c.runs_per_eval)
        runs = self.evaluator(state.population, seeds, self.on_chunk)
        fit = self._fitness(runs)
        its = iterations_of(runs)
        best = int(np.lexsort((np.arange(len(fit)), -fit))[0])
        ok = (its >= 0) & (its < c.max_iter)
        best_its = np.where(ok[best], its[best], c.max_iter)
        held_out = float("nan")
        if self.validator is not None:
            # the same seeds every generation, so the curve compares like with like
            v_its = self.validator(state.population[best][None], validation_seeds(c.seed, c.runs_per_eval))
            held_out = float(self._fitness(v_its, held_out=True)[0])
        wall = time.perf_counter() - t0
        runs = int(its.size)
        row = {
            "generation": state.generation + 1,
            "best_fitness": float(fit[best]),
            "mean_fitness": float(fit.mean()),
            "median_fitness": float(np.median(fit)),
            "wall_s": wall,
            "best_median_iterations": float(np.median(best_its)),
            "success_rate": float(ok.mean()),
            "runs": runs,
            "runs_per_s": runs / wall if wall > 0 else float("nan"),
        }
        if self.validator is not None:
            row["validation_fitness"] = held_out
        generation = state.generation + 1
        done = generation >= c.generations or fit[best] >= c.target_fitness
        rng = np.random.Generator(np.random.PCG64())
        rng.bit_generator.state = state.rng_state
        next_pop = state.population if done else breed(state.population, fit, c, rng)
        new = TrainState(
            generation=generation, population=next_pop, rng_state=rng.bit_generator.state,
            history=[*state.history, row],
            hall_of_fame=[*state.hall_of_fame, state.population[best].copy()],
            last_fitness=fit, last_population=state.population, done=bool(done),
        )
        if self.on_generation:
            self.on_generation(row, new)
        return new

    def run(self, state: TrainState) -> TrainState:
        state = self.extend(state)
        while not state.done:
            state = self.step(state)
        return state

    def extend(self, state: TrainState) -> TrainState:
        """Reopen a finished run when the stopping options now allow more generations.

        A finished run skipped breeding after its last generation, so breeding now (with the
        generator state saved then) continues exactly as an uninterrupted longer run would.
        """
        c = self.config
        if not state.done or state.last_fitness is None:
            return state
        if state.generation >= c.generations or state.history[-1]["best_fitness"] >= c.target_fitness:
            return state
        rng = np.random.Generator(np.random.PCG64())
        rng.bit_generator.state = state.rng_state
        pop = breed(state.last_population, state.last_fitness, c, rng)
        return TrainState(generation=state.generation, population=pop,
                          rng_state=rng.bit_generator.state, history=state.history,
                          hall_of_fame=state.hall_of_fame, last_fitness=state.last_fitness,
                          last_population=state.last_population, done=False)

    def choose(self, state: TrainState, top: int = 5) -> TrainResult:
        """Re-evaluate the hall of fame and the final top individuals on validation seeds."""
        c = self.config
        cands: list[tuple[str, np.ndarray]] = [
            (f"hall of fame, generation {g + 1}", genes) for g, genes in enumerate(state.hall_of_fame)]
        if state.last_fitness is not None and state.last_population is not None:
            order = np.lexsort((np.arange(len(state.last_fitness)), -state.last_fitness))
            for rank, i in enumerate(order[:top]):
                cands.append((f"final generation, rank {rank + 1}", state.last_population[i]))
        # identical genomes need one evaluation
        unique: list[tuple[str, np.ndarray]] = []
        seen: set[bytes] = set()
        for label, g in cands:
            key = np.ascontiguousarray(g).tobytes()
            if key not in seen:
                seen.add(key)
                unique.append((label, g))
        genes = np.array([g for _, g in unique])
        if c.validation_runs == 0:
            last = len(state.hall_of_fame) - 1
            return TrainResult(genes=state.hall_of_fame[last], validation_fitness=float("nan"),
                               validation_iterations_median=float("nan"),
                               validation_success_rate=float("nan"),
                               chosen_from=f"hall of fame, generation {last + 1}", state=state)
        seeds = validation_seeds(c.seed, c.validation_runs)
        if self.validator is not None:
            runs = self.validator(genes, seeds, self.on_chunk)
            fit = self._fitness(runs, held_out=True)
        else:
            runs = self.evaluator(genes, seeds, self.on_chunk)
            fit = self._fitness(runs)
        its = iterations_of(runs)
        best = int(np.lexsort((np.arange(len(fit)), -fit))[0])
        ok = (its[best] >= 0) & (its[best] < c.max_iter)
        return TrainResult(
            genes=genes[best], validation_fitness=float(fit[best]),
            validation_iterations_median=float(np.median(np.where(ok, its[best], c.max_iter))),
            validation_success_rate=float(ok.mean()), chosen_from=unique[best][0], state=state)


__all__ = ["GAConfig", "HISTORY_COLUMNS", "TrainResult", "TrainState", "Trainer", "breed",
           "generation_seeds", "initial_population", "new_state", "seed_genomes", "term_blocks",
           "validation_seeds"]
