"""URDF of a KinematicTree: one kinematic tree that yourdfpy validates, whose forward kinematics
is the tree's at every state (the paper's hand and random safe trees)."""

from __future__ import annotations

import copy
import math
import warnings
import xml.etree.ElementTree as ET
from pathlib import Path

import numpy as np
import pytest
import trimesh
import yourdfpy
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from scipy.spatial.transform import Rotation

from kinegami import (
    SE3,
    EndTip,
    KinematicChain,
    KinematicTree,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)
from kinegami.clearance.solids import chain_parts
from kinegami.export.registry import export
from kinegami.export.urdf import chain_bodies, urdf_files

from .test_urdf import FK_TOL, in_metres, set_configuration

try:  # tests/ is not a package: reachable as tests.tree from the checkout, else as tree
    from tests.tree.helpers import hand_tree
except ImportError:  # pragma: no cover
    from tree.helpers import hand_tree

EXACT = {"relative": False, "safe": False, "fixedPosition": True, "fixedOrientation": True}


@pytest.fixture(scope="module")
def hand() -> KinematicTree:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the paper's hand touches its palm (tests/tree)
        return hand_tree()


def load(path) -> yourdfpy.URDF:
    robot = yourdfpy.URDF.load(str(path))
    assert robot.validate(), robot.errors  # the strict handler: any error fails
    return robot


def movable(tree) -> list[int]:
    return [k for k, j in enumerate(tree.Joints) if isinstance(j, RevoluteJoint | PrismaticJoint)]


def bodies_of(tree) -> tuple[list[int], list[int]]:
    """Body of every joint's Pose (its parent's distal body) and of its distal side: the b-th
    revolute or prismatic joint, in index order, starts body b."""
    starts = {k: b for b, k in enumerate(movable(tree), start=1)}
    proximal, distal = [], []
    for k, p in enumerate(tree.Parents):
        proximal.append(distal[p] if p >= 0 else 0)
        distal.append(starts.get(k, proximal[k]))
    return proximal, distal


def urdf_config(tree, states, metres: float) -> dict[str, float]:
    return {
        f"joint_{k}": states[k] * (metres if isinstance(tree.Joints[k], PrismaticJoint) else 1.0)
        for k in movable(tree)
    }


def configured(tree0, states):
    tree = copy.deepcopy(tree0)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # a random configuration may pass through itself
        assert tree.setJointStates(states)
    return tree


def fk_error(robot, tree0, configurations, metres: float = 1e-3) -> float:
    """Largest difference between the tree's joint Poses and distal frames after
    ``setJointStates(q)`` and those carried by yourdfpy's forward kinematics at q (metres and
    rotation-matrix entries). ``tree0`` has all states 0."""
    proximal, distal = bodies_of(tree0)
    set_configuration(robot, urdf_config(tree0, [0.0] * len(tree0.Joints), metres))
    body = {b: robot.get_transform(f"body_{b}") for b in set(distal)}
    rel_pose = [np.linalg.inv(body[proximal[k]]) @ in_metres(j.pose_matrix, metres)
                for k, j in enumerate(tree0.Joints)]  # fmt: skip
    rel_distal = [np.linalg.inv(body[distal[k]]) @ in_metres(j.distal_frame(), metres)
                  for k, j in enumerate(tree0.Joints)]  # fmt: skip
    worst = 0.0
    for states in configurations:
        tree = configured(tree0, states)
        set_configuration(robot, urdf_config(tree, states, metres))
        for k, joint in enumerate(tree.Joints):
            pose = robot.get_transform(f"body_{proximal[k]}") @ rel_pose[k]
            dist = robot.get_transform(f"body_{distal[k]}") @ rel_distal[k]
            worst = max(
                worst,
                float(np.abs(pose - in_metres(joint.pose_matrix, metres)).max()),
                float(np.abs(dist - in_metres(joint.distal_frame(), metres)).max()),
            )
    return worst


def random_configurations(tree, count: int, seed: int = 0) -> list[list[float]]:
    rng = np.random.default_rng(seed)
    return [[rng.uniform(*j.stateRange()) for j in tree.Joints] for _ in range(count)]


# --- the paper's hand ------------------------------------------------------------------------


def test_hand_is_one_kinematic_tree(tmp_path, hand):
    robot = load(export(hand, tmp_path / "hand.urdf"))
    assert robot.robot.name == "hand"
    assert list(robot.link_map) == [f"body_{b}" for b in range(9)]
    assert robot.base_link == "body_0"
    joints = [(j.name, j.type, j.parent, j.child) for j in robot.robot.joints]
    assert joints == [
        ("joint_1", "revolute", "body_0", "body_1"), ("joint_2", "revolute", "body_1", "body_2"),
        ("joint_3", "revolute", "body_2", "body_3"), ("joint_5", "revolute", "body_0", "body_4"),
        ("joint_6", "revolute", "body_4", "body_5"), ("joint_8", "revolute", "body_0", "body_6"),
        ("joint_9", "revolute", "body_6", "body_7"), ("joint_10", "revolute", "body_7", "body_8"),
    ]  # fmt: skip
    # the three fingers are sibling branches of the palm: joints 1, 5 and 8 on body_0
    children = [j.child for j in robot.robot.joints if j.parent == "body_0"]
    assert children == ["body_1", "body_4", "body_6"]


def test_hand_forward_kinematics(tmp_path, hand):
    robot = load(export(hand, tmp_path / "hand.urdf"))
    configurations = random_configurations(hand, 25)
    configurations += [[lo for lo, _ in (j.stateRange() for j in hand.Joints)]]
    configurations += [[hi for _, hi in (j.stateRange() for j in hand.Joints)]]
    assert fk_error(robot, hand, configurations) <= FK_TOL


def test_hand_limits_are_the_state_ranges(tmp_path, hand):
    robot = load(export(hand, tmp_path / "hand.urdf", effort=0.5, velocity=2.0))
    for k in movable(hand):
        limit = robot.joint_map[f"joint_{k}"].limit
        assert (limit.lower, limit.upper) == hand.Joints[k].stateRange()
        assert (limit.effort, limit.velocity) == (0.5, 2.0)
        assert list(robot.joint_map[f"joint_{k}"].axis) == [0.0, 0.0, 1.0]  # the joint's z


def test_hand_keeps_the_mujoco_compiler_element(tmp_path, hand):
    path = export(hand, tmp_path / "hand.urdf")
    root = ET.parse(path).getroot()
    assert [c.attrib for m in root.findall("mujoco") for c in m.findall("compiler")] == [
        {"strippath": "false"}
    ]
    assert "<!-- kinegami tree: 12 joints (3 leaves), 8 movable;" in path.read_text()


def test_hand_meshes_sit_where_the_tree_is(tmp_path, hand):
    """Every mesh file, moved by its body's forward kinematics at q, is the tree's part at q."""
    path = export(hand, tmp_path / "hand.urdf")
    robot = load(path)
    files = sorted(p.name for p in (tmp_path / "hand_meshes").iterdir())
    parts0 = chain_parts(hand, split_joints=True)
    assert files == sorted(f"{p.name}.stl" for p in parts0)
    # every joint with a body and every link with a tube has its parts
    assert {p.index for p in parts0 if p.is_joint} == {
        k for k, j in enumerate(hand.Joints) if not isinstance(j, Waypoint)
    }
    assert {p.index for p in parts0 if not p.is_joint} == set(range(1, len(hand.Joints)))
    meshes = {}
    for states in random_configurations(hand, 2, seed=3):
        tree = configured(hand, states)
        parts = {p.name: p for p in chain_parts(tree, split_joints=True)}
        set_configuration(robot, urdf_config(tree, states, 1e-3))
        for link_name, link in robot.link_map.items():
            T = robot.get_transform(link_name)
            for visual in link.visuals:
                name = visual.geometry.mesh.filename
                if name not in meshes:
                    meshes[name] = trimesh.load(tmp_path / name, file_type="stl")
                    assert meshes[name].is_watertight and meshes[name].is_volume, name
                moved = meshes[name].vertices @ T[:3, :3].T + T[:3, 3]
                expected = parts[visual.name].vertices * 1e-3
                d = np.linalg.norm(moved[:, None] - expected[None], axis=2)
                assert d.min(axis=1).max() < 1e-8 and d.min(axis=0).max() < 1e-8, visual.name
    assert len(meshes) == len(files)


def test_hand_exported_at_any_state_gives_the_same_robot(tmp_path, hand):
    moved = configured(hand, random_configurations(hand, 1, seed=7)[0])
    robot = load(export(moved, tmp_path / "moved.urdf", meshes=False))
    assert fk_error(robot, hand, random_configurations(hand, 10, seed=2)) <= FK_TOL


def test_hand_bodies(hand):
    bodies = chain_bodies(hand)
    assert bodies.movable == (1, 2, 3, 5, 6, 8, 9, 10)
    assert (list(bodies.proximal_body), list(bodies.distal_body)) == tuple(
        list(x) for x in bodies_of(hand)
    )


# --- structure -------------------------------------------------------------------------------


def test_rigid_tree_has_fixed_joints_to_the_parents(tmp_path):
    """Without movable joints every tree joint is a link, fixed to its parent's link."""
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    tree.addJoint(0, EndTip(4, 1, SE3.Trans(4, 0, 6), 1.5), **EXACT)
    tree.addJoint(0, Waypoint(4, 1, SE3.Trans(-4, 0, 6)), **EXACT)
    tree.addJoint(2, EndTip(4, 1, SE3.Trans(-4, 0, 10), 1.5), **EXACT)
    assert tree.Parents == (-1, 0, 0, 2)
    robot = load(export(tree, tmp_path / "rigid.urdf"))
    assert robot.num_actuated_joints == 0
    assert [(j.name, j.type, j.parent, j.child) for j in robot.robot.joints] == [
        ("joint_1", "fixed", "body_0", "body_1"), ("joint_2", "fixed", "body_0", "body_2"),
        ("joint_3", "fixed", "body_2", "body_3"),
    ]  # fmt: skip
    for k, joint in enumerate(tree.Joints):
        T = robot.get_transform(f"body_{k}", "body_0")
        np.testing.assert_allclose(T[:3, 3], joint.pose_matrix[:3, 3] * 1e-3, atol=1e-15)
        np.testing.assert_allclose(T[:3, :3], np.eye(3), atol=0)


def test_a_tree_that_is_a_chain_gives_the_chain_file(example_1a):
    """The same joints added to a chain and as a tree whose parents are i - 1: the same files,
    byte for byte."""
    chain = KinematicChain(example_1a.Joints[0])
    tree = KinematicTree(example_1a.Joints[0])
    for k, joint in enumerate(example_1a.Joints[1:], start=1):
        chain.append(joint, **EXACT)
        tree.addJoint(k - 1, joint, **EXACT)
    path = Path("robot.urdf")
    assert urdf_files(tree, path) == urdf_files(chain, path)


# --- random safe trees -----------------------------------------------------------------------

quaternions = st.tuples(*[st.floats(-1, 1)] * 4).filter(lambda q: math.hypot(*q) > 0.1)
translations = st.tuples(*[st.floats(-4, 4)] * 3)


@st.composite
def random_trees(draw, max_joints: int = 5):
    """A root (StartTip or Waypoint) and revolute / prismatic / waypoint joints with random
    poses, each added safely to a random earlier joint (relative to its pose); maybe EndTips.
    r in [0.5, 3], n in {4, 6}."""
    r = draw(st.floats(0.5, 3))
    n = draw(st.sampled_from([4, 6]))
    root = StartTip(n, r, SE3(), 1.5 * r) if draw(st.booleans()) else Waypoint(n, r, SE3())
    tree = KinematicTree(root)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for _ in range(draw(st.integers(2, max_joints))):
            parents = [k for k, j in enumerate(tree.Joints) if not isinstance(j, EndTip)]
            parent = draw(st.sampled_from(parents))
            T = np.eye(4)
            T[:3, :3] = Rotation.from_quat(draw(quaternions)).as_matrix()
            T[:3, 3] = np.array(draw(translations)) * r
            kind = draw(st.sampled_from("RRPWE"))
            if kind == "R":
                joint = RevoluteJoint(n, r, draw(st.floats(0.5, 3.0)), T)
            elif kind == "P":
                joint = PrismaticJoint(n, r, 2 * r, 2, draw(st.floats(math.pi / 6, 1.4)), T)
            elif kind == "W":
                joint = Waypoint(n, r, T)
            else:
                joint = EndTip(n, r, T, 1.5 * r)
            tree.addJoint(parent, joint)  # None (unchanged) when no link reaches it
    return tree


@settings(deadline=None, max_examples=20, suppress_health_check=[HealthCheck.too_slow])
@given(tree=random_trees(), seed=st.integers(0, 2**16))
def test_random_trees_forward_kinematics(tmp_path_factory, tree, seed):
    folder = tmp_path_factory.mktemp("random")
    exported = configured(tree, random_configurations(tree, 1, seed=seed + 1)[0])
    robot = load(export(exported, folder / "t.urdf", meshes=False))
    proximal, distal = bodies_of(tree)
    assert [j.parent for j in robot.robot.joints if j.type != "fixed"] == [
        f"body_{proximal[k]}" for k in movable(tree)
    ]
    configurations = random_configurations(tree, 3, seed=seed)
    assert fk_error(robot, tree, configurations) <= FK_TOL * max(1.0, tree.r)


def test_the_folded_tree_with_takeoffs_is_a_valid_robot(tmp_path, hand):
    """kinegami build --junctions takeoff writes the URDF of the tree as folded: the take-off
    branches leave their trunk's face (each trunk link cut there by a fixed waypoint)."""
    from kinegami.fabrication.sheets import fabricate

    folded = fabricate(hand, junction="takeoff").folded_tree()
    assert len(folded.Joints) > len(hand.Joints)
    robot = load(export(folded, tmp_path / "folded.urdf"))
    assert fk_error(robot, folded, random_configurations(folded, 3, seed=5)) < 1e-9
    # the same joints move as in the tree
    assert len(movable(folded)) == len(movable(hand))
