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

import numpy as np

__all__ = [
    "point_segment_parameters",
    "segment_distances",
    "segment_distances_xyz",
    "capsule_distances",
]

#: Segments shorter than this (squared, relative to the squared scale of the pair) are points.
_DEGENERATE = 1e-30


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
    found = segment_distances_xyz(
        *(tuple(x.reshape(-1, 3)[:, c] for c in range(3)) for x in (a1, b1, a2, b2))
    )
    return tuple(x.reshape(shape) for x in found)


def _dot(x1, y1, z1, x2, y2, z2):
    return (x1 * x2 + z1 * z2) + y1 * y2  # the order numpy.einsum sums (..., 3) in


def segment_distances_xyz(a1, b1, a2, b2) -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The segment distances of :func:`segment_distances` on end points given as three
    coordinate arrays each (``a1 = (x, y, z)``, 1-D arrays of one length): the kernel both
    layouts use, without the (..., 3) layout's copies. Returns ``(distance, s, t)``."""
    d1 = [q - p for p, q in zip(a1, b1, strict=True)]
    d2 = [q - p for p, q in zip(a2, b2, strict=True)]
    w = [p - q for p, q in zip(a1, a2, strict=True)]
    A, E, B = _dot(*d1, *d1), _dot(*d2, *d2), _dot(*d1, *d2)
    C, F = _dot(*d1, *w), _dot(*d2, *w)
    ok1 = A > _DEGENERATE
    ok2 = E > _DEGENERATE
    A_safe = np.where(ok1, A, 1.0)
    E_safe = np.where(ok2, E, 1.0)
    denom = A * E - B * B
    proper = ok1 & ok2 & (denom > 1e-14 * A_safe * E_safe)
    with np.errstate(invalid="ignore", divide="ignore"):
        s = np.where(proper, (B * F - C * E) / np.where(proper, denom, 1.0), 0.0)
    s = np.clip(s, 0.0, 1.0)
    t = np.where(ok2, np.clip((B * s + F) / E_safe, 0.0, 1.0), 0.0)
    s = np.where(ok1, np.clip((B * t - C) / A_safe, 0.0, 1.0), 0.0)
    t = np.where(ok2, np.clip((B * s + F) / E_safe, 0.0, 1.0), 0.0)

    def gap(s, t):
        e = [(p + s * u) - (q + t * v) for p, u, q, v in zip(a1, d1, a2, d2, strict=True)]
        return np.sqrt((e[0] * e[0] + e[1] * e[1]) + e[2] * e[2])  # numpy.linalg.norm's order

    # the four end-point-to-segment candidates at once: a1 and b1 against the second
    # segment, a2 and b2 against the first (point_segment_parameters' arithmetic)
    point = [np.stack(c) for c in zip(a1, b1, a2, b2, strict=True)]
    base = [np.stack(c) for c in zip(a2, a2, a1, a1, strict=True)]
    along = [np.stack(c) for c in zip(d2, d2, d1, d1, strict=True)]
    dd, ok = np.stack([E, E, A, A]), np.stack([ok2, ok2, ok1, ok1])
    num = _dot(*(p - q for p, q in zip(point, base, strict=True)), *along)
    u = np.where(ok, np.clip(num / np.where(ok, dd, 1.0), 0.0, 1.0), 0.0)
    zero = np.zeros_like(A)
    sc = np.stack([zero, zero + 1.0, u[2], u[3]])
    tc = np.stack([u[0], u[1], zero, zero + 1.0])
    # the first smallest of the critical point and the four, in that order
    every = np.concatenate([gap(s, t)[None], gap(sc, tc)])
    pick = np.argmin(every, axis=0)
    at = np.arange(pick.size)
    s = np.concatenate([s[None], sc])[pick, at]
    t = np.concatenate([t[None], tc])[pick, at]
    return every[pick, at], s, t



def capsule_distances(a1, b1, r1, a2, b2, r2) -> np.ndarray:
    """Signed distance between capsules: segment distance minus both radii (< 0: overlap)."""
    distance, _, _ = segment_distances(a1, b1, a2, b2)
    return distance - np.asarray(r1, dtype=float) - np.asarray(r2, dtype=float)
