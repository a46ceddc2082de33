"""A whole training job: scenarios in, rulebook directory + history + checkpoints out.

Output layout of ``--out DIR``::

    DIR/rulebook.toml, DIR/<output>.fis   the trained rulebook (written at the end)
    DIR/history.csv                       one row per generation (rewritten atomically each one)
    DIR/checkpoint/state.npz              the latest checkpoint (see .checkpoint)

Everything in the rulebook — the fuzzy systems (six at 2 DOF) *and* the manifest — depends only on the training
inputs (scenario files, seed rulebooks, options, ``--seed``), never on the worker count, the
engine or an interruption: the manifest records a canonical command line rebuilt from the
options (not the literal argv, which would differ with ``--workers`` or ``--resume``), the
SHA-256 of every input file, the versions of the libraries the numbers depend on, and no
wall-clock time.
``history.csv``'s ``wall_s`` and ``runs_per_s`` columns are the only measured (non-reproducible)
numbers a training run writes.
"""

from __future__ import annotations

import contextlib
import hashlib
import shlex
from dataclasses import dataclass, field
from pathlib import Path
from typing import Callable


from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.manifest import BOUNDS_MODES
from xfuzzy_rrt.fuzzy.semantics import of_mode
from xfuzzy_rrt.training.ga import HISTORY_COLUMNS, GAConfig, Trainer, TrainResult, new_state

CHECKPOINT_DIR = "checkpoint"
#: RRT runs per scenario (seeds 0..49) behind the log-ratio fitness's baseline.
BASELINE_RUNS = 50
HISTORY_FILE = "history.csv"
#: The seed rulebook of ``--init seeded`` when no ``--seed-rulebook`` is given (shipped).
DEFAULT_SEED_RULEBOOK = "expert"
#: What a default seed rulebook is recorded as (``source``) in the manifest.
PACKAGED = "packaged"
#: Libraries whose versions a byte-exact rebuild of a trained rulebook depends on.
VERSIONED = ("numpy", "numba", "pymoo", "scipy")


@dataclass(frozen=True)
class TrainingScenario:
    path: str  # as given (relative paths stay relative, for a reproducible command)
    sha256: str
    scenario: object


def expand_scenarios(paths: list[Path]) -> list[Path]:
    """Files as given; a directory means every ``*.toml`` in it (sorted)."""
    out: list[Path] = []
    for p in paths:
        p = Path(p)
        if p.is_dir():
            found = sorted(p.glob("*.toml"))
            if not found:
                raise InputError(str(p), "directory holds no *.toml scenario files")
            out.extend(found)
        else:
            out.append(p)
    if not out:
        raise InputError("--scenario", "give at least one training scenario (file or directory)")
    return out


def scenario_dof(scenario, bounds: str) -> int:
    """The rulebook DOF a training *scenario* asks for under *bounds*.

    The paper's semantics decides one arm's box (two bounds per joint), so its DOF is the
    per-arm DOF, and every arm of the scenario must have it. The goal-frame semantics works in
    the joint space of all arms together, so its DOF is the total (``scenario.dof``).
    """
    where = scenario.source or scenario.name
    if not of_mode(bounds).per_arm:  # the semantics reads the joints of all arms together
        return int(scenario.dof)
    dofs = [int(a.dof) for a in scenario.arms]
    if len(set(dofs)) != 1:
        raise InputError(str(where), f"arms: a paper-semantics rulebook gives every arm the same "
                         f"box, but the arms have {', '.join(map(str, dofs))} joints (use "
                         f"--bounds goal-frame, or arms of one DOF)")
    return dofs[0]


def training_dof(scenarios, bounds: str, dof: int | None = None) -> int:
    """The DOF to train: that of the scenarios (which must agree), or ``--dof`` (which must
    agree with them). *scenarios* are :class:`TrainingScenario` or scenario objects. A DOF-free
    semantics (``goal-frame-any``) takes scenarios of any DOF and no ``--dof``; its semantics
    object says 2, which is what this returns for it.

    Raises :class:`InputError` (one line) for scenarios of different DOF or a ``--dof`` that
    disagrees with them, naming a file of each DOF.
    """
    from xfuzzy_rrt.fuzzy import semantics as _sem

    sem = _sem.of_mode(bounds)
    if sem.dof_free:  # one rulebook for every arm: scenarios of any DOF train it together
        if dof is not None:
            raise InputError("--dof", f"a {sem.name} rulebook plans any number of joints; "
                             "train it without --dof")
        for t in scenarios:
            s = getattr(t, "scenario", t)
            problem = _sem.dof_problem(int(s.dof)) if len(s.arms) == 1 else None
            if problem:
                raise InputError(str(getattr(t, "path", None) or s.source or s.name),
                                 f"no rulebook for this arm: {problem}")
        return _sem.DEFAULT_DOF
    if dof is not None:
        problem = _sem.dof_problem(dof)
        if problem:
            raise InputError("--dof", problem)
    found: dict[int, str] = {}
    for t in scenarios:
        s = getattr(t, "scenario", t)
        d = scenario_dof(s, bounds)
        found.setdefault(d, str(getattr(t, "path", None) or s.source or s.name))
    what = "joints per arm" if _sem.of_mode(bounds).per_arm else "joints in all"
    if len(found) > 1:
        listed = "; ".join(f"{f} has {d}" for d, f in sorted(found.items()))
        raise InputError("--scenario", f"training scenarios of different DOF ({what}): {listed}; "
                         "train one DOF at a time")
    if not found:
        return dof if dof is not None else _sem.DEFAULT_DOF
    (have, file), = found.items()
    if dof is not None and dof != have:
        raise InputError("--dof", f"{dof} disagrees with the training scenarios ({file} has "
                         f"{have} {what})")
    problem = _sem.dof_problem(have)
    if problem:
        raise InputError(file, f"no rulebook for this arm: {problem}")
    return have


def load_training_scenarios(paths: list[Path]) -> list[TrainingScenario]:
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.planners.checks import check_dof

    items = []
    for p in expand_scenarios(paths):
        s = load_scenario(p)
        check_dof(s)
        items.append(TrainingScenario(path=str(p), sha256=hashlib.sha256(p.read_bytes()).hexdigest(),
                                      scenario=s))
    names = [t.scenario.name for t in items]
    if len(set(names)) != len(names):
        dup = sorted({n for n in names if names.count(n) > 1})[0]
        raise InputError("--scenario", f"two training scenarios share the name {dup!r}")
    return items


@dataclass(frozen=True)
class SeedRulebook:
    """A rulebook the seeded first generation starts from, and where it came from."""

    source: str  # the --seed-rulebook value as given, or PACKAGED for the default
    rulebook: object

    @property
    def sha256(self) -> str:
        return self.rulebook.sha256


def default_seed_rulebook(dof: int = 2) -> str:
    """Name of the shipped seed rulebook at *dof* joints: ``expert``, or ``expert-5dof``."""
    return DEFAULT_SEED_RULEBOOK if dof == 2 else f"{DEFAULT_SEED_RULEBOOK}-{dof}dof"


def resolve_seed_rulebooks(paths: list[Path] | None, init: str, bounds: str,
                           dof: int = 2) -> list[SeedRulebook]:
    """The seed rulebooks of a training run, loaded and checked.

    ``paths`` are the ``--seed-rulebook`` values (``None``: not given). Under ``--init
    seeded`` the default is the shipped ``expert`` rulebook when it means its bounds as
    ``bounds`` (none otherwise: the paper's absolute setting starts from the built-in genomes
    alone); a missing default or a given seed that does not exist, does not load or has the
    other bounds meaning is an error, never silently dropped (the first generation would
    change under the same recorded command). At another DOF the default is the shipped
    ``expert-<N>dof`` when there is one (:func:`default_seed_rulebook`), else none: the
    built-in genomes alone, which exist at every DOF. A given seed of another DOF is an error.
    """
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebooks_dir

    if init != "seeded":
        if paths:
            raise InputError("--seed-rulebook", "seed rulebooks are only used with --init seeded")
        return []
    if not paths:
        folder = rulebooks_dir() / default_seed_rulebook(dof)
        if not folder.is_dir():
            if dof != 2:
                return []
            raise InputError(str(folder), f"the default seed rulebook {DEFAULT_SEED_RULEBOOK!r} "
                             "is missing; pass --seed-rulebook DIR or --init random")
        rb = load_rulebook(folder)
        return [SeedRulebook(PACKAGED, rb)] if rb.bounds_mode == bounds and rb.dof == dof else []
    out = []
    for p in paths:
        rb = load_rulebook(p)  # a missing or broken folder is the usual one-line error
        want = of_mode(bounds)  # the semantics --bounds trains
        if want.dof_free and rb.dof != dof:  # the 2-DOF semantics object: see training_dof
            raise InputError(str(p), f"seed rulebook is for dof {rb.dof}; a {want.name} "
                             f"training is seeded by {want.name} rulebooks or 2-joint "
                             f"{' or '.join(want.seeded_by)} ones")
        if rb.dof != dof:
            raise InputError(str(p), f"seed rulebook is for dof {rb.dof}, the training for dof "
                             f"{dof}")
        if bounds not in BOUNDS_MODES:  # a semantics without the paper's bounds modes
            if not want.can_seed_from(rb.semantics.name):
                raise InputError(str(p), f"seed rulebook is not a {want.name} rulebook, but "
                                 f"--bounds is {bounds}")
        elif rb.semantics.name != want.name or rb.bounds_mode != bounds:
            raise InputError(str(p), f"seed rulebook has {rb.bounds_mode} bounds, but "
                             f"--bounds is {bounds}")
        out.append(SeedRulebook(str(p), rb))
    return out


def library_versions() -> dict[str, str]:
    """Python and the libraries whose versions the byte-exact result depends on."""
    import platform
    from importlib import metadata

    out = {"python": platform.python_version()}
    for dist in VERSIONED:
        try:
            out[dist] = metadata.version(dist)
        except metadata.PackageNotFoundError:
            out[dist] = "not installed"
    return out


def canonical_command(config: GAConfig, scenario_args: list[str], out: str,
                      seed_args: list[str] | None = None,
                      validation_args: list[str] = ()) -> str:
    """The command that reproduces this training run (independent of workers and engine).

    ``scenario_args`` are the ``--scenario`` values as given (a folder stays a folder; the
    manifest lists every file it held with its SHA-256); ``seed_args`` the ``--seed-rulebook``
    values as given (none for the packaged default; the manifest records its SHA-256).
    """
    args = ["xfuzzy-rrt", "train"]
    for a in scenario_args:
        args += ["--scenario", a]
    for a in seed_args or []:
        args += ["--seed-rulebook", a]
    defaults = GAConfig(scenarios=(("x", "y"),))
    options = [("population", "--population"), ("generations", "--generations"),
               ("runs_per_eval", "--runs-per-eval"), ("target_fitness", "--target-fitness"),
               ("seed", "--seed"), ("bounds", "--bounds"), ("max_iter", "--max-iter"),
               ("elite", "--elite"), ("tournament", "--tournament"),
               ("crossover_prob", "--crossover-prob"), ("crossover_eta", "--crossover-eta"),
               ("mutation_rate", "--mutation-rate"), ("mutation_eta", "--mutation-eta"),
               ("block_rate", "--block-rate"), ("block_sigma", "--block-sigma"),
               ("init", "--init"), ("validation_runs", "--validation-runs"),
               ("fitness", "--fitness"), ("cost_weight", "--cost-weight"),
               ("clearance_m", "--clearance"), ("dof", "--dof")]
    always = {"population", "generations", "runs_per_eval", "target_fitness", "seed", "bounds"}
    for attr, flag in options:
        value = getattr(config, attr)
        if attr in always or value != getattr(defaults, attr):
            args += [flag, f"{value:g}" if isinstance(value, float) else str(value)]
    for a in validation_args:
        args += ["--validation-scenario", a]
    args += ["--out", out]
    return " ".join(shlex.quote(a) for a in args)


def baselines(scenarios: list[TrainingScenario], max_iter: int,
              fitness: str = "log-ratio") -> tuple[float, ...]:
    """The fitness's reference on each scenario over seeds ``0..BASELINE_RUNS-1``: RRT's
    median iterations (``log-ratio``) or the tuned RRT's median work (``work-cvar``)."""
    import numpy as np

    from xfuzzy_rrt.training.evaluate import TrainingProblem, rrt_baseline, tuned_rrt_baseline

    problems = [TrainingProblem.from_scenario(t.scenario) for t in scenarios]
    reference = rrt_baseline if fitness == "log-ratio" else tuned_rrt_baseline
    return tuple(float(b) for b in reference(problems, np.arange(BASELINE_RUNS), max_iter))


def work_and_cost_baselines(scenarios: list[TrainingScenario], max_iter: int
                            ) -> tuple[tuple[float, ...], tuple[float, ...]]:
    """``work-cost-cvar``'s references from one set of the tuned RRT's runs per scenario (seeds
    ``0..BASELINE_RUNS-1``): its median work (as :func:`baselines` gives for ``work-cvar``)
    and its median path cost in degrees. A scenario on which it found no path is one line
    naming it (no reference to measure lengths against)."""
    import numpy as np

    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.training.evaluate import TrainingProblem, tuned_rrt_baselines

    problems = [TrainingProblem.from_scenario(t.scenario) for t in scenarios]
    work, costs = tuned_rrt_baselines(problems, np.arange(BASELINE_RUNS), max_iter,
                                      "work-cost-cvar")
    for t, c in zip(scenarios, costs):
        if c == 0.0:  # every path of length zero: the start is the goal
            raise InputError(t.path, "the tuned RRT's paths have length zero (the start is the "
                             "goal), so work-cost-cvar has no path cost to compare with: leave "
                             "this scenario out")
        if not (np.isfinite(c) and c > 0):
            raise InputError(t.path, f"the tuned RRT found no path in {BASELINE_RUNS} runs of "
                             f"{max_iter} iterations, so work-cost-cvar has no path cost to "
                             "compare with: leave this scenario out or raise --max-iter")
    return tuple(float(w) for w in work), tuple(float(c) for c in costs)


def history_frame(history: list[dict]):
    """One row per generation; ``validation_fitness`` only when the run has held-out scenarios
    (a run without them writes exactly the columns it always did)."""
    import pandas as pd

    held_out = any("validation_fitness" in row for row in history)
    return pd.DataFrame(history, columns=[c for c in HISTORY_COLUMNS
                                          if c != "validation_fitness" or held_out])


def write_history(path: Path, history: list[dict]) -> None:
    from xfuzzy_rrt.atomic import atomic_path

    with atomic_path(path) as tmp:
        history_frame(history).to_csv(tmp, index=False, float_format="%.10g")


@dataclass
class TrainJob:
    """Options of one ``xfuzzy-rrt train`` invocation, resolved and validated."""

    config: GAConfig
    scenarios: list[TrainingScenario]
    out: Path
    scenario_args: list[str] = field(default_factory=list)  # --scenario values as given
    validation: list[TrainingScenario] = field(default_factory=list)  # held-out scenarios
    validation_args: list[str] = field(default_factory=list)
    #: the seed rulebooks (see resolve_seed_rulebooks); must match config.seed_rulebooks
    seed_rulebooks: list[SeedRulebook] = field(default_factory=list)
    resume: bool = False
    workers: int | None = None
    scheduler: str | None = None
    name: str | None = None
    extra_provenance: dict = field(default_factory=dict)

    @property
    def checkpoint_dir(self) -> Path:
        return self.out / CHECKPOINT_DIR

    def check_out(self) -> None:
        """Refuse bad engine options and clobbering another run (a checkpoint needs --resume)."""
        from xfuzzy_rrt.training.checkpoint import checkpoint_file

        if self.workers is not None and self.workers < 1:
            raise InputError("--workers", f"must be >= 1, got {self.workers}")
        if self.out.exists() and not self.out.is_dir():
            raise InputError(str(self.out), "exists and is not a directory")
        has = checkpoint_file(self.checkpoint_dir).exists()
        if has and not self.resume:
            raise InputError(str(self.checkpoint_dir), "a training checkpoint is already here; "
                             "pass --resume to continue it or choose another --out")


def run_training(job: TrainJob,
                 on_start: Callable[[str, int], None] | None = None,
                 on_generation: Callable[[dict], None] | None = None,
                 on_chunk: Callable[[int, int], None] | None = None,
                 on_phase: Callable[[str], None] | None = None) -> TrainResult:
    """Train (or resume), checkpointing every generation; write the rulebook at the end."""
    from xfuzzy_rrt.training.checkpoint import load_checkpoint, save_checkpoint
    from xfuzzy_rrt.training.evaluate import TrainingProblem, measure_of
    from xfuzzy_rrt.training.workers import make_evaluator

    job.check_out()
    config = job.config
    if job.resume:
        state = load_checkpoint(job.checkpoint_dir, config)
    else:
        state = new_state(config, [s.rulebook for s in job.seed_rulebooks])
    problems = [TrainingProblem.from_scenario(t.scenario) for t in job.scenarios]
    held_out = [TrainingProblem.from_scenario(t.scenario) for t in job.validation]
    history_path = job.out / HISTORY_FILE

    def checkpoint(row: dict, new) -> None:
        save_checkpoint(job.checkpoint_dir, new, config)
        write_history(history_path, new.history)
        if on_generation:
            on_generation(row)

    measure = measure_of(config.fitness)
    # the engines first: a bad --scheduler or --workers fails before any folder is made
    with contextlib.ExitStack() as stack:
        evaluator = stack.enter_context(make_evaluator(problems, config.bounds, config.max_iter,
                                                       job.workers, job.scheduler,
                                                       dof=config.dof, measure=measure))
        validator = None
        if held_out:
            validator = stack.enter_context(make_evaluator(held_out, config.bounds,
                                                           config.max_iter, job.workers,
                                                           job.scheduler, dof=config.dof,
                                                           measure=measure))
        job.out.mkdir(parents=True, exist_ok=True)
        _remove_stale_temporaries(job)
        if on_start:
            on_start(evaluator.description, state.generation)
        if state.history:
            write_history(history_path, state.history)
        # compile and start the workers before generation 1 is timed (its runs/s)
        for engine in (evaluator, validator):
            if engine is not None and hasattr(engine, "warm_up") and len(state.population):
                engine.warm_up(state.population[:1])
        trainer = Trainer(config, evaluator, on_generation=checkpoint, on_chunk=on_chunk,
                          validator=validator)
        state = trainer.run(state)
        if on_phase:
            where = (f"{len(held_out)} held-out validation scenarios" if held_out
                     else "the training scenarios (fresh seeds)")
            on_phase(f"choosing the rulebook: {config.validation_runs} runs per scenario on "
                     f"{where} for each generation's best and the final top 5")
        result = trainer.choose(state)
    write_trained_rulebook(job, result)
    return result


def _remove_stale_temporaries(job: TrainJob) -> None:
    """Delete temporary files a killed run left beside its outputs (``kill -9`` skips the
    clean-up of an atomic write; the real files are always complete)."""
    for folder in (job.out, job.checkpoint_dir):
        if folder.is_dir():
            for tmp in folder.glob(".*.tmp"):
                tmp.unlink(missing_ok=True)


def write_trained_rulebook(job: TrainJob, result: TrainResult) -> Path:
    from xfuzzy_rrt import __version__
    from xfuzzy_rrt.fuzzy.rulebook import Rulebook, save_rulebook
    from xfuzzy_rrt.training.genome import decode

    c = job.config
    from xfuzzy_rrt.training.genome import semantics_of_mode

    knots, consts = decode(result.genes, c.bounds, c.dof)
    history = result.state.history
    name = job.name or job.out.name or "trained"
    sem = semantics_of_mode(c.bounds, c.dof)
    provenance = {
        "kind": "ga",
        "command": canonical_command(c, job.scenario_args or [t.path for t in job.scenarios],
                                     str(job.out), [s.source for s in job.seed_rulebooks
                                                    if s.source != PACKAGED], job.validation_args),
        "algorithm": "generational GA: tournament selection, SBX crossover, polynomial and "
                     "term-block mutation, elitism (xfuzzy_rrt.training)",
        "package_version": __version__,
        "seed": c.seed,
        "population": c.population,
        "generations_max": c.generations,
        "generations_run": len(history),
        "runs_per_eval": c.runs_per_eval,
        "target_fitness": c.target_fitness,
        "max_iter": c.max_iter,
        "init": c.init,
        "final_best_fitness": history[-1]["best_fitness"],
        "final_mean_fitness": history[-1]["mean_fitness"],
        "chosen_from": result.chosen_from,
        "validation_runs_per_scenario": c.validation_runs,
        "validation_fitness": result.validation_fitness,
        "validation_median_iterations": result.validation_iterations_median,
        "validation_success_rate": result.validation_success_rate,
        "history": HISTORY_FILE,
        "fitness": c.fitness,
        **({"clearance_m": c.clearance_m} if c.clearance_m is not None else {}),
        **({"dof": c.dof} if c.dof != 2 else {}),  # 2-DOF manifests keep their bytes
        "scenarios": [{"name": t.scenario.name, "file": t.path, "sha256": t.sha256}
                      for t in job.scenarios],
        "seed_rulebooks": [{"name": s.rulebook.name, "source": s.source, "sha256": s.sha256}
                           for s in job.seed_rulebooks],
        "versions": library_versions(),
        **job.extra_provenance,
    }
    if c.fitness == "log-ratio":
        provenance["baseline"] = ("RRT median iterations per training scenario (seeds 0.."
                                  f"{BASELINE_RUNS - 1}, step 10 deg, goal bias 0.05)")
        provenance["baseline_iterations"] = [float(b) for b in c.baseline]
    if c.fitness in ("work-cvar", "work-cost-cvar"):
        from xfuzzy_rrt.planners.tuned import describe_tuned_rrt, shape_of

        shapes = [shape_of(t.scenario) for t in job.scenarios]
        provenance["baseline"] = (f"rrt:tuned (data/tuned/rrt*.toml: "
                                  f"{describe_tuned_rrt(shapes, degree=' deg')}) median work per "
                                  f"training scenario (seeds 0..{BASELINE_RUNS - 1})")
        provenance["baseline_work"] = [float(b) for b in c.baseline]
    if c.fitness == "work-cost-cvar":
        provenance["cost_weight"] = c.cost_weight
        provenance["baseline_cost_deg"] = [float(b) for b in c.baseline_cost]
    if job.validation:
        provenance["validation_fitness_history"] = [float(r["validation_fitness"]) for r in history]
        provenance["validation_scenarios"] = [
            {"name": t.scenario.name, "file": t.path, "sha256": t.sha256} for t in job.validation]
        if c.fitness == "log-ratio":
            provenance["validation_baseline_iterations"] = [float(b) for b in c.validation_baseline]
        if c.fitness in ("work-cvar", "work-cost-cvar"):
            provenance["validation_baseline_work"] = [float(b) for b in c.validation_baseline]
        if c.fitness == "work-cost-cvar":
            provenance["validation_baseline_cost_deg"] = [float(b) for b in
                                                          c.validation_baseline_cost]
    bounds_mode = c.bounds if c.bounds in BOUNDS_MODES else None  # only the paper's has one
    what = f"{c.bounds} bounds" if bounds_mode else f"{sem.name} semantics"
    description = (f"Trained by the genetic algorithm ({what}, {c.fitness} fitness) on "
                   f"{len(job.scenarios)} scenario(s); see [provenance].")
    rb = Rulebook.from_arrays(knots[0], consts[0], name=name, bounds_mode=bounds_mode,
                              provenance=provenance, description=description, semantics=sem)
    return save_rulebook(rb, job.out)


__all__ = ["SeedRulebook", "TrainJob", "TrainingScenario", "canonical_command",
           "default_seed_rulebook", "expand_scenarios", "scenario_dof", "training_dof", "history_frame", "library_versions", "load_training_scenarios",
           "resolve_seed_rulebooks", "run_training"]
