"""Segment and capsule distances: exact, robust when parallel or degenerate; fcl as the oracle."""

from __future__ import annotations

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.optimize import minimize

from kinegami.geometry.segments import (
    capsule_distances,
    point_segment_parameters,
    segment_distances,
)

fcl = pytest.importorskip("fcl")

coords = st.floats(-10, 10, allow_nan=False, allow_infinity=False)
points = st.tuples(coords, coords, coords).map(np.array)


def _capsule_object(a, b, radius):
    d = b - a
    length = float(np.linalg.norm(d))
    z = d / length
    x = np.cross(z, [1.0, 0.0, 0.0])
    if np.linalg.norm(x) < 1e-6:
        x = np.cross(z, [0.0, 1.0, 0.0])
    x /= np.linalg.norm(x)
    R = np.column_stack([x, np.cross(z, x), z])
    return fcl.CollisionObject(fcl.Capsule(radius, length), fcl.Transform(R, 0.5 * (a + b)))


def test_fcl_agrees_on_random_capsule_pairs():
    """2000 random pairs: separated distances equal fcl's to 1e-9; overlap iff fcl collides."""
    rng = np.random.default_rng(7)
    P = rng.normal(size=(2000, 4, 3)) * 3.0
    radii = rng.uniform(0.1, 1.0, (2000, 2))
    mine = capsule_distances(P[:, 0], P[:, 1], radii[:, 0], P[:, 2], P[:, 3], radii[:, 1])
    separated = overlapping = 0
    for k in range(2000):
        first = _capsule_object(P[k, 0], P[k, 1], radii[k, 0])
        second = _capsule_object(P[k, 2], P[k, 3], radii[k, 1])
        if mine[k] > 1e-6:
            result = fcl.DistanceResult()
            d = fcl.distance(first, second, fcl.DistanceRequest(), result)
            assert abs(d - mine[k]) <= 1e-9, (k, d, mine[k])
            separated += 1
        elif mine[k] < -1e-6:
            assert fcl.collide(first, second, fcl.CollisionRequest(), fcl.CollisionResult()) > 0
            overlapping += 1
    assert separated > 500 and overlapping > 200


def _brute_force(a1, b1, a2, b2) -> float:
    def f(x):
        return float(np.linalg.norm(a1 + x[0] * (b1 - a1) - a2 - x[1] * (b2 - a2)))

    starts = [(0.5, 0.5), (0, 0), (1, 1), (0, 1), (1, 0)]
    return min(
        minimize(f, x0, bounds=[(0, 1), (0, 1)], method="L-BFGS-B").fun for x0 in starts
    )


@settings(deadline=None, max_examples=200)
@given(points, points, points, points)
def test_distance_is_the_minimum_and_its_points_realise_it(a1, b1, a2, b2):
    d, s, t = segment_distances(a1, b1, a2, b2)
    assert 0.0 <= s <= 1.0 and 0.0 <= t <= 1.0
    p = a1 + s * (b1 - a1)
    q = a2 + t * (b2 - a2)
    np.testing.assert_allclose(np.linalg.norm(p - q), d, atol=1e-9)
    assert d <= _brute_force(a1, b1, a2, b2) + 1e-7


def test_parallel_overlapping_and_degenerate_segments():
    d, _, _ = segment_distances([0, 0, 0], [4, 0, 0], [1, 2, 0], [3, 2, 0])
    assert d == pytest.approx(2.0, abs=1e-15)
    d, _, _ = segment_distances([0, 0, 0], [4, 0, 0], [6, 1, 0], [9, 1, 0])  # collinear gap
    assert d == pytest.approx(np.hypot(2.0, 1.0), abs=1e-15)
    d, s, t = segment_distances([1, 1, 1], [1, 1, 1], [0, 0, 0], [2, 0, 0])  # a point
    assert d == pytest.approx(np.sqrt(2.0)) and t == pytest.approx(0.5)
    d, _, _ = segment_distances([1, 1, 1], [1, 1, 1], [1, 1, 3], [1, 1, 3])  # two points
    assert d == pytest.approx(2.0)
    # nearly parallel, crossing in projection: the interior minimum
    d, _, _ = segment_distances([0, 0, 0], [10, 0, 0], [0, 1e-9, 1], [10, -1e-9, 1])
    assert d == pytest.approx(1.0, abs=1e-12)


def test_vectorised_over_many_pairs():
    rng = np.random.default_rng(3)
    P = rng.normal(size=(50, 4, 3))
    d, s, t = segment_distances(P[:, 0], P[:, 1], P[:, 2], P[:, 3])
    for k in range(50):
        dk, sk, tk = segment_distances(*P[k])
        assert d[k] == pytest.approx(float(dk), abs=1e-14)
    assert point_segment_parameters(P[:, 0], P[:, 2], P[:, 3]).shape == (50,)
