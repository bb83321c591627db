"""Self-intersection of a folded chain, at one configuration and over its range of motion.

See docs/clearance.md. The chain's parts are enclosed by capsules of radius r along its
centreline (:mod:`kinegami.bodies`). Two capsules are tested only when the centreline between
them turns by at least pi in total (arc angles plus |state| at every revolute hinge): a curve
that turns by less than pi cannot come back to itself, and parts closer along the tube than
that touch by construction (the two legs of an elbow, the halves of a joint, a link and its
joints). The clearance of a tested pair is the distance between their segments minus 2r;
negative values are overlap depths. The chain is clear when every tested pair has a clearance
of at least ``-CONTACT_TOLERANCE * r`` (parts that touch, such as the legs of a U-turn exactly
2r apart, are clear).

Examples
--------
>>> chain = KinematicChain(StartTip(4, 1, Pose=SE3(), length=1.5))
>>> chain.append(RevoluteJoint(4, 1, np.pi, SE3.Trans(0, 0, 4) @ SE3.Ry(np.pi / 2)))
1
>>> chain.clearance().ok
True
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Sequence
from dataclasses import dataclass, field

import numpy as np

from kinegami.bodies import JOINT_PRISMATIC, JOINT_REVOLUTE, CapsuleModel, capsule_model
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.geometry.segments import segment_distances
from kinegami.validation import check_real

__all__ = [
    "CONTACT_TOLERANCE",
    "TURN_TOLERANCE",
    "CollidingPair",
    "ClearanceReport",
    "SweepReport",
    "chain_clearance",
    "sweep",
    "ClearanceEngine",
    "engine_for",
]

#: Overlaps shallower than this many r count as contact, not collision.
CONTACT_TOLERANCE = 1e-9
#: Two capsules are tested when the centreline between them turns by at least pi minus this.
TURN_TOLERANCE = 1e-9
#: Pairs x configurations evaluated at once (memory bound of the batched broad phase).
_BATCH_PAIRS = 1_500_000


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
    """

    first: str
    second: str
    clearance: float
    points: tuple

    def __str__(self) -> str:
        if self.clearance < 0.0:
            return f"{self.first} and {self.second} overlap by {-self.clearance:.4g}"
        return f"{self.first} and {self.second} are {self.clearance:.4g} apart"


@dataclass(frozen=True)
class ClearanceReport:
    """The clearance of a chain at one configuration.

    Attributes
    ----------
    ok : bool
        True when no two parts overlap (clearance >= -CONTACT_TOLERANCE r everywhere).
    min_clearance : float
        Smallest clearance over the tested pairs (chain units; negative is the overlap depth;
        inf when no pair of parts is far enough apart along the tube to be tested).
    pairs : tuple of CollidingPair
        Every pair of parts that overlap, deepest first (one entry per pair of parts).
    closest : CollidingPair or None
        The tested pair with the smallest clearance (None when nothing is tested).
    states : tuple of float
        The configuration (one state per joint).
    """

    ok: bool
    min_clearance: float
    pairs: tuple
    closest: CollidingPair | None
    states: tuple

    def __str__(self) -> str:
        if self.closest is None:
            return "clear (no parts far enough apart along the tube to collide)"
        if self.ok:
            return f"clear: minimum clearance {self.min_clearance:.4g}"
        lines = [f"self-intersecting: {len(self.pairs)} pair(s), deepest overlap "
                 f"{-self.min_clearance:.4g}"]  # fmt: skip
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
    """

    samples: int
    colliding: int
    worst_pairs: tuple
    free_intervals: tuple
    states: tuple = field(default=())

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


class ClearanceEngine:
    """Fast clearance queries on one chain (its joints and links as they were when built).

    Configurations are absolute states, one per joint, as ``setJointStates`` takes them.
    """

    def __init__(self, chain, names=None):
        self.model: CapsuleModel = capsule_model(chain, names)
        m = self.model
        self.r = m.r
        self.ranges = np.array([joint.stateRange() for joint in chain.Joints], dtype=float)
        S = m.count
        revolute = m.joint_kind == JOINT_REVOLUTE
        self._revolute = revolute
        max_kink = np.where(revolute, np.max(np.abs(self.ranges), axis=1), 0.0)
        # most turning the hinges up to body b can add: prefix sums, index b + 1 (b = -1: 0)
        kink_prefix = np.concatenate([[0.0], np.cumsum(max_kink)])
        i, j = np.triu_indices(S, 1)
        gap_max = (
            m.turning[j] - m.turning[i]
            + kink_prefix[m.start_body[j] + 1] - kink_prefix[m.start_body[i] + 1]
        )  # fmt: skip
        keep = gap_max >= math.pi - TURN_TOLERANCE
        self.first = i[keep]
        self.second = j[keep]
        self._movable = np.nonzero(m.joint_kind != 0)[0]

    # --- kinematics ------------------------------------------------------------------------
    def check_states(self, states, name: str = "states") -> np.ndarray:
        """``states`` as a float array (one per joint, each within its range), or raise."""
        J = self.ranges.shape[0]
        if isinstance(states, str | bytes) or not isinstance(states, Sequence | np.ndarray):
            raise InvalidTypeError(
                f"{name} must be a list of {J} joint states, got {type(states).__name__}"
            )
        if len(states) != J:
            raise InvalidParameterError(
                f"{name} must have one state per joint ({J}), got {len(states)}"
            )
        values = np.array([check_real(f"{name}[{k}]", s) for k, s in enumerate(states)])
        for k, (s, (lo, hi)) in enumerate(zip(values, self.ranges, strict=True)):
            if not lo - 1e-12 <= s <= hi + 1e-12:
                raise InvalidParameterError(
                    f"{name}[{k}] = {s!r} is outside joint {k}'s state range "
                    f"[{lo:.6g}, {hi:.6g}]"
                )
        return values

    def body_transforms(self, Q: np.ndarray) -> np.ndarray:
        """(K, J + 1, 4, 4): world motion of every body (index b + 1; 0 = base) at each of the
        configurations ``Q`` (K, J), relative to the chain's current configuration."""
        m = self.model
        K, J = Q.shape
        B = np.empty((K, J + 1, 4, 4))
        B[:, 0] = np.eye(4)
        delta = Q - m.states[None, :]
        for j in range(J):
            kind = m.joint_kind[j]
            if kind == 0 or not np.any(delta[:, j]):
                B[:, j + 1] = B[:, j]
                continue
            M = np.zeros((K, 4, 4))
            M[:, 3, 3] = 1.0
            if kind == JOINT_REVOLUTE:
                R = _rotations(m.joint_axis[j], delta[:, j])
                p = m.joint_point[j]
                M[:, :3, :3] = R
                M[:, :3, 3] = p - R @ p
            else:  # prismatic
                M[:, :3, :3] = np.eye(3)
                M[:, :3, 3] = delta[:, j, None] * m.joint_axis[j]
            B[:, j + 1] = B[:, j] @ M
        return B

    def segments(self, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World segment end points (K, S, 3) twice, at configurations ``Q`` (K, J)."""
        m = self.model
        B = self.body_transforms(Q)
        Ba = B[:, m.start_body + 1]
        Bb = B[:, m.end_body + 1]
        a = np.einsum("ksij,sj->ksi", Ba[..., :3, :3], m.starts) + Ba[..., :3, 3]
        b = np.einsum("ksij,sj->ksi", Bb[..., :3, :3], m.ends) + Bb[..., :3, 3]
        return a, b

    def turning(self, Q: np.ndarray) -> np.ndarray:
        """(K, S) turning of the centreline up to every segment at configurations ``Q``."""
        m = self.model
        kinks = np.where(self._revolute[None, :], np.abs(Q), 0.0)
        prefix = np.concatenate([np.zeros((Q.shape[0], 1)), np.cumsum(kinks, axis=1)], axis=1)
        return m.turning[None, :] + prefix[:, m.start_body + 1]

    # --- queries ---------------------------------------------------------------------------
    def _pair(self, k: int, s: float, t: float, a, b, clearance: float) -> CollidingPair:
        i, j = int(self.first[k]), int(self.second[k])
        p = a[i] + s * (b[i] - a[i])
        q = a[j] + t * (b[j] - a[j])
        return CollidingPair(
            self.model.label(i, s),
            self.model.label(j, t),
            float(clearance),
            (tuple(map(float, p)), tuple(map(float, q))),
        )

    def report(self, states) -> ClearanceReport:
        """The :class:`ClearanceReport` at one configuration (absolute states, checked)."""
        q = self.check_states(states)
        values = tuple(float(x) for x in q)
        if self.first.size == 0:
            return ClearanceReport(True, math.inf, (), None, values)
        Q = q[None, :]
        a, b = (x[0] for x in self.segments(Q))
        tau = self.turning(Q)[0]
        tested = tau[self.second] - tau[self.first] >= math.pi - TURN_TOLERANCE
        idx = np.nonzero(tested)[0]
        if idx.size == 0:
            return ClearanceReport(True, math.inf, (), None, values)
        i, j = self.first[idx], self.second[idx]
        centre = 0.5 * (a + b)
        half = 0.5 * np.linalg.norm(b - a, axis=1)
        gap = np.linalg.norm(centre[i] - centre[j], axis=1)
        lower = gap - half[i] - half[j]
        bound = max(float(gap.min()), 2.0 * self.r)
        near = idx[lower <= bound]
        i, j = self.first[near], self.second[near]
        dist, s, t = segment_distances(a[i], b[i], a[j], b[j])
        clearance = dist - 2.0 * self.r
        order = np.argsort(clearance, kind="stable")
        best = int(order[0])
        closest = self._pair(int(near[best]), s[best], t[best], a, b, clearance[best])
        limit = -CONTACT_TOLERANCE * self.r
        pairs: dict[tuple[str, str], CollidingPair] = {}
        for k in order:
            if clearance[k] >= limit:
                break
            pair = self._pair(int(near[k]), s[k], t[k], a, b, clearance[k])
            pairs.setdefault((pair.first, pair.second), pair)
        min_clearance = float(clearance[best])
        return ClearanceReport(
            min_clearance >= limit, min_clearance, tuple(pairs.values()), closest, values
        )

    def worst(self, Q: np.ndarray) -> tuple[np.ndarray, list]:
        """Deepest overlap at each configuration of ``Q`` (K, J), unchecked.

        Returns ``(clearance, pairs)``: clearance (K,) is the most negative clearance of the
        tested pairs, or +inf when no tested capsules overlap (clear); pairs[k] is the
        CollidingPair of that overlap, or None.
        """
        Q = np.asarray(Q, dtype=float)
        K = Q.shape[0]
        out = np.full(K, np.inf)
        found: list = [None] * K
        P = self.first.size
        if P == 0 or K == 0:
            return out, found
        chunk = max(1, _BATCH_PAIRS // P)
        limit = -CONTACT_TOLERANCE * self.r
        for start in range(0, K, chunk):
            Qc = Q[start : start + chunk]
            a, b = self.segments(Qc)
            tau = self.turning(Qc)
            centre = 0.5 * (a + b)
            half = 0.5 * np.linalg.norm(b - a, axis=2)
            i, j = self.first, self.second
            gap = np.linalg.norm(centre[:, i] - centre[:, j], axis=2)
            candidate = gap - half[:, i] - half[:, j] < 2.0 * self.r + limit
            candidate &= tau[:, j] - tau[:, i] >= math.pi - TURN_TOLERANCE
            ks, ps = np.nonzero(candidate)
            if ks.size == 0:
                continue
            ii, jj = i[ps], j[ps]
            dist, s, t = segment_distances(a[ks, ii], b[ks, ii], a[ks, jj], b[ks, jj])
            clearance = dist - 2.0 * self.r
            colliding = clearance < limit
            for n in np.nonzero(colliding)[0]:
                k = int(ks[n]) + start
                if clearance[n] < out[k]:
                    out[k] = clearance[n]
                    found[k] = (int(ps[n]), float(s[n]), float(t[n]), int(ks[n]), a, b)
            # turn the winners of this chunk into pairs while a, b are at hand
            for k in range(start, min(K, start + chunk)):
                if found[k] is not None and not isinstance(found[k], CollidingPair):
                    p, s_k, t_k, local, a_c, b_c = found[k]
                    found[k] = self._pair(p, s_k, t_k, a_c[local], b_c[local], out[k])
        return out, found

    def colliding(self, Q: np.ndarray) -> np.ndarray:
        """(K,) True where the configuration self-intersects."""
        clearance, _ = self.worst(Q)
        return np.isfinite(clearance)

    def free_intervals(self, states: np.ndarray, resolution: int = 64) -> tuple:
        """Per joint, the clear interval of its own state around ``states`` (see SweepReport).

        The range is scanned on a grid of ``resolution`` steps and each end found by 30
        bisection steps between the last clear and the first colliding grid state, so an
        interval is exact to about range / 2^30 unless a collision hides between two grid
        states.
        """
        J = len(states)
        if self.colliding(states[None, :])[0]:
            return (None,) * J
        out: list = []
        for j in range(J):
            lo, hi = self.ranges[j]
            s0 = float(states[j])
            if self.model.joint_kind[j] == 0 or hi <= lo:
                out.append((s0, s0))
                continue
            ends = []
            for target in (lo, hi):
                grid = np.linspace(s0, target, resolution + 1)[1:]
                Q = np.repeat(states[None, :], grid.size, axis=0)
                Q[:, j] = grid
                hits = np.nonzero(self.colliding(Q))[0]
                if hits.size == 0:
                    ends.append(float(target))
                    continue
                bad = float(grid[hits[0]])
                good = s0 if hits[0] == 0 else float(grid[hits[0] - 1])
                for _ in range(30):
                    mid = 0.5 * (good + bad)
                    q = states.copy()
                    q[j] = mid
                    if self.colliding(q[None, :])[0]:
                        bad = mid
                    else:
                        good = mid
                ends.append(good)
            out.append((ends[0], ends[1]))
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


def chain_clearance(chain, states=None, names=None) -> ClearanceReport:
    """The clearance of ``chain`` at its current states, or at ``states`` (one per joint).

    Parameters
    ----------
    chain : KinematicChain
    states : sequence of float, optional
        A configuration (absolute states, each within its joint's ``stateRange()``); default:
        the chain's current states. The chain is not changed.
    names : sequence of str or None, optional
        Joint names for the report.

    Raises
    ------
    InvalidParameterError
        For ``states`` of the wrong length or outside a joint's range.
    """
    engine = engine_for(chain, names)
    return engine.report(_current(chain) if states is None else states)


def sweep(
    chain,
    samples: int = 1000,
    seed: int = 0,
    configurations=None,
    *,
    names=None,
    resolution: int = 64,
) -> SweepReport:
    """Clearance over the chain's range of motion.

    Parameters
    ----------
    chain : KinematicChain
    samples : int
        Number of configurations drawn uniformly from the joints' state ranges (> 0; ignored
        when ``configurations`` is given).
    seed : int
        Seed of the random configurations (numpy ``default_rng``).
    configurations : sequence of sequences of float, optional
        The configurations to test instead (absolute states, one per joint).
    names : joint names for the report, optional.
    resolution : int
        Grid steps per joint and direction when searching the free intervals (>= 1).

    Returns
    -------
    SweepReport
        The colliding fraction, the worst pairs, and each joint's free interval around the
        chain's current states.
    """
    engine = engine_for(chain, names)
    if isinstance(resolution, bool) or not isinstance(resolution, int | np.integer):
        raise InvalidTypeError(f"resolution must be an integer >= 1, got {resolution!r}")
    if resolution < 1:
        raise InvalidParameterError(f"resolution must be an integer >= 1, got {resolution!r}")
    if configurations is None:
        if isinstance(samples, bool) or not isinstance(samples, int | np.integer):
            raise InvalidTypeError(f"samples must be an integer > 0, got {samples!r}")
        if samples <= 0:
            raise InvalidParameterError(f"samples must be an integer > 0, got {samples!r}")
        if isinstance(seed, bool) or not isinstance(seed, int | np.integer):
            raise InvalidTypeError(f"seed must be an integer, got {seed!r}")
        rng = np.random.default_rng(int(seed))
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
    clearance, pairs = engine.worst(Q)
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
    )
