"""Engine throughput: six-output evaluations per second, batch and single call.

Targets (issue 4): a batch of 1M inputs at ≥ 5M six-output evaluations/s on one core, and
≤ 0.2 µs per six-output evaluation inside compiled code (the planner loop).

    .venv/bin/pytest benchmarks/test_bench_engine.py --benchmark-only

Each benchmark stores ``evals_per_s`` / ``ns_per_eval`` in ``extra_info``, computed from the
minimum round time (least disturbed by the machine).
"""

from __future__ import annotations

import numba
import numpy as np
import pytest

from xfuzzy_rrt.fuzzy import engine
from xfuzzy_rrt.fuzzy.rulebook import default_rulebook_path, load_rulebook
from xfuzzy_rrt.fuzzy.variables import INPUT_RANGES, INPUTS, N_OUTPUTS

N = 1_000_000


@pytest.fixture(scope="module")
def arrays():
    return load_rulebook(default_rulebook_path()).arrays()


@pytest.fixture(scope="module")
def X():
    rng = np.random.default_rng(0)
    cols = []
    for name in INPUTS:
        lo, hi = INPUT_RANGES[name]
        cols.append(rng.uniform(lo - 0.05 * (hi - lo), hi + 0.05 * (hi - lo), N))
    return np.ascontiguousarray(np.column_stack(cols))


@numba.njit(nogil=True)
def _loop(knots, consts, X, record):
    """What the planner does: one infer() per iteration into preallocated buffers."""
    out = np.empty(6)
    fr = np.empty((6, 16), np.int32)
    fw = np.empty((6, 16))
    acc = 0.0
    for j in range(X.shape[0]):
        engine.infer(knots, consts, X[j], out, fr, fw, record)
        acc += out[5]
    return acc


def _report(benchmark, n):
    t = benchmark.stats.stats.min
    benchmark.extra_info["evals_per_s"] = n / t
    benchmark.extra_info["ns_per_eval"] = t / n * 1e9
    return n / t, t / n * 1e9


def test_batch_1m(benchmark, arrays, X):
    knots, consts = arrays
    engine.infer_batch(knots, consts, X[:10])
    benchmark.pedantic(engine.infer_batch, args=(knots, consts, X), rounds=7, iterations=1)
    rate, _ = _report(benchmark, N)
    assert rate >= 5e6, f"{rate:.3g} six-output evals/s < 5M"


@pytest.mark.parametrize("record", [False, True], ids=["plain", "record"])
def test_njit_loop_per_call(benchmark, arrays, X, record):
    knots, consts = arrays
    _loop(knots, consts, X[:10], record)
    benchmark.pedantic(_loop, args=(knots, consts, X, record), rounds=7, iterations=1)
    _, ns = _report(benchmark, N)
    if not record:
        assert ns <= 200, f"{ns:.0f} ns per six-output evaluation > 200 ns"


def test_single_call_from_python(benchmark, arrays, X):
    knots, consts = arrays
    out = np.empty(N_OUTPUTS)
    fr, fw = engine.new_trace_buffers()
    x = X[0].copy()
    engine.infer(knots, consts, x, out, fr, fw, False)
    benchmark(engine.infer, knots, consts, x, out, fr, fw, False)
    benchmark.extra_info["evals_per_s"] = 1.0 / benchmark.stats.stats.mean
    benchmark.extra_info["ns_per_eval"] = benchmark.stats.stats.mean * 1e9
