"""The fair protocol against the fastest tuned peer per problem (issue 25's measure).

A user does not care which peer is fastest on a problem, only how long the fastest one takes:
``evaluate`` compares each planner with the fastest of the peers (``rrt:tuned`` and every
``--peer``) problem by problem, and says where its certified success falls below a peer's. The
numbers must follow from the runs table the protocol writes beside them.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from conftest import FIXTURES, load_script, run_main
from xfuzzy_rrt.bench.protocol import problem_table, run_protocol, summary_table
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
from xfuzzy_rrt.geometry.scenario import load_scenario

SCENARIOS = [FIXTURES / "scenarios" / "two-circles.toml",
             FIXTURES / "scenarios" / "boxes-and-circle.toml"]
PEERS = ["rrt:tuned", "fuzzy-rrt-connect"]


@pytest.fixture(scope="module")
def result():
    scenarios = [load_scenario(p) for p in SCENARIOS]
    default = load_rulebook(FIXTURES.parents[1] / "rulebooks" / "goal-frame")
    entries = [("rrt:tuned", "rrt:tuned", None), ("fuzzy-rrt:goal-frame", "fuzzy-rrt", default),
               ("fuzzy-rrt-connect", "fuzzy-rrt-connect", None)]
    return run_protocol(scenarios, entries, runs=5, max_iter=3000, caches="warm", peers=PEERS)


def test_each_problem_names_its_fastest_peer_and_the_ratio_to_it(result):
    runs, problems = result.runs, result.problems
    med = runs.groupby(["scenario", "planner"])["time_total_s"].median().unstack()
    ours = problems[problems["planner"] == "fuzzy-rrt:goal-frame"].set_index("scenario")
    for scenario, row in ours.iterrows():
        best = med.loc[scenario, PEERS]
        assert row["best_peer"] == best.idxmin()
        assert row["best_peer_ratio"] == pytest.approx(best.min() / med.loc[scenario,
                                                                          "fuzzy-rrt:goal-frame"])
    # the paper's RRT (10 deg) is never a peer
    assert set(problems["best_peer"]) <= set(PEERS)


def test_the_summary_is_the_median_geomean_worst_and_losses_of_those_ratios(result):
    problems, summary = result.problems, result.summary.set_index("planner")
    r = problems[problems["planner"] == "fuzzy-rrt:goal-frame"]["best_peer_ratio"].to_numpy()
    row = summary.loc["fuzzy-rrt:goal-frame"]
    assert row["median_best_peer_ratio"] == pytest.approx(np.median(r))
    assert row["geomean_best_peer_ratio"] == pytest.approx(np.exp(np.log(r).mean()))
    assert row["worst_best_peer_ratio"] == pytest.approx(r.min())
    assert row["problems_lost_best_peer"] == int((r < 1).sum())
    counts = problems.drop_duplicates("scenario")["best_peer"].value_counts()
    assert row["best_peers"] == ", ".join(f"{k} {v}" for k, v in counts.items())


def test_success_below_a_peer_is_counted_per_problem():
    runs = pd.DataFrame({
        "scenario": ["a"] * 6 + ["b"] * 6,
        "planner": ["rrt", "rrt", "rrt:tuned", "rrt:tuned", "mine", "mine"] * 2,
        "seed": [0, 1] * 6,
        "success": [True, True, True, True, True, False, True, True, True, False, True, True],
        "iterations": [10] * 12, "cost_deg": [100.0] * 12, "wall_s": [1e-4] * 12,
        "time_total_s": [3e-4, 3e-4, 2e-4, 2e-4, 1e-4, 1e-3, 3e-4, 3e-4, 2e-4, 4e-4, 1e-4, 1e-4],
        "work": [10.0] * 12, "work_total": [10.0] * 12})
    problems = problem_table(runs, ["rrt", "rrt:tuned", "mine"], ["rrt:tuned"])
    mine = problems[problems["planner"] == "mine"].set_index("scenario")
    assert bool(mine.loc["a", "success_below_peer"]) and not mine.loc["b", "success_below_peer"]
    # a failed run counts with the time it spent: median of 1e-4 and 1e-3
    assert mine.loc["a", "best_peer_ratio"] == pytest.approx(2e-4 / 5.5e-4)
    assert mine.loc["b", "best_peer_ratio"] == pytest.approx(3e-4 / 1e-4)
    summary = summary_table(problems).set_index("planner")
    assert summary.loc["mine", "problems_success_below_peer"] == 1
    assert summary.loc["mine", "problems_lost_best_peer"] == 1


def test_without_peers_named_the_fuzzy_planners_are_not_peers(result):
    scenarios = [load_scenario(SCENARIOS[0])]
    entries = [("rrt:tuned", "rrt:tuned", None), ("fuzzy-rrt-connect", "fuzzy-rrt-connect", None)]
    plain = run_protocol(scenarios, entries, runs=2, max_iter=3000, caches="warm")
    assert set(plain.problems["best_peer"]) == {"rrt:tuned"}


def test_evaluate_prints_the_fastest_peer_table_from_its_own_summary(tmp_path):
    proc = run_main("evaluate", *SCENARIOS, "--peer", "fuzzy-rrt-connect", "--runs", "3",
                    "--caches", "warm", "--out", tmp_path / "out")
    assert proc.returncode == 0, proc.stderr
    assert "Against the fastest of rrt:tuned, fuzzy-rrt-connect on each problem" in proc.stdout
    summary = pd.read_csv(tmp_path / "out" / "summary.csv").set_index("planner")
    row = summary.loc["fuzzy-rrt:goal-frame"]
    line = next(ln for ln in proc.stdout.splitlines() if ln.startswith("fuzzy-rrt:goal-frame")
                and "/2" in ln)
    assert f"{row['median_best_peer_ratio']:.3g}x" in line
    assert f"{row['problems_lost_best_peer']}/2" in line
    # the median's interval over problems, as the summary has it, and the sure counts' columns
    assert (f"[{row['median_best_peer_ratio_lo']:.3g}-{row['median_best_peer_ratio_hi']:.3g}]"
            in line)
    header = next(ln for ln in proc.stdout.splitlines() if ln.startswith("planner")
                  and "surely lost" in ln)
    assert "surely won" in header


def test_the_best_peer_script_refuses_a_folder_without_runs_in_one_line(tmp_path, capsys):
    module = load_script("scripts/best_peer.py")
    assert module.main(str(tmp_path)) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(tmp_path) in err[0] and "runs.csv" in err[0]
