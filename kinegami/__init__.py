"""kinegami: tubular origami kinematic chains and their crease patterns.

``from kinegami import *`` gives the names the paper's listings use: ``KinematicChain``,
the joints, ``LinkCSC``, ``TubularPattern``, ``SE3`` (spatialmath) and ``np`` (numpy), plus
``export(obj, path, **options)``, which writes a chain or a pattern in the format named by the
file suffix (DXF, SVG, FOLD, PDF, STL, OBJ, URDF; docs/exports.md).

Importing the package is cheap: the classes (and numpy, spatialmath) are imported when a name
is first used (a module ``__getattr__``, which ``import *`` goes through for the names of
``__all__``), so the ``kinegami`` command loads only what its command needs.
"""

from kinegami import _startup

if _startup.running_the_command():  # Ctrl-C while the rest imports: one line, no traceback
    _startup.quiet_interrupts()

from kinegami import _mplconfig

if _mplconfig.running_the_command():  # before spatialmath imports matplotlib
    _mplconfig.use_private_folder_if_needed()

import importlib

from kinegami._version import __version__ as __version__
from kinegami.errors import (
    ClearanceWarning,
    IncompatibleJointError,
    InvalidParameterError,
    InvalidTypeError,
    JointIndexError,
    KinegamiError,
    NoPathError,
)

# the function: it replaces the attribute the import gives the package kinegami.export, whose
# modules are imported by name (from kinegami.export import dxf)
from kinegami.export import export

__all__ = [
    "KinematicChain",
    "KinematicTree",
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

#: Names imported on first use: name -> (module, attribute; None for the module itself).
_LAZY = {
    "KinematicChain": ("kinegami.chain", "KinematicChain"),
    "KinematicTree": ("kinegami.tree", "KinematicTree"),
    "PlacementWarning": ("kinegami.chain", "PlacementWarning"),
    "RevoluteJoint": ("kinegami.chain.joints", "RevoluteJoint"),
    "ExtendedRevoluteJoint": ("kinegami.chain.joints", "ExtendedRevoluteJoint"),
    "PrismaticJoint": ("kinegami.chain.joints", "PrismaticJoint"),
    "Waypoint": ("kinegami.chain.joints", "Waypoint"),
    "StartTip": ("kinegami.chain.joints", "StartTip"),
    "EndTip": ("kinegami.chain.joints", "EndTip"),
    "Joint": ("kinegami.chain.joints", "Joint"),
    "LinkCSC": ("kinegami.chain.links", "LinkCSC"),
    "TubularPattern": ("kinegami.pattern", "TubularPattern"),
    "Ball": ("kinegami.geometry.balls", "Ball"),
    "SE3": ("spatialmath", "SE3"),
    "np": ("numpy", None),
}


def __getattr__(name: str):
    try:
        module_name, attribute = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'kinegami' has no attribute {name!r}") from None
    module = importlib.import_module(module_name)
    value = module if attribute is None else getattr(module, attribute)
    globals()[name] = value  # once imported, an ordinary attribute
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
