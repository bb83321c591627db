"""One behaviour per test for each editor command: what it does, and its refusals."""

from __future__ import annotations

import itertools
import math

import numpy as np
import pytest
from numpy.testing import assert_allclose
from spatialmath import SE3

from kinegami.editor import (
    AddJoint,
    Compact,
    DeleteJoint,
    EditorModel,
    RenameJoint,
    RollJoint,
    SetJointParameters,
    SetJointState,
    SetJointStates,
    SetOptions,
    SlideJoint,
    TransformAll,
    TransformJoint,
)
from tests.editor.helpers import example_model, snapshot


@pytest.fixture
def model() -> EditorModel:
    return example_model()


def refused(model: EditorModel, command, *words: str) -> str:
    """Apply ``command``, check that it failed and changed nothing; return the reason."""
    before = model.document
    bits = snapshot(before)
    history = model.undo_labels
    result = model.apply(command)
    assert not result.ok and result.change is None
    assert model.document is before and snapshot(model.document) == bits
    assert model.undo_labels == history
    for word in words:
        assert word in result.reason, result.reason
    return result.reason


# --- slide and roll ------------------------------------------------------------------------------
def test_slide_moves_the_joint_along_its_axis(model):
    j = model.document.names.index("revolute")
    T = model.chain.Joints[j].pose_matrix.copy()
    assert model.apply(SlideJoint("revolute", 0.5)).ok
    new = model.chain.Joints[j].pose_matrix
    assert_allclose(new[:3, 3], T[:3, 3] + 0.5 * T[:3, 2], atol=1e-12)
    assert_allclose(new[:3, :3], T[:3, :3], atol=1e-12)


def test_slide_with_propagation_moves_the_later_joints(model):
    end = model.chain.Joints[-1].pose_matrix.copy()
    assert model.apply(SlideJoint("revolute", 0.5, propagate=True)).ok
    assert not np.array_equal(model.chain.Joints[-1].pose_matrix, end)


def test_slide_without_propagation_keeps_the_later_joints(model):
    end = model.chain.Joints[-1].pose_matrix.copy()
    assert model.apply(SlideJoint("revolute", 0.5, propagate=False)).ok
    assert np.array_equal(model.chain.Joints[-1].pose_matrix, end)


def test_the_model_default_propagate_is_used_by_the_helpers(model):
    end = model.chain.Joints[-1].pose_matrix.copy()
    model.propagate = False
    assert model.slide("revolute", 0.5).ok
    assert np.array_equal(model.chain.Joints[-1].pose_matrix, end)
    model.propagate = True
    assert model.slide("revolute", 0.5).ok
    assert not np.array_equal(model.chain.Joints[-1].pose_matrix, end)


def test_a_refused_slide_or_roll_names_the_joint_once(model):
    reason = refused(model, SlideJoint("revolute", -5.0, propagate=False),
                     "slide joint 4 (RevoluteJoint 'revolute'): ", "no CSC path")  # fmt: skip
    assert "joint joint" not in reason
    reason = refused(model, RollJoint("revolute", 0.5, propagate=False),
                     "roll joint 4 (RevoluteJoint 'revolute'): ", "no CSC path")  # fmt: skip
    assert "joint joint" not in reason


def test_roll_turns_the_joint_about_its_axis(model):
    j = model.document.names.index("revolute")
    T = model.chain.Joints[j].pose_matrix.copy()
    assert model.apply(RollJoint(j, math.pi / 3)).ok
    new = model.chain.Joints[j].pose_matrix
    assert_allclose(new[:3, 2], T[:3, 2], atol=1e-12)
    assert_allclose(new[:3, 3], T[:3, 3], atol=1e-12)
    assert_allclose(new[:3, 0] @ T[:3, 0], 0.5, atol=1e-12)


@pytest.mark.parametrize(
    ("command", "words"),
    [
        (SlideJoint(99, 1.0), ["joint", "[-7, 6]", "99"]),
        (SlideJoint("elbow", 1.0), ["elbow", "'revolute'"]),
        (SlideJoint(True, 1.0), ["joint", "True"]),
        (SlideJoint(2, 1e9), ["distance", "1e+06", "1000000000.0"]),
        (SlideJoint(2, float("nan")), ["distance", "finite", "nan"]),
        (SlideJoint(2, "1"), ["distance", "number", "'1'"]),
        (SlideJoint(2, 1.0, propagate="yes"), ["propagate", "'yes'"]),
        (RollJoint(2, float("inf")), ["angle", "finite"]),
    ],
)
def test_bad_moves_are_refused_with_the_parameter_and_value(model, command, words):
    refused(model, command, *words)


def colliding_states(model: EditorModel) -> list[float]:
    """States (a grid over the movable joints' ranges) at which the chain passes through
    itself."""
    chain = model.chain
    movable = [i for i, j in enumerate(chain.Joints) if j.stateRange() != (0.0, 0.0)]
    for fractions in itertools.product(np.linspace(0.0, 1.0, 9), repeat=len(movable)):
        states = [0.0] * len(chain.Joints)
        for i, f in zip(movable, fractions, strict=True):
            lo, hi = chain.Joints[i].stateRange()
            states[i] = float(lo + (hi - lo) * f)
        if not chain.clearance(states).ok:
            return states
    raise AssertionError("no colliding configuration found")


def test_a_state_rejected_by_require_clearance_changes_nothing(model):
    states = colliding_states(model)
    assert model.set_options(requireClearance=True).ok
    refused(model, SetJointStates(states), "pass through itself")


def test_a_colliding_command_without_require_clearance_warns(model):
    result = model.apply(SetJointStates(colliding_states(model)))
    assert result.ok and result.warnings
    assert "passes through itself" in result.warnings[0]
    assert not model.clearance().ok


# --- transform -----------------------------------------------------------------------------------
def test_transform_moves_a_waypoint(model):
    j = 1
    assert model.chain.Joints[j].__class__.__name__ == "Waypoint"
    T = model.chain.Joints[j].pose_matrix.copy()
    assert model.apply(TransformJoint(j, SE3.Tz(0.5), propagate=False)).ok
    assert_allclose(model.chain.Joints[j].pose_matrix[:3, 3], T[:3, 3] + [0, 0, 0.5])


def test_transform_of_a_motion_joint_needs_kinematic(model):
    refused(model, TransformJoint("revolute", SE3.Tz(0.5)), "axis of motion", "kinematic=True")
    assert model.apply(TransformJoint("revolute", SE3.Tz(0.5), kinematic=True)).ok


@pytest.mark.parametrize(
    ("transform", "words"),
    [
        (np.eye(3), ["transform", "4x4", "(3, 3)"]),
        (np.diag([1.0, 1.0, 2.0, 1.0]), ["rigid", "orthonormal"]),
        ("Tz", ["transform", "4x4"]),
        (SE3.Tz(1e9).A, ["transform translation", "1e+06"]),
    ],
)
def test_bad_transforms_are_refused(model, transform, words):
    refused(model, TransformJoint(1, transform), *words)


def test_transform_all_moves_every_joint(model):
    before = [j.pose_matrix.copy() for j in model.chain.Joints]
    assert model.apply(TransformAll(SE3.Trans(1, 2, 3))).ok
    for old, joint in zip(before, model.chain.Joints, strict=True):
        assert_allclose(joint.pose_matrix[:3, 3], old[:3, 3] + [1, 2, 3], atol=1e-12)


# --- add -----------------------------------------------------------------------------------------
def test_add_after_the_last_joint_but_an_end_tip_is_refused(model):
    refused(model, AddJoint("RevoluteJoint"), "EndTip", "nothing can follow")


def test_add_in_the_middle_keeps_the_later_joints_and_relinks_them(model):
    old = [j.pose_matrix.tobytes() for j in model.chain.Joints]
    parent = model.chain.Joints[2].pose_matrix.copy()
    T = SE3.Trans(3, 0, 3)
    result = model.apply(AddJoint("RevoluteJoint", {}, T, after=2, placement="pose", name="new"))
    assert result.ok, result.reason
    joints = model.chain.Joints
    assert model.selected == 3 and model.document.names[3] == "new"
    assert type(joints[3]).__name__ == "RevoluteJoint"
    assert_allclose(joints[3].pose_matrix, parent @ T.A, atol=1e-12)
    sources = result.change.joint_sources
    kept = [(i, k) for i, k in enumerate(sources) if k is not None]
    assert [k for _, k in kept][:3] == [0, 1, 2] and kept[-1] == (len(joints) - 1, 6)
    for i, k in kept:
        assert joints[i].pose_matrix.tobytes() == old[k]
    assert model.document.names[-1] == "end"


def test_a_joint_no_link_reaches_is_placed_again_on_its_axis(model):
    result = model.apply(AddJoint("RevoluteJoint", {}, SE3.Trans(3, 0, 3), after=2,
                                  placement="pose"))  # fmt: skip
    assert result.ok
    assert any("placed again by safe placement" in w for w in result.warnings)


def test_add_with_compact_placement_slides_the_joint_along_its_axis(model):
    result = model.apply(
        AddJoint("Waypoint", {}, SE3.Trans(0, 0, 0), after=0, placement="compact", name="w")
    )
    assert result.ok, result.reason
    assert model.document.names[1] == "w"


def test_add_with_safe_placement_may_add_waypoints_without_names(model):
    n = len(model.chain.Joints)
    result = model.apply(
        AddJoint("PrismaticJoint", {"neutralLength": 2.0}, SE3.Ry(1.0), after=0, name="new")
    )
    assert result.ok, result.reason
    added = len(model.chain.Joints) - n
    assert added >= 1
    index = model.document.names.index("new")
    assert model.selected == index
    assert all(name is None for name in model.document.names[1:index])
    assert model.chain.Joints[index].neutralLength == 2.0


def test_add_an_end_tip_at_the_end():
    model = EditorModel(example_model().document)
    assert model.delete(-1).ok
    assert model.apply(AddJoint("EndTip", {"length": 2.0}, SE3.Tz(4), placement="safe")).ok
    assert type(model.chain.Joints[-1]).__name__ == "EndTip"


@pytest.mark.parametrize(
    ("command", "words"),
    [
        (AddJoint("Hinge", after=2), ["joint type", "RevoluteJoint", "'Hinge'"]),
        (AddJoint("StartTip", after=2), ["StartTip", "first joint"]),
        (AddJoint("EndTip", after=2), ["EndTip", "last joint"]),
        (AddJoint("RevoluteJoint", {"numSinkLayers": 0}, after=2), ["numSinkLayers", "[1, 32]"]),
        (AddJoint("RevoluteJoint", {"bend": 1}, after=2), ["unknown parameter 'bend'"]),
        (AddJoint("PrismaticJoint", {"coneAngle": 0.1}, after=2), ["coneAngle", "pi/6"]),
        (AddJoint("Waypoint", {"pathIndex": 3}, after=2), ["pathIndex", "[0, 2]", "3"]),
        (AddJoint("Waypoint", after=2, placement="near"), ["placement", "safe", "'near'"]),
        (AddJoint("Waypoint", after=2, name="revolute"), ["name 'revolute'", "unique"]),
        (AddJoint("Waypoint", after=2, name=""), ["name", "empty"]),
        (AddJoint("Waypoint", after=20), ["after", "[-7, 6]", "20"]),
        (AddJoint("Waypoint", after=2, relative=1), ["relative", "True or False"]),
        (AddJoint("Waypoint", parameters=[1], after=2), ["parameters", "mapping"]),
    ],
)
def test_bad_additions_are_refused(model, command, words):
    refused(model, command, *words)


def test_an_unreachable_compact_placement_is_refused_with_the_placement_reason(model):
    # a joint turned back onto the chain: compact placement with a fixed pose may find no link
    command = AddJoint(
        "RevoluteJoint", {}, SE3.Rx(math.pi), after=2, placement="pose", relative=True
    )
    result = model.apply(command)
    if not result.ok:  # depends on the geometry; when refused, nothing changed
        assert result.reason and model.undo_labels == ()


# --- delete --------------------------------------------------------------------------------------
def test_delete_removes_the_joint_and_its_name(model):
    n = len(model.chain.Joints)
    assert model.apply(DeleteJoint("revolute")).ok
    assert len(model.chain.Joints) == n - 1
    assert "revolute" not in model.document.names
    assert model.selected == 3


def test_the_last_joint_cannot_be_deleted():
    model = example_model()
    while len(model.chain.Joints) > 1:
        assert model.delete(-1).ok
    refused(model, DeleteJoint(0), "only joint")


# --- parameters, names, states -------------------------------------------------------------------
def test_changing_parameters_keeps_pose_state_and_other_joints(model):
    j = model.document.names.index("revolute")
    assert model.set_state("revolute", 0.4).ok
    pose = model.chain.Joints[j].pose_matrix.copy()
    others = [k.pose_matrix.tobytes() for k in model.chain.Joints[j + 1 :]]
    assert model.apply(SetJointParameters("revolute", {"numSinkLayers": 2})).ok
    joint = model.chain.Joints[j]
    assert joint.numSinkLayers == 2 and joint.state == 0.4
    assert np.array_equal(joint.pose_matrix, pose)
    assert [k.pose_matrix.tobytes() for k in model.chain.Joints[j + 1 :]] == others
    assert model.document.names[j] == "revolute"


def test_changing_the_root_parameters(model):
    assert model.apply(SetJointParameters(0, {"length": 2.0})).ok
    assert model.chain.Joints[0].length == 2.0


def test_parameters_that_strand_the_state_are_refused(model):
    assert model.set_state("revolute", 1.0).ok
    refused(model, SetJointParameters("revolute", {"totalBendingAngle": 1.0}), "state 1.0",
            "[-0.5, 0.5]")  # fmt: skip


def test_parameters_of_another_type_are_refused(model):
    refused(model, SetJointParameters("revolute", {"neutralLength": 2.0}), "neutralLength",
            "RevoluteJoint")  # fmt: skip


def test_rename_and_unname(model):
    assert model.apply(RenameJoint(1, "w1")).ok
    assert model.document.names[1] == "w1"
    assert model.apply(RenameJoint("w1", None)).ok
    assert model.document.names[1] is None
    refused(model, RenameJoint(1, "end"), "already the name", "joint 6")
    refused(model, RenameJoint(1, 5), "name", "string")


def test_renaming_to_its_own_name_is_allowed(model):
    assert model.apply(RenameJoint("end", "end")).ok


def test_set_state_moves_the_later_joints(model):
    end = model.chain.Joints[-1].pose_matrix.copy()
    assert model.apply(SetJointState("revolute", 0.5)).ok
    assert model.chain.Joints[model.document.names.index("revolute")].state == 0.5
    assert not np.array_equal(model.chain.Joints[-1].pose_matrix, end)


@pytest.mark.parametrize(
    ("command", "words"),
    [
        (SetJointState("revolute", 2.0), ["state", "revolute", "[-1.5708, 1.5708]", "2.0"]),
        (SetJointState("prismatic", 100.0), ["state", "prismatic", "length", "100.0"]),
        (SetJointState(0, 0.1), ["joint 0", "[0, 0]"]),
        (SetJointStates([0.0] * 3), ["one value per joint (7)", "3"]),
        (SetJointStates([0.0] * 6 + [1.0]), ["states[6]", "[0, 0]"]),
        (SetJointStates("0000000"), ["states", "sequence"]),
    ],
)
def test_bad_states_are_refused(model, command, words):
    refused(model, command, *words)


def test_set_all_states(model):
    states = [0.0] * 7
    states[model.document.names.index("revolute")] = -0.3
    states[model.document.names.index("prismatic")] = 0.5
    assert model.apply(SetJointStates(states)).ok
    assert [j.state for j in model.chain.Joints] == states


# --- options -------------------------------------------------------------------------------------
def test_max_angle_per_elbow_relinks_every_link(model):
    assert model.apply(SetOptions(maxAnglePerElbow=math.pi / 4)).ok
    assert model.chain.maxAnglePerElbow == math.pi / 4
    counts = [k.elbows1.count + k.elbows2.count for k in model.chain.Links]
    assert max(counts) >= 2


def test_require_clearance_cannot_be_turned_on_while_colliding(model):
    assert model.set_states(colliding_states(model)).ok
    refused(model, SetOptions(requireClearance=True), "requireClearance", "passes through")


def test_require_clearance_on_and_off(model):
    assert model.apply(SetOptions(requireClearance=True)).ok
    assert model.chain.requireClearance
    assert '"requireClearance": true' in model.to_design_text()
    assert model.apply(SetOptions(requireClearance=False)).ok
    assert not model.chain.requireClearance
    model.undo()
    assert model.chain.requireClearance


def test_texts_units_and_twist_portion(model):
    assert model.apply(SetOptions(name="arm", description=None, units="mm", twistPortion=0.3)).ok
    d = model.document
    assert (d.name, d.description, d.units, d.twistPortion) == ("arm", None, "mm", 0.3)
    assert '"twistPortion": 0.3' in model.to_design_text()
    refused(model, SetOptions(units="km"), "units", "'km'")
    refused(model, SetOptions(twistPortion=1.0), "twistPortion", "[0, 1)")
    refused(model, SetOptions(maxAnglePerElbow=0.0), "maxAnglePerElbow", "pi/180")
    refused(model, SetOptions(requireClearance="no"), "requireClearance", "'no'")


# --- compact -------------------------------------------------------------------------------------
def test_compact_keeps_names_and_shortens(model):
    from concurrent.futures import ThreadPoolExecutor

    from kinegami.optimize import tube_length

    before = tube_length(model.chain)
    with ThreadPoolExecutor(1) as pool:
        result = model.apply(Compact(seed=0, starts=1, executor=pool))
    assert result.ok, result.reason
    assert tube_length(model.chain) <= before + 1e-9
    named = [n for n in model.document.names if n is not None]
    assert named == ["start", "prismatic", "revolute", "end"]
    assert model.undo().ok and tube_length(model.chain) == before


def test_compact_with_bad_options_is_refused(model):
    assert "objective" in model.compact(objective="short").reason
    assert "seed must be an integer >= 0, got -1" in model.compact(seed=-1).reason
    assert not model.compact(colour="red").ok
