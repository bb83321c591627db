"""kinegami: tubular origami kinematic chains and their crease patterns.

``from kinegami import *`` gives the names the paper's listings use: ``KinematicChain``,
the joints, ``LinkCSC``, ``TubularPattern``, ``SE3`` (spatialmath) and ``np`` (numpy), plus
``export(obj, path, **options)``, which writes a chain or a pattern in the format named by the
file suffix (DXF, SVG, FOLD, PDF, STL, OBJ, URDF).
"""

from kinegami import _startup

if _startup.running_the_command():  # Ctrl-C while the rest imports: one line, no traceback
    _startup.quiet_interrupts()

from kinegami import _mplconfig

if _mplconfig.running_the_command():  # before spatialmath imports matplotlib
    _mplconfig.use_private_folder_if_needed()

import numpy as np
from spatialmath import SE3

from kinegami import export
from kinegami.chain import ClearanceWarning, KinematicChain, PlacementWarning
from kinegami.errors import (
    IncompatibleJointError,
    InvalidParameterError,
    InvalidTypeError,
    JointIndexError,
    KinegamiError,
    NoPathError,
)
from kinegami.geometry.balls import Ball
from kinegami.joints import (
    EndTip,
    ExtendedRevoluteJoint,
    Joint,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)
from kinegami.links import LinkCSC
from kinegami.pattern import TubularPattern

__version__ = "0.1.0"

__all__ = [
    "KinematicChain",
    "RevoluteJoint",
    "ExtendedRevoluteJoint",
    "PrismaticJoint",
    "Waypoint",
    "StartTip",
    "EndTip",
    "Joint",
    "LinkCSC",
    "TubularPattern",
    "Ball",
    "SE3",
    "np",
    "KinegamiError",
    "InvalidParameterError",
    "InvalidTypeError",
    "JointIndexError",
    "NoPathError",
    "IncompatibleJointError",
    "PlacementWarning",
    "ClearanceWarning",
    "export",
]
