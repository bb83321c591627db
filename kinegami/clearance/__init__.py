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

The names below load on first use (a module ``__getattr__``), so that importing one module of
the folder (``kinegami.clearance.tree_bodies`` for a tree's checks) does not import the engine.
"""

import importlib

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


def __getattr__(name: str):
    try:
        module_name = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'kinegami.clearance' has no attribute {name!r}") from None
    value = getattr(importlib.import_module(module_name), name)
    globals()[name] = value  # once imported, an ordinary attribute
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
