"""What a planner returns: a frozen result with the path, the bookkeeping and the tree.

``iterations`` is the paper's *x*: loop iterations until the goal joined the tree, every sample
counting whether it was accepted or rejected (``max_iter`` on failure). ``nodes`` is the tree
size at the end, start and (on success) goal included. ``cost_deg`` is the joint-space length of
the path in degrees (``None`` on failure).

``found`` says the planner returned a path; ``certified`` that every segment of it passes the
certified check (:func:`xfuzzy_rrt.geometry.path_check.certify_path`, whatever planner made
it); ``success`` is derived, ``found and certified``, so no result can call a colliding path a
success. ``min_clearance_m`` is the exact smallest signed distance between any link capsule
and any obstacle along the path (negative: penetration depth; ``None`` without a path, ``inf``
without obstacles -- ``null`` in JSON either way). Planners build results through :func:`certified_result`.

``work`` is the deterministic work count of the planning (not of the final certification), in
*distance evaluations*: every exact link-obstacle and link-link distance the collision kernels
evaluated (``Problem.work``) plus every tree node whose distance to a nearest-neighbour query
was computed (``TreeArrays.meta[NN_VISITS]``). Same seed, same count, on any machine and with
any number of workers, so it compares planners where wall-clock time is noisy. ``None`` for a
planner that does not count (OMPL's, until its bridge counts).
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field
from typing import Any

import numpy as np

#: Per-iteration outcome codes, shared by planners and traces.
ACCEPTED = 0
NODE_IN_COLLISION = 1
EDGE_BLOCKED = 2
GOAL_REACHED = 3
NO_PROGRESS = 4  # the sample coincided with its nearest node: nothing to steer towards

OUTCOME_NAMES = {
    ACCEPTED: "accepted",
    NODE_IN_COLLISION: "node_in_collision",
    EDGE_BLOCKED: "edge_blocked",
    GOAL_REACHED: "goal_reached",
    NO_PROGRESS: "no_progress",
}


def path_cost_deg(path_deg: np.ndarray) -> float:
    """Sum of Euclidean joint-space segment lengths, in degrees."""
    path = np.asarray(path_deg, dtype=np.float64)
    if path.shape[0] < 2:
        return 0.0
    return float(np.sum(np.sqrt(np.sum(np.diff(path, axis=0) ** 2, axis=1))))


@dataclass(frozen=True)
class PlanResult:
    scenario: str
    planner: str
    seed: int
    iterations: int
    nodes: int
    cost_deg: float | None
    wall_s: float
    path_deg: np.ndarray
    tree_nodes_deg: np.ndarray = field(repr=False)
    tree_parent: np.ndarray = field(repr=False)
    rulebook: str | None = None
    rulebook_sha256: str | None = None
    params: dict[str, Any] = field(default_factory=dict)
    trace: Any = field(default=None, repr=False)
    found: bool = False
    certified: bool = False
    min_clearance_m: float | None = None
    penetration_m: float | None = None
    #: Why a found path is not certified (one sentence naming the segment, configuration and
    #: depth); ``None`` when certified or when nothing was found.
    violation: str | None = None
    #: Deterministic work count (module docstring); ``None`` when the planner does not count.
    work: int | None = None
    #: The same count for certifying the returned path (exact minimum clearance and certified
    #: edge check; 0 without a path): ``work + certify_work`` is the end-to-end work, the
    #: deterministic stand-in for the time a user waits (the tuner's objective).
    certify_work: int = 0

    def __post_init__(self) -> None:
        if self.certified and not self.found:
            raise ValueError("a result without a path cannot be certified")

    @property
    def success(self) -> bool:
        """A path was found *and* it is certified collision-free."""
        return bool(self.found and self.certified)

    def to_json_dict(self) -> dict[str, Any]:
        """The SPEC.md result object (plus ``params``), with plain Python numbers."""
        cost = None if self.cost_deg is None or not math.isfinite(self.cost_deg) else self.cost_deg
        return {
            "scenario": self.scenario,
            "planner": self.planner,
            "rulebook": self.rulebook,
            "rulebook_sha256": self.rulebook_sha256,
            "seed": int(self.seed),
            "success": self.success,
            "iterations": int(self.iterations),
            "nodes": int(self.nodes),
            "cost_deg": cost,
            "found": bool(self.found),
            "certified": bool(self.certified),
            "min_clearance_m": _finite_or_none(self.min_clearance_m),
            "penetration_m": _finite_or_none(self.penetration_m),
            "wall_s": float(self.wall_s),
            "work": None if self.work is None else int(self.work),
            "certify_work": int(self.certify_work),
            "path_deg": [[float(a) for a in row] for row in self.path_deg],
            "params": dict(self.params),
        }


def _finite_or_none(x: float | None) -> float | None:
    return None if x is None or not math.isfinite(x) else float(x)


def certified_result(arrays, margin: float, found: bool, **fields: Any) -> PlanResult:
    """A :class:`PlanResult` whose path (``fields["path_deg"]``) has been certified.

    Every planner ends here, so ``found``/``certified``/``min_clearance_m`` mean the same for
    RRT, Fuzzy-RRT and OMPL's planners: the path is put through the exact check after the timed
    planning (``wall_s`` does not include it).
    """
    from xfuzzy_rrt.geometry.path_check import certify_path

    path = np.asarray(fields["path_deg"], dtype=np.float64)
    if not found or path.size == 0:
        return PlanResult(found=bool(found) and path.size > 0, **fields)
    check = certify_path(arrays, path, margin)
    return PlanResult(found=True, certified=check.certified,
                      min_clearance_m=float(check.min_clearance_m),
                      penetration_m=float(check.penetration_m),
                      violation=None if check.certified else check.describe(),
                      certify_work=int(check.work), **fields)
