"""Forward kinematics and Jacobians of a design, compiled once (docs/reach.md).

:func:`kinematics` turns a chain or a tree into a :class:`Kinematics` value: the joints as
screws about their axes at the design's current states (:class:`~kinegami.geometry.screws.
JointScrews`, the one forward kinematics of the package), the tips' frames at those states and
the joints' ranges. Solvers and workspaces evaluate it on batches of configurations without
touching a Joint or Link object.

Conventions are Robotics Toolbox for Python's: ``fkine(q)`` gives the tip's pose as a 4x4
array (world frame, the design's length units); ``jacob0(q)`` the geometric Jacobian in the
world frame, rows (v, ω): v the velocity of the tip frame's origin, ω its angular velocity. A
configuration ``q`` has one state per joint of ``design.Joints`` (tips and waypoints
included, their states 0), radians for revolute joints and length units for prismatic ones:
what ``design.setJointStates`` takes. :attr:`Kinematics.movable` maps it to RTB's vector of
movable joints.
"""

from __future__ import annotations

import weakref
from collections.abc import Sequence
from dataclasses import dataclass

import numpy as np

from kinegami.chain.joints import pose_array
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.geometry.screws import FIXED, REVOLUTE, JointScrews

__all__ = ["Kinematics", "kinematics"]


@dataclass(frozen=True, eq=False)
class Kinematics:
    """A design compiled for kinematics at its states when compiled (immutable: build it
    again after the design is edited; :func:`kinematics` does, and keeps it until then).

    Attributes
    ----------
    screws : JointScrews
        The joints as screws at the reference configuration ``q_ref``.
    tips : tuple of int
        The tip joints (their distal frames), in joint-index order.
    tip_frames : (L, 4, 4) array
        The tips' frames (tool included) at ``q_ref``, world frame.
    ranges : (n, 2) array
        Every joint's state range (tips and waypoints: [0, 0]).
    kinds : (n,) int array
        ``FIXED``, ``REVOLUTE`` or ``PRISMATIC`` per joint.
    """

    screws: JointScrews
    tips: tuple[int, ...]
    tip_frames: np.ndarray
    ranges: np.ndarray
    kinds: np.ndarray

    @property
    def n(self) -> int:
        """Entries of a configuration: the design's joints."""
        return int(self.kinds.shape[0])

    @property
    def q_ref(self) -> np.ndarray:
        """The configuration the design was compiled at (its states then), (n,)."""
        return self.screws.q_ref

    @property
    def movable(self) -> np.ndarray:
        """Indices of the revolute and prismatic joints: ``q[movable]`` is RTB's joint vector,
        and a configuration is ``q = q_ref.copy(); q[movable] = rtb_q``."""
        return np.flatnonzero(self.kinds != FIXED)

    def configurations(self, q) -> tuple[np.ndarray, bool]:
        """``q`` as a float array (m, n), and whether it was one configuration (n,); a clear
        error for anything else."""
        try:
            Q = np.asarray(q, dtype=float)
        except (TypeError, ValueError):
            raise InvalidTypeError(
                f"q must be numbers, one state per joint of design.Joints ({self.n}), got {q!r}"
            ) from None
        single = Q.ndim == 1
        Q = Q[None, :] if single else Q
        if Q.ndim != 2 or Q.shape[1] != self.n:
            raise InvalidParameterError(
                f"q must have shape ({self.n},) or (m, {self.n}): one state per joint of "
                f"design.Joints, tips and waypoints included (0); got shape {np.shape(q)}"
            )
        if not np.isfinite(Q).all():
            raise InvalidParameterError("q must be finite (a state is NaN or infinite)")
        return Q, single

    def fkine(self, q) -> np.ndarray:
        """The tip's pose at ``q``: (4, 4) for one configuration (n,), (m, 4, 4) for a batch
        (m, n); with several tips, (..., L, 4, 4), the tips in joint-index order."""
        Q, single = self.configurations(q)
        T = self.tip_poses(Q) if Q.shape[0] < COMPILED_BATCH else self._tip_poses_compiled(Q)
        if T.shape[1] == 1:
            T = T[:, 0]
        return T[0] if single else T

    def tip_poses(self, Q: np.ndarray) -> np.ndarray:
        """(m, L, 4, 4): every tip's pose at the configurations ``Q`` (m, n), unchecked."""
        return self.screws.frame_poses(Q, self.screws.body_of[list(self.tips)], self.tip_frames)

    def _tip_poses_compiled(self, Q: np.ndarray) -> np.ndarray:
        """:meth:`tip_poses` by the compiled, threaded kernel
        (:func:`kinegami.reach.kernels.frame_poses`; equal to rounding), or by numpy where
        numba cannot run."""
        kernel = _frame_kernel()
        if kernel is None:
            return self.tip_poses(Q)
        screws = self.screws
        steps, inverse = screws.elementary()
        bodies = screws.body_of[list(self.tips)]
        E = np.array([inverse[b] @ frame for b, frame in zip(bodies.tolist(), self.tip_frames,
                                                             strict=True)])  # fmt: skip
        delta = np.ascontiguousarray(Q[:, screws.moving] - screws.q_ref[screws.moving])
        out = np.empty((Q.shape[0], bodies.size, 4, 4))
        kernel(np.array(steps, dtype=float).reshape(-1, 4, 4), screws.body_parent,
               np.asarray(screws.revolute, dtype=np.bool_), delta, E, bodies, out)  # fmt: skip
        return out

    def jacob0(self, q) -> np.ndarray:
        """The geometric Jacobian of the tip at ``q`` in the world frame, rows (v, ω), one
        column per joint of ``design.Joints`` (zero for tips, waypoints and joints not on the
        tip's path): (6, n) for one configuration, (m, 6, n) for a batch; with several tips,
        (..., L, 6, n)."""
        Q, single = self.configurations(q)
        J, _ = self.jacobians(Q)
        if J.shape[1] == 1:
            J = J[:, 0]
        return J[0] if single else J

    def jacobians(self, Q: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """Every tip's Jacobian (m, L, 6, n) and pose (m, L, 4, 4) at ``Q`` (m, n),
        unchecked."""
        screws = self.screws
        m, L = Q.shape[0], len(self.tips)
        out = np.zeros((m, L, 6, self.n))
        tips, frames = screws.frame_poses(Q, screws.body_of[list(self.tips)], self.tip_frames,
                                          axes=True)  # fmt: skip
        moving = screws.moving
        if moving.size == 0:
            return out, tips
        # each moving joint's axis at Q: the z and the origin of its frame
        direction, point = frames[..., :3, 2], frames[..., :3, 3]  # (m, M, 3)
        origin = tips[..., :3, 3]  # (m, L, 3)
        revolute = self.kinds[moving] == REVOLUTE
        for k, ancestors in enumerate(self._ancestors()):
            cols = moving[ancestors]
            d = direction[:, ancestors]
            rev = revolute[ancestors]
            v = np.where(rev[None, :, None],
                         np.cross(d, origin[:, k, None, :] - point[:, ancestors]), d)  # fmt: skip
            w = np.where(rev[None, :, None], d, 0.0)
            tip = out[:, k]  # (m, 6, n), a view
            tip[:, :3, cols] = v.transpose(0, 2, 1)
            tip[:, 3:, cols] = w.transpose(0, 2, 1)
        return out, tips

    def path(self, tip: int) -> np.ndarray:
        """The moving bodies (1 .. M; body b moves with joint ``screws.moving[b - 1]``) from
        the root to joint ``tip``'s body, in order: the joints that move that tip."""
        screws = self.screws
        b = int(screws.body_of[tip])
        path = []
        while b > 0:
            path.append(b)
            b = int(screws.body_parent[b])
        return np.array(path[::-1], dtype=np.int64)

    def _ancestors(self) -> list[np.ndarray]:
        """Per tip, a mask over the moving joints: those on the path from the root to it."""
        screws = self.screws
        parent = screws.body_parent.tolist()
        masks = []
        for tip in self.tips:
            mask = np.zeros(screws.moving.size, dtype=bool)
            b = int(screws.body_of[tip])
            while b > 0:
                mask[b - 1] = True
                b = parent[b]
            masks.append(mask)
        return masks


#: Configurations from which :meth:`Kinematics.fkine` runs the compiled, threaded kernel (a
#: smaller batch stays on numpy: loading numba costs about 0.4 s once).
COMPILED_BATCH = 2048

_FRAME_KERNEL: list = []


def _frame_kernel():
    """:func:`kinegami.reach.kernels.frame_poses`, loaded on first use; None where numba
    cannot be imported or cannot keep its machine code."""
    if not _FRAME_KERNEL:
        try:
            from kinegami.reach.kernels import frame_poses
        except (ImportError, OSError, RuntimeError):
            frame_poses = None
        _FRAME_KERNEL.append(frame_poses)
    return _FRAME_KERNEL[0]


#: Compiled designs, until their joint list changes (a state change replaces joints).
_COMPILED: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def kinematics(design, tip=None, tool=None) -> Kinematics:
    """``design`` (a KinematicChain or KinematicTree) compiled for kinematics at its current
    states.

    Parameters
    ----------
    tip : int or sequence of int, optional
        The tip joints (their distal frames). Default: a chain's last joint, every leaf of a
        tree.
    tool : (4, 4) array or SE3, optional
        A fixed transform on every tip (a tool frame, in the tip's frame).
    """
    joints = getattr(design, "Joints", None)
    if joints is None or not hasattr(design, "Parents"):
        raise InvalidTypeError(
            f"design must be a KinematicChain or KinematicTree, got {type(design).__name__}"
        )
    n = len(joints)
    tips = _tips(design, tip, n)
    frame = _tool(tool)
    key = (tips, None if frame is None else frame.tobytes())
    cached = _COMPILED.get(design)
    if cached is not None and cached[0] == tuple(map(id, joints)) and key in cached[1]:
        return cached[1][key]
    screws = design.joint_screws()
    frames = np.array([joints[k].distal_dubins_frame() for k in tips], dtype=float)
    if frame is not None:
        frames = frames @ frame
    ranges = np.array([joint.stateRange() for joint in joints], dtype=float).reshape(n, 2)
    for array in (frames, ranges):
        array.setflags(write=False)
    compiled = Kinematics(screws, tips, frames, ranges, screws.kinds)
    if cached is None or cached[0] != tuple(map(id, joints)):
        cached = (tuple(map(id, joints)), {})
        _COMPILED[design] = cached
    if len(cached[1]) < 16:
        cached[1][key] = compiled
    return compiled


def _tips(design, tip, n: int) -> tuple[int, ...]:
    """The tip joints asked for (checked), or the default ones."""
    if tip is None:
        parents = design.Parents
        has_child = {int(p) for p in parents if p is not None and int(p) >= 0}
        leaves = tuple(k for k in range(n) if k not in has_child)
        return (n - 1,) if len(leaves) == 1 else leaves
    items = [tip] if isinstance(tip, (int, np.integer)) and not isinstance(tip, bool) else tip
    if not isinstance(items, Sequence) and not isinstance(items, np.ndarray):
        raise InvalidTypeError(f"tip must be a joint index or a sequence of them, got {tip!r}")
    out = []
    for k in items:
        if isinstance(k, bool) or not isinstance(k, (int, np.integer)):
            raise InvalidTypeError(f"tip must be joint indices (int), got {k!r}")
        if not 0 <= int(k) < n:
            raise InvalidParameterError(f"tip {int(k)} is not a joint index: valid 0 to {n - 1}")
        out.append(int(k))
    if not out:
        raise InvalidParameterError("tip must name at least one joint")
    return tuple(sorted(set(out)))


def _tool(tool) -> np.ndarray | None:
    """A tool transform as a 4x4 array (checked rigid), or None."""
    if tool is None:
        return None
    return pose_array(tool, "tool")
