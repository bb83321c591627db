"""The browser view of a tree without a browser (as test_view.py does for chains): the paper's
hand drawn, its joint list, its sheets in the pattern panel, the downloads of every sheet, the
PDF and the junction connectors, and a chain that a branch turns into a tree."""

from __future__ import annotations

import io
import json
import re
import zipfile

import pytest

pytest.importorskip("viser")

from kinegami.clearance.solids import chain_parts  # noqa: E402
from kinegami.editor.server import EditorServer  # noqa: E402
from kinegami.editor.view import ALL_SHEETS, COLLIDING_COLOR, download_data  # noqa: E402

from .helpers import EXAMPLE1, HAND, HAND_SHEET_JOINTS  # noqa: E402


@pytest.fixture(scope="module")
def server():
    """One server of the paper's hand for the module (its worker process starts once)."""
    server = EditorServer(HAND, port=0, autosave=False)
    yield server
    server.stop()


def test_the_tree_is_drawn_part_by_part(view):
    assert view.meshes_sent == len(chain_parts(view.model.chain))
    assert len(view._joints) == 12 and view._links[0] is None


def test_the_joint_list_names_each_parent(view):
    labels = view._labels()
    assert labels[5] == "5: RevoluteJoint 'pointer1' (on 0)"
    assert labels[0] == "0: Waypoint 'root'"
    view.act(lambda: view.model.select("root"))
    assert "children 1, 5, 8" in view._joint_info.content


def test_the_hands_colliding_parts_are_red(view):
    (pair,) = view.model.clearance().pairs  # the palm's joint and the pointer's first link
    assert pair.elements == (2, 9)
    assert view.colour_of("joint", 1) == COLLIDING_COLOR
    assert view.colour_of("link", 5) == COLLIDING_COLOR
    assert "self-intersects" in view._clearance.content


def test_animate_sweeps_the_trees_joints_and_gives_the_states_back(view):
    import time

    base = view.model.document
    assert view.animate(period=0.5, fps=40.0)
    end = time.monotonic() + 20.0
    while view.animation_frames < 5:
        assert time.monotonic() < end, "timed out"
        time.sleep(0.02)
    assert view.stop_animation()
    assert view.model.document is base and not view.model.can_undo


def test_the_tree_widgets_are_shown(view):
    assert view._sheet.visible and view._junctions.visible and view._fit.visible
    assert tuple(view._sheet.options) == (ALL_SHEETS, "sheet 0", "sheet 1", "sheet 2")


def test_the_pattern_panel_shows_every_sheet_fitted_in_the_worker(server):
    # the calls counted before the view exists: its panel's drawing, due after a pause, may
    # run in the background before the test body on a loaded machine
    calls = server.worker.calls
    view = server.new_view(server.server)
    try:
        view.flush()
        html = view.pattern_html
        for k in range(len(HAND_SHEET_JOINTS)):
            assert f'aria-label="crease pattern, sheet {k}"' in html
        assert html.count('class="kinegami-sheet-size"') == 3
        assert "Junction 0 (a printed connector) at joint 0 &#x27;root&#x27;" in html
        assert "slid -30.0 mm along its axis" in html  # -3 r, r = 1 cm
        assert server.worker.calls == calls + 1
    finally:
        view.close()


def test_selecting_a_joint_highlights_it_on_its_sheet(view):
    view.act(lambda: view.model.select("pointer2"))
    view.flush()
    html = view.pattern_html
    sheet1 = html.split('aria-label="crease pattern, sheet 1"')[1].split("</svg>")[0]
    assert 'class="kinegami-highlight"' in sheet1
    assert html.count('class="kinegami-highlight"') == 2  # the sheet and the close-up
    assert "close-up: joint 6 (RevoluteJoint &#x27;pointer2&#x27;) (sheet 1)" in html


def test_every_sheet_downloads_with_its_label(view):
    ezdxf = pytest.importorskip("ezdxf")
    for k in range(3):
        view._sheet.value = f"sheet {k}"
        name, data = view.download(".dxf")
        assert name == f"Three-finger_hand_sheet_{k}.dxf"
        texts = [e.dxf.text for e in ezdxf.read(io.StringIO(data.decode())).modelspace()
                 if e.dxftype() == "TEXT"]  # fmt: skip
        assert any(t.startswith(f"sheet {k}:") for t in texts), texts
    name, data = view.download(".fold")
    assert name == "Three-finger_hand_sheet_2.fold" and json.loads(data)["file_spec"]
    view._sheet.value = ALL_SHEETS
    name, data = view.download(".svg")
    assert name == "Three-finger_hand_sheets_svg.zip"
    assert sorted(zipfile.ZipFile(io.BytesIO(data)).namelist()) == [
        f"Three-finger_hand_sheet_{k}.svg" for k in range(3)
    ]


def test_the_pdf_has_a_page_per_sheet(view):
    name, data = view.download(".pdf")
    assert name == "Three-finger_hand.pdf" and data.startswith(b"%PDF")
    assert len(re.findall(rb"/Type\s*/Page\b", data)) == 3


def test_the_junctions_download_as_stl_and_3mf(view):
    trimesh = pytest.importorskip("trimesh")
    pytest.importorskip("manifold3d")
    name, data = view.download("junctions")
    archive = zipfile.ZipFile(io.BytesIO(data))
    assert name == "Three-finger_hand_junctions.zip"
    assert sorted(archive.namelist()) == ["Three-finger_hand_junction_0.3mf",
                                          "Three-finger_hand_junction_0.stl"]  # fmt: skip
    mesh = trimesh.load(io.BytesIO(archive.read("Three-finger_hand_junction_0.stl")),
                        file_type="stl")  # fmt: skip
    assert mesh.is_watertight


def test_the_whole_tree_downloads_as_stl_and_urdf(view):
    name, data = view.download(".stl")
    assert name == "Three-finger_hand.stl" and len(data) > 84
    name, data = view.download(".urdf")
    assert "Three-finger_hand.urdf" in zipfile.ZipFile(io.BytesIO(data)).namelist()


def test_a_refused_delete_shows_the_reason_and_changes_nothing(view):
    document, sent = view.model.document, view.meshes_sent
    result = view.act(lambda: view.model.delete("root"))
    assert not result.ok and "has 3 children" in view.message
    assert view.model.document is document and view.meshes_sent == sent


def test_a_branch_sends_only_the_new_parts(view):
    before = view.meshes_sent
    view.act(lambda: view.model.select("pointer2"))
    result = view.add_branch("RevoluteJoint")
    assert result.ok, result.reason
    new = [k for k in range(12, len(view.model.chain.Joints))]
    tree = view.model.chain
    expected = sum(1 for part in chain_parts(tree) if part.index in new)
    assert view.meshes_sent - before == expected
    assert tuple(view._sheet.options)[-1] == "sheet 3"
    view._sheet.value = "sheet 3"
    view.act(view._undo)  # the fourth sheet is gone: the menu falls back to every sheet
    assert tuple(view._sheet.options)[-1] == "sheet 2" and view._sheet.value == ALL_SHEETS


def test_a_branch_turns_a_chains_view_into_a_trees():
    server = EditorServer(EXAMPLE1, port=0, autosave=False)
    try:
        view = server.new_view(server.server)
        assert not view._sheet.visible
        view.act(lambda: view.model.select("revolute"))
        assert view.add_branch("RevoluteJoint").ok and view.model.is_tree
        assert view._sheet.visible and view._junctions.visible
        view.flush()  # this branch leaves no room for the first child's socket: said so
        assert "No crease pattern:" in view.pattern_html
        assert "cannot be made with printed junctions" in view.pattern_html
        assert view.download(".dxf") is None and "Download failed" in view.message
        assert view.download(".stl")[0].endswith(".stl")  # the tree as drawn still downloads
        assert view.download(".json")[0].endswith(".json")
        view.act(view._undo)
        assert not view.model.is_tree and not view._sheet.visible
        view.flush()
        assert 'aria-label="crease pattern, whole sheet"' in view.pattern_html
        view.close()
    finally:
        server.stop()


def test_a_chain_has_no_junctions_to_download():
    from kinegami.editor import EditorModel

    with pytest.raises(TypeError, match="a chain has none"):
        download_data(EditorModel.open(EXAMPLE1), "junctions")
