"""The planar graph of a sheet with cut-outs: what the FOLD and Origami Simulator SVG exports
write for a :class:`~kinegami.pattern.cutout.CutPattern` (docs/fold.md, docs/junctions.md).

The sheet graph of the pattern alone (:func:`kinegami.pattern.sheet_graph.sheet_graph`, from its
unsnapped geometry) is cut along the hole edges, the fish-mouth and the tabs' outlines: every
edge is split where those lines cross it, the lines are added, and the faces of that
arrangement are kept where there is paper (:meth:`~kinegami.pattern.cutout.CutRegions.classify`).
An edge with paper on both sides stays a crease when it is one (a glue tab's hinge is a valley)
and disappears otherwise (two pieces of one face); an edge with paper on one side only is the
paper's edge (``B``).

Folded positions: the vertices of the pattern's graph keep theirs; a new vertex on one of its
edges or inside one of its faces folds with that edge or face (a face is a rigid planar copy of
its flat polygon, so the affine map from its flat to its folded corners is exact); a glue tab's
corner is its hinge's face extended across the hinge and turned about it by the tab's valley
angle towards the printed side (the tube's outside).
"""

from __future__ import annotations

import numpy as np

from kinegami.errors import FoldExportError
from kinegami.pattern.cutout import CutPattern, points_in_polygon, split_parameters
from kinegami.pattern.planar import (
    SheetGraph,
    merge_straight_vertices,
    newell_normals,
    planar_faces,
    planar_graph,
    signed_area,
    straight_corner_diagonals,
)
from kinegami.pattern.sheet import TOLERANCE_FACTOR, clip_segments

__all__ = ["cut_sheet_graph", "interior_point"]


def cut_sheet_graph(cut: CutPattern, *, folded: bool = True, frame=None) -> SheetGraph:
    """The sheet of ``cut`` as a planar graph with faces (and folded positions).

    ``frame`` is the world Dubins frame of the pattern's proximal end (default: ``cut.frame``,
    else the folded form's default). Returns a :class:`~kinegami.pattern.planar.SheetGraph` whose
    faces are the paper's (none in a hole), with ``source`` -1 for the vertices the cut added.

    Raises
    ------
    FoldExportError
        If the cut lines do not make a valid planar sheet.
    """
    from kinegami.pattern.folded import unsnapped_form

    if frame is None:
        frame = cut.frame
    U = unsnapped_form(cut.pattern, frame=frame)
    G0 = planar_graph(U.pattern, U.vertices)
    regions = cut.regions(U.pattern.vertices_coords,
                          [U.modules[h.module].vertices for h in cut.holes])  # fmt: skip
    r = cut.r
    tol = TOLERANCE_FACTOR * r
    W, b = cut.width, cut.sideLength
    xmin, xmax = -0.5 * b, W + 0.5 * b

    # 1. the lines: the pattern's edges (no flat diagonal: they are made again) and the cuts
    keep = G0.assignment != "F"
    old = G0.vertices[G0.edges[keep]]
    old_kind = G0.assignment[keep]
    old_crease = G0.crease[keep]
    new, new_kind = [], []
    mouth, hinged = regions.mouth_segments()
    for segs, kinds in ((regions.hole_segments(), None), (mouth, hinged),
                        (regions.tab_outline_segments(), None)):  # fmt: skip
        if segs.shape[0] == 0:
            continue
        inside, clipped = clip_segments(segs, xmin, xmax, tol, cut.pattern.eps)
        new.append(clipped[inside])
        if kinds is None:
            new_kind.append(np.full(int(inside.sum()), "C", dtype="<U1"))
        else:
            new_kind.append(np.where(kinds[inside], "V", "C").astype("<U1"))
    new = np.concatenate(new) if new else np.zeros((0, 2, 2))
    new_kind = np.concatenate(new_kind) if new_kind else np.zeros(0, dtype="<U1")
    segments = np.concatenate([old, new])
    kinds = np.concatenate([old_kind, new_kind])
    crease = np.concatenate([old_crease, np.full(new.shape[0], -1)])

    # 2. the arrangement: split every line where a cut crosses it or ends on it, and the cuts
    # where any line ends on them
    params = split_parameters(old, new, tol) + split_parameters(new, segments, tol)
    ends = []
    for i, t in enumerate(params):
        knots = np.concatenate([[0.0], t, [1.0]])
        a, d = segments[i, 0], segments[i, 1] - segments[i, 0]
        pts = a + knots[:, None] * d
        pts[0], pts[-1] = segments[i, 0], segments[i, 1]
        ends.append(pts)
    P, index_of = _merge_points(G0.vertices, np.concatenate(ends), tol)
    edges, labels, creases = [], [], []
    at = 0
    for i, pts in enumerate(ends):
        ids = index_of[at : at + pts.shape[0]]
        at += pts.shape[0]
        for u, w in zip(ids[:-1].tolist(), ids[1:].tolist(), strict=True):
            if u != w:
                edges.append((u, w))
                labels.append(kinds[i])
                creases.append(int(crease[i]))
    E, A, C = _unique_edges(np.array(edges, dtype=np.intp), np.array(labels, dtype="<U1"),
                            np.array(creases))  # fmt: skip

    # 3. keep the paper: faces where there is paper; edges between paper and no paper are the
    # paper's edge, edges inside the paper only if they are creases
    faces, edge_faces = planar_faces(P, E, None)
    paper = _paper_faces(P, faces, regions)
    sides = np.where(edge_faces >= 0, paper[np.maximum(edge_faces, 0)], False).sum(axis=1)
    is_crease = np.isin(A, ("M", "V"))
    alive = (sides == 1) | ((sides == 2) & is_crease)
    A = np.where(sides == 1, "B", A).astype("<U1")
    C = np.where(sides == 1, -1, C)
    E, A, C = E[alive], A[alive], C[alive]
    used = np.zeros(P.shape[0], dtype=bool)
    used[E.ravel()] = True
    renumber = np.cumsum(used) - 1
    P, E = P[used], renumber[E]
    origin = np.flatnonzero(used)  # index in the arrangement (< len(G0.vertices): G0's vertex)
    faces, edge_faces = _paper_graph(P, E, regions)

    # 4. folded positions
    X = _folded_positions(P, origin, G0, regions, tol) if folded else None

    # 5. as the plain sheet graph: no vertex that only splits a straight line, no straight
    # face corner
    keep_v, alive_e, E = merge_straight_vertices(P, X, E, A, faces, edge_faces, tol)
    if not keep_v.all():
        A, C = A[alive_e], C[alive_e]
        P, origin = P[keep_v], origin[keep_v]
        X = None if X is None else X[keep_v]
        faces, edge_faces = _paper_graph(P, E, regions)
    extra = straight_corner_diagonals(P, faces, tol)
    if extra.size:
        E = np.concatenate([E, extra])
        A = np.concatenate([A, np.full(extra.shape[0], "F", dtype="<U1")])
        C = np.concatenate([C, np.full(extra.shape[0], -1)])
        faces, edge_faces = _paper_graph(P, E, regions)
    n0 = G0.vertices.shape[0]
    own = origin < n0
    source = np.full(P.shape[0], -1)
    source[own] = G0.source[origin[own]]
    between = np.zeros((P.shape[0], 3))
    between[own] = G0.between[origin[own]]
    y0 = float(P[:, 1].min())
    height = float(P[:, 1].max()) - y0
    return SheetGraph(P, X, source, between, E, A, C, faces, edge_faces, W, b, y0, height,
                      G0.pattern)  # fmt: skip


# --------------------------------------------------------------------------------------------


def _merge_points(base: np.ndarray, points: np.ndarray, tol: float):
    """``base`` followed by the points of ``points`` farther than ``tol`` from every earlier
    one, and the index of each point of ``points`` in that list."""
    from scipy.spatial import cKDTree

    tree = cKDTree(base)
    dist, near = tree.query(points, distance_upper_bound=tol)
    index = np.where(np.isfinite(dist), near, -1)
    extra: list[np.ndarray] = []
    for i in np.flatnonzero(index < 0).tolist():
        p = points[i]
        for k, q in enumerate(extra):
            if abs(q[0] - p[0]) <= tol and abs(q[1] - p[1]) <= tol:
                index[i] = base.shape[0] + k
                break
        else:
            index[i] = base.shape[0] + len(extra)
            extra.append(p)
    merged = np.concatenate([base, np.array(extra).reshape(-1, 2)])
    return merged, index


def _unique_edges(E: np.ndarray, A: np.ndarray, C: np.ndarray):
    """One edge per vertex pair; of several, a crease (M or V) wins, then the first."""
    lo, hi = np.minimum(E[:, 0], E[:, 1]), np.maximum(E[:, 0], E[:, 1])
    key = lo.astype(np.int64) * (int(E.max(initial=0)) + 1) + hi
    rank = np.where(np.isin(A, ("M", "V")), 0, 1)
    order = np.lexsort((np.arange(E.shape[0]), rank, key))
    first = np.ones(order.size, dtype=bool)
    first[1:] = key[order][1:] != key[order][:-1]
    chosen = np.sort(order[first])
    return E[chosen], A[chosen], C[chosen]


def interior_point(poly: np.ndarray) -> np.ndarray:
    """A point strictly inside the simple polygon ``poly`` (counter-clockwise or not).

    The corner with the smallest (x, y) is convex; the centroid of the triangle it makes with
    its neighbours is inside unless a corner of the polygon lies in that triangle, in which
    case the midpoint between it and the nearest such corner is."""
    poly = np.asarray(poly, dtype=float)
    k = poly.shape[0]
    i = int(np.lexsort((poly[:, 1], poly[:, 0]))[0])
    v, a, c = poly[i], poly[(i - 1) % k], poly[(i + 1) % k]
    others = np.delete(poly, [(i - 1) % k, i, (i + 1) % k], axis=0)
    if others.shape[0]:
        inside = points_in_polygon(others, np.array([a, v, c]))
        if inside.any():
            candidates = others[inside]
            nearest = candidates[np.argmin(np.hypot(*(candidates - v).T))]
            return 0.5 * (v + nearest)
    return (a + v + c) / 3.0


def _paper_faces(P: np.ndarray, faces: list, regions) -> np.ndarray:
    """Whether each face is paper (of the tube or of a tab)."""
    points = np.array([interior_point(P[f]) for f in faces]).reshape(-1, 2)
    return np.isin(regions.classify(points), ("P", "T"))


def _paper_graph(P: np.ndarray, E: np.ndarray, regions):
    """The paper faces of (P, E) and every edge's paper faces (-1 for no paper)."""
    faces, edge_faces = planar_faces(P, E, None)
    paper = _paper_faces(P, faces, regions)
    new_index = np.cumsum(paper) - 1
    edge_faces = np.where(edge_faces >= 0, np.where(paper[np.maximum(edge_faces, 0)],
                                                    new_index[np.maximum(edge_faces, 0)], -1),
                          -1)  # fmt: skip
    faces = [f for f, keep in zip(faces, paper, strict=True) if keep]
    if any(signed_area(P[f]) <= 0.0 for f in faces):  # pragma: no cover - the faces are ccw
        raise FoldExportError("a face of the cut sheet is not counter-clockwise")
    return faces, edge_faces


def _face_map(points2: np.ndarray, points3: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """The affine map X = M p + c taking a flat face's corners to its folded ones (least
    squares; exact for a rigid planar face)."""
    A = np.hstack([points2, np.ones((points2.shape[0], 1))])
    sol, *_ = np.linalg.lstsq(A, points3, rcond=None)
    return sol[:2].T, sol[2]


def _folded_positions(P, origin, G0, regions, tol) -> np.ndarray:
    n0 = G0.vertices.shape[0]
    X = np.empty((P.shape[0], 3))
    own = origin < n0
    X[own] = G0.vertices_3d[origin[own]]
    todo = np.flatnonzero(~own)
    if not todo.size:
        return X
    P0, X0, E0 = G0.vertices, G0.vertices_3d, G0.edges
    normals = newell_normals(X0, G0.faces)
    face_maps: dict[int, tuple] = {}

    def face_of(q: np.ndarray) -> int:
        for k, f in enumerate(G0.faces):
            if points_in_polygon(q[None], P0[f])[0]:
                return k
        raise FoldExportError(  # pragma: no cover - every sheet point lies in a face
            f"no face of the sheet holds the point {q.tolist()}"
        )

    def affine(k: int):
        if k not in face_maps:
            f = G0.faces[k]
            face_maps[k] = _face_map(P0[f], X0[f])
        return face_maps[k]

    a, c = P0[E0[:, 0]], P0[E0[:, 1]]
    d = c - a
    length2 = np.einsum("ij,ij->i", d, d)
    for v in todo.tolist():
        q = P[v]
        tab = _tab_of(q, regions, tol)
        if tab >= 0:
            X[v] = _tab_point(q, tab, regions, P0, X0, normals, face_of, affine)
            continue
        t = np.clip(np.einsum("ij,ij->i", q - a, d) / np.where(length2 > 0, length2, 1.0),
                    0.0, 1.0)  # fmt: skip
        off = np.hypot(*(a + t[:, None] * d - q).T)
        e = int(np.argmin(off))
        if off[e] <= tol:  # on an edge: along it
            X[v] = X0[E0[e, 0]] + t[e] * (X0[E0[e, 1]] - X0[E0[e, 0]])
            continue
        M, c0 = affine(face_of(q))
        X[v] = M @ q + c0
    return X


def _tab_of(q: np.ndarray, regions, tol: float) -> int:
    """The tab whose paper (or free edge) holds ``q`` but not its hinge, or -1."""
    for k, poly in enumerate(regions.tabs):
        p0, p1 = poly[0], poly[1]
        e = p1 - p0
        length = float(np.hypot(*e))
        s = float((q - p0) @ e) / (length * length)
        on_hinge = abs(float(e[0] * (q - p0)[1] - e[1] * (q - p0)[0])) / length <= tol and (
            -tol / length <= s <= 1.0 + tol / length
        )
        if on_hinge:
            continue
        if points_in_polygon(q[None], poly)[0] or _polygon_distance(q, poly) <= tol:
            return k
    return -1


def _polygon_distance(q: np.ndarray, poly: np.ndarray) -> float:
    a, c = poly, np.roll(poly, -1, axis=0)
    d = c - a
    t = np.clip(np.einsum("ij,ij->i", q - a, d) / np.einsum("ij,ij->i", d, d), 0.0, 1.0)
    return float(np.hypot(*(a + t[:, None] * d - q).T).min())


def _tab_point(q, tab, regions, P0, X0, normals, face_of, affine) -> np.ndarray:
    """The folded position of a point of glue tab ``tab``: the plane of the face above its
    hinge, extended across the hinge and turned about it by the tab's valley angle."""
    poly = regions.tabs[tab]
    omega = float(regions.tab_angles[tab])
    p0, p1 = poly[0], poly[1]
    e = (p1 - p0) / np.hypot(*(p1 - p0))
    nu = np.array([e[1], -e[0]])  # towards the tab (away from the skirt)
    above = 0.5 * (p0 + p1) - 1e3 * regions.tolerance * nu
    k = face_of(above)
    M, c0 = affine(k)
    alpha, beta = float((q - p0) @ e), float((q - p0) @ nu)
    across = M @ nu
    return (M @ p0 + c0) + alpha * (M @ e) + beta * (np.cos(omega) * across
                                                     + np.sin(omega) * normals[k])  # fmt: skip
