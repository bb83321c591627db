"""Chains from DH tables (chain.md 8 and 11.8): frames, axes, placement, errors."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kinegami import *
from kinegami.chain.dh import dh_frames, dh_joint_frames, dh_tool_frame, dh_transform
from kinegami.errors import InvalidParameterError, InvalidTypeError, NoPathError
from kinegami.optimize import shorten_by_axis_translations

PI = math.pi
PUMA = [
    (PI / 2, -PI / 2, 0, 0),
    (0, 0, 431.8, 149.09),
    (PI / 2, PI / 2, -20.32, 0),
    (0, -PI / 2, 0, 433.07),
    (0, PI / 2, 0, 0),
    (0, 0, 0, 56.25),
]


def matlab_rows(rows):
    """chain.md 8.1 rows (a_{i-1}, alpha_{i-1}, d_i, theta_i) -> our (theta, alpha, a, d)."""
    return [(theta, alpha, a, d) for a, alpha, d, theta in rows]


def structural(chain):
    """The chain's joints that come from table rows (safe placement adds waypoints)."""
    return [j for j in chain.Joints if not isinstance(j, Waypoint | EndTip)]


def assert_on_axes(chain, frames, scale):
    joints = structural(chain)
    assert len(joints) == len(frames)
    for joint, G in zip(joints, frames, strict=True):
        P = joint.pose_matrix
        # same axis line; same direction too, except that safe placement may reverse a
        # prismatic joint's path (= its axis), which only flips the sign of its state
        if isinstance(joint, PrismaticJoint) and P[:3, 2] @ G[:3, 2] < 0:
            np.testing.assert_allclose(-P[:3, 2], G[:3, 2], atol=1e-12)
        else:
            np.testing.assert_allclose(P[:3, 2], G[:3, 2], atol=1e-12)
        offset = P[:3, 3] - G[:3, 3]
        assert np.linalg.norm(np.cross(offset, G[:3, 2])) <= 1e-9 * scale


# --- frames ----------------------------------------------------------------------------------
def test_standard_row_matches_closed_form():
    theta, alpha, a, d = 0.3, -1.1, 2.5, -0.7
    c, s, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    expected = [
        [c, -s * ca, s * sa, a * c],
        [s, c * ca, -c * sa, a * s],
        [0, sa, ca, d],
        [0, 0, 0, 1],
    ]
    np.testing.assert_allclose(dh_transform(theta, alpha, a, d, "standard"), expected, atol=1e-15)


def test_modified_row_matches_chain_md_8_1():
    theta, alpha, a, d = 0.3, -1.1, 2.5, -0.7
    c, s, ca, sa = math.cos(theta), math.sin(theta), math.cos(alpha), math.sin(alpha)
    expected = [
        [c, -s, 0, a],
        [s * ca, c * ca, -sa, -d * sa],
        [s * sa, c * sa, ca, d * ca],
        [0, 0, 0, 1],
    ]
    np.testing.assert_allclose(dh_transform(theta, alpha, a, d, "modified"), expected, atol=1e-15)


TEMPLATES = {
    # chain.md 11.8: rows in MATLAB order, then origins, z and x of frames 1..n
    "spherical": (
        [(0, 0, 0.1, 0), (0, PI / 2, 0, PI / 2), (0, PI / 2, 0, PI / 2), (0, PI / 2, 0.1, 0)],
        [(0, 0, 0.1), (0, 0, 0.1), (0, 0, 0.1), (0, 0, 0.2)],
        [(0, 0, 1), (0, -1, 0), (1, 0, 0), (0, 0, 1)],
        [(1, 0, 0), (0, 0, 1), (0, -1, 0), (0, -1, 0)],
    ),
    "universal": (
        [(0, PI / 2, 0, PI / 2), (0, PI / 2, 0, 0), (0.2, 0, 0, 0)],
        [(0, 0, 0), (0, 0, 0), (0, 0, 0.2)],
        [(0, -1, 0), (1, 0, 0), (1, 0, 0)],
        [(0, 0, 1)] * 3,
    ),
    "planar": (
        [(0.15, 0, 0, 0)] * 4,
        [(0.15, 0, 0), (0.30, 0, 0), (0.45, 0, 0), (0.60, 0, 0)],
        [(0, 0, 1)] * 4,
        [(1, 0, 0)] * 4,
    ),
}


@pytest.mark.parametrize("name", sorted(TEMPLATES))
def test_matlab_template_frames(name):
    rows, origins, zs, xs = TEMPLATES[name]
    frames = dh_joint_frames(matlab_rows(rows), "modified")
    assert len(frames) == len(rows)
    for G, o, z, x in zip(frames, origins, zs, xs, strict=True):
        np.testing.assert_allclose(G[:3, 3], o, atol=1e-12)
        np.testing.assert_allclose(G[:3, 2], z, atol=1e-12)
        np.testing.assert_allclose(G[:3, 0], x, atol=1e-12)


def test_standard_joint_frames_are_frames_0_to_n_minus_1():
    frames = dh_frames(PUMA)
    assert len(frames) == 7
    np.testing.assert_array_equal(frames[0], np.eye(4))
    joint_frames = dh_joint_frames(PUMA)
    assert len(joint_frames) == 6
    for a, b in zip(joint_frames, frames[:-1], strict=True):
        np.testing.assert_array_equal(a, b)
    np.testing.assert_array_equal(dh_tool_frame(PUMA), frames[-1])


def test_modified_tool_frame_points_along_last_x():
    rows = matlab_rows(TEMPLATES["planar"][0])
    G = dh_frames(rows, "modified")[-1]
    T = dh_tool_frame(rows, "modified")
    np.testing.assert_allclose(T[:3, 2], G[:3, 0], atol=1e-15)
    np.testing.assert_allclose(T[:3, 3], G[:3, 3], atol=1e-15)
    np.testing.assert_allclose(T[:3, :3].T @ T[:3, :3], np.eye(3), atol=1e-15)
    assert np.linalg.det(T[:3, :3]) == pytest.approx(1.0)


# --- the PUMA 560 ----------------------------------------------------------------------------
@pytest.mark.parametrize("placement", ["compact", "safe"])
def test_puma_joints_lie_on_the_dh_axes(placement):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no placement may fail
        chain = KinematicChain.from_dh(PUMA, 6, 100, placement=placement)
    assert isinstance(chain.Joints[0], RevoluteJoint)
    assert isinstance(chain.Joints[-1], EndTip)
    assert all(isinstance(j, RevoluteJoint) for j in structural(chain))
    if placement == "compact":
        assert len(chain.Joints) == 7  # no waypoints
    assert_on_axes(chain, dh_joint_frames(PUMA), scale=1000)
    # the end tip lies on the tool frame's z axis
    tool = dh_tool_frame(PUMA)
    tip = chain.Joints[-1].pose_matrix
    np.testing.assert_allclose(tip[:3, 2], tool[:3, 2], atol=1e-12)
    assert np.linalg.norm(np.cross(tip[:3, 3] - tool[:3, 3], tool[:3, 2])) <= 1e-9 * 1000
    # every link starts at its parent's distal Dubins frame and ends at its joint's proximal one
    for parent, joint, link in zip(
        chain.Joints[:-1], chain.Joints[1:], chain.Links[1:], strict=True
    ):
        np.testing.assert_allclose(link.start_frame, parent.distal_dubins_frame(), atol=1e-9)
        np.testing.assert_allclose(link.end_frame, joint.proximal_dubins_frame(), atol=1e-9)


def test_puma_compact_keeps_the_dh_roll():
    chain = KinematicChain.from_dh(PUMA, 6, 100)
    for joint, G in zip(structural(chain), dh_joint_frames(PUMA), strict=True):
        np.testing.assert_allclose(joint.pose_matrix[:3, :3], G[:3, :3], atol=1e-12)


def test_puma_compact_clearance():
    """Each compact-placed joint is at least 4r beyond the ball of the joints before it."""
    chain = KinematicChain.from_dh(PUMA, 6, 100)
    # rebuild step by step to know the ball before each append
    frames = dh_joint_frames(PUMA)
    partial = KinematicChain(RevoluteJoint(6, 100, PI, frames[0]))
    for k, G in enumerate(frames[1:], start=1):
        ball = partial.boundingBall
        joint = chain.Joints[k]
        gap = np.linalg.norm(joint.pose_matrix[:3, 3] - ball.c)
        assert gap >= ball.r + 4 * 100 + joint.boundingBall().r - 1e-6
        assert partial.append(RevoluteJoint(6, 100, PI, G), relative=False, safe=False,
                              fixedOrientation=True) == k  # fmt: skip
        np.testing.assert_allclose(partial.Joints[k].pose_matrix, joint.pose_matrix, atol=1e-12)


def test_puma_can_be_shortened_by_axis_translations():
    """Figure 3(d): compact placement, then joints slid along their axes."""
    chain = KinematicChain.from_dh(PUMA, 6, 100)
    before = chain.totalPathLength()
    edits = shorten_by_axis_translations(chain)
    assert edits
    assert chain.totalPathLength() < 0.6 * before  # measured: 7757 -> 3445 mm
    assert_on_axes(chain, dh_joint_frames(PUMA), scale=1000)
    # the returned edits replay to the same chain
    replay = KinematicChain.from_dh(PUMA, 6, 100)
    for j, distance in edits:
        assert replay.translateJointAlongAxisOfMotion(j, distance, propagate=False)
    for a, b in zip(chain.Joints, replay.Joints, strict=True):
        np.testing.assert_allclose(a.pose_matrix, b.pose_matrix, atol=1e-9)


def test_shorten_rejects_bad_input():
    with pytest.raises(InvalidTypeError, match="chain"):
        shorten_by_axis_translations([1, 2])
    chain = KinematicChain.from_dh(PUMA[:2], 6, 100)
    with pytest.raises(InvalidParameterError, match="step"):
        shorten_by_axis_translations(chain, step=-1)
    with pytest.raises(InvalidParameterError, match="rounds"):
        shorten_by_axis_translations(chain, rounds=-1)


# --- other tables ----------------------------------------------------------------------------
@pytest.mark.parametrize("name", sorted(TEMPLATES))
@pytest.mark.parametrize("placement", ["compact", "safe"])
def test_matlab_templates_build(name, placement):
    rows = matlab_rows(TEMPLATES[name][0])
    r = 0.02
    try:
        chain = KinematicChain.from_dh(rows, 4, r, "modified", placement=placement)
    except NoPathError:
        assert placement == "compact"
        return
    assert_on_axes(chain, dh_joint_frames(rows, "modified"), scale=1)


def test_joint_types():
    rows = [(0, PI / 2, 2, 0), (PI / 2, -PI / 2, 0, 3), (0, 0, 1, 0)]
    chain = KinematicChain.from_dh(rows, 4, 0.5, jointTypes="RPR", placement="safe")
    kinds = [type(j) for j in structural(chain)]
    assert kinds == [RevoluteJoint, PrismaticJoint, RevoluteJoint]
    same = KinematicChain.from_dh(
        rows, 4, 0.5, jointTypes=["revolute", "Prismatic", "r"], placement="safe"
    )
    for a, b in zip(chain.Joints, same.Joints, strict=True):
        np.testing.assert_array_equal(a.pose_matrix, b.pose_matrix)


def test_joint_parameters_and_no_end_tip():
    rows = [(0, PI / 2, 2, 0), (PI / 2, -PI / 2, 0, 3)]
    chain = KinematicChain.from_dh(
        rows, 6, 0.5, jointTypes="RP", placement="safe", totalBendingAngle=PI / 2,
        neutralLength=2.0, numLayers=4, coneAngle=PI / 3, endTip=False,
    )  # fmt: skip
    revolute, prismatic = structural(chain)
    assert revolute.totalBendingAngle == pytest.approx(PI / 2)
    assert prismatic.numLayers == 4
    assert prismatic.coneAngle == pytest.approx(PI / 3)
    assert not isinstance(chain.Joints[-1], EndTip)


tables = st.lists(
    st.tuples(st.floats(-PI, PI), st.floats(-PI, PI), st.floats(-5, 5), st.floats(-5, 5)),
    min_size=1,
    max_size=5,
)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(
    rows=tables,
    convention=st.sampled_from(["standard", "modified"]),
    types=st.text(alphabet="RP", min_size=5, max_size=5),
)
def test_random_tables_safe_always_builds_on_the_axes(rows, convention, types):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        chain = KinematicChain.from_dh(
            rows, 4, 0.3, convention, types[: len(rows)], placement="safe"
        )
    assert_on_axes(chain, dh_joint_frames(rows, convention), scale=10)


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(rows=tables, convention=st.sampled_from(["standard", "modified"]))
def test_random_tables_compact_on_the_axes_or_clear_error(rows, convention):
    try:
        chain = KinematicChain.from_dh(rows, 6, 0.3, convention)
    except NoPathError as error:
        assert "try placement='safe'" in str(error)
        return
    assert_on_axes(chain, dh_joint_frames(rows, convention), scale=10)
    for joint, G in zip(structural(chain), dh_joint_frames(rows, convention), strict=True):
        np.testing.assert_allclose(joint.pose_matrix[:3, :3], G[:3, :3], atol=1e-12)


# --- bad input -------------------------------------------------------------------------------
@pytest.mark.parametrize(
    ("kwargs", "error", "words"),
    [
        ({"table": []}, InvalidParameterError, "at least one row"),
        ({"table": [(0, 0, 1)]}, InvalidParameterError, "4 entries"),
        ({"table": [(0, 0, "a", 1)]}, InvalidTypeError, "row 0"),
        ({"table": [(0, 0, math.nan, 1)]}, InvalidParameterError, "finite"),
        ({"table": "RRR"}, InvalidTypeError, "sequence of rows"),
        ({"convention": "craig"}, InvalidParameterError, "'standard', 'modified'"),
        ({"placement": "tight"}, InvalidParameterError, "'compact', 'safe'"),
        ({"jointTypes": "RX"}, InvalidParameterError, "jointTypes[1]"),
        ({"jointTypes": "R"}, InvalidParameterError, "one type per table row (2)"),
        ({"jointTypes": 3}, InvalidTypeError, "jointTypes"),
        ({"numSides": 2}, InvalidParameterError, "numSides"),
        ({"r": -1}, InvalidParameterError, "r"),
        ({"endTip": "yes"}, InvalidTypeError, "endTip"),
        ({"totalBendingAngle": 7}, InvalidParameterError, "totalBendingAngle"),
    ],
)
def test_bad_input(kwargs, error, words):
    arguments = {"table": [(0, PI / 2, 2, 0), (0, 0, 1, 0)], "numSides": 4, "r": 0.5}
    arguments.update(kwargs)
    with pytest.raises(error) as info:
        KinematicChain.from_dh(**arguments)
    assert words in str(info.value)


# bools and strings are not numbers (as for dh_transform and design files): each names its
# entry (row and column) and the value; numbers of every numeric type give the same chain
@pytest.mark.parametrize(
    ("table", "entry", "value"),
    [
        ([(True, 0, 0, 0)], "table row 0 theta (table[0][0])", "True"),
        ([(0, 0, 5, 0), (0, False, 1, 0)], "table row 1 alpha (table[1][1])", "False"),
        ([(np.bool_(True), 0, 5, 0)], "table row 0 theta (table[0][0])", "True"),
        ([("0", "0", "1", "0")], "table row 0 theta (table[0][0])", "'0'"),
        ([(0, 0, b"1", 0)], "table row 0 a (table[0][2])", "b'1'"),
        ([(0, 0, 1, None)], "table row 0 d (table[0][3])", "None"),
        ([(0, 0, 1 + 0j, 0)], "table row 0 a (table[0][2])", "(1+0j)"),
        (np.array([[True, False, True, False]]), "table row 0 theta (table[0][0])", "True"),
        (np.array([["0", "0", "1", "0"]]), "table row 0 theta (table[0][0])", "'0'"),
        (np.array([[0, 0, 1, 0]], dtype=complex), "table row 0 theta (table[0][0])", "0j"),
        (["0010"], "table row 0", "'0010'"),  # its characters are not 4 numbers either
    ],
    ids=(
        "bool bool-row-1 numpy-bool strings bytes None complex bool-array string-array "
        "complex-array string-row"
    ).split(),
)
def test_table_entries_must_be_real_numbers(table, entry, value):
    with warnings.catch_warnings():
        warnings.simplefilter("error")  # no ComplexWarning from numpy either
        with pytest.raises(InvalidTypeError) as info:
            KinematicChain.from_dh(table, 4, 1)
        message = str(info.value)
        assert entry in message and value in message, message
        assert "must be" in message, message
        with pytest.raises(InvalidTypeError):
            dh_frames(table)


def test_table_of_any_numeric_type_gives_the_same_chain(snapshot):
    from fractions import Fraction

    rows = [(0, 1, 2, 0), (1, 0, 3, -2), (0, -1, 0, 4)]
    expected = snapshot(KinematicChain.from_dh([tuple(map(float, r)) for r in rows], 4, 1))
    tables = [
        rows,
        [list(r) for r in rows],
        tuple(rows),
        np.array(rows),
        np.array(rows, dtype=np.int8),
        np.array(rows, dtype=np.float32),
        np.array(rows, dtype=object),
        list(np.array(rows, dtype=float)),
        [tuple(np.int64(v) for v in r) for r in rows],
        [tuple(np.float16(v) for v in r) for r in rows],
        [tuple(Fraction(v) for v in r) for r in rows],
    ]
    for table in tables:
        assert snapshot(KinematicChain.from_dh(table, 4, 1)) == expected, table


# --- compact placement's other side (used by the PUMA's first joint) ----------------------
def test_compact_tries_the_other_side_of_the_ball():
    """The tie case sends the joint to +z, where no link reaches it; the other side works."""
    frames = dh_frames(PUMA)
    chain = KinematicChain(RevoluteJoint(6, 100, PI, frames[0]))
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        index = chain.append(RevoluteJoint(6, 100, PI, frames[1]), relative=False, safe=False)
    assert index == 1
    p = chain.Joints[1].pose_matrix[:3, 3]
    z = frames[1][:3, 2]  # (-1, 0, 0): the rule's +z side is x < 0; the joint went to x > 0
    assert p @ z < 0
    ball = chain.Joints[0].boundingBall()
    assert np.linalg.norm(p) == pytest.approx(ball.r + 400 + chain.Joints[1].boundingBall().r)
