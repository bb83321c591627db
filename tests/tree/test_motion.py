"""A tree's clearance over its range of motion (kinegami.clearance.sweep and TreeMotion): the
hinges counted along each branch only, sweeps that agree with one-configuration clearance,
free intervals that are clear inside and collide just beyond, and ``kinegami check --motion``
on a tree."""

from __future__ import annotations

import json
import math
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

from kinegami import ClearanceWarning
from kinegami.clearance import SweepReport, TreeMotion, sweep
from kinegami.optimize import compact

from .helpers import quiet_hand

ROOT = Path(__file__).resolve().parents[2]
HAND_DESIGN = ROOT / "examples" / "designs" / "hand.json"


@pytest.fixture(scope="module")
def hand():
    return quiet_hand()


@pytest.fixture(scope="module")
def clear_hand(hand):
    """The paper's hand compacted: clear at its states (the palm no longer touches link 5)."""
    import concurrent.futures

    with concurrent.futures.ThreadPoolExecutor(1) as executor:
        return compact(hand, executor=executor, starts=1, progress=False)


def branch_of(tree, top: int) -> set[int]:
    return set(tree.subtree(top))


def node_of(element: int) -> int:
    """The joint an element belongs to (2 j: joint j; 2 j - 1: the link into joint j)."""
    return (element + 1) // 2


def pairs_within(report, nodes: set[int]) -> dict:
    return {
        (p.first, p.second): round(p.clearance, 9)
        for p in report.pairs
        if node_of(p.elements[0]) in nodes and node_of(p.elements[1]) in nodes
    }


def random_states(tree, rng) -> np.ndarray:
    ranges = np.array([j.stateRange() for j in tree.Joints])
    return ranges[:, 0] + (ranges[:, 1] - ranges[:, 0]) * rng.random(len(ranges))


def test_the_hinges_of_one_branch_do_not_count_on_another(hand):
    # the thumb (joints 1-4) bent by more than pi in all, the pointer's first joint (5) barely:
    # the pointer's own parts must be tested as if the thumb were straight (they were not: the
    # thumb's turning was added to the pointer's, and joint 5's two halves "overlapped by 2")
    states = np.zeros(len(hand.Joints))
    states[[1, 2, 3]] = [-1.172, 1.146, -1.384]
    states[5] = -0.221
    bent = hand.clearance(states)
    for pair in bent.pairs:  # never the two halves of one joint
        assert not (pair.elements[0] == pair.elements[1] and pair.elements[0] % 2 == 0), pair
    straight = states.copy()
    straight[[1, 2, 3]] = 0.0
    pointer = branch_of(hand, 5)
    assert pairs_within(bent, pointer) == pairs_within(hand.clearance(straight), pointer)


@settings(max_examples=15, deadline=None)
@given(seed=st.integers(0, 2**32 - 1), branch=st.sampled_from([1, 5, 8]))
def test_pairs_inside_a_branch_ignore_the_other_branches_states(hand, seed, branch):
    rng = np.random.default_rng(seed)
    states = random_states(hand, rng)
    mine = branch_of(hand, branch)
    others = random_states(hand, rng)
    changed = np.where([k in mine or k == 0 for k in range(len(states))], states, others)
    assert pairs_within(hand.clearance(states), mine) == pairs_within(
        hand.clearance(changed), mine
    )


def test_a_sweep_agrees_with_the_clearance_of_each_configuration(hand):
    rng = np.random.default_rng(3)
    configurations = [random_states(hand, rng) for _ in range(25)]
    report = sweep(hand, configurations=configurations)
    assert isinstance(report, SweepReport)
    assert report.samples == 25
    expected = sum(not hand.clearance(q).ok for q in configurations)
    assert report.colliding == expected
    for pair, count in report.worst_pairs:
        assert 1 <= count <= expected and pair.clearance < 0
    # the hand as published is not clear at its states: no free interval
    assert report.free_intervals == (None,) * len(hand.Joints)


def test_random_sweeps_are_deterministic_for_a_seed(hand):
    a = sweep(hand, samples=20, seed=5)
    b = sweep(hand, samples=20, seed=5)
    assert (a.colliding, a.worst_pairs) == (b.colliding, b.worst_pairs)


def test_free_intervals_are_clear_inside_and_collide_just_beyond(clear_hand):
    tree = clear_hand
    assert tree.clearance().ok
    motion = TreeMotion(tree)
    intervals = motion.free_intervals(np.array([j.state for j in tree.Joints]), resolution=16)
    assert len(intervals) == len(tree.Joints)
    width = 0
    for k, (joint, (lo, hi)) in enumerate(zip(tree.Joints, intervals, strict=True)):
        low, high = joint.stateRange()
        assert low - 1e-12 <= lo <= joint.state <= hi <= high + 1e-12
        width += hi - lo
        for end, bound, step in ((lo, low, -1), (hi, high, 1)):
            if end == joint.state and bound == end:
                continue
            inside = np.array([j.state for j in tree.Joints])
            inside[k] = end - step * 1e-6
            assert tree.clearance(inside).ok, (k, end)
            if abs(end - bound) > 1e-6:
                beyond = inside.copy()
                beyond[k] = end + step * 1e-5
                assert not tree.clearance(beyond).ok, (k, end)
    assert width > 0  # some joint moves


def test_kinegami_check_motion_sweeps_a_tree(capsys):
    import matplotlib

    matplotlib.use("Agg")
    from kinegami.cli import main

    code = main([str(a) for a in ("check", HAND_DESIGN, "--motion", "30", "--seed", "2", "--json")])
    data = json.loads(capsys.readouterr().out)
    assert code in (0, 3)  # 3: the design self-intersects at its states
    assert data["motion"]["samples"] == 30
    assert 0 <= data["motion"]["colliding"] <= 30
    assert math.isclose(data["motion"]["colliding_fraction"], data["motion"]["colliding"] / 30)


# --- closest points of pairs that leave one junction ---------------------------------------------


@settings(max_examples=25, deadline=None)
@given(
    gap=st.floats(0.0, 1.9),
    height=st.floats(8.0, 16.0),
    lean=st.floats(-0.3, 0.3),
)
def test_the_points_of_every_reported_pair_realise_its_clearance(gap, height, lean):
    """Two sibling tubes leaving the root together: within the junction (up to 5 r) they may
    touch; beyond it they overlap, and the reported parts and closest points are those beyond
    it (they were those of the whole rows: 'first elbow and first elbow' at the root)."""
    from spatialmath import SE3

    from kinegami import EndTip, KinematicTree, Waypoint

    tree = KinematicTree(Waypoint(4, 1, SE3()))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        for side in (-1, 1):
            pose = SE3.Trans(side * gap / 2, 0, height) * SE3.Ry(side * lean)
            tree.addJoint(0, EndTip(4, 1, pose, 1.5), safe=False, fixedPosition=True,
                          fixedOrientation=True)  # fmt: skip
    report = tree.clearance()
    assert not report.ok  # closer than 2 r beyond the junction
    for pair in (*report.pairs, report.closest):
        p, o = map(np.array, pair.points)
        assert abs(np.linalg.norm(p - o) - 2.0 - pair.clearance) < 1e-9, pair
        if node_of(pair.elements[0]) != node_of(pair.elements[1]):  # the two branches
            assert min(p[2], o[2]) > 4.0, pair  # beyond the junction, not at the root
