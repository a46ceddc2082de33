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

import numba as nb
import numpy as np

from xfuzzy_rrt.geometry.clearance import planning_margin
from xfuzzy_rrt.geometry.problem import Problem
from xfuzzy_rrt.geometry.scenario import Scenario
from xfuzzy_rrt.planners.checks import check_dof, check_max_iter
from xfuzzy_rrt.planners.extend import extend
from xfuzzy_rrt.planners.params import default, resolve_params
from xfuzzy_rrt.planners.result import GOAL_REACHED, PlanResult, certified_result, path_cost_deg
from xfuzzy_rrt.planners.rng import seed_state, uniform
from xfuzzy_rrt.planners.termination import StopFlag, stopped_by
from xfuzzy_rrt.planners.prepared import empty_tree, scenario_arrays
from xfuzzy_rrt.planners.tree import NN_VISITS, TreeArrays, add_node, extract_path, nearest, reset_tree

DEFAULT_STEP_DEG = default("rrt", "step_deg")
DEFAULT_GOAL_BIAS = default("rrt", "goal_bias")
DEFAULT_MAX_ITER = default("rrt", "max_iter")


@nb.njit(cache=True, nogil=True)
def rrt_kernel(P, T, seed, max_iter, step, goal_bias, stop):
    """Run RRT on problem ``P`` growing tree ``T``; return ``(success, iterations, index of the
    last path node or -1)``. ``stop[0] != 0`` (a wall-clock budget ran out) ends the run."""
    state = np.empty(4, dtype=np.uint64)
    seed_state(seed, state)
    dof = P.start.shape[0]
    sample = np.empty(dof, dtype=np.float64)
    q_near = np.empty(dof, dtype=np.float64)
    q_new = np.empty(dof, dtype=np.float64)
    add_node(T, P.start, -1)
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


@nb.njit(cache=True, nogil=True)
def rrt_entry(p, t, seed, max_iter, step, goal_bias, stop):
    """:func:`rrt_kernel` called with the problem and the tree as *plain* tuples.

    Why: numba types a named-tuple argument in Python, element by element, on every call
    (20-40 us for our two bundles, as much as a short 2-DOF plan); a plain tuple of arrays is
    typed by its fast C path. The bundles are rebuilt here, inside compiled code, for free.
    """
    return rrt_kernel(Problem(*p), TreeArrays(*t), seed, max_iter, step, goal_bias, stop)


def plan_rrt(scenario: Scenario, seed: int = 0, max_iter: int = DEFAULT_MAX_ITER,
             step_deg: float = DEFAULT_STEP_DEG, goal_bias: float = DEFAULT_GOAL_BIAS,
             margin: float | None = None, clearance_m: float | None = None,
             max_time_s: float | None = None) -> PlanResult:
    """Plan with RRT in the joint space of every arm. Same inputs and seed give the same result
    (``wall_s`` aside, and unless the wall-clock budget ``max_time_s`` ends the run).

    ``clearance_m``: the certified clearance (m; default the scenario's ``clearance_m``, else
    0); ``margin``: an explicit kernel margin instead (see ``geometry/clearance.py``).
    """
    check_dof(scenario)
    margin = planning_margin(scenario, clearance_m, margin)
    check_max_iter(max_iter)
    params = resolve_params("rrt", max_iter=max_iter, max_time_s=max_time_s,
                            step_deg=step_deg, goal_bias=goal_bias)
    max_iter = params["max_iter"]
    a = scenario_arrays(scenario)
    problem = a.problem(margin)
    tree = empty_tree(int(max_iter) + 2, a.limits_deg)
    args = (float(params["step_deg"]), float(params["goal_bias"]))
    if max_time_s is not None:  # the budget is for planning: compile (or load) the kernel first
        meta0 = tree.meta.copy()
        rrt_entry(tuple(problem), tuple(tree), int(seed), 0, *args, np.zeros(1, dtype=np.int64))
        reset_tree(tree, meta0)
        problem.work[0] = 0
    with StopFlag(max_time_s) as flag:
        t0 = time.perf_counter()
        ok, iterations, last = rrt_entry(tuple(problem), tuple(tree), int(seed), int(max_iter),
                                         *args,
                                          flag.array)
        wall = time.perf_counter() - t0
    n = int(tree.meta[0])
    path = extract_path(tree.nodes, tree.parent, last) if ok else np.zeros((0, a.dof))
    recorded = {"step_deg": float(params["step_deg"]), "goal_bias": float(params["goal_bias"]),
                "max_iter": int(max_iter), "margin_m": float(margin)}
    if max_time_s is not None:
        recorded["max_time_s"] = float(params["max_time_s"])
        recorded["stopped_by"] = stopped_by(bool(ok), int(iterations), int(max_iter), flag)
    return certified_result(
        a, margin, bool(ok), edges_certified=True, scenario=scenario.name, planner="rrt",
        planner_used="rrt",
        seed=int(seed),
        iterations=int(iterations), nodes=n,
        cost_deg=path_cost_deg(path) if ok else None, wall_s=wall, path_deg=path,
        tree_nodes_deg=tree.nodes[:n].copy(), tree_parent=tree.parent[:n].copy(),
        work=int(problem.work[0] + tree.meta[NN_VISITS]),
        params=recorded,
    )
