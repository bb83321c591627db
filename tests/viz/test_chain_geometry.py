"""The geometry that show() draws (chain.md section 6), checked without rendering."""

import math

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from kinegami import (
    SE3,
    EndTip,
    ExtendedRevoluteJoint,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)
from kinegami.viz import chain_geometry as geo


def _distance_to_line(points, point, direction):
    d = np.asarray(direction) / np.linalg.norm(direction)
    v = np.asarray(points) - point
    return np.linalg.norm(v - np.outer(v @ d, d), axis=1)


# --- polygons and prisms ---
def test_regular_polygon_phase_and_radius():
    frame = np.eye(4)
    frame[:3, 3] = (1.0, 2.0, 3.0)
    pts = geo.regular_polygon(frame, 2.0, 6)
    rel = pts - frame[:3, 3]
    assert_allclose(rel[:, 0], 0.0, atol=1e-12)
    assert_allclose(np.linalg.norm(rel, axis=1), 2.0)
    angles = np.arctan2(rel[:, 2], rel[:, 1])
    assert_allclose(np.mod(angles, 2 * np.pi), np.pi / 6 + 2 * np.pi * np.arange(6) / 6)


def test_polygon_side():
    assert_allclose(geo.polygon_side(1.0, 4), math.sqrt(2.0))
    assert_allclose(geo.polygon_side(1.0, 6), 1.0)


@settings(max_examples=40, deadline=None)
@given(
    n=st.sampled_from([4, 6, 8, 12]),
    r=st.floats(0.05, 20.0),
    rx=st.floats(-math.pi, math.pi),
    ry=st.floats(-math.pi, math.pi),
    rz=st.floats(-math.pi, math.pi),
    state_fraction=st.floats(0.0, 1.0),
)
def test_prismatic_prism_vertices_are_r_from_the_joint_axis(n, r, rx, ry, rz, state_fraction):
    pose = SE3.Trans(1.0, -2.0, 3.0) * SE3.Rz(rz) * SE3.Ry(ry) * SE3.Rx(rx)
    joint = PrismaticJoint(n, r, 3.0 * r, 3, math.pi / 4, pose)
    low, high = joint.stateRange()
    joint = joint.with_state(low + state_fraction * (high - low))
    T = joint.pose_matrix
    (piece,) = joint.body_pieces()
    kind, *polygons = piece.drawn[0]
    prism = np.stack(polygons)
    assert kind == "prism" and prism.shape == (2, n, 3)
    assert_allclose(piece.points, prism.reshape(-1, 3))
    assert_allclose(_distance_to_line(prism.reshape(-1, 3), T[:3, 3], T[:3, 2]), r, rtol=1e-9)
    # Bottom in the proximal plane, top L + state further along z.
    heights = (prism - joint.proximal_frame()[:3, 3]) @ T[:3, 2]
    assert_allclose(heights[0], 0.0, atol=1e-9 * r)
    assert_allclose(heights[1], joint.neutralLength + joint.state, rtol=1e-9)
    # Polygon phase measured about the joint's own axis, from its x axis.
    rel = prism[0] - joint.proximal_frame()[:3, 3]
    phase = np.mod(np.arctan2(rel @ T[:3, 1], rel @ T[:3, 0]), 2 * np.pi)
    assert_allclose(phase, np.pi / n + 2 * np.pi * np.arange(n) / n, atol=1e-9)


def test_prism_faces_counts():
    bottom = geo.regular_polygon(np.eye(4), 1.0, 6)
    faces = geo.prism_faces(bottom, bottom + (1.0, 0.0, 0.0))
    assert len(faces) == 8
    assert [len(f) for f in faces] == [4] * 6 + [6, 6]


def test_convex_hull_faces_merges_coplanar_triangles():
    cube = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    faces = geo.convex_hull_faces(cube)
    assert len(faces) == 6
    assert all(len(f) == 4 for f in faces)


def test_convex_hull_faces_come_in_index_order_from_their_lowest_index():
    """The output is canonical, whatever order qhull lists its triangles in: faces sorted by
    their point indices, each starting at its lowest index, counter-clockwise seen from
    outside."""
    cube = np.array([[x, y, z] for x in (0, 1) for y in (0, 1) for z in (0, 1)], dtype=float)
    faces = geo.convex_hull_faces(cube)
    index = {tuple(p): i for i, p in enumerate(cube)}
    ids = [[index[tuple(p)] for p in face] for face in faces]
    assert [sorted(f) for f in ids] == sorted(sorted(f) for f in ids)
    assert all(f[0] == min(f) for f in ids)
    centre = cube.mean(axis=0)
    for face in faces:
        outward = face.mean(axis=0) - centre
        assert geo.face_normals([face])[0] @ outward > 0


def test_face_normals_newell():
    square = np.array([[0, 0, 0], [2, 0, 0], [2, 2, 0], [0, 2, 0]], dtype=float)
    assert_allclose(geo.face_normals(square[None]), [[0, 0, 8]])  # twice the area, along +z
    assert_allclose(geo.face_normals([square[::-1]]), [[0, 0, -8]])


def test_face_normals_of_a_quadrilateral_with_two_coincident_vertices():
    """Where an elbow's mitre meets its end circle a quad is a triangle: its normal is the
    triangle's, to rounding, although the first three vertices span nothing."""
    a, b, c = np.array([5.0, 1.0, 2.0]), np.array([6.0, 1.0, 2.0]), np.array([5.0, 1.0, 3.0])
    quad = np.array([a, b, b + 1e-15, c])
    triangle = np.cross(b - a, c - a)
    normal = geo.face_normals(quad[None])[0]
    assert_allclose(
        normal / np.linalg.norm(normal), triangle / np.linalg.norm(triangle), atol=1e-12
    )
    assert_allclose(geo.face_normals([quad]), [normal])  # list and array agree


def test_convex_hull_of_flat_points_is_empty():
    assert geo.convex_hull_faces(np.array([[0, 0, 0], [1, 0, 0], [0, 1, 0], [1, 1, 0.0]])) == []


# --- joint bodies ---
def test_revolute_hull_points_polygons_and_hinge():
    joint = RevoluteJoint(4, 1.0, math.pi, SE3.Trans(1, 2, 3) * SE3.Ry(math.pi / 4))
    first, second = joint.hull_points()
    T = joint.pose_matrix
    side = geo.polygon_side(1.0, 4)
    for pts, frame in ((first, joint.proximal_frame()), (second, joint.distal_frame())):
        polygon, hinge = pts[:4], pts[4:]
        assert_allclose(np.linalg.norm(polygon - frame[:3, 3], axis=1), 1.0)
        assert_allclose((polygon - frame[:3, 3]) @ frame[:3, 0], 0.0, atol=1e-12)
        assert_allclose(hinge, [T[:3, 3] - side / 2 * T[:3, 2], T[:3, 3] + side / 2 * T[:3, 2]])


def test_revolute_distal_half_follows_the_state():
    joint = RevoluteJoint(6, 1.0, math.pi, SE3()).with_state(math.pi / 3)
    _, second = joint.hull_points()
    distal = joint.distal_frame()
    assert_allclose(np.linalg.norm(second[:6] - distal[:3, 3], axis=1), 1.0)
    assert_allclose((second[:6] - distal[:3, 3]) @ distal[:3, 0], 0.0, atol=1e-12)


def test_extended_revolute_body_has_tubes_and_hulls():
    joint = ExtendedRevoluteJoint(4, 1.0, math.pi, 2.0, SE3())
    first, _ = joint.hull_points()
    # The hull's polygon sits tubeLength inside the proximal frame.
    assert_allclose((first[:4] - joint.proximal_frame()[:3, 3]) @ (1, 0, 0), 2.0)
    faces = geo.joint_body_faces(joint)
    plain = geo.joint_body_faces(RevoluteJoint(4, 1.0, math.pi, SE3()))
    assert len(faces) == len(plain) + 2 * 6


@pytest.mark.parametrize("tip_class", [StartTip, EndTip])
def test_tip_hull_points_open_and_closed_ends(tip_class):
    joint = tip_class(6, 1.0, SE3.Trans(0, 0, 5), 1.5)
    pts = joint.hull_points()
    open_end, closed_end = joint.distal_frame(), joint.proximal_frame()
    if tip_class is EndTip:
        open_end, closed_end = closed_end, open_end
    assert_allclose(np.linalg.norm(pts[:6] - open_end[:3, 3], axis=1), 1.0)
    segment = pts[6:]
    assert_allclose(segment.mean(axis=0), closed_end[:3, 3])
    assert_allclose(np.linalg.norm(segment[1] - segment[0]), geo.polygon_side(1.0, 6))
    assert_allclose((segment[1] - segment[0]) @ joint.pose_matrix[:3, 2], 0.0, atol=1e-12)


def test_waypoint_has_no_body_and_no_axis():
    joint = Waypoint(4, 1.0, SE3())
    assert geo.joint_body_faces(joint) == []
    assert geo.joint_axis_segment(joint, 10) is None
    assert list(geo.joint_frames(joint)) == ["center"]


def test_joint_body_faces_are_closed_hulls(example_1a):
    for joint in example_1a.Joints:
        faces = geo.joint_body_faces(joint)
        if isinstance(joint, Waypoint):
            assert faces == []
        else:
            assert len(faces) >= 5


def test_joint_axis_segment():
    joint = RevoluteJoint(4, 0.5, math.pi, SE3.Trans(1, 0, 0))
    assert_allclose(geo.joint_axis_segment(joint, 10), [[1, 0, -5], [1, 0, 5]])


def test_frame_axes():
    frames = np.stack([np.eye(4), np.eye(4)])
    frames[1, :3, 3] = (1, 2, 3)
    origins, arrows = geo.frame_axes(frames, 2.0)
    assert_allclose(origins, [[0, 0, 0], [1, 2, 3]])
    assert arrows.shape == (3, 2, 3)
    assert_allclose(arrows[2, 1], [0, 0, 2])


# --- links ---
def _elbow_links(chain):
    return [link for link in chain.Links if link.elbows1.count + link.elbows2.count]


def test_elbow_grid_count_equals_elbow_count(example_1a):
    total = sum(link.elbows1.count + link.elbows2.count for link in example_1a.Links)
    drawn = sum(len(geo.link_elbow_grids(link, 32)) for link in example_1a.Links)
    assert total == 4
    assert drawn == total


def test_elbow_grid_circles_and_mitre(example_1a):
    for link in _elbow_links(example_1a):
        for arc in (link.elbows1, link.elbows2):
            grids = geo.elbow_grids(arc, 32)
            assert grids.shape == (arc.count, 3, 32, 3)
            for j, (start, mid, end) in enumerate(grids):
                F, G = arc.frames[j], arc.frames[j + 1]
                assert_allclose(np.linalg.norm(start - F[:3, 3], axis=1), link.r)
                assert_allclose((start - F[:3, 3]) @ F[:3, 0], 0.0, atol=1e-12)
                assert_allclose(np.linalg.norm(end - G[:3, 3], axis=1), link.r)
                assert_allclose((end - G[:3, 3]) @ G[:3, 0], 0.0, atol=1e-12)
                # The ellipse lies on both tubes and in the bisecting plane through the vertex.
                vertex = arc.vertices()[j]
                assert_allclose(_distance_to_line(mid, F[:3, 3], F[:3, 0]), link.r)
                assert_allclose(_distance_to_line(mid, G[:3, 3], G[:3, 0]), link.r)
                normal = F[:3, 0] + G[:3, 0]
                assert_allclose((mid - vertex) @ normal, 0.0, atol=1e-12)


def test_tube_grid(example_1a):
    link = example_1a.Links[2]
    grid = geo.tube_grid(link, 32)
    p = link.path
    assert grid.shape == (2, 32, 3)
    assert_allclose(np.linalg.norm(grid[0] - p.q1, axis=1), link.r)
    assert_allclose(np.linalg.norm(grid[1] - p.q2, axis=1), link.r)
    assert geo.tube_grid(example_1a.Links[0], 32) is None


def test_grid_quads():
    grid = np.random.default_rng(0).normal(size=(5, 3, 8, 3))
    quads = geo.grid_quads(grid)
    assert quads.shape == (5 * 2 * 8, 4, 3)
    assert_allclose(quads[0], [grid[0, 0, 0], grid[0, 0, 1], grid[0, 1, 1], grid[0, 1, 0]])
    assert_allclose(quads[7, 1], grid[0, 0, 0])  # rings are closed


def test_link_centreline_ends_and_straight_part(example_1a):
    for link in example_1a.Links[1:]:
        line = geo.link_centreline(link)
        p = link.path
        assert_allclose(line[0], p.p1, atol=1e-12)
        assert_allclose(line[-1], p.p2, atol=1e-9)
        i = int(np.argmin(np.linalg.norm(line - p.q1, axis=1)))
        assert_allclose(line[i], p.q1)
        assert_allclose(line[i + 1], p.q2)
        # Arc points stay at distance r from their circle's centre.
        if p.theta1 > 1e-9:
            assert_allclose(np.linalg.norm(line[: i + 1] - p.c1, axis=1), link.r)


def test_turning_circles(example_1a):
    link = example_1a.Links[2]
    first, second = geo.turning_circles(link)
    assert_allclose(np.linalg.norm(first - link.path.c1, axis=1), link.r)
    assert_allclose(np.linalg.norm(second - link.path.c2, axis=1), link.r)
    assert_allclose(first[0], first[-1], atol=1e-12)
    straight = example_1a.Links[5]
    assert geo.turning_circles(straight) == [None, None]


def test_elbow_pose_frames_and_axes(example_1a):
    arc = example_1a.Links[2].elbows1
    frames = geo.elbow_pose_frames(arc)
    assert frames.shape == (4, 4, 4)
    assert_allclose(frames[0], arc.frames[0])
    assert_allclose(frames[1][:3, 3], arc.vertices()[0])
    assert_allclose(frames[3], arc.frames[1], atol=1e-12)
    axes = geo.elbow_rotation_axes(arc)
    k = axes[0, 1] - axes[0, 0]
    # The rotation axis is perpendicular to both tangents.
    assert_allclose(k @ arc.frames[0][:3, 0], 0.0, atol=1e-12)
    assert_allclose(k @ arc.frames[1][:3, 0], 0.0, atol=1e-12)
    assert_allclose(axes[0].mean(axis=0), arc.vertices()[0])


def test_no_elbow_arcs_give_empty_arrays(straight_chain):
    link = straight_chain.Links[1]
    assert geo.link_elbow_grids(link).shape == (0, 3, 32, 3)
    assert geo.elbow_pose_frames(link.elbows1).shape == (0, 4, 4)
    assert geo.elbow_rotation_axes(link.elbows2).shape == (0, 2, 3)


# --- spheres and ground ---
def test_sphere_grid_radius():
    grid = geo.sphere_grid((1, 2, 3), 2.5, 6, 10)
    assert grid.shape == (7, 10, 3)
    assert_allclose(np.linalg.norm(grid - (1, 2, 3), axis=-1), 2.5)


def test_ground_plane_quads():
    quads = geo.ground_plane_quads(10.0, 1.0)
    assert quads.shape == (400, 4, 3)
    assert_allclose(quads[..., 2], 0.0)
    assert_allclose(quads[..., :2].min(axis=(0, 1)), [-10, -10])
    assert_allclose(quads[..., :2].max(axis=(0, 1)), [10, 10])
