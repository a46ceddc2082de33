"""goal-frame's step reaches 360 degrees at 2 joints; files written with its first range (0-120)
still load, and the N-joint goal-frame and goal-frame-any semantics keep 120."""

from __future__ import annotations

import math

import numpy as np
import pytest

from conftest import FIXTURES
from exact_geometry import Oracle
from xfuzzy_rrt.errors import RulebookError
from xfuzzy_rrt.fuzzy import semantics
from xfuzzy_rrt.fuzzy.fll import export_fll, import_fll
from xfuzzy_rrt.fuzzy.rulebook import Rulebook, load_rulebook, save_rulebook
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt
from xfuzzy_rrt.training.genome import decode, encode

GF = semantics.GOAL_FRAME


def _rulebook(step: float, sem=GF) -> Rulebook:
    """Constant outputs: goal bias 0.2, uniform share 0.1, a box 200 ahead, 20 behind, 60 across."""
    knots = np.array([[sem.default_knots(n) for n in sem.inputs]] * 6)
    consts = np.array([[v] * 625 for v in (0.2, 0.1, 200.0, 20.0, 60.0, step)])
    return Rulebook.from_arrays(knots, consts, name="steps", bounds_mode=None, semantics=sem,
                                provenance={"kind": "test"})


def test_the_two_joint_step_range_is_360_and_the_others_keep_120():
    assert GF.output_ranges["step_deg"] == (0.0, 360.0)
    assert semantics.get("goal-frame", 5).output_ranges["step_deg"] == (0.0, 120.0)
    assert semantics.GOAL_FRAME_ANY.output_ranges["step_deg"] == (0.0, 120.0)
    for name in ("goal-frame-5dof", "goal-frame-dual3", "goal-frame-any"):
        assert load_rulebook(f"rulebooks/{name}").semantics.output_ranges["step_deg"] == (0.0, 120.0)


def _segments(r) -> np.ndarray:
    return np.hypot(*np.diff(r.path_deg, axis=0).T)


@pytest.mark.parametrize("seed", range(3))
def test_a_step_above_120_joins_the_goal_from_further_than_120(seed):
    # start and goal 240 degrees apart in an empty workspace: a step of 300 joins the goal
    # from any node, one of 100 needs at least three moves
    scenario = load_scenario(FIXTURES / "scenarios" / "empty.toml")
    long = plan_fuzzy_rrt(scenario, _rulebook(300.0), seed=seed, trace=True)
    short = plan_fuzzy_rrt(scenario, _rulebook(100.0), seed=seed)
    assert long.success and short.success
    assert long.iterations == 1 and (long.trace.step_used_deg == 300.0).all()
    assert _segments(long).max() > 120.0 and _segments(long).max() <= 300.0
    assert _segments(short).max() <= 100.0 + 1e-9 and len(short.path_deg) >= 4


@pytest.mark.parametrize("seed", range(5))
def test_long_steps_between_obstacles_pass_the_exact_oracle(seed):
    file = FIXTURES / "scenarios" / "two-circles.toml"
    r = plan_fuzzy_rrt(load_scenario(file), _rulebook(360.0), seed=seed)
    assert r.success and Oracle(file).path_problems(r.path_deg) == []


def test_a_file_with_the_earlier_step_range_loads_and_is_written_back_with_today_s(tmp_path):
    rb = _rulebook(100.0)
    root = save_rulebook(rb, tmp_path / "rb")
    step = root / "step_deg.fis"
    text = step.read_text()
    assert "output step_deg range 0.0 360.0" in text
    step.write_text(text.replace("output step_deg range 0.0 360.0", "output step_deg range 0.0 120.0"))
    back = load_rulebook(root)
    assert np.array_equal(back.arrays()[1], rb.arrays()[1])
    again = save_rulebook(back, tmp_path / "again")
    assert "output step_deg range 0.0 360.0" in (again / "step_deg.fis").read_text()


def test_a_constant_outside_the_range_its_file_declares_is_one_clear_problem(tmp_path):
    root = save_rulebook(_rulebook(150.0), tmp_path / "rb")
    step = root / "step_deg.fis"
    step.write_text(step.read_text().replace("output step_deg range 0.0 360.0",
                                             "output step_deg range 0.0 120.0"))
    with pytest.raises(RulebookError, match=r"consequent 150\.0 outside the output range "
                                            r"\[0\.0, 120\.0\] of step_deg"):
        load_rulebook(root)


def test_any_other_step_range_is_still_refused(tmp_path):
    root = save_rulebook(_rulebook(100.0), tmp_path / "rb")
    step = root / "step_deg.fis"
    step.write_text(step.read_text().replace("output step_deg range 0.0 360.0",
                                             "output step_deg range 0.0 240.0"))
    with pytest.raises(RulebookError, match=r"range of step_deg must be 0\.0 360\.0"):
        load_rulebook(root)


def _declare_old_fll_step_range(fll_dir) -> None:
    """Make ``step_deg.fll``'s output variable declare the earlier range 0 120."""
    step = fll_dir / "step_deg.fll"
    head, out = step.read_text().split("OutputVariable:")
    assert "range: 0 360" in out
    step.write_text(head + "OutputVariable:" + out.replace("range: 0 360", "range: 0 120", 1))


def test_the_earlier_range_is_read_from_fuzzylite_too(tmp_path):
    rb = _rulebook(90.0)
    export_fll(rb, tmp_path / "fll")
    _declare_old_fll_step_range(tmp_path / "fll")
    back = import_fll(tmp_path / "fll")
    assert np.array_equal(back.arrays()[1], rb.arrays()[1])


def test_the_genome_spans_360_so_a_training_can_reach_it():
    rb = _rulebook(300.0)
    knots, consts = rb.arrays()
    genome = encode(knots, consts, "goal-frame")
    _, back = decode(genome, "goal-frame")
    assert math.isclose(back[0, 5, 0], 300.0, rel_tol=1e-12)


def test_a_fuzzylite_constant_outside_its_declared_earlier_range_is_refused(tmp_path):
    export_fll(_rulebook(150.0), tmp_path / "fll")
    _declare_old_fll_step_range(tmp_path / "fll")
    with pytest.raises(RulebookError, match=r"constant 150(\.0+)? outside the output range "
                                            r"\[0\.0, 120\.0\]"):
        import_fll(tmp_path / "fll")
