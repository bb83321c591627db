"""The browser view's logic without a browser: a viser server on a free port, no client, and
an EditorView drawing on the server's own scene and panel (docs/editor.md, The browser view)."""

from __future__ import annotations

import io

import numpy as np
import pytest
from numpy.testing import assert_allclose

pytest.importorskip("viser")

from kinegami.cli import main  # noqa: E402
from kinegami.editor import EditorModel  # noqa: E402
from kinegami.editor.server import EditorServer  # noqa: E402
from kinegami.editor.view import (  # noqa: E402
    COLLIDING_COLOR,
    DOWNLOADS,
    MAX_UPLOAD_BYTES,
    SELECTED_COLOR,
    download_data,
)
from kinegami.export.mesh import chain_parts, joint_parts, link_parts  # noqa: E402

from .helpers import EXAMPLE1  # noqa: E402


@pytest.fixture
def server():
    server = EditorServer(EXAMPLE1, port=0, autosave=False)
    yield server
    server.stop()


@pytest.fixture
def view(server):
    view = server.new_view(server.server)
    yield view
    view.close()


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


def test_state_change_resends_only_the_joint(view):
    before = view.meshes_sent
    assert view.set_state(4, 0.3).ok
    assert view.meshes_sent - before == len(joint_parts(view.model.chain.Joints[4], 4))


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
    for ((index, _), handle), row in zip(view._sliders, rows, strict=True):
        assert index == row.index
        assert (handle.min, handle.max) == pytest.approx(row.state_range)


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
        assert "self-intersecting" in view._clearance.content
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
