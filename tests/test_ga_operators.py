"""The GA's own breeding operators equal pymoo's, bit for bit, draw for draw.

``xfuzzy_rrt.training.operators`` replaced pymoo's ``TournamentSelection``/``SBX``/``PM`` for
speed; every shipped rulebook's provenance command must still rebuild the same populations.
The oracle below is the breeding code as it was, driving pymoo itself.
"""

from __future__ import annotations

import numpy as np
import pytest

from xfuzzy_rrt.training.ga import GAConfig, breed, term_blocks
from xfuzzy_rrt.training.genome import GENES_PER_FIS, MF_GENES
from xfuzzy_rrt.training.operators import polynomial_mutation, sbx, tournament


def _compare_max(pop, P, random_state=None, **kwargs):
    F = pop.get("F")[:, 0]
    S = np.empty(P.shape[0], dtype=int)
    for i, row in enumerate(P):
        best = row[0]
        for j in row[1:]:
            if F[j] < F[best] or (F[j] == F[best] and j < best):
                best = j
        S[i] = best
    return S


def _pymoo_offspring(pop, fit, config, rng):
    """Selection, crossover and mutation exactly as ``breed`` ran them through pymoo 0.6.2."""
    from pymoo.core.population import Population
    from pymoo.core.problem import Problem
    from pymoo.operators.crossover.sbx import SBX
    from pymoo.operators.mutation.pm import PM
    from pymoo.operators.selection.tournament import TournamentSelection

    n, n_var = pop.shape
    problem = Problem(n_var=n_var, xl=np.zeros(n_var), xu=np.ones(n_var))
    n_children = n - config.elite
    P = Population.new(X=pop, F=-fit[:, None])
    selection = TournamentSelection(func_comp=_compare_max, pressure=config.tournament)
    n_matings = (n_children + 1) // 2
    parents = selection.do(problem, P, n_matings, 2, to_pop=False, random_state=rng)
    crossover = SBX(prob=config.crossover_prob, eta=config.crossover_eta, prob_var=0.5)
    off = crossover.do(problem, P, parents, random_state=rng)
    mutation = PM(prob=1.0, prob_var=config.mutation_rate, eta=config.mutation_eta)
    off = mutation.do(problem, off, random_state=rng)
    return parents, off.get("X")


def _ours(pop, fit, config, rng):
    n_matings = (pop.shape[0] - config.elite + 1) // 2
    parents = tournament(fit, n_matings, config.tournament, rng)
    off = sbx(pop[parents[:, 0]], pop[parents[:, 1]], config.crossover_prob,
              config.crossover_eta, rng)
    return parents, polynomial_mutation(off, config.mutation_rate, config.mutation_eta, rng)


def _population(seed, n, n_var):
    rng = np.random.default_rng(seed)
    pop = rng.random((n, n_var)) ** 1.5  # off the 2**-53 grid of raw draws, like bred genes
    # genes on the bounds, equal genes (not crossed) and genes within 1e-14 of each other
    pop[rng.random((n, n_var)) < 0.05] = 0.0
    pop[rng.random((n, n_var)) < 0.05] = 1.0
    pop[1::2, : n_var // 4] = pop[0:-1:2, : n_var // 4]
    pop[3, 5] = pop[2, 5] + 5e-15
    fit = np.round(rng.normal(size=n) * 50) - 100.0 * (rng.random(n) < 0.3)  # many ties
    return pop, fit


_ONE = (("paper-reference", "-"),)
CONFIGS = [
    GAConfig(scenarios=_ONE),
    GAConfig(scenarios=_ONE, tournament=2, crossover_prob=1.0, mutation_rate=0.2,
             mutation_eta=5.0),
    GAConfig(scenarios=_ONE, elite=3, crossover_prob=0.5, crossover_eta=3.0, mutation_rate=0.0),
    GAConfig(scenarios=_ONE, elite=0, tournament=5, crossover_prob=0.0, mutation_rate=1.0),
]


@pytest.mark.parametrize("config", CONFIGS, ids=range(len(CONFIGS)))
@pytest.mark.parametrize("seed", [0, 1, 2])
def test_operators_match_pymoo_bit_for_bit_and_leave_the_generator_in_the_same_state(config,
                                                                                      seed):
    pop, fit = _population(seed, 41 if seed == 2 else 40, 97)
    rng_a, rng_b = np.random.default_rng(seed + 10), np.random.default_rng(seed + 10)
    parents_a, off_a = _pymoo_offspring(pop, fit, config, rng_a)
    parents_b, off_b = _ours(pop, fit, config, rng_b)
    assert np.array_equal(parents_a, parents_b)
    assert off_a.shape == off_b.shape
    assert off_a.tobytes() == off_b.tobytes()  # -0.0 and NaN included
    assert rng_a.bit_generator.state == rng_b.bit_generator.state


def test_breed_at_paper_scale_equals_the_pymoo_breeding():
    """400 individuals x 3,822 genes, the trainer's defaults: the whole next generation,
    term-block mutation (ours in both) and the final clip included."""
    config = GAConfig(scenarios=_ONE)
    pop, fit = _population(7, 400, 3822)
    rng_a, rng_b = np.random.default_rng(3), np.random.default_rng(3)
    _, off = _pymoo_offspring(pop, fit, config, rng_a)
    n_children = 400 - config.elite
    children = off[:n_children].copy()
    hit = np.flatnonzero(rng_a.random(n_children) < config.block_rate)
    fis = rng_a.integers(6, size=hit.size)
    children.reshape(n_children, 6, GENES_PER_FIS)[hit, fis, MF_GENES:] += term_blocks(
        rng_a, config.block_sigma, hit.size)
    order = np.lexsort((np.arange(400), -fit))
    expected = np.vstack([pop[order[: config.elite]], np.clip(children, 0.0, 1.0)])
    got = breed(pop, fit, config, rng_b)
    assert got.tobytes() == expected.tobytes()
    assert rng_a.bit_generator.state == rng_b.bit_generator.state


def test_tournament_refuses_a_non_finite_fitness():
    with pytest.raises(ValueError, match="finite"):
        tournament(np.array([1.0, np.nan, 2.0]), 2, 2, np.random.default_rng(0))


def test_tournament_picks_the_best_of_each_draw_and_the_lower_index_on_ties():
    fit = np.array([5.0, 5.0, 1.0, 9.0])
    rng = np.random.default_rng(0)
    parents = tournament(fit, 50, 4, rng)  # pressure 4 = the whole population each time
    assert np.all(parents == 3)
    fit = np.array([5.0, 5.0, 1.0, 1.0])
    assert np.all(tournament(fit, 50, 4, rng) == 0)
