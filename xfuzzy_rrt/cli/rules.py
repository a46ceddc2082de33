"""``xfuzzy-rrt rules``: evaluate, lint, show, export and import rulebooks.

Thin by design: arguments in, library call, text out. Problems surface as
:class:`~xfuzzy_rrt.errors.InputError`/:class:`~xfuzzy_rrt.errors.RulebookError` raised by the
library; ``cli/main.py`` prints them (``error: FILE:LINE: problem``) and exits 2. numba and
pandas are imported inside the commands so ``xfuzzy-rrt --help`` stays fast.
"""

from __future__ import annotations

import enum
import sys
from pathlib import Path
from typing import List, Optional

import typer

app = typer.Typer(help="Inspect, validate, evaluate and convert rulebooks.", no_args_is_help=True)


class ExportFormat(str, enum.Enum):
    fll = "fll"


class BoundsMode(str, enum.Enum):
    absolute = "absolute"
    relative = "relative"


def _out(text: str) -> None:
    sys.stdout.write(text if text.endswith("\n") else text + "\n")


@app.command("eval")
def eval_(
    rulebook: Path = typer.Argument(..., help="Rulebook directory."),
    input: Path = typer.Option(..., "--input", help="CSV with angle_to_goal, dist_to_goal, angle_to_obstacle, dist_to_obstacle."),
    output: Path = typer.Option(..., "--output", help="CSV to write: the input rows with the six outputs appended."),
) -> int:
    """Evaluate the rulebook on every row of a CSV (inputs outside a range are clamped)."""
    from xfuzzy_rrt.atomic import atomic_path
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
    from xfuzzy_rrt.fuzzy.tables import evaluate_frame, read_inputs_csv

    rb = load_rulebook(rulebook)
    df = read_inputs_csv(input)
    result = evaluate_frame(rb, df)
    with atomic_path(output) as tmp:
        result.to_csv(tmp, index=False, float_format="%.17g")
    return 0


@app.command("lint")
def lint(rulebook: Path = typer.Argument(..., help="Rulebook directory.")) -> int:
    """Validate a rulebook; report every problem as FILE:LINE: problem (exit 2)."""
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook

    rb = load_rulebook(rulebook)
    _out(f"ok: {rulebook}: rulebook {rb.name!r} ({rb.bounds_mode} bounds), sha256 {rb.sha256}")
    return 0


def _num(v: float) -> str:
    return f"{v:.6g}"


@app.command("show")
def show(
    rulebook: Path = typer.Argument(..., help="Rulebook directory."),
    when: Optional[List[str]] = typer.Option(
        None, "--when",
        help="List the rules matching INPUT=TERM conditions (repeatable or comma-separated), "
             "e.g. --when dist_to_goal=near,dist_to_obstacle=very_far.",
    ),
) -> int:
    """Readable summary: provenance, terms and peaks, rule count, consequent statistics."""
    from xfuzzy_rrt.fuzzy.manifest import thaw
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
    from xfuzzy_rrt.fuzzy.summary import consequent_stats, matching_rules, parse_conditions
    from xfuzzy_rrt.fuzzy.variables import INPUTS, N_RULES, OUTPUTS

    rb = load_rulebook(rulebook)
    if when:
        where = parse_conditions(when, rb)
        rows = matching_rules(rb, where)
        inputs = rb.systems[0].inputs
        header = ["rule", *INPUTS, *OUTPUTS]
        table = [header]
        for r, t, values in rows:
            table.append([f"r{r}", *(inputs[i].terms[t[i]] for i in range(len(INPUTS))),
                          *(_num(v) for v in values)])
        widths = [max(len(row[j]) for row in table) for j in range(len(header))]
        lines = ["  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip() for row in table]
        lines.append(f"{len(rows)} of {N_RULES} rules")
        _out("\n".join(lines))
        return 0

    lines = [f"rulebook {rb.name!r}  ({rulebook})", f"  bounds mode: {rb.bounds_mode}",
             f"  sha256: {rb.sha256}"]
    if rb.description:
        lines.append(f"  description: {rb.description}")
    lines.append("provenance:")
    def flat(prefix: str, mapping: dict) -> None:
        for key, value in mapping.items():
            if isinstance(value, dict):
                flat(f"{prefix}{key}.", value)
            else:
                lines.append(f"  {prefix}{key}: {value}")

    flat("", thaw(rb.provenance))
    lines.append("inputs (terms @ peaks; the first and last terms are shoulders):")
    shared = all(s.inputs == rb.systems[0].inputs for s in rb.systems)
    groups = [("all systems", rb.systems[0])] if shared else [(s.output, s) for s in rb.systems]
    for label, s in groups:
        if not shared:
            lines.append(f"  [{label}]")
        for inp in s.inputs:
            lo, hi = inp.range
            terms = ", ".join(f"{t} @ {_num(p)}" for t, p in zip(inp.terms, inp.peaks))
            lines.append(f"  {inp.name} [{_num(lo)}, {_num(hi)}]: {terms}")
    lines.append(f"rules: {N_RULES} per system, {N_RULES * len(rb.systems)} in all")
    lines.append("consequents:")
    stats = consequent_stats(rb)
    lines.append(f"  {'output':<10} {'range':<14} {'min':>9} {'mean':>9} {'median':>9} {'max':>9} {'distinct':>8}")
    for st in stats:
        rng = f"[{_num(st.range[0])}, {_num(st.range[1])}]"
        lines.append(
            f"  {st.output:<10} {rng:<14} {_num(st.min):>9} {_num(st.mean):>9} "
            f"{_num(st.median):>9} {_num(st.max):>9} {st.distinct:>8}"
        )
    _out("\n".join(lines))
    return 0


@app.command("export")
def export(
    rulebook: Path = typer.Argument(..., help="Rulebook directory."),
    format: ExportFormat = typer.Option(ExportFormat.fll, "--format", help="Export format."),
    out: Path = typer.Option(..., "--out", help="Directory to write <output>.fll files into."),
) -> int:
    """Export one FLL engine per output FIS (pyfuzzylite 8 loads them)."""
    from xfuzzy_rrt.fuzzy.fll import export_fll
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook

    rb = load_rulebook(rulebook)
    paths = export_fll(rb, out)
    _out(f"wrote {len(paths)} FLL files to {out}")
    return 0


@app.command("import")
def import_(
    fll_dir: Path = typer.Argument(..., help="Directory with goal_bias.fll ... step_size.fll."),
    out: Path = typer.Option(..., "--out", help="Rulebook directory to write."),
    name: Optional[str] = typer.Option(None, "--name", help="Rulebook name (default: from the export, else the directory name)."),
    bounds_mode: Optional[BoundsMode] = typer.Option(
        None, "--bounds-mode", help="How bounds are meant (default: from the export, else absolute)."),
) -> int:
    """Build a rulebook from FLL engines (the reverse of export)."""
    from xfuzzy_rrt.fuzzy.fll import import_fll
    from xfuzzy_rrt.fuzzy.rulebook import save_rulebook

    command = f"xfuzzy-rrt rules import {fll_dir} --out {out}"
    if name:
        command += f" --name {name}"
    if bounds_mode:
        command += f" --bounds-mode {bounds_mode.value}"
    rb = import_fll(fll_dir, name=name, bounds_mode=bounds_mode.value if bounds_mode else None,
                    command=command)
    save_rulebook(rb, out)
    _out(f"wrote rulebook {rb.name!r} to {out} (sha256 {rb.sha256})")
    return 0
