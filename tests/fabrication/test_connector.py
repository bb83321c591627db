"""The printed junction connector (kinegami.fabrication.connector, docs/junctions.md)."""

import math
import sys

import numpy as np
import pytest
from hypothesis import assume, example, given, settings
from hypothesis import strategies as st
from numpy.testing import assert_allclose

from kinegami.chain.joints import RevoluteJoint, Waypoint
from kinegami.chain.links import LinkCSC
from kinegami.errors import ExporterUnavailableError, InvalidParameterError, NoPathError
from kinegami.fabrication.connector import (
    ConnectorOptions,
    junction_connector,
    junction_sockets,
    link_frame_at,
    sibling_overlap_lengths,
    split_connector,
    trunk_split_plane,
)
from kinegami.geometry.csc_centreline import csc_distances, csc_points
from kinegami.geometry.frames import rot_x, rot_y, rotation_matrix, translation

pytest.importorskip("manifold3d")

# --- reference data: the paper's hand (tests/data/hand_reference.json) ---------------------
R, N = 1.0, 4
PI = math.pi
#: The root's children (palm, pointer1, middle0): poses relative to the root Waypoint at I.
HAND_CHILDREN = (
    translation((2.25, 0, 3)) @ rot_y(-PI / 4) @ rot_x(PI / 4),
    translation((0, 0, 8)) @ rot_y(-PI / 2) @ rot_x(PI),
    translation((-2.25, 0, 4)) @ rot_y(-PI / 2) @ rot_x(PI / 2),
)
#: Sibling overlap l_ov of the three root links (2r threshold), published to 0.01 r.
HAND_OVERLAPS = (3.10, 3.52, 3.35)
#: Length of the palm's link (= its overlap: the palm's socket cannot fit).
HAND_PALM_LINK = 3.095729
#: The published overlaps are the last sample within 2r at steps of 0.01 r.
OVERLAP_ATOL = 0.01
#: The default trunk of the hand (trees.md §5.1): the middle finger.
HAND_TRUNK = 2
#: A feasible variant: the palm slid along its axis by this (its link becomes 4.62 r long).
PALM_SLIDE = -3.0


def hand_links(palm_slide=0.0):
    root = Waypoint(N, R, np.eye(4), pathIndex=2)
    D = root.distal_dubins_frame()
    links = []
    for k, pose in enumerate(HAND_CHILDREN):
        joint = RevoluteJoint(N, R, PI, pose)
        if k == 0 and palm_slide:
            joint = joint.translated_along_z(palm_slide)
        links.append(LinkCSC(R, D, joint.proximal_dubins_frame()))
    return D, links


# --- overlap lengths -----------------------------------------------------------------------
def test_overlap_lengths_of_the_papers_hand():
    _, links = hand_links()
    assert_allclose(sibling_overlap_lengths(links, R), HAND_OVERLAPS, atol=OVERLAP_ATOL)


def test_palm_overlaps_for_its_whole_link():
    _, links = hand_links()
    assert_allclose(links[0].length, HAND_PALM_LINK, atol=1e-6)
    assert sibling_overlap_lengths(links, R)[0] == pytest.approx(links[0].length, abs=1e-12)


def test_overlap_ends_where_the_distance_crosses_2r():
    _, links = hand_links(PALM_SLIDE)
    ov = sibling_overlap_lengths(links, R)
    for k, link in enumerate(links):
        others = [m.path for j, m in enumerate(links) if j != k]
        assert 2 * R <= ov[k] < link.length

        def dist(s, link=link, others=others):
            return np.min([csc_distances(q, csc_points(link.path, s)) for q in others], 0)

        assert dist([ov[k]])[0] == pytest.approx(2 * R, abs=1e-9)
        after = np.linspace(ov[k] + 1e-6, link.length, 500)
        assert np.all(dist(after) >= 2 * R)


def test_overlap_refuses_a_coarse_step():
    _, links = hand_links()
    with pytest.raises(InvalidParameterError, match=r"step must lie in \(0, 0.01 r\].*got 0.1"):
        sibling_overlap_lengths(links, R, step=0.1)


def test_overlap_needs_siblings():
    _, links = hand_links()
    with pytest.raises(InvalidParameterError, match="at least 2 child links"):
        sibling_overlap_lengths(links[:1], R)


# --- frames along a link ---------------------------------------------------------------------
def elbow_frame(F, alpha, axis_world, r):
    """chain.md §3: one elbow of angle alpha, F Trans(delta x) Rot Trans(delta x)."""
    delta = r * math.tan(alpha / 2)
    step = np.eye(4)
    step[:3, :3] = F[:3, :3].T @ rotation_matrix(axis_world, alpha) @ F[:3, :3]
    step[:3, 3] = (np.eye(3) + step[:3, :3]) @ (delta, 0, 0)
    return F @ step


def test_frame_in_the_first_arc_is_one_elbow():
    _, links = hand_links()
    link = links[2]
    for sigma in (0.1, 0.4, R * link.path.theta1):
        expected = elbow_frame(link.start_frame, sigma / R, link.path.k1, R)
        assert_allclose(link_frame_at(link, sigma), expected, atol=1e-12)


def test_frame_on_the_straight_part_is_F1_translated():
    _, links = hand_links()
    link = links[0]
    x = 1.2
    F = link_frame_at(link, R * link.path.theta1 + x)
    expected = link.arc1_end_frame @ translation((x, 0, 0))
    assert_allclose(F, expected, atol=1e-12)


def test_frame_at_the_end_has_the_end_tangent():
    _, links = hand_links()
    for link in links:
        F = link_frame_at(link, link.length)
        assert_allclose(F[:3, 3], link.end_frame[:3, 3], atol=1e-9)
        assert_allclose(F[:3, 0], link.end_frame[:3, 0], atol=1e-9)


def test_frame_outside_the_link_is_refused():
    _, links = hand_links()
    with pytest.raises(InvalidParameterError, match=r"sigma must lie in \[0, 3.09573\]"):
        link_frame_at(links[0], 3.5)


# --- options -----------------------------------------------------------------------------------
def test_option_defaults_scale_with_r():
    o = ConnectorOptions().resolved(2.0)
    assert (o.thickness, o.clearance, o.wall, o.socket_depth) == (0.02, 0.04, 0.4, 2.0)
    assert o.inner_radius(2.0, 4) == pytest.approx(2 + 0.06 * math.sqrt(2))
    assert o.outer_radius(2.0, 4) == pytest.approx(2 + 0.46 * math.sqrt(2))


@pytest.mark.parametrize(
    "field, value, text",
    [
        ("wall", -0.1, r"wall must lie in \(0 r, 2 r\].*got -0.1"),
        ("socket_depth", 0, r"socket_depth must lie in \(0 r, 100 r\].*got 0"),
        ("thickness", 0.9, r"thickness must lie in \[0 r, 0.5 r\].*got 0.9"),
        ("socket_rule", "loose", r"socket_rule must be one of 'clear', 'overlap', got 'loose'"),
    ],
)
def test_bad_options_name_parameter_value_and_range(field, value, text):
    with pytest.raises(InvalidParameterError, match=text):
        ConnectorOptions(**{field: value}).resolved(1.0)


# --- sockets -----------------------------------------------------------------------------------
@pytest.mark.parametrize("rule", ["clear", "overlap"])
def test_palm_socket_is_infeasible(rule):
    D, links = hand_links()
    options = ConnectorOptions(socket_rule=rule)
    with pytest.raises(InvalidParameterError, match=r"junction child 0 is infeasible.*3.09573"):
        junction_sockets(links, R, N, trunk=HAND_TRUNK, options=options)
    with pytest.raises(InvalidParameterError, match="junction child 0 is infeasible"):
        junction_connector(R, N, D, links, parent_side="base", trunk=HAND_TRUNK, options=options)


@pytest.mark.parametrize("rule", ["clear", "overlap"])
def test_sockets_lie_between_overlap_plus_depth_and_link_end(rule):
    _, links = hand_links(PALM_SLIDE)
    options = ConnectorOptions(socket_rule=rule)
    d_s = options.resolved(R).socket_depth
    sockets = junction_sockets(links, R, N, trunk=HAND_TRUNK, options=options)
    ov = sibling_overlap_lengths(links, R)
    for sock, link, overlap in zip(sockets, links, ov, strict=True):
        assert sock.overlap == pytest.approx(overlap)
        assert sock.clear >= sock.overlap
        if sock.trunk:
            assert sock.sheet_start is None
            continue
        assert sock.socket_end >= overlap + d_s - 1e-12
        assert sock.socket_end <= link.length
        assert sock.sheet_start == pytest.approx(sock.socket_end - d_s)
        assert_allclose(sock.frame, link_frame_at(link, sock.sheet_start), atol=1e-12)
        if rule == "overlap":
            assert sock.socket_end == pytest.approx(overlap + d_s)


def test_links_must_start_at_D():
    D, links = hand_links(PALM_SLIDE)
    moved = translation((0, 0, 0.5)) @ D
    with pytest.raises(InvalidParameterError, match=r"links\[0\] must start at .* frame D"):
        junction_connector(R, N, moved, links, parent_side="base", trunk=HAND_TRUNK)


def test_parent_side_is_checked():
    D, links = hand_links(PALM_SLIDE)
    with pytest.raises(InvalidParameterError, match="parent_side must be one of 'socket'"):
        junction_connector(R, N, D, links, parent_side="glue", trunk=HAND_TRUNK)


def test_missing_manifold3d_names_the_extra(monkeypatch):
    D, links = hand_links(PALM_SLIDE)
    monkeypatch.setitem(sys.modules, "manifold3d", None)
    with pytest.raises(ExporterUnavailableError, match=r"pip install 'kinegami\[print\]'"):
        junction_connector(R, N, D, links, parent_side="base", trunk=HAND_TRUNK)


# --- the mesh ----------------------------------------------------------------------------------
@pytest.fixture(scope="module", params=["socket", "flange", "base", "none"])
def hand_connector(request):
    D, links = hand_links(PALM_SLIDE)
    mesh = junction_connector(R, N, D, links, parent_side=request.param, trunk=HAND_TRUNK)
    sockets = junction_sockets(links, R, N, trunk=HAND_TRUNK)
    return request.param, D, links, sockets, mesh


def test_connector_is_watertight(hand_connector):
    _, _, _, _, mesh = hand_connector
    assert mesh.is_watertight and mesh.is_winding_consistent and mesh.is_volume
    assert mesh.body_count == 1
    assert mesh.volume > 0


def face_points(link, sigmas, apothem, n, across=0.9, count=5):
    """Points at distance ``apothem`` from the centreline along each face normal of the
    n-gon (faces centred at angles 2 pi j / n from b), spread across each face."""
    pts = []
    for s in sigmas:
        F = link_frame_at(link, s)
        for j in range(n):
            ang = 2 * PI * j / n
            normal = math.cos(ang) * F[:3, 1] + math.sin(ang) * F[:3, 2]
            along = -math.sin(ang) * F[:3, 1] + math.cos(ang) * F[:3, 2]
            half = apothem * math.tan(PI / n)
            for u in np.linspace(-across, across, count):
                pts.append(F[:3, 3] + apothem * normal + u * half * along)
    return np.array(pts)


def socket_stations(sock, link, straight_only):
    lo, hi = sock.sheet_start + 1e-3, sock.socket_end - 1e-3
    if straight_only:  # away from the arcs' mitred prisms
        lo = max(lo, R * link.path.theta1 + 0.05 * R)
        hi = min(hi, R * link.path.theta1 + link.path.tMag - 0.05 * R)
    return np.linspace(lo, hi, 9) if hi > lo else np.array([])


def test_paper_tubes_lie_inside_the_voids(hand_connector):
    _, _, links, sockets, mesh = hand_connector
    o = ConnectorOptions().resolved(R)
    paper = o.paper_radius(R, N) * math.cos(PI / N)  # apothem of the paper's outside
    for sock, link in zip(sockets, links, strict=True):
        if sock.trunk:
            continue
        stations = np.linspace(sock.sheet_start, sock.socket_end, 11)
        for apothem in (paper, 0.5 * paper, 0.0):
            points = face_points(link, stations, apothem, N, across=1.0)
            assert not mesh.contains(points).any()


def test_socket_walls_are_at_least_w_thick(hand_connector):
    _, _, links, sockets, mesh = hand_connector
    o = ConnectorOptions().resolved(R)
    inner = o.inner_radius(R, N) * math.cos(PI / N)
    for sock, link in zip(sockets, links, strict=True):
        if sock.trunk:
            continue
        # exact on the straight part; on arcs the mitred prisms bulge by < 0.1 w
        for straight, fractions in ((True, (0.01, 0.5, 0.99)), (False, (0.1, 0.5, 0.9))):
            stations = socket_stations(sock, link, straight)
            for f in fractions:
                points = face_points(link, stations, inner + f * o.wall, N)
                assert mesh.contains(points).all(), (sock.child, straight, f)


def test_parent_socket_wall(hand_connector):
    parent_side, D, _, _, mesh = hand_connector
    if parent_side != "socket":
        pytest.skip("only the socket has a wall behind D")
    o = ConnectorOptions().resolved(R)
    inner = o.inner_radius(R, N) * math.cos(PI / N)
    back = LinkCSC(R, D @ translation((-o.socket_depth, 0, 0)), D)
    stations = np.linspace(0.05, o.socket_depth - 0.05, 7)
    assert not mesh.contains(face_points(back, stations, o.paper_radius(R, N) * 0.7, N)).any()
    assert mesh.contains(face_points(back, stations, inner + 0.5 * o.wall, N)).all()


def test_base_plate_closes_the_hub(hand_connector):
    parent_side, D, _, _, mesh = hand_connector
    o = ConnectorOptions().resolved(R)
    below = D[:3, 3] - 0.5 * o.plate * D[:3, 0]
    assert mesh.contains([below])[0] == (parent_side == "base")


def test_trunk_sleeve_splits_into_two_watertight_halves():
    D, links = hand_links(PALM_SLIDE)
    mesh = junction_connector(R, N, D, links, parent_side="socket", trunk=HAND_TRUNK)
    point, normal = trunk_split_plane(D, links[HAND_TRUNK])
    assert abs(normal @ D[:3, 0]) < 1e-12
    halves = split_connector(mesh, point, normal)
    for half in halves:
        assert half.is_watertight and half.is_volume
        assert np.all((half.vertices - point) @ normal * (1 if half is halves[0] else -1) > -1e-9)
    assert halves[0].volume + halves[1].volume == pytest.approx(mesh.volume, rel=1e-9)


# --- random sibling sets ---------------------------------------------------------------------
def random_links(D, ends):
    links = []
    for x, y, z, yaw, pitch in ends:
        T = np.eye(4)
        T[:3, :3] = rotation_matrix((0, 0, 1), yaw) @ rotation_matrix((0, 1, 0), pitch)
        T[:3, 3] = (x, y, z)
        links.append(LinkCSC(R, D, T))
    return links


child_ends = st.tuples(
    st.floats(4.0, 9.0),  # x: ahead of D
    st.floats(-6.0, 6.0),
    st.floats(-6.0, 6.0),
    st.floats(-1.2, 1.2),
    st.floats(-1.2, 1.2),
)


@settings(max_examples=10, deadline=None)
@given(
    ends=st.lists(child_ends, min_size=2, max_size=4),
    n=st.sampled_from([4, 6, 8]),
    parent_side=st.sampled_from(["socket", "flange", "base", "none"]),
    with_trunk=st.booleans(),
)
@example(  # the boolean left two pieces of no volume beside the child tilted by 1.2e-7 rad
    ends=[(4.0, 5.0, 0.0, 0.0, 1.192092896e-07), (4.0, 0.0, 2.0, 0.0, 0.0)],
    n=4, parent_side="socket", with_trunk=False,
)  # fmt: skip
def test_random_sibling_sets_give_watertight_connectors(ends, n, parent_side, with_trunk):
    D = np.eye(4)
    try:
        links = random_links(D, ends)
    except NoPathError:
        assume(False)
    trunk = 0 if with_trunk else None
    options = ConnectorOptions(socket_depth=0.5)
    try:
        junction_sockets(links, R, n, trunk=trunk, options=options)
    except InvalidParameterError:
        assume(False)  # a child too close to its siblings for a socket
    mesh = junction_connector(R, n, D, links, parent_side=parent_side, trunk=trunk, options=options)
    assert mesh.is_watertight and mesh.is_volume
    assert mesh.body_count == 1


def test_the_same_junction_is_measured_once_and_answers_stay_separate():
    """sibling_overlap_lengths keeps its answers for the last few sets of links (choosing a
    tree's trunks and then building its sockets asked for the same junctions again: fuzz
    operations seed 504290); the caller gets its own array each time."""
    from spatialmath import SE3

    import kinegami.fabrication.connector as connector

    a = LinkCSC(1, SE3(), SE3.Trans(10, 6, 0))
    b = LinkCSC(1, SE3(), SE3.Trans(10, -6, 0))
    connector._overlap_lengths.cache_clear()
    first = connector.sibling_overlap_lengths([a, b], 1.0)
    first[:] = -1.0  # the caller's own copy
    again = connector.sibling_overlap_lengths([a, b], 1.0)
    assert again.round(3).tolist() == [2.482, 2.482]
    assert connector._overlap_lengths.cache_info().hits == 1
