"""Fuzzy-RRT: the paper's Algorithm 1 (Shankar et al., "Fuzzy-RRT for Obstacle Avoidance in a
2-DOF Semi-Autonomous Surgical Robotic Arm"), compiled with numba, with optional per-iteration
traces of every fuzzy decision.

Each iteration, read top to bottom in :func:`fuzzy_rrt_kernel`:

1. ``ee`` = forward kinematics of the current ``nearest_node`` (the start at iteration 1).
2. Angle and distance from ``ee`` to the nearest obstacle *surface* (angle 0 and distance at the
   top of the input range when there are no obstacles) and to the goal's end-effector position.
   Angles are workspace directions, counter-clockwise from +x, in [0, 2π).
3. The six FIS (one rulebook) give ``(goal_bias, B1, B2, B3, B4, step)``.
4. Sample the goal with probability ``goal_bias``, else uniformly in the box
   ``[[B1, B2], [B3, B4]]``.
5. ``nearest_node`` = the tree node nearest to the sample; steer from it by ``step``.
6. Reject the new node if it is in collision, or if the edge to it is not certified free.
7. Add it; succeed if it *is* the goal, or if the goal is within ``step`` and that edge is free.

**Several joints and several arms.** With ``N`` joints per arm a paper-semantics rulebook has
``2N`` bound outputs (joint ``j``'s interval is ``[bound_{2j-1}, bound_{2j}]``) plus goal bias
and step. With several arms, each arm's end effector is read by the same rulebook (the arms
are identical in kind; the rulebook's DOF is one arm's): its inputs are that arm's angle and
distance to its own goal position and to its nearest obstacle, *the other arms' link capsules
included*, and its bound outputs give that arm's joint intervals. The sample is one
configuration of all arms: the goal with probability the *mean* of the arms' goal biases, else
drawn from the product of the arms' boxes; the step is the *smallest* of the arms' steps (the
most cautious arm sets the pace). With one arm both reduce to the paper's loop exactly.

The ``nearest_node`` carried into the next iteration is the one found for the last sample,
accepted or not, exactly as in the paper's pseudocode (it is not reset to the new node).

Choices where the paper is silent or ambiguous (and why):

- **Bounds meaning** comes from the rulebook manifest. ``absolute`` (the paper's literal
  reading, the default for trained paper-style rulebooks): joint-1 interval ``[B1, B2]``, joint-2
  ``[B3, B4]`` in degrees. ``relative``: the same intervals as offsets from the current
  ``nearest_node``; this is what lets a rulebook carry over to unseen problems, because the FIS
  only sees workspace quantities and cannot know a scenario's joint-space layout.
- **Reversed bounds** (``B1 > B2``) are reordered: the interval is ``[min, max]``. Each interval
  is then clipped to the joint limits. If clipping leaves nothing (the whole interval lies
  beyond a limit), the interval collapses onto that limit.
- **Step size** is clamped below at ``MIN_STEP_DEG`` = 0.5° so that a rulebook that outputs 0
  cannot stall the search; the same effective step is used for the goal-connection test.
- **Sampling order**: one uniform draw decides goal vs. box; a box sample then draws joint 1,
  then joint 2 (the RRT baseline draws in the same order).
- A sample that coincides with its nearest node (nothing to steer towards) counts as an
  iteration with outcome ``no_progress``.
"""

from __future__ import annotations

import time
from typing import Any, NamedTuple

import numba as nb
import numpy as np

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.engine import infer
from xfuzzy_rrt.fuzzy.rulebook import default_rulebook_str, load_rulebook_cached
from xfuzzy_rrt.fuzzy.variables import MAX_FIRED
from xfuzzy_rrt.geometry.collision import direction_and_distance, nearest_obstacle_for_arm
from xfuzzy_rrt.geometry.kinematics import arm_end_effector
from xfuzzy_rrt.geometry.scenario import Scenario
from xfuzzy_rrt.planners.checks import check_plan_call
from xfuzzy_rrt.planners.extend import extend, join_start_at_goal
from xfuzzy_rrt.planners.goal_frame import goal_frame_kernel
from xfuzzy_rrt.planners.params import default
from xfuzzy_rrt.planners.result import (GOAL_REACHED, PlanResult, bound_result,
                                       finished_tree, planner_template, replace_result)
from xfuzzy_rrt.planners.rng import seed_state, uniform
from xfuzzy_rrt.planners.termination import NEVER_STOPPED, StopFlag, stopped_by
from xfuzzy_rrt.planners.trace_record import (
    TraceArrays,
    make_trace,
    record_iteration,
)
from xfuzzy_rrt.planners.problem_arena import make_problem_arena, problem_in
from xfuzzy_rrt.planners.prepared import pooled_tree, scenario_arrays
from xfuzzy_rrt.planners.setup_memo import set_up
from xfuzzy_rrt.planners.tree import add_node, nearest
from xfuzzy_rrt.planners.tree_arena import emptied_tree_in

#: Smallest step (degrees) the planner takes whatever the rulebook says.
MIN_STEP_DEG = default("fuzzy-rrt", "min_step_deg")
BOUNDS_ABSOLUTE = 0
BOUNDS_RELATIVE = 1
#: Kernel mode of a goal-frame rulebook (see :mod:`xfuzzy_rrt.planners.goal_frame`).
GOAL_FRAME = 2


def kernel_mode(rb) -> int:
    """The integer mode the compiled kernels take for rulebook *rb* (chosen once per plan):
    its semantics' (:meth:`~xfuzzy_rrt.fuzzy.semantics.Semantics.kernel_mode`)."""
    return rb.semantics.kernel_mode(rb.bounds_mode)


def kernel_for(mode: int):
    """The compiled loop for *mode*: the paper's Algorithm 1 or its goal-frame variant."""
    return goal_frame_kernel if mode == GOAL_FRAME else fuzzy_rrt_kernel


def fis_groups(rb, scenario: Scenario) -> int:
    """Fuzzy evaluations per iteration: one per arm (paper), one for all arms (goal-frame);
    the semantics says (:attr:`~xfuzzy_rrt.fuzzy.semantics.Semantics.per_arm`)."""
    return rb.semantics.fis_groups(len(scenario.arms))


def check_rulebook_fits(rb, scenario: Scenario) -> None:
    """One clear error when the rulebook's DOF does not match the arm(s) it is asked to drive.

    Paper semantics reads one arm at a time, so its DOF is each arm's; goal-frame reads the
    joint space of all arms together, so its DOF is the total.

    Only a rulebook the user named gets here with a mismatch: without one, plain ``fuzzy-rrt``
    plans a problem that is not one 2-joint arm with Fuzzy-RRT-Connect and ``goal-frame-any``
    (:func:`xfuzzy_rrt.planners.api.shipped_default`), so the error says so.
    """
    dof = int(getattr(rb, "dof", 2))
    where = scenario.source or scenario.name
    default = ("; or name no rulebook: the default plans any arm with fuzzy-rrt-connect and "
               "goal-frame-any")
    if rb.semantics.dof_free:
        raise InputError(where, f"rulebook {rb.name!r} has the {rb.semantics.name} semantics, "
                         "which plans with --planner fuzzy-rrt-connect (fuzzy-rrt takes paper "
                         "and goal-frame rulebooks)")
    if not rb.semantics.per_arm:  # reads the joints of all arms together
        if dof != scenario.dof:
            raise InputError(where, f"rulebook {rb.name!r} is a {dof}-DOF "
                             f"{rb.semantics.name} rulebook; this problem has {scenario.dof} "
                             f"joints in all (train or pick a {scenario.dof}-DOF "
                             f"rulebook{default})")
        return
    for a, arm in enumerate(scenario.arms):
        if arm.dof != dof:
            which = "the arm" if len(scenario.arms) == 1 else f"arm {a + 1}"
            raise InputError(where, f"rulebook {rb.name!r} is a {dof}-DOF rulebook; {which} "
                             f"has {arm.dof} joints (train or pick a {arm.dof}-DOF "
                             f"rulebook{default})")


@nb.njit(cache=True, nogil=True, inline="always")
def arm_inputs(P, a, q, goal_ws, has_obstacles, no_obstacle_dist):
    """The paper's four fuzzy inputs of arm ``a`` at ``q``: ``(angle to goal, distance to goal,
    angle to the nearest obstacle, distance to it)``, from its end effector; with nothing to
    hit the obstacle distance is ``no_obstacle_dist`` (the input's top) and its angle 0. One
    definition for the planner kernel and the training loop (``training/memo.py``)."""
    ex, ey = arm_end_effector(P, a, q)
    d_obs = no_obstacle_dist
    a_obs = 0.0
    if has_obstacles:
        d, ang, _ = nearest_obstacle_for_arm(P, a, q, ex, ey)
        if d < np.inf:
            d_obs = d
            a_obs = ang
    d_goal, a_goal = direction_and_distance(ex, ey, goal_ws[a, 0], goal_ws[a, 1])
    return a_goal, d_goal, a_obs, d_obs


@nb.njit(cache=True, nogil=True, inline="always")
def _interval(lo_raw, hi_raw, offset, limit_lo, limit_hi):
    """Ordered, offset and clipped sampling interval (see the module docstring)."""
    lo = min(lo_raw, hi_raw) + offset
    hi = max(lo_raw, hi_raw) + offset
    if lo < limit_lo:
        lo = limit_lo
    if hi > limit_hi:
        hi = limit_hi
    if lo > hi:  # entirely beyond one limit: collapse onto it
        if lo >= limit_hi:
            lo = limit_hi
            hi = limit_hi
        else:
            lo = limit_lo
            hi = limit_lo
    return lo, hi


@nb.njit(cache=True, nogil=True, _nrt=True)
def fuzzy_rrt_kernel(P, T, seed, max_iter, knots, consts, bounds_mode, min_step, stop, TR):
    """Run Fuzzy-RRT; return ``(success, iterations, index of the last path node or -1)``.

    With trace arrays ``TR`` (:func:`~xfuzzy_rrt.planners.trace_record.make_trace`), row
    ``it - 1`` of each describes iteration ``it``; ``TR`` ``None`` records nothing, and its
    compiled loop has no trace code at all (:mod:`~xfuzzy_rrt.planners.trace_record`).
    ``stop[0] != 0`` (a wall-clock budget ran out) ends the run.
    """
    n_arms = P.arm_first.shape[0] - 1
    n_out = knots.shape[0]
    dof = P.start.shape[0]
    # an uncounted loop (README, "No reference counting in the loops") borrows these buffers
    return _fuzzy_rrt_loop(
        P, T, seed, max_iter, knots, consts, bounds_mode, min_step, stop, TR,
        np.empty(4, dtype=np.uint64), np.empty(4 * n_arms, dtype=np.float64),
        np.empty(n_out * n_arms, dtype=np.float64), np.empty((n_out, MAX_FIRED), dtype=np.int32),
        np.empty((n_out, MAX_FIRED), dtype=np.float64), np.empty(2 * dof, dtype=np.float64),
        np.empty(dof, dtype=np.float64), np.empty(dof, dtype=np.float64),
        np.empty(dof, dtype=np.float64), np.empty((n_arms, 2), dtype=np.float64))


@nb.njit(cache=True, nogil=True, _nrt=False)
def _fuzzy_rrt_loop(P, T, seed, max_iter, knots, consts, bounds_mode, min_step, stop, TR,
                    state, x, y, dummy_rule, dummy_w, box, sample, q_near, q_new, goal_ws):
    """:func:`fuzzy_rrt_kernel`'s loop, given its scratch buffers."""
    seed_state(seed, state)
    n_arms = P.arm_first.shape[0] - 1
    n_out = knots.shape[0]
    dof = P.start.shape[0]
    for a in range(n_arms):
        goal_ws[a, 0], goal_ws[a, 1] = arm_end_effector(P, a, P.goal)
    no_obstacle_dist = knots[0, 3, 4]
    has_obstacles = P.obstacles.shape[0] > 0 or n_arms > 1

    add_node(T, P.start, -1)
    g = join_start_at_goal(P, T)
    if g >= 0:
        return True, 0, g
    current = 0  # the paper's nearest_node: the start at iteration 1
    for it in range(1, max_iter + 1):
        if stop[0] != 0:
            return False, it - 1, -1
        row = it - 1
        q = T.nodes[current]
        bias_sum = 0.0
        step_min = np.inf
        for a in range(n_arms):
            # 1-2. Fuzzy inputs from this arm's end effector.
            a_goal, d_goal, a_obs, d_obs = arm_inputs(P, a, q, goal_ws, has_obstacles,
                                                      no_obstacle_dist)
            xa = x[4 * a:4 * a + 4]
            ya = y[n_out * a:n_out * (a + 1)]
            xa[0] = a_goal
            xa[1] = d_goal
            xa[2] = a_obs
            xa[3] = d_obs
            # 3. The rulebook's systems (goal bias, two bounds per joint, step).
            if TR is None:  # decided when compiled
                infer(knots, consts, xa, ya, dummy_rule, dummy_w, False)
            else:
                infer(knots, consts, xa, ya, TR.rule[row, n_out * a:n_out * (a + 1)],
                      TR.w[row, n_out * a:n_out * (a + 1)], True)
            bias_sum += ya[0]
            if ya[n_out - 1] < step_min:
                step_min = ya[n_out - 1]
            f = P.arm_first[a]
            for jl in range(P.arm_first[a + 1] - f):
                j = f + jl
                off = 0.0
                if bounds_mode == BOUNDS_RELATIVE:
                    off = q[j]
                lo, hi = _interval(ya[1 + 2 * jl], ya[2 + 2 * jl], off, P.limits[j, 0],
                                   P.limits[j, 1])
                box[2 * j] = lo
                box[2 * j + 1] = hi
        bias = bias_sum / n_arms
        step = max(step_min, min_step)
        # 4. Sample.
        goal_sampled = uniform(state) < bias
        if goal_sampled:
            for j in range(dof):
                sample[j] = P.goal[j]
        else:
            for j in range(dof):
                sample[j] = box[2 * j] + uniform(state) * (box[2 * j + 1] - box[2 * j])
        # 5. Nearest node (carried to the next iteration) and steering.
        from_node = current
        current = nearest(T, sample)
        # 6-7. Steer, certify, grow, try the goal (shared with RRT).
        outcome, new_index = extend(P, T, current, sample, step, q_near, q_new)
        if TR is not None:
            record_iteration(TR, row, from_node, x, y, box, goal_sampled, sample, current,
                             q_new, outcome, new_index, T.meta[0])
        if outcome == GOAL_REACHED:
            return True, it, new_index
    return False, max_iter, -1


@nb.njit(cache=True, nogil=True, inline="always")
def _fuzzy_rrt_run(pblock, playout, block, layout, seed, max_iter, knots, consts, bounds_mode,
                   min_step, stop, TR):
    """:func:`fuzzy_rrt_kernel` on the problem and the tree unpacked from their arenas (the
    tree emptied here), the run finished: the body of :func:`fuzzy_rrt_entry` and of
    :func:`fuzzy_rrt_untraced`."""
    P = problem_in(pblock, playout)
    T = emptied_tree_in(block, layout)
    ok, it, last = fuzzy_rrt_kernel(P, T, seed, max_iter, knots, consts, bounds_mode, min_step,
                                    stop, TR)
    return finished_tree(P, T, ok, it, last)


@nb.njit(cache=True, nogil=True, _nrt=True)
def fuzzy_rrt_entry(pblock, playout, block, layout, seed, max_iter, knots, consts, bounds_mode,
                    min_step, stop, tr):
    """:func:`fuzzy_rrt_kernel` with the problem and the tree as their arenas (the tree emptied
    here) and the trace bundle as a *plain* tuple; returns the run finished (see
    :func:`xfuzzy_rrt.planners.rrt.rrt_entry`: what a semantics' kernel entry takes and
    returns). ``tr`` ``None``: a run that records nothing, through the kernel compiled without
    trace code (the planner itself calls :func:`fuzzy_rrt_untraced` for such a run)."""
    if tr is None:  # decided when compiled: the branch not taken is not compiled at all
        return _fuzzy_rrt_run(pblock, playout, block, layout, seed, max_iter, knots, consts,
                              bounds_mode, min_step, stop, None)
    return _fuzzy_rrt_run(pblock, playout, block, layout, seed, max_iter, knots, consts,
                          bounds_mode, min_step, stop, TraceArrays(*tr))


@nb.njit(cache=True, nogil=True, _nrt=True)
def fuzzy_rrt_untraced(pblock, playout, block, layout, seed, max_iter, knots, consts,
                       bounds_mode, min_step, stop):
    """:func:`fuzzy_rrt_entry` with ``tr=None``, without taking it: numba types a ``None``
    argument by fingerprint on every call (:attr:`~xfuzzy_rrt.fuzzy.semantics.Semantics.
    untraced`), every other argument here through its fast path."""
    return _fuzzy_rrt_run(pblock, playout, block, layout, seed, max_iter, knots, consts,
                          bounds_mode, min_step, stop, None)


@nb.njit(cache=True, nogil=True, inline="always")
def _goal_frame_run(pblock, playout, block, layout, seed, max_iter, knots, consts, mode,
                    min_step, stop, TR):
    """:func:`_fuzzy_rrt_run` for :func:`~xfuzzy_rrt.planners.goal_frame.goal_frame_kernel`."""
    P = problem_in(pblock, playout)
    T = emptied_tree_in(block, layout)
    ok, it, last = goal_frame_kernel(P, T, seed, max_iter, knots, consts, mode, min_step, stop,
                                     TR)
    return finished_tree(P, T, ok, it, last)


@nb.njit(cache=True, nogil=True, _nrt=True)
def goal_frame_entry(pblock, playout, block, layout, seed, max_iter, knots, consts, mode,
                     min_step, stop, tr):
    """:func:`~xfuzzy_rrt.planners.goal_frame.goal_frame_kernel`, called as above."""
    if tr is None:  # decided when compiled, as above
        return _goal_frame_run(pblock, playout, block, layout, seed, max_iter, knots, consts,
                               mode, min_step, stop, None)
    return _goal_frame_run(pblock, playout, block, layout, seed, max_iter, knots, consts, mode,
                           min_step, stop, TraceArrays(*tr))


@nb.njit(cache=True, nogil=True, _nrt=True)
def goal_frame_untraced(pblock, playout, block, layout, seed, max_iter, knots, consts, mode,
                        min_step, stop):
    """:func:`goal_frame_entry` with ``tr=None``, without taking it (as
    :func:`fuzzy_rrt_untraced`)."""
    return _goal_frame_run(pblock, playout, block, layout, seed, max_iter, knots, consts, mode,
                           min_step, stop, None)


def _kernel_owner(mode: int):
    """The semantics whose Fuzzy-RRT kernel takes *mode* (a mode belongs to one semantics)."""
    from xfuzzy_rrt.fuzzy.semantics import SEMANTICS

    owner = next((s for s in SEMANTICS.values() if mode in s.modes.values() and s.kernel), None)
    if owner is None:
        raise ValueError(f"no semantics has a Fuzzy-RRT kernel for mode {mode!r}")
    return owner


def entry_for(mode: int):
    """The compiled loop of the semantics whose kernel takes *mode*, called with plain tuples
    (what :func:`plan_fuzzy_rrt` uses): :attr:`~xfuzzy_rrt.fuzzy.semantics.Semantics.kernel`,
    looked up in one dict."""
    entry = _ENTRIES.get(mode)
    if entry is None:
        from xfuzzy_rrt.fuzzy.semantics import resolve

        entry = _ENTRIES[mode] = resolve(_kernel_owner(mode).kernel)
    return entry


#: mode -> kernel entry, filled from the semantics registry on first use.
_ENTRIES: dict[int, object] = {}


def untraced_for(mode: int):
    """:func:`entry_for`'s entry for a run that records nothing, called without ``tr``: the
    same semantics' :attr:`~xfuzzy_rrt.fuzzy.semantics.Semantics.untraced` entry, or, for a
    semantics with none, its entry with ``tr=None`` added."""
    run = _UNTRACED.get(mode)
    if run is None:
        from xfuzzy_rrt.fuzzy.semantics import resolve

        owner = _kernel_owner(mode)
        if owner.untraced:
            run = resolve(owner.untraced)
        else:
            entry = entry_for(mode)

            def run(*args):
                return entry(*args, None)
        _UNTRACED[mode] = run
    return run


#: mode -> untraced kernel entry (:func:`untraced_for`), filled on first use.
_UNTRACED: dict[int, object] = {}


def _resolve_rulebook(rulebook):
    """A loaded rulebook as given, else the (cached) directory or shipped default."""
    if rulebook is None:
        rulebook = default_rulebook_str()
    elif hasattr(rulebook, "compiled"):
        return rulebook
    return load_rulebook_cached(rulebook)


class _Setup(NamedTuple):
    """Everything a Fuzzy-RRT call checks and builds before its kernel (see
    :mod:`xfuzzy_rrt.planners.setup_memo`): the same for every seed."""

    rb: Any
    arrays: Any
    margin: float
    max_iter: int
    min_step: float
    params: dict
    kernel: Any
    #: the kernel for a run that records nothing, taking no trace argument (:func:`untraced_for`)
    untraced: Any
    mode: int
    knots: np.ndarray
    consts: np.ndarray
    groups: int
    #: the problem in one block (:mod:`~xfuzzy_rrt.planners.problem_arena`)
    problem: Any
    #: the result's ``params`` as far as the set-up fixes them (each call copies it)
    recorded: dict
    #: ``(scenario name, label)`` -> the run :func:`_lane` made for this set-up
    lanes: dict


def _prepare(scenario: Scenario, rulebook, max_iter, min_step_deg, margin, clearance_m,
             max_time_s) -> _Setup:
    """Every check of a call, in the order errors are reported, and what the kernel takes."""
    margin, params = check_plan_call("fuzzy-rrt", scenario, max_iter, margin, clearance_m,
                                     max_time_s=max_time_s, min_step_deg=min_step_deg)
    rb = _resolve_rulebook(rulebook)
    check_rulebook_fits(rb, scenario)
    knots, consts = rb.kernel_arrays
    mode = kernel_mode(rb)
    a = scenario_arrays(scenario)
    groups = fis_groups(rb, scenario)
    problem = make_problem_arena(a.problem(margin))  # its work counter is made per call
    recorded = {"max_iter": int(max_iter), "semantics": rb.semantics.name,
                "bounds": rb.bounds_mode, "min_step_deg": float(min_step_deg),
                "margin_m": float(margin)}
    return _Setup(rb, a, margin, int(max_iter), float(min_step_deg), params, entry_for(mode),
                  untraced_for(mode), mode, knots, consts, groups, problem, recorded, {})


def _setup_for(scenario: Scenario, rulebook, max_iter, min_step_deg, margin,
               clearance_m) -> _Setup:
    """:func:`_prepare`, remembered per scenario object and settings while the rulebook
    resolves to the same object (a call without a time budget or a trace)."""
    return set_up("fuzzy-rrt", scenario, _prepare,
                  (rulebook, max_iter, min_step_deg, margin, clearance_m), _resolve_rulebook)


def plan_fuzzy_rrt(scenario: Scenario, rulebook=None, seed: int = 0, max_iter: int = 10_000,
                   trace: bool = False, min_step_deg: float = MIN_STEP_DEG,
                   margin: float | None = None, clearance_m: float | None = None,
                   max_time_s: float | None = None, label: str = "fuzzy-rrt") -> PlanResult:
    """Plan with Fuzzy-RRT.

    ``rulebook`` is a loaded :class:`~xfuzzy_rrt.fuzzy.rulebook.Rulebook`, a rulebook directory,
    or ``None`` for the shipped default; its DOF must fit the arms (:func:`check_rulebook_fits`).
    With ``trace=True`` the result carries a per-iteration DataFrame (see
    :mod:`xfuzzy_rrt.planners.trace`). Same inputs and seed, same result (unless the
    wall-clock budget ``max_time_s`` ends the run). ``clearance_m``/``margin`` as for
    :func:`~xfuzzy_rrt.planners.rrt.plan_rrt`. ``label``: the result's ``planner`` (the label
    the caller planned with, e.g. ``fuzzy-rrt:goal-frame``; ``planner_used`` stays
    ``fuzzy-rrt``), so that no finished result is copied to relabel it.
    """
    if trace or max_time_s is not None:
        setup = _prepare(scenario, rulebook, max_iter, min_step_deg, margin, clearance_m,
                         max_time_s)
    else:
        setup = _setup_for(scenario, rulebook, max_iter, min_step_deg, margin, clearance_m)
    return _run(setup, scenario.name, label, seed, trace, max_time_s)


def bind_fuzzy_rrt(scenario: Scenario, rulebook, *, max_iter, clearance_m, label):
    """:func:`plan_fuzzy_rrt` without a trace or a time budget, for every seed: ``run(seed) ->
    PlanResult``, the same result (what ``plan_scenario`` keeps for a loop of calls:
    ``api._LANES``)."""
    return _lane(_setup_for(scenario, rulebook, max_iter, MIN_STEP_DEG, None, clearance_m),
                 scenario.name, label)


def _lane(setup: _Setup, name: str, label: str):
    """The untraced run of ``setup`` without a time budget, ``run(seed) -> PlanResult``, made
    once per set-up, scenario name and label (``setup.lanes``; the same result as
    :func:`_run`'s general path, tests/test_plan_lanes.py): the twin of
    :func:`xfuzzy_rrt.planners.connect._lane` (why: :func:`~xfuzzy_rrt.planners.result.
    bound_result`)."""
    run = setup.lanes.get((name, label))
    if run is not None:
        return run
    rb, a, max_iter = setup.rb, setup.arrays, setup.max_iter
    knots, consts, mode, untraced, min_step = (setup.knots, setup.consts, setup.mode,
                                               setup.untraced, setup.min_step)
    pblock, playout = setup.problem
    tree_key = (max_iter + 2, a.limits_deg, a.stop_width)
    recorded, margin = setup.recorded, float(setup.margin)
    template = planner_template(name, label, "fuzzy-rrt", rb)
    clock = time.perf_counter

    def run(seed):
        arena = pooled_tree(*tree_key)
        t0 = clock()
        ok, iterations, _, n, nodes, parents, path, cost, within, work = untraced(
            pblock, playout, arena.block, arena.layout, seed, max_iter, knots, consts, mode,
            min_step, NEVER_STOPPED)
        wall = clock() - t0
        return bound_result(template, a, margin, ok, within, seed, iterations, n, cost, wall,
                            path, nodes, parents, work, dict(recorded))

    setup.lanes[(name, label)] = run
    return run


def _run(setup: _Setup, name: str, label: str, seed, trace=False,
         max_time_s=None) -> PlanResult:
    """One run of a checked set-up (:func:`plan_fuzzy_rrt`) of the scenario
    called ``name`` (the name, not the scenario: a kept run must not keep its scenario alive).
    Untraced without a time budget: :func:`_lane`'s run."""
    if not trace and max_time_s is None:
        return _lane(setup, name, label)(int(seed))
    rb, a, margin, max_iter = setup.rb, setup.arrays, setup.margin, setup.max_iter
    knots, consts, mode = setup.knots, setup.consts, setup.mode
    pblock, playout = setup.problem
    arena = pooled_tree(max_iter + 2, a.limits_deg, a.stop_width)
    block, layout = arena.block, arena.layout
    buffers = tuple(make_trace(max_iter, a.dof, knots.shape[0], setup.groups)) if trace else None
    # untraced: the entry that takes no trace argument (untraced_for)
    kernel, tail = (setup.kernel, (buffers,)) if trace else (setup.untraced, ())
    recorded = dict(setup.recorded)
    if max_time_s is None:
        t0 = time.perf_counter()
        ok, iterations, last, n, nodes, parents, path, cost, within, work = kernel(
            pblock, playout, block, layout, int(seed), max_iter, knots, consts, mode,
            setup.min_step, NEVER_STOPPED, *tail)
        wall = time.perf_counter() - t0
    else:  # the budget is for planning: compile (or load) the kernel first
        kernel(pblock, playout, block, layout, int(seed), 0, knots, consts, mode,
               setup.min_step, np.zeros(1, dtype=np.int64), *tail)
        with StopFlag(max_time_s) as flag:
            t0 = time.perf_counter()
            ok, iterations, last, n, nodes, parents, path, cost, within, work = kernel(
                pblock, playout, block, layout, int(seed), max_iter, knots, consts, mode,
                setup.min_step, flag.array, *tail)
            wall = time.perf_counter() - t0
        recorded["max_time_s"] = float(setup.params["max_time_s"])
        recorded["stopped_by"] = stopped_by(bool(ok), int(iterations), max_iter, flag)
    # certifies the path (found -> success)
    result = bound_result(planner_template(name, label, "fuzzy-rrt", rb), a, margin, ok, within,
                          int(seed), iterations, n, cost, wall, path, nodes, parents, work,
                          recorded)
    if trace:
        from xfuzzy_rrt.planners.trace import trace_frame

        frame = trace_frame(TraceArrays(*buffers), int(iterations), nodes, parents, last, rb,
                            setup.min_step, setup.groups)
        result = replace_result(result, trace=frame)
    return result
