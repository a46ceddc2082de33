"""The training loop that remembers per-node work gives the planner kernel's numbers exactly.

:func:`xfuzzy_rrt.training.memo.paper_population` re-uses, within one run, the fuzzy outputs
of a node already visited, the goal's nearest node while the tree is unchanged, and a goal
extension that already added nothing. A trained rulebook must behave in ``plan`` exactly as it
did in training, so each (individual, seed) run must end at the same iteration, with the same
success, as :func:`xfuzzy_rrt.training.evaluate.run_population` (the planner's own kernel).
"""

from __future__ import annotations

import numpy as np
import pytest

from conftest import FIXTURES
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebooks_dir
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.fuzzy_rrt import BOUNDS_ABSOLUTE, BOUNDS_RELATIVE, MIN_STEP_DEG
from xfuzzy_rrt.planners.tree import make_tree
from xfuzzy_rrt.resources import paper_reference_scenario
from xfuzzy_rrt.training.evaluate import TrainingProblem, run_population
from xfuzzy_rrt.training.ga import GAConfig, generation_seeds, initial_population
from xfuzzy_rrt.training.genome import constant_genome, decode, encode
from xfuzzy_rrt.training.memo import paper_population

MAX_ITER = 2500


def _population(bounds: str, dof: int, n: int) -> np.ndarray:
    """A seeded first generation (perturbed RRT-like and goal-biased rulebooks, some of which
    get stuck against an obstacle), plus a goal-greedy constant rulebook (bias 0.9) that
    retries the same blocked goal extension from the same node."""
    cfg = GAConfig(population=n, bounds=bounds, dof=dof, scenarios=(("x", "-"),))
    pop = initial_population(cfg, np.random.default_rng(dof))
    pop[-1] = constant_genome(0.9, (-180.0, 180.0) * dof, 10.0)
    return pop


def _both(problem: TrainingProblem, genes: np.ndarray, bounds: str, dof: int, seeds):
    mode = BOUNDS_RELATIVE if bounds == "relative" else BOUNDS_ABSOLUTE
    knots, consts = decode(genes, bounds, dof)
    reference = run_population(problem.bundle, make_tree(MAX_ITER + 2, problem.limits), knots,
                               consts, mode, seeds, MAX_ITER, MIN_STEP_DEG,
                               np.zeros(1, dtype=np.int64))
    remembered = paper_population(problem.bundle, make_tree(MAX_ITER + 2, problem.limits),
                                  knots, consts, mode, seeds, MAX_ITER, MIN_STEP_DEG)
    return reference, remembered


@pytest.mark.parametrize("bounds", ["absolute", "relative"])
def test_remembered_runs_end_where_the_planner_kernel_ends_on_the_papers_problem(bounds):
    problem = TrainingProblem.from_scenario(load_scenario(paper_reference_scenario()))
    genes = _population(bounds, 2, 24)
    genes[1] = np.clip(encode(*load_rulebook(rulebooks_dir() / "paper").arrays()), 0, 1)
    reference, remembered = _both(problem, genes, bounds, 2, generation_seeds(0, 0, 3))
    assert (reference >= 0).any() and (reference < 0).any()  # successes and failures both
    np.testing.assert_array_equal(remembered, reference)


@pytest.mark.parametrize("arms,dof,bounds", [(1, 3, "relative"), (1, 3, "absolute"),
                                             (2, 2, "absolute")])
def test_remembered_runs_end_where_the_planner_kernel_ends_at_n_joints_and_arms(arms, dof,
                                                                                bounds):
    from xfuzzy_rrt.scenarios.generate import generate_nd

    scenario = generate_nd(31, 0, dof=dof, arms=arms).scenario
    problem = TrainingProblem.from_scenario(scenario)
    reference, remembered = _both(problem, _population(bounds, dof, 12), bounds, dof,
                                  generation_seeds(1, 0, 2))
    np.testing.assert_array_equal(remembered, reference)


def test_one_set_of_buffers_serves_many_runs_without_leaking_between_them():
    """Runs of a chunk share the memo buffers: a run's numbers must not depend on the runs
    before it in the chunk (evaluated alone, each gives the same)."""
    problem = TrainingProblem.from_scenario(load_scenario(FIXTURES / "scenarios" / "two-circles.toml"))
    genes = _population("absolute", 2, 12)[-6:]
    seeds = generation_seeds(2, 0, 3)
    knots, consts = decode(genes)
    together = paper_population(problem.bundle, make_tree(MAX_ITER + 2, problem.limits), knots,
                                consts, BOUNDS_ABSOLUTE, seeds, MAX_ITER, MIN_STEP_DEG)
    for p in range(len(genes)):
        for r in range(len(seeds)):
            alone = paper_population(problem.bundle, make_tree(MAX_ITER + 2, problem.limits),
                                     knots[p:p + 1], consts[p:p + 1], BOUNDS_ABSOLUTE,
                                     seeds[r:r + 1], MAX_ITER, MIN_STEP_DEG)
            assert alone[0, 0] == together[p, r]
