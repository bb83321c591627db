"""Atomic file writes: the one routine every file kinegami writes goes through (docs/exports.md).

:func:`write_atomic` writes the data to a new hidden file in the target's folder, flushes it to
disk (:func:`os.fsync`) and moves it onto the target name with :func:`os.replace`, which is
atomic on POSIX and Windows. Readers therefore see the old file or the new one, never a part:
a failed or interrupted write (an error, Ctrl-C, a full disk) removes the temporary file and
leaves an existing file as it was. Missing parent folders are created.

A leaf module (standard library and :mod:`kinegami.errors` only), so that exporters, design
files and the command line can all use it.
"""

from __future__ import annotations

import errno
import os
from pathlib import Path

from kinegami.errors import ExportError, KinegamiError

__all__ = ["create_temp", "discard", "export_error", "prepare_folder", "write_atomic"]


def export_error(exc: OSError, path: str | os.PathLike, what: str) -> ExportError:
    """An ExportError carrying ``exc``'s errno, printed as ``[Errno n] message: 'path'``."""
    reason = exc.strerror or str(exc)
    message = f"cannot write the file ({what}): {reason}"
    if exc.errno is None:
        return ExportError(f"{message}: {os.fspath(path)!r}")
    return ExportError(exc.errno, message, os.fspath(path))


def create_temp(folder: str | os.PathLike, name: str) -> tuple[int, str]:
    """Create a new hidden file ``.<name>.<random>.tmp`` in ``folder``; returns (fd, path).

    The umask applies as for any new file.
    """
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    for _ in range(100):
        tmp = os.path.join(folder, f".{name}.{os.urandom(4).hex()}.tmp")
        try:
            return os.open(tmp, flags, 0o666), tmp
        except FileExistsError:
            continue
    raise FileExistsError(errno.EEXIST, "no free temporary file name", os.fspath(folder))


def prepare_folder(path: str | os.PathLike) -> None:
    """Create ``path``'s parent folder (ExportError if impossible, e.g. it is a file)."""
    path = Path(path)
    parent = path.parent
    if parent.exists() and not parent.is_dir():
        raise ExportError(
            errno.ENOTDIR, f"cannot write the file: {str(parent)!r} is a file, not a folder",
            str(path),
        )  # fmt: skip
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise export_error(exc, path, f"cannot create the folder {str(parent)!r}") from exc


def discard(tmp: str | os.PathLike) -> None:
    """Remove a temporary file, ignoring errors (it may not exist)."""
    try:
        os.unlink(tmp)
    except OSError:
        pass


def discard_tree(folder: str | os.PathLike) -> None:
    """Remove a temporary folder and everything in it, ignoring errors (it may not exist).

    ``shutil`` is imported here, not at the top: every command imports this module (through
    the export registry), few remove a folder, and shutil loads bz2 and lzma.
    """
    import shutil

    shutil.rmtree(folder, ignore_errors=True)


def write_atomic(path: str | os.PathLike, data: str | bytes) -> Path:
    """Write ``data`` to ``path`` atomically, creating missing parent folders; returns the path.

    Parameters
    ----------
    path : str or os.PathLike
        The file to write; an existing file is replaced.
    data : str or bytes
        The content; text is written as UTF-8 with ``\\n`` newlines.

    Raises
    ------
    ExportError
        If a folder cannot be created or the file cannot be written. Nothing is left behind
        and an existing file is unchanged; so too after an interrupt (KeyboardInterrupt
        passes through).
    """
    path = Path(path)
    if isinstance(data, str):
        data = data.encode("utf-8")
    elif not isinstance(data, bytes | bytearray | memoryview):
        raise TypeError(f"data must be str or bytes, got {type(data).__name__}")
    prepare_folder(path)
    try:
        fd, tmp = create_temp(path.parent, path.name)
    except OSError as exc:
        raise export_error(exc, path, "cannot create a file in its folder") from exc
    try:
        with os.fdopen(fd, "wb") as stream:
            stream.write(data)
            stream.flush()
            os.fsync(stream.fileno())
        os.replace(tmp, path)
    except BaseException as exc:
        discard(tmp)
        if isinstance(exc, OSError) and not isinstance(exc, KinegamiError):
            raise export_error(exc, path, "write failed") from exc
        raise
    return path
