"""A spherical joint built from three revolute joints (paper Figure 3(a-c)).

A spherical joint rotates a body about a point (three degrees of freedom). Three revolute joints
whose axes are mutually orthogonal and meet in one point do the same. Here the axes are z, x
and y through the origin; each joint sits 40 mm from the origin on its own axis, and its links
leave along the given x direction. The poses are given exactly (compact placement with a fixed
position and orientation), so the axes visibly meet at the origin.

Run: ``python examples/spherical_joint.py [output-folder]``. It writes the 3D view, the crease
pattern drawing and the pattern as DXF into ``examples/output/spherical_joint/`` (or the folder
given) and prints their paths. The same chain as a design file:
``examples/designs/spherical_joint.json``.
"""

import sys
import warnings

from _common import axis_pose, output_folder, report, save_outputs

from kinegami import *

NAME = "spherical_joint"
r = 10  # tube radius (mm)
numSides = 6
d = 4 * r  # distance of each joint from the centre of rotation (mm)
EXACT = dict(relative=False, safe=False, fixedPosition=True, fixedOrientation=True)


def revolute(point, axis, xhat):
    """A revolute joint (bending range pi) about ``axis`` through ``point``; links leave along xhat."""
    return RevoluteJoint(numSides, r, np.pi, axis_pose(point, axis, xhat))


def build(verbose=False):
    """The chain: revolute joints about z, x and y, all three axes through the origin."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)  # every append must succeed
        chain = KinematicChain(revolute([0, 0, -d], [0, 0, 1], [1, 0, 0]))
        chain.append(revolute([d, 0, 0], [1, 0, 0], [0, 1, 0]), **EXACT)
        chain.append(revolute([0, d, 0], [0, 1, 0], [-1, 0, 0]), **EXACT)
    if verbose:
        print(
            "axes of motion (all through the origin):",
            ", ".join(str(joint.Pose.a) for joint in chain.Joints),
        )
    return chain


if __name__ == "__main__":
    chain = build(verbose=True)
    report(chain, NAME, save_outputs(chain, NAME, output_folder(NAME, sys.argv)))
