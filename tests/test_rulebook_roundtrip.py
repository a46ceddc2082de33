"""Rulebooks round-trip exactly: load -> save gives identical bytes, floats survive exactly."""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from xfuzzy_rrt.errors import RulebookError
from xfuzzy_rrt.fuzzy import rulebook as rbmod
from xfuzzy_rrt.fuzzy.manifest import MANIFEST_NAME
from xfuzzy_rrt.fuzzy.rulebook import (
    Rulebook,
    default_rulebook_path,
    list_rulebooks,
    load_rulebook,
    save_rulebook,
)
from xfuzzy_rrt.fuzzy.variables import OUTPUTS

from _rulebook_helpers import copy_expert, random_arrays, random_rulebook

SHIPPED = list_rulebooks()


def _files(root: Path) -> dict[str, bytes]:
    """The rulebook's own files (a trained rulebook also keeps its history.csv beside them)."""
    return {p.name: p.read_bytes() for p in sorted(root.iterdir())
            if p.is_file() and (p.name == MANIFEST_NAME or p.suffix == ".fis")}


def test_the_default_rulebook_is_shipped():
    assert default_rulebook_path() in SHIPPED
    assert (default_rulebook_path() / MANIFEST_NAME).is_file()


@pytest.mark.parametrize("path", SHIPPED, ids=[p.name for p in SHIPPED])
def test_every_shipped_rulebook_saves_back_to_identical_bytes(path, tmp_path):
    rb = load_rulebook(path)
    save_rulebook(rb, tmp_path / "copy")
    assert _files(tmp_path / "copy") == _files(path)
    assert load_rulebook(tmp_path / "copy") == rb


def test_sha256_is_over_the_canonical_file_bytes(tmp_path):
    rb = load_rulebook(default_rulebook_path())
    import hashlib

    h = hashlib.sha256()
    for name in [MANIFEST_NAME] + [f"{o}.fis" for o in rb.outputs]:
        data = (default_rulebook_path() / name).read_bytes()
        h.update(f"{name}\n{len(data)}\n".encode())
        h.update(data)
    assert rb.sha256 == h.hexdigest()


def test_comments_do_not_change_identity_but_numbers_do(tmp_path):
    root = copy_expert(tmp_path)
    rb = load_rulebook(root)
    fis = root / "step_size.fis"
    fis.write_text(fis.read_text().replace("end\n", "# my note\nend\n"))
    assert load_rulebook(root).sha256 == rb.sha256
    fis.write_text(fis.read_text().replace("step_size = 10.0\n# my note", "step_size = 9.0\n# my note"))
    assert load_rulebook(root).sha256 != rb.sha256


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1))
def test_random_arrays_survive_text_exactly(seed, tmp_path_factory):
    rng = np.random.default_rng(seed)
    knots, consts = random_arrays(rng)
    # include awkward floats: subnormal-ish tiny, -0.0, range ends
    consts[0, :4] = [0.0, 1.0, 5e-324, 0.1 + 0.2]
    consts[1, :3] = [-0.0, -180.0, 180.0]
    rb = Rulebook.from_arrays(knots, consts, name="r", bounds_mode="absolute",
                              provenance={"kind": "test", "seed": seed, "fitness": 9750.5,
                                          "scenarios": ["a.toml", "b \"q\".toml"]})
    out = tmp_path_factory.mktemp("rt")
    save_rulebook(rb, out)
    back = load_rulebook(out)
    k2, c2 = back.arrays()
    assert np.array_equal(k2, knots) and np.array_equal(c2, consts)
    assert np.array_equal(np.signbit(c2), np.signbit(consts))
    assert back.sha256 == rb.sha256
    before = _files(out)
    save_rulebook(back, out)
    assert _files(out) == before


def test_arrays_are_fresh_contiguous_float64_copies():
    rb = load_rulebook(default_rulebook_path())
    k1, c1 = rb.arrays()
    assert k1.shape == (6, 4, 5) and c1.shape == (6, 625)
    assert k1.dtype == np.float64 and k1.flags.c_contiguous and c1.flags.c_contiguous
    k1[:] = 0
    assert rb.arrays()[0][0, 0, 1] != 0


def test_from_arrays_rejects_invalid_values():
    knots, consts = random_arrays(np.random.default_rng(0))
    bad = consts.copy()
    bad[5, 3] = 11.0
    with pytest.raises(ValueError, match="step_size"):
        Rulebook.from_arrays(knots, bad, name="x", bounds_mode="absolute", provenance={"kind": "t"})
    bad = knots.copy()
    bad[0, 1, 2] = bad[0, 1, 1]
    with pytest.raises(ValueError, match="strictly increasing"):
        Rulebook.from_arrays(bad, consts, name="x", bounds_mode="absolute", provenance={"kind": "t"})
    with pytest.raises(ValueError, match="bounds_mode"):
        Rulebook.from_arrays(knots, consts, name="x", bounds_mode="sideways", provenance={"kind": "t"})
    with pytest.raises(ValueError):
        Rulebook.from_arrays(knots[:5], consts, name="x", bounds_mode="absolute")


def test_rulebook_is_frozen():
    rb = random_rulebook(np.random.default_rng(1))
    with pytest.raises(Exception):
        rb.name = "other"
    with pytest.raises(TypeError):
        rb.provenance["kind"] = "other"


def test_missing_directory_raises_rulebook_error(tmp_path):
    with pytest.raises(RulebookError) as info:
        load_rulebook(tmp_path / "nope")
    assert info.value.problems[0][0].endswith("nope")


def test_save_leaves_no_partial_files_on_failure(tmp_path, monkeypatch):
    rb = random_rulebook(np.random.default_rng(2))
    calls = {"n": 0}
    real_fdopen = os.fdopen

    def flaky_fdopen(*a, **kw):
        calls["n"] += 1
        if calls["n"] == 4:
            raise OSError("disk full")
        return real_fdopen(*a, **kw)

    monkeypatch.setattr(rbmod.os, "fdopen", flaky_fdopen)
    with pytest.raises(OSError):
        save_rulebook(rb, tmp_path / "out")
    assert list((tmp_path / "out").iterdir()) == []


def test_save_keeps_unrelated_files(tmp_path):
    root = tmp_path / "trained"
    root.mkdir()
    (root / "history.csv").write_text("generation\n")
    save_rulebook(random_rulebook(np.random.default_rng(3)), root)
    assert (root / "history.csv").read_text() == "generation\n"


def test_env_var_overrides_the_rulebooks_folder(tmp_path, monkeypatch):
    from xfuzzy_rrt.fuzzy.rulebook import DEFAULT_RULEBOOK

    copy_expert(tmp_path, DEFAULT_RULEBOOK)
    copy_expert(tmp_path, "other")
    monkeypatch.setenv("XFUZZY_RRT_RULEBOOKS", str(tmp_path))
    assert default_rulebook_path() == tmp_path / DEFAULT_RULEBOOK
    assert [p.name for p in list_rulebooks()] == sorted([DEFAULT_RULEBOOK, "other"])
