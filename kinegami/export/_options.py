"""Options shared by the sheet exporters (DXF, SVG, PDF): units, scale, perforation, B10 skipping
(docs/theory/patterns.md §6)."""

from __future__ import annotations

import math
from typing import Any

import numpy as np

from kinegami._format import shown
from kinegami._record import Record
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.validation import UNITS_IN_MM, check_bool, check_options, check_positive

__all__ = [
    "BedText",
    "LABEL_HEIGHT",
    "check_label",
    "UNITS_IN_MM",
    "DEFAULT_DASH",
    "DEFAULT_GAP",
    "SheetOptions",
    "unit_factor",
    "resolve_sheet_options",
    "dash_segments",
    "format_numbers",
    "sheet_lines",
    "bed_lines",
]

#: Default perforation: cut length and bridge length along fold lines, millimetres.
DEFAULT_DASH = 1.0
DEFAULT_GAP = 1.0

_COMMON = ("units", "scale", "perforate", "dash", "gap", "skip_creases_on_cut")

#: Height of a sheet's label text, millimetres (the ``label`` option of DXF and SVG).
LABEL_HEIGHT = 3.0
#: Longest label accepted (characters).
MAX_LABEL = 500


def check_label(label: Any) -> str | None:
    """The ``label`` option: None, or one line of printable text (at most MAX_LABEL
    characters) written beside the sheet, e.g. "sheet 2: joints 5 to 7 ..." for a tree."""
    if label is None:
        return None
    if not isinstance(label, str):
        raise InvalidTypeError(f"label must be a string or None, got {type(label).__name__}")
    if len(label) > MAX_LABEL or not label.isprintable():
        raise InvalidParameterError(
            f"label must be one line of printable text of at most {MAX_LABEL} characters, "
            f"got {len(label)} characters" + ("" if label.isprintable() else " with control codes")
        )
    return label


class SheetOptions(Record):
    """Validated exporter options.

    Attributes
    ----------
    factor : float
        Millimetres per pattern unit (units times scale).
    perforate : bool
        Draw the fold lines as dashes.
    dash, gap : float
        Dash and gap lengths in millimetres (used when ``perforate``).
    skip_creases_on_cut : bool
        Drop creases lying on the top or bottom edge of the sheet (B10,
        docs/theory/patterns.md §6).
    extra : dict
        The exporter-specific options, unchecked.
    """

    factor: float
    perforate: bool
    dash: float
    gap: float
    skip_creases_on_cut: bool
    extra: dict


def unit_factor(units: Any = "mm", scale: Any = 1.0, unit: str = "pattern unit") -> float:
    """Millimetres per ``unit`` for the ``units`` and ``scale`` options (checked).

    Raises
    ------
    InvalidParameterError
        For a ``units`` not in :data:`UNITS_IN_MM`, or a ``scale`` that is not > 0.
    InvalidTypeError
        For a ``scale`` that is not a real number.
    """
    if not isinstance(units, str) or units not in UNITS_IN_MM:
        raise InvalidParameterError(
            f"units must be one of {', '.join(map(repr, UNITS_IN_MM))} (the length of one "
            f"{unit}), got {shown(units)}"
        )
    return UNITS_IN_MM[units] * check_positive("scale", scale)


def resolve_sheet_options(options: dict[str, Any], extra: dict[str, Any], fmt: str) -> SheetOptions:
    """Check the options of a sheet exporter.

    Parameters
    ----------
    options : dict
        The keyword arguments given by the user.
    extra : dict
        Defaults of the exporter-specific options (their names are accepted too).
    fmt : str
        Format name for messages, e.g. ``"DXF"``.

    Raises
    ------
    InvalidTypeError
        For an unknown option name or a value of the wrong type.
    InvalidParameterError
        For a value out of range, an unknown unit, or ``dash``/``gap`` with ``perforate=False``.
    """
    check_options(options, _COMMON + tuple(extra), f"{fmt} export")
    factor = unit_factor(options.get("units", "mm"), options.get("scale", 1.0))
    dash, gap = options.get("dash"), options.get("gap")
    perforate = options.get("perforate")
    if perforate is None:
        perforate = dash is not None or gap is not None
    perforate = check_bool("perforate", perforate)
    if not perforate and (dash is not None or gap is not None):
        raise InvalidParameterError(
            f"dash={dash!r} and gap={gap!r} only apply with perforate=True, got perforate=False"
        )
    dash = DEFAULT_DASH if dash is None else check_positive("dash", dash)
    gap = DEFAULT_GAP if gap is None else check_positive("gap", gap)
    skip = check_bool("skip_creases_on_cut", options.get("skip_creases_on_cut", False))
    values = dict(extra)
    values.update({k: v for k, v in options.items() if k in extra})
    return SheetOptions(factor, perforate, dash, gap, skip, values)


def dash_segments(segments: np.ndarray, dash: float, gap: float) -> tuple[np.ndarray, np.ndarray]:
    """Cut every segment into dashes of length ``dash`` separated by gaps of length ``gap``.

    Each segment starts with a full dash at its first point; the last dash is shorter when the
    segment ends inside it.

    Parameters
    ----------
    segments : numpy.ndarray, shape (K, 2, 2)
    dash, gap : float
        Lengths, same unit as the segments (> 0).

    Returns
    -------
    dashes : numpy.ndarray, shape (D, 2, 2)
        The dashes, in the order of the segments.
    source : numpy.ndarray of int, shape (D,)
        Index of the segment each dash comes from.
    """
    segments = np.asarray(segments, dtype=float).reshape(-1, 2, 2)
    p0 = segments[:, 0]
    d = segments[:, 1] - p0
    length = np.hypot(d[:, 0], d[:, 1])
    period = dash + gap
    tiny = 1e-9 * dash
    # dash k starts at k * period; keep the starts that leave a dash longer than tiny
    counts = np.where(length > tiny, np.ceil((length - tiny) / period), 0).astype(np.intp)
    source = np.repeat(np.arange(segments.shape[0]), counts)
    first = np.cumsum(counts) - counts
    k = np.arange(source.shape[0]) - np.repeat(first, counts)
    s = k * period
    e = np.minimum(s + dash, length[source])
    unit = d[source] / length[source, None]
    start = p0[source] + s[:, None] * unit
    end = p0[source] + e[:, None] * unit
    return np.stack([start, end], axis=1), source


def format_numbers(values: np.ndarray, extent: float) -> list[str]:
    """Shortest round-trip text of ``values`` rounded to 12 significant digits of ``extent``.

    Rounding removes float noise such as 1e-17 (written as 0.0) so files stay readable. The
    coordinates of a sheet repeat (about 16 times each), so each distinct value is formatted
    once: ``repr`` of a float is the slow part of writing a DXF or SVG.
    """
    values = np.asarray(values, dtype=float)
    digits = 12 - math.ceil(math.log10(extent)) if extent > 0 else 12
    rounded = np.round(values, digits).ravel() + 0.0  # + 0.0 turns -0.0 into 0.0
    if rounded.size < 64:
        return list(map(repr, rounded.tolist()))
    distinct, index = np.unique(rounded, return_inverse=True)
    texts = np.array(list(map(repr, distinct.tolist())), dtype=object)
    return texts[index.ravel()].tolist()


def sheet_lines(
    pattern, opts: SheetOptions
) -> tuple[np.ndarray, np.ndarray, tuple[float, float, float, float]]:
    """The lines to export, in millimetres: flattened, scaled and (optionally) perforated.

    Returns
    -------
    segments : numpy.ndarray, shape (K, 2, 2)
        Lines in mm; creases (or their dashes) first, then boundary and cut.
    kinds : numpy.ndarray of str, shape (K,)
        ``"M"``, ``"V"``, ``"B"`` or ``"C"``.
    bounds : tuple of float
        The cut rectangle (xmin, ymin, xmax, ymax) in mm.
    """
    from kinegami.pattern.sheet import flatten

    sheet = flatten(pattern, skip_creases_on_cut=opts.skip_creases_on_cut)
    segments = sheet.segments * opts.factor
    kinds = sheet.kinds
    if opts.perforate:
        folds = np.isin(kinds, ("M", "V"))
        dashes, source = dash_segments(segments[folds], opts.dash, opts.gap)
        segments = np.concatenate([dashes, segments[~folds]])
        kinds = np.concatenate([kinds[folds][source], kinds[~folds]])
    bounds = tuple(float(v) * opts.factor for v in sheet.bounds)
    return segments, kinds, bounds


class BedText(Record):
    """One line of text on a bed sheet: lower left corner (x, y), height and angle
    (degrees, counter-clockwise), mm."""

    text: str
    x: float
    y: float
    height: float
    angle: float


def _placed(points: np.ndarray, placement) -> np.ndarray:
    """Points (..., 2) in mm from a piece's lower left corner, where ``placement`` puts them
    on the bed (a quarter turn counter-clockwise when it is ``rotated``)."""
    if not placement.rotated:
        return points + [placement.x, placement.y]
    out = np.empty_like(points)
    out[..., 0] = placement.x + placement.width - points[..., 1]
    out[..., 1] = placement.y + points[..., 0]
    return out


def bed_lines(
    layout, index: int, opts: SheetOptions
) -> tuple[np.ndarray, np.ndarray, list[BedText], tuple[float, float, float, float]]:
    """The lines of bed sheet ``index`` (from 0) of a :class:`~kinegami.fabrication.beds.
    BedLayout`, in mm on the bed: every piece's sheet where the layout puts it, its marks on
    the Boundary layer (``"B"``: guides to etch), and its labels.

    ``opts.factor`` is not used: the layout says how many mm a pattern unit is.

    Returns
    -------
    segments : numpy.ndarray, shape (K, 2, 2)
        Creases (or their dashes) first, then boundary, marks and cut lines.
    kinds : numpy.ndarray of str, shape (K,)
    texts : list of BedText
    bounds : tuple of float
        The bed, (0, 0, width, height).
    """
    from kinegami.pattern.sheet import flatten

    unit = layout.unit
    segments, kinds, texts = [], [], []
    for k in layout.on_bed(index):
        piece, placement = layout.pieces[k], layout.placements[k]
        corner = np.array(layout.bounds[k][:2])
        sheet = flatten(piece.pattern, skip_creases_on_cut=opts.skip_creases_on_cut)
        lines = np.concatenate([sheet.segments, piece.marks])
        segments.append(_placed((lines - corner) * unit, placement))
        kinds.append(np.concatenate([sheet.kinds, np.full(piece.marks.shape[0], "B")]))
        for label in piece.labels:
            x, y = _placed((np.array([label.x, label.y]) - corner) * unit, placement).tolist()
            texts.append(BedText(label.text, x, y, label.height * unit,
                                 90.0 if placement.rotated else 0.0))  # fmt: skip
    segments = np.concatenate(segments) if segments else np.zeros((0, 2, 2))
    kinds = np.concatenate(kinds).astype("<U1") if kinds else np.zeros(0, dtype="<U1")
    if opts.perforate:
        folds = np.isin(kinds, ("M", "V"))
        dashes, source = dash_segments(segments[folds], opts.dash, opts.gap)
        segments = np.concatenate([dashes, segments[~folds]])
        kinds = np.concatenate([kinds[folds][source], kinds[~folds]])
    rank = {"M": 0, "V": 1, "B": 2, "C": 3}
    order = np.argsort([rank[k] for k in kinds.tolist()], kind="stable")
    return segments[order], kinds[order], texts, (0.0, 0.0, layout.bed.width, layout.bed.height)
