#!/usr/bin/env python3
"""Compare parameter sets of the expert-rulebook generator against plain RRT.

Why: the expert rulebook is hand-written from principles, but which *numbers* serve those
principles is an empirical question. This script measures it on a tuning set that excludes the
shared reference scenarios (so the shipped rulebook is not fitted to the files it is later
judged on): the shipped demo scenarios, the test fixtures, and random problems of the
``sample-*`` family (drawn as in ``tests/test_generated_family.py``, kept only when RRT solves
them on 5 of 5 seeds).

Score: for each scenario the median iterations over ``--seeds`` seeds, divided by RRT's; the
geometric mean over scenarios (below 1 = fewer iterations than RRT). Usage::

    python scripts/tune_expert_rulebook.py [--seeds 20] [--random 12]

prints one line per parameter set of the grid below.
"""

from __future__ import annotations

import argparse
import itertools
import sys
import tempfile
from pathlib import Path

import numpy as np

ROOT = Path(__file__).resolve().parents[1]
sys.path.insert(0, str(ROOT))
sys.path.insert(0, str(ROOT / "scripts"))
sys.path.insert(0, str(ROOT / "tests"))

import make_expert_rulebook as gen  # noqa: E402
from test_generated_family import _random_scenario_text  # noqa: E402
from xfuzzy_rrt.errors import ScenarioError  # noqa: E402
from xfuzzy_rrt.geometry.scenario import load_scenario  # noqa: E402
from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt  # noqa: E402
from xfuzzy_rrt.planners.rrt import plan_rrt  # noqa: E402

GRID = {
    "BIAS_GOAL_FAR": [0.25, 0.4],
    "BIAS_OBSTACLE": [0.05, 0.3],
    "WINDOW_NEAR_DEG": [60.0],
    "STEP_NEAR_OBSTACLE": [3.5, 10.0],
    "BIAS_ALIGN_PENALTY": [0.0, 0.5],
}


def tuning_set(n_random: int):
    files = sorted((ROOT / "xfuzzy_rrt" / "data" / "scenarios").glob("*.toml"))
    files += sorted((ROOT / "tests" / "fixtures" / "scenarios").glob("*.toml"))
    scenarios = [load_scenario(f) for f in files]
    rng = np.random.default_rng(77)
    folder = Path(tempfile.mkdtemp())
    while len(scenarios) < len(files) + n_random:
        path = folder / f"random-{len(scenarios)}.toml"
        path.write_text(_random_scenario_text(rng))
        try:
            s = load_scenario(path)
        except ScenarioError:
            continue
        if all(plan_rrt(s, seed=k).success for k in range(5)):
            scenarios.append(s)
    return scenarios


def main() -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--seeds", type=int, default=20)
    parser.add_argument("--random", type=int, default=12)
    args = parser.parse_args()
    scenarios = tuning_set(args.random)
    seeds = range(args.seeds)
    base = np.array([np.median([plan_rrt(s, seed=k).iterations for k in seeds]) for s in scenarios])
    keys = list(GRID)
    for values in itertools.product(*(GRID[k] for k in keys)):
        for k, v in zip(keys, values):
            setattr(gen, k, v)
        rb = gen.build("tuning", "tuning")
        runs = [[plan_fuzzy_rrt(s, rb, seed=k).iterations for k in seeds] for s in scenarios]
        med = np.array([np.median(r) for r in runs])
        score = float(np.exp(np.mean(np.log(med / base))))
        worst = max(max(r) for r in runs)
        print(f"{score:.3f}  worst {worst:5d}  " + "  ".join(f"{k}={v}" for k, v in zip(keys, values)),
              flush=True)
    return 0


if __name__ == "__main__":
    sys.exit(main())
