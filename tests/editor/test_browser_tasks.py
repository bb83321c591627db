"""A design's task in headless Chromium (as tests/editor/test_browser_jobs.py: Debian's chromium
through Playwright; marked ``browser``): the Task panel lists the targets of
tests/data/task_arm.json, two reached (green) and one not (red, with the reason); Design for
task shows its progress, Cancel leaves the design exactly as it was, and a second run replaces
the design (one undo step) by one that reaches every target (all green). Timeouts are generous
liveness limits, not timing asserts; the test takes about 25 s on an idle 2-core machine."""

from __future__ import annotations

import shutil

import pytest

from tests.editor.helpers import wait_for as helpers_wait_for

from .helpers import ROOT

pytestmark = pytest.mark.browser

TIMEOUT = 90.0  # seconds for the page or the server to react (software rendering, busy cores)
TASK_ARM = ROOT / "tests" / "data" / "task_arm.json"
#: The dot colours of the Task panel's rows, as the page computes them.
GREEN, RED = "rgb(40, 160, 80)", "rgb(220, 40, 40)"


def wait_for(condition, what: str, timeout: float = TIMEOUT):
    """tests/editor/helpers.wait_for with this file's timeout."""
    return helpers_wait_for(condition, what, timeout, step=0.05)


@pytest.fixture
def served(browser, tmp_path):
    """A server of a copy of tests/data/task_arm.json, a tab on it and the tab's view."""
    from kinegami.editor.server import EditorServer

    path = tmp_path / TASK_ARM.name
    shutil.copyfile(TASK_ARM, path)
    server = EditorServer(path, port=0)
    page = browser.new_page(viewport={"width": 1600, "height": 900})
    try:
        page.set_default_timeout(TIMEOUT * 1000)
        page.goto(server.url)
        view = wait_for(lambda: next(iter(server.views.values()), None), "the tab's editor view")
        page.wait_for_selector("canvas")
        page.get_by_text("Configuration", exact=True).wait_for()
        close = page.locator(".mantine-Notification-closeButton")  # "software WebGL" notice
        if close.count():
            close.first.click()
        yield page, view
    finally:
        page.close()
        server.stop()


def _dots(page) -> list[tuple[str, str]]:
    """(state, dot colour) of each row of the Task panel, in order."""
    rows = page.locator("li[data-target]").evaluate_all(
        "rows => rows.map(row => [row.dataset.state, "
        "getComputedStyle(row.querySelector('span')).color])"
    )
    return [tuple(row) for row in rows]


def test_the_task_panel_and_design_for_task_with_cancel(served, tmp_path):
    from kinegami.editor.view import MISSED_COLOR, REACHED_COLOR

    page, view = served
    before = view.model.document
    page.get_by_text("2 of 3 reached", exact=False).wait_for()
    assert _dots(page) == [("reached", GREEN), ("reached", GREEN), ("missed", RED)]
    row = page.locator('li[data-target="2"]')
    assert "target 2 'C': not reached: the nearest tip" in row.inner_text()
    assert view.task_checks[2].reason.split(";")[0] in row.inner_text()  # the solver's reason
    assert view.target_colours() == (REACHED_COLOR, REACHED_COLOR, MISSED_COLOR)
    page.screenshot(path=tmp_path / "1_task.png")

    design = page.get_by_role("button", name="Design for task", exact=True)
    design.click()
    job = wait_for(lambda: view.job, "the design job")
    page.get_by_text("Designing for the task").first.wait_for()  # its progress and Cancel
    page.get_by_role("button", name="Cancel", exact=True).click()
    wait_for(job.finished.is_set, "the cancelled job to end")
    assert job.outcome == "cancelled", view.message
    page.get_by_text("design for task cancelled: the design is unchanged").wait_for()
    assert view.model.document is before and not view.model.can_undo and not view.model.dirty
    assert _dots(page)[2] == ("missed", RED)

    design.click()
    job = wait_for(lambda: view.job, "the second design job")
    page.get_by_text("Designing for the task").first.wait_for()
    wait_for(lambda: job.total > 0, "the search's progress")
    wait_for(job.finished.is_set, "the design job to end")
    assert job.outcome == "done", view.message
    assert view.model.undo_labels == ("design for task",)
    assert view.model.document.task is before.task
    page.get_by_text("3 of 3 reached", exact=False).wait_for()
    assert _dots(page) == [("reached", GREEN)] * 3
    assert view.target_colours() == (REACHED_COLOR,) * 3
    page.screenshot(path=tmp_path / "2_designed.png")
