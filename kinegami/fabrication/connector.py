"""The printed junction connector of a branch node (docs/junctions.md).

A branch node B of a kinematic tree has a distal Dubins frame D and child links L_c, all
starting at D. Near D the sibling tubes overlap; a 3D-printed connector holds them there. Its
inputs are plain: the tube radius r, ``numSides`` n, D (4x4, world), the child links
(:class:`~kinegami.chain.links.LinkCSC`, each starting at D; children reached through zero-length
waypoints are given by their own links), which child is the trunk (optional) and the options.
Lengths are in the units of r; frames are 4x4 world arrays whose first axis is the tangent.

* :func:`sibling_overlap_lengths`: the overlap length l_ov(c), the largest arc length sigma on
  L_c at which the centreline is still within 2r of a sibling's centreline.
* :func:`link_frame_at`: the frame on a link at arc length sigma (the transported Dubins frame).
* :func:`junction_sockets`: where each child's socket ends (sigma_c = l_ov(c) + d_s) and where
  its sheet starts (the frame at sigma_c - d_s), with the feasibility check sigma_c <= l(L_c).
* :func:`junction_connector`: the watertight mesh (trimesh), built with manifold3d booleans
  (the optional ``print`` extra).
"""

from __future__ import annotations

import functools
import math
from collections.abc import Sequence
from dataclasses import dataclass
from typing import TYPE_CHECKING, Literal

import numpy as np

from kinegami.chain.links import LinkCSC
from kinegami.errors import ExporterUnavailableError, InvalidParameterError, InvalidTypeError
from kinegami.geometry.csc_centreline import (
    csc_distances,
    csc_points,
    csc_tangents,
    csc_transported_frame,
)
from kinegami.validation import (
    check_in_range,
    check_int,
    check_num_sides,
    check_radius,
)

if TYPE_CHECKING:  # pragma: no cover
    import trimesh

__all__ = [
    "ConnectorOptions",
    "JunctionSocket",
    "ParentSide",
    "sibling_overlap_lengths",
    "link_frame_at",
    "junction_sockets",
    "junction_connector",
    "trunk_split_plane",
    "split_connector",
    "section_polygon",
]

#: What the connector does on the parent's side of D (docs/junctions.md).
ParentSide = Literal["socket", "flange", "base", "none"]
PARENT_SIDES: tuple[str, ...] = ("socket", "flange", "base", "none")
#: Where a socket starts (:class:`ConnectorOptions`).
SOCKET_RULES: tuple[str, ...] = ("clear", "overlap")

#: Centreline points closer than this many r to a sibling's centreline overlap it.
OVERLAP_FACTOR = 2.0
#: Largest sampling step of the overlap search, in units of r.
MAX_OVERLAP_STEP = 0.01


# --- overlap lengths and frames -----------------------------------------------------------
def _check_links(links, r: float | None = None) -> list[LinkCSC]:
    if isinstance(links, LinkCSC) or not isinstance(links, Sequence):
        raise InvalidTypeError(f"links must be a sequence of LinkCSC, got {type(links).__name__}")
    links = list(links)
    for k, link in enumerate(links):
        if not isinstance(link, LinkCSC):
            raise InvalidTypeError(f"links[{k}] must be a LinkCSC, got {type(link).__name__}")
        if r is not None and abs(link.r - r) > 1e-12 * r:
            raise InvalidParameterError(
                f"links[{k}] has r = {link.r!r}, the junction's r = {r!r}; every child link "
                "must have the junction's tube radius"
            )
    if len(links) < 2:
        raise InvalidParameterError(
            f"links must hold at least 2 child links (a junction has siblings), got {len(links)}"
        )
    return links


def _check_step(step, r: float) -> float:
    if step is None:
        return MAX_OVERLAP_STEP * r
    return check_in_range(
        "step",
        step,
        0.0,
        MAX_OVERLAP_STEP * r,
        high_inclusive=True,
        range_text=f"(0, 0.01 r] = (0, {MAX_OVERLAP_STEP * r:g}] (r = {r:g})",
    )


def sibling_overlap_lengths(
    links: Sequence[LinkCSC],
    r: float,
    step: float | None = None,
    *,
    distance: float | None = None,
) -> np.ndarray:
    """The overlap length of each child link with its siblings (units of r).

    l_ov(c) = sup{sigma <= l(L_c) : the centreline point gamma_c(sigma) is within 2r of the
    centreline of some sibling}: sampled every ``step`` <= 0.01 r (default 0.01 r), with
    exact point-to-centreline distances, and the last crossing of 2r refined by bisection to
    1e-12 r. All links start at the same point, so l_ov(c) >= min(2r, l(L_c)).

    Parameters
    ----------
    links : the child links (at least 2), all starting at the branch node's distal frame.
    r : tube radius.
    step : sampling step along each link, in (0, 0.01 r].
    distance : the threshold, in [2r, 100 r] (default 2r; :func:`junction_sockets` also uses
        R_in + R_out, the centreline distance at which a socket's wall is clear of its
        siblings).

    Returns
    -------
    (k,) array, one overlap length per link, in link order.

    Examples
    --------
    >>> a = LinkCSC(1, SE3(), SE3.Trans(10, 6, 0))
    >>> b = LinkCSC(1, SE3(), SE3.Trans(10, -6, 0))
    >>> sibling_overlap_lengths([a, b], 1.0).round(3).tolist()
    [2.482, 2.482]
    """
    r = check_radius(r)
    links = _check_links(links, r)
    step = _check_step(step, r)
    if distance is None:
        limit = OVERLAP_FACTOR * r
    else:
        limit = check_in_range(
            "distance",
            distance,
            OVERLAP_FACTOR * r,
            100.0 * r,
            low_inclusive=True,
            high_inclusive=True,
            range_text=f"[2 r, 100 r] = [{2 * r:g}, {100 * r:g}] (r = {r:g})",
        )
    return _overlap_lengths(tuple(links), float(r), float(step), float(limit)).copy()


@functools.lru_cache(maxsize=32)
def _overlap_lengths(links: tuple, r: float, step: float, limit: float) -> np.ndarray:
    """:func:`sibling_overlap_lengths` of checked arguments, kept for the last few sets of
    links (immutable values, keyed by identity): choosing a tree's trunks and then building
    its sockets asked for the same junctions again (fuzz operations seed 504290: 18 calls,
    10 distinct, 0.7 s each)."""
    out = np.zeros(len(links))
    for k, link in enumerate(links):
        others = [other.path for j, other in enumerate(links) if j != k]
        length = link.length

        def gap(sigma, path=link.path, others=others):
            P = csc_points(path, sigma)
            return np.min([csc_distances(q, P) for q in others], axis=0) - limit

        count = max(1, math.ceil(length / step))
        i = _last_inside(gap, length, count)
        if i is None:  # cannot happen for links that start at one point
            continue
        if i == count:
            out[k] = length
            continue
        lo, hi = (float(x) for x in _grid(length, count, np.array([i, i + 1])))
        while hi - lo > 1e-12 * r:
            mid = 0.5 * (lo + hi)
            if not lo < mid < hi:  # adjacent floats (far out, 1e-12 r is below their spacing)
                break
            if gap(np.array([mid]))[0] < 0.0:
                lo = mid
            else:
                hi = mid
        out[k] = hi
    return out


#: Most samples :func:`sibling_overlap_lengths` evaluates at once (bounds its arrays).
_OVERLAP_CHUNK = 16_384
#: Index intervals this short are evaluated sample by sample rather than split further.
_OVERLAP_LEAF = 32


def _grid(length: float, count: int, k) -> np.ndarray:
    """Samples ``k`` (an int array) of ``np.linspace(0, length, count + 1)``, bit for bit."""
    sigma = np.asarray(k, dtype=float) * (length / count) + 0.0
    sigma[np.asarray(k) == count] = length
    return sigma


def _gaps(gap, length: float, count: int, k: np.ndarray) -> np.ndarray:
    """``gap`` at samples ``k``, at most :data:`_OVERLAP_CHUNK` at a time."""
    return np.concatenate(
        [gap(_grid(length, count, k[i : i + _OVERLAP_CHUNK]))
         for i in range(0, k.size, _OVERLAP_CHUNK)] or [np.zeros(0)]
    )  # fmt: skip


def _last_inside(gap, length: float, count: int) -> int | None:
    """The largest k in [0, count] with ``gap(sigma_k) < 0`` on the grid of :func:`_grid`,
    or None: the answer of evaluating every sample, without evaluating most of them.

    The index range is split at the middle of each interval: a middle inside makes everything
    below it irrelevant; a middle outside by g excludes the samples within g of it in arc
    length (the centreline moves at most as far as the arc length, so the distance to a
    sibling changes at most as much). Links 1e6 r long (1e8 samples) thus cost about as much
    as short ones, in bounded memory (issue 29)."""
    spacing = length / count
    best = -1
    intervals = np.array([[0, count]], dtype=np.int64)
    while intervals.size:
        intervals = intervals[intervals[:, 1] > best]
        intervals[:, 0] = np.maximum(intervals[:, 0], best + 1)
        short = intervals[:, 1] - intervals[:, 0] < _OVERLAP_LEAF
        if short.any():
            k = np.concatenate([np.arange(a, b + 1) for a, b in intervals[short]])
            inside = k[_gaps(gap, length, count, k) < 0.0]
            if inside.size:
                best = max(best, int(inside.max()))
        intervals = intervals[~short]
        if not intervals.size:
            break
        middle = (intervals[:, 0] + intervals[:, 1]) // 2
        g = _gaps(gap, length, count, middle)
        inside = g < 0.0
        if inside.any():
            best = max(best, int(middle[inside].max()))
        reach = np.where(inside | (spacing <= 0.0), 0.0, g * (1.0 - 1e-9) / max(spacing, 1e-300))
        skip = np.floor(np.minimum(reach, float(count + 1))).astype(np.int64)
        lower = np.stack([intervals[:, 0], middle - 1 - skip], axis=1)
        upper = np.stack([middle + 1 + skip, intervals[:, 1]], axis=1)
        lower = lower[~inside]
        intervals = np.concatenate([upper, lower])
        intervals = intervals[intervals[:, 0] <= intervals[:, 1]]
    return None if best < 0 else best


def link_frame_at(link: LinkCSC, sigma: float) -> np.ndarray:
    """The frame on ``link`` at arc length ``sigma`` (4x4 world array, first axis = tangent).

    The link's start Dubins frame transported along its centreline: for sigma <= r theta1 the
    frame after one elbow of angle sigma / r (same rotation-axis angle phi1 as arc 1); on the
    straight part F1 Trans(sigma - r theta1, 0, 0) with F1 the frame after arc 1 (the roll
    before the link's twist fitting); on arc 2 that frame turned about arc 2's axis.
    ``sigma`` must lie in [0, l(L)].

    Examples
    --------
    >>> link = LinkCSC(1, SE3(), SE3.Trans(10, 4, 0))
    >>> F = link_frame_at(link, link.length)
    >>> bool(np.allclose(F[:3, 3], (10, 4, 0)))
    True
    """
    if not isinstance(link, LinkCSC):
        raise InvalidTypeError(f"link must be a LinkCSC, got {type(link).__name__}")
    length = link.length
    sigma = check_in_range(
        "sigma",
        sigma,
        0.0,
        length,
        low_inclusive=True,
        high_inclusive=True,
        range_text=f"[0, {length:.6g}] (the link's length)",
    )
    return csc_transported_frame(link.path, link.start_frame, sigma)


# --- options -------------------------------------------------------------------------------
@dataclass(frozen=True)
class ConnectorOptions:
    """Dimensions of a printed junction connector (lengths in the units of r).

    ``None`` means the default for the tube radius r (``resolved(r)`` fills them in).

    Attributes
    ----------
    thickness : sheet thickness t, in [0, 0.5 r] (default 0.01 r).
    clearance : gap delta between the paper and the socket, in [0, 0.5 r] (default 0.02 r).
    wall : wall thickness w of the connector, in (0, 2 r] (default 0.2 r).
    socket_depth : how far each paper tube reaches into its socket, d_s, in (0, 100 r]
        (default r).
    extension : how far the voids reach past the open ends, epsilon, in (0, r]
        (default 0.01 r).
    plate : thickness of the flange and of the base plate, in (0, 10 r] (default = wall).
    mitre_angle : largest turn of one mitred prism where a channel follows an arc, in
        (0, pi/2] (default pi/16).
    socket_rule : where a socket starts. ``"clear"`` (default): at l_clear(c), the last arc
        length within (R_in + R_out) / cos(mitre_angle / 2) of a sibling's centreline, so no
        sibling's void or paper tube enters the socket's wall; ``"overlap"``: at l_ov(c) (2r),
        the shortest socket, whose wall a sibling's void may nick where the socket starts.
    """

    thickness: float | None = None
    clearance: float | None = None
    wall: float | None = None
    socket_depth: float | None = None
    extension: float | None = None
    plate: float | None = None
    mitre_angle: float = math.pi / 16
    socket_rule: Literal["clear", "overlap"] = "clear"

    def resolved(self, r: float) -> ConnectorOptions:
        """The options with every default filled in for the tube radius ``r``, checked."""
        r = check_radius(r)

        def length(name, value, default, low, high, low_inclusive):
            if value is None:
                value = default
            low_text = "[" if low_inclusive else "("
            return check_in_range(
                name,
                value,
                low * r,
                high * r,
                low_inclusive=low_inclusive,
                high_inclusive=True,
                range_text=(
                    f"{low_text}{low:g} r, {high:g} r] = {low_text}{low * r:g}, {high * r:g}] "
                    f"(r = {r:g})"
                ),
            )

        wall = length("wall", self.wall, 0.2 * r, 0.0, 2.0, False)
        if self.socket_rule not in SOCKET_RULES:
            raise InvalidParameterError(
                f"socket_rule must be one of {', '.join(map(repr, SOCKET_RULES))}, "
                f"got {self.socket_rule!r}"
            )
        return ConnectorOptions(
            thickness=length("thickness", self.thickness, 0.01 * r, 0.0, 0.5, True),
            clearance=length("clearance", self.clearance, 0.02 * r, 0.0, 0.5, True),
            wall=wall,
            socket_depth=length("socket_depth", self.socket_depth, r, 0.0, 100.0, False),
            extension=length("extension", self.extension, 0.01 * r, 0.0, 1.0, False),
            plate=length("plate", self.plate, wall, 0.0, 10.0, False),
            mitre_angle=check_in_range(
                "mitre_angle",
                self.mitre_angle,
                0.0,
                math.pi / 2,
                high_inclusive=True,
                range_text="(0, pi/2]",
            ),
            socket_rule=self.socket_rule,
        )

    def inner_radius(self, r: float, numSides: int) -> float:
        """Circumradius R_in = r + (t + delta) / cos(pi/n) of the voids (offsets normal to the
        faces). Call on resolved options."""
        return r + (self.thickness + self.clearance) / math.cos(math.pi / numSides)

    def outer_radius(self, r: float, numSides: int) -> float:
        """Circumradius R_out = R_in + w / cos(pi/n) of the channels. Call on resolved options."""
        return self.inner_radius(r, numSides) + self.wall / math.cos(math.pi / numSides)

    def paper_radius(self, r: float, numSides: int) -> float:
        """Circumradius r + t / cos(pi/n) of the outside of a paper tube of thickness t."""
        return r + self.thickness / math.cos(math.pi / numSides)


def _options(options: ConnectorOptions | None, r: float) -> ConnectorOptions:
    if options is None:
        options = ConnectorOptions()
    elif not isinstance(options, ConnectorOptions):
        raise InvalidTypeError(
            f"options must be a ConnectorOptions or None, got {type(options).__name__}"
        )
    return options.resolved(r)


# --- sockets -------------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class JunctionSocket:
    """Where one child's tube meets the connector (lengths in units of r, along the link).

    Attributes
    ----------
    child : index of the child in the links given.
    trunk : True for the trunk (a sleeve over [-d_s, start] around the continuous tube).
    overlap : l_ov(c) (centreline within 2r of a sibling's).
    clear : l_clear(c) (within (R_in + R_out) / cos(mitre_angle / 2)); >= overlap.
    start : where the socket starts: ``clear`` or ``overlap`` (``ConnectorOptions.socket_rule``).
    socket_end : sigma_c = start + d_s >= l_ov(c) + d_s, where the connector ends (trunk:
        ``start``, where its sleeve ends).
    sheet_start : sigma_c - d_s, where the child's paper tube (its sheet) starts (trunk: None,
        its sheet runs through).
    frame : read-only 4x4 frame on the link at ``sheet_start`` (trunk: at ``socket_end``).
    link_length : l(L_c).
    fits : False when the socket would end past the link (only with ``strict=False``; the
        socket is then clipped to the link's end).
    """

    child: int
    trunk: bool
    overlap: float
    clear: float
    start: float
    socket_end: float
    sheet_start: float | None
    frame: np.ndarray
    link_length: float
    fits: bool = True


def _check_frame(D, r: float) -> np.ndarray:
    try:
        D = np.array(getattr(D, "A", D), dtype=float)
    except (TypeError, ValueError):
        raise InvalidTypeError(f"D must be a 4x4 array or SE3, got {type(D).__name__}") from None
    if D.shape != (4, 4) or not np.all(np.isfinite(D)):
        raise InvalidParameterError(f"D must be a finite 4x4 frame, got shape {D.shape}")
    R = D[:3, :3]
    if (
        np.abs(R.T @ R - np.eye(3)).max() > 1e-9
        or np.linalg.det(R) < 0
        or np.abs(D[3] - (0, 0, 0, 1)).max() > 1e-12
    ):
        raise InvalidParameterError("D must be a rigid transform (rotation and translation)")
    return D


def _check_starts(links: list[LinkCSC], D: np.ndarray, r: float) -> None:
    for k, link in enumerate(links):
        S = link.start_frame
        scale = max(1.0, float(np.abs(D[:3, 3]).max()) / r)
        if (
            float(np.abs(S[:3, 3] - D[:3, 3]).max()) > 1e-9 * r * scale
            or float(np.abs(S[:3, :3] - D[:3, :3]).max()) > 1e-9
        ):
            raise InvalidParameterError(
                f"links[{k}] must start at the branch node's distal frame D: it starts at "
                f"{np.round(S[:3, 3], 6).tolist()} with axes {np.round(S[:3, :3], 6).tolist()}, "
                f"D is at {np.round(D[:3, 3], 6).tolist()} with axes "
                f"{np.round(D[:3, :3], 6).tolist()}"
            )


def _check_trunk(trunk, count: int) -> int | None:
    if trunk is None:
        return None
    trunk = check_int("trunk", trunk, 0)
    if trunk >= count:
        raise InvalidParameterError(
            f"trunk must be None or a child index in [0, {count - 1}], got {trunk}"
        )
    return trunk


def junction_sockets(
    links: Sequence[LinkCSC],
    r: float,
    numSides: int,
    *,
    trunk: int | None = None,
    options: ConnectorOptions | None = None,
    step: float | None = None,
    strict: bool = True,
) -> tuple[JunctionSocket, ...]:
    """The socket of each child: overlaps, socket end, sheet start and its frame.

    A socket starts at l_clear(c) (``socket_rule="clear"``, the default) or l_ov(c)
    (``"overlap"``) and ends d_s further, at sigma_c; the child's sheet starts where the
    socket starts, at the frame :func:`link_frame_at` gives there. Feasible only if
    sigma_c <= l(L_c): otherwise InvalidParameterError (naming the child, sigma_c and the link
    length); slide the child along its axis or re-place it first. The trunk gets no socket: its
    sleeve ends where its socket would start, and is always feasible. With ``strict=False``
    an infeasible socket is returned with ``fits=False`` (clipped to the link) instead.

    Examples
    --------
    >>> a = LinkCSC(1, SE3(), SE3.Trans(10, 6, 0))
    >>> b = LinkCSC(1, SE3(), SE3.Trans(10, -6, 0))
    >>> [round(s.socket_end, 3) for s in junction_sockets([a, b], 1.0, 4)]
    [3.901, 3.901]
    """
    r = check_radius(r)
    n = check_num_sides(numSides)
    links = _check_links(links, r)
    trunk = _check_trunk(trunk, len(links))
    opts = _options(options, r)
    overlaps = sibling_overlap_lengths(links, r, step)
    wall_distance = (opts.inner_radius(r, n) + opts.outer_radius(r, n)) / math.cos(
        opts.mitre_angle / 2.0
    )
    clears = sibling_overlap_lengths(links, r, step, distance=wall_distance)
    clears = np.maximum(clears, overlaps)
    d_s = opts.socket_depth
    sockets = []
    for k, (link, ov, cl) in enumerate(zip(links, overlaps, clears, strict=True)):
        ov, cl = float(ov), float(cl)
        length = link.length
        start = cl if opts.socket_rule == "clear" else ov
        if k == trunk:
            frame = link_frame_at(link, start)
            frame.setflags(write=False)
            sockets.append(JunctionSocket(k, True, ov, cl, start, start, None, frame, length))
            continue
        end = start + d_s
        if end > length + 1e-12 * r and not strict:
            frame = link_frame_at(link, max(length - d_s, 0.0))
            frame.setflags(write=False)
            sheet = max(length - d_s, 0.0)
            sockets.append(JunctionSocket(k, False, ov, cl, start, length, sheet, frame, length,
                                          False))  # fmt: skip
            continue
        if end > length + 1e-12 * r:
            rule = "l_clear" if opts.socket_rule == "clear" else "l_ov"
            raise InvalidParameterError(
                f"junction child {k} is infeasible: its socket would end at sigma_c = {rule} + "
                f"d_s = {start:.6g} + {d_s:.6g} = {end:.6g}, past the end of its link (length "
                f"{length:.6g}; l_ov = {ov:.6g}, l_clear = {cl:.6g}); sigma_c must lie in "
                f"[{rule} + d_s, l(L_c)] = [{end:.6g}, {length:.6g}], which is empty. Slide the "
                "child along its axis (or re-place it) so that its link is longer, or reduce "
                "socket_depth"
            )
        end = min(end, length)
        frame = link_frame_at(link, end - d_s)
        frame.setflags(write=False)
        sockets.append(JunctionSocket(k, False, ov, cl, start, end, end - d_s, frame, length))
    return tuple(sockets)


# --- geometry of the channels -----------------------------------------------------------------
def section_polygon(frame: np.ndarray, radius: float, numSides: int) -> np.ndarray:
    """(n, 3) vertices of the n-gon of circumradius ``radius`` in the (b, c) plane of
    ``frame``, vertex k at angle (k + 1/2) 2 pi / n from b (docs/theory/patterns.md §1)."""
    psi = (np.arange(numSides) + 0.5) * 2.0 * math.pi / numSides
    F = np.asarray(frame, dtype=float)
    return (
        F[:3, 3]
        + radius * np.cos(psi)[:, None] * F[:3, 1]
        + radius * np.sin(psi)[:, None] * F[:3, 2]
    )


@dataclass(frozen=True)
class _Sweep:
    """A polyline centreline with a frame per leg: leg i runs from points[i] to points[i+1]
    along frames[i][:3, 0]; consecutive legs meet in their bisector plane."""

    points: np.ndarray  # (m + 1, 3)
    frames: np.ndarray  # (m, 4, 4)


def _link_sweep(link: LinkCSC, s0: float, s1: float, max_angle: float) -> _Sweep:
    """The link's centreline over [s0, s1] as mitred legs (arcs split into sub-elbows of at
    most ``max_angle``, each from the arc to the crossing of its tangents and back), extended
    straight along the tangent before 0 and past the link's end."""
    path = link.path
    r = link.r
    length = link.length
    l1 = r * path.theta1
    l2 = l1 + path.tMag
    a0, a1 = max(s0, 0.0), min(s1, length)
    points = [csc_points(path, [a0])[0] + min(s0, 0.0) * csc_tangents(path, [0.0])[0]]
    frames = [csc_transported_frame(path, link.start_frame, a0)]
    for lo, hi in ((0.0, l1), (l2, length)):
        lo, hi = max(lo, a0), min(hi, a1)
        if hi - lo <= 1e-12 * r:
            continue
        count = max(1, math.ceil((hi - lo) / r / max_angle - 1e-12))
        beta = (hi - lo) / r / count
        half = r * math.tan(beta / 2.0)
        for j in range(count):
            F = csc_transported_frame(path, link.start_frame, lo + j * r * beta)
            points.append(F[:3, 3] + half * F[:3, 0])
            frames.append(csc_transported_frame(path, link.start_frame, lo + (j + 1) * r * beta))
    end = csc_points(path, [a1])[0] + max(s1 - length, 0.0) * csc_tangents(path, [length])[0]
    points.append(end)
    return _Sweep(np.array(points), np.array(frames))


def _straight_sweep(frame: np.ndarray, s0: float, s1: float) -> _Sweep:
    """A straight leg along the frame's first axis over [s0, s1] (frame origin at 0)."""
    F = np.asarray(frame, dtype=float)
    a = F[:3, 0]
    pts = np.array([F[:3, 3] + s0 * a, F[:3, 3] + s1 * a])
    G = F.copy()
    G[:3, 3] = pts[0]
    return _Sweep(pts, G[None])


def _leg_point_sets(
    sweep: _Sweep, radius: float, n: int, pairs: bool, overlap: float = 0.0
) -> list[np.ndarray]:
    """Point sets whose convex hulls make up the channel swept along ``sweep``.

    Each leg is a mitred prism: its section projected along the leg onto the planes at both
    ends (2n points), pushed ``overlap`` past each interior mitre so that neighbouring legs
    overlap instead of only touching (fragile in a boolean kernel). With ``pairs`` the pieces
    are the hulls of consecutive legs instead: they also fill the notch that the legs leave on
    the inside of a bend where the section reaches past the turning radius (for the outside of
    a channel; a void must not grow there)."""
    P, F = sweep.points, sweep.frames
    m = len(F)
    A = F[:, :3, 0]
    legs = []
    for i in range(m):
        a = A[i]
        n0 = a if i == 0 else A[i - 1] + A[i]
        n1 = a if i == m - 1 else A[i] + A[i + 1]
        G = F[i].copy()
        G[:3, 3] = P[i]
        poly = section_polygon(G, radius, n)
        ends = []
        for q, normal, push in (
            (P[i], n0, -overlap if i > 0 else 0.0),
            (P[i + 1], n1, overlap if i < m - 1 else 0.0),
        ):
            lam = ((q - poly) @ normal) / float(a @ normal) + push
            ends.append(poly + lam[:, None] * a)
        legs.append(np.vstack(ends))
    if not pairs or m < 2:
        return legs
    return [np.vstack(pair) for pair in zip(legs[:-1], legs[1:], strict=True)]


def _manifold():
    """manifold3d, once trimesh (which the mesh is returned as) is known to import too."""
    try:
        import manifold3d
        import trimesh  # noqa: F401
    except ImportError as exc:
        missing = getattr(exc, "name", None) or "manifold3d"
        raise ExporterUnavailableError(
            f"the junction connector mesh is not available: cannot import {missing} ({exc}); "
            "to add it: pip install 'kinegami[print]'"
        ) from exc
    return manifold3d


def _solid(mf, point_sets: list[np.ndarray]):
    """Union of the convex hulls of the point sets (empty hulls of flat legs dropped)."""
    hulls = [mf.Manifold.hull_points(np.ascontiguousarray(p, dtype=float)) for p in point_sets]
    hulls = [h for h in hulls if not h.is_empty()]
    if not hulls:
        return mf.Manifold()
    return mf.Manifold.batch_boolean(hulls, mf.OpType.Add)


def _to_trimesh(solid):
    import trimesh

    mesh = solid.to_mesh64()
    vertices = np.asarray(mesh.vert_properties, dtype=float)[:, :3]
    faces = np.asarray(mesh.tri_verts, dtype=np.int64)
    return trimesh.Trimesh(vertices=vertices, faces=faces, process=True)


def _check_parent_side(parent_side) -> str:
    if parent_side not in PARENT_SIDES:
        raise InvalidParameterError(
            f"parent_side must be one of {', '.join(map(repr, PARENT_SIDES))}, got {parent_side!r}"
        )
    return parent_side


def junction_connector(
    r: float,
    numSides: int,
    D,
    links: Sequence[LinkCSC],
    *,
    parent_side: ParentSide,
    trunk: int | None = None,
    options: ConnectorOptions | None = None,
    step: float | None = None,
) -> trimesh.Trimesh:
    """The printed junction connector of a branch node as one watertight mesh (world frame).

    Each child c gets a channel: the n-gon section of the transported Dubins frame swept along
    its centreline over [0, sigma_c] (straight parts as prisms, arcs as mitred prisms of at
    most ``options.mitre_angle``), outer circumradius R_out, void R_in (see
    :class:`ConnectorOptions`); the body is the union of the outer channels minus the union
    of the voids, which reach ``options.extension`` past every open end. The trunk (if given)
    gets a sleeve open at both ends, over [-d_s, l_clear(t)] (or l_ov(t)), instead of a socket.

    ``parent_side`` (docs/junctions.md) says what the connector does behind D, along -a_D:
    ``"socket"``: a socket over [-d_s, 0] for a parent that ends in a plain tube at least d_s
    long; ``"flange"``: an annular plate (R_in to R_out, thickness ``options.plate``) just
    behind D, glued to the parent's distal end; ``"base"``: a closed plate of that thickness
    (a root waypoint); ``"none"``: the hub stays open at D. With a trunk, ``"socket"`` is the
    sleeve's lower part.

    Parameters
    ----------
    r : tube radius. numSides : n, even >= 4.
    D : the branch node's distal Dubins frame (4x4 array or SE3, world).
    links : the child links (at least 2), each starting at D.
    parent_side : "socket", "flange", "base" or "none" (keyword, no default: the caller knows
        how the parent ends).
    trunk : index in ``links`` of the child whose tube runs through the hub, or None.
    options : :class:`ConnectorOptions` (defaults: t = 0.01 r, delta = 0.02 r, w = 0.2 r,
        d_s = r).
    step : sampling step of the overlap search (:func:`sibling_overlap_lengths`).

    Raises
    ------
    InvalidParameterError : a child whose socket would end past its link (sigma_c > l(L_c)),
        links that do not start at D, bad options.
    ExporterUnavailableError : manifold3d is not installed (``pip install 'kinegami[print]'``).
    """
    r = check_radius(r)
    n = check_num_sides(numSides)
    D = _check_frame(D, r)
    links = _check_links(links, r)
    _check_starts(links, D, r)
    parent_side = _check_parent_side(parent_side)
    opts = _options(options, r)
    sockets = junction_sockets(links, r, n, trunk=trunk, options=opts, step=step)
    mf = _manifold()
    return _clean_mesh(mf, n, D, links, sockets, parent_side, opts, r)


#: How far the legs of a void reach past each mitre into their neighbours (units of r), tried
#: in turn until the mesh has no two surfaces touching along an edge (see _clean_mesh).
_OVERLAPS = (1e-4, 3e-4, 1e-3, 3e-3)


def _clean_mesh(mf, n, D, links, sockets, parent_side, opts, r):
    """The connector as a trimesh that stays watertight when its vertices are merged.

    Where channels share faces the boolean kernel may return surfaces that touch along an
    edge (valid as a manifold, with coincident vertices, but not after a reader merges them):
    the voids' overlaps at the mitres are varied until that does not happen; if it always
    does, the last mesh is returned without merging (still closed and oriented)."""
    import trimesh

    for overlap in _OVERLAPS:
        solid = _without_slivers(
            mf, _connector_solid(mf, n, D, links, sockets, parent_side, opts, r, overlap * r), r
        )
        mesh = _to_trimesh(solid)
        if mesh.is_watertight and mesh.is_volume:
            merged = _single_precision_safe(mesh)
            if merged is not None:
                return merged
    raw = solid.to_mesh64()
    return trimesh.Trimesh(
        vertices=np.asarray(raw.vert_properties, dtype=float)[:, :3],
        faces=np.asarray(raw.tri_verts, dtype=np.int64),
        process=False,
    )


#: Pieces of a boolean's result below this volume (units of r^3) are rounding, not material.
_SLIVER_VOLUME = 1e-9


def _without_slivers(mf, solid, r: float):
    """``solid`` without the pieces of no volume that the boolean kernel may leave where faces
    nearly coincide (four-vertex pieces of 1e-28 r^3 beside a child tilted by 1.2e-7 rad: the
    connector then had three bodies)."""
    parts = solid.decompose()
    if len(parts) <= 1:
        return solid
    kept = [part for part in parts if part.volume() > _SLIVER_VOLUME * r**3]
    return mf.Manifold.compose(kept) if kept else mf.Manifold()


#: Vertices closer than this share one position (relative to the mesh's largest coordinate):
#: STL stores single precision (about 6e-8 relative), where they would merge anyway.
_MERGE_RELATIVE = 1e-6


def _single_precision_safe(mesh):
    """``mesh`` with the vertices that single precision cannot tell apart merged (clusters
    within _MERGE_RELATIVE of the largest coordinate), and its degenerate faces dropped, if it
    is still a watertight volume whose vertices stay distinct in 32-bit floats; else None. So
    the file a slicer reads (STL: 32-bit floats) is as watertight as the mesh built here."""
    import trimesh
    from scipy.sparse import coo_matrix
    from scipy.sparse.csgraph import connected_components
    from scipy.spatial import cKDTree

    vertices = np.asarray(mesh.vertices, dtype=float)
    tol = _MERGE_RELATIVE * max(1.0, float(np.abs(vertices).max()))
    pairs = cKDTree(vertices).query_pairs(tol, output_type="ndarray")
    faces = np.asarray(mesh.faces)
    if len(pairs):
        count = len(vertices)
        graph = coo_matrix((np.ones(len(pairs)), (pairs[:, 0], pairs[:, 1])), (count, count))
        _, label = connected_components(graph, directed=False)
        keep = np.unique(label, return_index=True)[1]  # the first vertex of every cluster
        vertices = vertices[keep]
        faces = label[faces]
        faces = faces[(faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2])
                      & (faces[:, 0] != faces[:, 2])]  # fmt: skip
    merged = trimesh.Trimesh(vertices=vertices, faces=faces, process=False)
    merged.remove_unreferenced_vertices()
    if not (merged.is_watertight and merged.is_volume):
        return None
    rounded = merged.vertices.astype(np.float32)
    if len(np.unique(rounded, axis=0)) != len(rounded):
        return None
    return merged


def _connector_solid(mf, n, D, links, sockets, parent_side, opts, r, overlap):
    R_in = opts.inner_radius(r, n)
    R_out = opts.outer_radius(r, n)
    eps = opts.extension
    d_s = opts.socket_depth
    # how far the parts reach behind D (outer) and whether the voids open there
    if parent_side == "socket":
        back, open_back = d_s, True
    elif parent_side == "flange":
        back, open_back = opts.plate, True
    elif parent_side == "base":
        back, open_back = opts.plate, False
    else:
        back, open_back = 0.0, True
    outer_sets: list[np.ndarray] = []
    inner_sets: list[np.ndarray] = []
    # children start along a_D: a short overlap behind D joins them to the parent side
    join = min(eps, back) if back > 0 else 0.0
    for link, sock in zip(links, sockets, strict=True):
        end = sock.socket_end
        outer = _link_sweep(link, -join, end, opts.mitre_angle)
        inner = _link_sweep(link, -eps if open_back else 0.0, end + eps, opts.mitre_angle)
        outer_sets += _leg_point_sets(outer, R_out, n, True)
        inner_sets += _leg_point_sets(inner, R_in, n, False, overlap)
    if back > 0.0:
        outer_sets += _leg_point_sets(_straight_sweep(D, -back, 0.0), R_out, n, True)
        if open_back:
            void = _straight_sweep(D, -back - eps, eps)
            inner_sets += _leg_point_sets(void, R_in, n, False, overlap)
    return _solid(mf, outer_sets) - _solid(mf, inner_sets)


# --- the trunk sleeve in two halves ------------------------------------------------------------
def trunk_split_plane(D, trunk_link: LinkCSC) -> tuple[np.ndarray, np.ndarray]:
    """(point, unit normal) of the plane that splits a trunk sleeve into two halves.

    The plane contains a_D and the trunk's first turn (the trunk's centreline over arc 1 and
    the straight part lies in it), so each half comes off the continuous trunk tube sideways;
    for a trunk that does not turn first, the plane (a_D, b_D).
    """
    D = _check_frame(D, trunk_link.r if isinstance(trunk_link, LinkCSC) else 1.0)
    if not isinstance(trunk_link, LinkCSC):
        raise InvalidTypeError(f"trunk_link must be a LinkCSC, got {type(trunk_link).__name__}")
    path = trunk_link.path
    normal = path.k1 if path.theta1 > 1e-9 else D[:3, 2]
    normal = np.asarray(normal, dtype=float)
    return D[:3, 3].copy(), normal / np.linalg.norm(normal)


def split_connector(
    mesh: trimesh.Trimesh, point, normal
) -> tuple[trimesh.Trimesh, trimesh.Trimesh]:
    """The two halves of a connector mesh cut by the plane through ``point`` with ``normal``
    (first the half on the normal's side); each half is watertight."""
    mf = _manifold()
    point = np.asarray(point, dtype=float)
    normal = np.asarray(normal, dtype=float)
    normal = normal / np.linalg.norm(normal)
    solid = mf.Manifold(
        mf.Mesh64(
            vert_properties=np.ascontiguousarray(mesh.vertices, dtype=np.float64),
            tri_verts=np.ascontiguousarray(mesh.faces, dtype=np.uint64),
        )
    )
    a, b = solid.split_by_plane(normal, float(point @ normal))
    return _to_trimesh(a), _to_trimesh(b)
