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
import numpy as np

from xfuzzy_rrt.geometry.collision import clearance_kernel, edge_free, within_limits
from xfuzzy_rrt.planners.result import (
    ACCEPTED,
    EDGE_BLOCKED,
    GOAL_REACHED,
    NO_PROGRESS,
    NODE_IN_COLLISION,
)
from xfuzzy_rrt.planners.tree import add_node


@nb.njit(cache=True, nogil=True)
def extend(P, T, near, sample, step, q_near, q_new):
    """Extend tree ``T`` from node ``near`` towards ``sample`` in problem ``P``.

    Writes the near and new configurations into ``q_near``/``q_new`` and returns
    ``(outcome, index)``: the index of the last node added (the goal on success) or -1.
    An added node's clearance goes to ``T.clear`` (the goal-frame kernel reads it as an input
    instead of measuring it again).
    Distances are Euclidean in joint space (degrees), over every joint of every arm.
    """
    dof = q_near.shape[0]
    d2 = 0.0
    for j in range(dof):
        q_near[j] = T.nodes[near, j]
        dj = sample[j] - q_near[j]
        d2 += dj * dj
    d = math.sqrt(d2)
    if d == 0.0:
        for j in range(dof):
            q_new[j] = q_near[j]
        return NO_PROGRESS, -1
    if d <= step:
        for j in range(dof):
            q_new[j] = sample[j]
    else:
        for j in range(dof):
            q_new[j] = q_near[j] + (sample[j] - q_near[j]) * (step / d)
    # config_free, spelt out so that the node keeps the clearance it was accepted with
    if not within_limits(P.limits, q_new):
        return NODE_IN_COLLISION, -1
    c_new = clearance_kernel(P, q_new)
    if not c_new > P.margin:
        return NODE_IN_COLLISION, -1
    if not edge_free(P, q_near, q_new, P.margin):
        return EDGE_BLOCKED, -1
    k = add_node(T, q_new, near)
    T.clear[k] = c_new
    at_goal = True
    g2 = 0.0
    for j in range(dof):
        if q_new[j] != P.goal[j]:
            at_goal = False
        gj = P.goal[j] - q_new[j]
        g2 += gj * gj
    if at_goal:
        return GOAL_REACHED, k
    if math.sqrt(g2) <= step and edge_free(P, q_new, P.goal, P.margin):
        g = add_node(T, P.goal, k)
        T.clear[g] = np.nan
        return GOAL_REACHED, g
    return ACCEPTED, k
