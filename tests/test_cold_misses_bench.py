"""benchmarks/cold_misses.py, cold calls counted under callgrind: that it counts every planner's
calls and that the same code gives the same counts (its figures go in the measurement log,
never asserted here). Skipped where valgrind or a C compiler with its header is missing."""

from __future__ import annotations

import importlib.util
import shutil
import tempfile
from pathlib import Path

import pytest

ROOT = Path(__file__).resolve().parents[1]
DEMO = ROOT / "xfuzzy_rrt" / "data" / "scenarios" / "demo-gap.toml"


@pytest.fixture(scope="module")
def cold_misses():
    if shutil.which("valgrind") is None:
        pytest.skip("valgrind is not installed")
    spec = importlib.util.spec_from_file_location("cold_misses_bench", ROOT / "benchmarks" /
                                                  "cold_misses.py")
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)
    with tempfile.TemporaryDirectory() as tmp:
        try:
            module.build_helper(Path(tmp))
        except SystemExit as why:
            pytest.skip(str(why))
    return module


def test_cold_calls_are_counted_per_planner_and_repeat_exactly(cold_misses):
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
