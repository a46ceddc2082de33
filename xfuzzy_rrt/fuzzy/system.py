"""The frozen model of one single-output fuzzy inference system (FIS) and its inputs.

A Fuzzy-RRT rulebook holds six of these (one per output, as in the paper). Objects are
immutable and validated on construction with real exceptions (``ValueError``), so a
:class:`FuzzySystem` that exists is always a usable one; the text parser
(:mod:`.text_format`) performs the same checks first to report them with file and line.
"""

from __future__ import annotations

import math
import re
from dataclasses import dataclass

from xfuzzy_rrt.fuzzy import semantics as _sem
from xfuzzy_rrt.fuzzy.variables import N_RULES, N_TERMS

#: Term names are identifiers (letters, digits, underscores; not starting with a digit) and
#: cannot be one of the words the rule grammar uses.
TERM_NAME = re.compile(r"[A-Za-z_][A-Za-z0-9_]*\Z")
RESERVED = frozenset({"if", "is", "and", "then", "or", "not", "any"})  # any: don't-care


def term_name_problem(name: str) -> str | None:
    """Why *name* cannot be a term name, or ``None`` when it can."""
    if not TERM_NAME.match(name):
        return f"term name {name!r} is not an identifier (letters, digits, _)"
    if name in RESERVED:
        return f"term name {name!r} is a reserved word"
    return None


def peaks_problem(peaks: tuple[float, ...], lo: float, hi: float) -> str | None:
    """Why *peaks* (``[lo, p1, p2, p3, hi]``) is not a valid partition of ``[lo, hi]``."""
    if len(peaks) != N_TERMS:
        return f"expected {N_TERMS} peaks, got {len(peaks)}"
    if not all(math.isfinite(p) for p in peaks):
        return "peaks must be finite numbers"
    if peaks[0] != lo or peaks[-1] != hi:
        return (
            f"first and last peaks must be the range ends {lo!r} and {hi!r} (the shoulders), "
            f"got {peaks[0]!r} and {peaks[-1]!r}"
        )
    inner = peaks[1:-1]
    outside = [p for p in inner if not lo < p < hi]
    if outside:
        return f"peak {outside[0]!r} outside the input range ({lo!r}, {hi!r})"
    if not all(a < b for a, b in zip(peaks, peaks[1:])):
        return "peaks are not strictly increasing: " + " ".join(repr(p) for p in peaks)
    return None


@dataclass(frozen=True)
class InputPartition:
    """One input of a FIS: its name, range, five term names and the five term peaks.

    ``peaks`` is the knot row ``[lo, p1, p2, p3, hi]`` of the engine: term ``j`` has its peak
    (membership 1) at ``peaks[j]``; the first and last terms are shoulders.

    ``dof`` is the rulebook's DOF: some ranges depend on it (goal-frame's
    ``joint_dist_to_goal``), so a partition is validated against the range at that DOF.
    """

    name: str
    terms: tuple[str, ...]
    peaks: tuple[float, ...]
    dof: int = _sem.DEFAULT_DOF

    def __post_init__(self) -> None:
        if self.name not in _sem.ALL_INPUT_RANGES:
            raise ValueError(f"unknown input variable {self.name!r}; inputs are "
                             f"{', '.join(_sem.ALL_INPUT_RANGES)}")
        problem = _sem.dof_problem(self.dof)
        if problem:
            raise ValueError(f"{self.name}: {problem}")
        object.__setattr__(self, "terms", tuple(str(t) for t in self.terms))
        object.__setattr__(self, "peaks", tuple(float(p) for p in self.peaks))
        if len(self.terms) != N_TERMS:
            raise ValueError(f"{self.name}: expected {N_TERMS} terms, got {len(self.terms)}")
        for t in self.terms:
            problem = term_name_problem(t)
            if problem:
                raise ValueError(f"{self.name}: {problem}")
        if len(set(self.terms)) != N_TERMS:
            raise ValueError(f"{self.name}: term names must be distinct: {self.terms}")
        problem = peaks_problem(self.peaks, *self.range)
        if problem:
            raise ValueError(f"{self.name}: {problem}")

    @property
    def range(self) -> tuple[float, float]:
        """The variable's range (fixed by its semantics and DOF, not per rulebook)."""
        return _sem.input_range(self.name, self.dof)


@dataclass(frozen=True)
class FuzzySystem:
    """A zero-order Takagi-Sugeno system with one output and the 625-rule grid.

    ``consts[r]`` is the consequent of rule ``r`` (index convention in :mod:`.variables`).
    ``dof`` (default: that of the inputs) is the rulebook's DOF; it decides which outputs exist
    (``bound_5`` needs a paper rulebook of at least 3 joints) and the inputs' ranges.
    """

    output: str
    inputs: tuple[InputPartition, ...]
    consts: tuple[float, ...]
    dof: int | None = None

    def __post_init__(self) -> None:
        object.__setattr__(self, "inputs", tuple(self.inputs))
        object.__setattr__(self, "consts", tuple(float(c) for c in self.consts))
        if self.dof is None:
            object.__setattr__(self, "dof", self.inputs[0].dof if self.inputs else _sem.DEFAULT_DOF)
        problem = _sem.dof_problem(self.dof)
        if problem:
            raise ValueError(f"{self.output}: {problem}")
        if any(i.dof != self.dof for i in self.inputs):
            raise ValueError(f"{self.output}: inputs are for dof {[i.dof for i in self.inputs]}, "
                             f"the system for dof {self.dof}")
        names = tuple(i.name for i in self.inputs)
        sem = _sem.of_inputs(names[0], self.dof) if names else None
        if sem is None or names != sem.inputs:
            raise ValueError(f"{self.output}: inputs must be those of one semantics in order "
                             f"(e.g. {_sem.PAPER.inputs}), got {names}")
        if self.output not in sem.outputs:
            raise ValueError(f"unknown output variable {self.output!r} for the {sem.name} "
                             f"semantics at dof {self.dof}; outputs are {sem.outputs}")
        if len(self.consts) != N_RULES:
            raise ValueError(f"{self.output}: expected {N_RULES} rule constants, got {len(self.consts)}")
        lo, hi = self.range
        for r, c in enumerate(self.consts):
            if not (math.isfinite(c) and lo <= c <= hi):
                raise ValueError(
                    f"{self.output}: rule {r} constant {c!r} outside the output range [{lo!r}, {hi!r}]"
                )

    @property
    def semantics(self) -> "_sem.Semantics":
        """The semantics (at this system's DOF) its inputs belong to."""
        return _sem.of_inputs(self.inputs[0].name, self.dof)

    @property
    def range(self) -> tuple[float, float]:
        """The output's range (fixed by the semantics)."""
        return self.semantics.output_ranges[self.output]
