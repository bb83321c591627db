"""The folded form: 3D positions of every vertex of a crease pattern at joint state 0.

A :class:`~kinegami.pattern.TubularPattern` made of catalog modules remembers which modules it
is made of (``pattern.modules``) and where each module's vertices went
(``pattern.module_vertices``, recorded by composition). :func:`folded_form` rebuilds every
module from its record, folds it with its catalog entry's fold in its own proximal frame
(docs/theory/patterns.md section 4 and docs/fold.md) and chains the module transforms, so
the result is an isometric 3D realisation of the whole pattern.

Frames. Inside a module, positions are computed in its proximal frame (e_u, e_v, e_a) of
docs/theory/patterns.md section 1. In world coordinates a module's end is described by its Dubins
frame (x = e_a, the path direction; y = e_u, the reference point; z = e_v), the convention of the
chain code (``joint.proximal_dubins_frame()``). For a chain, the first module's proximal Dubins
frame is the first joint's proximal Dubins frame, so the folded form lies on the chain's 3D model
at state 0: every module end coincides with the chain's joint and link frames. Two exceptions
follow the pattern rather than the kinematic model, because the pattern cannot fold otherwise:

* a prismatic joint's pattern folds to length d' + L instead of the kinematic d: the sleeve adds
  L = d / sin(coneAngle) (B7 of docs/theory/patterns.md §6) and the bellows, folded with rigid
  faces, is d' = :func:`rebo_folded_length` >= d long; everything after a prismatic joint is
  translated by d' + L - d along its axis;
* turns and twists of at most 0.01 rad that the link builder leaves out of the pattern, and tubes
  shorter than eps = 1e-4 b, are missing from the folded form too (docs/theory/patterns.md §4).

Where the pattern gives no positions (the REBO bellows, the nested sink layers of the revolute
joint, the free crimp flaps of the revolute joint and tips) docs/fold.md says which isometric
realisation is used; every face is then a rigid, planar copy of its flat polygon.

Snapped vertices. The catalog moves some vertices by a little (elbow columns merged or collapsed
by fix B6, points snapped onto the seam, section 2.1); no fold of those keeps every length.
:func:`unsnapped_form` rebuilds the modules without those rules (a few more vertices and short
creases) and folds them exactly: the FOLD exporter writes that sheet. :func:`folded_form` keeps
the catalog's vertices and puts the ones around snapped vertices back on an isometry of the
creases by a damped least-squares solve; the faces next to them bend slightly (docs/fold.md).
"""

from __future__ import annotations

import functools
from dataclasses import dataclass

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.pattern._fold import MERGE_TOLERANCE, FoldedFormError, mod_w
from kinegami.pattern._prism import make_prism, periodic_dx, readonly
from kinegami.pattern.catalog import module_kind
from kinegami.pattern.prismatic import rebo_folded_length, rebo_tilt
from kinegami.pattern.tubular import ModuleRecord, TubularPattern

__all__ = [
    "FoldedForm",
    "FoldedModule",
    "FoldedFormError",
    "UnsnappedForm",
    "folded_form",
    "folded_vertices",
    "module_fold",
    "rebo_folded_length",
    "rebo_tilt",
    "unsnapped_form",
    "pattern_and_frame",
    "UVA_TO_DUBINS",
]

#: Q such that a frame's Dubins form is ``G @ Q.T`` when ``G`` has the columns (e_u, e_v, e_a):
#: (x_D, y_D, z_D) = (e_a, e_u, e_v) (docs/theory/patterns.md 1.3).
UVA_TO_DUBINS = np.array(
    [[0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
)

#: Crease length errors above this many r trigger the Gauss-Newton repair.
REPAIR_TOLERANCE = 1e-10


@dataclass(frozen=True, eq=False)
class FoldedModule:
    """One catalog module of a folded pattern.

    Attributes
    ----------
    record : ModuleRecord
        The module's kind and parameters.
    vertices : numpy.ndarray of int, shape (V,)
        Global vertex index of each of the module's own vertices (in the module's local order).
    proximal : numpy.ndarray, shape (4, 4)
        World Dubins frame of the module's proximal end (x = path direction, y = e_u); for a
        start tip, the frame at its closing segment.
    distal : numpy.ndarray, shape (4, 4) or None
        World Dubins frame of the distal end (for an end tip: the frame at the closing segment).
    """

    record: ModuleRecord
    vertices: np.ndarray
    proximal: np.ndarray
    distal: np.ndarray

    @property
    def kind(self) -> str:
        """The module kind (``"tube"``, ``"elbow"``, ...)."""
        return self.record.kind


@dataclass(frozen=True, eq=False)
class FoldedForm:
    """The 3D positions of a pattern's vertices at joint state 0.

    Attributes
    ----------
    pattern : TubularPattern
        The pattern that was folded.
    vertices : numpy.ndarray, shape (N, 3)
        World position of every pattern vertex (pattern units). Read-only.
    modules : tuple of FoldedModule
        The modules in order, with their vertices and world end frames.
    repaired : numpy.ndarray of int
        Indices of the vertices moved by the isometry repair (near vertices the catalog had
        snapped, fix B6 and seam snapping); empty for exact patterns.
    maxLengthError : float
        Largest |3D length - flat length| over all creases after folding (pattern units).
    """

    pattern: TubularPattern
    vertices: np.ndarray
    modules: tuple[FoldedModule, ...]
    repaired: np.ndarray
    maxLengthError: float

    @property
    def repairedVertices(self) -> int:
        """Number of vertices moved by the isometry repair."""
        return int(self.repaired.shape[0])

    def length_errors(self) -> np.ndarray:
        """3D length minus flat length of every crease, shape (M,), pattern units."""
        e = self.pattern.edges_vertices
        d3 = np.linalg.norm(self.vertices[e[:, 1]] - self.vertices[e[:, 0]], axis=1)
        return d3 - self.pattern.edge_lengths()


@dataclass(frozen=True, eq=False)
class UnsnappedForm:
    """A pattern's unsnapped geometry and its exact folded form (what the FOLD file writes).

    The catalog moves some vertices a little (elbow columns merged with their base or collapsed onto
    the midline by fix B6: less than eps = 1e-4 b, or up to about 2e-4 r for a column collapsed by
    its tuck offset; points snapped onto the seam by composition: less than eps); no folded form
    of those vertices keeps every crease length. The unsnapped pattern puts every vertex where
    the module formulas put it (a few more vertices and short creases where B6 merged points),
    so its fold is piecewise isometric: every face is a planar rigid copy of its flat polygon.

    Attributes
    ----------
    pattern : TubularPattern
        The unsnapped pattern: vertex i < ``catalog.numVertices`` stands for vertex i of the
        catalog pattern (at most about eps away in the plane, see :meth:`displacement`); the
        vertices that only the unsnapped geometry has follow. Same n, r, height, markers' y and
        module records as the catalog pattern; creases labelled by the catalog's rules.
    catalog : TubularPattern
        The pattern that was given (as built by the catalog).
    vertices : numpy.ndarray, shape (N', 3)
        World position of every vertex of ``pattern`` at joint state 0 (pattern units).
    modules : tuple of FoldedModule
        The modules in order (``vertices``: their vertices in ``pattern``) with world end frames.
    maxLengthError : float
        Largest |3D length - flat length| over the creases of ``pattern`` (pattern units).
    """

    pattern: TubularPattern
    catalog: TubularPattern
    vertices: np.ndarray
    modules: tuple[FoldedModule, ...]
    maxLengthError: float

    @property
    def extraVertices(self) -> int:
        """Number of vertices that only the unsnapped pattern has (merged by fix B6)."""
        return self.pattern.numVertices - self.catalog.numVertices

    def length_errors(self) -> np.ndarray:
        """3D length minus flat length of every crease of ``pattern``, shape (M,)."""
        return _length_errors(self.pattern, self.vertices)

    def displacement(self) -> np.ndarray:
        """Flat distance from every catalog vertex to the unsnapped vertex standing for it (the
        shortest way on the tube), shape (N,), pattern units: 0 except where a point was
        snapped onto the seam, and below eps = 1e-4 b unless two snaps add up (a twist's
        reference point snapped onto the seam moves every later module by less than eps). The
        vertices that B6 merged are not included (they are ``extraVertices``)."""
        N = self.catalog.numVertices
        d = self.pattern.vertices_coords[:N] - self.catalog.vertices_coords
        return np.hypot(periodic_dx(d[:, 0], self.catalog.width), d[:, 1])


# ------------------------------------------------------------------------------------------------
# Public entry points


def folded_vertices(pattern_or_chain, frame=None, twistPortion: float = 0.2) -> np.ndarray:
    """World 3D position of every vertex of a pattern or of a chain's crease pattern.

    Parameters
    ----------
    pattern_or_chain : TubularPattern or KinematicChain
        A pattern made of catalog modules (for example ``chain.creasePattern()``), or a chain,
        whose ``creasePattern(twistPortion)`` is folded.
    frame : SE3 or array_like (4, 4), optional
        World Dubins frame (x = path direction, y = e_u) of the pattern's proximal end. Default:
        for a chain, its first joint's proximal Dubins frame (so the result is in the chain's
        world frame); for a pattern, the frame with e_u = x, e_v = y and the tube axis e_a = z.
    twistPortion : float, optional
        Passed to ``chain.creasePattern`` when a chain is given (default 0.2).

    Returns
    -------
    numpy.ndarray, shape (N, 3)
        ``result[i]`` is where vertex ``i`` of the pattern lies when folded, at joint state 0.

    Examples
    --------
    >>> from kinegami.pattern import TubeFittingPattern, ElbowFittingPattern
    >>> p = TubeFittingPattern(4, 1.0, 1.0).append(ElbowFittingPattern(4, 1.0, np.pi / 2, 0.0))
    >>> folded_vertices(p).shape
    (22, 3)
    """
    return folded_form(pattern_or_chain, frame=frame, twistPortion=twistPortion).vertices


def folded_form(pattern_or_chain, frame=None, twistPortion: float = 0.2) -> FoldedForm:
    """The folded form of a pattern or chain, with per-module frames (see :func:`folded_vertices`).

    Raises
    ------
    InvalidTypeError
        If the argument is neither a TubularPattern nor a chain.
    FoldedFormError
        If the pattern has no module records (built by hand) or its records do not rebuild its
        vertices (e.g. a reversed composite).
    """
    pattern, base = pattern_and_frame(pattern_or_chain, twistPortion)
    if frame is not None:
        base = _frame_array(frame)
    G0 = base @ UVA_TO_DUBINS
    return _fold(pattern, G0)


def unsnapped_form(pattern_or_chain, frame=None, twistPortion: float = 0.2) -> UnsnappedForm:
    """The unsnapped geometry of a pattern or chain and its exact folded form.

    Takes the arguments of :func:`folded_vertices`. Every module is rebuilt from its record
    without the catalog's eps rules (see :class:`UnsnappedForm`) and the modules are composed as
    in composition (docs/theory/patterns.md 2) but with x reduced modulo W only. The FOLD
    exporter writes this sheet.

    Raises
    ------
    InvalidTypeError, FoldedFormError
        As :func:`folded_form`.

    Examples
    --------
    >>> from kinegami.pattern import ElbowFittingPattern
    >>> p = ElbowFittingPattern(6, 1.0, np.pi / 2, 0.0)  # column 4 has h_4 = 0 (worked example B)
    >>> u = unsnapped_form(p)
    >>> u.extraVertices, bool(u.maxLengthError < 1e-12)
    (0, True)
    """
    pattern, base = pattern_and_frame(pattern_or_chain, twistPortion)
    if frame is not None:
        base = _frame_array(frame)
    return _fold_unsnapped(pattern, base @ UVA_TO_DUBINS)


def module_fold(pattern: TubularPattern) -> tuple[np.ndarray, np.ndarray | None]:
    """Positions of a single catalog module's vertices in its proximal frame (e_u, e_v, e_a).

    Returns ``(X, T)``: ``X`` of shape (V, 3) in the module's local vertex order, and the 4x4
    transform from the proximal to the distal frame, both in (e_u, e_v, e_a) coordinates
    (``T`` is the closing frame for an end tip).
    """
    if not isinstance(pattern, TubularPattern):
        raise InvalidTypeError(f"pattern must be a TubularPattern, got {type(pattern).__name__}")
    if len(pattern.modules) != 1:
        raise FoldedFormError(
            f"module_fold needs a single catalog module, got {len(pattern.modules)} records"
        )
    record = pattern.modules[0]
    X, T, _ = _module_geometry(pattern.numSides, pattern.r, record.kind, _freeze(record.params))
    return X.copy(), T.copy()


# ------------------------------------------------------------------------------------------------
# Input handling


def _frame_array(frame) -> np.ndarray:
    A = getattr(frame, "A", frame)
    try:
        T = np.array(A, dtype=float)
    except (TypeError, ValueError):
        raise InvalidTypeError(f"frame must be an SE3 or a 4x4 array, got {frame!r}") from None
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        raise InvalidParameterError(f"frame must be a finite 4x4 rigid transform, got {T!r}")
    R = T[:3, :3]
    if not (
        np.allclose(R.T @ R, np.eye(3), atol=1e-8)
        and abs(np.linalg.det(R) - 1.0) < 1e-8
        and np.allclose(T[3], (0.0, 0.0, 0.0, 1.0))
    ):
        raise InvalidParameterError(
            f"frame must be a proper rigid transform, got {np.round(T, 6).tolist()}"
        )
    return T


def pattern_and_frame(obj, twistPortion) -> tuple[TubularPattern, np.ndarray]:
    """(pattern, world Dubins frame of its proximal end) for a pattern or a chain."""
    if isinstance(obj, TubularPattern):
        return obj, UVA_TO_DUBINS.T.copy()
    joints = getattr(obj, "Joints", None)
    if callable(getattr(obj, "creasePattern", None)) and joints:
        pattern = obj.creasePattern(twistPortion)
        return pattern, np.array(joints[0].proximal_dubins_frame(), dtype=float)
    raise InvalidTypeError(
        "expected a TubularPattern or a KinematicChain, got " + type(obj).__name__
    )


def _freeze(params) -> tuple:
    return tuple(sorted((str(k), v) for k, v in dict(params).items()))


# ------------------------------------------------------------------------------------------------
# Placing the modules and assembling the folded form


@dataclass(frozen=True, eq=False)
class _Placement:
    """Where one catalog module went in the composite: global index of each local vertex and
    which of them it added (the others are its proximal base, shared with the module before)."""

    record: ModuleRecord
    mapping: np.ndarray
    is_new: np.ndarray


def _placements(pattern: TubularPattern) -> list[_Placement]:
    """Every module of ``pattern`` with the vertices composition gave it
    (``pattern.module_vertices``), checked against the module rebuilt from its record."""
    if not pattern.modules:
        raise FoldedFormError(
            "cannot fold a pattern without module records (kind 'custom'): only patterns made "
            "of catalog modules carry the information needed to fold them"
        )
    placed = pattern.module_vertices
    if placed is None:
        raise FoldedFormError(
            "the pattern's module records do not rebuild it: it does not know where its modules' "
            "vertices are (was it reversed, or built by hand with several records?)"
        )
    n, r = pattern.numSides, pattern.r
    prism = make_prism(n, r)
    tol = 8.0 * prism.eps
    xy = pattern.vertices_coords
    placements = []
    for m, (record, mapping) in enumerate(zip(pattern.modules, placed, strict=True)):
        local = _rebuild(n, r, record, m)
        if mapping.shape[0] != local.numVertices:
            raise _mismatch(m, record, "vertex count differs")
        # the module must sit in the pattern translated as a whole (composition moves it so)
        d = xy[mapping] - local.vertices_coords
        dx = periodic_dx(d[:, 0] - d[0, 0], prism.W)
        dy = d[:, 1] - d[0, 1]
        if np.abs(dx).max(initial=0.0) > tol or np.abs(dy).max(initial=0.0) > tol:
            raise FoldedFormError(
                "the pattern's module records do not rebuild its vertices (module "
                f"{m}, {record.kind!r}, is off by {max(np.abs(dx).max(), np.abs(dy).max()):.3g}); "
                "was it reversed or edited by hand?"
            )
        is_new = np.ones(local.numVertices, dtype=bool)
        if m > 0:
            if local.proximalBase is None:
                raise _mismatch(m, record, "a module without a proximal base")
            is_new[local.proximalBase] = False
        placements.append(_Placement(record, mapping, is_new))
    return placements


def _fold(pattern: TubularPattern, G0: np.ndarray) -> FoldedForm:
    placements = _placements(pattern)
    n, r = pattern.numSides, pattern.r
    X = np.full((pattern.numVertices, 3), np.nan)
    pinned = np.zeros(pattern.numVertices, dtype=bool)
    modules = []
    G = np.array(G0, dtype=float)
    seam_error = 0.0
    repaired = [np.zeros(0, dtype=np.intp)]
    for placement in placements:
        record, mapping, is_new = placement.record, placement.mapping, placement.is_new
        fold = _module_fold(n, r, record.kind, _freeze(record.params))
        world = (G[:3, :3] @ fold.X.T).T + G[:3, 3]
        old = mapping[~is_new]
        if old.size:
            seam_error = max(seam_error, float(np.abs(X[old] - world[~is_new]).max()))
        X[mapping[is_new]] = world[is_new]
        catalog = fold.catalog
        for base in (catalog.proximalBase, catalog.distalBase):
            if base is not None:
                pinned[mapping[base]] = True
        proximal = G @ UVA_TO_DUBINS.T
        G = G @ fold.T
        modules.append(
            FoldedModule(record, readonly(mapping.copy()), proximal, G @ UVA_TO_DUBINS.T)
        )
        repaired.append(mapping[fold.repaired])
    if seam_error > 1e-6 * r:  # pragma: no cover - would be a bug in a module's geometry
        raise FoldedFormError(f"module ends do not meet in 3D (gap {seam_error:.3g})")
    # composition may have snapped vertices near the seam (section 2.1): repair those too
    X, moved = _repair_isometry(pattern, X, pinned)
    repaired = np.unique(np.concatenate(repaired + [moved]))
    errors = _length_errors(pattern, X)
    X.flags.writeable = False
    return FoldedForm(pattern, X, tuple(modules), repaired, float(np.abs(errors).max(initial=0.0)))


def _fold_unsnapped(pattern: TubularPattern, G0: np.ndarray) -> UnsnappedForm:
    """Compose the unsnapped modules (:func:`unsnapped_form`) and fold them.

    The composition is that of docs/theory/patterns.md 2, without the eps rules: x is reduced
    modulo W only (no
    snapping onto the seam, also for the markers), and every module is placed with the exact
    marker. Vertex i < N of the result is vertex i of ``pattern`` (the correspondence comes
    from the replay of the catalog composition); the vertices that only the unsnapped modules
    have follow, numbered in module order.
    """
    placements = _placements(pattern)
    n, r = pattern.numSides, pattern.r
    prism = make_prism(n, r)
    W = prism.W
    N = pattern.numVertices
    coords = [np.full((N, 2), np.nan)]
    X = [np.full((N, 3), np.nan)]
    edges, labels, modules = [], [], []
    next_extra = N
    gap = 0.0
    G = np.array(G0, dtype=float)
    marker = np.array(pattern.proximalMarker, dtype=float)
    for placement in placements:
        record, mapping, is_new = placement.record, placement.mapping, placement.is_new
        _, exact, X_exact, T, corr = _exact_fold(n, r, record.kind, _freeze(record.params))
        offset = marker - exact.proximalMarker
        xy = exact.vertices_coords + offset
        xy[:, 0] = mod_w(xy[:, 0], W)
        world = (G[:3, :3] @ X_exact.T).T + G[:3, 3]
        emap = np.full(exact.numVertices, -1, dtype=np.intp)
        emap[corr] = mapping
        extra = emap < 0
        count = int(np.count_nonzero(extra))
        emap[extra] = np.arange(next_extra, next_extra + count)
        next_extra += count
        new = extra.copy()
        new[corr[is_new]] = True
        shared = emap[~new]
        if shared.size:  # the proximal base: must meet the previous distal base exactly
            flat = coords[0][shared] - xy[~new]
            flat[:, 0] = periodic_dx(flat[:, 0], W)
            gap = max(
                gap, float(np.abs(flat).max()), float(np.abs(X[0][shared] - world[~new]).max())
            )
        own = new & ~extra
        coords[0][emap[own]] = xy[own]
        X[0][emap[own]] = world[own]
        coords.append(xy[extra])
        X.append(world[extra])
        edges.append(emap[exact.edges_vertices])
        labels.append(exact.edges_assignment)
        proximal = G @ UVA_TO_DUBINS.T
        G = G @ T
        modules.append(FoldedModule(record, readonly(emap), proximal, G @ UVA_TO_DUBINS.T))
        marker = exact.distalMarker + offset
        marker[0] = mod_w(marker[0:1], W)[0]
    if gap > 1e-9 * r:  # pragma: no cover - would be a bug in a module's unsnapped geometry
        raise FoldedFormError(f"unsnapped module ends do not meet (gap {gap:.3g})")
    coords = np.concatenate(coords)
    X = np.concatenate(X)
    edges = np.concatenate(edges)
    labels = np.concatenate(labels)
    # composition step 4: a crease joining the same two vertices as an earlier one is dropped
    lo = np.minimum(edges[:, 0], edges[:, 1]).astype(np.int64)
    hi = np.maximum(edges[:, 0], edges[:, 1]).astype(np.int64)
    first = np.unique(lo * coords.shape[0] + hi, return_index=True)[1]
    first.sort()
    edges, labels = edges[first], labels[first]
    exact = TubularPattern._build(
        n, r, coords, np.ascontiguousarray(edges), labels,
        None if pattern.proximalBase is None else pattern.proximalBase.copy(),
        None if pattern.distalBase is None else pattern.distalBase.copy(),
        np.array(pattern.proximalMarker, dtype=float), marker, pattern.height, pattern.modules,
    )  # fmt: skip
    short = exact.edge_lengths() < MERGE_TOLERANCE * r
    if short.any():  # pragma: no cover - the unsnapped modules merge coincident vertices
        raise FoldedFormError(f"{int(short.sum())} unsnapped creases have zero length")
    errors = _length_errors(exact, X)
    for a in (coords, X):
        a.flags.writeable = False
    return UnsnappedForm(exact, pattern, X, tuple(modules), float(np.abs(errors).max(initial=0.0)))


def _mismatch(m: int, record: ModuleRecord, what: str) -> FoldedFormError:
    return FoldedFormError(
        f"the pattern's module records do not rebuild it ({what} at module {m}, "
        f"{record.kind!r}); was it reversed or edited by hand?"
    )


def _rebuild(n: int, r: float, record: ModuleRecord, m: int) -> TubularPattern:
    """The catalog module of a record, rebuilt from its parameters (cached)."""
    try:
        return _rebuild_cached(n, r, record.kind, _freeze(record.params))
    except (TypeError, KeyError) as exc:
        raise FoldedFormError(
            f"module {m} of kind {record.kind!r} has parameters {dict(record.params)!r} that do "
            f"not rebuild a catalog module ({exc})"
        ) from None


@functools.lru_cache(maxsize=512)
def _rebuild_cached(n: int, r: float, kind: str, params: tuple) -> TubularPattern:
    return module_kind(kind).rebuild(n, r, dict(params))


# ------------------------------------------------------------------------------------------------
# Isometry repair


def _length_errors(pattern: TubularPattern, X: np.ndarray) -> np.ndarray:
    e = pattern.edges_vertices
    return np.linalg.norm(X[e[:, 1]] - X[e[:, 0]], axis=1) - pattern.edge_lengths()


def _repair_isometry(
    pattern: TubularPattern, X: np.ndarray, pinned: np.ndarray, release: bool = True
) -> tuple[np.ndarray, np.ndarray]:
    """Move vertices so every crease has its flat length (weighted min-norm Gauss-Newton).

    Only needed where the pattern moved vertices a little (B6 snapping of elbow columns,
    snapping onto the seam, section 2.1): the exact module geometry then misses some flat
    lengths by O(eps). The ends of those creases move. Pinned vertices (base rings) stay
    on their frames unless ``release`` and a crease between two pinned vertices is wrong (a base
    vertex snapped onto the seam), or creases stay wrong with the base vertices fixed (a vertex
    next to a base snapped onto the seam): their base vertices then move too, 400 times more
    reluctantly than the others. (Inside a single module ``release`` is False: its bases are
    shared with the neighbouring modules, and the repair of the whole pattern moves them.)
    """
    tol = REPAIR_TOLERANCE * pattern.r
    edges = pattern.edges_vertices
    target = pattern.edge_lengths()
    errors = _length_errors(pattern, X)
    bad = np.abs(errors) > tol
    if not bad.any():
        return X, np.zeros(0, dtype=np.intp)
    free = np.zeros(X.shape[0], dtype=bool)
    free[edges[bad].ravel()] = True
    stiff = np.zeros(X.shape[0], dtype=bool)
    if release:
        stiff[edges[bad & pinned[edges[:, 0]] & pinned[edges[:, 1]]].ravel()] = True
    free &= ~pinned | stiff
    best, best_error = X, np.abs(errors).max()
    for _ in range(5):  # grow the free set by one ring of neighbours if needed
        weight = np.where(stiff[free], 0.05, 1.0)
        X_try = _gauss_newton(X, edges, target, free, tol, weight)
        worst = np.abs(_length_errors(pattern, X_try)).max()
        if worst < best_error:
            best, best_error = X_try, worst
        if best_error <= tol:
            break
        touching = free[edges[:, 0]] | free[edges[:, 1]]
        grown = free.copy()
        grown[edges[touching].ravel()] = True
        if release:  # base vertices of creases still wrong may move too (reluctantly)
            still = np.abs(_length_errors(pattern, best)) > tol
            stiff[edges[still].ravel()] |= pinned[edges[still].ravel()]
        grown &= ~pinned | stiff
        if grown.sum() == free.sum():
            break
        free = grown
    return best, np.flatnonzero(np.abs(best - X).max(axis=1) > 0.0)


def _gauss_newton(X, edges, target, free, tol, weight=None, iterations: int = 100):
    """Levenberg-Marquardt on the crease lengths, moving only the ``free`` vertices.

    The system is underdetermined (faces are not triangulated), so each step is the minimum
    norm damped step dx = -J^T (J J^T + mu I)^-1 f; a step is kept only if it lowers the sum of
    squared length errors.
    """
    X = X.copy()
    idx = np.flatnonzero(free)
    if idx.size == 0:
        return X
    column = np.full(X.shape[0], -1)
    column[idx] = np.arange(idx.size)
    w = np.ones(3 * idx.size) if weight is None else np.repeat(weight, 3)
    use = free[edges[:, 0]] | free[edges[:, 1]]
    e = edges[use]
    L = target[use]
    rows = np.arange(e.shape[0])

    def residual(Y):
        d = Y[e[:, 1]] - Y[e[:, 0]]
        length = np.linalg.norm(d, axis=1)
        return d, length, length - L

    d, length, f = residual(X)
    cost = float(f @ f)
    scale = float(np.mean(L * L)) if L.size else 1.0
    mu = 1e-12 * scale
    for _ in range(iterations):
        if np.abs(f).max() <= tol:
            break
        unit_d = d / np.maximum(length, 1e-300)[:, None]
        J = np.zeros((e.shape[0], 3 * idx.size))
        for end, sign in ((0, -1.0), (1, 1.0)):
            c = column[e[:, end]]
            ok = c >= 0
            for k in range(3):
                J[rows[ok], 3 * c[ok] + k] = sign * unit_d[ok, k]
        J *= w[None, :]
        JJ = J @ J.T
        improved = False
        for _ in range(40):
            A = JJ + mu * np.eye(JJ.shape[0])
            try:
                step = -J.T @ np.linalg.solve(A, f)
            except np.linalg.LinAlgError:
                step = -J.T @ np.linalg.lstsq(A, f, rcond=None)[0]
            Y = X.copy()
            Y[idx] += (w * step).reshape(-1, 3)
            d_new, length_new, f_new = residual(Y)
            new_cost = float(f_new @ f_new)
            if new_cost < cost:
                X, d, length, f, cost = Y, d_new, length_new, f_new, new_cost
                mu = max(mu / 10.0, 1e-15 * scale)
                improved = True
                break
            mu *= 10.0
        if not improved:
            break
    return X


# ------------------------------------------------------------------------------------------------
# One module folded (each kind's fold lives in its own file, see kinegami.pattern.catalog)


@dataclass(frozen=True, eq=False)
class _ModuleFold:
    """A catalog module folded at state 0, in its proximal frame (e_u, e_v, e_a).

    ``exact`` is the module without the eps rules (its catalog entry's ``unsnapped``) and
    ``X_exact`` its exact, piecewise isometric fold; ``corr[j]`` is the vertex of ``exact`` that
    vertex j of the catalog module stands for. ``X`` is the catalog module's fold:
    ``X_exact[corr]``, put back on an isometry of its creases where the catalog moved vertices
    (``repaired``, local indices).
    """

    catalog: TubularPattern
    exact: TubularPattern
    X_exact: np.ndarray
    T: np.ndarray
    corr: np.ndarray
    X: np.ndarray
    repaired: np.ndarray


@functools.lru_cache(maxsize=512)
def _exact_fold(n: int, r: float, kind: str, params: tuple) -> tuple:
    """(catalog, exact, X_exact, T, corr) of a record (cached): the fields of
    :class:`_ModuleFold` that need no isometry repair (all the unsnapped form uses)."""
    prism = make_prism(n, r)
    catalog = _rebuild_cached(n, r, kind, params)
    entry = module_kind(kind)
    p = dict(params)
    exact, corr = entry.unsnapped(prism, catalog, p)
    X, T = entry.fold(prism, exact, p)
    for a in (X, T, corr):
        a.flags.writeable = False
    return catalog, exact, X, T, corr


@functools.lru_cache(maxsize=512)
def _module_fold(n: int, r: float, kind: str, params: tuple) -> _ModuleFold:
    """The folded module of a record (cached): see :class:`_ModuleFold`."""
    catalog, exact, X, T, corr = _exact_fold(n, r, kind, params)
    pinned = np.zeros(catalog.numVertices, dtype=bool)
    for base in (catalog.proximalBase, catalog.distalBase):
        if base is not None:
            pinned[base] = True
    X_catalog, repaired = _repair_isometry(catalog, X[corr], pinned, release=False)
    for a in (X_catalog, repaired):
        a.flags.writeable = False
    return _ModuleFold(catalog, exact, X, T, corr, X_catalog, repaired)


def _module_geometry(n: int, r: float, kind: str, params: tuple):
    """(X, T, repaired): the catalog module's local vertex positions, its proximal-to-distal
    transform and the local indices of the vertices moved by the isometry repair."""
    fold = _module_fold(n, r, kind, params)
    return fold.X, fold.T, fold.repaired
