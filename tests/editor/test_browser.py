"""``kinegami edit`` end to end: the viser editor in headless Chromium (Debian's chromium
through Playwright, software WebGL: tests/headless_chromium.py, shared with the Origami Simulator
tests). Marked ``browser``; they skip when playwright or chromium is missing, and fail then
instead when KINEGAMI_REQUIRE_BROWSER is set (CI). Each step saves a screenshot in the test's
tmp folder.
"""

from __future__ import annotations

import math
import time
from pathlib import Path

import pytest

from tests.editor.helpers import wait_for as helpers_wait_for

from .helpers import EXAMPLE1, HAND

pytestmark = pytest.mark.browser

TIMEOUT = 60.0  # seconds for the page or the server to react (software rendering is slow)


@pytest.fixture(scope="module")
def server(browser):
    from kinegami.editor.server import EditorServer

    server = EditorServer(EXAMPLE1, port=0, autosave=False)
    yield server
    server.stop()


def wait_for(condition, what: str, timeout: float = TIMEOUT):
    """tests/editor/helpers.wait_for with this file's timeout."""
    return helpers_wait_for(condition, what, timeout)


@pytest.fixture
def tab(browser, server):
    """A new tab on the editor and the server's view of it (its own EditorModel)."""
    before = set(server.views)
    page = browser.new_page(viewport={"width": 1600, "height": 900}, accept_downloads=True)
    page.set_default_timeout(TIMEOUT * 1000)
    page.goto(server.url)
    new = wait_for(lambda: set(server.views) - before, "the tab's editor view")
    client_id = new.pop()
    view = server.views[client_id]
    page.wait_for_selector("canvas")
    page.get_by_text("Configuration", exact=True).wait_for()
    page.get_by_text("4: revolute", exact=True).wait_for()
    close = page.locator(".mantine-Notification-closeButton")  # "software WebGL" notice
    if close.count():
        close.first.click()
    view.client = server.server.get_clients()[client_id]
    yield page, view
    page.close()


def drawn_pixels(path: Path, box: dict) -> int:
    """Pixels of the 3D view (the canvas between the two panels) that are not background."""
    import numpy as np
    from PIL import Image

    image = np.asarray(Image.open(path).convert("RGB"), dtype=int)
    x0, x1 = int(box["x"]) + 20, int(box["x"] + box["width"]) - 20
    image = image[100:-100, x0:x1]
    return int((np.abs(image - image[-1, 0]).sum(axis=2) > 60).sum())


def screen_point(view, box: dict, point) -> tuple[float, float]:
    """Where the tab's camera shows the world point ``point`` on the page (pixels): viser's
    camera pose (OpenCV axes: x right, y down, z forward) and vertical field of view."""
    import numpy as np
    from scipy.spatial.transform import Rotation

    camera = view.client.camera
    w, x, y, z = camera.wxyz
    R = Rotation.from_quat([x, y, z, w]).as_matrix()
    p = R.T @ (np.asarray(point, dtype=float) - np.asarray(camera.position, dtype=float))
    focal = 0.5 * box["height"] / math.tan(0.5 * camera.fov)
    return (box["x"] + 0.5 * box["width"] + focal * p[0] / p[2],
            box["y"] + 0.5 * box["height"] + focal * p[1] / p[2])  # fmt: skip


def sheet_svg(page):
    return page.locator("svg[aria-label='crease pattern, whole sheet']")


def test_page_shows_the_chain_and_its_crease_pattern(tab, tmp_path):
    page, view = tab
    assert view.meshes_sent > 0
    sheet_svg(page).wait_for()
    size = page.locator(".kinegami-sheet-size").inner_text()
    assert size.startswith("Sheet ") and " mm" in size
    assert page.locator("svg path.kinegami-M").count() >= 1
    assert page.locator("svg path.kinegami-V").count() >= 1
    time.sleep(2.0)  # let the software renderer draw the meshes
    shot = tmp_path / "1_loaded.png"
    page.screenshot(path=shot)
    assert drawn_pixels(shot, page.locator("canvas").first.bounding_box()) > 5000


def test_selecting_a_joint_selects_it_and_highlights_its_modules(tab, tmp_path):
    page, view = tab
    page.get_by_role("combobox", name="Joint", exact=True).click()
    page.get_by_role("option", name="4: RevoluteJoint 'revolute'").click()
    wait_for(lambda: view.model.selected == 4, "joint 4 selected on the server")
    page.get_by_text("state 0° in [-90°, 90°]").wait_for()
    page.locator("rect.kinegami-highlight").first.wait_for()
    page.locator("svg[aria-label='crease pattern, selected joint']").wait_for()
    page.get_by_text("close-up: joint 4 (RevoluteJoint 'revolute')").wait_for()
    time.sleep(1.0)
    page.screenshot(path=tmp_path / "2_selected.png")


def test_dragging_the_axis_handle_slides_the_joint(tab, tmp_path):
    """A real mouse drag on the handle's arrow: the page's pointer events go to viser's
    transform controls, whose updates reach the server as a live drag (previews) and whose
    release is one slide command. The arrow is found by projecting the joint's axis with the
    tab's own camera (viser reports its pose, field of view and the canvas size)."""
    import numpy as np

    page, view = tab
    view.click_joint(4)  # what a click on its mesh does (test_view.py clicks it)
    page.locator("rect.kinegami-highlight").first.wait_for()
    time.sleep(1.5)  # the handle is drawn
    pose = view.model.chain.Joints[4].pose_matrix.copy()
    pattern_before = sheet_svg(page).inner_html()
    box = page.locator("canvas").first.bounding_box()
    length = 3.0 * view._r  # the handle's scale
    start = screen_point(view, box, pose[:3, 3] + 0.6 * length * pose[:3, 2])
    end = screen_point(view, box, pose[:3, 3] + 1.1 * length * pose[:3, 2])
    page.mouse.move(*start)
    page.mouse.down()
    for t in np.linspace(0.0, 1.0, 12)[1:]:
        page.mouse.move(start[0] + t * (end[0] - start[0]), start[1] + t * (end[1] - start[1]))
        time.sleep(0.05)
    page.screenshot(path=tmp_path / "3a_dragging.png")
    page.mouse.up()
    wait_for(lambda: view.model.undo_labels, "the slide command at the end of the drag")
    assert len(view.model.undo_labels) == 1
    assert view.model.undo_labels[0].startswith("slide joint 4 by ")
    moved = view.model.chain.Joints[4].pose_matrix[:3, 3] - pose[:3, 3]
    along = float(np.dot(moved, pose[:3, 2]))
    assert 0.5 * length * 0.5 < along < 0.5 * length * 2.0  # about the half scale dragged
    np.testing.assert_allclose(moved, along * pose[:3, 2], atol=1e-9)  # only along the axis
    np.testing.assert_allclose(view.model.chain.Joints[4].pose_matrix[:3, :3], pose[:3, :3],
                               atol=1e-12)  # fmt: skip
    wait_for(lambda: sheet_svg(page).inner_html() != pattern_before,
             "the crease-pattern panel drawn again")  # fmt: skip
    time.sleep(1.0)
    page.screenshot(path=tmp_path / "3b_dragged.png")


def test_state_slider_moves_the_servers_chain(tab, tmp_path):
    page, view = tab
    before = view.model.chain.Joints[-1].pose_matrix.copy()
    slider = page.get_by_role("slider").nth(1)  # 4: revolute
    slider.focus()
    for _ in range(20):
        slider.press("ArrowRight")
    state = wait_for(lambda: view.model.chain.Joints[4].state, "a new state of joint 4")
    assert 0.0 < state <= 1.5708
    assert abs(view.model.chain.Joints[-1].pose_matrix - before).max() > 1e-3
    time.sleep(1.0)
    page.screenshot(path=tmp_path / "4_state.png")


def test_animate_sweeps_the_joints_and_stop_gives_the_states_back(tab, tmp_path):
    page, view = tab
    base = view.model.document
    slider = page.get_by_role("slider").nth(1)
    page.get_by_role("button", name="Animate").click()
    wait_for(lambda: view.animating and view.animation_frames >= 10, "animation frames")
    values = set()
    deadline = time.monotonic() + TIMEOUT  # a loaded machine draws few frames a second
    while len(values) < 3 and time.monotonic() < deadline:
        values.add(slider.get_attribute("aria-valuenow"))
        time.sleep(0.1)
    assert len(values) >= 3  # the page's slider follows the sweep
    page.screenshot(path=tmp_path / "5_animating.png")
    page.get_by_role("button", name="Stop animation").click()
    wait_for(lambda: not view.animating, "the animation stopped")
    assert view.model.document is base and not view.model.can_undo
    page.get_by_role("button", name="Animate").wait_for()


def test_dxf_download_reads_back_with_ezdxf(tab, tmp_path):
    import ezdxf

    page, view = tab
    with page.expect_download() as info:
        page.get_by_role("button", name="Download DXF").click()
    target = tmp_path / info.value.suggested_filename
    info.value.save_as(target)
    assert target.suffix == ".dxf"
    doc = ezdxf.readfile(target)
    assert len(doc.modelspace()) > 0
    page.screenshot(path=tmp_path / "6_downloaded.png")


# --- a tree: the paper's hand --------------------------------------------------------------------
@pytest.fixture(scope="module")
def hand_server(browser):
    from kinegami.editor.server import EditorServer

    server = EditorServer(HAND, port=0, autosave=False)
    yield server
    server.stop()


def test_the_hand_gets_a_branch_and_a_sheet_downloads(browser, hand_server, tmp_path):
    """The paper's hand in a tab: drawn in 3D with its three sheets in the pattern panel; a
    joint picked in the Joint list gets a branch (Add branch at selected), the panel shows a
    fourth sheet, and Download DXF of that sheet gives a labelled file ezdxf reads."""
    import ezdxf

    before = set(hand_server.views)
    page = browser.new_page(viewport={"width": 1600, "height": 900}, accept_downloads=True)
    page.set_default_timeout(TIMEOUT * 1000)
    try:
        page.goto(hand_server.url)
        new = wait_for(lambda: set(hand_server.views) - before, "the tab's editor view")
        view = hand_server.views[new.pop()]
        page.wait_for_selector("canvas")
        page.locator("svg[aria-label='crease pattern, sheet 2']").wait_for()
        assert page.locator("svg[aria-label='crease pattern, sheet 3']").count() == 0
        close = page.locator(".mantine-Notification-closeButton")
        if close.count():
            close.first.click()
        time.sleep(2.0)  # let the software renderer draw the meshes
        shot = tmp_path / "7_hand.png"
        page.screenshot(path=shot)
        assert drawn_pixels(shot, page.locator("canvas").first.bounding_box()) > 5000

        page.get_by_role("combobox", name="Joint", exact=True).click()
        page.get_by_role("option", name="6: RevoluteJoint 'pointer2' (on 5)").click()
        wait_for(lambda: view.model.selected == 6, "joint 6 selected on the server")
        page.get_by_role("button", name="Add branch at selected").click()
        wait_for(lambda: len(view.model.chain.Children[6]) == 2, "the branch on the server")
        assert view.model.undo_labels == ("add RevoluteJoint as a branch of joint 6",)
        page.locator("svg[aria-label='crease pattern, sheet 3']").wait_for()
        time.sleep(1.0)
        page.screenshot(path=tmp_path / "8_branch.png")

        page.get_by_role("combobox", name="Sheet", exact=True).click()
        page.get_by_role("option", name="sheet 3", exact=True).click()
        with page.expect_download() as info:
            page.get_by_role("button", name="Download DXF").click()
        target = tmp_path / info.value.suggested_filename
        info.value.save_as(target)
        assert target.name == "Three-finger_hand_sheet_3.dxf"
        texts = [e.dxf.text for e in ezdxf.readfile(target).modelspace() if e.dxftype() == "TEXT"]
        assert any(t.startswith("sheet 3:") for t in texts), texts
        page.screenshot(path=tmp_path / "9_downloaded.png")
    finally:
        page.close()
