"""A series of spherical joints (paper Figure 3(e-g), other examples).

Three copies of the spherical joint of ``spherical_joint.py`` (revolute joints about z, x and y
whose axes meet in one point), the k-th centred at (0, 80 k, 40 k) mm, between a start tip and
an end tip: a snake of three ball joints. Each copy leaves along -x and the next one is entered
along +x, so the tube makes a U-turn between them. All poses are given exactly (compact placement
with a fixed position and orientation).

Run: ``python examples/spherical_series.py [output-folder]``. It writes the 3D view, the crease
pattern drawing and the pattern as DXF into ``examples/output/spherical_series/`` (or the folder
given) and prints their paths. The same chain as a design file:
``examples/designs/spherical_series.json``.
"""

import sys
import warnings

from _common import axis_pose, output_folder, report, save_outputs

from kinegami import *

NAME = "spherical_series"
r = 10  # tube radius (mm)
numSides = 6
d = 4 * r  # distance of each joint from the centre of its spherical joint (mm)
count = 3  # spherical joints
EXACT = dict(relative=False, safe=False, fixedPosition=True, fixedOrientation=True)
# One spherical joint about the centre c: (position - c, axis of motion, x direction) per joint.
SPHERICAL = [
    ([0, 0, -d], [0, 0, 1], [1, 0, 0]),
    ([d, 0, 0], [1, 0, 0], [0, 1, 0]),
    ([0, d, 0], [0, 1, 0], [-1, 0, 0]),
]


def centre(k):
    """Centre of the k-th spherical joint (mm)."""
    return np.array([0, 2 * d * k, d * k])


def revolute(point, axis, xhat):
    """A revolute joint (bending range pi) about ``axis`` through ``point``; links leave along xhat."""
    return RevoluteJoint(numSides, r, np.pi, axis_pose(point, axis, xhat))


def tip(kind, point, axis, xhat):
    """A StartTip or EndTip 1.5 r long pointing along ``axis``, centred at ``point``."""
    return kind(numSides, r, Pose=axis_pose(point, axis, xhat), length=1.5 * r)


def build(verbose=False):
    """The chain: start tip, three spherical joints (nine revolute joints), end tip."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)  # every append must succeed
        chain = KinematicChain(tip(StartTip, [-d, 0, -d], [1, 0, 0], [0, 0, -1]))
        for k in range(count):
            for offset, axis, xhat in SPHERICAL:
                chain.append(revolute(centre(k) + offset, axis, xhat), **EXACT)
        last = centre(count - 1)
        chain.append(tip(EndTip, last + [-d, d, 0], [-1, 0, 0], [0, 0, 1]), **EXACT)
    if verbose:
        print(
            "centres of the spherical joints (mm):", ", ".join(str(centre(k)) for k in range(count))
        )
    return chain


if __name__ == "__main__":
    chain = build(verbose=True)
    report(chain, NAME, save_outputs(chain, NAME, output_folder(NAME, sys.argv)))
