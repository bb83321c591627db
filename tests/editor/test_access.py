"""Who may use the ``kinegami edit`` server (docs/editor.md, Security): real connections to a
running editor, raw HTTP (http.client) and websockets (the ``websockets`` client viser installs).
A foreign Origin, a missing or wrong token, another site's script or frame and a DNS-rebinding
Host get a 403 and reach nothing: no page, no editor view, the design file unchanged. These
tests open the same port viser answers on, so they fail if a viser or websockets upgrade
starts the server some other way and the check is bypassed."""

from __future__ import annotations

import contextlib
import http.client
import os
import shutil
import socket
import subprocess
import sys
import time
from pathlib import Path
from urllib.parse import parse_qs, urlsplit

import pytest

from kinegami.editor.access import Gate, is_loopback, same_origin

from .helpers import EXAMPLE1

ROOT = Path(__file__).resolve().parents[2]
TIMEOUT = 30.0


# --- the rules, without a server ------------------------------------------------------------
@pytest.mark.parametrize(
    ("origin", "host", "same"),
    [
        ("http://127.0.0.1:8080", "127.0.0.1:8080", True),
        ("http://LOCALHOST:8080", "localhost:8080", True),
        ("http://[::1]:8080", "[::1]:8080", True),
        ("http://example.org", "example.org:80", True),
        ("http://example.org:80", "example.org", True),
        ("http://evil.example", "127.0.0.1:8080", False),
        ("http://127.0.0.1:8081", "127.0.0.1:8080", False),  # another port: another origin
        ("https://127.0.0.1:8080", "127.0.0.1:8080", False),
        ("http://localhost:8080", "127.0.0.1:8080", False),
        ("null", "127.0.0.1:8080", False),
        ("http://127.0.0.1:8080/x", "127.0.0.1:8080", False),
        ("http://u@127.0.0.1:8080", "127.0.0.1:8080", False),
        ("http://127.0.0.1:99999", "127.0.0.1:99999", False),
        ("http://127.0.0.1:8080", None, False),
    ],
)
def test_same_origin_is_scheme_host_and_port_of_the_host_header(origin, host, same):
    assert same_origin(origin, host) is same


@pytest.mark.parametrize(
    ("host", "loopback"),
    [("127.0.0.1", True), ("127.3.2.1", True), ("::1", True), ("[::1]", True),
     ("localhost", True), ("LocalHost.", True), ("0.0.0.0", False), ("::", False),
     ("192.168.1.4", False), ("evil.example", False), ("localhost.evil.example", False)],
)  # fmt: skip
def test_loopback_hosts(host, loopback):
    assert is_loopback(host) is loopback


def test_tokens_are_random_and_compared_whole():
    gate = Gate()
    assert Gate().token != gate.token and len(gate.token) >= 43  # 32 random bytes
    assert gate.valid(gate.token)
    assert not gate.valid(gate.token[:-1]) and not gate.valid(gate.token + "x")
    assert not gate.valid("") and not gate.valid(None) and not gate.valid("é" * 43)
    with pytest.raises(ValueError, match="token must be at least 16 characters among letters, "
                                         "digits, '-' and '_', got 3 characters$"):  # fmt: skip
        Gate("abc")
    with pytest.raises(ValueError, match="got 20 characters, some of them others"):
        Gate("a" * 16 + "; x=")  # it goes into a Set-Cookie header


# --- a running editor -----------------------------------------------------------------------
pytest.importorskip("viser")
msgspec = pytest.importorskip("msgspec")


@pytest.fixture(scope="module")
def design(tmp_path_factory):
    path = tmp_path_factory.mktemp("access") / "arm.json"
    shutil.copyfile(EXAMPLE1, path)
    return path


@pytest.fixture(scope="module")
def server(design):
    from kinegami.editor.server import EditorServer

    server = EditorServer(design, port=0, autosave=False)
    yield server
    server.stop()


@pytest.fixture
def unchanged(server, design):
    """Asserts, after the test, that no editor view was made and the design file is as it was."""
    views, text = set(server.views), design.read_bytes()
    yield
    time.sleep(0.2)  # a connection the server let through would have its view by now
    assert set(server.views) == views
    assert design.read_bytes() == text


def get(server, path: str, headers: dict[str, str] | None = None):
    """(status, headers, body) of a GET of ``path`` on the editor's port."""
    connection = http.client.HTTPConnection("127.0.0.1", server.port, timeout=TIMEOUT)
    try:
        connection.request("GET", path, headers=headers or {})
        response = connection.getresponse()
        return response.status, response.headers, response.read()
    finally:
        connection.close()


def token_query(server) -> str:
    return f"/?{urlsplit(server.url).query}"


def cookie(server) -> dict[str, str]:
    return {"Cookie": f"kinegami-edit-{server.port}={server.gate.token}"}


def own_origin(server) -> str:
    return f"http://127.0.0.1:{server.port}"


def test_the_url_carries_the_token(server):
    parts = urlsplit(server.url)
    assert (parts.scheme, parts.hostname, parts.port, parts.path) == ("http", "127.0.0.1",
                                                                      server.port, "/")  # fmt: skip
    assert parse_qs(parts.query) == {"token": [server.gate.token]}
    assert server.address == f"http://127.0.0.1:{server.port}"


def test_the_printed_url_sets_a_strict_httponly_cookie_and_drops_the_token(server):
    status, headers, body = get(server, token_query(server) + "&darkMode")
    assert status == 302 and body == b""
    assert headers["Location"] == "/?darkMode="  # viser's own parameters are kept
    assert headers["Set-Cookie"] == (f"kinegami-edit-{server.port}={server.gate.token}; Path=/; "
                                     "HttpOnly; SameSite=Strict")  # fmt: skip
    assert headers["Cache-Control"] == "no-store"
    status, headers, _ = get(server, "//evil.example/" + token_query(server)[1:])
    assert status == 302 and headers["Location"] == "/"  # never to another site
    status, headers, body = get(server, "/", cookie(server))
    assert status == 200 and body.startswith(b"<!doctype html>")
    assert headers["X-Frame-Options"] == "DENY"
    assert headers["Content-Security-Policy"] == "frame-ancestors 'none'"


def test_the_own_page_with_its_origin_is_served(server):
    headers = {**cookie(server), "Origin": own_origin(server), "Sec-Fetch-Site": "same-origin",
               "Sec-Fetch-Mode": "cors", "Sec-Fetch-Dest": "script"}  # fmt: skip
    status, _, body = get(server, "/index.html", headers)
    assert status == 200 and body.startswith(b"<!doctype html>")


@pytest.mark.parametrize("path", ["/", "/index.html", "/assets/index.js", "/../server.py"])
@pytest.mark.parametrize(
    ("headers", "reason"),
    [
        ({}, "open the address that kinegami edit printed"),
        ({"Cookie": "kinegami-edit-{port}=wrong-token-of-43-characters-aaaaaaaaaaaaa"},
         "open the address that kinegami edit printed"),
        ({"Cookie": "kinegami-edit-1={token}"}, "open the address"),  # another editor's cookie
        ({"Cookie": "kinegami-edit-{port}={token}", "Origin": "http://evil.example"},
         "Origin is not the editor's own address"),
        ({"Cookie": "kinegami-edit-{port}={token}", "Origin": "http://127.0.0.1:1"},
         "Origin is not the editor's own address"),
        ({"Cookie": "kinegami-edit-{port}={token}", "Origin": "null"}, "Origin is not"),
        ({"Cookie": "kinegami-edit-{port}={token}", "Host": "evil.example:{port}",
          "Origin": "http://evil.example:{port}"}, "its own address on this machine"),
        ({"Cookie": "kinegami-edit-{port}={token}", "Sec-Fetch-Site": "same-site",
          "Sec-Fetch-Mode": "no-cors", "Sec-Fetch-Dest": "script"}, "cannot load or frame"),
        ({"Cookie": "kinegami-edit-{port}={token}", "Sec-Fetch-Site": "cross-site",
          "Sec-Fetch-Mode": "navigate", "Sec-Fetch-Dest": "iframe"}, "cannot load or frame"),
    ],
)  # fmt: skip
def test_refused_pages_get_403_and_nothing(server, unchanged, path, headers, reason):
    headers = {key: value.format(port=server.port, token=server.gate.token)
               for key, value in headers.items()}  # fmt: skip
    status, answer, body = get(server, path, headers)
    assert status == 403
    assert body.startswith(b"403 Forbidden: ") and reason.encode() in body
    assert b"<html" not in body and answer["Content-Type"] == "text/plain; charset=utf-8"


@pytest.mark.parametrize(
    "query", ["?token=", "?token=wrong", "?token={token}x", "?token={token}&token={token}"]
)
def test_a_wrong_token_in_the_address_is_refused(server, unchanged, query):
    status, headers, body = get(server, "/" + query.format(token=server.gate.token))
    assert status == 403 and b"wrong token" in body and "Set-Cookie" not in headers


def test_a_foreign_page_cannot_use_the_printed_url(server, unchanged):
    status, headers, _ = get(server, token_query(server), {"Origin": "http://evil.example"})
    assert status == 403 and "Set-Cookie" not in headers


def test_a_top_level_navigation_from_another_site_is_allowed_with_the_token(server):
    headers = {"Sec-Fetch-Site": "cross-site", "Sec-Fetch-Mode": "navigate",
               "Sec-Fetch-Dest": "document"}  # fmt: skip
    status, answer, _ = get(server, token_query(server), headers)
    assert status == 302 and "Set-Cookie" in answer
    assert get(server, "/", headers)[0] == 403  # without the token or its cookie: refused


# --- the websocket --------------------------------------------------------------------------
def connect(server, query: str = "", host: str = "127.0.0.1", **kwargs):
    """A websocket to the editor (``host``: the name in the address and the Host header; the
    connection goes to 127.0.0.1 in any case)."""
    import viser
    from websockets.sync.client import connect

    sock = socket.create_connection(("127.0.0.1", server.port), timeout=TIMEOUT)
    try:
        return connect(f"ws://{host}:{server.port}/{query}", sock=sock, open_timeout=TIMEOUT,
                       subprotocols=[f"viser-v{viser.__version__}"], **kwargs)  # fmt: skip
    except BaseException:
        sock.close()
        raise


#: What viser's page sends first (a ViewerCameraMessage in viser's msgpack wire format).
CAMERA = msgspec.msgpack.encode({
    "type": "ViewerCameraMessage", "wxyz": [1.0, 0.0, 0.0, 0.0], "position": [0.0, 0.0, 1.0],
    "fov": 1.0, "near": 0.01, "far": 100.0, "image_height": 600, "image_width": 800,
    "look_at": [0.0, 0.0, 0.0], "up_direction": [0.0, 0.0, 1.0],
})  # fmt: skip


def connected_view(server, before: set[int]) -> int:
    end = time.monotonic() + TIMEOUT
    while time.monotonic() < end:
        new = set(server.views) - before
        if new:
            return new.pop()
        time.sleep(0.05)
    raise AssertionError("the websocket connected but the server made no editor view")


@pytest.mark.parametrize("how", ["cookie", "query", "cookie without origin"])
def test_the_websocket_with_the_token_gets_an_editor(server, how):
    before = set(server.views)
    if how == "query":
        kwargs = {"origin": own_origin(server)}
        query = f"?token={server.gate.token}"
    else:
        kwargs = {"additional_headers": cookie(server)}
        query = ""
        if how == "cookie":
            kwargs["origin"] = own_origin(server)
    with connect(server, query, **kwargs) as websocket:
        assert isinstance(websocket.recv(timeout=TIMEOUT), bytes)  # the server talks to it
        websocket.send(CAMERA)  # viser's clients count from their first camera message
        client = connected_view(server, before)
        assert server.views[client].model.path is not None
    end = time.monotonic() + TIMEOUT
    while client in server.views and time.monotonic() < end:
        time.sleep(0.05)
    assert client not in server.views  # closed: its view is gone


@pytest.mark.parametrize(
    ("query", "headers", "origin", "host"),
    [
        ("", {}, "{own}", "127.0.0.1"),  # no token
        ("?token=wrong", {}, "{own}", "127.0.0.1"),
        ("?token={token}0", {}, None, "127.0.0.1"),
        ("", {"Cookie": "kinegami-edit-{port}=x{token}"}, "{own}", "127.0.0.1"),
        ("", {"Cookie": "kinegami-edit-{port}={token}"}, "http://evil.example", "127.0.0.1"),
        ("?token={token}", {}, "http://evil.example", "127.0.0.1"),
        ("?token={token}", {}, "http://127.0.0.1:1", "127.0.0.1"),
        ("", {"Cookie": "kinegami-edit-{port}={token}"}, "null", "127.0.0.1"),
        # a DNS rebinding: another name for this machine, its page's own origin, the token
        ("?token={token}", {}, "http://rebound.example:{port}", "rebound.example"),
    ],
)  # fmt: skip
def test_the_websocket_without_the_token_or_from_another_origin_is_refused(
    server, unchanged, query, headers, origin, host
):
    from websockets.exceptions import InvalidStatus

    def fill(text: str) -> str:
        return text.format(port=server.port, token=server.gate.token, own=own_origin(server))

    kwargs = {"additional_headers": {key: fill(value) for key, value in headers.items()}}
    if origin is not None:
        kwargs["origin"] = fill(origin)
    with pytest.raises(InvalidStatus) as refused:
        connect(server, fill(query), host, **kwargs).close()
    assert refused.value.response.status_code == 403


def test_refusals_are_counted_by_reason(server):
    before = dict(server.gate.refused)
    get(server, "/")
    get(server, "/", {**cookie(server), "Origin": "http://evil.example"})
    after = server.gate.refused
    assert after.get("token", 0) == before.get("token", 0) + 1
    assert after.get("origin", 0) == before.get("origin", 0) + 1


# --- how the check is attached to viser -----------------------------------------------------
def test_the_substitute_serve_is_removed_after_the_start():
    import websockets.asyncio.server as ws_server

    from kinegami.editor.access import guard_viser

    original = ws_server.serve
    with guard_viser(Gate()) as guarded:
        assert ws_server.serve is not original and guarded() == 0
    assert ws_server.serve is original


def test_without_the_check_the_editor_does_not_serve(monkeypatch, design):
    """A viser that starts its server some other way (here: the substitute is never called)
    makes EditorServer stop the server and raise: the port is not left listening."""
    from kinegami.editor import server as server_module
    from kinegami.editor.access import GuardError

    @contextlib.contextmanager
    def bypassed(gate):
        yield lambda: 0

    monkeypatch.setattr(server_module, "guard_viser", bypassed)
    with socket.socket() as free:
        free.bind(("127.0.0.1", 0))
        port = free.getsockname()[1]
    with pytest.raises(GuardError, match="cannot check its requests and does not serve"):
        server_module.EditorServer(design, port=port, autosave=False)
    with socket.socket() as probe:
        assert probe.connect_ex(("127.0.0.1", port)) != 0


# --- the command ----------------------------------------------------------------------------
@contextlib.contextmanager
def kinegami_edit(*args: str):
    """``kinegami edit ARGS`` in a subprocess (stopped by SIGTERM after the block): yields a
    dict with its first stdout line (``line``); ``stderr`` is added after the block."""
    env = {**os.environ, "PYTHONUNBUFFERED": "1"}
    process = subprocess.Popen([sys.executable, "-m", "kinegami", "edit", *args], cwd=ROOT,
                               env=env, stdout=subprocess.PIPE, stderr=subprocess.PIPE,
                               text=True)  # fmt: skip
    run = {"line": process.stdout.readline()}
    try:
        yield run
    finally:
        process.terminate()
        run["stderr"] = process.communicate(timeout=TIMEOUT)[1]


def printed_url(line: str) -> str:
    return next(word for word in line.split() if word.startswith("http://"))


def status(url, path: str, headers: dict[str, str] | None = None):
    connection = http.client.HTTPConnection(url.hostname, url.port, timeout=TIMEOUT)
    try:
        connection.request("GET", path, headers=headers or {})
        response = connection.getresponse()
        return response.status, response.headers
    finally:
        connection.close()


def test_kinegami_edit_prints_a_url_with_a_token_that_opens_the_page(design, data_home):
    with kinegami_edit(str(design), "--port", "0") as run:
        assert run["line"].startswith(f"kinegami edit: editing {design} at http://127.0.0.1:")
        url = urlsplit(printed_url(run["line"]))
        assert len(parse_qs(url.query)["token"][0]) >= 43
        code, headers = status(url, f"{url.path}?{url.query}")
        assert code == 302
        assert status(url, "/", {"Cookie": headers["Set-Cookie"].split(";")[0]})[0] == 200
        assert status(url, "/")[0] == 403
    assert "warning" not in run["stderr"]


def test_kinegami_edit_on_every_address_warns(design, data_home):
    with kinegami_edit(str(design), "--port", "0", "--host", "0.0.0.0") as run:
        url = urlsplit(printed_url(run["line"]))
        assert url.hostname == "127.0.0.1" and "token" in parse_qs(url.query)
        assert status(url, "/")[0] == 403
        # reached under the machine's network name: that Host is fine, a foreign Origin is not
        named = {"Host": f"mybox.example:{url.port}"}
        assert status(url, f"/?{url.query}", named)[0] == 302
        own = {**named, "Origin": f"http://mybox.example:{url.port}"}
        assert status(url, f"/?{url.query}", own)[0] == 302
        foreign = {**named, "Origin": f"http://127.0.0.1:{url.port}"}
        assert status(url, f"/?{url.query}", foreign)[0] == 403
    assert "kinegami edit: warning: listening on 0.0.0.0: anyone who can reach port " in run[
        "stderr"]
    assert f"and has the token can open the editor, edit and save {design}" in run["stderr"]
