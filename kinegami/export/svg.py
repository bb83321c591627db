"""SVG export of the flat sheet, in two flavours (docs/fabrication.md); plain text.

``flavour="simulator"`` (the default) is a crease pattern for Origami Simulator: the planar graph
of the FOLD export (:func:`kinegami.export.fold.sheet_graph`: the same vertices, edges and fold
angles, no point that only splits a straight line, no face with a straight corner) drawn in the
simulator's import convention:

* the sheet outline black ``#000000`` (the simulator's border), mountains red ``#ff0000``,
  valleys blue ``#0000ff``, flat lines yellow ``#ffff00`` (the simulator's facet lines: the
  diagonals that split a face with a straight corner, and creases whose fold angle in the
  folded form is 0, because the simulator reads an opacity of 0 as no target angle at all);
* the fold angle as the line's ``stroke-opacity``: |fold angle| / 180 degrees (0.5 is a
  90 degree fold), the folded form at joint state 0 being the target;
* a user unit of 10^-k mm, small enough that the simulator's vertex merge tolerance (3 user
  units by default) is at most a tenth of the smallest distance between two vertices or between
  a vertex and an edge it is not on; ``width`` and ``height`` keep the true size in mm;
* y negated (SVG's y axis points down), so the sheet reads as in the plot, printed side up,
  proximal end at the bottom; in this orientation the simulator folds the same tube as from
  the FOLD file (negating x as well would fold its mirror image).

``flavour="laser"`` is the sheet of the DXF export (:func:`kinegami.pattern.sheet.flatten`) for
cutters and vector editors: mountain red, valley blue, the nominal tube's boundary black and the
sheet outline green ``#00ff00`` (a cut; Origami Simulator reads green as slits, so this flavour
falls apart there), optional perforation, one user unit = 1 mm, y flipped so the sheet reads as
in the plot (proximal end at the bottom, printed side up). ``colors=`` overrides its colours.

Each line is a ``<line>`` in one group per kind and carries its own ``stroke``.
"""

from __future__ import annotations

import io
import math
from typing import TYPE_CHECKING, Any, TextIO
from xml.sax.saxutils import escape, quoteattr

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.export._options import (
    LABEL_HEIGHT,
    bed_lines,
    check_label,
    format_numbers,
    resolve_sheet_options,
    sheet_lines,
    unit_factor,
)
from kinegami.pattern.sheet import SHEET_KINDS
from kinegami.validation import check_options, check_positive

if TYPE_CHECKING:  # pragma: no cover
    from kinegami.pattern.tubular import TubularPattern

__all__ = [
    "SVG_FLAVOURS",
    "SVG_COLORS",
    "SVG_GROUPS",
    "SIMULATOR_COLORS",
    "SIMULATOR_GROUPS",
    "SIMULATOR_MERGE_TOLERANCE",
    "simulator_unit",
    "svg_data",
    "bed_svg_data",
    "write_svg",
]

#: The two kinds of SVG file: for Origami Simulator (default) and for laser cutting.
SVG_FLAVOURS = ("simulator", "laser")

#: Colours of the laser flavour (mountain red, valley blue: the reverse of the paper's plots).
SVG_COLORS = {"M": "#ff0000", "V": "#0000ff", "B": "#000000", "C": "#00ff00"}

#: Group id of each kind of line in the laser flavour.
SVG_GROUPS = {"M": "Mountain", "V": "Valley", "B": "Boundary", "C": "Cut"}

#: Colours of the simulator flavour: Origami Simulator's border, mountain, valley, facet.
SIMULATOR_COLORS = {"B": "#000000", "M": "#ff0000", "V": "#0000ff", "F": "#ffff00"}

#: Group id of each kind of line in the simulator flavour.
SIMULATOR_GROUPS = {"B": "Outline", "M": "Mountain", "V": "Valley", "F": "Flat"}

#: Origami Simulator's default vertex merge tolerance, in SVG user units.
SIMULATOR_MERGE_TOLERANCE = 3.0

#: The smallest distance in the drawing is at least this many merge tolerances.
_MERGE_MARGIN = 10.0

_DEFAULT_STROKE_WIDTH = 0.1  # mm
_LASER_ONLY = ("perforate", "dash", "gap", "skip_creases_on_cut", "colors")
_SIMULATOR_OPTIONS = ("units", "scale", "stroke_width", "flavour", "label")


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


def _title(title: str, label: str | None) -> str:
    return escape(title if not label else f"{label} ({title})")


def _stroke_width(value: Any) -> float:
    return check_positive("stroke_width", value)


def svg_data(pattern: TubularPattern, **options: Any) -> str:
    """The sheet of ``pattern`` as SVG text (true size in mm); options as for :func:`write_svg`.

    Raises as :func:`write_svg` does.
    """
    stream = io.StringIO()
    write_svg(pattern, stream, **options)
    return stream.getvalue()


def write_svg(pattern: TubularPattern, stream: TextIO, **options: Any) -> None:
    """Write the sheet of ``pattern`` to a text stream as SVG (true size in mm).

    Parameters
    ----------
    pattern : TubularPattern
        The pattern to write. The simulator flavour needs a pattern made of catalog modules
        (for example ``chain.creasePattern()``), whose folded form gives the fold angles.
    stream : text stream
        Where the SVG text goes.
    flavour : {'simulator', 'laser'}, optional
        ``'simulator'`` (default): for Origami Simulator (module docstring); ``'laser'``: the
        DXF's sheet for cutting, outline as cut.
    units, scale
        Length of one pattern unit (``'mm'``, ``'cm'``, ``'m'``, ``'in'``) and an extra factor,
        as for :func:`kinegami.export.dxf.write_dxf`.
    stroke_width : float, optional
        Line width in mm (default 0.1).
    label : str, optional
        One line of text naming the sheet: in the title, and in the laser flavour also as text
        below the sheet (3 mm high); default none.
    perforate, dash, gap, skip_creases_on_cut, colors
        Laser flavour only: as for :func:`kinegami.export.dxf.write_dxf`; ``colors`` maps a
        kind (``"M"``, ``"V"``, ``"B"``, ``"C"``) to a colour replacing :data:`SVG_COLORS`.

    Raises
    ------
    InvalidTypeError, InvalidParameterError
        For an unknown option, a bad value, or a laser option with the simulator flavour
        (before anything is written).
    FoldedFormError
        Simulator flavour: for a pattern without module records (use ``flavour='laser'``).
    """
    flavour = options.get("flavour", "simulator")
    if flavour not in SVG_FLAVOURS:
        raise InvalidParameterError(
            f"flavour must be one of {', '.join(map(repr, SVG_FLAVOURS))}, got {flavour!r}"
        )
    if flavour == "laser":
        _write_laser(pattern, stream, {k: v for k, v in options.items() if k != "flavour"})
    else:
        _write_simulator(pattern, stream, options)


# --- laser flavour ---------------------------------------------------------------------------


def _write_laser(pattern, stream: TextIO, options: dict[str, Any]) -> None:
    opts = resolve_sheet_options(
        options, {"colors": None, "stroke_width": _DEFAULT_STROKE_WIDTH, "label": None}, "SVG"
    )
    label = check_label(opts.extra["label"])
    colors = _check_colors(opts.extra["colors"])
    stroke_width = _stroke_width(opts.extra["stroke_width"])
    segments, kinds, bounds = sheet_lines(pattern, opts)
    xmin, ymin, xmax, ymax = bounds
    text_y = ymin - 1.5 * LABEL_HEIGHT  # the label's baseline, below the sheet (mm)
    if label:
        ymin = ymin - 2.5 * LABEL_HEIGHT  # the drawing takes the label in
    extent = max(abs(v) for v in bounds) or 1.0
    flipped = segments.copy()
    flipped[:, :, 1] *= -1.0
    width, height = format_numbers(np.array([xmax - xmin, ymax - ymin]), extent)
    left, top = format_numbers(np.array([xmin, -ymax]), extent)
    stroke = format_numbers(np.array([stroke_width]), 1.0)[0]
    out = [
        '<?xml version="1.0" encoding="UTF-8" standalone="no"?>\n',
        f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{width}mm" '
        f'height="{height}mm" viewBox="{left} {top} {width} {height}">\n',
        f"<title>{_title('kinegami tubular crease pattern (laser cutting)', label)}</title>\n",
    ]
    out += _line_groups(flipped, kinds, colors, stroke, extent)
    if label:  # below the sheet's lower edge, inside the drawing's width
        size = format_numbers(np.array([LABEL_HEIGHT]), 1.0)[0]
        x, y = format_numbers(np.array([xmin, -text_y]), extent)
        out.append(f'<text id="label" x="{x}" y="{y}" font-family="sans-serif" '
                   f'font-size="{size}" fill="black" stroke="none">{escape(label)}</text>\n')
    out.append("</svg>\n")
    stream.write("".join(out))


def _line_groups(flipped: np.ndarray, kinds: np.ndarray, colors: dict[str, str], stroke: str,
                 extent: float) -> list[str]:  # fmt: skip
    """The laser flavour's lines (y already flipped): one group per kind, each line with its
    own stroke."""
    out = []
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
    return out


def bed_svg_data(layout, index: int, **options: Any) -> str:
    """Bed sheet ``index`` (from 0) of a :class:`~kinegami.fabrication.beds.BedLayout` as a
    laser flavour SVG (the bed's size in mm, one user unit = 1 mm): every piece where the
    layout puts it, its marks (join line, alignment ticks) with the Boundary lines, and its
    labels as text in the Boundary colour, turned with the piece.

    Parameters
    ----------
    layout : BedLayout
    index : int
    perforate, dash, gap, skip_creases_on_cut, colors, stroke_width
        As for the laser flavour of :func:`write_svg` (the layout fixes the units);
        ``flavour`` may only be ``'laser'`` (a bed sheet is for cutting).
    title : str, optional
        The document's title (default "kinegami bed sheet k of m").

    Raises
    ------
    InvalidTypeError, InvalidParameterError
        For an unknown option or a bad value.
    """
    options = dict(options)
    flavour = options.pop("flavour", "laser")
    if flavour != "laser":
        raise InvalidParameterError(
            f"flavour must be 'laser' for a bed sheet (it is for cutting; Origami Simulator "
            f"takes a piece's own pattern), got {flavour!r}"
        )
    if "units" in options or "scale" in options:
        raise InvalidParameterError("units and scale are the layout's (lay_out(..., unit=)); "
                                    "a bed sheet takes neither")  # fmt: skip
    title = options.pop("title", None)
    opts = resolve_sheet_options(
        options, {"colors": None, "stroke_width": _DEFAULT_STROKE_WIDTH}, "SVG bed sheet"
    )
    colors = _check_colors(opts.extra["colors"])
    stroke = format_numbers(np.array([_stroke_width(opts.extra["stroke_width"])]), 1.0)[0]
    segments, kinds, texts, bounds = bed_lines(layout, index, opts)
    title = check_label(title) or f"kinegami bed sheet {index + 1} of {layout.count}"
    _, _, width_mm, height_mm = bounds
    extent = max(width_mm, height_mm) or 1.0
    flipped = segments.copy()
    flipped[:, :, 1] *= -1.0
    width, height = format_numbers(np.array([width_mm, height_mm]), extent)
    (top,) = format_numbers(np.array([-height_mm]), extent)
    out = [
        '<?xml version="1.0" encoding="UTF-8" standalone="no"?>\n',
        f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{width}mm" '
        f'height="{height}mm" viewBox="0 {top} {width} {height}">\n',
        f"<title>{_title(title + ' (laser cutting)', None)}</title>\n",
    ]
    out += _line_groups(flipped, kinds, colors, stroke, extent)
    color = quoteattr(colors["B"])
    out.append(f'<g id="Labels" font-family="sans-serif" fill={color} stroke="none">\n')
    for text in texts:
        x, y, size = format_numbers(np.array([text.x, -text.y, text.height]), extent)
        turn = f' transform="rotate({-text.angle!r} {x} {y})"' if text.angle else ""
        out.append(f'<text x="{x}" y="{y}" font-size="{size}"{turn}>{escape(text.text)}</text>\n')
    out.append("</g>\n</svg>\n")
    return "".join(out)


# --- simulator flavour -----------------------------------------------------------------------


def _simulator_options(options: dict[str, Any]) -> tuple[float, float]:
    """(millimetres per pattern unit, stroke width in mm) of the simulator flavour."""
    laser = sorted(set(options) & set(_LASER_ONLY))
    if laser:
        raise InvalidParameterError(
            f"{', '.join(map(repr, laser))} only apply to flavour='laser' (the simulator "
            "flavour draws whole fold lines in the simulator's colours), got flavour="
            f"{options.get('flavour', 'simulator')!r}"
        )
    check_options(options, _SIMULATOR_OPTIONS + _LASER_ONLY, "SVG export")  # laser ones: above
    factor = unit_factor(options.get("units", "mm"), options.get("scale", 1.0))
    return factor, _stroke_width(options.get("stroke_width", _DEFAULT_STROKE_WIDTH))


def _smallest_gap(P: np.ndarray, E: np.ndarray) -> float:
    """Smallest distance between two vertices, or between a vertex and an edge not ending at it.

    Vertex pairs come from a k-d tree; for each edge only the vertices within that distance of
    its bounding circle are measured.
    """
    from itertools import chain

    from scipy.spatial import cKDTree

    tree = cKDTree(P)
    d, _ = tree.query(P, k=2)
    best = float(d[:, 1].min())
    a, c = P[E[:, 0]], P[E[:, 1]]
    radius = 0.5 * np.linalg.norm(c - a, axis=1) + best
    near = tree.query_ball_point(0.5 * (a + c), radius)
    counts = np.fromiter(map(len, near), dtype=np.intp, count=len(near))
    vertex = np.fromiter(chain.from_iterable(near), dtype=np.intp, count=int(counts.sum()))
    edge = np.repeat(np.arange(E.shape[0]), counts)
    other = (vertex != E[edge, 0]) & (vertex != E[edge, 1])
    vertex, edge = vertex[other], edge[other]
    if vertex.size:
        ac = (c - a)[edge]
        t = np.clip(np.einsum("ij,ij->i", P[vertex] - a[edge], ac) / np.einsum("ij,ij->i", ac, ac),
                    0.0, 1.0)  # fmt: skip
        gap = np.linalg.norm(P[vertex] - (a[edge] + t[:, None] * ac), axis=1)
        best = min(best, float(gap.min()))
    return best


def simulator_unit(vertices_mm: np.ndarray, edges: np.ndarray) -> float:
    """The user unit of the simulator flavour, in mm: the largest power of ten (at most 1 mm)
    for which the smallest vertex-vertex or vertex-edge distance is at least 10 times
    :data:`SIMULATOR_MERGE_TOLERANCE` units."""
    gap = _smallest_gap(np.asarray(vertices_mm, dtype=float), np.asarray(edges))
    wanted = gap / (_MERGE_MARGIN * SIMULATOR_MERGE_TOLERANCE)
    return min(1.0, 10.0 ** math.floor(math.log10(wanted)))


def _write_simulator(pattern, stream: TextIO, options: dict[str, Any]) -> None:
    from kinegami.export.fold import file_fold_angles, sheet_graph
    from kinegami.pattern.folded import FoldedFormError

    factor, stroke_mm = _simulator_options(options)
    label = check_label(options.get("label"))
    try:
        graph = sheet_graph(pattern, folded=True)
    except FoldedFormError as exc:
        raise FoldedFormError(
            f"{exc}; the Origami Simulator SVG takes its fold angles from the folded form, "
            "so a pattern without module records can only be written with flavour='laser'"
        ) from exc
    angles = file_fold_angles(graph)
    P = graph.vertices * factor  # mm
    unit = simulator_unit(P, graph.edges)
    Q = P / unit
    Q[:, 1] *= -1.0  # SVG's y axis points down: the sheet reads as in the plot
    xmin, ymin, xmax, ymax = (v * factor for v in graph.bounds)
    kinds = graph.assignment.copy()
    kinds[(kinds != "B") & (angles == 0.0)] = "F"
    opacity = np.round(np.abs(angles) / 180.0, 9)
    extent = float(np.abs(Q).max()) or 1.0
    width_mm, height_mm = format_numbers(np.array([xmax - xmin, ymax - ymin]), extent * unit)
    left, top, width, height = format_numbers(
        np.array([xmin, -ymax, xmax - xmin, ymax - ymin]) / unit, extent
    )
    stroke = format_numbers(np.array([stroke_mm / unit]), max(1.0, stroke_mm / unit))[0]
    unit_text = format_numbers(np.array([unit]), 1.0)[0]
    out = [
        '<?xml version="1.0" encoding="UTF-8" standalone="no"?>\n',
        f'<svg xmlns="http://www.w3.org/2000/svg" version="1.1" width="{width_mm}mm" '
        f'height="{height_mm}mm" viewBox="{left} {top} {width} {height}">\n',
        f"<title>{_title('kinegami tubular crease pattern (Origami Simulator)', label)}"
        "</title>\n",
        f"<desc>One user unit is {unit_text} mm. Stroke opacity = |fold angle| / 180 degrees "
        "(folded form at joint state 0).</desc>\n",
    ]
    for kind, gid in SIMULATOR_GROUPS.items():
        color = quoteattr(SIMULATOR_COLORS[kind])
        chosen = np.flatnonzero(kinds == kind)
        out.append(f'<g id="{gid}" fill="none" stroke={color} stroke-width="{stroke}">\n')
        ends = Q[graph.edges[chosen]].reshape(-1, 4)
        numbers = format_numbers(ends, extent)
        for k, i in enumerate(chosen.tolist()):
            x1, y1, x2, y2 = numbers[4 * k : 4 * k + 4]
            alpha = ""
            if kind in ("M", "V"):
                alpha = f' stroke-opacity="{repr(float(opacity[i]))}"'
            out.append(f'<line x1="{x1}" y1="{y1}" x2="{x2}" y2="{y2}" stroke={color}{alpha}/>\n')
        out.append("</g>\n")
    out.append("</svg>\n")
    stream.write("".join(out))
