"""Joint axes as screws, and forward kinematics as one vectorised product of exponentials
(docs/theory/kinematics.md).

A design at a reference configuration q_ref (its current states) is compiled into arrays: per
joint its kind (:data:`FIXED`, :data:`REVOLUTE`, :data:`PRISMATIC`), the unit direction of its
axis and a point on it (world frame, at q_ref), and its parent (``j - 1`` in a chain, -1 for
the root). Joint j moves everything downstream of it by the screw motion

* G_j(d) = RotLine(axis_j, point_j, d) for a revolute joint (d radians),
* G_j(d) = Trans(d axis_j) for a prismatic joint (d length units),
* the identity for the other joints (tips, waypoints),

where d = q_j - q_ref_j. Everything downstream of joint j's motion (its distal frame, the link
after it, the joints beyond) is moved from its place at q_ref by the product along the path
from the root, A_j(q) = A_parent(j)(q) G_j(d_j) (the space form of the product of
exponentials, with the axes at q_ref); joint j's own pose and proximal side move by
A_parent(j)(q). ``KinematicChain.setJointStates`` applies the same motions joint by joint.

Every function works on a batch of K configurations at once: ``q`` has shape (K, J) (or (J,)
for one), and the results have a leading K axis. Pure numpy on plain arrays.
"""

from __future__ import annotations

import numpy as np

__all__ = [
    "FIXED",
    "REVOLUTE",
    "PRISMATIC",
    "screw_motions",
    "path_products",
    "forward_kinematics",
    "world_axes",
]

#: Joint kinds: a joint that does not move (tip, waypoint), a rotation about its axis, a
#: slide along it.
FIXED, REVOLUTE, PRISMATIC = 0, 1, 2


def _configurations(q, joints: int) -> tuple[np.ndarray, bool]:
    """``q`` as a (K, J) float array, and whether it was one configuration (J,)."""
    q = np.asarray(q, dtype=float)
    single = q.ndim == 1
    q = q[None, :] if single else q
    if q.ndim != 2 or q.shape[1] != joints:
        raise ValueError(f"configurations must have shape ({joints},) or (K, {joints}), "
                         f"got {q.shape}")  # fmt: skip
    return q, single


def screw_motions(kinds, axes, points, d) -> np.ndarray:
    """G_j(d_j) of every joint, shape (K, J, 4, 4) for displacements ``d`` (K, J) from the
    reference configuration ((J,) gives (J, 4, 4)).

    ``kinds`` (J,), ``axes`` (J, 3) unit directions, ``points`` (J, 3) points on the axes.
    Revolute motions are Rodrigues rotations about the line; prismatic ones translations
    along the axis; the others the identity.
    """
    kinds = np.asarray(kinds)
    axes = np.asarray(axes, dtype=float)
    points = np.asarray(points, dtype=float)
    d, single = _configurations(d, kinds.shape[0])
    K, J = d.shape
    G = np.zeros((K, J, 4, 4))
    G[..., 0, 0] = G[..., 1, 1] = G[..., 2, 2] = G[..., 3, 3] = 1.0
    revolute = np.flatnonzero(kinds == REVOLUTE)
    if revolute.size:
        k = axes[revolute]  # (R, 3)
        cross = np.zeros((revolute.size, 3, 3))
        cross[:, 0, 1], cross[:, 0, 2] = -k[:, 2], k[:, 1]
        cross[:, 1, 0], cross[:, 1, 2] = k[:, 2], -k[:, 0]
        cross[:, 2, 0], cross[:, 2, 1] = -k[:, 1], k[:, 0]
        angle = d[:, revolute]  # (K, R)
        s = np.sin(angle)[..., None, None]
        c = (1.0 - np.cos(angle))[..., None, None]
        R = np.eye(3) + s * cross + c * (cross @ cross)  # (K, R, 3, 3)
        p = points[revolute]
        block = np.empty((K, revolute.size, 3, 4))  # [R | p - R p], one index array only
        block[..., :3] = R
        block[..., 3] = p - np.einsum("krij,rj->kri", R, p)
        G[:, revolute, :3, :] = block
    prismatic = np.flatnonzero(kinds == PRISMATIC)
    if prismatic.size:
        block = np.zeros((K, prismatic.size, 3, 4))
        block[..., 0, 0] = block[..., 1, 1] = block[..., 2, 2] = 1.0
        block[..., 3] = d[:, prismatic, None] * axes[prismatic]
        G[:, prismatic, :3, :] = block
    return G[0] if single else G


def path_products(motions: np.ndarray, parents) -> np.ndarray:
    """A_j = A_parent(j) G_j for every joint (A of the root's parent: the identity), from the
    motions G (K, J, 4, 4) or (J, 4, 4); ``parents[j] < j`` (-1 for a root)."""
    motions = np.asarray(motions, dtype=float)
    parents = np.asarray(parents)
    A = np.empty_like(motions)
    for j in range(parents.shape[0]):
        p = int(parents[j])
        G = motions[..., j, :, :]
        A[..., j, :, :] = G if p < 0 else A[..., p, :, :] @ G
    return A


def forward_kinematics(kinds, axes, points, parents, q, q_ref) -> np.ndarray:
    """A_j(q) of every joint j, shape (K, J, 4, 4) (or (J, 4, 4) for one configuration):
    the world motion of everything downstream of joint j from the reference configuration
    ``q_ref`` (J,) to ``q``. A frame F downstream of joint j is at ``A_j(q) @ F(q_ref)``."""
    q, single = _configurations(q, np.asarray(kinds).shape[0])
    d = q - np.asarray(q_ref, dtype=float)[None, :]
    A = path_products(screw_motions(kinds, axes, points, d), parents)
    return A[0] if single else A


def world_axes(kinds, axes, points, parents, A: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Every joint's axis direction and point at the configurations of ``A`` (the output of
    :func:`forward_kinematics`): joint j's axis moves with its parent's motion. Returns
    (directions, points), each of shape A.shape[:-2] + (3,)."""
    parents = np.asarray(parents)
    axes = np.asarray(axes, dtype=float)
    points = np.asarray(points, dtype=float)
    lead = A.shape[:-3]
    J = parents.shape[0]
    upstream = np.broadcast_to(np.eye(4), lead + (J, 4, 4)).copy()
    has = parents >= 0
    upstream[..., has, :, :] = A[..., parents[has], :, :]
    R, t = upstream[..., :3, :3], upstream[..., :3, 3]
    directions = np.einsum("...ij,...j->...i", R, np.broadcast_to(axes, lead + (J, 3)))
    moved = np.einsum("...ij,...j->...i", R, np.broadcast_to(points, lead + (J, 3))) + t
    return directions, moved
