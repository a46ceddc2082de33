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

from xfuzzy_rrt.cli.common import check_seed_option, check_workers_option, rulebook_arg

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
    rulebook: Path = typer.Argument(..., help="Rulebook directory (or a shipped rulebook's name).", callback=rulebook_arg),
    input: Path = typer.Option(..., "--input", help="CSV with the rulebook's four inputs (paper: angle_to_goal, dist_to_goal, angle_to_obstacle, dist_to_obstacle)."),
    output: Path = typer.Option(..., "--output", help="CSV to write: the input rows with the rulebook's outputs appended (six at 2 DOF; goal_bias, bound_1 ... bound_2N, step_size for a paper rulebook of N joints)."),
) -> int:
    """Evaluate the rulebook on every row of a CSV (inputs outside a range are clamped)."""
    from xfuzzy_rrt.atomic import atomic_path
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
    from xfuzzy_rrt.fuzzy.tables import evaluate_frame, read_inputs_csv

    rb = load_rulebook(rulebook)
    df = read_inputs_csv(input, rb.inputs)
    result = evaluate_frame(rb, df)
    from xfuzzy_rrt.cli.common import warn
    from xfuzzy_rrt.fuzzy.tables import clamped_inputs

    for name, n, lo, hi in clamped_inputs(rb, df):
        warn(f"{input}: {name}: {n} of {len(df)} values outside [{lo:g}, {hi:g}] were clamped "
             "to the range")
    with atomic_path(output) as tmp:
        result.to_csv(tmp, index=False, float_format="%.17g")
    _out(_eval_echo(result, rb, output))
    return 0


#: Rows of ``rules eval`` output echoed on the terminal (the file has them all).
ECHO_ROWS = 5


def _eval_echo(result, rb, output: Path) -> str:
    """What ``rules eval`` wrote, and its first rows with 4 significant digits and units (the
    file keeps full precision)."""
    from xfuzzy_rrt.report.fuzzy_figures import semantics, with_unit
    from xfuzzy_rrt.report.numbers import sig

    units = semantics(rb)[4]
    head = result.head(ECHO_ROWS)
    cols = list(head.columns)
    table = [[with_unit(c, units) for c in cols]]
    for _, row in head.iterrows():
        table.append([sig(v) if isinstance(v, (int, float)) else str(v) for v in row])
    widths = [max(len(r[j]) for r in table) for j in range(len(cols))]
    lines = [f"wrote {len(result)} rows to {output} (full precision); first "
             f"{len(head)}:"]
    lines += ["  " + "  ".join(c.rjust(w) for c, w in zip(r, widths)) for r in table]
    return "\n".join(lines)


@app.command("lint")
def lint(rulebook: Path = typer.Argument(..., help="Rulebook directory (or a shipped rulebook's name).", callback=rulebook_arg)) -> int:
    """Validate a rulebook; report every problem as FILE:LINE: problem (exit 2)."""
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook

    rb = load_rulebook(rulebook)
    kind = f"{rb.bounds_mode} bounds" if rb.bounds_mode else f"{rb.semantics.name} semantics"
    if rb.dof != 2:  # 2-DOF lines stay as they were
        kind += f", dof {rb.dof}: {len(rb.systems)} FIS"
    _out(f"ok: {rulebook}: rulebook {rb.name!r} ({kind}), sha256 {rb.sha256}")
    return 0


def _num(v: float) -> str:
    """Numbers for people: 4 significant digits (the rulebook files keep every digit)."""
    from xfuzzy_rrt.report.numbers import sig

    return sig(v)


def _readable(text: str, exact: bool) -> str:
    from xfuzzy_rrt.report.numbers import readable_numbers

    return text if exact else readable_numbers(text)


@app.command("show")
def show(
    rulebook: Path = typer.Argument(..., help="Rulebook directory (or a shipped rulebook's name).", callback=rulebook_arg),
    when: Optional[List[str]] = typer.Option(
        None, "--when",
        help="List the rules matching INPUT=TERM conditions (repeatable or comma-separated), "
             "e.g. --when dist_to_goal=near,dist_to_obstacle=very_far.",
    ),
    rules: bool = typer.Option(False, "--rules", help="Print every FIS's rules in the compact "
                               "layout (fewest rules, 'any' terms; same constants)."),
    exact: bool = typer.Option(False, "--exact", help="Print numbers with full precision "
                               "instead of 4 significant digits."),
) -> int:
    """Readable summary: provenance, terms and peaks, rule count, consequent statistics."""
    from xfuzzy_rrt.fuzzy.manifest import thaw
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
    from xfuzzy_rrt.fuzzy.summary import consequent_stats, matching_rules, parse_conditions
    from xfuzzy_rrt.fuzzy.variables import N_RULES

    rb = load_rulebook(rulebook)
    if rules:
        from xfuzzy_rrt.fuzzy.cover import min_partition
        from xfuzzy_rrt.fuzzy.text_format import pattern_sentence

        lines = []
        for s in rb.systems:
            part = min_partition(s.consts)
            lines.append(f"# {s.output}: {len(part)} rules (compact, exact)")
            lines += [_readable(pattern_sentence(s, pat, v), exact) for pat, v in part.rules]
        _out("\n".join(lines))
        return 0
    if when:
        where = parse_conditions(when, rb)
        rows = matching_rules(rb, where)
        inputs = rb.systems[0].inputs
        header = ["rule", *rb.inputs, *rb.outputs]
        table = [header]
        for r, t, values in rows:
            table.append([f"r{r}", *(inputs[i].terms[t[i]] for i in range(len(rb.inputs))),
                          *(repr(float(v)) if exact else _num(v) for v in values)])
        widths = [max(len(row[j]) for row in table) for j in range(len(header))]
        lines = ["  ".join(cell.ljust(w) for cell, w in zip(row, widths)).rstrip() for row in table]
        lines.append(f"{len(rows)} of {N_RULES} rules")
        _out("\n".join(lines))
        return 0

    lines = [f"rulebook {rb.name!r}  ({rulebook})", f"  semantics: {rb.semantics.summary}",
             f"  bounds mode: {rb.bounds_mode or '(none: not the paper semantics)'}",
             f"  dof: {'any' if rb.semantics.dof_free else rb.dof} ({len(rb.systems)} FIS: {rb.outputs[0]} \u2026 {rb.outputs[-1]})",
             f"  sha256: {rb.sha256}"]
    if rb.description:
        lines.append(f"  description: {rb.description}")
    lines.append("provenance:")
    def flat(prefix: str, mapping: dict) -> None:
        for key, value in mapping.items():
            if isinstance(value, dict):
                flat(f"{prefix}{key}.", value)
            elif (isinstance(value, list) and len(value) > 3 and not exact
                  and all(isinstance(v, dict) for v in value)):
                names = [str(v.get("name", "?")) for v in value]
                lines.append(f"  {prefix}{key}: {len(value)} entries ({names[0]} \u2026 "
                             f"{names[-1]}; --exact lists them)")
            else:
                text = str(value)
                lines.append(f"  {prefix}{key}: "
                             + (_readable(text, exact) if isinstance(value, float) else text))

    flat("", thaw(rb.provenance))
    from xfuzzy_rrt.report.fuzzy_figures import semantics
    from xfuzzy_rrt.report.numbers import unit_of

    units = semantics(rb)[4]
    lines.append("inputs (terms @ peaks; the first and last terms are shoulders):")
    shared = all(s.inputs == rb.systems[0].inputs for s in rb.systems)
    groups = [("all systems", rb.systems[0])] if shared else [(s.output, s) for s in rb.systems]
    for label, s in groups:
        if not shared:
            lines.append(f"  [{label}]")
        for inp in s.inputs:
            lo, hi = inp.range
            num = (lambda v: repr(float(v))) if exact else _num
            unit = units.get(inp.name, "")
            unit = " " + unit_of(unit) if unit else ""
            terms = ", ".join(f"{t} @ {num(p)}" for t, p in zip(inp.terms, inp.peaks))
            lines.append(f"  {inp.name} [{num(lo)}, {num(hi)}]{unit}: {terms}")
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
    rulebook: Path = typer.Argument(..., help="Rulebook directory (or a shipped rulebook's name).", callback=rulebook_arg),
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
    fll_dir: Path = typer.Argument(..., help="Directory with goal_bias.fll ... step_size.fll (the DOF follows from the bound_K.fll files present)."),
    out: Path = typer.Option(..., "--out", help="Rulebook directory to write."),
    name: Optional[str] = typer.Option(None, "--name", help="Rulebook name (default: from the export, else the directory name)."),
    bounds_mode: Optional[BoundsMode] = typer.Option(
        None, "--bounds-mode", help="How bounds are meant (default: from the export, else absolute)."),
) -> int:
    """Build a rulebook from FLL engines (the reverse of export)."""
    from xfuzzy_rrt.fuzzy.fll import import_fll
    from xfuzzy_rrt.fuzzy.rulebook import save_rulebook

    if name is not None and not name.strip():
        from xfuzzy_rrt.errors import InputError

        raise InputError("--name", "must be a non-empty rulebook name")
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


# ------------------------------------------------------------------ analysis: coverage


def _command_line() -> str:
    import shlex

    return "xfuzzy-rrt " + " ".join(shlex.quote(a) for a in sys.argv[1:])


def _expand_sources(sources: List[Path]) -> tuple[list[Path], list[Path]]:
    """Split arguments into scenario files (a directory: its ``*.toml``) and trace files."""
    from xfuzzy_rrt.errors import InputError

    scenarios: list[Path] = []
    traces: list[Path] = []
    for p in sources:
        if p.is_dir():
            found = sorted(p.glob("*.toml"))
            if not found:
                raise InputError(str(p), "directory holds no *.toml scenario files")
            scenarios += found
        elif p.suffix.lower() in (".parquet", ".csv"):
            traces.append(p)
        else:
            scenarios.append(p)
    return scenarios, traces


@app.command("coverage")
def coverage(
    rulebook: Path = typer.Argument(..., help="Rulebook directory (or a shipped rulebook's name).", callback=rulebook_arg),
    sources: List[Path] = typer.Argument(..., help="Scenario TOML files or directories (planned "
                                         "--runs times each), or saved trace files (.parquet/.csv)."),
    runs: int = typer.Option(10, "--runs", min=1, help="Runs per scenario (seeds seed..seed+runs-1)."),
    seed: int = typer.Option(0, "--seed", callback=check_seed_option, help="First seed."),
    max_iter: int = typer.Option(10_000, "--max-iter", min=1, max=1_000_000, help="Iteration budget per run."),
    workers: int = typer.Option(1, "--workers", callback=check_workers_option, min=1, help="Worker processes."),
    out: Optional[Path] = typer.Option(None, "--out", help="CSV: one row per FIS and rule (3,750 rows at 2 DOF)."),
    html: Optional[Path] = typer.Option(None, "--html", help="HTML page with 25x25 heatmaps per FIS."),
    top: int = typer.Option(5, "--top", min=0, help="Rules to list per FIS (largest output mass)."),
) -> int:
    """Which rules fire, how strongly, on or off the final path; dead rules; coverage."""
    from xfuzzy_rrt.analysis.coverage import (
        collect_counts, counts_from_trace_files, coverage_frame, coverage_summary)
    from xfuzzy_rrt.atomic import atomic_path, write_text_atomic
    from xfuzzy_rrt.cli.common import load_scenario_warn
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook

    rb = load_rulebook(rulebook)
    scen_paths, trace_paths = _expand_sources(sources)
    scenarios = [load_scenario_warn(p) for p in scen_paths]
    counts = counts_from_trace_files(trace_paths, rb)
    if scenarios:
        counts.add(collect_counts(rb, scenarios, runs=runs, seed=seed, max_iter=max_iter,
                                  workers=workers))
    cov = coverage_frame(counts, rb)
    summary = coverage_summary(cov, counts.iterations)
    page = None
    if html is not None:  # render everything before writing anything
        from xfuzzy_rrt.report.coverage_figure import coverage_page

        page = coverage_page(cov, summary, rb, command=_command_line())
    if out is not None:
        with atomic_path(out) as tmp:
            cov.to_csv(tmp, index=False, float_format="%.17g")
    if page is not None:
        write_text_atomic(html, page)
    lines = [f"rulebook {rb.name!r} (sha256 {rb.sha256[:12]}...): {counts.runs} runs, "
             f"{counts.successes} successful, {counts.iterations} iterations",
             summary.to_string(index=False, float_format=lambda x: f"{x:.3f}")]
    tot = summary.iloc[-1]
    n_all = len(cov)
    lines.append(f"{tot['rules_fired']} of {n_all} rules ({tot['coverage']:.1%}) fired at least "
                 f"once; {tot['rules_carrying_90']} ({tot['share_carrying_90']:.1%}) carry 90 % "
                 "of the output mass (per FIS, largest share first)")
    if top:
        for o in summary["output"][:-1]:
            g = cov[cov["output"] == o].sort_values("rank").head(top)
            lines.append(f"{o}: top {len(g)} rules by output mass")
            for row in g.itertuples(index=False):
                lines.append(f"  r{row.rule:<4} share {row.mass_share:.4f}  fired {row.fired:>6} "
                             f"(on path {row.fired_on_path})  = {row.constant:.6g}  if {row.antecedent}")
    written = [str(p) for p in (out, html) if p is not None]
    if written:
        lines.append("wrote " + ", ".join(written))
    _out("\n".join(lines))
    return 0


# ---------------------------------------------------------------------- analysis: diff


def _short(value, width: int = 72) -> str:
    """A value in at most ``width`` characters (long lists and texts say how long they are)."""
    text = repr(value)
    if len(text) <= width:
        return text
    size = f"{len(value)} items" if isinstance(value, (list, tuple)) else f"{len(text)} chars"
    return f"{text[:width - 20]}... ({size})"


def _documentary_lines(doc, limit: int) -> list[str]:
    """Documentary differences, compact: changed values shortened, keys that only one side has
    listed by name on one line per side (an FLL round trip drops the whole provenance)."""
    from xfuzzy_rrt.analysis.diff import ABSENT

    lines = []
    only = {"a": [], "b": []}
    changed = []
    for f in doc.itertuples(index=False):
        if f.b is ABSENT:
            only["a"].append(f.field)
        elif f.a is ABSENT:
            only["b"].append(f.field)
        else:
            changed.append(f)
    for f in changed[:limit]:
        lines.append(f"note: {f.field}: {_short(f.a)} -> {_short(f.b)}")
    if len(changed) > limit:
        lines.append(f"note: ... and {len(changed) - limit} more documentary differences "
                     "(--limit, --html)")
    for side, other in (("a", "b"), ("b", "a")):
        keys = only[side]
        if keys:
            shown = ", ".join(keys[:limit]) + (f", ... ({len(keys) - limit} more)"
                                               if len(keys) > limit else "")
            lines.append(f"note: {len(keys)} key(s) only in {side} (absent in {other}): {shown}")
    return lines


@app.command("diff")
def diff(
    a: Path = typer.Argument(..., help="Rulebook directory A (or a shipped rulebook's name).", callback=rulebook_arg),
    b: Path = typer.Argument(..., help="Rulebook directory B (or a shipped rulebook's name).", callback=rulebook_arg),
    html: Optional[Path] = typer.Option(None, "--html", help="Write an HTML page of the differences."),
    out: Optional[Path] = typer.Option(None, "--out", help="CSV of every changed cell."),
    limit: int = typer.Option(50, "--limit", min=0, help="Changed cells to print per FIS."),
    replay: Optional[Path] = typer.Option(None, "--replay", help="Scenario to plan with both rulebooks."),
    seed: int = typer.Option(0, "--seed", callback=check_seed_option, help="Seed for --replay."),
    max_iter: int = typer.Option(10_000, "--max-iter", min=1, max=1_000_000, help="Iteration budget for --replay."),
) -> int:
    """Exit 0 when A and B behave identically, 1 when they differ (differences on stdout)."""
    from xfuzzy_rrt.analysis.diff import diff_rulebooks, replay_diff
    from xfuzzy_rrt.atomic import atomic_path, write_text_atomic
    from xfuzzy_rrt.cli.common import load_scenario_warn
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook

    ra, rb = load_rulebook(a), load_rulebook(b)
    scenario = load_scenario_warn(replay) if replay is not None else None
    d = diff_rulebooks(ra, rb)
    lines = [f"a: {a} ({ra.name}, sha256 {ra.sha256[:12]}...)",
             f"b: {b} ({rb.name}, sha256 {rb.sha256[:12]}...)"]
    if d.identical:
        lines.append("identical: every FIS evaluates identically and the bounds mode is the same")
    for row in d.per_output().itertuples(index=False):
        if row.cells_changed or row.peaks_moved:
            lines.append(f"{row.output}: {row.cells_changed} cells changed "
                         f"(max |b - a| {row.max_abs_delta:.6g}), {row.peaks_moved} peaks moved")
            g = d.cells[d.cells["output"] == row.output]
            if row.cells_rounding_only:
                lines.append(f"  {row.cells_rounding_only} of them differ only by float rounding "
                             "(<= 1e-12 relative; listed with --out)")
                g = g[~d.rounding_mask(g)]
            for c in g.head(limit).itertuples(index=False):
                lines.append(f"  r{c.rule}: {c.a!r} -> {c.b!r} ({c.delta:+.6g})  if {c.antecedent}")
            if len(g) > limit:
                lines.append(f"  ... and {len(g) - limit} more (--limit, --out)")
            for p in d.peaks[d.peaks["output"] == row.output].itertuples(index=False):
                lines.append(f"  peak {p.input}.{p.term}: {p.a!r} -> {p.b!r} ({p.shift:+.6g})")
    if d.bounds_mode:
        lines.append(f"bounds mode: {d.bounds_mode[0]} -> {d.bounds_mode[1]}")
    lines.extend(_documentary_lines(d.documentary, limit))
    rep = None
    if scenario is not None:
        rep = replay_diff(scenario, ra, rb, seed=seed, max_iter=max_iter)
        lines.append(f"replay {rep.scenario} seed {seed}:")
        if rep.divergence is None:
            lines.append(f"  no divergence: identical decisions in all {rep.result_a.iterations} iterations")
        else:
            plan_note = (f"the plan itself (sample, outcome) first differs at iteration "
                         f"{rep.plan_divergence}" if rep.plan_divergence is not None else
                         "the plans are identical (same samples, outcomes and nodes in all "
                         f"{rep.result_a.iterations} iterations)")
            lines.append(f"  first divergence at iteration {rep.divergence} (decisions before it "
                         f"identical); {plan_note}")
            for q in rep.decisions.itertuples(index=False):
                lines.append(f"    {q.quantity}: {q.a} | {q.b}")
            for c in rep.causes.itertuples(index=False):
                lines.append(f"    cause {c.output} r{c.rule}: strength {c.strength_a:.4g} | "
                             f"{c.strength_b:.4g}, constant {c.constant_a:.6g} -> {c.constant_b:.6g}"
                             f"  if {c.antecedent}")
            if rep.plan_divergence is not None and rep.plan_divergence != rep.divergence:
                lines.append(f"  at iteration {rep.plan_divergence} (plan divergence):")
                for c in rep.plan_causes.itertuples(index=False):
                    lines.append(f"    cause {c.output} r{c.rule}: strength {c.strength_a:.4g} | "
                                 f"{c.strength_b:.4g}, constant {c.constant_a:.6g} -> "
                                 f"{c.constant_b:.6g}  if {c.antecedent}")
        for o in rep.outcomes().itertuples(index=False):
            lines.append(f"  {o.rulebook} ({o.name}): success {o.success}, {o.iterations} iterations, "
                         f"{o.nodes} nodes, cost {o.cost_deg:.2f} deg")
    page = None
    if html is not None:  # render everything before writing anything
        from xfuzzy_rrt.report.diff_page import diff_page

        page = diff_page(d, ra, rb, replay=rep, scenario=scenario, command=_command_line())
    if out is not None:
        with atomic_path(out) as tmp:
            d.cells.to_csv(tmp, index=False, float_format="%.17g")
        lines.append(f"wrote {out}")
    if page is not None:
        write_text_atomic(html, page)
        lines.append(f"wrote {html}")
    _out("\n".join(lines))
    return 0 if d.identical else 1


# ------------------------------------------------------------------ analysis: simplify


def _measures_text(before, after) -> str:
    cols = ["rules", "mean_antecedent_length", "distinct_constants", "dead_cells", "dead_rules",
            "max_jaccard"]
    head = f"  {'output':<10}" + "".join(f" {c:>22}" for c in cols)
    lines = [head]
    for (_, x), (_, y) in zip(before.iterrows(), after.iterrows()):
        cells = []
        for c in cols:
            a, b = x[c], y[c]
            fa = "-" if a != a else (f"{a:.3g}" if isinstance(a, float) else str(a))
            fb = "-" if b != b else (f"{b:.3g}" if isinstance(b, float) else str(b))
            cells.append(f" {fa + ' -> ' + fb:>22}")
        lines.append(f"  {x['output']:<10}" + "".join(cells))
    return "\n".join(lines)


@app.command("simplify")
def simplify_cmd(
    rulebook: Path = typer.Argument(..., help="Rulebook directory (or a shipped rulebook's name).", callback=rulebook_arg),
    out: Path = typer.Option(..., "--out", help="Directory to write the simplified (compact) rulebook."),
    name: Optional[str] = typer.Option(None, "--name", help="Name of the new rulebook (default NAME-simplified)."),
    budget: Optional[str] = typer.Option(None, "--budget", help="Allow lossy steps within e.g. 'iterations+10%' "
                                         "(mean iterations over --scenario x --seeds)."),
    scenario: Optional[List[Path]] = typer.Option(None, "--scenario", help="Scenario for the budget check (repeatable)."),
    seeds: int = typer.Option(10, "--seeds", min=1, help="Seeds per scenario for the budget check."),
    seed: int = typer.Option(0, "--seed", callback=check_seed_option, help="First seed of the budget check."),
    max_iter: int = typer.Option(10_000, "--max-iter", min=1, max=1_000_000, help="Iteration budget per run."),
    levels: Optional[int] = typer.Option(None, "--levels", help="Round constants to K levels per FIS (lossy)."),
    tolerance: Optional[float] = typer.Option(None, "--tolerance", help="Merge rules whose constants differ "
                                              "by at most this share of the output range (lossy)."),
    absorb: Optional[str] = typer.Option(None, "--absorb", help="'dead' or 'weak:SHARE': such cells take "
                                         "their neighbours' values (lossy)."),
    strict: bool = typer.Option(False, "--strict", help="Require loss + 1.645 standard errors "
                                "(paired over seeds) to be within the budget, not just the mean."),
    workers: int = typer.Option(1, "--workers", callback=check_workers_option, min=1, help="Worker processes for the budget runs."),
    holdout_seeds: Optional[int] = typer.Option(None, "--holdout-seeds", min=1, help="Fresh seeds per scenario (never searched on) to re-measure a lossy result's loss (default: --seeds)."),
) -> int:
    """Fewest 'any' rules with the same constants; lossy steps only within a stated budget."""
    from xfuzzy_rrt.analysis.simplify import simplify as run_simplify
    from xfuzzy_rrt.cli.common import load_scenario_warn
    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, save_rulebook

    rb = load_rulebook(rulebook)
    if out.exists() and out.resolve() == rulebook.resolve():
        raise InputError("--out", "refusing to overwrite the source rulebook; choose another directory")
    scenarios = [load_scenario_warn(p) for p in (scenario or [])]
    res = run_simplify(rb, name=name, command=_command_line(), budget=budget, scenarios=scenarios,
                       seeds=seeds, seed=seed, max_iter=max_iter, levels=levels,
                       tolerance=tolerance, absorb=absorb, strict=strict, workers=workers,
                       holdout_seeds=holdout_seeds)
    save_rulebook(res.rulebook, out, compact=True)
    lines = [f"source {rulebook}: {rb.name!r}, sha256 {rb.sha256[:12]}..."]
    rel = res.budget is not None and res.budget.relative

    def loss_text(v: float) -> str:
        return f"{v:+.2%}" if rel else f"{v:+.2f} iterations"

    if res.budget is not None:
        lines.append(f"budget {res.budget} on {', '.join(s.name for s in scenarios)} x {seeds} seeds "
                     f"(seeds {seed}..{seed + seeds - 1}); source mean iterations {res.base_mean:.2f}")
        for c in res.candidates.itertuples(index=False):
            if c.mean_iterations != c.mean_iterations:  # NaN: stopped early
                lines.append(f"  tried {c.candidate:<28} {c.rules:>5} rules  over budget "
                             "(stopped early: the iterations so far already exceed it)")
                continue
            se = f" (± {abs(c.loss_se):.2%} s.e.)" if rel else ""
            verdict = "within budget" if c.within_budget else "over budget"
            lines.append(f"  tried {c.candidate:<28} {c.rules:>5} rules  mean iterations "
                         f"{c.mean_iterations:9.2f}  success {c.success_rate:.2f}  "
                         f"loss {loss_text(c.loss)}{se}  {verdict}")
    kind = "lossless" if res.lossless else f"lossy ({res.chosen.label})"
    before = int(res.measures_before["rules"].iloc[-1])
    lines.append(f"result: {kind}; rules {before} -> {res.lossless_rules} lossless -> "
                 f"{res.chosen.rules} written")
    not_proven = [s.output for s, p in zip(rb.systems, res.chosen.partitions) if not p.optimal]
    lines.append("rule count: proven minimal for every FIS (exact 0/1 programme)" if not not_proven
                 else f"rule count: not proven minimal for {', '.join(not_proven)} (solver time limit)")
    if res.budget is not None:
        lines.append(f"measured on the searched seeds: mean iterations {res.base_mean:.2f} -> "
                     f"{res.new_mean:.2f} (loss {loss_text(res.loss)}, budget {res.budget})")
    if res.holdout_loss is not None:
        first, last = res.holdout_seeds
        verdict = "within budget" if res.holdout_within_budget else "OVER BUDGET"
        lines.append(f"held out (fresh seeds {first}..{last}, not searched on): mean iterations "
                     f"{res.holdout_base_mean:.2f} -> {res.holdout_new_mean:.2f} "
                     f"(loss {loss_text(res.holdout_loss)}; {verdict})")
        if not res.holdout_within_budget:
            lines.append("warning: the loss on fresh seeds exceeds the budget; the in-sample "
                         "figure was luck of the searched seeds (try more --seeds or --strict)")
    if res.absorbed_cells:
        lines.append(f"warning: {res.absorbed_cells} cells that never fired (or were weak) on the "
                     "budget runs changed value; behaviour elsewhere may differ")
    lines.append("interpretability (before -> after):")
    lines.append(_measures_text(res.measures_before, res.measures_after))
    lines.append(f"wrote {out} ({res.rulebook.name!r}, sha256 {res.rulebook.sha256[:12]}...; "
                 "compact layout)")
    _out("\n".join(lines))
    return 0
