"""Rule-coverage figures and page: the 625 rules of a FIS as a 25 x 25 heatmap.

Layout: rows are (angle_to_goal, dist_to_goal) term pairs, columns (angle_to_obstacle,
dist_to_obstacle) term pairs, both in rule-index order, so rule ``r`` sits at row ``r // 25``,
column ``r % 25`` and a block of 5 x 5 cells shares the two angle terms. Dead rules (never
fired) are left blank, which makes "which situations did the benchmark never reach" visible at
a glance. Reused by the report and by ``rules coverage --html``.
"""

from __future__ import annotations

import numpy as np
import plotly.graph_objects as go

from xfuzzy_rrt.analysis.coverage import coverage_grid
from xfuzzy_rrt.fuzzy.variables import INPUTS, OUTPUTS

VALUE_LABELS = {"mass_share": "share of output mass", "fired": "iterations fired",
                "strength_mean": "mean normalised strength", "constant": "rule constant"}


def _labels(rulebook, f: int, pair: tuple[int, int]) -> list[str]:
    a, b = (rulebook.systems[f].inputs[i] for i in pair)
    return [f"{ta} / {tb}" for ta in a.terms for tb in b.terms]


def coverage_heatmap(coverage, rulebook, output: str, value: str = "mass_share",
                     title: str | None = None) -> go.Figure:
    """Heatmap of one coverage column (see :data:`VALUE_LABELS`) for one FIS; dead rules blank."""
    f = OUTPUTS.index(output)
    z = coverage_grid(coverage, output, value)
    fired = coverage_grid(coverage, output, "fired")
    z = np.where(fired > 0, z, np.nan) if value != "constant" else z
    g = coverage[coverage["output"] == output].sort_values("rule")
    text = [f"r{r}: {a}<br>constant {c:.6g}<br>fired {n}, share {s:.4g}"
            for r, a, c, n, s in zip(g["rule"], g["antecedent"], g["constant"], g["fired"],
                                     g["mass_share"])]
    text = np.asarray(text, dtype=object).reshape(25, 25)
    rows = _labels(rulebook, f, (0, 1))
    cols = _labels(rulebook, f, (2, 3))
    fig = go.Figure(go.Heatmap(
        z=z, x=cols, y=rows, text=text, hovertemplate="%{text}<extra></extra>",
        colorscale="Viridis", colorbar=dict(title=VALUE_LABELS.get(value, value)),
        xgap=1, ygap=1))
    for k in range(1, 5):  # separate the 5 x 5 blocks of equal angle terms
        fig.add_hline(y=5 * k - 0.5, line=dict(color="#888", width=1))
        fig.add_vline(x=5 * k - 0.5, line=dict(color="#888", width=1))
    fig.update_layout(
        title=dict(text=title or f"{output}: {VALUE_LABELS.get(value, value)} per rule "
                                 "(blank: never fired)", x=0.5, xanchor="center"),
        height=720, margin=dict(l=190, r=20, t=60, b=190), template="plotly_white")
    fig.update_xaxes(title_text=f"{INPUTS[2]} / {INPUTS[3]}", tickangle=-60, tickfont=dict(size=9))
    fig.update_yaxes(title_text=f"{INPUTS[0]} / {INPUTS[1]}", autorange="reversed",
                     tickfont=dict(size=9))
    return fig


def coverage_page(coverage, summary, rulebook, command: str = "", value: str = "mass_share") -> str:
    """A self-contained HTML page: summary table, the rules carrying 90 % and one heatmap per FIS."""
    from xfuzzy_rrt.report.html import Page, esc, table

    page = Page(f"Rule coverage: {rulebook.name}")
    page.heading(f"Rule coverage of rulebook {rulebook.name!r}", level=1)
    page.paragraph(f"sha256 {rulebook.sha256}")
    if command:
        page.add(f"<pre>{esc(command)}</pre>")
    page.paragraph("mass share = Σ over iterations of the rule's normalised firing strength, "
                   "divided by the iterations (shares sum to 1 per output). 'carrying 90 %' is "
                   "the smallest set of rules, largest share first, whose shares reach 0.9.")
    page.add(table(summary.itertuples(index=False), list(summary.columns),
                   formats=[None, None, None, lambda v: f"{v:.3f}", None, None,
                            lambda v: f"{v:.3f}"]))
    for out in OUTPUTS:
        page.heading(out, level=2, anchor=f"cov-{out}")
        top = coverage[(coverage["output"] == out) & coverage["carries_90"]].sort_values("rank")
        rows = [(f"r{r}", a, c, n, s, cs, on, off) for r, a, c, n, s, cs, on, off in zip(
            top["rule"], top["antecedent"], top["constant"], top["fired"], top["mass_share"],
            top["cumulative_share"], top["fired_on_path"], top["fired_off_path"])]
        page.add("<details><summary>"
                 f"{len(rows)} rules carry 90 % of the {esc(out)} mass</summary>"
                 + table(rows, ["rule", "antecedent", "constant", "fired", "share",
                                "cumulative", "on path", "off path"],
                         formats=[None, None, lambda v: f"{v:.6g}", None,
                                  lambda v: f"{v:.4f}", lambda v: f"{v:.4f}", None, None])
                 + "</details>")
        page.add(page.figure(coverage_heatmap(coverage, rulebook, out, value), f"cov-fig-{out}"))
    return page.render()
