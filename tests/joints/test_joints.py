"""Joints: per-type geometry, frames as functions of the state, balls (spec/chain.md 1, 11.1.10)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import reference_values as ref
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from kinegami import (
    SE3,
    EndTip,
    ExtendedRevoluteJoint,
    KinematicChain,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)
from kinegami.geometry.frames import rotation_about_line

POSE = (SE3.Trans(1.0, -2.0, 0.5) * SE3.RPY(0.3, -0.7, 1.9)).A


def at_state(joint, state):
    """The joint inside a one-joint chain, set to ``state`` (states are set through chains)."""
    chain = KinematicChain(joint)
    assert chain.setJointState(0, state) is True
    return chain.Joints[0]


# --- per-type data (chain.md 1.3) ------------------------------------------------------------


@pytest.mark.parametrize("n", sorted(ref.REVOLUTE_PI))
def test_revolute_neutral_length_reference(n):
    joint = RevoluteJoint(n, 1, math.pi, SE3())
    expected = ref.REVOLUTE_PI[n]
    assert joint.neutralLength == pytest.approx(expected["neutral_length"], abs=ref.ATOL)
    if "bounding_radius" in expected:
        assert joint.boundingBall().r == pytest.approx(expected["bounding_radius"], abs=ref.ATOL)


@pytest.mark.parametrize("n", [4, 6, 8, 12])
@pytest.mark.parametrize("r", [0.02, 1.0, 37.5])
@pytest.mark.parametrize("bend", [0.3, math.pi, 1.9 * math.pi])
def test_revolute_data(n, r, bend):
    joint = RevoluteJoint(n, r, bend, POSE)
    L = 2 * r * math.cos(math.pi / n) * math.tan(bend / 4)
    assert joint.neutralLength == pytest.approx(L, rel=1e-14)
    assert joint.pathIndex() == 0
    assert joint.stateRange() == pytest.approx((-bend / 2, bend / 2), rel=1e-15)
    assert joint.boundingBall().r == pytest.approx(math.hypot(r, L / 2), rel=1e-14)
    np.testing.assert_array_equal(joint.boundingBall().c, POSE[:3, 3])
    assert joint.state == 0.0 and joint.r == r and joint.numSides == n


def test_extended_revolute_data():
    joint = ExtendedRevoluteJoint(6, 2.0, math.pi / 2, 0.75, POSE)
    L = 2 * 2.0 * math.cos(math.pi / 6) * math.tan(math.pi / 8) + 2 * 0.75
    assert joint.neutralLength == pytest.approx(L, rel=1e-14)
    assert joint.pathIndex() == 0
    assert joint.stateRange() == pytest.approx((-math.pi / 4, math.pi / 4))
    assert joint.boundingBall().r == pytest.approx(math.hypot(2.0, L / 2))


@pytest.mark.parametrize("cone", [math.pi / 6 + 1e-9, math.pi / 4, math.pi / 3, 1.5])
@pytest.mark.parametrize("length, layers", [(3.0, 3), (0.1, 1), (40.0, 7)])
def test_prismatic_data(cone, length, layers):
    joint = PrismaticJoint(4, 1.5, length, layers, cone, POSE)
    assert joint.neutralLength == length
    assert joint.pathIndex() == 2
    lo, hi = joint.stateRange()
    assert lo == pytest.approx(length / (2 * math.sin(cone)) - length, abs=1e-12 * length)
    assert hi == pytest.approx(length / math.sin(cone) - length, abs=1e-12 * length)
    assert lo <= 0.0 <= hi
    assert joint.boundingBall().r == pytest.approx(math.hypot(1.5, length / 2))


def test_prismatic_state_range_contains_zero_at_the_smallest_cone_angle():
    joint = PrismaticJoint(4, 1, 3, 3, math.pi / 6, SE3())
    lo, hi = joint.stateRange()
    assert lo <= 0.0 <= hi
    chain = KinematicChain(joint)
    assert chain.setJointState(0, 0.0) is True


@pytest.mark.parametrize("k", [0, 1, 2])
def test_waypoint_data(k):
    joint = Waypoint(6, 0.7, POSE, pathIndex=k)
    assert joint.pathIndex() == k
    assert joint.neutralLength == 0.0
    assert joint.stateRange() == (0.0, 0.0)
    assert joint.boundingBall().r == 0.7
    np.testing.assert_array_equal(joint.proximal_frame(), POSE)
    np.testing.assert_array_equal(joint.distal_frame(), POSE)


def test_waypoint_default_path_index_is_z():
    assert Waypoint(4, 1, SE3()).pathIndex() == 2


@pytest.mark.parametrize("kind", [StartTip, EndTip])
def test_tip_data(kind):
    joint = kind(4, 2.0, POSE, 1.5)
    assert joint.pathIndex() == 2
    assert joint.neutralLength == 1.5
    assert joint.stateRange() == (0.0, 0.0)
    assert joint.boundingBall().r == pytest.approx(math.hypot(2.0, 0.75))


# --- frames (chain.md 1.2, 11.1 item 10) ------------------------------------------------------


def all_joints(pose=POSE):
    return [
        RevoluteJoint(4, 1.0, math.pi, pose),
        ExtendedRevoluteJoint(6, 1.0, 2.0, 0.5, pose),
        PrismaticJoint(6, 1.0, 3.0, 3, math.pi / 4, pose),
        Waypoint(4, 1.0, pose, pathIndex=0),
        Waypoint(4, 1.0, pose, pathIndex=1),
        Waypoint(4, 1.0, pose, pathIndex=2),
        StartTip(4, 1.0, pose, 1.5),
        EndTip(4, 1.0, pose, 1.5),
    ]


@pytest.mark.parametrize("joint", all_joints(), ids=lambda j: type(j).__name__)
def test_state_zero_frames(joint):
    a = POSE[:3, joint.pathIndex()]
    L = joint.neutralLength
    for frame, sign in ((joint.proximal_frame(), -1), (joint.distal_frame(), 1)):
        np.testing.assert_allclose(frame[:3, 3], POSE[:3, 3] + sign * L / 2 * a, rtol=0, atol=1e-14)
        np.testing.assert_array_equal(frame[:3, :3], POSE[:3, :3])
    np.testing.assert_array_equal(joint.path_direction(), a)


@pytest.mark.parametrize("joint", all_joints(), ids=lambda j: type(j).__name__)
def test_dubins_frames_permute_the_axes(joint):
    k = joint.pathIndex()
    for frame, dubins in (
        (joint.proximal_frame(), joint.proximal_dubins_frame()),
        (joint.distal_frame(), joint.distal_dubins_frame()),
    ):
        for column in range(3):
            np.testing.assert_array_equal(dubins[:3, column], frame[:3, (k + column) % 3])
        np.testing.assert_array_equal(dubins[:3, 3], frame[:3, 3])
        assert np.linalg.det(dubins[:3, :3]) == pytest.approx(1.0, abs=1e-12)


@pytest.mark.parametrize("joint", all_joints(), ids=lambda j: type(j).__name__)
def test_se3_accessors_equal_the_arrays(joint):
    np.testing.assert_array_equal(joint.Pose.A, joint.pose_matrix)
    for name in ("proximal_frame", "distal_frame", "proximal_dubins_frame", "distal_dubins_frame"):
        published = "".join(part.capitalize() for part in name.split("_"))
        np.testing.assert_array_equal(getattr(joint, published)().A, getattr(joint, name)())


def test_pose_is_read_only():
    joint = RevoluteJoint(4, 1, math.pi, POSE)
    with pytest.raises(ValueError):
        joint.pose_matrix[0, 3] = 5.0
    np.testing.assert_array_equal(joint.pose_matrix, POSE)


@pytest.mark.parametrize("state", [-1.5, -0.3, 0.0, 0.8, math.pi / 2])
def test_revolute_distal_frame_rotates_about_the_axis(state):
    joint = at_state(RevoluteJoint(4, 1.0, math.pi, POSE), state)
    neutral = RevoluteJoint(4, 1.0, math.pi, POSE).distal_frame()
    expected = rotation_about_line(POSE[:3, 2], POSE[:3, 3], state) @ neutral
    np.testing.assert_allclose(joint.distal_frame(), expected, rtol=0, atol=1e-14)
    # the proximal frame and the Pose do not move
    np.testing.assert_array_equal(joint.pose_matrix, POSE)
    np.testing.assert_array_equal(
        joint.proximal_frame(), RevoluteJoint(4, 1.0, math.pi, POSE).proximal_frame()
    )


@pytest.mark.parametrize("fraction", [0.0, 0.25, 1.0])
def test_prismatic_distal_frame_and_ball_follow_the_state(fraction):
    template = PrismaticJoint(4, 1.0, 3.0, 3, math.pi / 4, POSE)
    lo, hi = template.stateRange()
    state = lo + fraction * (hi - lo)
    joint = at_state(template, state)
    z = POSE[:3, 2]
    np.testing.assert_allclose(
        joint.distal_frame()[:3, 3], POSE[:3, 3] + (1.5 + state) * z, rtol=0, atol=1e-14
    )
    np.testing.assert_array_equal(joint.distal_frame()[:3, :3], POSE[:3, :3])
    ball = joint.boundingBall()
    np.testing.assert_allclose(ball.c, POSE[:3, 3] + state / 2 * z, rtol=0, atol=1e-14)
    assert ball.r == pytest.approx(math.hypot(1.0, (3.0 + state) / 2))
    # the ball covers the proximal-to-distal segment with the tube around it
    for end in (joint.proximal_frame()[:3, 3], joint.distal_frame()[:3, 3]):
        assert np.linalg.norm(end - ball.c) ** 2 + 1.0 <= ball.r**2 + 1e-12


def test_joints_are_copied_when_added(example_1a_factory):
    joint = RevoluteJoint(4, 1, math.pi, SE3.Ry(math.pi / 4))
    before = joint.pose_matrix.copy()
    chain = example_1a_factory()
    chain.delete(-1)
    chain.append(joint)
    np.testing.assert_array_equal(joint.pose_matrix, before)
    assert joint.state == 0.0
    assert all(j is not joint for j in chain.Joints)


# --- properties ------------------------------------------------------------------------------

quaternions = st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda q: math.hypot(*q) > 0.1)


@settings(deadline=None, max_examples=60)
@given(
    quaternion=quaternions,
    origin=st.tuples(*[st.floats(-100, 100)] * 3),
    r=st.floats(0.02, 50),
    fraction=st.floats(0, 1),
)
def test_random_revolute_and_prismatic_frames(quaternion, origin, r, fraction):
    T = np.eye(4)
    T[:3, :3] = Rotation.from_quat(quaternion).as_matrix()
    T[:3, 3] = origin
    tol = 1e-12 * max(1.0, float(np.abs(T[:3, 3]).max()), r)
    for template in (RevoluteJoint(6, r, 2.0, T), PrismaticJoint(6, r, 2 * r, 2, 0.9, T)):
        lo, hi = template.stateRange()
        state = lo + fraction * (hi - lo)
        joint = at_state(template, state)
        G = template.state_transform(state)
        np.testing.assert_allclose(
            joint.distal_frame(), G @ template.distal_frame(), rtol=0, atol=tol
        )
        # the distal frame is a proper rigid frame
        R = joint.distal_frame()[:3, :3]
        np.testing.assert_allclose(R.T @ R, np.eye(3), rtol=0, atol=1e-12)
        # distance from the axis is kept by the motion
        p, z = T[:3, 3], T[:3, 2]
        before = template.distal_frame()[:3, 3] - p
        after = joint.distal_frame()[:3, 3] - p
        assert np.linalg.norm(np.cross(after, z)) == pytest.approx(
            np.linalg.norm(np.cross(before, z)), abs=tol
        )
