"""Joints of a tubular chain: revolute, prismatic, waypoints and tips (docs/theory/chain.md §1).

Every joint has a ``Pose`` (an SE3: origin at the joint centre in the state-0 configuration,
z axis = axis of motion), a tube radius ``r``, a polygon side count ``numSides``, a
``neutralLength`` (proximal-to-distal distance at state 0), a ``state`` (radians for revolute,
length for prismatic joints, 0 at construction) and a path direction: column ``pathIndex()`` of
the Pose, the tangent of the tube centreline through the joint.

Lengths lie in (0, 1e6 r] and Pose translations within +-1e6 r (see
:mod:`kinegami.validation`); an InvalidParameterError names the parameter, the value and the
bound otherwise.

Joints are values: a chain never changes a joint in place, it swaps in modified copies
(``with_pose``, ``with_state``), which is what makes its edits transactions. Their public
attributes are read-only: ``joint.totalBendingAngle = 0.1`` raises ReadOnlyError (a KinegamiError
and an AttributeError; docs/errors.md) instead of silently changing the state range.
"""

from __future__ import annotations

import functools
import math
import sys
from typing import TYPE_CHECKING

import numpy as np

from kinegami._record import Record
from kinegami.errors import IncompatibleJointError, InvalidParameterError, InvalidTypeError
from kinegami.geometry.balls import Ball
from kinegami.geometry.frames import (
    cross3,
    dubins_frame,
    is_rigid_transform,
    rot_x,
    rot_z,
    rotation_about_line,
    translation,
    unit,
)
from kinegami.geometry.screws import FIXED, PRISMATIC, REVOLUTE
from kinegami.geometry.shapes import hinge_segment, polygon_side, regular_polygon, shifted_frame
from kinegami.validation import (
    REAL_NUMBER_TYPES,
    ReadOnlyAttributes,
    check_in_range,
    check_int,
    check_length,
    check_num_layers,
    check_num_sides,
    check_num_sink_layers,
    check_radius,
    check_translation_part,
    shown,
)

__all__ = [
    "Joint",
    "BodyPiece",
    "CapsuleSegment",
    "JOINT_KINDS",
    "register_joint_kind",
    "RevoluteJoint",
    "ExtendedRevoluteJoint",
    "PrismaticJoint",
    "Waypoint",
    "Tip",
    "StartTip",
    "EndTip",
    "pose_array",
]


class BodyPiece(Record):
    """A convex piece of a joint's solid (docs/clearance.md): the convex hull of ``points``
    ((k, 3), world, units of r), moving with the joint's proximal side, its distal side, or
    the joint as a whole (``side`` "proximal", "distal" or ""). ``drawn`` is None (pictures
    draw the hull's faces) or how pictures draw it: ``("hull", points)`` and
    ``("prism", bottom, top)`` items, whose union is the piece."""

    side: str
    points: np.ndarray
    drawn: tuple | None = None


class CapsuleSegment(Record):
    """A segment of a joint's centreline (world, units of r): every part of the joint lies
    within r of its segments. ``start_moves`` / ``end_moves``: whether that end moves with the
    joint's own motion (its distal side) rather than with the body before the joint;
    ``words`` is added to the joint's name in reports (", proximal half")."""

    start: np.ndarray
    end: np.ndarray
    start_moves: bool
    end_moves: bool
    words: str = ""



if TYPE_CHECKING:
    from spatialmath import SE3


def as_se3(T: np.ndarray) -> SE3:
    """``T`` as a spatialmath SE3 (imported on first use: importing spatialmath costs most of
    a second, which commands that never hand out an SE3 should not pay)."""
    from spatialmath import SE3

    return SE3(T, check=False)


def _is_se3(value) -> bool:
    """Whether ``value`` is a spatialmath SE3 (without importing spatialmath: an SE3 can only
    exist once spatialmath is imported)."""
    spatialmath = sys.modules.get("spatialmath")
    return spatialmath is not None and isinstance(value, spatialmath.SE3)


#: Kinds of numpy dtypes whose arrays are real numbers (signed, unsigned ints and floats).
_REAL_KINDS = frozenset("iuf")
#: Entry types found real so far (issubclass with the abstract numbers.Real is slow).
_KNOWN_REAL_TYPES = {int, float, np.float64, np.int64}


def _is_real_type(t: type) -> bool:
    """Whether entries of type ``t`` are real numbers, as check_real decides (no bools)."""
    if t in _KNOWN_REAL_TYPES:
        return True
    if issubclass(t, REAL_NUMBER_TYPES) and not issubclass(t, bool):
        _KNOWN_REAL_TYPES.add(t)
        return True
    return False


def _value_text(value) -> str:
    """``value`` in a message, with its type (``str '1'``, ``bool True``; ``None``)."""
    return "None" if value is None else f"{type(value).__name__} {shown(value)}"


def _not_a_pose(name: str, got: str) -> InvalidTypeError:
    return InvalidTypeError(
        f"{name} must be an SE3 or a 4x4 array of real numbers (ints or floats), got {got}"
    )


def _real_entries(A: np.ndarray, name: str, what: str) -> None:
    """Raise InvalidTypeError unless every entry of the object array ``A`` (``what``, in the
    message) is a real number (bools, strings, complex numbers and None are not), naming the
    first entry that is not."""
    types = set(map(type, A.flat))
    if types <= _KNOWN_REAL_TYPES or all(_is_real_type(t) for t in types):
        return
    if A.ndim == 0:
        raise _not_a_pose(name, _value_text(A[()]))
    for index in np.ndindex(A.shape):
        value = A[index]
        if not _is_real_type(type(value)):
            entry = f"{name}{''.join(f'[{i}]' for i in index)}"
            if isinstance(value, list | tuple | np.ndarray):  # np.array found no common shape
                got = f"{what} whose rows differ in length ({entry} is {shown(value)})"
            else:
                got = f"{what} whose entry {entry} is {_value_text(value)}"
            raise _not_a_pose(name, got)


def _real_matrix(Pose, name: str) -> np.ndarray:
    """``Pose`` (not an SE3) as a float array, or InvalidTypeError unless it is an array or a
    nested sequence of real numbers (numpy's int and float dtypes; bool, complex, string
    dtypes and None are refused). The shape is checked by the caller."""
    if isinstance(Pose, np.ndarray):
        kind = Pose.dtype.kind
        if kind not in _REAL_KINDS:
            if kind != "O":
                raise _not_a_pose(name, f"an array of dtype {Pose.dtype} (shape {Pose.shape})")
            _real_entries(Pose, name, f"an object array (shape {Pose.shape})")
        return np.array(Pose, dtype=float)
    if Pose is None or isinstance(Pose, str | bytes):
        raise _not_a_pose(name, _value_text(Pose))
    # a nested sequence: its entries as they are (np.array(..., dtype=float) would read the
    # strings '1', and bools as 0/1), checked, then converted as np.array(Pose, dtype=float)
    try:
        A = np.array(Pose, dtype=object)
    except (TypeError, ValueError):
        raise _not_a_pose(name, type(Pose).__name__) from None
    _real_entries(A, name, type(Pose).__name__)
    return A.astype(float)


def pose_array(Pose, name: str = "Pose", r: float | None = None) -> np.ndarray:
    """A validated 4x4 float array from an SE3 or a 4x4 array-like (proper rigid, finite).

    An array-like is an array or nested sequence of real numbers: ints and floats (Python's,
    numpy's); None, strings, bools and complex numbers raise InvalidTypeError. With the tube
    radius ``r``, the translation must also lie within +-1e6 r in each coordinate
    (:data:`kinegami.validation.LENGTH_FACTOR`).
    """
    if _is_se3(Pose):
        if len(Pose) != 1:
            raise InvalidParameterError(f"{name} must be a single SE3, got {len(Pose)} poses")
        T = np.array(Pose.A, dtype=float)
    else:
        try:
            T = _real_matrix(Pose, name)
        except OverflowError:  # a Python int beyond the float range
            raise InvalidParameterError(
                f"{name} must be finite, got an entry beyond the float range (+-1.8e308)"
            ) from None
    if T.shape != (4, 4):
        raise InvalidParameterError(f"{name} must be a 4x4 rigid transform, got shape {T.shape}")
    if not np.all(np.isfinite(T)):
        raise InvalidParameterError(f"{name} must be finite, got a matrix containing NaN or inf")
    if not is_rigid_transform(T, tol=1e-8):
        raise InvalidParameterError(
            f"{name} must be a proper rigid transform (orthonormal rotation with determinant +1 "
            f"and last row 0 0 0 1), got {shown(np.round(T, 6).tolist(), 200)}"
        )
    if r is not None:
        check_translation_part(name, T, r)
    T.setflags(write=False)
    return T


def _frozen(T: np.ndarray) -> np.ndarray:
    T = np.array(T, dtype=float)
    T.setflags(write=False)
    return T


class Joint(ReadOnlyAttributes):
    """Base class of all joints (abstract: use one of the subclasses).

    Joints are values: assigning or deleting a public attribute (``joint.r = 5``) raises
    :class:`~kinegami.errors.ReadOnlyError` (docs/errors.md).
    """

    _READ_ONLY_ADVICE = (
        "joints are values; build a new joint with the value you want, or change the chain's "
        "joint with its edit methods (translateJointAlongAxisOfMotion, "
        "rotateJointAboutAxisOfMotion, transformJoint, setJointState)"
    )

    #: Index of the Pose column that is the path direction (overridden by Waypoint).
    _PATH_INDEX = 2

    #: How the joint moves what is beyond it (kinegami.geometry.screws): FIXED (tips,
    #: waypoints), REVOLUTE (about the Pose z axis) or PRISMATIC (along it).
    motion = FIXED
    #: False for a joint without a solid (a waypoint only routes the tube).
    has_body = True
    #: The joint closes the tube's start (nothing may precede it: only a root) or its end
    #: (nothing may follow it).
    closes_start = False
    closes_end = False
    #: The design-file fields that are angles (written in the file's angleUnits).
    design_angles: tuple[str, ...] = ()

    def __init__(self, numSides, r, neutralLength, Pose):
        self._numSides = check_num_sides(numSides)
        self._r = check_radius(r)
        self._neutralLength = float(neutralLength)
        self._T = pose_array(Pose, r=self._r)
        self._state = 0.0

    # --- published attributes -------------------------------------------------------------
    @property
    def numSides(self) -> int:
        """Number of sides of the tube's polygon cross-section (even, >= 4)."""
        return self._numSides

    @property
    def r(self) -> float:
        """Tube radius (circumradius of the polygon)."""
        return self._r

    @property
    def neutralLength(self) -> float:
        """Distance from the proximal to the distal frame at state 0."""
        return self._neutralLength

    @property
    def state(self) -> float:
        """Current state (0 at construction); change it with ``KinematicChain.setJointState``."""
        return self._state

    @property
    def Pose(self) -> SE3:
        """Pose of the joint centre at state 0; z is the axis of motion (world coordinates).

        A new SE3 each time: changing it does not change the joint (edit through the chain).
        """
        return as_se3(np.array(self._T))

    @property
    def pose_matrix(self) -> np.ndarray:
        """The Pose as a read-only 4x4 numpy array."""
        return self._T

    def pathIndex(self) -> int:
        """Index (0 = x, 1 = y, 2 = z) of the Pose axis that is the path direction."""
        return self._PATH_INDEX

    def stateRange(self) -> tuple[float, float]:
        """The closed interval of valid states."""
        return (0.0, 0.0)

    # --- frames (4x4 arrays) --------------------------------------------------------------
    def path_direction(self) -> np.ndarray:
        """Unit path direction (column ``pathIndex()`` of the Pose)."""
        return self._T[:3, self.pathIndex()]

    def state_transform(self, delta: float) -> np.ndarray:
        """World motion G(delta) that a state change by ``delta`` applies downstream."""
        return np.eye(4)

    # --- the joint's kind as data: its solid and its centreline (docs/architecture.md) ------
    def body_pieces(self, split: bool = False) -> tuple[BodyPiece, ...]:
        """The joint's solid at its current state as convex pieces (meshes, views and URDF
        draw them). Here: the hull of the proximal and distal cross sections. ``split`` asks
        for pieces that each move with one side of the joint (the URDF's rigid bodies)."""
        n, r = self.numSides, self.r
        points = np.vstack([regular_polygon(self.proximal_dubins_frame(), r, n),
                            regular_polygon(self.distal_dubins_frame(), r, n)])  # fmt: skip
        return (BodyPiece("", points),)

    def capsule_segments(self) -> tuple[CapsuleSegment, ...]:
        """The joint's centreline, which the clearance engine's capsules follow: here the
        segment from the proximal to the distal origin, fixed to the body before the joint."""
        ends_move = self.motion == PRISMATIC
        return (CapsuleSegment(self.proximal_frame()[:3, 3], self.distal_frame()[:3, 3],
                               False, ends_move),)  # fmt: skip

    def design_fields(self) -> dict:
        """The parameters a design file holds for this joint besides type, pose and
        placement (radians, the chain's length units); see :data:`JOINT_KINDS`."""
        raise InvalidTypeError(
            f"cannot save a joint of type {type(self).__name__}: design files know "
            f"{', '.join(JOINT_KINDS)}"
        )

    @classmethod
    def design_defaults(cls, r: float) -> dict:
        """Default values of the design fields (what a new joint of this kind gets in the
        editor when a field is not given), for tube radius ``r``."""
        return {}

    @classmethod
    def from_design(cls, numSides: int, r: float, pose, fields: dict):
        """The joint of a design file's entry (``fields``: its parameters, angles in radians,
        lengths in the chain's units; the inverse of :meth:`design_fields`)."""
        raise InvalidTypeError(f"design files cannot hold a {cls.__name__}")

    def proximal_frame(self) -> np.ndarray:
        """Proximal frame (independent of the state) as a 4x4 array."""
        T = np.array(self._T)
        T[:3, 3] -= (self._neutralLength / 2.0) * self.path_direction()
        return T

    def distal_frame(self) -> np.ndarray:
        """Distal frame at the current state as a 4x4 array."""
        T = np.array(self._T)
        T[:3, 3] += (self._neutralLength / 2.0) * self.path_direction()
        if self._state != 0.0:
            T = self.state_transform(self._state) @ T
        return T

    def proximal_dubins_frame(self) -> np.ndarray:
        """Proximal frame with its axes permuted so x is the path direction."""
        return dubins_frame(self.proximal_frame(), self.pathIndex())

    def distal_dubins_frame(self) -> np.ndarray:
        """Distal frame with its axes permuted so x is the path direction."""
        return dubins_frame(self.distal_frame(), self.pathIndex())

    # --- published frame accessors (SE3) ----------------------------------------------------
    def ProximalFrame(self) -> SE3:
        """Proximal frame (where the incoming link ends) as an SE3."""
        return as_se3(self.proximal_frame())

    def DistalFrame(self) -> SE3:
        """Distal frame (where the outgoing link starts) at the current state, as an SE3."""
        return as_se3(self.distal_frame())

    def ProximalDubinsFrame(self) -> SE3:
        """Proximal Dubins frame (x = path direction) as an SE3."""
        return as_se3(self.proximal_dubins_frame())

    def DistalDubinsFrame(self) -> SE3:
        """Distal Dubins frame (x = path direction) at the current state, as an SE3."""
        return as_se3(self.distal_dubins_frame())

    # --- bounding ball --------------------------------------------------------------------
    def boundingBall(self) -> Ball:
        """A ball containing the joint at its current state (docs/theory/chain.md §2)."""
        return Ball(self._T[:3, 3], math.hypot(self._r, self._neutralLength / 2.0))

    def bounding_radius(self) -> float:
        """Radius of ``boundingBall()``."""
        return self.boundingBall().r

    # --- value-style modifications (used by the chain) -------------------------------------
    def _copy(self) -> Joint:
        new = object.__new__(type(self))
        new.__dict__.update(self.__dict__)
        new.__dict__.pop("_moved_from", None)
        return new

    def with_pose(self, T: np.ndarray) -> Joint:
        """A copy with the Pose replaced by the 4x4 array ``T`` (state kept)."""
        new = self._copy()
        new._T = _frozen(T)
        return new

    def with_state(self, state: float) -> Joint:
        """A copy with the state replaced (no range check: the chain checks)."""
        new = self._copy()
        new._state = float(state)
        return new

    def transformed(self, T: np.ndarray) -> Joint:
        """A copy whose Pose is moved by the world transform ``T`` (Pose <- T Pose)."""
        new = self.with_pose(T @ self._T)
        # the joint this one is a rigid copy of, and the transform from it (kinegami.chain.bodies
        # moves that joint's cached capsules instead of rebuilding them)
        origin, moved = self.__dict__.get("_moved_from", (self, None))
        new.__dict__["_moved_from"] = (origin, T if moved is None else T @ moved)
        return new

    def with_reversed_path_direction(self) -> Joint:
        """A copy with the path direction reversed, axis-of-motion line kept.

        See docs/theory/chain.md §1.
        """
        flip = rot_x(math.pi) if self.pathIndex() == 2 else rot_z(math.pi)
        return self.with_pose(_exact_flip(self._T, flip))

    def with_xhat_about_zhat(self, x) -> Joint:
        """A copy with x set to ``x`` (orthogonalised against z), z and the origin kept."""
        z = self._T[:3, 2]
        x = np.asarray(x, dtype=float)
        x = unit(x - (x @ z) * z)
        T = np.array(self._T)
        T[:3, 0] = x
        T[:3, 1] = cross3(z, x)
        return self.with_pose(T)

    def translated_along_z(self, distance: float) -> Joint:
        """A copy moved by ``distance`` along its own z axis."""
        T = np.array(self._T)
        T[:3, 3] += distance * T[:3, 2]
        return self.with_pose(T)

    # --- pattern --------------------------------------------------------------------------
    @property
    def pattern(self):
        """The joint's crease pattern (a TubularPattern).

        Patterns are values, so joints with the same parameters share one (built on first use).
        """
        return _catalog_pattern(*self.pattern_recipe())

    def pattern_pieces(self) -> list[tuple[str, tuple]]:
        """What :attr:`pattern` is built from, as ``LinkCSC.pattern_pieces``: a (catalog kind,
        build arguments) pair per module, in order (nothing is built)."""
        return list(self.pattern_recipe())

    def pattern_recipe(self) -> tuple:
        """The pieces of this joint's pattern: (catalog module kind, its build arguments) each,
        composed in order (see kinegami.pattern.catalog)."""
        raise InvalidTypeError(f"{type(self).__name__} has no crease pattern")

    def _describe(self) -> str:
        return ""

    def __repr__(self) -> str:
        p = ", ".join(f"{v:.6g}" for v in self._T[:3, 3])
        z = ", ".join(f"{v:.6g}" for v in self._T[:3, 2])
        extra = self._describe()
        return (
            f"{type(self).__name__}(numSides={self._numSides}, r={self._r:.6g}{extra}, "
            f"origin=({p}), z=({z}), state={self._state:.6g})"
        )


def _exact_flip(T: np.ndarray, flip: np.ndarray) -> np.ndarray:
    """T @ flip for flip = Rx(pi) or Rz(pi), done by exact sign changes (no round-off)."""
    out = np.array(T)
    if flip[1, 1] < 0 and flip[2, 2] < 0:  # Rx(pi): y, z negated
        out[:3, 1] = -T[:3, 1]
        out[:3, 2] = -T[:3, 2]
    else:  # Rz(pi): x, y negated
        out[:3, 0] = -T[:3, 0]
        out[:3, 1] = -T[:3, 1]
    return out


class RevoluteJoint(Joint):
    """A revolute joint: rotation about the Pose z axis; the tube passes through along x.

    Parameters
    ----------
    numSides : even number of polygon sides, >= 4.
    r : tube radius, in [1e-6, 1e6].
    totalBendingAngle : total range of rotation in (0, 2pi) radians; states lie in
        [-totalBendingAngle/2, +totalBendingAngle/2].
    Pose : SE3 (or 4x4 array) of the joint centre; z is the rotation axis. Its translation
        lies within +-1e6 r (as every length and translation, see :mod:`kinegami.validation`).
    numSinkLayers : number of recursive sink gadget layers in the pattern (>= 1; stiffness).
    """

    motion = REVOLUTE
    design_angles = ("totalBendingAngle",)

    _PATH_INDEX = 0

    def __init__(self, numSides, r, totalBendingAngle, Pose, numSinkLayers=1):
        n = check_num_sides(numSides)
        r = check_radius(r)
        B = check_in_range(
            "totalBendingAngle", totalBendingAngle, 0.0, 2.0 * math.pi, range_text="(0, 2pi)"
        )
        self._set_attribute("totalBendingAngle", B)
        self._set_attribute(
            "numSinkLayers", check_num_sink_layers(numSinkLayers)
        )
        L = 2.0 * r * math.cos(math.pi / n) * math.tan(B / 4.0)
        super().__init__(n, r, L, Pose)

    def stateRange(self) -> tuple[float, float]:
        return (-self.totalBendingAngle / 2.0, self.totalBendingAngle / 2.0)

    def state_transform(self, delta: float) -> np.ndarray:
        return rotation_about_line(self._T[:3, 2], self._T[:3, 3], delta)

    def hull_points(self) -> tuple[np.ndarray, np.ndarray]:
        """Point sets whose hulls are the two halves of the body, each (n + 2, 3): the n-gon
        of the proximal (distal) Dubins frame plus the hinge segment p +- (side/2) z at the
        centre (for an extended joint, the n-gons at the inner ends of its tubes)."""
        n, r = self.numSides, self.r
        T = self._T
        hinge = hinge_segment(T[:3, 3], T[:3, 2], polygon_side(r, n))
        h = self._tube_length()
        proximal = shifted_frame(self.proximal_dubins_frame(), h)
        distal = shifted_frame(self.distal_dubins_frame(), -h)
        return (np.vstack([regular_polygon(proximal, r, n), hinge]),
                np.vstack([regular_polygon(distal, r, n), hinge]))  # fmt: skip

    def _tube_length(self) -> float:
        return 0.0

    def body_pieces(self, split: bool = False) -> tuple[BodyPiece, ...]:
        """Two halves, each the hull of one side's n-gon and the hinge segment; the distal
        half turns with the state."""
        first, second = self.hull_points()
        return (BodyPiece("proximal", first), BodyPiece("distal", second))

    def capsule_segments(self) -> tuple[CapsuleSegment, ...]:
        """Proximal origin -> centre (fixed) and centre -> distal origin (turns with the
        joint: a kink by the state at the hinge)."""
        centre = self._T[:3, 3]
        return (CapsuleSegment(self.proximal_frame()[:3, 3], centre, False, False,
                               ", proximal half"),
                CapsuleSegment(centre, self.distal_frame()[:3, 3], True, True,
                               ", distal half"))  # fmt: skip

    def design_fields(self) -> dict:
        return {"totalBendingAngle": float(self.totalBendingAngle),
                "numSinkLayers": int(self.numSinkLayers)}  # fmt: skip

    @classmethod
    def design_defaults(cls, r: float) -> dict:
        return {"totalBendingAngle": math.pi, "numSinkLayers": 1}

    @classmethod
    def from_design(cls, numSides: int, r: float, pose, fields: dict):
        return cls(numSides, r, fields["totalBendingAngle"], pose, fields.get("numSinkLayers", 1))

    def pattern_recipe(self) -> tuple:
        return (("revolute", (self.numSides, self.r, self.totalBendingAngle, self.numSinkLayers)),)

    def _describe(self) -> str:
        return f", totalBendingAngle={self.totalBendingAngle:.6g}"


class ExtendedRevoluteJoint(RevoluteJoint):
    """A revolute joint with a straight tube of length ``tubeLength`` on each side."""

    def __init__(self, numSides, r, totalBendingAngle, tubeLength, Pose, numSinkLayers=1):
        self._set_attribute("tubeLength", check_length("tubeLength", tubeLength, check_radius(r)))
        super().__init__(numSides, r, totalBendingAngle, Pose, numSinkLayers)
        self._neutralLength += 2.0 * self.tubeLength

    def pattern_recipe(self) -> tuple:
        tube = ("tube", (self.numSides, self.r, self.tubeLength))
        return (tube, *super().pattern_recipe(), tube)

    def _tube_length(self) -> float:
        return self.tubeLength

    def body_pieces(self, split: bool = False) -> tuple[BodyPiece, ...]:
        """The two halves with their straight tubes (each half is convex)."""
        first, second = self.hull_points()
        n, r = self.numSides, self.r
        h = self.tubeLength
        pieces = []
        for side, hull, frame, sign in (("proximal", first, self.proximal_dubins_frame(), 1.0),
                                        ("distal", second, self.distal_dubins_frame(), -1.0)):
            outer = regular_polygon(frame, r, n)
            inner = regular_polygon(shifted_frame(frame, sign * h), r, n)
            pieces.append(BodyPiece(side, np.vstack([hull, outer]),
                                    (("hull", hull), ("prism", outer, inner))))
        return tuple(pieces)  # fmt: skip

    def design_fields(self) -> dict:
        return {"totalBendingAngle": float(self.totalBendingAngle),
                "tubeLength": float(self.tubeLength),
                "numSinkLayers": int(self.numSinkLayers)}  # fmt: skip

    @classmethod
    def design_defaults(cls, r: float) -> dict:
        return {"totalBendingAngle": math.pi, "tubeLength": 2.0 * r, "numSinkLayers": 1}

    @classmethod
    def from_design(cls, numSides: int, r: float, pose, fields: dict):
        return cls(numSides, r, fields["totalBendingAngle"], fields["tubeLength"], pose,
                   fields.get("numSinkLayers", 1))  # fmt: skip


class PrismaticJoint(Joint):
    """A prismatic joint (REBO bellows in a sleeve): translation along the Pose z axis.

    Parameters
    ----------
    numSides, r : as for every joint.
    neutralLength : length d of the joint at state 0, in (0, 1e6 r].
    numLayers : number of REBO layers (integer >= 1).
    coneAngle : REBO cone angle in [pi/6, pi/2) radians; the state range is
        [d/(2 sin coneAngle) - d, d/sin coneAngle - d].
    Pose : SE3 (or 4x4 array) of the joint centre at state 0; z is the axis of motion.
    """

    motion = PRISMATIC
    design_angles = ("coneAngle",)

    def __init__(self, numSides, r, neutralLength, numLayers, coneAngle, Pose):
        n = check_num_sides(numSides)
        r = check_radius(r)
        d = check_length("neutralLength", neutralLength, r)
        self._set_attribute("numLayers", check_num_layers(numLayers))
        cone = check_in_range(
            "coneAngle",
            coneAngle,
            math.pi / 6.0,
            math.pi / 2.0,
            low_inclusive=True,
            range_text="[pi/6, pi/2)",
        )
        self._set_attribute("coneAngle", cone)
        super().__init__(n, r, d, Pose)

    def stateRange(self) -> tuple[float, float]:
        d = self._neutralLength
        s = math.sin(self.coneAngle)
        # at coneAngle = pi/6 the lower bound is 0 exactly; sin rounds it to +4e-16
        return (min(d / (2.0 * s) - d, 0.0), d / s - d)

    def state_transform(self, delta: float) -> np.ndarray:
        return translation(delta * self._T[:3, 2])

    def body_pieces(self, split: bool = False) -> tuple[BodyPiece, ...]:
        """The n-gon prism from the proximal origin along z, length L + state; split: two
        halves of length L/2 at either end (each moving with its side)."""
        n, r = self.numSides, self.r
        z = self._T[:3, 2]
        bottom = regular_polygon(self.proximal_dubins_frame(), r, n)
        L, s = self.neutralLength, self.state
        if not split:
            top = bottom + (L + s) * z
            return (BodyPiece("", np.vstack([bottom, top]), (("prism", bottom, top),)),)
        top = regular_polygon(self.distal_dubins_frame(), r, n)
        return (BodyPiece("proximal", np.vstack([bottom, bottom + 0.5 * L * z])),
                BodyPiece("distal", np.vstack([top - 0.5 * L * z, top])))  # fmt: skip

    def design_fields(self) -> dict:
        return {"neutralLength": float(self.neutralLength), "numLayers": int(self.numLayers),
                "coneAngle": float(self.coneAngle)}  # fmt: skip

    @classmethod
    def design_defaults(cls, r: float) -> dict:
        return {"neutralLength": 3.0 * r, "numLayers": 3, "coneAngle": math.pi / 4}

    @classmethod
    def from_design(cls, numSides: int, r: float, pose, fields: dict):
        return cls(numSides, r, fields["neutralLength"], fields["numLayers"],
                   fields["coneAngle"], pose)  # fmt: skip

    def distal_frame(self) -> np.ndarray:
        T = np.array(self._T)
        T[:3, 3] += (self._neutralLength / 2.0 + self._state) * T[:3, 2]
        return T

    def boundingBall(self) -> Ball:
        s = self._state
        return Ball(
            self._T[:3, 3] + (s / 2.0) * self._T[:3, 2],
            math.hypot(self._r, (self._neutralLength + s) / 2.0),
        )

    def pattern_recipe(self) -> tuple:
        args = (self.numSides, self.r, self.neutralLength, self.numLayers, self.coneAngle)
        return (("prismatic", args),)

    def _describe(self) -> str:
        return (
            f", neutralLength={self._neutralLength:.6g}, numLayers={self.numLayers}, "
            f"coneAngle={self.coneAngle:.6g}"
        )


class Waypoint(Joint):
    """A pose the tube passes through, with no structure and no state.

    ``pathIndex`` (0, 1 or 2, default 2) says which Pose axis the tube follows.
    """

    def __init__(self, numSides, r, Pose, pathIndex=2):
        n = check_num_sides(numSides)
        r = check_radius(r)
        k = check_int("pathIndex", pathIndex)
        if k not in (0, 1, 2):
            raise InvalidParameterError(f"pathIndex must be 0, 1 or 2, got {k}")
        self._path_index = k
        super().__init__(n, r, 0.0, Pose)

    def pathIndex(self) -> int:
        return self._path_index

    def boundingBall(self) -> Ball:
        return Ball(self._T[:3, 3], self._r)

    has_body = False

    def pattern_recipe(self) -> tuple:
        return (("waypoint", (self.numSides, self.r)),)

    def body_pieces(self, split: bool = False) -> tuple[BodyPiece, ...]:
        """None: a waypoint has no solid."""
        return ()

    def capsule_segments(self) -> tuple[CapsuleSegment, ...]:
        """None: a waypoint adds nothing to the tube."""
        return ()

    def design_fields(self) -> dict:
        return {"pathIndex": int(self.pathIndex())}

    @classmethod
    def design_defaults(cls, r: float) -> dict:
        return {"pathIndex": 2}

    @classmethod
    def from_design(cls, numSides: int, r: float, pose, fields: dict):
        return cls(numSides, r, pose, fields.get("pathIndex", 2))

    def _describe(self) -> str:
        return f", pathIndex={self._path_index}"


class Tip(Joint):
    """Base of the closed tube ends; ``length`` is the axial length, in (0, 1e6 r]."""

    def __init__(self, numSides, r, Pose, length):
        n = check_num_sides(numSides)
        r = check_radius(r)
        self._set_attribute("length", check_length("length", length, r))
        super().__init__(n, r, self.length, Pose)

    def _describe(self) -> str:
        return f", length={self.length:.6g}"

    def open_and_closed_ends(self) -> tuple[np.ndarray, np.ndarray]:
        """The Dubins frames of the tip's open end and of its closed (folded) end: a tip that
        closes the tube's start is closed at its proximal end, one that closes its end at its
        distal end."""
        proximal, distal = self.proximal_dubins_frame(), self.distal_dubins_frame()
        return (distal, proximal) if self.closes_start else (proximal, distal)

    def hull_points(self) -> np.ndarray:
        """(n + 2, 3): the n-gon at the open end plus a segment of one side's length at the
        closed end (along the frame's c axis, parallel to two sides of the polygon)."""
        n, r = self.numSides, self.r
        open_end, closed_end = self.open_and_closed_ends()
        segment = hinge_segment(closed_end[:3, 3], closed_end[:3, 2], polygon_side(r, n))
        return np.vstack([regular_polygon(open_end, r, n), segment])

    def body_pieces(self, split: bool = False) -> tuple[BodyPiece, ...]:
        """The hull of :meth:`hull_points`."""
        return (BodyPiece("", self.hull_points()),)

    def design_fields(self) -> dict:
        return {"length": float(self.length)}

    @classmethod
    def design_defaults(cls, r: float) -> dict:
        return {"length": 1.5 * r}

    @classmethod
    def from_design(cls, numSides: int, r: float, pose, fields: dict):
        return cls(numSides, r, Pose=pose, length=fields["length"])


class StartTip(Tip):
    """The closed start of the tube (nothing may precede it). Path direction: Pose z."""

    closes_start = True

    def pattern_recipe(self) -> tuple:
        return (("start_tip", (self.numSides, self.r, self.length)),)


class EndTip(Tip):
    """The closed end of the tube (nothing may follow it). Path direction: Pose z."""

    closes_end = True

    def pattern_recipe(self) -> tuple:
        return (("end_tip", (self.numSides, self.r, self.length)),)


#: The joint kinds design files know, by their "type" name (docs/architecture.md: a new kind is
#: its class, which gives its solid, centreline, motion and design fields, plus one
#: :func:`register_joint_kind`).
JOINT_KINDS: dict[str, type[Joint]] = {}


def register_joint_kind(cls: type[Joint]) -> type[Joint]:
    """Make ``cls`` a joint kind of design files (under its class name); returns it."""
    if not (isinstance(cls, type) and issubclass(cls, Joint)):
        raise InvalidTypeError(f"a joint kind must be a Joint subclass, got {cls!r}")
    JOINT_KINDS[cls.__name__] = cls
    return cls


register_joint_kind(StartTip)
register_joint_kind(EndTip)
register_joint_kind(RevoluteJoint)
register_joint_kind(ExtendedRevoluteJoint)
register_joint_kind(PrismaticJoint)
register_joint_kind(Waypoint)


@functools.lru_cache(maxsize=256)
def _catalog_pattern(*pieces: tuple):
    """The pattern of (module kind, build arguments) pieces, composed in order; looked up in
    the module catalog (patterns are immutable: cached)."""
    from kinegami.pattern import TubularPattern
    from kinegami.pattern.catalog import module_kind

    built: dict = {}
    for piece in pieces:
        if piece not in built:
            kind, args = piece
            built[piece] = module_kind(kind).build(*args)
    patterns = [built[piece] for piece in pieces]
    return patterns[0] if len(patterns) == 1 else TubularPattern.concatenate(patterns)


def check_same_tube(joint: Joint, numSides: int, r: float) -> None:
    """Raise IncompatibleJointError if ``joint`` has another numSides or r."""
    if not isinstance(joint, Joint):
        raise InvalidTypeError(f"expected a Joint, got {type(joint).__name__}")
    if joint.numSides != numSides:
        raise IncompatibleJointError(
            f"numSides of the new joint ({joint.numSides}) must equal the chain's ({numSides})"
        )
    if joint.r != r:
        raise IncompatibleJointError(
            f"r of the new joint ({joint.r!r}) must equal the chain's ({r!r})"
        )
