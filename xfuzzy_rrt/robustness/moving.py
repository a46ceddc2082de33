"""Moving obstacles: execute a plan while the obstacles drift, with or without replanning.

Each obstacle drifts in a straight line at ``speed_m_s`` in a direction drawn per run (seeded),
while the arm follows its path at ``joint_speed_deg_s`` (joint-space length per second). The
executor runs at ``rate_hz``: every tick it advances the arm, moves the obstacles, and checks
the arm's motion over the tick *exactly* against the obstacles where they are at the end of the
tick (the obstacles themselves moved at most ``speed / rate`` during it; that is the time
resolution of the collision record). With ``replan``, it also re-checks the remaining path with
the certified check against the current obstacles and, when the path would now touch one, plans
again from the current configuration with the clearance in force (planning with the clearance
but re-checking for contact is the hysteresis that keeps a path planned right at its clearance
from being replanned at every tick as soon as anything moves) (the arm holds still while it plans; the wall
time of each replanning is recorded as its latency). Without ``replan`` the arm follows the
original plan blind. A run succeeds when the arm reaches the goal without touching anything
within ``time_limit_s``.

This is the simple baseline the issue anchors to RRTX: replanning from scratch, not repairing a
tree. Its latencies are what a repairing planner must beat.
"""

from __future__ import annotations

import dataclasses
import math
import time

import numpy as np
import pandas as pd

from xfuzzy_rrt.errors import InputError


def _positive(name: str, value: float) -> float:
    if isinstance(value, bool) or not isinstance(value, (int, float)) or not (
            math.isfinite(value) and value > 0):
        raise InputError(name, f"must be a positive number, got {value!r}")
    return float(value)


def _moved(obstacles: np.ndarray, velocity: np.ndarray, t: float) -> np.ndarray:
    out = obstacles.copy()
    out[:, 1] += velocity[:, 0] * t
    out[:, 2] += velocity[:, 1] * t
    box = out[:, 0] == 1.0
    out[box, 3] += velocity[box, 0] * t
    out[box, 4] += velocity[box, 1] * t
    return out


def _scenario_at(scenario, obstacles: np.ndarray, start):
    from xfuzzy_rrt.geometry.scenario import Box, Circle

    obs = tuple(Circle((float(r[1]), float(r[2])), float(r[3])) if r[0] == 0.0 else
                Box((float(r[1]), float(r[2])), (float(r[3]), float(r[4]))) for r in obstacles)
    return dataclasses.replace(scenario, obstacles=obs,
                               start_deg=tuple(float(v) for v in start))


def _remaining(path: np.ndarray, q: np.ndarray, index: int) -> np.ndarray:
    """The rest of the path from configuration ``q`` on segment ``index``."""
    return np.vstack([q[None, :], path[index + 1:]])


#: Why a replanning found no path (columns of a run's row, summed per table row):
#: the arm's current configuration (the new start) is in collision with the moved obstacles;
#: the goal is; or neither, and the planner used its whole ``max_iter`` budget.
FAILURE_CAUSES = ("replan_fail_start_blocked", "replan_fail_goal_blocked",
                  "replan_fail_budget")


def _failure_cause(problem, q: np.ndarray, goal: np.ndarray) -> str:
    from xfuzzy_rrt.geometry.collision import clearance_kernel

    if clearance_kernel(problem, np.asarray(q, dtype=np.float64)) <= 0.0:
        return "replan_fail_start_blocked"
    if clearance_kernel(problem, np.asarray(goal, dtype=np.float64)) <= 0.0:
        return "replan_fail_goal_blocked"
    return "replan_fail_budget"


def diagnosis(row) -> str | None:
    """One sentence on why runs of a table row failed (``None`` when all succeeded): how the
    runs ended and, with replanning, what stopped the replans. Why: "success 0.000 with 1,499
    replan failures" alone does not say whether to raise ``--max-iter`` or expect a blocked
    start."""
    runs = int(row["runs"])
    failed = runs - int(round(float(row["success_rate"]) * runs))
    if failed == 0:
        return None
    ends = []
    for key, what in (("runs_unplanned", "found no first plan"),
                      ("runs_collided", "collided"),
                      ("runs_timed_out", f"ran out of time ({row['time_limit_s']:g} s simulated)")):
        if int(row.get(key, 0)):
            ends.append(f"{int(row[key])} {what}")
    text = f"{failed} of {runs} runs failed: " + ", ".join(ends or ["unknown"])
    if int(row.get("replan_failures", 0)):
        causes = [(int(row[c]), w) for c, w in (
            ("replan_fail_start_blocked", "the arm's configuration was already in collision"),
            ("replan_fail_goal_blocked", "the goal was in collision"),
            ("replan_fail_budget", f"no path within {int(row['max_iter'])} iterations"))]
        text += (f"; {int(row['replan_failures'])} replannings found no path: "
                 + ", ".join(f"{n} {w}" for n, w in causes if n))
    return text


def execute_once(scenario, planner: str, seed: int, speed_m_s: float, joint_speed_deg_s: float,
                 rate_hz: float, replan: bool, max_iter: int = 10_000,
                 clearance_m: float | None = None, time_limit_s: float = 60.0) -> dict:
    """One execution; returns its row (success, collided, replans, latencies, time)."""
    from xfuzzy_rrt.geometry.clearance import min_clearance_kernel
    from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M, edge_free
    from xfuzzy_rrt.planners.api import plan_scenario

    a = scenario.arrays()
    rng = np.random.default_rng([int(seed), 7])
    angle = rng.uniform(0.0, 2 * math.pi, size=a.obstacles.shape[0])
    velocity = speed_m_s * np.stack([np.cos(angle), np.sin(angle)], axis=1)
    first = plan_scenario(scenario, planner=planner, seed=seed, max_iter=max_iter,
                          clearance_m=clearance_m)
    row = {"seed": seed, "success": False, "collided": False, "replans": 0,
           "replan_failures": 0, "latency_median_s": math.nan, "latency_max_s": math.nan,
           "time_s": math.nan, "planned": bool(first.path_deg.size), "timed_out": False,
           **{cause: 0 for cause in FAILURE_CAUSES}}
    if not first.path_deg.size:
        return row
    path = np.asarray(first.path_deg, dtype=np.float64)
    goal = a.goal_deg
    dt = 1.0 / rate_hz
    step = joint_speed_deg_s * dt
    q = path[0].copy()
    index = 0  # q lies on segment path[index] -> path[index + 1]
    latencies = []
    t = 0.0
    while t < time_limit_s:
        obs_now = _moved(a.obstacles, velocity, t)
        hold = False
        if replan:
            rest = _remaining(path, q, index)
            now = a.problem(CERT_MARGIN_M)._replace(obstacles=obs_now)
            valid = all(edge_free(now, rest[i], rest[i + 1], CERT_MARGIN_M)
                        for i in range(rest.shape[0] - 1))
            if not valid:
                row["replans"] += 1
                t0 = time.perf_counter()
                here = _scenario_at(scenario, obs_now, q)
                r = None
                try:
                    r = plan_scenario(here, planner=planner, seed=seed + row["replans"],
                                      max_iter=max_iter, clearance_m=clearance_m)
                except InputError:
                    # An obstacle already came within the clearance of the arm: escape with a
                    # collision-free plan (no clearance) rather than stand still.
                    try:
                        r = plan_scenario(here, planner=planner, seed=seed + row["replans"],
                                          max_iter=max_iter, clearance_m=0.0)
                    except InputError:
                        r = None  # the start or the goal itself is in collision now
                new = (np.asarray(r.path_deg, dtype=np.float64) if r is not None
                       else np.zeros((0, a.dof)))
                latencies.append(time.perf_counter() - t0)
                if new.size:
                    path, index = new, 0
                    q = path[0].copy()
                else:
                    row["replan_failures"] += 1
                    row[_failure_cause(now, q, goal)] += 1
                    hold = True  # hold still this tick (obstacles may still run into the arm)
        # Advance the arm by one tick along the path.
        moved = np.array([q])
        budget = 0.0 if hold else step
        while budget > 0.0 and index < path.shape[0] - 1:
            target = path[index + 1]
            d = float(np.linalg.norm(target - q))
            if d <= budget:
                q = target.copy()
                index += 1
                budget -= d
            else:
                q = q + (target - q) * (budget / d)
                budget = 0.0
            moved = np.vstack([moved, q[None, :]])
        t += dt
        obs_next = _moved(a.obstacles, velocity, t)
        c = min_clearance_kernel(a.problem(CERT_MARGIN_M)._replace(obstacles=obs_next), moved,
                                 1e-6, 200_000, True)[0]
        if c <= 0.0:
            row["collided"] = True
            row["time_s"] = t
            break
        if index >= path.shape[0] - 1 and np.array_equal(q, goal):
            row["success"] = True
            row["time_s"] = t
            break
    else:
        row["timed_out"] = True
    if latencies:
        row["latency_median_s"] = float(np.median(latencies))
        row["latency_max_s"] = float(np.max(latencies))
    return row


def moving_obstacles(scenarios, planners, speeds, joint_speed_deg_s: float = 30.0,
                     rate_hz: float = 20.0, replan: bool = True, runs: int = 10, seed: int = 0,
                     max_iter: int = 10_000, clearance_m: float | None = None,
                     time_limit_s: float = 60.0) -> pd.DataFrame:
    """Per (scenario, planner, speed): success, collision and replanning figures over runs."""
    _positive("--joint-speed", joint_speed_deg_s)
    _positive("--rate", rate_hz)
    _positive("--time-limit", time_limit_s)
    rows = []
    for scenario in scenarios:
        for planner in planners:
            for speed in speeds:
                if not (math.isfinite(speed) and speed >= 0):
                    raise InputError("--speed", f"must be non-negative m/s, got {speed!r}")
                runs_ = [execute_once(scenario, planner, seed + k, speed, joint_speed_deg_s,
                                      rate_hz, replan, max_iter, clearance_m, time_limit_s)
                         for k in range(runs)]
                df = pd.DataFrame(runs_)
                lat = df["latency_median_s"].dropna()
                rows.append({
                    "scenario": scenario.name, "planner": planner, "speed_m_s": speed,
                    "replan": replan, "runs": runs, "success_rate": df["success"].mean(),
                    "collision_rate": df["collided"].mean(),
                    "replans_mean": df["replans"].mean(),
                    "replan_failures": int(df["replan_failures"].sum()),
                    "runs_unplanned": int((~df["planned"]).sum()),
                    "runs_collided": int(df["collided"].sum()),
                    "runs_timed_out": int(df["timed_out"].sum()),
                    **{c: int(df[c].sum()) for c in FAILURE_CAUSES},
                    "max_iter": int(max_iter), "time_limit_s": float(time_limit_s),
                    "latency_median_s": float(lat.median()) if len(lat) else math.nan,
                    "latency_max_s": float(df["latency_max_s"].max()) if len(lat) else math.nan,
                    "time_median_s": float(df["time_s"].median()),
                })
    return pd.DataFrame(rows)
