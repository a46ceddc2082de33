"""OMPL's geometric planners as peers of RRT and Fuzzy-RRT, on the same problem and checker.

Why: OMPL is the field's reference implementation; a claim that Fuzzy-RRT is "faster" means
little unless it stands next to OMPL's planners configured like ours. So an OMPL run here is set
up exactly as our planners are (``plan_scenario(..., planner="ompl:RRTConnect")``):

- **State space**: ``RealVectorStateSpace(dof)`` in *degrees*, bounded by the scenario's joint
  limits (the same units and the same box our planners sample in).
- **Start and goal exact**: a ``GoalState`` with threshold ``GOAL_THRESHOLD_DEG`` (machine
  epsilon), so a solution must end on the goal. The planners copy the goal state itself, so the
  path ends on it bit for bit; should a planner ever stop within the threshold but not on it,
  the exact goal is appended *only if our certified check accepts that last edge*
  (``params["goal_appended"]``), otherwise the run counts as a failure.
- **Settings**: range ``step_deg`` (10°) and goal bias ``goal_bias`` (0.05) on planners that
  have them (RRT, RRT*; RRTConnect has a range but no goal bias; BIT* has neither — it is a
  batch planner). What was applied is recorded in ``params``.
- **Stop at the first solution**: optimising planners (RRT*, BIT*, ...) get a path-length
  objective whose cost threshold is +inf, so any exact solution satisfies it and they return it
  immediately. ``wall_s`` is the time of the ``solve`` call: the time to the first solution
  (setup and the validity-checker construction are not included, as for our planners).
- **Budget derived from ``max_iter``**: the termination condition is evaluated once per planner
  loop iteration; it stops the run after ``max_iter`` evaluations (a deterministic budget,
  like ours) or after a wall-clock safety cap ``time_limit_s`` (default
  ``max(10 s, 1 ms × max_iter)``; ``params["stopped_by"]`` says which, if any, ended the run).
- **Iterations**: planners that count their own iterations (RRT*, Informed RRT*, SORRT*, BIT*
  expose ``numIterations()``) report that number; for the others the count of
  termination-condition evaluations that returned "go on", which for RRT is exactly its loop
  iterations (one sample each, like ours) and for RRTConnect its loop iterations (one sample,
  one extension, then connection attempts), possibly plus one evaluation while it draws the
  goal root. The planner progress properties (``"iterations INTEGER"``) would be the natural
  source, but the 2.0.1 Python bindings cannot convert that map. ``params["iterations_source"]``
  names the source used. ``nodes`` is the number of vertices in the planner data.
- **Validity: our checker.** A state is valid iff
  :func:`~xfuzzy_rrt.geometry.collision.config_free` holds with ``CERT_MARGIN_M``. It runs as a
  numba ``cfunc`` over a packed float64 buffer, called through ctypes from a two-line Python
  callback (the bindings only accept a Python callable); see the report for its per-call cost.
- **Motion validation: OMPL's own** (``DiscreteMotionValidator`` at OMPL's default resolution,
  1 % of the space's extent, about 5.1° for ±180° limits, unless ``validity_resolution`` is
  given). That is deliberate: OMPL checks an edge by sampling it, so its raw path is then put
  through :func:`~xfuzzy_rrt.geometry.path_check.certify_path` like every planner's
  (:func:`~xfuzzy_rrt.planners.result.certified_result`): ``found`` is OMPL's exact solution,
  ``success`` needs ``certified`` too, and a grazing path reports where and how deep it goes
  (``violation``, ``penetration_m``, ``min_clearance_m``), never silently accepted.
- **Raw path**: the path is the planner's own, not simplified by OMPL (shortening is ours and
  certified: :mod:`xfuzzy_rrt.planners.shortcut`).

Known limitation of the ompl 2.0.1 wheel: after ``BITstar.getPlannerData`` the BIT* graph is
never freed — as far as we can tell OMPL's BIT* keeps every vertex it hands to a
``PlannerData`` alive on purpose (so the raw state pointers stay valid), and the vertices hold
the ``SpaceInformation``. So each BIT* run keeps its graph for the life of the process (about
70 kB per run on the test fixtures, more for larger graphs) and nanobind lists the leaked
objects on stderr at interpreter exit. No other supported planner does this; ``clear()`` and
``gc.collect()`` do not help. Long BIT* benchmarks are best run in worker processes.

Determinism: ``ompl.util.RNG.setSeed`` is called before each plan and every OMPL object that
draws random numbers (space, samplers, planner) is created after it, so the same seed gives the
same path, iterations and nodes within a process and across processes, as long as the run is
not ended by the wall-clock cap (which depends on the machine) and OMPL runs single-threaded
(all planners used here are). OMPL seeds must be positive 32-bit integers, so our seed is
mapped to ``seed mod (2**32 - 1) + 1`` (``params["ompl_seed"]``). OMPL's own log output is
silenced during a plan (it would otherwise warn that re-seeding happens after the first seed).
"""

from __future__ import annotations

import ctypes
import math
import time

import numba as nb
import numpy as np
from numba import carray

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M, config_free, segment_free
from xfuzzy_rrt.geometry.scenario import Scenario
from xfuzzy_rrt.geometry.problem import Problem
from xfuzzy_rrt.planners.checks import check_dof, check_max_iter, check_positive
from xfuzzy_rrt.planners.result import PlanResult, certified_result, path_cost_deg

OMPL_PREFIX = "ompl:"
MISSING_EXTRA = "ompl:* planners need the optional 'ompl' extra: pip install -e '.[ompl]'"
#: Goal tolerance in degrees: machine epsilon, so "reaching the goal" means being on it.
GOAL_THRESHOLD_DEG = 2.220446049250313e-16


#: Geometric planners of the wheel that cannot run here, and why (found by running each one).
UNSUPPORTED = {
    "PRM": "it grows its roadmap in a second thread, which cannot call the Python validity "
           "callback while solve() holds the interpreter lock (the run deadlocks)",
    "PRMstar": "it grows its roadmap in a second thread, which cannot call the Python validity "
               "callback while solve() holds the interpreter lock (the run deadlocks)",
    "AORRTC": "it crashes the interpreter (segmentation fault) on some seeds in the ompl 2.0.1 "
              "wheel ('AOXRRTConnect: Failed to find any neighbours for a state')",
}


def import_ompl(where: str = "--planners"):
    """``(ompl.base, ompl.geometric, ompl.util)`` or one clear InputError naming the extra
    (and the option, ``where``, that asked for an OMPL planner)."""
    try:
        from ompl import base as ob
        from ompl import geometric as og
        from ompl import util as ou
    except ImportError:
        raise InputError(where, MISSING_EXTRA) from None
    return ob, og, ou


def ompl_planner_names(where: str = "--planners") -> tuple[str, ...]:
    """Geometric planners this OMPL build exposes and ``ompl:NAME`` accepts (not UNSUPPORTED)."""
    ob, og, _ = import_ompl(where)
    names = []
    for name in dir(og):
        obj = getattr(og, name)
        if (isinstance(obj, type) and issubclass(obj, ob.Planner) and not name.startswith("_")
                and name not in UNSUPPORTED):
            names.append(name)
    return tuple(sorted(names))


def check_ompl_planner(name: str, where: str = "--planners") -> str:
    """The bare OMPL planner name of ``ompl:NAME`` (or ``NAME``); InputError naming ``where``
    (the option the name came from) if unknown."""
    bare = name[len(OMPL_PREFIX):] if name.startswith(OMPL_PREFIX) else name
    known = ompl_planner_names(where)
    if bare in UNSUPPORTED:
        raise InputError(where, f"OMPL planner {bare!r} is not supported: "
                         f"{UNSUPPORTED[bare]} (supported: {', '.join(known)})")
    if bare not in known:
        raise InputError(where, f"unknown OMPL planner {bare!r} (known: {', '.join(known)})")
    return bare


def ompl_seed(seed: int) -> int:
    """Map any integer seed to OMPL's positive 32-bit seed range (0 would be ignored)."""
    return int(seed) % (2**32 - 1) + 1


# ----------------------------------------------------------------------------------------------
# The compiled validity check
# ----------------------------------------------------------------------------------------------

_HEADER = 4  # [dof, obstacles, arms, margin]


def pack_scenario(arrays, margin: float) -> np.ndarray:
    """The problem as one contiguous float64 buffer the validity ``cfunc`` reads through a raw
    pointer: ``[dof, obstacles, arms, margin, arm_first (arms + 1), bases (2 arms), radii
    (arms), links (dof), limits (2 dof), obstacles (5 per obstacle)]``."""
    dof = arrays.links.shape[0]
    m = arrays.obstacles.shape[0]
    n_arms = arrays.n_arms
    return np.ascontiguousarray(np.concatenate([
        [float(dof), float(m), float(n_arms), float(margin)],
        arrays.arm_first.astype(np.float64), arrays.bases.ravel(), arrays.radii, arrays.links,
        arrays.limits_deg.ravel(), arrays.obstacles.ravel(),
    ]).astype(np.float64))


@nb.cfunc(nb.types.boolean(nb.types.voidptr, nb.types.voidptr), cache=True)
def _valid_cfunc(qptr, ptr):
    """Compiled check of the configuration at ``qptr`` in the :func:`pack_scenario` buffer at
    ``ptr``: the planners' own :func:`~xfuzzy_rrt.geometry.collision.config_free`."""
    head = carray(ptr, (_HEADER,), dtype=np.float64)
    dof = int(head[0])
    m = int(head[1])
    n_arms = int(head[2])
    size = _HEADER + (n_arms + 1) + 3 * n_arms + 3 * dof + 5 * m
    data = carray(ptr, (size,), dtype=np.float64)
    k = _HEADER
    arm_first = np.empty(n_arms + 1, dtype=np.int64)
    for a in range(n_arms + 1):
        arm_first[a] = int(data[k + a])
    k += n_arms + 1
    bases = data[k:k + 2 * n_arms].reshape((n_arms, 2))
    k += 2 * n_arms
    radii = data[k:k + n_arms]
    k += n_arms
    links = data[k:k + dof]
    k += dof
    limits = data[k:k + 2 * dof].reshape((dof, 2))
    k += 2 * dof
    obstacles = data[k:k + 5 * m].reshape((m, 5))
    q = carray(qptr, (dof,), dtype=np.float64)
    P = Problem(links, arm_first, bases, radii, obstacles, limits, q, q, head[3], 0.0,
                np.zeros(1, dtype=np.int64))
    return config_free(P, q, head[3])


def validity_cfunc():
    """The compiled check ``(q_deg*, buffer*) -> bool`` as a ctypes function."""
    fn = _valid_cfunc.ctypes
    fn.argtypes = [ctypes.c_void_p, ctypes.c_void_p]
    fn.restype = ctypes.c_bool
    return fn


def make_validity_callback(arrays, margin: float = CERT_MARGIN_M):
    """A Python callable ``state -> bool`` for OMPL that runs our compiled check.

    The buffers are bound as default arguments so they live as long as the callback.
    """
    buffer = pack_scenario(arrays, margin)
    fn = validity_cfunc()
    address = buffer.ctypes.data
    dof = arrays.links.shape[0]
    q = np.empty(dof, dtype=np.float64)
    q_address = q.ctypes.data
    joints = range(dof)

    def is_valid(state, _fn=fn, _address=address, _buffer=buffer, _q=q, _qa=q_address):
        for j in joints:
            _q[j] = state[j]
        return _fn(_qa, _address)

    return is_valid


# ----------------------------------------------------------------------------------------------
# Planning
# ----------------------------------------------------------------------------------------------

def plan_ompl(scenario: Scenario, planner: str, seed: int = 0, max_iter: int = 10_000,
              step_deg: float = 10.0, goal_bias: float = 0.05, margin: float | None = None,
              time_limit_s: float | None = None,
              validity_resolution: float | None = None,
              clearance_m: float | None = None) -> PlanResult:
    """Plan ``scenario`` with OMPL planner ``planner`` (``"RRT"`` or ``"ompl:RRT"``).

    ``validity_resolution`` is OMPL's state-validity checking resolution as a fraction of the
    space's extent (``None``: OMPL's default 0.01). See the module docstring for everything
    else; the returned ``PlanResult.planner`` is ``"ompl:NAME"``.
    """
    ob, og, ou = import_ompl("--planner")
    bare = check_ompl_planner(planner, "--planner")
    check_dof(scenario)
    check_max_iter(max_iter)
    check_positive("step_deg", step_deg)
    if not 0.0 <= goal_bias <= 1.0:
        raise InputError("goal_bias", f"must lie in [0, 1], got {goal_bias!r}")
    from xfuzzy_rrt.geometry.clearance import planning_margin  # validity callback and certify

    margin = planning_margin(scenario, clearance_m, margin)
    if time_limit_s is None:
        time_limit_s = max(10.0, 1e-3 * max_iter)
    check_positive("time_limit_s", time_limit_s)
    if validity_resolution is not None:
        check_positive("validity_resolution", validity_resolution)
    a = scenario.arrays()
    dof = a.links.shape[0]
    callback = make_validity_callback(a, margin)

    previous_level = ou.getLogLevel()
    ou.setLogLevel(ou.LOG_NONE)
    try:
        seed_used = ompl_seed(seed)
        ou.RNG.setSeed(seed_used)
        space = ob.RealVectorStateSpace(dof)
        bounds = ob.RealVectorBounds(dof)
        for j in range(dof):
            bounds.setLow(j, float(a.limits_deg[j, 0]))
            bounds.setHigh(j, float(a.limits_deg[j, 1]))
        space.setBounds(bounds)
        si = ob.SpaceInformation(space)
        si.setStateValidityChecker(callback)
        if validity_resolution is not None:
            si.setStateValidityCheckingResolution(float(validity_resolution))
        si.setup()
        start = space.allocState()
        goal = space.allocState()
        for j in range(dof):
            start[j] = float(a.start_deg[j])
            goal[j] = float(a.goal_deg[j])
        pdef = ob.ProblemDefinition(si)
        pdef.setStartAndGoalStates(start, goal, GOAL_THRESHOLD_DEG)
        objective = ob.PathLengthOptimizationObjective(si)
        objective.setCostThreshold(ob.Cost(math.inf))  # any solution is good enough: stop
        pdef.setOptimizationObjective(objective)

        p = getattr(og, bare)(si)
        applied: dict[str, float | None] = {"range_deg": None, "goal_bias": None}
        if hasattr(p, "setRange"):
            p.setRange(float(step_deg))
            applied["range_deg"] = float(step_deg)
        if hasattr(p, "setGoalBias"):
            p.setGoalBias(float(goal_bias))
            applied["goal_bias"] = float(goal_bias)
        p.setProblemDefinition(pdef)
        p.setup()

        state = {"go_on": 0, "stopped_by": None}
        deadline = [math.inf]

        def terminate() -> bool:
            if state["go_on"] >= max_iter:
                state["stopped_by"] = "max_iter"
                return True
            if time.perf_counter() > deadline[0]:
                state["stopped_by"] = "time_limit"
                return True
            state["go_on"] += 1
            return False

        ptc = ob.PlannerTerminationCondition(terminate)
        t0 = time.perf_counter()
        deadline[0] = t0 + time_limit_s
        status = str(p.solve(ptc))
        wall = time.perf_counter() - t0

        exact = bool(pdef.hasExactSolution())
        path = np.zeros((0, dof))
        goal_appended = False
        failure = None
        if exact:
            states = pdef.getSolutionPath().getStates()
            path = np.array([[s[j] for j in range(dof)] for s in states], dtype=np.float64)
            if not np.array_equal(path[0], a.start_deg):
                exact, failure = False, "path does not start at the start configuration"
            elif not np.array_equal(path[-1], a.goal_deg):
                if segment_free(a, path[-1], a.goal_deg, margin):
                    path = np.vstack([path, a.goal_deg[None, :]])
                    goal_appended = True
                else:
                    exact, failure = False, "last state is within the goal threshold but the " \
                                            "edge to the exact goal is not certified"
        if not exact:
            path = np.zeros((0, dof))

        if hasattr(p, "numIterations"):
            iterations, source = int(p.numIterations()), "numIterations"
        else:
            iterations, source = int(state["go_on"]), "termination-condition evaluations"

        data = ob.PlannerData(si)
        p.getPlannerData(data)
        n = int(data.numVertices())
        tree = np.empty((n, dof), dtype=np.float64)
        parent = np.full(n, -1, dtype=np.int64)
        for i in range(n):
            s = data.getVertex(i).getState()
            for j in range(dof):
                tree[i, j] = s[j]
            for child in data.getEdges(i):
                parent[int(child)] = i
        motions_checked = int(si.getCheckedMotionCount())
        resolution_deg = float(space.getLongestValidSegmentLength())
    finally:
        ou.setLogLevel(previous_level)

    params = {
        "ompl_planner": bare,
        "ompl_version": _ompl_version(),
        "ompl_seed": seed_used,
        "range_deg": applied["range_deg"],
        "goal_bias": applied["goal_bias"],
        "max_iter": int(max_iter),
        "time_limit_s": float(time_limit_s),
        "stopped_by": "solution" if exact else (state["stopped_by"] or "planner"),
        "ompl_status": status,
        "iterations_source": source,
        "motion_validator": "DiscreteMotionValidator",
        "validity_resolution_deg": resolution_deg,
        "motions_checked": motions_checked,
        "margin_m": float(margin),
        "goal_threshold_deg": GOAL_THRESHOLD_DEG,
        "goal_appended": goal_appended,
    }
    if failure is not None:
        params["failure"] = failure
    result = certified_result(
        a, margin, exact, scenario=scenario.name, planner=OMPL_PREFIX + bare, seed=int(seed),
        iterations=iterations, nodes=n, cost_deg=path_cost_deg(path) if exact else None,
        wall_s=wall, path_deg=path, tree_nodes_deg=tree, tree_parent=parent, params=params,
    )
    # Kept in params too for readers of older result files; the top-level fields are the truth.
    params["certified"] = result.certified if exact else None
    params["penetration_m"] = result.penetration_m if exact else None
    return result


def _ompl_version() -> str:
    try:
        from importlib.metadata import version

        return version("ompl")
    except Exception:  # pragma: no cover - metadata missing in odd installs
        return "unknown"
