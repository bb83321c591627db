"""Keep-out boxes (docs/design-for-a-task.md): axis-aligned boxes of the world that no part of a
design may come near (the table a robot stands on), and the test of a configuration against
them (each part a capsule of radius r, as the clearance engine measures parts)."""

from __future__ import annotations

import math
from collections.abc import Mapping, Sequence
from dataclasses import dataclass

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError

__all__ = ["Box", "keep_out_violation", "segment_box_distances"]


@dataclass(frozen=True)
class Box:
    """An axis-aligned box (world frame, the design's units) no part of the robot may enter."""

    min: tuple[float, float, float]
    max: tuple[float, float, float]

    @classmethod
    def of(cls, value, name: str = "keep_out box") -> Box:
        """A Box from a Box, a mapping ``{"min": [x, y, z], "max": [x, y, z]}`` or a pair."""
        if isinstance(value, Box):
            return value
        if isinstance(value, Mapping):
            if set(value) != {"min", "max"}:
                raise InvalidParameterError(
                    f"{name} must have the keys 'min' and 'max', got {sorted(value)}"
                )
            low, high = value["min"], value["max"]
        elif isinstance(value, Sequence) and len(value) == 2:
            low, high = value
        else:
            raise InvalidTypeError(
                f"{name} must be {{'min': [x, y, z], 'max': [x, y, z]}}, got {value!r}"
            )
        low, high = (_point(v, f"{name} {key}") for v, key in ((low, "min"), (high, "max")))
        if not np.all(low <= high):
            raise InvalidParameterError(
                f"{name} min {low.tolist()} must be <= max {high.tolist()} in every coordinate"
            )
        return cls(tuple(low.tolist()), tuple(high.tolist()))


def _point(value, name: str) -> np.ndarray:
    try:
        p = np.asarray(value, dtype=float)
    except (TypeError, ValueError):
        raise InvalidTypeError(f"{name} must be 3 numbers, got {value!r}") from None
    if p.shape != (3,) or not np.isfinite(p).all():
        raise InvalidParameterError(f"{name} must be 3 finite numbers, got {value!r}")
    return p


def keep_out_violation(design, states, boxes, margin: float = 0.0) -> tuple[int, float] | None:
    """(box index, depth) of the first keep-out box that a part of ``design`` at ``states``
    comes within ``margin`` of (its tube of radius r), or None. Depth: how far inside the allowed
    distance (design units)."""
    from kinegami.chain.model import KinematicChain
    from kinegami.clearance.engine import engine_for, tree_engine

    if not boxes:
        return None
    engine = engine_for(design) if isinstance(design, KinematicChain) else tree_engine(design)
    a, b = engine.segments(np.asarray(states, dtype=float)[None, :])
    a, b = a[0], b[0]
    r = float(design.r)
    for k, box in enumerate(boxes):
        box = Box.of(box)
        d = segment_box_distances(a, b, np.array(box.min), np.array(box.max))
        worst = float(d.min()) if d.size else math.inf
        if worst < r + margin - 1e-9 * r:
            return k, r + margin - worst
    return None


def segment_box_distances(a, b, low, high) -> np.ndarray:
    """(S,): the distance of each segment (a, b) to the box [low, high]: the distance to a
    convex set along a segment is convex in its parameter, so a golden-section search finds
    its minimum (to about 1e-15 of the segment's length)."""

    def distance(t):
        p = a + t[:, None] * (b - a)
        return np.linalg.norm(p - np.clip(p, low, high), axis=1)

    lo, hi = np.zeros(len(a)), np.ones(len(a))
    g = (math.sqrt(5.0) - 1.0) / 2.0
    for _ in range(80):
        m1, m2 = hi - g * (hi - lo), lo + g * (hi - lo)
        left = distance(m1) <= distance(m2)
        hi = np.where(left, m2, hi)
        lo = np.where(left, lo, m1)
    return np.minimum.reduce([distance(lo), distance(hi), distance(np.zeros(len(a))),
                              distance(np.ones(len(a)))])  # fmt: skip


