"""Property tests of the editor model on trees: random command sequences, valid and invalid,
on the two-finger gripper (a tree) and on example 1 (a chain that branches become a tree).

As for chains (test_properties.py): a failed command changes nothing; every successful one is
undone and redone exactly; undoing everything gives back the original document bit for bit
(design text, structure, parents, poses, states, link frames), redoing everything the final
one; and the design text of every document loads as a document with the same structure.
"""

from __future__ import annotations

import math

from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from spatialmath import SE3

from kinegami.editor import (
    AddBranch,
    AddJoint,
    DeleteJoint,
    Document,
    EditorModel,
    RenameJoint,
    RollJoint,
    SetJointParameters,
    SetJointState,
    SetJointStates,
    SetOptions,
    SlideJoint,
    TransformJoint,
)
from tests.editor.helpers import EXAMPLE1, GRIPPER, snapshot

NAMES = ["palm", "leftTip", "rightBase", "revolute", "end", "nope"]
KINDS = ["RevoluteJoint", "PrismaticJoint", "Waypoint", "EndTip", "StartTip"]

joint_refs = st.one_of(st.integers(-12, 12), st.sampled_from(NAMES))
amounts = st.one_of(st.floats(-2, 2, allow_nan=False), st.sampled_from([float("nan"), 1e12]))
poses = st.one_of(
    st.none(),
    st.builds(lambda x, a: (SE3.Trans(x, 0, 4) * SE3.Ry(a)).A, st.floats(-3, 3),
              st.floats(-math.pi, math.pi)),  # fmt: skip
)

commands = st.one_of(
    st.builds(SlideJoint, joint_refs, amounts, st.booleans(), st.booleans()),
    st.builds(RollJoint, joint_refs, amounts, st.booleans()),
    st.builds(TransformJoint, joint_refs, poses, st.booleans()),
    st.builds(DeleteJoint, joint_refs),
    st.builds(AddBranch, st.sampled_from(KINDS), st.just({}), poses, joint_refs,
              st.sampled_from(["safe", "safe", "compact", "pose"])),  # fmt: skip
    st.builds(AddJoint, st.sampled_from(KINDS), st.just({}), poses, joint_refs,
              st.sampled_from(["safe", "compact", "pose"])),  # fmt: skip
    st.builds(SetJointParameters, joint_refs, st.sampled_from([{"numSinkLayers": 2}, {"x": 1}])),
    st.builds(RenameJoint, joint_refs, st.sampled_from([None, "w", "palm"])),
    st.builds(SetJointState, joint_refs, amounts),
    st.builds(SetJointStates, st.lists(st.floats(-0.5, 0.5), min_size=10, max_size=12)),
    st.builds(SetOptions, maxAnglePerElbow=st.sampled_from([math.pi / 2, 1.2])),
)
actions = st.one_of(commands, commands, st.sampled_from(["undo", "redo"]))


@settings(deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.sampled_from([GRIPPER, EXAMPLE1]), st.lists(actions, min_size=1, max_size=8))
def test_random_command_sequences_on_trees_undo_and_redo_exactly(path, sequence):
    model = EditorModel.open(path)
    original = snapshot(model.document)
    for action in sequence:
        document, bits, history = model.document, snapshot(model.document), model.undo_labels
        if action in ("undo", "redo"):
            result = getattr(model, action)()
            if not result.ok:
                assert model.document is document and model.undo_labels == history
            continue
        result = model.apply(action)
        event(f"{type(action).__name__} {'applied' if result.ok else 'refused'}")
        if not result.ok:
            assert result.reason and result.change is None
            assert model.document is document and snapshot(model.document) == bits
            assert model.undo_labels == history
            continue
        event("a tree" if model.is_tree else "a chain")
        after = snapshot(model.document)
        assert model.undo().ok and snapshot(model.document) == bits
        assert model.redo().ok and snapshot(model.document) == after
        if model.selected is not None:
            assert 0 <= model.selected < len(model.chain.Joints)
        try:
            text = model.to_design_text()
        except ValueError:
            continue
        again = Document.loads(text)
        assert again.is_tree == model.is_tree and again.chain.Parents == model.chain.Parents
        assert again.names == model.document.names
    final, done = snapshot(model.document), len(model.undo_labels)
    while model.can_undo:
        assert model.undo().ok
    assert snapshot(model.document) == original and not model.dirty
    for _ in range(done):
        assert model.redo().ok
    assert snapshot(model.document) == final
