"""Bounding balls and their greedy merge (docs/theory/chain.md §2)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np


@dataclass(frozen=True, eq=False)
class Ball:
    """A closed ball with centre ``c`` (3-vector, world coordinates) and radius ``r``."""

    c: np.ndarray
    r: float

    def __post_init__(self):
        c = np.array(self.c, dtype=float)
        c.setflags(write=False)
        object.__setattr__(self, "c", c)
        object.__setattr__(self, "r", float(self.r))

    @property
    def center(self) -> np.ndarray:
        """The centre (alias of ``c``)."""
        return self.c

    @property
    def radius(self) -> float:
        """The radius (alias of ``r``)."""
        return self.r

    def contains(self, other: Ball, tol: float = 0.0) -> bool:
        """True if ``other`` lies inside this ball (within ``tol``)."""
        return float(np.linalg.norm(other.c - self.c)) + other.r <= self.r + tol

    def transformed(self, T: np.ndarray) -> Ball:
        """The ball moved rigidly by the 4x4 transform ``T``."""
        return Ball(T[:3, :3] @ self.c + T[:3, 3], self.r)

    def __repr__(self) -> str:
        c = ", ".join(f"{v:.6g}" for v in self.c)
        return f"Ball(c=({c}), r={self.r:.6g})"


def merge_balls(b1: Ball, b2: Ball) -> Ball:
    """The smallest ball containing two balls (docs/theory/chain.md §2; the order of the
    arguments matters only through which one is "smaller" when the radii tie, as in the
    reference)."""
    small, large = (b1, b2) if b1.r <= b2.r else (b2, b1)
    v = large.c - small.c
    dist = math.sqrt(float(v @ v))
    if dist + small.r <= large.r:
        return large
    vhat = v / dist
    P = small.c - small.r * vhat
    Q = large.c + large.r * vhat
    return Ball((P + Q) / 2.0, float(np.linalg.norm(Q - P)) / 2.0)
