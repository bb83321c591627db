"""Modules built together (catalog.build_pieces, a constructor's ``many``) equal, bit for bit,
the modules built one at a time; the constructors' caches hold either."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.pattern import (
    ElbowFittingPattern,
    TubeFittingPattern,
    TwistFittingPattern,
    catalog,
)

ARRAYS = ("vertices_coords", "edges_vertices", "edges_assignment", "proximalBase", "distalBase",
          "proximalMarker", "distalMarker")  # fmt: skip
BUILDS = {"elbow": ElbowFittingPattern, "twist": TwistFittingPattern, "tube": TubeFittingPattern}


def assert_same_pattern(a, b):
    for name in ARRAYS:
        x, y = getattr(a, name), getattr(b, name)
        assert (x is None) == (y is None), name
        if x is not None:
            assert x.dtype == y.dtype and x.shape == y.shape, name
            assert x.tobytes() == y.tobytes(), name  # bit for bit (also -0.0 against 0.0)
            assert not x.flags.writeable, name
    assert (a.height, a.width, a.numSides, a.r) == (b.height, b.width, b.numSides, b.r)
    assert a.modules == b.modules and a.removedDuplicates == b.removedDuplicates
    for u, v in zip(a.module_vertices, b.module_vertices, strict=True):
        np.testing.assert_array_equal(u, v)


def one_at_a_time(kind, calls):
    """Each call built alone, on an empty cache; an exception stands for a failed call."""
    build = BUILDS[kind]
    out = []
    for args in calls:
        build.cache_clear()
        try:
            out.append(build(*args))
        except InvalidParameterError as error:
            out.append(error)
    build.cache_clear()
    return out


angles = st.floats(-7.0, 7.0, allow_nan=False) | st.sampled_from(
    [1e-7, 1e-6, 2e-6, 1e-5, 1e-4, 1e-3, math.pi / 2, math.pi - 1e-6, math.pi - 1e-5, 3.0]
)
prisms = st.tuples(st.sampled_from([4, 6, 8, 12]), st.sampled_from([0.5, 1.0, 2.3]))


def call_lists(kind):
    if kind == "elbow":
        one = st.tuples(prisms, angles, angles).map(lambda t: (*t[0], t[1], t[2]))
    elif kind == "twist":
        one = st.tuples(prisms, angles, st.floats(0.0, 5.0)).map(lambda t: (*t[0], t[1], t[2]))
    else:
        one = st.tuples(prisms, st.floats(0.0, 9.0)).map(lambda t: (*t[0], t[1]))
    return st.lists(one, min_size=1, max_size=12)


@pytest.mark.parametrize("kind", sorted(BUILDS))
@settings(deadline=None, max_examples=60)
@given(data=st.data())
def test_a_batch_equals_the_modules_built_alone(kind, data):
    calls = data.draw(call_lists(kind))
    alone = one_at_a_time(kind, calls)
    build = BUILDS[kind]
    valid = [c for c, p in zip(calls, alone, strict=True) if not isinstance(p, Exception)]
    expected = [p for p in alone if not isinstance(p, Exception)]
    build.cache_clear()
    together = build.many(valid)
    assert len(together) == len(valid)
    for a, b in zip(together, expected, strict=True):
        assert_same_pattern(a, b)
    # the batch filled the cache: each call now returns the very pattern of the batch
    for args, pattern in zip(valid, together, strict=True):
        assert build(*args) is pattern
    if len(valid) < len(calls):  # a batch with a bad call fails as that call does alone
        build.cache_clear()
        with pytest.raises(InvalidParameterError):
            build.many(calls)
    build.cache_clear()


def test_build_pieces_keeps_the_order_and_shares_equal_pieces():
    ElbowFittingPattern.cache_clear()
    pieces = [("elbow", (4, 1.0, 1.0, 0.3)), ("tube", (4, 1.0, 2.0)),
              ("elbow", (4, 1.0, 0.5, 2.0)), ("elbow", (4, 1.0, 1.0, 0.3)),
              ("twist", (4, 1.0, 0.7, 0.4)), ("revolute", (4, 1.0, math.pi / 2, 1))]  # fmt: skip
    built = catalog.build_pieces(pieces)
    assert [p.kind for p in built] == ["elbow", "tube", "elbow", "elbow", "twist", "revolute"]
    assert built[0] is built[3]
    for (kind, args), pattern in zip(pieces, built, strict=True):
        assert catalog.module_kind(kind).build(*args) is pattern


def test_build_pieces_with_an_unhashable_argument_builds_each_alone():
    built = catalog.build_pieces([("tube", (4, 1.0, np.float64(2.0))), ("tube", (4, 1.0, 3.0))])
    assert [p.height for p in built] == [2.0, 3.0]
    with pytest.raises(InvalidTypeError, match="height must be a real number, got"):
        catalog.build_pieces([("tube", (4, 1.0, 2.0)), ("tube", (4, 1.0, [2.0]))])
    with pytest.raises(InvalidTypeError, match="height must be a real number, got"):
        TubeFittingPattern.many([(4, 1.0, 2.0), (4, 1.0, [2.0])])
    with pytest.raises(InvalidParameterError):
        catalog.build_pieces([("elbow", (4, 1.0, 1e-9, 0.0)), ("elbow", (4, 1.0, 1.0, 0.0))])


def test_cache_info_counts_hits_and_misses_and_errors_are_not_cached():
    ElbowFittingPattern.cache_clear()
    ElbowFittingPattern(4, 1.0, 1.0, 0.0)
    ElbowFittingPattern(4, 1.0, 1.0, 0.0)
    ElbowFittingPattern.many([(4, 1.0, 1.0, 0.0), (4, 1.0, 2.0, 0.0), (4, 1.0, 2.5, 0.0)])
    info = ElbowFittingPattern.cache_info()
    assert (info.hits, info.misses, info.currsize) == (2, 3, 3)
    for _ in range(2):
        with pytest.raises(InvalidParameterError):
            ElbowFittingPattern(4, 1.0, 0.0, 0.0)
    assert ElbowFittingPattern.cache_info().currsize == 3
    # argument types are part of the key (as functools.lru_cache(typed=True))
    assert ElbowFittingPattern(4, 1.0, 1, 0.0) is not ElbowFittingPattern(4, 1.0, 1.0, 0.0)
    ElbowFittingPattern.cache_clear()
    assert ElbowFittingPattern.cache_info() == (0, 0, catalog.CACHE_SIZE, 0)


def test_the_cache_keeps_at_most_cache_size_patterns(monkeypatch):
    monkeypatch.setattr(catalog, "CACHE_SIZE", 3)
    TubeFittingPattern.cache_clear()
    first = TubeFittingPattern(4, 1.0, 1.0)
    for h in (2.0, 3.0, 4.0):
        TubeFittingPattern(4, 1.0, h)
    assert TubeFittingPattern.cache_info().currsize == 3
    assert TubeFittingPattern(4, 1.0, 1.0) is not first  # the oldest was dropped
    TubeFittingPattern.cache_clear()


def test_a_batch_larger_than_the_cache_returns_every_pattern(monkeypatch):
    """The cache drops its oldest patterns while a batch fills it (the gallery's SVG tests hit
    this once a long test run had filled the caches): the batch still returns all of them."""
    monkeypatch.setattr(catalog, "CACHE_SIZE", 2)
    calls = [(6, 1.0, 0.3, 0.0)] + [(6, 1.0, 0.4 + 0.1 * i, 1.0) for i in range(5)]
    alone = one_at_a_time("elbow", calls)
    cached = ElbowFittingPattern(6, 1.0, 0.3, 0.0)  # a hit, then dropped by the batch's misses
    together = ElbowFittingPattern.many(calls)
    assert together[0] is cached
    for a, b in zip(together, alone, strict=True):
        assert_same_pattern(a, b)
    assert ElbowFittingPattern.cache_info().currsize == 2
    ElbowFittingPattern.cache_clear()
