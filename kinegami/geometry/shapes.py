"""Plain shapes of the tube's cross sections (world coordinates; pure numpy): the regular n-gon
of circumradius r in a Dubins frame, points on a circle, a hinge segment, a frame moved along its
path direction. Joints build their solids from them (docs/clearance.md)."""

from __future__ import annotations

import math

import numpy as np

__all__ = ["polygon_side", "circle_points", "regular_polygon", "hinge_segment", "shifted_frame"]


def polygon_side(r: float, n: int) -> float:
    """Side length 2 r sin(pi/n) of the regular n-gon of circumradius r."""
    return 2.0 * r * math.sin(math.pi / n)


def circle_points(centre, e1, e2, r: float, angles) -> np.ndarray:
    """Points ``centre + r (cos t e1 + sin t e2)`` for each t in ``angles``, shape (m, 3)."""
    t = np.asarray(angles, dtype=float)[:, None]
    return (
        np.asarray(centre, dtype=float)
        + r * np.cos(t) * np.asarray(e1, dtype=float)
        + r * np.sin(t) * np.asarray(e2, dtype=float)
    )


def regular_polygon(frame: np.ndarray, r: float, n: int) -> np.ndarray:
    """(n, 3) vertices of the n-gon of circumradius ``r`` in the (b, c) plane of ``frame``.

    ``frame`` is a 4x4 Dubins frame (first axis = path direction); the polygon is centred at
    its origin and its vertex k lies at angle pi/n + 2 pi k/n from the frame's b axis, so two
    sides are parallel to c (the revolute hinge line, the fold of a tip).
    """
    psi = math.pi / n + 2.0 * math.pi * np.arange(n) / n
    return circle_points(frame[:3, 3], frame[:3, 1], frame[:3, 2], r, psi)


def hinge_segment(centre, direction, length: float) -> np.ndarray:
    """(2, 3): the segment of ``length`` centred at ``centre`` along unit ``direction``."""
    d = 0.5 * length * np.asarray(direction, dtype=float)
    return np.stack([centre - d, centre + d])


def shifted_frame(frame: np.ndarray, distance: float) -> np.ndarray:
    """``frame`` translated along its own first axis."""
    out = np.array(frame)
    out[:3, 3] += distance * frame[:3, 0]
    return out
