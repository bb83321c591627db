"""Tools shared by the module folds (not public): frames, polygon points, named points.

Every module file folds its own kind (its ``fold`` entry in :mod:`kinegami.pattern.catalog`);
positions are in the module's proximal frame (e_u, e_v, e_a), see docs/theory/patterns.md
("The folded form") and docs/fold.md.
"""

from __future__ import annotations

import math

import numpy as np

from kinegami.errors import FoldedFormError
from kinegami.pattern._prism import SHEET_TOLERANCE_FACTOR, Prism, periodic_dx
from kinegami.pattern.tubular import TubularPattern

#: Points of an unsnapped module closer than this many r are one vertex: they coincide to the
#: tolerance of the flat sheet (SHEET_TOLERANCE_FACTOR), below which the sheet's
#: planar graph cannot tell points apart.
MERGE_TOLERANCE = SHEET_TOLERANCE_FACTOR


def translation(a: float) -> np.ndarray:
    """The 4x4 translation by ``a`` along the tube axis e_a."""
    T = np.eye(4)
    T[2, 3] = a
    return T


def rot_axis(axis, angle: float) -> np.ndarray:
    """The 3x3 rotation by ``angle`` (radians) about ``axis`` (Rodrigues)."""
    k = np.asarray(axis, dtype=float)
    k = k / np.linalg.norm(k)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    return np.eye(3) + math.sin(angle) * K + (1.0 - math.cos(angle)) * (K @ K)


def polygon_point(prism: Prism, x: np.ndarray) -> np.ndarray:
    """c(x): the point at arc length x on the polygon (a = 0), shape (m, 3).

    See docs/theory/patterns.md, section 1.
    """
    x = np.asarray(x, dtype=float)
    n, b, a = prism.numSides, prism.b, prism.a
    m = np.round(x / b)
    sigma = m * (2.0 * math.pi / n)
    t = x - m * b
    out = np.zeros(x.shape + (3,))
    out[..., 0] = a * np.cos(sigma) - t * np.sin(sigma)
    out[..., 1] = a * np.sin(sigma) + t * np.cos(sigma)
    return out


def corners(prism: Prism, angle_offset: float = 0.0) -> np.ndarray:
    """The polygon's corners p_k at a = 0, turned by ``angle_offset`` about e_a, shape (n, 3)."""
    beta = prism.vertex_angles + angle_offset
    return prism.r * np.stack([np.cos(beta), np.sin(beta), np.zeros_like(beta)], axis=1)


def mod_w(x: np.ndarray, W: float) -> np.ndarray:
    """x reduced into [0, W) without snapping (the wrapping of composition, less its eps rule)."""
    x = np.mod(x, W)
    return np.where(x >= W, 0.0, x)


def match_vertices(catalog_xy: np.ndarray, exact_xy: np.ndarray, prism: Prism) -> np.ndarray:
    """For every catalog vertex, the nearest unsnapped vertex (periodic in x): the same point
    (a collapsed column's Q_k is M_k), or less than eps away for a point snapped onto the
    seam."""
    nearest, dist = nearest_within(catalog_xy, exact_xy, prism.W, 3.0 * prism.eps)
    worst = np.where(nearest < 0, np.inf, dist).max(initial=0.0)
    if worst > 3.0 * prism.eps or np.unique(nearest).size != nearest.size:
        raise FoldedFormError(  # pragma: no cover - a catalog module changed its vertices
            f"the catalog module's vertices do not match its unsnapped geometry ({worst:.3g})"
        )
    return nearest


def assign(
    xy: np.ndarray, named_xy: np.ndarray, named_X: np.ndarray, W: float, tol: float
) -> tuple[np.ndarray, np.ndarray]:
    """Give each vertex the 3D position of the nearest named flat point (periodic in x).

    Returns (X, matched): vertices farther than ``tol`` from every named point are unmatched
    (their rows of X are NaN).
    """
    nearest, _ = nearest_within(xy, named_xy, W, tol)
    matched = nearest >= 0
    X = np.full((xy.shape[0], 3), np.nan)
    X[matched] = named_X[nearest[matched]]
    return X, matched


#: Most (point, named point) pairs :func:`nearest_within` measures at once.
_NEAREST_PAIRS = 1 << 20


def nearest_within(xy: np.ndarray, named_xy: np.ndarray, W: float, tol: float):
    """For each point of ``xy``, the first of the nearest points of ``named_xy`` (periodic in
    x, distance ``hypot(dx, dy)``) when it is at most ``tol`` away, else -1; and that distance.

    Only named points within ``tol`` in y are measured (sorted by y), a bounded number of pairs
    at a time: a module of 38,400 vertices asked for an 11 GiB distance matrix (issue 29)."""
    count = xy.shape[0]
    nearest = np.full(count, -1, dtype=np.int64)
    best = np.full(count, np.inf)
    if count == 0 or named_xy.shape[0] == 0:
        return nearest, best
    order = np.argsort(named_xy[:, 1], kind="stable")
    ys = named_xy[order, 1]
    slack = tol * (1.0 + 1e-9) + 1e-12 * (float(np.abs(ys).max()) + float(np.abs(xy[:, 1]).max()))
    low = np.searchsorted(ys, xy[:, 1] - slack, side="left")
    size = np.searchsorted(ys, xy[:, 1] + slack, side="right") - low
    size = np.maximum(size, 0)
    cut = np.searchsorted(np.cumsum(size), np.arange(1, 1 + int(size.sum()) // _NEAREST_PAIRS)
                          * _NEAREST_PAIRS)  # fmt: skip
    for part in np.split(np.arange(count), np.unique(cut)):
        n = size[part]
        if part.size == 0 or n.sum() == 0:
            continue
        i = np.repeat(part, n)
        q = np.arange(int(n.sum())) - np.repeat(np.cumsum(n) - n, n)  # place in each window
        j = order[np.repeat(low[part], n) + q]
        dx = periodic_dx(xy[i, 0] - named_xy[j, 0], W)
        dist = np.hypot(dx, xy[i, 1] - named_xy[j, 1])
        keep = dist <= tol
        i, j, dist = i[keep], j[keep], dist[keep]
        first = np.lexsort((j, dist, i))  # by point, then distance, then the named point's index
        lead = first[np.r_[True, i[first][1:] != i[first][:-1]]] if first.size else first
        nearest[i[lead]], best[i[lead]] = j[lead], dist[lead]
    return nearest, best


def require_all(matched: np.ndarray, kind: str) -> None:
    """Raise FoldedFormError unless every vertex got a position."""
    if not matched.all():  # pragma: no cover - a catalog module changed its vertices
        raise FoldedFormError(
            f"{int((~matched).sum())} vertices of a {kind} module have no known 3D position"
        )


def moved_copy(
    catalog: TubularPattern, xy: np.ndarray, distal_marker: np.ndarray
) -> TubularPattern:
    """``catalog`` with its vertices at ``xy`` and its distal marker at ``distal_marker``."""
    return TubularPattern._build(
        catalog.numSides, catalog.r, xy, catalog.edges_vertices.copy(),
        catalog.edges_assignment.copy(), catalog.proximalBase.copy(), catalog.distalBase.copy(),
        catalog.proximalMarker.copy(), distal_marker, catalog.height, catalog.modules,
    )  # fmt: skip
