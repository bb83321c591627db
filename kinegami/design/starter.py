"""The starter design that ``kinegami new`` writes: a small chain that validates and builds.

It ships with the package as ``kinegami/design/starter.json``: a start tip, a revolute joint, a
prismatic joint and an end tip on a square tube of radius 10 mm (units mm, angles in degrees),
with a description saying what to change and how to check it.

>>> path = write_starter_design("my_robot.json")  # doctest: +SKIP
>>> chain = load_design(path)  # doctest: +SKIP
"""

from __future__ import annotations

import json
import os
import secrets
from importlib import resources
from pathlib import Path

from kinegami._atomic import discard, write_atomic
from kinegami.errors import DesignFileExistsError, InvalidParameterError
from kinegami.validation import check_bool

__all__ = [
    "DesignFileExistsError",
    "starter_document",
    "starter_text",
    "write_starter_design",
]


def starter_document(name: str | None = None) -> dict:
    """The starter design as a new JSON document, its ``name`` set to ``name`` if given."""
    text = resources.files("kinegami.design").joinpath("starter.json").read_text("utf-8")
    document = json.loads(text)
    if name is not None:
        document["name"] = name
    return document


def starter_text(name: str | None = None) -> str:
    """:func:`starter_document` as JSON text: one top-level key per line, one joint per line."""
    document = starter_document(name)
    lines = []
    for key, value in document.items():
        if key == "joints":
            joints = ",\n".join(f"    {json.dumps(joint, ensure_ascii=False)}" for joint in value)
            lines.append(f'  "joints": [\n{joints}\n  ]')
        else:
            lines.append(f"  {json.dumps(key)}: {json.dumps(value, ensure_ascii=False)}")
    return "{\n" + ",\n".join(lines) + "\n}\n"


def write_starter_design(path: str | os.PathLike, *, overwrite: bool = False) -> Path:
    """Write the starter design to ``path`` (a ``.json`` name), named after the file's stem.

    The file appears whole or not at all (written to a hidden file in the same folder, then
    linked or renamed into place); missing folders are created. An existing ``path`` is kept
    unless ``overwrite``, even if it appears while the file is written.

    Returns
    -------
    Path : the file written.

    Raises
    ------
    DesignFileExistsError : ``path`` exists and ``overwrite`` is False.
    InvalidParameterError : ``path`` does not end in ``.json``.
    InvalidTypeError : ``overwrite`` is not True or False.
    kinegami.export.ExportError : the file cannot be written (folder missing rights, disk full).
    """
    overwrite = check_bool("overwrite", overwrite)
    path = Path(path)
    if path.suffix.lower() != ".json" or not path.stem:
        raise InvalidParameterError(f"a design file name ends in .json, got {str(path)!r}")
    text = starter_text(path.stem)
    if overwrite:
        write_atomic(path, text)
        return path
    if os.path.lexists(path):
        raise _exists(path)
    hidden = path.with_name(f".{path.name}.{secrets.token_hex(4)}.new")
    write_atomic(hidden, text)
    try:
        try:
            os.link(hidden, path)  # fails if path exists, never replaces it
        except FileExistsError:
            raise _exists(path) from None
        except OSError:  # no hard links on this file system: rename, after one more check
            if os.path.lexists(path):
                raise _exists(path) from None
            os.replace(hidden, path)
    finally:
        discard(hidden)
    return path


def _exists(path: Path) -> DesignFileExistsError:
    return DesignFileExistsError(
        f"{str(path)!r} exists already; it was left as it is (overwrite=True replaces it)"
    )
