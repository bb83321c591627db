"""A cylindrical joint built from a revolute and a prismatic joint (paper Figure 3(a-c)).

A cylindrical joint rotates about and slides along one axis: two degrees of freedom that are
not coupled. Here a revolute joint and a prismatic joint share the axis z. This is the
"cylindrical variant" of the planar compound joint of docs/theory/chain.md §9, scaled to a tube
radius of 10 mm: safe placement routes the link around the revolute joint with two waypoints and
puts the prismatic joint at (0, 0, 71.256513) on the same axis.

Run: ``python examples/cylindrical_joint.py [output-folder]``. It writes the 3D view, the crease
pattern drawing and the pattern as DXF into ``examples/output/cylindrical_joint/`` (or the folder
given) and prints their paths. The same chain as a design file:
``examples/designs/cylindrical_joint.json`` (``kinegami build`` it).
"""

import sys
import warnings

from _common import output_folder, report, save_outputs

from kinegami import *

NAME = "cylindrical_joint"
r = 10  # tube radius (mm)
numSides = 6


def build(verbose=False):
    """The chain: a revolute joint about z at the origin, then a prismatic joint along z."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)  # every append must succeed
        chain = KinematicChain(RevoluteJoint(numSides, r, np.pi, SE3()))
        # Pose SE3() relative to the revolute joint: the same axis of motion (safe placement)
        chain.append(
            PrismaticJoint(
                numSides, r, neutralLength=3 * r, numLayers=3, coneAngle=np.pi / 4, Pose=SE3()
            )
        )
    if verbose:
        print(f"prismatic joint at {chain.Joints[-1].Pose.t} on the revolute joint's axis z")
    return chain


if __name__ == "__main__":
    chain = build(verbose=True)
    report(chain, NAME, save_outputs(chain, NAME, output_folder(NAME, sys.argv)))
