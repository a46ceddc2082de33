"""The benchmark audit report: offline, self-contained, deterministic, showing the numbers.

The report is read by auditors who may open it on an air-gapped machine, so the checks that
matter are: plotly.js embedded exactly once and no script fetched from the network; the
scenario, the summary numbers and every figure present; escaping of user-supplied text; and the
same inputs giving the same bytes (apart from the date line). The CLI test drives the real
console script end to end (runs.csv, summary.csv with the SPEC columns, report.html).
"""

from __future__ import annotations

import dataclasses
import re

import numpy as np
import pandas as pd
import pytest

from conftest import FIXTURES

TWO_CIRCLES = FIXTURES / "scenarios" / "two-circles.toml"
BOXES = FIXTURES / "scenarios" / "boxes-and-circle.toml"

SPEC_RUN_COLUMNS = ["scenario", "planner", "seed", "success", "iterations", "nodes", "cost_deg",
                    "wall_s"]
SPEC_SUMMARY_COLUMNS = ["runs", "success_rate", "iterations_min", "iterations_median",
                        "iterations_max", "cost_min", "cost_median", "cost_max",
                        "wall_median_s"]


def _plotlyjs() -> str:
    from plotly.offline import get_plotlyjs

    return get_plotlyjs()


def _as_text(x: float) -> str:
    """How a median of counts is expected to appear: '142' or '142.5'."""
    x = float(x)
    return str(int(x)) if x.is_integer() else f"{x:.1f}"


def _assert_offline(text: str) -> None:
    assert not re.search(r"<script[^>]*\bsrc\s*=", text, flags=re.I), "external script"
    assert not re.search(r"<link[^>]*href\s*=\s*[\"']?https?://", text, flags=re.I)
    assert text.count(_plotlyjs()) == 1


@pytest.fixture(scope="module")
def scenario():
    from xfuzzy_rrt.geometry.scenario import load_scenario

    return load_scenario(TWO_CIRCLES)


@pytest.fixture(scope="module")
def bench(scenario):
    from xfuzzy_rrt.bench.runner import run_benchmark

    return run_benchmark([scenario], ["rrt"], runs=3)


@pytest.fixture(scope="module")
def two_planner_bench():
    """A two-planner result without depending on Fuzzy-RRT being available in the tree.

    RRT runs relabelled as ``fuzzy-rrt`` and given a synthetic trace exercise the two-column
    layout, the ratio table and the outcome chart; a second scenario has no fuzzy example
    (as when every run failed).
    """
    from xfuzzy_rrt.bench.runner import BenchResult, run_benchmark, summarise
    from xfuzzy_rrt.geometry.scenario import load_scenario

    scen = [load_scenario(TWO_CIRCLES), load_scenario(BOXES)]
    a = run_benchmark(scen, ["rrt"], runs=4, seed=0)
    b = run_benchmark(scen, ["rrt"], runs=4, seed=50)
    runs = pd.concat([a.runs, b.runs.assign(planner="fuzzy-rrt", rulebook="paper",
                                            rulebook_sha256="0" * 64)], ignore_index=True)
    examples = dict(a.examples)
    r = b.examples[("two-circles", "rrt")]
    trace = pd.DataFrame({"outcome": np.array([0] * 5 + [1] * 3 + [2] * 2 + [3])})
    examples[("two-circles", "fuzzy-rrt")] = dataclasses.replace(r, planner="fuzzy-rrt",
                                                                 trace=trace)
    return BenchResult(runs=runs, summary=summarise(runs), examples=examples,
                       scenarios=a.scenarios,
                       settings={**a.settings, "planners": ["fuzzy-rrt", "rrt"],
                                 "rulebook": "paper", "rulebook_sha256": "0" * 64})


def test_report_is_written_offline_with_numbers_and_figures(bench, tmp_path):
    from xfuzzy_rrt.report.bench_report import write_bench_report

    out = tmp_path / "report.html"
    write_bench_report(bench, out, command="xfuzzy-rrt bench two-circles.toml --planners rrt")
    assert out.is_file()
    text = out.read_text(encoding="utf-8")
    _assert_offline(text)
    assert "two-circles" in text
    assert "xfuzzy-rrt bench two-circles.toml --planners rrt" in text
    import xfuzzy_rrt

    assert xfuzzy_rrt.__version__ in text

    med = float(np.median(bench.runs["iterations"]))
    assert bench.summary.loc[0, "iterations_median"] == med
    assert f'<td class="num">{_as_text(med)}</td>' in text
    for col in ("iterations_min", "iterations_max"):
        assert f'<td class="num">{int(bench.summary.loc[0, col])}</td>' in text
    assert f"{bench.summary.loc[0, 'cost_median']:.1f}" in text

    for div_id in ("fig-boxplots", "fig-s0-rrt-joint", "fig-s0-rrt-workspace"):
        assert f'id="{div_id}"' in text
    # Every figure div is drawn by a newPlot call on the same id.
    ids = re.findall(r'<div id="(fig-[^"]+)" class="plotly-graph-div"', text)
    assert len(ids) == len(set(ids)) == 3
    # The example run is identified so that it can be reproduced.
    ex = bench.examples[("two-circles", "rrt")]
    assert f"--planner rrt --seed {ex.seed}" in text


def test_report_is_deterministic_and_escapes_text(bench):
    from xfuzzy_rrt.report.bench_report import render_bench_report

    cmd = "xfuzzy-rrt bench '<script>alert(1)</script>' & more"
    one = render_bench_report(bench, cmd, generated_at="2000-01-01 00:00:00 UTC")
    two = render_bench_report(bench, cmd, generated_at="2000-01-01 00:00:00 UTC")
    assert one == two
    assert "<script>alert(1)</script>" not in one
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in one


def test_two_planner_report_has_ratios_outcomes_and_placeholders(two_planner_bench):
    from xfuzzy_rrt.report.bench_report import render_bench_report

    text = render_bench_report(two_planner_bench, "cmd", generated_at="t")
    _assert_offline(text)
    assert "Fuzzy-RRT relative to RRT" in text
    s = two_planner_bench.summary.set_index(["scenario", "planner"])
    ratio = (s.loc[("two-circles", "fuzzy-rrt"), "iterations_median"]
             / s.loc[("two-circles", "rrt"), "iterations_median"])
    assert f"{ratio:.2f}" in text
    for div_id in ("fig-s0-rrt-joint", "fig-s0-fuzzy-rrt-joint", "fig-s0-fuzzy-rrt-workspace",
                   "fig-s0-outcomes", "fig-s1-rrt-joint"):
        assert f'id="{div_id}"' in text
    # No fuzzy example on the second scenario, and no trace there: skipped gracefully.
    assert 'id="fig-s1-fuzzy-rrt-joint"' not in text
    assert 'id="fig-s1-outcomes"' not in text
    assert "Fuzzy-RRT: no successful run to show" in text
    # Planner order is RRT then Fuzzy-RRT whatever the settings order.
    assert text.index('id="fig-s0-rrt-joint"') < text.index('id="fig-s0-fuzzy-rrt-joint"')


def test_figures_geometry(scenario, bench):
    from xfuzzy_rrt.geometry.collision import in_collision
    from xfuzzy_rrt.report import figures as F

    grid = F.cspace_grid(scenario, res_deg=2.0)
    assert grid.collision.shape == (181, 181)
    assert 0 < grid.collision.mean() < 1
    a = scenario.arrays()
    for j, i in [(10, 20), (90, 90), (150, 40)]:
        q = (grid.q1_deg[i], grid.q2_deg[j])
        assert grid.collision[j, i] == in_collision(a, q)

    r = bench.examples[("two-circles", "rrt")]
    ex, ey = F.tree_edges(r.tree_nodes_deg, r.tree_parent)
    n_edges = int(np.sum(r.tree_parent >= 0))
    assert ex.shape == ey.shape == (3 * n_edges,)
    assert np.isnan(ex[2::3]).all()

    dense = F.interpolate_path(r.path_deg, 1.0)
    np.testing.assert_array_equal(dense[0], r.path_deg[0])
    np.testing.assert_array_equal(dense[-1], r.path_deg[-1])
    assert np.max(np.linalg.norm(np.diff(dense, axis=0), axis=1)) <= 1.0 + 1e-9

    js = F.joint_space_figure(scenario, r, grid=grid)
    assert js.layout.yaxis.scaleanchor == "x"
    ws = F.workspace_figure(scenario, r)
    assert ws.layout.yaxis.scaleanchor == "x"
    assert len(ws.layout.shapes) == len(scenario.obstacles) + 1  # + the reach circle
    assert F.outcome_figure({"rrt": r}) is None  # plain RRT has no trace


def test_bench_cli_writes_tables_and_report(run_cli, tmp_path):
    out = tmp_path / "bench"
    proc = run_cli("bench", TWO_CIRCLES, "--planners", "rrt", "--runs", "3", "--out", out)
    assert proc.returncode == 0, proc.stderr
    runs = pd.read_csv(out / "runs.csv")
    summary = pd.read_csv(out / "summary.csv")
    assert set(SPEC_RUN_COLUMNS) <= set(runs.columns)
    assert set(["scenario", "planner"] + SPEC_SUMMARY_COLUMNS) <= set(summary.columns)
    assert len(runs) == 3 and len(summary) == 1
    text = (out / "report.html").read_text(encoding="utf-8")
    _assert_offline(text)
    assert "two-circles" in text
    assert f'<td class="num">{_as_text(summary.loc[0, "iterations_median"])}</td>' in text
    assert not [p.name for p in out.iterdir() if p.name.startswith(".")]  # no temp files left


def test_benchmark_results_do_not_depend_on_the_number_of_workers():
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.geometry.scenario import load_scenario

    s = load_scenario(TWO_CIRCLES)
    one = run_benchmark([s], ["rrt", "fuzzy-rrt"], runs=6, workers=1)
    two = run_benchmark([s], ["rrt", "fuzzy-rrt"], runs=6, workers=2)
    cols = [c for c in one.runs.columns if c != "wall_s"]
    assert one.runs[cols].to_csv(index=False) == two.runs[cols].to_csv(index=False)


def test_report_names_the_rules_that_drove_the_fuzzy_example_run():
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.report.bench_report import render_bench_report

    s = load_scenario(TWO_CIRCLES)
    result = run_benchmark([s], ["rrt", "fuzzy-rrt"], runs=3)
    example = result.examples[(s.name, "fuzzy-rrt")]
    assert example.trace is not None and len(example.trace) == example.iterations
    html = render_bench_report(result, command="xfuzzy-rrt bench", generated_at="T")
    assert "Rules that drove the example Fuzzy-RRT run" in html
    assert html.count("if angle_to_goal is ") >= 6 * 3
