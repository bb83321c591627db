"""The tubular crease pattern: plain data in the spirit of FOLD, and its composition.

A :class:`TubularPattern` is a graph drawn on the surface of a regular n-gonal prism, unrolled
into the strip 0 <= x < W (docs/theory/patterns.md section 1.4). It is immutable: every operation
returns a new pattern and the stored arrays are read-only.

Composition (section 2.2) is implemented once, in :func:`_compose_step`, which works on the
running state of the composite (its distal base, distal marker and the creases lying on the
distal base) and on the next module only. :meth:`TubularPattern.append` applies one step to two
patterns; :meth:`TubularPattern.concatenate` applies the steps to a whole list and concatenates
the arrays once, so composing m modules costs O(total size) instead of O(m * total size).
"""

from __future__ import annotations

import math
from collections.abc import Iterable, Mapping
from itertools import chain
from typing import Any

import numpy as np

from kinegami._record import Record
from kinegami.errors import InvalidParameterError, InvalidTypeError, ReadOnlyError
from kinegami.pattern._prism import EPS_FACTOR, make_prism, periodic_dx, readonly, wrap_x
from kinegami.validation import check_nonnegative

_KEY_SHIFT = np.int64(1) << np.int64(32)
_WIDTHS: dict = {}  # (n, r) -> W, as TubularPattern computes it
_ASSIGNMENT_DTYPE = np.dtype("<U1")

__all__ = ["FrozenParams", "ModuleRecord", "TubularPattern", "ValidationReport"]


_FROZEN_PARAMS_HELP = (
    "ModuleRecord.params is read-only: a pattern is a value shared (through the pattern caches) "
    "by every joint and link built with the same parameters, so changing it would change them "
    "all. Build a new record instead, e.g. ModuleRecord(record.kind, {**record.params, name: "
    "value}), or a new pattern from the module's constructor"
)


_RECORD_HELP = (
    "a record is shared by every pattern built with the same parameters; build a new one, e.g. "
    "ModuleRecord(record.kind, {**record.params, name: value})"
)


class FrozenParams(Mapping):
    """A read-only mapping of a module's parameters (what :attr:`ModuleRecord.params` holds).

    Reads like a dict (``params["height"]``, ``dict(params)`` for a mutable copy); item
    assignment and deletion raise :class:`~kinegami.errors.InvalidTypeError`. Hashable.
    """

    __slots__ = ("_data",)

    def __init__(self, data: Mapping[str, Any] | Iterable = ()) -> None:
        object.__setattr__(self, "_data", dict(data))

    def __getitem__(self, key: str) -> Any:
        return self._data[key]

    def __iter__(self):
        return iter(self._data)

    def __len__(self) -> int:
        return len(self._data)

    def __contains__(self, key) -> bool:
        return key in self._data

    def __setitem__(self, key, value) -> None:
        raise InvalidTypeError(f"cannot set params[{key!r}]: {_FROZEN_PARAMS_HELP}")

    def __delitem__(self, key) -> None:
        raise InvalidTypeError(f"cannot delete params[{key!r}]: {_FROZEN_PARAMS_HELP}")

    def __setattr__(self, name: str, value) -> None:
        raise InvalidTypeError(f"cannot set {name!r}: {_FROZEN_PARAMS_HELP}")

    def __hash__(self) -> int:
        return hash(tuple(sorted(self._data.items())))

    def __eq__(self, other) -> bool:
        if isinstance(other, FrozenParams):
            return self._data == other._data
        return self._data == other if isinstance(other, Mapping) else NotImplemented

    def __repr__(self) -> str:
        return repr(self._data)

    def __reduce__(self):
        return (FrozenParams, (self._data,))


class _RecordFields(Record):
    kind: str
    params: Mapping[str, Any]


class ModuleRecord(_RecordFields):
    """Which catalog module (and with which parameters) a piece of a pattern came from.

    A value: read-only, equal and hashable by kind and parameters.

    Attributes
    ----------
    kind : str
        A kind registered in :mod:`kinegami.pattern.catalog`: ``"tube"``, ``"twist"``,
        ``"elbow"``, ``"revolute"``, ``"rebo"``, ``"prismatic"``, ``"start_tip"``,
        ``"end_tip"``, ``"waypoint"``.
    params : Mapping[str, Any]
        The validated parameters the module was built with (same names as the constructor),
        stored read-only (:class:`FrozenParams`): records are shared by every pattern built
        with the same parameters.
    """

    __slots__ = ()

    def __new__(cls, kind: str, params: Mapping[str, Any] | None = None) -> ModuleRecord:
        if not isinstance(params, FrozenParams):
            params = FrozenParams(() if params is None else params)
        return tuple.__new__(cls, (kind, params))

    @classmethod
    def _of(cls, kind: str, params: dict) -> ModuleRecord:
        """A record taking ownership of the new dict ``params`` (the builders' fast path)."""
        frozen = object.__new__(FrozenParams)
        object.__setattr__(frozen, "_data", params)
        return tuple.__new__(cls, (kind, frozen))

    def __setattr__(self, name: str, value) -> None:
        raise ReadOnlyError(f"ModuleRecord.{name} is read-only: {_RECORD_HELP}")

    def __delattr__(self, name: str) -> None:
        raise ReadOnlyError(f"ModuleRecord.{name} is read-only (not deletable): {_RECORD_HELP}")

    def __reduce__(self):
        return (ModuleRecord, (self.kind, self.params))


class ValidationReport(Record):
    """Result of :meth:`TubularPattern.validate`: every problem found (empty when fine)."""

    problems: tuple[str, ...] = ()

    @property
    def ok(self) -> bool:
        """True when no problem was found."""
        return not self.problems

    def __str__(self) -> str:
        if self.ok:
            return "pattern OK"
        return f"{len(self.problems)} problem(s):\n" + "\n".join(f"- {p}" for p in self.problems)


def _edge_keys(edges: np.ndarray) -> np.ndarray:
    """One int64 per crease identifying its unordered vertex pair."""
    lo = np.minimum(edges[:, 0], edges[:, 1]).astype(np.int64)
    hi = np.maximum(edges[:, 0], edges[:, 1]).astype(np.int64)
    return lo * _KEY_SHIFT + hi


def _repeats(keys: np.ndarray) -> np.ndarray:
    """Boolean mask of the keys equal to an earlier key (all but the first of each group)."""
    order = np.argsort(keys, kind="stable")  # equal keys stay in their order: the first leads
    ordered = keys[order]
    repeated = np.zeros(keys.shape[0], dtype=bool)
    repeated[order[1:][ordered[1:] == ordered[:-1]]] = True
    return repeated


def first_occurrence_mask(keys: np.ndarray) -> np.ndarray:
    """Boolean mask keeping the first crease of every group of equal keys."""
    return ~_repeats(keys)


class TubularPattern:
    """A crease pattern on the surface of a regular n-gonal tube (docs/theory/patterns.md 1.4).

    Parameters
    ----------
    numSides : int
        Number of sides n of the tube, even and >= 4.
    r : float
        Circumradius of the tube's polygon (the length unit of everything else).
    vertices_coords : array_like, shape (N, 2)
        Vertex positions (x, y) in pattern coordinates: x is the arc length around the tube from
        the reference point, in [0, W); y is the distance along the tube axis.
    edges_vertices : array_like of int, shape (M, 2)
        The creases as pairs of vertex indices. A crease is the shortest path on the tube between
        its two vertices (horizontal displacement taken in (-W/2, W/2]).
    edges_assignment : array_like of str, shape (M,)
        ``"M"`` (mountain, convex seen from outside) or ``"V"`` (valley) for each crease.
    proximalBase, distalBase : array_like of int, shape (n,), or None
        Indices of the start and end polygon vertices, in order k = 0 .. n-1; None for a start
        tip's proximal side or an end tip's distal side.
    proximalMarker, distalMarker : array_like, shape (2,)
        Position (x, y) of the reference point of the proximal and distal boundary frames.
    height : float
        Extent H of the pattern along the tube axis (>= 0).
    modules : iterable of ModuleRecord, optional
        The catalog modules this pattern is made of, in order (used by :meth:`validate`).

    Notes
    -----
    Everything is stored as read-only numpy arrays; patterns are values. ``show()`` and
    ``save()`` (plotting and export) are thin delegates to :mod:`kinegami.viz` and
    :mod:`kinegami.export`, kept out of this module.

    Examples
    --------
    >>> from kinegami.pattern import TubeFittingPattern, ElbowFittingPattern
    >>> import numpy as np
    >>> p = TubeFittingPattern(4, 1.0, 1.0).append(ElbowFittingPattern(4, 1.0, np.pi / 2, 0.0))
    >>> p.numVertices, p.numEdges, round(p.height, 6)
    (22, 32, 4.414214)
    """

    __slots__ = (
        "numSides",
        "r",
        "width",
        "height",
        "vertices_coords",
        "edges_vertices",
        "edges_assignment",
        "proximalBase",
        "distalBase",
        "proximalMarker",
        "distalMarker",
        "modules",
        "removedDuplicates",
        "_distal_keys",
        "_has_internal_duplicates",
        "_module_vertices",
    )

    def __init__(
        self,
        numSides: int,
        r: float,
        vertices_coords,
        edges_vertices,
        edges_assignment,
        proximalBase,
        distalBase,
        proximalMarker,
        distalMarker,
        height: float,
        modules: Iterable[ModuleRecord] = (),
    ) -> None:
        prism = make_prism(numSides, r)
        n = prism.numSides
        vertices = np.array(vertices_coords, dtype=float)
        if vertices.size == 0:
            vertices = vertices.reshape(0, 2)
        if vertices.ndim != 2 or vertices.shape[1] != 2:
            raise InvalidParameterError(
                f"vertices_coords must have shape (N, 2), got {vertices.shape}"
            )
        if not np.all(np.isfinite(vertices)):
            raise InvalidParameterError("vertices_coords must be finite")
        edges = np.array(edges_vertices)
        if edges.size == 0:
            edges = edges.reshape(0, 2).astype(np.intp)
        if not np.issubdtype(edges.dtype, np.integer):
            raise InvalidTypeError(f"edges_vertices must be integers, got dtype {edges.dtype}")
        if edges.ndim != 2 or edges.shape[1] != 2:
            raise InvalidParameterError(f"edges_vertices must have shape (M, 2), got {edges.shape}")
        edges = edges.astype(np.intp)
        if edges.size and (edges.min() < 0 or edges.max() >= vertices.shape[0]):
            raise InvalidParameterError(
                f"edges_vertices must index the {vertices.shape[0]} vertices, "
                f"got indices in [{edges.min()}, {edges.max()}]"
            )
        assignment = np.array(edges_assignment, dtype=_ASSIGNMENT_DTYPE).reshape(-1)
        if assignment.shape[0] != edges.shape[0]:
            raise InvalidParameterError(
                f"edges_assignment must have one label per crease ({edges.shape[0]}), "
                f"got {assignment.shape[0]}"
            )
        bad = ~np.isin(assignment, ("M", "V"))
        if bad.any():
            raise InvalidParameterError(
                f"edges_assignment must be 'M' or 'V', got {sorted(set(assignment[bad]))}"
            )
        bases = []
        for name, base in (("proximalBase", proximalBase), ("distalBase", distalBase)):
            if base is not None:
                base = np.array(base)
                if not np.issubdtype(base.dtype, np.integer) or base.shape != (n,):
                    raise InvalidParameterError(
                        f"{name} must be None or {n} vertex indices, got {base!r}"
                    )
                if base.min() < 0 or base.max() >= vertices.shape[0]:
                    raise InvalidParameterError(f"{name} indices out of range: {base!r}")
                base = base.astype(np.intp)
            bases.append(base)
        markers = []
        for name, marker in (("proximalMarker", proximalMarker), ("distalMarker", distalMarker)):
            marker = np.array(marker, dtype=float)
            if marker.shape != (2,) or not np.all(np.isfinite(marker)):
                raise InvalidParameterError(f"{name} must be a finite point (x, y), got {marker!r}")
            markers.append(marker)
        height = check_nonnegative("height", height)
        modules = tuple(modules)
        if not all(isinstance(m, ModuleRecord) for m in modules):
            raise InvalidTypeError("modules must be ModuleRecord objects")
        self._init(
            n, prism.r, vertices, edges, assignment, bases[0], bases[1], markers[0], markers[1],
            height, modules, 0, None, None, None,
        )  # fmt: skip

    def _init(
        self,
        n: int,
        r: float,
        vertices: np.ndarray,
        edges: np.ndarray,
        assignment: np.ndarray,
        proximal: np.ndarray | None,
        distal: np.ndarray | None,
        proximal_marker: np.ndarray,
        distal_marker: np.ndarray,
        height: float,
        modules: tuple[ModuleRecord, ...],
        removed: int,
        distal_keys: np.ndarray | None,
        internal_duplicates: bool | None,
        module_vertices: tuple[np.ndarray, ...] | None,
        frozen: bool = False,
    ) -> None:
        # every module of a chain passes here: the arrays are frozen in place (setflags, not a
        # helper call; not at all when the caller says they are: ``frozen``) and the slots set
        # through object.__setattr__ (bound once)
        s = object.__setattr__
        if not frozen:
            vertices.setflags(write=False)
            edges.setflags(write=False)
            assignment.setflags(write=False)
            proximal_marker.setflags(write=False)
            distal_marker.setflags(write=False)
            if proximal is not None:
                proximal.setflags(write=False)
            if distal is not None:
                distal.setflags(write=False)
            if distal_keys is not None:
                distal_keys.setflags(write=False)
        width = _WIDTHS.get((n, r))
        if width is None:
            width = _WIDTHS[(n, r)] = float(n * 2.0 * r * np.sin(np.pi / n))
        s(self, "numSides", int(n))
        s(self, "r", float(r))
        s(self, "width", width)
        s(self, "height", float(height))
        s(self, "vertices_coords", vertices)
        s(self, "edges_vertices", edges)
        s(self, "edges_assignment", assignment)
        s(self, "proximalBase", proximal)
        s(self, "distalBase", distal)
        s(self, "proximalMarker", proximal_marker)
        s(self, "distalMarker", distal_marker)
        s(self, "modules", modules)
        s(self, "removedDuplicates", int(removed))
        s(self, "_distal_keys", distal_keys)
        s(self, "_has_internal_duplicates", internal_duplicates)
        s(self, "_module_vertices", module_vertices)

    @classmethod
    def _build(cls, n, r, vertices, edges, assignment, proximal, distal, pm, dm, height, modules,
               removed=0, distal_keys=None, internal_duplicates=None,
               module_vertices=None, frozen=False):  # fmt: skip
        """Internal constructor from arrays that are already valid (no checks, no copies).

        ``module_vertices``: see :attr:`module_vertices`; None for a single module (its own
        vertices, in order) or when unknown. ``frozen``: every array given is read-only already
        (the batch builders', whose arrays are rows of read-only blocks).
        """
        self = object.__new__(cls)
        self._init(n, r, vertices, edges, assignment, proximal, distal, pm, dm, height, modules,
                   removed, distal_keys, internal_duplicates, module_vertices,
                   frozen)  # fmt: skip
        return self

    def __setattr__(self, name: str, value) -> None:
        raise AttributeError(f"TubularPattern is immutable (cannot set {name!r})")

    def __delattr__(self, name: str) -> None:
        raise AttributeError(f"TubularPattern is immutable (cannot delete {name!r})")

    # ----------------------------------------------------------------------------------------
    # Derived quantities

    @property
    def sideLength(self) -> float:
        """Side length b = 2 r sin(pi/n) of the polygon (width of one panel)."""
        return 2.0 * self.r * float(np.sin(np.pi / self.numSides))

    @property
    def eps(self) -> float:
        """Length tolerance 1e-4 b used to identify points (docs/theory/patterns.md 1.1)."""
        return EPS_FACTOR * self.sideLength

    @property
    def numVertices(self) -> int:
        """Number of vertices N."""
        return int(self.vertices_coords.shape[0])

    @property
    def numEdges(self) -> int:
        """Number of creases M."""
        return int(self.edges_vertices.shape[0])

    @property
    def numMountains(self) -> int:
        """Number of mountain creases."""
        return int(np.count_nonzero(self.edges_assignment == "M"))

    @property
    def numValleys(self) -> int:
        """Number of valley creases."""
        return int(np.count_nonzero(self.edges_assignment == "V"))

    @property
    def kind(self) -> str:
        """The module kind when the pattern is one catalog module, else ``"composite"``
        (or ``"custom"`` for a pattern built without module records)."""
        if len(self.modules) == 1:
            return self.modules[0].kind
        return "composite" if self.modules else "custom"

    @property
    def module_vertices(self) -> tuple[np.ndarray, ...] | None:
        """Where every module's vertices went: one read-only int array per record of
        :attr:`modules`, giving the vertex of this pattern that each of the module's own
        vertices became (in the order the module's constructor numbers them).

        Composition computes these; the folded form uses them to place every module. None when
        they are not known: a reversed composite, or a pattern built by hand with several module
        records (a single record stands for all the vertices, in order).
        """
        mv = self._module_vertices
        if mv is None and len(self.modules) == 1:
            mv = (readonly(np.arange(self.numVertices)),)
            object.__setattr__(self, "_module_vertices", mv)
        return mv

    @property
    def isEmpty(self) -> bool:
        """True for a pattern that only consists of its base polygon (e.g. a waypoint)."""
        return (
            self.numEdges == 0
            and self.numVertices == self.numSides
            and self.proximalBase is not None
            and self.distalBase is not None
            and np.array_equal(self.proximalBase, self.distalBase)
            and np.array_equal(self.proximalMarker, self.distalMarker)
        )

    def crease_vectors(self) -> np.ndarray:
        """Flat displacement (dx, dy) from the first to the second vertex of every crease.

        dx is the representative in (-W/2, W/2] of the x difference, i.e. the crease's shortest
        path on the tube (section 1.4). Shape (M, 2), pattern units.
        """
        v = self.vertices_coords
        d = v[self.edges_vertices[:, 1]] - v[self.edges_vertices[:, 0]]
        d[:, 0] = periodic_dx(d[:, 0], self.width)
        return d

    def edge_lengths(self) -> np.ndarray:
        """Flat length of every crease (its shortest path on the tube), shape (M,)."""
        return np.hypot(*self.crease_vectors().T)

    def __repr__(self) -> str:
        return (
            f"TubularPattern(kind={self.kind!r}, numSides={self.numSides}, r={self.r:g}, "
            f"numVertices={self.numVertices}, numEdges={self.numEdges}, "
            f"height={self.height:.6g})"
        )

    # ----------------------------------------------------------------------------------------
    # Operations

    def append(self, other: TubularPattern) -> TubularPattern:
        """Return this pattern followed by ``other`` (docs/theory/patterns.md 2.2).

        ``other`` is translated so that its proximal marker lands on this pattern's distal
        marker, its proximal base is identified with this pattern's distal base (for the cyclic
        shift that makes them coincide), and duplicate creases are dropped keeping this
        pattern's. The cost is proportional to the size of ``other`` plus one copy of the
        arrays.

        Raises
        ------
        InvalidParameterError
            If numSides or r differ, if this pattern has no distal base (end tip), if ``other``
            has no proximal base (start tip) or if the bases cannot be matched.
        """
        _check_composable(self, other, 1)
        state = _ComposeState.after(self)
        step = _compose_step(state, other, 1)
        if step is None:
            return self
        vertices = np.concatenate([self.vertices_coords, step.vertices])
        edges = np.concatenate([self.edges_vertices, step.edges])
        assignment = np.concatenate([self.edges_assignment, step.assignment])
        return TubularPattern._build(
            self.numSides, self.r, vertices, edges, assignment,
            self.proximalBase, step.state.distal_idx, self.proximalMarker, step.state.marker,
            self.height + other.height, self.modules + other.modules,
            self.removedDuplicates + other.removedDuplicates + step.removed,
            step.state.distal_keys, self._has_internal_duplicates,
            _join_placements(self.module_vertices, _placed(other, step.mapping)),
        )  # fmt: skip

    @classmethod
    def concatenate(cls, patterns: Iterable[TubularPattern]) -> TubularPattern:
        """Compose many patterns in one pass; same result as ``p0.append(p1).append(p2)...``.

        The arrays are concatenated once at the end, so a chain of m modules is composed in
        O(total size) time.

        Raises
        ------
        InvalidParameterError
            For an empty list, or for any pair that :meth:`append` would reject.
        """
        patterns = list(patterns)
        if not patterns:
            raise InvalidParameterError("concatenate needs at least one pattern, got none")
        for i, p in enumerate(patterns):
            if not isinstance(p, TubularPattern):
                raise InvalidTypeError(f"patterns[{i}] must be a TubularPattern, got {p!r}")
        first = patterns[0]
        n, r = first.numSides, first.r
        if not (
            all(p.numSides == n and p.r == r and p.proximalBase is not None for p in patterns[1:])
            and all(p.distalBase is not None for p in patterns[:-1])
        ):  # the common case in one pass; otherwise find the first pair at fault (and its r
            # may still be close enough)
            for i in range(1, len(patterns)):
                _check_composable(first, patterns[i], i, previous=patterns[i - 1])
        if len(patterns) == 1:
            return first
        return _compose_all(first, patterns)

    def reversed(self) -> TubularPattern:
        """The pattern read from the other end (docs/theory/patterns.md 2.4).

        y is mapped to 2 y0 + H - y (y0 = proximal marker y), the two bases are swapped, the x
        coordinates of the two markers are swapped and labels are kept. The mirror image of the
        folded tube through a cross-section plane; used to make the start tip from the end tip.
        """
        y0 = float(self.proximalMarker[1])
        vertices = self.vertices_coords.copy()
        vertices[:, 1] = 2.0 * y0 + self.height - vertices[:, 1]
        from kinegami.pattern.catalog import find_kind

        def mirrored(record: ModuleRecord) -> ModuleRecord:
            entry = find_kind(record.kind)
            if entry is None or entry.mirror is None:
                return record
            return ModuleRecord(entry.mirror, record.params)

        modules = tuple(mirrored(m) for m in reversed(self.modules))
        return TubularPattern._build(
            self.numSides, self.r, vertices, self.edges_vertices.copy(),
            self.edges_assignment.copy(), _copy_or_none(self.distalBase),
            _copy_or_none(self.proximalBase),
            np.array([self.distalMarker[0], y0]),
            np.array([self.proximalMarker[0], y0 + self.height]),
            self.height, modules, self.removedDuplicates, None, self._has_internal_duplicates,
        )  # fmt: skip

    def validate(self) -> ValidationReport:
        """Check the pattern and return a report listing every problem found.

        Checks: vertices with x outside [0, W), duplicate vertices (closer than eps), zero-length
        creases, duplicate creases, collinear overlapping creases, vertices lying inside a crease
        they do not end on, creases wider than one panel (|dx| > b + eps), bases that do not
        match their markers (section 1.4) and, for patterns made of catalog modules,
        vertex / crease counts that differ from the closed-form counts of section 3.
        """
        from kinegami.pattern._audit import audit_pattern

        return ValidationReport(tuple(audit_pattern(self)))

    def show(self, **options):
        """Draw the flattened pattern with matplotlib (valley folds red, mountain folds blue,
        boundary, glue tab and cut outline); returns (figure, axes). See kinegami.viz."""
        from kinegami.viz.pattern_plot import show_pattern

        return show_pattern(self, **options)

    def save(self, dxfName=None, **options):
        """Write the flattened sheet for fabrication: DXF, or SVG when the name ends in .svg.

        Written atomically; missing folders are created. See docs/fabrication.md for layers,
        colours, units (1 pattern unit = 1 mm unless ``units``/``scale``) and perforation.
        """
        from kinegami.export import save_pattern

        return save_pattern(self, dxfName, **options)

    # ----------------------------------------------------------------------------------------
    # Internal helpers for composition

    def _get_distal_keys(self) -> np.ndarray:
        """Keys of the creases whose two ends are both distal base vertices (cached)."""
        if self._distal_keys is None:
            if self.distalBase is None:
                keys = np.zeros(0, dtype=np.int64)
            else:
                keys = _keys_within(_edge_keys(self.edges_vertices), self.distalBase)
            object.__setattr__(self, "_distal_keys", readonly(keys))
        return self._distal_keys

    def _get_internal_duplicates(self) -> bool:
        """Whether two of this pattern's own creases join the same two vertices (cached)."""
        if self._has_internal_duplicates is None:
            keys = _edge_keys(self.edges_vertices)
            value = bool(np.unique(keys).shape[0] != keys.shape[0])
            object.__setattr__(self, "_has_internal_duplicates", value)
        return self._has_internal_duplicates


def _placed(pattern: TubularPattern, mapping: np.ndarray) -> tuple[np.ndarray, ...] | None:
    """``pattern.module_vertices`` renumbered by ``mapping`` (its vertex -> composite vertex)."""
    if pattern._module_vertices is None and len(pattern.modules) == 1:
        return (readonly(mapping),)
    own = pattern.module_vertices
    return None if own is None else tuple(readonly(mapping[v]) for v in own)


def _join_placements(first, second):
    return None if first is None or second is None else first + second


def _compose_all(first: TubularPattern, patterns: list[TubularPattern]) -> TubularPattern:
    """``patterns[0]`` followed by every other pattern (already checked to be composable).

    The same result as applying :func:`_compose_step` to each pattern in turn, computed in a
    few whole-array passes: the markers (a scalar recurrence) first, then every module's
    translated and wrapped vertices at once, all cyclic shifts at once, the identification of
    base vertices by following each proximal base vertex to the distal base vertex it lands on,
    and the duplicate creases. A crease can only repeat an earlier one when both its ends are
    base vertices shared with the module before, and then the earlier one is the first crease
    on those two vertices, whichever module it came from: the first one wins.
    """
    n, W, eps = first.numSides, first.width, first.eps
    items = [
        (i, p) for i, p in enumerate(patterns)
        if i > 0 and (p.edges_vertices.shape[0] or not p.isEmpty)
    ]  # fmt: skip
    if not items:
        return first
    m = len(items)
    pats = [p for _, p in items]
    # 1. the markers: module k is translated by offsets[k], the composite ends at (mx, my)
    #    (a scalar recurrence on Python floats, the markers read in one numpy call)
    markers = np.concatenate([a for p in pats for a in (p.proximalMarker, p.distalMarker)])
    markers = markers.tolist()
    offsets = []
    mx, my = (float(v) for v in first.distalMarker)
    high = W - eps  # wrap_scalar, inlined: x mod W, snapped to 0 within eps of 0 or W
    four = iter(markers)
    for px, py, dx, dy in zip(four, four, four, four, strict=True):
        ox, oy = mx - px, my - py
        offsets += (ox, oy)
        x = (dx + ox) % W
        mx, my = 0.0 if x < eps or x > high else x, dy + oy
    height = first.height
    for p in pats:  # in order: a float sum
        height += p.height
    removed = first.removedDuplicates + sum(p.removedDuplicates for p in pats)
    modules = first.modules + tuple(chain.from_iterable(p.modules for p in pats))
    offsets = np.array(offsets).reshape(m, 2)
    sizes = np.array([p.vertices_coords.shape[0] for p in pats], dtype=np.intp)
    # 2. every module's vertices, translated and wrapped; slots are module vertices, numbered
    #    after the first pattern's vertices (slot s < N0 is vertex s of the first pattern)
    N0 = first.numVertices
    starts = np.zeros(m, dtype=np.intp)
    np.cumsum(sizes[:-1], out=starts[1:])
    coords = np.concatenate([p.vertices_coords for p in pats])
    coords += np.repeat(offsets, sizes, axis=0)
    coords[:, 0] = wrap_x(coords[:, 0], W, eps)
    proximal = np.concatenate([p.proximalBase for p in pats]) + np.repeat(starts, n)
    last_distal = pats[-1].distalBase
    distal = np.concatenate([p.distalBase for p in pats[:-1]] + [first.distalBase[:0]])
    distal = distal + np.repeat(starts[:-1], n)
    # 3. the cyclic shift of every module: first j with base k on previous distal k + j
    target = np.concatenate([first.vertices_coords[first.distalBase], coords[distal]])
    target = target.reshape(m, n, 2)
    base = coords[proximal].reshape(m, n, 2)
    roll = (np.arange(n)[:, None] + np.arange(n)[None, :]) % n  # roll[j, k] = k + j mod n
    rolled = target[:, roll, :] - base[:, None, :, :]
    good = (np.abs(periodic_dx(rolled[..., 0], W)) < eps) & (np.abs(rolled[..., 1]) < eps)
    good = good.all(axis=2)
    found = good.any(axis=1)
    if not found.all():
        k = int(np.flatnonzero(~found)[0])
        state = _ComposeState(n, W, eps, None, None, target[k], None, 0)
        _find_shift(state, base[k], items[k][0])  # raises with the module's index
    shift = good.argmax(axis=1)
    # 4. identify each proximal base vertex with the previous distal base vertex it lands on
    #    (following degenerate modules whose distal base is their proximal base)
    previous = np.empty((m, n), dtype=np.intp)
    previous[0] = first.distalBase
    previous[1:] = (N0 + distal).reshape(m - 1, n)
    previous = previous[np.arange(m)[:, None], (np.arange(n)[None, :] + shift[:, None]) % n]
    S = int(sizes.sum())
    ref = np.arange(N0 + S)
    ref[N0 + proximal] = previous.ravel()
    while True:
        followed = ref[ref]
        if np.array_equal(followed, ref):
            break
        ref = followed
    is_new = np.ones(S, dtype=bool)
    is_new[proximal] = False
    num_new = int(np.count_nonzero(is_new))
    value = np.empty(N0 + S, dtype=np.intp)
    value[:N0] = np.arange(N0)
    value[N0:][is_new] = np.arange(N0, N0 + num_new)
    index = value[ref]  # composite vertex of every slot
    # 5. creases, and the duplicates among those joining two shared base vertices
    local = [p.edges_vertices for p in pats]
    counts = np.array([e.shape[0] for e in local], dtype=np.intp)
    slot_edges = np.concatenate(local) + np.repeat(N0 + starts, counts)[:, None]
    edges = index[slot_edges]
    assignment = np.concatenate([p.edges_assignment for p in pats])
    keep = np.ones(edges.shape[0], dtype=bool)
    flagged = [
        k for k, p in enumerate(pats)
        if p._has_internal_duplicates is not False and p._get_internal_duplicates()
    ]  # fmt: skip
    if flagged:
        edge_starts = np.concatenate([[0], np.cumsum(counts)])
        for k in flagged:
            a, b = edge_starts[k], edge_starts[k + 1]
            keep[a:b] &= first_occurrence_mask(_edge_keys(edges[a:b]))
    shared = np.zeros(N0 + num_new, dtype=bool)
    shared[index[N0 + proximal]] = True
    old_edges = first.edges_vertices
    old_sub = old_edges[shared[old_edges[:, 0]] & shared[old_edges[:, 1]]]
    sub = np.flatnonzero(shared[edges[:, 0]] & shared[edges[:, 1]])
    if sub.shape[0]:
        keys = _edge_keys(np.concatenate([old_sub, edges[sub]]))
        keep[sub[_repeats(keys)[old_sub.shape[0] :]]] = False
    dropped = int(keep.shape[0] - np.count_nonzero(keep))
    if dropped:
        edges, assignment = edges[keep], assignment[keep]
    removed += dropped
    placements = first.module_vertices
    if placements is not None:
        placements = list(placements)
        bounds = zip((N0 + starts).tolist(), (N0 + starts + sizes).tolist(), strict=True)
        readonly(index)  # its slices are read-only views
        if all(p._module_vertices is None and len(p.modules) == 1 for p in pats):
            placements += [index[a:b] for a, b in bounds]  # _placed's common case, at once
        else:
            for p, (a, b) in zip(pats, bounds, strict=True):
                own = _placed(p, index[a:b])
                if own is None:
                    placements = None
                    break
                placements.extend(own)
        placements = None if placements is None else tuple(placements)
    distal_idx = None if last_distal is None else index[N0 + starts[-1] + last_distal]
    return TubularPattern._build(
        n, first.r, np.concatenate([first.vertices_coords, coords[is_new]]),
        np.concatenate([first.edges_vertices, edges]),
        np.concatenate([first.edges_assignment, assignment]), first.proximalBase, distal_idx,
        first.proximalMarker, np.array([mx, my]), height, modules, removed, None,
        first._has_internal_duplicates, placements,
    )  # fmt: skip


def _copy_or_none(array: np.ndarray | None) -> np.ndarray | None:
    return None if array is None else array.copy()


def _keys_within(keys: np.ndarray, vertex_set: np.ndarray) -> np.ndarray:
    """The keys whose two vertices both belong to ``vertex_set``."""
    if keys.shape[0] == 0:
        return keys[:0]
    lo = keys // _KEY_SHIFT
    hi = keys % _KEY_SHIFT
    return keys[np.isin(lo, vertex_set) & np.isin(hi, vertex_set)]


def _check_composable(
    first: TubularPattern, other: TubularPattern, index: int, previous: TubularPattern | None = None
) -> None:
    """Raise unless ``other`` may follow ``previous`` (default ``first``) in a composite."""
    if not isinstance(other, TubularPattern):
        raise InvalidTypeError(f"can only append a TubularPattern, got {other!r}")
    previous = first if previous is None else previous
    if other.numSides != first.numSides:
        raise InvalidParameterError(
            f"cannot append a pattern with numSides={other.numSides} to one with "
            f"numSides={first.numSides} (they must be equal)"
        )
    if not math.isclose(other.r, first.r, rel_tol=1e-12, abs_tol=0.0):
        raise InvalidParameterError(
            f"cannot append a pattern with r={other.r!r} to one with r={first.r!r} "
            "(they must be equal)"
        )
    if previous.distalBase is None:
        raise InvalidParameterError(
            f"cannot append pattern {index} after a pattern without a distal base "
            f"(kind={previous.kind!r}); nothing may follow an end tip"
        )
    if other.proximalBase is None:
        raise InvalidParameterError(
            f"cannot append pattern {index} (kind={other.kind!r}): it has no proximal base; "
            "a start tip may only begin a pattern"
        )


class _ComposeState(Record):
    """What composition needs to know about the pattern built so far."""

    n: int
    W: float
    eps: float
    marker: np.ndarray  # distal marker (2,)
    distal_idx: np.ndarray | None  # global indices of the distal base, in order
    distal_xy: np.ndarray | None  # their coordinates (n, 2)
    distal_keys: np.ndarray  # keys of creases with both ends on the distal base
    next_index: int  # number of vertices so far

    @classmethod
    def after(cls, pattern: TubularPattern) -> _ComposeState:
        distal = pattern.distalBase
        return cls(
            pattern.numSides,
            pattern.width,
            pattern.eps,
            pattern.distalMarker,
            distal,
            None if distal is None else pattern.vertices_coords[distal],
            pattern._get_distal_keys(),
            pattern.numVertices,
        )


class _Step(Record):
    mapping: np.ndarray  # composite vertex of each of the module's vertices
    vertices: np.ndarray
    edges: np.ndarray
    assignment: np.ndarray
    removed: int
    state: _ComposeState


def _find_shift(state: _ComposeState, base_xy: np.ndarray, index: int) -> int:
    """Cyclic shift j with base vertex k of the new module on distal vertex k + j (section 2.2)."""
    n, W, eps = state.n, state.W, state.eps
    target = state.distal_xy
    dx = periodic_dx(target[:, 0] - base_xy[0, 0], W)
    dy = target[:, 1] - base_xy[0, 1]
    candidates = np.flatnonzero((np.abs(dx) < eps) & (np.abs(dy) < eps))
    for j in candidates.tolist():
        rolled = target[(np.arange(n) + j) % n] - base_xy
        if (np.abs(periodic_dx(rolled[:, 0], W)) < eps).all() and (
            np.abs(rolled[:, 1]) < eps
        ).all():
            return j
    raise InvalidParameterError(
        f"cannot append pattern {index}: its proximal base does not coincide with the previous "
        f"distal base for any cyclic shift (proximal base starts at {base_xy[0]}, distal base at "
        f"{target[0]}, tolerance {eps:.3g})"
    )


def _compose_step(state: _ComposeState, other: TubularPattern, index: int) -> _Step | None:
    """Append ``other`` to the composite described by ``state`` (docs/theory/patterns.md 2).

    Returns the new vertices, the re-indexed creases that survive duplicate removal and the new
    state, or None when ``other`` is empty (a waypoint: nothing changes). The work is
    proportional to the size of ``other``.
    """
    if other.isEmpty:
        return None
    n, W, eps = state.n, state.W, state.eps
    # 1. translate by mu_d(A) - mu_p(B) and wrap
    offset = state.marker - other.proximalMarker
    coords = other.vertices_coords + offset
    coords[:, 0] = wrap_x(coords[:, 0], W, eps)
    marker = other.distalMarker + offset
    marker[0] = wrap_x(marker[0:1], W, eps)[0]
    # 3. cyclic shift
    base = other.proximalBase
    j = _find_shift(state, coords[base], index)
    # 4. identify the base vertices, number the others after the existing ones
    local_edges = other.edges_vertices
    is_new = np.ones(other.numVertices, dtype=bool)
    is_new[base] = False
    mapping = np.empty(other.numVertices, dtype=np.intp)
    mapping[base] = state.distal_idx[(np.arange(n) + j) % n]
    num_new = other.numVertices - n
    mapping[is_new] = np.arange(state.next_index, state.next_index + num_new)
    edges = mapping[local_edges]
    keys = _edge_keys(edges)
    # 5. drop creases already present (only creases joining two shared base vertices can
    #    repeat one of the composite's) and repeats inside the new module; the first one wins
    keep = np.ones(keys.shape[0], dtype=bool)
    if state.distal_keys.shape[0]:
        on_base = ~is_new[local_edges]
        candidates = np.flatnonzero(on_base[:, 0] & on_base[:, 1])
        if candidates.shape[0]:
            repeated = (keys[candidates, None] == state.distal_keys[None, :]).any(axis=1)
            keep[candidates[repeated]] = False
    if other._get_internal_duplicates():
        keep &= first_occurrence_mask(keys)
    removed = int(keep.shape[0] - np.count_nonzero(keep))
    if removed:
        edges, keys = edges[keep], keys[keep]
        assignment = other.edges_assignment[keep]
    else:
        assignment = other.edges_assignment
    # 6. new distal base and marker, and the creases lying on the new distal base
    if other.distalBase is None:
        distal_idx, distal_xy, distal_keys = None, None, np.zeros(0, dtype=np.int64)
    else:
        distal_idx = mapping[other.distalBase]
        distal_xy = coords[other.distalBase]
        on_distal = np.zeros(other.numVertices, dtype=bool)
        on_distal[other.distalBase] = True
        on_distal = on_distal[local_edges]
        if removed:
            on_distal = on_distal[keep]
        distal_keys = keys[on_distal[:, 0] & on_distal[:, 1]]
        if state.distal_keys.shape[0] and not is_new[other.distalBase].all():
            # degenerate module whose distal base reuses vertices of the previous distal base
            distal_keys = np.concatenate([_keys_within(state.distal_keys, distal_idx), distal_keys])
    new_state = _ComposeState(
        n, W, eps, marker, distal_idx, distal_xy, distal_keys, state.next_index + num_new
    )
    return _Step(mapping, coords[is_new], edges, assignment, removed, new_state)
