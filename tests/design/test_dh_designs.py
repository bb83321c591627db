"""Design files with a DH table ("dh") instead of a joint list."""

from __future__ import annotations

import math

import pytest

from kinegami import KinematicChain, PrismaticJoint, RevoluteJoint, Waypoint
from kinegami.design import DesignError, chain_from_dict, design_to_dict, loads_design

from . import assert_same_chain, pose_error

PUMA_DEG = [
    [90, -90, 0, 0],
    [0, 0, 431.8, 149.09],
    [90, 90, -20.32, 0],
    [0, -90, 0, 433.07],
    [0, 90, 0, 0],
    [0, 0, 0, 56.25],
]
PUMA_RAD = [[math.radians(t), math.radians(al), a, d] for t, al, a, d in PUMA_DEG]


def _design(dh: dict, **top) -> dict:
    return {"format": "kinegami-design", "version": 1, "numSides": 6, "r": 100, "dh": dh, **top}


def test_puma_in_degrees_equals_from_dh_in_radians():
    chain = chain_from_dict(_design({"rows": PUMA_DEG}, angleUnits="deg"))
    expected = KinematicChain.from_dh(PUMA_RAD, 6, 100)
    assert_same_chain(chain, expected, pose_tol=1e-12)
    assert pose_error(chain, expected) == 0.0


def test_only_the_keys_in_the_file_are_passed(monkeypatch):
    """Defaults live in from_dh: the loader passes exactly the keys the file has."""
    calls = []
    original = KinematicChain.from_dh.__func__

    def spy(cls, *args, **kwargs):
        calls.append((args, kwargs))
        return original(cls, *args, **kwargs)

    monkeypatch.setattr(KinematicChain, "from_dh", classmethod(spy))
    chain_from_dict(_design({"rows": PUMA_RAD}))
    chain_from_dict(_design({"rows": PUMA_RAD, "placement": "safe"}, maxAnglePerElbow=1.0))
    (args0, kwargs0), (args1, kwargs1) = calls
    assert args0 == (PUMA_RAD, 6, 100.0) and kwargs0 == {}
    assert args1[1:] == (6, 100.0)
    assert kwargs1 == {"placement": "safe", "maxAnglePerElbow": 1.0}


def test_every_option_is_passed_in_radians():
    rows = [[10, 90, 0, 200], [0, -90, 300, 0], [45, 0, 0, 150]]
    options = {
        "convention": "modified",
        "jointTypes": ["revolute", "P", "R"],
        "placement": "safe",
        "totalBendingAngle": 120,
        "numSinkLayers": 2,
        "neutralLength": 250,
        "numLayers": 4,
        "coneAngle": 50,
        "endTip": True,
        "tipLength": 80,
    }
    chain = chain_from_dict(
        _design({"rows": rows, **options}, angleUnits="deg", maxAnglePerElbow=60)
    )
    expected = KinematicChain.from_dh(
        [[math.radians(t), math.radians(al), a, d] for t, al, a, d in rows],
        6,
        100,
        convention="modified",
        jointTypes=["revolute", "P", "R"],
        placement="safe",
        totalBendingAngle=math.radians(120),
        numSinkLayers=2,
        neutralLength=250,
        numLayers=4,
        coneAngle=math.radians(50),
        endTip=True,
        tipLength=80,
        maxAnglePerElbow=math.radians(60),
    )
    assert_same_chain(chain, expected, pose_tol=1e-12)
    prismatic = [j for j in chain.Joints if isinstance(j, PrismaticJoint)]
    assert len(prismatic) == 1 and prismatic[0].numLayers == 4
    revolute = [j for j in chain.Joints if isinstance(j, RevoluteJoint)]
    assert revolute[0].totalBendingAngle == pytest.approx(2 * math.pi / 3, abs=1e-15)


def test_joint_types_as_a_string_and_no_end_tip():
    dh = {"rows": PUMA_RAD[:3], "jointTypes": "RPR", "endTip": False, "placement": "safe"}
    chain = chain_from_dict(_design(dh))
    assert [type(j).__name__ for j in chain.Joints if not isinstance(j, Waypoint)] == [
        "RevoluteJoint",
        "PrismaticJoint",
        "RevoluteJoint",
    ]


def test_edits_and_states_apply_to_the_dh_chain():
    dh = {"rows": PUMA_RAD}
    edits = [
        {"op": "translateJointAlongAxisOfMotion", "joint": 2, "distance": -50},
        {"op": "setJointState", "joint": 1, "state": 0.5},
    ]
    chain = chain_from_dict(_design(dh, edits=edits, states=[0.1, 0.5, 0, 0, 0, -0.2, 0]))
    expected = KinematicChain.from_dh(PUMA_RAD, 6, 100)
    assert expected.translateJointAlongAxisOfMotion(2, -50)
    assert expected.setJointStates([0.1, 0.5, 0, 0, 0, -0.2, 0])
    assert_same_chain(chain, expected, pose_tol=1e-12)


def test_a_dh_chain_saves_as_joints_and_round_trips():
    chain = chain_from_dict(_design({"rows": PUMA_RAD, "placement": "safe"}))
    document = design_to_dict(chain)
    assert "dh" not in document and len(document["joints"]) == len(chain.Joints)
    assert_same_chain(chain_from_dict(document), chain, pose_tol=1e-12)


@pytest.mark.parametrize(
    ("dh", "field", "fragment"),
    [
        ({"rows": PUMA_RAD, "jointTypes": "RRR"}, "dh.jointTypes", "one type per table row (6)"),
        ({"rows": PUMA_RAD, "jointTypes": "RRRRRX"}, "dh.jointTypes", "letters R and P"),
        ({"rows": PUMA_RAD, "jointTypes": ["R"] * 5 + ["Q"]}, "dh.jointTypes[5]", "'revolute'"),
        ({"rows": [[0, 0, 0]]}, "dh.rows[0]", "4 numbers [theta, alpha, a, d]"),
        ({"rows": []}, "dh.rows", "at least 1 item"),
        ({}, "dh.rows", "missing required field 'rows'"),
        ({"rows": PUMA_RAD, "placement": "loose"}, "dh.placement", "'compact', 'safe'"),
        ({"rows": PUMA_RAD, "convention": "craig"}, "dh.convention", "'standard', 'modified'"),
        ({"rows": PUMA_RAD, "tipLength": -1}, "dh.tipLength", "> 0"),
        ({"rows": PUMA_RAD, "coneAngle": 2}, "dh.coneAngle", "[pi/6, pi/2) radians"),
        ({"rows": PUMA_RAD, "endtip": False}, "dh.endtip", "did you mean 'endTip'"),
    ],
)
def test_dh_errors(dh, field, fragment):
    with pytest.raises(DesignError) as info:
        chain_from_dict(_design(dh), file="puma.json")
    assert info.value.field == field
    assert fragment in str(info.value)
    assert str(info.value).startswith(f"puma.json: {field}: ")


def test_a_failing_dh_placement_names_the_table():
    """Compact placement of this RPR table finds no link to joint 1 (from_dh says so)."""
    with pytest.raises(DesignError) as info:
        chain_from_dict(_design({"rows": PUMA_RAD[:3], "jointTypes": "RPR", "endTip": False}))
    assert info.value.field == "dh"
    assert "compact placement cannot place joint 1" in info.value.reason
    assert "try placement='safe'" in info.value.reason


def test_dh_designs_from_text():
    chain = loads_design(
        '{"format": "kinegami-design", "version": 1, "numSides": 4, "r": 1,'
        ' "dh": {"rows": [[0, 0, 0, 5], [0, 0, 0, 5]], "placement": "safe"}}'
    )
    assert isinstance(chain.Joints[0], RevoluteJoint)
