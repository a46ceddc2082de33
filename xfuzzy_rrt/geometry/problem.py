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
- ``margin``: the clearance (m) configurations must keep, with the user clearance folded in
  (:func:`~xfuzzy_rrt.geometry.collision.effective_margin`).
- ``clearance``: the surgeon's clearance (m) alone, ``margin`` less the certification slack.
- ``work[1]`` (int64): the deterministic work counter -- every exact element distance the
  collision kernels evaluate adds 1 (one per link-obstacle pair, per link-link pair of two
  arms). Fresh and zeroed for every bundle :meth:`ScenarioArrays.problem` makes, so a plan's
  count starts at 0; counting never changes a result.

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


def single_arm_problem(links, base, radius, obstacles, limits, start=None, goal=None,
                       margin: float = 1e-6) -> Problem:
    """A one-arm :class:`Problem` from the old positional pieces (tests, small tools)."""
    links = np.ascontiguousarray(links, dtype=np.float64)
    n = links.shape[0]
    limits = np.ascontiguousarray(limits, dtype=np.float64).reshape(n, 2)
    start = np.zeros(n) if start is None else np.ascontiguousarray(start, dtype=np.float64)
    goal = np.zeros(n) if goal is None else np.ascontiguousarray(goal, dtype=np.float64)
    return Problem(links, np.array([0, n], dtype=np.int64),
                   np.ascontiguousarray(base, dtype=np.float64).reshape(1, 2),
                   np.array([float(radius)]), np.ascontiguousarray(obstacles, dtype=np.float64).reshape(-1, 5),
                   limits, start, goal, float(margin), _clearance_of(float(margin)),
                   np.zeros(1, dtype=np.int64))


def _clearance_of(margin: float) -> float:
    """The user clearance folded into a kernel ``margin`` (0 for margins at or below the
    certification slack)."""
    from xfuzzy_rrt.geometry.collision import CERT_MARGIN_M

    return max(0.0, margin - CERT_MARGIN_M)


@nb.njit(cache=True, nogil=True)
def with_obstacles(P, obstacles):
    """``P`` with other obstacles (the robustness analysis moves and grows them per trial)."""
    return Problem(P.links, P.arm_first, P.bases, P.radii, obstacles, P.limits, P.start, P.goal,
                   P.margin, P.clearance, P.work)
