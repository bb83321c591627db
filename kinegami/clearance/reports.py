"""What a clearance check reports: the colliding pairs, one configuration's verdict, a sweep's
figures, and the lengths they are worded in (docs/clearance.md)."""

from __future__ import annotations

import math
from dataclasses import dataclass, field

from kinegami.chain.bodies import (
    clear_limit,
)
from kinegami.errors import InvalidParameterError
from kinegami.validation import (
    UNITS_IN_MM,
    shown,
)

__all__ = ["Lengths", "CollidingPair", "ClearanceReport", "SweepReport"]


class Lengths:
    """Lengths in words as every verdict prints them: in millimetres and, when the design's
    unit is not mm, in that unit beside them ("9.9 mm (0.99 cm)"), to about r / 100; without
    ``units``, plain numbers in chain units to 4 significant digits.

    Parameters
    ----------
    r : float
        The tube's circumradius (chain units): sets the digits.
    units : {"mm", "cm", "m", "in"} or None
        The design's length unit.
    """

    def __init__(self, r: float, units: str | None = None):
        if units is not None and units not in UNITS_IN_MM:
            raise InvalidParameterError(
                f"units must be one of {', '.join(UNITS_IN_MM)}, got {shown(units)}"
            )
        self.units = units
        self.factor = UNITS_IN_MM.get(units, 1.0)
        size = r * self.factor if math.isfinite(r) and r > 0 else 1.0
        self.mm_digits = max(0, 2 - math.floor(math.log10(size)))
        self.own_digits = max(0, 2 - math.floor(math.log10(size / self.factor)))

    @staticmethod
    def _fixed(value: float, digits: int) -> str:
        value = round(value, digits)
        return f"{value if value else 0.0:.{digits}f}"  # no "-0.00"

    def mm(self, value: float) -> str:
        """``value`` (chain units) in mm only: "9.9 mm" (without units: "9.9")."""
        if self.units is None:
            return f"{value:.4g}"
        return f"{self._fixed(value * self.factor, self.mm_digits)} mm"

    def __call__(self, value: float) -> str:
        """``value`` (chain units) in mm and in the design's unit: "9.9 mm (0.99 cm)"."""
        if self.units in (None, "mm"):
            return self.mm(value)
        return f"{self.mm(value)} ({self._fixed(value, self.own_digits)} {self.units})"

    def exact(self, value: float) -> str:
        """A value the user chose (a margin), without rounding: "0.2 mm (0.02 cm)"."""
        if self.units is None:
            return f"{value:g}"
        text = f"{value * self.factor:g} mm"
        return text if self.units == "mm" else f"{text} ({value:g} {self.units})"

    def span(self, low: float, high: float) -> str:
        """An interval: "-8.8 to 12.4 mm (-0.88 to 1.24 cm)"."""
        if self.units is None:
            return f"{low:.4g} to {high:.4g}"
        f, d = self.factor, self.mm_digits
        text = f"{self._fixed(low * f, d)} to {self._fixed(high * f, d)} mm"
        if self.units != "mm":
            d = self.own_digits
            text += f" ({self._fixed(low, d)} to {self._fixed(high, d)} {self.units})"
        return text


@dataclass(frozen=True)
class CollidingPair:
    """Two parts of the chain and how close they are.

    Attributes
    ----------
    first, second : str
        The parts in words, in order along the tube ("link 3, second elbow",
        "joint 5, RevoluteJoint 'wrist', distal half").
    clearance : float
        Distance between the parts' capsules (chain units); negative: overlap depth.
    points : tuple of two tuples
        The closest points of the two capsule axes (world coordinates, chain units).
    elements : tuple of two ints
        The parts' places along the tube: 2 i for joint i, 2 i - 1 for link i (the link into
        joint i).
    """

    first: str
    second: str
    clearance: float
    points: tuple
    elements: tuple = (-1, -1)

    def __str__(self) -> str:
        if self.clearance < 0.0:
            return f"{self.first} and {self.second} overlap by {-self.clearance:.4g}"
        return f"{self.first} and {self.second} are {self.clearance:.4g} apart"


@dataclass(frozen=True)
class ClearanceReport:
    """The clearance of a chain at one configuration, judged with a margin.

    Attributes
    ----------
    ok : bool
        True when every tested pair of parts is at least the margin apart (clearance >=
        margin - CONTACT_TOLERANCE r everywhere; margin 0: no two parts overlap).
    min_clearance : float
        Smallest clearance over the tested pairs (chain units; negative is the overlap depth;
        inf when no pair of parts is far enough apart along the tube to be tested).
    pairs : tuple of CollidingPair
        Every pair of parts closer than the margin (margin 0: that overlap), closest first (one
        entry per pair of parts).
    closest : CollidingPair or None
        The tested pair with the smallest clearance (None when nothing is tested).
    states : tuple of float
        The configuration (one state per joint).
    margin : float
        The clearance required (chain units, >= 0).
    r : float
        The tube's circumradius (chain units; sets the digits of :meth:`verdict`).
    note : str
        For a tree whose closest parts are two tubes leaving a junction: where (words
        :meth:`verdict` appends), else "".
    """

    ok: bool
    min_clearance: float
    pairs: tuple
    closest: CollidingPair | None
    states: tuple
    margin: float = 0.0
    r: float = math.nan
    note: str = ""

    def verdict(self, units: str | None = None) -> str:
        """The verdict in one line, as ``kinegami build``, ``kinegami check`` and the editor
        print it: "clear with margin 0 mm: minimum clearance 9.9 mm (0.99 cm), between A and
        B" or "self-intersects, parts closer than the margin 0 mm: minimum clearance -2.5 mm
        (-0.25 cm), between A and B". Lengths in mm and the design's ``units`` (None: plain
        numbers in chain units)."""
        length = Lengths(self.r, units)
        margin = length.exact(self.margin)
        if self.closest is None:
            return (f"clear with margin {margin}: no two parts are far enough apart along the "
                    "tube to collide")  # fmt: skip
        if self.ok:
            return (f"clear with margin {margin}: minimum clearance "
                    f"{length(self.min_clearance)}, between {self.closest.first} and "
                    f"{self.closest.second}{self.note}")  # fmt: skip
        first = self.pairs[0] if self.pairs else self.closest
        overlapping = self.min_clearance < clear_limit(self.r if math.isfinite(self.r) else 0.0)
        more = f"; {len(self.pairs)} pairs of parts" if len(self.pairs) > 1 else ""
        return (f"{'self-intersects, ' if overlapping else ''}parts closer than the margin "
                f"{margin}: minimum clearance {length(self.min_clearance)}, between "
                f"{first.first} and {first.second}{more}")  # fmt: skip

    def __str__(self) -> str:
        lines = [self.verdict()]
        if not self.ok:
            lines += [f"  {pair}" for pair in self.pairs]
        return "\n".join(lines)


@dataclass(frozen=True)
class SweepReport:
    """Clearance over sampled configurations (see :func:`sweep`).

    Attributes
    ----------
    samples : int
        Number of configurations tested.
    colliding : int
        How many of them self-intersect.
    worst_pairs : tuple of (CollidingPair, int)
        The pairs of parts that were the deepest overlap of some configuration, each with the
        number of configurations in which it was; deepest first, at most 10.
    free_intervals : tuple
        Per joint, ``(low, high)``: the interval of its own state around its current state
        over which moving it alone keeps the chain clear (within its ``stateRange()``), or
        None when the chain is not clear at its current states.
    states : tuple of float
        The current states the free intervals start from.
    margin : float
        The clearance required (chain units): a configuration whose parts come closer counts
        as colliding.
    """

    samples: int
    colliding: int
    worst_pairs: tuple
    free_intervals: tuple
    states: tuple = field(default=())
    margin: float = 0.0

    @property
    def colliding_fraction(self) -> float:
        """Fraction of the sampled configurations that self-intersect."""
        return self.colliding / self.samples if self.samples else 0.0
