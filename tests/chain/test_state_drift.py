"""Many state changes leave no trace: every configuration is one motion from the design's home
lists (the states the last edit left), so after thousands of ``setJointStates`` and
``setJointState`` calls each frame is still the forward kinematics of its states, to rounding.
Composing each change onto the last one let rounding build up and feed back through the screws
compiled from drifted frames: 300 random configurations had moved the 9-joint spherical
series' tip by 0.1 r, and 1,000 made it NaN."""

from __future__ import annotations

import warnings

import numpy as np
import pytest
from gallery_designs import DESIGN_DIR, TREE_DESIGNS
from hypothesis import given, settings
from hypothesis import strategies as st

from kinegami.design import load_design
from kinegami.reach import kinematics

RANDOM_CONFIGURATIONS = 600


def _frames(design) -> np.ndarray:
    return np.array([np.asarray(j.distal_dubins_frame(), dtype=float) for j in design.Joints])


@pytest.mark.parametrize("name", ["spherical_series", "puma"])
def test_many_configurations_do_not_drift(name):
    design = load_design(DESIGN_DIR / f"{name}.json")
    design.requireClearance = False
    home = _frames(design)
    compiled = kinematics(design)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    rng = np.random.default_rng(1)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # many of them pass through themselves
        for k in range(RANDOM_CONFIGURATIONS):
            q = low + (high - low) * rng.random(low.size)
            if k % 3 == 2:  # one joint at a time, too
                j = int(rng.integers(low.size))
                assert design.setJointState(j, float(q[j]))
            else:
                assert design.setJointStates(list(q))
    states = np.array([joint.state for joint in design.Joints])
    tip = np.asarray(design.Joints[-1].distal_dubins_frame(), dtype=float)
    assert np.abs(tip - compiled.fkine(states)).max() <= 1e-12 * design.r
    R = tip[:3, :3]
    assert np.abs(R.T @ R - np.eye(3)).max() <= 1e-14
    # back at the home states: the home frames again, to rounding
    assert design.setJointStates(list(compiled.q_ref))
    assert np.abs(_frames(design) - home).max() <= 1e-12 * design.r


def test_a_tree_does_not_drift():
    path = next(p for p in TREE_DESIGNS if p.stem == "hand")
    hand = load_design(path)
    hand.requireClearance = False
    compiled = kinematics(hand)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    rng = np.random.default_rng(2)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for _ in range(300):
            assert hand.setJointStates(list(low + (high - low) * rng.random(low.size)))
    states = np.array([joint.state for joint in hand.Joints])
    tips = np.array([np.asarray(hand.Joints[t].distal_dubins_frame()) for t in compiled.tips])
    assert np.abs(tips - compiled.fkine(states)).max() <= 1e-12 * hand.r


@settings(max_examples=20, deadline=None)
@given(st.lists(st.tuples(st.integers(0, 6), st.floats(0.0, 1.0)), min_size=1, max_size=40))
def test_an_edit_between_state_changes_becomes_home(moves):
    """State changes, then an edit (a new home), then state changes: each frame is the forward
    kinematics of the design the edit left, whatever came before."""
    design = load_design(DESIGN_DIR / "puma.json")
    design.requireClearance = False
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for n, (j, u) in enumerate(moves):
            joint = design.Joints[j]
            lo, hi = joint.stateRange()
            design.setJointState(j, lo + (hi - lo) * u)
            if n == len(moves) // 2:
                design.translateJointAlongAxisOfMotion(3, 0.1 * design.r)
                compiled = kinematics(design)  # the edited design, at its states then
    states = np.array([joint.state for joint in design.Joints])
    tip = np.asarray(design.Joints[-1].distal_dubins_frame(), dtype=float)
    assert np.abs(tip - compiled.fkine(states)).max() <= 1e-11 * design.r
