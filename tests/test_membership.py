"""Membership functions agree with scikit-fuzzy and form a Ruspini partition."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from xfuzzy_rrt.fuzzy import membership

skfuzzy = pytest.importorskip("skfuzzy", reason="scikit-fuzzy (needs scipy) not importable")

KNOTS = [0.0, 0.1, 0.25, 0.5, 0.6]


def _x(lo=0.0, hi=0.6):
    return np.concatenate([np.linspace(lo, hi, 1201), KNOTS])


def test_triangles_match_skfuzzy_trimf_exactly():
    x = _x()
    for j in range(1, 4):
        ours = membership.trimf(x, *KNOTS[j - 1 : j + 2])
        theirs = skfuzzy.trimf(x, KNOTS[j - 1 : j + 2])
        np.testing.assert_array_equal(ours, theirs)


def test_shoulders_match_skfuzzy_trapmf_inside_the_range():
    x = _x()  # inputs are clamped to the range before evaluation, so compare there
    lo, p1, _, p3, hi = KNOTS
    np.testing.assert_array_equal(
        membership.left_shoulder(x, lo, p1), skfuzzy.trapmf(x, [lo - 1.0, lo - 0.5, lo, p1])
    )
    np.testing.assert_array_equal(
        membership.right_shoulder(x, p3, hi), skfuzzy.trapmf(x, [p3, hi, hi + 0.5, hi + 1.0])
    )


def test_shoulders_saturate_outside_the_range():
    assert membership.left_shoulder([-5.0], 0.0, 0.1)[0] == 1.0
    assert membership.right_shoulder([5.0], 0.5, 0.6)[0] == 1.0
    mu = membership.partition([-1.0, 2.0], KNOTS)
    np.testing.assert_array_equal(mu[0], [1, 0, 0, 0, 0])
    np.testing.assert_array_equal(mu[1], [0, 0, 0, 0, 1])


@settings(max_examples=200, deadline=None)
@given(st.floats(-1.0, 2.0, allow_nan=False))
def test_partition_sums_to_one_with_at_most_two_active_terms(x):
    mu = membership.partition(np.array([x]), KNOTS)[0]
    assert abs(mu.sum() - 1.0) <= 1e-15
    assert np.count_nonzero(mu) <= 2
    assert np.all(mu >= 0)


def test_each_term_is_one_at_its_peak():
    mu = membership.partition(np.array(KNOTS), KNOTS)
    np.testing.assert_array_equal(mu, np.eye(5))
