"""csc_lengths: many CSC path lengths at once, equal to solve_csc's."""

from __future__ import annotations

import math

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st

from kinegami.geometry.csc import csc_lengths, solve_csc


def _reference(P1, D1, P2, D2, r):
    out = []
    for p1, d1, p2, d2 in zip(P1, D1, P2, D2, strict=True):
        path = solve_csc(p1, d1, p2, d2, r)
        out.append(math.inf if path is None else path.length)
    return np.array(out)


@settings(deadline=None, max_examples=20)
@given(st.integers(0, 2**32 - 1), st.floats(0.01, 100.0))
def test_lengths_equal_solve_csc_one_by_one(seed, r):
    rng = np.random.default_rng(seed)
    n = 200
    P1 = rng.normal(size=(n, 3)) * 5 * r
    P2 = rng.normal(size=(n, 3)) * 5 * r
    D1 = rng.normal(size=(n, 3))
    D2 = rng.normal(size=(n, 3))
    expected = _reference(P1, D1, P2, D2, r)
    got = csc_lengths(P1, D1, P2, D2, r)
    np.testing.assert_array_equal(np.isfinite(got), np.isfinite(expected))
    finite = np.isfinite(expected)
    np.testing.assert_allclose(got[finite], expected[finite], rtol=0, atol=1e-9 * r)


def test_without_restarts_no_length_is_wrong_only_some_are_missing():
    rng = np.random.default_rng(3)
    n = 500
    P1, P2 = rng.normal(size=(n, 3)) * 5, rng.normal(size=(n, 3)) * 5
    D1, D2 = rng.normal(size=(n, 3)), rng.normal(size=(n, 3))
    expected = _reference(P1, D1, P2, D2, 1.0)
    quick = csc_lengths(P1, D1, P2, D2, 1.0, restarts=False)
    found = np.isfinite(quick)
    assert found.sum() > 0.9 * np.isfinite(expected).sum()
    np.testing.assert_allclose(quick[found], expected[found], rtol=0, atol=1e-9)


def test_identical_frames_and_a_straight_line():
    got = csc_lengths([(0, 0, 0), (0, 0, 0)], [(1, 0, 0), (1, 0, 0)],
                      [(0, 0, 0), (7, 0, 0)], [(1, 0, 0), (2, 0, 0)], 1.0)  # fmt: skip
    np.testing.assert_allclose(got, [0.0, 7.0], atol=1e-12)
