"""Rigid transforms and angles on plain numpy arrays (docs/theory/chain.md §0).

Frames are 4x4 homogeneous matrices ``T = [[R, p], [0, 1]]`` whose rotation columns are the frame
axes (x, y, z) in world coordinates and whose translation is the frame origin. "Transform F by T"
means ``T @ F`` (T in world coordinates). Angles are radians.
"""

from __future__ import annotations

import math

import numpy as np

#: Angles within this of 2*pi wrap to 0 (docs/theory/chain.md §0).
WRAP_SNAP = 1e-5


_EYE3 = np.eye(3)
_LAST_ROW = np.array([0.0, 0.0, 0.0, 1.0])


def cross3(a, b) -> np.ndarray:
    """a x b of two 3-vectors: np.cross's arithmetic (bit for bit), without its per-call
    overhead (about 20x faster on single vectors, which the CSC solver builds by thousands)."""
    a0, a1, a2 = float(a[0]), float(a[1]), float(a[2])
    b0, b1, b2 = float(b[0]), float(b[1]), float(b[2])
    return np.array([a1 * b2 - a2 * b1, a2 * b0 - a0 * b2, a0 * b1 - a1 * b0])


def translation(v) -> np.ndarray:
    """Trans(v): the 4x4 translation by the 3-vector ``v``."""
    T = np.eye(4)
    T[:3, 3] = v
    return T


def rotation_matrix(axis, angle: float) -> np.ndarray:
    """Rot(k, angle) as a 3x3 matrix (Rodrigues); the axis is normalised, zero gives identity."""
    k = np.asarray(axis, dtype=float)
    norm = math.sqrt(k[0] * k[0] + k[1] * k[1] + k[2] * k[2])
    if norm == 0.0:
        return np.eye(3)
    x, y, z = k / norm
    c, s = math.cos(angle), math.sin(angle)
    C = 1.0 - c
    return np.array(
        [
            [c + x * x * C, x * y * C - z * s, x * z * C + y * s],
            [y * x * C + z * s, c + y * y * C, y * z * C - x * s],
            [z * x * C - y * s, z * y * C + x * s, c + z * z * C],
        ]
    )


def rotation(axis, angle: float) -> np.ndarray:
    """Rot(k, angle) as a 4x4 transform about an axis through the origin."""
    T = np.eye(4)
    T[:3, :3] = rotation_matrix(axis, angle)
    return T


def rot_x(angle: float) -> np.ndarray:
    """Rx(angle) as 4x4."""
    return rotation((1.0, 0.0, 0.0), angle)


def rot_y(angle: float) -> np.ndarray:
    """Ry(angle) as 4x4."""
    return rotation((0.0, 1.0, 0.0), angle)


def rot_z(angle: float) -> np.ndarray:
    """Rz(angle) as 4x4."""
    return rotation((0.0, 0.0, 1.0), angle)


def rotation_about_line(axis, point, angle: float) -> np.ndarray:
    """RotLine(k, q, angle): rotation by ``angle`` about the line through q along k."""
    T = rotation(axis, angle)
    q = np.asarray(point, dtype=float)
    T[:3, 3] = q - T[:3, :3] @ q
    return T


def inverse(T: np.ndarray) -> np.ndarray:
    """Inverse of a rigid transform."""
    R = T[:3, :3]
    out = np.eye(4)
    out[:3, :3] = R.T
    out[:3, 3] = -R.T @ T[:3, 3]
    return out


def is_rigid_transform(T, tol: float = 1e-9) -> bool:
    """True if ``T`` is a finite 4x4 proper rigid transform (orthonormal, det +1, last row 0001)."""
    T = np.asarray(T)
    if T.shape != (4, 4) or not np.all(np.isfinite(T)):
        return False
    R = T[:3, :3]
    if not float(np.abs(R.T @ R - _EYE3).max()) <= tol:  # np.allclose(..., rtol=0), cheaper
        return False
    if abs(np.linalg.det(R) - 1.0) > tol:
        return False
    return float(np.abs(T[3] - _LAST_ROW).max()) <= tol


def unit(v) -> np.ndarray:
    """v / |v| (raises ZeroDivisionError-free: returns zeros for a zero vector)."""
    v = np.asarray(v, dtype=float)
    n = math.sqrt(float(v @ v))
    return v / n if n > 0.0 else np.zeros_like(v)


def angle_between(a, b) -> float:
    """Unsigned angle in [0, pi] between two vectors (atan2 of |a x b| and a.b)."""
    a = np.asarray(a, dtype=float)
    b = np.asarray(b, dtype=float)
    return math.atan2(float(np.linalg.norm(cross3(a, b))), float(a @ b))


def signed_angle(a, b, normal) -> float:
    """signedAngle(a, b, n): atan2((a x b).n, a.b) of the normalised vectors.

    See docs/theory/chain.md §0.
    """
    a = unit(a)
    b = unit(b)
    n = unit(normal)
    return math.atan2(float(cross3(a, b) @ n), float(a @ b))


def wrap_angle(angle: float) -> float:
    """angle mod 2pi in [0, 2pi), snapping values within WRAP_SNAP of 2pi to 0."""
    w = angle % (2.0 * math.pi)
    if 2.0 * math.pi - w < WRAP_SNAP:
        return 0.0
    return w


def any_perpendicular(a, b=None) -> np.ndarray:
    """A unit vector orthogonal to ``a`` (and to ``b`` if given): unit(a x b) when nonzero.

    In the degenerate case (b parallel to a, or not given) it returns a deterministic unit
    vector orthogonal to ``a``: the cross product with the world axis least aligned with ``a``.
    """
    a = np.asarray(a, dtype=float)
    if b is not None:
        c = cross3(a, np.asarray(b, dtype=float))
        n = float(np.linalg.norm(c))
        if n > 1e-12:
            return c / n
    axis = np.zeros(3)
    axis[int(np.argmin(np.abs(a)))] = 1.0
    return unit(cross3(a, axis))


def dubins_frame(T: np.ndarray, path_index: int) -> np.ndarray:
    """The Dubins frame of ``T``: axes cyclically permuted so the first is column ``path_index``."""
    if path_index == 0:
        return T.copy()
    out = T.copy()
    k = path_index
    out[:3, 0] = T[:3, k]
    out[:3, 1] = T[:3, (k + 1) % 3]
    out[:3, 2] = T[:3, (k + 2) % 3]
    return out
