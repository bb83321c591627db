"""REBO (section 3.7, fix B11) and prismatic joint (section 3.8)."""

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from kinegami.errors import InvalidParameterError
from kinegami.pattern import PrismaticJointPattern, REBOPattern
from kinegami.pattern._prism import make_prism
from kinegami.pattern.prismatic import rebo_geometry

from .helpers import find_vertex, prism_numbers
from .reference_values import ATOL, PRISMATIC, REBO_4


def _rebo():
    return REBOPattern(4, 1.0, REBO_4["d"], REBO_4["N"], REBO_4["beta"])


def test_rebo_geometry_reference_values():
    geo = rebo_geometry(make_prism(4, 1.0), REBO_4["d"], REBO_4["N"], REBO_4["beta"])
    computed = [geo.l1, geo.flat_cone_angle, geo.offset, geo.height]
    assert_allclose(computed, [REBO_4[k] for k in ("l1", "alpha_f", "o", "H")], atol=ATOL)


def test_rebo_counts_and_height():
    p = _rebo()
    assert (p.numVertices, p.numEdges, p.numMountains) == (REBO_4["V"], REBO_4["E"], REBO_4["M"])
    assert_allclose(p.height, REBO_4["H"], atol=ATOL)
    assert_allclose(p.distalMarker, [0.0, REBO_4["H"]], atol=ATOL)


def test_rebo_vertex_rows():
    p = _rebo()
    b, _, _ = prism_numbers(4, 1.0)
    for y in REBO_4["rows_y"]:
        for k in range(4):
            find_vertex(p, ((k + 0.5) * b, y))
    for y in REBO_4["mid_y"]:
        for x in REBO_4["offset_x"]:
            find_vertex(p, (x, y))
        for k in range(4):
            find_vertex(p, ((k + 0.5) * b, y))


def test_rebo_proximal_valleys_relabels_only_the_first_ring():
    p = REBOPattern(4, 1.0, REBO_4["d"], REBO_4["N"], REBO_4["beta"], proximalValleys=True)
    assert p.numMountains == 4 * REBO_4["N"] * 4
    base = set(p.proximalBase.tolist())
    ring = [i for i, (a, b) in enumerate(p.edges_vertices.tolist()) if a in base and b in base]
    assert len(ring) == 4 and set(p.edges_assignment[ring]) == {"V"}


@pytest.mark.parametrize("d", [0.0, -1.0, float("nan")])
def test_rebo_rejects_non_positive_length(d):
    with pytest.raises(InvalidParameterError, match="neutralLength"):
        REBOPattern(4, 1.0, d, 2, math.pi / 4)


@pytest.mark.parametrize("beta", [0.0, math.pi / 2, -0.1, 2.0])
def test_rebo_rejects_cone_angle_out_of_range(beta):
    with pytest.raises(InvalidParameterError, match="coneAngle"):
        REBOPattern(4, 1.0, 2.0, 2, beta)


def test_rebo_rejects_offset_wider_than_a_panel():
    """Fix B11: o = l1 cot(alpha_f) must stay below b, else creases cross."""
    with pytest.raises(InvalidParameterError, match="offset"):
        REBOPattern(4, 1.0, 20.0, 1, math.pi / 4)


@pytest.mark.parametrize("n", sorted(PRISMATIC["counts"]))
def test_prismatic_counts_and_height(n):
    p = PrismaticJointPattern(n, 1.0, PRISMATIC["d"], PRISMATIC["N"], PRISMATIC["beta"])
    assert (p.numVertices, p.numEdges) == PRISMATIC["counts"][n]
    assert_allclose(p.height, PRISMATIC["height"], atol=ATOL)
    assert_allclose(p.distalMarker, [0.0, PRISMATIC["height"]], atol=ATOL)
    assert p.kind == "prismatic"


def test_prismatic_layout_of_labels():
    """Sleeve M edges, M ring at y = L, lining V edges, V ring at y = 2 L, REBO, piston."""
    p = PrismaticJointPattern(4, 1.0, PRISMATIC["d"], PRISMATIC["N"], PRISMATIC["beta"])
    L = PRISMATIC["d"] / math.sin(PRISMATIC["beta"])
    assert_allclose(L, PRISMATIC["L"], atol=ATOL)
    v = p.vertices_coords
    e = p.edges_vertices
    y0, y1 = v[e[:, 0], 1], v[e[:, 1], 1]
    horizontal = np.isclose(y0, y1)
    for y, label in ((L, "M"), (2 * L, "V"), (3 * L, "M")):
        ring = horizontal & np.isclose(y0, y, atol=1e-9)
        assert ring.sum() == 4 and set(p.edges_assignment[ring]) == {label}
    lining = ~horizontal & (np.minimum(y0, y1) > L - 1e-9) & (np.maximum(y0, y1) < 2 * L + 1e-9)
    assert lining.sum() == 4 and set(p.edges_assignment[lining]) == {"V"}
    sleeve = ~horizontal & (np.maximum(y0, y1) < L + 1e-9)
    assert set(p.edges_assignment[sleeve]) == {"M"}


@pytest.mark.parametrize("beta", [math.pi / 6 - 1e-6, 0.3, math.pi / 2])
def test_prismatic_rejects_cone_angle_outside_pi6_pi2(beta):
    with pytest.raises(InvalidParameterError, match=r"coneAngle must lie in \[pi/6, pi/2\)"):
        PrismaticJointPattern(4, 1.0, 1.0, 2, beta)


def test_prismatic_accepts_pi6():
    assert PrismaticJointPattern(4, 1.0, 0.5, 2, math.pi / 6).validate().ok


def test_rebo_rejects_vanishing_offset():
    """A cone angle very close to pi/2 makes o = l1 cot(alpha_f) shorter than eps."""
    with pytest.raises(InvalidParameterError, match="must exceed the tolerance"):
        REBOPattern(4, 1.0, 0.0625, 3, 1.5546875)
