"""How sure is a per-problem speed ratio? A bootstrap interval for a ratio of two medians.

Why: issue 25's aims are per problem ("worst >= 1x on every problem"), and a per-problem ratio
is the ratio of two medians over a finite set of seeds, each with its timing noise. On the
2-joint families a run takes a few dozen microseconds and its time varies several-fold from
seed to seed, so the default measured against *itself* -- its 25 even seeds against its 25 odd
ones -- already "loses" some problem among 48 by 0.64-0.84x (``scripts/noise_floor.py``;
docs/peer-measurements.md, twentieth session). A count of problems lost cannot tell such a coin
toss from a real loss; an interval can. ``evaluate`` reports, beside each ratio to the fastest
peer, the 95 % percentile-bootstrap interval, and counts a problem *surely lost* only when the
whole interval lies below 1 (and *surely won* when it lies above). By chance alone about 2.5 %
of problems fall on each side (one of 48); the self-comparisons of two sittings put 0-5 of 48
wholly off 1, both sides together.

The same resampling over *problems* bounds a family's median (:func:`median_interval`): the
mission's warning that 24 problems swing a median by +-20 % is what its width shows, and it says
whether a median cost ratio of 1.02 is a miss or a toss.

The method: resample the planner's runs and the peer's runs, each with replacement and
independently (the two planners share seeds, but not what a seed makes them do, so their runs
are not pairs), take the ratio of the two medians, and read the 2.5 % and 97.5 % quantiles of
:data:`RESAMPLES` such ratios. Deterministic: the draws come from a generator seeded by the
problem's and planner's names (CRC-32) and each sample is sorted first, so an interval depends
on the times alone: not on which other problems or planners were in the table, nor on the order
of its rows.
"""

from __future__ import annotations

import zlib

import numpy as np

#: Bootstrap resamples per interval (the quantiles move by ~0.01 between runs of 2,000).
RESAMPLES = 2000
#: Two-sided level of the interval.
LEVEL = 0.95


def median_interval(values, key: str, level: float = LEVEL,
                    resamples: int = RESAMPLES) -> tuple[float, float]:
    """``(lo, hi)``: the percentile-bootstrap interval of ``median(values)`` at *level*,
    resampling the values (a family's per-problem ratios: how far the median could move had
    other problems of the family been drawn); *key* seeds the draws. ``(nan, nan)`` without
    finite values (the others are left out)."""
    v = np.asarray(values, dtype=np.float64)
    v = np.sort(v[np.isfinite(v)])
    if v.size == 0:
        return float("nan"), float("nan")
    _check(level, resamples)
    rng = _draws(key)
    return _bounds(_resampled_medians(v, rng, resamples), level)


def _check(level: float, resamples: int) -> None:
    if not 0.0 < level < 1.0:
        raise ValueError(f"level must lie in (0, 1), got {level}")
    if resamples < 1:
        raise ValueError(f"resamples must be at least 1, got {resamples}")


def _draws(key: str) -> np.random.Generator:
    """The generator of one interval's draws, seeded by its *key* alone."""
    return np.random.default_rng(zlib.crc32(key.encode("utf-8")))


def _resampled_medians(v: np.ndarray, rng: np.random.Generator, resamples: int) -> np.ndarray:
    """Medians of *resamples* resamples of *v* with replacement."""
    return np.median(v[rng.integers(0, v.size, (resamples, v.size))], axis=1)


def _bounds(draws: np.ndarray, level: float) -> tuple[float, float]:
    """The two-sided percentile interval of *draws* at *level*."""
    tail = (1.0 - level) / 2.0
    lo, hi = np.quantile(draws, [tail, 1.0 - tail])
    return float(lo), float(hi)


def median_ratio_interval(numerator, denominator, key: str, level: float = LEVEL,
                          resamples: int = RESAMPLES) -> tuple[float, float]:
    """``(lo, hi)``: the percentile-bootstrap interval of ``median(numerator) /
    median(denominator)`` at *level*, resampling each sample on its own; *key* seeds the
    draws (same samples and key, same interval). ``(nan, nan)`` when either sample is empty
    or holds a value that is not finite."""
    # sorted: the draws then depend on the values only, not on the order the runs came in
    a = np.sort(np.asarray(numerator, dtype=np.float64))
    b = np.sort(np.asarray(denominator, dtype=np.float64))
    if a.size == 0 or b.size == 0 or not (np.isfinite(a).all() and np.isfinite(b).all()):
        return float("nan"), float("nan")
    _check(level, resamples)
    rng = _draws(key)
    top = _resampled_medians(a, rng, resamples)
    bottom = _resampled_medians(b, rng, resamples)
    with np.errstate(divide="ignore", invalid="ignore"):
        return _bounds(top / bottom, level)
