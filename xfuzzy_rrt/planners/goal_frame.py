"""Fuzzy-RRT with the *goal-frame* rulebook semantics (see :mod:`xfuzzy_rrt.fuzzy.semantics`).

The loop is the paper's Algorithm 1 (same tree, same nearest-node carry-over, same extension
and certified checks, same ``iterations``); only what the six systems read and what their
outputs mean differ. Each iteration, top to bottom in :func:`goal_frame_kernel`:

1. Inputs at the current node ``q`` (the paper's ``nearest_node``):
   ``joint_dist_to_goal`` = ``|goal - q|`` (deg); ``stagnation`` = iterations since the tree's
   closest approach to the goal last improved; ``clearance_deg`` = the arm's clearance at ``q``
   (m) divided by ``lever`` (m per radian of joint-space motion, the Cauchy-Schwarz bound
   ``sqrt(Σ_j (Σ_{i>=j} l_i)^2)`` on how fast any arm point moves), in degrees: within that
   joint-space radius no link can reach an obstacle; ``reject_rate`` = exponentially weighted
   (factor ``REJECT_DECAY``) share of rejected extensions.
2. Six TSK systems give ``goal_bias, uniform_share, ahead_deg, behind_deg, side_deg, step_deg``.
3. Sample: the goal with probability ``goal_bias``; else, with probability ``uniform_share``,
   uniformly over the joint limits (the escape from traps); else uniformly in the goal-frame
   box around ``q``: ``q + a·e + b·n`` with ``a ~ U(-behind, ahead)``, ``b ~ U(-side, side)``,
   ``e`` the unit joint-space direction from ``q`` to the goal and ``n`` its normal (``e`` is
   ``+q1`` at the goal itself). The sample is clamped to the joint limits.
4-7. Nearest node, steer by ``max(step_deg, min_step)``, certified checks, goal connection:
   :func:`xfuzzy_rrt.planners.extend.extend`, exactly as for RRT and the paper's semantics.

**Several joints, several arms.** The inputs are joint-space quantities, so they read the
joint space of all arms together: distances are Euclidean over every joint, ``clearance_deg``
counts the other arms' capsules as obstacles and divides by ``sqrt(Σ_arms lever_a^2)`` (a
Cauchy-Schwarz bound on how fast any point moves, for arm-obstacle and arm-arm distances alike),
and a rulebook's DOF is the total number of joints. With more than two joints the box's
"across" part is an ``N``-cube of half-width ``side`` with its component along ``e`` removed
(``N`` draws, joint by joint), and the traced box is a bounding box of the region (tight only
along the axes). With two joints every formula and draw is the 2-joint one exactly.

Random draws, in order: one uniform for the goal decision; for a non-goal sample one uniform for
the uniform-or-box decision, then two (joint 1, joint 2 / along, across).

Traces use the same buffers as the paper's kernel: inputs, outputs, fired rules, and as ``box``
the axis-aligned bounding box of the (clipped) sampling region — the whole joint space for a
uniform sample — so every drawing of a sampling box keeps working.
"""

from __future__ import annotations

import math

import numba as nb
import numpy as np

from xfuzzy_rrt.fuzzy.engine import infer
from xfuzzy_rrt.fuzzy.variables import MAX_FIRED
from xfuzzy_rrt.planners.extend import extend, join_start_at_goal, node_clearance
from xfuzzy_rrt.planners.result import ACCEPTED, EDGE_BLOCKED, GOAL_REACHED, NODE_IN_COLLISION
from xfuzzy_rrt.planners.rng import seed_state, uniform
from xfuzzy_rrt.planners.trace_record import record_iteration
from xfuzzy_rrt.planners.tree import add_node, nearest

#: Weight of the newest outcome in ``reject_rate`` (about the last ten extensions count).
REJECT_DECAY = 0.9


@nb.njit(cache=True, nogil=True, inline="always")
def _clamp(v, lo, hi):
    return min(max(v, lo), hi)


@nb.njit(cache=True, nogil=True, _nrt=False)
def arm_lever(links):
    """``sqrt(Σ_j (Σ_{i>=j} l_i)^2)``: metres an arm point moves at most per radian of
    Euclidean joint-space motion (joint ``j`` swings everything beyond it)."""
    total = 0.0
    for j in range(links.shape[0]):
        tail = 0.0
        for i in range(j, links.shape[0]):
            tail += links[i]
        total += tail * tail
    return math.sqrt(total)


@nb.njit(cache=True, nogil=True, _nrt=False)
def problem_lever(P):
    """:func:`arm_lever` over all arms: ``sqrt(Σ_arms Σ_j tail_j^2)`` bounds how fast any arm
    point, and any arm-arm distance, changes per radian of joint-space motion."""
    total = 0.0
    for a in range(P.arm_first.shape[0] - 1):
        f1 = P.arm_first[a + 1]
        for j in range(P.arm_first[a], f1):
            tail = 0.0
            for i in range(j, f1):
                tail += P.links[i]
            total += tail * tail
    return math.sqrt(total)


@nb.njit(cache=True, nogil=True, inline="always")
def _joint_dist(a, b):
    """Euclidean distance, as a chain of ``hypot`` (exactly ``hypot(dx, dy)`` for 2 joints)."""
    d = 0.0
    for j in range(a.shape[0]):
        d = math.hypot(d, b[j] - a[j])
    return d


@nb.njit(cache=True, nogil=True, inline="always")
def sample_goal_frame(q, goal, d_goal, y, limits, state, sample, box, e):
    """Step 3 of the module docstring: draw the sample of one goal-frame iteration.

    ``q`` is the current node, ``goal`` the configuration the box points at (the goal here;
    the other tree's newest node in :mod:`xfuzzy_rrt.planners.connect`), ``d_goal`` their
    distance and ``y`` the six outputs. Writes ``sample``, the traced bounding ``box`` and the
    direction ``e``; returns whether ``goal`` itself was sampled. Shared so that both planners
    draw the same random numbers in the same order for the same outputs.
    """
    dof = q.shape[0]
    goal_sampled = uniform(state) < y[0]
    if goal_sampled:
        for j in range(dof):
            sample[j] = goal[j]
            box[2 * j] = goal[j]
            box[2 * j + 1] = goal[j]
    elif uniform(state) < y[1]:
        for j in range(dof):
            sample[j] = limits[j, 0] + uniform(state) * (limits[j, 1] - limits[j, 0])
            box[2 * j] = limits[j, 0]
            box[2 * j + 1] = limits[j, 1]
    else:
        if d_goal > 0.0:
            for j in range(dof):
                e[j] = (goal[j] - q[j]) / d_goal
        else:
            for j in range(dof):
                e[j] = 0.0
            e[0] = 1.0
        ahead = y[2]
        behind = y[3]
        side = y[4]
        a = -behind + uniform(state) * (ahead + behind)
        if dof == 2:
            ex = e[0]
            ey = e[1]
            b = (2.0 * uniform(state) - 1.0) * side
            sample[0] = _clamp(q[0] + a * ex - b * ey, limits[0, 0], limits[0, 1])
            sample[1] = _clamp(q[1] + a * ey + b * ex, limits[1, 0], limits[1, 1])
            # bounding box of the rotated box (for traces and drawings), clipped
            hx = abs(ex) * 0.5 * (ahead + behind) + abs(ey) * side
            hy = abs(ey) * 0.5 * (ahead + behind) + abs(ex) * side
            cx = q[0] + ex * 0.5 * (ahead - behind)
            cy = q[1] + ey * 0.5 * (ahead - behind)
            box[0] = _clamp(cx - hx, limits[0, 0], limits[0, 1])
            box[1] = _clamp(cx + hx, limits[0, 0], limits[0, 1])
            box[2] = _clamp(cy - hy, limits[1, 0], limits[1, 1])
            box[3] = _clamp(cy + hy, limits[1, 0], limits[1, 1])
        else:
            # across: a cube of half-width ``side`` with its part along e removed
            proj = 0.0
            for j in range(dof):
                sample[j] = (2.0 * uniform(state) - 1.0) * side
                proj += sample[j] * e[j]
            e_l1 = 0.0
            for j in range(dof):
                e_l1 += abs(e[j])
            for j in range(dof):
                sample[j] = _clamp(q[j] + a * e[j] + sample[j] - proj * e[j],
                                   limits[j, 0], limits[j, 1])
                h = abs(e[j]) * 0.5 * (ahead + behind) + side * (1.0 + abs(e[j]) * e_l1)
                c0 = q[j] + e[j] * 0.5 * (ahead - behind)
                box[2 * j] = _clamp(c0 - h, limits[j, 0], limits[j, 1])
                box[2 * j + 1] = _clamp(c0 + h, limits[j, 0], limits[j, 1])
    return goal_sampled


@nb.njit(cache=True, nogil=True, _nrt=True)
def goal_frame_kernel(P, T, seed, max_iter, knots, consts, unused_mode, min_step, stop, TR):
    """Run goal-frame Fuzzy-RRT; return ``(success, iterations, index of the last path node or -1)``.

    Same signature as :func:`xfuzzy_rrt.planners.fuzzy_rrt.fuzzy_rrt_kernel` (``unused_mode``
    stands where the paper's bounds mode is; ``TR`` ``None``: no trace, and no trace code in
    the compiled loop), so callers and traces treat both alike.
    """
    n_out = knots.shape[0]
    dof = P.start.shape[0]
    # an uncounted loop (README, "No reference counting in the loops") borrows these buffers
    return _goal_frame_loop(
        P, T, seed, max_iter, knots, consts, min_step, stop, TR,
        np.empty(4, dtype=np.uint64), np.empty(4, dtype=np.float64),
        np.empty(n_out, dtype=np.float64), np.empty((n_out, MAX_FIRED), dtype=np.int32),
        np.empty((n_out, MAX_FIRED), dtype=np.float64), np.empty(2 * dof, dtype=np.float64),
        np.empty(dof, dtype=np.float64), np.empty(dof, dtype=np.float64),
        np.empty(dof, dtype=np.float64), np.empty(dof, dtype=np.float64))


@nb.njit(cache=True, nogil=True, _nrt=False)
def _goal_frame_loop(P, T, seed, max_iter, knots, consts, min_step, stop, TR, state, x, y,
                     dummy_rule, dummy_w, box, sample, e, q_near, q_new):
    """:func:`goal_frame_kernel`'s loop, given its scratch buffers."""
    seed_state(seed, state)
    n_out = knots.shape[0]
    dof = P.start.shape[0]
    goal = P.goal
    limits = P.limits
    deg_per_m = math.degrees(1.0) / problem_lever(P)
    clear_top = knots[0, 2, 4]  # nothing to hit: clearance saturates at the top of its range
    has_obstacles = P.obstacles.shape[0] > 0 or P.arm_first.shape[0] > 2

    root = add_node(T, P.start, -1)  # 0, not as a constant (connect.py: one compiled copy)
    g = join_start_at_goal(P, T)
    if g >= 0:
        return True, 0, g
    if has_obstacles:
        T.clear[root] = node_clearance(P, T, root)
    current = 0
    best = _joint_dist(P.start, goal)
    stagnation = 0.0
    reject = 0.0
    for it in range(1, max_iter + 1):
        if stop[0] != 0:
            return False, it - 1, -1
        row = it - 1
        q = T.nodes[current]
        d_goal = _joint_dist(q, goal)
        if has_obstacles:
            c = T.clear[current]  # measured when the node was accepted (extend)
            c_deg = max(c, 0.0) * deg_per_m
        else:
            c_deg = clear_top
        x[0] = d_goal
        x[1] = stagnation
        x[2] = c_deg
        x[3] = reject
        if TR is None:  # decided when compiled (see trace_record.py)
            infer(knots, consts, x, y, dummy_rule, dummy_w, False)
        else:
            infer(knots, consts, x, y, TR.rule[row], TR.w[row], True)
        step = max(y[5], min_step)
        goal_sampled = sample_goal_frame(q, goal, d_goal, y, limits, state, sample, box, e)
        from_node = current
        current = nearest(T, sample)
        outcome, new_index = extend(P, T, current, sample, step, q_near, q_new)
        rejected = 1.0 if (outcome == NODE_IN_COLLISION or outcome == EDGE_BLOCKED) else 0.0
        reject = REJECT_DECAY * reject + (1.0 - REJECT_DECAY) * rejected
        stagnation += 1.0
        if outcome == ACCEPTED:
            d_new = _joint_dist(q_new, goal)
            if d_new < best:
                best = d_new
                stagnation = 0.0
        if TR is not None:
            record_iteration(TR, row, from_node, x, y, box, goal_sampled, sample, current,
                             q_new, outcome, new_index, T.meta[0])
        if outcome == GOAL_REACHED:
            return True, it, new_index
    return False, max_iter, -1
