"""A tree task in headless Chromium (as tests/editor/test_browser_tasks.py; marked
``browser``): the Task panel of tests/data/task_fingers.json, its right finger's second point
moved out of reach, lists the targets leaf by leaf, each row with its leaf and grasp; grasp 0
green for both leaves, grasp 1 red for both, the unreachable point with the solver's reason
and the other leaf's point naming it; Design for task is offered. Timeouts are generous
liveness limits, not timing asserts."""

from __future__ import annotations

import json

import pytest

from tests.editor.helpers import wait_for as helpers_wait_for

from .helpers import ROOT

pytestmark = pytest.mark.browser

TIMEOUT = 90.0  # seconds for the page or the server to react (software rendering, busy cores)
FINGERS = ROOT / "tests" / "data" / "task_fingers.json"
#: The dot colours of the Task panel's rows, as the page computes them.
GREEN, RED = "rgb(40, 160, 80)", "rgb(220, 40, 40)"


def wait_for(condition, what: str, timeout: float = TIMEOUT):
    """tests/editor/helpers.wait_for with this file's timeout."""
    return helpers_wait_for(condition, what, timeout, step=0.05)


@pytest.fixture
def served(browser, tmp_path):
    """A server of task_fingers.json with its right finger's second point out of reach, a tab
    on it and the tab's view."""
    from kinegami.editor.server import EditorServer

    document = json.loads(FINGERS.read_text(encoding="utf-8"))
    document["task"]["targets"][1][1]["position"] = [1000.0, 0.0, 130.0]
    path = tmp_path / FINGERS.name
    path.write_text(json.dumps(document), encoding="utf-8")
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


def _rows(page) -> list[tuple[str, str, str, str]]:
    """(leaf, grasp, state, dot colour) of each row of the Task panel, in order."""
    rows = page.locator("li[data-target]").evaluate_all(
        "rows => rows.map(row => [row.dataset.leaf, row.dataset.grasp, row.dataset.state, "
        "getComputedStyle(row.querySelector('span')).color])"
    )
    return [tuple(row) for row in rows]


def test_the_task_panel_lists_a_tree_tasks_targets_per_leaf(served, tmp_path):
    from kinegami.editor.view import MISSED_COLOR, REACHED_COLOR

    page, view = served
    page.get_by_text("2 of 4 reached (1 of 2 grasps)", exact=False).wait_for()
    assert _rows(page) == [("0", "0", "reached", GREEN), ("0", "1", "missed", RED),
                           ("1", "0", "reached", GREEN), ("1", "1", "missed", RED)]  # fmt: skip
    page.get_by_text("leaf tips: joints 4, 8", exact=False).wait_for()
    far = page.locator('li[data-target="3"]').inner_text()
    assert far.startswith("● leaf 1, target 1 'right 1': not reached: beyond reach: the target")
    assert view.task_checks[3].reason in far  # the solver's reason, whole
    partner = page.locator('li[data-target="1"]').inner_text()
    assert partner.endswith(
        "leaf 0, target 1 'left 1': not reached: its tip reaches it, but not at once with "
        "leaf 1, target 1 'right 1', which is not reached")  # fmt: skip
    assert "reached, exactly and clear" in page.locator('li[data-target="0"]').inner_text()
    assert view.target_colours() == (REACHED_COLOR, MISSED_COLOR, REACHED_COLOR,
                                     MISSED_COLOR)  # fmt: skip
    page.get_by_role("button", name="Design for task", exact=True).wait_for()
    page.screenshot(path=tmp_path / "tree_task.png")
