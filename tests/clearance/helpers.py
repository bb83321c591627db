"""Chains through given frames, for hand-made clearance cases."""

from __future__ import annotations

import numpy as np

from kinegami import EndTip, KinematicChain, StartTip, Waypoint

FIXED = {"relative": False, "safe": False, "fixedPosition": True, "fixedOrientation": True}


def frame(p, x, up=(0.0, 0.0, 1.0)) -> np.ndarray:
    """A frame at ``p`` whose x axis is ``x`` and whose z axis is as close to ``up`` as can be."""
    x = np.asarray(x, dtype=float)
    x = x / np.linalg.norm(x)
    z = np.asarray(up, dtype=float)
    z = z - (z @ x) * x
    if np.linalg.norm(z) < 1e-9:
        z = np.array([0.0, 1.0, 0.0]) - x[1] * x
    z /= np.linalg.norm(z)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, p
    return T


def tip_pose(p, d) -> np.ndarray:
    """A tip's Pose at ``p`` whose path direction (z) is ``d``."""
    d = np.asarray(d, dtype=float)
    d = d / np.linalg.norm(d)
    a = np.array([1.0, 0.0, 0.0]) if abs(d[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = a - (a @ d) * d
    x /= np.linalg.norm(x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(d, x), d, p
    return T


def through(points, r=1.0, n=4, end=None, tip_length=1.5) -> KinematicChain:
    """A start tip at points[0] (position, direction), waypoints at the others (x = direction),
    and an end tip at ``end`` if given; every joint exactly where it is put."""
    (p0, d0), *rest = points
    chain = KinematicChain(StartTip(n, r, tip_pose(p0, d0), tip_length * r))
    for p, d in rest:
        assert chain.append(Waypoint(n, r, frame(p, d), pathIndex=0), **FIXED) is not None
    if end is not None:
        assert chain.append(EndTip(n, r, tip_pose(*end), 1.5 * r), **FIXED) is not None
    return chain
