"""benchmarks/cold_misses.py, cold calls counted under callgrind: how a dump becomes per-call
counts, and (with ``XFUZZY_VALGRIND_TESTS=1``) that it counts every planner's calls and that
the same code gives the same counts. Its figures go in the measurement log, never asserted here.

Why the second is opt-in: numba keys its cache on the CPU, and valgrind presents another one
than the host (no AVX-512), so the first run on a machine compiles every kernel it plans with a
second time, for that CPU (natively since the twenty-seventh session; under valgrind before, over
5 minutes in a CI run): minutes that a clean checkout's CI would spend on one test."""

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
    with pytest.raises(SystemExit) as stop:
        cold_misses.main([str(DEMO), "--by-function", "0"])
    assert stop.value.code == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--by-function" in err[0] and "at least 1" in err[0]
    missing = tmp_path / "nowhere.toml"
    assert cold_misses.main([str(missing)]) == 2
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "nowhere.toml" in err[0]


def test_a_dump_without_the_cache_simulation_is_refused(cold_misses):
    no_cache = "events: Ir\nsummary: 4000\n"
    with pytest.raises(SystemExit, match="ILmr"):
        cold_misses.per_call(no_cache, calls=1)


# positions: instr line; a call line's next line is the callee's inclusive cost (skipped)
INSTR_DUMP = """version: 1
positions: instr line
events: Ir Dr Dw I1mr D1mr D1mw ILmr DLmr DLmw
summary: 36 0 0 0 0 0 9 4 1
fn=(1) outer
0x1000 0 10 0 0 0 0 0 3 1
+4 * 5 0 0 0 0 0 2
cfn=(2) inner
calls=1 0x2000 0
* * 99 0 0 0 0 0 99 99 99
+2 * 1
fn=(2)
0x2000 0 20 0 0 0 0 0 4 3 1
"""


def test_each_instruction_keeps_its_own_cost_and_not_its_callees(cold_misses):
    events, costs = cold_misses.instruction_costs(INSTR_DUMP)
    ir, il = events.index("Ir"), events.index("ILmr")
    assert {a: (c[ir], c[il]) for a, c in costs.items()} == {
        0x1000: (10, 3), 0x1004: (5, 2), 0x1006: (1, 0), 0x2000: (20, 4)}
    assert sum(c[ir] for c in costs.values()) == 36  # the summary: nothing counted twice


def test_misses_are_attributed_to_the_function_whose_code_holds_the_address(cold_misses):
    ranges = [(0x1000, 0x1005, "pkg.outer[v1]"), (0x2000, 0x2010, "pkg.inner[v2]")]
    rows = {r["function"]: r for r in cold_misses.by_function(INSTR_DUMP, ranges, calls=2)}
    assert rows["pkg.inner[v2]"]["Ir"] == 10 and rows["pkg.inner[v2]"]["LL"] == 4
    assert rows["pkg.outer[v1]"]["Ir"] == 7.5 and rows["pkg.outer[v1]"]["ILmr"] == 2.5
    # 0x1006 lies past outer's last byte: outside compiled code
    assert rows[cold_misses.OUTSIDE]["Ir"] == 0.5
    assert list(rows)[0] == "pkg.inner[v2]"  # the costliest first


def test_a_dump_without_instruction_addresses_is_refused_for_attribution(cold_misses):
    with pytest.raises(SystemExit, match="dump-instr"):
        cold_misses.instruction_costs(DUMP)


def test_numba_symbols_read_as_module_function_and_specialisation(cold_misses):
    loop = ("_ZN10xfuzzy_rrt8planners7connect13_connect_loopB3v25B48c8tJTIeFIjxB2IKSgI4Crv"
            "E380Problem_28array")
    assert cold_misses.demangle(loop) == "xfuzzy_rrt.planners.connect._connect_loop[v25]"
    wrapper = "_ZN7cpython10xfuzzy_rrt8planners3rrt9rrt_entryB2v1B52c8tJTIeE5ArrayIhLi1E"
    assert cold_misses.demangle(wrapper) == "cpython.xfuzzy_rrt.planners.rrt.rrt_entry[v1]"
    local = "_ZN5numba2np8arrayobj13_change_dtype12_3clocals_3e3impB4v124B4xxxxE"
    assert cold_misses.demangle(local) == "numba.np.arrayobj._change_dtype.<locals>.imp[v124]"
    assert cold_misses.demangle("memcpy") == "memcpy"
    # a symbol cut short after a length prefix keeps the parts read (no IndexError)
    assert cold_misses.demangle("_ZN10xfuzzy_rrt12") == "xfuzzy_rrt"
    assert cold_misses.demangle("_ZN10xfuzzy_rrt8plan") == "xfuzzy_rrt"


@pytest.mark.skipif(os.environ.get("XFUZZY_VALGRIND_TESTS") != "1",
                    reason="set XFUZZY_VALGRIND_TESTS=1 (a first run compiles every kernel again)")
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


@pytest.mark.skipif(os.environ.get("XFUZZY_VALGRIND_TESTS") != "1",
                    reason="set XFUZZY_VALGRIND_TESTS=1 (a first run compiles every kernel again)")
def test_every_miss_of_a_call_is_attributed_once_and_the_entry_is_named(cold_misses):
    if shutil.which("valgrind") is None or shutil.which("nm") is None:
        pytest.skip("valgrind or nm is not installed")
    (row,) = cold_misses.measure([DEMO], ["rrt:tuned"], seeds=2, top=10_000)
    names = [f["function"] for f in row["functions"]]
    assert "xfuzzy_rrt.planners.rrt._rrt_loop" in {n.split("[")[0] for n in names}
    assert cold_misses.OUTSIDE in names
    for event in ("Ir", "ILmr", "DLmr", "DLmw"):
        assert sum(f[event] for f in row["functions"]) == pytest.approx(row[event])
