"""Who may use the ``kinegami edit`` server: the holder of the secret token in the address it
prints, from the editor's own page (docs/editor.md, Security).

viser serves its page and its websocket on one port through
``websockets.asyncio.server.serve(..., process_request=...)`` and has no hook for a check.
:func:`guard_viser` substitutes a thin wrapper for that ``serve`` while a viser server starts,
so that :meth:`Gate.check` runs before viser's own ``process_request`` on every request of that
server (HTTP pages, assets and the websocket handshake alike); a refused request gets a 403 and
never reaches viser.

>>> gate = Gate()
>>> len(gate.token) >= 43
True
>>> same_origin("http://127.0.0.1:8080", "127.0.0.1:8080")
True
>>> same_origin("http://evil.example", "127.0.0.1:8080")
False
"""

from __future__ import annotations

import contextlib
import http
import ipaddress
import secrets
import string
import threading
from collections.abc import Callable, Iterator
from http.cookies import CookieError, SimpleCookie
from typing import Any
from urllib.parse import parse_qsl, urlencode, urlsplit

from kinegami.errors import GuardError, InvalidParameterError

__all__ = [
    "COOKIE_PREFIX",
    "TOKEN_PARAMETER",
    "Gate",
    "GuardError",
    "guard_viser",
    "is_loopback",
    "same_origin",
]

#: The query parameter of the printed address that carries the token.
TOKEN_PARAMETER = "token"
#: The cookie that carries the token after the first request, followed by the server's port
#: (a browser sends a host's cookies to every port of it: one cookie per editor).
COOKIE_PREFIX = "kinegami-edit-"

_FORBIDDEN = http.HTTPStatus.FORBIDDEN
_TOKEN_CHARACTERS = frozenset(string.ascii_letters + string.digits + "-_")
_SERVE_LOCK = threading.Lock()


def is_loopback(host: str) -> bool:
    """Whether ``host`` (a name or an IP address, IPv6 with or without brackets) names this
    machine only: ``localhost`` or a loopback address."""
    host = host.strip().lower().rstrip(".")
    if host.startswith("[") and host.endswith("]"):
        host = host[1:-1]
    if host == "localhost" or host.endswith(".localhost"):
        return True
    try:
        return ipaddress.ip_address(host).is_loopback
    except ValueError:
        return False


def _host_port(netloc: str) -> tuple[str, int] | None:
    """The host (lower case, IPv6 without brackets) and port (default 80) of ``netloc``
    (``host[:port]``), or None when it is not one."""
    try:
        parts = urlsplit(f"//{netloc}")
        port = parts.port
    except ValueError:
        return None
    if not parts.hostname or parts.username is not None or parts.password is not None:
        return None
    if parts.path or parts.query or parts.fragment:
        return None
    return parts.hostname, 80 if port is None else port


def same_origin(origin: str, host: str | None) -> bool:
    """Whether the ``Origin`` header ``origin`` is the page ``http://{host}`` where ``host`` is
    the ``Host`` header of the request: the same scheme (http), host and port."""
    if host is None:
        return False
    scheme, sep, netloc = origin.strip().partition("://")
    if not sep or scheme.lower() != "http":
        return False
    theirs, ours = _host_port(netloc), _host_port(host.strip())
    return theirs is not None and theirs == ours


class Gate:
    """The check in front of every request of one editor server.

    A request is refused (403, nothing served) when it carries an ``Origin`` that is not the
    page the browser reached (``http://`` and the ``Host`` header); when the browser says
    (``Sec-Fetch-Site``) that another page asks for it, other than by a top-level navigation
    (a script, an image, a frame); when the server listens on this machine only and the
    ``Host`` header names another one (a DNS rebinding); or when it has no valid token: the
    ``token`` query parameter or this server's cookie. A page request with a valid ``token``
    parameter is answered with the cookie (HttpOnly, SameSite=Strict) and a redirect to the
    page without the token, so that the page's websocket carries the cookie and the token does
    not stay in the address bar.

    Parameters
    ----------
    token : the secret (None: a new one from :func:`secrets.token_urlsafe`, 256 bits; else at
        least 16 characters among letters, digits, ``-`` and ``_``).
    local_only : the server listens on a loopback address: refuse any other ``Host``.
    """

    def __init__(self, token: str | None = None, *, local_only: bool = True):
        self.token = secrets.token_urlsafe(32) if token is None else str(token)
        others = not set(self.token) <= _TOKEN_CHARACTERS
        if len(self.token) < 16 or others:  # the token itself is not repeated: it is a secret
            raise InvalidParameterError(
                "token must be at least 16 characters among letters, digits, '-' and '_', got "
                f"{len(self.token)} characters" + (", some of them others" if others else "")
            )
        self.local_only = bool(local_only)
        self._count_lock = threading.Lock()
        #: Requests refused so far (HTTP and websocket), and by reason.
        self.refused: dict[str, int] = {}

    def cookie_name(self, port: int) -> str:
        """The name of the token's cookie for the server on ``port``."""
        return f"{COOKIE_PREFIX}{int(port)}"

    def valid(self, token: str | None) -> bool:
        """Whether ``token`` is this server's (compared in constant time)."""
        if token is None:
            return False
        return secrets.compare_digest(token.encode("utf-8"), self.token.encode("utf-8"))

    def check(self, connection: Any, request: Any) -> Any:
        """The response refusing ``request`` (a ``websockets.http11.Request`` on the
        ``websockets.asyncio.server.ServerConnection`` ``connection``) or redirecting it with
        the token's cookie, or None to let viser answer it."""
        headers = request.headers
        host = _single(headers, "Host")
        origins = headers.get_all("Origin")
        if len(origins) > 1 or (origins and not same_origin(origins[0], host)):
            return self._refuse(connection, "origin", "this page's Origin is not the editor's "
                                                      "own address")  # fmt: skip
        site = headers.get("Sec-Fetch-Site", "").lower()
        mode = headers.get("Sec-Fetch-Mode", "").lower()
        top_level = mode == "navigate" and headers.get("Sec-Fetch-Dest", "").lower() == "document"
        if site not in ("", "none", "same-origin") and not top_level:
            return self._refuse(connection, "site", "another page cannot load or frame the "
                                                    "editor")  # fmt: skip
        if self.local_only:
            reached = _host_port(host) if host is not None else None
            if reached is None or not is_loopback(reached[0]):
                return self._refuse(connection, "host", "the editor answers only its own "
                                                        "address on this machine")  # fmt: skip
        port = connection.local_address[1]
        query = request.path.partition("?")[2]
        params = parse_qsl(query, keep_blank_values=True)
        given = [value for key, value in params if key == TOKEN_PARAMETER]
        upgrade = "websocket" in headers.get("Upgrade", "").lower()
        if given:
            if len(given) != 1 or not self.valid(given[0]):
                return self._refuse(connection, "token", "wrong token")
            if upgrade:
                return None
            rest = urlencode([(key, value) for key, value in params if key != TOKEN_PARAMETER])
            response = connection.respond(http.HTTPStatus.FOUND, "")
            response.headers["Location"] = "/" + (f"?{rest}" if rest else "")  # never off-site
            response.headers["Set-Cookie"] = (f"{self.cookie_name(port)}={self.token}; Path=/; "
                                              "HttpOnly; SameSite=Strict")  # fmt: skip
            response.headers["Cache-Control"] = "no-store"
            return _harden(response)
        if self.valid(_cookie(headers, self.cookie_name(port))):
            return None
        return self._refuse(connection, "token", "open the address that kinegami edit printed "
                                                 "(with its token)")  # fmt: skip

    def _refuse(self, connection: Any, reason: str, text: str) -> Any:
        with self._count_lock:
            self.refused[reason] = self.refused.get(reason, 0) + 1
        response = connection.respond(_FORBIDDEN, f"403 Forbidden: {text}\n")
        response.headers["Cache-Control"] = "no-store"
        return _harden(response)

    def wrap(self, process_request: Callable | None) -> Callable:
        """``process_request`` (viser's, or None) behind :meth:`check`."""

        def checked(connection, request):
            refusal = self.check(connection, request)
            if refusal is not None or process_request is None:
                return refusal
            response = process_request(connection, request)
            if response is not None and hasattr(response, "headers"):
                _harden(response)
            return response

        checked.gate = self  # type: ignore[attr-defined]
        return checked


def _harden(response: Any) -> Any:
    """``response`` with headers that keep other sites from framing the page (a framed editor
    would pass the Origin check, and clicks could be tricked into it)."""
    response.headers["X-Frame-Options"] = "DENY"
    response.headers["Content-Security-Policy"] = "frame-ancestors 'none'"
    response.headers["X-Content-Type-Options"] = "nosniff"
    return response


def _single(headers: Any, name: str) -> str | None:
    values = headers.get_all(name)
    return values[0] if len(values) == 1 else None


def _cookie(headers: Any, name: str) -> str | None:
    found = None
    for header in headers.get_all("Cookie"):
        jar: SimpleCookie = SimpleCookie()
        with contextlib.suppress(CookieError):
            jar.load(header)
        if name in jar:
            if found is not None:
                return None  # two cookies of the name: neither
            found = jar[name].value
    return found


@contextlib.contextmanager
def guard_viser(gate: Gate) -> Iterator[Callable[[], int]]:
    """Within the block, every server started through ``websockets.asyncio.server.serve``
    (viser's, in ``viser.infra``) gets ``gate.wrap`` around its ``process_request``. Yields a
    function counting the servers so wrapped: start the viser server inside the block and check
    it is at least 1 (0: viser started its server another way, unchecked; see
    :class:`GuardError`). One block at a time in the process; the original ``serve`` is back
    when the block ends."""
    import websockets.asyncio.server as ws_server

    wrapped = 0
    with _SERVE_LOCK:
        original = ws_server.serve

        def serve(*args, **kwargs):
            nonlocal wrapped
            kwargs["process_request"] = gate.wrap(kwargs.get("process_request"))
            wrapped += 1
            return original(*args, **kwargs)

        ws_server.serve = serve  # type: ignore[misc,assignment]
        try:
            yield lambda: wrapped
        finally:
            ws_server.serve = original  # type: ignore[misc]
