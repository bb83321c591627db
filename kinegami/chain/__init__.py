"""The model of a serial chain (docs/architecture.md): joints, the CSC links between them,
placement of new joints, the solid parts and their distances (``bodies``), the base class a chain
shares with a tree (``assembly``), ``KinematicChain`` itself (``model``) and DH tables (``dh``).

``KinematicChain`` and ``JointAssembly`` load on first use, so that importing one module of the
folder (``kinegami.chain.joints`` for a joint's pattern) does not import the whole chain model.
"""

import importlib

from kinegami.errors import ClearanceWarning, PlacementWarning

__all__ = ["KinematicChain", "JointAssembly", "PlacementWarning", "ClearanceWarning"]

#: Names imported on first use: name -> module.
_LAZY = {"KinematicChain": "kinegami.chain.model", "JointAssembly": "kinegami.chain.assembly"}


def __getattr__(name: str):
    try:
        module_name = _LAZY[name]
    except KeyError:
        raise AttributeError(f"module 'kinegami.chain' has no attribute {name!r}") from None
    value = getattr(importlib.import_module(module_name), name)
    globals()[name] = value  # once imported, an ordinary attribute
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
