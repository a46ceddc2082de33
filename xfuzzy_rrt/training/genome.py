"""The genome: how 3,822 genes become six fuzzy systems that are always valid.

Layout (the paper's count): per FIS, in the semantics' output order, 637 genes —
``4 inputs x 3`` membership genes, then the 625 rule constants in rule-index order — so an
individual has ``6 x 637 = 3,822`` genes at 2 DOF, and ``n_out x 637`` for a rulebook of
``n_out`` FIS: the paper's semantics at N joints has ``2N + 2`` (``12 x 637 = 7,644`` genes at
N = 5), goal-frame always six (its DOF only widens ``joint_dist_to_goal``'s range, which the
decoding reads from the semantics). :func:`n_genes` gives the count. Every gene lives in ``[0, 1]`` (the GA's bounds), and
decoding maps it into the fuzzy system, so *whatever crossover and mutation do* (as long as
they respect the box, which bounded operators do and :func:`decode` re-clips anyway):

- **Peaks stay strictly inside the range and strictly increasing** by stick-breaking: with
  fractions ``a_k = A_MIN + (A_MAX - A_MIN) * g_k`` in ``[0.05, 0.95]``,
  ``p1 = lo + a1 (hi - lo)``, ``p2 = p1 + a2 (hi - p1)``, ``p3 = p2 + a3 (hi - p2)``.
  Every gap is at least 5 % of what remains, so no term degenerates to a spike (which would make
  the partition ill-conditioned in floating point). The default quarter peaks are
  ``a = (1/4, 1/3, 1/2)``.
- **Constants stay inside the output range**: ``c = lo + g (hi - lo)``.

Decoding is vectorised over a whole population (no Python per individual or per gene), and
:func:`encode` is its exact inverse up to rounding, used to seed the population from existing
rulebooks.
"""

from __future__ import annotations

import numpy as np

from xfuzzy_rrt.fuzzy import semantics as _sem
from xfuzzy_rrt.fuzzy.variables import N_INPUTS, N_OUTPUTS, N_RULES, N_TERMS

DEFAULT_DOF = _sem.DEFAULT_DOF

#: Membership genes per input (the three interior peaks; the ends are the range ends).
MF_GENES_PER_INPUT = N_TERMS - 2
MF_GENES = N_INPUTS * MF_GENES_PER_INPUT  # 12
GENES_PER_FIS = MF_GENES + N_RULES  # 637
N_GENES = N_OUTPUTS * GENES_PER_FIS  # 3,822: the 2-DOF genome (see n_genes for any DOF)
A_MIN = 0.05
A_MAX = 0.95

#: The planner modes a genome can be trained for: the paper's semantics with absolute or
#: relative bounds, or the goal-frame semantics (which has no bounds mode) -- each
#: semantics' ``modes`` (:func:`xfuzzy_rrt.fuzzy.semantics.training_modes`).
MODES = _sem.training_modes()


def semantics_of_mode(mode: str, dof: int = DEFAULT_DOF) -> "_sem.Semantics":
    """The rulebook semantics a training mode produces, at *dof* joints: the registered
    semantics that offers *mode* (:func:`xfuzzy_rrt.fuzzy.semantics.of_mode`), whose names
    and ranges are the genome's layout."""
    return _sem.of_mode(mode).for_dof(dof)


def n_outputs(mode: str, dof: int = DEFAULT_DOF) -> int:
    """Number of FIS a genome of *mode* at *dof* joints encodes (6 at 2 DOF)."""
    return len(semantics_of_mode(mode, dof).outputs)


def n_genes(mode: str = "absolute", dof: int = DEFAULT_DOF) -> int:
    """Genes of one individual: ``n_outputs * (12 + 625)`` (3,822 at 2 DOF; 7,644 for the
    paper's semantics at 5 DOF)."""
    return n_outputs(mode, dof) * GENES_PER_FIS


def _ranges(sem: "_sem.Semantics"):
    """``(in_lo, in_hi, out_lo, out_hi)`` arrays of *sem* (inputs and outputs in order)."""
    return (np.array([sem.input_ranges[n][0] for n in sem.inputs]),
            np.array([sem.input_ranges[n][1] for n in sem.inputs]),
            np.array([sem.output_ranges[n][0] for n in sem.outputs]),
            np.array([sem.output_ranges[n][1] for n in sem.outputs]))


def _split(genes: np.ndarray, n_out: int) -> tuple[np.ndarray, np.ndarray]:
    """``(mf [n, n_out, 4, 3], consts [n, n_out, 625])`` views of a population
    ``[n, n_out * 637]``."""
    g = genes.reshape(genes.shape[0], n_out, GENES_PER_FIS)
    mf = g[:, :, :MF_GENES].reshape(genes.shape[0], n_out, N_INPUTS, MF_GENES_PER_INPUT)
    return mf, g[:, :, MF_GENES:]


def decode(genes, mode: str = "absolute", dof: int = DEFAULT_DOF) -> tuple[np.ndarray, np.ndarray]:
    """Engine arrays ``(knots [n, n_out, 4, 5], consts [n, n_out, 625])`` of a population
    ``[n, n_out * 637]`` (``n_out`` = 6 at 2 DOF; see :func:`n_genes`).

    A single genome is accepted too (then ``n = 1``). Genes are clipped to [0, 1]. *mode*
    (one of :data:`MODES`) and *dof* fix the semantics, hence the outputs and every range.
    """
    sem = semantics_of_mode(mode, dof)
    n_out = len(sem.outputs)
    in_lo, in_hi, out_lo, out_hi = _ranges(sem)
    genes = np.clip(np.atleast_2d(np.asarray(genes, dtype=np.float64)), 0.0, 1.0)
    if genes.shape[1] != n_out * GENES_PER_FIS:
        raise ValueError(f"a {mode} genome at dof {dof} has {n_out * GENES_PER_FIS} genes, "
                         f"got {genes.shape[1]}")
    mf, c = _split(genes, n_out)
    a = A_MIN + (A_MAX - A_MIN) * mf
    lo = np.broadcast_to(in_lo[None, None, :], a.shape[:3])
    hi = np.broadcast_to(in_hi[None, None, :], a.shape[:3])
    knots = np.empty(a.shape[:3] + (N_TERMS,))
    knots[..., 0] = lo
    p1 = lo + a[..., 0] * (hi - lo)
    p2 = p1 + a[..., 1] * (hi - p1)
    p3 = p2 + a[..., 2] * (hi - p2)
    knots[..., 1] = p1
    knots[..., 2] = p2
    knots[..., 3] = p3
    knots[..., 4] = hi
    consts = out_lo[None, :, None] + c * (out_hi - out_lo)[None, :, None]
    return np.ascontiguousarray(knots), np.ascontiguousarray(consts)


def encode(knots, consts, mode: str = "absolute", dof: int = DEFAULT_DOF) -> np.ndarray:
    """Genome ``[n_out * 637]`` of engine arrays ``knots [n_out, 4, 5]``, ``consts
    [n_out, 625]`` of a rulebook of *mode* at *dof* joints.

    Peaks whose fractions fall outside ``[A_MIN, A_MAX]`` (possible for hand-written rulebooks)
    are clipped to the nearest encodable partition; constants are clipped to their range.
    """
    knots = np.asarray(knots, dtype=np.float64)
    consts = np.asarray(consts, dtype=np.float64)
    sem = semantics_of_mode(mode, dof)
    n_out = len(sem.outputs)
    if knots.shape != (n_out, N_INPUTS, N_TERMS) or consts.shape != (n_out, N_RULES):
        raise ValueError(f"expected knots [{n_out}, 4, 5] and consts [{n_out}, 625] ({mode} at "
                         f"dof {dof}), got {list(knots.shape)} and {list(consts.shape)}")
    _, _, out_lo, out_hi = _ranges(sem)
    lo = knots[..., 0]
    hi = knots[..., 4]
    p1, p2, p3 = knots[..., 1], knots[..., 2], knots[..., 3]
    a = np.stack([(p1 - lo) / (hi - lo), (p2 - p1) / (hi - p1), (p3 - p2) / (hi - p2)], axis=-1)
    mf = np.clip((a - A_MIN) / (A_MAX - A_MIN), 0.0, 1.0)
    c = np.clip((consts - out_lo[:, None]) / (out_hi - out_lo)[:, None], 0.0, 1.0)
    genome = np.empty((n_out, GENES_PER_FIS))
    genome[:, :MF_GENES] = mf.reshape(n_out, MF_GENES)
    genome[:, MF_GENES:] = c
    return genome.reshape(n_out * GENES_PER_FIS)


def constant_genome(goal_bias: float, box: tuple[float, ...], step: float) -> np.ndarray:
    """A genome whose systems output constants (every rule the same value), paper semantics.

    *box* holds two bounds per joint (``len(box) = 2N`` gives an N-DOF genome). With
    ``box = (-180, 180, -180, 180)``, bias 0.05 and step 10 in absolute mode this is plain RRT
    with the baseline's settings (the "RRT-equivalent" rulebook).
    """
    if len(box) % 2:
        raise ValueError(f"box needs two bounds per joint, got {len(box)} values")
    return constant_outputs_genome((goal_bias, *box, step), "absolute", len(box) // 2)


def constant_outputs_genome(values, mode: str, dof: int = DEFAULT_DOF) -> np.ndarray:
    """A genome whose systems output the constants *values* (the semantics' output order at
    *dof*), with the default membership peaks of *mode*'s semantics."""
    sem = semantics_of_mode(mode, dof)
    if len(values) != len(sem.outputs):
        raise ValueError(f"{len(sem.outputs)} output values needed ({', '.join(sem.outputs)}), "
                         f"got {len(values)}")
    knots = np.array([[sem.default_knots(n) for n in sem.inputs]] * len(sem.outputs))
    consts = np.array([[v] * N_RULES for v in values], dtype=np.float64)
    return encode(knots, consts, mode, dof)
