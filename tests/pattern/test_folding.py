"""Section 7.2: fold the vertices to their 3D positions and compare crease lengths."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from kinegami.pattern import (
    ElbowFittingPattern,
    EndTipPattern,
    RevoluteJointPattern,
    TubeFittingPattern,
    TwistFittingPattern,
)

from .folding import (
    elbow_numbers,
    elbow_transform,
    fold_elbow,
    fold_revolute_half,
    fold_tube,
    fold_twist,
    revolute_numbers,
)
from .helpers import crease_length_errors, find_vertex, rotation
from .reference_values import ATOL, ELBOW_A

TOL = 1e-9


@pytest.mark.parametrize("n", [4, 6, 10])
def test_tube_is_isometric(n):
    p = TubeFittingPattern(n, 1.3, 2.0)
    assert crease_length_errors(p, fold_tube(p)).max() < TOL


@pytest.mark.parametrize("n, alpha, h", [(4, 0.5, 0.5), (6, 0.5, 0.5), (6, -2.0, 0.1),
                                         (8, 4.0, 1.0), (6, 0.7, 0.0)])  # fmt: skip
def test_twist_is_isometric(n, alpha, h):
    p = TwistFittingPattern(n, 1.0, alpha, h)
    assert crease_length_errors(p, fold_twist(p, alpha, h)).max() < TOL


def test_twist_distal_polygon_is_rotated_and_raised():
    n, alpha, h = 6, 0.5, 0.5
    p = TwistFittingPattern(n, 1.0, alpha, h)
    X = fold_twist(p, alpha, h)
    expected = X[p.proximalBase] @ rotation([0, 0, 1], alpha).T + [0, 0, h]
    assert_allclose(X[p.distalBase], expected, atol=1e-12)


@pytest.mark.parametrize(
    "n, theta, phi",
    [(4, math.pi / 2, 0.0), (6, math.pi / 2, 0.0), (6, math.pi / 2, math.pi / 6),
     (6, math.pi / 2, math.pi / 3), (8, 1.0, 0.3), (8, 2.5, 4.0), (10, -0.7, 1.0),
     (12, 0.2, 2.0), (8, 1.2, 0.4)],
)  # fmt: skip
def test_elbow_is_isometric_including_tucked_strip(n, theta, phi):
    p = ElbowFittingPattern(n, 1.0, theta, phi)
    X = fold_elbow(p, theta, phi)
    assert not np.isnan(X).any()
    e = elbow_numbers(n, 1.0, theta, phi)
    # fix B6 moves tuck vertices by less than eps (P_k reused, columns collapsed)
    tol = TOL if e["exact"] else e["approx_tol"]
    assert crease_length_errors(p, X).max() < tol


def test_elbow_example_a_distal_frame():
    p = ElbowFittingPattern(4, 1.0, ELBOW_A["theta"], ELBOW_A["phi"])
    E, R, _, _ = elbow_transform(1.0, ELBOW_A["theta"], ELBOW_A["phi"])
    assert_allclose(E(np.zeros(3)), ELBOW_A["distal_centre"], atol=ATOL)
    assert_allclose(R @ [0, 0, 1], ELBOW_A["distal_axis"], atol=1e-12)
    X = fold_elbow(p, ELBOW_A["theta"], ELBOW_A["phi"])
    assert_allclose(X[p.distalBase[0]], ELBOW_A["D0_3d"], atol=ATOL)


@pytest.mark.parametrize("theta, phi", [(math.pi / 2, 0.0), (1.0, 0.3), (2.8, 5.0)])
def test_elbow_transform_is_arc_and_dubins_composition(theta, phi):
    r = 1.7
    E, R, g, w = elbow_transform(r, theta, phi)
    d_w = r * math.tan(theta / 2)
    axis = np.array([0.0, 0.0, 1.0])
    assert_allclose(E(np.zeros(3)), r * math.sin(theta) * axis + r * (1 - math.cos(theta)) * w,
                    atol=1e-12)  # fmt: skip
    assert_allclose(E(np.zeros(3)), d_w * axis + R @ (d_w * axis), atol=1e-12)
    assert_allclose(R @ axis, math.cos(theta) * axis + math.sin(theta) * w, atol=1e-12)


def test_elbow_tuck_boundaries_meet_on_the_mid_polygon():
    n, theta, phi = 8, 1.2, 0.4
    p = ElbowFittingPattern(n, 1.0, theta, phi)
    X = fold_elbow(p, theta, phi)
    e = elbow_numbers(n, 1.0, theta, phi)
    b = p.sideLength
    for k in np.flatnonzero(~e["collapsed"] & ~e["low"]):
        lower = find_vertex(p, ((k + 0.5) * b, e["h"][k]))
        upper = find_vertex(p, ((k + 0.5) * b, 2 * e["H_m"] - e["h"][k]))
        assert_allclose(X[lower], X[upper], atol=1e-12)


@pytest.mark.parametrize("n, theta_m", [(4, math.pi), (6, math.pi), (8, 2.0), (10, 4.0),
                                        (12, 0.5)])  # fmt: skip
def test_revolute_state_zero_is_isometric(n, theta_m):
    p = RevoluteJointPattern(n, 1.0, theta_m)
    _, a, _ = (None, math.cos(math.pi / n), None)
    h_r = a * math.tan(theta_m / 4)
    X, skipped = fold_revolute_half(p, h_r, with_distal=True)
    assert not np.isnan(np.delete(X, skipped, axis=0)).any()
    assert crease_length_errors(p, X, skip_vertices=skipped).max() < TOL


def test_revolute_crimped_midline_vertex_flat_lengths():
    """For M_k of a crimped column: |K_k M_k| = H - t_k, |M_k C| = b/2, right angle at M_k."""
    n, theta_m = 8, 2.0
    p = RevoluteJointPattern(n, 1.0, theta_m)
    d = revolute_numbers(n, 1.0, math.cos(math.pi / n) * math.tan(theta_m / 4))
    b, H = d["b"], d["H"]
    for k in d["crimped"]:
        M = np.array([(k + 0.5) * b, H])
        K = np.array([(k + 0.5) * b, d["t"][k]])
        C = np.array([(k + 1) * b, H])
        for idx in (find_vertex(p, M), find_vertex(p, K), find_vertex(p, C)):
            assert idx >= 0
        assert_allclose(np.linalg.norm(M - K), H - d["t"][k])
        assert_allclose(np.linalg.norm(C - M), b / 2)
        assert_allclose((K - M) @ (C - M), 0.0, atol=1e-12)


def test_revolute_crimps_fold_onto_the_axis_and_centres_onto_o():
    n, theta_m = 8, 2.0
    p = RevoluteJointPattern(n, 1.0, theta_m)
    h_r = math.cos(math.pi / n) * math.tan(theta_m / 4)
    X, _ = fold_revolute_half(p, h_r, with_distal=True)
    d = revolute_numbers(n, 1.0, h_r)
    for k in d["crimped"]:
        K = find_vertex(p, ((k + 0.5) * d["b"], d["t"][k]))
        U = find_vertex(p, ((k + 0.5) * d["b"], 2 * d["H"] - d["t"][k]))
        assert_allclose(X[K], X[U])
        assert_allclose(X[K][[0, 2]], [0.0, h_r], atol=1e-12)
        assert d["t"][k] ** 2 >= h_r**2 + math.cos(d["beta"][k]) ** 2 - 1e-12


@pytest.mark.parametrize("n, ell", [(4, 0.5), (6, 0.5), (8, 0.3), (10, 2.0)])
def test_end_tip_is_isometric_with_fix_b1(n, ell):
    p = EndTipPattern(n, 1.0, ell)
    X, skipped = fold_revolute_half(p, ell, with_distal=False)
    assert crease_length_errors(p, X, skip_vertices=skipped).max() < TOL


def test_reference_tip_crimp_would_not_fold_onto_the_axis():
    """B1: with psi = arctan(b / H) the crimp sits at 0.527046, whose triangle to the panel
    centre cannot fold onto the closing axis (P-K-C lengths do not match)."""
    d = revolute_numbers(6, 1.0, 0.5)
    k = d["crimped"][0]
    t_ref = 0.527046
    p = np.array([math.cos(d["beta"][k]), math.sin(d["beta"][k]), 0.0])
    K3 = np.array([0.0, d["s"][k], 0.5])
    assert abs(np.linalg.norm(K3 - p) - d["t"][k]) < 1e-9
    assert abs(np.linalg.norm(K3 - p) - t_ref) > 1e-2
