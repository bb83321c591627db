"""``kinegami build --bed`` and the sheet material on the command line (issue 33; docs/cli.md,
docs/fabrication.md "Laser bed" and "Material")."""

from __future__ import annotations

import json
import os

import ezdxf
import numpy as np
import pytest

from .helpers import ROOT, assert_clean_failure, main_in_process, run, write

PUMA = ROOT / "examples" / "designs" / "puma.json"
HAND = ROOT / "examples" / "designs" / "algorithmic_hand.json"


def _fits(path, width, height, margin=5.0) -> None:
    """Every line and text of a DXF inside the bed less its margin."""
    points = []
    for entity in ezdxf.readfile(path).modelspace():
        if entity.dxftype() == "LINE":
            start, end = entity.dxf.start, entity.dxf.end
            points += [(start.x, start.y), (end.x, end.y)]
        else:
            points.append((entity.dxf.insert.x, entity.dxf.insert.y))
    points = np.array(points)
    assert points.min() >= margin - 1e-6
    assert points[:, 0].max() <= width - margin + 1e-6
    assert points[:, 1].max() <= height - margin + 1e-6


def test_the_puma_on_a_600_by_400_laser(tmp_path, capsys):
    assert main_in_process("build", PUMA, "-o", tmp_path, "--bed", "600x400", "--formats",
                           "dxf,svg") == 0  # fmt: skip
    out = capsys.readouterr().out
    assert sorted(os.listdir(tmp_path)) == [f"puma_bed_{m}.{s}" for m in (1, 2, 3)
                                            for s in ("dxf", "svg")]  # fmt: skip
    for m in (1, 2, 3):
        _fits(tmp_path / f"puma_bed_{m}.dxf", 600, 400)
    assert ("  laser bed: 600 x 400 mm (margin 5 mm), tab 10 mm (a cut needs 15 mm of plain "
            "tube): 5 pieces on 3 bed sheets, 0.72 square metres of material") in out
    assert "    piece 5: 1,916 to 2,435 mm along the strip (520 x 175 mm), bed sheet" in out
    for m in (1, 2, 3):
        assert f"    {tmp_path / f'puma_bed_{m}.dxf'}" in out


def test_the_design_file_names_bed_and_material(tmp_path, capsys):
    document = json.loads(PUMA.read_text(encoding="utf-8"))
    document.update(version=4, material={"name": "PET", "thickness": 0.18},
                    bed={"width": 1000, "height": 600, "tab": 12})  # fmt: skip
    design = write(tmp_path / "arm.json", document)
    out_dir = tmp_path / "out"
    assert main_in_process("build", design, "-o", out_dir, "--formats", "dxf") == 0
    out = capsys.readouterr().out
    assert os.listdir(out_dir) == ["arm_bed_1.dxf"]
    _fits(out_dir / "arm_bed_1.dxf", 1000, 600)
    assert "  material: PET, 0.18 mm thick, the clearance margin" in out
    assert "  clearance: clear with margin 0.18 mm" in out
    assert "tab 12 mm (a cut needs 18 mm of plain tube): 3 pieces on 1 bed sheet" in out
    # --bed replaces it for one build; none writes the whole sheet, and the bed files of the
    # earlier build go (they are this design's dxf, from another build)
    assert main_in_process("build", design, "-o", out_dir, "--formats", "dxf", "--bed",
                           "none") == 0  # fmt: skip
    assert os.listdir(out_dir) == ["arm.dxf"]


def test_fewer_beds_remove_the_earlier_bed_files_in_the_same_publish(tmp_path):
    (tmp_path / "puma_bed_9.svg").write_text("an svg of an earlier build")
    (tmp_path / "notes_bed_2.dxf").write_text("another design's")
    assert main_in_process("build", PUMA, "-o", tmp_path, "--bed", "600x400", "--formats",
                           "dxf") == 0  # fmt: skip
    assert {f"puma_bed_{m}.dxf" for m in (1, 2, 3)} <= set(os.listdir(tmp_path))
    assert main_in_process("build", PUMA, "-o", tmp_path, "--bed", "1000x600", "--formats",
                           "dxf") == 0  # fmt: skip
    # the svg was not written by these builds: left; the dxf of the 3 beds: now 1
    assert sorted(os.listdir(tmp_path)) == ["notes_bed_2.dxf", "puma_bed_1.dxf",
                                            "puma_bed_9.svg"]  # fmt: skip


def test_a_bed_too_small_fails_in_one_line_and_writes_nothing(tmp_path):
    assert main_in_process("build", PUMA, "-o", tmp_path, "--bed", "600x400", "--formats",
                           "dxf") == 0  # fmt: skip
    before = {p.name: p.read_bytes() for p in tmp_path.iterdir()}
    result = run("build", PUMA, "-o", tmp_path, "--bed", "300x200")
    assert_clean_failure(result, "puma.json: the sheet does not fit the 300 x 200 mm bed",
                         "from 1,926 to 2,435 mm along the strip there is no plain tube of at "
                         "least 15 mm", "the smallest bed that works is 530 x 185 mm",
                         "(--bed 530x185)")  # fmt: skip
    assert {p.name: p.read_bytes() for p in tmp_path.iterdir()} == before


def test_a_tree_writes_every_sheets_beds(tmp_path, capsys):
    assert main_in_process("build", HAND, "-o", tmp_path, "--bed", "600x400", "--formats",
                           "dxf") == 0  # fmt: skip
    out = capsys.readouterr().out
    names = sorted(os.listdir(tmp_path))
    assert names == ["algorithmic_hand_sheet_0_bed_1.dxf", "algorithmic_hand_sheet_0_bed_2.dxf",
                     "algorithmic_hand_sheet_1_bed_1.dxf", "algorithmic_hand_sheet_2_bed_1.dxf"]
    for name in names:
        _fits(tmp_path / name, 600, 400)
    assert "    sheet 0: 9 pieces on 2 bed sheets" in out
    texts = [e.dxf.text for name in names[:2] for e in ezdxf.readfile(tmp_path / name).modelspace()
             if e.dxftype() == "TEXT"]  # fmt: skip
    assert "Algorithmic hand, sheet 0, piece 2 of 9, joins piece 1 here" in texts
    assert "Algorithmic hand, sheet 0, piece 9 of 9, joins piece 8 here" in texts


def test_check_and_compact_name_the_material(tmp_path, capsys):
    assert main_in_process("check", PUMA, "--material", "pet") == 0
    out = capsys.readouterr().out
    assert "  material: PET, 0.25 mm thick, the clearance margin" in out
    assert main_in_process("check", PUMA, "--material", "paper", "--margin", "1", "--json") == 0
    data = json.loads(capsys.readouterr().out)
    assert data["material"] == {"name": "paper", "thickness": 0.1} and data["margin"] == 1.0
    out_file = tmp_path / "short.json"
    assert main_in_process("compact", PUMA, "-o", out_file, "--time-limit", "2", "--material",
                           "PET", "--thickness", "0.2") == 0  # fmt: skip
    assert "  material: PET, 0.2 mm thick, the clearance margin" in capsys.readouterr().out
    written = json.loads(out_file.read_text(encoding="utf-8"))
    assert written["version"] == 4 and written["material"] == {"name": "PET", "thickness": 0.2}
    assert "margin" not in written  # the thickness is the margin


@pytest.mark.parametrize(("args", "words"), [
    (("--bed", "600"), ["--bed: bed must be WIDTHxHEIGHT in mm, e.g. 600x400, got '600'"]),
    (("--bed", "600x400", "--tab", "0"), ["--tab: tab must be a number > 0"]),
    (("--bed", "600x40", "--bed-margin", "20"), ["--bed-margin: bed margin must be less than"]),
    (("--tab", "12"), ["--tab: give the bed too (--bed WxH, mm)"]),
    (("--thickness", "0.2"), ["--thickness: give the material too (--material NAME)"]),
    (("--material", "Tyvek"), ["--thickness: give the thickness of Tyvek in mm"]),
    (("--material", "PET", "--thickness", "x"), ["--thickness: must be a number of millimetres"]),
])  # fmt: skip
def test_bad_options_are_one_line(tmp_path, args, words):
    result = run("build", PUMA, "-o", tmp_path / "out", *args)
    assert_clean_failure(result, *words)
    assert not (tmp_path / "out").exists()
