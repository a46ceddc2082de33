"""Tables in and out of the engine: read an inputs CSV, evaluate a rulebook over a DataFrame.

Why here and not in the CLI: ``rules eval`` is one user of this; notebooks and analysis code
are others, and they need the same validation (columns present, every value a number) and the
same column names. pandas is imported lazily by the functions that need it.
"""

from __future__ import annotations

import os
from pathlib import Path

import numpy as np

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.variables import INPUTS


def _to_float(text: str) -> float:
    try:
        return float(text)
    except ValueError:
        return float("nan")


def read_inputs_csv(path: str | os.PathLike[str], inputs: tuple[str, ...] = INPUTS):
    """Read a CSV with (at least) the four input columns; return a pandas DataFrame.

    Numbers are parsed with Python's ``float`` (correctly rounded), so values written with 17
    significant digits or ``repr`` come back bit-identical. Raises :class:`InputError` naming the file
    (and line) for a missing file, missing columns, or a value that is not a finite number.
    """
    import pandas as pd

    file = str(path)
    if not Path(path).is_file():
        raise InputError(file, "input CSV does not exist")
    try:
        df = pd.read_csv(path, dtype=str, keep_default_na=False,
                         skipinitialspace=True)
    except UnicodeDecodeError:
        raise InputError(file, "not valid UTF-8") from None
    except (pd.errors.ParserError, pd.errors.EmptyDataError) as exc:
        raise InputError(file, f"not a readable CSV: {str(exc).strip()}") from None
    df.columns = [str(c).strip() for c in df.columns]
    missing = [c for c in inputs if c not in df.columns]
    if missing:
        raise InputError(file, f"missing column(s) {', '.join(missing)} (need {', '.join(inputs)})")
    for col in inputs:
        text = df[col].astype(str).str.strip()
        values = np.fromiter((_to_float(v) for v in text), dtype=np.float64, count=len(text))
        bad = ~np.isfinite(values)
        if bad.any():
            row = int(np.argmax(bad))
            raise InputError(f"{file}:{row + 2}", f"{col}: {text.iloc[row]!r} is not a finite number")
        df[col] = values
    return df


def evaluate_frame(rulebook, df):
    """Append (or overwrite) the six output columns for the input columns of *df*; return a copy."""
    from xfuzzy_rrt.fuzzy.engine import evaluate

    knots, consts = rulebook.arrays()
    X = np.ascontiguousarray(df[list(rulebook.inputs)].to_numpy(dtype=np.float64))
    Y = evaluate(knots, consts, X) if len(X) else np.empty((0, len(rulebook.outputs)))
    out = df.copy()
    for j, name in enumerate(rulebook.outputs):
        out[name] = Y[:, j]
    return out


def clamped_inputs(rulebook, df) -> list[tuple[str, int, float, float]]:
    """Per input column with values outside its range: ``(name, how many, lo, hi)``.

    The engine clamps such inputs to the range (they sit on a shoulder term; SPEC.md), which is
    the intended behaviour, but silent clamping hides a unit mistake -- degrees fed to an input
    in radians -- so ``rules eval`` reports these counts on stderr.
    """
    out = []
    ranges = rulebook.semantics.input_ranges
    for name in rulebook.inputs:
        lo, hi = ranges[name]
        x = df[name].to_numpy(dtype=np.float64)
        n = int(np.count_nonzero((x < lo) | (x > hi)))
        if n:
            out.append((name, n, float(lo), float(hi)))
    return out
