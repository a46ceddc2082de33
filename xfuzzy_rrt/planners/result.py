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

**Measured when asked.** The exact minimum clearance is a Lipschitz branch and bound that costs
more than most plans (median ~0.6 ms against a ~0.3 ms kernel), and most callers (training, the
time-to-certified-path measure, library loops) never read it. So for a certified path
``min_clearance_m`` and ``penetration_m`` are computed on first access (the ``plan`` JSON,
``bench`` runs.csv and the report do access them) and then kept: the value is the one an eager
computation gives, bit for bit. Copy a result with :func:`replace_result`, which carries the
pending measurement along instead of forcing it (``dataclasses.replace`` works too, but
measures first).

``work`` is the deterministic work count of the planning (not of the final certification), in
*distance evaluations*: every exact link-obstacle and link-link distance the collision kernels
evaluated (``Problem.work``) plus every tree node whose distance to a nearest-neighbour query
was computed (``TreeArrays.meta[NN_VISITS]``). Same seed, same count, on any machine and with
any number of workers, so it compares planners where wall-clock time is noisy. ``None`` for a
planner that does not count (OMPL's, until its bridge counts).
"""

from __future__ import annotations

import dataclasses
import functools
import math
from dataclasses import dataclass, field
from typing import Any

import numba as nb
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
    """Sum of Euclidean joint-space segment lengths, in degrees.

    The ufuncs are called directly (``np.diff``, ``** 2`` and ``np.sum`` are these same
    operations behind several layers of argument handling: a third of a short plan's overhead),
    so the value is the one they give, bit for bit."""
    path = np.asarray(path_deg, dtype=np.float64)
    if path.shape[0] < 2:
        return 0.0
    d = path[1:] - path[:-1]
    return float(np.add.reduce(np.sqrt(np.add.reduce(d * d, axis=1)), axis=0))


class _Pending:
    """The "not measured yet" marker; pickles as a reference to the one instance."""

    def __reduce__(self):
        return "_PENDING"

    def __repr__(self):
        return "<pending>"


#: Stands for "not measured yet" in a result's clearance slots.
_PENDING = _Pending()


class _Measured:
    """A field whose value may be computed on first read (see the module docstring).

    A data descriptor, so the dataclass ``__init__`` stores through it and a read of a pending
    value runs the result's measurement once. Its default (class-level read) is ``None``.
    """

    def __set_name__(self, owner, name):
        self.slot = "_" + name

    def __get__(self, obj, owner=None):
        if obj is None:
            return None
        value = obj.__dict__[self.slot]
        if value is _PENDING:
            obj._measure()
            value = obj.__dict__[self.slot]
        return value

    def __set__(self, obj, value):
        obj.__dict__[self.slot] = value


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
    min_clearance_m: float | None = _Measured()
    penetration_m: float | None = _Measured()
    #: Why a found path is not certified (one sentence naming the segment, configuration and
    #: depth); ``None`` when certified or when nothing was found.
    violation: str | None = None
    #: Deterministic work count (module docstring); ``None`` when the planner does not count.
    work: int | None = None
    #: The same count for certifying the returned path (exact minimum clearance and certified
    #: edge check; 0 without a path): ``work + certify_work`` is the end-to-end work, the
    #: deterministic stand-in for the time a user waits (the tuner's objective).
    certify_work: int = 0
    #: The planner that actually ran, as ``--planner`` names it without a rulebook
    #: (``fuzzy-rrt-connect`` when plain ``fuzzy-rrt`` planned a problem that is not one 2-joint
    #: arm with its shipped default; ``fuzzy-rrt`` for ``fuzzy-rrt:NAME``); ``None``: ``planner``.
    planner_used: str | None = None

    def __post_init__(self) -> None:
        if self.certified and not self.found:
            raise ValueError("a result without a path cannot be certified")

    def _measure(self) -> None:
        """Run the pending clearance measurement and keep its values."""
        value, penetration = self.__dict__.pop("_measurement")()
        self.__dict__["_min_clearance_m"] = float(value)
        self.__dict__["_penetration_m"] = float(penetration)

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
            "planner_used": self.planner_used or self.planner,
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


def replace_result(result: PlanResult, **changes: Any) -> PlanResult:
    """``dataclasses.replace`` that keeps a pending clearance measurement pending."""
    pending = result.__dict__.get("_measurement")
    if pending is None:
        return dataclasses.replace(result, **changes)
    new = dataclasses.replace(result, min_clearance_m=_PENDING, penetration_m=_PENDING,
                              **changes)
    new.__dict__["_measurement"] = pending
    return new


@nb.njit(cache=True, nogil=True)
def _vertices_within(path, limits):
    """Every vertex of ``path`` [k, dof] finite and within ``limits`` [dof, 2] (one compiled
    pass instead of six NumPy calls: this runs after every plan)."""
    for i in range(path.shape[0]):
        for j in range(path.shape[1]):
            v = path[i, j]
            if not (math.isfinite(v) and v >= limits[j, 0] and v <= limits[j, 1]):
                return False
    return True


_path_check = None


def _path_check_module():
    """``geometry.path_check``, imported on first use (it imports the planners' neighbours)."""
    global _path_check
    if _path_check is None:
        from xfuzzy_rrt.geometry import path_check

        _path_check = path_check
    return _path_check


def certified_result(arrays, margin: float, found: bool, edges_certified: bool = False,
                     **fields: Any) -> PlanResult:
    """A :class:`PlanResult` whose path (``fields["path_deg"]``) has been certified.

    Every planner ends here, so ``found``/``certified``/``min_clearance_m`` mean the same for
    RRT, Fuzzy-RRT and OMPL's planners: the path is put through the exact check after the timed
    planning (``wall_s`` does not include it).

    ``edges_certified``: every segment of the path is a tree edge that the planner's kernel
    accepted with :func:`~xfuzzy_rrt.geometry.collision.edge_free` at this ``margin``, from
    parent to child on the very same floats (our RRT and Fuzzy-RRT kernels). Running
    ``edge_free`` again would return the same verdicts, so only the vertices' joint limits are
    re-checked: no certification work is done twice. A certified path's exact clearance is
    measured on first access (module docstring).
    """
    path = np.asarray(fields["path_deg"], dtype=np.float64)
    if not found or path.size == 0:
        return PlanResult(found=bool(found) and path.size > 0, **fields)
    checks = _path_check_module()
    if edges_certified and path.ndim == 2 and path.shape[0] >= 2 and path.shape[1] == \
            arrays.limits_deg.shape[0] and _vertices_within(
                np.ascontiguousarray(path), np.ascontiguousarray(arrays.limits_deg,
                                                                 dtype=np.float64)):
        result = PlanResult(found=True, certified=True, min_clearance_m=_PENDING,
                            penetration_m=_PENDING, violation=None, **fields)
        result.__dict__["_measurement"] = functools.partial(checks.path_min_clearance, arrays,
                                                            path, float(margin))
        return result
    if path.ndim == 2 and path.shape[0] >= 2 and path.shape[1] == arrays.limits_deg.shape[0] \
            and np.all(np.isfinite(path)):
        # Another planner's path (OMPL's): every segment goes through the certified check now;
        # only when it passes is the exact clearance deferred like ours. A path that fails is
        # measured at once, because its violation sentence names where and how deep.
        work = checks.segments_certified(arrays, path, margin)
        if work is not None:
            result = PlanResult(found=True, certified=True, min_clearance_m=_PENDING,
                                penetration_m=_PENDING, violation=None, certify_work=work,
                                **fields)
            result.__dict__["_measurement"] = functools.partial(checks.path_min_clearance,
                                                                arrays, path, float(margin))
            return result
    check = checks.certify_path(arrays, path, margin)
    return PlanResult(found=True, certified=check.certified,
                      min_clearance_m=float(check.min_clearance_m),
                      penetration_m=float(check.penetration_m),
                      violation=None if check.certified else check.describe(),
                      certify_work=int(check.work), **fields)
