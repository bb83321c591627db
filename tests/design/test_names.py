"""Joint names: edits by name, the joint table of the built chain, names kept when saving."""

from __future__ import annotations

import copy
import json
import math

import pytest

from kinegami import KinematicChain
from kinegami.design import (
    DesignError,
    chain_from_dict,
    design_to_dict,
    joint_table,
    load_design,
    load_design_with_info,
    origin_of,
    read_design,
    save_design,
    validate_design,
)

from . import DATA, assert_same_chain

EXAMPLE_1B = DATA / "example1b.json"
DOC_1B = json.loads(EXAMPLE_1B.read_text(encoding="utf-8"))  # names: start, slider, elbow, tip
TABLE_1B = [
    (0, "StartTip", "start"),
    (1, "Waypoint", None),
    (2, "PrismaticJoint", "slider"),
    (3, "Waypoint", None),
    (4, "RevoluteJoint", "elbow"),
    (5, "Waypoint", None),
    (6, "EndTip", "tip"),
]


def _document(**changes) -> dict:
    """Example 1B with top-level keys replaced (or removed, for None)."""
    document = copy.deepcopy(DOC_1B)
    document.update(changes)
    return {key: value for key, value in document.items() if value is not None}


def _error(document) -> DesignError:
    with pytest.raises(DesignError) as info:
        chain_from_dict(document, "arm.json")
    return info.value


# --- edits by name ------------------------------------------------------------------------------
def test_edits_by_name_equal_edits_by_index():
    """Example 1B's edits name joints 4, 6, 4, 2: elbow, tip, elbow, slider."""
    by_name = _document()
    for edit, name in zip(by_name["edits"], ["elbow", "tip", "elbow", "slider"], strict=True):
        edit["joint"] = name
    assert_same_chain(chain_from_dict(by_name), load_design(EXAMPLE_1B), pose_tol=0.0)


def test_a_name_follows_its_joint_through_deletes():
    """After deleting the waypoints at 1 and 3, 'elbow' is joint 2, not 4."""
    edits = [
        {"op": "delete", "joint": 1},
        {"op": "delete", "joint": 2},
        {"op": "setJointState", "joint": "elbow", "state": 30},
    ]
    chain = chain_from_dict(_document(edits=edits, states=None))
    by_index = _document(states=None)
    by_index["edits"] = [*edits[:2], {"op": "setJointState", "joint": 2, "state": 30}]
    assert_same_chain(chain, chain_from_dict(by_index), pose_tol=0.0)
    assert type(chain.Joints[2]).__name__ == "RevoluteJoint"
    assert chain.Joints[2].state == pytest.approx(math.pi / 6, abs=1e-15)


def test_a_name_resolves_at_edit_time_with_negative_deletes():
    edits = [
        {"op": "delete", "joint": -2},  # the waypoint before the tip
        {"op": "translateJointAlongAxisOfMotion", "joint": "tip", "distance": 1},
    ]
    chain = chain_from_dict(_document(edits=edits, states=[0] * 6))
    expected = chain_from_dict(
        _document(
            edits=[edits[0], {"op": "translateJointAlongAxisOfMotion", "joint": 5, "distance": 1}],
            states=[0] * 6,
        )
    )
    assert_same_chain(chain, expected, pose_tol=0.0)
    assert [row[2] for row in joint_table(chain, _document(edits=edits))] == [
        "start", None, "slider", None, "elbow", "tip"
    ]  # fmt: skip


def test_set_joint_state_by_name_uses_degrees_for_revolute_joints():
    edits = [{"op": "setJointState", "joint": "elbow", "state": 45}]
    chain = chain_from_dict(_document(edits=edits, states=None))
    assert chain.Joints[4].state == pytest.approx(math.pi / 4, abs=1e-15)


def test_an_edit_of_a_deleted_joint_names_the_delete():
    edits = [
        {"op": "delete", "joint": "slider"},
        {"op": "translateJointAlongAxisOfMotion", "joint": "slider", "distance": 1},
    ]
    error = _error(_document(edits=edits, states=None))
    assert error.field == "edits[1].joint" and error.value == "slider"
    assert error.reason == (
        "joint 'slider' (joints[1]) is no longer in the chain: edits[0] deleted it"
    )
    assert str(error).startswith("arm.json: edits[1].joint: ")


# (document, field, value, reason) found by validation, without building
NAME_ERRORS = {
    "duplicate names": (
        lambda d: d["joints"][2].update(name="slider"),
        "joints[2].name",
        "slider",
        "duplicate joint name: joints[1] is also named 'slider' (names must be unique, edits "
        "refer to joints by name)",
    ),
    "unknown name": (
        lambda d: d["edits"][0].update(joint="elbw"),
        "edits[0].joint",
        "elbw",
        "no joint is named 'elbw'; the joint names are 'start', 'slider', 'elbow', 'tip'",
    ),
    "no names at all": (
        lambda d: [j.pop("name") for j in d["joints"]] and d["edits"][1].update(joint="tip"),
        "edits[1].joint",
        "tip",
        "no joint is named 'tip': no entry of 'joints' has a \"name\" (add one, or use the "
        "index in the built chain)",
    ),
    "empty name": (
        lambda d: d["edits"][0].update(joint=""),
        "edits[0].joint",
        "",
        "a joint name must not be empty",
    ),
    "joint neither index nor name": (
        lambda d: d["edits"][0].update(joint=4.5),
        "edits[0].joint",
        4.5,
        "must be a joint index (an integer) or a joint name (a string)",
    ),
}


@pytest.mark.parametrize("case", list(NAME_ERRORS))
def test_name_errors_are_found_by_validation(tmp_path, case):
    change, field, value, reason = NAME_ERRORS[case]
    document = _document()
    change(document)
    path = tmp_path / "arm.json"
    path.write_text(json.dumps(document), encoding="utf-8")
    with pytest.raises(DesignError) as info:
        validate_design(path)
    assert (info.value.field, info.value.value, info.value.reason) == (field, value, reason)


def test_a_dh_design_has_no_joint_names():
    document = {
        "format": "kinegami-design",
        "version": 1,
        "numSides": 4,
        "r": 1,
        "dh": {"rows": [[0, 0, 4, 0]], "placement": "safe"},
        "edits": [{"op": "delete", "joint": "base"}],
    }
    error = _error(document)
    assert error.field == "edits[0].joint"
    assert error.reason == "a DH design has no joint names: refer to its joints by index"


def test_names_that_look_like_indices_are_names():
    document = _document(edits=[{"op": "rotateJointAboutAxisOfMotion", "joint": "4", "angle": 0}])
    document["joints"][1]["name"] = "4"  # the slider, at index 2
    chain = chain_from_dict(document)
    assert joint_table(chain, document)[2] == (2, "PrismaticJoint", "4")


# --- the joint table ----------------------------------------------------------------------------
def test_joint_table_of_example_1b():
    chain, _ = load_design_with_info(EXAMPLE_1B)
    assert joint_table(chain, read_design(EXAMPLE_1B)) == TABLE_1B
    origin = origin_of(chain)
    assert origin.sources == (0, None, 1, None, 2, None, 3)
    assert origin.file == str(EXAMPLE_1B) and origin.kind == "joints"


def test_joint_table_survives_moves_and_states():
    chain = load_design(EXAMPLE_1B)
    assert chain.setJointState(4, 0.2)
    assert chain.translateJointAlongAxisOfMotion(2, 0.5)
    assert joint_table(chain, DOC_1B) == TABLE_1B


def test_joint_table_of_a_chain_built_in_python(example_1b):
    """A chain the loader did not build: the document is built again to find the entries."""
    assert origin_of(example_1b) is None
    document = _document()
    document.pop("states")
    assert joint_table(example_1b, document) == TABLE_1B


def test_joint_table_of_another_chain_is_an_error(example_1a):
    assert example_1a.delete(1)
    with pytest.raises(DesignError) as info:
        joint_table(example_1a, DOC_1B)
    assert info.value.reason == (
        "the chain does not come from this design: the design builds 7 joints (StartTip, "
        "Waypoint, PrismaticJoint, Waypoint, RevoluteJoint, Waypoint, EndTip), the chain has 6 "
        "(StartTip, PrismaticJoint, Waypoint, RevoluteJoint, Waypoint, EndTip)"
    )


def test_joint_table_without_names_does_not_build(monkeypatch):
    import kinegami.design.checks as checks

    monkeypatch.setattr(checks, "build_plan", None)  # would fail if called
    document = _document()
    for joint in document["joints"]:
        joint.pop("name")
    chain = chain_from_dict(document)
    assert joint_table(chain, document) == [(i, kind, None) for i, kind, _ in TABLE_1B]


def test_joint_table_of_a_dh_design():
    document = {
        "format": "kinegami-design",
        "version": 1,
        "numSides": 4,
        "r": 1,
        "dh": {"rows": [[0, 0, 4, 0], [0, 0, 4, 0]], "jointTypes": "RP", "placement": "safe"},
    }
    chain = chain_from_dict(document)
    table = joint_table(chain, document)
    assert [row[0] for row in table] == list(range(len(chain)))
    assert [row[1] for row in table] == [type(j).__name__ for j in chain.Joints]
    assert {row[2] for row in table} == {None}
    assert origin_of(chain).kind == "dh"


def test_joint_table_rejects_wrong_types():
    chain = load_design(EXAMPLE_1B)
    with pytest.raises(TypeError, match="document must be a dict"):
        joint_table(chain, str(EXAMPLE_1B))
    with pytest.raises(TypeError, match="chain must be a KinematicChain"):
        joint_table(DOC_1B, DOC_1B)


def test_origin_is_forgotten_when_the_joints_change():
    chain = load_design(EXAMPLE_1B)
    assert origin_of(chain) is not None
    assert chain.delete(1)
    assert origin_of(chain) is None
    assert origin_of(KinematicChain(chain.Joints[0])) is None


# --- saving keeps names ---------------------------------------------------------------------
def test_saving_a_loaded_chain_keeps_its_names(tmp_path):
    chain = load_design(EXAMPLE_1B)
    document = design_to_dict(chain)
    assert [entry.get("name") for entry in document["joints"]] == [row[2] for row in TABLE_1B]
    assert list(document["joints"][2])[:2] == ["type", "name"]
    again, _ = load_design_with_info(save_design(chain, tmp_path / "again.json"))
    assert joint_table(again, read_design(tmp_path / "again.json")) == TABLE_1B
    assert_same_chain(again, chain, pose_tol=1e-12)


def test_names_survive_root_deletes(tmp_path):
    chain = chain_from_dict(_document(edits=[{"op": "delete", "joint": 0}], states=None))
    path = save_design(chain, tmp_path / "d.json")
    saved = read_design(path)
    assert [row[2] for row in joint_table(load_design(path), saved)] == [
        None, "slider", None, "elbow", None, "tip"
    ]  # fmt: skip


def test_a_tip_left_as_root_keeps_its_name(tmp_path):
    """A chain reduced to its end tip is saved as a waypoint root, the tip and a delete edit."""
    deletes = [{"op": "delete", "joint": 0}] * 6
    chain = chain_from_dict(_document(edits=deletes, states=None))
    path = save_design(chain, tmp_path / "d.json")
    saved = read_design(path)
    assert saved["edits"] == [{"op": "delete", "joint": 0}]
    assert [entry.get("name") for entry in saved["joints"]] == [None, "tip"]
    assert joint_table(load_design(path), saved) == [(0, "EndTip", "tip")]


def test_chains_without_a_known_origin_are_saved_without_names(example_1b):
    chain = load_design(EXAMPLE_1B)
    assert chain.delete(1)  # joint types change: the origin is forgotten
    assert all("name" not in entry for entry in design_to_dict(chain)["joints"])
    assert all("name" not in entry for entry in design_to_dict(copy.deepcopy(example_1b))["joints"])
