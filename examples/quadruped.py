"""A four-legged walker: a kinematic tree with four legs of three revolute joints each.

The body is a spine along y, from the rear waypoint (the root) to the front one; each carries
a pair of legs, one on each side. A leg has a hip yaw joint (axis vertical) 45 mm from the
spine, a hip pitch joint 30 mm further out and a knee 60 mm beyond it (both about horizontal
axes along the body), and a foot (end tip) 80 mm beyond the knee. Every joint is placed exactly
on its axis (``safe=False`` with fixed position and orientation), so the legs are built
straight; joint states then make it stand: each leg splayed 25 degrees towards its end of the
body, thighs raised 20 degrees and knees bent 80 degrees, which puts the knees above the body
and the feet's ends 53 mm below it. Its left is -x (it faces +y).

The tree has four leaves, so it is folded from four sheets: the spine and the front left leg
in one piece, and one sheet per other leg, starting in the printed junctions at the two body
waypoints (the three tubes leaving the rear one, the two leaving the front one).

Run: ``python examples/quadruped.py [output-folder]``. It writes the 3D view and each sheet's
crease pattern drawing and DXF into ``examples/output/quadruped/`` (or the folder given) and
prints their paths. The same tree as a design file: ``examples/designs/quadruped.json``.
"""

import sys
import warnings

from _common import axis_pose, output_folder, report_tree, save_tree_outputs, tree_sheets

from kinegami import *

NAME = "quadruped"
r = 10  # tube radius (mm)
numSides = 6
EXACT = dict(relative=False, safe=False, fixedPosition=True, fixedOrientation=True)
W, A, B, C = 45, 30, 60, 80  # spine to hip yaw, hip yaw to hip pitch, thigh, shin (mm)
REAR, FRONT = -60, 60  # y of the rear and front pairs of legs (mm)
#: The stance (degrees): splay of each leg towards its end of the body, thigh lift, knee bend.
SPLAY, LIFT, BEND = 25, 20, -80
LEGS = ("rearLeft", "rearRight", "frontLeft", "frontRight")


def revolute(point, axis, xhat):
    """A revolute joint (bending range pi) about ``axis`` through ``point``; links leave along xhat."""
    return RevoluteJoint(numSides, r, np.pi, axis_pose(point, axis, xhat))


def add_leg(tree, parent, y, side):
    """A leg on ``side`` (+1 left, -1 right) at height 0 and ``y``; returns its joints' indices."""
    out = [-side, 0, 0]  # the leg's direction (left is -x)
    yaw = tree.addJoint(parent, revolute([-side * W, y, 0], [0, 0, 1], out), **EXACT)
    hip = tree.addJoint(yaw, revolute([-side * (W + A), y, 0], [0, side, 0], out), **EXACT)
    knee = tree.addJoint(hip, revolute([-side * (W + A + B), y, 0], [0, side, 0], out), **EXACT)
    foot = EndTip(numSides, r, axis_pose([-side * (W + A + B + C), y, 0], out, [0, 0, 1]), r)
    tree.addJoint(knee, foot, **EXACT)
    return yaw, hip, knee


def build():
    """The quadruped: body waypoints, four straight legs, then the standing states."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)  # every addJoint must succeed
        warnings.simplefilter("error", ClearanceWarning)  # and never pass through itself
        tree = KinematicTree(Waypoint(numSides, r, axis_pose([0, -70, 0], [0, 1, 0], [0, 0, 1]),
                                      pathIndex=2))  # fmt: skip
        legs = {"rearLeft": add_leg(tree, 0, REAR, 1), "rearRight": add_leg(tree, 0, REAR, -1)}
        front = tree.addJoint(0, Waypoint(numSides, r, axis_pose([0, 50, 0], [0, 1, 0],
                                                                 [0, 0, 1]), pathIndex=2),
                              **EXACT)  # fmt: skip
        legs["frontLeft"] = add_leg(tree, front, FRONT, 1)
        legs["frontRight"] = add_leg(tree, front, FRONT, -1)
        for name in LEGS:  # the yaw that turns a leg towards its end of the body
            yaw, hip, knee = legs[name]
            left, rear = name.endswith("Left"), name.startswith("rear")
            splay = SPLAY if left == rear else -SPLAY
            for joint, angle in ((yaw, splay), (hip, LIFT), (knee, BEND)):
                tree.setJointState(joint, np.radians(angle))
    return tree


if __name__ == "__main__":
    tree = build()
    fabrication, slides = tree_sheets(tree)
    written = save_tree_outputs(tree, NAME, output_folder(NAME, sys.argv), fabrication=fabrication)
    report_tree(tree, NAME, fabrication, slides, written)
