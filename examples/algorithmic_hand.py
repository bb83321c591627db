"""A three-finger hand placed by the tree construction (Feshbach et al., WAFR 2024).

The upstream algorithmic-hand example, on nearly the axes of the paper's hand (``hand.py``):
a root waypoint, the palm joint and a two-joint thumb, a two-joint pointer and a three-joint
middle finger, each ending in a fingertip; the revolute joints are extended ones (a short
straight tube on each side). It is written as a *joint specification*: each pose only says on
which line the joint's axis lies. ``from_specification`` chooses everything else: a growth
direction n (here (1/2, 1/sqrt 2, 1/2), which keeps every axis within 60 degrees of it),
where on its line each joint sits (just beyond a cylinder along n that holds
everything built before it), its roll and the sign of its axis, and two waypoints that route
each later finger of the root out of the cylinder. That guarantees that every link exists, but
not a small robot: the hand comes out at 754.59 cm of links in a ball of radius about 116 cm,
against 32.28 cm for the hand placed by hand. The routes of the two later fingers leave the
root 0.5 rad apart about n (kinegami's default); the published construction, which routes them
side by side, gives 755.9963 cm and a tree that passes through itself.

Run: ``python examples/algorithmic_hand.py [output-folder]``. It prints what the construction
chose, writes the 3D view and each sheet's crease pattern drawing and DXF into
``examples/output/algorithmic_hand/`` (or the folder given) and prints their paths. The same
specification as a design file: ``examples/designs/algorithmic_hand.json``.
"""

import sys

from _common import output_folder, report_tree, save_tree_outputs, tree_sheets

from kinegami import *
from kinegami.tree import JointSpecificationTree, from_specification

NAME = "algorithmic_hand"
r = 1  # tube radius (cm)
numSides = 4
#: Each side's straight tube of the extended revolute joints: the joint is 0.45/0.245 r long.
h = (0.45 / 0.245 - np.sqrt(2)) / 2


def revolute(Pose):
    return ExtendedRevoluteJoint(numSides, r, np.pi, h, Pose)


def fingertip(Pose):
    return EndTip(numSides, r, Pose, 1)


def specification() -> JointSpecificationTree:
    """The joint specification: every pose relative to its parent's specified pose."""
    tip = SE3.Ry(np.pi / 2) * SE3.Rz(np.pi / 2)
    spec = JointSpecificationTree(Waypoint(numSides, r, SE3(), pathIndex=2))
    palm = spec.addJoint(0, revolute(SE3.Trans(4, 0, 3) * SE3.Ry(-np.pi / 4) * SE3.Rx(np.pi / 4)),
                         name="palm")  # fmt: skip
    thumb0 = spec.addJoint(palm, revolute(SE3.Trans(0.45 / 0.245, 0, 0) * SE3.Rx(np.pi / 2)),
                           name="thumb0")  # fmt: skip
    thumb1 = spec.addJoint(thumb0, revolute(SE3.Trans(4, 0, 0)), name="thumb1")
    spec.addJoint(thumb1, fingertip(SE3.Trans(3, 0, 0) * tip), name="thumbEnd")
    pointer1 = spec.addJoint(0, revolute(SE3.Trans(0, 0, 8) * SE3.Ry(-np.pi / 2) * SE3.Rx(np.pi)),
                             name="pointer1")  # fmt: skip
    pointer2 = spec.addJoint(pointer1, revolute(SE3.Trans(4, 0, 0)), name="pointer2")
    spec.addJoint(pointer2, fingertip(SE3.Trans(4, 0, 0) * tip), name="pointerEnd")
    middle0 = spec.addJoint(0, revolute(SE3.Trans(-2.25, 0, 4) * SE3.Ry(-np.pi / 2)
                                        * SE3.Rx(np.pi / 2)), name="middle0")  # fmt: skip
    middle1 = spec.addJoint(middle0, revolute(SE3.Trans(4, 0, 0) * SE3.Rx(np.pi / 2)),
                            name="middle1")  # fmt: skip
    middle2 = spec.addJoint(middle1, revolute(SE3.Trans(4, 0, 0)), name="middle2")
    spec.addJoint(middle2, fingertip(SE3.Trans(4, 0, 0) * tip), name="middleEnd")
    return spec


def build(verbose=False):
    """The tree the construction makes of the specification (its default options)."""
    tree = from_specification(specification())
    if verbose:
        made = tree.construction
        print(
            f"growth direction n = {np.round(made.growth_direction, 6)} (chosen: {made.chosen}), "
            f"min |z . n| = {made.quality:.6f}; {len(made.waypoints)} later fingers routed "
            f"through two waypoints each; tree ball radius {made.recomputed_ball.r:.4f} cm"
        )
        published = from_specification(specification(), sibling_azimuth=0.0)
        print(
            f"total link length {tree.totalPathLength():.4f} cm; the published routing: "
            f"{published.totalPathLength():.4f} cm, {published.clearance()}"
        )
    return tree


if __name__ == "__main__":
    tree = build(verbose=True)
    fabrication, slides = tree_sheets(tree)
    written = save_tree_outputs(tree, NAME, output_folder(NAME, sys.argv), fabrication=fabrication,
                                units="cm")  # fmt: skip
    report_tree(tree, NAME, fabrication, slides, written, units="cm")
