"""Revolute joint with sink layers, and the tips made from its half.

See docs/theory/patterns.md 3.4-3.6.
"""

from __future__ import annotations

import math

import numpy as np

from kinegami._record import Record
from kinegami.errors import InvalidParameterError
from kinegami.pattern import catalog
from kinegami.pattern._build import assemble, crease_block
from kinegami.pattern._fold import FoldedFormError, assign, corners, translation
from kinegami.pattern._prism import Prism, make_prism, periodic_dx
from kinegami.pattern.catalog import ModuleCounts
from kinegami.pattern.tubular import ModuleRecord, TubularPattern
from kinegami.validation import check_in_range, check_num_sink_layers, check_positive

__all__ = [
    "EndTipPattern",
    "RevoluteGeometry",
    "RevoluteJointPattern",
    "StartTipPattern",
    "revolute_geometry",
]


class RevoluteGeometry(Record):
    """Derived quantities of a revolute joint or tip (sections 3.4, 3.6); lengths in units of r.

    Attributes
    ----------
    h_r : float
        Half the neutral length (joint centre above the proximal base); the tip length.
    H : float
        Half the revolute pattern height (the whole tip height), sqrt(a^2 + h_r^2).
    psi : float
        arctan(b / (2 H)), angle between a panel's X diagonal and the vertical, radians.
    crimped : ndarray of bool, shape (n,)
        Columns that carry a crimp (all but 0, n/2 - 1, n/2, n - 1).
    t : ndarray, shape (n,)
        Crimp height t_k of every column (equal to H on the flap-adjacent columns).
    """

    h_r: float
    H: float
    psi: float
    crimped: np.ndarray
    t: np.ndarray

    @property
    def flap_panels(self) -> tuple[int, int]:
        """The two flap (non-sink) panels mp = n/2 - 1 and ep = n - 1."""
        n = self.crimped.shape[0]
        return n // 2 - 1, n - 1


def revolute_geometry(prism: Prism, h_r: float) -> RevoluteGeometry:
    """Crimp heights for joint centre height ``h_r`` (section 3.4, with psi of fix B1)."""
    n, r, a, b = prism.numSides, prism.r, prism.a, prism.b
    H = math.hypot(a, h_r)
    psi = math.atan(b / (2.0 * H))
    beta = prism.vertex_angles
    lam = np.sqrt(h_r**2 + (r * np.cos(beta)) ** 2)
    gamma = np.arctan2(lam, r * np.abs(np.sin(beta)))
    t = lam / np.sin(gamma + psi)
    crimped = np.ones(n, dtype=bool)
    crimped[[0, n // 2 - 1, n // 2, n - 1]] = False
    return RevoluteGeometry(h_r, H, psi, crimped, t)


def _check_resolvable(prism: Prism, geo: RevoluteGeometry, name: str, value: float) -> None:
    """Reject parameters so extreme that a crimp vertex lands within eps of P_k or M_k."""
    t = geo.t[geo.crimped]
    if t.size and not (t.min() > prism.eps and (geo.H - t).min() > prism.eps):
        raise InvalidParameterError(
            f"{name}={value!r} is too close to the end of its range for numSides="
            f"{prism.numSides}, r={prism.r:g}: a crimp vertex would lie within the tolerance "
            f"eps = {prism.eps:.3g} of a base or midline vertex (crimp heights in "
            f"[{t.min():.3g}, {t.max():.3g}], half height {geo.H:.6g})"
        )


@catalog.cached_build
def RevoluteJointPattern(
    numSides: int, r: float, totalBendingAngle: float, numSinkLayers: int = 1
) -> TubularPattern:
    """A revolute joint of total range ``totalBendingAngle`` with ``numSinkLayers`` sinks.

    Two flaps (panels n/2 - 1 and n - 1, centred on -e_u and +e_u) fold about the rotation axis
    along e_v at height h_r = a tan(theta_m / 4); the other n - 2 panels are sunk (one layer:
    section 3.4; N >= 2 nested layers: section 3.5, with fixes B2 and B3). At state 0 the
    distal frame is the proximal frame translated by 2 h_r along the tube axis.

    Parameters
    ----------
    numSides : int
        Number of sides n (even, >= 4).
    r : float
        Tube circumradius (> 0).
    totalBendingAngle : float
        theta_m in (0, 2 pi), radians; the joint's state range is [-theta_m/2, theta_m/2].
    numSinkLayers : int, optional
        Number N >= 1 of nested sink layers (default 1).

    Raises
    ------
    InvalidParameterError
        For out-of-range parameters; for an angle so close to 0 or 2 pi that a crimp vertex
        would coincide (within eps = 1e-4 b) with a base or midline vertex; for N >= 2 when the
        crimps are too low for the nested sink chains to stay inside their panels.
    """
    prism = make_prism(numSides, r)
    theta = check_in_range(
        "totalBendingAngle", totalBendingAngle, 0.0, 2.0 * math.pi, range_text="(0, 2 pi)"
    )
    layers = check_num_sink_layers(numSinkLayers)
    h_r = prism.a * math.tan(theta / 4.0)
    geo = revolute_geometry(prism, h_r)
    _check_resolvable(prism, geo, "totalBendingAngle", theta)
    record = ModuleRecord("revolute", {"totalBendingAngle": theta, "numSinkLayers": layers})
    return _build_revolute(prism, geo, layers, record)


@catalog.cached_build
def EndTipPattern(numSides: int, r: float, length: float) -> TubularPattern:
    """The end tip: closes the tube on a segment of length b along e_v at ``length`` (3.6).

    It is the proximal half of a revolute joint with h_r = length (with the crimp angle
    psi = arctan(b / (2 H)) of fix B1). It has no distal base: nothing may follow it.

    Parameters
    ----------
    numSides : int
        Number of sides n (even, >= 4).
    r : float
        Tube circumradius (> 0).
    length : float
        Axial distance l > 0 from the base to the closing segment; pattern height
        sqrt(a^2 + l^2). Extreme lengths whose crimp vertex would lie within eps = 1e-4 b of a
        base or midline vertex are rejected.
    """
    prism = make_prism(numSides, r)
    ell = check_positive("length", length)
    geo = revolute_geometry(prism, ell)
    _check_resolvable(prism, geo, "length", ell)
    return _build_end_tip(prism, geo, ModuleRecord("end_tip", {"length": ell}))


@catalog.cached_build
def StartTipPattern(numSides: int, r: float, length: float) -> TubularPattern:
    """The start tip: the end tip reversed (section 2.4); its base is the distal base at y = H.

    Parameters
    ----------
    numSides : int
        Number of sides n (even, >= 4).
    r : float
        Tube circumradius (> 0).
    length : float
        Axial distance l > 0 from the closing segment to the base.
    """
    return EndTipPattern(numSides, r, length).reversed()


# --------------------------------------------------------------------------------------------
# Revolute joint, one sink layer (section 3.4)


class _Layout:
    """Vertex indices of the revolute / tip pattern, vectorised over columns and panels."""

    def __init__(self, prism: Prism, geo: RevoluteGeometry, with_distal: bool) -> None:
        n = prism.numSides
        self.n = n
        k = np.arange(n)
        self.P = k
        nxt = n
        if with_distal:
            self.D = nxt + k
            nxt += n
        else:
            self.D = None
        self.M = nxt + k
        self.C = nxt + n + k
        nxt += 2 * n
        crimped = np.flatnonzero(geo.crimped)
        self.crimped = crimped
        self.K = np.full(n, -1)
        self.K[crimped] = nxt + np.arange(crimped.shape[0])
        nxt += crimped.shape[0]
        if with_distal:
            self.U = np.full(n, -1)
            self.U[crimped] = nxt + np.arange(crimped.shape[0])
            nxt += crimped.shape[0]
        self.total = nxt
        mp, ep = geo.flap_panels
        self.mp, self.ep = mp, ep
        self.sink = np.array([p for p in range(n) if p not in (mp, ep)])
        self.flap_columns = np.array([0, mp, mp + 1, ep])


def _revolute_vertices(prism: Prism, geo: RevoluteGeometry, lay: _Layout) -> np.ndarray:
    x = prism.columns
    H = geo.H
    v = np.empty((lay.total, 2))
    v[lay.P, 0], v[lay.P, 1] = x, 0.0
    cr = lay.crimped
    if lay.D is not None:
        v[lay.D, 0], v[lay.D, 1] = x, 2.0 * H
        v[lay.U[cr], 0], v[lay.U[cr], 1] = x[cr], 2.0 * H - geo.t[cr]
    v[lay.M, 0], v[lay.M, 1] = x, H
    v[lay.C, 0], v[lay.C, 1] = prism.panel_centres, H
    v[lay.K[cr], 0], v[lay.K[cr], 1] = x[cr], geo.t[cr]
    return v


def _common_blocks(lay: _Layout, half_midlines: bool) -> list:
    """Creases shared by the revolute joint (any N) and the lower half used by the tip."""
    n, P, M, C = lay.n, lay.P, lay.M, lay.C
    k = np.arange(n)
    nxt = (k + 1) % n
    mp, ep = lay.mp, lay.ep
    F = lay.flap_columns
    blocks = [crease_block(P, P[nxt], "M")]
    if lay.D is not None:
        blocks.append(crease_block(lay.D, lay.D[nxt], "M"))
    blocks.append(crease_block(P[F], M[F], "M"))
    if lay.D is not None:
        blocks.append(crease_block(M[F], lay.D[F], "M"))
    if half_midlines:
        blocks.append(
            crease_block(
                [M[0], C[mp - 1], M[mp + 1], C[ep - 1]], [C[0], M[mp], C[mp + 1], M[ep]], "M"
            )
        )
    blocks.append(crease_block([M[mp], C[mp], M[ep], C[ep]], [C[mp], M[mp + 1], C[ep], M[0]], "V"))
    cr = lay.crimped
    K = lay.K
    blocks.append(crease_block(P[cr], K[cr], "M"))
    blocks.append(crease_block(K[cr], M[cr], "V"))
    if lay.D is not None:
        U = lay.U
        blocks.append(crease_block(M[cr], U[cr], "M"))
        blocks.append(crease_block(U[cr], lay.D[cr], "M"))
    return blocks


def _single_sink_blocks(lay: _Layout) -> list:
    """The N = 1 sink folds: the X of every sink panel and the crimp-to-centre creases."""
    n, P, M, C, K = lay.n, lay.P, lay.M, lay.C, lay.K
    s = lay.sink
    cr = lay.crimped
    prev = (cr - 1) % n
    blocks = [
        crease_block(P[s], C[s], "V"),
        crease_block(C[s], P[(s + 1) % n], "V"),
    ]
    if lay.D is not None:
        blocks.insert(1, crease_block(lay.D[s], C[s], "V"))
        blocks.append(crease_block(C[s], lay.D[(s + 1) % n], "V"))
    blocks += [
        crease_block(C[prev], M[cr], "V"),
        crease_block(M[cr], C[cr], "V"),
        crease_block(C[prev], K[cr], "M"),
        crease_block(K[cr], C[cr], "M"),
    ]
    if lay.D is not None:
        blocks.append(crease_block(C[prev], lay.U[cr], "V"))
        blocks.append(crease_block(lay.U[cr], C[cr], "M"))
    return blocks


def _build_revolute(
    prism: Prism, geo: RevoluteGeometry, layers: int, record: ModuleRecord
) -> TubularPattern:
    lay = _Layout(prism, geo, with_distal=True)
    vertices = _revolute_vertices(prism, geo, lay)
    if layers == 1:
        blocks = _common_blocks(lay, half_midlines=True) + _single_sink_blocks(lay)
    else:
        blocks = _common_blocks(lay, half_midlines=False)  # fix B2: the chains cover them
        try:
            vertices, sink_blocks = _sink_gadget(prism, lay, vertices, layers)
        except _ChainOutsidePanelError:
            theta = record.params["totalBendingAngle"]
            raise InvalidParameterError(
                f"numSinkLayers={layers} cannot be folded with totalBendingAngle={theta!r} for "
                f"numSides={prism.numSides}: the crimp is so low that a projected sink chain "
                "(docs/theory/patterns.md 3.5) leaves its panel and the creases would overlap; use "
                "numSinkLayers=1 or a larger totalBendingAngle"
            ) from None
        blocks += sink_blocks
    return assemble(prism, vertices, blocks, lay.P, lay.D, 2.0 * geo.H, record)


def _build_end_tip(prism: Prism, geo: RevoluteGeometry, record: ModuleRecord) -> TubularPattern:
    lay = _Layout(prism, geo, with_distal=False)
    vertices = _revolute_vertices(prism, geo, lay)
    blocks = _common_blocks(lay, half_midlines=True) + _single_sink_blocks(lay)
    return assemble(prism, vertices, blocks, lay.P, None, geo.H, record)


# --------------------------------------------------------------------------------------------
# Recursive sink gadget, N >= 2 layers (section 3.5)


def _plain_chain(S: np.ndarray, C: np.ndarray, N: int) -> np.ndarray:
    j = np.arange(N + 1)[:, None] / N
    return S + j * (C - S)


def _crimp_chain(G: np.ndarray, C: np.ndarray, N: int, d: float) -> np.ndarray:
    u = (G - C) / np.linalg.norm(G - C)
    j = np.arange(N + 1)[:, None]
    chain = C + (N - j) * d * u
    chain[0] = G
    return chain


class _ChainOutsidePanelError(Exception):
    """A projected sink chain's first inner point is not between its outer point and C."""


def _projected_chain(
    Y: np.ndarray, C: np.ndarray, inner: np.ndarray, N: int, eps: float
) -> np.ndarray:
    span = float(np.linalg.norm(Y - C))
    u = (Y - C) / span
    g = inner - C
    along = float(u @ g)
    rho = float(g @ g) / along if along > 0 else math.inf
    if not eps < rho < span - eps:
        raise _ChainOutsidePanelError
    j = np.arange(N + 1)[:, None]
    chain = C + ((N - j) / (N - 1)) * rho * u
    chain[0] = Y
    return chain


def _alternating(N: int, first: str) -> np.ndarray:
    other = "V" if first == "M" else "M"
    return np.array([first if j % 2 == 0 else other for j in range(N)])


def _sink_gadget(
    prism: Prism, lay: _Layout, vertices: np.ndarray, N: int
) -> tuple[np.ndarray, list]:
    """Vertices and creases of the N nested sinks of every sink panel (section 3.5)."""
    n, b = prism.numSides, prism.b
    d = b / (2.0 * N)
    crimped = np.zeros(n, dtype=bool)
    crimped[lay.crimped] = True
    new_points: list[np.ndarray] = []
    next_index = vertices.shape[0]
    edges: list[np.ndarray] = []
    labels: list[np.ndarray] = []
    ring_labels = np.array(["V" if j % 2 else "M" for j in range(N)])

    def add_chain(points: np.ndarray, outer: int, centre: int, radial: np.ndarray) -> np.ndarray:
        """Register the inner points of a chain; return the indices of S_0 .. S_N."""
        nonlocal next_index
        idx = np.empty(N + 1, dtype=np.intp)
        idx[0], idx[N] = outer, centre
        idx[1:N] = next_index + np.arange(N - 1)
        next_index += N - 1
        new_points.append(points[1:N])
        edges.append(np.stack([idx[:-1], idx[1:]], axis=1))
        labels.append(radial)
        return idx

    for p in lay.sink:
        q = (p + 1) % n
        c_idx = lay.C[p]
        # unwrapped coordinates of the panel (sink panels never straddle the seam)
        Cxy = np.array([(p + 1) * b, vertices[c_idx, 1]])
        xl, xr = (p + 0.5) * b, (p + 1.5) * b

        def at(index: int, x: float) -> np.ndarray:
            return np.array([x, vertices[index, 1]])

        cl, cr = bool(crimped[p]), bool(crimped[q])
        side = {}
        for name, col, x, is_c in (("L", p, xl, cl), ("R", q, xr, cr)):
            T, B, Mid = lay.D[col], lay.P[col], lay.M[col]
            if is_c:
                Up, Lo = lay.U[col], lay.K[col]
                up = _crimp_chain(at(Up, x), Cxy, N, d)
                lo = _crimp_chain(at(Lo, x), Cxy, N, d)
                top = _projected_chain(at(T, x), Cxy, up[1], N, prism.eps)
                bot = _projected_chain(at(B, x), Cxy, lo[1], N, prism.eps)
                mid = _projected_chain(at(Mid, x), Cxy, lo[1], N, prism.eps)
                first_up = "M" if name == "L" else "V"
                side[name] = {
                    "up": add_chain(up, Up, c_idx, _alternating(N, first_up)),
                    "lo": add_chain(lo, Lo, c_idx, _alternating(N, "M")),
                    "top": add_chain(top, T, c_idx, _alternating(N, "V")),
                    "bot": add_chain(bot, B, c_idx, _alternating(N, "V")),
                    "mid": add_chain(mid, Mid, c_idx, np.full(N, "V")),
                }
            else:
                side[name] = {
                    "top": add_chain(
                        _plain_chain(at(T, x), Cxy, N), T, c_idx, _alternating(N, "V")
                    ),
                    "bot": add_chain(
                        _plain_chain(at(B, x), Cxy, N), B, c_idx, _alternating(N, "V")
                    ),
                    # fix B3: the uncrimped horizontal chain is M, V, M, ... on both sides
                    "mid": add_chain(
                        _plain_chain(at(Mid, x), Cxy, N), Mid, c_idx, _alternating(N, "M")
                    ),
                }
        left, right = side["L"], side["R"]
        for j in range(1, N):
            for ring in ("top", "bot"):
                chain = [left["mid"]]
                if cl:
                    chain.append(left["up" if ring == "top" else "lo"])
                chain += [left[ring], right[ring]]
                if cr:
                    chain.append(right["up" if ring == "top" else "lo"])
                chain.append(right["mid"])
                pts = np.array([c[j] for c in chain])
                lab = np.full(pts.shape[0] - 1, ring_labels[j])
                if ring == "bot":  # the "diamond" rule (kept as in the reference, B4)
                    flip = {"M": "V", "V": "M"}[ring_labels[j]]
                    if cl:
                        lab[0] = flip
                    if cr:
                        lab[-1] = flip
                edges.append(np.stack([pts[:-1], pts[1:]], axis=1))
                labels.append(lab)
    vertices = np.concatenate([vertices, *new_points])
    return vertices, list(zip(edges, labels, strict=True))


# --------------------------------------------------------------------------------------------
# Catalog entries: counts and folds


def _revolute_counts(prism: Prism, params) -> ModuleCounts:
    """6n - 8 vertices and 16n - 32 creases for one sink layer; fix B2 for N >= 2 layers."""
    n, N = prism.numSides, params["numSinkLayers"]
    if N == 1:
        return ModuleCounts(6 * n - 8, 16 * n - 32)
    return ModuleCounts(
        6 * n - 8 + (10 * n - 28) * (N - 1), 6 * n - 4 + (10 * n - 28) * (2 * N - 1)
    )


def _tip_counts(prism: Prism, params) -> ModuleCounts:
    n = prism.numSides
    return ModuleCounts(4 * n - 4, 9 * n - 16)


def _fold_revolute(
    prism: Prism,
    pattern: TubularPattern,
    h_r: float,
    with_distal: bool,
    xy: np.ndarray | None = None,
) -> np.ndarray:
    """Revolute joint at state 0 (or the end tip when ``with_distal`` is False).

    Named points of docs/theory/patterns.md section 3.4; the crimp flap vertex M_k of a crimped
    column lies in the plane of its lower fin (docs/fold.md); the nested sink vertices (N >= 2)
    lie on the N = 1 creases they subdivide, at the same fraction of the way to the panel
    centre.
    """
    n, r, b = prism.numSides, prism.r, prism.b
    geo = revolute_geometry(prism, h_r)
    H, t = geo.H, geo.t
    x = prism.columns
    beta = prism.vertex_angles
    sin_b, cos_b = np.sin(beta), np.cos(beta)
    sgn = np.where(sin_b >= 0.0, 1.0, -1.0)
    centre = np.array([0.0, 0.0, h_r])
    ev = np.array([0.0, 1.0, 0.0])
    p = corners(prism)
    s = r * sin_b - sgn * np.sqrt(np.maximum(t**2 - h_r**2 - (r * cos_b) ** 2, 0.0))
    M3 = centre + np.outer(sgn * (b / 2.0), ev)
    # crimped column: the flap (K, M, O) is a right triangle, |OM| = b/2, |KM| = H - t, right
    # angle at M, hinged on the axis line. It lies in the plane of the lower fin (p_k, K, O):
    # folded onto the fin where sin(beta) cos(beta) >= 0, continuing it beyond the axis line
    # elsewhere; this is the choice under which every crimp crease folds the way its label
    # says (docs/fold.md). A tip has no upper crimp: its flaps are all folded onto the fin.
    for k in np.flatnonzero(geo.crimped):
        along = (b * b / 4.0) / s[k]
        radius = (b / 2.0) * (H - t[k]) / abs(s[k])
        towards_fin = np.array([r * cos_b[k], 0.0, -h_r])
        towards_fin /= np.linalg.norm(towards_fin)
        if with_distal and sin_b[k] * cos_b[k] < -1e-12:
            towards_fin = -towards_fin
        M3[k] = centre + along * ev + radius * towards_fin
    centres = prism.panel_centres
    named_xy = [np.stack([x, np.zeros(n)], axis=1), np.stack([x, np.full(n, H)], axis=1)]
    named_X = [p, M3]
    named_xy.append(np.stack([centres, np.full(n, H)], axis=1))
    named_X.append(np.repeat(centre[None], n, axis=0))
    ck = np.flatnonzero(geo.crimped)
    K3 = centre + np.outer(s[ck], ev)
    named_xy.append(np.stack([x[ck], t[ck]], axis=1))
    named_X.append(K3)
    if with_distal:
        top = p.copy()
        top[:, 2] = 2.0 * h_r
        named_xy.append(np.stack([x, np.full(n, 2.0 * H)], axis=1))
        named_X.append(top)
        named_xy.append(np.stack([x[ck], 2.0 * H - t[ck]], axis=1))
        named_X.append(K3)
    named_xy = np.concatenate(named_xy)
    named_X = np.concatenate(named_X)
    xy = pattern.vertices_coords if xy is None else xy
    X, matched = assign(xy, named_xy, named_X, prism.W, 1e-9 * r)
    if not matched.all():
        X = _fold_sink_chains(prism, xy, X, matched, centre, H)
    return X


def _fold_sink_chains(prism, xy, X, matched, centre, H):
    """Nested sink vertices: on the segment from an outer point of their panel to its centre.

    Every chain of the nested sinks runs along an N = 1 crease from an outer point Y of the panel
    (corner, crimp, midline point) to the panel centre C; its vertex at flat distance f |Y - C|
    from C folds to O + f (Y3 - O), O = ``centre``, where the N = 1 fold is affine
    (docs/fold.md).
    """
    b, W = prism.b, prism.W
    outer_xy = xy[matched]
    outer_X = X[matched]
    tol = 1e-9 * prism.r
    for i in np.flatnonzero(~matched):
        px, py = xy[i]
        p = math.floor(px / b - 0.5)  # sink panels lie between columns p and p + 1
        cx = (p + 1) * b
        rel = np.stack([periodic_dx(outer_xy[:, 0] - cx, W), outer_xy[:, 1] - H], axis=1)
        v = np.array([periodic_dx(np.array([px - cx]), W)[0], py - H])
        span = np.linalg.norm(rel, axis=1)
        along = float(np.linalg.norm(v))
        cross = np.abs(rel[:, 0] * v[1] - rel[:, 1] * v[0])
        candidate = (
            (np.abs(rel[:, 0]) <= 0.5 * b + tol)
            & (rel @ v > 0.0)
            & (span > along + tol)
            & (cross <= tol * np.maximum(span, 1.0))
        )
        if not candidate.any():  # pragma: no cover - a catalog module changed its sink chains
            raise FoldedFormError(f"sink vertex {i} at {xy[i]} lies on no crease to its centre")
        best = np.flatnonzero(candidate)[np.argmin(span[candidate])]
        X[i] = centre + (along / span[best]) * (outer_X[best] - centre)
    return X


def _fold_joint(prism: Prism, pattern: TubularPattern, params):
    h_r = prism.a * math.tan(params["totalBendingAngle"] / 4.0)
    X = _fold_revolute(prism, pattern, h_r, with_distal=True)
    return X, translation(2.0 * h_r)


def _fold_end_tip(prism: Prism, pattern: TubularPattern, params):
    ell = params["length"]
    return _fold_revolute(prism, pattern, ell, with_distal=False), translation(ell)


def _fold_start_tip(prism: Prism, pattern: TubularPattern, params):
    """The end tip's fold mirrored through the cross-section plane at half its length."""
    ell = params["length"]
    xy = pattern.vertices_coords
    mirrored = xy.copy()
    mirrored[:, 1] = pattern.height - xy[:, 1]
    X = _fold_revolute(prism, pattern, ell, with_distal=False, xy=mirrored)
    X[:, 2] = ell - X[:, 2]
    return X, translation(ell)


catalog.register(
    catalog.ModuleKind(
        "revolute",
        RevoluteJointPattern,
        ("totalBendingAngle", "numSinkLayers"),
        _revolute_counts,
        _fold_joint,
    )
)
catalog.register(
    catalog.ModuleKind(
        "end_tip", EndTipPattern, ("length",), _tip_counts, _fold_end_tip, mirror="start_tip"
    )
)
catalog.register(
    catalog.ModuleKind(
        "start_tip", StartTipPattern, ("length",), _tip_counts, _fold_start_tip, mirror="end_tip"
    )
)
