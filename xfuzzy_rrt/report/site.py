"""The benchmark report as a small site: an overview that answers on the first screen, and the
evidence one click away.

Why a site and not one page: the first edition put everything on one page -- 8 MB and 321,064
px tall for 24 scenarios, ~21 s before it responded -- and the verdict sat below a 48-row
table. Now ``DIR/report.html`` (the entry point, as before) is the overview:

- first screen (1400 × 900, no scrolling): the verdict sentences (one per planner, generated
  from :mod:`.overview`), the per-planner table (certified success, median and worst ratio to
  RRT, median time to first path, cost, minimum clearance) and the sorted per-scenario ratio
  plot of each planner (log axis, ticks 0.5 1 2 5 ...; a click on a point opens its scenario);
- below: the certification panel (the *worst* path of each planner over the obstacles, with
  the configuration closest to them), the rulebooks, the scenario index and the provenance.

``DIR/report/`` holds the evidence pages -- one per scenario (paths and trees of every planner,
box plots over runs, outcomes, *Follow one plan* with the drill-down) and one per rulebook
(membership functions with units, rule surfaces with colour bars, rule coverage over the
benchmark's example runs, the training curve) -- and ``plotly.min.js``, loaded by every page
(one copy, offline, ``file://``). The folder is replaced as a set: written beside, then
swapped, so no page of an older report survives next to a newer one.

Only the ``BenchResult`` is read; nothing is re-planned.
"""

from __future__ import annotations

import datetime as _dt
import os
import shlex
import shutil
import tempfile
from pathlib import Path
from typing import Any

import numpy as np
import pandas as pd

from xfuzzy_rrt.report import figures as F
from xfuzzy_rrt.report import numbers as N
from xfuzzy_rrt.report.html import Page, esc, kv_table, slug, table
from xfuzzy_rrt.report.overview import (BASELINE, found_mask, is_ours, planner_table,
                                        scenario_medians, scenario_ratios, success_mask,
                                        verdicts)

ENTRY = "report.html"
ASSETS = "report"
PLOTLY_JS = "plotly.min.js"
PDF = "report.pdf"
SEP = " \u00b7 "


# ----------------------------------------------------------------------------------------------
# What the pages are built from
# ----------------------------------------------------------------------------------------------

def rulebooks_of(result) -> dict[str, Any]:
    """Planner name -> the rulebook it ran with, for every Fuzzy-RRT planner of the benchmark.

    Works with one rulebook (``result.rulebook``, the first edition's ``fuzzy-rrt``) and with
    several (``result.rulebooks``: ``fuzzy-rrt:NAME`` side by side); a planner is matched to a
    rulebook by the SHA-256 its runs recorded.
    """
    books: dict[str, Any] = {}
    many = getattr(result, "rulebooks", None)
    if isinstance(many, dict):
        books.update({str(k): v for k, v in many.items() if v is not None})
    single = getattr(result, "rulebook", None)
    known = {getattr(rb, "sha256", None): rb for rb in list(books.values()) + [single]
             if rb is not None}
    runs = result.runs
    for p in dict.fromkeys(runs["planner"]):
        if p in books or not is_ours(p) or p == BASELINE:
            continue
        shas = runs.loc[runs["planner"] == p, "rulebook_sha256"].dropna() \
            if "rulebook_sha256" in runs.columns else pd.Series(dtype=object)
        sha = str(shas.iloc[0]) if len(shas) else None
        if sha in known:
            books[p] = known[sha]
        elif single is not None and p == "fuzzy-rrt" and sha is None:
            books[p] = single
    return books


def rulebook_dir(planner: str, result) -> str | None:
    """Where the rulebook of ``planner`` was read from (for reproduce commands)."""
    settings = dict(result.settings or {})
    for entry in settings.get("rulebooks") or []:
        if isinstance(entry, dict) and entry.get("planner") == planner and entry.get("dir"):
            return str(entry["dir"])
    if planner == "fuzzy-rrt":
        return settings.get("rulebook_dir")
    from xfuzzy_rrt.planners.registry import lookup

    form = lookup(planner)  # fuzzy-rrt:NAME, fuzzy-rrt-connect:DIR, ...: the part after ':'
    if form is not None and form.is_prefix and form.takes_rulebook:
        return planner[len(form.label):]
    return None


class Names:
    """File names of the pages, relative to the folder they are linked from."""

    def __init__(self, scenarios: list[str], rulebook_planners: list[str]) -> None:
        self.scen = {n: f"scenario-{i:02d}-{slug(n)[:48]}.html" for i, n in enumerate(scenarios)}
        self.rb = {p: f"rulebook-{slug(p)}.html" for p in rulebook_planners}

    @staticmethod
    def from_entry(name: str) -> str:
        return f"{ASSETS}/{name}"


# ----------------------------------------------------------------------------------------------
# Writing
# ----------------------------------------------------------------------------------------------

def write_report(result, folder: Path, command: str | None = None,
                 generated_at: str | None = None) -> Path:
    """Write ``folder/report.html`` and ``folder/report/`` (pages and plotly.js); return the
    entry page.

    The evidence folder is written complete under a hidden name (``.report-XXXX.tmp``) and
    swapped in; the entry page goes through :func:`~xfuzzy_rrt.atomic.atomic_path`. So an
    interrupted run leaves the previous report or the new one, never a mix; hidden staging
    folders left by a killed run are removed by the next one.
    """
    from plotly.offline import get_plotlyjs

    from xfuzzy_rrt.atomic import atomic_path

    folder = Path(folder)
    folder.mkdir(parents=True, exist_ok=True)
    pages = build_pages(result, command=command, generated_at=generated_at, folder=folder)
    for stale in folder.glob(".report-*.tmp"):
        shutil.rmtree(stale, ignore_errors=True)
    stage = Path(tempfile.mkdtemp(prefix=".report-", suffix=".tmp", dir=folder))
    try:
        (stage / ASSETS).mkdir()
        (stage / ASSETS / PLOTLY_JS).write_text(get_plotlyjs(), encoding="utf-8")
        for rel, text in pages.items():
            if rel != ENTRY:
                (stage / rel).write_text(text, encoding="utf-8", newline="\n")
        with atomic_path(folder / ENTRY) as tmp:
            tmp.write_text(pages[ENTRY], encoding="utf-8", newline="\n")
            old = folder / ASSETS
            if old.exists():
                os.replace(old, stage / "old")
            os.replace(stage / ASSETS, old)
    finally:
        shutil.rmtree(stage, ignore_errors=True)
    return folder / ENTRY


def build_pages(result, command: str | None = None, generated_at: str | None = None,
                folder: Path | None = None) -> dict[str, str]:
    """Relative path -> HTML of every page (the entry page first). Deterministic for equal
    inputs and equal ``generated_at``."""
    if generated_at is None:
        generated_at = _dt.datetime.now(_dt.timezone.utc).strftime("%Y-%m-%d %H:%M:%S UTC")
    prov = dict(getattr(result, "provenance", None) or {})
    command = command or prov.get("command") or "xfuzzy-rrt bench"
    settings = dict(result.settings or {})
    runs = result.runs
    planners = F.planner_order(list(settings.get("planners") or []) + list(runs["planner"]))
    planners = [p for p in planners if p in set(runs["planner"])] or planners
    scen_names = list(dict.fromkeys(list(result.summary["scenario"]) + list(result.scenarios)))
    books = rulebooks_of(result)
    names = Names(scen_names, list(books))
    ctx = dict(result=result, command=command, generated_at=generated_at, prov=prov,
               settings=settings, planners=planners, scen_names=scen_names, books=books,
               names=names, folder=folder)
    from xfuzzy_rrt.report.plotjson import no_default_template

    with no_default_template():
        pages = {ENTRY: _overview(ctx)}
        for i, n in enumerate(scen_names):
            pages[f"{ASSETS}/{names.scen[n]}"] = _scenario_page(ctx, i, n)
        for p, rb in books.items():
            pages[f"{ASSETS}/{names.rb[p]}"] = _rulebook_page(ctx, p, rb)
    return pages


def _title(planners: list[str]) -> str:
    return "Benchmark: " + (" vs ".join(F.planner_label(p) for p in planners) or "planners")


def _nav(ctx, here: str, in_assets: bool) -> str:
    up = "../" if in_assets else ""
    sub = "" if in_assets else f"{ASSETS}/"
    links = [f'<a href="{up}{ENTRY}">overview</a>',
             f'<a href="{up}{ENTRY}#certification">certification</a>',
             f'<a href="{up}{ENTRY}#scenarios">scenarios</a>']
    links += [f'<a href="{sub}{esc(f)}">rulebook {esc(F.planner_label(p))}</a>'
              for p, f in ctx["names"].rb.items()]
    if here:
        links.append(f'<span class="muted">{esc(here)}</span>')
    return '<nav class="xf-nav">' + SEP.join(links) + "</nav>"


def _footer(ctx, page: Page) -> None:
    from xfuzzy_rrt import __version__

    page.add(f'<p class="muted">Generated by xfuzzy-rrt {esc(__version__)} on '
             f'{esc(ctx["generated_at"])} from the bench folder (nothing re-planned). '
             "plotly.js is loaded from the report folder; no network is used.</p>")


def _reproduce(cmd: str) -> str:
    return f'<p class="muted">Reproduce: <code>{esc(cmd)}</code></p>'


# ----------------------------------------------------------------------------------------------
# Overview (report.html)
# ----------------------------------------------------------------------------------------------

def _overview(ctx) -> str:
    result, settings = ctx["result"], ctx["settings"]
    runs = result.runs
    table_ = planner_table(runs)
    page = Page(_title(ctx["planners"]), eager=True)
    page.add(_nav(ctx, "", in_assets=False))
    page.add(f'<h1 class="xf-title">{esc(_title(ctx["planners"]))}</h1>')
    n_scen = len(ctx["scen_names"])
    seed, nruns = settings.get("seed"), settings.get("runs")
    bits = [f"{n_scen} scenario{'s' if n_scen != 1 else ''}",
            f"{nruns} runs per scenario and planner" if nruns else None,
            (f"seeds {seed}\u2013{seed + nruns - 1}" if isinstance(seed, int)
             and isinstance(nruns, int) else None),
            f"budget {settings.get('max_iter')} iterations" if settings.get("max_iter") else None,
            f"benchmark run {ctx['prov'].get('date')}" if ctx["prov"].get("date") else None]
    page.add(f'<p class="muted xf-sub">{esc(SEP.join(b for b in bits if b))}{SEP}'
             '<a href="#provenance">command and provenance</a></p>')
    page.add('<ul class="xf-verdict" id="verdict">'
             + "".join(f"<li>{esc(s)}</li>" for s in verdicts(table_, settings.get("tuned")))
             + "</ul>")
    # The verdict and the ratio plot are the answer, so they come first: the table below can
    # grow with the planners and its columns without pushing the plot off the first screen.
    page.add(_ratio_plot(ctx, runs))
    page.add(_planner_table(table_))
    page.heading("Certification: the worst path of each planner", anchor="certification")
    _certification(ctx, page, table_)
    from xfuzzy_rrt.report.robustness_section import robustness_html

    robust = robustness_html(ctx.get("folder"), F.planner_label)
    if robust:
        page.heading("Robustness: when the anatomy moves", anchor="robustness")
        page.add(robust)
    page.heading("Rulebooks", anchor="rulebooks")
    _rulebook_list(ctx, page)
    page.heading("Scenarios", anchor="scenarios")
    page.add(_scenario_index(ctx, runs))
    page.heading("Command and provenance", anchor="provenance")
    _provenance(ctx, page)
    _footer(ctx, page)
    return page.render(plotly_src=f"{ASSETS}/{PLOTLY_JS}")


def _planner_table(t: pd.DataFrame) -> str:
    timed = "time_ratio_median" in t.columns and t["time_ratio_median"].notna().any()
    tb = F.planner_label(str(t["time_baseline"].iloc[0])) if timed else ""
    header = ["planner", "certified success", "found a path", "compared on",
              "median ratio to RRT", "worst ratio", "loses on", "median time to first path",
              "median cost", "min clearance", "penetrating paths"]
    if timed:
        header[1:1] = [f"end-to-end time vs {tb} (median / worst)",
                       f"end-to-end work vs {tb} (median / worst)", "median end-to-end time",
                       "median end-to-end work"]
    rows = []
    for r in t.itertuples(index=False):
        base = r.planner == BASELINE
        lead = []
        if timed:
            tbase = r.planner == r.time_baseline
            lead = ["1\u00d7 (baseline)" if tbase else
                    f"{N.ratio(r.time_ratio_median)} / {N.ratio(r.time_ratio_worst)}",
                    "1\u00d7 (baseline)" if tbase else
                    f"{N.ratio(r.work_ratio_median)} / {N.ratio(r.work_ratio_worst)}",
                    N.seconds(r.time_total_median_s), N.sig(r.work_median, 3)]
        rows.append([
            r.label, *lead, N.percent(r.success_rate), N.percent(r.found_rate),
            "\u2014" if base else ("iterations" if r.metric == "iterations"
                                   else "time to first path"),
            "1\u00d7 (baseline)" if base else N.ratio(r.ratio_median),
            "\u2014" if base else N.ratio(r.ratio_worst),
            "\u2014" if base else f"{r.losses} of {r.compared}",
            N.seconds(r.time_first_median_s), N.qty(r.cost_median_deg, "deg"),
            _clearance(r.min_clearance_m),
            f"{r.penetrating_paths} of {r.paths}" + (
                f" (deepest {N.metres(r.penetration_max_m)})" if r.penetrating_paths else ""),
        ])
    return ('<div class="scroll">' + table(rows, header, [str] * len(header),
                                           css_class="data xf-planners") + "</div>")


def _ratio_plot(ctx, runs: pd.DataFrame) -> str:
    """The sorted per-scenario ratio panels (inline SVG, see :mod:`.ratio_svg`)."""
    from xfuzzy_rrt.report.ratio_svg import ratio_svg

    ratios = scenario_ratios(runs)
    others = [p for p in ctx["planners"] if p != BASELINE and p in set(ratios["planner"])]
    if not others:
        return ""
    names = ctx["names"]
    panels = []
    for p in others:
        g = ratios[ratios["planner"] == p]
        m = g["metric"].iloc[0]
        panels.append({
            "title": f"{F.planner_label(p)}: "
                     + ("iterations" if m == "iterations" else "time to first path"),
            "color": F.planner_color(p),
            "points": [(s, float(r), Names.from_entry(names.scen[s]))
                       for s, r in zip(g["scenario"], g["ratio"]) if s in names.scen]})
    return ('<div class="xf-ratio-wrap"><p class="muted" style="margin: 4px 0;">Per-scenario '
            "ratio to RRT, sorted (red: the planner loses on that scenario); a point opens its "
            "scenario.</p>" + ratio_svg(panels) + "</div>")


def worst_per_planner(result) -> dict[str, Any]:
    """Per planner, the stored run that came closest to an obstacle (or went deepest into one)
    over all scenarios: the smallest ``min_clearance_m`` among the bench's worst examples (one
    per scenario and planner); the first scenario on ties."""
    out: dict[str, Any] = {}
    key: dict[str, float] = {}
    order = {n: i for i, n in enumerate(result.scenarios)}
    items = sorted((getattr(result, "worst_examples", None) or {}).items(),
                   key=lambda kv: (order.get(kv[0][0], 1 << 30), kv[0][1]))
    for (_, planner), run in items:
        c = run.min_clearance_m
        c = float(c) if c is not None and np.isfinite(c) else float("inf")
        if planner not in out or c < key[planner]:
            out[planner], key[planner] = run, c
    return out


def worst_pose(scenario, path_deg: np.ndarray) -> tuple[np.ndarray, float]:
    """The configuration along ``path_deg`` (sampled every 0.25°) with the smallest signed
    clearance, and that clearance in metres (negative: penetration)."""
    from xfuzzy_rrt.geometry.path_check import signed_clearance

    dense = F.interpolate_path(np.asarray(path_deg, dtype=np.float64), 0.25)
    arrays = scenario.arrays()
    c = np.array([signed_clearance(arrays, q) for q in dense])
    k = int(np.argmin(c))
    return dense[k], float(c[k])


def worst_path_figure(scenario, run):
    """The workspace figure of ``run`` with the arm drawn (red) where it comes closest."""
    q, c = worst_pose(scenario, run.path_deg)
    closest = ("penetration " + N.metres(-c)) if c < 0 else N.metres(c)
    fig = F.workspace_figure(scenario, run, n_poses=3, title=(
        f"<b>{F.plot_text(F.planner_label(run.planner))}</b><br><sup>"
        f"{F.plot_text(scenario.name)}, seed {int(run.seed)}<br>closest approach {closest}"
        "</sup>"))
    fig.add_traces(F._arm_traces(scenario, q, "closest configuration", "#d7191c", 5, True,
                                 "closest"))
    fig.update_layout(height=400, showlegend=False, margin=dict(l=50, r=10, t=80, b=40))
    return fig


def _certification(ctx, page: Page, t: pd.DataFrame) -> None:
    result = ctx["result"]
    page.paragraph(
        "Every returned path is re-checked with this project's certified edge check (every "
        "configuration along every segment). A found path that fails it does not count as a "
        "success. Drawn: for each planner, the found run whose path came closest to an "
        "obstacle (or went deepest into one) over all scenarios and seeds -- grey: obstacles; "
        "green and pink: the arm at start and goal; pale: the arm along the path; line: the "
        "end-effector trace; red: the arm at its closest configuration. OMPL checks motions by "
        "sampling, so its paths may graze obstacles between samples.")
    worst = worst_per_planner(result)
    cells = []
    for p in ctx["planners"]:
        r = worst.get(p)
        s = result.scenarios.get(r.scenario) if r is not None else None
        if r is None or s is None or np.size(r.path_deg) < 2 * s.dof:
            cells.append(f'<div class="cell"><p class="muted">{esc(F.planner_label(p))}: no '
                         "stored worst path (no path found, or a bench folder written before "
                         "worst paths were stored)</p></div>")
            continue
        fig = worst_path_figure(s, r)
        link = Names.from_entry(ctx["names"].scen[r.scenario]) \
            if r.scenario in ctx["names"].scen else None
        more = (f'<p class="muted"><a href="{esc(link)}">scenario {esc(r.scenario)}</a> '
                f'\u00b7 reproduce: <code>{esc(_plan_cmd(ctx, s, p, r.seed, r))}</code></p>'
                if link else "")
        cells.append(f'<div class="cell">{page.figure(fig, f"fig-worst-{slug(p)}")}{more}</div>')
    page.add('<div class="grid" style="grid-template-columns: repeat(auto-fill, '
             'minmax(300px, 1fr));">' + "".join(cells) + "</div>")


def _rulebook_list(ctx, page: Page) -> None:
    books, names = ctx["books"], ctx["names"]
    if not books:
        page.paragraph("No Fuzzy-RRT planner in this benchmark.")
        return
    rows = []
    for p, rb in books.items():
        link = f'<a href="{esc(Names.from_entry(names.rb[p]))}">{esc(rb.name)}</a>'
        rows.append([esc(F.planner_label(p)), link, esc(rb.bounds_mode),
                     esc(_semantics_name(rb)), f"<code>{esc(rb.sha256[:16])}\u2026</code>",
                     esc(rulebook_dir(p, ctx["result"]) or "\u2014")])
    page.add(table(rows, ["planner", "rulebook (membership functions, surfaces, coverage, "
                          "training)", "bounds", "inputs", "sha256", "directory"],
                   raw_html=True))


def _semantics_name(rb) -> str:
    sem = getattr(rb, "semantics", None)
    return str(getattr(sem, "name", None) or "paper")


def _scenario_index(ctx, runs: pd.DataFrame) -> str:
    ratios = scenario_ratios(runs)
    others = [p for p in ctx["planners"] if p != BASELINE]
    result, names = ctx["result"], ctx["names"]
    succ = runs.assign(_ok=success_mask(runs))
    header = ["scenario", "obstacles", "RRT median iterations"]
    header += [f"{F.planner_label(p)} ratio" for p in others]
    header += ["certified success (all planners)"]
    rows = []
    base = ratios.set_index(["scenario", "planner"])
    med = scenario_medians(runs).set_index(["scenario", "planner"])
    for n in ctx["scen_names"]:
        s = result.scenarios.get(n)
        row = [f'<a href="{esc(Names.from_entry(names.scen[n]))}">{esc(n)}</a>',
               esc(len(s.obstacles) if s is not None else "\u2014"),
               esc(N.sig(med.loc[(n, BASELINE), "iterations"]) if (n, BASELINE) in med.index
                   else "\u2014")]
        for p in others:
            v = base.loc[(n, p), "ratio"] if (n, p) in base.index else float("nan")
            cls = "xf-lose" if np.isfinite(v) and v < 1 else ""
            row.append(f'<span class="{cls}">{esc(N.ratio(v))}</span>')
        g = succ[succ["scenario"] == n]
        row.append(esc(f"{int(g['_ok'].sum())}/{len(g)}"))
        rows.append(row)
    return ('<p class="note">Ratio: RRT\'s median over the planner\'s on that scenario '
            "(iterations for RRT and Fuzzy-RRT, time to first path for OMPL); red: below 1, "
            "the planner loses. Each name opens the scenario's evidence page.</p>"
            '<div class="scroll">' + table(rows, header, raw_html=True) + "</div>")


METRICS_NOTE = (
    "iterations: loop iterations until the goal joined the tree, every sample counting whether "
    "accepted or rejected (the paper's x); a run without a path counts as the budget. OMPL "
    "planners count other things, so they are compared on time to first path (median over the "
    "runs that found one). cost: joint-space path length in degrees, over certified successful "
    "runs. clearance: the exact smallest distance between a link and an obstacle along a path. "
    "Certified success: a path was found and every segment passed the certified check.")


def _provenance(ctx, page: Page) -> None:
    from xfuzzy_rrt.report.evidence import _versions

    prov, settings = ctx["prov"], ctx["settings"]
    page.add(f"<pre>{esc(ctx['command'])}</pre>")
    git = prov.get("git") or {}
    commit = git.get("commit")
    if commit and git.get("dirty"):
        commit += " (with uncommitted changes)"
    machine = prov.get("machine") or {}
    pairs = [("benchmark run", prov.get("date")), ("report generated", ctx["generated_at"]),
             ("git commit", commit)]
    versions = prov.get("versions") or dict(_versions())
    pairs += [(k, v) for k, v in versions.items() if v is not None]
    if machine:
        pairs.append(("machine", f"{machine.get('hostname')} \u00b7 {machine.get('system')} "
                                 f"\u00b7 {machine.get('machine')} \u00b7 "
                                 f"{machine.get('cpus')} CPUs"))
    pairs += [("planners", ", ".join(F.planner_label(p) for p in ctx["planners"])),
              ("runs per scenario and planner", settings.get("runs")),
              ("first seed", settings.get("seed")),
              ("max_iter (iteration budget)", settings.get("max_iter")),
              ("certified shortcutting", "yes" if settings.get("shortcut") else "no"),
              ("worker processes", settings.get("workers"))]
    page.add('<div class="grid" style="grid-template-columns: minmax(0, 1fr) minmax(0, 1fr);">')
    page.add(f"<div>{kv_table(pairs)}</div>")
    page.add(f'<div><h3>What the numbers mean</h3><p class="note">{esc(METRICS_NOTE)}</p>'
             "<h3>Files</h3><p>"
             + " \u00b7 ".join(f'<a href="{f}">{f}</a>' for f in
                               ("runs.csv", "summary.csv", "ratios.csv", "bench.json")
                               if _exists_beside(ctx, f))
             + "</p></div></div>")


def _exists_beside(ctx, name: str) -> bool:
    """Link a table only when the report sits in a bench folder that has it."""
    folder = ctx.get("folder")
    return folder is None or (Path(folder) / name).is_file()


# ----------------------------------------------------------------------------------------------
# Scenario pages
# ----------------------------------------------------------------------------------------------

def _plan_cmd(ctx, s, planner: str, seed: int, run=None) -> str:
    src = getattr(s, "source", "") or f"{s.name}.toml"
    from xfuzzy_rrt.report.evidence import cli_planner, takes_rulebook

    plan_planner = cli_planner(planner)
    cmd = (f"xfuzzy-rrt plan {shlex.quote(src)} --planner {shlex.quote(plan_planner)} "
           f"--seed {int(seed)}")
    if ctx["settings"].get("max_iter") is not None:
        cmd += f" --max-iter {int(ctx['settings']['max_iter'])}"
    d = (rulebook_dir(planner, ctx["result"])
         if takes_rulebook(plan_planner) else None)
    if d and not _ran_any_arm_default(planner, run):
        cmd += f" --rulebook {shlex.quote(str(d))}"
    return cmd


def _ran_any_arm_default(planner: str, run) -> bool:
    """A run of plain ``fuzzy-rrt`` that its shipped default planned with Fuzzy-RRT-Connect
    (a problem that is not one 2-joint arm): ``plan --planner fuzzy-rrt`` without
    ``--rulebook`` reproduces it, and the 2-joint rulebook would be refused there."""
    return planner == "fuzzy-rrt" and getattr(run, "planner_used", None) == "fuzzy-rrt-connect"


def _book_of_run(ctx, planner: str, run):
    """The rulebook that made ``run``: its planner's, else the benchmark's rulebook with the
    run's SHA-256 (plain ``fuzzy-rrt`` runs ``goal-frame-any`` on problems that are not one
    2-joint arm; the benchmark lists it under ``fuzzy-rrt (any arm)``)."""
    rb = ctx["books"].get(planner)
    sha = getattr(run, "rulebook_sha256", None)
    if rb is None or rb.sha256 == sha:
        return rb
    return next((b for b in ctx["books"].values() if b.sha256 == sha), rb)


def _scenario_page(ctx, idx: int, name: str) -> str:
    from xfuzzy_rrt.report.evidence import _scenario_details

    result, planners = ctx["result"], ctx["planners"]
    page = Page(f"Scenario {name}")
    order = ctx["scen_names"]
    prev_ = (f'<a href="{esc(ctx["names"].scen[order[idx - 1]])}">previous</a>'
             if idx > 0 else "")
    next_ = (f'<a href="{esc(ctx["names"].scen[order[idx + 1]])}">next</a>'
             if idx + 1 < len(order) else "")
    page.add(_nav(ctx, f"scenario {idx + 1} of {len(order)}", in_assets=True)
             + f'<p class="muted">{prev_} {next_}</p>')
    page.heading(f"Scenario: {name}", level=1)
    s = result.scenarios.get(name)
    runs = result.runs[result.runs["scenario"] == name]
    page.add(_scenario_table(runs, planners))
    if s is None:
        page.paragraph("The scenario object is not available; figures are omitted.")
        return page.render(plotly_src=PLOTLY_JS)
    page.add("<details><summary>Scenario definition</summary>" + _scenario_details(s)
             + "</details>")
    grid = F.cspace_grid(s, res_deg=2.0) if F.has_cspace_map(s) else None
    page.heading("Paths and trees (the median-iteration run of each planner)", anchor="paths")
    page.paragraph("Joint space: grey cells are configurations in collision (2\u00b0 grid, the "
                   "planners' own checker); light lines the tree; bold the path. Workspace: "
                   "obstacles grey, the arm at start, goal and along the path, the end-effector "
                   "trace.")
    if grid is None:
        page.paragraph(f"This scenario has {len(s.arms)} arm(s) and {s.dof} joints in all: the "
                       "joint-space view shows the first two joints of the first arm, without a "
                       "C-obstacle map (which needs one 2-DOF arm). The workspace draws every "
                       "arm from its own joint angles" + (" (arm 1 solid, arm 2 dashed, arm 3 "
                       "dotted, arm 4 dash-dotted)." if len(s.arms) > 1 else "."))
    ran = set(runs["planner"])
    ncol = max(1, min(4, len(planners)))
    for kind in ("joint", "workspace"):
        cells = []
        for p in planners:
            r = result.examples.get((name, p))
            if r is None:
                msg = (f"{F.planner_label(p)}: no successful run to show" if p in ran
                       else f"{F.planner_label(p)}: not run on this scenario")
                cells.append(f'<div class="cell"><p class="muted">{esc(msg)}</p></div>')
                continue
            fig = (F.joint_space_figure(s, r, grid=grid) if kind == "joint"
                   else F.workspace_figure(s, r))
            fig.update_layout(height=500, legend=dict(y=-0.2))
            extra = (_reproduce(_plan_cmd(ctx, s, p, r.seed, r)) if kind == "workspace" else "")
            cells.append(f'<div class="cell">{page.figure(fig, f"fig-{slug(p)}-{kind}")}'
                         f"{extra}</div>")
        page.add(f'<div class="grid" style="grid-template-columns: repeat({ncol}, '
                 f'minmax(0, 1fr));">' + "".join(cells) + "</div>")
    page.heading("Iterations and cost over runs", anchor="runs")
    page.add(page.figure(F.boxplots(runs, scenarios=[name],
                                    max_iter=ctx["settings"].get("max_iter")), "fig-boxplots"))
    examples = {p: result.examples.get((name, p)) for p in planners}
    ofig = F.outcome_figure({p: r for p, r in examples.items() if r is not None},
                            title=f"{F.plot_text(name)}: outcome of each iteration (example runs)")
    if ofig is not None:
        page.add(f'<div style="max-width: 760px;">{page.figure(ofig, "fig-outcomes")}</div>')
    n_drill = max(1, len(order))
    any_drill = False
    for k, p in enumerate(planners):
        r = examples.get(p)
        rb = _book_of_run(ctx, p, r)
        if rb is None or r is None or not _followable(r, rb):
            continue
        from xfuzzy_rrt.report.evidence import _follow_one_plan, _influence_table

        page.heading(f"Follow one plan: {F.planner_label(p)}", anchor=f"follow-{slug(p)}")
        page.add(_influence_table(r, rb))
        settings = dict(ctx["settings"], planner=p)
        settings["rulebook_dir"] = (None if _ran_any_arm_default(p, r)
                                    else rulebook_dir(p, result))
        _follow_one_plan(page, f"{k}", s, r, rb, grid, settings, n_drill)
        any_drill = True
    if any_drill:
        from xfuzzy_rrt.report.drilldown import DRILL_JS

        page.script(DRILL_JS)
    _footer(ctx, page)
    return page.render(plotly_src=PLOTLY_JS)


def _followable(run, rulebook) -> bool:
    trace = getattr(run, "trace", None)
    return (isinstance(trace, pd.DataFrame) and len(trace) > 0
            and any(c.endswith("_rule_0") for c in trace.columns)
            and run.rulebook_sha256 == rulebook.sha256)


def _clearance(c) -> str:
    """A minimum clearance; a negative one is a penetration and says so."""
    if c is not None and c < 0:
        return f"penetrates {N.metres(-c)}"
    return N.metres(c)


def _scenario_table(runs: pd.DataFrame, planners: list[str]) -> str:
    ok, found = success_mask(runs), found_mask(runs)
    rows = []
    for p in planners:
        sel = runs["planner"] == p
        g = runs[sel]
        if g.empty:
            continue
        it = pd.to_numeric(g["iterations"])
        tf = pd.to_numeric(g.loc[found[sel], "time_first_s"], errors="coerce").dropna() \
            if "time_first_s" in g.columns else pd.Series(dtype=float)
        cost = pd.to_numeric(g.loc[ok[sel], "cost_deg"], errors="coerce").dropna()
        clear = pd.to_numeric(g.loc[found[sel], "min_clearance_m"], errors="coerce").dropna() \
            if "min_clearance_m" in g.columns else pd.Series(dtype=float)
        rows.append([F.planner_label(p), f"{int(ok[sel].sum())}/{len(g)}",
                     f"{N.sig(it.min())} / {N.sig(it.median())} / {N.sig(it.max())}",
                     N.seconds(tf.median() if len(tf) else None),
                     N.qty(cost.median() if len(cost) else None, "deg"),
                     _clearance(clear.min() if len(clear) else None)])
    return table(rows, ["planner", "certified success", "iterations min / median / max",
                        "median time to first path", "median cost", "min clearance"],
                 [str] * 6)


# ----------------------------------------------------------------------------------------------
# Rulebook pages
# ----------------------------------------------------------------------------------------------

def _rulebook_page(ctx, planner: str, rb) -> str:
    from xfuzzy_rrt.report.fuzzy_figures import (coverage_figure, membership_figure,
                                                 partition_groups, surface_figure,
                                                 training_figure)

    result = ctx["result"]
    page = Page(f"Rulebook {rb.name}")
    page.add(_nav(ctx, f"rulebook {rb.name}", in_assets=True))
    page.heading(f"Rulebook {rb.name} ({F.planner_label(planner)})", level=1)
    d = rulebook_dir(planner, result)
    page.add(kv_table([("sha256", rb.sha256), ("directory", d), ("bounds", rb.bounds_mode),
                       ("inputs", _semantics_name(rb)), ("description", rb.description or None),
                       ("made by", (rb.provenance or {}).get("command"))]))
    page.paragraph("Six zero-order Takagi-Sugeno systems, one per output. Each input has five "
                   "terms forming a partition (memberships sum to 1); a rule's strength is the "
                   "product of its four memberships, normalised over the fired rules, and the "
                   "output is the strength-weighted average of the rule constants.")
    page.heading("Membership functions", anchor="membership")
    for k, (outs, fis) in enumerate(partition_groups(rb)):
        page.add(page.figure(membership_figure(fis, outs, rb), f"fig-mf-{k}"))
    page.heading("Rule surfaces", anchor="surfaces")
    fig, _ = surface_figure(rb)
    page.add(page.figure(fig, "fig-surfaces"))
    page.add(_reproduce(f"xfuzzy-rrt rules show {shlex.quote(str(d or rb.name))}"))
    page.heading("Rule coverage in this benchmark's example runs", anchor="coverage")
    from xfuzzy_rrt.planners.api import ANY_ARM_KEY

    ran = ("fuzzy-rrt",) if planner == ANY_ARM_KEY else (planner,)  # its runs' label
    traces = [r.trace for (_, p), r in result.examples.items()
              if p in ran and _followable(r, rb)]
    cov = coverage_figure(traces, rb)
    if cov is None:
        page.paragraph("No trace of this rulebook is stored in the bench folder.")
    else:
        page.paragraph(f"Over the traced median runs of {len(traces)} scenario(s): how many of "
                       "the rules of each system fired at least once, and how few of them "
                       "carry 90% of the summed firing strength. For coverage "
                       "over many runs: xfuzzy-rrt rules coverage.")
        page.add(page.figure(cov, "fig-coverage"))
    page.heading("Training", anchor="training")
    history = _history_for(ctx, planner, rb)
    if history is None:
        page.paragraph("No training history is known for this rulebook (a hand-written "
                       "rulebook, or pass one with xfuzzy-rrt report DIR --history FILE).")
    else:
        path, frame = history
        page.paragraph(f"Fitness per generation from {path} ({len(frame)} generations).")
        page.add(page.figure(training_figure(frame), "fig-training"))
        if (rb.provenance or {}).get("command"):
            page.add(_reproduce(str(rb.provenance["command"])))
    _footer(ctx, page)
    return page.render(plotly_src=PLOTLY_JS)


def _history_for(ctx, planner: str, rb) -> tuple[str, pd.DataFrame] | None:
    """The training history of ``rb``: the one passed with ``--history`` when it belongs to
    this rulebook (checked by ``xfuzzy-rrt report``), else the one its manifest names."""
    prov = ctx["prov"]
    candidates = []
    given = prov.get("history_for") or {}
    if given.get(rb.sha256):
        candidates.append(given[rb.sha256])
    elif prov.get("history") and planner in ("fuzzy-rrt",) and not given:
        candidates.append(prov["history"])
    d = rulebook_dir(planner, ctx["result"])
    rel = (rb.provenance or {}).get("history")
    if d and isinstance(rel, str) and (Path(d) / rel).is_file():
        candidates.append(str((Path(d) / rel).resolve()))
    for path in candidates:
        try:
            frame = pd.read_csv(path)
        except Exception:  # an unreadable history is not evidence; try the next
            continue
        if {"generation", "best_fitness"} <= set(frame.columns):
            return str(path), frame
    return None


# ----------------------------------------------------------------------------------------------
# A training history given on the command line
# ----------------------------------------------------------------------------------------------

def history_rulebook_sha(path: Path) -> tuple[str, str]:
    """``(name, sha256)`` of the rulebook a training ``history.csv`` belongs to: its own
    ``rulebook_sha256`` column when it has one, else the rulebook written beside it by
    ``xfuzzy-rrt train`` (the history alone does not say which rulebook it trained)."""
    from xfuzzy_rrt.errors import InputError

    path = Path(path)
    if not path.is_file():
        raise InputError(str(path), "no such file")
    try:
        frame = pd.read_csv(path)
    except Exception as exc:  # pandas raises many types for unreadable files
        raise InputError(str(path), f"cannot read: {exc}") from None
    if not {"generation", "best_fitness"} <= set(frame.columns):
        raise InputError(str(path), "not a training history (needs the columns generation, "
                         "best_fitness)")
    if "rulebook_sha256" in frame.columns and frame["rulebook_sha256"].notna().any():
        return "", str(frame["rulebook_sha256"].dropna().iloc[-1])
    if not (path.parent / "rulebook.toml").is_file():
        raise InputError(str(path), "cannot tell which rulebook this history trained (no "
                         "rulebook.toml beside it)")
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook

    rb = load_rulebook(path.parent)
    return rb.name, rb.sha256


def attach_history(result, path: Path) -> None:
    """Show ``path`` on the page of the rulebook it trained; refuse it (``InputError`` naming the
    file) when no rulebook of the benchmark has that SHA-256, so the ``paper`` curve is never
    drawn under the ``general`` rulebook."""
    from xfuzzy_rrt.errors import InputError

    name, sha = history_rulebook_sha(path)
    books = rulebooks_of(result)
    if not any(rb.sha256 == sha for rb in books.values()):
        used = ", ".join(f"{rb.name} ({rb.sha256[:12]}\u2026)" for rb in books.values()) \
            or "none (no Fuzzy-RRT planner)"
        raise InputError(str(path), f"history of rulebook {name or '?'} (sha256 {sha[:12]}\u2026), "
                         f"not of a rulebook this benchmark ran: {used}")
    prov = result.provenance
    prov.setdefault("history_for", {})[sha] = str(Path(path).resolve())
