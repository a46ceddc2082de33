"""The compiled problem bundle: what every planner, check and certificate works on.

OMPL splits a planning job into a *problem* (space, start, goal), a *validity checker* and a
*planner*; this is our problem, as one typed record numba passes by value into compiled code.
Kernels take a ``Problem`` instead of a dozen positional arrays, so a new capability (another
arm, a margin) changes one record, not every signature.

Fields (all float64 unless said):

- ``links[L]``: link lengths of every arm, arm after arm. Joint ``j`` turns link ``j``.
- ``arm_first[A + 1]`` (int64): arm ``a`` owns links and joints ``arm_first[a]`` to
  ``arm_first[a + 1] - 1``; ``arm_first[A] == L`` is the joint-space dimension.
- ``bases[A, 2]``: each arm's base (m); ``radii[A]``: each arm's capsule radius (m).
- ``obstacles[O, 5]``: ``[kind, a, b, c, d]`` rows (see ``geometry/scenario.py``).
- ``limits[L, 2]``, ``start[L]``, ``goal[L]``: joint limits and configurations in degrees.
- ``margin``: the clearance (m) configurations must keep: the surgeon's clearance plus the
  1 µm certification margin (:func:`~xfuzzy_rrt.geometry.collision.effective_margin`).
- ``clearance``: the surgeon's clearance (m) alone, which the certified edge check holds
  everywhere along a segment (0.0 by default; ``collision.clearance_of_margin``).
- ``work`` (int64, length 1): ``work[0]`` counts exact element distance evaluations (one per
  link-obstacle pair, per link pair of two arms, per non-adjacent link pair of one arm) made by
  ``clearance_kernel`` and ``edge_free``. A mutable counter inside an immutable record: every
  bundle built by ``ScenarioArrays.problem`` or :func:`single_arm_problem` gets a fresh zeroed
  one, and copies made with ``_replace`` / :func:`with_obstacles` share it. Never read by a
  kernel, so counting cannot change a result.

A single-arm problem has ``A = 1`` and every loop over arms runs once, so its arithmetic is the
one of the single-arm code it replaced, operation for operation (the golden files pin it).
"""

from __future__ import annotations

from typing import NamedTuple

import numba as nb
import numpy as np


class Problem(NamedTuple):
    links: np.ndarray
    arm_first: np.ndarray
    bases: np.ndarray
    radii: np.ndarray
    obstacles: np.ndarray
    limits: np.ndarray
    start: np.ndarray
    goal: np.ndarray
    margin: float
    clearance: float
    work: np.ndarray


def stop_record_width(arm_first) -> int:
    """Columns of a tree node's stop record for arms split as ``arm_first`` (joints in all:
    ``arm_first[-1]``): what :func:`~xfuzzy_rrt.geometry.collision.stop_width` computes in
    compiled code (a flag, one per link, one per link pair that can touch), for the Python
    side that makes the trees (:func:`~xfuzzy_rrt.planners.tree.make_tree`); 0 with two joints
    in all, where a two-link arm keeps its own per-link values and two one-link arms keep
    none."""
    sizes = [int(n) for n in np.diff(np.asarray(arm_first, dtype=np.int64))]
    dof = sum(sizes)
    if dof <= 2:
        return 0
    pairs = sum((n - 1) * (n - 2) // 2 for n in sizes if n >= 3)
    pairs += sum(a * b for i, a in enumerate(sizes) for b in sizes[i + 1:])
    return 1 + dof + pairs


def new_work_counter() -> np.ndarray:
    """A fresh zeroed ``work`` counter (``np.int64``, length 1)."""
    return np.zeros(1, dtype=np.int64)


def single_arm_problem(links, base, radius, obstacles, limits, start=None, goal=None,
                       margin: float = 1e-6) -> Problem:
    """A one-arm :class:`Problem` from the old positional pieces (tests, small tools); its
    clearance is the one ``margin`` stands for (``collision.clearance_of_margin``)."""
    from xfuzzy_rrt.geometry.collision import clearance_of_margin

    links = np.ascontiguousarray(links, dtype=np.float64)
    n = links.shape[0]
    limits = np.ascontiguousarray(limits, dtype=np.float64).reshape(n, 2)
    start = np.zeros(n) if start is None else np.ascontiguousarray(start, dtype=np.float64)
    goal = np.zeros(n) if goal is None else np.ascontiguousarray(goal, dtype=np.float64)
    return Problem(links, np.array([0, n], dtype=np.int64),
                   np.ascontiguousarray(base, dtype=np.float64).reshape(1, 2),
                   np.array([float(radius)]), np.ascontiguousarray(obstacles, dtype=np.float64).reshape(-1, 5),
                   limits, start, goal, float(margin), clearance_of_margin(margin),
                   new_work_counter())


@nb.njit(cache=True, nogil=True, _nrt=True)
def with_obstacles(P, obstacles):
    """``P`` with other obstacles (the robustness analysis moves and grows them per trial)."""
    return Problem(P.links, P.arm_first, P.bases, P.radii, obstacles, P.limits, P.start, P.goal,
                   P.margin, P.clearance, P.work)


def arms_problem(arms, obstacles=(), limits=None, margin: float = 1e-6) -> Problem:
    """A :class:`Problem` of several arms ``[(links, base, radius), ...]`` (tests, small tools):
    obstacle rows ``[kind, a, b, c, d]``, joint limits ``[L, 2]`` (default ±180°), start and
    goal at zero, the clearance ``margin`` stands for and a fresh work counter."""
    from xfuzzy_rrt.geometry.collision import clearance_of_margin

    links = np.ascontiguousarray(np.concatenate([np.asarray(l, dtype=np.float64).reshape(-1)
                                                 for l, _, _ in arms]))
    first = np.zeros(len(arms) + 1, dtype=np.int64)
    for a, (l, _, _) in enumerate(arms):
        first[a + 1] = first[a] + np.asarray(l).reshape(-1).shape[0]
    n = links.shape[0]
    limits = (np.tile([-180.0, 180.0], (n, 1)) if limits is None
              else np.ascontiguousarray(limits, dtype=np.float64).reshape(n, 2))
    bases = np.ascontiguousarray([np.asarray(b, dtype=np.float64).reshape(2) for _, b, _ in arms])
    radii = np.array([float(r) for _, _, r in arms])
    obstacles = np.ascontiguousarray(np.asarray(obstacles, dtype=np.float64).reshape(-1, 5))
    return Problem(links, first, bases, radii, obstacles, limits, np.zeros(n), np.zeros(n),
                   float(margin), clearance_of_margin(margin), new_work_counter())
