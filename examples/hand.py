"""The paper's three-finger hand, a kinematic tree, and its three grasps.

A root waypoint carries three fingers: the palm joint and the thumb (two joints), the pointer
(two joints) and the middle finger (three joints), each ending in a fingertip. Every joint is
added exactly where its pose says, relative to its parent's pose (``safe=False`` with fixed
position and orientation), as in the upstream ``hand.py``; n = 4, r = 1 cm. The grasps are
joint states (``POSES``): spherical (the palm turned by -pi/2, the middle finger's base by
pi/2, the six other finger joints by pi/3), cylindrical (the same with the middle finger's base
straight) and pinch (the palm by -pi/2; thumb, pointer and middle finger bent by pi/2 at one
joint each).

The tree is folded from three sheets, one per fingertip, joined at the root by a printed
junction. The palm's link from the root runs beside the pointer's for all of its length, so
the palm joint is first slid 3 cm along its axis (the kinematics stay) to give its socket room,
as ``kinegami build`` does.

Run: ``python examples/hand.py [output-folder]``. It writes the 3D view, each sheet's crease
pattern drawing and DXF, and a 3D view of each grasp into ``examples/output/hand/`` (or the
folder given) and prints their paths. The same tree as a design file:
``examples/designs/hand.json``.
"""

import copy
import sys
import warnings

from _common import output_folder, report_tree, save_tree_outputs, tree_sheets

from kinegami import *

NAME = "hand"
r = 1  # tube radius (cm)
numSides = 4
EXACT = dict(relative=True, safe=False, fixedPosition=True, fixedOrientation=True)
#: The joints in the order they are added (the names of examples/designs/hand.json).
JOINT_NAMES = ("root", "palm", "thumb0", "thumb1", "thumbEnd", "pointer1", "pointer2",
               "pointerEnd", "middle0", "middle1", "middle2", "middleEnd")  # fmt: skip
#: The grasps: joint name -> state (radians); joints not named stay at 0.
GRASPS = {
    "spherical": {"palm": -np.pi / 2, "thumb0": np.pi / 3, "thumb1": np.pi / 3,
                  "pointer1": np.pi / 3, "pointer2": np.pi / 3, "middle0": np.pi / 2,
                  "middle1": np.pi / 3, "middle2": np.pi / 3},
    "cylindrical": {"palm": -np.pi / 2, "thumb0": np.pi / 3, "thumb1": np.pi / 3,
                    "pointer1": np.pi / 3, "pointer2": np.pi / 3, "middle1": np.pi / 3,
                    "middle2": np.pi / 3},
    "pinch": {"palm": -np.pi / 2, "thumb0": np.pi / 2, "pointer1": np.pi / 2,
              "middle1": np.pi / 2},
}  # fmt: skip


def grasp_states(grasp: str) -> list[float]:
    """One state per joint of the hand (in JOINT_NAMES order) for ``grasp``."""
    return [GRASPS[grasp].get(name, 0.0) for name in JOINT_NAMES]


#: The configurations drawn besides the hand as built (examples/make_gallery.py draws them too).
POSES = {grasp: grasp_states(grasp) for grasp in GRASPS}


def revolute(Pose):
    return RevoluteJoint(numSides, r, np.pi, Pose, numSinkLayers=1)


def fingertip(Pose):
    return EndTip(numSides, r, Pose, 1)


def build():
    """The hand: every joint at its pose relative to its parent's, fingers from the root."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)  # every addJoint must succeed
        warnings.simplefilter("ignore", ClearanceWarning)  # the palm near the pointer's link
        tree = KinematicTree(Waypoint(numSides, r, SE3(), pathIndex=2))
        palm = tree.addJoint(0, revolute(SE3.Trans(2.25, 0, 3) * SE3.Ry(-np.pi / 4)
                                         * SE3.Rx(np.pi / 4)), **EXACT)  # fmt: skip
        thumb0 = tree.addJoint(palm, revolute(SE3.Trans(1.5, 0, 0) * SE3.Rx(np.pi / 2)), **EXACT)
        thumb1 = tree.addJoint(thumb0, revolute(SE3.Trans(4, 0, 0)), **EXACT)
        tree.addJoint(thumb1, fingertip(SE3.Trans(3, 0, 0) * SE3.Ry(np.pi / 2)
                                        * SE3.Rz(np.pi / 2)), **EXACT)  # fmt: skip
        pointer1 = tree.addJoint(0, revolute(SE3.Trans(0, 0, 8) * SE3.Ry(-np.pi / 2)
                                             * SE3.Rx(np.pi)), **EXACT)  # fmt: skip
        pointer2 = tree.addJoint(pointer1, revolute(SE3.Trans(4, 0, 0)), **EXACT)
        tree.addJoint(pointer2, fingertip(SE3.Trans(4, 0, 0) * SE3.Ry(np.pi / 2)
                                          * SE3.Rz(np.pi / 2)), **EXACT)  # fmt: skip
        middle0 = tree.addJoint(0, revolute(SE3.Trans(-2.25, 0, 4) * SE3.Ry(-np.pi / 2)
                                            * SE3.Rx(np.pi / 2)), **EXACT)  # fmt: skip
        middle1 = tree.addJoint(middle0, revolute(SE3.Trans(4, 0, 0) * SE3.Rx(np.pi / 2)), **EXACT)
        middle2 = tree.addJoint(middle1, revolute(SE3.Trans(4, 0, 0)), **EXACT)
        tree.addJoint(middle2, fingertip(SE3.Trans(4, 0, 0) * SE3.Ry(np.pi / 2)
                                         * SE3.Rz(np.pi / 2)), **EXACT)  # fmt: skip
    return tree


def print_grasps(tree, built):
    """Each grasp's fingertips on ``tree`` and the clearance of ``built`` (the hand with its palm
    slid, as folded) in that grasp."""
    tips = [JOINT_NAMES.index(name) for name in ("thumbEnd", "pointerEnd", "middleEnd")]
    for grasp, states in POSES.items():
        posed, folded = copy.copy(tree), copy.copy(built)  # the hands themselves stay as built
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ClearanceWarning)  # printed below
            posed.setJointStates(states)
            folded.setJointStates(states)
        where = ", ".join(f"{JOINT_NAMES[k]} {np.round(posed.Joints[k].pose_matrix[:3, 3], 3)}"
                          for k in tips)  # fmt: skip
        print(f"{grasp} grasp: fingertips at {where} (cm); as folded: {folded.clearance()}")


if __name__ == "__main__":
    tree = build()
    fabrication, slides = tree_sheets(tree)
    print_grasps(tree, fabrication.tree)
    written = save_tree_outputs(tree, NAME, output_folder(NAME, sys.argv), poses=POSES,
                                fabrication=fabrication, units="cm")  # fmt: skip
    report_tree(tree, NAME, fabrication, slides, written, units="cm")
