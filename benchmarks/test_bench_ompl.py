"""OMPL peers: cost of the compiled validity callback, and OMPL plans on the reference problem.

The validity callback is called by OMPL for every state it checks, so its per-call cost is
part of every OMPL time we report. Three variants are timed per call on the same state:

- ``compiled``: what the bridge uses (a two-line Python callable around a numba ``cfunc``
  reached through ctypes),
- ``python``: the same check written in plain Python (exact capsule–circle/box distances),
- ``via_isValid``: the compiled callback as OMPL calls it (``SpaceInformation.isValid``).

Run: ``.venv/bin/python -m pytest benchmarks/test_bench_ompl.py --benchmark-only``.
"""

from __future__ import annotations

import math

import numpy as np
import pytest

from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M
from xfuzzy_rrt.geometry.path_check import certify_path
from xfuzzy_rrt.planners.ompl_bridge import make_validity_callback, plan_ompl

SEEDS = range(50)




def python_validity(arrays, margin=CERT_MARGIN_M):
    """The same test as ``config_free`` in plain Python (the baseline the figure compares to)."""
    links = [float(v) for v in arrays.links]
    bx, by = (float(v) for v in arrays.base)
    radius = float(arrays.link_radius)
    limits = [tuple(map(float, row)) for row in arrays.limits_deg]
    obstacles = [tuple(map(float, row)) for row in arrays.obstacles]

    def point_segment(px, py, ax, ay, dx, dy, den):
        t = 0.0 if den == 0.0 else min(1.0, max(0.0, ((px - ax) * dx + (py - ay) * dy) / den))
        return math.hypot(ax + t * dx - px, ay + t * dy - py)

    def seg_box(ax, ay, ex, ey, x0, y0, x1, y1):
        # Liang–Barsky intersection, else the closest of endpoints and corners.
        t0, t1, dx, dy = 0.0, 1.0, ex - ax, ey - ay
        hit = True
        for p, q in ((-dx, ax - x0), (dx, x1 - ax), (-dy, ay - y0), (dy, y1 - ay)):
            if p == 0.0:
                if q < 0.0:
                    hit = False
                    break
            else:
                r = q / p
                if p < 0.0:
                    if r > t1:
                        hit = False
                        break
                    t0 = max(t0, r)
                else:
                    if r < t0:
                        hit = False
                        break
                    t1 = min(t1, r)
        if hit:
            return 0.0
        den = dx * dx + dy * dy
        d = min(math.hypot(max(x0 - px, 0.0, px - x1), max(y0 - py, 0.0, py - y1))
                for px, py in ((ax, ay), (ex, ey)))
        for cx, cy in ((x0, y0), (x1, y0), (x0, y1), (x1, y1)):
            d = min(d, point_segment(cx, cy, ax, ay, dx, dy, den))
        return d

    def is_valid(state):
        q = (state[0], state[1])
        for (lo, hi), v in zip(limits, q):
            if v < lo or v > hi:
                return False
        x, y, theta, best = bx, by, 0.0, math.inf
        for length, angle in zip(links, q):
            theta += math.radians(angle)
            nx, ny = x + length * math.cos(theta), y + length * math.sin(theta)
            dx, dy = nx - x, ny - y
            den = dx * dx + dy * dy
            for kind, a, b, c, d in obstacles:
                if kind == 0.0:
                    dist = max(point_segment(a, b, x, y, dx, dy, den) - c, 0.0)
                else:
                    dist = seg_box(x, y, nx, ny, a, b, c, d)
                best = min(best, dist - radius)
            x, y = nx, ny
        return best > margin

    return is_valid


@pytest.fixture(scope="module")
def state():
    from ompl import base as ob

    space = ob.RealVectorStateSpace(2)
    s = space.allocState()
    s[0], s[1] = 37.0, -52.0
    return space, s


def _per_call(benchmark, fn, s, calls=2000):
    def run():
        for _ in range(calls):
            fn(s)

    benchmark.pedantic(run, rounds=20, iterations=1, warmup_rounds=1)
    benchmark.extra_info["per_call_us"] = benchmark.stats.stats.median / calls * 1e6


def test_validity_callback_compiled(benchmark, scenario, state):
    callback = make_validity_callback(scenario.arrays())
    _per_call(benchmark, callback, state[1])


def test_validity_callback_plain_python(benchmark, scenario, state):
    fn = python_validity(scenario.arrays())
    assert fn(state[1]) == make_validity_callback(scenario.arrays())(state[1])
    _per_call(benchmark, fn, state[1])


def test_validity_callback_via_ompl_isvalid(benchmark, scenario, state):
    from ompl import base as ob

    space, s = state
    a = scenario.arrays()
    bounds = ob.RealVectorBounds(2)
    bounds.setLow(-180.0)
    bounds.setHigh(180.0)
    space.setBounds(bounds)
    si = ob.SpaceInformation(space)
    si.setStateValidityChecker(make_validity_callback(a))
    si.setup()
    _per_call(benchmark, si.isValid, s)


@pytest.mark.parametrize("planner", ["RRT", "RRTConnect", "BITstar"])
def test_ompl_planner_50_seeds(benchmark, scenario, planner):
    plan_ompl(scenario, planner, seed=0)  # warm-up
    results = []

    def run():
        results.clear()
        results.extend(plan_ompl(scenario, planner, seed=s) for s in SEEDS)

    benchmark.pedantic(run, rounds=1, iterations=1)
    ok = [r for r in results if r.success]
    checks = [certify_path(scenario.arrays(), r.path_deg) for r in ok]
    benchmark.extra_info.update({
        "scenario": scenario.name,
        "success_rate": len(ok) / len(results),
        "time_to_first_solution_median_ms": float(np.median([r.wall_s for r in ok]) * 1e3),
        "iterations_median": float(np.median([r.iterations for r in ok])),
        "nodes_median": float(np.median([r.nodes for r in ok])),
        "cost_median_deg": float(np.median([r.cost_deg for r in ok])),
        "certified_fraction": float(np.mean([c.certified for c in checks])),
        "worst_penetration_m": float(max(c.penetration_m for c in checks)),
    })
