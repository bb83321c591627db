"""Reference values of spec/chain.md 11.2-11.6 and the deterministic edits of section 5.

Every expected number comes from ``reference_values``; the chains are built as the spec says.
"""

from __future__ import annotations

import contextlib
import math
import warnings

import numpy as np
import pytest
import reference_values as ref
from spatialmath import SE3

from kinegami import (
    ClearanceWarning,
    EndTip,
    KinematicChain,
    LinkCSC,
    PlacementWarning,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)


def assert_close(actual, expected, atol=ref.ATOL):
    np.testing.assert_allclose(
        np.asarray(actual, dtype=float), np.asarray(expected, float), rtol=0.0, atol=atol
    )


def origin(joint):
    return joint.pose_matrix[:3, 3]


@contextlib.contextmanager
def no_warnings():
    """Turn any PlacementWarning (a rejected operation) into an error."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)
        yield


# --- Example 1A (chain.md 11.2) --------------------------------------------------------------


def test_example_1a_append_returns_the_new_joint_indices(example_1a_append_results):
    assert example_1a_append_results == ref.EXAMPLE_1A_APPEND_RESULTS


@pytest.mark.parametrize("i", range(len(ref.EXAMPLE_1A_JOINTS)))
def test_example_1a_joint(example_1a, i):
    expected = ref.EXAMPLE_1A_JOINTS[i]
    joint = example_1a.Joints[i]
    assert type(joint).__name__ == expected["type"]
    assert example_1a.Parents[i] == expected["parent"]
    assert joint.pathIndex() == expected["path_index"]
    assert_close(joint.pose_matrix[:3, 0], expected["x"])
    assert_close(joint.pose_matrix[:3, 2], expected["z"])
    assert_close(origin(joint), expected["origin"])
    assert joint.state == 0.0


@pytest.mark.parametrize("i", range(1, len(ref.EXAMPLE_1A_LINKS) + 1))
def test_example_1a_link(example_1a, i):
    theta1, s, theta2, length, elbows, phis, twist = ref.EXAMPLE_1A_LINKS[i - 1]
    link = example_1a.Links[i]
    assert_close(
        [link.path.theta1, link.path.tMag, link.path.theta2, link.path.length],
        [theta1, s, theta2, length],
    )
    assert (link.elbows1.count, link.elbows2.count) == elbows
    if phis is not None:
        assert_close([link.elbows1.rotationalAxisAngle, link.elbows2.rotationalAxisAngle], phis)
    assert_close(link.twistAngle, twist)


def test_example_1a_root_link_is_empty(example_1a):
    root = example_1a.Links[0]
    assert (root.path.theta1, root.path.tMag, root.path.theta2) == (0.0, 0.0, 0.0)
    assert (root.elbows1.count, root.elbows2.count) == (0, 0)
    np.testing.assert_array_equal(root.start_frame, example_1a.Joints[0].proximal_dubins_frame())


def test_example_1a_total_path_length(example_1a):
    assert_close(example_1a.totalPathLength(), ref.EXAMPLE_1A_TOTAL_LENGTH)


def test_example_1a_incremental_ball(example_1a):
    assert_close(example_1a.boundingBall.c, ref.EXAMPLE_1A_BALL["c"])
    assert_close(example_1a.boundingBall.r, ref.EXAMPLE_1A_BALL["r"])


def test_example_1a_recomputed_ball(example_1a):
    returned = example_1a.recomputeBoundingBall()
    for ball in (returned, example_1a.boundingBall):
        assert_close(ball.c, ref.EXAMPLE_1A_BALL_RECOMPUTED["c"])
        assert_close(ball.r, ref.EXAMPLE_1A_BALL_RECOMPUTED["r"])


def test_incremental_ball_leaves_out_the_root_links_arc_balls():
    """chain.md 3.3: the first ball is the root joint's; the root's empty link only enters on
    recompute. Its arc ball (root proximal origin, r) then sticks out of the incremental ball
    (a spec-level inconsistency with 11.1 item 9, kept for the reference numbers)."""
    chain = KinematicChain(StartTip(4, 1, SE3(), 1.5))
    root_ball = chain.Links[0].arc1Ball
    assert_close(root_ball.c, (0, 0, -0.75), atol=1e-15)
    assert root_ball.r == 1.0
    assert not chain.boundingBall.contains(root_ball)
    assert chain.recomputeBoundingBall().contains(root_ball)


def test_example_1a_first_ball_is_the_start_tips():
    start = ref.EXAMPLE_1A_START
    chain = KinematicChain(StartTip(4, 1, Pose=SE3.Trans(*start["origin"]), length=start["length"]))
    assert_close(chain.boundingBall.c, ref.EXAMPLE_1A_FIRST_BALL["c"])
    assert_close(chain.boundingBall.r, ref.EXAMPLE_1A_FIRST_BALL["r"])


def test_example_1a_first_waypoint_and_far_plane(example_1a):
    assert_close(origin(example_1a.Joints[1]), ref.EXAMPLE_1A_W1)
    # far plane: tangent plane + 4r + rho(prismatic) = 1.25 + 4 + sqrt(1 + 1.5^2)
    far = ref.EXAMPLE_1A_W1[2] + 4 + math.hypot(1, 1.5)
    assert_close(far, ref.EXAMPLE_1A_FAR_PLANE_Z)
    assert_close(origin(example_1a.Joints[2])[2], ref.EXAMPLE_1A_FAR_PLANE_Z)


def test_example_1a_link_2_derivation(example_1a):
    link = example_1a.Links[2]
    expected = ref.EXAMPLE_1A_LINK2
    assert_close(link.path.q1, expected["q1"])
    assert_close(link.path.q2, expected["q2"])
    assert_close(link.path.tUnit, expected["u"])
    for ball, name in ((link.arc1Ball, "arc1_ball"), (link.arc2Ball, "arc2_ball")):
        assert_close(ball.c, expected[name]["c"])
        assert_close(ball.r, expected[name]["r"])


@pytest.mark.parametrize("i", sorted(ref.EXAMPLE_1A_PROXIMAL_DISTAL))
def test_example_1a_proximal_and_distal_origins(example_1a, i):
    proximal, distal = ref.EXAMPLE_1A_PROXIMAL_DISTAL[i]
    joint = example_1a.Joints[i]
    assert_close(joint.proximal_frame()[:3, 3], proximal)
    assert_close(joint.distal_frame()[:3, 3], distal)
    assert_close(joint.ProximalFrame().t, proximal)
    assert_close(joint.DistalFrame().t, distal)


def test_example_1a_invariants(example_1a, chain_checker):
    chain_checker(example_1a)


# --- Example 1B (chain.md 11.3) --------------------------------------------------------------


@pytest.mark.parametrize("step", range(1, len(ref.EXAMPLE_1B_STEPS) + 1))
def test_example_1b_step(example_1a, example_1b_steps, chain_checker, step):
    with no_warnings():
        results = example_1b_steps(example_1a, step)
    assert results == [True] * step
    expected = ref.EXAMPLE_1B_RESULTS[step - 1]
    assert_close(example_1a.totalPathLength(), expected["total_length"])
    assert_close(example_1a.boundingBall.r, expected["ball_r"])
    assert_close(origin(example_1a.Joints[6]), expected["end_origin"])
    assert_close(origin(example_1a.Joints[4]), expected["revolute_origin"])
    chain_checker(example_1a)


def test_example_1b_after_b4_details(example_1b):
    expected = ref.EXAMPLE_1B_AFTER_B4
    assert_close(origin(example_1b.Joints[2]), expected["prismatic_origin"])
    assert_close(example_1b.Joints[4].pose_matrix[:3, 0], expected["revolute_x"])
    assert_close(origin(example_1b.Joints[5]), expected["waypoint5_origin"])
    for i, (theta1, s, theta2, elbows) in expected["links"].items():
        link = example_1b.Links[i]
        assert_close([link.path.theta1, link.path.tMag, link.path.theta2], [theta1, s, theta2])
        assert (link.elbows1.count, link.elbows2.count) == elbows


def test_example_1b_b4_moves_the_prismatic_alone(example_1a, example_1b_steps):
    example_1b_steps(example_1a, 3)
    before = example_1a.Joints
    method, (j, distance), kwargs = ref.EXAMPLE_1B_STEPS[3]
    assert getattr(example_1a, method)(j, distance, **kwargs) is True
    after = example_1a.Joints
    # B4 (propagate=False) moved joint j only, along its own axis.
    for i, (a, b) in enumerate(zip(before, after, strict=True)):
        if i == j:
            assert_close(origin(b) - origin(a), distance * a.pose_matrix[:3, 2], atol=1e-12)
            np.testing.assert_array_equal(b.pose_matrix[:3, :3], a.pose_matrix[:3, :3])
        else:
            assert snapshot_joint(a) == snapshot_joint(b)


def snapshot_joint(joint):
    return (joint.pose_matrix.tobytes(), joint.state)


# --- Example 1C (chain.md 11.4) --------------------------------------------------------------


def set_example_1c_states(chain):
    lo, hi = chain.Joints[2].stateRange()
    return (chain.setJointState(2, hi), chain.setJointState(4, ref.EXAMPLE_1C_REVOLUTE_STATE))


def test_example_1c_prismatic_state_range(example_1b):
    assert_close(example_1b.Joints[2].stateRange(), ref.EXAMPLE_1C_PRISMATIC_RANGE)


def test_example_1c_states(example_1b, chain_checker):
    with no_warnings():
        assert set_example_1c_states(example_1b) == (True, True)
    expected = ref.EXAMPLE_1C
    joints = example_1b.Joints
    assert_close(origin(joints[3]), expected["waypoint3_origin"])
    assert_close(origin(joints[4]), expected["revolute_origin"])
    assert_close(joints[4].pose_matrix[:3, 0], expected["revolute_x"])
    assert_close(origin(joints[5]), expected["waypoint5_origin"])
    assert_close(joints[5].pose_matrix[:3, 0], expected["waypoint5_x"])
    assert_close(origin(joints[6]), expected["end_origin"])
    assert_close(joints[6].pose_matrix[:3, 2], expected["end_z"])
    assert_close(joints[2].distal_frame()[:3, 3], expected["prismatic_distal_origin"])
    assert_close(joints[4].distal_frame()[:3, 3], expected["revolute_distal_origin"])
    assert_close(example_1b.boundingBall.c, expected["ball"]["c"])
    assert_close(example_1b.boundingBall.r, expected["ball"]["r"])
    assert joints[2].state == joints[2].stateRange()[1]
    assert joints[4].state == ref.EXAMPLE_1C_REVOLUTE_STATE
    chain_checker(example_1b)


def test_example_1c_link_parameters_are_those_of_b4(example_1b):
    before = [(lk.path.theta1, lk.path.tMag, lk.path.theta2) for lk in example_1b.Links]
    set_example_1c_states(example_1b)
    after = [(lk.path.theta1, lk.path.tMag, lk.path.theta2) for lk in example_1b.Links]
    assert after == before


def test_example_1c_revolute_state_out_of_range_is_rejected(example_1b, snapshot):
    set_example_1c_states(example_1b)
    before = snapshot(example_1b)
    with pytest.warns(PlacementWarning):
        assert example_1b.setJointState(4, ref.EXAMPLE_1C_REJECTED_REVOLUTE_STATE) is False
    assert snapshot(example_1b) == before


# --- planar and cylindrical compound joints (chain.md 11.5) ----------------------------------


@pytest.fixture
def planar():
    n = ref.PLANAR_NUM_SIDES
    chain = KinematicChain(RevoluteJoint(n, 1, math.pi, SE3()))
    with no_warnings():
        for _ in range(2):
            assert chain.append(RevoluteJoint(n, 1, math.pi, SE3.Trans(*ref.PLANAR_STEP)))
    return chain


def test_planar_append_indices():
    n = ref.PLANAR_NUM_SIDES
    chain = KinematicChain(RevoluteJoint(n, 1, math.pi, SE3()))
    step = SE3.Trans(*ref.PLANAR_STEP)
    assert chain.append(RevoluteJoint(n, 1, math.pi, step)) == 3
    assert chain.append(RevoluteJoint(n, 1, math.pi, step)) == 6


@pytest.mark.parametrize("i", range(len(ref.PLANAR_JOINTS)))
def test_planar_joint(planar, i):
    expected = ref.PLANAR_JOINTS[i]
    joint = planar.Joints[i]
    assert type(joint).__name__ == expected["type"]
    if "path_index" in expected:
        assert joint.pathIndex() == expected["path_index"]
    assert_close(joint.pose_matrix[:3, 0], expected["x"])
    assert_close(joint.pose_matrix[:3, 2], expected["z"])
    assert_close(origin(joint), expected["origin"])


@pytest.mark.parametrize("i", range(1, len(ref.PLANAR_LINKS) + 1))
def test_planar_link(planar, i):
    theta1, s, theta2, elbows = ref.PLANAR_LINKS[i - 1]
    link = planar.Links[i]
    assert_close([link.path.theta1, link.path.tMag, link.path.theta2], [theta1, s, theta2])
    assert (link.elbows1.count, link.elbows2.count) == elbows


def test_planar_total_length_and_ball(planar, chain_checker):
    assert_close(planar.totalPathLength(), ref.PLANAR_TOTAL_LENGTH)
    assert_close(planar.boundingBall.c, ref.PLANAR_BALL["c"])
    assert_close(planar.boundingBall.r, ref.PLANAR_BALL["r"])
    chain_checker(planar)


def test_planar_deleting_the_waypoints(planar, chain_checker):
    with no_warnings():
        for index in ref.PLANAR_DELETE_INDICES:
            assert planar.delete(index) is True
    assert [type(j).__name__ for j in planar.Joints] == ["RevoluteJoint"] * 3
    for link, expected in zip(planar.Links[1:], ref.PLANAR_AFTER_DELETE_LINKS, strict=True):
        assert_close([link.path.theta1, link.path.tMag, link.path.theta2], expected)
    assert_close(planar.totalPathLength(), ref.PLANAR_AFTER_DELETE_TOTAL)
    chain_checker(planar)


def test_planar_translating_joints_to_the_plane(planar, chain_checker):
    for index in ref.PLANAR_DELETE_INDICES:
        planar.delete(index)
    with no_warnings():
        for i in range(len(planar.Joints)):
            height = float(origin(planar.Joints[i])[2])
            assert planar.translateJointAlongAxisOfMotion(i, -height) is True
    for link in planar.Links[1:]:
        assert_close([link.path.theta1, link.path.theta2], [0, 0])
        assert_close(link.path.tMag, ref.PLANAR_STRAIGHT_LINK)
    assert_close(planar.totalPathLength(), ref.PLANAR_STRAIGHT_TOTAL)
    chain_checker(planar)


def test_cylindrical_variant(planar, chain_checker):
    n = ref.PLANAR_NUM_SIDES
    chain = KinematicChain(RevoluteJoint(n, 1, math.pi, SE3()))
    p = ref.CYLINDRICAL_PRISMATIC
    with no_warnings():
        assert (
            chain.append(
                PrismaticJoint(n, 1, p["neutralLength"], p["numLayers"], p["coneAngle"], SE3())
            )
            == 3
        )
    for i in (1, 2):  # the same two waypoints as the planar example
        np.testing.assert_allclose(
            chain.Joints[i].pose_matrix, planar.Joints[i].pose_matrix, rtol=0, atol=1e-12
        )
    assert_close(origin(chain.Joints[3]), ref.CYLINDRICAL_PRISMATIC_ORIGIN)
    assert_close(chain.totalPathLength(), ref.CYLINDRICAL_TOTAL_LENGTH)
    chain_checker(chain)


# --- compact placement: prismatic spiral (chain.md 11.6) -------------------------------------


def build_spiral(check_clearance=False):
    n = ref.SPIRAL_NUM_SIDES
    p = ref.SPIRAL_PRISMATIC

    def prismatic(pose):
        return PrismaticJoint(n, 1, p["neutralLength"], p["numLayers"], p["coneAngle"], pose)

    chain = KinematicChain(prismatic(SE3()))
    for _ in range(ref.SPIRAL_APPENDS):
        ball = chain.boundingBall
        new = prismatic(SE3.Ry(ref.SPIRAL_RY))
        with no_warnings():
            index = chain.append(new, safe=False)
        assert index == len(chain.Joints) - 1
        if check_clearance:
            placed = chain.Joints[index]
            distance = np.linalg.norm(origin(placed) - ball.c)
            assert distance >= 4 + ball.r + placed.bounding_radius() - 1e-9
    return chain


def test_spiral_joints():
    chain = build_spiral()
    joints = chain.Joints[1:]
    assert len(joints) == ref.SPIRAL_APPENDS
    for joint, o, z, x in zip(joints, ref.SPIRAL_ORIGINS, ref.SPIRAL_Z, ref.SPIRAL_X, strict=True):
        assert_close(origin(joint), o)
        assert_close(joint.pose_matrix[:3, 2], z)
        assert_close(joint.pose_matrix[:3, 0], x)


def test_spiral_links_length_and_ball(chain_checker):
    chain = build_spiral()
    for link, expected in zip(chain.Links[1:], ref.SPIRAL_LINKS, strict=True):
        assert_close([link.path.theta1, link.path.tMag, link.path.theta2], expected)
    assert_close(chain.totalPathLength(), ref.SPIRAL_TOTAL_LENGTH)
    assert_close(chain.boundingBall.c, ref.SPIRAL_BALL["c"])
    assert_close(chain.boundingBall.r, ref.SPIRAL_BALL["r"])
    chain_checker(chain)


def test_spiral_compact_clearance():
    build_spiral(check_clearance=True)


# --- rejections are bit-identical (chain.md 11.1 item 7) -------------------------------------


def test_rejected_rotation_is_bit_identical(example_1a, snapshot):
    before = snapshot(example_1a)
    with pytest.warns(PlacementWarning):
        assert example_1a.rotateJointAboutAxisOfMotion(*ref.REJECT_ROTATE, propagate=False) is False
    assert snapshot(example_1a) == before


def test_rejected_translation_is_bit_identical(example_1a, snapshot):
    before = snapshot(example_1a)
    with pytest.warns(PlacementWarning):
        assert (
            example_1a.translateJointAlongAxisOfMotion(*ref.REJECT_TRANSLATE, propagate=False)
            is False
        )
    assert snapshot(example_1a) == before


def test_rejected_append_is_bit_identical(snapshot):
    spec = ref.REJECT_APPEND
    chain = KinematicChain(StartTip(4, 1, SE3(), spec["start_length"]))
    before = snapshot(chain)
    joint = RevoluteJoint(4, 1, math.pi, SE3.Trans(*spec["translation"]) * SE3.Ry(spec["ry"]))
    with pytest.warns(PlacementWarning):
        result = chain.append(joint, safe=False, fixedPosition=True, fixedOrientation=True)
    assert result is None
    assert len(chain.Joints) == 1
    assert snapshot(chain) == before


@pytest.mark.parametrize("joint, distance", [(4, -1), (2, -1)])
@pytest.mark.parametrize("propagate", [True, False])
def test_rejected_waypoint_edit_is_bit_identical(example_1a, snapshot, joint, distance, propagate):
    before = snapshot(example_1a)
    with pytest.warns(PlacementWarning):
        assert (
            example_1a.translateJointAlongAxisOfMotion(
                joint, distance, propagate=propagate, applyToPreviousWaypoint=True
            )
            is False
        )
    assert snapshot(example_1a) == before


def detour_chain():
    """StartTip -> Waypoint -> EndTip, where the tip sits straight above the start pointing
    down: without the waypoint the link would need a U-turn (deleting it must fail)."""
    chain = KinematicChain(StartTip(4, 1, SE3(), 1.5))
    exact = {"relative": False, "safe": False, "fixedPosition": True, "fixedOrientation": True}
    with no_warnings(), warnings.catch_warnings():
        # the tube up from the start passes through the end tip: a ClearanceWarning, not the
        # subject here
        warnings.simplefilter("ignore", ClearanceWarning)
        assert chain.append(Waypoint(4, 1, SE3.Trans(5, 0, 10) * SE3.Ry(math.pi / 2)), **exact)
        assert chain.append(EndTip(4, 1, SE3.Trans(0, 0, 5) * SE3.Rx(math.pi), 1.5), **exact)
    return chain


#: Rejected operations (most on Example 1A), each expected to warn once.
REJECTED_CALLS = {
    "append": lambda c: KinematicChain(StartTip(4, 1, SE3(), 1.5)).append(
        RevoluteJoint(4, 1, math.pi, SE3.Trans(0, 0, 10) * SE3.Ry(math.pi / 2)),
        safe=False,
        fixedPosition=True,
        fixedOrientation=True,
    ),
    "setJointState": lambda c: c.setJointState(4, math.pi),
    "setJointStates": lambda c: c.setJointStates([0, 0, 0, 0, math.pi, 0, 0]),
    "delete single joint": lambda c: KinematicChain(StartTip(4, 1, SE3(), 1.5)).delete(0),
    "translateJointAlongAxisOfMotion": lambda c: c.translateJointAlongAxisOfMotion(
        *ref.REJECT_TRANSLATE, propagate=False
    ),
    "rotateJointAboutAxisOfMotion": lambda c: c.rotateJointAboutAxisOfMotion(
        *ref.REJECT_ROTATE, propagate=False
    ),
    "transformJoint": lambda c: c.transformJoint(2, SE3.Trans(0, 0, 20), propagate=False),
    "delete without path": lambda c: detour_chain().delete(1),
}


@pytest.mark.parametrize("call", list(REJECTED_CALLS))
def test_rejection_warns_once_at_the_callers_line(example_1a, call):
    with warnings.catch_warnings(record=True) as caught:
        warnings.simplefilter("always")
        REJECTED_CALLS[call](example_1a)
    assert [w.category for w in caught] == [PlacementWarning]
    assert caught[0].filename == __file__


# --- edits (chain.md 5) ----------------------------------------------------------------------


def test_delete_first_joint_makes_joint_1_the_root(example_1a, chain_checker):
    old_joints, old_links = example_1a.Joints, example_1a.Links
    with no_warnings():
        assert example_1a.delete(0) is True
    assert len(example_1a.Joints) == len(example_1a.Links) == len(old_joints) - 1
    for new, old in zip(example_1a.Joints, old_joints[1:], strict=True):
        assert snapshot_joint(new) == snapshot_joint(old)
    root = example_1a.Links[0]
    assert (root.path.theta1, root.path.tMag, root.path.theta2) == (0.0, 0.0, 0.0)
    np.testing.assert_array_equal(root.start_frame, example_1a.Joints[0].proximal_dubins_frame())
    np.testing.assert_array_equal(root.end_frame, root.start_frame)
    for new, old in zip(example_1a.Links[1:], old_links[2:], strict=True):
        assert new is old
    chain_checker(example_1a)


@pytest.mark.parametrize("index", [6, -1])
def test_delete_last_joint_drops_it(example_1a, chain_checker, index):
    old_joints, old_links = example_1a.Joints, example_1a.Links
    with no_warnings():
        assert example_1a.delete(index) is True
    assert example_1a.Joints == old_joints[:-1]
    assert example_1a.Links == old_links[:-1]
    chain_checker(example_1a)


def test_delete_middle_joint_joins_its_neighbours(example_1a, chain_checker):
    old_joints, old_links = example_1a.Joints, example_1a.Links
    with no_warnings():
        assert example_1a.delete(3) is True
    assert example_1a.Joints == old_joints[:3] + old_joints[4:]
    assert example_1a.Links[:3] == old_links[:3]
    assert example_1a.Links[4:] == old_links[5:]
    expected = LinkCSC(1, old_joints[2].DistalDubinsFrame(), old_joints[4].ProximalDubinsFrame())
    new = example_1a.Links[3]
    assert (new.path.theta1, new.path.tMag, new.path.theta2) == (
        expected.path.theta1,
        expected.path.tMag,
        expected.path.theta2,
    )
    chain_checker(example_1a)


def test_delete_on_a_single_joint_chain_is_rejected(snapshot):
    chain = KinematicChain(StartTip(4, 1, SE3(), 1.5))
    before = snapshot(chain)
    with pytest.warns(PlacementWarning):
        assert chain.delete(0) is False
    assert snapshot(chain) == before


def test_delete_without_a_path_is_rejected(snapshot):
    chain = detour_chain()
    before = snapshot(chain)
    with pytest.warns(PlacementWarning):  # start and end would need a U-turn
        assert chain.delete(1) is False
    assert snapshot(chain) == before


@pytest.mark.parametrize(
    "method, args",
    [
        ("translateJointAlongAxisOfMotion", (2, -0.5)),
        ("rotateJointAboutAxisOfMotion", (4, 0.3)),
        ("transformJoint", (4, SE3.Trans(0.1, 0.2, 0) * SE3.Rz(0.05))),
    ],
)
@pytest.mark.parametrize("flag", [True, False])
def test_propagate_spelling_is_accepted(example_1a_factory, snapshot, method, args, flag):
    paper, correct = example_1a_factory(), example_1a_factory()
    with no_warnings():
        assert getattr(paper, method)(*args, propogate=flag) is True
        assert getattr(correct, method)(*args, propagate=flag) is True
    assert snapshot(paper) == snapshot(correct)
    if not flag:  # and the flag really is honoured
        default = example_1a_factory()
        getattr(default, method)(*args)
        assert snapshot(default) != snapshot(paper)


TRANSFORM = SE3.Trans(0.1, 0.2, 0) * SE3.Rz(0.05)


def assert_moved(new_joint, old_joint, T):
    np.testing.assert_allclose(new_joint.pose_matrix, T @ old_joint.pose_matrix, rtol=0, atol=1e-12)
    assert new_joint.state == old_joint.state


def test_transform_joint_propagating_moves_the_rest_rigidly(example_1a, chain_checker):
    old_joints, old_links = example_1a.Joints, example_1a.Links
    with no_warnings():
        assert example_1a.transformJoint(4, TRANSFORM) is True
    T = TRANSFORM.A
    for i, (new, old) in enumerate(zip(example_1a.Joints, old_joints, strict=True)):
        if i < 4:
            assert new is old
        else:
            assert_moved(new, old, T)
    assert example_1a.Links[:4] == old_links[:4]
    for new, old in zip(example_1a.Links[5:], old_links[5:], strict=True):
        # moved rigidly, not re-solved: same shape to the bit
        assert (new.path.theta1, new.path.tMag, new.path.theta2) == (
            old.path.theta1,
            old.path.tMag,
            old.path.theta2,
        )
        np.testing.assert_allclose(new.start_frame, T @ old.start_frame, rtol=0, atol=1e-12)
    chain_checker(example_1a)


def test_transform_joint_not_propagating_moves_one_joint(example_1a, chain_checker):
    old_joints, old_links = example_1a.Joints, example_1a.Links
    with no_warnings():
        assert example_1a.transformJoint(4, TRANSFORM, propagate=False) is True
    for i, (new, old) in enumerate(zip(example_1a.Joints, old_joints, strict=True)):
        if i == 4:
            assert_moved(new, old, TRANSFORM.A)
        else:
            assert new is old
    new_links = example_1a.Links
    assert new_links[:4] == old_links[:4] and new_links[6:] == old_links[6:]
    assert new_links[4] is not old_links[4] and new_links[5] is not old_links[5]
    chain_checker(example_1a)


#: Lowers the StartTip of Example 1A by 0.3 and turns it by 0.2 about its own axis.
ROOT_TRANSFORM = SE3.Trans(3, 3, -0.3) * SE3.Rz(0.2) * SE3.Trans(-3, -3, 0)


@pytest.mark.parametrize("propagate", [True, False])
def test_transform_root(example_1a, chain_checker, propagate):
    old_joints = example_1a.Joints
    with no_warnings():
        assert example_1a.transformJoint(0, ROOT_TRANSFORM, propagate=propagate) is True
    assert_moved(example_1a.Joints[0], old_joints[0], ROOT_TRANSFORM.A)
    for new, old in zip(example_1a.Joints[1:], old_joints[1:], strict=True):
        if propagate:
            assert_moved(new, old, ROOT_TRANSFORM.A)
        else:
            assert new is old
    chain_checker(example_1a)


def test_transform_all_moves_everything_rigidly(example_1a, chain_checker):
    old_joints, old_links = example_1a.Joints, example_1a.Links
    old_ball = example_1a.boundingBall
    assert example_1a.transformAll(TRANSFORM) is True
    for new, old in zip(example_1a.Joints, old_joints, strict=True):
        assert_moved(new, old, TRANSFORM.A)
    for new, old in zip(example_1a.Links, old_links, strict=True):
        assert (new.path.theta1, new.path.tMag, new.path.theta2) == (
            old.path.theta1,
            old.path.tMag,
            old.path.theta2,
        )
    assert example_1a.boundingBall.r == old_ball.r
    assert_close(
        example_1a.boundingBall.c, TRANSFORM.A[:3, :3] @ old_ball.c + TRANSFORM.A[:3, 3], atol=1e-12
    )
    chain_checker(example_1a)


def test_apply_to_previous_waypoint_propagating(example_1a, chain_checker):
    """Waypoint 3, joint 4 and everything after move together; only link 3 is re-solved."""
    old_joints, old_links = example_1a.Joints, example_1a.Links
    z = old_joints[4].pose_matrix[:3, 2]
    with no_warnings():
        assert (
            example_1a.translateJointAlongAxisOfMotion(
                4, 1.0, propagate=True, applyToPreviousWaypoint=True
            )
            is True
        )
    T = SE3.Trans(*(1.0 * z)).A
    for i, (new, old) in enumerate(zip(example_1a.Joints, old_joints, strict=True)):
        if i < 3:
            assert new is old
        else:
            assert_moved(new, old, T)
    assert example_1a.Links[:3] == old_links[:3]
    for new, old in zip(example_1a.Links[4:], old_links[4:], strict=True):
        assert (new.path.theta1, new.path.tMag, new.path.theta2) == (
            old.path.theta1,
            old.path.tMag,
            old.path.theta2,
        )
    chain_checker(example_1a)


def test_apply_to_previous_waypoint_not_propagating(example_1a, chain_checker):
    """Waypoint 3 and joint 4 move; everything else stays; links 3, 4, 5 are re-solved."""
    old_joints, old_links = example_1a.Joints, example_1a.Links
    z = old_joints[4].pose_matrix[:3, 2]
    with no_warnings():
        assert (
            example_1a.translateJointAlongAxisOfMotion(
                4, 1.0, propagate=False, applyToPreviousWaypoint=True
            )
            is True
        )
    T = SE3.Trans(*(1.0 * z)).A
    for i, (new, old) in enumerate(zip(example_1a.Joints, old_joints, strict=True)):
        if i in (3, 4):
            assert_moved(new, old, T)
        else:
            assert new is old
    links = example_1a.Links
    assert links[:3] == old_links[:3] and links[6:] == old_links[6:]
    # waypoint -> joint 4 moved as a pair: the link between them keeps its shape
    np.testing.assert_allclose(
        [links[4].path.theta1, links[4].path.tMag, links[4].path.theta2],
        [old_links[4].path.theta1, old_links[4].path.tMag, old_links[4].path.theta2],
        rtol=0,
        atol=1e-9,
    )
    chain_checker(example_1a)


@pytest.mark.parametrize("propagate", [True, False])
def test_apply_to_previous_waypoint_ignores_a_non_waypoint(example_1a_factory, snapshot, propagate):
    """Joint 1's predecessor is the StartTip, so only joint 1 moves."""
    flagged, plain = example_1a_factory(), example_1a_factory()
    with no_warnings():
        assert (
            flagged.translateJointAlongAxisOfMotion(
                1, 0.5, propagate=propagate, applyToPreviousWaypoint=True
            )
            is True
        )
        assert plain.translateJointAlongAxisOfMotion(1, 0.5, propagate=propagate) is True
    assert snapshot(flagged) == snapshot(plain)


def test_translation_keeps_the_rotation_exactly(example_1a):
    old = example_1a.Joints[4].pose_matrix
    example_1a.translateJointAlongAxisOfMotion(4, 0.7)
    new = example_1a.Joints[4].pose_matrix
    np.testing.assert_array_equal(new[:3, :3], old[:3, :3])
    assert_close(new[:3, 3] - old[:3, 3], 0.7 * old[:3, 2], atol=1e-12)


def test_rotation_keeps_the_origin_and_axis(example_1a):
    old = example_1a.Joints[4].pose_matrix
    example_1a.rotateJointAboutAxisOfMotion(4, 0.4)
    new = example_1a.Joints[4].pose_matrix
    assert_close(new[:3, 3], old[:3, 3], atol=1e-12)
    assert_close(new[:3, 2], old[:3, 2], atol=1e-12)
    assert_close(new[:3, 0] @ old[:3, 0], math.cos(0.4), atol=1e-12)


# --- states (chain.md 5.4) -------------------------------------------------------------------


@pytest.mark.parametrize(
    "joint, state",
    [(2, 1.3), (2, -0.9), (4, 1.6), (4, -1.6), (4, math.pi), (1, 0.1), (0, -1e-9), (6, 1.0)],
)
def test_state_outside_range_is_rejected(example_1a, snapshot, joint, state):
    before = snapshot(example_1a)
    with pytest.warns(PlacementWarning):
        assert example_1a.setJointState(joint, state) is False
    assert snapshot(example_1a) == before


@pytest.mark.parametrize("joint", [1, 3, 5])
def test_waypoint_state_zero_is_accepted(example_1a, joint):
    """A no-op state change succeeds and moves nothing (the ball may be recomputed, 3.3)."""
    old_joints, old_links = example_1a.Joints, example_1a.Links
    with no_warnings():
        assert example_1a.setJointState(joint, 0.0) is True
    for new, old in zip(example_1a.Joints, old_joints, strict=True):
        assert snapshot_joint(new) == snapshot_joint(old)
    for new, old in zip(example_1a.Links, old_links, strict=True):
        np.testing.assert_array_equal(new.start_frame, old.start_frame)
        np.testing.assert_array_equal(new.end_frame, old.end_frame)
        assert (new.path.theta1, new.path.tMag, new.path.theta2) == (
            old.path.theta1,
            old.path.tMag,
            old.path.theta2,
        )
    recomputed = example_1a.recomputeBoundingBall()
    np.testing.assert_array_equal(example_1a.boundingBall.c, recomputed.c)


def test_state_range_bounds_are_inclusive(example_1a):
    for j in (2, 4):
        lo, hi = example_1a.Joints[j].stateRange()
        with no_warnings():
            assert example_1a.setJointState(j, lo) is True
            assert example_1a.setJointState(j, hi) is True


def test_set_joint_states_equals_one_by_one(example_1a_factory, chain_checker):
    states = [0.0, 0.0, 0.8, 0.0, -1.1, 0.0, 0.0]
    together, one_by_one = example_1a_factory(), example_1a_factory()
    with no_warnings():
        assert together.setJointStates(states) is True
        for j, s in enumerate(states):
            assert one_by_one.setJointState(j, s) is True
    for a, b in zip(together.Joints, one_by_one.Joints, strict=True):
        np.testing.assert_allclose(a.pose_matrix, b.pose_matrix, rtol=0, atol=1e-12)
        assert a.state == b.state
    assert [j.state for j in together.Joints] == states
    chain_checker(together)


def test_set_joint_states_is_all_or_nothing(example_1a, snapshot):
    before = snapshot(example_1a)
    with pytest.warns(PlacementWarning):
        assert example_1a.setJointStates([0.0, 0.0, 0.8, 0.0, 2.0, 0.0, 0.0]) is False
    assert snapshot(example_1a) == before


@pytest.mark.parametrize(
    "states",
    [
        3,
        None,
        "0000000",
        b"0000000",
        {0: 0.0, 1: 0.0, 2: 0.8, 3: 0.0, 4: 0.0, 5: 0.0, 6: 0.0},
        {0.0, 0.1, 0.2, 0.3, 0.4, 0.5, 0.6},
        np.float64(0.0),
        np.array(0.0),
    ],
    ids=["int", "None", "str", "bytes", "dict", "set", "numpy scalar", "0-d array"],
)
def test_set_joint_states_refuses_what_is_not_a_sequence(example_1a, snapshot, states):
    """A dict's keys, a string's characters and a set in no order are not read as states."""
    from kinegami import InvalidTypeError

    before = snapshot(example_1a)
    with pytest.raises(InvalidTypeError, match=r"^states must be a sequence of numbers, got "):
        example_1a.setJointStates(states)
    assert snapshot(example_1a) == before


def test_set_joint_states_refuses_a_generator(example_1a, snapshot):
    from kinegami import InvalidTypeError

    before = snapshot(example_1a)
    with pytest.raises(InvalidTypeError, match="states must be a sequence of numbers"):
        example_1a.setJointStates(0.0 for _ in example_1a.Joints)
    assert snapshot(example_1a) == before


def test_set_joint_states_takes_a_tuple_and_an_array(example_1a_factory):
    states = [0.0, 0.0, 0.8, 0.0, -1.1, 0.0, 0.0]
    results = []
    for form in (list, tuple, np.array):
        chain = example_1a_factory()
        with no_warnings():
            assert chain.setJointStates(form(states)) is True
        results.append([j.pose_matrix.tobytes() for j in chain.Joints])
    assert results[0] == results[1] == results[2]


def test_states_back_to_zero_restore_the_design(example_1a, chain_checker):
    design = [j.pose_matrix for j in example_1a.Joints]
    design_links = [(lk.start_frame, lk.end_frame) for lk in example_1a.Links]
    with no_warnings():
        assert example_1a.setJointState(2, 1.0)
        assert example_1a.setJointState(4, 1.2)
        assert example_1a.setJointState(2, -0.5)
        assert example_1a.setJointStates([0.0] * 7)
    for joint, pose in zip(example_1a.Joints, design, strict=True):
        np.testing.assert_allclose(joint.pose_matrix, pose, rtol=0, atol=1e-12)
    for link, (start, end) in zip(example_1a.Links, design_links, strict=True):
        np.testing.assert_allclose(link.start_frame, start, rtol=0, atol=1e-12)
        np.testing.assert_allclose(link.end_frame, end, rtol=0, atol=1e-12)
    chain_checker(example_1a)


def test_own_state_does_not_move_the_pose(example_1a):
    pose = example_1a.Joints[4].pose_matrix
    proximal = example_1a.Joints[4].proximal_frame()
    example_1a.setJointState(4, 0.9)
    np.testing.assert_array_equal(example_1a.Joints[4].pose_matrix, pose)
    np.testing.assert_array_equal(example_1a.Joints[4].proximal_frame(), proximal)
