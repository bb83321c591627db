"""``kinegami edit`` in headless Chromium (tests/headless_chromium.py; see test_browser.py):
framing, typed values and keyboard shortcuts, on the PUMA (mm, r = 25), the paper's hand (a
tree, cm) and Example 1 (cm, r = 1). Visibility is measured on the page: a screenshot of the
canvas with the grid and world axes hidden, pixels that differ from the background (the
canvas's corners). Each step saves a screenshot in the test's tmp folder."""

from __future__ import annotations

import math
import shutil
import time

import numpy as np
import pytest

from .helpers import EXAMPLE1, HAND, ROOT, choose, snapshot
from .test_browser import TIMEOUT, wait_for

pytestmark = [pytest.mark.browser,
              pytest.mark.filterwarnings("ignore::kinegami.errors.ClearanceWarning")]  # fmt: skip

PUMA = ROOT / "examples" / "designs" / "puma.json"
#: The least share of the canvas the design covers on first paint, and the most it may
#: cover (all of it in view, with a margin).
MIN_COVER, MAX_COVER = 0.01, 0.6


def _server(path):
    from kinegami.editor.server import EditorServer

    return EditorServer(path, port=0, autosave=False)


@pytest.fixture(scope="module")
def servers(browser, tmp_path_factory):
    """One server per design; the PUMA's on a copy of its file (Ctrl+S writes it)."""
    folder = tmp_path_factory.mktemp("designs")
    puma = folder / "puma.json"
    shutil.copyfile(PUMA, puma)
    made = {"puma": _server(puma), "hand": _server(HAND), "example1": _server(EXAMPLE1)}
    yield made
    for server in made.values():
        server.stop()


def open_tab(browser, server):
    """A new tab on ``server`` and the server's view of it, once the panel is there."""
    before = set(server.views)
    page = browser.new_page(viewport={"width": 1600, "height": 900}, accept_downloads=True)
    page.set_default_timeout(TIMEOUT * 1000)
    page.goto(server.url)
    new = wait_for(lambda: set(server.views) - before, "the tab's editor view")
    view = server.views[new.pop()]
    page.wait_for_selector("canvas")
    page.get_by_role("button", name="Frame all").wait_for()
    close = page.locator(".mantine-Notification-closeButton")  # "software WebGL" notice
    if close.count():
        close.first.click()
    return page, view


def coverage(page, view, path) -> tuple[float, tuple[int, int, int, int], tuple[int, int]]:
    """(share of the canvas the design covers, bounding box of its pixels (x0, y0, x1, y1),
    canvas size) from a screenshot of the canvas with the grid and world axes hidden (shown
    again after)."""
    from PIL import Image

    with view.lock:
        view._grid_handle.visible = False
        view._world_axes.visible = False
    time.sleep(1.5)  # the software renderer draws the frame
    page.locator("canvas").first.screenshot(path=path)
    with view.lock:
        view._grid_handle.visible = True
        view._world_axes.visible = True
    image = np.asarray(Image.open(path).convert("RGB"), dtype=int)
    corners = np.array([image[2, 2], image[2, -3], image[-3, 2], image[-3, -3]])
    background = np.median(corners, axis=0)
    drawn = np.abs(image - background).sum(axis=2) > 40
    ys, xs = np.nonzero(drawn)
    box = (int(xs.min()), int(ys.min()), int(xs.max()), int(ys.max())) if len(xs) else (0,) * 4
    return float(drawn.mean()), box, (image.shape[1], image.shape[0])


def assert_whole_design_in_view(page, view, path) -> float:
    """The design covers a fair share of the canvas and touches none of its edges (all of
    it in view). Returns the share."""
    share, (x0, y0, x1, y1), (width, height) = coverage(page, view, path)
    assert MIN_COVER < share < MAX_COVER, (share, path)
    assert x0 > 2 and y0 > 2 and x1 < width - 3 and y1 < height - 3, ((x0, y0, x1, y1), path)
    return share


def camera_ok(view) -> None:
    """The tab's own camera (as the browser reports it) sees the design inside its planes."""
    camera = view.target.camera
    framing = view.framing
    distance = float(np.linalg.norm(np.asarray(camera.position) - framing.look_at))
    assert camera.far >= distance + framing.radius
    assert camera.near <= distance - framing.radius


@pytest.mark.parametrize("design", ["puma", "hand", "example1"])
def test_the_design_is_visible_on_first_paint(browser, servers, design, tmp_path):
    page, view = open_tab(browser, servers[design])
    try:
        time.sleep(2.0)  # the first frames
        page.screenshot(path=tmp_path / f"1_{design}_first_paint.png")
        share = assert_whole_design_in_view(page, view, tmp_path / f"1_{design}_canvas.png")
        wait_for(lambda: view.target.camera.far == pytest.approx(view.framing.far),
                 "the tab's camera reports the design's far plane")  # fmt: skip
        camera_ok(view)
        print(f"{design}: the design covers {share:.1%} of the canvas on first paint; "
              f"camera {view.framing.distance:.4g} {view.model.document.units} away, far "
              f"plane {view.target.camera.far:.4g}")  # fmt: skip
    finally:
        page.close()


def _zoom_out(page, box, clicks: int = 40) -> None:
    page.mouse.move(box["x"] + 0.5 * box["width"], box["y"] + 0.5 * box["height"])
    for _ in range(clicks):
        page.mouse.wheel(0, 400)
        time.sleep(0.02)


def test_frame_all_after_opening_a_much_smaller_design(browser, servers, tmp_path):
    """A PUMA tab (1.2 m, mm) opens Example 1 (12 cm, in cm: 1/100 of the PUMA's numbers):
    the grid, axes and camera follow; zoomed far out the design shrinks to a few pixels, and
    F (then the Frame all button) brings all of it back in view."""
    page, view = open_tab(browser, servers["puma"])
    try:
        time.sleep(2.0)
        puma_grid = view.grid.section
        choose(page, "Example", "example1")
        page.get_by_role("button", name="Open example").click()
        wait_for(lambda: view.model.document.units == "cm"
                 and view.grid.section * 50 < puma_grid, "Example 1 opened, its grid drawn")
        time.sleep(1.5)
        assert_whole_design_in_view(page, view, tmp_path / "2a_opened.png")
        box = page.locator("canvas").first.bounding_box()
        _zoom_out(page, box)
        share, _, _ = coverage(page, view, tmp_path / "2b_zoomed_out.png")
        assert share < MIN_COVER  # a speck
        page.keyboard.press("f")
        wait_for(lambda: view.message.startswith("framed all"), "F framed the design")
        time.sleep(1.0)
        assert_whole_design_in_view(page, view, tmp_path / "2c_f_key.png")
        camera_ok(view)
        _zoom_out(page, box)
        page.get_by_role("button", name="Frame all").click()
        time.sleep(1.5)
        assert_whole_design_in_view(page, view, tmp_path / "2d_frame_all.png")
    finally:
        page.close()


def test_the_hand_opened_after_the_puma_is_framed(browser, servers, tmp_path):
    page, view = open_tab(browser, servers["puma"])
    try:
        choose(page, "Example", "hand")
        page.get_by_role("button", name="Open example").click()
        wait_for(lambda: view.model.is_tree and view.grid.section < 10.0, "the hand opened")
        time.sleep(1.5)
        assert_whole_design_in_view(page, view, tmp_path / "3_hand_after_puma.png")
        camera_ok(view)
    finally:
        page.close()


def _type(page, view, label: str, field: str, text: str, expected) -> None:
    """Type ``text`` into the number field labelled ``label`` and wait for the server."""
    box = page.get_by_label(label, exact=True)
    box.fill(text)

    def arrived():
        value = view._joint_fields[field].value
        value = value[0] if isinstance(value, tuple) else value
        return math.isclose(float(value), expected, abs_tol=1e-9)

    wait_for(arrived, f"{label} = {text} on the server")


def test_typed_pose_parameters_and_state(browser, servers, tmp_path):
    page, view = open_tab(browser, servers["puma"])
    try:
        page.get_by_role("combobox", name="Joint", exact=True).click()
        page.get_by_role("option", name="2: RevoluteJoint", exact=True).click()
        wait_for(lambda: view.model.selected == 2, "joint 2 selected")
        page.get_by_text("state 0° in [-90°, 90°]").wait_for()
        page.get_by_label("Position (mm)", exact=True).wait_for()
        x = float(view._joint_fields["position"].value[0])
        _type(page, view, "Position (mm)", "position", f"{x + 50:.2f}", round(x + 50, 2))
        before = view.model.chain.Joints[2].pose_matrix.copy()
        page.get_by_role("button", name="Set pose").click()
        wait_for(lambda: view.model.undo_labels == ("set pose of joint 2",), "Set pose")
        moved = view.model.chain.Joints[2].pose_matrix[:3, 3] - before[:3, 3]
        assert moved == pytest.approx([round(x + 50, 2) - before[0, 3], 0.0, 0.0], abs=1e-9)
        page.screenshot(path=tmp_path / "4a_pose.png")

        document, bits = view.model.document, snapshot(view.model.document)
        _type(page, view, "numSinkLayers", "parameter numSinkLayers", "0", 0.0)
        page.get_by_role("button", name="Set parameters").click()
        page.get_by_text("numSinkLayers must be an integer in [1, 32], got 0").wait_for()
        assert view.model.document is document and snapshot(view.model.document) == bits
        page.screenshot(path=tmp_path / "4b_refused.png")

        _type(page, view, "totalBendingAngle (°)", "parameter totalBendingAngle", "150", 150.0)
        _type(page, view, "numSinkLayers", "parameter numSinkLayers", "2", 2.0)
        page.get_by_role("button", name="Set parameters").click()
        wait_for(lambda: len(view.model.undo_labels) == 2, "Set parameters")
        parameters = view.model.joint_table()[2].parameters
        assert parameters["totalBendingAngle"] == pytest.approx(math.radians(150.0))
        assert parameters["numSinkLayers"] == 2

        _type(page, view, "State (°)", "state", "-30", -30.0)
        page.get_by_role("button", name="Set state").click()
        wait_for(lambda: len(view.model.undo_labels) == 3, "Set state")
        assert view.model.chain.Joints[2].state == pytest.approx(math.radians(-30.0)), (
            view.model.undo_labels, view.message, view._shown_fields.get("state"))
        page.get_by_text("state -30° in [-75°, 75°]").wait_for()  # 150° bends +-75°
        page.screenshot(path=tmp_path / "4c_state.png")
    finally:
        page.close()


def test_shortcuts(browser, servers, tmp_path):
    """Ctrl+Z, Ctrl+Y, Ctrl+Shift+Z, Delete, Escape, Ctrl+S on the PUMA's tab (its file is a
    copy); nothing fires while the focus is in a number field."""
    page, view = open_tab(browser, servers["puma"])
    try:
        page.get_by_text("Shortcuts", exact=True).click()  # the help folder opens
        page.get_by_text("delete the selected joint").wait_for()
        wait_for(lambda: view.act(lambda: view.model.select(3)).ok, "joint 3 selected")
        assert view.act(lambda: view.model.slide(3, 40.0)).ok
        document = view.model.document
        page.keyboard.press("Control+z")
        wait_for(lambda: not view.model.can_undo, "Ctrl+Z undid the slide")
        page.keyboard.press("Control+y")
        wait_for(lambda: view.model.document is document, "Ctrl+Y redid it")
        page.keyboard.press("Control+z")
        wait_for(lambda: not view.model.can_undo, "Ctrl+Z again")
        page.keyboard.press("Control+Shift+z")
        wait_for(lambda: view.model.document is document, "Ctrl+Shift+Z redid it")

        # keys do nothing while typing in a field
        count = len(view.model.chain.Joints)
        field = page.get_by_label("Position (mm)", exact=True)
        field.click()
        page.keyboard.press("Delete")
        page.keyboard.press("f")
        time.sleep(1.0)
        assert len(view.model.chain.Joints) == count and view.model.selected == 3
        assert not view.message.startswith("framed all")
        page.keyboard.press("Escape")  # leaves the field only
        time.sleep(0.5)
        assert view.model.selected == 3

        page.keyboard.press("Delete")
        wait_for(lambda: len(view.model.chain.Joints) == count - 1, "Delete deleted joint 3")
        assert view.model.undo_labels[-1].startswith("delete")
        page.keyboard.press("Escape")
        wait_for(lambda: view.model.selected is None, "Escape deselected")

        path = view.model.path
        page.keyboard.press("Control+s")
        wait_for(lambda: not view.model.dirty, "Ctrl+S saved the design file")
        from kinegami.editor import Document

        assert len(Document.load(path).chain.Joints) == count - 1
        presses = page.evaluate("window.__kinegami.keyPresses")
        assert presses == ["undo", "redo", "undo", "redo", "delete", "escape", "save"]
        page.screenshot(path=tmp_path / "5_shortcuts.png")
    finally:
        page.close()


def test_escape_cancels_a_real_handle_drag(browser, servers, tmp_path):
    """A mouse drag of the axis handle of Example 1's revolute joint, Escape while the button
    is held: the design is as before the drag, and the release applies nothing."""
    from .test_browser import screen_point

    page, view = open_tab(browser, servers["example1"])
    try:
        view.click_joint(4)
        # the selection reaches the page (its modules highlighted on the sheet), then the
        # handle is drawn: as test_browser.py's drag waits
        page.locator("rect.kinegami-highlight").first.wait_for()
        time.sleep(1.5)
        document = view.model.document
        pose = view.model.chain.Joints[4].pose_matrix.copy()
        box = page.locator("canvas").first.bounding_box()
        length = 3.0 * view._r
        view.client = view.target
        start = screen_point(view, box, pose[:3, 3] + 0.6 * length * pose[:3, 2])
        end = screen_point(view, box, pose[:3, 3] + 1.1 * length * pose[:3, 2])
        page.mouse.move(*start)
        page.mouse.down()
        for t in np.linspace(0.0, 1.0, 12)[1:]:
            page.mouse.move(start[0] + t * (end[0] - start[0]), start[1] + t * (end[1] - start[1]))
            time.sleep(0.05)
        wait_for(lambda: view.model.previewing, "the drag previewed")
        page.keyboard.press("Escape")
        wait_for(lambda: not view.model.previewing, "Escape cancelled the drag")
        page.mouse.up()
        time.sleep(1.0)
        assert view.model.document is document and not view.model.can_undo
        assert view.model.selected == 4  # cancelling a drag keeps the selection
        page.screenshot(path=tmp_path / "6_drag_cancelled.png")
    finally:
        page.close()
