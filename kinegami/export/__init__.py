"""File formats for chains and crease patterns, in one registry (docs/exports.md).

``kinegami.export(obj, path, **options)`` (:func:`kinegami.export.registry.export`, also
importable from here) writes a chain or a pattern in the format the file suffix names: DXF,
SVG, FOLD, PDF, STL, OBJ, URDF. ``TubularPattern.save`` (:func:`save_pattern`) and
``kinegami build --formats`` use the same registry, so every format works from each of them.

One module per format, each with a function returning the file's data
(:func:`kinegami.export.dxf.dxf_data`, ...); :mod:`kinegami.export.registry` maps suffixes to
them and imports a format's module only when a file of that format is written. Every file is
written atomically by :func:`kinegami._atomic.write_atomic`. Import the format modules by
name: ``from kinegami.export import dxf`` or ``from kinegami.export.dxf import dxf_data``
(``kinegami.export`` itself, an attribute of the package ``kinegami``, is the function).
"""

from __future__ import annotations

from kinegami._atomic import discard, prepare_folder, write_atomic
from kinegami.errors import ExportError, ExporterUnavailableError
from kinegami.export.registry import (
    EXPORTERS,
    FORMATS,
    ExportFormat,
    export,
    known_formats,
    register,
    register_exporter,
    save_pattern,
    write_atomic_bytes,
    write_atomic_files,
)

__all__ = [
    "ExportError",
    "ExportFormat",
    "ExporterUnavailableError",
    "EXPORTERS",
    "FORMATS",
    "discard",
    "export",
    "known_formats",
    "prepare_folder",
    "register",
    "register_exporter",
    "save_pattern",
    "write_atomic",
    "write_atomic_bytes",
    "write_atomic_files",
]
