"""REBO bellows and the prismatic joint built around it (docs/theory/patterns.md 3.7, 3.8)."""

from __future__ import annotations

import math

import numpy as np

from kinegami._record import Record
from kinegami.errors import InvalidParameterError
from kinegami.pattern import catalog
from kinegami.pattern._build import assemble, check_bool, crease_block
from kinegami.pattern._fold import (
    assign,
    corners,
    mod_w,
    moved_copy,
    polygon_point,
    require_all,
    translation,
)
from kinegami.pattern._prism import Prism, make_prism, wrap_x
from kinegami.pattern.catalog import ModuleCounts
from kinegami.pattern.tube import tube_pattern
from kinegami.pattern.tubular import ModuleRecord, TubularPattern
from kinegami.validation import (
    check_in_range,
    check_num_layers,
    check_num_sides,
    check_positive,
)

__all__ = [
    "PrismaticJointPattern",
    "REBOGeometry",
    "REBOPattern",
    "rebo_folded_length",
    "rebo_geometry",
    "rebo_tilt",
]


class REBOGeometry(Record):
    """Derived quantities of a REBO (section 3.7); lengths in units of r, angles in radians.

    Attributes
    ----------
    l1 : float
        Flat half-height of one layer, d / (2 N sin(beta)).
    height : float
        Pattern height 2 N l1 = d / sin(beta).
    flat_cone_angle : float
        alpha_f = (pi/2)(1 - 2 cos(beta) / n).
    offset : float
        o = l1 cot(alpha_f), x offset of the mid-layer pleat vertices.
    """

    l1: float
    height: float
    flat_cone_angle: float
    offset: float


def rebo_geometry(prism: Prism, d: float, N: int, beta: float) -> REBOGeometry:
    """Layer height, flat cone angle and pleat offset of a REBO (section 3.7)."""
    l1 = d / (2.0 * N * math.sin(beta))
    alpha_f = 0.5 * math.pi * (1.0 - 2.0 * math.cos(beta) / prism.numSides)
    return REBOGeometry(l1, 2.0 * N * l1, alpha_f, l1 / math.tan(alpha_f))


def _check_rebo(numSides, r, neutralLength, numLayers, coneAngle, low: float):
    prism = make_prism(numSides, r)
    d = check_positive("neutralLength", neutralLength)
    N = check_num_layers(numLayers)
    if low > 0:
        beta = check_in_range(
            "coneAngle", coneAngle, low, 0.5 * math.pi, low_inclusive=True,
            range_text="[pi/6, pi/2)",
        )  # fmt: skip
    else:
        beta = check_in_range("coneAngle", coneAngle, 0.0, 0.5 * math.pi, range_text="(0, pi/2)")
    geo = rebo_geometry(prism, d, N, beta)
    given = f"neutralLength={d!r}, numLayers={N}, coneAngle={beta!r}"
    if not geo.offset < prism.b - prism.eps:
        raise InvalidParameterError(
            f"REBO pleat offset o = l1 cot(alpha_f) = {geo.offset:.6g} must be < b = {prism.b:.6g} "
            f"(else creases cross); got {given}: use more layers or a shorter neutralLength"
        )
    if not min(geo.offset, geo.l1) > prism.eps:
        raise InvalidParameterError(
            f"REBO pleat offset o = {geo.offset:.6g} and layer half-height l1 = {geo.l1:.6g} "
            f"must exceed the tolerance eps = {prism.eps:.3g} (else creases have zero length); "
            f"got {given}: use fewer layers or a coneAngle further from pi/2"
        )
    return prism, d, N, beta, geo


@catalog.cached_build
def REBOPattern(
    numSides: int,
    r: float,
    neutralLength: float,
    numLayers: int,
    coneAngle: float,
    proximalValleys: bool = False,
) -> TubularPattern:
    """The REBO bellows of ``numLayers`` layers (section 3.7).

    Each layer is a ring of pleats: layer rings (M) are the outer ridges and the long midline
    segments (V) the waist. Flat, the pattern height is neutralLength / sin(coneAngle).

    Parameters
    ----------
    numSides : int
        Number of sides n (even, >= 4).
    r : float
        Tube circumradius (> 0).
    neutralLength : float
        Length d > 0 of the bellows with its faces at the cone angle.
    numLayers : int
        Number of layers N >= 1.
    coneAngle : float
        beta in (0, pi/2), radians.
    proximalValleys : bool, optional
        Label the first ring (at y = 0) V instead of M (used inside the prismatic joint).

    Raises
    ------
    InvalidParameterError
        Also when the pleat offset o = l1 cot(alpha_f) is not below b (fix B11), or when o or
        the layer half-height l1 is below eps = 1e-4 b (the creases would have zero length).
    """
    prism, d, N, beta, geo = _check_rebo(numSides, r, neutralLength, numLayers, coneAngle, 0.0)
    valleys = check_bool("proximalValleys", proximalValleys)
    record = ModuleRecord(
        "rebo",
        {"neutralLength": d, "numLayers": N, "coneAngle": beta, "proximalValleys": valleys},
    )
    return _build_rebo(prism, geo, N, valleys, record)


def _build_rebo(
    prism: Prism, geo: REBOGeometry, N: int, valleys: bool, record: ModuleRecord
) -> TubularPattern:
    n = prism.numSides
    x = prism.columns
    l1 = geo.l1
    k = np.arange(n)
    rows = np.arange(N + 1)
    layers = np.arange(N)
    # indices: B[i, k] rows 0..N, then A[i, k], then O[i, k] (array Of), layers 0..N-1
    B = rows[:, None] * n + k[None, :]
    A = (N + 1) * n + layers[:, None] * n + k[None, :]
    Of = (2 * N + 1) * n + layers[:, None] * n + k[None, :]
    vertices = np.empty(((3 * N + 1) * n, 2))
    vertices[B.ravel()] = np.stack([np.tile(x, N + 1), np.repeat(2.0 * l1 * rows, n)], axis=1)
    mid_y = np.repeat((2.0 * layers + 1.0) * l1, n)
    vertices[A.ravel()] = np.stack([np.tile(x, N), mid_y], axis=1)
    vertices[Of.ravel()] = np.stack(
        [np.tile(wrap_x(x - geo.offset, prism.W, prism.eps), N), mid_y], axis=1
    )
    nxt = (k + 1) % n
    Bl, Bu = B[:-1], B[1:]
    ring = np.full((N, n), "M")
    if valleys:
        ring[0] = "V"
    blocks = [
        crease_block(Bl.ravel(), Bl[:, nxt].ravel(), ring.ravel()),
        crease_block(Bl.ravel(), A.ravel(), "M"),
        crease_block(A.ravel(), Bu.ravel(), "M"),
        crease_block(Of.ravel(), A.ravel(), "M"),
        crease_block(A.ravel(), Of[:, nxt].ravel(), "V"),
        crease_block(Of.ravel(), Bl.ravel(), "V"),
        crease_block(Of.ravel(), Bu.ravel(), "V"),
        crease_block(B[N], B[N][nxt], "M"),
    ]
    return assemble(prism, vertices, blocks, B[0], B[N], geo.height, record)


@catalog.cached_build
def PrismaticJointPattern(
    numSides: int, r: float, neutralLength: float, numLayers: int, coneAngle: float
) -> TubularPattern:
    """The prismatic joint: sleeve, folded-back lining, REBO and piston (section 3.8).

    With L = neutralLength / sin(coneAngle): Tube(L), a mountain ring, a tube of height L with
    valley edges, REBO(proximalValleys=True) and Tube(L); pattern height 4 L. (See note B7 on
    the folded length, docs/patterns.md.)

    Parameters
    ----------
    numSides : int
        Number of sides n (even, >= 4).
    r : float
        Tube circumradius (> 0).
    neutralLength : float
        Length d > 0 of the joint at state 0.
    numLayers : int
        Number of REBO layers N >= 1.
    coneAngle : float
        REBO cone angle beta in [pi/6, pi/2), radians (below pi/6 the state 0 is not reachable).
    """
    prism, d, N, beta, geo = _check_rebo(
        numSides, r, neutralLength, numLayers, coneAngle, math.pi / 6.0
    )
    L = geo.height
    n = prism.numSides
    sleeve = tube_pattern(prism, L, "M", ModuleRecord("tube", {"height": L}))
    lining = tube_pattern(prism, L, "V", ModuleRecord("tube", {"height": L}))
    k = np.arange(n)
    lining = TubularPattern._build(
        n, prism.r, lining.vertices_coords.copy(),
        np.concatenate([np.stack([k, (k + 1) % n], axis=1), lining.edges_vertices]),
        np.concatenate([np.full(n, "M"), lining.edges_assignment]),
        lining.proximalBase.copy(), lining.distalBase.copy(), np.zeros(2),
        lining.distalMarker.copy(), L, lining.modules, 0, None, False,
    )  # fmt: skip
    rebo = _build_rebo(prism, geo, N, True, ModuleRecord("rebo", {}))
    piston = tube_pattern(prism, L, "M", ModuleRecord("tube", {"height": L}))
    whole = TubularPattern.concatenate([sleeve, lining, rebo, piston])
    record = ModuleRecord("prismatic", {"neutralLength": d, "numLayers": N, "coneAngle": beta})
    return TubularPattern._build(  # whole's arrays are its own (read-only, shared with none)
        n, prism.r, whole.vertices_coords, whole.edges_vertices, whole.edges_assignment,
        whole.proximalBase, whole.distalBase, np.zeros(2), np.array([0.0, 4.0 * L]), 4.0 * L,
        (record,), 0, None, False,
    )  # fmt: skip


# --------------------------------------------------------------------------------------------
# Catalog entries: counts, unsnapped geometry and folds


def _rebo_counts(prism: Prism, params) -> ModuleCounts:
    n, N = prism.numSides, params["numLayers"]
    mountains = 4 * N * n if params["proximalValleys"] else n * (4 * N + 1)
    return ModuleCounts(n * (3 * N + 1), n * (7 * N + 1), mountains)


def _prismatic_counts(prism: Prism, params) -> ModuleCounts:
    n, N = prism.numSides, params["numLayers"]
    return ModuleCounts(n * (3 * N + 4), n * (7 * N + 5))


def _unsnapped(prism: Prism, pattern: TubularPattern, params):
    """The pattern with its pleat offset points of column 0 not snapped onto the seam (the
    only points of a REBO or prismatic joint that the eps rules can move)."""
    identity = np.arange(pattern.numVertices)
    xy = pattern.vertices_coords.copy()
    snapped = xy[:, 0] == 0.0
    if not snapped.any():
        return pattern, identity
    geo = rebo_geometry(prism, params["neutralLength"], params["numLayers"], params["coneAngle"])
    xy[snapped, 0] = mod_w(prism.columns[:1] - geo.offset, prism.W)[0]
    return moved_copy(pattern, xy, pattern.distalMarker.copy()), identity


def rebo_tilt(numSides: int, coneAngle: float) -> float:
    """Inclination gamma of the REBO's faces in its rigid folded state, radians.

    Every layer folds as a rigid bellows (docs/fold.md): each quadrilateral face turns about its
    layer-ring edge, inwards, until it makes the angle gamma with the cross-section plane, and
    the pleat triangles close exactly when l1 cos(gamma) = o cot(pi/n), i.e.

        cos(gamma) = cot(alpha_f) cot(pi/n) = tan(pi cos(beta) / n) / tan(pi / n),

    with alpha_f = (pi/2)(1 - 2 cos(beta)/n) the flat cone angle of the REBO pattern. Then
    beta <= gamma < pi/2, and gamma -> beta as n grows. (The other rigid state, gamma = pi/2,
    is the unfolded tube.)

    Parameters
    ----------
    numSides : int
        n, even and >= 4.
    coneAngle : float
        beta in (0, pi/2), radians.

    Examples
    --------
    >>> round(rebo_tilt(4, math.pi / 4), 6)
    0.90141
    """
    n = check_num_sides(numSides)
    beta = check_in_range("coneAngle", coneAngle, 0.0, 0.5 * math.pi, range_text="(0, pi/2)")
    ratio = math.tan(math.pi * math.cos(beta) / n) / math.tan(math.pi / n)
    return math.acos(min(ratio, 1.0))


def rebo_folded_length(numSides: int, neutralLength: float, coneAngle: float) -> float:
    """Axial length of a REBO in its rigid folded state: d sin(gamma) / sin(beta) (>= d).

    Each of the N layers is 2 l1 sin(gamma) long, l1 = d / (2 N sin(beta)); gamma is
    :func:`rebo_tilt`. This is the length of the prismatic joint's bellows in the folded form
    (same unit as ``neutralLength``; independent of r and of the number of layers).
    """
    gamma = rebo_tilt(numSides, coneAngle)
    d = check_positive("neutralLength", neutralLength)
    return d * math.sin(gamma) / math.sin(coneAngle)


def _fold_rebo_vertices(prism: Prism, xy: np.ndarray, d: float, N: int, beta: float):
    """Positions of REBO vertices given their local flat coordinates (y from 0 to H).

    The rigid folded state (docs/fold.md): layer rings are the base polygon, 2 l1 sin(gamma)
    apart and not twisted. The lower quadrilateral (B_{i,k}, B_{i,k+1}, O_{i,k+1}, A_{i,k}) of
    panel k is the flat quadrilateral turned about its ring edge by gamma towards the axis, so
    A_{i,k} = B_{i,k} + l1 (cos(gamma) nu_k + sin(gamma) e_a), nu_k the inward normal of panel k,
    and O_{i,k+1} = A_{i,k} + (b - o) t_k, t_k the direction of the ring edge; the upper
    quadrilateral is its mirror image in the waist plane. Every face is planar and every crease
    keeps its length.
    """
    n, b = prism.numSides, prism.b
    geo = rebo_geometry(prism, d, N, beta)
    l1, o = geo.l1, geo.offset
    gamma = rebo_tilt(n, beta)
    layer = 2.0 * l1 * math.sin(gamma)
    ring = corners(prism)
    normal_angle = (np.arange(n) + 1.0) * (2.0 * math.pi / n)  # outward normal of panel k
    inward = -np.stack([np.cos(normal_angle), np.sin(normal_angle), np.zeros(n)], axis=1)
    edge = np.roll(ring, -1, axis=0) - ring
    edge /= np.linalg.norm(edge, axis=1)[:, None]
    mid = ring + l1 * math.cos(gamma) * inward  # A_{0,k}
    mid[:, 2] = 0.5 * layer
    offset_mid = np.roll(mid + (b - o) * edge, 1, axis=0)  # O_{0,k+1} from panel k
    x = prism.columns
    names_xy = []
    names_X = []
    for i in range(N + 1):
        names_xy.append(np.stack([x, np.full(n, 2.0 * i * l1)], axis=1))
        names_X.append(ring + np.array([0.0, 0.0, i * layer]))
    offset_x = mod_w(x - o, prism.W)
    for i in range(N):
        mid_y = np.full(n, (2.0 * i + 1.0) * l1)
        rise = np.array([0.0, 0.0, i * layer])
        names_xy += [np.stack([x, mid_y], axis=1), np.stack([offset_x, mid_y], axis=1)]
        names_X += [mid + rise, offset_mid + rise]
    X, matched = assign(
        xy, np.concatenate(names_xy), np.concatenate(names_X), prism.W, 1e-9 * prism.r
    )
    require_all(matched, "REBO")
    return X


def _fold_prismatic(prism: Prism, pattern: TubularPattern, params):
    """Sleeve, lining folded back inside it, REBO, piston (the folded reading, note B7).

    The bellows is in its rigid folded state, of length d' = :func:`rebo_folded_length`, so the
    joint folds to d' + L.
    """
    d, N, beta = params["neutralLength"], params["numLayers"], params["coneAngle"]
    geo = rebo_geometry(prism, d, N, beta)
    L = geo.height
    xy = pattern.vertices_coords
    y = xy[:, 1]
    X = polygon_point(prism, xy[:, 0])
    tol = 1e-9 * prism.r
    sleeve = y <= L + tol
    lining = (y > L + tol) & (y <= 2.0 * L + tol)
    rebo = (y > 2.0 * L + tol) & (y <= 3.0 * L + tol)
    piston = y > 3.0 * L + tol
    X[sleeve, 2] = y[sleeve]
    X[lining, 2] = 2.0 * L - y[lining]
    local = xy[rebo].copy()
    local[:, 1] -= 2.0 * L
    X[rebo] = _fold_rebo_vertices(prism, local, d, N, beta)
    length = rebo_folded_length(prism.numSides, d, beta)
    X[piston, 2] = length + (y[piston] - 3.0 * L)
    return X, translation(length + L)


def _fold_rebo(prism: Prism, pattern: TubularPattern, params):
    d, N, beta = params["neutralLength"], params["numLayers"], params["coneAngle"]
    X = _fold_rebo_vertices(prism, pattern.vertices_coords, d, N, beta)
    return X, translation(rebo_folded_length(prism.numSides, d, beta))


catalog.register(
    catalog.ModuleKind(
        "rebo",
        REBOPattern,
        ("neutralLength", "numLayers", "coneAngle", "proximalValleys"),
        _rebo_counts,
        _fold_rebo,
        _unsnapped,
    )
)
catalog.register(
    catalog.ModuleKind(
        "prismatic",
        PrismaticJointPattern,
        ("neutralLength", "numLayers", "coneAngle"),
        _prismatic_counts,
        _fold_prismatic,
        _unsnapped,
    )
)
