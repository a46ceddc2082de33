"""Benchmark tables computed from ``runs.csv`` alone: the per-(scenario, planner) summary and the
per-planner-pair ratio distribution.

Why a module of its own: every number in ``summary.csv`` and ``ratios.csv`` must be
re-derivable from ``runs.csv`` by anyone (the tests do exactly that), so these functions take a
runs DataFrame -- freshly computed or read back from disk -- and nothing else.

Conventions (the paper's, kept for every planner):

- iteration statistics cover *all* runs; a failed run counts as ``max_iter`` iterations (the
  planner reports that), it is never dropped;
- cost statistics cover successful runs only (a failed run has no path);
- ``certified_fraction`` is over successful runs: the share whose returned path passes this
  project's certified edge check (always 1 for our planners; OMPL checks motions by sampling,
  so its paths may graze obstacles);
- a planner pair's *ratio* on one scenario is ``baseline median iterations / planner median
  iterations`` (above 1: the planner needed fewer iterations than the baseline), and the ratio
  table gives its distribution over scenarios -- this is how "2x faster" is judged across many
  problems instead of one.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

BASELINE = "rrt"

SUMMARY_COLUMNS = ["scenario", "planner", "runs", "success_rate", "iterations_min",
                   "iterations_median", "iterations_max", "cost_min", "cost_median", "cost_max",
                   "wall_median_s", "time_first_median_s", "certified_fraction",
                   "penetration_max_m", "iter_ratio_vs_rrt"]
SHORTCUT_COLUMNS = ["cost_short_median"]
RATIO_COLUMNS = ["baseline", "planner", "scenarios", "ratio_median", "ratio_worst",
                 "ratio_best", "ratio_geomean"]


def _bool(series: pd.Series) -> pd.Series:
    """Booleans as read back from CSV (True/False strings or bools; empty = missing)."""
    if series.dtype == bool:
        return series
    return series.map(lambda v: v if isinstance(v, (bool, np.bool_)) else
                      {"true": True, "false": False}.get(str(v).strip().lower(), np.nan))


def _median(values: pd.Series) -> float:
    values = pd.to_numeric(values, errors="coerce").dropna()
    return float(values.median()) if len(values) else float("nan")


def summarise(runs: pd.DataFrame) -> pd.DataFrame:
    """One row per (scenario, planner), in order of first appearance in ``runs``."""
    rows = []
    success = _bool(runs["success"]).astype(bool)
    shortcut = "cost_short_deg" in runs.columns
    for (scen, planner), g in runs.groupby(["scenario", "planner"], sort=False):
        ok_mask = success.loc[g.index]
        ok = g[ok_mask]
        row = {
            "scenario": scen, "planner": planner, "runs": len(g),
            "success_rate": float(ok_mask.mean()),
            "iterations_min": int(g["iterations"].min()),
            "iterations_median": float(g["iterations"].median()),
            "iterations_max": int(g["iterations"].max()),
            "cost_min": float(ok["cost_deg"].min()) if len(ok) else np.nan,
            "cost_median": float(ok["cost_deg"].median()) if len(ok) else np.nan,
            "cost_max": float(ok["cost_deg"].max()) if len(ok) else np.nan,
            "wall_median_s": float(g["wall_s"].median()),
            "time_first_median_s": (_median(ok["time_first_s"])
                                    if "time_first_s" in g.columns else np.nan),
            "certified_fraction": np.nan,
            "penetration_max_m": np.nan,
        }
        if "certified" in g.columns and len(ok):
            cert = _bool(ok["certified"])
            row["certified_fraction"] = float(cert.astype(bool).mean())
        if "penetration_m" in g.columns and len(ok):
            pen = pd.to_numeric(ok["penetration_m"], errors="coerce").dropna()
            row["penetration_max_m"] = float(pen.max()) if len(pen) else np.nan
        if shortcut:
            row["cost_short_median"] = _median(ok["cost_short_deg"])
        rows.append(row)
    columns = SUMMARY_COLUMNS + (SHORTCUT_COLUMNS if shortcut else [])
    frame = pd.DataFrame(rows, columns=columns)
    frame["iter_ratio_vs_rrt"] = scenario_ratios(frame)
    return frame


def scenario_ratios(summary: pd.DataFrame, baseline: str = BASELINE) -> pd.Series:
    """Per summary row: baseline median iterations / this planner's (NaN without a baseline)."""
    base = summary[summary["planner"] == baseline].set_index("scenario")["iterations_median"]
    ref = summary["scenario"].map(base).astype(float)
    mine = summary["iterations_median"].astype(float)
    return pd.Series(np.where(mine > 0, ref / mine.where(mine > 0, np.nan), np.nan),
                     index=summary.index, dtype=float)


def ratio_table(summary: pd.DataFrame, baseline: str = BASELINE) -> pd.DataFrame:
    """Per planner other than ``baseline``: the distribution over scenarios of its per-scenario
    median-iteration ratio (``worst`` = smallest ratio, ``best`` = largest)."""
    ratios = summary.assign(_r=scenario_ratios(summary, baseline))
    rows = []
    for planner, g in ratios[ratios["planner"] != baseline].groupby("planner", sort=False):
        r = g["_r"].dropna().to_numpy(dtype=float)
        if r.size == 0:
            continue
        rows.append({"baseline": baseline, "planner": planner, "scenarios": int(r.size),
                     "ratio_median": float(np.median(r)), "ratio_worst": float(r.min()),
                     "ratio_best": float(r.max()),
                     "ratio_geomean": float(np.exp(np.mean(np.log(r)))) if np.all(r > 0)
                     else float("nan")})
    return pd.DataFrame(rows, columns=RATIO_COLUMNS)
