"""Tubular crease patterns: the pattern data structure and the module catalog.

Every function of the catalog returns a :class:`TubularPattern` built in the module's proximal
frame (proximal marker at (0, 0), proximal base on the columns x_k = (k + 1/2) b at y = 0);
patterns are composed with :meth:`TubularPattern.append` or
:meth:`TubularPattern.concatenate` (docs/theory/patterns.md). Every module kind has one entry
in :mod:`kinegami.pattern.catalog` (docs/patterns.md, "The module catalog").
"""

from kinegami.pattern import catalog
from kinegami.pattern.elbow import ElbowFittingPattern
from kinegami.pattern.prismatic import PrismaticJointPattern, REBOPattern
from kinegami.pattern.revolute import EndTipPattern, RevoluteJointPattern, StartTipPattern
from kinegami.pattern.tube import TubeFittingPattern, WaypointPattern
from kinegami.pattern.tubular import FrozenParams, ModuleRecord, TubularPattern, ValidationReport
from kinegami.pattern.twist import TwistFittingPattern

#: Alias of :func:`WaypointPattern`: the pattern with only its n base vertices and height 0.
EmptyPattern = WaypointPattern

__all__ = [
    "TubularPattern",
    "ModuleRecord",
    "FrozenParams",
    "catalog",
    "ValidationReport",
    "TubeFittingPattern",
    "TwistFittingPattern",
    "ElbowFittingPattern",
    "RevoluteJointPattern",
    "PrismaticJointPattern",
    "REBOPattern",
    "StartTipPattern",
    "EndTipPattern",
    "WaypointPattern",
    "EmptyPattern",
]
