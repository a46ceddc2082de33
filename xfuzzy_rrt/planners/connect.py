"""Fuzzy-RRT-Connect: two goal-frame trees, one from the start and one from the goal, that
grow towards each other and try to join after every accepted extension (RRT-Connect, Kuffner
and LaValle, ICRA 2000, with the sampling decided by a goal-frame rulebook).

Each iteration, read top to bottom in :func:`connect_kernel`, grows one tree: **the one with
fewer nodes**, and on a tie the one that did not grow last (iteration 1 grows the start tree).
Why not strictly by turns (Kuffner and LaValle's swap): a tree whose root sits in a pocket
(every exit needs a short step in one direction) accepts few extensions and stays small, while
the other tree fills the space and its connects cannot enter the pocket; by turns, half the
budget went to the tree that did not need it. Growing the smaller tree ("balanced
bidirectional search", LaValle, *Planning Algorithms*, section 5.5.3) pours the iterations into
the stuck tree, and on trees that grow alike it is alternation. On problems no tuning saw
(generator seeds 5240, 5340 and 5440, 24 or 48 per family, 20-60 seeds), the tuned RRT's work
over this planner's rose in every family (geometric mean 1.69 -> 1.70 at 3 joints, 1.81 -> 1.89
at 5, 1.80 -> 1.86 at 7, 2.29 -> 2.41 with two 3-joint arms, 2.52 -> 2.61 with two 2-joint
arms; docs/peer-measurements.md, thirty-fifth session).

1. **Target**: the *other* tree's most recently added node. Why this one and not the other
   tree's node nearest to the growing tree: (a) after a CONNECT attempt the two newest nodes
   are the closest pair the last attempt produced -- the place where the trees nearly met, the
   gap to close; (b) it costs no nearest-neighbour query (queries dominate the time of large
   trees); (c) it moves whenever the other tree grows or a connect adds to it, so a tree
   stuck behind an obstacle sees its target move along the other tree's frontier instead of
   staring at one fixed point. (A smaller tree whose growth is refused keeps the iterations,
   and its target stays where it is until a connect adds to the other tree.)
2. **Inputs** of the goal-frame semantics (:mod:`xfuzzy_rrt.planners.goal_frame`), read
   relative to the target instead of the goal, at the growing tree's current node ``q`` (the
   node nearest to that tree's previous sample, its root at first -- the paper's carried
   ``nearest_node``, one per tree): ``joint_dist_to_goal`` = ``|target - q|``;
   ``stagnation`` = iterations (of both trees) since the gap between the two trees' newest
   nodes last shrank; ``clearance_deg`` at ``q`` (as measured when ``q`` was accepted, the
   roots' once per run: not measured again); ``reject_rate`` of the growing tree's own
   extensions (each tree explores its own region, so each has its own clutter estimate).
3. **Sample** exactly as goal-frame Fuzzy-RRT
   (:func:`~xfuzzy_rrt.planners.goal_frame.sample_goal_frame`) with the target in the goal's
   place: the target with probability ``goal_bias``, else uniformly over the joint limits with
   probability ``uniform_share``, else in the box laid along the direction from ``q`` to the
   target.
4. **Grow**: nearest node of the growing tree, one certified extension of at most
   ``max(step_deg, min_step)`` (:func:`~xfuzzy_rrt.planners.extend.extend`; for the start
   tree its goal test joins the goal directly, for the goal tree -- run on the problem with
   start and goal swapped -- the start). When it is accepted, the growing tree goes on
   towards the same sample by further steps of that size, each from the node the previous
   step added, until it reaches the sample, a step is rejected, its goal test joins the other
   tree's root, or the tree is full: RRT-Connect's greedy CONNECT used for growth as well
   ("connect-connect", Kuffner and LaValle). Why: the rulebook's box already aims the sample
   at the other tree, and one step towards it left the rest of a free stretch to later
   iterations, each paying a nearest-node search and an inference for it. On problems no
   tuning saw (generator seed 6600, 24 per family, 10 seeds), the tuned RRT's work over this
   planner's rose from a median 1.62 to 1.76 at 5 joints and 3.08 to 3.36 with two 3-joint
   arms (docs/peer-measurements.md, thirty-third session). Only the first step counts for the
   growing tree's ``reject_rate`` (the fuzzy decision it judges); a later step that is
   rejected only ends the run of steps.
5. **Connect** (only when step 4 added a node): the other tree's node nearest to the last
   node step 4 added extends towards it by certified steps of the same size, each from the
   node the previous step added, until it reaches that node exactly (the trees are joined), a
   step is rejected, or the tree is full. Every edge of either tree is certified by
   ``edge_free`` with ``P.margin`` and every node by ``config_free``; the junction is one configuration held
   by both trees, so no uncertified edge joins them.

**Rulebooks.** A ``goal-frame`` rulebook (its DOF = the problem's joints in all) or a DOF-free
``goal-frame-any`` one, the default (the shipped ``goal-frame-any``): its lengths are normalised
degrees, so the kernel divides the distance and clearance inputs by ``scale = sqrt(N/2)`` (``N``
joints in all) and multiplies the box and step outputs by it; at 2 joints ``scale`` is exactly
1 and the run is bit for bit the goal-frame one. The paper's semantics is refused: its box is
absolute or relative to one node, and cannot point at another tree.

The path is the start tree's path to the junction followed by the goal tree's path from the
junction, reversed; it begins exactly at the start and ends exactly at the goal.

``iterations`` counts loop iterations (one growth and its connect attempt each; both trees
together), so the growth's further steps and the connect's steps are not iterations: ``nodes``
(both trees) may exceed ``iterations``. ``params["extensions"]`` counts every extension
attempted (growth and connect steps). Each tree holds at most ``2 * max_iter + 8`` nodes; a
growth or a connect stops when its tree is full, and a run whose growing tree is full ends as a
failure.

Random draws per iteration: those of goal-frame Fuzzy-RRT's step 3, nothing else, so a seed
fixes the run byte for byte.

Traces (``trace=True``): one row per iteration with every column of a goal-frame Fuzzy-RRT
trace (inputs as read relative to the target; node indices into the result's tree, start tree
first then goal tree; ``tree_size`` is both trees' nodes; ``outcome`` is ``goal_reached`` on the
row where the trees joined, whether the growth or the connect joined them; ``new_q*`` and
``new_node`` are the growth's first step, the one the fuzzy step decided), plus ``tree`` (0:
the start tree grew, 1: the goal tree), ``grow_nodes`` (nodes the growth added to the growing
tree: its first step and the further ones; 0 when the first was rejected) and
``connect_nodes`` (nodes the connect added to the other tree).
"""

from __future__ import annotations

import math
import time
from typing import Any, NamedTuple

import numba as nb
import numpy as np

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.engine import infer
from xfuzzy_rrt.fuzzy.semantics import length_scale
from xfuzzy_rrt.fuzzy.variables import MAX_FIRED
from xfuzzy_rrt.geometry.scenario import Scenario
from xfuzzy_rrt.planners.checks import check_plan_call
from xfuzzy_rrt.planners.extend import extend, join_start_at_goal, node_clearance
from xfuzzy_rrt.planners.goal_frame import (
    REJECT_DECAY,
    _joint_dist,
    problem_lever,
    sample_goal_frame,
)
from xfuzzy_rrt.planners.result import (
    ACCEPTED,
    EDGE_BLOCKED,
    GOAL_REACHED,
    NODE_IN_COLLISION,
    PlanResult,
    bound_result,
    path_cost_compiled,
    planner_template,
    replace_result,
    vertices_within,
)
from xfuzzy_rrt.planners.rng import seed_state
from xfuzzy_rrt.planners.termination import NEVER_STOPPED, StopFlag, stopped_by
from xfuzzy_rrt.planners.trace_record import TraceArrays, make_trace, record_iteration
from xfuzzy_rrt.geometry.problem import Problem
from xfuzzy_rrt.planners.problem_arena import make_problem_arena, problem_in
from xfuzzy_rrt.planners.prepared import pooled_trees, scenario_arrays
from xfuzzy_rrt.planners.setup_memo import set_up
from xfuzzy_rrt.planners.tree import NN_VISITS, add_node, nearest
from xfuzzy_rrt.planners.tree_arena import emptied_tree_in

PLANNER = "fuzzy-rrt-connect"
#: The rulebook used without one: the shipped DOF-free rulebook (any arm; trained on 3 to 7
#: joints and two arms, rulebooks/README.md).
DEFAULT_RULEBOOK = "goal-frame-any"
START_TREE = 0
GOAL_TREE = 1


def tree_capacity(max_iter: int) -> int:
    """Nodes each tree can hold (growth adds at most 2 per iteration, connects add more)."""
    return 2 * int(max_iter) + 8


@nb.njit(cache=True, nogil=True, inline="always")
def _same(a, b):
    for j in range(a.shape[0]):
        if a[j] != b[j]:
            return False
    return True


@nb.njit(cache=True, nogil=True, inline="always")
def reversed_problem(P):
    """The goal tree's view of ``P``: start and goal swapped, everything else (the work
    counter included) shared, so its extensions join the start directly when they can."""
    return Problem(P.links, P.arm_first, P.bases, P.radii, P.obstacles, P.limits, P.goal,
                   P.start, P.margin, P.clearance, P.work)


@nb.njit(cache=True, nogil=True, _nrt=False)
def _steps_towards(P, T, node, target, step, cap, q_near, q_new):
    """Extend ``T`` from ``node`` towards ``target`` by steps of ``step`` (the last one
    shorter), each from the node the one before added, while they are accepted and the tree
    has room; return ``(outcome, last node, extensions attempted)``.

    The growth's further steps and the connect are this one loop (RRT-Connect's CONNECT).
    ``outcome`` is ``ACCEPTED`` when the loop ended at ``target`` or at a full tree (the
    caller tells them apart by ``last``'s configuration), ``GOAL_REACHED`` when a step joined
    ``P``'s goal (``last`` is that node), else the refusal (``last`` is the node before it).
    Compiled once, not inlined: one copy of :func:`extend` serves both call sites (a
    kernel's code is read from memory on a cold call; benchmarks/cold_misses.py).
    """
    n = 0
    while T.meta[0] + 2 <= cap and not _same(T.nodes[node], target):
        outcome, k = extend(P, T, node, target, step, q_near, q_new)
        n += 1
        if outcome == GOAL_REACHED:
            return outcome, k, n
        if outcome != ACCEPTED:
            return outcome, node, n
        node = k
    return ACCEPTED, node, n


@nb.njit(cache=True, nogil=True, _nrt=True)
def connect_kernel(P, TA, TB, seed, max_iter, knots, consts, scale, min_step, stop, TR, grown,
                   added, counts):
    """Run Fuzzy-RRT-Connect; return ``(success, iterations, junction node in TA, junction
    node in TB)`` (-1, -1 on failure). The two junction nodes hold the same configuration.

    ``P`` is the problem; the goal tree sees it with start and goal swapped
    (:func:`reversed_problem`, built in the loop: its extension joins the start directly when
    it can); ``TA``/``TB`` the empty start and goal trees. With trace arrays ``TR``
    (:func:`~xfuzzy_rrt.planners.trace_record.make_trace`), row ``it - 1`` of ``TR``, ``grown``
    and ``added`` (``[max_iter, 2]``: nodes the growth added, nodes the connect added)
    describes iteration ``it``; ``TR`` ``None`` (and ``grown``, ``added`` ``None``) records
    nothing, through a loop compiled without trace code.
    ``counts[0]`` receives the number of extensions attempted. ``stop[0] != 0`` ends the
    run. ``scale``: Euclidean degrees per unit of the rulebook's lengths (1 for goal-frame,
    ``sqrt(N/2)`` for goal-frame-any): the distance and clearance inputs are divided by it, the
    box and step outputs multiplied.
    """
    n_out = knots.shape[0]
    dof = P.start.shape[0]
    # an uncounted loop (README, "No reference counting in the loops") borrows these buffers
    return _connect_loop(
        P, TA, TB, seed, max_iter, knots, consts, scale, min_step, stop, TR, grown,
        added, counts, np.empty(4, dtype=np.uint64), np.empty(4, dtype=np.float64),
        np.empty(n_out, dtype=np.float64), np.empty(n_out, dtype=np.float64),
        np.empty((n_out, MAX_FIRED), dtype=np.int32),
        np.empty((n_out, MAX_FIRED), dtype=np.float64), np.empty(2 * dof, dtype=np.float64),
        np.empty((7, dof), dtype=np.float64), np.zeros(2, dtype=np.int64),
        np.zeros(2, dtype=np.float64))


@nb.njit(cache=True, nogil=True, _nrt=False)
def _connect_loop(P, TA, TB, seed, max_iter, knots, consts, scale, min_step, stop, TR, grown,
                  added, counts, state, x, y, ys, dummy_rule, dummy_w, box, vecs,
                  current, reject):
    """:func:`connect_kernel`'s loop, given its scratch buffers (``vecs``: one row each for
    the sample, ``e``, the near and new configurations of both trees and the target)."""
    seed_state(seed, state)
    # Built here, not passed in: the loop chooses between P and PR every iteration, and with
    # both made from the same arrays in this function the compiler chooses only the start and
    # the goal (passed in, every field of both records was chosen, every iteration).
    PR = reversed_problem(P)
    n_out = knots.shape[0]
    dof = P.start.shape[0]
    sample = vecs[0]
    e = vecs[1]
    q_near = vecs[2]
    q_new = vecs[3]
    c_near = vecs[4]
    c_new = vecs[5]
    target = vecs[6]
    limits = P.limits
    deg_per_m = math.degrees(1.0) / problem_lever(P)
    clear_top = knots[0, 2, 4]
    has_obstacles = P.obstacles.shape[0] > 0 or P.arm_first.shape[0] > 2
    cap = TA.nodes.shape[0]
    extensions = 0

    # the roots' indices (0) as add_node returns them, not as the constant: a constant makes
    # node_clearance and the stop-record code under it a second compiled copy (for the literal
    # 0) beside the one extend runs, ~130 more cold cache misses per call at 3+ joints
    # (benchmarks/cold_misses.py --by-function, twenty-seventh session)
    root_a = add_node(TA, P.start, -1)
    root_b = add_node(TB, P.goal, -1)
    g = join_start_at_goal(P, TA)
    if g >= 0:  # the start is the goal: [start, goal], joined at the goal tree's root
        counts[0] = 0
        return True, 0, g, 0
    if has_obstacles:  # the roots' clearance, once; every other node keeps the one it was
        TA.clear[root_a] = node_clearance(P, TA, root_a)  # accepted with (extend)
        TB.clear[root_b] = node_clearance(PR, TB, root_b)
    best = _joint_dist(P.start, P.goal)
    stagnation = 0.0
    g = START_TREE
    for it in range(1, max_iter + 1):
        if stop[0] != 0:
            counts[0] = extensions
            return False, it - 1, -1, -1
        row = it - 1
        # the smaller tree grows; on a tie g stays as flipped at the end of the last iteration
        size_a = TA.meta[0]
        size_b = TB.meta[0]
        if size_a < size_b:
            g = START_TREE
        elif size_b < size_a:
            g = GOAL_TREE
        if g == START_TREE:
            G = TA
            O = TB
            PG = P
            PO = PR
        else:
            G = TB
            O = TA
            PG = PR
            PO = P
        if G.meta[0] + 2 > cap:  # the growing tree is full: give up (documented)
            counts[0] = extensions
            return False, it - 1, -1, -1
        # 1. target: the other tree's newest node
        newest_o = O.meta[0] - 1
        for j in range(dof):
            target[j] = O.nodes[newest_o, j]
        # 2. inputs at this tree's current node, relative to the target
        from_node = current[g]
        q = G.nodes[from_node]
        d_target = _joint_dist(q, target)
        if has_obstacles:
            c = G.clear[from_node]
            c_in = max(c, 0.0) * deg_per_m / scale
        else:
            c_in = clear_top
        x[0] = d_target / scale
        x[1] = stagnation
        x[2] = c_in
        x[3] = reject[g]
        if TR is None:  # decided when compiled (trace_record.py)
            infer(knots, consts, x, y, dummy_rule, dummy_w, False)
        else:
            infer(knots, consts, x, y, TR.rule[row], TR.w[row], True)
        ys[0] = y[0]
        ys[1] = y[1]
        for k in range(2, n_out):  # lengths back to joint-space degrees
            ys[k] = y[k] * scale
        step = max(ys[5], min_step)
        # 3. sample in the box pointing at the target
        target_sampled = sample_goal_frame(q, target, d_target, ys, limits, state, sample, box, e)
        # 4. grow: one step, then on towards the sample while the steps are accepted
        n_g = G.meta[0]
        near = nearest(G, sample)
        current[g] = near
        outcome, k = extend(PG, G, near, sample, step, q_near, q_new)
        extensions += 1
        rejected = 1.0 if (outcome == NODE_IN_COLLISION or outcome == EDGE_BLOCKED) else 0.0
        reject[g] = REJECT_DECAY * reject[g] + (1.0 - REJECT_DECAY) * rejected
        stagnation += 1.0
        last = k
        if outcome == ACCEPTED:
            og, last, n_ext = _steps_towards(PG, G, k, sample, step, cap, c_near, c_new)
            extensions += n_ext
            if og == GOAL_REACHED:
                outcome = GOAL_REACHED
        meet_g = -1
        meet_o = -1
        n_o = O.meta[0]
        if outcome == GOAL_REACHED:  # the growing tree joined the other tree's root
            meet_g = last
            meet_o = 0
        elif outcome == ACCEPTED:
            # 5. connect the other tree to the growth's last node
            reach = G.nodes[last]
            oc, ko, n_ext = _steps_towards(PO, O, nearest(O, reach), reach, step, cap, c_near,
                                           c_new)
            extensions += n_ext
            if oc == GOAL_REACHED:  # it joined the growing tree's root
                meet_g = 0
                meet_o = ko
            elif oc == ACCEPTED and _same(O.nodes[ko], reach):
                meet_g = last
                meet_o = ko
        gap = _joint_dist(G.nodes[G.meta[0] - 1], O.nodes[O.meta[0] - 1])
        if gap < best:
            best = gap
            stagnation = 0.0
        if TR is not None:
            row_outcome = GOAL_REACHED if meet_g >= 0 else outcome
            record_iteration(TR, row, from_node, x, y, box, target_sampled, sample, near,
                             q_new, row_outcome, k, TA.meta[0] + TB.meta[0])
            grown[row] = g
            added[row, 0] = G.meta[0] - n_g
            added[row, 1] = O.meta[0] - n_o
        if meet_g >= 0:
            counts[0] = extensions
            if g == START_TREE:
                return True, it, meet_g, meet_o
            return True, it, meet_o, meet_g
        g = 1 - g
    counts[0] = extensions
    return False, max_iter, -1, -1


def _resolve_rulebook(rulebook):
    """A loaded rulebook as given, else the (cached) directory, else the shipped default."""
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook_cached, shipped_rulebook_str

    if rulebook is None:
        rulebook = shipped_rulebook_str(DEFAULT_RULEBOOK)
    elif hasattr(rulebook, "compiled"):
        return rulebook
    return load_rulebook_cached(rulebook)


def check_connect_rulebook(rb, scenario: Scenario) -> None:
    """One clear error unless *rb* is a goal-frame rulebook of the problem's total DOF or a
    DOF-free goal-frame-any one: the connect kernel points the goal-frame box at the other
    tree, which the paper's workspace semantics cannot express."""
    from xfuzzy_rrt.planners.fuzzy_rrt import check_rulebook_fits

    if rb.semantics.name not in ("goal-frame", "goal-frame-any"):
        raise InputError(scenario.source or scenario.name,
                         f"rulebook {rb.name!r} has the {rb.semantics.name!r} semantics; "
                         f"{PLANNER} needs a goal-frame or goal-frame-any rulebook (e.g. "
                         f"{DEFAULT_RULEBOOK})")
    if not rb.semantics.dof_free:  # a goal-frame-any rulebook plans every arm
        check_rulebook_fits(rb, scenario)


@nb.njit(cache=True, nogil=True, _nrt=True)
def finish_connect_run(nodes_a, parent_a, na, nodes_b, parent_b, nb_, last_a, last_b, limits):
    """What a result keeps of a run, in one compiled call (see
    :func:`~xfuzzy_rrt.planners.result.finish_tree_run`): the two trees as one forest (the start
    tree first; the goal tree's parents shifted past it, its root's ``-1`` kept), the joined path
    (the start tree's path to the junction, then the goal tree's from the junction's parent to
    its root; none when ``last_a < 0``), its cost, whether every vertex is within ``limits``, and
    whether the two junction nodes are the same configuration (the kernel joins trees at one
    only)."""
    dof = nodes_a.shape[1]
    nodes = np.empty((na + nb_, dof), dtype=np.float64)
    parent = np.empty(na + nb_, dtype=np.int64)
    for i in range(na):
        parent[i] = parent_a[i]
        for d in range(dof):
            nodes[i, d] = nodes_a[i, d]
    for i in range(nb_):
        parent[na + i] = parent_b[i] + na if parent_b[i] >= 0 else -1
        for d in range(dof):
            nodes[na + i, d] = nodes_b[i, d]
    if last_a < 0:
        return nodes, parent, np.empty((0, dof), dtype=np.float64), 0.0, False, True
    ka = 0
    i = last_a
    while i >= 0:
        ka += 1
        i = parent_a[i]
    kb = 0
    i = last_b
    while i >= 0:
        kb += 1
        i = parent_b[i]
    same = True
    for d in range(dof):
        if nodes_a[last_a, d] != nodes_b[last_b, d]:
            same = False
    path = np.empty((ka + kb - 1, dof), dtype=np.float64)
    i = last_a
    j = ka - 1
    while i >= 0:
        for d in range(dof):
            path[j, d] = nodes_a[i, d]
        j -= 1
        i = parent_a[i]
    i = parent_b[last_b]
    j = ka
    while i >= 0:
        for d in range(dof):
            path[j, d] = nodes_b[i, d]
        j += 1
        i = parent_b[i]
    return nodes, parent, path, path_cost_compiled(path), vertices_within(path, limits), same


@nb.njit(cache=True, nogil=True, inline="always")
def _connect_run(pblock, playout, block_a, layout_a, block_b, layout_b, seed, max_iter, knots,
                 consts, scale, min_step, stop, TR, grown, added):
    """The body of :func:`connect_entry` and :func:`connect_untraced`: the problem and both
    trees unpacked from their arenas (the trees emptied), the kernel run and the run finished."""
    P = problem_in(pblock, playout)
    TA = emptied_tree_in(block_a, layout_a)
    TB = emptied_tree_in(block_b, layout_b)
    counts = np.zeros(1, dtype=np.int64)
    ok, it, last_a, last_b = connect_kernel(P, TA, TB, seed, max_iter, knots, consts, scale,
                                            min_step, stop, TR, grown, added, counts)
    na = TA.meta[0]
    nb_ = TB.meta[0]
    nodes, parent, path, cost, within, same = finish_connect_run(
        TA.nodes, TA.parent, na, TB.nodes, TB.parent, nb_, last_a if ok else -1, last_b,
        P.limits)
    work = P.work[0] + TA.meta[NN_VISITS] + TB.meta[NN_VISITS]
    return (ok, it, last_a, last_b, counts[0], na, nb_, nodes, parent, path, cost, within, same,
            work)


@nb.njit(cache=True, nogil=True, _nrt=True)
def connect_entry(pblock, playout, block_a, layout_a, block_b, layout_b, seed, max_iter, knots,
                  consts, scale, min_step, stop, tr, grown, added):
    """:func:`connect_kernel` with the problem and the two trees as their arenas (the trees
    emptied here) and the trace bundle as a *plain* tuple (see
    :func:`xfuzzy_rrt.planners.rrt.rrt_entry`); the goal tree's view of the problem is built in
    the kernel's loop (:func:`reversed_problem`), not unboxed a second time. Returns the run
    finished, in one call: the kernel's four values, the number of extensions attempted, both
    trees' sizes, :func:`finish_connect_run`'s six values (no path when the run failed) and
    the run's work (``P.work[0]`` and both trees' nearest-neighbour visits).

    ``tr`` ``None`` (a run that records nothing; ``grown`` and ``added`` are then
    ``None`` too): the kernel compiled without trace code runs, and no trace array is unboxed
    (an untraced call passed 16 idle arrays until the eleventh session, ~12 us of a 3-joint
    call with cold caches; docs/peer-measurements.md). The planner itself runs such a run
    through :func:`connect_untraced`, which takes none of the three."""
    if tr is None:  # decided when compiled: the branch not taken is not compiled at all
        return _connect_run(pblock, playout, block_a, layout_a, block_b, layout_b, seed,
                            max_iter, knots, consts, scale, min_step, stop, None, None, None)
    return _connect_run(pblock, playout, block_a, layout_a, block_b, layout_b, seed, max_iter,
                        knots, consts, scale, min_step, stop, TraceArrays(*tr), grown,
                        added)


@nb.njit(cache=True, nogil=True, _nrt=True)
def connect_untraced(pblock, playout, block_a, layout_a, block_b, layout_b, seed, max_iter,
                     knots, consts, scale, min_step, stop):
    """:func:`connect_entry` with ``tr``, ``grown`` and ``added`` ``None``, without
    taking them: numba types a ``None`` argument by fingerprint on every call (~25 last-level
    misses of a cold call; :attr:`~xfuzzy_rrt.fuzzy.semantics.Semantics.untraced`)."""
    return _connect_run(pblock, playout, block_a, layout_a, block_b, layout_b, seed, max_iter,
                        knots, consts, scale, min_step, stop, None, None, None)


class _Setup(NamedTuple):
    """What a Fuzzy-RRT-Connect call checks and builds before its kernel (see
    :mod:`xfuzzy_rrt.planners.setup_memo`): the same for every seed."""

    rb: Any
    arrays: Any
    margin: float
    max_iter: int
    min_step: float
    params: dict
    knots: np.ndarray
    consts: np.ndarray
    scale: float
    #: the problem in one block (:mod:`~xfuzzy_rrt.planners.problem_arena`; the goal tree's
    #: view, start and goal swapped, is made in the kernel: :func:`reversed_problem`)
    problem: Any
    #: the result's ``params`` as far as the set-up fixes them (each call copies it)
    recorded: dict
    #: nodes per tree (:func:`tree_capacity`; kept here: one Python call less per plan)
    capacity: int
    #: ``(scenario name, label)`` -> the run :func:`_lane` made for this set-up
    lanes: dict


def _prepare(scenario: Scenario, rulebook, max_iter, min_step_deg, margin, clearance_m,
             max_time_s) -> _Setup:
    """Every check of a call, in the order errors are reported, and what the kernel takes."""
    margin, params = check_plan_call("fuzzy-rrt", scenario, max_iter, margin, clearance_m,
                                     max_time_s=max_time_s, min_step_deg=min_step_deg)
    rb = _resolve_rulebook(rulebook)
    check_connect_rulebook(rb, scenario)
    knots, consts = rb.kernel_arrays
    scale = length_scale(rb.semantics, scenario.dof)
    a = scenario_arrays(scenario)
    min_step = float(params["min_step_deg"])
    recorded = {"max_iter": int(max_iter), "semantics": rb.semantics.name,
                "min_step_deg": min_step, "margin_m": float(margin), "length_scale": scale}
    return _Setup(rb, a, margin, int(max_iter), min_step, params, knots, consts, scale,
                  make_problem_arena(a.problem(margin)), recorded, tree_capacity(max_iter), {})


def _setup_for(scenario: Scenario, rulebook, max_iter, min_step_deg, margin,
               clearance_m) -> _Setup:
    """:func:`_prepare`, remembered per scenario object and settings while the rulebook
    resolves to the same object (a call without a time budget or a trace)."""
    return set_up(PLANNER, scenario, _prepare,
                  (rulebook, max_iter, min_step_deg, margin, clearance_m), _resolve_rulebook)


def plan_fuzzy_rrt_connect(scenario: Scenario, rulebook=None, seed: int = 0,
                           max_iter: int = 10_000, trace: bool = False,
                           min_step_deg: float | None = None, margin: float | None = None,
                           clearance_m: float | None = None,
                           max_time_s: float | None = None, label: str = PLANNER) -> PlanResult:
    """Plan with Fuzzy-RRT-Connect (see the module docstring).

    ``rulebook``: a loaded goal-frame or goal-frame-any rulebook, a rulebook directory, or
    ``None`` for the shipped ``goal-frame-any`` (any arm); a goal-frame rulebook's DOF must be
    the problem's total number of joints. Other arguments (``label``: the result's
    ``planner``) as for :func:`~xfuzzy_rrt.planners.fuzzy_rrt.plan_fuzzy_rrt`.
    """
    if trace or max_time_s is not None:
        setup = _prepare(scenario, rulebook, max_iter, min_step_deg, margin, clearance_m,
                         max_time_s)
    else:
        setup = _setup_for(scenario, rulebook, max_iter, min_step_deg, margin, clearance_m)
    return _run(setup, scenario.name, label, seed, trace, max_time_s)


def bind_fuzzy_rrt_connect(scenario: Scenario, rulebook, *, max_iter, clearance_m, label):
    """:func:`plan_fuzzy_rrt_connect` without a trace or a time budget, for every seed:
    ``run(seed) -> PlanResult``, the same result (what ``plan_scenario`` keeps for a loop of
    calls: ``api._LANES``)."""
    return _lane(_setup_for(scenario, rulebook, max_iter, None, None, clearance_m),
                 scenario.name, label)


def _lane(setup: _Setup, name: str, label: str):
    """The untraced run of ``setup`` without a time budget, ``run(seed) -> PlanResult``, made
    once per set-up, scenario name and label (``setup.lanes``): everything a run reads is
    looked up here, once, and its result is :func:`~xfuzzy_rrt.planners.result.bound_result`'s
    copy of a template. The same result as :func:`_run`'s general path (tests/test_plan_lanes.py
    compares them field by field); why a separate path: result.bound_result."""
    run = setup.lanes.get((name, label))
    if run is not None:
        return run
    rb, a = setup.rb, setup.arrays
    pblock, playout = setup.problem
    knots, consts, scale, min_step, max_iter = (setup.knots, setup.consts, setup.scale,
                                                setup.min_step, setup.max_iter)
    trees_key = (setup.capacity, a.limits_deg, 2, a.stop_width)
    margin = float(setup.margin)
    # the run's params with its three counts' keys already in place: a copy of a dict of every
    # key takes them without growing (a dict of the five set-up keys grew on the sixth: ~30
    # more cold misses a call, benchmarks/cold_misses.py); same keys, same order as _run's
    slots = {**setup.recorded, "extensions": 0, "start_tree_nodes": 0, "goal_tree_nodes": 0}
    template = planner_template(name, label, PLANNER, rb)
    clock = time.perf_counter

    def run(seed):
        arena_a, arena_b = pooled_trees(*trees_key)
        t0 = clock()
        (ok, iterations, last_a, last_b, extensions, na, nb_, nodes, parent, path, cost, within,
         same, work) = connect_untraced(pblock, playout, arena_a.block, arena_a.layout,
                                        arena_b.block, arena_b.layout, seed, max_iter, knots,
                                        consts, scale, min_step, NEVER_STOPPED)
        wall = clock() - t0
        if not same:
            raise RuntimeError("fuzzy-rrt-connect: the two trees' junction nodes differ")
        params = dict(slots)
        params["extensions"] = extensions
        params["start_tree_nodes"] = na
        params["goal_tree_nodes"] = nb_
        return bound_result(template, a, margin, ok, within, seed, iterations, na + nb_, cost,
                            wall, path, nodes, parent, work, params)

    setup.lanes[(name, label)] = run
    return run


def _run(setup: _Setup, name: str, label: str, seed, trace=False,
         max_time_s=None) -> PlanResult:
    """One run of a checked set-up (:func:`plan_fuzzy_rrt_connect`) of the scenario
    called ``name`` (the name, not the scenario: a kept run must not keep its scenario alive).
    Untraced without a time budget: :func:`_lane`'s run."""
    if not trace and max_time_s is None:
        return _lane(setup, name, label)(int(seed))
    rb, a, margin, max_iter = setup.rb, setup.arrays, setup.margin, setup.max_iter
    knots, consts, scale, min_step = setup.knots, setup.consts, setup.scale, setup.min_step
    arena_a, arena_b = pooled_trees(setup.capacity, a.limits_deg, 2, a.stop_width)
    if trace:
        buffers = make_trace(max_iter, a.dof, knots.shape[0], 1)
        grown = np.zeros(max_iter, dtype=np.int8)
        added = np.zeros((max_iter, 2), dtype=np.int64)
        entry, tail = connect_entry, (tuple(buffers), grown, added)
    else:  # no trace: the kernel compiled without trace code runs
        entry, tail = connect_untraced, ()
    args = (*setup.problem, arena_a.block, arena_a.layout, arena_b.block, arena_b.layout,
            int(seed))
    recorded = dict(setup.recorded)
    if max_time_s is None:  # the entry called here, not through a helper (one Python call less)
        t0 = time.perf_counter()
        (ok, iterations, last_a, last_b, extensions, na, nb_, nodes, parent, path, cost, within,
         same, work) = entry(*args, max_iter, knots, consts, scale, min_step, NEVER_STOPPED,
                             *tail)
        wall = time.perf_counter() - t0
    else:  # the budget is for planning: compile (or load) the kernel first
        # (the next run empties the trees again and counts its own work)
        entry(*args, 0, knots, consts, scale, min_step, np.zeros(1, dtype=np.int64), *tail)
        with StopFlag(max_time_s) as flag:
            t0 = time.perf_counter()
            (ok, iterations, last_a, last_b, extensions, na, nb_, nodes, parent, path, cost,
             within, same, work) = entry(*args, max_iter, knots, consts, scale, min_step,
                                         flag.array, *tail)
            wall = time.perf_counter() - t0
    ok = bool(ok)
    na, nb_ = int(na), int(nb_)
    if not same:
        raise RuntimeError("fuzzy-rrt-connect: the two trees' junction nodes differ")
    recorded.update(extensions=int(extensions), start_tree_nodes=na, goal_tree_nodes=nb_)
    if max_time_s is not None:
        recorded["max_time_s"] = float(setup.params["max_time_s"])
        recorded["stopped_by"] = stopped_by(ok, int(iterations), max_iter, flag)
    # every path segment is a tree edge the kernel certified with edge_free at this margin (the
    # goal tree's, traversed backwards: the same set of configurations)
    result = bound_result(planner_template(name, label, PLANNER, rb), a, margin, ok, within,
                          int(seed), iterations, na + nb_, cost, wall, path, nodes, parent, work,
                          recorded)
    if trace:
        frame = _trace_frame(buffers, grown, added, int(iterations), nodes, parent, na,
                             int(last_a), int(last_b) + na if ok else -1, rb, min_step, scale)
        result = replace_result(result, trace=frame)
    return result


def _trace_frame(buffers, grown, added_nodes, n, nodes, parent, na, last_a, last_b, rb,
                 min_step, scale):
    """The goal-frame trace frame with merged-tree node indices, ``on_path`` over both trees,
    and the ``tree``/``grow_nodes``/``connect_nodes`` columns appended."""
    from xfuzzy_rrt.planners.trace import trace_frame

    goal_rows = grown[:n] == GOAL_TREE
    for arr in (buffers.from_node, buffers.nearest, buffers.node):
        col = arr[:n]
        shift = goal_rows & (col >= 0)
        col[shift] += na
    frame = trace_frame(buffers, n, nodes, parent, -1, rb, min_step, 1)
    on_path_nodes = np.zeros(len(parent), dtype=bool)
    for i in (last_a, last_b):
        while i >= 0:
            on_path_nodes[i] = True
            i = int(parent[i])
    new_node = frame["new_node"].to_numpy()
    added = new_node >= 0
    on_path = np.zeros(n, dtype=bool)
    on_path[added] = on_path_nodes[new_node[added]]
    frame["on_path"] = on_path
    if scale != 1.0:  # the recorded outputs are the rulebook's (normalised) values
        frame["step_used_deg"] = np.maximum(buffers.y[:n, -1] * scale, min_step)
    frame["tree"] = grown[:n].astype(np.int64)
    frame["grow_nodes"] = added_nodes[:n, 0].copy()
    frame["connect_nodes"] = added_nodes[:n, 1].copy()
    return frame
