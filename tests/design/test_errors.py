"""Broken design files: one-line DesignErrors naming the field, the value and what is allowed."""

from __future__ import annotations

import copy
import json
import pickle
import warnings
from pathlib import Path

import pytest

from kinegami.design import (
    DesignError,
    chain_from_dict,
    load_design,
    loads_design,
    read_design,
    validate_design,
)
from kinegami.errors import KinegamiError

from . import DATA, located

BASE = json.loads((DATA / "example1a.json").read_text(encoding="utf-8"))
JOINT_TYPES = "StartTip, EndTip, RevoluteJoint, ExtendedRevoluteJoint, PrismaticJoint, Waypoint"


def _mutated(change) -> dict:
    document = copy.deepcopy(BASE)
    change(document)
    return document


def _write(folder: Path, document, name: str = "design.json") -> Path:
    path = folder / name
    text = document if isinstance(document, str) else json.dumps(document, indent=2)
    path.write_text(text, encoding="utf-8")
    return path


def _error_of(folder: Path, document, check=load_design) -> DesignError:
    path = _write(folder, document)
    before = sorted(p.name for p in folder.iterdir())
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no warning may escape
        with pytest.raises(DesignError) as info:
            check(path)
    assert sorted(p.name for p in folder.iterdir()) == before  # nothing written
    error = info.value
    text = str(error)
    assert "\n" not in text and "Traceback" not in text and 'File "' not in text
    assert text.startswith(f"{path}: {located(error)}{error.reason}")
    assert error.file == str(path)
    return error


def _drop(key):
    return lambda d: d.pop(key)


def _set(key, value):
    return lambda d: d.update({key: value})


def _joint(i, key, value):
    return lambda d: d["joints"][i].update({key: value})


# (change, field, value, fragments of the reason that say what is allowed)
SCHEMA_CASES = {
    "missing numSides": (_drop("numSides"), "numSides", None, ["missing required field"]),
    "missing r": (_drop("r"), "r", None, ["missing required field 'r'"]),
    "r as string": (_set("r", "1.0"), "r", '"1.0"', ["must be a number in [1e-6, 1e6]"]),
    "numSides 2": (_set("numSides", 2), "numSides", "2", ["even integer in [4, 64]"]),
    "numSides odd": (_set("numSides", 5), "numSides", "5", ["even integer in [4, 64]"]),
    "numSides float": (_set("numSides", 4.5), "numSides", "4.5", ["even integer in [4, 64]"]),
    "r negative": (_set("r", -1), "r", "-1", ["in [1e-6, 1e6]"]),
    "r zero": (_set("r", 0), "r", "0", ["in [1e-6, 1e6]"]),
    "bending 7 rad": (
        _joint(2, "totalBendingAngle", 7),
        "joints[2].totalBendingAngle",
        "7",
        ["(0, 2pi) radians"],
    ),
    "bending 0": (
        _joint(2, "totalBendingAngle", 0),
        "joints[2].totalBendingAngle",
        "0",
        ["(0, 2pi) radians"],
    ),
    "bending 400 deg": (
        lambda d: (
            d.update(angleUnits="deg")
            or d["joints"][1].update(coneAngle=45)
            or d["joints"][2].update(totalBendingAngle=400)
        ),
        "joints[2].totalBendingAngle",
        "400",
        ["(0, 360) degrees"],
    ),
    "cone angle too small": (
        _joint(1, "coneAngle", 0.1),
        "joints[1].coneAngle",
        "0.1",
        ["[pi/6, pi/2) radians"],
    ),
    "numLayers 0": (_joint(1, "numLayers", 0), "joints[1].numLayers", "0", ["in [1, 200]"]),
    "length negative": (_joint(0, "length", -2), "joints[0].length", "-2", ["> 0"]),
    "pathIndex 3": (
        lambda d: d["joints"].insert(1, {"type": "Waypoint", "pathIndex": 3}),
        "joints[1].pathIndex",
        "3",
        ["0, 1, 2"],
    ),
    "maxAnglePerElbow 4": (
        _set("maxAnglePerElbow", 4),
        "maxAnglePerElbow",
        "4",
        ["[pi/180, pi] radians"],
    ),
    "twistPortion 1": (_set("twistPortion", 1), "twistPortion", "1", ["[0, 1)"]),
    "units": (_set("units", "km"), "units", '"km"', ["'mm', 'cm', 'm', 'in'"]),
    "angleUnits": (_set("angleUnits", "grad"), "angleUnits", '"grad"', ["'rad', 'deg'"]),
    "unknown joint type": (
        _joint(2, "type", "Foo"),
        "joints[2].type",
        '"Foo"',
        ["unknown joint type 'Foo'", f"known: {JOINT_TYPES}"],
    ),
    "missing joint type": (
        lambda d: d["joints"][2].pop("type"),
        "joints[2].type",
        None,
        ["missing required field 'type'", JOINT_TYPES],
    ),
    "missing joint parameter": (
        lambda d: d["joints"][2].pop("totalBendingAngle"),
        "joints[2].totalBendingAngle",
        None,
        ["missing required field 'totalBendingAngle'"],
    ),
    "typo numSide": (
        lambda d: d.update(numSide=d.pop("numSides")),
        "numSide",
        None,
        ["unknown key 'numSide'", "allowed keys: format, version, name", "numSides, r"],
    ),
    "typo in a joint": (
        _joint(2, "numSinkLayer", 2),
        "joints[2].numSinkLayer",
        None,
        ["unknown key 'numSinkLayer'", "totalBendingAngle, numSinkLayers"],
    ),
    "placement key on the root": (
        _joint(0, "relative", True),
        "joints[0].relative",
        None,
        ["root joint cannot have 'relative'"],
    ),
    "flag not boolean": (_joint(1, "safe", "no"), "joints[1].safe", '"no"', ["true or false"]),
    "version 5": (_set("version", 5), "version", "5",
                  ["version 5 is newer than this kinegami", "reads (versions 1, 2, 3, 4)",
                   "upgrade kinegami"]),
    "version 0": (_set("version", 0), "version", "0", ["supported versions: 1, 2, 3, 4"]),
    "version true": (_set("version", True), "version", "true",
                     ["supported versions: 1, 2, 3, 4"]),
    "missing version": (_drop("version"), "version", None, ["supported versions: 1, 2, 3, 4"]),
    "material in version 3": (lambda d: d.update(version=3, material={"name": "PET"}),
                              "material", None,
                              ["'material' is a field of version 4", 'write "version": 4']),
    "bed in version 1": (_set("bed", {"width": 600, "height": 400}), "bed", None,
                         ["'bed' is a field of version 4", 'write "version": 4']),
    "unknown material without thickness": (
        lambda d: d.update(version=4, material={"name": "kapton"}), "material.thickness", None,
        ["give the thickness of kapton in mm"]),
    "material too thick": (lambda d: d.update(version=4, material={"name": "PET", "thickness": 12}),
                           "material.thickness", "12", ["<= 10"]),
    "bed margin too wide": (
        lambda d: d.update(version=4, bed={"width": 600, "height": 40, "margin": 20}),
        "bed.margin", None, ["less than half the bed's shorter side (20 mm", "got 20"]),
    "bed without height": (lambda d: d.update(version=4, bed={"width": 600}), "bed.height", None,
                           ["missing required field 'height'"]),
    "margin in version 1": (_set("margin", 0.5), "margin", None,
                            ["'margin' is a field of version 3", 'write "version": 3']),
    "negative margin": (lambda d: d.update(version=3, margin=-0.5), "margin", "-0.5",
                        [">= 0"]),
    "margin not a number": (lambda d: d.update(version=3, margin="0.2"), "margin", '"0.2"',
                            ["must be a number"]),
    "format": (
        _set("format", "kinegami"),
        "format",
        '"kinegami"',
        ["format must be 'kinegami-design'"],
    ),
    "missing format": (_drop("format"), "format", None, ["kinegami-design"]),
    "joints and dh": (
        _set("dh", {"rows": [[0, 0, 0, 1]]}),
        "$",
        None,
        ["exactly one of 'joints' and 'dh'"],
    ),
    "neither joints nor dh": (_drop("joints"), "$", None, ["'joints'", "'dh'"]),
    "empty joints": (_set("joints", []), "joints", "[]", ["at least 1 item"]),
    "matrix with 3 rows": (
        _joint(1, "pose", [[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]),
        "joints[1].pose",
        "[[1, 0, 0, 0], [0, 1, 0, 0], [0, 0, 1, 0]]",
        ["4 rows of 4 numbers"],
    ),
    "pose of wrong type": (
        _joint(1, "pose", "up"),
        "joints[1].pose",
        '"up"',
        ["4x4 matrix", "list of steps", "axis object"],
    ),
    "unknown step": (
        _joint(1, "pose", [{"Trans": [1, 2, 3]}, {"Roll": 1}]),
        "joints[1].pose[1].Roll",
        None,
        ["unknown key 'Roll'", "allowed keys: Trans, Tx, Ty, Tz, Rx, Ry, Rz"],
    ),
    "step with two keys": (
        _joint(1, "pose", [{"Rx": 1, "Ry": 2}]),
        "joints[1].pose[0]",
        '{"Rx": 1, "Ry": 2}',
        ["exactly one key", "Trans, Tx, Ty, Tz, Rx, Ry, Rz"],
    ),
    "Trans with 2 numbers": (
        _joint(1, "pose", [{"Trans": [1, 2]}]),
        "joints[1].pose[0].Trans",
        "[1, 2]",
        ["3 numbers"],
    ),
    "unknown edit op": (
        _set("edits", [{"op": "explode", "joint": 1}]),
        "edits[0].op",
        '"explode"',
        ["unknown edit op 'explode'", "translateJointAlongAxisOfMotion", "setJointState"],
    ),
    "edit missing argument": (
        _set("edits", [{"op": "delete"}]),
        "edits[0].joint",
        None,
        ["missing required field 'joint'"],
    ),
    "edit unknown key": (
        _set("edits", [{"op": "delete", "joint": 1, "propagate": True}]),
        "edits[0].propagate",
        None,
        ["unknown key 'propagate'", "allowed keys: op, joint"],
    ),
    "state not a number": (_set("states", [0, "x"]), "states[1]", '"x"', ["a number"]),
}


@pytest.mark.parametrize("case", list(SCHEMA_CASES))
def test_schema_errors(tmp_path, case):
    change, field, value, allowed = SCHEMA_CASES[case]
    error = _error_of(tmp_path, _mutated(change), validate_design)
    assert error.field == field
    text = str(error)
    if value is None:
        assert "(got" not in text
    else:
        assert text.endswith(f"(got {value})"), text
    for fragment in allowed:
        assert fragment in error.reason, (fragment, text)
    # loading reports the same problem
    assert str(_error_of(tmp_path, _mutated(change))) == text


SEMANTIC_CASES = {
    "non-rigid matrix": (
        _joint(1, "pose", [[1, 0, 0, 5], [0, 1, 0, 5], [0, 0, 1.01, 0], [0, 0, 0, 1]]),
        "joints[1].pose",
        ["not a rigid transform", "orthonormal"],
    ),
    "reflection": (
        _joint(1, "pose", [[1, 0, 0, 5], [0, 1, 0, 5], [0, 0, -1, 0], [0, 0, 0, 1]]),
        "joints[1].pose",
        ["determinant +1"],
    ),
    "bad last row": (
        _joint(1, "pose", [[1, 0, 0, 5], [0, 1, 0, 5], [0, 0, 1, 0], [0, 0, 1, 1]]),
        "joints[1].pose",
        ["last row must be [0, 0, 0, 1]"],
    ),
    "zero axis": (
        _joint(1, "pose", {"point": [5, 5, 0], "axis": [0, 0, 0]}),
        "joints[1].pose.axis",
        ["non-zero"],
    ),
    "xhat parallel to axis": (
        _joint(1, "pose", {"axis": [0, 0, 2], "xhat": [0, 0, -1]}),
        "joints[1].pose.xhat",
        ["parallel to the axis"],
    ),
    "start tip later": (
        lambda d: d["joints"].insert(2, {"type": "StartTip", "length": 1}),
        "joints[2].type",
        ["StartTip can only be the first joint"],
    ),
    "end tip as root": (
        lambda d: d["joints"].__setitem__(0, {"type": "EndTip", "length": 1}),
        "joints[0].type",
        ["cannot be an EndTip"],
    ),
    "end tip not last": (
        lambda d: d["joints"].append({"type": "Waypoint"}),
        "joints[3].type",
        ["EndTip must be the last joint"],
    ),
    "fixed position with safe placement": (
        _joint(2, "fixedPosition", True),
        "joints[2].fixedPosition",
        ['requires "safe": false'],
    ),
    "non-rigid edit transform": (
        _set("edits", [{"op": "transformAll", "transform": [[2, 0, 0, 0]] * 4}]),
        "edits[0].transform",
        ["not a rigid transform"],
    ),
}


@pytest.mark.parametrize("case", list(SEMANTIC_CASES))
def test_semantic_errors_found_without_building(tmp_path, case):
    change, field, fragments = SEMANTIC_CASES[case]
    error = _error_of(tmp_path, _mutated(change), validate_design)
    assert error.field == field
    for fragment in fragments:
        assert fragment in error.reason, (fragment, str(error))
    assert str(_error_of(tmp_path, _mutated(change))) == str(error)


def _unreachable_waypoint(d):
    """A waypoint at the start tip's distal end pointing back: no link reaches it."""
    d["joints"] = [
        {"type": "StartTip", "length": 1.5},
        {
            "type": "Waypoint",
            "pose": [[1, 0, 0, 0], [0, -1, 0, 0], [0, 0, -1, 0.75], [0, 0, 0, 1]],
            "relative": False,
            "safe": False,
            "fixedPosition": True,
            "fixedOrientation": True,
        },
    ]


BUILD_CASES = {
    "infeasible placement": (_unreachable_waypoint, "joints[1]", ["infeasible placement"]),
    "state out of range in an edit": (
        _set("edits", [{"op": "setJointState", "joint": 4, "state": 3}]),
        "edits[0]",
        ["infeasible edit setJointState", "outside its range [-1.5708, 1.5708]"],
    ),
    "edit of a joint that does not exist": (
        _set("edits", [{"op": "translateJointAlongAxisOfMotion", "joint": 7, "distance": 1}]),
        "edits[0].joint",
        ["no such joint", "7 joints", "-7 to 6"],
    ),
    "second edit infeasible": (
        _set(
            "edits",
            [
                {"op": "delete", "joint": 1},
                {"op": "setJointState", "joint": 1, "state": 5},
            ],
        ),
        "edits[1]",
        ["infeasible edit setJointState"],
    ),
    "too few states": (_set("states", [0, 0, 0, 0]), "states", ["7", "it has 4", "waypoints"]),
    "state out of range": (
        _set("states", [0, 0, 5, 0, 0, 0, 0]),
        "states[2]",
        ["PrismaticJoint", "outside its range"],
    ),
}


@pytest.mark.parametrize("case", list(BUILD_CASES))
def test_infeasible_designs_fail_when_built(tmp_path, case, capsys):
    change, field, fragments = BUILD_CASES[case]
    validate_design(_write(tmp_path, _mutated(change)))  # the file itself is well-formed
    error = _error_of(tmp_path, _mutated(change))
    assert error.field == field
    for fragment in fragments:
        assert fragment in str(error), (fragment, str(error))
    assert capsys.readouterr() == ("", "")  # nothing printed


def test_degree_states_are_checked_in_degrees(tmp_path):
    document = _mutated(_set("angleUnits", "deg"))
    document["joints"][1]["coneAngle"] = 45
    document["joints"][2].update(totalBendingAngle=180, pose=[{"Ry": 45}])
    document["joints"][3]["pose"] = [{"Ry": 90}]
    document["states"] = [0, 0, 0, 0, 91, 0, 0]
    error = _error_of(tmp_path, document)
    assert error.field == "states[4]" and error.value == 91


def test_invalid_json_names_line_and_column(tmp_path):
    error = _error_of(tmp_path, '{\n  "format": "kinegami-design",\n  "version": 1,,\n}')
    assert error.field == "$"
    assert "invalid JSON at line 3, column 16" in error.reason


@pytest.mark.parametrize("content", [b"", b" \n\t\r\n", b"\xef\xbb\xbf"])
@pytest.mark.parametrize("check", [load_design, validate_design, read_design])
def test_an_empty_file_says_it_is_empty(tmp_path, content, check):
    """Not "invalid JSON at line 1, column 1: Expecting value": empty, only whitespace, or only
    a BOM (which a design file may start with)."""
    path = tmp_path / "design.json"
    path.write_bytes(content)
    with pytest.raises(DesignError) as info:
        check(path)
    error = info.value
    assert type(error) is DesignError and error.field == "$" and error.file == str(path)
    assert str(error) == f"{path}: {error.reason}" and "\n" not in str(error)
    empty = "empty (only whitespace)" if content.decode("utf-8-sig") else "empty"
    assert error.reason.startswith(f"the design file is {empty}: a design is a JSON object {{")
    assert '"format": "kinegami-design"' in error.reason and "kinegami new" in error.reason
    assert "invalid JSON" not in error.reason


@pytest.mark.parametrize(
    ("text", "field", "fragment"),
    [
        ('{"format": "kinegami-design", "version": 1, "r": NaN}', "r", "finite"),
        ('{"format": "kinegami-design", "version": 1, "r": 1e999}', "r", "finite"),
        ('{"format": "kinegami-design", "version": 1, "r": -Infinity}', "r", "finite"),
        ('{"format": "kinegami-design", "version": 1, "r": 1, "r": 2}', "r", "duplicate key 'r'"),
        ("[1, 2]", "$", "JSON object"),
        ("", "$", "the design file is empty"),
    ],
)
def test_invalid_values(tmp_path, text, field, fragment):
    error = _error_of(tmp_path, text)
    assert error.field == field
    assert fragment in error.reason


def test_unreadable_files(tmp_path):
    with pytest.raises(DesignError, match="cannot read the design file"):
        load_design(tmp_path / "missing.json")
    (tmp_path / "bin.json").write_bytes(b'{"format": "\xff"}')
    with pytest.raises(DesignError, match="not UTF-8 text"):
        validate_design(tmp_path / "bin.json")
    with pytest.raises(DesignError, match="cannot read the design file"):
        read_design(tmp_path)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bin.json"]


def test_a_bom_is_accepted(tmp_path):
    path = tmp_path / "bom.json"
    path.write_bytes(b"\xef\xbb\xbf" + json.dumps(BASE).encode())
    assert len(load_design(path).Joints) == 7


def test_error_attributes_and_classes():
    with pytest.raises(DesignError) as info:
        loads_design(json.dumps(_mutated(_set("r", "1"))), file="arm.json")
    error = info.value
    assert isinstance(error, KinegamiError) and isinstance(error, ValueError)
    assert (error.file, error.field, error.value) == ("arm.json", "r", "1")
    assert error.reason == "must be a number in [1e-6, 1e6] (file length units)"
    assert str(error) == (
        'arm.json: r: must be a number in [1e-6, 1e6] (file length units) (got "1")'
    )
    again = pickle.loads(pickle.dumps(error))
    assert str(again) == str(error) and again.field == "r"


def test_errors_without_a_file_have_no_file_prefix():
    with pytest.raises(DesignError) as info:
        chain_from_dict(_mutated(_drop("numSides")))
    assert info.value.file is None
    assert str(info.value) == "numSides: missing required field 'numSides'"


def test_long_values_are_shortened_to_one_line():
    pose = [[1.123456789012345, 0.1, 0.2, 0.3] for _ in range(4)]
    with pytest.raises(DesignError) as info:
        chain_from_dict(_mutated(_joint(1, "pose", pose)))
    text = str(info.value)
    assert "\n" not in text and text.endswith("...)") and len(text) < 300
    assert info.value.value == pose


def test_read_design_returns_the_document(tmp_path):
    path = _write(tmp_path, BASE)
    assert read_design(path) == BASE
    assert validate_design(path) is None


def test_validate_does_not_place_joints(tmp_path, monkeypatch):
    """validate_design never builds a chain (placement is only checked by loading)."""
    import kinegami.chain

    def refuse(*args, **kwargs):
        raise AssertionError("validate_design must not build a chain")

    monkeypatch.setattr(kinegami.chain.KinematicChain, "append", refuse)
    monkeypatch.setattr(kinegami.chain.KinematicChain, "__init__", refuse)
    validate_design(_write(tmp_path, _mutated(_unreachable_waypoint)))


def test_library_errors_become_design_errors_at_the_named_field(monkeypatch):
    """A joint constructor's own check (should it be stricter than the schema) names the field."""
    from kinegami.chain.joints import JOINT_KINDS, RevoluteJoint
    from kinegami.errors import InvalidParameterError

    def kind_raising(message):  # the registered kind, with a stricter constructor
        class Strict(RevoluteJoint):
            @classmethod
            def from_design(cls, *args, **kwargs):
                raise InvalidParameterError(message)

        return Strict

    monkeypatch.setitem(JOINT_KINDS, "RevoluteJoint",
                        kind_raising("totalBendingAngle must lie in (0, 2pi), got 3.0"))
    with pytest.raises(DesignError) as info:
        chain_from_dict(BASE, file="a.json")
    assert info.value.field == "joints[2].totalBendingAngle"
    assert str(info.value) == (
        "a.json: joints[2].totalBendingAngle: totalBendingAngle must lie in (0, 2pi), got 3.0"
    )

    monkeypatch.setitem(JOINT_KINDS, "RevoluteJoint",
                        kind_raising("maxAnglePerElbow must lie in (0, pi], got 9"))
    with pytest.raises(DesignError) as info:
        chain_from_dict(BASE)
    assert info.value.field == "maxAnglePerElbow"
