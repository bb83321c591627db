"""The flat sheet of a tubular crease pattern as a planar graph with faces (and, folded, the 3D
position of every vertex): what the FOLD and Origami Simulator SVG exports write
(:mod:`kinegami.export.fold`, docs/fold.md).

The sheet is x in [-b/2, W + b/2], y in [y0, y0 + H] (the glue tab is the second copy of the
starting panel). Every crease is cut where it meets the sheet's vertical edges, the outline is
split at every vertex on it, and the faces are those of that planar graph, counter-clockwise.
No vertex only splits a straight line (two collinear edges with the same assignment and fold
angle are merged) and no face has a straight corner (such a corner is split by a flat ``F``
diagonal): Origami Simulator's solver blows up on the zero-area triangles it would make.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import Any

import numpy as np

from kinegami.errors import FoldExportError, InvalidParameterError
from kinegami.pattern._prism import periodic_dx
from kinegami.pattern.sheet import TOLERANCE_FACTOR

__all__ = [
    "SheetGraph",
    "planar_graph",
    "planar_faces",
    "merge_straight_vertices",
    "straight_corners",
    "straight_corner_diagonals",
    "signed_area",
    "newell_normals",
    "fold_angles",
    "STRAIGHT_CORNER_SINE",
]


@dataclass(frozen=True, eq=False)
class SheetGraph:
    """The flattened sheet as a planar graph with faces and its folded 3D positions.

    Attributes
    ----------
    vertices : numpy.ndarray, shape (K, 2)
        Sheet coordinates (pattern units), x in [-b/2, W + b/2].
    vertices_3d : numpy.ndarray, shape (K, 3) or None
        Folded position of every sheet vertex (pattern units), or None when not folded.
    source : numpy.ndarray of int, shape (K,)
        Pattern vertex each sheet vertex is a copy of, or -1 for points where a crease meets a
        vertical edge of the sheet (and sheet corners that are no pattern vertex).
    between : numpy.ndarray, shape (K, 3)
        For the vertices with ``source == -1``: (u, w, t), the point lies at fraction t of the
        way from pattern vertex u to pattern vertex w (zeros for copies).
    edges : numpy.ndarray of int, shape (E, 2)
        Vertex pairs.
    assignment : numpy.ndarray of str, shape (E,)
        ``"M"``, ``"V"``, ``"B"`` or ``"F"`` (a flat diagonal splitting a straight corner).
    crease : numpy.ndarray of int, shape (E,)
        Pattern crease each edge is (a piece of; for collinear creases merged into one edge, the
        first of them), or -1 for the outline and the flat diagonals.
    faces : list of numpy.ndarray
        Vertex indices of every face, counter-clockwise in the sheet, none with a straight
        corner (:func:`straight_corners`).
    edge_faces : numpy.ndarray of int, shape (E, 2)
        Face on the left and on the right of each edge (from its first to its second vertex),
        -1 outside the sheet.
    width, sideLength, y0, height : float
        W, b, the bottom edge and the height H of the sheet.
    pattern : TubularPattern or None
        The pattern the sheet was drawn from (for a catalog pattern its unsnapped geometry),
        whose vertices ``source`` and ``between`` index and whose creases ``crease`` indexes.
    """

    vertices: np.ndarray
    vertices_3d: np.ndarray | None
    source: np.ndarray
    between: np.ndarray
    edges: np.ndarray
    assignment: np.ndarray
    crease: np.ndarray
    faces: list
    edge_faces: np.ndarray
    width: float
    sideLength: float
    y0: float
    height: float
    pattern: Any = None

    @property
    def bounds(self) -> tuple[float, float, float, float]:
        """The sheet rectangle (xmin, ymin, xmax, ymax) = (-b/2, y0, W + b/2, y0 + H)."""
        half = 0.5 * self.sideLength
        return (-half, self.y0, self.width + half, self.y0 + self.height)

    def face_areas(self) -> np.ndarray:
        """Signed area of every face in the sheet (all positive: counter-clockwise)."""
        return np.array([signed_area(self.vertices[f]) for f in self.faces])


# ------------------------------------------------------------------------------------------------
# The planar graph of the sheet


# ------------------------------------------------------------------------------------------------
# The planar graph of the sheet


def planar_graph(pattern, X3: np.ndarray | None) -> SheetGraph:
    """The sheet graph of ``pattern`` (a TubularPattern), with the folded positions ``X3``
    of its vertices ((N, 3), or None: not folded)."""
    W, b, r = pattern.width, pattern.sideLength, pattern.r
    tol = TOLERANCE_FACTOR * r
    y0 = float(pattern.proximalMarker[1])
    H = float(pattern.height)
    if H <= tol:
        raise FoldExportError(
            f"cannot export a pattern of height {H!r}: its sheet has no area (a lone waypoint or "
            "an empty tube has no faces)"
        )
    xmin, xmax = -0.5 * b, W + 0.5 * b
    v = pattern.vertices_coords
    nv = v.shape[0]
    # vertex copies at shifts 0, +W, -W that lie on the sheet (ends within tol snap onto it)
    shifts = np.array([0.0, W, -W])
    cx = v[None, :, 0] + shifts[:, None]
    inside = (cx >= xmin - tol) & (cx <= xmax + tol)
    cx = np.where(np.abs(cx - xmin) <= tol, xmin, np.where(np.abs(cx - xmax) <= tol, xmax, cx))
    copy_index = np.full((3, nv), -1)
    s_idx, v_idx = np.nonzero(inside)
    copy_index[s_idx, v_idx] = np.arange(s_idx.size)
    points = [np.stack([cx[s_idx, v_idx], v[v_idx, 1]], axis=1)]
    source = [v_idx]
    interp = [np.zeros((s_idx.size, 3))]  # (vertex u, vertex w, t) for clip points
    count = s_idx.size
    clip_points: dict[tuple[int, int], int] = {}

    def clip_vertex(x: float, y: float, u: int, w: int, t: float) -> int:
        nonlocal count
        key = (0 if x < 0.5 * W else 1, round(y / tol))
        for dk in (0, -1, 1):
            found = clip_points.get((key[0], key[1] + dk))
            if found is not None:
                return found
        clip_points[key] = count
        points.append(np.array([[x, y]]))
        source.append(np.array([-1]))
        interp.append(np.array([[u, w, t]]))
        count += 1
        return count - 1

    e = pattern.edges_vertices
    labels = pattern.edges_assignment
    start = v[e[:, 0]]
    dx = periodic_dx(v[e[:, 1], 0] - start[:, 0], W)
    # every crease at the shifts 0, +W, -W (in that order, crease by crease): its ends a, c
    x0 = start[:, 0]
    a = x0[:, None] + shifts[None, :]
    c = (x0 + dx)[:, None] + shifts[None, :]
    lo, hi = np.minimum(a, c), np.maximum(a, c)
    on_sheet = ~((hi < xmin + tol) | (lo > xmax - tol))  # else outside, or touching an edge
    # a piece lying on a vertical edge of the sheet is the outline
    on_sheet &= ~((np.abs(c - a) <= tol) & ((np.abs(a - xmin) <= tol) | (np.abs(a - xmax) <= tol)))
    a_in = (xmin - tol <= a) & (a <= xmax + tol)
    c_in = (xmin - tol <= c) & (c <= xmax + tol)
    u_all, w_all = e[:, 0], e[:, 1]
    # each end on the sheet is the copy of its vertex at the shift nearest to where the piece
    # puts it (the first nearest, as argmin); for every piece at once
    k_a = np.argmin(np.abs(shifts - (a - v[u_all, 0][:, None])[..., None]), axis=2)
    k_c = np.argmin(np.abs(shifts - (c - v[w_all, 0][:, None])[..., None]), axis=2)
    end_a, end_c = copy_index[k_a, u_all[:, None]], copy_index[k_c, w_all[:, None]]
    x_a, x_c = cx[k_a, u_all[:, None]], cx[k_c, w_all[:, None]]
    # pieces with both ends on the sheet, all at once
    whole = on_sheet & a_in & c_in
    i_whole, s_whole = np.nonzero(whole)
    ends_a, ends_c = end_a[whole], end_c[whole]
    if ends_a.size and min(int(ends_a.min()), int(ends_c.min())) < 0:  # pragma: no cover
        raise FoldExportError("a crease ends at a vertex missing from the sheet")
    xs_a, xs_c = x_a[whole], x_c[whole]
    keep = ~((np.maximum(xs_a, xs_c) <= xmin + tol) | (np.minimum(xs_a, xs_c) >= xmax - tol))
    keep &= ends_a != ends_c
    order = [i_whole[keep] * 3 + s_whole[keep]]
    found_a, found_c = [ends_a[keep]], [ends_c[keep]]
    # pieces with an end beyond the sheet: clipped there, one by one in crease order (clip
    # points are numbered in the order they are first met)
    vy = v[:, 1].tolist()
    clipped_order, clipped_a, clipped_c = [], [], []
    i_clip, s_clip = np.nonzero(on_sheet & ~(a_in & c_in))
    for i, k_s in zip(i_clip.tolist(), s_clip.tolist(), strict=True):
        u, w = int(u_all[i]), int(w_all[i])
        a_i, c_i = float(a[i, k_s]), float(c[i, k_s])
        y_0, y_1 = vy[u], vy[w]
        ends = []
        xs = []
        for x_end, end, x_copy in ((a_i, end_a, x_a), (c_i, end_c, x_c)):
            if xmin - tol <= x_end <= xmax + tol:
                ends.append(int(end[i, k_s]))
                xs.append(float(x_copy[i, k_s]))
            else:
                edge_x = xmin if x_end < xmin else xmax
                t = (edge_x - a_i) / (c_i - a_i)
                ends.append(clip_vertex(edge_x, y_0 + t * (y_1 - y_0), u, w, t))
                xs.append(edge_x)
        if min(ends) < 0:  # pragma: no cover - copies and clipping use the same tolerance
            raise FoldExportError(f"crease {i} ends at a vertex missing from the sheet")
        if max(xs) <= xmin + tol or min(xs) >= xmax - tol:
            continue  # the piece inside lies on a vertical edge: that is the outline
        if ends[0] == ends[1]:
            continue
        clipped_order.append(i * 3 + k_s)
        clipped_a.append(ends[0])
        clipped_c.append(ends[1])
    order.append(np.array(clipped_order, dtype=np.intp))
    found_a.append(np.array(clipped_a, dtype=np.intp))
    found_c.append(np.array(clipped_c, dtype=np.intp))
    order_all = np.concatenate(order)
    by_piece = np.argsort(order_all, kind="stable")  # crease by crease, shift by shift
    piece_crease = (order_all[by_piece] // 3).tolist()
    edges = list(zip(np.concatenate(found_a)[by_piece].tolist(),
                     np.concatenate(found_c)[by_piece].tolist(), strict=True))  # fmt: skip
    assignment = labels[piece_crease].tolist() if piece_crease else []
    crease = piece_crease
    # sheet corners that are no vertex (the distal base is shifted after a twist): a point of
    # the straight edge between the two nearest vertices on that end of the pattern
    for cy in (y0, y0 + H):
        on_edge = np.flatnonzero(np.abs(v[:, 1] - cy) <= tol)
        for corner_x in (xmin, xmax):
            current = np.concatenate(points)
            here = (np.abs(current[:, 0] - corner_x) <= tol) & (np.abs(current[:, 1] - cy) <= tol)
            if here.any():
                continue
            if on_edge.size < 2:  # pragma: no cover - every module end has its n base vertices
                raise FoldExportError(f"no vertices on the sheet edge y = {cy:.6g}")
            offset = periodic_dx(v[on_edge, 0] - corner_x, W)
            left = on_edge[np.argmax(np.where(offset < 0, offset, -np.inf))]
            right = on_edge[np.argmin(np.where(offset > 0, offset, np.inf))]
            dl = -periodic_dx(np.array([v[left, 0] - corner_x]), W)[0]
            dr = periodic_dx(np.array([v[right, 0] - corner_x]), W)[0]
            clip_vertex(corner_x, cy, int(left), int(right), dl / (dl + dr))
    P = np.concatenate(points)
    src = np.concatenate(source)
    itp = np.concatenate(interp)
    edges, assignment, crease = _add_outline(P, edges, assignment, crease, xmin, xmax, y0, H, tol)
    sheet_area = (xmax - xmin) * H
    faces, edge_faces = planar_faces(P, edges, sheet_area)
    V3 = None
    if X3 is not None:
        V3 = np.empty((P.shape[0], 3))
        own = src >= 0
        V3[own] = X3[src[own]]
        clip = ~own
        uu, ww, tt = itp[clip, 0].astype(int), itp[clip, 1].astype(int), itp[clip, 2]
        V3[clip] = X3[uu] + tt[:, None] * (X3[ww] - X3[uu])
    keep, alive, edges = merge_straight_vertices(P, V3, edges, assignment, faces, edge_faces, tol)
    if not keep.all():  # the faces lose the merged vertices, the edges keep their faces
        new_index = np.cumsum(keep) - 1
        faces = [new_index[f[keep[f]]] for f in faces]
        assignment, crease, edge_faces = assignment[alive], crease[alive], edge_faces[alive]
        P, src, itp = P[keep], src[keep], itp[keep]
        V3 = None if V3 is None else V3[keep]
    extra = straight_corner_diagonals(P, faces, tol)
    if extra.size:
        edges = np.concatenate([edges, extra])
        assignment = np.concatenate([assignment, np.full(extra.shape[0], "F", dtype="<U1")])
        crease = np.concatenate([crease, np.full(extra.shape[0], -1)])
        faces, edge_faces = planar_faces(P, edges, sheet_area)
    return SheetGraph(
        P, V3, src, itp, edges, assignment, crease, faces, edge_faces, W, b, y0, H, pattern
    )


def _add_outline(P, edges, assignment, crease, xmin, xmax, y0, H, tol):
    """Add the sheet outline split at every vertex on it; creases on it become boundary."""
    corners = [(xmin, y0), (xmax, y0), (xmax, y0 + H), (xmin, y0 + H)]
    for cx_, cy_ in corners:
        if not ((np.abs(P[:, 0] - cx_) <= tol) & (np.abs(P[:, 1] - cy_) <= tol)).any():
            raise FoldExportError(f"no vertex at the sheet corner ({cx_:.6g}, {cy_:.6g})")
    outline = []
    for axis, value, other in ((1, y0, 0), (0, xmax, 1), (1, y0 + H, 0), (0, xmin, 1)):
        on = np.flatnonzero(np.abs(P[:, axis] - value) <= tol)
        lo = xmin if other == 0 else y0
        hi = xmax if other == 0 else y0 + H
        on = on[(P[on, other] >= lo - tol) & (P[on, other] <= hi + tol)]
        on = on[np.argsort(P[on, other], kind="stable")]
        outline += list(zip(on[:-1].tolist(), on[1:].tolist(), strict=True))
    key = {}
    for i, (a, c) in enumerate(edges):
        key.setdefault((min(a, c), max(a, c)), i)
    keep = np.ones(len(edges), dtype=bool)
    out_edges = []
    for a, c in outline:
        i = key.get((min(a, c), max(a, c)))
        if i is not None:
            keep[i] = False  # a crease on the paper's edge is the paper's edge (B10)
        out_edges.append((a, c))
    E = np.array([ed for ed, k in zip(edges, keep, strict=True) if k] + out_edges, dtype=np.intp)
    A = np.array(
        [a for a, k in zip(assignment, keep, strict=True) if k] + ["B"] * len(out_edges),
        dtype="<U1",
    )
    C = np.array([c for c, k in zip(crease, keep, strict=True) if k] + [-1] * len(out_edges))
    # the same piece twice (only possible for duplicate creases): keep the first
    lo, hi = np.minimum(E[:, 0], E[:, 1]), np.maximum(E[:, 0], E[:, 1])
    _, first = np.unique(lo.astype(np.int64) * (P.shape[0] + 1) + hi, return_index=True)
    first.sort()
    return E[first], A[first], C[first]


def merge_straight_vertices(P, X, E, A, faces, edge_faces, tol):
    """Remove the vertices that only split a straight line: degree 2, on the segment between
    their two neighbours (within ``tol`` in the sheet and, when folded, in 3D), both edges with
    the same assignment and fold angle. The two edges become one, which keeps the index (and
    so the crease and faces) of the first.

    Returns the vertices to keep and the edges to keep (boolean masks), and the kept edges'
    vertex pairs, renumbered.
    """
    m = E.shape[0]
    angle = None
    if X is not None:
        angle = _dihedral_angles(X, faces, E, edge_faces)
    ends = E.copy()
    alive = np.ones(m, dtype=bool)
    incident: list[list[int]] = [[] for _ in range(P.shape[0])]
    for i, (a, c) in enumerate(E.tolist()):
        incident[a].append(i)
        incident[c].append(i)
    keep = np.ones(P.shape[0], dtype=bool)
    for v in range(P.shape[0]):
        if len(incident[v]) != 2:
            continue
        i, j = incident[v]
        a = int(ends[i, 0] if ends[i, 1] == v else ends[i, 1])
        c = int(ends[j, 0] if ends[j, 1] == v else ends[j, 1])
        if a == c or A[i] != A[j]:
            continue
        if _off_segment(P[v], P[a], P[c]) > tol:
            continue
        if X is not None and (
            _off_segment(X[v], X[a], X[c]) > tol or abs(angle[i] - angle[j]) > 1e-9
        ):
            continue
        ends[i, ends[i] == v] = c  # edge i now runs to c; edge j goes
        alive[j] = False
        incident[c][incident[c].index(j)] = i
        incident[v] = []
        keep[v] = False
    new_index = np.cumsum(keep) - 1
    return keep, alive, new_index[ends[alive]]


def _off_segment(p: np.ndarray, a: np.ndarray, c: np.ndarray) -> float:
    """Distance from p to the segment a-c (any dimension)."""
    d = c - a
    t = float(np.clip(np.dot(p - a, d) / max(float(np.dot(d, d)), 1e-300), 0.0, 1.0))
    return float(np.linalg.norm(p - (a + t * d)))


#: A face corner counts as straight when the sine of its angle is at most this (and it is not a
#: zero angle): within 1e-6 rad of 180 degrees.
STRAIGHT_CORNER_SINE = 1e-6


def _corner_sines(poly: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Sine and cosine of the angle at every corner of a polygon (2D)."""
    before = np.roll(poly, 1, axis=0) - poly
    after = np.roll(poly, -1, axis=0) - poly
    norm = np.linalg.norm(before, axis=1) * np.linalg.norm(after, axis=1)
    cross = before[:, 0] * after[:, 1] - before[:, 1] * after[:, 0]
    dot = np.einsum("ij,ij->i", before, after)
    return cross / norm, dot / norm


def straight_corners(P: np.ndarray, face: np.ndarray) -> np.ndarray:
    """Positions in ``face`` of its straight corners (angle within 1e-6 rad of 180 degrees)."""
    sine, cosine = _corner_sines(P[face])
    return np.flatnonzero((np.abs(sine) <= STRAIGHT_CORNER_SINE) & (cosine < 0))


def straight_corner_diagonals(P: np.ndarray, faces: list, tol: float) -> np.ndarray:
    """Flat diagonals that split every face with a straight corner into faces without one.

    A straight corner (a crease ending on a straight line: a T junction) makes a face whose
    triangulation, in Origami Simulator, has zero-area triangles. Each such corner gets a
    diagonal to the vertex of its face that maximises the smallest of the four angles the
    diagonal makes; the pieces are split again until no straight corner is left.
    """
    out: list[tuple[int, int]] = []
    corners, nxt, prev, first = _face_cycles(faces)
    before, after = P[prev] - P[corners], P[nxt] - P[corners]
    norm = np.linalg.norm(before, axis=1) * np.linalg.norm(after, axis=1)
    sine = (before[:, 0] * after[:, 1] - before[:, 1] * after[:, 0]) / norm
    straight = (np.abs(sine) <= STRAIGHT_CORNER_SINE) & (np.einsum("ij,ij->i", before, after) < 0)
    face_of = np.repeat(np.arange(len(faces)), np.diff(np.append(first, corners.size)))
    stack = [faces[i] for i in np.unique(face_of[straight]).tolist()]
    while stack:
        face = stack.pop()
        corners = straight_corners(P, face)
        if not corners.size:
            continue
        best = None
        k = face.size
        for i in corners.tolist():
            for j in range(k):
                if (j - i) % k in (0, 1, k - 1):
                    continue
                first = np.roll(face, -i)[: (j - i) % k + 1]
                second = np.roll(face, -j)[: (i - j) % k + 1]
                if not _is_inner_diagonal(P, face, first, second, tol):
                    continue
                score = min(_smallest_angle(P[first]), _smallest_angle(P[second]))
                if best is None or score > best[0]:
                    best = (score, first, second)
        if best is None:  # pragma: no cover - a face with a straight corner has a diagonal
            raise FoldExportError(f"no diagonal splits the face {face.tolist()} at its corner")
        _, first, second = best
        out.append((int(first[0]), int(first[-1])))
        stack += [first, second]
    return np.array(out, dtype=np.intp).reshape(-1, 2)


def _smallest_angle(poly: np.ndarray) -> float:
    sine, cosine = _corner_sines(poly)
    return float(np.arctan2(sine, cosine).min())


def _is_inner_diagonal(P, face, first, second, tol) -> bool:
    """The chord first[0]-first[-1] lies inside the face: both pieces are counter-clockwise
    with areas adding up to the face's, and it crosses no side of the face."""
    a, c = P[first[0]], P[first[-1]]
    area1, area2 = signed_area(P[first]), signed_area(P[second])
    if area1 <= tol * tol or area2 <= tol * tol:
        return False
    if not math.isclose(area1 + area2, signed_area(P[face]), rel_tol=1e-9):
        return False
    ends = {int(first[0]), int(first[-1])}
    for u, w in zip(face.tolist(), np.roll(face, -1).tolist(), strict=True):
        if u in ends or w in ends:
            continue
        if _segments_cross(a, c, P[u], P[w], tol):
            return False
    return True


def _segments_cross(a, c, p, q, tol) -> bool:
    """Segments a-c and p-q meet (touching within tol counts)."""

    def side(o, u, w):
        return (u[0] - o[0]) * (w[1] - o[1]) - (u[1] - o[1]) * (w[0] - o[0])

    d1, d2 = side(a, c, p), side(a, c, q)
    d3, d4 = side(p, q, a), side(p, q, c)
    if d1 * d2 < 0 and d3 * d4 < 0:
        return True
    return min(_off_segment(p, a, c), _off_segment(q, a, c)) <= tol


def signed_area(poly: np.ndarray) -> float:
    """Shoelace area, relative to the first corner (exact enough for slivers far from 0)."""
    rel = poly - poly[0]
    x, y = rel[:, 0], rel[:, 1]  # the closing term vanishes: the first corner is the origin
    return 0.5 * float(np.dot(x[:-1], y[1:]) - np.dot(y[:-1], x[1:]))


def planar_faces(P: np.ndarray, E: np.ndarray, sheet_area: float | None):
    """Faces of the planar straight-line graph (P, E): counter-clockwise vertex cycles.

    Half-edge h = 2i goes E[i, 0] -> E[i, 1], h = 2i + 1 the other way. Around each vertex the
    outgoing half-edges are sorted by angle; the face to the left of u -> v continues with the
    outgoing half-edge of v just clockwise of v -> u. The faces must cover ``sheet_area``
    (None: the area inside the one boundary loop, for a sheet that is no rectangle).
    """
    m = E.shape[0]
    tail = np.empty(2 * m, dtype=np.intp)
    head = np.empty(2 * m, dtype=np.intp)
    tail[0::2], head[0::2] = E[:, 0], E[:, 1]
    tail[1::2], head[1::2] = E[:, 1], E[:, 0]
    d = P[head] - P[tail]
    angle = np.arctan2(d[:, 1], d[:, 0])
    order = np.lexsort((angle, tail))
    position = np.empty(2 * m, dtype=np.intp)
    position[order] = np.arange(2 * m)
    first = np.searchsorted(tail[order], np.arange(P.shape[0]))
    degree = np.bincount(tail, minlength=P.shape[0])
    twin = np.arange(2 * m) ^ 1
    t = twin
    v = tail[t]  # = head of h
    rank = position[t] - first[v]
    prev_rank = (rank - 1) % degree[v]
    nxt = order[first[v] + prev_rank]
    face_of = np.full(2 * m, -1)
    visited = bytearray(2 * m)
    following = nxt.tolist()  # the cycles are traced on Python ints (no numpy per-item cost)
    cycles = []
    for h0 in range(2 * m):
        if visited[h0]:
            continue
        cycle = []
        h = h0
        while not visited[h]:
            visited[h] = 1
            cycle.append(h)
            h = following[h]
        cycles.append(cycle)
    # every cycle's shoelace area at once, each relative to its first corner (signed_area)
    lengths = np.array([len(cycle) for cycle in cycles], dtype=np.intp)
    half_edges = np.concatenate([np.array(cycle, dtype=np.intp) for cycle in cycles])
    starts = np.zeros(lengths.size, dtype=np.intp)
    np.cumsum(lengths[:-1], out=starts[1:])
    verts_all = tail[half_edges]
    rel = P[verts_all] - np.repeat(P[verts_all[starts]], lengths, axis=0)
    x, y = rel[:, 0], rel[:, 1]
    terms = np.zeros(half_edges.size)
    terms[:-1] = x[:-1] * y[1:] - y[:-1] * x[1:]
    terms[starts[1:] - 1] = 0.0  # no term across two cycles (each closing term vanishes)
    cycle_areas = 0.5 * np.add.reduceat(terms, starts)
    faces = []
    areas = []  # of the faces
    outer = []
    for k, area in enumerate(cycle_areas.tolist()):
        verts = verts_all[starts[k] : starts[k] + lengths[k]]
        if area > 0:
            face_of[half_edges[starts[k] : starts[k] + lengths[k]]] = len(faces)
            faces.append(verts)
            areas.append(area)
        else:
            outer.append(verts)
    total = sum(areas)
    problems = []
    if len(outer) != 1:
        problems.append(f"{len(outer)} boundary loops (expected 1: creases not connected)")
    elif sheet_area is None:
        sheet_area = -signed_area(P[outer[0]])
    if sheet_area is not None and not math.isclose(total, sheet_area, rel_tol=1e-9):
        problems.append(f"faces cover {total!r} instead of the sheet area {sheet_area!r}")
    repeated = sum(1 for f in faces if len(set(f.tolist())) != f.size)
    if repeated:
        problems.append(f"{repeated} faces are not simple polygons")
    if problems:
        raise FoldExportError(
            "the sheet is not a valid planar crease pattern (crossing or overlapping creases?): "
            + "; ".join(problems)
        )
    edge_faces = np.stack([face_of[0::2], face_of[1::2]], axis=1)
    return faces, edge_faces


# ------------------------------------------------------------------------------------------------
# Fold angles


def _face_cycles(faces: list) -> tuple[np.ndarray, np.ndarray, np.ndarray, np.ndarray]:
    """All faces' corners in one array: (corner vertex, next corner's vertex, previous
    corner's vertex), face after face, and the index of every face's first corner."""
    sizes = np.array([f.size for f in faces], dtype=np.intp)
    first = np.concatenate([[0], np.cumsum(sizes)[:-1]]).astype(np.intp)
    corners = np.concatenate(faces).astype(np.intp)
    position = np.arange(corners.size) - np.repeat(first, sizes)
    size = np.repeat(sizes, sizes)
    start = np.repeat(first, sizes)
    nxt = corners[start + (position + 1) % size]
    prev = corners[start + (position - 1) % size]
    return corners, nxt, prev, first


def newell_normals(X: np.ndarray, faces: list) -> np.ndarray:
    """Unit Newell normal of every 3D face polygon (zero for a degenerate one)."""
    corners, nxt, _, first = _face_cycles(faces)
    p, q = X[corners], X[nxt]
    terms = np.stack(
        [
            (p[:, 1] - q[:, 1]) * (p[:, 2] + q[:, 2]),
            (p[:, 2] - q[:, 2]) * (p[:, 0] + q[:, 0]),
            (p[:, 0] - q[:, 0]) * (p[:, 1] + q[:, 1]),
        ],
        axis=1,
    )
    n = np.add.reduceat(terms, first, axis=0)
    norm = np.linalg.norm(n, axis=1)
    return n / np.where(norm > 0, norm, 1.0)[:, None]


def fold_angles(graph: SheetGraph) -> np.ndarray:
    """Signed dihedral angle of every edge in the folded form, radians, valley positive.

    For an edge with faces on both sides, the angle between the two faces' printed-side normals
    (Newell normals of their 3D polygons), positive when the crease folds towards the printed
    side (a valley); 0 for outline edges. Folds of nearly pi come out with an arbitrary sign:
    :func:`fold_dict` takes the sign from the assignment.
    """
    if graph.vertices_3d is None:
        raise InvalidParameterError("fold_angles needs a graph built with folded=True")
    return _dihedral_angles(graph.vertices_3d, graph.faces, graph.edges, graph.edge_faces)


def _dihedral_angles(X, faces, edges, edge_faces) -> np.ndarray:
    """Signed dihedral angle of every edge (radians, valley positive; 0 on the outline)."""
    normals = newell_normals(X, faces)
    out = np.zeros(edges.shape[0])
    inner = (edge_faces >= 0).all(axis=1)
    n1 = normals[edge_faces[inner, 0]]
    n2 = normals[edge_faces[inner, 1]]
    d = X[edges[inner, 1]] - X[edges[inner, 0]]
    d /= np.linalg.norm(d, axis=1)[:, None]
    out[inner] = np.arctan2(
        -np.einsum("ij,ij->i", np.cross(n1, n2), d), np.einsum("ij,ij->i", n1, n2)
    )
    return out
