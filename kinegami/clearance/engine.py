"""Self-intersection of a folded chain, at one configuration and over its range of motion.

See docs/clearance.md. The chain's parts are enclosed by capsules of radius r along its
centreline (:mod:`kinegami.chain.bodies`). Two capsules are tested only when the centreline between
them turns by at least pi in total (arc angles plus |state| at every revolute hinge): a curve
that turns by less than pi cannot come back to itself, and parts closer along the tube than
that touch by construction (the two legs of an elbow, the halves of a joint, a link and its
joints). The clearance of a tested pair is the distance between their segments minus 2r;
negative values are overlap depths. The chain is clear when every tested pair has a clearance
of at least ``margin - CONTACT_TOLERANCE * r`` (:func:`~kinegami.chain.bodies.clear_limit`): the
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

import bisect
import math
import operator
import weakref
from collections.abc import Sequence

import numpy as np

from kinegami.chain.bodies import (
    CONTACT_TOLERANCE,
    TURN_TOLERANCE,
    CapsuleModel,
    capsule_model,
    check_margin,
    clear_limit,
    with_joint_name,
)
from kinegami.clearance.reports import ClearanceReport, CollidingPair
from kinegami.clearance.tree_bodies import tree_capsules
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.geometry.screws import JointScrews
from kinegami.geometry.segments import (
    segment_distance,
    segment_distances,
    segment_distances_stacked,
)
from kinegami.limits import MAX_REPORTED_PAIRS
from kinegami.validation import (
    check_real,
)

__all__ = [
    "CONTACT_TOLERANCE",
    "TURN_TOLERANCE",
    "ClearanceEngine",
    "TreeEngine",
    "TreeMotion",
    "ChainMotion",
    "engine_for",
    "tree_engine",
    "keep_tree_engine",
    "current_states",
]

#: Pairs x configurations evaluated at once (memory bound of the batched broad phase).
_BATCH_PAIRS = 1_500_000



#: Most capsules in one group (a part's run of capsules is split into groups this long).
_GROUP_SIZE = 3

#: Group pairs above which the broad phase finds near groups per configuration with a k-d
#: tree instead of testing a precomputed list of every group pair (memory and time grow with
#: the pairs that are near, not with all pairs).
_GROUP_PAIRS_LISTED = 300_000

#: Pair-configuration entries (group pairs, moved points) one batch holds at most.
_BATCH_ENTRIES = 2_000_000
#: Capsule pair-configuration entries measured at once at most: their exact distances take
#: about 400 bytes of temporaries each (100 MiB a slice).
_PAIR_ENTRIES = 250_000

#: Pairs a one-configuration report must measure (their bounds put them closer than the
#: limit) above which it measures them at once with numpy rather than one by one in plain
#: floats (a plain-float pair costs about 6 us, numpy's kernel about 60 us whatever the few).
_ONE_BY_ONE = 16
def _in_slices(pairs: np.ndarray, lows: np.ndarray, start: int, size: int = 256):
    """(pair, bound) from index ``start`` on, as Python numbers, converted a slice at a time."""
    for a in range(start, pairs.size, size):
        yield from zip(pairs[a : a + size].tolist(), lows[a : a + size].tolist(), strict=True)


#: Entries (pairs of capsules) :meth:`ClearanceEngine._distinct_pairs` words at a time.
_DISTINCT_ENTRIES = 1_000_000

#: Measured pairs beyond which a one-configuration report keeps them as arrays, not as a
#: Python tuple each (memory: about 200 bytes a pair as tuples).
_FOUND_AS_ARRAYS = 4096
#: One-configuration reports an engine answers with numpy before it runs the compiled kernel
#: (kinegami.clearance.kernels): a single query (a command line's check) does not pay for
#: loading numba and its cached machine code (about 0.4 s); a loop of queries does, once.
COMPILED_AFTER = 16


_KERNEL: list = []  # [the compiled one-configuration kernel, or None where numba cannot run]


def _kernel():
    """:func:`kinegami.clearance.kernels.one_configuration`, loaded on first use; None where
    numba cannot be imported or cannot keep its machine code (the numpy path then answers:
    the same reports, slower)."""
    if not _KERNEL:
        try:
            from kinegami.clearance.kernels import body_motions, one_configuration
        except (ImportError, OSError, RuntimeError):  # no numba, or no cache it can write
            body_motions = one_configuration = None
        _KERNEL.extend((one_configuration, body_motions))
    return _KERNEL[0]


def _compiled_motions(screws, q: np.ndarray) -> np.ndarray:
    """``screws.body_motions_one(q)`` by the compiled kernel
    (:func:`kinegami.clearance.kernels.body_motions`: the same bits; sin and cos are numpy's,
    as there); call only where :func:`_kernel` is not None."""
    moving = screws.moving
    delta = q.take(moving) - screws.q_ref.take(moving)
    K1, K2 = screws.rotation_generators
    return _KERNEL[1](delta, np.sin(delta), 1.0 - np.cos(delta), K1, K2, screws.points,
                      screws.axes, screws.revolute, screws.body_parent)  # fmt: skip


class _Layout:
    """Points that move with rigid bodies, sorted by body so that each body's are one slice:
    ``column[p]`` is where point p lands in :meth:`move`'s arrays."""

    def __init__(self, points: np.ndarray, body: np.ndarray):
        order = np.argsort(body, kind="stable")
        self.column = np.empty(order.size, dtype=np.int64)
        self.column[order] = np.arange(order.size)
        sorted_body = body[order]
        cuts = np.flatnonzero(np.r_[True, sorted_body[1:] != sorted_body[:-1]]) \
            if order.size else np.zeros(0, dtype=np.int64)  # fmt: skip
        ends = np.r_[cuts[1:], order.size] if order.size else cuts  # no points: no slices
        self.slices = [(int(sorted_body[a]), int(a), int(b), points[order[a:b]])
                       for a, b in zip(cuts, ends, strict=True)]  # fmt: skip
        self.size = order.size
        self.body = sorted_body
        self.points = points[order]

    def move(self, B: np.ndarray) -> np.ndarray:
        """x, y and z of every point (3, K, size), moved by the body motions ``B``
        (K, NB, 4, 4)."""
        K = B.shape[0]
        out = np.empty((3, K, self.size))
        if K * len(self.slices) <= 64:  # few configurations: every point's motion gathered
            M = B.reshape(K, -1, 16)[:, self.body]
            P = self.points
            for c in range(3):
                out[c] = M[..., 4 * c] * P[:, 0] + M[..., 4 * c + 1] * P[:, 1] \
                    + M[..., 4 * c + 2] * P[:, 2] + M[..., 4 * c + 3]  # fmt: skip
            return out
        for b, lo, hi, P in self.slices:
            if b == 0:  # the base does not move
                for c in range(3):
                    out[c][:, lo:hi] = P[:, c]
                continue
            R = B[:, b, :3, :, None]
            for c in range(3):
                out[c][:, lo:hi] = R[:, c, 0] * P[:, 0] + R[:, c, 1] * P[:, 1] \
                    + R[:, c, 2] * P[:, 2] + R[:, c, 3]  # fmt: skip
        return out


def _moved(M: np.ndarray, row: np.ndarray, points: np.ndarray) -> tuple:
    """x, y and z of ``points`` (n, 3) moved by the motions ``M[row]`` (rows of 16: flattened
    4x4), the same arithmetic as :meth:`_Layout.move`."""
    T = M[row]
    return tuple(T[:, 4 * c] * points[:, 0] + T[:, 4 * c + 1] * points[:, 1]
                 + T[:, 4 * c + 2] * points[:, 2] + T[:, 4 * c + 3] for c in range(3))  # fmt: skip


class _OneConfiguration:
    """The arrays of :meth:`ClearanceEngine._report_one`, built once per engine: the listed
    capsule pairs (indices, flat indices of their capsule centres' coordinates and of their
    end points' coordinates, twice their half lengths added up, tie order), the pairs whose
    test by the turning rule depends on the configuration, the static pairs in a report's
    order, and the end points (homogeneous) with their bodies."""

    def __init__(self, engine: ClearanceEngine):
        e = engine
        S = e._S
        entry = np.repeat(np.arange(e._gp1.size), e._cp_count)
        i, j = e._cp_i, e._cp_j
        # a pair on one path whose turning apart at the current states is below pi (with room
        # for rounding) is tested at some configurations only ("maybe"); the others always:
        # the hinge turning up to the farther part is never less than up to the nearer. The
        # pairs tested always come first (the ``sure`` first), then the maybe ones.
        same = e._gp_same[entry]
        turn = e._turning[j] - e._turning[i]
        maybe = same & (np.abs(turn) < math.pi - TURN_TOLERANCE + 1e-9)
        order = np.r_[np.flatnonzero(~maybe), np.flatnonzero(maybe)]
        i, j, turn = i[order], j[order], turn[order]
        self.sure = int(order.size - np.count_nonzero(maybe))
        self.pairs = int(i.size)
        self.pi, self.pj = i.tolist(), j.tolist()
        # flat indices of the capsule centres' coordinates in (3, S) (rows x, y, z), (3,
        # pairs); the pairs' capsules, (2, pairs); flat indices of every pair's four end
        # points' coordinates in (3, 2S), (4, 3, pairs)
        xyz = np.arange(3)[:, None]
        self.centre_i, self.centre_j = S * xyz + i[None, :], S * xyz + j[None, :]
        self.pair_ij = np.stack([i, j])
        self.ends = 2 * S * xyz[None] + np.stack([i, S + i, j, S + j])[:, None, :]
        self.twice_half = 2.0 * (e._half[i] + e._half[j])
        self.rank = e._rank(i, j).tolist()
        tail = slice(self.sure, None)
        self.maybe_turn = turn[tail]
        self.maybe_bi, self.maybe_bj = e.body_a[i[tail]], e.body_a[j[tail]]
        self.maybe_lists = (self.maybe_turn.tolist(), self.maybe_bi.tolist(),
                            self.maybe_bj.tolist())  # fmt: skip
        # the turning the revolute hinges add up to every body (ClearanceEngine._kinks)
        self.kink_joints = [int(m) if rev else -1 for m, rev in
                            zip(e.movable.tolist(), e._revolute_b.tolist(), strict=True)]
        self.kink_parents = None if e._chain_bodies else e._body_parent.tolist()
        # the states' bounds (ClearanceEngine.check_states' test)
        self.state_bounds = ((e.ranges[:, 0] - 1e-12).tolist(), (e.ranges[:, 1] + 1e-12).tolist())
        order = np.lexsort((e._static_rank, e._static_clearance))
        si, sj = e._static_pairs
        self.static_count = int(order.size)
        self.static_sorted = e._static_clearance[order]
        # (the closest static clearance, (N, 2) the pairs in order): an array, as a list of
        # millions of pairs took gigabytes (fuzz operations seed 402187: 6.2 million)
        self.static_first = (float(self.static_sorted[0]) if order.size else math.inf,
                             np.stack([si[order], sj[order]], axis=1))
        self._static_chain = e._caps is None
        # kept as arrays, a key made when asked: a list of every static pair's key took
        # gigabytes on a design of many parts (a MemoryError the fuzzer found)
        self._static_s = e._static_st[0][order]
        self._static_t = e._static_st[1][order]
        self._static_ranks = e._static_rank[order]
        points = np.concatenate([e._starts, e._ends])
        # (1, 4, 2S): every end point, homogeneous, coordinate by coordinate
        self.points = np.concatenate([points, np.ones((2 * S, 1))], axis=1).T[None].copy()
        self.rows = np.concatenate([e.body_a, e.body_b])
        self.slack = 1e-9 * (e._extent() + e.r)
        self.none = np.zeros(0, dtype=np.int64)
        self._taken: dict[float, int] = {}  # static_taken's answers by limit
        self.queries = 0  # one-configuration reports asked so far
        self.compiled: tuple | None = None  # the kernel's arrays, made on its first use

    def kernel_arrays(self, engine: ClearanceEngine) -> tuple:
        """The fixed arguments of :func:`kinegami.clearance.kernels.one_configuration`."""
        if self.compiled is None:
            e = engine
            pairs = self.pair_ij
            self.compiled = (
                np.ascontiguousarray(self.rows, dtype=np.int64),
                np.ascontiguousarray(np.concatenate([e._starts, e._ends]), dtype=float),
                np.ascontiguousarray(pairs[0], dtype=np.int64),
                np.ascontiguousarray(pairs[1], dtype=np.int64),
                np.ascontiguousarray(self.twice_half, dtype=float),
                self.sure,
                np.ascontiguousarray(self.maybe_turn, dtype=float),
                np.ascontiguousarray(self.maybe_bi, dtype=np.int64),
                np.ascontiguousarray(self.maybe_bj, dtype=np.int64),
                np.array(self.kink_joints, dtype=np.int64),
                np.array(self.kink_parents if self.kink_parents is not None else [],
                         dtype=np.int64),  # fmt: skip
            )
        return self.compiled

    def static_taken(self, limit: float) -> int:
        """How many static pairs (in their order) a report with ``limit`` lists: those closer
        than the limit, at least the closest (none without static pairs); kept for the last
        few limits."""
        if not self.static_count:
            return 0
        take = self._taken.get(limit)
        if take is None:
            take = max(1, int(np.searchsorted(self.static_sorted, limit)))
            if len(self._taken) >= 8:
                self._taken.clear()
            self._taken[limit] = take
        return take

    def static_key(self, n: int) -> tuple:
        """The report's sort key of the n-th static pair (in their order)."""
        c, rank = float(self.static_sorted[n]), int(self._static_ranks[n])
        s, t = float(self._static_s[n]), float(self._static_t[n])
        return (c, 1, rank, -n - 1, s, t) if self._static_chain else (c, rank, 1, -n - 1, s, t)

    def kinks(self, values) -> list:
        """:meth:`ClearanceEngine._kinks` at one configuration (``values``: its states), in
        plain floats: the same sums in the same order, so the same bits."""
        add = [abs(values[m]) if m >= 0 else 0.0 for m in self.kink_joints]
        out = [0.0]
        if self.kink_parents is None:  # a chain's bodies: a running sum (numpy.cumsum's)
            total = 0.0
            for a in add:  # 0.0 + a is a: every a is >= 0
                total += a
                out.append(total)
            return out
        parent = self.kink_parents
        for b in range(1, len(parent)):
            out.append(out[parent[b]] + add[b - 1])
        return out


class ClearanceEngine:
    """Fast clearance queries on one chain (its joints and links as they were when built).

    Configurations are absolute states, one per joint, as ``setJointStates`` takes them.

    The capsules are grouped into rigid bodies (the parts between two movable joints), and
    within a body into *groups* (the capsules of one part that move together). Pairs inside
    one body never move relative to each other, so they are measured once. For the others, a
    ball around each group (fixed in its body) is the broad phase; the capsules of two groups
    whose balls are close are then tested capsule ball against capsule ball, and exactly
    (segment distance) when those are close too. Every step is batched over configurations
    (docs/clearance.md, "The engine").
    """

    def __init__(self, chain, names=None):
        from kinegami.chain.model import KinematicChain

        if not isinstance(chain, KinematicChain):
            raise InvalidTypeError(f"chain must be a KinematicChain, got {type(chain).__name__}")
        self.model: CapsuleModel = capsule_model(chain, names)
        m = self.model
        joints = chain.Joints
        self._setup(
            r=m.r, starts=m.starts, ends=m.ends, start_joint=m.start_body, end_joint=m.end_body,
            turning=m.turning, element=m.element, parents=np.arange(len(joints)) - 1,
            kinds=m.joint_kind, points=m.joint_point, axes=m.joint_axis, states=m.states,
            ranges=np.array([joint.stateRange() for joint in joints], dtype=float),
            pieces=[(np.asarray(b, dtype=float), labels) for b, labels in m.pieces],
            lengths=[float(np.linalg.norm(m.ends[s] - m.starts[s])) for s in range(m.count)],
        )  # fmt: skip

    # --- set-up ----------------------------------------------------------------------------
    def _setup(self, *, r, starts, ends, start_joint, end_joint, turning, element, parents,
               kinds, points, axes, states, ranges, pieces, lengths,
               caps=None) -> None:  # fmt: skip
        """Everything the queries need, from the capsules at the current configuration
        (``caps``: a tree's :class:`~kinegami.clearance.tree_bodies.TreeCapsules`, None for a
        chain)."""
        self.r = r = float(r)
        self.ranges = ranges
        self._caps = caps
        self._starts, self._ends = starts, ends
        self._turning = turning
        self._pieces, self._lengths = pieces, np.asarray(lengths, dtype=float)
        self._pieces_listed = [(b.tolist(), labels) for b, labels in pieces]
        self._lengths_listed = self._lengths.tolist()
        self._element = element
        self._states = np.asarray(states, dtype=float)
        S = starts.shape[0]
        self._S = S
        # rigid bodies: the base (0) and one per movable joint, in joint order, moved by the
        # one forward kinematics (kinegami.geometry.screws)
        screws = JointScrews(kinds, axes, points, parents, self._states)
        self.screws = screws
        body_of = screws.body_of
        body_parent = screws.body_parent
        NB = screws.bodies
        self.bodies = NB
        self.movable = screws.moving
        self._body_parent = body_parent
        self._chain_bodies = screws.chain_bodies
        bj = self.movable
        self._revolute_b = screws.revolute
        self._any_revolute = bool(self._revolute_b.any())
        self._all_revolute = screws.all_revolute
        self._hinge_point, self._axis = screws.points, screws.axes

        def body(joint_index: np.ndarray) -> np.ndarray:
            return np.where(joint_index >= 0, body_of[np.maximum(joint_index, 0)], 0)

        ba, bb = body(np.asarray(start_joint)), body(np.asarray(end_joint))
        self.body_a, self.body_b = ba, bb
        # most turning the hinges up to each body can add
        max_kink = np.where(self._revolute_b, np.max(np.abs(ranges[bj]), axis=1), 0.0) \
            if bj.size else np.zeros(0)  # fmt: skip
        kink_max = np.zeros(NB)
        for b in range(1, NB):
            kink_max[b] = kink_max[body_parent[b]] + max_kink[b - 1]
        # groups: runs of capsules of one part with the same bodies at both ends; a capsule
        # whose end slides (prismatic) is a group of its own with a ball over the stroke
        spanning = ba != bb
        if S:
            change = np.r_[True, (element[1:] != element[:-1]) | (ba[1:] != ba[:-1])
                           | (bb[1:] != bb[:-1]) | spanning[1:] | spanning[:-1]]  # fmt: skip
        else:
            change = np.zeros(0, dtype=bool)
        if S and _GROUP_SIZE:  # and at most _GROUP_SIZE capsules each
            run = np.cumsum(change) - 1
            within = np.arange(S) - np.flatnonzero(change)[run]
            change |= within % _GROUP_SIZE == 0
        gstart = np.flatnonzero(change)
        gsize = np.diff(np.r_[gstart, S])
        G = gstart.size
        lo_pts = np.minimum(starts, ends)
        hi_pts = np.maximum(starts, ends)
        stroke = [np.zeros((0, 3))] * 2
        if spanning.any():
            sp = np.flatnonzero(spanning)
            j = np.asarray(end_joint)[sp]
            ext = ranges[j] - self._states[j][:, None]
            stroke = [ends[sp] + ext[:, 0:1] * axes[j], ends[sp] + ext[:, 1:2] * axes[j]]
            lo_pts[sp] = np.minimum(lo_pts[sp], np.minimum(*stroke))
            hi_pts[sp] = np.maximum(hi_pts[sp], np.maximum(*stroke))
        # half lengths (a sliding capsule's: the most its end can reach from its centre)
        self._half = 0.5 * np.sqrt(((ends - starts) ** 2).sum(axis=1))
        if spanning.any():
            self._half[sp] += np.abs(ext).max(axis=1)
        if G:
            centre = 0.5 * (np.minimum.reduceat(lo_pts, gstart, axis=0)
                            + np.maximum.reduceat(hi_pts, gstart, axis=0))  # fmt: skip
            owner = np.repeat(np.arange(G), gsize)
            far = np.maximum(np.sqrt(((starts - centre[owner]) ** 2).sum(axis=1)),
                             np.sqrt(((ends - centre[owner]) ** 2).sum(axis=1)))  # fmt: skip
            if spanning.any():
                for p in stroke:
                    far[sp] = np.maximum(far[sp], np.sqrt(((p - centre[owner[sp]]) ** 2).sum(1)))
            radius = np.maximum.reduceat(far, gstart) + r
            tau_lo = np.minimum.reduceat(turning, gstart)
            tau_hi = np.maximum.reduceat(turning, gstart)
        else:
            centre, radius, tau_lo, tau_hi = np.zeros((0, 3)), np.zeros(0), np.zeros(0), np.zeros(0)
            owner = np.zeros(0, dtype=np.int64)
        self._gstart, self._gsize = gstart, gsize
        self._spanning = bool(spanning.any())
        self._gcentre, self._gradius = centre, radius
        self._gbody = ba[gstart]
        self._gbody_end = bb[gstart]  # differs from _gbody for a sliding capsule's group
        self._gspan = spanning[gstart]
        self._body_of = body_of
        self._affected_by: dict[int, np.ndarray] = {}
        self._closest_ever = None  # _closest_over_motion, on first use
        self._reach_cache: dict[float, tuple] = {}
        self._reach_slack = 1e-9 * (float(np.abs(centre).max()) + float(radius.max())) \
            if G else 0.0  # fmt: skip
        node = (element + 1) // 2
        self._gnode = node[gstart]
        self._gtau_lo, self._gtau_hi = tau_lo, tau_hi
        self._gkink = kink_max[self._gbody]
        self._ancestor = None if caps is None else caps.ancestor
        # the k-d tree broad phase searches within twice the radius of most groups; the
        # largest tenth is tested against every group
        self._radius_cut = float(np.quantile(radius, 0.9)) if G else 0.0
        self._is_large = radius > self._radius_cut
        self._large_groups = np.flatnonzero(self._is_large)
        self._small_groups = np.flatnonzero(~self._is_large)
        # tie order of pairs at equal clearance (as the one-configuration answers list them)
        blocks = np.cumsum(np.r_[True, element[1:] != element[:-1]]) - 1 if S else owner
        self._block, self._blocks = blocks, int(blocks[-1]) + 1 if S else 0
        # the points the queries move, sorted by body: segment ends; capsule and group centres
        self._end_points = _Layout(np.concatenate([starts, ends]), np.concatenate([ba, bb]))
        self._centres = _Layout(np.concatenate([0.5 * (starts + ends), centre]),
                                np.concatenate([ba, self._gbody]))  # fmt: skip
        self._ccol = self._centres.column[:S]
        self._gcol = self._centres.column[S:]
        # group pairs: listed when few, else found per configuration
        G2 = G * (G + 1) // 2
        self._listed = G2 <= _GROUP_PAIRS_LISTED
        static_groups = []
        if self._listed:
            g1, g2 = np.triu_indices(G)
            feasible = self._feasible(g1, g2)
            static = feasible & self._same_body(g1, g2)
            static_groups.append((g1[static], g2[static]))
            dynamic = feasible & ~static & (g1 != g2)
            self._gp1, self._gp2 = g1[dynamic], g2[dynamic]
            self._gp_same = self._same_path(self._gp1, self._gp2)
            self._list_capsule_pairs(kink_max)
        else:
            for b in np.unique(self._gbody):
                gs = np.flatnonzero(self._gbody == b)
                a1, a2 = np.triu_indices(gs.size)
                g1, g2 = gs[a1], gs[a2]
                ok = self._feasible(g1, g2) & self._same_body(g1, g2)
                static_groups.append((g1[ok], g2[ok]))
        self._static_pairs_from(static_groups)

    def _list_capsule_pairs(self, kink_max: np.ndarray) -> None:
        """The capsule pairs of every listed group pair that the rule may test at some
        configuration (as :meth:`_feasible`, capsule by capsule), grouped by group pair; group
        pairs left without one are dropped."""
        i, j, entry = self._expand(self._gp1, self._gp2)
        same = self._gp_same[entry]
        gap = self._turning[j] - self._turning[i] + kink_max[self.body_a[j]] \
            - kink_max[self.body_a[i]]  # fmt: skip
        ok = ~same | (gap >= math.pi - TURN_TOLERANCE)
        i, j, entry = i[ok], j[ok], entry[ok]
        count = np.bincount(entry, minlength=self._gp1.size)
        used = count > 0
        self._gp1, self._gp2 = self._gp1[used], self._gp2[used]
        self._gp_same = self._gp_same[used]
        self._cp_count = count[used]
        self._cp_offset = np.cumsum(self._cp_count) - self._cp_count
        self._cp_i, self._cp_j = i, j

    def _same_path(self, g1: np.ndarray, g2: np.ndarray) -> np.ndarray:
        """Whether groups g1, g2 lie on one path from the root (always, in a chain)."""
        if self._ancestor is None:
            return np.ones(g1.shape, dtype=bool)
        n1, n2 = self._gnode[g1], self._gnode[g2]
        return self._ancestor[n1, n2] | self._ancestor[n2, n1]

    def _feasible(self, g1: np.ndarray, g2: np.ndarray) -> np.ndarray:
        """Group pairs (g1 <= g2) that hold a pair the rule may test at some configuration:
        on different branches, or turning by up to pi or more between them."""
        gap = (self._gtau_hi[g2] - self._gtau_lo[g1] + self._gkink[g2] - self._gkink[g1])
        return (gap >= math.pi - TURN_TOLERANCE) | ~self._same_path(g1, g2)

    def _same_body(self, g1: np.ndarray, g2: np.ndarray) -> np.ndarray:
        """Group pairs that never move relative to each other."""
        return (self._gbody[g1] == self._gbody[g2]) & ~self._gspan[g1] & ~self._gspan[g2]

    def _expand(self, g1: np.ndarray, g2: np.ndarray, k: np.ndarray | None = None):
        """Capsule pairs (i < j) of group pairs (g1 <= g2), with their entry's index."""
        n1, n2 = self._gsize[g1], self._gsize[g2]
        count = n1 * n2
        total = int(count.sum())
        entry = np.repeat(np.arange(g1.size), count)
        q = np.arange(total) - np.repeat(np.cumsum(count) - count, count)
        n2r = n2[entry]
        i = self._gstart[g1][entry] + q // n2r
        j = self._gstart[g2][entry] + q % n2r
        keep = i < j
        return i[keep], j[keep], entry[keep]

    def _static_pairs_from(self, groups: list) -> None:
        """Measure the pairs inside rigid bodies once (a tree's junction pairs beyond their
        junctions)."""
        si, sj = [], []
        for g1, g2 in groups:
            for start in range(0, g1.size, 4096):
                i, j, _ = self._expand(g1[start : start + 4096], g2[start : start + 4096])
                same = self._pair_same_path(i, j)
                ok = ~same | (self._turning[j] - self._turning[i] >= math.pi - TURN_TOLERANCE)
                si.append(i[ok])
                sj.append(j[ok])
        i = np.concatenate(si) if si else np.zeros(0, dtype=np.int64)
        j = np.concatenate(sj) if sj else np.zeros(0, dtype=np.int64)
        order = np.lexsort((j, i))
        i, j = i[order], j[order]
        del order, si, sj
        # measured a bounded number at a time: a tree folded onto itself had 6.2 million
        d, s, t = np.empty(i.size), np.empty(i.size), np.empty(i.size)
        for a in range(0, i.size, _PAIR_ENTRIES):
            b = slice(a, a + _PAIR_ENTRIES)
            d[b], s[b], t[b] = segment_distances(self._starts[i[b]], self._ends[i[b]],
                                                 self._starts[j[b]], self._ends[j[b]])  # fmt: skip
            if self._caps is not None:
                q = a + np.flatnonzero(self._caps.junction_pairs(i[b], j[b]))
                if q.size:
                    d[q], s[q], t[q] = self._caps.beyond_junction(i[q], j[q])
        self._static_pairs = (i, j)
        self._static_clearance = d - 2.0 * self.r
        self._static_st = (s, t)
        self._static_rank = self._rank(i, j, static=True)
        self._static_best = None
        self._one = None  # the one-configuration path's arrays (_one_arrays)
        if i.size:
            self._static_best = int(np.lexsort((self._static_rank, self._static_clearance))[0])

    def _pair_same_path(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        if self._ancestor is None:
            return np.ones(i.shape, dtype=bool)
        n1, n2 = (self._element[i] + 1) // 2, (self._element[j] + 1) // 2
        return self._ancestor[n1, n2] | self._ancestor[n2, n1]

    def _rank(self, i: np.ndarray, j: np.ndarray, static: bool = False) -> np.ndarray:
        """The order in which pairs at equal clearance are taken (the one-configuration
        answers' order): a chain's static pairs in their own order, the others by the bodies'
        pair and then the capsules; a tree's all by parts, then capsules."""
        S = max(self._S, 1)
        if self._caps is None:
            if static:
                return np.arange(i.size, dtype=np.int64)
            b1, b2 = self.body_a[i], self.body_a[j]
            code = np.minimum(b1, b2) * self.bodies + np.maximum(b1, b2)
            return (code * S + i) * S + j
        return ((self._block[i] * self._blocks + self._block[j]) * S + i) * S + j

    # --- kinematics ------------------------------------------------------------------------
    def check_states(self, states, name: str = "states") -> np.ndarray:
        """``states`` as a float array (one per joint, each within its range), or raise."""
        return _checked_states(states, self.ranges, name)

    def body_transforms(self, Q: np.ndarray) -> np.ndarray:
        """(K, bodies, 4, 4): world motion of every rigid body (0 = base) at each of the
        configurations ``Q`` (K, J), relative to the current configuration."""
        return self.screws.body_motions(Q)

    def _segments_at(self, B: np.ndarray, k: int) -> tuple[np.ndarray, np.ndarray]:
        """Segment starts and ends (S, 3) at configuration k of the body motions ``B``."""
        S = self._S
        W = np.stack(self._end_points.move(B[k : k + 1]), axis=-1)[0, self._end_points.column]
        return W[:S], W[S:]

    def segments(self, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """World segment end points (K, S, 3) twice, at configurations ``Q`` (K, J)."""
        layout = self._end_points
        W = np.stack(layout.move(self.body_transforms(self._configurations(Q))), axis=-1)
        W = W[:, layout.column]
        S = self._S
        return W[:, :S], W[:, S:]

    def _kinks(self, Q: np.ndarray) -> np.ndarray:
        """(K, bodies): the turning the revolute hinges add up to every body."""
        K, NB = Q.shape[0], self.bodies
        add = np.where(self._revolute_b[None, :], np.abs(Q[:, self.movable]), 0.0)
        if self._chain_bodies:
            return np.concatenate([np.zeros((K, 1)), np.cumsum(add, axis=1)], axis=1)
        out = np.zeros((K, NB))
        for b in range(1, NB):
            out[:, b] = out[:, self._body_parent[b]] + add[:, b - 1]
        return out

    def turning(self, Q: np.ndarray) -> np.ndarray:
        """(K, S) turning of the centreline up to every segment at configurations ``Q``."""
        Q = self._configurations(Q)
        return self._turning[None, :] + self._kinks(Q)[:, self.body_a]

    def _configurations(self, Q) -> np.ndarray:
        """``Q`` as a float array (a tree's states clamped into their ranges)."""
        Q = np.asarray(Q, dtype=float)
        if self._caps is not None:
            Q = np.clip(Q, self.ranges[:, 0], self.ranges[:, 1])
        return Q

    # --- the core query --------------------------------------------------------------------
    def _affected(self, joint: int) -> np.ndarray:
        """The listed group pairs that move relative to each other when joint ``joint`` alone
        moves: one group beyond it (in its body's subtree) and the other not, or a sliding
        capsule's group whose ends lie on both sides."""
        if joint not in self._affected_by:
            NB = self.bodies
            inside = np.zeros(NB, dtype=bool)
            b = int(self._body_of[joint])
            inside[b] = True
            for c in range(b + 1, NB):  # parents come before their children
                inside[c] = inside[self._body_parent[c]]
            start, end = inside[self._gbody], inside[self._gbody_end]
            mixed = start != end
            g1, g2 = self._gp1, self._gp2
            pairs = np.flatnonzero(mixed[g1] | mixed[g2] | (start[g1] != start[g2]))
            # the closest the two group centres come while the joint alone moves, at any
            # state: the one inside turns about (slides along) the joint's axis
            g1, g2 = g1[pairs], g2[pairs]
            inner = np.where(start[g1], g1, g2)
            outer = np.where(start[g1], g2, g1)
            m = int(np.flatnonzero(self.movable == joint)[0])
            axis = self._axis[m]
            u = self._gcentre[inner] - self._hinge_point[m]
            w = self._gcentre[outer] - self._hinge_point[m]
            along = u @ axis
            if self._revolute_b[m]:
                across = u - along[:, None] * axis
                cos_part = np.einsum("ij,ij->i", across, w)
                sin_part = np.einsum("ij,ij->i", np.cross(axis, across), w)
                low = np.einsum("ij,ij->i", u, u) + np.einsum("ij,ij->i", w, w) \
                    - 2.0 * along * (w @ axis) - 2.0 * np.hypot(cos_part, sin_part)  # fmt: skip
            else:
                d = u - w
                low = np.einsum("ij,ij->i", d, d) - (d @ axis) ** 2
            closest = np.sqrt(np.maximum(low, 0.0))
            closest[mixed[g1] | mixed[g2]] = -math.inf  # a sliding capsule's group: always
            self._affected_by[joint] = (pairs, closest - self._gradius[g1] - self._gradius[g2])
        return self._affected_by[joint]

    def _reachable(self, threshold: float) -> tuple:
        """The listed group pairs whose balls can come within ``threshold`` at some
        configuration (with their centres' columns and their reach): the others never come
        near. Over any motion, a group lies within a ball about the hinge of the first joint
        between it and the two groups' deepest common body, fixed in that body: its radius
        is the distance from the group's centre to its own body's hinge plus the distances
        between the hinges on the way and the strokes of the sliding joints there."""
        cached = self._reach_cache.get(threshold)
        if cached is None:
            if self._closest_ever is None:
                self._closest_ever = self._closest_over_motion()
            sub = np.flatnonzero(self._closest_ever <= threshold + self._reach_slack)
            g1, g2 = self._gp1[sub], self._gp2[sub]
            reach = self._gradius[g1] + self._gradius[g2] + threshold
            cached = (sub, self._gcol[g1], self._gcol[g2], reach)
            if len(self._reach_cache) < 8:
                self._reach_cache[threshold] = cached
        return cached

    def _closest_over_motion(self) -> np.ndarray:
        """For every listed group pair, a lower bound of the gap between their balls over
        every configuration (see :meth:`_reachable`; -inf for a sliding capsule's group)."""
        NB, parent = self.bodies, self._body_parent
        hinge = np.vstack([np.zeros((1, 3)), self._hinge_point])
        stroke = np.zeros(NB)
        slides = np.flatnonzero(~self._revolute_b)
        if slides.size:
            j = self.movable[slides]
            stroke[slides + 1] = np.abs(self.ranges[j] - self._states[j][:, None]).max(axis=1)
        depth = np.zeros(NB, dtype=np.int64)
        along = np.zeros(NB)  # hinge to hinge from the first movable body on the way
        strokes = np.zeros(NB)
        for b in range(1, NB):
            p = int(parent[b])
            depth[b] = depth[p] + 1
            along[b] = along[p] + (float(np.linalg.norm(hinge[b] - hinge[p])) if p else 0.0)
            strokes[b] = strokes[p] + stroke[b]
        g1, g2 = self._gp1, self._gp2
        b1, b2 = self._gbody[g1], self._gbody[g2]
        x1, x2 = b1.copy(), b2.copy()
        while True:  # the deepest common body
            up1, up2 = depth[x1] > depth[x2], depth[x2] > depth[x1]
            if not (up1.any() or up2.any()):
                break
            x1, x2 = np.where(up1, parent[x1], x1), np.where(up2, parent[x2], x2)
        while True:
            differ = x1 != x2
            if not differ.any():
                break
            x1, x2 = np.where(differ, parent[x1], x1), np.where(differ, parent[x2], x2)
        common = x1

        def ball(g: np.ndarray, b: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
            first = b.copy()  # the body after the common one on the way to b
            while True:
                up = (first != common) & (parent[np.maximum(first, 0)] != common)
                if not up.any():
                    break
                first = np.where(up, parent[first], first)
            centre = self._gcentre[g]
            moves = b != common
            radius = np.where(moves, np.sqrt(((centre - hinge[b]) ** 2).sum(axis=1))
                              + along[b] - along[first] + strokes[b] - strokes[common], 0.0)
            return np.where(moves[:, None], hinge[first], centre), radius  # fmt: skip

        c1, r1 = ball(g1, b1)
        c2, r2 = ball(g2, b2)
        gap = np.sqrt(((c1 - c2) ** 2).sum(axis=1)) - r1 - r2 - self._gradius[g1] \
            - self._gradius[g2]  # fmt: skip
        gap[self._gspan[g1] | self._gspan[g2]] = -math.inf
        return gap

    def _near_groups(self, xyz: np.ndarray, threshold: float, moving=None):
        """(k, g1, g2, same path, n): the pairs of groups that move relative to each other
        (and may be tested) whose balls come within ``threshold`` at configuration k (n: their
        index in the list, when listed). ``moving`` (listed engines): per configuration, the
        joint in which it differs from a clear configuration; only the group pairs that joint
        moves relative to each other are tested there (see :meth:`worst_arrays`)."""
        radius = self._gradius
        if self._listed and moving is not None:
            kk, n = [], []
            slack = 1e-9 * (float(np.abs(self._gcentre).max()) + float(radius.max()))
            for joint in np.unique(moving).tolist():
                rows = np.flatnonzero(moving == joint)
                pairs, gap = self._affected(joint)
                pairs = pairs[gap <= threshold + slack]  # the others never come near
                kk.append(np.repeat(rows, pairs.size))
                n.append(np.tile(pairs, rows.size))
            kk, n = np.concatenate(kk), np.concatenate(n)
            g1, g2 = self._gp1[n], self._gp2[n]
            P = xyz.shape[2]
            flat = xyz.reshape(3, -1)
            d = flat.take(kk * P + self._gcol[g1], axis=1) \
                - flat.take(kk * P + self._gcol[g2], axis=1)  # fmt: skip
            reach = radius[g1] + radius[g2] + threshold
            near = np.flatnonzero(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= reach * reach)
            n = n[near]
            return kk[near], g1[near], g2[near], self._gp_same[n], n
        if self._listed:
            sub, c1, c2, reach = self._reachable(threshold)
            d = [np.take(c, c1, axis=1) - np.take(c, c2, axis=1) for c in xyz]
            kk, m = np.nonzero(d[0] * d[0] + d[1] * d[1] + d[2] * d[2] <= reach * reach)
            n = sub[m]
            return kk, self._gp1[n], self._gp2[n], self._gp_same[n], n
        from scipy.spatial import cKDTree

        large = self._large_groups
        cut = self._radius_cut
        out_k, out_1, out_2 = [], [], []
        for k in range(xyz[0].shape[0]):
            centres = np.stack([c[k, self._gcol] for c in xyz], axis=-1)
            small = self._small_groups
            pairs = cKDTree(centres[small]).query_pairs(2.0 * cut + threshold,
                                                        output_type="ndarray")  # fmt: skip
            a, b = small[pairs[:, 0]], small[pairs[:, 1]]
            if large.size:  # the largest groups against every group
                d = centres[large][:, None, :] - centres[None, :, :]
                reach = radius[large][:, None] + radius[None, :] + threshold
                n1, n2 = np.nonzero(np.einsum("lgi,lgi->lg", d, d) <= reach * reach)
                n1 = large[n1]
                keep = (n1 != n2) & ~(self._is_large[n2] & (n2 < n1))  # each pair once
                a, b = np.concatenate([a, n1[keep]]), np.concatenate([b, n2[keep]])
            g1, g2 = np.minimum(a, b), np.maximum(a, b)
            d = centres[g1] - centres[g2]
            near = np.sqrt(np.einsum("gi,gi->g", d, d)) - radius[g1] - radius[g2] <= threshold
            near &= self._feasible(g1, g2) & ~self._same_body(g1, g2)
            out_k.append(np.full(int(near.sum()), k))
            out_1.append(g1[near])
            out_2.append(g2[near])
        g1, g2 = np.concatenate(out_1), np.concatenate(out_2)
        return np.concatenate(out_k), g1, g2, self._same_path(g1, g2), None

    def _candidates(self, Q: np.ndarray, threshold: float, moving=None):
        """Exact clearances of the tested pairs that move relative to each other and whose
        capsule balls are within ``threshold`` of each other, at configurations ``Q`` (K, J).

        Returns (k, i, j, clearance, s, t, B): configuration and capsule indices, the
        clearance and closest-point parameters of each such pair, and the body transforms.
        ``moving``: as in :meth:`worst_arrays`.
        """
        B, parts = self._candidate_slices(Q, threshold, moving)
        parts = list(parts)
        if not parts:
            none = np.zeros(0, dtype=np.int64)
            return none, none, none, np.zeros(0), np.zeros(0), np.zeros(0), B
        return (*(np.concatenate(column) for column in zip(*parts, strict=True)), B)

    def _candidate_slices(self, Q: np.ndarray, threshold: float, moving=None) -> tuple:
        """(B, slices): the body transforms at ``Q`` and an iterator of (k, i, j, clearance,
        s, t), :meth:`_candidates`'s answer in order, a bounded number of capsule pairs
        (:data:`_PAIR_ENTRIES`) at a time, so that memory stays bounded however many pairs
        come near (a caller that keeps only a few of each slice holds no more)."""
        B = self.body_transforms(Q)
        if self._listed and self._gp1.size == 0:
            return B, iter(())
        xyz = self._centres.move(B)
        kk, g1, g2, same, n_gp = self._near_groups(xyz, threshold, moving)
        if kk.size == 0:
            return B, iter(())
        if self._listed:  # cut where the capsule pairs so far pass the batch
            total = np.cumsum(self._cp_count[n_gp])
            cuts = np.searchsorted(total, np.arange(1, int(total[-1]) // _PAIR_ENTRIES + 1)
                                   * _PAIR_ENTRIES, side="right")  # fmt: skip
            bounds = np.unique(np.r_[0, np.maximum(cuts, 1), kk.size]).tolist()
        else:  # many groups: at most the batch in capsule pairs of the largest groups
            step = max(1, _PAIR_ENTRIES // int(max(self._gsize.max(), 1) ** 2))
            bounds = [*range(0, kk.size, step), kk.size]
        slices = (self._pairs_of(Q, B, xyz, threshold, kk[a:b], g1[a:b], g2[a:b], same[a:b],
                                 None if n_gp is None else n_gp[a:b])
                  for a, b in zip(bounds[:-1], bounds[1:], strict=True))  # fmt: skip
        return B, slices

    def _pairs_of(self, Q, B, xyz, threshold: float, kk, g1, g2, same, n_gp) -> tuple:
        """(k, i, j, clearance, s, t) of the capsule pairs of near group pairs (configuration
        kk, groups g1 and g2, their listed index n_gp) whose balls are within ``threshold``."""
        if self._listed:
            count = self._cp_count[n_gp]
            entry = np.repeat(np.arange(n_gp.size), count)
            pos = np.arange(entry.size) + np.repeat(self._cp_offset[n_gp] - np.cumsum(count)
                                                    + count, count)  # fmt: skip
            i, j = self._cp_i[pos], self._cp_j[pos]
        else:
            i, j, entry = self._expand(g1, g2)
        k = kk[entry]
        same = same[entry]
        P = xyz[0].shape[1]
        flat = [c.reshape(-1) for c in xyz]
        NB = self.bodies
        # capsule balls first: centre distance minus both half lengths (a sliding capsule's
        # half length is its longest)
        fi, fj = k * P + self._ccol[i], k * P + self._ccol[j]
        d = [np.take(c, fi) - np.take(c, fj) for c in flat]
        gap = np.sqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2])
        keep = gap - self._half[i] - self._half[j] <= threshold + 2.0 * self.r
        gap_turn = self._turning[j] - self._turning[i]
        if self._any_revolute:
            kink = self._kinks(Q).reshape(-1)
            gap_turn = gap_turn + np.take(kink, k * NB + self.body_a[j]) \
                - np.take(kink, k * NB + self.body_a[i])  # fmt: skip
        keep &= ~same | (np.abs(gap_turn) >= math.pi - TURN_TOLERANCE)
        n = np.flatnonzero(keep)
        k, i, j = k[n], i[n], j[n]
        m = k.size
        S = self._S
        layout = self._end_points
        if 4 * m >= layout.size * B.shape[0]:  # every end point moved, then the pairs' taken
            col = layout.column
            base = k * layout.size
            at = np.concatenate([base + col[i], base + col[S + i], base + col[j],
                                 base + col[S + j]])  # fmt: skip
            ends = layout.move(B).reshape(3, -1).take(at, axis=1)
        else:  # the segments of the pairs left, moved one by one
            points = np.concatenate([self._starts[i], self._ends[i], self._starts[j],
                                     self._ends[j]])  # fmt: skip
            bodies = np.concatenate([self.body_a[i], self.body_b[i], self.body_a[j],
                                     self.body_b[j]])  # fmt: skip
            ends = np.array(_moved(B.reshape(-1, 16), np.tile(k, 4) * NB + bodies, points))
        ends = ends.reshape(3, 4, m)
        dist, s, t = segment_distances_stacked(ends[:, 0], ends[:, 1], ends[:, 2], ends[:, 3])
        return k, i, j, dist - 2.0 * self.r, s, t

    def _chunk(self) -> int:
        """Configurations per batch (bounds the batch's group-pair and moved-point entries;
        :meth:`_candidate_slices` bounds its capsule pairs)."""
        if not self._listed:
            return 1
        per = max(self._gp1.size, self._end_points.size, self._centres.size, 1)
        return int(min(1024, max(1, _BATCH_ENTRIES // per)))

    # --- labels ----------------------------------------------------------------------------
    def _texts(self, rows: np.ndarray, s: np.ndarray) -> list[str]:
        """The part at parameter s of capsule row, in words, for every (row, s)."""
        if rows.size <= 8:  # a few: one by one
            return [self._label(row, at) for row, at in zip(rows.tolist(), s.tolist(),
                                                            strict=True)]  # fmt: skip
        codes, texts = self.text_codes(rows, s)
        return [texts[c] for c in codes.tolist()]

    def text_codes(self, rows: np.ndarray, s: np.ndarray) -> tuple[np.ndarray, list[str]]:
        """The parts at parameters ``s`` of capsule ``rows`` as (codes, texts): ``texts`` the
        distinct parts in words, in order of first appearance, and ``texts[codes[n]]`` the
        part of entry n. Words are made once per distinct (row, piece), so millions of
        entries cost a few array passes."""
        rows = np.asarray(rows, dtype=np.int64)
        s = np.asarray(s, dtype=float)
        if rows.size == 0:
            return np.zeros(0, dtype=np.int64), []
        piece = np.zeros(rows.size, dtype=np.int64)
        order = np.argsort(rows, kind="stable")
        sorted_rows = rows[order]
        cuts = np.flatnonzero(np.diff(sorted_rows)) + 1
        for lo, hi in zip(np.r_[0, cuts].tolist(), np.r_[cuts, rows.size].tolist(),
                          strict=True):  # fmt: skip
            row = int(sorted_rows[lo])
            breaks, labels = self._pieces[row]
            n = order[lo:hi]
            at = s[n] * self._lengths[row]
            # the first break beyond the point, else the last piece (as _label)
            found = np.searchsorted(breaks, at, side="right")
            piece[n] = np.where(found < len(breaks), found, len(labels) - 1)
        combo = rows * (int(piece.max()) + 1) + piece
        distinct, first, inverse = np.unique(combo, return_index=True, return_inverse=True)
        names: dict[str, int] = {}
        code_of = np.empty(distinct.size, dtype=np.int64)
        for m in np.argsort(first, kind="stable").tolist():  # in order of first appearance
            row = int(rows[first[m]])
            text = self._named(row, self._pieces[row][1][int(piece[first[m]])])
            code_of[m] = names.setdefault(text, len(names))
        return code_of[inverse.reshape(-1)], list(names)

    def _named(self, row: int, text: str) -> str:
        return text

    def label(self, row: int, s: float) -> str:
        """The part at parameter ``s`` in [0, 1] of capsule ``row``, in words."""
        return self._texts(np.array([row]), np.array([float(s)]))[0]

    def _pair(self, i: int, j: int, s: float, t: float, a, b, clearance: float,
              row_i: int | None = None, row_j: int | None = None) -> CollidingPair:  # fmt: skip
        """The CollidingPair of capsules ``row_i`` and ``row_j`` (default: i and j) at
        parameters s and t, whose starts and ends are ``a[i]``, ``b[i]``, ``a[j]`` and
        ``b[j]`` (arrays or lists of three floats each)."""
        p = tuple(float(x + s * (y - x)) for x, y in zip(a[i], b[i], strict=True))
        q = tuple(float(x + t * (y - x)) for x, y in zip(a[j], b[j], strict=True))
        i = i if row_i is None else row_i
        j = j if row_j is None else row_j
        first, second = self._label(i, float(s)), self._label(j, float(t))
        return CollidingPair(first, second, float(clearance), (p, q),
                             (int(self._element[i]), int(self._element[j])))  # fmt: skip

    def _label(self, row: int, s: float) -> str:
        """The part at parameter s of capsule row, in words (as :meth:`_texts`)."""
        breaks, labels = self._pieces_listed[row]
        at = s * self._lengths_listed[row]
        for n, b in enumerate(breaks):
            if at < b:
                return self._named(row, labels[n])
        return self._named(row, labels[-1])

    # --- queries ---------------------------------------------------------------------------
    def worst_arrays(self, Q: np.ndarray, margin: float, moving=None) -> tuple:
        """The closest pair closer than ``margin`` at each configuration of ``Q`` (K, J):
        ``(clearance, i, j, s, t)`` (K,) each; +inf and -1 where clear.

        ``moving`` (K,) ints, optional: per configuration, the one joint in which it differs
        from a configuration that is clear with ``margin``; the pairs of parts that this
        joint does not move relative to each other are as clear as there and are not tested
        (the free intervals' scans)."""
        Q = self._configurations(Q)
        K = Q.shape[0]
        out = np.full(K, np.inf)
        oi = np.full(K, -1, dtype=np.int64)
        oj = np.full(K, -1, dtype=np.int64)
        os_, ot = np.zeros(K), np.zeros(K)
        limit = clear_limit(self.r, margin)
        n = self._static_best
        static = n is not None and self._static_clearance[n] < limit
        chain = self._caps is None
        for start in range(0, K, self._chunk()):
            Qc = Q[start : start + self._chunk()]
            mc = None if moving is None else moving[start : start + self._chunk()]
            best = []  # per slice, the closest pair of each configuration closer than limit
            for part in self._candidate_slices(Qc, margin, mc)[1]:
                k, i, j, c, s, t = part
                hit = np.flatnonzero(c < limit)
                k, i, j, c, s, t = k[hit], i[hit], j[hit], c[hit], s[hit], t[hit]
                rank = self._rank(i, j)
                order = np.lexsort((rank, c, k))
                first = order[np.r_[True, k[order][1:] != k[order][:-1]]] if k.size else order
                best.append((k[first], i[first], j[first], c[first], s[first], t[first],
                             rank[first]))  # fmt: skip
            if best:
                k, i, j, c, s, t, rank = (np.concatenate(column)
                                          for column in zip(*best, strict=True))  # fmt: skip
            else:
                none = np.zeros(0, dtype=np.int64)
                k, i, j, c, s, t, rank = none, none, none, np.zeros(0), np.zeros(0), \
                    np.zeros(0), none  # fmt: skip
            if static:
                si, sj = self._static_pairs
                m = Qc.shape[0]
                k = np.r_[k, np.arange(m)]
                i, j = np.r_[i, np.full(m, si[n])], np.r_[j, np.full(m, sj[n])]
                c = np.r_[c, np.full(m, self._static_clearance[n])]
                s = np.r_[s, np.full(m, self._static_st[0][n])]
                t = np.r_[t, np.full(m, self._static_st[1][n])]
                rank = np.r_[rank, np.full(m, -1 if chain else self._static_rank[n])]
            if k.size == 0:
                continue
            order = np.lexsort((rank, c, k))
            first = order[np.r_[True, k[order][1:] != k[order][:-1]]]
            kk = start + k[first]
            out[kk], oi[kk], oj[kk] = c[first], i[first], j[first]
            os_[kk], ot[kk] = s[first], t[first]
        return out, oi, oj, os_, ot

    def _pairs_at(self, Q: np.ndarray, which: np.ndarray, found: tuple) -> list:
        """CollidingPairs of the configurations ``which`` from :meth:`_worst_arrays`'s
        ``found``."""
        if which.size == 0:
            return []
        clearance, i, j, s, t = found
        a, b = self.segments(Q[which])
        return [self._pair(int(i[w]), int(j[w]), float(s[w]), float(t[w]), a[n], b[n],
                           clearance[w]) for n, w in enumerate(which.tolist())]  # fmt: skip

    def worst(self, Q: np.ndarray, margin: float = 0.0) -> tuple[np.ndarray, list]:
        """Closest pair at each configuration of ``Q`` (K, J) that is closer than ``margin``
        (chain units; 0: the deepest overlap), unchecked.

        Returns ``(clearance, pairs)``: clearance (K,) is the smallest clearance of the
        tested pairs when it is below the margin, or +inf when the configuration is clear;
        pairs[k] is the CollidingPair of that clearance, or None.
        """
        Q = np.asarray(Q, dtype=float)
        found = self.worst_arrays(Q, margin)
        which = np.flatnonzero(np.isfinite(found[0]))
        pairs: list = [None] * Q.shape[0]
        for w, pair in zip(which.tolist(), self._pairs_at(Q, which, found), strict=True):
            pairs[w] = pair
        return found[0], pairs

    def colliding(self, Q: np.ndarray, margin: float = 0.0, moving=None) -> np.ndarray:
        """(K,) True where the configuration has parts closer than ``margin`` (0: where it
        self-intersects); ``moving`` as in :meth:`worst_arrays`."""
        return np.isfinite(self.worst_arrays(np.asarray(Q, dtype=float), margin, moving)[0])

    def tally(self, Q: np.ndarray, found: tuple) -> tuple[np.ndarray, tuple]:
        """What :func:`sweep` reports of ``Q`` from :meth:`worst_arrays`'s ``found``: the
        clearance at each configuration (+inf where clear) and up to 10 ``(pair, count)``: the
        pairs of parts that were the deepest overlap of some configuration, deepest first."""
        clearance, i, j, s, t = found
        hit = np.flatnonzero(np.isfinite(clearance))
        if hit.size == 0:
            return clearance, ()
        codes, texts = self.text_codes(np.r_[i[hit], j[hit]], np.r_[s[hit], t[hit]])
        key = codes[: hit.size] * len(texts) + codes[hit.size :]
        _, group, counts = np.unique(key, return_inverse=True, return_counts=True)
        # per group: its first configuration, and the first configuration of its deepest
        order = np.lexsort((hit, clearance[hit], group))
        lead = np.r_[True, group[order][1:] != group[order][:-1]]
        deepest = hit[order[lead]]
        first_seen = np.full(counts.size, hit.size)
        np.minimum.at(first_seen, group, np.arange(hit.size))
        ranking = np.lexsort((first_seen, clearance[deepest]))[:10]
        pairs = self._pairs_at(Q, deepest[ranking], found)
        return clearance, tuple(zip(pairs, (int(c) for c in counts[ranking]), strict=True))

    def report(self, states, margin: float = 0.0) -> ClearanceReport:
        """The :class:`ClearanceReport` at one configuration (absolute states, checked), with
        ``margin`` (chain units, >= 0) the clearance required."""
        limit = clear_limit(self.r, margin)
        if self._listed:
            q = self._plain_states(states)
            q = self.check_states(states) if q is None else q
            Q = self._configurations(q[None, :])
            return self._report_one(Q, tuple(Q[0].tolist()), limit, margin)
        q = self.check_states(states)
        Q = self._configurations(q[None, :])
        values = tuple(float(x) for x in Q[0]) if self._caps is not None \
            else tuple(float(x) for x in q)  # fmt: skip
        threshold = (4.0 if self._listed else 0.5) * self.r + margin
        static = self._static_clearance
        static_min = float(static.min()) if static.size else math.inf
        while True:
            _, i, j, clearance, s, t, B = self._candidates(Q, threshold)
            best = min(float(clearance.min()) if clearance.size else math.inf, static_min)
            if best <= threshold or threshold > 1e3 * self._extent():
                break
            threshold = max(2.0 * threshold, best)
        if clearance.size + static.size == 0:
            return ClearanceReport(True, math.inf, (), None, values, margin, self.r)
        si, sj = self._static_pairs
        ci, cj = np.concatenate([i, si]), np.concatenate([j, sj])
        cc = np.concatenate([clearance, static])
        cs = np.concatenate([s, self._static_st[0]])
        ct = np.concatenate([t, self._static_st[1]])
        rank = np.concatenate([self._rank(i, j), self._static_rank])
        if self._caps is None:  # a chain's: moving pairs first, each kind in its order
            kind = np.concatenate([np.zeros(i.size), np.ones(si.size)])
            order = np.lexsort((rank, kind, cc))
        else:
            order = np.lexsort((rank, cc))
        a0, b0 = self._segments_at(B, 0)

        def make(n: int) -> CollidingPair:
            return self._pair(int(ci[n]), int(cj[n]), float(cs[n]), float(ct[n]), a0, b0,
                              float(cc[n]))  # fmt: skip

        closest = make(int(order[0]))
        hit = order[: int(np.searchsorted(cc[order], limit, side="left"))]
        listed, unlisted, overlapping = self._distinct_pairs(ci[hit], cj[hit], cs[hit],
                                                             ct[hit], cc[hit])  # fmt: skip
        pairs = tuple(make(int(n)) for n in hit[listed].tolist())
        min_clearance = float(cc[order[0]])
        return ClearanceReport(min_clearance >= limit, min_clearance, pairs, closest, values,
                               margin, self.r, unlisted=unlisted,
                               unlisted_overlapping=overlapping)  # fmt: skip

    def closest_pairs(self, states, margin: float = 0.0) -> tuple:
        """Where the parts bind at one configuration (absolute states, checked): the tested
        pairs of capsules closer than ``margin`` (chain units, >= 0, to within
        ``CONTACT_TOLERANCE`` r as every verdict) and the closest pair (all of them on a
        tie), in the order of :meth:`report` (closest first), without words: what a solver
        needs for the clearance's gradient (docs/reach.md, "Inverse kinematics").

        Returns ``(clearance, ends, bodies, s, t, capsules)``: ``clearance`` (k,) chain units
        (negative: overlap depth); ``ends`` (k, 4, 3) the world end points of the two
        capsules' segments (first start, first end, second start, second end); ``bodies``
        (k, 4) the rigid body each end point rides on (0 the base, b the body that moving
        joint ``screws.moving[b - 1]`` turns or slides; a sliding capsule's ends ride on
        two); ``s``, ``t`` (k,) the closest points' parameters: the first at ``ends[:, 0] + s
        (ends[:, 1] - ends[:, 0])``, the second at ``ends[:, 2] + t (ends[:, 3] - ends[:,
        2])``; ``capsules`` (k, 2) the two capsules (``label(capsules[n, 0], s[n])`` words the
        first part). Pairs inside one rigid body are listed too (they never move apart). The
        first pair is the report's ``closest`` at these states and its clearance the
        report's ``min_clearance``, the same arithmetic (k = 0 when nothing is tested).
        """
        margin = check_margin(margin)
        return self._closest_at(self._configurations(self.check_states(states)[None, :]),
                                margin)  # fmt: skip

    def closest_pairs_many(self, Q, margin: float = 0.0) -> list[tuple]:
        """:meth:`closest_pairs` at each configuration of ``Q`` (K, J) (absolute states,
        checked at once): the same arrays to the bit, a tuple per configuration, without
        checking the states and the margin once per configuration (a solver's batch of
        targets asks them together)."""
        margin = check_margin(margin)
        Q = np.asarray(Q, dtype=float)
        J = self.ranges.shape[0]
        plain = Q.ndim == 2 and Q.shape[1] == J and bool(np.all(
            (self.ranges[:, 0] - 1e-12 <= Q) & (Q <= self.ranges[:, 1] + 1e-12)
            & np.isfinite(Q)))  # fmt: skip
        if not plain:  # the first configuration that is not states says why
            if Q.ndim != 2:
                raise InvalidParameterError(f"Q must be (K, {J}) states, got shape {Q.shape}")
            Q = np.array([self.check_states(q, f"Q[{k}]") for k, q in enumerate(Q)])
        Q = self._configurations(Q.copy())
        return [self._closest_at(Q[k : k + 1], margin) for k in range(Q.shape[0])]

    def _closest_at(self, Q: np.ndarray, margin: float) -> tuple:
        """:meth:`closest_pairs` at the one checked configuration ``Q`` (1, J)."""
        limit = clear_limit(self.r, margin)
        S = self._S
        one = self._one_arrays() if self._listed else None
        compiled = one is not None and one.pairs and _kernel() is not None
        if compiled:  # the kernel keeps the pairs closer than the limit and the closest
            B = _compiled_motions(self.screws, Q[0])
            c, n, s, t, W = _kernel()(B, *one.kernel_arrays(self), Q[0],
                                      math.pi - TURN_TOLERANCE, limit, one.static_first[0],
                                      one.slack, 2.0 * self.r)  # fmt: skip
            listed = getattr(self, "_closest_listed", None)
            if listed is None:  # every listed pair's end point rows and tie rank, made once
                i, j = one.pair_ij
                listed = self._closest_listed = (np.stack([i, S + i, j, S + j], axis=1),
                                                 np.asarray(one.rank, dtype=np.int64))  # fmt: skip
            rows, rank = listed[0][n], listed[1][n]
        else:  # the batched candidates, the search widened until the closest is among them
            threshold = (4.0 if self._listed else 0.5) * self.r + margin
            static_min = float(self._static_clearance.min()) if self._static_clearance.size \
                else math.inf  # fmt: skip
            while True:
                _, i, j, c, s, t, B = self._candidates(Q, threshold)
                best = min(float(c.min()) if c.size else math.inf, static_min)
                if best <= threshold or threshold > 1e3 * self._extent():
                    break
                threshold = max(2.0 * threshold, best)
            W = np.concatenate(self._segments_at(B, 0))
            rows, rank = np.stack([i, S + i, j, S + j], axis=1), self._rank(i, j)
        static = self._static_clearance
        low = one.static_first[0] if one is not None else \
            float(static.min()) if static.size else math.inf  # fmt: skip
        if low < limit or (static.size and (not c.size or low <= float(c.min()))):
            # the pairs inside one body closer than the limit, or the closest
            fixed = np.flatnonzero((static < limit) | (static == low))
            si, sj = self._static_pairs[0][fixed], self._static_pairs[1][fixed]
            kind = np.r_[np.zeros(c.size, dtype=np.int64), np.ones(fixed.size, dtype=np.int64)]
            c = np.concatenate([c, static[fixed]])
            s = np.concatenate([s, self._static_st[0][fixed]])
            t = np.concatenate([t, self._static_st[1][fixed]])
            rows = np.concatenate([rows, np.stack([si, S + si, sj, S + sj], axis=1)])
            rank = np.concatenate([rank, self._static_rank[fixed]])
            keep = np.flatnonzero((c < limit) | (c == c.min()))
            # the report's order: a chain's moving pairs before its static ones
            keep = keep[np.lexsort((rank[keep], kind[keep], c[keep]) if self._caps is None
                                   else (rank[keep], c[keep]))]  # fmt: skip
            c, s, t, rows = c[keep], s[keep], t[keep], rows[keep]
        elif c.size > 1:  # the moving pairs only, in the report's order
            keep = np.arange(c.size) if compiled else np.flatnonzero((c < limit) | (c == c.min()))
            keep = keep[np.lexsort((rank[keep], c[keep]))]
            c, s, t, rows = c[keep], s[keep], t[keep], rows[keep]
        bodies = one.rows if one is not None else np.concatenate([self.body_a, self.body_b])
        return c, W[rows], bodies[rows], s, t, rows[:, ::2]

    def _distinct_pairs(self, i, j, s, t, clearance) -> tuple[np.ndarray, int, int]:
        """Of capsule pairs (rows i and j at parameters s and t), closest first: the index of
        the first (closest) of each pair of parts, at most MAX_REPORTED_PAIRS of them, the
        number of pairs of parts left out and how many of those overlap. The parts' words are
        codes for every entry (:meth:`text_codes`), so a report makes a pair only for the
        first of each of the pairs it lists."""
        i, j = np.asarray(i, dtype=np.int64), np.asarray(j, dtype=np.int64)
        s, t = np.asarray(s, dtype=float), np.asarray(t, dtype=float)
        n = i.size
        ids: dict[str, int] = {}  # every part's words, one number for the whole call
        key = np.empty(n, dtype=np.int64)  # (first part, second part) of each entry
        # worded a slice of entries at a time, so that memory stays bounded for millions of
        # them (fuzz operations seed 501008: 8 million pairs of a folded tree took 2.6 GB)
        for a in range(0, n, _DISTINCT_ENTRIES):
            b = min(n, a + _DISTINCT_ENTRIES)
            codes, texts = self.text_codes(np.r_[i[a:b], j[a:b]], np.r_[s[a:b], t[a:b]])
            to_id = np.array([ids.setdefault(text, len(ids)) for text in texts], dtype=np.int64)
            codes = to_id[codes]
            key[a:b] = (codes[: b - a] << 32) | codes[b - a :]
        first = np.sort(np.unique(key, return_index=True)[1])
        rest = first[MAX_REPORTED_PAIRS:]
        overlapping = int((np.asarray(clearance, dtype=float)[rest] < 0.0).sum())
        return first[:MAX_REPORTED_PAIRS], int(rest.size), overlapping

    def _one_arrays(self) -> _OneConfiguration:
        """What :meth:`_report_one` needs, built on first use."""
        if self._one is None:
            self._one = _OneConfiguration(self)
        return self._one

    def _measured(self, one: _OneConfiguration, W: np.ndarray, points: list,
                  twice: np.ndarray, near: np.ndarray, low: np.ndarray, values: tuple,
                  limit: float, static_min: float) -> list:  # fmt: skip
        """The exact clearances ``(clearance, pair, s, t)`` of :meth:`_report_one`: of the
        candidate pairs ``near`` (indices; ``low``: twice their lower bounds plus 4r; ``W``
        the end points (3, 2S), also as a list of 2S points, and ``twice`` twice the
        centres (3, S)), in the order of their bounds, those the turning rule tests, up to the
        first bound beyond the limit and the smallest clearance found (and ``static_min``)."""
        r2, slack, sure, pi, pj = 2.0 * self.r, one.slack, one.sure, one.pi, one.pj
        # a closer lower bound of the candidates' distances (twice): the gap between the two
        # segments' shadows on the line through their centres (the centres' distance less
        # both segments projected on it; about 0 where the centres coincide: the projections
        # are then divided by 1e-300, no more than the lengths)
        S = self._S
        ends = np.concatenate([twice, W[:, S:] - W[:, :S]])
        shadows = []
        for a in range(0, near.size, _PAIR_ENTRIES):  # bounded temporaries (~100 B a pair)
            part = near[a : a + _PAIR_ENTRIES]
            k = part.size
            X = ends.take(one.pair_ij.take(part, axis=1).reshape(-1), axis=1).reshape(6, 2, k)
            d = X[:3, 0] - X[:3, 1]
            gap = d * d
            gap = np.sqrt((gap[0] + gap[1]) + gap[2])
            e = X[3:]  # (3, 2, k): both segments
            along = e * d[:, None]
            along = np.abs((along[0] + along[1]) + along[2])
            shadows.append(gap - (along[0] + along[1]) / np.maximum(gap, 1e-300))
        shadow = np.concatenate(shadows) if shadows else np.zeros(0)
        low = np.fmax(shadow, low)
        order = low.argsort(kind="stable")
        pairs = near.take(order)
        lows_sorted = low.take(order)
        must = int(np.searchsorted(lows_sorted, 2.0 * (limit + slack + r2), side="right"))
        kinks = None  # the turning up to every body, when a maybe pair needs it
        turn_max = math.pi - TURN_TOLERANCE
        turn, bi, bj = one.maybe_lists
        # the pairs closer than the limit by their bounds that the turning rule tests (many
        # of them, when a design is folded onto itself: tested as arrays, the same sums)
        if must > _FOUND_AS_ARRAYS:
            head = pairs[:must]
            if int(head.max()) >= sure:
                kinks = one.kinks(values)
                k_arr = np.array(kinks)
                m = head[head >= sure] - sure
                tested = ~(np.abs((one.maybe_turn[m] + k_arr[one.maybe_bj[m]])
                                  - k_arr[one.maybe_bi[m]]) < turn_max)  # fmt: skip
                keep = np.ones(head.size, dtype=bool)
                keep[head >= sure] = tested
                head = head[keep]
            first = head.tolist()
        else:
            first = pairs[:must].tolist()
            if max(first, default=-1) >= sure:
                kinks = one.kinks(values)
                first = [n for n in first if n < sure or not abs(
                    (turn[n - sure] + kinks[bj[n - sure]]) - kinks[bi[n - sure]]) < turn_max]
        found: list[tuple] = []
        bulk = None  # (clearance, pair, s, t) arrays, for many pairs
        if len(first) > _ONE_BY_ONE:  # many: at once, in slices of bounded memory
            batch = np.array(first, dtype=np.int64)
            parts = []
            for a in range(0, batch.size, _PAIR_ENTRIES):
                piece = batch[a : a + _PAIR_ENTRIES]
                dist, s, t = segment_distances_stacked(*W.take(one.ends[:, :, piece]))
                parts.append((dist - r2, piece, s, t))
            if batch.size > _FOUND_AS_ARRAYS:
                bulk = tuple(np.concatenate(column) for column in zip(*parts, strict=True))
            else:
                for clearance, piece, s, t in parts:
                    found += zip(clearance.tolist(), piece.tolist(), s.tolist(), t.tolist(),
                                 strict=True)  # fmt: skip
        else:
            for n in first:
                i, j = pi[n], pj[n]
                dist, s, t = segment_distance(points[i], points[S + i], points[j], points[S + j])
                found.append((dist - r2, n, s, t))
        best = min([entry[0] for entry in found], default=math.inf)
        if bulk is not None and bulk[0].size:
            best = min(best, float(bulk[0].min()))
        # then the others, up to the first bound beyond the limit and the closest found (a
        # slice of them at a time as Python numbers: the loop usually stops in the first)
        for n, lw in _in_slices(pairs, lows_sorted, must):
            if lw > 2.0 * (max(limit, min(best, static_min)) + slack + r2):
                break
            if n >= sure:
                if kinks is None:
                    kinks = one.kinks(values)
                m = n - sure
                if abs((turn[m] + kinks[bj[m]]) - kinks[bi[m]]) < turn_max:
                    continue  # the turning rule does not test it here
            i, j = pi[n], pj[n]
            dist, s, t = segment_distance(points[i], points[S + i], points[j], points[S + j])
            found.append((dist - r2, n, s, t))
            if dist - r2 < best:
                best = dist - r2
        if bulk is None:
            return found
        if found:  # the few measured one by one after the batch
            c, n, s, t = (np.array(column) for column in zip(*found, strict=True))
            bulk = (np.r_[bulk[0], c], np.r_[bulk[1], n.astype(np.int64)], np.r_[bulk[2], s],
                    np.r_[bulk[3], t])  # fmt: skip
        return bulk

    def _plain_states(self, states) -> np.ndarray | None:
        """``states`` as :meth:`check_states` gives them when they are a list or tuple of
        plain finite numbers, one per joint, each within its range (the common case, checked
        in plain floats); else None (:meth:`check_states` then checks them and words the
        error)."""
        low, high = self._one_arrays().state_bounds
        if type(states) not in (list, tuple) or len(states) != len(low) \
                or not all(type(v) in _PLAIN_STATES for v in states):  # fmt: skip
            return None
        try:
            values = [float(v) for v in states]
        except OverflowError:  # an int beyond the float range
            return None
        if all(map(operator.le, low, values)) and all(map(operator.le, values, high)) \
                and all(map(math.isfinite, values)):  # fmt: skip
            return np.array(values, dtype=float)
        return None

    def _report_one(self, Q: np.ndarray, values: tuple, limit: float,
                    margin: float) -> ClearanceReport:  # fmt: skip
        """:meth:`report` at one configuration ``Q`` (1, J) of a listed engine, in the fewest
        numpy calls: every listed capsule pair's clearance is bounded below by its capsule
        centres' distance minus both half lengths and above by that distance. The pairs are
        measured exactly in the order of their lower bounds until the next bound exceeds both
        the limit and the smallest clearance found (and the static pairs' smallest), so every
        pair closer than the limit and the closest pair are measured; with the same
        arithmetic as the batch (bit for bit), one by one in plain floats
        (:func:`~kinegami.geometry.segments.segment_distance`), or at once when many pairs
        are closer than the limit. The turning rule is applied to the pairs measured only."""
        one = self._one_arrays()
        r2 = 2.0 * self.r
        S = self._S
        static_min = one.static_first[0]
        found: list[tuple] = []
        one.queries += 1
        if one.pairs and one.queries > COMPILED_AFTER and _kernel() is not None:
            one_configuration = _kernel()  # many queries: the compiled kernels
            clearance, n, s, t, moved = one_configuration(
                _compiled_motions(self.screws, Q[0]), *one.kernel_arrays(self), Q[0],
                math.pi - TURN_TOLERANCE, limit, static_min, one.slack, r2)  # fmt: skip
            if clearance.size > _FOUND_AS_ARRAYS:  # a design folded onto itself
                found = (clearance, n.astype(np.int64), s, t)
            else:
                found = list(zip(clearance.tolist(), n.tolist(), s.tolist(), t.tolist(),
                                 strict=True))  # fmt: skip
            return self._one_report(one, found, moved, values, limit, margin)
        B = self.screws.body_motions_one(Q[0])
        # every end point moved (the arithmetic of _Layout.move), coordinate-major (3, 2S)
        NB = B.shape[0]
        M = B.reshape(NB, 16)[:, :12].T.take(one.rows, axis=1).reshape(3, 4, -1)
        M *= one.points
        W = ((M[:, 0] + M[:, 1]) + M[:, 2]) + M[:, 3]
        points = W.T.tolist()
        if one.pairs:
            twice = W[:, :S] + W[:, S:]  # twice the capsule centres
            d = twice.take(one.centre_i) - twice.take(one.centre_j)
            d *= d
            twice_gap = np.sqrt((d[0] + d[1]) + d[2])  # twice the centres' distance
            low = twice_gap - one.twice_half  # twice (the lower bound + 2r)
            # an upper bound of the closest tested pair's clearance: the pairs tested always
            top = 0.5 * float(twice_gap[: one.sure].min()) - r2 if one.sure else math.inf
            bound = max(limit, min(top, static_min))
            near = np.flatnonzero(low <= 2.0 * (bound + one.slack + r2)) \
                if math.isfinite(bound) else np.arange(one.pairs)  # fmt: skip
            if near.size:
                found = self._measured(one, W, points, twice, near, low.take(near), values,
                                       limit, static_min)  # fmt: skip
        return self._one_report(one, found, points, values, limit, margin)

    def _one_report(self, one: _OneConfiguration, found: list, points, values: tuple,
                    limit: float, margin: float) -> ClearanceReport:  # fmt: skip
        """The report of :meth:`_report_one` from the measured pairs ``found`` (clearance,
        pair, s, t) and the moved end points ``points`` (2S rows of x, y, z: a list or an
        array)."""
        S = self._S
        if isinstance(found, tuple):  # arrays: many pairs
            return self._one_report_arrays(one, found, points, values, limit, margin)
        # in the report's order: clearance, then (chains) moving pairs before static ones,
        # then the tie order of :meth:`_rank`
        rank = one.rank
        chain = self._caps is None
        moving = sorted((c, 0, rank[n], n, s, t) if chain else (c, rank[n], 0, n, s, t)
                        for c, n, s, t in found)  # fmt: skip
        statics = one.static_first
        if not moving and not one.static_count:
            return ClearanceReport(True, math.inf, (), None, values, margin, self.r)
        take = one.static_taken(limit)
        ordered = moving + [one.static_key(n) for n in range(take)]
        if take and moving:
            ordered.sort()

        def make(entry: tuple) -> CollidingPair:
            c, _, _, n, s, t = entry
            i, j = (one.pi[n], one.pj[n]) if n >= 0 else statics[1][-n - 1].tolist()
            a_i, a_j, b_i, b_j = (points[i], points[j], points[S + i], points[S + j]) \
                if isinstance(points, list) else points[[i, j, S + i, S + j]].tolist()  # fmt: skip
            return self._pair(0, 1, s, t, (a_i, a_j), (b_i, b_j), c, i, j)

        closest = make(ordered[0])
        min_clearance = ordered[0][0]
        hit = ordered[: bisect.bisect_left([entry[0] for entry in ordered], limit)]
        if len(hit) <= 1:
            pairs: tuple = (closest,) if hit else ()
            unlisted = overlapping = 0
        else:
            rows = [one.pi[n] if n >= 0 else int(statics[1][-n - 1, 0]) for _, _, _, n, _, _
                    in hit]  # fmt: skip
            cols = [one.pj[n] if n >= 0 else int(statics[1][-n - 1, 1]) for _, _, _, n, _, _
                    in hit]  # fmt: skip
            listed, unlisted, overlapping = self._distinct_pairs(
                np.array(rows, dtype=np.int64), np.array(cols, dtype=np.int64),
                np.array([entry[4] for entry in hit]), np.array([entry[5] for entry in hit]),
                np.array([entry[0] for entry in hit]))  # fmt: skip
            pairs = tuple(closest if n == 0 else make(hit[n]) for n in listed.tolist())
        return ClearanceReport(min_clearance >= limit, min_clearance, pairs, closest, values,
                               margin, self.r, unlisted=unlisted,
                               unlisted_overlapping=overlapping)  # fmt: skip

    def _one_report_arrays(self, one: _OneConfiguration, found: tuple, points, values: tuple,
                           limit: float, margin: float) -> ClearanceReport:  # fmt: skip
        """:meth:`_one_report` of many measured pairs, ``found`` as arrays (clearance, pair,
        s, t): the same order (clearance, then moving before static for a chain, then the
        tie order of :meth:`_rank`, then the pair), the same pairs listed and counted, with
        per-pair Python objects made only for the pairs the report lists (a chain folded onto
        itself measured 1.5 million pairs: fuzz operations seed 500286)."""
        S = self._S
        C, N, Sp, Tp = (np.asarray(column) for column in found)
        N = N.astype(np.int64)
        rank = np.asarray(one.rank, dtype=np.int64)[N]
        zero = np.zeros(N.size, dtype=np.int64)
        chain = self._caps is None
        K1, K2 = (zero, rank) if chain else (rank, zero)
        take = one.static_taken(limit)
        if take:
            keys = [one.static_key(n) for n in range(take)]
            columns = [np.array([key[m] for key in keys]) for m in range(6)]
            C, K1, K2 = np.r_[C, columns[0]], np.r_[K1, columns[1]], np.r_[K2, columns[2]]
            N, Sp, Tp = np.r_[N, columns[3].astype(np.int64)], np.r_[Sp, columns[4]], \
                np.r_[Tp, columns[5]]  # fmt: skip
        order = np.lexsort((N, K2, K1, C))
        C, K1, K2, N, Sp, Tp = (column[order] for column in (C, K1, K2, N, Sp, Tp))
        statics = one.static_first
        pi, pj = np.asarray(one.pi, dtype=np.int64), np.asarray(one.pj, dtype=np.int64)

        def make(k: int) -> CollidingPair:
            c, n, s, t = float(C[k]), int(N[k]), float(Sp[k]), float(Tp[k])
            i, j = (int(pi[n]), int(pj[n])) if n >= 0 else statics[1][-n - 1].tolist()
            a_i, a_j, b_i, b_j = (points[i], points[j], points[S + i], points[S + j]) \
                if isinstance(points, list) else points[[i, j, S + i, S + j]].tolist()  # fmt: skip
            return self._pair(0, 1, s, t, (a_i, a_j), (b_i, b_j), c, i, j)

        closest = make(0)
        min_clearance = float(C[0])
        hits = int(np.searchsorted(C, limit, side="left"))
        if hits <= 1:
            pairs: tuple = (closest,) if hits else ()
            unlisted = overlapping = 0
        else:
            n = N[:hits]
            moving = n >= 0
            rows = np.empty(hits, dtype=np.int64)
            cols = np.empty(hits, dtype=np.int64)
            rows[moving], cols[moving] = pi[n[moving]], pj[n[moving]]
            if not moving.all():
                fixed = statics[1][-n[~moving] - 1]
                rows[~moving], cols[~moving] = fixed[:, 0], fixed[:, 1]
            listed, unlisted, overlapping = self._distinct_pairs(rows, cols, Sp[:hits],
                                                                 Tp[:hits], C[:hits])
            pairs = tuple(closest if k == 0 else make(k) for k in listed.tolist())
        return ClearanceReport(min_clearance >= limit, min_clearance, pairs, closest, values,
                               margin, self.r, unlisted=unlisted,
                               unlisted_overlapping=overlapping)  # fmt: skip

    def _extent(self) -> float:
        """Size of the assembly (for the search radius of :meth:`report`)."""
        if self._S == 0:
            return self.r
        pts = np.vstack([self._starts, self._ends])
        return float(np.ptp(pts, axis=0).max()) + self.r

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
        moving = np.repeat([j for j, _ in jobs], resolution)
        hits = self.colliding(np.vstack(rows), margin, moving).reshape(len(jobs), resolution)
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
            hit = self.colliding(Q, margin, np.array([jobs[n][0] for n in open_]))
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
    """The chain's :class:`ClearanceEngine` for ``names``, cached until the chain's joints or
    links change (a few per chain: the editor asks with its joint names, inverse kinematics
    without, in turn)."""
    from kinegami.chain.model import KinematicChain

    if not isinstance(chain, KinematicChain):
        raise InvalidTypeError(f"chain must be a KinematicChain, got {type(chain).__name__}")
    joints, links = chain.Joints, chain.Links
    names = None if names is None else tuple(names)
    cached = _ENGINES.get(chain)
    if cached is None or not (_same_objects(cached[0], joints)
                              and _same_objects(cached[1], links)):  # fmt: skip
        cached = (tuple(joints), tuple(links), {})
        _ENGINES[chain] = cached
    engines = cached[2]
    engine = engines.get(names)
    if engine is None:
        engine = ClearanceEngine(chain, names)
        if len(engines) >= 4:
            engines.pop(next(iter(engines)))
        engines[names] = engine
    return engine


_TREE_ENGINES: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def tree_engine(tree, names=None, margin: float = 0.0) -> TreeEngine:
    """The tree's :class:`TreeEngine` for ``names`` and ``margin``, cached until its joints,
    links or parents change (a few per tree: one per margin and names asked for)."""
    joints, links, parents = tree.Joints, tree.Links, tuple(tree.Parents)
    names = None if names is None else tuple(names)
    cached = _TREE_ENGINES.setdefault(tree, [])
    for entry in cached:
        if (entry[2:5] == (parents, names, margin) and _same_objects(entry[0], joints)
                and _same_objects(entry[1], links)):  # fmt: skip
            return entry[5]
    engine = TreeEngine(tree, names, margin)
    cached.insert(0, (tuple(joints), tuple(links), parents, names, margin, engine))
    del cached[4:]
    return engine


def keep_tree_engine(tree, engine: TreeEngine, margin: float) -> None:
    """Keep ``engine`` (built for ``tree`` at other states, for ``margin`` and no names) as
    the engine of ``tree`` as it is now. An engine answers absolute states and measures a
    tree's junctions on the links its links are rigid copies of, so it stays valid when
    setJointStates moves the design; the tree's next clearance queries then need no new
    engine and name the parts it names."""
    joints, links, parents = tree.Joints, tree.Links, tuple(tree.Parents)
    if not isinstance(engine, TreeEngine) or len(engine.ranges) != len(joints):
        raise InvalidTypeError("engine must be a TreeEngine of the tree's design")
    cached = _TREE_ENGINES.setdefault(tree, [])
    cached.insert(0, (tuple(joints), tuple(links), parents, None, check_margin(margin), engine))
    del cached[4:]


def _same_objects(known: tuple, now) -> bool:
    return len(known) == len(now) and all(map(operator.is_, known, now))


def current_states(chain) -> np.ndarray:
    return np.array([joint.state for joint in chain.Joints], dtype=float)


class ChainMotion:
    """A chain's :class:`ClearanceEngine` with a margin: the queries :func:`sweep` asks."""

    def __init__(self, engine: ClearanceEngine, margin: float):
        self.engine, self.margin = engine, margin
        self.ranges = engine.ranges

    def check_states(self, states, name: str = "states") -> np.ndarray:
        return self.engine.check_states(states, name)

    def worst_arrays(self, Q: np.ndarray) -> tuple:
        return self.engine.worst_arrays(Q, self.margin)

    def tally(self, Q: np.ndarray, found: tuple) -> tuple:
        return self.engine.tally(Q, found)

    def free_intervals(self, states: np.ndarray, resolution: int = 64) -> tuple:
        return self.engine.free_intervals(states, resolution, self.margin)


class TreeEngine(ClearanceEngine):
    """:class:`ClearanceEngine` for a :class:`~kinegami.tree.KinematicTree` (its joints,
    links and parents as they were when built, and one margin): the same queries with the pair
    rule of trees (docs/trees.md).

    Rigid bodies hang from their parent body in the tree. Parts on one path from the root are
    tested as in a chain; parts on different branches always, except the tubes that leave one
    branching joint inside its junction. Those tubes hang from the same body (the branching
    joint's distal side, waypoints add no motion), so their junction, and the distance between
    their parts beyond it, does not change with the configuration: they are measured once, at
    the tree's current states. Configurations outside the ranges by rounding are clamped.
    """

    def __init__(self, tree, names=None, margin: float = 0.0):
        joints = tree.Joints
        r = float(tree.r)
        caps = tree_capsules(joints, tree.Links, tree.Parents, r, check_margin(margin))
        self._joints = tuple(joints)
        self._names = None if names is None else tuple(names)
        J = len(joints)
        kinds = np.array([joint.motion for joint in joints], dtype=np.int64)
        poses = np.array([joint.pose_matrix for joint in joints]).reshape(J, 4, 4)
        rows = caps.rows
        self._setup(
            r=r, starts=caps.starts, ends=caps.ends, start_joint=caps.start_joint,
            end_joint=caps.end_joint, turning=caps.turning, element=caps.element,
            parents=np.asarray(caps.parents, dtype=np.int64), kinds=kinds,
            points=poses[:, :3, 3], axes=poses[:, :3, 2],
            states=np.array([joint.state for joint in joints], dtype=float),
            ranges=np.array([joint.stateRange() for joint in joints], dtype=float),
            pieces=[(np.asarray(row[6], dtype=float), row[7]) for row in rows],
            lengths=[float(np.linalg.norm(row[1] - row[0])) for row in rows], caps=caps,
        )  # fmt: skip

    def _named(self, row: int, text: str) -> str:
        """``text`` with the joint's name (as :func:`~kinegami.chain.bodies.part_label` words
        it)."""
        return with_joint_name(text, int(self._element[row]), self._joints, self._names)


class TreeMotion:
    """Clearance queries over the motion of a :class:`~kinegami.tree.KinematicTree` (what
    :func:`sweep` uses for trees): the same queries as :class:`ClearanceEngine`, with the pair
    rule of trees (docs/trees.md), batched over configurations by a :class:`TreeEngine`.

    Configurations are absolute states, one per joint in index order.
    """

    #: Bisection steps that refine each end of a free interval after the grid scan.
    BISECTIONS = 24

    def __init__(self, tree, names=None, margin: float = 0.0):
        self.margin = check_margin(margin)
        self.engine = tree_engine(tree, names, self.margin)
        self.r = self.engine.r
        self.ranges = self.engine.ranges
        self.movable = np.flatnonzero(self.ranges[:, 1] > self.ranges[:, 0])

    def check_states(self, states, name: str = "states") -> np.ndarray:
        """``states`` as a float array (one per joint, each within its range), or raise."""
        return _checked_states(states, self.ranges, name)

    def worst_arrays(self, Q: np.ndarray) -> tuple:
        return self.engine.worst_arrays(Q, self.margin)

    def tally(self, Q: np.ndarray, found: tuple) -> tuple:
        return self.engine.tally(Q, found)

    def worst(self, Q: np.ndarray) -> tuple[np.ndarray, list]:
        """Closest pair closer than the margin at each configuration of ``Q`` (K, J),
        unchecked: ``(clearance, pairs)`` as :meth:`ClearanceEngine.worst` gives them (+inf and
        None where clear)."""
        return self.engine.worst(Q, self.margin)

    def colliding(self, Q: np.ndarray, moving=None) -> np.ndarray:
        """(K,) True where the configuration has parts closer than the margin (``moving``:
        see :meth:`ClearanceEngine.worst_arrays`)."""
        return self.engine.colliding(Q, self.margin, moving)

    def free_intervals(self, states: np.ndarray, resolution: int = 64) -> tuple:
        """Per joint, the clear interval of its own state around ``states`` (see SweepReport):
        each side scanned on a grid of ``resolution`` steps up to the first colliding state,
        then refined by :attr:`BISECTIONS` bisection steps (every side at once)."""
        states = np.asarray(states, dtype=float)
        if self.colliding(states[None, :])[0]:
            return (None,) * len(states)
        out: list = [(float(v), float(v)) for v in states]
        jobs = [(int(j), float(target)) for j in self.movable.tolist()
                for target in self.ranges[j]]  # fmt: skip
        if not jobs:
            return tuple(out)
        grids = [np.linspace(states[j], target, resolution + 1) for j, target in jobs]
        Q = np.repeat(states[None, :], len(jobs) * resolution, axis=0)
        for n, (j, _) in enumerate(jobs):
            Q[n * resolution : (n + 1) * resolution, j] = grids[n][1:]
        hits = self.colliding(Q, np.repeat([j for j, _ in jobs], resolution))
        hits = hits.reshape(len(jobs), resolution)
        good = np.empty(len(jobs))
        bad = np.full(len(jobs), np.nan)
        for n in range(len(jobs)):
            first = np.flatnonzero(hits[n])
            if first.size == 0:
                good[n] = float(grids[n][-1])
            else:
                good[n] = float(grids[n][first[0]])
                bad[n] = float(grids[n][first[0] + 1])
        open_ = np.flatnonzero(~np.isnan(bad))
        for _ in range(self.BISECTIONS):
            if open_.size == 0:
                break
            mid = 0.5 * (good[open_] + bad[open_])
            Q = np.repeat(states[None, :], open_.size, axis=0)
            joints = np.array([jobs[n][0] for n in open_.tolist()])
            Q[np.arange(open_.size), joints] = mid
            hit = self.colliding(Q, joints)
            bad[open_[hit]] = mid[hit]
            good[open_[~hit]] = mid[~hit]
        for n in range(0, len(jobs), 2):
            j = jobs[n][0]
            ends = (float(good[n]), float(good[n + 1]))
            out[j] = (min(ends), max(ends))
        return tuple(out)


#: The plain types of a state that need no conversion check (bool is not among them).
_PLAIN_STATES = frozenset({float, int, np.float64})


def _checked_states(states, ranges: np.ndarray, name: str) -> np.ndarray:
    """``states`` as a float array (one per joint, each within ``ranges``), or raise."""
    J = ranges.shape[0]
    # the common case in a few steps: a list or array of plain finite numbers within range
    # (anything else, or any failure, takes the checks below, which word the error)
    plain = None
    if type(states) in (list, tuple) and len(states) == J \
            and all(type(v) in _PLAIN_STATES for v in states):  # fmt: skip
        try:
            plain = np.array(states, dtype=float)
        except OverflowError:  # an int beyond the float range
            plain = None
    elif type(states) is np.ndarray and states.shape == (J,) and states.dtype == np.float64:
        plain = states.copy()
    if plain is not None and bool(np.all((ranges[:, 0] - 1e-12 <= plain)
                                         & (plain <= ranges[:, 1] + 1e-12)
                                         & np.isfinite(plain))):  # fmt: skip
        return plain
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
