#!/usr/bin/env python3
"""Check that pyfuzzylite 8 loads our FLL export and computes the same outputs.

Runs in a *separate* interpreter that has pyfuzzylite installed (it pins numpy<2, so it is not
a project dependency). It imports nothing from xfuzzy_rrt: it reads the exported ``.fll``
files and a CSV of expected values (as written by ``xfuzzy-rrt rules eval``), evaluates every
row with pyfuzzylite, and prints the maximum absolute deviation per output as JSON on stdout.
Exit code 0 if every deviation is within ``--tol`` (default 1e-9), 1 otherwise.

    python check_fll_pyfuzzylite.py FLL_DIR EXPECTED.csv [--tol 1e-9]

Create the interpreter with::

    python3 -m venv /tmp/fll-env && /tmp/fll-env/bin/pip install 'pyfuzzylite==8.*'
"""

from __future__ import annotations

import argparse
import csv
import json
import math
import sys
from pathlib import Path

INPUTS = ("angle_to_goal", "dist_to_goal", "angle_to_obstacle", "dist_to_obstacle")
OUTPUTS = ("goal_bias", "bound_1", "bound_2", "bound_3", "bound_4", "step_size")


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("fll_dir", type=Path)
    parser.add_argument("expected_csv", type=Path)
    parser.add_argument("--tol", type=float, default=1e-9)
    args = parser.parse_args()

    import fuzzylite as fl
    import numpy as np

    with args.expected_csv.open(newline="") as fh:
        rows = list(csv.DictReader(fh))
    result = {"pyfuzzylite": fl.__version__, "rows": len(rows), "max_abs_dev": {}}
    worst = 0.0
    for output in OUTPUTS:
        engine = fl.FllImporter().from_file(args.fll_dir / f"{output}.fll")
        inputs = [engine.input_variable(name) for name in INPUTS]
        out_var = engine.output_variable(output)
        # pyfuzzylite 8 evaluates arrays of values in one process() call
        for var, name in zip(inputs, INPUTS):
            var.value = np.array([float(row[name]) for row in rows])
        engine.process()
        got = np.atleast_1d(np.asarray(out_var.value, dtype=float))
        want = np.array([float(row[output]) for row in rows])
        if got.shape != want.shape or np.isnan(got).any():
            dev = math.inf
        else:
            dev = float(np.max(np.abs(got - want))) if len(rows) else 0.0
        result["max_abs_dev"][output] = dev
        worst = max(worst, dev)
    result["max"] = worst
    result["ok"] = worst <= args.tol
    json.dump(result, sys.stdout)
    sys.stdout.write("\n")
    return 0 if result["ok"] else 1


if __name__ == "__main__":
    sys.exit(main())
