"""The editor on trees: documents, the commands acting on subtrees, branches (a chain becomes a
tree), refusals, sheets, files and the autosave (docs/editor.md, Trees)."""

from __future__ import annotations

import concurrent.futures
import json

import numpy as np
import pytest
from numpy.testing import assert_allclose
from spatialmath import SE3

from kinegami.editor import (
    AddBranch,
    AddJoint,
    DeleteJoint,
    Document,
    EditorModel,
    FitJunctions,
    SetJointState,
    SlideJoint,
)
from kinegami.editor.autosave import Autosaver, autosave_path, find_recovery
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.fabrication.sheets import fabricate, fit_junctions
from kinegami.tree import KinematicTree
from tests.editor.helpers import (
    GRIPPER,
    HAND,
    HAND_JUNCTION,
    HAND_PARENTS,
    HAND_SHEET_JOINTS,
    HAND_SLIDES,
    example_model,
    hand_model,
    snapshot,
)


@pytest.fixture
def hand() -> EditorModel:
    return hand_model()


def refused(model: EditorModel, command, *words: str) -> str:
    """Apply ``command``, check that it failed and changed nothing; return the reason."""
    before, bits, history = model.document, snapshot(model.document), model.undo_labels
    result = model.apply(command)
    assert not result.ok and result.change is None
    assert model.document is before and snapshot(model.document) == bits
    assert model.undo_labels == history
    for word in words:
        assert word in result.reason, result.reason
    return result.reason


def _poses(model: EditorModel, joints) -> list[bytes]:
    return [model.chain.Joints[k].pose_matrix.tobytes() for k in joints]


# --- the document ----------------------------------------------------------------------------
def test_a_tree_design_opens_as_a_tree(hand):
    assert hand.is_tree and isinstance(hand.chain, KinematicTree)
    assert hand.chain.Parents == HAND_PARENTS
    assert hand.document.names[5] == "pointer1"


def test_the_joint_table_has_parents_and_children(hand):
    rows = hand.joint_table()
    assert [row.parent for row in rows] == list(HAND_PARENTS)
    assert rows[0].children == (1, 5, 8) and rows[4].children == ()
    chain = example_model().joint_table()
    assert [row.parent for row in chain] == list(range(-1, 6))


def test_a_tree_has_sheets_not_one_pattern(hand):
    with pytest.raises(InvalidTypeError, match="one per leaf"):
        hand.pattern()
    with pytest.raises(InvalidTypeError, match="one per leaf"):
        hand.joint_modules()


# --- commands on subtrees --------------------------------------------------------------------
def test_a_propagated_slide_moves_the_subtree_only(hand):
    others = [k for k in range(12) if k not in hand.chain.subtree(5)]
    before = _poses(hand, others)
    tip = hand.chain.Joints[7].pose_matrix.copy()
    assert hand.slide("pointer1", 0.5, propagate=True).ok
    assert _poses(hand, others) == before
    axis = hand.chain.Joints[5].pose_matrix[:3, 2]
    assert_allclose(hand.chain.Joints[7].pose_matrix[:3, 3], tip[:3, 3] + 0.5 * axis, atol=1e-12)


def test_a_slide_without_propagation_relinks_the_joint_and_its_children(hand):
    change = hand.slide("pointer1", 0.5, propagate=False).change
    assert change.joints == (5,)
    assert change.links == (5, 6)


def test_a_state_change_moves_the_subtree_beyond_the_joint(hand):
    others = [k for k in range(12) if k not in hand.chain.subtree(9)[1:]]
    before = _poses(hand, others)
    tip = hand.chain.Joints[11].pose_matrix.copy()
    result = hand.apply(SetJointState("middle1", 0.4))
    assert result.ok and hand.selected == 9
    assert _poses(hand, [k for k in others if k != 9]) == [
        p for k, p in zip(others, before, strict=True) if k != 9
    ]
    assert not np.array_equal(hand.chain.Joints[11].pose_matrix, tip)


def test_new_parameters_keep_the_tree(hand):
    assert hand.set_parameters("pointer2", numSinkLayers=2).ok
    assert hand.chain.Parents == HAND_PARENTS
    assert hand.joint_table()[6].parameters["numSinkLayers"] == 2
    assert_allclose(hand.chain.Joints[11].pose_matrix, hand_model().chain.Joints[11].pose_matrix,
                    atol=1e-12)  # fmt: skip


def test_a_new_max_angle_rebuilds_the_tree(hand):
    assert hand.set_options(maxAnglePerElbow=1.0).ok
    assert hand.is_tree and hand.chain.Parents == HAND_PARENTS
    assert hand.chain.maxAnglePerElbow == 1.0


def test_compact_keeps_the_names_of_the_joints_it_keeps():
    model = EditorModel.open(GRIPPER)
    names = model.document.names
    result = model.compact(starts=1, time_limit=5.0,
                           executor=concurrent.futures.ThreadPoolExecutor(1))  # fmt: skip
    assert result.ok, result.reason
    assert model.is_tree and model.clearance().ok
    kept = [n for n in model.document.names if n is not None]
    assert kept == [n for n in names if n is not None]


def test_motion_compaction_of_a_tree_is_a_reason(hand):
    assert "chains" in hand.compact(motion=True).reason


# --- adding joints -----------------------------------------------------------------------------
def test_a_branch_of_a_tree_is_a_new_child_and_moves_nothing(hand):
    before = snapshot(hand.document)
    poses = _poses(hand, range(12))
    result = hand.add_branch("RevoluteJoint", parent="pointer2", name="extra")
    assert result.ok, result.reason
    new = hand.selected
    assert hand.document.names[new] == "extra" and new >= 12
    assert _poses(hand, range(12)) == poses
    parents = hand.chain.Parents
    assert parents[:12] == HAND_PARENTS
    k = new
    while parents[k] != 6:  # safe placement's waypoints lead from pointer2 to it
        assert type(hand.chain.Joints[parents[k]]).__name__ == "Waypoint"
        k = parents[k]
    assert 7 in hand.chain.Children[6]  # pointer2 keeps its child
    assert hand.undo().ok and snapshot(hand.document) == before


def test_a_branch_makes_a_chain_a_tree():
    model = example_model()
    chain = model.chain
    result = model.add_branch("RevoluteJoint", parent="revolute")
    assert result.ok, result.reason
    tree = model.chain
    assert isinstance(tree, KinematicTree) and model.is_tree
    n = len(chain.Joints)
    assert tree.Parents[:n] == tuple(range(-1, n - 1))
    assert len(tree.Children[4]) == 2
    for old, new in zip(chain.Joints, tree.Joints, strict=False):  # the chain's part, bit for bit
        assert new is old
    for old, new in zip(chain.Links, tree.Links, strict=False):
        assert new is old
    text = json.loads(model.to_design_text())
    assert text["version"] == 2 and text["structure"] == "tree"
    assert Document.loads(model.to_design_text()).chain.Parents == tree.Parents
    assert model.undo().ok and not model.is_tree and model.chain is chain


def test_a_child_of_a_chains_last_joint_keeps_it_a_chain():
    model, other = example_model(), example_model()
    model.apply(DeleteJoint("end"))
    other.apply(DeleteJoint("end"))
    assert model.add_branch("RevoluteJoint").ok
    assert other.add_joint("RevoluteJoint", after=-1).ok
    assert not model.is_tree
    assert snapshot(model.document) == snapshot(other.document)


def test_adding_after_a_tree_joint_takes_over_its_children(hand):
    result = hand.add_joint("Waypoint", pose=SE3.Trans(0, 0, 4).A, after="pointer1",
                            placement="pose", name="mid")  # fmt: skip
    assert result.ok and not any("placed again" in w for w in result.warnings), result
    mid = hand.document.names.index("mid")
    pointer2 = hand.document.names.index("pointer2")
    assert hand.chain.Parents[mid] == 5 and hand.chain.Parents[pointer2] == mid
    assert hand.document.names.index("thumbEnd") == 4  # the joints before it keep their index
    assert_allclose(hand.chain.Joints[pointer2].pose_matrix,
                    hand_model().chain.Joints[6].pose_matrix, atol=1e-12)  # fmt: skip


def test_an_end_tip_takes_no_children(hand):
    refused(hand, AddJoint("EndTip", after="pointer1"), "an EndTip can only be a leaf",
            "joints 6")  # fmt: skip


def test_nothing_is_added_to_an_end_tip(hand):
    refused(hand, AddBranch("RevoluteJoint", parent="thumbEnd"), "nothing can follow",
            "is a leaf of the tree")  # fmt: skip


def test_a_start_tip_is_only_the_root(hand):
    refused(hand, AddBranch("StartTip", parent=0), "StartTip can only be the first joint",
            "tree")  # fmt: skip


def test_a_branch_of_a_missing_joint_is_a_reason(hand):
    refused(hand, AddBranch("RevoluteJoint", parent="wrist"), "parent: no joint is named 'wrist'")


# --- deleting ----------------------------------------------------------------------------------
def test_a_joint_with_several_children_is_not_deleted(hand):
    refused(hand, DeleteJoint("root"), "has 3 children (joints 1, 5, 8)",
            "at most one child")  # fmt: skip


def test_deleting_a_joint_links_its_child_to_its_parent(hand):
    assert hand.delete("pointer1").ok
    assert hand.selected == 0  # its parent
    pointer2 = hand.document.names.index("pointer2")
    assert hand.chain.Parents[pointer2] == 0
    assert len(hand.chain.Joints) == 11


def test_deleting_a_leaf_selects_its_parent(hand):
    assert hand.delete("thumbEnd").ok
    assert hand.selected == 3 and hand.chain.Children[3] == ()


# --- sheets ------------------------------------------------------------------------------------
def test_the_hands_sheets_are_what_kinegami_build_makes(hand):
    sheets = hand.sheets()
    assert [s.joints for s in sheets.sheets] == list(HAND_SHEET_JOINTS)
    assert sheets.slides == HAND_SLIDES
    (junction,) = sheets.fabrication.junctions
    assert (junction.joint, junction.children, junction.trunk) == HAND_JUNCTION
    fitted, _ = fit_junctions(hand.chain)
    theirs = fabricate(fitted)
    for mine, built in zip(sheets.sheets, theirs.sheets, strict=True):
        assert np.array_equal(mine.pattern.vertices_coords, built.pattern.vertices_coords)
    assert "'pointer1'" in sheets.labels[1]
    assert [where for where, _ in sheets.places][:2] == [0, 2]


def test_the_sheets_are_computed_once_per_document(hand):
    assert hand.sheets() is hand.sheets()
    first = hand.sheets()
    hand.rename("palm", "wrist")
    assert hand.sheets() is not first and "'wrist'" in hand.sheets().labels[2]


def test_a_tree_that_cannot_be_made_says_why_every_time(hand):
    calls = []

    def fit(tree):
        calls.append(tree)
        raise InvalidParameterError("no slide makes room")

    for _ in range(2):
        with pytest.raises(InvalidParameterError, match="no slide makes room"):
            hand.sheets(fit=fit)
    assert len(calls) == 1


def test_a_chain_has_no_sheets():
    with pytest.raises(InvalidTypeError, match="one sheet"):
        example_model().sheets()


def test_fit_junctions_slides_the_joints_as_build_does(hand):
    pose = hand.chain.Joints[1].pose_matrix.copy()
    result = hand.apply(FitJunctions())
    assert result.ok and hand.selected == 1
    moved = hand.chain.Joints[1].pose_matrix
    assert_allclose(moved[:3, 3], pose[:3, 3] + HAND_SLIDES[0][1] * pose[:3, 2], atol=1e-9)
    assert hand.sheets().slides == ()
    refused(hand, FitJunctions(), "fits already")


def test_fit_junctions_of_a_chain_is_a_reason():
    refused(example_model(), FitJunctions(), "a chain has no junctions")


# --- files -------------------------------------------------------------------------------------
def test_a_tree_saves_and_loads_exactly(hand, tmp_path):
    assert hand.slide("pointer1", 0.5).ok
    assert hand.add_branch("EndTip", parent="middle1").ok
    text = hand.to_design_text()
    assert hand.save(tmp_path / "hand.json").ok and not hand.dirty
    loaded = EditorModel.open(tmp_path / "hand.json")
    assert loaded.is_tree and loaded.chain.Parents == hand.chain.Parents
    assert loaded.document.names == hand.document.names
    assert loaded.to_design_text() == text
    for a, b in zip(loaded.chain.Joints, hand.chain.Joints, strict=True):
        assert a.pose_matrix.tobytes() == b.pose_matrix.tobytes()


def test_a_tree_with_states_round_trips(hand, tmp_path):
    assert hand.set_state("pointer1", 0.7).ok
    assert hand.save(tmp_path / "hand.json").ok
    loaded = EditorModel.open(tmp_path / "hand.json")
    for a, b in zip(loaded.chain.Joints, hand.chain.Joints, strict=True):
        assert_allclose(a.pose_matrix, b.pose_matrix, atol=1e-12)
    assert loaded.joint_table()[5].state == 0.7


def test_parents_follow_renamed_joints(hand):
    assert hand.rename("root", "palmBase").ok
    assert hand.rename("palm", "root").ok  # the old name of joint 0 now names joint 1
    entries = json.loads(hand.to_design_text())["joints"]
    assert entries[5]["parent"] == "palmBase" and entries[2]["parent"] == "root"
    assert Document.loads(hand.to_design_text()).chain.Parents == HAND_PARENTS


def test_a_trees_autosave_is_offered_back(tmp_path):
    design = tmp_path / "hand.json"
    design.write_bytes(HAND.read_bytes())
    model = EditorModel.open(design)
    assert model.add_branch("RevoluteJoint", parent="thumb1").ok
    saver = Autosaver(autosave_path(design), delay=60.0)
    saver.record(model.document, model.dirty)
    saver.flush()
    recovery = find_recovery(design)
    assert recovery is not None and recovery.document.is_tree
    assert snapshot(recovery.document) == snapshot(model.document)


def test_an_undone_branch_gives_the_chain_back_bit_for_bit():
    model = example_model()
    original = snapshot(model.document)
    for command in (AddBranch("Waypoint", {}, None, 2), SlideJoint(4, 0.25),
                    AddBranch("EndTip", {}, None, 0)):  # fmt: skip
        assert model.apply(command).ok
    while model.can_undo:
        assert model.undo().ok
    assert snapshot(model.document) == original and not model.dirty
