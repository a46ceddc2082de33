"""Plain reference TSK inference over all 625 rules, for tests and as executable documentation.

Deliberately naive: memberships from :mod:`.membership`, the firing strength of *every* rule
as the product of its four memberships, output = ``Σ w_r c_r / Σ w_r``. The compiled engine
(:mod:`.engine`) must agree with this to ≤ 1e-12; it is fast because it only visits the ≤ 16
rules the partition can activate, not because it computes anything different.
"""

from __future__ import annotations

import numpy as np

from xfuzzy_rrt.fuzzy.membership import partition
from xfuzzy_rrt.fuzzy.variables import N_INPUTS, N_RULES, N_TERMS


def strengths(knots_fis, X) -> np.ndarray:
    """Raw firing strengths of all rules of one FIS: ``float64[n, 625]`` in rule-index order."""
    X = np.atleast_2d(np.asarray(X, dtype=np.float64))
    mu = [partition(X[:, i], knots_fis[i]) for i in range(N_INPUTS)]  # each (n, 5)
    # rule r = ((t0*5 + t1)*5 + t2)*5 + t3, i.e. C-order over (t0, t1, t2, t3)
    w = np.einsum("na,nb,nc,nd->nabcd", mu[0], mu[1], mu[2], mu[3])
    return w.reshape(X.shape[0], N_TERMS**N_INPUTS)


def infer_reference(knots, consts, X) -> np.ndarray:
    """Outputs ``float64[n, n_fis]`` of every FIS for inputs ``X`` (``float64[n, 4]``)."""
    knots = np.asarray(knots, dtype=np.float64)
    consts = np.asarray(consts, dtype=np.float64)
    X = np.atleast_2d(np.asarray(X, dtype=np.float64))
    out = np.empty((X.shape[0], knots.shape[0]))
    for f in range(knots.shape[0]):
        w = strengths(knots[f], X)
        out[:, f] = (w @ consts[f]) / w.sum(axis=1)
    return out


def fired_reference(knots_fis, consts_fis, x) -> tuple[np.ndarray, np.ndarray]:
    """For one input *x*: indices (ascending) and normalised strengths of the rules that fire."""
    w = strengths(knots_fis, np.asarray(x, dtype=np.float64)[None, :])[0]
    idx = np.nonzero(w)[0]
    if len(idx) > 2**N_INPUTS or w.size != N_RULES:  # pragma: no cover - partition invariant
        raise RuntimeError("more rules fired than a Ruspini partition allows")
    return idx, w[idx] / w.sum()
