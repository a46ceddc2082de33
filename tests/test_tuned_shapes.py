"""A peer tuned per arm shape: ``rrt:tuned`` and ``ompl:NAME`` run every problem with the
settings tuned for its shape, or the nearest shape's (planners/tuned.py, "Per arm shape").

Why: RRT's 2-joint settings needed 1.2-4.3x the work of each shape's best at 3-7 joints and
with two to four arms (thirty-first session, training problems), so a peer tuned on 2-joint
problems only was a handicapped peer wherever the default plans other arms.
"""

from __future__ import annotations

import tomllib
from pathlib import Path

import pytest

from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners import tuned
from xfuzzy_rrt.planners.api import TunedRRT, load_tuned_rrt, plan_scenario

HERE = Path(__file__).parent
TWO_JOINT = HERE / "fixtures" / "scenarios" / "two-circles.toml"
FIVE_JOINT = HERE / "fixtures" / "arms" / "five-dof.toml"
DUAL_3 = HERE / "fixtures" / "arms" / "dual-3dof.toml"


def _write(folder: Path, name: str, step: float, bias: float) -> None:
    (folder / name).write_text(f"[params]\nstep_deg = {step}\ngoal_bias = {bias}\n")


@pytest.fixture
def tuned_folder(monkeypatch, tmp_path):
    monkeypatch.setattr(tuned, "tuned_dir", lambda: tmp_path)
    _write(tmp_path, "rrt.toml", 45.0, 0.2)
    _write(tmp_path, "rrt.1-arm-5-joints.toml", 480.0, 0.1)
    _write(tmp_path, "rrt.2-arms-6-joints.toml", 360.0, 0.0)
    return tmp_path


def test_a_shape_names_its_file_and_one_two_joint_arm_keeps_the_plain_name():
    assert tuned.tuned_file_name("rrt") == "rrt.toml"
    assert tuned.tuned_file_name("rrt", (1, 5)) == "rrt.1-arm-5-joints.toml"
    assert tuned.tuned_file_name("ompl:RRTConnect", (2, 6)) == \
        "ompl-RRTConnect.2-arms-6-joints.toml"
    assert tuned.shape_of(load_scenario(DUAL_3)) == (2, 6)
    assert tuned.shape_of(load_scenario(FIVE_JOINT)) == (1, 5)
    assert tuned.shape_of(load_scenario(TWO_JOINT)) == (1, 2)
    assert tuned.arm_shape(3, 2) == (2, 6) and tuned.arm_shape(5) == (1, 5)


def test_the_nearest_shape_keeps_the_number_of_arms_then_the_closest_joints_fewer_on_a_tie():
    have = [(1, 2), (1, 5), (1, 7), (2, 6)]
    assert tuned.nearest_shape((1, 5), have) == (1, 5)
    assert tuned.nearest_shape((1, 6), have) == (1, 5)  # a tie between 5 and 7: fewer
    assert tuned.nearest_shape((1, 3), have) == (1, 2)
    assert tuned.nearest_shape((2, 4), have) == (2, 6)  # the only two-arm shape
    assert tuned.nearest_shape((3, 6), have) == (2, 6)  # no three-arm shape: closest joints
    assert tuned.nearest_shape((3, 9), [(1, 2), (2, 6)]) == (2, 6)
    assert tuned.nearest_shape((1, 3), []) is None


def test_the_tuned_files_of_a_folder_are_listed_by_shape(tuned_folder):
    (tuned_folder / "rrt-other.toml").write_text("")  # another label's file
    (tuned_folder / "rrt.toml.bak").write_text("")
    assert tuned.tuned_shapes("rrt") == ((1, 2), (1, 5), (2, 6))
    assert tuned.tuned_by_shape("rrt")[(1, 5)] == {"step_deg": 480.0, "goal_bias": 0.1}
    assert tuned.tuned_params("rrt", (1, 6)) == {"step_deg": 480.0, "goal_bias": 0.1}
    _write(tuned_folder, "rrt.1-arm-6-joints.toml", 300.0, 0.05)  # a new file is seen
    assert tuned.tuned_params("rrt", (1, 6)) == {"step_deg": 300.0, "goal_bias": 0.05}


@pytest.mark.parametrize("fixture, step, bias, shape", [
    (TWO_JOINT, 45.0, 0.2, "1 arm, 2 joints"),
    (FIVE_JOINT, 480.0, 0.1, "1 arm, 5 joints"),
    (DUAL_3, 360.0, 0.0, "2 arms, 6 joints"),
])
def test_the_tuned_rrt_plans_each_problem_with_its_shapes_settings(tuned_folder, fixture, step,
                                                                    bias, shape):
    sc = load_scenario(fixture)
    alone = plan_scenario(sc, "rrt:tuned", seed=3, max_iter=4000)
    assert alone.params["step_deg"] == step and alone.params["goal_bias"] == bias
    assert alone.params["tuned"] is True and alone.params["tuned_shape"] == shape
    read_once = plan_scenario(sc, "rrt:tuned", rulebook=load_tuned_rrt(), seed=3, max_iter=4000)
    same = plan_scenario(sc, "rrt", step_deg=step, goal_bias=bias, seed=3, max_iter=4000)
    for r in (read_once, same):
        assert (r.success, r.iterations, r.work) == (alone.success, alone.iterations, alone.work)
        assert r.path_deg.tobytes() == alone.path_deg.tobytes()
    assert read_once.params["tuned_shape"] == shape


def test_a_shape_without_a_file_runs_with_the_nearest_shapes_settings(tuned_folder):
    (tuned_folder / "rrt.1-arm-5-joints.toml").unlink()
    r = plan_scenario(load_scenario(FIVE_JOINT), "rrt:tuned", seed=1, max_iter=2000)
    assert r.params["step_deg"] == 45.0 and r.params["tuned_shape"] == "1 arm, 2 joints"


def test_a_callers_own_tuned_settings_apply_to_every_shape(tuned_folder):
    r = plan_scenario(load_scenario(FIVE_JOINT), "rrt:tuned", rulebook=TunedRRT(90.0, 0.3),
                      seed=1, max_iter=2000)
    assert r.params["step_deg"] == 90.0 and "tuned_shape" not in r.params


def test_a_broken_shape_file_is_one_error_naming_it(tuned_folder, capsys):
    from xfuzzy_rrt.cli.main import main

    (tuned_folder / "rrt.1-arm-5-joints.toml").write_text("[params]\nstep_deg = 'x'\n")
    out = tuned_folder / "r.json"
    code = main(["plan", str(FIVE_JOINT), "--planner", "rrt:tuned", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and not out.exists()
    assert len(err) == 1 and "rrt.1-arm-5-joints.toml" in err[0], err


@pytest.mark.parametrize("name", ["rrt.not-a-shape.toml", "rrt.1-arms-5-joints.toml",
                                  "rrt.1-arm-2-joints.toml", "rrt.0-arms-4-joints.toml"])
def test_a_file_named_like_no_shape_is_one_error_naming_it(tuned_folder, capsys, name):
    """Passed over in silence, its shape would run the nearest shape's settings while the user
    believes it runs the file's."""
    from xfuzzy_rrt.cli.main import main

    _write(tuned_folder, name, 90.0, 0.1)
    out = tuned_folder / "r.json"
    code = main(["plan", str(FIVE_JOINT), "--planner", "rrt:tuned", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and not out.exists()
    assert len(err) == 1 and name in err[0] and "not a tuned file name" in err[0], err


def test_a_file_tuned_for_another_shape_than_its_name_is_refused(tuned_folder, capsys):
    from xfuzzy_rrt.cli.main import main

    (tuned_folder / "rrt.1-arm-5-joints.toml").write_text(
        "[params]\nstep_deg = 480.0\ngoal_bias = 0.1\n"
        "[provenance]\narms = 2\njoints_per_arm = 3\n")
    out = tuned_folder / "r.json"
    code = main(["plan", str(FIVE_JOINT), "--planner", "rrt:tuned", "--out", str(out)])
    err = capsys.readouterr().err.strip().splitlines()
    assert code == 2 and not out.exists()
    assert len(err) == 1 and "rrt.1-arm-5-joints.toml" in err[0], err
    assert "tuned for 2 arms, 6 joints" in err[0] and "rrt.2-arms-6-joints.toml" in err[0]


def test_the_ompl_range_is_tuned_per_shape(monkeypatch, tmp_path):
    from xfuzzy_rrt.planners.ompl_bridge import load_tuned_range, parse_ompl_label, resolve_range

    monkeypatch.setattr(tuned, "tuned_dir", lambda: tmp_path)
    (tmp_path / "ompl-RRTConnect.toml").write_text("[params]\nrange_deg = 240.0\n")
    (tmp_path / "ompl-RRTConnect.1-arm-5-joints.toml").write_text("[params]\nrange_deg = 120.0\n")
    spec = parse_ompl_label("ompl:RRTConnect", "--planner")
    loaded = load_tuned_range("ompl:RRTConnect")
    assert resolve_range(spec, tuned=loaded) == (240.0, "tuned")
    assert resolve_range(spec, tuned=loaded, shape=(1, 5)) == (120.0, "tuned for 1 arm, 5 joints")
    assert resolve_range(spec, shape=(1, 7)) == (120.0, "tuned for 1 arm, 5 joints")
    # no two-arm file: the closest number of joints (5 is one away from 4, 2 is two)
    assert resolve_range(spec, shape=(2, 4)) == (120.0, "tuned for 1 arm, 5 joints")
    assert resolve_range(spec, shape=(1, 3)) == (240.0, "tuned")


def test_the_evaluate_header_names_each_tuned_shapes_settings(tuned_folder, tmp_path):
    from conftest import run_main

    problems = tmp_path / "p"
    problems.mkdir()
    for f in (TWO_JOINT, FIVE_JOINT):
        (problems / f.name).write_text(f.read_text())
    proc = run_main("evaluate", problems, "--runs", "2", "--max-iter", "2000", "--caches",
                    "warm")
    assert proc.returncode == 0, proc.stderr
    assert ("rrt:tuned (1 arm, 2 joints: step 45 deg, goal bias 0.2; 1 arm, 5 joints: step 480 "
            "deg, goal bias 0.1)") in proc.stdout


def test_tuning_a_shape_generates_that_shape_and_names_it_in_the_command():
    from xfuzzy_rrt.bench.tuning import render_tuned_file, run_tuning

    result = run_tuning("rrt", problems=1, seed=8150, runs=2, grid={"step_deg": (60.0, 480.0),
                        "goal_bias": (0.1,)}, max_iter=2000, dof=3, arms=2)
    data = tomllib.loads(render_tuned_file(result))
    assert data["provenance"]["command"] == (
        "xfuzzy-rrt tune rrt --problems 1 --seed 8150 --runs 2 --dof 3 --arms 2 --max-iter 2000 "
        "--grid 'step_deg=60,480;goal_bias=0.1'")
    assert data["provenance"]["shape"] == "2 arms, 6 joints"
    assert data["provenance"]["families"] == ["nd"]
    assert result.settings["scenarios"] == ["tune-2x3-8150-000"]


@pytest.mark.parametrize("args, message", [
    (["--dof", "9"], "error: --dof: must be 2 to 7 joints per arm, got 9"),
    (["--arms", "0"], "error: --arms: must be 1 to 4, got 0"),
    (["--dof", "3", "--family", "hard"], "error: --family: families exist for one 2-joint arm"),
])
def test_tune_refuses_a_bad_shape_with_one_line(tmp_path, args, message):
    from conftest import run_main

    out = tmp_path / "t.toml"
    proc = run_main("tune", "rrt", "--problems", "1", "--runs", "1", *args, "--out", out)
    lines = proc.stderr.strip().splitlines()
    assert proc.returncode == 2 and not out.exists()
    assert len(lines) == 1 and lines[0].startswith(message), proc.stderr


def test_every_shipped_tuned_file_is_named_for_the_shape_it_was_tuned_on():
    folder = Path(tuned.__file__).resolve().parent.parent / "data" / "tuned"
    for label in ("rrt", "ompl:RRTConnect"):
        for shape in tuned.tuned_shapes(label):
            data = tomllib.loads((folder / tuned.tuned_file_name(label, shape)).read_text())
            prov = data["provenance"]
            arms, per_arm = prov.get("arms", 1), prov.get("joints_per_arm", 2)
            assert (arms, arms * per_arm) == shape, tuned.tuned_file_name(label, shape)


def test_a_report_names_each_tuned_shapes_settings():
    from xfuzzy_rrt.report.overview import baseline_description

    one = {"rrt:tuned": {"step_deg": 300.0, "goal_bias": 0.05}}
    assert baseline_description("rrt:tuned", one) == "RRT tuned (step 300\u00b0, goal bias 0.05)"
    many = {"rrt:tuned": {"by_shape": {"1 arm, 2 joints": {"step_deg": 300.0, "goal_bias": 0.05},
                                       "1 arm, 5 joints": {"step_deg": 480.0, "goal_bias": 0.0}}}}
    assert baseline_description("rrt:tuned", many) == (
        "RRT tuned (1 arm, 2 joints: step 300\u00b0, goal bias 0.05; 1 arm, 5 joints: step "
        "480\u00b0, goal bias 0)")


def test_a_bench_of_two_shapes_records_each_shapes_tuned_settings(tuned_folder, tmp_path):
    from xfuzzy_rrt.bench.runner import run_benchmark

    scenarios = [load_scenario(TWO_JOINT), load_scenario(FIVE_JOINT)]
    result = run_benchmark(scenarios, planners=["rrt:tuned"], runs=1, max_iter=2000)
    assert result.settings["tuned"] == {"rrt:tuned": {"by_shape": {
        "1 arm, 2 joints": {"step_deg": 45.0, "goal_bias": 0.2},
        "1 arm, 5 joints": {"step_deg": 480.0, "goal_bias": 0.1}}}}
