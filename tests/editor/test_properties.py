"""Property tests of the editor model: random command sequences, valid and invalid.

* a failed command changes nothing (the same document object, the same bits, the same history);
* every successful command is undone and redone exactly;
* undoing everything gives back the original document bit for bit (design text, joint poses,
  states, link frames), redoing everything the final one; the dirty flag follows;
* the model's crease pattern is the chain's, bit for bit.
"""

from __future__ import annotations

import math

import numpy as np
from hypothesis import HealthCheck, event, given, settings
from hypothesis import strategies as st
from spatialmath import SE3

from kinegami.editor import (
    KEEP,
    AddJoint,
    DeleteJoint,
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

NAMES = ["start", "prismatic", "revolute", "end", "w", "nope", ""]
BAD_NUMBERS = [float("nan"), float("inf"), 1e12, "1", None, True]


def numbers(lo: float, hi: float):
    return st.one_of(
        st.floats(lo, hi, allow_nan=False, allow_infinity=False),
        st.floats(lo, hi, allow_nan=False, allow_infinity=False),
        st.sampled_from(BAD_NUMBERS),
    )


joint_refs = st.one_of(
    st.integers(-8, 8), st.integers(-8, 8), st.sampled_from(NAMES), st.sampled_from([True, 2.5])
)


@st.composite
def transforms(draw):
    if draw(st.integers(0, 9)) == 0:
        return draw(st.sampled_from([np.eye(3), np.diag([1.0, 1.0, 2.0, 1.0]), "Tz"]))
    t = draw(st.lists(st.floats(-4, 4), min_size=3, max_size=3))
    a = draw(st.floats(-math.pi, math.pi))
    return (SE3.Trans(t) * SE3.Rx(a) * SE3.Rz(a / 2)).A


parameters = st.sampled_from(
    [{}, {"numSinkLayers": 2}, {"numSinkLayers": 0}, {"length": 2.0}, {"neutralLength": 2.0},
     {"totalBendingAngle": 1.0}, {"pathIndex": 0}, {"coneAngle": 0.1}, {"bogus": 1}]
)  # fmt: skip

commands = st.one_of(
    st.builds(SlideJoint, joint_refs, numbers(-3, 3), st.booleans(), st.booleans()),
    st.builds(RollJoint, joint_refs, numbers(-3, 3), st.booleans(), st.booleans()),
    st.builds(TransformJoint, joint_refs, transforms(), st.booleans(), st.booleans()),
    st.builds(TransformAll, transforms()),
    st.builds(DeleteJoint, joint_refs),
    st.builds(
        AddJoint,
        st.sampled_from(
            [
                "RevoluteJoint",
                "PrismaticJoint",
                "Waypoint",
                "EndTip",
                "ExtendedRevoluteJoint",
                "StartTip",
                "Hinge",
            ]
        ),  # fmt: skip
        parameters,
        transforms(),
        st.one_of(st.none(), joint_refs),
        st.sampled_from(["safe", "compact", "pose", "near"]),
        st.booleans(),
        st.sampled_from([None, None, "w", "start", ""]),
    ),
    st.builds(
        AddJoint,
        st.sampled_from(["RevoluteJoint", "PrismaticJoint", "Waypoint"]),
        st.just({}),
        transforms(),
        st.integers(0, 4),
        st.sampled_from(["safe", "safe", "compact", "pose"]),
    ),
    st.builds(SetJointParameters, joint_refs, parameters),
    st.builds(RenameJoint, joint_refs, st.sampled_from([None, "w", "start", "", 5])),
    st.builds(SetJointState, joint_refs, numbers(-2, 2)),
    st.builds(SetJointStates, st.lists(st.floats(-0.5, 0.5), max_size=9)),
    st.builds(
        SetOptions,
        requireClearance=st.sampled_from([KEEP, True, False, "yes"]),
        maxAnglePerElbow=st.sampled_from([KEEP, KEEP, math.pi / 2, math.pi / 3, 0.0]),
        twistPortion=st.sampled_from([KEEP, None, 0.3, 1.5]),
    ),
)

actions = st.one_of(
    commands, commands, commands, st.sampled_from(["undo", "redo"]), st.tuples(joint_refs)
)


def check_failed(model, result, bits, document, history) -> None:
    assert not result.ok and result.reason and result.change is None
    assert model.document is document
    assert snapshot(model.document) == bits
    assert model.undo_labels == history


@settings(deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(st.lists(actions, min_size=1, max_size=10))
def test_random_command_sequences_undo_and_redo_exactly(sequence):
    model = example_model()
    original = snapshot(model.document)
    for action in sequence:
        document, bits, history = model.document, snapshot(model.document), model.undo_labels
        dirty = model.dirty
        if action == "undo" or action == "redo":
            result = getattr(model, action)()
            if not result.ok:
                check_failed(model, result, bits, document, history)
            continue
        if isinstance(action, tuple):  # a selection
            result = model.select(action[0])
            assert model.document is document
            if not result.ok:
                assert dirty == model.dirty
            continue
        result = model.apply(action)
        event(f"{type(action).__name__} {'applied' if result.ok else 'refused'}")
        if not result.ok:
            check_failed(model, result, bits, document, history)
            assert model.dirty == dirty
            continue
        assert model.dirty or model.document is model._saved
        after = snapshot(model.document)
        assert model.undo().ok and snapshot(model.document) == bits
        assert model.redo().ok and snapshot(model.document) == after
        if model.selected is not None:
            assert 0 <= model.selected < len(model.chain.Joints)
    final, done = snapshot(model.document), len(model.undo_labels)
    while model.can_undo:
        assert model.undo().ok
    assert snapshot(model.document) == original
    assert not model.dirty
    for _ in range(done):  # redo what was done (an undone command may wait beyond it)
        assert model.redo().ok
    assert snapshot(model.document) == final
    try:
        theirs = model.chain.creasePattern(model.document.twist_portion)
    except ValueError:
        return
    mine = model.pattern()
    for name in ("vertices_coords", "edges_vertices", "edges_assignment"):
        assert np.array_equal(getattr(mine, name), getattr(theirs, name))
