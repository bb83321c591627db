"""Self-intersection of a folded chain, at one configuration and over its range of motion.

See docs/clearance.md. The chain's parts are enclosed by capsules of radius r along its
centreline (:mod:`kinegami.chain.bodies`). Two capsules are tested only when the centreline between
them turns by at least pi in total (arc angles plus |state| at every revolute hinge): a curve
that turns by less than pi cannot come back to itself, and parts closer along the tube than
that touch by construction (the two legs of an elbow, the halves of a joint, a link and its
joints). The clearance of a tested pair is the distance between their segments minus 2r;
negative values are overlap depths. The chain is clear when every tested pair has a clearance
of at least ``margin - CONTACT_TOLERANCE * r`` (:func:`~kinegami.chain.bodies.clear_limit`): the
margin is the clearance the design requires (chain units, ``chain.margin``, default 0: parts
that touch, such as the legs of a U-turn exactly 2r apart, are clear). Every verdict is worded
by :meth:`ClearanceReport.verdict`, which states the margin.

Examples
--------
>>> chain = KinematicChain(StartTip(4, 1, Pose=SE3(), length=1.5))
>>> chain.append(RevoluteJoint(4, 1, np.pi, SE3.Trans(0, 0, 4) @ SE3.Ry(np.pi / 2)))
3
>>> chain.clearance().ok
True
"""

from kinegami.chain.bodies import CONTACT_TOLERANCE, TURN_TOLERANCE
from kinegami.clearance.checks import chain_clearance, clearance_report, sweep, tree_clearance
from kinegami.clearance.engine import (
    ClearanceEngine,
    TreeEngine,
    TreeMotion,
    engine_for,
    keep_tree_engine,
)
from kinegami.clearance.reports import ClearanceReport, CollidingPair, Lengths, SweepReport
from kinegami.validation import UNITS_IN_MM

__all__ = [
    "CONTACT_TOLERANCE",
    "TURN_TOLERANCE",
    "UNITS_IN_MM",
    "Lengths",
    "CollidingPair",
    "ClearanceReport",
    "SweepReport",
    "chain_clearance",
    "tree_clearance",
    "clearance_report",
    "sweep",
    "ClearanceEngine",
    "TreeEngine",
    "TreeMotion",
    "engine_for",
    "keep_tree_engine",
]
