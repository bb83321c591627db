"""Files of a sheet laid out on laser beds: one DXF or SVG per bed sheet (docs/fabrication.md,
"Laser bed").

``export(chain, "out/arm.dxf", bed="600x400")`` (or ``pattern.save(...)``) cuts the sheet into
pieces that fit the bed, nests them onto bed sheets (:func:`kinegami.fabrication.beds.lay_out`)
and writes ``out/arm_bed_1.dxf``, ``out/arm_bed_2.dxf``, ... as one transaction
(:mod:`kinegami.export.publish`), removing any ``arm_bed_<m>.dxf`` of an earlier save with more
beds; it returns every path written. ``kinegami build --bed`` writes the same files.
"""

from __future__ import annotations

import os
import re
from pathlib import Path
from typing import Any

from kinegami._atomic import export_error
from kinegami.errors import InvalidParameterError, KinegamiError
from kinegami.export._options import unit_factor
from kinegami.export.registry import BED_FORMATS
from kinegami.fabrication.beds import Bed, BedLayout, lay_out, parse_bed

__all__ = [
    "BED_FORMATS",
    "BED_OPTIONS",
    "bed_file_name",
    "bed_files",
    "save_on_beds",
    "stale_bed_files",
]

#: The save options that lay a sheet out on beds (the rest go to the format's writer).
BED_OPTIONS = ("bed", "bed_margin", "tab", "name", "units", "scale")


def bed_file_name(stem: str, suffix: str, index: int) -> str:
    """``<stem>_bed_<index + 1><suffix>`` (beds are numbered from 1 in file names)."""
    return f"{stem}_bed_{index + 1}{suffix}"


def bed_files(layout: BedLayout, stem: str, suffix: str, **options: Any) -> dict[str, str]:
    """Every bed sheet's file, by name: ``{"<stem>_bed_1.dxf": text, ...}``.

    ``options`` go to :func:`kinegami.export.dxf.bed_dxf_data` or
    :func:`kinegami.export.svg.bed_svg_data` (perforation, colours, ...).
    """
    suffix = suffix.lower()
    if suffix == ".dxf":
        from kinegami.export.dxf import bed_dxf_data as data
    elif suffix == ".svg":
        from kinegami.export.svg import bed_svg_data as data
    else:
        raise InvalidParameterError(
            f"files per bed sheet are {' and '.join(BED_FORMATS)}, got {suffix!r}"
        )
    return {bed_file_name(stem, suffix, m): data(layout, m, **options)
            for m in range(layout.count)}  # fmt: skip


def stale_bed_files(folder: str | os.PathLike, stem: str, suffix: str,
                    keep: set[str] | frozenset[str] = frozenset()) -> list[str]:  # fmt: skip
    """The files ``<stem>_bed_<m><suffix>`` in ``folder`` that are not in ``keep``: what an
    earlier save with more beds left."""
    pattern = re.compile(re.escape(stem) + r"_bed_[1-9][0-9]*" + re.escape(suffix) + r"\Z")
    try:
        names = os.listdir(folder)
    except FileNotFoundError:
        return []
    return sorted(n for n in names if pattern.match(n) and n not in keep
                  and os.path.isfile(os.path.join(folder, n)))  # fmt: skip


def save_on_beds(pattern, path: Path, **options: Any) -> list[Path]:
    """Write ``pattern`` laid out on beds as ``<stem>_bed_<m><suffix>`` beside ``path``, all
    or nothing, removing the stale ones; return every path written (what :func:`kinegami.export`
    does when given ``bed=``).

    Options: ``bed`` (``"WxH"`` or (width, height), mm), ``bed_margin`` (mm, default 5),
    ``tab`` (mm, default 10), ``name`` (what the labels call the design; default the file
    stem), ``units`` and ``scale`` (as for the sheet formats); the rest go to the format's
    bed-sheet writer.

    Raises
    ------
    BedTooSmallError
        When the sheet cannot be cut into pieces that fit (nothing is written).
    InvalidParameterError, InvalidTypeError, ExportError
        As for any export; nothing is written.
    """
    from kinegami.export.publish import staging_folder

    path = Path(path)
    suffix = path.suffix.lower()
    width, height = parse_bed(options.pop("bed"))
    bed = Bed.of(width, height, options.pop("bed_margin", None), options.pop("tab", None))
    unit = unit_factor(options.pop("units", "mm"), options.pop("scale", 1.0))
    name = options.pop("name", None)
    layout = lay_out(pattern, bed, unit=unit, name=path.stem if name is None else name)
    files = bed_files(layout, path.stem, suffix, **options)
    folder = path.parent
    try:
        with staging_folder(folder) as staging:
            for file_name, text in files.items():
                (staging.new / file_name).write_text(text, encoding="utf-8")
            stale = stale_bed_files(folder, path.stem, suffix, set(files))
            return staging.publish(remove=stale)
    except OSError as error:
        if isinstance(error, KinegamiError):
            raise
        raise export_error(error, path, "write failed") from error
