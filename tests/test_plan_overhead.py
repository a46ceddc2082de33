"""What a plan call does around its kernel: nothing twice, the clearance only when asked, the
rulebook re-read only when its files changed (issue 24). Speed itself is measured in
benchmarks/overhead.py, never asserted here."""

from __future__ import annotations

import os
import pickle
import re
import shutil
import time

import numpy as np
import pytest

import xfuzzy_rrt.fuzzy.rulebook as rbmod
import xfuzzy_rrt.geometry.path_check as path_check
from xfuzzy_rrt.geometry.path_check import certify_path
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.api import plan_scenario
from xfuzzy_rrt.planners.result import replace_result
from xfuzzy_rrt.resources import demo_scenarios


@pytest.fixture(scope="module")
def scenarios():
    return [load_scenario(p) for p in demo_scenarios()]


def _count_measurements(monkeypatch):
    calls = []
    real = path_check.path_min_clearance
    monkeypatch.setattr(path_check, "path_min_clearance",
                        lambda *a: calls.append(1) or real(*a))
    return calls


@pytest.mark.parametrize("planner", ["fuzzy-rrt", "rrt"])
def test_the_exact_clearance_is_measured_only_when_asked_and_equals_the_eager_check(
        scenarios, planner, monkeypatch):
    calls = _count_measurements(monkeypatch)
    for s in scenarios:
        r = plan_scenario(s, planner, seed=4)
        if not r.success:
            continue
        assert calls == []  # planning and certifying did not measure it
        check = certify_path(s.arrays(), r.path_deg, r.params["margin_m"])
        assert check.certified and r.certified and r.violation is None
        assert r.to_json_dict()["min_clearance_m"] == check.min_clearance_m
        assert r.penetration_m == check.penetration_m == 0.0
        assert len(calls) == 1
        _ = r.min_clearance_m  # kept, not measured again
        assert len(calls) == 1
        calls.clear()


def test_a_copied_or_pickled_result_still_measures_the_same_clearance(scenarios, monkeypatch):
    s = scenarios[0]
    r = plan_scenario(s, "rrt", seed=2)
    assert r.success
    blob = pickle.dumps(r)
    calls = _count_measurements(monkeypatch)
    renamed = replace_result(r, planner="rrt:renamed")
    thawed = pickle.loads(blob)
    assert calls == []
    expected = certify_path(s.arrays(), r.path_deg, r.params["margin_m"]).min_clearance_m
    assert renamed.planner == "rrt:renamed"
    assert renamed.min_clearance_m == thawed.min_clearance_m == r.min_clearance_m == expected


def test_a_plan_repeated_after_other_plans_is_identical(scenarios):
    # trees and buffers are reused between calls: nothing of one plan may leak into the next
    first = plan_scenario(scenarios[0], "fuzzy-rrt", seed=7)
    for s in scenarios[1:]:
        plan_scenario(s, "fuzzy-rrt", seed=1)
        plan_scenario(s, "rrt", seed=1)
    again = plan_scenario(scenarios[0], "fuzzy-rrt", seed=7)
    assert again.iterations == first.iterations and again.nodes == first.nodes
    assert np.array_equal(again.path_deg, first.path_deg)
    assert np.array_equal(again.tree_nodes_deg, first.tree_nodes_deg)
    assert np.array_equal(again.tree_parent, first.tree_parent)


@pytest.fixture()
def rulebook_copy(tmp_path, monkeypatch):
    """A copy of the shipped default with old timestamps and no racy window (so the stat key
    alone decides), and a counter of how often its bytes are hashed."""
    root = tmp_path / "rb"
    shutil.copytree(rbmod.default_rulebook_path(), root)
    old = time.time_ns() - 3600 * 10**9
    for p in [root, *root.iterdir()]:
        os.utime(p, ns=(old, old))
    monkeypatch.setattr(rbmod, "RACY_WINDOW_NS", 0)
    hashed = []
    real = rbmod._content_key
    monkeypatch.setattr(rbmod, "_content_key", lambda r: hashed.append(r) or real(r))
    return root, hashed


def _edit_same_size(fis):
    text = fis.read_text()
    m = re.search(r"then \w+ = (\S+)\n", text)
    old = m.group(1)
    new = old[:-1] + ("1" if old[-1] != "1" else "2")
    edited = text[:m.start(1)] + new + text[m.end(1):]
    assert edited != text and len(edited) == len(text)
    return edited


def test_an_unchanged_rulebook_directory_is_neither_reread_nor_rehashed(rulebook_copy):
    root, hashed = rulebook_copy
    first = rbmod.load_rulebook_cached(root)
    assert len(hashed) == 1
    assert rbmod.load_rulebook_cached(root) is first
    assert rbmod.load_rulebook_cached(str(root)) is first
    assert len(hashed) == 1


def test_a_same_size_edit_with_the_mtime_put_back_is_seen_by_its_ctime(rulebook_copy):
    root, hashed = rulebook_copy
    before = rbmod.load_rulebook_cached(root)
    fis = sorted(root.glob("*.fis"))[0]
    st = fis.stat()
    time.sleep(0.05)  # past the file system's timestamp tick, so the new ctime differs
    edited = _edit_same_size(fis)
    fis.write_text(edited)
    os.utime(fis, ns=(st.st_atime_ns, st.st_mtime_ns))
    after_stat = fis.stat()
    assert (after_stat.st_size, after_stat.st_mtime_ns, after_stat.st_ino) == \
        (st.st_size, st.st_mtime_ns, st.st_ino)
    after = rbmod.load_rulebook_cached(root)
    assert len(hashed) == 2
    assert after is not before and after.sha256 == rbmod.load_rulebook(root).sha256
    assert after.sha256 != before.sha256


def test_a_file_added_to_the_rulebook_directory_is_seen(rulebook_copy):
    root, hashed = rulebook_copy
    rbmod.load_rulebook_cached(root)
    time.sleep(0.05)
    (root / "notes.txt").write_text("a new file\n")
    rbmod.load_rulebook_cached(root)
    assert len(hashed) == 2


def test_a_freshly_written_rulebook_is_rehashed_until_its_stamps_can_be_trusted(
        tmp_path, monkeypatch):
    # an edit within the same timestamp tick as the last look-up cannot show in the stamps
    root = tmp_path / "rb"
    shutil.copytree(rbmod.default_rulebook_path(), root)
    hashed = []
    real = rbmod._content_key
    monkeypatch.setattr(rbmod, "_content_key", lambda r: hashed.append(r) or real(r))
    rbmod.load_rulebook_cached(root)
    rbmod.load_rulebook_cached(root)
    assert len(hashed) == 2
