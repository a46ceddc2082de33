"""Quick, indicative N-DOF and two-arm comparison of Fuzzy-RRT-Connect with its DOF-free default
rulebook against per-DOF Fuzzy-RRT and RRT (60 deg, bias 0.1) (issue 25; README numbers).

Problems::

    xfuzzy-rrt scenarios generate --dof 5 --count 8 --seed 9600 --out /tmp/cnd/d5
    xfuzzy-rrt scenarios generate --dof 3 --arms 2 --count 8 --seed 9600 --out /tmp/cnd/dual3

Usage: ``python benchmarks/connect_ndof_quick.py /tmp/cnd [SEEDS]``. Per planner: the median
over problems of the per-problem median iterations (failures count as 10^9), extensions and
planning-loop time (``wall_s``, failures infinite), certified success, and the median/worst
per-problem ratio of each planner's iterations and loop time to Fuzzy-RRT-Connect's. Iterations
and success are deterministic; times are one run on a loaded machine: indicative only.
"""

from __future__ import annotations

import sys
from pathlib import Path

import numpy as np

from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebooks_dir
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.api import plan_scenario

FAMILIES = (("d5", "goal-frame-5dof"), ("dual3", "goal-frame-dual3"))


def main(root: Path, seeds: int) -> None:
    anyb = load_rulebook(rulebooks_dir() / "goal-frame-any")
    for sub, book in FAMILIES:
        per_dof = load_rulebook(rulebooks_dir() / book)
        planners = (("fuzzy-rrt-connect", "fuzzy-rrt-connect", {"rulebook": anyb}),
                    (f"fuzzy-rrt:{book}", "fuzzy-rrt", {"rulebook": per_dof}),
                    ("rrt-60-0.1", "rrt", {"step_deg": 60.0, "goal_bias": 0.1}))
        rows: dict[str, list[tuple[float, float, float, float]]] = {}
        for f in sorted((root / sub).glob("*.toml")):
            s = load_scenario(f)
            for label, planner, kw in planners:
                plan_scenario(s, planner, seed=10_000, max_iter=5, **kw)  # compile/load first
                rs = [plan_scenario(s, planner, seed=k, **kw) for k in range(seeds)]
                rows.setdefault(label, []).append((
                    float(np.median([r.iterations if r.success else 1e9 for r in rs])),
                    float(np.median([r.params.get("extensions", r.iterations) for r in rs])),
                    float(np.median([r.wall_s if r.success else np.inf for r in rs])),
                    float(np.mean([r.success for r in rs]))))
        ref = np.array(rows["fuzzy-rrt-connect"])
        print(f"{sub} ({len(ref)} problems x {seeds} seeds)")
        for label, v in rows.items():
            a = np.array(v)
            it, ext, t, ok = a.T
            print(f"  {label:26s} iterations {np.median(it):8.1f} extensions {np.median(ext):8.1f} "
                  f"loop {np.median(t) * 1e3:7.2f} ms success {ok.mean():.3f} | ratio to connect: "
                  f"iterations median {np.median(it / ref[:, 0]):.2f}x worst {np.min(it / ref[:, 0]):.2f}x, "
                  f"loop time median {np.median(t / ref[:, 2]):.2f}x worst {np.min(t / ref[:, 2]):.2f}x")


if __name__ == "__main__":
    main(Path(sys.argv[1]), int(sys.argv[2]) if len(sys.argv) > 2 else 10)
