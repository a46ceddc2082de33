"""Set-up a plan call reuses instead of rebuilding: a scenario's arrays and the tree.

Why: on a 2-DOF problem the planner's kernel often runs for 0.1-0.5 ms, and building its inputs
from scratch (a scenario's arrays from the TOML model, a 10,000-node tree, thirteen trace
buffers that are never written when not tracing) cost as much again. Everything here is an
exact stand-in for the fresh object: the arrays are the same numbers, the tree is emptied by
the compiled entry before every use (:func:`~xfuzzy_rrt.planners.tree_arena.emptied_tree_in`,
:func:`~xfuzzy_rrt.planners.tree.reset_tree`'s state). (An untraced run takes no trace
buffers at all: :mod:`~xfuzzy_rrt.planners.trace_record`.)
Trees are per thread, so concurrent plans never share one.
"""

from __future__ import annotations

import threading
import weakref
from collections import OrderedDict

import numpy as np

from xfuzzy_rrt.planners.tree_arena import TreeArena, make_tree_arena

#: Trees (or pairs of trees) kept per thread (each up to ``capacity x dof`` floats: 0.6 MB at
#: 10,000 x 7).
_TREES_PER_THREAD = 4
_local = threading.local()
_arrays: dict[int, tuple] = {}


def scenario_arrays(scenario):
    """``scenario.arrays()``, built once per scenario object (scenarios are frozen)."""
    key = id(scenario)
    hit = _arrays.get(key)
    if hit is not None and hit[0]() is scenario:
        return hit[1]
    arrays = scenario.arrays()
    try:
        ref = weakref.ref(scenario, lambda _r, k=key: _arrays.pop(k, None))
    except TypeError:  # not weak-referenceable: no caching
        return arrays
    _arrays[key] = (ref, arrays)
    return arrays


def pooled_tree(capacity: int, limits_deg: np.ndarray, stops: int = 0) -> TreeArena:
    """A tree for ``capacity`` nodes in ``limits_deg`` in one block (:mod:`.tree_arena`), with
    stop records of ``stops`` columns (:func:`~xfuzzy_rrt.planners.tree.make_tree`), reused
    within this thread from one plan to the next (a result keeps copies, never the tree's
    arrays), *not* emptied: the compiled entries empty it
    (:func:`~xfuzzy_rrt.planners.tree_arena.emptied_tree_in`)."""
    return pooled_trees(capacity, limits_deg, 1, stops)[0]


def pooled_trees(capacity: int, limits_deg: np.ndarray, count: int,
                 stops: int = 0) -> tuple[TreeArena, ...]:
    """``count`` distinct trees as :func:`pooled_tree` gives one (Fuzzy-RRT-Connect's start and
    goal trees: ``count=2``), kept as one pool entry and found with one look-up.

    The look-up is by the limits array's identity first: every plan of a scenario passes the
    same array (:func:`scenario_arrays`), and hashing its bytes, ``asarray`` and the LRU's
    bookkeeping cost ~19 us of a call that starts with cold caches (27.5 against 8.6 us;
    docs/peer-measurements.md, twelfth session), for every planner. The entry keeps the
    array, so its identity cannot be taken by another array while it is remembered; like the
    set-ups that hold the same arrays (:mod:`.setup_memo`), it relies on nobody writing into a
    scenario's arrays."""
    by_id = getattr(_local, "by_id", None)
    if by_id is None:
        by_id = _local.by_id = {}
    id_key = (capacity, id(limits_deg), count, stops)
    hit = by_id.get(id_key)
    if hit is not None and hit[0] is limits_deg:
        return hit[1]
    trees = _pooled_by_value(capacity, limits_deg, count, stops)
    if len(by_id) >= _IDENTITIES_PER_THREAD:
        by_id.clear()
    by_id[id_key] = (limits_deg, trees)
    return trees


#: Identity look-ups kept per thread (each holds a pooled entry and a limits array alive).
_IDENTITIES_PER_THREAD = 8


def _pooled_by_value(capacity: int, limits_deg: np.ndarray, count: int,
                     stops: int) -> tuple[TreeArena, ...]:
    """The pool proper, keyed by the limits' values (LRU of :data:`_TREES_PER_THREAD`)."""
    limits = np.asarray(limits_deg, dtype=np.float64)
    key = (int(capacity), limits.shape, limits.tobytes(), int(count), int(stops))
    pool = getattr(_local, "trees", None)
    if pool is None:
        pool = _local.trees = OrderedDict()
    hit = pool.get(key)
    if hit is None:
        hit = pool[key] = tuple(make_tree_arena(int(capacity), limits, int(stops))
                                for _ in range(count))
        while len(pool) > _TREES_PER_THREAD:
            pool.popitem(last=False)
            # the identity look-ups may name the evicted trees: forget them all, so that no
            # more than the pool's trees are ever kept alive
            getattr(_local, "by_id", {}).clear()
        return hit
    pool.move_to_end(key)
    return hit

