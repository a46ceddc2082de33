"""One hash of many plans, to show that a change which should not change any plan did not.

Why: the planners' hot paths are rewritten for speed (stop records, the Connect loop, shared
inline helpers) under the rule that every plan stays the same bit for bit -- path, tree size,
iteration count and the deterministic work count. Timing cannot show that; a hash of every
field a plan reports can. Run it before and after a change, on the same problems and seeds::

    python scripts/plan_hash.py DIR [DIR ...] --problems 8 --seeds 3

Each DIR is a folder of scenario files (``xfuzzy-rrt scenarios generate``; e.g. the families
sample, hard, mira, trap, and ``--dof 3/5/7``, ``--dof 3 --arms 2``); the first ``--problems``
files of each (sorted by name) are planned by the default (``fuzzy-rrt``, shipped rulebooks),
``rrt:tuned`` and ``rrt`` with seeds ``0 .. --seeds - 1``. Prints the number of runs and a
16-hex-digit hash; with ``--verbose`` one line per run, so two outputs can be diffed to find the
first run that moved.
"""

from __future__ import annotations

import argparse
import hashlib
import sys
from pathlib import Path

PLANNERS = ("fuzzy-rrt", "rrt:tuned", "rrt")


def run_digest(result) -> bytes:
    """The bytes of every deterministic field of one plan (not its wall time)."""
    import numpy as np

    head = (f"{result.scenario}|{result.planner}|{result.planner_used}|{result.seed}|"
            f"{result.success}|{result.iterations}|{result.nodes}|{result.work}|"
            f"{result.certify_work}|{result.cost_deg!r}|")
    path = np.ascontiguousarray(result.path_deg, dtype=np.float64).tobytes()
    return head.encode() + path


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument("dirs", nargs="+", type=Path)
    parser.add_argument("--problems", type=int, default=8)
    parser.add_argument("--seeds", type=int, default=3)
    parser.add_argument("--verbose", action="store_true")
    args = parser.parse_args(argv)

    from xfuzzy_rrt.planners.api import plan_scenario
    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.training.run import expand_scenarios

    total = hashlib.sha256()
    runs = 0
    for folder in args.dirs:
        if not folder.is_dir():
            print(f"{folder}: not a folder", file=sys.stderr)
            return 2
        try:  # the training command's reading of a folder (one line for a bad one)
            files = expand_scenarios([folder])[: args.problems]
        except InputError as err:
            print(err, file=sys.stderr)
            return 2
        for path in files:
            scenario = load_scenario(path)
            for planner in PLANNERS:
                for seed in range(args.seeds):
                    result = plan_scenario(scenario, planner, seed=seed)
                    digest = run_digest(result)
                    total.update(digest)
                    runs += 1
                    if args.verbose:
                        print(path.stem, planner, seed, hashlib.sha256(digest).hexdigest()[:16],
                              result.iterations, result.work)
    print(f"{runs} runs, hash {total.hexdigest()[:16]}")
    return 0


if __name__ == "__main__":
    sys.exit(main())
