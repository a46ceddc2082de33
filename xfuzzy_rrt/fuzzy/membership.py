"""Membership functions as small pure vectorised numpy functions (scikit-fuzzy style).

These are *not* on the planning hot path (the compiled engine in :mod:`.engine` inlines the
same arithmetic); they exist for the reference implementation, tests and plots, and they are
checked against scikit-fuzzy's ``trimf``/``trapmf``. The formulas are written exactly as the
engine evaluates them, ``(x - a) / (b - a)`` on a rising edge and ``(c - x) / (c - b)`` on a
falling edge, so that both agree to the last bit on the same inputs.

A partition row is ``knots = [lo, p1, p2, p3, hi]``: term ``j`` peaks at ``knots[j]``; term 0
is a left shoulder (1 at or below ``lo``), term 4 a right shoulder (1 at or above ``hi``), the
three middle terms are triangles between neighbouring knots. Together they form a Ruspini
partition (memberships sum to 1 everywhere).
"""

from __future__ import annotations

import numpy as np


def trimf(x, a: float, b: float, c: float) -> np.ndarray:
    """Triangle rising from ``a`` to 1 at ``b``, falling to 0 at ``c`` (requires a < b < c)."""
    x = np.asarray(x, dtype=np.float64)
    y = np.zeros_like(x)
    rising = (x > a) & (x < b)
    y[rising] = (x[rising] - a) / (b - a)
    falling = (x >= b) & (x < c)
    y[falling] = (c - x[falling]) / (c - b)
    return y


def left_shoulder(x, lo: float, p1: float) -> np.ndarray:
    """1 at or below ``lo``, falling linearly to 0 at ``p1`` and beyond."""
    x = np.asarray(x, dtype=np.float64)
    y = np.zeros_like(x)
    y[x <= lo] = 1.0
    mid = (x > lo) & (x < p1)
    y[mid] = (p1 - x[mid]) / (p1 - lo)
    return y


def right_shoulder(x, p3: float, hi: float) -> np.ndarray:
    """0 at or below ``p3``, rising linearly to 1 at ``hi`` and beyond."""
    x = np.asarray(x, dtype=np.float64)
    y = np.zeros_like(x)
    y[x >= hi] = 1.0
    mid = (x > p3) & (x < hi)
    y[mid] = (x[mid] - p3) / (hi - p3)
    return y


def clamp(x, lo: float, hi: float) -> np.ndarray:
    """Inputs outside a variable's range are clamped onto it (they then sit on a shoulder)."""
    return np.clip(np.asarray(x, dtype=np.float64), lo, hi)


def partition(x, knots) -> np.ndarray:
    """Memberships of *x* (any shape) in the five terms of one input: shape ``x.shape + (5,)``.

    *x* is clamped to ``[knots[0], knots[4]]`` first, as the engine does.
    """
    k = [float(v) for v in np.asarray(knots, dtype=np.float64)]
    if len(k) != 5:
        raise ValueError(f"a partition needs 5 knots, got {len(k)}")
    xc = clamp(x, k[0], k[4])
    return np.stack(
        [
            left_shoulder(xc, k[0], k[1]),
            trimf(xc, k[0], k[1], k[2]),
            trimf(xc, k[1], k[2], k[3]),
            trimf(xc, k[2], k[3], k[4]),
            right_shoulder(xc, k[3], k[4]),
        ],
        axis=-1,
    )
