"""What ``KinematicChain.show`` and ``KinematicTree.show`` draw, as plain numpy geometry
(docs/theory/chain.md §6).

Pure functions from joints and links to vertex arrays (world coordinates, units of r); no
matplotlib. Each takes one joint or one link on its own (a link carries its start and end
frames), so the same functions draw a chain and a tree. The drawing in
:mod:`kinegami.viz.chain_plot` only hands these arrays to matplotlib, so everything drawn can
be tested without rendering. The shapes of the parts (the n-gons, the point sets whose hulls are
the joints) come from :mod:`kinegami.chain.bodies`, the body model shared with the mesh exporter and
the clearance engine; their names stay importable from here.

Polygons of a joint lie in the plane spanned by the second and third axes (b, c) of one of its
Dubins frames (first axis a = path direction); vertex k sits at angle pi/n + 2 pi k/n from b
towards c, so two sides are parallel to c (the revolute hinge line, the fold of a tip).
"""

from __future__ import annotations

import math

import numpy as np

from kinegami.chain.joints import Joint
from kinegami.chain.links import ELBOW_MIN_ANGLE
from kinegami.geometry.frames import rotation
from kinegami.geometry.screws import FIXED
from kinegami.geometry.shapes import circle_points, hinge_segment, polygon_side, regular_polygon

__all__ = [
    "regular_polygon",
    "polygon_side",
    "circle_points",
    "arc_points",
    "convex_hull_faces",
    "face_normals",
    "prism_faces",
    "joint_body_faces",
    "joint_axis_segment",
    "joint_frames",
    "frame_axes",
    "elbow_grids",
    "link_elbow_grids",
    "tube_grid",
    "grid_quads",
    "link_centreline",
    "turning_circles",
    "elbow_pose_frames",
    "elbow_rotation_axes",
    "sphere_grid",
    "ground_plane_quads",
]


# --- elementary shapes ---
def arc_points(centre, axis, start, angles) -> np.ndarray:
    """``start`` rotated about the line (``centre``, unit ``axis``) by each angle, shape (m, 3)."""
    centre = np.asarray(centre, dtype=float)
    k = np.asarray(axis, dtype=float)
    v = np.asarray(start, dtype=float) - centre
    t = np.asarray(angles, dtype=float)[:, None]
    kxv = np.cross(k, v)
    return centre + v * np.cos(t) + kxv * np.sin(t) + k * float(k @ v) * (1.0 - np.cos(t))


def convex_hull_faces(points, frame=None) -> list[np.ndarray]:
    """Faces of the convex hull of ``points`` (k, 3): one ordered polygon per planar facet.

    Coplanar hull triangles are merged, so a box gives 6 quadrilaterals. A flat or degenerate
    point set gives an empty list. The output does not depend on the order in which qhull lists
    its triangles (which changes with the last bits of the points): faces come in the order of
    their point indices, each counter-clockwise about its outward normal from its lowest index.

    ``frame`` (4x4, optional) is a frame the points are rigidly attached to (a joint's pose):
    point sets with the same coordinates in their frames (equal joints anywhere in a chain)
    then share one hull computation (the faces are the same, moved).
    """
    pts = np.asarray(points, dtype=float)
    if frame is None:
        return [pts[idx] for idx in _hull_face_indices(pts)]
    F = np.asarray(frame, dtype=float)
    local = (pts - F[:3, 3]) @ F[:3, :3]
    scale = max(float(np.abs(local).max(initial=0.0)), 1e-300)
    key = (pts.shape, np.round(local / scale, 9).tobytes(), float(f"{scale:.9g}"))
    faces = _HULLS.get(key)
    if faces is None:
        faces = _hull_face_indices(local)
        if len(_HULLS) >= 1024:
            _HULLS.clear()
        _HULLS[key] = faces
    return [pts[idx] for idx in faces]


#: Hulls already computed (convex_hull_faces with a frame): their faces' index arrays.
_HULLS: dict[tuple, tuple[np.ndarray, ...]] = {}


def _hull_face_indices(pts: np.ndarray) -> tuple[np.ndarray, ...]:
    """The faces of :func:`convex_hull_faces` as ordered index arrays into ``pts``."""
    from scipy.spatial import ConvexHull, QhullError

    try:
        hull = ConvexHull(pts)
    except (QhullError, ValueError):
        return ()
    scale = max(float(np.ptp(pts, axis=0).max()), 1e-300)
    groups: dict[tuple, set[int]] = {}
    normals: dict[tuple, np.ndarray] = {}
    for simplex, eq in zip(hull.simplices, hull.equations, strict=True):
        key = tuple(np.round(np.append(eq[:3], eq[3] / scale), 6))
        groups.setdefault(key, set()).update(int(i) for i in simplex)
        normals[key] = eq[:3]
    faces = []
    for key in sorted(groups, key=lambda k: sorted(groups[k])):
        idx = np.array(sorted(groups[key]))
        face = pts[idx]
        normal = normals[key]
        centre = face.mean(axis=0)
        e1 = face[0] - centre
        e1 /= np.linalg.norm(e1)
        e2 = np.cross(normal, e1)
        d = face - centre
        order = np.argsort(np.arctan2(d @ e2, d @ e1))
        order = np.roll(order, -int(np.argmin(order)))  # start at the lowest index
        faces.append(idx[order])
    return tuple(faces)


def face_normals(polygons) -> np.ndarray:
    """(q, 3) normals of q planar polygons (each (k, 3), or a (q, k, 3) array), by Newell's
    method: twice the area times the unit normal, right-handed about the vertex order.

    Unlike a normal from three of the vertices, it stays exact when two vertices coincide (a
    quadrilateral that is really a triangle, where an elbow's mitre meets its end circle).
    A polygon without area gives a zero vector.
    """
    if isinstance(polygons, np.ndarray) and polygons.ndim == 3:
        d = polygons - polygons.mean(axis=1, keepdims=True)
        return np.cross(d, np.roll(d, -1, axis=1)).sum(axis=1)
    out = np.zeros((len(polygons), 3))
    for i, poly in enumerate(polygons):
        d = np.asarray(poly, dtype=float)
        d = d - d.mean(axis=0)
        out[i] = np.cross(d, np.roll(d, -1, axis=0)).sum(axis=0)
    return out


def prism_faces(bottom: np.ndarray, top: np.ndarray) -> list[np.ndarray]:
    """Side quadrilaterals and both caps of the prism between two (n, 3) polygons."""
    n = len(bottom)
    nxt = np.roll(np.arange(n), -1)
    sides = np.stack([bottom, bottom[nxt], top[nxt], top], axis=1)
    return [*sides, bottom, top]


# --- joints ---
def joint_body_faces(joint: Joint) -> list[np.ndarray]:
    """Polygons (each (k, 3)) of a joint's body (its kind's
    :meth:`~kinegami.chain.joints.Joint.body_pieces`, drawn as each piece says: prisms with
    their quads, the rest as hulls); empty for a waypoint."""
    faces: list[np.ndarray] = []
    T = joint.pose_matrix
    for piece in joint.body_pieces():
        for item in piece.drawn or (("hull", piece.points),):
            if item[0] == "prism":
                faces += prism_faces(item[1], item[2])
            else:
                faces += convex_hull_faces(item[1], T)
    return faces


def joint_axis_segment(joint: Joint, scale: float) -> np.ndarray | None:
    """(2, 3) axis of motion p -+ scale r z of a revolute or prismatic joint, else None."""
    if joint.motion == FIXED:
        return None
    T = joint.pose_matrix
    return hinge_segment(T[:3, 3], T[:3, 2], 2.0 * scale * joint.r)


def joint_frames(joint: Joint) -> dict[str, np.ndarray]:
    """The frames drawn for a joint: ``{'proximal', 'center', 'distal'}`` -> 4x4 (waypoints:
    only ``'center'``, the Pose)."""
    if not joint.has_body:
        return {"center": np.array(joint.pose_matrix)}
    return {
        "proximal": joint.proximal_frame(),
        "center": np.array(joint.pose_matrix),
        "distal": joint.distal_frame(),
    }


def frame_axes(frames, length: float) -> tuple[np.ndarray, np.ndarray]:
    """Origins (k, 3) and arrows (3, k, 3) of length ``length`` along each frame's axes."""
    F = np.asarray(frames, dtype=float).reshape(-1, 4, 4)
    origins = F[:, :3, 3]
    arrows = length * np.transpose(F[:, :3, :3], (2, 0, 1))
    return origins, arrows


# --- links ---
def elbow_grids(arc, sides: int = 32) -> np.ndarray:
    """(count, 3, sides, 3): start circle, mitre ellipse and end circle of each elbow of ``arc``.

    ``arc`` is an :class:`~kinegami.chain.links.ElbowArc`. The mitre ellipse is the start circle
    carried along the incoming axis to the plane through the vertex that bisects the turn.
    """
    count = arc.count
    if count == 0:
        return np.zeros((0, 3, sides, 3))
    r = arc.r
    t = 2.0 * math.pi * np.arange(sides) / sides
    cos_t, sin_t = np.cos(t)[None, :, None], np.sin(t)[None, :, None]
    F = np.asarray(arc.frames)
    start_f, end_f = F[:-1], F[1:]

    def rings(frames):
        return (
            frames[:, None, :3, 3]
            + r * cos_t * frames[:, None, :3, 1]
            + r * sin_t * frames[:, None, :3, 2]
        )

    start = rings(start_f)
    end = rings(end_f)
    a_in = start_f[:, :3, 0]
    a_out = end_f[:, :3, 0]
    vertex = start_f[:, :3, 3] + r * math.tan(arc.elbowAngle / 2.0) * a_in
    normal = a_in + a_out
    normal /= np.linalg.norm(normal, axis=1, keepdims=True)
    lam = np.einsum("ej,ej->e", vertex, normal)[:, None] - np.einsum("epj,ej->ep", start, normal)
    lam /= np.einsum("ej,ej->e", a_in, normal)[:, None]
    mid = start + lam[:, :, None] * a_in[:, None, :]
    return np.stack([start, mid, end], axis=1)


def link_elbow_grids(link, sides: int = 32) -> np.ndarray:
    """(elbows, 3, sides, 3): :func:`elbow_grids` of both arcs of a link."""
    return np.concatenate([elbow_grids(link.elbows1, sides), elbow_grids(link.elbows2, sides)])


def tube_grid(link, sides: int = 32) -> np.ndarray | None:
    """(2, sides, 3): end circles of the straight part (q1 along u for tMag), or None if it is
    shorter than 0.01 r."""
    path = link.path
    if path.tMag <= 0.01 * link.r:
        return None
    F = link.arc1_end_frame
    t = 2.0 * math.pi * np.arange(sides) / sides
    ring = circle_points(path.q1, F[:3, 1], F[:3, 2], link.r, t)
    return np.stack([ring, ring + path.tMag * np.asarray(path.tUnit)])


def grid_quads(grid) -> np.ndarray:
    """(q, 4, 3) quadrilaterals of one or more closed-ring grids of shape (..., rows, m, 3)."""
    g = np.asarray(grid, dtype=float)
    rows, m = g.shape[-3], g.shape[-2]
    g = g.reshape(-1, rows, m, 3)
    nxt = np.roll(np.arange(m), -1)
    a, b = g[:, :-1], g[:, 1:]
    quads = np.stack([a, a[:, :, nxt], b[:, :, nxt], b], axis=-2)
    return quads.reshape(-1, 4, 3)


def link_centreline(link, points_per_arc: int = 16) -> np.ndarray:
    """(k, 3) centreline: arc 1 from p1 to q1, the straight q1 -> q2, arc 2 from q2 to p2."""
    p = link.path
    parts = []
    for theta, k, start, centre in ((p.theta1, p.k1, p.p1, p.c1), (p.theta2, p.k2, p.q2, p.c2)):
        if theta > ELBOW_MIN_ANGLE:
            parts.append(arc_points(centre, k, start, np.linspace(0.0, theta, points_per_arc)))
        else:
            parts.append(np.array(start, dtype=float)[None])
    first, second = parts
    first[-1] = p.q1
    second[0] = p.q2
    if p.theta2 > ELBOW_MIN_ANGLE:
        second[-1] = p.p2
    return np.vstack([first, second])


def turning_circles(link, points: int = 64) -> list[np.ndarray]:
    """[circle 1, circle 2]: closed (points + 1, 3) turning circles, None for an arc that does
    not turn (its circle would have an arbitrary plane)."""
    p = link.path
    t = np.linspace(0.0, 2.0 * math.pi, points + 1)
    out = []
    for theta, k, start, centre in ((p.theta1, p.k1, p.p1, p.c1), (p.theta2, p.k2, p.p2, p.c2)):
        out.append(arc_points(centre, k, start, t) if theta > ELBOW_MIN_ANGLE else None)
    return out


def elbow_pose_frames(arc) -> np.ndarray:
    """(4 count, 4, 4): per elbow its start frame, after the first delta, after the rotation,
    and its end frame."""
    count = arc.count
    if count == 0:
        return np.zeros((0, 4, 4))
    alpha = arc.elbowAngle
    phi = arc.rotationalAxisAngle
    delta = arc.r * math.tan(alpha / 2.0)
    step = np.eye(4)
    step[0, 3] = delta
    turn = step @ rotation((0.0, math.cos(phi), math.sin(phi)), alpha)
    F = np.asarray(arc.frames)
    out = np.empty((count, 4, 4, 4))
    out[:, 0] = F[:-1]
    out[:, 1] = F[:-1] @ step
    out[:, 2] = F[:-1] @ turn
    out[:, 3] = F[1:]
    return out.reshape(-1, 4, 4)


def elbow_rotation_axes(arc) -> np.ndarray:
    """(count, 2, 3): each elbow's rotation axis as the segment vertex -+ r k (world)."""
    count = arc.count
    if count == 0:
        return np.zeros((0, 2, 3))
    phi = arc.rotationalAxisAngle
    F = np.asarray(arc.frames)[:-1]
    k = math.cos(phi) * F[:, :3, 1] + math.sin(phi) * F[:, :3, 2]
    v = arc.vertices()
    return np.stack([v - arc.r * k, v + arc.r * k], axis=1)


# --- spheres and ground ---
def sphere_grid(centre, radius: float, parallels: int = 8, meridians: int = 16) -> np.ndarray:
    """(parallels + 1, meridians, 3): points of a sphere, pole to pole (closed in longitude)."""
    lat = np.linspace(0.0, math.pi, parallels + 1)[:, None, None]
    lon = (2.0 * math.pi * np.arange(meridians) / meridians)[None, :, None]
    unit = np.concatenate(
        np.broadcast_arrays(np.sin(lat) * np.cos(lon), np.sin(lat) * np.sin(lon), np.cos(lat)),
        axis=-1,
    )
    return np.asarray(centre, dtype=float) + radius * unit


def ground_plane_quads(half_size: float, step: float) -> np.ndarray:
    """(q, 4, 3) squares of side ``step`` covering [-half_size, half_size]^2 at z = 0."""
    cells = max(1, int(round(2.0 * half_size / step)))
    edges = np.linspace(-half_size, half_size, cells + 1)
    x0, y0 = np.meshgrid(edges[:-1], edges[:-1], indexing="ij")
    x1, y1 = np.meshgrid(edges[1:], edges[1:], indexing="ij")
    z = np.zeros_like(x0)
    corners = [(x0, y0), (x1, y0), (x1, y1), (x0, y1)]
    quads = np.stack([np.stack([x, y, z], axis=-1) for x, y in corners], axis=-2)
    return quads.reshape(-1, 4, 3)
