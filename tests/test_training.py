"""Genetic training: valid genomes, the compiled evaluation, reproducibility and safe long runs."""

from __future__ import annotations

import os
import shutil
import signal
import subprocess
import time
from pathlib import Path

import numpy as np
import pandas as pd
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from conftest import FIXTURES, console_script
from xfuzzy_rrt.fuzzy.rulebook import Rulebook, load_rulebook, save_rulebook
from xfuzzy_rrt.fuzzy.variables import INPUT_RANGES, INPUTS, OUTPUT_RANGES, OUTPUTS
from xfuzzy_rrt.geometry.scenario import load_scenario
from xfuzzy_rrt.planners.fuzzy_rrt import plan_fuzzy_rrt
from xfuzzy_rrt.training.evaluate import TrainingProblem, fitness, iterations_for
from xfuzzy_rrt.training.ga import GAConfig, generation_seeds, initial_population
from xfuzzy_rrt.training.genome import N_GENES, constant_genome, decode, encode

SCENARIOS = [FIXTURES / "scenarios" / "two-circles.toml", FIXTURES / "scenarios" / "boxes-and-circle.toml"]
TIMING_COLUMNS = ["wall_s", "runs_per_s"]


def _args(*extra: str) -> list[str]:
    """A tiny training run into ./rb (later options override earlier ones, as in click)."""
    return [console_script(), "train", *[a for s in SCENARIOS for a in ("--scenario", str(s))],
            "--population", "12", "--generations", "3", "--runs-per-eval", "2",
            "--target-fitness", "10000", "--seed", "7", "--bounds", "relative",
            "--validation-runs", "2", "--out", "rb", *extra]


def _train(cwd: Path, *extra: str, timeout: float = 600) -> subprocess.CompletedProcess:
    return subprocess.run(_args(*extra), cwd=cwd, capture_output=True, text=True, timeout=timeout)


def _outputs(folder: Path) -> tuple[dict[str, bytes], pd.DataFrame]:
    files = {p.name: p.read_bytes() for p in sorted(folder.iterdir()) if p.is_file()
             and p.name != "history.csv"}
    history = pd.read_csv(folder / "history.csv").drop(columns=TIMING_COLUMNS)
    return files, history


# ------------------------------------------------------------------------------ genome


@settings(max_examples=100, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), spread=st.sampled_from([0.0, 0.5, 1e6]),
       edges=st.sampled_from([0.0, 0.1, 0.9, 1.0]))
def test_any_genome_decodes_to_a_valid_rulebook(seed, spread, edges):
    # whatever an operator produces, in or out of the box, exactly on its faces or not
    rng = np.random.default_rng(seed)
    genes = rng.uniform(-spread, 1.0 + spread, N_GENES)
    at_edge = rng.random(N_GENES) < edges
    genes[at_edge] = rng.choice([0.0, 1.0, -0.0], size=int(at_edge.sum()))
    knots, consts = decode(genes)
    rb = Rulebook.from_arrays(knots[0], consts[0], name="g", bounds_mode="absolute",
                              provenance={"kind": "test"})  # validates ranges and ordering
    for f, s in enumerate(rb.systems):
        lo, hi = OUTPUT_RANGES[s.output]
        assert all(lo <= c <= hi for c in s.consts)
        for i, inp in enumerate(s.inputs):
            a, b = INPUT_RANGES[INPUTS[i]]
            p = inp.peaks
            assert p[0] == a and p[4] == b and p[0] < p[1] < p[2] < p[3] < p[4]


def test_encoding_inverts_decoding():
    genes = np.random.default_rng(3).random(N_GENES)
    knots, consts = decode(genes)
    assert np.allclose(encode(knots[0], consts[0]), genes, atol=1e-12)


def test_the_constant_rrt_genome_plans_exactly_like_rrt():
    from xfuzzy_rrt.planners.rrt import plan_rrt

    s = load_scenario(SCENARIOS[0])
    knots, consts = decode(constant_genome(0.05, (-180, 180, -180, 180), 10.0))
    rb = Rulebook.from_arrays(knots[0], consts[0], name="rrt", bounds_mode="absolute",
                              provenance={"kind": "test"})
    for seed in range(3):
        assert plan_fuzzy_rrt(s, rb, seed=seed).iterations == plan_rrt(s, seed=seed).iterations


# ------------------------------------------------------------------------------ evaluation


def test_compiled_evaluation_matches_the_planner_run_for_run():
    scenarios = [load_scenario(p) for p in SCENARIOS]
    genes = np.random.default_rng(5).random((3, N_GENES)) * 0.2 + constant_genome(
        0.3, (-60, 60, -60, 60), 10.0) * 0.8
    knots, consts = decode(genes)
    seeds = np.array([11, 12, 13])
    its = iterations_for([TrainingProblem.from_scenario(s) for s in scenarios], knots, consts,
                         "relative", seeds, 3000)
    for p in range(3):
        rb = Rulebook.from_arrays(knots[p], consts[p], name="x", bounds_mode="relative",
                                  provenance={"kind": "test"})
        for k, s in enumerate(scenarios):
            for r, seed in enumerate(seeds):
                res = plan_fuzzy_rrt(s, rb, seed=int(seed), max_iter=3000)
                assert its[p, k, r] == (res.iterations if res.success else -1)


def test_fitness_is_the_papers_mean_reward():
    its = np.array([[[100, -1], [9999, 10000]]])  # one individual, 2 scenarios x 2 runs
    assert fitness(its, 10_000)[0] == pytest.approx((9900 - 100 + 1 - 100) / 4)


def test_seeded_first_generation_solves_problems_where_random_rulebooks_fail():
    problems = [TrainingProblem.from_scenario(load_scenario(SCENARIOS[0]))]
    seeds = generation_seeds(0, 0, 3)
    result = {}
    for init in ("seeded", "random"):
        cfg = GAConfig(population=16, init=init, scenarios=(("a", "b"),))
        pop = initial_population(cfg, np.random.default_rng(0))
        k, c = decode(pop)
        result[init] = fitness(iterations_for(problems, k, c, "absolute", seeds, 2000), 2000)
    assert result["random"].max() == -100.0  # flat: nothing for selection to choose from
    assert (result["seeded"] > 0).mean() > 0.5


def test_generation_seeds_are_shared_fresh_and_reproducible():
    a, b = generation_seeds(3, 0, 5), generation_seeds(3, 1, 5)
    assert np.array_equal(a, generation_seeds(3, 0, 5))
    assert not np.array_equal(a, b)
    assert (a >= 0).all()


# ------------------------------------------------------------------------------ the command


def test_training_result_is_identical_with_1_worker_2_workers_and_dask(tmp_path):
    distributed = pytest.importorskip("distributed")
    runs = {}
    for label, extra in (("one", ["--workers", "1"]), ("two", ["--workers", "2"])):
        (tmp_path / label).mkdir()
        proc = _train(tmp_path / label, *extra)
        assert proc.returncode == 0, proc.stderr
        runs[label] = _outputs(tmp_path / label / "rb")
    with distributed.LocalCluster(n_workers=1, threads_per_worker=2, processes=False, protocol="tcp://",
                                  host="127.0.0.1", dashboard_address=None) as cluster:
        (tmp_path / "dask").mkdir()
        proc = _train(tmp_path / "dask", "--scheduler", cluster.scheduler_address)
        assert proc.returncode == 0, proc.stderr
        assert "Dask scheduler" in proc.stderr
        runs["dask"] = _outputs(tmp_path / "dask" / "rb")
    files, history = runs["one"]
    assert len(history) == 3 and set(files) >= {"rulebook.toml", "goal_bias.fis"}
    for label in ("two", "dask"):
        assert runs[label][0] == files, label
        pd.testing.assert_frame_equal(runs[label][1], history)


def test_a_run_killed_after_a_checkpoint_resumes_to_the_uninterrupted_result(tmp_path):
    # long enough that the kill lands mid-run: 30 generations of 12 x 2 x 8 runs
    extra = ["--generations", "30", "--runs-per-eval", "8", "--workers", "1"]
    (tmp_path / "full").mkdir()
    proc = _train(tmp_path / "full", *extra)
    assert proc.returncode == 0, proc.stderr

    (tmp_path / "killed").mkdir()
    child = subprocess.Popen(_args(*extra), cwd=tmp_path / "killed", stdout=subprocess.DEVNULL,
                             stderr=subprocess.DEVNULL)
    state = tmp_path / "killed" / "rb" / "checkpoint" / "state.npz"
    deadline = time.monotonic() + 300
    while not state.exists() and time.monotonic() < deadline and child.poll() is None:
        time.sleep(0.005)
    os.kill(child.pid, signal.SIGKILL)
    assert child.wait() == -signal.SIGKILL, "the run finished before it could be killed"
    assert not (tmp_path / "killed" / "rb" / "rulebook.toml").exists()

    resumed = _train(tmp_path / "killed", *extra, "--resume")
    assert resumed.returncode == 0, resumed.stderr
    assert "resuming after generation" in resumed.stderr
    full_files, full_history = _outputs(tmp_path / "full" / "rb")
    files, history = _outputs(tmp_path / "killed" / "rb")
    assert files == full_files
    pd.testing.assert_frame_equal(history, full_history)


def test_corrupt_or_foreign_checkpoint_is_one_clear_error(tmp_path):
    proc = _train(tmp_path, "--workers", "1")
    assert proc.returncode == 0, proc.stderr
    state = tmp_path / "rb" / "checkpoint" / "state.npz"
    good = state.read_bytes()

    other = _train(tmp_path, "--workers", "1", "--resume", "--population", "14")
    assert other.returncode == 2
    assert other.stderr.strip().splitlines() == [other.stderr.strip()]
    assert other.stderr.startswith("error: rb/checkpoint/state.npz: checkpoint belongs to a different")

    for damage in (b"not a checkpoint", good[: len(good) // 2], good[:100] + b"\0" * 64 + good[164:]):
        state.write_bytes(damage)
        proc = _train(tmp_path, "--workers", "1", "--resume")
        assert proc.returncode == 2, proc.stderr
        lines = proc.stderr.strip().splitlines()
        assert len(lines) == 1 and "Traceback" not in proc.stderr
        assert lines[0].startswith("error: rb/checkpoint/state.npz: corrupt checkpoint"), lines


def test_an_existing_checkpoint_is_not_overwritten_without_resume(tmp_path):
    assert _train(tmp_path, "--workers", "1").returncode == 0
    again = _train(tmp_path, "--workers", "1")
    assert again.returncode == 2
    assert "pass --resume" in again.stderr


def test_bad_training_options_are_one_line_errors(tmp_path):
    proc = _train(tmp_path, "--bounds", "sideways")
    assert proc.returncode == 2 and proc.stderr.startswith("error: --bounds: ")
    proc = subprocess.run([console_script(), "train", "--scenario", "nope.toml", "--out", "rb"],
                          cwd=tmp_path, capture_output=True, text=True)
    assert proc.returncode == 2 and proc.stderr.startswith("error: nope.toml")
    assert not (tmp_path / "rb").exists()


def test_seed_rulebooks_are_part_of_the_fingerprint_and_must_match_it():
    from xfuzzy_rrt.fuzzy.rulebook import rulebooks_dir

    expert = load_rulebook(rulebooks_dir() / "expert")
    base = GAConfig(population=12, bounds="relative", scenarios=(("a", "b"),))
    seeded = GAConfig(population=12, bounds="relative", scenarios=(("a", "b"),),
                      seed_rulebooks=((expert.name, expert.sha256),))
    assert base.fingerprint() != seeded.fingerprint()
    rng = lambda: np.random.default_rng(0)  # noqa: E731
    pop = initial_population(seeded, rng(), [expert])
    assert not np.array_equal(pop, initial_population(base, rng()))
    with pytest.raises(ValueError, match="not the configuration's"):
        initial_population(seeded, rng())  # the recorded seed is not given: refuse
    with pytest.raises(ValueError, match="not the configuration's"):
        initial_population(base, rng(), [expert])  # an unrecorded seed: refuse


def test_a_missing_or_mismatched_seed_rulebook_is_an_error_before_any_output(tmp_path):
    proc = _train(tmp_path, "--seed-rulebook", "nowhere")
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == ["error: nowhere: rulebook directory does not exist"]
    from xfuzzy_rrt.fuzzy.rulebook import rulebooks_dir

    paper = rulebooks_dir() / "paper"  # absolute bounds; the run asks for relative
    proc = _train(tmp_path, "--seed-rulebook", str(paper))
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [
        f"error: {paper}: seed rulebook has absolute bounds, but --bounds is relative"]
    proc = _train(tmp_path, "--init", "random", "--seed-rulebook", str(paper))
    assert proc.returncode == 2 and proc.stderr.startswith("error: --seed-rulebook: ")
    # the default seed hidden (it used to be dropped silently, same recorded command)
    empty = tmp_path / "no-rulebooks"
    empty.mkdir()
    proc = subprocess.run(_args(), cwd=tmp_path, capture_output=True, text=True,
                          env={**os.environ, "XFUZZY_RRT_RULEBOOKS": str(empty)})
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == [
        f"error: {empty / 'expert'}: the default seed rulebook 'expert' is missing; pass "
        "--seed-rulebook DIR or --init random"]
    assert not (tmp_path / "rb").exists()


def test_an_explicit_seed_rulebook_is_in_the_reproduce_command():
    from xfuzzy_rrt.training.run import canonical_command

    config = GAConfig(scenarios=(("a", "b"),))
    cmd = canonical_command(config, ["s.toml"], "out", ["my seeds/expert"])
    assert "--seed-rulebook 'my seeds/expert'" in cmd
    assert "--seed-rulebook" not in canonical_command(config, ["s.toml"], "out")


def test_workers_0_is_rejected_before_any_folder_is_made(tmp_path):
    proc = _train(tmp_path, "--workers", "0")
    assert proc.returncode == 2
    assert proc.stderr.splitlines() == ["error: --workers: must be >= 1, got 0"]
    assert not (tmp_path / "rb").exists()


def test_a_bad_scheduler_fails_fast_with_one_line_and_no_folder(tmp_path):
    pytest.importorskip("distributed")
    import socket

    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.training.workers import check_scheduler_address

    with socket.socket() as sock:  # a port where nothing listens
        sock.bind(("127.0.0.1", 0))
        closed = f"tcp://127.0.0.1:{sock.getsockname()[1]}"
    for address, expected in (("nonsense", "'nonsense' is not a scheduler address"),
                              (closed, f"cannot reach a Dask scheduler at {closed!r}")):
        started = time.monotonic()
        with pytest.raises(InputError, match=expected):
            check_scheduler_address(address)
        assert time.monotonic() - started <= 5.0  # the issue: it hung 20 s
        proc = _train(tmp_path, "--scheduler", address, timeout=60)
        assert proc.returncode == 2
        lines = proc.stderr.splitlines()
        assert len(lines) == 1 and lines[0].startswith("error: --scheduler: "), proc.stderr
        assert expected in lines[0]
        assert not (tmp_path / "rb").exists()


def _children(pid: int) -> list[int]:
    out = []
    for stat in Path("/proc").glob("[0-9]*/stat"):
        try:
            fields = stat.read_text().rsplit(")", 1)[1].split()
        except OSError:
            continue
        if int(fields[1]) == pid:
            out.append(int(stat.parent.name))
    return out


def _alive(pid: int) -> bool:
    try:
        state = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()[0]
    except OSError:
        return False
    return state != "Z"


@pytest.mark.skipif(not Path("/proc/self/stat").exists(), reason="needs Linux /proc")
def test_workers_die_with_a_killed_training_process(tmp_path):
    proc = subprocess.Popen(_args("--workers", "2", "--population", "200", "--generations", "50"),
                            cwd=tmp_path, stdout=subprocess.DEVNULL, stderr=subprocess.DEVNULL)
    workers: list[int] = []
    try:
        deadline = time.monotonic() + 120
        while len(workers) < 2 and time.monotonic() < deadline and proc.poll() is None:
            time.sleep(0.1)  # waiting for a state, not racing one: the workers must exist
            workers = _children(proc.pid)
        assert len(workers) == 2, "the training did not start its two workers"
        proc.kill()
        proc.wait()
        deadline = time.monotonic() + 10
        while any(_alive(w) for w in workers) and time.monotonic() < deadline:
            time.sleep(0.1)
        assert not any(_alive(w) for w in workers), "orphaned workers outlived kill -9"
    finally:
        if proc.poll() is None:
            proc.kill()
        for w in workers:  # only the processes this test started
            if _alive(w):
                os.kill(w, signal.SIGKILL)


def test_trained_rulebook_lints_round_trips_and_records_its_provenance(tmp_path, run_cli):
    proc = _train(tmp_path, "--workers", "1")
    assert proc.returncode == 0, proc.stderr
    folder = tmp_path / "rb"
    assert run_cli("rules", "lint", folder).returncode == 0
    rb = load_rulebook(folder)
    prov = rb.provenance
    assert prov["kind"] == "ga" and prov["seed"] == 7 and prov["generations_run"] == 3
    assert prov["command"].startswith("xfuzzy-rrt train --scenario ")
    assert [s["sha256"] for s in prov["scenarios"]] == [
        __import__("hashlib").sha256(p.read_bytes()).hexdigest() for p in SCENARIOS]
    assert prov["package_version"] and prov["history"] == "history.csv"
    # the first generation started from the packaged expert (relative bounds): recorded
    from xfuzzy_rrt.fuzzy.rulebook import rulebooks_dir

    expert = load_rulebook(rulebooks_dir() / "expert")
    assert [dict(x) for x in prov["seed_rulebooks"]] == [
        {"name": "expert", "source": "packaged", "sha256": expert.sha256}]
    import numba
    import scipy

    assert prov["versions"]["numpy"] == np.__version__
    assert prov["versions"]["numba"] == numba.__version__
    assert prov["versions"]["scipy"] == scipy.__version__
    assert set(prov["versions"]) == {"python", "numpy", "numba", "pymoo", "scipy"}
    # text round trip: save and reload gives the same bytes and rulebook
    save_rulebook(rb, tmp_path / "copy")
    for name in ["rulebook.toml", *(o + ".fis" for o in OUTPUTS)]:
        assert (tmp_path / "copy" / name).read_bytes() == (folder / name).read_bytes()
    # FLL round trip
    assert run_cli("rules", "export", folder, "--format", "fll", "--out", tmp_path / "fll").returncode == 0
    assert run_cli("rules", "import", tmp_path / "fll", "--out", tmp_path / "back").returncode == 0
    back = load_rulebook(tmp_path / "back")
    k1, c1 = rb.arrays()
    k2, c2 = back.arrays()
    assert np.array_equal(k1, k2) and np.array_equal(c1, c2)


# ------------------------------------------------------------------------------ generated problems


def test_generated_scenarios_are_valid_solvable_nontrivial_and_deterministic(tmp_path, run_cli):
    from xfuzzy_rrt.geometry.collision import segment_free
    from xfuzzy_rrt.planners.rrt import plan_rrt

    for folder in ("a", "b"):
        proc = run_cli("scenarios", "generate", "--count", "3", "--seed", "42", "--out", tmp_path / folder)
        assert proc.returncode == 0, proc.stderr
    files = sorted((tmp_path / "a").glob("*.toml"))
    assert len(files) == 3
    for f in files:
        assert f.read_bytes() == (tmp_path / "b" / f.name).read_bytes()
        s = load_scenario(f)  # the project's own validating (and strict) loader
        a = s.arrays()
        assert not segment_free(a, a.start_deg, a.goal_deg)  # non-trivial
        assert 2 <= len(s.obstacles) <= 7 and s.arm.dof == 2
        assert plan_rrt(s, seed=0, max_iter=20_000).success  # solvable (a certified path)
    other = run_cli("scenarios", "generate", "--count", "1", "--seed", "43", "--out", tmp_path / "c")
    assert other.returncode == 0
    first = sorted((tmp_path / "c").glob("*.toml"))[0].read_text()
    assert first.split("\n", 2)[2] != files[0].read_text().split("\n", 2)[2]


def test_default_rulebook_is_parsed_once_while_unchanged(tmp_path, monkeypatch):
    import xfuzzy_rrt.fuzzy.rulebook as rbmod

    shutil.copytree(rbmod.rulebooks_dir() / "general", tmp_path / "rb")  # edits step_size.fis
    calls = []
    real = rbmod.load_rulebook
    monkeypatch.setattr(rbmod, "load_rulebook", lambda p: calls.append(p) or real(p))
    rbmod._load_cached.cache_clear()
    s = load_scenario(SCENARIOS[0])
    first = plan_fuzzy_rrt(s, tmp_path / "rb", seed=1)
    second = plan_fuzzy_rrt(s, tmp_path / "rb", seed=1)
    assert len(calls) == 1 and first.iterations == second.iterations
    import re

    fis = tmp_path / "rb" / "step_size.fis"
    text, n = re.subn(r"(r0: .* then step_size = )\S+", r"\g<1>5.0", fis.read_text())
    assert n == 1
    time.sleep(0.01)
    fis.write_text(text)
    plan_fuzzy_rrt(s, tmp_path / "rb", seed=1)
    assert len(calls) == 2  # an edited file is re-read


def test_a_same_size_edit_with_the_old_mtime_is_not_served_from_the_cache(tmp_path):
    # cp -p, rsync -t and tar x restore timestamps: only the bytes tell the edit apart
    import re

    import xfuzzy_rrt.fuzzy.rulebook as rbmod

    root = tmp_path / "rb"
    shutil.copytree(rbmod.rulebooks_dir() / "general", root)  # edits step_size.fis
    fis = root / "step_size.fis"
    before = rbmod.load_rulebook_cached(root)
    st_before = fis.stat()
    text = fis.read_text()
    old = re.search(r"r0: .* then step_size = (\S+)", text).group(1)
    new = old[:-1] + ("1" if old[-1] != "1" else "2")  # same length, another value
    edited = text.replace(f"then step_size = {old}\n", f"then step_size = {new}\n", 1)
    assert edited != text and len(edited) == len(text)
    fis.write_text(edited)
    os.utime(fis, ns=(st_before.st_atime_ns, st_before.st_mtime_ns))
    assert fis.stat().st_size == st_before.st_size
    assert fis.stat().st_mtime_ns == st_before.st_mtime_ns
    after = rbmod.load_rulebook_cached(root)
    assert after is not before
    assert after.sha256 == rbmod.load_rulebook(root).sha256 != before.sha256


def test_resuming_a_finished_run_with_more_generations_equals_the_longer_run(tmp_path):
    (tmp_path / "long").mkdir()
    assert _train(tmp_path / "long", "--workers", "1", "--generations", "4").returncode == 0
    (tmp_path / "extended").mkdir()
    assert _train(tmp_path / "extended", "--workers", "1", "--generations", "2").returncode == 0
    more = _train(tmp_path / "extended", "--workers", "1", "--generations", "4", "--resume")
    assert more.returncode == 0, more.stderr
    long_files, long_history = _outputs(tmp_path / "long" / "rb")
    files, history = _outputs(tmp_path / "extended" / "rb")
    assert files == long_files
    pd.testing.assert_frame_equal(history, long_history)


def test_every_damaged_checkpoint_byte_is_caught_or_harmless(tmp_path):
    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.training.checkpoint import load_checkpoint, save_checkpoint
    from xfuzzy_rrt.training.ga import new_state

    config = GAConfig(population=4, elite=1, scenarios=(("a", "b"),))
    state = new_state(config)
    save_checkpoint(tmp_path, state, config)
    path = tmp_path / "state.npz"
    good = path.read_bytes()
    rng = np.random.default_rng(0)
    for k in range(300):
        data = bytearray(good)
        if k % 3 == 0:
            data = data[: int(rng.integers(len(data)))]
        else:
            i = int(rng.integers(len(data)))
            data[i] ^= int(rng.integers(1, 256))
        path.write_bytes(bytes(data))
        try:
            loaded = load_checkpoint(tmp_path, config)
        except InputError as exc:
            assert str(exc).startswith(str(path))
        else:  # the damage hit bytes nothing reads (e.g. zip comments): same state
            assert np.array_equal(loaded.population, state.population)
            assert loaded.rng_state == state.rng_state


def test_a_checkpoint_with_an_unknown_array_or_meta_key_is_refused(tmp_path):
    import io
    import json

    from xfuzzy_rrt.errors import InputError
    from xfuzzy_rrt.training.checkpoint import load_checkpoint, save_checkpoint
    from xfuzzy_rrt.training.ga import new_state

    config = GAConfig(population=4, elite=1, scenarios=(("a", "b"),))
    path = save_checkpoint(tmp_path, new_state(config), config)

    def rewrite(change) -> None:
        with np.load(io.BytesIO(path.read_bytes()), allow_pickle=False) as z:
            arrays = {name: z[name] for name in z.files}
        change(arrays)
        with open(path, "wb") as fh:
            np.savez(fh, **arrays)

    good = path.read_bytes()
    rewrite(lambda a: a.update(populaton=a["population"]))
    with pytest.raises(InputError, match=r"unknown key 'populaton' in the arrays \(did you mean "
                                         r"'population'\?\)"):
        load_checkpoint(tmp_path, config)

    path.write_bytes(good)

    def add_meta_key(a):
        meta = json.loads(str(a["meta"][()]))
        meta["generations"] = 3
        a["meta"] = np.array(json.dumps(meta))

    rewrite(add_meta_key)
    with pytest.raises(InputError) as info:
        load_checkpoint(tmp_path, config)
    assert str(info.value) == (f"{path}: unknown key 'generations' in meta "
                               f"(did you mean 'generation'?)")


def test_a_training_clearance_is_recorded_and_a_resume_with_another_is_refused(tmp_path):
    proc = _train(tmp_path, "--clearance", "0.002", "--generations", "2", "--workers", "1")
    assert proc.returncode == 0, proc.stderr
    manifest = (tmp_path / "rb" / "rulebook.toml").read_text()
    assert "--clearance 0.002" in manifest and "clearance_m = 0.002" in manifest
    other = _train(tmp_path, "--clearance", "0.003", "--generations", "3", "--workers", "1",
                   "--resume")
    assert other.returncode == 2, other.stderr
    assert other.stderr.startswith("error: ") and len(other.stderr.strip().splitlines()) == 1
