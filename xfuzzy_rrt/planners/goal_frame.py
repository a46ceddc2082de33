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
from xfuzzy_rrt.fuzzy.variables import MAX_FIRED, N_OUTPUTS
from xfuzzy_rrt.geometry.collision import clearance_kernel
from xfuzzy_rrt.planners.extend import extend
from xfuzzy_rrt.planners.fuzzy_rrt import record_iteration
from xfuzzy_rrt.planners.result import ACCEPTED, EDGE_BLOCKED, GOAL_REACHED, NODE_IN_COLLISION
from xfuzzy_rrt.planners.rng import seed_state, uniform
from xfuzzy_rrt.planners.tree import add_node, nearest

#: Weight of the newest outcome in ``reject_rate`` (about the last ten extensions count).
REJECT_DECAY = 0.9


@nb.njit(cache=True, nogil=True, inline="always")
def _clamp(v, lo, hi):
    return min(max(v, lo), hi)


@nb.njit(cache=True, nogil=True)
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


@nb.njit(cache=True, nogil=True)
def goal_frame_kernel(links, base, radius, obstacles, limits, start, goal, seed, max_iter,
                      knots, consts, unused_mode, min_step, margin,
                      nodes, parent, cell_next, cell_head, meta, grid,
                      record, tr_from, tr_x, tr_y, tr_box, tr_goal_sampled, tr_sample,
                      tr_nearest, tr_new, tr_outcome, tr_node, tr_tree, tr_rule, tr_w):
    """Run goal-frame Fuzzy-RRT; return ``(success, iterations, index of the last path node or -1)``.

    Same signature as :func:`xfuzzy_rrt.planners.fuzzy_rrt.fuzzy_rrt_kernel` (``unused_mode``
    stands where the paper's bounds mode is), so callers and traces treat both alike.
    """
    state = np.empty(4, dtype=np.uint64)
    seed_state(seed, state)
    x = np.empty(4, dtype=np.float64)
    y = np.empty(N_OUTPUTS, dtype=np.float64)
    dummy_rule = np.empty((N_OUTPUTS, MAX_FIRED), dtype=np.int32)
    dummy_w = np.empty((N_OUTPUTS, MAX_FIRED), dtype=np.float64)
    q_near = np.empty(2, dtype=np.float64)
    q_new = np.empty(2, dtype=np.float64)
    deg_per_m = math.degrees(1.0) / arm_lever(links)
    clear_top = knots[0, 2, 4]  # no obstacles: clearance saturates at the top of its range
    lo0 = limits[0, 0]
    hi0 = limits[0, 1]
    lo1 = limits[1, 0]
    hi1 = limits[1, 1]

    add_node(nodes, parent, cell_next, cell_head, meta, grid, start[0], start[1], -1)
    current = 0
    best = math.hypot(goal[0] - start[0], goal[1] - start[1])
    stagnation = 0.0
    reject = 0.0
    for it in range(1, max_iter + 1):
        row = it - 1
        qx = nodes[current, 0]
        qy = nodes[current, 1]
        gx = goal[0] - qx
        gy = goal[1] - qy
        d_goal = math.hypot(gx, gy)
        if obstacles.shape[0] > 0:
            c = clearance_kernel(links, base, radius, obstacles, nodes[current])
            c_deg = max(c, 0.0) * deg_per_m
        else:
            c_deg = clear_top
        x[0] = d_goal
        x[1] = stagnation
        x[2] = c_deg
        x[3] = reject
        if record:
            infer(knots, consts, x, y, tr_rule[row], tr_w[row], True)
        else:
            infer(knots, consts, x, y, dummy_rule, dummy_w, False)
        step = max(y[5], min_step)
        goal_sampled = uniform(state) < y[0]
        if goal_sampled:
            sx = goal[0]
            sy = goal[1]
            bx0, bx1, by0, by1 = goal[0], goal[0], goal[1], goal[1]
        elif uniform(state) < y[1]:
            sx = lo0 + uniform(state) * (hi0 - lo0)
            sy = lo1 + uniform(state) * (hi1 - lo1)
            bx0, bx1, by0, by1 = lo0, hi0, lo1, hi1
        else:
            if d_goal > 0.0:
                ex = gx / d_goal
                ey = gy / d_goal
            else:
                ex = 1.0
                ey = 0.0
            ahead = y[2]
            behind = y[3]
            side = y[4]
            a = -behind + uniform(state) * (ahead + behind)
            b = (2.0 * uniform(state) - 1.0) * side
            sx = _clamp(qx + a * ex - b * ey, lo0, hi0)
            sy = _clamp(qy + a * ey + b * ex, lo1, hi1)
            # bounding box of the rotated box (for traces and drawings), clipped
            hx = abs(ex) * 0.5 * (ahead + behind) + abs(ey) * side
            hy = abs(ey) * 0.5 * (ahead + behind) + abs(ex) * side
            cx = qx + ex * 0.5 * (ahead - behind)
            cy = qy + ey * 0.5 * (ahead - behind)
            bx0 = _clamp(cx - hx, lo0, hi0)
            bx1 = _clamp(cx + hx, lo0, hi0)
            by0 = _clamp(cy - hy, lo1, hi1)
            by1 = _clamp(cy + hy, lo1, hi1)
        from_node = current
        current = nearest(nodes, cell_next, cell_head, meta, grid, sx, sy)
        outcome, new_index = extend(links, base, radius, obstacles, limits, goal, margin,
                                    nodes, parent, cell_next, cell_head, meta, grid, current,
                                    sx, sy, step, q_near, q_new)
        rejected = 1.0 if (outcome == NODE_IN_COLLISION or outcome == EDGE_BLOCKED) else 0.0
        reject = REJECT_DECAY * reject + (1.0 - REJECT_DECAY) * rejected
        stagnation += 1.0
        if outcome == ACCEPTED:
            d_new = math.hypot(goal[0] - q_new[0], goal[1] - q_new[1])
            if d_new < best:
                best = d_new
                stagnation = 0.0
        if record:
            record_iteration(row, tr_from, tr_x, tr_y, tr_box, tr_goal_sampled, tr_sample,
                             tr_nearest, tr_new, tr_outcome, tr_node, tr_tree, from_node, x, y,
                             bx0, bx1, by0, by1, goal_sampled, sx, sy, current, q_new, outcome,
                             new_index, meta[0])
        if outcome == GOAL_REACHED:
            return True, it, new_index
    return False, max_iter, -1
