"""Regenerate the golden files that pin engine outputs and plans (pyfuzzylite's habit).

    .venv/bin/python scripts/make_golden.py

Writes ``tests/golden/engine.csv`` (every shipped rulebook evaluated on fixed inputs) and
``tests/golden/plans.csv`` (RRT and every shipped rulebook on fixed scenarios, seeds 0-4:
iterations, nodes, cost). ``tests/test_golden.py`` checks the code against them. Run this only
for a *deliberate* change of behaviour; the diff of these files then shows in review what
changed. Scenarios: the test fixtures, the packaged demo scenarios, and ``paper-reference`` and
two ``sample-*`` files from ``../shared/scenarios`` when that folder is present (the test skips
those rows without it).
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np
import pandas as pd

ROOT = Path(__file__).resolve().parents[1]
GOLDEN = ROOT / "tests" / "golden"
SHARED = ROOT.parent / "shared" / "scenarios"
SEEDS = range(5)


def golden_scenarios() -> list[Path]:
    """The scenario files the golden plans cover, in a fixed order."""
    from xfuzzy_rrt.bench.runner import shipped_scenarios

    files = [ROOT / "tests" / "fixtures" / "scenarios" / f for f in ("two-circles.toml", "boxes-and-circle.toml")]
    files += list(shipped_scenarios())
    files += [SHARED / f for f in ("paper-reference.toml", "sample-00.toml", "sample-03.toml")]
    return files


def shipped_rulebooks() -> list[Path]:
    from xfuzzy_rrt.fuzzy.rulebook import list_rulebooks

    return list(list_rulebooks())


def two_joint_rulebooks() -> list[Path]:
    """The shipped rulebooks ``fuzzy-rrt`` plans a 2-joint arm with (the golden scenarios are
    2-joint problems; the N-DOF and any-arm rulebooks are pinned by their engine rows)."""
    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
    from xfuzzy_rrt.planners.fuzzy_rrt import check_rulebook_fits

    two_joints = load_scenario(golden_scenarios()[0])
    out = []
    for p in shipped_rulebooks():
        try:
            check_rulebook_fits(load_rulebook(p), two_joints)
        except InputError:
            continue
        out.append(p)
    return out


def engine_inputs(rb, n: int = 64) -> np.ndarray:
    """Fixed inputs spread over the rulebook's input ranges (plus the corners of the range)."""
    rng = np.random.default_rng(20261201)
    knots, _ = rb.compiled
    lo, hi = knots[0, :, 0], knots[0, :, 4]
    X = lo + rng.random((n, lo.size)) * (hi - lo)
    return np.vstack([X, lo, hi])


def engine_frame() -> pd.DataFrame:
    from xfuzzy_rrt.fuzzy.engine import evaluate
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook

    rows = []
    for path in shipped_rulebooks():
        rb = load_rulebook(path)
        X = engine_inputs(rb)
        Y = evaluate(*rb.compiled, X)
        for x, y in zip(X, Y):
            rows.append({"rulebook": path.name, **{f"x{i}": v for i, v in enumerate(x)},
                         **{f"y{j}": v for j, v in enumerate(y)}})
    return pd.DataFrame(rows)


def plans_frame() -> pd.DataFrame:
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt
    from xfuzzy_rrt.planners.rrt import plan_rrt

    rows = []
    for file in golden_scenarios():
        if not file.exists():
            print(f"note: {file} absent; its golden rows are not written", file=sys.stderr)
            continue
        sc = load_scenario(file)
        planners = [("rrt", None)] + [("fuzzy-rrt", p) for p in two_joint_rulebooks()]
        for planner, rb in planners:
            for seed in SEEDS:
                r = (plan_rrt(sc, seed=seed) if rb is None
                     else plan_fuzzy_rrt(sc, rulebook=rb, seed=seed))
                rows.append({"scenario": file.name, "planner": planner,
                             "rulebook": rb.name if rb else "", "seed": seed,
                             "found": bool(len(r.path_deg) > 0), "iterations": r.iterations,
                             "nodes": r.nodes,
                             "cost_deg": float("nan") if r.cost_deg is None else r.cost_deg})
    return pd.DataFrame(rows)


def main() -> None:
    GOLDEN.mkdir(parents=True, exist_ok=True)
    engine_frame().to_csv(GOLDEN / "engine.csv", index=False, float_format="%.17g")
    plans_frame().to_csv(GOLDEN / "plans.csv", index=False, float_format="%.17g")
    print(f"wrote {GOLDEN / 'engine.csv'} and {GOLDEN / 'plans.csv'}")


if __name__ == "__main__":
    main()
