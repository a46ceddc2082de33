"""The audit report in a real browser, at the size the issue asks for: 24 generated scenarios
× 4 planners (RRT, two rulebooks side by side, one OMPL planner), two runs each.

A report that passes string checks can still fail where it matters -- in the reader's browser
(a JavaScript error, a figure plotly cannot draw, a resource fetched from the network, a link
to nowhere, an answer below the fold). So the generated site is opened from ``file://`` in
headless Chromium (Debian's ``chromium``, driven by Playwright) and checked the way a reader
would meet it: the overview's first screen (1400 × 900) shows the verdict and the ratio plot and
responds within 2 s, every figure on every page has drawn marks, nothing is requested but
local files, no console error, every link resolves. The fixture is large enough that the
rule-firing heatmaps bin their columns (traces of 300+ iterations), the case that once drew
blank plots.

In CI (``CI`` set) a missing browser or Playwright is a failure, not a skip: ``.ci/run``
installs Chromium when it is absent.
"""

from __future__ import annotations

import io
import json
import os
import re
from pathlib import Path
from urllib.parse import unquote, urlparse

import pytest

CHROMIUM = Path(os.environ.get("XFUZZY_CHROMIUM", "/usr/bin/chromium"))
ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run"]
PLANNERS = ["rrt", "fuzzy-rrt:goal-frame", "fuzzy-rrt:paper", "ompl:RRTConnect"]  # the default and the paper rulebook
N_SCENARIOS = 24
#: The overview must respond within this time (issue 16) and weigh at most this much (without
#: the shared plotly.js).
INTERACTIVE_MS = 2000
OVERVIEW_BYTES = 1_500_000

#: Per figure, the number of drawn marks: line/marker/bar/box paths with real coordinates and
#: heatmap images with a positive width (a plot whose axis plotly misread draws none).
MARKS_JS = """() => Array.from(document.querySelectorAll('.plotly-graph-div')).map(d => {
  let n = 0;
  d.querySelectorAll('path.js-line, path.point, .bars path, .boxlayer path, path.js-fill')
    .forEach(p => { const a = p.getAttribute('d');
                    if (a && a.length > 3 && a.indexOf('NaN') < 0) n++; });
  d.querySelectorAll('image').forEach(i => {
    if (parseFloat(i.getAttribute('width')) > 0) n++; });
  return [d.id, n]; })"""


def _unavailable(reason: str):
    if os.environ.get("CI"):
        pytest.fail(f"browser test cannot run in CI: {reason}")
    pytest.skip(reason)


@pytest.fixture(scope="module")
def site(tmp_path_factory) -> Path:
    """The bench folder of 24 generated scenarios × 4 planners, written by the CLI's writer."""
    from xfuzzy_rrt.atomic import write_text_atomic
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.cli.bench import write_outputs
    from xfuzzy_rrt.geometry.scenario import load_scenario
    from xfuzzy_rrt.planners.api import check_planner

    try:
        check_planner("ompl:RRTConnect", "--planners")
    except Exception as exc:  # the OMPL extra is part of the test extras
        _unavailable(f"OMPL is not available: {exc}")
    from xfuzzy_rrt.scenarios.generate import generate_one

    out = tmp_path_factory.mktemp("browser")
    scenarios = []
    for k in range(N_SCENARIOS):
        problem = generate_one(2000, k)
        path = out / "scenarios" / f"{problem.scenario.name}.toml"
        write_text_atomic(path, problem.text)
        scenarios.append(load_scenario(path))
    result = run_benchmark(scenarios, PLANNERS, runs=2, max_iter=3000)
    write_outputs(result, out / "bench", "xfuzzy-rrt bench scenarios/ --planners "
                  + ",".join(PLANNERS) + " --runs 2 --max-iter 3000")
    return out / "bench"


@pytest.fixture(scope="module")
def browser():
    if not CHROMIUM.exists():
        _unavailable(f"{CHROMIUM} not found (Debian package 'chromium')")
    try:
        from playwright.sync_api import sync_playwright
    except ImportError:
        _unavailable("playwright is not installed (test extra)")
    with sync_playwright() as p:
        b = p.chromium.launch(executable_path=str(CHROMIUM), args=ARGS, headless=True)
        yield b
        b.close()


def _listen(page) -> dict:
    """What ``page`` logs, requests and asks from here on (cleared per visit by :func:`_visit`)."""
    seen = {"errors": [], "requests": [], "dialogs": []}
    page.on("console", lambda m: seen["errors"].append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: seen["errors"].append(str(e)))
    page.on("request", lambda r: seen["requests"].append(r.url))
    page.on("dialog", lambda d: (seen["dialogs"].append(d.message), d.dismiss()))
    return seen


def _visit(page, seen: dict, url: str) -> None:
    """Navigate ``page`` to ``url`` and draw every figure; ``seen`` then holds only this
    visit's messages and requests (anything left over from the previous document unloading
    would count against this one, never hide an error)."""
    for entries in seen.values():
        entries.clear()
    page.goto(url, wait_until="load")
    page.evaluate("() => XF.renderAll()")  # a promise: awaited by Playwright
    page.wait_for_timeout(100)


def _open(browser, url: str):
    """A page opened at ``url`` with every figure drawn; what it logged and requested."""
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    seen = _listen(page)
    _visit(page, seen, url)
    return page, seen


def _pages(site: Path) -> list[Path]:
    return [site / "report.html"] + sorted((site / "report").glob("*.html"))


def test_overview_answers_on_the_first_screen_within_two_seconds(browser, site, tmp_path):
    from PIL import Image, ImageStat

    html = site / "report.html"
    assert html.stat().st_size <= OVERVIEW_BYTES
    # Interactive: the document is parsed and its scripts have run (DOMContentLoaded) -- the
    # verdict, tables and the SVG ratio plot are in the HTML; plotly.js arrives asynchronously.
    # Best of three loads: the machine's other work should not decide the measurement.
    times = []
    for _ in range(3):
        page = browser.new_page(viewport={"width": 1400, "height": 900})
        page.goto(html.as_uri(), wait_until="domcontentloaded")
        times.append(page.evaluate("() => performance.getEntriesByType('navigation')[0]"
                                   ".domContentLoadedEventEnd"))
        page.close()
    assert min(times) <= INTERACTIVE_MS, times
    page, seen = _open(browser, html.as_uri())
    boxes = {sel: page.eval_on_selector(sel, "e => { const r = e.getBoundingClientRect(); "
                                             "return [r.top, r.bottom, r.width]; }")
             for sel in ("#verdict", "#ratio-plot")}
    for sel, (top, bottom, width) in boxes.items():
        assert 0 <= top < bottom <= 900 and width > 600, (sel, top, bottom)
    verdict = page.text_content("#verdict")
    assert "Fuzzy-RRT goal-frame" in verdict and "Fuzzy-RRT paper" in verdict
    assert "OMPL RRTConnect finds its first path" in verdict
    assert f"on {N_SCENARIOS} problems" in verdict
    points = page.eval_on_selector_all("#ratio-plot a.xf-point", "els => els.length")
    assert points == 3 * N_SCENARIOS
    png = page.screenshot()  # the viewport: 1400 × 900, no scrolling
    (tmp_path / "overview.png").write_bytes(png)
    image = Image.open(io.BytesIO(png)).convert("L")
    assert image.size == (1400, 900)
    top, bottom = int(boxes["#ratio-plot"][0]), int(boxes["#ratio-plot"][1])
    plot = image.crop((0, top, 1400, bottom))
    assert ImageStat.Stat(plot).stddev[0] > 10.0  # points and grid drawn, not blank
    assert seen["errors"] == []
    page.close()


def test_a_ratio_point_opens_its_scenario(browser, site):
    page, _ = _open(browser, (site / "report.html").as_uri())
    href = page.eval_on_selector("#ratio-plot a.xf-point", "a => a.getAttribute('href')")
    page.click("#ratio-plot a.xf-point circle")
    page.wait_for_load_state("load")
    assert page.url == (site / href).resolve().as_uri()
    assert page.text_content("h1").startswith("Scenario: ")
    page.close()


def test_every_figure_on_every_page_is_drawn_without_errors_or_network(browser, site):
    pages = _pages(site)
    assert len(pages) == 1 + N_SCENARIOS + 2  # overview, scenarios, two rulebooks
    binned = 0
    # One tab navigated from page to page, as a reader clicks through: a new tab per page
    # started a renderer process each time (~1.4 s of this test's ~7 s a page in a VM).
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    seen = _listen(page)
    for path in pages:
        _visit(page, seen, path.as_uri())
        html = path.read_text(encoding="utf-8")
        ids = re.findall(r'<div id="(fig-[^"]+)" class="plotly-graph-div"', html)
        marks = dict(page.evaluate(MARKS_JS))
        assert sorted(marks) == sorted(ids), path.name
        blank = [i for i, n in marks.items() if n == 0]
        assert blank == [], f"{path.name}: figures without marks: {blank}"
        assert seen["errors"] == [], f"{path.name}: {seen['errors'][:3]}"
        assert seen["requests"] and all(u.startswith("file://") for u in seen["requests"]), \
            [u for u in seen["requests"] if not u.startswith("file://")]
        assert seen["dialogs"] == []
        for fig_id in (i for i in ids if i.endswith("-firing")):
            xs = page.evaluate(f"() => document.getElementById('{fig_id}').data[0].x")
            binned += any("-" in str(x) for x in xs)  # columns are bins of iterations
    page.close()
    assert binned >= 1  # the fixture has traces long enough to bin (the blank-figure case)


def test_every_link_resolves(browser, site):
    for path in _pages(site):
        html = path.read_text(encoding="utf-8")
        for href in re.findall(r'href="([^"]+)"', html):
            url = urlparse(href)
            assert url.scheme in ("", "file"), f"{path.name}: external link {href}"
            target = (path.parent / unquote(url.path)).resolve() if url.path else path
            assert target.is_file(), f"{path.name}: broken link {href}"
            if url.fragment:
                text = target.read_text(encoding="utf-8", errors="replace")
                assert f'id="{url.fragment}"' in text, f"{path.name}: no anchor {href}"


def test_drilldown_slider_shows_the_chosen_iteration(browser, site):
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
    from xfuzzy_rrt.fuzzy.text_format import rule_sentence
    from xfuzzy_rrt.report.numbers import readable_numbers

    bench = json.loads((site / "bench.json").read_text())
    rb_dir = next(e["dir"] for e in bench["rulebooks"] if e["planner"] == "fuzzy-rrt:goal-frame")
    rb = load_rulebook(rb_dir)
    path = next(p for p in sorted((site / "report").glob("scenario-*.html"))
                if 'id="drill-s1-data"' in p.read_text(encoding="utf-8"))
    html = path.read_text(encoding="utf-8")
    data = json.loads(re.search(r'<script type="application/json" id="drill-s1-data">(.*?)'
                                r"</script>", html, re.S).group(1))
    assert data["rulebook"] == "goal-frame"
    page, seen = _open(browser, path.as_uri())
    last = len(data["iterations"]) - 1
    record = data["iterations"][last]
    root = "#follow-fuzzy-rrt-goal-frame ~ .xf-drill"
    page.eval_on_selector(f"{root} input[type=range]",
                          f"s => {{ s.value = {last}; s.dispatchEvent(new Event('input')); }}")
    page.wait_for_timeout(300)
    assert page.text_content(f"{root} .xf-drill-label").startswith(
        f"iteration {record['iteration']} ")
    cells = page.evaluate(
        f"() => Array.from(document.querySelector('{root}').querySelectorAll("
        "'.xf-drill-systems .cell')).map(c => Array.from(c.querySelectorAll("
        "'table:last-of-type tbody tr')).map(r => Array.from(r.cells).map(x => x.textContent)))")
    assert len(cells) == 6
    for f, rows in enumerate(cells):
        _, _, rules, _, _ = record["systems"][f]
        assert [r[0] for r in rows] == [f"r{idx}" for idx, _, _ in rules]
        for row, (idx, strength, contribution) in zip(rows, rules):
            assert row[1] == readable_numbers(rule_sentence(rb.systems[f], idx))
            assert row[2] == strength and row[4] == contribution
    box = page.evaluate("() => document.getElementById('fig-s1-drill').layout.shapes[0]")
    assert [box["x0"], box["x1"], box["y0"], box["y1"]] == pytest.approx(record["box"])
    assert seen["errors"] == []
    page.close()
