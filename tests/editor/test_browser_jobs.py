"""Long jobs and unsaved changes in headless Chromium (as tests/editor/test_browser.py: Debian's
chromium through Playwright; marked ``browser``): Compact runs in the background on the PUMA
while the page answers a joint picked in the Joint list, its result is one undo step; on the
paper's hand a slider moves the server's joint while Compact runs, and Cancel leaves the
design as it was; on Example 1 Open with unsaved changes asks (Cancel, Discard, Save each do
what they say) and closing the tab warns while the design is dirty. Timeouts are generous
liveness limits, not timing asserts (benchmarks/editor_jobs.py measures the latency)."""

from __future__ import annotations

import shutil

import pytest

from tests.editor.helpers import choose
from tests.editor.helpers import wait_for as helpers_wait_for

from .helpers import EXAMPLE1, HAND, ROOT

pytestmark = pytest.mark.browser

TIMEOUT = 90.0  # seconds for the page or the server to react (software rendering, busy cores)
PUMA = ROOT / "examples" / "designs" / "puma.json"


def wait_for(condition, what: str, timeout: float = TIMEOUT):
    """tests/editor/helpers.wait_for with this file's timeout."""
    return helpers_wait_for(condition, what, timeout, step=0.05)


def open_tab(browser, server):
    """A tab on ``server`` and the server's view of it."""
    before = set(server.views)
    page = browser.new_page(viewport={"width": 1600, "height": 900}, accept_downloads=True)
    page.set_default_timeout(TIMEOUT * 1000)
    page.goto(server.url)
    new = wait_for(lambda: set(server.views) - before, "the tab's editor view")
    view = server.views[new.pop()]
    page.wait_for_selector("canvas")
    page.get_by_text("Configuration", exact=True).wait_for()
    page.get_by_role("slider").first.wait_for()
    close = page.locator(".mantine-Notification-closeButton")  # "software WebGL" notice
    if close.count():
        close.first.click()
    return page, view


@pytest.fixture
def served(browser, tmp_path):
    """``serve(design)``: a server of a copy of ``design`` (in tmp_path) and a tab on it."""
    servers, pages = [], []

    def serve(design):
        from kinegami.editor.server import EditorServer

        path = tmp_path / design.name
        shutil.copyfile(design, path)
        server = EditorServer(path, port=0)
        servers.append(server)
        page, view = open_tab(browser, server)
        pages.append(page)
        return path, page, view

    yield serve
    for page in pages:
        page.close()
    for server in servers:
        server.stop()


def pick(page, view, joint: int) -> None:
    label = ("(none)",) + view._labels()
    choose(page, "Joint", label[joint + 1])


def test_the_puma_answers_while_compact_runs_and_the_result_is_one_undo_step(served, tmp_path):
    path, page, view = served(PUMA)
    before = view.model.document
    page.get_by_role("button", name="Compact", exact=True).click()
    job = wait_for(lambda: view.job, "the compact job")
    page.get_by_role("button", name="Cancel", exact=True).wait_for()  # progress and Cancel
    page.get_by_text("Compacting").first.wait_for()
    page.screenshot(path=tmp_path / "1_compacting.png")
    answered = []
    for joint in (2, 1):
        pick(page, view, joint)  # the page answers while the job process compacts
        wait_for(lambda joint=joint: view.model.selected == joint, f"joint {joint} selected")
        page.get_by_text(f"{joint}: RevoluteJoint", exact=False).first.wait_for()
        answered.append(not job.finished.is_set())
    assert answered[0], "compaction ended before the page was asked anything"
    wait_for(job.finished.is_set, "compaction to end", timeout=300.0)
    assert job.outcome == "done", view.message
    wait_for(lambda: view.model.undo_labels == ("compact",), "the compacted design")
    page.get_by_role("button", name="Cancel", exact=True).wait_for(state="hidden")
    page.screenshot(path=tmp_path / "2_compacted.png")
    page.get_by_role("button", name="Undo", exact=True).click()
    wait_for(lambda: view.model.document is before, "undo to give the design back")
    assert not view.model.dirty


def test_the_hand_moves_a_slider_while_compact_runs_and_cancel_keeps_it(served, tmp_path):
    path, page, view = served(HAND)
    page.get_by_role("button", name="Compact", exact=True).click()
    job = wait_for(lambda: view.job, "the compact job")
    wait_for(lambda: job.total > 0, "compaction's first progress report")
    page.get_by_text(" of 4 starts").first.wait_for()
    joint = next(row.index for row in view.model.joint_table() if row.movable)
    state = float(view.model.chain.Joints[joint].state)
    slider = page.get_by_role("slider").first
    slider.focus()
    slider.press("ArrowRight")
    wait_for(lambda: float(view.model.chain.Joints[joint].state) != state,
             "the slider's state on the server")  # fmt: skip
    assert not job.finished.is_set(), "compaction ended before the slider answered"
    edited = view.model.document
    page.screenshot(path=tmp_path / "3_hand_compacting.png")
    page.get_by_role("button", name="Cancel", exact=True).click()
    wait_for(job.finished.is_set, "the cancelled job to end")
    assert job.outcome == "cancelled"
    page.get_by_text("compact cancelled: the design is unchanged").wait_for()
    assert view.model.document is edited and len(view.model.undo_labels) == 1
    assert view.pending_result is None
    page.screenshot(path=tmp_path / "4_hand_cancelled.png")


def _edit(page, view) -> None:
    """Move a state slider by a key until the server's design is dirty (a slider of a design
    just opened may be drawn again meanwhile, and a step may be refused: try the next)."""
    for attempt in range(6):
        slider = page.get_by_role("slider").nth(attempt % 2)
        slider.focus()
        slider.press("ArrowRight" if attempt < 4 else "ArrowLeft")
        try:
            wait_for(lambda: view.model.dirty, "an unsaved edit on the server", timeout=15.0)
            return
        except AssertionError:
            continue
    raise AssertionError(f"no slider key made an edit ({view.message})")


def _open_puma(page) -> None:
    choose(page, "Example", "puma")
    page.get_by_role("button", name="Open example", exact=True).click()


def test_open_with_unsaved_changes_asks_and_each_answer_does_what_it_says(served, tmp_path):
    path, page, view = served(EXAMPLE1)
    original = path.read_text(encoding="utf-8")
    _edit(page, view)
    edited = view.model.document
    _open_puma(page)
    page.get_by_text("Unsaved changes").first.wait_for()
    page.screenshot(path=tmp_path / "5_unsaved.png")
    page.get_by_role("button", name="Cancel", exact=True).click()
    wait_for(lambda: view.pending_open is None, "the question answered")
    assert view.model.document is edited and view.model.dirty  # nothing opened, nothing lost
    assert path.read_text(encoding="utf-8") == original

    _open_puma(page)
    page.get_by_text("Unsaved changes").first.wait_for()
    page.get_by_role("button", name="Save", exact=True).click()
    wait_for(lambda: view.model.document.name != edited.name, "the example opened")
    assert path.read_text(encoding="utf-8") == edited.design_text  # saved first
    assert not view.model.dirty

    _edit(page, view)  # the PUMA, edited; then Discard
    _open_puma(page)
    page.get_by_role("button", name="Discard", exact=True).click()
    wait_for(lambda: not view.model.dirty, "the fresh PUMA")
    assert path.read_text(encoding="utf-8") == edited.design_text  # the file untouched


#: Dispatches a cancelable ``beforeunload`` to the page, as the browser does before it closes
#: or reloads a tab: True when a handler asked the browser to warn (prevented the default).
BEFORE_UNLOAD = """() => {
  const event = new Event("beforeunload", {cancelable: true});
  return !window.dispatchEvent(event) || event.defaultPrevented;
}"""


def test_closing_the_tab_with_unsaved_changes_warns(served):
    """The page's beforeunload handler asks the browser to warn exactly while the design has
    unsaved changes. (Headless Chromium closes a page through Playwright without showing its
    leave-page dialog, so the test dispatches the event the browser would.)"""
    path, page, view = served(EXAMPLE1)
    wait_for(lambda: page.evaluate("() => !!(window.__kinegami || {}).unloadGuard"),
             "the page's unload guard")  # fmt: skip
    assert page.evaluate(BEFORE_UNLOAD) is False  # nothing to lose: no warning
    _edit(page, view)
    wait_for(lambda: page.evaluate(BEFORE_UNLOAD), "the warning once the design is dirty")
    page.get_by_role("button", name="Undo", exact=True).click()  # back to the saved design
    wait_for(lambda: not view.model.dirty, "undo to the saved design")
    wait_for(lambda: page.evaluate(BEFORE_UNLOAD) is False, "no warning once clean again")


def test_the_puma_reaches_a_target_says_why_it_cannot_and_draws_its_workspace(served, tmp_path):
    """The Reach folder in Chromium: Reach target puts the PUMA's tip on a target (one undo
    step), a target out of reach is refused with its reason on the page, and Workspace draws
    the cloud from a background job (issue 31, docs/editor.md Reach)."""
    import numpy as np

    from kinegami.reach import kinematics

    path, page, view = served(PUMA)
    before = view.model.document
    compiled = kinematics(view.model.chain)
    rng = np.random.default_rng(3)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    while True:
        q = low + (high - low) * rng.random(low.size)
        if view.model.chain.clearance(q.tolist()).ok:
            break
    target = compiled.fkine(q)[:3, 3]
    view._reach_target.value = tuple(target.tolist())
    page.get_by_role("button", name="Reach target", exact=True).click()
    page.get_by_text("reached: tip", exact=False).first.wait_for()
    wait_for(lambda: view.model.dirty, "the states found to be set")
    tip = np.asarray(view.model.chain.Joints[-1].distal_dubins_frame())[:3, 3]
    assert np.abs(tip - target).max() <= 1e-9 * view.model.chain.r
    page.screenshot(path=tmp_path / "1_reached.png")
    page.get_by_role("button", name="Undo", exact=True).click()
    wait_for(lambda: view.model.document is before, "undo to give the states back")
    view._reach_target.value = (1e6, 0.0, 0.0)
    page.get_by_role("button", name="Reach target", exact=True).click()
    page.get_by_text("Cannot reach:", exact=False).first.wait_for()
    assert view.model.document is before
    page.get_by_role("button", name="Workspace", exact=True).click()
    page.get_by_role("button", name="Hide workspace", exact=True).wait_for(timeout=300_000)
    assert view.workspace_points is not None and view.workspace_points.shape[0] > 1_000
    page.screenshot(path=tmp_path / "2_workspace.png")
