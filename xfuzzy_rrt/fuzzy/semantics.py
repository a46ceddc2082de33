"""Rulebook semantics: which inputs the planner computes and what each output means.

A rulebook is six zero-order TSK systems over four inputs (5 terms each, 625 rules). *What*
those inputs and outputs are is the rulebook's semantics, named in its manifest
(``semantics = "..."``; absent means ``paper``). Every tool (parser, lint, engine arrays,
traces, ``explain``, coverage, FLL) reads names, ranges and units from here, never from
module constants, so a new semantics is one :func:`register` call plus its planner kernel.
A semantics is also the plug-in the planner and the trainer run it through: its training
``modes`` and the integer each passes to its compiled ``kernel``, its training ``population``
evaluation, and ``per_arm`` (one fuzzy evaluation per arm or one for all arms: its DOF, and
the trace's column groups); nothing else switches on a semantics' name to choose them.

``paper`` — the paper's (Shankar et al.) four workspace inputs and a joint box: exactly the
conventions of SPEC.md. It cannot generalise: workspace angles do not say which way a joint
should turn on an unseen problem.

``goal-frame`` — inputs measured in the joint space the planner searches, and a sampling box
laid along the joint-space direction from the current node to the goal:

- ``joint_dist_to_goal`` (deg): Euclidean joint-space distance from the current node to the goal.
- ``stagnation`` (iterations): iterations since the tree last got closer to the goal.
- ``clearance_deg`` (deg): how far the joints may move from the current node, in any direction,
  before any link could touch an obstacle — the arm's workspace clearance divided by the
  largest lever of a unit joint move (a certified free radius in joint space).
- ``reject_rate`` (0..1): exponentially weighted share of recent extensions that were
  rejected (node in collision or edge blocked); how cluttered the search currently is.

Outputs: ``goal_bias`` (probability of sampling the goal), ``uniform_share`` (probability that
a non-goal sample is drawn uniformly over the whole joint space: the escape from traps),
``ahead_deg``/``behind_deg`` (box extent along the direction to the goal, towards and away
from it), ``side_deg`` (half-width across it) and ``step_deg`` (extension step). Because
every quantity is relative to the problem's own start, goal and obstacles in joint space, one
rulebook transfers between problems.

Degrees of freedom. A rulebook declares its arm's DOF ``N`` (2..7; manifest key ``dof``, absent
means 2). :func:`get` (or :meth:`Semantics.for_dof`) gives the semantics at that DOF; at ``N = 2``
it returns the very objects :data:`PAPER` and :data:`GOAL_FRAME`, so nothing about a 2-DOF
rulebook changes. What depends on ``N``:

- ``paper``: the joint box has one interval per joint, so the outputs are ``goal_bias,
  bound_1 … bound_2N, step_size`` (``bound_2j-1``/``bound_2j`` = joint ``j``'s interval);
  2N + 2 FIS. Inputs and ranges are unchanged (they are workspace quantities).
- ``goal-frame``: the same six outputs (the box is laid along the joint-space direction, whatever
  its dimension); only ``joint_dist_to_goal``'s range grows to ``[0, 180*sqrt(2N)]`` degrees,
  the diagonal of a joint space of N joints of 360° each (scaled so that N = 2 gives exactly
  the 360 it always had). For several arms, N is the total number of joints planned together.
  ``step_deg`` spans [0, 360] at 2 joints and the [0, 120] the N-joint rulebooks were trained
  with at more (the 2-joint range grew in the eighteenth session; a 2-joint file that declares
  [0, 120] still loads: :attr:`Semantics.earlier_output_ranges`).

``goal-frame-any`` — goal-frame for any arm (manifest ``dof = "any"``; :attr:`Semantics.dof_free`):
the same four inputs and six outputs, renamed (input names are unique across semantics) and
with every joint-space length (distance, clearance, ahead, behind, side, step) in *normalised
degrees*: Euclidean joint-space degrees divided by ``sqrt(N/2)`` (:func:`length_scale`). At
N = 2 every number is goal-frame's (but steps span [0, 120], as it was trained); at other N
the ranges still hold (the distance range
``180*sqrt(2N)`` normalises to 360), so one rulebook plans 2 to 7 joints and several arms.
Only Fuzzy-RRT-Connect (:mod:`xfuzzy_rrt.planners.connect`) plans with it, and training
(``train --bounds goal-frame-any``) runs that planner, on problems of any DOF mixed.
"""

from __future__ import annotations

import math
from dataclasses import dataclass, field, replace
from types import MappingProxyType
from typing import Mapping

from xfuzzy_rrt.fuzzy import variables as _paper


@dataclass(frozen=True)
class Semantics:
    """Names, ranges, units and default terms of one rulebook semantics at one DOF.

    Always four inputs; the outputs depend on the semantics and the DOF (``len(outputs)`` is
    the number of FIS, the first axis of the compiled arrays). Instances are shared: get them
    from :func:`get` / :meth:`for_dof`, and compare them with ``is``.
    """

    name: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    input_ranges: Mapping[str, tuple[float, float]]
    output_ranges: Mapping[str, tuple[float, float]]
    units: Mapping[str, str]
    default_terms: Mapping[str, tuple[str, ...]]
    default_peaks: Mapping[str, tuple[float, float, float]]
    summary: str
    dof: int = 2
    #: One rulebook for every arm: inputs and outputs do not depend on the number of joints
    #: (manifest ``dof = "any"``; the object is the same at every DOF and says ``dof = 2``).
    dof_free: bool = False
    # --- The plug-in: what planners and training need to run this semantics ---------------
    # ``fuzzy/`` imports no planner (layers import upward only), so code is named as
    # ``"module:attribute"`` and imported on first use (:func:`resolve`; a semantics
    # registered from above may give the function itself).
    #: Training modes (``train --bounds``) this semantics offers -> the integer mode its
    #: compiled kernel takes (the first is the mode of a rulebook without ``bounds_mode``);
    #: empty: training does not make it. Fuzzy-RRT plans with it only when it has a
    #: :attr:`kernel`.
    modes: Mapping[str, int] = field(default_factory=lambda: MappingProxyType({}))
    #: The Fuzzy-RRT kernel entry (the problem and the tree as arenas, the signature and the
    #: finished run it returns of ``planners/fuzzy_rrt.py:fuzzy_rrt_entry``), or ``None``.
    kernel: object = None
    #: :attr:`kernel` for a run that records nothing, with the same arguments but the last
    #: (``tr``), or ``None``: the planner then calls :attr:`kernel` with ``tr=None``. Why it
    #: exists: numba's dispatcher types ``None`` by building and looking up a fingerprint on
    #: every call, code that a cold call fetches from memory (~25 last-level misses a call,
    #: ``benchmarks/cold_misses.py``); arrays and numbers take its fast path.
    untraced: object = None
    #: The fitness evaluation of a population in training: ``fn(problem, tree, knots_b,
    #: consts_b, mode, seeds, max_iter) -> int64[P, R]`` iterations (``-1``: failed); one that
    #: also counts work (``"work"`` in :attr:`measures`) takes an eighth argument,
    #: ``measure="work"``, and then returns int64[P, R, 2] (iterations, work); with
    #: ``measure="cost"`` int64[P, R, 3] (iterations, work, path cost).
    population: object = None
    #: What :attr:`population` can report per run: iterations always; ``"work"`` only when it
    #: runs the planner's own kernel (a remembering evaluation does not spend the planner's
    #: work), which ``train --fitness work-cvar`` needs; ``"cost"`` (work and the found path's
    #: cost) for ``--fitness work-cost-cvar``.
    measures: tuple[str, ...] = ("iterations",)
    #: One fuzzy evaluation per arm (the paper's workspace inputs are one arm's: its DOF is
    #: each arm's, and trace columns are prefixed ``arm<a>_``), else one for all arms (the
    #: DOF is the joints in all).
    per_arm: bool = False
    #: The planner label that plans with it when nothing else is said.
    planner: str = "fuzzy-rrt"
    #: Other semantics whose (2-DOF) rulebooks may seed a training of this one: the same
    #: inputs and outputs, and ranges that encode into the same genome (constants outside
    #: this semantics' range are clipped to it: :func:`xfuzzy_rrt.training.genome.encode`;
    #: :meth:`can_seed_from`).
    seeded_by: tuple[str, ...] = ()
    #: Output ranges this semantics had before (output -> ranges): a file that declares one of
    #: them still loads (its constants lie inside today's range, so they mean what they
    #: meant) and is written back with today's range.
    earlier_output_ranges: Mapping[str, tuple[tuple[float, float], ...]] = field(
        default_factory=lambda: MappingProxyType({}))

    def can_seed_from(self, name: str) -> bool:
        """May a rulebook of semantics *name* seed a training of this one?"""
        return name == self.name or name in self.seeded_by

    @property
    def n_outputs(self) -> int:
        """Number of FIS (and first axis of ``knots``/``consts``) at this DOF."""
        return len(self.outputs)

    def for_dof(self, dof: int) -> "Semantics":
        """This semantics at *dof* joints (the same cached object for the same DOF)."""
        return get(self.name, dof)

    def kernel_mode(self, bounds_mode: str | None) -> int:
        """The integer the compiled kernel takes for a rulebook with *bounds_mode* (chosen once
        per plan): that mode's, else the first mode's (0 when there is none)."""
        mode = self.modes.get(bounds_mode) if bounds_mode is not None else None
        if mode is None:
            mode = next(iter(self.modes.values()), 0)
        return mode

    def fis_groups(self, n_arms: int) -> int:
        """Fuzzy evaluations per iteration on a problem of *n_arms* arms (trace groups)."""
        return n_arms if self.per_arm else 1

    def default_knots(self, name: str) -> tuple[float, float, float, float, float]:
        """``(lo, p1, p2, p3, hi)`` for input *name* with the default peaks."""
        lo, hi = self.input_ranges[name]
        return (lo, *self.default_peaks[name], hi)


def _ro(d: dict) -> Mapping:
    return MappingProxyType(dict(d))


PAPER = Semantics(
    name="paper",
    inputs=_paper.INPUTS,
    outputs=_paper.OUTPUTS,
    input_ranges=_ro(_paper.INPUT_RANGES),
    output_ranges=_ro(_paper.OUTPUT_RANGES),
    units=_ro({"angle_to_goal": "rad", "dist_to_goal": "m", "angle_to_obstacle": "rad",
               "dist_to_obstacle": "m", "goal_bias": "", "bound_1": "deg", "bound_2": "deg",
               "bound_3": "deg", "bound_4": "deg", "step_size": "deg"}),
    default_terms=_ro(_paper.DEFAULT_TERMS),
    default_peaks=_ro(_paper.DEFAULT_PEAKS),
    summary="the paper's: workspace angle/distance to goal and nearest obstacle -> goal bias, "
            "joint box (absolute or relative bounds), step",
    # the integers of planners/fuzzy_rrt.py's BOUNDS_ABSOLUTE and BOUNDS_RELATIVE
    modes=_ro({"absolute": 0, "relative": 1}),
    kernel="xfuzzy_rrt.planners.fuzzy_rrt:fuzzy_rrt_entry",
    untraced="xfuzzy_rrt.planners.fuzzy_rrt:fuzzy_rrt_untraced",
    population="xfuzzy_rrt.training.evaluate:memo_population",
    per_arm=True,
)

#: goal-frame's output ranges before the eighteenth session (steps up to 120 degrees).
_GOAL_FRAME_OUTPUTS = {"goal_bias": (0.0, 1.0), "uniform_share": (0.0, 1.0),
                       "ahead_deg": (0.0, 360.0), "behind_deg": (0.0, 360.0),
                       "side_deg": (0.0, 180.0), "step_deg": (0.0, 120.0)}

GOAL_FRAME = Semantics(
    name="goal-frame",
    inputs=("joint_dist_to_goal", "stagnation", "clearance_deg", "reject_rate"),
    outputs=("goal_bias", "uniform_share", "ahead_deg", "behind_deg", "side_deg", "step_deg"),
    input_ranges=_ro({"joint_dist_to_goal": (0.0, 360.0), "stagnation": (0.0, 200.0),
                      "clearance_deg": (0.0, 30.0), "reject_rate": (0.0, 1.0)}),
    # step_deg up to 360 (any step the box can ask for) since the eighteenth session: at 120
    # (before) 250 of the trained default's 625 step rules sat on the cap, and the tuned
    # RRT's best step is 180 (docs/peer-measurements.md). The N-joint goal-frame rulebooks and
    # goal-frame-any were trained with 120 and keep it (_goal_frame_at, GOAL_FRAME_ANY).
    output_ranges=_ro({**_GOAL_FRAME_OUTPUTS, "step_deg": (0.0, 360.0)}),
    units=_ro({"joint_dist_to_goal": "deg", "stagnation": "iterations", "clearance_deg": "deg",
               "reject_rate": "", "goal_bias": "", "uniform_share": "", "ahead_deg": "deg",
               "behind_deg": "deg", "side_deg": "deg", "step_deg": "deg"}),
    default_terms=_ro({
        "joint_dist_to_goal": ("very_near", "near", "medium", "far", "very_far"),
        "stagnation": ("none", "brief", "some", "long", "stuck"),
        "clearance_deg": ("touching", "tight", "narrow", "open", "wide"),
        "reject_rate": ("none", "low", "half", "high", "blocked"),
    }),
    default_peaks=_ro({"joint_dist_to_goal": (30.0, 90.0, 180.0),
                       "stagnation": (10.0, 30.0, 80.0),
                       "clearance_deg": (2.0, 6.0, 15.0),
                       "reject_rate": (0.25, 0.5, 0.75)}),
    summary="goal-frame: joint-space distance to goal, stagnation, C-space clearance, reject "
            "rate -> goal bias, uniform share, box ahead/behind/across the direction to the "
            "goal, step",
    modes=_ro({"goal-frame": 2}),  # planners/fuzzy_rrt.py's GOAL_FRAME
    kernel="xfuzzy_rrt.planners.fuzzy_rrt:goal_frame_entry",
    untraced="xfuzzy_rrt.planners.fuzzy_rrt:goal_frame_untraced",
    population="xfuzzy_rrt.training.evaluate:kernel_population",
    measures=("iterations", "work", "cost"),
    earlier_output_ranges=_ro({"step_deg": ((0.0, 120.0),)}),
)

#: Joint-space lengths of ``goal-frame-any`` are Euclidean degrees divided by ``sqrt(N / 2)``
#: for ``N`` joints in all ("normalised degrees"): the length a move of the same per-joint size
#: has with two joints. So at ``N = 2`` every number is goal-frame's, and the ranges (distance
#: ``[0, 360]``: the joint-space diagonal ``180*sqrt(2N)`` normalised) hold at every DOF.
NORM_UNIT = "ndeg"

GOAL_FRAME_ANY = Semantics(
    name="goal-frame-any",
    inputs=("norm_dist_to_goal", "stall", "norm_clearance", "reject_share"),
    outputs=GOAL_FRAME.outputs,
    input_ranges=_ro({"norm_dist_to_goal": (0.0, 360.0), "stall": (0.0, 200.0),
                      "norm_clearance": (0.0, 30.0), "reject_share": (0.0, 1.0)}),
    output_ranges=_ro(_GOAL_FRAME_OUTPUTS),
    units=_ro({"norm_dist_to_goal": NORM_UNIT, "stall": "iterations",
               "norm_clearance": NORM_UNIT, "reject_share": "", "goal_bias": "",
               "uniform_share": "", "ahead_deg": NORM_UNIT, "behind_deg": NORM_UNIT,
               "side_deg": NORM_UNIT, "step_deg": NORM_UNIT}),
    default_terms=_ro({
        "norm_dist_to_goal": ("very_near", "near", "medium", "far", "very_far"),
        "stall": ("none", "brief", "some", "long", "stuck"),
        "norm_clearance": ("touching", "tight", "narrow", "open", "wide"),
        "reject_share": ("none", "low", "half", "high", "blocked"),
    }),
    default_peaks=_ro({"norm_dist_to_goal": (30.0, 90.0, 180.0), "stall": (10.0, 30.0, 80.0),
                       "norm_clearance": (2.0, 6.0, 15.0),
                       "reject_share": (0.25, 0.5, 0.75)}),
    summary="goal-frame for any arm: goal-frame's inputs and outputs with every joint-space "
            "length in normalised degrees (Euclidean degrees / sqrt(N/2), N joints in all), so "
            "one rulebook plans 2 to 7 joints and several arms",
    dof_free=True,
    # trained with Fuzzy-RRT-Connect, the planner that runs it (no Fuzzy-RRT kernel: mode 3
    # names the training evaluation only)
    modes=_ro({"goal-frame-any": 3}),
    population="xfuzzy_rrt.training.evaluate:connect_population",
    measures=("iterations", "work"),
    planner="fuzzy-rrt-connect",
    # goal-frame's lengths are its normalised degrees at 2 joints: the same genome (a
    # 2-joint goal-frame step above 120 is clipped to 120)
    seeded_by=("goal-frame",),
)

#: The registry: name -> semantics at 2 DOF (a live read-only view; :func:`register` adds).
_REGISTRY: dict[str, Semantics] = {s.name: s for s in (PAPER, GOAL_FRAME, GOAL_FRAME_ANY)}
SEMANTICS: Mapping[str, Semantics] = MappingProxyType(_REGISTRY)
DEFAULT = PAPER

#: Every input name of every semantics and its range (input names are unique across semantics,
#: so a FIS's inputs alone say which semantics it belongs to).
_ALL_INPUTS: dict[str, tuple[float, float]] = {
    n: r for s in _REGISTRY.values() for n, r in s.input_ranges.items()}
ALL_INPUT_RANGES: Mapping[str, tuple[float, float]] = MappingProxyType(_ALL_INPUTS)


MIN_DOF = 2
MAX_DOF = 7
DEFAULT_DOF = 2
#: The manifest's ``dof`` of a DOF-free semantics.
ANY_DOF = "any"


def length_scale(sem: Semantics, dof: int) -> float:
    """Euclidean joint-space degrees per unit of *sem*'s lengths at *dof* joints in all:
    ``sqrt(dof / 2)`` for a DOF-free semantics, exactly 1 otherwise (and at 2 joints)."""
    return math.sqrt(dof / 2.0) if sem.dof_free else 1.0


def dof_problem(dof) -> str | None:
    """Why *dof* is not a valid degree of freedom (``None`` when it is): an ``int`` 2..7."""
    if type(dof) is not int or not MIN_DOF <= dof <= MAX_DOF:
        return f"dof must be an integer from {MIN_DOF} to {MAX_DOF} (the arm's joints), got {dof!r}"
    return None


def bound_outputs(dof: int) -> tuple[str, ...]:
    """``bound_1 … bound_{2*dof}`` of the paper's semantics (two per joint)."""
    return tuple(f"bound_{k}" for k in range(1, 2 * dof + 1))


def joint_dist_range(dof: int) -> tuple[float, float]:
    """Range of ``joint_dist_to_goal`` at *dof* joints: ``[0, 180*sqrt(2*dof)]`` degrees.

    ``sqrt(4) == 2.0`` exactly, so the 2-DOF range is exactly the ``[0, 360]`` of the files.
    """
    return (0.0, 180.0 * math.sqrt(2 * dof))


def _paper_at(dof: int) -> Semantics:
    bounds = bound_outputs(dof)
    outputs = ("goal_bias", *bounds, "step_size")
    ranges = {"goal_bias": PAPER.output_ranges["goal_bias"],
              **{b: PAPER.output_ranges["bound_1"] for b in bounds},
              "step_size": PAPER.output_ranges["step_size"]}
    units = {**{n: PAPER.units[n] for n in PAPER.inputs}, "goal_bias": "",
             **{b: "deg" for b in bounds}, "step_size": "deg"}
    return replace(PAPER, outputs=outputs, output_ranges=_ro(ranges), units=_ro(units),
                   summary=f"{PAPER.summary} ({dof} joints)", dof=dof)


def _goal_frame_at(dof: int) -> Semantics:
    ranges = dict(GOAL_FRAME.input_ranges)
    ranges["joint_dist_to_goal"] = joint_dist_range(dof)
    # steps up to 120 as the shipped N-joint rulebooks were trained (only the 2-joint default
    # was trained again with the wider range)
    return replace(GOAL_FRAME, input_ranges=_ro(ranges), output_ranges=_ro(_GOAL_FRAME_OUTPUTS),
                   earlier_output_ranges=_ro({}),
                   summary=f"{GOAL_FRAME.summary} ({dof} joints in all)", dof=dof)


_BUILDERS = {PAPER.name: _paper_at, GOAL_FRAME.name: _goal_frame_at,
             GOAL_FRAME_ANY.name: lambda dof: GOAL_FRAME_ANY}
#: (name, dof) -> Semantics; 2-DOF entries are the module constants themselves (a DOF-free
#: semantics is its constant at every DOF).
_CACHE: dict[tuple[str, int], Semantics] = {(s.name, DEFAULT_DOF): s
                                            for s in (PAPER, GOAL_FRAME, GOAL_FRAME_ANY)}


def register(sem: Semantics, at_dof=None) -> Semantics:
    """Add a semantics (its 2-DOF object) to the registry: every tool that reads names,
    ranges and units, the genome (:func:`of_mode`) and the planner kernel (:attr:`Semantics.kernel`)
    then know it. ``at_dof(dof) -> Semantics``: the semantics at another DOF (``None``: the
    same object at every DOF, as for a DOF-free semantics). ``ValueError`` when its name,
    an input name or a training mode is taken."""
    if sem.name in _REGISTRY:
        raise ValueError(f"semantics {sem.name!r} is already registered")
    taken = set(sem.inputs) & set(_ALL_INPUTS)
    if taken:
        raise ValueError(f"semantics {sem.name!r}: input names must be unique across "
                         f"semantics; {', '.join(sorted(taken))} taken")
    modes = set(sem.modes) & {m for s in _REGISTRY.values() for m in s.modes}
    if modes:
        raise ValueError(f"semantics {sem.name!r}: training mode(s) {', '.join(sorted(modes))} "
                         "taken")
    _REGISTRY[sem.name] = sem
    _ALL_INPUTS.update(sem.input_ranges)
    _BUILDERS[sem.name] = at_dof or (lambda dof: sem)
    _CACHE[(sem.name, DEFAULT_DOF)] = sem
    return sem


def unregister(name: str) -> None:
    """Remove a semantics :func:`register` added (tests)."""
    sem = _REGISTRY.pop(name)
    for n in sem.inputs:
        _ALL_INPUTS.pop(n, None)
    _BUILDERS.pop(name, None)
    for key in [k for k in _CACHE if k[0] == name]:
        del _CACHE[key]


def of_mode(mode: str) -> Semantics:
    """The (2-DOF) semantics that offers training mode *mode* (``absolute``, ``relative``,
    ``goal-frame``, or a registered semantics' own); the paper's for an unknown mode, as
    before the registry (callers validate modes against :func:`training_modes`)."""
    for s in _REGISTRY.values():
        if mode in s.modes:
            return s
    return PAPER


def training_modes() -> tuple[str, ...]:
    """Every training mode of every registered semantics, in registration order."""
    return tuple(m for s in _REGISTRY.values() for m in s.modes)


def resolve(ref):
    """The object a ``"module:attribute"`` name of a plug-in field refers to, imported once
    and kept; anything else (``None``, a function a registered semantics gives directly) as
    given."""
    if not isinstance(ref, str):
        return ref
    obj = _RESOLVED.get(ref)
    if obj is None:
        import importlib

        module, _, attr = ref.partition(":")
        obj = _RESOLVED[ref] = getattr(importlib.import_module(module), attr)
    return obj


_RESOLVED: dict[str, object] = {}


def get(name: str | None, dof: int = DEFAULT_DOF) -> Semantics:
    """The semantics called *name* (``None``: the paper's) at *dof* joints.

    ``ValueError`` when the name is unknown or *dof* is not an integer 2..7. Instances are
    cached, so ``get(n, d) is get(n, d)``, and ``get(n, 2)`` is :data:`PAPER`/:data:`GOAL_FRAME`.
    """
    if name is None:
        name = DEFAULT.name
    if name not in SEMANTICS:
        raise ValueError(f"unknown semantics {name!r} (known: {', '.join(SEMANTICS)})")
    problem = dof_problem(dof)
    if problem:
        raise ValueError(problem)
    key = (name, dof)
    sem = _CACHE.get(key)
    if sem is None:
        sem = _CACHE[key] = _BUILDERS[name](dof)
    return sem


def input_range(name: str, dof: int = DEFAULT_DOF) -> tuple[float, float]:
    """Range of input *name* (of any semantics) at *dof* joints; ``KeyError`` when unknown."""
    sem = of_input(name)
    if sem is None:
        raise KeyError(name)
    return get(sem.name, dof).input_ranges[name]


def dof_of_outputs(name: str, outputs) -> int | None:
    """The DOF whose output names are exactly *outputs* (any order) for semantics *name*, or
    ``None`` (none fits, or the outputs do not depend on the DOF, as in goal-frame)."""
    wanted = set(outputs)
    fits = [d for d in range(MIN_DOF, MAX_DOF + 1) if set(get(name, d).outputs) == wanted]
    return fits[0] if len(fits) == 1 else None


def of_inputs(first_input: str, dof: int = DEFAULT_DOF) -> Semantics | None:
    """The semantics (at *dof*) whose first input is *first_input* (how a lone FIS is placed)."""
    for s in SEMANTICS.values():
        if s.inputs[0] == first_input:
            return get(s.name, dof)
    return None


def of_input(name: str) -> Semantics | None:
    """The (2-DOF) semantics that has an input called *name* (input names are unique)."""
    for s in SEMANTICS.values():
        if name in s.inputs:
            return s
    return None


def unit_suffix(sem: Semantics, name: str) -> str:
    """`` deg`` / `` m`` / ... for readable numbers ('' when unitless)."""
    u = sem.units.get(name, "")
    return f" {u}" if u else ""


def _check() -> None:
    for base in SEMANTICS.values():
        for dof in range(MIN_DOF, MAX_DOF + 1):
            s = get(base.name, dof)
            want = 2 * dof + 2 if s.name == PAPER.name else _paper.N_OUTPUTS
            if len(s.inputs) != _paper.N_INPUTS or len(s.outputs) != want:
                raise RuntimeError(f"semantics {s.name} at dof {dof}: must have 4 inputs and "
                                   f"{want} outputs")
            if set(s.output_ranges) != set(s.outputs) or set(s.input_ranges) != set(s.inputs):
                raise RuntimeError(f"semantics {s.name} at dof {dof}: ranges do not match names")
        s = base
        for n in s.inputs:
            lo, hi = s.input_ranges[n]
            p = s.default_peaks[n]
            if not (lo < p[0] < p[1] < p[2] < hi) or not all(map(math.isfinite, p)):
                raise RuntimeError(f"semantics {s.name}: bad default peaks for {n}")


_check()


def of_columns(columns) -> Semantics:
    """The semantics whose inputs name columns of a trace or table (the paper's by default),
    at the DOF its output columns show (``bound_1 … bound_2N``; goal-frame's outputs do not
    depend on the DOF, so it comes back at 2 there, with the same output names)."""
    cols = {str(c) for c in columns}
    base = next((s for s in SEMANTICS.values() if s.inputs[0] in cols), DEFAULT)
    if base.name == PAPER.name:
        k = 4
        while f"bound_{k + 1}" in cols:
            k += 1
        if k % 2 == 0 and MIN_DOF <= k // 2 <= MAX_DOF:
            return get(base.name, k // 2)
    return base
