"""What differs between two rulebooks, and what the difference did to a plan.

:func:`diff_rulebooks` compares what decides behaviour — the *effective* constants of the 625
cells of every FIS (after ``any`` expansion, so a compact rulebook and its full form compare
equal), the membership peaks and the bounds mode — and, separately, what only documents a
rulebook (name, description, provenance, term names). Two rulebooks are ``identical`` when
every FIS evaluates identically on every input and the bounds are meant the same way, i.e. when
planning with one or the other gives the same result for every scenario and seed; documentary
differences are reported but do not count.

:func:`replay_diff` plans one scenario and seed with both rulebooks (traces on) and finds the
first iteration whose *decisions* differ — the six outputs, the sample, whether the goal was
sampled, the outcome, the node added. Both runs draw the same random numbers up to that point,
so everything before it is identical and the cause is local: the rules that fired at that
iteration whose constants (or, when peaks moved, strengths) differ.
"""

from __future__ import annotations

from dataclasses import dataclass
from typing import Any

import numpy as np
import pandas as pd

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.manifest import thaw
from xfuzzy_rrt.fuzzy.variables import MAX_FIRED, N_RULES, rule_terms

class _Absent:
    """A key one rulebook has and the other lacks (shown as ``absent``, never ``nan``)."""

    def __repr__(self) -> str:
        return "absent"

    __str__ = __repr__

    def __reduce__(self):  # one instance, also across processes
        return "ABSENT"


ABSENT = _Absent()
#: Numbers closer than this (relative) differ only by float rounding (an FLL round trip, a
#: decimal print): not a documentary difference, and summarised in one line among cells.
ROUNDING_REL = 1e-12


def rounding_only(a: Any, b: Any, rel: float = ROUNDING_REL) -> bool:
    """``a`` and ``b`` are (nested lists of) numbers equal to within ``rel`` relative."""
    if isinstance(a, (list, tuple)) and isinstance(b, (list, tuple)):
        return len(a) == len(b) and all(rounding_only(x, y, rel) for x, y in zip(a, b))
    if isinstance(a, bool) or isinstance(b, bool):
        return a == b
    if isinstance(a, (int, float, np.integer, np.floating)) and isinstance(
            b, (int, float, np.integer, np.floating)):
        a, b = float(a), float(b)
        return a == b or abs(a - b) <= rel * max(abs(a), abs(b))
    return a == b


CELL_COLUMNS = ["output", "rule", "antecedent", "a", "b", "delta"]
PEAK_COLUMNS = ["output", "input", "term", "a", "b", "shift"]
META_COLUMNS = ["field", "a", "b"]
#: What a decision is beside the outputs (whose names come from the rulebooks' semantics), for
#: a 2-DOF trace; :func:`decision_columns` gives those of a trace of any DOF.
DECISION_COLUMNS = ["goal_sampled", "sample_q1_deg", "sample_q2_deg", "outcome",
                    "new_node"]
CAUSE_COLUMNS = ["output", "rule", "antecedent", "strength_a", "strength_b", "constant_a",
                 "constant_b", "contribution_change"]


@dataclass(frozen=True)
class RulebookDiff:
    a_name: str
    b_name: str
    a_sha256: str
    b_sha256: str
    cells: pd.DataFrame  # one row per changed cell (CELL_COLUMNS)
    peaks: pd.DataFrame  # one row per moved peak (PEAK_COLUMNS)
    bounds_mode: tuple[str, str] | None  # (a, b) when they differ
    documentary: pd.DataFrame  # name, description, provenance.*, term names (META_COLUMNS)

    @property
    def identical(self) -> bool:
        """Same behaviour: equal constants, peaks and bounds mode (documentation aside)."""
        return self.cells.empty and self.peaks.empty and self.bounds_mode is None

    @staticmethod
    def rounding_mask(cells: pd.DataFrame) -> pd.Series:
        """Rows of ``cells`` whose change is float rounding only (:data:`ROUNDING_REL`)."""
        a = cells["a"].astype(float).abs()
        b = cells["b"].astype(float).abs()
        return cells["delta"].astype(float).abs() <= ROUNDING_REL * np.maximum(a, b)

    def per_output(self) -> pd.DataFrame:
        """Changed cells per FIS with the largest absolute change."""
        rows = []
        for out in dict.fromkeys(self.cells["output"].tolist() + self.peaks["output"].tolist()):
            g = self.cells[self.cells["output"] == out]
            rows.append({"output": out, "cells_changed": len(g),
                         "max_abs_delta": float(g["delta"].abs().max()) if len(g) else 0.0,
                         "peaks_moved": int((self.peaks["output"] == out).sum()),
                         "cells_rounding_only": int(self.rounding_mask(g).sum())})
        return pd.DataFrame(rows)


def _antecedent(fis, r: int) -> str:
    t = rule_terms(r)
    return " and ".join(f"{inp.name} is {inp.terms[t[i]]}" for i, inp in enumerate(fis.inputs))


def _flat(prefix: str, value: Any, out: dict[str, Any]) -> None:
    if isinstance(value, dict):
        for k, v in value.items():
            _flat(f"{prefix}{k}.", v, out)
    else:
        out[prefix[:-1]] = value


def diff_rulebooks(a, b) -> RulebookDiff:
    """Compare two loaded rulebooks (see the module docstring).

    Both must have the same semantics and DOF: their systems are compared cell by cell, and a
    rulebook for another arm has other outputs (``InputError`` naming both).
    """
    if (a.semantics.name, a.dof) != (b.semantics.name, b.dof):
        raise InputError("b", f"cannot compare rulebook {a.name!r} ({a.semantics.name} "
                         f"semantics, dof {a.dof}) with {b.name!r} ({b.semantics.name} "
                         f"semantics, dof {b.dof}): their fuzzy systems differ")
    cells, peaks, doc = [], [], []
    for fa, fb in zip(a.systems, b.systems):
        ca = np.asarray(fa.consts)
        cb = np.asarray(fb.consts)
        for r in np.nonzero(ca != cb)[0].tolist():
            cells.append((fa.output, r, _antecedent(fa, r), ca[r], cb[r], cb[r] - ca[r]))
        for ia, ib in zip(fa.inputs, fb.inputs):
            for j, (pa, pb) in enumerate(zip(ia.peaks, ib.peaks)):
                if pa != pb:
                    peaks.append((fa.output, ia.name, ia.terms[j], pa, pb, pb - pa))
            if ia.terms != ib.terms:
                doc.append((f"{fa.output}.{ia.name}.terms", " ".join(ia.terms), " ".join(ib.terms)))
    for key in ("name", "description"):
        va, vb = getattr(a, key), getattr(b, key)
        if va != vb:
            doc.append((key, va, vb))
    pa: dict[str, Any] = {}
    pb: dict[str, Any] = {}
    _flat("provenance.", thaw(a.provenance), pa)
    _flat("provenance.", thaw(b.provenance), pb)
    for key in sorted(set(pa) | set(pb)):
        va, vb = pa.get(key, ABSENT), pb.get(key, ABSENT)
        if va is ABSENT or vb is ABSENT or not rounding_only(va, vb):
            doc.append((key, va, vb))
    return RulebookDiff(
        a_name=a.name, b_name=b.name, a_sha256=a.sha256, b_sha256=b.sha256,
        cells=pd.DataFrame(cells, columns=CELL_COLUMNS),
        peaks=pd.DataFrame(peaks, columns=PEAK_COLUMNS),
        bounds_mode=None if a.bounds_mode == b.bounds_mode else (a.bounds_mode, b.bounds_mode),
        documentary=pd.DataFrame(doc, columns=META_COLUMNS),
    )


# ------------------------------------------------------------------------------ replay


@dataclass(frozen=True)
class ReplayDiff:
    scenario: str
    seed: int
    result_a: Any  # PlanResult with trace
    result_b: Any
    #: first iteration (1-based) whose decisions differ; None when the runs are identical
    divergence: int | None
    #: the decision values at that iteration (DECISION_COLUMNS that differ: quantity, a, b)
    decisions: pd.DataFrame
    #: first iteration where the *plan* differs (sample, goal sampled, outcome, node added);
    #: outputs can differ earlier without changing what was sampled (e.g. a goal bias change
    #: that does not cross the random draw)
    plan_divergence: int | None
    #: the same as ``causes`` at ``plan_divergence``
    plan_causes: pd.DataFrame
    #: fired rules at that iteration whose constant or strength differs (CAUSE_COLUMNS)
    causes: pd.DataFrame

    def outcomes(self) -> pd.DataFrame:
        """Both runs side by side: success, iterations, nodes, cost."""
        rows = []
        for label, r in (("a", self.result_a), ("b", self.result_b)):
            rows.append({"rulebook": label, "name": r.rulebook, "success": r.success,
                         "iterations": r.iterations, "nodes": r.nodes,
                         "cost_deg": np.nan if r.cost_deg is None else r.cost_deg})
        return pd.DataFrame(rows)


PLAN_COLUMNS = ["goal_sampled", "sample_q1_deg", "sample_q2_deg", "outcome", "new_node"]


def decision_columns(trace: pd.DataFrame) -> list[str]:
    """DECISION_COLUMNS (= PLAN_COLUMNS) for the joints the trace has: ``sample_q1_deg …
    sample_qN_deg`` (a trace of N joints has N sample columns; 2 when it shows none)."""
    n = 0
    while f"sample_q{n + 1}_deg" in trace.columns:
        n += 1
    return ["goal_sampled", *(f"sample_q{j}_deg" for j in range(1, max(n, 2) + 1)),
            "outcome", "new_node"]


def first_divergence(ta: pd.DataFrame, tb: pd.DataFrame, columns=None) -> int | None:
    """First 1-based iteration where the decisions of two traces differ (None: never).

    A decision is the outputs (named by the traces' semantics) and the decision columns
    (:func:`decision_columns`: the sample in every joint, goal sampled, outcome, node). When
    one trace is a prefix of the other (one run stopped earlier), the divergence is the first
    iteration past the shorter one.
    """
    if columns is None:
        from xfuzzy_rrt.fuzzy import semantics as _sem

        columns = [*_sem.of_columns(ta.columns).outputs, *decision_columns(ta)]
    n = min(len(ta), len(tb))
    for c in columns:
        if c not in ta.columns or c not in tb.columns:
            raise ValueError(f"trace lacks column {c!r}")
    differ = np.zeros(n, dtype=bool)
    for c in columns:
        va = ta[c].iloc[:n]
        vb = tb[c].iloc[:n]
        if c == "outcome":
            differ |= va.astype(str).to_numpy() != vb.astype(str).to_numpy()
        else:
            differ |= va.to_numpy() != vb.to_numpy()
    idx = np.nonzero(differ)[0]
    if idx.size:
        return int(idx[0]) + 1
    if len(ta) != len(tb):
        return n + 1
    return None


def _fired(trace: pd.DataFrame, row: int, out: str) -> dict[int, float]:
    rules = [int(trace[f"{out}_rule_{k}"].iloc[row]) for k in range(MAX_FIRED)]
    ws = [float(trace[f"{out}_strength_{k}"].iloc[row]) for k in range(MAX_FIRED)]
    return {r: w for r, w in zip(rules, ws) if r >= 0}


def replay_diff(scenario, a, b, seed: int = 0, max_iter: int = 10_000) -> ReplayDiff:
    """Plan *scenario* with seed *seed* under rulebooks *a* and *b* and explain the divergence."""
    from xfuzzy_rrt.planners.api import plan_scenario

    # each with the planner its semantics names (goal-frame-any: Fuzzy-RRT-Connect)
    ra = plan_scenario(scenario, a.semantics.planner, rulebook=a, seed=seed,
                       max_iter=max_iter, trace=True)
    rb = plan_scenario(scenario, b.semantics.planner, rulebook=b, seed=seed,
                       max_iter=max_iter, trace=True)
    ta, tb = ra.trace, rb.trace
    it = first_divergence(ta, tb)
    plan_it = first_divergence(ta, tb, decision_columns(ta))
    decisions, causes = _explain_row(ta, tb, it, a, b)
    _, plan_causes = _explain_row(ta, tb, plan_it, a, b)
    return ReplayDiff(scenario=scenario.name, seed=int(seed), result_a=ra, result_b=rb,
                      divergence=it, decisions=decisions, causes=causes,
                      plan_divergence=plan_it, plan_causes=plan_causes)


def _explain_row(ta, tb, it, a, b) -> tuple[pd.DataFrame, pd.DataFrame]:
    """Inputs and differing decisions at iteration *it*, and the fired rules whose constant or
    normalised strength differs there."""
    decisions = pd.DataFrame(columns=["quantity", "a", "b"])
    causes = pd.DataFrame(columns=CAUSE_COLUMNS)
    if it is None:
        return decisions, causes
    if it > min(len(ta), len(tb)):
        return pd.DataFrame([("iterations", len(ta), len(tb))], columns=["quantity", "a", "b"]), causes
    row = it - 1
    drows = []
    for c in [*a.inputs, *a.outputs, *decision_columns(ta)]:
        if c not in ta or c not in tb:
            continue
        va, vb = ta[c].iloc[row], tb[c].iloc[row]
        if c == "outcome":
            va, vb = str(va), str(vb)
        if c in a.inputs or va != vb:
            drows.append((c, va, vb))
    crows = []
    for f, out in enumerate(a.outputs):
        fa, fb = _fired(ta, row, out), _fired(tb, row, out)
        ca, cb = a.systems[f].consts, b.systems[f].consts
        for r in sorted(set(fa) | set(fb)):
            wa, wb = fa.get(r, 0.0), fb.get(r, 0.0)
            if ca[r] != cb[r] or wa != wb:
                crows.append((out, r, _antecedent(a.systems[f], r), wa, wb, ca[r], cb[r],
                              wb * cb[r] - wa * ca[r]))
    return (pd.DataFrame(drows, columns=["quantity", "a", "b"]),
            pd.DataFrame(crows, columns=CAUSE_COLUMNS))


def changed_grid(diff: RulebookDiff, output: str) -> np.ndarray:
    """25 x 25 matrix of ``b - a`` per cell for one FIS (0 where unchanged); layout as
    :func:`xfuzzy_rrt.analysis.coverage.coverage_grid`."""
    z = np.zeros(N_RULES)
    g = diff.cells[diff.cells["output"] == output]
    z[g["rule"].to_numpy(dtype=np.int64)] = g["delta"].to_numpy(dtype=np.float64)
    return z.reshape(25, 25)
