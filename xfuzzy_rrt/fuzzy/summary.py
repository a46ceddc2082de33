"""Human-oriented views of a rulebook: summary statistics and rule look-up by condition.

The data here is what ``rules show`` renders; it lives in the library so reports and notebooks
can use the same numbers.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.variables import N_RULES, rule_terms


@dataclass(frozen=True)
class ConsequentStats:
    output: str
    range: tuple[float, float]
    min: float
    mean: float
    median: float
    max: float
    distinct: int


def consequent_stats(rulebook) -> list[ConsequentStats]:
    """Per-output statistics of the 625 rule constants."""
    stats = []
    for s in rulebook.systems:
        c = np.asarray(s.consts)
        stats.append(ConsequentStats(
            output=s.output, range=s.range, min=float(c.min()), mean=float(c.mean()),
            median=float(np.median(c)), max=float(c.max()), distinct=int(np.unique(c).size),
        ))
    return stats


def parse_conditions(conditions: list[str], rulebook) -> dict[int, int]:
    """``["dist_to_goal=near", ...]`` -> ``{input index: term index}``; InputError if unknown.

    Terms are those of the first FIS (all FIS of shipped rulebooks share term names; a FIS with
    different names is matched by term *index*).
    """
    inputs = rulebook.systems[0].inputs
    out: dict[int, int] = {}
    for cond in conditions:
        for part in cond.split(","):
            part = part.strip()
            if not part:
                continue
            var, sep, term = (p.strip() for p in part.partition("="))
            if not sep:
                raise InputError("--when", f"expected INPUT=TERM, got {part!r}")
            names = rulebook.inputs
            if var not in names:
                raise InputError("--when", f"unknown input {var!r} (inputs: {', '.join(names)})")
            i = names.index(var)
            if term not in inputs[i].terms:
                raise InputError("--when", f"unknown term {term!r} for {var} (terms: {' '.join(inputs[i].terms)})")
            out[i] = inputs[i].terms.index(term)
    return out


def matching_rules(rulebook, where: dict[int, int]) -> list[tuple[int, tuple[int, ...], list[float]]]:
    """Rules whose antecedent has the given terms: ``(index, term indices, six consequents)``."""
    rows = []
    for r in range(N_RULES):
        t = rule_terms(r)
        if all(t[i] == k for i, k in where.items()):
            rows.append((r, t, [s.consts[r] for s in rulebook.systems]))
    return rows


__all__ = ["ConsequentStats", "consequent_stats", "matching_rules", "parse_conditions"]
