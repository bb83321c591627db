"""A long sheet cut into pieces across plain tube, each with a tab to glue it to the next
(docs/fabrication.md, "Laser bed").

Everything here is in pattern units (the unit of r) and in the sheet's coordinates: x around
the tube (the strip -b/2 <= x <= W + b/2), y along it.

* **Where a cut may go.** Only across a plain tube module (kind ``"tube"``; on a tree's sheet,
  one without a take-off hole), never through a joint, an elbow, a twist, a tip or a skirt. A
  cut at y = c needs plain tube on [c - mark, c + tab]: the tab above it, the alignment ticks
  below it. So a plain tube carries a cut only if it is at least ``tab + mark`` long
  (:func:`minimum_tube`), and the allowed cuts of a tube of [y0, y1] are c in
  [y0 + mark, y1 - tab] (:func:`cut_intervals`).
* **Pieces.** Cuts c_1 < ... < c_{N-1} make N pieces: piece k covers [c_{k-1}, c_k] of the sheet
  (c_0 and c_N its ends). Each piece is a pattern of its own, composed from the sheet's modules
  (a cut tube becomes two tubes), so every exporter and the folded form take it, and its
  creases lie exactly where they lie on the sheet.
* **The tab.** Every piece but the last carries on its far end a copy of the next piece's first
  ``tab`` of plain tube [c_k, c_k + tab], with its creases (the tube's edges). Rolled, the tab
  slips inside the next piece and is glued there, the next piece's edge on the *join line*
  y = c_k.
* **Marks** (to etch, not to cut or fold): the join line across the strip, and short ticks on
  the centre line of every panel (and of both copies of the seam's panel): from c_k - mark to
  c_k on piece k, from c_k to c_k + mark on piece k + 1. Glued straight, the ticks of the two
  pieces continue each other.
* **Labels** (one line each): at the near end of every piece but the first, "NAME, piece k of
  N, joins piece k-1 here" (above its ticks); on every tab, "NAME, piece k of N: glue this tab
  inside piece k+1".

The cuts are chosen greedily, as far along as the piece's length allows: that needs the fewest
pieces and finds a split whenever one exists (:func:`needed_length` is the shortest piece
length that allows one).
"""

from __future__ import annotations

import bisect

import numpy as np

from kinegami._record import Record
from kinegami.errors import InvalidParameterError, InvalidTypeError, SplitError
from kinegami.pattern._prism import readonly, wrap_x
from kinegami.pattern.catalog import module_kind
from kinegami.pattern.cutout import CutPattern, SheetHole
from kinegami.pattern.tube import TubeFittingPattern, WaypointPattern
from kinegami.pattern.tubular import TubularPattern
from kinegami.validation import check_positive

__all__ = [
    "CHARACTER_WIDTH",
    "Label",
    "Piece",
    "SplitError",
    "Stretch",
    "TubeSpan",
    "cut_intervals",
    "minimum_tube",
    "needed_length",
    "split_sheet",
    "tube_spans",
]

#: Width of one character of a label, as a share of its height (generous for sans-serif and
#: for the DXF's standard font), used to shrink a label that would not fit across the strip.
CHARACTER_WIDTH = 0.7


class TubeSpan(Record):
    """A plain tube module of a sheet: its index in ``pattern.modules``, where it runs along
    the sheet (y0 to y1, pattern units) and the x of its reference point (its marker)."""

    module: int
    y0: float
    y1: float
    x: float


class Stretch(Record):
    """A stretch of a sheet with no allowed cut: from ``y0`` to ``y1`` (pattern units), holding
    the modules ``kinds`` (in order; a plain tube too short to cut as ``"tube"``)."""

    y0: float
    y1: float
    kinds: tuple[str, ...]


class Label(Record):
    """One line of text on a piece: lower left corner (x, y) and height, pattern units."""

    text: str
    x: float
    y: float
    height: float


class Piece(Record):
    """One piece of a sheet (see the module docstring).

    Attributes
    ----------
    index, count : int
        Piece ``index`` (1 to ``count``) of ``count``, in order along the sheet.
    pattern : TubularPattern or CutPattern
        The piece's own pattern, tab included, in the sheet's coordinates.
    start, end : float
        The part of the sheet it covers, y from ``start`` to ``end`` (pattern units).
    tab : float
        Height of its tab beyond ``end`` (0 for the last piece).
    marks : numpy.ndarray, shape (K, 2, 2)
        The join line and the alignment ticks (segments, pattern units). Read-only.
    labels : tuple of Label
    """

    index: int
    count: int
    pattern: TubularPattern | CutPattern
    start: float
    end: float
    tab: float
    marks: np.ndarray
    labels: tuple[Label, ...]

    @property
    def length(self) -> float:
        """Its extent along the sheet, tab included (pattern units)."""
        return self.end + self.tab - self.start


# --- where cuts may go --------------------------------------------------------------------------


def _parts(sheet) -> tuple[TubularPattern, tuple[SheetHole, ...]]:
    if isinstance(sheet, CutPattern):
        return sheet.pattern, sheet.holes
    if isinstance(sheet, TubularPattern):
        return sheet, ()
    raise InvalidTypeError(
        f"pattern must be a TubularPattern or a CutPattern, got {type(sheet).__name__}"
    )


def _module_extents(pattern: TubularPattern) -> list[tuple[float, float]]:
    """Where every module runs along the sheet: (y0, y1) of its vertices."""
    placed = pattern.module_vertices
    if placed is None or len(placed) != len(pattern.modules):
        raise InvalidParameterError(
            "the pattern cannot be cut into pieces: it does not record where its modules are "
            "(a pattern built by hand or reversed); cut the chain's creasePattern()"
        )
    ys = pattern.vertices_coords[:, 1]
    return [(float(ys[v].min()), float(ys[v].max())) for v in placed]


def tube_spans(sheet) -> tuple[TubeSpan, ...]:
    """The plain tube modules of a sheet that a cut may cross (no take-off hole), in order."""
    pattern, holes = _parts(sheet)
    extents = _module_extents(pattern)
    holed = {hole.module for hole in holes}
    spans = []
    W = pattern.width
    for i, record in enumerate(pattern.modules):
        if record.kind != "tube" or i in holed or extents[i][1] <= extents[i][0]:
            continue
        first = pattern.vertices_coords[pattern.module_vertices[i][0]]
        local = module_kind("tube").rebuild(pattern.numSides, pattern.r, record.params)
        x = float(np.mod(first[0] - local.vertices_coords[0, 0], W))
        spans.append(TubeSpan(i, extents[i][0], extents[i][1], x))
    return tuple(spans)


def minimum_tube(tab: float, mark: float | None = None) -> float:
    """The shortest plain tube a cut may cross: ``tab + mark`` (mark default tab / 2)."""
    return tab + (0.5 * tab if mark is None else mark)


def cut_intervals(sheet, tab: float, mark: float | None = None) -> list[tuple[float, float]]:
    """Every interval of allowed cut positions y (pattern units), in order: [y0 + mark,
    y1 - tab] for each plain tube [y0, y1] at least :func:`minimum_tube` long."""
    tab, mark = _tab_and_mark(tab, mark)
    return [(s.y0 + mark, s.y1 - tab) for s in tube_spans(sheet) if s.y1 - s.y0 >= tab + mark]


def _tab_and_mark(tab, mark) -> tuple[float, float]:
    tab = check_positive("tab", tab)
    mark = 0.5 * tab if mark is None else check_positive("mark", mark)
    return tab, mark


def _sheet_range(pattern: TubularPattern) -> tuple[float, float]:
    y0 = float(pattern.proximalMarker[1])
    return y0, y0 + pattern.height


def needed_length(sheet, tab: float, mark: float | None = None) -> tuple[float, Stretch]:
    """The shortest piece length (tab included, pattern units) that a split of ``sheet`` can
    keep to, and the stretch that needs it (the longest between two allowed cuts, or an end).

    The stretch gives a lower bound; where the cuts' spacing (``tab + mark`` at least, for the
    ticks and labels) asks for a little more, the length is found by bisection on the split
    itself, to 1e-9 r, so that a split with it succeeds.
    """
    tab, mark = _tab_and_mark(tab, mark)
    pattern, _ = _parts(sheet)
    start, end = _sheet_range(pattern)
    intervals = cut_intervals(sheet, tab, mark)
    if not intervals:
        return end - start, _stretch(sheet, start, end, tab, mark)
    # a piece from one end of an interval to the start of the next, plus the tab
    cases = [(intervals[0][0] + tab - start, start, intervals[0][0] - mark)]
    for (_, hi), (lo, _) in zip(intervals[:-1], intervals[1:], strict=True):
        cases.append((lo + tab - hi, hi + tab, lo - mark))
    cases.append((end - intervals[-1][1], intervals[-1][1] + tab, end))
    need, y0, y1 = max(cases, key=lambda case: case[0])
    if _cuts(sheet, need, tab, mark, intervals) is None:
        low, high = need, need + tab + mark
        while _cuts(sheet, high, tab, mark, intervals) is None:
            high += tab + mark
        while high - low > 1e-9 * pattern.r:
            middle = 0.5 * (low + high)
            low, high = (low, middle) if _cuts(sheet, middle, tab, mark, intervals) is not None \
                else (middle, high)  # fmt: skip
        need = high
    return need, _stretch(sheet, y0, y1, tab, mark)


def _stretch(sheet, y0: float, y1: float, tab: float, mark: float) -> Stretch:
    """The stretch from y0 to y1 and the modules (of non-zero height) in it."""
    pattern, _ = _parts(sheet)
    extents = _module_extents(pattern)
    tol = 1e-9 * pattern.r
    kinds = tuple(
        record.kind for record, (a, b) in zip(pattern.modules, extents, strict=True)
        if b > a and b > y0 + tol and a < y1 - tol
    )  # fmt: skip
    return Stretch(y0, y1, kinds)


# --- splitting --------------------------------------------------------------------------------


def _cuts(sheet, max_length: float, tab: float, mark: float,
          intervals: list[tuple[float, float]] | None = None) -> list[float] | None:
    """The greedy cuts: each as far along as a piece of ``max_length`` (tab included) allows,
    and at least ``tab + mark`` after the previous one (room for its label and ticks); None
    when a piece cannot reach an allowed cut."""
    pattern, _ = _parts(sheet)
    start, end = _sheet_range(pattern)
    if intervals is None:
        intervals = cut_intervals(sheet, tab, mark)
    tol = 1e-9 * pattern.r
    starts = [lo for lo, _ in intervals]  # sorted, and so are the ends (disjoint tubes)
    cuts: list[float] = []
    s = start
    while end - s > max_length + tol:
        low = s + tab + mark if cuts else s
        high = s + max_length - tab
        # the last interval starting within reach; no earlier one ends later
        k = bisect.bisect_right(starts, high + tol) - 1
        if k < 0 or intervals[k][1] < low - tol:
            return None
        best = min(intervals[k][1], high)  # the last allowed cut within reach
        if best <= s + tol or best < low - tol:
            return None
        cuts.append(best)
        s = best
    return cuts


def _split_error(sheet, max_length: float, tab: float, mark: float) -> SplitError:
    need, stretch = needed_length(sheet, tab, mark)
    return SplitError(
        f"the sheet cannot be cut into pieces of at most {max_length:.6g}: from "
        f"{stretch.y0:.6g} to {stretch.y1:.6g} along it there is no plain tube of at least "
        f"{tab + mark:.6g} to cut across ({', '.join(stretch.kinds) or 'nothing'}); pieces need "
        f"to be {need:.6g} long",
        stretch,
        need,
    )


def _translated(pattern: TubularPattern, dx: float, dy: float) -> TubularPattern:
    """``pattern`` moved by (dx, dy), x wrapped into [0, W) (a module placed in the sheet)."""
    W, eps = pattern.width, pattern.eps
    vertices = pattern.vertices_coords + [dx, dy]
    vertices[:, 0] = wrap_x(vertices[:, 0], W, eps)
    markers = np.stack([pattern.proximalMarker, pattern.distalMarker]) + [dx, dy]
    markers[:, 0] = wrap_x(markers[:, 0], W, eps)
    return TubularPattern(
        pattern.numSides, pattern.r, vertices, pattern.edges_vertices, pattern.edges_assignment,
        pattern.proximalBase, pattern.distalBase, markers[0], markers[1], pattern.height,
        pattern.modules,
    )  # fmt: skip


def _label(text: str, y: float, room: float, height: float, W: float, b: float) -> Label:
    """A label along the strip at y (its line centred in ``room`` above y), shrunk to fit
    between the two copies of the seam's panel."""
    size = min(height, 0.6 * room)
    size = min(size, (W - b - 0.5 * size) / (CHARACTER_WIDTH * max(len(text), 1)))
    return Label(text, 0.5 * b + 0.25 * size, y + 0.5 * (room - size), size)


def _ticks(span: TubeSpan, W: float, b: float, n: int, y0: float, y1: float) -> np.ndarray:
    """Ticks from y0 to y1 on the centre line of every panel of the tube (and the copies
    of the seam's panel within the strip)."""
    xs = wrap_x(span.x + np.arange(n) * b, W, 1e-12 * W)
    xs = np.concatenate([xs, xs[xs <= 0.5 * b] + W, xs[xs >= W - 0.5 * b] - W])
    xs = np.sort(xs[(xs >= -0.5 * b) & (xs <= W + 0.5 * b)])
    return np.array([[[x, y0], [x, y1]] for x in xs.tolist()]).reshape(-1, 2, 2)


def split_sheet(
    sheet,
    max_length: float,
    *,
    tab: float,
    mark: float | None = None,
    name: str | None = None,
    label_height: float | None = None,
) -> tuple[Piece, ...]:
    """Cut ``sheet`` into pieces at most ``max_length`` long, tab included (pattern units).

    Parameters
    ----------
    sheet : TubularPattern or CutPattern
        A chain's ``creasePattern()`` or a tree's sheet (made of catalog modules).
    max_length : float
        Longest piece along the sheet, tab included (> 0).
    tab : float
        Height of the overlap tab (> 0); also what a cut needs above it.
    mark : float, optional
        Length of the alignment ticks on each side of a join (default ``tab / 2``); also what
        a cut needs below it.
    name : str, optional
        What the labels call the design (default: none, labels start with "piece").
    label_height : float, optional
        Height of the labels' text (default ``tab / 4``); smaller where the room is.

    Returns
    -------
    tuple of Piece
        One piece (the sheet itself, no tab, marks or labels) when it is not longer than
        ``max_length``.

    Raises
    ------
    SplitError
        When a stretch without an allowed cut is too long (the message names it and the piece
        length that would work).
    """
    pattern, holes = _parts(sheet)
    max_length = check_positive("max_length", max_length)
    tab, mark = _tab_and_mark(tab, mark)
    height = 0.25 * tab if label_height is None else check_positive("label_height", label_height)
    start, end = _sheet_range(pattern)
    cuts = _cuts(sheet, max_length, tab, mark)
    if cuts is None:
        raise _split_error(sheet, max_length, tab, mark)
    if not cuts:
        return (Piece(1, 1, sheet, start, end, 0.0, readonly(np.zeros((0, 2, 2))), ()),)
    n, r, W, b = pattern.numSides, pattern.r, pattern.width, pattern.sideLength
    extents = _module_extents(pattern)
    spans = {s.module: s for s in tube_spans(sheet)}
    modules = [module_kind(m.kind).rebuild(n, r, m.params) for m in pattern.modules]
    if pattern.proximalMarker.tolist() != modules[0].proximalMarker.tolist():
        offset = pattern.proximalMarker - modules[0].proximalMarker
        modules[0] = _translated(modules[0], float(offset[0]), float(offset[1]))
    bounds = [start, *cuts, end]
    count = len(bounds) - 1
    prefix = f"{name}, " if name else ""
    # the tube module holding every cut
    cut_modules = [next(i for i, (a, z) in enumerate(extents) if i in spans and a < c < z)
                   for c in cuts]  # fmt: skip
    pieces = []
    for k in range(count):
        low, high = bounds[k], bounds[k + 1]
        parts: list[TubularPattern] = []
        numbering: dict[int, int] = {}  # module of the sheet -> module of the piece
        first = 0 if k == 0 else cut_modules[k - 1]
        last = len(modules) - 1 if k == count - 1 else cut_modules[k]
        for i in range(first, last + 1):
            a, z = extents[i]
            lo = low if k > 0 and i == first else a  # the cut tubes: from or up to the cut
            hi = high if k < count - 1 and i == last else z
            if k > 0 and i == first:  # the piece starts where the cut is, in the sheet
                parts.append(_translated(WaypointPattern(n, r), spans[i].x, low))
            if lo != a or hi != z:
                parts.append(TubeFittingPattern(n, r, hi - lo))
                continue
            # composition leaves out empty modules (waypoints) after the first
            numbering[i] = sum(len(p.modules) for j, p in enumerate(parts)
                               if j == 0 or p.numEdges or not p.isEmpty)  # fmt: skip
            parts.append(modules[i])
        if k < count - 1:
            parts.append(TubeFittingPattern(n, r, tab))
        piece = TubularPattern.concatenate(parts)
        if isinstance(sheet, CutPattern):
            kept = tuple(SheetHole(h.name, numbering[h.module], h.junction)
                         for h in holes if h.module in numbering)  # fmt: skip
            piece = CutPattern(piece, holes=kept,
                               skirt=sheet.skirt if k == 0 else None,
                               skirt_name=sheet.skirt_name if k == 0 else None,
                               frame=sheet.frame if k == 0 else None)  # fmt: skip
        marks, labels = [], []
        if k > 0:  # the near end: ticks above the join, the label above them
            marks.append(_ticks(spans[cut_modules[k - 1]], W, b, n, low, low + mark))
            labels.append(_label(f"{prefix}piece {k + 1} of {count}, joins piece {k} here",
                                 low + mark, tab - mark, height, W, b))  # fmt: skip
        if k < count - 1:  # the far end: ticks below the join line, the tab's label
            marks.append(_ticks(spans[cut_modules[k]], W, b, n, high - mark, high))
            marks.append(np.array([[[-0.5 * b, high], [W + 0.5 * b, high]]]))
            labels.append(_label(
                f"{prefix}piece {k + 1} of {count}: glue this tab inside piece {k + 2}",
                high, tab, height, W, b,
            ))  # fmt: skip
        pieces.append(Piece(k + 1, count, piece, low, high, tab if k < count - 1 else 0.0,
                            readonly(np.concatenate(marks)), tuple(labels)))  # fmt: skip
    return tuple(pieces)
