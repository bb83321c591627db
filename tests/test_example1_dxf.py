"""examples/example1.py gives a DXF at true size: the paper's r = 1 is 1 cm, so the tube's
sheet (n sides of b = 2 r sin(pi/n) and half a side of glue tab at each end) is 70.7 mm wide in
a file whose unit is the millimetre, as laser-cutter software reads it."""

from __future__ import annotations

import math
import os
import subprocess
import sys
from pathlib import Path

import ezdxf
import pytest
from ezdxf import bbox

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"

NUM_SIDES = 4
R_MM = 10.0  # the paper's r = 1 is 1 cm
INSUNITS_MM = 4


@pytest.fixture(scope="module")
def run(tmp_path_factory):
    folder = tmp_path_factory.mktemp("example1")
    result = subprocess.run(
        [sys.executable, str(EXAMPLES / "example1.py"), str(folder / "out")],
        capture_output=True, text=True, cwd=folder, timeout=600,
        env=dict(os.environ, MPLBACKEND="Agg", PYTHONPATH=os.pathsep.join(
            [str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])),
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    return folder / "out", result.stdout


def test_the_dxf_is_true_size_in_millimetres(run):
    folder, _ = run
    doc = ezdxf.readfile(folder / "examplePatterns" / "example1.dxf")
    assert doc.header["$INSUNITS"] == INSUNITS_MM
    extents = bbox.extents(doc.modelspace())
    side = 2.0 * R_MM * math.sin(math.pi / NUM_SIDES)
    assert extents.size.x == pytest.approx((NUM_SIDES + 1) * side, abs=1e-6)  # 70.71 mm
    # its length is the sheet's the script prints (cm) times 10
    _, stdout = run
    sheet = next(line for line in stdout.splitlines() if line.strip().startswith("sheet:"))
    height_cm = float(sheet.split(" x ")[1].split(" cm")[0])
    assert extents.size.y == pytest.approx(10.0 * height_cm, abs=0.01)


def test_the_script_says_the_dxf_is_true_size(run):
    _, stdout = run
    assert "examplePatterns/example1.dxf is true size (1 unit = 1 cm, written in mm)" in stdout


def test_the_listing_keeps_the_papers_save_line():
    """The paper's line stays as written; the true-size save is the script's own line after it."""
    lines = (EXAMPLES / "example1.py").read_text().splitlines()
    paper = lines.index('pattern.save(dxfName="examplePatterns/example1.dxf")')
    assert lines[paper + 1].startswith(
        'pattern.save(dxfName="examplePatterns/example1.dxf", units="cm")  # not the paper\'s'
    )
