"""Lines and the common normal of two axes (docs/theory/placement.md §3)."""

from __future__ import annotations

import math

import numpy as np

from kinegami.geometry.frames import cross3


def common_normal(p_from, z_from, p_to, z_to, tol: float) -> np.ndarray | None:
    """Unit common normal from the line (p_from, z_from) to the line (p_to, z_to).

    It points from the first line towards the second. Returns None when undefined:
    coincident axes, or axes that intersect (the normal would have no preferred sign).
    ``tol`` is a length tolerance (scaled by r by the caller); the direction tests use
    1e-9 (docs/theory/placement.md §3: no exact-zero tests).
    """
    v = np.asarray(p_to, dtype=float) - np.asarray(p_from, dtype=float)
    z1 = np.asarray(z_from, dtype=float)
    c = cross3(z1, np.asarray(z_to, dtype=float))
    nc = math.sqrt(float(c.dot(c)))
    if nc > 1e-9:
        n = c / nc
    else:
        q = cross3(z1, cross3(v, z1))
        nq = math.sqrt(float(q.dot(q)))
        if nq <= tol:
            return None
        n = q / nq
    side = float(v @ n)
    if side > tol:
        return n
    if side < -tol:
        return -n
    return None
