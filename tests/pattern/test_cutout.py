"""Sheets with take-off cut-outs (kinegami.pattern.cutout): the trunk's sheet with its hole, the
branch's sheet with its skirt and glue tabs, drawn as lines of the flat sheet."""

from __future__ import annotations

import math

import numpy as np
import pytest
from numpy.testing import assert_allclose

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.pattern import (
    ElbowFittingPattern,
    TubeFittingPattern,
    TubularPattern,
    TwistFittingPattern,
)
from kinegami.pattern.cutout import CutPattern, SheetHole, flatten_cut
from kinegami.pattern.sheet import flatten
from kinegami.pattern.takeoff import takeoff_junction

from .helpers import prism_numbers

ALL_N = (4, 6, 8, 10, 12, 16)
#: Tube module height and hole height of the trunk tests (r = 1).
TUBE, Y0 = 4.0, 2.0
TOL = 1e-9


def trunk(n: int, face: int, y0: float = Y0):
    """A twist, a plain tube holding a hole in ``face``, an elbow; and the junction."""
    modules = [TwistFittingPattern(n, 1.0, 0.4, 0.5), TubeFittingPattern(n, 1.0, TUBE),
               ElbowFittingPattern(n, 1.0, 0.6, 0.3)]  # fmt: skip
    j = takeoff_junction(n, 1.0, face, y0)
    return CutPattern(TubularPattern.concatenate(modules), holes=[SheetHole("A", 1, j)]), j


def branch(n: int, face: int = 0):
    """A skirt followed by a tube; and the junction."""
    j = takeoff_junction(n, 1.0, face, 0.0)
    pattern = TubularPattern.concatenate([j.skirt_pattern(), TubeFittingPattern(n, 1.0, 2.0)])
    return CutPattern(pattern, skirt=j), j


def point_segment_distance(points, segments) -> np.ndarray:
    """Distance from each point to the nearest segment, shape (m,)."""
    a, c = segments[None, :, 0], segments[None, :, 1]
    d = c - a
    t = np.clip(((points[:, None] - a) * d).sum(-1) / np.maximum((d * d).sum(-1), 1e-300), 0, 1)
    return np.linalg.norm(a + t[..., None] * d - points[:, None], axis=-1).min(axis=1)


def on_lines(points, segments) -> np.ndarray:
    return point_segment_distance(points, segments) <= TOL


def samples(segments, fractions=(0.2, 0.5, 0.8)) -> np.ndarray:
    f = np.asarray(fractions)[None, :, None]
    return (segments[:, :1] + f * (segments[:, 1:] - segments[:, :1])).reshape(-1, 2)


def inside(points, poly) -> np.ndarray:
    x, y = points[:, :1], points[:, 1:]
    xa, ya = poly[:, 0], poly[:, 1]
    xb, yb = np.roll(xa, -1), np.roll(ya, -1)
    crosses = (ya > y) != (yb > y)
    with np.errstate(divide="ignore", invalid="ignore"):
        xc = xa + (y - ya) * (xb - xa) / (yb - ya)
    return (np.count_nonzero(crosses & (x < xc), axis=1) % 2) == 1


def strip_copies(poly, W, b):
    """The polygon's copies at -W, 0, +W that reach into the strip -b/2 < x < W + b/2."""
    out = []
    for s in (-W, 0.0, W):
        q = poly + [s, 0.0]
        if q[:, 0].max() > -0.5 * b + TOL and q[:, 0].min() < W + 0.5 * b - TOL:
            out.append(q)
    return out


def closed_loops(segments) -> bool:
    """Every end point is shared by an even number of segment ends (the lines close up)."""
    ends = np.round(segments.reshape(-1, 2), 7)
    _, counts = np.unique(ends, axis=0, return_counts=True)
    return bool((counts % 2 == 0).all())


# --- the trunk's sheet ---------------------------------------------------------------------


@pytest.mark.parametrize("n", ALL_N)
@pytest.mark.parametrize("which", ["middle", "seam"])
def test_the_hole_is_cut_and_no_crease_is_left_inside_it(n, which):
    """The hole's edges (each copy, clipped to the strip) are cut lines; no crease or boundary
    line has a point inside the hole; the cut lines close up."""
    b, _, W = prism_numbers(n, 1.0)
    face = n // 2 - 1 if which == "middle" else n - 1  # centre x = W/2, or on the seam
    cut, j = trunk(n, face)
    sheet = flatten_cut(cut)
    [hole] = cut.hole_polygons()
    copies = strip_copies(hole, W, b)
    assert len(copies) == (1 if which == "middle" else 2)
    cuts = sheet.select("C")
    for poly in copies:
        edges = np.stack([poly, np.roll(poly, -1, axis=0)], axis=1)
        pts = samples(edges)
        in_strip = (pts[:, 0] > -0.5 * b + TOL) & (pts[:, 0] < W + 0.5 * b - TOL)
        assert on_lines(pts[in_strip], cuts).all()
        for kind in ("M", "V", "B"):
            lines = sheet.select(kind)
            if lines.shape[0]:
                assert not inside(samples(lines, (0.01, 0.5, 0.99)), poly).any(), kind
    assert closed_loops(cuts)
    # the sheet's outline is the pattern's, less what the hole takes
    assert sheet.bounds == flatten(cut.pattern).bounds


@pytest.mark.parametrize("n", ALL_N)
def test_the_hole_interrupts_exactly_the_columns_it_crosses(n):
    """Every trunk column keeps its crease outside [y_low, y_high] of column_gaps and loses it
    inside: the total column length lost is the gaps' length."""
    b, _, W = prism_numbers(n, 1.0)
    cut, j = trunk(n, n // 2 - 1)
    whole, sheet = flatten(cut.pattern), flatten_cut(cut)
    dx, dy = cut.hole_offset(cut.holes[0])
    gaps = j.column_gaps()

    def column_length(s, x):
        m = s.select("M")
        vertical = (np.abs(m[:, 0, 0] - x) < TOL) & (np.abs(m[:, 1, 0] - x) < TOL)
        return float(np.abs(m[vertical, 1, 1] - m[vertical, 0, 1]).sum())

    for k, low, high in gaps.tolist():
        x = (k + 0.5) * b + dx
        x -= W * math.floor(x / W)
        lost = column_length(whole, x) - column_length(sheet, x)
        assert lost == pytest.approx(high - low, abs=1e-9)
    assert len(gaps) >= 2


def test_a_trunk_sheet_keeps_everything_away_from_its_hole():
    """Lines far from the hole are those of the pattern's own sheet."""
    cut, _ = trunk(8, 3)
    whole, sheet = flatten(cut.pattern), flatten_cut(cut)
    [hole] = cut.hole_polygons()
    lo, hi = hole[:, 1].min() - 0.5, hole[:, 1].max() + 0.5

    def far(s, kind):
        return {tuple(np.round(x, 9).ravel()) for x in s.select(kind)
                if x[:, 1].max() < lo or x[:, 1].min() > hi}  # fmt: skip

    for kind in ("M", "V"):
        assert far(whole, kind) == far(sheet, kind)


# --- the branch's sheet --------------------------------------------------------------------


@pytest.mark.parametrize("n", ALL_N)
def test_the_skirt_sheet_is_cut_along_its_tabs(n):
    """The outline below the skirt is the tabs' free edges (every tab, and its copy in the glue
    panel); nothing is drawn below the fish-mouth outside the tabs; the tabs' hinges are valley
    creases (not on flush segments); the lines close; the sheet reaches down to the tabs."""
    b, a, W = prism_numbers(n, 1.0)
    cut, j = branch(n)
    sheet = flatten_cut(cut)
    regions = cut.regions()
    cuts = sheet.select("C")
    free = regions.tab_outline_segments()
    pts = samples(free)
    in_strip = (pts[:, 0] > -0.5 * b + TOL) & (pts[:, 0] < W + 0.5 * b - TOL)
    assert on_lines(pts[in_strip], cuts).all()
    assert closed_loops(cuts)
    # the hinges (non-flush fish-mouth segments) are valleys
    mouth, hinged = regions.mouth_segments()
    mid = samples(mouth, (0.5,))
    keep = (mid[:, 0] > -0.5 * b + TOL) & (mid[:, 0] < W + 0.5 * b - TOL)
    valleys = sheet.select("V")
    assert on_lines(mid[keep & hinged], valleys).all()
    if (~hinged).any():
        assert not on_lines(mid[keep & ~hinged], valleys).any()
    # no line below the fish-mouth except inside a tab or on its outline
    for kind in "MVB":
        lines = sheet.select(kind)
        p = samples(lines, (0.5,))
        below = p[:, 1] < regions.mouth_height(p[:, 0]) - 1e-7
        in_tab = np.zeros(p.shape[0], dtype=bool)
        for poly in regions.tabs:
            in_tab |= inside(p, poly)
        assert not (below & ~in_tab).any(), kind
    lowest = min(float(t[:, 1].min()) for t in regions.tabs)
    assert sheet.y0 == pytest.approx(lowest)
    assert sheet.y0 + sheet.height == pytest.approx(cut.pattern.height)
    assert lowest == pytest.approx(-j.tab_width, abs=1e-12) or lowest > -j.tab_width


@pytest.mark.parametrize("n", (6, 8, 12))
def test_the_fish_mouth_is_the_tube_boundary(n):
    """Within [0, W] the nominal tube's lower edge is the fish-mouth."""
    _, _, W = prism_numbers(n, 1.0)
    cut, _ = branch(n)
    sheet = flatten_cut(cut)
    regions = cut.regions()
    xs = np.linspace(0.0, W, 97)
    on_mouth = np.stack([xs, regions.mouth_height(xs)], axis=1)
    assert on_lines(on_mouth, sheet.select("B")).all()


def test_cut_patterns_flatten_through_flatten_and_show():
    cut, _ = branch(6)
    assert np.array_equal(flatten(cut).segments, flatten_cut(cut).segments)
    assert flatten(cut, skip_creases_on_cut=True).numLines <= flatten(cut).numLines


# --- bad input -----------------------------------------------------------------------------


def test_bad_cut_patterns_name_what_is_wrong():
    tube = TubularPattern.concatenate([TwistFittingPattern(6, 1.0, 0.4, 0.5),
                                       TubeFittingPattern(6, 1.0, TUBE)])  # fmt: skip
    j = takeoff_junction(6, 1.0, 0, Y0)
    with pytest.raises(InvalidTypeError, match="pattern must be a TubularPattern"):
        CutPattern("not a pattern")
    with pytest.raises(InvalidTypeError, match=r"holes\[0\] must be a SheetHole"):
        CutPattern(tube, holes=[j])
    with pytest.raises(InvalidParameterError, match=r"holes\[0\]\.module: module 0 is a 'twist'"):
        CutPattern(tube, holes=[SheetHole("A", 0, j)])
    with pytest.raises(InvalidParameterError, match=r"holes\[0\]\.module must be a module index"):
        CutPattern(tube, holes=[SheetHole("A", 5, j)])
    low = takeoff_junction(6, 1.0, 0, 0.5)  # the hole and its margin reach below the tube
    with pytest.raises(InvalidParameterError, match=r"holes\[0\]: the hole and its margin"):
        CutPattern(tube, holes=[SheetHole("A", 1, low)])
    with pytest.raises(InvalidParameterError, match=r"holes\[0\]\.junction is for n = 8"):
        CutPattern(tube, holes=[SheetHole("A", 1, takeoff_junction(8, 1.0, 0, Y0))])
    with pytest.raises(InvalidParameterError, match="skirt: the pattern must start"):
        CutPattern(tube, skirt=j)
    with pytest.raises(InvalidParameterError, match="frame must be a finite 4x4"):
        CutPattern(tube, frame=np.eye(3))
    with pytest.raises(InvalidTypeError, match="cut must be a CutPattern"):
        flatten_cut(tube)


def test_hole_offset_follows_the_module():
    """The hole sits where composition put its tube module: the module's first vertex."""
    cut, j = trunk(6, 2)
    record_vertices = cut.pattern.module_vertices[1]
    dx, dy = cut.hole_offset(cut.holes[0])
    first = cut.pattern.vertices_coords[record_vertices[0]]
    b, _, W = prism_numbers(6, 1.0)
    assert_allclose([np.mod(first[0] - 0.5 * b, W), first[1]], [dx, dy], atol=1e-12)
