"""One tree extension, shared by RRT and Fuzzy-RRT (steps 5–7 of the paper's Algorithm 1).

Steer from a tree node towards a sample by at most ``step`` degrees, reject the new
configuration if it is in collision or the edge to it is not certified free, otherwise add it
and try to join the goal: done when the new node *is* the goal, or when the goal lies within
``step`` and that edge is certified free. Keeping this in one place guarantees that
``iterations`` and the safety checks mean exactly the same for both planners.
"""

from __future__ import annotations

import math

import numba as nb

from xfuzzy_rrt.geometry.collision import config_free, edge_free
from xfuzzy_rrt.planners.result import (
    ACCEPTED,
    EDGE_BLOCKED,
    GOAL_REACHED,
    NO_PROGRESS,
    NODE_IN_COLLISION,
)
from xfuzzy_rrt.planners.tree import add_node


@nb.njit(cache=True, nogil=True)
def extend(links, base, radius, obstacles, limits, goal, margin,
           nodes, parent, cell_next, cell_head, meta, grid, near, sx, sy, step, q_near, q_new):
    """Extend the tree from node ``near`` towards ``(sx, sy)``.

    Writes the near and new configurations into ``q_near``/``q_new`` and returns
    ``(outcome, index)``: the index of the last node added (the goal on success) or -1.
    """
    q_near[0] = nodes[near, 0]
    q_near[1] = nodes[near, 1]
    dx = sx - q_near[0]
    dy = sy - q_near[1]
    d = math.sqrt(dx * dx + dy * dy)
    if d == 0.0:
        q_new[0] = q_near[0]
        q_new[1] = q_near[1]
        return NO_PROGRESS, -1
    if d <= step:
        q_new[0] = sx
        q_new[1] = sy
    else:
        q_new[0] = q_near[0] + dx * (step / d)
        q_new[1] = q_near[1] + dy * (step / d)
    if not config_free(links, base, radius, obstacles, limits, q_new, margin):
        return NODE_IN_COLLISION, -1
    if not edge_free(links, base, radius, obstacles, q_near, q_new, margin):
        return EDGE_BLOCKED, -1
    k = add_node(nodes, parent, cell_next, cell_head, meta, grid, q_new[0], q_new[1], near)
    if q_new[0] == goal[0] and q_new[1] == goal[1]:
        return GOAL_REACHED, k
    gx = goal[0] - q_new[0]
    gy = goal[1] - q_new[1]
    if math.sqrt(gx * gx + gy * gy) <= step and edge_free(
            links, base, radius, obstacles, q_new, goal, margin):
        g = add_node(nodes, parent, cell_next, cell_head, meta, grid, goal[0], goal[1], k)
        return GOAL_REACHED, g
    return ACCEPTED, k
