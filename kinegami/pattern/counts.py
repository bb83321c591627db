"""Vertex and crease counts of the catalog modules (spec section 7.1 item 4, with the fixes).

These are the closed-form counts, written independently of the module builders, so that
:meth:`TubularPattern.validate` can compare a pattern with them.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinegami.pattern._prism import Prism
from kinegami.pattern.tubular import ModuleRecord

__all__ = ["ModuleCounts", "expected_counts"]


@dataclass(frozen=True)
class ModuleCounts:
    """Expected numbers of vertices, creases and (when the spec gives it) mountain creases."""

    numVertices: int
    numEdges: int
    numMountains: int | None = None


def expected_counts(record: ModuleRecord, prism: Prism) -> ModuleCounts | None:
    """The counts of one catalog module, or None for an unknown kind.

    Fix B6 (no coincident vertices, no zero-length creases) changes the reference's formulas
    in two places: a tube or twist of pattern height below eps is the empty pattern (n, 0), and
    every elbow column with h_k < eps reuses P_k and D_k (2 vertices and 2 creases fewer).
    Fix B2 removes 4 creases from the revolute joint with N >= 2 sink layers.
    """
    n, p, kind = prism.numSides, record.params, record.kind
    if kind == "waypoint":
        return ModuleCounts(n, 0, 0)
    if kind == "tube":
        if p["height"] < prism.eps:
            return ModuleCounts(n, 0, 0)
        return ModuleCounts(2 * n, n, n)
    if kind == "twist":
        from kinegami.pattern.twist import twist_geometry

        if twist_geometry(prism, p["twistAngle"], p["moduleHeight"]).degenerate:
            return ModuleCounts(n, 0, 0)
        return ModuleCounts(2 * n, 4 * n, 2 * n)
    if kind == "elbow":
        from kinegami.pattern.elbow import elbow_geometry

        geo = elbow_geometry(prism, p["bendingAngle"], p["rotationalAxisAngle"])
        c = int(np.count_nonzero(geo.collapsed))
        z = int(np.count_nonzero(geo.low))
        return ModuleCounts(6 * n - 3 * c - 2 * z, 10 * n - 5 * c - 2 * (c == 2) - 2 * z)
    if kind == "revolute":
        N = p["numSinkLayers"]
        if N == 1:
            return ModuleCounts(6 * n - 8, 16 * n - 32)
        return ModuleCounts(
            6 * n - 8 + (10 * n - 28) * (N - 1), 6 * n - 4 + (10 * n - 28) * (2 * N - 1)
        )
    if kind in ("start_tip", "end_tip"):
        return ModuleCounts(4 * n - 4, 9 * n - 16)
    if kind == "rebo":
        N = p["numLayers"]
        mountains = 4 * N * n if p["proximalValleys"] else n * (4 * N + 1)
        return ModuleCounts(n * (3 * N + 1), n * (7 * N + 1), mountains)
    if kind == "prismatic":
        N = p["numLayers"]
        return ModuleCounts(n * (3 * N + 4), n * (7 * N + 5))
    return None
