"""Sheets and printed junctions of a tree: as many sheets as leaves, the trunk rule, branch sheets
that start at their sockets with the rest of their links, and what cannot be made."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose
from spatialmath import SE3

from kinegami import (
    ClearanceWarning,
    EndTip,
    InvalidParameterError,
    InvalidTypeError,
    KinematicChain,
    KinematicTree,
    LinkCSC,
    RevoluteJoint,
    StartTip,
    Waypoint,
)
from kinegami.fabrication.sheets import (
    choose_trunks,
    default_trunks,
    fabricate,
    fit_junctions,
    junction_problems,
)
from tests.tree.helpers import hand_tree

RY = SE3.Ry(math.pi / 2)


def slid_hand() -> KinematicTree:
    """The paper's hand with the palm slid 3 r down its axis, so that its socket fits."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        tree = hand_tree()
        assert tree.translateJointAlongAxisOfMotion(1, -3.0)
    return tree


def test_the_papers_hand_cannot_be_made_as_designed():
    """Its palm's link (3.10 r) runs with its siblings for all of its length."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        hand = hand_tree()
    problems = junction_problems(hand)
    assert [child for child, _ in problems] == [1]
    assert "no room for its 1 r socket" in problems[0][1]
    with pytest.raises(InvalidParameterError, match="cannot be made with printed junctions"):
        fabricate(hand)


def test_hand_sheets_follow_the_trunk_rule():
    hand = slid_hand()
    assert default_trunks(hand) == {0: 8}  # the middle finger has the longest path (17.29 r)
    made = fabricate(hand)
    assert [s.joints for s in made.sheets] == [(0, 8, 9, 10, 11), (5, 6, 7), (1, 2, 3, 4)]
    assert [s.junction for s in made.sheets] == [None, 0, 0]
    assert [s.leaf for s in made.sheets] == [11, 7, 4]
    (junction,) = made.junctions
    assert (junction.joint, junction.children, junction.trunk) == (0, (1, 5, 8), 8)
    assert junction.parent_side == "base"
    text = made.sheets[1].label(hand)
    assert text.startswith("sheet 1: joints 5 to 7; starts in junction 0 (at joint 0)")


def test_an_overridden_trunk():
    hand = slid_hand()
    # middle0 runs with its siblings all along its link: it can only be the trunk
    assert [c for c, _ in junction_problems(hand, trunks={0: 5})] == [8]
    with pytest.raises(InvalidParameterError, match="joint 8 .* no room"):
        fabricate(hand, trunks={0: 5})
    assert hand.translateJointAlongAxisOfMotion(8, -3.0)  # now it has room
    made = fabricate(hand, trunks={0: 5})
    assert [s.joints for s in made.sheets] == [(0, 5, 6, 7), (8, 9, 10, 11), (1, 2, 3, 4)]
    with pytest.raises(InvalidParameterError, match="not a child of joint 0"):
        fabricate(slid_hand(), trunks={0: 2})
    with pytest.raises(InvalidParameterError, match="does not branch"):
        fabricate(slid_hand(), trunks={1: 2})


@pytest.mark.parametrize(
    ("trunks", "error", "message"),
    [
        ({0: True}, InvalidTypeError, r"trunks\[0\] must be an integer, got True"),
        ({True: 1}, InvalidTypeError, "trunks: a joint must be an integer, got True"),
        ({0: 1.0}, InvalidTypeError, r"trunks\[0\] must be an integer, got 1.0"),
        ({"0": 1}, InvalidTypeError, "trunks: a joint must be an integer, got '0'"),
        ({0: 10**5000}, InvalidParameterError, "integer of about 5001 digits"),
        ({10**5000: 1}, InvalidParameterError, "integer of about 5001 digits"),
        ([(0, 1)], InvalidTypeError, r"trunks must map joints to children, got \[\(0, 1\)\]"),
    ],
    ids=["bool child", "bool joint", "float child", "str joint", "huge child", "huge joint",
         "list"],
)
def test_trunks_of_the_wrong_kind(trunks, error, message):
    """Bools were read as 0/1, a huge index crashed repr(); each names what is wrong."""
    hand = slid_hand()
    with pytest.raises(error, match=message):
        junction_problems(hand, trunks=trunks)


def test_trunks_take_numpy_integers():
    hand = slid_hand()
    assert junction_problems(hand, trunks={np.int64(0): np.int64(5)}) == junction_problems(
        hand, trunks={0: 5}
    )


def test_a_child_whose_socket_does_not_fit_becomes_the_trunk():
    hand = slid_hand()
    assert hand.translateJointAlongAxisOfMotion(1, 3.0)  # back where the paper has it
    assert hand.translateJointAlongAxisOfMotion(8, -3.0)  # middle0 gets room instead
    trunks, problems = choose_trunks(hand)
    assert trunks == {0: 1} and problems == []


def test_a_branch_sheet_starts_with_the_rest_of_its_link():
    hand = slid_hand()
    made = fabricate(hand)
    for sheet in made.sheets[1:]:
        first = sheet.joints[0]
        link = hand.Links[first]
        socket = made.junctions[0].sockets[made.junctions[0].children.index(first)]
        assert sheet.start_arc == pytest.approx(socket.sheet_start)
        assert socket.start + 1.0 == pytest.approx(socket.socket_end)  # d_s = r
        rest = LinkCSC(1, socket.frame, hand.Joints[first].proximal_dubins_frame(),
                       hand.maxAnglePerElbow)  # fmt: skip
        # the same path from the socket on: it is as long as the rest of the link
        assert rest.path.length == pytest.approx(link.path.length - sheet.start_arc, abs=1e-6)
        # and the sheet is that rest plus the chain beyond it, module for module
        kinds = [m.kind for m in sheet.pattern.modules]
        assert kinds[: len(rest.pattern_modules(4, 0.2))] == [
            m.modules[0].kind for m in rest.pattern_modules(4, 0.2)
        ]


def test_the_trunk_sheet_of_a_chain_is_its_crease_pattern():
    tree = KinematicTree(StartTip(4, 1, SE3(), 1.5))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        up = SE3.Trans(0, 0, 6) * SE3.Ry(-math.pi / 2)
        a = tree.addJoint(0, RevoluteJoint(4, 1, math.pi, up))
        tree.addJoint(a, EndTip(4, 1, SE3.Trans(5, 0, 0) * RY, 1.5))
    made = fabricate(tree)
    assert len(made.sheets) == 1 and made.junctions == ()
    from kinegami import KinematicChain

    chain = KinematicChain(tree.Joints[0])
    for joint in tree.Joints[1:]:
        chain.append(joint, relative=False, safe=False, fixedPosition=True, fixedOrientation=True)
    expected = chain.creasePattern()
    got = made.sheets[0].pattern
    assert np.array_equal(got.vertices_coords, expected.vertices_coords)
    assert np.array_equal(got.edges_vertices, expected.edges_vertices)
    assert np.array_equal(got.edges_assignment, expected.edges_assignment)


@settings(max_examples=8, deadline=None)
@given(st.lists(st.tuples(st.floats(0, 2 * math.pi), st.integers(1, 2)), min_size=2, max_size=4))
def test_one_sheet_per_leaf_and_every_joint_on_one_sheet(fingers):
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for angle, joints in fingers:
            parent = 0
            pose = SE3.Rz(angle) * SE3.Trans(3, 0, 4) * RY
            for _ in range(joints):
                parent = tree.addJoint(parent, RevoluteJoint(4, 1, math.pi, pose))
                pose = SE3.Trans(4, 0, 0)
    if junction_problems(tree):
        with pytest.raises(InvalidParameterError):
            fabricate(tree)
        return
    made = fabricate(tree)
    leaves = [k for k, c in enumerate(tree.Children) if not c]
    assert len(made.sheets) == len(leaves)
    assert sorted(s.leaf for s in made.sheets) == leaves
    carried = sorted(k for s in made.sheets for k in s.joints)
    assert carried == list(range(len(tree.Joints)))  # each joint on exactly one sheet
    for sheet in made.sheets:
        for a, b in zip(sheet.joints, sheet.joints[1:], strict=False):
            assert tree.Parents[b] == a  # a sheet follows the tree
        assert sheet.pattern.validate().ok


def test_connectors_are_watertight():
    pytest.importorskip("manifold3d")
    made = fabricate(slid_hand())
    mesh = made.connector(0)
    assert mesh.is_watertight and mesh.is_volume
    # the connector sits at the root: it reaches the sockets of all three fingers
    junction = made.junctions[0]
    centre = slid_hand().Joints[0].distal_dubins_frame()[:3, 3]
    reach = max(s.socket_end for s in junction.sockets)
    assert np.max(np.linalg.norm(mesh.vertices - centre, axis=1)) <= reach + 2.0
    with pytest.raises(InvalidParameterError, match="junctions"):
        made.connector(1)


def test_sheet_start_frames_lie_on_their_links():
    made = fabricate(slid_hand())
    hand = made.tree
    for socket, child in zip(made.junctions[0].sockets, made.junctions[0].children, strict=True):
        link = hand.Links[child]
        if socket.trunk:
            continue
        # the frame is on the tube's centreline, at the socket's distance from the junction
        d = np.linalg.norm(socket.frame[:3, 3] - link.start_frame[:3, 3])
        assert d <= socket.sheet_start + 1e-9
        assert_allclose(np.linalg.det(socket.frame[:3, :3]), 1.0, atol=1e-12)


def test_default_labels_give_lengths_as_multiples_of_r():
    """A tree in mm with r = 10 mm: the label's "x r along its link" is start_arc / r (it
    printed the length in mm followed by "r")."""
    import re
    from pathlib import Path

    from kinegami.design import load_design
    from kinegami.fabrication.sheets import fit_junctions

    design = Path(__file__).resolve().parents[2] / "examples" / "designs" / "quadruped.json"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        tree, _ = fit_junctions(load_design(design))
    assert tree.r == 10.0
    made = fabricate(tree)
    for sheet in made.sheets[1:]:
        found = re.search(r"([0-9.]+) r along its link", sheet.label(tree))
        assert found, sheet.label(tree)
        assert abs(float(found.group(1)) - sheet.start_arc / tree.r) < 0.01


# --- bad input -----------------------------------------------------------------------------
TREE_FUNCTIONS = [fit_junctions, junction_problems, choose_trunks, default_trunks, fabricate]


@pytest.mark.parametrize("function", TREE_FUNCTIONS, ids=lambda f: f.__name__)
@pytest.mark.parametrize(
    ("value", "got"), [("x", "str"), (None, "NoneType"), (1, "int")], ids=["str", "None", "int"]
)
def test_a_tree_is_needed(function, value, got):
    with pytest.raises(InvalidTypeError, match=f"^tree must be a KinematicTree, got {got}$"):
        function(value)


@pytest.mark.parametrize("function", TREE_FUNCTIONS, ids=lambda f: f.__name__)
def test_a_chain_is_not_a_tree_and_the_message_says_how_to_get_one(function):
    chain = KinematicChain.from_dh([(0, math.pi / 2, 0, 0), (0, 0, 4, 0)], 4, 1)
    hint = r"\(KinematicTree\.from_chain\(chain\) is the tree of a chain\)"
    with pytest.raises(InvalidTypeError, match=f"tree must be a KinematicTree {hint}, got Kinem"):
        function(chain)
    tree, moves = fit_junctions(KinematicTree.from_chain(chain))  # what the message says works
    assert moves == [] and tree.Parents == chain.Parents


@pytest.mark.parametrize("function", [fit_junctions, junction_problems, choose_trunks, fabricate],
                         ids=lambda f: f.__name__)  # fmt: skip
def test_connector_options_are_checked(function):
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    with pytest.raises(InvalidTypeError, match="^options must be ConnectorOptions, got 'x'$"):
        function(tree, options="x")
