"""Helpers shared by the rulebook tests (not a test module)."""

from __future__ import annotations

import shutil
from pathlib import Path

import numpy as np

from xfuzzy_rrt.fuzzy.rulebook import Rulebook, rulebooks_dir
from xfuzzy_rrt.fuzzy.variables import INPUT_RANGES, INPUTS, N_RULES, OUTPUT_RANGES, OUTPUTS

EXPERT = rulebooks_dir() / "expert"


def copy_expert(tmp_path: Path, name: str = "rb") -> Path:
    dest = tmp_path / name
    shutil.copytree(EXPERT, dest)
    return dest


def random_arrays(rng: np.random.Generator, integers: bool = False) -> tuple[np.ndarray, np.ndarray]:
    """Random valid engine arrays: strictly increasing interior peaks, consts within range."""
    knots = np.empty((len(OUTPUTS), len(INPUTS), 5))
    for f in range(len(OUTPUTS)):
        for i, name in enumerate(INPUTS):
            lo, hi = INPUT_RANGES[name]
            while True:
                p = np.sort(rng.uniform(lo, hi, 3))
                if lo < p[0] < p[1] < p[2] < hi:
                    break
            knots[f, i] = [lo, *p, hi]
    consts = np.empty((len(OUTPUTS), N_RULES))
    for f, name in enumerate(OUTPUTS):
        lo, hi = OUTPUT_RANGES[name]
        consts[f] = rng.uniform(lo, hi, N_RULES)
    if integers:
        consts = np.round(consts)
    return knots, consts


def random_rulebook(rng: np.random.Generator, **kw) -> Rulebook:
    knots, consts = random_arrays(rng)
    return Rulebook.from_arrays(
        knots, consts, name=kw.get("name", "random"), bounds_mode=kw.get("bounds_mode", "absolute"),
        provenance=kw.get("provenance", {"kind": "test", "seed": 1}),
    )


def random_inputs(rng: np.random.Generator, n: int, margin: float = 0.2) -> np.ndarray:
    """Inputs spread over each range widened by *margin* of its width on both sides."""
    cols = []
    for name in INPUTS:
        lo, hi = INPUT_RANGES[name]
        w = hi - lo
        cols.append(rng.uniform(lo - margin * w, hi + margin * w, n))
    return np.column_stack(cols)
