"""PDF of the flat sheet at 1:1, tiled over A4 or Letter pages (docs/pdf.md).

The lines are those of the DXF (:func:`kinegami.export._options.sheet_lines`: same flattening,
``units``, ``scale``, ``perforate``, ``dash``, ``gap`` and ``skip_creases_on_cut`` options), in
millimetres on the paper. Each page is a matplotlib figure of exactly the paper's size whose
axes span the whole page with 1 mm of drawing = 1 mm of paper, saved with ``PdfPages``.

Page layout (all lengths in mm)::

    +------------------------------------------------+  paper
    |   B1  page 2 of 3 ...    A1 ^                  |  top margin: label, neighbour above
    |  -+----------------------------------------+-  |
    |   |                                        |   |
    |  <|  the part of the sheet on this page    |>  |  neighbours left and right
    |   |  (window = paper - 2 margin - footer)  |   |
    |  -+----------------------------------------+-  |  crop marks at the window corners
    |                          C1 v                  |  footer: neighbour below,
    |   legend: mountain valley cut       |--50 mm--|  |  legend, scale bar,
    |   title, units; print at 100 %                 |  title and units
    +------------------------------------------------+

The footer is ``FOOTER`` high for a one-line title; a longer title wraps to the window's width
and the footer grows by ``TITLE_STEP`` per line, and a legend too long to sit beside the scale
bar goes under it on rows of its own, so the footer always lies inside the page less its
margins.

Pages are named by row letter (A = top) and column number (1 = left) and numbered row by row.
Trim each page along its crop marks and butt the pages edge to edge; with ``overlap`` > 0 the
windows of neighbouring pages overlap by that much and a dashed grey line marks where the
neighbour's window begins (glue the overlap). The sheet is centred in the tiled area.

Line styles (the DXF layer colours where they print well): mountain blue dash-dot, valley red
dashed, cut black solid, boundary grey dotted; with ``perforate=True`` the fold lines are
already dashes and are drawn solid.
"""

from __future__ import annotations

import functools
import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any, BinaryIO

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.export._options import resolve_sheet_options, sheet_lines
from kinegami.limits import MAX_PDF_PAGES
from kinegami.validation import check_int, check_nonnegative, check_positive

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure

    from kinegami.pattern.tubular import TubularPattern

__all__ = [
    "PAPER_SIZES",
    "POINTS_PER_MM",
    "PDF_DEFAULTS",
    "Tile",
    "PdfLayout",
    "pdf_layout",
    "sheets_pdf_data",
    "draw_page",
    "pdf_data",
    "write_pdf",
]

#: Paper sizes (width, height) in mm, portrait.
PAPER_SIZES = {"A4": (210.0, 297.0), "Letter": (215.9, 279.4)}

#: PostScript points per millimetre.
POINTS_PER_MM = 72.0 / 25.4

#: Options specific to the PDF exporter and their defaults (lengths in mm).
PDF_DEFAULTS = {
    "paper": "A4",
    "orientation": "auto",
    "margin": 10.0,
    "overlap": 0.0,
    "scale_bar": 50.0,
    "max_pages": MAX_PDF_PAGES,
    "title": "kinegami crease pattern",
}

MIN_MARGIN = 6.0  # mm: the crop marks and the page label go in the margin
#: mm between the bottom margin and the window for a one-line title and a one-row legend beside
#: the scale bar; each further title line adds TITLE_STEP, each further legend row LEGEND_STEP.
FOOTER = 14.0
TITLE_STEP = 3.0  # mm from one line of the footer's title to the next
LEGEND_STEP = 3.5  # mm from one row of the legend to the next
LEGEND_SAMPLE = 8.0  # mm of each line style drawn in the legend
LEGEND_GAP = 4.0  # mm between two legend entries
BAR_GAP = 5.0  # mm between the legend and the scale bar on one row
MARK_GAP = 1.5  # crop mark: gap to the window corner (mm)
MARK_LENGTH = 4.0  # crop mark length (mm)
LABEL_INDENT = MARK_GAP + MARK_LENGTH + 2.0  # mm from the window's left edge to the page label
_FONT = 7.0  # points

# kind -> (colour, line width mm, dash pattern mm or None, legend name)
_STYLES = {
    "M": ("#0000ff", 0.2, (3.0, 1.0, 0.5, 1.0), "mountain"),
    "V": ("#ff0000", 0.2, (2.0, 1.0), "valley"),
    "C": ("#000000", 0.3, None, "cut"),
    "B": ("#808080", 0.15, (0.4, 0.8), "boundary"),
}


@dataclass(frozen=True)
class Tile:
    """One page: which part of the sheet it shows.

    Attributes
    ----------
    row, col : int
        0-based; row 0 is the top row.
    label : str
        Row letter(s) and column number, e.g. ``"A1"``, ``"B3"``.
    page : int
        1-based page number (row by row).
    window : tuple of float
        (xmin, ymin, xmax, ymax) of the sheet shown, sheet millimetres.
    """

    row: int
    col: int
    label: str
    page: int
    window: tuple[float, float, float, float]


@dataclass(frozen=True, eq=False)
class PdfLayout:
    """Pages and lines of a PDF export (see :func:`pdf_layout`).

    Attributes
    ----------
    paper : str
    orientation : str
        ``'portrait'`` or ``'landscape'``.
    page_size : tuple of float
        (width, height) of a page, mm.
    content : tuple of float
        (x, y, width, height) of the window on the page, mm from the lower-left corner.
    rows, cols : int
    tiles : tuple of Tile
    segments : numpy.ndarray, shape (K, 2, 2)
        The sheet's lines, sheet mm.
    kinds : numpy.ndarray of str, shape (K,)
    sheet_bounds : tuple of float
        The cut rectangle (xmin, ymin, xmax, ymax), sheet mm.
    margin, overlap, scale_bar : float
        mm.
    perforated : bool
    units_text : str
        What one pattern unit is, for the footer (e.g. ``"1 unit = 1 mm"``).
    title : str
    footer : float
        Height of the footer between the bottom margin and the window, mm (``FOOTER`` for a
        one-line title; more when the title wraps or the legend needs more rows).
    title_lines : tuple of str
        The footer's text (title, units, how to print) wrapped to the window's width, top line
        first.
    legend : tuple of (str, str, float, float)
        (kind, name, x, y) of every legend entry: its line sample starts at (x, y), page mm.
    bar_base : float
        Height of the scale bar above the page's bottom edge, mm.
    """

    paper: str
    orientation: str
    page_size: tuple[float, float]
    content: tuple[float, float, float, float]
    rows: int
    cols: int
    tiles: tuple[Tile, ...]
    segments: np.ndarray
    kinds: np.ndarray
    sheet_bounds: tuple[float, float, float, float]
    margin: float
    overlap: float
    scale_bar: float
    perforated: bool
    units_text: str
    title: str
    footer: float
    title_lines: tuple[str, ...]
    legend: tuple[tuple[str, str, float, float], ...]
    bar_base: float

    @property
    def page_count(self) -> int:
        """Number of pages (rows x cols)."""
        return len(self.tiles)

    def page_offset(self, tile: Tile) -> tuple[float, float]:
        """(dx, dy) with page = sheet + (dx, dy) on ``tile``'s page, mm."""
        x, y = self.content[0], self.content[1]
        return x - tile.window[0], y - tile.window[1]

    def page_lines(self, tile: Tile) -> tuple[np.ndarray, np.ndarray]:
        """The lines on ``tile``'s page, clipped to its window, in page mm (and their kinds)."""
        keep, clipped = clip_to_rectangle(self.segments, tile.window)
        dx, dy = self.page_offset(tile)
        return clipped[keep] + np.array([dx, dy]), self.kinds[keep]


def _row_label(row: int) -> str:
    label = ""
    row += 1
    while row:
        row, rest = divmod(row - 1, 26)
        label = chr(ord("A") + rest) + label
    return label


def _count(length: float, window: float, overlap: float) -> int:
    """Pages needed along one direction: windows of ``window`` overlapping by ``overlap``."""
    if length <= window + 1e-9:
        return 1
    return int(math.ceil((length - overlap) / (window - overlap) - 1e-9))


def clip_to_rectangle(
    segments: np.ndarray, rect: tuple[float, float, float, float]
) -> tuple[np.ndarray, np.ndarray]:
    """Clip segments to a closed rectangle (Liang-Barsky).

    Parameters
    ----------
    segments : numpy.ndarray, shape (K, 2, 2)
    rect : (xmin, ymin, xmax, ymax)

    Returns
    -------
    keep : numpy.ndarray of bool, shape (K,)
        True where a piece of positive length lies in the rectangle (boundary included).
    clipped : numpy.ndarray, shape (K, 2, 2)
        The pieces (meaningful where ``keep``).
    """
    seg = np.asarray(segments, dtype=float).reshape(-1, 2, 2)
    p0 = seg[:, 0]
    d = seg[:, 1] - p0
    t0 = np.zeros(seg.shape[0])
    t1 = np.ones(seg.shape[0])
    inside = np.ones(seg.shape[0], dtype=bool)
    xmin, ymin, xmax, ymax = rect
    for axis, low, high in ((0, xmin, xmax), (1, ymin, ymax)):
        delta = d[:, axis]
        start = p0[:, axis]
        still = np.abs(delta) <= 1e-12
        inside &= ~still | ((start >= low) & (start <= high))
        safe = np.where(still, 1.0, delta)
        ta = (low - start) / safe
        tb = (high - start) / safe
        lo = np.where(still, -np.inf, np.minimum(ta, tb))
        hi = np.where(still, np.inf, np.maximum(ta, tb))
        t0 = np.maximum(t0, lo)
        t1 = np.minimum(t1, hi)
    clipped = np.stack([p0 + t0[:, None] * d, p0 + t1[:, None] * d], axis=1)
    length = np.linalg.norm(clipped[:, 1] - clipped[:, 0], axis=1)
    keep = inside & (t1 > t0) & (length > 1e-9)
    return keep, clipped


def text_width(text: str, bold: bool = False) -> float:
    """Width of ``text`` in the pages' font (7 pt, matplotlib's default family), mm: the sum of
    its characters' advances (kerning, left out, moves a line's end by well under 1 mm)."""
    return sum(_char_width(char, bold) for char in text)


@functools.lru_cache(maxsize=1024)
def _char_width(char: str, bold: bool) -> float:
    """Advance of one character in the pages' font, mm (measuring is slow: each once)."""
    from matplotlib.font_manager import FontProperties
    from matplotlib.textpath import TextToPath

    font = FontProperties(size=_FONT, weight="bold" if bold else "normal")
    width, _, _ = TextToPath().get_text_width_height_descent(char, font, ismath=False)
    return width / POINTS_PER_MM


def wrap_text(text: str, width: float) -> tuple[str, ...]:
    """``text`` cut into lines of at most ``width`` mm (:func:`text_width`): at spaces, and
    inside a word only when the word alone is wider than a line."""
    lines: list[str] = []
    line = ""
    for word in text.split(" "):
        candidate = f"{line} {word}" if line else word
        if text_width(candidate) <= width:
            line = candidate
            continue
        if line:
            lines.append(line)
        line = ""
        for char in word:  # a word longer than a line: cut it where the line is full
            if line and text_width(line + char) > width:
                lines.append(line)
                line = ""
            line += char
    lines.append(line)
    return tuple(lines)


def page_label(tile: Tile, count: int, rows: int, cols: int) -> str:
    """The label above the window of ``tile``'s page (``count`` pages in ``rows`` x ``cols``)."""
    return (
        f"{tile.label}   page {tile.page} of {count} (row {_row_label(tile.row)} of {rows}, "
        f"column {tile.col + 1} of {cols})"
    )


def _legend_entries(perforated: bool) -> list[tuple[str, str, float]]:
    """(kind, name, width in mm: line sample, gap and text) of the legend's entries."""
    entries = []
    for kind in ("M", "V", "C", "B"):
        name = _STYLES[kind][3]
        if perforated and kind in "MV":
            name += " (perforated)"
        entries.append((kind, name, LEGEND_SAMPLE + 1.5 + text_width(name)))
    return entries


@dataclass(frozen=True)
class _Footer:
    height: float
    title_lines: tuple[str, ...]
    legend: tuple[tuple[str, str, float, float], ...]
    bar_base: float


def _footer_layout(text: str, perforated: bool, margin: float, x: float, width: float,
                   scale_bar: float) -> _Footer:  # fmt: skip
    """Where the footer's parts go in a window ``width`` mm wide starting at ``x`` (page mm):
    the text wrapped at the bottom, the legend above it, the scale bar at the right of the
    legend's row when both fit on it, else above the legend (whose entries then fill rows of
    the whole width)."""
    lines = wrap_text(text, width)
    above_text = margin + 6.5 + (len(lines) - 1) * TITLE_STEP  # centre of the legend's last row
    entries = _legend_entries(perforated)
    widest = max(w for _, _, w in entries)
    if widest > width:
        raise InvalidParameterError(
            f"margin={margin:g} mm leaves a window {width:.1f} mm wide, too narrow for the "
            f"legend (its widest entry is {widest:.1f} mm); use a smaller margin"
        )
    in_one_row = sum(w for _, _, w in entries) + LEGEND_GAP * (len(entries) - 1)
    beside = in_one_row + BAR_GAP + scale_bar <= width
    rows: list[list[tuple[str, str, float]]] = [[]]
    used = 0.0
    for entry in entries:
        if rows[-1] and used + LEGEND_GAP + entry[2] > width and not beside:
            rows.append([])
            used = 0.0
        used += (LEGEND_GAP if rows[-1] else 0.0) + entry[2]
        rows[-1].append(entry)
    legend = []
    for row, members in enumerate(rows):
        y = above_text + (len(rows) - 1 - row) * LEGEND_STEP
        cursor = x
        for kind, name, entry_width in members:
            legend.append((kind, name, cursor, y))
            cursor += entry_width + LEGEND_GAP
    top_row = above_text + (len(rows) - 1) * LEGEND_STEP
    bar_base = above_text if beside else top_row + LEGEND_STEP
    return _Footer(bar_base + FOOTER - 6.5 - margin, lines, tuple(legend), bar_base)


def _choice(name: str, value: Any, choices) -> Any:
    if not isinstance(value, str) or value not in choices:
        raise InvalidParameterError(
            f"{name} must be one of {', '.join(map(repr, choices))}, got {value!r}"
        )
    return value


def pdf_layout(pattern: TubularPattern, **options: Any) -> PdfLayout:
    """Lay the sheet of ``pattern`` out on pages (no drawing); options as for :func:`write_pdf`.

    Raises
    ------
    InvalidTypeError, InvalidParameterError
        For an unknown option or a bad value, a page too small for its margins, or more
        pages than ``max_pages``.
    """
    from kinegami.pattern.cutout import CutPattern
    from kinegami.pattern.tubular import TubularPattern

    if not isinstance(pattern, TubularPattern | CutPattern):
        raise InvalidTypeError(f"pattern must be a TubularPattern, got {type(pattern).__name__}")
    opts = resolve_sheet_options(options, PDF_DEFAULTS, "PDF")
    extra = opts.extra
    paper = _choice("paper", extra["paper"], tuple(PAPER_SIZES))
    orientation = _choice("orientation", extra["orientation"], ("auto", "portrait", "landscape"))
    margin = check_nonnegative("margin", extra["margin"])
    if margin < MIN_MARGIN:
        raise InvalidParameterError(
            f"margin must be >= {MIN_MARGIN:g} mm (room for crop marks and labels), got {margin!r}"
        )
    overlap = check_nonnegative("overlap", extra["overlap"])
    scale_bar = check_positive("scale_bar", extra["scale_bar"])
    max_pages = check_int("max_pages", extra["max_pages"], minimum=1)
    title = extra["title"]
    if not isinstance(title, str):
        raise InvalidTypeError(f"title must be a string, got {title!r}")

    units = options.get("units", "mm")
    scale = float(options.get("scale", 1.0))
    units_text = f"1 unit = {scale:g} {units}" if scale != 1.0 else f"1 unit = 1 {units}"
    text = f"{title}, {units_text}; print at 100 % (actual size); trim along the crop marks"
    segments, kinds, bounds = sheet_lines(pattern, opts)
    sheet_w, sheet_h = bounds[2] - bounds[0], bounds[3] - bounds[1]
    candidates = []
    for name in ("portrait", "landscape") if orientation == "auto" else (orientation,):
        w, h = PAPER_SIZES[paper]
        if name == "landscape":
            w, h = h, w
        win_w = w - 2.0 * margin
        if win_w < 20.0:
            raise InvalidParameterError(
                f"margin={margin!r} mm leaves no room on {paper} {name} paper: the window "
                f"({win_w:.1f} mm wide) must be at least 20 mm wide"
            )
        if scale_bar > 0.5 * win_w - 10.0:
            raise InvalidParameterError(
                f"scale_bar must be at most {0.5 * win_w - 10.0:.1f} mm (half the window width "
                f"less 10 mm) on {paper} {name} paper with margin={margin:g} mm, got "
                f"{scale_bar!r}"
            )
        footer = _footer_layout(text, opts.perforate, margin, margin, win_w, scale_bar)
        win_h = h - 2.0 * margin - footer.height
        if win_h < 20.0:
            raise InvalidParameterError(
                f"margin={margin!r} mm and a footer of {footer.height:.1f} mm (title "
                f"{len(title)} characters) leave no room on {paper} {name} paper: the window "
                f"({win_w:.1f} x {win_h:.1f} mm) must be at least 20 x 20 mm"
            )
        if overlap > 0.5 * min(win_w, win_h):
            raise InvalidParameterError(
                f"overlap must be at most half the window ({0.5 * min(win_w, win_h):.1f} mm on "
                f"{paper} {name} paper), got {overlap!r}"
            )
        cols = _count(sheet_w, win_w, overlap)
        rows = _count(sheet_h, win_h, overlap)
        candidates.append((rows * cols, name, (w, h), (win_w, win_h), rows, cols, footer))
    count, name, (w, h), (win_w, win_h), rows, cols, footer = min(candidates, key=lambda c: c[0])
    if count > max_pages:
        raise InvalidParameterError(
            f"the sheet ({sheet_w:.1f} x {sheet_h:.1f} mm) needs {count} {paper} pages, more "
            f"than max_pages={max_pages}; use a smaller scale or raise max_pages"
        )
    total_w = cols * win_w - (cols - 1) * overlap
    total_h = rows * win_h - (rows - 1) * overlap
    left = bounds[0] - 0.5 * (total_w - sheet_w)
    top = bounds[3] + 0.5 * (total_h - sheet_h)
    tiles = []
    for row in range(rows):
        for col in range(cols):
            x0 = left + col * (win_w - overlap)
            y1 = top - row * (win_h - overlap)
            tiles.append(
                Tile(
                    row,
                    col,
                    f"{_row_label(row)}{col + 1}",
                    len(tiles) + 1,
                    (x0, y1 - win_h, x0 + win_w, y1),
                )
            )
    widest = max(text_width(page_label(t, len(tiles), rows, cols), bold=True) for t in tiles)
    if widest > win_w - LABEL_INDENT:
        raise InvalidParameterError(
            f"margin={margin:g} mm leaves a window {win_w:.1f} mm wide on {paper} {name} paper, "
            f"too narrow for the page labels ({widest:.1f} mm from {LABEL_INDENT:g} mm in); use "
            f"a smaller margin"
        )
    return PdfLayout(
        paper=paper,
        orientation=name,
        page_size=(w, h),
        content=(margin, margin + footer.height, win_w, win_h),
        rows=rows,
        cols=cols,
        tiles=tuple(tiles),
        segments=segments,
        kinds=kinds,
        sheet_bounds=bounds,
        margin=margin,
        overlap=overlap,
        scale_bar=scale_bar,
        perforated=opts.perforate,
        units_text=units_text,
        title=title,
        footer=footer.height,
        title_lines=footer.title_lines,
        legend=footer.legend,
        bar_base=footer.bar_base,
    )


def _dashes(pattern: tuple[float, ...] | None):
    if pattern is None:
        return "solid"
    return (0.0, tuple(v * POINTS_PER_MM for v in pattern))


def scale_bar_segment(layout: PdfLayout) -> np.ndarray:
    """(2, 2): the scale bar's line on every page, page mm (its length is ``scale_bar``)."""
    x, _, w, _ = layout.content
    right = x + w
    return np.array([[right - layout.scale_bar, layout.bar_base], [right, layout.bar_base]])


def draw_page(layout: PdfLayout, index: int, figure: Figure | None = None) -> Figure:
    """Draw page ``index`` (0-based) of ``layout`` on a figure of exactly the paper's size.

    The axes fill the figure with limits (0, width) x (0, height) in mm, so one drawing unit
    is one millimetre of paper.
    """
    import matplotlib as mpl
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    tile = layout.tiles[index]
    w, h = layout.page_size
    if figure is None:
        figure = Figure(figsize=(w / 25.4, h / 25.4))
    else:
        figure.set_size_inches(w / 25.4, h / 25.4)
    ax = figure.add_axes((0.0, 0.0, 1.0, 1.0))
    ax.set_xlim(0.0, w)
    ax.set_ylim(0.0, h)
    ax.set_axis_off()
    lines, kinds = layout.page_lines(tile)
    text = {"fontsize": _FONT, "color": "black"}
    with mpl.rc_context({"lines.scale_dashes": False}):
        for kind in ("B", "C", "V", "M"):
            color, width, dashes, _ = _STYLES[kind]
            if layout.perforated and kind in "MV":
                dashes = None
            selected = lines[kinds == kind]
            if selected.shape[0]:
                ax.add_collection(
                    LineCollection(
                        selected,
                        colors=color,
                        linewidths=width * POINTS_PER_MM,
                        linestyles=[_dashes(dashes)],
                        capstyle="butt",
                    )
                )
        _marks(ax, layout, tile)
        _footer(ax, layout, tile, text)
    return figure


def _marks(ax, layout: PdfLayout, tile: Tile) -> None:
    """Crop marks at the window corners, neighbour labels and overlap lines."""
    from matplotlib.collections import LineCollection

    x, y, w, h = layout.content
    gap = MARK_GAP
    length = min(MARK_LENGTH, max(layout.margin - gap - 1.0, 1.0))
    marks = []
    for cx, sx in ((x, -1.0), (x + w, 1.0)):
        for cy, sy in ((y, -1.0), (y + h, 1.0)):
            marks.append([(cx + sx * gap, cy), (cx + sx * (gap + length), cy)])
            marks.append([(cx, cy + sy * gap), (cx, cy + sy * (gap + length))])
    ax.add_collection(LineCollection(marks, colors="black", linewidths=0.1 * POINTS_PER_MM))
    by_position = {(t.row, t.col): t for t in layout.tiles}
    neighbours = {
        "up": by_position.get((tile.row - 1, tile.col)),
        "down": by_position.get((tile.row + 1, tile.col)),
        "left": by_position.get((tile.row, tile.col - 1)),
        "right": by_position.get((tile.row, tile.col + 1)),
    }
    style = {"fontsize": _FONT, "color": "dimgray"}
    o = layout.overlap
    overlap_lines = []
    if neighbours["up"] is not None:
        ax.text(x + 0.5 * w, y + h + gap, f"{neighbours['up'].label} \u2191", ha="center",
                va="bottom", **style)  # fmt: skip
        overlap_lines.append([(x, y + h - o), (x + w, y + h - o)])
    if neighbours["down"] is not None:
        ax.text(x + 0.5 * w, y - gap, f"{neighbours['down'].label} \u2193", ha="center",
                va="top", **style)  # fmt: skip
        overlap_lines.append([(x, y + o), (x + w, y + o)])
    if neighbours["left"] is not None:
        ax.text(x - gap, y + 0.5 * h, f"\u2190 {neighbours['left'].label}", ha="right",
                va="center", rotation=90, **style)  # fmt: skip
        overlap_lines.append([(x + o, y), (x + o, y + h)])
    if neighbours["right"] is not None:
        ax.text(x + w + gap, y + 0.5 * h, f"{neighbours['right'].label} \u2192", ha="left",
                va="center", rotation=90, **style)  # fmt: skip
        overlap_lines.append([(x + w - o, y), (x + w - o, y + h)])
    if o > 0.0 and overlap_lines:
        ax.add_collection(
            LineCollection(
                overlap_lines,
                colors="gray",
                linewidths=0.1 * POINTS_PER_MM,
                linestyles=[_dashes((1.0, 1.0))],
            )
        )


def _footer(ax, layout: PdfLayout, tile: Tile, text: dict) -> None:
    """Page label above the window; legend, scale bar and the wrapped title below it."""
    from matplotlib.collections import LineCollection

    x, y, w, h = layout.content
    ax.text(x + LABEL_INDENT, y + h + MARK_GAP + 1.0,
            page_label(tile, layout.page_count, layout.rows, layout.cols), ha="left",
            va="bottom", fontweight="bold", **text)  # fmt: skip
    for k, line in enumerate(reversed(layout.title_lines)):  # the last line at the bottom
        ax.text(x, layout.margin + 1.5 + k * TITLE_STEP, line, ha="left", va="center", **text)
    for kind, name, left, base in layout.legend:
        color, width, dashes, _ = _STYLES[kind]
        if layout.perforated and kind in "MV":
            dashes = None
        ax.add_collection(
            LineCollection(
                [[(left, base), (left + LEGEND_SAMPLE, base)]],
                colors=color,
                linewidths=width * POINTS_PER_MM,
                linestyles=[_dashes(dashes)],
            )
        )
        ax.text(left + LEGEND_SAMPLE + 1.5, base, name, ha="left", va="center", **text)
    bar = scale_bar_segment(layout)
    (x0, y0), (x1, _) = bar
    ticks = [[(x0, y0), (x1, y0)]]
    step = 10.0 if layout.scale_bar >= 20.0 else layout.scale_bar
    count = int(math.floor(layout.scale_bar / step + 1e-9))
    for k in range(count + 1):
        tick = 2.0 if k in (0, count) else 1.0
        ticks.append([(x0 + k * step, y0), (x0 + k * step, y0 + tick)])
    if count * step < layout.scale_bar - 1e-9:
        ticks.append([(x1, y0), (x1, y0 + 2.0)])
    ax.add_collection(LineCollection(ticks, colors="black", linewidths=0.2 * POINTS_PER_MM))
    ax.text(0.5 * (x0 + x1), y0 + 2.5, f"{layout.scale_bar:g} mm", ha="center",
            va="bottom", **text)  # fmt: skip


def pdf_data(pattern: TubularPattern, **options: Any) -> bytes:
    """The sheet of ``pattern`` at 1:1 as a PDF tiled over pages (needs matplotlib).

    Parameters
    ----------
    pattern : TubularPattern
    units, scale, perforate, dash, gap, skip_creases_on_cut
        As for :func:`kinegami.export.dxf.write_dxf` (units of the pattern; lengths in mm).
    paper : {'A4', 'Letter'}, optional
        Default ``'A4'`` (210 x 297 mm; Letter 215.9 x 279.4 mm).
    orientation : {'auto', 'portrait', 'landscape'}, optional
        ``'auto'`` (default) takes the one needing fewer pages (portrait on a tie).
    margin : float, optional
        Border of every page, mm (>= 6, default 10): the crop marks, the page label and the
        title are drawn in it, nothing of the sheet.
    overlap : float, optional
        Overlap of neighbouring pages' windows, mm (default 0: trim and butt).
    scale_bar : float, optional
        Length of the scale bar on every page, mm (default 50).
    max_pages : int, optional
        Refuse layouts needing more pages (default 200).
    title : str, optional
        Text in the footer (wrapped to the window's width) and the PDF's Title (default
        ``'kinegami crease pattern'``).

    Raises
    ------
    InvalidTypeError, InvalidParameterError
        For an unknown option or a bad value (before anything is written).
    """
    import io

    from matplotlib.backends.backend_pdf import PdfPages

    layout = pdf_layout(pattern, **options)
    stream = io.BytesIO()
    metadata = {"Title": layout.title, "Creator": "kinegami", "CreationDate": None}
    with PdfPages(stream, metadata=metadata) as pdf:
        for index in range(layout.page_count):
            figure = draw_page(layout, index)
            pdf.savefig(figure)
    return stream.getvalue()


def sheets_pdf_data(patterns, titles=None, **options: Any) -> bytes:
    """Several sheets (a tree's) in one PDF, each tiled at 1:1 as :func:`pdf_data` does, one
    after the other; ``titles`` (one per sheet) go in each sheet's footer.

    Options as for :func:`pdf_data` (``title`` names the whole document).
    """
    import io

    from matplotlib.backends.backend_pdf import PdfPages

    patterns = list(patterns)
    if not patterns:
        raise InvalidParameterError("sheets_pdf_data needs at least one pattern, got none")
    titles = [None] * len(patterns) if titles is None else list(titles)
    if len(titles) != len(patterns):
        raise InvalidParameterError(
            f"titles must have one entry per pattern ({len(patterns)}), got {len(titles)}"
        )
    document = options.pop("title", PDF_DEFAULTS["title"])
    layouts = [pdf_layout(p, **options, **({} if t is None else {"title": t}))
               for p, t in zip(patterns, titles, strict=True)]  # fmt: skip
    stream = io.BytesIO()
    metadata = {"Title": document, "Creator": "kinegami", "CreationDate": None}
    with PdfPages(stream, metadata=metadata) as pdf:
        for layout in layouts:
            for index in range(layout.page_count):
                pdf.savefig(draw_page(layout, index))
    return stream.getvalue()


def write_pdf(pattern: TubularPattern, stream: BinaryIO, **options: Any) -> None:
    """Write :func:`pdf_data` of ``pattern`` to a binary stream (options as there)."""
    stream.write(pdf_data(pattern, **options))
