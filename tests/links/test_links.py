"""LinkCSC: CSC paths turned into elbows, twist and tube (spec/chain.md 2.4-2.6, 3.2)."""

from __future__ import annotations

import math

import numpy as np
import pytest
import reference_values as ref
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from kinegami import SE3, LinkCSC
from kinegami.geometry.balls import Ball, merge_balls
from kinegami.geometry.csc import solve_csc
from kinegami.geometry.frames import rotation_matrix, signed_angle


def frame(origin, x, y):
    """A 4x4 frame with the given origin and first two axes (z = x cross y)."""
    T = np.eye(4)
    T[:3, 0], T[:3, 1] = x, y
    T[:3, 2] = np.cross(x, y)
    T[:3, 3] = origin
    return T


def link_of(case, r=1.0, max_angle=math.pi / 2):
    """The link of a unit case of 11.7, with the start frame's y = world y / z."""
    d1, d2 = np.array(case["d1"], float), np.array(case["d2"], float)
    y1 = np.cross((0, 0, 1), d1) if abs(d1[2]) < 0.9 else np.array([0.0, 1.0, 0.0])
    y2 = np.cross((0, 0, 1), d2) if abs(d2[2]) < 0.9 else np.array([1.0, 0.0, 0.0])
    S = frame(case["p1"], d1, y1 / np.linalg.norm(y1))
    E = frame(case["p2"], d2, y2 / np.linalg.norm(y2))
    return LinkCSC(r, S, E, max_angle), S, E


def elbow_step(r, alpha, phi):
    """Trans(delta x) Rot((0, cos phi, sin phi), alpha) Trans(delta x), chain.md 2.4."""
    delta = r * math.tan(alpha / 2)
    shift = np.eye(4)
    shift[0, 3] = delta
    turn = np.eye(4)
    turn[:3, :3] = rotation_matrix((0.0, math.cos(phi), math.sin(phi)), alpha)
    return shift @ turn @ shift


def test_link_path_is_the_csc_solution():
    case = ref.CSC_3D
    link, S, E = link_of(case)
    path = solve_csc(case["p1"], case["d1"], case["p2"], case["d2"], 1.0)
    assert (link.path.theta1, link.path.tMag, link.path.theta2) == (
        path.theta1,
        path.tMag,
        path.theta2,
    )
    assert link.length == link.path.length
    np.testing.assert_array_equal(link.start_frame, S)
    np.testing.assert_array_equal(link.end_frame, E)
    np.testing.assert_array_equal(link.StartDubinsPose.A, S)
    np.testing.assert_array_equal(link.EndDubinsPose.A, E)


def test_link_accepts_se3_and_arrays():
    case = ref.CSC_3D
    link, S, E = link_of(case)
    other = LinkCSC(1.0, SE3(S, check=False), SE3(E, check=False))
    assert (other.path.theta1, other.path.tMag, other.path.theta2) == (
        link.path.theta1,
        link.path.tMag,
        link.path.theta2,
    )


@pytest.mark.parametrize("max_angle", [math.pi, math.pi / 2, math.pi / 4, 0.3, 0.05])
def test_arcs_are_split_into_equal_elbows(max_angle, link_checker):
    link, _, _ = link_of(ref.CSC_3D, max_angle=max_angle)
    for arc, theta in ((link.elbows1, link.path.theta1), (link.elbows2, link.path.theta2)):
        assert arc.count == math.ceil(theta / max_angle)
        assert arc.angle == theta
        assert arc.elbowAngle == pytest.approx(theta / arc.count, abs=1e-15)
    link_checker(link)


def test_elbow_frames_follow_the_published_composition():
    link, _, _ = link_of(ref.CSC_3D, max_angle=math.pi / 4)
    for arc in (link.elbows1, link.elbows2):
        step = elbow_step(link.r, arc.elbowAngle, arc.rotationalAxisAngle)
        F = arc.frames[0]
        for k in range(arc.count):
            F = F @ step
            np.testing.assert_allclose(arc.frames[k + 1], F, rtol=0, atol=1e-12)


def test_rotation_axis_angles():
    link, S, E = link_of(ref.CSC_3D)
    p = link.path
    assert link.elbows1.rotationalAxisAngle == pytest.approx(
        signed_angle(S[:3, 1], p.k1, S[:3, 0]), abs=1e-12
    )
    # measured in the arc's start frame or, equivalently, in E (the roll is transported)
    F2 = link.arc2_start_frame
    phi2 = link.elbows2.rotationalAxisAngle
    assert phi2 == pytest.approx(signed_angle(F2[:3, 1], p.k2, F2[:3, 0]), abs=1e-12)
    assert phi2 == pytest.approx(signed_angle(E[:3, 1], p.k2, E[:3, 0]), abs=1e-12)
    # in the start frame's coordinates the axis is (0, cos phi, sin phi)
    for phi, F, k in ((link.elbows1.rotationalAxisAngle, S, p.k1), (phi2, F2, p.k2)):
        np.testing.assert_allclose(
            F[:3, :3].T @ k, (0, math.cos(phi), math.sin(phi)), rtol=0, atol=1e-12
        )


def test_arc_frames_at_the_ends_of_the_straight_part():
    link, _, E = link_of(ref.CSC_3D)
    p = link.path
    np.testing.assert_allclose(link.arc1_end_frame[:3, 3], p.q1, rtol=0, atol=1e-12)
    np.testing.assert_allclose(link.arc1_end_frame[:3, 0], p.tUnit, rtol=0, atol=1e-12)
    np.testing.assert_allclose(link.arc2_start_frame[:3, 3], p.q2, rtol=0, atol=1e-12)
    np.testing.assert_allclose(link.arc2_start_frame[:3, 0], p.tUnit, rtol=0, atol=1e-12)
    np.testing.assert_allclose(
        rotation_matrix(p.k2, p.theta2) @ link.arc2_start_frame[:3, :3],
        E[:3, :3],
        rtol=0,
        atol=1e-12,
    )


def test_single_elbow_ball_is_centred_on_the_vertex():
    link, _, _ = link_of(ref.CSC_PLANAR_S)
    for arc, ball in ((link.elbows1, link.arc1Ball), (link.elbows2, link.arc2Ball)):
        assert arc.count == 1
        delta = math.tan(arc.angle / 2)
        vertex = arc.frames[0][:3, 3] + delta * arc.frames[0][:3, 0]
        np.testing.assert_allclose(ball.c, vertex, rtol=0, atol=1e-12)
        assert ball.r == pytest.approx(math.hypot(delta, 1.0), abs=1e-12)


def test_multi_elbow_ball_is_the_fold_of_the_elbow_balls():
    link, _, _ = link_of(ref.CSC_3D, max_angle=0.3)
    arc = link.elbows1
    alpha = arc.elbowAngle
    radius = math.hypot(math.tan(alpha / 2), 1.0)
    vertices = [F[:3, 3] + math.tan(alpha / 2) * F[:3, 0] for F in arc.frames[:-1]]
    expected = Ball(vertices[0], radius)
    for v in vertices[1:]:
        expected = merge_balls(expected, Ball(v, radius))
    np.testing.assert_allclose(link.arc1Ball.c, expected.c, rtol=0, atol=1e-12)
    assert link.arc1Ball.r == pytest.approx(expected.r, abs=1e-12)


def test_straight_link_has_no_elbows_and_endpoint_balls():
    S = np.eye(4)
    E = SE3.Trans(5, 0, 0).A
    link = LinkCSC(0.5, S, E)
    assert (link.path.theta1, link.path.tMag, link.path.theta2) == (0.0, 5.0, 0.0)
    assert (link.elbows1.count, link.elbows2.count) == (0, 0)
    assert link.arc1Ball.r == 0.5 and link.arc2Ball.r == 0.5
    np.testing.assert_array_equal(link.arc1Ball.c, S[:3, 3])
    np.testing.assert_array_equal(link.arc2Ball.c, E[:3, 3])
    assert link.twistAngle == 0.0 and not link.hasTwist


def test_empty_link():
    F = SE3.Trans(1, 2, 3).A @ SE3.Rz(0.3).A
    link = LinkCSC(2.0, F, F)
    assert (link.path.theta1, link.path.tMag, link.path.theta2, link.length) == (0, 0, 0, 0)
    assert link.twistAngle == 0.0


@pytest.mark.parametrize(
    "roll, has_twist", [(0.7, True), (-2.0, True), (0.005, False), (math.pi / 2, True)]
)
def test_twist_on_a_straight_link(roll, has_twist):
    E = SE3.Trans(4, 0, 0) * SE3.Rx(roll)
    link = LinkCSC(1.0, SE3(), E)
    assert link.twistAngle == pytest.approx(roll, abs=1e-12)
    assert link.hasTwist is has_twist


def test_transformed_link_equals_the_link_of_transformed_frames(link_checker):
    link, S, E = link_of(ref.CSC_3D, max_angle=0.5)
    _ = (link.elbows1, link.elbows2, link.arc1Ball, link.twistAngle)  # fill some caches
    T = (SE3.Trans(3, -2, 7) * SE3.RPY(0.3, -1.1, 2.0)).A
    moved = link.transformed(T)
    solved = LinkCSC(1.0, T @ S, T @ E, 0.5)
    assert moved.path.theta1 == link.path.theta1 and moved.path.tMag == link.path.tMag
    for a, b in (
        (moved.path.q1, solved.path.q1),
        (moved.path.tUnit, solved.path.tUnit),
        (moved.elbows1.frames, solved.elbows1.frames),
        (moved.elbows2.frames, solved.elbows2.frames),
        (moved.arc1Ball.c, solved.arc1Ball.c),
        (moved.arc2Ball.c, solved.arc2Ball.c),
    ):
        np.testing.assert_allclose(a, b, rtol=0, atol=1e-9)
    assert moved.twistAngle == pytest.approx(solved.twistAngle, abs=1e-9)
    link_checker(moved)


# --- properties (hypothesis) -----------------------------------------------------------------

quaternions = st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda q: math.hypot(*q) > 0.1)
offsets = st.tuples(*[st.floats(-12, 12)] * 3)


def random_frame(quaternion, origin):
    T = np.eye(4)
    T[:3, :3] = Rotation.from_quat(quaternion).as_matrix()
    T[:3, 3] = origin
    return T


def tube_points_of_arc(link, which, samples=9, around=12):
    """Points of the circular tube (radius r) swept along arc 1 or 2 of the centreline."""
    p = link.path
    if which == 1:
        theta, k, start, tangent, centre = p.theta1, p.k1, p.p1, p.d1, p.c1
    else:
        theta, k, start, tangent, centre = p.theta2, p.k2, p.q2, p.tUnit, p.c2
    points = []
    for t in np.linspace(0, theta, samples):
        R = rotation_matrix(k, t)
        x = centre + R @ (start - centre)
        normal = np.cross(R @ tangent, k)
        for a in np.linspace(0, 2 * math.pi, around, endpoint=False):
            points.append(x + link.r * (math.cos(a) * k + math.sin(a) * normal))
    return points


@settings(deadline=None, max_examples=120)
@given(
    r=st.floats(0.02, 50),
    max_angle=st.floats(0.05, math.pi),
    q1=quaternions,
    q2=quaternions,
    origin=offsets,
    offset=offsets,
)
def test_random_links(link_checker, r, max_angle, q1, q2, origin, offset):
    S = random_frame(q1, np.array(origin) * r)
    E = random_frame(q2, S[:3, 3] + np.array(offset) * r)
    try:
        link = LinkCSC(r, S, E, max_angle)
    except ValueError:
        assert solve_csc(S[:3, 3], S[:3, 0], E[:3, 3], E[:3, 0], r) is None
        return
    link_checker(link)
    # the arc balls contain the tube around their arcs (tight at the elbow ends and mid-plane)
    for which, ball, arc in ((1, link.arc1Ball, link.elbows1), (2, link.arc2Ball, link.elbows2)):
        if arc.count == 0:
            continue
        for x in tube_points_of_arc(link, which):
            assert np.linalg.norm(x - ball.c) <= ball.r + 1e-9 * r


# --- a link along a chosen path (LinkCSC.from_path) ---------------------------------------------


def test_link_from_a_chosen_path_is_the_solved_link():
    from kinegami.geometry.csc import solve_csc_all

    case = ref.CSC_3D
    link, S, E = link_of(case)
    (path,) = solve_csc_all(case["p1"], case["d1"], case["p2"], case["d2"], 1.0)
    chosen = LinkCSC.from_path(1.0, S, E, path)
    assert chosen.path is path
    np.testing.assert_allclose(
        [chosen.path.theta1, chosen.path.tMag, chosen.path.theta2, chosen.twistAngle],
        [link.path.theta1, link.path.tMag, link.path.theta2, link.twistAngle],
        rtol=0,
        atol=1e-12,
    )
    assert (chosen.elbows1.count, chosen.elbows2.count) == (link.elbows1.count, link.elbows2.count)
    np.testing.assert_allclose(chosen.elbows2.frames, link.elbows2.frames, rtol=0, atol=1e-12)
    kinds = [type(m).__name__ for m in link.pattern_modules(4, 0.2)]
    assert [type(m).__name__ for m in chosen.pattern_modules(4, 0.2)] == kinds


@pytest.mark.parametrize("what", ["start point", "end tangent", "radius"])
def test_link_from_path_rejects_a_path_that_misses_its_frames(what):
    from kinegami import InvalidParameterError

    case = ref.CSC_3D
    _, S, E = link_of(case)
    path = solve_csc(case["p1"], case["d1"], case["p2"], case["d2"], 1.0)
    r = 1.0
    if what == "start point":
        S = S.copy()
        S[0, 3] += 1e-6
    elif what == "end tangent":
        E = E @ np.block([[rotation_matrix((0, 0, 1), 1e-6), np.zeros((3, 1))], [0, 0, 0, 1]])
    else:
        r = 1.1
    with pytest.raises(InvalidParameterError, match="path"):
        LinkCSC.from_path(r, S, E, path)
