"""One DXF or SVG per laser bed sheet (kinegami.export.beds, docs/fabrication.md "Laser bed"):
read back with ezdxf and an XML parser, every line and label inside the bed less its margin, as
many crease lines as the pieces have, stale files of an earlier save removed, nothing written
when the sheet cannot be cut to fit."""

from __future__ import annotations

import functools
import os
import warnings
import xml.etree.ElementTree as ET
from collections import Counter

import ezdxf
import numpy as np
import pytest

from kinegami import export
from kinegami.design import load_design
from kinegami.errors import BedTooSmallError, InvalidParameterError
from kinegami.export.beds import bed_files, stale_bed_files
from kinegami.fabrication.beds import Bed, lay_out
from kinegami.pattern.sheet import flatten
from tests.gallery_designs import DESIGN_DIR, is_tree

SVG = "{http://www.w3.org/2000/svg}"


@functools.cache
def puma():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        return load_design(DESIGN_DIR / "puma.json")


def _dxf_content(path):
    """(lines (K, 2, 2) by layer, texts) of a DXF file, read by ezdxf."""
    doc = ezdxf.readfile(path)
    lines, texts = {}, []
    for entity in doc.modelspace():
        if entity.dxftype() == "LINE":
            s, e = entity.dxf.start, entity.dxf.end
            lines.setdefault(entity.dxf.layer, []).append([[s.x, s.y], [e.x, e.y]])
        elif entity.dxftype() == "TEXT":
            texts.append(entity)
    assert doc.header["$INSUNITS"] == 4  # mm
    return {k: np.array(v) for k, v in lines.items()}, texts


def test_the_puma_on_a_600_by_400_bed_is_three_dxf_files_that_fit(tmp_path):
    written = export(puma(), tmp_path / "puma.dxf", bed="600x400", name="PUMA 560")
    assert [p.name for p in written] == ["puma_bed_1.dxf", "puma_bed_2.dxf", "puma_bed_3.dxf"]
    layout = lay_out(puma().creasePattern(), Bed.of(600, 400), name="PUMA 560")
    creases = Counter()
    for piece in layout.pieces:
        creases.update(flatten(piece.pattern).kinds.tolist())
    found = Counter()
    labels = []
    for path in written:
        lines, texts = _dxf_content(path)
        points = np.concatenate([v.reshape(-1, 2) for v in lines.values()])
        assert points.min() >= 5.0 - 1e-9 and points[:, 0].max() <= 595.0 + 1e-9
        assert points[:, 1].max() <= 395.0 + 1e-9
        for text in texts:
            assert text.dxf.layer == "Boundary"
            x, y = text.dxf.insert.x, text.dxf.insert.y
            assert 5.0 <= x <= 595.0 and 5.0 <= y <= 395.0
            labels.append(text.dxf.text)
        found.update({"M": len(lines.get("Mountain", [])), "V": len(lines.get("Valley", [])),
                      "C": len(lines.get("Cut", []))})  # fmt: skip
    assert (found["M"], found["V"], found["C"]) == (creases["M"], creases["V"], creases["C"])
    assert "PUMA 560, piece 2 of 5, joins piece 1 here" in labels
    assert "PUMA 560, piece 4 of 5: glue this tab inside piece 5" in labels


def test_the_svg_files_are_laser_sheets_of_the_bed(tmp_path):
    written = export(puma(), tmp_path / "arm.svg", bed=(1000, 600), tab=12)
    assert [p.name for p in written] == ["arm_bed_1.svg"]
    root = ET.parse(written[0]).getroot()
    assert (root.get("width"), root.get("height")) == ("1000.0mm", "600.0mm")
    groups = {g.get("id"): g for g in root.iter(f"{SVG}g")}
    assert set(groups) == {"Mountain", "Valley", "Boundary", "Cut", "Labels"}
    ys = []
    for line in root.iter(f"{SVG}line"):
        xs = [float(line.get("x1")), float(line.get("x2"))]
        assert 5.0 - 1e-9 <= min(xs) and max(xs) <= 995.0 + 1e-9
        ys += [-float(line.get("y1")), -float(line.get("y2"))]
    assert 5.0 - 1e-9 <= min(ys) and max(ys) <= 595.0 + 1e-9
    texts = [t.text for t in root.iter(f"{SVG}text")]
    assert texts == ["arm, piece 1 of 3: glue this tab inside piece 2",
                     "arm, piece 2 of 3, joins piece 1 here",
                     "arm, piece 2 of 3: glue this tab inside piece 3",
                     "arm, piece 3 of 3, joins piece 2 here"]
    with pytest.raises(InvalidParameterError, match="flavour must be 'laser' for a bed sheet"):
        export(puma(), tmp_path / "arm.svg", bed="1000x600", flavour="simulator")


def test_a_save_with_fewer_beds_removes_the_earlier_extra_files(tmp_path):
    (tmp_path / "other_bed_7.dxf").write_text("another design's")
    (tmp_path / "puma_bed_2.dxf.bak").write_text("a user's copy")
    export(puma(), tmp_path / "puma.dxf", bed="600x400")
    assert sorted(os.listdir(tmp_path)) == ["other_bed_7.dxf", "puma_bed_1.dxf",
                                            "puma_bed_2.dxf", "puma_bed_2.dxf.bak",
                                            "puma_bed_3.dxf"]  # fmt: skip
    export(puma(), tmp_path / "puma.dxf", bed="1000x600")
    assert sorted(os.listdir(tmp_path)) == ["other_bed_7.dxf", "puma_bed_1.dxf",
                                            "puma_bed_2.dxf.bak"]  # fmt: skip
    assert stale_bed_files(tmp_path, "puma", ".dxf") == ["puma_bed_1.dxf"]


def test_a_bed_too_small_writes_nothing_and_keeps_the_earlier_files(tmp_path):
    written = export(puma(), tmp_path / "puma.dxf", bed="600x400")
    before = {p.name: p.read_bytes() for p in written}
    with pytest.raises(BedTooSmallError, match="smallest bed that works is 530 x 185 mm"):
        export(puma(), tmp_path / "puma.dxf", bed="300x200")
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_bed_applies_to_dxf_and_svg_only(tmp_path):
    with pytest.raises(InvalidParameterError, match=r"bed applies to \.dxf and \.svg files"):
        export(puma(), tmp_path / "puma.fold", bed="600x400")
    assert not any(tmp_path.iterdir())


def test_pattern_save_takes_the_bed_too(tmp_path):
    written = puma().creasePattern().save(tmp_path / "p.dxf", bed="1000x600", perforate=True)
    assert [p.name for p in written] == ["p_bed_1.dxf"]
    lines, _ = _dxf_content(written[0])
    lengths = np.hypot(*(lines["Mountain"][:, 1] - lines["Mountain"][:, 0]).T)
    assert lengths.max() <= 1.0 + 1e-6  # dashes of 1 mm (12 significant digits)


def test_bed_files_are_reproducible(monkeypatch):
    monkeypatch.setenv("SOURCE_DATE_EPOCH", "1700000000")
    layout = lay_out(puma().creasePattern(), Bed.of(600, 400))
    first = bed_files(layout, "puma", ".dxf")
    assert first == bed_files(layout, "puma", ".dxf")
    assert list(first) == ["puma_bed_1.dxf", "puma_bed_2.dxf", "puma_bed_3.dxf"]


@pytest.mark.parametrize("path", sorted(DESIGN_DIR.glob("*.json")), ids=lambda p: p.stem)
def test_every_gallery_design_draws_inside_a_600_by_400_bed(path):
    """What the bed files of every gallery design hold (every sheet of a tree): every line,
    and every label's estimated extent, inside the bed less its 5 mm margin."""
    from kinegami.design import load_design_with_info
    from kinegami.export._options import bed_lines, resolve_sheet_options
    from kinegami.pattern.pieces import CHARACTER_WIDTH
    from kinegami.validation import UNITS_IN_MM

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain, info = load_design_with_info(path)
    if is_tree(path):
        from kinegami.fabrication.sheets import fabricate

        sheets = [s.pattern for s in fabricate(chain, twistPortion=info.twistPortion).sheets]
    else:
        sheets = [chain.creasePattern(twistPortion=info.twistPortion)]
    opts = resolve_sheet_options({}, {}, "test")
    tol = 1e-6
    for sheet in sheets:
        layout = lay_out(sheet, Bed.of(600, 400), unit=UNITS_IN_MM[info.units], name=info.name)
        for m in range(layout.count):
            segments, _, texts, _ = bed_lines(layout, m, opts)
            assert segments[:, :, 0].min() >= 5 - tol and segments[:, :, 0].max() <= 595 + tol
            assert segments[:, :, 1].min() >= 5 - tol and segments[:, :, 1].max() <= 395 + tol
            for text in texts:
                length = CHARACTER_WIDTH * text.height * len(text.text)
                x1, y1 = (text.x, text.y + length) if text.angle else (text.x + length, text.y)
                assert 5 - tol <= min(text.x, x1) and max(text.x, x1) <= 595 + tol
                assert 5 - tol <= min(text.y, y1) and max(text.y, y1) <= 395 + tol
