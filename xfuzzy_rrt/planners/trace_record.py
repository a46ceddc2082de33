"""The per-iteration trace buffers every Fuzzy-RRT kernel fills, and the one function that
writes a row (shared by every kernel, so a trace means one thing whatever the semantics).

Buffers are preallocated in Python (``np.empty``: the kernel writes every field of every row it
records, and untouched pages of a 10,000-row buffer then cost nothing) and travel into the
compiled loop as one :class:`TraceArrays` record. When tracing is off a kernel gets ``None``
instead, and numba decides ``TR is None`` when it compiles: the untraced kernel is a
specialisation of its own, with no trace code and no trace buffers. Why: until the seventeenth
session an untraced run took 1-row buffers (made in compiled code each call) and chose at run
time; with the caches cold (a benchmark, or a program doing anything between plans) whole
calls of the default are 1-6 % faster without them (``benchmarks/cold_calls.py``, old and new
alternated; docs/peer-measurements.md, seventeenth session). A trace never changes a
plan: both specialisations make the same decisions on the same floats
(``tests/test_tracing_leaves_the_plan_unchanged.py``).

Shapes, with ``dof`` the joint-space dimension, ``groups`` the number of fuzzy evaluations per
iteration (one per arm for the paper's workspace semantics, one for the goal-frame semantics)
and ``n_out`` the rulebook's outputs: ``x[rows, groups * 4]``, ``y[rows, groups * n_out]``,
``box[rows, 2 * dof]`` (``lo, hi`` per joint), ``sample``/``new[rows, dof]``,
``rule``/``w[rows, groups * n_out, MAX_FIRED]``.
"""

from __future__ import annotations

from typing import NamedTuple

import numba as nb
import numpy as np

from xfuzzy_rrt.fuzzy.variables import MAX_FIRED


class TraceArrays(NamedTuple):
    from_node: np.ndarray
    x: np.ndarray
    y: np.ndarray
    box: np.ndarray
    goal_sampled: np.ndarray
    sample: np.ndarray
    nearest: np.ndarray
    new: np.ndarray
    outcome: np.ndarray
    node: np.ndarray
    tree: np.ndarray
    rule: np.ndarray
    w: np.ndarray


def make_trace(rows: int, dof: int, n_out: int, groups: int = 1) -> TraceArrays:
    """Buffers for ``rows`` iterations (a kernel that traces nothing takes ``None``)."""
    rows = max(int(rows), 1)
    return TraceArrays(
        np.empty(rows, dtype=np.int64), np.empty((rows, 4 * groups)),
        np.empty((rows, n_out * groups)), np.empty((rows, 2 * dof)),
        np.empty(rows, dtype=np.bool_), np.empty((rows, dof)), np.empty(rows, dtype=np.int64),
        np.empty((rows, dof)), np.empty(rows, dtype=np.int8), np.empty(rows, dtype=np.int64),
        np.empty(rows, dtype=np.int64), np.empty((rows, n_out * groups, MAX_FIRED), dtype=np.int32),
        np.empty((rows, n_out * groups, MAX_FIRED)))


@nb.njit(cache=True, nogil=True, inline="always")
def record_iteration(TR, row, from_node, x, y, box, goal_sampled, sample, nearest_node, q_new,
                     outcome, new_index, tree_size):
    """Write trace row ``row`` (the fired rules were written by the engine already)."""
    TR.from_node[row] = from_node
    for k in range(x.shape[0]):
        TR.x[row, k] = x[k]
    for k in range(y.shape[0]):
        TR.y[row, k] = y[k]
    for k in range(box.shape[0]):
        TR.box[row, k] = box[k]
    TR.goal_sampled[row] = goal_sampled
    for k in range(sample.shape[0]):
        TR.sample[row, k] = sample[k]
        TR.new[row, k] = q_new[k]
    TR.nearest[row] = nearest_node
    TR.outcome[row] = outcome
    TR.node[row] = new_index
    TR.tree[row] = tree_size
