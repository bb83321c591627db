"""Independent checks for the FOLD export and the folded form (no code shared with the package).

* :func:`check_fold` is a JSON-level structural checker of a FOLD 1.2 dict (array lengths,
  index ranges, assignments, angles, faces, frames), written from the FOLD specification.
* :func:`polygon_errors` compares base rings with the regular polygon around a Dubins frame.
* :func:`chain_pieces` splits a chain pattern's module records into its joints and links, and
  :func:`prismatic_offsets` gives the translation that spec B7 (and the rigid bellows) adds
  after each prismatic joint.
* :func:`face_congruence` and :func:`face_planarity` measure how far a folded face is from a
  rigid copy of its flat polygon; :func:`rebo_rigid_length` is the length of a bellows whose
  faces stay rigid.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

ASSIGNMENTS = {"M", "V", "B", "C", "F", "U", "J"}


def _is_number(v) -> bool:
    return isinstance(v, numbers.Real) and not isinstance(v, bool) and math.isfinite(v)


def check_fold(data: dict) -> list[str]:
    """Every structural problem of a FOLD 1.2 dict (empty list when valid)."""
    problems: list[str] = []
    if data.get("file_spec") != 1.2:
        problems.append(f"file_spec is {data.get('file_spec')!r}, expected 1.2")
    creator = data.get("file_creator")
    if not (isinstance(creator, str) and creator.startswith("kinegami ")):
        problems.append(f"file_creator {creator!r} is not 'kinegami <version>'")
    if data.get("file_classes") != ["singleModel"]:
        problems.append(f"file_classes {data.get('file_classes')!r}")
    if data.get("frame_classes") != ["creasePattern"]:
        problems.append(f"frame_classes {data.get('frame_classes')!r}")
    if not isinstance(data.get("frame_unit"), str):
        problems.append("frame_unit missing")
    V = data.get("vertices_coords")
    if not isinstance(V, list) or not V:
        return problems + ["vertices_coords missing or empty"]
    nv = len(V)
    for i, p in enumerate(V):
        if not (isinstance(p, list) and len(p) == 2 and all(_is_number(c) for c in p)):
            problems.append(f"vertices_coords[{i}] = {p!r} is not a 2D point")
            break
    E = data.get("edges_vertices")
    A = data.get("edges_assignment")
    F = data.get("edges_foldAngle")
    if not (isinstance(E, list) and isinstance(A, list) and isinstance(F, list)):
        return problems + ["edges_vertices / edges_assignment / edges_foldAngle missing"]
    if not len(E) == len(A) == len(F):
        problems.append(f"edge arrays differ in length: {len(E)}, {len(A)}, {len(F)}")
    seen = set()
    for i, e in enumerate(E):
        ok = (
            isinstance(e, list)
            and len(e) == 2
            and all(isinstance(k, int) and 0 <= k < nv for k in e)
            and e[0] != e[1]
        )
        if not ok:
            problems.append(f"edges_vertices[{i}] = {e!r} is not two distinct vertex indices")
            continue
        key = tuple(sorted(e))
        if key in seen:
            problems.append(f"edge {key} appears twice")
        seen.add(key)
    for i, (a, f) in enumerate(zip(A, F, strict=False)):
        if a not in ASSIGNMENTS:
            problems.append(f"edges_assignment[{i}] = {a!r}")
        if not (_is_number(f) and -180.0 <= f <= 180.0):
            problems.append(f"edges_foldAngle[{i}] = {f!r} is not in [-180, 180]")
        elif a in ("B", "C", "F") and f != 0:
            problems.append(f"edge {i} ({a}) has fold angle {f}")
        elif a == "V" and f < 0 or a == "M" and f > 0:
            problems.append(f"edge {i} ({a}) has fold angle of the wrong sign {f}")
    faces = data.get("faces_vertices")
    if not isinstance(faces, list) or not faces:
        return problems + ["faces_vertices missing or empty (Origami Simulator needs faces)"]
    edge_set = seen
    for i, face in enumerate(faces):
        if not (isinstance(face, list) and len(face) >= 3):
            problems.append(f"faces_vertices[{i}] has fewer than 3 vertices")
            continue
        if not all(isinstance(k, int) and 0 <= k < nv for k in face):
            problems.append(f"faces_vertices[{i}] has an invalid index")
            continue
        if len(set(face)) != len(face):
            problems.append(f"faces_vertices[{i}] repeats a vertex")
        for a, b in zip(face, face[1:] + face[:1], strict=True):
            if tuple(sorted((a, b))) not in edge_set:
                problems.append(f"faces_vertices[{i}] side {a}-{b} is not an edge")
                break
    for j, frame in enumerate(data.get("file_frames", [])):
        if "foldedForm" not in frame.get("frame_classes", []):
            problems.append(f"file_frames[{j}] is not a foldedForm")
        if frame.get("frame_inherit") is not True or frame.get("frame_parent") != 0:
            problems.append(f"file_frames[{j}] does not inherit from frame 0")
        X = frame.get("vertices_coords")
        if not (isinstance(X, list) and len(X) == nv):
            problems.append(f"file_frames[{j}] has {len(X or [])} vertices, expected {nv}")
        elif not all(isinstance(p, list) and len(p) == 3 and all(map(_is_number, p)) for p in X):
            problems.append(f"file_frames[{j}] vertices are not 3D points")
    return problems


def signed_area(poly: np.ndarray) -> float:
    """Shoelace area of a polygon (relative to its first corner, for accuracy)."""
    rel = poly - poly[0]
    x, y = rel[:, 0], rel[:, 1]
    return 0.5 * float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1)))


def face_planarity(points: np.ndarray) -> float:
    """Largest distance of a polygon's vertices from its least-squares plane."""
    c = points - points.mean(axis=0)
    normal = np.linalg.svd(c)[2][-1]
    return float(np.abs(c @ normal).max())


def face_congruence(flat: np.ndarray, folded: np.ndarray) -> float:
    """Largest |3D distance - flat distance| over all vertex pairs of one face.

    Zero exactly when the folded face is a rigid (possibly mirrored) copy of the flat polygon,
    so every straight segment drawn across the face keeps its length.
    """
    d2 = np.linalg.norm(flat[:, None] - flat[None], axis=2)
    d3 = np.linalg.norm(folded[:, None] - folded[None], axis=2)
    return float(np.abs(d3 - d2).max())


def rebo_rigid_length(n: int, d: float, cone_angle: float) -> float:
    """Axial length of a REBO of neutral length d folded with rigid faces (spec 3.7 geometry).

    Derivation (independent of the package): turn every lower quadrilateral of a layer about
    its ring edge by the inclination g towards the axis. Its midline corners then sit l1 cos g
    inside the ring edge, along the panel's inward normal, at height l1 sin g. The pleat
    crease O_k-A_k (flat length o) joins the corners of two neighbouring panels, whose normals
    differ by 2 pi / n: its squared 3D length is o^2 - 2 o l1 cos g sin(2 pi/n)
    + 2 (l1 cos g)^2 (1 - cos(2 pi/n)), which equals o^2 iff l1 cos g = o cot(pi/n). With
    l1 = d / (2 N sin(beta)) and o = l1 tan(pi cos(beta) / n) every layer is 2 l1 sin g long, so
    the N layers are d sin g / sin(beta) long.
    """
    cos_g = math.tan(math.pi * math.cos(cone_angle) / n) / math.tan(math.pi / n)
    return d * math.sqrt(1.0 - cos_g**2) / math.sin(cone_angle)


def polygon_corners(frame: np.ndarray, n: int, r: float) -> np.ndarray:
    """Corners of the regular n-gon of circumradius r about a Dubins frame's origin, in its
    y-z plane (perpendicular to the path direction x), at angles (k + 1/2) 2 pi / n from y."""
    beta = (np.arange(n) + 0.5) * 2 * np.pi / n
    return (
        frame[:3, 3]
        + r * np.cos(beta)[:, None] * frame[:3, 1]
        + r * np.sin(beta)[:, None] * frame[:3, 2]
    )


def ring_error(points: np.ndarray, frame: np.ndarray, n: int, r: float) -> float:
    """Largest distance from a ring vertex to the nearest polygon corner; also requires every
    corner to be used once (the ring is the polygon, not a subset)."""
    corners = polygon_corners(frame, n, r)
    d = np.linalg.norm(points[:, None] - corners[None], axis=2)
    nearest = d.argmin(axis=1)
    if len(set(nearest.tolist())) != n:
        return math.inf
    return float(d.min(axis=1).max())


def chain_pieces(chain, twistPortion: float = 0.2) -> list[tuple[str, int, object, int, int]]:
    """(kind, index, joint or link, first record, end record) of the chain's crease pattern.

    Mirrors how the chain composes its pattern (joint 0, then link i and joint i), with the
    composition rule that an empty pattern after the first one leaves no record.
    """
    n = chain.numSides
    pieces = []
    count = 0
    first = True

    def add(kind, index, obj, patterns):
        nonlocal count, first
        start = count
        for p in patterns:
            if first or not p.isEmpty:
                count += len(p.modules)
            first = False
        pieces.append((kind, index, obj, start, count))

    add("joint", 0, chain.Joints[0], [chain.Joints[0].pattern])
    for i in range(1, len(chain.Joints)):
        add("link", i, chain.Links[i], chain.Links[i].pattern_modules(n, twistPortion))
        add("joint", i, chain.Joints[i], [chain.Joints[i].pattern])
    return pieces


def prismatic_offsets(chain, pieces) -> list[np.ndarray]:
    """World translation, per piece, that the folded prismatic joints add: each folds to
    d' + L instead of the kinematic d (spec B7: the sleeve adds L = d / sin(coneAngle); the
    rigid bellows is d' = :func:`rebo_rigid_length` long), along its axis, for every prismatic
    joint before the piece's end (the prismatic's own distal end included)."""
    offsets = []
    total = np.zeros(3)
    for kind, _, obj, _, _ in pieces:
        before = total.copy()
        if kind == "joint" and type(obj).__name__ == "PrismaticJoint":
            d, beta = obj.neutralLength, obj.coneAngle
            extra = d / math.sin(beta) + rebo_rigid_length(chain.numSides, d, beta) - d
            total = total + extra * obj.pose_matrix[:3, 2]
        offsets.append((before, total.copy()))
    return offsets


def segments_distance(A: np.ndarray, B: np.ndarray, samples: int = 9) -> float:
    """Largest distance from a point of the segments ``A`` (k, 2, 2) to the union of the
    segments ``B`` (m, 2, 2), sampling ``samples`` points along every segment of ``A``."""
    if A.shape[0] == 0:
        return 0.0
    if B.shape[0] == 0:
        return math.inf
    t = np.linspace(0.0, 1.0, samples)
    points = (A[:, None, 0] + t[None, :, None] * (A[:, None, 1] - A[:, None, 0])).reshape(-1, 2)
    a = B[:, 0]
    ab = B[:, 1] - B[:, 0]
    length2 = np.maximum(np.einsum("ij,ij->i", ab, ab), 1e-300)
    worst = 0.0
    for start in range(0, points.shape[0], 256):
        p = points[start : start + 256]
        ap = p[:, None, :] - a[None, :, :]
        s = np.clip(np.einsum("pij,ij->pi", ap, ab) / length2, 0.0, 1.0)
        d = np.linalg.norm(ap - s[..., None] * ab[None], axis=2)
        worst = max(worst, float(d.min(axis=1).max()))
    return worst


def sheet_distance(graph, sheet) -> float:
    """Hausdorff distance (sampled) between the FOLD sheet's creases and the DXF sheet's.

    Every FOLD crease (M or V) must lie near a DXF crease or the cut outline (the DXF drops
    crease pieces within eps of a vertical cut edge), and every DXF crease near a FOLD crease
    or the FOLD outline (creases on the top and bottom edges are the outline, B, in FOLD).
    Labels are not compared: where fix B6 put an elbow's tuck boundary on a module ring, the
    DXF has one crease there and FOLD two, h_k apart, each with its own label.
    """
    P, E, A = graph.vertices, graph.edges, graph.assignment
    segments = P[E]
    ours = segments[A != "B"]
    theirs = np.concatenate([sheet.select("M"), sheet.select("V")])
    return max(
        segments_distance(ours, np.concatenate([theirs, sheet.select("C")])),
        segments_distance(theirs, np.concatenate([ours, segments[A == "B"]])),
    )


def vertex_degrees(data: dict) -> np.ndarray:
    """Number of edges at every vertex of a FOLD dict."""
    E = np.array(data["edges_vertices"])
    return np.bincount(E.ravel(), minlength=len(data["vertices_coords"]))


def degree_two_vertices(data: dict) -> list[tuple[int, float]]:
    """(vertex, angle between its two edges in radians) for every vertex with two edges."""
    V = np.array(data["vertices_coords"], dtype=float)
    E = np.array(data["edges_vertices"])
    out = []
    for v in np.flatnonzero(vertex_degrees(data) == 2):
        ends = E[(E == v).any(axis=1)]
        a, c = (int(e[0] if e[1] == v else e[1]) for e in ends)
        u, w = V[a] - V[v], V[c] - V[v]
        cosine = float(u @ w) / float(np.linalg.norm(u) * np.linalg.norm(w))
        out.append((int(v), math.acos(max(-1.0, min(1.0, cosine)))))
    return out


def face_corner_angles(data: dict) -> list[np.ndarray]:
    """Interior angle (radians, in (0, 2 pi)) at every corner of every face, counter-clockwise
    faces assumed."""
    V = np.array(data["vertices_coords"], dtype=float)
    out = []
    for face in data["faces_vertices"]:
        P = V[face]
        before = np.roll(P, 1, axis=0) - P
        after = np.roll(P, -1, axis=0) - P
        # angle from the side to the next corner round to the side to the previous one
        cross = after[:, 0] * before[:, 1] - after[:, 1] * before[:, 0]
        dot = np.einsum("ij,ij->i", after, before)
        out.append(np.mod(np.arctan2(cross, dot), 2 * math.pi))
    return out
