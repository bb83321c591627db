"""Autosave and crash recovery for ``kinegami edit``.

While a document has unsaved changes, :class:`Autosaver` writes its design file text, a second
after the last change, to an autosave file (atomically, through
:func:`kinegami._atomic.write_atomic`, so a crash leaves the previous autosave whole), in the
user's data folder (``$XDG_DATA_HOME/kinegami`` or ``~/.local/share/kinegami``), never beside
the design (where it would land in the user's own repository):

* for a design file: ``autosaves/<name>-<hash>.autosave``, the hash of the design's absolute
  path (so two ``arm.json`` in different folders have different autosaves);
* for a design with no file on the server (the starter design, an example, an upload):
  ``untitled.json.autosave``.

An explicit save removes the autosave, and so does going back (undo) to the saved document.
On start, :func:`find_recovery` offers back an autosave that is newer than its design (also
one an earlier version wrote beside the design, ``.<name>.autosave``). The autosave is a
design file: ``kinegami validate`` reads it. See docs/editor.md.
"""

from __future__ import annotations

import hashlib
import os
import threading
import time
from dataclasses import dataclass
from pathlib import Path

from kinegami._atomic import write_atomic
from kinegami.editor.background import Debounced
from kinegami.editor.document import Document

__all__ = [
    "AUTOSAVE_DELAY",
    "Autosaver",
    "Recovery",
    "autosave_path",
    "data_folder",
    "find_recovery",
    "legacy_autosave_path",
]

#: Seconds without a change before the autosave is written.
AUTOSAVE_DELAY = 1.0
#: Name of the autosave of a design with no file, in the data folder.
UNTITLED = "untitled.json.autosave"
#: The data folder's subfolder of the autosaves of design files.
AUTOSAVES = "autosaves"


def data_folder() -> Path:
    """The user's kinegami data folder: ``$XDG_DATA_HOME/kinegami`` or
    ``~/.local/share/kinegami``."""
    base = os.environ.get("XDG_DATA_HOME") or os.path.join(os.path.expanduser("~"), ".local",
                                                           "share")  # fmt: skip
    return Path(base) / "kinegami"


def autosave_path(design: str | os.PathLike | None) -> Path:
    """Where the autosave of the design file ``design`` goes (None: a design with no file):
    in the data folder, keyed by the design's absolute path (its name, then 16 hex digits of
    the SHA-256 of the path)."""
    if design is None:
        return data_folder() / UNTITLED
    design = Path(os.path.abspath(os.fspath(design)))
    digest = hashlib.sha256(os.fsencode(design)).hexdigest()[:16]
    return data_folder() / AUTOSAVES / f"{design.name}-{digest}.autosave"


def legacy_autosave_path(design: str | os.PathLike) -> Path:
    """Where earlier versions wrote the autosave of ``design``: ``.<name>.autosave`` beside it
    (only read, to offer it back once)."""
    design = Path(os.fspath(design))
    return design.with_name(f".{design.name}.autosave")


@dataclass(frozen=True)
class Recovery:
    """An autosave found on start: its file, its time and the document in it."""

    path: Path
    design: Path | None
    mtime: float
    document: Document

    @property
    def legacy(self) -> bool:
        """Whether it is an autosave an earlier version wrote beside the design."""
        return self.design is not None and self.path == legacy_autosave_path(self.design)

    def describe(self) -> str:
        """E.g. ``unsaved changes to arm.json from 2024-05-01 14:03``."""
        when = time.strftime("%Y-%m-%d %H:%M", time.localtime(self.mtime))
        what = self.design.name if self.design is not None else "a design with no file"
        return f"unsaved changes to {what} from {when}"


def find_recovery(design: str | os.PathLike | None) -> Recovery | None:
    """The autosave of ``design`` when there is one newer than the design (None otherwise,
    also when it cannot be read as a design file): the data folder's, else one an earlier
    version wrote beside the design."""
    design = None if design is None else Path(os.fspath(design))
    paths = [autosave_path(design)]
    if design is not None:
        paths.append(legacy_autosave_path(design))
    for path in paths:
        try:
            mtime = path.stat().st_mtime
            if design is not None and design.exists() and mtime <= design.stat().st_mtime:
                continue
            text = path.read_text(encoding="utf-8")
            document = Document.loads(text, path)
        except (OSError, ValueError, UnicodeError):
            continue
        return Recovery(path, design, mtime, document)
    return None


class Autosaver:
    """Keeps one autosave file up to date with the latest unsaved document given to it.

    Parameters
    ----------
    path : the autosave file (see :func:`autosave_path`).
    delay : seconds without a change before it is written.

    Several editors (browser tabs) may share one autosaver: the latest change wins, and only
    the editor that wrote it removes it when it is clean again.
    """

    def __init__(self, path: str | os.PathLike, delay: float = AUTOSAVE_DELAY):
        self.path = Path(os.fspath(path))
        self._lock = threading.Lock()  # what is pending (held only briefly: changes wait on it)
        self._file_lock = threading.Lock()  # the file: a write or a removal at a time
        self._pending: Document | None = None
        self._owner: object = None
        self._generation = 0  # bumped by discard: a write begun before it is dropped
        self._debounced = Debounced(self._write_pending, delay, name="kinegami-autosave")
        #: How many times the file was written (tests read it).
        self.writes = 0
        #: Why the last write failed (None when it did not).
        self.error: str | None = None

    def record(self, document: Document, dirty: bool, owner: object = None) -> None:
        """Called after every change: autosave ``document`` when ``dirty``; when clean, remove
        the autosave if ``owner`` wrote it last."""
        with self._lock:
            if dirty:
                self._pending, self._owner = document, owner
            elif owner is not self._owner:
                return
        if dirty:
            self._debounced.trigger()
        else:
            self.discard()

    def flush(self) -> None:
        """Write a pending autosave now."""
        self._debounced.flush()

    def discard(self) -> None:
        """Remove the autosave (after an explicit save) and forget what was pending."""
        with self._file_lock:
            with self._lock:
                self._pending, self._owner = None, None
                self._generation += 1
            try:
                self.path.unlink()
            except FileNotFoundError:
                pass

    def close(self) -> None:
        """Write what is pending and stop (the server stops)."""
        self._debounced.close(flush=True)

    def _write_pending(self) -> None:
        with self._lock:
            document, generation = self._pending, self._generation
        if document is None:
            return
        try:
            text = document.design_text
        except ValueError as error:  # cannot be written as a design now: keep the last one
            self.error = str(error)
            return
        with self._file_lock:
            with self._lock:
                if generation != self._generation or document is not self._pending:
                    return  # discarded, or a newer document is pending (written next)
            try:
                write_atomic(self.path, text)
            except OSError as error:
                self.error = str(error)
                return
            self.writes += 1
            self.error = None
