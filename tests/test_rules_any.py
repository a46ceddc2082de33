"""The ``any`` don't-care term: parsing, compact layout, gaps and overlaps, FLL export."""

from __future__ import annotations

import re

import numpy as np
import pytest

from xfuzzy_rrt.errors import RulebookError
from xfuzzy_rrt.fuzzy.fll import export_fll
from xfuzzy_rrt.fuzzy.rulebook import Rulebook, load_rulebook, save_rulebook
from xfuzzy_rrt.fuzzy.text_format import format_fis, parse_fis
from xfuzzy_rrt.fuzzy.variables import N_RULES, OUTPUTS, default_knots, INPUTS, rule_terms

from _rulebook_helpers import EXPERT, copy_expert


def _structured_rulebook(seed: int = 0) -> Rulebook:
    """Constants that depend on only some inputs plus a few odd cells, so 'any' merges exist."""
    rng = np.random.default_rng(seed)
    knots = np.array([[default_knots(i) for i in INPUTS]] * len(OUTPUTS))
    consts = np.empty((len(OUTPUTS), N_RULES))
    t = np.array([rule_terms(r) for r in range(N_RULES)])
    for f in range(len(OUTPUTS)):
        base = 0.1 * t[:, 1] + 0.05 * t[:, 3]
        odd = rng.choice(N_RULES, 7, replace=False)
        base[odd] = 0.9
        consts[f] = base if f in (0, 5) else base * 100 - 50
    return Rulebook.from_arrays(knots, consts, name="structured", bounds_mode="relative",
                                provenance={"kind": "test"})


def _fis_header(path) -> list[str]:
    text = path.read_text().splitlines()
    first_rule = next(i for i, line in enumerate(text) if line.startswith("r0:"))
    return text[:first_rule]


def test_compact_layout_reads_back_to_the_same_constants_and_bytes(tmp_path):
    rb = _structured_rulebook()
    save_rulebook(rb, tmp_path / "c", compact=True)
    back = load_rulebook(tmp_path / "c")
    assert np.array_equal(back.arrays()[1], rb.arrays()[1])
    assert np.array_equal(back.arrays()[0], rb.arrays()[0])
    assert back.sha256 == rb.sha256  # identity is the full canonical form
    for name, text in back.texts(compact=True).items():
        assert (tmp_path / "c" / name).read_text() == text
    n_lines = sum(1 for line in (tmp_path / "c" / "goal_bias.fis").read_text().splitlines()
                  if " then " in line)
    assert n_lines < N_RULES
    assert "is any" in (tmp_path / "c" / "goal_bias.fis").read_text()


def test_default_save_keeps_the_full_layout_and_bytes(tmp_path):
    rb = load_rulebook(EXPERT)
    save_rulebook(rb, tmp_path / "full")
    for name in rb.texts():
        assert (tmp_path / "full" / name).read_bytes() == (EXPERT / name).read_bytes()


def test_hand_written_any_rule_expands_to_its_cells(tmp_path):
    rb_dir = copy_expert(tmp_path)
    fis = load_rulebook(rb_dir).system("step_size")
    text = format_fis(fis, compact=True)
    # the expert step size is one constant: one rule with four 'any'
    rules = [line for line in text.splitlines() if " then " in line]
    assert rules == ["if angle_to_goal is any and dist_to_goal is any and angle_to_obstacle is "
                     "any and dist_to_obstacle is any then step_size = 10.0"]
    edited = text.replace("step_size = 10.0", "step_size = 7.5")
    parsed, problems = parse_fis(edited.encode(), "step_size.fis", "step_size")
    assert problems == []
    assert parsed.consts == (7.5,) * N_RULES


def _compact_lines(rb: Rulebook, output: str) -> list[str]:
    return format_fis(rb.system(output), compact=True).splitlines()


def test_gap_after_expansion_is_rejected_with_file_line_naming_both_neighbours(tmp_path):
    rb = _structured_rulebook()
    lines = _compact_lines(rb, "goal_bias")
    idx = [i for i, line in enumerate(lines) if " then " in line and "is any" in line]
    victim = idx[len(idx) // 2]
    del lines[victim]
    _, problems = parse_fis(("\n".join(lines) + "\n").encode(), "goal_bias.fis", "goal_bias")
    assert problems, "a removed rule must leave a gap"
    gap = [p for p in problems if "gap" in p[2]]
    assert gap
    file, line, message = gap[0]
    assert file == "goal_bias.fis" and isinstance(line, int)
    assert re.search(r"after the rule on line \d+", message)
    assert re.search(r"before the rule on line \d+", message)


def test_overlap_after_expansion_is_rejected_naming_both_lines(tmp_path):
    rb = _structured_rulebook()
    lines = _compact_lines(rb, "bound_1")
    first_any = next(i for i, line in enumerate(lines) if " then " in line and "is any" in line)
    # a full-grid rule overlaps every other rule
    lines.insert(first_any + 1, "if angle_to_goal is any and dist_to_goal is any and "
                                "angle_to_obstacle is any and dist_to_obstacle is any then bound_1 = 1.0")
    _, problems = parse_fis(("\n".join(lines) + "\n").encode(), "bound_1.fis", "bound_1")
    overlaps = [p for p in problems if "overlaps the rule on line" in p[2]]
    assert overlaps
    assert {p[1] for p in overlaps} == {first_any + 2}  # 1-based line of the inserted rule
    # one message per earlier rule it overlaps, each naming that rule's line
    named = {int(re.search(r"on line (\d+)", p[2]).group(1)) for p in overlaps}
    assert first_any + 1 in named


def test_lint_cli_rejects_a_gap_with_file_and_line(tmp_path, run_cli):
    rb = _structured_rulebook()
    save_rulebook(rb, tmp_path / "c", compact=True)
    path = tmp_path / "c" / "bound_2.fis"
    lines = path.read_text().splitlines()
    victim = next(i for i, line in enumerate(lines) if " then " in line and "is any" in line)
    del lines[victim]
    path.write_text("\n".join(lines) + "\n")
    proc = run_cli("rules", "lint", tmp_path / "c")
    assert proc.returncode == 2
    assert re.match(rf"error: {re.escape(str(path))}:\d+: gap: no rule covers", proc.stderr)
    assert "Traceback" not in proc.stderr


def test_label_on_an_any_rule_and_a_term_named_any_are_rejected():
    rb = _structured_rulebook()
    lines = _compact_lines(rb, "bound_3")
    i = next(i for i, line in enumerate(lines) if " then " in line and "is any" in line)
    lines[i] = "r7: " + lines[i]
    _, problems = parse_fis(("\n".join(lines) + "\n").encode(), "bound_3.fis", "bound_3")
    assert any("takes no label" in p[2] and p[1] == i + 1 for p in problems)
    with pytest.raises(ValueError, match="reserved"):
        Rulebook.from_arrays(rb.arrays()[0], rb.arrays()[1], name="x", bounds_mode="absolute",
                             term_names={"dist_to_goal": ("any", "b", "c", "d", "e")})


def test_fll_export_of_a_compact_rulebook_is_the_full_expansion(tmp_path):
    rb = _structured_rulebook()
    save_rulebook(rb, tmp_path / "c", compact=True)
    save_rulebook(rb, tmp_path / "f")
    a = export_fll(load_rulebook(tmp_path / "c"), tmp_path / "fa")
    b = export_fll(load_rulebook(tmp_path / "f"), tmp_path / "fb")
    for pa, pb in zip(a, b):
        assert pa.read_bytes() == pb.read_bytes()
        assert pa.read_text().count("  rule: ") == N_RULES


def test_rulebook_error_lists_problems_of_a_damaged_compact_rulebook(tmp_path):
    rb = _structured_rulebook()
    save_rulebook(rb, tmp_path / "c", compact=True)
    path = tmp_path / "c" / "bound_4.fis"
    assert "angle_to_obstacle is any" in path.read_text()
    text = path.read_text().replace("angle_to_obstacle is any", "angle_to_obstacle is north", 1)
    path.write_text(text)
    with pytest.raises(RulebookError) as info:
        load_rulebook(tmp_path / "c")
    assert any("gap" in m for _, _, m in info.value.problems)


def test_show_rules_prints_the_compact_layout(run_cli):
    proc = run_cli("rules", "show", EXPERT, "--rules")
    assert proc.returncode == 0, proc.stderr
    rb = load_rulebook(EXPERT)
    for s in rb.systems:
        n = sum(1 for line in format_fis(s, compact=True).splitlines() if " then " in line)
        assert f"# {s.output}: {n} rules (compact, exact)" in proc.stdout
    assert proc.stdout.count(" then ") < N_RULES * len(OUTPUTS)
