"""The browser view's logic without a browser: a viser server on a free port, no client, and
an EditorView drawing on the server's own scene and panel (docs/editor.md, The browser view)."""

from __future__ import annotations

import io

import numpy as np
import pytest
from numpy.testing import assert_allclose

pytest.importorskip("viser")

from kinegami.clearance.solids import chain_parts, joint_parts, link_parts  # noqa: E402
from kinegami.cli import main  # noqa: E402
from kinegami.editor import EditorModel  # noqa: E402
from kinegami.editor.autosave import autosave_path  # noqa: E402
from kinegami.editor.server import EditorServer  # noqa: E402
from kinegami.editor.view import (  # noqa: E402
    COLLIDING_COLOR,
    DOWNLOADS,
    MAX_UPLOAD_BYTES,
    SELECTED_COLOR,
    download_data,
)

from .helpers import EXAMPLE1  # noqa: E402


@pytest.fixture
def server():
    server = EditorServer(EXAMPLE1, port=0, autosave=False)
    yield server
    server.stop()


def test_server_binds_localhost_by_default(server):
    assert server.url.startswith("http://127.0.0.1:")
    assert server.port > 0


def test_view_draws_every_part_once(view):
    assert view.meshes_sent == len(chain_parts(view.model.chain))
    assert len(view._joints) == len(view.model.chain.Joints)


def test_slide_without_propagation_resends_only_its_links(view):
    before = view.meshes_sent
    result = view.act(lambda: view.model.slide(4, -0.5, propagate=False))
    assert result.ok
    chain = view.model.chain
    expected = sum(len(link_parts(chain.Links[i], i, chain.numSides)) for i in (4, 5))
    assert view.meshes_sent - before == expected


def _world(handle, *frames) -> np.ndarray:
    """A mesh's vertices in the world: its own, moved by the frames it hangs from (outermost
    first), each a viser (wxyz, position)."""
    from scipy.spatial.transform import Rotation

    points = np.asarray(handle.vertices, dtype=float)
    for frame in reversed(frames):
        w, x, y, z = frame.wxyz
        points = points @ Rotation.from_quat([x, y, z, w]).as_matrix().T + np.asarray(
            frame.position)
    return points


def test_a_prismatic_state_change_resends_only_the_joint(view):
    before = view.meshes_sent
    assert view.set_state(2, 0.3).ok
    assert view.meshes_sent - before == len(joint_parts(view.model.chain.Joints[2], 2))


def test_a_revolute_state_change_turns_its_distal_half_and_sends_no_mesh(view):
    """A revolute joint's halves are drawn at state 0, the distal one under a frame turned by
    the state: a state change (a drag, an animation) sends no mesh, and every vertex is where
    the joint's own parts at the new state put it (1e-6: viser sends single precision)."""
    from scipy.spatial import ConvexHull

    node = view._joints[4]
    before = view.meshes_sent
    for state in (0.3, -1.2, 0.7):
        assert view.set_state(4, state).ok
        assert view._joints[4] is node
        joint = view.model.chain.Joints[4]
        for part, handle in zip(joint_parts(joint, 4), node.handles, strict=True):
            frames = (node.frame, node.turn) if part.side == "distal" else (node.frame,)
            drawn = _world(handle, *frames)
            expected = np.asarray(part.vertices, dtype=float)
            # the same hull: every drawn vertex is a vertex of the part's, and the other way
            # (to viser's single precision)
            gap = np.linalg.norm(drawn[:, None] - expected[None], axis=2)
            assert gap.min(axis=1).max() <= 1e-6 and gap.min(axis=0).max() <= 1e-6
            assert ConvexHull(drawn).volume == pytest.approx(ConvexHull(expected).volume,
                                                             rel=1e-6)  # fmt: skip
    assert view.meshes_sent == before
    # an edit that reshapes the joint (its bending angle) draws it again, at its new shape
    assert view.act(lambda: view.model.set_parameters(4, totalBendingAngle=2.0)).ok
    assert view.meshes_sent > before and view._joints[4] is not node
    node, joint = view._joints[4], view.model.chain.Joints[4]
    for part, handle in zip(joint_parts(joint, 4), node.handles, strict=True):
        frames = (node.frame, node.turn) if part.side == "distal" else (node.frame,)
        drawn = _world(handle, *frames)
        gap = np.linalg.norm(drawn[:, None] - np.asarray(part.vertices)[None], axis=2)
        assert gap.min(axis=1).max() <= 1e-6 and gap.min(axis=0).max() <= 1e-6


def test_moved_meshes_get_the_new_pose(view):
    assert view.act(lambda: view.model.slide(2, 1.0, propagate=True)).ok
    pose = view.model.chain.Joints[-1].pose_matrix
    assert_allclose(view._joints[-1].frame.position, pose[:3, 3], atol=1e-6)


def test_drag_along_the_axis_slides_the_joint(view):
    view.act(lambda: view.model.select(4))
    pose = view.model.chain.Joints[4].pose_matrix.copy()
    sideways = pose[:3, 0] * 3.0  # motion off the axis is ignored
    result = view.drag_to(pose[:3, 3] + 0.5 * pose[:3, 2] + sideways, view._gizmo.wxyz)
    assert result.ok
    assert_allclose(view.model.chain.Joints[4].pose_matrix[:3, 3], pose[:3, 3] + 0.5 * pose[:3, 2],
                    atol=1e-9)  # fmt: skip


def test_refused_drag_snaps_back_with_the_reason(view):
    view.act(lambda: view.model.select(4))
    pose = view.model.chain.Joints[4].pose_matrix.copy()
    result = view.drag_to(pose[:3, 3] + 1e9 * pose[:3, 2], view._gizmo.wxyz)
    assert not result.ok
    assert "distance must be within" in view.message
    assert_allclose(view._gizmo.position, pose[:3, 3], atol=1e-6)
    assert_allclose(view.model.chain.Joints[4].pose_matrix, pose)


def test_selection_highlights_and_fills_the_panel(view):
    view.act(lambda: view.model.select(4))
    assert view.colour_of("joint", 4) == SELECTED_COLOR
    assert tuple(view._joints[4].handles[0].color) == SELECTED_COLOR
    assert str(view._joint_list.value).startswith("4: RevoluteJoint")
    assert "RevoluteJoint" in view._joint_info.content


def test_configuration_sliders_span_the_state_ranges(view):
    rows = [row for row in view.model.joint_table() if row.movable]
    assert len(view._sliders) == len(rows)
    for ((index, kind, _, _), handle), row in zip(view._sliders, rows, strict=True):
        assert index == row.index
        if kind == "PrismaticJoint":  # in the design's units (cm)
            assert (handle.min, handle.max) == pytest.approx(row.state_range)
        else:  # in degrees
            assert (handle.min, handle.max) == pytest.approx(np.degrees(row.state_range))


def test_colliding_parts_are_red():
    server = EditorServer(port=0, autosave=False)
    try:
        view = server.new_view(server.server)
        view.act(lambda: view.model.select(2))
        result = view.act(lambda: view.model.add_joint("RevoluteJoint"))
        assert result.ok and result.warnings
        report = view.model.clearance()
        assert not report.ok
        element = report.pairs[0].elements[0]
        kind, index = ("joint", element // 2) if element % 2 == 0 else ("link", (element + 1) // 2)
        if not (kind == "joint" and index == view.model.selected):
            assert view.colour_of(kind, index) == COLLIDING_COLOR
        assert "self-intersects" in view._clearance.content
    finally:
        server.stop()


def test_undo_redraws_the_original(view):
    first = view.model.document
    view.act(lambda: view.model.delete(4))
    assert len(view._joints) == len(view.model.chain.Joints)
    view.act(view._undo)
    assert view.model.document is first
    assert [node.obj for node in view._joints] == list(first.chain.Joints)


def test_dxf_download_reads_back_with_ezdxf(view):
    ezdxf = pytest.importorskip("ezdxf")
    name, data = view.download(".dxf")
    assert name.endswith(".dxf")
    doc = ezdxf.read(io.StringIO(data.decode()))
    assert len(doc.modelspace()) > 0


@pytest.mark.parametrize("suffix", [".json", *DOWNLOADS.values()])
def test_every_download_has_data(suffix):
    name, data = download_data(EditorModel.open(EXAMPLE1), suffix)
    assert data and name.endswith(".zip" if suffix == ".urdf" else suffix)


def test_upload_refuses_large_and_bad_files(view):
    document = view.model.document
    assert not view.upload("big.json", b" " * (MAX_UPLOAD_BYTES + 1))
    assert "16 MiB" in view.message
    assert not view.upload("bad.json", b"{not json")
    assert "not a design file" in view.message
    assert view.model.document is document


def test_upload_opens_a_design(view):
    assert view.upload("arm.json", EXAMPLE1.read_bytes())
    assert len(view._joints) == len(view.model.chain.Joints) == 7


def test_examples_open_only_gallery_designs(view):
    assert not view.open_example("../../pyproject")
    assert view.open_example("puma")
    assert view.model.document.name and len(view._joints) == len(view.model.chain.Joints)


def test_tabs_edit_their_own_documents(server):
    other = EditorServer(EXAMPLE1, port=0, autosave=False)
    try:
        a, b = server.new_view(server.server), other.new_view(other.server)
        assert a.act(lambda: a.model.slide(4, 0.5)).ok
        assert b.model.document is not a.model.document
        assert not np.array_equal(a.model.chain.Joints[4].pose_matrix,
                                  b.model.chain.Joints[4].pose_matrix)  # fmt: skip
    finally:
        other.stop()


def test_cli_edit_refuses_a_bad_port(capsys):
    assert main(["edit", "--port", "99999"]) == 1
    assert "--port must be an integer in [0, 65535]" in capsys.readouterr().err


def test_cli_edit_refuses_a_missing_design(capsys, tmp_path):
    assert main(["edit", str(tmp_path / "missing.json"), "--port", "0"]) == 1
    assert capsys.readouterr().err.startswith("kinegami edit: error:")


def test_quaternions_of_rotations():
    from scipy.spatial.transform import Rotation

    from kinegami.editor.view import _matrix, _wxyz

    flips = [np.diag(d) for d in ([1.0, -1.0, -1.0], [-1.0, 1.0, -1.0], [-1.0, -1.0, 1.0])]
    rotations = [np.eye(3), *flips, *Rotation.random(50, random_state=1).as_matrix()]
    for R in rotations:
        assert_allclose(_matrix(_wxyz(R)), R, atol=1e-12)


def test_clicking_a_joint_mesh_selects_it(view):
    node = view._joints[4]
    view._click(node)
    assert view.model.selected == 4
    assert view._gizmo.visible
    assert_allclose(view._gizmo.position, view.model.chain.Joints[4].pose_matrix[:3, 3], atol=1e-6)


# --- the crease-pattern panel -------------------------------------------------------------------
def test_the_pattern_panel_shows_the_sheet_and_its_size(view):
    view.flush()
    html = view.pattern_html
    assert "<svg" in html and 'class="kinegami-M"' in html and 'class="kinegami-V"' in html
    pattern = view.model.pattern()
    from kinegami.pattern.sheet import flatten

    sheet = flatten(pattern)
    xmin, y0, xmax, y1 = sheet.bounds
    # example1 is in cm: the sheet's size in mm is ten times its size in pattern units
    assert f"Sheet {10 * (y1 - y0):.1f} x {10 * (xmax - xmin):.1f} mm" in html
    assert f"{sheet.count('M')} mountain, {sheet.count('V')} valley" in html


def test_the_pattern_is_drawn_after_a_pause_not_in_the_edit(view):
    view.flush()
    draws, before = view.pattern_draws, view.pattern_html
    assert view.act(lambda: view.model.slide(4, 0.5, propagate=False)).ok
    assert view.pattern_draws == draws  # nothing drawn while the edit runs
    view.flush()
    assert view.pattern_draws == draws + 1 and view.pattern_html != before


def test_the_pattern_is_drawn_again_only_when_it_or_the_selection_changed(view):
    view.act(lambda: view.model.select(4))
    view.flush()
    draws = view.pattern_draws
    view.set_state(4, 0.3)  # states move the chain, not its crease pattern
    view.flush()
    assert view.pattern_draws == draws
    view.act(lambda: view.model.select(2))
    view.flush()
    assert view.pattern_draws == draws + 1


def test_selecting_a_joint_highlights_its_modules(view):
    import re

    from kinegami.editor.sheet_drawing import joint_span

    view.click_joint(4)
    view.flush()
    pattern = view.model.pattern()
    lo, hi = joint_span(pattern, view.model.joint_modules()[4])
    y0 = float(pattern.proximalMarker[1])
    match = re.search(r'class="kinegami-highlight" x="([-\d.e]+)" y="0" width="([-\d.e]+)"',
                      view.pattern_html)  # fmt: skip
    assert match is not None
    assert float(match[1]) == pytest.approx(lo - y0, rel=1e-4)
    assert float(match[2]) == pytest.approx(hi - lo, rel=1e-4)
    # the revolute joint's own vertices span what is highlighted
    ys = pattern.vertices_coords[pattern.module_vertices[view.model.joint_modules()[4][0]], 1]
    assert (ys.min(), ys.max()) == pytest.approx((lo, hi))
    assert "close-up: joint 4 (RevoluteJoint &#x27;revolute&#x27;)" in view.pattern_html


def test_a_waypoint_is_marked_by_a_line(view):
    view.act(lambda: view.model.select(3))
    view.flush()
    assert "no modules of its own" in view.pattern_html
    assert 'stroke-width="3"' in view.pattern_html


# --- animation --------------------------------------------------------------------------------
def _wait(condition, timeout: float = 30.0):
    import time

    end = time.monotonic() + timeout
    while not condition():
        assert time.monotonic() < end, "timed out"
        time.sleep(0.02)


def test_animate_sweeps_the_joints_without_undo_entries(view):
    base = view.model.document
    seen = set()

    def watch(change):
        seen.add(round(float(view.model.chain.Joints[4].state), 3))

    view.model.subscribe(watch)
    assert view.toggle_animation() and view.animating
    _wait(lambda: view.animation_frames >= 5)
    assert len(seen) >= 3  # the revolute joint moved through several states
    assert not view.model.can_undo and not view.model.dirty
    assert view.model.base_document is base
    assert not view.toggle_animation() and not view.animating
    assert view.model.document is base  # the states are back as they were


def test_animate_reaches_both_ends_of_the_ranges(view):
    lo, hi = view.model.joint_table()[4].state_range
    states = []
    view.model.subscribe(lambda change: states.append(float(view.model.chain.Joints[4].state)))
    view.animate(period=0.6, fps=60.0)
    _wait(lambda: view.animation_frames >= 40)
    view.stop_animation()
    assert min(states) < lo + 0.2 * (hi - lo) and max(states) > hi - 0.2 * (hi - lo)
    assert all(lo - 1e-12 <= s <= hi + 1e-12 for s in states)


def test_an_edit_stops_the_animation_and_applies_to_the_design(view):
    base = view.model.document
    view.animate()
    _wait(lambda: view.animation_frames >= 2)
    assert view.act(lambda: view.model.slide(4, 0.5)).ok
    assert not view.animating
    assert view.model.undo_labels == ("slide joint 4 by 0.5",)
    view.act(view.model.undo)
    assert view.model.document is base


# --- autosave, saving and recovery ----------------------------------------------------------------
@pytest.fixture
def design(tmp_path):
    import shutil

    path = tmp_path / "arm.json"
    shutil.copyfile(EXAMPLE1, path)
    return path


def _edited(server) -> tuple:
    view = server.new_view(server.server)
    assert view.act(lambda: view.model.slide(4, 0.5, propagate=False)).ok
    view.autosave.flush()
    return view, view.model.document.design_text


def test_edits_are_autosaved_in_the_data_folder_never_beside_the_design(design, data_home):
    server = EditorServer(design, port=0)
    try:
        view, text = _edited(server)
        autosave = autosave_path(design)
        assert autosave.read_text(encoding="utf-8") == text
        assert autosave.parent == data_home / "kinegami" / "autosaves"
        assert design.read_bytes() == EXAMPLE1.read_bytes()
        assert sorted(p.name for p in design.parent.iterdir()) == ["arm.json"]
    finally:
        server.stop()


def test_save_to_file_writes_the_design_and_removes_the_autosave(design):
    server = EditorServer(design, port=0)
    try:
        view, text = _edited(server)
        assert view._save_file.visible and view._save_file.label == "Save to arm.json"
        assert view.save_file().ok
        assert design.read_text(encoding="utf-8") == text
        assert not autosave_path(design).exists()
        assert not view.model.dirty
    finally:
        server.stop()


def test_a_new_start_offers_the_autosave_back(design):
    server = EditorServer(design, port=0)
    try:
        _, text = _edited(server)
    finally:
        server.stop()  # as after a crash: the design file was never saved
    again = EditorServer(design, port=0)
    try:
        assert again.recovery is not None and again.recovery.document.design_text == text
        view = again.new_view(again.server)
        assert view._recovery_modal is not None  # the dialog asks
        assert view.model.document.design_text != text
        view.choose_recovery(again.recovery, "recover")
        assert view.model.document.design_text == text and view.model.dirty
        assert view.model.undo_labels[-1].startswith("recover the autosave")
        view.act(view.model.undo)
        assert view.model.document is again.document
    finally:
        again.stop()


def test_discarding_the_offer_removes_the_autosave(design):
    server = EditorServer(design, port=0)
    try:
        _edited(server)
    finally:
        server.stop()
    again = EditorServer(design, port=0)
    try:
        view = again.new_view(again.server)
        view.choose_recovery(again.recovery, "discard")
        assert not autosave_path(design).exists()
        assert view.model.document is again.document
    finally:
        again.stop()


def test_an_old_autosave_beside_the_design_is_offered_and_moved_to_the_data_folder(design):
    server = EditorServer(design, port=0)
    try:
        _, text = _edited(server)
    finally:
        server.stop()
    legacy = design.parent / ".arm.json.autosave"  # where earlier versions wrote it
    autosave_path(design).replace(legacy)
    again = EditorServer(design, port=0)
    try:
        assert again.recovery is not None and again.recovery.path == legacy
        view = again.new_view(again.server)
        view.choose_recovery(again.recovery, "recover")
        assert view.model.document.design_text == text and view.model.dirty
        assert not legacy.exists()  # moved: now in the data folder
        assert autosave_path(design).read_text(encoding="utf-8") == text
        assert sorted(p.name for p in design.parent.iterdir()) == ["arm.json"]
    finally:
        again.stop()


def test_recover_starts_every_tab_from_the_autosave(design):
    server = EditorServer(design, port=0)
    try:
        _, text = _edited(server)
    finally:
        server.stop()
    again = EditorServer(design, port=0, recover=True)
    try:
        view = again.new_view(again.server)
        assert view._recovery_modal is None
        assert view.model.document.design_text == text and view.model.dirty
    finally:
        again.stop()


def test_without_a_file_the_autosave_is_in_the_data_folder(data_home):
    server = EditorServer(port=0)
    try:
        view, text = _edited(server)
        autosave = data_home / "kinegami" / "untitled.json.autosave"
        assert autosave.read_text(encoding="utf-8") == text
        assert not view._save_file.visible and not view.save_file().ok
        view.download(".json")  # with no file on the server, the download is the save
        assert not autosave.exists()
    finally:
        server.stop()


def test_a_design_opened_in_the_browser_autosaves_in_the_data_folder(data_home, design):
    server = EditorServer(design, port=0)
    try:
        view = server.new_view(server.server)
        assert view.open_example("puma")
        assert view.act(lambda: view.model.slide(1, 0.5)).ok
        view.autosave.flush()
        assert (data_home / "kinegami" / "untitled.json.autosave").exists()
        assert not autosave_path(design).exists()
        assert sorted(p.name for p in design.parent.iterdir()) == ["arm.json"]
        assert not view._save_file.visible
    finally:
        server.stop()


# --- a live handle drag -------------------------------------------------------------------------
def test_a_handle_drag_is_previewed_and_its_end_is_one_command(view):
    view.click_joint(4)
    pose = view.model.chain.Joints[4].pose_matrix.copy()
    base = view.model.document
    for k in range(1, 6):
        result = view.drag_preview(pose[:3, 3] + 0.1 * k * pose[:3, 2], view._gizmo.wxyz)
        assert result.ok and view.model.previewing
        assert_allclose(view.model.chain.Joints[4].pose_matrix[:3, 3],
                        pose[:3, 3] + 0.1 * k * pose[:3, 2], atol=1e-9)  # fmt: skip
        assert_allclose(view._joints[4].frame.position, pose[:3, 3] + 0.1 * k * pose[:3, 2],
                        atol=1e-6)  # fmt: skip
    assert not view.model.can_undo and view.model.base_document is base
    sent = view.meshes_sent
    assert view.drag_to(pose[:3, 3] + 0.5 * pose[:3, 2], view._gizmo.wxyz).ok
    assert view.meshes_sent == sent  # the last preview already showed it
    assert len(view.model.undo_labels) == 1 and not view.model.previewing
    assert_allclose(view.model.chain.Joints[4].pose_matrix[:3, 3], pose[:3, 3] + 0.5 * pose[:3, 2],
                    atol=1e-9)  # fmt: skip


def test_a_stale_drag_event_is_skipped(view):
    view.click_joint(4)
    pose = view.model.chain.Joints[4].pose_matrix.copy()
    view._drag_latest = 7
    assert view.drag_preview(pose[:3, 3] + pose[:3, 2], view._gizmo.wxyz, drag=6) is None
    assert not view.model.previewing


def test_a_drag_released_where_it_began_changes_nothing(view):
    view.click_joint(4)
    pose = view.model.chain.Joints[4].pose_matrix.copy()
    base = view.model.document
    view.drag_preview(pose[:3, 3] + pose[:3, 2], view._gizmo.wxyz)
    assert view.drag_to(pose[:3, 3], view._gizmo.wxyz) is None
    assert view.model.document is base and not view.model.can_undo
