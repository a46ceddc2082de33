"""Figures of the fuzzy systems and of what they did during one run.

- :func:`firing_heatmap` -- which rules fired when (iteration x rule, one panel per output);
- :func:`io_series` -- the four inputs and six outputs over the iterations of a run;
- :func:`membership_figure` -- the five terms of each input of a FIS (or of several FIS that
  share the same partitions);
- :func:`surface_figure` -- each output over two chosen inputs, the other two fixed;
- :func:`training_figure` -- best / mean / median fitness per generation;
- :func:`coverage_figure` -- how many rules fired over the traced runs, and how few decide.

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

from xfuzzy_rrt.fuzzy.variables import MAX_FIRED, rule_terms
from xfuzzy_rrt.report.figures import TEMPLATE, plot_text

MAX_HEATMAP_COLUMNS = 80
MAX_HEATMAP_RULES = 24
MAX_SERIES_POINTS = 300
SURFACE_GRID = 31
SURFACE_AXES = ("dist_to_goal", "dist_to_obstacle")
#: Low values blue, high values red (each panel's own range, stated in its title).
SURFACE_COLORS = [[0.0, "#2166ac"], [0.5, "#f7f7f7"], [1.0, "#b2182b"]]


DEGREE = "\u00b0"
#: Units of the first edition's variables, used when a rulebook does not state its own.
_DEFAULT_UNITS = {"angle_to_goal": "rad", "angle_to_obstacle": "rad", "dist_to_goal": "m",
                  "dist_to_obstacle": "m", "goal_bias": "", "bound_1": "deg", "bound_2": "deg",
                  "bound_3": "deg", "bound_4": "deg", "step_size": "deg"}


def semantics(rulebook) -> tuple[tuple[str, ...], tuple[str, ...], dict, dict, dict]:
    """``(inputs, outputs, input_ranges, output_ranges, units)`` of ``rulebook``: read from the
    rulebook (``rulebook.semantics``) when it says, else the paper's variables."""
    from xfuzzy_rrt.fuzzy import variables as V

    sem = getattr(rulebook, "semantics", None) if rulebook is not None else None
    if sem is not None:
        units = dict(_DEFAULT_UNITS)
        units.update(dict(getattr(sem, "units", {}) or {}))
        return (tuple(sem.inputs), tuple(sem.outputs), dict(sem.input_ranges),
                dict(sem.output_ranges), units)
    return V.INPUTS, V.OUTPUTS, dict(V.INPUT_RANGES), dict(V.OUTPUT_RANGES), dict(_DEFAULT_UNITS)


def with_unit(name: str, units: dict) -> str:
    """``'dist_to_goal (m)'``, ``'bound_1 (°)'``, ``'goal_bias'``."""
    u = units.get(name, "")
    return f"{name} ({'°' if u == 'deg' else u})" if u else name


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
    # Bin labels such as "4-5" would be read as dates by plotly (an empty plot and NaN widths):
    # they are categories.
    fig.update_xaxes(type="category")
    return fig


def io_series(trace: pd.DataFrame, max_points: int = MAX_SERIES_POINTS,
              rulebook=None) -> go.Figure:
    """The four inputs and six outputs per iteration (every k-th iteration when dense)."""
    n = len(trace)
    step = max(1, math.ceil(n / max_points))
    view = trace.iloc[::step]
    inputs, outputs, _, _, units = semantics(rulebook)
    names = [c for c in list(inputs) + list(outputs) if c in trace.columns]
    fig = make_subplots(rows=max(1, math.ceil(len(names) / 2)), cols=2, shared_xaxes=True,
                        vertical_spacing=0.05, horizontal_spacing=0.08,
                        subplot_titles=[with_unit(c, units) for c in names])
    x = view["iteration"].to_numpy(dtype=np.int32)
    for k, c in enumerate(names):
        is_input = c in inputs
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


#: Term labels of a membership figure: the first row's height, the step between rows (data
#: units of the 0..1 membership axis), the plotting width assumed for all subplots together
#: (the report's 1400 px page less margins) and the width of one character at 10 px.
LABEL_Y0 = 1.07
LABEL_DY = 0.13
LABEL_AXIS_PX = 1150.0
LABEL_CHAR_PX = 6.5


def label_rows(peaks: list[float], labels: list[str], axis_px: float) -> list[int]:
    """A row (0, 1, ...) for each term label, centred on its peak, so that no two labels on
    one row overlap: each label goes on the lowest row whose last label ends (with a 6 px
    gap) before it starts. Why not alternate rows: trained peaks crowd (clearance_deg 0,
    2.36, 5.57 of 30), and labels two terms apart then overlapped on the same row."""
    lo, hi = float(peaks[0]), float(peaks[-1])
    per_px = (hi - lo) / axis_px if hi > lo else 1.0
    ends: list[float] = []
    rows = []
    for x, text in sorted(zip(peaks, labels), key=lambda t: t[0]):
        half = 0.5 * len(text) * LABEL_CHAR_PX * per_px
        left, right = float(x) - half, float(x) + half + 6.0 * per_px
        row = next((r for r, end in enumerate(ends) if end <= left), len(ends))
        if row == len(ends):
            ends.append(right)
        else:
            ends[row] = right
        rows.append(row)
    order = sorted(range(len(peaks)), key=lambda j: peaks[j])
    out = [0] * len(peaks)
    for position, j in enumerate(order):
        out[j] = rows[position]
    return out


def membership_figure(fis, outputs: list[str], rulebook=None) -> go.Figure:
    """The five terms of each input of ``fis`` (exact piecewise-linear, drawn through knots);
    axis titles with units, term labels on as many rows as needed so that none overlap
    (:func:`label_rows`)."""
    units = semantics(rulebook)[4]
    fig = make_subplots(rows=1, cols=len(fis.inputs), horizontal_spacing=0.05)
    palette = ("#0072B2", "#009E73", "#E69F00", "#CC79A7", "#D55E00")
    top = 1
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
        labels = [f"{plot_text(term)} {_sig(k[j])}" for j, term in enumerate(inp.terms)]
        rows = label_rows(list(k), labels, LABEL_AXIS_PX / len(fis.inputs))
        top = max(top, max(rows))
        for j, text in enumerate(labels):
            fig.add_annotation(x=k[j], y=LABEL_Y0 + LABEL_DY * rows[j], text=text,
                               showarrow=False, font=dict(size=10, color=palette[j]),
                               xref=f"x{c + 1}" if c else "x", yref=f"y{c + 1}" if c else "y")
        fig.update_xaxes(title_text=with_unit(inp.name, units), row=1, col=c + 1)
    fig.update_yaxes(range=[0, LABEL_Y0 + LABEL_DY * (top + 0.8)], tickvals=[0, 0.5, 1])
    fig.update_layout(template=TEMPLATE, height=300, margin=dict(l=40, r=30, t=60, b=45),
                      title=dict(text="Membership functions \u2014 " + plot_text(", ".join(outputs)),
                                 x=0))
    return fig


def _sig(x: float) -> str:
    from xfuzzy_rrt.report.numbers import sig

    return sig(x, 3)


def surface_axes(rulebook) -> tuple[str, str]:
    """The two inputs a surface is drawn over: the two distances (unit ``m``) when the rulebook
    has them, else its first two inputs."""
    inputs, _, _, _, units = semantics(rulebook)
    dist = [i for i in inputs if units.get(i) == "m"]
    return (dist[0], dist[1]) if len(dist) >= 2 else (inputs[0], inputs[1])


def surface_inputs(fis_list, axes: tuple[str, str] = SURFACE_AXES) -> dict[str, float]:
    """Fixed values for the inputs not on the surface axes: the middle peak of the first FIS."""
    first = fis_list[0]
    return {i.name: float(i.peaks[2]) for i in first.inputs if i.name not in axes}


def surface_figure(rulebook, n: int = SURFACE_GRID) -> tuple[go.Figure, dict[str, float]]:
    """Each output over two inputs (the compiled engine), the other inputs fixed; one colour
    bar per panel, in the output's unit."""
    from xfuzzy_rrt.fuzzy.engine import evaluate

    inputs, outputs, in_ranges, _, units = semantics(rulebook)
    ax, ay = surface_axes(rulebook)
    fixed = surface_inputs(rulebook.systems, (ax, ay))
    xs = np.linspace(*in_ranges[ax], n)
    ys = np.linspace(*in_ranges[ay], n)
    gx, gy = np.meshgrid(xs, ys)
    X = np.zeros((gx.size, len(inputs)))
    for i, name in enumerate(inputs):
        X[:, i] = gx.ravel() if name == ax else gy.ravel() if name == ay else fixed[name]
    knots, consts = rulebook.arrays()
    Y = evaluate(knots, consts, X)
    titles = [with_unit(out, units) if Y[:, f].max() > Y[:, f].min()
              else f"{with_unit(out, units)}: constant {_sig(Y[0, f])}"
              for f, out in enumerate(outputs)]
    fig = make_subplots(rows=2, cols=3, subplot_titles=titles, horizontal_spacing=0.11,
                        vertical_spacing=0.16)
    for f, out in enumerate(outputs):
        row, col = f // 3 + 1, f % 3 + 1
        xd = fig.get_subplot(row, col).xaxis.domain
        yd = fig.get_subplot(row, col).yaxis.domain
        u = units.get(out, "")
        fig.add_trace(go.Heatmap(
            x=xs, y=ys, z=Y[:, f].reshape(n, n), colorscale=SURFACE_COLORS, showscale=True,
            colorbar=dict(x=xd[1] + 0.008, y=(yd[0] + yd[1]) / 2, len=yd[1] - yd[0],
                          thickness=10, xanchor="left", tickfont=dict(size=9),
                          title=dict(text=DEGREE if u == "deg" else u, side="right")),
            hovertemplate=f"{ax} %{{x:.3g}}<br>{ay} %{{y:.3g}}<br>{out} %{{z:.4g}}"
                          "<extra></extra>"), row=row, col=col)
    fig.update_xaxes(title_text=with_unit(ax, units))
    fig.update_yaxes(title_text=with_unit(ay, units))
    fixed_text = ", ".join(f"{k} = {_sig(v)} {units.get(k, '')}".rstrip()
                           for k, v in fixed.items())
    fig.update_layout(template=TEMPLATE, height=660, margin=dict(l=60, r=40, t=90, b=50),
                      title=dict(text=f"Rule surfaces: each output over {plot_text(ax)} \u00d7 "
                                      f"{plot_text(ay)}<br><sup>fixed: {plot_text(fixed_text)}"
                                      " (hover for values)</sup>", x=0))
    return fig, fixed


def coverage_figure(traces: list, rulebook) -> go.Figure | None:
    """Per output: how many of its rules fired at least once over ``traces``, and how many
    carry 90 % of the summed firing strength (a few rules usually decide)."""
    traces = [t for t in traces if isinstance(t, pd.DataFrame) and len(t)]
    if not traces:
        return None
    outputs = semantics(rulebook)[1]
    n_rules = len(rulebook.systems[0].consts)
    fired, core = [], []
    for out in outputs:
        w = np.zeros(n_rules)
        for t in traces:
            cols = [c for c in (f"{out}_rule_{k}" for k in range(MAX_FIRED)) if c in t]
            r = t[cols].to_numpy()
            st = t[[c.replace("_rule_", "_strength_") for c in cols]].to_numpy()
            m = r >= 0
            w += np.bincount(r[m], weights=st[m], minlength=n_rules)
        order = np.sort(w)[::-1]
        total = order.sum()
        fired.append(int(np.count_nonzero(w > 0)))
        core.append(int(np.searchsorted(np.cumsum(order), 0.9 * total) + 1) if total > 0 else 0)
    fig = go.Figure()
    fig.add_trace(go.Bar(x=list(outputs), y=fired, name="rules that fired",
                         marker_color="#0072B2", text=fired, textposition="outside"))
    fig.add_trace(go.Bar(x=list(outputs), y=core, name="rules carrying 90% of the strength",
                         marker_color="#D55E00", text=core, textposition="outside"))
    fig.update_xaxes(type="category")
    fig.update_yaxes(title_text=f"rules (of {n_rules} per system)", rangemode="tozero")
    fig.update_layout(template=TEMPLATE, height=360, barmode="group",
                      margin=dict(l=60, r=20, t=60, b=40),
                      legend=dict(orientation="h", y=1.02, yanchor="bottom", x=0),
                      title=dict(text=f"Rule coverage over {len(traces)} traced run(s)", x=0,
                                 y=0.98))
    return fig


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
