"""The editor's commands: every user action on a design, as a value that applies to a document.

A command's :meth:`Command.apply` takes a :class:`~kinegami.editor.document.Document` and
returns an :class:`Outcome` with a new document, or raises :class:`CommandError` whose message
names the parameter, the value and what is allowed. It never changes the document it was
given, so a failed command leaves nothing half done. :class:`~kinegami.editor.model.EditorModel`
runs commands, keeps the undo history and tells views what changed. See docs/editor.md.
"""

from __future__ import annotations

import abc
import math
import warnings
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field, replace
from typing import Any, ClassVar

import numpy as np

from kinegami.chain.joints import (
    JOINT_KINDS,
    EndTip,
    Joint,
    StartTip,
    Waypoint,
)
from kinegami.chain.model import KinematicChain
from kinegami.design import limits
from kinegami.design.reader import UNITS
from kinegami.editor.document import Document, fork_chain, joint_parameters
from kinegami.editor.units import angle_text
from kinegami.errors import (
    Cancelled,
    ClearanceWarning,
    EditorCommandError,
    KinegamiError,
    PlacementWarning,
)
from kinegami.geometry.screws import PRISMATIC
from kinegami.tree import KinematicTree
from kinegami.validation import shown

__all__ = [
    "CommandError",
    "Outcome",
    "Command",
    "AddJoint",
    "AddBranch",
    "DeleteJoint",
    "SlideJoint",
    "RollJoint",
    "TransformJoint",
    "TransformAll",
    "SetJointPose",
    "SetJointParameters",
    "RenameJoint",
    "SetJointState",
    "SetJointStates",
    "Compact",
    "DesignForTask",
    "SetOptions",
    "FitJunctions",
    "ReplaceDocument",
    "LongCommand",
    "Computed",
    "JOINT_TYPES",
    "PLACEMENTS",
    "KEEP",
]


CommandError = EditorCommandError  # the editor's name for it


class _Keep:
    """Marker of an option a command leaves as it is."""

    def __repr__(self) -> str:
        return "KEEP"


#: Default of :class:`SetOptions` fields: leave the option as it is.
KEEP: Any = _Keep()

#: The joint types the editor can add, by name: the registered joint kinds
#: (kinegami.chain.joints.JOINT_KINDS).
JOINT_TYPES = JOINT_KINDS

#: How a new joint is placed: ``"safe"`` (safe placement, waypoints; never fails), ``"compact"``
#: (slides along its axis to just beyond the chain) or ``"pose"`` (exactly at the given pose).
PLACEMENTS = ("safe", "compact", "pose")


@dataclass(frozen=True)
class Outcome:
    """What a command made: the new document, the joint to select (None: keep the selection
    where it is) and the warnings it raised (e.g. the chain now passes through itself)."""

    document: Document
    selected: int | None = None
    warnings: tuple[str, ...] = ()
    sources: tuple | None = None  # per new joint, the old index it is (None: new or unknown)


# --- checks ------------------------------------------------------------------------------------
def _fail(message: str) -> None:
    raise CommandError(message)


def _number(name: str, value) -> float:
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        _fail(f"{name} must be a number, got {shown(value)}")
    value = float(value)
    if not math.isfinite(value):
        _fail(f"{name} must be a finite number, got {value!r}")
    return value


def _integer(name: str, value, lo: int, hi: int) -> int:
    if isinstance(value, bool) or not isinstance(value, int | np.integer):
        _fail(f"{name} must be an integer in [{lo}, {hi}], got {shown(value)}")
    if not lo <= int(value) <= hi:
        _fail(f"{name} must be an integer in [{lo}, {hi}], got {int(value)}")
    return int(value)


def _flag(name: str, value) -> bool:
    if not isinstance(value, bool | np.bool_):
        _fail(f"{name} must be True or False, got {shown(value)}")
    return bool(value)


def _length(name: str, value, r: float) -> float:
    value = _number(name, value)
    limit = limits.LENGTH_FACTOR * r
    if not 0.0 < value <= limit:
        _fail(f"{name} must be > 0 and <= 1e6 r = {limit:g}, got {value!r}")
    return value


def _distance(name: str, value, r: float) -> float:
    value = _number(name, value)
    limit = limits.LENGTH_FACTOR * r
    if not abs(value) <= limit:
        _fail(f"{name} must be within +-1e6 r = +-{limit:g}, got {value!r}")
    return value


def _pose(name: str, value, r: float) -> np.ndarray:
    """A rigid 4x4 transform (array, nested lists or SE3), translation within 1e6 r."""
    if value is None:
        return np.eye(4)
    if hasattr(value, "A") and not isinstance(value, np.ndarray):
        value = value.A
    try:
        T = np.array(value, dtype=float)
    except (TypeError, ValueError):
        _fail(f"{name} must be a 4x4 rigid transform, got {shown(value)}")
    if T.shape != (4, 4):
        _fail(f"{name} must be a 4x4 rigid transform, got an array of shape {T.shape}")
    if not np.isfinite(T).all():
        _fail(f"{name} must contain finite numbers only, got {shown(value)}")
    R = T[:3, :3]
    error = float(np.abs(R.T @ R - np.eye(3)).max())
    if error > 1e-9 or np.linalg.det(R) <= 0 or not np.array_equal(T[3], [0.0, 0.0, 0.0, 1.0]):
        _fail(
            f"{name} must be a rigid transform: orthonormal rotation to 1e-9 (max |R^T R - I| "
            f"is {error:.3g}), determinant +1 and last row [0, 0, 0, 1]"
        )
    _distance(f"{name} translation", float(np.abs(T[:3, 3]).max()), r)
    return T


def _names_text(names: Sequence) -> str:
    known = [n for n in names if n is not None]
    if not known:
        return "the joints have no names"
    shown_names = ", ".join(repr(n) for n in known[:10])
    return f"names: {shown_names}" + (", ..." if len(known) > 10 else "")


def resolve_joint(document: Document, joint, name: str = "joint") -> int:
    """The index of ``joint`` (an index, negative from the end, or a joint name)."""
    n = len(document.chain.Joints)
    if isinstance(joint, str):
        if joint in document.names:
            return document.names.index(joint)
        _fail(f"{name}: no joint is named {joint!r} ({_names_text(document.names)})")
    if isinstance(joint, bool) or not isinstance(joint, int | np.integer):
        _fail(
            f"{name} must be a joint index in [{-n}, {n - 1}] or a joint name, got {shown(joint)}"
        )
    if not -n <= int(joint) < n:
        _fail(f"{name} must be a joint index in [{-n}, {n - 1}] or a joint name, got {int(joint)}")
    return int(joint) % n


def _label(document: Document, j: int) -> str:
    joint = document.chain.Joints[j]
    text = f"joint {j} ({type(joint).__name__}"
    if document.names[j] is not None:
        text += f" {document.names[j]!r}"
    return text + ")"


# --- running chain operations -----------------------------------------------------------------
def _reason(message: str) -> str:
    for tail in ("; the chain is unchanged",):
        if message.endswith(tail):
            message = message[: -len(tail)]
    return message


class _Run:
    """Runs chain operations: numeric errors raised, PlacementWarnings turned into
    CommandErrors, ClearanceWarnings collected (the last one is reported)."""

    def __init__(self):
        self.warnings: list[str] = []

    def __call__(self, what: str, call):
        with (
            warnings.catch_warnings(record=True) as caught,
            np.errstate(over="raise", invalid="raise", divide="raise"),
        ):
            warnings.simplefilter("always")
            try:
                result = call()
            except (CommandError, Cancelled):
                raise
            except (KinegamiError, ValueError, TypeError, IndexError, ArithmeticError) as error:
                _fail(f"{what}: {_reason(str(error))}")
        placement = [str(w.message) for w in caught if issubclass(w.category, PlacementWarning)]
        clearance = [str(w.message) for w in caught if issubclass(w.category, ClearanceWarning)]
        if result is False or result is None:
            _fail(f"{what}: {_reason(placement[-1])}" if placement else f"{what} failed")
        if clearance:
            self.warnings[:] = [clearance[-1]]
        return result

    def clear_warning(self, chain) -> tuple[str, ...]:
        """The collected warnings that still hold for ``chain`` (it passes through itself)."""
        if not self.warnings:
            return ()
        return tuple(self.warnings) if not chain.clearance().ok else ()


_FIXED = {"relative": False, "safe": False, "fixedPosition": True, "fixedOrientation": True}


def _is_tree(chain) -> bool:
    return isinstance(chain, KinematicTree)


def _attach(new, parent: int, joint: Joint, **options):
    """Add ``joint`` to ``new`` as a child of joint ``parent``: a chain appends it (``parent``
    is then its last joint), a tree adds it with ``addJoint``. Returns the new joint's index
    (or None/False with a PlacementWarning, as the chain does)."""
    if _is_tree(new):
        return new.addJoint(parent, joint, **options)
    return new.append(joint, **options)


def _rebuilt(run: _Run, chain, joints: Sequence[Joint], keep: int = 0,
             maxAnglePerElbow: float | None = None,
             parents: Sequence[int] | None = None):  # fmt: skip
    """A chain (or tree) of ``joints`` at their exact poses and states: the first ``keep``
    joints are those of ``chain`` (its first ``keep`` links kept as they are when ``keep`` > 0
    and ``keep`` joints are left in the fork), the others added at fixed poses, joint k as a
    child of ``parents[k]`` (default: the chain's or tree's parents)."""
    parents = chain.Parents if parents is None else parents
    if keep >= len(chain.Joints) and maxAnglePerElbow is None:
        new = fork_chain(chain)
        start = len(chain.Joints)
    elif keep > 0 and maxAnglePerElbow is None:
        new = fork_chain(chain)
        for _ in range(len(chain.Joints) - keep):  # a tree's last joint is always a leaf
            run("re-linking the chain", lambda: new.delete(-1))
        start = keep
    else:
        root = joints[0]
        if root.closes_end:
            _fail("a chain whose first joint is an EndTip cannot be rebuilt; add a joint first")
        angle = chain.maxAnglePerElbow if maxAnglePerElbow is None else maxAnglePerElbow
        kind = KinematicTree if _is_tree(chain) else KinematicChain
        new = run(
            "rebuilding the chain",
            lambda: kind(root, angle, requireClearance=chain.requireClearance,
                         margin=chain.margin),
        )
        start = 1
    for k in range(start, len(joints)):
        joint = joints[k]
        run(
            f"re-linking joint {k} ({type(joint).__name__})",
            lambda j=joint, p=parents[k]: _attach(new, p, j, **_FIXED),
        )
    return new


def _new_joint(kind: str, parameters: Mapping, pose: np.ndarray, numSides: int, r: float,
               base: Mapping | None = None) -> Joint:  # fmt: skip
    """A joint of type ``kind`` with ``parameters`` (others from ``base`` or the defaults),
    checked against the bounds of design files."""
    if kind not in JOINT_TYPES:
        _fail(f"joint type must be one of {', '.join(JOINT_TYPES)}, got {shown(kind)}")
    if not isinstance(parameters, Mapping):
        _fail(f"parameters must be a mapping of parameter names to values, got {shown(parameters)}")
    cls = JOINT_TYPES[kind]
    defaults = cls.design_defaults(r)
    unknown = [key for key in parameters if key not in defaults]
    if unknown:
        _fail(
            f"unknown parameter {unknown[0]!r} of a {kind}; its parameters are "
            f"{', '.join(defaults) or 'none'}"
        )
    p = {**defaults, **(base or {}), **parameters}
    return cls.from_design(numSides, r, pose, {key: _checked_field(key, p[key], r) for key in p})


def _checked_field(name: str, value, r: float):
    """A joint parameter checked against the bounds of design files, with the editor's words;
    a field these checks do not know is left to the joint kind's own constructor."""
    if name == "totalBendingAngle":
        angle = _number(name, value)
        if not 0.0 < angle < 2.0 * math.pi:
            _fail(f"totalBendingAngle must be in (0, 2pi) radians (0° to 360°), got {angle!r} "
                  f"({angle_text(angle)})")  # fmt: skip
        return angle
    if name == "coneAngle":
        cone = _number(name, value)
        if not math.pi / 6 <= cone < math.pi / 2:
            _fail(f"coneAngle must be in [pi/6, pi/2) radians ([30°, 90°)), got {cone!r} "
                  f"({angle_text(cone)})")  # fmt: skip
        return cone
    if name == "numSinkLayers":
        return _integer(name, value, 1, limits.NUM_SINK_LAYERS_MAX)
    if name == "numLayers":
        return _integer(name, value, 1, limits.NUM_LAYERS_MAX)
    if name in ("tubeLength", "neutralLength", "length"):
        return _length(name, value, r)
    if name == "pathIndex":
        return _integer(name, value, 0, 2)
    return value


def _check_name(document: Document, name, j: int | None = None):
    if name is None:
        return None
    if not isinstance(name, str):
        _fail(f"name must be a string or None, got {shown(name)}")
    if not name.strip():
        _fail(f"name must not be empty or blank, got {name!r}")
    for i, other in enumerate(document.names):
        if other == name and i != j:
            _fail(f"name {name!r} is already the name of {_label(document, i)}; names are unique")
    return name


# --- commands ------------------------------------------------------------------------------------
class Command(abc.ABC):
    """Base class of the editor's commands (frozen dataclasses; see docs/editor.md)."""

    #: Short text for menus and the undo history.
    label: ClassVar[str] = "command"

    @abc.abstractmethod
    def apply(self, document: Document) -> Outcome:
        """The document this command makes of ``document`` (raises CommandError)."""

    def describe(self) -> str:
        """One line for the undo history, e.g. ``slide joint 3 by 0.5``."""
        return self.label


#: How each placement is asked of the chain's append or the tree's addJoint.
_PLACEMENT_OPTIONS = {
    "safe": {"safe": True},
    "compact": {"safe": False},
    "pose": {"safe": False, "fixedPosition": True, "fixedOrientation": True},
}


def _children(chain, j: int) -> list[int]:
    return [k for k, p in enumerate(chain.Parents) if p == j]


def _joint_list(indices) -> str:
    return ", ".join(str(k) for k in indices)


@dataclass(frozen=True)
class _NewJoint:
    """The checked fields of a command that adds a joint (AddJoint, AddBranch)."""

    joint: Joint
    parent: int
    relative: bool
    options: dict
    name: str | None


def _new_joint_of(command, document: Document, ref, what: str) -> _NewJoint:
    chain = document.chain
    if command.placement not in PLACEMENTS:
        _fail(f"placement must be one of {', '.join(PLACEMENTS)}, got {shown(command.placement)}")
    relative = _flag("relative", command.relative)
    parent = len(chain.Joints) - 1 if ref is None else resolve_joint(document, ref, what)
    pose = _pose("pose", command.pose, chain.r)
    joint = _new_joint(command.kind, command.parameters, pose, chain.numSides, chain.r)
    name = _check_name(document, command.name)
    if joint.closes_start:
        noun = "tree" if _is_tree(chain) else "chain"
        _fail(f"a StartTip can only be the first joint of a {noun}, which already has one")
    if chain.Joints[parent].closes_end:
        ends = "ends the chain" if not _is_tree(chain) else "is a leaf of the tree"
        _fail(f"nothing can follow {_label(document, parent)}: an EndTip {ends}")
    return _NewJoint(joint, parent, relative, _PLACEMENT_OPTIONS[command.placement], name)


@dataclass(frozen=True)
class AddJoint(Command):
    """Add a joint after joint ``after`` (default: the last one), placed as ``append`` does.

    On a tree the new joint becomes the child of joint ``after`` and takes over ``after``'s
    children (inserted between them); :class:`AddBranch` adds a joint beside them instead.

    Parameters
    ----------
    kind : the joint type, one of :data:`JOINT_TYPES` (not a StartTip: only the root is one, and
        an EndTip only at the end, or on a tree after a leaf).
    parameters : its parameters (defaults: totalBendingAngle pi, numSinkLayers 1, tubeLength 2r,
        neutralLength 3r, numLayers 3, coneAngle pi/4, pathIndex 2, length 1.5r).
    pose : its Pose, a 4x4 rigid transform (default the identity); relative to joint
        ``after``'s Pose when ``relative``.
    after : the joint it follows (index or name); the joints after it keep their poses and
        are linked to it again.
    placement : ``"safe"``, ``"compact"`` or ``"pose"`` (see :data:`PLACEMENTS`).
    relative : the pose is relative to joint ``after`` (True) or global (False).
    name : its name (unique) or None.
    """

    kind: str
    parameters: Mapping = field(default_factory=dict)
    pose: Any = None
    after: int | str | None = None
    placement: str = "safe"
    relative: bool = True
    name: str | None = None

    label: ClassVar[str] = "add joint"

    def describe(self) -> str:
        return f"add {self.kind}"

    def apply(self, document: Document) -> Outcome:
        chain = document.chain
        run = _Run()
        spec = _new_joint_of(self, document, self.after, "after")
        joint, after = spec.joint, spec.parent
        parents = chain.Parents
        if joint.closes_end and _children(chain, after):
            if _is_tree(chain):
                _fail(
                    f"an EndTip can only be a leaf; after={after} has children (joints "
                    f"{_joint_list(_children(chain, after))}), which the new joint would take "
                    "over: add the EndTip as a branch, or after a leaf"
                )
            _fail(
                f"an EndTip can only be the last joint; after={after} is followed by "
                f"{len(chain.Joints) - after - 1} joint(s)"
            )
        new = _rebuilt(run, chain, chain.Joints[: after + 1], keep=after + 1)
        index = run(
            f"adding the {self.kind}",
            lambda: _attach(new, after, joint, relative=spec.relative, **spec.options),
        )
        added = index - after
        names = [*document.names[: after + 1], *(None,) * (added - 1), spec.name]
        sources: list = [*range(after + 1), *(None,) * added]
        where = list(range(after + 1))  # each old joint's index in the new chain or tree
        notes = []
        for k in range(after + 1, len(chain.Joints)):
            later = chain.Joints[k]
            p = index if parents[k] == after else where[parents[k]]
            what = f"re-linking joint {k} ({type(later).__name__}) after the new joint"
            try:
                run(what, lambda j=later, p=p: _attach(new, p, j, **_FIXED))
                source = k
            except CommandError as fixed:
                try:  # no link reaches it where it is: place it again on its axis
                    run(what, lambda j=later, p=p: _attach(new, p, j, relative=False, safe=True))
                except CommandError:
                    raise fixed from None
                source = None
                notes.append(
                    f"joint {len(new.Joints) - 1} ({type(later).__name__}, joint {k} before) "
                    "could not be linked where it was and was placed again by safe placement "
                    "(its axis of motion kept)"
                )
            count = len(new.Joints) - len(names)
            names += [None] * (count - 1) + [document.names[k]]
            sources += [None] * (count - 1) + [source]
            where.append(len(new.Joints) - 1)
        return Outcome(document.replaced(chain=new, names=tuple(names)), index,
                       (*notes, *run.clear_warning(new)), tuple(sources))  # fmt: skip


@dataclass(frozen=True)
class AddBranch(Command):
    """Add a joint as a new child of joint ``parent`` (default: the last one), beside the
    children it has: a branch. Placed as ``KinematicTree.addJoint`` places it (docs/trees.md).

    On a chain, a child of the last joint is simply appended (the chain stays a chain); a child
    of any other joint makes a branch, and the document's chain becomes a
    :class:`~kinegami.tree.KinematicTree` (the same joints and links, bit for bit, joint i the
    child of joint i - 1). Nothing else moves: the new joint and the waypoints safe placement
    adds before it take the next indices.

    Parameters
    ----------
    kind, parameters, pose, placement, relative, name : as for :class:`AddJoint` (the pose is
        relative to joint ``parent``'s Pose when ``relative``).
    parent : the joint it is added to (index or name).
    """

    kind: str
    parameters: Mapping = field(default_factory=dict)
    pose: Any = None
    parent: int | str | None = None
    placement: str = "safe"
    relative: bool = True
    name: str | None = None

    label: ClassVar[str] = "add branch"

    def describe(self) -> str:
        return f"add {self.kind} as a branch of joint {self.parent!r}"

    def apply(self, document: Document) -> Outcome:
        chain = document.chain
        spec = _new_joint_of(self, document, self.parent, "parent")
        parent = spec.parent
        n = len(chain.Joints)
        if not _is_tree(chain) and parent == n - 1:  # no branch: the chain grows
            return AddJoint(self.kind, self.parameters, self.pose, parent, self.placement,
                            self.relative, self.name).apply(document)  # fmt: skip
        run = _Run()
        if _is_tree(chain):
            new = fork_chain(chain)
        else:
            new = run("making the chain a tree", lambda: KinematicTree.from_chain(chain))
        index = run(
            f"adding the {self.kind} to {_label(document, parent)}",
            lambda: new.addJoint(parent, spec.joint, relative=spec.relative, **spec.options),
        )
        added = index - (n - 1)
        names = (*document.names, *(None,) * (added - 1), spec.name)
        sources = (*range(n), *(None,) * added)
        return Outcome(document.replaced(chain=new, names=names), index, run.clear_warning(new),
                       sources)  # fmt: skip


@dataclass(frozen=True)
class DeleteJoint(Command):
    """Remove a joint with at most one child; its parent and its child (if any) are joined by
    a new link (the root can go when it has exactly one child, which becomes the root)."""

    joint: int | str

    label: ClassVar[str] = "delete joint"

    def describe(self) -> str:
        return f"delete joint {self.joint!r}"

    def apply(self, document: Document) -> Outcome:
        chain = document.chain
        j = resolve_joint(document, self.joint)
        if len(chain.Joints) == 1:
            noun = "tree" if _is_tree(chain) else "chain"
            _fail(f"the {noun}'s only joint cannot be deleted: a {noun} keeps at least one joint")
        kids = _children(chain, j)
        if len(kids) > 1:
            _fail(
                f"{_label(document, j)} has {len(kids)} children (joints {_joint_list(kids)}): "
                "only a joint with at most one child can be deleted; delete all its branches "
                "but one first"
            )
        run = _Run()
        new = fork_chain(chain)
        run(f"deleting {_label(document, j)}", lambda: new.delete(j))
        names = document.names[:j] + document.names[j + 1 :]
        n = len(chain.Joints)
        sources = tuple(k for k in range(n) if k != j)
        return Outcome(document.replaced(chain=new, names=names), max(chain.Parents[j], 0),
                       run.clear_warning(new), sources)  # fmt: skip


@dataclass(frozen=True)
class _AxisMove(Command, abc.ABC):
    joint: int | str
    amount: float
    propagate: bool = True
    applyToPreviousWaypoint: bool = False

    _method: ClassVar[str] = ""
    _amount: ClassVar[str] = ""

    def describe(self) -> str:
        return f"{self.label} {self.joint!r} by {self.amount!r}"

    @abc.abstractmethod
    def _check_amount(self, r: float) -> float:
        """The move's amount, checked (raises CommandError)."""

    def apply(self, document: Document) -> Outcome:
        j = resolve_joint(document, self.joint)
        amount = self._check_amount(document.chain.r)
        propagate = _flag("propagate", self.propagate)
        previous = _flag("applyToPreviousWaypoint", self.applyToPreviousWaypoint)
        run = _Run()
        new = fork_chain(document.chain)
        method = getattr(new, self._method)
        run(
            f"{self.label.split()[0]} {_label(document, j)}",  # "slide joint 3 (...)"
            lambda: method(j, amount, applyToPreviousWaypoint=previous, propagate=propagate),
        )
        sources = tuple(range(len(new.Joints)))
        return Outcome(document.replaced(chain=new), j, run.clear_warning(new), sources)


@dataclass(frozen=True)
class SlideJoint(_AxisMove):
    """Slide a joint by ``amount`` (a length) along its axis of motion; the kinematics are kept.

    ``propagate`` moves the later joints with it; ``applyToPreviousWaypoint`` moves a
    waypoint just before it too.
    """

    label: ClassVar[str] = "slide joint"
    _method: ClassVar[str] = "translateJointAlongAxisOfMotion"

    def _check_amount(self, r: float) -> float:
        return _distance("distance", self.amount, r)


@dataclass(frozen=True)
class RollJoint(_AxisMove):
    """Turn a joint by ``amount`` (radians) about its axis of motion; the kinematics are kept."""

    label: ClassVar[str] = "roll joint"
    _method: ClassVar[str] = "rotateJointAboutAxisOfMotion"

    def _check_amount(self, r: float) -> float:
        return _number("angle", self.amount)


#: The joints whose pose is not part of the kinematics (no range of motion).
_FREE_TYPES = (Waypoint, StartTip, EndTip)


@dataclass(frozen=True)
class TransformJoint(Command):
    """Move a waypoint or a tip by the world transform ``transform`` (4x4 rigid).

    Moving a revolute or prismatic joint this way changes its axis of motion, i.e. the robot's
    kinematics: that needs ``kinematic=True`` (use :class:`SlideJoint` and :class:`RollJoint`
    to keep them).
    """

    joint: int | str
    transform: Any
    propagate: bool = True
    kinematic: bool = False

    label: ClassVar[str] = "transform joint"

    def describe(self) -> str:
        return f"transform joint {self.joint!r}"

    def apply(self, document: Document) -> Outcome:
        chain = document.chain
        j = resolve_joint(document, self.joint)
        T = _pose("transform", self.transform, chain.r)
        propagate = _flag("propagate", self.propagate)
        if not _flag("kinematic", self.kinematic) and not isinstance(chain.Joints[j], _FREE_TYPES):
            _fail(
                f"transform of {_label(document, j)} would change its axis of motion: "
                "transform moves waypoints and tips; slide or roll a joint to keep the "
                "kinematics, or pass kinematic=True"
            )
        run = _Run()
        new = fork_chain(chain)
        run(
            f"transform {_label(document, j)}",
            lambda: new.transformJoint(j, T, propagate=propagate),
        )
        sources = tuple(range(len(new.Joints)))
        return Outcome(document.replaced(chain=new), j, run.clear_warning(new), sources)


@dataclass(frozen=True)
class SetJointPose(Command):
    """Put a joint at the world pose ``pose`` (4x4 rigid; what a typed position and
    orientation give).

    The joint is moved by the transform that takes its Pose to ``pose`` (``transformJoint``):
    with ``propagate`` its subtree moves along, else only its links are solved again. For a
    revolute or prismatic joint the pose is its axis of motion, so typing one changes the
    robot's kinematics on purpose (a drag or :class:`SlideJoint` keeps them).
    """

    joint: int | str
    pose: Any
    propagate: bool = True

    label: ClassVar[str] = "set pose"

    def describe(self) -> str:
        return f"set pose of joint {self.joint!r}"

    def apply(self, document: Document) -> Outcome:
        chain = document.chain
        j = resolve_joint(document, self.joint)
        P = _pose("pose", self.pose, chain.r)
        propagate = _flag("propagate", self.propagate)
        old = np.asarray(chain.Joints[j].pose_matrix, dtype=float)
        if np.array_equal(P[:3, :3], old[:3, :3]):  # a move only: the rotation stays exact
            T = np.eye(4)
            T[:3, 3] = P[:3, 3] - old[:3, 3]
        else:
            T = P @ np.linalg.inv(old)
            T[3] = (0.0, 0.0, 0.0, 1.0)
        run = _Run()
        new = fork_chain(chain)
        run(
            f"set pose of {_label(document, j)}",
            lambda: new.transformJoint(j, T, propagate=propagate),
        )
        sources = tuple(range(len(new.Joints)))
        return Outcome(document.replaced(chain=new), j, run.clear_warning(new), sources)


@dataclass(frozen=True)
class TransformAll(Command):
    """Move the whole chain rigidly by the world transform ``transform``."""

    transform: Any

    label: ClassVar[str] = "transform all"

    def apply(self, document: Document) -> Outcome:
        T = _pose("transform", self.transform, document.chain.r)
        run = _Run()
        new = fork_chain(document.chain)
        run("transform all", lambda: new.transformAll(T))
        return Outcome(document.replaced(chain=new), None, (), tuple(range(len(new.Joints))))


@dataclass(frozen=True)
class SetJointParameters(Command):
    """Change a joint's parameters (e.g. ``{"numSinkLayers": 2}``); its pose and state stay,
    its two links are solved again, the other joints stay where they are."""

    joint: int | str
    parameters: Mapping

    label: ClassVar[str] = "change joint"

    def describe(self) -> str:
        keys = ", ".join(map(str, self.parameters)) if isinstance(self.parameters, Mapping) else ""
        return f"change {keys} of joint {self.joint!r}"

    def apply(self, document: Document) -> Outcome:
        chain = document.chain
        j = resolve_joint(document, self.joint)
        old = chain.Joints[j]
        kind = type(old).__name__
        if kind not in JOINT_TYPES:
            _fail(f"{_label(document, j)} has no parameters the editor can change")
        joint = _new_joint(
            kind, self.parameters, old.pose_matrix, chain.numSides, chain.r, joint_parameters(old)
        )
        lo, hi = joint.stateRange()
        if not lo <= old.state <= hi:
            _fail(
                f"the state {old.state!r} of {_label(document, j)} would be outside the new "
                f"range [{lo:.6g}, {hi:.6g}]; set the state within it first"
            )
        if old.state != 0.0:
            joint = joint.with_state(old.state)
        run = _Run()
        joints = list(chain.Joints)
        joints[j] = joint
        new = _rebuilt(run, chain, joints, keep=j)
        return Outcome(document.replaced(chain=new), j, run.clear_warning(new),
                       tuple(range(len(new.Joints))))  # fmt: skip


@dataclass(frozen=True)
class RenameJoint(Command):
    """Give a joint a name (unique among the joints), or take it away with None."""

    joint: int | str
    name: str | None

    label: ClassVar[str] = "rename joint"

    def describe(self) -> str:
        return f"rename joint {self.joint!r} to {self.name!r}"

    def apply(self, document: Document) -> Outcome:
        j = resolve_joint(document, self.joint)
        name = _check_name(document, self.name, j)
        names = document.names[:j] + (name,) + document.names[j + 1 :]
        return Outcome(document.replaced(names=names), j, (), tuple(range(len(names))))


def _check_state(document: Document, j: int, value, name: str) -> float:
    s = _number(name, value)
    joint = document.chain.Joints[j]
    lo, hi = joint.stateRange()
    if not lo <= s <= hi:
        if joint.motion == PRISMATIC:
            unit = f"(a length, {document.units})"
            got = repr(s)
        else:
            unit = f"radians ([{angle_text(lo)}, {angle_text(hi)}])"
            got = f"{s!r} ({angle_text(s)})"
        _fail(f"{name} of {_label(document, j)} must be in [{lo:.6g}, {hi:.6g}] {unit}, got {got}")
    return s


@dataclass(frozen=True)
class SetJointState(Command):
    """Set a joint's state (radians or a length); the later joints follow rigidly."""

    joint: int | str
    state: float

    label: ClassVar[str] = "set state"

    def describe(self) -> str:
        return f"set state of joint {self.joint!r} to {self.state!r}"

    def apply(self, document: Document) -> Outcome:
        j = resolve_joint(document, self.joint)
        s = _check_state(document, j, self.state, "state")
        run = _Run()
        new = fork_chain(document.chain)
        run(f"set state of {_label(document, j)}", lambda: new.setJointState(j, s))
        return Outcome(document.at_other_states(new), j, run.clear_warning(new),
                       tuple(range(len(new.Joints))))  # fmt: skip


@dataclass(frozen=True)
class SetJointStates(Command):
    """Set every joint's state at once (one value per joint; 0 for joints that do not move)."""

    states: Sequence[float]

    label: ClassVar[str] = "set states"

    def apply(self, document: Document) -> Outcome:
        n = len(document.chain.Joints)
        if isinstance(self.states, str | bytes) or not isinstance(
            self.states, Sequence | np.ndarray
        ):
            _fail(f"states must be a sequence of {n} numbers, got {shown(self.states)}")
        if len(self.states) != n:
            _fail(f"states must have one value per joint ({n}), got {len(self.states)}")
        values = [_check_state(document, i, s, f"states[{i}]") for i, s in enumerate(self.states)]
        run = _Run()
        new = fork_chain(document.chain)
        run("set states", lambda: new.setJointStates(values))
        return Outcome(document.at_other_states(new), None, run.clear_warning(new),
                       tuple(range(n)))  # fmt: skip


def _kept_by_compact(chain) -> list[int]:
    """The joints compaction keeps (the others are waypoints it may move, add or drop): every
    joint that is not a waypoint; in a tree also the root and the waypoints where it branches."""
    if not _is_tree(chain):
        return [i for i, joint in enumerate(chain.Joints) if type(joint) is not Waypoint]
    children = chain.Children
    return [i for i, joint in enumerate(chain.Joints)
            if i == 0 or type(joint) is not Waypoint or len(children[i]) > 1]  # fmt: skip


class LongCommand(Command):
    """A command whose heavy part may run elsewhere (the editor runs it in a worker process,
    with progress and Cancel; docs/editor.md#background-jobs).

    :meth:`compute` is the heavy part, given the chain (or tree) only and a ``progress``
    callback (docs/progress.md); it returns a picklable ``(result, warnings)``. :meth:`finish`
    makes the new document of ``document`` from that result, quickly. :meth:`apply` does both
    here; :class:`Computed` is the command that applies a result computed elsewhere.
    """

    def check(self, document: Document) -> None:
        """Refuse ``document`` before any heavy work (raises CommandError)."""

    def compute(self, chain, progress=False) -> tuple[Any, tuple[str, ...]]:
        """``(result, warnings)`` of the heavy part for ``chain`` (raises CommandError, or
        :class:`~kinegami.errors.Cancelled` when ``progress`` returned False)."""
        run = _Run()
        result = run(self.label, lambda: self._compute(chain, progress))
        return result, tuple(run.warnings)

    @abc.abstractmethod
    def _compute(self, chain, progress):
        """The library call (any process)."""

    @abc.abstractmethod
    def finish(self, document: Document, computed: tuple[Any, tuple[str, ...]]) -> Outcome:
        """The outcome for ``document`` of :meth:`compute`'s result for its chain."""

    def prepared(self, document: Document) -> LongCommand:
        """This command with what its heavy part needs of ``document`` besides the chain (e.g.
        the task Compact keeps), to run elsewhere; by default itself."""
        return self

    def apply(self, document: Document) -> Outcome:
        command = self.prepared(document)
        command.check(document)
        return command.finish(document, command.compute(document.chain))


@dataclass(frozen=True, eq=False)
class Computed(Command):
    """A :class:`LongCommand` whose heavy part was computed elsewhere for ``source``: applying
    it makes ``command``'s document of ``source`` (whatever the document is now: a view that
    lets edits happen meanwhile asks first), one step in the undo history."""

    command: LongCommand
    source: Document
    computed: tuple

    @property
    def label(self) -> str:  # type: ignore[override]
        return self.command.label

    def apply(self, document: Document) -> Outcome:
        outcome = self.command.finish(self.source, self.computed)
        if document is not self.source:  # joints matched by value, not by the source's indices
            return Outcome(outcome.document, outcome.selected, outcome.warnings)
        return outcome

    def describe(self) -> str:
        return self.command.describe()


@dataclass(frozen=True)
class Compact(LongCommand):
    """Replace the chain (or tree) by a shorter one with the same kinematics and no collisions
    (:func:`kinegami.optimize.compact`, docs/clearance.md; a tree's sockets fit afterwards);
    names follow their joints. ``motion`` is for chains only.

    A design with a task keeps it (``keep_task``, as ``kinegami compact`` does): a shorter
    design is accepted only when every target (a tree's: every grasp, the k-th target of every
    leaf at once) is still reached exactly, in range, clear with the larger of the design's and
    the task's margins and outside the keep-out boxes
    (:func:`kinegami.optimize.compact_for_task`; ``motion`` and ``objective`` are then not
    used), else the command is refused. A tree task on a chain, or a chain's on a tree, is not
    kept (the design cannot reach it as it is). ``task`` is the task document to keep (default: the
    document's) and ``units`` the design's length units; :meth:`prepared` fills both in.
    """

    seed: int = 0
    motion: bool = False
    objective: str = "length"
    starts: int = 4
    time_limit: float | None = None
    executor: Any = None
    keep_task: bool = True
    task: Any = None
    units: str = "mm"

    label: ClassVar[str] = "compact"

    def prepared(self, document: Document) -> Compact:
        task = self.task
        if task is None and self.keep_task and document.task is not None and \
                document.is_tree == _is_tree_task(document.task):  # fmt: skip
            task = document.task  # (a chain's task for a chain, a tree's for a tree)
        if task is None:
            return self
        return replace(self, task=task, units=document.units)

    def _compute(self, chain, progress):
        from kinegami.optimize import compact

        if self.task is None:
            return compact(chain, seed=self.seed, motion=self.motion, executor=self.executor,
                           time_limit=self.time_limit, progress=progress,
                           objective=self.objective, starts=self.starts)  # fmt: skip
        from kinegami.editor.tasks import task_goals

        goals = task_goals(self.task, self.units)
        margin = max(float(chain.margin), goals.margin)
        found = compact(chain, seed=self.seed, executor=self.executor, time_limit=self.time_limit,
                        progress=progress, starts=self.starts, targets=list(goals.targets),
                        keep_out=goals.keep_out, margin=margin)  # fmt: skip
        if found is chain:
            _fail("compact: no shorter design keeps the task (every target reached exactly, in "
                  "range, clear and outside the keep-out boxes); the design is unchanged")
        if found.margin != chain.margin:  # checked with the larger margin; the design keeps its own
            found = fork_chain(found)
            found.margin = chain.margin
        return found

    def finish(self, document: Document, computed) -> Outcome:
        new, warned = computed
        chain = document.chain
        old_kept, new_kept = _kept_by_compact(chain), _kept_by_compact(new)
        old_types = [type(chain.Joints[i]) for i in old_kept]
        new_types = [type(new.Joints[i]) for i in new_kept]
        if old_types != new_types:  # pragma: no cover - compact keeps the joints
            _fail("compact changed the joints' types; the design is unchanged")
        names = [None] * len(new.Joints)
        sources: list = [None] * len(new.Joints)
        for i, k in zip(new_kept, old_kept, strict=True):
            names[i], sources[i] = document.names[k], k
        clear = tuple(warned) if warned and not new.clearance().ok else ()
        if self.task is not None and self.motion:
            clear += ("motion was not checked: the design's task is kept instead (every target "
                      "still reached, clear)",)  # fmt: skip
        return Outcome(document.replaced(chain=new, names=tuple(names)), None, clear,
                       tuple(sources))  # fmt: skip


def _is_tree_task(task) -> bool:
    """Whether a task document is a tree's (its joints given per leaf)."""
    return isinstance(task, dict) and isinstance(task.get("joints"), list)


@dataclass(frozen=True)
class DesignForTask(LongCommand):
    """Replace the chain by one designed for the document's task
    (:func:`kinegami.optimize.design_for`, docs/design-for-a-task.md): its tip reaches every
    target exactly, in range, clear of itself and outside the keep-out boxes, as
    ``kinegami design`` makes it. A tree task (joints given per leaf) designs a
    :class:`~kinegami.tree.KinematicTree` whose leaves reach their k-th targets at once; the
    task decides the kind, whatever the design was. The task stays in the document; the
    design's length units become the task's (the designed chain is in them), its name and
    description stay (a design without a name takes the task's). ``seed`` and ``starts``
    default to the task's.
    Refused (the design unchanged) when the search finds no design, with its reason
    (:class:`~kinegami.errors.InfeasibleTaskError`). ``task`` is filled in by
    :meth:`prepared` from the document.
    """

    seed: int | None = None
    starts: int | None = None
    executor: Any = None
    task: Any = None

    label: ClassVar[str] = "design for task"

    def prepared(self, document: Document) -> DesignForTask:
        if self.task is not None or document.task is None:
            return self
        return replace(self, task=document.task)

    def check(self, document: Document) -> None:
        if self.task is None:
            _fail("design for task: this design has no task (a design file made by kinegami "
                  "design carries one in its \"task\" block; docs/design-for-a-task.md)")

    def _compute(self, chain, progress):
        from kinegami.design.task import task_from_dict
        from kinegami.optimize import design_for

        task = task_from_dict(self.task, where=("task",))
        options = task.options()
        if self.seed is not None:
            options["seed"] = self.seed
        if self.starts is not None:
            options["starts"] = self.starts
        targets, joints = list(task.targets), task.joints
        if task.is_tree:  # one list of targets and one joint string per leaf
            targets, joints = [list(leaf) for leaf in task.targets], list(task.joints)
        # a search, run as kinegami design runs it (numpy's default floating-point handling)
        with np.errstate(over="warn", invalid="warn", divide="warn", under="ignore"):
            return design_for(targets, joints, executor=self.executor, progress=progress,
                              **options)  # fmt: skip

    def finish(self, document: Document, computed) -> Outcome:
        new, warned = computed
        task = self.task
        name = document.name if document.name is not None else task.get("name")
        designed = Document(new, (None,) * len(new.Joints), name, document.description,
                            task.get("units", "mm"), document.twistPortion, task)  # fmt: skip
        clear = tuple(warned) if warned and not new.clearance().ok else ()
        return Outcome(designed, None, clear, (None,) * len(new.Joints))


@dataclass(frozen=True)
class SetOptions(Command):
    """Change the design's options; fields left at :data:`KEEP` stay as they are.

    Parameters
    ----------
    requireClearance : reject every later command that makes the chain pass through itself
        (the chain must be clear now to turn it on).
    maxAnglePerElbow : largest turn of one elbow, in [pi/180, pi]; every link is solved again.
    twistPortion : share of each link's straight part given to its twist, in [0, 1), or None
        for the default (0.2).
    name, description : the design's texts (or None).
    units : the length unit, "mm", "cm", "m" or "in".
    """

    requireClearance: Any = KEEP
    maxAnglePerElbow: Any = KEEP
    twistPortion: Any = KEEP
    name: Any = KEEP
    description: Any = KEEP
    units: Any = KEEP

    label: ClassVar[str] = "set options"

    def describe(self) -> str:
        keys = [k for k in ("requireClearance", "maxAnglePerElbow", "twistPortion", "name",
                            "description", "units") if getattr(self, k) is not KEEP]  # fmt: skip
        return "set " + (", ".join(keys) or "no option")

    def apply(self, document: Document) -> Outcome:
        changes: dict = {}
        chain = document.chain
        for key in ("name", "description"):
            value = getattr(self, key)
            if value is not KEEP:
                if value is not None and not isinstance(value, str):
                    _fail(f"{key} must be a string or None, got {shown(value)}")
                changes[key] = value
        if self.units is not KEEP:
            if self.units not in UNITS:
                _fail(
                    f"units must be one of {', '.join(map(repr, UNITS))}, got {shown(self.units)}"
                )
            changes["units"] = self.units
        if self.twistPortion is not KEEP:
            if self.twistPortion is not None:
                value = _number("twistPortion", self.twistPortion)
                if not 0.0 <= value < 1.0:
                    _fail(f"twistPortion must be in [0, 1), got {value!r}")
                changes["twistPortion"] = value
            else:
                changes["twistPortion"] = None
        run = _Run()
        new = chain
        if self.maxAnglePerElbow is not KEEP:
            angle = _number("maxAnglePerElbow", self.maxAnglePerElbow)
            if not limits.MIN_ANGLE_PER_ELBOW <= angle <= math.pi:
                _fail(f"maxAnglePerElbow must be in [pi/180, pi] radians, got {angle!r}")
            if angle != chain.maxAnglePerElbow:
                new = _rebuilt(run, chain, chain.Joints, maxAnglePerElbow=angle)
        if self.requireClearance is not KEEP:
            require = _flag("requireClearance", self.requireClearance)
            if require != new.requireClearance:
                if require:
                    report = new.clearance()
                    if not report.ok:
                        noun = "tree" if _is_tree(new) else "chain"
                        _fail(
                            f"requireClearance cannot be turned on: the {noun} passes through "
                            f"itself ({report.pairs[0]})"
                        )
                new = fork_chain(new) if new is chain else new
                new.requireClearance = require
        if new is not chain:
            changes["chain"] = new
        return Outcome(document.replaced(**changes), None, run.clear_warning(new),
                       tuple(range(len(new.Joints))))  # fmt: skip


@dataclass(frozen=True)
class FitJunctions(LongCommand):
    """Slide the branch children of a tree whose printed junction socket would not fit on
    their link, along their axes (:func:`kinegami.fabrication.sheets.fit_junctions`: the kinematics
    stay, no new collision): what ``kinegami build`` does before it makes the sheets."""

    label: ClassVar[str] = "fit junctions"

    def check(self, document: Document) -> None:
        if not document.is_tree:
            _fail("fit junctions: a chain has no junctions (a tree has one at every joint "
                  "with several children)")  # fmt: skip

    def _compute(self, chain, progress):
        from kinegami.fabrication.sheets import fit_junctions

        return fit_junctions(chain, progress=progress)

    def finish(self, document: Document, computed) -> Outcome:
        (fitted, moves), warned = computed
        if not moves:
            _fail("fit junctions: every junction's socket fits already; nothing to slide")
        clear = tuple(warned) if warned and not fitted.clearance().ok else ()
        return Outcome(document.replaced(chain=fitted), moves[0][0], clear,
                       tuple(range(len(fitted.Joints))))  # fmt: skip


@dataclass(frozen=True)
class ReplaceDocument(Command):
    """Replace the whole document by ``document`` (e.g. an autosave offered back after a
    crash); undo gives the one before back. ``what`` is its line in the undo history."""

    document: Document
    what: str = "replace the document"

    label: ClassVar[str] = "replace the document"

    def apply(self, document: Document) -> Outcome:
        if not isinstance(self.document, Document):
            _fail(f"document must be an editor Document, got {shown(self.document)}")
        return Outcome(self.document)

    def describe(self) -> str:
        return str(self.what)
