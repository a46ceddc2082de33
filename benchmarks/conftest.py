"""Shared benchmark fixtures."""

from __future__ import annotations

from pathlib import Path

import pytest

SHARED_SCENARIOS = Path(__file__).resolve().parents[2] / "shared" / "scenarios"


@pytest.fixture(scope="module")
def scenario():
    """``paper-reference`` when ``../shared`` is present, else the shipped demo scenario."""
    from xfuzzy_rrt.bench.runner import shipped_scenarios
    from xfuzzy_rrt.geometry.scenario import load_scenario

    ref = SHARED_SCENARIOS / "paper-reference.toml"
    return load_scenario(ref if ref.exists() else shipped_scenarios()[-1])
