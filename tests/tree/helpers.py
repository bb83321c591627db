"""The paper's hand as a KinematicTree, built from its reference data
(tests/data/hand_reference.json)."""

from __future__ import annotations

import json
from pathlib import Path

from spatialmath import SE3

from kinegami import EndTip, KinematicTree, RevoluteJoint, Waypoint

HAND = Path(__file__).resolve().parents[1] / "data" / "hand_reference.json"


def load_fixture(path: Path = HAND) -> dict:
    """The hand's joint specification and reference numbers (``reference``)."""
    with open(path, encoding="utf-8") as f:
        return json.load(f)


def pose_of(steps) -> SE3:
    """Elementary motions ``[["Trans", [x, y, z]], ["Rx", a], ...]`` composed left to right."""
    T = SE3()
    for name, value in steps:
        T = T * (SE3.Trans(*value) if name == "Trans" else getattr(SE3, name)(value))
    return T


def hand_tree(**options) -> KinematicTree:
    """The paper's three-finger hand: every joint added with its exact pose (relative to its
    parent's pose), in the file's order."""
    data = load_fixture()
    joints = data["joints"]
    tree = KinematicTree(Waypoint(4, 1, pose_of(joints[0]["relative_pose"])), **options)
    for spec in joints[1:]:
        pose = pose_of(spec["relative_pose"])
        params = spec["params"]
        if spec["type"] == "RevoluteJoint":
            joint = RevoluteJoint(4, 1, params["totalBendingAngle"], pose,
                                  numSinkLayers=params["numSinkLayers"])  # fmt: skip
        else:
            joint = EndTip(4, 1, pose, params["length"])
        index = tree.addJoint(spec["parent"], joint, relative=True, safe=False,
                              fixedPosition=True, fixedOrientation=True)  # fmt: skip
        assert index == spec["index"]
    return tree


def quiet_hand(**options) -> KinematicTree:
    """:func:`hand_tree` without its ClearanceWarnings (the paper's hand, as designed, has its
    palm 0.25 r into the tube to the pointer)."""
    import warnings

    from kinegami import ClearanceWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        return hand_tree(**options)
