"""Fitness evaluation: many individuals x many seeds x several scenarios, compiled end to end.

Why a dedicated kernel: a paper-scale generation is 400 individuals x 5 runs per scenario, and
each run is ~0.5-10 ms of compiled planning. Going through ``plan_fuzzy_rrt`` would parse nothing
(rulebooks are arrays already) but would still allocate a 10,000-node tree, build a
``PlanResult`` and copy the tree per run. :func:`run_population` instead takes the decoded
engine arrays of a whole chunk of individuals, allocates one tree, and calls the *same*
:func:`~xfuzzy_rrt.planners.fuzzy_rrt.fuzzy_rrt_kernel` the planner uses (so a trained rulebook
behaves in ``plan`` exactly as it did during training), resetting the tree between runs.
No Python runs per iteration or per run. For the paper's semantics,
:func:`~.memo.paper_population` does the same with the loop's pure per-node work remembered
(see :mod:`.memo`): identical iterations, tested run for run against :func:`run_population`.
Nothing is certified after a run: every edge of a found path was certified when the kernel
added it, and the fitness needs only the iteration count.

The reward of one run is the paper's: ``max_iter - x`` when a path was found after ``x <
max_iter`` iterations, else ``FAILURE_REWARD`` (-100). With the default ``max_iter = 10000`` this
is exactly ``10000 - x``. Fitness is the mean reward over every (scenario, seed) pair.
"""

from __future__ import annotations

from dataclasses import dataclass

import numba as nb
import numpy as np

from xfuzzy_rrt.fuzzy import semantics as _sem
from xfuzzy_rrt.planners.fuzzy_rrt import GOAL_FRAME, MIN_STEP_DEG, fuzzy_rrt_kernel
from xfuzzy_rrt.planners.goal_frame import goal_frame_kernel
from xfuzzy_rrt.planners.trace_record import make_trace
from xfuzzy_rrt.planners.tree import make_tree, reset_tree
from xfuzzy_rrt.training.memo import paper_population

FAILURE_REWARD = -100.0


@nb.njit(cache=True, nogil=True)
def run_population(P, T, knots_b, consts_b, bounds_mode, seeds, max_iter, min_step, stop, TR):
    """Iterations of every (individual, seed) run: int64[P, R], ``-1`` for a failed run.

    ``knots_b`` [P, n_out, 4, 5] and ``consts_b`` [P, n_out, 625] are decoded individuals;
    ``T`` is one preallocated tree (:func:`~xfuzzy_rrt.planners.tree.make_tree`), emptied
    before each run; ``TR`` 1-row trace buffers the kernels never touch (``record`` is off).
    ``bounds_mode`` is the integer the semantics' kernel takes (``Semantics.kernel_mode``;
    compiled code cannot take the semantics object, so the choice of loop stays this one
    integer test per run).
    """
    n_ind = knots_b.shape[0]
    n_seeds = seeds.shape[0]
    out = np.empty((n_ind, n_seeds), dtype=np.int64)
    meta0 = T.meta.copy()
    for p in range(n_ind):
        for r in range(n_seeds):
            reset_tree(T, meta0)
            if bounds_mode == GOAL_FRAME:
                ok, iterations, _ = goal_frame_kernel(
                    P, T, seeds[r], max_iter, knots_b[p], consts_b[p], bounds_mode, min_step,
                    stop, False, TR)
            else:
                ok, iterations, _ = fuzzy_rrt_kernel(
                    P, T, seeds[r], max_iter, knots_b[p], consts_b[p], bounds_mode, min_step,
                    stop, False, TR)
            out[p, r] = iterations if ok else -1
    return out


@dataclass(frozen=True)
class TrainingProblem:
    """One training scenario: its name and the compiled problem bundle the kernels take
    (``bundle``, a :class:`xfuzzy_rrt.geometry.problem.Problem`; picklable: sent once to each
    worker). ``groups``: fuzzy evaluations per iteration under the paper's semantics (one per
    arm). Named apart from the geometry ``Problem`` so one name means one thing."""

    name: str
    bundle: object
    groups: int = 1

    @property
    def limits(self) -> np.ndarray:
        return self.bundle.limits

    @property
    def dof(self) -> int:
        return int(self.bundle.start.shape[0])

    @classmethod
    def from_scenario(cls, scenario) -> "TrainingProblem":
        from xfuzzy_rrt.geometry.clearance import planning_margin
        from xfuzzy_rrt.planners.checks import check_dof

        check_dof(scenario)
        return cls(name=scenario.name, bundle=scenario.arrays().problem(planning_margin(scenario)),
                   groups=len(scenario.arms))


def iterations_for(problems: list[TrainingProblem], knots_b: np.ndarray, consts_b: np.ndarray,
                   bounds_mode: str, seeds: np.ndarray, max_iter: int) -> np.ndarray:
    """Iterations int64[P, S, R] (``-1`` = failed) of P individuals on S problems x R seeds.

    This is the unit of work a worker process or Dask task runs; the result depends only on its
    arguments, so splitting a population into chunks never changes any number. The paper's
    semantics runs through :func:`~.memo.paper_population` (the planner's loop with its pure
    per-node work remembered: the same numbers, about 30 % less CPU), the goal-frame one
    through :func:`run_population` (the planner's own kernel): the semantics that offers
    *bounds_mode* names its evaluation and its kernel mode
    (:attr:`~xfuzzy_rrt.fuzzy.semantics.Semantics.population`, ``modes``).
    """
    sem = _sem.of_mode(bounds_mode)
    mode = sem.kernel_mode(bounds_mode)
    population = _sem.resolve(sem.population)
    knots_b = np.ascontiguousarray(knots_b, dtype=np.float64)
    consts_b = np.ascontiguousarray(consts_b, dtype=np.float64)
    seeds = np.ascontiguousarray(seeds, dtype=np.int64)
    out = np.empty((knots_b.shape[0], len(problems), seeds.shape[0]), dtype=np.int64)
    for s, pr in enumerate(problems):
        tree = make_tree(int(max_iter) + 2, pr.limits)
        out[:, s, :] = population(pr, tree, knots_b, consts_b, mode, seeds, int(max_iter))
    return out


def kernel_population(pr: TrainingProblem, tree, knots_b, consts_b, mode: int, seeds,
                      max_iter: int) -> np.ndarray:
    """A population's iterations through the planner's own kernel (:func:`run_population`):
    the ``population`` of a semantics with no faster evaluation (goal-frame)."""
    buffers = make_trace(1, pr.dof, knots_b.shape[1], 1)
    return run_population(pr.bundle, tree, knots_b, consts_b, mode, seeds, int(max_iter),
                          MIN_STEP_DEG, np.zeros(1, dtype=np.int64), buffers)


def memo_population(pr: TrainingProblem, tree, knots_b, consts_b, mode: int, seeds,
                    max_iter: int) -> np.ndarray:
    """A population's iterations through :func:`~.memo.paper_population` (the paper's
    semantics: the planner's loop with its pure per-node work remembered)."""
    return paper_population(pr.bundle, tree, knots_b, consts_b, mode, seeds, int(max_iter),
                            MIN_STEP_DEG)


def rewards(iterations: np.ndarray, max_iter: int) -> np.ndarray:
    """The paper's reward per run: ``max_iter - x`` on success with ``x < max_iter``, else -100."""
    it = np.asarray(iterations)
    ok = (it >= 0) & (it < max_iter)
    return np.where(ok, float(max_iter) - it, FAILURE_REWARD)


def fitness(iterations: np.ndarray, max_iter: int) -> np.ndarray:
    """Mean reward over every (scenario, seed) of each individual: float64[P]."""
    r = rewards(iterations, max_iter)
    return r.reshape(r.shape[0], -1).mean(axis=1)


#: Fitness functions ``train --fitness`` offers.
FITNESSES = ("paper", "log-ratio")


def log_ratio_fitness(iterations: np.ndarray, baseline: np.ndarray, max_iter: int) -> np.ndarray:
    """Mean over problems and runs of ``log(baseline[s] / x)``: float64[P].

    ``iterations`` is int64[P, S, R] (``-1`` = failed, counted as ``max_iter``); ``baseline[s]``
    is RRT's median iterations on problem ``s`` (same seeds for every individual). Why a log
    ratio and not the paper's ``10000 - x``: the paper's reward is dominated by the few hardest
    problems (hundreds of iterations there outweigh a 5x gain on an easy one), so training with
    it lowers mean iterations while the *median* ratio to RRT falls. A log ratio weighs a
    halving of the iterations the same on every problem — the quantity the generalisation claim
    is about. ``0`` means "as fast as RRT"; ``log 3 ≈ 1.1`` means three times fewer iterations.
    """
    it = np.asarray(iterations, dtype=np.float64)
    x = np.where((it >= 0) & (it < max_iter), it, float(max_iter))
    b = np.asarray(baseline, dtype=np.float64)
    if it.ndim != 3 or b.shape != (it.shape[1],):
        raise ValueError(f"need iterations [P, S, R] and one baseline per problem, got "
                         f"{it.shape} and {b.shape}")
    r = np.log(b[None, :, None] / np.maximum(x, 1.0))
    return r.reshape(r.shape[0], -1).mean(axis=1)


def score(iterations: np.ndarray, kind: str, max_iter: int, baseline=None) -> np.ndarray:
    """Fitness of each individual under the fitness *kind* (one of :data:`FITNESSES`)."""
    if kind == "log-ratio":
        return log_ratio_fitness(iterations, baseline, max_iter)
    return fitness(iterations, max_iter)


def rrt_baseline(problems: list[TrainingProblem], seeds: np.ndarray, max_iter: int) -> np.ndarray:
    """RRT's median iterations per problem over *seeds* (failures count as ``max_iter``):
    the reference the log-ratio fitness divides by, computed once per training run."""
    from xfuzzy_rrt.planners.rrt import DEFAULT_GOAL_BIAS, DEFAULT_STEP_DEG, rrt_kernel

    out = np.empty(len(problems))
    for s, pr in enumerate(problems):
        tree = make_tree(int(max_iter) + 2, pr.limits)
        meta0 = tree.meta.copy()
        stop = np.zeros(1, dtype=np.int64)
        its = []
        for seed in seeds:
            reset_tree(tree, meta0)
            ok, x, _ = rrt_kernel(pr.bundle, tree, int(seed), int(max_iter), DEFAULT_STEP_DEG,
                                  DEFAULT_GOAL_BIAS, stop)
            its.append(x if ok else max_iter)
        out[s] = float(np.median(its))
    return out
