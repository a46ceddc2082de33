"""The planners hand their compiled kernels writable copies of a rulebook's arrays, and training
hands the same kernels the same types.

Why it matters: numba's dispatcher fingerprints a read-only array on every call (code that a
cold call fetches from memory), and types it apart from a writable one, so a read-only array
anywhere on these paths compiles every kernel under it a second time."""

from __future__ import annotations

from pathlib import Path

import numpy as np
import pytest
from numba.core import types

from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners import connect, fuzzy_rrt
from xfuzzy_rrt.planners.api import load_shipped_default, plan_scenario
from xfuzzy_rrt.training.evaluate import TrainingProblem, iterations_for

SCENARIO = Path(__file__).parent / "fixtures" / "scenarios" / "boxes-and-circle.toml"


def _read_only_arrays(dispatcher) -> list:
    """Every read-only array type in any signature *dispatcher* has compiled or loaded."""
    return [(sig, a) for sig in dispatcher.signatures for a in sig
            if isinstance(a, types.Array) and not a.mutable]


def test_the_kernel_arrays_are_writable_copies_made_once_and_the_public_ones_stay_read_only():
    rb = load_shipped_default().two_joint
    knots, consts = rb.kernel_arrays
    assert knots.flags.writeable and consts.flags.writeable
    assert rb.kernel_arrays[0] is knots and rb.kernel_arrays[1] is consts
    public = rb.compiled
    assert not public[0].flags.writeable and not public[1].flags.writeable
    assert not np.shares_memory(knots, public[0]) and not np.shares_memory(consts, public[1])
    np.testing.assert_array_equal(knots, public[0])
    np.testing.assert_array_equal(consts, public[1])


@pytest.mark.parametrize("planner, traced, untraced", [
    ("fuzzy-rrt", fuzzy_rrt.goal_frame_entry, fuzzy_rrt.goal_frame_untraced),
    ("fuzzy-rrt-connect", connect.connect_entry, connect.connect_untraced),
])
@pytest.mark.parametrize("trace", [False, True])
def test_a_plan_compiles_its_entry_for_writable_arrays_only(planner, traced, untraced, trace):
    """(An untraced plan runs the entry's twin that takes no trace argument, since numba
    fingerprints a ``None`` argument as it does a read-only array.)"""
    entry = traced if trace else untraced
    scenario = load_scenario(SCENARIO)
    assert plan_scenario(scenario, planner, seed=0, trace=trace).success
    assert entry.signatures, "the plan ran this entry"
    assert _read_only_arrays(entry) == []
    if not trace:
        assert all(not isinstance(a, types.NoneType) for sig in entry.signatures for a in sig)


@pytest.mark.parametrize("semantics, planner, rulebook, population", [
    ("goal-frame", "fuzzy-rrt", "two_joint", "run_population_measured"),
    ("goal-frame-any", "fuzzy-rrt-connect", "any_arm", "connect_population_measured"),
])
def test_training_hands_the_kernels_writable_arrays_even_from_a_read_only_rulebook(
        semantics, planner, rulebook, population):
    """The population entry is what Python calls (its signatures are recorded whether it was
    compiled or loaded from the cache); it passes each individual's slice of these arrays to
    the planner's kernel, so writable here means the kernel the planner compiled."""
    from xfuzzy_rrt.training import evaluate

    scenario = load_scenario(SCENARIO)
    rb = getattr(load_shipped_default(), rulebook)
    knots, consts = rb.compiled  # read-only, as a loaded rulebook's
    out = iterations_for([TrainingProblem.from_scenario(scenario)], knots[None], consts[None],
                         semantics, np.arange(2, dtype=np.int64), 2000, measure="work")
    assert out.shape == (1, 1, 2, 2) and (out[..., 0] > 0).all()
    entry = getattr(evaluate, population)
    assert entry.signatures, "training ran this population entry"
    assert _read_only_arrays(entry) == []
    # and the same numbers as planning each seed with that rulebook
    for seed in range(2):
        plan = plan_scenario(scenario, planner, rulebook=rb, seed=seed, max_iter=2000)
        assert (out[0, 0, seed, 0], out[0, 0, seed, 1]) == (plan.iterations, plan.work)
