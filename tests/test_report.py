"""The benchmark audit report: an overview that answers first, evidence pages one click away.

What matters to its readers, and so what is checked: the verdict and the per-planner numbers
on the overview are the ones ``runs.csv`` gives (recomputed here independently); the site
works offline with one shared copy of plotly.js and every link resolves; user-supplied text is
escaped on every page; each scenario page holds the paths, runs and *Follow one plan* with the
very numbers ``xfuzzy-rrt explain`` prints; the worst path of each planner is stored and drawn;
``xfuzzy-rrt report DIR`` rebuilds the same pages without planning and refuses a training
history of another rulebook; numbers are shown with 3-4 significant digits.
"""

from __future__ import annotations

import dataclasses
import json
import re
import shutil
from pathlib import Path

import numpy as np
import pandas as pd
import pytest

from conftest import FIXTURES, PROJECT, run_main


@pytest.fixture
def run_cli():
    """The CLI through ``main(argv)`` in this process (``conftest.run_main``): these tests
    check what commands print, return and write, not the process; ~1.5 s less a call."""
    return run_main


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


def _pages(out: Path) -> dict[str, str]:
    pages = {"report.html": (out / "report.html").read_text(encoding="utf-8")}
    for p in sorted((out / "report").glob("*.html")):
        pages[f"report/{p.name}"] = p.read_text(encoding="utf-8")
    return pages


def _scenario_page(out: Path, name: str) -> str:
    (page,) = [p for p in (out / "report").glob("scenario-*.html")
               if f"<h1>Scenario: {name}</h1>" in p.read_text(encoding="utf-8")]
    return page.read_text(encoding="utf-8")


def _figures(text: str) -> dict:
    m = re.search(r'<script type="application/json" id="xf-figs">(.*?)</script>', text, re.S)
    return json.loads(m.group(1))


def _drill(text: str, key: str) -> dict:
    m = re.search(rf'<script type="application/json" id="{key}">(.*?)</script>', text, re.S)
    return json.loads(m.group(1))


def _visible(text: str) -> str:
    """The text of the page without scripts and markup (what a reader sees)."""
    return re.sub(r"<[^>]+>", " ", re.sub(r"<script\b.*?</script>", "", text, flags=re.S))


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
    return result, out


# ------------------------------------------------------------------------------ the overview


def test_overview_verdict_and_table_are_the_numbers_of_runs_csv(full):
    from xfuzzy_rrt.report.numbers import ratio

    _, out = full
    runs = pd.read_csv(out / "runs.csv")
    med = runs.groupby(["scenario", "planner"])["iterations"].median().unstack()
    r = (med["rrt"] / med["fuzzy-rrt"]).to_numpy()
    median = float(np.median(r))
    losses = int(np.sum(r < 1))
    html = (out / "report.html").read_text(encoding="utf-8")
    verdict = re.search(r'<ul class="xf-verdict" id="verdict">(.*?)</ul>', html, re.S).group(1)
    more_or_fewer = "fewer" if median >= 1 else "more"
    shown = ratio(median if median >= 1 else 1 / median)
    assert f"Fuzzy-RRT needs {shown} {more_or_fewer} iterations than RRT on 2 problems" in verdict
    assert ("it loses on none" if losses == 0 else f"it loses on {losses} ") in verdict
    assert "no path touched an obstacle" in verdict
    # The per-planner table: certified success and the median ratio.
    ok = runs.groupby("planner")["success"].mean()
    row = re.search(r"<tr><td class=\"txt\">Fuzzy-RRT</td>(.*?)</tr>", html).group(1)
    assert f">{round(100 * ok['fuzzy-rrt'])}%<" in row
    assert f">{ratio(median)}<" in row
    # The verdict and the ratio plot come before any other section (the first screen), and
    # before the planner table, whose height grows with its planners and columns.
    assert html.index('id="verdict"') < html.index('id="ratio-plot"') < html.index(
        'class="data xf-planners"') < html.index('id="certification"')


def test_ratio_plot_points_link_to_their_scenario_pages(full):
    _, out = full
    html = (out / "report.html").read_text(encoding="utf-8")
    svg = re.search(r'<svg class="xf-ratio".*?</svg>', html, re.S).group(0)
    links = re.findall(r'<a href="([^"]+)" class="xf-point">', svg)
    assert len(links) == 2  # one point per scenario for the one planner compared
    for link in links:
        assert (out / link).is_file()
    for name in ("two-circles", "boxes-and-circle"):
        assert any(f"<h1>Scenario: {name}</h1>" in (out / link).read_text() for link in links)
    # Readable log ticks around 1.
    ticks = re.findall(r'text-anchor="end" fill="#444">([^<]+)</text>', svg)
    assert {"0.5", "1", "2"} <= set(ticks)


def test_site_is_offline_with_one_shared_plotly_and_every_link_resolves(full):
    _, out = full
    assert (out / "report" / "plotly.min.js").read_text(encoding="utf-8") == _plotlyjs()
    pages = _pages(out)
    assert len(pages) == 1 + 2 + 1  # overview, two scenarios, one rulebook
    for rel, text in pages.items():
        assert _plotlyjs()[:2000] not in text, rel  # not embedded: loaded from the copy
        srcs = re.findall(r"<script[^>]*\bsrc=\"([^\"]+)\"", text)
        assert srcs == [("report/" if rel == "report.html" else "") + "plotly.min.js"], rel
        assert not re.search(r"(src|href)=\"(https?:)?//", text), rel
        base = (out / rel).parent
        for href in re.findall(r'href="([^"#]+)(?:#[^"]*)?"', text):
            assert (base / href).is_file(), f"{rel}: broken link {href}"


def test_pages_are_deterministic_and_escape_the_command(full):
    from xfuzzy_rrt.report.site import build_pages

    result, _ = full
    cmd = "xfuzzy-rrt bench '<script>alert(1)</script>' & more"
    one = build_pages(result, cmd, generated_at="2000-01-01 00:00:00 UTC")
    two = build_pages(result, cmd, generated_at="2000-01-01 00:00:00 UTC")
    assert one == two
    assert all("<script>alert(1)</script>" not in t for t in one.values())
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in one["report.html"]


def test_scenario_named_like_a_script_appears_escaped_on_every_page(run_cli, tmp_path):
    evil = tmp_path / "evil.toml"
    text = re.sub(r'^name = .*$', 'name = "<script>alert(1)</script>"', TWO_CIRCLES.read_text(),
                  count=1, flags=re.M)
    evil.write_text(text)
    out = tmp_path / "out"
    proc = run_cli("bench", evil, "--planners", "rrt,fuzzy-rrt", "--runs", "2", "--out", out)
    assert proc.returncode == 0, proc.stderr
    pages = _pages(out)
    for rel, html in pages.items():
        assert "alert(1)</script>" not in html, rel  # not even inside the embedded JSON
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in pages["report.html"]
    scen = next(t for r, t in pages.items() if r.startswith("report/scenario-"))
    assert "<h1>Scenario: &lt;script&gt;alert(1)&lt;/script&gt;</h1>" in scen
    assert "&lt;script&gt;alert(1)&lt;/script&gt;" in json.dumps(_figures(scen)["fig-boxplots"])


def test_overview_answers_without_scrolling_through_tables(full):
    """The first edition began with a 48-row table; the overview holds no per-run table."""
    _, out = full
    html = (out / "report.html").read_text(encoding="utf-8")
    assert len(html.encode()) < 1_500_000
    assert html.count("<tr>") < 40


# ------------------------------------------------------------------------- evidence pages


def test_scenario_pages_hold_paths_runs_and_follow_one_plan(full):
    result, out = full
    for name in ("two-circles", "boxes-and-circle"):
        page = _scenario_page(out, name)
        figs = _figures(page)
        for fig_id in ("fig-rrt-joint", "fig-rrt-workspace", "fig-fuzzy-rrt-joint",
                       "fig-fuzzy-rrt-workspace", "fig-boxplots", "fig-outcomes",
                       "fig-s1-firing", "fig-s1-io", "fig-s1-drill"):
            assert fig_id in figs, (name, fig_id)
        ex = result.examples[(name, "rrt")]
        assert f"--planner rrt --seed {ex.seed}" in page
        assert "Rules that drove the example Fuzzy-RRT run" in page
        assert page.count("if angle_to_goal is ") >= 6 * 3
    # Bin labels of the rule-firing heatmap are categories, never dates (blank plots).
    assert _figures(page)["fig-s1-firing"]["layout"]["xaxis"]["type"] == "category"


def test_rulebook_page_has_units_colour_bars_and_coverage(full):
    _, out = full
    (page_path,) = (out / "report").glob("rulebook-*.html")
    figs = _figures(page_path.read_text(encoding="utf-8"))
    mf = figs["fig-mf-0"]["layout"]
    titles = [mf[k]["title"]["text"] for k in sorted(mf) if k.startswith("xaxis")]
    assert "dist_to_goal (m)" in titles and "angle_to_goal (rad)" in titles
    surf = figs["fig-surfaces"]["data"]
    assert len(surf) == 6 and all(t["showscale"] for t in surf)
    xs = sorted(round(t["colorbar"]["x"], 3) for t in surf)
    assert len(set(xs)) == 3  # one colour bar beside each panel column, not stacked
    assert "fig-coverage" in figs


def test_drilldown_numbers_equal_what_explain_prints(full, run_cli):
    result, out = full
    page = _scenario_page(out, "two-circles")
    payload = _drill(page, "drill-s1-data")
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
        block = lines[lines.index(f"== {output} =="):]
        for name, terms in active:
            assert f"  {name:18s}: {terms}" in block[:6]
        for idx, strength, contribution in rules:
            const = payload["consts"][output][str(idx)]
            k = block.index(next(line for line in block if line.startswith(f"    r{idx}: ")))
            assert block[k + 1] == f"          strength {strength} \u00d7 {const} = {contribution}"
            assert block[k].endswith(f" = {const}")  # the sentence shows the same constant
        assert f"  {output} = \u03a3 contributions = {value}  (planner recorded {recorded})" in block
    decision = lines[lines.index("Decision:") + 1:]
    for line in record["decision"]:
        assert f"  {line}" in decision


def test_drilldown_selects_path_expansions_within_budget(full):
    from xfuzzy_rrt.report.drilldown import per_scenario, select_iterations

    result, _ = full
    trace = result.examples[("two-circles", "fuzzy-rrt")].trace
    its = select_iterations(trace, 12)
    assert len(its) == 12 and its == sorted(set(its))
    assert its[0] == 1
    on_path = set(trace.loc[trace["on_path"], "iteration"])
    assert int(trace["iteration"].iloc[-1]) in its  # the goal expansion
    assert len(on_path & set(its)) >= 6
    assert per_scenario(1) == 40 and per_scenario(24) == 5


def test_people_read_numbers_with_at_most_four_significant_digits(full):
    _, out = full
    for rel, text in _pages(out).items():
        nums = re.findall(r"(?<![\w.#-])\d+\.\d+(?:e[-+]?\d+)?(?![\w.])", _visible(text))
        # Hashes and paths aside, no visible number carries more than 4 significant digits.
        long_numbers = [n for n in nums
                        if len(n.split("e")[0].replace(".", "").lstrip("0")) > 4]
        assert long_numbers == [], (rel, long_numbers[:5])


# ------------------------------------------------------------------ certification evidence


def test_worst_path_of_a_planner_is_its_closest_approach_over_all_scenarios():
    from types import SimpleNamespace

    from xfuzzy_rrt.report.site import worst_per_planner

    def run(scen, clearance):
        return SimpleNamespace(scenario=scen, min_clearance_m=clearance)

    result = SimpleNamespace(scenarios={"a": None, "b": None, "c": None}, worst_examples={
        ("a", "rrt"): run("a", 0.02), ("b", "rrt"): run("b", 0.005), ("c", "rrt"): run("c", 0.005),
        ("a", "ompl:RRT"): run("a", -0.003), ("b", "ompl:RRT"): run("b", None)})
    worst = worst_per_planner(result)
    assert worst["rrt"].scenario == "b"  # the smallest clearance; the first scenario on ties
    assert worst["ompl:RRT"].scenario == "a"  # a penetration is worse than any clearance


def test_worst_path_of_each_planner_is_stored_and_drawn(full):
    result, out = full
    index = json.loads((out / "examples" / "index.json").read_text())
    stored = [e for e in index if e.get("role") == "worst"]
    runs = result.runs
    html = (out / "report.html").read_text(encoding="utf-8")
    figs = _figures(html)
    for planner in ("rrt", "fuzzy-rrt"):
        mine = [e for e in stored if e["planner"] == planner]
        assert len(mine) == 2  # one per scenario
        closest = min(mine, key=lambda e: e["min_clearance_m"])
        found = runs[(runs["planner"] == planner) & runs["found"].astype(bool)]
        assert closest["min_clearance_m"] == pytest.approx(found["min_clearance_m"].min())
        fig = figs[f"fig-worst-{planner}"]
        assert any(t.get("name") == "closest configuration" for t in fig["data"])
        title = json.dumps(fig["layout"]["title"])
        assert f"{closest['scenario']}, seed {closest['seed']}" in title


def test_worst_pose_is_the_closest_configuration_along_the_path(full):
    from xfuzzy_rrt.geometry.path_check import signed_clearance
    from xfuzzy_rrt.report import figures as F
    from xfuzzy_rrt.report.site import worst_pose

    result, _ = full
    from xfuzzy_rrt.report.site import worst_per_planner

    r = worst_per_planner(result)["rrt"]
    s = result.scenarios[r.scenario]
    q, c = worst_pose(s, r.path_deg)
    dense = F.interpolate_path(r.path_deg, 0.25)
    assert c == pytest.approx(min(signed_clearance(s.arrays(), p) for p in dense))
    assert c > 0  # a certified path


# ----------------------------------------------------------------------- verdict sentences


def _runs(**planners) -> pd.DataFrame:
    rows = []
    for planner, per_scen in planners.items():
        for scen, (its, tf, cert, pen) in per_scen.items():
            rows.append({"scenario": scen, "planner": planner, "seed": 0, "success": cert,
                         "found": True, "certified": cert, "iterations": its, "nodes": its,
                         "cost_deg": 100.0, "wall_s": tf, "time_first_s": tf,
                         "min_clearance_m": 0.004 if cert else -pen, "penetration_m": pen})
    return pd.DataFrame(rows)


def test_verdict_compares_ompl_on_time_to_first_path_and_reports_penetration():
    from xfuzzy_rrt.report.overview import planner_table, verdicts

    runs = _runs(**{
        "rrt": {"a": (100, 0.010, True, 0.0), "b": (100, 0.010, True, 0.0),
                "c": (100, 0.010, True, 0.0)},
        "fuzzy-rrt:general": {"a": (50, 0.004, True, 0.0), "b": (25, 0.003, True, 0.0),
                              "c": (200, 0.020, True, 0.0)},
        # Far fewer "iterations" but slower: compared on time, it loses twice.
        "ompl:RRTConnect": {"a": (5, 0.020, True, 0.0), "b": (5, 0.020, False, 0.0074),
                            "c": (5, 0.005, True, 0.0)}})
    table = planner_table(runs)
    general, ompl = table.iloc[1], table.iloc[2]
    assert general["metric"] == "iterations" and general["ratio_median"] == pytest.approx(2.0)
    assert general["losses"] == 1 and general["ratio_worst"] == pytest.approx(0.5)
    assert ompl["metric"] == "time_first_s" and ompl["ratio_median"] == pytest.approx(0.5)
    assert ompl["success_rate"] == pytest.approx(2 / 3)
    text = verdicts(table)
    assert text[0] == ("Fuzzy-RRT general needs 2\u00d7 fewer iterations than RRT on 3 problems "
                       "(median); it loses on 1 (worst 0.5\u00d7); no path touched an obstacle "
                       "(closest 4 mm).")
    assert text[1].startswith("OMPL RRTConnect finds its first path 2\u00d7 slower than RRT")
    assert "certified success 67%" in text[1]
    assert "1 of 3 paths penetrated an obstacle (deepest 7.4 mm)" in text[1]
    assert text[2].startswith("RRT (the baseline)")
    even = planner_table(runs.assign(iterations=100, time_first_s=0.01))
    assert verdicts(even)[0].startswith("Fuzzy-RRT general needs as many iterations as RRT")


# -------------------------------------------------------------------------------- numbers


def test_numbers_read_with_four_significant_digits_and_units():
    from xfuzzy_rrt.report import numbers as N

    assert N.sig(2.4664367420312074e-05) == "2.466e-05"
    assert N.sig(0.44999999999999996) == "0.45"
    assert N.sig(1234.5678) == "1235" and N.sig(142.5) == "142.5" and N.sig(3.0) == "3"
    assert N.sig(float("nan")) == "\u2014" and N.sig(None) == "\u2014"
    assert N.qty(12.3456, "deg") == "12.35\u00b0" and N.qty(0.15, "m") == "0.15 m"
    assert N.seconds(0.000218) == "218 \u00b5s" and N.seconds(0.0123) == "12.3 ms"
    assert N.metres(0.0074) == "7.4 mm" and N.metres(-2e-6) == "-2 \u00b5m"
    assert N.percent(199 / 200) == "99.5%" and N.percent(1.0) == "100%"
    assert N.ratio(1.4142) == "1.4\u00d7"
    assert (N.readable_numbers("r12: if x is near then goal_bias = 0.28991466315272363")
            == "r12: if x is near then goal_bias = 0.2899")


# ------------------------------------------------------------------------ report DIR (CLI)


def test_report_dir_rebuilds_the_same_pages_without_planning(full, monkeypatch, tmp_path):
    from xfuzzy_rrt.bench.store import load_bench_dir
    from xfuzzy_rrt.cli.main import main
    from xfuzzy_rrt.planners import api, fuzzy_rrt, rrt
    from xfuzzy_rrt.report.site import build_pages

    result, out = full
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    (copy / "report.html").unlink()
    shutil.rmtree(copy / "report")

    def boom(*a, **k):
        raise AssertionError("report must not plan")

    for mod, name in ((api, "plan_scenario"), (rrt, "plan_rrt"), (fuzzy_rrt, "plan_fuzzy_rrt")):
        monkeypatch.setattr(mod, name, boom)
    assert main(["report", str(copy)]) == 0
    assert _scenario_page(copy, "boxes-and-circle")
    assert not [p for p in copy.iterdir() if p.name.startswith(".")]  # no staging left
    again = load_bench_dir(copy)
    assert (build_pages(again, generated_at="T", folder=copy)
            == build_pages(result, generated_at="T", folder=copy))


def _trained_copy(tmp_path: Path, folder: str, **changes) -> Path:
    """A rulebook folder with a ``history.csv`` beside it; ``changes`` to the expert rulebook
    (none: the expert's own files, so the same SHA-256)."""
    from xfuzzy_rrt.fuzzy.manifest import thaw
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, save_rulebook

    d = tmp_path / folder
    if changes:
        rb = load_rulebook(EXPERT)
        save_rulebook(dataclasses.replace(rb, provenance={**thaw(rb.provenance),
                                                          "history": "history.csv"}, **changes), d)
    else:
        shutil.copytree(EXPERT, d)
    pd.DataFrame({"generation": [0, 1, 2], "best_fitness": [3.0, 2.0, 1.5],
                  "mean_fitness": [5.0, 4.0, 3.0], "median_fitness": [4.5, 3.5, 2.9],
                  "wall_s": [1.0, 1.0, 1.0]}).to_csv(d / "history.csv", index=False)
    return d


def test_report_history_of_the_benchmarks_rulebook_is_drawn_on_its_page(full, tmp_path, run_cli):
    _, out = full
    same = _trained_copy(tmp_path, "same")  # same systems: the same SHA-256
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    proc = run_cli("report", copy, "--history", same / "history.csv")
    assert proc.returncode == 0, proc.stderr
    (page,) = (copy / "report").glob("rulebook-*.html")
    text = page.read_text(encoding="utf-8")
    fig = _figures(text)["fig-training"]
    assert [t["name"] for t in fig["data"]] == ["best", "mean", "median"]
    assert str((same / "history.csv").resolve()) in text


def test_report_history_of_another_rulebook_is_refused(full, tmp_path, run_cli):
    _, out = full
    other = _trained_copy(tmp_path, "other", name="other", bounds_mode="relative")
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    before = (copy / "report.html").read_bytes()
    proc = run_cli("report", copy, "--history", other / "history.csv")
    assert proc.returncode == 2
    lines = proc.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"error: {other / 'history.csv'}: ")
    assert "history of rulebook other" in lines[0] and "expert" in lines[0]
    assert (copy / "report.html").read_bytes() == before  # nothing rewritten


def test_report_history_that_names_no_rulebook_is_refused(full, tmp_path, run_cli):
    _, out = full
    loose = tmp_path / "history.csv"
    pd.DataFrame({"generation": [0], "best_fitness": [1.0]}).to_csv(loose, index=False)
    proc = run_cli("report", out, "--history", loose)
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [
        f"error: {loose}: cannot tell which rulebook this history trained (no rulebook.toml "
        "beside it)"]


def test_training_history_named_by_the_rulebook_manifest_is_found(tmp_path):
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.cli.bench import write_outputs
    from xfuzzy_rrt.geometry.scenario import load_scenario

    trained = _trained_copy(tmp_path, "trained", description="trained, with its history")
    result = run_benchmark([load_scenario(TWO_CIRCLES)], ["fuzzy-rrt"], runs=2, rulebook=trained)
    write_outputs(result, tmp_path / "out", "cmd")
    (page,) = (tmp_path / "out" / "report").glob("rulebook-*.html")
    assert "fig-training" in _figures(page.read_text(encoding="utf-8"))


def test_report_on_a_folder_without_bench_json_is_one_error_line(run_cli, tmp_path):
    proc = run_cli("report", tmp_path)
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [
        f"error: {tmp_path / 'bench.json'}: missing (not a folder written by 'xfuzzy-rrt bench')"]


def test_report_with_a_different_rulebook_is_refused(full, run_cli, tmp_path):
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, save_rulebook

    _, out = full
    rb = load_rulebook(EXPERT)
    other = tmp_path / "other"
    save_rulebook(dataclasses.replace(rb, name="other"), other)
    proc = run_cli("report", out, "--rulebook", other)
    assert proc.returncode == 2
    assert "is not the one this benchmark used" in proc.stderr
    assert len(proc.stderr.strip().splitlines()) == 1


def test_report_pdf_without_chromium_is_one_error_line_and_no_file(full, run_cli, tmp_path,
                                                                   monkeypatch):
    _, out = full
    monkeypatch.setenv("XFUZZY_CHROMIUM", str(tmp_path / "no-such-browser"))
    proc = run_cli("report", out, "--pdf")
    assert proc.returncode == 2
    assert proc.stderr.strip().splitlines() == [
        f"error: XFUZZY_CHROMIUM: {tmp_path / 'no-such-browser'}: no such file"]
    assert not (out / "report.pdf").exists()


def test_report_pdf_prints_the_overview_with_chromium(full, run_cli, tmp_path):
    import os

    from xfuzzy_rrt.report.pdf import find_chromium

    try:
        find_chromium()
    except Exception as exc:
        if os.environ.get("CI"):
            pytest.fail(f"Chromium is needed in CI: {exc}")
        pytest.skip(str(exc))
    _, out = full
    copy = tmp_path / "copy"
    shutil.copytree(out, copy)
    proc = run_cli("report", copy, "--pdf")
    assert proc.returncode == 0, proc.stderr
    data = (copy / "report.pdf").read_bytes()
    assert data.startswith(b"%PDF") and len(data) > 20_000
    assert not [p for p in copy.iterdir() if p.name.startswith(".")]


# -------------------------------------------------------------------------------- figures


def test_figures_geometry():
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.geometry.collision import in_collision
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.report import figures as F

    scenario = load_scenario(TWO_CIRCLES)
    bench = run_benchmark([scenario], ["rrt"], runs=3)
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


def test_planners_of_one_report_get_distinct_labels_and_colours():
    from xfuzzy_rrt.report import figures as F

    names = ["ompl:RRTConnect", "fuzzy-rrt:paper", "rrt", "fuzzy-rrt:general"]
    assert F.planner_order(names) == ["rrt", "fuzzy-rrt:paper", "fuzzy-rrt:general",
                                      "ompl:RRTConnect"]
    assert [F.planner_label(p) for p in names] == ["OMPL RRTConnect", "Fuzzy-RRT paper", "RRT",
                                                   "Fuzzy-RRT general"]
    assert len({F.planner_color(p) for p in names}) == 4


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
    from xfuzzy_rrt.report.numbers import sig

    out = tmp_path / "bench"
    proc = run_cli("bench", TWO_CIRCLES, "--planners", "rrt", "--runs", "3", "--out", out)
    assert proc.returncode == 0, proc.stderr
    runs = pd.read_csv(out / "runs.csv")
    summary = pd.read_csv(out / "summary.csv")
    assert set(SPEC_RUN_COLUMNS) <= set(runs.columns)
    assert set(["scenario", "planner"] + SPEC_SUMMARY_COLUMNS) <= set(summary.columns)
    assert len(runs) == 3 and len(summary) == 1
    page = _scenario_page(out, "two-circles")
    s = summary.iloc[0]
    assert (f"{sig(s['iterations_min'])} / {sig(s['iterations_median'])} / "
            f"{sig(s['iterations_max'])}") in page
    assert not [p.name for p in out.rglob(".*")]  # no temp files left
