"""The API's bounds (kinegami.validation): r in [1e-6, 1e6], lengths and translations within
1e6 r, numbers finite; an InvalidParameterError (also a ValueError) naming the parameter, the
value and the limit, never an OverflowError, and the chain bit-identical after a rejection."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from spatialmath import SE3

from kinegami import (
    EndTip,
    ExtendedRevoluteJoint,
    InvalidParameterError,
    JointIndexError,
    KinegamiError,
    KinematicChain,
    LinkCSC,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)
from kinegami.chain.dh import dh_transform
from kinegami.validation import LENGTH_FACTOR, R_MAX, R_MIN, shorten, shown, shown_path

HUGE = 10**400  # a Python int beyond the float range
ENORMOUS = 10**5000  # beyond int -> str conversion (4300 digits)


def _message(excinfo) -> str:
    error = excinfo.value
    assert isinstance(error, KinegamiError) and isinstance(error, ValueError)
    text = str(error)
    assert "\n" not in text and len(text) < 300, text
    return text


def _matrix(x=0.0, y=0.0, z=0.0):
    T = np.eye(4).tolist()
    T[0][3], T[1][3], T[2][3] = x, y, z
    return T


# --- edits of a chain ----------------------------------------------------------------------
@pytest.mark.parametrize("distance", [1.3e154, -1.3e154, 1e6 * (1 + 1e-9), 1e300, -2e6])
def test_translation_beyond_the_bound_names_distance_value_and_limit(
    example_1a, snapshot, distance
):
    before = snapshot(example_1a)
    with pytest.raises(InvalidParameterError) as excinfo:
        example_1a.translateJointAlongAxisOfMotion(4, distance)
    text = _message(excinfo)
    assert "distance" in text and repr(float(distance)) in text and "1e6 r" in text
    assert snapshot(example_1a) == before


@pytest.mark.parametrize("distance", [1e6, -1e6, 5e5])
def test_translation_at_the_bound_is_computed_without_overflow(example_1a, distance):
    with warnings.catch_warnings():
        warnings.simplefilter("error", RuntimeWarning)  # no numpy overflow
        warnings.simplefilter("ignore", UserWarning)  # a rejected edit may warn
        moved = example_1a.translateJointAlongAxisOfMotion(4, distance)
    assert moved in (True, False)
    ball = example_1a.boundingBall
    assert math.isfinite(ball.r) and np.all(np.isfinite(ball.c))
    if moved:
        assert example_1a.Links[4].path.length > 0.5 * abs(distance)


@pytest.mark.parametrize(
    "edit, args, name",
    [
        ("translateJointAlongAxisOfMotion", (4, HUGE), "distance"),
        ("translateJointAlongAxisOfMotion", (4, -ENORMOUS), "distance"),
        ("rotateJointAboutAxisOfMotion", (4, HUGE), "angle"),
        ("setJointState", (4, HUGE), "newState"),
        ("setJointState", (2, -HUGE), "newState"),
        ("setJointStates", ([0, 0, 0, 0, HUGE, 0, 0],), "states[4]"),
        ("transformJoint", (2, _matrix(HUGE)), "Transformation"),
        ("transformAll", (_matrix(0, 0, -HUGE),), "Transformation"),
    ],
)
def test_ints_beyond_the_float_range_are_parameter_errors(
    example_1a, snapshot, edit, args, name
):
    before = snapshot(example_1a)
    with pytest.raises(InvalidParameterError) as excinfo:  # not an OverflowError
        getattr(example_1a, edit)(*args)
    text = _message(excinfo)
    assert name in text and ("digits" in text or "float range" in text)
    assert snapshot(example_1a) == before


@pytest.mark.parametrize("edit", ["transformJoint", "transformAll"])
@pytest.mark.parametrize("offset", [2e6, -1.5e6, 1e200])
def test_transformations_beyond_the_bound(example_1a, snapshot, edit, offset):
    before = snapshot(example_1a)
    args = (SE3.Trans(0, offset, 0),) if edit == "transformAll" else (3, SE3.Tz(offset))
    with pytest.raises(InvalidParameterError) as excinfo:
        getattr(example_1a, edit)(*args)
    text = _message(excinfo)
    assert "Transformation" in text and repr(float(offset)) in text and "1e6 r" in text
    assert snapshot(example_1a) == before


def test_a_huge_joint_index_is_named_by_its_digits(example_1a, snapshot):
    before = snapshot(example_1a)
    with pytest.raises(JointIndexError) as excinfo:
        example_1a.setJointState(ENORMOUS, 0.0)
    assert "jointIndex" in str(excinfo.value) and "digits" in str(excinfo.value)
    assert snapshot(example_1a) == before


# --- joints, links, DH tables ----------------------------------------------------------------
TOO_LONG = 2e6  # r = 1
MAKERS = {
    "StartTip length": (lambda v: StartTip(4, 1, SE3(), v), "length"),
    "EndTip length": (lambda v: EndTip(4, 1, SE3(), v), "length"),
    "tubeLength": (lambda v: ExtendedRevoluteJoint(4, 1, math.pi, v, SE3()), "tubeLength"),
    "neutralLength": (lambda v: PrismaticJoint(4, 1, v, 3, math.pi / 4, SE3()), "neutralLength"),
}


@pytest.mark.parametrize(
    "value", [TOO_LONG, 1e300, HUGE, ENORMOUS], ids=["2e6", "1e300", "10**400", "10**5000"]
)
@pytest.mark.parametrize("case", MAKERS)
def test_lengths_beyond_the_bound(case, value):
    make, name = MAKERS[case]
    with pytest.raises(InvalidParameterError) as excinfo:
        make(value)
    text = _message(excinfo)
    assert name in text
    if isinstance(value, float):
        assert repr(value) in text and "1e6 r" in text


POSED = {
    "RevoluteJoint": lambda T: RevoluteJoint(4, 1, math.pi, T),
    "PrismaticJoint": lambda T: PrismaticJoint(4, 1, 3, 3, math.pi / 4, T),
    "Waypoint": lambda T: Waypoint(4, 1, T),
    "StartTip": lambda T: StartTip(4, 1, T, 1.5),
    "EndTip": lambda T: EndTip(4, 1, T, 1.5),
}


@pytest.mark.parametrize("kind", POSED)
@pytest.mark.parametrize("pose", [SE3.Trans(0, 0, 1.5e6), _matrix(-1e300), _matrix(0, HUGE)])
def test_poses_beyond_the_bound(kind, pose):
    with pytest.raises(InvalidParameterError) as excinfo:
        POSED[kind](pose)
    assert "Pose" in _message(excinfo)


@pytest.mark.parametrize("kind", POSED)
def test_poses_at_the_bound(kind):
    joint = POSED[kind](SE3.Trans(1e6, -1e6, 1e6))
    assert np.all(joint.pose_matrix[:3, 3] == (1e6, -1e6, 1e6))


@pytest.mark.parametrize("r", [R_MIN / 2, R_MAX * 2, 1e300, HUGE], ids=str)
@pytest.mark.parametrize("kind", POSED)
def test_radius_outside_its_range(kind, r):
    make = {
        "RevoluteJoint": lambda: RevoluteJoint(4, r, math.pi, SE3()),
        "PrismaticJoint": lambda: PrismaticJoint(4, r, 3 * R_MIN, 3, math.pi / 4, SE3()),
        "Waypoint": lambda: Waypoint(4, r, SE3()),
        "StartTip": lambda: StartTip(4, r, SE3(), 1.5 * R_MIN),
        "EndTip": lambda: EndTip(4, r, SE3(), 1.5 * R_MIN),
    }[kind]
    with pytest.raises(InvalidParameterError) as excinfo:
        make()
    assert "r " in _message(excinfo)


@pytest.mark.parametrize("r", [R_MIN, R_MAX])
def test_radius_at_its_bounds(r):
    assert RevoluteJoint(4, r, math.pi, SE3()).r == r


def test_link_poses_beyond_the_bound():
    with pytest.raises(InvalidParameterError) as excinfo:
        LinkCSC(1, SE3(), SE3.Trans(3e6, 0, 0))
    assert "EndDubinsPose" in _message(excinfo)
    with pytest.raises(InvalidParameterError) as excinfo:
        LinkCSC(1, _matrix(HUGE), SE3())
    assert "StartDubinsPose" in _message(excinfo)


@pytest.mark.parametrize("row", [[0, 0, 2e6, 0], [0, 0, 0, -2e6], [0, 0, HUGE, 0], [HUGE, 0, 1, 0]])
def test_dh_rows_beyond_the_bound(row):
    with pytest.raises(InvalidParameterError) as excinfo:
        KinematicChain.from_dh([row, [0, 0, 1, 0]], 4, 1)
    assert "table row 0" in _message(excinfo)


def test_dh_transform_rejects_ints_beyond_the_float_range():
    with pytest.raises(InvalidParameterError) as excinfo:
        dh_transform(HUGE, 0, 0, 0)
    assert "theta" in _message(excinfo)


# --- what the library computes itself is not held to the bounds -------------------------------
def test_positions_reached_by_relative_poses_may_exceed_the_bound():
    chain = KinematicChain(StartTip(4, 1, SE3.Trans(9e5, 0, 0), 1.5))
    for _ in range(2):
        index = chain.append(Waypoint(4, 1, SE3.Trans(9e5, 0, 0)), safe=False, fixedPosition=True)
        assert index is not None
    assert chain.Joints[-1].pose_matrix[0, 3] == pytest.approx(2.7e6)
    assert chain.translateJointAlongAxisOfMotion(len(chain) - 1, 1e6)


def test_dh_frames_may_compose_beyond_the_bound():
    rows = [[0, 0, 9e5, 0], [0, 0, 9e5, 0], [0, 0, 9e5, 0]]
    chain = KinematicChain.from_dh(rows, 4, 1, placement="safe")
    assert max(abs(j.pose_matrix[0, 3]) for j in chain.Joints) > LENGTH_FACTOR


# --- rendering of values in messages ---------------------------------------------------------
def test_shown_values_are_short():
    assert shown("x" * 10_000).endswith("...") and len(shown("x" * 10_000)) == 80
    assert shown(ENORMOUS) == "<an integer of about 5001 digits>"
    assert shown(-HUGE) == "<a negative integer of 401 digits>"
    assert shown(list(range(100_000))).endswith("...")
    deep: list = []
    for _ in range(100_000):
        deep = [deep]
    assert len(shown(deep)) <= 80
    assert shorten("a\nb " * 100, 10) == "a b a b..."


def test_long_paths_in_messages_keep_their_name():
    """A path too long to show keeps its start and its end, so the name the user gave stays."""
    path = "/check/work/" + "/".join(["pytest-of-root-popen-gw1"] * 6) + "/file.txt/out.json"
    text = shown_path(path)
    assert len(text) == 80 and text.startswith("'/check/") and text.endswith("file.txt/out.json'")
    assert "..." in text
    assert shown_path("/tmp/a b\nc") == "'/tmp/a b c'"
