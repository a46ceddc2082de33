"""Which rules drove a run: firing statistics over a Fuzzy-RRT trace.

For an auditor the question after "what did the planner do?" is "which rules made it do that?".
A rule's *influence* on one output over a run is the sum of its normalised firing strengths
over the iterations (each iteration's strengths sum to 1, so influences sum to the number of
iterations and ``share`` = influence / iterations sums to 1 over all rules). Rules that never
fired are absent; ``rules_fired`` over 625 says how much of a rulebook a run exercised.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy import semantics as _sem
from xfuzzy_rrt.fuzzy.variables import MAX_FIRED

INFLUENCE_COLUMNS = ["output", "rule", "iterations_fired", "influence", "share",
                     "mean_strength"]


def rule_influence(trace: pd.DataFrame, output: str) -> pd.DataFrame:
    """Per fired rule of one output: iterations fired, summed strength, share, mean strength.

    Sorted by decreasing influence (ties: lower rule index first).
    """
    outputs = _sem.of_columns(trace.columns).outputs
    if output not in outputs:
        raise InputError("output", f"unknown output {output!r}; outputs are {', '.join(outputs)}")
    n = len(trace)
    rules = trace[[f"{output}_rule_{k}" for k in range(MAX_FIRED)]].to_numpy().ravel()
    strengths = trace[[f"{output}_strength_{k}" for k in range(MAX_FIRED)]].to_numpy().ravel()
    fired = rules >= 0
    rules, strengths = rules[fired], strengths[fired]
    if rules.size == 0:
        return pd.DataFrame(columns=INFLUENCE_COLUMNS)
    counts = np.bincount(rules, minlength=1)
    totals = np.bincount(rules, weights=strengths, minlength=1)
    idx = np.nonzero(counts)[0]
    frame = pd.DataFrame({
        "output": output,
        "rule": idx.astype(np.int64),
        "iterations_fired": counts[idx].astype(np.int64),
        "influence": totals[idx],
        "share": totals[idx] / max(n, 1),
        "mean_strength": totals[idx] / counts[idx],
    }, columns=INFLUENCE_COLUMNS)
    order = np.lexsort((frame["rule"].to_numpy(), -frame["influence"].to_numpy()))
    return frame.iloc[order].reset_index(drop=True)


def top_rules(trace: pd.DataFrame, k: int = 5) -> pd.DataFrame:
    """The ``k`` most influential rules of every output, one table."""
    parts = [rule_influence(trace, out).head(k) for out in _sem.of_columns(trace.columns).outputs]
    return pd.concat(parts, ignore_index=True)
