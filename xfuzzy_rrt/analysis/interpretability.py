"""Interpretability measures of a rulebook, so that "simpler" is a number and not a claim.

Per FIS (following the complexity- and semantics-based measures surveyed by Gacto, Alcalá and
Herrera 2011, "Interpretability of linguistic fuzzy rule-based systems: an overview of
interpretability measures", Information Sciences 181(20)):

- ``rules``: rules as written — 625 in the full layout, the fewest ``any`` rules that
  reproduce the constants exactly in the compact layout (:func:`~xfuzzy_rrt.fuzzy.cover.min_partition`);
- ``mean_antecedent_length``: conditions per rule that are not ``any`` (4 in the full layout);
- ``distinct_constants``: different consequent values (fewer means fewer things to remember);
- ``dead_cells`` / ``dead_rules``: cells (of 625) and written rules whose cells all never fired
  on the given runs (only when coverage counts are given);
- ``max_jaccard`` / ``mean_jaccard``: similarity of *adjacent* membership functions over the
  four inputs, ``|A ∩ B| / |A ∪ B|`` with min/max as intersection/union (the
  distinguishability measure of the survey; lower is better distinguished). For the Ruspini
  triangles used here it has a closed form: on the segment ``[p_j, p_{j+1}]`` of width ``d``
  the two sets cross at 1/2, so ``|A ∩ B| = d/4``; a set's area is half the sum of its two
  segment widths (one for a shoulder); hence ``J = (d/4) / (|A| + |B| - d/4)``. Uniform peaks
  give 1/7 between interior sets and 1/5 next to a shoulder.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

from xfuzzy_rrt.fuzzy.cover import ANY, min_partition
from xfuzzy_rrt.fuzzy.variables import N_RULES

MEASURE_COLUMNS = ["output", "rules", "mean_antecedent_length", "distinct_constants",
                   "dead_cells", "dead_rules", "max_jaccard", "mean_jaccard"]


def adjacent_jaccard(peaks) -> np.ndarray:
    """Jaccard similarity of the four adjacent pairs of a 5-term Ruspini triangle partition."""
    p = np.asarray(peaks, dtype=np.float64)
    d = np.diff(p)
    area = np.empty(len(p))
    area[0] = d[0] / 2
    area[-1] = d[-1] / 2
    area[1:-1] = (d[:-1] + d[1:]) / 2
    inter = d / 4
    return inter / (area[:-1] + area[1:] - inter)


def measures(rulebook, compact: bool = True, fired=None) -> pd.DataFrame:
    """One row per FIS (columns MEASURE_COLUMNS) plus a ``total``/mean row.

    ``compact`` measures the rulebook as the compact layout writes it (else the full 625-rule
    layout); ``fired`` is an optional int[n_out, 625] of firing counts (dead = 0).
    """
    rows = []
    for f, s in enumerate(rulebook.systems):
        consts = np.asarray(s.consts)
        if compact:
            patterns = [pat for pat, _ in min_partition(consts).rules]
        else:
            patterns = None
        n_rules = len(patterns) if compact else N_RULES
        length = (float(np.mean([sum(t != ANY for t in pat) for pat in patterns]))
                  if compact else 4.0)
        jac = np.concatenate([adjacent_jaccard(inp.peaks) for inp in s.inputs])
        dead_cells = dead_rules = np.nan
        if fired is not None:
            dead = np.asarray(fired[f]) == 0
            dead_cells = int(dead.sum())
            if compact:
                from xfuzzy_rrt.fuzzy.cover import pattern_cells

                dead_rules = int(sum(bool(dead[pattern_cells(p)].all()) for p in patterns))
            else:
                dead_rules = dead_cells
        rows.append({"output": s.output, "rules": n_rules, "mean_antecedent_length": length,
                     "distinct_constants": int(np.unique(consts).size),
                     "dead_cells": dead_cells, "dead_rules": dead_rules,
                     "max_jaccard": float(jac.max()), "mean_jaccard": float(jac.mean())})
    df = pd.DataFrame(rows, columns=MEASURE_COLUMNS)
    total = {"output": "total", "rules": int(df["rules"].sum()),
             "mean_antecedent_length": float(np.average(df["mean_antecedent_length"],
                                                        weights=df["rules"])),
             "distinct_constants": int(df["distinct_constants"].sum()),
             "dead_cells": df["dead_cells"].sum() if fired is not None else np.nan,
             "dead_rules": df["dead_rules"].sum() if fired is not None else np.nan,
             "max_jaccard": float(df["max_jaccard"].max()),
             "mean_jaccard": float(df["mean_jaccard"].mean())}
    return pd.concat([df, pd.DataFrame([total], columns=MEASURE_COLUMNS)], ignore_index=True)


__all__ = ["MEASURE_COLUMNS", "adjacent_jaccard", "measures"]
