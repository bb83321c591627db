"""Reach (docs/reach.md): where a design's tip is and how it moves (``kinematics``: forward
kinematics and Jacobians, compiled once).

The names below load on first use, so that importing one module of the folder does not import
the others.
"""

from kinegami._lazy import lazy_names

__all__ = ["Kinematics", "kinematics"]

#: Names imported on first use: name -> module.
_LAZY = {
    "Kinematics": "kinegami.reach.forward",
    "kinematics": "kinegami.reach.forward",
}

__getattr__, __dir__ = lazy_names("kinegami.reach", globals(), _LAZY)
