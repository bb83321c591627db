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
    "JointScrews",
    "rigid_product",
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


class JointScrews:
    """The joints of a chain or tree as screws about their axes at a reference configuration,
    compiled once: the world motion of every rigid body, or of everything downstream of every
    joint, at any batch of configurations.

    Rigid bodies: the base (0) and one per moving joint (revolute or prismatic), in joint
    order; a fixed joint (tip, waypoint) moves with its parent's body. Body b of moving joint
    m hangs from the body of m's parent: B_b(q) = B_parent(b)(q) G_m(q_m - q_ref_m).

    Parameters
    ----------
    kinds : (J,) FIXED, REVOLUTE or PRISMATIC per joint.
    axes, points : (J, 3) unit axis directions and points on the axes (world, at ``q_ref``).
    parents : (J,) parent index per joint (``parents[j] < j``; -1 for a root).
    q_ref : (J,) the reference configuration (radians or length units per joint).
    """

    __slots__ = ("kinds", "parents", "q_ref", "body_of", "moving", "body_parent", "bodies",
                 "chain_bodies", "revolute", "all_revolute", "axes", "points", "_K1", "_K2",
                 "_ref_moving", "_parent_list", "_elementary")

    def __init__(self, kinds, axes, points, parents, q_ref) -> None:
        kinds = np.asarray(kinds, dtype=np.int64)
        parents = np.asarray(parents, dtype=np.int64)
        J = kinds.shape[0]
        body_of = np.zeros(J, dtype=np.int64)
        moving, body_parent = [], [-1]
        for k in range(J):
            p = int(parents[k])
            base = int(body_of[p]) if p >= 0 else 0
            if kinds[k] != FIXED:
                body_of[k] = len(body_parent)
                moving.append(k)
                body_parent.append(base)
            else:
                body_of[k] = base
        self.kinds, self.parents = kinds, parents
        self.q_ref = np.asarray(q_ref, dtype=float)
        #: (J,) the body that joint j's distal side moves with.
        self.body_of = body_of
        #: (M,) the moving joints, in index order (joint moving[b - 1] moves body b).
        self.moving = np.array(moving, dtype=np.int64)
        #: (M + 1,) each body's parent body (-1 for the base).
        self.body_parent = np.array(body_parent, dtype=np.int64)
        self.bodies = len(body_parent)
        #: True when every body hangs from the one before it (a chain's bodies).
        self.chain_bodies = bool(np.all(self.body_parent[1:] == np.arange(self.bodies - 1)))
        m = self.moving
        self.revolute = kinds[m] == REVOLUTE
        self.all_revolute = bool(self.revolute.all())
        ax = np.asarray(axes, dtype=float).reshape(J, 3)[m]
        K1 = np.zeros((m.size, 3, 3))
        K1[:, 0, 1], K1[:, 0, 2], K1[:, 1, 2] = -ax[:, 2], ax[:, 1], -ax[:, 0]
        K1[:, 1, 0], K1[:, 2, 0], K1[:, 2, 1] = ax[:, 2], -ax[:, 1], ax[:, 0]
        self._K1, self._K2 = K1, K1 @ K1
        #: (M, 3) the moving joints' axes and points on them, at ``q_ref``.
        self.axes = ax
        self.points = np.asarray(points, dtype=float).reshape(J, 3)[m]
        self._ref_moving = self.q_ref[m]
        self._parent_list = self.body_parent.tolist()
        self._elementary = None  # frame_poses' constants, made on first use
        for array in (kinds, parents, self.q_ref, body_of, self.moving, self.body_parent,
                      self.revolute, ax, self.points, K1, self._K2, self._ref_moving):  # fmt: skip
            array.setflags(write=False)

    def body_motions(self, Q) -> np.ndarray:
        """(K, bodies, 4, 4): the world motion of every rigid body (0 = base) from ``q_ref``
        to each configuration of ``Q`` (K, J).

        The arithmetic is written out (:func:`rigid_product`, :meth:`local_motions`), not left
        to BLAS, so that a compiled kernel can do the same sums in the same order and give the
        same bits (the clearance engine's one-configuration query does)."""
        Q = np.asarray(Q, dtype=float)
        K, NB = Q.shape[0], self.bodies
        B = np.empty((K, NB, 4, 4))
        B[:, 0] = _EYE4
        if NB == 1:
            return B
        delta = Q[:, self.moving] - self._ref_moving
        R, t = self.local_motions(delta, np.sin(delta), 1.0 - np.cos(delta))
        B[..., 3, :] = _LAST_ROW
        parent = self._parent_list
        for b in range(1, NB):
            if parent[b] == 0:
                B[:, b, :3, :3], B[:, b, :3, 3] = R[:, b - 1], t[:, b - 1]
            else:
                rigid_product(B[:, parent[b]], R[:, b - 1], t[:, b - 1], B[:, b])
        return B

    def body_motions_one(self, q) -> np.ndarray:
        """(bodies, 4, 4): :meth:`body_motions` of one configuration ``q`` (J,), the same
        arithmetic on the same shapes but one, so the same bits."""
        q = np.asarray(q, dtype=float)
        NB = self.bodies
        B = np.empty((NB, 4, 4))
        B[0] = _EYE4
        if NB == 1:
            return B
        delta = q.take(self.moving) - self._ref_moving
        R, t = self.local_motions(delta, np.sin(delta), 1.0 - np.cos(delta))
        B[:, 3, :] = _LAST_ROW
        parent = self._parent_list
        for b in range(1, NB):
            if parent[b] == 0:
                B[b, :3, :3], B[b, :3, 3] = R[b - 1], t[b - 1]
            else:
                rigid_product(B[parent[b]], R[b - 1], t[b - 1], B[b])
        return B

    def local_motions(self, delta, sine, versine) -> tuple[np.ndarray, np.ndarray]:
        """Each moving joint's motion G (rotation (..., M, 3, 3), translation (..., M, 3)) for
        its state change ``delta`` (..., M), with ``sine`` = sin(delta) and ``versine`` =
        1 - cos(delta) given (numpy's, which a compiled kernel takes as they are): a revolute
        joint's R = (I + sin K) + (1 - cos) K² about its axis (K its cross-product matrix) and
        t = p - R p for the point p on it; a prismatic joint's R = I, t = delta axis."""
        rev = self.revolute
        if self.all_revolute:
            s, c = sine[..., None, None], versine[..., None, None]
        else:
            s = np.where(rev, sine, 0.0)[..., None, None]
            c = np.where(rev, versine, 0.0)[..., None, None]
        R = _EYE3 + s * self._K1 + c * self._K2
        p = self.points
        Rp = (R[..., 0] * p[:, None, 0] + R[..., 1] * p[:, None, 1]) + R[..., 2] * p[:, None, 2]
        t = p - Rp
        if not self.all_revolute:
            t = np.where(rev[:, None], t, delta[..., None] * self.axes)
        return R, t

    @property
    def rotation_generators(self) -> tuple[np.ndarray, np.ndarray]:
        """(K, K²) per moving joint (M, 3, 3) each: the cross-product matrix of its axis and
        its square, as :meth:`local_motions` uses them."""
        return self._K1, self._K2

    def frame_poses(self, Q, bodies, frames, axes: bool = False):
        """Poses of frames fixed in rigid bodies, at many configurations: for frame l, fixed in
        body ``bodies[l]`` and at ``frames[l]`` (4x4) at ``q_ref``, its pose at each
        configuration of ``Q`` (K, J): ``body_motions(Q)[:, bodies] @ frames`` to rounding
        (1e-15 relative), several times faster on large batches.

        Each body's motion is written as a product of elementary transforms (Robotics
        Toolbox's ETS form): with Z_b a frame whose z is body b's joint axis, S_b(q) =
        B_b(q) Z_b = S_parent(b)(q) (Z_parent(b)^-1 Z_b) Rz(d_b) (Tz(d_b) for a sliding joint),
        a constant 4x4 product (one matrix product over the batch) and a turn of two columns.
        Returns the poses (K, L, 4, 4); with ``axes``, ``(poses, axes)`` with every moving
        joint's axis at each configuration, (K, M, 3, 4): frames [x y z o] whose z is the axis
        direction and whose origin o is on it (what Jacobians need)."""
        Q = np.asarray(Q, dtype=float)
        K, NB = Q.shape[0], self.bodies
        steps, inverse = self.elementary()
        bodies = np.asarray(bodies, dtype=np.int64)
        delta = Q[:, self.moving] - self._ref_moving  # (K, M)
        S = [None] * NB  # S_b, (K, 3, 4): the rows that move (the last is 0 0 0 1)
        frames_out = np.empty((K, NB - 1, 3, 4)) if axes else None
        for b in range(1, NB):
            pb = self._parent_list[b]
            if pb == 0:  # from the base: the constant itself
                A = np.broadcast_to(steps[b - 1][:3], (K, 3, 4)).copy()
            else:  # [R | t] (K*3, 4) @ (4, 4): one matrix product for the batch
                A = (S[pb].reshape(-1, 4) @ steps[b - 1]).reshape(K, 3, 4)
            if frames_out is not None:
                frames_out[:, b - 1] = A
            d = delta[:, b - 1, None]
            if self.revolute[b - 1]:  # columns x, y turned by Rz(d): (x + iy) e^(-id)
                A.view(np.complex128)[:, :, 0] *= np.exp(-1j * d)
            else:
                A[:, :, 3] += d * A[:, :, 2]
            S[b] = A
        poses = np.empty((K, bodies.size, 4, 4))
        poses[..., 3, :] = _LAST_ROW
        for l, b in enumerate(bodies.tolist()):  # noqa: E741 - frame l
            E = inverse[b] @ np.asarray(frames[l], dtype=float)  # Z_b^-1 F, constant
            if b == 0:
                poses[:, l] = E
                continue
            poses[:, l, :3] = (S[b].reshape(-1, 4) @ E).reshape(K, 3, 4)
        return (poses, frames_out) if axes else poses

    def elementary(self) -> tuple[list, list]:
        """:meth:`frame_poses`' constants, made once: per moving body b (1..), the step
        Z_parent(b)^-1 Z_b from its parent's axis frame to its own (4x4), and every body's
        Z_b^-1 (the base's: the identity). Compiled solvers use them as frame_poses does."""
        if self._elementary is None:
            self._elementary = self._elementary_constants()
        return self._elementary

    def _elementary_constants(self) -> tuple[list, list]:
        """For :meth:`frame_poses`: per moving body b, Z_parent(b)^-1 Z_b, and every body's
        Z_b^-1 (the base's: the identity)."""
        frames = [np.eye(4)]
        for a, p in zip(self.axes, self.points, strict=True):
            helper = np.array([1.0, 0.0, 0.0]) if abs(a[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
            x = np.cross(helper, a)
            x /= np.linalg.norm(x)
            Z = np.eye(4)
            Z[:3, 0], Z[:3, 1], Z[:3, 2], Z[:3, 3] = x, np.cross(a, x), a, p
            frames.append(Z)
        inverse = []
        for Z in frames:
            inv = np.eye(4)
            inv[:3, :3] = Z[:3, :3].T
            inv[:3, 3] = -Z[:3, :3].T @ Z[:3, 3]
            inverse.append(inv)
        steps = [inverse[self._parent_list[b]] @ frames[b] for b in range(1, self.bodies)]
        return steps, inverse

    def joint_motions(self, Q) -> np.ndarray:
        """A_j(q) of every joint: (K, J, 4, 4) for ``Q`` (K, J), (J, 4, 4) for one
        configuration (J,). Everything downstream of joint j's motion is at A_j(q) times its
        place at ``q_ref``; joint j's own pose and proximal side move by its parent's A."""
        Q, single = _configurations(Q, self.kinds.shape[0])
        A = self.body_motions(Q)[:, self.body_of]
        return A[0] if single else A


_EYE3 = np.eye(3)
_EYE4 = np.eye(4)
_LAST_ROW = np.array([0.0, 0.0, 0.0, 1.0])


def rigid_product(P: np.ndarray, R: np.ndarray, t: np.ndarray, out: np.ndarray) -> None:
    """``out`` = P [R | t] for rigid motions (..., 4, 4) P and out (last rows 0 0 0 1) and a
    rotation R (..., 3, 3) and translation t (..., 3), the sums in a fixed order
    (((P_i0 x_0j + P_i1 x_1j) + P_i2 x_2j), plus P_i3 for the translation): what
    :meth:`JointScrews.body_motions` and the compiled kernels compute, bit for bit."""
    PR = P[..., :3, :3]
    out[..., :3, :3] = (PR[..., :, 0, None] * R[..., None, 0, :]
                        + PR[..., :, 1, None] * R[..., None, 1, :]) \
        + PR[..., :, 2, None] * R[..., None, 2, :]  # fmt: skip
    out[..., :3, 3] = ((PR[..., 0] * t[..., None, 0] + PR[..., 1] * t[..., None, 1])
                       + PR[..., 2] * t[..., None, 2]) + P[..., :3, 3]  # fmt: skip


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
    ``q_ref`` (J,) to ``q``. A frame F downstream of joint j is at ``A_j(q) @ F(q_ref)``.
    (:class:`JointScrews` compiled once, for one call.)"""
    return JointScrews(kinds, axes, points, parents, q_ref).joint_motions(q)


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
