"""The ``kinegami edit`` server: a viser server where each browser tab edits its own document.

>>> from kinegami.editor.server import EditorServer
>>> server = EditorServer(port=0)  # doctest: +SKIP
>>> server.url  # doctest: +SKIP
'http://127.0.0.1:8080/?token=...'

Every tab (viser client) gets an :class:`~kinegami.editor.view.EditorView` over a new
:class:`~kinegami.editor.model.EditorModel` of the starting design; the design is read once,
on the server, from the path given on the command line. Browsers can only upload design
files' contents, never name server paths: the only files the server writes are that design
(the Save button) and its autosave in the user's data folder
(:mod:`kinegami.editor.autosave`). Only the holder of the token in :attr:`EditorServer.url`
may use the server, and only from the editor's own page (:mod:`kinegami.editor.access`). See
docs/editor.md.
"""

from __future__ import annotations

import contextlib
import io
import os
import threading
import warnings
from pathlib import Path

from kinegami.editor.access import (
    TOKEN_PARAMETER,
    Gate,
    GuardError,
    guard_viser,
    is_loopback,
)
from kinegami.editor.autosave import Autosaver, Recovery, autosave_path, find_recovery
from kinegami.editor.background import ProcessWorker
from kinegami.editor.commands import ReplaceDocument
from kinegami.editor.document import Document
from kinegami.editor.model import EditorModel
from kinegami.editor.view import EditorView, gallery
from kinegami.errors import ClearanceWarning, ExporterUnavailableError

__all__ = ["EditorServer", "LOCAL_HOSTS", "is_local", "starting_document"]

#: The usual hosts that only this machine can reach (any loopback address is local too; any
#: other --host gets a warning, see :func:`is_local`).
LOCAL_HOSTS = ("127.0.0.1", "localhost", "::1")
#: Hosts that listen on every address of the machine: the printed address names this machine.
_WILDCARD_HOSTS = {"0.0.0.0": "127.0.0.1", "::": "::1", "": "127.0.0.1"}


def is_local(host: str) -> bool:
    """Whether listening on ``host`` keeps the editor on this machine (``localhost`` or a
    loopback address)."""
    return host in LOCAL_HOSTS or is_loopback(host)


def starting_document(design: str | os.PathLike | None = None) -> Document:
    """The document each new tab starts from: the design file, else the starter design of
    ``kinegami new`` (a start tip and a few joints). Raises DesignError for a bad file. A
    design that passes through itself is loaded without printing the loader's
    ClearanceWarnings: the editor's clearance panel reports it."""
    if design is None:
        return EditorModel().document
    with warnings.catch_warnings():  # on start, before the server's threads run
        warnings.simplefilter("ignore", ClearanceWarning)
        return Document.load(design)


def _viser():
    try:
        import viser
    except ImportError as exc:
        raise ExporterUnavailableError(
            "the browser editor needs viser: pip install 'kinegami[gui]'"
        ) from exc
    return viser


class EditorServer:
    """A viser server with one editor per connected tab.

    Parameters
    ----------
    design : the design file every tab starts from (None: the starter design).
    host, port : where to listen (port 0: a free port).
    autosave : keep an autosave of every tab's unsaved changes (see
        :mod:`kinegami.editor.autosave`).
    recover : start every tab from the autosave found on start (when there is one) instead
        of asking.
    token : the secret of :attr:`url` (None: a new random one).

    Every request (page, asset, websocket) passes :class:`~kinegami.editor.access.Gate` first:
    a foreign ``Origin`` or a missing or wrong token gets a 403 (docs/editor.md, Security).
    """

    def __init__(self, design: str | os.PathLike | None = None, host: str = "127.0.0.1",
                 port: int = 8080, *, autosave: bool = True,
                 recover: bool = False, token: str | None = None):  # fmt: skip
        viser = _viser()
        #: The access check of every request (its token is in :attr:`url`).
        self.gate = Gate(token, local_only=is_local(host))
        self.document = starting_document(design)
        self.path = None if design is None else Path(os.fspath(design))
        self.views: dict[int, EditorView] = {}
        self._lock = threading.Lock()
        self.autosave = bool(autosave)
        self._autosavers: dict[Path, Autosaver] = {}
        #: The autosave found on start that is newer than the design (offered to each new
        #: tab until one recovers or discards it), or None.
        with warnings.catch_warnings():  # the recovered document's clearance is shown too
            warnings.simplefilter("ignore", ClearanceWarning)
            self.recovery: Recovery | None = find_recovery(self.path) if self.autosave else None
        self.recover = bool(recover)
        #: Fits trees' junctions for the tabs' pattern panels (a process started on first use).
        self.worker = ProcessWorker()
        if port == 0:
            port = _free_port(host)
        banner = contextlib.redirect_stdout(io.StringIO())  # viser's: the CLI prints its own
        with banner, guard_viser(self.gate) as guarded:
            self.server = viser.ViserServer(host=host, port=port, label="kinegami edit",
                                            verbose=False)  # fmt: skip
        if guarded() < 1:  # fail closed: never serve the editor unchecked
            with contextlib.redirect_stdout(io.StringIO()):
                self.server.stop()
            self.worker.close()
            raise GuardError(f"viser {viser.__version__} did not start its server through "
                             "websockets.asyncio.server.serve: kinegami edit cannot check its "
                             "requests and does not serve")  # fmt: skip
        self.server.on_client_connect(self._connect)
        self.server.on_client_disconnect(self._disconnect)

    @property
    def port(self) -> int:
        return self.server.get_port()

    @property
    def address(self) -> str:
        """The server's address without the token (``http://host:port``; a wildcard --host
        such as 0.0.0.0 as this machine's loopback address)."""
        host = self.server.get_host()
        host = _WILDCARD_HOSTS.get(host, host)
        if ":" in host:
            host = f"[{host}]"
        return f"http://{host}:{self.port}"

    @property
    def url(self) -> str:
        """The address to open in a browser: :attr:`address` with the token
        (``http://127.0.0.1:8080/?token=...``)."""
        return f"{self.address}/?{TOKEN_PARAMETER}={self.gate.token}"

    def autosaver(self, design: Path | None) -> Autosaver:
        """The one autosaver of a design file (None: of designs with no file), shared by the
        tabs."""
        path = autosave_path(design)
        with self._lock:
            saver = self._autosavers.get(path)
            if saver is None:
                saver = self._autosavers[path] = Autosaver(path)
            return saver

    def new_view(self, target) -> EditorView:
        """An editor over a new model of the starting document, drawn on ``target`` (a viser
        client, or the server itself in tests). With an autosave found on start, the tab
        starts from it (``recover``) or offers it back."""
        model = EditorModel(self.document, self.path)
        recovery = self.recovery
        if recovery is not None and self.recover:
            model.apply(ReplaceDocument(recovery.document, f"recover the autosave "
                                                           f"({recovery.describe()})"))  # fmt: skip
            recovery = None
        return EditorView(
            target, model, autosave_for=self.autosaver if self.autosave else None,
            recovery=recovery, on_recovery=self._recovered, worker=self.worker,
        )  # fmt: skip

    def _recovered(self, choice: str) -> None:
        self.recovery = None  # offered once: recovered or discarded in one tab

    def _connect(self, client) -> None:
        view = self.new_view(client)
        with self._lock:
            self.views[client.client_id] = view

    def _disconnect(self, client) -> None:
        with self._lock:
            view = self.views.pop(client.client_id, None)
        if view is not None:
            view.close()

    def stop(self) -> None:
        """Stop serving; pending autosaves are written."""
        with self._lock:
            views = list(self.views.values())
            self.views.clear()
            savers = list(self._autosavers.values())
        for view in views:
            view.close()
        for saver in savers:
            saver.close()
        self.worker.close()
        with contextlib.redirect_stdout(io.StringIO()):
            self.server.stop()


def _free_port(host: str) -> int:
    import socket

    family = socket.AF_INET6 if ":" in host else socket.AF_INET
    with socket.socket(family, socket.SOCK_STREAM) as sock:
        sock.bind((host, 0))
        return sock.getsockname()[1]


def examples() -> tuple[str, ...]:
    """The gallery designs a tab can open."""
    return tuple(gallery())
