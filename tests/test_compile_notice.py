"""The first-run compile is announced once, and only when numba really compiles."""

from __future__ import annotations


def test_the_notice_fires_once_on_a_real_compile_and_never_on_a_cached_call():
    import numba

    from xfuzzy_rrt.compile_notice import notify_first_compile

    calls = []
    notify_first_compile(lambda: calls.append(1))

    @numba.njit(cache=False)
    def twice(x):
        return 2 * x

    assert calls == []  # defining is not compiling
    assert twice(3) == 6
    assert calls == [1]
    assert twice(4.5) == 9.0  # a second signature compiles again: still one notice
    assert calls == [1]


def test_a_warm_command_prints_no_compile_notice(run_cli, tmp_path):
    from conftest import FIXTURES

    scenario = FIXTURES / "scenarios" / "two-circles.toml"
    first = run_cli("plan", scenario, "--planner", "rrt", "--seed", "1", "--max-iter", "500")
    assert first.returncode in (0, 1), first.stderr
    again = run_cli("plan", scenario, "--planner", "rrt", "--seed", "1", "--max-iter", "500")
    assert "compiling planners" not in again.stderr  # every kernel came from numba's cache


def test_commands_run_in_process_leave_no_listener_behind():
    """Each in-process ``main()`` removes its listener when it ends; before this, twenty
    earlier commands left twenty listeners and one later compile printed the notice 20 times."""
    from numba.core import event

    from xfuzzy_rrt.cli.main import main

    before = len(event._registered.get("numba:compile", []))
    for _ in range(3):
        main(["plan", "--help"])  # --help: no listener at all
        main(["plan", "no-such-file.toml"])  # exit 2 after the listener was registered
    assert len(event._registered.get("numba:compile", [])) == before

