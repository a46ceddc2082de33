"""The benchmark audit report: offline, self-contained, deterministic, showing the numbers.

The report is read by auditors who may open it on an air-gapped machine, so the checks that
matter are: plotly.js embedded exactly once and no script fetched from the network; the
scenarios, planners, summary numbers and every figure present; escaping of user-supplied text
(a scenario may be named ``<script>alert(1)</script>``); the drill-down showing the very numbers
``xfuzzy-rrt explain`` prints; ``xfuzzy-rrt report DIR`` rebuilding the same page from the
files on disk without planning; a training curve when a history is given.
"""

from __future__ import annotations

import dataclasses
import json
import re
import shutil

import numpy as np
import pandas as pd
import pytest

from conftest import FIXTURES, PROJECT

TWO_CIRCLES = FIXTURES / "scenarios" / "two-circles.toml"
BOXES = FIXTURES / "scenarios" / "boxes-and-circle.toml"
EXPERT = PROJECT / "rulebooks" / "expert"

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


def _figures(text: str) -> dict:
    m = re.search(r'<script type="application/json" id="xf-figs">(.*?)</script>', text, re.S)
    return json.loads(m.group(1))


def _drill(text: str, idx: int = 0) -> dict:
    m = re.search(rf'<script type="application/json" id="drill-s{idx}-data">(.*?)</script>',
                  text, re.S)
    return json.loads(m.group(1))


@pytest.fixture(scope="module")
def scenario():
    from xfuzzy_rrt.geometry.scenario import load_scenario

    return load_scenario(TWO_CIRCLES)


@pytest.fixture(scope="module")
def bench(scenario):
    from xfuzzy_rrt.bench.runner import run_benchmark

    return run_benchmark([scenario], ["rrt"], runs=3)


@pytest.fixture(scope="module")
def full(tmp_path_factory):
    """RRT and Fuzzy-RRT on two scenarios, written by the CLI's writer (tables + report)."""
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.cli.bench import write_outputs
    from xfuzzy_rrt.geometry.scenario import load_scenario

    result = run_benchmark([load_scenario(TWO_CIRCLES), load_scenario(BOXES)],
                           ["rrt", "fuzzy-rrt"], runs=4, rulebook=EXPERT)
    out = tmp_path_factory.mktemp("full")
    result = write_outputs(result, out, "xfuzzy-rrt bench two-circles.toml boxes-and-circle.toml")
    return result, out, (out / "report.html").read_text(encoding="utf-8")


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
    # Every figure div has exactly one figure specification under the same id.
    ids = re.findall(r'<div id="(fig-[^"]+)" class="plotly-graph-div"', text)
    assert len(ids) == len(set(ids)) == 3
    assert set(_figures(text)) == set(ids)
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


def test_scenario_named_like_a_script_appears_escaped_everywhere(run_cli, tmp_path):
    evil = tmp_path / "evil.toml"
    text = TWO_CIRCLES.read_text()
    text = re.sub(r'^name = .*$', 'name = "<script>alert(1)</script>"', text, count=1,
                  flags=re.M)
    evil.write_text(text)
    out = tmp_path / "out"
    proc = run_cli("bench", evil, "--planners", "rrt,fuzzy-rrt", "--runs", "2", "--out", out)
    assert proc.returncode == 0, proc.stderr
    html = (out / "report.html").read_text(encoding="utf-8")
    assert "<script>alert(1)</script>" not in html
    assert "alert(1)</script>" not in html  # not even inside the embedded JSON
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in html
    # Figure titles carry it HTML-escaped (plotly renders a subset of HTML in them).
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in json.dumps(_figures(html)["fig-boxplots"])
    assert re.search(r"Scenario: &lt;script&gt;alert\(1\)&lt;/script&gt;", html)


def test_report_names_every_planner_and_scenario(full):
    result, _, text = full
    _assert_offline(text)
    for name in ("two-circles", "boxes-and-circle"):
        assert f"Scenario: {name}" in text
    for label in ("RRT", "Fuzzy-RRT"):
        assert f"<td class=\"txt\">{label}</td>" in text
    for (scen, planner) in result.examples:
        idx = list(result.scenarios).index(scen)
        assert f'id="fig-s{idx}-{planner}-joint"' in text


def test_report_has_follow_one_plan_fuzzy_systems_and_provenance(full):
    result, _, text = full
    figs = _figures(text)
    for fig_id in ("fig-s0-firing", "fig-s0-io", "fig-s0-drill", "fig-mf-0", "fig-surfaces",
                   "fig-ratios", "fig-s1-firing"):
        assert fig_id in figs, fig_id
    assert "fixed: angle_to_goal = " in json.dumps(figs["fig-surfaces"]["layout"]["title"])
    rb = result.rulebook
    assert rb.sha256 in text
    assert result.provenance["versions"]["numpy"] in text
    sha = result.provenance["scenarios"]["two-circles"]["sha256"]
    assert sha[:16] in text
    assert "Reproduce: <code>xfuzzy-rrt rules show " in text
    assert "xfuzzy-rrt explain trace.parquet --rulebook" in text
    # The plotly template is stored once for all figures (not once per figure).
    assert text.replace(_plotlyjs(), "").count('"histogram2dcontour":') == 1


def test_drilldown_numbers_equal_what_explain_prints(full, run_cli):
    result, out, text = full
    payload = _drill(text, 0)
    index = json.loads((out / "examples" / "index.json").read_text())
    entry = next(e for e in index if e["scenario"] == "two-circles" and e["planner"] == "fuzzy-rrt")
    record = payload["iterations"][len(payload["iterations"]) // 2]
    proc = run_cli("explain", out / "examples" / entry["trace"], "--iteration",
                   str(record["iteration"]), "--rulebook", EXPERT)
    assert proc.returncode == 0, proc.stderr
    lines = proc.stdout.splitlines()
    assert lines[0].startswith(f"Iteration {record['iteration']} ")
    for name, value, note in record["inputs"]:
        assert f"  {name:18s} = {value}" + (f" ({note})" if note else "") in lines
    active = None
    for output, act, rules, value, recorded in record["systems"]:
        active = act or active
        start = lines.index(f"== {output} ==")
        block = lines[start:]
        for name, terms in active:
            assert f"  {name:18s}: {terms}" in block[:6]
        for idx, strength, contribution in rules:
            const = payload["consts"][output][str(idx)]
            const = const[1] if isinstance(const, list) else const
            k = block.index(next(line for line in block if line.startswith(f"    r{idx}: ")))
            assert block[k + 1] == f"          strength {strength} \u00d7 {const} = {contribution}"
        assert f"  {output} = \u03a3 contributions = {value}  (planner recorded {recorded})" in block
    decision = lines[lines.index("Decision:") + 1:]
    for line in record["decision"]:
        assert f"  {line}" in decision
    assert len(rules) >= 1


def test_drilldown_selects_path_expansions_within_budget(full):
    from xfuzzy_rrt.report.drilldown import per_scenario, select_iterations

    result, _, _ = full
    trace = result.examples[("two-circles", "fuzzy-rrt")].trace
    its = select_iterations(trace, 12)
    assert len(its) == 12 and its == sorted(set(its))
    assert its[0] == 1
    on_path = set(trace.loc[trace["on_path"], "iteration"])
    assert int(trace["iteration"].iloc[-1]) in its  # the goal expansion
    assert len(on_path & set(its)) >= 6
    assert per_scenario(1) == 40 and per_scenario(24) == 5


def test_report_dir_rebuilds_the_same_page_without_planning(full, monkeypatch, tmp_path):
    from xfuzzy_rrt.bench.store import load_bench_dir
    from xfuzzy_rrt.cli.main import main
    from xfuzzy_rrt.planners import api, fuzzy_rrt, rrt
    from xfuzzy_rrt.report.bench_report import render_bench_report

    result, out, _ = full
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    (copy / "report.html").unlink()

    def boom(*a, **k):
        raise AssertionError("report must not plan")

    for mod, name in ((api, "plan_scenario"), (rrt, "plan_rrt"), (fuzzy_rrt, "plan_fuzzy_rrt")):
        monkeypatch.setattr(mod, name, boom)
    assert main(["report", str(copy)]) == 0
    rebuilt = (copy / "report.html").read_text(encoding="utf-8")
    assert "Scenario: boxes-and-circle" in rebuilt and 'id="fig-s1-drill"' in rebuilt
    again = load_bench_dir(copy)
    assert render_bench_report(again, generated_at="T") == render_bench_report(result,
                                                                                generated_at="T")


def test_report_shows_the_training_curve_from_history(full, tmp_path, run_cli):
    _, out, text = full
    assert 'id="fig-training"' not in text
    history = tmp_path / "history.csv"
    pd.DataFrame({"generation": [0, 1, 2], "best_fitness": [3.0, 2.0, 1.5],
                  "mean_fitness": [5.0, 4.0, 3.0], "median_fitness": [4.5, 3.5, 2.9],
                  "wall_s": [1.0, 1.0, 1.0]}).to_csv(history, index=False)
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    proc = run_cli("report", copy, "--history", history)
    assert proc.returncode == 0, proc.stderr
    html = (copy / "report.html").read_text(encoding="utf-8")
    fig = _figures(html)["fig-training"]
    assert [t["name"] for t in fig["data"]] == ["best", "mean", "median"]
    assert str(history) in html


def test_training_history_named_by_the_rulebook_manifest_is_found(tmp_path):
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.cli.bench import write_outputs
    from xfuzzy_rrt.fuzzy.manifest import thaw
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, save_rulebook
    from xfuzzy_rrt.geometry.scenario import load_scenario

    rb = load_rulebook(EXPERT)
    trained = tmp_path / "trained"
    save_rulebook(dataclasses.replace(rb, provenance={**thaw(rb.provenance),
                                                      "history": "history.csv"}), trained)
    pd.DataFrame({"generation": [0, 1], "best_fitness": [2.0, 1.0], "mean_fitness": [3.0, 2.0],
                  "median_fitness": [2.5, 1.8], "wall_s": [1.0, 1.0]}).to_csv(
        trained / "history.csv", index=False)
    result = run_benchmark([load_scenario(TWO_CIRCLES)], ["fuzzy-rrt"], runs=2, rulebook=trained)
    write_outputs(result, tmp_path / "out", "cmd")
    html = (tmp_path / "out" / "report.html").read_text(encoding="utf-8")
    assert "fig-training" in _figures(html)


def test_report_on_a_folder_without_bench_json_is_one_error_line(run_cli, tmp_path):
    proc = run_cli("report", tmp_path)
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [
        f"error: {tmp_path / 'bench.json'}: missing (not a folder written by 'xfuzzy-rrt bench')"]


def test_report_with_a_different_rulebook_is_refused(full, run_cli, tmp_path):
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, save_rulebook

    _, out, _ = full
    rb = load_rulebook(EXPERT)
    other = tmp_path / "other"
    save_rulebook(dataclasses.replace(rb, name="other"), other)
    proc = run_cli("report", out, "--rulebook", other)
    assert proc.returncode == 2
    assert "is not the one this benchmark used" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_two_planner_report_has_ratios_outcomes_and_placeholders(two_planner_bench):
    from xfuzzy_rrt.report.bench_report import render_bench_report

    text = render_bench_report(two_planner_bench, "cmd", generated_at="t")
    _assert_offline(text)
    assert "Relative to RRT" in text
    s = two_planner_bench.summary.set_index(["scenario", "planner"])
    ratio = (s.loc[("two-circles", "rrt"), "iterations_median"]
             / s.loc[("two-circles", "fuzzy-rrt"), "iterations_median"])
    assert f"{ratio:.2f}" in text
    for div_id in ("fig-s0-rrt-joint", "fig-s0-fuzzy-rrt-joint", "fig-s0-fuzzy-rrt-workspace",
                   "fig-s0-outcomes", "fig-s1-rrt-joint", "fig-ratios"):
        assert f'id="{div_id}"' in text
    # No fuzzy example on the second scenario, and no trace there: skipped gracefully.
    assert 'id="fig-s1-fuzzy-rrt-joint"' not in text
    assert 'id="fig-s1-outcomes"' not in text
    assert 'id="fig-s0-drill"' not in text  # a trace without fired rules cannot be followed
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


def test_compact_figure_json_round_trips_arrays_and_shares_repeats():
    import plotly.graph_objects as go

    from xfuzzy_rrt.report.plotjson import SharedStore, _decode, figure_spec, script_json

    shared = SharedStore()
    grid = (np.arange(10_000).reshape(100, 100) % 3 == 0).astype(np.uint8)
    xs = np.linspace(-180, 180, 500)
    specs = [figure_spec(go.Figure([go.Heatmap(z=grid), go.Scatter(x=xs, y=xs)]), shared)
             for _ in range(3)]
    assert specs[0] == specs[1] == specs[2]
    heat, line = specs[0]["data"]
    bits = shared.values[heat["z"]["$ref"]]
    unpacked = np.unpackbits(np.frombuffer(__import__("base64").b64decode(bits["$bits"]),
                                           dtype=np.uint8))[:10_000].reshape(100, 100)
    np.testing.assert_array_equal(unpacked, grid)
    x = _decode(shared.values[line["x"]["$ref"]])
    assert x.dtype == np.float32 and np.allclose(x, xs, atol=1e-4)
    assert "<" not in script_json({"t": "</script><b>&"})


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
    assert not [p.name for p in out.rglob(".*")]  # no temp files left


def test_report_names_the_rules_that_drove_the_fuzzy_example_run(full):
    result, _, html = full
    example = result.examples[("two-circles", "fuzzy-rrt")]
    assert example.trace is not None and len(example.trace) == example.iterations
    assert "Rules that drove the example Fuzzy-RRT run" in html
    assert html.count("if angle_to_goal is ") >= 6 * 3
