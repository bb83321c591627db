"""Elbow fitting (section 3.3), worked examples A and B, and fix B6 / B9."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from kinegami.errors import InvalidParameterError
from kinegami.pattern import ElbowFittingPattern
from kinegami.pattern._prism import make_prism
from kinegami.pattern.elbow import ELBOW_ANGLE_TOL, elbow_geometry

from .helpers import crease_set, find_vertex
from .reference_values import ATOL, ELBOW_A, ELBOW_B, ELBOW_B_PHI_30_HEIGHT


def _geometry(ref):
    return elbow_geometry(make_prism(ref["n"], 1.0), ref["theta"], ref["phi"])


def test_example_a_heights_and_tuck_angles():
    geo = _geometry(ELBOW_A)
    assert_allclose(geo.d_w, ELBOW_A["d_w"], atol=ATOL)
    assert_allclose(geo.h, ELBOW_A["h"], atol=ATOL)
    assert_allclose(geo.H_m, ELBOW_A["H_m"], atol=ATOL)
    assert_allclose(geo.tuck, ELBOW_A["tuck"], atol=1e-9)
    assert tuple(np.flatnonzero(geo.collapsed)) == ELBOW_A["collapsed"]


def test_example_a_pattern():
    p = ElbowFittingPattern(4, 1.0, ELBOW_A["theta"], ELBOW_A["phi"])
    assert_allclose(p.height, ELBOW_A["H"], atol=ATOL)
    assert (p.numVertices, p.numEdges) == (ELBOW_A["V"], ELBOW_A["E"])
    for q in ELBOW_A["Q"]:
        find_vertex(p, q)
    for points in ELBOW_A["columns"].values():
        for point in points:
            find_vertex(p, point)
    assert_allclose(p.distalMarker, [0.0, ELBOW_A["H"]], atol=ATOL)


def test_example_a_collapsed_pair_is_one_mountain():
    p = ElbowFittingPattern(4, 1.0, ELBOW_A["theta"], ELBOW_A["phi"])
    q0, q1 = (find_vertex(p, q) for q in ELBOW_A["Q"])
    e = p.edges_vertices
    joined = np.flatnonzero(
        ((e[:, 0] == q0) & (e[:, 1] == q1)) | ((e[:, 0] == q1) & (e[:, 1] == q0))
    )
    assert joined.size == 1 and p.edges_assignment[joined[0]] == "M"


def test_example_b_heights_and_offsets():
    geo = _geometry(ELBOW_B)
    assert_allclose(geo.h, ELBOW_B["h"], atol=ATOL)
    assert_allclose(np.tan(geo.tuck), ELBOW_B["tan_tuck"], atol=ATOL)
    assert tuple(np.flatnonzero(geo.collapsed)) == ELBOW_B["collapsed"]
    p = ElbowFittingPattern(6, 1.0, ELBOW_B["theta"], ELBOW_B["phi"])
    assert_allclose(p.height, ELBOW_B["H"], atol=ATOL)
    for point in ELBOW_B["O"].values():
        find_vertex(p, point)


def test_example_b_fixed_counts_without_zero_length_creases():
    p = ElbowFittingPattern(6, 1.0, ELBOW_B["theta"], ELBOW_B["phi"])
    assert (p.numVertices, p.numEdges) == (ELBOW_B["V"], ELBOW_B["E"])
    assert p.edge_lengths().min() > p.eps


def test_example_b_fix_reuses_base_vertices_at_zero_height_column():
    p = ElbowFittingPattern(6, 1.0, ELBOW_B["theta"], ELBOW_B["phi"])
    P4 = p.proximalBase[4]
    m4 = find_vertex(p, (4.5, 2.0))
    e = p.edges_vertices
    assert np.any(((e[:, 0] == P4) & (e[:, 1] == m4)) | ((e[:, 0] == m4) & (e[:, 1] == P4)))


def test_height_with_phi_30_degrees():
    p = ElbowFittingPattern(6, 1.0, math.pi / 2, math.pi / 6)
    assert_allclose(p.height, ELBOW_B_PHI_30_HEIGHT, atol=ATOL)


def test_negative_angle_is_the_opposite_axis():
    a = ElbowFittingPattern(6, 1.0, 1.1, 0.4)
    b = ElbowFittingPattern(6, 1.0, -1.1, 0.4 + math.pi)
    assert crease_set(a) == crease_set(b)


def test_angle_reduced_modulo_two_pi():
    a = ElbowFittingPattern(4, 1.0, 1.0, 0.2)
    b = ElbowFittingPattern(4, 1.0, 1.0 + 2 * math.pi, 0.2 - 2 * math.pi)
    assert crease_set(a) == crease_set(b)


def test_heights_of_opposite_columns_sum_to_twice_d_w():
    geo = elbow_geometry(make_prism(8, 1.3), 0.9, 1.7)
    assert_allclose(geo.h + np.roll(geo.h, -4), 2 * geo.d_w)


def test_tuck_angles_positive_and_sum_to_pi():
    geo = elbow_geometry(make_prism(8, 1.0), 2.0, 0.3)
    assert np.all(geo.tuck > 0)
    assert_allclose(geo.tuck.sum(), math.pi, atol=1e-9)


def test_labels_of_a_generic_column():
    """Column 2 of example A: the ten creases at L, M, O, U with the table's labels."""
    p = ElbowFittingPattern(4, 1.0, ELBOW_A["theta"], ELBOW_A["phi"])
    L, M, Ok, U = (tuple(np.round(v, 5)) for v in ELBOW_A["columns"][2])
    creases = crease_set(p, decimals=5)
    for a, b, lab in ((L, M, "V"), (M, U, "M"), (L, Ok, "M"), (U, Ok, "V"), (M, Ok, "V")):
        assert (min(a, b), max(a, b), lab) in creases


@pytest.mark.parametrize("theta", [0.0, ELBOW_ANGLE_TOL / 2, math.pi, -math.pi, 2 * math.pi])
def test_bending_angle_out_of_range(theta):
    with pytest.raises(InvalidParameterError, match="bendingAngle"):
        ElbowFittingPattern(6, 1.0, theta, 0.0)


def test_angle_tolerance_is_not_the_length_tolerance():
    """Fix B9: with r = 1e6, 1e-4 b is about 141, which the reference compared with |theta|."""
    p = ElbowFittingPattern(4, 1e6, 1.0, 0.3)
    assert p.validate().ok


def test_small_bend_is_valid():
    assert ElbowFittingPattern(4, 1.0, 1e-3, 0.3).validate().ok


def test_unresolvable_tiny_angle_is_rejected_clearly():
    with pytest.raises(InvalidParameterError, match="too small to resolve"):
        ElbowFittingPattern(12, 1.0, 1e-5, 0.0)
