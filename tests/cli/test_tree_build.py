"""``kinegami build`` of a tree (docs/trees.md): a sheet per leaf, the junction connectors, the
whole tree; the defaults when an optional library is missing; clean failures."""

from __future__ import annotations

import json
import sys

import pytest

from .helpers import ROOT, main_in_process

HAND = ROOT / "examples" / "designs" / "hand.json"  # the paper's hand: 3 leaves, 1 junction

SHEET_FILES = {f"hand_sheet_{k}{suffix}" for k in range(3) for suffix in (".dxf", ".svg", ".fold")}
PICTURES = {"hand_3d.png", *(f"hand_sheet_{k}_pattern.png" for k in range(3))}
JUNCTION_FILES = {"hand_junction_0.stl", "hand_junction_0.3mf"}
WHOLE_TREE = {"hand.urdf", "hand_meshes"}


def names(folder) -> set[str]:
    return {path.name for path in folder.iterdir()}


@pytest.fixture(scope="module")
def hand_build(tmp_path_factory):
    """The paper's hand built with the default formats: (exit code, folder, stdout)."""
    import contextlib
    import io

    out = tmp_path_factory.mktemp("hand")
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout):
        code = main_in_process("build", HAND, "-o", out)
    return code, out, stdout.getvalue()


def test_the_default_build_writes_every_sheet_the_junctions_and_the_whole_tree(hand_build):
    code, out, _ = hand_build
    assert code == 0
    assert names(out) == SHEET_FILES | PICTURES | JUNCTION_FILES | WHOLE_TREE | {"hand.pdf"}
    for name in SHEET_FILES | JUNCTION_FILES | {"hand.pdf", "hand.urdf"}:
        assert (out / name).stat().st_size > 0, name
    assert _pdf_pages(out / "hand.pdf") == 3  # one page per sheet
    # every FOLD is a sheet of its own that starts at its frame
    for k in range(3):
        fold = json.loads((out / f"hand_sheet_{k}.fold").read_text())
        assert fold["vertices_coords"] and fold["edges_vertices"]


def _pdf_pages(path) -> int:
    import re

    return len(re.findall(rb"/Type\s*/Page\b(?!s)", path.read_bytes()))


def test_the_summary_lists_the_sheets_and_the_junctions(hand_build):
    _, _, text = hand_build
    assert "a tree with 3 leaves" in text
    assert "sheets: 3 (one per leaf)" in text
    for k in range(3):
        assert f"    sheet {k}: joints " in text
    assert "junctions: 1 (printed connectors)" in text
    assert "junction 0: at joint 0, children 1, 5, 8" in text
    assert "clearance:" in text and "(clear)" in text
    # the palm slides along its axis so that its socket fits, and the summary says so
    assert "note: joint 1 slid" in text


def test_the_urdf_of_a_tree_build_is_one_kinematic_tree(hand_build):
    yourdfpy = pytest.importorskip("yourdfpy")
    _, out, _ = hand_build
    robot = yourdfpy.URDF.load(str(out / "hand.urdf"), build_scene_graph=False,
                               load_meshes=False)  # fmt: skip
    assert robot.validate()
    children = [joint.child for joint in robot.robot.joints]
    assert len(children) == len(set(children))  # every link has one parent: a tree
    roots = {link.name for link in robot.robot.links} - set(children)
    assert len(roots) == 1


def test_only_the_formats_asked_for_are_written(tmp_path, capsys):
    assert main_in_process("build", HAND, "-o", tmp_path, "--formats", "dxf,pdf") == 0
    assert names(tmp_path) == {f"hand_sheet_{k}.dxf" for k in range(3)} | {"hand.pdf"}


@pytest.mark.parametrize(
    "missing, left_out, extra",
    [("manifold3d", JUNCTION_FILES, "print"), ("trimesh", JUNCTION_FILES | WHOLE_TREE, "mesh")],
)
def test_a_missing_optional_library_leaves_out_its_files_with_a_note(
    tmp_path, capsys, monkeypatch, missing, left_out, extra
):
    monkeypatch.setitem(sys.modules, missing, None)  # import raises ImportError
    assert main_in_process("build", HAND, "-o", tmp_path) == 0
    written = names(tmp_path)
    assert not written & left_out
    assert SHEET_FILES | {"hand.pdf"} <= written
    err = capsys.readouterr().err
    assert f"needs {missing}" in err
    assert "pip install 'kinegami[" in err


def test_asking_for_junctions_without_manifold3d_fails_in_one_line_writing_nothing(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.setitem(sys.modules, "manifold3d", None)
    out = tmp_path / "out"
    out.mkdir()
    (out / "keep.txt").write_text("earlier")
    assert main_in_process("build", HAND, "-o", out, "--formats", "dxf,junctions") == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "manifold3d" in err[0] and "kinegami[print]" in err[0], err
    assert "Traceback" not in err[0]
    assert names(out) == {"keep.txt"}  # nothing written, nothing lost


def test_an_unknown_tree_format_is_a_one_line_error(tmp_path, capsys):
    assert main_in_process("build", HAND, "-o", tmp_path, "--formats", "dxf,gcode") == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "gcode" in err[0] and "junctions" in err[0], err
    assert list(tmp_path.iterdir()) == []
