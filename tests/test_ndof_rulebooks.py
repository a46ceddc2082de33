"""Rulebooks for arms of N joints (2..7): the manifest's ``dof``, text format, lint, engine, FLL
and the rules tools that need no planning. Every 2-DOF file keeps its bytes (the golden tests
pin that); here the N-DOF side."""

from __future__ import annotations

import math
import re
import shutil

import numpy as np
import pytest

from xfuzzy_rrt.errors import RulebookError
from xfuzzy_rrt.fuzzy import semantics as S
from xfuzzy_rrt.fuzzy.rulebook import Rulebook, load_rulebook, save_rulebook
from xfuzzy_rrt.fuzzy.variables import N_RULES

from _rulebook_helpers import EXPERT
from conftest import run_main


@pytest.fixture
def run_cli():
    """The CLI through ``main(argv)`` in this process (``conftest.run_main``): these tests
    check what commands print, return and write, not the process; ~1.5 s less a call."""
    return run_main


def ndof_arrays(sem, rng, structured: bool = False):
    """Valid random engine arrays for *sem* (its DOF fixes the outputs and ranges).

    ``structured``: one constant per FIS (fast to simplify exactly)."""
    n_out = len(sem.outputs)
    knots = np.empty((n_out, 4, 5))
    for f in range(n_out):
        for i, name in enumerate(sem.inputs):
            lo, hi = sem.input_ranges[name]
            while True:
                p = np.sort(rng.uniform(lo, hi, 3))
                if lo < p[0] < p[1] < p[2] < hi:
                    break
            knots[f, i] = [lo, *p, hi]
    consts = np.empty((n_out, N_RULES))
    for f, name in enumerate(sem.outputs):
        lo, hi = sem.output_ranges[name]
        consts[f] = rng.uniform(lo, hi, 1 if structured else N_RULES)
    return knots, consts


def ndof_rulebook(dof: int, semantics: str = "paper", seed: int = 0, **kw) -> Rulebook:
    sem = S.get(semantics, dof)
    knots, consts = ndof_arrays(sem, np.random.default_rng(seed), kw.pop("structured", False))
    return Rulebook.from_arrays(
        knots, consts, name=kw.pop("name", f"{semantics}-{dof}dof"),
        bounds_mode="relative" if semantics == "paper" else None,
        provenance={"kind": "test", "seed": seed}, semantics=sem, **kw)


# ------------------------------------------------------------------------------ semantics


def test_semantics_at_two_dof_are_the_very_objects_of_today():
    assert S.get("paper") is S.PAPER and S.get("paper", 2) is S.PAPER
    assert S.get("goal-frame", 2) is S.GOAL_FRAME and S.GOAL_FRAME.for_dof(2) is S.GOAL_FRAME
    assert S.PAPER.dof == S.GOAL_FRAME.dof == 2
    assert S.GOAL_FRAME.input_ranges["joint_dist_to_goal"] == (0.0, 360.0)
    assert S.joint_dist_range(2) == (0.0, 360.0)


@pytest.mark.parametrize("dof", range(2, 8))
def test_paper_semantics_has_two_bounds_per_joint(dof):
    sem = S.get("paper", dof)
    assert sem is S.PAPER.for_dof(dof) is S.get("paper", dof)  # cached
    assert sem.dof == dof and sem.n_outputs == 2 * dof + 2
    assert sem.outputs == ("goal_bias", *(f"bound_{k}" for k in range(1, 2 * dof + 1)), "step_size")
    assert sem.inputs == S.PAPER.inputs and dict(sem.input_ranges) == dict(S.PAPER.input_ranges)
    assert all(sem.output_ranges[f"bound_{k}"] == (-180.0, 180.0) for k in range(1, 2 * dof + 1))
    assert sem.units["bound_3"] == "deg"


@pytest.mark.parametrize("dof", range(2, 8))
def test_goal_frame_only_widens_the_joint_distance_range(dof):
    sem = S.get("goal-frame", dof)
    assert sem.outputs == S.GOAL_FRAME.outputs
    assert sem.input_ranges["joint_dist_to_goal"] == (0.0, 180.0 * math.sqrt(2 * dof))
    for name in ("stagnation", "clearance_deg", "reject_rate"):
        assert sem.input_ranges[name] == S.GOAL_FRAME.input_ranges[name]
    # every output range but the step's, which stays at the [0, 120] the N-joint rulebooks
    # were trained with (the 2-joint one grew to [0, 360]: tests/test_goal_frame_step_range.py)
    assert {**sem.output_ranges, "step_deg": None} == {**S.GOAL_FRAME.output_ranges, "step_deg": None}
    assert sem.output_ranges["step_deg"] == ((0.0, 360.0) if dof == 2 else (0.0, 120.0))


@pytest.mark.parametrize("bad", [0, 1, 8, 2.5, "five", True, None])
def test_a_dof_outside_two_to_seven_is_refused(bad):
    with pytest.raises(ValueError, match="dof must be an integer from 2 to 7"):
        S.get("paper", bad)


# ------------------------------------------------------------------------ text round trip


@pytest.mark.parametrize("dof,semantics", [(3, "paper"), (5, "paper"), (7, "paper"),
                                            (3, "goal-frame"), (5, "goal-frame")])
def test_an_ndof_rulebook_round_trips_its_text_exactly(tmp_path, dof, semantics):
    rb = ndof_rulebook(dof, semantics, seed=dof)
    assert rb.dof == dof and len(rb.systems) == len(rb.outputs) == rb.n_outputs
    root = save_rulebook(rb, tmp_path / "rb")
    names = sorted(p.name for p in root.iterdir())
    assert names == sorted(["rulebook.toml", *(f"{o}.fis" for o in rb.outputs)])
    manifest = (root / "rulebook.toml").read_text()
    assert f"\ndof = {dof}\n" in manifest
    back = load_rulebook(root)
    assert back.dof == dof and back.semantics is rb.semantics
    assert back.sha256 == rb.sha256 and back.texts() == rb.texts()
    for name, text in rb.texts().items():
        assert (root / name).read_text() == text
    knots, consts = back.arrays()
    assert knots.shape == (len(rb.outputs), 4, 5) and consts.shape == (len(rb.outputs), N_RULES)
    np.testing.assert_array_equal(consts, rb.arrays()[1])
    # compact layout reads back to the same model
    save_rulebook(rb, tmp_path / "compact", compact=True)
    assert load_rulebook(tmp_path / "compact").sha256 == rb.sha256


def test_a_two_dof_manifest_has_no_dof_key(tmp_path):
    rb = ndof_rulebook(2, seed=1)
    text = rb.texts()["rulebook.toml"]
    assert "dof =" not in text and "the six FIS files" in text
    assert load_rulebook(EXPERT).dof == 2
    assert "dof =" not in (EXPERT / "rulebook.toml").read_text()


def test_an_ndof_manifest_counts_its_files():
    assert "the twelve FIS files (goal_bias.fis ... step_size.fis)" in \
        ndof_rulebook(5).texts()["rulebook.toml"]
    assert "the six FIS files" in ndof_rulebook(5, "goal-frame").texts()["rulebook.toml"]


def test_pickling_keeps_the_dof():
    import pickle

    rb = ndof_rulebook(4)
    back = pickle.loads(pickle.dumps(rb))
    assert back.dof == 4 and back.sha256 == rb.sha256 and back.semantics is rb.semantics


def test_from_arrays_checks_the_shape_for_the_dof():
    sem = S.get("paper", 5)
    knots, consts = ndof_arrays(sem, np.random.default_rng(0))
    with pytest.raises(ValueError, match=r"knots must have shape \(6, 4, 5\)"):
        Rulebook.from_arrays(knots, consts, name="x", bounds_mode="absolute")
    rb = Rulebook.from_arrays(knots, consts, name="x", bounds_mode="absolute", dof=5)
    assert rb.dof == 5 and rb.outputs[-2] == "bound_10"


# ------------------------------------------------------------------------------------ lint


def _problems(root):
    with pytest.raises(RulebookError) as exc:
        load_rulebook(root)
    return exc.value.lines()


def _manifest_with(root, line: str) -> int:
    """Insert *line* after ``name = ...``; return its line number."""
    path = root / "rulebook.toml"
    lines = path.read_text().splitlines()
    at = next(i for i, l in enumerate(lines) if l.startswith("name = ")) + 1
    lines.insert(at, line)
    path.write_text("\n".join(lines) + "\n")
    return at + 1


@pytest.mark.parametrize("value", ["0", "8", "2.5", '"five"', "true", "-3"])
def test_a_bad_dof_value_is_one_line_naming_file_and_line(tmp_path, run_cli, value):
    root = tmp_path / "rb"
    shutil.copytree(EXPERT, root)
    line = _manifest_with(root, f"dof = {value}")
    lines = _problems(root)
    assert len(lines) == 1, lines
    assert lines[0].startswith(f"{root / 'rulebook.toml'}:{line}: dof must be an integer from 2 to 7")
    proc = run_cli("rules", "lint", root)
    assert proc.returncode == 2 and "Traceback" not in proc.stderr
    assert proc.stderr.splitlines() == [f"error: {lines[0]}"]


def test_a_missing_bound_file_names_the_dof_and_the_file(tmp_path, run_cli):
    root = save_rulebook(ndof_rulebook(5), tmp_path / "rb")
    (root / "bound_7.fis").unlink()
    dof_line = (root / "rulebook.toml").read_text().splitlines().index("dof = 5") + 1
    lines = _problems(root)
    assert lines == [f"{root / 'rulebook.toml'}:{dof_line}: dof = 5 needs bound_1.fis \u2026 "
                     "bound_10.fis; bound_7.fis is missing"]
    proc = run_cli("rules", "lint", root)
    assert proc.returncode == 2 and proc.stderr == f"error: {lines[0]}\n"


def test_bound_files_for_more_joints_than_declared_are_one_line_with_a_hint(tmp_path):
    root = save_rulebook(ndof_rulebook(5), tmp_path / "rb")
    text = (root / "rulebook.toml").read_text().replace("dof = 5\n", "")
    (root / "rulebook.toml").write_text(text)  # the key forgotten
    lines = _problems(root)
    assert len(lines) == 1, lines
    assert lines[0] == (f"{root / 'rulebook.toml'}: dof = 2 (no dof key) needs bound_1.fis \u2026 "
                        "bound_4.fis; bound_5.fis \u2026 bound_10.fis are extra "
                        "(the files present fit dof = 5)")


def test_bound_files_for_fewer_joints_than_declared(tmp_path):
    root = save_rulebook(ndof_rulebook(3), tmp_path / "rb")
    path = root / "rulebook.toml"
    path.write_text(path.read_text().replace("dof = 3", "dof = 4"))
    lines = _problems(root)
    assert len(lines) == 1 and lines[0].endswith(
        "dof = 4 needs bound_1.fis \u2026 bound_8.fis; bound_7.fis, bound_8.fis are missing "
        "(the files present fit dof = 3)"), lines


def test_a_goal_frame_fis_of_another_dof_says_which(tmp_path):
    root = save_rulebook(ndof_rulebook(5, "goal-frame"), tmp_path / "rb")
    two = save_rulebook(ndof_rulebook(2, "goal-frame"), tmp_path / "two")
    shutil.copy(two / "ahead_deg.fis", root / "ahead_deg.fis")
    lines = _problems(root)  # the range, then the peaks that end at the old range
    assert len(lines) == 2
    assert re.search(r"ahead_deg\.fis:\d+: range of joint_dist_to_goal must be 0\.0 "
                     r"569\.2099788303083 .*got 0\.0 360\.0 \(the range at dof = 2; the manifest "
                     r"says dof = 5\)", lines[0]), lines


def test_lint_reports_the_dof(tmp_path, run_cli):
    root = save_rulebook(ndof_rulebook(5), tmp_path / "rb")
    proc = run_cli("rules", "lint", root)
    assert proc.returncode == 0, proc.stderr
    assert "(relative bounds, dof 5: 12 FIS)" in proc.stdout
    proc = run_cli("rules", "lint", EXPERT)
    assert "dof" not in proc.stdout


# ---------------------------------------------------------------------------------- engine


def _plain_625(knots, consts, x):
    """The definition, written out: product of the four memberships of every one of the 625
    rules, weighted average of the constants; no shortcut of the engine's."""
    def mu(k, v):
        v = min(max(v, k[0]), k[4])
        out = []
        for j in range(5):
            if j > 0 and k[j - 1] <= v <= k[j]:
                out.append((v - k[j - 1]) / (k[j] - k[j - 1]))
            elif j < 4 and k[j] <= v <= k[j + 1]:
                out.append((k[j + 1] - v) / (k[j + 1] - k[j]))
            else:
                out.append(0.0)
            if j > 0 and j < 4 and v == k[j]:
                out[-1] = 1.0
        if v == k[0]:
            out[0] = 1.0
        if v == k[4]:
            out[4] = 1.0
        return out

    y = []
    for f in range(knots.shape[0]):
        m = [mu(knots[f, i], x[i]) for i in range(4)]
        num = den = 0.0
        for r in range(N_RULES):
            t = (r // 125, r // 25 % 5, r // 5 % 5, r % 5)
            w = m[0][t[0]] * m[1][t[1]] * m[2][t[2]] * m[3][t[3]]
            num += w * consts[f, r]
            den += w
        y.append(num / den)
    return np.array(y)


@pytest.mark.parametrize("semantics", ["paper", "goal-frame"])
def test_the_engine_on_a_five_dof_rulebook_equals_the_625_rule_definition(semantics):
    from xfuzzy_rrt.fuzzy.engine import evaluate, infer, new_trace_buffers
    from xfuzzy_rrt.fuzzy.reference import infer_reference

    rb = ndof_rulebook(5, semantics, seed=11)
    knots, consts = rb.compiled
    n_out = knots.shape[0]
    assert n_out == (12 if semantics == "paper" else 6)
    rng = np.random.default_rng(3)
    sem = rb.semantics
    X = np.column_stack([rng.uniform(lo - 0.1 * (hi - lo), hi + 0.1 * (hi - lo), 40)
                         for lo, hi in (sem.input_ranges[n] for n in sem.inputs)])
    X[0] = [knots[0, i, 2] for i in range(4)]  # on a peak of every input
    Y = evaluate(knots, consts, X)
    assert Y.shape == (40, n_out)
    for x, y in zip(X, Y):
        np.testing.assert_allclose(y, _plain_625(knots, consts, x), rtol=0, atol=1e-9)
    np.testing.assert_allclose(Y, infer_reference(knots, consts, X), rtol=0, atol=1e-12)
    # the planner's entry point, recording or not, with buffers sized from knots.shape[0]
    out = np.empty(n_out)
    rule, w = new_trace_buffers(n_out)
    for x, y in zip(X[:10], Y[:10]):
        infer(knots, consts, x, out, rule, w, True)
        np.testing.assert_array_equal(out, y)
        assert rule.shape == (n_out, 16) and np.allclose(w.sum(axis=1), 1.0)
        infer(knots, consts, x, out, rule, w, False)
        np.testing.assert_array_equal(out, y)


# ------------------------------------------------------------------------------------- FLL


@pytest.mark.parametrize("semantics", ["paper", "goal-frame"])
def test_fll_export_and_import_round_trip_at_three_dof(tmp_path, semantics):
    from xfuzzy_rrt.fuzzy.fll import export_fll, import_fll

    rb = ndof_rulebook(3, semantics, seed=5)
    paths = export_fll(rb, tmp_path / "fll")
    assert sorted(p.name for p in paths) == sorted(f"{o}.fll" for o in rb.outputs)
    back = import_fll(tmp_path / "fll")
    assert back.dof == 3 and back.semantics is rb.semantics and back.outputs == rb.outputs
    assert back.name == rb.name and back.bounds_mode == rb.bounds_mode
    for a, b in zip(rb.arrays(), back.arrays()):
        np.testing.assert_array_equal(a, b)


def test_fll_import_with_a_gap_in_the_bound_files_is_one_line(tmp_path):
    from xfuzzy_rrt.fuzzy.fll import export_fll, import_fll

    export_fll(ndof_rulebook(3), tmp_path / "fll")
    (tmp_path / "fll" / "bound_6.fll").unlink()
    with pytest.raises(RulebookError) as exc:
        import_fll(tmp_path / "fll")
    assert len(exc.value.problems) == 1
    assert "bound_1, bound_2, bound_3, bound_4, bound_5 fit no DOF" in exc.value.lines()[0]


def test_the_two_dof_fll_export_is_unchanged_in_form(tmp_path):
    from xfuzzy_rrt.fuzzy.fll import export_fll

    rb = load_rulebook(EXPERT)
    export_fll(rb, tmp_path / "fll")
    assert '"dof"' not in (tmp_path / "fll" / "goal_bias.fll").read_text()


# ------------------------------------------------------------------ tools that need no plan


def test_rules_eval_writes_one_column_per_output(tmp_path, run_cli):
    import pandas as pd

    rb = ndof_rulebook(5, seed=2)
    root = save_rulebook(rb, tmp_path / "rb")
    pd.DataFrame({"angle_to_goal": [0.5, 3.0], "dist_to_goal": [0.1, 0.4],
                  "angle_to_obstacle": [1.0, 5.0], "dist_to_obstacle": [0.05, 0.5]}
                 ).to_csv(tmp_path / "in.csv", index=False)
    proc = run_cli("rules", "eval", root, "--input", tmp_path / "in.csv",
                   "--output", tmp_path / "out.csv")
    assert proc.returncode == 0, proc.stderr
    out = pd.read_csv(tmp_path / "out.csv")
    assert list(out.columns) == [*rb.inputs, *rb.outputs]
    assert "bound_10" in out.columns and len(out) == 2


def test_rules_show_names_the_dof(tmp_path, run_cli):
    root = save_rulebook(ndof_rulebook(4), tmp_path / "rb")
    proc = run_cli("rules", "show", root)
    assert proc.returncode == 0, proc.stderr
    assert "dof: 4 (10 FIS: goal_bias \u2026 step_size)" in proc.stdout
    assert "rules: 625 per system, 6250 in all" in proc.stdout
    assert re.search(r"^  bound_8 ", proc.stdout, re.M)
    proc = run_cli("rules", "show", root, "--when", "dist_to_goal=near")
    assert proc.returncode == 0 and "bound_8" in proc.stdout.splitlines()[0]


def test_diff_compares_ndof_rulebooks_and_refuses_another_dof(tmp_path):
    from xfuzzy_rrt.analysis.diff import diff_rulebooks
    from xfuzzy_rrt.errors import InputError

    a = ndof_rulebook(5, seed=1)
    knots, consts = a.arrays()
    consts[7, 3] = 0.0 if consts[7, 3] else 1.0  # bound_7, rule 3
    b = Rulebook.from_arrays(knots, consts, name="b", bounds_mode="relative",
                             provenance={"kind": "test"}, semantics=a.semantics)
    d = diff_rulebooks(a, b)
    assert not d.identical and d.cells["output"].tolist() == ["bound_7"]
    assert d.cells["rule"].tolist() == [3]
    with pytest.raises(InputError, match="dof 5.*dof 2"):
        diff_rulebooks(a, load_rulebook(EXPERT))


def test_simplify_is_lossless_on_an_ndof_rulebook(tmp_path):
    from xfuzzy_rrt.analysis.simplify import simplify

    rb = ndof_rulebook(4, structured=True, seed=4)
    res = simplify(rb, name="small", command="test")
    assert res.rulebook.dof == 4 and res.lossless
    assert res.chosen.rules == len(rb.outputs)  # one constant per FIS: one 'any' rule each
    np.testing.assert_array_equal(res.rulebook.arrays()[1], rb.arrays()[1])
    root = save_rulebook(res.rulebook, tmp_path / "s", compact=True)
    assert load_rulebook(root).sha256 == res.rulebook.sha256


def test_coverage_counts_a_trace_with_one_block_per_output():
    """Coverage on an N-DOF trace made by the engine itself (no planner needed)."""
    import pandas as pd

    from xfuzzy_rrt.analysis.coverage import counts_from_trace, coverage_frame, coverage_summary
    from xfuzzy_rrt.analysis.firing import top_rules
    from xfuzzy_rrt.fuzzy.engine import infer, new_trace_buffers

    rb = ndof_rulebook(5, seed=8)
    knots, consts = rb.compiled
    n_out = knots.shape[0]
    rng = np.random.default_rng(0)
    rows = []
    for it in range(30):
        x = np.array([rng.uniform(*rb.semantics.input_ranges[n]) for n in rb.inputs])
        out = np.empty(n_out)
        rule, w = new_trace_buffers(n_out)
        infer(knots, consts, x, out, rule, w, True)
        row = {"iteration": it + 1, "on_path": it % 3 == 0, **dict(zip(rb.inputs, x)),
               **dict(zip(rb.outputs, out))}
        for f, o in enumerate(rb.outputs):
            row.update({f"{o}_rule_{k}": int(rule[f, k]) for k in range(16)})
            row.update({f"{o}_strength_{k}": float(w[f, k]) for k in range(16)})
        rows.append(row)
    trace = pd.DataFrame(rows)
    counts = counts_from_trace(trace, success=True)
    assert counts.fired.shape == (12, N_RULES)
    cov = coverage_frame(counts, rb)
    assert len(cov) == 12 * N_RULES and cov["output"].unique().tolist() == list(rb.outputs)
    summary = coverage_summary(cov, counts.iterations)
    assert summary["output"].tolist() == [*rb.outputs, "all"]
    for o in rb.outputs:
        assert cov[cov["output"] == o]["mass_share"].sum() == pytest.approx(1.0)
    assert set(top_rules(trace, 2)["output"]) == set(rb.outputs)


def test_explain_recomputes_an_ndof_row_and_shows_every_joint():
    """``explain`` on a trace row of a 5-joint run (made here by the engine; the planner's
    trace has the same columns): every FIS recomputed, the box and sample in all five joints."""
    import pandas as pd

    from xfuzzy_rrt.analysis.explain import explain_row, render_text, trace_joints
    from xfuzzy_rrt.fuzzy.engine import infer, new_trace_buffers

    rb = ndof_rulebook(5, seed=9)
    knots, consts = rb.compiled
    n_out = knots.shape[0]
    x = np.array([1.0, 0.2, 4.0, 0.1])
    out = np.empty(n_out)
    rule, w = new_trace_buffers(n_out)
    infer(knots, consts, x, out, rule, w, True)
    row = {"iteration": 3, "rulebook_sha256": rb.sha256, **dict(zip(rb.inputs, x)),
           **dict(zip(rb.outputs, out)), "from_node": 0, "step_used_deg": 10.0,
           "goal_sampled": False, "nearest_node": 0, "outcome": "added", "new_node": 1,
           "tree_size": 2, "on_path": False}
    for j in range(1, 6):
        row.update({f"from_q{j}_deg": 10.0 * j, f"box_q{j}_lo": -j, f"box_q{j}_hi": j,
                    f"sample_q{j}_deg": 0.5 * j, f"new_q{j}_deg": 0.25 * j})
    for f, o in enumerate(rb.outputs):
        row.update({f"{o}_rule_{k}": int(rule[f, k]) for k in range(16)})
        row.update({f"{o}_strength_{k}": float(w[f, k]) for k in range(16)})
    series = pd.Series(row)
    assert trace_joints(series.index) == [1, 2, 3, 4, 5]
    e = explain_row(series, rb)
    assert [s.output for s in e.systems] == list(rb.outputs)
    assert e.max_discrepancy < 1e-12
    text = render_text(e)
    assert "== bound_10 ==" in text and "joint 5 [-5, 5] deg" in text
    assert "sample: [0.5, 1, 1.5, 2, 2.5]" in text and "[10, 20, 30, 40, 50]" in text
