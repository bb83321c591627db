"""Appends, edits and state changes that make a chain pass through itself: ClearanceWarning,
or a transactional rejection with requireClearance."""

from __future__ import annotations

import math
import warnings

import pytest

from kinegami import ClearanceWarning, KinematicChain, PlacementWarning, StartTip, Waypoint
from kinegami.errors import InvalidTypeError

from .helpers import FIXED, frame, tip_pose
from .test_clearance import fold_back_chain


def snapshot(chain):
    return (chain.Joints, chain.Links, chain.boundingBall)


def test_a_state_change_into_a_collision_warns_and_applies():
    chain = fold_back_chain()
    with pytest.warns(ClearanceWarning, match="joint 0, StartTip") as record:
        assert chain.setJointState(1, math.radians(20)) is True
    warning = record[0].message
    assert warning.clearance < 0 and warning.first == "joint 0, StartTip"
    assert chain.Joints[1].state == pytest.approx(math.radians(20))
    with pytest.warns(ClearanceWarning):
        assert chain.setJointStates([0.0, math.radians(25), 0.0])


def test_clear_operations_do_not_warn():
    chain = fold_back_chain()
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        assert chain.setJointState(1, -0.5)
        assert chain.translateJointAlongAxisOfMotion(1, 0.5)


def test_require_clearance_rejects_and_keeps_the_chain():
    chain = fold_back_chain()
    chain.requireClearance = True
    before = snapshot(chain)
    with pytest.warns(PlacementWarning, match="would pass through itself"):
        assert chain.setJointState(1, math.radians(20)) is False
    assert snapshot(chain) == before
    with pytest.warns(PlacementWarning, match="would pass through itself"):
        assert chain.setJointStates([0.0, math.radians(20), 0.0]) is False
    assert snapshot(chain) == before
    assert chain.setJointState(1, -0.3)  # clear: applied


def test_require_clearance_on_appends_and_edits():
    chain = KinematicChain(StartTip(4, 1, tip_pose((-6, 0, 0), (1, 0, 0)), 1.5),
                           requireClearance=True)  # fmt: skip
    assert chain.requireClearance is True
    assert chain.append(Waypoint(4, 1, frame((0, 0, 0), (1, 0, 0)), pathIndex=0), **FIXED) == 1
    assert chain.append(Waypoint(4, 1, frame((0, 0, 6), (-1, 0, 0)), pathIndex=0), **FIXED) == 2
    before = snapshot(chain)
    into_the_tip = Waypoint(4, 1, frame((-10, 1.5, 0), (-1, 0, 0)), pathIndex=0)
    with pytest.warns(PlacementWarning, match="append failed: the chain would pass"):
        assert chain.append(into_the_tip, **FIXED) is None
    assert snapshot(chain) == before
    clear = Waypoint(4, 1, frame((-10, 3.0, 0), (-1, 0, 0)), pathIndex=0)
    assert chain.append(clear, **FIXED) == 3
    before = snapshot(chain)
    with pytest.warns(PlacementWarning, match="transformJoint failed: the chain would pass"):
        assert chain.transformJoint(3, frame((0, -1.5, 0), (1, 0, 0)), propagate=False) is False
    assert snapshot(chain) == before
    # without requireClearance the same edit applies and warns
    chain.requireClearance = False
    with pytest.warns(ClearanceWarning, match="transformJoint: the chain passes through itself"):
        assert chain.transformJoint(3, frame((0, -1.5, 0), (1, 0, 0)), propagate=False)


def test_require_clearance_is_a_bool():
    with pytest.raises(InvalidTypeError, match="requireClearance must be True or False"):
        KinematicChain(StartTip(4, 1, tip_pose((0, 0, 0), (1, 0, 0)), 1.5), requireClearance=1)
    chain = fold_back_chain()
    with pytest.raises(InvalidTypeError, match="requireClearance"):
        chain.requireClearance = "yes"
