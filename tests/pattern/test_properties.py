"""Property tests (hypothesis) of section 7.1 over random valid parameters."""

import math
import os

import numpy as np
from hypothesis import HealthCheck, assume, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose, assert_array_equal

from kinegami.errors import InvalidParameterError
from kinegami.pattern import (
    ElbowFittingPattern,
    EndTipPattern,
    PrismaticJointPattern,
    REBOPattern,
    RevoluteJointPattern,
    StartTipPattern,
    TubeFittingPattern,
    TubularPattern,
    TwistFittingPattern,
    WaypointPattern,
)

from .folding import elbow_numbers, fold_elbow, fold_revolute_half, fold_twist
from .helpers import crease_length_errors, crease_set, prism_numbers

# KINEGAMI_HYPOTHESIS_EXAMPLES raises the number of examples for a longer search
SETTINGS = settings(
    max_examples=int(os.environ.get("KINEGAMI_HYPOTHESIS_EXAMPLES", "40")),
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow],
)

sides = st.sampled_from([4, 6, 8, 10, 12, 16])
radii = st.floats(0.1, 10.0)
angles = st.floats(-20.0, 20.0)
elbow_angles = st.floats(0.05, math.pi - 0.05)
heights = st.floats(0.0, 5.0)


def _check_invariants(p):
    """7.1 items 1 and 2 (via validate: range, bases, panel width, counts, no overlaps)."""
    report = p.validate()
    assert report.ok, str(report)
    b, _, W = prism_numbers(p.numSides, p.r)
    assert_allclose([p.width, p.sideLength], [W, b])
    assert np.all((p.vertices_coords[:, 0] >= 0) & (p.vertices_coords[:, 0] < W))
    if p.numEdges:
        assert np.abs(p.crease_vectors()[:, 0]).max() <= b + p.eps


@SETTINGS
@given(sides, radii, heights)
def test_tube_invariants(n, r, h):
    p = TubeFittingPattern(n, r, h * r)
    _check_invariants(p)
    assert p.height == (h * r if h * r >= p.eps else 0.0)


@SETTINGS
@given(sides, radii, angles, heights)
def test_twist_invariants_and_isometry(n, r, alpha, h):
    p = TwistFittingPattern(n, r, alpha, h * r)
    _check_invariants(p)
    if p.numEdges:
        _, _, W = prism_numbers(n, r)
        beta = (alpha % (2 * math.pi)) % (2 * math.pi / n)
        e = r * (math.cos(math.pi / n - beta) - math.cos(math.pi / n))
        assert_allclose(p.height, math.hypot(h * r, e), rtol=1e-12)
        X = fold_twist(p, alpha, h * r)
        b, _, W = prism_numbers(n, r)
        s = r * (math.sin(math.pi / n) + math.sin(beta - math.pi / n))
        raw = np.mod((np.arange(n) + 0.5) * b + s, W)
        seam = np.minimum(raw, W - raw)
        snapped = np.any((seam < p.eps) & (seam > 1e-12))  # moved onto the seam (2.1)
        tol = p.eps if snapped else 1e-9 * max(1.0, r)
        assert crease_length_errors(p, X).max() < tol


@SETTINGS
@given(sides, radii, angles, st.floats(0.1, 3.0))
def test_twist_full_turn_is_identical(n, r, alpha, h):
    a = TwistFittingPattern(n, r, alpha, h)
    b = TwistFittingPattern(n, r, alpha + 2 * math.pi, h)
    assert_allclose(a.vertices_coords, b.vertices_coords, atol=1e-9 * r)
    assert_array_equal(a.edges_vertices, b.edges_vertices)


@SETTINGS
@given(sides, radii, st.integers(0, 40), st.floats(0.1, 3.0))
def test_twist_whole_columns(n, r, j, h):
    p = TwistFittingPattern(n, r, j * 2 * math.pi / n, h)
    b, _, W = prism_numbers(n, r)
    assert_allclose(p.height, h, rtol=1e-9)
    dx = (p.distalMarker[0] - (j % n) * b + W / 2) % W - W / 2
    assert abs(dx) < 1e-9 * r + p.eps


@SETTINGS
@given(sides, radii, elbow_angles, angles, st.booleans())
def test_elbow_invariants_height_and_isometry(n, r, theta, phi, negative):
    if negative:
        theta, phi = -theta, phi + math.pi
    p = ElbowFittingPattern(n, r, theta, phi)
    _check_invariants(p)
    e = elbow_numbers(n, r, theta, phi)
    beta = (np.arange(n) + 0.5) * 2 * math.pi / n
    gap = np.abs((beta - (e["phi"] + math.pi / 2) + math.pi) % (2 * math.pi) - math.pi)
    delta = gap.min()
    assert_allclose(p.height, 2 * r * math.tan(e["theta"] / 2) * (1 + math.cos(delta)), rtol=1e-9)
    assert_allclose(e["h"] + np.roll(e["h"], -n // 2), 2 * r * math.tan(e["theta"] / 2))
    assert np.all(e["tuck"] > 0) and abs(e["tuck"].sum() - math.pi) < 1e-9
    collapsed = np.flatnonzero(e["collapsed"])
    assert len(collapsed) in (1, 2)
    if len(collapsed) == 2:
        assert (collapsed[1] - collapsed[0]) % n in (1, n - 1)
    tol = 1e-9 * max(1.0, r) if e["exact"] else e["approx_tol"]
    assert crease_length_errors(p, fold_elbow(p, theta, phi)).max() < tol


@SETTINGS
@given(sides, st.floats(0.5, 2.0), elbow_angles, angles)
def test_elbow_opposite_angle_is_identical(n, r, theta, phi):
    a = ElbowFittingPattern(n, r, theta, phi)
    b = ElbowFittingPattern(n, r, -theta, phi + math.pi)
    assert crease_set(a, decimals=7) == crease_set(b, decimals=7)


@SETTINGS
@given(sides, radii, st.floats(0.1, 2 * math.pi - 0.1), st.integers(1, 3))
def test_revolute_invariants(n, r, theta_m, N):
    try:
        p = RevoluteJointPattern(n, r, theta_m, numSinkLayers=N)
    except InvalidParameterError as error:
        # nested sinks need a high enough crimp (see docs/patterns.md); one layer always works
        assert N >= 2 and "cannot be folded" in str(error)
        return
    _check_invariants(p)
    _, a, _ = prism_numbers(n, r)
    assert_allclose(p.height, 2 * a / math.cos(theta_m / 4), rtol=1e-12)


@SETTINGS
@given(sides, radii, st.floats(0.1, 2 * math.pi - 0.1))
def test_revolute_state_zero_isometry(n, r, theta_m):
    p = RevoluteJointPattern(n, r, theta_m)
    _, a, _ = prism_numbers(n, r)
    X, skipped = fold_revolute_half(p, a * math.tan(theta_m / 4), with_distal=True)
    assert crease_length_errors(p, X, skip_vertices=skipped).max() < 1e-9 * max(1.0, r)


@SETTINGS
@given(sides, radii, st.floats(0.02, 5.0))
def test_tip_invariants(n, r, ell):
    end, start = EndTipPattern(n, r, ell * r), StartTipPattern(n, r, ell * r)
    _check_invariants(end)
    _check_invariants(start)
    _, a, _ = prism_numbers(n, r)
    assert_allclose(end.height, math.hypot(a, ell * r), rtol=1e-12)
    assert_allclose(start.vertices_coords[:, 1], end.height - end.vertices_coords[:, 1])
    X, skipped = fold_revolute_half(end, ell * r, with_distal=False)
    assert crease_length_errors(end, X, skip_vertices=skipped).max() < 1e-9 * max(1.0, r)


@SETTINGS
@given(sides, radii, st.floats(0.05, 3.0), st.integers(1, 5), st.floats(0.05, math.pi / 2 - 0.01),
       st.booleans())  # fmt: skip
def test_rebo_invariants_or_clear_error(n, r, d, N, beta, valleys):
    b, _, _ = prism_numbers(n, r)
    l1 = d * r / (2 * N * math.sin(beta))
    o = l1 / math.tan(math.pi / 2 * (1 - 2 * math.cos(beta) / n))
    if not (1e-4 * b < min(o, l1) and o < b - 1e-4 * b):
        try:
            REBOPattern(n, r, d * r, N, beta, valleys)
        except InvalidParameterError as error:
            assert "offset" in str(error) and "coneAngle=" in str(error)
            return
        raise AssertionError("expected the offset check to fail")
    p = REBOPattern(n, r, d * r, N, beta, valleys)
    _check_invariants(p)
    assert_allclose(p.height, d * r / math.sin(beta), rtol=1e-12)


@SETTINGS
@given(sides, radii, st.floats(0.05, 2.0), st.integers(1, 4), st.floats(math.pi / 6, 1.5))
def test_prismatic_invariants(n, r, d, N, beta):
    b, _, _ = prism_numbers(n, r)
    l1 = d * r / (2 * N * math.sin(beta))
    assume(l1 / math.tan(math.pi / 2 * (1 - 2 * math.cos(beta) / n)) < 0.99 * b)
    p = PrismaticJointPattern(n, r, d * r, N, beta)
    _check_invariants(p)
    assert_allclose(p.height, 4 * d * r / math.sin(beta), rtol=1e-12)


def _module(draw, n, r):
    kind = draw(st.sampled_from(["tube", "twist", "elbow", "revolute", "waypoint", "rebo"]))
    if kind == "tube":
        return TubeFittingPattern(n, r, draw(st.floats(0.0, 3.0)) * r)
    if kind == "twist":
        return TwistFittingPattern(n, r, draw(angles), draw(st.floats(0.0, 1.0)) * r)
    if kind == "elbow":
        return ElbowFittingPattern(n, r, draw(elbow_angles), draw(angles))
    if kind == "revolute":
        if draw(st.booleans()):
            return RevoluteJointPattern(n, r, draw(st.floats(0.3, 6.0)))
        return RevoluteJointPattern(n, r, draw(st.floats(2.0, 6.0)), numSinkLayers=2)
    if kind == "rebo":
        return REBOPattern(n, r, 0.2 * r, 2, 1.0)
    return WaypointPattern(n, r)


@st.composite
def chains(draw):
    n, r = draw(sides), draw(st.floats(0.2, 5.0))
    mods = [_module(draw, n, r) for _ in range(draw(st.integers(1, 12)))]
    if draw(st.booleans()):
        mods.insert(0, StartTipPattern(n, r, 0.5 * r))
    if draw(st.booleans()):
        mods.append(EndTipPattern(n, r, 0.5 * r))
    return mods


@SETTINGS
@given(chains())
def test_composition_invariants(mods):
    n = mods[0].numSides
    p = TubularPattern.concatenate(mods)
    _check_invariants(p)
    assert p.numVertices == n + sum(m.numVertices - n for m in mods)
    assert p.numEdges == sum(m.numEdges for m in mods) - p.removedDuplicates
    assert_allclose(p.height, sum(m.height for m in mods), rtol=1e-12)
    shifts = sum(m.distalMarker[0] - m.proximalMarker[0] for m in mods)
    dx = (p.distalMarker[0] - shifts + p.width / 2) % p.width - p.width / 2
    assert abs(dx) < 1e-6 * p.r


@SETTINGS
@given(chains())
def test_concatenate_agrees_with_append(mods):
    a = mods[0]
    for m in mods[1:]:
        a = a.append(m)
    c = TubularPattern.concatenate(mods)
    assert_array_equal(a.vertices_coords, c.vertices_coords)
    assert_array_equal(a.edges_vertices, c.edges_vertices)
    assert_array_equal(a.edges_assignment, c.edges_assignment)
    assert_allclose(a.distalMarker, c.distalMarker)
