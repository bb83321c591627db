"""SVG export of the flat sheet (spec/patterns.md section 5), plain text, no extra dependency.

Colours follow Origami Simulator's import convention: mountain red ``#ff0000``, valley blue
``#0000ff``, cut green ``#00ff00``, boundary black ``#000000``. This is the reverse of the
paper's plots and of the DXF layer colours (valley red, mountain blue); ``colors=`` overrides it.

The drawing is in millimetres (``width``/``height`` in mm, one user unit of the ``viewBox`` =
1 mm); y is flipped (SVG's y axis points down) so the sheet reads as in the plot, proximal end at
the bottom, not mirrored. Each line is a ``<line>`` in one group per kind (ids Mountain, Valley,
Boundary, Cut) and carries its own ``stroke`` attribute.
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, TextIO
from xml.sax.saxutils import quoteattr

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.export._options import format_numbers, resolve_sheet_options, sheet_lines
from kinegami.pattern.sheet import SHEET_KINDS

if TYPE_CHECKING:  # pragma: no cover
    from kinegami.pattern.tubular import TubularPattern

__all__ = ["SVG_COLORS", "SVG_GROUPS", "write_svg"]

#: Origami Simulator's import colours (mountain red, valley blue: the reverse of the paper's).
SVG_COLORS = {"M": "#ff0000", "V": "#0000ff", "B": "#000000", "C": "#00ff00"}

#: Group id of each kind of line.
SVG_GROUPS = {"M": "Mountain", "V": "Valley", "B": "Boundary", "C": "Cut"}

_DEFAULT_STROKE_WIDTH = 0.1  # mm


def _check_colors(colors: Any) -> dict[str, str]:
    if colors is None:
        return dict(SVG_COLORS)
    if not isinstance(colors, dict):
        raise InvalidTypeError(f"colors must be a dict kind -> colour, got {colors!r}")
    unknown = sorted(set(colors) - set(SHEET_KINDS))
    if unknown:
        raise InvalidParameterError(
            f"colors keys must be among {SHEET_KINDS} (mountain, valley, boundary, cut), "
            f"got {unknown}"
        )
    for kind, value in colors.items():
        if not isinstance(value, str) or not value.strip():
            raise InvalidTypeError(f"colors[{kind!r}] must be a colour string, got {value!r}")
    merged = dict(SVG_COLORS)
    merged.update(colors)
    return merged


def write_svg(pattern: TubularPattern, stream: TextIO, **options: Any) -> None:
    """Write the sheet of ``pattern`` to a text stream as SVG (millimetres).

    Parameters
    ----------
    pattern : TubularPattern
        The pattern to write.
    stream : text stream
        Where the SVG text goes.
    units, scale, perforate, dash, gap, skip_creases_on_cut
        As for :func:`kinegami.export.dxf.write_dxf` (units of the pattern, lengths in mm).
    colors : dict, optional
        Colour per kind (``"M"``, ``"V"``, ``"B"``, ``"C"``) replacing :data:`SVG_COLORS`.
    stroke_width : float, optional
        Line width in mm (default 0.1).

    Raises
    ------
    InvalidTypeError, InvalidParameterError
        For an unknown option or a bad value (before anything is written).
    """
    opts = resolve_sheet_options(
        options, {"colors": None, "stroke_width": _DEFAULT_STROKE_WIDTH}, "SVG"
    )
    colors = _check_colors(opts.extra["colors"])
    stroke_width = opts.extra["stroke_width"]
    if isinstance(stroke_width, bool) or not isinstance(
        stroke_width, int | float | np.integer | np.floating
    ):
        raise InvalidTypeError(f"stroke_width must be a number, got {stroke_width!r}")
    if not (np.isfinite(stroke_width) and stroke_width > 0):
        raise InvalidParameterError(f"stroke_width must be finite and > 0, got {stroke_width!r}")
    segments, kinds, bounds = sheet_lines(pattern, opts)
    xmin, ymin, xmax, ymax = bounds
    extent = max(abs(v) for v in bounds) or 1.0
    flipped = segments.copy()
    flipped[:, :, 1] *= -1.0
    width, height = format_numbers(np.array([xmax - xmin, ymax - ymin]), extent)
    left, top = format_numbers(np.array([xmin, -ymax]), extent)
    stroke = format_numbers(np.array([float(stroke_width)]), 1.0)[0]
    out = [
        '<?xml version="1.0" encoding="UTF-8" standalone="no"?>\n',
        f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{width}mm" '
        f'height="{height}mm" viewBox="{left} {top} {width} {height}">\n',
        "<title>kinegami tubular crease pattern</title>\n",
    ]
    for kind in SHEET_KINDS:
        color = quoteattr(colors[kind])
        selected = flipped[kinds == kind]
        out.append(
            f'<g id="{SVG_GROUPS[kind]}" fill="none" stroke={color} stroke-width="{stroke}">\n'
        )
        numbers = format_numbers(selected.reshape(-1, 4), extent)
        for i in range(selected.shape[0]):
            x1, y1, x2, y2 = numbers[4 * i : 4 * i + 4]
            out.append(f'<line x1="{x1}" y1="{y1}" x2="{x2}" y2="{y2}" stroke={color}/>\n')
        out.append("</g>\n")
    out.append("</svg>\n")
    stream.write("".join(out))
