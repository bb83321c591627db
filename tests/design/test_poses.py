"""The three pose spellings (matrix, steps, axis) and angle units."""

from __future__ import annotations

import copy
import json
import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from spatialmath import SE3

from kinegami.design import DesignError, chain_from_dict, pose_from_json
from kinegami.design.poses import RIGID_TOL, default_xhat

from . import PI, assert_same_chain

angles = st.floats(-math.pi, math.pi, allow_nan=False)
lengths = st.floats(-50, 50, allow_nan=False)
unit_vectors = (
    st.tuples(st.floats(-1, 1), st.floats(-1, 1), st.floats(-1, 1))
    .map(np.array)
    .filter(lambda v: np.linalg.norm(v) > 0.1)
)


def _spellings(T: np.ndarray) -> list:
    """The same pose as a matrix and as an axis (point, axis = z, xhat = x)."""
    return [
        T.tolist(),
        {"point": T[:3, 3].tolist(), "axis": T[:3, 2].tolist(), "xhat": T[:3, 0].tolist()},
    ]


@given(t=st.tuples(lengths, lengths, lengths), a=angles, b=angles, c=angles)
def test_steps_are_spatialmath_products(t, a, b, c):
    steps = [{"Trans": list(t)}, {"Rz": a}, {"Ry": b}, {"Rx": c}, {"Tx": 1.5}, {"Tz": -2}]
    expected = SE3.Trans(*t) * SE3.Rz(a) * SE3.Ry(b) * SE3.Rx(c) * SE3.Tx(1.5) * SE3.Tz(-2)
    np.testing.assert_array_equal(pose_from_json(steps), expected.A)  # bit for bit


@given(t=st.tuples(lengths, lengths, lengths), a=angles, b=angles, c=angles)
def test_three_spellings_give_the_same_pose(t, a, b, c):
    steps = [{"Trans": list(t)}, {"Rz": a}, {"Ry": b}, {"Rx": c}]
    T = pose_from_json(steps)
    for spelling in _spellings(T):
        np.testing.assert_allclose(pose_from_json(spelling), T, rtol=0, atol=1e-12)
    assert np.array_equal(pose_from_json(T.tolist()), T)  # matrices are used as written


@given(t=st.tuples(lengths, lengths, lengths), a=angles, b=angles)
def test_degrees_and_radians_agree(t, a, b):
    rad = pose_from_json([{"Trans": list(t)}, {"Ry": a}, {"Rz": b}], angle_units="rad")
    deg = pose_from_json(
        [{"Trans": list(t)}, {"Ry": math.degrees(a)}, {"Rz": math.degrees(b)}], angle_units="deg"
    )
    np.testing.assert_allclose(deg, rad, rtol=0, atol=1e-12)


def test_empty_steps_and_missing_pose_are_the_identity():
    assert np.array_equal(pose_from_json([]), np.eye(4))
    chain = chain_from_dict(
        {"format": "kinegami-design", "version": 1, "numSides": 4, "r": 1,
         "joints": [{"type": "Waypoint"}]}
    )  # fmt: skip
    assert np.array_equal(chain.Joints[0].pose_matrix, np.eye(4))


def test_axis_with_z_axis_and_no_xhat_is_exact():
    T = pose_from_json({"point": [1, 2, 3], "axis": [0, 0, 5]})
    expected = np.eye(4)
    expected[:3, 3] = (1, 2, 3)
    assert np.array_equal(T, expected)
    assert np.array_equal(pose_from_json({"axis": [0, 0, 1]}), np.eye(4))  # point defaults to 0


@given(axis=unit_vectors)
def test_default_xhat_is_perpendicular_and_deterministic(axis):
    T = pose_from_json({"axis": axis.tolist()})
    z = axis / np.linalg.norm(axis)
    np.testing.assert_allclose(T[:3, 2], z, atol=1e-15)
    assert abs(T[:3, 0] @ z) <= 1e-15
    np.testing.assert_allclose(T[:3, :3].T @ T[:3, :3], np.eye(3), atol=1e-15)
    assert np.linalg.det(T[:3, :3]) == pytest.approx(1.0, abs=1e-15)
    assert np.array_equal(pose_from_json({"axis": axis.tolist()}), T)
    # the world axis least aligned with the joint axis, made perpendicular
    e = default_xhat(z)
    assert abs(e @ z) == pytest.approx(float(np.min(np.abs(z))))


@given(axis=unit_vectors, xhat=unit_vectors)
def test_xhat_is_made_perpendicular(axis, xhat):
    z = axis / np.linalg.norm(axis)
    if np.linalg.norm(xhat - (xhat @ z) * z) < 1e-3 * np.linalg.norm(xhat):
        return  # (nearly) parallel: covered by test_parallel_xhat_is_an_error
    T = pose_from_json({"axis": axis.tolist(), "xhat": xhat.tolist()})
    x = xhat - (xhat @ z) * z
    np.testing.assert_allclose(T[:3, 0], x / np.linalg.norm(x), atol=1e-12)
    np.testing.assert_allclose(T[:3, 1], np.cross(z, T[:3, 0]), atol=1e-15)


@pytest.mark.parametrize("xhat", [[0, 0, 3], [0, 0, -1e-3], [0, 0, 0]])
def test_parallel_xhat_is_an_error(xhat):
    with pytest.raises(DesignError, match="parallel") as info:
        pose_from_json({"axis": [0, 0, 1], "xhat": xhat}, ["joints", 1, "pose"])
    assert info.value.field == "joints[1].pose.xhat" and info.value.value == xhat


def test_rigidity_tolerance_is_1e_9():
    near = np.eye(4)
    near[0, 0] += 0.4 * RIGID_TOL
    assert np.array_equal(pose_from_json(near.tolist()), near)
    far = np.eye(4)
    far[0, 0] += 10 * RIGID_TOL
    with pytest.raises(DesignError, match="orthonormal"):
        pose_from_json(far.tolist())


CHAIN = {
    "format": "kinegami-design",
    "version": 1,
    "numSides": 6,
    "r": 0.75,
    "joints": [
        {"type": "RevoluteJoint", "totalBendingAngle": 2.0, "pose": []},
        {"type": "PrismaticJoint", "neutralLength": 2, "numLayers": 2, "coneAngle": 0.9},
        {"type": "ExtendedRevoluteJoint", "totalBendingAngle": 1.5, "tubeLength": 0.5},
        {"type": "Waypoint", "pathIndex": 0},
        {"type": "EndTip", "length": 1},
    ],
}
PLACEMENTS = [
    {},
    {"safe": False},
    {"relative": False, "safe": False},
    {"safe": False, "fixedPosition": True, "fixedOrientation": True},
]
FIXED = {"relative": False, "safe": False, "fixedPosition": True, "fixedOrientation": True}


def _chain_or_none(document):
    try:
        return chain_from_dict(document)
    except DesignError as error:
        assert "infeasible placement" in error.reason
        return None


@settings(max_examples=25, deadline=None)
@given(
    poses=st.lists(
        st.tuples(st.tuples(lengths, lengths, lengths), angles, angles), min_size=5, max_size=5
    ),
    placement=st.sampled_from(PLACEMENTS),
)
def test_spellings_build_the_same_chain(poses, placement):
    """The same design written with steps, matrices and axes gives the same chain.

    Steps and matrices give bit-identical poses, so every placement mode must give the same
    chain. The axis spelling re-orthogonalises (poses equal to ~1e-16), so it is compared with
    fixed placement only: safe and compact placement make discrete choices (how many waypoints,
    which side) that a last-bit change may flip.
    """
    documents = [copy.deepcopy(CHAIN) for _ in range(3)]
    for i, (t, a, b) in enumerate(poses):
        steps = [{"Trans": list(t)}, {"Rz": a}, {"Ry": b}]
        matrix, axis = _spellings(pose_from_json(steps))
        for document, pose in zip(documents, (steps, matrix, axis), strict=True):
            document["joints"][i]["pose"] = pose
            if i:
                document["joints"][i].update(FIXED if document is documents[2] else placement)
    steps_chain, matrix_chain = _chain_or_none(documents[0]), _chain_or_none(documents[1])
    if steps_chain is None:
        assert matrix_chain is None  # a placement the chain rejects, for both spellings
    else:
        assert_same_chain(matrix_chain, steps_chain, pose_tol=0.0)
    for document in documents[:2]:
        for joint in document["joints"][1:]:
            joint.update(FIXED)
    fixed, axis_chain = _chain_or_none(documents[0]), _chain_or_none(documents[2])
    if fixed is None:
        assert axis_chain is None
    else:
        assert_same_chain(axis_chain, fixed, pose_tol=1e-12)


def test_axis_spelling_of_example_1a(example_1a):
    """Example 1A with axis poses: same chain as the Python listing (safe placement)."""
    from . import DATA

    document = json.loads((DATA / "example1a.json").read_text(encoding="utf-8"))
    joints = document["joints"]
    joints[0]["pose"] = {"point": [3, 3, 0], "axis": [0, 0, 1]}
    joints[1]["pose"] = {"point": [5, 5, 0], "axis": [0, 0, 1], "xhat": [1, 0, 0]}
    joints[2]["pose"] = {"axis": [1, 0, 1], "xhat": [1, 0, -1]}  # Ry(pi/4)
    joints[3]["pose"] = {"axis": [1, 0, 0], "xhat": [0, 0, -1]}  # Ry(pi/2)
    assert_same_chain(chain_from_dict(document), example_1a, pose_tol=1e-12)


def test_degrees_build_the_same_chain_as_radians():
    rad = copy.deepcopy(CHAIN)
    rad["maxAnglePerElbow"] = PI / 3
    rad["joints"][1]["pose"] = [{"Trans": [4, 1, 0]}, {"Ry": PI / 4}]
    rad["edits"] = [
        {"op": "rotateJointAboutAxisOfMotion", "joint": 2, "angle": -0.5},
        {"op": "transformAll", "transform": [{"Rz": 1.0}]},
        {"op": "setJointState", "joint": 0, "state": 0.5},
    ]
    deg = copy.deepcopy(rad)
    deg["angleUnits"] = "deg"
    deg["maxAnglePerElbow"] = 60
    deg["joints"][0]["totalBendingAngle"] = math.degrees(2.0)
    deg["joints"][1]["coneAngle"] = math.degrees(0.9)
    deg["joints"][1]["pose"][1]["Ry"] = 45
    deg["joints"][2]["totalBendingAngle"] = math.degrees(1.5)
    deg["edits"][0]["angle"] = math.degrees(-0.5)
    deg["edits"][1]["transform"] = [{"Rz": math.degrees(1.0)}]
    deg["edits"][2]["state"] = math.degrees(0.5)
    a, b = chain_from_dict(rad), chain_from_dict(deg)
    assert b.Joints[0].state == pytest.approx(0.5, abs=1e-15)
    assert b.maxAnglePerElbow == PI / 3
    # joint parameters may differ in the last bit after the degree conversion
    np.testing.assert_allclose(
        [j.pose_matrix for j in b.Joints], [j.pose_matrix for j in a.Joints], rtol=0, atol=1e-12
    )


_STEP_KINDS = ["Trans", "Tx", "Ty", "Tz", "Rx", "Ry", "Rz"]


@given(st.lists(st.tuples(st.sampled_from(_STEP_KINDS), st.tuples(lengths, lengths, lengths)),
                min_size=1, max_size=6))  # fmt: skip
def test_any_steps_equal_spatialmath_to_the_bit_without_importing_it(steps):
    """Design poses use spatialmath's arithmetic without importing spatialmath (which costs
    most of a second): equal bits, signs of zeros included, for any sequence of steps."""
    json_steps, expected = [], None
    for kind, v in steps:
        if kind == "Trans":
            json_steps.append({kind: list(v)})
            factor = SE3.Trans(*v)
        elif kind in ("Tx", "Ty", "Tz"):
            json_steps.append({kind: v[0]})
            factor = getattr(SE3, kind)(v[0])
        else:
            json_steps.append({kind: v[0]})
            factor = getattr(SE3, kind)(v[0])
        expected = factor if expected is None else expected * factor
    got = pose_from_json(json_steps)
    want = np.array(expected.A, dtype=float)
    assert got.tobytes() == want.tobytes()
