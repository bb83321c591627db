"""The top-level field ``requireClearance``: a design that passes through itself while it
requires clearance fails to load, naming the operation and the parts; saving keeps the field."""

from __future__ import annotations

import copy
import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from kinegami import ClearanceWarning, KinematicChain, RevoluteJoint, StartTip, Waypoint
from kinegami.design import chain_from_dict, design_to_dict, load_design, save_design
from kinegami.design.errors import DesignError
from kinegami.errors import InvalidParameterError

from . import assert_same_chain

EXAMPLES = Path(__file__).parents[2] / "examples" / "designs"
FIXED = {"relative": False, "safe": False, "fixedPosition": True, "fixedOrientation": True}

#: A revolute state (degrees) at which the fold-back chain passes through itself.
COLLIDING_DEG = 20.0
#: A DH table (degrees) whose compact placement brings link 2 back through link 1.
COLLIDING_DH = [[149, 2, 1.1, -0.8], [143, 96, 0.1, -1.4], [-149, 167, -0.4, -0.8]]


def frame(p, x) -> np.ndarray:
    """A frame at ``p`` in the plane z = p_z whose x axis is ``x`` (horizontal) and z is up."""
    x = np.asarray(x, dtype=float) / np.linalg.norm(x)
    z = np.array([0.0, 0.0, 1.0])
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, p
    return T


def tip_pose(p, d) -> np.ndarray:
    """A tip's Pose at ``p`` whose path direction (z) is the horizontal ``d``."""
    d = np.asarray(d, dtype=float) / np.linalg.norm(d)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = (0.0, 0.0, 1.0), np.cross(d, (0, 0, 1)), d, p
    return T


def fold_back_chain() -> KinematicChain:
    """A start tip, a revolute joint and a waypoint folding back beside the tip, 2.5 r from it
    (clear at state 0; turning the joint brings the return leg into the tip)."""
    chain = KinematicChain(StartTip(4, 1, tip_pose((-6, 0, 0), (1, 0, 0)), 1.5))
    assert chain.append(RevoluteJoint(4, 1, math.pi, frame((0, 0, 0), (1, 0, 0))), **FIXED)
    assert chain.append(Waypoint(4, 1, frame((-6, 2.5, 0), (-1, 0, 0)), pathIndex=0), **FIXED)
    return chain


@pytest.fixture
def fold_back():
    """The fold-back chain as a design document (requireClearance absent)."""
    return design_to_dict(fold_back_chain())


def required(document: dict) -> dict:
    document = copy.deepcopy(document)
    document["requireClearance"] = True
    return document


def load_quietly(document: dict) -> KinematicChain:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        return chain_from_dict(document)


def test_default_is_false_and_true_sets_the_chain(fold_back):
    assert load_quietly(fold_back).requireClearance is False
    assert chain_from_dict(required(fold_back)).requireClearance is True


def test_a_colliding_state_fails_to_load_only_when_clearance_is_required(fold_back):
    fold_back["states"] = [0.0, math.radians(COLLIDING_DEG), 0.0]
    with pytest.warns(ClearanceWarning, match="passes through itself"):
        chain_from_dict(fold_back)
    with pytest.raises(DesignError, match="requireClearance") as caught:
        chain_from_dict(required(fold_back))
    message = str(caught.value)
    assert message.startswith("states: infeasible states: setJointStates failed")
    assert "joint 0, StartTip" in message and "link 2" in message


def test_a_colliding_edit_names_the_edit_and_the_parts(fold_back):
    fold_back["edits"] = [
        {"op": "setJointState", "joint": 1, "state": math.radians(COLLIDING_DEG)}
    ]
    with pytest.raises(DesignError) as caught:
        chain_from_dict(required(fold_back))
    message = str(caught.value)
    assert message.startswith("edits[0]: infeasible edit setJointState: setJointState failed")
    assert "joint 0, StartTip" in message and '"requireClearance": true' in message


def test_a_colliding_placement_names_the_joint_and_the_parts():
    """Up, back over the start, and down into the start tip."""
    chain = KinematicChain(StartTip(4, 1, tip_pose((-6, 0, 0), (1, 0, 0)), 1.5))
    assert chain.append(Waypoint(4, 1, frame((0, 0, 0), (1, 0, 0)), pathIndex=0), **FIXED)
    assert chain.append(Waypoint(4, 1, frame((0, 0, 6), (-1, 0, 0)), pathIndex=0), **FIXED)
    design = design_to_dict(chain)
    design["joints"].append({
        "type": "Waypoint", "pathIndex": 0, **FIXED,
        "pose": frame((-10, 1.5, 0), (-1, 0, 0)).tolist(),  # 1.5 r beside the start tip
    })  # fmt: skip
    with pytest.warns(ClearanceWarning):
        assert len(chain_from_dict(design)) == 4
    with pytest.raises(DesignError) as caught:
        chain_from_dict(required(design))
    message = str(caught.value)
    assert message.startswith("joints[3]: infeasible placement of the Waypoint: append failed")
    assert "joint 0, StartTip" in message and "requireClearance" in message


def dh_design(**extra) -> dict:
    return {
        "format": "kinegami-design", "version": 1, "angleUnits": "deg", "numSides": 4, "r": 1,
        "dh": {"rows": COLLIDING_DH}, **extra,
    }  # fmt: skip


def test_a_dh_table_that_places_into_itself_fails_when_clearance_is_required():
    chain = chain_from_dict(dh_design())
    assert not chain.clearance().ok  # loads without the field
    with pytest.raises(DesignError) as caught:
        chain_from_dict(dh_design(requireClearance=True))
    message = str(caught.value)
    assert message.startswith(
        "dh: the chain of the DH table passes through itself (joint 0, RevoluteJoint"
    )
    assert "requireClearance" in message


def test_a_dh_design_requiring_clearance_keeps_it_for_edits():
    """The PUMA 560 (clear as built) with joint 4 turned by 60 degrees, where links 4 and 5
    overlap: a warning without the field, an error with it."""
    design = json.loads((EXAMPLES / "puma.json").read_text())
    design["edits"].append({"op": "setJointState", "joint": 4, "state": 60})
    with pytest.warns(ClearanceWarning, match="link 4"):
        assert chain_from_dict(design).requireClearance is False
    design["requireClearance"] = True
    with pytest.raises(DesignError, match=r"^edits\[5\]: infeasible edit setJointState.*link 4"):
        chain_from_dict(design)
    del design["edits"][-1]
    assert chain_from_dict(design).requireClearance is True


def test_requireClearance_must_be_a_boolean(fold_back):
    fold_back["requireClearance"] = 1
    with pytest.raises(DesignError, match="requireClearance.*true or false"):
        chain_from_dict(fold_back)


def test_save_writes_the_field_and_loads_the_same_chain(tmp_path):
    chain = fold_back_chain()
    assert chain.setJointState(1, -0.3)
    path = save_design(chain, tmp_path / "plain.json")
    assert "requireClearance" not in path.read_text()
    chain.requireClearance = True
    path = save_design(chain, tmp_path / "required.json")
    assert design_to_dict(chain)["requireClearance"] is True
    loaded = load_design(path)
    assert loaded.requireClearance is True
    assert assert_same_chain(loaded, chain, pose_tol=1e-12) <= 1e-12
    assert [j.state for j in loaded.Joints] == [j.state for j in chain.Joints]


def test_save_refuses_a_required_chain_that_would_not_load(tmp_path):
    chain = fold_back_chain()
    with pytest.warns(ClearanceWarning):
        assert chain.setJointState(1, math.radians(COLLIDING_DEG))
    chain.requireClearance = True  # set on a chain that already passes through itself
    with pytest.raises(InvalidParameterError, match="at its states .*loading it would fail"):
        save_design(chain, tmp_path / "bad.json")
    assert list(tmp_path.iterdir()) == []
