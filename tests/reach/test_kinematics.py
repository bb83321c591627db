"""Forward kinematics and Jacobians (kinegami.reach.forward, docs/reach.md): every gallery
design's tips where setJointStates puts them (1e-12 r), Jacobians against central differences
(1e-6), the shapes and conventions of Robotics Toolbox for Python, tips and tools, the chain's
and tree's own ``fkine``/``jacob0``, and clear errors for bad input."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from gallery_designs import CHAIN_DESIGNS, GALLERY, TREE_DESIGNS
from hypothesis import given, settings
from hypothesis import strategies as st
from spatialmath import SE3

from kinegami.design import load_design
from kinegami.errors import InvalidParameterError, InvalidTypeError, KinegamiError
from kinegami.reach import Kinematics, kinematics

_DESIGNS: dict[str, object] = {}


def design(path):
    """A fresh copy of the gallery design (loaded once, then copied by loading again only
    when a test changes it)."""
    return load_design(path)


def random_states(compiled: Kinematics, rng, m: int | None = None) -> np.ndarray:
    lo, hi = compiled.ranges[:, 0], compiled.ranges[:, 1]
    shape = (lo.size,) if m is None else (m, lo.size)
    return lo + (hi - lo) * rng.random(shape)


@pytest.mark.parametrize("path", GALLERY, ids=lambda p: p.stem)
def test_tips_are_where_set_joint_states_puts_them(path):
    built = design(path)
    compiled = kinematics(built)
    rng = np.random.default_rng(31)
    Q = random_states(compiled, rng, 6)
    poses = compiled.fkine(Q)
    poses = poses if len(compiled.tips) > 1 else poses[:, None]
    for q, expected in zip(Q, poses, strict=True):
        moved = load_design(path)
        moved.requireClearance = False
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            assert moved.setJointStates(q.tolist())
        for k, tip in enumerate(compiled.tips):
            found = moved.Joints[tip].distal_dubins_frame()
            assert np.abs(expected[k] - found).max() <= 1e-12 * built.r


@pytest.mark.parametrize("path", GALLERY, ids=lambda p: p.stem)
def test_jacobians_are_the_derivatives_of_the_tips(path):
    """jacob0 against central differences of fkine: v the tip origin's velocity, ω from the
    rotation's derivative (dR Rᵀ), to 1e-6 of the design's scale."""
    compiled = kinematics(design(path))
    rng = np.random.default_rng(7)
    h = 1e-6
    scale = max(1.0, float(np.abs(compiled.tip_frames[:, :3, 3]).max()))
    for q in random_states(compiled, rng, 3):
        J = compiled.jacob0(q)
        T = compiled.fkine(q)
        J, T = (J, T) if len(compiled.tips) > 1 else (J[None], T[None])
        for j in range(compiled.n):
            step = np.zeros(compiled.n)
            step[j] = h
            plus, minus = compiled.fkine(q + step), compiled.fkine(q - step)
            plus, minus = (plus, minus) if len(compiled.tips) > 1 else (plus[None], minus[None])
            for k in range(len(compiled.tips)):
                v = (plus[k][:3, 3] - minus[k][:3, 3]) / (2 * h)
                dR = (plus[k][:3, :3] - minus[k][:3, :3]) / (2 * h) @ T[k][:3, :3].T
                w = np.array([dR[2, 1], dR[0, 2], dR[1, 0]])
                assert np.abs(J[k][:3, j] - v).max() <= 1e-6 * scale
                assert np.abs(J[k][3:, j] - w).max() <= 1e-6


def test_shapes_and_conventions_are_rtb_s():
    puma = design(CHAIN_DESIGNS[[p.stem for p in CHAIN_DESIGNS].index("puma")])
    compiled = kinematics(puma)
    n = len(puma.Joints)
    q = np.array([joint.state for joint in puma.Joints])
    assert compiled.fkine(q).shape == (4, 4)
    assert compiled.fkine(np.stack([q, q, q])).shape == (3, 4, 4)
    assert compiled.jacob0(q).shape == (6, n)
    assert compiled.jacob0(np.stack([q, q])).shape == (2, 6, n)
    # the current states give the last joint's distal frame, unchanged
    assert np.array_equal(compiled.fkine(q), puma.Joints[-1].distal_dubins_frame())
    # columns of tips and waypoints are zero; RTB's joint vector is q[movable]
    fixed = np.flatnonzero(compiled.kinds == 0)
    assert fixed.size and not compiled.jacob0(q)[:, fixed].any()
    assert compiled.movable.tolist() == [k for k in range(n) if k not in fixed]
    # the chain's own words, at its states and at q
    assert np.array_equal(puma.fkine(), compiled.fkine(q))
    assert np.array_equal(puma.jacob0(q.tolist()), compiled.jacob0(q))


def test_a_tree_answers_for_every_leaf_and_a_finger_moves_only_its_own_tip():
    hand = design(TREE_DESIGNS[[p.stem for p in TREE_DESIGNS].index("hand")])
    compiled = kinematics(hand)
    leaves = tuple(k for k in range(len(hand.Joints)) if not hand.Children[k])
    assert compiled.tips == leaves and len(leaves) == 3
    q = np.array([joint.state for joint in hand.Joints])
    assert compiled.fkine(q).shape == (3, 4, 4)
    J = compiled.jacob0(q)
    assert J.shape == (3, 6, len(hand.Joints))
    for k, tip in enumerate(leaves):
        path, j = set(), tip
        while j >= 0:
            path.add(j)
            j = hand.Parents[j]
        off_path = [j for j in range(len(hand.Joints)) if j not in path]
        assert not J[k][:, off_path].any()  # another finger's joints do not move this tip
        assert J[k].any()
    one = kinematics(hand, tip=leaves[1])
    assert np.array_equal(one.fkine(q), compiled.fkine(q)[1])


def test_tip_and_tool():
    puma = design(CHAIN_DESIGNS[[p.stem for p in CHAIN_DESIGNS].index("puma")])
    q = np.array([joint.state for joint in puma.Joints])
    tool = SE3.Trans(0, 0, 50) * SE3.Rx(0.3)
    tooled = kinematics(puma, tool=tool)
    assert np.allclose(tooled.fkine(q), puma.Joints[-1].distal_dubins_frame() @ tool.A,
                       rtol=0, atol=1e-12 * puma.r)  # fmt: skip
    middle = kinematics(puma, tip=3)
    assert np.array_equal(middle.fkine(q), puma.Joints[3].distal_dubins_frame())
    assert puma.fkine(tip=3).shape == (4, 4)


def test_a_changed_design_is_compiled_again():
    puma = design(CHAIN_DESIGNS[[p.stem for p in CHAIN_DESIGNS].index("puma")])
    before = kinematics(puma)
    assert kinematics(puma) is before  # kept while the design is unchanged
    q = random_states(before, np.random.default_rng(2))
    puma.requireClearance = False
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        assert puma.setJointStates(q.tolist())
    after = kinematics(puma)
    assert after is not before and np.array_equal(after.q_ref, q)
    assert np.abs(after.fkine(q) - before.fkine(q)).max() <= 1e-12 * puma.r


@pytest.mark.parametrize("bad, error, words", [
    ([0.0] * 3, InvalidParameterError, "shape (7,) or (m, 7)"),
    (np.zeros((2, 2, 7)), InvalidParameterError, "shape"),
    ([math.nan] * 7, InvalidParameterError, "finite"),
    ("q", InvalidTypeError, "numbers"),
])  # fmt: skip
def test_bad_configurations_are_refused_in_one_line(bad, error, words):
    puma = design(CHAIN_DESIGNS[[p.stem for p in CHAIN_DESIGNS].index("puma")])
    for call in (kinematics(puma).fkine, kinematics(puma).jacob0, puma.fkine):
        with pytest.raises(error, match=words.replace("(", r"\(").replace(")", r"\)")) as raised:
            call(bad)
        assert "\n" not in str(raised.value)


def test_bad_tips_and_designs_are_refused():
    puma = design(CHAIN_DESIGNS[[p.stem for p in CHAIN_DESIGNS].index("puma")])
    with pytest.raises(InvalidParameterError, match="tip 9 is not a joint index: valid 0 to 6"):
        kinematics(puma, tip=9)
    with pytest.raises(InvalidTypeError, match="tip must be joint indices"):
        kinematics(puma, tip=[1.5])
    with pytest.raises(InvalidTypeError, match="KinematicChain or KinematicTree"):
        kinematics("puma")
    with pytest.raises(KinegamiError):
        kinematics(puma, tool=np.ones((4, 4)))


@settings(max_examples=40, deadline=None)
@given(path=st.sampled_from(GALLERY), seed=st.integers(0, 2**32 - 1),
       m=st.integers(1, 40))  # fmt: skip
def test_frame_poses_are_the_body_motions_to_rounding(path, seed, m):
    """geometry.screws.JointScrews.frame_poses (the elementary-transform form fkine runs)
    against body_motions times the frames, on random batches."""
    compiled = kinematics(design(path))
    screws = compiled.screws
    Q = random_states(compiled, np.random.default_rng(seed), m)
    bodies = screws.body_of[list(compiled.tips)]
    expected = screws.body_motions(Q)[:, bodies] @ compiled.tip_frames
    found = screws.frame_poses(Q, bodies, compiled.tip_frames)
    scale = max(1.0, float(np.abs(expected[..., :3, 3]).max()))
    assert np.abs(found - expected).max() <= 1e-13 * scale


@pytest.mark.parametrize("path", GALLERY, ids=lambda p: p.stem)
def test_large_batches_run_compiled_and_agree_with_numpy(path, monkeypatch):
    """fkine of a batch of COMPILED_BATCH or more configurations runs the threaded kernel
    (kinegami.reach.kernels.frame_poses): the same poses as the numpy path to rounding, every
    tip of a tree included; and where numba cannot run, numpy answers the same call."""
    from kinegami.reach import forward

    compiled = kinematics(design(path))
    Q = random_states(compiled, np.random.default_rng(7), forward.COMPILED_BATCH)
    expected = compiled.tip_poses(Q)
    expected = expected[:, 0] if expected.shape[1] == 1 else expected
    calls = []
    kernel = forward._frame_kernel()
    assert kernel is not None  # numba is a core dependency

    def counted(*args):
        calls.append(1)
        return kernel(*args)

    monkeypatch.setattr(forward, "_FRAME_KERNEL", [counted])
    found = compiled.fkine(Q)
    assert calls == [1]
    scale = max(1.0, float(np.abs(expected[..., :3, 3]).max()))
    assert found.shape == expected.shape
    assert np.abs(found - expected).max() <= 1e-13 * scale
    assert np.all(found[..., 3, :] == [0.0, 0.0, 0.0, 1.0])
    monkeypatch.setattr(forward, "_FRAME_KERNEL", [None])
    assert np.array_equal(compiled.fkine(Q), expected)
    assert np.array_equal(compiled.fkine(Q[:5]), expected[:5])  # small batches: numpy
