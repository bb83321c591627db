"""KinematicTree: the paper's hand (reference numbers), the chain as the special case (bit for
bit), subtree edits and states, the tree's fixes (siblings, applyToPreviousWaypoint), delete,
transactions and bad input."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import example, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from spatialmath import SE3

from kinegami import (
    ClearanceWarning,
    EndTip,
    InvalidParameterError,
    InvalidTypeError,
    JointIndexError,
    KinematicChain,
    KinematicTree,
    PlacementWarning,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)
from kinegami.clearance import chain_clearance

from .helpers import hand_tree, load_fixture, quiet_hand

REF = load_fixture()["reference"]
RY = SE3.Ry(math.pi / 2)  # a revolute joint's path (its x axis) along -z
EXACT = {"relative": False, "safe": False, "fixedPosition": True, "fixedOrientation": True}


@pytest.fixture(scope="module")
def hand():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)  # the palm nearly touches link 5
        return hand_tree()


# --- the paper's hand ------------------------------------------------------------------------
def test_hand_structure(hand):
    assert hand.Parents == tuple(REF["parents"])
    assert hand.Children[0] == tuple(REF["children_of_root"])
    children = hand.Children
    for k, p in enumerate(hand.Parents):
        assert (k in children[p]) if p >= 0 else k == 0
    assert sum(1 for c in children if not c) == 3


def test_hand_links_and_total(hand):
    for link, expected in zip(hand.Links, REF["links"], strict=True):
        p = link.path
        assert_allclose([p.theta1, p.tMag, p.theta2, p.length],
                        [expected["theta1"], expected["s"], expected["theta2"], expected["length"]],
                        atol=1e-6)  # fmt: skip
    assert hand.totalPathLength() == pytest.approx(REF["total_link_length"], abs=1e-6)


def test_hand_balls():
    tree = quiet_hand()
    incremental = REF["bounding_ball_incremental"]
    assert_allclose(tree.boundingBall.c, incremental["center"], atol=1e-6)
    assert tree.boundingBall.r == pytest.approx(incremental["radius"], abs=1e-6)
    recomputed = REF["bounding_ball_recomputed"]
    ball = tree.recomputeBoundingBall()
    assert_allclose(ball.c, recomputed["center"], atol=1e-6)
    assert ball.r == pytest.approx(recomputed["radius"], abs=1e-6)


def test_hand_branching_parameters(hand):
    found = np.round(hand.branchingParametersFrom(0), 3)
    expected = np.array(REF["branchingParametersFrom_0_deg_rounded3"])
    # the rotation-axis angle of a zero turn is undefined (its axis is): compare it only for
    # real turns
    for row in (found, expected):
        row[:, 0] = np.where(expected[:, 1] > 0.0, row[:, 0], 0.0)
        row[:, 4] = np.where(expected[:, 5] > 0.0, row[:, 4], 0.0)
    assert_allclose(found, expected, atol=1.1e-3)
    names = [j["name"] for j in load_fixture()["joints"]]
    for name, length in REF["straight_lengths_rounded3"].items():
        assert hand.Links[names.index(name)].path.tMag == pytest.approx(length, abs=6e-4)


@pytest.mark.parametrize("grasp", sorted(REF["grasps"]))
def test_hand_grasps(grasp):
    tree = quiet_hand()
    data = REF["grasps"][grasp]
    # the fixture's states are rounded to 12 digits: clamp the last digit into each range
    states = [min(max(s, j.stateRange()[0]), j.stateRange()[1])
              for s, j in zip(data["states"], tree.Joints, strict=True)]  # fmt: skip
    relative = [np.linalg.inv(link.start_frame) @ link.end_frame for link in tree.Links]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        assert tree.setJointStates(states)
    names = [j["name"] for j in load_fixture()["joints"]]
    for name, origin in data["fingertip_origins"].items():
        assert_allclose(tree.Joints[names.index(name)].pose_matrix[:3, 3], origin, atol=1e-6)
    assert tree.recomputeBoundingBall().r == pytest.approx(
        data["bounding_ball_radius_recomputed"], abs=1e-6
    )
    for before, link in zip(relative, tree.Links, strict=True):  # link shapes never change
        assert_allclose(np.linalg.inv(link.start_frame) @ link.end_frame, before, atol=1e-12)


def test_hand_clearance_names_the_palm_near_contact(hand):
    """The palm's body comes within 1.75 r of the tube to pointer1: a real overlap of 0.25 r;
    the three tubes leaving the root run together only inside the junction."""
    report = hand.clearance()
    assert not report.ok
    assert len(report.pairs) == 1
    pair = report.pairs[0]
    assert pair.clearance == pytest.approx(-0.25, abs=1e-6)
    assert sorted(pair.elements) == [2, 9]  # joint 1 (the palm) and link 5


# --- the chain is the special case --------------------------------------------------------------
def _random_joint(data, k: int):
    kind = data.draw(st.sampled_from(["revolute", "prismatic", "waypoint"]), label=f"kind{k}")
    x, y, z = (data.draw(st.floats(-6, 6), label=f"p{k}{c}") for c in "xyz")
    a, b = (data.draw(st.floats(-math.pi, math.pi), label=f"a{k}{c}") for c in "ab")
    pose = SE3.Trans(x, y, z) * SE3.Rx(a) * SE3.Ry(b)
    if kind == "revolute":
        return RevoluteJoint(4, 1, math.pi, pose)
    if kind == "prismatic":
        return PrismaticJoint(4, 1, 2, 3, math.pi / 4, pose)
    return Waypoint(4, 1, pose)


@settings(max_examples=25)
@given(data=st.data())
def test_a_tree_whose_parents_are_the_previous_joints_is_the_chain(data, snapshot):
    """The same calls on a chain and on a tree (each joint the child of the last one) give the
    same joints, links, ball and results, bit for bit."""
    root = StartTip(4, 1, SE3.Trans(0, 0, 0), 1.5)
    chain, tree = KinematicChain(root), KinematicTree(root)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for k in range(data.draw(st.integers(1, 4), label="joints")):
            joint = _random_joint(data, k)
            safe = data.draw(st.booleans(), label=f"safe{k}")
            a = chain.append(joint, safe=safe)
            b = tree.addJoint(len(tree.Joints) - 1, joint, safe=safe)
            assert a == b
        n = len(chain.Joints)
        for step in range(data.draw(st.integers(0, 4), label="edits")):
            j = data.draw(st.integers(0, n - 1), label=f"j{step}")
            what = data.draw(st.sampled_from(["slide", "roll", "state", "delete"]),
                             label=f"edit{step}")  # fmt: skip
            if what == "slide":
                d = data.draw(st.floats(-3, 3), label=f"d{step}")
                prop = data.draw(st.booleans(), label=f"prop{step}")
                results = [x.translateJointAlongAxisOfMotion(j, d, propagate=prop)
                           for x in (chain, tree)]  # fmt: skip
            elif what == "roll":
                angle = data.draw(st.floats(-3, 3), label=f"angle{step}")
                results = [x.rotateJointAboutAxisOfMotion(j, angle) for x in (chain, tree)]
            elif what == "state":
                lo, hi = chain.Joints[j].stateRange()
                u = data.draw(st.floats(0, 1), label=f"u{step}")
                results = [x.setJointState(j, lo + u * (hi - lo)) for x in (chain, tree)]
            else:
                if len(chain.Joints) < 2:
                    continue
                results = [x.delete(len(x.Joints) - 1) for x in (chain, tree)]
                n = len(chain.Joints)
            assert results[0] == results[1]
        states = [j.state for j in chain.Joints]
        assert chain.setJointStates(states) == tree.setJointStates(states)
    assert snapshot(chain) == snapshot(tree)
    assert chain.clearance().ok == tree.clearance().ok
    if chain.clearance().closest is not None:
        assert tree.clearance().min_clearance == pytest.approx(
            chain_clearance(chain).min_clearance, abs=1e-9
        )


# --- subtree edits and states ------------------------------------------------------------------
@pytest.mark.parametrize("j", [0, 1, 5, 8, 9])
@pytest.mark.parametrize("propagate", [True, False])
def test_transform_moves_exactly_the_subtree(j, propagate, snapshot):
    tree = quiet_hand()
    before = [joint.pose_matrix.copy() for joint in tree.Joints]
    links_before = list(tree.Links)
    T = (SE3.Trans(0.3, -0.2, 0.1) * SE3.Rz(0.2)).A
    subtree = set(tree.subtree(j))
    unchanged = snapshot(tree)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        warnings.simplefilter("ignore", PlacementWarning)
        ok = tree.transformJoint(j, T, propagate=propagate)
    if (j, propagate) == (1, False):  # the palm's 0.09 r link to thumb0 cannot follow alone
        assert not ok and snapshot(tree) == unchanged
        return
    assert ok
    moved = subtree if propagate else {j}
    children = set(tree.Children[j])
    for k, joint in enumerate(tree.Joints):
        if k in moved:
            assert_allclose(joint.pose_matrix, T @ before[k], atol=1e-12)
        else:
            assert np.array_equal(joint.pose_matrix, before[k]), k
        resolved = {j} | (set() if propagate else children)
        if k not in moved and k not in resolved:
            assert tree.Links[k] is links_before[k], k  # untouched links are the same values


@pytest.mark.parametrize("j", [1, 2, 5, 8, 9])
def test_state_change_moves_the_subtrees_beyond_the_joint(j):
    tree = quiet_hand()
    before = [joint.pose_matrix.copy() for joint in tree.Joints]
    shapes = [np.linalg.inv(link.start_frame) @ link.end_frame for link in tree.Links]
    beyond = set(tree.subtree(j)) - {j}
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        assert tree.setJointState(j, 0.4)
    G = tree.Joints[j].state_transform(0.4)
    for k, joint in enumerate(tree.Joints):
        if k in beyond:
            assert_allclose(joint.pose_matrix, G @ before[k], atol=1e-12)
        elif k != j:
            assert np.array_equal(joint.pose_matrix, before[k]), k
    for shape, link in zip(shapes, tree.Links, strict=True):
        assert_allclose(np.linalg.inv(link.start_frame) @ link.end_frame, shape, atol=1e-12)
    assert tree.Joints[j].state == 0.4


def test_states_all_at_once_equal_one_at_a_time():
    one, many = quiet_hand(), quiet_hand()
    states = [0.0] * len(one.Joints)
    for k, value in ((1, -0.5), (2, 0.7), (5, 0.3), (6, -0.2), (8, 1.0), (9, 0.4)):
        states[k] = value
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        for k, value in enumerate(states):
            if value:
                assert one.setJointState(k, value)
        assert many.setJointStates(states)
    for a, b in zip(one.Joints, many.Joints, strict=True):
        assert_allclose(a.pose_matrix, b.pose_matrix, atol=1e-12)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        assert many.setJointStates([0.0] * len(many.Joints))
    for a, b in zip(many.Joints, quiet_hand().Joints, strict=True):
        assert_allclose(a.pose_matrix, b.pose_matrix, atol=1e-12)


# --- the tree's fixes --------------------------------------------------------------------------
def test_apply_to_previous_waypoint_uses_the_parent():
    """The published code moves joint j - 1, another branch; the parent only moves with j when
    it is a waypoint whose only child is j."""
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    a = tree.addJoint(0, RevoluteJoint(4, 1, math.pi, SE3.Trans(0, 0, 4)), **EXACT)
    q = tree.addJoint(a, Waypoint(4, 1, SE3.Trans(0, 0, 8)), **EXACT)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        b = tree.addJoint(0, RevoluteJoint(4, 1, math.pi, SE3.Trans(4, 0, 4) * SE3.Rx(math.pi / 2)),
                          **EXACT)  # fmt: skip
        before = [joint.pose_matrix.copy() for joint in tree.Joints]
        assert tree.translateJointAlongAxisOfMotion(b, 1, applyToPreviousWaypoint=True)
    assert_allclose(tree.Joints[b].pose_matrix[:3, 3] - before[b][:3, 3], (0, -1, 0), atol=1e-12)
    assert np.array_equal(tree.Joints[q].pose_matrix, before[q])
    assert np.array_equal(tree.Joints[0].pose_matrix, before[0])
    # a waypoint parent with one child moves with it
    tree = KinematicTree(StartTip(4, 1, SE3(), 1.5))
    w = tree.addJoint(0, Waypoint(4, 1, SE3.Trans(0, 0, 3)), **EXACT)
    j = tree.addJoint(w, RevoluteJoint(4, 1, math.pi, SE3.Trans(0, 0, 8) * SE3.Ry(-math.pi / 2)),
                      **EXACT)  # fmt: skip
    before = [joint.pose_matrix.copy() for joint in tree.Joints]
    assert tree.translateJointAlongAxisOfMotion(j, 0.5, applyToPreviousWaypoint=True)
    axis = before[j][:3, 2]
    for k in (w, j):
        assert_allclose(tree.Joints[k].pose_matrix[:3, 3], before[k][:3, 3] + 0.5 * axis,
                        atol=1e-12)  # fmt: skip


def test_safe_siblings_do_not_overlap():
    """Two siblings placed safely: the second does not reuse the first one's ray, and the tree
    is clear (the published rule puts both first waypoints on the root's axis)."""
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    with warnings.catch_warnings():
        warnings.simplefilter("error", ClearanceWarning)
        first = tree.addJoint(0, RevoluteJoint(4, 1, math.pi, SE3.Trans(3, 0, 4) * RY))
        second = tree.addJoint(0, RevoluteJoint(4, 1, math.pi, SE3.Trans(-3, 0, 4) * RY))
    assert tree.clearance().ok
    w1, w2 = tree.Children[0]
    assert isinstance(tree.Joints[w1], Waypoint) and isinstance(tree.Joints[w2], Waypoint)
    ray = tree.Joints[0].distal_frame()[:3, 2]
    p2 = tree.Joints[w2].pose_matrix[:3, 3]
    assert np.linalg.norm(p2 - (p2 @ ray) * ray) > 1.0  # off the root's path ray
    for j in (first, second):  # both kept their axes
        assert abs(tree.Joints[j].pose_matrix[1, 3]) < 1e-9


#: Children (angle, tilt) of one joint that no escape placed clear at the usual place: the
#: last one's axis line had siblings at both of its places (found by the property test below
#: and by a stress run of 1300 trees; each fourth child was refused).
BOXED_SIBLINGS = [
    [(1.0, 0.0), (2.0, 0.0), (2.1875, 1.0), (2.0, 0.0)],
    [(-0.4375, 0.0)] * 4,
    [(0.5, 0.0)] * 4,
    [(1.9375, 0.0), (1.6875, 0.0), (1.9375, 0.0), (1.6875, 0.0)],
    [(2.8125, 1.0), (0.875, 0.25), (0.875, 0.25), (0.875, 0.25)],
    [(0.25, 0.0), (0.625, 0.0), (0.625, 0.0), (0.625, 0.0)],
    [(-1.9375, 0.0), (-1.5, -0.5), (-1.9375, 0.0), (-1.5, -0.5)],
]


def _safe_siblings(children) -> KinematicTree:
    tree = KinematicTree(Waypoint(4, 1, SE3()), requireClearance=True)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ClearanceWarning)
        for angle, tilt in children:
            pose = SE3.Rz(angle) * SE3.Trans(3, 0, 4) * SE3.Rx(tilt) * SE3.Ry(math.pi / 2)
            assert tree.addJoint(0, RevoluteJoint(4, 1, math.pi, pose)) is not None
    return tree


@settings(max_examples=10)
@given(st.lists(st.tuples(st.floats(-math.pi, math.pi), st.floats(-1, 1)), min_size=2, max_size=4))
@example(BOXED_SIBLINGS[0])
def test_safe_siblings_are_clear(children):
    """Up to four children added safely to one joint: each is placed and the tree stays clear
    (four identical ones needed the diagonal escapes: the fourth was refused; the example,
    whose fourth child's axis line had siblings at both places, the joint farther out)."""
    tree = _safe_siblings(children)
    assert tree.clearance().ok
    assert len(tree.Children[0]) == len(children)


@pytest.mark.parametrize("children", BOXED_SIBLINGS)
def test_siblings_whose_place_is_taken_are_placed_clear(children):
    """Every route to the place where the radial construction puts the fourth child ran
    beside a sibling already there; the last variants put it SIBLING_OUTWARD r farther out
    on its axis, clear (docs/trees.md)."""
    tree = _safe_siblings(children)
    assert tree.clearance().ok and len(tree.Children[0]) == 4
    joint, first = tree.Joints[-1], tree.Children[0][-1]
    assert tree.Parents[first] == 0 and not isinstance(tree.Joints[first], RevoluteJoint)
    axis = joint.pose_matrix[:3, 2]  # still on its axis line, as given
    given_pose = SE3.Rz(children[-1][0]) * SE3.Trans(3, 0, 4) * SE3.Rx(children[-1][1]) \
        * SE3.Ry(math.pi / 2)  # fmt: skip
    offset = joint.pose_matrix[:3, 3] - given_pose.A[:3, 3]
    assert np.linalg.norm(offset - (offset @ axis) * axis) < 1e-9
    assert abs(abs(axis @ given_pose.A[:3, 2]) - 1.0) < 1e-12


def test_a_child_of_a_waypoint_inside_a_junction_is_refused_or_warned():
    """Found by a stress run: the root's second child runs within r of the waypoint that safe
    placement put r beyond the root; a child of that waypoint cannot be clear (docs/trees.md).
    requireClearance refuses it and leaves the tree as it was; otherwise it is warned."""
    for require in (True, False):
        tree = KinematicTree(Waypoint(4, 1, SE3()), requireClearance=require)
        for _ in range(2):
            tree.addJoint(0, RevoluteJoint(4, 1, math.pi, np.eye(4)), relative=False)
        assert tree.clearance().ok and isinstance(tree.Joints[1], Waypoint)
        assert tree.Parents == (-1, 0, 1, 0, 3, 4, 5)
        before = (tree.Parents, [j.pose_matrix.tobytes() for j in tree.Joints])
        if require:
            with pytest.warns(PlacementWarning, match="would pass through itself"):
                assert tree.addJoint(1, RevoluteJoint(4, 1, math.pi, np.eye(4)), False) is None
            assert (tree.Parents, [j.pose_matrix.tobytes() for j in tree.Joints]) == before
        else:
            with pytest.warns(ClearanceWarning, match="passes through itself"):
                assert tree.addJoint(1, RevoluteJoint(4, 1, math.pi, np.eye(4)), False) == 10
            assert not tree.clearance().ok


#: Found by a random-tree stress run (known limitation, see the test below): the second child
#: of joint 6 routes its tube 3 r from the distal exit of joint 12, the first child, with more
#: of that subtree around it. Steps: (parent, kind, quaternion (x, y, z, w), translation in r,
#: relative).
BOXED_IN_R = 14.811869983267973
BOXED_IN_STEPS = [
    (0, "P", (0.0, 0.0, 0.0, -0.8404589657920347), (0.0, 0.027089478684854562, 0.0), False),
    (0, "P", (-0.5, 0.0, 0.37896032777011857, 0.0), (0.0, 0.0, 0.0), False),
    (0, "R", (0.0, -0.6776570041201637, -0.3212638836038474, 0.0), (0.0, 0.0, -2.236604594672442),
     False),
    (6, "R", (0.0, -0.2510579669489704, 0.0, -0.7449094470715298),
     (-3.4267993588279513, 3.0872835963408907, 0.0), True),
    (6, "R", (-0.375, 0.0, -0.75, 0.25), (0.0, 0.0, 0.0), False),
    (0, "R", (0.0, 0.0, 0.0, 1.0), (0.0, 0.0, 0.0), False),
]  # fmt: skip


def _boxed_in_tree(require: bool) -> KinematicTree:
    from scipy.spatial.transform import Rotation

    r = BOXED_IN_R
    tree = KinematicTree(Waypoint(4, r, SE3()), requireClearance=require)
    for parent, kind, quaternion, translation, relative in BOXED_IN_STEPS:
        T = np.eye(4)
        T[:3, :3] = Rotation.from_quat(quaternion).as_matrix()
        T[:3, 3] = np.array(translation) * r
        joint = (RevoluteJoint(4, r, math.pi, T) if kind == "R"
                 else PrismaticJoint(4, r, 3 * r, 3, math.pi / 4, T))  # fmt: skip
        with warnings.catch_warnings():
            warnings.simplefilter("error", ClearanceWarning)
            assert tree.addJoint(parent, joint, relative=relative) is not None
    assert tree.clearance().ok and len(tree.Joints) == 21
    return tree


def test_a_leaf_boxed_in_by_its_siblings_subtree_is_refused_not_placed_through():
    """Known limitation (docs/trees.md): no safe route leaves joint 12 clear, so its child is
    refused under requireClearance (tree unchanged) and warned about otherwise. When safe
    placement learns to keep leaves' exits free, this test should change to 'is clear'."""
    tree = _boxed_in_tree(require=True)
    before = (tree.Parents, [j.pose_matrix.tobytes() for j in tree.Joints])
    with pytest.warns(PlacementWarning, match="would pass through itself"):
        assert tree.addJoint(12, RevoluteJoint(4, BOXED_IN_R, math.pi, np.eye(4)), False) is None
    assert (tree.Parents, [j.pose_matrix.tobytes() for j in tree.Joints]) == before
    tree = _boxed_in_tree(require=False)
    with pytest.warns(ClearanceWarning, match="passes through itself"):
        assert tree.addJoint(12, RevoluteJoint(4, BOXED_IN_R, math.pi, np.eye(4)), False) == 23


def test_four_identical_safe_siblings_are_placed_and_clear():
    tree = KinematicTree(Waypoint(4, 1, SE3()), requireClearance=True)
    pose = SE3.Trans(3, 0, 4) * SE3.Ry(math.pi / 2)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ClearanceWarning)
        for _ in range(4):
            assert tree.addJoint(0, RevoluteJoint(4, 1, math.pi, pose)) is not None
    assert tree.clearance().ok and len(tree.Children[0]) == 4


# --- delete ------------------------------------------------------------------------------------
def test_delete_a_joint_with_one_child_relinks_it():
    tree = quiet_hand()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        assert tree.delete(6)  # pointer2: pointerEnd (7) now follows pointer1 (5)
    assert tree.Parents == (-1, 0, 1, 2, 3, 0, 5, 0, 7, 8, 9)
    link = tree.Links[6]
    assert_allclose(link.start_frame, tree.Joints[5].distal_dubins_frame(), atol=1e-12)
    assert_allclose(link.end_frame, tree.Joints[6].proximal_dubins_frame(), atol=1e-12)


def test_delete_a_joint_with_several_children():
    tree = KinematicTree(StartTip(4, 1, SE3(), 1.5))
    w = tree.addJoint(0, Waypoint(4, 1, SE3.Trans(0, 0, 3)), **EXACT)
    a = tree.addJoint(w, RevoluteJoint(4, 1, math.pi, SE3.Trans(3, 0, 8) * SE3.Ry(-math.pi / 2)),
                      **EXACT)  # fmt: skip
    b = tree.addJoint(w, RevoluteJoint(4, 1, math.pi, SE3.Trans(-3, 0, 8) * SE3.Ry(-math.pi / 2)),
                      **EXACT)  # fmt: skip
    assert (a, b) == (2, 3)
    assert tree.delete(w)
    assert tree.Parents == (-1, 0, 0)
    for k in (1, 2):
        assert_allclose(tree.Links[k].start_frame, tree.Joints[0].distal_dubins_frame(),
                        atol=1e-12)  # fmt: skip


def test_delete_the_root():
    tree = KinematicTree(StartTip(4, 1, SE3(), 1.5))
    tree.addJoint(0, RevoluteJoint(4, 1, math.pi, SE3.Trans(0, 0, 5) * SE3.Ry(-math.pi / 2)),
                  **EXACT)  # fmt: skip
    assert tree.delete(0)
    assert tree.Parents == (-1,) and isinstance(tree.Joints[0], RevoluteJoint)
    hand = quiet_hand()
    before = hand.Joints
    with pytest.warns(PlacementWarning, match="exactly one child"):
        assert hand.delete(0) is False
    assert hand.Joints == before


# --- transactions and bad input --------------------------------------------------------------
@pytest.mark.parametrize(
    "states",
    [3, None, "0" * 12, {k: 0.0 for k in range(12)}, set(range(12)), np.array(0.0)],
    ids=["int", "None", "str", "dict", "set", "0-d array"],
)
def test_set_joint_states_refuses_what_is_not_a_sequence(states, snapshot):
    """As for a chain (one check): a dict's keys, a set in no order and a 0-d array (its len()
    raised numpy's TypeError) are not states."""
    tree = quiet_hand()
    before = snapshot(tree)
    with pytest.raises(InvalidTypeError, match=r"^states must be a sequence of numbers, got "):
        tree.setJointStates(states)
    assert snapshot(tree) == before


def test_refused_operations_leave_the_tree_bit_identical(snapshot):
    tree = quiet_hand()
    before = snapshot(tree)
    with pytest.warns(PlacementWarning, match="outside its range"):
        assert tree.setJointState(1, 4.0) is False
    with pytest.warns(PlacementWarning, match="outside"):
        assert tree.setJointStates([0.0] * 11 + [5.0]) is False
    with pytest.warns(PlacementWarning, match="addJoint failed"):  # a U-turn over the root
        assert tree.addJoint(0, RevoluteJoint(4, 1, math.pi, SE3.Trans(0, 0, 10)
                                              * SE3.Ry(math.pi / 2)), **EXACT) is None
    assert snapshot(tree) == before
    tree.requireClearance = True
    with pytest.warns(PlacementWarning, match="would pass through itself"):
        assert tree.setJointState(8, 0.2) is False  # the palm contact stays
    with pytest.warns(PlacementWarning, match="would pass through itself"):
        assert tree.translateJointAlongAxisOfMotion(9, 0.1) is False
    assert snapshot(tree) == before


def test_no_link_reaches_the_joint(snapshot):
    """A joint right behind its parent facing back: no CSC with turns < pi; refused."""
    tree = KinematicTree(StartTip(4, 1, SE3(), 1.5))
    before = snapshot(tree)
    with pytest.warns(PlacementWarning, match="addJoint failed"):
        index = tree.addJoint(0, RevoluteJoint(4, 1, math.pi, SE3.Trans(0, 0, 10) * RY), **EXACT)
    assert index is None
    assert snapshot(tree) == before


def test_bad_input_names_the_parameter():
    tree = KinematicTree(StartTip(4, 1, SE3(), 1.5))
    with pytest.raises(InvalidTypeError, match="parentIndex must be an integer"):
        tree.addJoint("0", RevoluteJoint(4, 1, math.pi, SE3()))
    with pytest.raises(JointIndexError, match=r"parentIndex must be in \[-1, 0\]"):
        tree.addJoint(3, RevoluteJoint(4, 1, math.pi, SE3()))
    end = tree.addJoint(0, EndTip(4, 1, SE3.Trans(0, 0, 5), 1.5), **EXACT)
    with pytest.raises(InvalidParameterError, match="EndTip"):
        tree.addJoint(end, RevoluteJoint(4, 1, math.pi, SE3()))
    with pytest.raises(InvalidParameterError, match="StartTip"):
        tree.addJoint(0, StartTip(4, 1, SE3(), 1.5))
    with pytest.raises(InvalidParameterError, match="one value per joint"):
        tree.setJointStates([0.0])
    with pytest.raises(InvalidTypeError):
        tree.setJointStates("00")
    with pytest.raises(InvalidParameterError, match="safe=True and fixedPosition"):
        tree.addJoint(0, RevoluteJoint(4, 1, math.pi, SE3()), fixedPosition=True)


# --- from_joints: bad input ---------------------------------------------------------------
W0, W5 = Waypoint(4, 1, SE3()), Waypoint(4, 1, SE3.Trans(0, 0, 5))


@pytest.mark.parametrize(
    ("parents", "message"),
    [
        ([-1, None], r"parents\[1\] must be an integer, got None"),
        ([-1, 0.5], r"parents\[1\] must be an integer, got 0\.5"),
        ([-1, 0.0], r"parents\[1\] must be an integer, got 0\.0"),
        ([-1.0, 0], r"parents\[0\] must be an integer, got -1\.0"),
        ([-1, "0"], r"parents\[1\] must be an integer, got '0'"),
        ([-1, True], r"parents\[1\] must be an integer, got True"),
        ((-1, np.bool_(False)), r"parents\[1\] must be an integer, got .*False"),
        (np.array([-1.0, 0.0]), r"parents\[0\] must be an integer, got np\.float64\(-1\.0\)"),
        ("x", r"parents must be a sequence of integers .*, got 'x'"),
        ("-10", r"parents must be a sequence of integers .*, got '-10'"),
        (None, r"parents must be a sequence of integers .*, got None"),
        ({-1, 0}, r"parents must be a sequence of integers"),
        (iter([-1, 0]), r"parents must be a sequence of integers"),
        (np.array([[-1, 0]]), r"parents must be a sequence of integers"),
        (np.int64(-1), r"parents must be a sequence of integers"),
    ],
)
def test_from_joints_parents_must_be_integers(parents, message):
    with pytest.raises(InvalidTypeError, match=message):
        KinematicTree.from_joints([W0, W5], parents)


def test_from_joints_parents_one_per_joint_describing_a_tree():
    with pytest.raises(InvalidParameterError, match=r"one entry per joint \(1\), got 2"):
        KinematicTree.from_joints([W0], [-1, 0])
    with pytest.raises(InvalidParameterError, match=r"one entry per joint \(2\), got 1"):
        KinematicTree.from_joints([W0, W5], np.array([-1]))
    with pytest.raises(InvalidParameterError, match=r"parents\[0\] must be -1 \(the root\), got 0"):
        KinematicTree.from_joints([W0, W5], np.array([0, 0]))
    with pytest.raises(InvalidParameterError, match=r"parents\[1\] must be in \[0, 0\], got 1"):
        KinematicTree.from_joints([W0, W5], [-1, np.int32(1)])
    with pytest.raises(InvalidParameterError, match=r"parents\[1\] must be in \[0, 0\], got <an"):
        KinematicTree.from_joints([W0, W5], [-1, 10**5000])  # named, not printed


@pytest.mark.parametrize(
    ("joints", "message"),
    [
        (None, r"joints must be a sequence of Joint objects, got None"),
        ("ab", r"joints must be a sequence of Joint objects, got 'ab'"),
        (W0, r"joints must be a sequence of Joint objects, got Waypoint\("),
        ([W0, "x"], r"joints\[1\] must be a Joint, got 'x'"),
        (["x", W5], r"joints\[0\] must be a Joint, got 'x'"),
        ([W0, None], r"joints\[1\] must be a Joint, got None"),
    ],
)
def test_from_joints_joints_must_be_joints(joints, message):
    with pytest.raises(InvalidTypeError, match=message):
        KinematicTree.from_joints(joints, [-1, 0])


def test_from_joints_needs_a_root():
    with pytest.raises(InvalidParameterError, match="at least one joint"):
        KinematicTree.from_joints([], [])


def test_from_joints_takes_numpy_integers(snapshot):
    hand = quiet_hand()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        expected = snapshot(KinematicTree.from_joints(hand.Joints, hand.Parents))
        for parents in (
            np.array(hand.Parents),
            np.array(hand.Parents, dtype=np.int8),
            [np.int64(p) for p in hand.Parents],
            list(hand.Parents),
        ):
            tree = KinematicTree.from_joints(list(hand.Joints), parents)
            assert tree.Parents == hand.Parents
            assert all(type(p) is int for p in tree.Parents)
            assert snapshot(tree) == expected
    small = KinematicTree.from_joints((j for j in (W0, W5)), range(-1, 1))  # any iterable of joints
    assert small.Parents == (-1, 0)


def test_clearance_at_other_states_does_not_change_the_tree(hand, snapshot):
    before = snapshot(hand)
    report = hand.clearance([0.0] * len(hand.Joints))
    assert report.states == tuple([0.0] * len(hand.Joints))
    assert snapshot(hand) == before
    with pytest.raises(InvalidParameterError, match="outside joint 1"):
        hand.clearance([0.0, 9.0] + [0.0] * 10)
