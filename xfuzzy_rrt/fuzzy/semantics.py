"""Rulebook semantics: which inputs the planner computes and what each output means.

A rulebook is six zero-order TSK systems over four inputs (5 terms each, 625 rules). *What*
those inputs and outputs are is the rulebook's semantics, named in its manifest
(``semantics = "..."``; absent means ``paper``). Every tool (parser, lint, engine arrays,
traces, ``explain``, coverage, FLL) reads names, ranges and units from here, never from
module constants, so a new semantics is one entry below plus its planner kernel.

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
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from types import MappingProxyType
from typing import Mapping

from xfuzzy_rrt.fuzzy import variables as _paper


@dataclass(frozen=True)
class Semantics:
    """Names, ranges, units and default terms of one rulebook semantics (4 inputs, 6 outputs)."""

    name: str
    inputs: tuple[str, ...]
    outputs: tuple[str, ...]
    input_ranges: Mapping[str, tuple[float, float]]
    output_ranges: Mapping[str, tuple[float, float]]
    units: Mapping[str, str]
    default_terms: Mapping[str, tuple[str, ...]]
    default_peaks: Mapping[str, tuple[float, float, float]]
    summary: str

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
)

GOAL_FRAME = Semantics(
    name="goal-frame",
    inputs=("joint_dist_to_goal", "stagnation", "clearance_deg", "reject_rate"),
    outputs=("goal_bias", "uniform_share", "ahead_deg", "behind_deg", "side_deg", "step_deg"),
    input_ranges=_ro({"joint_dist_to_goal": (0.0, 360.0), "stagnation": (0.0, 200.0),
                      "clearance_deg": (0.0, 30.0), "reject_rate": (0.0, 1.0)}),
    output_ranges=_ro({"goal_bias": (0.0, 1.0), "uniform_share": (0.0, 1.0),
                       "ahead_deg": (0.0, 360.0), "behind_deg": (0.0, 360.0),
                       "side_deg": (0.0, 180.0), "step_deg": (0.0, 30.0)}),
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
)

SEMANTICS: Mapping[str, Semantics] = _ro({s.name: s for s in (PAPER, GOAL_FRAME)})
DEFAULT = PAPER

#: Every input name of every semantics and its range (input names are unique across semantics,
#: so a FIS's inputs alone say which semantics it belongs to).
ALL_INPUT_RANGES: Mapping[str, tuple[float, float]] = _ro(
    {n: r for s in SEMANTICS.values() for n, r in s.input_ranges.items()})


def get(name: str | None) -> Semantics:
    """The semantics called *name* (``None``: the paper's); ``ValueError`` when unknown."""
    if name is None:
        return DEFAULT
    try:
        return SEMANTICS[name]
    except KeyError:
        raise ValueError(f"unknown semantics {name!r} (known: {', '.join(SEMANTICS)})") from None


def of_inputs(first_input: str) -> Semantics | None:
    """The semantics whose first input is *first_input* (how a lone FIS file is placed)."""
    for s in SEMANTICS.values():
        if s.inputs[0] == first_input:
            return s
    return None


def of_input(name: str) -> Semantics | None:
    """The semantics that has an input called *name*."""
    for s in SEMANTICS.values():
        if name in s.inputs:
            return s
    return None


def unit_suffix(sem: Semantics, name: str) -> str:
    """`` deg`` / `` m`` / ... for readable numbers ('' when unitless)."""
    u = sem.units.get(name, "")
    return f" {u}" if u else ""


def _check() -> None:
    for s in SEMANTICS.values():
        if len(s.inputs) != _paper.N_INPUTS or len(s.outputs) != _paper.N_OUTPUTS:
            raise RuntimeError(f"semantics {s.name}: must have 4 inputs and 6 outputs")
        for n in s.inputs:
            lo, hi = s.input_ranges[n]
            p = s.default_peaks[n]
            if not (lo < p[0] < p[1] < p[2] < hi) or not all(map(math.isfinite, p)):
                raise RuntimeError(f"semantics {s.name}: bad default peaks for {n}")


_check()


def of_columns(columns) -> Semantics:
    """The semantics whose inputs name columns of a trace or table (the paper's by default)."""
    cols = set(columns)
    for s in SEMANTICS.values():
        if s.inputs[0] in cols:
            return s
    return DEFAULT
