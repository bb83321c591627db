"""Names of a package imported on first use (a module ``__getattr__``), so that importing one
module of a folder does not import the others (docs/architecture.md, "Lazy imports")."""

from __future__ import annotations

import importlib
from collections.abc import Callable


def lazy_names(package: str, namespace: dict, lazy: dict[str, str]) -> tuple[Callable, Callable]:
    """``__getattr__`` and ``__dir__`` for ``package`` (its globals ``namespace``) that import
    each name of ``lazy`` (name -> module) from its module on first use and keep it."""

    def attribute(name: str):
        try:
            module_name = lazy[name]
        except KeyError:
            raise AttributeError(f"module {package!r} has no attribute {name!r}") from None
        value = getattr(importlib.import_module(module_name), name)
        namespace[name] = value  # once imported, an ordinary attribute
        return value

    def names() -> list[str]:
        return sorted(set(namespace) | set(lazy))

    return attribute, names
