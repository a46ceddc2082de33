"""A planning problem in one block of memory, so that a plan call hands it to compiled code as
one array and a small layout table instead of a tuple of eight arrays and two numbers.

Why: numba types and unboxes every array of a call's arguments, a tuple's one by one, on every
call. A compiled no-op taking a tuple of nine arrays against one taking one array: 3.5 against
1.7 us warm, 45 against 28 us cold. In whole 2-joint calls the problem as a block saved less,
~0.5 us warm and nothing measurable cold (docs/peer-measurements.md, twenty-second session):
rebuilding the views costs a little of what unboxing cost. As for the search trees
(:mod:`.tree_arena`, whose packing it uses), the arrays are copied once per set-up into a
``uint8`` block at 64-byte aligned offsets, and a compiled entry rebuilds the
:class:`~xfuzzy_rrt.geometry.problem.Problem` from the block with slices and ``view``/``reshape``
(no copy; numba types the views exactly as it typed the separate arrays, so every kernel keeps
its one specialisation), with a fresh zeroed ``work`` counter made there.

No kernel writes into a problem's arrays (only into its ``work`` counter, made per call), so
the block is shared by every thread that plans the scenario with those settings: it belongs to
a remembered set-up (:mod:`.setup_memo`), whose ``block`` the call passes and so holds for
as long as the borrowed views live. It is not flagged read-only, because numba types a
read-only array differently and every kernel would be compiled a second time for it.
"""

from __future__ import annotations

from typing import NamedTuple

import numba as nb
import numpy as np

from xfuzzy_rrt.geometry.problem import Problem
from xfuzzy_rrt.planners.tree_arena import borrowed_1d, borrowed_2d, packed

#: dtype and number of dimensions of each array field of :class:`Problem` before ``margin``,
#: in order (links, arm_first, bases, radii, obstacles, limits, start, goal); row
#: :data:`NUMBERS` of the layout holds ``[margin, clearance]``.
FIELD_KINDS = ((np.float64, 1), (np.int64, 1), (np.float64, 2), (np.float64, 1),
               (np.float64, 2), (np.float64, 2), (np.float64, 1), (np.float64, 1))
NUMBERS = len(FIELD_KINDS)


class ProblemArena(NamedTuple):
    """A problem's arrays (and its margin and clearance) in ``block``; ``layout[k] = offset,
    nbytes, rows, cols`` (``cols`` 0 for a 1-D field)."""

    block: np.ndarray
    layout: np.ndarray


def make_problem_arena(problem: Problem) -> ProblemArena:
    """``problem``'s fields (all but ``work``) copied into one aligned block."""
    parts = [np.ascontiguousarray(problem[k], dtype=dtype) for k, (dtype, _) in
             enumerate(FIELD_KINDS)]
    for k, (arr, (_, ndim)) in enumerate(zip(parts, FIELD_KINDS)):
        if arr.ndim != ndim:
            raise TypeError(f"problem field {Problem._fields[k]} is {arr.ndim}-D; the arena "
                            f"expects {ndim}-D (FIELD_KINDS)")
    parts.append(np.array([problem.margin, problem.clearance], dtype=np.float64))
    block, layout, _ = packed(parts)
    return ProblemArena(block, layout)


@nb.njit(cache=True, nogil=True, inline="always")
def problem_in(block, layout):
    """The :class:`Problem` whose arrays are ``block``'s fields, borrowed (no copy, no owner:
    :mod:`.tree_arena`'s "Borrowed views"; for compiled callers, while they hold ``block``),
    with a fresh zeroed ``work`` counter made here (each plan counts its own work)."""
    f8, i8, L, b = np.float64, np.int64, layout, block
    numbers = borrowed_1d(b, L, NUMBERS, f8)
    return Problem(
        borrowed_1d(b, L, 0, f8), borrowed_1d(b, L, 1, i8), borrowed_2d(b, L, 2, f8),
        borrowed_1d(b, L, 3, f8), borrowed_2d(b, L, 4, f8), borrowed_2d(b, L, 5, f8),
        borrowed_1d(b, L, 6, f8), borrowed_1d(b, L, 7, f8),
        numbers[0], numbers[1], np.zeros(1, dtype=np.int64))
