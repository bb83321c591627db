"""Writing patterns to files: a registry of exporters, one per file suffix.

:func:`save_pattern` (what ``TubularPattern.save`` calls) picks the exporter from the file name's
suffix and writes atomically: the file is rendered in memory, written to a temporary file in the
target folder and moved onto the target name with :func:`os.replace`, so a failed save never
leaves a partial or temporary file behind. Missing parent folders are created.

An exporter is a function ``exporter(pattern, stream, **options)`` writing text to ``stream``;
:func:`register_exporter` adds one. Built in: ``.dxf`` (:func:`kinegami.export.dxf.write_dxf`),
``.svg`` (:func:`kinegami.export.svg.write_svg`) and ``.fold`` (:mod:`kinegami.export.fold`).
See docs/fabrication.md.

:func:`export` (in :mod:`kinegami.export.registry`) is the entry point for every format, patterns
and chains alike (DXF, SVG, FOLD, PDF, STL, OBJ, URDF). This module is itself callable, so
``kinegami.export(chain, "arm.urdf")`` works as well as ``from kinegami.export import export``.
"""

from __future__ import annotations

import errno
import io
import os
import secrets
import sys
import types
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING, Any

from kinegami.errors import InvalidParameterError, InvalidTypeError, KinegamiError

if TYPE_CHECKING:  # pragma: no cover
    from kinegami.pattern.tubular import TubularPattern

__all__ = [
    "ExportError",
    "EXPORTERS",
    "export",
    "known_formats",
    "register_exporter",
    "save_pattern",
    "write_atomic",
    "write_atomic_bytes",
]


class ExportError(KinegamiError, OSError):
    """A pattern could not be written (folder not writable, disk full, ...).

    ``errno`` and ``filename`` are those of the underlying :class:`OSError`.
    """


#: Exporter function per lower-case file suffix (with the dot).
EXPORTERS: dict[str, Callable[..., None]] = {}


def register_exporter(suffix: str, exporter: Callable[..., None]) -> None:
    """Register ``exporter(pattern, stream, **options)`` for files ending in ``suffix``.

    Parameters
    ----------
    suffix : str
        File suffix including the dot, e.g. ``".dxf"`` (matched case-insensitively).
    exporter : callable
        Writes the pattern as text to the stream; raises a KinegamiError on bad options.
    """
    if not isinstance(suffix, str) or not suffix.startswith(".") or len(suffix) < 2:
        raise InvalidParameterError(f"suffix must look like '.ext', got {suffix!r}")
    if not callable(exporter):
        raise InvalidTypeError(f"exporter must be callable, got {exporter!r}")
    EXPORTERS[suffix.lower()] = exporter


def _known() -> str:
    return ", ".join(sorted(EXPORTERS))


def _target_path(dxfName: str | os.PathLike | None) -> Path:
    """Check the file name and return it as a Path (no file system changes)."""
    if dxfName is None:
        raise InvalidParameterError(
            f"a file name is required, e.g. save(dxfName='pattern.dxf') (known suffixes: "
            f"{_known()})"
        )
    if not isinstance(dxfName, str | os.PathLike):
        raise InvalidTypeError(f"the file name must be a str or a path, got {dxfName!r}")
    text = os.fspath(dxfName)
    if isinstance(text, bytes):
        raise InvalidTypeError(f"the file name must be a str or a path, got {dxfName!r}")
    if not text.strip():
        raise InvalidParameterError(f"the file name is empty ({dxfName!r})")
    path = Path(text).expanduser()
    if path.is_dir() or text.endswith(("/", os.sep)):
        raise InvalidParameterError(f"{text!r} is a directory, not a file name")
    if path.name.lower() in EXPORTERS:
        raise InvalidParameterError(f"the file name {text!r} has a suffix but no name")
    suffix = path.suffix.lower()
    if suffix not in EXPORTERS:
        raise InvalidParameterError(
            f"cannot save {text!r}: unknown file suffix {path.suffix or '(none)'!r}; "
            f"known suffixes: {_known()}"
        )
    return path


def _export_error(exc: OSError, path: Path, what: str) -> ExportError:
    """ExportError carrying ``exc``'s errno, printed as ``[Errno n] message: 'path'``."""
    reason = exc.strerror or str(exc)
    message = f"cannot write the file ({what}): {reason}"
    if exc.errno is None:
        return ExportError(f"{message}: {str(path)!r}")
    return ExportError(exc.errno, message, str(path))


def _create_temp(folder: Path, name: str) -> tuple[int, str]:
    """Create a new hidden file next to the target; the umask applies as for any new file."""
    flags = os.O_WRONLY | os.O_CREAT | os.O_EXCL | getattr(os, "O_BINARY", 0)
    for _ in range(100):
        tmp = os.path.join(folder, f".{name}.{secrets.token_hex(4)}.tmp")
        try:
            return os.open(tmp, flags, 0o666), tmp
        except FileExistsError:
            continue
    raise FileExistsError(errno.EEXIST, "no free temporary file name", str(folder))


def prepare_folder(path: Path) -> None:
    """Create ``path``'s parent folder (ExportError if impossible, e.g. it is a file)."""
    parent = path.parent
    if parent.exists() and not parent.is_dir():
        raise ExportError(
            errno.ENOTDIR, f"cannot write the file: {str(parent)!r} is a file, not a folder",
            str(path),
        )  # fmt: skip
    try:
        parent.mkdir(parents=True, exist_ok=True)
    except OSError as exc:
        raise _export_error(exc, path, f"cannot create the folder {str(parent)!r}") from exc


def discard(tmp: str | os.PathLike) -> None:
    """Remove a temporary file, ignoring errors (it may not exist)."""
    try:
        os.unlink(tmp)
    except OSError:
        pass


def write_atomic_bytes(path: Path, data: bytes) -> None:
    """Write ``data`` to ``path`` atomically, creating missing parent folders.

    Raises
    ------
    ExportError
        If a folder cannot be created or the file cannot be written; no file is left behind.
    """
    path = Path(path)
    prepare_folder(path)
    try:
        fd, tmp = _create_temp(path.parent, path.name)
    except OSError as exc:
        raise _export_error(exc, path, "cannot create a file in its folder") from exc
    try:
        with os.fdopen(fd, "wb") as stream:
            stream.write(data)
        os.replace(tmp, path)
    except BaseException as exc:
        discard(tmp)
        if isinstance(exc, OSError) and not isinstance(exc, KinegamiError):
            raise _export_error(exc, path, "write failed") from exc
        raise


def write_atomic(path: Path, text: str) -> None:
    """Write ``text`` as UTF-8 (newlines as ``\\n``) atomically; see :func:`write_atomic_bytes`."""
    write_atomic_bytes(path, text.encode("utf-8"))


def save_pattern(
    pattern: TubularPattern, dxfName: str | os.PathLike | None, **options: Any
) -> Path:
    """Save a pattern to a file whose format is chosen by the suffix (``.dxf`` or ``.svg``).

    Parameters
    ----------
    pattern : TubularPattern
        The pattern to write (a module or a whole chain).
    dxfName : str or os.PathLike
        Target file name (the paper's keyword; any registered suffix works). Missing parent
        folders are created; an existing file is replaced.
    **options
        Passed to the exporter. The DXF and SVG exporters accept ``units`` (length of one
        pattern unit: ``'mm'`` (default), ``'cm'``, ``'m'``, ``'in'``), ``scale`` (extra
        multiplier), ``perforate`` / ``dash`` / ``gap`` (fold lines as dashes, lengths in mm)
        and ``skip_creases_on_cut``; see docs/fabrication.md.

    Returns
    -------
    pathlib.Path
        The path written.

    Raises
    ------
    InvalidParameterError
        For a missing or empty name, a directory, or an unknown suffix (the message lists the
        known ones), or a bad option value.
    InvalidTypeError
        For an unknown option.
    ExportError
        If the file cannot be written; nothing is left behind.

    Examples
    --------
    >>> from kinegami.pattern import TubeFittingPattern
    >>> save_pattern(TubeFittingPattern(4, 10.0, 30.0), "out/tube.dxf")  # doctest: +SKIP
    PosixPath('out/tube.dxf')
    """
    from kinegami.pattern.tubular import TubularPattern

    if not isinstance(pattern, TubularPattern):
        raise InvalidTypeError(f"pattern must be a TubularPattern, got {type(pattern).__name__}")
    path = _target_path(dxfName)
    exporter = EXPORTERS[path.suffix.lower()]
    buffer = io.StringIO()
    try:
        exporter(pattern, buffer, **options)
    except OSError as exc:  # e.g. ezdxf cannot read its configuration on import
        if isinstance(exc, KinegamiError):
            raise
        raise _export_error(exc, path, "the exporter failed") from exc
    write_atomic(path, buffer.getvalue())
    return path


def _register_builtin() -> None:
    from kinegami.export.dxf import write_dxf
    from kinegami.export.svg import write_svg

    register_exporter(".dxf", write_dxf)
    register_exporter(".svg", write_svg)
    register_exporter(".fold", _write_fold)


def _write_fold(pattern: TubularPattern, stream, **options: Any) -> None:
    """FOLD 1.2 (imported on first use; see kinegami.export.fold.write_fold)."""
    from kinegami.export.fold import write_fold

    write_fold(pattern, stream, **options)


_register_builtin()


from kinegami.export.registry import export, known_formats  # noqa: E402


class _CallableModule(types.ModuleType):
    """``kinegami.export(obj, path, **options)`` calls :func:`export`."""

    def __call__(self, obj: Any, path: str | os.PathLike, **options: Any) -> Path:
        return export(obj, path, **options)


sys.modules[__name__].__class__ = _CallableModule
