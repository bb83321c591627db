"""The tree construction: a KinematicTree from a joint specification (docs/trees.md, "The tree
construction"; the theory in docs/theory/trees.md).

A *joint specification* gives, for every joint, its type, its parameters, its parent and the
line its axis of motion lies on. What it leaves free (where on that line the joint sits, its
roll about the line and the sign of its axis) the construction chooses so that every link is
guaranteed to exist: all joints are oriented towards one growth direction n, and each new joint
is slid along its axis until it lies beyond a bounding cylinder of everything built before it.

>>> spec = JointSpecificationTree(Waypoint(4, 1, SE3()))
>>> spec.addJoint(0, RevoluteJoint(4, 1, np.pi, SE3.Trans(0, 0, 4) * SE3.Ry(np.pi / 2)))
1
>>> spec.addJoint(0, EndTip(4, 1, SE3.Trans(3, 0, 2), 1))
2
>>> tree = from_specification(spec, growth_direction=(1, 0, 1))
>>> tree.Parents  # the tip comes after two waypoints (nodes 2 and 3)
(-1, 0, 0, 2, 3)
>>> tree.construction.node_of
(0, 1, 4)
"""

from __future__ import annotations

import json
import math
import os
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from kinegami.chain.joints import (
    JOINT_KINDS,
    Joint,
    Waypoint,
    check_same_tube,
    pose_array,
)
from kinegami.errors import (
    ClearanceWarning,
    DesignError,
    InvalidParameterError,
    InvalidTypeError,
    JointIndexError,
    NoPathError,
    PlacementWarning,
)
from kinegami.geometry.balls import Ball, merge_balls
from kinegami.geometry.frames import rot_x, rot_y, rot_z, rotation_matrix, translation
from kinegami.tree.model import KinematicTree
from kinegami.validation import (
    FILE_NUM_SIDES_MAX,
    R_MAX,
    R_MIN,
    check_bool,
    check_int,
    check_num_sides,
    check_radius,
    check_real,
    shown,
)

__all__ = [
    "JointSpecification",
    "JointSpecificationTree",
    "load_joint_specification",
    "from_specification",
    "choose_growth_direction",
    "growth_quality",
    "BoundingCylinder",
    "TreeConstruction",
    "SIBLING_AZIMUTH",
    "JOINT_TREE_FORMAT",
]

#: The format name of joint specification files (``"format"`` at their top level).
JOINT_TREE_FORMAT = "kinegami.joint_tree/1"
#: Elbow size of the constructed tree (radians).
MAX_ANGLE_PER_ELBOW = math.pi / 10
#: Azimuth step (radians) about n between the routes of successive later siblings of one parent
#: (docs/trees.md): large enough that two routes leaving the same frame are 2r apart within a
#: few r, small enough that the waypoints stay near the parent's side of the cylinder. 0.0
#: gives the published construction, in which the routes run side by side.
SIBLING_AZIMUTH = 0.5
#: Smallest |z . n| accepted for a given growth direction (a joint's slide grows as 1/|z . n|).
MIN_GROWTH_DOT = 1e-6
#: Number of points of the Fibonacci lattice searched for the growth direction.
LATTICE_SIZE = 10_000
#: Growth directions whose qualities differ by at most this count as tied.
TIE_TOLERANCE = 1e-9
_PLANE_TOLERANCE = 1e-8  # signed distances below this are 0 (docs/theory/chain.md §0)

# --- the specification -------------------------------------------------------------------------
def _frozen(array) -> np.ndarray:
    out = np.array(array, dtype=float)
    out.setflags(write=False)
    return out


@dataclass(frozen=True, eq=False)
class JointSpecification:
    """A joint specification (a value): the joints with their specified poses, their parents
    and their names, in the order they were given (a parent always comes before its children).

    Each joint's Pose (world coordinates) gives its type, parameters and **axis line** (the
    line through the Pose origin along its z axis); the construction keeps the line and chooses
    the rest. Build one with :class:`JointSpecificationTree` or read one with
    :func:`load_joint_specification`.

    Attributes
    ----------
    Joints : tuple of Joint, the specified joints (index 0 is the root).
    Parents : tuple of int, the parent of every joint (-1 for the root).
    names : tuple of str, one name per joint.
    growth_direction : the growth direction the specification asks for (a read-only unit
        3-vector), or None to let the construction choose.
    """

    Joints: tuple
    Parents: tuple
    names: tuple
    growth_direction: np.ndarray | None = None

    def __post_init__(self):
        joints = tuple(self.Joints)
        parents = self.Parents
        if isinstance(parents, str | bytes) or not (
            isinstance(parents, Sequence) or (isinstance(parents, np.ndarray) and parents.ndim == 1)
        ):
            raise InvalidTypeError(
                "Parents must be a sequence of integers (one per joint, -1 for the root), "
                f"got {shown(parents)}"
            )
        parents = tuple(check_int(f"Parents[{k}]", p, floats=False) for k, p in enumerate(parents))
        names = tuple(str(n) for n in self.names)
        if not joints:
            raise InvalidParameterError("a joint specification needs a root joint, got none")
        if not len(joints) == len(parents) == len(names):
            raise InvalidParameterError(
                f"Joints, Parents and names must have one entry per joint, got {len(joints)}, "
                f"{len(parents)} and {len(names)}"
            )
        for i, joint in enumerate(joints):
            if not isinstance(joint, Joint):
                raise InvalidTypeError(f"Joints[{i}] must be a Joint, got {type(joint).__name__}")
            check_same_tube(joint, joints[0].numSides, joints[0].r)
        _check_structure(joints, parents)
        object.__setattr__(self, "Joints", joints)
        object.__setattr__(self, "Parents", parents)
        object.__setattr__(self, "names", names)
        if self.growth_direction is not None:
            object.__setattr__(
                self, "growth_direction", _frozen(_unit_direction(self.growth_direction))
            )

    @property
    def r(self) -> float:
        """The tube radius (shared by every joint)."""
        return self.Joints[0].r

    @property
    def numSides(self) -> int:
        """The polygon side count (shared by every joint)."""
        return self.Joints[0].numSides

    @property
    def Children(self) -> tuple[tuple[int, ...], ...]:
        """The children of every joint, in the order they were given."""
        children: list[list[int]] = [[] for _ in self.Joints]
        for k, p in enumerate(self.Parents):
            if p >= 0:
                children[p].append(k)
        return tuple(tuple(c) for c in children)

    def __len__(self) -> int:
        return len(self.Joints)

    def axis(self, index: int) -> tuple[np.ndarray, np.ndarray]:
        """The axis line of joint ``index``: (a point of it, its unit direction), world."""
        T = self.Joints[_spec_index(index, len(self.Joints))].pose_matrix
        return T[:3, 3], T[:3, 2]

    def depth_first(self) -> tuple[int, ...]:
        """The joint indices in depth-first pre-order, children in the order given."""
        children = self.Children
        order, stack = [], [0]
        while stack:
            k = stack.pop()
            order.append(k)
            stack.extend(reversed(children[k]))
        return tuple(order)

    def __repr__(self) -> str:
        leaves = sum(1 for c in self.Children if not c)
        return f"JointSpecification({len(self.Joints)} joints, {leaves} leaves)"

    # --- files -------------------------------------------------------------------------------
    @classmethod
    def from_dict(cls, data: Mapping, file=None) -> JointSpecification:
        """The specification in a ``kinegami.joint_tree/1`` document (a dict, as read from
        JSON; docs/trees.md says what it holds). Raises DesignError naming the field."""
        return _from_document(data, file)

    @classmethod
    def load(cls, path) -> JointSpecification:
        """Read a ``kinegami.joint_tree/1`` file (see :func:`load_joint_specification`)."""
        return load_joint_specification(path)


def _spec_index(index, count: int, name: str = "index") -> int:
    if isinstance(index, bool) or not isinstance(index, int | np.integer):
        raise InvalidTypeError(f"{name} must be an integer, got {shown(index)}")
    i = int(index)
    if not -count <= i < count:
        raise JointIndexError(
            f"{name} must be in [{-count}, {count - 1}] for a specification of {count} joints, "
            f"got {i}"
        )
    return i % count


def _check_structure(joints: Sequence[Joint], parents: Sequence[int]) -> None:
    if parents[0] != -1:
        raise InvalidParameterError(f"Parents[0] (the root's parent) must be -1, got {parents[0]}")
    if joints[0].closes_end:
        raise InvalidParameterError("the root joint cannot be an EndTip (nothing may follow it)")
    for i in range(1, len(joints)):
        p = parents[i]
        if not 0 <= p < i:
            raise InvalidParameterError(
                f"Parents[{i}] must be the index of an earlier joint, in [0, {i - 1}], got {p}"
            )
        if joints[p].closes_end:
            raise InvalidParameterError(
                f"joint {i}'s parent, joint {p}, is an EndTip: nothing can follow it"
            )
        if joints[i].closes_start:
            raise InvalidParameterError(f"joint {i} is a StartTip: a StartTip can only be the root")


class JointSpecificationTree:
    """A joint specification built joint by joint (published name).

    Parameters
    ----------
    root : the root joint; its Pose (world coordinates) gives its axis line.
    name : the root's name (default "root").

    ``addJoint(parent, joint, relative=True)`` adds a joint under any earlier joint; with
    ``relative`` its Pose is taken relative to the parent's *specified* Pose. The tree is only a
    description: :func:`from_specification` builds the robot from it (or from its value,
    :meth:`specification`).

    Examples
    --------
    >>> spec = JointSpecificationTree(Waypoint(4, 1, SE3()))
    >>> spec.addJoint(0, RevoluteJoint(4, 1, np.pi, SE3.Trans(0, 0, 4) * SE3.Ry(np.pi / 2)),
    ...               name="shoulder")
    1
    >>> spec.addJoint(1, EndTip(4, 1, SE3.Trans(4, 0, 0), 1))
    2
    >>> spec.Parents, spec.names
    ((-1, 0, 1), ('root', 'shoulder', 'joint2'))
    """

    def __init__(self, root: Joint, name: str = "root"):
        if not isinstance(root, Joint):
            raise InvalidTypeError(f"root must be a Joint, got {type(root).__name__}")
        _check_structure([root], [-1])
        self._joints: list[Joint] = [root._copy()]
        self._parents: list[int] = [-1]
        self._names: list[str] = [_check_name(name, [])]

    @property
    def Joints(self) -> tuple[Joint, ...]:
        """The specified joints (world poses), in the order they were added."""
        return tuple(self._joints)

    @property
    def Parents(self) -> tuple[int, ...]:
        """The parent of every joint (-1 for the root)."""
        return tuple(self._parents)

    @property
    def Children(self) -> tuple[tuple[int, ...], ...]:
        """The children of every joint, in the order they were added."""
        return self.specification().Children

    @property
    def names(self) -> tuple[str, ...]:
        """The joint names."""
        return tuple(self._names)

    def __len__(self) -> int:
        return len(self._joints)

    def addJoint(self, parentIndex: int, newJoint: Joint, relative: bool = True,
                 name: str | None = None) -> int:  # fmt: skip
        """Add ``newJoint`` under joint ``parentIndex`` and return its index.

        Parameters
        ----------
        parentIndex : an existing joint (negative counts from the end).
        newJoint : the joint (copied); its Pose gives its axis line.
        relative : the Pose is relative to the parent's specified Pose (True) or global.
        name : its name (default ``"joint<index>"``); names are unique.
        """
        p = _spec_index(parentIndex, len(self._joints), "parentIndex")
        relative = check_bool("relative", relative)
        if not isinstance(newJoint, Joint):
            raise InvalidTypeError(f"newJoint must be a Joint, got {type(newJoint).__name__}")
        check_same_tube(newJoint, self._joints[0].numSides, self._joints[0].r)
        name = f"joint{len(self._joints)}" if name is None else name
        name = _check_name(name, self._names)
        joint = newJoint._copy()
        if relative:
            joint = joint.with_pose(self._joints[p].pose_matrix @ joint.pose_matrix)
        _check_structure([*self._joints, joint], [*self._parents, p])
        self._joints.append(joint)
        self._parents.append(p)
        self._names.append(name)
        return len(self._joints) - 1

    def specification(self, growth_direction=None) -> JointSpecification:
        """The specification as a value (optionally asking for a growth direction)."""
        return JointSpecification(self._joints, self._parents, self._names, growth_direction)

    def __repr__(self) -> str:
        return f"JointSpecificationTree({len(self._joints)} joints)"


def _check_name(name, taken) -> str:
    if not isinstance(name, str) or not name:
        raise InvalidTypeError(f"name must be a non-empty string, got {shown(name)}")
    if name in taken:
        raise InvalidParameterError(f"name must be unique, got {name!r} a second time")
    return name


# --- reading the file format ---------------------------------------------------------------------
def load_joint_specification(path) -> JointSpecification:
    """Read a joint specification file (``kinegami.joint_tree/1``, JSON).

    The file holds ``r``, ``numSides`` and a list ``joints``, each with ``name``, ``type`` (a
    joint class name), ``parent`` (an index, -1 for the root), ``params`` (the class's
    parameters) and ``relative_pose`` (elementary motions ``["Trans", [x, y, z]]``,
    ``["Rx" | "Ry" | "Rz", angle]`` composed left to right and taken relative to the parent's
    pose) or a global 4x4 ``pose``; an optional ``placement.growth_direction`` asks for a
    growth direction. Raises DesignError (a ValueError) naming the file and the field.
    """
    try:
        with open(path, encoding="utf-8") as f:
            data = json.load(f)
    except OSError as error:
        raise DesignError(f"cannot read the file: {error.strerror or error}", file=path) from None
    except json.JSONDecodeError as error:
        raise DesignError(f"not JSON: {error.msg} at line {error.lineno}", file=path) from None
    return _from_document(data, os.fspath(path))


def _motion(step, field: str, file) -> np.ndarray:
    if (not isinstance(step, Sequence) or isinstance(step, str) or len(step) != 2
            or step[0] not in ("Trans", "Rx", "Ry", "Rz")):  # fmt: skip
        raise DesignError(
            'must be ["Trans", [x, y, z]] or ["Rx" | "Ry" | "Rz", angle]',
            field=field, value=step, file=file,
        )  # fmt: skip
    kind, value = step
    try:
        if kind == "Trans":
            v = np.array(value, dtype=float)
            if v.shape != (3,) or not np.all(np.isfinite(v)):
                raise ValueError
            return translation(v)
        angle = float(value)
        if not math.isfinite(angle) or isinstance(value, bool):
            raise ValueError
    except (TypeError, ValueError):
        raise DesignError(
            "must be a finite 3-vector for Trans, a finite angle (radians) for a rotation",
            field=field, value=value, file=file,
        ) from None  # fmt: skip
    return {"Rx": rot_x, "Ry": rot_y, "Rz": rot_z}[kind](angle)


def _from_document(data, file=None) -> JointSpecification:
    if not isinstance(data, Mapping):
        raise DesignError("must be a JSON object", value=type(data).__name__, file=file)
    fmt = data.get("format", JOINT_TREE_FORMAT)
    if fmt != JOINT_TREE_FORMAT:
        raise DesignError(f"must be {JOINT_TREE_FORMAT!r}", field="format", value=fmt, file=file)
    for key in ("r", "numSides", "joints"):
        if key not in data:
            raise DesignError(f"missing (a joint specification needs {key!r})", field=key,
                              file=file)  # fmt: skip
    radius = f"a number in [{R_MIN:g}, {R_MAX:g}] (the tube radius)"
    r = _top_level(data, "r", check_radius, radius, file)
    n = _top_level(data, "numSides", _file_num_sides,
                   f"an even integer >= 4 (at most {FILE_NUM_SIDES_MAX})", file)  # fmt: skip
    entries = data["joints"]
    if not isinstance(entries, Sequence) or isinstance(entries, str) or not entries:
        raise DesignError("must be a non-empty list of joints", field="joints", file=file)
    joints: list[Joint] = []
    parents: list[int] = []
    names: list[str] = []
    for i, entry in enumerate(entries):
        where = f"joints[{i}]"
        if not isinstance(entry, Mapping):
            raise DesignError("must be an object", field=where, value=entry, file=file)
        kind = entry.get("type")
        if kind not in JOINT_KINDS:
            raise DesignError(f"must be one of {', '.join(sorted(JOINT_KINDS))}",
                              field=f"{where}.type", value=kind, file=file)  # fmt: skip
        parent = entry.get("parent", -1 if i == 0 else None)
        if (
            isinstance(parent, bool)
            or not isinstance(parent, int)
            or not ((i == 0 and parent == -1) or 0 <= parent < i)
        ):
            valid = "-1 for the root" if i == 0 else f"an earlier joint's index, in [0, {i - 1}]"
            raise DesignError(f"must be {valid}", field=f"{where}.parent", value=parent,
                              file=file)  # fmt: skip
        name = entry.get("name", f"joint{i}")
        if not isinstance(name, str) or not name or name in names:
            raise DesignError("must be a unique non-empty string", field=f"{where}.name",
                              value=name, file=file)  # fmt: skip
        if "relative_pose" in entry:
            steps = entry["relative_pose"]
            if not isinstance(steps, Sequence) or isinstance(steps, str):
                raise DesignError(
                    "must be a list of elementary motions",
                    field=f"{where}.relative_pose",
                    value=steps,
                    file=file,
                )
            T = np.eye(4)
            for k, step in enumerate(steps):
                T = T @ _motion(step, f"{where}.relative_pose[{k}]", file)
            if parent >= 0:
                T = joints[parent].pose_matrix @ T
            pose_field = f"{where}.relative_pose"
        elif "pose" in entry:
            T = entry["pose"]
            pose_field = f"{where}.pose"
        else:
            raise DesignError("needs a relative_pose or a pose", field=where, file=file)
        try:
            T = pose_array(T, "pose", r)
        except (InvalidParameterError, InvalidTypeError) as error:
            reason = str(error).removeprefix("pose ")  # "must be ...", "translation must ..."
            raise DesignError(reason, field=pose_field, file=file) from None
        params = entry.get("params", {})
        if not isinstance(params, Mapping):
            raise DesignError("must be an object", field=f"{where}.params", value=params,
                              file=file)  # fmt: skip
        try:
            joint = JOINT_KINDS[kind](numSides=n, r=r, Pose=T, **params)
        except TypeError as error:
            raise DesignError(f"wrong parameters for {kind}: {error}", field=f"{where}.params",
                              value=dict(params), file=file) from None  # fmt: skip
        except ValueError as error:  # kinegami's parameter checks (InvalidParameterError)
            raise DesignError(str(error), field=where, file=file) from None
        joints.append(joint)
        parents.append(parent)
        names.append(name)
    direction = _growth_direction(data, file)
    try:
        return JointSpecification(joints, parents, names, direction)
    except ValueError as error:
        raise DesignError(str(error), file=file) from None


def _file_num_sides(value) -> int:
    """numSides of a file: at most FILE_NUM_SIDES_MAX, as in design files."""
    return check_num_sides(value, maximum=FILE_NUM_SIDES_MAX)


def _top_level(data: Mapping, key: str, check, valid: str, file):
    """``data[key]`` checked by ``check`` (a kinegami.validation check), else a DesignError at
    ``key`` saying that it must be ``valid``."""
    value = data[key]
    try:
        return check(value)
    except (InvalidParameterError, InvalidTypeError):
        raise DesignError(f"must be {valid}", field=key, value=value, file=file) from None


def _growth_direction(data: Mapping, file) -> list | None:
    """``placement.growth_direction`` of a joint specification document (None if absent), as
    given (:class:`JointSpecification` makes it a unit vector); DesignError naming the field."""
    placement = data.get("placement")
    if placement is None:
        return None
    if not isinstance(placement, Mapping):
        raise DesignError("must be an object", field="placement", value=placement, file=file)
    direction = placement.get("growth_direction")
    if direction is None:
        return None
    field = "placement.growth_direction"
    numbers = (
        isinstance(direction, Sequence)
        and not isinstance(direction, str)
        and len(direction) == 3
        and all(isinstance(c, int | float) and not isinstance(c, bool) for c in direction)
    )
    if not numbers:
        raise DesignError(
            "must be a list [x, y, z] of three numbers (the growth direction)",
            field=field,
            value=direction,
            file=file,
        )
    try:
        _unit_direction(direction, field)
    except InvalidParameterError:
        if all(c == 0 for c in direction):
            reason = "must be a nonzero vector (the growth direction)"
        else:
            reason = "must be a vector of finite numbers (the growth direction)"
        raise DesignError(reason, field=field, value=direction, file=file) from None
    return list(direction)


# --- the growth direction ----------------------------------------------------------------------
def _unit_direction(value, name: str = "growth_direction") -> np.ndarray:
    try:
        v = np.array(value, dtype=float)
    except OverflowError:  # a Python int beyond the float range
        raise InvalidParameterError(
            f"{name} must be a finite 3-vector, got {shown(value)}"
        ) from None
    except (TypeError, ValueError):
        raise InvalidTypeError(f"{name} must be a 3-vector, got {shown(value)}") from None
    if v.shape != (3,) or not np.all(np.isfinite(v)):
        raise InvalidParameterError(f"{name} must be a finite 3-vector, got {shown(value)}")
    items = value.tolist() if isinstance(value, np.ndarray) else value
    if any(isinstance(c, bool | np.bool_ | str | bytes) for c in items):  # numbers only
        raise InvalidTypeError(f"{name} must be a 3-vector of numbers, got {shown(value)}")
    norm = math.sqrt(float(v @ v))
    if norm < 1e-12:
        raise InvalidParameterError(f"{name} must be a nonzero 3-vector, got {shown(value)}")
    return v / norm


def growth_quality(spec: JointSpecification, direction) -> float:
    """f(n) = min over the specified joints of |z . n|: how far from orthogonal to every axis
    the unit growth direction n is (joints slide about 1/f as far as they must rise)."""
    spec = _as_specification(spec)
    n = _unit_direction(direction)
    Z = np.array([joint.pose_matrix[:3, 2] for joint in spec.Joints])
    return float(np.min(np.abs(Z @ n)))


def _fibonacci_lattice(count: int) -> np.ndarray:
    """``count`` nearly uniform unit vectors (the Fibonacci lattice), shape (count, 3)."""
    i = np.arange(count, dtype=float)
    z = 1.0 - (2.0 * i + 1.0) / count
    rho = np.sqrt(np.maximum(0.0, 1.0 - z * z))
    phi = i * (math.pi * (3.0 - math.sqrt(5.0)))
    return np.column_stack([rho * np.cos(phi), rho * np.sin(phi), z])


def _min_norm_point(A: np.ndarray) -> np.ndarray:
    """The point of the convex hull of the rows of A nearest the origin (Wolfe's algorithm)."""
    norms = (A * A).sum(axis=1)
    S = [int(np.argmin(norms))]
    lam = np.array([1.0])
    x = A[S[0]].copy()
    scale = float(norms.max())
    for _ in range(100):
        j = int(np.argmin(A @ x))
        if float(A[j] @ x) >= float(x @ x) - 1e-14 * scale or j in S:
            return x
        S.append(j)
        lam = np.append(lam, 0.0)
        while True:
            P = A[S]
            k = len(S)
            M = np.zeros((k + 1, k + 1))
            M[:k, :k] = P @ P.T
            M[:k, k] = 1.0
            M[k, :k] = 1.0
            rhs = np.zeros(k + 1)
            rhs[k] = 1.0
            mu = np.linalg.lstsq(M, rhs, rcond=None)[0][:k]
            if np.all(mu > 1e-14):
                lam = mu
                x = mu @ P
                break
            negative = mu <= 1e-14
            theta = float(np.min(lam[negative] / (lam[negative] - mu[negative])))
            lam = lam + theta * (mu - lam)
            keep = lam > 1e-14
            S = [s for s, kept in zip(S, keep, strict=True) if kept]
            lam = lam[keep]
            x = lam @ A[S]
    return x  # pragma: no cover - Wolfe's algorithm ends after finitely many steps


def choose_growth_direction(spec) -> tuple[np.ndarray, float]:
    """The default growth direction of a specification and its quality f (docs/trees.md).

    The best point of a Fibonacci lattice of LATTICE_SIZE unit vectors, then the best
    direction with the same sign pattern of z . n (the exact maximiser of min |z . n| there: a
    convex problem, solved as the point of the hull of the signed axes nearest the origin);
    the cells of the 32 best lattice points are refined. Ties (within TIE_TOLERANCE) go to the
    larger n . (c - p_root), c the mean of the axis points, then to the lexicographically
    larger n. Deterministic.
    """
    spec = _as_specification(spec)
    Z = np.array([joint.pose_matrix[:3, 2] for joint in spec.Joints])
    points = np.array([joint.pose_matrix[:3, 3] for joint in spec.Joints])
    lattice = _fibonacci_lattice(LATTICE_SIZE)
    dots = lattice @ Z.T
    quality = np.abs(dots).min(axis=1)
    order = np.argsort(-quality, kind="stable")[:32]
    candidates = []
    seen = set()
    for k in order:
        if quality[k] <= 0.0:
            continue
        signs = np.where(dots[k] >= 0.0, 1.0, -1.0)
        key = tuple(signs.astype(int))
        if key in seen:
            continue
        seen.add(key)
        v = _min_norm_point(signs[:, None] * Z)
        f = float(np.linalg.norm(v))
        n = v / f if f > 0.0 else lattice[k]
        f = float(np.min(np.abs(Z @ n)))
        if f < quality[k]:  # round-off: keep the lattice point
            n, f = lattice[k], float(quality[k])
        candidates += [(f, n), (f, -n)]
    if not candidates:  # pragma: no cover - some lattice point is off every axis plane
        raise InvalidParameterError("no growth direction is off every joint's axis plane")
    best = max(f for f, _ in candidates)
    tied = [n for f, n in candidates if f >= best - TIE_TOLERANCE]
    towards = points.mean(axis=0) - points[0]

    def key(n):
        # rounded so that values equal up to round-off compare equal
        return (round(float(n @ towards) / TIE_TOLERANCE), *np.round(n / TIE_TOLERANCE))

    n = max(tied, key=key)
    return n, float(np.min(np.abs(Z @ n)))


# --- the bounding cylinder -----------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class BoundingCylinder:
    """A solid cylinder: its start disk's centre ``start``, unit ``axis``, ``length`` along the
    axis and ``radius`` (world coordinates, units of the tube radius)."""

    start: np.ndarray
    axis: np.ndarray
    length: float
    radius: float

    def __post_init__(self):
        object.__setattr__(self, "start", _frozen(self.start))
        object.__setattr__(self, "axis", _frozen(self.axis))
        object.__setattr__(self, "length", float(self.length))
        object.__setattr__(self, "radius", float(self.radius))

    @property
    def end(self) -> np.ndarray:
        """The centre of the end disk."""
        return self.start + self.length * self.axis

    def height(self, point) -> float:
        """Signed distance of ``point`` from the start plane along the axis."""
        return _snap(float((np.asarray(point, dtype=float) - self.start) @ self.axis))

    def contains(self, ball: Ball, tol: float = 1e-9) -> bool:
        """True if the ball lies inside the cylinder (within ``tol``)."""
        h = float((ball.c - self.start) @ self.axis)
        side = ball.c - self.start - h * self.axis
        return (
            h - ball.r >= -tol
            and h + ball.r <= self.length + tol
            and float(np.linalg.norm(side)) + ball.r <= self.radius + tol
        )

    def expanded(self, ball: Ball) -> BoundingCylinder:
        """The cylinder grown (axis kept) until it contains ``ball`` (docs/theory/trees.md)."""
        n = self.axis
        start, length = self.start, self.length
        top = _snap(float((ball.c + ball.r * n - start) @ n)) - length
        if top > 0.0:
            length += top
        bottom = _snap(float((ball.c - ball.r * n - start) @ n))
        if bottom < 0.0:
            start = start + bottom * n
            length -= bottom
        foot = ball.c - float((ball.c - start) @ n) * n
        disk = merge_balls(Ball(start, self.radius), Ball(foot, ball.r))
        return BoundingCylinder(disk.c, n, length, disk.r)

    def __repr__(self) -> str:
        s = ", ".join(f"{v:.6g}" for v in self.start)
        a = ", ".join(f"{v:.6g}" for v in self.axis)
        return (f"BoundingCylinder(start=({s}), axis=({a}), length={self.length:.6g}, "
                f"radius={self.radius:.6g})")  # fmt: skip


def _snap(d: float) -> float:
    return 0.0 if abs(d) < _PLANE_TOLERANCE else d


def link_end_balls(link) -> tuple[Ball, Ball]:
    """The two balls that cover a link's tube: for an arc with elbows the ball of radius 2r
    about its turning circle's centre, for an arc without the ball of radius r about the
    link's end on that side; the straight part lies in their convex hull."""
    r, path = link.r, link.path
    first = Ball(path.c1, 2.0 * r) if link.elbows1.count else Ball(path.p1, r)
    second = Ball(path.c2, 2.0 * r) if link.elbows2.count else Ball(path.p2, r)
    return first, second


def _cylinder_roll(n: np.ndarray) -> np.ndarray:
    """R_C = [u, n x u, n] with u the second axis of the Householder reflection taking n to
    the first world axis (what an SVD of n returns as its first null vector)."""
    v = n + (1.0 if n[0] >= 0.0 else -1.0) * np.array([1.0, 0.0, 0.0])
    u = np.array([0.0, 1.0, 0.0]) - (2.0 * v[1] / float(v @ v)) * v
    u = u - float(u @ n) * n
    u /= float(np.linalg.norm(u))
    return np.column_stack([u, np.cross(n, u), n])


# --- the construction --------------------------------------------------------------------------
@dataclass(frozen=True, eq=False)
class TreeConstruction:
    """How :func:`from_specification` built a tree (``tree.construction``; it describes the
    tree as built and is not updated by later edits).

    Attributes
    ----------
    growth_direction : the unit growth direction n (read-only 3-vector).
    quality : f = min |z . n| over the specified joints.
    chosen : True if the construction chose n (none was given).
    extra_roll, sibling_azimuth : the options used.
    node_of : the tree node of every specified joint, in specification order.
    waypoints : for every later sibling (a specified joint whose parent already had a child
        when it was placed), ``(joint index, W1 node, W2 node)``.
    slides : for every specified joint but the root, ``(lambda, lambda_min)``: how far it was
        slid along its axis and the least slide that puts it 4r past the cylinder.
    cylinder : the final bounding cylinder (it contains every joint ball and link end ball).
    recomputed_ball : the tree's bounding ball recomputed from every part in index order (the
        tree itself keeps the ball merged as its joints were added).
    """

    growth_direction: np.ndarray
    quality: float
    chosen: bool
    extra_roll: bool
    sibling_azimuth: float
    node_of: tuple
    waypoints: tuple
    slides: tuple
    cylinder: BoundingCylinder
    recomputed_ball: Ball


def _as_specification(spec) -> JointSpecification:
    if isinstance(spec, JointSpecificationTree):
        return spec.specification()
    if isinstance(spec, JointSpecification):
        return spec
    raise InvalidTypeError(
        f"spec must be a JointSpecification or a JointSpecificationTree, got {type(spec).__name__}"
    )


def _oriented(joint: Joint, n: np.ndarray) -> Joint:
    """The joint with z turned towards n (a half turn about x if needed) and x as close to n
    as z allows: x = unit(n - (n . z) z), kept when n is along z."""
    T = np.array(joint.pose_matrix)
    if float(T[:3, 2] @ n) < 0.0:
        T[:3, 1] = -T[:3, 1]
        T[:3, 2] = -T[:3, 2]
    z = T[:3, 2]
    x = n - float(n @ z) * z
    norm = float(np.linalg.norm(x))
    if norm > 1e-12:
        T[:3, 0] = x / norm
        T[:3, 1] = np.cross(z, T[:3, 0])
    return joint.with_pose(T)


def _extra_roll(joint: Joint, n: np.ndarray) -> Joint:
    """The published extra roll: the joint turned about its own z by the angle that would
    bring its x closest to n by a turn about the *world* z axis (docs/trees.md)."""
    T = joint.pose_matrix
    x = T[:3, 0]
    alpha = math.atan2(n[1] * x[0] - n[0] * x[1], n[0] * x[0] + n[1] * x[1])
    R = np.eye(4)
    R[:3, :3] = rotation_matrix((0.0, 0.0, 1.0), alpha)
    return joint.with_pose(T @ R)


def from_specification(
    spec,
    *,
    growth_direction=None,
    extra_roll: bool = False,
    sibling_azimuth: float = SIBLING_AZIMUTH,
) -> KinematicTree:
    """Build a KinematicTree from a joint specification by the tree construction
    (docs/trees.md, "The tree construction"; why every link exists: docs/theory/trees.md).

    Every joint stays on its specified axis line; the construction chooses its slide along the
    line, its roll and the sign of its axis, and adds two waypoints before every later sibling.
    The tree has maxAnglePerElbow = pi/10; ``tree.construction`` (a :class:`TreeConstruction`)
    says how it was built.

    Parameters
    ----------
    spec : a :class:`JointSpecification` or :class:`JointSpecificationTree`.
    growth_direction : the growth direction n (any nonzero 3-vector, normalised; every joint's
        axis must satisfy |z . n| >= 1e-6). Default: the specification's own, else the
        direction chosen by :func:`choose_growth_direction`.
    extra_roll : apply the published extra roll after each placement (default False: omitted,
        which keeps every revolute joint's path direction as close to n as its axis allows and
        gives shorter trees).
    sibling_azimuth : the azimuth step (radians) about n between the routes of successive later
        siblings of one parent (default SIBLING_AZIMUTH = 0.5): the k-th later sibling's route
        leaves at (k - 1) times this angle from the published one. 0.0 gives the published
        construction, whose routes from one parent run side by side.

    Raises
    ------
    InvalidParameterError : a growth direction (nearly) orthogonal to a joint's axis, or a bad
        option value.
    NoPathError : a link could not be built (the construction's guarantee makes this an
        internal error).

    Examples
    --------
    >>> spec = JointSpecificationTree(Waypoint(4, 1, SE3()))
    >>> spec.addJoint(0, RevoluteJoint(4, 1, np.pi, SE3.Trans(0, 0, 4) * SE3.Ry(np.pi / 2)))
    1
    >>> tree = from_specification(spec)
    >>> tree.construction.quality > 0.7
    True
    """
    spec = _as_specification(spec)
    extra_roll = check_bool("extra_roll", extra_roll)
    azimuth = check_real("sibling_azimuth", sibling_azimuth)
    Z = np.array([joint.pose_matrix[:3, 2] for joint in spec.Joints])
    chosen = False
    if growth_direction is not None:
        n = _unit_direction(growth_direction)
    elif spec.growth_direction is not None:
        n = np.array(spec.growth_direction)
    else:
        n, _ = choose_growth_direction(spec)
        chosen = True
    dots = np.abs(Z @ n)
    worst = int(np.argmin(dots))
    if dots[worst] < MIN_GROWTH_DOT:
        raise InvalidParameterError(
            f"growth_direction {np.round(n, 9).tolist()} is orthogonal to the axis of joint "
            f"{worst} ({spec.names[worst]!r}): |z . n| = {dots[worst]:.3g}; it must be at "
            f"least {MIN_GROWTH_DOT:g} for every joint"
        )
    quality = float(dots.min())

    root = _oriented(spec.Joints[0], n)
    tree = KinematicTree(root, maxAnglePerElbow=MAX_ANGLE_PER_ELBOW)
    # Each addJoint would measure the whole tree's clearance again (to warn), which is nearly
    # all the time of a construction; the construction never consults it, so the tree's
    # overlap hook is switched off while it is built (tree.clearance() measures the result).
    tree._overlap = _no_overlap
    try:
        node_of, waypoints, slides, cylinder = _build(tree, spec, n, extra_roll, azimuth)
    finally:
        del tree._overlap
    tree.construction = TreeConstruction(
        _frozen(n), quality, chosen, extra_roll, azimuth, node_of, waypoints, slides, cylinder,
        _recomputed_ball(tree),
    )  # fmt: skip
    return tree


def _no_overlap(*args, **kwargs) -> None:
    return None


def _build(tree: KinematicTree, spec: JointSpecification, n: np.ndarray, extra_roll: bool,
           azimuth: float):  # fmt: skip
    """The main loop (docs/theory/trees.md): add every specified joint in depth-first order,
    later siblings after their two waypoints; returns the parts of the report."""
    r = spec.r
    ball = tree.Joints[0].boundingBall()
    cyl = BoundingCylinder(ball.c - ball.r * n, n, 2.0 * ball.r, ball.r)
    R_C = _cylinder_roll(n)
    node_of = [0] * len(spec)
    waypoints, slides = [], [None] * len(spec)
    children_in_tree: dict[int, int] = {}

    def add(parent: int, joint: Joint, what: str) -> int:
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            index = tree.addJoint(parent, joint, relative=False, safe=False,
                                  fixedPosition=True, fixedOrientation=True)  # fmt: skip
        for w in caught:
            if not issubclass(w.category, PlacementWarning | ClearanceWarning):
                warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
        if index is None:
            reasons = "; ".join(str(w.message) for w in caught
                                if issubclass(w.category, PlacementWarning))  # fmt: skip
            raise NoPathError(f"the tree construction could not add {what}: {reasons}")
        return index

    def expand_by_link(cylinder: BoundingCylinder, index: int) -> BoundingCylinder:
        for end_ball in link_end_balls(tree.Links[index]):
            cylinder = cylinder.expanded(end_ball)
        return cylinder

    for j in spec.depth_first()[1:]:
        P = node_of[spec.Parents[j]]
        later = children_in_tree.get(P, 0)
        children_in_tree[P] = later + 1
        if later:
            # a later sibling: out through the cylinder's side, 4r above the parent's ball,
            # then straight up to the cylinder's end plane
            top_ball = tree.Joints[P].boundingBall()
            e = top_ball.c + top_ball.r * n
            d = e - cyl.height(e) * n - cyl.start
            norm = float(np.linalg.norm(d))
            d_hat = d / norm if norm >= 1e-6 * r else R_C[:, 0]
            if azimuth != 0.0 and later > 1:
                d_hat = rotation_matrix(n, (later - 1) * azimuth) @ d_hat
            o1 = cyl.start + (cyl.radius + r) * d_hat + (4.0 * r + cyl.height(e)) * n
            W1 = add(P, Waypoint(spec.numSides, r, _pose(R_C, o1), 2),
                     f"the first waypoint before joint {j} ({spec.names[j]!r})")  # fmt: skip
            cyl = expand_by_link(cyl, W1)
            o2 = o1 - (cyl.height(o1) - cyl.length) * n
            W2 = add(W1, Waypoint(spec.numSides, r, _pose(R_C, o2), 2),
                     f"the second waypoint before joint {j} ({spec.names[j]!r})")  # fmt: skip
            cyl = cyl.expanded(Ball(o2, r))
            waypoints.append((j, W1, W2))
            P = W2
        # orient, then slide along the axis to the point nearest P that is 4r past the end plane
        joint = _oriented(spec.Joints[j], n)
        T = joint.pose_matrix
        p, z = T[:3, 3], T[:3, 2]
        lam_star = float((tree.Joints[P].pose_matrix[:3, 3] - p) @ z)
        lam_min = (4.0 * r + joint.bounding_radius() - float((p - cyl.end) @ n)) / float(z @ n)
        lam = max(lam_star, lam_min)
        joint = joint.translated_along_z(lam)
        if extra_roll:
            joint = _extra_roll(joint, n)
        slides[j] = (lam, lam_min)
        node_of[j] = index = add(P, joint, f"joint {j} ({spec.names[j]!r})")
        cyl = cyl.expanded(tree.Joints[index].boundingBall())
        cyl = expand_by_link(cyl, index)
    return tuple(node_of), tuple(waypoints), tuple(slides), cyl


def _pose(R: np.ndarray, origin: np.ndarray) -> np.ndarray:
    T = np.eye(4)
    T[:3, :3] = R
    T[:3, 3] = origin
    return T


def _recomputed_ball(tree: KinematicTree) -> Ball:
    """The tree's ball recomputed in index order: joints, then both arc balls of each link
    (docs/theory/chain.md §2), without changing the tree."""
    joints, links = tree.Joints, tree.Links
    ball = joints[0].boundingBall()
    for joint in joints[1:]:
        ball = merge_balls(ball, joint.boundingBall())
    for link in links:
        ball = merge_balls(ball, link.arc1Ball)
        ball = merge_balls(ball, link.arc2Ball)
    return ball
