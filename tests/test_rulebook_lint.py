"""``rules lint``: one bad-rulebook fixture per failure kind, driven through the console script.

Each fixture is the shipped expert rulebook copied to a temporary folder with one mutation of
its text. Every case must exit 2, print ``error: FILE:LINE: ...`` naming the right file and
line, and never a traceback.
"""

from __future__ import annotations

import re
from pathlib import Path

import pytest

from xfuzzy_rrt.errors import RulebookError
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook

from _rulebook_helpers import copy_expert


def _line_of(path: Path, needle: str) -> int:
    for n, line in enumerate(path.read_text().splitlines(), start=1):
        if needle in line:
            return n
    raise AssertionError(f"{needle!r} not in {path}")


def _edit(path: Path, old: str, new: str) -> None:
    text = path.read_text()
    assert text.count(old) >= 1, old
    path.write_text(text.replace(old, new, 1))


def _errors(proc) -> list[tuple[str, int | None, str]]:
    """Parse ``error: FILE[:LINE]: message`` lines."""
    out = []
    for line in proc.stderr.splitlines():
        m = re.match(r"error: (.+?)(?::(\d+))?: (.*)$", line)
        assert m, f"unexpected stderr line {line!r}"
        out.append((m.group(1), int(m.group(2)) if m.group(2) else None, m.group(3)))
    return out


def _lint(run_cli, root):
    proc = run_cli("rules", "lint", root)
    assert "Traceback" not in proc.stderr + proc.stdout
    return proc


def test_the_shipped_rulebook_is_clean(run_cli):
    from xfuzzy_rrt.fuzzy.rulebook import default_rulebook_path

    proc = _lint(run_cli, default_rulebook_path())
    assert proc.returncode == 0, proc.stderr
    assert proc.stdout.startswith("ok:")


# each case: (file, mutate(root) -> expected line, expected message fragment)
def _missing_rule(root):
    f = root / "step_size.fis"
    line = _line_of(f, "r312:")
    lines = f.read_text().splitlines(keepends=True)
    del lines[line - 1]
    f.write_text("".join(lines))
    return line, "missing rule r312"  # reported where it belongs: now r313's line


def _duplicate_rule(root):
    f = root / "goal_bias.fis"
    line = _line_of(f, "r40:")
    lines = f.read_text().splitlines(keepends=True)
    lines.insert(line, lines[line - 1].replace("r40: ", ""))
    f.write_text("".join(lines))
    return line + 1, f"same conditions as line {line}"


def _unknown_term(root):
    f = root / "bound_2.fis"
    line = _line_of(f, "r52:")
    _edit(f, "r52: if angle_to_goal is east_0 and dist_to_goal is medium", "r52: if angle_to_goal is east_0 and dist_to_goal is mediumish")
    return line, "unknown term 'mediumish'"


def _consequent_out_of_range(root):
    f = root / "goal_bias.fis"
    line = _line_of(f, "r4:")
    _edit(f, "then goal_bias = 0.8\n", "then goal_bias = 1.5\n")
    return line, "outside the output range"


def _peaks_not_increasing(root):
    f = root / "bound_3.fis"
    line = _line_of(f, "peaks 0.0 0.15 0.3 0.45 0.6")
    _edit(f, "peaks 0.0 0.15 0.3 0.45 0.6", "peaks 0.0 0.3 0.15 0.45 0.6")
    return line, "not strictly increasing"


def _peak_outside_range(root):
    f = root / "bound_4.fis"
    lines = f.read_text().splitlines()
    idx = [n for n, l in enumerate(lines, 1) if "peaks 0.0 0.15 0.3 0.45 0.6" in l][1]  # dist_to_obstacle
    lines[idx - 1] = "  peaks 0.0 0.15 0.3 0.75 0.6"
    f.write_text("\n".join(lines) + "\n")
    return idx, "outside the input range"


def _wrong_variable_name(root):
    f = root / "step_size.fis"
    line = _line_of(f, "input dist_to_goal range")
    _edit(f, "input dist_to_goal range", "input dist_to_gaol range")
    return line, "unknown input variable 'dist_to_gaol'"


def _truncated(root):
    f = root / "bound_1.fis"
    data = f.read_bytes()
    cut = data[: len(data) * 3 // 5]
    f.write_bytes(cut)
    return cut.count(b"\n") + 1, "truncated"


def _bad_manifest(root):
    f = root / "rulebook.toml"
    line = _line_of(f, "bounds_mode")
    _edit(f, 'bounds_mode = "relative"', 'bounds_mode = "sideways"')
    return line, "bounds_mode must be"


def _bad_manifest_syntax(root):
    f = root / "rulebook.toml"
    line = _line_of(f, "name =")
    _edit(f, 'name = "expert"', 'name = "expert')
    return line, "not valid TOML"


def _non_utf8(root):
    f = root / "step_size.fis"
    line = _line_of(f, "r600:")
    data = f.read_bytes().replace(b"r600: if angle_to_goal is east_2pi", b"r600: if angle_to_goal is east_2pi\xe9", 1)
    f.write_bytes(data)
    return line, "not valid UTF-8"


CASES = {
    "missing_rule": ("step_size.fis", _missing_rule),
    "duplicate_rule": ("goal_bias.fis", _duplicate_rule),
    "unknown_term": ("bound_2.fis", _unknown_term),
    "consequent_out_of_range": ("goal_bias.fis", _consequent_out_of_range),
    "peaks_not_increasing": ("bound_3.fis", _peaks_not_increasing),
    "peak_outside_range": ("bound_4.fis", _peak_outside_range),
    "wrong_variable_name": ("step_size.fis", _wrong_variable_name),
    "truncated_file": ("bound_1.fis", _truncated),
    "bad_manifest": ("rulebook.toml", _bad_manifest),
    "bad_manifest_syntax": ("rulebook.toml", _bad_manifest_syntax),
    "non_utf8": ("step_size.fis", _non_utf8),
}


@pytest.mark.parametrize("case", sorted(CASES))
def test_each_failure_kind_is_reported_with_file_and_line(case, run_cli, tmp_path):
    file, mutate = CASES[case]
    root = copy_expert(tmp_path)
    line, fragment = mutate(root)
    proc = _lint(run_cli, root)
    assert proc.returncode == 2, proc.stdout + proc.stderr
    assert proc.stdout == ""
    errors = _errors(proc)
    hits = [e for e in errors if e[0] == str(root / file) and e[1] == line and fragment in e[2]]
    assert hits, f"expected {file}:{line}: ...{fragment}... in\n{proc.stderr}"
    if case not in ("truncated_file",):
        assert len(errors) == 1, proc.stderr  # one mistake, one message (no cascades)


def test_truncated_file_reports_the_missing_rules_and_the_missing_end(run_cli, tmp_path):
    root = copy_expert(tmp_path)
    _truncated(root)
    messages = [e[2] for e in _errors(_lint(run_cli, root))]
    assert any(m.startswith("missing rules r") for m in messages)
    assert any("ends without 'end'" in m for m in messages)


def test_all_problems_in_all_files_are_reported_in_one_run(run_cli, tmp_path):
    root = copy_expert(tmp_path)
    _unknown_term(root)
    _bad_manifest(root)
    _peaks_not_increasing(root)
    _consequent_out_of_range(root)
    (root / "step_size.fis").unlink()
    proc = _lint(run_cli, root)
    assert proc.returncode == 2
    files = {Path(e[0]).name for e in _errors(proc)}
    assert files == {"bound_2.fis", "rulebook.toml", "bound_3.fis", "goal_bias.fis", "step_size.fis"}
    assert len(_errors(proc)) == 5


def test_missing_directory_and_unexpected_fis_file(run_cli, tmp_path):
    proc = _lint(run_cli, tmp_path / "nope")
    assert proc.returncode == 2 and "does not exist" in proc.stderr
    root = copy_expert(tmp_path)
    (root / "stepsize.fis").write_text("")
    proc = _lint(run_cli, root)
    assert proc.returncode == 2 and "stepsize.fis: unexpected FIS file" in proc.stderr


def test_library_error_carries_every_problem(tmp_path):
    root = copy_expert(tmp_path)
    _unknown_term(root)
    _wrong_variable_name(root)
    with pytest.raises(RulebookError) as info:
        load_rulebook(root)
    assert len(info.value.problems) == 2
    assert all(isinstance(line, int) for _, line, _ in info.value.problems)


@pytest.mark.parametrize(
    "old,new,fragment",
    [
        ("r5: if", "r6: if", "label r6 does not match"),
        ("format xfuzzy-rrt-fis 1", "format xfuzzy-rrt-fis 2", "unsupported format"),
        ("output goal_bias range 0.0 1.0", "output goal_bias range 0.0 2.0", "range of goal_bias must be"),
        ("terms very_near near medium far very_far", "terms very_near near near far very_far", "duplicate term"),
        ("then goal_bias = 0.3\n", "then goal_bias = nan\n", "not a finite number"),
        ("then goal_bias = 0.3\n", "then goal_bais = 0.3\n", "rule concludes 'goal_bais'"),
        ("r5: if angle_to_goal is east_0 and", "r5: if angle_to_goal is east_0 and angle_to_goal is north and", "appears twice"),
        ("end\n", "end\nr0: junk\n", "statement after 'end'"),
    ],
)
def test_more_text_problems(tmp_path, old, new, fragment):
    root = copy_expert(tmp_path)
    _edit(root / "goal_bias.fis", old, new)
    with pytest.raises(RulebookError) as info:
        load_rulebook(root)
    assert any(fragment in msg for _, _, msg in info.value.problems), info.value.lines()
