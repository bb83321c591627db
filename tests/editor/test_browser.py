"""``kinegami edit`` end to end: the viser editor in headless Chromium (Debian's chromium
through Playwright, software WebGL: tests/headless_chromium.py, shared with the Origami Simulator
tests). Marked ``browser``; they skip when playwright or chromium is missing, and fail then
instead when KINEGAMI_REQUIRE_BROWSER is set (CI). Each step saves a screenshot in the test's
tmp folder.
"""

from __future__ import annotations

import time
from pathlib import Path

import headless_chromium
import pytest

from .helpers import EXAMPLE1

pytestmark = pytest.mark.browser

TIMEOUT = 60.0  # seconds for the page or the server to react (software rendering is slow)


@pytest.fixture(scope="module")
def browser():
    headless_chromium.require(headless_chromium.missing("viser"))
    with headless_chromium.browser() as chromium:
        yield chromium


@pytest.fixture(scope="module")
def server(browser):
    from kinegami.editor.server import EditorServer

    server = EditorServer(EXAMPLE1, port=0, autosave=False)
    yield server
    server.stop()


def wait_for(condition, what: str, timeout: float = TIMEOUT):
    end = time.monotonic() + timeout
    while time.monotonic() < end:
        value = condition()
        if value:
            return value
        time.sleep(0.1)
    raise AssertionError(f"timed out after {timeout} s waiting for {what}")


@pytest.fixture
def tab(browser, server):
    """A new tab on the editor and the server's view of it (its own EditorModel)."""
    before = set(server.views)
    page = browser.new_page(viewport={"width": 1280, "height": 800}, accept_downloads=True)
    page.set_default_timeout(TIMEOUT * 1000)
    page.goto(server.url)
    new = wait_for(lambda: set(server.views) - before, "the tab's editor view")
    view = server.views[new.pop()]
    page.wait_for_selector("canvas")
    page.get_by_text("Configuration", exact=True).wait_for()
    page.get_by_text("4: revolute", exact=True).wait_for()
    close = page.locator(".mantine-Notification-closeButton")  # "software WebGL" notice
    if close.count():
        close.first.click()
    yield page, view
    page.close()


def drawn_pixels(path: Path) -> int:
    """Pixels of the 3D view (left of the side panel) that are not background."""
    import numpy as np
    from PIL import Image

    image = np.asarray(Image.open(path).convert("RGB"), dtype=int)[150:, 320:900]
    return int((np.abs(image - image[-1, 0]).sum(axis=2) > 60).sum())


def test_page_shows_the_chain(tab, tmp_path):
    page, view = tab
    assert view.meshes_sent > 0
    time.sleep(2.0)  # let the software renderer draw the meshes
    shot = tmp_path / "1_loaded.png"
    page.screenshot(path=shot)
    assert drawn_pixels(shot) > 5000


def test_selecting_a_joint_selects_it_on_the_server(tab, tmp_path):
    page, view = tab
    page.get_by_role("combobox", name="Joint", exact=True).click()
    page.get_by_role("option", name="4: RevoluteJoint 'revolute'").click()
    wait_for(lambda: view.model.selected == 4, "joint 4 selected on the server")
    page.get_by_text("state 0 in [-1.571, 1.571]").wait_for()
    time.sleep(1.0)
    page.screenshot(path=tmp_path / "2_selected.png")


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
    page.screenshot(path=tmp_path / "3_state.png")


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
    page.screenshot(path=tmp_path / "4_downloaded.png")
