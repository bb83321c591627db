"""A two-finger gripper on a wrist: a kinematic tree with two leaves.

A mount (start tip) at the origin brings the tube up along z through a wrist of two revolute
joints with orthogonal axes (pitch about x at 30 mm, yaw about y at 60 mm) to a palm waypoint
at 85 mm, where the tube splits into two fingers 60 mm apart. Each finger has a base joint at
140 mm and a middle joint 50 mm above it, about parallel axes along y (positive states close
the fingers towards each other), and a fingertip 45 mm further. Every joint is placed exactly on
its axis (``safe=False`` with fixed position and orientation); the states then open the
fingers by 10 degrees at their bases and curl them in by 25 degrees at the middle joints, ready
to close on something between them.

It is folded from two sheets: the mount, the wrist and the left finger in one piece, and the
right finger starting in the printed junction at the palm.

Run: ``python examples/gripper.py [output-folder]``. It writes the 3D view and each sheet's
crease pattern drawing and DXF into ``examples/output/gripper/`` (or the folder given) and
prints their paths. The same tree as a design file: ``examples/designs/gripper.json``.
"""

import sys
import warnings

from _common import axis_pose, output_folder, report_tree, save_tree_outputs, tree_sheets

from kinegami import *

NAME = "gripper"
r = 10  # tube radius (mm)
numSides = 6
EXACT = dict(relative=False, safe=False, fixedPosition=True, fixedOrientation=True)
SPREAD = 30  # each finger's distance from the wrist's axis (mm)
#: The fingers' states (degrees): opened at the base, curled in at the middle joint.
OPEN, CURL = -10, 25


def revolute(point, axis, xhat):
    """A revolute joint (bending range pi) about ``axis`` through ``point``; links leave along xhat."""
    return RevoluteJoint(numSides, r, np.pi, axis_pose(point, axis, xhat))


def build():
    """The gripper: mount, wrist pitch and yaw, palm, two fingers, then the fingers' states."""
    up = [0, 0, 1]
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)  # every addJoint must succeed
        warnings.simplefilter("error", ClearanceWarning)  # and never pass through itself
        tree = KinematicTree(StartTip(numSides, r, axis_pose([0, 0, 0], up, [1, 0, 0]), r))
        pitch = tree.addJoint(0, revolute([0, 0, 30], [1, 0, 0], up), **EXACT)
        yaw = tree.addJoint(pitch, revolute([0, 0, 60], [0, 1, 0], up), **EXACT)
        palm = tree.addJoint(yaw, Waypoint(numSides, r, axis_pose([0, 0, 85], up, [1, 0, 0]),
                                           pathIndex=2), **EXACT)  # fmt: skip
        fingers = []
        for side in (1, -1):  # left (-x), then right (+x)
            x = -side * SPREAD
            base = tree.addJoint(palm, revolute([x, 0, 140], [0, side, 0], up), **EXACT)
            middle = tree.addJoint(base, revolute([x, 0, 190], [0, side, 0], up), **EXACT)
            tip = EndTip(numSides, r, axis_pose([x, 0, 235], up, [1, 0, 0]), r)
            tree.addJoint(middle, tip, **EXACT)
            fingers.append((base, middle))
        for base, middle in fingers:
            tree.setJointState(base, np.radians(OPEN))
            tree.setJointState(middle, np.radians(CURL))
    return tree


if __name__ == "__main__":
    tree = build()
    fabrication, slides = tree_sheets(tree)
    written = save_tree_outputs(tree, NAME, output_folder(NAME, sys.argv), fabrication=fabrication)
    report_tree(tree, NAME, fabrication, slides, written)
