"""Tube fitting (3.1), twist fitting (3.2) and the empty waypoint pattern (3.9)."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from kinegami.pattern import TubeFittingPattern, TwistFittingPattern, WaypointPattern
from kinegami.pattern._prism import make_prism
from kinegami.pattern.twist import twist_geometry

from .helpers import crease_set, find_vertex, prism_numbers
from .reference_values import ATOL, PRISM, TWIST, TWIST_ALPHA, TWIST_H


@pytest.mark.parametrize("n", [4, 6, 8])
def test_tube_vertices_creases_and_markers(n):
    b, _, _ = prism_numbers(n, 1.0)
    p = TubeFittingPattern(n, 1.0, 1.5)
    x = (np.arange(n) + 0.5) * b
    assert_allclose(p.vertices_coords[p.proximalBase], np.c_[x, np.zeros(n)])
    assert_allclose(p.vertices_coords[p.distalBase], np.c_[x, np.full(n, 1.5)])
    assert (p.numVertices, p.numEdges, p.numMountains) == (2 * n, n, n)
    assert_allclose(p.proximalMarker, [0.0, 0.0])
    assert_allclose(p.distalMarker, [0.0, 1.5])
    assert p.height == 1.5


def test_tube_creases_are_the_tube_edges():
    p = TubeFittingPattern(6, 1.0, 1.0)
    pairs = {tuple(sorted(e)) for e in p.edges_vertices.tolist()}
    bases = zip(p.proximalBase.tolist(), p.distalBase.tolist(), strict=True)
    assert pairs == {tuple(sorted(pair)) for pair in bases}


@pytest.mark.parametrize("height", [0.0, 1e-6])
def test_tube_below_eps_is_empty(height):
    p = TubeFittingPattern(6, 1.0, height)
    assert p.isEmpty and p.numEdges == 0 and p.height == 0.0


def test_waypoint_is_n_base_vertices():
    p = WaypointPattern(6, 1.0)
    assert_allclose(p.vertices_coords, np.c_[PRISM[6]["columns"], np.zeros(6)], atol=ATOL)
    assert_array_equal(p.proximalBase, p.distalBase)


@pytest.mark.parametrize("n", sorted(TWIST))
def test_twist_reference_values(n):
    ref = TWIST[n]
    geo = twist_geometry(make_prism(n, 1.0), TWIST_ALPHA, TWIST_H)
    assert geo.K == ref["K"]
    assert_allclose([geo.shift, geo.excess, geo.height], [ref["s"], ref["e"], ref["H"]], atol=ATOL)
    p = TwistFittingPattern(n, 1.0, TWIST_ALPHA, TWIST_H)
    assert_allclose(p.height, ref["H"], atol=ATOL)
    assert_allclose(p.distalMarker, [ref["marker_x"], ref["H"]], atol=ATOL)
    assert_allclose(p.vertices_coords[p.distalBase[0]], ref["D0"], atol=ATOL)


@pytest.mark.parametrize("n", [4, 6])
def test_twist_counts_and_labels(n):
    p = TwistFittingPattern(n, 1.0, TWIST_ALPHA, TWIST_H)
    assert (p.numVertices, p.numEdges, p.numMountains, p.numValleys) == (2 * n, 4 * n, 2 * n, 2 * n)


def test_twist_creases_follow_the_table():
    n, b = 6, 1.0
    p = TwistFittingPattern(n, 1.0, TWIST_ALPHA, TWIST_H)
    s, H = TWIST[6]["s"], TWIST[6]["H"]
    P = [((k + 0.5) * b, 0.0) for k in range(n)]
    D = [(((k + 0.5) * b + s) % (n * b), H) for k in range(n)]
    expected = set()
    for k in range(n):
        km = (k - 1) % n
        for a, c, lab in ((P[k], D[k], "M"), (D[km], P[k], "M"), (P[km], P[k], "V"),
                          (D[km], D[k], "V")):  # fmt: skip
            a, c = tuple(np.round(a, 5)), tuple(np.round(c, 5))
            expected.add((min(a, c), max(a, c), lab))
    assert crease_set(p, decimals=5) == expected


def test_twist_shift_is_zero_at_zero_residual():
    geo = twist_geometry(make_prism(6, 1.0), 0.0, 1.0)
    assert geo.shift == 0.0 and geo.excess == 0.0 and geo.height == 1.0


def test_twist_shift_tends_to_b_below_a_full_column():
    prism = make_prism(6, 1.0)
    geo = twist_geometry(prism, 2 * math.pi / 6 - 1e-9, 1.0)
    assert geo.K == 0
    assert_allclose(geo.shift, prism.b, atol=1e-8)


def test_twist_by_whole_columns_shifts_marker_without_folding():
    n, j = 6, 2
    p = TwistFittingPattern(n, 1.0, j * 2 * math.pi / n, 0.5)
    assert_allclose(p.height, 0.5, atol=1e-12)
    assert_allclose(p.distalMarker[0], j * 1.0, atol=1e-9)


def test_twist_zero_angle_keeps_the_unfolded_module():
    p = TwistFittingPattern(6, 1.0, 0.0, 0.5)
    assert (p.numVertices, p.numEdges) == (12, 24) and p.height == 0.5


def test_twist_full_turn_gives_the_same_pattern():
    a = TwistFittingPattern(6, 1.0, 0.5, 0.5)
    b = TwistFittingPattern(6, 1.0, 0.5 + 2 * math.pi, 0.5)
    assert_allclose(b.vertices_coords, a.vertices_coords, atol=1e-9)
    assert_array_equal(b.edges_vertices, a.edges_vertices)
    assert_allclose(b.distalMarker, a.distalMarker, atol=1e-9)


def test_twist_negative_angle_folds_the_complement():
    n = 6
    geo = twist_geometry(make_prism(n, 1.0), -0.1, 1.0)
    assert geo.K == n - 1
    assert_allclose(geo.residual, 2 * math.pi / n - 0.1, atol=1e-12)


def test_twist_zero_height_is_a_flat_band():
    p = TwistFittingPattern(6, 1.0, 0.5, 0.0)
    assert_allclose(p.height, TWIST[6]["e"], atol=ATOL)
    assert p.validate().ok


def test_twist_zero_height_whole_columns_is_a_relabelling():
    p = TwistFittingPattern(6, 1.0, 2 * 2 * math.pi / 6, 0.0)
    assert p.numEdges == 0 and p.height == 0.0 and p.numVertices == 6
    assert_allclose(p.distalMarker, [2.0, 0.0], atol=1e-9)
    assert p.validate().ok


def test_twist_distal_vertex_lands_on_marker_column():
    """The next module's vertex j lands on D_{j+K} (section 3.2)."""
    n = 6
    p = TwistFittingPattern(n, 1.0, 2.0, 0.3)
    geo = twist_geometry(make_prism(n, 1.0), 2.0, 0.3)
    for j in range(n):
        target = ((j + 0.5) * 1.0 + p.distalMarker[0], p.height)
        assert find_vertex(p, target) == p.distalBase[(j + geo.K) % n]
