"""geometry.screws: one vectorised product of exponentials equals what setJointStates does to
every joint of every gallery design (chains and trees), to 1e-12 r."""

from __future__ import annotations

import copy
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinegami.chain.joints import PrismaticJoint, RevoluteJoint
from kinegami.design import load_design
from kinegami.geometry import screws
from kinegami.geometry.frames import rotation_about_line, translation

GALLERY = sorted((Path(__file__).resolve().parents[2] / "examples" / "designs").glob("*.json"))


def compiled(design):
    """(kinds, axes, points, parents, q_ref) of a chain or tree at its current states."""
    joints = design.Joints
    kinds = np.array([screws.REVOLUTE if isinstance(j, RevoluteJoint) else
                      screws.PRISMATIC if isinstance(j, PrismaticJoint) else screws.FIXED
                      for j in joints])  # fmt: skip
    poses = np.array([np.asarray(j.pose_matrix, dtype=float) for j in joints])
    parents = np.array(getattr(design, "Parents", None) or [j - 1 for j in range(len(joints))])
    q_ref = np.array([j.state for j in joints], dtype=float)
    return kinds, poses[:, :3, 2], poses[:, :3, 3], parents, q_ref


def random_states(design, rng, count):
    ranges = np.array([j.stateRange() for j in design.Joints], dtype=float)
    return ranges[:, 0] + (ranges[:, 1] - ranges[:, 0]) * rng.random((count, len(ranges)))


@pytest.mark.parametrize("path", GALLERY, ids=lambda p: p.stem)
def test_forward_kinematics_is_what_set_joint_states_does(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        design = load_design(path)
    kinds, axes, points, parents, q_ref = compiled(design)
    rng = np.random.default_rng(7)
    Q = random_states(design, rng, 4)
    A = screws.forward_kinematics(kinds, axes, points, parents, Q, q_ref)
    assert A.shape == (4, len(kinds), 4, 4)
    distal0 = np.array([j.distal_dubins_frame() for j in design.Joints])
    pose0 = np.array([j.pose_matrix for j in design.Joints], dtype=float)
    r = design.r
    for q, A_q in zip(Q, A, strict=True):
        moved = copy.deepcopy(design)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            assert moved.setJointStates(list(q)) is not False
        distal = np.array([j.distal_dubins_frame() for j in moved.Joints])
        pose = np.array([j.pose_matrix for j in moved.Joints], dtype=float)
        assert np.abs(A_q @ distal0 - distal).max() <= 1e-12 * r
        upstream = np.array([A_q[p] if p >= 0 else np.eye(4) for p in parents])
        assert np.abs(upstream @ pose0 - pose).max() <= 1e-12 * r
        # the axes at q are the moved joints' own
        directions, on_axes = screws.world_axes(kinds, axes, points, parents, A_q)
        assert np.abs(directions - pose[:, :3, 2]).max() <= 1e-12
        assert np.abs(on_axes - pose[:, :3, 3]).max() <= 1e-12 * r
    one = screws.forward_kinematics(kinds, axes, points, parents, Q[0], q_ref)
    np.testing.assert_array_equal(one, A[0])


@settings(max_examples=60, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), size=st.integers(1, 6))
def test_each_motion_is_the_joint_kinds_transform(seed, size):
    rng = np.random.default_rng(seed)
    kinds = rng.integers(0, 3, size)
    axes = rng.normal(size=(size, 3))
    axes /= np.linalg.norm(axes, axis=1)[:, None]
    points = rng.normal(size=(size, 3)) * 10
    d = rng.uniform(-4, 4, (3, size))
    G = screws.screw_motions(kinds, axes, points, d)
    for k in range(3):
        for j in range(size):
            expected = (rotation_about_line(axes[j], points[j], d[k, j]) if kinds[j] == 1 else
                        translation(d[k, j] * axes[j]) if kinds[j] == 2 else np.eye(4))  # fmt: skip
            np.testing.assert_allclose(G[k, j], expected, atol=1e-12)
    # a chain's products are running products, a tree's follow the parents
    parents = np.array([-1] + [int(rng.integers(0, j)) for j in range(1, size)])
    A = screws.path_products(G, parents)
    for j in range(size):
        path, p = [], j
        while p >= 0:
            path.append(p)
            p = int(parents[p])
        expected = np.eye(4)
        for p in reversed(path):
            expected = expected @ G[:, p]
        np.testing.assert_allclose(A[:, j], expected, atol=1e-12)


def test_bad_configurations_are_refused():
    with pytest.raises(ValueError, match=r"shape \(2,\) or \(K, 2\)"):
        screws.forward_kinematics([1, 2], np.eye(3)[:2], np.zeros((2, 3)), [-1, 0],
                                  np.zeros(3), np.zeros(2))  # fmt: skip


def sequential_configuration(design, values):
    """What setJointStates did before it used the screws: every joint's motion computed from
    the joint already moved by its parent's, composed along the path (the reference)."""
    joints, links = list(design.Joints), list(design.Links)
    parents = list(getattr(design, "Parents", None) or range(-1, len(joints) - 1))
    beyond = [None] * len(joints)
    for k, p in enumerate(parents):
        moved = beyond[p] if p >= 0 else None
        if moved is not None:
            joints[k] = joints[k].transformed(moved)
            links[k] = links[k].transformed(moved)
        if values[k] != joints[k].state:
            G = joints[k].state_transform(values[k] - joints[k].state)
            joints[k] = joints[k].with_state(values[k])
            moved = G if moved is None else G @ moved
        beyond[k] = moved
    return joints, links


@pytest.mark.parametrize("path", GALLERY, ids=lambda p: p.stem)
def test_set_joint_states_moves_everything_as_before_to_1e12_r(path):
    """States through the one forward kinematics equal the joint-by-joint composition they
    replaced: poses, distal frames, link frames and the deepest overlap, to 1e-12 r."""
    from kinegami.chain.bodies import worst_overlap
    from kinegami.clearance.tree_bodies import tree_worst_overlap

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        design = load_design(path)
    r = design.r
    parents = list(design.Parents)
    for q in random_states(design, np.random.default_rng(11), 3):
        expected_joints, expected_links = sequential_configuration(design, list(q))
        joints, links = design._configured(list(q))
        for a, b in zip(joints, expected_joints, strict=True):
            assert np.abs(a.pose_matrix - b.pose_matrix).max() <= 1e-12 * r
            assert np.abs(a.distal_frame() - b.distal_frame()).max() <= 1e-12 * r
            assert a.state == b.state
        for a, b in zip(links[1:], expected_links[1:], strict=True):
            assert np.abs(a.start_frame - b.start_frame).max() <= 1e-12 * r
            assert np.abs(a.end_frame - b.end_frame).max() <= 1e-12 * r
        if parents == list(range(-1, len(joints) - 1)):
            now = worst_overlap(joints, links, r, margin=1e9 * r)
            before = worst_overlap(expected_joints, expected_links, r, margin=1e9 * r)
        else:
            now = tree_worst_overlap(joints, links, parents, r, margin=1e9 * r)
            before = tree_worst_overlap(expected_joints, expected_links, parents, r,
                                        margin=1e9 * r)  # fmt: skip
        assert (now is None) == (before is None)
        if now is not None:
            assert abs(now.clearance - before.clearance) <= 1e-12 * r
