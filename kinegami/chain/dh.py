"""Chains from Denavit-Hartenberg tables (docs/theory/chain.md §8).

A DH table has one row (theta, alpha, a, d) per joint; angles in radians, lengths in the chain's
unit. Two conventions are supported:

* ``"standard"`` (distal, Denavit-Hartenberg 1955; Spong, Corke): row i is the transform from
  frame i-1 to frame i, ``Rz(theta) Tz(d) Tx(a) Rx(alpha)``. Joint i moves about the z axis of
  frame i-1 (frame 0 is the world), and frame n is the tool frame.
* ``"modified"`` (proximal, Craig; Khalil-Dombre; the MATLAB Kinegami): row i is
  ``Rx(alpha) Tx(a) Rz(theta) Tz(d)`` and joint i moves about the z axis of frame i.

The joints are placed on those axes: joint k of the chain (0-based) moves about the z axis of the
k-th joint frame returned by :func:`dh_joint_frames`. Placement may slide a joint along its axis
(compact or safe placement) and compact placement keeps the DH roll (docs/theory/chain.md §8).
"""

from __future__ import annotations

import math
import warnings
from collections.abc import Sequence
from typing import TYPE_CHECKING

import numpy as np

from kinegami.chain.joints import EndTip, PrismaticJoint, RevoluteJoint
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.geometry.frames import rot_x, rot_z, translation
from kinegami.validation import (
    check_bool,
    check_num_sides,
    check_radius,
    check_real,
    check_translation,
    shown,
)

if TYPE_CHECKING:  # pragma: no cover
    from kinegami.chain.model import KinematicChain

__all__ = ["CONVENTIONS", "PLACEMENTS", "dh_frames", "dh_joint_frames", "dh_tool_frame",
           "dh_transform", "chain_from_dh", "parse_joint_types"]  # fmt: skip

CONVENTIONS = ("standard", "modified")
PLACEMENTS = ("compact", "safe")

_TYPE_NAMES = {"r": "R", "revolute": "R", "p": "P", "prismatic": "P"}


def _check_convention(convention) -> str:
    if convention not in CONVENTIONS:
        raise InvalidParameterError(
            f"convention must be one of {', '.join(map(repr, CONVENTIONS))}, got {convention!r}"
        )
    return convention


def dh_transform(theta: float, alpha: float, a: float, d: float, convention: str = "standard"):
    """4x4 transform of one DH row (angles in radians) from frame i-1 to frame i."""
    convention = _check_convention(convention)
    theta, alpha = check_real("theta", theta), check_real("alpha", alpha)
    a, d = check_real("a", a), check_real("d", d)
    if convention == "standard":
        return rot_z(theta) @ translation([0.0, 0.0, d]) @ translation([a, 0.0, 0.0]) @ rot_x(alpha)
    return rot_x(alpha) @ translation([a, 0.0, 0.0]) @ rot_z(theta) @ translation([0.0, 0.0, d])


#: The columns of a DH table row, named in messages (``table row 0 theta``).
_COLUMNS = ("theta", "alpha", "a", "d")


def _check_table(table) -> np.ndarray:
    """The table as an n x 4 float array; every entry is a finite real number (bools and
    strings are not numbers: ``True`` or ``"1"`` raise InvalidTypeError naming the entry)."""
    if isinstance(table, str | bytes) or not hasattr(table, "__len__"):
        raise InvalidTypeError(
            f"table must be a sequence of rows (theta, alpha, a, d), got {type(table).__name__}"
        )
    if (
        isinstance(table, np.ndarray)
        and table.dtype.kind in "iuf"
        and table.ndim == 2
        and table.shape[0] > 0
        and table.shape[1] == 4
    ):
        rows = np.array(table, dtype=float)
        if np.all(np.isfinite(rows)):
            return rows  # else the row by row checks below name the entry
    rows = []
    for i, row in enumerate(table):
        try:
            if isinstance(row, str | bytes):  # its characters would be read as numbers
                raise TypeError
            entries = list(row)
        except TypeError:
            raise InvalidTypeError(
                f"table row {i} must be 4 numbers (theta, alpha, a, d), got {shown(row)}"
            ) from None
        if len(entries) != 4:
            raise InvalidParameterError(
                f"table row {i} must have 4 entries (theta, alpha, a, d), got {len(entries)}: "
                f"{shown(row)}"
            )
        rows.append(
            [
                check_real(f"table row {i} {column} (table[{i}][{j}])", value)
                for j, (column, value) in enumerate(zip(_COLUMNS, entries, strict=True))
            ]
        )
    if not rows:
        raise InvalidParameterError("table must have at least one row (theta, alpha, a, d)")
    return np.array(rows, dtype=float)


def dh_frames(table, convention: str = "standard") -> list[np.ndarray]:
    """World frames [G_0 = I, G_1, ..., G_n] of a DH table (4x4 arrays)."""
    convention = _check_convention(convention)
    rows = _check_table(table)
    frames = [np.eye(4)]
    for theta, alpha, a, d in rows:
        frames.append(frames[-1] @ dh_transform(theta, alpha, a, d, convention))
    return frames


def dh_joint_frames(table, convention: str = "standard") -> list[np.ndarray]:
    """One world frame per joint, whose z axis is the joint's axis of motion.

    Standard: G_0 ... G_{n-1}; modified: G_1 ... G_n.
    """
    frames = dh_frames(table, convention)
    return frames[:-1] if convention == "standard" else frames[1:]


def dh_tool_frame(table, convention: str = "standard") -> np.ndarray:
    """The frame an end tip is placed on, its z axis pointing out of the chain.

    Standard: the tool frame G_n. Modified: G_n turned so that its z axis is G_n's x axis
    (the MATLAB fingertip 'x', docs/theory/chain.md §8), since G_n's z is the last joint's axis.
    """
    frames = dh_frames(table, convention)
    if convention == "standard":
        return frames[-1]
    G = frames[-1]
    C = np.eye(4)
    C[:3, :3] = [[0.0, 0.0, 1.0], [1.0, 0.0, 0.0], [0.0, 1.0, 0.0]]
    return G @ C


def parse_joint_types(jointTypes, count: int) -> list[str]:
    """'R'/'P' per joint from None (all revolute), a string such as 'RRP' or a sequence of
    'R', 'P', 'revolute', 'prismatic' (case-insensitive)."""
    if jointTypes is None:
        return ["R"] * count
    if isinstance(jointTypes, str):
        items = list(jointTypes)
    elif isinstance(jointTypes, Sequence):
        items = list(jointTypes)
    else:
        raise InvalidTypeError(
            f"jointTypes must be None, a string of R/P or a sequence of 'revolute'/'prismatic', "
            f"got {type(jointTypes).__name__}"
        )
    if len(items) != count:
        raise InvalidParameterError(
            f"jointTypes must give one type per table row ({count}), got {len(items)}: "
            f"{jointTypes!r}"
        )
    types = []
    for i, item in enumerate(items):
        key = item.strip().lower() if isinstance(item, str) else None
        if key not in _TYPE_NAMES:
            raise InvalidParameterError(
                f"jointTypes[{i}] must be 'R', 'P', 'revolute' or 'prismatic', got {item!r}"
            )
        types.append(_TYPE_NAMES[key])
    return types


def chain_from_dh(
    cls,
    table,
    numSides: int,
    r: float,
    convention: str = "standard",
    jointTypes=None,
    *,
    placement: str = "compact",
    totalBendingAngle: float = math.pi,
    numSinkLayers: int = 1,
    neutralLength: float | None = None,
    numLayers: int = 3,
    coneAngle: float = math.pi / 4,
    endTip: bool = True,
    tipLength: float | None = None,
    maxAnglePerElbow: float = math.pi / 2,
) -> KinematicChain:
    """Build a chain whose joints move about the axes of a DH table (docs/theory/chain.md §8).

    See :meth:`kinegami.chain.KinematicChain.from_dh`. Raises NoPathError (a ValueError) when
    compact placement cannot link a joint; nothing is returned half-built.
    """
    from kinegami.errors import NoPathError, PlacementWarning

    convention = _check_convention(convention)
    if placement not in PLACEMENTS:
        raise InvalidParameterError(
            f"placement must be one of {', '.join(map(repr, PLACEMENTS))}, got {placement!r}"
        )
    numSides = check_num_sides(numSides)
    r = check_radius(r)
    endTip = check_bool("endTip", endTip)
    rows = _check_table(table)
    for i, (_, _, a, d) in enumerate(rows):
        check_translation(f"table row {i} a", a, r)
        check_translation(f"table row {i} d", d, r)
    types = parse_joint_types(jointTypes, len(rows))
    if neutralLength is None:
        neutralLength = 3.0 * r
    if tipLength is None:
        tipLength = 1.5 * r

    # the joints are made at the identity and then moved to their frames: composed DH frames
    # are computed positions, not user poses, so they are not held to the +-1e6 r bound
    def make(kind: str, T: np.ndarray):
        if kind == "R":
            joint = RevoluteJoint(numSides, r, totalBendingAngle, I4, numSinkLayers=numSinkLayers)
        else:
            joint = PrismaticJoint(numSides, r, neutralLength, numLayers, coneAngle, I4)
        return joint.with_pose(T)

    I4 = np.eye(4)
    frames = dh_joint_frames(rows, convention)
    joints = [make(kind, T) for kind, T in zip(types, frames, strict=True)]
    if endTip:
        tool = dh_tool_frame(rows, convention)
        joints.append(EndTip(numSides, r, I4, tipLength).with_pose(tool))

    chain = cls(joints[0], maxAnglePerElbow=maxAnglePerElbow)
    options = {"relative": False}
    if placement == "compact":
        options.update(safe=False, fixedOrientation=True)
    else:
        options.update(safe=True)
    for k, joint in enumerate(joints[1:], start=1):
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always", PlacementWarning)
            index = chain.append(joint, **options)
        if index is None:
            reason = str(caught[-1].message) if caught else "no link reaches it"
            what = "the end tip" if endTip and k == len(joints) - 1 else f"joint {k} (row {k})"
            raise NoPathError(
                f"{placement} placement cannot place {what} of the DH table: {reason}; "
                f"try placement='safe'"
            )
    return chain
