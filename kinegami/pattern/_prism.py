"""Parameters of the regular prism and the wrapping of pattern coordinates (spec sections 1, 2.1).

Pattern coordinates (x, y): x is the arc length around the polygon, measured from the midpoint of
the starting side and reduced to [0, W); y is the distance along the tube axis.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinegami.validation import check_num_sides, check_radius

#: Relative length tolerance of the reference: eps = EPS_FACTOR * b (spec section 1.1).
EPS_FACTOR = 1e-4


@dataclass(frozen=True)
class Prism:
    """The regular n-gonal prism of circumradius ``r`` that every module is folded from.

    Attributes
    ----------
    numSides : int
        n, even and >= 4.
    r : float
        Circumradius of the polygon (length unit of the user).
    b : float
        Side length 2 r sin(pi/n).
    a : float
        Apothem r cos(pi/n).
    W : float
        Pattern width (perimeter) n b.
    eps : float
        Length tolerance 1e-4 b used to identify points.
    """

    numSides: int
    r: float
    b: float
    a: float
    W: float
    eps: float

    @property
    def columns(self) -> np.ndarray:
        """x of the n tube edges (polygon vertices), x_k = (k + 1/2) b, shape (n,)."""
        return (np.arange(self.numSides) + 0.5) * self.b

    @property
    def vertex_angles(self) -> np.ndarray:
        """Angle beta_k = (k + 1/2) 2 pi / n of polygon vertex k about the axis, radians."""
        return (np.arange(self.numSides) + 0.5) * (2.0 * math.pi / self.numSides)

    @property
    def panel_centres(self) -> np.ndarray:
        """x of the panel centre lines, c_p = (p + 1) b mod W, shape (n,)."""
        return wrap_x((np.arange(self.numSides) + 1.0) * self.b, self.W, self.eps)


def make_prism(numSides, r) -> Prism:
    """Validate ``numSides`` and ``r`` and return the :class:`Prism` (raises on bad input)."""
    n = check_num_sides(numSides)
    r = check_radius(r)
    b = 2.0 * r * math.sin(math.pi / n)
    return Prism(n, r, b, r * math.cos(math.pi / n), n * b, EPS_FACTOR * b)


def wrap_x(x: np.ndarray, W: float, eps: float) -> np.ndarray:
    """Reduce x modulo W into [0, W), snapping values within ``eps`` of 0 or W to 0 (section 2.1).

    The reduction is done first so that any translation is handled; values then within ``eps``
    of 0 or of W become exactly 0.
    """
    x = np.mod(x, W)
    return np.where((x < eps) | (x > W - eps), 0.0, x)


def periodic_dx(dx: np.ndarray, W: float) -> np.ndarray:
    """The representative of ``dx`` modulo W in (-W/2, W/2] (the shortest path on the tube)."""
    return dx + W * np.floor((0.5 * W - dx) / W)
