"""Section 1.1 and 2.1: prism parameters, wrapping and the shortest-path representative."""

import numpy as np
import pytest
from numpy.testing import assert_allclose

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.pattern._prism import make_prism, periodic_dx, wrap_x

from .reference_values import ATOL, PRISM


@pytest.mark.parametrize("n", sorted(PRISM))
def test_prism_side_width_apothem(n):
    prism = make_prism(n, 1.0)
    ref = PRISM[n]
    assert_allclose([prism.b, prism.W, prism.a], [ref["b"], ref["W"], ref["a"]], atol=ATOL)


@pytest.mark.parametrize("n", sorted(PRISM))
def test_prism_columns_and_panel_centres(n):
    prism = make_prism(n, 1.0)
    assert_allclose(prism.columns, PRISM[n]["columns"], atol=ATOL)
    assert_allclose(prism.panel_centres, PRISM[n]["panel_centres"], atol=ATOL)


def test_prism_eps_is_relative_to_side():
    prism = make_prism(6, 2.0)
    assert_allclose(prism.eps, 1e-4 * prism.b)


@pytest.mark.parametrize("n", [3, 5, 2, 0, -4])
def test_prism_rejects_bad_num_sides(n):
    with pytest.raises(InvalidParameterError, match="numSides"):
        make_prism(n, 1.0)


def test_prism_rejects_non_integer_num_sides():
    with pytest.raises(InvalidTypeError, match="numSides"):
        make_prism("6", 1.0)


@pytest.mark.parametrize("r", [0.0, -1.0, float("nan"), float("inf")])
def test_prism_rejects_bad_radius(r):
    with pytest.raises(InvalidParameterError, match="r must"):
        make_prism(6, r)


def test_wrap_reduces_into_range_and_snaps_near_seam():
    W, eps = 6.0, 1e-4
    x = np.array([-0.5, 6.5, 12.25, -1e-6, 6.0 - 1e-6, 3.0, 6.0])
    assert_allclose(wrap_x(x, W, eps), [5.5, 0.5, 0.25, 0.0, 0.0, 3.0, 0.0])


def test_periodic_dx_is_shortest_representative():
    W = 6.0
    assert_allclose(periodic_dx(np.array([0.5, 5.5, -5.5, 3.0, -3.0, 9.0]), W),
                    [0.5, -0.5, 0.5, 3.0, 3.0, 3.0])  # fmt: skip


def test_cached_many_computes_the_missing_values_in_one_call():
    prism = make_prism(10, 0.25)  # a prism no other test of this file caches values on
    prism._cache.clear()
    prism.cached("b", lambda: "cached b")
    calls = []

    def make_many(missing):
        calls.append(list(missing))
        return [f"made {key}" for key in missing]

    values = prism.cached_many(["a", "b", "c", "a", "c"], make_many)
    assert values == ["made a", "cached b", "made c", "made a", "made c"]
    assert calls == [["a", "c"]]  # once, each missing key once, in order of first appearance
    assert prism.cached_many(["c", "a"], make_many) == ["made c", "made a"]
    assert len(calls) == 1  # nothing missing: no call
    prism._cache.clear()
