"""Small helpers shared by the catalog modules (not public): parameter checks used only by
the catalog (the shared ones are in kinegami.validation) and the assembly of a module's
pattern from its vertices and crease blocks."""

from __future__ import annotations

import math

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.pattern._prism import Prism
from kinegami.pattern.tubular import ModuleRecord, TubularPattern, first_occurrence_mask
from kinegami.validation import check_nonnegative, check_real


def check_bool(name: str, value) -> bool:
    """A Python or numpy boolean."""
    if not isinstance(value, bool | np.bool_):
        raise InvalidTypeError(f"{name} must be a bool, got {value!r}")
    return bool(value)


def real(name: str, value) -> float:
    """:func:`kinegami.validation.check_real`, with a fast path for a finite Python float."""
    if type(value) is float and math.isfinite(value):
        return value
    return check_real(name, value)


def nonnegative(name: str, value) -> float:
    """:func:`kinegami.validation.check_nonnegative`, fast for a finite Python float >= 0."""
    if type(value) is float and value >= 0.0 and math.isfinite(value):
        return value
    return check_nonnegative(name, value)


def check_at_least(name: str, value: float, minimum: float, range_text: str) -> float:
    """Raise unless ``value >= minimum``; ``range_text`` describes the valid range."""
    if not value >= minimum:
        raise InvalidParameterError(f"{name} must be {range_text}, got {value!r}")
    return value


def crease_block(first, second, label: str) -> tuple[np.ndarray, str]:
    """A block of creases first[i]-second[i], all with the same label ("M" or "V")."""
    first = np.asarray(first)
    block = np.empty((first.shape[0], 2), dtype=np.intp)
    block[:, 0] = first
    block[:, 1] = second
    return block, label


def distinct_creases(
    edges: np.ndarray, labels: np.ndarray, num_vertices: int
) -> tuple[np.ndarray, np.ndarray]:
    """The creases without those joining a vertex to itself and without repeats (the first of
    equal creases kept), with their labels."""
    keep = edges[:, 0] != edges[:, 1]
    lo = np.minimum(edges[:, 0], edges[:, 1])
    hi = np.maximum(edges[:, 0], edges[:, 1])
    key = lo.astype(np.int64) * num_vertices + hi
    keep &= first_occurrence_mask(key)
    return edges[keep], labels[keep]


def assemble(
    prism: Prism,
    vertices: np.ndarray,
    blocks: list[tuple[np.ndarray, str | np.ndarray]],
    proximal: np.ndarray | None,
    distal: np.ndarray | None,
    height: float,
    record: ModuleRecord,
    distal_marker_x: float = 0.0,
    drop_degenerate: bool = True,
) -> TubularPattern:
    """Build a module pattern from vertex coordinates and labelled crease blocks.

    Each block is an (m, 2) array of vertex index pairs with one label or an array of m labels.

    Creases joining a vertex to itself are dropped, and so are repeated creases (the first one
    in block order is kept), so every module comes out without zero-length or duplicate creases.
    The proximal marker is (0, 0) and the distal marker (``distal_marker_x``, ``height``).
    """
    edges = np.concatenate([b for b, _ in blocks]).astype(np.intp)
    if all(type(lab) is str for _, lab in blocks):  # one label per block: one numpy call
        labels = np.repeat(
            np.array([lab for _, lab in blocks], dtype="<U1"), [b.shape[0] for b, _ in blocks]
        )
    else:
        labels = np.concatenate(
            [
                np.full(b.shape[0], lab, dtype="<U1") if isinstance(lab, str) else np.asarray(lab)
                for b, lab in blocks
            ]
        ).astype("<U1")
    if drop_degenerate:
        edges, labels = distinct_creases(edges, labels, vertices.shape[0])
    return TubularPattern._build(
        prism.numSides,
        prism.r,
        np.ascontiguousarray(vertices, dtype=float),
        np.ascontiguousarray(edges),
        labels,
        None if proximal is None else np.asarray(proximal, dtype=np.intp),
        None if distal is None else np.asarray(distal, dtype=np.intp),
        np.zeros(2),
        np.array([distal_marker_x, height], dtype=float),
        float(height),
        (record,),
        0,
        None,
        False,
    )
