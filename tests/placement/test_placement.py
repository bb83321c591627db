"""The radial safe placement on its own: every link it asks for exists (docs/placement.md)."""

import warnings

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from kinegami import (
    KinematicChain,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)
from kinegami.chain.bodies import link_polyline
from kinegami.chain.placement import radial_safe_placement
from kinegami.geometry.balls import Ball


def _pose(rotvec, translation):
    T = np.eye(4)
    T[:3, :3] = Rotation.from_rotvec(rotvec).as_matrix()
    T[:3, 3] = translation
    return T


vectors = st.lists(st.floats(-1.0, 1.0), min_size=3, max_size=3).map(np.array)


@settings(deadline=None, max_examples=150)
@given(
    r=st.sampled_from([0.05, 1.0, 20.0]),
    numSides=st.sampled_from([4, 6, 8]),
    kind=st.integers(0, 2),
    path_index=st.integers(0, 2),
    rotvec=vectors.map(lambda v: 3.0 * v),
    offset=vectors.map(lambda v: 6.0 * v),
    parent_rotvec=vectors.map(lambda v: 3.0 * v),
    parent_offset=vectors,
    ball_radius=st.floats(1.5, 40.0),
)
def test_radial_placement_links_always_exist(
    r, numSides, kind, path_index, rotvec, offset, parent_rotvec, parent_offset, ball_radius
):
    # a parent inside a ball of radius R, anywhere within it, in any orientation
    R = ball_radius * r
    parent_T = _pose(parent_rotvec, parent_offset * (R - 1.5 * r) / np.sqrt(3.0))
    parent = RevoluteJoint(numSides, r, np.pi, parent_T)
    T = parent_T @ _pose(rotvec, offset * r)
    joint = [
        RevoluteJoint(numSides, r, 2.0, T),
        PrismaticJoint(numSides, r, 3 * r, 3, np.pi / 3, T),
        Waypoint(numSides, r, T, pathIndex=path_index),
    ][kind]
    chain = KinematicChain(parent)
    ball = Ball(np.zeros(3), R)
    chain._ball = ball  # the placement only reads the ball
    new = radial_safe_placement(parent.distal_frame(), parent.pathIndex(), joint, ball)
    joints, links, _, _ = chain._extended(new, len(chain.Joints) - 1)  # NoPathError: no link
    placed = new[-1]
    # the joint keeps its axis line and lies at least 4r + rho beyond the ball
    z_old, z_new = T[:3, 2], placed.pose_matrix[:3, 2]
    assert np.linalg.norm(np.cross(z_old, z_new)) < 1e-12
    assert np.linalg.norm(np.cross(placed.pose_matrix[:3, 3] - T[:3, 3], z_old)) < 1e-9 * r
    assert (
        np.linalg.norm(placed.pose_matrix[:3, 3]) >= R + 4 * r + placed.bounding_radius() - 1e-9 * r
    )
    for link in links[1:]:
        assert link.path.theta1 < np.pi and link.path.theta2 < np.pi


def test_safe_appends_on_long_random_chain_never_fail():
    rng = np.random.default_rng(7)
    r = 1.0
    chain = KinematicChain(StartTip(4, r, np.eye(4), r))
    for i in range(48):
        T = _pose(
            Rotation.random(random_state=int(rng.integers(1 << 31))).as_rotvec(),
            rng.uniform(-4 * r, 4 * r, 3),
        )
        joint = (
            RevoluteJoint(4, r, np.pi, T)
            if i % 2 == 0
            else PrismaticJoint(4, r, 3 * r, 3, np.pi / 4, T)
        )
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert chain.append(joint) is not None
    assert chain.boundingBall.r <= 10 * r * 48
    assert chain.totalPathLength() <= 60 * r * 48


@settings(deadline=None, max_examples=100)
@given(
    r=st.sampled_from([0.05, 1.0, 20.0]),
    kind=st.integers(0, 2),
    rotvec=vectors.map(lambda v: 3.0 * v),
    offset=vectors.map(lambda v: 6.0 * v),
    parent_rotvec=vectors.map(lambda v: 3.0 * v),
    parent_offset=vectors,
    ball_radius=st.floats(1.5, 40.0),
    past=st.lists(vectors, min_size=1, max_size=6),
)
def test_radial_placement_holding_past_points(
    r, kind, rotvec, offset, parent_rotvec, parent_offset, ball_radius, past
):
    # hold_past: one more waypoint W_h straight ahead of W_a; from it on, every point of the
    # new tube lies at least 2r past every given point along the outward normal m
    R = ball_radius * r
    parent_T = _pose(parent_rotvec, parent_offset * (R - 1.5 * r) / np.sqrt(3.0))
    parent = RevoluteJoint(4, r, np.pi, parent_T)
    T = parent_T @ _pose(rotvec, offset * r)
    joint = [
        RevoluteJoint(4, r, 2.0, T),
        PrismaticJoint(4, r, 3 * r, 3, np.pi / 3, T),
        Waypoint(4, r, T, pathIndex=2),
    ][kind]
    points = np.array(past) * 1.5 * R  # anywhere in and somewhat beyond the ball
    chain = KinematicChain(parent)
    ball = Ball(np.zeros(3), R)
    chain._ball = ball
    plain = radial_safe_placement(parent.distal_frame(), parent.pathIndex(), joint, ball)
    new = radial_safe_placement(
        parent.distal_frame(), parent.pathIndex(), joint, ball, hold_past=points
    )
    joints, links, _, _ = chain._extended(new, len(chain.Joints) - 1)  # NoPathError: no link
    for link in links[1:]:
        assert link.path.theta1 < np.pi and link.path.theta2 < np.pi
    placed = new[-1]
    assert np.linalg.norm(np.cross(placed.pose_matrix[:3, 3] - T[:3, 3], T[:3, 2])) < 1e-9 * r
    wa = new[0].pose_matrix[:3, 3]
    m = new[0].path_direction()  # W_a faces m
    if len(new) == len(plain):  # W_a was already 2r past every point: nothing added
        # (to rounding: the placement measured from W_a before it became a pose)
        assert float(np.max((points - wa) @ m)) + 2.0 * r <= 1e-9 * R
        return
    assert len(new) == len(plain) + 1
    wh = new[1].pose_matrix[:3, 3]
    assert np.linalg.norm(np.cross(wh - wa, m)) < 1e-9 * R  # straight ahead of W_a
    limit = float(np.max(points @ m)) + 2.0 * r - 1e-9 * R
    assert float(wh @ m) >= limit
    for link in links[3:]:  # W_h -> W_b and W_b -> the joint never come back against m
        assert float(np.min(link_polyline(link) @ m)) >= limit
    assert float(placed.proximal_frame()[:3, 3] @ m) >= limit
