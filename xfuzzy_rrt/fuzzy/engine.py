"""The compiled zero-order Takagi-Sugeno engine (numba) that the planner loop calls.

Inputs: ``knots`` float64[n_out, 4, 5] (per FIS, per input, ``[lo, p1, p2, p3, hi]``) and
``consts`` float64[n_out, 625] (rule constants, index ``((t0*5 + t1)*5 + t2)*5 + t3``), as made
by :meth:`xfuzzy_rrt.fuzzy.rulebook.Rulebook.arrays`. ``n_out = knots.shape[0]`` is the
rulebook's number of FIS: 6 at 2 DOF, ``2N + 2`` for a paper rulebook of N joints. Nothing here
assumes six; every function loops over ``knots.shape[0]``, so callers size their buffers from it.

Why it is fast without being different: the five terms of every input form a Ruspini
partition, so an input value lies in one knot segment ``[knots[k], knots[k+1]]`` where only
terms ``k`` and ``k+1`` are non-zero. Locating the segment for each of the four inputs leaves
``2**4 = 16`` candidate rules; product AND over them and ``Σ w c / Σ w`` give exactly what
the plain 625-rule evaluation (:mod:`.reference`) gives (tests: ≤ 1e-12). Memberships use the
same expressions as :mod:`.membership`, ``(right - x) / (right - left)`` and
``(x - left) / (right - left)``. ``Σ w`` is computed rather than assumed to be 1.

Inputs outside a variable's range are clamped to it (they sit on a shoulder). NaN inputs
propagate to NaN outputs (validate at the boundary, e.g. ``rules eval`` rejects them).

Tracing: with ``record=True``, :func:`infer` also writes, per FIS, the rules with non-zero
strength (ascending index) and their normalised strengths (summing to 1) into the caller's
``fired_rule`` int32[n_out, 16] / ``fired_w`` float64[n_out, 16]; unused slots get -1 and 0.0. The
outputs are bit-identical with and without recording (same arithmetic), so turning a trace on
never changes what a planner does. Recording costs the 16 products and stores per FIS
(~0.1 µs per six-output call). Nothing allocates.
"""

from __future__ import annotations

import numba
import numpy as np

from xfuzzy_rrt.fuzzy.variables import MAX_FIRED, N_INPUTS, N_OUTPUTS, N_RULES, N_TERMS



@numba.njit(cache=True, nogil=True, inline="always")
def _locate(knots, f, i, v):
    """Segment ``k`` of (clamped) *v* on input *i* of FIS *f*, and the memberships of terms
    ``k`` and ``k + 1`` there."""
    lo = knots[f, i, 0]
    hi = knots[f, i, 4]
    v = min(max(v, lo), hi)
    # branch-free segment index: number of interior peaks at or below v
    k = np.int64(v >= knots[f, i, 1]) + np.int64(v >= knots[f, i, 2]) + np.int64(v >= knots[f, i, 3])
    left = knots[f, i, k]
    right = knots[f, i, k + 1]
    width = right - left
    return k, (right - v) / width, (v - left) / width


@numba.njit(cache=True, nogil=True, inline="always")
def _infer_fis(knots, consts, f, x0, x1, x2, x3):
    """Output of FIS *f* only (the hot path, no recording).

    The 16 corner rules ``r + 125*i0 + 25*i1 + 5*i2 + i3`` have strengths
    ``m0[i0]*m1[i1]*m2[i2]*m3[i3]``; the sums ``Σ w c`` and ``Σ w`` are evaluated in factorised
    (Horner-like) form, innermost input first, which is the same sum with 30 instead of 64
    multiplications (and ``Σ w = Π (a_i + b_i)`` by the distributive law). ~1.6x faster than
    the plain 16-term loop; the difference to it is rounding only (≤ 1e-15 in the tests).
    """
    k0, a0, b0 = _locate(knots, f, 0, x0)
    k1, a1, b1 = _locate(knots, f, 1, x1)
    k2, a2, b2 = _locate(knots, f, 2, x2)
    k3, a3, b3 = _locate(knots, f, 3, x3)
    r = ((k0 * 5 + k1) * 5 + k2) * 5 + k3
    return _combine(consts[f], r, a0, b0, a1, b1, a2, b2, a3, b3)


@numba.njit(cache=True, nogil=True, inline="always")
def _combine(c, r, a0, b0, a1, b1, a2, b2, a3, b3):
    """``Σ w c / Σ w`` over the 16 corner rules from the base rule *r* (factorised)."""
    s00 = a2 * (a3 * c[r] + b3 * c[r + 1]) + b2 * (a3 * c[r + 5] + b3 * c[r + 6])
    s01 = a2 * (a3 * c[r + 25] + b3 * c[r + 26]) + b2 * (a3 * c[r + 30] + b3 * c[r + 31])
    s10 = a2 * (a3 * c[r + 125] + b3 * c[r + 126]) + b2 * (a3 * c[r + 130] + b3 * c[r + 131])
    s11 = a2 * (a3 * c[r + 150] + b3 * c[r + 151]) + b2 * (a3 * c[r + 155] + b3 * c[r + 156])
    num = a0 * (a1 * s00 + b1 * s01) + b0 * (a1 * s10 + b1 * s11)
    den = (a0 + b0) * (a1 + b1) * (a2 + b2) * (a3 + b3)
    return num / den


@numba.njit(cache=True, nogil=True, _nrt=False)
def infer(knots, consts, x, out, fired_rule, fired_w, record):
    """Evaluate every FIS at input ``x`` (float64[4], inputs order) into ``out``
    float64[n_out] (``n_out = knots.shape[0]``; six at 2 DOF).

    With ``record`` true, also fill ``fired_rule`` int32[n_out, 16] and ``fired_w``
    float64[n_out, 16] (see the module docstring). Callable from other njit code; no allocation.
    """
    n_fis = knots.shape[0]
    if not record:  # the planner's normal path: factorised, nothing stored
        for f in range(n_fis):
            out[f] = _infer_fis(knots, consts, f, x[0], x[1], x[2], x[3])
        return
    width = fired_rule.shape[1]
    for f in range(n_fis):
        k0, a0, b0 = _locate(knots, f, 0, x[0])
        k1, a1, b1 = _locate(knots, f, 1, x[1])
        k2, a2, b2 = _locate(knots, f, 2, x[2])
        k3, a3, b3 = _locate(knots, f, 3, x[3])
        base = ((k0 * 5 + k1) * 5 + k2) * 5 + k3
        # the output uses exactly the arithmetic of the non-recording path, so switching
        # tracing on can never change a planner's decisions
        out[f] = _combine(consts[f], base, a0, b0, a1, b1, a2, b2, a3, b3)
        den = 0.0
        n_fired = 0
        for i0 in range(2):
            w0 = a0 if i0 == 0 else b0
            for i1 in range(2):
                w1 = w0 * (a1 if i1 == 0 else b1)
                for i2 in range(2):
                    w2 = w1 * (a2 if i2 == 0 else b2)
                    for i3 in range(2):
                        w = w2 * (a3 if i3 == 0 else b3)
                        den += w
                        # branch-free compaction: always write, advance only past non-zero
                        fired_rule[f, n_fired] = base + i0 * 125 + i1 * 25 + i2 * 5 + i3
                        fired_w[f, n_fired] = w
                        n_fired += np.int64(w != 0.0)
        for j in range(n_fired):
            fired_w[f, j] = fired_w[f, j] / den
        for j in range(n_fired, width):
            fired_rule[f, j] = -1
            fired_w[f, j] = 0.0


@numba.njit(cache=True, nogil=True, _nrt=True)
def infer_batch(knots, consts, X):
    """Evaluate every row of ``X`` float64[n, 4]; return float64[n, n_fis] (single thread)."""
    n = X.shape[0]
    n_fis = knots.shape[0]
    out = np.empty((n, n_fis))
    for j in range(n):
        x0 = X[j, 0]
        x1 = X[j, 1]
        x2 = X[j, 2]
        x3 = X[j, 3]
        for f in range(n_fis):
            out[j, f] = _infer_fis(knots, consts, f, x0, x1, x2, x3)
    return out


def check_arrays(knots, consts) -> tuple[np.ndarray, np.ndarray]:
    """Validate shapes and dtypes of compiled arrays; return C-contiguous float64 views/copies.

    The njit functions do not check (they run in the hot loop); call this once at a boundary.
    """
    knots = np.ascontiguousarray(knots, dtype=np.float64)
    consts = np.ascontiguousarray(consts, dtype=np.float64)
    if knots.ndim != 3 or knots.shape[1:] != (N_INPUTS, N_TERMS):
        raise ValueError(f"knots must have shape (n_fis, {N_INPUTS}, {N_TERMS}), got {knots.shape}")
    if consts.shape != (knots.shape[0], N_RULES):
        raise ValueError(f"consts must have shape ({knots.shape[0]}, {N_RULES}), got {consts.shape}")
    if not (np.all(np.isfinite(knots)) and np.all(np.diff(knots, axis=2) > 0)):
        raise ValueError("knots must be finite and strictly increasing along each input")
    return knots, consts


def evaluate(knots, consts, X) -> np.ndarray:
    """Checked convenience wrapper: outputs float64[n, n_fis] for inputs ``X`` (n×4 or 4)."""
    knots, consts = check_arrays(knots, consts)
    X = np.ascontiguousarray(np.atleast_2d(X), dtype=np.float64)
    if X.ndim != 2 or X.shape[1] != N_INPUTS:
        raise ValueError(f"inputs must have shape (n, {N_INPUTS}), got {X.shape}")
    return infer_batch(knots, consts, X)


def new_trace_buffers(n_fis: int = N_OUTPUTS) -> tuple[np.ndarray, np.ndarray]:
    """``(fired_rule, fired_w)`` buffers of the shapes :func:`infer` fills when recording.

    Pass ``knots.shape[0]`` (or ``rulebook.n_outputs``) for a rulebook of another DOF; the
    default is the 2-DOF six.
    """
    return np.full((n_fis, MAX_FIRED), -1, dtype=np.int32), np.zeros((n_fis, MAX_FIRED))
