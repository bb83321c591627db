"""The sheet material and the laser bed: a sheet cut into pieces that fit the bed, nested onto
as few bed-sized sheets as they fit (docs/fabrication.md, "Laser bed" and "Material").

* :class:`Material`: what the sheet is cut from and its thickness (mm), which is also the
  default clearance margin of a design (folded sheets need room: docs/clearance.md).
* :class:`Bed`: the laser cutter's bed (mm, whatever the design's units, as the DXF is), the
  margin kept from its edges and between pieces, and the overlap tab's height.
* :func:`lay_out`: the pieces of a sheet (:func:`kinegami.pattern.pieces.split_sheet`) placed
  on beds by a first-fit decreasing packing (:func:`kinegami.geometry.packing.pack_rectangles`),
  a piece turned a quarter turn where that fits better; a :class:`BedLayout`.
"""

from __future__ import annotations

import math
import re
from collections import Counter
from collections.abc import Mapping
from typing import Any

from kinegami._format import shorten, shown
from kinegami._record import Record
from kinegami.errors import BedTooSmallError, InvalidParameterError, InvalidTypeError, SplitError
from kinegami.geometry.packing import Placement, pack_rectangles
from kinegami.pattern.pieces import Piece, needed_length, split_sheet
from kinegami.pattern.sheet import flatten

__all__ = [
    "Bed",
    "BedLayout",
    "DEFAULT_BED_MARGIN",
    "DEFAULT_TAB",
    "LABEL_HEIGHT",
    "MATERIALS",
    "MAX_BED",
    "MAX_THICKNESS",
    "Material",
    "check_material",
    "lay_out",
    "parse_bed",
]

#: Default distance kept from the bed's edges and between two pieces, mm.
DEFAULT_BED_MARGIN = 5.0
#: Default height of the overlap tab, mm (a cut needs 1.5 times this much plain tube).
DEFAULT_TAB = 10.0
#: Height of the pieces' labels, mm (less where the tab leaves less room).
LABEL_HEIGHT = 3.0
#: Largest bed side accepted, mm.
MAX_BED = 10_000.0
#: Thickest sheet accepted, mm.
MAX_THICKNESS = 10.0
#: Known materials: name -> (usual thickness range in mm, default thickness in mm).
MATERIALS: Mapping[str, tuple[tuple[float, float], float]] = {
    "PET": ((0.1, 0.25), 0.25),
    "paper": ((0.05, 0.3), 0.1),
    "cardstock": ((0.2, 0.5), 0.3),
    "polypropylene": ((0.2, 0.8), 0.3),
}
_MAX_NAME = 60


class Material(Record):
    """The sheet material: its ``name`` (e.g. ``"PET"``) and ``thickness`` in mm."""

    name: str
    thickness: float

    def describe(self) -> str:
        """Like "PET, 0.25 mm thick"."""
        return f"{self.name}, {self.thickness:g} mm thick"


def _number(name: str, value: Any, low: float, high: float, low_open: bool = True) -> float:
    """A finite number in (low, high] (or [low, high]); a one-line error naming ``name``."""
    if isinstance(value, bool) or not isinstance(value, int | float):
        raise InvalidTypeError(f"{name} must be a number, got {shown(value)}")
    number = float(value)
    ok = math.isfinite(number) and (number > low if low_open else number >= low) and number <= high
    if not ok:
        bound = f"> {low:g}" if low_open else f">= {low:g}"
        raise InvalidParameterError(f"{name} must be a number {bound} and <= {high:g} (mm), "
                                    f"got {shown(value)}")  # fmt: skip
    return number


def check_material(name: Any, thickness: Any = None) -> Material:
    """The material ``name`` (one line of text; a known name in any case gives its spelling
    of :data:`MATERIALS`) and its ``thickness`` in mm, in (0, MAX_THICKNESS] (default: the
    known material's usual thickness; required for another material).

    Raises
    ------
    InvalidParameterError, InvalidTypeError
        Naming the parameter, the value and the valid range.
    """
    if not isinstance(name, str):
        raise InvalidTypeError(f"material must be a name (a string), got {shown(name)}")
    text = " ".join(name.split())
    if not text or len(text) > _MAX_NAME or not name.isprintable():
        raise InvalidParameterError(
            f"material must be one line of 1 to {_MAX_NAME} printable characters, got "
            f"{shown(name)}"
        )
    known = {key.lower(): key for key in MATERIALS}
    text = known.get(text.lower(), text)
    if thickness is None:
        if text not in MATERIALS:
            raise InvalidParameterError(
                f"thickness: give the thickness of {shorten(text)} in mm (known materials, "
                f"with a usual thickness: {', '.join(MATERIALS)})"
            )
        thickness = MATERIALS[text][1]
    return Material(text, _number("thickness", thickness, 0.0, MAX_THICKNESS))


class Bed(Record):
    """A laser cutter's bed, mm: ``width`` x ``height``, the ``margin`` kept from its edges
    and between pieces (default 5), and the overlap ``tab``'s height (default 10)."""

    width: float
    height: float
    margin: float = DEFAULT_BED_MARGIN
    tab: float = DEFAULT_TAB

    @classmethod
    def of(cls, width: Any, height: Any, margin: Any = None, tab: Any = None) -> Bed:
        """A checked bed: sides in (0, MAX_BED] mm, ``margin`` >= 0 and less than half the
        shorter side, ``tab`` in (0, 1000] mm."""
        w = _number("bed width", width, 0.0, MAX_BED)
        h = _number("bed height", height, 0.0, MAX_BED)
        m = DEFAULT_BED_MARGIN if margin is None else _number("bed margin", margin, 0.0,
                                                                MAX_BED, low_open=False)
        if 2.0 * m >= min(w, h):
            raise InvalidParameterError(
                f"bed margin must be less than half the bed's shorter side ({0.5 * min(w, h):g}"
                f" mm for a {w:g} x {h:g} mm bed), got {m:g}"
            )
        t = DEFAULT_TAB if tab is None else _number("tab", tab, 0.0, 1000.0)
        return cls(w, h, m, t)

    @property
    def room(self) -> tuple[float, float]:
        """What the pieces may use: the bed less its margins, (width, height) mm."""
        return (self.width - 2.0 * self.margin, self.height - 2.0 * self.margin)

    @property
    def minimum_tube(self) -> float:
        """The shortest plain tube a cut may cross, mm: the tab and the ticks below the cut
        (half a tab)."""
        return 1.5 * self.tab

    def describe(self) -> str:
        """Like "600 x 400 mm"."""
        return f"{self.width:g} x {self.height:g} mm"


_BED = re.compile(r"\s*([0-9]*\.?[0-9]+)\s*[x×X*]\s*([0-9]*\.?[0-9]+)\s*(mm)?\s*\Z")


def parse_bed(text: Any) -> tuple[float, float]:
    """``"600x400"`` (mm; also ``600 x 400``, ``600×400 mm``) -> (600.0, 400.0)."""
    if isinstance(text, tuple | list) and len(text) == 2:
        return (_number("bed width", text[0], 0.0, MAX_BED),
                _number("bed height", text[1], 0.0, MAX_BED))  # fmt: skip
    match = _BED.match(text) if isinstance(text, str) else None
    if match is None:
        raise InvalidParameterError(
            f"bed must be WIDTHxHEIGHT in mm, e.g. 600x400, got {shown(text)}"
        )
    return (_number("bed width", float(match[1]), 0.0, MAX_BED),
            _number("bed height", float(match[2]), 0.0, MAX_BED))  # fmt: skip


class BedLayout(Record):
    """A sheet cut into pieces and nested onto beds (:func:`lay_out`).

    Attributes
    ----------
    bed : Bed
    unit : float
        Millimetres per pattern unit.
    pieces : tuple of Piece
        In order along the sheet (one, the sheet itself, when it fits whole).
    placements : tuple of Placement
        Where each piece goes, mm on its bed (``bin`` is the bed's index from 0); a piece
        ``rotated`` a quarter turn counter-clockwise runs along the bed's width.
    bounds : tuple of (xmin, ymin, xmax, ymax)
        Each piece's sheet rectangle, pattern units (what the placement puts on the bed).
    """

    bed: Bed
    unit: float
    pieces: tuple[Piece, ...]
    placements: tuple[Placement, ...]
    bounds: tuple[tuple[float, float, float, float], ...]

    @property
    def count(self) -> int:
        """Number of bed sheets used."""
        return 1 + max(p.bin for p in self.placements)

    def on_bed(self, index: int) -> list[int]:
        """The pieces (their indices in :attr:`pieces`) on bed ``index`` (from 0)."""
        return [k for k, p in enumerate(self.placements) if p.bin == index]

    @property
    def material_area(self) -> float:
        """Area of the bed-sized sheets used, mm²."""
        return self.count * self.bed.width * self.bed.height

    @property
    def pieces_area(self) -> float:
        """Area of the pieces (their rectangles, tabs included), mm²."""
        return sum(p.width * p.height for p in self.placements)


_KIND_WORDS = {
    "elbow": ("elbow", "elbows"),
    "twist": ("twist", "twists"),
    "revolute": ("revolute joint", "revolute joints"),
    "prismatic": ("prismatic joint", "prismatic joints"),
    "rebo": ("bellows", "bellows"),
    "start_tip": ("start tip", "start tips"),
    "end_tip": ("end tip", "end tips"),
    "tube": ("tube too short to cut", "tubes too short to cut"),
    "takeoff_skirt": ("take-off skirt", "take-off skirts"),
}


def _kinds_in_words(kinds: tuple[str, ...]) -> str:
    counts = Counter(k for k in kinds if k != "waypoint")
    words = []
    for kind, count in counts.items():
        one, many = _KIND_WORDS.get(kind, (kind, kind + "s"))
        words.append(f"a{'n' if one[0] in 'aeiou' else ''} {one}" if count == 1
                     else f"{count} {many}")  # fmt: skip
    return ", ".join(words) or "no module"


def _mm(value: float) -> str:
    return f"{value:,.0f} mm"


def lay_out(sheet, bed: Bed, *, unit: float = 1.0, name: str | None = None) -> BedLayout:
    """Cut ``sheet`` into pieces that fit ``bed`` and nest them onto as few beds as they fit.

    Parameters
    ----------
    sheet : TubularPattern or CutPattern
        A chain's crease pattern or a tree's sheet.
    bed : Bed
    unit : float, optional
        Millimetres per pattern unit (the design's units times any scale; default 1).
    name : str, optional
        What the pieces' labels call the design ("PUMA 560, piece 2 of 5, ...").

    Returns
    -------
    BedLayout
        A sheet that fits the bed whole is one piece, without tab, marks or labels.

    Raises
    ------
    BedTooSmallError
        When the strip is wider than the bed, or a stretch without plain tube to cut across
        needs a piece longer than the bed; the message names it and the smallest bed that
        works (``error.smallest``); nothing is laid out.
    """
    if not isinstance(bed, Bed):
        raise InvalidTypeError(f"bed must be a Bed, got {type(bed).__name__}")
    unit = _number("unit", unit, 0.0, 1e12)
    whole = flatten(sheet).bounds
    xmin, ymin, xmax, ymax = whole
    pattern = getattr(sheet, "pattern", sheet)
    start = float(pattern.proximalMarker[1])
    below = max(0.0, start - ymin)  # a skirt's glue tabs hang below the sheet's start
    strip = (xmax - xmin) * unit
    room_w, room_h = bed.room
    lengths = [room for across, room in ((room_w, room_h), (room_h, room_w)) if strip <= across]
    where = f"the {bed.describe()} bed (less its {bed.margin:g} mm margins)"
    tab = bed.tab / unit
    if not lengths:
        need, _ = needed_length(sheet, tab)
        long_side = math.ceil(max(need * unit + below * unit, 0.0) + 2.0 * bed.margin)
        short_side = math.ceil(strip + 2.0 * bed.margin)
        smallest = (float(max(long_side, short_side)), float(min(long_side, short_side)))
        raise BedTooSmallError(
            f"the sheet's strip is {strip:.1f} mm wide: wider than {where} both ways; the "
            f"smallest bed that works is {smallest[0]:g} x {smallest[1]:g} mm",
            smallest,
        )
    longest = max(lengths) / unit * (1.0 - 1e-12) - below  # the round-off inside the room
    try:
        pieces = split_sheet(sheet, longest, tab=tab, name=name,
                             label_height=LABEL_HEIGHT / unit)  # fmt: skip
    except SplitError as error:
        stretch, need = error.stretch, error.needed
        long_side = math.ceil((need + below) * unit + 2.0 * bed.margin)
        short_side = math.ceil(strip + 2.0 * bed.margin)
        smallest = (float(max(long_side, short_side)), float(min(long_side, short_side)))
        raise BedTooSmallError(
            f"the sheet does not fit {where} and cannot be cut into pieces that do: from "
            f"{(stretch.y0 - start) * unit:,.0f} to {_mm((stretch.y1 - start) * unit)} along "
            f"the strip there is no plain tube of at least {bed.minimum_tube:g} mm to cut "
            f"across ({_kinds_in_words(stretch.kinds)}), so one piece must be "
            f"{need * unit:.0f} mm long (tabs of {bed.tab:g} mm included); the smallest bed "
            f"that works is {smallest[0]:g} x {smallest[1]:g} mm",
            smallest,
            stretch,
            need,
        ) from None
    bounds = tuple(flatten(piece.pattern).bounds for piece in pieces)
    sizes = [((b[2] - b[0]) * unit, (b[3] - b[1]) * unit) for b in bounds]
    placements = pack_rectangles(sizes, (bed.width, bed.height), margin=bed.margin,
                                 gap=bed.margin)  # fmt: skip
    return BedLayout(bed, unit, pieces, placements, bounds)
