"""A small offline HTML page for a path robustness analysis (plotly, embedded once).

Per path: P(collision) vs σ with its 95 % intervals, the minimum-clearance histogram at each σ,
and the worst sampled execution (largest σ) drawn over its perturbed obstacles, beside the
model's obstacles, so a reader sees *how* the path fails, not only how often.
"""

from __future__ import annotations

import math

import numpy as np


def _arm_points(links, base, q_deg):
    theta = np.cumsum(np.radians(q_deg))
    pts = [np.asarray(base, dtype=float)]
    for k, length in enumerate(links):
        pts.append(pts[-1] + length * np.array([math.cos(theta[k]), math.sin(theta[k])]))
    return np.array(pts)


def _arms_points(arrays, q_deg):
    """Every arm's points for the full configuration ``q_deg`` (each arm from its own slice)."""
    q = np.asarray(q_deg, dtype=float)
    first = getattr(arrays, "arm_first", None)
    if first is None or len(first) <= 2:
        return [_arm_points(arrays.links, arrays.base, q)]
    return [_arm_points(arrays.links[first[k]:first[k + 1]], arrays.bases[k],
                        q[first[k]:first[k + 1]]) for k in range(len(first) - 1)]


def _obstacle_shapes(obstacles, colour, dash):
    shapes = []
    for ob in obstacles:
        line = dict(color=colour, dash=dash)
        if ob[0] == 0.0:
            shapes.append(dict(type="circle", x0=ob[1] - ob[3], y0=ob[2] - ob[3],
                               x1=ob[1] + ob[3], y1=ob[2] + ob[3], line=line))
        else:
            shapes.append(dict(type="rect", x0=ob[1], y0=ob[2], x1=ob[3], y1=ob[4], line=line))
    return shapes


def robustness_page(items) -> str:
    """``items``: ``(PlannedPath, table, results)`` triples from the CLI. Returns HTML."""
    import html

    import plotly.graph_objects as go

    parts = ["<h1>Stochastic Robustness Analysis</h1>",
             "<p>P(collision): share of Monte Carlo executions whose exact minimum clearance "
             "along the continuous motion is &lt;= 0, with 95 % Clopper-Pearson intervals. "
             "σ: obstacle centre offset per axis.</p>"]
    figures = []

    def add(fig, div_id):
        # plotly.js is embedded once (the first figure): the page works offline.
        parts.append(fig.to_html(full_html=False, include_plotlyjs=not figures,
                                 div_id=div_id))
        figures.append(div_id)
    for n, (pp, table, results) in enumerate(items):
        parts.append(f"<h3>{html.escape(pp.label)}</h3>")
        sig = table["sigma_m"].to_numpy() * 1e3
        p = table["p_collision"].to_numpy()
        fig = go.Figure(go.Scatter(
            x=sig, y=p, mode="lines+markers", name="P(collision)",
            error_y=dict(type="data", symmetric=False,
                         array=table["ci_high"].to_numpy() - p,
                         arrayminus=p - table["ci_low"].to_numpy())))
        fig.update_layout(xaxis_title="σ (mm)", yaxis_title="P(collision)", height=360,
                          template="plotly_white", title="P(collision) vs σ")
        add(fig, f"p-{n}")
        hist = go.Figure()
        for s, res in zip(sig, results):
            hist.add_trace(go.Histogram(x=res.min_clearance_m * 1e3, name=f"σ {s:.3g} mm",
                                        opacity=0.6, nbinsx=60))
        hist.update_layout(barmode="overlay", xaxis_title="minimum clearance (mm)",
                           yaxis_title="trials", height=360, template="plotly_white",
                           title="Minimum clearance of the executed path")
        add(hist, f"h-{n}")
        worst = results[-1]
        a = pp.scenario.arrays()
        arm = go.Figure()
        for q in worst.worst_path_deg:
            for k, pts in enumerate(_arms_points(a, q)):
                line = dict(color="rgba(30,90,200,0.35)")
                if k:  # several arms: the second dashed, ...
                    line["dash"] = ("dash", "dot", "dashdot")[(k - 1) % 3]
                arm.add_trace(go.Scatter(x=pts[:, 0], y=pts[:, 1], mode="lines",
                                         line=line, showlegend=False))
        arm.update_layout(
            shapes=_obstacle_shapes(a.obstacles, "grey", "dot")
            + _obstacle_shapes(worst.worst_obstacles, "crimson", "solid"),
            height=480, template="plotly_white", yaxis=dict(scaleanchor="x"),
            title=f"Worst execution at σ {sig[-1]:.3g} mm (min clearance "
                  f"{worst.min_clearance_m[worst.worst_trial] * 1e3:.3g} mm; dotted: model)")
        add(arm, f"w-{n}")
    return ("<!DOCTYPE html>\n<html lang=\"en\"><head><meta charset=\"utf-8\">"
            "<title>Stochastic Robustness Analysis</title></head><body>\n"
            + "\n".join(parts) + "\n</body></html>\n")
