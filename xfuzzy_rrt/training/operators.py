"""The GA's breeding operators: tournament selection, SBX crossover, polynomial mutation.

They are pymoo 0.6.2's ``TournamentSelection``, ``SBX(prob_var=0.5)`` and ``PM`` as
:func:`~.ga.breed` configured them before, for genomes in the box ``[0, 1]^n``: the same draws
from the same ``numpy.random.Generator`` in the same order and the same floating-point
arithmetic, so every population — and so every shipped rulebook's provenance command — comes
out the same, bit for bit (tested against pymoo itself, ``tests/test_ga_operators.py``).

Why our own: breeding ran serially in the main process while the workers waited, and pymoo's
general operators (``Population`` objects of 400 ``Individual`` records, bounds repeated to the
population's shape, powers computed for every crossed gene on both branches, repairs over
every gene) made it 0.21-0.37 s of a ~1.0 s paper-scale evaluation. Here the bounds ``0`` and
``1`` are folded in where that is exact (``x - 0.0 == x``, ``x / 1.0 == x``, ``d * 1.0 == d``),
and a power is computed only where its branch uses it (an elementwise ufunc gives each element
the same value whatever else is in the array). Array shapes are kept where they decide which
numpy loop runs (a broadcast exponent can take a different loop than an array one).
"""

from __future__ import annotations

import math

import numpy as np

#: pymoo's SBX: genes closer than this are not crossed.
SBX_EPS = 1.0e-14
#: pymoo's SBX default share of a mating's genes that are crossed.
SBX_PROB_VAR = 0.5
#: pymoo's SBX default probability of swapping the two children of a crossed gene.
SBX_PROB_BIN = 0.5


def tournament(fitness: np.ndarray, n_matings: int, pressure: int,
               rng: np.random.Generator) -> np.ndarray:
    """Parent indices int[n_matings, 2]: each the winner of ``pressure`` individuals drawn
    without replacement within consecutive random permutations of the population; the
    highest fitness wins, ties go to the lower index."""
    fitness = np.asarray(fitness, dtype=np.float64)
    n = fitness.shape[0]
    if not np.all(np.isfinite(fitness)):
        raise ValueError("tournament: every fitness must be finite")
    n_random = n_matings * 2 * pressure
    n_perms = math.ceil(n_random / n)
    draws = np.concatenate([rng.permutation(n) for _ in range(n_perms)])[:n_random]
    rows = draws.reshape(n_matings * 2, pressure)
    # best fitness first, then lowest index: a total order, so the minimum of (-fitness,
    # index) is what a left-to-right scan keeping the better one finds
    first = np.lexsort((rows, -fitness[rows]), axis=1)[:, 0]
    return rows[np.arange(rows.shape[0]), first].reshape(n_matings, 2)


def _betaq(beta: np.ndarray, rand: np.ndarray, eta: np.ndarray) -> np.ndarray:
    alpha = 2.0 - np.power(beta, -(eta + 1.0))
    inv = 1.0 / alpha
    mask = rand <= inv
    mask_not = rand > inv
    expo = 1.0 / (eta + 1.0)
    betaq = np.zeros(mask.shape)
    betaq[mask] = np.power((rand * alpha)[mask], expo[mask])
    betaq[mask_not] = np.power((1.0 / (2.0 - rand * alpha))[mask_not], expo[mask_not])
    return betaq


def sbx(x1: np.ndarray, x2: np.ndarray, prob: float, eta: float,
        rng: np.random.Generator) -> np.ndarray:
    """Children float64[2 * n, n_var] of the matings ``(x1[k], x2[k])``: all first children,
    then all second ones (pymoo's order). A mating is crossed with probability ``prob``, each
    of its genes with probability 0.5 (unless the parents' genes are within 1e-14); an
    uncrossed mating's children are its parents."""
    n_matings, n_var = x1.shape
    children = np.empty((2, n_matings, n_var))
    mated = rng.random(n_matings) < np.full(n_matings, prob)
    if mated.any():
        # pymoo draws a per-mating "exchange" number; with exchange probability 1 it never
        # changes anything, but it is drawn
        rng.random((n_matings, 1))
        cross = rng.random((n_matings, n_var)) < np.full((n_matings, 1), SBX_PROB_VAR)
        cross[np.abs(x1 - x2) <= SBX_EPS] = False
        p1 = x1[cross]
        p2 = x2[cross]
        sm = p1 < p2
        y1 = np.where(sm, p1, p2)
        y2 = np.where(sm, p2, p1)
        etas = np.full(p1.shape[0], float(eta))
        rand = rng.random(p1.shape[0])
        delta = y2 - y1
        total = y1 + y2
        c1 = 0.5 * (total - _betaq(1.0 + (2.0 * y1 / delta), rand, etas) * delta)
        c2 = 0.5 * (total + _betaq(1.0 + (2.0 * (1.0 - y2) / delta), rand, etas) * delta)
        child1 = np.where(sm, c1, c2)
        child2 = np.where(sm, c2, c1)
        swap = np.bitwise_xor(rng.random(p1.shape[0]) < np.full(p1.shape[0], SBX_PROB_BIN),
                              p1 > p2)
        q1 = x1.copy()
        q2 = x2.copy()
        q1[cross] = np.where(swap, child2, child1)
        q2[cross] = np.where(swap, child1, child2)
        for q in (q1, q2):
            q[q < 0.0] = 0.0
            q[q > 1.0] = 1.0
        children[0, mated] = q1[mated]
        children[1, mated] = q2[mated]
    children[0, ~mated] = x1[~mated]
    children[1, ~mated] = x2[~mated]
    return children.reshape(2 * n_matings, n_var)


def polynomial_mutation(x: np.ndarray, rate: float, eta: float,
                        rng: np.random.Generator) -> np.ndarray:
    """``x`` [n, n_var] with each gene mutated with probability ``rate`` by pymoo's
    polynomial mutation of index ``eta`` (bounds 0 and 1); a new array."""
    n, n_var = x.shape
    mut = rng.random((n, n_var)) < np.full(n, float(rate))[:, None]
    xm = x[mut]
    etas = np.full(xm.shape[0], float(eta))
    mut_pow = 1.0 / (etas + 1.0)
    rand = rng.random(xm.shape)
    mask = rand <= 0.5
    mask_not = np.logical_not(mask)
    deltaq = np.zeros(xm.shape)
    with np.errstate(invalid="ignore"):
        val = 2.0 * rand + (1.0 - 2.0 * rand) * np.power(1.0 - xm, etas + 1.0)
        deltaq[mask] = (np.power(val, mut_pow) - 1.0)[mask]
        val = 2.0 * (1.0 - rand) + 2.0 * (rand - 0.5) * np.power(1.0 - (1.0 - xm), etas + 1.0)
        deltaq[mask_not] = (1.0 - np.power(val, mut_pow))[mask_not]
    y = xm + deltaq
    y[y < 0.0] = 0.0
    y[y > 1.0] = 1.0
    out = x.astype(np.float64, copy=True)
    out[mut] = y
    out[out < 0.0] = 0.0
    out[out > 1.0] = 1.0
    # pymoo then draws whether each individual takes its mutation (probability 1: all do)
    rng.random(n)
    return out
