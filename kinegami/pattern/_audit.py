"""The checks behind :meth:`TubularPattern.validate` (each returns a list of problem strings)."""

from __future__ import annotations

from typing import TYPE_CHECKING

import numpy as np
from scipy.spatial import cKDTree

from kinegami.pattern._prism import make_prism, periodic_dx
from kinegami.pattern.catalog import expected_counts

if TYPE_CHECKING:  # pragma: no cover
    from kinegami.pattern.tubular import TubularPattern

_SHOWN = 8  # how many offending indices a message lists
_TIGHT = 1.0 - 1e-6  # points exactly eps apart (up to rounding) are distinct, as in composition


def _listing(indices) -> str:
    indices = list(indices)
    shown = ", ".join(str(i) for i in indices[:_SHOWN])
    return shown + (", ..." if len(indices) > _SHOWN else "")


def audit_pattern(p: TubularPattern) -> list[str]:
    """Every problem found in ``p`` (see :meth:`TubularPattern.validate`)."""
    problems: list[str] = []
    problems += _check_range(p)
    tree, points = _vertex_tree(p)
    problems += _check_duplicate_vertices(p, tree)
    problems += _check_creases(p)
    problems += _check_overlaps(p, tree, points)
    problems += _check_bases(p)
    problems += _check_counts(p)
    return problems


def _check_range(p: TubularPattern) -> list[str]:
    out = []
    x, y = p.vertices_coords[:, 0], p.vertices_coords[:, 1]
    bad = np.flatnonzero((x < 0) | (x >= p.width))
    if bad.size:
        out.append(
            f"{bad.size} vertices have x outside [0, W = {p.width:.6g}): vertices {_listing(bad)}"
        )
    y0 = p.proximalMarker[1]
    bad = np.flatnonzero((y < y0 - p.eps) | (y > y0 + p.height + p.eps))
    if bad.size:
        out.append(
            f"{bad.size} vertices have y outside [{y0:.6g}, {y0 + p.height:.6g}] (the pattern's "
            f"height): vertices {_listing(bad)}"
        )
    return out


def _vertex_tree(p: TubularPattern) -> tuple[cKDTree, np.ndarray]:
    """A k-d tree of the vertices that is periodic in x (period W) and not in y."""
    points = p.vertices_coords.copy()
    points[:, 0] = np.mod(points[:, 0], p.width)
    points[points[:, 0] >= p.width, 0] = 0.0
    if points.shape[0]:
        points[:, 1] -= points[:, 1].min()
    span = float(points[:, 1].max()) if points.shape[0] else 0.0
    return cKDTree(points, boxsize=[p.width, 2.0 * span + 1.0 + p.width]), points


def _check_duplicate_vertices(p: TubularPattern, tree: cKDTree) -> list[str]:
    pairs = tree.query_pairs(p.eps * _TIGHT, output_type="ndarray")
    if not pairs.shape[0]:
        return []
    listed = "; ".join(f"{i}-{j}" for i, j in pairs[:_SHOWN])
    more = "; ..." if pairs.shape[0] > _SHOWN else ""
    return [
        f"{pairs.shape[0]} pairs of vertices closer than eps = {p.eps:.3g} (duplicates): "
        f"{listed}{more}"
    ]


def _check_creases(p: TubularPattern) -> list[str]:
    out = []
    if not p.numEdges:
        return out
    vectors = p.crease_vectors()
    lengths = np.hypot(vectors[:, 0], vectors[:, 1])
    bad = np.flatnonzero(lengths < p.eps * _TIGHT)
    if bad.size:
        out.append(f"{bad.size} zero-length creases (shorter than eps): creases {_listing(bad)}")
    e = p.edges_vertices
    keys = np.minimum(e[:, 0], e[:, 1]).astype(np.int64) * p.numVertices + np.maximum(
        e[:, 0], e[:, 1]
    )
    unique, index, counts = np.unique(keys, return_index=True, return_counts=True)
    dup = np.ones(keys.shape[0], dtype=bool)
    dup[index] = False
    if dup.any():
        out.append(
            f"{int(dup.sum())} duplicate creases (same two vertices as an earlier crease): "
            f"creases {_listing(np.flatnonzero(dup))}"
        )
    wide = np.flatnonzero(np.abs(vectors[:, 0]) > p.sideLength + p.eps)
    if wide.size:
        out.append(
            f"{wide.size} creases are wider than one panel (|dx| > b = {p.sideLength:.6g}): "
            f"creases {_listing(wide)}"
        )
    return out


def _check_overlaps(p: TubularPattern, tree: cKDTree, points: np.ndarray) -> list[str]:
    """Collinear overlapping creases, and vertices lying inside a crease they do not end on."""
    if not p.numEdges:
        return []
    W, eps = p.width, p.eps
    e = p.edges_vertices
    start = points[e[:, 0]]
    vec = p.crease_vectors()
    length = np.hypot(vec[:, 0], vec[:, 1])
    usable = np.flatnonzero(length >= eps)
    mid = start[usable] + 0.5 * vec[usable]
    mid[:, 0] = np.mod(mid[:, 0], W)
    mid[mid[:, 0] >= W, 0] = 0.0
    hits = tree.query_ball_point(mid, 0.5 * length[usable] + eps)
    sizes = np.fromiter((len(h) for h in hits), dtype=np.intp, count=len(hits))
    if not sizes.sum():
        return []
    crease = np.repeat(usable, sizes)
    vertex = np.concatenate([np.asarray(h, dtype=np.intp) for h in hits if len(h)])
    not_end = (vertex != e[crease, 0]) & (vertex != e[crease, 1])
    crease, vertex = crease[not_end], vertex[not_end]
    rel = points[vertex] - start[crease]
    rel[:, 0] = periodic_dx(rel[:, 0], W)
    unit = vec[crease] / length[crease, None]
    along = np.einsum("ij,ij->i", rel, unit)
    across = np.abs(rel[:, 0] * unit[:, 1] - rel[:, 1] * unit[:, 0])
    inside = (across < eps) & (along > eps) & (along < length[crease] - eps)
    crease, vertex, unit = crease[inside], vertex[inside], unit[inside]
    if not crease.shape[0]:
        return []
    # a crease at the interior vertex that runs along the line of the crease overlaps it
    overlapping: list[tuple[int, int]] = []
    junctions: list[tuple[int, int]] = []
    for c, v, u in zip(crease, vertex, unit, strict=True):
        incident = np.flatnonzero((e[:, 0] == v) | (e[:, 1] == v))
        other = np.where(e[incident, 0] == v, e[incident, 1], e[incident, 0])
        d = points[other] - points[v]
        d[:, 0] = periodic_dx(d[:, 0], W)
        collinear = incident[np.abs(d[:, 0] * u[1] - d[:, 1] * u[0]) < eps]
        if collinear.size:
            overlapping += [(int(c), int(f)) for f in collinear]
        else:
            junctions.append((int(c), int(v)))
    out = []
    if overlapping:
        pairs = sorted({tuple(sorted(pair)) for pair in overlapping})
        out.append(
            f"{len(pairs)} pairs of collinear overlapping creases: "
            + "; ".join(f"{a}-{b}" for a, b in pairs[:_SHOWN])
            + ("; ..." if len(pairs) > _SHOWN else "")
        )
    if junctions:
        out.append(
            f"{len(junctions)} vertices lie inside a crease without splitting it: "
            + "; ".join(f"vertex {v} on crease {c}" for c, v in junctions[:_SHOWN])
            + ("; ..." if len(junctions) > _SHOWN else "")
        )
    return out


def _check_bases(p: TubularPattern) -> list[str]:
    """Section 7.1 item 1: the bases sit on the columns shifted by their markers."""
    out = []
    n, W, eps = p.numSides, p.width, p.eps
    columns = (np.arange(n) + 0.5) * p.sideLength
    y0 = p.proximalMarker[1]
    if p.proximalBase is not None:
        xy = p.vertices_coords[p.proximalBase]
        dx = periodic_dx(xy[:, 0] - (columns + p.proximalMarker[0]), W)
        if np.any(np.abs(dx) > eps) or np.any(np.abs(xy[:, 1] - y0) > eps):
            out.append(
                "the proximal base is not the polygon {((k + 1/2) b + x_p) mod W} at y = y_p of "
                f"the proximal marker ({p.proximalMarker[0]:.6g}, {y0:.6g}), in order k"
            )
    if p.distalBase is not None:
        xy = p.vertices_coords[p.distalBase]
        expected = columns + p.distalMarker[0]
        dx = periodic_dx(xy[:, 0][:, None] - expected[None, :], W)
        matched = (np.abs(dx) < eps).sum(axis=1) == 1
        if not matched.all() or np.any(np.abs(xy[:, 1] - (y0 + p.height)) > eps):
            out.append(
                "the distal base is not a relabelling of {((k + 1/2) b + x_d) mod W} at "
                f"y = {y0 + p.height:.6g} (distal marker x_d = {p.distalMarker[0]:.6g})"
            )
        elif abs(p.distalMarker[1] - (y0 + p.height)) > eps:
            out.append(
                f"the distal marker y = {p.distalMarker[1]:.6g} differs from y_p + H = "
                f"{y0 + p.height:.6g}"
            )
    return out


def _check_counts(p: TubularPattern) -> list[str]:
    """Section 7.1 item 4 for each module, and V = n + sum(V_i - n) for a composite."""
    if not p.modules:
        return []
    prism = make_prism(p.numSides, p.r)
    n = p.numSides
    expected = [expected_counts(m, prism) for m in p.modules]
    if any(c is None for c in expected):
        return []
    out = []
    V = n + sum(c.numVertices - n for c in expected)
    E = sum(c.numEdges for c in expected) - p.removedDuplicates
    what = p.kind if len(p.modules) == 1 else f"composite of {len(p.modules)} modules"
    if V != p.numVertices:
        out.append(f"{what}: {p.numVertices} vertices, the formula gives {V}")
    if E != p.numEdges:
        out.append(
            f"{what}: {p.numEdges} creases, the formula gives {E} "
            f"(after {p.removedDuplicates} merged duplicates)"
        )
    if len(expected) == 1 and expected[0].numMountains is not None:
        if expected[0].numMountains != p.numMountains:
            out.append(
                f"{what}: {p.numMountains} mountain creases, the formula gives "
                f"{expected[0].numMountains}"
            )
    return out
