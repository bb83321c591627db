"""The chain's crease pattern (patterns.md 4.2-4.3): composition of joint and link modules."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
import reference_values as ref
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from kinegami import (
    SE3,
    EndTip,
    InvalidParameterError,
    KinematicChain,
    LinkCSC,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)
from kinegami.chain.links import PATTERN_MIN_ANGLE


def _modules(pattern, kind):
    return [m for m in pattern.modules if m.kind == kind]


def test_example_1_pattern_height_and_marker(example_1b):
    pattern = example_1b.creasePattern()
    assert pattern.height == pytest.approx(ref.EXAMPLE_1_PATTERN_HEIGHT, abs=ref.ATOL)
    assert pattern.distalMarker[0] == pytest.approx(
        ref.EXAMPLE_1_PATTERN_DISTAL_MARKER_X, abs=ref.ATOL
    )
    assert pattern.width == pytest.approx(4 * 2 * math.sin(math.pi / 4))
    assert pattern.validate().ok


def test_chain_pattern_is_the_joints_and_links_in_order(example_1b):
    chain = example_1b
    pattern = chain.creasePattern()
    expected_height = chain.Joints[0].pattern.height
    for link, joint in zip(chain.Links[1:], chain.Joints[1:], strict=True):
        expected_height += link.creasePattern(chain.numSides).height + joint.pattern.height
    assert pattern.height == pytest.approx(expected_height, abs=1e-12)
    kinds = [
        m.kind
        for m in pattern.modules
        if m.kind in ("start_tip", "end_tip", "prismatic", "revolute")
    ]
    assert kinds == ["start_tip", "prismatic", "revolute", "end_tip"]


def test_link_pattern_has_one_elbow_module_per_elbow(example_1b):
    for link in example_1b.Links[1:]:
        pattern = link.creasePattern(4)
        expected = sum(
            arc.count for arc in (link.elbows1, link.elbows2) if arc.angle > PATTERN_MIN_ANGLE
        )
        assert len(_modules(pattern, "elbow")) == expected
        assert len(_modules(pattern, "twist")) == (1 if link.hasTwist else 0)
        for record in _modules(pattern, "elbow"):
            angles = {round(link.elbows1.elbowAngle, 12), round(link.elbows2.elbowAngle, 12)}
            assert round(record.params["bendingAngle"], 12) in angles


def test_link_pattern_tube_and_twist_share_the_straight_length():
    link = LinkCSC(1, SE3(), SE3.Trans(0, 0, 12) @ SE3.Ry(-np.pi / 2) @ SE3.Rx(1.0))
    assert link.hasTwist
    pattern = link.creasePattern(6, twistPortion=0.25)
    (twist,) = _modules(pattern, "twist")
    (tube,) = _modules(pattern, "tube")
    assert twist.params["moduleHeight"] == pytest.approx(0.25 * link.path.tMag)
    assert tube.params["height"] == pytest.approx(0.75 * link.path.tMag)


def test_pattern_does_not_depend_on_the_configuration(example_1b):
    chain = example_1b
    before = chain.creasePattern()
    lo, hi = chain.Joints[2].stateRange()
    assert chain.setJointState(2, hi)
    assert chain.setJointState(4, np.pi / 3)
    after = chain.creasePattern()
    np.testing.assert_allclose(after.vertices_coords, before.vertices_coords, atol=1e-9)
    np.testing.assert_array_equal(after.edges_vertices, before.edges_vertices)
    np.testing.assert_array_equal(after.edges_assignment, before.edges_assignment)


@pytest.mark.parametrize(
    "bad",
    [
        {"numSides": 5},
        {"numSides": 2},
        {"twistPortion": 1.5},
        {"twistPortion": -0.1},
        {"twistPortion": float("nan")},
    ],
)
def test_link_pattern_bad_input(bad):
    link = LinkCSC(1, SE3(), SE3.Trans(5, 1, 0))
    kwargs = {"numSides": 4, "twistPortion": 0.2} | bad
    with pytest.raises(InvalidParameterError):
        link.creasePattern(**kwargs)


@settings(deadline=None, max_examples=25)
@given(
    seed=st.integers(0, 2**31 - 1),
    numSides=st.sampled_from([4, 6, 8]),
    r=st.sampled_from([0.5, 1.0, 10.0]),
)
def test_random_safe_chain_patterns_are_valid(seed, numSides, r):
    rng = np.random.default_rng(seed)
    chain = KinematicChain(StartTip(numSides, r, SE3(), r))
    for i in range(5):
        T = np.eye(4)
        T[:3, :3] = Rotation.random(random_state=int(rng.integers(1 << 31))).as_matrix()
        T[:3, 3] = rng.uniform(-4 * r, 4 * r, 3)
        joint = [
            RevoluteJoint(numSides, r, np.pi, T),
            PrismaticJoint(numSides, r, 3 * r, 3, np.pi / 4, T),
            Waypoint(numSides, r, T),
        ][i % 3]
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert chain.append(joint) is not None
    T = np.eye(4)
    T[:3, 3] = (0, 0, 2 * r)
    assert chain.append(EndTip(numSides, r, T, r)) is not None
    pattern = chain.creasePattern()
    assert pattern.width == pytest.approx(numSides * 2 * r * math.sin(math.pi / numSides))
    report = pattern.validate()
    assert report.ok, report.problems
    assert pattern.proximalBase is None and pattern.distalBase is None
