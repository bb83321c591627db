"""Reach (docs/reach.md): where a design's tip is and how it moves (``kinematics``: forward
kinematics and Jacobians, compiled once), and which states put it on a target without the
design passing through itself (``solve``, ``solve_many``).

The names below load on first use, so that importing one module of the folder does not import
the others.
"""

from kinegami._lazy import lazy_names

__all__ = [
    "Answer",
    "Kinematics",
    "Target",
    "Workspace",
    "kinematics",
    "solve",
    "solve_many",
    "workspace",
]

#: Names imported on first use: name -> module.
_LAZY = {
    "Kinematics": "kinegami.reach.forward",
    "kinematics": "kinegami.reach.forward",
    "Answer": "kinegami.reach.inverse",
    "Target": "kinegami.reach.inverse",
    "solve": "kinegami.reach.inverse",
    "solve_many": "kinegami.reach.inverse",
    "Workspace": "kinegami.reach.workspaces",
    "workspace": "kinegami.reach.workspaces",
}

__getattr__, __dir__ = lazy_names("kinegami.reach", globals(), _LAZY)
