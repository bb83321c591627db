"""The JSON Schema of design files (schema.json) and its errors turned into DesignErrors.

jsonschema finds every violation; :func:`check_schema` reports the first one in document order
(ties: the most basic keyword first) as a one-line :class:`DesignError` naming the JSON path,
the value and what is allowed.
"""

from __future__ import annotations

import difflib
import functools
import json
from importlib import resources

import jsonschema

from kinegami.chain.joints import JOINT_KINDS
from kinegami.design.errors import DesignError, format_value, json_path
from kinegami.design.limits import (
    MAX_DH_ROWS,
    MAX_EDITS,
    MAX_JOINTS,
    MAX_POSE_STEPS,
    MAX_STATES,
    NUM_LAYERS_MAX,
    NUM_SIDES_MAX,
    NUM_SINK_LAYERS_MAX,
    too_many,
)
from kinegami.validation import shorten, shown

__all__ = ["design_schema", "check_schema", "JOINT_TYPES", "EDIT_OPS", "PLACEMENT_KEYS"]

#: The joint types design files know: the registered joint kinds (kinegami.chain.joints).
JOINT_TYPES = tuple(JOINT_KINDS)
EDIT_OPS = (
    "translateJointAlongAxisOfMotion",
    "rotateJointAboutAxisOfMotion",
    "transformJoint",
    "transformAll",
    "delete",
    "setJointState",
)
PLACEMENT_KEYS = ("relative", "safe", "fixedPosition", "fixedOrientation")
#: Keys the root joint cannot have (it is placed by its global pose and has no parent).
ROOT_FORBIDDEN = (*PLACEMENT_KEYS, "parent")

#: Valid ranges of numeric fields as the messages state them (radians / degrees for angles).
_LENGTH = "> 0 and <= 1e6 r (1e6 times the tube radius)"
_COORDINATE = "within +-1e6 r (1e6 times the tube radius)"
_RANGES = {
    "numSides": f"an even integer in [4, {NUM_SIDES_MAX}]",
    "r": "in [1e-6, 1e6] (file length units)",
    "twistPortion": "in [0, 1)",
    "length": _LENGTH,
    "tubeLength": _LENGTH,
    "neutralLength": _LENGTH,
    "tipLength": _LENGTH,
    "numSinkLayers": f"an integer in [1, {NUM_SINK_LAYERS_MAX}]",
    "numLayers": f"an integer in [1, {NUM_LAYERS_MAX}]",
    "pathIndex": "0, 1 or 2",
}
_ANGLE_RANGES = {
    "maxAnglePerElbow": {"rad": "in [pi/180, pi] radians", "deg": "in [1, 180] degrees"},
    "totalBendingAngle": {"rad": "in (0, 2pi) radians", "deg": "in (0, 360) degrees"},
    "coneAngle": {"rad": "in [pi/6, pi/2) radians", "deg": "in [30, 90) degrees"},
}
_TYPE_NAMES = {
    "number": "a number",
    "integer": "an integer",
    "string": "a string",
    "boolean": "true or false",
    "object": "an object {...}",
    "array": "a list [...]",
    "null": "null",
}
_POSE_TEXT = (
    "a pose: a 4x4 matrix (list of 4 rows), a list of steps such as "
    '[{"Trans": [x, y, z]}, {"Ry": angle}], or an axis object {"point", "axis", "xhat"}'
)
#: Capped lists: JSON path -> (what the items are, the name of the cap in limits).
_CAPS = {
    ("joints",): ("joints", "MAX_JOINTS"),
    ("edits",): ("edits", "MAX_EDITS"),
    ("states",): ("states", "MAX_STATES"),
    ("dh", "rows"): ("DH rows", "MAX_DH_ROWS"),
}
_CAP_VALUES = {
    "MAX_JOINTS": MAX_JOINTS,
    "MAX_EDITS": MAX_EDITS,
    "MAX_STATES": MAX_STATES,
    "MAX_DH_ROWS": MAX_DH_ROWS,
}
#: Keyword order among several errors at the same place (most basic first).
_PRIORITY = {
    "type": 0,
    "additionalProperties": 1,  # before "required": a typo also makes a key go missing
    "propertyNames": 2,
    "required": 3,
    "const": 4,
    "enum": 4,
    "minProperties": 5,
    "maxProperties": 5,
    "minItems": 6,
    "maxItems": 6,
}


#: What a joint's ``parent`` may be.
_PARENT_TEXT = (
    "must be the joint this one is added to: the index of an earlier entry of 'joints' (an "
    "integer from 0) or its name (a string); a design has one root, joints[0], so a later "
    "joint cannot be a root (leave 'parent' out to follow the previous entry)"
)


#: The versions of the format this kinegami reads (3 adds ``"margin"``, 4 ``"material"`` and
#: ``"bed"``).
VERSIONS = (1, 2, 3, 4)


def version_problem(version) -> str:
    """Why ``version`` (the value of a design's ``"version"``, not one of :data:`VERSIONS`) is
    refused, in words: newer than this kinegami reads, or not a version at all."""
    supported = ", ".join(map(str, VERSIONS))
    if isinstance(version, int) and not isinstance(version, bool) and version > max(VERSIONS):
        return (f"version {version} is newer than this kinegami reads (versions {supported}); "
                "upgrade kinegami to read it")  # fmt: skip
    return f"unsupported version; supported versions: {supported}"


def _version_2_field(document) -> str:
    for key in ("structure", "placement"):
        if isinstance(document, dict) and key in document:
            return f"'{key}' (a field of version 2)"
    return "a field of version 2"


def design_schema() -> dict:
    """The JSON Schema (draft 2020-12) of design files, as a dict: schema.json as shipped, plus
    an entry for every joint kind registered since (kinegami.chain.joints.register_joint_kind;
    its fields are those of its ``design_defaults``)."""
    return _schema_of(tuple(JOINT_KINDS))


@functools.cache
def _schema_of(kinds: tuple[str, ...]) -> dict:
    """The schema with the joint kinds ``kinds`` (read once per set of kinds)."""
    text = resources.files("kinegami.design").joinpath("schema.json").read_text("utf-8")
    schema = json.loads(text)
    _add_registered_kinds(schema)
    return schema


def _add_registered_kinds(schema: dict) -> None:
    """Add the joint kinds the shipped schema does not describe (a kind a user registered)."""
    defs = schema["$defs"]
    joint = defs["joint"]
    for name, kind in JOINT_KINDS.items():
        if name in defs:
            continue
        joint["properties"]["type"]["enum"].append(name)
        properties = dict(defs["Waypoint"]["properties"])  # type, name, pose, placement keys
        properties.pop("pathIndex", None)
        for key, value in kind.design_defaults(1.0).items():
            properties[key] = {"type": "integer" if isinstance(value, int) else "number"}
        defs[name] = {"properties": properties, "additionalProperties": False}
        joint["allOf"].append({
            "if": {"required": ["type"], "properties": {"type": {"const": name}}},
            "then": {"$ref": f"#/$defs/{name}"},
        })  # fmt: skip


def _validator() -> jsonschema.Draft202012Validator:
    return _validator_of(tuple(JOINT_KINDS))


@functools.cache
def _validator_of(kinds: tuple[str, ...]) -> jsonschema.Draft202012Validator:
    """The validator of the schema with the joint kinds ``kinds`` (registered ones included)."""
    return jsonschema.Draft202012Validator(design_schema())


#: Parts of the schema that describe bulky content: the top-level check keeps only these (the
#: full check validates their items; their caps are checked without jsonschema, whose
#: messages contain the whole list).
_SIZE_KEYWORDS = ("type", "minItems")


#: Top-level keywords of the schema the top-level check leaves out (``dependentSchemas``: the
#: version-2 fields, which :func:`kinegami.design.trees.check_version_features` checks).
_NOT_TOP_LEVEL = ("properties", "then", "else", "dependentSchemas")


@functools.cache
def _top_level_validator() -> jsonschema.Draft202012Validator:
    """A validator of the top-level fields only: every small field as in the full schema, the
    type of ``joints``, ``edits``, ``states`` and ``dh.rows``, nothing inside them."""
    full = design_schema()
    defs = full["$defs"]
    properties = {}
    for key, schema in full["properties"].items():
        if key in ("joints", "edits", "states"):
            schema = {k: v for k, v in schema.items() if k in _SIZE_KEYWORDS}
        elif key == "dh":
            rows = defs["dh"]["properties"]["rows"]
            schema = {
                "type": "object",
                "properties": {"rows": {k: v for k, v in rows.items() if k in _SIZE_KEYWORDS}},
            }
        properties[key] = schema
    angle = {
        units: {"properties": {"maxAnglePerElbow": defs[name]["properties"]["maxAnglePerElbow"]}}
        for units, name in (("deg", "angleRangesDeg"), ("rad", "angleRangesRad"))
    }
    top = {
        **{k: v for k, v in full.items() if k not in _NOT_TOP_LEVEL},
        "properties": properties,
        "then": angle["deg"],
        "else": angle["rad"],
    }
    return jsonschema.Draft202012Validator(top)


def check_top_level(document, file=None) -> None:
    """Raise a DesignError for the first problem of the top-level fields of ``document``.

    Cheap whatever the size of the design: it checks the small fields (format, version,
    units, numSides, r, ...) and only the type and length of the joints, edits, states and
    DH rows (at most :data:`~kinegami.design.limits.MAX_JOINTS` joints, and so on), not what
    they contain (:func:`check_schema` does). ``document`` must not nest deeper than
    MAX_DEPTH outside those lists (jsonschema's messages recurse).
    """
    _first_error(_top_level_validator(), document, file)
    for path, (what, name) in _CAPS.items():
        node = document
        for key in path:
            node = node.get(key) if isinstance(node, dict) else None
        cap = _CAP_VALUES[name]
        if isinstance(node, list) and len(node) > cap:
            reason = too_many(what, cap, name, len(node))
            raise DesignError(reason, field=json_path(path), file=file)
    for key, field in (("joints", "pose"), ("edits", "transform")):
        entries = document.get(key)
        for i, entry in enumerate(entries if isinstance(entries, list) else ()):
            steps = entry.get(field) if isinstance(entry, dict) else None
            if isinstance(steps, list) and len(steps) > MAX_POSE_STEPS:
                reason = too_many("pose steps", MAX_POSE_STEPS, "MAX_POSE_STEPS", len(steps))
                raise DesignError(reason, field=json_path([key, i, field]), file=file)


def _position(document, path) -> tuple:
    """Document-order sort key of a JSON path (positions of keys in their objects)."""
    key = []
    node = document
    for part in path:
        if isinstance(node, dict):
            keys = list(node)
            key.append(keys.index(part) if part in keys else len(keys))
            node = node.get(part)
        elif isinstance(node, list) and isinstance(part, int) and 0 <= part < len(node):
            key.append(part)
            node = node[part]
        else:
            key.append(0)
            node = None
    return tuple(key)


def check_schema(document, file=None) -> None:
    """Raise a DesignError for the first schema violation of ``document`` (if any)."""
    _first_error(_validator(), document, file)


def _first_error(validator, document, file) -> None:
    errors = list(validator.iter_errors(document))
    if not errors:
        return
    raise translate(min(errors, key=lambda e: _rank(document, e)), document, file)


def _rank(document, error) -> tuple:
    """Which of several schema errors to report first: the earliest in the document, then
    the most telling keyword, then the most specific schema rule."""
    return (_position(document, error.absolute_path), _PRIORITY.get(error.validator, 9),
            len(error.absolute_schema_path))  # fmt: skip


def schema_errors(document, file=None) -> list[DesignError]:
    """Every schema violation of ``document``, one per JSON location (the one
    :func:`check_schema` would report there), in document order."""
    best: dict[tuple, object] = {}
    for error in _validator().iter_errors(document):
        where = tuple(error.absolute_path)
        if where not in best or _rank(document, error) < _rank(document, best[where]):
            best[where] = error
    ordered = sorted(best.values(), key=lambda e: _rank(document, e))
    return [translate(error, document, file) for error in ordered]


def _angle_units(document) -> str:
    units = document.get("angleUnits") if isinstance(document, dict) else None
    return units if units in ("rad", "deg") else "rad"


def _range_text(name, document, schema=None) -> str | None:
    defs = design_schema()["$defs"]
    if schema is not None and schema == defs["coordinate"]:
        return _COORDINATE
    if schema is not None and schema == defs["length"]:
        return _LENGTH
    if name in _ANGLE_RANGES:
        return _ANGLE_RANGES[name][_angle_units(document)]
    return _RANGES.get(name)


def _quoted(values) -> str:
    return ", ".join(json.dumps(v) if not isinstance(v, str) else f"'{v}'" for v in values)


def translate(error: jsonschema.ValidationError, document, file=None) -> DesignError:
    """One jsonschema error as a DesignError with path, value and what is allowed."""
    path = list(error.absolute_path)
    field = json_path(path)
    name = path[-1] if path and isinstance(path[-1], str) else None
    keyword = error.validator
    expected = error.validator_value
    value = error.instance

    def fail(reason, where=field, **kw):
        return DesignError(reason, field=where, file=file, **kw)

    if keyword == "required":
        missing = [k for k in expected if k not in value]
        key = missing[0] if missing else expected[0]
        where = json_path([*path, key])
        if key == "type":
            return fail(f"missing required field 'type' (one of: {', '.join(JOINT_KINDS)})", where)
        if key == "op":
            return fail(f"missing required field 'op' (one of: {', '.join(EDIT_OPS)})", where)
        return fail(f"missing required field '{key}'", where)
    if keyword == "type":
        if name in ("pose", "transform"):
            return fail(f"must be {_POSE_TEXT}", value=value)
        if name == "joint" and len(path) == 3 and path[0] == "edits":
            return fail(
                "must be a joint index (an integer) or a joint name (a string)", value=value
            )
        if name == "parent" and len(path) == 3 and path[0] == "joints":
            return fail(_PARENT_TEXT, value=value)
        kinds = expected if isinstance(expected, list) else [expected]
        what = " or ".join(_TYPE_NAMES.get(k, k) for k in kinds)
        text = _range_text(name, document) if set(kinds) & {"number", "integer"} else None
        if text is not None and name != "pathIndex":
            what = text if text.startswith(("a ", "an ")) else f"{what} {text}"
        return fail(f"must be {what}", value=value)
    if keyword == "enum":
        if name == "type" and len(path) >= 2 and path[0] == "joints":
            return fail(
                f"unknown joint type {shown(value)}; known: {', '.join(JOINT_KINDS)}", value=value
            )
        if name == "op":
            known = ", ".join(EDIT_OPS)
            return fail(f"unknown edit op {shown(value)}; known: {known}", value=value)
        if path == ["version"] and error.validator_value == [2, 3, 4]:  # a version-2 field
            return fail(f"{_version_2_field(document)} needs \"version\": 2 (or 3 or 4)",
                        value=value)  # fmt: skip
        if path == ["version"] and error.validator_value == [3, 4]:  # a field of version 3
            return fail("'margin' (a field of version 3) needs \"version\": 3 (or 4)",
                        value=value)  # fmt: skip
        if path == ["version"]:
            return fail(version_problem(value), value=value)
        return fail(f"must be one of {_quoted(expected)}", value=value)
    if keyword == "const":
        if path == ["format"]:
            return fail("not a kinegami design: format must be 'kinegami-design'", value=value)
        if path == ["version"] and error.validator_value == 4:  # a field of version 4
            key = next((k for k in ("material", "bed") if k in document), "material")
            return fail(f"'{key}' (a field of version 4) needs \"version\": 4", value=value)
        if path == ["placement", "method"]:
            return fail(f"unknown placement method {shown(value)}; known: wafr2024", value=value)
        return fail(f"must be {format_value(expected)}", value=value)
    if keyword == "minimum" and name == "parent":
        return fail(_PARENT_TEXT, value=value)
    if keyword in ("minimum", "maximum", "exclusiveMinimum", "exclusiveMaximum", "multipleOf"):
        text = _range_text(name, document, error.schema)
        if text is None:
            text = {
                "minimum": ">=",
                "maximum": "<=",
                "exclusiveMinimum": ">",
                "exclusiveMaximum": "<",
                "multipleOf": "a multiple of",
            }[keyword] + f" {format_value(expected)}"
        return fail(f"out of range: must be {text}", value=value)
    if keyword == "maxItems" and tuple(path) in _CAPS:
        what, name = _CAPS[tuple(path)]
        return fail(too_many(what, expected, name, len(value)))
    if keyword == "maxItems" and len(path) >= 2 and path[-1] in ("pose", "transform"):
        return fail(too_many("pose steps", expected, "MAX_POSE_STEPS", len(value)))
    if keyword in ("minItems", "maxItems"):
        low = error.schema.get("minItems")
        high = error.schema.get("maxItems")
        if low == high == 3:
            what = "must be 3 numbers [x, y, z]"
        elif low == high == 4 and "rows" in path:
            what = "a DH row must have 4 numbers [theta, alpha, a, d]"
        elif low == high == 4:
            what = "a 4x4 matrix must have 4 rows of 4 numbers"
        elif keyword == "minItems":
            what = f"must have at least {low} item{'s' if low != 1 else ''}"
        else:
            what = f"must have at most {high} items"
        return fail(f"{what}; it has {len(value)}", value=value)
    if keyword == "additionalProperties":
        allowed = list(error.schema.get("properties", {}))
        if path and path[0] == "joints" and len(path) == 2 and path[1] == 0:
            allowed = [k for k in allowed if k not in ROOT_FORBIDDEN]
        unknown = [k for k in value if k not in allowed and k not in ROOT_FORBIDDEN]
        unknown = unknown or [k for k in value if k not in error.schema.get("properties", {})]
        listed = ", ".join(allowed)
        if len(unknown) == 1:
            close = difflib.get_close_matches(unknown[0], allowed, n=1)
            hint = f" (did you mean '{close[0]}'?)" if close else ""
            return fail(
                f"unknown key '{shorten(unknown[0])}'{hint}; allowed keys: {listed}",
                json_path([*path, unknown[0]]),
            )
        names = ", ".join(f"'{shorten(k)}'" for k in unknown[:5])
        names += f", ... ({len(unknown)} keys)" if len(unknown) > 5 else ""
        return fail(f"unknown keys {names}; allowed keys: {listed}")
    if keyword == "propertyNames" or "propertyNames" in error.absolute_schema_path:
        if value == "parent":
            return fail(
                "the root joint (joints[0]) cannot have a 'parent': a design has one root, "
                "and every later joint has a parent (default: the previous entry)",
                json_path([*path, value]),
            )
        return fail(
            f"the root joint cannot have '{value}': its pose is global and "
            f"{', '.join(PLACEMENT_KEYS)} apply only to the joints appended after it",
            json_path([*path, value]),
        )
    if keyword in ("minProperties", "maxProperties"):
        keys = ", ".join(error.schema.get("properties", {}))
        return fail(f"a pose step must have exactly one key, one of: {keys}", value=value)
    if keyword == "oneOf" and not path:
        if "joints" in value and "dh" in value:
            return fail("give exactly one of 'joints' and 'dh', not both")
        return fail("missing required field: one of 'joints' (a list) or 'dh' (a DH table)")
    if keyword == "minLength" and name in ("joint", "parent"):
        return fail("a joint name must not be empty", value=value)
    if keyword == "pattern" and name == "jointTypes":
        return fail('must be a string of the letters R and P (e.g. "RRP")', value=value)
    return fail(shorten(error.message, 200), value=value)
