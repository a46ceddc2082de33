"""A search tree in one block of memory, so that a plan call hands it to compiled code as one
array instead of seventeen.

Why: numba unboxes every array argument of a compiled call on its own (a reference, a
bookkeeping record, a check of type and layout: ~60-100 ns each). A Fuzzy-RRT-Connect call took
two trees of 17 arrays each, plus their reset in Python (two ``fill`` calls and a ``meta`` copy
per tree); on a 3-joint problem that was ~5 us of a call whose whole planning often takes
20-50 us. Here the tree's arrays are views into one ``uint8`` block (the *arena*), laid out by
a small ``layout`` table; a compiled entry rebuilds the :class:`~xfuzzy_rrt.planners.tree.
TreeArrays` record from the block's address (borrowed views, below: no copy, no allocation)
and empties the tree itself (:func:`emptied_tree_in`). The Python side keeps the
same arrays as views, so reading ``tree.meta`` or ``tree.nodes`` after a run is unchanged.

What goes in is exactly :func:`~xfuzzy_rrt.planners.tree.make_tree`'s tree (its shapes, dtypes
and initial values: the fields are copied in), plus ``meta0``, the empty tree's ``meta``, as an
18th field, so that emptying needs nothing from outside. Fields start at multiples of 64 bytes
(aligned views: numba types them exactly as the separate arrays were typed).

**Borrowed views.** A view made with ``block[o:o + n].view(...)`` holds a reference to the
block: numba increments and decrements the block's reference count (an atomic operation) for
each of the 17 views and again as they pass between functions, and calls its ``view`` and
``reshape`` helpers for each. That was ~0.7 us of every call per tree, warm (a whole warm
2-joint call of the tuned RRT takes 10-25 us). The compiled entries therefore rebuild the
record from the block's address instead (:func:`borrowed_1d`, :func:`borrowed_2d`): arrays
with no owner, which reference counting skips. This is sound because the views never outlive
the call that was handed the block: the caller's ``block`` argument keeps it alive for the
whole call, and what an entry returns is copied out of the tree
(:func:`~xfuzzy_rrt.planners.result.finish_tree_run`;
tests/test_results_outlive_the_pooled_trees.py checks that no result shares memory with a
pooled tree and that the next plan leaves it as it was). Python code has the owning views in
:attr:`TreeArena.tree`.
"""

from __future__ import annotations

from typing import NamedTuple

import numba as nb
import numpy as np
from numba.core import types
from numba.extending import intrinsic

from xfuzzy_rrt.planners.tree import TreeArrays, make_tree, reset_tree

#: dtype and number of dimensions of each :class:`TreeArrays` field, in order; what
#: :func:`tree_in` rebuilds (``make_tree_arena`` refuses a tree that differs).
FIELD_KINDS = (
    (np.float64, 2), (np.int64, 1), (np.int64, 1), (np.int64, 1), (np.int64, 1),
    (np.float64, 1), (np.int64, 1), (np.int64, 1), (np.int64, 2), (np.float64, 1),
    (np.float64, 2), (np.float64, 1), (np.float64, 2), (np.uint64, 1), (np.float64, 2),
    (np.float64, 1), (np.float64, 2),
)
#: Row of ``layout`` holding the empty tree's ``meta`` (after the tree's own fields).
META0 = len(FIELD_KINDS)
_ALIGN = 64


class TreeArena(NamedTuple):
    """A tree whose arrays are views into ``block`` (``layout[k] = offset, nbytes, rows,
    cols``; ``cols`` 0 for a 1-D field; row :data:`META0` holds the empty tree's ``meta``)."""

    tree: TreeArrays
    block: np.ndarray
    layout: np.ndarray


def make_tree_arena(capacity: int, limits_deg: np.ndarray, stops: int = 0) -> TreeArena:
    """:func:`~xfuzzy_rrt.planners.tree.make_tree`'s empty tree, moved into one block."""
    fresh = make_tree(capacity, limits_deg, stops=stops)
    parts = list(fresh) + [fresh.meta.copy()]
    for name, arr, (dtype, ndim) in zip(TreeArrays._fields, fresh, FIELD_KINDS):
        if arr.dtype != dtype or arr.ndim != ndim:
            raise TypeError(f"tree field {name} is {arr.dtype}[{arr.ndim}-D]; the arena "
                            f"expects {np.dtype(dtype)}[{ndim}-D] (FIELD_KINDS)")
    block, layout, views = packed(parts)
    return TreeArena(TreeArrays(*views[:META0]), block, layout)


def packed(parts) -> tuple[np.ndarray, np.ndarray, list[np.ndarray]]:
    """``(block, layout, views)``: the 1-D or 2-D arrays *parts* copied into one ``uint8``
    block, each at a 64-byte boundary, ``layout[k] = offset, nbytes, rows, cols`` (``cols`` 0
    for a 1-D part), and the views of the block that hold them (what :func:`tree_in` and
    :func:`~xfuzzy_rrt.planners.problem_arena.problem_in` rebuild in compiled code)."""
    layout = np.zeros((len(parts), 4), dtype=np.int64)
    offset = 0
    for k, arr in enumerate(parts):
        layout[k] = (offset, arr.nbytes, arr.shape[0], arr.shape[1] if arr.ndim == 2 else 0)
        offset += -(-arr.nbytes // _ALIGN) * _ALIGN
    block = np.empty(offset + _ALIGN, dtype=np.uint8)
    # numpy aligns allocations to 16 bytes; start at the block's first 64-byte boundary
    shift = (-block.ctypes.data) % _ALIGN
    layout[:, 0] += shift
    views = []
    for k, arr in enumerate(parts):
        o, n = int(layout[k, 0]), int(layout[k, 1])
        view = block[o:o + n].view(arr.dtype).reshape(arr.shape)
        view[...] = arr
        views.append(view)
    return block, layout, views


@intrinsic
def pointer_at(typingctx, address):
    """The integer ``address`` (a buffer's ``ctypes.data``, the buffer held by the caller) as a
    ``void*``, what ``numba.carray`` takes (also the OMPL bridge's callbacks' buffers)."""
    if not isinstance(address, types.Integer):
        return None

    def codegen(context, builder, signature, args):
        return builder.inttoptr(args[0], context.get_value_type(types.voidptr))

    return types.voidptr(address), codegen


@nb.njit(cache=True, nogil=True, inline="always")
def borrowed_1d(b, L, k, dtype):
    """Field ``k`` of block ``b`` as a 1-D ``dtype`` array of ``L[k, 2]`` items that borrows
    the block (no owner: see the module docstring; valid only while the caller holds ``b``)."""
    return nb.carray(pointer_at(b.ctypes.data + L[k, 0]), L[k, 2], dtype)


@nb.njit(cache=True, nogil=True, inline="always")
def borrowed_2d(b, L, k, dtype):
    """Field ``k`` of block ``b`` as a 2-D ``dtype`` array of ``L[k, 2]`` rows and ``L[k, 3]``
    columns that borrows the block (see :func:`borrowed_1d`)."""
    return nb.carray(pointer_at(b.ctypes.data + L[k, 0]), (L[k, 2], L[k, 3]), dtype)


@nb.njit(cache=True, nogil=True, _nrt=True)
def tree_in(block, layout):
    """The :class:`TreeArrays` whose arrays are ``block``'s fields, borrowed (no copy, no
    owner): for compiled callers, while they hold ``block`` (Python has
    :attr:`TreeArena.tree`)."""
    f8, i8, L, b = np.float64, np.int64, layout, block
    return TreeArrays(
        borrowed_2d(b, L, 0, f8), borrowed_1d(b, L, 1, i8), borrowed_1d(b, L, 2, i8),
        borrowed_1d(b, L, 3, i8), borrowed_1d(b, L, 4, i8), borrowed_1d(b, L, 5, f8),
        borrowed_1d(b, L, 6, i8), borrowed_1d(b, L, 7, i8), borrowed_2d(b, L, 8, i8),
        borrowed_1d(b, L, 9, f8), borrowed_2d(b, L, 10, f8), borrowed_1d(b, L, 11, f8),
        borrowed_2d(b, L, 12, f8), borrowed_1d(b, L, 13, np.uint64), borrowed_2d(b, L, 14, f8),
        borrowed_1d(b, L, 15, f8), borrowed_2d(b, L, 16, f8))


@nb.njit(cache=True, nogil=True, _nrt=True)
def emptied_tree_in(block, layout):
    """:func:`tree_in`, emptied for a new run (:func:`~xfuzzy_rrt.planners.tree.reset_tree`
    with the block's own ``meta0``)."""
    T = tree_in(block, layout)
    reset_tree(T, borrowed_1d(block, layout, META0, np.int64))
    return T
