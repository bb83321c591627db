"""Limits on work that the counts of a design multiply (issue 29, docs/limits.md): joints added
through the API (MAX_API_JOINTS). Each refusal is one line naming the value, the limit and why,
given before the work starts, and leaves the design bit-identical."""

from __future__ import annotations

import warnings

import pytest
from spatialmath import SE3

from kinegami import (
    EndTip,
    KinematicChain,
    KinematicTree,
    PlacementWarning,
    StartTip,
    Waypoint,
    limits,
)


# --- joints through the API -------------------------------------------------------------------
def _full(monkeypatch, limit: int) -> None:
    monkeypatch.setattr("kinegami.validation.MAX_API_JOINTS", limit)


def test_append_to_a_chain_with_max_api_joints_returns_none_and_warns(monkeypatch, snapshot):
    chain = KinematicChain(StartTip(4, 1, SE3(), 1))
    for k in range(2):
        assert chain.append(Waypoint(4, 1, SE3.Trans(0, 0, 5)), safe=False) == k + 1
    _full(monkeypatch, 3)
    before = snapshot(chain)
    with pytest.warns(PlacementWarning) as caught:
        assert chain.append(Waypoint(4, 1, SE3.Trans(0, 0, 5)), safe=False) is None
    text = str(caught[0].message)
    assert "\n" not in text
    for word in ("append failed", "has 3 joints", "MAX_API_JOINTS = 3", "unchanged"):
        assert word in text, (word, text)
    assert snapshot(chain) == before
    _full(monkeypatch, 4)  # one more fits
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)
        assert chain.append(Waypoint(4, 1, SE3.Trans(0, 0, 5)), safe=False) == 3


def test_add_joint_to_a_full_tree_returns_none_and_warns(monkeypatch, snapshot):
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    assert tree.addJoint(0, Waypoint(4, 1, SE3.Trans(0, 0, 5)), safe=False) == 1
    _full(monkeypatch, 2)
    before = snapshot(tree)
    with pytest.warns(PlacementWarning, match=r"addJoint failed: the tree has 2 joints"):
        assert tree.addJoint(0, EndTip(4, 1, SE3.Trans(5, 0, 0), 1), safe=False) is None
    assert snapshot(tree) == before


def test_max_api_joints_leaves_room_for_every_design_file():
    # a file's MAX_JOINTS entries with the waypoints safe placement adds (up to four each)
    assert limits.MAX_API_JOINTS >= limits.MAX_STATES == 5 * limits.MAX_JOINTS
