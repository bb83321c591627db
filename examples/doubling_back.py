"""A chain that doubles back on itself (paper Figure 3(e-g), other examples).

The chain runs out along +x (a revolute joint about z, a prismatic joint along x, a revolute
joint about y), makes a U-turn 60 mm upwards and comes back along -x above itself (a revolute
joint about z, a prismatic joint, a revolute joint about y) to an end tip above the start tip.
The placement algorithms always place a new joint beyond the chain built so far, so a chain
that folds back over itself is given by exact poses (compact placement with a fixed position
and orientation); every link is still a CSC Dubins path with turns below pi.

Run: ``python examples/doubling_back.py [output-folder]``. It writes the 3D view, the crease
pattern drawing and the pattern as DXF into ``examples/output/doubling_back/`` (or the folder
given) and prints their paths. The same chain as a design file:
``examples/designs/doubling_back.json``.
"""

import sys
import warnings

from _common import axis_pose, output_folder, report, save_outputs

from kinegami import *

NAME = "doubling_back"
r = 10  # tube radius (mm)
numSides = 6
h = 6 * r  # height of the way back above the way out (mm)
EXACT = dict(relative=False, safe=False, fixedPosition=True, fixedOrientation=True)


def revolute(point, axis, xhat):
    """A revolute joint (bending range pi) about ``axis`` through ``point``; links leave along xhat."""
    return RevoluteJoint(numSides, r, np.pi, axis_pose(point, axis, xhat))


def prismatic(point, axis, xhat):
    """A prismatic joint (30 mm at rest, 3 REBO layers) sliding along ``axis`` through ``point``."""
    return PrismaticJoint(
        numSides,
        r,
        neutralLength=3 * r,
        numLayers=3,
        coneAngle=np.pi / 4,
        Pose=axis_pose(point, axis, xhat),
    )


def tip(kind, point, axis, xhat):
    """A StartTip or EndTip 1.5 r long pointing along ``axis``, centred at ``point``."""
    return kind(numSides, r, Pose=axis_pose(point, axis, xhat), length=1.5 * r)


def build(verbose=False):
    """The chain: out along +x, a U-turn upwards, back along -x."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)  # every append must succeed
        chain = KinematicChain(tip(StartTip, [0, 0, 0], [1, 0, 0], [0, 0, 1]))
        for joint in [
            revolute([60, 0, 0], [0, 0, 1], [1, 0, 0]),  # the way out
            prismatic([120, 0, 0], [1, 0, 0], [0, 0, 1]),
            revolute([180, 0, 0], [0, 1, 0], [1, 0, 0]),
            revolute([180, 0, h], [0, 0, 1], [-1, 0, 0]),  # after the U-turn: the way back
            prismatic([120, 0, h], [-1, 0, 0], [0, 0, 1]),
            revolute([60, 0, h], [0, 1, 0], [-1, 0, 0]),
            tip(EndTip, [0, 0, h], [-1, 0, 0], [0, 0, 1]),
        ]:
            chain.append(joint, **EXACT)
    if verbose:
        uturn = chain.Links[4].path
        print(
            f"U-turn link: arcs {uturn.theta1:.4f} and {uturn.theta2:.4f} rad, "
            f"straight part {uturn.tMag:.4f} mm"
        )
    return chain


if __name__ == "__main__":
    chain = build(verbose=True)
    report(chain, NAME, save_outputs(chain, NAME, output_folder(NAME, sys.argv)))
