"""The browser view's framing, units, typed values and shortcuts without a browser: a viser
server on a free port and an EditorView drawing on the server's own scene and panel
(docs/editor.md: Framing, Units, Typed values, Keyboard shortcuts)."""

from __future__ import annotations

import json
import math
import re

import numpy as np
import pytest
from numpy.testing import assert_allclose

pytest.importorskip("viser")

from kinegami.editor.keys import SHORTCUTS, keys_script, shortcuts_markdown  # noqa: E402
from kinegami.editor.server import EditorServer  # noqa: E402
from kinegami.editor.units import pose_to_display  # noqa: E402
from kinegami.errors import InvalidParameterError  # noqa: E402

from .helpers import EXAMPLE1, ROOT, snapshot  # noqa: E402

PUMA = ROOT / "examples" / "designs" / "puma.json"

pytestmark = pytest.mark.filterwarnings("ignore::kinegami.errors.ClearanceWarning")


@pytest.fixture
def server():
    server = EditorServer(PUMA, port=0, autosave=False)
    yield server
    server.stop()


def _mesh_points(view) -> np.ndarray:
    from kinegami.clearance.solids import chain_parts

    return np.concatenate([part.vertices for part in chain_parts(view.model.chain)])


def test_the_puma_opens_framed_with_its_grid_in_mm(view):
    points = _mesh_points(view)
    lo, hi = view.design_box()
    assert (points >= lo - 1e-9).all() and (points <= hi + 1e-9).all()
    assert_allclose(lo, points.min(0), atol=1e-6)  # the box is the meshes' own
    framing = view.framing
    assert framing.far > framing.distance + framing.radius > 1000.0
    assert view.grid.section == 200.0 and view.grid.cell == 50.0  # mm
    assert view._grid_handle.cell_size == 50.0 and view._grid_handle.section_size == 200.0
    assert view._world_axes.axes_length == 200.0
    assert "Lengths in **mm**" in view._view_text.content
    assert "50 mm cells, 200 mm sections" in view._view_text.content
    assert view._step.label == "Slide by (mm)" and view._step.value == 10.0  # 0.4 r


def test_opening_another_design_resizes_the_grid_axes_step_and_framing(view):
    puma = (view.framing.radius, view.grid.section)
    assert view.open_example("example1")
    assert view.model.document.units == "cm"
    assert view.framing.radius < puma[0] / 20.0
    assert view.grid.section < puma[1] / 20.0
    assert view._world_axes.axes_length == view.grid.section
    assert view._step.label == "Slide by (cm)" and view._step.value == 0.5
    points = _mesh_points(view)
    lo, hi = view.design_box()
    assert (points >= lo - 1e-9).all() and (points <= hi + 1e-9).all()
    assert "Lengths in **cm**" in view._view_text.content


def test_the_box_follows_moved_parts(view):
    view.act(lambda: view.model.select(2))
    assert view.act(lambda: view.model.slide(2, 300.0, propagate=True)).ok
    points = _mesh_points(view)
    lo, hi = view.design_box()
    assert (points >= lo - 1e-6).all() and (points <= hi + 1e-6).all()


def test_frame_all_reports_the_size_in_the_units(view):
    framing = view.frame_all()
    assert framing is view.framing
    assert re.match(r"framed all: 12\d\d mm across, seen from \d+ mm", view.message), view.message


def test_state_sliders_are_in_degrees_and_the_panel_names_units(view):
    slider = view._sliders[0][1]
    assert (slider.min, slider.max) == pytest.approx((-90.0, 90.0))
    view.act(lambda: view.model.select(1))
    assert "state 0° in [-90°, 90°]" in view._joint_info.content
    assert "- totalBendingAngle: 180°" in view._joint_info.content
    slider.value = 45.0
    view._on_slider(0, slider)
    assert view.model.chain.Joints[0].state == pytest.approx(math.pi / 4)


def test_typed_pose_parameters_and_state_are_undoable_commands(view):
    view.act(lambda: view.model.select(2))
    fields = view._joint_fields
    position, angles = pose_to_display(view.model.chain.Joints[2].pose_matrix)
    assert fields["position"].value == pytest.approx(position, abs=0.01)
    assert fields["orientation"].value == pytest.approx(angles, abs=1e-4)
    assert {"parameter totalBendingAngle", "parameter numSinkLayers", "state"} <= set(fields)
    # a typed x only: the joint moves along x and keeps its exact rotation
    before = view.model.chain.Joints[2].pose_matrix.copy()
    moved = (fields["position"].value[0] + 40.0,) + tuple(fields["position"].value[1:])
    result = view.set_typed_pose(position=moved)
    assert result.ok, result.reason
    after = view.model.chain.Joints[2].pose_matrix
    assert after[0, 3] == pytest.approx(moved[0], abs=1e-9)  # the typed x
    assert_allclose(after[1:3, 3], before[1:3, 3], atol=1e-9)  # y and z as they were
    assert np.array_equal(after[:3, :3], before[:3, :3])
    assert fields["position"].value[0] == pytest.approx(moved[0])  # refilled
    # a typed yaw: the rotation is the typed one
    turned = (angles[0], angles[1], angles[2] + 10.0)
    assert view.set_typed_pose(angles=turned).ok
    assert pose_to_display(view.model.chain.Joints[2].pose_matrix)[1] == pytest.approx(turned)
    assert view.set_typed_parameters({"totalBendingAngle": 150.0}).ok
    assert view.model.joint_table()[2].parameters["totalBendingAngle"] == pytest.approx(
        math.radians(150.0))  # fmt: skip
    assert view.set_typed_state(-30.0).ok
    assert view.model.chain.Joints[2].state == pytest.approx(math.radians(-30.0))
    assert view.model.undo_labels == (
        "set pose of joint 2", "set pose of joint 2",
        "change totalBendingAngle of joint 2", "set state of joint 2 to -0.5235987755982988",
    )  # fmt: skip
    for _ in range(4):
        assert view.act(view._undo).ok
    assert np.array_equal(view.model.chain.Joints[2].pose_matrix, before)


@pytest.mark.parametrize(
    ("action", "value", "reason"),
    [("parameters", {"numSinkLayers": 2.5}, "numSinkLayers must be an integer in [1, 32], got 2.5"),
     ("parameters", {"totalBendingAngle": 0.0}, "totalBendingAngle must be in (0, 2pi) radians"),
     ("state", 120.0, "state of joint 2 (RevoluteJoint) must be in [-1.5708, 1.5708] radians "
                      "([-90°, 90°]), got"),
     ("pose", (float("nan"), 0.0, 0.0), "set pose: position x must be a finite number"),
     ("pose", (0.0, 0.0, 0.0), "set pose of joint 2 (RevoluteJoint): transformJoint failed: "
                               "no CSC path")],
)  # fmt: skip
def test_a_refused_typed_value_shows_the_reason_and_changes_nothing(view, action, value, reason):
    view.act(lambda: view.model.select(2))
    before, document = snapshot(view.model.document), view.model.document
    call = {"parameters": view.set_typed_parameters, "state": view.set_typed_state,
            "pose": lambda v: view.set_typed_pose(position=v)}[action]  # fmt: skip
    result = call(value)
    assert not result.ok and result.reason.startswith(reason), result.reason
    assert view.message == f"**Refused:** {result.reason}"
    assert view.model.document is document and snapshot(view.model.document) == before
    assert not view.model.can_undo


def test_typed_fields_follow_the_joint_type(view):
    assert view.open_example("example1")
    view.act(lambda: view.model.select("prismatic"))
    fields = view._joint_fields
    assert fields["parameter neutralLength"].label == "neutralLength (cm)"
    assert fields["parameter coneAngle"].label == "coneAngle (°)"
    assert fields["state"].label == "State (cm)"
    assert fields["position"].label == "Position (cm)"
    view.act(lambda: view.model.select("end"))
    assert set(view._joint_fields) == {"position", "orientation", "set pose",
                                       "parameter length", "set parameters"}  # fmt: skip
    view.act(lambda: view.model.select(None))
    assert set(view._joint_fields) == {"none"}
    result = view.set_typed_state(1.0)
    assert not result.ok and "no joint is selected" in result.reason


def test_escape_cancels_a_drag_then_deselects(view):
    view.act(lambda: view.model.select(2))
    document = view.model.document
    pose = view.model.chain.Joints[2].pose_matrix
    assert view.drag_preview(pose[:3, 3] + 50.0 * pose[:3, 2], view._gizmo.wxyz).ok
    assert view.model.previewing
    assert view.escape() == "drag"
    assert not view.model.previewing and view.model.document is document

    class Event:
        phase = "end"

    view._gizmo.position = pose[:3, 3] + 60.0 * pose[:3, 2]  # where the mouse let go
    view._on_gizmo(Event())  # the drag's end after Escape applies nothing
    assert view.model.document is document and not view.model.can_undo
    assert_allclose(view._gizmo.position, pose[:3, 3])  # the handle is back
    assert view.escape() == "deselect" and view.model.selected is None
    assert view.escape() == "nothing"


def test_escape_closes_the_latest_dialog_first(view):
    closed = []
    view.dialog_cancels.append(lambda: closed.append("first"))
    view.dialog_cancels.append(lambda: closed.append("second"))
    view.act(lambda: view.model.select(2))
    assert view.escape() == "dialog" and closed == ["second"]
    assert view.escape() == "dialog" and closed == ["second", "first"]
    assert view.escape() == "deselect"


def test_the_shortcut_script_points_every_key_at_its_button(view):
    save = [view._save_file, view._download_design]
    script = keys_script({"undo": [view._undo_button], "save": save})
    targets = json.loads(re.search(r"k\.keyTargets = (\{.*\});", script).group(1))
    assert targets["undo"] == [view._undo_button._impl.uuid]
    assert targets["save"] == [view._save_file._impl.uuid, view._download_design._impl.uuid]
    assert targets["frame"] == []
    with pytest.raises(InvalidParameterError, match="unknown shortcut action 'print'"):
        keys_script({"print": []})
    assert view.send_shortcuts()
    table = shortcuts_markdown()
    for keys, _, what in SHORTCUTS:
        assert f"| {keys} | {what} |" in table
    assert view._shortcuts.content == table


def test_example1_opens_with_its_own_framing():
    server = EditorServer(EXAMPLE1, port=0, autosave=False)
    try:
        view = server.new_view(server.server)
        assert view.grid.section == 2.0 and view.grid.cell == 0.5  # cm
        assert 9.0 < view.framing.radius < 11.0
        view.close()
    finally:
        server.stop()


def test_a_field_being_typed_survives_other_changes_but_not_another_selection(view):
    view.act(lambda: view.model.select(2))
    view._joint_fields["state"].value = -30.0  # typed, not set yet
    assert view.act(lambda: view.model.rename(2, "shoulder")).ok  # the state did not change
    assert view._joint_fields["state"].value == -30.0
    assert view.set_typed_state().ok
    assert view.model.chain.Joints[2].state == pytest.approx(math.radians(-30.0))
    view._joint_fields["state"].value = 10.0
    view.act(lambda: view.model.select(3))  # another joint: its own values
    assert view._joint_fields["state"].value == 0.0


def test_recovering_an_autosave_of_another_size_resizes_the_grid_and_framing(view, tmp_path):
    """The tab shows the PUMA; the autosave it recovers is Example 1 (as if the design file
    had been replaced): one undoable step, and the grid and the camera follow."""
    from kinegami.editor import Document
    from kinegami.editor.autosave import Recovery

    puma = (view.grid.section, view.framing.radius)
    recovery = Recovery(tmp_path / "x.autosave", None, 0.0, Document.load(EXAMPLE1))
    assert view.choose_recovery(recovery, "recover").ok
    assert view.grid.section == 2.0 and view.framing.radius < puma[1] / 20.0
    points_lo, points_hi = view.design_box()
    assert (points_hi - points_lo).max() < 20.0  # cm: Example 1's box


class _Camera:
    """A tab's camera as viser checks it: min <= max orbit distance, assignments recorded."""

    fov, image_width, image_height = math.radians(75.0), 800, 900

    def __init__(self):
        self.near, self.far = 0.01, 1000.0
        self._min, self._max = 0.01, 1e4
        self.up_direction = self.position = self.look_at = None

    @property
    def min_orbit_distance(self):
        return self._min

    @min_orbit_distance.setter
    def min_orbit_distance(self, value):
        if value > self._max:
            raise ValueError(f"min_orbit_distance ({value}) must be <= max ({self._max})")
        self._min = value

    @property
    def max_orbit_distance(self):
        return self._max

    @max_orbit_distance.setter
    def max_orbit_distance(self, value):
        if value < self._min:
            raise ValueError(f"max_orbit_distance ({value}) must be >= min ({self._min})")
        self._max = value


def test_the_camera_is_set_from_a_huge_design_to_a_tiny_one_and_back(view, monkeypatch):
    """From the PUMA (mm) to Example 1 scaled to metres (1/1000 of its numbers) and back: the
    zoom limits and clipping planes are set in an order viser accepts."""
    from types import SimpleNamespace

    camera = _Camera()
    monkeypatch.setattr(view, "target", SimpleNamespace(camera=camera))
    big = view.frame_camera()
    assert (camera.near, camera.far) == (big.near, big.far)
    limits = (camera.min_orbit_distance, camera.max_orbit_distance)
    assert limits == (big.min_distance, big.max_distance)
    tiny = np.array([[0.0, 0.0, 0.0], [0.012, 0.01, 0.013]])
    monkeypatch.setattr(view, "design_box", lambda: (tiny[0], tiny[1]))
    small = view.frame_camera()
    assert small.max_distance < big.min_distance  # the order matters
    limits = (camera.min_orbit_distance, camera.max_orbit_distance)
    assert limits == (small.min_distance, small.max_distance)
    assert camera.far == small.far and camera.near == small.near
    assert_allclose(camera.look_at, tiny.mean(0))
    monkeypatch.undo()
    monkeypatch.setattr(view, "target", SimpleNamespace(camera=camera))
    again = view.frame_camera()
    assert camera.max_orbit_distance == again.max_distance
