"""Names, ranges and default linguistic terms of the Fuzzy-RRT systems (SPEC.md conventions).

Six single-output Takagi-Sugeno systems (one per output, as in the paper) share the same four
inputs. Each input has five terms forming a Ruspini partition of its range, so at most two
terms per input are non-zero and at most ``2**4 = 16`` of the ``5**4 = 625`` rules fire.

Rule index convention (arrays, traces and files): ``r = ((t0*5 + t1)*5 + t2)*5 + t3`` where
``t_i`` is the 0-based term index of input ``i`` in :data:`INPUTS` order.

Default term names. Distances read naturally (``very_near`` .. ``very_far``). Angles are
absolute workspace directions measured counter-clockwise from +x, in [0, 2π]; with the default
peaks (π/2, π, 3π/2) the terms sit at east, north, west, south and east again. Because 0 and
2π are the same direction but the partition does not wrap, *east is split in two terms*:
``east_0`` (directions just counter-clockwise of +x, i.e. slightly north of east) and
``east_2pi`` (just clockwise of +x, slightly south of east). The names are honest about that
rather than pretending the partition is circular. A rulebook file may rename terms; these are
only the defaults.
"""

from __future__ import annotations

import math

INPUTS: tuple[str, ...] = ("angle_to_goal", "dist_to_goal", "angle_to_obstacle", "dist_to_obstacle")
OUTPUTS: tuple[str, ...] = ("goal_bias", "bound_1", "bound_2", "bound_3", "bound_4", "step_size")

TWO_PI = 2.0 * math.pi

INPUT_RANGES: dict[str, tuple[float, float]] = {
    "angle_to_goal": (0.0, TWO_PI),
    "dist_to_goal": (0.0, 0.6),
    "angle_to_obstacle": (0.0, TWO_PI),
    "dist_to_obstacle": (0.0, 0.6),
}
OUTPUT_RANGES: dict[str, tuple[float, float]] = {
    "goal_bias": (0.0, 1.0),
    "bound_1": (-180.0, 180.0),
    "bound_2": (-180.0, 180.0),
    "bound_3": (-180.0, 180.0),
    "bound_4": (-180.0, 180.0),
    "step_size": (0.0, 10.0),
}

N_INPUTS = len(INPUTS)
N_OUTPUTS = len(OUTPUTS)
N_TERMS = 5
N_RULES = N_TERMS**N_INPUTS  # 625
MAX_FIRED = 2**N_INPUTS  # 16: two active terms per input in a Ruspini partition

ANGLE_TERMS: tuple[str, ...] = ("east_0", "north", "west", "south", "east_2pi")
DISTANCE_TERMS: tuple[str, ...] = ("very_near", "near", "medium", "far", "very_far")

DEFAULT_TERMS: dict[str, tuple[str, ...]] = {
    "angle_to_goal": ANGLE_TERMS,
    "dist_to_goal": DISTANCE_TERMS,
    "angle_to_obstacle": ANGLE_TERMS,
    "dist_to_obstacle": DISTANCE_TERMS,
}


#: Default interior peaks ``(p1, p2, p3)``: quarters of each range, written as the literals a
#: person would type (``0.45``, not ``0.6 * 3 / 4 = 0.44999999999999996``).
DEFAULT_PEAKS: dict[str, tuple[float, float, float]] = {
    "angle_to_goal": (math.pi / 2, math.pi, 3 * math.pi / 2),
    "dist_to_goal": (0.15, 0.3, 0.45),
    "angle_to_obstacle": (math.pi / 2, math.pi, 3 * math.pi / 2),
    "dist_to_obstacle": (0.15, 0.3, 0.45),
}


def default_knots(name: str) -> tuple[float, float, float, float, float]:
    """``(lo, p1, p2, p3, hi)`` for input *name* with the default peaks."""
    lo, hi = INPUT_RANGES[name]
    return (lo, *DEFAULT_PEAKS[name], hi)


def rule_index(terms: tuple[int, int, int, int] | list[int]) -> int:
    """Rule index of the antecedent with 0-based term indices *terms* (INPUTS order)."""
    t0, t1, t2, t3 = terms
    return ((t0 * N_TERMS + t1) * N_TERMS + t2) * N_TERMS + t3


def rule_terms(r: int) -> tuple[int, int, int, int]:
    """Inverse of :func:`rule_index`: the four 0-based term indices of rule *r*."""
    if not 0 <= r < N_RULES:
        raise ValueError(f"rule index {r} outside 0..{N_RULES - 1}")
    t3 = r % N_TERMS
    r //= N_TERMS
    t2 = r % N_TERMS
    r //= N_TERMS
    t1 = r % N_TERMS
    t0 = r // N_TERMS
    return (t0, t1, t2, t3)
