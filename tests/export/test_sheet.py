"""Flattening (spec/patterns.md section 5, fix B8, B10) and the periodicity check 7.5."""

import math

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.pattern import TubeFittingPattern, TubularPattern
from kinegami.pattern.sheet import (
    check_periodicity,
    clip_segments,
    flatten,
    unique_segments,
)

from .conftest import build
from .helpers import duplicate_pairs, lengths
from .reference_values import CLIPPED_COUNTS, CREASES_ON_CUT, OUTLINE_LINES


@pytest.mark.parametrize("name", list(CLIPPED_COUNTS))
def test_clipped_line_counts(name):
    spec, (mountains, valleys) = CLIPPED_COUNTS[name]
    sheet = flatten(build(spec))
    counts = tuple(sheet.count(k) for k in "MVBC")
    assert counts == (mountains, valleys, OUTLINE_LINES, OUTLINE_LINES)


def test_boundary_and_cut_rectangles(revolute6):
    sheet = flatten(revolute6)
    W, b, H = revolute6.width, revolute6.sideLength, revolute6.height
    for kind, (x0, x1) in (("B", (0.0, W)), ("C", (-b / 2, W + b / 2))):
        seg = sheet.select(kind)
        assert_allclose(np.sort(seg[:, :, 0].ravel()), np.repeat([x0, x1], 4), atol=1e-12)
        assert_allclose(np.sort(seg[:, :, 1].ravel()), np.repeat([0.0, H], 4), atol=1e-12)
        assert_allclose(lengths(seg).sum(), 2 * (x1 - x0) + 2 * H)
    assert_allclose(sheet.bounds, (-b / 2, 0.0, W + b / 2, H))
    assert_allclose(sheet.boundary, (0.0, 0.0, W, H))
    assert_allclose(sheet.glueTabs, ((-b / 2, b / 2), (W - b / 2, W + b / 2)))


def test_sheet_order_and_kinds(composite6):
    sheet = flatten(composite6)
    kinds = "".join(sheet.kinds.tolist())
    m, v = sheet.count("M"), sheet.count("V")
    assert kinds == "M" * m + "V" * v + "BBBBCCCC"
    assert sheet.numLines == m + v + 8
    assert "M=" in repr(sheet)


@pytest.mark.parametrize("name", list(CLIPPED_COUNTS))
def test_creases_inside_sheet_none_on_vertical_cut_edges(name):
    sheet = flatten(build(CLIPPED_COUNTS[name][0]))
    xmin, ymin, xmax, ymax = sheet.bounds
    tol = sheet.tolerance
    creases = sheet.segments[np.isin(sheet.kinds, ("M", "V"))]
    xs, ys = creases[:, :, 0], creases[:, :, 1]
    assert (xs >= xmin - tol).all() and (xs <= xmax + tol).all()
    assert (ys >= ymin - tol).all() and (ys <= ymax + tol).all()
    assert not ((np.abs(xs - xmin) <= tol).all(axis=1)).any()
    assert not ((np.abs(xs - xmax) <= tol).all(axis=1)).any()


def test_no_zero_length_or_duplicate_lines(composite6):
    sheet = flatten(composite6)
    assert lengths(sheet.segments).min() > sheet.tolerance
    assert duplicate_pairs(sheet.segments, sheet.kinds, 1e-9) == []


@pytest.mark.parametrize("n", [4, 6])
def test_periodicity_of_composite(n):
    from .conftest import build_composite

    assert check_periodicity(flatten(build_composite(n))) == []


def test_periodicity_check_finds_a_missing_copy(revolute6):
    sheet = flatten(revolute6)
    W, b = sheet.width, sheet.sideLength
    creases = sheet.segments[:-8]
    right = (creases[:, :, 0] > W - b / 2 + 1e-6).all(axis=1)
    victim = int(np.flatnonzero(right)[0])
    keep = np.ones(sheet.numLines, dtype=bool)
    keep[victim] = False
    broken = sheet._replace(segments=sheet.segments[keep], kinds=sheet.kinds[keep])
    problems = check_periodicity(broken)
    assert problems and any("no counterpart" in p or "pieces" in p for p in problems)


def test_periodicity_check_finds_a_relabelled_copy(revolute6):
    sheet = flatten(revolute6)
    b = sheet.sideLength
    kinds = sheet.kinds.copy()
    inside = (sheet.segments[:, :, 0] < b / 2 - 1e-6).all(axis=1) & np.isin(kinds, ("M", "V"))
    i = int(np.flatnonzero(inside)[0])
    kinds[i] = "V" if kinds[i] == "M" else "M"
    broken = sheet._replace(kinds=kinds)
    assert check_periodicity(broken)


@pytest.mark.parametrize("name", list(CREASES_ON_CUT))
def test_skip_creases_on_cut(name):
    pattern = build(CLIPPED_COUNTS[name][0])
    kept = flatten(pattern)
    skipped = flatten(pattern, skip_creases_on_cut=True)
    dm, dv = CREASES_ON_CUT[name]
    assert kept.count("M") - skipped.count("M") == dm
    assert kept.count("V") - skipped.count("V") == dv
    creases = skipped.segments[np.isin(skipped.kinds, ("M", "V"))]
    ys = creases[:, :, 1]
    horizontal = np.abs(ys[:, 0] - ys[:, 1]) <= 1e-9
    on_edge = (np.abs(ys) <= 1e-9).all(axis=1) | (np.abs(ys - pattern.height) <= 1e-9).all(axis=1)
    assert not (horizontal & on_edge).any()
    assert check_periodicity(skipped) == []


def _custom(n, points, creases, labels):
    """A pattern with the given vertices and creases (bases: the n points of the first ring)."""
    b = 2 * math.sin(math.pi / n)
    ring = [((k + 0.5) * b, 0.0) for k in range(n)]
    top = [((k + 0.5) * b, 1.0) for k in range(n)]
    vertices = ring + top + list(points)
    edges = [(2 * n + i, 2 * n + j) for i, j in creases]
    return TubularPattern(
        n, 1.0, vertices, edges, labels, list(range(n)), list(range(n, 2 * n)),
        (0.0, 0.0), (0.0, 1.0), 1.0,
    )  # fmt: skip


def test_wrapping_crease_is_drawn_at_both_ends():
    n = 4
    b = 2 * math.sin(math.pi / n)
    W = n * b
    p = _custom(n, [(W - 0.2 * b, 0.25), (0.3 * b, 0.75)], [(0, 1)], ["V"])
    sheet = flatten(p)
    valleys = sheet.select("V")
    assert valleys.shape[0] == 2
    xs = np.sort(valleys[:, :, 0], axis=1)
    xs = xs[np.argsort(xs[:, 0])]
    assert_allclose(xs, [[-0.2 * b, 0.3 * b], [W - 0.2 * b, W + 0.3 * b]], atol=1e-12)
    assert check_periodicity(sheet) == []


def test_copies_are_clipped_to_the_cut():
    n = 4
    b = 2 * math.sin(math.pi / n)
    W = n * b
    # a crease from the seam to x = 0.9 b: its copy shifted by +W is cut at x = W + b/2
    p = _custom(n, [(0.0, 0.0), (0.9 * b, 1.0)], [(0, 1)], ["M"])
    sheet = flatten(p)
    m = sheet.select("M")
    assert m.shape[0] == 2
    clipped = m[np.argmax(m[:, :, 0].max(axis=1))]
    assert_allclose(clipped[:, 0].max(), W + b / 2, atol=1e-12)
    assert_allclose(clipped[np.argmax(clipped[:, 0]), 1], (0.5 * b) / (0.9 * b), atol=1e-12)


def test_exactly_opposite_vertices_follow_the_stored_order():
    n = 4
    b = 2 * math.sin(math.pi / n)
    W = n * b
    points = [(0.5 * b, 0.2), (2.5 * b, 0.8)]
    direct = flatten(_custom(n, points, [(0, 1)], ["M"])).select("M")
    wrapped = flatten(_custom(n, points, [(1, 0)], ["M"])).select("M")
    assert direct.shape[0] == 1
    assert_allclose(np.sort(direct[0, :, 0]), [0.5 * b, 2.5 * b], atol=1e-12)
    assert wrapped.shape[0] == 2
    spans = np.sort(np.sort(wrapped[:, :, 0], axis=1), axis=0)
    assert_allclose(spans, [[-0.5 * b, 0.5 * b], [2.5 * b, W + 0.5 * b]], atol=1e-12)


def test_clip_segments_rules():
    segs = np.array(
        [
            [[-1.0, 0.0], [-1.0, 1.0]],  # vertical on the left edge: dropped
            [[2.0, 0.0], [2.0, 1.0]],  # vertical on the right edge: dropped
            [[0.5, 0.0], [0.5, 1.0]],  # vertical inside: kept
            [[-2.0, 0.0], [3.0, 5.0]],  # crossing both edges: clipped
            [[-3.0, 0.0], [-1.0, 1.0]],  # outside, touching the edge: dropped
            [[2.0, 0.0], [2.0 + 1e-13, 1.0]],  # nearly vertical on the edge: dropped
        ]
    )
    keep, clipped = clip_segments(segs, -1.0, 2.0, 1e-9)
    assert keep.tolist() == [False, False, True, True, False, False]
    assert_allclose(clipped[3], [[-1.0, 1.0], [2.0, 4.0]])
    assert clipped[3, 0, 0] == -1.0 and clipped[3, 1, 0] == 2.0


def test_unique_segments_either_orientation_same_kind_only():
    segs = np.array(
        [
            [[0.0, 0.0], [1.0, 1.0]],
            [[1.0, 1.0 + 1e-12], [0.0, 0.0]],  # same, reversed, within tolerance
            [[0.0, 0.0], [1.0, 1.0]],  # same geometry, other kind
            [[0.0, 0.0], [1.0, 1.0 + 1e-6]],  # different
        ]
    )
    kinds = np.array(["M", "M", "V", "M"])
    assert unique_segments(segs, kinds, 1e-9).tolist() == [True, False, True, True]


def _first_of_each_group(segs: np.ndarray, kinds, tol: float) -> list[bool]:
    """unique_segments written out: coordinates grouped by single linkage (sorted values less
    than tol apart share a group), then each line compared with the earlier ones."""

    def groups(values):
        order = sorted(range(len(values)), key=values.__getitem__)
        ids, group = [0] * len(values), 0
        for a, b in zip(order[:-1], order[1:], strict=True):
            group += values[b] - values[a] > tol
            ids[b] = group
        return ids

    gx = groups(segs[:, :, 0].ravel().tolist())
    gy = groups(segs[:, :, 1].ravel().tolist())
    seen, keep = set(), []
    for i, kind in enumerate(kinds):
        ends = sorted([(gx[2 * i], gy[2 * i]), (gx[2 * i + 1], gy[2 * i + 1])])
        key = (str(kind), tuple(ends))
        keep.append(key not in seen)
        seen.add(key)
    return keep


@given(
    st.lists(st.tuples(st.integers(0, 5), st.integers(0, 5), st.integers(0, 5),
                       st.integers(0, 5), st.sampled_from("MVBCF")), max_size=60),
    st.lists(st.floats(-1.0, 1.0), min_size=240, max_size=240),
    st.sampled_from(["<U1", "<U2", "object"]),
)  # fmt: skip
def test_unique_segments_keeps_the_first_of_every_group(rows, noise, dtype):
    """Random lines on a coarse grid, each coordinate moved by up to 0.3 tol (so near values
    group, also in chains), any kind dtype: the first of each group of equal lines stays."""
    tol = 1e-3
    segs = np.array([r[:4] for r in rows], dtype=float).reshape(-1, 2, 2) * 0.01
    segs += 0.3 * tol * np.array(noise[: segs.size]).reshape(segs.shape)
    kinds = np.array([r[4] for r in rows], dtype=dtype)
    assert unique_segments(segs, kinds, tol).tolist() == _first_of_each_group(segs, kinds, tol)


def test_unique_segments_with_many_groups_falls_back_to_a_sort_by_columns():
    """Too many distinct groups for one 64-bit key: the same answer."""
    rng = np.random.default_rng(3)
    segs = np.round(rng.uniform(0, 1, (40000, 2, 2)), 5)
    segs[20000:] = segs[:20000][:, ::-1]  # every line again, reversed
    kinds = np.array(["M"] * 40000)
    keep = unique_segments(segs, kinds, 1e-9)
    assert keep.tolist() == _first_of_each_group(segs, kinds, 1e-9)
    assert not keep[20000:].any()


def test_sheet_is_read_only(revolute6):
    sheet = flatten(revolute6)
    with pytest.raises(ValueError):
        sheet.segments[0, 0, 0] = 1.0
    with pytest.raises(AttributeError):
        sheet.width = 2.0


def test_bad_arguments():
    with pytest.raises(InvalidTypeError):
        flatten("not a pattern")
    with pytest.raises(InvalidTypeError):
        flatten(TubeFittingPattern(4, 1.0, 1.0), skip_creases_on_cut="yes")
    with pytest.raises(InvalidParameterError, match="kind"):
        flatten(TubeFittingPattern(4, 1.0, 1.0)).count("X")


def test_units_follow_r():
    small, big = (
        flatten(TubeFittingPattern(6, 1.0, 2.0)),
        flatten(TubeFittingPattern(6, 10.0, 20.0)),
    )
    assert_allclose(big.segments, 10.0 * small.segments, atol=1e-12)
    assert big.tolerance == pytest.approx(10.0 * small.tolerance)
