"""OMPL's geometric planners as peers of RRT and Fuzzy-RRT, on the same problem and checker.

Why: OMPL is the field's reference implementation; a claim that Fuzzy-RRT is "faster" means
little unless it stands next to OMPL's planners at their best, checked as strictly as ours. So
an OMPL run here is set up exactly as our planners are
(``plan_scenario(..., planner="ompl:RRTConnect")``):

- **Labels**: ``ompl:NAME[:sampled][:range=DEG]`` (:func:`parse_ompl_label`). ``NAME`` is any
  geometric planner of the wheel but the ``UNSUPPORTED`` ones; the options may come in any
  order, each at most once; anything else is one InputError naming the option.
- **State space**: ``RealVectorStateSpace(dof)`` in *degrees*, bounded by the scenario's joint
  limits (the same units and the same box our planners sample in).
- **Start and goal exact**: a ``GoalState`` with threshold ``GOAL_THRESHOLD_DEG`` (machine
  epsilon), so a solution must end on the goal. The planners copy the goal state itself, so the
  path ends on it bit for bit; should a planner ever stop within the threshold but not on it,
  the exact goal is appended *only if our certified check accepts that last edge*
  (``params["goal_appended"]``), otherwise the run counts as a failure.
- **Range** (planners that have one: RRT, RRTConnect, RRT*, ...; BIT* has none, it is a batch
  planner): the label's ``range=DEG``, else an explicit ``step_deg`` argument, else the tuned
  range of ``ompl:NAME`` (:func:`xfuzzy_rrt.planners.tuned.tuned_params`; the same range with
  ``:sampled``, so the two validators are compared at one setting), else ``DEFAULT_RANGE_DEG``
  (10 degrees, the paper's RRT step). ``params`` records ``range_deg`` and ``range_source``.
  Goal bias ``goal_bias`` (0.05) on the planners that have one (RRT, RRT*).
- **Stop at the first solution**: optimising planners (RRT*, BIT*, ...) get a path-length
  objective whose cost threshold is +inf, so any exact solution satisfies it and they return it
  immediately. ``wall_s`` is the time of the ``solve`` call: the time to the first solution
  (setup and the validity-checker construction are not included, as for our planners).
- **Budget derived from ``max_iter``**: the termination condition is evaluated once per planner
  loop iteration; it stops the run after ``max_iter`` evaluations (a deterministic budget,
  like ours) or after a wall-clock safety cap ``time_limit_s`` (default
  ``max(10 s, 1 ms × max_iter)``; ``params["stopped_by"]`` says which, if any, ended the run).
- **Iterations**: planners that count their own iterations (RRT*, Informed RRT*, SORRT*, BIT*
  expose ``numIterations()``) report that number; for the others the count of
  termination-condition evaluations that returned "go on", which for RRT is exactly its loop
  iterations (one sample each, like ours) and for RRTConnect its loop iterations (one sample,
  one extension, then connection attempts), possibly plus one evaluation while it draws the
  goal root. The planner progress properties (``"iterations INTEGER"``) would be the natural
  source, but the 2.0.1 Python bindings cannot convert that map. ``params["iterations_source"]``
  names the source used. ``nodes`` is the number of vertices in the planner data.
- **Validity: our checker.** A state is valid iff
  :func:`~xfuzzy_rrt.geometry.collision.config_free` holds with the scenario's margin (its
  clearance folded in). It runs compiled (:func:`state_free_at`, numba) over a packed float64
  buffer, called with integer addresses from a short Python callback (the bindings only
  accept a Python callable).
- **Motions: our certified edge check** (``ompl:NAME``, ``params["motion_validator"] ==
  "certified"``). OMPL asks a :class:`ob.MotionValidator <ompl.base.MotionValidator>` subclass,
  whose ``checkMotion(s1, s2)`` copies both states into two preallocated arrays (one
  projection call each) and makes one call into a compiled function (:func:`motion_free_at`)
  that runs
  :func:`~xfuzzy_rrt.geometry.collision.edge_free` (conservative advancement) on the whole
  straight segment -- OMPL's ``RealVectorStateSpace`` interpolates linearly, so that segment is
  exactly the motion the planner adds. Every edge of every OMPL tree is therefore certified, and
  OMPL competes on its algorithm, not on a cheaper check. Python still runs once per motion and
  once per state (no Python per stop inside an edge): the 2.0.1 bindings cannot take a
  compiled validator (``setMotionValidator`` accepts a ``MotionValidator`` object, and only
  Python subclasses of it can be written without compiling against the wheel's OMPL; Debian's
  ``libompl-dev`` is OMPL 1.5, another ABI). ``benchmarks/test_bench_ompl.py`` times the
  per-call overhead.
- **The last-valid-state overload.** The bindings' trampoline maps
  ``checkMotion(s1, s2, lastValid)`` onto ``checkMotion(s1, s2)`` and never writes
  ``lastValid``, so a planner that asks for the valid part of a refused motion sees the pair as
  it initialised it. KPIECE1, BKPIECE1, LBKPIECE1, STRIDE, RLRT and BiRLRT initialise the
  fraction to 0 and so keep nothing of a refused motion (conservative: they lose partial
  extensions, never add an unchecked state). PDST ignores the verdict and reads the last valid
  state from the pair: it would add the unchecked end state, so it runs only as
  ``ompl:PDST:sampled`` (``CERTIFIED_UNSUPPORTED``).
- **Motions: OMPL's own** (``ompl:NAME:sampled``, ``params["motion_validator"] ==
  "sampled"``): OMPL's ``DiscreteMotionValidator`` at OMPL's default resolution (1 % of the
  space's extent, about 5.1° for ±180° limits, unless ``validity_resolution`` is given), kept
  to show what sampling an edge costs in penetrating paths.
- **Belt and braces**: the raw path goes through
  :func:`~xfuzzy_rrt.planners.result.certified_result` like every planner's: ``found`` is
  OMPL's exact solution, ``success`` needs ``certified`` too, and a grazing path (possible only
  with ``:sampled``) reports where and how deep it goes (``violation``, ``penetration_m``,
  ``min_clearance_m``). With the certified validator, the validator logs the motions it accepts
  (:func:`motion_free_logged_at`, up to :data:`MOTION_LOG`); a path whose every segment is a
  logged motion bit for bit (either way round; the edge to an appended goal is certified by
  ``segment_free``) is certified already and is not checked a second time -- our own planners'
  tree edges are not either (fair comparisons: the second check was 5-8 % of an OMPL call).
  Any other path, and every ``:sampled`` one, is certified after planning
  (``params["path_check"]`` says which).
- **Counts**: ``params["state_checks"]`` and ``params["motions_checked"]`` count the checks
  OMPL asked for. ``params["work"]`` is the number of exact element distance evaluations of
  those checks when the problem bundle counts them (``Problem.work``, interfaces.md item 1),
  else ``None``. It counts collision-check work only: OMPL's nearest-neighbour work happens in
  C++ and is invisible to us.
- **Raw path**: the path is the planner's own, not simplified by OMPL (shortening is ours and
  certified: :mod:`xfuzzy_rrt.planners.shortcut`).

Known limitation of the ompl 2.0.1 wheel: after ``BITstar.getPlannerData`` the BIT* graph is
never freed -- as far as we can tell OMPL's BIT* keeps every vertex it hands to a
``PlannerData`` alive on purpose (so the raw state pointers stay valid), and the vertices hold
the ``SpaceInformation``. So each BIT* run keeps its graph for the life of the process (about
70 kB per run on the test fixtures, more for larger graphs) and nanobind lists the leaked
objects on stderr at interpreter exit. No other supported planner does this; ``clear()`` and
``gc.collect()`` do not help. Long BIT* benchmarks are best run in worker processes.

Determinism: ``ompl.util.RNG.setSeed`` is called before each plan and every OMPL object that
draws random numbers (space, samplers, planner) is created after it, so the same seed gives the
same path, iterations and nodes within a process and across processes, as long as the run is
not ended by the wall-clock cap (which depends on the machine) and OMPL runs single-threaded
(all planners used here are). OMPL seeds must be positive 32-bit integers, so our seed is
mapped to ``seed mod (2**32 - 1) + 1`` (``params["ompl_seed"]``). OMPL's own log output is
silenced during a plan (it would otherwise warn that re-seeding happens after the first seed).
"""

from __future__ import annotations

import functools
import math
import time
from dataclasses import dataclass

import numba as nb
import numpy as np
from numba import carray

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.geometry import collision
from xfuzzy_rrt.geometry.collision import (CERT_MARGIN_M, config_free, edge_free, segment_free,
                                           within_limits)
from xfuzzy_rrt.geometry.scenario import Scenario
from xfuzzy_rrt.geometry.problem import Problem
from xfuzzy_rrt.planners.checks import check_dof, check_max_iter, check_positive
from xfuzzy_rrt.planners.prepared import scenario_arrays
from xfuzzy_rrt.planners.result import PlanResult, certified_result, path_cost_deg
from xfuzzy_rrt.planners.tuned import TWO_JOINT, shape_of
from xfuzzy_rrt.planners.tree_arena import pointer_at

OMPL_PREFIX = "ompl:"
MISSING_EXTRA = "ompl:* planners need the optional 'ompl' extra: pip install -e '.[ompl]'"
#: Goal tolerance in degrees: machine epsilon, so "reaching the goal" means being on it.
GOAL_THRESHOLD_DEG = 2.220446049250313e-16
#: Range (degrees) when neither the label, the caller nor a tuned file gives one: the paper's
#: RRT step, which was the only setting before ranges were tuned.
DEFAULT_RANGE_DEG = 10.0
#: Label options after ``ompl:NAME`` (each at most once, any order).
SAMPLED_OPTION = "sampled"
RANGE_OPTION = "range"
LABEL_OPTIONS = "sampled, range=DEG"


#: Geometric planners of the wheel that cannot run here, and why (found by running each one).
UNSUPPORTED = {
    "PRM": "it grows its roadmap in a second thread, which cannot call the Python validity "
           "callback while solve() holds the interpreter lock (the run deadlocks)",
    "PRMstar": "it grows its roadmap in a second thread, which cannot call the Python validity "
               "callback while solve() holds the interpreter lock (the run deadlocks)",
    "AORRTC": "it crashes the interpreter (segmentation fault) on some seeds in the ompl 2.0.1 "
              "wheel ('AOXRRTConnect: Failed to find any neighbours for a state')",
}
#: Planners that cannot be certified by construction (they run only with ``:sampled``).
CERTIFIED_UNSUPPORTED = {
    "PDST": "it ignores the motion check's verdict and reads the last valid state of the motion, "
            "which the bindings' Python motion validators cannot report (it would add unchecked "
            "states)",
}


def import_ompl(where: str = "--planners"):
    """``(ompl.base, ompl.geometric, ompl.util)`` or one clear InputError naming the extra
    (and the option, ``where``, that asked for an OMPL planner)."""
    try:
        from ompl import base as ob
        from ompl import geometric as og
        from ompl import util as ou
    except ImportError:
        raise InputError(where, MISSING_EXTRA) from None
    return ob, og, ou


def ompl_planner_names(where: str = "--planners") -> tuple[str, ...]:
    """Geometric planners this OMPL build exposes and ``ompl:NAME`` accepts (not UNSUPPORTED)."""
    import_ompl(where)
    return _planner_names()


@functools.cache
def _planner_names() -> tuple[str, ...]:
    # Cached: every plan validates its label, and scanning the module is not free.
    ob, og, _ = import_ompl()
    names = []
    for name in dir(og):
        obj = getattr(og, name)
        if (isinstance(obj, type) and issubclass(obj, ob.Planner) and not name.startswith("_")
                and name not in UNSUPPORTED):
            names.append(name)
    return tuple(sorted(names))


@dataclass(frozen=True)
class OmplLabel:
    """An ``ompl:NAME[:sampled][:range=DEG]`` label, validated (:func:`parse_ompl_label`).

    ``label`` is the text as written (with the ``ompl:`` prefix); ``sampled`` selects OMPL's
    own discrete motion validator instead of the certified one; ``range_deg`` is the label's
    range (``None``: the tuned or default range applies).
    """

    label: str
    name: str
    sampled: bool = False
    range_deg: float | None = None

    @property
    def base(self) -> str:
        """``ompl:NAME`` without options: the key of the tuned parameters."""
        return OMPL_PREFIX + self.name


#: Labels :func:`parse_ompl_label` accepted, as parsed. Why: a plan parses its label twice (the
#: registry's hook, then :func:`plan_ompl`), string work and look-ups a call that our own
#: planners do not pay (fair comparisons). Safe to keep: with OMPL importable, a label's verdict
#: cannot change in this process; whether it still is importable is asked again on every call
#: (the missing extra is named under the caller's ``where``). Errors are never kept.
_PARSED_LABELS: dict[str, OmplLabel] = {}


def parse_ompl_label(label: str, where: str = "--planners") -> OmplLabel:
    """Validate ``ompl:NAME[:sampled][:range=DEG]`` (or ``NAME[:...]``): one InputError naming
    ``where`` for an unknown or unsupported planner, an unknown or repeated option, a range
    that is not a positive number of degrees, or a range on a planner without one."""
    hit = _PARSED_LABELS.get(label)
    if hit is not None:
        import_ompl(where)
        return hit
    spec = _parse_ompl_label(label, where)
    _PARSED_LABELS[label] = spec
    return spec


def _parse_ompl_label(label: str, where: str) -> OmplLabel:
    text = label if label.startswith(OMPL_PREFIX) else OMPL_PREFIX + label
    name, *options = text[len(OMPL_PREFIX):].split(":")
    _, og, _ = import_ompl(where)
    known = ompl_planner_names(where)
    if name in UNSUPPORTED:
        raise InputError(where, f"OMPL planner {name!r} is not supported: "
                         f"{UNSUPPORTED[name]} (supported: {', '.join(known)})")
    if name not in known:
        raise InputError(where, f"unknown OMPL planner {name!r} (known: {', '.join(known)})")
    sampled = False
    range_deg = None
    seen: set[str] = set()
    for option in options:
        key, eq, value = option.partition("=")
        if key in seen:
            raise InputError(where, f"option {key!r} given twice in {text!r}")
        seen.add(key)
        if key == SAMPLED_OPTION and not eq:
            sampled = True
        elif key == RANGE_OPTION:
            range_deg = _label_range(value if eq else None, text, where)
            if not hasattr(getattr(og, name), "setRange"):
                raise InputError(where, f"OMPL planner {name!r} has no range (in {text!r})")
        else:
            raise InputError(where, f"unknown option {option!r} in {text!r} "
                             f"(options: {LABEL_OPTIONS})")
    if not sampled and name in CERTIFIED_UNSUPPORTED:
        raise InputError(where, f"OMPL planner {name!r} cannot run with the certified motion "
                         f"check: {CERTIFIED_UNSUPPORTED[name]}; use {OMPL_PREFIX}{name}:"
                         f"{SAMPLED_OPTION}")
    return OmplLabel(text, name, sampled, range_deg)


def _label_range(value: str | None, text: str, where: str) -> float:
    problem = f"range must be a positive number of degrees (range=DEG) in {text!r}"
    if value is None:
        raise InputError(where, problem)
    try:
        r = float(value)
    except ValueError:
        raise InputError(where, f"{problem}, got {value!r}") from None
    if not (math.isfinite(r) and r > 0.0):
        raise InputError(where, f"{problem}, got {value!r}")
    return r


def check_ompl_planner(name: str, where: str = "--planners") -> str:
    """The bare OMPL planner name of a valid ``ompl:NAME[:OPTIONS]`` label (or ``NAME``);
    InputError naming ``where`` (the option the label came from) otherwise."""
    return parse_ompl_label(name, where).name


@dataclass(frozen=True)
class TunedRange:
    """The range ``ompl:NAME`` runs at when neither its label nor the caller gives one: the
    shipped tuned file's (``source`` ``"tuned"``), else :data:`DEFAULT_RANGE_DEG`
    (``"default"``), read once (:func:`load_tuned_range`). Callers that plan many problems
    (evaluate, bench) pass it as ``plan_scenario(..., "ompl:NAME", rulebook=...)``, as they
    pass ``rrt:tuned``'s :class:`~xfuzzy_rrt.planners.api.TunedRRT` and the default's loaded
    rulebooks: no peer re-reads a file inside a timed call (fair comparisons)."""

    base: str
    range_deg: float
    source: str
    #: ``((shape, range_deg), ...)``: every shipped shape's tuned range
    #: (:mod:`xfuzzy_rrt.planners.tuned`, "Per arm shape"); a problem runs at its nearest
    #: shape's. Empty: ``range_deg`` for every problem.
    by_shape: tuple = ()

    def range_for(self, shape) -> tuple[float, str]:
        """``(range_deg, source)`` for a problem of ``shape``: the nearest tuned shape's range
        with source ``"tuned"`` (one 2-joint arm) or ``"tuned for 2 arms, 6 joints"``."""
        if not self.by_shape:
            return self.range_deg, self.source
        from xfuzzy_rrt.planners.tuned import nearest_row, tuned_source

        near, range_deg = nearest_row(self.by_shape, tuple(shape))
        return range_deg, tuned_source(near)


def _checked_range(base: str, tuned: dict) -> float:
    r = float(tuned["range_deg"])
    if not (math.isfinite(r) and r > 0.0):
        raise InputError(base, f"tuned range must be a positive number of degrees, "
                         f"got {tuned['range_deg']!r}")
    return r


def load_tuned_range(base: str) -> TunedRange:
    """:class:`TunedRange` of ``ompl:NAME`` (``base``) as the tuned files give it now, every
    shape's; a broken file is one InputError naming it."""
    from xfuzzy_rrt.planners.tuned import tuned_by_shape

    rows = tuple(sorted((shape, _checked_range(base, params))
                        for shape, params in tuned_by_shape(base).items()
                        if params.get("range_deg") is not None))
    two = [r for shape, r in rows if shape == TWO_JOINT]
    if rows:
        return TunedRange(base, two[0] if two else rows[0][1], "tuned", rows)
    return TunedRange(base, DEFAULT_RANGE_DEG, "default")


def resolve_range(spec: OmplLabel, step_deg: float | None = None,
                  tuned: TunedRange | None = None, shape=TWO_JOINT) -> tuple[float, str]:
    """``(range_deg, source)`` for a planner that has a range: the label's, else ``step_deg``
    (an explicit argument), else the tuned range of ``ompl:NAME`` for problems of ``shape``
    (:meth:`TunedRange.range_for`), else ``DEFAULT_RANGE_DEG``. ``source`` is ``"label"``,
    ``"argument"``, ``"tuned"`` (``"tuned for 2 arms, 6 joints"`` when another shape's file
    set it) or ``"default"``. ``tuned``: that tuned range read before
    (:func:`load_tuned_range`; one of another planner is ignored)."""
    if spec.range_deg is not None:
        return spec.range_deg, "label"
    if step_deg is not None:
        check_positive("step_deg", step_deg)
        return float(step_deg), "argument"
    if tuned is None or tuned.base != spec.base:
        tuned = load_tuned_range(spec.base)
    return tuned.range_for(shape)


def ompl_seed(seed: int) -> int:
    """Map any integer seed to OMPL's positive 32-bit seed range (0 would be ignored)."""
    return int(seed) % (2**32 - 1) + 1


# ----------------------------------------------------------------------------------------------
# The compiled checks
# ----------------------------------------------------------------------------------------------

_HEADER = 5  # [dof, obstacles, arms, margin, clearance]

#: Slots of the int64 counter array the compiled checks update (read after a plan).
STATE_CHECKS = 0
MOTION_CHECKS = 1
MOTIONS_REFUSED = 2
WORK = 3
N_COUNTS = 4

#: Does the problem bundle count its distance evaluations (``Problem.work``, interfaces.md
#: item 1, with the surgeon's ``clearance`` beside ``margin``)? Then the checks below hand it
#: the ``WORK`` slot of the counters, and ``params["work"]`` reports it.
COUNTS_WORK = "work" in Problem._fields


def _clearance_of(margin: float) -> float:
    """The surgeon's clearance a kernel ``margin`` stands for (what ``edge_free`` recovers)."""
    of_margin = getattr(collision, "clearance_of_margin", None)
    if of_margin is not None:
        return float(of_margin(margin))
    return max(float(margin) - CERT_MARGIN_M, 0.0)


def pack_scenario(arrays, margin: float) -> np.ndarray:
    """The problem as one contiguous float64 buffer the compiled checks read through a raw
    pointer: ``[dof, obstacles, arms, margin, clearance, arm_first (arms + 1), bases
    (2 arms), radii (arms), links (dof), limits (2 dof), obstacles (5 per obstacle)]``."""
    dof = arrays.links.shape[0]
    m = arrays.obstacles.shape[0]
    n_arms = arrays.n_arms
    return np.ascontiguousarray(np.concatenate([
        [float(dof), float(m), float(n_arms), float(margin), _clearance_of(margin)],
        arrays.arm_first.astype(np.float64), arrays.bases.ravel(), arrays.radii, arrays.links,
        arrays.limits_deg.ravel(), arrays.obstacles.ravel(),
    ]).astype(np.float64))


@nb.njit(cache=True, nogil=True, _nrt=True)
def _unpack(ptr):
    """The :func:`pack_scenario` buffer at ``ptr`` as the pieces of a problem bundle."""
    head = carray(ptr, (_HEADER,), dtype=np.float64)
    dof = int(head[0])
    m = int(head[1])
    n_arms = int(head[2])
    size = _HEADER + (n_arms + 1) + 3 * n_arms + 3 * dof + 5 * m
    data = carray(ptr, (size,), dtype=np.float64)
    k = _HEADER
    arm_first = np.empty(n_arms + 1, dtype=np.int64)
    for a in range(n_arms + 1):
        arm_first[a] = int(data[k + a])
    k += n_arms + 1
    bases = data[k:k + 2 * n_arms].reshape((n_arms, 2))
    k += 2 * n_arms
    radii = data[k:k + n_arms]
    k += n_arms
    links = data[k:k + dof]
    k += dof
    limits = data[k:k + 2 * dof].reshape((dof, 2))
    k += 2 * dof
    obstacles = data[k:k + 5 * m].reshape((m, 5))
    return links, arm_first, bases, radii, obstacles, limits, head[3], head[4]


@nb.njit(cache=True, nogil=True, _nrt=True)
def _bundle_counting(ptr, counts, q):
    links, arm_first, bases, radii, obstacles, limits, margin, clear = _unpack(ptr)
    return Problem(links, arm_first, bases, radii, obstacles, limits, q, q, margin, clear,
                   counts[WORK:WORK + 1])


@nb.njit(cache=True, nogil=True, _nrt=True)
def _bundle_plain(ptr, counts, q):
    links, arm_first, bases, radii, obstacles, limits, margin, clear = _unpack(ptr)
    return Problem(links, arm_first, bases, radii, obstacles, limits, q, q, margin)


#: The problem bundle of a packed buffer (its start and goal are unused placeholders). Only the
#: variant matching ``Problem``'s fields is ever compiled.
_bundle = _bundle_counting if COUNTS_WORK else _bundle_plain


#: Explicit signatures: compiled (or loaded from the cache) at import, like a ``cfunc``, so the
#: first plan of a process does not compile inside OMPL's timed ``solve`` (and hit its cap).
_AT3 = nb.types.boolean(nb.types.intp, nb.types.intp, nb.types.intp)
_AT4 = nb.types.boolean(nb.types.intp, nb.types.intp, nb.types.intp, nb.types.intp)
_AT6 = nb.types.boolean(nb.types.intp, nb.types.intp, nb.types.intp, nb.types.intp,
                        nb.types.intp, nb.types.intp)
#: Accepted motions a certified validator remembers (:func:`motion_free_logged_at`): enough for
#: the runs where checking the path again would matter; a run that accepts more simply has its
#: path certified again (~110 KB at 7 joints, allocated per plan, never touched beyond use).
MOTION_LOG = 1024


@nb.njit(_AT3, cache=True, nogil=True, _nrt=True)
def state_free_at(q_at, buffer_at, counts_at):
    """Compiled check of the configuration at address ``q_at`` in the :func:`pack_scenario`
    buffer at ``buffer_at`` (counters at ``counts_at``): the planners' own
    :func:`~xfuzzy_rrt.geometry.collision.config_free`.

    Why addresses: OMPL calls a Python callable, and a compiled function taking only integers
    is the cheapest compiled call we found from Python (numba's dispatcher types integers at
    once; calling a ``cfunc`` through ctypes cost more per call in our measurements, passing
    arrays more still). The caller keeps the buffers alive while the addresses are in use.
    """
    ptr = pointer_at(buffer_at)
    head = carray(ptr, (_HEADER,), dtype=np.float64)
    counts = carray(pointer_at(counts_at), (N_COUNTS,), dtype=np.int64)
    q = carray(pointer_at(q_at), (int(head[0]),), dtype=np.float64)
    P = _bundle(ptr, counts, q)
    counts[STATE_CHECKS] += 1
    return config_free(P, q, P.margin)


@nb.njit(_AT4, cache=True, nogil=True, _nrt=True)
def motion_free_at(qa_at, qb_at, buffer_at, counts_at):
    """Compiled certified check of the straight motion from the configuration at ``qa_at`` to
    the one at ``qb_at``: :func:`~xfuzzy_rrt.geometry.collision.edge_free` on the whole
    segment, both ends within the joint limits (``edge_free`` assumes it)."""
    ptr = pointer_at(buffer_at)
    head = carray(ptr, (_HEADER,), dtype=np.float64)
    counts = carray(pointer_at(counts_at), (N_COUNTS,), dtype=np.int64)
    dof = int(head[0])
    qa = carray(pointer_at(qa_at), (dof,), dtype=np.float64)
    qb = carray(pointer_at(qb_at), (dof,), dtype=np.float64)
    P = _bundle(ptr, counts, qa)
    counts[MOTION_CHECKS] += 1
    ok = within_limits(P.limits, qa) and within_limits(P.limits, qb) and \
        edge_free(P, qa, qb, P.margin)
    if not ok:
        counts[MOTIONS_REFUSED] += 1
    return ok


@nb.njit(_AT6, cache=True, nogil=True, _nrt=True)
def motion_free_logged_at(qa_at, qb_at, buffer_at, counts_at, log_at, meta_at):
    """:func:`motion_free_at`, and an accepted motion's two ends copied into the log at
    ``log_at`` (``[cap, 2, dof]`` float64; ``meta_at``: int64 ``[logged, cap]``) while it has
    room. Why: the path OMPL returns is made of motions this validator accepted, and a path
    segment found in the log, bit for bit, was certified at this margin already (the
    certificate covers the segment's configurations, whichever way it was checked), so the
    result need not certify it again: our own planners are not made to certify their tree
    edges twice either (fair comparisons; :func:`segments_logged`)."""
    ok = motion_free_at(qa_at, qb_at, buffer_at, counts_at)
    if ok:
        meta = carray(pointer_at(meta_at), (2,), dtype=np.int64)
        n = meta[0]
        if n < meta[1]:
            ptr = pointer_at(buffer_at)
            dof = int(carray(ptr, (_HEADER,), dtype=np.float64)[0])
            log = carray(pointer_at(log_at), (meta[1], 2, dof), dtype=np.float64)
            qa = carray(pointer_at(qa_at), (dof,), dtype=np.float64)
            qb = carray(pointer_at(qb_at), (dof,), dtype=np.float64)
            for j in range(dof):
                log[n, 0, j] = qa[j]
                log[n, 1, j] = qb[j]
            meta[0] = n + 1
    return ok


@nb.njit(cache=True, nogil=True, _nrt=False)
def segments_logged(path, log, n_logged):
    """Whether every segment of ``path`` (``[k, dof]``) is one of the first ``n_logged``
    motions of ``log`` (``[cap, 2, dof]``), exactly, in either direction."""
    dof = path.shape[1]
    for i in range(path.shape[0] - 1):
        found = False
        for m in range(n_logged):
            for end in range(2):
                same = True
                for j in range(dof):
                    if log[m, end, j] != path[i, j] or log[m, 1 - end, j] != path[i + 1, j]:
                        same = False
                        break
                if same:
                    found = True
                    break
            if found:
                break
        if not found:
            return False
    return True


def new_counts() -> np.ndarray:
    """A zeroed counter array for the compiled checks (slots ``STATE_CHECKS`` ... ``WORK``)."""
    return np.zeros(N_COUNTS, dtype=np.int64)


def make_validity_callback(arrays, margin: float = CERT_MARGIN_M, counts=None, space=None):
    """A Python callable ``state -> bool`` for OMPL that runs our compiled check.

    ``counts`` (from :func:`new_counts`) receives the number of checks (and the work when the
    problem bundle counts it). The state is copied by OMPL's identity projection of ``space``
    (the planning ``RealVectorStateSpace``; a fresh one of the same dimension if ``None``): one
    C++ call instead of one Python indexing per joint. The buffers and the projection are bound
    as default arguments so they live as long as the callback.
    """
    ob, _, _ = import_ompl("--planner")
    buffer = pack_scenario(arrays, margin)
    counts = new_counts() if counts is None else counts
    dof = arrays.links.shape[0]
    space = ob.RealVectorStateSpace(dof) if space is None else space
    projection = ob.RealVectorIdentityProjectionEvaluator(space)
    q = np.empty(dof, dtype=np.float64)

    def is_valid(state, _project=projection.project, _fn=state_free_at, _q=q,
                 _args=(q.ctypes.data, buffer.ctypes.data, counts.ctypes.data),
                 _keep=(buffer, counts, projection, space)):
        _project(state, _q)
        return _fn(*_args)

    return is_valid


@functools.cache
def _certified_validator_class():
    """The ``ob.MotionValidator`` subclass (made once: ompl is an optional import)."""
    ob, _, _ = import_ompl("--planner")

    class CertifiedMotionValidator(ob.MotionValidator):
        """OMPL motion validator that runs the certified edge check, compiled.

        One Python call per motion: both states are copied by OMPL's identity projection
        (one C++ call each) into preallocated arrays, then one compiled call,
        :func:`motion_free_at`, checks the whole segment. It must not hold the
        ``SpaceInformation``'s Python object (that would make a cycle through C++ that the
        garbage collector cannot see).
        """

        def __init__(self, si, space, arrays, margin: float, counts: np.ndarray):
            super().__init__(si)
            dof = arrays.links.shape[0]
            self._projection = ob.RealVectorIdentityProjectionEvaluator(space)
            self._project = self._projection.project
            self._qa = np.empty(dof, dtype=np.float64)
            self._qb = np.empty(dof, dtype=np.float64)
            self._buffer = pack_scenario(arrays, margin)
            self._counts = counts
            #: the accepted motions (motion_free_logged_at) and ``[logged, capacity]``
            self.log = np.empty((MOTION_LOG, 2, dof), dtype=np.float64)
            self.log_meta = np.array([0, MOTION_LOG], dtype=np.int64)
            self._fn = motion_free_logged_at
            self._args = (self._qa.ctypes.data, self._qb.ctypes.data,
                          self._buffer.ctypes.data, counts.ctypes.data, self.log.ctypes.data,
                          self.log_meta.ctypes.data)

        def certified(self, path: np.ndarray) -> bool:
            """Whether every segment of ``path`` is a motion this validator accepted (exactly,
            either way: :func:`segments_logged`), so certified already at its margin."""
            n = int(self.log_meta[0])
            return path.shape[0] >= 2 and n > 0 and bool(
                segments_logged(np.ascontiguousarray(path, dtype=np.float64), self.log, n))

        def checkMotion(self, s1, s2):  # noqa: N802 - OMPL's name
            self._project(s1, self._qa)
            self._project(s2, self._qb)
            return self._fn(*self._args)

    return CertifiedMotionValidator


def certified_motion_validator(si, space, arrays, margin: float = CERT_MARGIN_M, counts=None):
    """An OMPL motion validator for ``si`` (over ``space``, a ``RealVectorStateSpace`` in
    degrees) that accepts a motion iff our certified edge check does."""
    counts = new_counts() if counts is None else counts
    return _certified_validator_class()(si, space, arrays, margin, counts)


# ----------------------------------------------------------------------------------------------
# Planning
# ----------------------------------------------------------------------------------------------

def plan_ompl(scenario: Scenario, planner: str, seed: int = 0, max_iter: int = 10_000,
              step_deg: float | None = None, goal_bias: float = 0.05,
              margin: float | None = None, time_limit_s: float | None = None,
              validity_resolution: float | None = None,
              clearance_m: float | None = None,
              tuned: TunedRange | None = None) -> PlanResult:
    """Plan ``scenario`` with the OMPL planner a label names (``"ompl:RRTConnect"``,
    ``"ompl:RRT:sampled:range=60"``, or a bare ``"RRT"``).

    ``step_deg`` sets the range when the label does not (``None``: the tuned range, else
    ``DEFAULT_RANGE_DEG``; ``tuned``: that range read once, :func:`load_tuned_range`).
    ``validity_resolution`` is OMPL's state-validity checking resolution
    as a fraction of the space's extent, for ``:sampled`` only (``None``: OMPL's default 0.01).
    See the module docstring for everything else; the returned ``PlanResult.planner`` is the
    label (with its ``ompl:`` prefix).
    """
    ob, og, ou = import_ompl("--planner")
    spec = parse_ompl_label(planner, "--planner")
    bare = spec.name
    check_dof(scenario)
    check_max_iter(max_iter)
    if not 0.0 <= goal_bias <= 1.0:
        raise InputError("goal_bias", f"must lie in [0, 1], got {goal_bias!r}")
    from xfuzzy_rrt.geometry.clearance import planning_margin  # validity callback and certify

    margin = planning_margin(scenario, clearance_m, margin)
    if time_limit_s is None:
        time_limit_s = max(10.0, 1e-3 * max_iter)
    check_positive("time_limit_s", time_limit_s)
    if validity_resolution is not None:
        check_positive("validity_resolution", validity_resolution)
        if not spec.sampled:
            raise InputError("validity_resolution", "sets OMPL's sampled motion check: use "
                             f"{spec.base}:{SAMPLED_OPTION}")
    has_range = hasattr(getattr(og, bare), "setRange")
    range_deg, range_source = (resolve_range(spec, step_deg, tuned, shape_of(scenario))
                               if has_range else (None, None))
    # built once per scenario object, as for our planners (read only here)
    a = scenario_arrays(scenario)
    dof = a.links.shape[0]
    counts = new_counts()

    previous_level = ou.getLogLevel()
    ou.setLogLevel(ou.LOG_NONE)
    try:
        seed_used = ompl_seed(seed)
        ou.RNG.setSeed(seed_used)
        space = ob.RealVectorStateSpace(dof)
        bounds = ob.RealVectorBounds(dof)
        for j in range(dof):
            bounds.setLow(j, float(a.limits_deg[j, 0]))
            bounds.setHigh(j, float(a.limits_deg[j, 1]))
        space.setBounds(bounds)
        si = ob.SpaceInformation(space)
        si.setStateValidityChecker(make_validity_callback(a, margin, counts, space))
        validator = None
        if spec.sampled:
            if validity_resolution is not None:
                si.setStateValidityCheckingResolution(float(validity_resolution))
        else:
            validator = certified_motion_validator(si, space, a, margin, counts)
            si.setMotionValidator(validator)
        si.setup()
        start = space.allocState()
        goal = space.allocState()
        for j in range(dof):
            start[j] = float(a.start_deg[j])
            goal[j] = float(a.goal_deg[j])
        pdef = ob.ProblemDefinition(si)
        pdef.setStartAndGoalStates(start, goal, GOAL_THRESHOLD_DEG)
        objective = ob.PathLengthOptimizationObjective(si)
        objective.setCostThreshold(ob.Cost(math.inf))  # any solution is good enough: stop
        pdef.setOptimizationObjective(objective)

        p = getattr(og, bare)(si)
        applied: dict[str, float | None] = {"range_deg": None, "goal_bias": None}
        if range_deg is not None:
            p.setRange(float(range_deg))
            applied["range_deg"] = float(range_deg)
        if hasattr(p, "setGoalBias"):
            p.setGoalBias(float(goal_bias))
            applied["goal_bias"] = float(goal_bias)
        p.setProblemDefinition(pdef)
        p.setup()

        state = {"go_on": 0, "stopped_by": None}
        deadline = [math.inf]

        def terminate() -> bool:
            if state["go_on"] >= max_iter:
                state["stopped_by"] = "max_iter"
                return True
            if time.perf_counter() > deadline[0]:
                state["stopped_by"] = "time_limit"
                return True
            state["go_on"] += 1
            return False

        ptc = ob.PlannerTerminationCondition(terminate)
        # One C++ call per state read back (path and tree), not one Python index per joint.
        copy_state = ob.RealVectorIdentityProjectionEvaluator(space).project
        t0 = time.perf_counter()
        deadline[0] = t0 + time_limit_s
        status = str(p.solve(ptc))
        wall = time.perf_counter() - t0

        exact = bool(pdef.hasExactSolution())
        path = np.zeros((0, dof))
        goal_appended = False
        failure = None
        if exact:
            states = pdef.getSolutionPath().getStates()
            path = np.empty((len(states), dof), dtype=np.float64)
            for k, s in enumerate(states):
                copy_state(s, path[k])
            if not np.array_equal(path[0], a.start_deg):
                exact, failure = False, "path does not start at the start configuration"
            elif not np.array_equal(path[-1], a.goal_deg):
                if segment_free(a, path[-1], a.goal_deg, margin):
                    path = np.vstack([path, a.goal_deg[None, :]])
                    goal_appended = True
                else:
                    exact, failure = False, "last state is within the goal threshold but the " \
                                            "edge to the exact goal is not certified"
        if not exact:
            path = np.zeros((0, dof))

        if hasattr(p, "numIterations"):
            iterations, source = int(p.numIterations()), "numIterations"
        else:
            iterations, source = int(state["go_on"]), "termination-condition evaluations"

        data = ob.PlannerData(si)
        p.getPlannerData(data)
        n = int(data.numVertices())
        tree = np.empty((n, dof), dtype=np.float64)
        parent = np.full(n, -1, dtype=np.int64)
        for i in range(n):
            copy_state(data.getVertex(i).getState(), tree[i])
            for child in data.getEdges(i):
                parent[int(child)] = i
        if spec.sampled:
            motions_checked = int(si.getCheckedMotionCount())
            resolution_deg = float(space.getLongestValidSegmentLength())
        else:  # OMPL's own counters stay 0: a Python validator cannot update them
            motions_checked = int(counts[MOTION_CHECKS])
            resolution_deg = None
    finally:
        ou.setLogLevel(previous_level)

    params = {
        "ompl_planner": bare,
        "ompl_version": _ompl_version(),
        "ompl_seed": seed_used,
        "range_deg": applied["range_deg"],
        "range_source": range_source,
        "goal_bias": applied["goal_bias"],
        "max_iter": int(max_iter),
        "time_limit_s": float(time_limit_s),
        "stopped_by": "solution" if exact else (state["stopped_by"] or "planner"),
        "ompl_status": status,
        "iterations_source": source,
        "motion_validator": "sampled" if spec.sampled else "certified",
        "validity_resolution_deg": resolution_deg,
        "motions_checked": motions_checked,
        "state_checks": int(counts[STATE_CHECKS]),
        "work": int(counts[WORK]) if COUNTS_WORK else None,
        "margin_m": float(margin),
        "goal_threshold_deg": GOAL_THRESHOLD_DEG,
        "goal_appended": goal_appended,
    }
    if failure is not None:
        params["failure"] = failure
    # A path whose every segment is a motion the certified validator accepted, bit for bit (the
    # one to an appended goal was certified by segment_free above), is certified already: it is
    # not checked again, as our planners' tree edges are not (a sampled validator's always is).
    edges_certified = False
    if exact and validator is not None:
        head = path[:-1] if goal_appended else path
        edges_certified = (goal_appended and head.shape[0] < 2) or validator.certified(head)
    if exact:
        params["path_check"] = "motions certified in planning" if edges_certified \
            else "certified after planning"
    result = certified_result(
        a, margin, exact, edges_certified=edges_certified,
        scenario=scenario.name, planner=spec.label, seed=int(seed),
        iterations=iterations, nodes=n, cost_deg=path_cost_deg(path) if exact else None,
        wall_s=wall, path_deg=path, tree_nodes_deg=tree, tree_parent=parent, params=params,
        work=params["work"],
    )
    # Kept in params too for readers of older result files; the top-level fields are the truth.
    # (``penetration_m`` is not copied here: reading it would measure the exact clearance on
    # every plan, which the result defers until someone asks.)
    params["certified"] = result.certified if exact else None
    return result


@functools.cache
def _ompl_version() -> str:
    # Cached: reading the package metadata costs milliseconds, more than many OMPL solves.
    try:
        from importlib.metadata import version

        return version("ompl")
    except Exception:  # pragma: no cover - metadata missing in odd installs
        return "unknown"
