"""Writing chains and trees as design files: exact 4x4 poses at state 0, plus the states.

Every joint is written with its own parameters and its Pose at state 0 (full precision; float
``repr`` round-trips exactly), and every non-root joint with ``relative: false, safe: false,
fixedPosition: true, fixedOrientation: true``, so loading re-creates each joint where it was.
Non-zero states go to ``"states"``; loading builds the chain at state 0 and then sets them.
A chain whose root is an EndTip (possible after deleting joint 0) is written as a waypoint
root, the tip, and an edit deleting the waypoint. Joint names are kept for a chain loaded from a
design (see :func:`kinegami.design.reader.origin_of`). A chain with ``requireClearance`` is
written with ``"requireClearance": true``. A chain is written as version 1, exactly as before
trees existed; a :class:`~kinegami.tree.KinematicTree` as version 2 with ``"structure": "tree"``
and every non-root joint's ``"parent"`` (its name when it has one, else its index), so that
loading gives a tree again, whatever its shape. A chain or tree whose ``margin`` is not 0 is
written as version 3 with its ``"margin"``; one saved with a sheet ``material`` or a laser
``bed`` as version 4 with them; every other one exactly as before.
"""

from __future__ import annotations

import copy
import json
import os
from pathlib import Path

from kinegami._atomic import write_atomic
from kinegami.chain.bodies import worst_overlap
from kinegami.chain.joints import (
    JOINT_KINDS,
    Joint,
)
from kinegami.chain.model import KinematicChain
from kinegami.clearance.tree_bodies import tree_worst_overlap
from kinegami.design.errors import DesignError
from kinegami.design.reader import FORMAT, UNITS, check_document, origin_of
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.tree import KinematicTree
from kinegami.validation import UNITS_IN_MM, check_twist_portion

__all__ = ["design_to_dict", "dumps_design", "save_design"]

#: The placement options that re-create a joint exactly where it is.
_FIXED = {"relative": False, "safe": False, "fixedPosition": True, "fixedOrientation": True}


def _joint_parameters(joint: Joint) -> dict:
    """The joint's type and constructor parameters (radians, chain length units): its kind's
    :meth:`~kinegami.chain.joints.Joint.design_fields`."""
    name = type(joint).__name__
    if JOINT_KINDS.get(name) is not type(joint):
        raise InvalidTypeError(
            f"cannot save a joint of type {name}: design files know {', '.join(JOINT_KINDS)}"
        )
    return {"type": name, **joint.design_fields()}


def _matrix(T) -> list[list[float]]:
    return [[float(v) for v in row] for row in T]


def _overlap(assembly):
    if isinstance(assembly, KinematicTree):
        return tree_worst_overlap(assembly.Joints, assembly.Links, assembly.Parents, assembly.r,
                                  margin=assembly.margin)  # fmt: skip
    return worst_overlap(assembly.Joints, assembly.Links, assembly.r, margin=assembly.margin)


def design_to_dict(
    chain: KinematicChain | KinematicTree,
    *,
    name: str | None = None,
    description: str | None = None,
    units: str = "mm",
    twistPortion: float | None = None,
    task: dict | None = None,
    material=None,
    bed=None,
) -> dict:
    """The design document (a JSON-ready dict) that re-creates ``chain`` exactly.

    Parameters
    ----------
    chain : the chain or tree (any edits and states). A tree is written as version 2, with
        ``"structure": "tree"`` and the parent of every joint.
    name, description : optional texts stored in the file.
    units : the length unit of the chain ("mm", "cm", "m" or "in"); metadata for exporters.
    twistPortion : stored for the crease pattern when given (in [0, 1)).
    task : the task document the design was made for (docs/design-for-a-task.md), kept as
        its ``"task"`` block.
    material : the sheet material (a :class:`~kinegami.fabrication.beds.Material`), kept as
        ``"material"`` (version 4); the chain's margin is then written only when it is not
        the material's thickness (the default a loaded file gets).
    bed : the laser bed (a :class:`~kinegami.fabrication.beds.Bed`), kept as ``"bed"``
        (version 4).

    Poses are those of the state-0 configuration (computed on a copy of the chain); non-zero
    states are listed in ``"states"`` (radians for revolute joints, lengths for prismatic).
    Angles are in radians (``"angleUnits": "rad"``). A chain whose ``margin`` is not 0 is
    written as version 3 with its ``"margin"`` (design units); with margin 0 the version is 1
    or 2 as before. ``"requireClearance": true`` is written
    when ``chain.requireClearance``; such a chain must be clear at its states and at state 0,
    where loading builds it (InvalidParameterError otherwise). If the chain was loaded from a design
    whose joints have names, each joint keeps its ``"name"`` (as long as the chain's joints
    still have the types they were loaded with; waypoints added by placement have none).
    """
    if not isinstance(chain, KinematicChain | KinematicTree):
        raise InvalidTypeError(
            f"chain must be a KinematicChain or a KinematicTree, got {type(chain).__name__}"
        )
    tree = isinstance(chain, KinematicTree)
    for key, text in (("name", name), ("description", description)):
        if text is not None and not isinstance(text, str):
            raise InvalidTypeError(f"{key} must be a string or None, got {text!r}")
    if units not in UNITS:
        raise InvalidParameterError(
            f"units must be one of {', '.join(map(repr, UNITS))}, got {units!r}"
        )
    origin = origin_of(chain)
    names = origin.names if origin is not None else (None,) * len(chain.Joints)
    states = [float(joint.state) for joint in chain.Joints]
    rest = chain
    if any(states):
        rest = copy.deepcopy(chain)
        rest.requireClearance = False  # checked below, with a message for the file
        if not rest.setJointStates([0.0] * len(states)):  # pragma: no cover - 0 is in range
            raise InvalidParameterError("cannot return the chain to state 0")
    if chain.requireClearance:  # loading builds the chain at state 0, then sets the states
        for where, built in (("at state 0", rest), ("at its states", chain)):
            found = _overlap(built)
            if found is not None:
                noun = "tree" if tree else "chain"
                raise InvalidParameterError(
                    f"a {noun} with requireClearance cannot be saved when it passes through "
                    f"itself {where} ({found}): loading it would fail; set requireClearance "
                    "to False or move it clear"
                )
    margin = float(chain.margin)
    fabrication = _fabrication_fields(material, bed)
    if material is not None and margin == material.thickness / UNITS_IN_MM[units]:
        margin = 0.0  # the material's thickness is the margin a loaded file gets
    # a newer version only when it says something older readers do not know
    version = 4 if fabrication else 3 if margin else 2 if tree else 1
    document = {"format": FORMAT, "version": version}
    if name is not None:
        document["name"] = name
    if description is not None:
        document["description"] = description
    document.update(
        units=units,
        angleUnits="rad",
        numSides=int(chain.numSides),
        r=float(chain.r),
        maxAnglePerElbow=float(chain.maxAnglePerElbow),
    )
    if chain.requireClearance:
        document["requireClearance"] = True
    if margin:
        document["margin"] = margin
    document.update(fabrication)
    if twistPortion is not None:
        document["twistPortion"] = check_twist_portion(twistPortion)
    if tree:
        document["structure"] = "tree"
    # Deleting joint 0 can leave an EndTip as root, which nothing can start with: then a
    # waypoint at the tip's proximal frame is written as root, and an edit deletes it again.
    shift = 1 if rest.Joints[0].closes_end else 0
    parents = rest.Parents
    joints = []
    for i, joint in enumerate(rest.Joints):
        entry = _joint_parameters(joint)
        head = {"type": entry.pop("type")}
        if names[i] is not None:
            head["name"] = names[i]
        if tree and i + shift > 0:
            p = parents[i]
            head["parent"] = 0 if p < 0 else names[p] if names[p] is not None else p + shift
        entry = {**head, **entry}
        if i + shift > 0:
            entry.update(_FIXED)
        entry["pose"] = _matrix(joint.pose_matrix)
        joints.append(entry)
    if shift:
        T = rest.Joints[0].proximal_frame()
        joints.insert(0, {"type": "Waypoint", "pathIndex": 2, "pose": _matrix(T)})
        document["joints"] = joints
        document["edits"] = [{"op": "delete", "joint": 0}]
    else:
        document["joints"] = joints
    if any(states):
        document["states"] = states
    if task is not None:  # the task the design was made for, as its task file says it
        if not isinstance(task, dict):
            raise InvalidTypeError(f"task must be a task document (a dict), got {task!r}")
        document["task"] = task
    return document


def _fabrication_fields(material, bed) -> dict:
    """The ``"material"`` and ``"bed"`` fields of the given records (none for None)."""
    from kinegami.fabrication.beds import Bed, Material

    fields = {}
    if material is not None:
        if not isinstance(material, Material):
            raise InvalidTypeError(f"material must be a Material or None, got {material!r}")
        fields["material"] = {"name": material.name, "thickness": float(material.thickness)}
    if bed is not None:
        if not isinstance(bed, Bed):
            raise InvalidTypeError(f"bed must be a Bed or None, got {bed!r}")
        fields["bed"] = {"width": float(bed.width), "height": float(bed.height),
                         "margin": float(bed.margin), "tab": float(bed.tab)}  # fmt: skip
    return fields


def _dumps(value, indent: str) -> str:
    """JSON with lists of plain values (matrix rows, vectors) on one line."""
    inner = indent + "  "
    if isinstance(value, dict):
        if not value:
            return "{}"
        items = [f"{inner}{json.dumps(k)}: {_dumps(v, inner)}" for k, v in value.items()]
        return "{\n" + ",\n".join(items) + "\n" + indent + "}"
    if isinstance(value, list):
        if all(not isinstance(v, dict | list) for v in value):
            return "[" + ", ".join(json.dumps(v, allow_nan=False) for v in value) + "]"
        items = [f"{inner}{_dumps(v, inner)}" for v in value]
        return "[\n" + ",\n".join(items) + "\n" + indent + "]"
    return json.dumps(value, allow_nan=False, ensure_ascii=False)


def dumps_design(document: dict) -> str:
    """A design document as JSON text (indent 2, one matrix row or vector per line)."""
    return _dumps(document, "") + "\n"


def save_design(
    chain: KinematicChain | KinematicTree,
    path: str | os.PathLike,
    *,
    name: str | None = None,
    description: str | None = None,
    units: str = "mm",
    twistPortion: float | None = None,
    task: dict | None = None,
    material=None,
    bed=None,
) -> Path:
    """Write ``chain`` (a chain or a tree) to the design file ``path`` (suffix .json)
    atomically; return the path.

    See :func:`design_to_dict` for the content. The document is checked against the format
    before it is written, and a failed write leaves no file and an existing one as it was
    (:func:`kinegami._atomic.write_atomic`).

    Examples
    --------
    >>> save_design(chain, "designs/arm.json", name="arm", units="mm")  # doctest: +SKIP
    PosixPath('designs/arm.json')
    """
    if not isinstance(path, str | os.PathLike) or isinstance(os.fspath(path), bytes):
        raise InvalidTypeError(f"path must be a str or a path, got {path!r}")
    target = Path(os.fspath(path)).expanduser()
    if target.suffix.lower() != ".json":
        raise InvalidParameterError(
            f"a design file name must end in .json, got {os.fspath(path)!r}"
        )
    if target.is_dir():
        raise InvalidParameterError(f"{os.fspath(path)!r} is a directory, not a file name")
    document = design_to_dict(
        chain, name=name, description=description, units=units, twistPortion=twistPortion,
        task=task, material=material, bed=bed,
    )  # fmt: skip
    text = dumps_design(document)
    try:
        check_document(json.loads(text))
    except DesignError as error:  # e.g. a pose drifted from rigid by > 1e-9 after many edits
        raise InvalidParameterError(f"the chain cannot be saved as a design: {error}") from None
    write_atomic(target, text)
    return target
