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

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.clearance import planning_margin
from xfuzzy_rrt.geometry.scenario import Scenario
from xfuzzy_rrt.planners.checks import check_max_iter, check_planar_2dof, check_positive
from xfuzzy_rrt.planners.extend import extend
from xfuzzy_rrt.planners.result import GOAL_REACHED, PlanResult, certified_result, path_cost_deg
from xfuzzy_rrt.planners.rng import seed_state, uniform
from xfuzzy_rrt.planners.tree import Tree, add_node, extract_path, nearest

DEFAULT_STEP_DEG = 10.0
DEFAULT_GOAL_BIAS = 0.05
DEFAULT_MAX_ITER = 10_000


@nb.njit(cache=True, nogil=True)
def rrt_kernel(links, base, radius, obstacles, limits, start, goal, seed, max_iter, step,
               goal_bias, margin, nodes, parent, cell_next, cell_head, meta, grid):
    """Run RRT; return ``(success, iterations, index of the last path node or -1)``."""
    state = np.empty(4, dtype=np.uint64)
    seed_state(seed, state)
    q_near = np.empty(2, dtype=np.float64)
    q_new = np.empty(2, dtype=np.float64)
    add_node(nodes, parent, cell_next, cell_head, meta, grid, start[0], start[1], -1)
    for it in range(1, max_iter + 1):
        if uniform(state) < goal_bias:
            sx = goal[0]
            sy = goal[1]
        else:
            sx = limits[0, 0] + uniform(state) * (limits[0, 1] - limits[0, 0])
            sy = limits[1, 0] + uniform(state) * (limits[1, 1] - limits[1, 0])
        ni = nearest(nodes, cell_next, cell_head, meta, grid, sx, sy)
        outcome, k = extend(links, base, radius, obstacles, limits, goal, margin, nodes, parent,
                            cell_next, cell_head, meta, grid, ni, sx, sy, step, q_near, q_new)
        if outcome == GOAL_REACHED:
            return True, it, k
    return False, max_iter, -1


def plan_rrt(scenario: Scenario, seed: int = 0, max_iter: int = DEFAULT_MAX_ITER,
             step_deg: float = DEFAULT_STEP_DEG, goal_bias: float = DEFAULT_GOAL_BIAS,
             margin: float | None = None, clearance_m: float | None = None) -> PlanResult:
    """Plan with RRT. Same inputs and seed give the same result (``wall_s`` aside).

    ``clearance_m``: the certified clearance (m; default the scenario's ``clearance_m``, else
    0); ``margin``: an explicit kernel margin instead (see ``geometry/clearance.py``).
    """
    check_planar_2dof(scenario)
    margin = planning_margin(scenario, clearance_m, margin)
    check_positive("step_deg", step_deg)
    if not 0.0 <= goal_bias <= 1.0:
        raise InputError("goal_bias", f"must lie in [0, 1], got {goal_bias!r}")
    check_max_iter(max_iter)
    a = scenario.arrays()
    tree = Tree(int(max_iter) + 2, a.limits_deg)
    t0 = time.perf_counter()
    ok, iterations, last = rrt_kernel(
        a.links, a.base, a.link_radius, a.obstacles, a.limits_deg, a.start_deg, a.goal_deg,
        int(seed), int(max_iter), float(step_deg), float(goal_bias), float(margin),
        tree.nodes, tree.parent, tree.cell_next, tree.cell_head, tree.meta, tree.grid)
    wall = time.perf_counter() - t0
    n = int(tree.meta[0])
    path = extract_path(tree.nodes, tree.parent, last) if ok else np.zeros((0, 2))
    return certified_result(
        a, margin, bool(ok), scenario=scenario.name, planner="rrt", seed=int(seed),
        iterations=int(iterations), nodes=n,
        cost_deg=path_cost_deg(path) if ok else None, wall_s=wall, path_deg=path,
        tree_nodes_deg=tree.nodes[:n].copy(), tree_parent=tree.parent[:n].copy(),
        params={"step_deg": float(step_deg), "goal_bias": float(goal_bias),
                "max_iter": int(max_iter), "margin_m": float(margin)},
    )
