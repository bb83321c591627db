"""How a tree is made (docs/trees.md, docs/junctions.md): cut into one sheet per leaf
(``sheets``), joined by printed junction connectors (``connector``) or folded take-offs
(``takeoffs``).

The names below load on first use, so that importing one module of the folder does not import
the others.
"""

from kinegami._lazy import lazy_names

__all__ = [
    "fabricate",
    "fit_junctions",
    "junction_problems",
    "TreeFabrication",
    "TreeSheet",
    "TakeoffOptions",
    "ConnectorOptions",
]

#: Names imported on first use: name -> module.
_LAZY = {
    "fabricate": "kinegami.fabrication.sheets",
    "fit_junctions": "kinegami.fabrication.sheets",
    "junction_problems": "kinegami.fabrication.sheets",
    "TreeFabrication": "kinegami.fabrication.sheets",
    "TreeSheet": "kinegami.fabrication.sheets",
    "TakeoffOptions": "kinegami.fabrication.takeoffs",
    "ConnectorOptions": "kinegami.fabrication.connector",
}


__getattr__, __dir__ = lazy_names("kinegami.fabrication", globals(), _LAZY)
