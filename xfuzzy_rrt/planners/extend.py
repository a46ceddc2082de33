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

from xfuzzy_rrt.geometry.collision import (
    clearance_into,
    edge_free_rows,
    edge_free_two_link,
    n_distance_pairs,
    node_stop_into,
    stop_record_into,
    stop_width,
    two_link_clearances,
    within_limits,
)
from xfuzzy_rrt.planners.result import (
    ACCEPTED,
    EDGE_BLOCKED,
    GOAL_REACHED,
    NO_PROGRESS,
    NODE_IN_COLLISION,
)
from xfuzzy_rrt.planners.tree import N_NODES, add_node


@nb.njit(cache=True, nogil=True, inline="always")
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
    if dof == 2 and P.arm_first.shape[0] == 2:
        return _extend_two_link(P, T, near, step, q_near, q_new)
    # Stop records (a tree made with ``stops = stop_width(P)``: make_tree): the new node's is
    # measured by its node check into the row it will take, and the edge takes its two ends
    # from the near node's record and that one instead of measuring them again.
    rows = T.link_clear
    n = T.meta[N_NODES]
    # (never into the goal's row: a full tree, which no planner extends, measures as before)
    records = rows.shape[1] == stop_width(P) and n < rows.shape[0] - 1
    if records:
        c_new = node_stop_into(P, q_new, T.seg, T.mks, T.msf, rows, n)
    else:
        c_new = clearance_into(P, q_new, T.seg)
    if not c_new > P.margin:
        return NODE_IN_COLLISION, -1
    ra = near if records else -1
    rb = n if records else -1
    if not edge_free_rows(P, q_near, q_new, P.margin, T.seg, T.mks, T.msf, rows, ra, rb):
        return EDGE_BLOCKED, -1
    k = add_node(T, q_new, near)  # k == n: its record is already in place
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
    if math.sqrt(g2) <= step:
        rg = -1
        if records:  # the goal's record, measured once per run into the last row
            rg = rows.shape[0] - 1
            if not rows[rg, 0] == 1.0:
                stop_record_into(P, P.goal, T.seg, T.mks, T.msf, rows, rg)
        if edge_free_rows(P, q_new, P.goal, P.margin, T.seg, T.mks, T.msf, rows, rb, rg):
            g = add_node(T, P.goal, k)
            T.clear[g] = np.nan
            if records:
                rows[g, 0] = np.nan  # no record measured at this index in this run
            return GOAL_REACHED, g
    return ACCEPTED, k


@nb.njit(cache=True, nogil=True, inline="always")
def _extend_two_link(P, T, near, step, q_near, q_new):
    """:func:`extend` from the node check on, for one two-link arm (every 2-DOF problem).

    The same checks on the same floats in the same order, hence the same outcome, tree and
    ``P.work``; what changes is that no clearance is measured twice. The node check measures
    ``q_new`` per link (:func:`~xfuzzy_rrt.geometry.collision.two_link_clearances`), which is
    the edge's last stop; the near node's values, kept in ``T.link_clear`` when it was
    accepted (or measured at its first edge: the root), are the edge's first stop; the goal's
    are measured once per run. ``T`` must have been grown on ``P``'s geometry (as every
    planner does: one problem per run).
    """
    C = T.link_clear
    c0, c1 = two_link_clearances(P, q_new[0], q_new[1])
    P.work[0] += n_distance_pairs(P)
    c_new = min(min(np.inf, c0), c1)  # clearance_kernel's arithmetic
    if not c_new > P.margin:
        return NODE_IN_COLLISION, -1
    free, a0, a1 = edge_free_two_link(P, q_near, q_new, P.margin, C[near, 0], C[near, 1], c0, c1)
    C[near, 0] = a0
    C[near, 1] = a1
    if not free:
        return EDGE_BLOCKED, -1
    k = add_node(T, q_new, near)
    T.clear[k] = c_new
    C[k, 0] = c0
    C[k, 1] = c1
    goal = P.goal
    if q_new[0] == goal[0] and q_new[1] == goal[1]:
        return GOAL_REACHED, k
    g0 = goal[0] - q_new[0]
    g1 = goal[1] - q_new[1]
    if math.sqrt(0.0 + g0 * g0 + g1 * g1) <= step:
        gi = C.shape[0] - 1
        if not C[gi, 0] == C[gi, 0]:  # the goal, measured once per run
            C[gi, 0], C[gi, 1] = two_link_clearances(P, goal[0], goal[1])
        free, _, _ = edge_free_two_link(P, q_new, goal, P.margin, c0, c1, C[gi, 0], C[gi, 1])
        if free:
            g = add_node(T, goal, k)
            T.clear[g] = np.nan
            return GOAL_REACHED, g
    return ACCEPTED, k


@nb.njit(cache=True, nogil=True, _nrt=False)
def node_clearance(P, T, i):
    """``clearance_kernel(P, T.nodes[i])`` (same value, same work), keeping a two-link arm's
    per-link values, or any other arm's stop record (a tree with records: :func:`extend`), in
    ``T.link_clear`` for the edges that will leave node ``i``."""
    q = T.nodes[i]
    if q.shape[0] == 2 and P.arm_first.shape[0] == 2:
        c0, c1 = two_link_clearances(P, q[0], q[1])
        P.work[0] += n_distance_pairs(P)
        T.link_clear[i, 0] = c0
        T.link_clear[i, 1] = c1
        return min(min(np.inf, c0), c1)
    if T.link_clear.shape[1] == stop_width(P):  # and its stop record (extend)
        return node_stop_into(P, q, T.seg, T.mks, T.msf, T.link_clear, i)
    return clearance_into(P, q, T.seg)


@nb.njit(cache=True, nogil=True, inline="always")
def join_start_at_goal(P, T):
    """When the start *is* the goal, the path is ``[start, goal]``, of length zero: add the goal
    as the root's child and return its index (a planner returns success after 0 iterations);
    otherwise -1, and nothing is measured or added.

    Why: a problem that asks the arm to stay where it is got a path that went away and came back
    (166 deg from ``fuzzy-rrt``, 14 deg from ``rrt``), because a planner only looks for the goal
    at the nodes it adds, never at the root. The zero-length edge is certified as every node is:
    the start's clearance (:func:`node_clearance`, counted in the work) must exceed the margin;
    a start that does not keep it returns -1, and the run goes on as before (it can find no
    path). ``T`` holds only the root."""
    for j in range(P.start.shape[0]):
        if P.start[j] != P.goal[j]:
            return -1
    c = node_clearance(P, T, T.meta[0] - 1)  # the root (not the constant 0: connect.py)
    if not c > P.margin:
        return -1
    g = add_node(T, P.goal, 0)
    T.clear[g] = c
    return g
