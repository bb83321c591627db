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
from collections.abc import Callable, Iterable, Mapping
from typing import TYPE_CHECKING, Any

import numpy as np

from kinegami._record import Record
from kinegami.errors import InvalidParameterError, UnknownModuleKindError
from kinegami.limits import MAX_PATTERN_VERTICES

if TYPE_CHECKING:
    from kinegami.pattern._prism import Prism
    from kinegami.pattern.tubular import ModuleRecord, TubularPattern

__all__ = [
    "ModuleCounts",
    "ModuleKind",
    "UnknownModuleKindError",
    "build_pieces",
    "cached_build",
    "check_pattern_size",
    "expected_counts",
    "find_kind",
    "kinds",
    "module_kind",
    "module_vertices",
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


class ModuleCounts(Record):
    """Expected numbers of vertices, creases and (when known) mountain creases of a module:
    what a catalog entry's ``counts`` returns (its closed-form counts, written independently of
    the module's builder, so that :meth:`TubularPattern.validate` can compare a pattern with
    them)."""

    numVertices: int
    numEdges: int
    numMountains: int | None = None


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


#: Patterns each cached constructor keeps (the oldest are dropped first).
CACHE_SIZE = 1024


class CacheInfo(Record):
    """What a cached constructor's ``cache_info()`` returns (as ``functools.lru_cache``)."""

    hits: int
    misses: int
    maxsize: int
    currsize: int


def cached_build(
    build: Callable[..., TubularPattern] | None = None,
    *,
    many: Callable[[list[tuple]], list[TubularPattern]] | None = None,
) -> Callable[..., TubularPattern]:
    """Cache a module constructor per argument values (and types): patterns are immutable
    values, so equal arguments may share one pattern. Errors are not cached; unhashable
    arguments bypass the cache. ``cache_clear()`` empties it, ``cache_info()`` says how full
    it is.

    ``many``, when given, builds the patterns of a list of (distinct, hashable) argument tuples
    at once, equal bit for bit to ``build`` of each (the constructor's ``many(calls)`` attribute
    uses it for the calls not in the cache, and caches their results; :func:`build_pieces`
    calls it). Used as ``@cached_build`` or ``@cached_build(many=...)``.
    """
    if build is None:
        return functools.partial(cached_build, many=many)
    cache: dict = {}
    hits_misses = [0, 0]

    def remember(key, value) -> None:
        if len(cache) >= CACHE_SIZE:
            del cache[next(iter(cache))]
        cache[key] = value

    @functools.wraps(build)
    def wrapper(*args, **kwargs):
        key = (args, tuple(map(type, args)), tuple(kwargs.items())) if kwargs else (
            args, tuple(map(type, args)))  # fmt: skip
        try:
            value = cache[key]
        except KeyError:
            pass
        except TypeError:  # an unhashable argument
            return build(*args, **kwargs)
        else:
            hits_misses[0] += 1
            return value
        hits_misses[1] += 1
        value = build(*args, **kwargs)
        remember(key, value)
        return value

    def build_many(calls: list[tuple]) -> list[TubularPattern]:
        """``[wrapper(*args) for args in calls]``, building the missing ones in one batch."""
        keys = []
        found: dict = {}  # this call's patterns (the cache may drop some while it fills)
        missing: dict = {}
        for args in calls:
            key = (args, tuple(map(type, args)))
            try:
                if key not in found:
                    if key in cache:
                        found[key] = cache[key]
                    else:
                        missing.setdefault(key, args)
            except TypeError:
                return [wrapper(*a) for a in calls]
            keys.append(key)
        if missing:
            todo = list(missing.values())
            built = many(todo) if many is not None and len(todo) > 1 else [build(*a) for a in todo]
            for key, value in zip(missing, built, strict=True):
                remember(key, value)
                found[key] = value
            hits_misses[1] += len(missing)
        hits_misses[0] += len(keys) - len(missing)
        return [found[key] for key in keys]

    def cache_clear() -> None:
        cache.clear()
        hits_misses[:] = [0, 0]

    wrapper.many = build_many
    wrapper.cache_clear = cache_clear
    wrapper.cache_info = lambda: CacheInfo(hits_misses[0], hits_misses[1], CACHE_SIZE, len(cache))
    return wrapper


def build_pieces(pieces: Iterable[tuple[str, tuple]]) -> list[TubularPattern]:
    """The pattern of every (kind, build arguments) piece, in order: the same patterns as
    ``module_kind(kind).build(*args)`` of each, with the modules of one kind built together
    where the kind's constructor can (its ``many``)."""
    pieces = list(pieces)
    calls: dict[str, dict] = {}
    try:
        for kind, args in pieces:
            calls.setdefault(kind, {})[args] = None
    except TypeError:  # an unhashable argument: no batches
        return [module_kind(kind).build(*args) for kind, args in pieces]
    built: dict = {}
    for kind, unique in calls.items():
        build = module_kind(kind).build
        arguments = list(unique)
        many = getattr(build, "many", None)
        patterns = many(arguments) if many is not None else [build(*a) for a in arguments]
        built[kind] = dict(zip(arguments, patterns, strict=True))
    return [built[kind][args] for kind, args in pieces]


def module_vertices(kind: str, args: tuple) -> int:
    """At most how many vertices the module ``kind`` built from ``args`` has (its first argument
    is numSides n), from its counts alone: a revolute joint of L sink layers n (10 L + 6), a
    prismatic joint of M layers n (3 M + 4), an elbow 6 n + 4, a twist or tube 2 n, anything
    else 4 n (measured for n from 4 to 1024: docs/limits.md)."""
    try:
        n = int(args[0])
        if kind == "revolute":
            return n * (10 * int(args[3]) + 6)
        if kind == "prismatic":
            return n * (3 * int(args[3]) + 4)
    except (TypeError, ValueError, IndexError):
        return 0  # not a count: the module's own checks refuse it
    if kind == "elbow":
        return 6 * n + 4
    if kind in ("twist", "tube"):
        return 2 * n
    return 4 * n


def check_pattern_size(pieces: Iterable[tuple[str, tuple]], what: str = "the pattern") -> int:
    """Raise InvalidParameterError, before anything is built, when the modules ``pieces``
    ((kind, build arguments) each) would have more than ``MAX_PATTERN_VERTICES`` vertices
    together (:func:`module_vertices`); return the estimate otherwise."""
    total = 0
    modules = 0
    for kind, args in pieces:
        total += module_vertices(kind, args)
        modules += 1
    if total > MAX_PATTERN_VERTICES:
        raise InvalidParameterError(
            f"{what} would have about {total:,} crease-pattern vertices in {modules:,} modules, "
            f"more than the limit {MAX_PATTERN_VERTICES:,} (kinegami.limits."
            "MAX_PATTERN_VERTICES: each vertex costs about 250 bytes and every export and view "
            "works per vertex); use fewer joints, elbows (a larger maxAnglePerElbow), sides "
            "or layers"
        )
    return total


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


def expected_counts(record: ModuleRecord, prism: Prism) -> ModuleCounts | None:
    """The counts of one catalog module, or None for a kind the catalog does not have.

    Fix B6 (no coincident vertices, no zero-length creases) changes the reference's formulas
    in two places: a tube or twist of pattern height below eps is the empty pattern (n, 0), and
    every elbow column with h_k < eps reuses P_k and D_k (2 vertices and 2 creases fewer).
    Fix B2 removes 4 creases from the revolute joint with N >= 2 sink layers
    (docs/theory/patterns.md §6).
    """
    entry = find_kind(record.kind)
    return None if entry is None else entry.counts(prism, record.params)


def find_kind(name: str) -> ModuleKind | None:
    """The catalog entry of kind ``name``, or None."""
    return _REGISTRY.get(name)


def kinds() -> tuple[str, ...]:
    """The registered kinds, in registration order."""
    return tuple(_REGISTRY)
