"""``rules eval/show/export/import`` through the real console script."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from xfuzzy_rrt.fuzzy import engine
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
from xfuzzy_rrt.fuzzy.variables import INPUTS, OUTPUTS, rule_terms

from _rulebook_helpers import EXPERT, copy_expert, random_inputs
from conftest import PROJECT, run_main


@pytest.fixture
def run_cli():
    """The CLI through ``main(argv)`` in this process (``conftest.run_main``): these tests
    check what commands print, return and write, not the process; ~1.5 s less a call."""
    return run_main


def _write_inputs(path, X):
    path.write_text(",".join(INPUTS) + "\n" + "\n".join(",".join(repr(float(v)) for v in row) for row in X) + "\n")


def _read(path):
    df = pd.read_csv(path)
    return df


def _eval(run_cli, rb, inp, out):
    proc = run_cli("rules", "eval", rb, "--input", inp, "--output", out)
    assert proc.returncode == 0, proc.stderr
    return _read(out)


def test_eval_appends_the_six_outputs_with_full_precision(run_cli, tmp_path):
    X = random_inputs(np.random.default_rng(0), 500, margin=0.3)
    _write_inputs(tmp_path / "in.csv", X)
    df = _eval(run_cli, EXPERT, tmp_path / "in.csv", tmp_path / "out.csv")
    assert list(df.columns) == [*INPUTS, *OUTPUTS]
    assert np.array_equal(df[list(INPUTS)].to_numpy(), X)
    knots, consts = load_rulebook(EXPERT).arrays()
    assert np.array_equal(df[list(OUTPUTS)].to_numpy(), engine.infer_batch(knots, consts, X))


def test_eval_clamps_out_of_range_inputs(run_cli, tmp_path):
    X = np.array([[-1.0, -0.5, 100.0, 9.0], [0.0, 0.0, 2 * np.pi, 0.6]])
    _write_inputs(tmp_path / "in.csv", X)
    df = _eval(run_cli, EXPERT, tmp_path / "in.csv", tmp_path / "out.csv")
    assert np.array_equal(df.loc[0, list(OUTPUTS)].to_numpy(float), df.loc[1, list(OUTPUTS)].to_numpy(float))


@pytest.mark.parametrize(
    "content,fragment,where",
    [
        ("angle_to_goal,dist_to_goal,angle_to_obstacle\n1,2,3\n", "missing column(s) dist_to_obstacle", ""),
        ("angle_to_goal,dist_to_goal,angle_to_obstacle,dist_to_obstacle\n1,2,3,4\n1,x,3,4\n", "dist_to_goal: 'x' is not a finite number", ":3"),
        ("angle_to_goal,dist_to_goal,angle_to_obstacle,dist_to_obstacle\n1,2,,4\n", "is not a finite number", ":2"),
    ],
)
def test_eval_rejects_bad_csv_without_partial_output(run_cli, tmp_path, content, fragment, where):
    (tmp_path / "in.csv").write_text(content)
    proc = run_cli("rules", "eval", EXPERT, "--input", tmp_path / "in.csv", "--output", tmp_path / "out.csv")
    assert proc.returncode == 2
    assert proc.stderr.startswith(f"error: {tmp_path / 'in.csv'}{where}: ") and fragment in proc.stderr
    assert "Traceback" not in proc.stderr
    assert not (tmp_path / "out.csv").exists()
    assert list(tmp_path.iterdir()) == [tmp_path / "in.csv"]


def test_editing_one_rule_changes_eval_exactly_where_it_fires(run_cli, tmp_path):
    root = copy_expert(tmp_path)
    rb = load_rulebook(root)
    knots, consts = rb.arrays()
    f, r, new_value = OUTPUTS.index("step_size"), 312, 7.25
    t = rule_terms(r)
    # full strength: every input at the peak of the rule's term
    full = np.array([knots[f, i, t[i]] for i in range(4)])
    # inputs where the rule does not fire at all
    X = random_inputs(np.random.default_rng(1), 3000, margin=0.1)
    fr, fw = engine.new_trace_buffers()
    out = np.empty(6)
    keep = []
    for x in X:
        engine.infer(knots, consts, x, out, fr, fw, True)
        if r not in fr[f]:
            keep.append(x)
    X = np.vstack([full, np.array(keep)])
    assert len(X) > 2000
    _write_inputs(tmp_path / "in.csv", X)
    before = _eval(run_cli, root, tmp_path / "in.csv", tmp_path / "before.csv")

    fis = root / "step_size.fis"
    lines = fis.read_text().splitlines(keepends=True)
    (n,) = [k for k, line in enumerate(lines) if line.startswith(f"r{r}: ")]
    head, _, _ = lines[n].rpartition(" = ")
    assert float(lines[n].rpartition(" = ")[2]) != new_value
    lines[n] = f"{head} = {new_value}\n"
    fis.write_text("".join(lines))
    after = _eval(run_cli, root, tmp_path / "in.csv", tmp_path / "after.csv")

    changed = before[list(OUTPUTS)].to_numpy() != after[list(OUTPUTS)].to_numpy()
    assert changed[0, f] and after.loc[0, "step_size"] == new_value
    changed[0, f] = False
    assert not changed.any()


def test_show_summarises_and_finds_rules_by_condition(run_cli):
    proc = run_cli("rules", "show", EXPERT)
    assert proc.returncode == 0, proc.stderr
    for needle in ("rulebook 'expert'", "kind: hand-written",
                   "dist_to_goal [0, 0.6] m: very_near @ 0", "rules: 625 per system",
                   "goal_bias", "step_size", "sha256"):
        assert needle in proc.stdout
    proc = run_cli("rules", "show", EXPERT, "--when", "dist_to_goal=near,dist_to_obstacle=very_far")
    assert proc.returncode == 0
    assert proc.stdout.strip().endswith("25 of 625 rules")
    proc = run_cli("rules", "show", EXPERT, "--when", "dist_to_goal=close")
    assert proc.returncode == 2 and "unknown term 'close'" in proc.stderr


def test_export_import_round_trip_through_the_cli(run_cli, tmp_path):
    assert run_cli("rules", "export", EXPERT, "--format", "fll", "--out", tmp_path / "fll").returncode == 0
    proc = run_cli("rules", "import", tmp_path / "fll", "--out", tmp_path / "back", "--name", "again")
    assert proc.returncode == 0, proc.stderr
    back = load_rulebook(tmp_path / "back")
    assert back.name == "again"
    for a, b in zip(load_rulebook(EXPERT).arrays(), back.arrays()):
        assert np.array_equal(a, b)
    proc = run_cli("rules", "export", EXPERT, "--format", "json", "--out", tmp_path / "x")
    assert proc.returncode == 2 and "Traceback" not in proc.stderr


def test_show_and_eval_print_numbers_people_read_and_files_keep_every_digit(run_cli, tmp_path):
    """4 significant digits on the terminal; ``--exact`` and the CSV keep full precision."""
    import re

    def too_precise(text: str) -> list[str]:
        """Decimal numbers with more than 4 significant digits."""
        nums = re.findall(r"(?<![\w.])-?\d+\.\d+(?:e[-+]?\d+)?(?![\w.])", text)
        return [n for n in nums
                if len(n.split("e")[0].lstrip("-").replace(".", "").lstrip("0")) > 4]

    rb = PROJECT / "rulebooks" / "general"
    for args in ((), ("--rules",), ("--when", "dist_to_goal=near")):
        proc = run_cli("rules", "show", rb, *args)
        assert proc.returncode == 0, proc.stderr
        assert too_precise(proc.stdout) == [], args
    exact = run_cli("rules", "show", rb, "--rules", "--exact")
    assert too_precise(exact.stdout)
    inp = tmp_path / "in.csv"
    inp.write_text("angle_to_goal,dist_to_goal,angle_to_obstacle,dist_to_obstacle\n"
                   "1.0,0.2,2.0,0.3\n")
    out = tmp_path / "out.csv"
    proc = run_cli("rules", "eval", rb, "--input", inp, "--output", out)
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith(f"wrote 1 rows to {out} (full precision)")
    assert "dist_to_goal (m)" in proc.stdout and too_precise(proc.stdout) == []
    assert too_precise(out.read_text())
