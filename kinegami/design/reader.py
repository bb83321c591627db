"""Reading design files: parse, check (schema, then semantics) and build the chain.

Building uses exactly the Python calls a user would type: ``KinematicChain(root,
maxAnglePerElbow=...)``, ``append(joint, relative, safe, fixedPosition, fixedOrientation)`` per
joint (or ``KinematicChain.from_dh`` for a DH table), the edit methods in order, then
``setJointStates``. A PlacementWarning or a rejected edit becomes a DesignError naming
``joints[i]`` or ``edits[i]``; nothing is printed.
"""

from __future__ import annotations

import json
import math
import os
import warnings
from dataclasses import dataclass
from pathlib import Path

from kinegami.chain import KinematicChain, PlacementWarning
from kinegami.design.errors import DesignError, json_path
from kinegami.design.poses import pose_from_json, to_radians
from kinegami.design.schema import PLACEMENT_KEYS, check_schema
from kinegami.errors import JointIndexError, KinegamiError
from kinegami.joints import (
    EndTip,
    ExtendedRevoluteJoint,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)

__all__ = [
    "DesignInfo",
    "FORMAT",
    "VERSIONS",
    "UNITS",
    "parse_design_text",
    "read_design_file",
    "check_document",
    "build_chain",
]

FORMAT = "kinegami-design"
VERSIONS = (1,)
UNITS = ("mm", "cm", "m", "in")
DEFAULT_TWIST_PORTION = 0.2


@dataclass(frozen=True)
class DesignInfo:
    """What a design file says besides the chain (for exporters and the command line).

    Attributes
    ----------
    name, description : the optional texts of the file (None when absent).
    units : the length unit of every length in the file (and of the chain): mm, cm, m or in.
    twistPortion : share of each link's straight part given to its twist (crease pattern).
    file : the design file (None for a design given as text or a dict).
    """

    name: str | None
    description: str | None
    units: str
    twistPortion: float
    file: str | None

    @classmethod
    def of(cls, document: dict, file=None) -> DesignInfo:
        """The info of a checked design document."""
        return cls(
            name=document.get("name"),
            description=document.get("description"),
            units=document.get("units", "mm"),
            twistPortion=float(document.get("twistPortion", DEFAULT_TWIST_PORTION)),
            file=None if file is None else os.fspath(file),
        )


# --- parsing ---------------------------------------------------------------------------------
class _Object(dict):
    """A JSON object remembering the keys it saw more than once."""

    duplicates: tuple = ()


def _object_pairs(pairs):
    obj = _Object()
    duplicates = []
    for key, value in pairs:
        if key in obj and key not in duplicates:
            duplicates.append(key)
        obj[key] = value
    obj.duplicates = tuple(duplicates)
    return obj


def parse_design_text(text: str, file=None):
    """The JSON value of ``text``; DesignError on invalid JSON (with line and column)."""
    if not isinstance(text, str):
        raise DesignError(
            f"the design must be JSON text (str), got {type(text).__name__}", file=file
        )
    try:
        document = json.loads(
            text, object_pairs_hook=_object_pairs, parse_constant=lambda name: float(name)
        )
    except json.JSONDecodeError as exc:
        raise DesignError(
            f"invalid JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}", file=file
        ) from None
    except RecursionError:
        raise DesignError("invalid JSON: nested too deeply", file=file) from None
    _check_values(document, [], file)
    return document


def _check_values(node, path, file) -> None:
    """Duplicate keys and non-finite numbers (NaN, Infinity, 1e999) are errors."""
    if isinstance(node, dict):
        for key in getattr(node, "duplicates", ()):
            raise DesignError(
                f"duplicate key '{key}' (each key may appear once per object)",
                field=json_path([*path, key]),
                file=file,
            )
        for key, value in node.items():
            if not isinstance(key, str):
                raise DesignError(
                    f"object keys must be strings, got {key!r}", field=json_path(path), file=file
                )
            _check_values(value, [*path, key], file)
    elif isinstance(node, list | tuple):
        for i, value in enumerate(node):
            _check_values(value, [*path, i], file)
    elif isinstance(node, float):
        if not math.isfinite(node):
            raise DesignError(
                "numbers must be finite (NaN and Infinity are not valid JSON)",
                field=json_path(path),
                value=node,
                file=file,
            )
    elif isinstance(node, int) and not isinstance(node, bool):
        try:
            float(node)
        except OverflowError:
            raise DesignError(
                "number too large", field=json_path(path), value=node, file=file
            ) from None


def read_design_file(path) -> tuple[object, str]:
    """The JSON value of the design file at ``path`` and the file name (for messages)."""
    if not isinstance(path, str | os.PathLike):
        raise DesignError(f"the design file name must be a str or a path, got {path!r}")
    name = os.fspath(path)
    if isinstance(name, bytes):
        raise DesignError(f"the design file name must be a str or a path, got {path!r}")
    try:
        data = Path(name).expanduser().read_bytes()
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise DesignError(f"cannot read the design file: {reason}", file=name) from None
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise DesignError(
            f"the design file is not UTF-8 text (byte {exc.start}: {exc.reason})", file=name
        ) from None
    return parse_design_text(text, name), name


# --- checks ----------------------------------------------------------------------------------
def _check_header(document, file) -> None:
    if not isinstance(document, dict):
        raise DesignError(
            'a design must be a JSON object {...} with "format": "kinegami-design"',
            value=document,
            file=file,
        )
    if "format" not in document:
        raise DesignError(
            "missing required field 'format' (not a kinegami design?): it must be "
            '"kinegami-design"',
            field="format",
            file=file,
        )
    if document["format"] != FORMAT:
        raise DesignError(
            f"not a kinegami design: format must be '{FORMAT}'",
            field="format",
            value=document["format"],
            file=file,
        )
    supported = ", ".join(map(str, VERSIONS))
    if "version" not in document:
        raise DesignError(
            f"missing required field 'version' (supported versions: {supported})",
            field="version",
            file=file,
        )
    version = document["version"]
    if isinstance(version, bool) or version not in VERSIONS:
        raise DesignError(
            f"unsupported version; supported versions: {supported}",
            field="version",
            value=version,
            file=file,
        )


@dataclass
class _Plan:
    """A checked design turned into Python objects, ready for the chain calls."""

    numSides: int
    r: float
    angle_units: str
    chain_options: dict
    joints: list  # (Joint, append options) per entry of "joints"
    dh: dict | None  # keyword arguments of from_dh
    edits: list  # (method name, args, kwargs); setJointState angles converted when applied
    states: list | None


#: Top-level fields that library messages may name.
_TOP_LEVEL = ("numSides", "r", "maxAnglePerElbow")


def _library_error(error: Exception, path, names, file) -> DesignError:
    """A library error as a DesignError at ``path``, or at the field its message starts with
    (kinegami messages start with the parameter name: "totalBendingAngle must lie in ...")."""
    message = str(error)
    first = message.split(" ", 1)[0]
    field = list(path)
    if first in _TOP_LEVEL:
        field = [first]
    elif first in names:
        field = [*path, first]
    return DesignError(message, field=json_path(field), file=file)


def _make_joint(spec: dict, i: int, numSides: int, r: float, units: str, file):
    kind = spec["type"]
    path = ["joints", i]
    pose = pose_from_json(spec.get("pose", []), [*path, "pose"], units)
    angle = {
        key: to_radians(spec[key], units)
        for key in ("totalBendingAngle", "coneAngle")
        if key in spec
    }
    try:
        if kind in ("StartTip", "EndTip"):
            cls = StartTip if kind == "StartTip" else EndTip
            return cls(numSides, r, Pose=pose, length=spec["length"])
        if kind == "RevoluteJoint":
            return RevoluteJoint(
                numSides, r, angle["totalBendingAngle"], pose, spec.get("numSinkLayers", 1)
            )
        if kind == "ExtendedRevoluteJoint":
            return ExtendedRevoluteJoint(
                numSides,
                r,
                angle["totalBendingAngle"],
                spec["tubeLength"],
                pose,
                spec.get("numSinkLayers", 1),
            )
        if kind == "PrismaticJoint":
            return PrismaticJoint(
                numSides, r, spec["neutralLength"], spec["numLayers"], angle["coneAngle"], pose
            )
        return Waypoint(numSides, r, pose, spec.get("pathIndex", 2))
    except KinegamiError as error:
        raise _library_error(error, path, set(spec), file) from None


def _check_joint_order(joints, file) -> None:
    last = len(joints) - 1
    for i, spec in enumerate(joints):
        kind = spec["type"]
        where = json_path(["joints", i, "type"])
        if kind == "StartTip" and i > 0:
            raise DesignError(
                "a StartTip can only be the first joint (joints[0])",
                field=where, value=kind, file=file,
            )  # fmt: skip
        if kind == "EndTip" and i == 0:
            raise DesignError(
                "the first joint (the root) cannot be an EndTip: nothing may follow an EndTip",
                field=where, value=kind, file=file,
            )  # fmt: skip
        if kind == "EndTip" and i < last:
            raise DesignError(
                f"an EndTip must be the last joint (joints[{last}]): nothing may follow it",
                field=where, value=kind, file=file,
            )  # fmt: skip
        if i == 0:
            continue
        safe = spec.get("safe", True)
        for key in ("fixedPosition", "fixedOrientation"):
            if safe and spec.get(key, False):
                raise DesignError(
                    'true requires "safe": false (safe placement moves and turns the joint)',
                    field=json_path(["joints", i, key]),
                    value=True,
                    file=file,
                )


def _plan_edits(edits, units: str) -> list:
    plan = []
    for i, spec in enumerate(edits):
        op = spec["op"]
        path = ["edits", i]
        kwargs = {}
        if op == "transformAll":
            args = (pose_from_json(spec["transform"], [*path, "transform"], units),)
        elif op == "transformJoint":
            args = (
                spec["joint"],
                pose_from_json(spec["transform"], [*path, "transform"], units),
            )
        elif op == "translateJointAlongAxisOfMotion":
            args = (spec["joint"], float(spec["distance"]))
        elif op == "rotateJointAboutAxisOfMotion":
            args = (spec["joint"], to_radians(spec["angle"], units))
        elif op == "delete":
            args = (spec["joint"],)
        else:  # setJointState: the unit of the state depends on the joint (at apply time)
            args = (spec["joint"], float(spec["state"]))
        for key in ("propagate", "applyToPreviousWaypoint"):
            if key in spec:
                kwargs[key] = spec[key]
        plan.append((op, args, kwargs))
    return plan


def _plan_dh(dh: dict, units: str) -> dict:
    rows = [
        [to_radians(theta, units), to_radians(alpha, units), float(a), float(d)]
        for theta, alpha, a, d in dh["rows"]
    ]
    options = {"table": rows}
    for key in ("convention", "jointTypes", "placement", "numSinkLayers", "numLayers", "endTip"):
        if key in dh:
            options[key] = dh[key]
    for key in ("neutralLength", "tipLength"):
        if key in dh:
            options[key] = float(dh[key])
    for key in ("totalBendingAngle", "coneAngle"):
        if key in dh:
            options[key] = to_radians(dh[key], units)
    return options


def check_document(document, file=None) -> _Plan:
    """Check a parsed design (header, schema, semantics) without building the chain.

    Returns the plan :func:`build_chain` executes. Joints are constructed (they check their
    own parameters) but nothing is placed, so infeasible placements, edits and states are only
    found by :func:`build_chain`.
    """
    try:
        return _check_document(document, file)
    except DesignError as error:
        if error.file is None and file is not None:
            raise error.with_file(file) from None
        raise


def _check_document(document, file) -> _Plan:
    _check_values(document, [], file)
    _check_header(document, file)
    check_schema(document, file)
    units = document.get("angleUnits", "rad")
    numSides = int(document["numSides"])
    r = float(document["r"])
    chain_options = {}
    if "maxAnglePerElbow" in document:
        chain_options["maxAnglePerElbow"] = to_radians(document["maxAnglePerElbow"], units)
    joints = []
    dh = None
    if "joints" in document:
        specs = document["joints"]
        _check_joint_order(specs, file)
        for i, spec in enumerate(specs):
            joint = _make_joint(spec, i, numSides, r, units, file)
            options = {key: spec[key] for key in PLACEMENT_KEYS if key in spec}
            joints.append((joint, options))
    else:
        dh = _plan_dh(document["dh"], units)
    edits = _plan_edits(document.get("edits", []), units)
    states = document.get("states")
    return _Plan(numSides, r, units, chain_options, joints, dh, edits, states)


# --- building --------------------------------------------------------------------------------
def _recorded(call):
    """Run ``call()`` with PlacementWarnings recorded, not shown; (result, last message)."""
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PlacementWarning)
        result = call()
    messages = []
    for w in caught:
        if issubclass(w.category, PlacementWarning):
            messages.append(str(w.message))
        else:  # not ours to swallow
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return result, (messages[-1] if messages else None)


def _build_from_joints(plan: _Plan, file) -> KinematicChain:
    root, _ = plan.joints[0]
    try:
        chain = KinematicChain(root, **plan.chain_options)
    except KinegamiError as error:
        raise _library_error(error, ["joints", 0], set(), file) from None
    for i, (joint, options) in enumerate(plan.joints[1:], start=1):
        where = json_path(["joints", i])
        try:
            index, message = _recorded(lambda j=joint, o=options: chain.append(j, **o))
        except KinegamiError as error:
            raise _library_error(error, ["joints", i], set(PLACEMENT_KEYS), file) from None
        if index is None:
            raise DesignError(
                f"infeasible placement of the {type(joint).__name__}: "
                f"{message or 'append returned None'}",
                field=where,
                file=file,
            )
    return chain


def _build_from_dh(plan: _Plan, file) -> KinematicChain:
    options = dict(plan.dh)
    table = options.pop("table")
    options.update(plan.chain_options)
    names = set(options) | {"table", "convention", "jointTypes"}
    try:
        chain, _ = _recorded(
            lambda: KinematicChain.from_dh(table, plan.numSides, plan.r, **options)
        )
    except KinegamiError as error:
        message = str(error)
        first = message.split(" ", 1)[0]
        if first == "maxAnglePerElbow":
            field = first
        elif first in names:
            field = "dh.rows" if first == "table" else f"dh.{first}"
        else:
            field = "dh"
        raise DesignError(message, field=field, file=file) from None
    return chain


def _apply_edits(chain: KinematicChain, plan: _Plan, file) -> None:
    for i, (op, args, kwargs) in enumerate(plan.edits):
        where = ["edits", i]
        if "joint" in _ARGUMENTS[op]:
            args = (int(args[0]), *args[1:])
        if op == "setJointState":
            index, state = args
            if -len(chain) <= index < len(chain) and isinstance(chain.Joints[index], RevoluteJoint):
                args = (index, to_radians(state, plan.angle_units))
        try:
            ok, message = _recorded(lambda op=op, a=args, k=kwargs: getattr(chain, op)(*a, **k))
        except JointIndexError:
            n = len(chain)
            raise DesignError(
                f"no such joint: the chain has {n} joints at this edit (indices {-n} to {n - 1})",
                field=json_path([*where, "joint"]), value=args[0], file=file,
            ) from None  # fmt: skip
        except KinegamiError as error:
            raise _library_error(error, where, set(_ARGUMENTS[op]), file) from None
        if not ok:
            raise DesignError(
                f"infeasible edit {op}: {message or 'the chain rejected it'}",
                field=json_path(where),
                file=file,
            )


_ARGUMENTS = {
    "translateJointAlongAxisOfMotion": ("joint", "distance"),
    "rotateJointAboutAxisOfMotion": ("joint", "angle"),
    "transformJoint": ("joint", "transform"),
    "transformAll": ("transform",),
    "delete": ("joint",),
    "setJointState": ("joint", "state"),
}


def _apply_states(chain: KinematicChain, plan: _Plan, file) -> None:
    states = plan.states
    joints = chain.Joints
    if len(states) != len(joints):
        kinds = ", ".join(type(j).__name__ for j in joints)
        raise DesignError(
            f"must have one state per joint of the chain after the edits: {len(joints)} "
            f"({kinds}; safe placement adds waypoints); it has {len(states)}",
            field="states",
            value=states,
            file=file,
        )
    values = []
    for k, (joint, state) in enumerate(zip(joints, states, strict=True)):
        if isinstance(joint, RevoluteJoint):
            state = to_radians(state, plan.angle_units)
        state = float(state)
        lo, hi = joint.stateRange()
        if not lo <= state <= hi:
            unit = "radians" if isinstance(joint, RevoluteJoint) else "length units"
            raise DesignError(
                f"state of joint {k} ({type(joint).__name__}) outside its range "
                f"[{lo!r}, {hi!r}] ({unit})",
                field=json_path(["states", k]),
                value=states[k],
                file=file,
            )
        values.append(state)
    ok, message = _recorded(lambda: chain.setJointStates(values))
    if not ok:  # pragma: no cover - ranges were checked above
        raise DesignError(f"infeasible states: {message}", field="states", file=file)


def build_chain(plan: _Plan, file=None) -> KinematicChain:
    """Execute a plan of :func:`check_document`: place, edit, set states."""
    if plan.dh is not None:
        chain = _build_from_dh(plan, file)
    else:
        chain = _build_from_joints(plan, file)
    _apply_edits(chain, plan, file)
    if plan.states is not None:
        _apply_states(chain, plan, file)
    return chain
