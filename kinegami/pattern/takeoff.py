"""The folded take-off junction: a side branch leaving a trunk face at a right angle.

See docs/theory/takeoff.md.

A branch tube (the same n-gon prism of circumradius r as the trunk) leaves the trunk's straight
plain-tube section through face (panel) ``face`` along that face's outward normal. The trunk's
sheet gets a hole, the branch's sheet starts with a fish-mouth cut, a skirt and glue tabs; this
module computes all of that exactly, plus the 3D fold maps of both nets used to check it.

Frames and coordinates (docs/theory/patterns.md, section 1):

* trunk pattern (x, y): x around the trunk in [0, W), W = n b, y along the trunk axis e_a; the
  trunk's straight frame (e_u, e_v, e_a) is given as a 4x4 whose origin is the axis point at
  pattern height y = 0;
* face p has centre line x_p = (p + 1) b and outward normal m = cos(phi) e_u + sin(phi) e_v,
  phi = (p + 1) 2 pi / n; s = e_a x m is the direction of increasing x on it;
* O = the axis point at the hole's height y0; the branch's straight frame is (s, e_a, m) at O,
  so the branch pattern (x', y') folds to O + c(x') + y' m, y' measured from O along m;
* local junction coordinates (h, u, t) of a point q: q = O + h m + u s + t e_a.

Everything is in the user's length unit (r sets the scale); angles are radians.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.pattern import catalog
from kinegami.pattern._build import assemble, crease_block
from kinegami.pattern._fold import polygon_point
from kinegami.pattern._prism import Prism, make_prism, wrap_x
from kinegami.pattern.catalog import ModuleCounts
from kinegami.pattern.sheet import clip_segments
from kinegami.pattern.tube import fold_straight
from kinegami.pattern.tubular import ModuleRecord, TubularPattern
from kinegami.validation import LENGTH_FACTOR, check_in_range, check_int, check_translation

__all__ = [
    "GlueTab",
    "TakeoffJunction",
    "TakeoffSkirtPattern",
    "SKIRT_KIND",
    "TAB_WIDTH_FACTOR",
    "MARGIN_FACTOR",
    "VERTEX_TOLERANCE_FACTOR",
    "takeoff_junction",
    "trunk_profile",
    "branch_section",
]

#: Default glue-tab width, as a multiple of r.
TAB_WIDTH_FACTOR = 0.2
#: Smallest trunk margin around the hole, as a multiple of r (the margin is
#: max(tab width, MARGIN_FACTOR r)).
MARGIN_FACTOR = 0.25
#: Polyline vertices closer than this many r (in x') are one vertex.
VERTEX_TOLERANCE_FACTOR = 1e-12


def _readonly(array: np.ndarray) -> np.ndarray:
    array = np.ascontiguousarray(array)
    array.flags.writeable = False
    return array


# --------------------------------------------------------------------------------------------
# The two profiles


def _visible_faces(n: int) -> np.ndarray:
    """The relative trunk faces j with cos(j 2 pi / n) > 0 (those facing +m), ascending."""
    J = -(-n // 4) - 1  # ceil(n / 4) - 1
    return np.arange(-J, J + 1)


def _visible_columns(prism: Prism) -> np.ndarray:
    """u of the trunk columns between visible faces, r sin((j + 1/2) gamma), |angle| < pi/2."""
    n = prism.numSides
    j = np.arange(-n, n)
    j = j[2 * np.abs(2 * j + 1) < n]  # |(j + 1/2) gamma| < pi/2
    return prism.r * np.sin((j + 0.5) * (2.0 * math.pi / n))


def branch_section(prism: Prism, x_branch) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The branch cross-section point at arc length x' (branch pattern coordinate).

    Parameters
    ----------
    prism : Prism
        The common prism (numSides, r).
    x_branch : array_like
        x' values (any real; the branch face is m' = round(x' / b)).

    Returns
    -------
    u, t : ndarray
        Lateral offset along s and axial offset along e_a of the branch surface line, in r's
        unit.
    face : ndarray of int
        The branch face m' (not reduced mod n).
    """
    x = np.asarray(x_branch, dtype=float)
    m = np.round(x / prism.b)
    xi = x - m * prism.b
    sigma = m * (2.0 * math.pi / prism.numSides)
    u = prism.a * np.cos(sigma) - xi * np.sin(sigma)
    t = prism.a * np.sin(sigma) + xi * np.cos(sigma)
    return u, t, m.astype(int)


def trunk_profile(prism: Prism, u) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The trunk seen along the face normal m: where a line parallel to m meets its surface.

    Parameters
    ----------
    prism : Prism
        The common prism (numSides, r).
    u : array_like
        Lateral offsets along s, |u| <= a.

    Returns
    -------
    height : ndarray
        H(u): the coordinate along m (from the axis) at which the line at lateral offset u,
        coming from +m, meets the trunk.
    face : ndarray of int
        j(u): the relative trunk face met (panel p + j); at a column the face of smaller j.
    offset : ndarray
        Xi(u): the arc position of the meeting point around the trunk, measured from face p's
        centre line (so the trunk pattern x is x_p + Xi).
    """
    u = np.asarray(u, dtype=float)
    gamma = 2.0 * math.pi / prism.numSides
    js = _visible_faces(prism.numSides)
    angle = js * gamma
    flat = u.reshape(-1)
    values = (prism.a - flat[:, None] * np.sin(angle)) / np.cos(angle)
    k = np.argmin(values, axis=1)
    height = values[np.arange(flat.shape[0]), k].reshape(u.shape)
    j = js[k].reshape(u.shape)
    offset = j * prism.b + (u - prism.a * np.sin(j * gamma)) / np.cos(j * gamma)
    return height, j, offset


# --------------------------------------------------------------------------------------------
# Data


@dataclass(frozen=True, eq=False)
class GlueTab:
    """One glue tab of the branch skirt, hanging from one fish-mouth segment.

    Attributes
    ----------
    segment : int
        The fish-mouth segment (vertices ``segment`` and ``segment + 1`` mod V) it hangs from.
    polygon : ndarray, shape (k, 2)
        Corners (x', y') in the branch sheet, k = 4 (trapezoid with 45-degree chamfers) or 3
        (triangle, for a segment shorter than twice the tab width); more if clipped to its
        trunk face. The first two corners are the hinge (the segment, in increasing x'). x' is
        continuous across the seam (not reduced mod W). Read-only.
    footprint : ndarray, shape (k, 2)
        Where the corners land once folded, in trunk sheet coordinates (x, y), same order; x
        continuous (x_p + Xi, not reduced mod W). Read-only.
    branchFace : int
        The branch face m' (0 .. n-1) containing the hinge.
    trunkFace : int
        j*: the relative trunk face the tab is glued under (panel (p + j*) mod n).
    panel : int
        The trunk panel (p + j*) mod n.
    foldAngle : float
        omega in [0, pi/2], radians: the valley fold at the hinge (towards the branch's outside).
    flush : bool
        True for a segment lying on a trunk column (n = 0 mod 4): the tab stays flat (omega = 0)
        and slides behind the coplanar trunk face j* = +-n/4; the hinge is no crease.
    clipped : bool
        True if the trapezoid (or triangle) was cut back along a trunk column so that, folded,
        it stays on its trunk face (a chamfer steeper than the column, or a wide tab).
    """

    segment: int
    polygon: np.ndarray
    footprint: np.ndarray
    branchFace: int
    trunkFace: int
    panel: int
    foldAngle: float
    flush: bool
    clipped: bool = False


@dataclass(frozen=True, eq=False)
class TakeoffJunction:
    """The exact geometry of a right-angle take-off junction (docs/theory/takeoff.md).

    Build it with :func:`takeoff_junction`. Arrays are read-only.

    Attributes
    ----------
    numSides, r : int, float
        The prism shared by trunk and branch.
    face : int
        p, the trunk panel the branch leaves through.
    y0 : float
        Trunk pattern height of the hole's centre (the axis point O).
    stub_length : float
        h0, the straight stub between the skirt (which ends at y' = a) and the take-off frame.
    tab_width : float
        Height of the glue tabs.
    fish_mouth : ndarray, shape (V, 2)
        The cut line of the branch sheet, vertices (x', y') with x' in [0, W) ascending; the
        polyline is closed (the last vertex joins the first across the seam). Material is at
        y' >= the line; the full tube starts at y' = a.
    hole : ndarray, shape (V, 2)
        The hole in the trunk sheet, vertices (x, y) with x reduced mod W; vertex i is the
        same 3D point as fish-mouth vertex i.
    hole_unwrapped : ndarray, shape (V, 2)
        The same polygon with x = x_p + Xi continuous (a simple polygon in the plane).
    depth : ndarray, shape (V,)
        a - y' at each fish-mouth vertex (>= 0).
    segment_branch_faces : ndarray of int, shape (V,)
        Branch face m' (0 .. n-1) of segment i (vertices i, i + 1).
    segment_trunk_faces : ndarray of int, shape (V,)
        Relative trunk face j(u) that segment i lies on (for a flush segment: the face on the
        hole's side of the column).
    flush : ndarray of bool, shape (V,)
        Segment i lies on a trunk column (n = 0 mod 4 only).
    tabs : tuple of GlueTab
        One tab per segment, in segment order.
    max_depth : float
        Largest depth of the fish-mouth below y' = a.
    lateral_half_extent : float
        Half-width of the hole across the trunk axis, seen along m (= a).
    axial_half_extent : float
        Half-extent of the hole along the trunk axis: a (n = 0 mod 4) or r (n = 2 mod 4).
    hole_area : float
        Area of the hole in the trunk sheet.
    margin : float
        Trunk margin to keep around the hole: max(tab width, 0.25 r).
    """

    numSides: int
    r: float
    face: int
    y0: float
    stub_length: float
    tab_width: float
    fish_mouth: np.ndarray
    hole: np.ndarray
    hole_unwrapped: np.ndarray
    depth: np.ndarray
    segment_branch_faces: np.ndarray
    segment_trunk_faces: np.ndarray
    flush: np.ndarray
    tabs: tuple[GlueTab, ...]
    max_depth: float
    lateral_half_extent: float
    axial_half_extent: float
    hole_area: float
    margin: float

    # --- derived scalars -----------------------------------------------------------------

    @property
    def prism(self) -> Prism:
        """The shared :class:`~kinegami.pattern._prism.Prism` (b, a, W, columns)."""
        return make_prism(self.numSides, self.r)

    @property
    def numVertices(self) -> int:
        """V, the number of vertices of the fish-mouth (and of the hole)."""
        return int(self.fish_mouth.shape[0])

    @property
    def face_centre(self) -> float:
        """x_p = (p + 1) b mod W, the trunk pattern x of face p's centre line."""
        prism = self.prism
        return float(wrap_x(np.array((self.face + 1) * prism.b), prism.W, 0.0))

    @property
    def normal_angle(self) -> float:
        """phi = (p + 1) 2 pi / n: angle of the face normal m from e_u about e_a, radians."""
        return (self.face + 1) * 2.0 * math.pi / self.numSides

    @property
    def degenerate(self) -> bool:
        """True for n = 4: the hole is all of panel p over |y - y0| <= a and the fish-mouth is
        straight (depth 0); fold it only with a reinforcing collar, or prefer n >= 6."""
        return self.numSides == 4

    @property
    def trunk_span(self) -> tuple[float, float]:
        """The y interval of the trunk's plain tube that must hold the hole and its margin,
        (y0 - e, y0 + e) with e = axial half-extent + margin."""
        e = self.axial_half_extent + self.margin
        return (self.y0 - e, self.y0 + e)

    @property
    def skirt_base(self) -> float:
        """y' of the skirt pattern's y = 0 (the lowest fish-mouth point, a - max depth)."""
        return self.prism.a - self.max_depth

    def segments(self, which: str = "fish_mouth") -> np.ndarray:
        """The closed polyline as segments, shape (V, 2, 2), continuous in x.

        ``which`` is ``"fish_mouth"`` (branch sheet, the closing segment's end shifted by W) or
        ``"hole"`` (trunk sheet, from :attr:`hole_unwrapped`).
        """
        if which == "fish_mouth":
            points = self.fish_mouth
            end = np.roll(points, -1, axis=0).copy()
            end[-1, 0] += self.prism.W
        elif which == "hole":
            points = self.hole_unwrapped
            end = np.roll(points, -1, axis=0)
        else:
            raise InvalidParameterError(f"which must be 'fish_mouth' or 'hole', got {which!r}")
        return np.stack([points, end], axis=1)

    # --- frames ----------------------------------------------------------------------------

    def junction_axes(self, trunk_frame) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
        """(O, m, s, e_a) in world coordinates for the trunk's straight frame ``trunk_frame``.

        ``trunk_frame`` is a 4x4 rigid transform (or an SE3) with axes (e_u, e_v, e_a) and
        origin the trunk axis point at pattern height y = 0.
        """
        F = _frame(trunk_frame)
        phi = self.normal_angle
        e_u, e_v, e_a = F[:3, 0], F[:3, 1], F[:3, 2]
        m = math.cos(phi) * e_u + math.sin(phi) * e_v
        s = math.cos(phi) * e_v - math.sin(phi) * e_u  # e_a x m
        origin = F[:3, 3] + self.y0 * e_a
        return origin, m, s, e_a

    def branch_frame(self, trunk_frame) -> np.ndarray:
        """The branch's straight frame (e_u', e_v', e_a') = (s, e_a, m) at O, as a 4x4.

        The branch pattern point (x', y') folds to ``branch_frame @ (c(x'), y', 1)``.
        """
        origin, m, s, e_a = self.junction_axes(trunk_frame)
        B = np.eye(4)
        B[:3, 0], B[:3, 1], B[:3, 2], B[:3, 3] = s, e_a, m, origin
        return B

    def takeoff_frame(self, trunk_frame) -> np.ndarray:
        """The take-off frame T as a 4x4 Dubins frame: origin O + (a + h0) m, axes (m, s, e_a).

        The branch chain's first link starts here; it is rigidly attached to the trunk link.
        """
        origin, m, s, e_a = self.junction_axes(trunk_frame)
        T = np.eye(4)
        T[:3, 0], T[:3, 1], T[:3, 2] = m, s, e_a
        T[:3, 3] = origin + (self.prism.a + self.stub_length) * m
        return T

    def skirt_frame(self, trunk_frame) -> np.ndarray:
        """The proximal Dubins frame of :meth:`skirt_pattern`, as a 4x4: the take-off frame's
        axes (m, s, e_a) at O + skirt_base m. Folding the skirt (a straight tube) from here ends
        at the take-off frame; it is the ``frame`` to give the folded form of a branch sheet."""
        T = self.takeoff_frame(trunk_frame)
        T[:3, 3] -= (self.max_depth + self.stub_length) * T[:3, 0]
        return T

    # --- fold maps ---------------------------------------------------------------------------

    def fold_trunk(self, xy, trunk_frame) -> np.ndarray:
        """3D points (world) of trunk pattern points (x, y), shape (m, 3): c(x) + y e_a in the
        trunk frame (docs/theory/patterns.md, section 1)."""
        return _fold(self.prism, _frame(trunk_frame), xy)

    def fold_branch(self, xy, trunk_frame) -> np.ndarray:
        """3D points (world) of branch pattern points (x', y'), shape (m, 3): c(x') + y' m in
        the branch frame (:meth:`branch_frame`)."""
        return _fold(self.prism, self.branch_frame(trunk_frame), xy)

    def fold_tab(self, index: int, trunk_frame) -> np.ndarray:
        """3D corners (world) of tab ``index`` folded by its valley angle, shape (k, 3)."""
        tab = self.tabs[check_int("index", index)]
        local = _fold_tab_local(self.prism, tab.polygon, tab.foldAngle)
        origin, m, s, e_a = self.junction_axes(trunk_frame)
        return origin + local[:, :1] * m + local[:, 1:2] * s + local[:, 2:] * e_a

    # --- sheet data ------------------------------------------------------------------------

    def column_gaps(self) -> np.ndarray:
        """The trunk column creases the hole interrupts, shape (g, 3): rows (k, y_low, y_high).

        Column k (x_k = (k + 1/2) b) must have no crease over [y_low, y_high] (inside the hole
        or along its edge). Ascending k.
        """
        prism = self.prism
        poly = self.hole_unwrapped
        rows = []
        for k in range(prism.numSides):
            xk = prism.columns[k]
            # the copy of column k nearest the face centre
            xk = xk + prism.W * round((self.face_centre - xk) / prism.W)
            ys = _vertical_cut(poly, xk, 1e-12 * self.r)
            if ys is not None:
                rows.append((float(k), ys[0], ys[1]))
        return _readonly(np.array(rows, dtype=float).reshape(-1, 3))

    def hole_segments(self) -> np.ndarray:
        """The hole's edges as cut lines of the trunk sheet, shape (K, 2, 2): each edge and its
        copies shifted by +-W, clipped to the sheet strip -b/2 <= x <= W + b/2 (as
        :func:`kinegami.pattern.sheet.flatten` draws creases)."""
        return _sheet_copies(self.segments("hole"), self.prism, self.r)

    def skirt_outline(self) -> np.ndarray:
        """The cut outline of the skirt's lower edge (the tabs' free edges), shape (K, 2, 2),
        in branch sheet coordinates (x', y'), continuous in x' over one turn."""
        pieces = []
        for tab in self.tabs:
            poly = tab.polygon
            loop = np.concatenate([poly[:1], poly[:1:-1], poly[1:2]])  # p0, free edge, p1
            pieces.append(np.stack([loop[:-1], loop[1:]], axis=1))
        return _readonly(np.concatenate(pieces))

    def skirt_outline_segments(self) -> np.ndarray:
        """:meth:`skirt_outline` with copies shifted by +-W, clipped to the branch sheet strip
        -b/2 <= x' <= W + b/2, shape (K, 2, 2)."""
        return _sheet_copies(self.skirt_outline(), self.prism, self.r)

    def skirt_pattern(self) -> TubularPattern:
        """The skirt and stub as a pattern prefix of the branch sheet (:class:`TubularPattern`).

        Same as ``TakeoffSkirtPattern(numSides, r, stub_length)``: its y is y' - skirt_base, it
        has no proximal base, its distal base and marker are at y = max_depth + h0 (the
        take-off frame), so the branch chain's pattern can be appended to it.
        """
        return TakeoffSkirtPattern(self.numSides, self.r, self.stub_length)


# --------------------------------------------------------------------------------------------
# Construction


def takeoff_junction(
    numSides: int,
    r: float,
    face: int,
    y0: float = 0.0,
    *,
    stub_length: float = 0.0,
    tab_width: float | None = None,
) -> TakeoffJunction:
    """The exact geometry of a branch leaving trunk face ``face`` at a right angle.

    Parameters
    ----------
    numSides : int
        n, even and >= 4 (n = 4 is degenerate: straight fish-mouth, the hole takes the whole
        panel; see :attr:`TakeoffJunction.degenerate`).
    r : float
        Circumradius of trunk and branch.
    face : int
        p in [0, n - 1]: the trunk panel the branch leaves through (centre x_p = (p + 1) b).
    y0 : float, optional
        Trunk pattern height of the hole's centre (within +-1e6 r).
    stub_length : float, optional
        h0 >= 0: straight tube between the skirt (y' = a) and the take-off frame.
    tab_width : float, optional
        Glue tab height in (0, r]; default 0.2 r.

    Returns
    -------
    TakeoffJunction

    Examples
    --------
    >>> j = takeoff_junction(6, 1.0, 0)
    >>> j.numVertices, round(j.max_depth, 6), round(j.hole_area, 6)
    (10, 0.633975, 3.484828)
    """
    prism = make_prism(numSides, r)
    n, r = prism.numSides, prism.r
    p = check_int("face", face)
    if not 0 <= p < n:
        raise InvalidParameterError(
            f"face must be an integer in [0, {n - 1}] (a panel of the {n}-gon), got {p}"
        )
    y0 = check_translation("y0", y0, r)
    h0 = check_in_range(
        "stub_length", stub_length, 0.0, LENGTH_FACTOR * r, low_inclusive=True,
        high_inclusive=True, range_text=f"[0, 1e6 r] = [0, {LENGTH_FACTOR * r:g}]",
    )  # fmt: skip
    if tab_width is None:
        w = TAB_WIDTH_FACTOR * r
    else:
        w = check_in_range(
            "tab_width", tab_width, 0.0, r, high_inclusive=True,
            range_text=f"(0, r] = (0, {r:g}]",
        )  # fmt: skip
    base = _base_geometry(prism)
    x_p = float(wrap_x(np.array((p + 1) * prism.b), prism.W, 0.0))
    hole_unwrapped = base["hole_local"] + np.array([x_p, y0])
    hole = hole_unwrapped.copy()
    hole[:, 0] = np.mod(hole[:, 0], prism.W)
    hole[hole[:, 0] >= prism.W, 0] = 0.0
    tabs = tuple(
        _make_tab(prism, base, i, w, p, x_p, y0) for i in range(base["fish_mouth"].shape[0])
    )
    return TakeoffJunction(
        numSides=n,
        r=r,
        face=p,
        y0=y0,
        stub_length=h0,
        tab_width=w,
        fish_mouth=base["fish_mouth"],
        hole=_readonly(hole),
        hole_unwrapped=_readonly(hole_unwrapped),
        depth=base["depth"],
        segment_branch_faces=base["branch_faces"],
        segment_trunk_faces=base["trunk_faces"],
        flush=base["flush"],
        tabs=tabs,
        max_depth=base["max_depth"],
        lateral_half_extent=prism.a,
        axial_half_extent=base["axial"],
        hole_area=base["area"],
        margin=max(w, MARGIN_FACTOR * r),
    )


def _base_geometry(prism: Prism) -> dict:
    """The parts that depend on (n, r) only, computed once per prism."""
    return prism.cached("takeoff", lambda: _compute_base(prism))


def _compute_base(prism: Prism) -> dict:
    n, b, a, W, r = prism.numSides, prism.b, prism.a, prism.W, prism.r
    gamma = 2.0 * math.pi / n
    tol = VERTEX_TOLERANCE_FACTOR * r
    columns_u = _visible_columns(prism)
    # vertices: the branch columns, and where u(x') crosses a trunk column
    xs = list(prism.columns)
    for m in range(n):
        sin_s, cos_s = math.sin(m * gamma), math.cos(m * gamma)
        if abs(sin_s) < 1e-12:  # u is constant on this branch face
            continue
        for c in columns_u:
            xi = (a * cos_s - c) / sin_s
            if abs(xi) < 0.5 * b - tol:
                xs.append(m * b + xi)
    x = np.sort(np.mod(np.array(xs), W))
    keep = np.concatenate([[True], np.diff(x) > tol])
    x = x[keep]
    if x.shape[0] > 1 and x[0] + W - x[-1] <= tol:
        x = x[:-1]
    u, t, _ = branch_section(prism, x)
    # the exact values at the branch columns (no rounding of round(x'/b) at the half-integers)
    f = x / b - 0.5
    on_column = np.abs(f - np.round(f)) < 1e-12
    beta = (np.round(f) + 0.5) * gamma
    u = np.where(on_column, r * np.cos(beta), u)
    t = np.where(on_column, r * np.sin(beta), t)
    height, _, offset = trunk_profile(prism, u)
    fish_mouth = np.stack([x, height], axis=1)
    hole_local = np.stack([offset, t], axis=1)
    # segments
    nxt = np.roll(np.arange(x.shape[0]), -1)
    dx = np.mod(x[nxt] - x, W)
    mid = x + 0.5 * dx
    u_mid, _, branch_face = branch_section(prism, mid)
    _, trunk_face, _ = trunk_profile(prism, u_mid)
    flush = np.zeros(x.shape[0], dtype=bool)
    if n % 4 == 0:
        edge = r * math.sin((n // 4 - 0.5) * gamma)  # = a: the outermost visible column
        flush = (np.abs(np.abs(u) - edge) <= tol) & (np.abs(np.abs(u[nxt]) - edge) <= tol)
        flush &= np.abs(np.abs(u_mid) - edge) <= tol
    area = 0.5 * abs(
        float(np.sum(hole_local[:, 0] * hole_local[nxt, 1] - hole_local[nxt, 0] * hole_local[:, 1]))
    )
    depth = a - height
    return {
        "fish_mouth": _readonly(fish_mouth),
        "hole_local": hole_local,
        "u": u,
        "depth": _readonly(depth),
        "branch_faces": _readonly(np.mod(branch_face, n)),
        "branch_faces_unwrapped": branch_face,
        "trunk_faces": _readonly(trunk_face),
        "flush": _readonly(flush),
        "max_depth": float(a - trunk_profile(prism, np.array([a]))[0][0]),
        "axial": float(a if n % 4 == 0 else r),
        "area": area,
    }


def _make_tab(prism: Prism, base: dict, i: int, w: float, p: int, x_p: float, y0: float):
    n, b, W = prism.numSides, prism.b, prism.W
    gamma = 2.0 * math.pi / n
    fm = base["fish_mouth"]
    V = fm.shape[0]
    p0 = fm[i].copy()
    p1 = fm[(i + 1) % V].copy()
    if i == V - 1:
        p1[0] += W
    m_face = int(base["branch_faces_unwrapped"][i])
    flush = bool(base["flush"][i])
    j = int(base["trunk_faces"][i])
    if flush:
        j = int(np.sign(base["u"][i])) * (n // 4)
    sigma = m_face * gamma
    cos_omega = math.cos(sigma) * math.sin(j * gamma)  # n'.N_j*
    omega = 0.0 if flush else math.acos(min(1.0, max(-1.0, cos_omega)))
    d = p1 - p0
    length = math.hypot(d[0], d[1])
    e = d / length
    nu = np.array([e[1], -e[0]])  # towards the non-material side (below the cut line)
    if length > 2.0 * w:
        polygon = np.array([p0, p1, p1 + w * (nu - e), p0 + w * (nu + e)])
    else:
        polygon = np.array([p0, p1, 0.5 * (p0 + p1) + 0.5 * length * nu])
    # x' continuous from the hinge's face: keep the face's m' for every corner
    folded = _fold_tab_local(prism, polygon, omega)
    footprint = _to_trunk_face(prism, folded, j)
    clipped = _clip_strip(footprint, (j - 0.5) * b, (j + 0.5) * b, 1e-12 * prism.r)
    was_clipped = clipped.shape[0] != footprint.shape[0] or not np.array_equal(clipped, footprint)
    if was_clipped:
        polygon = _map_back(polygon, footprint, clipped)
        footprint = clipped
    footprint = footprint + np.array([x_p, y0])
    return GlueTab(
        segment=i,
        polygon=_readonly(polygon),
        footprint=_readonly(footprint),
        branchFace=int(np.mod(m_face, n)),
        trunkFace=j,
        panel=int(np.mod(p + j, n)),
        foldAngle=omega,
        flush=flush,
        clipped=was_clipped,
    )


# --------------------------------------------------------------------------------------------
# Helpers


def _frame(trunk_frame) -> np.ndarray:
    """``trunk_frame`` as a float 4x4 rigid transform (SE3 objects accepted), or raise."""
    F = getattr(trunk_frame, "A", trunk_frame)
    try:
        F = np.array(F, dtype=float)
    except (TypeError, ValueError):
        raise InvalidTypeError(
            f"trunk_frame must be a 4x4 rigid transform, got {type(trunk_frame).__name__}"
        ) from None
    if F.shape != (4, 4) or not np.all(np.isfinite(F)):
        raise InvalidParameterError(
            f"trunk_frame must be a finite 4x4 rigid transform, got shape {F.shape}"
        )
    R = F[:3, :3]
    if (
        not np.allclose(R.T @ R, np.eye(3), atol=1e-9, rtol=0.0)
        or abs(np.linalg.det(R) - 1.0) > 1e-9
        or not np.allclose(F[3], (0.0, 0.0, 0.0, 1.0), atol=1e-12, rtol=0.0)
    ):
        raise InvalidParameterError(
            "trunk_frame must be a rigid transform (orthonormal rotation with det +1, last row "
            "0 0 0 1)"
        )
    return F


def _fold(prism: Prism, frame: np.ndarray, xy) -> np.ndarray:
    xy = np.asarray(xy, dtype=float).reshape(-1, 2)
    local = polygon_point(prism, xy[:, 0])
    local[:, 2] = xy[:, 1]
    return local @ frame[:3, :3].T + frame[:3, 3]


def _fold_tab_local(prism: Prism, polygon: np.ndarray, omega: float) -> np.ndarray:
    """Tab corners in local junction coordinates (h, u, t), the tab turned about its hinge
    (the first two corners) by the valley angle ``omega`` towards the branch face's outside.

    Every corner is placed in the plane of the hinge's branch face (m' = round of the hinge
    midpoint's x' / b), before the turn."""
    gamma = 2.0 * math.pi / prism.numSides
    m_face = round(0.5 * float(polygon[0, 0] + polygon[1, 0]) / prism.b)
    sigma = m_face * gamma
    xi = polygon[:, 0] - m_face * prism.b
    flat = np.stack(
        [
            polygon[:, 1],
            prism.a * math.cos(sigma) - xi * math.sin(sigma),
            prism.a * math.sin(sigma) + xi * math.cos(sigma),
        ],
        axis=1,
    )
    if omega == 0.0:
        return flat
    outward = np.array([0.0, math.cos(sigma), math.sin(sigma)])
    hinge = flat[1] - flat[0]
    hinge /= np.linalg.norm(hinge)
    # the in-face direction of the tab, perpendicular to the hinge
    rel = flat - flat[0]
    along = rel @ hinge
    across = rel - along[:, None] * hinge
    norms = np.linalg.norm(across, axis=1)
    far = int(np.argmax(norms))
    v0 = across[far] / norms[far]
    width = across @ v0
    turned = math.cos(omega) * v0 + math.sin(omega) * outward
    return flat[0] + along[:, None] * hinge + width[:, None] * turned


def _to_trunk_face(prism: Prism, local: np.ndarray, j: int) -> np.ndarray:
    """Local points (h, u, t) on trunk face j developed into trunk coordinates (Xi, t)."""
    angle = j * 2.0 * math.pi / prism.numSides
    xi = j * prism.b + local[:, 1] * math.cos(angle) - local[:, 0] * math.sin(angle)
    return np.stack([xi, local[:, 2]], axis=1)


def _clip_strip(poly: np.ndarray, lo: float, hi: float, tol: float) -> np.ndarray:
    """Sutherland-Hodgman clip of a polygon to lo <= x <= hi (vertex order kept; corners
    within ``tol`` of the line count as inside, repeated corners are dropped)."""
    out = poly
    for bound, sign in ((lo, 1.0), (hi, -1.0)):
        if out.shape[0] == 0:
            break
        inside = sign * (out[:, 0] - bound) >= -tol
        if inside.all():
            continue
        pts = []
        k = out.shape[0]
        for a_i in range(k):
            A, B = out[a_i], out[(a_i + 1) % k]
            ia, ib = inside[a_i], inside[(a_i + 1) % k]
            if ia:
                pts.append(A)
            if ia != ib:
                s = (bound - A[0]) / (B[0] - A[0])
                pts.append(A + s * (B - A))
        out = np.array(pts).reshape(-1, 2)
    if out.shape[0] > 1:  # drop repeated corners (an end of the hinge on the clip line)
        keep = np.ones(out.shape[0], dtype=bool)
        keep[1:] = np.abs(np.diff(out, axis=0)).max(axis=1) > tol
        out = out[keep]
        if out.shape[0] > 1 and np.abs(out[-1] - out[0]).max() <= tol:
            out = out[:-1]
    return out


def _map_back(polygon: np.ndarray, footprint: np.ndarray, clipped: np.ndarray) -> np.ndarray:
    """``clipped`` (trunk coordinates) mapped back into the branch sheet through the isometry
    that takes ``polygon`` to ``footprint``."""
    A = np.hstack([footprint, np.ones((footprint.shape[0], 1))])
    M, *_ = np.linalg.lstsq(A, polygon, rcond=None)
    return np.hstack([clipped, np.ones((clipped.shape[0], 1))]) @ M


def _vertical_cut(poly: np.ndarray, x: float, tol: float) -> tuple[float, float] | None:
    """The y range where the vertical line at ``x`` meets the closed polygon (None if not)."""
    ys = []
    k = poly.shape[0]
    for i in range(k):
        A, B = poly[i], poly[(i + 1) % k]
        lo, hi = min(A[0], B[0]), max(A[0], B[0])
        if x < lo - tol or x > hi + tol:
            continue
        if hi - lo <= tol:
            ys += [A[1], B[1]]
        else:
            s = (x - A[0]) / (B[0] - A[0])
            ys.append(A[1] + min(1.0, max(0.0, s)) * (B[1] - A[1]))
    if not ys:
        return None
    return float(min(ys)), float(max(ys))


def _sheet_copies(segments: np.ndarray, prism: Prism, r: float) -> np.ndarray:
    """Segments and their copies shifted by +-W (and 2W for x beyond W), clipped to the sheet
    strip [-b/2, W + b/2]."""
    W, b = prism.W, prism.b
    segments = np.asarray(segments, dtype=float)
    # bring every segment's first point into [0, W)
    shift = np.floor(segments[:, 0, 0] / W) * W
    base = segments.copy()
    base[:, :, 0] -= shift[:, None]
    copies = np.concatenate([base + np.array([k * W, 0.0]) for k in (-1.0, 0.0, 1.0)])
    keep, clipped = clip_segments(copies, -0.5 * b, W + 0.5 * b, 1e-9 * r, prism.eps)
    return _readonly(clipped[keep])


# --------------------------------------------------------------------------------------------
# The skirt as a pattern prefix


@catalog.cached_build
def TakeoffSkirtPattern(numSides: int, r: float, stubLength: float = 0.0) -> TubularPattern:
    """The branch sheet's first module: the skirt between the fish-mouth and y' = a, and the
    straight stub of length ``stubLength`` (docs/theory/takeoff.md).

    Its y is y' - (a - max depth), so it starts at y = 0 at the lowest fish-mouth point. Vertices:
    the fish-mouth vertices, then the distal base on the columns at y = max depth + stubLength.
    Creases: the tube edges (mountains, from the fish-mouth up; none of zero length) and the tab
    hinges (valleys; not on flush segments). No proximal base (the lower edge is the cut line of
    :meth:`TakeoffJunction.skirt_outline`). Folded as a straight tube from
    :meth:`TakeoffJunction.skirt_frame`, it ends at the take-off frame.

    Parameters
    ----------
    numSides : int
        Number of sides n (even, >= 4).
    r : float
        Tube circumradius.
    stubLength : float, optional
        h0 >= 0.
    """
    prism = make_prism(numSides, r)
    h0 = check_in_range(
        "stubLength", stubLength, 0.0, LENGTH_FACTOR * prism.r, low_inclusive=True,
        high_inclusive=True, range_text=f"[0, 1e6 r] = [0, {LENGTH_FACTOR * prism.r:g}]",
    )  # fmt: skip
    base = _base_geometry(prism)
    n = prism.numSides
    shift = prism.a - base["max_depth"]
    fm = base["fish_mouth"].copy()
    fm[:, 1] -= shift
    height = base["max_depth"] + h0
    V = fm.shape[0]
    # the fish-mouth vertex on each column
    col_index = np.array(
        [int(np.argmin(np.abs(fm[:, 0] - xk))) for xk in prism.columns], dtype=np.intp
    )
    vertices = [fm]
    distal = np.empty(n, dtype=np.intp)
    count = V
    col_first, col_second = [], []
    for k in range(n):
        v = col_index[k]
        if height - fm[v, 1] < prism.eps:
            distal[k] = v  # a column of zero length: the fish-mouth vertex is the base vertex
            continue
        vertices.append(np.array([[prism.columns[k], height]]))
        distal[k] = count
        col_first.append(v)
        col_second.append(count)
        count += 1
    vertices = np.concatenate(vertices)
    vertices[:V, 1] = np.where(height - fm[:, 1] < prism.eps, height, fm[:, 1])
    hinges = np.flatnonzero(~base["flush"])
    blocks = [
        crease_block(np.array(col_first, dtype=np.intp), np.array(col_second, dtype=np.intp), "M"),
        crease_block(hinges, (hinges + 1) % V, "V"),
    ]
    record = ModuleRecord._of("takeoff_skirt", {"stubLength": h0})
    return assemble(prism, vertices, blocks, None, distal, height, record)


def _skirt_counts(prism: Prism, params) -> ModuleCounts:
    base = _base_geometry(prism)
    height = base["max_depth"] + params["stubLength"]
    fm = base["fish_mouth"]
    shift = prism.a - base["max_depth"]
    columns = sum(
        1
        for xk in prism.columns
        if height - (fm[int(np.argmin(np.abs(fm[:, 0] - xk))), 1] - shift) >= prism.eps
    )
    hinges = int(np.count_nonzero(~base["flush"]))
    return ModuleCounts(fm.shape[0] + columns, columns + hinges, columns)


#: The catalog entry of the skirt (registered on import, so that the folded form and
#: validate() of a branch sheet know the kind). It folds as a straight tube.
SKIRT_KIND = catalog.register(
    catalog.ModuleKind(
        "takeoff_skirt", TakeoffSkirtPattern, ("stubLength",), _skirt_counts, fold_straight
    )
)
