"""Reusable plotly figures for the audit reports: joint space, workspace, run statistics, traces.

Why one module: the bench report, the training report and the trace/explain report all need to
show the same things the same way -- a planner's tree and path over the C-obstacle map, the arm
moving among the obstacles, distributions over runs -- so a reader who learned one report can
read the others. Each function takes the stable objects of the lower layers (``Scenario``,
``PlanResult``, run/trace DataFrames) and returns a ``plotly.graph_objects.Figure``; none of
them writes files or touches a planner's internals.

Several arms (``scenario.arms``): the workspace draws every arm, each from its own slice of the
configuration (``scenario.arm_slices()``), arm 1 solid, arm 2 dashed, arm 3 dotted, arm 4
dash-dotted. The joint-space view plots two angles: for one 2-DOF arm over the C-obstacle map;
otherwise the first two joints of the first arm, without a map, and the title says so.

Conventions: joint angles in degrees, lengths in metres, equal axis scaling in both joint space
and workspace (a 10 degree step looks like 10 degrees on both joints; circles look round), one
colour per planner used everywhere (:data:`PLANNER_COLORS`, Okabe-Ito, colour-blind safe), and
the planner order RRT then Fuzzy-RRT (:func:`planner_order`). Text that ends up in a figure
(titles, legend names, hover labels) is HTML-escaped because plotly renders a subset of HTML.
"""

from __future__ import annotations

import html
import math
from dataclasses import dataclass
from typing import Any, Iterable, Mapping

import numpy as np
import pandas as pd
import plotly.graph_objects as go
from plotly.subplots import make_subplots

from xfuzzy_rrt.geometry.collision import clearance_kernel
from xfuzzy_rrt.geometry.kinematics import joint_points
from xfuzzy_rrt.geometry.scenario import Box, Circle, Scenario
from xfuzzy_rrt.planners.result import OUTCOME_NAMES

#: Known planners in display order, with their labels and colours.
PLANNER_ORDER = ("rrt", "fuzzy-rrt")
PLANNER_LABELS = {"rrt": "RRT", "fuzzy-rrt": "Fuzzy-RRT"}
PLANNER_COLORS = {"rrt": "#0072B2", "fuzzy-rrt": "#D55E00"}
_EXTRA_COLORS = ("#009E73", "#CC79A7", "#E69F00", "#56B4E9", "#000000")

START_COLOR = "#1a9850"
GOAL_COLOR = "#c51b7d"
OBSTACLE_FILL = "#a6a6a6"
OBSTACLE_LINE = "#444444"
C_OBSTACLE_COLOR = "#bdbdbd"
#: Figures are built without a template object: constructing plotly's template for each of a
#: report's ~400 figures took half the time of writing it. The pages attach
#: :data:`PAGE_TEMPLATE` once (:func:`xfuzzy_rrt.report.plotjson.figure_spec`), so the figures
#: look the same.
TEMPLATE = "none"
PAGE_TEMPLATE = "plotly_white"


def plot_text(text: Any) -> str:
    """Escape text for plotly titles/labels (plotly renders a subset of HTML in them)."""
    return html.escape(str(text), quote=False)


def planner_order(names: Iterable[str]) -> list[str]:
    """RRT, then the Fuzzy-RRT planners (one per rulebook), then the others, each group in order
    of appearance."""
    from xfuzzy_rrt.report.overview import planner_order as order

    return order(names)


def planner_label(name: str) -> str:
    """``RRT``, ``Fuzzy-RRT``, ``Fuzzy-RRT general`` (``fuzzy-rrt:general``), ``OMPL RRTConnect``."""
    from xfuzzy_rrt.report.overview import planner_label as label

    return label(name)


#: Fuzzy-RRT rulebooks in warm colours, OMPL planners in the others (Okabe-Ito).
_FUZZY_COLORS = ("#D55E00", "#CC79A7", "#E69F00", "#8C510A")
_OTHER_COLORS = ("#009E73", "#56B4E9", "#000000", "#999933")


#: Fixed colours for the shipped rulebooks and common OMPL planners, so that two planners of one
#: report never share a colour in the usual cases; others by a stable hash.
_NAMED_COLORS = {"fuzzy-rrt:general": "#D55E00", "fuzzy-rrt:paper": "#CC79A7",
                 "fuzzy-rrt:expert": "#E69F00", "ompl:RRTConnect": "#009E73",
                 "ompl:RRT": "#56B4E9", "ompl:BITstar": "#000000", "ompl:RRTstar": "#999933",
                 "rrt:tuned": "#7FA7D9"}


def planner_color(name: str) -> str:
    if name in PLANNER_COLORS:
        return PLANNER_COLORS[name]
    if name in _NAMED_COLORS:
        return _NAMED_COLORS[name]
    import zlib

    pal = _FUZZY_COLORS if name.startswith("fuzzy-rrt") else _OTHER_COLORS
    return pal[zlib.crc32(name.encode("utf-8")) % len(pal)]


def _rgba(hex_color: str, alpha: float) -> str:
    h = hex_color.lstrip("#")
    r, g, b = (int(h[i:i + 2], 16) for i in (0, 2, 4))
    return f"rgba({r}, {g}, {b}, {alpha})"


# ----------------------------------------------------------------------------------------------
# Joint space
# ----------------------------------------------------------------------------------------------

@dataclass(frozen=True)
class CSpaceGrid:
    """Collision flags of a 2-DOF arm on a regular grid over its joint limits.

    ``collision[j, i]`` is True when configuration ``(q1[i], q2[j])`` has clearance <= 0 (rows
    are joint 2, as a heatmap wants them).
    """

    q1_deg: np.ndarray
    q2_deg: np.ndarray
    collision: np.ndarray
    res_deg: float


def _axis(lo: float, hi: float, res: float) -> np.ndarray:
    n = max(1, int(round((hi - lo) / res)))
    return np.linspace(lo, hi, n + 1)


def cspace_grid(scenario: Scenario, res_deg: float = 2.0) -> CSpaceGrid:
    """Evaluate the collision checker on a ``res_deg`` grid (about 33k points at 2 degrees).

    Uses the planners' own ``clearance_kernel``, so the map shows exactly the obstacles the
    planners saw (not a re-implementation). A plain loop over the compiled kernel takes ~50 ms.
    Only for one 2-DOF arm: the map is then the whole joint space.
    """
    if not has_cspace_map(scenario):
        raise ValueError(f"joint-space map needs one 2-DOF arm, got {len(scenario.arms)} arm(s) "
                         f"with {scenario.dof} joints")
    a = scenario.arrays()
    (lo1, hi1), (lo2, hi2) = a.limits_deg
    q1 = _axis(lo1, hi1, res_deg)
    q2 = _axis(lo2, hi2, res_deg)
    flags = np.zeros((q2.size, q1.size), dtype=bool)
    if a.obstacles.shape[0]:
        problem = a.problem(0.0)
        q = np.empty(2, dtype=np.float64)
        for j in range(q2.size):
            q[1] = q2[j]
            for i in range(q1.size):
                q[0] = q1[i]
                flags[j, i] = clearance_kernel(problem, q) <= 0.0
    return CSpaceGrid(q1_deg=q1, q2_deg=q2, collision=flags, res_deg=float(res_deg))


def has_cspace_map(scenario: Scenario) -> bool:
    """True when the joint space is a plane (one 2-DOF arm), so a C-obstacle map exists."""
    return len(scenario.arms) == 1 and scenario.arm.dof == 2


def joint_view_note(scenario: Scenario) -> str:
    """What a joint-space figure of ``scenario`` shows beyond one 2-DOF arm ('' for one)."""
    if has_cspace_map(scenario):
        return ""
    who = "arm 1" if len(scenario.arms) > 1 else "the arm"
    return (f"first two joints of {who} ({scenario.dof} joints in all); no C-obstacle map "
            "beyond one 2-DOF arm")


def tree_edges(nodes_deg: np.ndarray, parent: np.ndarray, cols: tuple[int, int] = (0, 1)):
    """Parent->child segments as ``(x, y)`` arrays separated by NaN (one plotly trace)."""
    nodes = np.asarray(nodes_deg, dtype=np.float64)
    parent = np.asarray(parent)
    child = np.flatnonzero(parent >= 0)
    if child.size == 0:
        return np.empty(0), np.empty(0)
    par = parent[child]
    out = []
    for c in cols:
        seg = np.stack([nodes[par, c], nodes[child, c], np.full(child.size, np.nan)], axis=1)
        out.append(seg.ravel())
    return out[0], out[1]


def _legend_square(name: str, color: str) -> go.Scatter:
    """A legend-only entry (for heatmaps and shapes, which have no legend item of their own)."""
    return go.Scatter(x=[None], y=[None], mode="markers", name=name, hoverinfo="skip",
                      marker=dict(symbol="square", size=12, color=color,
                                  line=dict(color=OBSTACLE_LINE, width=1)))


def run_caption(result) -> str:
    """One line describing a run: seed, iterations, nodes, cost (plain text, unescaped)."""
    cost = "\u2014" if result.cost_deg is None or not math.isfinite(result.cost_deg) \
        else f"{result.cost_deg:.1f}\u00b0"
    return (f"seed {result.seed} \u00b7 {result.iterations} iterations \u00b7 {result.nodes} nodes"
            f" \u00b7 cost {cost}")


def _default_title(scenario: Scenario, result, view: str) -> str:
    """``<scenario> — <view>``, or ``<planner>: <view>`` with the run caption for a result."""
    if result is None:
        return f"{plot_text(scenario.name)} \u2014 {view}"
    return (f"{plot_text(planner_label(result.planner))}: {view}<br>"
            f"<sup>{plot_text(run_caption(result))}</sup>")


def joint_space_figure(scenario: Scenario, result=None, grid: CSpaceGrid | None = None,
                       title: str | None = None, show_tree: bool = True) -> go.Figure:
    """C-obstacle map, the planner's tree (light), its path (bold), start and goal, in degrees.

    ``result`` is a ``PlanResult`` (or ``None`` to draw the scenario alone); ``grid`` may be a
    precomputed :func:`cspace_grid` to share between planners. Beyond one 2-DOF arm (more joints
    or more arms) the map is omitted, the first two joints of the first arm are drawn and the
    title says so (:func:`joint_view_note`).
    """
    fig = go.Figure()
    limits = np.asarray(scenario.arm.joint_limits_deg, dtype=np.float64).reshape(-1, 2)
    if limits.shape[0] < 2:  # a one-link arm: q2 is the next arm's first joint, or nothing
        limits = np.asarray(scenario.joint_limits_deg, dtype=np.float64).reshape(-1, 2)
        if limits.shape[0] < 2:
            limits = np.vstack([limits, limits])
    note = joint_view_note(scenario)
    if has_cspace_map(scenario):
        grid = grid or cspace_grid(scenario)
        if grid.collision.any():
            fig.add_trace(go.Heatmap(
                x=grid.q1_deg, y=grid.q2_deg, z=grid.collision.astype(np.uint8), zmin=0, zmax=1,
                colorscale=[[0.0, "rgba(255,255,255,0)"], [1.0, C_OBSTACLE_COLOR]],
                showscale=False, hoverinfo="skip", name="C-obstacle"))
            fig.add_trace(_legend_square("C-obstacle (collision)", C_OBSTACLE_COLOR))
    color = planner_color(result.planner) if result is not None else "#333333"
    if result is not None and show_tree and np.size(result.tree_parent):
        ex, ey = tree_edges(result.tree_nodes_deg, result.tree_parent)
        fig.add_trace(go.Scatter(x=ex, y=ey, mode="lines", name=f"tree ({result.nodes} nodes)",
                                 line=dict(color=_rgba(color, 0.35), width=1), hoverinfo="skip"))
    if result is not None and np.size(result.path_deg):
        p = np.asarray(result.path_deg, dtype=np.float64)
        if p.shape[1] < 2:
            p = np.hstack([p, np.zeros_like(p)])
        fig.add_trace(go.Scatter(
            x=p[:, 0], y=p[:, 1], mode="lines+markers", name="path",
            line=dict(color=color, width=3.5), marker=dict(size=4, color=color),
            hovertemplate="q1 %{x:.1f}\u00b0<br>q2 %{y:.1f}\u00b0<extra>path</extra>"))
    s, g = tuple(scenario.start_deg) + (0.0,), tuple(scenario.goal_deg) + (0.0,)
    fig.add_trace(go.Scatter(x=[s[0]], y=[s[1]], mode="markers", name="start",
                             marker=dict(symbol="circle", size=13, color=START_COLOR,
                                         line=dict(color="white", width=1.5)),
                             hovertemplate="start (%{x:.1f}\u00b0, %{y:.1f}\u00b0)<extra></extra>"))
    fig.add_trace(go.Scatter(x=[g[0]], y=[g[1]], mode="markers", name="goal",
                             marker=dict(symbol="star", size=16, color=GOAL_COLOR,
                                         line=dict(color="white", width=1)),
                             hovertemplate="goal (%{x:.1f}\u00b0, %{y:.1f}\u00b0)<extra></extra>"))
    if title is None:
        title = _default_title(scenario, result, "joint space")
        if note:
            title += f"<br><sup>{plot_text(note)}</sup>"
    elif note:  # a caller's title: the note goes above the plot
        fig.add_annotation(text=plot_text(note), xref="paper", yref="paper", x=0.0, y=1.0,
                           xanchor="left", yanchor="bottom", showarrow=False,
                           font=dict(size=11, color="#555555"), name="joint-view-note")
    fig.update_layout(
        template=TEMPLATE, title=dict(text=title, x=0.5, xanchor="center"),
        margin=dict(l=55, r=15, t=70, b=50),
        legend=dict(orientation="h", yanchor="top", y=-0.12, x=0.5, xanchor="center"),
        height=560)
    fig.update_xaxes(title_text="q1 (deg)", range=list(limits[0]), dtick=45, zeroline=False,
                     constrain="domain", showline=True, linecolor="#888", mirror=True)
    fig.update_yaxes(title_text="q2 (deg)", range=list(limits[1]), dtick=45, zeroline=False,
                     scaleanchor="x", scaleratio=1, constrain="domain", showline=True,
                     linecolor="#888", mirror=True)
    return fig


# ----------------------------------------------------------------------------------------------
# Workspace
# ----------------------------------------------------------------------------------------------

def interpolate_path(path_deg: np.ndarray, max_step_deg: float = 1.0) -> np.ndarray:
    """Subdivide each joint-space segment so no step exceeds ``max_step_deg``.

    Straight joint-space segments are curves in the workspace; drawing the end effector at
    the nodes only would cut corners through obstacles that the arm actually avoids.
    """
    p = np.asarray(path_deg, dtype=np.float64)
    if p.shape[0] < 2:
        return p.copy()
    pieces = []
    for a, b in zip(p[:-1], p[1:]):
        n = max(1, int(math.ceil(float(np.linalg.norm(b - a)) / max_step_deg)))
        t = np.arange(n, dtype=np.float64)[:, None] / n
        pieces.append(a + t * (b - a))
    pieces.append(p[-1:])
    return np.vstack(pieces)


def _poses_along(dense: np.ndarray, n: int) -> list[np.ndarray]:
    """``n`` configurations evenly spaced by joint-space arc length, endpoints excluded."""
    if n <= 0 or dense.shape[0] < 3:
        return []
    seg = np.sqrt(np.sum(np.diff(dense, axis=0) ** 2, axis=1))
    s = np.concatenate([[0.0], np.cumsum(seg)])
    if s[-1] <= 0.0:
        return []
    targets = s[-1] * np.arange(1, n + 1) / (n + 1)
    idx = np.searchsorted(s, targets)
    return [dense[min(i, dense.shape[0] - 1)] for i in idx]


def _obstacle_shapes(obstacles) -> list[dict]:
    """Circles and boxes as layout shapes, drawn above the grid lines and below the traces."""
    shapes = []
    for o in obstacles:
        common = dict(xref="x", yref="y", fillcolor=OBSTACLE_FILL, layer="between",
                      line=dict(color=OBSTACLE_LINE, width=1))
        if isinstance(o, Circle):
            (cx, cy), r = o.center, o.radius
            shapes.append(dict(type="circle", x0=cx - r, y0=cy - r, x1=cx + r, y1=cy + r,
                               **common))
        elif isinstance(o, Box):
            shapes.append(dict(type="rect", x0=o.min[0], y0=o.min[1], x1=o.max[0], y1=o.max[1],
                               **common))
    return shapes


def workspace_bounds(scenario: Scenario, pad: float = 0.08) -> tuple[list[float], list[float]]:
    """Axis ranges covering every arm's reachable disc and every obstacle, padded by ``pad``."""
    xs, ys = [], []
    for arm in scenario.arms:
        bx, by = arm.base
        r = arm.reach + arm.link_radius
        xs += [bx - r, bx + r]
        ys += [by - r, by + r]
    for o in scenario.obstacles:
        if isinstance(o, Circle):
            xs += [o.center[0] - o.radius, o.center[0] + o.radius]
            ys += [o.center[1] - o.radius, o.center[1] + o.radius]
        elif isinstance(o, Box):
            xs += [o.min[0], o.max[0]]
            ys += [o.min[1], o.max[1]]
    span = max(max(xs) - min(xs), max(ys) - min(ys))
    m = pad * span
    return [min(xs) - m, max(xs) + m], [min(ys) - m, max(ys) + m]


#: Line styles telling the arms apart (arm 1 solid, arm 2 dashed, ...).
ARM_DASHES = ("solid", "dash", "dot", "dashdot")


def arm_label(scenario: Scenario, a: int) -> str:
    """``arm`` for a single arm; else the arm's ``[[arms]] name`` or ``arm 2``."""
    if len(scenario.arms) == 1:
        return "arm"
    names = scenario.arm_names
    return names[a] if a < len(names) and names[a] else f"arm {a + 1}"


def arm_joint_points(scenario: Scenario, q) -> list[np.ndarray]:
    """Each arm's base, joints and tip (``[dof_a + 1, 2]``) for the full configuration ``q``."""
    q = np.asarray(q, dtype=np.float64)
    return [joint_points(arm.links, arm.base, q[sl])
            for arm, sl in zip(scenario.arms, scenario.arm_slices())]


def _arm_traces(scenario: Scenario, q, name: str, color: str, width: float, showlegend: bool,
                group: str, opacity: float = 1.0) -> list[go.Scatter]:
    """One trace per arm for configuration ``q`` (see :func:`_arm_trace`); for several arms the
    names say which arm (``left at start``) and the line style tells them apart."""
    if len(scenario.arms) == 1:
        return [_arm_trace(scenario, q, name, color, width, showlegend, group, opacity)]
    out = []
    q = np.asarray(q, dtype=np.float64)
    for a, sl in enumerate(scenario.arm_slices()):
        label = name.replace("arm", arm_label(scenario, a), 1) if "arm" in name \
            else f"{arm_label(scenario, a)} {name}"
        out.append(_arm_trace(scenario, q, label, color, width, showlegend, group, opacity,
                              arm=a))
    return out


def _arm_trace(scenario: Scenario, q, name: str, color: str, width: float, showlegend: bool,
               group: str, opacity: float = 1.0, arm: int = 0) -> go.Scatter:
    """Arm ``arm`` of ``scenario`` at configuration ``q`` (all arms' angles, or one arm's)."""
    q = np.asarray(q, dtype=np.float64)
    a = scenario.arms[arm]
    if q.shape[0] == scenario.dof and len(scenario.arms) > 1:
        q = q[scenario.arm_slices()[arm]]
    pts = joint_points(a.links, a.base, q)
    label = ", ".join(f"{v:.1f}\u00b0" for v in q)
    line = dict(color=color, width=width)
    if len(scenario.arms) > 1:
        line["dash"] = ARM_DASHES[arm % len(ARM_DASHES)]
    return go.Scatter(x=pts[:, 0], y=pts[:, 1], mode="lines+markers", name=name,
                      legendgroup=group, showlegend=showlegend, opacity=opacity,
                      line=line,
                      marker=dict(size=[9] + [6] * (pts.shape[0] - 1), color=color,
                                  line=dict(color="white", width=1)),
                      hovertemplate=f"{plot_text(name)} q=({label})<br>"
                                    "x %{x:.3f} m, y %{y:.3f} m<extra></extra>")


def workspace_figure(scenario: Scenario, result=None, n_poses: int = 5,
                     title: str | None = None) -> go.Figure:
    """Obstacles, the arm at start, goal and ``n_poses`` intermediate path configurations, and
    the end-effector trace along the (densely interpolated) path; metres, equal scaling.

    ``result`` may be ``None`` (or a failed run with an empty path): then only the scenario is
    drawn (arm at start and goal).
    """
    fig = go.Figure()
    shapes = [dict(type="circle", xref="x", yref="y", x0=arm.base[0] - arm.reach,
                   y0=arm.base[1] - arm.reach, x1=arm.base[0] + arm.reach,
                   y1=arm.base[1] + arm.reach, layer="below",
                   line=dict(color="#999999", width=1, dash="dot")) for arm in scenario.arms]
    shapes += _obstacle_shapes(scenario.obstacles)
    if scenario.obstacles:
        fig.add_trace(_legend_square("obstacle", OBSTACLE_FILL))
    color = planner_color(result.planner) if result is not None else "#333333"
    path = np.asarray(result.path_deg, dtype=np.float64) if result is not None else np.empty((0, 2))
    if path.shape[0] >= 2:
        dense = interpolate_path(path, 1.0)
        for k, q in enumerate(_poses_along(dense, n_poses)):
            fig.add_traces(_arm_traces(scenario, q, "arm along path", color, 4, k == 0, "poses",
                                       opacity=0.35))
        several = len(scenario.arms) > 1
        for a, sl in enumerate(scenario.arm_slices()):
            arm = scenario.arms[a]
            ee = np.array([joint_points(arm.links, arm.base, q[sl])[-1] for q in dense])
            line = dict(color=color, width=2.5)
            name = "end-effector trace"
            if several:
                line["dash"] = ARM_DASHES[a % len(ARM_DASHES)]
                name = f"{arm_label(scenario, a)} end-effector trace"
            fig.add_trace(go.Scatter(x=ee[:, 0], y=ee[:, 1], mode="lines",
                                     name=name, line=line,
                                     hovertemplate="x %{x:.3f} m, y %{y:.3f} m<extra>end effector"
                                                   "</extra>"))
    fig.add_traces(_arm_traces(scenario, scenario.start_deg, "arm at start", START_COLOR, 5, True,
                               "start"))
    fig.add_traces(_arm_traces(scenario, scenario.goal_deg, "arm at goal", GOAL_COLOR, 5, True,
                               "goal"))
    bxs = [arm.base[0] for arm in scenario.arms]
    bys = [arm.base[1] for arm in scenario.arms]
    fig.add_trace(go.Scatter(x=bxs, y=bys, mode="markers", name="base", showlegend=False,
                             marker=dict(symbol="square", size=11, color="#222222"),
                             hovertemplate="base<extra></extra>"))
    if title is None:
        title = _default_title(scenario, result, "workspace")
    xr, yr = workspace_bounds(scenario)
    fig.update_layout(
        template=TEMPLATE, shapes=shapes, title=dict(text=title, x=0.5, xanchor="center"),
        margin=dict(l=55, r=15, t=70, b=50),
        legend=dict(orientation="h", yanchor="top", y=-0.12, x=0.5, xanchor="center"),
        height=560)
    fig.update_xaxes(title_text="x (m)", range=xr, zeroline=False, constrain="domain",
                     showline=True, linecolor="#888", mirror=True)
    fig.update_yaxes(title_text="y (m)", range=yr, zeroline=False, scaleanchor="x",
                     scaleratio=1, constrain="domain", showline=True, linecolor="#888",
                     mirror=True)
    return fig


# ----------------------------------------------------------------------------------------------
# Statistics over runs
# ----------------------------------------------------------------------------------------------

def boxplots(runs: pd.DataFrame, scenarios: Iterable[str] | None = None,
             max_iter: int | None = None) -> go.Figure:
    """Iterations and path cost per planner, one row per scenario (the paper's Fig. 3/4).

    Every run is drawn as a point over its box. Iterations cover all runs (a failure counts as
    the iteration budget, ``max_iter``, and is drawn as an ``x``); cost covers successful runs
    only. Each row has its own y axes because scenarios differ in difficulty.
    """
    names = list(scenarios) if scenarios is not None else list(dict.fromkeys(runs["scenario"]))
    planners = planner_order(runs["planner"])
    titles = []
    for n in names:
        titles += [f"{plot_text(n)}: iterations (all runs)",
                   f"{plot_text(n)}: path cost, deg (successful runs)"]
    fig = make_subplots(rows=max(1, len(names)), cols=2, subplot_titles=titles,
                        horizontal_spacing=0.1,
                        vertical_spacing=min(0.12, 0.5 / max(1, len(names))))
    for r, scen in enumerate(names, start=1):
        sub = runs[runs["scenario"] == scen]
        for p in planners:
            g = sub[sub["planner"] == p]
            if g.empty:
                continue
            color = planner_color(p)
            label = plot_text(planner_label(p))
            ok = g[g["success"].astype(bool)]
            common = dict(name=label, legendgroup=p, marker=dict(color=color, size=5),
                          line=dict(color=color), fillcolor=_rgba(color, 0.25),
                          boxpoints="all", jitter=0.35, pointpos=0, boxmean=False)
            fig.add_trace(go.Box(y=g["iterations"].to_numpy(),
                                 customdata=g["seed"].to_numpy(), showlegend=(r == 1),
                                 hovertemplate="seed %{customdata}<br>%{y} iterations"
                                               "<extra>" + label + "</extra>", **common),
                          row=r, col=1)
            failed = g[~g["success"].astype(bool)]
            if len(failed):
                fig.add_trace(go.Scatter(
                    x=[label] * len(failed), y=failed["iterations"].to_numpy(), mode="markers",
                    name="failed run (counted as max_iter)", legendgroup="failed",
                    showlegend=False, marker=dict(symbol="x", size=9, color="#b2182b"),
                    customdata=failed["seed"].to_numpy(),
                    hovertemplate="FAILED seed %{customdata}<extra></extra>"), row=r, col=1)
            if len(ok):
                fig.add_trace(go.Box(y=ok["cost_deg"].to_numpy(),
                                     customdata=ok["seed"].to_numpy(), showlegend=False,
                                     hovertemplate="seed %{customdata}<br>%{y:.1f}\u00b0"
                                                   "<extra>" + label + "</extra>", **common),
                              row=r, col=2)
        fig.update_yaxes(title_text="iterations", rangemode="tozero", row=r, col=1)
        fig.update_yaxes(title_text="cost (deg)", rangemode="tozero", row=r, col=2)
    title = "Iterations and path cost per planner"
    if max_iter is not None and (~runs["success"].astype(bool)).any():
        title += (f"<br><sup><span style='color:#b2182b'>x</span> = failed run, counted as "
                  f"max_iter = {int(max_iter)}</sup>")
    height = 170 + 330 * max(1, len(names))
    fig.update_layout(template=TEMPLATE, height=height,
                      margin=dict(l=60, r=20, t=120, b=40),
                      title=dict(text=title, x=0.0, xanchor="left", xref="paper",
                                 yref="container", y=1.0 - 12 / height, yanchor="top"),
                      legend=dict(orientation="h", yref="container", y=1.0 - 62 / height,
                                  yanchor="top", x=0.0, xanchor="left"))
    return fig


def outcome_counts(trace: Any) -> pd.Series | None:
    """Counts of the trace's ``outcome`` column by outcome name, or ``None`` when absent.

    Outcomes may be stored as integer codes (``planners.result``) or as names.
    """
    if not isinstance(trace, pd.DataFrame) or "outcome" not in trace.columns or trace.empty:
        return None
    col = trace["outcome"]
    if pd.api.types.is_numeric_dtype(col):
        col = col.map(lambda v: OUTCOME_NAMES.get(int(v), str(v)))
    counts = col.astype(str).value_counts()
    order = [n for n in OUTCOME_NAMES.values() if n in counts.index]
    order += sorted(n for n in counts.index if n not in order)
    return counts.reindex(order)


def outcome_figure(results: Mapping[str, Any], title: str | None = None) -> go.Figure | None:
    """Grouped bars of per-iteration outcomes, one colour per planner; ``None`` when no result
    in ``results`` (planner -> ``PlanResult``) carries a trace with an ``outcome`` column."""
    counted = {p: outcome_counts(getattr(r, "trace", None)) for p, r in results.items()
               if r is not None}
    counted = {p: c for p, c in counted.items() if c is not None}
    if not counted:
        return None
    fig = go.Figure()
    for p in planner_order(counted):
        c = counted[p]
        fig.add_trace(go.Bar(x=list(c.index), y=c.to_numpy(), name=plot_text(planner_label(p)),
                             marker_color=planner_color(p), text=c.to_numpy(),
                             textposition="outside", cliponaxis=False))
    fig.update_layout(template=TEMPLATE, barmode="group", height=380,
                      title=dict(text=title or "Outcome of each iteration (example run)", x=0.0),
                      yaxis_title="iterations", margin=dict(l=55, r=15, t=60, b=50),
                      showlegend=True)
    return fig


def drilldown_figure(scenario: Scenario, result, grid: CSpaceGrid | None = None) -> go.Figure:
    """The joint-space map of a Fuzzy-RRT run for the drill-down: the page's script draws the
    chosen iteration's sampling box (a shape) and moves the last trace -- the node the fuzzy
    systems looked at, the sample, and the new configuration -- onto that iteration."""
    fig = joint_space_figure(scenario, result, grid=grid,
                             title=f"{plot_text(planner_label(result.planner))}: the chosen "
                                   "iteration in joint space<br><sup>dashed box: sampling box; "
                                   "circle: node expanded; x: sample; diamond: new "
                                   "configuration</sup>")
    fig.add_trace(go.Scatter(
        x=[None, None, None], y=[None, None, None], mode="markers+lines", name="this iteration",
        line=dict(color="#000000", width=1, dash="dot"),
        marker=dict(symbol=["circle-open", "x", "diamond"], size=[14, 11, 12],
                    color=["#000000", "#D55E00", "#009E73"], line=dict(width=2)),
        text=["node expanded", "sample", "new configuration"],
        hovertemplate="%{text}: (%{x:.2f}\u00b0, %{y:.2f}\u00b0)<extra></extra>"))
    return fig
