"""Rule-influence statistics over a trace add up and name the rules that actually fired."""

from __future__ import annotations

import pytest

from conftest import FIXTURES
from xfuzzy_rrt.analysis.firing import rule_influence, top_rules
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.rulebook import default_rulebook_path, load_rulebook
from xfuzzy_rrt.fuzzy.variables import MAX_FIRED
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt


OUTPUTS = load_rulebook(default_rulebook_path()).outputs  # the default rulebook's semantics


@pytest.fixture(scope="module")
def trace():
    rb = load_rulebook(default_rulebook_path())
    s = load_scenario(FIXTURES / "scenarios" / "boxes-and-circle.toml")
    return plan_fuzzy_rrt(s, rb, seed=3, trace=True).trace


@pytest.mark.parametrize("output", OUTPUTS)
def test_influence_shares_sum_to_one_and_counts_match_the_trace(trace, output):
    inf = rule_influence(trace, output)
    assert inf["share"].sum() == pytest.approx(1.0, abs=1e-9)
    assert inf["influence"].sum() == pytest.approx(len(trace), rel=1e-12)
    rules = trace[[f"{output}_rule_{k}" for k in range(MAX_FIRED)]].to_numpy()
    for _, row in inf.head(3).iterrows():
        assert row["iterations_fired"] == int((rules == row["rule"]).any(axis=1).sum())
    assert list(inf["influence"]) == sorted(inf["influence"], reverse=True)


def test_top_rules_has_k_rows_per_output(trace):
    top = top_rules(trace, k=4)
    assert list(top.groupby("output", sort=False).size()) == [4] * len(OUTPUTS)


def test_unknown_output_is_an_input_error(trace):
    with pytest.raises(InputError):
        rule_influence(trace, "speed")
