"""Twist fitting: a band of triangles that rotates the tube about its axis.

See docs/theory/patterns.md 3.2.
"""

from __future__ import annotations

import math

import numpy as np

from kinegami._record import Record
from kinegami.pattern import catalog
from kinegami.pattern._build import assemble, crease_block, nonnegative, real
from kinegami.pattern._fold import corners, mod_w, moved_copy, polygon_point, rot_axis
from kinegami.pattern._prism import Prism, make_prism, wrap_scalar, wrap_x
from kinegami.pattern.catalog import ModuleCounts
from kinegami.pattern.tubular import ModuleRecord, TubularPattern

__all__ = ["TwistFittingPattern", "TwistGeometry", "twist_geometry"]


class TwistGeometry(Record):
    """Derived quantities of a twist (section 3.2); lengths in units of r, angles in radians.

    Attributes
    ----------
    K : int
        Whole columns of the rotation (relabelling only), in 0 .. n-1.
    residual : float
        The folded part of the rotation, alpha_bar in [0, 2 pi / n).
    shift : float
        Side shift s of the distal base in x, in [0, b).
    excess : float
        Radial excess e of a rotated vertex beyond the original side.
    height : float
        Pattern height H = sqrt(h^2 + e^2).
    degenerate : bool
        True when H < eps: the module is only a relabelling by round(n alpha' / 2 pi) columns.
    """

    K: int
    residual: float
    shift: float
    excess: float
    height: float
    degenerate: bool


def twist_geometry(prism: Prism, twistAngle: float, moduleHeight: float) -> TwistGeometry:
    """Decompose ``twistAngle`` into whole columns and the folded residual (section 3.2)."""
    n, r = prism.numSides, prism.r
    step = 2.0 * math.pi / n
    alpha = twistAngle % (2.0 * math.pi)
    if alpha >= 2.0 * math.pi:  # float rounding of tiny negative angles
        alpha = 0.0
    K = min(int(math.floor(alpha / step)), n - 1)
    residual = max(alpha - K * step, 0.0)
    shift = r * (math.sin(math.pi / n) + math.sin(residual - math.pi / n))
    excess = r * (math.cos(math.pi / n - residual) - math.cos(math.pi / n))
    height = math.hypot(moduleHeight, excess)
    return TwistGeometry(K, residual, shift, excess, height, height < prism.eps)


def _many_twists(calls: list[tuple]) -> list[TubularPattern]:
    """TwistFittingPattern of every (numSides, r, twistAngle, moduleHeight) call (a single
    twist is a batch of one). The twists of one prism share one block of vertices (each
    twist's array a read-only row) and one of distal markers, their distal columns wrapped
    together (bit for bit as alone: elementwise)."""
    checked = [
        (make_prism(numSides, r), real("twistAngle", alpha), nonnegative("moduleHeight", h))
        for numSides, r, alpha, h in calls
    ]
    geos = [twist_geometry(prism, alpha, h) for prism, alpha, h in checked]
    built: list = [None] * len(calls)
    groups: dict[Prism, list[int]] = {}
    for i, ((prism, alpha, h), geo) in enumerate(zip(checked, geos, strict=True)):
        if geo.degenerate:
            built[i] = _relabelling(prism, alpha, h)
        else:
            groups.setdefault(prism, []).append(i)
    for prism, rows in groups.items():
        n, b = prism.numSides, prism.b
        band = prism.cached("twist", lambda prism=prism: _band(prism))
        shifts = np.array([geos[i].shift for i in rows])
        heights = np.array([geos[i].height for i in rows])
        block = np.empty((len(rows), 2 * n, 2))
        block[:] = band.vertices_coords
        block[:, n:, 0] = wrap_x(prism.columns + shifts[:, None], prism.W, prism.eps)
        block[:, n:, 1] = heights[:, None]
        block.setflags(write=False)
        markers = np.empty((len(rows), 2))
        markers[:, 0] = [wrap_scalar(geos[i].K * b + geos[i].shift, prism.W, prism.eps)
                         for i in rows]  # fmt: skip
        markers[:, 1] = heights
        markers.setflags(write=False)
        origin = np.zeros(2)
        origin.setflags(write=False)
        for i, vertices, marker in zip(rows, block, markers, strict=True):
            _, alpha, h = checked[i]
            built[i] = TubularPattern._build(
                n, prism.r, vertices, band.edges_vertices, band.edges_assignment,
                band.proximalBase, band.distalBase, origin, marker, float(geos[i].height),
                (ModuleRecord._of("twist", {"twistAngle": alpha, "moduleHeight": h}),), 0, None,
                False, None, True,
            )  # fmt: skip
    return built


def _relabelling(prism: Prism, alpha: float, h: float) -> TubularPattern:
    """A degenerate twist (pattern height below eps): no creases, the distal marker moved by
    the nearest whole number of columns."""
    record = ModuleRecord._of("twist", {"twistAngle": alpha, "moduleHeight": h})
    n, b = prism.numSides, prism.b
    k = np.arange(n)
    columns = round(n * ((alpha % (2.0 * math.pi)) / (2.0 * math.pi))) % n
    vertices = np.stack([prism.columns, np.zeros(n)], axis=1)
    return assemble(
        prism, vertices, [(np.zeros((0, 2), int), "M")], k, k, 0.0, record,
        distal_marker_x=float(wrap_x(np.array([columns * b]), prism.W, prism.eps)[0]),
    )  # fmt: skip


@catalog.cached_build(many=_many_twists)
def TwistFittingPattern(
    numSides: int, r: float, twistAngle: float, moduleHeight: float
) -> TubularPattern:
    """A twist by ``twistAngle`` about the tube axis over axial length ``moduleHeight``.

    The rotation is split into K whole columns (a relabelling, no folds) and a residual
    alpha_bar in [0, 2 pi/n) that is folded as a band of 2n triangles: right diagonals
    P_k-D_k and left diagonals D_{k-1}-P_k (mountain), both rings valley. The distal base is
    shifted by s in x and the distal marker by K b + s (section 3.2).

    Parameters
    ----------
    numSides : int
        Number of sides n (even, >= 4).
    r : float
        Tube circumradius (> 0).
    twistAngle : float
        Rotation alpha about the forward tube axis, radians, any real value (alpha and
        alpha + 2 pi give the same pattern). Positive alpha turns e_u towards e_v.
    moduleHeight : float
        Axial length h of the twist in 3D, >= 0. h = 0 is allowed but folds a band lying in one
        cross-section plane (note B13). If the pattern height sqrt(h^2 + e^2) is below
        eps = 1e-4 b the twist is only a relabelling: the result has no creases, height 0 and a
        distal marker shifted by the nearest whole number of columns.
    """
    return _many_twists([(numSides, r, twistAngle, moduleHeight)])[0]


def _band(prism: Prism) -> TubularPattern:
    """The twist's creases and bases (shared by every twist of the prism), at height 0."""
    n = prism.numSides
    k = np.arange(n)
    x = prism.columns
    vertices = np.concatenate([np.stack([x, np.zeros(n)], axis=1)] * 2)
    P, D = k, n + k
    prev = (k - 1) % n
    blocks = [
        crease_block(P, D, "M"),  # right diagonals
        crease_block(D[prev], P, "M"),  # left diagonals
        crease_block(P[prev], P, "V"),  # proximal ring
        crease_block(D[prev], D, "V"),  # distal ring
    ]
    return assemble(prism, vertices, blocks, P, D, 0.0, ModuleRecord("twist"))


# --------------------------------------------------------------------------------------------
# Catalog entry: counts, unsnapped geometry and fold


def _counts(prism: Prism, params) -> ModuleCounts:
    n = prism.numSides
    if twist_geometry(prism, params["twistAngle"], params["moduleHeight"]).degenerate:
        return ModuleCounts(n, 0, 0)
    return ModuleCounts(2 * n, 4 * n, 2 * n)


def _unsnapped(prism: Prism, pattern: TubularPattern, params):
    """The twist with its distal base and marker not snapped onto the seam."""
    identity = np.arange(pattern.numVertices)
    geo = twist_geometry(prism, params["twistAngle"], params["moduleHeight"])
    if geo.degenerate:
        return pattern, identity
    xy = pattern.vertices_coords.copy()
    distal_marker = pattern.distalMarker.copy()
    xy[pattern.distalBase, 0] = mod_w(prism.columns + geo.shift, prism.W)
    distal_marker[0] = mod_w(np.array([geo.K * prism.b + geo.shift]), prism.W)[0]
    return moved_copy(pattern, xy, distal_marker), identity


def _fold(prism: Prism, pattern: TubularPattern, params):
    """The band of triangles at state 0: the distal ring is the base turned by the residual."""
    alpha, h = params["twistAngle"], params["moduleHeight"]
    geo = twist_geometry(prism, alpha, h)
    n = prism.numSides
    p = corners(prism)
    xy = pattern.vertices_coords
    R = np.eye(4)
    if geo.degenerate:
        columns = round(n * ((alpha % (2.0 * math.pi)) / (2.0 * math.pi))) % n
        R[:3, :3] = rot_axis((0.0, 0.0, 1.0), columns * 2.0 * math.pi / n)
        X = polygon_point(prism, xy[:, 0])
        return X, R
    X = np.empty((pattern.numVertices, 3))
    X[pattern.proximalBase] = p
    X[pattern.distalBase] = corners(prism, geo.residual) + np.array([0.0, 0.0, h])
    R[:3, :3] = rot_axis((0.0, 0.0, 1.0), alpha)
    R[2, 3] = h
    return X, R


catalog.register(
    catalog.ModuleKind(
        "twist", TwistFittingPattern, ("twistAngle", "moduleHeight"), _counts, _fold, _unsnapped
    )
)
