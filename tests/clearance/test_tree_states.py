"""setJointStates of a tree asks the tree's clearance engine (kept across state changes) for
the deepest overlap at the new states: the same verdict as the brute-force tree overlap of the
configured joints and links, the same depth to rounding, and the pair its clearance report
names."""

from __future__ import annotations

import copy
import warnings
from pathlib import Path

import numpy as np
import pytest

from kinegami.clearance.tree_bodies import tree_worst_overlap
from kinegami.design import load_design
from kinegami.errors import ClearanceWarning, PlacementWarning

DESIGNS = Path(__file__).parents[2] / "examples" / "designs"


def _random_states(tree, count: int, seed: int) -> list[list[float]]:
    ranges = np.array([joint.stateRange() for joint in tree.Joints])
    rng = np.random.default_rng(seed)
    return [list(ranges[:, 0] + (ranges[:, 1] - ranges[:, 0]) * rng.random(len(ranges)))
            for _ in range(count)]  # fmt: skip


@pytest.mark.parametrize("name", ["algorithmic_hand", "hand", "quadruped", "gripper"])
def test_set_joint_states_warns_as_the_brute_force_overlap(name):
    tree = load_design(DESIGNS / f"{name}.json")
    r = float(tree.r)
    warned = 0
    for states in _random_states(tree, 25, seed=4):
        joints, links = tree._configured(tuple(states))
        expected = tree_worst_overlap(joints, links, tree.Parents, r, margin=tree.margin)
        with warnings.catch_warnings(record=True) as caught:
            warnings.simplefilter("always")
            assert tree.setJointStates(states)
        found = [w.message for w in caught if isinstance(w.message, ClearanceWarning)]
        assert [j.state for j in tree.Joints] == pytest.approx(states, abs=0)
        report = tree.clearance()
        if expected is None:
            assert not found and report.ok
            continue
        warned += 1
        (message,) = found
        assert abs(message.clearance - expected.clearance) <= 1e-9 * r
        assert abs(message.clearance - report.min_clearance) <= 1e-9 * r
        assert (message.first, message.second) == (report.pairs[0].first, report.pairs[0].second)
        assert not report.ok
    assert warned > 0


def test_require_clearance_rejects_and_the_engine_stays_valid():
    """A tree that requires clearance refuses states where it passes through itself and is left
    as it was; the states it accepts after that are judged from the same kept engine."""
    tree = load_design(DESIGNS / "algorithmic_hand.json")
    tree.requireClearance = True
    before = [j.state for j in tree.Joints]
    accepted = rejected = 0
    for states in _random_states(tree, 30, seed=9):
        joints, links = tree._configured(tuple(states))
        expected = tree_worst_overlap(joints, links, tree.Parents, tree.r, margin=tree.margin)
        current = [j.state for j in tree.Joints]
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PlacementWarning)
            ok = tree.setJointStates(states)
        assert ok is (expected is None)
        if ok:
            accepted += 1
            assert tree.clearance().ok
        else:
            rejected += 1
            assert [j.state for j in tree.Joints] == current
    assert accepted and rejected
    fresh = copy.deepcopy(load_design(DESIGNS / "algorithmic_hand.json"))
    assert [j.state for j in fresh.Joints] == before
