"""A tree in one block (planners/tree_arena.py): the same arrays as make_tree's, seen by
compiled code exactly as separate arrays were, and emptied by the compiled entries."""

import numba as nb
import numpy as np
import pytest

from xfuzzy_rrt.planners import tree_arena
from xfuzzy_rrt.planners.tree import TreeArrays, make_tree
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


def test_the_compiled_entries_empty_a_used_tree():
    arena = make_tree_arena(200, _limits(2))
    arena.tree.meta[:] = 7
    arena.tree.cell_head[:] = 3
    arena.tree.occ[:] = 1
    emptied_tree_in(arena.block, arena.layout)
    fresh = make_tree(200, _limits(2))
    np.testing.assert_array_equal(arena.tree.meta, fresh.meta)
    np.testing.assert_array_equal(arena.tree.cell_head, fresh.cell_head)
    np.testing.assert_array_equal(arena.tree.occ, fresh.occ)


def test_an_arena_refuses_a_tree_whose_fields_changed_kind(monkeypatch):
    def changed(capacity, limits, stops=0):
        tree = make_tree(capacity, limits, stops=stops)
        return tree._replace(parent=tree.parent.astype(np.int32))

    monkeypatch.setattr(tree_arena, "make_tree", changed)
    with pytest.raises(TypeError, match="tree field parent is int32"):
        make_tree_arena(100, _limits(3))
