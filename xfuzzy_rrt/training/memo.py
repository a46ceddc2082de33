"""The paper-semantics Fuzzy-RRT loop with its pure per-node work remembered, for training.

Why a second loop: a paper-scale generation is about three million planner iterations, and
profiling the GA's population (``benchmarks/generation.py``) shows where they go. Long runs
revisit the same ``current`` node (the paper's ``nearest_node``) again and again — across the
benchmark's costliest runs only a third of the iterations start from a node not seen before —
and a run stuck against an obstacle with a high goal bias samples the goal from the same
nearest node with the same step thousands of times, repeating an extension that was already
rejected. Both are pure functions of values the loop already has:

- the fuzzy outputs an iteration uses (goal bias, the clipped sampling box, the step) depend
  only on the node ``q = T.nodes[current]`` (its end effector, nearest obstacle, the goal, the
  rulebook); they are computed once per node and read back afterwards;
- :func:`~xfuzzy_rrt.planners.tree.nearest` of the goal depends only on the tree, and a tree
  only grows: the goal's nearest node is kept up to date as each node joins (the new node
  wins only when strictly nearer, by the same distance arithmetic, so ties still go to the
  lowest index) instead of being searched for on every goal sample;
- :func:`~xfuzzy_rrt.planners.extend.extend` from node ``n`` towards the goal with step ``s``
  that added nothing will add nothing again (it reads only ``n``, the goal, ``s`` and the
  problem), so its outcome is reused for the same ``(n, s)``.

Everything else — the random draws, their order, the box samples, every extension that can add
a node — is :func:`~xfuzzy_rrt.planners.fuzzy_rrt.fuzzy_rrt_kernel`'s, calling the same
compiled functions, so ``(success, iterations)`` are identical to the planner's for every
rulebook and seed (tested against the planner's kernel on trained, seeded and random
genomes, one and two arms, absolute and relative bounds). The loop records no trace and
never reads a stop flag: training has neither.
"""

from __future__ import annotations

import numba as nb
import numpy as np

from xfuzzy_rrt.fuzzy.engine import infer
from xfuzzy_rrt.fuzzy.variables import MAX_FIRED
from xfuzzy_rrt.geometry.kinematics import arm_end_effector
from xfuzzy_rrt.planners.extend import extend, join_start_at_goal
from xfuzzy_rrt.planners.fuzzy_rrt import BOUNDS_RELATIVE, _interval, arm_inputs
from xfuzzy_rrt.planners.result import ACCEPTED, GOAL_REACHED
from xfuzzy_rrt.planners.rng import seed_state, uniform
from xfuzzy_rrt.planners.tree import _d2, add_node, nearest, reset_tree

#: Columns of the per-node memo before the box: goal bias, step.
_BIAS, _STEP, _BOX = 0, 1, 2


@nb.njit(cache=True, nogil=True, _nrt=False)
def paper_run(P, T, seed, max_iter, knots, consts, bounds_mode, min_step, memo, seen,
              goal_step, goal_outcome, stamp, state, x, y, dummy_rule, dummy_w, sample, q_near,
              q_new, goal_ws):
    """``(success, iterations)`` of one Fuzzy-RRT run, as
    :func:`~xfuzzy_rrt.planners.fuzzy_rrt.fuzzy_rrt_kernel` gives them.

    ``T`` is an empty tree; ``memo`` [capacity, 2 + 2 dof], ``seen``, ``goal_step``,
    ``goal_outcome`` [capacity] are scratch buffers reused across runs: an entry belongs to
    this run only where ``seen`` (for the outputs) or ``goal_outcome`` (for goal extensions,
    stored as ``stamp * 8 + outcome``) carries this run's ``stamp`` (unique per run of one set
    of buffers), so nothing is cleared between runs. ``state`` ... ``goal_ws`` are the loop's
    scratch buffers, allocated once per population by :func:`paper_population`: the loop is
    compiled without reference counting (``_nrt=False``) and may not allocate.
    """
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
        return True, 0
    current = 0
    goal_near = 0  # nearest(T, goal), kept up to date as nodes join
    goal_d2 = _d2(T.nodes, 0, P.goal)
    for it in range(1, max_iter + 1):
        if seen[current] != stamp:
            # 1-3: the fuzzy outputs at this node (fuzzy_rrt_kernel's arithmetic, in its order)
            q = T.nodes[current]
            bias_sum = 0.0
            step_min = np.inf
            for a in range(n_arms):
                a_goal, d_goal, a_obs, d_obs = arm_inputs(P, a, q, goal_ws, has_obstacles,
                                                          no_obstacle_dist)
                x[0] = a_goal
                x[1] = d_goal
                x[2] = a_obs
                x[3] = d_obs
                infer(knots, consts, x, y, dummy_rule, dummy_w, False)
                bias_sum += y[0]
                if y[n_out - 1] < step_min:
                    step_min = y[n_out - 1]
                f = P.arm_first[a]
                for jl in range(P.arm_first[a + 1] - f):
                    j = f + jl
                    off = 0.0
                    if bounds_mode == BOUNDS_RELATIVE:
                        off = q[j]
                    lo, hi = _interval(y[1 + 2 * jl], y[2 + 2 * jl], off, P.limits[j, 0],
                                       P.limits[j, 1])
                    memo[current, _BOX + 2 * j] = lo
                    memo[current, _BOX + 2 * j + 1] = hi
            memo[current, _BIAS] = bias_sum / n_arms
            memo[current, _STEP] = max(step_min, min_step)
            seen[current] = stamp
        bias = memo[current, _BIAS]
        step = memo[current, _STEP]
        # 4. Sample (the same draws in the same order).
        if uniform(state) < bias:
            current = goal_near
            if goal_outcome[current] // 8 == stamp and goal_step[current] == step:
                continue  # this extension was tried and added nothing: it adds nothing now
            outcome, k = extend(P, T, current, P.goal, step, q_near, q_new)
            if outcome == GOAL_REACHED:
                return True, it
            if outcome != ACCEPTED:
                goal_step[current] = step
                goal_outcome[current] = stamp * 8 + outcome
        else:
            for j in range(dof):
                lo = memo[current, _BOX + 2 * j]
                sample[j] = lo + uniform(state) * (memo[current, _BOX + 2 * j + 1] - lo)
            # 5-7. Nearest node (carried to the next iteration), steer, certify, grow.
            current = nearest(T, sample)
            outcome, k = extend(P, T, current, sample, step, q_near, q_new)
            if outcome == GOAL_REACHED:
                return True, it
        if outcome == ACCEPTED:
            # node k joined: the goal's nearest node changes only if k is strictly nearer
            # (ties keep the lower index, as nearest() does), by nearest()'s own distance
            d2 = _d2(T.nodes, k, P.goal)
            if d2 < goal_d2:
                goal_near = k
                goal_d2 = d2
    return False, max_iter


@nb.njit(cache=True, nogil=True, _nrt=True)
def paper_population(P, T, knots_b, consts_b, bounds_mode, seeds, max_iter, min_step):
    """Iterations int64[n, R] (``-1`` = failed) of every (individual, seed) run of the paper's
    semantics (absolute or relative bounds): one compiled call for a whole chunk.

    ``T`` is one preallocated empty tree (emptied again before each run); the memo buffers
    are allocated once here and shared by all runs through per-run stamps.
    """
    n_ind = knots_b.shape[0]
    n_seeds = seeds.shape[0]
    out = np.empty((n_ind, n_seeds), dtype=np.int64)
    meta0 = T.meta.copy()
    cap = T.nodes.shape[0]
    memo = np.empty((cap, _BOX + 2 * T.nodes.shape[1]), dtype=np.float64)
    seen = np.zeros(cap, dtype=np.int64)
    goal_step = np.empty(cap, dtype=np.float64)
    goal_outcome = np.zeros(cap, dtype=np.int64)
    stamp = 0
    n_out = knots_b.shape[1]
    dof = T.nodes.shape[1]
    state = np.empty(4, dtype=np.uint64)
    x = np.empty(4, dtype=np.float64)
    y = np.empty(n_out, dtype=np.float64)
    dummy_rule = np.empty((n_out, MAX_FIRED), dtype=np.int32)
    dummy_w = np.empty((n_out, MAX_FIRED), dtype=np.float64)
    sample = np.empty(dof, dtype=np.float64)
    q_near = np.empty(dof, dtype=np.float64)
    q_new = np.empty(dof, dtype=np.float64)
    goal_ws = np.empty((P.arm_first.shape[0] - 1, 2), dtype=np.float64)
    for p in range(n_ind):
        for r in range(n_seeds):
            reset_tree(T, meta0)
            stamp += 1
            ok, iterations = paper_run(P, T, seeds[r], max_iter, knots_b[p], consts_b[p],
                                       bounds_mode, min_step, memo, seen, goal_step,
                                       goal_outcome, stamp, state, x, y, dummy_rule, dummy_w,
                                       sample, q_near, q_new, goal_ws)
            out[p, r] = iterations if ok else -1
    return out
