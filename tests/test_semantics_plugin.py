"""Semantics as plug-ins: a semantics carries its kernel, its training evaluation and (through
its names and ``per_arm``) its genome layout and trace columns; the planner and the trainer
look them up instead of switching on integer modes.

A toy semantics (the paper's, with its inputs renamed and its own training mode) is
registered by a fixture without touching any planner, and removed afterwards.
"""

from __future__ import annotations

from dataclasses import replace
from types import MappingProxyType, SimpleNamespace

import numpy as np
import pytest

from xfuzzy_rrt.fuzzy import semantics as sem
from xfuzzy_rrt.planners import fuzzy_rrt
from xfuzzy_rrt.training import evaluate, genome
from xfuzzy_rrt.training.evaluate import TrainingProblem, iterations_for, memo_population

CALLS: list[int] = []
TWIN_MODE = 7


def twin_population(pr, tree, knots_b, consts_b, mode, seeds, max_iter):
    """The paper's evaluation (absolute bounds), counting that the trainer came here."""
    CALLS.append(mode)
    return memo_population(pr, tree, knots_b, consts_b, fuzzy_rrt.BOUNDS_ABSOLUTE, seeds,
                           max_iter)


@pytest.fixture
def twin():
    names = {n: f"twin_{n}" for n in sem.PAPER.inputs}
    ren = lambda m: MappingProxyType({names.get(k, k): v for k, v in m.items()})  # noqa: E731
    toy = replace(sem.PAPER, name="twin", inputs=tuple(names.values()),
                  input_ranges=ren(sem.PAPER.input_ranges), units=ren(sem.PAPER.units),
                  default_terms=ren(sem.PAPER.default_terms),
                  default_peaks=ren(sem.PAPER.default_peaks),
                  modes=MappingProxyType({"twin": TWIN_MODE}), population=twin_population)
    sem.register(toy)
    CALLS.clear()
    try:
        yield toy
    finally:
        sem.unregister("twin")
        fuzzy_rrt._ENTRIES.pop(TWIN_MODE, None)
        fuzzy_rrt._UNTRACED.pop(TWIN_MODE, None)
    assert "twin" not in sem.SEMANTICS and "twin_dist_to_goal" not in sem.ALL_INPUT_RANGES


def test_a_registered_semantics_trains_through_its_own_evaluation(twin):
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.resources import paper_reference_scenario

    assert genome.n_genes("twin") == genome.n_genes("absolute")
    genes = genome.constant_outputs_genome((0.05, -180, 180, -180, 180, 10), "twin")
    knots, consts = genome.decode(genes, "twin")
    problems = [TrainingProblem.from_scenario(load_scenario(paper_reference_scenario()))]
    seeds = np.arange(3, dtype=np.int64)
    mine = iterations_for(problems, knots, consts, "twin", seeds, 400)
    assert CALLS == [TWIN_MODE]  # its evaluation, with its kernel mode
    paper = iterations_for(problems, *genome.decode(genes, "absolute"), "absolute", seeds, 400)
    np.testing.assert_array_equal(mine, paper)


def test_the_planner_takes_kernel_and_fis_groups_from_the_semantics(twin):
    rb = SimpleNamespace(semantics=twin, bounds_mode=None)
    two_arms = SimpleNamespace(arms=[object(), object()])
    assert fuzzy_rrt.kernel_mode(rb) == TWIN_MODE
    assert fuzzy_rrt.entry_for(TWIN_MODE) is fuzzy_rrt.fuzzy_rrt_entry  # its declared kernel
    assert fuzzy_rrt.untraced_for(TWIN_MODE) is fuzzy_rrt.fuzzy_rrt_untraced  # and its twin
    assert fuzzy_rrt.fis_groups(rb, two_arms) == 2  # one per arm, like the paper's
    assert sem.of_columns(["twin_angle_to_goal", "goal_bias"]) is twin


def test_a_semantics_without_an_untraced_entry_gets_its_kernel_called_with_no_trace(twin):
    calls = []

    def kernel(*args):
        calls.append(args)
        return "finished"

    sem.unregister("twin")
    sem.register(replace(twin, kernel=kernel, untraced=None))
    assert fuzzy_rrt.untraced_for(TWIN_MODE)(1, 2, 3) == "finished"
    assert calls == [(1, 2, 3, None)]


def test_the_builtin_semantics_declare_the_kernels_integers():
    assert dict(sem.PAPER.modes) == {"absolute": fuzzy_rrt.BOUNDS_ABSOLUTE,
                                     "relative": fuzzy_rrt.BOUNDS_RELATIVE}
    assert dict(sem.GOAL_FRAME.modes) == {"goal-frame": fuzzy_rrt.GOAL_FRAME}
    assert sem.resolve(sem.PAPER.kernel) is fuzzy_rrt.fuzzy_rrt_entry
    assert sem.resolve(sem.GOAL_FRAME.kernel) is fuzzy_rrt.goal_frame_entry
    assert sem.resolve(sem.PAPER.untraced) is fuzzy_rrt.fuzzy_rrt_untraced
    assert sem.resolve(sem.GOAL_FRAME.untraced) is fuzzy_rrt.goal_frame_untraced
    assert genome.MODES == ("absolute", "relative", "goal-frame", "goal-frame-any")
    for s in (sem.PAPER, sem.GOAL_FRAME):
        for dof in range(sem.MIN_DOF, sem.MAX_DOF + 1):  # the plug-in survives for_dof
            at = s.for_dof(dof)
            assert (at.modes, at.kernel, at.population, at.per_arm) == \
                (s.modes, s.kernel, s.population, s.per_arm)
    # trained with the planner that runs it; Fuzzy-RRT has no kernel for it
    any_ = sem.GOAL_FRAME_ANY
    assert dict(any_.modes) == {"goal-frame-any": 3} and any_.kernel is None
    assert any_.planner == "fuzzy-rrt-connect" and "work" in any_.measures
    assert sem.resolve(any_.population) is evaluate.connect_population
    assert all(any_.for_dof(dof) is any_ for dof in range(sem.MIN_DOF, sem.MAX_DOF + 1))


def test_a_semantics_cannot_take_another_ones_inputs_or_modes():
    with pytest.raises(ValueError, match="input names must be unique"):
        sem.register(replace(sem.PAPER, name="copy"))
    with pytest.raises(ValueError, match="already registered"):
        sem.register(sem.GOAL_FRAME)
