"""How a tree is made (docs/trees.md, docs/junctions.md): cut into one sheet per leaf
(``sheets``), joined by printed junction connectors (``connector``) or folded take-offs
(``takeoffs``).

The names below load on first use, so that importing one module of the folder does not import
the others.
"""

import importlib

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


def __getattr__(name: str):
    try:
        module_name = _LAZY[name]
    except KeyError:
        raise AttributeError(
            f"module 'kinegami.fabrication' has no attribute {name!r}"
        ) from None
    value = getattr(importlib.import_module(module_name), name)
    globals()[name] = value  # once imported, an ordinary attribute
    return value


def __dir__() -> list[str]:
    return sorted(set(globals()) | set(_LAZY))
