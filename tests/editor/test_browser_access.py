"""``kinegami edit`` answers only its own page, in headless Chromium (docs/editor.md, Security):
the printed URL opens a working editor (its token becomes an HttpOnly, SameSite=Strict cookie and
leaves the address bar), and a page of another origin in the same browser, which holds that
cookie, cannot open the editor's websocket, fetch its page or frame it. Marked ``browser``;
skipped without playwright or chromium (failed under KINEGAMI_REQUIRE_BROWSER)."""

from __future__ import annotations

import shutil
import time

import headless_chromium
import pytest

from .helpers import EXAMPLE1
from .helpers import wait_for as helpers_wait_for

pytestmark = pytest.mark.browser

TIMEOUT = 60.0  # seconds (software rendering is slow)


@pytest.fixture(scope="module")
def browser():
    """Chromium without its Local Network Access checks: Chromium itself keeps public pages
    (and pages it cannot place, such as the routed ones here) from reaching 127.0.0.1; without
    those checks, as in browsers that have none, the other page's requests reach the editor
    and the editor's own check is what refuses them."""
    headless_chromium.require(headless_chromium.missing("viser"))
    from playwright.sync_api import sync_playwright

    with sync_playwright() as playwright:
        chromium = playwright.chromium.launch(
            executable_path=str(headless_chromium.chromium_path()),
            args=[*headless_chromium.CHROMIUM_ARGS, "--disable-features=LocalNetworkAccessChecks"],
        )
        try:
            yield chromium
        finally:
            chromium.close()


@pytest.fixture(scope="module")
def design(tmp_path_factory):
    path = tmp_path_factory.mktemp("browser_access") / "arm.json"
    shutil.copyfile(EXAMPLE1, path)
    return path


@pytest.fixture(scope="module")
def server(browser, design):
    from kinegami.editor.server import EditorServer

    server = EditorServer(design, port=0, autosave=False)
    yield server
    server.stop()


def wait_for(condition, what: str, timeout: float = TIMEOUT):
    """tests/editor/helpers.wait_for with this file's timeout."""
    return helpers_wait_for(condition, what, timeout)


@pytest.fixture
def context(browser):
    context = browser.new_context(viewport={"width": 1600, "height": 900})
    context.set_default_timeout(TIMEOUT * 1000)
    yield context
    context.close()


def open_editor(context, server):
    """A tab on the printed URL, once the server has made its editor view: (page, view)."""
    before = set(server.views)
    page = context.new_page()
    page.goto(server.url)
    client = wait_for(lambda: set(server.views) - before, "the tab's editor view").pop()
    page.get_by_text("4: revolute", exact=True).wait_for()
    return page, server.views[client]


def test_the_printed_url_opens_a_working_editor(context, server, design):
    page, view = open_editor(context, server)
    assert page.url == f"{server.address}/"  # the token left the address bar
    (cookie,) = context.cookies()
    assert (cookie["name"], cookie["value"]) == (f"kinegami-edit-{server.port}", server.gate.token)
    assert cookie["httpOnly"] and cookie["sameSite"] == "Strict"
    assert page.evaluate("document.cookie") == ""  # no script of the page reads it

    page.get_by_role("combobox", name="Joint", exact=True).click()
    page.get_by_role("option", name="4: RevoluteJoint 'revolute'").click()
    wait_for(lambda: view.model.selected == 4, "joint 4 selected on the server")
    before = design.read_text(encoding="utf-8")
    assert view.act(lambda: view.model.slide(4, 0.5)).ok
    page.get_by_role("button", name=f"Save to {design.name}").click()
    wait_for(lambda: design.read_text(encoding="utf-8") != before, "the design saved")
    assert design.read_text(encoding="utf-8") == view.model.document.design_text

    page.reload()  # the cookie alone opens the editor again
    page.get_by_text("4: revolute", exact=True).wait_for()


def test_the_page_without_the_token_is_refused(context, server):
    page = context.new_page()
    response = page.goto(server.address)
    assert response.status == 403
    assert "open the address that kinegami edit printed" in page.inner_text("body")
    response = page.goto(f"{server.address}/?token=not-the-token")
    assert response.status == 403 and context.cookies() == []


#: A page of another origin: it opens the editor's websocket, fetches its page, frames it and
#: loads it as a script, then reports what happened.
ATTACK = """<!doctype html><html><body><script>
window.report = {websocket: "pending", fetch: "pending", script: "pending"};
const ws = new WebSocket("ws://127.0.0.1:PORT/");
ws.onopen = () => { window.report.websocket = "open"; };
const wsRefused = () => {
  if (window.report.websocket === "pending") window.report.websocket = "refused";
};
ws.onerror = wsRefused;
ws.onclose = wsRefused;
fetch("http://127.0.0.1:PORT/", {credentials: "include"})
  .then((r) => { window.report.fetch = "status " + r.status; })
  .catch(() => { window.report.fetch = "refused"; });
const script = document.createElement("script");
script.src = "http://127.0.0.1:PORT/index.html";
script.onload = () => { window.report.script = "loaded"; };
script.onerror = () => { window.report.script = "refused"; };
document.body.appendChild(script);
const frame = document.createElement("iframe");
frame.src = "http://127.0.0.1:PORT/";
document.body.appendChild(frame);
</script></body></html>"""


@pytest.mark.parametrize("attacker", ["http://127.0.0.1:{other}", "http://evil.example"])
def test_another_origin_in_the_same_browser_gets_nothing(context, server, design, attacker):
    """After the user opened the editor (the cookie is in the browser), a page of another
    origin tries the editor: another port of 127.0.0.1 is the same *site*, so the browser
    sends the SameSite=Strict cookie and only the Origin and Sec-Fetch-Site checks stand
    between; evil.example is another site (no cookie, and it is refused the same way)."""
    views = set(server.views)
    open_editor(context, server)[0].close()
    wait_for(lambda: set(server.views) == views, "the editor's tab closed")
    origin = attacker.format(other=server.port + 1 if server.port < 65535 else server.port - 1)
    body = ATTACK.replace("PORT", str(server.port))
    context.route(f"{origin}/", lambda route: route.fulfill(body=body, content_type="text/html"))
    text = design.read_bytes()
    refused = dict(server.gate.refused)

    page = context.new_page()
    page.goto(f"{origin}/")
    report = wait_for(lambda: (lambda r: r if "pending" not in r.values() else None)(
        page.evaluate("window.report")), "the attack page's report")  # fmt: skip
    assert report == {"websocket": "refused", "fetch": "refused", "script": "refused"}
    time.sleep(1.0)
    assert set(server.views) == views  # no editor for the other page
    assert design.read_bytes() == text
    # every request reached the server and was refused there: the websocket and the fetch by
    # their Origin, the script and the frame (no Origin) by the browser's Sec-Fetch-Site
    gained = {key: server.gate.refused.get(key, 0) - refused.get(key, 0) for key in
              ("origin", "site", "token", "host")}  # fmt: skip
    assert gained == {"origin": 2, "site": 2, "token": 0, "host": 0}
