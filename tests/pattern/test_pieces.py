"""A sheet cut into pieces across plain tube (kinegami.pattern.pieces, docs/fabrication.md
"Laser bed"): the pieces put back together are the sheet, exactly."""

from __future__ import annotations

import functools
import warnings

import numpy as np
import pytest

from kinegami.design import load_design_with_info
from kinegami.errors import InvalidParameterError, SplitError
from kinegami.pattern import TubeFittingPattern, TubularPattern
from kinegami.pattern.cutout import CutPattern
from kinegami.pattern.pieces import (
    cut_intervals,
    minimum_tube,
    needed_length,
    split_sheet,
    tube_spans,
)
from tests.gallery_designs import GALLERY, is_tree

from .pieces_helpers import reassembly_error, sheet_creases


@functools.cache
def sheets(path, junction: str = "connector") -> tuple:
    """The crease pattern of a gallery chain, or the sheets of a gallery tree."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain, info = load_design_with_info(path)
    if is_tree(path):
        from kinegami.fabrication.sheets import fabricate

        fabrication = fabricate(chain, twistPortion=info.twistPortion, junction=junction)
        return tuple(sheet.pattern for sheet in fabrication.sheets)
    return (chain.creasePattern(twistPortion=info.twistPortion),)


def _tab(pattern) -> float:
    return 0.5 * pattern.r


def _smallest_split(pattern):
    tab = _tab(pattern)
    need, _ = needed_length(pattern, tab)
    return split_sheet(pattern, need, tab=tab, name="test")


@pytest.mark.parametrize("path", GALLERY, ids=lambda p: p.stem)
def test_pieces_put_back_together_are_the_sheet(path):
    """Same creases, same assignments, within 1e-9 of the design's unit: every gallery sheet
    cut into as short pieces as it can be."""
    for pattern in sheets(path):
        pieces = _smallest_split(pattern)
        assert len(pieces) > 1
        assert reassembly_error(pattern, pieces) <= 1e-9


@pytest.mark.parametrize("path", GALLERY, ids=lambda p: p.stem)
def test_cuts_cross_plain_tube_with_room_for_tab_and_ticks(path):
    for pattern in sheets(path):
        tab = _tab(pattern)
        need, _ = needed_length(pattern, tab)
        pieces = _smallest_split(pattern)
        spans = tube_spans(pattern)
        tol = 1e-9 * pattern.r
        for piece in pieces:
            assert piece.length <= need + tol
            assert piece.pattern.validate().ok
        for piece in pieces[:-1]:
            c = piece.end
            assert any(s.y0 + 0.5 * tab - tol <= c <= s.y1 - tab + tol for s in spans), c
            assert pattern.modules[next(s.module for s in spans if s.y0 < c < s.y1)].kind == "tube"


def test_the_tab_repeats_the_next_pieces_plain_tube():
    (pattern,) = sheets(GALLERY[[p.stem for p in GALLERY].index("puma")])
    pieces = split_sheet(pattern, 590.0, tab=10.0)
    tol = 1e-9 * pattern.r
    for piece, following in zip(pieces[:-1], pieces[1:], strict=True):
        assert piece.tab == 10.0 and piece.end == following.start
        segments, kinds = sheet_creases(piece.pattern)
        on_tab = (segments[:, :, 1] >= piece.end - tol).all(axis=1)
        theirs, their_kinds = sheet_creases(following.pattern)
        start = np.abs(theirs[:, 0, 1] - following.start) <= tol  # the creases from its edge
        # the tab's creases are the tube's edges, mountains, where the next piece's start
        assert set(kinds[on_tab]) == {"M"} == set(their_kinds[start])
        mine = np.sort(segments[on_tab][:, 0, 0])
        next_ones = np.sort(theirs[start][:, 0, 0])
        np.testing.assert_allclose(mine, next_ones, atol=tol)
        np.testing.assert_allclose(segments[on_tab][:, 1, 1], piece.end + 10.0, atol=tol)
    assert pieces[-1].tab == 0.0


def test_alignment_ticks_of_two_pieces_continue_each_other():
    (pattern,) = sheets(GALLERY[[p.stem for p in GALLERY].index("puma")])
    pieces = split_sheet(pattern, 590.0, tab=10.0)
    b, W = pattern.sideLength, pattern.width
    for piece, following in zip(pieces[:-1], pieces[1:], strict=True):
        c = piece.end
        below = piece.marks[np.isclose(piece.marks[:, 1, 1], c) & np.isclose(piece.marks[:, 0, 1],
                                                                              c - 5.0)]
        above = following.marks[np.isclose(following.marks[:, 0, 1], c)
                                & np.isclose(following.marks[:, 1, 1], c + 5.0)]  # fmt: skip
        assert len(below) == len(above) >= pattern.numSides
        np.testing.assert_array_equal(below[:, 0, 0], above[:, 0, 0])
        xs = below[:, 0, 0]
        assert xs.min() >= -0.5 * b and xs.max() <= W + 0.5 * b
        # on panel centre lines: half a panel from the tube's edges (the creases)
        segments, _ = sheet_creases(piece.pattern)
        edges = np.unique(np.round(segments[(segments[:, :, 1] >= c - 1e-9).all(axis=1)][:, 0, 0],
                                   9))  # fmt: skip
        gaps = np.abs(xs[:, None] - edges[None, :]).min(axis=1)
        np.testing.assert_allclose(gaps, 0.5 * b, atol=1e-9)
        ys = piece.marks[:, :, 1]
        join = piece.marks[np.isclose(ys[:, 0], c) & np.isclose(ys[:, 1], c)]
        assert join.shape[0] == 1 and join[0, 0, 0] == -0.5 * b and join[0, 1, 0] == W + 0.5 * b


def test_labels_say_which_piece_and_where_it_joins():
    (pattern,) = sheets(GALLERY[[p.stem for p in GALLERY].index("puma")])
    pieces = split_sheet(pattern, 590.0, tab=10.0, name="PUMA 560", label_height=3.0)
    assert [label.text for label in pieces[1].labels] == [
        "PUMA 560, piece 2 of 5, joins piece 1 here",
        "PUMA 560, piece 2 of 5: glue this tab inside piece 3",
    ]
    assert [label.text for label in pieces[0].labels] == [
        "PUMA 560, piece 1 of 5: glue this tab inside piece 2"
    ]
    assert [label.text for label in pieces[-1].labels] == [
        "PUMA 560, piece 5 of 5, joins piece 4 here"
    ]
    for piece in pieces:
        for label in piece.labels:
            assert label.height == 3.0
            assert piece.start + 5.0 <= label.y <= piece.end + piece.tab - label.height
            assert label.x >= 0.5 * pattern.sideLength


def test_a_sheet_that_fits_is_one_piece_without_tab_or_marks():
    (pattern,) = sheets(GALLERY[[p.stem for p in GALLERY].index("example1")])
    (piece,) = split_sheet(pattern, pattern.height + 1.0, tab=1.0)
    assert piece.pattern is pattern and piece.tab == 0.0 and piece.marks.shape == (0, 2, 2)
    assert piece.labels == ()


def test_a_stretch_without_plain_tube_longer_than_a_piece_is_named():
    (pattern,) = sheets(GALLERY[[p.stem for p in GALLERY].index("puma")])
    need, stretch = needed_length(pattern, 10.0)
    # the PUMA's end: elbows, a joint, a twist and an end tip after the last long plain tube
    assert need == pytest.approx(519.53, abs=0.01)
    assert (stretch.y0, stretch.y1) == pytest.approx((1925.8, 2435.3), abs=0.1)
    assert {"elbow", "revolute", "twist", "end_tip"} <= set(stretch.kinds)
    split_sheet(pattern, need, tab=10.0)  # the needed length works
    with pytest.raises(SplitError, match=r"from 1925\.8 to 2435\.33 along it there is no plain "
                                         r"tube of at least 15 ") as error:  # fmt: skip
        split_sheet(pattern, need * (1 - 1e-6), tab=10.0)
    assert error.value.needed == need and isinstance(error.value, ValueError)


def test_needed_length_is_the_shortest_that_splits_every_gallery_sheet():
    for path in GALLERY:
        for pattern in sheets(path):
            tab = _tab(pattern)
            need, _ = needed_length(pattern, tab)
            split_sheet(pattern, need, tab=tab)
            with pytest.raises(SplitError):
                split_sheet(pattern, need - 1e-6 * pattern.r, tab=tab)


def test_a_cut_needs_a_tab_and_a_half_of_plain_tube():
    n, r = 6, 1.0
    assert minimum_tube(2.0) == 3.0
    short = TubularPattern.concatenate([TubeFittingPattern(n, r, 2.9)])
    assert cut_intervals(short, 2.0) == []
    enough = TubularPattern.concatenate([TubeFittingPattern(n, r, 3.0)])
    assert cut_intervals(enough, 2.0) == [(1.0, 1.0)]


def test_take_off_sheets_keep_their_holes_and_skirt():
    path = GALLERY[[p.stem for p in GALLERY].index("hand")]
    for pattern in sheets(path, "takeoff"):
        assert isinstance(pattern, CutPattern)
        pieces = _smallest_split(pattern)
        assert all(isinstance(piece.pattern, CutPattern) for piece in pieces)
        assert sum(len(piece.pattern.holes) for piece in pieces) == len(pattern.holes)
        assert [piece.pattern.skirt is not None for piece in pieces] == (
            [pattern.skirt is not None] + [False] * (len(pieces) - 1))
        assert reassembly_error(pattern, pieces) <= 1e-9
        # no cut crosses a hole's tube
        holed = {hole.module for hole in pattern.holes}
        assert not holed & {span.module for span in tube_spans(pattern)}


def test_a_pattern_without_module_places_is_refused():
    two = TubeFittingPattern(4, 1.0, 10.0).append(TubeFittingPattern(4, 1.0, 5.0))
    pattern = two.reversed()  # a reversed composite does not know where its modules went
    assert pattern.module_vertices is None
    with pytest.raises(InvalidParameterError, match="does not record where its modules are"):
        split_sheet(pattern, 4.0, tab=1.0)
