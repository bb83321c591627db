"""Elbow fitting: a bend of the tube by a tucked, flat-folded strip.

See docs/theory/patterns.md 3.3; the fixes B6 and B9 are in its §6.
"""

from __future__ import annotations

import math

import numpy as np

from kinegami._record import Record
from kinegami.errors import InvalidParameterError
from kinegami.pattern import catalog
from kinegami.pattern._build import assemble, crease_block, real
from kinegami.pattern._fold import (
    MERGE_TOLERANCE,
    assign,
    corners,
    match_vertices,
    mod_w,
    require_all,
    rot_axis,
)
from kinegami.pattern._prism import Prism, make_prism, periodic_dx, readonly, wrap_x
from kinegami.pattern.catalog import ModuleCounts
from kinegami.pattern.tubular import ModuleRecord, TubularPattern, first_occurrence_mask

__all__ = ["ELBOW_ANGLE_TOL", "ElbowFittingPattern", "ElbowGeometry", "elbow_geometry"]

#: Angle tolerance (radians) on the bending angle: |theta| must lie in (tol, pi - tol) (fix B9;
#: the reference compared the angle with the length tolerance 1e-4 b).
ELBOW_ANGLE_TOL = 1e-6


class ElbowGeometry(Record):
    """Derived quantities of an elbow (section 3.3); lengths in units of r, angles in radians.

    Attributes
    ----------
    bendingAngle, rotationalAxisAngle : float
        The normalised theta in (0, pi) and phi in [0, 2 pi).
    d_w : float
        r tan(theta / 2).
    h : ndarray, shape (n,)
        Column heights h_k where tube edge k meets the bisecting plane.
    H_m : float
        max_k h_k (the midline height); the pattern height is 2 H_m.
    tuck : ndarray, shape (n,)
        Tuck angles eps_k (flat angle minus 3D angle at column k, halved).
    collapsed : ndarray of bool, shape (n,)
        Columns with h_k >= H_m - eps, or whose tuck offset (H_m - h_k) tan(eps_k) is below eps
        (one vertex Q_k at (x_k, H_m) instead of four; fix B6).
    low : ndarray of bool, shape (n,)
        Columns with h_k < eps whose tuck boundary vertices reuse P_k and D_k (fix B6).
    """

    bendingAngle: float
    rotationalAxisAngle: float
    d_w: float
    h: np.ndarray
    H_m: float
    tuck: np.ndarray
    collapsed: np.ndarray
    low: np.ndarray

    @property
    def height(self) -> float:
        """Pattern height H = 2 H_m."""
        return 2.0 * self.H_m


def normalise_elbow_angles(bendingAngle: float, rotationalAxisAngle: float) -> tuple[float, float]:
    """Reduce (theta, phi) to theta in (0, pi), phi in [0, 2 pi) (section 3.3 steps 1-2).

    Raises
    ------
    InvalidParameterError
        If |theta| (after reduction to [-pi, pi]) is not in (ELBOW_ANGLE_TOL, pi - ELBOW_ANGLE_TOL).
    """
    theta = real("bendingAngle", bendingAngle)
    phi = real("rotationalAxisAngle", rotationalAxisAngle)
    theta_n = theta - 2.0 * math.pi * round(theta / (2.0 * math.pi))
    if not ELBOW_ANGLE_TOL < abs(theta_n) < math.pi - ELBOW_ANGLE_TOL:
        raise InvalidParameterError(
            f"bendingAngle must satisfy {ELBOW_ANGLE_TOL:g} < |theta| < pi - {ELBOW_ANGLE_TOL:g} "
            f"(after reduction modulo 2 pi), got {theta!r}"
        )
    if theta_n < 0:
        theta_n, phi = -theta_n, phi + math.pi
    phi = phi % (2.0 * math.pi)
    if phi >= 2.0 * math.pi:
        phi = 0.0
    return theta_n, phi


def elbow_geometry(prism: Prism, bendingAngle: float, rotationalAxisAngle: float) -> ElbowGeometry:
    """Column heights, tuck angles and collapsed columns of an elbow (section 3.3)."""
    theta, phi = normalise_elbow_angles(bendingAngle, rotationalAxisAngle)
    d_w = prism.r * math.tan(theta / 2.0)
    h, H_m, tuck, collapsed, low = _column_arrays(prism, np.array([phi]), np.array([d_w]))
    return ElbowGeometry(theta, phi, d_w, h[0], float(H_m[0]), tuck[0], collapsed[0], low[0])


def _column_arrays(prism: Prism, phi: np.ndarray, d_w: np.ndarray) -> tuple:
    """(h, H_m, tuck, collapsed, low) of E elbows at once, from their normalised phi and d_w
    (shape (E,)): h, tuck, collapsed and low have shape (E, n), H_m shape (E,).

    Row i is, bit for bit, what elbow i alone gives: every operation is elementwise or a
    maximum, on contiguous arrays, so no result depends on the other rows.
    """
    b, eps = prism.b, prism.eps
    beta, prev, nxt, ring = prism.cached("elbow", lambda: _prism_arrays(prism))
    h = d_w[:, None] * (1.0 + np.sin(beta - phi[:, None]))
    H_m = h.max(axis=1)
    dh_prev = h[:, prev] - h
    dh_next = h[:, nxt] - h
    flat = math.pi - np.arctan(dh_prev / b) - np.arctan(dh_next / b)
    # the angle at corner k of the polygon q_k = (r cos beta_k, r sin beta_k, h_k) between
    # u = q_{k+1} - q_k and w = q_{k-1} - q_k; the dot products are summed in the order
    # (x + z) + y, the order numpy's einsum uses (the results are bit for bit the same)
    uw = (ring.uw0 + dh_next * dh_prev) + ring.uw1
    uu = (ring.uu0 + dh_next * dh_next) + ring.uu1
    ww = (ring.ww0 + dh_prev * dh_prev) + ring.ww1
    cos_b = uw / np.sqrt(uu * ww)
    polygon = np.arccos(np.minimum(np.maximum(cos_b, -1.0), 1.0))
    tuck = 0.5 * (flat - polygon)
    # a column collapses when its tuck vertices L, M, O would lie within eps of each other:
    # h_k >= H_m - eps (section 3.3), or the offset (H_m - h_k) tan(eps_k) of O_k below eps
    # (fix B6)
    below = H_m[:, None] - h
    collapsed = (h >= H_m[:, None] - eps) | (below * np.tan(tuck) < eps)
    low = (h < eps) & ~collapsed
    return h, H_m, tuck, collapsed, low


class _Ring:
    """Products of the ring's x and y differences to the next (u) and previous (w) corner."""

    __slots__ = ("uw0", "uw1", "uu0", "uu1", "ww0", "ww1")


def _prism_arrays(prism: Prism):
    """beta_k, the previous and next column, and the :class:`_Ring` of the prism."""
    n = prism.numSides
    beta = prism.vertex_angles
    prev, nxt = np.arange(-1, n - 1), np.arange(1, n + 1) % n
    qx = prism.r * np.cos(beta)
    qy = prism.r * np.sin(beta)
    u0, u1 = qx[nxt] - qx, qy[nxt] - qy
    w0, w1 = qx[prev] - qx, qy[prev] - qy
    ring = _Ring()
    ring.uw0, ring.uw1 = u0 * w0, u1 * w1
    ring.uu0, ring.uu1 = u0 * u0, u1 * u1
    ring.ww0, ring.ww1 = w0 * w0, w1 * w1
    return beta, prev, nxt, ring


def _many_elbows(calls: list[tuple]) -> list[TubularPattern]:
    """ElbowFittingPattern of every (numSides, r, bendingAngle, rotationalAxisAngle) call, the
    calls on one prism computed together."""
    prisms = [make_prism(numSides, r) for numSides, r, *_ in calls]
    groups: dict[Prism, list[int]] = {}
    for i, prism in enumerate(prisms):
        groups.setdefault(prism, []).append(i)
    built: list = [None] * len(calls)
    for prism, rows in groups.items():
        angles = [calls[i][2:] for i in rows]
        for i, pattern in zip(rows, _elbow_patterns(prism, angles), strict=True):
            built[i] = pattern
    return built


@catalog.cached_build(many=_many_elbows)
def ElbowFittingPattern(
    numSides: int, r: float, bendingAngle: float, rotationalAxisAngle: float
) -> TubularPattern:
    """A bend of the tube by ``bendingAngle`` about an axis at ``rotationalAxisAngle``.

    The bend is a rotation by theta about the axis g = cos(phi) e_u + sin(phi) e_v through
    r w (w = g x e_a, the direction the tube turns to); folded, it equals a circular arc of
    radius r and angle theta. The strip between the two tuck boundaries is tucked inside and
    folded flat in the bisecting plane (section 3.3).

    Parameters
    ----------
    numSides : int
        Number of sides n (even, >= 4).
    r : float
        Tube circumradius (> 0).
    bendingAngle : float
        theta, radians; reduced modulo 2 pi into [-pi, pi], then 1e-6 < |theta| < pi - 1e-6 is
        required. (theta, phi) and (-theta, phi + pi) give the same pattern.
    rotationalAxisAngle : float
        phi, radians, angle of the bending axis from e_u towards e_v (any real value).

    Raises
    ------
    InvalidParameterError
        For a bending angle out of range, or one so small that more than two columns collapse
        at the length tolerance eps = 1e-4 b (the pattern could not be resolved).
    """
    return _elbow_patterns(make_prism(numSides, r), [(bendingAngle, rotationalAxisAngle)])[0]


def _elbow_patterns(prism: Prism, angles: list[tuple]) -> list[TubularPattern]:
    """The elbows of (bendingAngle, rotationalAxisAngle) pairs on one prism, computed together
    (each equal, bit for bit, to the elbow computed alone)."""
    n, r, W, eps = prism.numSides, prism.r, prism.W, prism.eps
    normalised = [normalise_elbow_angles(theta, phi) for theta, phi in angles]
    d_w = np.array([r * math.tan(theta / 2.0) for theta, _ in normalised])
    phi = np.array([phi for _, phi in normalised])
    h, H_m, tuck, collapsed, low = _column_arrays(prism, phi, d_w)
    layouts = _layouts(prism, collapsed, low)
    for (theta, _), layout, c in zip(angles, layouts, collapsed, strict=True):
        if layout is None:
            raise InvalidParameterError(
                f"bendingAngle {theta!r} is too small to resolve for numSides={n}, r={r:g}: "
                f"{int(np.count_nonzero(c))} columns lie within the tolerance {eps:.3g} of the "
                "midline (at most two adjacent ones are allowed)"
            )
    H = 2.0 * H_m
    offset = (H_m[:, None] - h) * np.tan(tuck)
    E = len(angles)
    x_source = np.empty((E, 2 * n))
    x_source[:, :n] = prism.columns
    x_source[:, n:] = wrap_x(prism.columns + offset, W, eps)
    y_source = np.empty((E, 3 + 2 * n))
    y_source[:, 0] = 0.0
    y_source[:, 1] = H
    y_source[:, 2] = H_m
    y_source[:, 3 : 3 + n] = h
    y_source[:, 3 + n :] = H[:, None] - h
    # the vertices of the elbows sharing a layout gathered at once (each elbow's array is a
    # row of the block, read-only); the markers are rows of one array too
    vertices: list = [None] * E
    groups: dict[int, list[int]] = {}
    for i, layout in enumerate(layouts):
        groups.setdefault(id(layout), []).append(i)
    for rows in groups.values():
        layout = layouts[rows[0]]
        block = np.empty((len(rows), layout.total, 2))
        block[:, :, 0] = x_source[rows][:, layout.x_index]
        block[:, :, 1] = y_source[rows][:, layout.y_index]
        block.setflags(write=False)
        for i, row in zip(rows, block, strict=True):
            vertices[i] = row
    proximal_marker = readonly(np.zeros(2))
    distal_markers = np.zeros((E, 2))
    distal_markers[:, 1] = H
    distal_markers.setflags(write=False)
    return [
        TubularPattern._build(
            n, r, xy, layout.edges, layout.labels, layout.P, layout.D, proximal_marker, marker,
            height, (ModuleRecord._of("elbow", {"bendingAngle": float(theta),
                                                "rotationalAxisAngle": float(phi)}),),
            0, None, False, None, True,
        )
        for (theta, phi), layout, xy, marker, height in zip(
            angles, layouts, vertices, distal_markers, H.tolist(), strict=True
        )
    ]  # fmt: skip


class _Layout:
    """The elbow's vertex numbering and creases for one set of collapsed and low columns.

    They depend on n and on which columns are collapsed or low only, so they are computed once
    per prism and column set (:func:`_layouts`, through :meth:`Prism.cached_many`) and shared,
    read-only, by every elbow with that set; an elbow then only computes its vertex
    coordinates: x = x_source[x_index] and y = y_source[y_index], with x_source = (x_k, O_k's
    wrapped x) and y_source = (0, H, H_m, h_k, H - h_k).
    """

    __slots__ = ("P", "D", "total", "edges", "labels", "x_index", "y_index")


def _layouts(prism: Prism, collapsed: np.ndarray, low: np.ndarray) -> list[_Layout | None]:
    """The shared layout of each row of ``collapsed`` and ``low`` (shape (E, n)), or None for
    a row that cannot be resolved (more than two collapsed columns, or two that are not
    adjacent). Layouts not yet in the prism's cache are computed together."""
    n = prism.numSides
    # a row's key: its columns as bytes, 1 for collapsed, 2 for low (one tobytes for all)
    codes = (collapsed.view(np.uint8) | (low.view(np.uint8) << 1)).tobytes()
    keys = [("elbow layout", codes[i : i + n]) for i in range(0, len(codes), n)]
    row_of = {key: i for i, key in reversed(list(enumerate(keys)))}

    def make_many(missing: list) -> list:
        rows = [row_of[key] for key in missing]
        c, z = collapsed[rows], low[rows]
        count = np.count_nonzero(c, axis=1)
        previous = c[:, np.arange(-1, n - 1)]  # column k - 1 of every row
        adjacent = (count == 1) | ((count == 2) & np.any(c & previous, axis=1))
        layouts: list = [None] * len(rows)
        good = np.flatnonzero(adjacent)
        if good.shape[0]:
            for j, layout in zip(good.tolist(), _new_layouts(prism, c[good], z[good]),
                                 strict=True):  # fmt: skip
                layouts[j] = layout
        return layouts

    return prism.cached_many(keys, make_many)


def _new_layouts(prism: Prism, collapsed: np.ndarray, low: np.ndarray) -> list[_Layout]:
    """The layouts of the rows of ``collapsed`` and ``low`` (shape (U, n), every row
    resolvable), computed in whole-array passes over the rows."""
    n = prism.numSides
    U = collapsed.shape[0]
    k = np.arange(n)
    P, D = k, n + k
    full = ~collapsed
    # vertices: P, D, then per column Q (collapsed) or L, M, O (array Of), U (no L, U when
    # low)
    has_l = full & ~low
    counts = np.where(collapsed, 1, 2 + 2 * has_l.astype(int))
    ends = np.cumsum(counts, axis=1)
    start = 2 * n + ends - counts
    L = np.where(has_l, start, np.where(low, P, start))
    M = np.where(has_l, start + 1, start)
    Of = np.where(has_l, start + 2, np.where(low, start + 1, start))
    Up = np.where(has_l, start + 3, np.where(low, D, start))
    totals = (2 * n + ends[:, -1]).tolist()
    # x_index and y_index of every row, padded to the longest
    width = max(totals)
    x_index = np.empty((U, width), dtype=np.intp)
    y_index = np.empty((U, width), dtype=np.intp)
    x_index[:, P], y_index[:, P] = k, 0
    x_index[:, D], y_index[:, D] = k, 1
    kk = k + np.zeros((U, 1), dtype=np.intp)  # column k of every row
    at = np.arange(U)[:, None] * width  # where each row starts in the flattened index arrays
    x_flat, y_flat = x_index.reshape(-1), y_index.reshape(-1)
    x_flat[at + M], y_flat[at + M] = kk, 2
    x_flat[(at + Of)[full]], y_flat[(at + Of)[full]] = n + kk[full], 2
    x_flat[(at + L)[has_l]], y_flat[(at + L)[has_l]] = kk[has_l], 3 + kk[has_l]
    x_flat[(at + Up)[has_l]], y_flat[(at + Up)[has_l]] = kk[has_l], 3 + n + kk[has_l]
    # the creases of every row, and the first of each distinct one (as distinct_creases)
    table = _crease_table(kk, n + kk, L, M, Of, Up)
    edges = np.empty((U, n * len(table), 2), dtype=np.intp)
    edges[:, :, 0] = np.concatenate([first for first, _, _ in table], axis=1)
    edges[:, :, 1] = np.concatenate([second for _, second, _ in table], axis=1)
    labels = np.repeat(np.array([label for _, _, label in table], dtype="<U1"), n)
    lo = np.minimum(edges[:, :, 0], edges[:, :, 1]).astype(np.int64)
    hi = np.maximum(edges[:, :, 0], edges[:, :, 1])
    key = (np.arange(U)[:, None] * width + lo) * width + hi
    first = first_occurrence_mask(key.reshape(-1)).reshape(U, -1)
    keep = first & (edges[:, :, 0] != edges[:, :, 1])
    P, D = readonly(P), readonly(D.copy())
    layouts = []
    for u, total in enumerate(totals):
        layout = _Layout()
        layout.P, layout.D, layout.total = P, D, total
        layout.edges = readonly(edges[u][keep[u]])
        layout.labels = readonly(labels[keep[u]])
        layout.x_index = readonly(x_index[u, :total].copy())
        layout.y_index = readonly(y_index[u, :total].copy())
        layouts.append(layout)
    return layouts


def _build_elbow_reference(prism: Prism, geo: ElbowGeometry, record: ModuleRecord):
    """The elbow built column by column (the layout's definition; kept for the tests)."""
    n = prism.numSides
    x = prism.columns
    h, H_m = geo.h, geo.H_m
    H = 2.0 * H_m
    k = np.arange(n)
    P, D = k, n + k
    full = ~geo.collapsed
    low = geo.low
    # vertices: P, D, then per column Q (collapsed) or L, M, O (array Of), U (no L, U when low)
    has_l = full & ~low
    counts = np.where(geo.collapsed, 1, 2 + 2 * has_l.astype(int))
    start = 2 * n + np.concatenate([[0], np.cumsum(counts)[:-1]])
    M = start.copy()
    L = np.where(has_l, start, np.where(low, P, start))
    M = np.where(has_l, start + 1, np.where(low, start, start))
    Of = np.where(has_l, start + 2, np.where(low, start + 1, start))
    U = np.where(has_l, start + 3, np.where(low, D, start))
    total = 2 * n + int(counts.sum())
    vertices = np.empty((total, 2))
    vertices[P, 0], vertices[P, 1] = x, 0.0
    vertices[D, 0], vertices[D, 1] = x, H
    offset = (H_m - h) * np.tan(geo.tuck)
    vertices[M, 0], vertices[M, 1] = x, H_m
    vertices[Of[full], 0] = wrap_x(x[full] + offset[full], prism.W, prism.eps)
    vertices[Of[full], 1] = H_m
    vertices[L[has_l], 0], vertices[L[has_l], 1] = x[has_l], h[has_l]
    vertices[U[has_l], 0], vertices[U[has_l], 1] = x[has_l], H - h[has_l]
    blocks = [crease_block(a, c, label) for a, c, label in _crease_table(P, D, L, M, Of, U)]
    return assemble(prism, vertices, blocks, P, D, H, record)


def _crease_table(P, D, L, M, Of, U) -> list:
    """The elbow's creases as (first ends, second ends, label), one entry per column.

    The arrays give, per column k, the indices of P_k, D_k and of the tuck vertices L_k, M_k,
    O_k, U_k (the catalog reuses indices where fix B6 merges points; the unsnapped elbow does
    not). The order matters: where two collapsed columns are adjacent the lower boundary, upper
    boundary and midline coincide, and the first (lower boundary, M) is kept. The arrays may
    have leading dimensions (several layouts at once): columns are the last axis.
    """
    n = P.shape[-1]
    k = np.arange(n)
    prev, nxt = (k - 1) % n, (k + 1) % n
    return [
        (L[..., prev], L, "M"),  # lower tuck boundary
        (P, L, "M"),  # proximal tube edge
        (U[..., prev], U, "M"),  # upper tuck boundary
        (U, D, "M"),  # distal tube edge
        (M, Of, "V"),  # midline
        (Of, M[..., nxt], "V"),  # midline
        (L, M, "V"),  # lower half of the column line
        (M, U, "M"),  # upper half of the column line
        (L, Of, "M"),  # lower tuck diagonal
        (U, Of, "V"),  # upper tuck diagonal
    ]


# --------------------------------------------------------------------------------------------
# Catalog entry: counts, unsnapped geometry and fold


def _counts(prism: Prism, params) -> ModuleCounts:
    """6n - 3c - 2z vertices and 10n - 5c - 2[c = 2] - 2z creases, c collapsed columns and z
    low ones (fix B6)."""
    n = prism.numSides
    geo = elbow_geometry(prism, params["bendingAngle"], params["rotationalAxisAngle"])
    c = int(np.count_nonzero(geo.collapsed))
    z = int(np.count_nonzero(geo.low))
    return ModuleCounts(6 * n - 3 * c - 2 * z, 10 * n - 5 * c - 2 * (c == 2) - 2 * z)


def _unsnapped(prism: Prism, pattern: TubularPattern, params):
    """The elbow with four tuck vertices on every column, and the catalog vertices in it."""
    exact = _exact_elbow(
        prism, params["bendingAngle"], params["rotationalAxisAngle"], pattern.modules
    )
    return exact, match_vertices(pattern.vertices_coords, exact.vertices_coords, prism)


def _exact_elbow(prism: Prism, theta: float, phi: float, records) -> TubularPattern:
    """The elbow with four tuck vertices L, M, O, U on every column (no eps rules).

    Vertices closer than ``MERGE_TOLERANCE`` r are merged (exactly collapsed columns, h_k = 0),
    the creases between merged vertices dropped and repeated creases kept once, the first in
    the catalog's order (so two adjacent collapsed columns share one M crease, as in step 5).
    """
    geo = elbow_geometry(prism, theta, phi)
    n, W = prism.numSides, prism.W
    x = prism.columns
    h, H_m = geo.h, geo.H_m
    H = 2.0 * H_m
    k = np.arange(n)
    P, D = k, n + k
    L, M, Of, U = 2 * n + 4 * k, 2 * n + 4 * k + 1, 2 * n + 4 * k + 2, 2 * n + 4 * k + 3
    xy = np.empty((6 * n, 2))
    xy[P] = np.stack([x, np.zeros(n)], axis=1)
    xy[D] = np.stack([x, np.full(n, H)], axis=1)
    xy[L] = np.stack([x, h], axis=1)
    xy[M] = np.stack([x, np.full(n, H_m)], axis=1)
    xy[Of] = np.stack([mod_w(x + (H_m - h) * np.tan(geo.tuck), W), np.full(n, H_m)], axis=1)
    xy[U] = np.stack([x, H - h], axis=1)
    table = _crease_table(P, D, L, M, Of, U)
    edges = np.concatenate([np.stack([a, c], axis=1) for a, c, _ in table])
    labels = np.concatenate([np.full(n, lab, dtype="<U1") for _, _, lab in table])
    # merge coincident vertices into the lowest index (P and D come first)
    dx = periodic_dx(xy[:, None, 0] - xy[None, :, 0], W)
    close = np.hypot(dx, xy[:, None, 1] - xy[None, :, 1]) < MERGE_TOLERANCE * prism.r
    rep = np.argmax(close, axis=1)
    while not np.array_equal(rep[rep], rep):
        rep = rep[rep]
    keep = np.flatnonzero(rep == np.arange(6 * n))
    index = np.full(6 * n, -1)
    index[keep] = np.arange(keep.size)
    edges = index[rep[edges]]
    lo, hi = edges.min(axis=1), edges.max(axis=1)
    first = np.zeros(edges.shape[0], dtype=bool)
    first[np.unique(lo * keep.size + hi, return_index=True)[1]] = True
    first &= lo != hi
    return TubularPattern._build(
        n, prism.r, xy[keep], np.ascontiguousarray(edges[first]), labels[first], index[P],
        index[D], np.zeros(2), np.array([0.0, H]), H, tuple(records),
    )  # fmt: skip


def _fold(prism: Prism, pattern: TubularPattern, params):
    """The elbow at state 0: every vertex at the 3D position of the named point it is.

    P on the base ring, D on the ring turned by theta about g, L and U on the bisecting plane,
    and the tucked points O_k, M_{k+1} in the bisecting plane, each flat triangle of the tuck
    laid rigidly into that plane from its edge L_k-L_{k+1} (docs/fold.md).
    """
    theta, phi = params["bendingAngle"], params["rotationalAxisAngle"]
    geo = elbow_geometry(prism, theta, phi)
    n, r, b = prism.numSides, prism.r, prism.b
    theta, phi = geo.bendingAngle, geo.rotationalAxisAngle
    h, H_m = geo.h, geo.H_m
    H = 2.0 * H_m
    x = prism.columns
    g = np.array([math.cos(phi), math.sin(phi), 0.0])
    w = np.cross(g, (0.0, 0.0, 1.0))
    R = rot_axis(g, theta)
    shift = r * w - R @ (r * w)
    n_pi = rot_axis(g, theta / 2.0) @ np.array([0.0, 0.0, 1.0])
    p = corners(prism)
    q = p.copy()
    q[:, 2] = h
    offset = (H_m - h) * np.tan(geo.tuck)
    names_xy = []
    names_X = []

    def add(points_xy, points_X):
        names_xy.append(np.atleast_2d(points_xy))
        names_X.append(np.atleast_2d(points_X))

    add(np.stack([x, np.zeros(n)], axis=1), p)  # P
    add(np.stack([x, np.full(n, H)], axis=1), p @ R.T + shift)  # D = E(p)
    add(np.stack([x, h], axis=1), q)  # L
    add(np.stack([x, H - h], axis=1), q)  # U
    for k in range(n):
        k1 = (k + 1) % n
        e1 = np.array([b, h[k1] - h[k]])
        e1 /= np.linalg.norm(e1)
        e2 = np.array([-e1[1], e1[0]])
        f1 = q[k1] - q[k]
        f1 /= np.linalg.norm(f1)
        f2 = np.cross(n_pi, f1)
        L_k = np.array([x[k], h[k]])
        O_k = np.array([x[k] + offset[k], H_m])
        M_1 = np.array([x[k] + b, H_m])
        for point in (O_k, M_1):
            rel = point - L_k
            image = q[k] + (rel @ e1) * f1 + (rel @ e2) * f2
            wrapped = point.copy()
            wrapped[0] = wrap_x(point[0:1], prism.W, 0.0)[0]
            add(wrapped, image)
    named_xy = np.concatenate(names_xy)
    named_X = np.concatenate(names_X)
    # the unsnapped elbow's vertices are named points (merged ones within MERGE_TOLERANCE r)
    X, matched = assign(pattern.vertices_coords, named_xy, named_X, prism.W, MERGE_TOLERANCE * r)
    require_all(matched, "elbow")
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = shift
    return X, T


catalog.register(
    catalog.ModuleKind(
        "elbow",
        ElbowFittingPattern,
        ("bendingAngle", "rotationalAxisAngle"),
        _counts,
        _fold,
        _unsnapped,
    )
)
