"""Fuzzy-RRT-Connect (issue 25): two goal-frame trees that grow towards each other.

Its successful paths are proven collision-free by the independent oracle
(tests/exact_geometry.py) at 2 joints and at every DOF and arm count a goal-frame rulebook is
shipped for; it is deterministic per seed; its traces explain with the numbers the planner
recorded; a rulebook it cannot use, or of the wrong DOF, is refused in one line.
"""

from __future__ import annotations

import subprocess

import numpy as np
import pytest

from conftest import FIXTURES, console_script
from exact_geometry import oracle_path_problems
from test_ndof_paths_oracle import dual_arm, single_arm
from xfuzzy_rrt.analysis.explain import explain_row, trace_row
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebooks_dir
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.api import parse_planner, plan_scenario
from xfuzzy_rrt.planners.connect import plan_fuzzy_rrt_connect

TWO_JOINTS = [FIXTURES / "scenarios" / "two-circles.toml",
              FIXTURES / "scenarios" / "boxes-and-circle.toml"]


def _shipped(name: str) -> bool:
    return (rulebooks_dir() / name / "rulebook.toml").is_file()


def _oracle_ok(s, r):
    assert r.success, (s.name, r.seed, r.violation)
    assert np.array_equal(r.path_deg[0], np.asarray(s.start_deg, dtype=float))
    assert np.array_equal(r.path_deg[-1], np.asarray(s.goal_deg, dtype=float))
    assert oracle_path_problems(s, r.path_deg, s.start_deg, s.goal_deg) == []


@pytest.mark.parametrize("path", TWO_JOINTS, ids=lambda p: p.stem)
def test_two_joint_connect_paths_pass_the_oracle_with_the_goal_frame_rulebook(path):
    s = load_scenario(path)
    for seed in range(3):
        r = plan_scenario(s, "fuzzy-rrt-connect:goal-frame", seed=seed, max_iter=20_000)
        assert r.planner == "fuzzy-rrt-connect:goal-frame" and r.rulebook == "goal-frame"
        _oracle_ok(s, r)


@pytest.fixture(scope="module")
def goal_frame_read_as_any(tmp_path_factory):
    """goal-frame's own knots and rules as a goal-frame-any rulebook (the script that made the
    first shipped goal-frame-any, whose training now starts from goal-frame)."""
    import sys

    from conftest import PROJECT

    from xfuzzy_rrt.fuzzy.rulebook import Rulebook, save_rulebook

    # the shipped goal-frame with its steps kept to goal-frame-any's [0, 120] (it may step up
    # to 360; the script clips longer steps, which would then decide differently)
    root = tmp_path_factory.mktemp("any")
    shipped = load_rulebook(rulebooks_dir() / "goal-frame")
    knots, consts = shipped.arrays()
    consts = consts.copy()
    consts[5] = np.minimum(consts[5], 120.0)
    source = save_rulebook(Rulebook.from_arrays(
        knots, consts, name="goal-frame-short-steps", bounds_mode=None,
        semantics=shipped.semantics, provenance={"kind": "test"}), root / "goal-frame-short-steps")
    out = root / "goal-frame-read-as-any"
    proc = subprocess.run([sys.executable, str(PROJECT / "scripts" /
                                                "make_goal_frame_any_rulebook.py"),
                           "--source", str(source), "--out", str(out), "--date", "2026-12-04"],
                          capture_output=True, text=True, timeout=300)
    assert proc.returncode == 0, proc.stderr
    return source, out


@pytest.mark.parametrize("path", TWO_JOINTS, ids=lambda p: p.stem)
def test_at_two_joints_the_dof_free_semantics_decides_exactly_as_goal_frame(
        path, goal_frame_read_as_any):
    s = load_scenario(path)
    source, derived = goal_frame_read_as_any
    for seed in range(3):
        a = plan_scenario(s, f"fuzzy-rrt-connect:{derived}", seed=seed)
        b = plan_scenario(s, f"fuzzy-rrt-connect:{source}", seed=seed)
        assert a.rulebook == "goal-frame-read-as-any" and a.params["length_scale"] == 1.0
        assert a.path_deg.tobytes() == b.path_deg.tobytes()
        assert a.tree_nodes_deg.tobytes() == b.tree_nodes_deg.tobytes()
        _oracle_ok(s, a)


ANY_ARM = [single_arm(3, 0), single_arm(4, 0), single_arm(6, 0), single_arm(7, 0),
           single_arm(7, 1), dual_arm(2, 0), dual_arm(3, 0), dual_arm(3, 1)]


@pytest.mark.parametrize("s", ANY_ARM, ids=lambda s: s.name)
def test_the_default_plans_any_arm_without_a_rulebook_and_the_oracle_agrees(s):
    for seed in range(2):
        r = plan_scenario(s, "fuzzy-rrt-connect", seed=seed, max_iter=20_000)
        assert r.rulebook == "goal-frame-any"
        assert r.params["length_scale"] == pytest.approx((s.dof / 2) ** 0.5)
        _oracle_ok(s, r)


@pytest.mark.parametrize("path", sorted((FIXTURES / "many-arms").glob("*.toml")),
                         ids=lambda p: p.stem)
def test_the_default_plans_three_and_four_arms(path):
    # written by ``xfuzzy-rrt scenarios generate --seed 9500 --arms 3`` (and ``--arms 4``)
    s = load_scenario(path)
    assert len(s.arms) in (3, 4)
    for seed in range(2):
        r = plan_scenario(s, "fuzzy-rrt-connect", seed=seed, max_iter=20_000)
        _oracle_ok(s, r)


def test_fuzzy_rrt_refuses_a_dof_free_rulebook_in_one_line():
    s = load_scenario(TWO_JOINTS[0])
    with pytest.raises(InputError, match="fuzzy-rrt-connect"):
        plan_scenario(s, "fuzzy-rrt:goal-frame-any")


def test_a_dof_free_manifest_must_say_dof_any_and_only_it_may(tmp_path):
    import shutil

    from xfuzzy_rrt.errors import RulebookError

    src = rulebooks_dir() / "goal-frame-any"
    assert 'dof = "any"' in (src / "rulebook.toml").read_text()
    bad = tmp_path / "bad"
    shutil.copytree(src, bad)
    m = bad / "rulebook.toml"
    m.write_text(m.read_text().replace('dof = "any"', "dof = 5"))
    with pytest.raises(RulebookError, match='write dof = "any"'):
        load_rulebook(bad)
    gf = tmp_path / "gf"
    shutil.copytree(rulebooks_dir() / "goal-frame", gf)
    m = gf / "rulebook.toml"
    m.write_text(m.read_text().replace('semantics = "goal-frame"\n',
                                       'semantics = "goal-frame"\ndof = "any"\n'))
    with pytest.raises(RulebookError, match="needs a DOF-free semantics"):
        load_rulebook(gf)


CASES = [(single_arm(5, 0), "goal-frame-5dof"), (single_arm(5, 1), "goal-frame-5dof"),
         (dual_arm(3, 0), "goal-frame-dual3"), (dual_arm(3, 1), "goal-frame-dual3")]


@pytest.mark.parametrize("s,book", CASES, ids=lambda c: getattr(c, "name", c))
def test_ndof_and_two_arm_connect_paths_pass_the_oracle(s, book):
    if not _shipped(book):
        pytest.skip(f"no {book} rulebook is shipped")
    for seed in range(2):
        r = plan_scenario(s, f"fuzzy-rrt-connect:{book}", seed=seed, max_iter=20_000)
        _oracle_ok(s, r)


def test_same_seed_same_bytes_and_other_seeds_differ():
    s = load_scenario(TWO_JOINTS[1])
    a = plan_fuzzy_rrt_connect(s, seed=7)
    b = plan_fuzzy_rrt_connect(s, seed=7)
    c = plan_fuzzy_rrt_connect(s, seed=8)
    assert a.path_deg.tobytes() == b.path_deg.tobytes()
    assert a.tree_nodes_deg.tobytes() == b.tree_nodes_deg.tobytes()
    assert (a.iterations, a.nodes, a.params) == (b.iterations, b.nodes, b.params)
    assert a.path_deg.tobytes() != c.path_deg.tobytes()


def test_both_trees_grow_and_the_result_holds_both():
    s = load_scenario(TWO_JOINTS[0])
    r = plan_fuzzy_rrt_connect(s, seed=1, trace=True)
    p = r.params
    assert p["start_tree_nodes"] + p["goal_tree_nodes"] == r.nodes == len(r.tree_nodes_deg)
    # the forest has exactly two roots: the start and the goal
    roots = np.flatnonzero(r.tree_parent < 0)
    assert roots.tolist() == [0, p["start_tree_nodes"]]
    assert np.array_equal(r.tree_nodes_deg[roots[1]], s.goal_deg)
    t = r.trace
    assert set(t["tree"].unique()) <= {0, 1} and t["tree"].iloc[0] == 0
    assert t["outcome"].iloc[-1] == "goal_reached"
    assert (t["outcome"] == "goal_reached").sum() == 1
    # every node on the path was added by some row or is a root/junction copy
    assert t["on_path"].any()


def _trees_that_should_grow(trace):
    """Per row, the tree the planner must grow: the one with fewer nodes, on a tie the one that
    did not grow last (the start tree first), with the sizes rebuilt from the trace alone (each
    tree starts as its root; a row adds ``grow_nodes`` to the growing tree and
    ``connect_nodes`` to the other)."""
    sizes, last, want = [1, 1], 1, []
    for g, grown, connected in zip(trace["tree"], trace["grow_nodes"], trace["connect_nodes"]):
        expect = 0 if sizes[0] < sizes[1] else 1 if sizes[1] < sizes[0] else 1 - last
        want.append(expect)
        sizes[int(g)] += int(grown)
        sizes[1 - int(g)] += int(connected)
        last = int(g)
    return want


def test_the_smaller_tree_grows_and_a_tie_alternates():
    # balanced bidirectional growth: the iteration goes to the tree with fewer nodes, so a
    # tree stuck in a pocket gets the iterations instead of half of them; by turns (the old
    # rule) or always the same tree fails this on the runs below
    repeats = 0
    for s in (single_arm(4, 0), dual_arm(3, 0), single_arm(3, 1)):
        for seed in range(12):
            t = plan_fuzzy_rrt_connect(s, seed=seed, trace=True).trace
            assert t["tree"].tolist() == _trees_that_should_grow(t), (s.name, seed)
            repeats += int((t["tree"].to_numpy()[1:] == t["tree"].to_numpy()[:-1]).sum())
    assert repeats > 0, "no run grew one tree twice in a row: the balance was never exercised"


def test_iterations_count_loop_iterations_not_connect_steps():
    s = load_scenario(TWO_JOINTS[0])
    r = plan_fuzzy_rrt_connect(s, seed=3, trace=True)
    assert len(r.trace) == r.iterations
    connected = int((r.trace["connect_nodes"] > 0).sum())
    assert r.params["extensions"] >= r.iterations + connected


def _grown_runs(s, seeds, max_iter=10_000):
    return [plan_fuzzy_rrt_connect(s, seed=k, trace=True, max_iter=max_iter) for k in seeds]


@pytest.mark.parametrize("path", TWO_JOINTS, ids=lambda p: p.stem)
def test_every_node_of_both_trees_is_a_root_or_counted_by_one_growth_or_connect(path):
    s = load_scenario(path)
    for r in _grown_runs(s, range(4)):
        t = r.trace
        assert r.nodes == 2 + int(t["grow_nodes"].sum()) + int(t["connect_nodes"].sum())
        refused = t["outcome"].isin(["node_in_collision", "edge_blocked"]).to_numpy()
        # a growth adds nothing exactly when its first (fuzzy-decided) step was refused
        assert ((t["grow_nodes"].to_numpy() == 0) == (refused | (t["new_node"] < 0))).all()
        assert not (t["connect_nodes"].to_numpy()[refused] > 0).any()


def test_a_growth_goes_on_towards_its_sample_while_its_steps_are_accepted():
    s = load_scenario(TWO_JOINTS[0])
    runs = _grown_runs(s, range(10))
    # rows where the trees did not meet (a join adds the other root's copy as well)
    multi = [(r, i) for r in runs
             for i in np.flatnonzero((r.trace["grow_nodes"].to_numpy() > 1)
                                     & (r.trace["outcome"] == "accepted").to_numpy())]
    assert multi, "no growth took more than one step in ten runs"
    for r, i in multi:
        row = r.trace.iloc[i]
        first, n = int(row["new_node"]), int(row["grow_nodes"])
        sample = np.array([row["sample_q1_deg"], row["sample_q2_deg"]])
        near = r.tree_nodes_deg[int(row["nearest_node"])]
        # the further steps are a chain from the first, each node the next one's parent ...
        chain = list(range(first, first + n))
        assert r.tree_parent[first] == int(row["nearest_node"])
        assert [int(r.tree_parent[k]) for k in chain[1:]] == chain[:-1]
        # ... on the line from the nearest node to the sample, by steps of one size
        span = np.linalg.norm(sample - near)
        direction = (sample - near) / span
        along = []
        for k in chain:
            off = r.tree_nodes_deg[k] - near
            assert np.linalg.norm(off - direction * (off @ direction)) < 1e-9
            along.append(off @ direction)
        steps = np.diff([0.0, *along])
        assert np.all(steps > 0) and along[-1] <= span + 1e-9
        assert steps[:-1] == pytest.approx(np.full(n - 1, steps[0]))
        assert steps[-1] <= steps[0] + 1e-9  # the last one may stop at the sample


def test_explain_reproduces_every_recorded_output_of_a_connect_trace(tmp_path):
    s = load_scenario(TWO_JOINTS[1])
    # a seed whose plan takes several iterations (a lucky one connects at iteration 1)
    seed = next(k for k in range(50) if plan_fuzzy_rrt_connect(s, seed=k).iterations >= 3)
    r = plan_fuzzy_rrt_connect(s, seed=seed, trace=True)
    rb = load_rulebook(rulebooks_dir() / r.rulebook)
    for it in sorted({1, 2, r.iterations // 2 + 1, r.iterations}):
        e = explain_row(trace_row(r.trace, it), rb)
        assert e.max_discrepancy < 1e-12
        assert e.decision["tree"] == r.trace["tree"].iloc[it - 1]
    # the command line explains a written trace too
    trace = tmp_path / "t.parquet"
    scen = TWO_JOINTS[1]
    cli = [console_script()]
    done = subprocess.run([*cli, "plan", str(scen), "--planner", "fuzzy-rrt-connect",
                           "--seed", str(seed), "--trace", str(trace), "--out", str(tmp_path / "r.json")],
                          capture_output=True, text=True)
    assert done.returncode == 0, done.stderr
    out = subprocess.run([*cli, "explain", str(trace), "--iteration", "2", "--exact"],
                         capture_output=True, text=True)
    assert out.returncode == 0, out.stderr
    assert "Fuzzy-RRT-Connect, goal tree grows" in out.stdout
    assert f"planner recorded {float(r.trace.loc[1, 'step_deg'])!r}" in out.stdout
    grew = int(r.trace.loc[1, "grow_nodes"])
    assert f"growth: the growing tree added {grew} node(s) towards the sample" in out.stdout
    replay = subprocess.run([*cli, "explain", str(tmp_path / "r.json"), "--iteration", "1"],
                            capture_output=True, text=True)
    assert replay.returncode == 0, replay.stderr


def test_a_paper_semantics_rulebook_is_refused_in_one_line():
    s = load_scenario(TWO_JOINTS[0])
    with pytest.raises(InputError, match="needs a goal-frame or goal-frame-any rulebook"):
        plan_scenario(s, "fuzzy-rrt-connect:paper")


def test_a_rulebook_of_the_wrong_dof_is_refused_in_one_line():
    if not _shipped("goal-frame-5dof"):
        pytest.skip("no goal-frame-5dof rulebook is shipped")
    s = load_scenario(TWO_JOINTS[0])
    with pytest.raises(InputError, match="5-DOF goal-frame rulebook"):
        plan_scenario(s, "fuzzy-rrt-connect:goal-frame-5dof")


def test_an_unknown_rulebook_names_the_connect_label():
    with pytest.raises(InputError, match="fuzzy-rrt-connect:nosuch"):
        parse_planner("fuzzy-rrt-connect:nosuch")


def test_cli_wrong_rulebook_is_one_line_exit_2(tmp_path):
    cli = [console_script()]
    out = tmp_path / "r.json"
    done = subprocess.run([*cli, "plan", str(TWO_JOINTS[0]), "--planner",
                           "fuzzy-rrt-connect:paper", "--out", str(out)],
                          capture_output=True, text=True)
    assert done.returncode == 2
    lines = done.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith("error: ") and "goal-frame" in lines[0]
    assert not out.exists()


def test_the_report_reproduce_command_of_a_connect_run_is_one_plan_accepts(tmp_path):
    """A report's reproduce line for ``fuzzy-rrt-connect:NAME`` names the Connect planner
    (``--planner fuzzy-rrt`` would refuse a Connect rulebook), and ``plan`` takes it with
    ``--rulebook`` like Fuzzy-RRT does; the rerun is the same plan."""
    import json
    import shlex

    from xfuzzy_rrt.cli.main import main
    from xfuzzy_rrt.report.evidence import _plan_cmd

    s = load_scenario(TWO_JOINTS[0])
    book = rulebooks_dir() / "goal-frame-any"
    cmd = _plan_cmd(s, "fuzzy-rrt-connect:goal-frame-any", 3,
                    {"max_iter": 2000, "rulebook_dir": str(book)})
    args = shlex.split(cmd)
    assert args[:2] == ["xfuzzy-rrt", "plan"]
    assert args[args.index("--planner") + 1] == "fuzzy-rrt-connect"
    out = tmp_path / "r.json"
    assert main([*args[1:], "--out", str(out)]) == 0
    rerun = json.loads(out.read_text())
    direct = plan_scenario(s, "fuzzy-rrt-connect", rulebook=load_rulebook(book), seed=3,
                           max_iter=2000)
    assert rerun["iterations"] == direct.iterations
    assert rerun["rulebook"] == "goal-frame-any"


def test_a_dof_free_trace_records_the_rulebook_values_and_the_degrees_used():
    s = single_arm(4, 0)
    seed = next(k for k in range(50)
                if plan_fuzzy_rrt_connect(s, seed=k, max_iter=20_000).iterations >= 3)
    r = plan_fuzzy_rrt_connect(s, seed=seed, trace=True, max_iter=20_000)
    t = r.trace
    scale = r.params["length_scale"]
    assert scale == pytest.approx(2 ** 0.5)
    # outputs as the rulebook gave them (explain recomputes them); the step in joint degrees
    assert np.allclose(t["step_used_deg"], np.maximum(t["step_deg"] * scale, 0.5))
    rb = load_rulebook(rulebooks_dir() / "goal-frame-any")
    for it in sorted({1, 2, r.iterations}):
        assert explain_row(trace_row(t, it), rb).max_discrepancy < 1e-12
    # the distance input is the normalised distance from the current node to the target
    row = t.iloc[0]
    d = np.linalg.norm(np.asarray(s.goal_deg) - np.asarray(s.start_deg))
    assert row["norm_dist_to_goal"] == pytest.approx(d / scale)


def test_a_dof_free_rulebook_round_trips_through_fll(tmp_path):
    from xfuzzy_rrt.fuzzy.fll import export_fll, import_fll

    rb = load_rulebook(rulebooks_dir() / "goal-frame-any")
    export_fll(rb, tmp_path / "fll")
    back = import_fll(tmp_path / "fll")
    assert back.semantics is rb.semantics and back.semantics.dof_free
    assert all((a == b).all() for a, b in zip(back.arrays(), rb.arrays()))


@pytest.mark.parametrize("s", [single_arm(4, 0), dual_arm(3, 0)], ids=lambda s: s.name)
def test_the_clearance_input_is_the_clearance_of_the_node_it_was_read_at(s):
    # the loop reads each node's clearance as it was measured when the node was accepted (the
    # roots once per run) instead of measuring it again: every traced value must still equal
    # an independent measurement at that row's node, in either tree
    import math

    from xfuzzy_rrt.geometry.collision import clearance
    from xfuzzy_rrt.planners.goal_frame import problem_lever

    arrays = s.arrays()
    lever = problem_lever(arrays.problem(1e-6))
    rows_per_tree = [0, 0]
    for seed in range(60):
        if min(rows_per_tree) >= 3:
            break
        r = plan_fuzzy_rrt_connect(s, seed=seed, trace=True, max_iter=20_000)
        t = r.trace
        scale = r.params["length_scale"]
        for _, row in t.iterrows():
            rows_per_tree[int(row["tree"])] += 1
            q = r.tree_nodes_deg[int(row["from_node"])]
            want = max(clearance(arrays, q), 0.0) * math.degrees(1.0) / lever / scale
            assert row["norm_clearance"] == pytest.approx(want, rel=1e-12, abs=1e-12)
    assert min(rows_per_tree) >= 3, rows_per_tree  # both trees' nodes were read
