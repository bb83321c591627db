"""Revolute joint (3.4), recursive sink layers (3.5, fixes B2 and B3) and tips (3.6, fix B1)."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose, assert_array_equal

from kinegami.errors import InvalidParameterError
from kinegami.pattern import EndTipPattern, RevoluteJointPattern, StartTipPattern
from kinegami.pattern._prism import make_prism
from kinegami.pattern.revolute import revolute_geometry

from .helpers import crease_set, find_vertex, prism_numbers
from .reference_values import (
    ATOL,
    REVOLUTE_4,
    REVOLUTE_6,
    SINK_B2_REMOVED,
    SINK_COUNTS_REF,
    TIP_4,
    TIP_6,
)


def _revolute_geometry(n, theta_m, r=1.0):
    prism = make_prism(n, r)
    return revolute_geometry(prism, prism.a * math.tan(theta_m / 4))


def test_revolute_6_parameters():
    geo = _revolute_geometry(6, math.pi)
    assert_allclose([geo.h_r, 2 * geo.h_r, geo.H, 2 * geo.H, geo.psi],
                    [REVOLUTE_6[k] for k in ("h_r", "neutral_length", "H", "height", "psi")],
                    atol=ATOL)  # fmt: skip
    assert geo.flap_panels == (REVOLUTE_6["mp"], REVOLUTE_6["ep"])
    assert tuple(np.flatnonzero(geo.crimped)) == REVOLUTE_6["crimped"]
    assert_allclose(geo.t[list(REVOLUTE_6["crimped"])], REVOLUTE_6["t"], atol=ATOL)


def test_revolute_6_vertices():
    p = RevoluteJointPattern(6, 1.0, math.pi)
    H, top = REVOLUTE_6["H"], REVOLUTE_6["height"]
    for k in range(6):
        for y in (0.0, H, top):
            find_vertex(p, (k + 0.5, y))
        find_vertex(p, ((k + 1) % 6, H))
    for k in REVOLUTE_6["crimped"]:
        find_vertex(p, (k + 0.5, REVOLUTE_6["t"]))
        find_vertex(p, (k + 0.5, REVOLUTE_6["upper_crimp_y"]))
    assert p.numVertices == REVOLUTE_6["V"]


def test_revolute_6_counts_and_labels():
    p = RevoluteJointPattern(6, 1.0, math.pi)
    assert (p.numEdges, p.numMountains, p.numValleys) == (
        REVOLUTE_6["E"], REVOLUTE_6["M"], REVOLUTE_6["Vv"],
    )  # fmt: skip
    assert_allclose(p.height, REVOLUTE_6["height"], atol=ATOL)
    assert_allclose(p.distalMarker, [0.0, REVOLUTE_6["height"]], atol=ATOL)


def test_revolute_4_counts_height_and_no_crimps():
    p = RevoluteJointPattern(4, 1.0, math.pi)
    assert (p.numVertices, p.numEdges) == (REVOLUTE_4["V"], REVOLUTE_4["E"])
    assert_allclose(p.height, REVOLUTE_4["height"], atol=ATOL)
    assert not _revolute_geometry(4, math.pi).crimped.any()


@pytest.mark.parametrize("n, ref", [(4, REVOLUTE_4), (6, REVOLUTE_6)])
def test_revolute_neutral_length(n, ref):
    assert_allclose(2 * _revolute_geometry(n, ref["theta_m"]).h_r, ref["neutral_length"], atol=ATOL)


def test_revolute_crimp_labels():
    """Crimped column 1 of n = 6: P-K M, K-M V, M-U M, U-D M; C0-K M, K-C1 M, C0-U V, U-C1 M."""
    p = RevoluteJointPattern(6, 1.0, math.pi)
    H, t, u = REVOLUTE_6["H"], REVOLUTE_6["t"], REVOLUTE_6["upper_crimp_y"]
    P, K, M, U, D = (1.5, 0.0), (1.5, t), (1.5, H), (1.5, u), (1.5, 2 * H)
    C0, C1 = (1.0, H), (2.0, H)
    creases = crease_set(p, decimals=5)
    expected = [
        (P, K, "M"), (K, M, "V"), (M, U, "M"), (U, D, "M"), (C0, K, "M"),
        (K, C1, "M"), (C0, U, "V"), (U, C1, "M"), (C0, M, "V"), (M, C1, "V"),
    ]  # fmt: skip
    for a, b, lab in expected:
        a, b = tuple(np.round(a, 5)), tuple(np.round(b, 5))
        assert (min(a, b), max(a, b), lab) in creases


def test_flap_adjacent_crimp_formula_gives_h():
    geo = _revolute_geometry(8, 2.0)
    assert_allclose(geo.t[~geo.crimped], geo.H, atol=1e-12)
    assert np.all((geo.t[geo.crimped] > 0) & (geo.t[geo.crimped] < geo.H))


@pytest.mark.parametrize("n", sorted(SINK_COUNTS_REF))
@pytest.mark.parametrize("N", [1, 2, 3])
def test_sink_layer_counts_with_fix_b2(n, N):
    V, E_ref = SINK_COUNTS_REF[n][N]
    E = E_ref - (SINK_B2_REMOVED if N >= 2 else 0)
    p = RevoluteJointPattern(n, 1.0, math.pi, numSinkLayers=N)
    assert (p.numVertices, p.numEdges) == (V, E)


@pytest.mark.parametrize("n", [4, 6, 8])
def test_sink_layers_have_no_overlapping_creases(n):
    """Fix B2: the flap-adjacent half-midlines are not duplicated by the radial chains."""
    assert RevoluteJointPattern(n, 1.0, math.pi, numSinkLayers=3).validate().ok


def test_sink_layers_keep_heights_and_bases():
    one = RevoluteJointPattern(6, 1.0, 2.0)
    three = RevoluteJointPattern(6, 1.0, 2.0, numSinkLayers=3)
    assert three.height == one.height
    assert_allclose(three.vertices_coords[three.distalBase], one.vertices_coords[one.distalBase])


def test_sink_chain_points_of_a_plain_panel():
    """n = 4, N = 2: panel 0 has no crimped side; its chains are straight and halve the way."""
    b, _, _ = prism_numbers(4, 1.0)
    p = RevoluteJointPattern(4, 1.0, math.pi, numSinkLayers=2)
    H = 1.0
    C = np.array([b, H])
    for corner in ((0.5 * b, 0.0), (1.5 * b, 0.0), (0.5 * b, 2 * H), (1.5 * b, 2 * H),
                   (0.5 * b, H), (1.5 * b, H)):  # fmt: skip
        find_vertex(p, 0.5 * (np.array(corner) + C))


@pytest.mark.parametrize("n", [6, 8])
def test_sink_crimp_chain_points_are_at_multiples_of_d(n):
    N = 3
    b, _, _ = prism_numbers(n, 1.0)
    geo = _revolute_geometry(n, math.pi)
    p = RevoluteJointPattern(n, 1.0, math.pi, numSinkLayers=N)
    d = b / (2 * N)
    k = int(np.flatnonzero(geo.crimped)[0])
    C = np.array([(k + 1) * b, geo.H])  # panel k (right of column k)
    G = np.array([(k + 0.5) * b, geo.t[k]])
    u = (G - C) / np.linalg.norm(G - C)
    for j in range(1, N):
        find_vertex(p, C + (N - j) * d * u)


def test_tip_6_reference_values_with_fix_b1():
    p = EndTipPattern(6, 1.0, 0.5)
    assert_allclose(p.height, TIP_6["H"], atol=ATOL)
    assert (p.numVertices, p.numEdges) == (TIP_6["V"], TIP_6["E"])
    for k in TIP_6["crimped"]:
        find_vertex(p, (k + 0.5, TIP_6["t"]))
        with pytest.raises(AssertionError):
            find_vertex(p, (k + 0.5, TIP_6["t_REF"]))


def test_tip_4():
    p = EndTipPattern(4, 1.0, 0.5)
    assert_allclose(p.height, TIP_4["H"], atol=ATOL)
    assert (p.numVertices, p.numEdges) == (TIP_4["V"], TIP_4["E"])


def test_end_tip_has_no_distal_base():
    p = EndTipPattern(6, 1.0, 0.5)
    assert p.distalBase is None and p.proximalBase is not None


def test_tip_equals_proximal_half_of_equivalent_revolute():
    """Fix B1: the tip's crimps are those of the revolute joint of angle 4 arctan(l / a)."""
    n, ell = 8, 0.7
    _, a, _ = prism_numbers(n, 1.0)
    tip = EndTipPattern(n, 1.0, ell)
    joint = RevoluteJointPattern(n, 1.0, 4 * math.atan(ell / a))
    lower = joint.vertices_coords[joint.vertices_coords[:, 1] <= tip.height + 1e-9]
    key = lambda v: sorted(map(tuple, np.round(v, 9)))  # noqa: E731
    assert key(tip.vertices_coords) == key(lower)


def test_start_tip_is_reversed_end_tip():
    end, start = EndTipPattern(6, 1.0, 0.5), StartTipPattern(6, 1.0, 0.5)
    assert_allclose(start.vertices_coords[:, 1], end.height - end.vertices_coords[:, 1])
    assert start.proximalBase is None
    assert_array_equal(start.distalBase, end.proximalBase)
    assert_allclose(start.vertices_coords[start.distalBase][:, 1], start.height)
    assert_allclose(start.proximalMarker, [0.0, 0.0])
    assert_allclose(start.distalMarker, [0.0, start.height])


def test_sink_layers_with_too_low_a_crimp_are_rejected():
    """A projected chain (3.5) leaving its panel would make overlapping creases."""
    with pytest.raises(InvalidParameterError, match="numSinkLayers=3 cannot be folded"):
        RevoluteJointPattern(6, 1.0, 1.0, numSinkLayers=3)


@pytest.mark.parametrize("n", [4, 6, 8, 10, 12, 16, 20])
def test_two_sink_layers_fold_at_pi(n):
    assert RevoluteJointPattern(n, 1.0, math.pi, numSinkLayers=2).validate().ok


@pytest.mark.parametrize("theta_m", [1e-9, 2 * math.pi - 1e-6])
def test_revolute_angle_too_close_to_range_end_is_rejected(theta_m):
    with pytest.raises(InvalidParameterError, match="totalBendingAngle=.* too close to the end"):
        RevoluteJointPattern(6, 1.0, theta_m)


@pytest.mark.parametrize("ell", [1e-9, 1e5])
def test_tip_length_too_extreme_is_rejected(ell):
    with pytest.raises(InvalidParameterError, match="length=.* too close to the end"):
        EndTipPattern(6, 1.0, ell)
