"""Section 7.3: Maekawa and Kawasaki at the vertices that lie flat in 3D (and B3 / B4)."""

import math

import numpy as np
import pytest

from kinegami.pattern import ElbowFittingPattern, EndTipPattern, REBOPattern, RevoluteJointPattern

from .folding import elbow_numbers, revolute_numbers
from .helpers import find_vertex, incident, kawasaki_defect, maekawa_ok, mv_counts

TOL = 1e-9


def _assert_flat_foldable(p, vertex, degree, mountains):
    angles, labels = incident(p, vertex)
    assert len(angles) == degree
    assert mv_counts(p, vertex)[0] == mountains
    assert maekawa_ok(p, vertex)
    assert kawasaki_defect(p, vertex) < TOL


@pytest.mark.parametrize("n, theta, phi", [(4, math.pi / 2, 0.0), (6, math.pi / 2, 0.0),
                                           (8, 1.0, 0.3), (10, 2.0, 5.0)])  # fmt: skip
def test_elbow_mid_and_offset_vertices(n, theta, phi):
    p = ElbowFittingPattern(n, 1.0, theta, phi)
    e = elbow_numbers(n, 1.0, theta, phi)
    b = p.sideLength
    for k in np.flatnonzero(~e["collapsed"]):
        M = find_vertex(p, ((k + 0.5) * b, e["H_m"]))
        Ok = find_vertex(p, ((k + 0.5) * b + (e["H_m"] - e["h"][k]) * math.tan(e["tuck"][k]),
                            e["H_m"]))  # fmt: skip
        _assert_flat_foldable(p, M, 4, 1)
        _assert_flat_foldable(p, Ok, 4, 1)


@pytest.mark.parametrize("n, d, N, beta", [(4, 2.0, 2, math.pi / 4), (6, 1.0, 3, 1.0),
                                           (8, 0.5, 1, 0.6)])  # fmt: skip
def test_rebo_non_base_vertices(n, d, N, beta):
    p = REBOPattern(n, 1.0, d, N, beta)
    base = set(p.proximalBase.tolist()) | set(p.distalBase.tolist())
    for v in range(p.numVertices):
        if v in base:
            continue
        degree = len(incident(p, v)[0])
        if degree == 6:
            _assert_flat_foldable(p, v, 6, 4)
        else:
            assert degree == 4
            assert maekawa_ok(p, v) and kawasaki_defect(p, v) < TOL


@pytest.mark.parametrize("n, theta_m", [(4, math.pi), (6, math.pi), (8, 2.0), (10, 4.5)])
def test_revolute_midline_crimp_and_flap_centre_vertices(n, theta_m):
    p = RevoluteJointPattern(n, 1.0, theta_m)
    d = revolute_numbers(n, 1.0, math.cos(math.pi / n) * math.tan(theta_m / 4))
    b, H = d["b"], d["H"]
    for k in range(n):
        M = find_vertex(p, ((k + 0.5) * b, H))
        _assert_flat_foldable(p, M, 4, 3 if k in d["flap"] else 1)
    for k in d["crimped"]:
        _assert_flat_foldable(p, find_vertex(p, ((k + 0.5) * b, d["t"][k])), 4, 3)
        _assert_flat_foldable(p, find_vertex(p, ((k + 0.5) * b, 2 * H - d["t"][k])), 4, 3)
    for panel in (n // 2 - 1, n - 1):
        C = find_vertex(p, (((panel + 1) * b) % p.width, H))
        assert mv_counts(p, C) == (0, 2) and kawasaki_defect(p, C) < TOL


@pytest.mark.parametrize("n, ell", [(6, 0.5), (8, 0.3), (12, 1.5)])
def test_tip_crimp_vertices(n, ell):
    p = EndTipPattern(n, 1.0, ell)
    d = revolute_numbers(n, 1.0, ell)
    for k in d["crimped"]:
        _assert_flat_foldable(p, find_vertex(p, ((k + 0.5) * d["b"], d["t"][k])), 4, 3)


@pytest.mark.parametrize("N", [2, 3, 4])
def test_sink_gadget_n4_ring_vertices_are_3_to_1_with_fix_b3(N):
    p = RevoluteJointPattern(4, 1.0, math.pi, numSinkLayers=N)
    for v in range(16, p.numVertices):  # the chain points added by the gadget
        m, vv = mv_counts(p, v)
        assert {m, vv} == {1, 3}, (v, m, vv)


def test_sink_gadget_diamond_vertices_keep_reference_2_to_2():
    """B4 (open question, kept): the j-th point of a lower crimp chain has 2 M + 2 V."""
    n, N = 6, 2
    p = RevoluteJointPattern(n, 1.0, math.pi, numSinkLayers=N)
    d = revolute_numbers(n, 1.0, math.cos(math.pi / n))
    b, H = d["b"], d["H"]
    step = b / (2 * N)
    for k in d["crimped"]:
        for panel_centre in (k * b, (k + 1) * b):
            C = np.array([panel_centre, H])
            G = np.array([(k + 0.5) * b, d["t"][k]])
            u = (G - C) / np.linalg.norm(G - C)
            diamond = find_vertex(p, C + (N - 1) * step * u)
            assert mv_counts(p, diamond) == (2, 2)
