"""TreeGrowth, the incremental overlap test of placement's candidates (issue 29 §3): on random
trees and random additions it answers exactly what the whole-tree test answers for the pairs
with a new part, and placement no longer measures the whole tree per candidate."""

from __future__ import annotations

import math
import warnings
from pathlib import Path
from unittest import mock

import numpy as np
from hypothesis import given, settings
from hypothesis import strategies as st
from spatialmath import SE3

from kinegami import (
    ClearanceWarning,
    KinematicTree,
    PlacementWarning,
    PrismaticJoint,
    RevoluteJoint,
    Waypoint,
)
from kinegami.chain.bodies import link_capsule_arrays, link_polyline, overlap_of_deepest_pair
from kinegami.clearance.tree_bodies import (
    TreeGrowth,
    junction_extent,
    tree_pair_distances,
    tree_worst_overlap,
)

#: Turns and translations of siblings that leave together (their tubes share a junction).
ALIKE = ((0.0, 0.0, math.pi / 2), (0.25, 0.0, math.pi / 2), (2.0, 0.5, math.pi / 2))
#: One addition: where its parent is (the root, or a fraction of the joints so far), its kind
#: (revolute, prismatic, waypoint), three turns (rad), a translation (in r), how it is placed
#: and whether the tree's states change first.
STEP = st.tuples(
    st.one_of(st.just(0.0), st.floats(0, 0.999)), st.sampled_from("RRPW"),
    st.one_of(st.sampled_from(ALIKE), st.tuples(*[st.floats(-math.pi, math.pi)] * 3)),
    st.one_of(st.just((3.0, 0.0, 4.0)), st.tuples(*[st.floats(-4, 4)] * 3)),
    st.sampled_from(("safe", "safe", "safe", "compact", "exact")),
    st.sampled_from((False, False, False, True)),
)  # fmt: skip
PLACEMENTS = {
    "safe": {},
    "compact": {"safe": False},
    "exact": {"safe": False, "fixedPosition": True, "fixedOrientation": True},
}


def _joint(kind: str, turns, shift, r: float):
    T = (SE3.Rz(turns[0]) * SE3.Trans(*(r * np.array(shift))) * SE3.Rx(turns[1])
         * SE3.Ry(turns[2]))  # fmt: skip
    if kind == "R":
        return RevoluteJoint(4, r, math.pi, T)
    if kind == "P":
        return PrismaticJoint(4, r, 3 * r, 3, math.pi / 4, T)
    return Waypoint(4, r, T)


def _same(found, expected) -> bool:
    if found is None or expected is None:
        return found is expected
    return (found.clearance, found.first, found.second, found.elements) == (
        expected.clearance, expected.first, expected.second, expected.elements)  # fmt: skip


@settings(max_examples=15, deadline=None)
@given(steps=st.lists(STEP, min_size=2, max_size=9),
       margin=st.sampled_from((0.0, 0.0, 0.3)),
       elbow=st.sampled_from((math.pi / 2, math.pi / 2, math.pi / 7, 2.8)),
       r=st.sampled_from((1.0, 1.0, 0.01)))  # fmt: skip
def test_the_incremental_test_answers_as_the_whole_tree_test(steps, margin, elbow, r):
    """Every addition (safe placement's waypoints and joint, or one joint) to a random tree,
    some of them after the tree's states changed (its links are then moved copies): the
    extension's overlap by TreeGrowth is tree_worst_overlap's with since = the old size
    (the same pair, depth and names), and TreeGrowth.clear agrees with it."""
    tree = KinematicTree(Waypoint(4, r, SE3()), maxAnglePerElbow=elbow, margin=margin * r)
    checked = 0
    for where, kind, turns, shift, placement, move in steps:
        if move:
            lows_highs = [joint.stateRange() for joint in tree.Joints]
            with warnings.catch_warnings():
                warnings.simplefilter("ignore", ClearanceWarning)
                tree.setJointStates([0.5 * (lo + hi) + 0.3 * (hi - lo) for lo, hi in lows_highs])
        before = (tree.Joints, tree.Links, tree.Parents)
        parent = int(where * len(tree.Joints))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ClearanceWarning)
            warnings.simplefilter("ignore", PlacementWarning)
            added = tree.addJoint(parent, _joint(kind, turns, shift, r), **PLACEMENTS[placement])
        if added is None:
            continue
        growth = TreeGrowth(*before, tree.r, tree.margin)
        after = (tree.Joints, tree.Links, tree.Parents)
        assert growth.extends(*after)
        expected = tree_worst_overlap(*after, tree.r, since=len(before[0]), margin=tree.margin)
        assert _same(growth.overlap(*after), expected)
        # the closest pair is found measuring nearest bounds first, a chunk at a time: the
        # same pair as measuring every listed pair, whatever the chunk
        for since in (len(before[0]), 0):
            every = tree_pair_distances(*after, tree.r, since, margin=tree.margin)
            whole = None if every is None else overlap_of_deepest_pair(
                *every[:6], tree.Joints, None, tree.r, tree.margin)  # fmt: skip
            if since:
                assert _same(expected, whole)
            for chunk in (1, 3):
                with mock.patch("kinegami.clearance.tree_bodies._CLOSEST_CHUNK", chunk):
                    assert _same(tree_worst_overlap(*after, tree.r, since=since,
                                                    margin=tree.margin), whole)  # fmt: skip
                    if since:
                        assert _same(TreeGrowth(*before, tree.r, tree.margin).overlap(*after),
                                     whole)  # fmt: skip
        assert TreeGrowth(*before, tree.r, tree.margin).clear(*after) is (expected is None)
        with mock.patch("kinegami.clearance.tree_bodies._CLEAR_CHUNK", 3):  # its first chunk
            assert TreeGrowth(*before, tree.r, tree.margin).clear(*after) is (expected is None)
        # new rows a few at a time (the blocks whose pairs are listed and measured in turn)
        for block in (1, 5):
            with mock.patch("kinegami.clearance.tree_bodies._NEW_ROWS_PER_BLOCK", block):
                assert TreeGrowth(*before, tree.r, tree.margin).clear(*after) is \
                    (expected is None)  # fmt: skip
        checked += 1
    assert checked or len(tree.Joints) == 1


@settings(max_examples=10, deadline=None)
@given(poses=st.lists(st.tuples(st.sampled_from(ALIKE + ((1.0, -0.5, 1.2),)),
                                st.sampled_from((0.0, 0.5, -1.0))), min_size=3, max_size=5),
       margin=st.sampled_from((0.0, 0.4)), elbow=st.sampled_from((math.pi / 2, math.pi / 20)),
       limit=st.sampled_from((math.inf, 5.0, 1.5)))  # fmt: skip
def test_the_extent_against_several_tubes_is_the_largest_against_each(poses, margin, elbow,
                                                                      limit):  # fmt: skip
    """What TreeGrowth relies on to measure a junction one new tube at a time: a tube's
    junction extent against its siblings' tubes together equals, bit for bit, the largest of
    its extents against each, also when the scan stops at ``limit``."""
    tree = KinematicTree(Waypoint(4, 1, SE3()), maxAnglePerElbow=elbow)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        for (turn, tilt, roll), lift in poses:
            T = SE3.Rz(turn) * SE3.Trans(3, lift, 4) * SE3.Rx(tilt) * SE3.Ry(roll)
            tree.addJoint(0, RevoluteJoint(4, 1, math.pi, T), safe=False, fixedPosition=True)
    tubes = [link_capsule_arrays(tree.Links[k], k, tree.r, 0.2)[0][:2] for k in tree.Children[0]]
    for k, own in zip(tree.Children[0], tubes, strict=True):
        line = link_polyline(tree.Links[k])
        others = [tube for tube in tubes if tube is not own]
        each = [junction_extent(line, own, other, tree.r, margin, limit) for other in others]
        together = junction_extent(line, own, (np.concatenate([t[0] for t in others]),
                                               np.concatenate([t[1] for t in others])),
                                   tree.r, margin, limit)  # fmt: skip
        assert together == max(each)


def test_an_extension_must_begin_with_the_tree():
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    tree.addJoint(0, RevoluteJoint(4, 1, math.pi, SE3.Trans(3, 0, 4) * SE3.Ry(math.pi / 2)))
    growth = TreeGrowth(tree.Joints, tree.Links, tree.Parents, tree.r)
    other = KinematicTree(Waypoint(4, 1, SE3()))
    other.addJoint(0, RevoluteJoint(4, 1, math.pi, SE3.Trans(3, 0, 4) * SE3.Ry(math.pi / 2)))
    assert not growth.extends(other.Joints, other.Links, other.Parents)  # equal, not the same
    assert growth.extends(tree.Joints, tree.Links, tree.Parents)
    assert growth.overlap(tree.Joints, tree.Links, tree.Parents) is None  # nothing new


def test_placement_does_not_measure_the_whole_tree_per_candidate(monkeypatch):
    """Issue 29 §3: every candidate of a safe placement was measured on the whole tree (about
    57 per later sibling; fuzz case design 302441 took 46 s with tubes of hundreds of
    capsules). Now the tree's capsules are built once for the candidates and once for the
    commit, however many candidates are tried."""
    import kinegami.clearance.tree_bodies as tree_bodies

    calls = {"capsules": 0, "candidates": 0}
    capsules, clear = tree_bodies.tree_capsules, TreeGrowth.clear

    def counted_capsules(*args, **kwargs):
        calls["capsules"] += 1
        return capsules(*args, **kwargs)

    def counted_clear(self, *args, **kwargs):
        calls["candidates"] += 1
        return clear(self, *args, **kwargs)

    monkeypatch.setattr(tree_bodies, "tree_capsules", counted_capsules)
    monkeypatch.setattr(TreeGrowth, "clear", counted_clear)
    tree = KinematicTree(Waypoint(4, 1, SE3()), requireClearance=True)
    pose = SE3.Rz(0.5) * SE3.Trans(3, 0, 4) * SE3.Ry(math.pi / 2)
    with warnings.catch_warnings():
        warnings.simplefilter("error", ClearanceWarning)
        for count in range(4):  # four identical children: the fourth tries about 50 routes
            assert tree.addJoint(0, RevoluteJoint(4, 1, math.pi, pose)) is not None
            assert calls["capsules"] <= 2 * (count + 1)
    assert calls["candidates"] >= 20 and len(tree.Children[0]) == 4 and tree.clearance().ok


def test_junction_extents_are_remembered_by_the_links_not_the_joint_numbers(monkeypatch):
    """A take-off candidate's folded body is a new tree whose joints are numbered anew and
    whose links mix moved copies (the tree at its states) with new ones: the junctions whose
    tubes are the same link objects are not measured again (the fuzzer's 22-joint tree spent
    half of its 70 s there), and the extents are those measured afresh."""
    import kinegami.clearance.tree_bodies as tree_bodies
    from kinegami.chain.links import LinkCSC
    from kinegami.design import load_design

    tree = load_design(Path(__file__).parents[2] / "examples" / "designs" / "gripper.json")
    tree.requireClearance = False
    assert tree.setJointStates([0.2 * (-1) ** k if j.stateRange()[1] > 0.2 else 0.0
                                for k, j in enumerate(tree.Joints)])  # fmt: skip
    links = list(tree.Links)
    assert any("_moved_from" in vars(link) for link in links)
    m = next(k for k in range(2, len(links)) if len(tree.Children[tree.Parents[k]]) > 1)
    assert "_moved_from" in vars(links[m])  # a junction that the states moved
    old = links[m]  # a tube of a junction, replaced by a new link (not a moved copy)
    links[m] = LinkCSC(tree.r, old.StartDubinsPose, old.EndDubinsPose, tree.maxAnglePerElbow)
    measured = []
    extent = tree_bodies.junction_extent

    def counted(*args, **kwargs):
        measured.append(1)
        return extent(*args, **kwargs)

    monkeypatch.setattr(tree_bodies, "junction_extent", counted)
    monkeypatch.setattr(tree_bodies, "_EXTENT_MEMO", {})
    first = tree_bodies.tree_capsules(tree.Joints, links, tree.Parents, tree.r)
    assert measured
    measured.clear()
    again = tree_bodies.tree_capsules(tree.Joints, links, tree.Parents, tree.r)
    assert not measured  # remembered
    monkeypatch.setattr(tree_bodies, "_EXTENT_MEMO", {})
    fresh = tree_bodies.tree_capsules(tree.Joints, links, tree.Parents, tree.r)
    assert np.array_equal(first.extent, again.extent)
    assert np.array_equal(again.extent, fresh.extent)


def test_a_colliding_candidate_is_told_by_its_first_block_of_new_rows(monkeypatch):
    """Issue 29 §3 (fuzz operations seed 407229): the pairs of a candidate with the tree are
    listed a block of new rows at a time and measured before the next block's are listed,
    so a candidate whose first rows collide lists no more than that block's pairs."""
    import kinegami.clearance.tree_bodies as tree_bodies

    tree = KinematicTree(Waypoint(4, 1, SE3()), maxAnglePerElbow=math.pi / 36)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        tree.addJoint(0, RevoluteJoint(4, 1, math.pi, SE3.Trans(0, 0, 30)), safe=False)
    before = (tree.Joints, tree.Links, tree.Parents)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        # a second child whose link doubles back along the first's: it collides at once
        tree.addJoint(0, RevoluteJoint(4, 1, math.pi, SE3.Trans(0, 0.5, 20) * SE3.Rx(math.pi)),
                      safe=False)  # fmt: skip
    after = (tree.Joints, tree.Links, tree.Parents)
    blocks = []
    listed = tree_bodies._near_pairs_by_block

    def counted(*args, **kwargs):
        for pair in listed(*args, **kwargs):
            blocks.append(pair[0].size)
            yield pair

    monkeypatch.setattr(tree_bodies, "_NEW_ROWS_PER_BLOCK", 2)
    monkeypatch.setattr(tree_bodies, "_near_pairs_by_block", counted)
    growth = TreeGrowth(*before, tree.r, tree.margin)
    assert growth.clear(*after) is False
    new_rows = int((growth._extended(*after, 0).node >= len(before[0])).sum())
    assert len(blocks) < new_rows / 2  # stopped before the last block
