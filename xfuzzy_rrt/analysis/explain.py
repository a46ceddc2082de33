"""Explain one Fuzzy-RRT expansion so that an auditor can re-derive every number by hand.

Given a trace row and the rulebook that produced it, :func:`explain_row` lists for each of the
rulebook's fuzzy systems (six at 2 DOF; ``2N + 2`` for a paper rulebook of N joints): the (clamped) inputs, the terms active on each input with their membership
degrees (each system has its own term peaks), every fired rule as a sentence with its constant,
normalised strength and contribution ``strength × constant``, and the output — recomputed here
from the rulebook as ``Σ strength × constant`` and compared with the value the compiled planner
recorded. It then shows how the outputs became the planner's decision (sampling box, step,
sample, outcome).

Strengths are recomputed from the memberships (product AND, normalised by their sum) rather
than copied from the trace, and then checked against the trace, so a disagreement between the
compiled engine, the trace and the rulebook text would show up here.
"""

from __future__ import annotations

import re

from dataclasses import dataclass
from pathlib import Path

import numpy as np
import pandas as pd

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.membership import partition
from xfuzzy_rrt.fuzzy.text_format import rule_sentence
from xfuzzy_rrt.fuzzy import semantics as _sem
from xfuzzy_rrt.fuzzy.variables import MAX_FIRED, rule_terms


@dataclass(frozen=True)
class ActiveTerm:
    term: str
    index: int
    degree: float


@dataclass(frozen=True)
class FiredRule:
    index: int
    sentence: str
    constant: float
    strength: float
    traced_strength: float

    @property
    def contribution(self) -> float:
        return self.strength * self.constant


@dataclass(frozen=True)
class SystemExplanation:
    output: str
    active: dict[str, tuple[ActiveTerm, ...]]
    rules: tuple[FiredRule, ...]
    value: float
    traced_value: float


@dataclass(frozen=True)
class Explanation:
    iteration: int
    rulebook: str
    bounds_mode: str
    inputs: dict[str, float]
    clamped_inputs: dict[str, float]
    systems: tuple[SystemExplanation, ...]
    decision: dict[str, object]

    @property
    def max_discrepancy(self) -> float:
        """Largest |recomputed − traced| over outputs and strengths (should be ~1e-15)."""
        worst = 0.0
        for s in self.systems:
            worst = max(worst, abs(s.value - s.traced_value))
            for r in s.rules:
                worst = max(worst, abs(r.strength - r.traced_strength))
        return worst


#: What explaining a run of no iteration says: a planner whose start is its goal returns the
#: path ``[start, goal]`` before its first iteration (planners/extend.py, join_start_at_goal).
NO_ITERATION = "the run made no iteration (its start is its goal), so no decision to explain"


def load_trace(path: str | Path) -> pd.DataFrame:
    """Read a trace written by ``plan --trace`` (Parquet or CSV by suffix)."""
    path = Path(path)
    if not path.exists():
        raise InputError(str(path), "no such file")
    try:
        if path.suffix.lower() == ".parquet":
            frame = pd.read_parquet(path)
        elif path.suffix.lower() == ".csv":
            frame = pd.read_csv(path)
        else:
            raise InputError(str(path), "expected a .parquet or .csv trace, or a .json result")
    except InputError:
        raise
    except Exception as exc:  # pandas/pyarrow raise many types for unreadable files
        raise InputError(str(path), f"cannot read trace: {exc}") from None
    # the trace's columns say which semantics made it (input names are unique per semantics);
    # a trace of several arms read by a paper rulebook has them once per arm (``arm<k>_``)
    columns = arm_view(frame.iloc[0], 1).index if arm_count(frame.columns) else frame.columns
    sem = _sem.of_columns(columns)
    missing = [c for c in ("iteration", *sem.inputs, *sem.outputs, "rulebook_sha256")
               if c not in columns]
    if missing:
        raise InputError(str(path), f"not a Fuzzy-RRT trace: missing column(s) {', '.join(missing)}")
    return frame


_ARM_PREFIX = re.compile(r"arm(\d+)_")


def arm_count(columns) -> int:
    """How many arms a trace reads one at a time (``arm<k>_`` column prefixes; 0: none).

    The paper's semantics evaluates its rulebook once per arm, from that arm's end effector, so
    a trace of two arms has every input, output and fired-rule column twice."""
    arms = {int(m.group(1)) for c in map(str, columns) if (m := _ARM_PREFIX.match(c))}
    return max(arms) if arms else 0


def arm_view(row: pd.Series, arm: int) -> pd.Series:
    """Trace row ``row`` as arm ``arm`` (1-based) saw it: its ``arm<k>_`` columns without the
    prefix, plus the columns every arm shares (sample, box, outcome, ...)."""
    prefix = f"arm{arm}_"
    data = {k: v for k, v in row.items() if not _ARM_PREFIX.match(str(k))}
    data.update({str(k)[len(prefix):]: v for k, v in row.items() if str(k).startswith(prefix)})
    return pd.Series(data)


def explain_rows(row: pd.Series, rulebook) -> list[Explanation]:
    """One :class:`Explanation` per arm the rulebook read in this row (one without arms)."""
    n = arm_count(row.index)
    if not n:
        return [explain_row(row, rulebook)]
    return [explain_row(arm_view(row, a), rulebook) for a in range(1, n + 1)]


def trace_row(frame: pd.DataFrame, iteration: int, where: str = "--iteration") -> pd.Series:
    if len(frame) == 0:
        raise InputError(where, NO_ITERATION)
    rows = frame.index[frame["iteration"] == iteration]
    if len(rows) == 0:
        raise InputError(where, f"iteration {iteration} is not in the trace "
                         f"(1..{int(frame['iteration'].max())})")
    return frame.loc[rows[0]]


def explain_row(row: pd.Series, rulebook) -> Explanation:
    """Explain one trace row with ``rulebook`` (must be the rulebook that made the trace)."""
    if str(row["rulebook_sha256"]) != rulebook.sha256:
        raise InputError("--rulebook", f"rulebook {rulebook.name!r} (sha256 {rulebook.sha256[:12]}…) "
                         f"is not the one that made this trace (sha256 "
                         f"{str(row['rulebook_sha256'])[:12]}…)")
    x = {name: float(row[name]) for name in rulebook.inputs}
    systems = []
    clamped: dict[str, float] = {}
    for f, output in enumerate(rulebook.outputs):
        fis = rulebook.systems[f]
        degrees = []
        active: dict[str, tuple[ActiveTerm, ...]] = {}
        for i, inp in enumerate(fis.inputs):
            lo, hi = inp.range
            clamped[inp.name] = min(max(x[inp.name], lo), hi)
            mu = partition(np.array([x[inp.name]]), inp.peaks)[0]
            degrees.append(mu)
            active[inp.name] = tuple(ActiveTerm(inp.terms[j], j, float(mu[j]))
                                     for j in range(len(mu)) if mu[j] > 0.0)
        traced = {int(row[f"{output}_rule_{k}"]): float(row[f"{output}_strength_{k}"])
                  for k in range(MAX_FIRED) if int(row[f"{output}_rule_{k}"]) >= 0}
        raw: list[tuple[int, float]] = []
        for r in range(len(fis.consts)):
            t = rule_terms(r)
            w = degrees[0][t[0]] * degrees[1][t[1]] * degrees[2][t[2]] * degrees[3][t[3]]
            if w > 0.0:
                raw.append((r, float(w)))
        total = sum(w for _, w in raw)
        rules = []
        for r, w in raw:
            rules.append(FiredRule(index=r, sentence=rule_sentence(fis, r),
                                   constant=fis.consts[r], strength=w / total,
                                   traced_strength=traced.get(r, float("nan"))))
        value = sum(rr.contribution for rr in rules)
        systems.append(SystemExplanation(output=output, active=active, rules=tuple(rules),
                                         value=value, traced_value=float(row[output])))
    js = trace_joints(row.index) or [1, 2]
    decision = {k: row[k] for k in (
        "from_node", *(f"from_q{j}_deg" for j in js),
        *(c for j in js for c in (f"box_q{j}_lo", f"box_q{j}_hi")),
        "step_used_deg", "goal_sampled", *(f"sample_q{j}_deg" for j in js),
        "nearest_node", *(f"new_q{j}_deg" for j in js), "outcome", "new_node", "tree_size",
        "on_path", "tree", "grow_nodes", "connect_nodes")
        if k in row}
    return Explanation(iteration=int(row["iteration"]), rulebook=rulebook.name,
                       bounds_mode=rulebook.bounds_mode, inputs=x, clamped_inputs=clamped,
                       systems=tuple(systems), decision=decision)


def trace_joints(columns) -> list[int]:
    """Joint numbers ``1 … N`` whose ``box_q<j>_lo`` column a trace has (the trace's DOF).

    Why from the columns: a trace of N joints carries ``*_q1 … *_qN`` columns, and explaining
    must not assume two.
    """
    cols = set(map(str, columns))
    n = 0
    while f"box_q{n + 1}_lo" in cols or f"new_q{n + 1}_deg" in cols:
        n += 1
    return list(range(1, n + 1))


def _joints_text(d: dict, fmt: str) -> list[str]:
    """``[fmt(j)…]`` values of every joint present in decision *d*, e.g. ``sample_q{j}_deg``."""
    out, j = [], 1
    while fmt.format(j=j) in d:
        out.append(f"{d[fmt.format(j=j)]:.6g}")
        j += 1
    return out


def _box_text(d: dict) -> str:
    """``joint 1 [lo, hi] deg, joint 2 [lo, hi] deg, …`` for every joint in the decision."""
    parts, j = [], 1
    while f"box_q{j}_lo" in d:
        parts.append(f"joint {j} [{d[f'box_q{j}_lo']:.6g}, {d[f'box_q{j}_hi']:.6g}] deg")
        j += 1
    return ", ".join(parts)


def header_lines(e: Explanation) -> list[str]:
    """The first lines of every rendering: iteration, rulebook, what the inputs measure."""
    if e.bounds_mode:  # the paper's semantics
        kind, where = f"bounds: {e.bounds_mode}", "measured from the end effector of the current node"
    elif "tree" in e.decision:  # a Fuzzy-RRT-Connect trace: the target stands for the goal
        grown = "start" if int(e.decision["tree"]) == 0 else "goal"
        kind = f"goal-frame semantics, Fuzzy-RRT-Connect, {grown} tree grows"
        where = ("measured at the growing tree's current node, in joint space; 'goal' is the "
                 "other tree's newest node")
    else:
        kind, where = "goal-frame semantics", "measured at the current node, in joint space"
    return [f"Iteration {e.iteration} \u2014 rulebook {e.rulebook!r} ({kind})", "",
            f"Inputs ({where}; clamped to the ranges):"]


def render_text(e: Explanation) -> str:
    """A plain-text rendering (what ``xfuzzy-rrt explain`` prints)."""
    lines = header_lines(e)
    for name in e.inputs:
        raw, c = e.inputs[name], e.clamped_inputs[name]
        note = "" if raw == c else f" (measured {raw!r}, clamped)"
        lines.append(f"  {name:18s} = {c!r}{note}")
    for s in e.systems:
        lines += ["", f"== {s.output} =="]
        for name, terms in s.active.items():
            lines.append(f"  {name:18s}: " + ", ".join(f"{t.term} {t.degree:.6g}" for t in terms))
        lines.append(f"  fired rules ({len(s.rules)}): strength = product of degrees / sum of products")
        for r in s.rules:
            lines.append(f"    r{r.index}: {r.sentence}")
            lines.append(f"          strength {r.strength:.12g} × {r.constant!r} = {r.contribution:.12g}")
        lines.append(f"  {s.output} = Σ contributions = {s.value!r}  (planner recorded {s.traced_value!r})")
    d = e.decision
    if d:
        lines += ["", "Decision:"]
        if "box_q1_lo" in d and not e.bounds_mode:
            lines.append(f"  sampling region (bounding box of the box along the direction to the "
                         f"goal, or the whole joint space for a uniform sample): {_box_text(d)}")
        elif "box_q1_lo" in d:
            lines.append(f"  sampling box: {_box_text(d)}"
                         + (f" (bounds offset from node {int(d['from_node'])} at "
                            f"[{', '.join(_joints_text(d, 'from_q{j}_deg'))}], clipped to the joint limits)"
                            if e.bounds_mode == "relative" else " (clipped to the joint limits)"))
        if "step_used_deg" in d:
            lines.append(f"  step used: {d['step_used_deg']:.6g} deg")
        if "sample_q1_deg" in d:
            src = ("the goal (goal bias)" if bool(d.get("goal_sampled"))
                   else "uniform in the box" if e.bounds_mode else "uniform in the region")
            lines.append(f"  sample: [{', '.join(_joints_text(d, 'sample_q{j}_deg'))}] from {src}")
        if "nearest_node" in d:
            lines.append(f"  nearest node: {int(d['nearest_node'])}; new configuration "
                         f"[{', '.join(_joints_text(d, 'new_q{j}_deg'))}]")
        if "outcome" in d:
            lines.append(f"  outcome: {d['outcome']}; tree size {int(d['tree_size'])}; "
                         f"on final path: {bool(d.get('on_path'))}")
        if "grow_nodes" in d:
            lines.append(f"  growth: the growing tree added {int(d['grow_nodes'])} node(s) "
                         f"towards the sample (this step and the steps after it)")
        if "connect_nodes" in d:
            lines.append(f"  connect: the other tree added {int(d['connect_nodes'])} node(s) "
                         f"towards the growth's last node")
    lines.append("")
    lines.append(f"max |recomputed - recorded| = {e.max_discrepancy:.3g}")
    return "\n".join(lines) + "\n"
