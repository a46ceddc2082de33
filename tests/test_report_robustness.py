"""The bench report's robustness section: present when asked for, numbers from the tables."""

from __future__ import annotations

import pandas as pd
import pytest

from conftest import FIXTURES
from xfuzzy_rrt.report.robustness_section import pooled_table
from xfuzzy_rrt.robustness.montecarlo import clopper_pearson

SCENARIO = FIXTURES / "scenarios" / "boxes-and-circle.toml"


def test_pooled_probability_is_collisions_over_trials_with_its_interval():
    frame = pd.DataFrame({"planner": ["rrt", "rrt", "rrt"], "sigma_m": [0.001, 0.001, 0.002],
                          "collisions": [3, 0, 10], "trials": [100, 100, 100],
                          "clearance_q01_m": [-0.001, 0.002, -0.003]})
    t = pooled_table(frame)
    first = t.iloc[0]
    assert (first["collisions"], first["trials"], first["paths_with_collision"]) == (3, 200, 1)
    assert first["p_collision"] == pytest.approx(3 / 200)
    assert (first["ci_low"], first["ci_high"]) == pytest.approx(clopper_pearson(3, 200))
    assert first["clearance_q01_min_m"] == -0.001
    assert len(t) == 2


def test_report_gains_a_robustness_section_after_robustness_bench(tmp_path, run_cli):
    out = tmp_path / "b"
    proc = run_cli("bench", SCENARIO, "--planners", "rrt,fuzzy-rrt", "--runs", "2",
                   "--workers", "1", "--out", out)
    assert proc.returncode == 0, proc.stderr
    assert "Robustness: when the anatomy moves" not in (out / "report.html").read_text()
    proc = run_cli("robustness", "bench", out, "--trials", "200", "--sigma", "0.001,0.005",
                   "--workers", "1", "--html")
    assert proc.returncode == 0, proc.stderr
    assert f"xfuzzy-rrt report {out}" in proc.stdout
    proc = run_cli("report", out)
    assert proc.returncode == 0, proc.stderr
    page = (out / "report.html").read_text()
    assert "Robustness: when the anatomy moves" in page
    assert 'href="robustness/robustness.html"' in page
    table = pooled_table(pd.read_csv(out / "robustness" / "path_robustness.csv"))
    for r in table.itertuples():
        assert f"{r.p_collision:.4f} [{r.ci_low:.4f}, {r.ci_high:.4f}]" in page
