"""The model of a serial chain (docs/architecture.md): joints, the CSC links between them,
placement of new joints, the solid parts and their distances (``bodies``), the base class a chain
shares with a tree (``assembly``), ``KinematicChain`` itself (``model``) and DH tables (``dh``).

``KinematicChain`` and ``JointAssembly`` load on first use, so that importing one module of the
folder (``kinegami.chain.joints`` for a joint's pattern) does not import the whole chain model.
"""

from kinegami._lazy import lazy_names
from kinegami.errors import ClearanceWarning, PlacementWarning

__all__ = ["KinematicChain", "JointAssembly", "PlacementWarning", "ClearanceWarning"]

#: Names imported on first use: name -> module.
_LAZY = {"KinematicChain": "kinegami.chain.model", "JointAssembly": "kinegami.chain.assembly"}


__getattr__, __dir__ = lazy_names("kinegami.chain", globals(), _LAZY)
