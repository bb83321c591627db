"""STL and OBJ of a chain's 3D model: closed parts, exact tube geometry, trimesh round trips."""

from __future__ import annotations

import io
import math

import numpy as np
import pytest
import trimesh
from hypothesis import given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from kinegami import (
    SE3,
    EndTip,
    ExtendedRevoluteJoint,
    KinematicChain,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.export.mesh import (
    chain_mesh,
    chain_parts,
    joint_parts,
    shell_mass_properties,
    write_obj,
    write_stl,
)
from kinegami.viz.chain_geometry import regular_polygon

EXAMPLE_1_PARTS = [
    "joint_0",
    "link_1_tube",
    "link_2_arc1",
    "link_2_tube",
    "link_2_arc2",
    "joint_2",
    "link_3_tube",
    "link_4_arc1",
    "link_4_twist",
    "link_4_tube",
    "link_4_arc2",
    "joint_4_proximal",
    "joint_4_distal",
    "link_5_tube",
    "link_6_twist",
    "link_6_tube",
    "joint_6",
]


def polygon_area(n: int, r: float) -> float:
    return 0.5 * n * r * r * math.sin(2.0 * math.pi / n)


def rings(part, n: int) -> np.ndarray:
    """The rings of a swept part, in order."""
    assert part.rings.shape[1:] == (n, 3)
    return part.rings


def same_point_sets(a: np.ndarray, b: np.ndarray, tol: float) -> bool:
    if a.shape != b.shape:
        return False
    d = np.linalg.norm(a[:, None, :] - b[None, :, :], axis=2)
    return bool(d.min(axis=1).max() <= tol and d.min(axis=0).max() <= tol)


def mixed_chain() -> KinematicChain:
    """Revolute, prismatic and extended revolute joints (n = 6), safe placement."""
    chain = KinematicChain(StartTip(6, 1, SE3(), 1.5))
    assert chain.append(RevoluteJoint(6, 1, math.pi, SE3.Ry(math.pi / 3))) is not None
    assert (
        chain.append(PrismaticJoint(6, 1, 2, 2, math.pi / 4, SE3.Rx(0.5) * SE3.Trans(3, 0, 0)))
        is not None
    )
    assert (
        chain.append(ExtendedRevoluteJoint(6, 1, math.pi / 2, 1.0, SE3.Rz(0.7) * SE3.Ry(1.2)))
        is not None
    )
    assert chain.append(EndTip(6, 1, SE3.Ry(math.pi / 2), 1.5)) is not None
    return chain


# --- random chains -------------------------------------------------------------------------

quaternions = st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda q: math.hypot(*q) > 0.1)
translations = st.tuples(*[st.floats(-4, 4)] * 3)


@st.composite
def random_chains(draw, max_joints: int = 4):
    """A StartTip, revolute / prismatic / waypoint joints with random poses (safe placement)
    and maybe an EndTip; r in [0.5, 5], n in {4, 6, 8}."""
    r = draw(st.floats(0.5, 5))
    n = draw(st.sampled_from([4, 6, 8]))
    chain = KinematicChain(StartTip(n, r, SE3(), 1.5 * r))
    for _ in range(draw(st.integers(1, max_joints))):
        T = np.eye(4)
        T[:3, :3] = Rotation.from_quat(draw(quaternions)).as_matrix()
        T[:3, 3] = np.array(draw(translations)) * r
        kind = draw(st.sampled_from("RPW"))
        if kind == "R":
            joint = RevoluteJoint(n, r, draw(st.floats(0.5, 3.0)), T)
        elif kind == "P":
            joint = PrismaticJoint(n, r, 2 * r, 2, draw(st.floats(math.pi / 6, 1.4)), T)
        else:
            joint = Waypoint(n, r, T, pathIndex=draw(st.sampled_from([0, 1, 2])))
        chain.append(joint)
    if draw(st.booleans()):
        chain.append(EndTip(n, r, SE3.Trans(0, 0, 3 * r), 1.5 * r))
    return chain


# --- parts ---------------------------------------------------------------------------------


def test_example_1_part_names(example_1a):
    assert [p.name for p in chain_parts(example_1a)] == EXAMPLE_1_PARTS


def test_every_part_is_a_closed_outward_volume(example_1a):
    for part in chain_parts(example_1a) + chain_parts(mixed_chain(), split_joints=True):
        mesh = part.to_trimesh()
        assert mesh.is_watertight, part.name
        assert mesh.is_winding_consistent, part.name
        assert mesh.is_volume, part.name
        assert mesh.volume > 0.0, part.name


def test_tube_and_prism_volumes_are_polygon_area_times_length(example_1a):
    n, r = 4, 1.0
    area = polygon_area(n, r)
    parts = {p.name: p for p in chain_parts(example_1a)}
    link = example_1a.Links[2]
    assert parts["link_2_tube"].to_trimesh().volume == pytest.approx(area * link.path.tMag)
    link6 = example_1a.Links[6]
    tube = parts["link_6_tube"].to_trimesh().volume + parts["link_6_twist"].to_trimesh().volume
    # twist of -pi/2 on a square: a whole-column relabelling, the twisted prism is straight
    assert tube == pytest.approx(area * link6.path.tMag)
    prismatic = example_1a.Joints[2]
    assert parts["joint_2"].to_trimesh().volume == pytest.approx(area * prismatic.neutralLength)


def test_link_parts_join_edge_to_edge(example_1a):
    """Arc 1 starts on the link's start polygon, each swept part ends where the next starts,
    arc 2 ends on the end polygon."""
    n, r = 4, 1.0
    parts = chain_parts(example_1a)
    for i in range(1, len(example_1a.Joints)):
        link = example_1a.Links[i]
        swept = [p for p in parts if p.name.startswith(f"link_{i}_")]
        assert swept
        start = regular_polygon(link.start_frame, r, n)
        end = regular_polygon(link.end_frame, r, n)
        assert same_point_sets(rings(swept[0], n)[0], start, 1e-9)
        assert same_point_sets(rings(swept[-1], n)[-1], end, 1e-9)
        for a, b in zip(swept, swept[1:], strict=False):
            assert same_point_sets(rings(a, n)[-1], rings(b, n)[0], 1e-9)


def test_elbow_mitres_lie_in_the_bisecting_plane(example_1a):
    n, r = 4, 1.0
    link = example_1a.Links[4]
    parts = {p.name: p for p in chain_parts(example_1a)}
    for arc, name in ((link.elbows1, "link_4_arc1"), (link.elbows2, "link_4_arc2")):
        ring = rings(parts[name], n)
        assert ring.shape[0] == 2 * arc.count + 1
        F = arc.frames
        for j in range(arc.count):
            a_in, a_out = F[j, :3, 0], F[j + 1, :3, 0]
            vertex = F[j, :3, 3] + r * math.tan(arc.elbowAngle / 2) * a_in
            normal = (a_in + a_out) / np.linalg.norm(a_in + a_out)
            mitre = ring[2 * j + 1]
            np.testing.assert_allclose((mitre - vertex) @ normal, 0.0, atol=1e-12)
            # the mitre is the start polygon carried along the incoming axis
            carried = mitre - ring[2 * j]
            np.testing.assert_allclose(np.cross(carried, a_in), 0.0, atol=1e-12)
            np.testing.assert_allclose(ring[2 * j + 2], regular_polygon(F[j + 1], r, n), atol=0)


def test_twist_turns_by_its_residual_angle():
    """A twist of 1 rad on a hexagon: the far ring is the near one turned by 1 rad about u."""
    chain = KinematicChain(StartTip(6, 1, SE3(), 1.5))
    target = SE3.Trans(0, 0, 8) * SE3.Rz(1.0)
    chain.append(EndTip(6, 1, target, 1.5), safe=False, fixedPosition=True, fixedOrientation=True)
    link = chain.Links[1]
    assert link.hasTwist and link.twistAngle == pytest.approx(1.0)
    parts = {p.name: p for p in chain_parts(chain, twistPortion=0.25)}
    near, far = rings(parts["link_1_twist"], 6)
    u = np.asarray(link.path.tUnit)
    height = 0.25 * link.path.tMag
    residual = 1.0 % (2 * math.pi / 6)
    R = Rotation.from_rotvec(residual * u).as_matrix()
    centre = link.path.q1
    np.testing.assert_allclose(far, (near - centre) @ R.T + centre + height * u, atol=1e-12)
    tube = rings(parts["link_1_tube"], 6)
    assert np.linalg.norm(tube[1, 0] - tube[0, 0]) == pytest.approx(link.path.tMag - height)


def test_joint_shapes():
    chain = mixed_chain()
    n, r = 6, 1.0
    for k, joint in enumerate(chain.Joints):
        parts = joint_parts(joint, k, split=True)
        if isinstance(joint, Waypoint):
            assert parts == []
            continue
        if isinstance(joint, PrismaticJoint):
            proximal, distal = parts
            area = polygon_area(n, r)
            assert proximal.to_trimesh().volume == pytest.approx(area * joint.neutralLength / 2)
            assert distal.to_trimesh().volume == pytest.approx(area * joint.neutralLength / 2)
            polygon = regular_polygon(joint.distal_dubins_frame(), r, n)
            d = np.linalg.norm(distal.vertices[:, None] - polygon[None], axis=2).min(axis=0)
            assert d.max() < 1e-12  # the distal polygon is a face of the distal half
        if isinstance(joint, RevoluteJoint):
            proximal, distal = parts
            T = joint.pose_matrix
            side = 2 * r * math.sin(math.pi / n)
            hinge = np.array([T[:3, 3] - side / 2 * T[:3, 2], T[:3, 3] + side / 2 * T[:3, 2]])
            for half, frame in ((proximal, joint.proximal_dubins_frame()),
                                (distal, joint.distal_dubins_frame())):  # fmt: skip
                points = np.vstack([regular_polygon(frame, r, n), hinge])
                d = np.linalg.norm(half.vertices[:, None] - points[None], axis=2).min(axis=0)
                assert d.max() < 1e-12, (k, half.name)


def test_parts_follow_the_current_configuration(example_1a):
    q = [0.0, 0.0, 0.8, 0.0, 1.2, 0.0, 0.0]
    assert example_1a.setJointStates(q)
    parts = {p.name: p for p in chain_parts(example_1a)}
    prismatic = example_1a.Joints[2]
    area = polygon_area(4, 1.0)
    assert parts["joint_2"].to_trimesh().volume == pytest.approx(area * (3 + 0.8))
    revolute = example_1a.Joints[4]
    polygon = regular_polygon(revolute.distal_dubins_frame(), 1.0, 4)
    d = np.linalg.norm(parts["joint_4_distal"].vertices[:, None] - polygon[None], axis=2)
    assert d.min(axis=0).max() < 1e-12
    end = regular_polygon(example_1a.Links[6].end_frame, 1.0, 4)
    assert same_point_sets(rings(parts["link_6_tube"], 4)[-1], end, 1e-9)
    assert prismatic.state == 0.8


def random_states(data, chain) -> list[float]:
    """A random state in range for every joint."""
    return [data.draw(st.floats(*j.stateRange())) for j in chain.Joints]


@settings(deadline=None, max_examples=25)
@given(chain=random_chains(), data=st.data())
def test_random_chains_give_closed_parts(chain, data):
    assert chain.setJointStates(random_states(data, chain))
    for part in chain_parts(chain, split_joints=True):
        mesh = part.to_trimesh()
        assert mesh.is_watertight and mesh.is_winding_consistent, part.name
        assert mesh.volume > 0.0, part.name
        # as a reader sees it: coincident vertices merged, degenerate faces dropped
        processed = trimesh.Trimesh(part.vertices, part.faces)
        assert processed.is_watertight and processed.is_volume, part.name


# --- files ---------------------------------------------------------------------------------


def _stl(chain, **options) -> trimesh.Trimesh:
    buffer = io.BytesIO()
    write_stl(chain, buffer, **options)
    data = buffer.getvalue()
    assert not data.startswith(b"solid")  # binary, not ASCII
    return trimesh.load(io.BytesIO(data), file_type="stl")


def test_stl_round_trip(example_1a):
    parts = chain_parts(example_1a)
    mesh = _stl(example_1a)
    assert mesh.faces.shape[0] == sum(p.faces.shape[0] for p in parts)
    total = sum(p.to_trimesh().volume for p in parts)
    assert mesh.volume == pytest.approx(total, rel=1e-5)
    lo, hi = mesh.bounds
    for joint in example_1a.Joints:
        p = joint.pose_matrix[:3, 3]
        assert np.all(p >= lo - 1e-5) and np.all(p <= hi + 1e-5)
    # the file's own normals are unit outward normals
    np.testing.assert_allclose(np.linalg.norm(mesh.face_normals, axis=1), 1.0, atol=1e-6)


@pytest.mark.parametrize(("options", "factor"), [({"units": "cm"}, 10.0), ({"scale": 2.5}, 2.5),
                                                 ({"units": "in", "scale": 2}, 50.8)])  # fmt: skip
def test_stl_units(example_1a, options, factor):
    base = _stl(example_1a)
    scaled = _stl(example_1a, **options)
    np.testing.assert_allclose(scaled.bounds, base.bounds * factor, rtol=1e-6, atol=1e-5)


def test_obj_round_trip_one_object_per_part(example_1a):
    stream = io.StringIO()
    write_obj(example_1a, stream)
    scene = trimesh.load(io.BytesIO(stream.getvalue().encode()), file_type="obj",
                         split_objects=True, group_material=False)  # fmt: skip
    parts = {p.name: p for p in chain_parts(example_1a)}
    assert set(scene.geometry) == set(parts)
    for name, mesh in scene.geometry.items():
        assert mesh.is_watertight, name
        assert mesh.volume == pytest.approx(parts[name].to_trimesh().volume, rel=1e-9)


def test_chain_mesh_is_all_parts(example_1a):
    mesh = chain_mesh(example_1a, units="cm")
    parts = chain_parts(example_1a)
    assert mesh.vertices.shape[0] == sum(p.vertices.shape[0] for p in parts)
    assert mesh.volume == pytest.approx(1000.0 * sum(p.to_trimesh().volume for p in parts))


def test_chain_without_links_or_movable_joints():
    chain = KinematicChain(StartTip(4, 1, SE3(), 1.5))
    chain.append(EndTip(4, 1, SE3.Trans(0, 0, 6), 1.5), safe=False, fixedPosition=True,
                 fixedOrientation=True)  # fmt: skip
    names = [p.name for p in chain_parts(chain)]
    assert names == ["joint_0", "link_1_tube", "joint_1"]
    assert _stl(chain).bounds[1][2] == pytest.approx(6 + 0.75, abs=1e-6)


# --- bad input -----------------------------------------------------------------------------


def test_pattern_is_not_a_chain(example_1a):
    with pytest.raises(InvalidTypeError, match="KinematicChain"):
        write_stl(example_1a.creasePattern(), io.BytesIO())
    with pytest.raises(InvalidTypeError, match="KinematicChain"):
        write_obj("chain", io.StringIO())


@pytest.mark.parametrize(
    ("options", "error"),
    [
        ({"unit": "mm"}, InvalidTypeError),
        ({"units": "km"}, InvalidParameterError),
        ({"scale": 0}, InvalidParameterError),
        ({"scale": "2"}, InvalidTypeError),
        ({"twistPortion": 1.5}, InvalidParameterError),
    ],
)
def test_bad_options(example_1a, options, error):
    stream = io.BytesIO()
    with pytest.raises(error):
        write_stl(example_1a, stream, **options)
    assert stream.getvalue() == b""


# --- shell inertia -------------------------------------------------------------------------


def test_shell_inertia_of_a_cube():
    """Thin cube shell of side a: mass 6 a^2 rho, I = 5/18 m a^2 about every centroidal axis."""
    a, rho = 2.0, 0.3
    box = trimesh.creation.box(extents=(a, a, a))
    R = Rotation.from_rotvec([0.3, -0.2, 0.9]).as_matrix()
    shift = np.array([1.0, -2.0, 0.5])
    mass, com, inertia = shell_mass_properties(box.vertices @ R.T + shift, box.faces, rho)
    assert mass == pytest.approx(6 * a * a * rho)
    np.testing.assert_allclose(com, shift, atol=1e-12)
    np.testing.assert_allclose(inertia, 5.0 / 18.0 * mass * a * a * np.eye(3), atol=1e-12)


def test_shell_inertia_of_a_thin_cylinder():
    """A 256-gon tube without caps approximates a cylinder shell: I_axis = m R^2."""
    n, radius, length = 256, 1.0, 3.0
    t = 2 * math.pi * np.arange(n) / n
    ring = np.stack([radius * np.cos(t), radius * np.sin(t), np.zeros(n)], axis=1)
    vertices = np.vstack([ring, ring + [0, 0, length]])
    i = np.arange(n)
    j = (i + 1) % n
    faces = np.concatenate([np.stack([i, j, j + n], 1), np.stack([i, j + n, i + n], 1)])
    mass, com, inertia = shell_mass_properties(vertices, faces, 1.0)
    assert mass == pytest.approx(2 * math.pi * radius * length, rel=1e-3)
    np.testing.assert_allclose(com, [0, 0, length / 2], atol=1e-12)
    assert inertia[2, 2] == pytest.approx(mass * radius**2, rel=1e-3)
    expected = mass * (radius**2 / 2 + length**2 / 12)
    assert inertia[0, 0] == pytest.approx(expected, rel=1e-3)
