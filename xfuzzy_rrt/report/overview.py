"""The numbers of the report's first screen, computed from ``runs.csv`` alone.

Why here and not in the page code: the verdict sentence is a claim ("needs 1.4× fewer
iterations than RRT on 24 problems; it loses on 7") and must be recomputable by anyone from the
runs table, so it is built from a DataFrame by plain functions the tests call directly.

Conventions (the same as ``summary.csv`` / ``ratios.csv``):

- a planner's *success* is certified success: a path was found **and** passed the certified
  check (``success`` in runs.csv; older folders without that meaning are corrected with their
  ``certified`` column);
- our planners (RRT, Fuzzy-RRT with any rulebook) are compared on loop iterations, the median
  over all runs of a scenario (a failed run counts as ``max_iter``); OMPL planners count other
  things, so they are compared on time to first path (median over the runs that found one);
- a ratio is ``RRT's median / the planner's median`` on the same scenario: above 1 the planner
  is better; "loses" counts scenarios with a ratio below 1;
- **time and work as the measure** (issue 23): when ``runs.csv`` has them, every planner is
  also compared on end-to-end time to the first certified path (``time_total_s``, the whole
  planner call) and on its deterministic end-to-end work count (``work_total``: the search's
  ``work`` plus the certification's ``certify_work``), medians over all runs (a
  failed run counts with what it spent), against the peer at its best -- the tuned RRT
  (``rrt:tuned``) when the benchmark ran it, else RRT. The verdict leads with that
  comparison and names the baseline with its settings; iterations stay the paper's measure,
  against the paper's RRT.
"""

from __future__ import annotations

import numpy as np
import pandas as pd

BASELINE = "rrt"
#: The peer at its best (planners/tuned.py): the time and work baseline when it ran.
TUNED_BASELINE = "rrt:tuned"
TIME_TOTAL = "time_total_s"
WORK = "work_total"  # end to end, like the time: the search plus the certification

PLANNER_COLUMNS = ["planner", "label", "metric", "scenarios", "runs", "success_rate",
                   "found_rate", "ratio_median", "ratio_worst", "ratio_best", "ratio_geomean",
                   "losses", "compared", "time_first_median_s", "cost_median_deg",
                   "min_clearance_m", "paths", "penetrating_paths", "penetration_max_m",
                   "time_baseline", "time_ratio_median", "time_ratio_worst", "time_losses",
                   "time_compared", "work_ratio_median", "work_ratio_worst", "work_losses",
                   "work_compared", "time_total_median_s", "work_median"]


def is_ours(planner: str) -> bool:
    """RRT (paper or tuned) and Fuzzy-RRT (any rulebook) count the same loop iterations."""
    return (planner in ("rrt", TUNED_BASELINE, "fuzzy-rrt") or planner.startswith("fuzzy-rrt:"))


def metric_of(planner: str) -> str:
    """What a planner is compared to RRT on: ``iterations`` or ``time_first_s``."""
    return "iterations" if is_ours(planner) else "time_first_s"


def planner_label(planner: str) -> str:
    """``Fuzzy-RRT `general``` style display names (``ompl:RRTConnect`` -> ``OMPL RRTConnect``)."""
    if planner == "rrt":
        return "RRT"
    if planner == TUNED_BASELINE:
        return "RRT tuned"
    if planner == "fuzzy-rrt":
        return "Fuzzy-RRT"
    if planner.startswith("fuzzy-rrt:"):
        name = planner.split(":", 1)[1].rstrip("/").rsplit("/", 1)[-1]
        return f"Fuzzy-RRT {name}"
    if planner.startswith("ompl:"):
        return f"OMPL {planner.split(':', 1)[1]}"
    return planner


def planner_order(names) -> list[str]:
    """RRT, then Fuzzy-RRT planners, then the others, each group in order of appearance."""
    seen = list(dict.fromkeys(names))
    return ([p for p in seen if p == BASELINE] + [p for p in seen if is_ours(p) and p != BASELINE]
            + [p for p in seen if not is_ours(p)])


def _bool(series: pd.Series) -> pd.Series:
    if series.dtype == bool:
        return series
    return series.map(lambda v: bool(v) if isinstance(v, (bool, np.bool_)) else
                      str(v).strip().lower() == "true")


def found_mask(runs: pd.DataFrame) -> pd.Series:
    """Runs that returned a path (``found``; older tables: ``success``)."""
    return _bool(runs["found"] if "found" in runs.columns else runs["success"])


def success_mask(runs: pd.DataFrame) -> pd.Series:
    """Certified success: found and certified (whatever an older ``success`` column meant)."""
    ok = found_mask(runs) & _bool(runs["success"])
    if "certified" in runs.columns:
        ok = ok & _bool(runs["certified"].astype(object).where(runs["certified"].notna(), False))
    return ok


def scenario_medians(runs: pd.DataFrame) -> pd.DataFrame:
    """Per (scenario, planner): median iterations (all runs), median time to first path (runs
    that found one), and median end-to-end time and work (all runs; NaN without the column)."""
    found = found_mask(runs)
    rows = []
    for (scen, planner), g in runs.groupby(["scenario", "planner"], sort=False):
        tf = (pd.to_numeric(g.loc[found.loc[g.index], "time_first_s"], errors="coerce").dropna()
              if "time_first_s" in g.columns else pd.Series(dtype=float))
        rows.append({"scenario": str(scen), "planner": str(planner),
                     "iterations": float(pd.to_numeric(g["iterations"]).median()),
                     "time_first_s": float(tf.median()) if len(tf) else np.nan,
                     TIME_TOTAL: _all_runs_median(g, TIME_TOTAL),
                     WORK: _all_runs_median(g, WORK)})
    return pd.DataFrame(rows, columns=["scenario", "planner", "iterations", "time_first_s",
                                       TIME_TOTAL, WORK])


def _all_runs_median(g: pd.DataFrame, column: str) -> float:
    """Median over every run (NaN when the column is missing or any run lacks a value: a
    planner that does not count work is not compared on work)."""
    if column not in g.columns:
        return np.nan
    v = pd.to_numeric(g[column], errors="coerce")
    return float(v.median()) if len(v) and v.notna().all() else np.nan


def time_baseline(planners) -> str:
    """The baseline of the time and work comparison: the tuned RRT when it ran, else RRT."""
    return TUNED_BASELINE if TUNED_BASELINE in set(planners) else BASELINE


def baseline_description(planner: str, tuned: dict | None = None) -> str:
    """The baseline named with its settings: ``RRT tuned (step 60°, goal bias 0.1)``.

    ``tuned`` is the benchmark's record of what ``rrt:tuned`` resolved to (``bench.json``
    settings); without it, the shipped tuned file."""
    from xfuzzy_rrt.planners.tuned import rrt_settings_text, tuned_params
    from xfuzzy_rrt.report.numbers import sig

    if planner == TUNED_BASELINE:
        params = (tuned or {}).get(TUNED_BASELINE)
        if params is None:
            params = tuned_params("rrt") or {}

        def one(p):
            return rrt_settings_text(p, "\u00b0", sig)

        if "by_shape" in params:  # tuned per arm shape (planners/tuned.py)
            return "RRT tuned (" + "; ".join(f"{shape}: {one(p)}" for shape, p
                                             in params["by_shape"].items()) + ")"
        return f"RRT tuned ({one(params)})"
    if planner == BASELINE:
        from xfuzzy_rrt.planners.params import default

        return (f"RRT (step {sig(default('rrt', 'step_deg'))}\u00b0, goal bias "
                f"{sig(default('rrt', 'goal_bias'))})")
    return planner_label(planner)


def time_work_ratios(runs: pd.DataFrame, baseline: str | None = None) -> pd.DataFrame:
    """Per (scenario, planner other than ``baseline``, metric in time_total_s/work): the two
    medians and ``ratio = baseline / planner`` (NaN when either is missing)."""
    med = scenario_medians(runs)
    baseline = time_baseline(med["planner"]) if baseline is None else baseline
    base = med[med["planner"] == baseline].set_index("scenario")
    rows = []
    for r in med[med["planner"] != baseline].itertuples(index=False):
        for m in (TIME_TOTAL, WORK):
            mine = float(getattr(r, m))
            ref = float(base.loc[r.scenario, m]) if r.scenario in base.index else np.nan
            ratio = ref / mine if (np.isfinite(ref) and np.isfinite(mine) and mine > 0) else np.nan
            rows.append({"scenario": r.scenario, "planner": r.planner, "metric": m,
                         "baseline_value": ref, "value": mine, "ratio": ratio})
    return pd.DataFrame(rows, columns=["scenario", "planner", "metric", "baseline_value",
                                       "value", "ratio"])


def scenario_ratios(runs: pd.DataFrame, baseline: str = BASELINE) -> pd.DataFrame:
    """One row per (scenario, planner other than the baseline): ``metric``, the two medians and
    ``ratio = baseline / planner`` (NaN when either is missing)."""
    med = scenario_medians(runs)
    base = med[med["planner"] == baseline].set_index("scenario")
    rows = []
    for r in med[med["planner"] != baseline].itertuples(index=False):
        m = metric_of(r.planner)
        mine = getattr(r, m)
        ref = float(base.loc[r.scenario, m]) if r.scenario in base.index else np.nan
        ratio = ref / mine if (np.isfinite(ref) and np.isfinite(mine) and mine > 0) else np.nan
        rows.append({"scenario": r.scenario, "planner": r.planner, "metric": m,
                     "baseline_value": ref, "value": mine, "ratio": ratio})
    return pd.DataFrame(rows, columns=["scenario", "planner", "metric", "baseline_value",
                                       "value", "ratio"])


def planner_table(runs: pd.DataFrame, baseline: str = BASELINE) -> pd.DataFrame:
    """One row per planner: the facts of the first screen (see the module docstring)."""
    ratios = scenario_ratios(runs, baseline)
    tbase = time_baseline(runs["planner"])
    tw = time_work_ratios(runs, tbase)
    med = scenario_medians(runs)
    found = found_mask(runs)
    success = success_mask(runs)
    rows = []
    for p in planner_order(runs["planner"]):
        sel = runs["planner"] == p
        g = runs[sel]
        f = found[sel]
        paths = g[f]
        r = ratios.loc[ratios["planner"] == p, "ratio"].dropna().to_numpy(dtype=float)
        pen = (pd.to_numeric(paths["penetration_m"], errors="coerce").fillna(0.0)
               if "penetration_m" in paths.columns else pd.Series(0.0, index=paths.index))
        uncert = (~_bool(paths["certified"].astype(object).where(paths["certified"].notna(),
                                                                 False))
                  if "certified" in paths.columns else pd.Series(False, index=paths.index))
        clear = (pd.to_numeric(paths["min_clearance_m"], errors="coerce").dropna()
                 if "min_clearance_m" in paths.columns else pd.Series(dtype=float))
        tf = (pd.to_numeric(paths["time_first_s"], errors="coerce").dropna()
              if "time_first_s" in paths.columns else pd.Series(dtype=float))
        cost = pd.to_numeric(g.loc[success[sel], "cost_deg"], errors="coerce").dropna()
        rows.append({
            "planner": p, "label": planner_label(p), "metric": metric_of(p),
            "scenarios": int(g["scenario"].nunique()), "runs": int(len(g)),
            "success_rate": float(success[sel].mean()) if len(g) else np.nan,
            "found_rate": float(f.mean()) if len(g) else np.nan,
            "ratio_median": float(np.median(r)) if r.size else np.nan,
            "ratio_worst": float(r.min()) if r.size else np.nan,
            "ratio_best": float(r.max()) if r.size else np.nan,
            "ratio_geomean": (float(np.exp(np.mean(np.log(r)))) if r.size and np.all(r > 0)
                              else np.nan),
            "losses": int(np.sum(r < 1.0)), "compared": int(r.size),
            "time_first_median_s": float(tf.median()) if len(tf) else np.nan,
            "cost_median_deg": float(cost.median()) if len(cost) else np.nan,
            "min_clearance_m": float(clear.min()) if len(clear) else np.nan,
            "paths": int(len(paths)),
            "penetrating_paths": int(((pen > 0) | uncert).sum()),
            "penetration_max_m": float(pen.max()) if len(pen) and pen.max() > 0 else 0.0,
            "time_baseline": tbase,
            "time_total_median_s": _nan_median(med.loc[med["planner"] == p, TIME_TOTAL]),
            "work_median": _nan_median(med.loc[med["planner"] == p, WORK]),
        })
        for m, key in ((TIME_TOTAL, "time"), (WORK, "work")):
            t = tw.loc[(tw["planner"] == p) & (tw["metric"] == m), "ratio"].dropna()
            t = t.to_numpy(dtype=float)
            rows[-1].update({f"{key}_ratio_median": float(np.median(t)) if t.size else np.nan,
                             f"{key}_ratio_worst": float(t.min()) if t.size else np.nan,
                             f"{key}_losses": int(np.sum(t < 1.0)),
                             f"{key}_compared": int(t.size)})
    return pd.DataFrame(rows, columns=PLANNER_COLUMNS)


def _nan_median(values: pd.Series) -> float:
    v = pd.to_numeric(values, errors="coerce").dropna()
    return float(v.median()) if len(v) else np.nan


def _x(value: float) -> str:
    from xfuzzy_rrt.report.numbers import sig

    return f"{sig(value, 2 if 0.1 <= value < 100 else 3)}\u00d7"


def _time_work_clause(row, problems: str, time_label: str) -> str | None:
    """``X finds its first certified path 1.3× faster than RRT tuned (step 60°, goal bias
    0.1) end to end on 24 problems (median; it loses on 5, worst 0.41×) and needs 1.2× less
    work (median; worst 0.5×)``; ``None`` without end-to-end times."""
    med = pd.to_numeric(row.get("time_ratio_median", np.nan), errors="coerce")
    if not np.isfinite(med):
        return None
    n = int(row["scenarios"])
    compared = int(row["time_compared"])
    on = f"on {problems}" if compared == n else f"on {compared} of {problems}"
    shown = _x(med if med >= 1 else 1 / med)
    if shown == _x(1.0):
        lead = f"{row['label']} finds its first certified path as fast as {time_label}"
    else:
        lead = (f"{row['label']} finds its first certified path {shown} "
                f"{'faster' if med >= 1 else 'slower'} than {time_label}")
    losses = int(row["time_losses"])
    lost = ("it loses on none" if losses == 0 else
            f"it loses on {losses}, worst {_x(row['time_ratio_worst'])}")
    text = f"{lead} end to end {on} (median; {lost})"
    wmed = pd.to_numeric(row.get("work_ratio_median", np.nan), errors="coerce")
    if np.isfinite(wmed):
        wshown = _x(wmed if wmed >= 1 else 1 / wmed)
        what = ("as much end-to-end work" if wshown == _x(1.0) else
                f"{wshown} {'less' if wmed >= 1 else 'more'} end-to-end work")
        text += f" and needs {what} (median; worst {_x(row['work_ratio_worst'])})"
    return text


def verdict(row, baseline_label: str = "RRT", time_label: str | None = None) -> str:
    """The sentence for one planner row of :func:`planner_table` (plain text, no markup).

    ``time_label`` names the time-and-work baseline with its settings
    (:func:`baseline_description`); the clause comparing end-to-end time and work comes first
    when the runs have them."""
    from xfuzzy_rrt.report.numbers import metres, percent, seconds

    n = int(row["scenarios"])
    problems = f"{n} problem{'s' if n != 1 else ''}"
    parts = []
    if time_label is not None and row["planner"] != row.get("time_baseline"):
        clause = _time_work_clause(row, problems, time_label)
        if clause is not None:
            parts.append(clause)
    if row["planner"] == BASELINE:
        parts.append(f"{row['label']} (the baseline) solves {percent(row['success_rate'])} of "
                     f"its runs with a certified path on {problems}; median time to first path "
                     f"{seconds(row['time_first_median_s'])}")
    else:
        med = row["ratio_median"]
        if not np.isfinite(med):
            parts.append(f"{row['label']} cannot be compared with {baseline_label} "
                         "(no scenario where both have a median)")
        else:
            if _x(med if med >= 1 else 1 / med) == _x(1.0):  # "1× fewer" would say nothing
                lead = (f"{row['label']} needs as many iterations as" if row["metric"] ==
                        "iterations" else f"{row['label']} finds its first path as fast as")
            elif row["metric"] == "iterations":
                what = ("fewer iterations than" if med >= 1 else "more iterations than")
                lead = f"{row['label']} needs {_x(med if med >= 1 else 1 / med)} {what}"
            else:
                what = "faster than" if med >= 1 else "slower than"
                lead = f"{row['label']} finds its first path {_x(med if med >= 1 else 1 / med)} {what}"
            compared = int(row["compared"])
            on = (f"on {problems}" if compared == n
                  else f"on {compared} of {problems}")
            parts.append(f"{lead} {baseline_label} {on} (median)")
            losses = int(row["losses"])
            parts.append("it loses on none" if losses == 0 else
                         f"it loses on {losses} (worst {_x(row['ratio_worst'])})")
        if row["success_rate"] < 1:
            parts.append(f"certified success {percent(row['success_rate'])}")
    pen = int(row["penetrating_paths"])
    if row["paths"] == 0:
        parts.append("it returned no path")
    elif pen == 0:
        clear = row["min_clearance_m"]
        parts.append("no path touched an obstacle" + (
            f" (closest {metres(clear)})" if np.isfinite(clear) else ""))
    else:
        parts.append(f"{pen} of {int(row['paths'])} paths penetrated an obstacle (deepest "
                     f"{metres(row['penetration_max_m'])}); they count as failures")
    return "; ".join(parts) + "."


def verdicts(table: pd.DataFrame, tuned: dict | None = None) -> list[str]:
    """One sentence per planner, the baseline's last (it is the reference, not the news).

    ``tuned``: the benchmark's record of the tuned settings (``bench.json`` ``settings.tuned``)
    so that the time baseline is named with the values it ran with."""
    base = table[table["planner"] == BASELINE]
    label = str(base["label"].iloc[0]) if len(base) else planner_label(BASELINE)
    tl = None
    if "time_baseline" in table.columns and len(table):
        tl = baseline_description(str(table["time_baseline"].iloc[0]), tuned)
    others = [verdict(r, label, tl) for _, r in table[table["planner"] != BASELINE].iterrows()]
    return others + [verdict(r, label, tl) for _, r in base.iterrows()]
