"""Parameters of the regular prism and the wrapping of pattern coordinates.

See docs/theory/patterns.md, sections 1 and 2.

Pattern coordinates (x, y): x is the arc length around the polygon, measured from the midpoint of
the starting side and reduced to [0, W); y is the distance along the tube axis.
"""

from __future__ import annotations

import math

import numpy as np

from kinegami.validation import check_num_sides, check_radius

#: Relative length tolerance of the reference: eps = EPS_FACTOR * b (docs/theory/patterns.md 1.1).
EPS_FACTOR = 1e-4
#: Length tolerance of the flat sheet, as a multiple of the tube radius r: points closer than this
#: are one point of the sheet's planar graph (kinegami.pattern.sheet) and of the folded form.
SHEET_TOLERANCE_FACTOR = 1e-9


class Prism:
    """The regular n-gonal prism of circumradius ``r`` that every module is folded from.

    Immutable, and shared: :func:`make_prism` returns one object per (numSides, r), whose
    arrays are computed once and read-only.

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
    columns : ndarray, shape (n,)
        x of the n tube edges (polygon vertices), x_k = (k + 1/2) b.
    vertex_angles : ndarray, shape (n,)
        Angle beta_k = (k + 1/2) 2 pi / n of polygon vertex k about the axis, radians.
    panel_centres : ndarray, shape (n,)
        x of the panel centre lines, c_p = (p + 1) b mod W.
    """

    __slots__ = (
        "numSides", "r", "b", "a", "W", "eps", "columns", "vertex_angles", "panel_centres",
        "_cache",
    )  # fmt: skip

    def __init__(self, numSides: int, r: float, b: float, a: float, W: float, eps: float):
        s = object.__setattr__
        for name, value in (("numSides", numSides), ("r", r), ("b", b), ("a", a), ("W", W),
                            ("eps", eps)):  # fmt: skip
            s(self, name, value)
        k = np.arange(numSides)
        s(self, "columns", readonly((k + 0.5) * b))
        s(self, "vertex_angles", readonly((k + 0.5) * (2.0 * math.pi / numSides)))
        s(self, "panel_centres", readonly(wrap_x((k + 1.0) * b, W, eps)))
        s(self, "_cache", {})

    def cached(self, key, make):
        """``make()`` computed once per prism and ``key`` (for values derived from n and r
        only; the value must be immutable)."""
        try:
            return self._cache[key]
        except KeyError:
            value = self._cache[key] = make()
            return value

    def cached_many(self, keys: list, make_many) -> list:
        """:meth:`cached` of every key, the values not yet cached computed by one call
        ``make_many(missing)``: ``missing`` lists those keys once each, in order of first
        appearance, and the call returns their values in that order."""
        cache = self._cache
        missing = [key for key in dict.fromkeys(keys) if key not in cache]
        if missing:
            for key, value in zip(missing, make_many(missing), strict=True):
                cache[key] = value
        return [cache[key] for key in keys]

    def __setattr__(self, name: str, value) -> None:
        raise AttributeError(f"Prism is immutable (cannot set {name!r})")

    def __eq__(self, other) -> bool:
        if not isinstance(other, Prism):
            return NotImplemented
        return (self.numSides, self.r) == (other.numSides, other.r)

    def __hash__(self) -> int:
        return hash((self.numSides, self.r))

    def __repr__(self) -> str:
        return (
            f"Prism(numSides={self.numSides}, r={self.r!r}, b={self.b!r}, a={self.a!r}, "
            f"W={self.W!r}, eps={self.eps!r})"
        )


def readonly(array: np.ndarray) -> np.ndarray:
    """``array`` made read-only (in place) and returned."""
    array.setflags(write=False)
    return array


def make_prism(numSides, r) -> Prism:
    """Validate ``numSides`` and ``r`` and return the :class:`Prism` (raises on bad input).

    Prisms are shared: the same (numSides, r) gives the same object.
    """
    try:
        return _prism_cache[(type(numSides), numSides, type(r), r)]
    except (KeyError, TypeError):
        pass
    n = check_num_sides(numSides)
    r_checked = check_radius(r)
    prism = _prism_cache.get((int, n, float, r_checked))
    if prism is None:
        b = 2.0 * r_checked * math.sin(math.pi / n)
        prism = Prism(n, r_checked, b, r_checked * math.cos(math.pi / n), n * b, EPS_FACTOR * b)
        if len(_prism_cache) > 1024:
            _prism_cache.clear()
        _prism_cache[(int, n, float, r_checked)] = prism
    try:
        _prism_cache[(type(numSides), numSides, type(r), r)] = prism
    except TypeError:  # an unhashable (but valid) value: not cached
        pass
    return prism


_prism_cache: dict = {}


def wrap_x(x: np.ndarray, W: float, eps: float) -> np.ndarray:
    """Reduce x modulo W into [0, W), snapping values within ``eps`` of 0 or W to 0 (section 2.1).

    The reduction is done first so that any translation is handled; values then within ``eps``
    of 0 or of W become exactly 0.
    """
    x = np.mod(x, W)
    return np.where((x < eps) | (x > W - eps), 0.0, x)


def wrap_scalar(x: float, W: float, eps: float) -> float:
    """:func:`wrap_x` of one Python float (the same arithmetic, without numpy's overhead)."""
    x = x % W
    return 0.0 if x < eps or x > W - eps else x


def periodic_dx(dx: np.ndarray, W: float) -> np.ndarray:
    """The representative of ``dx`` modulo W in (-W/2, W/2] (the shortest path on the tube)."""
    return dx + W * np.floor((0.5 * W - dx) / W)
