"""Points, frames and distances along the centreline of a CSC path, by arc length.

See docs/junctions.md. The centreline of a :class:`~kinegami.geometry.csc.CSCPath` is arc 1
(radius r, turning by theta1 about k1 around the centre c1), the straight segment q1 -> q2 and
arc 2 (turning by theta2 about k2 around c2). Arc length sigma runs from 0 at p1 to the path
length at p2; lengths are in the units of r, frames are 4x4 world arrays whose first axis is the
tangent.

The *transported frame* at sigma is the start frame carried along the centreline without
rolling: on an arc it is turned about the arc's axis (so on arc 1 it is the frame after one
elbow of angle sigma / r, docs/theory/chain.md §3), on the straight part it is the frame at
the end of arc 1 moved along the tangent. On arc 2 it differs from the link's own arc-2 frames
by the link's twist angle (a roll about the tangent).
"""

from __future__ import annotations

import numpy as np

from kinegami.geometry.csc import CSCPath
from kinegami.geometry.frames import rotation_matrix

__all__ = ["csc_points", "csc_tangents", "csc_transported_frame", "csc_distances"]

#: Arcs turning less than this (radians) are treated as points.
_MIN_ARC = 1e-12


def _rotation_matrices(axis: np.ndarray, angles: np.ndarray) -> np.ndarray:
    """(m, 3, 3) rotations about the unit ``axis`` by each angle (Rodrigues, vectorised)."""
    k = np.asarray(axis, dtype=float)
    K = np.array([[0.0, -k[2], k[1]], [k[2], 0.0, -k[0]], [-k[1], k[0], 0.0]])
    s = np.sin(angles)[:, None, None]
    c = np.cos(angles)[:, None, None]
    return np.eye(3)[None] + s * K[None] + (1.0 - c) * (K @ K)[None]


def _pieces(path: CSCPath, sigma: np.ndarray):
    """Masks and local parameters of the three pieces for the arc lengths ``sigma``."""
    r = path.r
    l1 = r * path.theta1
    l2 = l1 + path.tMag
    in1 = sigma <= l1
    in2 = ~in1 & (sigma <= l2)
    in3 = ~in1 & ~in2
    return l1, l2, in1, in2, in3


def csc_points(path: CSCPath, sigma) -> np.ndarray:
    """(m, 3) centreline points at the arc lengths ``sigma`` (clipped to [0, length]).

    Examples
    --------
    >>> from kinegami.geometry.csc import solve_csc
    >>> p = solve_csc((0, 0, 0), (1, 0, 0), (10, 0, 0), (1, 0, 0), 1.0)
    >>> csc_points(p, [2.5]).round(6).tolist()
    [[2.5, 0.0, 0.0]]
    """
    sigma = np.clip(np.atleast_1d(np.asarray(sigma, dtype=float)), 0.0, path.length)
    r = path.r
    l1, l2, in1, in2, in3 = _pieces(path, sigma)
    out = np.empty((sigma.size, 3))
    if in1.any():
        R = _rotation_matrices(path.k1, sigma[in1] / r)
        out[in1] = path.c1 + R @ (path.p1 - path.c1)
    if in2.any():
        out[in2] = path.q1 + (sigma[in2] - l1)[:, None] * path.tUnit
    if in3.any():
        R = _rotation_matrices(path.k2, (sigma[in3] - l2) / r)
        out[in3] = path.c2 + R @ (path.q2 - path.c2)
    return out


def csc_tangents(path: CSCPath, sigma) -> np.ndarray:
    """(m, 3) unit tangents at the arc lengths ``sigma`` (clipped to [0, length])."""
    sigma = np.clip(np.atleast_1d(np.asarray(sigma, dtype=float)), 0.0, path.length)
    r = path.r
    l1, l2, in1, in2, in3 = _pieces(path, sigma)
    out = np.empty((sigma.size, 3))
    if in1.any():
        out[in1] = _rotation_matrices(path.k1, sigma[in1] / r) @ path.d1
    if in2.any():
        out[in2] = path.tUnit
    if in3.any():
        out[in3] = _rotation_matrices(path.k2, (sigma[in3] - l2) / r) @ path.tUnit
    return out


def csc_transported_frame(path: CSCPath, start: np.ndarray, sigma: float) -> np.ndarray:
    """The start frame transported to arc length ``sigma`` along the path (a new 4x4 array).

    ``start`` is the path's start Dubins frame (origin p1, first axis d1). For sigma <= r theta1
    this is the frame after one elbow of angle sigma / r (its rotation axis at the angle phi1 of
    arc 1); on the straight part it is F1 Trans(sigma - r theta1, 0, 0), F1 the frame at the end
    of arc 1; on arc 2, F1 Trans(tMag, 0, 0) turned about k2. ``sigma`` is clipped to
    [0, length].

    Examples
    --------
    >>> from kinegami.geometry.csc import solve_csc
    >>> p = solve_csc((0, 0, 0), (1, 0, 0), (10, 4, 0), (1, 0, 0), 1.0)
    >>> F = csc_transported_frame(p, np.eye(4), p.length)
    >>> bool(np.allclose(F[:3, 3], (10, 4, 0)) and np.allclose(F[:3, 0], (1, 0, 0)))
    True
    """
    sigma = float(min(max(sigma, 0.0), path.length))
    r = path.r
    l1 = r * path.theta1
    l2 = l1 + path.tMag
    F = np.array(start, dtype=float)
    R0 = F[:3, :3]
    if sigma <= l1:
        F[:3, :3] = rotation_matrix(path.k1, sigma / r) @ R0
    else:
        R1 = rotation_matrix(path.k1, path.theta1) @ R0
        if sigma <= l2:
            F[:3, :3] = R1
        else:
            F[:3, :3] = rotation_matrix(path.k2, (sigma - l2) / r) @ R1
    F[:3, 3] = csc_points(path, [sigma])[0]
    return F


def _arc_distances(
    points: np.ndarray, centre: np.ndarray, start: np.ndarray, axis: np.ndarray, theta: float
) -> np.ndarray:
    """Distance from each point to the circular arc from ``start`` turning by ``theta`` about
    ``axis`` around ``centre`` (closed form: the nearest point of the circle if it lies on the
    arc, else the nearer end)."""
    rho0 = start - centre
    radius = float(np.linalg.norm(rho0))
    end = centre + rotation_matrix(axis, theta) @ rho0
    d = points - centre
    h = d @ axis
    v = d - h[:, None] * axis
    nv = np.linalg.norm(v, axis=1)
    phi = np.arctan2(np.cross(rho0, v) @ axis, v @ rho0)
    phi = np.where(phi < 0.0, phi + 2.0 * np.pi, phi)
    on_arc = (phi <= theta) | (nv < 1e-300)
    to_circle = np.sqrt(h * h + (nv - radius) ** 2)
    to_ends = np.minimum(
        np.linalg.norm(points - start, axis=1), np.linalg.norm(points - end, axis=1)
    )
    return np.where(on_arc, to_circle, to_ends)


def _segment_distances(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    ab = b - a
    L2 = float(ab @ ab)
    if L2 <= 0.0:
        return np.linalg.norm(points - a, axis=1)
    t = np.clip((points - a) @ ab / L2, 0.0, 1.0)
    return np.linalg.norm(points - (a + t[:, None] * ab), axis=1)


def csc_distances(path: CSCPath, points) -> np.ndarray:
    """(m,) exact distance from each of the (m, 3) ``points`` to the path's centreline.

    Examples
    --------
    >>> from kinegami.geometry.csc import solve_csc
    >>> p = solve_csc((0, 0, 0), (1, 0, 0), (10, 0, 0), (1, 0, 0), 1.0)
    >>> csc_distances(p, [[5.0, 3.0, 4.0]]).tolist()
    [5.0]
    """
    points = np.atleast_2d(np.asarray(points, dtype=float))
    best = _segment_distances(points, path.q1, path.q2)
    if path.theta1 > _MIN_ARC:
        best = np.minimum(best, _arc_distances(points, path.c1, path.p1, path.k1, path.theta1))
    if path.theta2 > _MIN_ARC:
        best = np.minimum(best, _arc_distances(points, path.c2, path.q2, path.k2, path.theta2))
    return best
