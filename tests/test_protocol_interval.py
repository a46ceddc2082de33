"""How sure a per-problem ratio to the fastest peer is (``bench/interval.py``).

With a few dozen seeds of runs that last microseconds, a ratio of 0.8x can be a coin toss, so
``evaluate`` gives each ratio a 95 % bootstrap interval and counts a problem surely lost (won)
only when the whole interval lies below (above) 1. The interval must contain the ratio it is
about, be the same whatever else is in the table, and tell a real loss from noise.
"""

from __future__ import annotations

import numpy as np
import pandas as pd
import pytest

from conftest import load_script
from xfuzzy_rrt.bench.interval import median_interval, median_ratio_interval
from xfuzzy_rrt.bench.protocol import problem_table, summary_table


def _runs(times: dict[tuple[str, str], np.ndarray]) -> pd.DataFrame:
    rows = []
    for (scenario, planner), ts in times.items():
        for seed, t in enumerate(ts):
            rows.append({"scenario": scenario, "planner": planner, "seed": seed, "success": True,
                         "iterations": 10, "cost_deg": 100.0, "wall_s": t, "time_total_s": t,
                         "work": 10.0, "work_total": 10.0})
    return pd.DataFrame(rows)


def _noisy(rng, scale, n=50):
    return scale * rng.lognormal(0.0, 0.5, n)


@pytest.fixture(scope="module")
def table():
    rng = np.random.default_rng(7)
    times = {}
    for sc, mine in (("slower", 2.0), ("level", 1.0), ("faster", 0.4)):
        times[(sc, "rrt")] = _noisy(rng, 5.0)
        times[(sc, "rrt:tuned")] = _noisy(rng, 1.0)
        times[(sc, "mine")] = _noisy(rng, mine)
    runs = _runs(times)
    return runs, problem_table(runs, ["rrt", "rrt:tuned", "mine"], ["rrt:tuned"])


def test_the_interval_contains_the_ratio_and_separates_a_real_loss_from_a_toss(table):
    _, problems = table
    mine = problems[problems["planner"] == "mine"].set_index("scenario")
    for sc, row in mine.iterrows():
        assert row["best_peer_ratio_lo"] <= row["best_peer_ratio"] <= row["best_peer_ratio_hi"]
    assert mine.loc["slower", "best_peer_ratio_hi"] < 1.0   # twice as slow: surely lost
    assert mine.loc["faster", "best_peer_ratio_lo"] > 1.0   # 2.5x faster: surely won
    assert mine.loc["level", "best_peer_ratio_lo"] < 1.0 < mine.loc["level", "best_peer_ratio_hi"]


def test_the_summary_counts_only_intervals_wholly_below_or_above_one(table):
    _, problems = table
    row = summary_table(problems).set_index("planner").loc["mine"]
    assert row["problems_surely_lost_best_peer"] == 1
    assert row["problems_surely_won_best_peer"] == 1
    # a level problem may fall on either side of 1; it is never counted as sure
    assert row["problems_lost_best_peer"] >= row["problems_surely_lost_best_peer"]


def test_an_interval_does_not_depend_on_the_other_rows_or_their_order(table):
    runs, problems = table
    alone = runs[runs["scenario"] == "slower"].sample(frac=1.0, random_state=3)
    again = problem_table(alone, ["rrt", "rrt:tuned", "mine"], ["rrt:tuned"])
    a = problems.set_index(["scenario", "planner"]).loc[("slower", "mine")]
    b = again.set_index(["scenario", "planner"]).loc[("slower", "mine")]
    assert (a["best_peer_ratio_lo"], a["best_peer_ratio_hi"]) == \
        (b["best_peer_ratio_lo"], b["best_peer_ratio_hi"])


def test_identical_runs_give_a_point_interval():
    lo, hi = median_ratio_interval([2e-5] * 30, [1e-5] * 30, "k")
    assert lo == hi == pytest.approx(2.0)


def test_a_wider_spread_gives_a_wider_interval():
    rng = np.random.default_rng(1)
    base = rng.lognormal(0.0, 1.0, 40)
    tight = median_ratio_interval(np.full(40, 1.0), 1.0 + 0.01 * base, "k")
    wide = median_ratio_interval(np.full(40, 1.0), base, "k")
    assert wide[1] - wide[0] > 10 * (tight[1] - tight[0])


def test_missing_or_infinite_times_give_no_interval():
    assert all(np.isnan(median_ratio_interval([], [1.0], "k")))
    assert all(np.isnan(median_ratio_interval([1.0, np.inf], [1.0], "k")))
    with pytest.raises(ValueError, match="level"):
        median_ratio_interval([1.0], [1.0], "k", level=1.5)


def test_without_peers_the_interval_columns_are_empty(table):
    runs, _ = table
    problems = problem_table(runs, ["rrt", "rrt:tuned", "mine"])
    assert problems["best_peer_ratio_lo"].isna().all()
    assert problems["best_peer_ratio_hi"].isna().all()


def _noise_floor_script():
    return load_script("scripts/noise_floor.py")


def test_the_noise_floor_compares_a_planners_even_seeds_with_its_odd_ones():
    times = {("a", "mine"): np.array([1.0, 2.0, 1.0, 2.0, 1.0, 2.0]),   # even 1, odd 2
             ("b", "mine"): np.array([3.0, 3.0, 3.0, 3.0])}
    floor = _noise_floor_script().noise_floor(_runs(times), "mine")
    assert floor["problems"] == 2
    assert floor["worst"] == pytest.approx(0.5) and floor["median"] == pytest.approx(0.75)
    assert floor["below_0.9"] == 1 and floor["sure"] == 1


def test_the_noise_floor_script_refuses_a_folder_without_runs_in_one_line(tmp_path, capsys):
    assert _noise_floor_script().main([str(tmp_path)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and str(tmp_path) in err[0] and "runs.csv" in err[0]


def test_a_familys_median_comes_with_its_interval_over_problems(table):
    _, problems = table
    row = summary_table(problems).set_index("planner").loc["mine"]
    assert row["median_best_peer_ratio_lo"] <= row["median_best_peer_ratio"] \
        <= row["median_best_peer_ratio_hi"]
    # three problems this far apart: the median could be any of them
    r = problems[problems["planner"] == "mine"]["best_peer_ratio"]
    assert row["median_best_peer_ratio_lo"] == pytest.approx(r.min())
    assert row["median_best_peer_ratio_hi"] == pytest.approx(r.max())
    assert row["median_cost_peer_ratio_lo"] == row["median_cost_peer_ratio_hi"] == 1.0


def test_the_median_interval_narrows_with_more_problems():
    rng = np.random.default_rng(3)
    few = median_interval(rng.lognormal(0.0, 0.3, 12), "k")
    many = median_interval(rng.lognormal(0.0, 0.3, 480), "k")
    assert many[1] - many[0] < 0.5 * (few[1] - few[0])
    assert all(np.isnan(median_interval([np.nan], "k")))


def test_a_problem_no_peer_ran_on_has_no_interval():
    rng = np.random.default_rng(5)
    runs = _runs({("a", "rrt"): _noisy(rng, 5.0, 10), ("a", "rrt:tuned"): _noisy(rng, 1.0, 10),
                  ("a", "mine"): _noisy(rng, 1.0, 10), ("b", "rrt"): _noisy(rng, 5.0, 10),
                  ("b", "mine"): _noisy(rng, 1.0, 10)})
    problems = problem_table(runs, ["rrt", "rrt:tuned", "mine"], ["rrt:tuned"])
    mine = problems[problems["planner"] == "mine"].set_index("scenario")
    assert np.isfinite(mine.loc["a", "best_peer_ratio_lo"])
    assert np.isnan(mine.loc["b", "best_peer_ratio_lo"])
    assert np.isnan(mine.loc["b", "best_peer_ratio_hi"])
