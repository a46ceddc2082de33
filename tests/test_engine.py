"""The compiled engine agrees with the 625-rule reference and reports fired rules correctly."""

from __future__ import annotations

import numba
import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from xfuzzy_rrt.fuzzy import engine, reference
from xfuzzy_rrt.fuzzy.rulebook import load_rulebook
from xfuzzy_rrt.fuzzy.variables import INPUT_RANGES, INPUTS, MAX_FIRED, N_OUTPUTS, rule_terms

from _rulebook_helpers import EXPERT, random_arrays, random_inputs


@pytest.fixture(scope="module")
def arrays():
    return random_arrays(np.random.default_rng(42))


def test_batch_matches_reference_on_10000_inputs_including_out_of_range(arrays):
    knots, consts = arrays
    X = random_inputs(np.random.default_rng(7), 10_000, margin=0.25)
    outside = np.zeros(len(X), bool)
    for i, name in enumerate(INPUTS):
        lo, hi = INPUT_RANGES[name]
        outside |= (X[:, i] < lo) | (X[:, i] > hi)
    assert outside.sum() > 1000  # the test really covers clamping
    got = engine.infer_batch(knots, consts, X)
    want = reference.infer_reference(knots, consts, X)
    assert np.max(np.abs(got - want)) <= 1e-12


def test_expert_rulebook_matches_reference():
    knots, consts = load_rulebook(EXPERT).arrays()
    X = random_inputs(np.random.default_rng(3), 2000)
    np.testing.assert_allclose(engine.infer_batch(knots, consts, X),
                               reference.infer_reference(knots, consts, X), rtol=0, atol=1e-12)


def test_single_call_equals_batch_and_records_fired_rules(arrays):
    knots, consts = arrays
    X = random_inputs(np.random.default_rng(11), 300)
    batch = engine.infer_batch(knots, consts, X)
    out = np.empty(N_OUTPUTS)
    fr, fw = engine.new_trace_buffers()
    for j, x in enumerate(X):
        engine.infer(knots, consts, x, out, fr, fw, True)
        assert np.array_equal(out, batch[j])  # tracing on never changes an output bit
        for f in range(N_OUTPUTS):
            idx, w = reference.fired_reference(knots[f], consts[f], x)
            n = len(idx)
            np.testing.assert_array_equal(fr[f, :n], idx)
            np.testing.assert_allclose(fw[f, :n], w, rtol=0, atol=1e-14)
            assert np.all(fr[f, n:] == -1) and np.all(fw[f, n:] == 0.0)
            assert abs(fw[f].sum() - 1.0) <= 1e-14
            assert np.all(np.diff(fr[f, :n]) > 0)  # stable order: increasing rule index
            # the recorded rules explain the output
            assert abs(np.dot(fw[f, :n], consts[f, fr[f, :n]]) - out[f]) <= 1e-12
        engine.infer(knots, consts, x, out, fr, fw, False)
        assert np.array_equal(out, batch[j])


def test_generic_input_fires_sixteen_rules_and_a_peak_fires_exactly_one(arrays):
    knots, consts = arrays
    out = np.empty(N_OUTPUTS)
    fr, fw = engine.new_trace_buffers()
    mid = np.array([(knots[0, i, 1] + knots[0, i, 2]) / 2 for i in range(4)])
    engine.infer(knots, consts, mid, out, fr, fw, True)
    assert (fr[0] >= 0).sum() == MAX_FIRED
    r = 312
    t = rule_terms(r)
    x = np.array([knots[2, i, t[i]] for i in range(4)])
    engine.infer(knots, consts, x, out, fr, fw, True)
    assert fr[2, 0] == r and fw[2, 0] == 1.0 and np.all(fr[2, 1:] == -1)
    assert out[2] == consts[2, r]  # exactly, not approximately


@settings(max_examples=200, deadline=None)
@given(st.lists(st.floats(-10, 10, allow_nan=False), min_size=4, max_size=4))
def test_engine_matches_reference_property(xs):
    knots, consts = random_arrays(np.random.default_rng(5))
    x = np.array([xs])
    assert np.max(np.abs(engine.infer_batch(knots, consts, x)
                         - reference.infer_reference(knots, consts, x))) <= 1e-12


def test_outputs_stay_within_the_consequent_hull(arrays):
    knots, consts = arrays
    Y = engine.infer_batch(knots, consts, random_inputs(np.random.default_rng(2), 5000, 1.0))
    assert np.all(Y >= consts.min(axis=1) - 1e-12) and np.all(Y <= consts.max(axis=1) + 1e-12)


def test_infer_is_callable_from_njit_code_without_allocation(arrays):
    knots, consts = arrays

    @numba.njit
    def loop(knots, consts, X):
        out = np.empty(6)
        fr = np.empty((6, 16), np.int32)
        fw = np.empty((6, 16))
        acc = 0.0
        for j in range(X.shape[0]):
            engine.infer(knots, consts, X[j], out, fr, fw, j % 2 == 0)
            acc += out[0]
        return acc

    X = random_inputs(np.random.default_rng(9), 100)
    assert abs(loop(knots, consts, X) - engine.infer_batch(knots, consts, X)[:, 0].sum()) <= 1e-9


def test_evaluate_checks_shapes(arrays):
    knots, consts = arrays
    with pytest.raises(ValueError):
        engine.evaluate(knots[:, :3], consts, np.zeros((1, 4)))
    with pytest.raises(ValueError):
        engine.evaluate(knots, consts, np.zeros((1, 3)))
    assert engine.evaluate(knots, consts, np.zeros(4)).shape == (1, 6)


def test_nan_inputs_propagate_instead_of_being_clamped(arrays):
    knots, consts = arrays
    Y = engine.infer_batch(knots, consts, np.array([[np.nan, 0.1, 1.0, 0.1]]))
    assert np.all(np.isnan(Y))
