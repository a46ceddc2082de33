"""The RRT baseline (LaValle, "Rapidly-exploring random trees: a new tool for path planning",
TR 98-11, Iowa State University, 1998), compiled with numba.

Per iteration: draw a sample (the goal with probability ``goal_bias``, else uniform in the joint
limits), find the nearest tree node, steer towards the sample by at most ``step_deg``, reject
the new node if it is in collision or the edge to it is not certified free, else add it; stop
when the new node *is* the goal or when the goal is within one step and that edge is free. The
bookkeeping is the one of the paper's Algorithm 1, so ``iterations`` means the same for RRT and
Fuzzy-RRT: every sample counts, accepted or not.
"""

from __future__ import annotations

import time
from typing import Any, NamedTuple

import numba as nb
import numpy as np

from xfuzzy_rrt.geometry.scenario import Scenario
from xfuzzy_rrt.planners.checks import check_plan_call
from xfuzzy_rrt.planners.extend import extend, join_start_at_goal
from xfuzzy_rrt.planners.params import default
from xfuzzy_rrt.planners.result import (GOAL_REACHED, PlanResult, bound_result,
                                       finished_tree, planner_template)
from xfuzzy_rrt.planners.rng import seed_state, uniform
from xfuzzy_rrt.planners.termination import NEVER_STOPPED, StopFlag, stopped_by
from xfuzzy_rrt.planners.prepared import pooled_tree, scenario_arrays
from xfuzzy_rrt.planners.problem_arena import make_problem_arena, problem_in
from xfuzzy_rrt.planners.setup_memo import set_up
from xfuzzy_rrt.planners.tree import add_node, nearest
from xfuzzy_rrt.planners.tree_arena import emptied_tree_in

DEFAULT_STEP_DEG = default("rrt", "step_deg")
DEFAULT_GOAL_BIAS = default("rrt", "goal_bias")
DEFAULT_MAX_ITER = default("rrt", "max_iter")


@nb.njit(cache=True, nogil=True, _nrt=True)
def rrt_kernel(P, T, seed, max_iter, step, goal_bias, stop):
    """Run RRT on problem ``P`` growing tree ``T``; return ``(success, iterations, index of the
    last path node or -1)``. ``stop[0] != 0`` (a wall-clock budget ran out) ends the run."""
    dof = P.start.shape[0]
    # an uncounted loop (README, "No reference counting in the loops") borrows these buffers
    return _rrt_loop(P, T, seed, max_iter, step, goal_bias, stop,
                     np.empty(4, dtype=np.uint64), np.empty(dof, dtype=np.float64),
                     np.empty(dof, dtype=np.float64), np.empty(dof, dtype=np.float64))


@nb.njit(cache=True, nogil=True, _nrt=False)
def _rrt_loop(P, T, seed, max_iter, step, goal_bias, stop, state, sample, q_near, q_new):
    """:func:`rrt_kernel`'s loop, given its scratch buffers."""
    seed_state(seed, state)
    dof = P.start.shape[0]
    add_node(T, P.start, -1)
    g = join_start_at_goal(P, T)
    if g >= 0:
        return True, 0, g
    for it in range(1, max_iter + 1):
        if stop[0] != 0:
            return False, it - 1, -1
        if uniform(state) < goal_bias:
            for j in range(dof):
                sample[j] = P.goal[j]
        else:
            for j in range(dof):
                sample[j] = P.limits[j, 0] + uniform(state) * (P.limits[j, 1] - P.limits[j, 0])
        ni = nearest(T, sample)
        outcome, k = extend(P, T, ni, sample, step, q_near, q_new)
        if outcome == GOAL_REACHED:
            return True, it, k
    return False, max_iter, -1


@nb.njit(cache=True, nogil=True, _nrt=True)
def rrt_entry(pblock, playout, block, layout, seed, max_iter, step, goal_bias, stop):
    """:func:`rrt_kernel` called with the problem as its arena
    (:mod:`~xfuzzy_rrt.planners.problem_arena`, the work counter made here) and the tree as its
    arena (:mod:`~xfuzzy_rrt.planners.tree_arena`), emptied here; returns the run finished
    (:func:`~xfuzzy_rrt.planners.result.finished_tree`: the kernel's three values, the tree's
    size, its copies, the path, its cost, the limits re-check and the work).

    Why: numba types and unboxes every argument in Python on every call (a named tuple element
    by element: 20-40 us for our two bundles, as much as a short 2-DOF plan); one block and a
    layout table each instead of the problem's eight arrays and the tree's 17 are unboxed
    once, and the bundles are rebuilt here, inside compiled code, for free.
    """
    P = problem_in(pblock, playout)
    T = emptied_tree_in(block, layout)
    ok, it, last = rrt_kernel(P, T, seed, max_iter, step, goal_bias, stop)
    return finished_tree(P, T, ok, it, last)


class _Setup(NamedTuple):
    """What an RRT call checks and builds before its kernel (see
    :mod:`xfuzzy_rrt.planners.setup_memo`): the same for every seed."""

    arrays: Any
    margin: float
    params: dict
    #: the problem in one block (:mod:`~xfuzzy_rrt.planners.problem_arena`)
    problem: Any
    recorded: dict
    #: ``(scenario name, label, extra params)`` -> the run :func:`_lane` made for this set-up
    lanes: dict


def _prepare(scenario: Scenario, max_iter, step_deg, goal_bias, margin, clearance_m,
             max_time_s) -> _Setup:
    """Every check of a call, in the order errors are reported, and what the kernel takes."""
    margin, params = check_plan_call("rrt", scenario, max_iter, margin, clearance_m,
                                     max_time_s=max_time_s, step_deg=step_deg,
                                     goal_bias=goal_bias)
    a = scenario_arrays(scenario)
    recorded = {"step_deg": float(params["step_deg"]), "goal_bias": float(params["goal_bias"]),
                "max_iter": int(params["max_iter"]), "margin_m": float(margin)}
    return _Setup(a, margin, params, make_problem_arena(a.problem(margin)), recorded, {})


def _setup_for(scenario: Scenario, max_iter, step_deg, goal_bias, margin,
               clearance_m) -> _Setup:
    """:func:`_prepare`, remembered per scenario object and settings (no time budget)."""
    return set_up("rrt", scenario, _prepare,
                  (max_iter, step_deg, goal_bias, margin, clearance_m))


def plan_rrt(scenario: Scenario, seed: int = 0, max_iter: int = DEFAULT_MAX_ITER,
             step_deg: float = DEFAULT_STEP_DEG, goal_bias: float = DEFAULT_GOAL_BIAS,
             margin: float | None = None, clearance_m: float | None = None,
             max_time_s: float | None = None) -> PlanResult:
    """Plan with RRT in the joint space of every arm. Same inputs and seed give the same result
    (``wall_s`` aside, and unless the wall-clock budget ``max_time_s`` ends the run).

    ``clearance_m``: the certified clearance (m; default the scenario's ``clearance_m``, else
    0); ``margin``: an explicit kernel margin instead (see ``geometry/clearance.py``).
    """
    return plan_rrt_as("rrt", None, scenario, seed, max_iter, step_deg, goal_bias, margin,
                       clearance_m, max_time_s)


def plan_rrt_as(label: str, extra_params: dict | None, scenario: Scenario, seed: int = 0,
                max_iter: int = DEFAULT_MAX_ITER, step_deg: float = DEFAULT_STEP_DEG,
                goal_bias: float = DEFAULT_GOAL_BIAS, margin: float | None = None,
                clearance_m: float | None = None,
                max_time_s: float | None = None) -> PlanResult:
    """:func:`plan_rrt`, its result named ``label`` (``planner`` and ``planner_used``) with
    ``extra_params`` added to its ``params``: how ``rrt:tuned`` runs, without copying a
    finished result to relabel it (a tenth of a short plan's overhead)."""
    if max_time_s is None:
        setup = _setup_for(scenario, max_iter, step_deg, goal_bias, margin, clearance_m)
    else:
        setup = _prepare(scenario, max_iter, step_deg, goal_bias, margin, clearance_m,
                         max_time_s)
    return _run(setup, scenario.name, label, extra_params, seed, max_time_s)


def bind_rrt_as(label: str, extra_params: dict | None, scenario: Scenario, *, max_iter,
                step_deg, goal_bias, clearance_m):
    """:func:`plan_rrt_as` without a time budget, for every seed: ``run(seed) -> PlanResult``,
    the same result (what ``plan_scenario`` keeps for a loop of calls: ``api._LANES``)."""
    return _lane(_setup_for(scenario, max_iter, step_deg, goal_bias, None, clearance_m),
                 scenario.name, label, extra_params)


def _lane(setup: _Setup, name: str, label: str, extra_params: dict | None):
    """The run of ``setup`` without a time budget, ``run(seed) -> PlanResult``, made once per
    set-up, scenario name, label and extra params (``setup.lanes``; the same result as
    :func:`_run`'s general path, tests/test_plan_lanes.py): the twin of
    :func:`xfuzzy_rrt.planners.connect._lane`, so that ``rrt:tuned`` sheds the same Python
    as the default (why: :func:`~xfuzzy_rrt.planners.result.bound_result`)."""
    key = (name, label, None if extra_params is None else tuple(extra_params.items()))
    try:
        run = setup.lanes.get(key)
    except TypeError:  # extra params that cannot be a key: a run made for this call only
        key, run = None, None
    if run is not None:
        return run
    a, params = setup.arrays, setup.params
    pblock, playout = setup.problem
    max_iter = int(params["max_iter"])
    step, bias = float(params["step_deg"]), float(params["goal_bias"])
    tree_key = (max_iter + 2, a.limits_deg, a.stop_width)
    recorded = dict(setup.recorded) if extra_params is None else {**setup.recorded,
                                                                   **extra_params}
    margin = float(setup.margin)
    template = planner_template(name, label, label)
    clock = time.perf_counter

    def run(seed):
        arena = pooled_tree(*tree_key)
        t0 = clock()
        ok, iterations, _, n, nodes, parents, path, cost, within, work = rrt_entry(
            pblock, playout, arena.block, arena.layout, seed, max_iter, step, bias,
            NEVER_STOPPED)
        wall = clock() - t0
        return bound_result(template, a, margin, ok, within, seed, iterations, n, cost, wall,
                            path, nodes, parents, work, dict(recorded))

    if key is not None:
        setup.lanes[key] = run
    return run


def _run(setup: _Setup, name: str, label: str, extra_params: dict | None, seed,
         max_time_s=None) -> PlanResult:
    """One run of a checked set-up (:func:`plan_rrt_as`) of the scenario called ``name`` (the
    name, not the scenario: a kept run must not keep its scenario alive). Without a time
    budget: :func:`_lane`'s run."""
    if max_time_s is None:
        return _lane(setup, name, label, extra_params)(int(seed))
    a, margin, params = setup.arrays, setup.margin, setup.params
    max_iter = int(params["max_iter"])
    pblock, playout = setup.problem
    arena = pooled_tree(max_iter + 2, a.limits_deg, a.stop_width)
    block, layout = arena.block, arena.layout
    step, bias = float(params["step_deg"]), float(params["goal_bias"])
    recorded = dict(setup.recorded)
    # the budget is for planning: compile (or load) the kernel first
    rrt_entry(pblock, playout, block, layout, int(seed), 0, step, bias,
              np.zeros(1, dtype=np.int64))
    with StopFlag(max_time_s) as flag:
        t0 = time.perf_counter()
        ok, iterations, _, n, nodes, parents, path, cost, within, work = rrt_entry(
            pblock, playout, block, layout, int(seed), max_iter, step, bias, flag.array)
        wall = time.perf_counter() - t0
    recorded["max_time_s"] = float(params["max_time_s"])
    recorded["stopped_by"] = stopped_by(bool(ok), int(iterations), max_iter, flag)
    return bound_result(planner_template(name, label, label), a, margin, ok, within, int(seed),
                        iterations, n, cost, wall, path, nodes, parents, work,
                        recorded if extra_params is None else {**recorded, **extra_params})
