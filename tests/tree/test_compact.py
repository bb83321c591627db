"""Compaction of trees: shorter, clear, the same kinematics, deterministic; and the exact-pose
constructor it builds candidates with."""

from __future__ import annotations

import concurrent.futures
import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from spatialmath import SE3

from kinegami import (
    ClearanceWarning,
    EndTip,
    InvalidParameterError,
    KinematicTree,
    NoPathError,
    PlacementWarning,
    RevoluteJoint,
    Waypoint,
)
from kinegami.fabrication.sheets import junction_problems
from kinegami.optimize import CompactionError, compact, tube_length

from .helpers import quiet_hand

RY = SE3.Ry(math.pi / 2)


def _serial() -> concurrent.futures.Executor:
    return concurrent.futures.ThreadPoolExecutor(1)


def assert_same_kinematics(before: KinematicTree, after: KinematicTree) -> None:
    """Every joint that is not a waypoint keeps its type, parameters and axis line, and the
    tree keeps its shape (parents, up to dropped waypoints)."""
    kept = [k for k, j in enumerate(before.Joints) if not isinstance(j, Waypoint) or k == 0]
    moved = [k for k, j in enumerate(after.Joints) if not isinstance(j, Waypoint) or k == 0]
    assert len(kept) == len(moved)
    for a, b in zip(kept, moved, strict=True):
        ja, jb = before.Joints[a], after.Joints[b]
        assert type(ja) is type(jb)
        assert ja.neutralLength == jb.neutralLength and ja.stateRange() == jb.stateRange()
        za, zb = ja.pose_matrix[:3, 2], jb.pose_matrix[:3, 2]
        assert np.linalg.norm(np.cross(za, zb)) < 1e-9
        offset = jb.pose_matrix[:3, 3] - ja.pose_matrix[:3, 3]
        assert np.linalg.norm(np.cross(offset, za)) < 1e-9 * before.r


def test_the_papers_hand_gets_shorter_and_clear():
    hand = quiet_hand()
    assert not hand.clearance().ok  # the palm nearly touches the tube to pointer1
    # three starts: which start finds the short design depends on the last bits of rounding,
    # which differ between machines (numpy picks SIMD code by CPU): on an AVX2 machine start 0
    # ends at 34.09, longer than the input's 32.28, and start 2 at 27.05; on the machine this
    # test was written on, start 0 was already shorter
    shorter = compact(hand, executor=_serial(), starts=3)
    assert shorter.clearance().ok
    assert shorter.Parents == hand.Parents  # no waypoint to drop, none added
    assert shorter.totalPathLength() < hand.totalPathLength() - 1.0
    assert_same_kinematics(hand, shorter)
    again = compact(hand, executor=_serial(), starts=3)
    assert tube_length(again) == tube_length(shorter)  # deterministic for a seed


def _three_fingers() -> KinematicTree:
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        for k in range(3):
            pose = SE3.Rz(2 * math.pi * k / 3) * SE3.Trans(3, 0, 4) * RY
            a = tree.addJoint(0, RevoluteJoint(4, 1, math.pi, pose))
            b = tree.addJoint(a, RevoluteJoint(4, 1, math.pi, SE3.Trans(4, 0, 0)))
            tree.addJoint(b, EndTip(4, 1, SE3.Trans(4, 0, 0) * RY, 1.5))
    return tree


def test_a_safe_tree_loses_its_waypoints_and_stays_clear():
    tree = _three_fingers()
    assert tree.clearance().ok
    shorter = compact(tree, executor=_serial(), starts=1)
    assert shorter.clearance().ok
    assert tube_length(shorter) < 0.6 * tube_length(tree)
    assert len(shorter.Children[0]) == 3  # still three fingers from the root
    assert_same_kinematics(tree, shorter)


@settings(max_examples=5, deadline=None)
@given(st.lists(st.tuples(st.floats(0, 2 * math.pi), st.floats(-0.5, 0.5)), min_size=2,
                max_size=3))  # fmt: skip
def test_compaction_of_random_safe_trees_is_clear_and_never_longer(children):
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        for angle, tilt in children:
            pose = SE3.Rz(angle) * SE3.Trans(3, 0, 4) * SE3.Rx(tilt) * RY
            a = tree.addJoint(0, RevoluteJoint(4, 1, math.pi, pose))
            tree.addJoint(a, EndTip(4, 1, SE3.Trans(3, 0, 0) * RY, 1.5))
    sockets = junction_problems(tree)
    try:
        shorter = compact(tree, executor=_serial(), starts=1)
    except CompactionError as error:  # only a design compaction must repair may be refused
        assert not tree.clearance().ok or sockets, error
        if tree.clearance().ok:
            assert f"has a junction that cannot be made: {sockets[0][1]}" in str(error)
        return
    assert shorter.clearance().ok
    assert not junction_problems(shorter)
    if tree.clearance().ok and not sockets:  # the input competes: never longer
        assert tube_length(shorter) <= tube_length(tree) + 1e-9
    assert_same_kinematics(tree, shorter)


def test_a_clear_tree_whose_sockets_do_not_fit_is_refused_by_name_or_repaired():
    """Two children 2 rad apart leave no room for the sockets (a hypothesis example): clear,
    but not a valid result, so one start that cannot repair it is an error that says so."""
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        for angle in (2.0, 0.0, 1.625):
            pose = SE3.Rz(angle) * SE3.Trans(3, 0, 4) * RY
            a = tree.addJoint(0, RevoluteJoint(4, 1, math.pi, pose))
            tree.addJoint(a, EndTip(4, 1, SE3.Trans(3, 0, 0) * RY, 1.5))
    assert tree.clearance().ok and junction_problems(tree)
    with pytest.raises(CompactionError, match=r"the input has a junction that cannot be made: "
                       r"joint 1 \(a child of joint 0\)"):  # fmt: skip
        compact(tree, executor=_serial(), starts=1)
    repaired = compact(tree, executor=_serial(), starts=2)
    assert repaired.clearance().ok and not junction_problems(repaired)
    assert_same_kinematics(tree, repaired)


@pytest.mark.parametrize("seed", [-1, np.int64(-1), -(10**5000)], ids=["int", "numpy", "huge"])
def test_a_negative_seed_is_refused(seed):
    with pytest.raises(InvalidParameterError, match="seed must be an integer >= 0, got -1|got <a"):
        compact(quiet_hand(), seed=seed)


def test_motion_is_refused_for_trees():
    with pytest.raises(InvalidParameterError, match="chains only"):
        compact(quiet_hand(), motion=True)


# --- from_joints -------------------------------------------------------------------------------
def test_from_joints_is_adding_joint_by_joint(snapshot):
    hand = quiet_hand()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        rebuilt = KinematicTree.from_joints(hand.Joints, hand.Parents)
    assert snapshot(rebuilt) == snapshot(hand)
    with pytest.warns(ClearanceWarning, match="from_joints"):
        KinematicTree.from_joints(hand.Joints, hand.Parents)


def test_from_joints_rejects_what_is_not_a_tree():
    joints = quiet_hand().Joints
    with pytest.raises(InvalidParameterError, match=r"parents\[3\] must be in \[0, 2\]"):
        KinematicTree.from_joints(joints, [-1, 0, 1, 3] + [0] * 8)
    with pytest.raises(InvalidParameterError, match="one entry per joint"):
        KinematicTree.from_joints(joints, [-1, 0])
    with pytest.raises(InvalidParameterError, match="EndTip"):
        KinematicTree.from_joints(joints[:6], [-1, 0, 1, 2, 3, 4])
    back = RevoluteJoint(4, 1, math.pi, SE3.Trans(0, 0, 10) * RY)  # a U-turn over the root
    with pytest.raises(NoPathError, match="joint 1") as caught:
        KinematicTree.from_joints([Waypoint(4, 1, SE3()), back], [-1, 0])
    assert caught.value.joint == 1


def test_compaction_keeps_the_callers_warning_filters():
    with warnings.catch_warnings(record=True) as seen:
        warnings.simplefilter("always")
        compact(_three_fingers(), executor=_serial(), starts=1)
    assert not [w for w in seen if issubclass(w.category, PlacementWarning)]
