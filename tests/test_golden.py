"""Golden files: engine outputs of every shipped rulebook and fixed plans stay what they were.

The files are written by ``scripts/make_golden.py`` (run it only for a deliberate change; the
diff then shows in review). Engine and planner could drift together and still agree with each
other's reference implementation; these files pin the numbers themselves.
"""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from tests.conftest import FIXTURES, SHARED_SCENARIOS
from xfuzzy_rrt.fuzzy.engine import evaluate
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebooks_dir
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt
from xfuzzy_rrt.planners.rrt import plan_rrt

GOLDEN = Path(__file__).resolve().parent / "golden"
ENGINE = pd.read_csv(GOLDEN / "engine.csv")
PLANS = pd.read_csv(GOLDEN / "plans.csv").fillna({"rulebook": ""})


def _scenario_file(name: str) -> Path | None:
    from xfuzzy_rrt.bench.runner import shipped_scenarios

    for candidate in [FIXTURES / "scenarios" / name, *(p for p in shipped_scenarios() if p.name == name),
                      SHARED_SCENARIOS / name]:
        if candidate.is_file():
            return candidate
    return None


@pytest.mark.parametrize("name", sorted(ENGINE["rulebook"].unique()))
def test_engine_outputs_of_shipped_rulebooks_match_golden_file(name):
    rows = ENGINE[ENGINE["rulebook"] == name].dropna(axis=1, how="all")  # rulebooks differ in outputs
    X = rows[[c for c in rows.columns if c.startswith("x")]].to_numpy()
    expected = rows[[c for c in rows.columns if c.startswith("y")]].to_numpy()
    got = evaluate(*load_rulebook(rulebooks_dir() / name).compiled, X)
    np.testing.assert_allclose(got, expected, rtol=1e-13, atol=1e-12)


def test_golden_plans_cover_rrt_and_every_shipped_rulebook():
    assert set(PLANS["planner"]) == {"rrt", "fuzzy-rrt"}
    assert {"paper", "expert", "general", "goal-frame"} <= set(PLANS["rulebook"])
    assert set(PLANS["seed"]) == set(range(5))


@pytest.mark.parametrize("scenario", sorted(PLANS["scenario"].unique()))
def test_plans_match_golden_iterations_nodes_and_cost(scenario):
    file = _scenario_file(scenario)
    if file is None:
        pytest.skip(f"{scenario} not available here (../shared absent)")
    sc = load_scenario(file)
    for row in PLANS[PLANS["scenario"] == scenario].itertuples():
        if row.planner == "rrt":
            r = plan_rrt(sc, seed=row.seed)
        else:
            r = plan_fuzzy_rrt(sc, rulebook=rulebooks_dir() / row.rulebook, seed=row.seed)
        label = f"{scenario} {row.planner} {row.rulebook} seed {row.seed}"
        assert (r.iterations, r.nodes) == (row.iterations, row.nodes), label
        if math.isnan(row.cost_deg):
            assert r.cost_deg is None, label
        else:
            assert r.cost_deg == pytest.approx(row.cost_deg, rel=1e-12), label
