"""``kinegami build`` of every gallery tree (examples/designs, tests/gallery_designs.py), as a user
runs it: with the default formats, one DXF, SVG and FOLD and one pattern picture per sheet (one
sheet per leaf), one PDF with a page per sheet, an STL and a 3MF per printed junction (one per
joint with several children), the URDF of the whole tree with its meshes, the 3D picture; and
the summary says so. Each tree is built once, in this process."""

from __future__ import annotations

import contextlib
import io
import json
import warnings
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from ezdxf import bbox
from gallery_designs import TREE_DESIGNS

from kinegami import ClearanceWarning
from kinegami.design import load_design_with_info
from kinegami.export._options import UNITS_IN_MM
from kinegami.export.pdf import pdf_layout
from kinegami.fabrication.sheets import fabricate, fit_junctions

from .helpers import main_in_process

#: The gallery trees (the paper's hand is clear as built, once its palm is slid).
NAMES = [path.stem for path in TREE_DESIGNS]


def expected_files(stem: str, sheets: int, junctions: int) -> set[str]:
    per_sheet = {f"{stem}_sheet_{k}{suffix}" for k in range(sheets)
                 for suffix in (".dxf", ".svg", ".fold", "_pattern.png")}  # fmt: skip
    per_junction = {f"{stem}_junction_{k}{suffix}" for k in range(junctions)
                    for suffix in (".stl", ".3mf")}  # fmt: skip
    whole = {f"{stem}.pdf", f"{stem}.urdf", f"{stem}_meshes", f"{stem}_3d.png"}
    return per_sheet | per_junction | whole


def pdf_pages(path) -> int:
    import re

    return len(re.findall(rb"/Type\s*/Page\b(?!s)", path.read_bytes()))


@pytest.fixture(scope="module")
def builds(tmp_path_factory):
    """name -> (exit code, output folder, summary, leaves, branching joints, the sheets as
    fitted and cut in Python, the design's units) for every tree."""
    done = {}
    for path in TREE_DESIGNS:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ClearanceWarning)  # the paper's hand as designed
            tree, info = load_design_with_info(path)
            fitted, _ = fit_junctions(tree)
        leaves = sum(1 for children in tree.Children if not children)
        branching = sum(1 for children in tree.Children if len(children) > 1)
        out = tmp_path_factory.mktemp(path.stem)
        summary = io.StringIO()
        with contextlib.redirect_stdout(summary):
            code = main_in_process("build", path, "-o", out)
        done[path.stem] = (code, out, summary.getvalue(), leaves, branching,
                           fabricate(fitted), info.units)  # fmt: skip
    return done


def test_the_gallery_has_trees():
    assert {"hand", "algorithmic_hand", "quadruped", "gripper"} <= set(NAMES)


@pytest.mark.parametrize("name", NAMES)
def test_every_gallery_tree_builds_its_sheets_junctions_and_urdf(name, builds):
    code, out, _, leaves, branching, fabrication, units = builds[name]
    assert code == 0
    assert {p.name for p in out.iterdir()} == expected_files(name, leaves, branching)
    for path in out.iterdir():
        if path.is_file():
            assert path.stat().st_size > 0, path.name
    assert any((out / f"{name}_meshes").iterdir())
    # the PDF: every sheet tiled at 1:1 (a sheet longer than a page takes several)
    pages = sum(pdf_layout(sheet.pattern, units=units).page_count for sheet in fabrication.sheets)
    assert pdf_pages(out / f"{name}.pdf") == pages >= leaves
    for sheet in fabrication.sheets:
        stem = out / f"{name}_sheet_{sheet.index}"
        # the DXF is that sheet at true size: n b wide plus a glue panel, as long as its pattern
        pattern, mm = sheet.pattern, UNITS_IN_MM[units]
        lines = ezdxf.readfile(f"{stem}.dxf").modelspace().query("LINE")  # not the label
        size = bbox.extents(lines).size
        assert size.x == pytest.approx((pattern.width + pattern.width / pattern.numSides) * mm,
                                       rel=1e-6)  # fmt: skip
        assert size.y == pytest.approx(pattern.height * mm, rel=1e-6)
        # the FOLD is the same flat sheet (mm)
        fold = json.loads(Path(f"{stem}.fold").read_text())
        xy = np.array(fold["vertices_coords"])
        assert np.ptp(xy, axis=0) == pytest.approx([size.x, size.y], rel=1e-6)


@pytest.mark.parametrize("name", NAMES)
def test_every_gallery_tree_is_clear_as_built(name, builds):
    _, _, text, leaves, branching, _, _ = builds[name]
    assert f"a tree with {leaves} leaves" in text
    assert f"sheets: {leaves} (one per leaf)" in text
    assert f"junctions: {branching} (printed connectors)" in text
    clearance = next(line for line in text.splitlines() if "clearance:" in line)
    assert clearance.startswith("  clearance: clear with margin 0 mm"), clearance


@pytest.mark.parametrize("name", NAMES)
def test_the_junction_connectors_are_watertight(name, builds):
    trimesh = pytest.importorskip("trimesh")
    _, out, _, _, branching, fabrication, units = builds[name]
    for k in range(branching):
        printed = trimesh.load(out / f"{name}_junction_{k}.3mf", force="mesh")
        assert printed.is_watertight and printed.is_volume, (name, k)
        # in mm: the connector's volume (units of the design) times the unit's mm cubed
        expected = fabrication.connector(k).volume * UNITS_IN_MM[units] ** 3
        assert printed.volume == pytest.approx(expected, rel=1e-6)
        # STL stores 32-bit floats: vertices the connector keeps apart must stay apart there
        stl = trimesh.load(out / f"{name}_junction_{k}.stl")
        assert stl.is_watertight and stl.is_volume, (name, k)
        assert stl.volume == pytest.approx(expected, rel=1e-4)


@pytest.mark.parametrize("name", NAMES)
def test_the_urdf_of_every_gallery_tree_is_one_kinematic_tree(name, builds):
    yourdfpy = pytest.importorskip("yourdfpy")
    _, out, _, _, _, _, _ = builds[name]
    robot = yourdfpy.URDF.load(str(out / f"{name}.urdf"), build_scene_graph=False,
                               load_meshes=False)  # fmt: skip
    assert robot.validate()
    children = [joint.child for joint in robot.robot.joints]
    assert len(children) == len(set(children))
    assert len({link.name for link in robot.robot.links} - set(children)) == 1
