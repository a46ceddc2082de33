"""benchmarks/ceiling.py, the bound on the default's speed-up over rrt:tuned: what it runs and
how it summarises (its figures are timings, reported in the README, never asserted here)."""

from __future__ import annotations

import math
from pathlib import Path

import pytest

from conftest import load_script
from xfuzzy_rrt.geometry.scenario import load_scenario

ROOT = Path(__file__).resolve().parents[1]
DEMO = ROOT / "xfuzzy_rrt" / "data" / "scenarios" / "demo-gap.toml"


@pytest.fixture(scope="module")
def ceiling():
    return load_script("benchmarks/ceiling.py")


def test_the_ceiling_is_the_tuned_call_over_the_floor_and_counts_problems_below_2x(ceiling):
    rows = [(4e-5, 2e-5, 3e-5), (9e-5, 3e-5, 4e-5), (3e-5, 2e-5, math.inf)]
    s = ceiling.summarise(rows)
    assert s["problems"] == 3 and s["ceiling"] == pytest.approx(2.0)
    assert s["worst_ceiling"] == pytest.approx(1.5) and s["below_2x"] == 1
    assert s["speedup"] == pytest.approx(4 / 3)  # a failed default counts as infinitely slow
    assert s["tuned_us"] == pytest.approx(40.0) and s["floor_us"] == pytest.approx(20.0)


def test_the_ceiling_measures_every_problem_with_all_three_calls(ceiling):
    scenario = load_scenario(DEMO)
    rows = ceiling.measure([scenario, scenario], range(3))
    assert len(rows) == 2
    for tuned, floor, default in rows:
        assert 0 < floor < math.inf and 0 < tuned < math.inf and 0 < default < math.inf
