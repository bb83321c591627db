"""The bill of materials (kinegami.fabrication.bom; docs/fabrication.md "Bill of materials")."""

from __future__ import annotations

import numpy.testing as npt
import pytest

from kinegami.design import load_design_with_info
from kinegami.errors import InvalidParameterError
from kinegami.fabrication.beds import Bed, check_material, lay_out
from kinegami.fabrication.bom import bill_of_materials
from kinegami.pattern.sheet import flatten
from tests.cli.helpers import ROOT


@pytest.fixture(scope="module")
def puma():
    chain, info = load_design_with_info(ROOT / "examples" / "designs" / "puma.json")
    return chain.creasePattern(info.twistPortion)


def test_a_sheet_without_a_bed(puma):
    bom = bill_of_materials([puma], 1.0, material=check_material("PET"))
    xmin, ymin, xmax, ymax = flatten(puma).bounds
    npt.assert_allclose(bom.sheet_area, (xmax - xmin) * (ymax - ymin))
    npt.assert_allclose(bom.glue_tab, puma.height)  # the long seam
    npt.assert_allclose(bom.tube_perimeter, puma.width)
    assert (bom.sheets, bom.pieces, bom.joins, bom.bed_sheets, bom.bed_area) == (1, 1, 0, None,
                                                                                 None)  # fmt: skip
    assert (bom.tape, bom.connectors) == (0.0, 0)
    assert bom.lines()[0] == f"material: {bom.sheet_area / 1e6:.3f} m² of PET, 0.25 mm thick"
    assert bom.lines()[3] == "tape: none needed (no joins of pieces, no sockets)"


def test_pieces_on_beds_need_tape_at_every_join(puma):
    layout = lay_out(puma, Bed.of(600, 400), unit=1.0)
    bom = bill_of_materials([puma], 1.0, layouts=[layout])
    assert (bom.pieces, bom.joins, bom.bed_sheets) == (5, 4, 3)
    npt.assert_allclose(bom.bed_area, 3 * 600 * 400)
    npt.assert_allclose(bom.tape, 4 * puma.width)  # one turn of the tube at each join


def test_units_scale_lengths_and_areas(puma):
    mm, cm = bill_of_materials([puma], 1.0), bill_of_materials([puma], 10.0)
    npt.assert_allclose(cm.glue_tab, 10 * mm.glue_tab)
    npt.assert_allclose(cm.sheet_area, 100 * mm.sheet_area)


def test_bad_arguments():
    with pytest.raises(InvalidParameterError, match="at least one sheet"):
        bill_of_materials([], 1.0)
