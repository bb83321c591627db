"""DXF export of the flat sheet (spec/patterns.md section 5), for laser cutters.

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

ezdxf builds the document (header, tables, layers, objects); the LINE entities are written by
:func:`write_dxf` as text straight into the ENTITIES section with handles reserved in the
document, which is about ten times faster than ``msp.add_line`` followed by ``saveas`` (5000
lines: ~20 ms instead of ~200 ms). :func:`dxf_document` builds the same drawing with ezdxf
entities, for users who want to edit it.
"""

from __future__ import annotations

import io
from typing import TYPE_CHECKING, Any, TextIO

import numpy as np

from kinegami.errors import KinegamiError
from kinegami.export._options import format_numbers, resolve_sheet_options, sheet_lines
from kinegami.pattern.sheet import SHEET_KINDS

if TYPE_CHECKING:  # pragma: no cover
    from ezdxf.document import Drawing

    from kinegami.pattern.tubular import TubularPattern

__all__ = ["LAYERS", "DXF_VERSION", "write_dxf", "dxf_document"]

#: Layer name and ACI colour for each kind of line.
LAYERS = {"M": ("Mountain", 5), "V": ("Valley", 1), "B": ("Boundary", 2), "C": ("Cut", 3)}

#: DXF version written (AutoCAD 2013).
DXF_VERSION = "R2013"

_INSUNITS_MM = 4
_MEASUREMENT_METRIC = 1


def _new_document(bounds: tuple[float, float, float, float]) -> Drawing:
    """An empty R2013 drawing in mm with the four layers and the sheet's extents."""
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
    """The sheet of ``pattern`` as an ezdxf drawing (same content as :func:`write_dxf`).

    Slower than :func:`write_dxf` (one ezdxf entity per line); use it to edit the drawing
    before saving it with ``doc.saveas(...)``.

    Parameters
    ----------
    pattern : TubularPattern
    **options
        As for :func:`write_dxf`.

    Returns
    -------
    ezdxf.document.Drawing
    """
    opts = resolve_sheet_options(options, {}, "DXF")
    segments, kinds, bounds = sheet_lines(pattern, opts)
    doc = _new_document(bounds)
    msp = doc.modelspace()
    for kind in SHEET_KINDS:
        name, color = LAYERS[kind]
        attribs = {"layer": name, "color": color}
        for (x0, y0), (x1, y1) in segments[kinds == kind].tolist():
            msp.add_line((x0, y0), (x1, y1), dxfattribs=attribs)
    return doc


def write_dxf(pattern: TubularPattern, stream: TextIO, **options: Any) -> None:
    """Write the sheet of ``pattern`` to a text stream as DXF R2013 (millimetres).

    Parameters
    ----------
    pattern : TubularPattern
        The pattern to write.
    stream : text stream
        Where the DXF text goes.
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
        Drop creases lying on the sheet's top or bottom edge (spec B10); default False.

    Raises
    ------
    InvalidTypeError, InvalidParameterError
        For an unknown option or a bad value (before anything is written).
    """
    opts = resolve_sheet_options(options, {}, "DXF")
    segments, kinds, bounds = sheet_lines(pattern, opts)
    doc = _new_document(bounds)
    owner = doc.modelspace().block_record_handle
    # let ezdxf create what it adds on write (app ids, metadata) before reserving handles
    doc.commit_pending_changes()
    doc.update_all()
    handles = doc.entitydb.handles
    count = segments.shape[0]
    first = int(str(handles), 16)
    handles.reset(f"{first + count:X}")  # reserve the handles of the LINEs ($HANDSEED after them)
    buffer = io.StringIO()
    doc.write(buffer)
    skeleton = buffer.getvalue()
    if int(str(handles), 16) != first + count:  # pragma: no cover - ezdxf allocated on write
        raise KinegamiError("ezdxf allocated handles while writing; cannot place the LINEs")
    marker = "  2\nENTITIES\n"
    cut = skeleton.index(marker) + len(marker)
    stream.write(skeleton[:cut])
    stream.write(_line_entities(segments, kinds, first, owner, bounds))
    stream.write(skeleton[cut:])


def _line_entities(
    segments: np.ndarray,
    kinds: np.ndarray,
    first_handle: int,
    owner: str,
    bounds: tuple[float, float, float, float],
) -> str:
    """The LINE entities as DXF text (group codes as ezdxf writes them)."""
    extent = max(abs(v) for v in bounds) or 1.0
    numbers = format_numbers(segments.reshape(-1, 4), extent)
    heads = {
        kind: f"330\n{owner}\n100\nAcDbEntity\n  8\n{name}\n 62\n{color}\n100\nAcDbLine\n 10\n"
        for kind, (name, color) in LAYERS.items()
    }
    parts = []
    append = parts.append
    for i, kind in enumerate(kinds.tolist()):
        x0, y0, x1, y1 = numbers[4 * i : 4 * i + 4]
        append(
            f"  0\nLINE\n  5\n{first_handle + i:X}\n{heads[kind]}{x0}\n 20\n{y0}\n 30\n0.0\n"
            f" 11\n{x1}\n 21\n{y1}\n 31\n0.0\n"
        )
    return "".join(parts)
