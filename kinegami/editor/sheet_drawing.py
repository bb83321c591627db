"""The crease pattern as the editor shows it: the flat sheet as inline SVG.

:func:`sheet_lines` draws a pattern's sheet (:func:`kinegami.pattern.sheet.flatten`) once:
mountain, valley, boundary and cut lines and the glue tab, coloured as the pattern plot
(:data:`kinegami.viz.pattern_plot.PATTERN_PLOT_DEFAULTS`), with the sheet's size in
millimetres. :func:`sheet_html` lays it out for the view's pattern panel: the whole sheet and,
when a joint is selected, a close-up of its modules, both with the joint's part of the sheet
highlighted; :func:`sheets_html` does the same for a tree's sheets, one per leaf. The sheet is
drawn lying down: the tube's axis runs left to right (the proximal end at the left) and the way
around the tube runs bottom to top. No web framework here: the view puts the text in a viser
HTML element. See docs/editor.md.
"""

from __future__ import annotations

import functools
import html
import itertools
from dataclasses import dataclass

import numpy as np

__all__ = ["SheetLines", "sheet_lines", "sheet_html", "sheets_html", "joint_span"]

#: How the highlighted part of the sheet is filled (the 3D view's selection colour).
HIGHLIGHT = "#fab428"
#: The close-up shows this many sheet widths (W + b) around the selected joint's modules.
CLOSE_UP_MARGIN = 1.0
#: The whole-sheet strip is stretched (not to scale) when it would be thinner than this share
#: of its length.
MIN_STRIP_ASPECT = 1.0 / 12.0

_ids = itertools.count(1)


@dataclass(frozen=True)
class SheetLines:
    """A pattern's sheet drawn once, ready to be placed in any view box.

    Attributes
    ----------
    group_id : the id of the SVG group holding the lines (unique per drawing).
    group : the SVG ``<g>`` element with every line and the glue tab.
    bounds : (umin, vmin, umax, vmax) of the sheet in the drawing's coordinates (u along the
        tube from its proximal end, v around it from the top), pattern units.
    y0 : the sheet's proximal end (pattern y of u = 0).
    xmax : pattern x of v = 0 (the top of the drawing).
    size_mm : (around, along) the tube: the cut outline's (W + b) x H in millimetres.
    counts : number of lines of each kind ("M", "V", "B", "C").
    """

    group_id: str
    group: str
    bounds: tuple[float, float, float, float]
    y0: float
    xmax: float
    size_mm: tuple[float, float]
    counts: dict


@functools.cache
def _colours() -> dict[str, str]:
    from matplotlib.colors import to_hex

    from kinegami.viz.pattern_plot import PATTERN_PLOT_DEFAULTS

    d = PATTERN_PLOT_DEFAULTS
    return {
        "M": to_hex(d["mountainColor"]),
        "V": to_hex(d["valleyColor"]),
        "B": to_hex(d["boundaryColor"]),
        "C": to_hex(d["cutColor"]),
        "glue": to_hex(d["glueTabColor"]),
        "glueOpacity": f"{float(d['glueTabOpacity']):g}",
    }


def _path(segments: np.ndarray) -> str:
    """SVG path data of line segments (K, 2, 2) already in drawing coordinates."""
    if not len(segments):
        return ""
    numbers = np.round(segments.reshape(-1, 4), 4).tolist()
    return "".join(f"M{a:g} {b:g}L{c:g} {d:g}" for a, b, c, d in numbers)


def sheet_lines(pattern, units: str = "mm") -> SheetLines:
    """Draw the sheet of ``pattern`` (a TubularPattern in ``units``) once.

    Drawing coordinates: u = y - y0 along the tube, v = xmax - x around it (so the drawing's
    top edge is the sheet's x = W + b/2 edge), pattern units.
    """
    from kinegami.pattern.sheet import flatten
    from kinegami.validation import UNITS_IN_MM

    sheet = flatten(pattern)
    xmin, y0, xmax, y1 = sheet.bounds
    colours = _colours()
    segments = sheet.segments
    drawn = np.empty_like(segments)
    drawn[..., 0] = segments[..., 1] - y0
    drawn[..., 1] = xmax - segments[..., 0]
    group_id = f"kinegami-sheet-{next(_ids)}"
    parts = [f'<g id="{group_id}">']
    length = y1 - y0
    for lo, hi in sheet.glueTabs:
        parts.append(
            f'<rect x="0" y="{xmax - hi:g}" width="{length:g}" height="{hi - lo:g}" '
            f'fill="{colours["glue"]}" fill-opacity="{colours["glueOpacity"]}"/>'
        )
    styles = {"C": "", "B": ' stroke-dasharray="4 3"', "M": "", "V": ""}
    for kind in ("C", "B", "M", "V"):
        data = _path(drawn[sheet.kinds == kind])
        if data:
            parts.append(
                f'<path class="kinegami-{kind}" d="{data}" fill="none" stroke="{colours[kind]}" '
                f'stroke-width="1" vector-effect="non-scaling-stroke"{styles[kind]}/>'
            )
    parts.append("</g>")
    scale = UNITS_IN_MM[units]
    counts = {kind: sheet.count(kind) for kind in ("M", "V", "B", "C")}
    return SheetLines(
        group_id, "".join(parts), (0.0, 0.0, length, xmax - xmin), y0, xmax,
        ((xmax - xmin) * scale, length * scale), counts,
    )  # fmt: skip


def joint_span(pattern, records: range) -> tuple[float, float] | None:
    """The pattern y range of the module records ``records`` (a joint's own modules; see
    ``EditorModel.joint_modules``); None when they are not known. A joint without modules
    of its own (a waypoint) gets the y where the modules before it end."""
    placed = pattern.module_vertices
    if placed is None:
        return None
    ys = pattern.vertices_coords[:, 1]
    if len(records):
        values = np.concatenate([ys[placed[k]] for k in records])
        return float(values.min()), float(values.max())
    if records.start == 0:
        return None
    y = float(ys[placed[records.start - 1]].max())
    return y, y


def _highlight(lines: SheetLines, span) -> str:
    if span is None:
        return ""
    u0, u1 = span[0] - lines.y0, span[1] - lines.y0
    height = lines.bounds[3]
    if u1 - u0 <= 0.0:
        return (f'<line x1="{u0:g}" y1="0" x2="{u0:g}" y2="{height:g}" stroke="{HIGHLIGHT}" '
                'stroke-width="3" vector-effect="non-scaling-stroke"/>')  # fmt: skip
    return (f'<rect class="kinegami-highlight" x="{u0:g}" y="0" width="{u1 - u0:g}" '
            f'height="{height:g}" fill="{HIGHLIGHT}" fill-opacity="0.35" stroke="{HIGHLIGHT}" '
            'stroke-width="2" vector-effect="non-scaling-stroke"/>')  # fmt: skip


def _svg(view_box, content: str, label: str, stretch: bool = False) -> str:
    u, v, w, h = view_box
    ratio = ' preserveAspectRatio="none"' if stretch else ""
    shown_h = max(h, MIN_STRIP_ASPECT * w) if stretch else h
    return (
        f'<svg xmlns="http://www.w3.org/2000/svg" role="img" aria-label="{html.escape(label)}" '
        f'viewBox="{u:g} {v:g} {w:g} {h:g}"{ratio} style="width:100%;height:auto;'
        f'aspect-ratio:{w:g}/{shown_h:g};display:block;background:white;'
        f'border:1px solid #ccc">{content}</svg>'
    )


def _legend(colours: dict) -> str:
    def swatch(colour: str, text: str) -> str:
        return (f'<span style="white-space:nowrap;margin-right:0.8em"><span style="display:'
                f'inline-block;width:1.4em;height:0.25em;vertical-align:middle;background:'
                f'{colour}"></span> {text}</span>')  # fmt: skip

    return "".join([swatch(colours["M"], "mountain"), swatch(colours["V"], "valley"),
                    swatch(colours["C"], "cut"), swatch(colours["glue"], "glue tab"),
                    swatch(HIGHLIGHT, "selected joint")])  # fmt: skip


def _size_line(lines: SheetLines, title: str = "Sheet") -> str:
    around, along = lines.size_mm
    c = lines.counts
    return (f'<div class="kinegami-sheet-size"><b>{html.escape(title)} {along:.1f} x '
            f'{around:.1f} mm</b> (along x around the tube; cut outline) &middot; {c["M"]} '
            f'mountain, {c["V"]} valley folds</div>')  # fmt: skip


def _whole(lines: SheetLines, highlight: str, label: str) -> str:
    umin, vmin, umax, vmax = lines.bounds
    stretched = (vmax - vmin) < MIN_STRIP_ASPECT * (umax - umin)
    title = "whole sheet, proximal end at the left" + (" (not to scale)" if stretched else "")
    return f"<div>{title}</div>" + _svg(
        (umin, vmin, umax - umin, vmax - vmin), lines.group + highlight, label, stretch=stretched
    )


def _close_up(lines: SheetLines, span: tuple[float, float], highlight: str, joint) -> str:
    umin, vmin, umax, vmax = lines.bounds
    margin = CLOSE_UP_MARGIN * (vmax - vmin)
    u0 = max(umin, span[0] - lines.y0 - margin)
    u1 = min(umax, span[1] - lines.y0 + margin)
    content = f'<use href="#{lines.group_id}"/>' + highlight
    return (f'<div style="margin-top:0.4em">close-up: {html.escape(joint or "")}</div>'
            + _svg((u0, vmin, max(u1 - u0, 1e-9), vmax - vmin), content,
                   "crease pattern, selected joint"))  # fmt: skip


def sheet_html(lines: SheetLines, span: tuple[float, float] | None = None,
               joint: str | None = None) -> str:  # fmt: skip
    """The pattern panel: the sheet's size and line counts, the whole sheet, and for a
    selected joint (``span``: its pattern y range, ``joint``: its label) a close-up."""
    highlight = _highlight(lines, span)
    parts = [
        '<div class="kinegami-pattern" style="font-size:0.8em;line-height:1.4">',
        _size_line(lines),
        f'<div style="margin:0.2em 0">{_legend(_colours())}</div>',
        _whole(lines, highlight, "crease pattern, whole sheet"),
    ]
    if span is not None:
        parts.append(_close_up(lines, span, highlight, joint))
    elif joint is not None:
        parts.append(f"<div>{html.escape(joint)}</div>")
    parts.append("</div>")
    return "".join(parts)


def sheets_html(sheets, selected: int | None = None, span: tuple[float, float] | None = None,
                joint: str | None = None, notes=()) -> str:  # fmt: skip
    """The pattern panel of a tree: ``sheets`` is one ``(lines, label)`` per sheet (a
    :class:`SheetLines` and the sheet's label), each drawn whole with its size; ``notes`` are
    lines of text above them (the junctions, the slides that fit them). For a selected joint,
    ``selected`` is the sheet that carries it, ``span`` its pattern y range there and
    ``joint`` its label: that sheet is highlighted and a close-up follows the sheets."""
    parts = [
        '<div class="kinegami-pattern" style="font-size:0.8em;line-height:1.4">',
        f"<div><b>{len(sheets)} sheets</b>, one per leaf of the tree</div>",
        f'<div style="margin:0.2em 0">{_legend(_colours())}</div>',
    ]
    parts += [f'<div class="kinegami-sheet-note">{html.escape(note)}</div>' for note in notes]
    for k, (lines, label) in enumerate(sheets):
        highlight = _highlight(lines, span) if k == selected else ""
        parts.append('<div class="kinegami-sheet" style="margin-top:0.6em">')
        parts.append(_size_line(lines, f"Sheet {k}:"))
        parts.append(f'<div class="kinegami-sheet-label">{html.escape(label)}</div>')
        parts.append(_whole(lines, highlight, f"crease pattern, sheet {k}"))
        parts.append("</div>")
    if selected is not None and span is not None:
        lines = sheets[selected][0]
        parts.append(_close_up(lines, span, _highlight(lines, span),
                               f"{joint or ''} (sheet {selected})"))  # fmt: skip
    elif joint is not None:
        parts.append(f"<div>{html.escape(joint)}</div>")
    parts.append("</div>")
    return "".join(parts)
