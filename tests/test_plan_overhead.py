"""What a plan call does around its kernel: nothing twice, the clearance only when asked, the
rulebook re-read only when its files changed (issue 24). Speed itself is measured in
benchmarks/overhead.py, never asserted here."""

from __future__ import annotations

import dataclasses
import math
import os
import pickle
import re
import shutil
import time

import numpy as np
import pytest

import xfuzzy_rrt.fuzzy.rulebook as rbmod
import xfuzzy_rrt.fuzzy.watch as watchmod
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.planners import setup_memo
from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt
from xfuzzy_rrt.planners.result import (
    _PENDING,
    PlanResult,
    _certified,
    finish_tree_run,
    path_cost_compiled,
    path_cost_deg,
)
import xfuzzy_rrt.geometry.path_check as path_check
from xfuzzy_rrt.geometry.path_check import certify_path
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.api import plan_scenario
from xfuzzy_rrt.planners.rrt import plan_rrt
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


@pytest.fixture(params=["kernel-watch", "stamps-only"])
def rulebook_copy(request, tmp_path, monkeypatch):
    """A copy of the shipped default with old timestamps and no racy window, and a counter of
    how often its bytes are hashed; once with kernel change notices (inotify, where this system
    has them) and once with the stat key alone deciding."""
    monkeypatch.setattr(watchmod, "ENABLED", request.param == "kernel-watch")
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
    # (without kernel notices: with them nothing is racy, tests/test_rulebook_watch.py)
    monkeypatch.setattr(watchmod, "ENABLED", False)
    root = tmp_path / "rb"
    shutil.copytree(rbmod.default_rulebook_path(), root)
    hashed = []
    real = rbmod._content_key
    monkeypatch.setattr(rbmod, "_content_key", lambda r: hashed.append(r) or real(r))
    rbmod.load_rulebook_cached(root)
    rbmod.load_rulebook_cached(root)
    assert len(hashed) == 2


# --- the compiled finish of a tree planner's run, and the fast result -----------------------



def test_the_compiled_path_cost_is_numpys_float_bit_for_bit():
    # NumPy sums pairwise (8 running sums up to 128 terms, halves beyond): a plain loop
    # differs in the last bits, which golden files would catch one plan at a time
    rng = np.random.default_rng(5)
    for dof in (1, 2, 3, 5, 7, 8, 9, 14, 16, 17, 28):
        for k in (*range(0, 20), 63, 64, 65, 127, 128, 129, 130, 300, 1031, 4099):
            path = rng.uniform(-180.0, 180.0, (k, dof)) * rng.choice([1e-3, 1.0, 1e3])
            assert path_cost_compiled(path) == path_cost_deg(path), (dof, k)


def test_finishing_a_run_copies_the_tree_and_flags_a_vertex_beyond_the_limits():
    nodes = np.array([[0.0, 0.0], [10.0, 5.0], [20.0, 30.0], [9.0, 9.0]])
    parent = np.array([-1, 0, 1, 0], dtype=np.int64)
    limits = np.array([[-180.0, 180.0], [-180.0, 180.0]])
    tn, tp, path, cost, within = finish_tree_run(nodes, parent, 3, 2, limits)
    assert np.array_equal(path, nodes[:3]) and within and cost == path_cost_deg(nodes[:3])
    assert np.array_equal(tn, nodes[:3]) and np.array_equal(tp, parent[:3])
    tn[0, 0] = 99.0  # copies: the tree is reused by the next plan
    assert nodes[0, 0] == 0.0
    tight = np.array([[-180.0, 180.0], [-180.0, 29.0]])
    assert not finish_tree_run(nodes, parent, 3, 2, tight)[4]
    nodes[1, 0] = np.nan
    assert not finish_tree_run(nodes, parent, 3, 2, limits)[4]
    none = finish_tree_run(nodes, parent, 4, -1, limits)
    assert none[2].shape == (0, 2) and not none[4]


def test_the_fast_certified_result_is_the_dataclass_one_field_for_field():
    p = np.zeros((3, 2))
    fields = dict(scenario="s", planner="fuzzy-rrt", planner_used="fuzzy-rrt", seed=3,
                  iterations=5, nodes=4, cost_deg=1.5, wall_s=0.1, path_deg=p, tree_nodes_deg=p,
                  tree_parent=np.zeros(3, dtype=np.int64), work=7, rulebook="goal-frame",
                  rulebook_sha256="ab", params={"max_iter": 10})
    fast = _certified(dict(fields))
    slow = PlanResult(found=True, certified=True, min_clearance_m=_PENDING,
                      penetration_m=_PENDING, violation=None, **fields)
    assert type(fast) is PlanResult
    assert fast.__dict__.keys() == slow.__dict__.keys()
    for k, v in slow.__dict__.items():
        assert fast.__dict__[k] is v or fast.__dict__[k] == v, k
    assert fast.success and fast.certify_work == 0 and fast.trace is None
    with pytest.raises(dataclasses.FrozenInstanceError):
        fast.seed = 4
    # a field the fast path does not take goes through __init__ (and its checks)
    with pytest.raises(TypeError):
        _certified({**fields, "found": False})


@pytest.fixture()
def fresh_memo():
    setup_memo.clear()
    yield
    setup_memo.clear()


def test_a_remembered_set_up_never_hides_an_error_or_a_different_setting(scenarios, fresh_memo):
    s = scenarios[0]
    good = plan_fuzzy_rrt(s, seed=1, max_iter=500)
    for _ in range(2):  # errors are never remembered: the same line every time
        with pytest.raises(InputError, match="must be an integer"):
            plan_fuzzy_rrt(s, seed=1, max_iter=500.0)
        with pytest.raises(InputError, match="must be an integer"):
            plan_rrt(s, seed=1, max_iter=True)
    # equal in Python, not to the checks: True is not 1, -0.0 is not 0.0
    plan_rrt(s, seed=1, max_iter=1)
    with pytest.raises(InputError):
        plan_rrt(s, seed=1, max_iter=True)
    plus = plan_rrt(s, seed=1, margin=0.0)
    minus = plan_rrt(s, seed=1, margin=-0.0)
    assert math.copysign(1, plus.params["margin_m"]) == 1.0
    assert math.copysign(1, minus.params["margin_m"]) == -1.0
    again = plan_fuzzy_rrt(s, seed=1, max_iter=500)
    assert again.iterations == good.iterations and again.params == good.params


def test_a_remembered_set_up_follows_an_edited_rulebook_and_a_new_scenario_object(
        scenarios, rulebook_copy, fresh_memo):
    root, _hashed = rulebook_copy
    s = scenarios[0]
    first = plan_fuzzy_rrt(s, root, seed=2)
    assert plan_fuzzy_rrt(s, root, seed=2).rulebook_sha256 == first.rulebook_sha256
    fis = sorted(root.glob("*.fis"))[0]
    time.sleep(0.05)
    fis.write_text(_edit_same_size(fis))
    edited = plan_fuzzy_rrt(s, root, seed=2)
    assert edited.rulebook_sha256 != first.rulebook_sha256
    assert edited.rulebook_sha256 == rbmod.load_rulebook(root).sha256
    # a different (equal) scenario object is checked afresh, not matched by a recycled id
    copy = dataclasses.replace(s, clearance_m=s.clearance_m)
    key_count = len(setup_memo._memo)
    plan_fuzzy_rrt(copy, root, seed=2)
    assert len(setup_memo._memo) == key_count + 1
    assert setup_memo.lookup(("no such key",), s) is None


def test_relabelling_a_result_copies_every_field_and_keeps_the_measurement_pending(
        scenarios, monkeypatch):
    calls = _count_measurements(monkeypatch)
    r = plan_scenario(scenarios[0], "rrt", seed=2)
    assert r.success and calls == []
    fast = replace_result(r, planner="rrt:tuned", planner_used="rrt:tuned",
                          params={**r.params, "tuned": True})
    assert calls == [] and fast.__dict__["_min_clearance_m"] is _PENDING
    slow = dataclasses.replace(r, planner="rrt:tuned", planner_used="rrt:tuned",
                               params={**r.params, "tuned": True})  # measures r, eagerly
    assert len(calls) == 1 and type(fast) is PlanResult and fast.planner == "rrt:tuned"
    for f in dataclasses.fields(PlanResult):
        a, b = getattr(fast, f.name), getattr(slow, f.name)
        assert a is b or np.array_equal(a, b) or a == b, f.name
    assert len(calls) == 2  # the copy measured once, on its own
    assert fast.params["tuned"] and "tuned" not in r.params
    with pytest.raises(ValueError):  # anything else still goes through __init__'s checks
        replace_result(r, found=False)


def _random_tree(rng, n, dof):
    nodes = rng.uniform(-180.0, 180.0, (n, dof))
    parent = np.array([-1] + [int(rng.integers(0, i)) for i in range(1, n)], dtype=np.int64)
    return nodes, parent


def _path_to(nodes, parent, last):
    rows = []
    while last >= 0:
        rows.append(nodes[last])
        last = parent[last]
    return np.array(rows[::-1])


def test_finishing_a_connect_run_joins_both_trees_as_numpy_would():
    from xfuzzy_rrt.planners.connect import finish_connect_run

    rng = np.random.default_rng(11)
    limits = np.tile([-180.0, 180.0], (3, 1))
    for _ in range(30):
        na, nb = int(rng.integers(1, 40)), int(rng.integers(1, 40))
        A, pa = _random_tree(rng, na + 5, 3)  # spare rows past the trees' sizes are ignored
        B, pb = _random_tree(rng, nb + 5, 3)
        la, lb = int(rng.integers(0, na)), int(rng.integers(0, nb))
        B[lb] = A[la]  # the junction: one configuration in both trees
        nodes, parent, path, cost, within, same = finish_connect_run(A, pa, na, B, pb, nb, la,
                                                                     lb, limits)
        assert np.array_equal(nodes, np.vstack([A[:na], B[:nb]]))
        assert np.array_equal(parent, np.concatenate([pa[:na],
                                                      np.where(pb[:nb] >= 0, pb[:nb] + na, -1)]))
        expected = np.vstack([_path_to(A, pa, la), _path_to(B, pb, lb)[::-1][1:]])
        assert np.array_equal(path, expected) and same and within
        assert cost == path_cost_deg(expected)
        B[lb, 0] += 1.0  # trees that do not meet are reported, never joined silently
        assert not finish_connect_run(A, pa, na, B, pb, nb, la, lb, limits)[5]
    none = finish_connect_run(A, pa, na, B, pb, nb, -1, -1, limits)
    assert none[2].shape == (0, 3) and not none[4] and none[5]


def test_set_ups_survive_a_cycle_of_many_problems_and_planners(scenarios, fresh_memo,
                                                               monkeypatch):
    # a benchmark's order: every problem x planner, then the next seed; 48 x 3 set-ups must
    # all still be remembered when the cycle comes round (a memo of 128 missed every call)
    problems = [dataclasses.replace(scenarios[i % len(scenarios)], name=f"p{i}")
                for i in range(48)]
    planners = ["fuzzy-rrt", "rrt", "rrt:tuned"]
    for p in problems:
        for planner in planners:
            plan_scenario(p, planner, seed=0, max_iter=50)
    misses = []
    real = setup_memo.remember
    monkeypatch.setattr(setup_memo, "remember", lambda *a: misses.append(a[0]) or real(*a))
    for p in problems:
        for planner in planners:
            plan_scenario(p, planner, seed=1, max_iter=50)
    assert misses == []


def test_a_set_up_goes_with_its_scenario(scenarios, fresh_memo):
    import gc

    copy = dataclasses.replace(scenarios[0], name="short-lived")
    plan_scenario(copy, "fuzzy-rrt", seed=0, max_iter=50)
    plan_scenario(copy, "rrt", seed=0, max_iter=50)
    assert len(setup_memo._memo) == 2
    del copy
    gc.collect()
    assert len(setup_memo._memo) == 0


def test_a_scenario_freed_after_the_memo_module_is_torn_down_drops_its_entry_silently(
        monkeypatch):
    """At interpreter exit a script's global scenario can die after the modules' names are
    cleared (set to None); its entry's callback must not look ``_forget`` up then (it printed
    "Exception ignored ... 'NoneType' object is not callable" after a benchmark run)."""
    import gc
    import sys

    class Owner:  # any object with weak references, as a scenario has
        pass

    store: dict = {}
    owner = Owner()
    setup_memo.remember(("key", id(owner)), owner, "value", store)
    complaints = []
    monkeypatch.setattr(sys, "unraisablehook", complaints.append)
    monkeypatch.setattr(setup_memo, "_forget", None)  # as module teardown leaves it
    del owner
    gc.collect()
    assert complaints == [] and store == {}


def test_a_loaded_rulebook_is_matched_by_identity_and_another_load_gets_its_own_set_up(
        scenarios, rulebook_copy, fresh_memo):
    from xfuzzy_rrt.planners.connect import plan_fuzzy_rrt_connect

    root, _hashed = rulebook_copy
    s = scenarios[0]
    for plan in (plan_fuzzy_rrt, plan_fuzzy_rrt_connect):
        rb = rbmod.load_rulebook(root)
        first = plan(s, rb, seed=3)
        count = len(setup_memo._memo)
        assert plan(s, rb, seed=3).iterations == first.iterations
        assert len(setup_memo._memo) == count  # found again, not rebuilt
        other = rbmod.load_rulebook(root)  # equal, but another object: checked afresh
        assert plan(s, other, seed=3).iterations == first.iterations
        assert len(setup_memo._memo) == count + 1


def test_a_results_params_are_its_own_not_the_remembered_set_ups(scenarios, fresh_memo):
    from xfuzzy_rrt.planners.connect import plan_fuzzy_rrt_connect

    s = scenarios[0]
    for plan in (plan_fuzzy_rrt, plan_fuzzy_rrt_connect, plan_rrt):
        first = plan(s, seed=4)
        expected = dict(first.params)
        first.params["max_iter"] = -1
        first.params["added"] = True
        assert plan(s, seed=4).params == expected


def test_a_loop_passing_the_same_objects_finds_its_set_up_without_building_a_key(
        scenarios, fresh_memo, monkeypatch):
    from xfuzzy_rrt.planners.api import load_shipped_default, load_tuned_rrt

    s = scenarios[0]
    other = dataclasses.replace(s, name="another")  # planned in between: several kept per planner
    calls = [("fuzzy-rrt", load_shipped_default()), ("rrt:tuned", load_tuned_rrt()),
             ("rrt", None)]
    first = [plan_scenario(s, planner, rulebook=given, seed=0, max_iter=300)
             for planner, given in calls]
    plan_scenario(other, "rrt", seed=0, max_iter=300)
    monkeypatch.setattr(setup_memo, "exact", lambda v: pytest.fail("a key was built"))
    for k in range(3):  # rrt and rrt:tuned in turn: both still found
        for (planner, given), was in zip(calls, first):
            again = plan_scenario(s, planner, rulebook=given, seed=0, max_iter=300)
            assert again.iterations == was.iterations and again.params == was.params


def test_equal_settings_in_other_objects_take_the_key_and_find_the_same_set_up(
        scenarios, fresh_memo, monkeypatch):
    s = scenarios[0]
    plan_rrt(s, seed=0, max_iter=300, step_deg=45.0)
    keys, stored = [], []
    real_exact, real_remember = setup_memo.exact, setup_memo.remember
    monkeypatch.setattr(setup_memo, "exact", lambda v: keys.append(v) or real_exact(v))
    monkeypatch.setattr(setup_memo, "remember", lambda *a: stored.append(a) or real_remember(*a))
    step = float("45." + "0")  # equal, another object
    plan_rrt(s, seed=0, max_iter=300, step_deg=step)
    assert keys and not stored  # the key was built and found the remembered set-up
    plan_rrt(s, seed=0, max_iter=300, step_deg=45)  # an int is not the float: checked afresh
    assert len(stored) == 1


def test_a_rulebook_directory_is_resolved_every_call_not_matched_by_identity(
        scenarios, rulebook_copy, fresh_memo, monkeypatch):
    root, _hashed = rulebook_copy
    s = scenarios[0]
    plan_fuzzy_rrt(s, root, seed=0, max_iter=300)
    monkeypatch.setattr(setup_memo, "last_call", lambda *a: pytest.fail("matched by identity"))
    plan_fuzzy_rrt(s, root, seed=0, max_iter=300)
    plan_fuzzy_rrt(s, None, seed=0, max_iter=300)


def test_clearing_the_memo_forgets_the_identity_matches_too(scenarios, fresh_memo,
                                                             monkeypatch):
    s = scenarios[0]
    plan_rrt(s, seed=0, max_iter=300)
    setup_memo.clear()
    stored = []
    real = setup_memo.remember
    monkeypatch.setattr(setup_memo, "remember", lambda *a: stored.append(a) or real(*a))
    plan_rrt(s, seed=0, max_iter=300)
    assert len(stored) == 1  # checked again
