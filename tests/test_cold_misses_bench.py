"""benchmarks/cold_misses.py, cold calls counted under callgrind: how a dump becomes per-call
counts, and (with ``XFUZZY_VALGRIND_TESTS=1``) that it counts every planner's calls and that
the same code gives the same counts. Its figures go in the measurement log, never asserted here.

Why the second is opt-in: numba keys its cache on the CPU, and valgrind presents another one
than the host (no AVX-512), so the first run on a machine compiles every kernel under valgrind,
several minutes (over 5 in a CI run) that a clean checkout's CI would spend on one test."""

from __future__ import annotations

import os
import shutil
import tempfile
from pathlib import Path

import pytest

from conftest import PROJECT, load_script

DEMO = PROJECT / "xfuzzy_rrt" / "data" / "scenarios" / "demo-gap.toml"


@pytest.fixture(scope="module")
def cold_misses():
    return load_script("benchmarks/cold_misses.py")


DUMP = """version: 1
creator: callgrind-3.19.0
desc: LL cache: 8388608 B, 64 B, 16-way associative
events: Ir Dr Dw I1mr D1mr D1mw ILmr DLmr DLmw
summary: 4000 800 600 120 40 20 100 30 10
totals: 4000 800 600 120 40 20 100 30 10
"""


def test_a_dump_becomes_per_call_counts_with_the_last_level_misses_summed(cold_misses):
    r = cold_misses.per_call(DUMP, calls=4)
    assert r["calls"] == 4 and r["Ir"] == 1000 and r["ILmr"] == 25
    assert r["DLmr"] == 7.5 and r["DLmw"] == 2.5 and r["LL"] == 35


def test_a_typo_in_a_planner_or_a_path_is_one_line_before_any_callgrind_run(cold_misses,
                                                                           capsys, tmp_path):
    assert cold_misses.main([str(DEMO), "--planner", "fuzy-rrt"]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--planner" in err[0] and "fuzy-rrt" in err[0]
    missing = tmp_path / "nowhere.toml"
    assert cold_misses.main([str(missing)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nowhere.toml" in err[0]


def test_a_dump_without_the_cache_simulation_is_refused(cold_misses):
    no_cache = "events: Ir\nsummary: 4000\n"
    with pytest.raises(SystemExit, match="ILmr"):
        cold_misses.per_call(no_cache, calls=1)


@pytest.mark.skipif(os.environ.get("XFUZZY_VALGRIND_TESTS") != "1",
                    reason="set XFUZZY_VALGRIND_TESTS=1 (the first run compiles under valgrind)")
def test_cold_calls_are_counted_per_planner_and_repeat_within_two_percent(cold_misses):
    if shutil.which("valgrind") is None:
        pytest.skip("valgrind is not installed")
    with tempfile.TemporaryDirectory() as tmp:
        try:
            cold_misses.build_helper(Path(tmp))
        except SystemExit as why:
            pytest.skip(str(why))
    rows = cold_misses.measure([DEMO], ["fuzzy-rrt", "rrt:tuned", "rrt:tuned"], seeds=2)
    assert [r["planner"] for r in rows] == ["fuzzy-rrt", "rrt:tuned", "rrt:tuned"]
    for r in rows:
        assert r["calls"] == 2
        assert r["Ir"] > 10_000 and r["ILmr"] > 100 and r["DLmr"] > 0 and r["DLmw"] > 0
        assert r["LL"] == pytest.approx(r["ILmr"] + r["DLmr"] + r["DLmw"])
    # the same calls of the same code, counted twice in separate processes: the same counts
    # (up to the few lines that Python's own allocations shift)
    again, first = rows[2], rows[1]
    assert again["Ir"] == pytest.approx(first["Ir"], rel=0.02)
    assert again["LL"] == pytest.approx(first["LL"], rel=0.02)
