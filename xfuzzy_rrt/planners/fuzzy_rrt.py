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

import dataclasses
import time

import numba as nb
import numpy as np

from xfuzzy_rrt.fuzzy.engine import infer
from xfuzzy_rrt.fuzzy.variables import MAX_FIRED, N_OUTPUTS
from xfuzzy_rrt.geometry.clearance import planning_margin
from xfuzzy_rrt.geometry.collision import (
    direction_and_distance,
    nearest_obstacle_from_point,
)
from xfuzzy_rrt.geometry.kinematics import end_effector
from xfuzzy_rrt.geometry.scenario import Scenario
from xfuzzy_rrt.planners.extend import extend
from xfuzzy_rrt.planners.result import GOAL_REACHED, PlanResult, path_cost_deg
from xfuzzy_rrt.planners.rng import seed_state, uniform
from xfuzzy_rrt.planners.checks import check_max_iter, check_planar_2dof
from xfuzzy_rrt.planners.tree import Tree, add_node, extract_path, nearest

#: Smallest step (degrees) the planner takes whatever the rulebook says.
MIN_STEP_DEG = 0.5
BOUNDS_ABSOLUTE = 0
BOUNDS_RELATIVE = 1
#: Kernel mode of a goal-frame rulebook (see :mod:`xfuzzy_rrt.planners.goal_frame`).
GOAL_FRAME = 2


def kernel_mode(rb) -> int:
    """The integer mode the compiled kernels take for rulebook *rb* (chosen once per plan)."""
    if rb.semantics.name == "goal-frame":
        return GOAL_FRAME
    return BOUNDS_RELATIVE if rb.bounds_mode == "relative" else BOUNDS_ABSOLUTE


def kernel_for(mode: int):
    """The compiled loop for *mode*: the paper's Algorithm 1 or its goal-frame variant."""
    if mode == GOAL_FRAME:
        from xfuzzy_rrt.planners.goal_frame import goal_frame_kernel

        return goal_frame_kernel
    return fuzzy_rrt_kernel


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


@nb.njit(cache=True, nogil=True, inline="always")
def record_iteration(row, tr_from, tr_x, tr_y, tr_box, tr_goal_sampled, tr_sample, tr_nearest,
                     tr_new, tr_outcome, tr_node, tr_tree, from_node, x, y, box_lo0, box_hi0,
                     box_lo1, box_hi1, goal_sampled, sx, sy, nearest_node, q_new, outcome,
                     new_index, tree_size):
    """Write trace row *row* (shared by every Fuzzy-RRT kernel, so traces mean one thing)."""
    tr_from[row] = from_node
    for k in range(x.shape[0]):
        tr_x[row, k] = x[k]
    for k in range(y.shape[0]):
        tr_y[row, k] = y[k]
    tr_box[row, 0] = box_lo0
    tr_box[row, 1] = box_hi0
    tr_box[row, 2] = box_lo1
    tr_box[row, 3] = box_hi1
    tr_goal_sampled[row] = goal_sampled
    tr_sample[row, 0] = sx
    tr_sample[row, 1] = sy
    tr_nearest[row] = nearest_node
    tr_new[row, 0] = q_new[0]
    tr_new[row, 1] = q_new[1]
    tr_outcome[row] = outcome
    tr_node[row] = new_index
    tr_tree[row] = tree_size


@nb.njit(cache=True, nogil=True)
def fuzzy_rrt_kernel(links, base, radius, obstacles, limits, start, goal, seed, max_iter,
                     knots, consts, bounds_mode, min_step, margin,
                     nodes, parent, cell_next, cell_head, meta, grid,
                     record, tr_from, tr_x, tr_y, tr_box, tr_goal_sampled, tr_sample,
                     tr_nearest, tr_new, tr_outcome, tr_node, tr_tree, tr_rule, tr_w):
    """Run Fuzzy-RRT; return ``(success, iterations, index of the last path node or -1)``.

    With ``record`` true, row ``it - 1`` of every ``tr_*`` array describes iteration ``it``;
    otherwise the ``tr_*`` arrays are never touched (pass 1-row dummies).
    """
    state = np.empty(4, dtype=np.uint64)
    seed_state(seed, state)
    x = np.empty(4, dtype=np.float64)
    y = np.empty(N_OUTPUTS, dtype=np.float64)
    dummy_rule = np.empty((N_OUTPUTS, MAX_FIRED), dtype=np.int32)
    dummy_w = np.empty((N_OUTPUTS, MAX_FIRED), dtype=np.float64)
    q_near = np.empty(2, dtype=np.float64)
    q_new = np.empty(2, dtype=np.float64)
    gx_ws, gy_ws = end_effector(links, base, goal)
    no_obstacle_dist = knots[0, 3, 4]

    add_node(nodes, parent, cell_next, cell_head, meta, grid, start[0], start[1], -1)
    current = 0  # the paper's nearest_node: the start at iteration 1
    for it in range(1, max_iter + 1):
        row = it - 1
        # 1-2. Fuzzy inputs from the current node's end effector.
        ex, ey = end_effector(links, base, nodes[current])
        if obstacles.shape[0] > 0:
            d_obs, a_obs, _ = nearest_obstacle_from_point(ex, ey, obstacles)
        else:
            d_obs = no_obstacle_dist
            a_obs = 0.0
        d_goal, a_goal = direction_and_distance(ex, ey, gx_ws, gy_ws)
        x[0] = a_goal
        x[1] = d_goal
        x[2] = a_obs
        x[3] = d_obs
        # 3. Six TSK systems.
        if record:
            infer(knots, consts, x, y, tr_rule[row], tr_w[row], True)
        else:
            infer(knots, consts, x, y, dummy_rule, dummy_w, False)
        bias = y[0]
        off0 = 0.0
        off1 = 0.0
        if bounds_mode == BOUNDS_RELATIVE:
            off0 = nodes[current, 0]
            off1 = nodes[current, 1]
        lo0, hi0 = _interval(y[1], y[2], off0, limits[0, 0], limits[0, 1])
        lo1, hi1 = _interval(y[3], y[4], off1, limits[1, 0], limits[1, 1])
        step = max(y[5], min_step)
        # 4. Sample.
        goal_sampled = uniform(state) < bias
        if goal_sampled:
            sx = goal[0]
            sy = goal[1]
        else:
            sx = lo0 + uniform(state) * (hi0 - lo0)
            sy = lo1 + uniform(state) * (hi1 - lo1)
        # 5. Nearest node (carried to the next iteration) and steering.
        from_node = current
        current = nearest(nodes, cell_next, cell_head, meta, grid, sx, sy)
        # 6-7. Steer, certify, grow, try the goal (shared with RRT).
        outcome, new_index = extend(links, base, radius, obstacles, limits, goal, margin,
                                    nodes, parent, cell_next, cell_head, meta, grid, current,
                                    sx, sy, step, q_near, q_new)
        if record:
            record_iteration(row, tr_from, tr_x, tr_y, tr_box, tr_goal_sampled, tr_sample,
                             tr_nearest, tr_new, tr_outcome, tr_node, tr_tree, from_node, x, y,
                             lo0, hi0, lo1, hi1, goal_sampled, sx, sy, current, q_new, outcome,
                             new_index, meta[0])
        if outcome == GOAL_REACHED:
            return True, it, new_index
    return False, max_iter, -1


class _TraceBuffers:
    """Preallocated per-iteration arrays the kernel fills when tracing (1-row dummies if not)."""

    def __init__(self, rows: int):
        # np.empty, not zeros: the kernel writes every field of every row it records, and
        # untouched pages of a 10,000-row buffer then cost nothing.
        self.from_node = np.empty(rows, dtype=np.int64)
        self.x = np.empty((rows, 4))
        self.y = np.empty((rows, N_OUTPUTS))
        self.box = np.empty((rows, 4))
        self.goal_sampled = np.empty(rows, dtype=np.bool_)
        self.sample = np.empty((rows, 2))
        self.nearest = np.empty(rows, dtype=np.int64)
        self.new = np.empty((rows, 2))
        self.outcome = np.empty(rows, dtype=np.int8)
        self.node = np.empty(rows, dtype=np.int64)
        self.tree = np.empty(rows, dtype=np.int64)
        self.rule = np.empty((rows, N_OUTPUTS, MAX_FIRED), dtype=np.int32)
        self.w = np.empty((rows, N_OUTPUTS, MAX_FIRED))

    def args(self):
        return (self.from_node, self.x, self.y, self.box, self.goal_sampled, self.sample,
                self.nearest, self.new, self.outcome, self.node, self.tree, self.rule, self.w)


def _resolve_rulebook(rulebook):
    """A loaded rulebook as given, else the (cached) directory or shipped default."""
    from xfuzzy_rrt.fuzzy.rulebook import default_rulebook_path, load_rulebook_cached

    if rulebook is None:
        rulebook = default_rulebook_path()
    if hasattr(rulebook, "compiled"):
        return rulebook
    return load_rulebook_cached(rulebook)


def plan_fuzzy_rrt(scenario: Scenario, rulebook=None, seed: int = 0, max_iter: int = 10_000,
                   trace: bool = False, min_step_deg: float = MIN_STEP_DEG,
                   margin: float | None = None, clearance_m: float | None = None) -> PlanResult:
    """Plan with Fuzzy-RRT.

    ``rulebook`` is a loaded :class:`~xfuzzy_rrt.fuzzy.rulebook.Rulebook`, a rulebook directory,
    or ``None`` for the shipped default. With ``trace=True`` the result carries a per-iteration
    DataFrame (see :mod:`xfuzzy_rrt.planners.trace`). Same inputs and seed, same result.
    ``clearance_m``/``margin`` as for :func:`~xfuzzy_rrt.planners.rrt.plan_rrt`.
    """
    check_planar_2dof(scenario)
    margin = planning_margin(scenario, clearance_m, margin)
    check_max_iter(max_iter)
    rb = _resolve_rulebook(rulebook)
    knots, consts = rb.compiled
    mode = kernel_mode(rb)
    kernel = kernel_for(mode)
    a = scenario.arrays()
    tree = Tree(int(max_iter) + 2, a.limits_deg)
    buffers = _TraceBuffers(int(max_iter) if trace else 1)
    t0 = time.perf_counter()
    ok, iterations, last = kernel(
        a.links, a.base, a.link_radius, a.obstacles, a.limits_deg, a.start_deg, a.goal_deg,
        int(seed), int(max_iter), knots, consts, mode, float(min_step_deg), float(margin),
        tree.nodes, tree.parent, tree.cell_next, tree.cell_head, tree.meta, tree.grid,
        bool(trace), *buffers.args())
    wall = time.perf_counter() - t0
    n = int(tree.meta[0])
    path = extract_path(tree.nodes, tree.parent, last) if ok else np.zeros((0, 2))
    from xfuzzy_rrt.planners.result import certified_result  # certifies the path (found -> success)

    result = certified_result(
        a, margin, bool(ok), scenario=scenario.name, planner="fuzzy-rrt", seed=int(seed),
        iterations=int(iterations), nodes=n,
        cost_deg=path_cost_deg(path) if ok else None, wall_s=wall, path_deg=path,
        tree_nodes_deg=tree.nodes[:n].copy(), tree_parent=tree.parent[:n].copy(),
        rulebook=rb.name, rulebook_sha256=rb.sha256,
        params={"max_iter": int(max_iter), "semantics": rb.semantics.name, "bounds": rb.bounds_mode,
                "min_step_deg": float(min_step_deg), "margin_m": float(margin)},
    )
    if trace:
        from xfuzzy_rrt.planners.trace import trace_frame

        frame = trace_frame(buffers, int(iterations), tree.nodes[:n], tree.parent[:n], last, rb,
                            float(min_step_deg))
        result = dataclasses.replace(result, trace=frame)
    return result
