"""Distances between line segments, vectorised over many pairs (docs/clearance.md).

A segment is given by its two end points ``a`` and ``b`` (arrays of shape (..., 3)); the point
at parameter ``s`` in [0, 1] is ``a + s (b - a)``. A capsule is a segment with a radius: the
distance between two capsules is the segment distance minus both radii.

The solver is exact and robust: the squared distance is a convex quadratic in (s, t) on the
unit square, so its minimum is either the interior critical point or lies on an edge of the
square, where it is a point-to-segment distance. :func:`segment_distances` evaluates the
clamped critical point (Ericson's method, one more alternation for the clamped cases) and the
four end-point-to-segment distances and keeps the smallest, so parallel, overlapping and
degenerate (zero-length) segments need no special case beyond guarding the divisions.
"""

from __future__ import annotations

import math

import numpy as np

__all__ = [
    "point_segment_parameters",
    "segment_distances",
    "segment_distances_xyz",
    "segment_distances_stacked",
    "segment_distance",
    "capsule_distances",
]

#: Segments shorter than this (squared, relative to the squared scale of the pair) are points.
_DEGENERATE = 1e-30

#: The dot products of :func:`segment_distances_stacked`, as rows of its differences (b1 - a1,
#: b2 - a2, a1 - a2, b1 - a2, b2 - a1): A, E, B, C, F and the numerators of b1 and b2.
_DOT_LEFT = np.array([0, 1, 0, 0, 1, 3, 4])
_DOT_RIGHT = np.array([0, 1, 1, 2, 2, 1, 0])
#: The numerators of the end-point candidates among those dot products (a1: F; a2: -C).
_NUMERATORS = np.array([4, 5, 2, 6])


def point_segment_parameters(points, a, b) -> np.ndarray:
    """Parameter t in [0, 1] of the point of segment (a, b) nearest to each of ``points``.

    All arguments broadcast, shape (..., 3); returns shape (...). A zero-length segment gives 0.
    """
    points = np.asarray(points, dtype=float)
    a = np.asarray(a, dtype=float)
    d = np.asarray(b, dtype=float) - a
    dd = np.einsum("...i,...i->...", d, d)
    num = np.einsum("...i,...i->...", points - a, d)
    safe = np.where(dd > _DEGENERATE, dd, 1.0)
    return np.where(dd > _DEGENERATE, np.clip(num / safe, 0.0, 1.0), 0.0)


def segment_distances(a1, b1, a2, b2) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """Distance between segment (a1, b1) and segment (a2, b2), for every pair at once.

    Parameters
    ----------
    a1, b1, a2, b2 : array_like, shape (..., 3)
        End points; they broadcast against each other.

    Returns
    -------
    distance : numpy.ndarray, shape (...)
        The smallest distance between a point of the first and a point of the second segment.
    s, t : numpy.ndarray, shape (...)
        Parameters in [0, 1] of a pair of closest points: ``a1 + s (b1 - a1)`` and
        ``a2 + t (b2 - a2)``.

    Examples
    --------
    >>> d, s, t = segment_distances([0, 0, 0], [2, 0, 0], [1, 1, 0], [1, 3, 0])
    >>> float(d), float(s), float(t)
    (1.0, 0.5, 0.0)
    """
    a1, b1, a2, b2 = np.broadcast_arrays(
        *(np.asarray(x, dtype=float) for x in (a1, b1, a2, b2))
    )
    shape = a1.shape[:-1]
    found = segment_distances_stacked(*(x.reshape(-1, 3).T for x in (a1, b1, a2, b2)))
    return tuple(x.reshape(shape) for x in found)


def segment_distances_xyz(a1, b1, a2, b2) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The segment distances of :func:`segment_distances` on end points given as three
    coordinate arrays each (``a1 = (x, y, z)``, 1-D arrays of one length). Returns
    ``(distance, s, t)``."""
    return segment_distances_stacked(*(np.array(p, dtype=float) for p in (a1, b1, a2, b2)))


#: Pairs the kernel measures at once: its temporaries (up to 21 values a pair) stay in cache
#: (twice as fast as one pass over 37,000 pairs).
_KERNEL_PAIRS = 8192


def segment_distances_stacked(a1, b1, a2, b2) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The kernel of :func:`segment_distances` on end points given as (3, n) arrays (rows x,
    y and z; views are fine), in few numpy calls whatever n (in slices of _KERNEL_PAIRS).
    Returns ``(distance, s, t)``, each (n,)."""
    n = np.shape(a1)[-1]
    if n <= _KERNEL_PAIRS:
        return _segment_kernel(a1, b1, a2, b2)
    out = np.empty((3, n))
    for lo in range(0, n, _KERNEL_PAIRS):
        part = slice(lo, lo + _KERNEL_PAIRS)
        out[:, part] = _segment_kernel(a1[:, part], b1[:, part], a2[:, part], b2[:, part])
    return out[0], out[1], out[2]


def _segment_kernel(a1, b1, a2, b2) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """:func:`segment_distances_stacked` on one slice."""
    # b1 - a1, b2 - a2, a1 - a2, b1 - a2 and b2 - a1 at once
    v = np.array([b1, b2, a1, b1, b2]) - np.array([a1, a2, a2, a2, a1])
    # seven dot products at once, each summed (x + z) + y as numpy.einsum sums (..., 3):
    # A = d1.d1, E = d2.d2, B = d1.d2, C = d1.w, F = d2.w (w = a1 - a2), and the numerators
    # of b1 against the second segment and b2 against the first
    prod = v[_DOT_LEFT] * v[_DOT_RIGHT]
    dots = (prod[:, 0] + prod[:, 2]) + prod[:, 1]
    A, E, B, C, F = dots[:5]
    if A.min(initial=math.inf) > _DEGENERATE and E.min(initial=math.inf) > _DEGENERATE:
        ok1 = ok2 = None  # no segment is a point: no guard needed
        A_safe, E_safe = A, E
        denom = A * E - B * B
        proper = denom > 1e-14 * A * E
    else:
        ok1 = A > _DEGENERATE
        ok2 = E > _DEGENERATE
        A_safe = np.where(ok1, A, 1.0)
        E_safe = np.where(ok2, E, 1.0)
        denom = A * E - B * B
        proper = ok1 & ok2 & (denom > 1e-14 * A_safe * E_safe)
    s = np.where(proper, (B * F - C * E) / np.where(proper, denom, 1.0), 0.0).clip(0.0, 1.0)
    t = ((B * s + F) / E_safe).clip(0.0, 1.0)
    if ok2 is not None:
        t = np.where(ok2, t, 0.0)
    s = ((B * t - C) / A_safe).clip(0.0, 1.0)
    if ok1 is not None:
        s = np.where(ok1, s, 0.0)
    t = ((B * s + F) / E_safe).clip(0.0, 1.0)
    # the four end-point-to-segment candidates at once: a1 and b1 against the second
    # segment, a2 and b2 against the first (point_segment_parameters' arithmetic; the
    # numerator of a2 is -C exactly)
    num = dots[_NUMERATORS]
    num[2] = -C
    u = (num / np.array([E_safe, E_safe, A_safe, A_safe])).clip(0.0, 1.0)
    if ok1 is not None:
        u = np.where(np.array([ok2, ok2, ok1, ok1]), u, 0.0)
    S = np.empty((5, A.size))
    T = np.empty((5, A.size))
    S[0], S[1], S[2], S[3:] = s, 0.0, 1.0, u[2:]
    T[0], T[1:3], T[3], T[4] = t, u[:2], 0.0, 1.0
    # the first smallest of the critical point and the four, in that order
    e = (a1[:, None] + S * v[0][:, None]) - (a2[:, None] + T * v[1][:, None])
    e *= e
    every = np.sqrt((e[0] + e[1]) + e[2])  # numpy.linalg.norm's order
    pick = every.argmin(axis=0)
    at = np.arange(pick.size)
    return every[pick, at], S[pick, at], T[pick, at]


def _unit(x: float) -> float:
    """``x`` clamped to [0, 1] as numpy.clip does it (-0.0 stays -0.0)."""
    x = x if x >= 0.0 else 0.0
    return x if x <= 1.0 else 1.0


def segment_distance(a1, b1, a2, b2) -> tuple[float, float, float]:
    """One pair of :func:`segment_distances` in plain floats (end points: three floats each),
    the same arithmetic step by step, so the same bits: faster than numpy for a few pairs.
    Returns ``(distance, s, t)``."""
    ax, ay, az = a1
    bx, by, bz = b1
    cx, cy, cz = a2
    ex, ey, ez = b2
    ux, uy, uz = bx - ax, by - ay, bz - az  # b1 - a1
    vx, vy, vz = ex - cx, ey - cy, ez - cz  # b2 - a2
    wx, wy, wz = ax - cx, ay - cy, az - cz  # a1 - a2
    A = (ux * ux + uz * uz) + uy * uy
    E = (vx * vx + vz * vz) + vy * vy
    B = (ux * vx + uz * vz) + uy * vy
    C = (ux * wx + uz * wz) + uy * wy
    F = (vx * wx + vz * wz) + vy * wy
    ok1 = A > _DEGENERATE
    ok2 = E > _DEGENERATE
    # every parameter clamped to [0, 1] as _unit does it, inline
    if ok1 and ok2:
        denom = A * E - B * B
        if denom > 1e-14 * A * E:
            s = (B * F - C * E) / denom
            s = (s if s <= 1.0 else 1.0) if s >= 0.0 else 0.0
        else:
            s = 0.0
        t = (B * s + F) / E
        t = (t if t <= 1.0 else 1.0) if t >= 0.0 else 0.0
        s = (B * t - C) / A
        s = (s if s <= 1.0 else 1.0) if s >= 0.0 else 0.0
        t = (B * s + F) / E
        t = (t if t <= 1.0 else 1.0) if t >= 0.0 else 0.0
        u0 = ((wx * vx + wz * vz) + wy * vy) / E
        u0 = (u0 if u0 <= 1.0 else 1.0) if u0 >= 0.0 else 0.0
        px, py, pz = bx - cx, by - cy, bz - cz  # b1 - a2
        u1 = ((px * vx + pz * vz) + py * vy) / E
        u1 = (u1 if u1 <= 1.0 else 1.0) if u1 >= 0.0 else 0.0
        px, py, pz = cx - ax, cy - ay, cz - az  # a2 - a1
        u2 = ((px * ux + pz * uz) + py * uy) / A
        u2 = (u2 if u2 <= 1.0 else 1.0) if u2 >= 0.0 else 0.0
        px, py, pz = ex - ax, ey - ay, ez - az  # b2 - a1
        u3 = ((px * ux + pz * uz) + py * uy) / A
        u3 = (u3 if u3 <= 1.0 else 1.0) if u3 >= 0.0 else 0.0
    else:  # a segment is a point
        return _segment_distance_guarded(a1, b1, a2, b2)
    sqrt = math.sqrt
    gx = (ax + s * ux) - (cx + t * vx)
    gy = (ay + s * uy) - (cy + t * vy)
    gz = (az + s * uz) - (cz + t * vz)
    best, p, q = sqrt((gx * gx + gy * gy) + gz * gz), s, t
    gx = (ax + 0.0 * ux) - (cx + u0 * vx)
    gy = (ay + 0.0 * uy) - (cy + u0 * vy)
    gz = (az + 0.0 * uz) - (cz + u0 * vz)
    d = sqrt((gx * gx + gy * gy) + gz * gz)
    if d < best:
        best, p, q = d, 0.0, u0
    gx = (ax + 1.0 * ux) - (cx + u1 * vx)
    gy = (ay + 1.0 * uy) - (cy + u1 * vy)
    gz = (az + 1.0 * uz) - (cz + u1 * vz)
    d = sqrt((gx * gx + gy * gy) + gz * gz)
    if d < best:
        best, p, q = d, 1.0, u1
    gx = (ax + u2 * ux) - (cx + 0.0 * vx)
    gy = (ay + u2 * uy) - (cy + 0.0 * vy)
    gz = (az + u2 * uz) - (cz + 0.0 * vz)
    d = sqrt((gx * gx + gy * gy) + gz * gz)
    if d < best:
        best, p, q = d, u2, 0.0
    gx = (ax + u3 * ux) - (cx + 1.0 * vx)
    gy = (ay + u3 * uy) - (cy + 1.0 * vy)
    gz = (az + u3 * uz) - (cz + 1.0 * vz)
    d = sqrt((gx * gx + gy * gy) + gz * gz)
    if d < best:
        best, p, q = d, u3, 1.0
    return best, p, q


def _segment_distance_guarded(a1, b1, a2, b2) -> tuple[float, float, float]:
    """:func:`segment_distance` with the guards of a segment that is a point."""
    ax, ay, az = a1
    bx, by, bz = b1
    cx, cy, cz = a2
    ex, ey, ez = b2
    ux, uy, uz = bx - ax, by - ay, bz - az  # b1 - a1
    vx, vy, vz = ex - cx, ey - cy, ez - cz  # b2 - a2
    wx, wy, wz = ax - cx, ay - cy, az - cz  # a1 - a2
    A = (ux * ux + uz * uz) + uy * uy
    E = (vx * vx + vz * vz) + vy * vy
    B = (ux * vx + uz * vz) + uy * vy
    C = (ux * wx + uz * wz) + uy * wy
    F = (vx * wx + vz * wz) + vy * wy
    ok1 = A > _DEGENERATE
    ok2 = E > _DEGENERATE
    A_safe = A if ok1 else 1.0
    E_safe = E if ok2 else 1.0
    denom = A * E - B * B
    proper = ok1 and ok2 and denom > 1e-14 * A_safe * E_safe
    s = _unit((B * F - C * E) / denom) if proper else 0.0
    t = _unit((B * s + F) / E_safe) if ok2 else 0.0
    s = _unit((B * t - C) / A_safe) if ok1 else 0.0
    t = _unit((B * s + F) / E_safe) if ok2 else 0.0
    u0 = _unit(((wx * vx + wz * vz) + wy * vy) / E_safe) if ok2 else 0.0
    px, py, pz = bx - cx, by - cy, bz - cz  # b1 - a2
    u1 = _unit(((px * vx + pz * vz) + py * vy) / E_safe) if ok2 else 0.0
    px, py, pz = cx - ax, cy - ay, cz - az  # a2 - a1
    u2 = _unit(((px * ux + pz * uz) + py * uy) / A_safe) if ok1 else 0.0
    px, py, pz = ex - ax, ey - ay, ez - az  # b2 - a1
    u3 = _unit(((px * ux + pz * uz) + py * uy) / A_safe) if ok1 else 0.0
    best = (math.inf, 0.0, 0.0)
    for p, q in ((s, t), (0.0, u0), (1.0, u1), (u2, 0.0), (u3, 1.0)):
        gx = (ax + p * ux) - (cx + q * vx)
        gy = (ay + p * uy) - (cy + q * vy)
        gz = (az + p * uz) - (cz + q * vz)
        d = math.sqrt((gx * gx + gy * gy) + gz * gz)
        if d < best[0]:  # the first smallest, as numpy.argmin
            best = (d, p, q)
    return best


def capsule_distances(a1, b1, r1, a2, b2, r2) -> np.ndarray:
    """Signed distance between capsules: segment distance minus both radii (< 0: overlap)."""
    distance, _, _ = segment_distances(a1, b1, a2, b2)
    return distance - np.asarray(r1, dtype=float) - np.asarray(r2, dtype=float)
