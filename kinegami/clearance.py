"""Self-intersection of a folded chain, at one configuration and over its range of motion.

See docs/clearance.md. The chain's parts are enclosed by capsules of radius r along its
centreline (:mod:`kinegami.bodies`). Two capsules are tested only when the centreline between
them turns by at least pi in total (arc angles plus |state| at every revolute hinge): a curve
that turns by less than pi cannot come back to itself, and parts closer along the tube than
that touch by construction (the two legs of an elbow, the halves of a joint, a link and its
joints). The clearance of a tested pair is the distance between their segments minus 2r;
negative values are overlap depths. The chain is clear when every tested pair has a clearance
of at least ``margin - CONTACT_TOLERANCE * r`` (:func:`~kinegami.bodies.clear_limit`): the
margin is the clearance the design requires (chain units, ``chain.margin``, default 0: parts
that touch, such as the legs of a U-turn exactly 2r apart, are clear). Every verdict is worded
by :meth:`ClearanceReport.verdict`, which states the margin.

Examples
--------
>>> chain = KinematicChain(StartTip(4, 1, Pose=SE3(), length=1.5))
>>> chain.append(RevoluteJoint(4, 1, np.pi, SE3.Trans(0, 0, 4) @ SE3.Ry(np.pi / 2)))
3
>>> chain.clearance().ok
True
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from kinegami.bodies import (
    CONTACT_TOLERANCE,
    JOINT_REVOLUTE,
    TURN_TOLERANCE,
    CapsuleModel,
    capsule_model,
    check_margin,
    clear_limit,
    part_label,
    tree_pair_distances,
)
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.geometry.segments import segment_distances
from kinegami.validation import check_int, check_real, shorten, shown

__all__ = [
    "CONTACT_TOLERANCE",
    "TURN_TOLERANCE",
    "UNITS_IN_MM",
    "Lengths",
    "CollidingPair",
    "ClearanceReport",
    "SweepReport",
    "chain_clearance",
    "tree_clearance",
    "clearance_report",
    "sweep",
    "ClearanceEngine",
    "TreeMotion",
    "engine_for",
]

#: Pairs x configurations evaluated at once (memory bound of the batched broad phase).
_BATCH_PAIRS = 1_500_000

#: Millimetres per design length unit (the units a verdict can print lengths in).
UNITS_IN_MM = {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4}


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


def _rotations(axes: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """Rotation matrices about unit ``axes`` (3,) by ``angles`` (K,), shape (K, 3, 3)."""
    k = axes
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    s = np.sin(angles)[:, None, None]
    c = (1.0 - np.cos(angles))[:, None, None]
    return np.eye(3) + s * K + c * (K @ K)


def _ball(points: np.ndarray, r: float) -> tuple[np.ndarray, float]:
    """A ball (centre, radius) containing every point of ``points`` (k, 3) grown by r."""
    centre = 0.5 * (points.min(axis=0) + points.max(axis=0))
    return centre, float(np.sqrt(((points - centre) ** 2).sum(axis=1)).max()) + r


class ClearanceEngine:
    """Fast clearance queries on one chain (its joints and links as they were when built).

    Configurations are absolute states, one per joint, as ``setJointStates`` takes them.

    The capsules are grouped into rigid bodies (the parts between two movable joints). Pairs
    inside one body never move relative to each other, so they are measured once. For pairs
    of bodies, a ball around each body (fixed in the body) is the broad phase; the capsules of
    two bodies whose balls are close are then tested capsule ball against capsule ball, and
    exactly (segment distance) when those are close too.
    """

    def __init__(self, chain, names=None):
        self.model: CapsuleModel = capsule_model(chain, names)
        m = self.model
        self.r = r = m.r
        self.ranges = np.array([joint.stateRange() for joint in chain.Joints], dtype=float)
        movable = np.nonzero(m.joint_kind != 0)[0]
        self.movable = movable
        # rigid body of every joint's distal side: number of movable joints up to it
        body_of_joint = np.cumsum(m.joint_kind != 0)
        body = np.concatenate([[0], body_of_joint])  # index j + 1; joint -1 (base) -> 0
        self.body_a = body[m.start_body + 1]
        self.body_b = body[m.end_body + 1]
        kinds = m.joint_kind[movable]
        self._revolute_m = kinds == JOINT_REVOLUTE
        S = m.count
        NB = movable.size + 1
        self.bodies = NB
        # most turning the hinges before body b can add (prefix over movable joints)
        max_kink = np.where(
            self._revolute_m, np.max(np.abs(self.ranges[movable]), axis=1), 0.0
        ) if movable.size else np.zeros(0)  # fmt: skip
        kink_prefix = np.concatenate([[0.0], np.cumsum(max_kink)])
        # body balls (in the current configuration; they move with their body); a prismatic
        # segment belongs to its proximal body, with its ball over the whole stroke
        ext_lo = np.zeros(S)
        ext_hi = np.zeros(S)
        seg_body = self.body_a
        axis = np.zeros((S, 3))
        for s in np.nonzero(self.body_a != self.body_b)[0]:
            j = int(movable[self.body_b[s] - 1])
            lo, hi = self.ranges[j]
            ext_lo[s] = lo - m.states[j]
            ext_hi[s] = hi - m.states[j]
            axis[s] = m.joint_axis[j]
        points_by_body: list[list[np.ndarray]] = [[] for _ in range(NB)]
        for s in range(S):
            pts = points_by_body[seg_body[s]]
            pts += [m.starts[s], m.ends[s]]
            if ext_hi[s] != ext_lo[s]:
                pts += [m.ends[s] + ext_lo[s] * axis[s], m.ends[s] + ext_hi[s] * axis[s]]
        centres = np.zeros((NB, 3))
        radii = np.zeros(NB)
        for b, pts in enumerate(points_by_body):
            if pts:
                centres[b], radii[b] = _ball(np.array(pts), r)
            else:
                radii[b] = -np.inf  # an empty body never collides
        self.body_centres = centres
        self.body_radii = radii
        # candidate pairs i < j whose turning gap can reach pi
        i, j = np.triu_indices(S, 1)
        gap_max = (
            m.turning[j] - m.turning[i]
            + kink_prefix[self.body_a[j]] - kink_prefix[self.body_a[i]]
        )  # fmt: skip
        keep = gap_max >= math.pi - TURN_TOLERANCE
        i, j = i[keep], j[keep]
        bi, bj = seg_body[i], seg_body[j]
        same = (bi == bj) & (self.body_a[i] == self.body_b[i]) & (self.body_a[j] == self.body_b[j])
        # pairs inside one rigid body: measured once
        self.static = None  # (clearance, pair index in static arrays) of the worst static pair
        si, sj = i[same], j[same]
        self._static_pairs = (si, sj)
        if si.size:
            d, s_, t_ = segment_distances(m.starts[si], m.ends[si], m.starts[sj], m.ends[sj])
            self._static_clearance = d - 2.0 * r
            self._static_st = (s_, t_)
        else:
            self._static_clearance = np.zeros(0)
            self._static_st = (np.zeros(0), np.zeros(0))
        # pairs across bodies, grouped by body pair (CSR)
        di, dj = i[~same], j[~same]
        lo_b = np.minimum(seg_body[di], seg_body[dj])
        hi_b = np.maximum(seg_body[di], seg_body[dj])
        code = lo_b * NB + hi_b
        order = np.argsort(code, kind="stable")
        di, dj, code = di[order], dj[order], code[order]
        self.first, self.second = di, dj
        pair_codes, starts, counts = np.unique(code, return_index=True, return_counts=True)
        self.body_pair_lo = pair_codes // NB
        self.body_pair_hi = pair_codes % NB
        self.body_pair_start = starts
        self.body_pair_count = counts

    # --- kinematics ------------------------------------------------------------------------
    def check_states(self, states, name: str = "states") -> np.ndarray:
        """``states`` as a float array (one per joint, each within its range), or raise."""
        return _checked_states(states, self.ranges, name)

    def body_transforms(self, Q: np.ndarray) -> np.ndarray:
        """(K, bodies, 4, 4): world motion of every rigid body (0 = base) at each of the
        configurations ``Q`` (K, J), relative to the chain's current configuration."""
        m = self.model
        K = Q.shape[0]
        B = np.empty((K, self.bodies, 4, 4))
        B[:, 0] = np.eye(4)
        for b, j in enumerate(self.movable, start=1):
            delta = Q[:, j] - m.states[j]
            if not np.any(delta):
                B[:, b] = B[:, b - 1]
                continue
            M = np.zeros((K, 4, 4))
            M[:, 3, 3] = 1.0
            if m.joint_kind[j] == JOINT_REVOLUTE:
                R = _rotations(m.joint_axis[j], delta)
                p = m.joint_point[j]
                M[:, :3, :3] = R
                M[:, :3, 3] = p - R @ p
            else:  # prismatic
                M[:, :3, :3] = np.eye(3)
                M[:, :3, 3] = delta[:, None] * m.joint_axis[j]
            B[:, b] = B[:, b - 1] @ M
        return B

    def _segments(self, B: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        m = self.model
        Ba = B[:, self.body_a]
        Bb = B[:, self.body_b]
        a = np.einsum("ksij,sj->ksi", Ba[..., :3, :3], m.starts) + Ba[..., :3, 3]
        b = np.einsum("ksij,sj->ksi", Bb[..., :3, :3], m.ends) + Bb[..., :3, 3]
        return a, b

    def segments(self, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World segment end points (K, S, 3) twice, at configurations ``Q`` (K, J)."""
        return self._segments(self.body_transforms(np.asarray(Q, dtype=float)))

    def turning(self, Q: np.ndarray) -> np.ndarray:
        """(K, S) turning of the centreline up to every segment at configurations ``Q``."""
        m = self.model
        Qm = np.asarray(Q, dtype=float)[:, self.movable]
        kinks = np.where(self._revolute_m[None, :], np.abs(Qm), 0.0)
        prefix = np.concatenate([np.zeros((Qm.shape[0], 1)), np.cumsum(kinks, axis=1)], axis=1)
        return m.turning[None, :] + prefix[:, self.body_a]

    # --- the core query --------------------------------------------------------------------
    def _candidates(self, Q: np.ndarray, threshold: float):
        """Exact clearances of every tested pair across bodies whose capsule balls are within
        ``threshold`` of each other, at configurations ``Q`` (K, J).

        Returns (k, pair, clearance, s, t, a, b): config index, index into first/second, the
        clearance and closest-point parameters of each such pair, and the world segments.
        """
        B = self.body_transforms(Q)
        a, b = self._segments(B)
        empty = (np.zeros(0, dtype=np.int64),) * 2 + (np.zeros(0),) * 3
        if self.body_pair_lo.size == 0:
            return (*empty, a, b)
        centres = np.einsum("kbij,bj->kbi", B[..., :3, :3], self.body_centres) + B[..., :3, 3]
        lo, hi = self.body_pair_lo, self.body_pair_hi
        gap = np.sqrt(((centres[:, lo] - centres[:, hi]) ** 2).sum(axis=2))
        near = gap - self.body_radii[lo] - self.body_radii[hi] <= threshold
        kk, bp = np.nonzero(near)
        if kk.size == 0:
            return (*empty, a, b)
        counts = self.body_pair_count[bp]
        total = int(counts.sum())
        k_rep = np.repeat(kk, counts)
        offsets = np.repeat(self.body_pair_start[bp] - np.cumsum(counts) + counts, counts)
        pair = offsets + np.arange(total)
        S = self.model.count
        flat_i = k_rep * S + self.first[pair]
        flat_j = k_rep * S + self.second[pair]
        # capsule balls first (centre and half-length per capsule and configuration)
        centre = (0.5 * (a + b)).reshape(-1, 3)
        half = (0.5 * np.sqrt(((b - a) ** 2).sum(axis=2))).reshape(-1)
        d = np.take(centre, flat_i, axis=0) - np.take(centre, flat_j, axis=0)
        lower = np.sqrt(np.einsum("ij,ij->i", d, d)) - half[flat_i] - half[flat_j]
        keep = lower <= threshold + 2.0 * self.r
        if self._revolute_m.any():
            tau = self.turning(Q).reshape(-1)
            keep &= tau[flat_j] - tau[flat_i] >= math.pi - TURN_TOLERANCE
        idx = np.nonzero(keep)[0]
        fi, fj = flat_i[idx], flat_j[idx]
        af, bf = a.reshape(-1, 3), b.reshape(-1, 3)
        dist, s, t = segment_distances(af[fi], bf[fi], af[fj], bf[fj])
        return k_rep[idx], pair[idx], dist - 2.0 * self.r, s, t, a, b

    def _pair(self, i: int, j: int, s: float, t: float, a, b, clearance: float):
        p = a[i] + s * (b[i] - a[i])
        q = a[j] + t * (b[j] - a[j])
        return CollidingPair(
            self.model.label(i, s),
            self.model.label(j, t),
            float(clearance),
            (tuple(map(float, p)), tuple(map(float, q))),
            (int(self.model.element[i]), int(self.model.element[j])),
        )

    def _static_at(self, k_static: int, a, b) -> CollidingPair:
        si, sj = self._static_pairs
        s_, t_ = self._static_st
        return self._pair(int(si[k_static]), int(sj[k_static]), s_[k_static], t_[k_static],
                          a, b, self._static_clearance[k_static])  # fmt: skip

    # --- queries ---------------------------------------------------------------------------
    def report(self, states, margin: float = 0.0) -> ClearanceReport:
        """The :class:`ClearanceReport` at one configuration (absolute states, checked), with
        ``margin`` (chain units, >= 0) the clearance required."""
        q = self.check_states(states)
        values = tuple(float(x) for x in q)
        Q = q[None, :]
        limit = clear_limit(self.r, margin)
        threshold = 4.0 * self.r + margin
        while True:
            k, pair, clearance, s, t, a, b = self._candidates(Q, threshold)
            a0, b0 = a[0], b[0]
            best = float(clearance.min()) if clearance.size else math.inf
            if self._static_clearance.size:
                best = min(best, float(self._static_clearance.min()))
            if best <= threshold or threshold > 1e3 * self._extent():
                break
            threshold = max(2.0 * threshold, best)
        entries = [
            (float(c), ("d", int(p), float(si), float(ti)))
            for c, p, si, ti in zip(clearance, pair, s, t, strict=True)
        ]
        entries += [(float(c), ("s", n)) for n, c in enumerate(self._static_clearance)]
        if not entries:
            return ClearanceReport(True, math.inf, (), None, values, margin, self.r)
        entries.sort(key=lambda e: e[0])

        def make(entry):
            c, ref = entry
            if ref[0] == "s":
                return self._static_at(ref[1], a0, b0)
            _, p, si, ti = ref
            return self._pair(int(self.first[p]), int(self.second[p]), si, ti, a0, b0, c)

        closest = make(entries[0])
        pairs: dict[tuple[str, str], CollidingPair] = {}
        for entry in entries:
            if entry[0] >= limit:
                break
            pair = make(entry)
            pairs.setdefault((pair.first, pair.second), pair)
        min_clearance = entries[0][0]
        return ClearanceReport(min_clearance >= limit, min_clearance, tuple(pairs.values()),
                               closest, values, margin, self.r)  # fmt: skip

    def _extent(self) -> float:
        """Size of the chain (for the search radius of :meth:`report`)."""
        m = self.model
        if m.count == 0:
            return self.r
        pts = np.vstack([m.starts, m.ends])
        return float(np.ptp(pts, axis=0).max()) + self.r

    def worst(self, Q: np.ndarray, margin: float = 0.0) -> tuple[np.ndarray, list]:
        """Closest pair at each configuration of ``Q`` (K, J) that is closer than ``margin``
        (chain units; 0: the deepest overlap), unchecked.

        Returns ``(clearance, pairs)``: clearance (K,) is the smallest clearance of the
        tested pairs when it is below the margin, or +inf when the configuration is clear;
        pairs[k] is the CollidingPair of that clearance, or None.
        """
        Q = np.asarray(Q, dtype=float)
        K = Q.shape[0]
        out = np.full(K, np.inf)
        found: list = [None] * K
        limit = clear_limit(self.r, margin)
        static_worst = None
        if self._static_clearance.size:
            n = int(np.argmin(self._static_clearance))
            if self._static_clearance[n] < limit:
                static_worst = n
        chunk = 256
        for start in range(0, K, chunk):
            Qc = Q[start : start + chunk]
            k, pair, clearance, s, t, a, b = self._candidates(Qc, margin)
            if static_worst is not None:
                value = float(self._static_clearance[static_worst])
                for local in range(Qc.shape[0]):
                    out[start + local] = value
                    found[start + local] = ("s", static_worst, local)
            colliding = np.nonzero(clearance < limit)[0]
            # the deepest overlap per configuration
            order = colliding[np.argsort(clearance[colliding], kind="stable")]
            for n in order:
                kk = start + int(k[n])
                if clearance[n] < out[kk]:
                    out[kk] = clearance[n]
                    found[kk] = ("d", int(pair[n]), float(s[n]), float(t[n]), int(k[n]))
            for local in range(Qc.shape[0]):
                ref = found[start + local]
                if ref is None or isinstance(ref, CollidingPair):
                    continue
                if ref[0] == "s":
                    found[start + local] = self._static_at(ref[1], a[local], b[local])
                else:
                    _, p, si, ti, kl = ref
                    found[start + local] = self._pair(
                        int(self.first[p]), int(self.second[p]), si, ti, a[kl], b[kl],
                        out[start + local],
                    )  # fmt: skip
        return out, found

    def colliding(self, Q: np.ndarray, margin: float = 0.0) -> np.ndarray:
        """(K,) True where the configuration has parts closer than ``margin`` (0: where it
        self-intersects)."""
        clearance, _ = self.worst(Q, margin)
        return np.isfinite(clearance)

    def free_intervals(self, states: np.ndarray, resolution: int = 64,
                       margin: float = 0.0) -> tuple:  # fmt: skip
        """Per joint, the clear interval (with ``margin``) of its own state around ``states``
        (see SweepReport).

        The range is scanned on a grid of ``resolution`` steps per side and each end found by
        30 bisection steps between the last clear and the first colliding grid state, so an
        interval is exact to about range / 2^30 unless a collision hides between two grid
        states.
        """
        J = len(states)
        if self.colliding(states[None, :], margin)[0]:
            return (None,) * J
        out: list = [(float(s), float(s)) for s in states]
        jobs = []  # (joint, side target)
        for j in self.movable:
            lo, hi = self.ranges[j]
            if hi > lo:
                jobs += [(int(j), float(lo)), (int(j), float(hi))]
        if not jobs:
            return tuple(out)
        # grid scan of every joint and side in one batch
        rows = []
        for j, target in jobs:
            grid = np.linspace(states[j], target, resolution + 1)[1:]
            Q = np.repeat(states[None, :], grid.size, axis=0)
            Q[:, j] = grid
            rows.append(Q)
        hits = self.colliding(np.vstack(rows), margin).reshape(len(jobs), resolution)
        good = np.empty(len(jobs))
        bad = np.full(len(jobs), np.nan)
        for n, (j, target) in enumerate(jobs):
            grid = np.linspace(states[j], target, resolution + 1)
            first = np.nonzero(hits[n])[0]
            if first.size == 0:
                good[n] = target
            else:
                good[n] = grid[first[0]]
                bad[n] = grid[first[0] + 1]
        open_ = np.nonzero(~np.isnan(bad))[0]
        for _ in range(30):  # bisection, all open ends at once
            if open_.size == 0:
                break
            mid = 0.5 * (good[open_] + bad[open_])
            Q = np.repeat(states[None, :], open_.size, axis=0)
            for row, n in enumerate(open_):
                Q[row, jobs[n][0]] = mid[row]
            hit = self.colliding(Q, margin)
            bad[open_[hit]] = mid[hit]
            good[open_[~hit]] = mid[~hit]
        for n, (j, _) in enumerate(jobs):
            lo, hi = out[j]
            if good[n] <= states[j]:
                out[j] = (float(good[n]), hi)
            else:
                out[j] = (lo, float(good[n]))
        return tuple(out)


_ENGINES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def engine_for(chain, names=None) -> ClearanceEngine:
    """The chain's :class:`ClearanceEngine`, cached until the chain's joints or links change."""
    from kinegami.chain import KinematicChain

    if not isinstance(chain, KinematicChain):
        raise InvalidTypeError(f"chain must be a KinematicChain, got {type(chain).__name__}")
    key = (chain.Joints, chain.Links, None if names is None else tuple(names))
    cached = _ENGINES.get(chain)
    if cached is not None and cached[0] == key:
        return cached[1]
    engine = ClearanceEngine(chain, names)
    _ENGINES[chain] = (key, engine)
    return engine


def _current(chain) -> np.ndarray:
    return np.array([joint.state for joint in chain.Joints], dtype=float)


def clearance_report(assembly, names=None, margin=None, states=None) -> ClearanceReport:
    """The one clearance verdict of a chain or a tree: what ``kinegami build``, ``kinegami
    check``, ``kinegami compact`` and the editor report (:meth:`ClearanceReport.verdict` words
    it).

    Parameters
    ----------
    assembly : KinematicChain or KinematicTree
    names : sequence of str or None, optional
        Joint names for the parts (each shown on one line, at most 80 characters).
    margin : float, optional
        The clearance required (chain units, >= 0); default: ``assembly.margin``.
    states : sequence of float, optional
        A configuration; default: the current states.
    """
    from kinegami.chain import KinematicChain

    if names is not None:
        names = tuple(None if name is None else shorten(name) for name in names)
    if isinstance(assembly, KinematicChain):
        return chain_clearance(assembly, states, names, margin)
    return tree_clearance(assembly, states, names, margin)


def _margin_of(chain, margin) -> float:
    """``margin`` checked, or the chain's (or tree's) own ``margin`` when None."""
    if margin is None:
        return float(getattr(chain, "margin", 0.0))
    return check_margin(margin)


def chain_clearance(chain, states=None, names=None, margin=None) -> ClearanceReport:
    """The clearance of ``chain`` at its current states, or at ``states`` (one per joint).

    Parameters
    ----------
    chain : KinematicChain
    states : sequence of float, optional
        A configuration (absolute states, each within its joint's ``stateRange()``); default:
        the chain's current states. The chain is not changed.
    names : sequence of str or None, optional
        Joint names for the report.
    margin : float, optional
        The clearance required (chain units, >= 0); default: ``chain.margin``.

    Raises
    ------
    InvalidParameterError
        For ``states`` of the wrong length or outside a joint's range, or a negative margin.
    """
    margin = _margin_of(chain, margin)
    engine = engine_for(chain, names)
    return engine.report(_current(chain) if states is None else states, margin)


def sweep(
    chain,
    samples: int = 1000,
    seed: int = 0,
    configurations=None,
    *,
    names=None,
    resolution: int = 64,
    progress=None,
    margin=None,
) -> SweepReport:
    """Clearance over the range of motion of a chain or a tree.

    Parameters
    ----------
    chain : KinematicChain or KinematicTree
        A tree is tested configuration by configuration with the pair rule of trees
        (:class:`TreeMotion`, docs/trees.md); a chain with its vectorised engine.
    samples : int
        Number of configurations drawn uniformly from the joints' state ranges (> 0; ignored
        when ``configurations`` is given).
    seed : int
        Seed of the random configurations (numpy ``default_rng``; >= 0; ignored when
        ``configurations`` is given).
    configurations : sequence of sequences of float, optional
        The configurations to test instead (absolute states, one per joint).
    names : joint names for the report, optional.
    resolution : int
        Grid steps per joint and direction when searching the free intervals (>= 1).
    progress : bool or callable, optional
        ``progress(done, total)`` as configurations are tested (total: their count);
        returning False stops the sweep with :class:`~kinegami.errors.Cancelled`. True or
        None: a progress bar on stderr (None: when stderr is a terminal). docs/progress.md.
    margin : float, optional
        The clearance required (chain units, >= 0): a configuration whose parts come closer
        counts as colliding; default: ``chain.margin``.

    Returns
    -------
    SweepReport
        The colliding fraction, the worst pairs, and each joint's free interval around the
        chain's current states.
    """
    from kinegami.chain import KinematicChain, _JointAssembly

    margin = _margin_of(chain, margin)
    if isinstance(chain, _JointAssembly) and not isinstance(chain, KinematicChain):
        engine = TreeMotion(chain, names, margin)  # a KinematicTree (a layer above this one)
    else:
        engine = _ChainMotion(engine_for(chain, names), margin)
    if isinstance(resolution, bool) or not isinstance(resolution, int | np.integer):
        raise InvalidTypeError(f"resolution must be an integer >= 1, got {shown(resolution)}")
    if resolution < 1:
        raise InvalidParameterError(f"resolution must be an integer >= 1, got {shown(resolution)}")
    if configurations is None:
        if isinstance(samples, bool) or not isinstance(samples, int | np.integer):
            raise InvalidTypeError(f"samples must be an integer > 0, got {shown(samples)}")
        if samples <= 0:
            raise InvalidParameterError(f"samples must be an integer > 0, got {shown(samples)}")
        seed = check_int("seed", seed, minimum=0, floats=False)
        rng = np.random.default_rng(seed)
        lo, hi = engine.ranges[:, 0], engine.ranges[:, 1]
        Q = lo + (hi - lo) * rng.random((int(samples), lo.size))
    else:
        if isinstance(configurations, str | bytes) or not isinstance(
            configurations, Sequence | np.ndarray
        ):
            raise InvalidTypeError(
                "configurations must be a list of configurations (one state per joint), got "
                f"{type(configurations).__name__}"
            )
        if len(configurations) == 0:
            raise InvalidParameterError("configurations must not be empty")
        Q = np.array(
            [engine.check_states(c, f"configurations[{k}]") for k, c in enumerate(configurations)]
        )
    clearance, pairs = _worst_with_progress(engine, Q, progress)
    colliding = int(np.count_nonzero(np.isfinite(clearance)))
    tally: dict[tuple[str, str], list] = {}
    for pair in pairs:
        if pair is None:
            continue
        entry = tally.setdefault((pair.first, pair.second), [pair, 0])
        entry[1] += 1
        if pair.clearance < entry[0].clearance:
            entry[0] = pair
    worst = sorted(tally.values(), key=lambda e: e[0].clearance)[:10]
    current = _current(chain)
    return SweepReport(
        samples=int(Q.shape[0]),
        colliding=colliding,
        worst_pairs=tuple((pair, count) for pair, count in worst),
        free_intervals=engine.free_intervals(current, int(resolution)),
        states=tuple(float(x) for x in current),
        margin=margin,
    )


def _worst_with_progress(engine, Q: np.ndarray, progress) -> tuple[np.ndarray, list]:
    """``engine.worst(Q)`` in chunks, reporting each chunk to ``progress`` (may cancel)."""
    from kinegami.progress import Progress

    chunk = 2048 if isinstance(engine, _ChainMotion) else 4
    clearance, pairs = [], []
    with Progress(progress, Q.shape[0], desc="sweep", unit="configuration") as bar:
        for start in range(0, Q.shape[0], chunk):
            c, p = engine.worst(Q[start : start + chunk])
            clearance.append(c)
            pairs.extend(p)
            bar.update(c.shape[0])
    return np.concatenate(clearance), pairs


def tree_clearance(tree, states=None, names=None, margin=None) -> ClearanceReport:
    """The clearance of a :class:`~kinegami.tree.KinematicTree` at its current states or at
    ``states`` (one per joint, in index order), with ``margin`` (chain units, >= 0; default:
    ``tree.margin``); the tree is not changed.

    The pair rule of trees (docs/trees.md): parts on one path from the root are tested as in a
    chain; parts on different branches always, except where two tubes leaving the same
    branching joint run together inside the junction that joins them (until they are the
    margin apart). A tree that is a chain gets the chain's report. When the closest parts of a
    clear tree are two tubes leaving one junction, the report's ``note`` says so.

    Raises
    ------
    InvalidParameterError, InvalidTypeError
        For ``states`` of the wrong length or type, or outside a joint's range, or a negative
        margin.
    """
    margin = _margin_of(tree, margin)
    joints = tree.Joints
    if states is None:
        values = tuple(float(joint.state) for joint in joints)
        links = tree.Links
    else:
        ranges = np.array([joint.stateRange() for joint in joints], dtype=float)
        values = _clipped(_checked_states(states, ranges, "states"), ranges)
        joints, links = tree._configured(values)
    r = float(tree.r)
    found = tree_pair_distances(joints, links, tree.Parents, r, reach=math.inf, margin=margin)
    if found is None:
        return ClearanceReport(True, math.inf, (), None, values, margin, r)
    clearance = found[2] - 2.0 * r
    order = np.argsort(clearance, kind="stable")
    limit = clear_limit(r, margin)

    def make(q: int) -> CollidingPair:
        return _pair_at(found, q, float(clearance[q]), joints, names)

    closest = make(int(order[0]))
    pairs: dict[tuple[str, str], CollidingPair] = {}
    for q in order:
        if clearance[q] >= limit:
            break
        pair = make(int(q))
        pairs.setdefault((pair.first, pair.second), pair)
    best = float(clearance[order[0]])
    ok = best >= limit
    note = _junction_note(tree, closest) if ok else ""
    return ClearanceReport(ok, best, tuple(pairs.values()), closest, values, margin, r, note)


def _junction_note(tree, pair: CollidingPair) -> str:
    """When ``pair`` (the closest parts of a clear tree) are two tubes leaving the same
    branching joint: "; closest where the tubes leaving joint J come out of its junction"
    (they touch there by construction: the junction covers them up to where they are the
    margin apart), else ""."""
    from kinegami.joints import Waypoint

    if any(e < 1 or e % 2 == 0 for e in pair.elements):
        return ""
    parents, joints = tree.Parents, tree.Joints
    children = [0] * len(parents)
    for p in parents:
        if p >= 0:
            children[p] += 1

    def top(k: int) -> int | None:  # the child of a branching joint whose tube k continues
        while k > 0:
            parent = parents[k]
            if children[parent] > 1:
                return k
            if not isinstance(joints[parent], Waypoint):
                return None
            k = parent
        return None

    a, b = (top((e + 1) // 2) for e in pair.elements)
    if a is None or b is None or a == b or parents[a] != parents[b]:
        return ""
    return f"; closest where the tubes leaving joint {parents[a]} come out of its junction"


class _ChainMotion:
    """A chain's :class:`ClearanceEngine` with a margin: the queries :func:`sweep` asks."""

    def __init__(self, engine: ClearanceEngine, margin: float):
        self.engine, self.margin = engine, margin
        self.ranges = engine.ranges

    def check_states(self, states, name: str = "states") -> np.ndarray:
        return self.engine.check_states(states, name)

    def worst(self, Q: np.ndarray) -> tuple[np.ndarray, list]:
        return self.engine.worst(Q, self.margin)

    def free_intervals(self, states: np.ndarray, resolution: int = 64) -> tuple:
        return self.engine.free_intervals(states, resolution, self.margin)


class TreeMotion:
    """Clearance queries over the motion of a :class:`~kinegami.tree.KinematicTree` (what
    :func:`sweep` uses for trees): the same queries as :class:`ClearanceEngine`, answered one
    configuration at a time with the pair rule of trees (docs/trees.md), about 5 ms each for
    the paper's hand.

    Configurations are absolute states, one per joint in index order.
    """

    #: Bisection steps that refine each end of a free interval after the grid scan.
    BISECTIONS = 24

    def __init__(self, tree, names=None, margin: float = 0.0):
        self._tree = tree
        self._names = None if names is None else tuple(names)
        self.margin = check_margin(margin)
        self._parents = tree.Parents
        self.r = float(tree.r)
        self.ranges = np.array([joint.stateRange() for joint in tree.Joints], dtype=float)
        self.movable = np.flatnonzero(self.ranges[:, 1] > self.ranges[:, 0])

    def check_states(self, states, name: str = "states") -> np.ndarray:
        """``states`` as a float array (one per joint, each within its range), or raise."""
        return _checked_states(states, self.ranges, name)

    def _pair(self, values) -> CollidingPair | None:
        """The closest pair closer than the margin at the configuration ``values``, or None
        when it is clear."""
        joints, links = self._tree._configured(_clipped(values, self.ranges))
        found = tree_pair_distances(joints, links, self._parents, self.r, margin=self.margin)
        if found is None:
            return None
        dist = found[2]
        q = int(np.argmin(dist))
        clearance = float(dist[q]) - 2.0 * self.r
        if clearance >= clear_limit(self.r, self.margin):
            return None
        return _pair_at(found, q, clearance, joints, self._names)

    def worst(self, Q: np.ndarray) -> tuple[np.ndarray, list]:
        """Deepest overlap at each configuration of ``Q`` (K, J), unchecked: ``(clearance,
        pairs)`` as :meth:`ClearanceEngine.worst` gives them (+inf and None where clear)."""
        pairs = [self._pair(q) for q in np.asarray(Q, dtype=float)]
        clearance = np.array([np.inf if p is None else p.clearance for p in pairs])
        return clearance, pairs

    def colliding(self, Q: np.ndarray) -> np.ndarray:
        """(K,) True where the configuration self-intersects."""
        return np.array([self._pair(q) is not None for q in np.asarray(Q, dtype=float)], bool)

    def free_intervals(self, states: np.ndarray, resolution: int = 64) -> tuple:
        """Per joint, the clear interval of its own state around ``states`` (see SweepReport):
        each side scanned on a grid of ``resolution`` steps up to the first colliding state,
        then refined by :attr:`BISECTIONS` bisection steps."""
        states = np.asarray(states, dtype=float)
        if self._pair(states) is not None:
            return (None,) * len(states)
        out: list = [(float(v), float(v)) for v in states]

        def clear_at(j: int, value: float) -> bool:
            q = states.copy()
            q[j] = value
            return self._pair(q) is None

        for j in self.movable.tolist():
            ends = []
            for target in self.ranges[j]:
                good = float(states[j])
                bad = None
                for value in np.linspace(states[j], target, resolution + 1)[1:]:
                    if not clear_at(j, float(value)):
                        bad = float(value)
                        break
                    good = float(value)
                if bad is not None:
                    for _ in range(self.BISECTIONS):
                        mid = 0.5 * (good + bad)
                        if clear_at(j, mid):
                            good = mid
                        else:
                            bad = mid
                ends.append(good)
            out[j] = (min(ends), max(ends))
        return tuple(out)


def _clipped(values, ranges: np.ndarray) -> tuple[float, ...]:
    """Checked states clamped into ``ranges`` (one within 1e-12 of its range moves onto it), as
    the tuple ``KinematicTree._configured`` takes."""
    clipped = np.clip(np.asarray(values, dtype=float), ranges[:, 0], ranges[:, 1])
    return tuple(float(v) for v in clipped)


def _pair_at(found: tuple, q: int, clearance: float, joints, names) -> CollidingPair:
    """Pair ``q`` of :func:`~kinegami.bodies.tree_pair_distances`'s result ``found`` as a
    CollidingPair: its parts in words, ``clearance``, its closest points and elements."""
    i, j, _, s, t, rows, a, b = found
    ii, jj = int(i[q]), int(j[q])
    p = a[ii] + s[q] * (b[ii] - a[ii])
    o = a[jj] + t[q] * (b[jj] - a[jj])
    return CollidingPair(
        part_label(rows[ii], float(s[q]), joints, names),
        part_label(rows[jj], float(t[q]), joints, names),
        clearance,
        (tuple(map(float, p)), tuple(map(float, o))),
        (int(rows[ii][5]), int(rows[jj][5])),
    )


def _checked_states(states, ranges: np.ndarray, name: str) -> np.ndarray:
    """``states`` as a float array (one per joint, each within ``ranges``), or raise."""
    J = ranges.shape[0]
    if isinstance(states, str | bytes) or not isinstance(states, Sequence | np.ndarray):
        raise InvalidTypeError(
            f"{name} must be a list of {J} joint states, got {type(states).__name__}"
        )
    if len(states) != J:
        raise InvalidParameterError(
            f"{name} must have one state per joint ({J}), got {len(states)}"
        )
    values = np.array([check_real(f"{name}[{k}]", v) for k, v in enumerate(states)])
    for k, (v, (lo, hi)) in enumerate(zip(values, ranges, strict=True)):
        if not lo - 1e-12 <= v <= hi + 1e-12:
            raise InvalidParameterError(
                f"{name}[{k}] = {float(v)!r} is outside joint {k}'s state range "
                f"[{lo:.6g}, {hi:.6g}]"
            )
    return values
