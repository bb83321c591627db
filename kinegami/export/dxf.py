"""DXF export of the flat sheet (docs/theory/patterns.md §5, docs/fabrication.md), for laser
cutters.

The file is DXF R2013 with four layers, each line a LINE entity on its layer with its colour also
set on the entity (laser programs often map entity colours to cut settings):

========  =================================  =========
layer     lines                              ACI colour
========  =================================  =========
Mountain  mountain folds                     5 (blue)
Valley    valley folds                       1 (red)
Boundary  the nominal tube, x in [0, W]      2 (yellow)
Cut       the sheet outline [-b/2, W + b/2]  3 (green)
========  =================================  =========

Units are millimetres (``$INSUNITS`` = 4, ``$MEASUREMENT`` = 1): one pattern unit (the unit of
the tube radius r) is written as 1 mm unless ``units`` or ``scale`` say otherwise. With
``perforate=True`` the fold lines are written as separate dash LINEs (many laser programs
ignore DXF line types).

The document skeleton (header, tables, layers, objects) is a template made once with ezdxf and
shipped as package data (``dxf_skeleton.json``, :func:`dxf_skeleton`): :func:`dxf_data` fills
in the sheet's extents,
the handle seed, new GUIDs and the time (with ``SOURCE_DATE_EPOCH`` set: that time, and GUIDs
made from the drawing, so equal sheets give equal files; :mod:`kinegami.export._reproducible`),
and writes the LINE entities as text straight into the ENTITIES section, with the handles the
template leaves free. So a DXF file is written
without importing ezdxf (the first save in a process: ~10 ms instead of ~350 ms), and the file
is the one ezdxf writes for the same drawing. :func:`dxf_document` builds the same drawing
with ezdxf entities, for users who want to edit it; :func:`make_skeleton` makes the skeleton
again (after an ezdxf upgrade: ``python -m kinegami.export.dxf``).
"""

from __future__ import annotations

import datetime
import functools
import io
import json
import os
import time
from typing import TYPE_CHECKING, Any, NamedTuple, TextIO

import numpy as np

from kinegami.errors import InvalidParameterError, KinegamiError
from kinegami.export._options import (
    LABEL_HEIGHT,
    bed_lines,
    check_label,
    format_numbers,
    resolve_sheet_options,
    sheet_lines,
)
from kinegami.export._reproducible import content_uuid, source_date_epoch
from kinegami.pattern.sheet import SHEET_KINDS

if TYPE_CHECKING:  # pragma: no cover
    from ezdxf.document import Drawing

    from kinegami.pattern.tubular import TubularPattern

__all__ = ["LAYERS", "DXF_VERSION", "dxf_data", "bed_dxf_data", "write_dxf", "dxf_document",
           "dxf_skeleton", "make_skeleton", "DxfSkeleton"]

#: Layer name and ACI colour for each kind of line.
LAYERS = {"M": ("Mountain", 5), "V": ("Valley", 1), "B": ("Boundary", 2), "C": ("Cut", 3)}

#: DXF version written (AutoCAD 2013).
DXF_VERSION = "R2013"

_INSUNITS_MM = 4
_MEASUREMENT_METRIC = 1

#: Bounds written into the template where the sheet's go (exact in binary and in decimal).
_SENTINEL_BOUNDS = (-111111.25, -222222.25, 333333.25, 444444.25)
_ENTITIES = "  2\nENTITIES\n"


def _new_document(bounds: tuple[float, float, float, float]) -> Drawing:
    """An empty R2013 drawing in mm with the four layers and the sheet's extents (ezdxf)."""
    import ezdxf

    doc = ezdxf.new(DXF_VERSION, setup=False, units=_INSUNITS_MM)
    doc.header["$MEASUREMENT"] = _MEASUREMENT_METRIC
    xmin, ymin, xmax, ymax = bounds
    layout = doc.modelspace().dxf  # ezdxf copies these into $EXTMIN ... $LIMMAX on write
    layout.extmin = (xmin, ymin, 0.0)
    layout.extmax = (xmax, ymax, 0.0)
    layout.limmin = (xmin, ymin)
    layout.limmax = (xmax, ymax)
    for kind in SHEET_KINDS:
        name, color = LAYERS[kind]
        doc.layers.add(name, color=color, linetype="Continuous")
    return doc


def dxf_document(pattern: TubularPattern, **options: Any) -> Drawing:
    """The sheet of ``pattern`` as an ezdxf drawing (same content as :func:`dxf_data`).

    Slower than :func:`dxf_data` (imports ezdxf, one ezdxf entity per line); use it to edit
    the drawing before saving it with ``doc.saveas(...)``.

    Parameters
    ----------
    pattern : TubularPattern
    **options
        As for :func:`dxf_data`.

    Returns
    -------
    ezdxf.document.Drawing

    Raises
    ------
    ExporterUnavailableError
        If ezdxf is not installed.
    """
    from kinegami.export.registry import import_library

    import_library("ezdxf", "dxf_document", "dxf")
    opts = resolve_sheet_options(options, {"label": None}, "DXF")
    label = check_label(opts.extra["label"])
    segments, kinds, bounds = sheet_lines(pattern, opts)
    doc = _new_document(bounds)
    msp = doc.modelspace()
    for kind in SHEET_KINDS:
        name, color = LAYERS[kind]
        attribs = {"layer": name, "color": color}
        for (x0, y0), (x1, y1) in segments[kinds == kind].tolist():
            msp.add_line((x0, y0), (x1, y1), dxfattribs=attribs)
    if label:
        msp.add_text(label, height=LABEL_HEIGHT,
                     dxfattribs={"layer": "0", "insert": _label_point(bounds)})  # fmt: skip
    return doc


def dxf_data(pattern: TubularPattern, **options: Any) -> str:
    """The sheet of ``pattern`` as DXF R2013 text (millimetres).

    Parameters
    ----------
    pattern : TubularPattern
        The pattern to write.
    units : {'mm', 'cm', 'm', 'in'}, optional
        Length of one pattern unit; default ``'mm'``.
    scale : float, optional
        Extra multiplier: one pattern unit is ``scale`` times ``units`` (default 1).
    perforate : bool, optional
        Write the fold lines (mountain and valley, never boundary or cut) as dashes; implied by
        ``dash`` or ``gap``.
    dash, gap : float, optional
        Dash and gap lengths in mm (default 1 and 1); the last dash of a line may be shorter.
    skip_creases_on_cut : bool, optional
        Drop creases lying on the sheet's top or bottom edge (B10, docs/theory/patterns.md
        §6); default False.
    label : str, optional
        One line of text written below the sheet (TEXT on layer 0, 3 mm high), for example
        which sheet of a tree this is; default none.

    Raises
    ------
    InvalidTypeError, InvalidParameterError
        For an unknown option or a bad value.

    Examples
    --------
    >>> from kinegami.pattern import TubeFittingPattern
    >>> dxf_data(TubeFittingPattern(4, 10.0, 30.0)).split()[:2]
    ['0', 'SECTION']
    """
    opts = resolve_sheet_options(options, {"label": None}, "DXF")
    label = check_label(opts.extra["label"])
    segments, kinds, bounds = sheet_lines(pattern, opts)
    texts = []
    if label:  # one TEXT entity on layer 0, below the sheet, after the lines
        texts.append(_Text(label, *_label_point(bounds), LABEL_HEIGHT, 0.0, "0", None))
    return _document(segments, kinds, bounds, texts, repr((bounds, label)).encode())


def bed_dxf_data(layout, index: int, **options: Any) -> str:
    """Bed sheet ``index`` (from 0) of a :class:`~kinegami.fabrication.beds.BedLayout` as DXF
    R2013 text (mm, the bed's corner at the origin): every piece on it where the layout puts
    it, with its marks (join line and alignment ticks) on the Boundary layer and its labels as
    TEXT on the Boundary layer, turned with the piece (docs/fabrication.md, "Laser bed").

    Parameters
    ----------
    layout : BedLayout
    index : int
    perforate, dash, gap, skip_creases_on_cut
        As for :func:`dxf_data` (the layout fixes the units).

    Raises
    ------
    InvalidTypeError, InvalidParameterError
        For an unknown option or a bad value.
    """
    opts = resolve_sheet_options(options, {}, "DXF bed sheet")
    if "units" in options or "scale" in options:
        raise InvalidParameterError("units and scale are the layout's (lay_out(..., unit=)); "
                                    "a bed sheet takes neither")  # fmt: skip
    segments, kinds, texts, bounds = bed_lines(layout, index, opts)
    name, color = LAYERS["B"]
    placed = [_Text(t.text, t.x, t.y, t.height, t.angle, name, color) for t in texts]
    return _document(segments, kinds, bounds, placed, repr((bounds, placed)).encode())


class _Text(NamedTuple):
    text: str
    x: float
    y: float
    height: float
    angle: float  # degrees, counter-clockwise
    layer: str
    color: int | None


def _text_entity(text: _Text, handle: int, owner: str) -> str:
    """One TEXT entity, group codes as ezdxf writes them."""
    x, y, height = (repr(float(v)) for v in (text.x, text.y, text.height))
    color = "" if text.color is None else f" 62\n{text.color}\n"
    angle = "" if not text.angle else f" 50\n{float(text.angle)!r}\n"
    return (f"  0\nTEXT\n  5\n{handle:X}\n330\n{owner}\n100\nAcDbEntity\n  8\n{text.layer}\n"
            f"{color}100\nAcDbText\n 10\n{x}\n 20\n{y}\n 30\n0.0\n 40\n{height}\n"
            f"  1\n{text.text}\n{angle}100\nAcDbText\n")  # fmt: skip


def _document(segments: np.ndarray, kinds: np.ndarray, bounds: tuple, texts: list[_Text],
              fingerprint: bytes) -> str:  # fmt: skip
    """The DXF text of lines and texts in the skeleton; ``fingerprint`` (with the lines) makes
    the GUIDs under SOURCE_DATE_EPOCH."""
    template = dxf_skeleton()
    count = segments.shape[0]
    entities = _line_entities(segments, kinds, template.first_handle, template.owner, bounds)
    for text in texts:  # after the lines, as ezdxf writes them
        entities += _text_entity(text, template.first_handle + count, template.owner)
        count += 1
    xmin, ymin, xmax, ymax = (repr(float(v)) for v in bounds)
    epoch = source_date_epoch()
    if epoch is None:  # as ezdxf writes a file: the time now and new GUIDs
        seconds = time.time()
        fingerprint, version = _guid(), _guid()
    else:  # SOURCE_DATE_EPOCH: that time, and GUIDs made from the drawing
        seconds = float(epoch)
        drawing = b"".join((segments.tobytes(), kinds.tobytes(), fingerprint))
        fingerprint, version = (f"{{{content_uuid(drawing, tag).upper()}}}"
                                for tag in ("FINGERPRINTGUID", "VERSIONGUID"))  # fmt: skip
    now = datetime.datetime.fromtimestamp(seconds, datetime.UTC)
    # as ezdxf and AutoCAD write $TDCREATE: the Julian day number (2440588 on 1970-01-01) plus
    # the fraction of the day since midnight (not the astronomical Julian date, half a day less).
    # seconds count from 1970-01-01 UTC (time.time() or SOURCE_DATE_EPOCH), never local time,
    # so this is the UTC time that $TDUCREATE and $TDUUPDATE hold, and $TDCREATE and $TDUPDATE
    # get the same value (a file does not depend on the time zone of the machine writing it)
    julian = 2440588.0 + seconds / 86400.0
    fields = {
        "XMIN": xmin,
        "YMIN": ymin,
        "XMAX": xmax,
        "YMAX": ymax,
        "HANDSEED": f"{template.first_handle + count:X}",
        "FINGERPRINTGUID": fingerprint,
        "VERSIONGUID": version,
        "TDCREATE": repr(julian),
        "TDUCREATE": repr(julian),
        "TDUPDATE": repr(julian),
        "TDUUPDATE": repr(julian),
        "CREATED": f"{template.ezdxf_version} @ {now.isoformat()}",
        "WRITTEN": f"{template.ezdxf_version} @ {now.isoformat()}",
        "ENTITIES": entities,
    }
    parts = list(template.parts)
    for i in range(1, len(parts), 2):
        parts[i] = fields[parts[i]]
    return "".join(parts)


def _label_point(bounds: tuple) -> tuple[float, float]:
    """Where a label starts: below the sheet's lower left corner (mm)."""
    xmin, ymin = float(bounds[0]), float(bounds[1])
    return (xmin, ymin - 2.0 * LABEL_HEIGHT)


def write_dxf(pattern: TubularPattern, stream: TextIO, **options: Any) -> None:
    """Write :func:`dxf_data` of ``pattern`` to a text stream (options as there)."""
    stream.write(dxf_data(pattern, **options))


def _guid() -> str:
    """A random GUID (UUID version 4) as DXF writes them: ``{XXXXXXXX-XXXX-...}``."""
    raw = bytearray(os.urandom(16))
    raw[6] = raw[6] & 0x0F | 0x40  # version 4
    raw[8] = raw[8] & 0x3F | 0x80  # RFC 4122 variant
    h = raw.hex().upper()
    return f"{{{h[:8]}-{h[8:12]}-{h[12:16]}-{h[16:20]}-{h[20:]}}}"


def _line_entities(
    segments: np.ndarray,
    kinds: np.ndarray,
    first_handle: int,
    owner: str,
    bounds: tuple[float, float, float, float],
) -> str:
    """The LINE entities as DXF text (group codes as ezdxf writes them)."""
    count = segments.shape[0]
    if count == 0:
        return ""
    extent = max(abs(v) for v in bounds) or 1.0
    numbers = format_numbers(segments.reshape(-1, 4), extent)
    heads = {
        kind: f"\n330\n{owner}\n100\nAcDbEntity\n  8\n{name}\n 62\n{color}\n100\nAcDbLine\n 10\n"
        for kind, (name, color) in LAYERS.items()
    }
    # one list of pieces, filled a field at a time (str.join of it is the fastest way)
    pieces: list[str] = [""] * (11 * count)
    pieces[0::11] = ["  0\nLINE\n  5\n"] * count
    pieces[1::11] = map("%X".__mod__, range(first_handle, first_handle + count))
    pieces[2::11] = map(heads.__getitem__, kinds.tolist())
    pieces[3::11] = numbers[0::4]
    pieces[4::11] = ["\n 20\n"] * count
    pieces[5::11] = numbers[1::4]
    pieces[6::11] = ["\n 30\n0.0\n 11\n"] * count
    pieces[7::11] = numbers[2::4]
    pieces[8::11] = ["\n 21\n"] * count
    pieces[9::11] = numbers[3::4]
    pieces[10::11] = ["\n 31\n0.0\n"] * count
    return "".join(pieces)


# --- the template ----------------------------------------------------------------------------


def _ezdxf_skeleton(bounds: tuple[float, float, float, float], count: int) -> tuple[str, int, str]:
    """The text ezdxf writes for an empty drawing with ``count`` handles reserved after its
    own; returns (text, first free handle, modelspace block record handle)."""
    doc = _new_document(bounds)
    owner = doc.modelspace().block_record_handle
    # let ezdxf create what it adds on write (app ids, metadata) before reserving handles
    doc.commit_pending_changes()
    doc.update_all()
    handles = doc.entitydb.handles
    first = int(str(handles), 16)
    handles.reset(f"{first + count:X}")  # the LINEs' handles; $HANDSEED after them
    buffer = io.StringIO()
    doc.write(buffer)
    if int(str(handles), 16) != first + count:  # pragma: no cover - ezdxf allocated on write
        raise KinegamiError("ezdxf allocated handles while writing; cannot place the LINEs")
    return buffer.getvalue(), first, owner


def _replace_value(text: str, name: str, code: str, field: str) -> str:
    """Replace the value after header variable ``name`` and group ``code`` by ``@@field@@``."""
    start = text.index(f"  9\n{name}\n")
    at = text.index(f"{code}\n", start) + len(code) + 1
    end = text.index("\n", at)
    return text[:at] + f"@@{field}@@" + text[end:]


def _source_lines(text: str) -> str:
    """``text`` as Python string literals, one group (code and value) per line."""
    pieces = text.split("\n")
    groups = ["\n".join(pieces[i : i + 2]) for i in range(0, len(pieces), 2)]
    literals = [repr(g + "\n") for g in groups[:-1]] + ([repr(groups[-1])] if groups[-1] else [])
    return "    (\n" + "\n".join(f"        {s}" for s in literals) + "\n    )"


#: The package data file holding the skeleton (kinegami/export/dxf_skeleton.json).
SKELETON_FILE = "dxf_skeleton.json"


class DxfSkeleton(NamedTuple):
    """The DXF R2013 document ezdxf writes for an empty drawing, as :func:`dxf_data` fills it
    in: ``parts`` alternates text and the names of the fields it fills (extents, handle seed,
    GUIDs, times, the ENTITIES section's content); ``first_handle`` is the first free handle
    (the LINEs'), ``owner`` the modelspace block record's handle, ``ezdxf_version`` the ezdxf
    that wrote it."""

    ezdxf_version: str
    first_handle: int
    owner: str
    parts: tuple[str, ...]


@functools.cache
def dxf_skeleton() -> DxfSkeleton:
    """The skeleton shipped with the package (read once; see :func:`make_skeleton`)."""
    # read through this module's loader, as pkgutil.get_data does (also from a zip), without
    # the imports importlib.resources pays (15 ms, more than the rest of a first save)
    path = os.path.join(os.path.dirname(__spec__.origin), SKELETON_FILE)
    data = json.loads(__spec__.loader.get_data(path).decode("utf-8"))
    text = "\n".join(data["lines"])
    return DxfSkeleton(data["ezdxf"], int(data["first_handle"], 16), data["owner"],
                       tuple(text.split("@@")))  # fmt: skip


def make_skeleton() -> str:
    """The text of the skeleton file (JSON, one line of DXF text per line), made with the
    installed ezdxf: ``python -m kinegami.export.dxf`` writes it after an ezdxf upgrade, and a
    test fails when the shipped file differs from what the installed ezdxf writes."""
    import ezdxf

    text, first, owner = _ezdxf_skeleton(_SENTINEL_BOUNDS, 0)
    for value, field in zip(_SENTINEL_BOUNDS, ("XMIN", "YMIN", "XMAX", "YMAX"), strict=True):
        text = text.replace(f"\n{value!r}\n", f"\n@@{field}@@\n")
    variables = (("$HANDSEED", "  5"), ("$FINGERPRINTGUID", "  2"), ("$VERSIONGUID", "  2"),
                 ("$TDCREATE", " 40"), ("$TDUCREATE", " 40"), ("$TDUPDATE", " 40"),
                 ("$TDUUPDATE", " 40"))  # fmt: skip
    for name, code in variables:
        text = _replace_value(text, name, code, name[1:])
    for key, field in (("CREATED_BY_EZDXF", "CREATED"), ("WRITTEN_BY_EZDXF", "WRITTEN")):
        start = text.index(f"\n{key}\n")
        at = text.index(f"\n{ezdxf.__version__} @ ", start) + 1
        text = text[:at] + f"@@{field}@@" + text[text.index("\n", at):]
    cut = text.index(_ENTITIES) + len(_ENTITIES)
    text = text[:cut] + "@@ENTITIES@@" + text[cut:]
    data = {
        "format": "kinegami-dxf-skeleton",
        "about": "The DXF R2013 document ezdxf writes for an empty drawing; @@NAME@@ marks "
                 "what kinegami.export.dxf.dxf_data fills in. Made by python -m "
                 "kinegami.export.dxf; do not edit.",
        "ezdxf": ezdxf.__version__,
        "first_handle": f"{first:X}",
        "owner": owner,
        "lines": text.split("\n"),
    }
    return json.dumps(data, indent=0, ensure_ascii=False) + "\n"


if __name__ == "__main__":  # pragma: no cover - python -m kinegami.export.dxf
    from pathlib import Path

    from kinegami._atomic import write_atomic

    target = Path(__file__).with_name(SKELETON_FILE)
    write_atomic(target, make_skeleton())
    print(f"wrote {target}")
