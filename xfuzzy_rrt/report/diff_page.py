"""HTML page for ``rules diff``: changed cells (tables and 25 x 25 heatmaps of the change),
moved membership peaks, bounds mode, documentary differences, and with ``--replay`` both plans
side by side with the first divergence and the rules that caused it."""

from __future__ import annotations

import numpy as np
import plotly.graph_objects as go

from xfuzzy_rrt.analysis.diff import changed_grid
from xfuzzy_rrt.fuzzy.variables import INPUTS, OUTPUTS


def _labels(rulebook, pair: tuple[int, int]) -> list[str]:
    a, b = (rulebook.systems[0].inputs[i] for i in pair)
    return [f"{ta} / {tb}" for ta in a.terms for tb in b.terms]


def delta_heatmap(diff, rulebook, output: str) -> go.Figure:
    """``b - a`` per cell of one FIS (unchanged cells blank), rule-index layout 25 x 25."""
    z = changed_grid(diff, output)
    z = np.where(z != 0, z, np.nan)
    m = float(np.nanmax(np.abs(z))) if np.isfinite(z).any() else 1.0
    fig = go.Figure(go.Heatmap(z=z, x=_labels(rulebook, (2, 3)), y=_labels(rulebook, (0, 1)),
                               colorscale="RdBu", zmid=0, zmin=-m, zmax=m, xgap=1, ygap=1,
                               colorbar=dict(title="b - a")))
    for k in range(1, 5):
        fig.add_hline(y=5 * k - 0.5, line=dict(color="#888", width=1))
        fig.add_vline(x=5 * k - 0.5, line=dict(color="#888", width=1))
    fig.update_layout(title=dict(text=f"{output}: change per cell (blank: unchanged)", x=0.5),
                      height=700, margin=dict(l=190, r=20, t=60, b=190), template="plotly_white")
    fig.update_xaxes(title_text=f"{INPUTS[2]} / {INPUTS[3]}", tickangle=-60, tickfont=dict(size=9))
    fig.update_yaxes(title_text=f"{INPUTS[0]} / {INPUTS[1]}", autorange="reversed",
                     tickfont=dict(size=9))
    return fig


def diff_page(diff, a, b, replay=None, scenario=None, command: str = "",
              max_rows: int = 2000) -> str:
    from xfuzzy_rrt.report.html import Page, esc, kv_table, table

    page = Page(f"Rulebook diff: {a.name} vs {b.name}")
    page.heading(f"Rulebook diff: {a.name!r} (a) vs {b.name!r} (b)", level=1)
    if command:
        page.add(f"<pre>{esc(command)}</pre>")
    verdict = ("identical behaviour (same constants, peaks and bounds mode)" if diff.identical
               else "different behaviour")
    page.add(kv_table([("a", f"{a.name} sha256 {a.sha256}"), ("b", f"{b.name} sha256 {b.sha256}"),
                       ("verdict", verdict),
                       ("bounds mode", f"{a.bounds_mode} vs {b.bounds_mode}"
                        if diff.bounds_mode else f"{a.bounds_mode} (same)")]))
    page.heading("Changed cells per FIS")
    po = diff.per_output()
    page.add(table(po.itertuples(index=False), list(po.columns)))
    if not diff.cells.empty:
        rows = [(o, f"r{r}", t, x, y, d) for o, r, t, x, y, d in
                diff.cells.head(max_rows).itertuples(index=False)]
        fmt = lambda v: f"{v:.6g}"  # noqa: E731
        page.add("<details><summary>" + esc(f"{len(diff.cells)} changed cells"
                                              + (f" (first {max_rows})" if len(diff.cells) > max_rows else ""))
                 + "</summary>" + table(rows, ["output", "rule", "antecedent", "a", "b", "b - a"],
                                        formats=[None, None, None, fmt, fmt, fmt]) + "</details>")
        for out in OUTPUTS:
            if (diff.cells["output"] == out).any():
                page.add(page.figure(delta_heatmap(diff, a, out), f"diff-{out}"))
    page.heading("Membership peaks")
    if diff.peaks.empty:
        page.paragraph("No peak moved.")
    else:
        page.add(table(diff.peaks.itertuples(index=False), list(diff.peaks.columns)))
    page.heading("Documentary differences (name, description, provenance, term names)")
    if diff.documentary.empty:
        page.paragraph("None.")
    else:
        page.add(table(((f, str(x), str(y)) for f, x, y in diff.documentary.itertuples(index=False)),
                       ["field", "a", "b"]))
    if replay is not None:
        from xfuzzy_rrt.report.figures import joint_space_figure, plot_text

        page.heading(f"Replay: scenario {replay.scenario}, seed {replay.seed}")
        if replay.divergence is None:
            page.paragraph(f"No divergence: both runs made the same decisions in all "
                           f"{replay.result_a.iterations} iterations.")
        else:
            page.paragraph(f"The runs first diverge at iteration {replay.divergence}; "
                           "before it every decision was identical. The plan itself (sample, "
                           f"outcome) first differs at iteration {replay.plan_divergence}.")
            page.add(table(((q, str(x), str(y)) for q, x, y in replay.decisions.itertuples(index=False)),
                           ["quantity", "a", "b"]))
            if not replay.causes.empty:
                page.paragraph("Fired rules at that iteration whose constant or strength differs:")
                page.add(table(replay.causes.itertuples(index=False), list(replay.causes.columns),
                               formats=[None, None, None] + [lambda v: f"{v:.6g}"] * 5))
            if (replay.plan_divergence is not None and replay.plan_divergence != replay.divergence
                    and not replay.plan_causes.empty):
                page.paragraph(f"At iteration {replay.plan_divergence}, where the plan itself "
                               "first differs, the fired rules whose constant or strength differs:")
                page.add(table(replay.plan_causes.itertuples(index=False),
                               list(replay.plan_causes.columns),
                               formats=[None, None, None] + [lambda v: f"{v:.6g}"] * 5))
        oc = replay.outcomes()
        page.add(table(oc.itertuples(index=False), list(oc.columns)))
        figs = []
        for label, res, rb in (("a", replay.result_a, a), ("b", replay.result_b, b)):
            fig = joint_space_figure(scenario, res, title=plot_text(f"({label}) {rb.name}: "
                                                    f"{res.iterations} iterations"))
            figs.append(f'<div class="cell">{page.figure(fig, f"replay-{label}")}</div>')
        page.add('<div class="grid" style="grid-template-columns: 1fr 1fr">' + "".join(figs) + "</div>")
    return page.render()
