"""The audit report in a real browser: every plot drawn, no error, no network, not blank.

A report that passes string checks can still fail where it matters -- in the reader's browser
(a JavaScript error, a figure plotly cannot draw, a resource fetched from the network). So a
generated report is opened from ``file://`` in headless Chromium (Debian's ``chromium``, driven
by Playwright) and checked the way a reader would see it, the drill-down slider included.

In CI (``CI`` set) a missing browser or Playwright is a failure, not a skip: ``.ci/run``
installs Chromium when it is absent.
"""

from __future__ import annotations

import io
import json
import os
import re
from pathlib import Path

import pytest

from conftest import FIXTURES, PROJECT

CHROMIUM = Path(os.environ.get("XFUZZY_CHROMIUM", "/usr/bin/chromium"))
ARGS = ["--no-sandbox", "--disable-gpu", "--disable-background-networking",
        "--disable-component-update", "--disable-sync", "--no-first-run"]
EVIL = "<script>alert(1)</script>"


def _unavailable(reason: str):
    if os.environ.get("CI"):
        pytest.fail(f"browser test cannot run in CI: {reason}")
    pytest.skip(reason)


@pytest.fixture(scope="module")
def report(tmp_path_factory) -> Path:
    """RRT and Fuzzy-RRT on two scenarios, one of them named like a script."""
    from xfuzzy_rrt.bench.runner import run_benchmark
    from xfuzzy_rrt.cli.bench import write_outputs
    from xfuzzy_rrt.geometry.scenario import load_scenario

    out = tmp_path_factory.mktemp("browser")
    evil = out / "evil.toml"
    text = (FIXTURES / "scenarios" / "two-circles.toml").read_text()
    evil.write_text(re.sub(r"^name = .*$", f'name = "{EVIL}"', text, count=1, flags=re.M))
    scenarios = [load_scenario(evil), load_scenario(FIXTURES / "scenarios" / "boxes-and-circle.toml")]
    result = run_benchmark(scenarios, ["rrt", "fuzzy-rrt"], runs=3,
                           rulebook=PROJECT / "rulebooks" / "expert")
    write_outputs(result, out / "bench", "xfuzzy-rrt bench evil.toml boxes-and-circle.toml")
    return out / "bench" / "report.html"


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


@pytest.fixture(scope="module")
def opened(browser, report):
    """The report opened and fully drawn; what the page logged and requested meanwhile."""
    page = browser.new_page(viewport={"width": 1400, "height": 900})
    seen = {"errors": [], "requests": [], "dialogs": []}
    page.on("console", lambda m: seen["errors"].append(m.text) if m.type == "error" else None)
    page.on("pageerror", lambda e: seen["errors"].append(str(e)))
    page.on("request", lambda r: seen["requests"].append(r.url))
    page.on("dialog", lambda d: (seen["dialogs"].append(d.message), d.dismiss()))
    page.goto(report.as_uri(), wait_until="load")
    page.evaluate("() => XF.renderAll()")  # a promise: awaited by Playwright
    page.wait_for_timeout(300)
    yield page, seen
    page.close()


def test_every_plot_is_drawn_without_errors_or_network(opened, report):
    page, seen = opened
    html = report.read_text(encoding="utf-8")
    ids = re.findall(r'<div id="(fig-[^"]+)" class="plotly-graph-div"', html)
    assert len(ids) >= 10
    drawn = page.evaluate("""() => Array.from(document.querySelectorAll('.plotly-graph-div'))
        .filter(d => d.querySelector('svg.main-svg, canvas')).map(d => d.id)""")
    assert sorted(drawn) == sorted(ids)
    assert seen["errors"] == []
    assert seen["requests"] and all(u.startswith("file://") for u in seen["requests"]), \
        [u for u in seen["requests"] if not u.startswith("file://")]
    assert seen["dialogs"] == []  # the scenario named <script>alert(1)</script> stayed text
    headings = page.eval_on_selector_all("h2", "els => els.map(e => e.textContent)")
    assert f"Scenario: {EVIL}" in headings


def test_drilldown_slider_shows_the_chosen_iteration(opened, report):
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
    from xfuzzy_rrt.fuzzy.text_format import rule_sentence

    page, seen = opened
    html = report.read_text(encoding="utf-8")
    data = json.loads(re.search(r'<script type="application/json" id="drill-s0-data">(.*?)'
                                r"</script>", html, re.S).group(1))
    last = len(data["iterations"]) - 1
    record = data["iterations"][last]
    page.eval_on_selector(".xf-drill input[type=range]",
                          f"s => {{ s.value = {last}; s.dispatchEvent(new Event('input')); }}")
    page.wait_for_timeout(300)
    label = page.text_content(".xf-drill .xf-drill-label")
    assert label.startswith(f"iteration {record['iteration']} ")
    # The fired-rule sentences the page writes are the rulebook's own sentences.
    rb = load_rulebook(PROJECT / "rulebooks" / "expert")
    cells = page.evaluate(
        "() => Array.from(document.querySelector('.xf-drill').querySelectorAll("
        "'.xf-drill-systems .cell')).map(c => Array.from(c.querySelectorAll("
        "'table:last-of-type tbody tr')).map(r => Array.from(r.cells).map(x => x.textContent)))")
    assert len(cells) == 6
    for f, rows in enumerate(cells):
        output, _, rules, _, _ = record["systems"][f]
        assert [r[0] for r in rows] == [f"r{idx}" for idx, _, _ in rules]
        for row, (idx, strength, contribution) in zip(rows, rules):
            assert row[1] == rule_sentence(rb.systems[f], idx)
            assert row[2] == strength and row[4] == contribution
    box = page.evaluate("() => document.getElementById('fig-s0-drill').layout.shapes[0]")
    assert [box["x0"], box["x1"], box["y0"], box["y1"]] == pytest.approx(record["box"])
    assert seen["errors"] == []


def test_screenshot_is_not_blank(opened, tmp_path):
    from PIL import Image, ImageStat

    page, _ = opened
    page.eval_on_selector("#fig-s0-rrt-joint", "e => e.scrollIntoView()")
    page.wait_for_timeout(200)
    png = page.screenshot()
    (tmp_path / "shot.png").write_bytes(png)
    image = Image.open(io.BytesIO(png)).convert("L")
    assert ImageStat.Stat(image).stddev[0] > 10.0
    assert sum(1 for count in image.histogram() if count) > 20  # grey levels used
