"""The one exporter registry: ``export(obj, path, **options)`` for every file format.

The format is chosen by the file suffix. An exporter is a function that returns the file's
data: ``func(obj, **options) -> str | bytes`` (text is written as UTF-8). A format that writes
several files (``files=True``, the URDF and its meshes) is called as ``func(obj, path,
**options)`` and returns ``{path relative to the folder: bytes}``. Built in:

========  =======  ==============================================  =======================
suffix    object   exporter                                        needs
========  =======  ==============================================  =======================
``.dxf``  pattern  :func:`kinegami.export.dxf.dxf_data`            -
``.svg``  pattern  :func:`kinegami.export.svg.svg_data`            -
``.fold`` any      :func:`kinegami.export.fold.fold_data`          -
``.pdf``  pattern  :func:`kinegami.export.pdf.pdf_data`            matplotlib (``[pdf]``)
``.stl``  chain    :func:`kinegami.export.mesh.stl_data`           trimesh (``[mesh]``)
``.obj``  chain    :func:`kinegami.export.mesh.obj_data`           trimesh (``[mesh]``)
``.urdf`` chain    :func:`kinegami.export.urdf.urdf_files`         trimesh (``[mesh]``)
========  =======  ==============================================  =======================

The ``chain`` formats take a :class:`~kinegami.tree.KinematicTree` too. A tree is folded from
several sheets, so the pattern formats (and ``.fold``) refuse it with an InvalidTypeError that
says to export each sheet.

Every entry point goes through here: :func:`export`, :func:`save_pattern` (what
``TubularPattern.save`` calls), chain exports and ``kinegami build --formats``. A
:class:`~kinegami.chain.KinematicChain` given for a pattern format is exported as
``chain.creasePattern(twistPortion)`` (option ``twistPortion``, default 0.2).

Exporters are registered by name (``"package.module:function"``) and imported on first use, so
importing kinegami imports none of them, and a format whose library is missing only fails
when a file of that format is written: :class:`~kinegami.errors.ExporterUnavailableError`,
whose message names the ``pip install 'kinegami[extra]'`` that adds it.

Every write is atomic (:func:`kinegami._atomic.write_atomic`; :func:`write_atomic_files` for
a set of files): on any failure nothing is left behind and existing files are unchanged.
See docs/exports.md.
"""

from __future__ import annotations

import errno
import importlib
import io
import os
import signal
from collections.abc import Callable, Iterator, Mapping
from pathlib import Path, PurePosixPath
from typing import Any

from kinegami._atomic import (
    create_temp,
    discard,
    discard_tree,
    export_error,
    prepare_folder,
    write_atomic,
)
from kinegami._record import Record
from kinegami.errors import (
    ExportError,
    ExporterUnavailableError,
    InvalidParameterError,
    InvalidTypeError,
    KinegamiError,
)

__all__ = [
    "ACCEPTS",
    "EXPORTERS",
    "ExportFormat",
    "ExporterUnavailableError",
    "FORMATS",
    "export",
    "known_formats",
    "register",
    "register_exporter",
    "save_pattern",
    "write_atomic_bytes",
    "write_atomic_files",
]

#: What an exporter takes: a TubularPattern, a KinematicChain (or KinematicTree), or either as
#: given.
ACCEPTS = ("pattern", "chain", "any")

#: The formats that ``bed=`` writes one file per laser bed sheet of, and the function that
#: does (kinegami.export.beds.save_on_beds, imported when used).
BED_FORMATS = (".dxf", ".svg")
BED_WRITER = "kinegami.export.beds:save_on_beds"

#: The same writer as :func:`kinegami._atomic.write_atomic` (bytes or text), by its old name.
write_atomic_bytes = write_atomic


def import_library(module: str, what: str, extra: str | None) -> Any:
    """Import ``module`` for ``what``; a missing one is an :class:`ExporterUnavailableError`
    naming the extra that installs it."""
    try:
        return importlib.import_module(module)
    except ImportError as exc:
        raise _unavailable(what, module, extra, exc) from exc


def _unavailable(what: str, module: str, extra: str | None, exc: ImportError):
    missing = getattr(exc, "name", None) or module
    if missing.partition(".")[0] == "kinegami" or extra is None:
        hint = "reinstall kinegami" if missing.startswith("kinegami") else f"pip install {missing}"
    else:
        hint = f"pip install 'kinegami[{extra}]'"
    return ExporterUnavailableError(
        f"the {what} exporter is not available: cannot import {missing} ({exc}); to add it: "
        f"{hint}"
    )


class ExportFormat(Record):
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
        ``"text"`` or ``"binary"``: ``func(obj, **options)`` returns the data (str or bytes);
        ``"files"``: ``func(obj, path, **options)`` returns ``{relative path: bytes}`` for the
        file itself and any files beside it.
    description : str
        One line for ``known_formats()`` and the CLI.
    extra : str or None
        The ``pip install 'kinegami[extra]'`` that installs the libraries it needs.
    """

    suffix: str
    func: Callable[..., Any] | str
    accepts: str
    kind: str
    description: str
    extra: str | None = None

    @property
    def binary(self) -> bool:
        """True for binary files."""
        return self.kind == "binary"

    def load(self) -> Callable[..., Any]:
        """The exporter function, imported if registered by name (ExporterUnavailableError if
        that fails)."""
        if callable(self.func):
            return self.func
        module_name, _, attribute = self.func.partition(":")
        module = import_library(module_name, self.suffix, self.extra)
        try:
            return getattr(module, attribute)
        except AttributeError as exc:
            raise ExporterUnavailableError(
                f"the {self.suffix} exporter is not available: {module_name} has no {attribute!r}"
            ) from exc

    def render(self, obj: Any, path: Path, **options: Any) -> str | bytes | Mapping[str, bytes]:
        """The file's data (for ``"files"``: every file's), checked; nothing is written."""
        func = self.load()
        try:
            data = func(obj, path, **options) if self.kind == "files" else func(obj, **options)
        except ModuleNotFoundError as exc:  # a library the exporter imports when it runs
            raise _unavailable(self.suffix, exc.name or "?", self.extra, exc) from exc
        except OSError as exc:  # e.g. a library cannot read its configuration
            if isinstance(exc, KinegamiError):
                raise
            raise export_error(exc, path, "the exporter failed") from exc
        if self.kind == "files":
            if not isinstance(data, Mapping):
                raise KinegamiError(
                    f"the {self.suffix} exporter returned {type(data).__name__}, not a mapping "
                    "of file names to bytes"
                )
        elif not isinstance(data, str | bytes | bytearray):
            raise KinegamiError(
                f"the {self.suffix} exporter returned {type(data).__name__}, not str or bytes"
            )
        return data


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
    extra: str | None = None,
) -> None:
    """Register the exporter of files ending in ``suffix`` (replacing any earlier one).

    Parameters
    ----------
    suffix : str
        ``".ext"``, matched case-insensitively.
    func : callable or str
        ``func(obj, **options) -> str | bytes`` returning the file's data (with ``files=True``:
        ``func(obj, path, **options) -> {relative path: bytes}``), or its
        ``"package.module:function"`` name, imported when first used.
    accepts : {'pattern', 'chain', 'any'}
        What ``func`` takes. For ``'pattern'``, chains are given as their crease pattern;
        ``'chain'`` formats take a KinematicTree too.
    binary : bool
        The file is binary (``func`` returns bytes).
    description : str
        One line shown by :func:`known_formats` and ``kinegami build --help``.
    files : bool
        ``func`` writes a main file and files beside it (see :func:`write_atomic_files`).
    extra : str, optional
        The ``pip install 'kinegami[extra]'`` named when ``func``'s libraries are missing.

    Examples
    --------
    >>> def edge_count(pattern, **options):
    ...     return f"{pattern.numEdges}\\n"
    >>> register(".count", edge_count, description="number of creases")  # doctest: +SKIP
    """
    suffix = _check_suffix(suffix)
    if not callable(func):
        if not isinstance(func, str) or ":" not in func:
            raise InvalidTypeError(
                f"func must be callable or 'package.module:function', got {func!r}"
            )
    if accepts not in ACCEPTS:
        raise InvalidParameterError(f"accepts must be one of {ACCEPTS}, got {accepts!r}")
    if type(binary) is not bool or type(files) is not bool:  # validation imports numpy: only
        from kinegami.validation import check_bool  # when needed (import kinegami stays light)

        binary, files = check_bool("binary", binary), check_bool("files", files)
    if binary and files:
        raise InvalidParameterError("give binary=True or files=True, not both")
    if not isinstance(description, str):
        raise InvalidTypeError(f"description must be a string, got {description!r}")
    if extra is not None and not isinstance(extra, str):
        raise InvalidTypeError(f"extra must be a string or None, got {extra!r}")
    kind = "files" if files else "binary" if binary else "text"
    FORMATS[suffix] = ExportFormat(suffix, func, accepts, kind, description, extra)


def register_exporter(suffix: str, exporter: Callable[..., None]) -> None:
    """Register a pattern exporter written for a text stream: ``exporter(pattern, stream,
    **options)`` (the older convention; :func:`register` takes functions returning the data).

    Parameters
    ----------
    suffix : str
        ``".ext"``, matched case-insensitively.
    exporter : callable
        Writes the pattern as text to the stream; raises a KinegamiError on bad options.
    """
    if not callable(exporter):
        raise InvalidTypeError(f"exporter must be callable, got {exporter!r}")

    def data(pattern: Any, **options: Any) -> str:
        stream = io.StringIO()
        exporter(pattern, stream, **options)
        return stream.getvalue()

    data.__name__ = getattr(exporter, "__name__", "exporter")
    data.__wrapped__ = exporter
    name = getattr(exporter, "__name__", "exporter")
    register(suffix, data, "pattern", description=f"crease pattern ({name})")


class _PatternExporters(Mapping):
    """The registered formats that take a crease pattern, by suffix (a live, read-only view of
    :data:`FORMATS`)."""

    def __getitem__(self, suffix: str) -> ExportFormat:
        fmt = FORMATS[suffix]
        if fmt.accepts == "chain":
            raise KeyError(suffix)
        return fmt

    def __iter__(self) -> Iterator[str]:
        return iter([s for s, fmt in FORMATS.items() if fmt.accepts != "chain"])

    def __len__(self) -> int:
        return sum(fmt.accepts != "chain" for fmt in FORMATS.values())

    def __repr__(self) -> str:
        return f"EXPORTERS({', '.join(self)})"


#: The formats ``pattern.save(path)`` can write, by suffix (read-only view of FORMATS).
EXPORTERS: Mapping[str, ExportFormat] = _PatternExporters()


def known_formats() -> dict[str, str]:
    """Description of every exportable suffix, sorted by suffix (for ``--formats`` help)."""
    return {s: FORMATS[s].description for s in sorted(FORMATS)}


def _known() -> str:
    return ", ".join(sorted(FORMATS))


def _target(path: Any, verb: str = "export") -> Path:
    if path is None:
        raise InvalidParameterError(
            f"a file name is required, e.g. 'pattern.dxf' (known suffixes: {_known()})"
        )
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
            f"cannot {verb} {text!r}: the file name needs a name and a suffix; known suffixes: "
            f"{_known()}"
        )
    if suffix not in FORMATS:
        raise InvalidParameterError(
            f"cannot {verb} {text!r}: unknown file suffix {target.suffix!r}; known suffixes: "
            f"{_known()}"
        )
    return target


def _subject(obj: Any, fmt: ExportFormat, options: dict[str, Any]) -> Any:
    """The object the exporter takes (a chain's crease pattern for pattern formats)."""
    from kinegami.pattern.tubular import TubularPattern

    if fmt.accepts != "chain" and isinstance(obj, TubularPattern):
        return obj  # the common case, without importing the chain and tree packages
    from kinegami.chain.model import KinematicChain
    from kinegami.tree.model import KinematicTree

    if fmt.accepts == "chain":
        if not isinstance(obj, KinematicChain | KinematicTree):
            raise InvalidTypeError(
                f"{fmt.suffix} files are made from a KinematicChain or a KinematicTree, got "
                f"{type(obj).__name__}"
            )
        return obj
    if isinstance(obj, KinematicTree):
        sheets = sum(1 for kids in obj.Children if not kids)
        raise InvalidTypeError(
            f"{fmt.suffix} files hold one crease pattern, but a KinematicTree is folded from "
            f"{sheets} sheet{'s' if sheets != 1 else ''} (one per leaf): export each sheet's "
            "pattern (kinegami.fabrication.sheets.fabricate(tree).sheets[k].pattern)"
        )
    if not isinstance(obj, KinematicChain | TubularPattern):
        from kinegami.pattern.cutout import CutPattern

        if isinstance(obj, CutPattern):  # a tree's sheet with take-off holes or a skirt
            return obj
        raise InvalidTypeError(
            f"{fmt.suffix} files are made from a TubularPattern or a KinematicChain, got "
            f"{type(obj).__name__}"
        )
    if fmt.accepts == "pattern" and isinstance(obj, KinematicChain):
        return obj.creasePattern(options.pop("twistPortion", 0.2))
    return obj


def _write(obj: Any, target: Path, options: dict[str, Any]) -> Path | list[Path]:
    fmt = FORMATS[target.suffix.lower()]
    options = dict(options)
    subject = _subject(obj, fmt, options)
    if options.get("bed") is not None:  # one file per bed sheet (docs/fabrication.md)
        if fmt.suffix not in BED_FORMATS:
            raise InvalidParameterError(
                f"bed applies to {' and '.join(BED_FORMATS)} files (one per bed sheet), not "
                f"{fmt.suffix}"
            )
        module, _, name = BED_WRITER.partition(":")  # by name, as the formats' exporters
        return getattr(importlib.import_module(module), name)(subject, target, **options)
    options.pop("bed", None)
    data = fmt.render(subject, target, **options)
    if fmt.kind == "files":
        write_atomic_files(target, data)
    else:
        write_atomic(target, data)
    return target


def export(obj: Any, path: str | os.PathLike, **options: Any) -> Path | list[Path]:
    """Write ``obj`` (a KinematicChain, KinematicTree or TubularPattern) to ``path`` in the
    suffix's format.

    Parameters
    ----------
    obj : KinematicChain, KinematicTree or TubularPattern
        Chains can be written in every format (pattern formats get
        ``chain.creasePattern(twistPortion)``); trees in the chain formats (``.stl``,
        ``.obj``, ``.urdf``); patterns in the pattern formats.
    path : str or os.PathLike
        Target file; missing parent folders are created and an existing file is replaced.
    **options
        Passed to the exporter (see :func:`known_formats` and each exporter's docstring);
        ``twistPortion`` (default 0.2) is used to make a chain's crease pattern. ``bed``
        (``.dxf`` and ``.svg``: ``"600x400"``, mm) cuts the sheet into pieces that fit that
        laser bed and writes one file per bed sheet, ``<stem>_bed_<m>.dxf``, with
        ``bed_margin`` (mm, default 5), ``tab`` (mm, default 10) and ``name`` (the pieces'
        labels; default the stem): :func:`kinegami.export.beds.save_on_beds`.

    Returns
    -------
    pathlib.Path or list of pathlib.Path
        The path written (for ``.urdf`` the URDF itself; its meshes are in
        ``<stem>_meshes/`` beside it); with ``bed``, every bed sheet's path.

    Raises
    ------
    InvalidParameterError
        For a missing or bad file name, an unknown suffix (the message lists the known ones)
        or a bad option value.
    BedTooSmallError
        With ``bed``: the sheet cannot be cut into pieces that fit (nothing is written).
    InvalidTypeError
        For an object the format cannot take, or an unknown option.
    ExporterUnavailableError
        If a library the format needs is not installed (the message says what to install).
    ExportError
        If the files cannot be written; nothing is left behind.

    Examples
    --------
    >>> from kinegami import export
    >>> export(chain, "out/robot.urdf", units="mm")  # doctest: +SKIP
    PosixPath('out/robot.urdf')
    >>> export(chain, "out/pattern.pdf", paper="Letter", scale=10)  # doctest: +SKIP
    PosixPath('out/pattern.pdf')
    """
    return _write(obj, _target(path), options)


def save_pattern(
    pattern: Any, dxfName: str | os.PathLike | None, **options: Any
) -> Path | list[Path]:
    """Save a crease pattern in the format of the file suffix (what ``pattern.save`` calls).

    Parameters
    ----------
    pattern : TubularPattern
        The pattern to write (a module or a whole chain).
    dxfName : str or os.PathLike
        Target file name (the paper's keyword; every suffix of a format that takes a pattern:
        ``.dxf``, ``.svg``, ``.fold``, ``.pdf``, ...). Missing parent folders are created; an
        existing file is replaced.
    **options
        Passed to the exporter, e.g. ``units``, ``scale``, ``perforate`` for the sheet formats,
        or ``bed="600x400"`` for one file per laser bed sheet (as for :func:`export`); see
        docs/fabrication.md and docs/exports.md.

    Returns
    -------
    pathlib.Path or list of pathlib.Path
        The path written (with ``bed``: every bed sheet's).

    Raises
    ------
    InvalidParameterError, InvalidTypeError, ExporterUnavailableError, ExportError
        As for :func:`export`; nothing is left behind.

    Examples
    --------
    >>> from kinegami.pattern import TubeFittingPattern
    >>> save_pattern(TubeFittingPattern(4, 10.0, 30.0), "out/tube.dxf")  # doctest: +SKIP
    PosixPath('out/tube.dxf')
    """
    from kinegami.pattern.tubular import TubularPattern

    if not isinstance(pattern, TubularPattern):
        raise InvalidTypeError(f"pattern must be a TubularPattern, got {type(pattern).__name__}")
    return _write(pattern, _target(dxfName, "save"), options)


# --- atomic writing ------------------------------------------------------------------------


def _temp_folder(parent: Path, name: str, tag: str) -> Path:
    for _ in range(100):
        candidate = parent / f".{name}.{os.urandom(4).hex()}.{tag}"
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
    from kinegami.export.publish import deferred_signals

    path = Path(path)
    groups = _split_files(path, files)
    parent = path.parent
    for head, content in groups.items():
        existing = parent / head
        if isinstance(content, dict) and existing.exists() and not existing.is_dir():
            raise ExportError(
                errno.ENOTDIR,
                f"cannot write the folder {head!r}: a file of that name exists",
                str(existing),
            )
        if not isinstance(content, dict) and existing.is_dir():
            raise ExportError(
                errno.EISDIR, f"cannot write {head!r}: a folder of that name exists", str(existing)
            )
    prepare_folder(path)
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
                    fd, tmp = create_temp(parent, head)
                    temps.append((head, Path(tmp)))
                    with os.fdopen(fd, "wb") as stream:
                        stream.write(content)
            order = sorted(temps, key=lambda item: item[0] == path.name)  # main file last
            # Ctrl-C, SIGTERM and SIGHUP wait until the moves are done or undone
            with deferred_signals() as received:
                try:
                    for head, tmp in order:
                        if received:
                            raise ExportError(
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
                        discard_tree(target)
                        if backup is not None:
                            os.replace(backup, target)
                    raise
        finally:
            for _, tmp in temps:
                if tmp.is_dir():
                    discard_tree(tmp)
                else:
                    discard(str(tmp))
    except OSError as exc:
        if isinstance(exc, KinegamiError):
            raise
        raise export_error(exc, path, "write failed") from exc
    for _, backup in moved:
        if backup is not None:
            discard_tree(backup)


# --- built-in formats ----------------------------------------------------------------------


def _register_builtin() -> None:
    register(
        ".dxf",
        "kinegami.export.dxf:dxf_data",
        "pattern",
        description="DXF R2013 of the flat sheet for laser cutters (mm; layers Mountain, "
        "Valley, Boundary, Cut)",
    )
    register(
        ".svg",
        "kinegami.export.svg:svg_data",
        "pattern",
        description="SVG of the flat sheet, true size in mm: for Origami Simulator (fold angles "
        "as opacity), or for cutting with flavour='laser'",
    )
    register(
        ".fold",
        "kinegami.export.fold:fold_data",
        "any",
        description="FOLD (JSON origami format) of the crease pattern",
    )
    register(
        ".pdf",
        "kinegami.export.pdf:pdf_data",
        "pattern",
        binary=True,
        description="PDF of the flat sheet at 1:1 tiled over A4 or Letter pages, with crop "
        "marks and a scale bar",
        extra="pdf",
    )
    register(
        ".stl",
        "kinegami.export.mesh:stl_data",
        "chain",
        binary=True,
        description="binary STL of the chain's 3D model in its current configuration (mm)",
        extra="mesh",
    )
    register(
        ".obj",
        "kinegami.export.mesh:obj_data",
        "chain",
        description="Wavefront OBJ of the chain's 3D model, one object per part (mm)",
        extra="mesh",
    )
    register(
        ".urdf",
        "kinegami.export.urdf:urdf_files",
        "chain",
        files=True,
        description="URDF robot model (metres) with STL meshes in <name>_meshes/",
        extra="mesh",
    )


_register_builtin()
