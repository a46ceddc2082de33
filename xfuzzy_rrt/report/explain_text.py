"""One Fuzzy-RRT expansion explained in numbers a person reads (what ``xfuzzy-rrt explain``
prints, and what the report's drill-down shows).

Why not :func:`xfuzzy_rrt.analysis.explain.render_text`: that rendering prints every number
with full precision (``strength 0.252873563218 × 0.28991466315272363``) so that it can be
re-derived bit for bit; it stays available as ``explain --exact``. Here every number has 4
significant digits and inputs carry their unit (read from the rulebook). The named format
functions below are the single definition both the command and the drill-down use, so the two
always agree (the tests compare them).
"""

from __future__ import annotations

from xfuzzy_rrt.report.numbers import qty, readable_numbers, sig


def units_of(rulebook) -> dict[str, str]:
    from xfuzzy_rrt.report.fuzzy_figures import semantics

    return semantics(rulebook)[4]


def fmt_input(x: float, unit: str = "") -> str:
    return qty(x, unit)


def fmt_degree(x: float) -> str:
    return sig(x)


def fmt_strength(x: float) -> str:
    return sig(x)


def fmt_constant(x: float) -> str:
    return sig(x)


def fmt_value(x: float) -> str:
    return sig(x)


def input_note(raw: float, clamped: float, unit: str = "") -> str:
    return "" if raw == clamped else f"measured {fmt_input(raw, unit)}, clamped"


def render_readable(e, units: dict[str, str]) -> str:
    """The explanation ``e`` (:class:`~xfuzzy_rrt.analysis.explain.Explanation`) as text."""
    from xfuzzy_rrt.analysis.explain import header_lines, render_text

    lines = header_lines(e)
    for name in e.inputs:
        c = e.clamped_inputs[name]
        note = input_note(e.inputs[name], c, units.get(name, ""))
        lines.append(f"  {name:18s} = {fmt_input(c, units.get(name, ''))}"
                     + (f" ({note})" if note else ""))
    for s in e.systems:
        lines += ["", f"== {s.output} =="]
        for name, terms in s.active.items():
            lines.append(f"  {name:18s}: " + ", ".join(f"{t.term} {fmt_degree(t.degree)}"
                                                       for t in terms))
        lines.append(f"  fired rules ({len(s.rules)}): strength = product of degrees / sum of "
                     "products")
        for r in s.rules:
            lines.append(f"    r{r.index}: {readable_numbers(r.sentence)}")
            lines.append(f"          strength {fmt_strength(r.strength)} \u00d7 "
                         f"{fmt_constant(r.constant)} = {fmt_strength(r.contribution)}")
        lines.append(f"  {s.output} = \u03a3 contributions = {fmt_value(s.value)}  "
                     f"(planner recorded {fmt_value(s.traced_value)})")
    decision = decision_lines(render_text(e))
    if decision:
        lines += ["", "Decision:"] + [f"  {line}" for line in decision]
    lines += ["", f"max |recomputed - recorded| = {e.max_discrepancy:.3g}"]
    return "\n".join(lines) + "\n"


def decision_lines(exact_text: str) -> list[str]:
    """The decision block of the exact rendering, with readable numbers."""
    text = exact_text.splitlines()
    if "Decision:" not in text:
        return []
    out = []
    for line in text[text.index("Decision:") + 1:]:
        if not line.strip():
            break
        out.append(readable_numbers(line.strip()))
    return out
