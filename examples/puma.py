"""The PUMA 560 arm from its Denavit-Hartenberg table, then made shorter (paper Figure 3(d)).

``KinematicChain.from_dh`` puts one revolute joint on each axis of the standard DH table of the
PUMA 560 (lengths in mm, from Lee and Ziegler 1984) with the compact placement algorithm, and an
end tip on the tool frame. Compact placement keeps every joint at least 4r beyond the chain
built so far, which makes long detours. As in Figure 3(d), the chain is then shortened by
sliding joints along their axes of motion, which leaves the arm's kinematics unchanged:
``shorten_by_axis_translations`` tries such slides greedily and keeps those that shorten the
tube. The slides it keeps are printed, summed per joint, as the ``edits`` of a design file;
applied in joint order they give the same chain (tests/test_gallery.py checks it).

Run: ``python examples/puma.py [output-folder]``. It prints the total path length before and
after, writes the 3D view, the crease pattern drawing and the pattern as DXF into
``examples/output/puma/`` (or the folder given) and prints their paths. The same chain as a
design file: ``examples/designs/puma.json`` (the DH table plus those edits).
"""

import json
import sys

from _common import output_folder, report, save_outputs

from kinegami import *
from kinegami.optimize import shorten_by_axis_translations

NAME = "puma"
r = 25  # tube radius (mm): slim enough for the wrist joints, 100 mm apart, to stay untangled
numSides = 6
# Standard DH rows (theta, alpha, a, d) of the PUMA 560; radians and mm.
PUMA_560 = [
    (np.pi / 2, -np.pi / 2, 0, 0),
    (0, 0, 431.8, 149.09),
    (np.pi / 2, np.pi / 2, -20.32, 0),
    (0, -np.pi / 2, 0, 433.07),
    (0, np.pi / 2, 0, 0),
    (0, 0, 0, 56.25),
]


def slides_per_joint(edits):
    """The accepted slides [(joint, distance), ...] summed per joint, in joint order."""
    total = {}
    for joint, distance in edits:
        total[joint] = total.get(joint, 0.0) + distance
    return [(joint, total[joint]) for joint in sorted(total) if total[joint] != 0.0]


def build(verbose=False):
    """The PUMA chain: compact placement on the DH axes, then shortened along the axes."""
    # compact placement; raises NoPathError if a joint cannot be placed
    chain = KinematicChain.from_dh(PUMA_560, numSides, r)
    before = chain.totalPathLength()
    edits = shorten_by_axis_translations(chain)  # joints slide along their axes only
    if verbose:
        print(
            f"total path length: compact placement {before:.4f} mm, "
            f"after {len(edits)} slides along the axes {chain.totalPathLength():.4f} mm"
        )
        print("the slides as design-file edits:")
        for joint, distance in slides_per_joint(edits):
            edit = {"op": "translateJointAlongAxisOfMotion", "joint": joint, "distance": distance}
            print("  " + json.dumps({**edit, "propagate": False}))
    return chain


if __name__ == "__main__":
    chain = build(verbose=True)
    report(chain, NAME, save_outputs(chain, NAME, output_folder(NAME, sys.argv)))
