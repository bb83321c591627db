"""The flat sheet a tubular pattern is cut from (docs/fabrication.md).

The tube is cut open along the seam x = 0 = W, which bisects the starting panel. The sheet is
the rectangle x in [-b/2, W + b/2], y in [y0, y0 + H]: the n panels of the tube plus a second
copy of the starting panel, so that the two copies overlap face to face when the sheet is rolled
(the glue tab). :func:`flatten` turns a :class:`~kinegami.pattern.TubularPattern` into the
straight lines drawn on that sheet, as plain arrays that every exporter and plot reads:

* every crease is drawn at its position in [0, W) and at the periodic copies x +- W, following
  the shortest path on the tube (docs/theory/patterns.md §1.4), then clipped to the sheet,
  -b/2 <= x <= W + b/2 (the fix of problem B8, docs/theory/patterns.md §6). A piece is kept
  iff it has positive length strictly inside the sheet, so pieces lying on the vertical cut
  edges are dropped (end points within the pattern's tolerance eps = 1e-4 b of an edge count as
  on it); no zero-length and no duplicate lines are produced. For every catalog crease
  (horizontal extent <= b) this is exactly the reference copying rule (docs/theory/patterns.md
  §5.2: the crease, plus copies shifted by +W / -W when it touches the first / last panel
  column, or both halves of a wrapping crease) followed by the clipping; tests/export compares
  the two on random patterns. It also settles the exactly-opposite case of §1.4 by the stored
  vertex order (the B8 wrap-test fix);
* the Boundary: the rectangle x in [0, W] (the nominal tube, seam at both ends), 4 lines;
* the Cut: the rectangle x in [-b/2, W + b/2] (the sheet outline), 4 lines
  (for a pattern of zero height, e.g. a lone waypoint, each rectangle is a single line).

Creases lying on the top or bottom edge of the sheet (B10: the rings at the ends of a twist,
revolute joint or REBO, the midline of a tip) are kept by default, as in the reference, so the
reference line counts hold (tests/export/reference_values.py); ``skip_creases_on_cut=True``
drops every crease lying wholly on those edges (the laser then does not pass twice over the cut
edge).

Everything is in pattern units (the unit of the tube radius r); exporters scale it.
"""

from __future__ import annotations

import math
from collections.abc import Callable
from typing import TYPE_CHECKING

import numpy as np

from kinegami._record import Record
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.pattern._prism import SHEET_TOLERANCE_FACTOR, periodic_dx, readonly
from kinegami.validation import check_bool

if TYPE_CHECKING:  # pragma: no cover
    from kinegami.pattern.tubular import TubularPattern

__all__ = [
    "Sheet",
    "SHEET_KINDS",
    "TOLERANCE_FACTOR",
    "flatten",
    "clip_segments",
    "unique_segments",
    "check_periodicity",
]

#: The kinds of line on a sheet: mountain, valley, boundary (nominal tube), cut (sheet outline).
SHEET_KINDS = ("M", "V", "B", "C")

#: Length tolerance of the flattening, as a multiple of the tube radius r.
TOLERANCE_FACTOR = SHEET_TOLERANCE_FACTOR

_KIND_DTYPE = np.dtype("<U1")


class Sheet(Record):
    """The lines drawn on the flat sheet of a tubular pattern (docs/fabrication.md).

    Attributes
    ----------
    segments : numpy.ndarray, shape (K, 2, 2)
        Line ``i`` goes from ``segments[i, 0]`` to ``segments[i, 1]``, points (x, y) in pattern
        units. Creases come first (mountains, then valleys), then the 4 boundary and the 4 cut
        lines. Read-only.
    kinds : numpy.ndarray of str, shape (K,)
        ``"M"`` mountain, ``"V"`` valley, ``"B"`` boundary, ``"C"`` cut. Read-only.
    width : float
        Tube perimeter W = n b (pattern units).
    sideLength : float
        Panel width b (pattern units).
    y0 : float
        y of the proximal end (the sheet's bottom edge).
    height : float
        Pattern height H; the sheet spans y0 <= y <= y0 + H.
    tolerance : float
        Length tolerance used to clip and de-duplicate (1e-9 r).
    snapTolerance : float
        End points closer than this to a clip line (x = -b/2, W + b/2) are put on it: the
        pattern's tolerance eps = 1e-4 b (docs/theory/patterns.md 1.1).
    """

    segments: np.ndarray
    kinds: np.ndarray
    width: float
    sideLength: float
    y0: float
    height: float
    tolerance: float
    snapTolerance: float

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """The cut rectangle (xmin, ymin, xmax, ymax) = (-b/2, y0, W + b/2, y0 + H)."""
        half = 0.5 * self.sideLength
        return (-half, self.y0, self.width + half, self.y0 + self.height)

    @property
    def boundary(self) -> tuple[float, float, float, float]:
        """The nominal tube rectangle (0, y0, W, y0 + H) (xmin, ymin, xmax, ymax)."""
        return (0.0, self.y0, self.width, self.y0 + self.height)

    @property
    def glueTabs(self) -> tuple[tuple[float, float], tuple[float, float]]:
        """x ranges of the two copies of the starting panel, [-b/2, b/2] and [W - b/2, W + b/2].

        They overlap face to face when the sheet is rolled into the tube.
        """
        half = 0.5 * self.sideLength
        return ((-half, half), (self.width - half, self.width + half))

    @property
    def numLines(self) -> int:
        """Number of lines K (creases, boundary and cut)."""
        return int(self.segments.shape[0])

    def select(self, kind: str) -> np.ndarray:
        """The segments of one kind (``"M"``, ``"V"``, ``"B"`` or ``"C"``), shape (k, 2, 2)."""
        return self.segments[self.kinds == _check_kind(kind)]

    def count(self, kind: str) -> int:
        """Number of lines of one kind."""
        return int(np.count_nonzero(self.kinds == _check_kind(kind)))

    def lengths(self) -> np.ndarray:
        """Length of every line, shape (K,), pattern units."""
        d = self.segments[:, 1] - self.segments[:, 0]
        return np.hypot(d[:, 0], d[:, 1])

    def total_length(self, kind: str) -> float:
        """Summed length of the lines of one kind, pattern units."""
        return float(self.lengths()[self.kinds == _check_kind(kind)].sum())

    def __repr__(self) -> str:
        counts = ", ".join(f"{k}={self.count(k)}" for k in SHEET_KINDS)
        return (
            f"Sheet({counts}, width={self.width:.6g}, sideLength={self.sideLength:.6g}, "
            f"height={self.height:.6g})"
        )


def _check_kind(kind: str) -> str:
    if kind not in SHEET_KINDS:
        raise InvalidParameterError(f"kind must be one of {SHEET_KINDS}, got {kind!r}")
    return kind


def _rectangle(xmin: float, ymin: float, xmax: float, ymax: float) -> np.ndarray:
    """The 4 sides of an axis-aligned rectangle (bottom, right, top, left), shape (4, 2, 2)."""
    corners = np.array([[xmin, ymin], [xmax, ymin], [xmax, ymax], [xmin, ymax]])
    return np.stack([corners, np.roll(corners, -1, axis=0)], axis=1)


#: How :func:`flatten` draws the sheets that are no TubularPattern: their class and the
#: function drawing one (``draw(pattern, skip_creases_on_cut=...)``), registered by the module
#: that defines the class (kinegami.pattern.cutout registers CutPattern).
SHEET_DRAWERS: dict[type, Callable[..., Sheet]] = {}


def flatten(pattern: TubularPattern, *, skip_creases_on_cut: bool = False) -> Sheet:
    """The lines drawn on the flat sheet of ``pattern`` (docs/fabrication.md, clipped as in B8).

    Parameters
    ----------
    pattern : TubularPattern or CutPattern
        The pattern (a module or a whole chain); a
        :class:`~kinegami.pattern.cutout.CutPattern` (a sheet with take-off holes or a skirt)
        is drawn by :func:`~kinegami.pattern.cutout.flatten_cut`.
    skip_creases_on_cut : bool, optional
        Drop the crease pieces lying on the top or bottom edge of the sheet (y = y0 or
        y = y0 + H; B10). Default False: keep them, as the reference does.

    Returns
    -------
    Sheet
        Segments in pattern units with their kinds: the clipped creases (mountains first, then
        valleys), the boundary rectangle [0, W] and the cut rectangle [-b/2, W + b/2].

    Examples
    --------
    >>> from kinegami.pattern import TubeFittingPattern
    >>> sheet = flatten(TubeFittingPattern(4, 1.0, 1.0))
    >>> sheet.count("M"), sheet.count("V"), sheet.count("B"), sheet.count("C")
    (4, 0, 4, 4)
    """
    from kinegami.pattern.tubular import TubularPattern

    if not isinstance(pattern, TubularPattern):
        for kind, draw in SHEET_DRAWERS.items():  # a sheet with take-off holes or a skirt
            if isinstance(pattern, kind):
                return draw(pattern, skip_creases_on_cut=skip_creases_on_cut)
        raise InvalidTypeError(f"pattern must be a TubularPattern, got {type(pattern).__name__}")
    skip_creases_on_cut = check_bool("skip_creases_on_cut", skip_creases_on_cut)
    W, b = pattern.width, pattern.sideLength
    tol = TOLERANCE_FACTOR * pattern.r
    snap = pattern.eps
    y0 = float(pattern.proximalMarker[1])
    H = pattern.height
    xmin, xmax = -0.5 * b, W + 0.5 * b

    # every crease as its shortest path on the tube, starting at its first vertex in [0, W)
    v = pattern.vertices_coords
    e = pattern.edges_vertices
    start = v[e[:, 0]]
    end = v[e[:, 1]].copy()
    end[:, 0] = start[:, 0] + periodic_dx(end[:, 0] - start[:, 0], W)
    base = np.stack([start, end], axis=1)  # (M, 2, 2)
    labels = pattern.edges_assignment.astype(_KIND_DTYPE)
    if skip_creases_on_cut and base.shape[0]:
        ys = base[:, :, 1]
        flat = np.abs(ys[:, 1] - ys[:, 0]) <= tol
        on_edge = (np.abs(ys - y0) <= tol).all(axis=1) | (np.abs(ys - (y0 + H)) <= tol).all(axis=1)
        base, labels = base[~(flat & on_edge)], labels[~(flat & on_edge)]
    # its copies shifted by -W, 0, +W (no other copy can reach the sheet: |dx| < W/2, b <= W/4);
    # a shifted copy lying wholly beyond the strip (past the snap distance) cannot keep a piece,
    # so only the copies near the seam are clipped (same result, in the same order)
    xs = base[:, :, 0]
    reach = snap + tol
    right = base[xs.min(axis=1) + W <= xmax + reach].copy()
    right[..., 0] += W
    left = base[xs.max(axis=1) - W >= xmin - reach].copy()
    left[..., 0] -= W
    copies = np.concatenate([base, right, left])
    labels = np.concatenate([
        labels,
        labels[xs.min(axis=1) + W <= xmax + reach],
        labels[xs.max(axis=1) - W >= xmin - reach],
    ])

    keep, clipped = clip_segments(copies, xmin, xmax, tol, snap)
    creases, labels = clipped[keep], labels[keep]
    unique = unique_segments(creases, labels, tol)
    creases, labels = creases[unique], labels[unique]
    order = np.argsort(labels == "V", kind="stable")  # mountains first, then valleys
    creases, labels = creases[order], labels[order]

    outlines = np.concatenate([_rectangle(0.0, y0, W, y0 + H), _rectangle(xmin, y0, xmax, y0 + H)])
    outline_kinds = np.array(["B"] * 4 + ["C"] * 4, dtype=_KIND_DTYPE)
    if H <= tol:  # a sheet of zero height: each rectangle is a single line
        outlines, outline_kinds = outlines[[0, 4]], outline_kinds[[0, 4]]
    segments = np.concatenate([creases, outlines])
    kinds = np.concatenate([labels, outline_kinds])
    return Sheet(readonly(segments), readonly(kinds), W, b, y0, H, tol, snap)


def clip_segments(
    segments: np.ndarray, xmin: float, xmax: float, tol: float, snap: float | None = None
) -> tuple[np.ndarray, np.ndarray]:
    """Clip segments to the vertical strip xmin <= x <= xmax.

    Parameters
    ----------
    segments : numpy.ndarray, shape (K, 2, 2)
        Segments (start, end), points (x, y).
    xmin, xmax : float
        The strip.
    tol : float
        Length tolerance: segments with |dx| <= tol count as vertical, and pieces shorter than
        ``tol`` or within ``tol`` of x = xmin or x = xmax count as not inside.
    snap : float, optional
        End points within ``snap`` (default ``tol``) of x = xmin or x = xmax are first moved
        onto that line, so that a steep segment ending on the line (up to round-off) is not cut
        at an ill-conditioned height, and one lying along it is recognised as lying on it.

    Returns
    -------
    keep : numpy.ndarray of bool, shape (K,)
        True iff the segment has a piece of positive length strictly inside the strip (pieces
        lying on x = xmin or x = xmax are not inside).
    clipped : numpy.ndarray, shape (K, 2, 2)
        The pieces inside the strip, same orientation as the input (meaningful where ``keep``);
        clipped ends lie exactly on x = xmin or x = xmax.
    """
    segments = np.array(segments, dtype=float).reshape(-1, 2, 2)
    xs = segments[:, :, 0]
    snap = tol if snap is None else snap
    xs[np.abs(xs - xmin) <= snap] = xmin
    xs[np.abs(xs - xmax) <= snap] = xmax
    p0 = segments[:, 0]
    d = segments[:, 1] - p0
    dx = d[:, 0]
    vertical = np.abs(dx) <= tol
    safe_dx = np.where(vertical, 1.0, dx)
    t_min = (xmin - p0[:, 0]) / safe_dx
    t_max = (xmax - p0[:, 0]) / safe_dx
    t_in = np.where(vertical, 0.0, np.clip(np.minimum(t_min, t_max), 0.0, 1.0))
    t_out = np.where(vertical, 1.0, np.clip(np.maximum(t_min, t_max), 0.0, 1.0))
    q0 = p0 + t_in[:, None] * d
    q1 = p0 + t_out[:, None] * d
    # put clipped ends exactly on the strip's edges
    entered = t_in > 0.0
    q0[entered, 0] = np.where(dx[entered] > 0.0, xmin, xmax)
    exited = t_out < 1.0
    q1[exited, 0] = np.where(dx[exited] > 0.0, xmax, xmin)
    clipped = np.stack([q0, q1], axis=1)
    xs = clipped[:, :, 0]
    length = np.hypot(*(q1 - q0).T)
    keep = (
        (t_out > t_in)
        & (length > tol)
        & (xs.max(axis=1) > xmin + tol)
        & (xs.min(axis=1) < xmax - tol)
    )
    return keep, clipped


def unique_segments(segments: np.ndarray, kinds: np.ndarray, tol: float) -> np.ndarray:
    """Mask keeping the first of every group of equal lines.

    Two lines are equal when they have the same kind and the same end points, in either
    orientation, where coordinates closer than ``tol`` count as equal (x and y values are
    grouped separately by single linkage: sorted values less than ``tol`` apart share a group).

    Parameters
    ----------
    segments : numpy.ndarray, shape (K, 2, 2)
    kinds : numpy.ndarray, shape (K,)
    tol : float

    Returns
    -------
    numpy.ndarray of bool, shape (K,)
    """
    segments = np.asarray(segments, dtype=float).reshape(-1, 2, 2)
    k = segments.shape[0]
    keep = np.ones(k, dtype=bool)
    if k < 2:
        return keep
    kinds = np.asarray(kinds)
    if kinds.dtype == np.dtype("<U1"):  # one character each: its code point orders as the text
        codes = kinds.reshape(-1).view(np.uint32).astype(np.int64)
    else:
        codes = np.unique(kinds, return_inverse=True)[1].reshape(-1).astype(np.int64)
    ix = _cluster_ids(segments[:, :, 0].ravel(), tol).reshape(k, 2)
    iy = _cluster_ids(segments[:, :, 1].ravel(), tol).reshape(k, 2)
    # canonical orientation: the end with the smaller (x group, y group) first
    swap = (ix[:, 0] > ix[:, 1]) | ((ix[:, 0] == ix[:, 1]) & (iy[:, 0] > iy[:, 1]))
    ix = np.where(swap[:, None], ix[:, ::-1], ix)
    iy = np.where(swap[:, None], iy[:, ::-1], iy)
    keys = (iy[:, 1], ix[:, 1], iy[:, 0], ix[:, 0], codes)  # the last is the first sort key
    repeated = np.zeros(k, dtype=bool)
    radices = [int(key.max()) + 1 for key in keys]
    if math.prod(radices) < 2**63:  # the keys as digits of one int64: one stable sort
        packed = np.zeros(k, dtype=np.int64)
        for key, radix in zip(keys[::-1], radices[::-1], strict=True):
            packed *= radix
            packed += key
        order = np.argsort(packed, kind="stable")  # the first of a group has the smallest index
        ordered = packed[order]
        repeated[1:] = ordered[1:] == ordered[:-1]
    else:
        order = np.lexsort(keys)  # stable: the first of a group has the smallest index
        rows = np.stack(keys, axis=1)[order]
        repeated[1:] = (rows[1:] == rows[:-1]).all(axis=1)
    keep[order[repeated]] = False
    return keep


def _cluster_ids(values: np.ndarray, tol: float) -> np.ndarray:
    """Group ids of ``values``: sorted neighbours less than ``tol`` apart share a group."""
    order = np.argsort(values)  # equal values get one group in any order: no need for stable
    ordered = values[order]
    ids = np.empty(values.shape[0], dtype=np.int64)
    ids[order] = np.concatenate([[0], np.cumsum(np.diff(ordered) > tol)])
    return ids


def check_periodicity(sheet: Sheet) -> list[str]:
    """Check periodicity (docs/theory/patterns.md §5.3): the creases in [W - b/2, W + b/2] are
    those in [-b/2, b/2] shifted by W.

    Both strips are read with :func:`clip_segments` (pieces of positive length strictly inside)
    and pieces equal within the tolerance are counted once (:func:`unique_segments`); segments
    are compared with the sheet's tolerance, in either orientation, labels included.

    Returns
    -------
    list of str
        Every mismatch found (empty when the sheet is periodic).
    """
    from scipy.spatial import cKDTree

    W, half, tol = sheet.width, 0.5 * sheet.sideLength, sheet.tolerance
    is_crease = np.isin(sheet.kinds, ("M", "V"))
    segs, kinds = sheet.segments[is_crease], sheet.kinds[is_crease]
    snap = sheet.snapTolerance
    keep_l, left = clip_segments(segs, -half, half, tol, snap)
    keep_r, right = clip_segments(segs, W - half, W + half, tol, snap)
    left, kinds_l = left[keep_l].copy(), kinds[keep_l]
    right, kinds_r = right[keep_r], kinds[keep_r]
    left[:, :, 0] += W
    # pieces equal within the tolerance count once (as flatten merged them)
    unique_l = unique_segments(left, kinds_l, tol)
    unique_r = unique_segments(right, kinds_r, tol)
    left, kinds_l = left[unique_l], kinds_l[unique_l]
    right, kinds_r = right[unique_r], kinds_r[unique_r]
    problems = []
    if left.shape[0] != right.shape[0]:
        problems.append(
            f"{left.shape[0]} crease pieces in [-b/2, b/2] but {right.shape[0]} in "
            f"[W - b/2, W + b/2]"
        )

    def points(s, kd, reverse=False):
        s = s[:, ::-1] if reverse else s
        code = np.array([SHEET_KINDS.index(x) for x in kd], dtype=float).reshape(-1, 1)
        return np.hstack([s.reshape(-1, 4), 10.0 * tol * code])

    for name, a, ka, other, ko in (
        ("[-b/2, b/2] + W", left, kinds_l, right, kinds_r),
        ("[W - b/2, W + b/2]", right, kinds_r, left, kinds_l),
    ):
        if a.shape[0] == 0:
            continue
        if other.shape[0] == 0:
            problems.append(f"{a.shape[0]} crease pieces of {name} have no counterpart")
            continue
        tree = cKDTree(np.vstack([points(other, ko), points(other, ko, reverse=True)]))
        dist, _ = tree.query(points(a, ka), p=np.inf, distance_upper_bound=2.0 * tol)
        for i in np.flatnonzero(~np.isfinite(dist)).tolist():
            problems.append(
                f"{ka[i]} crease piece {a[i].tolist()} of {name} has no counterpart in the "
                f"other strip"
            )
    return problems
