"""Test helpers: locating vertices, folding them to 3D (spec section 3), vertex stars."""

from __future__ import annotations

import math

import numpy as np


def prism_numbers(n: int, r: float) -> tuple[float, float, float]:
    """(b, a, W) of the regular n-gon of circumradius r, computed here independently."""
    b = 2 * r * math.sin(math.pi / n)
    return b, r * math.cos(math.pi / n), n * b


def periodic(dx, W):
    """dx reduced to (-W/2, W/2]."""
    dx = np.asarray(dx, dtype=float)
    return dx - W * np.round(dx / W)


def find_vertex(pattern, xy, tol: float = 1e-6, nearest: bool = False) -> int:
    """Index of the unique vertex at ``xy`` (x compared modulo W), or the nearest one within
    ``tol`` when ``nearest`` is set."""
    v = pattern.vertices_coords
    dx = periodic(v[:, 0] - xy[0], pattern.width)
    dy = v[:, 1] - xy[1]
    hits = np.flatnonzero((np.abs(dx) < tol) & (np.abs(dy) < tol))
    if nearest and hits.size > 1:
        hits = hits[[np.argmin(np.hypot(dx[hits], dy[hits]))]]
    assert hits.size == 1, f"expected one vertex at {xy}, found {hits.size}"
    return int(hits[0])


def find_vertices(pattern, points, tol: float = 1e-6) -> np.ndarray:
    return np.array([find_vertex(pattern, p, tol) for p in points])


def crease_set(pattern, decimals: int = 9) -> set:
    """The creases as a set of (rounded end point pair, label), independent of indexing."""
    v = np.round(pattern.vertices_coords, decimals)
    v[:, 0] = np.round(np.mod(v[:, 0], pattern.width), decimals) % round(pattern.width, decimals)
    out = set()
    for (i, j), lab in zip(pattern.edges_vertices, pattern.edges_assignment, strict=True):
        a, b = tuple(v[i]), tuple(v[j])
        out.add((min(a, b), max(a, b), str(lab)))
    return out


def incident(pattern, vertex: int) -> tuple[np.ndarray, np.ndarray]:
    """Directions (angle, radians) and labels of the creases at ``vertex``."""
    e = pattern.edges_vertices
    idx = np.flatnonzero((e[:, 0] == vertex) | (e[:, 1] == vertex))
    other = np.where(e[idx, 0] == vertex, e[idx, 1], e[idx, 0])
    d = pattern.vertices_coords[other] - pattern.vertices_coords[vertex]
    d[:, 0] = periodic(d[:, 0], pattern.width)
    return np.arctan2(d[:, 1], d[:, 0]), pattern.edges_assignment[idx]


def mv_counts(pattern, vertex: int) -> tuple[int, int]:
    _, labels = incident(pattern, vertex)
    return int(np.sum(labels == "M")), int(np.sum(labels == "V"))


def kawasaki_defect(pattern, vertex: int) -> float:
    """|sum of alternate sector angles - pi| at ``vertex`` (0 for a flat-foldable vertex)."""
    angles, _ = incident(pattern, vertex)
    angles = np.sort(np.mod(angles, 2 * np.pi))
    sectors = np.diff(np.concatenate([angles, [angles[0] + 2 * np.pi]]))
    return abs(float(sectors[::2].sum()) - np.pi)


def maekawa_ok(pattern, vertex: int) -> bool:
    m, v = mv_counts(pattern, vertex)
    return abs(m - v) == 2


# --------------------------------------------------------------------------------------------
# Folding (section 3): 3D positions in the proximal frame (e_u, e_v, e_a) = (x, y, z)


def polygon_point(x, n: int, r: float) -> np.ndarray:
    """c(x): the point of the polygon at arc length x (section 1.3), shape (..., 3)."""
    b, a, _ = prism_numbers(n, r)
    x = np.asarray(x, dtype=float)
    m = np.round(x / b)
    s = m * 2 * np.pi / n
    t = x - m * b
    return np.stack(
        [a * np.cos(s) - t * np.sin(s), a * np.sin(s) + t * np.cos(s), np.zeros_like(x)], axis=-1
    )


def fold_straight(pattern) -> np.ndarray:
    """(x, y) -> c(x) + y e_a for every vertex."""
    v = pattern.vertices_coords
    X = polygon_point(v[:, 0], pattern.numSides, pattern.r)
    X[:, 2] = v[:, 1]
    return X


def rotation(axis, angle: float) -> np.ndarray:
    axis = np.asarray(axis, dtype=float)
    axis = axis / np.linalg.norm(axis)
    K = np.array([[0, -axis[2], axis[1]], [axis[2], 0, -axis[0]], [-axis[1], axis[0], 0]])
    return np.eye(3) + math.sin(angle) * K + (1 - math.cos(angle)) * K @ K


def crease_length_errors(pattern, X: np.ndarray, skip_vertices=()) -> np.ndarray:
    """|3D length - flat length| of every crease whose ends are both folded (not skipped)."""
    e = pattern.edges_vertices
    keep = ~np.isin(e, list(skip_vertices)).any(axis=1)
    e = e[keep]
    flat = pattern.edge_lengths()[keep]
    folded = np.linalg.norm(X[e[:, 1]] - X[e[:, 0]], axis=1)
    return np.abs(folded - flat)
