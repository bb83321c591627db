"""The folded take-off junction (docs/theory/takeoff.md): worked values, and both nets folded
to 3D giving the same closed curve on the trunk surface, with tabs glued inside the trunk."""

from __future__ import annotations

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from kinegami.errors import InvalidParameterError, InvalidTypeError, KinegamiError
from kinegami.geometry.frames import rotation_matrix
from kinegami.pattern import TubeFittingPattern, TubularPattern, catalog
from kinegami.pattern.takeoff import (
    SKIRT_KIND,
    TakeoffSkirtPattern,
    takeoff_junction,
)

from .helpers import prism_numbers

# --- reference numbers (r = 1, y0 = 0, published to 6 decimals) -----------------------------
ATOL = 1e-6
#: fish-mouth vertices (x', y' - a)
FISH_MOUTH = {
    6: [(0.5, -0.633975), (0.922650, 0.0), (1.5, 0.0), (2.077350, 0.0), (2.5, -0.633975),
        (3.5, -0.633975), (3.922650, 0.0), (4.5, 0.0), (5.077350, 0.0), (5.5, -0.633975)],
    # x' = (k + 1/2) b, deep for k in {0, 3, 4, 7}
    8: [((k + 0.5) * 2 * math.sin(math.pi / 8), -0.541196 if k in (0, 3, 4, 7) else 0.0)
        for k in range(8)],
}  # fmt: skip
#: hole vertices (Xi, t) relative to (x_p, y0), as a set
HOLE = {
    4: [(sx * 0.707107, st_ * 0.707107) for sx in (-1, 1) for st_ in (-1, 1)],
    6: [(sx * 1.232051, st_ * 0.5) for sx in (-1, 1) for st_ in (-1, 1)]
    + [(sx * 0.5, st_ * 0.711325) for sx in (-1, 1) for st_ in (-1, 1)]
    + [(0.0, 1.0), (0.0, -1.0)],
    8: [(sx * 1.148050, st_ * 0.382683) for sx in (-1, 1) for st_ in (-1, 1)]
    + [(sx * 0.382683, st_ * 0.923880) for sx in (-1, 1) for st_ in (-1, 1)],
}
HOLE_AREA = {4: 2.0, 6: 3.484828, 8: 3.414214}
MAX_DEPTH = {4: 0.0, 6: 0.633975, 8: 0.541196, 10: 0.800424, 12: 0.707107, 16: 0.785695}
#: tab segments over n = 4, 6, 8, 10, 12, 16
TAB_SEGMENTS = 68
ALL_N = list(range(4, 17, 2))
#: tolerance of the 3D comparisons, relative to the scale of the coordinates
FOLD_TOL = 1e-12


# --- helpers -----------------------------------------------------------------------------


def random_frame(rng: np.random.Generator, scale: float = 5.0) -> np.ndarray:
    F = np.eye(4)
    F[:3, :3] = rotation_matrix(rng.normal(size=3), rng.uniform(0, 2 * math.pi))
    F[:3, 3] = rng.uniform(-scale, scale, size=3)
    return F


def to_trunk_local(F: np.ndarray, X: np.ndarray) -> np.ndarray:
    """World points into the trunk frame's (e_u, e_v, e_a) coordinates."""
    return (X - F[:3, 3]) @ F[:3, :3]


def surface_gap(n: int, r: float, q: np.ndarray) -> np.ndarray:
    """max over the n trunk faces of q.N_k - a: 0 on the surface, < 0 inside, > 0 outside."""
    _, a, _ = prism_numbers(n, r)
    angles = (np.arange(n) + 1) * 2 * math.pi / n
    normals = np.stack([np.cos(angles), np.sin(angles)], axis=1)
    return (q[:, :2] @ normals.T).max(axis=1) - a


def face_normal(n: int, panel: int) -> np.ndarray:
    angle = (panel + 1) * 2 * math.pi / n
    return np.array([math.cos(angle), math.sin(angle), 0.0])


def inside_polygon(points: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Even-odd test (points on the boundary may go either way)."""
    x, y = points[:, 0:1], points[:, 1:2]
    xa, ya = poly[:, 0], poly[:, 1]
    xb, yb = np.roll(xa, -1), np.roll(ya, -1)
    crosses = (ya > y) != (yb > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = xa + (y - ya) * (xb - xa) / (yb - ya)
    return (np.count_nonzero(crosses & (x < xc), axis=1) % 2) == 1


def segment_samples(segments: np.ndarray, fractions=(0.1, 0.5, 0.9)) -> np.ndarray:
    f = np.asarray(fractions)[None, :, None]
    return (segments[:, :1] + f * (segments[:, 1:] - segments[:, :1])).reshape(-1, 2)


def entry_height(n: int, r: float, u: np.ndarray, t: np.ndarray) -> np.ndarray:
    """Where a line parallel to m at offsets (u, t) enters the trunk, found by bisection on the
    full n-face inside test (independent of the module's profile formula), for face p = n - 1
    (m = e_u, s = e_v)."""
    lo, hi = np.zeros_like(u), np.full_like(u, 2.0 * r)
    for _ in range(80):
        mid = 0.5 * (lo + hi)
        q = np.stack([mid, u, t], axis=1)
        outside = surface_gap(n, r, q) > 0
        hi = np.where(outside, mid, hi)
        lo = np.where(outside, lo, mid)
    return 0.5 * (lo + hi)


def check_takeoff(n: int, r: float, p: int, y0: float, F: np.ndarray) -> dict:
    """Every check of the verification; returns the measured worst errors."""
    j = takeoff_junction(n, r, p, y0)
    scale = max(r, float(np.abs(F[:3, 3]).max()) + abs(y0) + r)
    tol = FOLD_TOL * scale
    out = {}
    # same number of vertices, same closed curve (vertices and points along every segment)
    assert j.fish_mouth.shape == j.hole.shape
    A = j.fold_branch(j.fish_mouth, F)
    B = j.fold_trunk(j.hole, F)
    out["vertices"] = float(np.abs(A - B).max())
    A = j.fold_branch(segment_samples(j.segments("fish_mouth")), F)
    B = j.fold_trunk(segment_samples(j.segments("hole")), F)
    out["segments"] = float(np.abs(A - B).max())
    assert max(out["vertices"], out["segments"]) <= tol
    # on the trunk surface
    q = to_trunk_local(F, A)
    out["surface"] = float(np.abs(surface_gap(n, r, q)).max())
    assert out["surface"] <= tol
    # just above the fish-mouth outside, just below inside (on the face for flush segments)
    delta = 1e-6 * r
    mids = segment_samples(j.segments("fish_mouth"), (0.5,))
    above = surface_gap(n, r, to_trunk_local(F, j.fold_branch(mids + [0, delta], F)))
    below = surface_gap(n, r, to_trunk_local(F, j.fold_branch(mids - [0, delta], F)))
    assert (above > 0.1 * delta).all()
    assert (below[~j.flush] < -0.1 * delta).all()
    assert (np.abs(below[j.flush]) <= tol).all()
    # tabs: folded, every edge lies in its trunk face's plane, on the face, outside the hole
    worst_dir, worst_plane = 0.0, 0.0
    _, a, _ = prism_numbers(n, r)
    for i, tab in enumerate(j.tabs):
        X = j.fold_tab(i, F)
        N = F[:3, :3] @ face_normal(n, tab.panel)
        edges = np.roll(X, -1, axis=0) - X
        lengths = np.linalg.norm(edges, axis=1)
        dots = np.abs(edges[lengths > tol] @ N) / lengths[lengths > tol]
        worst_dir = max(worst_dir, float(dots.max()))
        worst_plane = max(worst_plane, float(np.abs((X - F[:3, 3]) @ N - a).max()))
        # where it lands on the trunk sheet (the footprint) is where it is in 3D
        assert_allclose(j.fold_trunk(tab.footprint, F), X, atol=tol, rtol=0)
        # inside its face strip, outside the hole (the hinge is the hole's edge)
        x_rel = tab.footprint[:, 0] - j.face_centre
        centre = tab.trunkFace * j.prism.b
        assert (np.abs(x_rel - centre) <= 0.5 * j.prism.b + tol).all()
        centroid = tab.footprint.mean(axis=0, keepdims=True)
        off_hinge = tab.footprint[2:]
        assert not inside_polygon(centroid, j.hole_unwrapped).any()
        assert not inside_polygon(off_hinge, j.hole_unwrapped).any()
        # on the non-material side of the cut in the branch sheet
        c = tab.polygon.mean(axis=0)
        fm, W = j.fish_mouth, j.prism.W
        cut = np.interp(c[0], np.r_[fm[:, 0], fm[0, 0] + W], np.r_[fm[:, 1], fm[0, 1]], period=W)
        assert c[1] < cut
    assert worst_dir <= 1e-12 and worst_plane <= tol
    out["tab_direction"], out["tab_plane"] = worst_dir, worst_plane
    return out


# --- worked values -------------------------------------------------------------------------


@pytest.mark.parametrize("n", sorted(FISH_MOUTH))
def test_fish_mouth_worked_values(n):
    j = takeoff_junction(n, 1.0, 0)
    _, a, _ = prism_numbers(n, 1.0)
    got = j.fish_mouth - [0.0, a]
    assert_allclose(got, FISH_MOUTH[n], atol=ATOL)
    assert_allclose(j.depth, -got[:, 1], atol=1e-15)


@pytest.mark.parametrize("n", sorted(HOLE))
def test_hole_worked_values(n):
    j = takeoff_junction(n, 1.0, 0)
    local = j.hole_unwrapped - [j.face_centre, 0.0]
    got = sorted(map(tuple, np.round(local, 6) + 0.0))
    want = sorted(map(tuple, np.round(HOLE[n], 6) + 0.0))
    assert len(got) == len(want)
    assert_allclose(got, want, atol=ATOL)


@pytest.mark.parametrize("n", sorted(HOLE_AREA))
def test_hole_area(n):
    assert takeoff_junction(n, 1.0, 2).hole_area == pytest.approx(HOLE_AREA[n], abs=ATOL)


@pytest.mark.parametrize("n", sorted(MAX_DEPTH))
def test_max_depth(n):
    j = takeoff_junction(n, 1.0, 1)
    assert j.max_depth == pytest.approx(MAX_DEPTH[n], abs=ATOL)
    assert j.depth.max() == pytest.approx(j.max_depth, abs=1e-15)
    # closed forms: r (cos - sin)(pi/n) for n = 0 mod 4, a (1 - tan(pi/2n)) for n = 2 mod 4
    c, s = math.cos(math.pi / n), math.sin(math.pi / n)
    formula = c - s if n % 4 == 0 else c * (1 - math.tan(math.pi / (2 * n)))
    assert j.max_depth == pytest.approx(formula, abs=1e-14)


@pytest.mark.parametrize("n", ALL_N)
def test_extents(n):
    j = takeoff_junction(n, 2.0, 0)
    _, a, _ = prism_numbers(n, 2.0)
    local = j.hole_unwrapped - [j.face_centre, 0.0]
    assert j.lateral_half_extent == pytest.approx(a)
    assert j.axial_half_extent == pytest.approx(a if n % 4 == 0 else 2.0)
    assert np.abs(local[:, 1]).max() == pytest.approx(j.axial_half_extent, abs=1e-14)
    assert j.margin == pytest.approx(max(j.tab_width, 0.5))
    lo, hi = j.trunk_span
    assert hi - lo == pytest.approx(2 * (j.axial_half_extent + j.margin))


def test_tab_segment_count():
    total = sum(len(takeoff_junction(n, 1.0, 0).tabs) for n in (4, 6, 8, 10, 12, 16))
    assert total == TAB_SEGMENTS


# --- the verification ----------------------------------------------------------------------


@pytest.mark.parametrize("n", ALL_N)
def test_both_nets_fold_to_one_curve_for_every_face(n):
    rng = np.random.default_rng(n)
    for p in range(n):
        check_takeoff(n, 1.0, p, rng.uniform(-3, 3), random_frame(rng))


@given(
    n=st.sampled_from(ALL_N),
    p=st.integers(0, 15),
    r=st.floats(0.05, 20.0),
    y0=st.floats(-10.0, 10.0),
    seed=st.integers(0, 2**32 - 1),
)
def test_both_nets_fold_to_one_curve_random_frames(n, p, r, y0, seed):
    check_takeoff(n, r, p % n, y0 * r, random_frame(np.random.default_rng(seed), 10.0 * r))


@pytest.mark.parametrize("n", ALL_N)
def test_fish_mouth_is_where_the_branch_enters_the_trunk(n):
    """Independent of the profile formula: bisection on the n-face inside test."""
    j = takeoff_junction(n, 1.0, n - 1)  # m = e_u, s = e_v
    _, _, W = prism_numbers(n, 1.0)
    x = np.linspace(0.0, W, 997, endpoint=False)
    X = j.fold_branch(np.stack([x, np.zeros_like(x)], axis=1), np.eye(4))
    u, t = X[:, 1], X[:, 2]
    fm = j.fish_mouth
    cut = np.interp(x, np.r_[fm[:, 0], fm[0, 0] + W], np.r_[fm[:, 1], fm[0, 1]], period=W)
    assert_allclose(cut, entry_height(n, 1.0, u, t), atol=1e-12)


@pytest.mark.parametrize("n", ALL_N)
def test_fish_mouth_and_hole_have_the_same_vertices(n):
    j = takeoff_junction(n, 1.0, 0)
    assert j.fish_mouth.shape == j.hole.shape == j.hole_unwrapped.shape
    assert (np.diff(j.fish_mouth[:, 0]) > 1e-12).all()
    _, _, W = prism_numbers(n, 1.0)
    assert (j.fish_mouth[:, 0] >= 0).all() and (j.fish_mouth[:, 0] < W).all()
    assert (j.hole[:, 0] >= 0).all() and (j.hole[:, 0] < W).all()
    # every branch column is a vertex
    b, _, _ = prism_numbers(n, 1.0)
    for k in range(n):
        assert np.abs(j.fish_mouth[:, 0] - (k + 0.5) * b).min() < 1e-12


@pytest.mark.parametrize("n", [8, 12, 16])
def test_hole_vertices_lie_on_trunk_columns_when_n_is_0_mod_4(n):
    j = takeoff_junction(n, 1.0, 3)
    b, _, _ = prism_numbers(n, 1.0)
    k = (j.hole_unwrapped[:, 0] - j.face_centre) / b - 0.5
    assert_allclose(k, np.round(k), atol=1e-12)


@pytest.mark.parametrize("n", ALL_N)
def test_flush_faces_and_fold_angles(n):
    j = takeoff_junction(n, 1.0, 0)
    flush = [t for t in j.tabs if t.flush]
    if n % 4:
        assert not flush and not j.flush.any()
    else:
        assert len(flush) == 2
        assert sorted(t.trunkFace for t in flush) == [-(n // 4), n // 4]
        assert all(t.foldAngle == 0.0 for t in flush)
    for t in j.tabs:
        assert 0.0 <= t.foldAngle <= math.pi / 2 + 1e-15
        sigma = t.branchFace * 2 * math.pi / n
        if not t.flush:
            want = math.acos(math.cos(sigma) * math.sin(t.trunkFace * 2 * math.pi / n))
            assert t.foldAngle == pytest.approx(want, abs=1e-15)
        if abs(math.cos(sigma)) < 1e-12:  # the top and bottom faces
            assert t.foldAngle == pytest.approx(math.pi / 2)


def cross2(a, b):
    return a[0] * b[1] - a[1] * b[0]


@pytest.mark.parametrize(("n", "kinds"), [(6, {4}), (10, {3, 4}), (14, {3}), (16, {3, 4})])
def test_tab_shapes(n, kinds):
    j = takeoff_junction(n, 1.0, 0, tab_width=0.2)
    shapes = set()
    for tab in j.tabs:
        if tab.clipped:
            continue
        P = tab.polygon
        hinge = P[1] - P[0]
        length = np.linalg.norm(hinge)
        shapes.add(P.shape[0])
        if P.shape[0] == 4:
            assert length > 0.4
            for corner, end in ((P[2], P[1]), (P[3], P[0])):  # 45-degree chamfers, height w
                d = corner - end
                cosine = abs(d @ hinge) / (np.linalg.norm(d) * length)
                assert cosine == pytest.approx(math.cos(math.pi / 4))
                height = abs(cross2(hinge, d)) / length
                assert height == pytest.approx(0.2)
        else:
            assert P.shape[0] == 3 and length <= 0.4
            height = abs(cross2(hinge, P[2] - P[0])) / length
            assert height == pytest.approx(length / 2)
    assert shapes == kinds


def test_clipped_tabs_keep_their_hinge():
    j = takeoff_junction(10, 1.0, 0)
    clipped = [t for t in j.tabs if t.clipped]
    assert clipped  # at n = 10 the 45-degree chamfers next to the outer columns cross them
    for tab in clipped:
        seg = j.segments("fish_mouth")[tab.segment]
        assert_allclose(tab.polygon[:2], seg, atol=1e-12)


def test_wide_tabs_are_clipped_to_their_trunk_face():
    n = 6
    j = takeoff_junction(n, 1.0, 5, tab_width=0.5)
    assert any(t.clipped for t in j.tabs)
    b, _, _ = prism_numbers(n, 1.0)
    for tab in j.tabs:
        x_rel = tab.footprint[:, 0] - j.face_centre - tab.trunkFace * b
        assert (np.abs(x_rel) <= 0.5 * b + 1e-12).all()
    check_frame = random_frame(np.random.default_rng(7))
    for i, tab in enumerate(j.tabs):  # the clipped polygon still folds onto its footprint
        assert_allclose(j.fold_trunk(tab.footprint, check_frame), j.fold_tab(i, check_frame),
                        atol=1e-12)  # fmt: skip


def test_degenerate_square():
    j = takeoff_junction(4, 1.0, 0)
    assert j.degenerate and not takeoff_junction(6, 1.0, 0).degenerate
    assert j.max_depth == 0.0
    local = j.hole_unwrapped - [j.face_centre, 0.0]
    b, a, _ = prism_numbers(4, 1.0)
    assert_allclose(np.abs(local), a, atol=1e-15)  # all of panel p over |y - y0| <= a
    assert a == pytest.approx(b / 2)


# --- frames --------------------------------------------------------------------------------


@pytest.mark.parametrize("n", [6, 8])
def test_takeoff_frame(n):
    rng = np.random.default_rng(3)
    F = random_frame(rng)
    j = takeoff_junction(n, 1.5, 2, 0.7, stub_length=0.4)
    T = j.takeoff_frame(F)
    _, a, _ = prism_numbers(n, 1.5)
    phi = 3 * 2 * math.pi / n
    m = F[:3, :3] @ [math.cos(phi), math.sin(phi), 0.0]
    origin = F[:3, 3] + 0.7 * F[:3, 2]
    assert_allclose(T[:3, 3], origin + (a + 0.4) * m, atol=1e-14)
    assert_allclose(T[:3, 0], m, atol=1e-15)
    assert_allclose(T[:3, 2], F[:3, 2], atol=1e-15)
    assert_allclose(T[:3, :3].T @ T[:3, :3], np.eye(3), atol=1e-15)
    assert np.linalg.det(T[:3, :3]) == pytest.approx(1.0)
    # the branch's proximal marker x' = 0 points along s = y_D; the polygon at y' = a + h0 is
    # the tube section of T (vertex k at angle (k + 1/2) 2 pi / n from y_D about x_D)
    b = 2 * 1.5 * math.sin(math.pi / n)
    beta = (np.arange(n) + 0.5) * 2 * math.pi / n
    top = j.fold_branch(np.stack([(np.arange(n) + 0.5) * b, np.full(n, a + 0.4)], axis=1), F)
    want = T[:3, 3] + 1.5 * (np.cos(beta)[:, None] * T[:3, 1] + np.sin(beta)[:, None] * T[:3, 2])
    assert_allclose(top, want, atol=1e-13)
    marker = j.fold_branch([[0.0, a + 0.4]], F)[0]
    assert_allclose((marker - T[:3, 3]) / a, T[:3, 1], atol=1e-14)
    # the hole's face normal is m: the hole centre folds to O + a m
    assert_allclose(j.fold_trunk([[j.face_centre, 0.7]], F)[0], origin + a * m, atol=1e-14)


def test_frame_accepts_se3_and_rejects_non_rigid():
    from spatialmath import SE3

    j = takeoff_junction(6, 1.0, 0)
    F = SE3.Rx(0.3) * SE3.Trans(1, 2, 3)
    assert_allclose(j.takeoff_frame(F), j.takeoff_frame(F.A))
    with pytest.raises(InvalidParameterError, match="trunk_frame"):
        j.takeoff_frame(np.diag([1.0, 1.0, -1.0, 1.0]))
    with pytest.raises(InvalidParameterError, match="trunk_frame"):
        j.takeoff_frame(np.eye(3))
    with pytest.raises(InvalidTypeError, match="trunk_frame"):
        j.takeoff_frame("frame")


# --- sheet data ----------------------------------------------------------------------------


@pytest.mark.parametrize("n", [6, 8, 12])
def test_column_gaps(n):
    j = takeoff_junction(n, 1.0, n - 1, 2.0)  # the hole crosses the seam
    gaps = j.column_gaps()
    b, _, W = prism_numbers(n, 1.0)
    assert gaps.shape == ((n if n % 4 == 0 else n - 2) // 2, 3)
    for k, lo, hi in gaps:
        assert lo < 2.0 < hi
        x = (k + 0.5) * b
        x += W * round((j.face_centre - x) / W)
        pts = np.array([[x, lo], [x, hi]])
        # the gap's ends are on the hole's edge: just beyond them is outside
        assert not inside_polygon(pts + [[0, -1e-9], [0, 1e-9]], j.hole_unwrapped).any()
        assert inside_polygon(pts + [[1e-9 * np.sign(j.face_centre - x), 1e-9],
                                     [1e-9 * np.sign(j.face_centre - x), -1e-9]],
                              j.hole_unwrapped).all()  # fmt: skip


def test_hole_segments_are_in_the_sheet_strip():
    j = takeoff_junction(6, 1.0, 5)  # centred on the seam
    segs = j.hole_segments()
    b, _, W = prism_numbers(6, 1.0)
    xs = segs[:, :, 0]
    assert (xs >= -0.5 * b - 1e-12).all() and (xs <= W + 0.5 * b + 1e-12).all()
    # the hole's perimeter appears once in [0, W] (plus copies in the glue strips)
    lengths = np.linalg.norm(segs[:, 1] - segs[:, 0], axis=1)
    in_main = segs[:, :, 0].mean(axis=1)
    perimeter = np.linalg.norm(np.diff(j.segments("hole"), axis=1), axis=2).sum()
    main = (in_main >= 0) & (in_main <= W)
    assert lengths[main].sum() == pytest.approx(perimeter, rel=1e-12)


def test_skirt_outline_is_closed_and_below_the_cut():
    j = takeoff_junction(8, 1.0, 0)
    out = j.skirt_outline()
    assert_allclose(out[1:, 0], out[:-1, 1], atol=1e-15)  # consecutive
    start, end = out[0, 0], out[-1, 1]
    assert_allclose(end - start, [j.prism.W, 0.0], atol=1e-12)  # one turn
    assert (out[:, :, 1] <= j.fish_mouth[:, 1].max() + 1e-15).all()
    segs = j.skirt_outline_segments()
    assert (segs[:, :, 0] >= -0.5 * j.prism.b - 1e-12).all()


@pytest.mark.parametrize("n", ALL_N)
@pytest.mark.parametrize("h0", [0.0, 0.5])
def test_skirt_pattern(n, h0):
    j = takeoff_junction(n, 1.0, 1, stub_length=h0)
    skirt = j.skirt_pattern()
    assert isinstance(skirt, TubularPattern) and skirt.kind == "takeoff_skirt"
    assert skirt is TakeoffSkirtPattern(n, 1.0, h0)
    assert skirt.height == pytest.approx(j.max_depth + h0)
    assert skirt.proximalBase is None
    counts = SKIRT_KIND.counts(j.prism, skirt.modules[0].params)
    assert (counts.numVertices, counts.numEdges) == (skirt.numVertices, skirt.numEdges)
    assert SKIRT_KIND.rebuild(n, 1.0, skirt.modules[0].params) is skirt
    # problems other than the unknown kind's counts: none
    assert skirt.validate().ok
    if h0 > 0:
        assert skirt.numMountains == n
    # folded as a straight tube from the skirt frame: the fish-mouth lands where the branch
    # net puts it, and the distal frame is the take-off frame
    F = random_frame(np.random.default_rng(n))
    X, T_local = SKIRT_KIND.fold(j.prism, skirt, skirt.modules[0].params)
    D = j.skirt_frame(F)  # Dubins axes (m, s, e_a): the tube frame is (s, e_a, m)
    S = np.column_stack([D[:3, 1], D[:3, 2], D[:3, 0]])
    world = X @ S.T + D[:3, 3]
    V = j.numVertices
    assert_allclose(world[:V], j.fold_branch(j.fish_mouth, F), atol=1e-12)
    assert_allclose(D[:3, 3] + S @ T_local[:3, 3], j.takeoff_frame(F)[:3, 3], atol=1e-12)
    # a branch chain appends after it
    chain = skirt.append(TubeFittingPattern(n, 1.0, 1.0))
    assert chain.height == pytest.approx(skirt.height + 1.0)
    assert chain.validate().ok


def test_registered_skirt_folds_with_the_branch_chain():
    """Once SKIRT_KIND is in the catalog, the folded form of skirt + chain starts at the
    fish-mouth of the branch net and the chain starts at the take-off frame."""
    from kinegami.pattern.folded import folded_vertices

    n = 8
    j = takeoff_junction(n, 1.0, 3, 0.5, stub_length=0.3)
    F = random_frame(np.random.default_rng(11))
    sheet = j.skirt_pattern().append(TubeFittingPattern(n, 1.0, 2.0))
    registered = "takeoff_skirt" in catalog.kinds()
    catalog.register(SKIRT_KIND)
    try:
        X = folded_vertices(sheet, frame=j.skirt_frame(F))
    finally:
        if not registered:
            catalog.unregister("takeoff_skirt")
    assert_allclose(X[: j.numVertices], j.fold_branch(j.fish_mouth, F), atol=1e-12)
    _, a, _ = prism_numbers(n, 1.0)
    top = sheet.vertices_coords[sheet.distalBase]
    branch_xy = top + [0.0, j.skirt_base]  # the skirt's y is y' - skirt_base
    assert_allclose(X[sheet.distalBase], j.fold_branch(branch_xy, F), atol=1e-12)
    assert branch_xy[0, 1] == pytest.approx(a + 0.3 + 2.0)


# --- values and bad input ------------------------------------------------------------------


def test_values_are_read_only():
    j = takeoff_junction(6, 1.0, 0)
    for array in (j.fish_mouth, j.hole, j.hole_unwrapped, j.depth, j.flush, j.tabs[0].polygon,
                  j.tabs[0].footprint, j.column_gaps(), j.segment_trunk_faces):  # fmt: skip
        with pytest.raises(ValueError):
            array[0] = 0
    with pytest.raises(AttributeError):
        j.face = 2
    with pytest.raises(AttributeError):
        j.tabs[0].foldAngle = 1.0


def test_same_shape_for_every_face_and_height():
    a = takeoff_junction(10, 1.0, 0, 0.0)
    b = takeoff_junction(10, 1.0, 7, 3.0)
    assert_allclose(a.fish_mouth, b.fish_mouth)
    assert_allclose(a.hole_unwrapped - [a.face_centre, 0], b.hole_unwrapped - [b.face_centre, 3],
                    atol=1e-14)  # fmt: skip


@pytest.mark.parametrize(
    ("args", "kwargs", "error", "words"),
    [
        ((5, 1.0, 0), {}, InvalidParameterError, "numSides"),
        ((2, 1.0, 0), {}, InvalidParameterError, "numSides"),
        ((6.5, 1.0, 0), {}, InvalidTypeError, "numSides"),
        ((6, 0.0, 0), {}, InvalidParameterError, "r must"),
        ((6, 1.0, 6), {}, InvalidParameterError, r"face must be an integer in \[0, 5\]"),
        ((6, 1.0, -1), {}, InvalidParameterError, "face"),
        ((6, 1.0, "0"), {}, InvalidTypeError, "face"),
        ((6, 1.0, 0, float("nan")), {}, InvalidParameterError, "y0"),
        ((6, 1.0, 0, 2e6), {}, InvalidParameterError, "y0"),
        ((6, 1.0, 0), {"stub_length": -0.1}, InvalidParameterError, "stub_length"),
        ((6, 1.0, 0), {"tab_width": 0.0}, InvalidParameterError, r"tab_width must lie in \(0, r\]"),
        ((6, 1.0, 0), {"tab_width": 1.5}, InvalidParameterError, "tab_width"),
    ],
)
def test_bad_input(args, kwargs, error, words):
    with pytest.raises(error, match=words) as info:
        takeoff_junction(*args, **kwargs)
    assert isinstance(info.value, KinegamiError)
    assert isinstance(info.value, ValueError | TypeError)


def test_bad_segments_name():
    with pytest.raises(InvalidParameterError, match="which"):
        takeoff_junction(6, 1.0, 0).segments("skirt")
