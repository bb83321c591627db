"""First-fit decreasing packing of rectangles onto bins (kinegami.geometry.packing)."""

from __future__ import annotations

import itertools

import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinegami.errors import InvalidParameterError
from kinegami.geometry.packing import pack_rectangles


def _check(sizes, bin_size, margin, gap, placements):
    """Every rectangle inside its bin within the margin, its own size (turned or not), and
    rectangles of one bin at least ``gap`` apart."""
    bw, bh = bin_size
    tol = 1e-9 * max(bin_size)
    assert len(placements) == len(sizes)
    for (w, h), p in zip(sizes, placements, strict=True):
        assert (p.width, p.height) == ((h, w) if p.rotated else (w, h))
        assert p.x >= margin - tol and p.y >= margin - tol
        assert p.x + p.width <= bw - margin + tol and p.y + p.height <= bh - margin + tol
    for a, b in itertools.combinations(placements, 2):
        if a.bin != b.bin:
            continue
        apart_x = a.x + a.width + gap <= b.x + tol or b.x + b.width + gap <= a.x + tol
        apart_y = a.y + a.height + gap <= b.y + tol or b.y + b.height + gap <= a.y + tol
        assert apart_x or apart_y, (a, b)
    used = {p.bin for p in placements}
    assert used == set(range(len(used)))  # bins numbered from 0, none empty


def test_strips_go_side_by_side_then_onto_a_new_bin():
    placements = pack_rectangles([(10, 50)] * 3, (25, 60))
    assert [p.bin for p in placements] == [0, 0, 1]
    _check([(10, 50)] * 3, (25, 60), 0.0, 0.0, placements)


def test_a_strip_is_turned_when_only_that_fits():
    (p,) = pack_rectangles([(50, 10)], (20, 60), margin=2)
    assert p.rotated and (p.width, p.height) == (10, 50)


def test_too_large_a_rectangle_is_refused_naming_it():
    with pytest.raises(InvalidParameterError, match=r"sizes\[1\] = 70 x 10 does not fit"):
        pack_rectangles([(10, 10), (70, 10)], (60, 60), margin=1)


@settings(max_examples=150, deadline=None)
@given(
    sizes=st.lists(st.tuples(st.floats(1, 60), st.floats(1, 60)), min_size=1, max_size=25),
    bin_size=st.tuples(st.floats(70, 150), st.floats(70, 150)),
    margin=st.floats(0, 4),
    gap=st.floats(0, 4),
)
def test_every_rectangle_fits_and_none_overlap(sizes, bin_size, margin, gap):
    placements = pack_rectangles(sizes, bin_size, margin=margin, gap=gap)
    _check(sizes, bin_size, margin, gap, placements)
    # first fit: no more bins than rectangles, and one bin when they all fit in a row
    assert max(p.bin for p in placements) < len(sizes)
