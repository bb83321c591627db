"""Every reader takes our URDFs the same way (issue 31 §5): on every gallery chain, the tip
that yourdfpy's forward kinematics carries and, when it is installed, the one Robotics
Toolbox for Python's carries equal ``kinematics(design).fkine(q)`` to 1e-9 (metres, one chain
unit a metre) at random configurations. RTB 1.5 read the old files, whose axes were written
in world coordinates, as a rotation of the joint frame (its issues #253, #441): the PUMA's tip
landed 1.7 m off. RTB is a benchmark-only extra (``.[bench]``), so its half skips without it;
PyBullet (a simulator users load URDFs into, not a dependency) likewise, and it computes in single
precision, so it agrees to 1e-6 of the chain's size."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
import yourdfpy
from gallery_designs import CHAIN_DESIGNS

from kinegami.design import load_design
from kinegami.export.registry import export
from kinegami.export.urdf import chain_bodies
from kinegami.reach import kinematics

TOLERANCE = 1e-9


def _tips(design, body_frames, configurations) -> tuple[np.ndarray, np.ndarray]:
    """(the tips a reader carries, the design's fkine tips) at ``configurations``: the reader's
    last body frame times the tip's place in that body (constant: measured at q = 0)."""
    compiled = kinematics(design)
    bodies = chain_bodies(design)
    zero = np.zeros(compiled.n)
    last = bodies.count - 1
    offset = np.linalg.inv(body_frames(zero, last)) @ compiled.fkine(zero)
    carried = np.array([body_frames(q, last) @ offset for q in configurations])
    return carried, compiled.fkine(np.array(configurations))


def _configurations(design, count: int = 8) -> list[np.ndarray]:
    compiled = kinematics(design)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    rng = np.random.default_rng(5)
    return [low + (high - low) * rng.random(low.size) for _ in range(count)]


@pytest.mark.parametrize("path", CHAIN_DESIGNS, ids=lambda p: p.stem)
def test_yourdfpy_carries_the_tip_of_fkine(path, tmp_path):
    design = load_design(path)
    urdf = export(design, tmp_path / f"{path.stem}.urdf", meshes=False, units="m")
    robot = yourdfpy.URDF.load(str(urdf))
    movable = chain_bodies(design).movable

    def frames(q, body):
        robot.update_cfg(np.asarray(q)[list(movable)])
        return robot.get_transform(f"body_{body}")

    carried, tips = _tips(design, frames, _configurations(design))
    assert np.abs(carried - tips).max() <= TOLERANCE


@pytest.mark.parametrize("path", CHAIN_DESIGNS, ids=lambda p: p.stem)
def test_robotics_toolbox_carries_the_tip_of_fkine(path, tmp_path):
    rtb = pytest.importorskip("roboticstoolbox", reason="Robotics Toolbox is the .[bench] "
                              "extra, not installed here")  # fmt: skip
    design = load_design(path)
    urdf = export(design, tmp_path / f"{path.stem}.urdf", meshes=False, units="m")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", DeprecationWarning)
        robot = rtb.Robot.URDF(str(urdf))
    movable = list(chain_bodies(design).movable)
    assert robot.n == len(movable)

    def frames(q, body):
        return robot.fkine(np.asarray(q)[movable], end=f"body_{body}").A

    carried, tips = _tips(design, frames, _configurations(design))
    assert np.abs(carried - tips).max() <= TOLERANCE


@pytest.mark.parametrize("path", CHAIN_DESIGNS, ids=lambda p: p.stem)
def test_pybullet_carries_the_tip_of_fkine(path, tmp_path):
    pybullet = pytest.importorskip("pybullet", reason="PyBullet is not installed here (a "
                                   "simulator, not a dependency)")  # fmt: skip
    design = load_design(path)
    urdf = export(design, tmp_path / f"{path.stem}.urdf", meshes=False, units="m")
    client = pybullet.connect(pybullet.DIRECT)
    try:
        robot = pybullet.loadURDF(str(urdf), useFixedBase=True, physicsClientId=client,
                                  flags=pybullet.URDF_USE_INERTIA_FROM_FILE)  # fmt: skip
        joints = {}  # child link name -> joint index (PyBullet's link index)
        for j in range(pybullet.getNumJoints(robot, physicsClientId=client)):
            info = pybullet.getJointInfo(robot, j, physicsClientId=client)
            joints[info[12].decode()] = (j, info[2])
        movable = list(chain_bodies(design).movable)
        driven = [j for j, kind in sorted(joints.values())
                  if kind in (pybullet.JOINT_REVOLUTE, pybullet.JOINT_PRISMATIC)]  # fmt: skip
        assert len(driven) == len(movable)

        def frames(q, body):
            for j, value in zip(driven, np.asarray(q)[movable], strict=True):
                pybullet.resetJointState(robot, j, float(value), physicsClientId=client)
            state = pybullet.getLinkState(robot, joints[f"body_{body}"][0],
                                          computeForwardKinematics=True,
                                          physicsClientId=client)  # fmt: skip
            T = np.eye(4)
            T[:3, :3] = np.reshape(pybullet.getMatrixFromQuaternion(state[5]), (3, 3))
            T[:3, 3] = state[4]
            return T

        carried, tips = _tips(design, frames, _configurations(design))
    finally:
        pybullet.disconnect(client)
    # PyBullet's wheels compute in single precision (rotations agree to about 1e-7): the same
    # tip to 1e-6 of the chain's size, where a misread axis would be off by the size itself
    size = max(1.0, float(np.abs(tips[:, :3, 3]).max()))
    assert np.abs(carried[:, :3, :3] - tips[:, :3, :3]).max() <= 1e-6
    assert np.abs(carried[:, :3, 3] - tips[:, :3, 3]).max() <= 1e-6 * size
