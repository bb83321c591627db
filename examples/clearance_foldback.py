"""A fold-back across a revolute joint, caught by the clearance engine.

Run from the repository root::

    python examples/clearance_foldback.py [picture.png]

The chain goes out along +x from a start tip, through a revolute joint (axis z) at the origin,
and its next link turns back to a waypoint 2.5 r beside the incoming tube. At state 0 it is
clear; at 20 degrees the returning tube swings into the start tip. The script prints both
reports and draws the chain at 20 degrees, seen from above, with ``show(showCollisions=True)``: the colliding
parts in red, their closest points joined by a red line, the clearance in the title. Default
picture: ``docs/images/clearance_foldback.png``.
"""

from __future__ import annotations

import math
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
from _common import axis_pose, save_figure  # noqa: E402

from kinegami import KinematicChain, RevoluteJoint, StartTip, Waypoint  # noqa: E402

PICTURE = Path(__file__).resolve().parents[1] / "docs" / "images" / "clearance_foldback.png"
#: Every joint exactly where it is put (no safe placement, no relative poses).
FIXED = {"relative": False, "safe": False, "fixedPosition": True, "fixedOrientation": True}


def fold_back_chain() -> KinematicChain:
    """Start tip along +x, a revolute joint at the origin, a waypoint 2.5 r back beside it."""
    n, r = 4, 1.0
    chain = KinematicChain(StartTip(n, r, axis_pose((-6, 0, 0), (1, 0, 0), (0, 1, 0)), 1.5 * r))
    chain.append(RevoluteJoint(n, r, math.pi, axis_pose((0, 0, 0), (0, 0, 1), (1, 0, 0))), **FIXED)
    chain.append(Waypoint(n, r, axis_pose((-6, 2.5, 0), (0, 0, 1), (-1, 0, 0)), pathIndex=0),
                 **FIXED)  # fmt: skip
    return chain


def main(argv: list[str]) -> None:
    if len(argv) > 2:
        sys.exit(f"usage: python {Path(argv[0]).name} [picture.png]")
    path = Path(argv[1]) if len(argv) == 2 else PICTURE
    chain = fold_back_chain()
    print("at state 0:", chain.clearance())
    assert chain.setJointState(1, math.radians(20))
    print("at 20 degrees:", chain.clearance())
    fig = plt.figure(figsize=(8.0, 6.0))
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0), projection="3d")
    # light surfaces so that the red lines inside the tubes show; seen from above (+z)
    chain.show(ax=ax, showCollisions=True, showJointPoses=False, jointAxisScale=3,
               surfaceOpacity=0.25)  # fmt: skip
    ax.view_init(elev=90.0, azim=-90.0)
    print("wrote", save_figure(fig, path, dpi=80, tight=True))


if __name__ == "__main__":
    main(sys.argv)
