"""The FIS text format (``<output>.fis``): parse, format and every lint check.

Why this shape: a person must be able to answer "what does the planner do when the goal is
near and no obstacle is close?" with one ``grep``, review a retrained rulebook as a diff, and
edit a number by hand. So every rule is one self-contained sentence on its own line, in a fixed
order, and every number is written as Python's ``repr(float)`` (the shortest text that reads
back as the same float), which makes ``load -> save`` byte-identical and floats exact.

Example (``goal_bias.fis``, abridged)::

    # xfuzzy-rrt fuzzy inference system: goal_bias
    # ... (explanatory comment header)
    format xfuzzy-rrt-fis 1
    output goal_bias range 0.0 1.0

    input angle_to_goal range 0.0 6.283185307179586
      terms east_0 north west south east_2pi
      peaks 0.0 1.5707963267948966 3.141592653589793 4.71238898038469 6.283185307179586
    input dist_to_goal range 0.0 0.6
      terms very_near near medium far very_far
      peaks 0.0 0.15 0.3 0.45 0.6
    ...

    # angle_to_goal is east_0, dist_to_goal is very_near
    r0: if angle_to_goal is east_0 and dist_to_goal is very_near and angle_to_obstacle is east_0 and dist_to_obstacle is very_near then goal_bias = 0.05
    ...
    end

Grammar (one statement per line; ``#`` starts a comment anywhere; blank lines are ignored;
indentation is free; ``\\r\\n`` and a UTF-8 BOM are tolerated):

- ``format xfuzzy-rrt-fis 1`` — must be the first statement.
- ``output NAME range LO HI`` — NAME must be the file's stem; the range must be the SPEC range.
- ``input NAME range LO HI`` followed by ``terms T0 T1 T2 T3 T4`` and
  ``peaks LO P1 P2 P3 HI`` — the four inputs, in the fixed order. Term ``j`` peaks at
  ``peaks[j]``; the first and last are shoulders, so the first and last peaks must be the
  range ends and the peaks strictly increasing.
- ``[rN:] if IN is TERM and IN is TERM and IN is TERM and IN is TERM then OUTPUT = VALUE`` —
  one per antecedent, 625 in all. The ``rN:`` label is optional when reading but, if present,
  must be the rule's index ``((t0*5 + t1)*5 + t2)*5 + t3``; the four inputs may appear in any
  order. VALUE must lie within the output range.
- ``TERM`` may be ``any`` (a don't-care: every term of that input), e.g.
  ``if angle_to_goal is north and dist_to_goal is near and angle_to_obstacle is any and
  dist_to_obstacle is any then goal_bias = 0.6`` stands for the 25 rules it covers. A rule with
  ``any`` carries no ``rN:`` label (it has no single index). After expanding ``any``, the rules
  must cover each of the 625 cells exactly once: a cell covered twice is reported on the later
  rule's line naming the earlier rule's line; an uncovered region is reported as the patterns
  nobody covers, naming the rules on either side of it (in index order). ``any`` is therefore
  reserved and cannot be a term name. The model is always the full 625-constant grid; ``any``
  exists only in the text.
- ``end`` — must close the file (so that a truncated file is recognised as such).

Compact layout (``format_fis(..., compact=True)``, written by ``rules simplify``): the same
header and inputs, then the fewest rules with ``any`` that reproduce the 625 constants exactly
(:func:`~xfuzzy_rrt.fuzzy.cover.min_partition`), ordered by the first cell each covers;
single-cell rules keep their ``rN:`` label. A compact file reads back to the same constants, and
writing it compact again gives identical bytes. The *default* canonical layout stays the full
625-rule form, and ``Rulebook.sha256`` is always computed over the full form, so a rulebook's
identity does not depend on the layout it is stored in.

Comments on save: saving writes the *canonical* layout — the fixed comment header, one
``# <input 0> is ..., <input 1> is ...`` comment above each block of 25 rules, rules in index
order with their ``rN:`` labels, numbers as ``repr``. Comments and blank lines added by hand are
**not** preserved (keep notes in the manifest's ``description`` or ``provenance`` instead), and
a hand-reordered file is written back in index order. A canonical file reads and writes back
to identical bytes.

All checks collect *every* problem in one pass as ``(file, line, message)``; nothing stops at
the first.
"""

from __future__ import annotations

import bisect
import math
import re
from dataclasses import dataclass, field

from xfuzzy_rrt.fuzzy.cover import ANY, ANY_WORD, greedy_gap_patterns, pattern_cells
from xfuzzy_rrt.fuzzy.system import (
    FuzzySystem,
    InputPartition,
    peaks_problem,
    term_name_problem,
)
from xfuzzy_rrt.fuzzy import semantics as _sem
from xfuzzy_rrt.fuzzy.variables import N_RULES, N_TERMS, rule_index, rule_terms

FORMAT_NAME = "xfuzzy-rrt-fis"
FORMAT_VERSION = 1
SUFFIX = ".fis"

Problem = tuple[str, "int | None", str]

_RULE = re.compile(
    r"(?:r(?P<label>[0-9]+)\s*:\s*)?if\s+(?P<ante>.+?)\s+then\s+(?P<out>\S+)\s*=\s*(?P<value>\S+)\Z"
)
_CLAUSE = re.compile(r"(?P<var>\S+)\s+is\s+(?P<term>\S+)\Z")
_AND = re.compile(r"\s+and\s+")
_LABEL = re.compile(r"r([0-9]+)\s*:")
_LABEL_BYTES = re.compile(rb"\s*r([0-9]+)\s*:")


def fnum(value: float) -> str:
    """A float as the shortest text that reads back exactly (``repr``)."""
    return repr(float(value))


def _parse_float(text: str) -> float | None:
    """A finite float from *text*, or ``None`` (``nan``/``inf`` are not numbers here)."""
    try:
        v = float(text)
    except ValueError:
        return None
    return v if math.isfinite(v) else None


# --------------------------------------------------------------------------------- format


_UNITS_NOTE = {
    "paper": ["# clamped to it. Angles are workspace directions counter-clockwise from +x in radians",
              "# (0 and 2*pi are both east); distances are in metres."],
    "goal-frame": ["# clamped to it. Goal-frame semantics: joint_dist_to_goal and clearance_deg are in",
                   "# joint-space degrees, stagnation in iterations, reject_rate a share (0..1)."],
    "goal-frame-any": ["# clamped to it. Goal-frame-any semantics (any arm): norm_dist_to_goal, norm_clearance",
                       "# and the box and step outputs are in normalised degrees (joint-space degrees divided",
                       "# by sqrt(N/2), N joints in all), stall in iterations, reject_share a share (0..1)."],
}


def header_comment(output: str, sem: "_sem.Semantics" = _sem.PAPER) -> list[str]:
    """The fixed explanatory comment at the top of every canonical FIS file."""
    lo, hi = sem.output_ranges[output]
    return [
        f"# xfuzzy-rrt fuzzy inference system: {output} (range {fnum(lo)} .. {fnum(hi)})",
        "#",
        "# Zero-order Takagi-Sugeno: a rule fires with the product of its four memberships;",
        f"# {output} is the firing-weighted average of the rule constants.",
        "# Each input has five terms; term j peaks at peaks[j] and falls to 0 at the",
        "# neighbouring peaks (the first and last are shoulders). Inputs outside a range are",
        *_UNITS_NOTE[sem.name],
        "# Rules: one per line, in index order r = ((t0*5 + t1)*5 + t2)*5 + t3 (t = term index).",
        "# Edit numbers freely; '#' comments are ignored but not kept when a tool saves the file.",
    ]


def rule_sentence(fis: FuzzySystem, r: int) -> str:
    """Rule *r* of *fis* as the sentence the text format writes (without the ``rN:`` label)."""
    t = rule_terms(r)
    ante = " and ".join(f"{inp.name} is {inp.terms[t[i]]}" for i, inp in enumerate(fis.inputs))
    return f"if {ante} then {fis.output} = {fnum(fis.consts[r])}"


def pattern_sentence(fis: FuzzySystem, pattern, value: float) -> str:
    """A rule with don't-care terms (``-1`` in *pattern*) as the sentence the format writes."""
    ante = " and ".join(
        f"{inp.name} is {ANY_WORD if pattern[i] == ANY else inp.terms[pattern[i]]}"
        for i, inp in enumerate(fis.inputs))
    return f"if {ante} then {fis.output} = {fnum(value)}"


def format_fis(fis: FuzzySystem, compact: bool = False) -> str:
    """The canonical text of *fis* (``\\n`` line ends, trailing newline).

    ``compact=True`` writes the fewest rules with ``any`` terms that expand to exactly the same
    625 constants (see the module docstring).
    """
    lo, hi = fis.range
    lines = header_comment(fis.output, fis.semantics)
    if compact:
        lines += [
            "# Compact layout: 'INPUT is any' matches every term of that input; after expanding",
            "# 'any' the rules cover each of the 625 cells exactly once (rN labels: single cells).",
        ]
    lines.append(f"format {FORMAT_NAME} {FORMAT_VERSION}")
    lines.append(f"output {fis.output} range {fnum(lo)} {fnum(hi)}")
    lines.append("")
    for inp in fis.inputs:
        ilo, ihi = inp.range
        lines.append(f"input {inp.name} range {fnum(ilo)} {fnum(ihi)}")
        lines.append("  terms " + " ".join(inp.terms))
        lines.append("  peaks " + " ".join(fnum(p) for p in inp.peaks))
    if compact:
        from xfuzzy_rrt.fuzzy.cover import min_partition

        part = min_partition(fis.consts)
        lines.append("")
        lines.append(f"# {len(part)} rules")
        for pattern, value in part.rules:
            label = "" if ANY in pattern else f"r{rule_index(pattern)}: "
            lines.append(label + pattern_sentence(fis, pattern, value))
        lines.append("end")
        return "\n".join(lines) + "\n"
    names = [inp.name for inp in fis.inputs]
    terms = [inp.terms for inp in fis.inputs]
    block = N_TERMS * N_TERMS
    for r in range(len(fis.consts)):
        t = rule_terms(r)
        if r % block == 0:
            lines.append("")
            lines.append(f"# {names[0]} is {terms[0][t[0]]}, {names[1]} is {terms[1][t[1]]}")
        lines.append(f"r{r}: {rule_sentence(fis, r)}")
    lines.append("end")
    return "\n".join(lines) + "\n"


# ---------------------------------------------------------------------------------- parse


@dataclass
class _InputDecl:
    name: str
    line: int
    terms: tuple[str, ...] | None = None
    peaks: tuple[float, ...] | None = None
    terms_ok: bool = False
    peaks_ok: bool = False


@dataclass
class _State:
    file: str
    expected_output: str
    sem: "_sem.Semantics" = _sem.PAPER
    problems: list[Problem] = field(default_factory=list)
    saw_format: bool = False
    output_line: int | None = None
    output_ok: bool = False
    inputs: list[_InputDecl] = field(default_factory=list)
    rules: dict[int, tuple[int, float]] = field(default_factory=dict)  # r -> (line, value)
    saw_any: bool = False  # a rule used 'any': gaps are described as patterns
    # labels of rule lines that were reported as broken: not reported again as "missing"
    attempted: set[int] = field(default_factory=set)
    end_line: int | None = None
    # the output range the file declares (today's, or one the semantics had before), which
    # its rule constants must keep to
    declared: tuple[float, float] | None = None

    def problem(self, line: int | None, message: str) -> None:
        self.problems.append((self.file, line, message))


def decode_lines(data: bytes, file: str) -> tuple[list[str | None], list[Problem]]:
    """Split *data* into text lines; a line that is not UTF-8 becomes ``None`` plus a problem.

    Decoding line by line (rather than the whole file) lets lint report *which* lines are
    broken and still check the rest.
    """
    problems: list[Problem] = []
    if data.startswith(b"\xef\xbb\xbf"):
        data = data[3:]
    raw = data.split(b"\n")
    if raw and raw[-1] == b"":
        raw.pop()
    lines: list[str | None] = []
    for n, chunk in enumerate(raw, start=1):
        try:
            text = chunk.decode("utf-8")
        except UnicodeDecodeError as exc:
            problems.append(
                (file, n, f"not valid UTF-8 (byte 0x{chunk[exc.start]:02x} at column {exc.start + 1})")
            )
            lines.append(None)
            continue
        lines.append(text[:-1] if text.endswith("\r") else text)
    return lines, problems


def parse_fis(data: bytes, file: str, expected_output: str,
              semantics: "_sem.Semantics" = _sem.PAPER) -> tuple[FuzzySystem | None, list[Problem]]:
    """Parse one FIS file. Returns the system (``None`` if anything is wrong) and all problems.

    *file* is the name used in problem messages; *expected_output* is the output this file must
    describe (its stem); *semantics* (from the rulebook manifest, at its DOF) fixes the input
    names, their order and every range.
    """
    lines, problems = decode_lines(data, file)
    st = _State(file=file, expected_output=expected_output, sem=semantics, problems=problems)
    raw_lines = data.split(b"\n") if problems else []
    last_line = 0
    for n, raw in enumerate(lines, start=1):
        if raw is None:
            m = _LABEL_BYTES.match(raw_lines[n - 1]) if n - 1 < len(raw_lines) else None
            if m:
                st.attempted.add(int(m.group(1)))
            continue
        text = raw.split("#", 1)[0].strip()
        if not text:
            continue
        last_line = n
        if st.end_line is not None:
            st.problem(n, f"statement after 'end' (line {st.end_line}): {text[:60]!r}")
            continue
        _statement(st, n, text)
    _finish(st, len(lines), last_line)
    if st.problems:
        return None, st.problems
    return _build(st), []


def _statement(st: _State, n: int, text: str) -> None:
    words = text.split()
    key = words[0]
    if not st.saw_format and key != "format":
        st.problem(n, f"the first statement must be 'format {FORMAT_NAME} {FORMAT_VERSION}'")
        st.saw_format = True  # report once
    if key == "format":
        st.saw_format = True
        if words[1:] != [FORMAT_NAME, str(FORMAT_VERSION)]:
            st.problem(n, f"unsupported format {' '.join(words[1:])!r} (expected '{FORMAT_NAME} {FORMAT_VERSION}')")
    elif key == "output":
        _output(st, n, words)
    elif key == "input":
        _input(st, n, words)
    elif key in ("terms", "peaks"):
        _input_detail(st, n, key, words)
    elif key == "end":
        if len(words) != 1:
            st.problem(n, "'end' takes no arguments")
        st.end_line = n
    elif key == "if" or re.match(r"r[0-9]+\s*:", text):
        _rule(st, n, text)
    else:
        st.problem(n, f"unknown statement {key!r} (expected format, output, input, terms, peaks, a rule or end)")


def _range_problem(words: list[str], expected: tuple[float, float], what: str,
                   earlier: tuple[tuple[float, float], ...] = ()) -> str | None:
    """Check ``... range LO HI`` in words[2:]; return a problem or None. A range in *earlier*
    (one the semantics had before: :attr:`~xfuzzy_rrt.fuzzy.semantics.Semantics.
    earlier_output_ranges`) is accepted too."""
    if len(words) != 5 or words[2] != "range":
        return f"expected '{words[0]} {what} range LO HI'"
    lo, hi = _parse_float(words[3]), _parse_float(words[4])
    if lo is None or hi is None:
        return f"range of {what} must be two finite numbers, got {words[3]!r} {words[4]!r}"
    if (lo, hi) != expected and (lo, hi) not in earlier:
        return f"range of {what} must be {fnum(expected[0])} {fnum(expected[1])} (SPEC.md), got {words[3]} {words[4]}"
    return None


def _output(st: _State, n: int, words: list[str]) -> None:
    if st.output_line is not None:
        st.problem(n, f"second 'output' declaration (first on line {st.output_line})")
        return
    st.output_line = n
    name = words[1] if len(words) > 1 else ""
    if name != st.expected_output:
        st.problem(n, f"wrong output variable {name!r}: this file describes {st.expected_output!r}")
        return
    problem = _range_problem(words, st.sem.output_ranges[name], name,
                             st.sem.earlier_output_ranges.get(name, ()))
    if problem:
        st.problem(n, problem)
    else:
        st.declared = (_parse_float(words[3]), _parse_float(words[4]))
    st.output_ok = True


def _input(st: _State, n: int, words: list[str]) -> None:
    k = len(st.inputs)
    name = words[1] if len(words) > 1 else ""
    inputs = st.sem.inputs
    expected = inputs[k] if k < len(inputs) else None
    if expected is None:
        st.problem(n, f"too many inputs: {name!r} (a FIS has exactly {len(inputs)}: {', '.join(inputs)})")
        st.inputs.append(_InputDecl(name=name, line=n))
        return
    decl = _InputDecl(name=name, line=n)
    st.inputs.append(decl)
    if name != expected:
        hint = "unknown input variable" if name not in inputs else "input out of order"
        other = _sem.of_input(name)
        if other is not None and other.name != st.sem.name:
            hint = f"input of the {other.name} semantics (the manifest says {st.sem.name})"
        st.problem(n, f"{hint} {name!r} (input {k + 1} must be {expected!r})")
        decl.name = expected  # check the rest as if it were the expected one
        decl.line = n
        return
    problem = _range_problem(words, st.sem.input_ranges[name], name)
    if problem:
        st.problem(n, problem + _dof_hint(st.sem, name, words))


def _dof_hint(sem: "_sem.Semantics", name: str, words: list[str]) -> str:
    """``' (the range at dof = 2; the manifest says dof = 5)'`` when a range depends on the
    DOF and the file's range is that of another DOF (a FIS copied from another rulebook)."""
    if len(words) != 5:
        return ""
    got = (_parse_float(words[3]), _parse_float(words[4]))
    for d in range(_sem.MIN_DOF, _sem.MAX_DOF + 1):
        if d != sem.dof and sem.for_dof(d).input_ranges[name] == got:
            return f" (the range at dof = {d}; the manifest says dof = {sem.dof})"
    return ""


def _input_detail(st: _State, n: int, key: str, words: list[str]) -> None:
    if not st.inputs:
        st.problem(n, f"'{key}' outside an input declaration")
        return
    decl = st.inputs[-1]
    if (decl.terms if key == "terms" else decl.peaks) is not None:
        st.problem(n, f"second '{key}' line for input {decl.name!r}")
        return
    values = words[1:]
    if key == "terms":
        decl.terms = tuple(values)
        ok = True
        if len(values) != N_TERMS:
            st.problem(n, f"input {decl.name!r} needs {N_TERMS} terms, got {len(values)}")
            ok = False
        for t in values:
            problem = term_name_problem(t)
            if problem:
                st.problem(n, problem)
                ok = False
        dupes = sorted({t for t in values if values.count(t) > 1})
        if dupes:
            st.problem(n, f"duplicate term name(s) {', '.join(dupes)} for input {decl.name!r}")
            ok = False
        decl.terms_ok = ok
    else:
        parsed = [_parse_float(v) for v in values]
        bad = [v for v, p in zip(values, parsed) if p is None]
        decl.peaks = tuple(p if p is not None else math.nan for p in parsed)
        if bad:
            st.problem(n, f"peak {bad[0]!r} of {decl.name!r} is not a finite number")
            return
        lo, hi = st.sem.input_ranges.get(decl.name, (math.nan, math.nan))
        problem = peaks_problem(decl.peaks, lo, hi)
        if problem:
            st.problem(n, f"{decl.name}: {problem}")
            return
        decl.peaks_ok = True


def _rule(st: _State, n: int, text: str) -> None:
    text = " ".join(text.split())
    label_match = _LABEL.match(text)
    if label_match:
        st.attempted.add(int(label_match.group(1)))
    m = _RULE.match(text)
    if not m:
        st.problem(n, "malformed rule (expected 'if IN is TERM and ... then OUTPUT = VALUE')")
        return
    clauses = _AND.split(m.group("ante"))
    by_var: dict[str, str] = {}
    ok = True
    for clause in clauses:
        cm = _CLAUSE.match(clause)
        if not cm:
            st.problem(n, f"malformed condition {clause!r} (expected 'INPUT is TERM')")
            ok = False
            continue
        var, term = cm.group("var"), cm.group("term")
        if var not in st.sem.inputs:
            st.problem(n, f"unknown input variable {var!r} in rule (inputs: {', '.join(st.sem.inputs)})")
            ok = False
            continue
        if var in by_var:
            st.problem(n, f"input {var!r} appears twice in rule")
            ok = False
            continue
        by_var[var] = term
    missing = [v for v in st.sem.inputs if v not in by_var]
    if ok and missing:
        st.problem(n, f"rule has no condition on {', '.join(missing)} (every rule names all four inputs)")
        ok = False
    t_idx: list[int] = []
    decls = {d.name: d for d in st.inputs[: len(st.sem.inputs)]}
    for var in st.sem.inputs:
        if var not in by_var:
            continue
        decl = decls.get(var)
        if decl is None or not decl.terms_ok:
            ok = False  # the input's own declaration is already reported (or missing: reported at the end)
            continue
        term = by_var[var]
        if term == ANY_WORD:
            t_idx.append(ANY)
            continue
        if term not in decl.terms:
            st.problem(n, f"unknown term {term!r} for {var} (terms: {' '.join(decl.terms)})")
            ok = False
            continue
        t_idx.append(decl.terms.index(term))
    out = m.group("out")
    if out != st.expected_output:
        st.problem(n, f"rule concludes {out!r} but this file describes {st.expected_output!r}")
    value = _parse_float(m.group("value"))
    lo, hi = st.declared or st.sem.output_ranges[st.expected_output]
    if value is None:
        st.problem(n, f"consequent {m.group('value')!r} is not a finite number")
    elif not lo <= value <= hi:
        st.problem(n, f"consequent {m.group('value')} outside the output range [{fnum(lo)}, {fnum(hi)}] of {st.expected_output}")
    if not ok or len(t_idx) != len(st.sem.inputs):
        return
    label = m.group("label")
    if ANY in t_idx:
        _any_rule(st, n, tuple(t_idx), label, value)
        return
    r = rule_index(t_idx)
    if label is not None and int(label) != r:
        st.problem(n, f"rule label r{label} does not match its conditions (they make rule r{r})")
        return
    if r in st.rules:
        first = st.rules[r][0]
        if st.saw_any:
            st.problem(n, f"rule r{r} overlaps the rule on line {first} (which already covers it)")
        else:
            st.problem(n, f"duplicate rule r{r}: same conditions as line {first}")
        return
    st.rules[r] = (n, value if value is not None else math.nan)


def _any_rule(st: _State, n: int, pattern: tuple[int, ...], label: str | None,
              value: float | None) -> None:
    """Expand a rule with ``any`` terms onto its cells; report overlaps once per earlier rule."""
    st.saw_any = True
    if label is not None:
        st.problem(n, f"a rule with 'any' covers several cells and takes no label (drop 'r{label}:')")
        return
    cells = pattern_cells(pattern)
    clashes: dict[int, list[int]] = {}
    for r in cells.tolist():
        if r in st.rules:
            clashes.setdefault(st.rules[r][0], []).append(r)
    for line, rs in sorted(clashes.items()):
        st.problem(n, f"rule overlaps the rule on line {line} at {len(rs)} cell(s) "
                      f"(first r{rs[0]}: {_cell_text(st, rs[0])})")
    if clashes:
        return
    v = value if value is not None else math.nan
    for r in cells.tolist():
        st.rules[r] = (n, v)


def _cell_text(st: _State, r: int) -> str:
    t = rule_terms(r)
    decls = st.inputs[: len(st.sem.inputs)]
    return " and ".join(f"{d.name} is {d.terms[t[k]]}" for k, d in enumerate(decls))


def _finish(st: _State, n_lines: int, last_line: int) -> None:
    """File-level checks once every line has been seen."""
    at_end = last_line if last_line else (n_lines or 1)
    if not st.saw_format:
        st.problem(at_end, "empty file (no statements)")
        return
    if st.output_line is None:
        st.problem(at_end, f"missing 'output {st.expected_output} range LO HI' declaration")
    for decl in st.inputs[: len(st.sem.inputs)]:
        if decl.terms is None:
            st.problem(decl.line, f"input {decl.name!r} has no 'terms' line")
        if decl.peaks is None:
            st.problem(decl.line, f"input {decl.name!r} has no 'peaks' line")
    for name in st.sem.inputs[len(st.inputs):]:
        st.problem(at_end, f"missing declaration of input {name!r}")
    inputs_ok = len(st.inputs) >= len(st.sem.inputs) and all(
        d.terms_ok for d in st.inputs[: len(st.sem.inputs)]
    )
    if inputs_ok:
        _report_missing_rules(st, at_end)
    if st.end_line is None:
        st.problem(at_end, f"file ends without 'end' (truncated? {len(st.rules)} of {N_RULES} rules read)")


def _report_missing_rules(st: _State, at_end: int) -> None:
    """Group missing rule indices into runs; report each run where it belongs."""
    present = sorted(st.rules)
    missing = [r for r in range(N_RULES) if r not in st.rules and r not in st.attempted]
    if not missing:
        return
    if st.saw_any:
        _report_gaps(st, present, missing, at_end)
        return
    runs: list[tuple[int, int]] = []
    start = prev = missing[0]
    for r in missing[1:]:
        if r != prev + 1:
            runs.append((start, prev))
            start = r
        prev = r
    runs.append((start, prev))
    decls = st.inputs[: len(st.sem.inputs)]
    for a, b in runs:
        # the line of the next present rule (where the missing one belongs), else the end
        i = bisect.bisect_right(present, b)
        line = st.rules[present[i]][0] if i < len(present) else (st.end_line or at_end)
        if a == b:
            t = rule_terms(a)
            ante = " and ".join(f"{d.name} is {d.terms[t[k]]}" for k, d in enumerate(decls))
            st.problem(line, f"missing rule r{a}: if {ante}")
        else:
            st.problem(line, f"missing rules r{a}..r{b} ({b - a + 1} rules)")


def _report_gaps(st: _State, present: list[int], missing: list[int], at_end: int) -> None:
    """Gaps in a file that uses ``any``: each uncovered region as a pattern, reported on the
    line of the rule that follows it in index order and naming the rule before it."""
    mask = [False] * N_RULES
    for r in missing:
        mask[r] = True
    decls = st.inputs[: len(st.sem.inputs)]
    for pattern in greedy_gap_patterns(mask):
        cells = pattern_cells(pattern)
        a, b = int(cells[0]), int(cells[-1])
        i = bisect.bisect_right(present, b)
        after = st.rules[present[i]][0] if i < len(present) else None
        j = bisect.bisect_left(present, a) - 1
        before = st.rules[present[j]][0] if j >= 0 else None
        ante = " and ".join(
            f"{d.name} is {ANY_WORD if pattern[k] == ANY else d.terms[pattern[k]]}"
            for k, d in enumerate(decls))
        where = []
        if before is not None:
            where.append(f"after the rule on line {before}")
        if after is not None:
            where.append(f"before the rule on line {after}")
        line = after if after is not None else (st.end_line or at_end)
        st.problem(line, f"gap: no rule covers {len(cells)} cell(s) 'if {ante}' "
                         f"({', '.join(where) or 'no rules at all'})")


def _build(st: _State) -> FuzzySystem:
    inputs = tuple(
        InputPartition(name=d.name, terms=d.terms, peaks=d.peaks, dof=st.sem.dof) for d in st.inputs
    )
    consts = tuple(st.rules[r][1] for r in range(N_RULES))
    return FuzzySystem(output=st.expected_output, inputs=inputs, consts=consts, dof=st.sem.dof)
