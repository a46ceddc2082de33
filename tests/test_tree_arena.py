"""A tree in one block (planners/tree_arena.py): the same arrays as make_tree's, seen by
compiled code exactly as separate arrays were, and emptied by the compiled entries."""

import numba as nb
import numpy as np
import pytest

from xfuzzy_rrt.planners import tree_arena
from xfuzzy_rrt.planners.tree import TreeArrays, add_node, make_tree
from xfuzzy_rrt.planners.tree_arena import emptied_tree_in, make_tree_arena, tree_in


def _limits(dof):
    return np.array([[-180.0, 180.0]] * dof)


@pytest.mark.parametrize("dof", [2, 3, 7])
def test_an_arena_tree_has_make_trees_fields_shapes_and_initial_values(dof):
    fresh = make_tree(500, _limits(dof))
    arena = make_tree_arena(500, _limits(dof))
    for name, got, want in zip(TreeArrays._fields, arena.tree, fresh):
        assert got.shape == want.shape and got.dtype == want.dtype, name
        assert got.flags.c_contiguous and got.flags.aligned, name
        assert np.shares_memory(got, arena.block), name
    for name in ("cell_head", "meta", "grid", "link_clear", "occ", "kd_stack", "mks"):
        np.testing.assert_array_equal(getattr(arena.tree, name), getattr(fresh, name),
                                      err_msg=name)
    o, n = arena.layout[tree_arena.META0, :2]
    meta0 = arena.block[o:o + n].view(np.int64)
    np.testing.assert_array_equal(meta0, fresh.meta)


@pytest.mark.parametrize("dof", [2, 5])
def test_compiled_code_sees_the_arena_fields_with_the_types_of_separate_arrays(dof):
    arena = make_tree_arena(300, _limits(dof))
    inside = tree_in(arena.block, arena.layout)
    for name, a, b in zip(TreeArrays._fields, inside, arena.tree):
        assert a.ctypes.data == b.ctypes.data and a.shape == b.shape, name
    # the kernels keep one specialisation: the rebuilt record types as make_tree's does
    compiled = [sig.return_type for sig in tree_in.nopython_signatures
                if sig.args[1] == nb.typeof(arena.layout)]
    assert nb.typeof(make_tree(300, _limits(dof))) in compiled


@pytest.mark.parametrize("spread", [0.0, 5.0, 60.0, 400.0])
@pytest.mark.parametrize("dof", [2, 3])
def test_the_compiled_entries_empty_a_used_tree(dof, spread):
    """However many cells a run filled (one; a corner of the grid; all of it, nodes beyond the
    limits clamped into the edge cells), the emptied tree is a new tree: every grid cell and
    occupied bit cleared, run after run of the same pooled tree."""
    rng = np.random.default_rng(int(spread) + dof)
    arena = make_tree_arena(400, _limits(dof))
    fresh = make_tree(400, _limits(dof))
    for _ in range(3):  # runs of the same pooled tree, emptied between them
        centre = rng.uniform(-180.0, 180.0, dof)
        for i in range(int(rng.integers(1, 400))):
            add_node(arena.tree, centre + rng.uniform(-spread, spread, dof), i - 1)
        if dof == 2 and spread > 0.0:
            assert (arena.tree.cell_head >= 0).sum() > 1 and arena.tree.occ.any()
        emptied_tree_in(arena.block, arena.layout)
        for name in ("meta", "cell_head", "occ"):
            np.testing.assert_array_equal(getattr(arena.tree, name), getattr(fresh, name),
                                          err_msg=name)


def test_an_arena_refuses_a_tree_whose_fields_changed_kind(monkeypatch):
    def changed(capacity, limits, stops=0):
        tree = make_tree(capacity, limits, stops=stops)
        return tree._replace(parent=tree.parent.astype(np.int32))

    monkeypatch.setattr(tree_arena, "make_tree", changed)
    with pytest.raises(TypeError, match="tree field parent is int32"):
        make_tree_arena(100, _limits(3))


@pytest.mark.parametrize("width", [8.0, 700.0])
def test_a_grid_of_one_cell_or_without_occupancy_words_is_emptied_too(width):
    """Joint limits narrower than a grid cell give a 2-joint grid of one cell, and limits wider
    than 640 degrees a grid with no occupancy words: a reused tree must still come back empty
    (a stale cell head made the next run's nearest-node search loop forever)."""
    limits = np.array([[0.0, width]] * 2)
    rng = np.random.default_rng(7)
    arena = make_tree_arena(300, limits)
    fresh = make_tree(300, limits)
    for _ in range(2):
        for i in range(int(rng.integers(150, 300))):
            add_node(arena.tree, rng.uniform(0.0, width, 2), i - 1)
        assert (arena.tree.cell_head >= 0).any()
        emptied_tree_in(arena.block, arena.layout)
        for name in ("meta", "cell_head", "occ"):
            np.testing.assert_array_equal(getattr(arena.tree, name), getattr(fresh, name),
                                          err_msg=name)
