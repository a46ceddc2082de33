"""``rules diff``: changed cells, peaks, bounds mode, provenance; --replay divergence."""

from __future__ import annotations

import re

import numpy as np
import pytest

from xfuzzy_rrt.analysis.coverage import collect_counts
from xfuzzy_rrt.analysis.diff import diff_rulebooks, first_divergence, replay_diff
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, save_rulebook
from xfuzzy_rrt.fuzzy.variables import OUTPUTS
from xfuzzy_rrt.geometry.scenario import load_scenario

from _rulebook_helpers import EXPERT, copy_expert
from conftest import PROJECT, run_main


@pytest.fixture
def run_cli():
    """The CLI through ``main(argv)`` in this process (``conftest.run_main``): these tests
    check what commands print, return and write, not the process; ~1.5 s less a call."""
    return run_main


DEMO = PROJECT / "xfuzzy_rrt" / "data" / "scenarios" / "demo-tissue.toml"


def _edit_rule(rb_dir, output: str, rule: int, value: float) -> None:
    path = rb_dir / f"{output}.fis"
    text = path.read_text()
    new, n = re.subn(rf"^(r{rule}: .* = )\S+$", rf"\g<1>{value!r}", text, flags=re.M)
    assert n == 1
    path.write_text(new)


def _busiest_rule(output: str = "goal_bias") -> int:
    """A rule that fires a lot on the demo scenario with the expert rulebook."""
    counts = collect_counts(load_rulebook(EXPERT), [load_scenario(DEMO)], runs=1, max_iter=500)
    return int(np.argmax(counts.strength[OUTPUTS.index(output)]))


def test_diff_of_one_hand_edited_rule_lists_exactly_that_cell(tmp_path):
    b = copy_expert(tmp_path)
    _edit_rule(b, "bound_3", 154, -12.5)
    d = diff_rulebooks(load_rulebook(EXPERT), load_rulebook(b))
    assert not d.identical
    assert d.cells[["output", "rule"]].values.tolist() == [["bound_3", 154]]
    row = d.cells.iloc[0]
    assert row["b"] == -12.5 and row["delta"] == pytest.approx(-12.5 - row["a"])
    assert d.peaks.empty and d.bounds_mode is None


def test_diff_reports_peaks_bounds_and_provenance(tmp_path):
    a = load_rulebook(EXPERT)
    knots, consts = a.arrays()
    knots[2, 1, 1] = 0.2  # bound_2: dist_to_goal 'near' peak 0.15 -> 0.2
    from xfuzzy_rrt.fuzzy.rulebook import Rulebook

    b = Rulebook.from_arrays(knots, consts, name="moved", bounds_mode="absolute",
                             provenance={"kind": "test"})
    d = diff_rulebooks(a, b)
    assert d.cells.empty
    assert d.peaks[["output", "input", "term"]].values.tolist() == [["bound_2", "dist_to_goal", "near"]]
    assert d.peaks.iloc[0]["shift"] == pytest.approx(0.05)
    assert d.bounds_mode == ("relative", "absolute")
    assert "provenance.kind" in set(d.documentary["field"]) and "name" in set(d.documentary["field"])
    assert not d.identical


def test_replay_of_identical_rulebooks_reports_no_divergence():
    scen = load_scenario(DEMO)
    a = load_rulebook(EXPERT)
    rep = replay_diff(scen, a, a, seed=3, max_iter=2000)
    assert rep.divergence is None and rep.plan_divergence is None
    assert rep.causes.empty
    assert rep.result_a.iterations == rep.result_b.iterations


def test_replay_finds_the_first_divergence_and_its_rule(tmp_path):
    scen = load_scenario(DEMO)
    r = _busiest_rule()
    b_dir = copy_expert(tmp_path)
    a = load_rulebook(EXPERT)
    _edit_rule(b_dir, "goal_bias", r, 0.95 if a.systems[0].consts[r] < 0.5 else 0.05)
    b = load_rulebook(b_dir)
    rep = replay_diff(scen, a, b, seed=0, max_iter=2000)
    assert rep.divergence is not None
    ta, tb = rep.result_a.trace, rep.result_b.trace
    k = rep.divergence - 1
    # everything before is identical, and the goal bias differs exactly there
    assert ta.iloc[:k]["goal_bias"].tolist() == tb.iloc[:k]["goal_bias"].tolist()
    assert ta.iloc[k]["goal_bias"] != tb.iloc[k]["goal_bias"]
    assert rep.causes[["output", "rule"]].values.tolist() == [["goal_bias", r]]
    assert first_divergence(ta, tb) == rep.divergence


def test_diff_cli_exit_codes_text_and_html(run_cli, tmp_path):
    b = copy_expert(tmp_path, "b")
    proc = run_cli("rules", "diff", EXPERT, b)
    assert proc.returncode == 0 and "identical" in proc.stdout
    _edit_rule(b, "step_size", 7, 4.0)
    proc = run_cli("rules", "diff", EXPERT, b, "--html", tmp_path / "d.html", "--replay", DEMO,
                   "--seed", "1", "--max-iter", "1500")
    assert proc.returncode == 1, proc.stderr
    changed = [line for line in proc.stdout.splitlines() if re.match(r"\s+r\d+: ", line)]
    assert len(changed) == 1 and changed[0].strip().startswith("r7: 10.0 -> 4.0")
    assert "replay demo-tissue seed 1" in proc.stdout
    page = (tmp_path / "d.html").read_text()
    assert "replay-a" in page and "replay-b" in page and "diff-step_size" in page
    proc = run_cli("rules", "diff", EXPERT, tmp_path / "nope")
    assert proc.returncode == 2 and proc.stderr.startswith("error: ")
    assert "Traceback" not in proc.stderr


def test_compact_and_full_layouts_of_one_rulebook_diff_identical(tmp_path, run_cli):
    rb = load_rulebook(EXPERT)
    save_rulebook(rb, tmp_path / "c", compact=True)
    assert diff_rulebooks(rb, load_rulebook(tmp_path / "c")).identical
    proc = run_cli("rules", "diff", EXPERT, tmp_path / "c")
    assert proc.returncode == 0
