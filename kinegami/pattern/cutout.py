"""Sheets with cut-outs: the sheets of a tree joined by folded take-off junctions.

A take-off junction (:mod:`kinegami.pattern.takeoff`, docs/theory/takeoff.md) joins two sheets:
the trunk's sheet gets a hole in one of its plain tube modules, and the branch's sheet starts
with a skirt whose lower edge is the fish-mouth, with a glue tab hanging from every segment of
it. A :class:`CutPattern` is a :class:`~kinegami.pattern.TubularPattern` (the creases, the
modules, the folded form) together with those cut-outs:

* ``holes``: :class:`SheetHole` objects, each the hole of a take-off junction in one tube module
  of the pattern (its place in that module's own coordinates, so that the hole moves with the
  module wherever composition put it);
* ``skirt``: the take-off junction whose skirt is the pattern's first module (a
  :func:`~kinegami.pattern.takeoff.TakeoffSkirtPattern`), or None;
* ``frame``: the world Dubins frame of the pattern's proximal end, where its folded form starts
  (a tree's sheets fold in the tree's world frame), or None.

:func:`flatten_cut` (what :func:`kinegami.pattern.sheet.flatten` does with a CutPattern) draws
the sheet: the pattern's sheet with every line cut back to the paper that is left (no crease
inside a hole, none below the fish-mouth), the hole edges and the tabs' free edges as cuts, and
the fish-mouth as the nominal tube's lower boundary. The FOLD exporter builds the same sheet as
a planar graph (:func:`kinegami.pattern.sheet_graph.sheet_graph`).

Lengths are in the pattern's unit (that of r).
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.pattern._prism import make_prism
from kinegami.pattern.catalog import module_kind
from kinegami.pattern.sheet import (
    SHEET_DRAWERS,
    TOLERANCE_FACTOR,
    Sheet,
    clip_segments,
    flatten,
    unique_segments,
)
from kinegami.pattern.takeoff import SKIRT_KIND, TakeoffJunction
from kinegami.pattern.tubular import TubularPattern
from kinegami.validation import check_bool

__all__ = [
    "SheetHole",
    "CutPattern",
    "CutRegions",
    "flatten_cut",
    "SIDE_OFFSET_FACTOR",
]

#: Lines are classified by the paper on either side of them, tested this many r away.
SIDE_OFFSET_FACTOR = 1e-6


def _readonly(array: np.ndarray) -> np.ndarray:
    array = np.ascontiguousarray(array)
    array.flags.writeable = False
    return array


@dataclass(frozen=True, eq=False)
class SheetHole:
    """The hole of a take-off junction in one tube module of a sheet.

    Attributes
    ----------
    name : str
        How the drawings call it (e.g. ``"A"``): the branch sheet whose skirt is glued into it
        says the same name.
    module : int
        Index in ``pattern.modules`` of the plain tube module that holds it.
    junction : TakeoffJunction
        The take-off geometry, with its ``y0`` measured in that module's own coordinates (0 at
        the module's proximal end), and its face numbered from the module's reference point.
    """

    name: str
    module: int
    junction: TakeoffJunction


@dataclass(frozen=True, eq=False)
class CutRegions:
    """Where the paper of a cut sheet is, in sheet coordinates (x continuous over the strip).

    Built by :meth:`CutPattern.regions` for one placement of the pattern (the catalog pattern
    for the drawings, its unsnapped geometry for FOLD).

    Attributes
    ----------
    holes : tuple of ndarray (V, 2)
        Every hole polygon, and its copies shifted by -W and +W (a hole near the seam shows on
        both copies of the starting panel).
    fish_mouth : ndarray (V, 2) or None
        The fish-mouth vertices (x ascending in [0, W)), a closed periodic polyline; paper is
        above it (and in the tabs).
    tabs : tuple of ndarray (k, 2)
        Every glue tab polygon and its copies shifted by -W and +W; the first two corners are
        the hinge.
    tab_angles : ndarray
        The valley fold angle omega of each entry of ``tabs`` (radians; 0 for a flush tab).
    tab_hinged : ndarray of bool
        Whether each tab's hinge is a crease (False for a flush tab, which stays flat).
    mouth_hinged : ndarray of bool
        Whether each fish-mouth segment (vertices i, i + 1) is a hinge crease.
    bounds : tuple
        The pattern's sheet rectangle (xmin, ymin, xmax, ymax) = (-b/2, y0, W + b/2, y0 + H).
    width, tolerance : float
        W and the length tolerance (1e-9 r).
    """

    holes: tuple[np.ndarray, ...]
    fish_mouth: np.ndarray | None
    tabs: tuple[np.ndarray, ...]
    tab_angles: np.ndarray
    tab_hinged: np.ndarray
    mouth_hinged: np.ndarray
    bounds: tuple[float, float, float, float]
    width: float
    tolerance: float

    # --- point tests ---------------------------------------------------------------------

    def in_hole(self, points: np.ndarray) -> np.ndarray:
        """True for points strictly inside a hole (or its copies)."""
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        out = np.zeros(points.shape[0], dtype=bool)
        for poly in self.holes:
            out |= points_in_polygon(points, poly)
        return out

    def tab_index(self, points: np.ndarray) -> np.ndarray:
        """Index in :attr:`tabs` of the tab each point lies in, or -1."""
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        out = np.full(points.shape[0], -1, dtype=np.intp)
        for k, poly in enumerate(self.tabs):
            inside = points_in_polygon(points, poly) & (out < 0)
            out[inside] = k
        return out

    def mouth_height(self, x: np.ndarray) -> np.ndarray:
        """y of the fish-mouth at ``x`` (periodic in W); -inf everywhere without a skirt."""
        x = np.asarray(x, dtype=float)
        if self.fish_mouth is None:
            return np.full(x.shape, -np.inf)
        fm, W = self.fish_mouth, self.width
        xs = np.concatenate([fm[-1:, 0] - 2.0 * W, fm[:, 0] - W, fm[:, 0], fm[:, 0] + W,
                             fm[:1, 0] + 2.0 * W])  # fmt: skip
        ys = np.concatenate([fm[-1:, 1], fm[:, 1], fm[:, 1], fm[:, 1], fm[:1, 1]])
        return np.interp(np.mod(x + W, 3.0 * W) - W, xs, ys)

    def classify(self, points: np.ndarray) -> np.ndarray:
        """What lies at each point: ``"P"`` paper of the tube, ``"T"`` paper of a glue tab,
        ``"H"`` cut away (a hole, or below the fish-mouth outside the tabs), ``"O"`` outside the
        pattern's sheet (always beyond the strip -b/2 < x < W + b/2)."""
        points = np.asarray(points, dtype=float).reshape(-1, 2)
        xmin, ymin, xmax, ymax = self.bounds
        x, y = points[:, 0], points[:, 1]
        strip = (x > xmin) & (x < xmax)
        inside = strip & (y > ymin) & (y < ymax)
        out = np.where(inside, "P", "O").astype("<U1")
        out[inside & (y < self.mouth_height(x))] = "H"
        out[strip & self.in_hole(points)] = "H"
        out[strip & (self.tab_index(points) >= 0)] = "T"
        return out

    # --- the cut lines ---------------------------------------------------------------------

    def hole_segments(self) -> np.ndarray:
        """Every edge of every hole copy, shape (K, 2, 2) (unclipped)."""
        return _polygon_edges(self.holes)

    def tab_outline_segments(self) -> np.ndarray:
        """The free edges of every tab copy (all but the hinge), shape (K, 2, 2)."""
        pieces = []
        for poly in self.tabs:
            loop = np.concatenate([poly[:1], poly[:1:-1], poly[1:2]])  # p0, free edge, p1
            pieces.append(np.stack([loop[:-1], loop[1:]], axis=1))
        return np.concatenate(pieces) if pieces else np.zeros((0, 2, 2))

    def mouth_segments(self) -> tuple[np.ndarray, np.ndarray]:
        """The fish-mouth segments, copies at -W, 0, +W, shape (K, 2, 2), and whether each is a
        hinge crease (a valley; False for flush segments)."""
        if self.fish_mouth is None:
            return np.zeros((0, 2, 2)), np.zeros(0, dtype=bool)
        fm, W = self.fish_mouth, self.width
        end = np.roll(fm, -1, axis=0).copy()
        end[-1, 0] += W
        base = np.stack([fm, end], axis=1)
        return (np.concatenate([base + [k * W, 0.0] for k in (-1.0, 0.0, 1.0)]),
                np.concatenate([self.mouth_hinged] * 3))  # fmt: skip

    def boundary_segments(self) -> np.ndarray:
        """Every line where paper may change: hole edges, fish-mouth segments and tab outlines
        (what the sheet's lines are split at)."""
        return np.concatenate(
            [self.hole_segments(), self.mouth_segments()[0], self.tab_outline_segments()]
        )


@dataclass(frozen=True, eq=False)
class CutPattern:
    """A tubular crease pattern with the cut-outs of folded take-off junctions.

    Parameters
    ----------
    pattern : TubularPattern
        The crease pattern (made of catalog modules).
    holes : sequence of SheetHole, optional
        Holes in its plain tube modules; each must fit in its module (the hole and its margin,
        :attr:`~kinegami.pattern.takeoff.TakeoffJunction.trunk_span`, within the module's
        height).
    skirt : TakeoffJunction, optional
        The take-off junction whose skirt the pattern starts with: then ``pattern.modules[0]``
        must be that junction's ``TakeoffSkirtPattern``.
    skirt_name : str, optional
        The name of the hole the skirt is glued into (for the drawings' labels).
    frame : array_like (4, 4), optional
        World Dubins frame of the pattern's proximal end (x = path direction, y = e_u), where
        its folded form starts; the FOLD file is written in that frame. Default: the folded
        form's default frame.

    Examples
    --------
    >>> from kinegami.pattern import TubeFittingPattern
    >>> from kinegami.pattern.takeoff import takeoff_junction
    >>> tube = TubeFittingPattern(6, 1.0, 4.0)
    >>> cut = CutPattern(tube, holes=[SheetHole("A", 0, takeoff_junction(6, 1.0, 0, 2.0))])
    >>> sheet = flatten_cut(cut)
    >>> sheet.count("C") > 4
    True
    """

    pattern: TubularPattern
    holes: tuple[SheetHole, ...] = ()
    skirt: TakeoffJunction | None = None
    skirt_name: str | None = None
    frame: np.ndarray | None = field(default=None, repr=False)

    def __post_init__(self) -> None:
        pattern = self.pattern
        if not isinstance(pattern, TubularPattern):
            raise InvalidTypeError(
                f"pattern must be a TubularPattern, got {type(pattern).__name__}"
            )
        holes = tuple(self.holes)
        for k, hole in enumerate(holes):
            if not isinstance(hole, SheetHole):
                raise InvalidTypeError(f"holes[{k}] must be a SheetHole, got {type(hole).__name__}")
            self._check_junction(f"holes[{k}].junction", hole.junction)
            m = hole.module
            if (
                isinstance(m, bool)
                or not isinstance(m, int | np.integer)
                or not (0 <= m < len(pattern.modules))
            ):
                raise InvalidParameterError(
                    f"holes[{k}].module must be a module index in [0, {len(pattern.modules) - 1}]"
                    f", got {m!r}"
                )
            record = pattern.modules[m]
            if record.kind != "tube":
                raise InvalidParameterError(
                    f"holes[{k}].module: module {m} is a {record.kind!r} module; a hole goes in "
                    "a plain tube module"
                )
            low, high = hole.junction.trunk_span
            height = float(record.params["height"])
            tol = TOLERANCE_FACTOR * pattern.r
            if low < -tol or high > height + tol:
                raise InvalidParameterError(
                    f"holes[{k}]: the hole and its margin need y in [{low:.6g}, {high:.6g}] of "
                    f"module {m}, a tube of height {height:.6g}"
                )
        object.__setattr__(self, "holes", holes)
        if self.skirt is not None:
            self._check_junction("skirt", self.skirt)
            first = pattern.modules[0] if pattern.modules else None
            if (first is None or first.kind != SKIRT_KIND.name
                    or abs(first.params["stubLength"] - self.skirt.stub_length)
                    > TOLERANCE_FACTOR * pattern.r):  # fmt: skip
                raise InvalidParameterError(
                    "skirt: the pattern must start with the junction's skirt "
                    f"(TakeoffSkirtPattern with stubLength {self.skirt.stub_length:g}), got "
                    f"{first.kind if first is not None else 'no module'!r} first"
                )
        if self.skirt_name is not None and not isinstance(self.skirt_name, str):
            raise InvalidTypeError(f"skirt_name must be a string, got {self.skirt_name!r}")
        if self.frame is not None:
            F = np.array(getattr(self.frame, "A", self.frame), dtype=float)
            if F.shape != (4, 4) or not np.all(np.isfinite(F)):
                raise InvalidParameterError(f"frame must be a finite 4x4 transform, got {F!r}")
            object.__setattr__(self, "frame", _readonly(F))

    def _check_junction(self, name: str, junction) -> None:
        if not isinstance(junction, TakeoffJunction):
            raise InvalidTypeError(
                f"{name} must be a TakeoffJunction, got {type(junction).__name__}"
            )
        if junction.numSides != self.pattern.numSides or junction.r != self.pattern.r:
            raise InvalidParameterError(
                f"{name} is for n = {junction.numSides}, r = {junction.r:g}; the pattern has "
                f"n = {self.pattern.numSides}, r = {self.pattern.r:g}"
            )

    # --- what it shares with its pattern -----------------------------------------------------

    @property
    def numSides(self) -> int:
        return self.pattern.numSides

    @property
    def r(self) -> float:
        return self.pattern.r

    @property
    def width(self) -> float:
        return self.pattern.width

    @property
    def sideLength(self) -> float:
        return self.pattern.sideLength

    @property
    def height(self) -> float:
        """Height of the pattern (the tabs hang below it, see :func:`flatten_cut`)."""
        return self.pattern.height

    @property
    def modules(self):
        return self.pattern.modules

    def __repr__(self) -> str:
        holes = ", ".join(h.name for h in self.holes) or "none"
        skirt = "none" if self.skirt is None else f"face {self.skirt.face}"
        return f"CutPattern({self.pattern!r}, holes: {holes}, skirt: {skirt})"

    # --- geometry ----------------------------------------------------------------------------

    def hole_offset(self, hole: SheetHole, vertices_coords=None, mapping=None) -> np.ndarray:
        """Where the hole's module sits in the sheet: (dx, dy) from the module's own
        coordinates to the sheet's (dx in [0, W)).

        By default from this pattern's vertices; ``vertices_coords`` and ``mapping`` (the sheet
        vertex of each of the module's own vertices) give another placement of it, e.g. the
        unsnapped geometry the FOLD file is drawn from.
        """
        if vertices_coords is None:
            vertices_coords = self.pattern.vertices_coords
            mapping = self.pattern.module_vertices[hole.module]
        record = self.pattern.modules[hole.module]
        local = module_kind(record.kind).rebuild(self.numSides, self.r, record.params)
        d = np.asarray(vertices_coords)[mapping[0]] - local.vertices_coords[0]
        return np.array([np.mod(d[0], self.width), d[1]])

    def regions(self, vertices_coords=None, mappings=None) -> CutRegions:
        """The paper of the sheet (:class:`CutRegions`), for this pattern's placement or for
        the one given (``mappings``: one vertex mapping per hole, as in :meth:`hole_offset`)."""
        prism = make_prism(self.numSides, self.r)
        W, b = prism.W, prism.b
        holes = []
        for k, hole in enumerate(self.holes):
            if vertices_coords is None:
                offset = self.hole_offset(hole)
            else:
                offset = self.hole_offset(hole, vertices_coords, mappings[k])
            poly = hole.junction.hole_unwrapped + offset
            poly[:, 0] -= W * math.floor(float(poly[:, 0].mean()) / W)  # centre in [0, W)
            holes += [poly + [s * W, 0.0] for s in (-1.0, 0.0, 1.0)]
        fish = None
        tabs: list[np.ndarray] = []
        angles: list[float] = []
        hinged: list[bool] = []
        mouth_hinged = np.zeros(0, dtype=bool)
        if self.skirt is not None:
            j = self.skirt
            shift = np.array([0.0, j.skirt_base])
            fish = j.fish_mouth - shift
            mouth_hinged = ~np.asarray(j.flush, dtype=bool)
            for tab in j.tabs:
                poly = tab.polygon - shift
                poly[:, 0] -= W * math.floor(float(poly[0, 0]) / W)  # hinge start in [0, W)
                for s in (-1.0, 0.0, 1.0):
                    tabs.append(poly + [s * W, 0.0])
                    angles.append(tab.foldAngle)
                    hinged.append(not tab.flush)
        y0 = float(self.pattern.proximalMarker[1])
        return CutRegions(
            holes=tuple(_readonly(h) for h in holes),
            fish_mouth=None if fish is None else _readonly(fish),
            tabs=tuple(_readonly(t) for t in tabs),
            tab_angles=_readonly(np.array(angles, dtype=float)),
            tab_hinged=_readonly(np.array(hinged, dtype=bool)),
            bounds=(-0.5 * b, y0, W + 0.5 * b, y0 + self.pattern.height),
            width=W,
            tolerance=TOLERANCE_FACTOR * self.r,
            mouth_hinged=_readonly(mouth_hinged),
        )

    def hole_polygons(self) -> list[np.ndarray]:
        """Each hole's polygon in sheet coordinates (x continuous, centre in [0, W))."""
        return list(self.regions().holes[1::3])

    def validate(self):
        """Every problem found (a :class:`~kinegami.pattern.ValidationReport`): those of the
        crease pattern, and holes that overlap each other."""
        from kinegami.pattern.tubular import ValidationReport

        problems = list(self.pattern.validate().problems)
        polygons = self.regions().holes
        for i, j in itertools.combinations(range(len(self.holes)), 2):
            first = polygons[3 * i + 1]
            for other in polygons[3 * j : 3 * j + 3]:
                if (points_in_polygon(other, first).any()
                        or points_in_polygon(first, other).any()):  # fmt: skip
                    problems.append(f"holes {self.holes[i].name} and {self.holes[j].name} overlap")
                    break
        return ValidationReport(tuple(problems))

    # --- drawing -------------------------------------------------------------------------

    def sheet(self, *, skip_creases_on_cut: bool = False) -> Sheet:
        """The lines of the flat sheet (:func:`flatten_cut`)."""
        return flatten_cut(self, skip_creases_on_cut=skip_creases_on_cut)

    def show(self, **options):
        """Draw the sheet with matplotlib (options of
        :func:`kinegami.viz.pattern_plot.show_pattern`); returns (figure, axes)."""
        from kinegami.viz.pattern_plot import show_pattern

        return show_pattern(self, **options)

    def save(self, dxfName=None, **options):
        """Write the sheet in the format of the file suffix (``.dxf``, ``.svg``, ``.fold``,
        ``.pdf``; see :func:`kinegami.export.save_pattern`)."""
        from kinegami.export.registry import export

        return export(self, dxfName, **options)


# --------------------------------------------------------------------------------------------
# The flat sheet


def flatten_cut(cut: CutPattern, *, skip_creases_on_cut: bool = False) -> Sheet:
    """The lines drawn on the flat sheet of a :class:`CutPattern`.

    The pattern's own sheet (:func:`~kinegami.pattern.sheet.flatten`) is split wherever a
    hole edge, the fish-mouth or a tab outline crosses it, and each piece is kept by what lies
    on its two sides:

    * creases (M, V) where there is paper on one side at least and nothing is cut away on
      either side (no crease inside a hole or along its edge, none below the fish-mouth);
    * the nominal tube's boundary (B) where there is tube paper on one side and no hole, tab
      or cut-away part on either side; the fish-mouth (within [0, W]) is its lower edge;
    * the outline (C) where there is paper on exactly one side and the other side is outside
      the pattern's rectangle; then the hole edges and the tabs' free edges are added as cuts.

    Every line is clipped to the strip -b/2 <= x <= W + b/2 (holes and tabs near the seam show
    on both copies of the starting panel). The sheet's bottom edge ``y0`` is the lowest tab
    corner when the sheet starts with a skirt. Lines: mountains, valleys, boundary, cut.
    """
    if not isinstance(cut, CutPattern):
        raise InvalidTypeError(f"cut must be a CutPattern, got {type(cut).__name__}")
    skip_creases_on_cut = check_bool("skip_creases_on_cut", skip_creases_on_cut)
    pattern = cut.pattern
    W, b, r = pattern.width, pattern.sideLength, pattern.r
    tol = TOLERANCE_FACTOR * r
    skirt = cut.skirt is not None
    base = flatten(pattern, skip_creases_on_cut=skip_creases_on_cut and not skirt)
    regions = cut.regions()
    segments, kinds = base.segments, base.kinds
    if skirt and skip_creases_on_cut:  # only the top edge is an edge of the paper there
        top = float(base.y0 + base.height)
        ys = segments[:, :, 1]
        on_top = (np.abs(ys - top) <= tol).all(axis=1) & np.isin(kinds, ("M", "V"))
        segments, kinds = segments[~on_top], kinds[~on_top]
    pieces, source = split_segments(segments, regions.boundary_segments(), tol)
    kinds = kinds[source]
    left, right = side_states(pieces, regions, SIDE_OFFSET_FACTOR * r)
    paper = np.isin(left, ("P", "T")) | np.isin(right, ("P", "T"))
    cut_away = (left == "H") | (right == "H")
    crease = np.isin(kinds, ("M", "V")) & paper & ~cut_away
    tube = (left == "P") | (right == "P")
    not_tube = np.isin(left, ("H", "T")) | np.isin(right, ("H", "T"))
    boundary = (kinds == "B") & tube & ~not_tube
    one_side = ((np.isin(left, ("P", "T")) & (right == "O"))
                | (np.isin(right, ("P", "T")) & (left == "O")))  # fmt: skip
    outline = (kinds == "C") & one_side
    keep = crease | boundary | outline
    pieces, kinds = pieces[keep], kinds[keep]

    xmin, xmax = -0.5 * b, W + 0.5 * b
    new = [(regions.hole_segments(), "C", xmin, xmax),
           (regions.tab_outline_segments(), "C", xmin, xmax)]  # fmt: skip
    if skirt:
        new.append((regions.mouth_segments()[0], "B", 0.0, W))
    for segs, kind, lo, hi in new:
        if segs.shape[0] == 0:
            continue
        inside, clipped = clip_segments(segs, lo, hi, tol, base.snapTolerance)
        pieces = np.concatenate([pieces, clipped[inside]])
        kinds = np.concatenate([kinds, np.full(int(inside.sum()), kind, dtype="<U1")])
    unique = unique_segments(pieces, kinds, tol)
    pieces, kinds = pieces[unique], kinds[unique]
    rank = {"M": 0, "V": 1, "B": 2, "C": 3}
    order = np.argsort(np.array([rank[k] for k in kinds.tolist()], dtype=int), kind="stable")
    pieces, kinds = pieces[order], kinds[order]
    y0 = float(base.y0)
    if regions.tabs:
        y0 = min(y0, min(float(t[:, 1].min()) for t in regions.tabs))
    height = float(base.y0 + base.height) - y0
    pieces.flags.writeable = False
    kinds = np.ascontiguousarray(kinds)
    kinds.flags.writeable = False
    return Sheet(pieces, kinds, W, b, y0, height, base.tolerance, base.snapTolerance)


SHEET_DRAWERS[CutPattern] = flatten_cut  # what flatten() does with a CutPattern

# --------------------------------------------------------------------------------------------
# Plane geometry (numpy)


def points_in_polygon(points: np.ndarray, poly: np.ndarray) -> np.ndarray:
    """Even-odd test: True for points strictly inside the closed polygon ``poly`` (points on
    its edges may go either way)."""
    points = np.asarray(points, dtype=float).reshape(-1, 2)
    x, y = points[:, :1], points[:, 1:]
    x0, y0 = poly[None, :, 0], poly[None, :, 1]
    x1, y1 = np.roll(poly[:, 0], -1)[None], np.roll(poly[:, 1], -1)[None]
    crosses = (y0 > y) != (y1 > y)
    dy = np.where(y1 != y0, y1 - y0, 1.0)
    at = x0 + (y - y0) * (x1 - x0) / dy
    return (np.count_nonzero(crosses & (x < at), axis=1) % 2) == 1


def _polygon_edges(polygons) -> np.ndarray:
    pieces = [np.stack([p, np.roll(p, -1, axis=0)], axis=1) for p in polygons]
    return np.concatenate(pieces) if pieces else np.zeros((0, 2, 2))


def _cross(a: np.ndarray, b: np.ndarray) -> np.ndarray:
    return a[..., 0] * b[..., 1] - a[..., 1] * b[..., 0]


def split_parameters(segments: np.ndarray, cutters: np.ndarray, tol: float) -> list[np.ndarray]:
    """For each segment, the parameters t in (0, 1) where it must be split: where a cutter
    crosses it, and where a cutter's end point lies on it (within ``tol``)."""
    segments = np.asarray(segments, dtype=float).reshape(-1, 2, 2)
    cutters = np.asarray(cutters, dtype=float).reshape(-1, 2, 2)
    K = segments.shape[0]
    if K == 0 or cutters.shape[0] == 0:
        return [np.zeros(0) for _ in range(K)]
    p = segments[:, None, 0]
    d = segments[:, None, 1] - p
    q = cutters[None, :, 0]
    e = cutters[None, :, 1] - q
    length = np.hypot(d[..., 0], d[..., 1])
    safe = np.where(length > 0.0, length, 1.0)
    denom = _cross(d, e)
    w = q - p
    parallel = np.abs(denom) <= 1e-12 * safe * np.hypot(e[..., 0], e[..., 1])
    den = np.where(parallel, 1.0, denom)
    t = _cross(w, e) / den
    u = _cross(w, d) / den
    e_len = np.where(np.hypot(e[..., 0], e[..., 1]) > 0.0, np.hypot(e[..., 0], e[..., 1]), 1.0)
    t_tol, u_tol = tol / safe, tol / e_len
    crossing = ~parallel & (t > t_tol) & (t < 1.0 - t_tol) & (u >= -u_tol) & (u <= 1.0 + u_tol)
    out = []
    ends = cutters.reshape(-1, 2)
    for i in range(K):
        params = [t[i, crossing[i]]]
        # cutter end points on the segment
        rel = ends - segments[i, 0]
        di = segments[i, 1] - segments[i, 0]
        li = float(np.hypot(*di))
        if li > 0.0:
            s = rel @ di / (li * li)
            off = np.abs(_cross(di[None], rel)) / li
            on = (off <= tol) & (s > tol / li) & (s < 1.0 - tol / li)
            params.append(s[on])
        values = np.sort(np.concatenate(params))
        if values.size:
            keep = np.concatenate([[True], np.diff(values) * max(li, 1e-300) > tol])
            values = values[keep]
        out.append(values)
    return out


def split_segments(
    segments: np.ndarray, cutters: np.ndarray, tol: float
) -> tuple[np.ndarray, np.ndarray]:
    """``segments`` cut into pieces at :func:`split_parameters`; returns the pieces (same
    orientation) and the index of the segment each comes from."""
    segments = np.asarray(segments, dtype=float).reshape(-1, 2, 2)
    params = split_parameters(segments, cutters, tol)
    pieces, source = [], []
    for i, t in enumerate(params):
        if t.size == 0:
            pieces.append(segments[i][None])
            source.append(i)
            continue
        knots = np.concatenate([[0.0], t, [1.0]])
        a, d = segments[i, 0], segments[i, 1] - segments[i, 0]
        pts = a + knots[:, None] * d
        pts[0], pts[-1] = segments[i, 0], segments[i, 1]
        pieces.append(np.stack([pts[:-1], pts[1:]], axis=1))
        source += [i] * (knots.size - 1)
    if not pieces:
        return np.zeros((0, 2, 2)), np.zeros(0, dtype=np.intp)
    return np.concatenate(pieces), np.array(source, dtype=np.intp)


def side_states(pieces: np.ndarray, regions: CutRegions, offset: float):
    """:meth:`CutRegions.classify` just left and just right of each piece's midpoint (``offset``
    away, perpendicular to it)."""
    pieces = np.asarray(pieces, dtype=float).reshape(-1, 2, 2)
    mid = 0.5 * (pieces[:, 0] + pieces[:, 1])
    d = pieces[:, 1] - pieces[:, 0]
    length = np.hypot(d[:, 0], d[:, 1])
    normal = np.stack([-d[:, 1], d[:, 0]], axis=1) / np.where(length > 0, length, 1.0)[:, None]
    return (regions.classify(mid + offset * normal), regions.classify(mid - offset * normal))
