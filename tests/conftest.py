"""Shared test fixtures: locations of fixtures and a runner for the real console script."""

from __future__ import annotations

import os
import subprocess
import sys
from pathlib import Path

import pytest

TESTS = Path(__file__).resolve().parent
FIXTURES = TESTS / "fixtures"
PROJECT = TESTS.parent
SHARED_SCENARIOS = PROJECT.parent / "shared" / "scenarios"


def console_script() -> str:
    """The installed ``xfuzzy-rrt`` entry point of the interpreter running the tests."""
    candidate = Path(sys.executable).parent / "xfuzzy-rrt"
    if not candidate.exists():
        raise RuntimeError(f"console script not installed next to {sys.executable}")
    return str(candidate)


@pytest.fixture
def run_cli():
    """Run ``xfuzzy-rrt ARGS...`` as a subprocess; return the CompletedProcess (text mode)."""

    def _run(*args: str, cwd: str | os.PathLike[str] | None = None, timeout: float = 300):
        return subprocess.run(
            [console_script(), *map(str, args)],
            capture_output=True,
            text=True,
            cwd=cwd,
            timeout=timeout,
        )

    return _run


def run_main(*args, cwd: str | os.PathLike[str] | None = None,
             timeout: float | None = None) -> subprocess.CompletedProcess:
    """``xfuzzy-rrt ARGS...`` through the console script's own function, ``main(argv)``, in
    this process: the exit code, stdout and stderr the script gives (text as ``run_cli``
    decodes it; an uncaught exception is a traceback on stderr and exit code 1, as Python
    does; ``sys.argv`` as the script has it, for the command lines recorded), without paying for a new interpreter and its numpy/numba/pandas imports (about 1.5 s
    a call). For tests of what a command computes, prints and writes; ``run_cli`` stays for
    what needs a real process (signals, time limits, the installed entry point, start-up)."""
    import contextlib
    import io
    import traceback

    from xfuzzy_rrt.cli.main import main

    del timeout  # in-process: pytest's own time limit, if any, applies
    raw_out, raw_err = io.BytesIO(), io.BytesIO()
    out = io.TextIOWrapper(raw_out, encoding="utf-8", write_through=True)
    err = io.TextIOWrapper(raw_err, encoding="utf-8", write_through=True)
    here, argv = os.getcwd(), sys.argv
    try:
        sys.argv = [console_script(), *map(str, args)]  # what the script sees (provenance)
        if cwd is not None:
            os.chdir(cwd)
        with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
            try:
                code = main([str(a) for a in args])
            except SystemExit as exc:
                code = exc.code if isinstance(exc.code, int) else (0 if exc.code is None else 1)
            except Exception:
                traceback.print_exc()
                code = 1
            out.flush()
            err.flush()
    finally:
        os.chdir(here)
        sys.argv = argv

    def text(raw: io.BytesIO) -> str:  # universal newlines, as subprocess.run(text=True)
        return raw.getvalue().decode("utf-8").replace("\r\n", "\n").replace("\r", "\n")

    return subprocess.CompletedProcess(["xfuzzy-rrt", *map(str, args)], code, text(raw_out),
                                       text(raw_err))


def load_script(relative: str):
    """The module of a project script that is not in the package (``benchmarks/NAME.py``,
    ``scripts/NAME.py``), loaded from its file, so tests can call its functions."""
    import importlib.util

    path = PROJECT / relative
    spec = importlib.util.spec_from_file_location(path.stem + "_script", path)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    return module


def shared_scenarios() -> list[Path]:
    """The shared scenario files when ``../shared/scenarios`` is present, else empty."""
    if not SHARED_SCENARIOS.is_dir():
        return []
    return sorted(SHARED_SCENARIOS.glob("*.toml"))


THIN_BOX_TOML = """
name = "thin-box"
description = "a thin box lying across the sweep of a straight arm, between coarse motion samples"
[arm]
links = [0.18, 0.12]
link_radius = 0.005
joint_limits_deg = [[-180.0, 180.0], [-180.0, 180.0]]
[start]
q_deg = [-60.0, 0.0]
[goal]
q_deg = [60.0, 0.0]
[[obstacles]]
type = "box"
min = [0.2, {ylo}]
max = [0.28, {yhi}]
"""


def thin_box(tmp_path: Path, ylo: float = -0.002, yhi: float = 0.002) -> Path:
    """Write the thin-box scenario (a grazing case for sampled motion checks); return its path."""
    path = tmp_path / "thin-box.toml"
    path.write_text(THIN_BOX_TOML.format(ylo=ylo, yhi=yhi))
    return path


# ------------------------------------------------------------------ parallel runs (xdist)
#
# Why: with ``-n auto`` every worker would compile the same numba kernels side by side on a
# cold cache (minutes each, and two writers of one cache entry). The controller compiles the
# kernels most tests need once, before any worker starts; the workers then load numba's on-disk
# cache. Compiling is single-threaded and takes minutes per planner (about 13 CPU-minutes for
# everything below), so it runs as a few processes at once, each compiling its own planners
# (a shared callee may be compiled twice; numba's cache writes are atomic). Tests write only
# under ``tmp_path`` (per test, so per worker), never to fixed paths.


def _warm_scenario():
    from xfuzzy_rrt.geometry.scenario import load_scenario

    return load_scenario(FIXTURES / "scenarios" / "boxes-and-circle.toml")


def _warm_rrt_and_fuzzy_rrt() -> None:
    from xfuzzy_rrt.fuzzy.rulebook import rulebooks_dir
    from xfuzzy_rrt.planners.api import plan_scenario

    s = _warm_scenario()
    plan_scenario(s, planner="rrt", seed=0, max_iter=20)
    for name in ("goal-frame", "expert"):
        for trace in (True, False):  # an untraced call runs the entry's untraced twin
            plan_scenario(s, planner="fuzzy-rrt", rulebook=rulebooks_dir() / name, seed=0,
                          max_iter=20, trace=trace)


def _warm_connect_and_certificate() -> None:
    from xfuzzy_rrt.planners.api import plan_scenario

    s = _warm_scenario()
    for trace in (True, False):
        plan_scenario(s, planner="fuzzy-rrt-connect", seed=0, max_iter=20, trace=trace)
    _warm_training("goal-frame-any")  # its population runs the connect kernel just compiled
    # The certificate and the exact minimum clearance (measured lazily, so no plan above
    # compiled them): tests with a time limit must not pay for their first compile.
    from xfuzzy_rrt.geometry.path_check import certify_path, path_min_clearance

    a = s.arrays()
    certify_path(a, [s.start_deg, s.goal_deg])
    path_min_clearance(a, [s.start_deg, s.goal_deg])


def _warm_training(mode: str) -> None:
    """The GA's population kernel of one semantics (``iterations_for``)."""
    import numpy as np

    from xfuzzy_rrt.training.evaluate import TrainingProblem, iterations_for
    from xfuzzy_rrt.training.genome import decode, n_genes

    knots, consts = decode(np.full((1, n_genes(mode)), 0.5), mode)
    iterations_for([TrainingProblem.from_scenario(_warm_scenario())], knots, consts, mode,
                   np.array([0]), 20)


def _warm_goal_frame_training_generator_and_engine() -> None:
    import numpy as np

    from xfuzzy_rrt.fuzzy.engine import evaluate
    from xfuzzy_rrt.fuzzy.rulebook import load_rulebook, rulebooks_dir
    from xfuzzy_rrt.scenarios.generate import generate_one

    _warm_training("goal-frame")
    generate_one(0, 0)
    evaluate(*load_rulebook(rulebooks_dir() / "expert").arrays(), np.zeros((1, 4)))


def _warm_planners_then_goal_frame_training() -> None:
    """One process: the goal-frame population runs the planners' own compiled kernels, so
    it loads what the planners compiled instead of compiling the same kernels beside them."""
    _warm_rrt_and_fuzzy_rrt()
    _warm_goal_frame_training_generator_and_engine()


#: Each run in its own process by :func:`_warm_numba_cache`, all at once.
_WARM_GROUPS = {
    "planners-then-goal-frame-training": _warm_planners_then_goal_frame_training,
    "connect-and-certificate": _warm_connect_and_certificate,
    "paper-training": lambda: _warm_training("relative"),
}


def _warm_numba_cache() -> None:
    code = ("import sys; sys.path.insert(0, sys.argv[1]); import conftest; "
            "conftest._WARM_GROUPS[sys.argv[2]]()")
    procs = {name: subprocess.Popen([sys.executable, "-c", code, str(TESTS), name], cwd=PROJECT)
             for name in _WARM_GROUPS}
    failed = [name for name, proc in procs.items() if proc.wait() != 0]
    if failed:
        raise RuntimeError(f"warming the numba cache failed ({', '.join(failed)}); see above")


def pytest_configure(config):
    is_worker = getattr(config, "workerinput", None) is not None
    workers = getattr(config.option, "numprocesses", None)
    if not is_worker and workers not in (None, 0, "0"):
        _warm_numba_cache()
    if is_worker:
        # xdist workers start with SIGINT ignored, and an ignored signal stays ignored in every
        # process they start: the interruption tests' Ctrl-C would never reach the CLI. Give
        # the worker Python's own handler back, so its children start with the default.
        import signal

        signal.signal(signal.SIGINT, signal.default_int_handler)


# ------------------------------------------------------------------ OMPL teardown noise
#
# Why: the ompl 2.0.1 wheel never frees the C++ graph of a BIT* planner once
# ``BITstar.getPlannerData`` has been called (reproduced without any project code: solve, get
# the planner data, drop everything, ``gc.collect()``; ``PlannerData.clear``,
# ``decoupleFromPlanner`` and ``planner.clear`` do not help, and no other supported planner
# does it). That graph holds the ``SpaceInformation`` and ``StateSpace`` created in Python, so
# at interpreter exit nanobind lists them (and every type and function of their module) as
# "leaked" on stderr -- ~36 lines after every test run that planned with BIT*. The console
# script avoids it by leaving with ``os._exit`` once its output is flushed
# (xfuzzy_rrt/cli/main.py); pytest gets the same treatment here: after the session has
# finished and reported, leave with its exit status before the bindings are torn down.

_EXIT_STATUS: list[int] = []


def pytest_sessionfinish(session, exitstatus):
    _EXIT_STATUS[:] = [int(exitstatus)]


def _leave_without_ompl_teardown() -> None:
    if "ompl" in sys.modules and _EXIT_STATUS:
        sys.stdout.flush()
        sys.stderr.flush()
        os._exit(_EXIT_STATUS[0])


import atexit  # noqa: E402  (registered last, so it runs first at exit: after pytest's own)

atexit.register(_leave_without_ompl_teardown)
