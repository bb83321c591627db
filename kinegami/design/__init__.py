"""Design files: a kinematic chain or tree as a JSON document (format "kinegami-design",
versions 1 to 4).

A design file lists the tube (``numSides``, ``r``), the joints as they would be appended in
Python (or a DH table), optional edits and joint states; see docs/design-format.md and the JSON
Schema shipped as ``kinegami/design/schema.json`` (:func:`design_schema`). Version 2 adds trees:
a joint may name its ``parent``, and the joints may be a joint specification that the tree
construction places (:mod:`kinegami.design.trees`). Loading gives a
:class:`~kinegami.chain.KinematicChain` for a chain and a :class:`~kinegami.tree.KinematicTree`
for a tree; saving writes either.

>>> chain = load_design("tests/design/data/example1.json")  # doctest: +SKIP
>>> save_design(chain, "out/example1.json", name="Example 1")  # doctest: +SKIP

Every problem (unreadable file, invalid JSON, schema violation, a value beyond the bounds of
:mod:`kinegami.design.limits`, infeasible placement or edit) raises :class:`DesignError`, whose
one-line message names the file, the JSON path of the problem (e.g.
``joints[2].totalBendingAngle``), what is allowed and the value found.
:func:`check_pattern` also checks that the chain's crease pattern can be built, and
:func:`joint_table` lists the joints of the built chain (the indices edits and states use).
"""

from __future__ import annotations

import os
from dataclasses import dataclass

from kinegami.chain.model import KinematicChain
from kinegami.design import limits
from kinegami.design.checks import check_pattern, joint_table
from kinegami.design.errors import DesignError
from kinegami.design.poses import pose_from_json
from kinegami.design.reader import (
    FORMAT,
    UNITS,
    VERSIONS,
    DesignInfo,
    DesignOrigin,
    DesignProblem,
    audit_document,
    build_plan,
    check_document,
    origin_of,
    parse_design_text,
    read_design_file,
)
from kinegami.design.schema import design_schema
from kinegami.design.writer import design_to_dict, dumps_design, save_design
from kinegami.tree import KinematicTree

__all__ = [
    "DesignError",
    "DesignInfo",
    "FORMAT",
    "VERSIONS",
    "UNITS",
    "load_design",
    "load_design_with_info",
    "loads_design",
    "chain_from_dict",
    "read_design",
    "validate_design",
    "audit_design",
    "DesignReport",
    "DesignProblem",
    "save_design",
    "design_to_dict",
    "dumps_design",
    "design_schema",
    "pose_from_json",
    "check_pattern",
    "joint_table",
    "origin_of",
    "DesignOrigin",
    "limits",
]


def _with_info(document, file) -> tuple[KinematicChain | KinematicTree, DesignInfo]:
    plan = check_document(document, file)
    return build_plan(plan, file)[0], DesignInfo.of(document, file)


def load_design_with_info(
    path: str | os.PathLike,
) -> tuple[KinematicChain | KinematicTree, DesignInfo]:
    """The chain (or tree) of the design file ``path`` and the file's metadata (units, name,
    ...).

    A KinematicTree when the design is a tree (``"structure": "tree"``, a joint whose
    ``parent`` is not the previous entry, or a joint specification), else a KinematicChain.

    Raises
    ------
    DesignError
        If the file cannot be read (not a regular file, larger than 16 MiB), is not valid JSON,
        violates the format or its bounds, or describes a chain that cannot be built
        (infeasible placement, edit or state). Whether the crease pattern can be built is
        checked by :func:`check_pattern`.
    """
    document, file = read_design_file(path)
    return _with_info(document, file)


def load_design(path: str | os.PathLike) -> KinematicChain | KinematicTree:
    """The chain or tree described by the design file ``path`` (lengths in the file's units).

    Raises DesignError for any problem (see :func:`load_design_with_info`).
    """
    return load_design_with_info(path)[0]


def loads_design(
    text: str, file: str | os.PathLike | None = None
) -> KinematicChain | KinematicTree:
    """The chain or tree described by the design JSON ``text``; ``file`` only names it in
    errors."""
    return _with_info(parse_design_text(text, file), file)[0]


def chain_from_dict(
    data: dict, file: str | os.PathLike | None = None
) -> KinematicChain | KinematicTree:
    """The chain or tree described by an already parsed design document (a dict)."""
    return _with_info(data, file)[0]


def read_design(path: str | os.PathLike) -> dict:
    """The parsed design document of ``path``, checked like :func:`validate_design`.

    The dict is the file's content as written (angles in its ``angleUnits``, no defaults
    filled in); ``DesignInfo.of(document)`` gives units, name and twistPortion with defaults.
    """
    document, file = read_design_file(path)
    check_document(document, file)
    return document


def validate_design(path: str | os.PathLike) -> None:
    """Check the design file ``path`` without building the chain.

    Parses the JSON, validates it against the schema and runs the checks the schema cannot
    express (lengths within 1e6 r, rigid matrices, axes, joint order, placement options,
    unique joint names and the names edits use, parents, joint parameters). Whether
    every joint can be placed and every edit and state applied is only known by building the
    chain: use :func:`load_design` for the full check. Raises DesignError; returns None.
    """
    read_design(path)


@dataclass(frozen=True)
class DesignReport:
    """Every problem found in a design file (:func:`audit_design`).

    Attributes
    ----------
    file : the design file as given.
    problems : the problems, each a :class:`~kinegami.design.reader.DesignProblem` (``code``,
        ``field``: its JSON path, ``error``: its DesignError); the first is the one
        :func:`validate_design` raises.
    """

    file: str
    problems: tuple[DesignProblem, ...]

    @property
    def ok(self) -> bool:
        """Whether the design has no problem (validate_design passes)."""
        return not self.problems

    def __str__(self) -> str:
        if self.ok:
            return f"{self.file}: valid"
        count = len(self.problems)
        lines = [f"{self.file}: {count} problem{'s' if count > 1 else ''}"]
        return "\n".join(lines + [f"  {problem}" for problem in self.problems])


def audit_design(path: str | os.PathLike) -> DesignReport:
    """Check the design file ``path`` as :func:`validate_design` does, and return every
    problem found instead of raising on the first (as ezdxf's ``audit()`` lists a drawing's
    errors). A file that cannot be read or parsed is one problem (code ``file``); see
    :func:`~kinegami.design.reader.audit_document` for the stages of the other checks.
    Like validate_design it does not build the chain (placements, edits and states are only
    checked by :func:`load_design`).
    """
    try:
        document, file = read_design_file(path)
    except DesignError as error:
        return DesignReport(os.fspath(path) if isinstance(path, str | os.PathLike) else
                            repr(path), (DesignProblem("file", error),))  # fmt: skip
    return DesignReport(file, tuple(audit_document(document, file)))
