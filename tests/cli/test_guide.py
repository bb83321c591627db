"""``kinegami build --formats guide``: the folding guide PDF (issue 33, items 3 and 4;
docs/fabrication.md "Folding guide" and "Bill of materials"), rendered with poppler's
pdftoppm and read back with pdftotext."""

from __future__ import annotations

import re
import shutil
import subprocess

import pytest

from .helpers import EXAMPLE1, ROOT, main_in_process

PUMA = ROOT / "examples" / "designs" / "puma.json"
GRIPPER = ROOT / "examples" / "designs" / "gripper.json"

pytestmark = pytest.mark.skipif(
    shutil.which("pdftoppm") is None or shutil.which("pdftotext") is None,
    reason="needs poppler's pdftoppm and pdftotext (apt-get install -y poppler-utils)",
)


@pytest.fixture
def reference() -> dict:
    """What the gallery's guides hold: steps (modules), extra pages after them, the joints by
    their design-file numbers, in folding order, and bill-of-materials lines."""
    return {
        "example1": {
            "steps": 18, "closing": 0,
            "joints": ["joint 0 (StartTip 'start')", "joint 2 (PrismaticJoint 'prismatic')",
                       "joint 4 (RevoluteJoint 'revolute')", "joint 6 (EndTip 'end')"],
            "links": [1, 2, 3, 4, 5, 6],
            "bom": ["material: 0.037 m² of sheet material", "pieces: 1 (1 sheet, 0 joins)",
                    "glue tab: 528 mm (the long seam of every sheet)"],
        },
        "puma": {
            "steps": 37, "closing": 1,
            "joints": [f"joint {j} (RevoluteJoint" for j in range(6)] + ["joint 6 (EndTip"],
            "links": [1, 2, 3, 4, 5, 6],
            "bom": ["cut from 3 bed sheets (0.720 m²)", "pieces: 5 (1 sheet, 4 joins)",
                    "glue tab: 2,435 mm", "tape: about 600 mm"],
        },
        "gripper": {
            "steps": 25, "closing": 2,
            "joints": ["sheet 0, joint 0 (StartTip 'mount')", "sheet 0, joint 6 (EndTip",
                       "sheet 1, joint 7 (RevoluteJoint 'rightBase')", "sheet 1, joint 9 (EndTip"],
            "links": [1, 2, 3, 4, 5, 6, 7, 8, 9],
            "bom": ["pieces: 3 (2 sheets, 1 join)", "cut from 2 bed sheets",
                    "printed connectors: 1 (1 socket)"],
        },
    }  # fmt: skip


def _pages(pdf, tmp_path) -> int:
    """Render every page with pdftoppm (at 10 dpi); the number of pages drawn."""
    folder = tmp_path / "pages"
    folder.mkdir()
    subprocess.run(["pdftoppm", "-r", "10", "-png", str(pdf), str(folder / "page")], check=True,
                   capture_output=True, timeout=120)  # fmt: skip
    pages = sorted(folder.glob("page-*.png"))
    assert all(page.stat().st_size > 100 for page in pages)
    return len(pages)


def _text(pdf) -> str:
    result = subprocess.run(["pdftotext", "-layout", str(pdf), "-"], check=True,
                            capture_output=True, text=True, timeout=60)  # fmt: skip
    return result.stdout


def _steps(text: str) -> list[tuple[int, int, str]]:
    """Every "Step k of N: title" line."""
    return [(int(k), int(n), title.strip())
            for k, n, title in re.findall(r"Step (\d+) of (\d+): (.*)", text)]  # fmt: skip


def _check(pdf, tmp_path, expected: dict) -> str:
    """The guide's text, after checking its pages, its steps in order and its joints once."""
    text = _text(pdf)
    steps = _steps(text)
    count = expected["steps"]
    assert [(k, n) for k, n, _ in steps] == [(k, count) for k in range(1, count + 1)]
    titles = [title for _, _, title in steps]
    assert len(set(titles)) == count  # every module named once
    where = []
    for joint in expected["joints"]:  # every joint once, in folding order
        hits = [k for k, title in enumerate(titles) if title.startswith(joint)]
        assert len(hits) == 1, (joint, hits)
        where += hits
    assert where == sorted(where)
    for link in expected["links"]:  # every link's modules, together
        hits = [k for k, title in enumerate(titles) if f"link {link} (joint " in title]
        assert hits and hits == list(range(hits[0], hits[0] + len(hits))), link
    flat = " ".join(text.split())  # the cover wraps its lines
    for line in expected["bom"]:
        assert line in flat
    assert "Bill of materials" in text
    assert "Join the tube along its glue tab" in text
    assert _pages(pdf, tmp_path) == 1 + count + 1 + expected["closing"]
    return text


def test_example1_guide(tmp_path, capsys, reference):
    assert main_in_process("build", EXAMPLE1, "-o", tmp_path, "--formats", "guide") == 0
    out = capsys.readouterr().out
    pdf = tmp_path / "example1_guide.pdf"
    assert f"    {pdf}" in out
    assert "  bill of materials:\n    material: 0.037 m² of sheet material" in out
    text = _check(pdf, tmp_path, reference["example1"])
    assert text.lstrip().startswith("Example 1")  # the cover names the design
    assert "Join the pieces" not in text  # no bed: one piece


def test_puma_guide_on_a_600_by_400_laser(tmp_path, capsys, reference):
    assert main_in_process("build", PUMA, "-o", tmp_path, "--bed", "600x400", "--formats",
                           "guide") == 0  # fmt: skip
    out = capsys.readouterr().out
    assert "    pieces: 5 (1 sheet, 4 joins)" in out
    text = _check(tmp_path / "puma_guide.pdf", tmp_path, reference["puma"])
    assert "PUMA" in text.split("Bill of materials")[0]
    assert "Join the pieces" in text
    for k in range(1, 5):
        assert f"tab of piece {k} of 5" in text
    pieces = [int(k) for k in re.findall(r"on piece (\d) of 5 \(bed sheet \d\)", text)]
    assert len(pieces) == 37 and pieces == sorted(pieces)  # every step on its piece, in order
    assert set(pieces) == {1, 2, 3, 4, 5}


def test_tree_guide_names_each_sheets_junction(tmp_path, capsys, reference):
    """The gripper on a 300 x 200 mm bed: sheet 0 in two pieces, sheet 1 whole."""
    assert main_in_process("build", GRIPPER, "-o", tmp_path, "--bed", "300x200", "--formats",
                           "guide") == 0  # fmt: skip
    out = capsys.readouterr().out
    assert "    printed connectors: 1 (1 socket)" in out
    text = _check(tmp_path / "gripper_guide.pdf", tmp_path, reference["gripper"])
    flat = " ".join(text.split())
    assert "Sheet 1 (joints 7 to 9) goes into junction 0 at joint 3" in flat
    assert "Sheet 0 (joints 0 to 6) starts at the root" in flat
    assert "Junction 0 (printed connector) at joint 3: sheet 0 runs through it" in flat
    assert "Sheet 0: glue the 10 mm tab of piece 1 of 2 (bed sheet 1) inside piece 2" in flat
    assert re.search(r"sheet 0, joint 6 \(EndTip 'leftTip'\)\s+\S.* on piece 2 of 2", text)


def test_all_includes_the_guide():
    from kinegami.cli import _parse_formats, _parse_tree_formats

    assert "guide" in [fmt.name for fmt in _parse_formats("all")]
    assert "guide" in _parse_tree_formats("all")
    (guide,) = _parse_formats("guide")
    assert guide.suffixes == ("_guide.pdf",)
