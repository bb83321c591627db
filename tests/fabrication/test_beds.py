"""The laser bed and the sheet material (kinegami.fabrication.beds, docs/fabrication.md "Laser
bed" and "Material"): every piece fits the bed, pieces are nested onto few beds, and a sheet
that cannot be cut to fit fails naming the stretch and the smallest bed."""

from __future__ import annotations

import functools
import itertools
import warnings

import pytest

from kinegami.design import load_design_with_info
from kinegami.errors import BedTooSmallError, InvalidParameterError, InvalidTypeError
from kinegami.fabrication.beds import Bed, Material, check_material, lay_out, parse_bed
from kinegami.validation import UNITS_IN_MM
from tests.gallery_designs import GALLERY, is_tree

#: The PUMA arm (r = 25 mm, a strip 175 mm wide and 2,435 mm long) on common beds: pieces and
#: bed sheets (docs/fabrication.md).
PUMA_BEDS = {(600, 400): (5, 3), (1000, 600): (3, 1)}


@functools.cache
def gallery_sheets(path) -> tuple:
    """(sheets, mm per pattern unit, name) of a gallery design."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain, info = load_design_with_info(path)
    if is_tree(path):
        from kinegami.fabrication.sheets import fabricate

        patterns = tuple(s.pattern for s in fabricate(chain, twistPortion=info.twistPortion).sheets)
    else:
        patterns = (chain.creasePattern(twistPortion=info.twistPortion),)
    return patterns, UNITS_IN_MM[info.units], info.name


def _puma():
    (pattern,), unit, name = gallery_sheets(GALLERY[[p.stem for p in GALLERY].index("puma")])
    return pattern, unit, name


def _check_fits(layout) -> None:
    """Every piece inside its bed within the margin, and pieces of one bed apart by it."""
    bed, tol = layout.bed, 1e-9
    for place, bounds in zip(layout.placements, layout.bounds, strict=True):
        w = (bounds[2] - bounds[0]) * layout.unit
        h = (bounds[3] - bounds[1]) * layout.unit
        assert (place.width, place.height) == pytest.approx((h, w) if place.rotated else (w, h))
        assert place.x >= bed.margin - tol and place.y >= bed.margin - tol
        assert place.x + place.width <= bed.width - bed.margin + tol
        assert place.y + place.height <= bed.height - bed.margin + tol
    for a, b in itertools.combinations(layout.placements, 2):
        if a.bin == b.bin:
            assert (a.x + a.width + bed.margin <= b.x + tol or b.x + b.width + bed.margin <= a.x
                    + tol or a.y + a.height + bed.margin <= b.y + tol
                    or b.y + b.height + bed.margin <= a.y + tol)  # fmt: skip


@pytest.mark.parametrize("size", sorted(PUMA_BEDS), ids=lambda s: f"{s[0]}x{s[1]}")
def test_the_puma_on_common_beds(size):
    pattern, unit, name = _puma()
    layout = lay_out(pattern, Bed.of(*size), unit=unit, name=name)
    assert (len(layout.pieces), layout.count) == PUMA_BEDS[size]
    _check_fits(layout)
    assert layout.material_area == layout.count * size[0] * size[1]
    assert 0 < layout.pieces_area < layout.material_area
    assert layout.pieces[0].labels[0].text.startswith("PUMA 560, piece 1 of ")


def test_the_puma_does_not_fit_a_small_laser_and_the_error_says_what_would():
    pattern, unit, name = _puma()
    with pytest.raises(BedTooSmallError) as error:
        lay_out(pattern, Bed.of(300, 200), unit=unit, name=name)
    text = str(error.value)
    assert "\n" not in text and isinstance(error.value, ValueError)
    assert ("from 1,926 to 2,435 mm along the strip there is no plain tube of at least 15 mm to "
            "cut across") in text
    assert "the smallest bed that works is 530 x 185 mm" in text
    assert error.value.smallest == (530.0, 185.0)
    lay_out(pattern, Bed.of(530, 185), unit=unit)  # it does
    for too_small in ((529, 185), (530, 184)):
        with pytest.raises(BedTooSmallError):
            lay_out(pattern, Bed.of(*too_small), unit=unit)


def test_a_strip_wider_than_the_bed_names_the_smallest_bed():
    pattern, unit, _ = _puma()
    with pytest.raises(BedTooSmallError, match=r"strip is 175\.0 mm wide: wider than the "
                                               r"150 x 150 mm bed") as error:  # fmt: skip
        lay_out(pattern, Bed.of(150, 150), unit=unit)
    assert error.value.smallest == (530.0, 185.0)


@pytest.mark.parametrize("path", GALLERY, ids=lambda p: p.stem)
def test_every_gallery_design_fits_a_600_by_400_bed(path):
    patterns, unit, name = gallery_sheets(path)
    for pattern in patterns:
        layout = lay_out(pattern, Bed.of(600, 400), unit=unit, name=name)
        _check_fits(layout)
        # a sheet that fits whole stays one piece
        assert (len(layout.pieces) == 1) == (layout.bounds[0] == layout.bounds[-1]
                                             and layout.pieces[0].pattern is pattern)


def test_a_wider_tab_needs_longer_plain_tube():
    pattern, unit, _ = _puma()
    assert Bed.of(600, 400, tab=20).minimum_tube == 30.0
    with pytest.raises(BedTooSmallError, match="no plain tube of at least 30 mm"):
        lay_out(pattern, Bed.of(530, 185, tab=20), unit=unit)


def test_parse_bed():
    assert parse_bed("600x400") == (600.0, 400.0)
    assert parse_bed(" 1000 × 600 mm") == (1000.0, 600.0)
    assert parse_bed((300, 200.5)) == (300.0, 200.5)
    for bad in ("600", "600x", "x400", "600x400x3", "-600x400", "0x400", None):
        with pytest.raises(InvalidParameterError, match="bed"):
            parse_bed(bad)


def test_bed_values_are_checked():
    assert Bed.of(600, 400) == Bed(600.0, 400.0, 5.0, 10.0)
    with pytest.raises(InvalidParameterError, match=r"bed margin must be less than half the "
                                                    r"bed's shorter side \(100 mm"):  # fmt: skip
        Bed.of(600, 200, margin=100)
    with pytest.raises(InvalidParameterError, match=r"tab must be a number > 0 and <= 1000"):
        Bed.of(600, 400, tab=0)
    with pytest.raises(InvalidTypeError, match="bed width must be a number"):
        Bed.of("600", 400)


def test_materials():
    assert check_material("pet") == Material("PET", 0.25)
    assert check_material("Paper") == Material("paper", 0.1)
    assert check_material("Tyvek", 0.15) == Material("Tyvek", 0.15)
    assert check_material("PET", 0.1).describe() == "PET, 0.1 mm thick"
    with pytest.raises(InvalidParameterError, match="give the thickness of Tyvek in mm"):
        check_material("Tyvek")
    with pytest.raises(InvalidParameterError, match=r"thickness must be a number > 0 and <= 10"):
        check_material("PET", 11)
    with pytest.raises(InvalidParameterError, match="one line"):
        check_material("PET\nsheet")
