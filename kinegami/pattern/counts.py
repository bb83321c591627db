"""Vertex and crease counts of the catalog modules (with the fixes B2 and B6 of
docs/theory/patterns.md §6).

Each module file gives its closed-form counts in its catalog entry (``ModuleKind.counts``),
written independently of the module's builder, so that :meth:`TubularPattern.validate` can
compare a pattern with them.
"""

from __future__ import annotations

from kinegami._record import Record
from kinegami.pattern._prism import Prism
from kinegami.pattern.tubular import ModuleRecord

__all__ = ["ModuleCounts", "expected_counts"]


class ModuleCounts(Record):
    """Expected numbers of vertices, creases and (when known) mountain creases."""

    numVertices: int
    numEdges: int
    numMountains: int | None = None


def expected_counts(record: ModuleRecord, prism: Prism) -> ModuleCounts | None:
    """The counts of one catalog module, or None for a kind the catalog does not have.

    Fix B6 (no coincident vertices, no zero-length creases) changes the reference's formulas
    in two places: a tube or twist of pattern height below eps is the empty pattern (n, 0), and
    every elbow column with h_k < eps reuses P_k and D_k (2 vertices and 2 creases fewer).
    Fix B2 removes 4 creases from the revolute joint with N >= 2 sink layers.
    """
    from kinegami.pattern.catalog import find_kind

    entry = find_kind(record.kind)
    return None if entry is None else entry.counts(prism, record.params)
