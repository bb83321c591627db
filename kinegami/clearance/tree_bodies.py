"""The body distances of a tree: junction extents, the tree's capsules and the pairs on
different branches (docs/trees.md, docs/clearance.md).

Parts on one path from the root are tested as in a chain (:mod:`kinegami.chain.bodies`); parts on
different branches always, except where two tubes leaving the same joint still run together
within the junction that joins them.
"""

from __future__ import annotations

import dataclasses
import math
import operator
import threading
from dataclasses import dataclass

import numpy as np

from kinegami.chain.bodies import (
    BALL_GROUP,
    CONTACT_TOLERANCE,
    TURN_TOLERANCE,
    clear_limit,
    joint_capsule_arrays,
    link_capsule_arrays,
    link_polyline,
    near_capsule_pairs,
    overlap_of_deepest_pair,
    worst_overlap,
)
from kinegami.geometry.screws import REVOLUTE
from kinegami.geometry.segments import point_segment_parameters, segment_distances

__all__ = [
    "JUNCTION_REACH",
    "junction_extent",
    "TreeCapsules",
    "TreeGrowth",
    "tree_capsules",
    "tree_pair_distances",
    "tree_worst_overlap",
]


#: Longest stretch (in r, along each tube from the branching frame) that a junction body covers:
#: tubes leaving the same joint may run within 2r of each other that far; beyond it they collide.
JUNCTION_REACH = 5.0


def _polyline_samples(points: np.ndarray, step: float) -> tuple[np.ndarray, np.ndarray]:
    """Points every ``step`` (or closer) along a polyline and their distances from its start."""
    d = np.diff(points, axis=0)
    lengths = np.sqrt((d**2).sum(axis=1))
    cumulative = np.concatenate([[0.0], np.cumsum(lengths)])
    total = float(cumulative[-1])
    if total <= 0.0:
        return points[:1], np.zeros(1)
    count = max(2, int(math.ceil(total / step)) + 1)
    s = np.linspace(0.0, total, count)
    k = np.clip(np.searchsorted(cumulative, s, side="right") - 1, 0, len(lengths) - 1)
    safe = np.where(lengths[k] > 0.0, lengths[k], 1.0)
    t = np.where(lengths[k] > 0.0, (s - cumulative[k]) / safe, 0.0)
    return points[k] + t[:, None] * d[k], s


#: Most (sample point, sibling segment) pairs junction_extent evaluates at once: its temporary
#: arrays then hold at most 3 x 2**20 floats (24 MiB) each, however many siblings there are.
_JUNCTION_CHUNK = 1 << 20
#: Most (own segment, sibling segment) pairs whose intervals are computed at once.
_JUNCTION_PAIRS = 262_144


def junction_extent(
    polyline: np.ndarray, own: tuple, siblings: tuple, r: float, margin: float = 0.0,
    limit: float = math.inf,
) -> float:
    """How far (along ``polyline``, from its start) a tube leaving a branching joint runs
    within 2r + ``margin`` of a sibling tube leaving the same frame: the distance along it of
    the last point of its capsules (``own``: segment starts and ends) that close to a sibling
    capsule (``siblings``), sampled every 0.02 r. The junction body covers the tube up to there
    (docs/trees.md). 0 when nothing is that close. With ``limit``, the answer is wanted only up
    to it: ``limit`` is returned as soon as the extent is known to reach it.

    Only the samples that can be that close are evaluated (those within the finite cylinder of
    radius 2r + margin around some sibling segment), a bounded number at a time, so tubes
    1e6 r long cost no more memory than short ones (issue 29, docs/limits.md)."""
    a, b = siblings
    if a.shape[0] == 0 or own[0].shape[0] == 0:
        return 0.0
    starts, ends = own
    lengths = np.sqrt(((ends - starts) ** 2).sum(axis=1))
    counts = np.maximum(2, np.ceil(lengths / (0.02 * r)).astype(np.int64) + 1)
    reach = (2.0 * r + margin) * (1.0 - CONTACT_TOLERANCE)
    first = np.cumsum(counts) - counts  # global index of each segment's first sample
    # a sample is measured against the sibling segments whose balls it comes near (with a
    # rounding allowance: the nearer ones decide whether it is within reach)
    centre, half = 0.5 * (a + b), 0.5 * np.sqrt(((b - a) ** 2).sum(axis=1))
    scale = max(float(np.abs(starts).max()), float(np.abs(ends).max()),
                float(np.abs(a).max()), float(np.abs(b).max()), 1.0)  # fmt: skip
    near = reach * (1.0 + 1e-6) + 1e-9 * scale
    # the candidate samples of the own segments a block at a time, the last block first (its
    # samples are the scan's first): a tube that reaches its sibling far along stops within
    # its first block (a margin of 1e8 made every sample of 1,316 segments a candidate, 0.2 s
    # of intervals for a scan that ended in its first chunk); each segment's samples are its
    # own, so the blocks give the same candidates in the same order
    chunk = max(1, _JUNCTION_CHUNK // a.shape[0])
    own_scale = max(float(np.abs(starts).max()), float(np.abs(ends).max()),
                    float(np.abs(a).max()), 1.0)  # fmt: skip
    found = -math.inf
    end, block = starts.shape[0], _JUNCTION_FIRST_SEGMENTS
    while end > 0:
        begin = max(0, end - block)
        part = slice(begin, end)
        low, high = _candidate_samples(starts[part], ends[part], counts[part], first[part], a,
                                       b, reach, own_scale)  # fmt: skip
        end, block = begin, 4 * block
        for index in _descending_chunks(low, high, chunk):
            i = np.searchsorted(first, index, side="right") - 1
            u = (index - first[i]) / (counts[i] - 1)
            points = starts[i] + u[:, None] * (ends - starts)[i]
            p, q = _ball_pairs(points, np.zeros(points.shape[0]), centre, half, near)
            t = _point_params(points[p], a[q], b[q])
            nearest = a[q] + t[:, None] * (b - a)[q]
            distance = np.sqrt(((points[p] - nearest) ** 2).sum(axis=1))
            close = np.zeros(points.shape[0], dtype=bool)
            close[p[distance < reach]] = True
            if close.any():
                found = max(found, float(_polyline_distance(points[close], polyline).max()))
                if found + 0.02 * r >= limit:
                    return limit
    if found == -math.inf:
        return 0.0
    return found + 0.02 * r


#: Own segments of junction_extent's first block of candidate samples; each next block is four
#: times larger.
_JUNCTION_FIRST_SEGMENTS = 64


#: Samples of junction_extent's first chunk; each next chunk is four times larger (up to its
#: memory bound): the scan, highest first, usually ends within the first few samples (a tube
#: that runs beside its sibling beyond the limit), and a first chunk of the largest size cost
#: 0.3 s on tubes 1e4 r long (a fuzzed tree's take-off search measured 86 of them).
_JUNCTION_FIRST_CHUNK = 256


def _descending_chunks(low: np.ndarray, high: np.ndarray, chunk: int,
                       first: int = _JUNCTION_FIRST_CHUNK):  # fmt: skip
    """The integers of the disjoint intervals [low, high) (sorted), highest first, in arrays
    of ``first`` integers, then four times as many each time, up to ``chunk`` (few of them:
    the scan may end early)."""
    pieces: list[np.ndarray] = []
    size = 0
    limit = max(1, min(first, chunk))
    for k in range(low.size - 1, -1, -1):
        lo, hi = int(low[k]), int(high[k])
        while hi > lo:
            take = min(hi - lo, limit - size)
            pieces.append(np.arange(hi - take, hi, dtype=np.int64))
            size += take
            hi -= take
            if size == limit:
                yield np.concatenate(pieces)
                pieces, size = [], 0
                limit = min(4 * limit, chunk)
    if pieces:
        yield np.concatenate(pieces)


def _candidate_samples(starts, ends, counts, first, a, b, reach: float,
                       scale: float | None = None):  # fmt: skip
    """Sorted disjoint intervals [low, high) of global sample indices (sample k of own segment
    i is ``first[i] + k``, at parameter k / (counts[i] - 1)) that may lie within ``reach`` of
    a sibling segment (a, b): those inside the cylinder of radius ``reach`` around the
    sibling's line, between the planes ``reach`` beyond its ends (a superset of the capsule),
    padded by two samples on each side against rounding. Only the (own, sibling) pairs whose
    balls come that close are measured (:func:`_ball_pairs`). ``scale``: the size that sets
    the rounding allowance (default: of these segments and the siblings' starts), so that the
    segments taken a block at a time get the intervals they get all together."""
    e = b - a
    length = np.sqrt((e**2).sum(axis=1))
    e = np.where(length[:, None] > 0.0, e / np.where(length > 0.0, length, 1.0)[:, None], 0.0)
    if scale is None:
        scale = max(float(np.abs(starts).max()), float(np.abs(ends).max()),
                    float(np.abs(a).max()), 1.0)  # fmt: skip
    slack = reach * (1.0 + 1e-6) + 1e-9 * scale
    # the region of a sibling lies within length / 2 + 2 slack of its midpoint: pairs whose
    # balls are 3 slack apart have no sample in it
    own_half = 0.5 * np.sqrt(((ends - starts) ** 2).sum(axis=1))
    pairs_i, pairs_j = _ball_pairs(0.5 * (starts + ends), own_half, 0.5 * (a + b), 0.5 * length,
                                   3.0 * slack)  # fmt: skip
    found_low, found_high = [np.zeros(0, np.int64)], [np.zeros(0, np.int64)]
    for p0 in range(0, pairs_i.size, _JUNCTION_PAIRS):
        i, j = pairs_i[p0 : p0 + _JUNCTION_PAIRS], pairs_j[p0 : p0 + _JUNCTION_PAIRS]
        d, ej = (ends - starts)[i], e[j]
        rel = starts[i] - a[j]  # (pairs, 3)
        t0 = (rel * ej).sum(axis=1)  # axial coordinate at u = 0 and its rate
        t1 = (d * ej).sum(axis=1)
        w0 = rel - t0[:, None] * ej  # the part across the sibling's line
        w1 = d - t1[:, None] * ej
        ww = (w1**2).sum(axis=1)
        with np.errstate(divide="ignore", invalid="ignore", over="ignore"):
            # across: |w0 + u w1| < slack, an interval around the nearest u
            centre = np.where(ww > 0.0, -(w0 * w1).sum(axis=1) / np.where(ww > 0.0, ww, 1.0),
                              0.0)  # fmt: skip
            gap = np.sqrt(((w0 + centre[:, None] * w1) ** 2).sum(axis=1))
            half = np.where(ww > 0.0, np.sqrt(np.maximum(slack**2 - gap**2, 0.0) / ww), np.inf)
            inside = gap < slack
            lo, hi = centre - half, centre + half
            # along: -slack < t0 + u t1 < length + slack
            ua = (-slack - t0) / t1
            ub = (length[j] + slack - t0) / t1
            moving = t1 != 0.0
            lo = np.where(moving, np.maximum(lo, np.minimum(ua, ub)), lo)
            hi = np.where(moving, np.minimum(hi, np.maximum(ua, ub)), hi)
            inside &= moving | ((t0 > -slack) & (t0 < length[j] + slack))
        lo, hi = np.maximum(lo, 0.0), np.minimum(hi, 1.0)
        inside &= lo <= hi
        q = np.flatnonzero(inside)
        steps = (counts[i[q]] - 1).astype(float)
        k0 = np.maximum(np.floor(lo[q] * steps) - 2.0, 0.0).astype(np.int64)
        k1 = np.minimum(np.ceil(hi[q] * steps) + 3.0, steps + 1.0).astype(np.int64)
        found_low.append(first[i[q]] + k0)
        found_high.append(first[i[q]] + k1)
    low, high = np.concatenate(found_low), np.concatenate(found_high)
    if low.size == 0:
        return low, high
    order = np.argsort(low, kind="stable")
    low, high = low[order], high[order]
    reach_end = np.maximum.accumulate(high)
    new = np.ones(low.size, dtype=bool)
    new[1:] = low[1:] > reach_end[:-1]
    starts_at = np.flatnonzero(new)
    return low[starts_at], np.maximum.reduceat(high, starts_at)


#: About the most pairs (of groups, or of balls) :func:`_ball_pairs` holds at once (groups of
#: BALL_GROUP consecutive balls).
_BALL_PAIRS = 1 << 18


def _group_balls(centre: np.ndarray, half: np.ndarray, size: int):
    """Balls around groups of ``size`` consecutive balls: (first index of each group, centre,
    radius)."""
    begin = np.arange(0, half.size, size)
    count = np.diff(np.r_[begin, half.size])
    c = np.add.reduceat(centre, begin, axis=0) / count[:, None]
    owner = np.repeat(np.arange(begin.size), count)
    spread = np.sqrt(((centre - c[owner]) ** 2).sum(axis=1)) + half
    return begin, c, np.maximum.reduceat(spread, begin)


def _ball_pairs(c1, h1, c2, h2, reach: float) -> tuple[np.ndarray, np.ndarray]:
    """Index pairs (i, j) of balls (centres ``c1``, radii ``h1``) and (``c2``, ``h2``) whose
    surfaces come within ``reach`` (|c1_i - c2_j| - h1_i - h2_j < reach), in no particular
    order. Groups of consecutive balls (a tube's capsules) are compared first, so far-apart
    stretches of two tubes cost one test per pair of groups; about 2**18 pairs (of groups or
    of balls) are held at once while searching."""
    empty = np.zeros(0, dtype=np.int64)
    if h1.size == 0 or h2.size == 0:
        return empty, empty
    g = BALL_GROUP
    begin1, gc1, gr1 = _group_balls(c1, h1, g)
    begin2, gc2, gr2 = _group_balls(c2, h2, g)
    # a rounding allowance: the groups' balls may only keep more pairs than the exact test
    slack = reach + 1e-9 * (1.0 + float(np.abs(gc1).max()) + float(np.abs(gc2).max())
                            + float(gr1.max()) + float(gr2.max()))  # fmt: skip
    sizes1, sizes2 = np.diff(np.r_[begin1, h1.size]), np.diff(np.r_[begin2, h2.size])
    found_i, found_j = [empty], [empty]
    rows = max(1, _BALL_PAIRS // begin2.size)
    for r0 in range(0, begin1.size, rows):
        d = gc1[r0 : r0 + rows, None, :] - gc2[None]
        near = np.sqrt((d**2).sum(axis=2)) - gr1[r0 : r0 + rows, None] - gr2[None] < slack
        ge, gf = np.nonzero(near)
        ge += r0
        block = sizes1[ge] * sizes2[gf]
        # the near group pairs, a few at a time: at most _BALL_PAIRS ball pairs each
        cut = np.searchsorted(np.cumsum(block), np.arange(1, 1 + int(block.sum()) //
                                                          _BALL_PAIRS) * _BALL_PAIRS)
        for part in np.split(np.arange(ge.size), np.unique(cut)):
            if part.size == 0:
                continue
            n2, size = sizes2[gf[part]], block[part]
            q = np.arange(int(size.sum())) - np.repeat(np.cumsum(size) - size, size)
            n2_rep = np.repeat(n2, size)
            i = np.repeat(begin1[ge[part]], size) + q // n2_rep
            j = np.repeat(begin2[gf[part]], size) + q % n2_rep
            d = c1[i] - c2[j]
            keep = np.sqrt((d**2).sum(axis=1)) - h1[i] - h2[j] < reach
            found_i.append(i[keep])
            found_j.append(j[keep])
    return np.concatenate(found_i), np.concatenate(found_j)


def _point_params(points, a, b) -> np.ndarray:
    return point_segment_parameters(points, a, b)


#: Most (point, segment) pairs :func:`_polyline_distance` measures all at once; beyond, it
#: measures each point against the segments that can be nearest, about _BALL_PAIRS at a time.
_POLYLINE_DENSE = 1 << 16
#: Consecutive segments per group in :func:`_polyline_distance` (fastest of 4, 8, 16, 32 on
#: the rows of fuzzed trees' tubes).
_POLYLINE_GROUP = 8


def _polyline_distance(points: np.ndarray, polyline: np.ndarray) -> np.ndarray:
    """Distance along ``polyline`` (from its start) of the point of it nearest each point
    (of equally near segments, the first)."""
    a, b = polyline[:-1], polyline[1:]
    lengths = np.sqrt(((b - a) ** 2).sum(axis=1))
    cumulative = np.concatenate([[0.0], np.cumsum(lengths)])
    if points.shape[0] * a.shape[0] <= _POLYLINE_DENSE:
        t = _point_params(points[:, None, :], a[None], b[None])
        nearest = a[None] + t[..., None] * (b - a)[None]
        k = np.sqrt(((points[:, None, :] - nearest) ** 2).sum(axis=2)).argmin(axis=1)
        rows = np.arange(points.shape[0])
        return cumulative[k] + t[rows, k] * lengths[k]
    # groups of consecutive segments: the nearest segment lies in a group whose ball comes
    # within the smallest distance to any group's far side (with a rounding allowance)
    begin, gc, gr = _group_balls(0.5 * (a + b), 0.5 * lengths, _POLYLINE_GROUP)
    sizes = np.diff(np.r_[begin, a.shape[0]])
    allowance = 1e-9 * (1.0 + float(np.abs(points).max()) + float(np.abs(polyline).max())
                        + 2.0 * float(gr.max()))  # fmt: skip
    best = np.full(points.shape[0], np.inf)
    best_k = np.zeros(points.shape[0], dtype=np.int64)
    best_t = np.zeros(points.shape[0])
    step = max(1, _BALL_PAIRS // begin.size)
    for p0 in range(0, points.shape[0], step):
        d = np.sqrt(((points[p0 : p0 + step, None, :] - gc[None]) ** 2).sum(axis=2))
        upper = (d + gr[None]).min(axis=1)
        pp, gg = np.nonzero(d - gr[None] <= upper[:, None] + allowance)  # by point, then group
        pp += p0
        size = sizes[gg]
        cut = np.searchsorted(np.cumsum(size), np.arange(1, 1 + int(size.sum()) //
                                                         _BALL_PAIRS) * _BALL_PAIRS)
        for part in np.split(np.arange(pp.size), np.unique(cut)):
            if part.size == 0:
                continue
            n = size[part]
            q = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)
            i = np.repeat(pp[part], n)
            k = np.repeat(begin[gg[part]], n) + q  # by point, then segment
            t = _point_params(points[i], a[k], b[k])
            nearest = a[k] + t[:, None] * (b - a)[k]
            dist = np.sqrt(((points[i] - nearest) ** 2).sum(axis=1))
            run = np.flatnonzero(np.r_[True, i[1:] != i[:-1]])
            low = np.minimum.reduceat(dist, run)
            hit = np.flatnonzero(dist == np.repeat(low, np.diff(np.r_[run, i.size])))
            _, first_hit = np.unique(i[hit], return_index=True)  # each point's first nearest
            at = hit[first_hit]
            better = dist[at] < best[i[at]]  # earlier segments win ties
            who = i[at][better]
            best[who], best_k[who], best_t[who] = dist[at][better], k[at][better], t[at][better]
    return cumulative[best_k] + best_t * lengths[best_k]


@dataclass(frozen=True, eq=False)
class TreeCapsules:
    """The capsules of a tree at its current configuration and what its pair rule needs
    (docs/trees.md); built by :func:`tree_capsules`. World coordinates, units of r.

    Attributes
    ----------
    r : float
        Capsule radius.
    starts, ends : numpy.ndarray, shape (S, 3)
        Every capsule's segment, row by row in joint order (a joint's link, then the joint).
    start_joint, end_joint : numpy.ndarray of int, shape (S,)
        The joint whose distal side each end moves with (-1: the root's base).
    turning : numpy.ndarray, shape (S,)
        Turning of the centreline from the root along the path to the row, links only: at a
        configuration every revolute joint on the path to ``start_joint`` (itself included)
        adds |state|.
    element, node : numpy.ndarray of int, shape (S,)
        2 j (joint j) or 2 j - 1 (the link into j), and j.
    rows : tuple
        The capsule rows (their labels: :func:`part_label`).
    parents : tuple of int
    ancestor : numpy.ndarray of bool, shape (n, n)
        ``ancestor[x, y]``: joint y is x or an ancestor of x.
    is_link : numpy.ndarray of bool, shape (S,)
    top : numpy.ndarray of int, shape (n,)
        For a joint on the tube leaving a branching joint (its child, continued through
        waypoints with one child): that child; else -1.
    extent : numpy.ndarray, shape (n,)
        The junction extent of each such child (:func:`junction_extent`, at most
        ``JUNCTION_REACH`` r); 0 elsewhere.
    along : numpy.ndarray, shape (S, 2)
        For the link rows of those tubes: how far along the tube (from the branching frame)
        each end of the row lies; nan elsewhere.
    path_turning : numpy.ndarray, shape (n,)
        Turning of the links from the root to the end of the link into each joint.
    """

    r: float
    starts: np.ndarray
    ends: np.ndarray
    start_joint: np.ndarray
    end_joint: np.ndarray
    turning: np.ndarray
    element: np.ndarray
    node: np.ndarray
    rows: tuple
    parents: tuple
    ancestor: np.ndarray
    is_link: np.ndarray
    top: np.ndarray
    extent: np.ndarray
    along: np.ndarray
    path_turning: np.ndarray

    @property
    def count(self) -> int:
        """Number of capsules."""
        return int(self.starts.shape[0])

    def hinge_turning(self, joints) -> np.ndarray:
        """(n,) the turning the revolute hinges add from the root to each joint's distal side
        (itself included), at the states of ``joints``."""
        n = len(self.parents)
        kinks = np.zeros(n)
        for j in range(n):
            p = self.parents[j]
            kink = abs(joints[j].state) if joints[j].motion == REVOLUTE else 0.0
            kinks[j] = kink + (kinks[p] if p >= 0 else 0.0)
        return kinks

    def junction_pairs(self, i: np.ndarray, j: np.ndarray) -> np.ndarray:
        """Which of the row pairs (i, j) are two link rows of the tubes leaving one branching
        joint (on different tubes): those are tested only beyond the junction."""
        nx, ny = self.node[i], self.node[j]
        same_path = self.ancestor[nx, ny] | self.ancestor[ny, nx]
        top, parents = self.top, np.asarray(self.parents, dtype=np.int64)
        parent_of_top = np.where(top >= 0, parents[np.maximum(top, 0)], -2)
        return (~same_path & self.is_link[i] & self.is_link[j] & (top[nx] >= 0)
                & (top[ny] >= 0) & (parent_of_top[nx] == parent_of_top[ny]))  # fmt: skip

    def beyond_junction(self, i: np.ndarray, j: np.ndarray, a=None, b=None) -> tuple:
        """``(distance, s, t)`` of junction pairs (i, j): the part of each row beyond its
        junction against the whole other row, the closer of the two ways (inf when neither row
        reaches beyond its junction); s, t along the whole rows. ``a``, ``b``: the rows'
        segments (default: ``starts``, ``ends``)."""
        a = self.starts if a is None else a
        b = self.ends if b is None else b
        rest = np.full(i.size, np.inf)
        rest_s, rest_t = np.zeros(i.size), np.zeros(i.size)
        # the part of one row beyond its junction, against the whole other row (both ways);
        # the closest points are those of the parts tested (parameters along the whole rows)
        for first_is_mine, (mine, other) in ((True, (i, j)), (False, (j, i))):
            e = self.extent[self.top[self.node[mine]]]
            d0, d1 = self.along[mine, 0], self.along[mine, 1]
            k = np.flatnonzero(np.maximum(d0, d1) > e)  # the rows that reach beyond it
            if k.size == 0:
                continue
            mine, other, e, d0, d1 = mine[k], other[k], e[k], d0[k], d1[k]
            span = d1 - d0
            u = np.clip(np.where(span != 0.0, (e - d0) / np.where(span != 0.0, span, 1.0), 0.0),
                        0.0, 1.0)  # fmt: skip
            p0, p1 = a[mine], b[mine]
            cut = p0 + u[:, None] * (p1 - p0)
            lo = np.where((d1 < d0)[:, None], p0, cut)
            hi = np.where((d1 < d0)[:, None], cut, p1)
            dd, ss, tt = segment_distances(lo, hi, a[other], b[other])
            # ss runs along [lo, hi]: the same point as a parameter along the whole row
            point = lo + ss[:, None] * (hi - lo)
            axis = p1 - p0
            length2 = np.einsum("ij,ij->i", axis, axis)
            along_row = np.einsum("ij,ij->i", point - p0, axis) / np.where(
                length2 > 0, length2, 1.0
            )
            along_row = np.clip(np.where(length2 > 0, along_row, 0.0), 0.0, 1.0)
            better = dd < rest[k]
            rest[k] = np.where(better, dd, rest[k])
            if first_is_mine:
                rest_s[k] = np.where(better, along_row, rest_s[k])
                rest_t[k] = np.where(better, tt, rest_t[k])
            else:
                rest_s[k] = np.where(better, tt, rest_s[k])
                rest_t[k] = np.where(better, along_row, rest_t[k])
        return rest, rest_s, rest_t


#: Junction extents of the last few trees, by the link objects they were computed from (a
#: state change moves a junction's tubes rigidly: their extents stay).
_EXTENT_MEMO: dict = {}
_EXTENT_MEMO_SIZE = 64
_EXTENT_MEMO_LOCK = threading.Lock()


def _rigid_origins(links) -> tuple | None:
    """The links these are rigid copies of when all moved by one transform (or none moved),
    else None."""
    origins, moves = [], []
    for link in links:
        origin, T = link.__dict__.get("_moved_from", (link, None))
        origins.append(origin)
        moves.append(T)
    if all(T is None for T in moves):
        return tuple(origins)
    if any(T is None for T in moves) or not all(np.array_equal(T, moves[0]) for T in moves):
        return None
    return tuple(origins)


def _tube(links, nodes, r: float) -> tuple:
    """The tube made of ``links`` (those into ``nodes``, in order): its centreline polyline
    and its capsules' segment starts and ends."""
    arrays = [link_capsule_arrays(link, m, r, 0.2)[0] for link, m in zip(links, nodes,
                                                                          strict=True)]
    points = [link_polyline(link) for link in links]
    polyline = np.concatenate([points[0]] + [pts[1:] for pts in points[1:]])
    return (polyline, np.concatenate([x[0] for x in arrays]),
            np.concatenate([x[1] for x in arrays]))  # fmt: skip


def _tube_path(joints, children, k: int) -> list[int]:
    """The joints whose links make the tube leaving towards child ``k`` of a branching joint:
    k, continued through waypoints with one child."""
    path = [k]
    while not joints[path[-1]].has_body and len(children[path[-1]]) == 1:
        path.append(children[path[-1]][0])
    return path


def _junction_extents(kids: list, paths: dict, links, r: float, margin: float) -> dict:
    """The junction extent (at most ``JUNCTION_REACH`` r) of every child in ``kids`` of one
    branching joint; ``paths[k]``: the joints whose links make the tube leaving towards k.

    The tubes of a junction move together (they all hang from the branching joint), so when
    they are rigid copies of links seen before, the extents are those of the originals
    (computed on the originals: the same answer whatever the configuration)."""
    nodes = [m for k in kids for m in paths[k]]
    origins = _rigid_origins([links[m] for m in nodes])
    # the extents depend on the links' geometry only (not on the joints' numbers): keyed by
    # the links (or the links they are rigid copies of) tube by tube, checked by identity
    sources = tuple(origins) if origins is not None else tuple(links[m] for m in nodes)
    key = (tuple(map(id, sources)), tuple(len(paths[k]) for k in kids), r, margin)
    with _EXTENT_MEMO_LOCK:
        hit = _EXTENT_MEMO.get(key)
    if hit is not None and all(map(operator.is_, hit[0], sources)):
        return dict(zip(kids, hit[1], strict=True))
    source = dict(zip(nodes, sources, strict=True))
    tubes = {k: _tube([source[m] for m in paths[k]], paths[k], r) for k in kids}
    extents = {}
    for k in kids:
        others = [tubes[o] for o in kids if o != k]
        a = np.concatenate([t[1] for t in others])
        b = np.concatenate([t[2] for t in others])
        found = junction_extent(tubes[k][0], (tubes[k][1], tubes[k][2]), (a, b), r, margin,
                                limit=JUNCTION_REACH * r)
        extents[k] = min(found, JUNCTION_REACH * r)
    with _EXTENT_MEMO_LOCK:
        _EXTENT_MEMO[key] = (sources, [extents[k] for k in kids])
        while len(_EXTENT_MEMO) > _EXTENT_MEMO_SIZE:
            del _EXTENT_MEMO[next(iter(_EXTENT_MEMO))]
    return extents


def tree_capsules(joints, links, parents, r: float, margin: float = 0.0) -> TreeCapsules:
    """The :class:`TreeCapsules` of a tree (its joints, links and parent list) at its current
    configuration, with the junctions of ``margin`` (docs/trees.md)."""
    parents = tuple(int(p) for p in parents)
    n = len(joints)
    children: list[list[int]] = [[] for _ in range(n)]
    for k in range(1, n):
        children[parents[k]].append(k)
    link_total = np.zeros(n)
    rows: list = []
    pieces_a, pieces_b, owner_node, base_turn = [], [], [], []
    for j in range(n):
        if j > 0:
            (A, B, _, turn), link_rows, total = link_capsule_arrays(links[j], j, r, 0.2)
            link_total[j] = total
            if len(link_rows):
                pieces_a.append(A)
                pieces_b.append(B)
                owner_node.append(np.full(len(link_rows), j))
                base_turn.append(turn)
                rows += link_rows
        (A, B, _, turn), joint_rows = joint_capsule_arrays(joints[j], j, r)
        if len(joint_rows):
            pieces_a.append(A)
            pieces_b.append(B)
            owner_node.append(np.full(len(joint_rows), j))
            base_turn.append(turn)
            rows += joint_rows
    S = len(rows)
    if S:
        a, b = np.concatenate(pieces_a), np.concatenate(pieces_b)
        node = np.concatenate(owner_node).astype(np.int64)
        own = np.concatenate(base_turn)
    else:
        a, b, node, own = np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, np.int64), np.zeros(0)
    element = np.fromiter((row[5] for row in rows), dtype=np.int64, count=S)
    body_a = np.fromiter((row[2] for row in rows), dtype=np.int64, count=S)
    body_b = np.fromiter((row[3] for row in rows), dtype=np.int64, count=S)
    is_link = element % 2 == 1
    path_links = np.zeros(n)  # link turning from the root to the end of joint j's link
    for j in range(n):
        p = parents[j]
        path_links[j] = link_total[j] + (path_links[p] if p >= 0 else 0.0)
    parent_of = np.array(parents, dtype=np.int64)
    before = np.where(is_link, path_links[np.maximum(parent_of[node], 0)], path_links[node])
    before = np.where(is_link & (parent_of[node] < 0), 0.0, before)
    # a joint's distal half (body = its own index) moves with the joint; everything else of
    # joint j (its link, a proximal half) with its parent (rows number bodies as in a chain,
    # where the parent of j is j - 1)
    start_joint = np.where(body_a == node, node, parent_of[node])
    end_joint = np.where(body_b == node, node, parent_of[node])

    # junctions: how far the tube to each child of a branching joint (continued through
    # waypoints with one child, which add no part) runs with its siblings
    extent = np.zeros(n)
    top = np.full(n, -1, dtype=np.int64)
    polylines: dict[int, np.ndarray] = {}
    for kids in children:
        if len(kids) < 2:
            continue
        paths = {}
        for k in kids:
            path = _tube_path(joints, children, k)
            top[path] = k
            paths[k] = path
            points = [link_polyline(links[m]) for m in path]
            polylines[k] = np.concatenate([points[0]] + [pts[1:] for pts in points[1:]])
        for k, value in _junction_extents(kids, paths, links, r, margin).items():
            extent[k] = value
    # distances along each tube of the end points of its rows
    along = np.full((S, 2), np.nan)
    for k, line in polylines.items():
        rows_k = np.flatnonzero((top[node] == k) & is_link)
        if rows_k.size:
            d = _polyline_distance(np.concatenate([a[rows_k], b[rows_k]]), line)
            along[rows_k, 0], along[rows_k, 1] = d[: rows_k.size], d[rows_k.size :]
    ancestor = np.zeros((n, n), dtype=bool)  # ancestor[x, y]: y is x or an ancestor of x
    for x in range(n):
        ancestor[x, x] = True
        if parents[x] >= 0:
            ancestor[x] |= ancestor[parents[x]]
    caps = TreeCapsules(r, a, b, start_joint, end_joint, own + before, element, node,
                        tuple(rows), parents, ancestor, is_link, top, extent, along,
                        path_links)  # fmt: skip
    for value in vars(caps).values():
        if isinstance(value, np.ndarray):
            value.setflags(write=False)
    return caps


def tree_pair_distances(
    joints, links, parents, r: float, since: int = 0, reach: float | None = None,
    margin: float = 0.0, measured: list | None = None,
) -> tuple | None:
    """The tested capsule pairs of a tree that come within ``reach`` (default 2r + ``margin``)
    and their distances (docs/trees.md): ``(i, j, distance, s, t, rows, a, b)`` with ``i``,
    ``j`` row indices, ``s``, ``t`` the closest points' parameters, ``rows`` the capsule rows
    (labels) and ``a``, ``b`` their end points; None when nothing is tested.

    Parts on one path from the root are tested as in a chain (when the centreline between
    them turns by at least pi, hinges included). Parts on different branches are always tested,
    except where two tubes leaving the same branching joint still run together within the
    junction that joins them (:func:`junction_extent` of each, with ``margin``: the junction
    covers them until they are the margin apart); on a chain the tested pairs are the chain's.
    """
    reach = 2.0 * r + margin if reach is None else reach
    return _tested_pairs(tree_capsules(joints, links, parents, r, margin), joints, since, reach,
                         measured)  # fmt: skip


def _tested_pairs(caps: TreeCapsules, joints, since: int, reach: float,
                  measured: list | None = None) -> tuple | None:  # fmt: skip
    """:func:`tree_pair_distances` of the tree whose capsules are ``caps``; ``measured``,
    when given, gets the number of pairs measured appended (what the test cost)."""
    found = _listed_pairs(caps, joints, since, reach, measured)
    if found is None:
        return None
    i, j = found
    return i, j, *_pair_distances(caps, i, j), caps.rows, caps.starts, caps.ends


def _listed_pairs(caps: TreeCapsules, joints, since: int, reach: float,
                  measured: list | None) -> tuple | None:  # fmt: skip
    """:func:`_near_pairs`, with their number appended to ``measured`` (when given)."""
    found = _near_pairs(caps, joints, since, reach)
    if measured is not None:
        measured.append(0 if found is None else int(found[0].size))
    return found


def _pair_distances(caps: TreeCapsules, i: np.ndarray, j: np.ndarray) -> tuple:
    """``(dist, s, t)`` of the row pairs (i, j) by the pair rule: junction pairs beyond their
    junction (:meth:`TreeCapsules.beyond_junction`), the others whole."""
    a, b = caps.starts, caps.ends
    dist, s, t = segment_distances(a[i], b[i], a[j], b[j])
    q = np.flatnonzero(caps.junction_pairs(i, j))
    if q.size:  # beyond the junction: parts of the rows, never nearer than the rows
        dist[q], s[q], t[q] = caps.beyond_junction(i[q], j[q])
    return dist, s, t


def _near_pairs(caps: TreeCapsules, joints, since: int, reach: float) -> tuple | None:
    """The row pairs (i, j) that :func:`_tested_pairs` measures (None when there are none):
    within ``reach`` by their balls, with a part of joint ``since`` or later when ``since`` >
    0, and tested by the pair rule. Needs no junction extent."""
    S = caps.count
    if S < 2:
        return None
    a, b, node = caps.starts, caps.ends, caps.node
    kinks = caps.hinge_turning(joints)
    tau = caps.turning + np.where(caps.start_joint >= 0, kinks[caps.start_joint], 0.0)
    centre = 0.5 * (a + b)
    half = 0.5 * np.sqrt(((b - a) ** 2).sum(axis=1))
    if since > 0:
        n = len(caps.parents)
        one_path = all(caps.parents[k] == k - 1 for k in range(since + 1, n))
        i, j = _near_new_pairs(caps.element, node >= since, centre, half, reach,
                               tau if one_path else None)  # fmt: skip
    else:
        i, j = near_capsule_pairs(caps.element, tau, np.arange(S) + 1, centre, half, reach)
    if since > 0 and i.size:
        keep = (node[i] >= since) | (node[j] >= since)
        i, j = i[keep], j[keep]
    if i.size == 0:
        return None
    # one path from the root (one node an ancestor of the other): the chain rule; different
    # branches: always, but two parts of the tubes leaving one branching joint only beyond
    # the junction
    nx, ny = node[i], node[j]
    same_path = caps.ancestor[nx, ny] | caps.ancestor[ny, nx]
    tested = ~same_path | (np.abs(tau[j] - tau[i]) >= math.pi - TURN_TOLERANCE)
    i, j = i[tested], j[tested]
    if i.size == 0:
        return None
    return i, j


#: New rows per block of :func:`_near_pairs_by_block`.
_NEW_ROWS_PER_BLOCK = 64


def _near_pairs_by_block(caps: TreeCapsules, joints, since: int, reach: float):
    """The pairs of :func:`_near_pairs` (``since`` > 0), yielded as (i, j) arrays a block of
    at most ``_NEW_ROWS_PER_BLOCK`` new rows (of joint ``since`` or later) at a time, in no
    particular order: each new row i with every row j of a part near a new part (by their
    balls, as :func:`_near_new_pairs` keeps them) that is old or a later new row, kept when
    the segments' balls come within ``reach`` and the pair rule tests them."""
    S = caps.count
    node = caps.node
    new_rows = np.flatnonzero(node >= since)
    if S < 2 or new_rows.size == 0:
        return
    a, b = caps.starts, caps.ends
    kinks = caps.hinge_turning(joints)
    tau = caps.turning + np.where(caps.start_joint >= 0, kinks[caps.start_joint], 0.0)
    centre = 0.5 * (a + b)
    half = 0.5 * np.sqrt(((b - a) ** 2).sum(axis=1))
    rows = _rows_near(caps.element, node >= since, centre, half, reach)
    is_new = node[rows] >= since
    for start in range(0, new_rows.size, _NEW_ROWS_PER_BLOCK):
        block = new_rows[start : start + _NEW_ROWS_PER_BLOCK]
        # old rows, and new rows after the block's own (each pair of new rows once)
        d = centre[block][:, None, :] - centre[rows][None, :, :]
        near = np.sqrt(np.einsum("ijk,ijk->ij", d, d)) - half[block][:, None] \
            - half[rows][None, :] < reach  # fmt: skip
        near &= ~is_new[None, :] | (rows[None, :] > block[:, None])
        bi, bj = np.nonzero(near)
        if bi.size == 0:
            continue
        i, j = block[bi], rows[bj]
        nx, ny = node[i], node[j]
        same_path = caps.ancestor[nx, ny] | caps.ancestor[ny, nx]
        tested = ~same_path | (np.abs(tau[j] - tau[i]) >= math.pi - TURN_TOLERANCE)
        if tested.any():
            i, j = i[tested], j[tested]
            yield np.minimum(i, j), np.maximum(i, j)  # i < j, as every pair list has them


def _rows_near(element, wanted, centre, half, reach: float) -> np.ndarray:
    """The rows of the parts (``element``: each row's part, contiguous) that are wanted
    (``wanted``: a bool per row, constant over each part) or whose balls come within
    ``reach`` of a wanted part's, with a rounding allowance (keeping more parts changes
    nothing): every row a wanted row can be near."""
    S = element.size
    starts = np.flatnonzero(np.r_[True, element[1:] != element[:-1]])
    sizes = np.diff(np.r_[starts, S])
    c = np.add.reduceat(centre, starts, axis=0) / sizes[:, None]
    owner = np.repeat(np.arange(starts.size), sizes)
    rho = np.maximum.reduceat(np.sqrt(((centre - c[owner]) ** 2).sum(axis=1)) + half, starts)
    mine = np.flatnonzero(wanted[starts])
    keep = np.zeros(starts.size, dtype=bool)
    keep[mine] = True
    allowance = reach + 1e-9 * (reach + float(np.abs(c).max(initial=0.0)) + float(rho.max()))
    for e in mine.tolist():
        d = c[e] - c
        keep |= np.sqrt(np.einsum("ij,ij->i", d, d)) - rho[e] - rho < allowance
    return np.flatnonzero(keep[owner])


def _near_new_pairs(element, wanted, centre, half, reach: float, tau=None) -> tuple:
    """:func:`near_capsule_pairs` (i < j) with ``wanted`` (a bool per row, constant over each
    part), the same pairs in the same order, measured among the parts that can be in one:
    the wanted ones and those whose balls come within ``reach`` of a wanted one's (the test
    near_capsule_pairs makes of every pair of parts). A new joint's parts are few, so the
    test of all pairs of parts of a large tree is left out.

    With ``tau`` (the rows' turning, given when the wanted rows are the last ones and lie on
    one path from the root), pairs of two wanted rows whose turning differs by less than pi
    (which the pair rule does not test) are not listed either, the others in the same
    order."""
    rows = _rows_near(element, wanted, centre, half, reach)
    first = np.arange(rows.size) + 1
    new = np.flatnonzero(wanted[rows])
    if tau is not None and new.size and new[0] == rows.size - new.size:
        t = tau[rows[new]]
        if bool(np.all(np.diff(t) >= 0.0)):
            # along one path the turning does not decrease: a wanted row's pairs with the
            # wanted rows after it start where the turning has grown by pi (less a rounding
            # allowance: the pair rule decides exactly)
            bound = t + (math.pi - TURN_TOLERANCE) - 1e-9 * (1.0 + np.abs(t))
            first[new] = np.maximum(first[new], new[0] + np.searchsorted(t, bound, side="left"))
    i, j = near_capsule_pairs(element[rows], np.zeros(rows.size), first, centre[rows],
                              half[rows], reach, wanted[rows])  # fmt: skip
    return rows[i], rows[j]


def tree_worst_overlap(joints, links, parents, r: float, names=None, since: int = 0,
                       margin: float = 0.0, measured: list | None = None):  # fmt: skip
    """:func:`worst_overlap` for a tree (docs/trees.md): the closest pair when it is closer
    than ``margin``, or None.

    Parts on one path from the root are tested as in a chain; parts on different branches are
    always tested, except where two tubes leaving the same branching joint still run together
    within the junction that joins them. On a chain it is :func:`worst_overlap`.
    """
    parents = [int(p) for p in parents]
    if parents == list(range(-1, len(joints) - 1)):
        return worst_overlap(joints, links, r, names=names, since=since, margin=margin)
    caps = tree_capsules(joints, links, parents, r, margin)
    found = _closest_tested_pairs(caps, joints, since, 2.0 * r + margin, measured)
    if found is None:
        return None
    i, j, dist, s, t = found
    return overlap_of_deepest_pair(i, j, dist, s, t, caps.rows, joints, names, r, margin)


#: Pairs :func:`_closest_tested_pairs` measures at once, nearest bound first.
_CLOSEST_CHUNK = 8192


def _closest_tested_pairs(caps: TreeCapsules, joints, since: int, reach: float,
                          measured: list | None = None) -> tuple | None:  # fmt: skip
    """``(i, j, dist, s, t)`` of the pairs of :func:`_tested_pairs` that may be the closest:
    in their order there, and among them every pair at the smallest distance (so the first
    closest pair is :func:`_tested_pairs`' first closest pair), or None when nothing is
    tested. The pairs are measured nearest lower bound first (the distance of their segments'
    balls), a chunk at a time, until the next bound is beyond the closest distance found: a body
    folded onto itself lists millions of near pairs but the closest is among its first few
    thousand (fuzz operations seed 407416). ``measured`` gets the number of pairs listed
    appended, as :func:`_tested_pairs` counts them."""
    found = _listed_pairs(caps, joints, since, reach, measured)
    if found is None:
        return None
    i, j = found
    a, b = caps.starts, caps.ends
    if i.size <= _CLOSEST_CHUNK:
        order = np.arange(i.size)
    else:
        centre = 0.5 * (a + b)
        half = 0.5 * np.sqrt(((b - a) ** 2).sum(axis=1))
        d = centre[i] - centre[j]
        bound = np.sqrt(np.einsum("ij,ij->i", d, d)) - half[i] - half[j]
        order = np.argsort(bound, kind="stable")
        bound = bound[order]
    taken, best = [], math.inf
    slack = 1e-9 * (1.0 + float(np.abs(a).max(initial=0.0)) + float(np.abs(b).max(initial=0.0)))
    for start in range(0, order.size, _CLOSEST_CHUNK):
        if start and bound[start] > best + slack:
            break
        k = order[start : start + _CLOSEST_CHUNK]
        dist, s, t = _pair_distances(caps, i[k], j[k])
        best = min(best, float(dist.min()))
        taken.append((k, dist, s, t))
    k = np.concatenate([x[0] for x in taken])
    back = np.argsort(k, kind="stable")
    k = k[back]
    dist, s, t = (np.concatenate([x[n] for x in taken])[back] for n in (1, 2, 3))
    return i[k], j[k], dist, s, t


#: Pairs TreeGrowth.clear measures at once before it may stop.
_CLEAR_CHUNK = 2048


class TreeGrowth:
    """The overlap test of a tree's extensions: the tree followed by new joints that hang, one
    after the other, from one of its joints (what placement tries, candidate after candidate).

    :meth:`overlap` answers what :func:`tree_worst_overlap` answers for the extension with
    ``since`` = the tree's size (the pairs with a new part; the same Overlap), and
    :meth:`clear` whether that is None, but both measure only what the new joints change: the
    tree's own capsules, its junction tubes and their extents against each other are computed
    once, and per extension only the new capsules, the junction the new tube joins (its extent
    against its siblings' tubes and theirs against it: the extent against several tubes is the
    largest against each) and the pairs with a new part (docs/trees.md). An extension of
    another shape is measured by tree_worst_overlap.

    Parameters
    ----------
    joints, links, parents : the tree (its lists are kept; an extension must begin with the
        same joint and link objects).
    r : tube radius.
    margin : the clearance required (tree units, >= 0).
    """

    def __init__(self, joints, links, parents, r: float, margin: float = 0.0):
        self.joints = tuple(joints)
        self.links = tuple(links)
        self.parents = tuple(int(p) for p in parents)
        self.r = float(r)
        self.margin = float(margin)
        self._children: list[list[int]] = [[] for _ in self.parents]
        for k, p in enumerate(self.parents):
            if p >= 0:
                self._children[p].append(k)
        self._caps: TreeCapsules | None = None
        self._junctions: dict[int, dict] = {}

    def extends(self, joints, links, parents) -> bool:
        """Whether the lists are this tree's (the same objects) followed by new joints."""
        n0 = len(self.joints)
        return (len(joints) == len(links) == len(parents) and len(joints) >= n0
                and all(map(operator.is_, joints[:n0], self.joints))
                and all(map(operator.is_, links[:n0], self.links))
                and tuple(int(p) for p in parents[:n0]) == self.parents)  # fmt: skip

    def overlap(self, joints, links, parents, names=None):
        """The deepest pair with a new part closer than the margin (an Overlap), or None:
        ``tree_worst_overlap(joints, links, parents, r, names, since=len(tree), margin)``."""
        parents = [int(p) for p in parents]
        p = self._grown_from(joints, links, parents)
        if p < 0:
            return tree_worst_overlap(joints, links, parents, self.r, names,
                                      since=len(self.joints), margin=self.margin)  # fmt: skip
        caps = self._extended(joints, links, parents, p)
        caps = self._with_junction(caps, joints, links, p)
        found = _closest_tested_pairs(caps, joints, len(self.joints), 2.0 * self.r + self.margin)
        if found is None:
            return None
        i, j, dist, s, t = found
        return overlap_of_deepest_pair(i, j, dist, s, t, caps.rows, joints, names, self.r,
                                       self.margin)  # fmt: skip

    def clear(self, joints, links, parents) -> bool:
        """Whether :meth:`overlap` is None, answered as soon as known: the pairs that no
        junction covers are measured first, and the junction the new tube joins only when
        none of them is too close."""
        parents = [int(p) for p in parents]
        p = self._grown_from(joints, links, parents)
        if p < 0:
            return self.overlap(joints, links, parents) is None
        caps = self._extended(joints, links, parents, p)
        limit = clear_limit(self.r, self.margin)
        a, b = caps.starts, caps.ends
        junction = []
        # the pairs with a new row, a block of new rows at a time, each block's plain pairs
        # measured before the next block's are found: a candidate that collides is told by
        # its first colliding block, before the pairs of the others are even listed (fuzz
        # operations seed 407229: a new link of 900 capsules folded among 1,000 others had a
        # million near pairs per rejected candidate)
        for i, j in _near_pairs_by_block(caps, joints, len(self.joints),
                                         2.0 * self.r + self.margin):  # fmt: skip
            q = caps.junction_pairs(i, j)
            plain = np.flatnonzero(~q)
            for start in range(0, plain.size, _CLEAR_CHUNK):
                chunk = plain[start : start + _CLEAR_CHUNK]
                k, m = i[chunk], j[chunk]
                dist = segment_distances(a[k], b[k], a[m], b[m])[0]
                if float(dist.min()) - 2.0 * self.r < limit:  # overlap_of_deepest_pair's test
                    return False
            if q.any():
                junction.append((i[q], j[q]))
        if junction:
            caps = self._with_junction(caps, joints, links, p)
            i = np.concatenate([pair[0] for pair in junction])
            j = np.concatenate([pair[1] for pair in junction])
            dist = caps.beyond_junction(i, j)[0]
            if float(dist.min()) - 2.0 * self.r < limit:
                return False
        return True

    def _grown_from(self, joints, links, parents: list[int]) -> int:
        """The joint the new joints hang from, or -1 when the extension is measured whole
        (not one sub-chain from an old joint, a chain, or the lengthening of a junction's
        tube)."""
        n0, n = len(self.joints), len(joints)
        if not self.extends(joints, links, parents):
            raise ValueError("TreeGrowth: the lists do not extend the tree")
        p = parents[n0] if n > n0 else -1
        incremental = (
            n > n0 and parents != list(range(-1, n - 1))  # a chain: worst_overlap's own way
            and 0 <= p < n0 and all(parents[k] == k - 1 for k in range(n0 + 1, n))
            # new links that are rigid copies would be measured as their originals
            and not any("_moved_from" in links[k].__dict__ for k in range(n0, n))
        )  # fmt: skip
        if incremental and not self._children[p] and not joints[p].has_body:
            # a leaf waypoint on a junction tube: the new joints would lengthen that tube
            incremental = int(self._base().top[p]) < 0
        return p if incremental else -1

    def _base(self) -> TreeCapsules:
        if self._caps is None:
            self._caps = tree_capsules(self.joints, self.links, self.parents, self.r,
                                       self.margin)  # fmt: skip
        return self._caps

    def _junction(self, p: int) -> dict:
        """What the tubes leaving joint ``p`` (which has children) give every extension that
        adds one more: each child's tube, rows, distances along it (``along``) and its extent
        against the other children's tubes; the capsules of all of them."""
        found = self._junctions.get(p)
        if found is not None:
            return found
        caps, r = self._base(), self.r
        kids = self._children[p]
        paths = {k: _tube_path(self.joints, self._children, k) for k in kids}
        tubes = {k: _tube([self.links[m] for m in paths[k]], paths[k], r) for k in kids}
        rows, along = {}, {}
        for k in kids:
            rows[k] = np.flatnonzero(np.isin(caps.node, paths[k]) & caps.is_link)
            if len(kids) > 1:  # a junction already: the tree's own distances along the tube
                along[k] = caps.along[rows[k]]
            elif rows[k].size:
                d = _polyline_distance(np.concatenate([caps.starts[rows[k]],
                                                       caps.ends[rows[k]]]), tubes[k][0])
                along[k] = np.stack([d[: rows[k].size], d[rows[k].size :]], axis=1)
            else:
                along[k] = np.zeros((0, 2))
        extent = {}
        for k in kids:  # measured on these links, as the extension's junction is
            others = [tubes[o] for o in kids if o != k]
            extent[k] = 0.0
            if others:
                found_k = junction_extent(
                    tubes[k][0], (tubes[k][1], tubes[k][2]),
                    (np.concatenate([t[1] for t in others]),
                     np.concatenate([t[2] for t in others])),
                    r, self.margin, limit=JUNCTION_REACH * r)  # fmt: skip
                extent[k] = min(found_k, JUNCTION_REACH * r)
        found = {
            "kids": kids, "paths": paths, "tubes": tubes, "rows": rows, "along": along,
            "extent": extent,
            "a": np.concatenate([tubes[k][1] for k in kids]),
            "b": np.concatenate([tubes[k][2] for k in kids]),
        }  # fmt: skip
        self._junctions[p] = found
        return found

    def _new_tube_path(self, joints, p: int) -> list[int]:
        """The new joints whose links make the tube leaving p towards the first of them."""
        n0, n = len(self.joints), len(joints)
        path = [n0]
        while not joints[path[-1]].has_body and path[-1] + 1 < n:
            path.append(path[-1] + 1)
        return path

    def _extended(self, joints, links, parents, p: int) -> TreeCapsules:
        """The TreeCapsules of the extension as far as pairs with a new part use them, but
        without the junction values (extent, along) of the junction at p (see
        :meth:`_with_junction`); other junctions keep the tree's."""
        caps, r = self._base(), self.r
        n0, n = len(self.joints), len(joints)
        path_turning = np.concatenate([caps.path_turning, np.zeros(n - n0)])
        rows: list = []
        pieces_a, pieces_b, owner_node, base_turn = [], [], [], []
        for j in range(n0, n):
            (A, B, _, turn), link_rows, total = link_capsule_arrays(links[j], j, r, 0.2)
            path_turning[j] = total + path_turning[parents[j]]
            for (A_, B_, _, turn_), part in (((A, B, None, turn), link_rows),
                                             joint_capsule_arrays(joints[j], j, r)):
                if len(part):
                    pieces_a.append(A_)
                    pieces_b.append(B_)
                    owner_node.append(np.full(len(part), j))
                    base_turn.append(turn_)
                    rows += part
        S1 = len(rows)
        if S1:
            a1, b1 = np.concatenate(pieces_a), np.concatenate(pieces_b)
            node1 = np.concatenate(owner_node).astype(np.int64)
            own1 = np.concatenate(base_turn)
        else:
            a1, b1, node1, own1 = (np.zeros((0, 3)), np.zeros((0, 3)), np.zeros(0, np.int64),
                                   np.zeros(0))  # fmt: skip
        element1 = np.fromiter((row[5] for row in rows), dtype=np.int64, count=S1)
        body_a = np.fromiter((row[2] for row in rows), dtype=np.int64, count=S1)
        body_b = np.fromiter((row[3] for row in rows), dtype=np.int64, count=S1)
        is_link1 = element1 % 2 == 1
        parent_of = np.array(parents, dtype=np.int64)
        before = np.where(is_link1, path_turning[parent_of[node1]], path_turning[node1])
        ancestor = np.zeros((n, n), dtype=bool)
        ancestor[:n0, :n0] = caps.ancestor
        for x in range(n0, n):
            ancestor[x] = ancestor[parents[x]]
            ancestor[x, x] = True
        top = np.concatenate([caps.top, np.full(n - n0, -1, dtype=np.int64)])
        if self._children[p]:  # the new tube joins the junction at p (new if p had one child)
            junction = self._junction(p)
            top[self._new_tube_path(joints, p)] = n0
            for k in junction["kids"]:
                top[junction["paths"][k]] = k
        return TreeCapsules(
            r, np.concatenate([caps.starts, a1]), np.concatenate([caps.ends, b1]),
            np.concatenate([caps.start_joint, np.where(body_a == node1, node1,
                                                       parent_of[node1])]),
            np.concatenate([caps.end_joint, np.where(body_b == node1, node1, parent_of[node1])]),
            np.concatenate([caps.turning, own1 + before]),
            np.concatenate([caps.element, element1]), np.concatenate([caps.node, node1]),
            caps.rows + tuple(rows), tuple(parents), ancestor,
            np.concatenate([caps.is_link, is_link1]), top,
            np.concatenate([caps.extent, np.zeros(n - n0)]),
            np.concatenate([caps.along, np.full((S1, 2), np.nan)]), path_turning,
        )  # fmt: skip

    def _with_junction(self, caps: TreeCapsules, joints, links, p: int) -> TreeCapsules:
        """``caps`` (of :meth:`_extended`) with the extents of the tubes leaving p and the
        distances along them of their rows."""
        if not self._children[p]:
            return caps
        r, n0 = self.r, len(self.joints)
        junction = self._junction(p)
        new_path = self._new_tube_path(joints, p)
        tube = _tube([links[m] for m in new_path], new_path, r)
        limit = JUNCTION_REACH * r
        extent, along = caps.extent.copy(), caps.along.copy()
        extent[n0] = min(junction_extent(tube[0], (tube[1], tube[2]),
                                         (junction["a"], junction["b"]), r, self.margin,
                                         limit=limit), limit)  # fmt: skip
        for k in junction["kids"]:
            own = junction["tubes"][k]
            against_new = junction_extent(own[0], (own[1], own[2]), (tube[1], tube[2]), r,
                                          self.margin, limit=limit)  # fmt: skip
            extent[k] = min(max(junction["extent"][k], against_new), limit)
            along[junction["rows"][k]] = junction["along"][k]
        rows_new = np.flatnonzero((caps.top[caps.node] == n0) & caps.is_link)
        if rows_new.size:
            d = _polyline_distance(np.concatenate([caps.starts[rows_new], caps.ends[rows_new]]),
                                   tube[0])  # fmt: skip
            along[rows_new, 0], along[rows_new, 1] = d[: rows_new.size], d[rows_new.size :]
        return dataclasses.replace(caps, extent=extent, along=along)
