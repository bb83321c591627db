"""The editor's document: a design (chain or tree, joint names, options, file metadata, the task
it is made for) as a value.

A :class:`Document` never changes once made: commands build a new one (see
:mod:`kinegami.editor.commands`), so undo keeps the old one and gives it back bit for bit. Its
chain (a :class:`~kinegami.chain.KinematicChain` or a :class:`~kinegami.tree.KinematicTree`)
is a private copy that nothing edits in place; its clearance report, joint table and design
text are computed on first use and kept. See docs/editor.md.
"""

from __future__ import annotations

import copy
import json
import os
import warnings
from dataclasses import dataclass
from functools import cached_property
from pathlib import Path
from typing import TYPE_CHECKING

import numpy as np

from kinegami._atomic import write_atomic
from kinegami.chain.joints import (
    Joint,
)
from kinegami.chain.model import KinematicChain
from kinegami.design import DesignInfo, design_to_dict, dumps_design
from kinegami.design.reader import (
    DEFAULT_TWIST_PORTION,
    UNITS,
    build_plan,
    check_document,
    origin_of,
    parse_design_text,
    read_design_file,
)
from kinegami.errors import ClearanceWarning, InvalidParameterError, InvalidTypeError
from kinegami.tree import KinematicTree

if TYPE_CHECKING:  # pragma: no cover
    from kinegami.fabrication.beds import Bed, Material

__all__ = ["Document", "JointRow", "joint_parameters", "fork_chain", "plain_task"]


def fork_chain(chain: KinematicChain | KinematicTree) -> KinematicChain | KinematicTree:
    """A copy of ``chain`` (a chain or a tree) that can be edited without touching ``chain``.

    Joints and links are immutable values and every chain or tree operation replaces the lists
    (joints, links, a tree's parents) rather than changing them, so a shallow copy shares them
    safely (and costs microseconds).
    """
    return copy.copy(chain)


def plain_task(task) -> dict | None:
    """A private copy of a task document made of plain JSON values (dicts, lists, numbers,
    strings), or None for None."""
    if task is None:
        return None
    if not isinstance(task, dict):
        raise InvalidTypeError(f"task must be a task document (a dict) or None, got "
                               f"{type(task).__name__}")  # fmt: skip
    return json.loads(json.dumps(task, allow_nan=False))


def joint_parameters(joint: Joint) -> dict:
    """The joint's constructor parameters (radians, chain lengths), as in a design file (its
    kind's :meth:`~kinegami.chain.joints.Joint.design_fields`)."""
    return joint.design_fields()


@dataclass(frozen=True)
class JointRow:
    """One row of the joint table.

    Attributes
    ----------
    index : the joint's index in the chain or tree (what commands use).
    type : the joint's class name (``"RevoluteJoint"``, ...).
    name : its name in the design, or None.
    pose : the joint's Pose as a read-only 4x4 array (world coordinates, z = axis of motion).
    state : its state (radians for revolute joints, a length for prismatic ones, else 0).
    state_range : the closed interval of its states.
    parameters : its constructor parameters (see :func:`joint_parameters`).
    parent : the index of its parent (-1 for the root; in a chain, index - 1).
    children : the indices of its children (in a chain, the next joint, if any).
    """

    index: int
    type: str
    name: str | None
    pose: np.ndarray
    state: float
    state_range: tuple[float, float]
    parameters: dict
    parent: int = -1
    children: tuple[int, ...] = ()

    @property
    def movable(self) -> bool:
        """Whether the joint has a range of motion (revolute and prismatic joints)."""
        return self.state_range[0] != self.state_range[1]


def _check_text(key: str, value) -> str | None:
    if value is not None and not isinstance(value, str):
        raise InvalidTypeError(f"{key} must be a string or None, got {value!r}")
    return value


@dataclass(frozen=True, eq=False)
class Document:
    """A design as the editor holds it: the built chain or tree and what a design file adds.

    Attributes
    ----------
    chain : the built KinematicChain or KinematicTree (a private copy: never edit it; commands
        make new documents). :attr:`is_tree` says which.
    names : one name (or None) per joint of ``chain``.
    name, description : the design's texts (None when absent).
    units : the length unit ("mm", "cm", "m" or "in").
    twistPortion : share of each link's straight part given to its twist (None: the default
        0.2, not written to the file).
    task : the task the design is made for (its ``"task"`` block, a task document as
        docs/design-for-a-task.md describes; None: none). Plain JSON values, never changed:
        commands keep it, :meth:`save` writes it back.
    material, bed : the design's sheet material and laser bed (version 4,
        kinegami.fabrication.beds.Material and Bed; None: none), kept and written back.
    shape_of : a document whose chain is this one's at other states (set by the commands
        that only change states; None otherwise): the clearance is measured with its chain's
        engine, built once for a whole drag or animation instead of once per step.

    ``chain.requireClearance`` and ``chain.maxAnglePerElbow`` are the design's chain options;
    the joints' states are the chain's.
    """

    chain: KinematicChain | KinematicTree
    names: tuple
    name: str | None = None
    description: str | None = None
    units: str = "mm"
    twistPortion: float | None = None
    task: dict | None = None
    material: Material | None = None
    bed: Bed | None = None
    shape_of: Document | None = None

    def __post_init__(self) -> None:
        if not isinstance(self.chain, KinematicChain | KinematicTree):
            raise InvalidTypeError(
                "chain must be a KinematicChain or a KinematicTree, got "
                f"{type(self.chain).__name__}"
            )
        names = tuple(self.names)
        if len(names) != len(self.chain.Joints):
            raise InvalidParameterError(
                f"names must have one entry per joint ({len(self.chain.Joints)}), got {len(names)}"
            )
        object.__setattr__(self, "names", names)
        _check_text("name", self.name)
        _check_text("description", self.description)
        if self.task is not None and not isinstance(self.task, dict):
            raise InvalidTypeError(f"task must be a task document (a dict) or None, got "
                                   f"{type(self.task).__name__}")  # fmt: skip
        if self.units not in UNITS:
            raise InvalidParameterError(
                f"units must be one of {', '.join(map(repr, UNITS))}, got {self.units!r}"
            )

    # --- making documents ---------------------------------------------------------------------
    @classmethod
    def from_chain(
        cls,
        chain: KinematicChain | KinematicTree,
        names=None,
        *,
        name: str | None = None,
        description: str | None = None,
        units: str = "mm",
        twistPortion: float | None = None,
        task: dict | None = None,
    ) -> Document:
        """A document holding a copy of ``chain``, a chain or a tree (later edits of ``chain``
        do not reach it), and a copy of ``task`` (a task document, or None).

        ``names`` defaults to the joint names the design loader remembers for ``chain``.
        """
        if not isinstance(chain, KinematicChain | KinematicTree):
            raise InvalidTypeError(
                f"chain must be a KinematicChain or a KinematicTree, got {type(chain).__name__}"
            )
        if names is None:
            origin = origin_of(chain)
            names = origin.names if origin is not None else (None,) * len(chain.Joints)
        return cls(fork_chain(chain), tuple(names), name, description, units, twistPortion,
                   plain_task(task))  # fmt: skip

    @classmethod
    def _from_parsed(cls, document, file) -> Document:
        plan = check_document(document, file)
        chain, origin = build_plan(plan, file)
        info = DesignInfo.of(document, file)
        return cls(
            fork_chain(chain),
            tuple(origin.names),
            info.name,
            info.description,
            info.units,
            document.get("twistPortion"),
            plain_task(info.task),
            info.material,
            info.bed,
        )

    @classmethod
    def load(cls, path: str | os.PathLike) -> Document:
        """The document of the design file ``path`` (raises DesignError, see
        docs/design-format.md)."""
        document, file = read_design_file(path)
        return cls._from_parsed(document, file)

    @classmethod
    def loads(cls, text: str, file: str | os.PathLike | None = None) -> Document:
        """The document of design JSON ``text`` (``file`` only names it in errors)."""
        return cls._from_parsed(parse_design_text(text, file), file)

    def replaced(self, **changes) -> Document:
        """A new document with some attributes replaced (``chain`` is used as given)."""
        values = {
            "chain": self.chain,
            "names": self.names,
            "name": self.name,
            "description": self.description,
            "units": self.units,
            "twistPortion": self.twistPortion,
            "task": self.task,
            "material": self.material,
            "bed": self.bed,
        }
        values.update(changes)
        return Document(**values)

    # --- derived values (computed once) -------------------------------------------------------
    @property
    def is_tree(self) -> bool:
        """Whether the design is a tree (its chain is a KinematicTree; folded from a sheet per
        leaf) rather than a chain."""
        return isinstance(self.chain, KinematicTree)

    @property
    def twist_portion(self) -> float:
        """The twist portion the crease pattern uses (``twistPortion`` or the default 0.2)."""
        return DEFAULT_TWIST_PORTION if self.twistPortion is None else float(self.twistPortion)

    @cached_property
    def clearance(self):
        """The chain's (or tree's) ClearanceReport at its states, with its margin and the parts
        named (kinegami.clearance.clearance_report: the verdict build and check give)."""
        from kinegami.clearance import clearance_report

        if self.shape_of is not None:  # the same chain at other states: its engine, cached
            states = [float(joint.state) for joint in self.chain.Joints]
            return clearance_report(self.shape_of.chain, names=self.names, states=states)
        return clearance_report(self.chain, names=self.names)

    def at_other_states(self, chain) -> Document:
        """This document with ``chain``, which is its chain at other states (what a command
        that only changes states makes; :attr:`shape_of` remembers the chain they share)."""
        return self.replaced(chain=chain, shape_of=self.shape_of or self)

    @cached_property
    def verdict(self) -> str:
        """The clearance verdict in one line, worded as ``kinegami build`` and ``kinegami check``
        print it (lengths in mm and the design's units; docs/clearance.md)."""
        return self.clearance.verdict(self.units)

    @cached_property
    def joint_table(self) -> tuple[JointRow, ...]:
        """One :class:`JointRow` per joint, in index order."""
        parents = self.chain.Parents
        children: list[list[int]] = [[] for _ in parents]
        for k, p in enumerate(parents):
            if p >= 0:
                children[p].append(k)
        rows = []
        for i, joint in enumerate(self.chain.Joints):
            lo, hi = joint.stateRange()
            rows.append(
                JointRow(
                    i, type(joint).__name__, self.names[i], joint.pose_matrix,
                    float(joint.state), (float(lo), float(hi)), joint_parameters(joint),
                    int(parents[i]), tuple(children[i]),
                )
            )  # fmt: skip
        return tuple(rows)

    @cached_property
    def design_dict(self) -> dict:
        """The design document (a JSON-ready dict) that loads as this document.

        Raises InvalidParameterError when the chain cannot be written as a design (see
        ``kinegami.design.design_to_dict``). A tree is written as version 2 with every joint's
        ``parent``: its name when it has one, else its entry's index.
        """
        with warnings.catch_warnings():  # the writer's state-0 copy may pass through itself
            warnings.simplefilter("ignore", ClearanceWarning)
            document = design_to_dict(
                self.chain,
                name=self.name,
                description=self.description,
                units=self.units,
                twistPortion=self.twistPortion,
                task=self.task,
                material=self.material,
                bed=self.bed,
            )
        entries = document["joints"]
        offset = len(entries) - len(self.names)  # 1 when the root is an EndTip (see writer)
        parents = self.chain.Parents if self.is_tree else None
        for i, label in enumerate(self.names):
            entry = entries[i + offset]
            entry.pop("name", None)
            head = {"type": entry.pop("type")}
            if label is not None:
                head["name"] = label
            if parents is not None and "parent" in entry:
                # the writer names parents by the loader's names, which edits may have changed
                entry.pop("parent")
                p = parents[i]
                if p < 0:  # an EndTip root, written after a waypoint root that an edit deletes
                    head["parent"] = 0
                else:
                    head["parent"] = self.names[p] if self.names[p] is not None else p + offset
            entries[i + offset] = {**head, **entry}
        return document

    @cached_property
    def design_text(self) -> str:
        """The design file's text (see :attr:`design_dict`), checked against the format.

        Raises InvalidParameterError when the chain cannot be saved as a design.
        """
        text = dumps_design(self.design_dict)
        try:
            check_document(json.loads(text))
        except ValueError as error:
            raise InvalidParameterError(f"the design cannot be saved: {error}") from None
        return text

    def save(self, path: str | os.PathLike) -> Path:
        """Write the design file ``path`` (suffix .json) atomically (:func:`kinegami._atomic.
        write_atomic`: an interrupted or failed write leaves the old file and no temporary
        file) and return its path."""
        if not isinstance(path, str | os.PathLike) or isinstance(os.fspath(path), bytes):
            raise InvalidTypeError(f"path must be a str or a path, got {path!r}")
        target = Path(os.fspath(path)).expanduser()
        if target.suffix.lower() != ".json":
            raise InvalidParameterError(
                f"a design file name must end in .json, got {os.fspath(path)!r}"
            )
        if target.is_dir():
            raise InvalidParameterError(f"{os.fspath(path)!r} is a directory, not a file name")
        return write_atomic(target, self.design_text)
