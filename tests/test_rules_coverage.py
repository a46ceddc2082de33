"""Rule coverage: counts recounted from raw traces, summaries, heatmap, CLI."""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from xfuzzy_rrt.analysis.coverage import (
    collect_counts, counts_from_trace, coverage_frame, coverage_grid, coverage_summary)
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
from xfuzzy_rrt.fuzzy.variables import MAX_FIRED, N_RULES, OUTPUTS
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.api import plan_scenario

from _rulebook_helpers import EXPERT, random_rulebook
from conftest import PROJECT

DEMO = PROJECT / "xfuzzy_rrt" / "data" / "scenarios" / "demo-tissue.toml"


@pytest.fixture(scope="module")
def rulebook():
    # random constants and per-FIS peaks: every FIS fires a different set of rules
    return random_rulebook(np.random.default_rng(3), bounds_mode="relative")


@pytest.fixture(scope="module")
def traces(rulebook):
    scen = load_scenario(DEMO)
    return [plan_scenario(scen, "fuzzy-rrt", rulebook=rulebook, seed=s, max_iter=400,
                          trace=True) for s in range(3)]


def _naive_recount(traces, f_out):
    """Row-by-row recount from the raw trace columns (no numpy tricks)."""
    fired = {}
    strength = {}
    on_path = {}
    n = 0
    for res in traces:
        t = res.trace
        for _, row in t.iterrows():
            n += 1
            for k in range(MAX_FIRED):
                r = int(row[f"{f_out}_rule_{k}"])
                if r < 0:
                    continue
                fired[r] = fired.get(r, 0) + 1
                strength[r] = strength.get(r, 0.0) + float(row[f"{f_out}_strength_{k}"])
                if bool(row["on_path"]):
                    on_path[r] = on_path.get(r, 0) + 1
    return fired, strength, on_path, n


def test_coverage_counts_equal_a_recount_from_raw_traces(rulebook, traces):
    total = None
    for res in traces:
        c = counts_from_trace(res.trace, success=res.success)
        if total is None:
            total = c
        else:
            total.add(c)
    cov = coverage_frame(total, rulebook)
    assert len(cov) == len(OUTPUTS) * N_RULES
    for out in ("goal_bias", "step_size"):
        fired, strength, on_path, n = _naive_recount(traces, out)
        g = cov[cov["output"] == out].set_index("rule")
        assert total.iterations == n
        assert {r: int(v) for r, v in g["fired"].items() if v} == fired
        assert {r: int(v) for r, v in g["fired_on_path"].items() if v} == on_path
        for r, s in strength.items():
            assert g.loc[r, "strength_total"] == pytest.approx(s, rel=1e-12)
            assert g.loc[r, "mass_share"] == pytest.approx(s / n, rel=1e-12)
        assert (g["fired_on_path"] + g["fired_off_path"] == g["fired"]).all()
        assert g["mass_share"].sum() == pytest.approx(1.0, abs=1e-9)
        dead = set(range(N_RULES)) - set(fired)
        assert set(g.index[g["fired"] == 0]) == dead


def test_collect_counts_matches_per_trace_counts_and_ignores_workers(rulebook, traces):
    scen = load_scenario(DEMO)
    one = collect_counts(rulebook, [scen], runs=3, seed=0, max_iter=400, workers=1)
    two = collect_counts(rulebook, [scen], runs=3, seed=0, max_iter=400, workers=2)
    for a, b in ((one.fired, two.fired), (one.strength, two.strength)):
        assert np.array_equal(a, b)
    ref = counts_from_trace(traces[0].trace)
    for res in traces[1:]:
        ref.add(counts_from_trace(res.trace))
    assert np.array_equal(one.fired, ref.fired)
    assert np.array_equal(one.strength, ref.strength)
    assert one.runs == 3 and one.successes == sum(r.success for r in traces)


def test_rules_carrying_90_percent_are_the_smallest_such_set(rulebook, traces):
    total = counts_from_trace(traces[0].trace)
    cov = coverage_frame(total, rulebook)
    summary = coverage_summary(cov, total.iterations)
    for out in OUTPUTS:
        g = cov[cov["output"] == out].sort_values("rank")
        k = int(g["carries_90"].sum())
        shares = g["mass_share"].to_numpy()
        assert shares[:k].sum() >= 0.9 - 1e-9
        assert shares[:k - 1].sum() < 0.9
        assert g["carries_90"].to_numpy()[:k].all()
        row = summary[summary["output"] == out].iloc[0]
        assert row["rules_carrying_90"] == k
        assert row["rules_fired"] == int((g["fired"] > 0).sum())
    allrow = summary[summary["output"] == "all"].iloc[0]
    assert allrow["rules_fired"] == summary["rules_fired"][:-1].sum()


def test_heatmap_is_the_25_by_25_rule_grid(rulebook, traces):
    from xfuzzy_rrt.report.coverage_figure import coverage_heatmap

    cov = coverage_frame(counts_from_trace(traces[0].trace), rulebook)
    z = coverage_grid(cov, "bound_1", "fired")
    g = cov[cov["output"] == "bound_1"].set_index("rule")
    assert z.shape == (25, 25)
    assert z[154 // 25, 154 % 25] == g.loc[154, "fired"]
    fig = coverage_heatmap(cov, rulebook, "bound_1")
    heat = np.asarray(fig.data[0].z, dtype=float)
    assert heat.shape == (25, 25)
    assert np.isnan(heat[z == 0]).all()  # dead rules blank


def test_coverage_cli_writes_csv_and_page_from_scenarios_and_traces(run_cli, tmp_path):
    scen = load_scenario(DEMO)
    res = plan_scenario(scen, "fuzzy-rrt", rulebook=load_rulebook(EXPERT), seed=7, max_iter=300,
                        trace=True)
    res.trace.to_parquet(tmp_path / "t.parquet", index=False)
    proc = run_cli("rules", "coverage", EXPERT, DEMO, tmp_path / "t.parquet", "--runs", "2",
                   "--max-iter", "300", "--out", tmp_path / "cov.csv", "--html", tmp_path / "cov.html")
    assert proc.returncode == 0, proc.stderr
    cov = pd.read_csv(tmp_path / "cov.csv")
    assert len(cov) == len(OUTPUTS) * N_RULES
    runs = [plan_scenario(scen, "fuzzy-rrt", rulebook=load_rulebook(EXPERT), seed=s,
                          max_iter=300).iterations for s in (0, 1)]
    assert cov.groupby("output")["mass_share"].sum().to_numpy() == pytest.approx(1.0)
    assert "3 runs" in proc.stdout and f"{sum(runs) + res.iterations} iterations" in proc.stdout
    assert (tmp_path / "cov.html").read_text().count("cov-fig-") >= len(OUTPUTS)


def test_coverage_cli_rejects_a_trace_of_another_rulebook(run_cli, tmp_path):
    scen = load_scenario(DEMO)
    other = random_rulebook(np.random.default_rng(1))
    res = plan_scenario(scen, "fuzzy-rrt", rulebook=other, seed=0, max_iter=50, trace=True)
    res.trace.to_csv(tmp_path / "t.csv", index=False)
    proc = run_cli("rules", "coverage", EXPERT, tmp_path / "t.csv", "--out", tmp_path / "c.csv")
    assert proc.returncode == 2
    assert proc.stderr.startswith(f"error: {tmp_path / 't.csv'}: trace was made by rulebook")
    assert not (tmp_path / "c.csv").exists()
