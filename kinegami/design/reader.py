"""Reading design files: parse, check (schema, then semantics) and build the chain or tree.

Building uses exactly the Python calls a user would type: ``KinematicChain(root,
maxAnglePerElbow=...)``, ``append(joint, relative, safe, fixedPosition, fixedOrientation)`` per
joint (or ``KinematicChain.from_dh`` for a DH table), the edit methods in order, then
``setJointStates``. A tree (version 2, :mod:`kinegami.design.trees`) is built the same way with
``KinematicTree(root, ...)`` and ``addJoint(parent, joint, ...)``, or by the tree construction
for a joint specification. A PlacementWarning or a rejected edit becomes a DesignError naming
``joints[i]`` or ``edits[i]``; nothing is printed. With ``"requireClearance": true`` the chain
is built with ``requireClearance=True``, so a placement, edit or state that makes it pass
through itself is rejected like any infeasible one (a DH design is checked once built). All
numeric work runs with numpy overflow, invalid and divide errors raised (see
:func:`~kinegami.design.errors.numeric_errors`), so a RuntimeWarning cannot be printed either.

Every chain built here is remembered (weakly) with the ``joints`` entry each of its joints
came from (:func:`origin_of`), so that joint names can be shown and saved.
"""

from __future__ import annotations

import json
import math
import os
import re
import stat
import warnings
import weakref
from dataclasses import dataclass
from typing import TYPE_CHECKING

from kinegami.chain.joints import (
    JOINT_KINDS,
)
from kinegami.chain.model import KinematicChain
from kinegami.design.errors import DesignError, json_path, numeric_errors
from kinegami.design.limits import (
    MAX_DEPTH,
    MAX_DH_ROWS,
    MAX_EDITS,
    MAX_FILE_BYTES,
    MAX_JOINTS,
    MAX_STATES,
    check_lengths,
    position_problem,
    too_deep,
    too_many,
)
from kinegami.design.poses import pose_from_json, to_radians
from kinegami.design.schema import (
    PLACEMENT_KEYS,
    VERSIONS,
    check_schema,
    check_top_level,
    schema_errors,
    version_problem,
)
from kinegami.design.task import task_from_dict
from kinegami.design.trees import (
    TreeSpecification,
    check_tree_fields,
    check_version_features,
    construct_tree,
    structure_of,
)
from kinegami.errors import ClearanceWarning, JointIndexError, KinegamiError, PlacementWarning
from kinegami.geometry.screws import REVOLUTE
from kinegami.tree import KinematicTree
from kinegami.validation import LENGTH_UNITS, UNITS_IN_MM, shorten, shown

if TYPE_CHECKING:  # pragma: no cover
    from kinegami.fabrication.beds import Bed, Material

__all__ = [
    "DesignInfo",
    "FORMAT",
    "fabrication_fields",
    "VERSIONS",
    "UNITS",
    "parse_design_text",
    "read_design_file",
    "check_document",
    "audit_document",
    "DesignProblem",
    "build_chain",
    "origin_of",
    "carry_origin",
    "DesignOrigin",
]

FORMAT = "kinegami-design"
UNITS = LENGTH_UNITS
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
    structure : ``"chain"`` or ``"tree"``: whether the design loads as a KinematicChain or a
        KinematicTree (version 2).
    task : the task block (kinegami design), or None.
    material : the sheet material (version 4, a :class:`~kinegami.fabrication.beds.Material`),
        or None.
    bed : the laser bed (version 4, a :class:`~kinegami.fabrication.beds.Bed`), or None.
    margin : the file's own ``"margin"`` (design units), None without one (then the chain's
        margin is the material's thickness, or 0).
    """

    name: str | None
    description: str | None
    units: str
    twistPortion: float
    file: str | None
    structure: str = "chain"
    task: dict | None = None
    material: Material | None = None
    bed: Bed | None = None
    margin: float | None = None

    @classmethod
    def of(cls, document: dict, file=None) -> DesignInfo:
        """The info of a checked design document."""
        material, bed = fabrication_fields(document)
        return cls(
            name=document.get("name"),
            description=document.get("description"),
            units=document.get("units", "mm"),
            twistPortion=float(document.get("twistPortion", DEFAULT_TWIST_PORTION)),
            file=None if file is None else os.fspath(file),
            structure=structure_of(document),
            task=document.get("task"),
            material=material,
            bed=bed,
            margin=float(document["margin"]) if "margin" in document else None,
        )


def fabrication_fields(document: dict, file=None) -> tuple[Material | None, Bed | None]:
    """The ``"material"`` and ``"bed"`` of a schema-valid design (version 4), checked: a
    known material's usual thickness when none is given (another needs one), a bed margin
    less than half the bed's shorter side. A DesignError names the field."""
    material = bed = None
    if "material" not in document and "bed" not in document:
        return None, None
    from kinegami.fabrication.beds import Bed, check_material

    if "material" in document:
        fields = document["material"]
        try:
            material = check_material(fields.get("name"), fields.get("thickness"))
        except KinegamiError as error:
            reason = str(error).removeprefix("thickness: ")
            where = "thickness" if "thickness" in str(error).split(" ")[0] else "name"
            raise DesignError(reason, field=f"material.{where}", file=file) from None
    if "bed" in document:
        fields = document["bed"]
        try:
            bed = Bed.of(fields.get("width"), fields.get("height"), fields.get("margin"),
                         fields.get("tab"))  # fmt: skip
        except KinegamiError as error:
            words = str(error).split(" ")
            where = "bed." + (words[1] if words[0] == "bed" else words[0])
            raise DesignError(str(error), field=where, file=file) from None
    return material, bed


def _margin_of(document: dict, material) -> float:
    """The chain's margin: the file's ``"margin"``, else the material's thickness in the
    design's units, else 0."""
    if "margin" in document:
        return float(document["margin"])
    if material is None:
        return 0.0
    return material.thickness / UNITS_IN_MM[document.get("units", "mm")]


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


class LongInteger:
    """An integer literal of a design with too many digits for ``int()`` (more than
    ``sys.get_int_max_str_digits()``, 4300 by default); the checks report it by its field."""

    __slots__ = ("digits", "negative")

    def __init__(self, literal: str):
        self.negative = literal.startswith("-")
        self.digits = len(literal) - self.negative

    def __repr__(self) -> str:
        sign = "a negative" if self.negative else "an"
        return f"<{sign} integer of {self.digits} digits>"


def _parse_int(literal: str):
    try:
        return int(literal)
    except ValueError:  # more digits than int() converts
        return LongInteger(literal)


_WHITESPACE = re.compile(r"[ \t\n\r]*")
#: Lists parsed one item at a time, so that an over-long one fails at its cap (JSON path ->
#: cap, what the items are).
_CAPPED = {
    ("joints",): (MAX_JOINTS, "joints", "MAX_JOINTS"),
    ("edits",): (MAX_EDITS, "edits", "MAX_EDITS"),
    ("states",): (MAX_STATES, "states", "MAX_STATES"),
    ("dh", "rows"): (MAX_DH_ROWS, "DH rows", "MAX_DH_ROWS"),
}
#: Objects parsed one member at a time (to reach the capped lists inside them).
_OPENED = {(), ("dh",)}


class _Parser:
    """JSON parsing of a design (the standard library's scanner does the work).

    The top-level object, ``dh`` and the capped lists are walked member by member, so that a
    list beyond its cap is rejected after reading at most cap + 1 items, however long the
    file. Integer literals too long for ``int()`` become :class:`LongInteger` (reported with
    their field by the checks); nesting deep enough to exhaust the parser's recursion is an
    error too.
    """

    def __init__(self, text: str, file):
        self.text = text
        self.file = file
        options = dict(object_pairs_hook=_object_pairs, parse_constant=float)
        self.scan_fast = json.JSONDecoder(**options).scan_once
        self.scan_long = json.JSONDecoder(**options, parse_int=_parse_int).scan_once

    def fail(self, message: str, pos: int):
        error = json.JSONDecodeError(message, self.text, pos)
        raise DesignError(
            f"invalid JSON at line {error.lineno}, column {error.colno}: {message}",
            file=self.file,
        )

    def skip(self, i: int) -> int:
        return _WHITESPACE.match(self.text, i).end()

    def document(self):
        if self.text.startswith("\ufeff"):
            self.fail("Unexpected UTF-8 BOM (decode using utf-8-sig)", 0)
        i = self.skip(0)
        value, i = self.value(i, ())
        i = self.skip(i)
        if i != len(self.text):
            self.fail("Extra data", i)
        return value

    def value(self, i: int, path: tuple):
        char = self.text[i : i + 1]
        if char == "{" and path in _OPENED:
            return self.object(i, path)
        if char == "[" and path in _CAPPED:
            return self.array(i, path)
        return self.scan(i, path)

    def scan(self, i: int, path: tuple):
        try:
            try:
                return self.scan_fast(self.text, i)
            except json.JSONDecodeError:
                raise
            except ValueError:  # an integer literal too long for int(): parse again
                return self.scan_long(self.text, i)
        except StopIteration as stop:
            self.fail("Expecting value", stop.value)
        except json.JSONDecodeError as error:
            self.fail(error.msg, error.pos)
        except RecursionError:
            raise DesignError(too_deep(), field=json_path(path), file=self.file) from None

    def object(self, i: int, path: tuple):
        text = self.text
        pairs = []
        i = self.skip(i + 1)
        if text[i : i + 1] == "}":
            return _object_pairs(pairs), i + 1
        while True:
            if text[i : i + 1] != '"':
                self.fail("Expecting property name enclosed in double quotes", i)
            try:
                key, i = json.decoder.scanstring(text, i + 1)
            except json.JSONDecodeError as error:
                self.fail(error.msg, error.pos)
            i = self.skip(i)
            if text[i : i + 1] != ":":
                self.fail("Expecting ':' delimiter", i)
            value, i = self.value(self.skip(i + 1), (*path, key))
            pairs.append((key, value))
            i = self.skip(i)
            char = text[i : i + 1]
            if char == "}":
                return _object_pairs(pairs), i + 1
            if char != ",":
                self.fail("Expecting ',' delimiter", i)
            i = self.skip(i + 1)

    def array(self, i: int, path: tuple):
        cap, what, name = _CAPPED[path]
        text = self.text
        items = []
        i = self.skip(i + 1)
        if text[i : i + 1] == "]":
            return items, i + 1
        while True:
            if len(items) == cap:
                raise DesignError(too_many(what, cap, name), field=json_path(path), file=self.file)
            value, i = self.scan(self.skip(i), (*path, len(items)))
            items.append(value)
            i = self.skip(i)
            char = text[i : i + 1]
            if char == "]":
                return items, i + 1
            if char != ",":
                self.fail("Expecting ',' delimiter", i)
            i += 1


def parse_design_text(text: str, file=None):
    """The JSON value of ``text``; DesignError on invalid JSON (with line and column).

    Also a DesignError: a list of joints, edits, states or DH rows beyond its cap
    (:mod:`kinegami.design.limits`; found while parsing, so a huge file fails fast) and nesting
    deeper than the parser can follow. Duplicate keys (remembered by the objects), nesting
    beyond MAX_DEPTH, non-finite numbers and integers beyond the float range (kept as
    :class:`LongInteger` when too long for ``int()``) are reported by :func:`check_document`.
    """
    if not isinstance(text, str):
        raise DesignError(
            f"the design must be JSON text (str), got {type(text).__name__}", file=file
        )
    return _Parser(text, file).document()


def _check_values(document, file, root: tuple = ()) -> None:
    """Nesting, keys and numbers of a parsed document, walked without recursion.

    Errors: nesting deeper than MAX_DEPTH (also catches a dict or list containing itself),
    duplicate and non-string keys, non-finite numbers (NaN, Infinity, 1e999), integers beyond
    the float range. Reported in document order, at the JSON path of the problem.
    """
    # entries: (node, depth, trail); a trail is (key, parent trail), built only on error
    stack = [(document, len(root) + 1, (root, None) if root else None)]
    while stack:
        node, depth, trail = stack.pop()
        if isinstance(node, dict | list | tuple):
            if depth > MAX_DEPTH:
                raise DesignError(too_deep(), field=_trail_path(trail), file=file)
            if isinstance(node, dict):
                for key in getattr(node, "duplicates", ()):
                    raise DesignError(
                        f"duplicate key '{shorten(key)}' (each key may appear once per "
                        "object)",
                        field=json_path([*_trail_parts(trail), key]),
                        file=file,
                    )
                for key in node:
                    if not isinstance(key, str):
                        raise DesignError(
                            f"object keys must be strings, got {shown(key)}",
                            field=_trail_path(trail),
                            file=file,
                        )
                items = node.items()
            else:
                items = enumerate(node)
            children = [
                (value, depth + 1, (key, trail))
                for key, value in items
                if isinstance(value, dict | list | tuple | float | int | LongInteger)
            ]
            stack.extend(reversed(children))
        elif isinstance(node, float):
            if not math.isfinite(node):
                raise DesignError(
                    "numbers must be finite: NaN, Infinity and numbers beyond +-1.8e308 "
                    "(such as 1e999) are not allowed",
                    field=_trail_path(trail),
                    value=node,
                    file=file,
                )
        elif isinstance(node, LongInteger) or (
            isinstance(node, int) and not isinstance(node, bool) and node.bit_length() > 1000
            and not _fits_float(node)
        ):
            raise DesignError(
                "number too large: numbers must be within +-1.8e308",
                field=_trail_path(trail),
                value=node,
                file=file,
            )


def _fits_float(value: int) -> bool:
    try:
        float(value)
    except OverflowError:
        return False
    return True


def _trail_parts(trail) -> list:
    parts = []
    while trail is not None:
        key, trail = trail
        if isinstance(key, tuple):  # the root path of a sub-walk
            parts.extend(reversed(key))
        else:
            parts.append(key)
    return parts[::-1]


def _trail_path(trail) -> str:
    return json_path(_trail_parts(trail))


def _file_kind(mode: int) -> str:
    for test, kind in (
        (stat.S_ISDIR, "a directory"),
        (stat.S_ISCHR, "a character device"),
        (stat.S_ISBLK, "a block device"),
        (stat.S_ISFIFO, "a FIFO (named pipe)"),
        (stat.S_ISSOCK, "a socket"),
    ):
        if test(mode):
            return kind
    return "a special file"


def _read_regular_file(name: str) -> bytes:
    """The bytes of the regular file ``name`` (at most MAX_FILE_BYTES); DesignError otherwise.

    Opened without blocking (a FIFO with no writer must not hang) and checked with fstat
    before reading, so devices such as /dev/zero are refused instead of read forever.
    """
    flags = os.O_RDONLY | getattr(os, "O_NONBLOCK", 0) | getattr(os, "O_BINARY", 0)
    try:
        fd = os.open(os.path.expanduser(name), flags)
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise DesignError(f"cannot read the design file: {reason}", file=name) from None
    limit = f"design files are at most {MAX_FILE_BYTES // 2**20} MiB ({MAX_FILE_BYTES} bytes)"
    try:
        info = os.fstat(fd)
        if not stat.S_ISREG(info.st_mode):
            raise DesignError(
                f"cannot read the design file: it is {_file_kind(info.st_mode)}, "
                "not a regular file",
                file=name,
            )
        if info.st_size > MAX_FILE_BYTES:
            raise DesignError(
                f"the design file is too large ({info.st_size} bytes); {limit}", file=name
            )
        with open(fd, "rb", closefd=False) as stream:
            data = stream.read(MAX_FILE_BYTES + 1)
    except OSError as exc:
        reason = exc.strerror or str(exc)
        raise DesignError(f"cannot read the design file: {reason}", file=name) from None
    finally:
        os.close(fd)
    if len(data) > MAX_FILE_BYTES:  # grew while being read, or a size-less special file
        raise DesignError(f"the design file is too large (more than {limit})", file=name)
    return data


def read_design_file(path) -> tuple[object, str]:
    """The JSON value of the design file at ``path`` and the file name (for messages).

    A file that is empty or holds only whitespace is a DesignError saying so (field ``$``).
    """
    if not isinstance(path, str | os.PathLike):
        raise DesignError(f"the design file name must be a str or a path, got {path!r}")
    name = os.fspath(path)
    if isinstance(name, bytes):
        raise DesignError(f"the design file name must be a str or a path, got {path!r}")
    data = _read_regular_file(name)
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise DesignError(
            f"the design file is not UTF-8 text (byte {exc.start}: {exc.reason})", file=name
        ) from None
    if _WHITESPACE.fullmatch(text):  # not "invalid JSON at line 1, column 1: Expecting value"
        what = "empty" if not text else "empty (only whitespace)"
        raise DesignError(
            f"the design file is {what}: a design is a JSON object {{...}} with "
            '"format": "kinegami-design" (\'kinegami new FILE\' writes a starter design)',
            file=name,
        )
    return parse_design_text(text, name), name


# --- checks ----------------------------------------------------------------------------------
def _check_header(document, file) -> None:
    if not isinstance(document, dict):
        raise DesignError(
            'a design must be a JSON object {...} with "format": "kinegami-design"',
            value=document,
            file=file,
        )
    for key in document.duplicates if isinstance(document, _Object) else ():
        raise DesignError(
            f"duplicate key '{shorten(key)}' (each key may appear once per object)",
            field=json_path([key]),
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
            version_problem(version),
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
    edits: list  # (method name, args, kwargs); a joint is an index or a name until applied
    states: list | None
    names: tuple = ()  # the "name" of every entry of "joints" (None where it has none)
    require_clearance: bool = False  # the design's "requireClearance"
    margin: float = 0.0  # the design's "margin" (version 3), else its material's thickness
    tree: bool = False  # build a KinematicTree (version 2)
    parents: tuple = ()  # per entry of "joints", the entry it is added to (-1: the root)
    specification: TreeSpecification | None = None  # a joint specification to construct


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
    cls = JOINT_KINDS[kind]
    fields = {key: to_radians(value, units) if key in cls.design_angles else value
              for key, value in spec.items()}  # fmt: skip
    try:
        with numeric_errors(json_path(path), file):
            return cls.from_design(numSides, r, pose, fields)
    except DesignError:
        raise
    except KinegamiError as error:
        raise _library_error(error, path, set(spec), file) from None


def _check_joint_order(joints, file, chain: bool = True) -> None:
    """The order of a chain's joint types (a tree's: :func:`check_tree_fields`) and the
    placement options of every joint."""
    last = len(joints) - 1
    for i, spec in enumerate(joints):
        kind = spec["type"]
        where = json_path(["joints", i, "type"])
        if chain and kind == "StartTip" and i > 0:
            raise DesignError(
                "a StartTip can only be the first joint (joints[0])",
                field=where, value=kind, file=file,
            )  # fmt: skip
        if chain and kind == "EndTip" and i == 0:
            raise DesignError(
                "the first joint (the root) cannot be an EndTip: nothing may follow an EndTip",
                field=where, value=kind, file=file,
            )  # fmt: skip
        if chain and kind == "EndTip" and i < last:
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


def _listed(names, limit: int = 10) -> str:
    listed = ", ".join(f"'{shorten(name)}'" for name in names[:limit])
    return listed + (f", ... ({len(names)} names)" if len(names) > limit else "")


def _check_names(document: dict, file) -> tuple:
    """The joint names (unique) and the names edits refer to (existing); the names per entry."""
    names = []
    seen: dict[str, int] = {}
    for i, spec in enumerate(document.get("joints", ())):
        name = spec.get("name")
        if name is not None:
            if name in seen:
                raise DesignError(
                    f"duplicate joint name: joints[{seen[name]}] is also named '{shorten(name)}' "
                    "(names must be unique, edits refer to joints by name)",
                    field=json_path(["joints", i, "name"]),
                    value=name,
                    file=file,
                )
            seen[name] = i
        names.append(name)
    for i, spec in enumerate(document.get("edits", ())):
        ref = spec.get("joint")
        if not isinstance(ref, str) or ref in seen:
            continue
        if "dh" in document:
            reason = "a DH design has no joint names: refer to its joints by index"
        elif seen:
            reason = (
                f"no joint is named '{shorten(ref)}'; the joint names are {_listed(list(seen))}"
            )
        else:
            reason = (
                f"no joint is named '{shorten(ref)}': no entry of 'joints' has a \"name\" "
                "(add one, or use the index in the built chain)"
            )
        raise DesignError(reason, field=json_path(["edits", i, "joint"]), value=ref, file=file)
    return tuple(names)


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
    """Check a parsed design (header, schema, bounds, semantics) without building the chain.

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


#: Top-level fields checked only after the cheap ones (their size is capped first).
_BULKY = ("joints", "dh", "edits", "states")


def _check_document(document, file) -> _Plan:
    # cheap checks first: the header, then the small top-level fields and the sizes of the
    # bulky ones, so that a huge design with a wrong "units" fails in no time
    _check_header(document, file)
    for key, value in document.items():
        if key not in _BULKY or not isinstance(value, dict if key == "dh" else list):
            _check_values(value, file, root=(key,))  # small, or a wrong type (walked whole)
    dh = document.get("dh")
    if isinstance(dh, dict):
        for key, value in dh.items():
            if key != "rows" or not isinstance(value, list):
                _check_values(value, file, root=("dh", key))
    check_top_level(document, file)
    check_version_features(document, file)
    _check_values(document, file)
    check_schema(document, file)
    check_lengths(document, file)
    material, _ = fabrication_fields(document, file)
    if "task" in document:  # the task the design was made for (kinegami design)
        task = task_from_dict(document["task"], file, where=("task",))
        if task.is_tree and structure_of(document) != "tree":
            raise DesignError("a tree task (joints given per leaf) is for a tree design; this "
                              "design is a chain", field="task.joints", file=file)  # fmt: skip
    names = _check_names(document, file)
    fields = check_tree_fields(document, file)
    units = document.get("angleUnits", "rad")
    numSides = int(document["numSides"])
    r = float(document["r"])
    chain_options = {}
    if "maxAnglePerElbow" in document:
        chain_options["maxAnglePerElbow"] = to_radians(document["maxAnglePerElbow"], units)
    joints = []
    dh = None
    specification = None
    if "joints" in document:
        specs = document["joints"]
        _check_joint_order(specs, file, chain=not fields.tree)
        for i, spec in enumerate(specs):
            joint = _make_joint(spec, i, numSides, r, units, file)
            options = {key: spec[key] for key in PLACEMENT_KEYS if key in spec}
            joints.append((joint, options))
        if fields.specification:
            specification = TreeSpecification.of(
                document,
                [joint for joint, _ in joints],
                fields.parents,
                [spec.get("relative", True) for spec in specs],
                names,
                lambda angle: to_radians(angle, units),
            )
    else:
        dh = _plan_dh(document["dh"], units)
    edits = _plan_edits(document.get("edits", []), units)
    states = document.get("states")
    return _Plan(
        numSides, r, units, chain_options, joints, dh, edits, states, names,
        require_clearance=document.get("requireClearance", False),
        margin=_margin_of(document, material),
        tree=fields.tree, parents=fields.parents, specification=specification,
    )  # fmt: skip


# --- every problem at once ------------------------------------------------------------------
@dataclass(frozen=True)
class DesignProblem:
    """One problem of a design file: ``code`` says which check found it (``file``,
    ``header``, ``value``, ``top-level``, ``version``, ``schema``, ``lengths``, ``names``,
    ``tree``, ``joint-order``, ``joint``, ``dh``, ``edits``, ``design``; ``build`` for what
    only building finds), ``error`` is the DesignError that check raises (its ``field`` is the
    JSON path, ``str(error)`` the one-line message)."""

    code: str
    error: DesignError

    @property
    def field(self) -> str:
        return self.error.field

    def __str__(self) -> str:
        return str(self.error)


def audit_document(document, file=None) -> list[DesignProblem]:
    """Every problem :func:`check_document` can find in a parsed design, not only the first
    (empty: the design passes :func:`check_document`).

    The checks run in stages, as check_document runs them: the header; the values (numbers
    too large, nesting too deep), the top-level fields and the version; the schema (one
    problem per JSON location); then the checks the schema cannot express (lengths, names,
    tree fields, the joints one by one, the joint order, a DH table, the edits). A stage runs
    only when the stages before it found nothing, since its checks assume what they check.
    The first problem is always the one check_document raises.
    """
    try:  # a valid design (the usual case) is checked once
        check_document(document, file)
        return []
    except DesignError as error:
        first = error
    problems: list[DesignProblem] = []

    def add(code: str, error: DesignError) -> None:
        if error.file is None and file is not None:
            error = error.with_file(file)
        if all(str(error) != str(known) for known in problems):
            problems.append(DesignProblem(code, error))

    def attempt(code: str, check, *args):
        try:
            return True, check(*args)
        except DesignError as error:
            add(code, error)
            return False, None

    if attempt("header", _check_header, document, file)[0]:
        for key, value in document.items():
            attempt("value", _check_values, value, file, (key,))
        attempt("top-level", check_top_level, document, file)
        attempt("version", check_version_features, document, file)
        if not problems:
            for error in schema_errors(document, file):
                add("schema", error)
        if not problems:
            _audit_semantics(document, file, attempt)
    # the problem check_document reports comes first
    at = next((k for k, p in enumerate(problems) if str(p) == str(first)), None)
    problems.insert(0, DesignProblem("design", first) if at is None else problems.pop(at))
    return problems


def _audit_semantics(document: dict, file, attempt) -> None:
    """The checks the schema cannot express, each through ``attempt(code, check, *args)``
    (:func:`audit_document`); the document is schema-valid."""
    units = document.get("angleUnits", "rad")
    numSides, r = int(document["numSides"]), float(document["r"])
    attempt("lengths", check_lengths, document, file)
    attempt("fabrication", fabrication_fields, document, file)
    attempt("names", _check_names, document, file)
    ok, fields = attempt("tree", check_tree_fields, document, file)
    if "joints" in document:
        specs = document["joints"]
        if ok:
            attempt("joint-order", _check_joint_order, specs, file, not fields.tree)
        for i, spec in enumerate(specs):
            attempt("joint", _make_joint, spec, i, numSides, r, units, file)
    else:
        attempt("dh", _plan_dh, document["dh"], units)
    attempt("edits", _plan_edits, document.get("edits", []), units)


# --- where the joints of a built chain come from ---------------------------------------------
@dataclass(frozen=True)
class DesignOrigin:
    """Where each joint of a chain built from a design came from.

    Attributes
    ----------
    kind : ``"joints"`` or ``"dh"``, how the design gave the chain.
    sources : per joint of the built chain, the index of its entry in the design's ``joints``
        list, or None for a waypoint added by safe placement (and for every joint of a DH
        design).
    names : per joint of the built chain, the ``name`` of its entry (None if it has none).
    types : the joints' type names when built (a chain whose joints no longer have these
        types, e.g. after a Python ``delete``, has no known origin).
    file : the design file (None for a design given as text or a dict without a file name).
    """

    kind: str
    sources: tuple
    names: tuple
    types: tuple
    file: str | None = None


_ORIGINS: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _type_names(chain: KinematicChain) -> tuple:
    return tuple(type(joint).__name__ for joint in chain.Joints)


def origin_of(chain: KinematicChain) -> DesignOrigin | None:
    """The :class:`DesignOrigin` of a chain built from a design, or None.

    None when ``chain`` was not built by the design loader, or when its joints have changed
    type since (joints were deleted or appended in Python). Edits that keep the joints, such
    as ``setJointState`` or ``transformJoint``, keep the origin.
    """
    origin = _ORIGINS.get(chain)
    if origin is None or origin.types != _type_names(chain):
        return None
    return origin


def carry_origin(source: KinematicChain, target: KinematicChain) -> DesignOrigin | None:
    """Give ``target`` the origin (joint names, design entries) of ``source`` and return it.

    For a chain or tree made from a loaded one with the same joints in the same order (a
    tree whose children :func:`kinegami.fabrication.sheets.fit_junctions` slid), every joint takes
    the origin of its counterpart, waypoints included. When only the joints apart from
    waypoints match (:func:`kinegami.optimize.compact`: waypoints may move, appear or
    disappear), each non-waypoint joint takes the origin of the matching joint of ``source``
    and waypoints have none. None (and nothing remembered) when ``source`` has no origin or
    the non-waypoint joints do not match by type.
    """
    origin = origin_of(source)
    if origin is None:
        return None
    if tuple(origin.types) == _type_names(target):  # the same joints: names for every one
        _ORIGINS[target] = origin
        return origin
    kept = [i for i, joint in enumerate(source.Joints) if joint.has_body]
    others = [i for i, joint in enumerate(target.Joints) if joint.has_body]
    if [origin.types[i] for i in kept] != [type(target.Joints[i]).__name__ for i in others]:
        return None
    sources = [None] * len(target.Joints)
    names = [None] * len(target.Joints)
    for i, k in zip(others, kept, strict=True):
        sources[i], names[i] = origin.sources[k], origin.names[k]
    carried = DesignOrigin(origin.kind, tuple(sources), tuple(names), _type_names(target),
                           origin.file)  # fmt: skip
    _ORIGINS[target] = carried
    return carried


# --- building --------------------------------------------------------------------------------
def _recorded(call, where: str, file, clearance_errors: bool = False):
    """Run ``call()`` with PlacementWarnings recorded, not shown; (result, last message).

    Numeric errors (overflow, NaN) and RuntimeWarnings become DesignErrors at ``where``; so
    does a ClearanceWarning when ``clearance_errors`` (a design requiring clearance).
    """
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always", PlacementWarning)
        warnings.simplefilter("always", RuntimeWarning)
        with numeric_errors(where, file):
            result = call()
    messages = []
    for w in caught:
        if issubclass(w.category, PlacementWarning):
            messages.append(str(w.message))
        elif issubclass(w.category, RuntimeWarning):
            raise DesignError(f"numeric problem: {w.message}", field=where, file=file)
        elif clearance_errors and issubclass(w.category, ClearanceWarning):
            text = str(w.message)
            required = _REQUIRED.replace("a chain", "a tree") if "the tree" in text else _REQUIRED
            raise DesignError(f"{text}{required}", field=where, file=file)
        else:  # not ours to swallow
            warnings.warn_explicit(w.message, w.category, w.filename, w.lineno)
    return result, (messages[-1] if messages else None)


#: Said after a rejection that only requireClearance makes an error.
_REQUIRED = ' ("requireClearance": true rejects a chain that passes through itself)'


def _reason(message: str | None, plan: _Plan, default: str) -> str:
    """The rejection message of a placement, edit or states, saying when requireClearance
    is why."""
    if not message:
        return default
    if plan.require_clearance and "pass through itself" in message:
        return message + (_REQUIRED.replace("a chain", "a tree") if plan.tree else _REQUIRED)
    return message


def _build_from_joints(plan: _Plan, file) -> tuple[KinematicChain | KinematicTree, list]:
    root, _ = plan.joints[0]
    options = dict(plan.chain_options, requireClearance=plan.require_clearance,
                   margin=plan.margin)  # fmt: skip
    kind = KinematicTree if plan.tree else KinematicChain
    try:
        chain, _ = _recorded(lambda: kind(root, **options), json_path(["joints", 0]), file)
    except DesignError:
        raise
    except KinegamiError as error:
        raise _library_error(error, ["joints", 0], set(), file) from None
    sources = [0]
    for i, (joint, options) in enumerate(plan.joints[1:], start=1):
        where = json_path(["joints", i])
        if plan.tree:  # the parent entry's joint, wherever placement put it
            parent = sources.index(plan.parents[i])
            add = lambda j=joint, o=options, p=parent: chain.addJoint(p, j, **o)  # noqa: E731
        else:
            add = lambda j=joint, o=options: chain.append(j, **o)  # noqa: E731
        try:
            index, message = _recorded(add, where, file)
        except DesignError:
            raise
        except KinegamiError as error:
            raise _library_error(error, ["joints", i], set(PLACEMENT_KEYS), file) from None
        if index is None:
            call = "addJoint" if plan.tree else "append"
            raise DesignError(
                f"infeasible placement of the {type(joint).__name__}: "
                f"{_reason(message, plan, f'{call} returned None')}",
                field=where,
                file=file,
            )
        # safe placement inserts waypoints before the new joint
        sources.extend([None] * (index - len(sources)))
        sources.append(i)
    return chain, sources


def _build_from_specification(plan: _Plan, file) -> tuple[KinematicTree, list]:
    """The tree construction on the plan's joint specification (kinegami.design.trees)."""
    try:
        (tree, sources), _ = _recorded(
            lambda: construct_tree(plan.specification, file),
            "placement",
            file,
            clearance_errors=plan.require_clearance,
        )
    except DesignError:
        raise
    except KinegamiError as error:
        message = str(error)
        field = "placement"
        if message.startswith("growth_direction") and plan.specification.growth_direction:
            field = "placement.growthDirection"
        raise DesignError(
            f"the tree construction failed: {message}", field=field, file=file
        ) from None
    tree.margin = plan.margin
    if plan.require_clearance:
        from kinegami.clearance.tree_bodies import tree_worst_overlap

        found = tree_worst_overlap(tree.Joints, tree.Links, tree.Parents, tree.r,
                                   margin=plan.margin)  # fmt: skip
        if found is not None:
            raise DesignError(
                f"the tree of the joint specification passes through itself ({found})"
                f"{_REQUIRED.replace('a chain', 'a tree')}",
                field="placement",
                file=file,
            )
        tree.requireClearance = True
    return tree, list(sources)


def _build_from_dh(plan: _Plan, file) -> tuple[KinematicChain, list]:
    options = dict(plan.dh)
    table = options.pop("table")
    options.update(plan.chain_options)
    names = set(options) | {"table", "convention", "jointTypes"}
    try:
        chain, _ = _recorded(
            lambda: KinematicChain.from_dh(table, plan.numSides, plan.r, **options),
            "dh",
            file,
            clearance_errors=plan.require_clearance,
        )
    except DesignError:
        raise
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
    chain.margin = plan.margin
    if plan.require_clearance:
        from kinegami.chain.bodies import worst_overlap

        found = worst_overlap(chain.Joints, chain.Links, chain.r, margin=plan.margin)
        if found is not None:  # placement warns only when it adds an overlap
            raise DesignError(
                f"the chain of the DH table passes through itself ({found}){_REQUIRED}",
                field="dh",
                file=file,
            )
        chain.requireClearance = True
    return chain, [None] * len(chain)


def _edit_index(ref, plan: _Plan, sources: list, deleted: dict, where, file) -> int:
    """The built-chain index an edit's ``joint`` (an index or a name) refers to now."""
    if not isinstance(ref, str):
        return int(ref)
    entry = plan.names.index(ref)  # the names were checked by check_document
    if entry in sources:
        return sources.index(entry)
    raise DesignError(
        f"joint '{shorten(ref)}' (joints[{entry}]) is no longer in the chain: "
        f"edits[{deleted[entry]}] deleted it",
        field=json_path([*where, "joint"]),
        value=ref,
        file=file,
    )


def _noun(chain) -> str:
    return "tree" if isinstance(chain, KinematicTree) else "chain"


def _apply_edits(chain: KinematicChain, plan: _Plan, file, sources: list) -> None:
    deleted: dict[int, int] = {}  # entry of "joints" -> the edit that deleted it
    for i, (op, args, kwargs) in enumerate(plan.edits):
        where = ["edits", i]
        if "joint" in _ARGUMENTS[op]:
            args = (_edit_index(args[0], plan, sources, deleted, where, file), *args[1:])
        if op == "setJointState":
            index, state = args
            if -len(chain) <= index < len(chain) and chain.Joints[index].motion == REVOLUTE:
                args = (index, to_radians(state, plan.angle_units))
        try:
            ok, message = _recorded(
                lambda op=op, a=args, k=kwargs: getattr(chain, op)(*a, **k), json_path(where), file
            )
        except DesignError:
            raise
        except JointIndexError:
            n = len(chain)
            raise DesignError(
                f"no such joint: the {_noun(chain)} has {n} joints at this edit (indices {-n} to "
                f"{n - 1})",
                field=json_path([*where, "joint"]), value=args[0], file=file,
            ) from None  # fmt: skip
        except KinegamiError as error:
            raise _library_error(error, where, set(_ARGUMENTS[op]), file) from None
        if not ok:
            raise DesignError(
                f"infeasible edit {op}: "
                f"{_reason(message, plan, f'the {_noun(chain)} rejected it')}",
                field=json_path(where),
                file=file,
            )
        if op == "delete":
            entry = sources.pop(args[0] % (len(chain) + 1))
            if entry is not None:
                deleted[entry] = i


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
            f"must have one state per joint of the {_noun(chain)} after the edits: {len(joints)} "
            f"({kinds}; safe placement adds waypoints); it has {len(states)}",
            field="states",
            value=states,
            file=file,
        )
    values = []
    for k, (joint, state) in enumerate(zip(joints, states, strict=True)):
        if joint.motion == REVOLUTE:
            state = to_radians(state, plan.angle_units)
        state = float(state)
        lo, hi = joint.stateRange()
        if not lo <= state <= hi:
            unit = "radians" if joint.motion == REVOLUTE else "length units"
            raise DesignError(
                f"state of joint {k} ({type(joint).__name__}) outside its range "
                f"[{lo!r}, {hi!r}] ({unit})",
                field=json_path(["states", k]),
                value=states[k],
                file=file,
            )
        values.append(state)
    ok, message = _recorded(lambda: chain.setJointStates(values), "states", file)
    if not ok:  # ranges were checked above: the chain requires clearance
        raise DesignError(
            f"infeasible states: {_reason(message, plan, f'the {_noun(chain)} rejected them')}",
            field="states",
            file=file,
        )


def build_plan(plan: _Plan, file=None) -> tuple[KinematicChain | KinematicTree, DesignOrigin]:
    """Execute a plan of :func:`check_document`; the chain (or tree) and where its joints came
    from."""
    if plan.dh is not None:
        chain, sources = _build_from_dh(plan, file)
    elif plan.specification is not None:
        chain, sources = _build_from_specification(plan, file)
    else:
        chain, sources = _build_from_joints(plan, file)
    _apply_edits(chain, plan, file, sources)
    if plan.states is not None:
        _apply_states(chain, plan, file)
    far = position_problem(chain)
    if far is not None:  # steps within the bounds that add up beyond them (docs/limits.md)
        i, reason = far
        source = sources[i] if i < len(sources) else None
        where = "dh" if plan.dh is not None else ("$" if source is None else f"joints[{source}]")
        raise DesignError(f"out of range: {reason}", field=where, file=file)
    origin = DesignOrigin(
        kind="dh" if plan.dh is not None else "joints",
        sources=tuple(sources),
        names=tuple(None if k is None else plan.names[k] for k in sources),
        types=_type_names(chain),
        file=None if file is None else os.fspath(file),
    )
    _ORIGINS[chain] = origin
    return chain, origin


def build_chain(plan: _Plan, file=None) -> KinematicChain | KinematicTree:
    """Execute a plan of :func:`check_document`: place, edit, set states."""
    return build_plan(plan, file)[0]
