"""``rules simplify``: fewest 'any' rules, exactness, budgeted lossy steps, measures."""

from __future__ import annotations

import numpy as np
import pytest

from xfuzzy_rrt.analysis.interpretability import adjacent_jaccard, measures
from xfuzzy_rrt.analysis.simplify import parse_budget, quantise, simplify
from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy.cover import min_partition, pattern_cells
from xfuzzy_rrt.fuzzy.engine import evaluate
from xfuzzy_rrt.fuzzy.manifest import thaw
from xfuzzy_rrt.fuzzy.membership import partition as memberships
from xfuzzy_rrt.fuzzy.rulebook import Rulebook, load_rulebook, save_rulebook
from xfuzzy_rrt.fuzzy.variables import N_RULES, OUTPUTS, rule_terms
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.api import plan_scenario

from _rulebook_helpers import EXPERT, random_arrays, random_inputs
from conftest import PROJECT, run_main


@pytest.fixture
def run_cli():
    """The CLI through ``main(argv)`` in this process (``conftest.run_main``): these tests
    check what commands print, return and write, not the process; ~1.5 s less a call."""
    return run_main


DEMO = PROJECT / "xfuzzy_rrt" / "data" / "scenarios" / "demo-tissue.toml"
T = np.array([rule_terms(r) for r in range(N_RULES)])


def _check_partition(p, values):
    covered = np.zeros(N_RULES, dtype=int)
    for pat, v in p.rules:
        c = pattern_cells(pat)
        covered[c] += 1
        assert (values[c] == v).all()
    assert (covered == 1).all()
    assert np.array_equal(p.values, values)


def test_min_partition_finds_the_obvious_optima():
    assert len(min_partition(np.full(N_RULES, 0.5))) == 1
    one_input = T[:, 2] * 0.1  # depends on angle_to_obstacle only: 5 rules
    p = min_partition(one_input)
    assert len(p) == 5 and p.optimal
    _check_partition(p, one_input)
    two = T[:, 1] * 10.0 + T[:, 3]  # 25 distinct values on two inputs: 25 rules
    assert len(min_partition(two)) == 25
    odd = one_input.copy()
    odd[123] = 7.0  # cell (0, 4, 4, 3) differs from its angle_to_obstacle=south block
    p = min_partition(odd)
    _check_partition(p, odd)
    # 4 untouched blocks + the exception + the rest of its 5x5x5 block: (any, t1<4, any) x4,
    # (any, 4, t3!=3) x4, (t0>0, 4, 3) x4 -> 4 + 1 + 12 = 17
    assert p.optimal and len(p) == 17


def test_min_partition_is_optimal_against_brute_force_on_a_small_case():
    """Values that depend on inputs 0 and 1 only, laid out so one 'any' choice dominates."""
    v = np.where(T[:, 0] == 0, 1.0, 2.0)
    v[(T[:, 0] == 1) & (T[:, 1] == 1)] = 3.0
    p = min_partition(v)
    _check_partition(p, v)
    # optimum: 1 (t0=0, rest any) + for t0 in 1: t1 in 0..4 (5 rules) + t0 in 2..4 (3 rules) = 9
    assert len(p) == 9


def test_lossless_simplify_evaluates_identically_on_100000_inputs(tmp_path):
    rng = np.random.default_rng(11)
    knots, _ = random_arrays(rng)
    consts = np.empty((len(OUTPUTS), N_RULES))
    for f in range(len(OUTPUTS)):
        levels = rng.uniform(0, 1, 6)
        consts[f] = levels[(T[:, f % 4] + T[:, (f + 1) % 4]) % 6]
        consts[f, rng.choice(N_RULES, 20, replace=False)] = rng.uniform(0, 1, 20)
        if f in (1, 2, 3, 4):
            consts[f] = consts[f] * 360 - 180
        if f == 5:
            consts[f] *= 10
    rb = Rulebook.from_arrays(knots, consts, name="t", bounds_mode="absolute")
    res = simplify(rb)
    assert res.lossless and res.chosen.rules < len(OUTPUTS) * N_RULES
    save_rulebook(res.rulebook, tmp_path / "s", compact=True)
    back = load_rulebook(tmp_path / "s")
    X = random_inputs(rng, 100_000, margin=0.25)  # includes out-of-range inputs
    ya = evaluate(*rb.arrays(), X)
    yb = evaluate(*back.arrays(), X)
    assert np.max(np.abs(ya - yb)) == 0.0
    prov = thaw(back.provenance)
    assert prov["source_sha256"] == rb.sha256 and prov["lossless"] is True


def test_lossy_steps_require_a_budget():
    rb = load_rulebook(EXPERT)
    with pytest.raises(InputError, match="budget"):
        simplify(rb, levels=4)
    with pytest.raises(InputError, match="--budget"):
        parse_budget("iterations*2")


def test_quantise_uses_at_most_k_levels_within_range():
    v = np.random.default_rng(0).uniform(-180, 180, N_RULES)
    q = quantise(v, 4, -180.0, 180.0)
    assert len(np.unique(q)) <= 4
    assert q.min() >= -180 and q.max() <= 180
    assert np.max(np.abs(q - v)) < 90


def test_budgeted_simplify_claimed_loss_is_remeasured_and_holds_and_rechecked_on_fresh_seeds(tmp_path):
    rb = load_rulebook(EXPERT)
    scen = load_scenario(DEMO)
    res = simplify(rb, budget="iterations+10%", scenarios=[scen], seeds=4, max_iter=2000,
                   absorb="dead")
    assert not res.lossless, "the expert rulebook has dead cells on the demo: absorbing them pays"
    assert res.chosen.rules < res.lossless_rules
    save_rulebook(res.rulebook, tmp_path / "s", compact=True)
    back = load_rulebook(tmp_path / "s")
    base = [plan_scenario(scen, "fuzzy-rrt", rulebook=rb, seed=s, max_iter=2000).iterations
            for s in range(4)]
    new = [plan_scenario(scen, "fuzzy-rrt", rulebook=back, seed=s, max_iter=2000).iterations
           for s in range(4)]
    measured = (np.mean(new) - np.mean(base)) / np.mean(base)
    assert measured == pytest.approx(res.loss, abs=1e-12)
    assert measured <= 0.10 + 1e-12
    prov = thaw(back.provenance)
    assert prov["measured_loss"] == pytest.approx(measured, abs=1e-12)
    assert prov["source_sha256"] == rb.sha256 and prov["budget"] == "iterations+10%"
    # the search chose on seeds 0..3: the loss is measured again on seeds it never ran
    assert res.holdout_seeds == (4, 7)
    base_h = [plan_scenario(scen, "fuzzy-rrt", rulebook=rb, seed=s, max_iter=2000).iterations
              for s in range(4, 8)]
    new_h = [plan_scenario(scen, "fuzzy-rrt", rulebook=back, seed=s, max_iter=2000).iterations
             for s in range(4, 8)]
    fresh = (np.mean(new_h) - np.mean(base_h)) / np.mean(base_h)
    assert res.holdout_loss == pytest.approx(fresh, abs=1e-12)
    assert res.holdout_within_budget == (fresh <= 0.10 + 1e-9)
    assert prov["holdout_loss"] == pytest.approx(fresh, abs=1e-12)
    assert prov["holdout_seeds"] == "4..7"


def test_adjacent_jaccard_matches_numeric_integration():
    peaks = (0.0, 0.1, 0.35, 0.4, 0.6)
    x = np.linspace(0, 0.6, 600_001)
    m = memberships(x, np.asarray(peaks)).T  # the project's membership functions, (5, n)
    dx = x[1] - x[0]
    numeric = [np.trapezoid(np.minimum(m[j], m[j + 1]), dx=dx)
               / np.trapezoid(np.maximum(m[j], m[j + 1]), dx=dx) for j in range(4)]
    assert adjacent_jaccard(peaks) == pytest.approx(numeric, rel=1e-4)
    assert adjacent_jaccard((0, 1, 2, 3, 4)) == pytest.approx([0.2, 1 / 7, 1 / 7, 0.2])


def test_measures_count_rules_and_antecedent_length():
    rb = load_rulebook(EXPERT)
    full = measures(rb, compact=False).set_index("output")
    comp = measures(rb, compact=True).set_index("output")
    assert (full.loc[list(OUTPUTS), "rules"] == N_RULES).all()
    assert comp.loc["step_size", "rules"] == 1 and comp.loc["step_size", "mean_antecedent_length"] == 0
    for f, out in enumerate(OUTPUTS):
        assert comp.loc[out, "rules"] == len(min_partition(rb.systems[f].consts))
        assert comp.loc[out, "distinct_constants"] == len(set(rb.systems[f].consts))


def test_simplify_cli_writes_a_compact_rulebook_that_diff_calls_identical(run_cli, tmp_path):
    proc = run_cli("rules", "simplify", EXPERT, "--out", tmp_path / "s")
    assert proc.returncode == 0, proc.stderr
    assert "lossless" in proc.stdout and "interpretability" in proc.stdout
    text = (tmp_path / "s" / "goal_bias.fis").read_text()
    assert "is any" in text and text.count(" then ") < N_RULES
    prov = thaw(load_rulebook(tmp_path / "s").provenance)
    assert prov["command"].startswith("xfuzzy-rrt rules simplify ")
    assert prov["source_sha256"] == load_rulebook(EXPERT).sha256
    proc = run_cli("rules", "diff", EXPERT, tmp_path / "s")
    assert proc.returncode == 0, proc.stdout + proc.stderr
    assert "identical" in proc.stdout
    proc = run_cli("rules", "simplify", EXPERT, "--out", tmp_path / "x", "--levels", "3")
    assert proc.returncode == 2 and proc.stderr.startswith("error: --budget:")
    assert not (tmp_path / "x").exists()


def test_measure_runs_gives_up_once_the_budget_is_certainly_exceeded():
    from xfuzzy_rrt.analysis.simplify import measure_runs

    rb = load_rulebook(EXPERT)
    scen = load_scenario(DEMO)
    full = measure_runs(rb, [scen], 3, max_iter=500)
    total = int(full["iterations"].sum())
    assert measure_runs(rb, [scen], 3, max_iter=500, stop_above=total - 1) is None
    again = measure_runs(rb, [scen], 3, max_iter=500, stop_above=total)
    assert again is not None and again.equals(full)
