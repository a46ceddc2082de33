"""Training an N-DOF rulebook: the genome's size and validity, the GA's operators and the
checkpoint at N joints, the DOF a training run takes from its scenarios, and the 2-DOF
fingerprints that must not move. (Planning N-DOF problems waits for the planner core; nothing
here plans.)"""

from __future__ import annotations

from types import SimpleNamespace

import numpy as np
import pytest

from xfuzzy_rrt.errors import InputError
from xfuzzy_rrt.fuzzy import semantics as S
from xfuzzy_rrt.fuzzy.rulebook import Rulebook, load_rulebook, rulebooks_dir
from xfuzzy_rrt.training.ga import GAConfig, breed, initial_population, seed_genomes
from xfuzzy_rrt.training.genome import (
    N_GENES,
    constant_genome,
    constant_outputs_genome,
    decode,
    encode,
    n_genes,
)


def test_genome_size_grows_with_the_papers_bound_outputs():
    assert n_genes() == n_genes("relative", 2) == N_GENES == 3822
    assert n_genes("absolute", 5) == 12 * 637 == 7644
    assert n_genes("relative", 7) == 16 * 637
    assert n_genes("goal-frame", 5) == 6 * 637  # the goal-frame outputs do not depend on N
    assert GAConfig(scenarios=(("a", "b"),), dof=5).n_genes == 7644


@pytest.mark.parametrize("mode,dof", [("relative", 5), ("absolute", 3), ("goal-frame", 5)])
def test_any_ndof_genome_decodes_to_a_valid_rulebook_and_back(mode, dof):
    sem = S.get("goal-frame" if mode == "goal-frame" else "paper", dof)
    rng = np.random.default_rng(dof)
    genes = rng.random((3, n_genes(mode, dof)))
    genes[0, :40] = 0.0  # the edges of the box decode too
    genes[1, :40] = 1.0
    knots, consts = decode(genes, mode, dof)
    assert knots.shape == (3, len(sem.outputs), 4, 5) and consts.shape == (3, len(sem.outputs), 625)
    for k in range(3):
        rb = Rulebook.from_arrays(knots[k], consts[k], name="g", semantics=sem,
                                  bounds_mode=None if mode == "goal-frame" else mode)
        assert rb.dof == dof
        np.testing.assert_allclose(encode(knots[k], consts[k], mode, dof), genes[k], atol=1e-9)
    if mode == "goal-frame":
        assert knots[0, 0, 0, 4] == 180.0 * np.sqrt(2 * dof)  # joint_dist_to_goal's range
    with pytest.raises(ValueError, match=f"has {n_genes(mode, dof)} genes"):
        decode(genes[:, :-637], mode, dof)


def test_the_two_dof_genome_is_unchanged():
    genes = np.random.default_rng(0).random((2, N_GENES))
    a = decode(genes, "relative")
    b = decode(genes, "relative", 2)
    for x, y in zip(a, b):
        np.testing.assert_array_equal(x, y)
    assert constant_genome(0.05, (-180, 180, -180, 180), 10.0).shape == (N_GENES,)


def test_constant_genomes_at_n_joints_hold_one_value_per_output():
    g = constant_genome(0.2, (-30.0, 30.0) * 5, 10.0)
    knots, consts = decode(g, "relative", 5)
    assert consts.shape == (1, 12, 625)
    np.testing.assert_allclose(consts[0, :, 0], [0.2, *(-30.0, 30.0) * 5, 10.0], atol=1e-9)
    with pytest.raises(ValueError, match="6 output values needed"):
        constant_outputs_genome((0.1, 0.2), "goal-frame", 4)


@pytest.mark.parametrize("bounds,dof", [("relative", 5), ("goal-frame", 4)])
def test_a_seeded_ndof_population_and_its_children_have_the_ndof_genome(bounds, dof):
    config = GAConfig(population=12, bounds=bounds, scenarios=(("a", "b"),), dof=dof, elite=2)
    pop = initial_population(config, np.random.default_rng(0))
    assert pop.shape == (12, n_genes(bounds, dof))
    assert np.all((pop >= 0) & (pop <= 1))
    names = [n for n, _ in seed_genomes(bounds, dof=dof)]
    assert names[0] in ("rrt-equivalent", "goal-frame-0")
    children = breed(pop, np.arange(12.0), config, np.random.default_rng(1))
    assert children.shape == pop.shape
    for g in children[:3]:
        decode(g, bounds, dof)  # always valid


def test_a_seed_rulebook_of_another_dof_is_refused():
    expert = load_rulebook(rulebooks_dir() / "expert")
    with pytest.raises(ValueError, match="seed rulebook 'expert' is for dof 2, the training for dof 5"):
        seed_genomes("relative", [expert], dof=5)


def test_dof_enters_the_fingerprint_only_when_not_two():
    base = GAConfig(scenarios=(("a", "b"),))
    assert GAConfig(scenarios=(("a", "b"),), dof=2).fingerprint() == base.fingerprint()
    five = GAConfig(scenarios=(("a", "b"),), dof=5)
    assert five.fingerprint() != base.fingerprint()
    with pytest.raises(InputError, match="dof must be an integer from 2 to 7"):
        GAConfig(scenarios=(("a", "b"),), dof=9)


def test_a_two_dof_fingerprint_is_the_one_of_before():
    """Pinned: a 2-DOF run's fingerprint (hence its checkpoints) must not move with this
    feature. The values were computed by the code before ``dof`` existed."""
    c = GAConfig(population=12, bounds="relative", scenarios=(("a", "b"),))
    assert c.fingerprint() == "d4efa299ec03e7aeca932ecb9ba5110483713e98851c3949524b9fa4681a8b78"
    g = GAConfig(population=12, bounds="goal-frame", scenarios=(("a", "b"),),
                 fitness="log-ratio", baseline=(10.0,))
    assert g.fingerprint() == "8b48658764dc03ee8fce0c5e2a717d516fd7e30b8ec3c6b2a244606e82b8f1fd"


def test_an_ndof_checkpoint_saves_and_resumes(tmp_path):
    from xfuzzy_rrt.training.checkpoint import load_checkpoint, save_checkpoint
    from xfuzzy_rrt.training.ga import new_state

    config = GAConfig(population=6, bounds="absolute", scenarios=(("a", "b"),), dof=5, elite=1)
    state = new_state(config)
    save_checkpoint(tmp_path, state, config)
    back = load_checkpoint(tmp_path, config)
    np.testing.assert_array_equal(back.population, state.population)
    with pytest.raises(InputError, match="different training run"):
        load_checkpoint(tmp_path, GAConfig(population=6, bounds="absolute",
                                           scenarios=(("a", "b"),), elite=1))


def test_the_canonical_command_records_an_ndof_training():
    from xfuzzy_rrt.training.run import canonical_command

    c5 = GAConfig(scenarios=(("a", "b"),), dof=5)
    assert "--dof 5" in canonical_command(c5, ["s.toml"], "out")
    assert "--dof" not in canonical_command(GAConfig(scenarios=(("a", "b"),)), ["s.toml"], "out")


# ---------------------------------------------------------------- the DOF of the scenarios


def _scenario(name, *arm_dofs):
    arms = tuple(SimpleNamespace(dof=d) for d in arm_dofs)
    return SimpleNamespace(name=name, source=f"{name}.toml", arms=arms, dof=sum(arm_dofs))


def test_the_training_dof_is_that_of_the_scenarios():
    from xfuzzy_rrt.training.run import training_dof

    assert training_dof([_scenario("a", 2), _scenario("b", 2)], "relative") == 2
    assert training_dof([_scenario("a", 5)], "absolute") == 5
    assert training_dof([_scenario("a", 5)], "absolute", 5) == 5
    # two arms: per arm for the paper's semantics, all together for goal-frame
    assert training_dof([_scenario("duo", 3, 3)], "relative") == 3
    assert training_dof([_scenario("duo", 3, 3)], "goal-frame") == 6
    assert training_dof([_scenario("duo", 2, 3)], "goal-frame") == 5


def test_mixed_or_contradicted_dof_is_one_line():
    from xfuzzy_rrt.training.run import training_dof

    with pytest.raises(InputError) as exc:
        training_dof([_scenario("a", 2), _scenario("b", 5)], "relative")
    assert str(exc.value) == ("--scenario: training scenarios of different DOF (joints per arm): "
                              "a.toml has 2; b.toml has 5; train one DOF at a time")
    with pytest.raises(InputError) as exc:
        training_dof([_scenario("a", 5)], "relative", 3)
    assert str(exc.value) == "--dof: 3 disagrees with the training scenarios (a.toml has 5 joints per arm)"
    with pytest.raises(InputError, match="arms have 2, 3 joints"):
        training_dof([_scenario("duo", 2, 3)], "relative")
    with pytest.raises(InputError, match="--dof: dof must be an integer from 2 to 7"):
        training_dof([_scenario("a", 2)], "relative", 8)
    with pytest.raises(InputError, match="no rulebook for this arm"):
        training_dof([_scenario("big", 4, 4)], "goal-frame")  # 8 joints in all


def test_train_refuses_a_dof_that_disagrees_before_any_output(tmp_path, run_cli):
    from conftest import FIXTURES

    proc = run_cli("train", "--scenario", FIXTURES / "scenarios" / "two-circles.toml",
                   "--dof", "5", "--out", tmp_path / "rb")
    assert proc.returncode == 2
    assert proc.stderr == ("error: --dof: 5 disagrees with the training scenarios ("
                           f"{FIXTURES / 'scenarios' / 'two-circles.toml'} has 2 joints per arm)\n")
    assert not (tmp_path / "rb").exists()


def test_the_default_seed_rulebook_at_n_joints():
    from xfuzzy_rrt.training.run import default_seed_rulebook, resolve_seed_rulebooks

    assert default_seed_rulebook(2) == "expert" and default_seed_rulebook(5) == "expert-5dof"
    seeds = resolve_seed_rulebooks(None, "seeded", "relative", 3)  # none shipped: built-ins
    assert seeds == [] or all(s.rulebook.dof == 3 for s in seeds)
    with pytest.raises(InputError, match="seed rulebook is for dof 2, the training for dof 5"):
        resolve_seed_rulebooks([rulebooks_dir() / "expert"], "seeded", "relative", 5)
