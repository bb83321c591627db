"""URDF export: yourdfpy reads it back, its forward kinematics is the chain's at every state."""

from __future__ import annotations

import copy
import io
import math
import os
import xml.etree.ElementTree as ET

import numpy as np
import pytest
import trimesh
import yourdfpy
from hypothesis import given, settings
from hypothesis import strategies as st

from kinegami import (
    SE3,
    EndTip,
    KinematicChain,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)
from kinegami.clearance.solids import chain_parts
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.export import ExportError
from kinegami.export.registry import export
from kinegami.export.urdf import roll_pitch_yaw, urdf_model, write_urdf

from .test_mesh import mixed_chain, random_chains, random_states

FK_TOL = 1e-9  # metres (positions) and rotation-matrix entries


def listing(folder) -> list[str]:
    """Every file and folder below ``folder`` (relative paths), sorted."""
    out = []
    for root, dirs, files in os.walk(folder):
        for name in dirs + files:
            out.append(os.path.relpath(os.path.join(root, name), folder))
    return sorted(out)


def movable_indices(chain) -> list[int]:
    return [k for k, j in enumerate(chain.Joints) if isinstance(j, RevoluteJoint | PrismaticJoint)]


def bodies_of(chain) -> tuple[list[int], list[int]]:
    """Body of every joint's Pose (proximal side) and of its distal side: a revolute or prismatic
    joint starts a new body."""
    movable = set(movable_indices(chain))
    proximal, distal, body = [], [], 0
    for k in range(len(chain.Joints)):
        proximal.append(body)
        body += k in movable
        distal.append(body)
    return proximal, distal


def in_metres(T, metres: float) -> np.ndarray:
    T = np.array(T, dtype=float)
    T[:3, 3] *= metres
    return T


def urdf_config(chain, states, metres: float) -> dict[str, float]:
    """yourdfpy configuration: radians, or metres for prismatic joints."""
    return {
        f"joint_{k}": states[k] * (metres if isinstance(chain.Joints[k], PrismaticJoint) else 1.0)
        for k in movable_indices(chain)
    }


def set_configuration(robot, config: dict[str, float]) -> None:
    """``robot.update_cfg(config)``, made exact: trimesh's scene graph ignores a change of a
    transform within its ``allclose`` tolerance (~1e-8), so every joint is first moved 1 away."""
    robot.update_cfg({name: value + 1.0 for name, value in config.items()})
    robot.update_cfg(config)


def fk_error(robot, chain0, configurations, metres: float = 1e-3) -> float:
    """Largest difference between the chain's joint Poses and distal frames after
    ``setJointStates(q)`` and those carried by yourdfpy's forward kinematics at q.

    ``chain0`` is the chain with all states 0: each frame is fixed in its body, so its pose in
    the body frame is read once at the zero configuration.
    """
    proximal, distal = bodies_of(chain0)
    set_configuration(robot, urdf_config(chain0, [0.0] * len(chain0.Joints), metres))
    body = [robot.get_transform(f"body_{b}") for b in range(max(distal) + 1)]
    rel_pose = [
        np.linalg.inv(body[proximal[k]]) @ in_metres(j.pose_matrix, metres)
        for k, j in enumerate(chain0.Joints)
    ]
    rel_distal = [
        np.linalg.inv(body[distal[k]]) @ in_metres(j.distal_frame(), metres)
        for k, j in enumerate(chain0.Joints)
    ]
    worst = 0.0
    for states in configurations:
        chain = copy.deepcopy(chain0)
        assert chain.setJointStates(states)
        set_configuration(robot, urdf_config(chain, states, metres))
        for k, joint in enumerate(chain.Joints):
            pose = robot.get_transform(f"body_{proximal[k]}") @ rel_pose[k]
            dist = robot.get_transform(f"body_{distal[k]}") @ rel_distal[k]
            worst = max(
                worst,
                float(np.abs(pose - in_metres(joint.pose_matrix, metres)).max()),
                float(np.abs(dist - in_metres(joint.distal_frame(), metres)).max()),
            )
    return worst


def random_configurations(chain, count: int, seed: int = 0) -> list[list[float]]:
    rng = np.random.default_rng(seed)
    return [[rng.uniform(*j.stateRange()) for j in chain.Joints] for _ in range(count)]


def load(path) -> yourdfpy.URDF:
    robot = yourdfpy.URDF.load(str(path))
    assert robot.validate(), robot.errors
    return robot


# --- forward kinematics ----------------------------------------------------------------------


def test_example_1_forward_kinematics(tmp_path, example_1a):
    path = export(example_1a, tmp_path / "example1.urdf")
    robot = load(path)
    assert robot.actuated_joint_names == ["joint_2", "joint_4"]
    assert [robot.joint_map[n].type for n in robot.actuated_joint_names] == [
        "prismatic",
        "revolute",
    ]
    configurations = random_configurations(example_1a, 25)
    configurations += [[lo for lo, _ in (j.stateRange() for j in example_1a.Joints)]]
    configurations += [[hi for _, hi in (j.stateRange() for j in example_1a.Joints)]]
    assert fk_error(robot, example_1a, configurations) <= FK_TOL


def test_mixed_chain_forward_kinematics(tmp_path):
    chain = mixed_chain()
    kinds = [type(chain.Joints[k]).__name__ for k in movable_indices(chain)]
    assert kinds == ["RevoluteJoint", "PrismaticJoint", "ExtendedRevoluteJoint"]
    robot = load(export(chain, tmp_path / "mixed.urdf"))
    assert fk_error(robot, chain, random_configurations(chain, 25, seed=1)) <= FK_TOL


def test_export_at_any_state_gives_the_same_robot(tmp_path):
    """The zero configuration of the URDF is the chain at all states 0, whatever its states."""
    chain0 = mixed_chain()
    moved = copy.deepcopy(chain0)
    assert moved.setJointStates(random_configurations(chain0, 1, seed=7)[0])
    robot = load(export(moved, tmp_path / "moved.urdf"))
    assert fk_error(robot, chain0, random_configurations(chain0, 10, seed=2)) <= FK_TOL


@pytest.mark.parametrize(
    ("units", "scale", "metres"),
    [("mm", 1.0, 1e-3), ("cm", 1.0, 1e-2), ("m", 0.5, 0.5), ("in", 2.0, 0.0508)],
)
def test_units(tmp_path, example_1a, units, scale, metres):
    path = export(example_1a, tmp_path / "u.urdf", units=units, scale=scale, meshes=False)
    robot = load(path)
    assert fk_error(robot, example_1a, random_configurations(example_1a, 5), metres) <= FK_TOL
    limit = robot.joint_map["joint_2"].limit
    lo, hi = example_1a.Joints[2].stateRange()
    assert limit.lower == pytest.approx(lo * metres, rel=1e-15)
    assert limit.upper == pytest.approx(hi * metres, rel=1e-15)


@settings(deadline=None, max_examples=20)
@given(chain=random_chains(), data=st.data())
def test_random_chains_forward_kinematics(tmp_path_factory, chain, data):
    folder = tmp_path_factory.mktemp("random")
    exported = copy.deepcopy(chain)
    assert exported.setJointStates(random_states(data, chain))  # export at some state
    robot = load(export(exported, folder / "r.urdf", meshes=False))
    configurations = [random_states(data, chain) for _ in range(3)]
    assert fk_error(robot, chain, configurations) <= FK_TOL * max(1.0, chain.r)


# --- conventions -----------------------------------------------------------------------------


def test_every_joint_turns_about_its_own_z(tmp_path, example_1a):
    """Each joint's frame is its Pose (state 0) and its axis is z (``0 0 1``): Robotics
    Toolbox 1.5 reads ``<axis xyz="-1 0 0">`` as a 1-radian rotation (its issues #253, #441),
    which put the PUMA's tip 1.7 m off. yourdfpy's body frames at zero are the joints' Poses."""
    path = export(example_1a, tmp_path / "e.urdf", meshes=False)
    root = ET.parse(path).getroot()
    axes = [joint.find("axis").get("xyz") for joint in root.iter("joint")]
    assert axes and set(axes) == {"0 0 1"}
    robot = load(path)
    for b, k in enumerate(movable_indices(example_1a), start=1):
        T = robot.get_transform(f"body_{b}")
        pose = example_1a.Joints[k].pose_matrix
        np.testing.assert_allclose(T[:3, :3], pose[:3, :3], atol=1e-15)
        np.testing.assert_allclose(T[:3, 3], 1e-3 * pose[:3, 3], atol=1e-15)


@given(st.floats(-math.pi, math.pi), st.floats(-math.pi / 2, math.pi / 2),
       st.floats(-math.pi, math.pi), st.sampled_from([0.0, 1e-14, 1e-9, 1e-5]))
def test_roll_pitch_yaw_rebuilds_the_rotation(roll, pitch, yaw, lock):
    """URDF's rpy of any rotation, at and near pitch +-pi/2 (gimbal lock) too."""
    from scipy.spatial.transform import Rotation

    if lock:
        pitch = math.copysign(math.pi / 2 - lock, pitch)
    R = Rotation.from_euler("xyz", [roll, pitch, yaw]).as_matrix()
    again = Rotation.from_euler("xyz", roll_pitch_yaw(R)).as_matrix()
    assert np.abs(again - R).max() <= 1e-13


def test_limits_effort_and_velocity(tmp_path, example_1a):
    robot = load(export(example_1a, tmp_path / "e.urdf", effort=2.5, velocity=0.25))
    for k in movable_indices(example_1a):
        limit = robot.joint_map[f"joint_{k}"].limit
        assert (limit.effort, limit.velocity) == (2.5, 0.25)
    limit = robot.joint_map["joint_4"].limit
    assert (limit.lower, limit.upper) == example_1a.Joints[4].stateRange()
    defaults = load(export(example_1a, tmp_path / "d.urdf", meshes=False))
    assert defaults.joint_map["joint_4"].limit.effort == 1.0
    assert defaults.joint_map["joint_4"].limit.velocity == 1.0


def test_chain_without_movable_joints_has_fixed_joints(tmp_path):
    """Issue 5: no movable joints still gives a valid file, with fixed joints."""
    chain = KinematicChain(StartTip(4, 1, SE3(), 1.5))
    fixed = {"relative": False, "safe": False, "fixedPosition": True, "fixedOrientation": True}
    chain.append(Waypoint(4, 1, SE3.Trans(0, 0, 4)), **fixed)
    chain.append(EndTip(4, 1, SE3.Trans(0, 0, 8), 1.5), **fixed)
    path = export(chain, tmp_path / "rigid.urdf")
    robot = load(path)
    assert robot.validate()
    assert list(robot.link_map) == ["body_0", "body_1", "body_2"]
    assert robot.num_actuated_joints == 0
    assert [(j.name, j.type, j.parent, j.child) for j in robot.robot.joints] == [
        ("joint_1", "fixed", "body_0", "body_1"), ("joint_2", "fixed", "body_1", "body_2"),
    ]  # fmt: skip
    for k, joint in enumerate(chain.Joints):  # each body sits at its joint's centre (metres)
        T = robot.get_transform(f"body_{k}", "body_0")
        assert np.allclose(T[:3, 3], joint.pose_matrix[:3, 3] * 1e-3, atol=1e-12)
        assert np.allclose(T[:3, :3], np.eye(3), atol=1e-12)
    visuals = {k: {v.name for v in link.visuals} for k, link in robot.link_map.items()}
    assert visuals == {
        "body_0": {"joint_0"}, "body_1": {"link_1_tube"}, "body_2": {"link_2_tube", "joint_2"},
    }  # fmt: skip
    lo, hi = robot.scene.bounds
    assert lo[2] == pytest.approx(-0.75e-3, abs=1e-8)  # STL is float32
    assert hi[2] == pytest.approx(8.75e-3, abs=1e-8)


def test_single_joint_chain_is_one_link(tmp_path):
    robot = load(export(KinematicChain(StartTip(4, 1, SE3(), 1.5)), tmp_path / "one.urdf"))
    assert robot.validate()
    assert list(robot.link_map) == ["body_0"] and robot.robot.joints == []


# --- meshes and inertia ----------------------------------------------------------------------


def test_meshes_sit_where_the_chain_is(tmp_path):
    """Every mesh file, moved by its body's forward kinematics at q, is the chain's part at q."""
    chain0 = mixed_chain()
    path = export(chain0, tmp_path / "mixed.urdf")
    robot = load(path)
    files = sorted(os.listdir(tmp_path / "mixed_meshes"))
    names = {p.name for p in chain_parts(chain0, split_joints=True)}
    assert files == sorted(f"{name}.stl" for name in names)
    for states in random_configurations(chain0, 3, seed=3):
        chain = copy.deepcopy(chain0)
        assert chain.setJointStates(states)
        parts = {p.name: p for p in chain_parts(chain, split_joints=True)}
        set_configuration(robot, urdf_config(chain, states, 1e-3))
        for link_name, link in robot.link_map.items():
            T = robot.get_transform(link_name)
            for visual in link.visuals:
                mesh = trimesh.load(tmp_path / visual.geometry.mesh.filename, file_type="stl")
                assert mesh.is_watertight and mesh.is_volume, visual.name
                moved = mesh.vertices @ T[:3, :3].T + T[:3, 3]
                expected = parts[visual.name].vertices * 1e-3
                d = np.linalg.norm(moved[:, None] - expected[None], axis=2)
                assert d.min(axis=1).max() < 1e-8 and d.min(axis=0).max() < 1e-8, visual.name
            collisions = [c.geometry.mesh.filename for c in link.collisions]
            assert collisions == [v.geometry.mesh.filename for v in link.visuals]


def test_mesh_paths_are_relative(tmp_path, example_1a):
    path = export(example_1a, tmp_path / "sub" / "robot.urdf")
    root = ET.parse(path).getroot()
    filenames = [m.get("filename") for m in root.iter("mesh")]
    assert filenames and all(f.startswith("robot_meshes/") for f in filenames)
    # loads from another working directory
    robot = yourdfpy.URDF.load(str(path))
    assert len(robot.scene.geometry) == len(set(filenames))


def test_mujoco_keeps_the_mesh_paths(tmp_path, example_1a):
    """MuJoCo's importer strips mesh paths to their file names unless the robot says
    <mujoco><compiler strippath="false"/></mujoco>; yourdfpy still validates the file."""
    path = export(example_1a, tmp_path / "robot.urdf")
    root = ET.parse(path).getroot()
    assert root.tag == "robot"
    mujoco = root.findall("mujoco")
    assert len(mujoco) == 1
    compilers = mujoco[0].findall("compiler")
    assert [c.attrib for c in compilers] == [{"strippath": "false"}]
    robot = load(path)
    assert len(robot.robot.links) == len(root.findall("link"))


def test_inertia_is_a_paper_shell(tmp_path, example_1a):
    robot = load(export(example_1a, tmp_path / "e.urdf", mass_per_area=0.1))
    total_area = 0.0
    total_mass = 0.0
    for link in robot.link_map.values():
        area = sum(
            trimesh.load(tmp_path / v.geometry.mesh.filename, file_type="stl").area
            for v in link.visuals
        )
        total_area += area
        total_mass += link.inertial.mass
        assert link.inertial.mass == pytest.approx(0.1 * area, rel=1e-6)
        eig = np.linalg.eigvalsh(link.inertial.inertia)
        assert eig.min() > 0.0
        assert eig[0] + eig[1] >= eig[2] * (1 - 1e-9)  # triangle inequality of inertia
    assert total_mass == pytest.approx(0.1 * total_area, rel=1e-6)
    no_inertia = load(export(example_1a, tmp_path / "n.urdf", mass_per_area=0, meshes=False))
    assert all(link.inertial is None for link in no_inertia.link_map.values())


def test_without_meshes_one_file(tmp_path, example_1a):
    export(example_1a, tmp_path / "k.urdf", meshes=False)
    assert listing(tmp_path) == ["k.urdf"]
    robot = load(tmp_path / "k.urdf")
    assert all(not link.visuals and not link.collisions for link in robot.link_map.values())


def test_write_urdf_to_a_stream(example_1a):
    stream = io.StringIO()
    write_urdf(example_1a, stream, name="arm")
    robot = yourdfpy.URDF.load(io.BytesIO(stream.getvalue().encode("utf-8")))
    assert robot.robot.name == "arm" and robot.validate()
    assert "<mesh" not in stream.getvalue()


def test_model_in_memory(example_1a):
    model = urdf_model(example_1a, name="arm", mesh_folder="parts")
    assert set(model.files) == {
        f"parts/{p.name}.stl" for p in chain_parts(example_1a, split_joints=True)
    }
    assert 'filename="parts/joint_0.stl"' in model.text


# --- bad input and failures ------------------------------------------------------------------


def test_pattern_is_rejected(tmp_path, example_1a):
    with pytest.raises(InvalidTypeError, match="KinematicChain"):
        export(example_1a.creasePattern(), tmp_path / "p.urdf")
    with pytest.raises(InvalidTypeError, match="KinematicChain"):
        urdf_model(example_1a.Joints[0])
    assert listing(tmp_path) == []


@pytest.mark.parametrize(
    ("options", "error"),
    [
        ({"effort": 0}, InvalidParameterError),
        ({"velocity": -1.0}, InvalidParameterError),
        ({"units": "ft"}, InvalidParameterError),
        ({"mass_per_area": -0.1}, InvalidParameterError),
        ({"meshes": "yes"}, InvalidTypeError),
        ({"name": ""}, InvalidParameterError),
        ({"mesh_folder": "../out"}, InvalidParameterError),
        ({"colour": "red"}, InvalidTypeError),
    ],
)
def test_bad_options_write_nothing(tmp_path, example_1a, options, error):
    with pytest.raises(error):
        export(example_1a, tmp_path / "bad.urdf", **options)
    assert listing(tmp_path) == []


def test_folder_that_is_a_file(tmp_path, example_1a):
    (tmp_path / "file").write_text("x")
    with pytest.raises(ExportError):
        export(example_1a, tmp_path / "file" / "robot.urdf")
    assert listing(tmp_path) == ["file"]


def test_mesh_folder_name_taken_by_a_file(tmp_path, example_1a):
    (tmp_path / "robot_meshes").write_text("x")
    with pytest.raises(ExportError, match="robot_meshes"):
        export(example_1a, tmp_path / "robot.urdf")
    assert listing(tmp_path) == ["robot_meshes"]


def test_failure_at_the_last_step_restores_everything(tmp_path, example_1a, monkeypatch):
    """The URDF is moved into place last; if that fails, the old URDF and meshes come back."""
    first = export(example_1a, tmp_path / "robot.urdf", name="old")
    (tmp_path / "robot_meshes" / "mine.txt").write_text("kept on failure")
    before = {p: (tmp_path / p).read_bytes() for p in listing(tmp_path) if (tmp_path / p).is_file()}
    real_replace = os.replace

    def failing(src, dst):
        if os.fspath(dst) == os.fspath(first):
            raise OSError(28, "No space left on device")
        return real_replace(src, dst)

    monkeypatch.setattr(os, "replace", failing)
    with pytest.raises(ExportError, match="No space left"):
        export(example_1a, first, name="new")
    after = {p: (tmp_path / p).read_bytes() for p in listing(tmp_path) if (tmp_path / p).is_file()}
    assert after == before


def test_export_replaces_the_mesh_folder(tmp_path, example_1a):
    export(example_1a, tmp_path / "robot.urdf")
    (tmp_path / "robot_meshes" / "stale.stl").write_bytes(b"old")
    export(mixed_chain(), tmp_path / "robot.urdf")
    files = listing(tmp_path / "robot_meshes")
    assert "stale.stl" not in files
    assert sorted(listing(tmp_path)) == sorted(["robot.urdf", "robot_meshes"] +
                                               [f"robot_meshes/{f}" for f in files])  # fmt: skip


def test_exporter_failure_leaves_nothing(tmp_path, example_1a, monkeypatch):
    from kinegami.export import urdf

    def broken(*args, **kwargs):
        raise MemoryError("out of memory while meshing")

    monkeypatch.setattr(urdf, "stl_bytes", broken)
    with pytest.raises(MemoryError):
        export(example_1a, tmp_path / "robot.urdf")
    assert listing(tmp_path) == []


def test_joint_angles_of_the_limits_are_reachable(tmp_path):
    """A revolute joint at its limit turns downstream parts by exactly that angle."""
    chain = KinematicChain(StartTip(4, 1, SE3(), 1.5))
    chain.append(RevoluteJoint(4, 1, math.pi, SE3.Trans(0, 0, 4) * SE3.Rx(math.pi / 2)),
                 safe=False, fixedPosition=True, fixedOrientation=True)  # fmt: skip
    robot = load(export(chain, tmp_path / "r.urdf", meshes=False))
    assert fk_error(robot, chain, [[0.0, -math.pi / 2], [0.0, math.pi / 2]]) <= FK_TOL
