"""One entry point for every file format: ``export(obj, path, **options)``.

The format is chosen by the file suffix from a registry of exporter functions, one per suffix.
Each works on a crease pattern or on a chain:

========  =======  ======  ===========================================================
suffix    object   kind    exporter
========  =======  ======  ===========================================================
``.dxf``  pattern  text    :func:`kinegami.export.dxf.write_dxf` (via ``EXPORTERS``)
``.svg``  pattern  text    :func:`kinegami.export.svg.write_svg` (via ``EXPORTERS``)
``.fold`` any      text    ``kinegami.export.fold.write_fold``
``.pdf``  pattern  binary  :func:`kinegami.export.pdf.write_pdf`
``.stl``  chain    binary  :func:`kinegami.export.mesh.write_stl`
``.obj``  chain    text    :func:`kinegami.export.mesh.write_obj`
``.urdf`` chain    files   :func:`kinegami.export.urdf.urdf_files` (URDF + mesh folder)
========  =======  ======  ===========================================================

A :class:`~kinegami.chain.KinematicChain` given for a pattern format is exported as
``chain.creasePattern(twistPortion)`` (the ``twistPortion`` option, default 0.2, is taken for
that). Exporters are imported when first used, so a format whose module is missing only fails
when a file of that format is written (:class:`ExporterUnavailableError`).

Every write is atomic: the file (or the set of files) is rendered in memory, written to
temporary names in the target folder and moved into place with :func:`os.replace`; on any
failure nothing is left behind and existing files are unchanged.
"""

from __future__ import annotations

import errno
import importlib
import io
import os
import secrets
import shutil
import signal
from collections.abc import Callable, Mapping
from dataclasses import dataclass
from pathlib import Path, PurePosixPath
from typing import Any

import kinegami.export as _base
from kinegami.errors import InvalidParameterError, InvalidTypeError, KinegamiError
from kinegami.export import write_atomic_bytes  # re-exported: part of this module's API
from kinegami.export.publish import deferred_signals

__all__ = [
    "ExportFormat",
    "ExporterUnavailableError",
    "FORMATS",
    "ACCEPTS",
    "register",
    "known_formats",
    "export",
    "write_atomic_bytes",
    "write_atomic_files",
]

#: What an exporter takes: a TubularPattern, a KinematicChain, or either as given.
ACCEPTS = ("pattern", "chain", "any")

_KINDS = ("text", "binary", "files")


class ExporterUnavailableError(KinegamiError, ImportError):
    """The exporter of a registered format cannot be imported (its module is missing)."""


@dataclass(frozen=True)
class ExportFormat:
    """A registered file format.

    Attributes
    ----------
    suffix : str
        Lower-case suffix with the dot, e.g. ``".stl"``.
    func : callable or str
        The exporter, or ``"package.module:function"`` imported on first use.
    accepts : str
        ``"pattern"``, ``"chain"`` or ``"any"``.
    kind : str
        ``"text"``: ``func(obj, stream, **options)`` writes text; ``"binary"``: bytes;
        ``"files"``: ``func(obj, path, **options)`` returns ``{relative path: bytes}`` for the
        file itself and any files beside it.
    description : str
        One line for ``known_formats()`` and the CLI.
    """

    suffix: str
    func: Callable[..., Any] | str
    accepts: str
    kind: str
    description: str

    @property
    def binary(self) -> bool:
        """True for binary files."""
        return self.kind == "binary"

    def load(self) -> Callable[..., Any]:
        """The exporter function, imported if registered by name."""
        if callable(self.func):
            return self.func
        module_name, _, attribute = self.func.partition(":")
        try:
            module = importlib.import_module(module_name)
        except ImportError as exc:
            raise ExporterUnavailableError(
                f"the {self.suffix} exporter is not available: cannot import {module_name} ({exc})"
            ) from exc
        try:
            return getattr(module, attribute)
        except AttributeError as exc:
            raise ExporterUnavailableError(
                f"the {self.suffix} exporter is not available: {module_name} has no {attribute!r}"
            ) from exc


#: Registered formats by lower-case suffix.
FORMATS: dict[str, ExportFormat] = {}


def _check_suffix(suffix: Any) -> str:
    if not isinstance(suffix, str) or not suffix.startswith(".") or len(suffix) < 2:
        raise InvalidParameterError(f"suffix must look like '.ext', got {suffix!r}")
    if any(c in suffix[1:] for c in "./\\") or suffix != suffix.strip():
        raise InvalidParameterError(f"suffix must look like '.ext', got {suffix!r}")
    return suffix.lower()


def register(
    suffix: str,
    func: Callable[..., Any] | str,
    accepts: str = "pattern",
    binary: bool = False,
    description: str = "",
    *,
    files: bool = False,
) -> None:
    """Register the exporter of files ending in ``suffix`` (replacing any earlier one).

    Parameters
    ----------
    suffix : str
        File suffix with the dot, e.g. ``".stl"`` (matched case-insensitively).
    func : callable or str
        ``func(obj, stream, **options)`` writing text (or bytes if ``binary``) to ``stream``;
        with ``files=True``, ``func(obj, path, **options) -> {relative path: bytes}``. A string
        ``"package.module:function"`` is imported when the format is first used.
    accepts : {'pattern', 'chain', 'any'}
        What ``func`` takes. For ``'pattern'`` a chain is turned into its crease pattern.
    binary : bool
        The stream is binary.
    description : str
        One line describing the format.
    files : bool
        The exporter returns a set of files (see ``func``).
    """
    suffix = _check_suffix(suffix)
    if not (callable(func) or (isinstance(func, str) and ":" in func)):
        raise InvalidTypeError(f"func must be callable or 'package.module:function', got {func!r}")
    if accepts not in ACCEPTS:
        raise InvalidParameterError(f"accepts must be one of {ACCEPTS}, got {accepts!r}")
    if not isinstance(binary, bool) or not isinstance(files, bool):
        raise InvalidTypeError(f"binary and files must be True or False, got {binary!r}, {files!r}")
    if binary and files:
        raise InvalidParameterError("give binary=True or files=True, not both")
    if not isinstance(description, str):
        raise InvalidTypeError(f"description must be a string, got {description!r}")
    kind = "files" if files else "binary" if binary else "text"
    FORMATS[suffix] = ExportFormat(suffix, func, accepts, kind, description)


def _format(suffix: str) -> ExportFormat | None:
    """The format of a suffix: registered here, or a pattern exporter of ``EXPORTERS``."""
    found = FORMATS.get(suffix)
    if found is not None:
        return found
    if suffix in _base.EXPORTERS:
        return ExportFormat(
            suffix, _base.EXPORTERS[suffix], "pattern", "text", "crease pattern (text)"
        )
    return None


def known_formats() -> dict[str, str]:
    """Description of every exportable suffix, sorted by suffix (for ``--formats`` help)."""
    suffixes = set(FORMATS) | set(_base.EXPORTERS)
    return {s: _format(s).description for s in sorted(suffixes)}


def _known() -> str:
    return ", ".join(known_formats())


def _target(path: Any) -> Path:
    if path is None:
        raise InvalidParameterError(f"a file name is required (known suffixes: {_known()})")
    if not isinstance(path, str | os.PathLike):
        raise InvalidTypeError(f"the file name must be a str or a path, got {path!r}")
    text = os.fspath(path)
    if isinstance(text, bytes):
        raise InvalidTypeError(f"the file name must be a str or a path, got {path!r}")
    if not text.strip():
        raise InvalidParameterError(f"the file name is empty ({path!r})")
    target = Path(text).expanduser()
    if target.is_dir() or text.endswith(("/", os.sep)):
        raise InvalidParameterError(f"{text!r} is a directory, not a file name")
    suffix = target.suffix.lower()
    if target.name.lower() == suffix or not suffix:
        raise InvalidParameterError(
            f"cannot export {text!r}: the file name needs a name and a suffix; known suffixes: "
            f"{_known()}"
        )
    if _format(suffix) is None:
        raise InvalidParameterError(
            f"cannot export {text!r}: unknown file suffix {target.suffix!r}; known suffixes: "
            f"{_known()}"
        )
    return target


def _subject(obj: Any, fmt: ExportFormat, options: dict[str, Any]) -> Any:
    """The object the exporter takes (a chain's crease pattern for pattern formats)."""
    from kinegami.chain import KinematicChain
    from kinegami.pattern.tubular import TubularPattern

    if fmt.accepts == "chain":
        if not isinstance(obj, KinematicChain):
            raise InvalidTypeError(
                f"{fmt.suffix} files are made from a KinematicChain, got {type(obj).__name__}"
            )
        return obj
    if not isinstance(obj, KinematicChain | TubularPattern):
        raise InvalidTypeError(
            f"{fmt.suffix} files are made from a TubularPattern or a KinematicChain, got "
            f"{type(obj).__name__}"
        )
    if fmt.accepts == "pattern" and isinstance(obj, KinematicChain):
        return obj.creasePattern(options.pop("twistPortion", 0.2))
    return obj


def export(obj: Any, path: str | os.PathLike, **options: Any) -> Path:
    """Write ``obj`` (a KinematicChain or a TubularPattern) to ``path`` in the suffix's format.

    Parameters
    ----------
    obj : KinematicChain or TubularPattern
        Chains can be written in every format (pattern formats get
        ``chain.creasePattern(twistPortion)``); patterns only in the pattern formats.
    path : str or os.PathLike
        Target file; missing parent folders are created and an existing file is replaced.
    **options
        Passed to the exporter (see :func:`known_formats` and each exporter's docstring);
        ``twistPortion`` (default 0.2) is used to make a chain's crease pattern.

    Returns
    -------
    pathlib.Path
        The path written (for ``.urdf`` the URDF itself; its meshes are in
        ``<stem>_meshes/`` beside it).

    Raises
    ------
    InvalidParameterError
        For a missing or bad file name, an unknown suffix (the message lists the known ones)
        or a bad option value.
    InvalidTypeError
        For an object the format cannot take, or an unknown option.
    ExporterUnavailableError
        If the format's exporter module cannot be imported.
    ExportError
        If the files cannot be written; nothing is left behind.

    Examples
    --------
    >>> export(chain, "out/robot.urdf", units="mm")  # doctest: +SKIP
    PosixPath('out/robot.urdf')
    >>> export(chain, "out/pattern.pdf", paper="Letter", scale=10)  # doctest: +SKIP
    PosixPath('out/pattern.pdf')
    """
    target = _target(path)
    fmt = _format(target.suffix.lower())
    options = dict(options)
    subject = _subject(obj, fmt, options)
    func = fmt.load()
    try:
        if fmt.kind == "files":
            files = func(subject, target, **options)
        elif fmt.kind == "binary":
            buffer = io.BytesIO()
            func(subject, buffer, **options)
            data = buffer.getvalue()
        else:
            stream = io.StringIO()
            func(subject, stream, **options)
            text = stream.getvalue()
    except OSError as exc:
        if isinstance(exc, KinegamiError):
            raise
        raise _base._export_error(exc, target, "the exporter failed") from exc
    if fmt.kind == "files":
        write_atomic_files(target, files)
    elif fmt.kind == "binary":
        write_atomic_bytes(target, data)
    else:
        _base.write_atomic(target, text)
    return target


# --- atomic writing ------------------------------------------------------------------------


def _temp_folder(parent: Path, name: str, tag: str) -> Path:
    for _ in range(100):
        candidate = parent / f".{name}.{secrets.token_hex(4)}.{tag}"
        try:
            candidate.mkdir()
            return candidate
        except FileExistsError:
            continue
    raise FileExistsError(errno.EEXIST, "no free temporary folder name", str(parent))


def _split_files(path: Path, files: Mapping[str, bytes]) -> dict[str, dict[str, bytes] | bytes]:
    """Group ``files`` by their first path component: a file or a folder beside ``path``."""
    if path.name not in files:
        raise KinegamiError(f"the exporter did not produce {path.name!r}")
    groups: dict[str, Any] = {}
    for name, data in files.items():
        rel = PurePosixPath(name)
        if rel.is_absolute() or ".." in rel.parts or not rel.parts or "\\" in name:
            raise KinegamiError(f"the exporter produced a file outside the folder: {name!r}")
        if not isinstance(data, bytes | bytearray):
            raise KinegamiError(f"the exporter produced {type(data).__name__} for {name!r}")
        head = rel.parts[0]
        if len(rel.parts) == 1:
            if head in groups:
                raise KinegamiError(f"the exporter produced {head!r} as a file and a folder")
            groups[head] = bytes(data)
        else:
            group = groups.setdefault(head, {})
            if not isinstance(group, dict):
                raise KinegamiError(f"the exporter produced {head!r} as a file and a folder")
            group[str(PurePosixPath(*rel.parts[1:]))] = bytes(data)
    return groups


def write_atomic_files(path: Path, files: Mapping[str, bytes]) -> None:
    """Write a set of files beside ``path`` as one unit (the URDF and its mesh folder).

    Parameters
    ----------
    path : Path
        The main file; ``files[path.name]`` is its content.
    files : mapping of str to bytes
        Contents by path relative to ``path``'s folder (POSIX separators). A first path
        component with more below it is a folder: it is written whole into a temporary folder
        and replaces any existing folder of that name entirely.

    Everything is written to temporary names first; then existing folders are moved aside,
    the new ones moved in and the files replaced, main file last. If any step fails the
    moves are undone and the temporaries removed, so the folder is as before. Ctrl-C, SIGTERM
    and SIGHUP are held back while the moves run (:func:`kinegami.export.publish.deferred_signals`):
    the moves stop and are undone, then the signal takes effect. (A SIGKILL in the middle can
    leave the old folder as a hidden ``.<name>.<random>.old`` beside it. ``kinegami build``
    writes into a fresh staging folder, so nothing old is at stake there, and publishes with
    :mod:`kinegami.export.publish`, which recovers after a SIGKILL.)

    Raises
    ------
    ExportError
        If anything cannot be written; nothing is left behind.
    """
    path = Path(path)
    groups = _split_files(path, files)
    parent = path.parent
    for head, content in groups.items():
        existing = parent / head
        if isinstance(content, dict) and existing.exists() and not existing.is_dir():
            raise _base.ExportError(
                errno.ENOTDIR,
                f"cannot write the folder {head!r}: a file of that name exists",
                str(existing),
            )
        if not isinstance(content, dict) and existing.is_dir():
            raise _base.ExportError(
                errno.EISDIR, f"cannot write {head!r}: a folder of that name exists", str(existing)
            )
    _base.prepare_folder(path)
    temps: list[tuple[str, Path]] = []  # (name, temporary path), not yet moved
    moved: list[tuple[Path, Path | None]] = []  # folders moved into place, with their backup
    try:
        try:
            for head, content in groups.items():
                if isinstance(content, dict):
                    folder = _temp_folder(parent, head, "tmp")
                    temps.append((head, folder))
                    for name, data in content.items():
                        target = folder / name
                        target.parent.mkdir(parents=True, exist_ok=True)
                        target.write_bytes(data)
                else:
                    fd, tmp = _base._create_temp(parent, head)
                    temps.append((head, Path(tmp)))
                    with os.fdopen(fd, "wb") as stream:
                        stream.write(content)
            order = sorted(temps, key=lambda item: item[0] == path.name)  # main file last
            # Ctrl-C, SIGTERM and SIGHUP wait until the moves are done or undone
            with deferred_signals() as received:
                try:
                    for head, tmp in order:
                        if received:
                            raise _base.ExportError(
                                errno.EINTR,
                                f"cannot write the files: interrupted by "
                                f"{signal.Signals(received[0]).name}; nothing was written",
                                str(path),
                            )
                        target = parent / head
                        if tmp.is_dir():
                            backup = None
                            if target.exists():
                                backup = _temp_folder(parent, head, "old")
                                backup.rmdir()
                                os.replace(target, backup)
                            try:
                                os.replace(tmp, target)
                            except BaseException:
                                if backup is not None:
                                    os.replace(backup, target)
                                raise
                            moved.append((target, backup))
                        else:  # a replaced file cannot come back: the main file is last
                            os.replace(tmp, target)
                        temps.remove((head, tmp))
                except BaseException:
                    for target, backup in reversed(moved):
                        shutil.rmtree(target, ignore_errors=True)
                        if backup is not None:
                            os.replace(backup, target)
                    raise
        finally:
            for _, tmp in temps:
                if tmp.is_dir():
                    shutil.rmtree(tmp, ignore_errors=True)
                else:
                    _base.discard(str(tmp))
    except OSError as exc:
        if isinstance(exc, KinegamiError):
            raise
        raise _base._export_error(exc, path, "write failed") from exc
    for _, backup in moved:
        if backup is not None:
            shutil.rmtree(backup, ignore_errors=True)


# --- built-in formats ----------------------------------------------------------------------


def _pattern_exporter(suffix: str) -> Callable[..., None]:
    """The text exporter registered in ``kinegami.export.EXPORTERS`` for ``suffix``, looked up
    at call time (so ``register_exporter`` replacements apply)."""

    def run(pattern, stream, **options):
        return _base.EXPORTERS[suffix](pattern, stream, **options)

    run.__name__ = f"pattern_exporter_{suffix[1:]}"
    return run


def _register_builtin() -> None:
    register(
        ".dxf",
        _pattern_exporter(".dxf"),
        "pattern",
        description="DXF R2013 of the flat sheet for laser cutters (mm; layers Mountain, "
        "Valley, Boundary, Cut)",
    )
    register(
        ".svg",
        _pattern_exporter(".svg"),
        "pattern",
        description="SVG of the flat sheet, true size in mm: for Origami Simulator (fold angles "
        "as opacity), or for cutting with flavour='laser'",
    )
    register(
        ".fold",
        "kinegami.export.fold:write_fold",
        "any",
        description="FOLD (JSON origami format) of the crease pattern",
    )
    register(
        ".pdf",
        "kinegami.export.pdf:write_pdf",
        "pattern",
        binary=True,
        description="PDF of the flat sheet at 1:1 tiled over A4 or Letter pages, with crop "
        "marks and a scale bar",
    )
    register(
        ".stl",
        "kinegami.export.mesh:write_stl",
        "chain",
        binary=True,
        description="binary STL of the chain's 3D model in its current configuration (mm)",
    )
    register(
        ".obj",
        "kinegami.export.mesh:write_obj",
        "chain",
        description="Wavefront OBJ of the chain's 3D model, one object per part (mm)",
    )
    register(
        ".urdf",
        "kinegami.export.urdf:urdf_files",
        "chain",
        files=True,
        description="URDF robot model (metres) with STL meshes in <name>_meshes/",
    )


_register_builtin()
