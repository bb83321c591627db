"""Tube fitting (a straight tube) and the empty waypoint pattern.

See docs/theory/patterns.md 3.1, 3.9.
"""

from __future__ import annotations

import numpy as np

from kinegami.pattern import catalog
from kinegami.pattern._build import assemble, crease_block, nonnegative
from kinegami.pattern._fold import polygon_point, translation
from kinegami.pattern._prism import make_prism
from kinegami.pattern.catalog import ModuleCounts
from kinegami.pattern.tubular import ModuleRecord, TubularPattern

__all__ = ["TubeFittingPattern", "WaypointPattern"]


@catalog.cached_build
def WaypointPattern(numSides: int, r: float) -> TubularPattern:
    """The empty pattern: the n base vertices at y = 0, no creases, height 0 (section 3.9).

    Its proximal and distal bases are the same vertices; appending it changes nothing.

    Parameters
    ----------
    numSides : int
        Number of sides n (even, >= 4).
    r : float
        Tube circumradius (> 0).
    """
    prism = make_prism(numSides, r)
    return _empty(prism, ModuleRecord("waypoint", {}))


def _empty(prism, record: ModuleRecord) -> TubularPattern:
    empty = prism.cached("empty", lambda: _empty_template(prism))
    return TubularPattern._build(
        prism.numSides, prism.r, empty.vertices_coords, empty.edges_vertices,
        empty.edges_assignment, empty.proximalBase, empty.distalBase, np.zeros(2), np.zeros(2),
        0.0, (record,), 0, None, False,
    )  # fmt: skip


def _empty_template(prism) -> TubularPattern:
    n = prism.numSides
    vertices = np.stack([prism.columns, np.zeros(n)], axis=1)
    base = np.arange(n)
    record = ModuleRecord("waypoint")
    return assemble(prism, vertices, [(np.zeros((0, 2), int), "M")], base, base, 0.0, record)


def _many_tubes(calls: list[tuple]) -> list[TubularPattern]:
    """TubeFittingPattern of every (numSides, r, height) call (a single tube is a batch of
    one); the tubes of one prism share one block of vertices (each tube's array a read-only
    row) and one of distal markers."""
    checked = [(make_prism(numSides, r), nonnegative("height", h)) for numSides, r, h in calls]
    built: list = [None] * len(calls)
    groups: dict = {}
    for i, (prism, h) in enumerate(checked):
        if h < prism.eps:
            built[i] = _empty(prism, ModuleRecord._of("tube", {"height": h}))
        else:
            groups.setdefault(prism, []).append(i)
    for prism, rows in groups.items():
        n = prism.numSides
        template = prism.cached(("tube", "M"), lambda prism=prism: _tube_template(prism, "M"))
        heights = np.array([checked[i][1] for i in rows])
        block = np.empty((len(rows), 2 * n, 2))
        block[:] = template.vertices_coords
        block[:, n:, 1] = heights[:, None]
        block.setflags(write=False)
        markers = np.zeros((len(rows), 2))
        markers[:, 1] = heights
        markers.setflags(write=False)
        origin = np.zeros(2)
        origin.setflags(write=False)
        for i, vertices, marker in zip(rows, block, markers, strict=True):
            h = checked[i][1]
            built[i] = TubularPattern._build(
                n, prism.r, vertices, template.edges_vertices, template.edges_assignment,
                template.proximalBase, template.distalBase, origin, marker, float(h),
                (ModuleRecord._of("tube", {"height": h}),), 0, None, False, None, True,
            )  # fmt: skip
    return built


@catalog.cached_build(many=_many_tubes)
def TubeFittingPattern(numSides: int, r: float, height: float) -> TubularPattern:
    """A straight tube of axial length ``height`` (section 3.1).

    Vertices P_k = (x_k, 0) and D_k = (x_k, height); creases P_k-D_k mountain (the tube
    edges). Folded, the distal frame is the proximal frame translated by ``height`` along the
    tube axis.

    Parameters
    ----------
    numSides : int
        Number of sides n (even, >= 4).
    r : float
        Tube circumradius (> 0).
    height : float
        Length of the tube along its axis, >= 0, in units of r. A height below the tolerance
        eps = 1e-4 b (including 0) gives the empty pattern, which adds nothing when appended
        (fix B6: no coincident vertices or zero-length creases).
    """
    return _many_tubes([(numSides, r, height)])[0]


def tube_pattern(prism, h: float, label: str, record: ModuleRecord) -> TubularPattern:
    """A straight tube of height ``h`` whose ring creases are labelled ``label`` (``"M"`` or
    ``"V"``), recorded as ``record`` (the sleeves and piston of a prismatic joint use it)."""
    if h < prism.eps:
        return _empty(prism, record)
    n = prism.numSides
    tube = prism.cached(("tube", label), lambda: _tube_template(prism, label))
    vertices = tube.vertices_coords.copy()
    vertices[n:, 1] = h
    return TubularPattern._build(
        n, prism.r, vertices, tube.edges_vertices, tube.edges_assignment, tube.proximalBase,
        tube.distalBase, np.zeros(2), np.array([0.0, h]), float(h), (record,), 0, None, False,
    )  # fmt: skip


def _tube_template(prism, label: str) -> TubularPattern:
    """The tube of height 0 with creases ``label`` (shared arrays of every tube)."""
    n = prism.numSides
    x = prism.columns
    vertices = np.concatenate([np.stack([x, np.zeros(n)], axis=1)] * 2)
    k = np.arange(n)
    record = ModuleRecord("tube")
    return assemble(prism, vertices, [crease_block(k, n + k, label)], k, n + k, 0.0, record)


# --------------------------------------------------------------------------------------------
# Catalog entries: counts and fold


def _empty_counts(prism, params) -> ModuleCounts:
    return ModuleCounts(prism.numSides, 0, 0)


def _tube_counts(prism, params) -> ModuleCounts:
    n = prism.numSides
    if params["height"] < prism.eps:
        return ModuleCounts(n, 0, 0)
    return ModuleCounts(2 * n, n, n)


def fold_straight(prism, exact: TubularPattern, params):
    """A straight tube (or the empty pattern) at state 0: vertex (x, y) at c(x) + y e_a."""
    xy = exact.vertices_coords
    X = polygon_point(prism, xy[:, 0])
    X[:, 2] = xy[:, 1]
    return X, translation(exact.height)


catalog.register(
    catalog.ModuleKind("tube", TubeFittingPattern, ("height",), _tube_counts, fold_straight)
)
catalog.register(catalog.ModuleKind("waypoint", WaypointPattern, (), _empty_counts, fold_straight))
