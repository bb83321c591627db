"""The folded form: 3D positions of every vertex of a crease pattern at joint state 0.

A :class:`~kinegami.pattern.TubularPattern` made of catalog modules remembers which modules it
is made of (``pattern.modules``). :func:`folded_form` rebuilds every module from its record,
replays the composition of spec/patterns.md section 2.2 to learn which global vertex each module
vertex became, folds every module in its own proximal frame (section 3 and docs/fold.md) and
chains the module transforms, so the result is an isometric 3D realisation of the whole pattern.

Frames. Inside a module, positions are computed in its proximal frame (e_u, e_v, e_a) of spec
section 1.3. In world coordinates a module's end is described by its Dubins frame (x = e_a, the
path direction; y = e_u, the reference point; z = e_v), the convention of the chain code
(``joint.proximal_dubins_frame()``). For a chain, the first module's proximal Dubins frame is the
first joint's proximal Dubins frame, so the folded form lies on the chain's 3D model at state 0:
every module end coincides with the chain's joint and link frames. Two exceptions follow the
pattern rather than the kinematic model, because the pattern cannot fold otherwise:

* a prismatic joint's pattern folds to length d' + L instead of the kinematic d: the sleeve adds
  L = d / sin(coneAngle) (spec B7) and the bellows, folded with rigid faces, is
  d' = :func:`rebo_folded_length` >= d long; everything after a prismatic joint is translated by
  d' + L - d along its axis;
* turns and twists of at most 0.01 rad that the link builder leaves out of the pattern, and tubes
  shorter than eps = 1e-4 b, are missing from the folded form too (patterns.md 4.2).

Where the spec gives no positions (the REBO bellows, the nested sink layers of the revolute
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
import math
from dataclasses import dataclass

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.pattern._prism import Prism, make_prism, periodic_dx, wrap_x
from kinegami.pattern.elbow import elbow_geometry
from kinegami.pattern.prismatic import rebo_geometry
from kinegami.pattern.revolute import revolute_geometry
from kinegami.pattern.sheet import TOLERANCE_FACTOR
from kinegami.pattern.tubular import ModuleRecord, TubularPattern
from kinegami.pattern.twist import twist_geometry
from kinegami.validation import check_in_range, check_num_sides, check_positive

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
    "UVA_TO_DUBINS",
]

#: Q such that a frame's Dubins form is ``G @ Q.T`` when ``G`` has the columns (e_u, e_v, e_a):
#: (x_D, y_D, z_D) = (e_a, e_u, e_v) (spec section 1.3).
UVA_TO_DUBINS = np.array(
    [[0.0, 0.0, 1.0, 0.0], [1.0, 0.0, 0.0, 0.0], [0.0, 1.0, 0.0, 0.0], [0.0, 0.0, 0.0, 1.0]]
)

#: Crease length errors above this many r trigger the Gauss-Newton repair.
REPAIR_TOLERANCE = 1e-10

#: Points of an unsnapped module closer than this many r are one vertex: they coincide to the
#: tolerance of the flat sheet (kinegami.pattern.sheet.TOLERANCE_FACTOR), below which the sheet's
#: planar graph cannot tell points apart.
MERGE_TOLERANCE = TOLERANCE_FACTOR


class FoldedFormError(InvalidParameterError):
    """A pattern cannot be folded (no module records, or records that do not rebuild it)."""


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
    its tuck offset; points snapped onto the seam, spec 2.1: less than eps); no folded form of those
    vertices keeps every crease length. The unsnapped pattern puts every vertex where the module
    formulas put it (a few more vertices and short creases where B6 merged points), so its fold is
    piecewise isometric: every face is a planar rigid copy of its flat polygon.

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
    pattern, base = _resolve_input(pattern_or_chain, twistPortion)
    if frame is not None:
        base = _frame_array(frame)
    G0 = base @ UVA_TO_DUBINS
    return _fold(pattern, G0)


def unsnapped_form(pattern_or_chain, frame=None, twistPortion: float = 0.2) -> UnsnappedForm:
    """The unsnapped geometry of a pattern or chain and its exact folded form.

    Takes the arguments of :func:`folded_vertices`. Every module is rebuilt from its record
    without the catalog's eps rules (see :class:`UnsnappedForm`) and the modules are composed as
    in spec 2.2 but with x reduced modulo W only. The FOLD exporter writes this sheet.

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
    pattern, base = _resolve_input(pattern_or_chain, twistPortion)
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
        raise InvalidParameterError(f"frame must be a proper rigid transform, got\n{T}")
    return T


def _resolve_input(obj, twistPortion) -> tuple[TubularPattern, np.ndarray]:
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
# Composition replay (spec section 2.2) and assembly


@dataclass(frozen=True, eq=False)
class _Placement:
    """Where one catalog module went in the composite: global index of each local vertex and
    which of them it added (the others are its proximal base, shared with the module before)."""

    record: ModuleRecord
    mapping: np.ndarray
    is_new: np.ndarray


def _replay(pattern: TubularPattern) -> list[_Placement]:
    """Replay the composition of ``pattern.modules`` (spec 2.2) and check that it rebuilds the
    pattern's vertices; returns the placement of every module."""
    if not pattern.modules:
        raise FoldedFormError(
            "cannot fold a pattern without module records (kind 'custom'): only patterns made "
            "of catalog modules carry the information needed to fold them"
        )
    n, r = pattern.numSides, pattern.r
    prism = make_prism(n, r)
    W, eps = prism.W, prism.eps
    coords = np.full((pattern.numVertices, 2), np.nan)
    placements = []
    marker = np.array(pattern.proximalMarker, dtype=float)
    distal_idx = None
    distal_xy = None
    next_index = 0
    for m, record in enumerate(pattern.modules):
        local = _rebuild(n, r, record, m)
        offset = marker - local.proximalMarker
        xy = local.vertices_coords + offset
        xy[:, 0] = wrap_x(xy[:, 0], W, eps)
        mapping = np.empty(local.numVertices, dtype=np.intp)
        is_new = np.ones(local.numVertices, dtype=bool)
        if m > 0:
            if local.proximalBase is None or distal_idx is None:
                raise FoldedFormError(
                    f"module {m} ({record.kind}) cannot follow module {m - 1}: the records do "
                    "not describe a valid composition"
                )
            base = local.proximalBase
            j = _find_shift(distal_xy, xy[base], W, eps, m)
            mapping[base] = distal_idx[(np.arange(n) + j) % n]
            is_new[base] = False
        count = int(np.count_nonzero(is_new))
        mapping[is_new] = np.arange(next_index, next_index + count)
        next_index += count
        if next_index > pattern.numVertices:
            raise _mismatch(m, record, "more vertices than the pattern has")
        coords[mapping[is_new]] = xy[is_new]
        placements.append(_Placement(record, mapping, is_new))
        marker = local.distalMarker + offset
        marker[0] = wrap_x(marker[0:1], W, eps)[0]
        if local.distalBase is None:
            distal_idx = distal_xy = None
        else:
            distal_idx = mapping[local.distalBase]
            distal_xy = xy[local.distalBase]
    if next_index != pattern.numVertices or np.isnan(coords).any():
        raise _mismatch(len(pattern.modules) - 1, pattern.modules[-1], "vertex count differs")
    dx = periodic_dx(coords[:, 0] - pattern.vertices_coords[:, 0], W)
    dy = coords[:, 1] - pattern.vertices_coords[:, 1]
    if np.abs(dx).max(initial=0.0) > 2 * eps or np.abs(dy).max(initial=0.0) > 2 * eps:
        raise FoldedFormError(
            "the pattern's module records do not rebuild its vertices (largest difference "
            f"{max(np.abs(dx).max(), np.abs(dy).max()):.3g}); was it reversed or edited by hand?"
        )
    return placements


def _fold(pattern: TubularPattern, G0: np.ndarray) -> FoldedForm:
    placements = _replay(pattern)
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
            FoldedModule(record, _readonly(mapping.copy()), proximal, G @ UVA_TO_DUBINS.T)
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

    The composition is that of spec 2.2 without the eps rules: x is reduced modulo W only (no
    snapping onto the seam, also for the markers), and every module is placed with the exact
    marker. Vertex i < N of the result is vertex i of ``pattern`` (the correspondence comes
    from the replay of the catalog composition); the vertices that only the unsnapped modules
    have follow, numbered in module order.
    """
    placements = _replay(pattern)
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
        fold = _module_fold(n, r, record.kind, _freeze(record.params))
        exact = fold.exact
        offset = marker - exact.proximalMarker
        xy = exact.vertices_coords + offset
        xy[:, 0] = _mod_w(xy[:, 0], W)
        world = (G[:3, :3] @ fold.X_exact.T).T + G[:3, 3]
        emap = np.full(exact.numVertices, -1, dtype=np.intp)
        emap[fold.corr] = mapping
        extra = emap < 0
        count = int(np.count_nonzero(extra))
        emap[extra] = np.arange(next_extra, next_extra + count)
        next_extra += count
        new = extra.copy()
        new[fold.corr[is_new]] = True
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
        G = G @ fold.T
        modules.append(FoldedModule(record, _readonly(emap), proximal, G @ UVA_TO_DUBINS.T))
        marker = exact.distalMarker + offset
        marker[0] = _mod_w(marker[0:1], W)[0]
    if gap > 1e-9 * r:  # pragma: no cover - would be a bug in a module's unsnapped geometry
        raise FoldedFormError(f"unsnapped module ends do not meet (gap {gap:.3g})")
    coords = np.concatenate(coords)
    X = np.concatenate(X)
    edges = np.concatenate(edges)
    labels = np.concatenate(labels)
    # spec 2.2 step 5: a crease joining the same two vertices as an earlier one is dropped
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
    import kinegami.pattern as catalog

    p = dict(params)
    if kind == "tube":
        return catalog.TubeFittingPattern(n, r, p["height"])
    if kind == "twist":
        return catalog.TwistFittingPattern(n, r, p["twistAngle"], p["moduleHeight"])
    if kind == "elbow":
        return catalog.ElbowFittingPattern(n, r, p["bendingAngle"], p["rotationalAxisAngle"])
    if kind == "revolute":
        return catalog.RevoluteJointPattern(n, r, p["totalBendingAngle"], p["numSinkLayers"])
    if kind == "prismatic":
        return catalog.PrismaticJointPattern(
            n, r, p["neutralLength"], p["numLayers"], p["coneAngle"]
        )
    if kind == "rebo":
        return catalog.REBOPattern(
            n, r, p["neutralLength"], p["numLayers"], p["coneAngle"], p["proximalValleys"]
        )
    if kind == "end_tip":
        return catalog.EndTipPattern(n, r, p["length"])
    if kind == "start_tip":
        return catalog.StartTipPattern(n, r, p["length"])
    if kind == "waypoint":
        return catalog.WaypointPattern(n, r)
    raise KeyError(f"unknown module kind {kind!r}")


def _find_shift(target: np.ndarray, base_xy: np.ndarray, W: float, eps: float, m: int) -> int:
    n = target.shape[0]
    for j in range(n):
        rolled = target[(np.arange(n) + j) % n] - base_xy
        if (np.abs(periodic_dx(rolled[:, 0], W)) < eps).all() and (
            np.abs(rolled[:, 1]) < eps
        ).all():
            return j
    raise FoldedFormError(
        f"module {m}'s proximal base does not meet the previous distal base in the replayed "
        "composition; the pattern's module records do not rebuild it"
    )


def _readonly(a: np.ndarray) -> np.ndarray:
    a.flags.writeable = False
    return a


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
# Module geometry (spec section 3 and docs/fold.md); positions in (e_u, e_v, e_a) coordinates


def _translation(a: float) -> np.ndarray:
    T = np.eye(4)
    T[2, 3] = a
    return T


def _rot_axis(axis, angle: float) -> np.ndarray:
    k = np.asarray(axis, dtype=float)
    k = k / np.linalg.norm(k)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * (K @ K)


def _polygon_point(prism: Prism, x: np.ndarray) -> np.ndarray:
    """c(x) of spec 1.3: the point at arc length x on the polygon (a = 0), shape (m, 3)."""
    x = np.asarray(x, dtype=float)
    n, b, a = prism.numSides, prism.b, prism.a
    m = np.round(x / b)
    sigma = m * (2.0 * math.pi / n)
    t = x - m * b
    out = np.zeros(x.shape + (3,))
    out[..., 0] = a * np.cos(sigma) - t * np.sin(sigma)
    out[..., 1] = a * np.sin(sigma) + t * np.cos(sigma)
    return out


def _corners(prism: Prism, angle_offset: float = 0.0) -> np.ndarray:
    beta = prism.vertex_angles + angle_offset
    return prism.r * np.stack([np.cos(beta), np.sin(beta), np.zeros_like(beta)], axis=1)


def _mod_w(x: np.ndarray, W: float) -> np.ndarray:
    """x reduced into [0, W) without snapping (spec 2.1 less its eps rule)."""
    x = np.mod(x, W)
    return np.where(x >= W, 0.0, x)


@dataclass(frozen=True, eq=False)
class _ModuleFold:
    """A catalog module folded at state 0, in its proximal frame (e_u, e_v, e_a).

    ``exact`` is the module without the eps rules (:func:`_exact_module`) and ``X_exact`` its
    exact, piecewise isometric fold; ``corr[j]`` is the vertex of ``exact`` that vertex j of the
    catalog module stands for. ``X`` is the catalog module's fold: ``X_exact[corr]``, put back on
    an isometry of its creases where the catalog moved vertices (``repaired``, local indices).
    """

    catalog: TubularPattern
    exact: TubularPattern
    X_exact: np.ndarray
    T: np.ndarray
    corr: np.ndarray
    X: np.ndarray
    repaired: np.ndarray


@functools.lru_cache(maxsize=512)
def _module_fold(n: int, r: float, kind: str, params: tuple) -> _ModuleFold:
    """The folded module of a record (cached): see :class:`_ModuleFold`."""
    prism = make_prism(n, r)
    catalog = _rebuild_cached(n, r, kind, params)
    p = dict(params)
    exact, corr = _exact_module(prism, catalog, kind, p)
    xy = exact.vertices_coords
    if kind in ("tube", "waypoint"):
        X = _polygon_point(prism, xy[:, 0])
        X[:, 2] = xy[:, 1]
        T = _translation(exact.height)
    elif kind == "twist":
        X, T = _fold_twist(prism, exact, p["twistAngle"], p["moduleHeight"])
    elif kind == "elbow":
        X, T = _fold_elbow(prism, exact, p["bendingAngle"], p["rotationalAxisAngle"])
    elif kind == "revolute":
        h_r = prism.a * math.tan(p["totalBendingAngle"] / 4.0)
        X = _fold_revolute(prism, exact, h_r, with_distal=True)
        T = _translation(2.0 * h_r)
    elif kind == "end_tip":
        X = _fold_revolute(prism, exact, p["length"], with_distal=False)
        T = _translation(p["length"])
    elif kind == "start_tip":
        ell = p["length"]
        mirrored = xy.copy()
        mirrored[:, 1] = exact.height - xy[:, 1]
        X = _fold_revolute(prism, exact, ell, with_distal=False, xy=mirrored)
        X[:, 2] = ell - X[:, 2]
        T = _translation(ell)
    elif kind == "rebo":
        X = _fold_rebo_vertices(prism, xy, p["neutralLength"], p["numLayers"], p["coneAngle"])
        T = _translation(rebo_folded_length(n, p["neutralLength"], p["coneAngle"]))
    elif kind == "prismatic":
        X, T = _fold_prismatic(prism, exact, p["neutralLength"], p["numLayers"], p["coneAngle"])
    else:  # pragma: no cover - _rebuild_cached rejects unknown kinds first
        raise KeyError(kind)
    pinned = np.zeros(catalog.numVertices, dtype=bool)
    for base in (catalog.proximalBase, catalog.distalBase):
        if base is not None:
            pinned[base] = True
    X_catalog, repaired = _repair_isometry(catalog, X[corr], pinned, release=False)
    for a in (X, T, corr, X_catalog, repaired):
        a.flags.writeable = False
    return _ModuleFold(catalog, exact, X, T, corr, X_catalog, repaired)


def _module_geometry(n: int, r: float, kind: str, params: tuple):
    """(X, T, repaired): the catalog module's local vertex positions, its proximal-to-distal
    transform and the local indices of the vertices moved by the isometry repair."""
    fold = _module_fold(n, r, kind, params)
    return fold.X, fold.T, fold.repaired


def _exact_module(prism: Prism, catalog: TubularPattern, kind: str, p: dict):
    """The module without the eps rules, and the vertex of it each catalog vertex stands for.

    The catalog moves some points a little: it snaps points within eps = 1e-4 b of the seam
    onto it (section 2.1; inside a module: a twist's distal base and marker, a REBO's pleat
    offset points, an elbow's offset points) and, in an elbow, merges the tuck vertices of
    columns with h_k < eps with P_k and D_k and collapses columns close to the midline into one
    vertex (fix B6). The unsnapped module keeps those points where the module's formulas put
    them, so that its exact fold is an isometry; only vertices closer than
    ``MERGE_TOLERANCE`` r are one vertex. Every other module is its catalog module.
    """
    identity = np.arange(catalog.numVertices)
    W, b = prism.W, prism.b
    xy = catalog.vertices_coords.copy()
    distal_marker = catalog.distalMarker.copy()
    if kind == "elbow":
        exact = _exact_elbow(prism, p["bendingAngle"], p["rotationalAxisAngle"], catalog.modules)
        return exact, _match_vertices(catalog.vertices_coords, exact.vertices_coords, prism)
    if kind == "twist":
        geo = twist_geometry(prism, p["twistAngle"], p["moduleHeight"])
        if geo.degenerate:
            return catalog, identity
        xy[catalog.distalBase, 0] = _mod_w(prism.columns + geo.shift, W)
        distal_marker[0] = _mod_w(np.array([geo.K * b + geo.shift]), W)[0]
    elif kind in ("rebo", "prismatic"):
        geo = rebo_geometry(prism, p["neutralLength"], p["numLayers"], p["coneAngle"])
        # the only points of these modules that can be snapped: the pleat offsets of column 0
        snapped = xy[:, 0] == 0.0
        if not snapped.any():
            return catalog, identity
        xy[snapped, 0] = _mod_w(prism.columns[:1] - geo.offset, W)[0]
    else:
        return catalog, identity
    exact = TubularPattern._build(
        prism.numSides, prism.r, xy, catalog.edges_vertices.copy(),
        catalog.edges_assignment.copy(), catalog.proximalBase.copy(), catalog.distalBase.copy(),
        catalog.proximalMarker.copy(), distal_marker, catalog.height, catalog.modules,
    )  # fmt: skip
    return exact, identity


def _exact_elbow(prism: Prism, theta: float, phi: float, records) -> TubularPattern:
    """The elbow of spec 3.3 with four tuck vertices L, M, O, U on every column (no eps rules).

    Vertices closer than ``MERGE_TOLERANCE`` r are merged (exactly collapsed columns, h_k = 0),
    the creases between merged vertices dropped and repeated creases kept once, the first in
    the spec's order (so two adjacent collapsed columns share one M crease, as in step 5).
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
    xy[Of] = np.stack([_mod_w(x + (H_m - h) * np.tan(geo.tuck), W), np.full(n, H_m)], axis=1)
    xy[U] = np.stack([x, H - h], axis=1)
    prev, nxt = (k - 1) % n, (k + 1) % n
    table = [  # spec 3.3 step 3, in the catalog's order
        (L[prev], L, "M"), (P, L, "M"), (U[prev], U, "M"), (U, D, "M"), (M, Of, "V"),
        (Of, M[nxt], "V"), (L, M, "V"), (M, U, "M"), (L, Of, "M"), (U, Of, "V"),
    ]  # fmt: skip
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


def _match_vertices(catalog_xy: np.ndarray, exact_xy: np.ndarray, prism: Prism) -> np.ndarray:
    """For every catalog vertex, the nearest unsnapped vertex (periodic in x): the same point
    (a collapsed column's Q_k is M_k), or less than eps away for a point snapped onto the
    seam."""
    dx = periodic_dx(catalog_xy[:, None, 0] - exact_xy[None, :, 0], prism.W)
    dist = np.hypot(dx, catalog_xy[:, None, 1] - exact_xy[None, :, 1])
    nearest = np.argmin(dist, axis=1)
    worst = dist[np.arange(catalog_xy.shape[0]), nearest].max(initial=0.0)
    if worst > 3.0 * prism.eps or np.unique(nearest).size != nearest.size:
        raise FoldedFormError(  # pragma: no cover - a catalog module changed its vertices
            f"the catalog module's vertices do not match its unsnapped geometry ({worst:.3g})"
        )
    return nearest


def _assign(
    xy: np.ndarray, named_xy: np.ndarray, named_X: np.ndarray, W: float, tol: float
) -> tuple[np.ndarray, np.ndarray]:
    """Give each vertex the 3D position of the nearest named flat point (periodic in x).

    Returns (X, matched): vertices farther than ``tol`` from every named point are unmatched
    (their rows of X are NaN).
    """
    dx = periodic_dx(xy[:, None, 0] - named_xy[None, :, 0], W)
    dy = xy[:, None, 1] - named_xy[None, :, 1]
    dist = np.hypot(dx, dy)
    nearest = np.argmin(dist, axis=1)
    matched = dist[np.arange(xy.shape[0]), nearest] <= tol
    X = np.full((xy.shape[0], 3), np.nan)
    X[matched] = named_X[nearest[matched]]
    return X, matched


def _require_all(matched: np.ndarray, kind: str) -> None:
    if not matched.all():  # pragma: no cover - a catalog module changed its vertices
        raise FoldedFormError(
            f"{int((~matched).sum())} vertices of a {kind} module have no known 3D position"
        )


# --- twist (spec 3.2) ----------------------------------------------------------------------


def _fold_twist(prism: Prism, pattern: TubularPattern, alpha: float, h: float):
    geo = twist_geometry(prism, alpha, h)
    n = prism.numSides
    p = _corners(prism)
    xy = pattern.vertices_coords
    R = np.eye(4)
    if geo.degenerate:
        columns = round(n * ((alpha % (2.0 * math.pi)) / (2.0 * math.pi))) % n
        R[:3, :3] = _rot_axis((0.0, 0.0, 1.0), columns * 2.0 * math.pi / n)
        X = _polygon_point(prism, xy[:, 0])
        return X, R
    X = np.empty((pattern.numVertices, 3))
    X[pattern.proximalBase] = p
    X[pattern.distalBase] = _corners(prism, geo.residual) + np.array([0.0, 0.0, h])
    R[:3, :3] = _rot_axis((0.0, 0.0, 1.0), alpha)
    R[2, 3] = h
    return X, R


# --- elbow (spec 3.3) ----------------------------------------------------------------------


def _fold_elbow(prism: Prism, pattern: TubularPattern, theta: float, phi: float):
    geo = elbow_geometry(prism, theta, phi)
    n, r, b = prism.numSides, prism.r, prism.b
    theta, phi = geo.bendingAngle, geo.rotationalAxisAngle
    h, H_m = geo.h, geo.H_m
    H = 2.0 * H_m
    x = prism.columns
    g = np.array([math.cos(phi), math.sin(phi), 0.0])
    w = np.cross(g, (0.0, 0.0, 1.0))
    R = _rot_axis(g, theta)
    shift = r * w - R @ (r * w)
    n_pi = _rot_axis(g, theta / 2.0) @ np.array([0.0, 0.0, 1.0])
    p = _corners(prism)
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
    X, matched = _assign(pattern.vertices_coords, named_xy, named_X, prism.W, MERGE_TOLERANCE * r)
    _require_all(matched, "elbow")
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = shift
    return X, T


# --- revolute joint and tips (spec 3.4-3.6) ------------------------------------------------


def _fold_revolute(
    prism: Prism,
    pattern: TubularPattern,
    h_r: float,
    with_distal: bool,
    xy: np.ndarray | None = None,
) -> np.ndarray:
    """Revolute joint at state 0 (or the end tip when ``with_distal`` is False).

    Named points of spec 3.4; the crimp flap vertex M_k of a crimped column lies in the plane of
    its lower fin (docs/fold.md); the nested sink vertices (N >= 2) lie on the N = 1 creases they
    subdivide, at the same fraction of the way to the panel centre.
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
    p = _corners(prism)
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
    X, matched = _assign(xy, named_xy, named_X, prism.W, 1e-9 * r)
    if not matched.all():
        X = _fold_sink_chains(prism, xy, X, matched, centre, H)
    return X


def _fold_sink_chains(prism, xy, X, matched, centre, H):
    """Nested sink vertices: on the segment from an outer point of their panel to its centre.

    Every chain of spec 3.5 runs along an N = 1 crease from an outer point Y of the panel
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


# --- REBO (spec 3.7) and prismatic joint (3.8) ---------------------------------------------


def rebo_tilt(numSides: int, coneAngle: float) -> float:
    """Inclination gamma of the REBO's faces in its rigid folded state, radians.

    Every layer folds as a rigid bellows (docs/fold.md): each quadrilateral face turns about its
    layer-ring edge, inwards, until it makes the angle gamma with the cross-section plane, and
    the pleat triangles close exactly when l1 cos(gamma) = o cot(pi/n), i.e.

        cos(gamma) = cot(alpha_f) cot(pi/n) = tan(pi cos(beta) / n) / tan(pi / n),

    with alpha_f = (pi/2)(1 - 2 cos(beta)/n) the flat cone angle of spec 3.7. Then beta <= gamma
    < pi/2, and gamma -> beta as n grows. (The other rigid state, gamma = pi/2, is the unfolded
    tube.)

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
    ring = _corners(prism)
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
    offset_x = _mod_w(x - o, prism.W)
    for i in range(N):
        mid_y = np.full(n, (2.0 * i + 1.0) * l1)
        rise = np.array([0.0, 0.0, i * layer])
        names_xy += [np.stack([x, mid_y], axis=1), np.stack([offset_x, mid_y], axis=1)]
        names_X += [mid + rise, offset_mid + rise]
    X, matched = _assign(
        xy, np.concatenate(names_xy), np.concatenate(names_X), prism.W, 1e-9 * prism.r
    )
    _require_all(matched, "REBO")
    return X


def _fold_prismatic(prism: Prism, pattern: TubularPattern, d: float, N: int, beta: float):
    """Sleeve, lining folded back inside it, REBO, piston (spec 3.8 folded reading, B7).

    The bellows is in its rigid folded state, of length d' = :func:`rebo_folded_length`, so the
    joint folds to d' + L.
    """
    geo = rebo_geometry(prism, d, N, beta)
    L = geo.height
    xy = pattern.vertices_coords
    y = xy[:, 1]
    X = _polygon_point(prism, xy[:, 0])
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
    return X, _translation(length + L)
