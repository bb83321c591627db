"""The module catalog: one entry per module kind, registered by the kind's own file.

An entry (:class:`ModuleKind`) holds everything the rest of the package needs to know about a
kind: how to build its pattern from a record's parameters, its vertex and crease counts, its
unsnapped geometry and its fold. Composition, validation and the folded form look the kind up
here instead of switching on its name (docs/patterns.md, "The module catalog").

Adding a kind: write one file that builds the pattern (records ``ModuleRecord(kind, params)``),
and calls :func:`register` with its entry; import that file in ``kinegami/pattern/__init__.py``.
"""

from __future__ import annotations

import functools
from collections.abc import Callable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from kinegami._record import Record
from kinegami.errors import UnknownModuleKindError

if TYPE_CHECKING:
    from kinegami.pattern._prism import Prism
    from kinegami.pattern.counts import ModuleCounts
    from kinegami.pattern.tubular import TubularPattern

__all__ = [
    "ModuleKind",
    "UnknownModuleKindError",
    "cached_build",
    "find_kind",
    "kinds",
    "module_kind",
    "register",
    "unregister",
]

#: (exact pattern, corr): the module without the eps rules, and for each catalog vertex the
#: vertex of the exact pattern it stands for.
Unsnapped = Callable[["Prism", "TubularPattern", Mapping[str, Any]], tuple["TubularPattern", Any]]
#: (X, T): vertex positions (V, 3) in the proximal frame (e_u, e_v, e_a) and the 4x4 transform
#: from the proximal to the distal frame.
Fold = Callable[["Prism", "TubularPattern", Mapping[str, Any]], tuple[Any, Any]]




def identity_unsnapped(prism: Prism, catalog: TubularPattern, params: Mapping[str, Any]):
    """The unsnapped geometry of a module the eps rules never move: the module itself."""
    return catalog, np.arange(catalog.numVertices)


class ModuleKind(Record):
    """The catalog entry of one module kind.

    Attributes
    ----------
    name : str
        The kind, as stored in ``ModuleRecord.kind`` (``"tube"``, ``"elbow"``, ...).
    build : callable
        The public constructor, ``build(numSides, r, *args)`` -> TubularPattern.
    params : tuple of str
        The record's parameter names in the order ``build`` takes them after (numSides, r).
    counts : callable
        ``counts(prism, params)`` -> ModuleCounts: the closed-form vertex and crease counts
        that :meth:`TubularPattern.validate` compares the pattern with.
    fold : callable
        ``fold(prism, exact, params)`` -> (X, T): the unsnapped module folded at state 0 in its
        proximal frame (docs/theory/patterns.md, "The folded form").
    unsnapped : callable
        ``unsnapped(prism, catalog, params)`` -> (exact, corr): the module without the eps rules
        and the vertex of it each catalog vertex stands for (default: the module itself).
    mirror : str or None
        The kind a record of this kind becomes when the pattern is reversed (default: itself).
    """

    name: str
    build: Callable[..., TubularPattern]
    params: tuple[str, ...]
    counts: Callable[[Prism, Mapping[str, Any]], ModuleCounts]
    fold: Fold
    unsnapped: Unsnapped = identity_unsnapped
    mirror: str | None = None

    def rebuild(self, numSides: int, r: float, params: Mapping[str, Any]) -> TubularPattern:
        """The catalog pattern of a record of this kind (``build`` with the record's values)."""
        return self.build(numSides, r, *(params[name] for name in self.params))


def cached_build(build: Callable[..., TubularPattern]) -> Callable[..., TubularPattern]:
    """Cache a module constructor per argument values (and types): patterns are immutable
    values, so equal arguments may share one pattern. Errors are not cached; unhashable
    arguments bypass the cache. ``cache_clear()`` empties it."""
    cached = functools.lru_cache(maxsize=1024, typed=True)(build)

    @functools.wraps(build)
    def wrapper(*args, **kwargs):
        try:
            hash(args)
            if kwargs:
                hash(tuple(kwargs.items()))
        except TypeError:
            return build(*args, **kwargs)
        return cached(*args, **kwargs)

    wrapper.cache_clear = cached.cache_clear
    wrapper.cache_info = cached.cache_info
    return wrapper


_REGISTRY: dict[str, ModuleKind] = {}


def register(entry: ModuleKind) -> ModuleKind:
    """Add ``entry`` to the catalog (replacing an entry of the same name); returns it."""
    if not isinstance(entry, ModuleKind):
        raise TypeError(f"register needs a ModuleKind, got {type(entry).__name__}")
    _REGISTRY[entry.name] = entry
    return entry


def unregister(name: str) -> None:
    """Remove the entry of kind ``name`` (for tests that register a toy kind)."""
    _REGISTRY.pop(name, None)


def module_kind(name: str) -> ModuleKind:
    """The catalog entry of kind ``name``.

    Raises
    ------
    UnknownModuleKindError
        If no entry is registered under ``name`` (the message lists the known kinds).
    """
    try:
        return _REGISTRY[name]
    except KeyError:
        raise UnknownModuleKindError(
            f"unknown module kind {name!r}; the catalog has {', '.join(sorted(_REGISTRY))}"
        ) from None


def find_kind(name: str) -> ModuleKind | None:
    """The catalog entry of kind ``name``, or None."""
    return _REGISTRY.get(name)


def kinds() -> tuple[str, ...]:
    """The registered kinds, in registration order."""
    return tuple(_REGISTRY)
