"""A limb on a spherical joint (paper Figure 3(e-g), other examples).

The spherical joint of ``spherical_joint.py`` (three revolute joints about z, x and y, all
three axes through the origin) between a start tip that brings the tube in along x and a limb:
a straight tube 144 mm long ending in an end tip. The limb turns about the origin as a rigid
body when the three joints move.

Run: ``python examples/spherical_limb.py [output-folder]``. It writes the 3D view, the crease
pattern drawing and the pattern as DXF into ``examples/output/spherical_limb/`` (or the folder
given) and prints their paths. The same chain as a design file:
``examples/designs/spherical_limb.json``.
"""

import sys
import warnings

from _common import axis_pose, output_folder, report, save_outputs

from kinegami import *

NAME = "spherical_limb"
r = 10  # tube radius (mm)
numSides = 6
d = 4 * r  # distance of each joint from the centre of rotation (mm)
EXACT = dict(relative=False, safe=False, fixedPosition=True, fixedOrientation=True)


def revolute(point, axis, xhat):
    """A revolute joint (bending range pi) about ``axis`` through ``point``; links leave along xhat."""
    return RevoluteJoint(numSides, r, np.pi, axis_pose(point, axis, xhat))


def tip(kind, point, axis, xhat):
    """A StartTip or EndTip 1.5 r long pointing along ``axis``, centred at ``point``."""
    return kind(numSides, r, Pose=axis_pose(point, axis, xhat), length=1.5 * r)


def build(verbose=False):
    """The chain: start tip, revolute joints about z, x and y through the origin, limb, end tip."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)  # every append must succeed
        chain = KinematicChain(tip(StartTip, [-d, 0, -d], [1, 0, 0], [0, 0, -1]))
        chain.append(revolute([0, 0, -d], [0, 0, 1], [1, 0, 0]), **EXACT)
        chain.append(revolute([d, 0, 0], [1, 0, 0], [0, 1, 0]), **EXACT)
        chain.append(revolute([0, d, 0], [0, 1, 0], [-1, 0, 0]), **EXACT)
        # the limb: a straight tube along -x from the last joint to the end tip
        chain.append(tip(EndTip, [-16 * r, d, 0], [-1, 0, 0], [0, 0, 1]), **EXACT)
    if verbose:
        print(f"limb length (straight tube) {chain.Links[-1].path.tMag:.4f} mm")
    return chain


if __name__ == "__main__":
    chain = build(verbose=True)
    report(chain, NAME, save_outputs(chain, NAME, output_folder(NAME, sys.argv)))
