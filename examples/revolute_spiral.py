"""A spiral of revolute joints (paper Figure 3(e-g), other examples).

Each revolute joint's axis is the previous one's turned by 45 degrees about its y axis. Compact
placement (``safe=False``) puts every new joint at least 4r beyond the chain built so far, and
the axes keep turning, so the chain winds outwards in a spiral. The orientation of each joint
about its axis follows the common normal with the previous axis (docs/theory/placement.md §3).

Run: ``python examples/revolute_spiral.py [output-folder]``. It writes the 3D view, the crease
pattern drawing and the pattern as DXF into ``examples/output/revolute_spiral/`` (or the folder
given) and prints their paths. The same chain as a design file:
``examples/designs/revolute_spiral.json``.
"""

import sys
import warnings

from _common import output_folder, report, save_outputs

from kinegami import *

NAME = "revolute_spiral"
r = 10  # tube radius (mm)
numSides = 6
turns = 6  # joints appended after the first


def build(verbose=False):
    """The chain: a revolute joint at the origin and six more, each turned 45 degrees."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)  # every append must succeed
        chain = KinematicChain(RevoluteJoint(numSides, r, np.pi, SE3()))
        for _ in range(turns):
            chain.append(RevoluteJoint(numSides, r, np.pi, SE3.Ry(np.pi / 4)), safe=False)
    if verbose:
        print("joint origins (mm):")
        for joint in chain.Joints:
            print(f"  {np.round(joint.Pose.t, 3)}")
    return chain


if __name__ == "__main__":
    chain = build(verbose=True)
    report(chain, NAME, save_outputs(chain, NAME, output_folder(NAME, sys.argv)))
