"""Figures of the fuzzy systems and of what they did during one run.

- :func:`firing_heatmap` -- which rules fired when (iteration x rule, one panel per output);
- :func:`io_series` -- the four inputs and six outputs over the iterations of a run;
- :func:`membership_figure` -- the five terms of each input of a FIS (or of several FIS that
  share the same partitions);
- :func:`surface_figure` -- each output over two chosen inputs, the other two fixed;
- :func:`training_figure` -- best / mean / median fitness per generation;
- :func:`ratio_figure` -- per planner, the per-scenario median-iteration ratios to the baseline.

Dense traces are decimated for drawing (a run may have 10,000 iterations; a browser plot needs
a few hundred columns): heatmap columns are *bins* of consecutive iterations showing the mean
normalised strength (in whole percent), line plots show every k-th iteration. Each figure says
what it shows when it decimates. Everything else is read, never recomputed: rule surfaces use
the compiled engine the planner uses.
"""

from __future__ import annotations

import math
from typing import Any

import numpy as np
import pandas as pd
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from xfuzzy_rrt.fuzzy.variables import INPUTS, MAX_FIRED, OUTPUTS, rule_terms
from xfuzzy_rrt.report.figures import TEMPLATE, plot_text, planner_color, planner_label

MAX_HEATMAP_COLUMNS = 80
MAX_HEATMAP_RULES = 24
MAX_SERIES_POINTS = 300
SURFACE_GRID = 31
SURFACE_AXES = ("dist_to_goal", "dist_to_obstacle")
#: Low values blue, high values red (each panel's own range, stated in its title).
SURFACE_COLORS = [[0.0, "#2166ac"], [0.5, "#f7f7f7"], [1.0, "#b2182b"]]


def _bins(n: int, max_cols: int) -> np.ndarray:
    """Bin index (0..cols-1) of each of ``n`` iterations, consecutive iterations together."""
    cols = max(1, min(n, max_cols))
    return (np.arange(n) * cols) // max(n, 1)


def rule_label(fis, r: int) -> str:
    """``r154: north, near, east_0, very_far`` (the antecedent's terms, INPUTS order)."""
    t = rule_terms(r)
    return f"r{r}: " + ", ".join(inp.terms[t[i]] for i, inp in enumerate(fis.inputs))


def firing_heatmap(trace: pd.DataFrame, rulebook, max_cols: int = MAX_HEATMAP_COLUMNS,
                   max_rules: int = MAX_HEATMAP_RULES) -> go.Figure:
    """Mean normalised firing strength (percent) per iteration bin and rule; only rules that
    fired, the ``max_rules`` most influential when more fired.

    A rule's strength depends only on the inputs and the input partitions, so systems that
    share their partitions fire identically: they share one panel (the usual case).
    """
    n = len(trace)
    b = _bins(n, max_cols)
    cols = int(b.max()) + 1 if n else 1
    first = np.searchsorted(b, np.arange(cols), side="left")
    last = np.searchsorted(b, np.arange(cols), side="right") - 1
    iters = trace["iteration"].to_numpy()
    x = [f"{iters[lo]}" if lo == hi else f"{iters[lo]}-{iters[hi]}"
         for lo, hi in zip(first, last)]
    groups = partition_groups(rulebook)
    titles = [", ".join(outs) + (" (same partitions, same firing)" if len(outs) > 1 else "")
              for outs, _ in groups]
    fig = make_subplots(rows=len(groups), cols=1, shared_xaxes=True, vertical_spacing=0.04,
                        subplot_titles=titles)
    counts = np.bincount(b, minlength=cols).astype(float)
    notes = []
    zmax = 1
    panels = []
    for outs, fis in groups:
        out = outs[0]
        rules = trace[[f"{out}_rule_{k}" for k in range(MAX_FIRED)]].to_numpy()
        w = trace[[f"{out}_strength_{k}" for k in range(MAX_FIRED)]].to_numpy()
        fired = rules >= 0
        rr, ww = rules[fired], w[fired]
        bins = np.broadcast_to(b[:, None], rules.shape)[fired]
        influence = np.bincount(rr, weights=ww, minlength=625) if rr.size else np.zeros(625)
        ids = np.flatnonzero(influence > 0)
        if ids.size > max_rules:
            ids = np.sort(ids[np.argsort(-influence[ids], kind="stable")[:max_rules]])
            notes.append(f"{max_rules} most influential of {np.count_nonzero(influence > 0)} "
                         "fired rules")
        pos = np.full(625, -1)
        pos[ids] = np.arange(ids.size)
        z = np.zeros((ids.size, cols))
        keep = pos[rr] >= 0
        np.add.at(z, (pos[rr[keep]], bins[keep]), ww[keep])
        z = np.rint(100.0 * z / np.maximum(counts, 1.0)).astype(np.uint8)
        zmax = max(zmax, int(z.max()) if z.size else 1)
        panels.append((fis, ids, z))
    for g, (fis, ids, z) in enumerate(panels):
        fig.add_trace(go.Heatmap(
            x=x, y=[plot_text(rule_label(fis, int(r))) for r in ids], z=z, zmin=0, zmax=zmax,
            colorscale="Viridis", showscale=(g == 0),
            colorbar=dict(title="mean strength %", len=min(1.0, 0.9 / len(groups)), y=1.0,
                          yanchor="top"),
            hovertemplate="iterations %{x}<br>%{y}<br>mean strength %{z}%<extra></extra>"),
            row=g + 1, col=1)
        fig.update_yaxes(tickfont=dict(size=9), autorange="reversed", row=g + 1, col=1)
    per_bin = math.ceil(n / cols) if cols else 1
    sub = [f"columns: bins of ~{per_bin} consecutive iterations" if per_bin > 1
           else "one column per iteration"]
    if notes:
        sub.append("rows: the " + notes[0])
    height = sum(120 + 14 * len(ids) for _, ids, _ in panels) + 110
    fig.update_layout(template=TEMPLATE, height=height,
                      title=dict(text="Rule firing over the run (only rules that fired)<br><sup>"
                                      + plot_text("; ".join(sub)) + "</sup>", x=0),
                      margin=dict(l=230, r=20, t=80, b=50))
    fig.update_xaxes(title_text="iteration", row=len(groups), col=1)
    return fig


def io_series(trace: pd.DataFrame, max_points: int = MAX_SERIES_POINTS) -> go.Figure:
    """The four inputs and six outputs per iteration (every k-th iteration when dense)."""
    n = len(trace)
    step = max(1, math.ceil(n / max_points))
    view = trace.iloc[::step]
    names = list(INPUTS) + ["goal_bias", "step_size", "bound_1", "bound_2", "bound_3", "bound_4"]
    units = {"angle_to_goal": "rad", "angle_to_obstacle": "rad", "dist_to_goal": "m",
             "dist_to_obstacle": "m", "goal_bias": "", "step_size": "deg"}
    fig = make_subplots(rows=5, cols=2, shared_xaxes=True, vertical_spacing=0.05,
                        horizontal_spacing=0.08,
                        subplot_titles=[f"{c} ({units.get(c, 'deg')})" if units.get(c, "deg")
                                        else c for c in names])
    x = view["iteration"].to_numpy(dtype=np.int32)
    for k, c in enumerate(names):
        is_input = c in INPUTS
        fig.add_trace(go.Scatter(x=x, y=view[c].to_numpy(dtype=np.float64), mode="lines",
                                   name=c, showlegend=False,
                                   line=dict(width=1, color="#0072B2" if is_input else "#D55E00"),
                                   hovertemplate="iteration %{x}<br>%{y:.4g}<extra>" + c
                                                 + "</extra>"),
                      row=k // 2 + 1, col=k % 2 + 1)
    sub = f"every {step}th iteration of {n}" if step > 1 else f"all {n} iterations"
    fig.update_layout(template=TEMPLATE, height=820,
                      title=dict(text=f"Inputs (blue) and outputs (orange) per iteration"
                                      f"<br><sup>{sub}</sup>", x=0),
                      margin=dict(l=50, r=20, t=80, b=40))
    return fig


def partition_groups(rulebook) -> list[tuple[list[str], Any]]:
    """Outputs grouped by identical input partitions (peaks and term names)."""
    groups: list[tuple[list[str], Any]] = []
    for s in rulebook.systems:
        key = tuple((i.terms, i.peaks) for i in s.inputs)
        for outs, fis in groups:
            if tuple((i.terms, i.peaks) for i in fis.inputs) == key:
                outs.append(s.output)
                break
        else:
            groups.append(([s.output], s))
    return groups


def membership_figure(fis, outputs: list[str]) -> go.Figure:
    """The five terms of each input of ``fis`` (exact piecewise-linear, drawn through knots)."""
    fig = make_subplots(rows=1, cols=4, horizontal_spacing=0.06,
                        subplot_titles=[i.name for i in fis.inputs])
    palette = ("#0072B2", "#009E73", "#E69F00", "#CC79A7", "#D55E00")
    for c, inp in enumerate(fis.inputs):
        k = inp.peaks
        for j, term in enumerate(inp.terms):
            if j == 0:
                xs, ys = [k[0], k[1]], [1, 0]
            elif j == 4:
                xs, ys = [k[3], k[4]], [0, 1]
            else:
                xs, ys = [k[j - 1], k[j], k[j + 1]], [0, 1, 0]
            fig.add_trace(go.Scatter(x=xs, y=ys, mode="lines", name=plot_text(term),
                                     showlegend=False, line=dict(color=palette[j], width=2),
                                     hovertemplate=plot_text(term)
                                     + " %{x:.4g}: %{y:.2f}<extra></extra>"),
                          row=1, col=c + 1)
            fig.add_annotation(x=k[j], y=1.06, text=plot_text(term), showarrow=False,
                               font=dict(size=9, color=palette[j]),
                               xref=f"x{c + 1}" if c else "x", yref=f"y{c + 1}" if c else "y")
    fig.update_yaxes(range=[0, 1.15])
    fig.update_layout(template=TEMPLATE, height=280, margin=dict(l=40, r=20, t=70, b=30),
                      title=dict(text="Membership functions \u2014 " + plot_text(", ".join(outputs)),
                                 x=0))
    return fig


def surface_inputs(fis_list) -> dict[str, float]:
    """Fixed values for the inputs not on the surface axes: the middle peak of the first FIS."""
    first = fis_list[0]
    return {i.name: float(i.peaks[2]) for i in first.inputs if i.name not in SURFACE_AXES}


def surface_figure(rulebook, n: int = SURFACE_GRID) -> tuple[go.Figure, dict[str, float]]:
    """Each output over ``SURFACE_AXES`` (the compiled engine), the other inputs fixed."""
    from xfuzzy_rrt.fuzzy.engine import evaluate
    from xfuzzy_rrt.fuzzy.variables import INPUT_RANGES

    fixed = surface_inputs(rulebook.systems)
    ax, ay = SURFACE_AXES
    xs = np.linspace(*INPUT_RANGES[ax], n)
    ys = np.linspace(*INPUT_RANGES[ay], n)
    gx, gy = np.meshgrid(xs, ys)
    X = np.zeros((gx.size, len(INPUTS)))
    for i, name in enumerate(INPUTS):
        X[:, i] = gx.ravel() if name == ax else gy.ravel() if name == ay else fixed[name]
    knots, consts = rulebook.arrays()
    Y = evaluate(knots, consts, X)
    titles = [f"{out}: {Y[:, f].min():.4g} (blue) \u2026 {Y[:, f].max():.4g} (red)"
              if Y[:, f].max() > Y[:, f].min() else f"{out}: constant {Y[0, f]:.4g}"
              for f, out in enumerate(OUTPUTS)]
    fig = make_subplots(rows=2, cols=3, subplot_titles=titles, horizontal_spacing=0.07,
                        vertical_spacing=0.14)
    for f, out in enumerate(OUTPUTS):
        fig.add_trace(go.Heatmap(x=xs, y=ys, z=Y[:, f].reshape(n, n), colorscale=SURFACE_COLORS,
                                 showscale=False, hovertemplate=f"{ax} %{{x:.3f}}<br>{ay} "
                                 f"%{{y:.3f}}<br>{out} %{{z:.4g}}<extra></extra>"),
                      row=f // 3 + 1, col=f % 3 + 1)
    fig.update_xaxes(title_text=f"{ax} (m)")
    fig.update_yaxes(title_text=f"{ay} (m)")
    fixed_text = ", ".join(f"{k} = {v:.4g} rad" for k, v in fixed.items())
    fig.update_layout(template=TEMPLATE, height=620, margin=dict(l=60, r=20, t=90, b=50),
                      title=dict(text="Rule surfaces: each output over dist_to_goal \u00d7 "
                                      f"dist_to_obstacle<br><sup>fixed: {plot_text(fixed_text)}"
                                      " (hover for values)</sup>", x=0))
    return fig, fixed


def training_figure(history: pd.DataFrame) -> go.Figure:
    fig = go.Figure()
    styles = {"best_fitness": ("best", "#D55E00", "solid"),
              "mean_fitness": ("mean", "#0072B2", "dash"),
              "median_fitness": ("median", "#009E73", "dot")}
    for col, (name, color, dash) in styles.items():
        if col in history:
            fig.add_trace(go.Scatter(x=history["generation"].to_numpy(),
                                     y=history[col].to_numpy(dtype=np.float64),
                                     mode="lines+markers", name=name,
                                     line=dict(color=color, dash=dash), marker=dict(size=4)))
    fig.update_layout(template=TEMPLATE, height=380, xaxis_title="generation",
                      yaxis_title="fitness", margin=dict(l=60, r=20, t=50, b=50),
                      title=dict(text="Training: fitness per generation", x=0))
    return fig


def ratio_figure(summary: pd.DataFrame, baseline: str = "rrt") -> go.Figure | None:
    """Per planner, one dot per scenario: baseline median iterations / planner median."""
    from xfuzzy_rrt.bench.summary import scenario_ratios
    from xfuzzy_rrt.report.figures import planner_order

    r = summary.assign(_r=scenario_ratios(summary, baseline))
    r = r[(r["planner"] != baseline) & r["_r"].notna()]
    if r.empty:
        return None
    fig = go.Figure()
    for p in planner_order(r["planner"]):
        g = r[r["planner"] == p]
        fig.add_trace(go.Box(x=g["_r"].to_numpy(dtype=np.float64), name=plot_text(planner_label(p)),
                             boxpoints="all", jitter=0.4, pointpos=0, orientation="h",
                             marker=dict(color=planner_color(p), size=6),
                             line=dict(color=planner_color(p)), fillcolor="rgba(0,0,0,0)",
                             text=[plot_text(s) for s in g["scenario"]],
                             hovertemplate="%{text}: %{x:.2f}<extra>" + plot_text(p) + "</extra>"))
    fig.add_vline(x=1.0, line=dict(color="#444", dash="dash"))
    fig.update_xaxes(type="log", title_text=f"{planner_label(baseline)} median iterations / "
                     "planner median iterations (log; > 1: fewer iterations than the baseline)")
    fig.update_layout(template=TEMPLATE, height=150 + 60 * r["planner"].nunique(),
                      showlegend=False, margin=dict(l=110, r=20, t=50, b=60),
                      title=dict(text="Per-scenario median-iteration ratio to "
                                      f"{planner_label(baseline)}", x=0))
    return fig
