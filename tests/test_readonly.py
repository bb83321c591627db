"""Joints and links are values: their public attributes refuse assignment and deletion with a
ReadOnlyError (a KinegamiError and an AttributeError) that says what to do instead
(docs/errors.md); construction, value-style copies and the chain keep working."""

from __future__ import annotations

import copy
import keyword
import math
import pickle

import numpy as np
import pytest
from hypothesis import given
from hypothesis import strategies as st
from spatialmath import SE3

from kinegami import (
    EndTip,
    ExtendedRevoluteJoint,
    KinegamiError,
    LinkCSC,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)
from kinegami.errors import ReadOnlyError

#: One value of every joint type and of LinkCSC, built by the public constructors.
MAKERS = {
    "RevoluteJoint": lambda: RevoluteJoint(4, 1.0, math.pi / 2, SE3.Trans(1, 2, 3)),
    "ExtendedRevoluteJoint": lambda: ExtendedRevoluteJoint(6, 1.0, math.pi, 2.0, SE3.Rx(0.3)),
    "PrismaticJoint": lambda: PrismaticJoint(4, 1.0, 1.5, 3, math.pi / 4, SE3.Ry(0.2)),
    "Waypoint": lambda: Waypoint(4, 1.0, SE3.Trans(0, 1, 0), pathIndex=0),
    "StartTip": lambda: StartTip(4, 1.0, SE3(), 2.0),
    "EndTip": lambda: EndTip(4, 1.0, SE3.Trans(0, 0, 9), 2.0),
    "LinkCSC": lambda: LinkCSC(1.0, SE3(), SE3.Trans(10, 4, 0) * SE3.Rx(0.7)),
}
KINDS = sorted(MAKERS)


def public_names(obj) -> list[str]:
    """Every public attribute of ``obj``: data, properties, cached properties and methods."""
    return [name for name in dir(obj) if not name.startswith("_")]


def fingerprint(obj) -> str:
    """The repr plus every public non-method attribute value (before and after a refusal)."""
    parts = [repr(obj)]
    for name in public_names(obj):
        value = getattr(obj, name)
        if not callable(value) or isinstance(value, SE3):
            parts.append(f"{name}={value!r}")
    return "\n".join(parts)


def all_cases() -> list[tuple[str, str]]:
    return [(kind, name) for kind in KINDS for name in public_names(MAKERS[kind]())]


def check_refusal(excinfo, obj, name: str) -> None:
    error = excinfo.value
    assert isinstance(error, ReadOnlyError)
    assert isinstance(error, KinegamiError)
    assert isinstance(error, AttributeError)
    message = str(error)
    assert f"{type(obj).__name__}.{name} is read-only" in message, message
    assert "build a new" in message, message


def test_read_only_error_is_a_kinegami_error_and_an_attribute_error():
    assert issubclass(ReadOnlyError, KinegamiError)
    assert issubclass(ReadOnlyError, AttributeError)


@pytest.mark.parametrize("kind", KINDS)
def test_every_type_has_public_attributes_to_protect(kind):
    names = public_names(MAKERS[kind]())
    assert "r" in names and len(names) > 5


@pytest.mark.parametrize(("kind", "name"), all_cases())
def test_every_public_attribute_refuses_assignment(kind, name):
    obj = MAKERS[kind]()
    before = fingerprint(obj)
    with pytest.raises(ReadOnlyError) as excinfo:
        setattr(obj, name, 5)
    check_refusal(excinfo, obj, name)
    assert fingerprint(obj) == before


@pytest.mark.parametrize(("kind", "name"), all_cases())
def test_every_public_attribute_refuses_deletion(kind, name):
    obj = MAKERS[kind]()
    before = fingerprint(obj)
    with pytest.raises(ReadOnlyError) as excinfo:
        delattr(obj, name)
    check_refusal(excinfo, obj, name)
    assert "cannot be deleted" in str(excinfo.value)
    assert fingerprint(obj) == before


identifiers = st.from_regex(r"[A-Za-z][A-Za-z0-9_]{0,20}", fullmatch=True).filter(
    lambda name: not keyword.iskeyword(name)
)
values = st.one_of(
    st.none(), st.booleans(), st.integers(), st.floats(), st.text(max_size=5), st.just(SE3())
)


@given(kind=st.sampled_from(KINDS), name=identifiers, value=values)
def test_no_public_attribute_can_be_set_or_added(kind, name, value):
    """Existing or new, no public name can be assigned: a joint cannot be given a stray
    attribute (``joint.totalBendingAngel = 1``, misspelt) that would silently do nothing."""
    obj = MAKERS[kind]()
    before = fingerprint(obj)
    with pytest.raises(ReadOnlyError):
        setattr(obj, name, value)
    assert fingerprint(obj) == before


def test_bending_angle_cannot_change_the_state_range():
    joint = MAKERS["RevoluteJoint"]()
    with pytest.raises(ReadOnlyError, match="setJointState"):
        joint.totalBendingAngle = 0.1
    np.testing.assert_allclose(joint.stateRange(), (-math.pi / 4, math.pi / 4), rtol=0, atol=0)


def test_link_radius_cannot_break_its_crease_pattern():
    link = MAKERS["LinkCSC"]()
    with pytest.raises(ReadOnlyError, match="LinkCSC"):
        link.r = 5
    assert link.r == 1.0
    assert link.creasePattern(4).numSides == 4


@pytest.mark.parametrize("kind", [k for k in KINDS if k != "LinkCSC"])
def test_value_style_copies_still_work(kind):
    joint = MAKERS[kind]()
    moved = joint.with_pose(SE3.Trans(5, 0, 0).A @ joint.pose_matrix)
    np.testing.assert_allclose(moved.pose_matrix[:3, 3], joint.pose_matrix[:3, 3] + [5, 0, 0])
    lo, hi = joint.stateRange()
    state = (lo + hi) / 2 + (hi - lo) / 4
    assert joint.with_state(state).state == state
    assert joint.state == 0.0  # the original is unchanged
    for other in (moved, joint.translated_along_z(1.0), joint.with_reversed_path_direction()):
        assert type(other) is type(joint)
        with pytest.raises(ReadOnlyError):
            other.r = 2.0


@pytest.mark.parametrize("kind", KINDS)
@pytest.mark.parametrize("how", ["copy", "deepcopy", "pickle"])
def test_copies_and_pickles_keep_the_value_and_stay_read_only(kind, how):
    obj = MAKERS[kind]()
    if how == "copy":
        other = copy.copy(obj)
    elif how == "deepcopy":
        other = copy.deepcopy(obj)
    else:
        other = pickle.loads(pickle.dumps(obj))
    assert fingerprint(other) == fingerprint(obj)
    with pytest.raises(ReadOnlyError):
        other.r = 2.0


def test_moved_link_keeps_its_cache_and_stays_read_only():
    link = MAKERS["LinkCSC"]()
    _ = link.elbows1, link.twistAngle, link.arc1Ball  # fill the cache transformed() copies
    moved = link.transformed(SE3.Trans(1, 2, 3).A)
    assert moved.twistAngle == link.twistAngle
    with pytest.raises(ReadOnlyError):
        moved.elbows1 = None
    with pytest.raises(ReadOnlyError):
        del moved.twistAngle


def test_the_chain_works_after_refused_assignments(example_1a, snapshot, chain_checker):
    chain = example_1a
    before = snapshot(chain)
    for obj in (*chain.Joints, *chain.Links):
        for name in public_names(obj):
            with pytest.raises(ReadOnlyError):
                setattr(obj, name, 0.1)
    assert snapshot(chain) == before
    index = next(k for k, j in enumerate(chain.Joints) if isinstance(j, RevoluteJoint))
    assert chain.setJointState(index, 0.1) is True
    assert chain.Joints[index].state == 0.1
    assert chain.setJointState(index, 0.0) is True
    assert chain.translateJointAlongAxisOfMotion(index, 0.5) is True
    chain_checker(chain)
    assert chain.creasePattern().numSides == chain.numSides


def test_the_chain_stays_an_editor():
    """The chain is the one editor object: its documented settings can still be assigned."""
    from kinegami import KinematicChain

    chain = KinematicChain(StartTip(4, 1.0, SE3(), 1.0))
    chain.requireClearance = False
    assert chain.requireClearance is False
    chain.requireClearance = True
    assert chain.requireClearance is True


def test_the_arrays_a_link_hands_out_are_read_only():
    link = MAKERS["LinkCSC"]()
    moved = link.transformed(SE3.Trans(1, 2, 3).A)
    for value in (link, moved):
        for array in (
            value.start_frame,
            value.end_frame,
            value.arc1_end_frame,
            value.arc2_start_frame,
            value.elbows1.frames,
            value.elbows2.frames,
        ):
            with pytest.raises(ValueError, match="read-only"):
                array[0, 0] = 7.0


@pytest.mark.parametrize("kind", [k for k in KINDS if k != "LinkCSC"])
def test_a_joints_pose_array_is_read_only(kind):
    joint = MAKERS[kind]()
    with pytest.raises(ValueError, match="read-only"):
        joint.pose_matrix[0, 3] = 7.0
    pose = joint.Pose
    pose.A[0, 3] = 7.0  # a new SE3 each time: changing it does not change the joint
    assert joint.pose_matrix[0, 3] != 7.0
