"""What a planner returns: a frozen result with the path, the bookkeeping and the tree.

``iterations`` is the paper's *x*: loop iterations until the goal joined the tree, every sample
counting whether it was accepted or rejected (``max_iter`` on failure). ``nodes`` is the tree
size at the end, start and (on success) goal included. ``cost_deg`` is the joint-space length of
the path in degrees (``None`` on failure).
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
    success: bool
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

    def to_json_dict(self) -> dict[str, Any]:
        """The SPEC.md result object (plus ``params``), with plain Python numbers."""
        cost = None if self.cost_deg is None or not math.isfinite(self.cost_deg) else self.cost_deg
        return {
            "scenario": self.scenario,
            "planner": self.planner,
            "rulebook": self.rulebook,
            "rulebook_sha256": self.rulebook_sha256,
            "seed": int(self.seed),
            "success": bool(self.success),
            "iterations": int(self.iterations),
            "nodes": int(self.nodes),
            "cost_deg": cost,
            "wall_s": float(self.wall_s),
            "path_deg": [[float(a) for a in row] for row in self.path_deg],
            "params": dict(self.params),
        }
