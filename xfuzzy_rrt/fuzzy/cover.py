"""Don't-care rule patterns over the 5x5x5x5 rule grid, and the fewest-rules partition.

A *pattern* is a rule antecedent in which each input is either one term (0..4) or ``any``
(written ``-1`` here): ``if dist_to_goal is near and dist_to_obstacle is any ...``. A pattern
with ``any`` on *k* inputs covers ``5**k`` of the 625 cells (rule indices, see
:mod:`.variables`). There are ``6**4 = 1296`` patterns.

Why patterns and not arbitrary term ranges: ``any`` is the one don't-care a reader needs no
explanation for ("whatever the obstacle direction"), and it keeps every rule a plain sentence.

:func:`min_partition` finds the fewest patterns that partition the grid (every cell covered by
exactly one rule, as the text format requires) such that each pattern is *uniform*: its cells
hold one constant. That is an exact-cover problem; it is solved as a 0/1 integer programme
(minimise the number of chosen patterns subject to "each cell covered exactly once") with
HiGHS through :func:`scipy.optimize.milp`. The programme is tiny (at most 1296 binaries, 625
equalities, each cell in 16 patterns) and solves in milliseconds, and the result is a proven
optimum (``Partition.optimal``). If HiGHS stops without a proof (time limit), the best
solution it found is used, or else a greedy largest-pattern-first partition; ``optimal`` is
then ``False``. HiGHS is deterministic for a given programme, so the same constants always give
the same rules.

Lossy variants use the same solver: *free* cells (e.g. rules that never fire on a benchmark)
may join any pattern and take its value, and a *tolerance* lets a pattern hold constants that
differ by at most that much (they are replaced by the pattern's mid-range value).
"""

from __future__ import annotations

import functools
import itertools
from dataclasses import dataclass

import numpy as np

from xfuzzy_rrt.fuzzy.variables import N_INPUTS, N_RULES, N_TERMS

ANY = -1
ANY_WORD = "any"

Pattern = tuple[int, int, int, int]


@functools.lru_cache(maxsize=1)
def all_patterns() -> tuple[tuple[Pattern, ...], np.ndarray, np.ndarray]:
    """Every pattern, plus the incidence as ``(pattern_ids, cells)`` (each cell in 16 patterns).

    Patterns are ordered with the most specific first (``itertools.product`` over
    ``0..4, ANY`` per input), so pattern ``p`` covers ``cells[pattern_ids == p]``.
    """
    choices = list(range(N_TERMS)) + [ANY]
    patterns = tuple(itertools.product(choices, repeat=N_INPUTS))
    pid: list[int] = []
    cells: list[int] = []
    for p, pat in enumerate(patterns):
        c = pattern_cells(pat)
        pid.extend([p] * len(c))
        cells.extend(c.tolist())
    return patterns, np.asarray(pid, dtype=np.int64), np.asarray(cells, dtype=np.int64)


def pattern_cells(pattern: Pattern) -> np.ndarray:
    """Rule indices (ascending) covered by *pattern*."""
    axes = [range(N_TERMS) if t == ANY else (t,) for t in pattern]
    out = [((a * N_TERMS + b) * N_TERMS + c) * N_TERMS + d for a, b, c, d in itertools.product(*axes)]
    return np.asarray(out, dtype=np.int64)


def pattern_size(pattern: Pattern) -> int:
    return N_TERMS ** sum(1 for t in pattern if t == ANY)


@dataclass(frozen=True)
class Partition:
    """A set of disjoint patterns covering all 625 cells, with one constant each.

    ``rules`` is sorted by each pattern's first (lowest) cell index, which is the order the
    compact text format writes. ``values`` is the float[625] grid the rules expand to.
    """

    rules: tuple[tuple[Pattern, float], ...]
    optimal: bool
    values: np.ndarray

    def __len__(self) -> int:
        return len(self.rules)


def _uniform_patterns(values: np.ndarray, free: np.ndarray, tol: float):
    """Boolean mask of usable patterns and each one's value (NaN for all-free patterns)."""
    patterns, pid, cells = all_patterns()
    n = len(patterns)
    live = ~free[cells]
    v = values[cells]
    big = np.inf
    vmin = np.full(n, big)
    vmax = np.full(n, -big)
    np.minimum.at(vmin, pid[live], v[live])
    np.maximum.at(vmax, pid[live], v[live])
    has_live = np.isfinite(vmin)
    if tol == 0.0:
        usable = ~has_live | (vmin == vmax)
        value = np.where(has_live, vmin, np.nan)
        return usable, value, vmin, vmax
    else:
        with np.errstate(invalid="ignore"):  # all-free patterns: inf - inf
            spread = vmax - vmin
            mid = 0.5 * (vmin + vmax)
        usable = ~has_live | (spread <= tol)
        value = np.where(has_live, mid, np.nan)
    return usable, value, vmin, vmax


def shortest_decimal(lo: float, hi: float) -> float:
    """The number with the fewest decimals in ``[lo, hi]`` (closest to the middle among
    those): a merged rule's constant should read ``0.3``, not ``0.30124...``."""
    mid = 0.5 * (lo + hi)
    for k in range(-3, 17):
        v = float(round(mid, k))
        if lo <= v <= hi:
            return float(f"{v:.{max(k, 0)}f}")
    return mid


def _solve(usable: np.ndarray, time_limit: float) -> tuple[np.ndarray, bool] | None:
    """Chosen pattern ids from HiGHS, and whether optimality was proven (None: no solution)."""
    from scipy.optimize import Bounds, LinearConstraint, milp
    from scipy.sparse import csr_array

    patterns, pid, cells = all_patterns()
    ids = np.nonzero(usable)[0]
    col_of = np.full(len(patterns), -1, dtype=np.int64)
    col_of[ids] = np.arange(len(ids))
    keep = usable[pid]
    a = csr_array((np.ones(int(keep.sum())), (cells[keep], col_of[pid[keep]])),
                  shape=(N_RULES, len(ids)))
    res = milp(c=np.ones(len(ids)), integrality=np.ones(len(ids)), bounds=Bounds(0, 1),
               constraints=LinearConstraint(a, 1, 1),
               options={"time_limit": time_limit, "presolve": True})
    if res.x is None:
        return None
    chosen = ids[np.round(res.x).astype(bool)]
    return chosen, res.status == 0


def _greedy(usable: np.ndarray) -> np.ndarray:
    """Largest usable pattern first, skipping any that overlaps a chosen one (always succeeds,
    because every single-cell pattern is usable)."""
    patterns, pid, cells = all_patterns()
    sizes = np.array([pattern_size(p) for p in patterns])
    order = sorted(np.nonzero(usable)[0], key=lambda p: (-sizes[p], p))
    covered = np.zeros(N_RULES, dtype=bool)
    chosen = []
    starts = np.searchsorted(pid, np.arange(len(patterns) + 1))
    for p in order:
        c = cells[starts[p]:starts[p + 1]]
        if not covered[c].any():
            covered[c] = True
            chosen.append(p)
    return np.asarray(chosen, dtype=np.int64)


def _fill_free(value: np.ndarray, chosen: np.ndarray, values: np.ndarray, free: np.ndarray) -> None:
    """All-free patterns take the value of the nearest live cell (grid L1 distance, then the
    lowest index): 'a dead rule takes its neighbours' value'."""
    patterns = all_patterns()[0]
    live = np.nonzero(~free)[0]
    if live.size == 0:
        return
    grid = np.array(np.unravel_index(np.arange(N_RULES), (N_TERMS,) * N_INPUTS)).T
    for p in chosen:
        if np.isnan(value[p]):
            c = pattern_cells(patterns[p])
            d = np.abs(grid[c][:, None, :] - grid[live][None, :, :]).sum(axis=2).min(axis=0)
            value[p] = values[live[int(np.argmin(d))]]


def min_partition(values, free=None, tol: float = 0.0, time_limit: float = 20.0) -> Partition:
    """Fewest uniform patterns partitioning the grid (see the module docstring).

    ``values`` float[625]; ``free`` optional bool[625] of cells whose value may change;
    ``tol`` the largest spread of constants one pattern may hold (0: exactly equal, lossless).
    """
    values = np.asarray(values, dtype=np.float64)
    if values.shape != (N_RULES,):
        raise ValueError(f"values must have shape ({N_RULES},), got {values.shape}")
    free = np.zeros(N_RULES, dtype=bool) if free is None else np.asarray(free, dtype=bool)
    if tol < 0:
        raise ValueError("tol must be >= 0")
    usable, value, vmin, vmax = _uniform_patterns(values, free, float(tol))
    solved = _solve(usable, time_limit)
    if solved is None:
        chosen, optimal = _greedy(usable), False
    else:
        chosen, optimal = solved
    if tol > 0:
        # any value within tol/2 of every live constant keeps each change <= tol/2: take the
        # most readable one (fewest decimals) rather than the raw mid-range
        for p in chosen:
            if np.isfinite(vmin[p]):
                # (also kept within [vmin, vmax], hence within the output range)
                value[p] = shortest_decimal(max(vmax[p] - tol / 2, vmin[p]),
                                            min(vmin[p] + tol / 2, vmax[p]))
    _fill_free(value, chosen, values, free)
    patterns = all_patterns()[0]
    out = np.empty(N_RULES)
    firsts = []
    for p in chosen:
        c = pattern_cells(patterns[p])
        out[c] = value[p]
        firsts.append((int(c[0]), patterns[p], float(value[p])))
    firsts.sort()
    return Partition(rules=tuple((pat, v) for _, pat, v in firsts), optimal=bool(optimal),
                     values=out)


def greedy_gap_patterns(missing) -> list[Pattern]:
    """Describe a set of cells (bool[625]) as disjoint patterns, largest first (for messages)."""
    missing = np.asarray(missing, dtype=bool)
    patterns, pid, cells = all_patterns()
    inside = np.ones(len(patterns), dtype=bool)
    np.logical_and.at(inside, pid, missing[cells])
    chosen = _greedy(inside)
    out = [patterns[p] for p in chosen]
    out.sort(key=lambda p: int(pattern_cells(p)[0]))
    return out
