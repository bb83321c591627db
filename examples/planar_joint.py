"""A planar joint built from three revolute joints with parallel axes (paper Figure 3(a-c)).

A planar joint moves a body within a plane (two translations and a rotation). Three revolute
joints whose axes are parallel (all along z) do the same. This is the planar compound joint of
docs/theory/chain.md §9, scaled to a tube radius of 10 mm, and shows the editing tools at work:

1. safe placement appends the joints 40 mm apart in x; it lifts each one along its axis and
   adds two waypoints per joint (total path length 196.39 mm);
2. deleting the four waypoints leaves two CSC links (161.89 mm);
3. sliding each joint along its axis of motion back to z = 0 (which keeps the kinematics) puts
   all three joints in one plane, joined by two straight tubes (45.36 mm).

Run: ``python examples/planar_joint.py [output-folder]``. It writes the 3D view, the crease
pattern drawing and the pattern as DXF into ``examples/output/planar_joint/`` (or the folder
given) and prints their paths. The same chain as a design file:
``examples/designs/planar_joint.json`` (which places the joints directly where step 3 ends).
"""

import sys
import warnings

from _common import output_folder, report, save_outputs

from kinegami import *

NAME = "planar_joint"
r = 10  # tube radius (mm)
numSides = 6


def build(verbose=False):
    """The chain: three revolute joints about z at x = 0, 40 and 80 mm in the plane z = 0."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)  # every edit must succeed
        chain = KinematicChain(RevoluteJoint(numSides, r, np.pi, SE3()))
        for _ in range(2):
            chain.append(RevoluteJoint(numSides, r, np.pi, SE3.Trans(4 * r, 0, 0)))
        lengths = [chain.totalPathLength()]
        for index in (1, 1, 2, 2):  # the waypoints (indices shift as they go)
            chain.delete(index)
        lengths.append(chain.totalPathLength())
        for index in (1, 2):  # slide each joint down its own axis into the plane z = 0
            chain.translateJointAlongAxisOfMotion(index, -chain.Joints[index].Pose.t[2])
        lengths.append(chain.totalPathLength())
    if verbose:
        print(
            "total path length: safe placement {:.6f}, waypoints deleted {:.6f}, "
            "joints in one plane {:.6f}".format(*lengths)
        )
    return chain


if __name__ == "__main__":
    chain = build(verbose=True)
    report(chain, NAME, save_outputs(chain, NAME, output_folder(NAME, sys.argv)))
