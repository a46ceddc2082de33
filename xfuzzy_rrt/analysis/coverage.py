"""Which of a rulebook's n_out x 625 rules actually drive the planner: rule coverage over runs.

``n_out`` is the rulebook's number of FIS (6 at 2 DOF; ``2N + 2`` for a paper rulebook of N
joints); every array and table below has one block per FIS, in the rulebook's output order.

Definitions (per FIS and rule ``r``, over every iteration ``i`` of every run considered;
``w_{r,i}`` is the *normalised* firing strength recorded in the trace, so ``Σ_r w_{r,i} = 1``
and the output at iteration ``i`` is ``Σ_r w_{r,i} c_r``):

- ``fired``: iterations with ``w_{r,i} > 0`` (the engine records only non-zero strengths).
- ``strength_total`` = ``Σ_i w_{r,i}``; ``strength_mean`` = ``strength_total / fired``.
- ``mass_share`` = ``strength_total / iterations``: the rule's share of the *output mass*, i.e.
  of the weight of the convex combination that forms the output, summed over the run. Shares
  sum to 1 per FIS. Why this and not ``Σ w |c|``: a bound of 0° or a step of 0 is as decisive as
  any other constant, so weighting by the constant's magnitude would make a rule's importance
  depend on where the output range happens to have its zero.
- ``rank`` orders rules by decreasing ``mass_share`` (ties: lower index first);
  ``cumulative_share`` is the running sum in that order, and ``carries_90`` marks the smallest
  set of rules whose shares reach 90 % of the mass (the rules "that carry 90 % of the output").
- ``fired_on_path`` / ``fired_off_path``: iterations whose new node ended on the returned path
  vs all other iterations (rejected samples, nodes that stayed off the path, failed runs);
  ``strength_on_path`` likewise.
- A rule is *dead* when ``fired == 0``; ``coverage`` of a FIS is the share of its 625 cells
  that fired at least once.

The counts are accumulated run by run into plain arrays (:class:`CoverageCounts`), so runs can
be planned in worker processes and only 4 x n_out x 625 numbers travel back; sums are taken in run
order, so the result does not depend on the number of workers.
"""

from __future__ import annotations

import os
from concurrent.futures import ProcessPoolExecutor
from dataclasses import dataclass, field
from pathlib import Path

import numpy as np
import pandas as pd

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy import semantics as _sem
from xfuzzy_rrt.fuzzy.variables import MAX_FIRED, N_OUTPUTS, N_RULES, rule_terms

COVERAGE_COLUMNS = ["output", "rule", "antecedent", "constant", "fired", "strength_total",
                    "strength_mean", "mass_share", "rank", "cumulative_share", "carries_90",
                    "fired_on_path", "fired_off_path", "strength_on_path"]
SUMMARY_COLUMNS = ["output", "iterations", "rules_fired", "coverage", "dead_rules",
                   "rules_carrying_90", "share_carrying_90"]
MASS_TARGET = 0.9


@dataclass
class CoverageCounts:
    """Raw sums over iterations, arrays float64/int64[n_out, 625] (see the module docstring).

    The default is the 2-DOF shape (6 FIS); use :meth:`empty` for a rulebook's own.
    """

    fired: np.ndarray = field(default_factory=lambda: np.zeros((N_OUTPUTS, N_RULES), np.int64))
    strength: np.ndarray = field(default_factory=lambda: np.zeros((N_OUTPUTS, N_RULES)))
    fired_on_path: np.ndarray = field(default_factory=lambda: np.zeros((N_OUTPUTS, N_RULES), np.int64))
    strength_on_path: np.ndarray = field(default_factory=lambda: np.zeros((N_OUTPUTS, N_RULES)))
    iterations: int = 0
    runs: int = 0
    successes: int = 0

    @classmethod
    def empty(cls, n_out: int = N_OUTPUTS) -> "CoverageCounts":
        """Zero counts for a rulebook of *n_out* FIS (``rulebook.n_outputs``)."""
        return cls(fired=np.zeros((n_out, N_RULES), np.int64), strength=np.zeros((n_out, N_RULES)),
                   fired_on_path=np.zeros((n_out, N_RULES), np.int64),
                   strength_on_path=np.zeros((n_out, N_RULES)))

    def add(self, other: "CoverageCounts") -> None:
        if other.fired.shape != self.fired.shape:
            raise InputError("trace", f"counts for {other.fired.shape[0]} fuzzy systems cannot "
                             f"be added to counts for {self.fired.shape[0]} (another DOF)")
        self.fired += other.fired
        self.strength += other.strength
        self.fired_on_path += other.fired_on_path
        self.strength_on_path += other.strength_on_path
        self.iterations += other.iterations
        self.runs += other.runs
        self.successes += other.successes


def counts_from_trace(trace: pd.DataFrame, success: bool | None = None) -> CoverageCounts:
    """Coverage counts of one run's trace (the DataFrame of :mod:`xfuzzy_rrt.planners.trace`)."""
    outputs = _sem.of_columns(trace.columns).outputs
    needed = ["on_path"] + [f"{o}_rule_{k}" for o in outputs for k in range(MAX_FIRED)]
    missing = [c for c in needed if c not in trace.columns]
    if missing:
        raise InputError("trace", f"not a Fuzzy-RRT trace (missing column {missing[0]!r})")
    n = len(trace)
    c = CoverageCounts.empty(len(outputs))
    c.iterations, c.runs = n, 1
    if success is None:
        success = bool(n and "outcome" in trace and str(trace["outcome"].iloc[-1]) == "goal_reached")
    c.successes = int(success)
    on = trace["on_path"].to_numpy(dtype=bool)
    for f, out in enumerate(outputs):
        rules = trace[[f"{out}_rule_{k}" for k in range(MAX_FIRED)]].to_numpy(dtype=np.int64)
        w = trace[[f"{out}_strength_{k}" for k in range(MAX_FIRED)]].to_numpy(dtype=np.float64)
        mask = rules >= 0
        if np.any(rules >= N_RULES):
            raise InputError("trace", f"{out}: rule index outside 0..{N_RULES - 1}")
        r, s = rules[mask], w[mask]
        c.fired[f] = np.bincount(r, minlength=N_RULES)
        c.strength[f] = np.bincount(r, weights=s, minlength=N_RULES)
        mon = mask & on[:, None]
        c.fired_on_path[f] = np.bincount(rules[mon], minlength=N_RULES)
        c.strength_on_path[f] = np.bincount(rules[mon], weights=w[mon], minlength=N_RULES)
    return c


def _one(args) -> CoverageCounts:
    from xfuzzy_rrt.planners.api import plan_scenario

    scenario, rulebook, seed, max_iter = args
    # the planner the rulebook's semantics names (goal-frame-any: Fuzzy-RRT-Connect)
    res = plan_scenario(scenario, planner=rulebook.semantics.planner, rulebook=rulebook,
                        seed=seed, max_iter=max_iter, trace=True)
    return counts_from_trace(res.trace, success=res.success)


def collect_counts(rulebook, scenarios, runs: int = 10, seed: int = 0, max_iter: int = 10_000,
                   workers: int = 1) -> CoverageCounts:
    """Plan every scenario ``runs`` times (seeds ``seed .. seed + runs - 1``) with tracing on
    and sum the coverage counts (in job order, so any number of workers gives the same sums)."""
    if runs < 1:
        raise InputError("--runs", f"must be >= 1, got {runs}")
    if workers < 1:
        raise InputError("--workers", f"must be >= 1, got {workers}")
    jobs = [(s, rulebook, seed + k, max_iter) for s in scenarios for k in range(runs)]
    total = CoverageCounts.empty(len(rulebook.outputs))
    if workers == 1 or len(jobs) == 1:
        parts = map(_one, jobs)
        for p in parts:
            total.add(p)
    else:
        with ProcessPoolExecutor(max_workers=min(workers, os.cpu_count() or 1)) as pool:
            for p in pool.map(_one, jobs):
                total.add(p)
    return total


def counts_from_trace_files(paths, rulebook) -> CoverageCounts:
    """Sum the counts of saved traces; each must have been made by *rulebook* (sha256)."""
    from xfuzzy_rrt.analysis.explain import load_trace

    total = CoverageCounts.empty(len(rulebook.outputs))
    for path in paths:
        frame = load_trace(Path(path))
        if "rulebook_sha256" in frame and len(frame):
            sha = str(frame["rulebook_sha256"].iloc[0])
            if sha != rulebook.sha256:
                raise InputError(str(path), f"trace was made by rulebook sha256 {sha[:12]}..., "
                                 f"not by this rulebook ({rulebook.sha256[:12]}...)")
        total.add(counts_from_trace(frame))
    return total


def antecedent_text(rulebook, f: int, r: int) -> str:
    inputs = rulebook.systems[f].inputs
    t = rule_terms(r)
    return " and ".join(f"{inp.name} is {inp.terms[t[i]]}" for i, inp in enumerate(inputs))


def coverage_frame(counts: CoverageCounts, rulebook) -> pd.DataFrame:
    """One row per FIS and rule (n_out x 625 rows, dead rules included); columns
    COVERAGE_COLUMNS."""
    parts = []
    n = max(counts.iterations, 1)
    for f, out in enumerate(rulebook.outputs):
        share = counts.strength[f] / n
        order = np.lexsort((np.arange(N_RULES), -share))
        rank = np.empty(N_RULES, dtype=np.int64)
        rank[order] = np.arange(1, N_RULES + 1)
        cum_sorted = np.cumsum(share[order])
        cumulative = np.empty(N_RULES)
        cumulative[order] = cum_sorted
        # rules up to and including the first whose running sum reaches the target
        k = int(np.searchsorted(cum_sorted, MASS_TARGET - 1e-12) + 1) if counts.iterations else 0
        carries = np.zeros(N_RULES, dtype=bool)
        carries[order[:k]] = True
        fired = counts.fired[f]
        with np.errstate(invalid="ignore", divide="ignore"):
            mean = np.where(fired > 0, counts.strength[f] / np.maximum(fired, 1), 0.0)
        parts.append(pd.DataFrame({
            "output": out,
            "rule": np.arange(N_RULES, dtype=np.int64),
            "antecedent": [antecedent_text(rulebook, f, r) for r in range(N_RULES)],
            "constant": np.asarray(rulebook.systems[f].consts),
            "fired": fired.astype(np.int64),
            "strength_total": counts.strength[f],
            "strength_mean": mean,
            "mass_share": share,
            "rank": rank,
            "cumulative_share": cumulative,
            "carries_90": carries,
            "fired_on_path": counts.fired_on_path[f].astype(np.int64),
            "fired_off_path": (fired - counts.fired_on_path[f]).astype(np.int64),
            "strength_on_path": counts.strength_on_path[f],
        }, columns=COVERAGE_COLUMNS))
    return pd.concat(parts, ignore_index=True)


def coverage_summary(coverage: pd.DataFrame, iterations: int) -> pd.DataFrame:
    """Per FIS plus an ``all`` row over all rules (3,750 at 2 DOF): fired rules, coverage, dead rules,
    rules carrying 90 % of the mass and their share of the rules."""
    rows = []
    for out, g in coverage.groupby("output", sort=False):
        fired = int((g["fired"] > 0).sum())
        k = int(g["carries_90"].sum())
        rows.append({"output": out, "iterations": iterations, "rules_fired": fired,
                     "coverage": fired / len(g), "dead_rules": len(g) - fired,
                     "rules_carrying_90": k, "share_carrying_90": k / len(g)})
    total = len(coverage)
    fired = sum(r["rules_fired"] for r in rows)
    k = sum(r["rules_carrying_90"] for r in rows)
    rows.append({"output": "all", "iterations": iterations, "rules_fired": fired,
                 "coverage": fired / total, "dead_rules": total - fired,
                 "rules_carrying_90": k, "share_carrying_90": k / total})
    return pd.DataFrame(rows, columns=SUMMARY_COLUMNS)


def coverage_grid(coverage: pd.DataFrame, output: str, value: str = "mass_share") -> np.ndarray:
    """The 25 x 25 matrix of one column for one FIS: row ``t0*5 + t1`` (angle_to_goal,
    dist_to_goal), column ``t2*5 + t3`` (angle_to_obstacle, dist_to_obstacle); with the rule
    index convention this is simply ``values.reshape(25, 25)``."""
    g = coverage[coverage["output"] == output].sort_values("rule")
    if len(g) != N_RULES:
        raise InputError("output", f"no coverage rows for {output!r}")
    return g[value].to_numpy(dtype=np.float64).reshape(25, 25)
