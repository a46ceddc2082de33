"""OMPL peers: cost of the compiled validity and motion callbacks, and OMPL plans on the
reference problem.

The validity callback is called by OMPL for every state it checks, so its per-call cost is
part of every OMPL time we report. Three variants are timed per call on the same state:

- ``compiled``: what the bridge uses (a two-line Python callable around a compiled numba
  function called with integer addresses),
- ``python``: the same check written in plain Python (exact capsule–circle/box distances),
- ``via_isValid``: the compiled callback as OMPL calls it (``SpaceInformation.isValid``).

The certified motion validator (``ompl:NAME``) is called once per motion; its overhead over
the compiled edge check itself is measured on the same set of motions
(:func:`motion_overhead`): ``compiled_us`` (``edge_free`` in a numba loop, no Python),
``from_python_us`` (the bridge's compiled ``motion_free_at`` called from a Python loop),
``via_ompl_us`` (OMPL's ``SpaceInformation.checkMotion`` with the certified validator: C++ ->
Python override -> two projections -> ``motion_free_at``) and ``dispatch_us`` (the same call to a Python validator
that returns True at once). Print it with
``.venv/bin/python benchmarks/test_bench_ompl.py [SCENARIO.toml ...]``.

Run: ``.venv/bin/python -m pytest benchmarks/test_bench_ompl.py --benchmark-only``.
"""

from __future__ import annotations

import math
import sys
import time

import numba as nb
import numpy as np
import pytest

from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M, config_free, edge_free
from xfuzzy_rrt.geometry.path_check import certify_path
from xfuzzy_rrt.planners.ompl_bridge import (certified_motion_validator, make_validity_callback,
                                             motion_free_at, new_counts, pack_scenario,
                                             plan_ompl)

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


@nb.njit(cache=True)
def _edge_checks(P, qa, qb, margin):
    free = 0
    for i in range(qa.shape[0]):
        free += edge_free(P, qa[i], qb[i], margin)
    return free


def _motions(arrays, n: int, length_deg: float, seed: int = 0):
    """``n`` motions of ``length_deg`` between free configurations (like a planner's edges)."""
    rng = np.random.default_rng(seed)
    P = arrays.problem(CERT_MARGIN_M)
    lo, hi = arrays.limits_deg[:, 0], arrays.limits_deg[:, 1]
    qa, qb = [], []
    while len(qa) < n:
        a = rng.uniform(lo, hi)
        d = rng.normal(size=a.shape)
        b = np.clip(a + length_deg * d / np.linalg.norm(d), lo, hi)
        if config_free(P, a, CERT_MARGIN_M) and config_free(P, b, CERT_MARGIN_M):
            qa.append(a)
            qb.append(b)
    return np.array(qa), np.array(qb)


def _best_per_call(fn, n: int, repeats: int = 7) -> float:
    """Smallest time per call (µs) over ``repeats`` runs of ``fn`` (which makes ``n`` calls)."""
    best = math.inf
    for _ in range(repeats):
        t = time.perf_counter()
        fn()
        best = min(best, time.perf_counter() - t)
    return best / n * 1e6


def motion_overhead(scenario, n: int = 500, length_deg: float = 10.0) -> dict[str, float]:
    """Per-motion cost (µs) of the certified motion check: compiled alone, called from Python
    and through OMPL, on the same ``n`` motions (see the module docstring)."""
    from ompl import base as ob

    a = scenario.arrays()
    dof = a.links.shape[0]
    qa, qb = _motions(a, n, length_deg)
    P = a.problem(CERT_MARGIN_M)
    expected = int(_edge_checks(P, qa, qb, CERT_MARGIN_M))
    compiled = _best_per_call(lambda: _edge_checks(P, qa, qb, CERT_MARGIN_M), n)

    fn = motion_free_at
    buffer = pack_scenario(a, CERT_MARGIN_M)
    counts = new_counts()
    xa, xb = np.empty(dof), np.empty(dof)
    args = (xa.ctypes.data, xb.ctypes.data, buffer.ctypes.data, counts.ctypes.data)

    def from_python():
        free = 0
        for i in range(n):
            xa[:] = qa[i]
            xb[:] = qb[i]
            free += fn(*args)
        return free

    assert from_python() == expected
    from_python_us = _best_per_call(from_python, n)

    space = ob.RealVectorStateSpace(dof)
    bounds = ob.RealVectorBounds(dof)
    for j in range(dof):
        bounds.setLow(j, float(a.limits_deg[j, 0]))
        bounds.setHigh(j, float(a.limits_deg[j, 1]))
    space.setBounds(bounds)
    states = []
    for i in range(n):
        s1, s2 = space.allocState(), space.allocState()
        for j in range(dof):
            s1[j], s2[j] = float(qa[i, j]), float(qb[i, j])
        states.append((s1, s2))

    def si_with(validator_of):
        si = ob.SpaceInformation(space)
        si.setStateValidityChecker(make_validity_callback(a))
        si.setMotionValidator(validator_of(si))
        si.setup()
        return si

    certified = si_with(lambda si: certified_motion_validator(si, space, a, CERT_MARGIN_M))

    class Accept(ob.MotionValidator):
        def checkMotion(self, s1, s2):  # noqa: N802
            return True

    trivial = si_with(Accept)

    def via(si):
        check = si.checkMotion
        return sum(check(s1, s2) for s1, s2 in states)

    assert via(certified) == expected
    return {"dof": dof, "motions": n, "length_deg": length_deg, "free": expected,
            "compiled_us": compiled, "from_python_us": from_python_us,
            "via_ompl_us": _best_per_call(lambda: via(certified), n),
            "dispatch_us": _best_per_call(lambda: via(trivial), n)}


def test_certified_motion_validator_overhead(benchmark, scenario):
    result = motion_overhead(scenario)
    benchmark.pedantic(lambda: None, rounds=1, iterations=1)
    benchmark.extra_info.update(result)
    benchmark.extra_info["overhead_us"] = result["via_ompl_us"] - result["compiled_us"]


@pytest.mark.parametrize("planner", ["RRT", "RRTConnect", "BITstar", "RRTConnect:sampled",
                                     "BITstar:sampled"])
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
        "found_uncertified": sum(r.found and not r.certified for r in results),
        "motion_validator": results[0].params["motion_validator"],
        "range_deg": results[0].params["range_deg"],
    })


if __name__ == "__main__":
    import os

    from xfuzzy_rrt.geometry.scenario import load_scenario

    files = sys.argv[1:] or [str(p) for p in (
        __import__("pathlib").Path(__file__).resolve().parents[2] / "shared" / "scenarios"
        / "paper-reference.toml",)]
    print(f"load {os.getloadavg()[0]:.2f}")
    for file in files:
        r = motion_overhead(load_scenario(file))
        print(f"{file}: " + ", ".join(f"{k} {v:.3g}" if isinstance(v, float) else f"{k} {v}"
                                      for k, v in r.items())
              + f", overhead_us {r['via_ompl_us'] - r['compiled_us']:.3g}")
    sys.stdout.flush()
    os._exit(0)  # skip the ompl wheel's teardown noise (see tests/conftest.py)
