"""Nearest neighbour: where the grid / k-d tree beats a linear scan, and how a whole run scales.

Two measurements on RRT-like trees (each node is a 10-degree step from its nearest node
towards a uniform sample, the order an RRT adds nodes in), in 2, 3, 5 and 7 joints:

1. **Crossover.** Per-query time of a linear scan against the structure (the 2-joint grid,
   or the k-d tree freshly built over all nodes) at tree sizes 16 ... 4096. The structure
   should be used above the first size where it wins for good: ``BRUTE_MAX_2D`` and
   ``BRUTE_MAX_KD`` in ``planners/tree.py``.
2. **Scaling.** Grow one tree to N nodes through ``add_node``/``nearest`` exactly as the
   planners do (brute force below the threshold, rebuilds, buffer) and record the cumulative
   distance evaluations (``meta[NN_VISITS]``) and time at N = 500 ... 10,000; the exponent of a
   log-log fit of total cost against N says whether a run is sub-quadratic (< 2).

    nice python benchmarks/nn_scaling.py                 # both, 2/3/5/7 joints
    nice python benchmarks/nn_scaling.py --dofs 7 --scaling-only
"""

from __future__ import annotations

import argparse
import math
import sys
import time

import numba as nb
import numpy as np

from xfuzzy_rrt.planners import tree as tr


@nb.njit(cache=True)
def rrt_like_points(dof, n, seed, step):
    """``n`` configurations in the order an RRT adds them (start at 0)."""
    np.random.seed(seed)
    pts = np.zeros((n, dof))
    for k in range(1, n):
        q = np.random.uniform(-180.0, 180.0, dof)
        best = 0
        bd = np.inf
        for i in range(k):
            d = 0.0
            for j in range(dof):
                d += (pts[i, j] - q[j]) ** 2
            if d < bd:
                bd = d
                best = i
        d = math.sqrt(bd)
        f = 1.0 if d <= step else step / d
        for j in range(dof):
            pts[k, j] = pts[best, j] + (q[j] - pts[best, j]) * f
    return pts


@nb.njit(cache=True)
def _fill(T, pts, n):
    for i in range(n):
        tr.add_node(T, pts[i], -1)


@nb.njit(cache=True)
def _time_scan(T, qs):
    s = 0
    for k in range(qs.shape[0]):
        s += tr.nearest_brute(T.nodes, T.meta[tr.N_NODES], qs[k])
    return s


@nb.njit(cache=True)
def _time_structure(T, qs):
    s = 0
    dof = T.nodes.shape[1]
    for k in range(qs.shape[0]):
        if dof == 2:
            s += tr._grid_nearest(T.nodes, T.cell_next, T.cell_head, T.meta, T.grid, qs[k])
        else:
            s += tr._kd_nearest(T, qs[k])
    return s


@nb.njit(cache=True)
def _grow(T, pts, qs, checkpoints, visits, elapsed_dummy):
    """Add ``pts`` one by one, one query (``qs[i]``) before each addition, as a planner does."""
    c = 0
    for i in range(pts.shape[0]):
        if i > 0:
            tr.nearest(T, qs[i])
        tr.add_node(T, pts[i], -1)
        if c < checkpoints.shape[0] and i + 1 == checkpoints[c]:
            visits[c] = T.meta[tr.NN_VISITS]
            c += 1
    return c


def _tree(dof, cap):
    return tr.make_tree(cap, np.array([[-180.0, 180.0]] * dof))


def crossover(dof, sizes, queries=2000, seed=1):
    pts = rrt_like_points(dof, max(sizes), seed, 10.0)
    rng = np.random.default_rng(seed)
    rows = []
    for n in sizes:
        T = _tree(dof, n + 1)
        _fill(T, pts, n)
        if dof > 2:
            tr._kd_build(T, n)
        qs = rng.uniform(-180.0, 180.0, (queries, dof))
        _time_scan(T, qs[:2]), _time_structure(T, qs[:2])
        best = {}
        for name, f in (("scan", _time_scan), ("structure", _time_structure)):
            times = []
            for _ in range(3):
                t0 = time.perf_counter()
                f(T, qs)
                times.append(time.perf_counter() - t0)
            best[name] = min(times) / queries * 1e9
        rows.append((n, best["scan"], best["structure"]))
    return rows


def scaling(dof, checkpoints, seed=2):
    n = max(checkpoints)
    pts = rrt_like_points(dof, n, seed, 10.0)
    qs = np.random.default_rng(seed).uniform(-180.0, 180.0, (n, dof))
    cps = np.array(sorted(checkpoints), dtype=np.int64)
    out = []
    for m in cps:  # time of a run grown to m nodes (separately: the clock is Python's)
        T = _tree(dof, int(m) + 1)
        _grow(T, pts[:2], qs[:2], cps[:0], np.zeros(0, dtype=np.int64), 0)
        T = _tree(dof, int(m) + 1)
        t0 = time.perf_counter()
        _grow(T, pts[:m], qs[:m], cps[:0], np.zeros(0, dtype=np.int64), 0)
        out.append((int(m), time.perf_counter() - t0, int(T.meta[tr.NN_VISITS])))
    return out


def fit_exponent(xs, ys):
    lx, ly = np.log(np.asarray(xs, float)), np.log(np.asarray(ys, float))
    return float(np.polyfit(lx, ly, 1)[0])


def main(argv=None) -> int:
    ap = argparse.ArgumentParser(description=__doc__.split("\n")[0])
    ap.add_argument("--dofs", default="2,3,5,7")
    ap.add_argument("--scaling-only", action="store_true")
    ap.add_argument("--max-n", type=int, default=10_000)
    args = ap.parse_args(argv)
    print(f"thresholds: BRUTE_MAX_2D={tr.BRUTE_MAX_2D} BRUTE_MAX_KD(3..7)={tr.BRUTE_MAX_KD}")
    for dof in (int(d) for d in args.dofs.split(",")):
        if not args.scaling_only:
            print(f"\n{dof} joints: ns per query (RRT-like tree, uniform queries)")
            print(f"{'nodes':>7} {'scan':>9} {'structure':>10}")
            for n, scan, st in crossover(dof, [16, 32, 64, 128, 256, 512, 1024, 2048, 4096]):
                print(f"{n:>7} {scan:>9.0f} {st:>10.0f}  {'structure' if st < scan else 'scan'}")
        cps = [c for c in (500, 1000, 2000, 4000, 7000, 10_000) if c <= args.max_n]
        rows = scaling(dof, cps)
        print(f"\n{dof} joints: a whole run through nearest()/add_node() (one query per node)")
        print(f"{'nodes':>7} {'total ms':>9} {'visits':>11} {'visits/query':>13}")
        for m, t, v in rows:
            print(f"{m:>7} {t * 1e3:>9.2f} {v:>11} {v / max(m - 1, 1):>13.1f}")
        big = [r for r in rows if r[0] >= 1000]
        print(f"fitted exponent (N >= 1000): time ~ N^{fit_exponent([r[0] for r in big], [r[1] for r in big]):.2f}, "
              f"visits ~ N^{fit_exponent([r[0] for r in big], [r[2] for r in big]):.2f}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
