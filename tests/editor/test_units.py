"""Typed values and units without a browser: the editor's unit wording and conversions
(kinegami.editor.units), the pose command (SetJointPose) and typed parameters and states
through the model, refused values leaving the document exactly as it was (docs/editor.md,
Typed values and Units)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest
from numpy.testing import assert_allclose

from kinegami.editor import EditorModel, SetJointPose
from kinegami.editor import units as u
from kinegami.errors import InvalidParameterError

from .helpers import ROOT, example_model, hand_model, snapshot

PUMA = ROOT / "examples" / "designs" / "puma.json"


# --- wording ------------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("value", "text"),
    [(2.223, "2.22"), (1367.77, "1368"), (0.5, "0.5"), (0.000123456, "0.000123"), (0.0, "0"),
     (-1.5708, "-1.57"), (25.0, "25"), (-0.0000001, "0"), (100.0, "100"), (12.0, "12")],
)  # fmt: skip
def test_number_text_has_three_significant_digits_and_no_exponent(value, text):
    assert u.number_text(value) == text


def test_lengths_name_the_unit_and_angles_are_degrees():
    assert u.length_text(2.223, "mm") == "2.22 mm"
    assert u.length_text(1.5, "cm") == "1.5 cm"
    assert u.angle_text(math.pi / 2) == "90°"
    assert u.angle_text(-math.pi / 4) == "-45°"
    assert u.state_text("RevoluteJoint", math.pi / 2, "mm") == "90°"
    assert u.state_text("PrismaticJoint", 1.5, "cm") == "1.5 cm"
    assert u.state_unit("ExtendedRevoluteJoint", "in") == "deg"
    assert u.state_unit("PrismaticJoint", "in") == "in"
    assert u.state_unit("Waypoint", "in") == ""


def test_parameter_units_and_conversions():
    assert [u.parameter_unit(k, "cm") for k in ("totalBendingAngle", "coneAngle", "tubeLength",
                                                 "neutralLength", "length", "numSinkLayers")] == [
        "deg", "deg", "cm", "cm", "cm", ""]  # fmt: skip
    assert u.parameter_to_display("totalBendingAngle", math.pi) == pytest.approx(180.0)
    assert u.parameter_from_display("coneAngle", 45.0) == pytest.approx(math.pi / 4)
    assert u.parameter_from_display("tubeLength", 2.5) == 2.5
    assert u.parameter_from_display("numSinkLayers", 2.0) == 2
    assert isinstance(u.parameter_from_display("numSinkLayers", 2.0), int)
    assert u.parameter_from_display("numSinkLayers", 2.5) == 2.5  # refused by the command
    assert u.state_from_display("RevoluteJoint", 90) == pytest.approx(math.pi / 2)
    assert u.state_from_display("PrismaticJoint", 1.25) == 1.25


def test_pose_round_trips_through_position_and_fixed_axis_angles():
    rng = np.random.default_rng(3)
    from scipy.spatial.transform import Rotation

    for _ in range(50):
        T = np.eye(4)
        T[:3, :3] = Rotation.random(random_state=rng).as_matrix()
        T[:3, 3] = rng.normal(scale=100.0, size=3)
        position, angles = u.pose_to_display(T)
        assert_allclose(u.pose_from_display(position, angles), T, atol=1e-9)


def test_fixed_axis_angles_are_roll_about_x_then_pitch_about_y_then_yaw_about_z():
    T = u.pose_from_display((1, 2, 3), (90, 0, 0))
    assert_allclose(T[:3, :3] @ [0, 1, 0], [0, 0, 1], atol=1e-12)  # roll: y turns into z
    T = u.pose_from_display((0, 0, 0), (90, 0, 90))  # roll, then yaw about the world z
    assert_allclose(T[:3, :3] @ [1, 0, 0], [0, 1, 0], atol=1e-12)  # (intrinsic: z)
    T = u.pose_from_display((0, 0, 0), (0, 90, 0))
    assert_allclose(T[:3, :3] @ [1, 0, 0], [0, 0, -1], atol=1e-12)
    assert_allclose(T[:3, 3], [0, 0, 0])
    assert u.pose_to_display(np.eye(4)) == ((0.0, 0.0, 0.0), (0.0, 0.0, 0.0))


@pytest.mark.parametrize(
    ("position", "angles", "message"),
    [((0, 0, float("nan")), (0, 0, 0), "position z must be a finite number, got nan"),
     ((0, 0, 0), (0, "a", 0), "orientation y must be a finite number, got 'a'"),
     ((0, 0), (0, 0, 0), "position must be three numbers, got 2"),
     ((0, 0, 0), None, "orientation must be three numbers, got None")],
)  # fmt: skip
def test_a_bad_typed_pose_names_the_field(position, angles, message):
    with pytest.raises(InvalidParameterError, match="^" + re.escape(message)):
        u.pose_from_display(position, angles)


# --- SetJointPose ---------------------------------------------------------------------------------
def test_set_pose_puts_a_waypoint_where_typed_and_undo_gives_the_document_back():
    model = example_model()
    before = snapshot(model.document)
    target = model.chain.Joints[3].pose_matrix.copy()
    target[:3, 3] += (0.5, -0.25, 0.75)
    result = model.set_pose(3, target)
    assert result.ok, result.reason
    assert_allclose(model.chain.Joints[3].pose_matrix, target, atol=1e-12)
    assert model.undo_labels == ("set pose of joint 3",)
    assert model.undo().ok
    assert snapshot(model.document) == before


def test_set_pose_of_a_revolute_joint_changes_its_axis_and_the_later_joints_follow():
    model = example_model()
    last = model.chain.Joints[-1].pose_matrix.copy()
    old = model.chain.Joints[4].pose_matrix.copy()
    position, angles = u.pose_to_display(old)
    target = u.pose_from_display(position, (angles[0], angles[1], angles[2] + 30.0))
    assert model.set_pose("revolute", target, propagate=True).ok
    assert_allclose(model.chain.Joints[4].pose_matrix, target, atol=1e-12)
    moved = target @ np.linalg.inv(old)
    assert_allclose(model.chain.Joints[-1].pose_matrix, moved @ last, atol=1e-9)


def test_set_pose_without_propagation_keeps_the_later_joints():
    model = example_model()
    last = model.chain.Joints[-1].pose_matrix.copy()
    target = model.chain.Joints[3].pose_matrix.copy()
    target[:3, 3] += (0.0, 0.0, 0.5)
    assert model.set_pose(3, target, propagate=False).ok
    assert_allclose(model.chain.Joints[-1].pose_matrix, last, atol=0)


@pytest.mark.filterwarnings("ignore::kinegami.errors.ClearanceWarning")  # the hand as designed
def test_set_pose_on_a_tree_moves_the_subtree():
    model = hand_model()
    others = [model.chain.Joints[k].pose_matrix.copy() for k in (1, 2, 8, 9)]
    target = model.chain.Joints[5].pose_matrix.copy()
    target[:3, 3] += (0.0, 0.5, 0.0)
    assert model.set_pose(5, target).ok, model.set_pose(5, target).reason
    assert_allclose(model.chain.Joints[5].pose_matrix, target, atol=1e-12)
    for k, pose in zip((1, 2, 8, 9), others, strict=True):
        assert_allclose(model.chain.Joints[k].pose_matrix, pose, atol=0)


@pytest.mark.parametrize(
    ("pose", "reason"),
    [(np.eye(3), "pose must be a 4x4 rigid transform, got an array of shape (3, 3)"),
     (np.diag([2.0, 1.0, 1.0, 1.0]), "pose must be a rigid transform"),
     ("up", "pose must be a 4x4 rigid transform"),
     (np.array([[1, 0, 0, 1e9], [0, 1, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]], dtype=float),
      "pose translation must be within +-1e6 r")],
)  # fmt: skip
def test_a_refused_pose_leaves_the_document_exactly_as_it_was(pose, reason):
    model = example_model()
    before, document = snapshot(model.document), model.document
    result = model.apply(SetJointPose(3, pose))
    assert not result.ok and result.reason.startswith(reason), result.reason
    assert model.document is document and snapshot(model.document) == before
    assert not model.can_undo


def test_a_pose_the_chain_cannot_link_is_refused_with_the_chains_reason():
    model = example_model()
    before = snapshot(model.document)
    target = model.chain.Joints[5].pose_matrix.copy()
    target[:3, 3] = model.chain.Joints[4].pose_matrix[:3, 3]  # on top of joint 4
    result = model.set_pose(5, target, propagate=False)
    assert not result.ok
    assert result.reason.startswith("set pose of joint 5 (Waypoint")
    assert snapshot(model.document) == before


# --- typed parameters and states ------------------------------------------------------------------
def test_typed_parameters_in_degrees_and_units_reach_the_joint():
    model = example_model()
    typed = {"totalBendingAngle": 120.0, "numSinkLayers": 2.0}
    assert model.set_parameters(4, **u.parameters_from_display(typed)).ok
    parameters = model.joint_table()[4].parameters
    assert parameters["totalBendingAngle"] == pytest.approx(math.radians(120.0))
    assert parameters["numSinkLayers"] == 2
    typed = {"neutralLength": 2.5, "numLayers": 4.0, "coneAngle": 50.0}
    assert model.set_parameters(2, **u.parameters_from_display(typed)).ok
    parameters = model.joint_table()[2].parameters
    assert parameters["neutralLength"] == 2.5 and parameters["numLayers"] == 4
    assert parameters["coneAngle"] == pytest.approx(math.radians(50.0))
    assert model.set_parameters(6, **u.parameters_from_display({"length": 2.0})).ok
    assert model.joint_table()[6].parameters["length"] == 2.0
    assert len(model.undo_labels) == 3


@pytest.mark.parametrize(
    ("joint", "typed", "reason"),
    [(4, {"numSinkLayers": 2.5}, "numSinkLayers must be an integer in [1, 32], got 2.5"),
     (4, {"numSinkLayers": 0.0}, "numSinkLayers must be an integer in [1, 32], got 0"),
     (4, {"totalBendingAngle": 400.0}, "totalBendingAngle must be in (0, 2pi) radians (0° to "
                                       "360°), got 6.981317007977318 (400°)"),
     (2, {"coneAngle": 20.0}, "coneAngle must be in [pi/6, pi/2) radians ([30°, 90°)), got "
                              "0.3490658503988659 (20°)"),
     (2, {"neutralLength": -1.0}, "neutralLength must be > 0"),
     (6, {"length": 0.0}, "length must be > 0")],
)  # fmt: skip
def test_a_refused_typed_parameter_gives_the_reason_and_keeps_the_document(joint, typed, reason):
    model = example_model()
    before, document = snapshot(model.document), model.document
    result = model.set_parameters(joint, **u.parameters_from_display(typed))
    assert not result.ok and result.reason.startswith(reason), result.reason
    assert model.document is document and snapshot(model.document) == before


def test_typed_states_in_degrees_and_in_the_unit():
    model = example_model()
    assert model.set_state(4, u.state_from_display("RevoluteJoint", 45.0)).ok
    assert model.chain.Joints[4].state == pytest.approx(math.pi / 4)
    lo, hi = model.chain.Joints[2].stateRange()
    assert model.set_state(2, u.state_from_display("PrismaticJoint", 0.5 * hi)).ok
    assert model.chain.Joints[2].state == pytest.approx(0.5 * hi)


def test_a_refused_typed_state_names_both_units_and_keeps_the_document():
    model = example_model()
    before, document = snapshot(model.document), model.document
    result = model.set_state(4, u.state_from_display("RevoluteJoint", 120.0))
    assert not result.ok
    assert result.reason == (
        "state of joint 4 (RevoluteJoint 'revolute') must be in [-1.5708, 1.5708] radians "
        "([-90°, 90°]), got 2.0943951023931953 (120°)"
    )
    assert model.document is document and snapshot(model.document) == before
    lo, hi = model.chain.Joints[2].stateRange()
    result = model.set_state(2, hi + 1.0)
    assert not result.ok
    assert f"(a length, {model.document.units}), got" in result.reason, result.reason


def test_the_puma_is_in_mm_and_its_states_read_in_degrees():
    model = EditorModel.open(PUMA)
    assert model.document.units == "mm" and float(model.chain.r) == 25.0
    row = next(row for row in model.joint_table() if row.movable)
    lo, hi = (u.state_to_display(row.type, v) for v in row.state_range)
    assert (lo, hi) == (pytest.approx(-90.0), pytest.approx(90.0))


def test_a_typed_move_keeps_the_joints_rotation_bit_for_bit():
    model = example_model()
    target = model.chain.Joints[4].pose_matrix.copy()
    target[:3, 3] += (0.125, 0.0, -0.25)
    assert model.set_pose(4, target).ok
    assert np.array_equal(model.chain.Joints[4].pose_matrix[:3, :3], target[:3, :3])
