"""What a clearance check reports: the colliding pairs, one configuration's verdict, a sweep's
figures, and the lengths they are worded in (docs/clearance.md).

The reports word themselves: ``kinegami check``, ``kinegami build``'s summary and the editor's
panels print what :meth:`ClearanceReport.summary`, :meth:`ClearanceReport.markdown`,
:meth:`SweepReport.summary` and :meth:`SweepReport.markdown` return."""

from __future__ import annotations

import math
from collections.abc import Sequence
from dataclasses import dataclass, field
from typing import TYPE_CHECKING

from kinegami.chain.bodies import (
    clear_limit,
)
from kinegami.errors import InvalidParameterError
from kinegami.geometry.screws import REVOLUTE
from kinegami.validation import (
    UNITS_IN_MM,
    shown,
)

if TYPE_CHECKING:
    from kinegami.chain.joints import Joint
    from kinegami.chain.model import KinematicChain

__all__ = ["Lengths", "CollidingPair", "ClearanceReport", "SweepReport", "moving_joints"]


def moving_joints(joints: Sequence[Joint]) -> list[int]:
    """Indices of the joints that move: a state range that is not a single point."""
    ranges = [joint.stateRange() for joint in joints]
    return [i for i, (low, high) in enumerate(ranges) if high > low]


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

    def separation(self, length: Lengths) -> str:
        """How close the parts are, in ``length``'s words: "overlap 0.7 mm (0.07 cm)" or
        "2.2 mm apart"."""
        if self.clearance < 0.0:
            return f"overlap {length(-self.clearance)}"
        return f"{length(self.clearance)} apart"


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
        The pairs of parts closer than the margin (margin 0: that overlap), closest first (one
        entry per pair of parts): every one, or the closest MAX_REPORTED_PAIRS (1,000; see
        ``unlisted``).
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
    unlisted : int
        Pairs of parts closer than the margin beyond those in ``pairs`` (0 unless there are
        more than MAX_REPORTED_PAIRS); :attr:`pair_count` counts them all.
    unlisted_overlapping : int
        How many of the unlisted pairs overlap.
    """

    ok: bool
    min_clearance: float
    pairs: tuple
    closest: CollidingPair | None
    states: tuple
    margin: float = 0.0
    r: float = math.nan
    note: str = ""
    unlisted: int = 0
    unlisted_overlapping: int = 0

    @property
    def pair_count(self) -> int:
        """Pairs of parts closer than the margin, listed or not."""
        return len(self.pairs) + self.unlisted

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
        more = f"; {self.pair_count} pairs of parts" if self.pair_count > 1 else ""
        return (f"{'self-intersects, ' if overlapping else ''}parts closer than the margin "
                f"{margin}: minimum clearance {length(self.min_clearance)}, between "
                f"{first.first} and {first.second}{more}")  # fmt: skip

    def headline(self, units: str | None = None) -> str:
        """The state of the chain at its states in a few words, as ``kinegami check`` heads its
        report: "clear at its states", "self-intersects at its states (2 pairs of parts
        overlap)" or "not clear at its states (1 pair of parts closer than the margin 0.2 mm
        (0.02 cm))" (no pair overlaps, some are closer than the margin)."""
        if self.ok:
            return "clear at its states"
        count = self.pair_count
        overlap = sum(1 for pair in self.pairs if pair.clearance < 0.0) \
            + self.unlisted_overlapping  # fmt: skip
        plural = "s" if count > 1 else ""
        what = (f"{count} pair{plural} of parts overlap" if overlap == count
                else f"{count} pair{plural} of parts closer than the margin "
                f"{Lengths(self.r, units).exact(self.margin)}")  # fmt: skip
        return f"{'self-intersects' if overlap else 'not clear'} at its states ({what})"

    def summary(self, units: str | None = None, *, title: str | None = None,
                listed: int | None = None) -> list[str]:  # fmt: skip
        """The report in lines, as ``kinegami check`` prints it (``kinegami build`` and
        ``compact``: the verdict's line alone, ``listed=0``).

        Parameters
        ----------
        units : {"mm", "cm", "m", "in"} or None
            The design's length unit (lengths in mm and in it; None: chain units).
        title : str or None
            The first line is "TITLE: " and :meth:`headline` (None: no such line).
        listed : int or None
            When the chain is not clear, the pairs closer than the margin, closest first, are
            listed after the verdict: at most ``listed`` of them and a line "    ... and N
            more" (None: all; 0: no list at all).

        Returns
        -------
        list of str
            "TITLE: clear at its states", "  clearance: " and :meth:`verdict`, "  parts closer
            than the margin (closest first):", then one line per pair ("    A and B: overlap
            0.7 mm (0.07 cm)").
        """
        length = Lengths(self.r, units)
        lines = [] if title is None else [f"{title}: {self.headline(units)}"]
        lines.append(f"  clearance: {self.verdict(units)}")
        if self.ok or listed == 0:
            return lines
        shown = self.pairs if listed is None else self.pairs[:listed]
        lines.append("  parts closer than the margin (closest first):")
        lines += [f"    {p.first} and {p.second}: {p.separation(length)}" for p in shown]
        if self.pair_count > len(shown):
            lines.append(f"    ... and {self.pair_count - len(shown)} more")
        return lines

    def markdown(self, units: str | None = None, *, listed: int | None = None) -> str:
        """The report as the editor's clearance panel shows it (Markdown): the :meth:`verdict`
        when the chain is clear; otherwise the verdict in bold and the first ``listed`` pairs
        closer than the margin (None: all) as a list, in chain units as ``str(pair)``."""
        verdict = self.verdict(units)
        if self.ok:
            return verdict
        shown = self.pairs if listed is None else self.pairs[:listed]
        return "\n".join([f"**{verdict}**", ""] + [f"- {pair}" for pair in shown])

    def __str__(self) -> str:
        lines = [self.verdict()]
        if not self.ok:
            lines += [f"  {pair}" for pair in self.pairs]
            if self.unlisted:
                lines.append(f"  ... and {self.unlisted} more")
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

    def summary(self, chain: KinematicChain, units: str | None = None, *,
                names: Sequence[str | None] | None = None, seed: int = 0) -> list[str]:  # fmt: skip
        """The sweep in lines, as ``kinegami check --motion`` prints them after the
        :meth:`ClearanceReport.summary`.

        Parameters
        ----------
        chain : KinematicChain or KinematicTree
            What was swept (its joints' kinds and state ranges, and r).
        units : {"mm", "cm", "m", "in"} or None
            The design's length unit (lengths in mm and in it; None: chain units). Revolute
            states are in degrees.
        names : sequence of str or None, optional
            One joint name (or None) per joint, quoted after the joint's kind.
        seed : int
            The seed the configurations were sampled with (named in the first line).

        Returns
        -------
        list of str
            "  motion: 28 of 150 sampled configurations self-intersect (18.7%; seed 3)", the
            pairs that overlap most, then each moving joint's free interval ("    joint 3,
            RevoluteJoint 'elbow': -12.3 to 90.0 deg, of its range -90.0 to 90.0 deg").
        """
        length = Lengths(chain.r, units)
        share = f"{100.0 * self.colliding_fraction:.1f}%"
        lines = [f"  motion: {self.colliding} of {self.samples} sampled configurations "
                 f"self-intersect ({share}; seed {seed})"]  # fmt: skip
        if self.worst_pairs:
            lines.append("  pairs that overlap most over the motion:")
            for pair, n in self.worst_pairs:
                lines.append(f"    {pair.first} and {pair.second}: the deepest overlap in {n} "
                             f"configuration{'s' if n > 1 else ''}, up to "
                             f"{length(-pair.clearance)}")  # fmt: skip
        movable = moving_joints(chain.Joints)
        if not movable:
            lines.append("  free intervals: none (no joint moves)")
        elif self.free_intervals[movable[0]] is None:
            lines.append("  free intervals: none (the design self-intersects at its states)")
        else:
            lines.append("  free intervals (each joint moved alone from its state, the others "
                         "kept):")  # fmt: skip
            for i in movable:
                joint = chain.Joints[i]
                low, high = self.free_intervals[i]
                lo, hi = joint.stateRange()
                span = _degrees if joint.motion == REVOLUTE else length.span
                whole = low <= lo and high >= hi
                label = f" '{names[i]}'" if names is not None and names[i] is not None else ""
                lines.append(
                    f"    joint {i}, {type(joint).__name__}{label}: {span(low, high)}, "
                    + ("its whole range" if whole else f"of its range {span(lo, hi)}")
                )
        return lines

    def markdown(self, chain: KinematicChain, *, names: Sequence[str | None] | None = None,
                 seed: int = 0, listed: int | None = None,
                 joints_listed: int | None = None) -> str:  # fmt: skip
        """The sweep as the editor's motion panel shows it (Markdown): the share of colliding
        configurations, the first ``listed`` pairs that were the deepest overlap (None: all)
        and the free intervals of the first ``joints_listed`` moving joints (None: all), each
        joint named by ``names[i]`` or its kind; lengths in chain units, revolute states in
        degrees. ``chain``, ``names`` and ``seed`` as for :meth:`summary`."""
        share = f"{100.0 * self.colliding_fraction:.1f}%"
        lines = [f"**Motion check:** {self.colliding} of {self.samples} random configurations "
                 f"self-intersect ({share}, seed {seed})"]  # fmt: skip
        if self.worst_pairs:
            lines += ["", "Deepest overlaps over the motion:", ""]
            for pair, count in self.worst_pairs[:listed]:
                lines.append(f"- {pair.first} and {pair.second}: up to {-pair.clearance:.3g} "
                             f"({count} configuration{'s' if count > 1 else ''})")  # fmt: skip
        movable = moving_joints(chain.Joints)
        if movable and self.free_intervals[movable[0]] is None:
            lines += ["", "Free intervals: none (the design self-intersects at its states)."]
        elif movable:
            lines += ["", "Free interval of each joint moved alone from its state:", ""]
            for i in movable[:joints_listed]:
                joint = chain.Joints[i]
                low, high = self.free_intervals[i]
                lo, hi = (float(v) for v in joint.stateRange())
                name = names[i] if names is not None and names[i] else type(joint).__name__
                whole = " (its whole range)" if low <= lo and high >= hi else ""
                lines.append(f"- {i} {name}: [{_state(joint, low)}, {_state(joint, high)}]"
                             f"{whole}")  # fmt: skip
            if len(movable) > len(movable[:joints_listed]):
                lines.append(f"- ... and {len(movable) - joints_listed} more joints")
        return "\n".join(lines)


def _degrees(low: float, high: float) -> str:
    """An interval of revolute states (radians) in degrees: "-12.3 to 90.0 deg"."""
    return f"{math.degrees(low):.1f} to {math.degrees(high):.1f} deg"


def _state(joint: Joint, value: float) -> str:
    """One state in the editor's words: degrees for a revolute joint, else 3 digits."""
    if joint.motion == REVOLUTE:
        return f"{math.degrees(value):.1f} deg"
    return f"{value:.3g}"
