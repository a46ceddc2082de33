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

from xfuzzy_rrt.planners.tree import NN_VISITS

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


@nb.njit(cache=True, nogil=True, _nrt=True)
def _block_sum(a, lo, n):
    """NumPy's pairwise summation of ``a[lo:lo + n]`` for ``n <= 128``: sequential below 8
    terms, else eight running sums combined as a balanced tree, then the remainder."""
    if n < 8:
        res = 0.0
        for i in range(lo, lo + n):
            res += a[i]
        return res
    r0, r1, r2, r3 = a[lo], a[lo + 1], a[lo + 2], a[lo + 3]
    r4, r5, r6, r7 = a[lo + 4], a[lo + 5], a[lo + 6], a[lo + 7]
    i = 8
    m = n - n % 8
    while i < m:
        k = lo + i
        r0 += a[k]
        r1 += a[k + 1]
        r2 += a[k + 2]
        r3 += a[k + 3]
        r4 += a[k + 4]
        r5 += a[k + 5]
        r6 += a[k + 6]
        r7 += a[k + 7]
        i += 8
    res = ((r0 + r1) + (r2 + r3)) + ((r4 + r5) + (r6 + r7))
    while i < n:
        res += a[lo + i]
        i += 1
    return res


@nb.njit(cache=True, nogil=True, _nrt=True)
def _pairwise_sum(a, lo, n):
    """``np.add.reduce(a[lo:lo + n])`` bit for bit: NumPy halves a sum of more than 128 terms
    at a multiple of 8 and adds the halves' sums (left + right). The same tree, walked with an
    explicit stack (a recursive numba function crashes when loaded from its cache)."""
    if n <= 128:
        return _block_sum(a, lo, n)
    los = np.empty(64, dtype=np.int64)
    ns = np.empty(64, dtype=np.int64)
    left = np.empty(64)
    has_left = np.zeros(64, dtype=np.bool_)
    top = 0
    los[0] = lo
    ns[0] = n
    while True:
        if ns[top] > 128:  # descend into the left half
            half = ns[top] // 2
            half -= half % 8
            has_left[top] = False
            los[top + 1] = los[top]
            ns[top + 1] = half
            top += 1
            continue
        v = _block_sum(a, los[top], ns[top])
        while True:  # hand v up until a frame still needs its right half
            if top == 0:
                return v
            top -= 1
            if has_left[top]:
                v = left[top] + v
                continue
            left[top] = v
            has_left[top] = True
            half = ns[top] // 2
            half -= half % 8
            los[top + 1] = los[top] + half
            ns[top + 1] = ns[top] - half
            top += 1
            break


@nb.njit(cache=True, nogil=True, _nrt=True)
def path_cost_compiled(path):
    """:func:`path_cost_deg` inside compiled code, the same float bit for bit (the same
    differences, squares and pairwise sums; ``tests/test_plan_overhead.py`` compares them)."""
    k, dof = path.shape
    if k < 2:
        return 0.0
    seg = np.empty(k - 1)
    sq = np.empty(dof)
    for i in range(k - 1):
        for j in range(dof):
            d = path[i + 1, j] - path[i, j]
            sq[j] = d * d
        seg[i] = np.sqrt(_pairwise_sum(sq, 0, dof))
    return _pairwise_sum(seg, 0, k - 1)


@nb.njit(cache=True, nogil=True, _nrt=True)
def finish_tree_run(nodes, parent, n, last, limits):
    """What a result keeps of a tree planner's run, in one compiled call: copies of the first
    ``n`` nodes and parents, the path from the root to node ``last`` (none when ``last < 0``),
    its cost (:func:`path_cost_compiled`), and whether every vertex is finite and within
    ``limits`` (:func:`vertices_within`, the re-check :func:`certified_result` makes of a
    kernel's path). Why one call: six NumPy and two compiled calls cost a short plan more
    than its search (``benchmarks/overhead.py``)."""
    tree_nodes = nodes[:n].copy()
    tree_parent = parent[:n].copy()
    path = branch_path(nodes, parent, last)
    within = path.shape[0] > 0 and vertices_within(path, limits)
    return tree_nodes, tree_parent, path, path_cost_compiled(path), within


@nb.njit(cache=True, nogil=True, inline="always")
def finished_tree(P, T, ok, iterations, last):
    """A tree kernel's run as its compiled entry returns it: ``(ok, iterations, last, n,
    nodes, parents, path, cost, within, work)`` -- the kernel's three values, the tree's size,
    :func:`finish_tree_run` of the tree (no path when the run failed), and the run's work
    (``P.work[0]`` plus the tree's nearest-neighbour visits).

    Why in the entry: a second compiled call from Python to finish the run, and reading the
    counters from Python, cost 40-60 us of a call that starts with cold caches (numba unboxes
    every argument again; docs/peer-measurements.md, twenty-second session)."""
    n = T.meta[0]
    nodes, parents, path, cost, within = finish_tree_run(T.nodes, T.parent, n,
                                                         last if ok else -1, P.limits)
    return (ok, iterations, last, n, nodes, parents, path, cost, within,
            P.work[0] + T.meta[NN_VISITS])


@nb.njit(cache=True, nogil=True, _nrt=True)
def branch_path(nodes, parent, last):
    """The path from the root to node ``last`` of a tree (``nodes``/``parent``), root first;
    empty when ``last < 0``. Shared by :func:`finish_tree_run` and the training evaluation
    (:func:`branch_cost`), so a trained path's cost is the planner's to the bit."""
    dof = nodes.shape[1]
    k = 0
    i = last
    while i >= 0:
        k += 1
        i = parent[i]
    path = np.empty((k, dof), dtype=np.float64)
    i = last
    j = k - 1
    while i >= 0:
        for d in range(dof):
            path[j, d] = nodes[i, d]
        j -= 1
        i = parent[i]
    return path


@nb.njit(cache=True, nogil=True, _nrt=True)
def branch_cost(nodes, parent, last):
    """``PlanResult.cost_deg`` of the path to node ``last`` (:func:`branch_path`,
    :func:`path_cost_compiled`), the same float bit for bit."""
    return path_cost_compiled(branch_path(nodes, parent, last))


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
    #: seconds of the planning call (for our planners, since the twenty-second session, the
    #: compiled entry: search, path extraction and tree copies; never the path's certification
    #: or anything before the entry): the kernel time of benchmark tables
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


#: Fields :func:`replace_result` changes by copying the instance dictionary: labels and
#: records that no check of ``__post_init__`` and no pending measurement depends on.
_RELABEL_FIELDS = frozenset({"planner", "planner_used", "params", "trace", "rulebook",
                             "rulebook_sha256"})


def replace_result(result: PlanResult, **changes: Any) -> PlanResult:
    """``dataclasses.replace`` that keeps a pending clearance measurement pending.

    Relabelling (``planner``, ``planner_used``, ``params``, ``trace``, ``rulebook``...) copies
    the instance dictionary instead of running the frozen ``__init__`` again (~10 us, paid by
    every ``rrt:tuned`` and ``fuzzy-rrt:NAME`` call): the same fields, the same pending
    measurement; any other change goes through ``dataclasses.replace``."""
    if type(result) is PlanResult and changes.keys() <= _RELABEL_FIELDS:
        new = object.__new__(PlanResult)
        d = new.__dict__
        d.update(result.__dict__)
        d.update(changes)
        return new
    pending = result.__dict__.get("_measurement")
    if pending is None:
        return dataclasses.replace(result, **changes)
    new = dataclasses.replace(result, min_clearance_m=_PENDING, penetration_m=_PENDING,
                              **changes)
    new.__dict__["_measurement"] = pending
    return new


@nb.njit(cache=True, nogil=True, _nrt=True)
def vertices_within(path, limits):
    """Every vertex of ``path`` [k, dof] finite and within ``limits`` [dof, 2] (one compiled
    pass instead of six NumPy calls: this runs after every plan)."""
    for i in range(path.shape[0]):
        for j in range(path.shape[1]):
            v = path[i, j]
            if not (math.isfinite(v) and v >= limits[j, 0] and v <= limits[j, 1]):
                return False
    return True


def _field_defaults() -> dict[str, Any]:
    """The instance dictionary of a certified, not yet measured :class:`PlanResult` before its
    caller's fields go in: every field's default, then the certified state."""
    out = {}
    for f in dataclasses.fields(PlanResult):
        slot = "_" + f.name if isinstance(PlanResult.__dict__.get(f.name), _Measured) else f.name
        if f.default is not dataclasses.MISSING:
            out[slot] = f.default
    out.update(found=True, certified=True, violation=None, _min_clearance_m=_PENDING,
               _penetration_m=_PENDING)
    return out


_CERTIFIED_DEFAULTS: dict[str, Any] | None = None
#: Fields without a default (``__init__`` refuses a call without them).
_REQUIRED = frozenset(f.name for f in dataclasses.fields(PlanResult)
                      if f.default is dataclasses.MISSING
                      and f.default_factory is dataclasses.MISSING)
#: The fields a :func:`_certified` caller may pass: the required ones, ``params`` (it must:
#: its default is a fresh dict) and these; the rest keep their defaults or the certified state.
_FAST_FIELDS = _REQUIRED | {"params", "rulebook", "rulebook_sha256", "trace", "work",
                            "certify_work", "planner_used"}


def _certified(fields: dict[str, Any]) -> PlanResult:
    """``PlanResult(found=True, certified=True, min_clearance_m=<pending>,
    penetration_m=<pending>, violation=None, **fields)`` without the frozen dataclass's
    ``__init__`` (one ``object.__setattr__`` per field: ~7 us, a tenth of a short plan's
    budget). The same instance dictionary, entry for entry (``tests/test_plan_overhead.py``
    compares the two); any other set of fields goes through ``__init__``."""
    global _CERTIFIED_DEFAULTS
    keys = fields.keys()
    if not (_REQUIRED <= keys and "params" in keys and keys <= _FAST_FIELDS):
        return PlanResult(found=True, certified=True, min_clearance_m=_PENDING,
                          penetration_m=_PENDING, violation=None, **fields)
    if _CERTIFIED_DEFAULTS is None:
        _CERTIFIED_DEFAULTS = _field_defaults()
    result = object.__new__(PlanResult)
    d = result.__dict__
    d.update(_CERTIFIED_DEFAULTS)
    d.update(fields)
    return result


def certified_template(**fields: Any) -> dict[str, Any]:
    """The instance dictionary :func:`certified_result` gives a compiled planner's certified
    path with these fields (every default, the certified state, then ``fields``, as
    :func:`_certified` makes it), for :func:`bound_result` to copy and fill run by run: the
    fields a run does not change (``scenario``, ``planner``, ``planner_used``, ``rulebook``,
    ``rulebook_sha256``) are set once, the others are placeholders."""
    return dict(_certified(fields).__dict__)


def planner_template(name: str, label: str, planner_used: str, rulebook=None) -> dict[str, Any]:
    """:func:`certified_template` for a run of a compiled planner: the fields a run does not
    change (the scenario's name, the label, the planner that ran, the rulebook if any) set,
    the run's own as placeholders for :func:`bound_result`. One list for every planner's kept
    runs and general path alike."""
    named = {} if rulebook is None else {"rulebook": rulebook.name,
                                         "rulebook_sha256": rulebook.sha256}
    return certified_template(
        scenario=name, planner=label, planner_used=planner_used, seed=0, iterations=0, nodes=0,
        cost_deg=None, wall_s=0.0, path_deg=None, tree_nodes_deg=None, tree_parent=None,
        work=0, params=None, **named)


def bound_result(template: dict[str, Any], arrays, margin: float, ok: bool, within: bool,
                 seed: int, iterations: int, nodes: int, cost: float, wall: float, path,
                 tree_nodes, tree_parent, work: int, params: dict) -> PlanResult:
    """``certified_result(arrays, margin, ok, edges_certified=True, within_limits=within,
    **fields)`` for a compiled planner's run, the fixed fields taken from ``template``
    (:func:`certified_template`) and the run's own passed by position. Every run of RRT,
    Fuzzy-RRT and Fuzzy-RRT-Connect ends here (the planners' ``_lane`` and ``_run``), so the
    fields a run does not change are listed once (:func:`planner_template`).

    Why: with the caches cold (``evaluate``'s default; a plan between other work) a run spent
    as much Python around its compiled call as in it: keyword calls, ``asarray``, the field
    checks of :func:`_certified` and the conversions. With the template made once per set-up
    and label (``_lane``) and filled here, a cold call of the default or ``rrt:tuned`` costs
    40-60 us less of ~300 us at 3 joints and ~50 us of ~230 at 2 (docs/peer-measurements.md,
    twenty-third session). A certified path (found, every vertex within the limits, every
    edge certified by the kernel) copies the template and sets the run's fields; anything else
    (a failure) goes through :func:`certified_result` itself. The values are the ones the
    kernel returned: Python ``int``/``bool``/``float`` already (numba boxes them so)."""
    if ok and within and path.shape[0] >= 2:
        result = _new_object(PlanResult)
        d = result.__dict__
        d.update(template)
        d["seed"] = seed
        d["iterations"] = iterations
        d["nodes"] = nodes
        d["cost_deg"] = cost
        d["wall_s"] = wall
        d["path_deg"] = path
        d["tree_nodes_deg"] = tree_nodes
        d["tree_parent"] = tree_parent
        d["work"] = work
        d["params"] = params
        d["_measurement"] = functools.partial(_path_check_module().path_min_clearance, arrays,
                                              path, margin)
        return result
    return certified_result(
        arrays, margin, bool(ok), edges_certified=True, within_limits=within,
        scenario=template["scenario"], planner=template["planner"],
        planner_used=template["planner_used"], seed=seed, iterations=iterations, nodes=nodes,
        cost_deg=cost if ok else None, wall_s=wall, path_deg=path, tree_nodes_deg=tree_nodes,
        tree_parent=tree_parent, work=work, rulebook=template["rulebook"],
        rulebook_sha256=template["rulebook_sha256"], params=params)


_new_object = object.__new__


_path_check = None


def _path_check_module():
    """``geometry.path_check``, imported on first use (it imports the planners' neighbours)."""
    global _path_check
    if _path_check is None:
        from xfuzzy_rrt.geometry import path_check

        _path_check = path_check
    return _path_check


def certified_result(arrays, margin: float, found: bool, edges_certified: bool = False,
                     within_limits: bool | None = None, **fields: Any) -> PlanResult:
    """A :class:`PlanResult` whose path (``fields["path_deg"]``) has been certified.

    Every planner ends here, so ``found``/``certified``/``min_clearance_m`` mean the same for
    RRT, Fuzzy-RRT and OMPL's planners: the path is put through the exact check after the timed
    planning (``wall_s`` does not include it).

    ``edges_certified``: every segment of the path is a tree edge that the planner's kernel
    accepted with :func:`~xfuzzy_rrt.geometry.collision.edge_free` at this ``margin``, from
    parent to child on the very same floats (our RRT and Fuzzy-RRT kernels). Running
    ``edge_free`` again would return the same verdicts, so only the vertices' joint limits are
    re-checked: no certification work is done twice. A certified path's exact clearance is
    measured on first access (module docstring). ``within_limits``: that re-check's verdict
    when the caller already made it on this very path (:func:`finish_tree_run`).
    """
    path = np.asarray(fields["path_deg"], dtype=np.float64)
    if not found or path.size == 0:
        return PlanResult(found=bool(found) and path.size > 0, **fields)
    checks = _path_check_module()
    if edges_certified and path.ndim == 2 and path.shape[0] >= 2 and path.shape[1] == \
            arrays.limits_deg.shape[0] and (within_limits if within_limits is not None else
                                            vertices_within(np.ascontiguousarray(path),
                                                             np.ascontiguousarray(
                                                                 arrays.limits_deg,
                                                                 dtype=np.float64))):
        result = _certified(fields)
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
