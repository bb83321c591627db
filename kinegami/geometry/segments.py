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

__all__ = ["point_segment_parameters", "segment_distances", "capsule_distances"]

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


def _lerp(a: np.ndarray, d: np.ndarray, s: np.ndarray) -> np.ndarray:
    return a + s[..., None] * d


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
    d1 = b1 - a1
    d2 = b2 - a2
    w = a1 - a2
    A = np.einsum("...i,...i->...", d1, d1)
    E = np.einsum("...i,...i->...", d2, d2)
    B = np.einsum("...i,...i->...", d1, d2)
    C = np.einsum("...i,...i->...", d1, w)
    F = np.einsum("...i,...i->...", d2, w)
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
    best = np.linalg.norm(_lerp(a1, d1, s) - _lerp(a2, d2, t), axis=-1)
    # the four end-point-to-segment candidates (the edges of the parameter square)
    for point_on_first, fixed in ((True, 0.0), (True, 1.0), (False, 0.0), (False, 1.0)):
        if point_on_first:
            p = a1 if fixed == 0.0 else b1
            tc = point_segment_parameters(p, a2, b2)
            sc = np.full_like(tc, fixed)
        else:
            p = a2 if fixed == 0.0 else b2
            sc = point_segment_parameters(p, a1, b1)
            tc = np.full_like(sc, fixed)
        dist = np.linalg.norm(_lerp(a1, d1, sc) - _lerp(a2, d2, tc), axis=-1)
        better = dist < best
        best = np.where(better, dist, best)
        s = np.where(better, sc, s)
        t = np.where(better, tc, t)
    return best, s, t


def capsule_distances(a1, b1, r1, a2, b2, r2) -> np.ndarray:
    """Signed distance between capsules: segment distance minus both radii (< 0: overlap)."""
    distance, _, _ = segment_distances(a1, b1, a2, b2)
    return distance - np.asarray(r1, dtype=float) - np.asarray(r2, dtype=float)
