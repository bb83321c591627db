"""Self-intersection of a folded chain, at one configuration and over its range of motion.

See docs/clearance.md; the rule of which capsules are tested, and the margin, are in
:mod:`kinegami.clearance.engine`.

Examples
--------
>>> chain = KinematicChain(StartTip(4, 1, Pose=SE3(), length=1.5))
>>> chain.append(RevoluteJoint(4, 1, np.pi, SE3.Trans(0, 0, 4) @ SE3.Ry(np.pi / 2)))
3
>>> chain.clearance().ok
True

The names below load on first use (a module ``__getattr__``), so that importing one module of
the folder (``kinegami.clearance.tree_bodies`` for a tree's checks) does not import the engine.
"""

from kinegami._lazy import lazy_names

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

#: Names imported on first use: name -> module.
_LAZY = {
    "CONTACT_TOLERANCE": "kinegami.chain.bodies",
    "TURN_TOLERANCE": "kinegami.chain.bodies",
    "UNITS_IN_MM": "kinegami.validation",
    "Lengths": "kinegami.clearance.reports",
    "CollidingPair": "kinegami.clearance.reports",
    "ClearanceReport": "kinegami.clearance.reports",
    "SweepReport": "kinegami.clearance.reports",
    "chain_clearance": "kinegami.clearance.checks",
    "tree_clearance": "kinegami.clearance.checks",
    "clearance_report": "kinegami.clearance.checks",
    "sweep": "kinegami.clearance.checks",
    "ClearanceEngine": "kinegami.clearance.engine",
    "TreeEngine": "kinegami.clearance.engine",
    "TreeMotion": "kinegami.clearance.engine",
    "engine_for": "kinegami.clearance.engine",
    "keep_tree_engine": "kinegami.clearance.engine",
}


__getattr__, __dir__ = lazy_names("kinegami.clearance", globals(), _LAZY)
