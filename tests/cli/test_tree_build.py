"""``kinegami build`` of a tree (docs/trees.md): a sheet per leaf, the junction connectors, the
whole tree; the defaults when an optional library is missing; clean failures; folded take-off
junctions (``--junctions takeoff``)."""

from __future__ import annotations

import json
import sys

import numpy as np
import pytest

from .helpers import ROOT, main_in_process

HAND = ROOT / "examples" / "designs" / "hand.json"  # the paper's hand: 3 leaves, 1 junction
#: The paper's hand as published (the gallery's has the palm slid so that its socket fits).
PAPERS_HAND = ROOT / "tests" / "design" / "data" / "papers_hand.json"

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
    assert "  clearance: clear with margin 0 mm (0 cm): minimum clearance 0.0 mm" in text
    # its closest parts touch where the junction ends (it covers them up to 2 r apart): said
    assert "; closest where the tubes leaving joint 0 come out of its junction\n" in text
    # the gallery's hand has the palm's fitting slide written in: nothing slides, and the tree
    # judged is the tree built
    assert "slid" not in text


def test_a_build_that_slides_a_joint_says_so_and_gives_both_verdicts(tmp_path):
    """The paper's hand as published: the palm's socket fits only after build slides it by
    -3 r; the summary judges the tree built and names the verdict of the file as written
    (what check and the editor say)."""
    import contextlib
    import io

    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout):
        assert main_in_process("build", PAPERS_HAND, "-o", tmp_path, "--formats", "dxf") == 0
    text = stdout.getvalue()
    assert "  clearance: clear with margin 0 mm (0 cm): minimum clearance 0.0 mm" in text
    assert "note: joint 1 slid -30.0 mm along its axis so that its socket fits" in text
    assert ("judge the design file as written: self-intersects, parts closer than the margin "
            "0 mm (0 cm): minimum clearance -2.5 mm (-0.25 cm), between joint 1, RevoluteJoint "
            "'palm', proximal half and link 5, straight tube") in " ".join(text.split())


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
    [
        ("manifold3d", JUNCTION_FILES, "print"),
        ("trimesh", JUNCTION_FILES | WHOLE_TREE, "mesh"),
        ("lxml", JUNCTION_FILES, "print"),  # trimesh writes 3MF with lxml and networkx
        ("networkx", JUNCTION_FILES, "print"),
    ],
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
    assert f"pip install 'kinegami[{extra}]'" in err


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


# --- folded take-off junctions (--junctions takeoff) -------------------------------------------


@pytest.fixture(scope="module")
def takeoff_build(tmp_path_factory):
    """The paper's hand built with take-offs: (exit code, folder, stdout)."""
    import contextlib
    import io

    out = tmp_path_factory.mktemp("hand_takeoff")
    stdout = io.StringIO()
    with contextlib.redirect_stdout(stdout):
        code = main_in_process("build", HAND, "-o", out, "--junctions", "takeoff",
                               "--formats", "dxf,svg,fold,pdf,junctions")  # fmt: skip
    return code, out, stdout.getvalue()


@pytest.fixture(scope="module")
def takeoff_fabrication():
    """The same fabrication in-process (the hand as the design file gives it; lengths in r)."""
    import warnings

    from kinegami.design import load_design_with_info
    from kinegami.errors import ClearanceWarning
    from kinegami.fabrication.sheets import fabricate

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        tree, info = load_design_with_info(HAND)
    return fabricate(tree, junction="takeoff", twistPortion=info.twistPortion)


MM = 10.0  # the hand's r = 1 cm


def test_a_takeoff_build_writes_every_sheet_and_no_connector(takeoff_build):
    code, out, _ = takeoff_build
    assert code == 0
    assert names(out) == SHEET_FILES | {"hand.pdf"}  # no connector to print
    assert _pdf_pages(out / "hand.pdf") == 3


def test_the_takeoff_summary_lists_where_each_branch_leaves(takeoff_build):
    _, _, text = takeoff_build
    assert "junctions: 0 (printed connectors)" in text
    assert "take-offs: 2 (folded)" in text
    # the palm slid down its axis (as the gallery's hand is): the palm's branch leaves through
    # face 2, the pointer's through face 0
    assert "take-off A: joint 1 leaves joint 8's link through face 2" in text
    assert "take-off B: joint 5 leaves joint 8's link through face 0" in text
    assert "hole A in sheet 0, sheet 2 starts with its skirt (4 glue tabs)" in text
    assert "folded body with the take-off links:" in text
    assert "cut out hole A (sheet 2's skirt glues in)" in text
    assert "note: joint 1 slid" not in text  # nothing to fit: the palm's tube leaves link 8


def _dxf_lines(path, layer):
    import ezdxf

    doc = ezdxf.readfile(path)
    lines = [[(e.dxf.start.x, e.dxf.start.y), (e.dxf.end.x, e.dxf.end.y)]
             for e in doc.modelspace().query(f"LINE[layer=='{layer}']")]  # fmt: skip
    return np.array(lines), [e.dxf.text for e in doc.modelspace().query("TEXT")]


def _on_lines(points, lines, tol=1e-6):
    a, c = lines[None, :, 0], lines[None, :, 1]
    d = c - a
    t = np.clip(((points[:, None] - a) * d).sum(-1) / np.maximum((d * d).sum(-1), 1e-300), 0, 1)
    return np.linalg.norm(a + t[..., None] * d - points[:, None], axis=-1).min(axis=1) <= tol


def _samples(lines):
    f = np.array([0.1, 0.5, 0.9])[None, :, None]
    return (lines[:, :1] + f * (lines[:, 1:] - lines[:, :1])).reshape(-1, 2)


def test_the_connector_build_names_the_joints_as_the_design_does(hand_build, takeoff_build):
    """Fitting the connectors slides children but keeps every joint, so the sheet labels keep
    every name the design gives, waypoints' included (the root is a named waypoint)."""
    import re

    import ezdxf

    _, out, text = hand_build
    assert "sheet 0: joints 0 'root' to 11 'middleEnd'" in text
    assert "starts in junction 0 (at joint 0 'root')" in text
    named = re.compile(r"joints? \d+ '\w+'")
    takeoff_text = takeoff_build[2]
    for k in range(3):  # the same names in both builds' sheet lines
        line = next(x for x in text.splitlines() if x.startswith(f"    sheet {k}: "))
        other = next(x for x in takeoff_text.splitlines() if x.startswith(f"    sheet {k}: "))
        assert named.findall(line) == named.findall(other), (line, other)
    labels = [e.dxf.text for e in ezdxf.readfile(out / "hand_sheet_0.dxf").modelspace()
              if e.dxftype() in ("TEXT", "MTEXT") and hasattr(e.dxf, "text")]  # fmt: skip
    assert any("'root'" in label for label in labels), labels


def test_the_takeoff_dxf_cuts_the_holes_and_the_tabs_and_labels_them(takeoff_build,
                                                                    takeoff_fabrication):
    pytest.importorskip("ezdxf")
    _, out, _ = takeoff_build
    trunk = takeoff_fabrication.sheets[0].pattern
    cuts, texts = _dxf_lines(out / "hand_sheet_0.dxf", "Cut")
    for hole in trunk.hole_polygons():
        edges = np.stack([hole, np.roll(hole, -1, axis=0)], axis=1) * MM
        assert _on_lines(_samples(edges), cuts).all()
    assert "cut out hole A" in texts[0] and "hole B" in texts[0]
    for k in (1, 2):
        sheet = takeoff_fabrication.sheets[k]
        cuts, texts = _dxf_lines(out / f"hand_sheet_{k}.dxf", "Cut")
        tabs = sheet.pattern.regions().tab_outline_segments()
        W, b = sheet.pattern.width, sheet.pattern.sideLength
        inside = (tabs[:, :, 0] > -0.5 * b - 1e-9) & (tabs[:, :, 0] < W + 0.5 * b + 1e-9)
        tabs = tabs[inside.all(axis=1)]
        assert _on_lines(_samples(tabs * MM), cuts).all()
        assert f"glue them inside hole {sheet.takeoff} of sheet 0" in texts[0]
        assert sheet.takeoff in (out / f"hand_sheet_{k}.svg").read_text()


def test_the_takeoff_fold_files_meet_in_the_world(takeoff_build, takeoff_fabrication):
    """The branch sheets' FOLD files, folded, put their fish-mouths on the trunk sheet's hole
    vertices (the files' folded forms are in the tree's world frame, mm)."""
    _, out, _ = takeoff_build
    data = {k: json.loads((out / f"hand_sheet_{k}.fold").read_text()) for k in range(3)}
    trunk = np.array(data[0]["file_frames"][0]["vertices_coords"])
    for t in takeoff_fabrication.takeoffs:
        sheet = data[t.branch_sheet]
        flat = np.array(sheet["vertices_coords"])
        folded = np.array(sheet["file_frames"][0]["vertices_coords"])
        fm = (t.junction.fish_mouth - [0.0, t.junction.skirt_base]) * MM
        at = [int(np.argmin(np.hypot(*(flat - p).T))) for p in fm]
        gap = np.linalg.norm(folded[at][:, None] - trunk[None], axis=2).min(axis=1)
        assert gap.max() <= 1e-6  # mm; measured 1e-13


def test_the_connector_build_fold_files_start_where_their_sheets_start(hand_build):
    """As the take-off sheets: every sheet's FOLD file is folded in the tree's world frame, its
    proximal polygon centred on the sheet's frame (mm), its axis along the frame's x."""
    import warnings

    from kinegami.design import load_design_with_info
    from kinegami.errors import ClearanceWarning
    from kinegami.fabrication.sheets import fabricate, fit_junctions

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        tree, info = load_design_with_info(HAND)
    fabrication = fabricate(fit_junctions(tree)[0], twistPortion=info.twistPortion)
    _, out, _ = hand_build
    for sheet in fabrication.sheets:
        data = json.loads((out / f"hand_sheet_{sheet.index}.fold").read_text())
        flat = np.array(data["vertices_coords"])
        folded = np.array(data["file_frames"][0]["vertices_coords"])
        pattern = sheet.pattern
        base = pattern.vertices_coords[pattern.proximalBase] * MM
        at = [int(np.argmin(np.hypot(*(flat - p).T))) for p in base]
        assert np.hypot(*(flat[at] - base).T).max() <= 1e-9  # the base vertices themselves
        ring = folded[at]
        frame = np.asarray(sheet.frame)
        np.testing.assert_allclose(ring.mean(axis=0), frame[:3, 3] * MM, atol=1e-6)
        # the ring lies in the plane normal to the path direction, at radius r
        np.testing.assert_allclose((ring - frame[:3, 3] * MM) @ frame[:3, 0], 0.0, atol=1e-6)
        np.testing.assert_allclose(np.linalg.norm(ring - frame[:3, 3] * MM, axis=1), MM,
                                   rtol=1e-9)  # fmt: skip


def test_an_unknown_junction_kind_is_a_one_line_error(tmp_path, capsys):
    assert main_in_process("build", HAND, "-o", tmp_path, "--junctions", "glue") == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--junctions" in err[0] and "'glue'" in err[0], err
    assert "connector, takeoff, auto" in err[0]
    assert list(tmp_path.iterdir()) == []


def test_junctions_on_a_chain_is_a_note_not_silence(tmp_path, capsys):
    chain = ROOT / "examples" / "designs" / "example1.json"
    assert main_in_process("build", chain, "-o", tmp_path, "--formats", "dxf",
                           "--junctions", "takeoff") == 0  # fmt: skip
    err = capsys.readouterr().err
    assert "--junctions takeoff ignored" in err and "is a chain" in err
    assert names(tmp_path) == {"example1.dxf"}


def test_check_says_when_the_closest_parts_leave_one_junction(capsys):
    gripper = ROOT / "examples" / "designs" / "gripper.json"
    assert main_in_process("check", gripper) == 0
    out = capsys.readouterr().out
    assert "clear at its states" in out
    assert "closest where the tubes leaving joint 3 come out of its junction" in out
    # a chain never gets the note
    assert main_in_process("check", ROOT / "examples" / "designs" / "puma.json") == 0
    assert "junction" not in capsys.readouterr().out


def test_takeoffs_need_no_connector_library_and_a_bad_kind_is_checked_first(
    tmp_path, capsys, monkeypatch
):
    monkeypatch.setitem(sys.modules, "manifold3d", None)
    assert main_in_process("build", HAND, "-o", tmp_path / "a", "--formats", "dxf",
                           "--junctions", "takeoff") == 0  # fmt: skip
    assert "manifold3d" not in capsys.readouterr().err  # no connector to print: no note
    assert main_in_process("build", HAND, "-o", tmp_path / "b", "--junctions", "bogus") == 1
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and "--junctions: unknown kind 'bogus'" in err[0], err
    assert not (tmp_path / "b").exists()


def test_a_character_the_font_lacks_is_one_warning_line(tmp_path, capsys):
    """matplotlib warns (in Python's two-line form) when a name has a character its font cannot
    draw; the command line says it in one line, naming the character."""
    design = json.loads(HAND.read_text())
    renamed = [j for j in design["joints"] if j.get("name") == "palm"]
    assert renamed, "the hand names its palm"
    renamed[0]["name"] = "palm\N{RAISED HAND}"
    path = tmp_path / "hand.json"
    path.write_text(json.dumps(design), encoding="utf-8")
    assert main_in_process("build", path, "-o", tmp_path / "out", "--formats", "pdf") == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert err == ["kinegami build: warning: the font DejaVu Sans has no '\N{RAISED HAND}' "
                   "(U+270B): the PDF and the pictures draw it as an empty box"], err  # fmt: skip
