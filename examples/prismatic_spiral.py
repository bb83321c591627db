"""A spiral of prismatic joints (paper Figure 3(e-g)): the prismatic spiral of
docs/theory/chain.md §9.

Each prismatic joint's axis is the previous one's turned by 45 degrees about its y axis, and
compact placement (``safe=False``) puts each new joint at least 4r beyond the chain built so far,
so the chain of five REBO prismatic joints curls round in a spiral. The numbers are the published
ones (tests/reference_values.py) scaled to a tube radius of 10 mm: total path length 281.96046 mm.

Run: ``python examples/prismatic_spiral.py [output-folder]``. It writes the 3D view, the crease
pattern drawing and the pattern as DXF into ``examples/output/prismatic_spiral/`` (or the folder
given) and prints their paths. The same chain as a design file:
``examples/designs/prismatic_spiral.json``.
"""

import sys
import warnings

from _common import output_folder, report, save_outputs

from kinegami import *

NAME = "prismatic_spiral"
r = 10  # tube radius (mm)
numSides = 6


def prismatic(Pose):
    """A prismatic joint 30 mm long at rest, with 5 REBO layers and 45-degree cones."""
    return PrismaticJoint(
        numSides, r, neutralLength=3 * r, numLayers=5, coneAngle=np.pi / 4, Pose=Pose
    )


def build(verbose=False):
    """The chain: a prismatic joint along z at the origin and four more, each turned 45 degrees."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)  # every append must succeed
        chain = KinematicChain(prismatic(SE3()))
        for _ in range(4):
            chain.append(prismatic(SE3.Ry(np.pi / 4)), safe=False)
    if verbose:
        print("joint origins (mm):")
        for joint in chain.Joints:
            print(f"  {np.round(joint.Pose.t, 4)}")
    return chain


if __name__ == "__main__":
    chain = build(verbose=True)
    report(chain, NAME, save_outputs(chain, NAME, output_folder(NAME, sys.argv)))
