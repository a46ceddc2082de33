"""The bench report's robustness section: P(collision) per planner as the anatomy moves.

Written when the bench folder holds ``robustness/path_robustness.csv`` (``xfuzzy-rrt
robustness bench DIR`` writes it; ``xfuzzy-rrt report DIR`` then adds this section). Per planner
and obstacle σ it pools the Monte Carlo trials of every example path (one median and one worst
run per scenario): collisions / trials with a 95 % Clopper-Pearson interval, the share of paths
with any collision, and the lowest 1 % quantile of the executed minimum clearance. The per-path
curves, clearance histograms and the worst sampled executions are on
``robustness/robustness.html`` when it was asked for (``--html``), linked from here.
"""

from __future__ import annotations

from pathlib import Path

import pandas as pd

TABLE = Path("robustness") / "path_robustness.csv"
PAGE = Path("robustness") / "robustness.html"
NEEDED = ("planner", "sigma_m", "collisions", "trials", "clearance_q01_m")


def pooled_table(frame: pd.DataFrame) -> pd.DataFrame:
    """Per planner and σ: pooled collisions, trials, P(collision) with its 95 % interval."""
    from xfuzzy_rrt.robustness.montecarlo import clopper_pearson

    missing = [c for c in NEEDED if c not in frame.columns]
    if missing:
        raise ValueError(f"robustness table lacks column(s) {', '.join(missing)}")
    rows = []
    for (planner, sigma), g in frame.groupby(["planner", "sigma_m"], sort=False):
        k, n = int(g["collisions"].sum()), int(g["trials"].sum())
        lo, hi = clopper_pearson(k, n)
        rows.append({"planner": planner, "sigma_m": float(sigma), "paths": len(g),
                     "paths_with_collision": int((g["collisions"] > 0).sum()),
                     "collisions": k, "trials": n, "p_collision": k / n if n else float("nan"),
                     "ci_low": lo, "ci_high": hi,
                     "clearance_q01_min_m": float(g["clearance_q01_m"].min())})
    return pd.DataFrame(rows)


def robustness_html(folder: Path | None, label) -> str:
    """The section's HTML ('' when the folder holds no robustness tables)."""
    from xfuzzy_rrt.report import numbers as N
    from xfuzzy_rrt.report.html import esc, table

    if folder is None or not (Path(folder) / TABLE).is_file():
        return ""
    from xfuzzy_rrt.errors import InputError

    try:
        pooled = pooled_table(pd.read_csv(Path(folder) / TABLE))
    except (ValueError, pd.errors.ParserError) as exc:
        raise InputError(str(Path(folder) / TABLE), str(exc)) from None
    rows = [[label(r.planner), N.metres(r.sigma_m), f"{r.paths_with_collision} of {r.paths}",
             f"{r.p_collision:.4f} [{r.ci_low:.4f}, {r.ci_high:.4f}]",
             f"{r.collisions} of {r.trials}", N.metres(r.clearance_q01_min_m)]
            for r in pooled.itertuples(index=False)]
    header = ["planner", "obstacle σ", "paths that collided", "P(collision) [95 % CI]",
              "colliding trials", "lowest 1 % clearance"]
    link = (f' Per-path curves, clearance histograms and the worst sampled executions: '
            f'<a href="{PAGE.as_posix()}">{esc(PAGE.as_posix())}</a>.'
            if (Path(folder) / PAGE).is_file() else "")
    return ('<p>How the example paths (each scenario\'s median and worst run) hold up when the '
            "obstacles are not where the model says: Monte Carlo over obstacle centre offsets "
            "of standard deviation σ per axis; a trial collides when the exact minimum clearance "
            "along the executed motion is &lt;= 0." + link + "</p>"
            + '<div class="scroll">' + table(rows, header, [str] * len(header)) + "</div>")
