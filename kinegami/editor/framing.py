"""Where the editor's camera, grid and world axes go for a design of any size (docs/editor.md,
Framing).

A design in the editor may be a 5 cm finger (r = 0.5 mm) or a 1.4 m arm (r = 25 mm, in mm),
and its numbers are the design's units. :func:`frame_box` computes a camera that shows a
whole axis-aligned box (the drawn meshes' bounds) in a view of a given field of view and
aspect ratio, with clipping planes and zoom limits scaled to it; :func:`grid_for_box` a grid
under it whose spacing is a round number of the design's units. Plain numpy: the browser view
(:mod:`kinegami.editor.view`) sends the results to viser.
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinegami.errors import InvalidParameterError

__all__ = ["VIEW_DIRECTION", "Framing", "GridLayout", "frame_box", "grid_for_box", "nice_step",
           "box_corners"]  # fmt: skip

#: From the looked-at point towards the camera (a three-quarter view from the front right,
#: above; z is up).
VIEW_DIRECTION = (1.0, -1.2, 0.8)
#: Free space around the design: the bounding sphere fills 1 / MARGIN of the narrower
#: half-angle of the view.
MARGIN = 1.1
#: How far the user may zoom out, as a multiple of the framing distance.
ZOOM_OUT = 20.0
#: The near clipping plane and the closest zoom, as fractions of the design's radius.
NEAR_FRACTION = 1e-3
MIN_DISTANCE_FRACTION = 1e-2


@dataclass(frozen=True)
class Framing:
    """A camera that shows a whole box.

    Attributes
    ----------
    look_at : the box's centre (design units).
    position : the camera's position.
    up : the camera's up direction (world z).
    radius : the radius of the box's bounding sphere.
    distance : from the camera to ``look_at``.
    near, far : the clipping planes: ``far`` covers the design from the farthest zoom.
    min_distance, max_distance : the zoom limits (orbit distances).
    """

    look_at: np.ndarray
    position: np.ndarray
    up: tuple[float, float, float]
    radius: float
    distance: float
    near: float
    far: float
    min_distance: float
    max_distance: float


@dataclass(frozen=True)
class GridLayout:
    """A square grid in a plane z = const under a box, lines at round world coordinates.

    Attributes
    ----------
    centre : the grid's centre (x, y at multiples of ``section``; z the box's lowest point).
    width : its side (a whole number of sections).
    cell, section : the spacing of the thin and the thick lines (1, 2 or 5 times a power of
        ten, in the design's units).
    """

    centre: tuple[float, float, float]
    width: float
    cell: float
    section: float


def _box(lo, hi) -> tuple[np.ndarray, np.ndarray]:
    lo, hi = np.asarray(lo, dtype=float).reshape(3), np.asarray(hi, dtype=float).reshape(3)
    if not (np.isfinite(lo).all() and np.isfinite(hi).all()) or (hi < lo).any():
        raise InvalidParameterError(
            f"a box needs finite corners with lo <= hi, got lo {lo.tolist()}, hi {hi.tolist()}"
        )
    return lo, hi


def box_corners(lo, hi) -> np.ndarray:
    """The 8 corners of the box [lo, hi] (an 8 x 3 array)."""
    lo, hi = _box(lo, hi)
    return np.array([[(lo, hi)[i][0], (lo, hi)[j][1], (lo, hi)[k][2]]
                     for i in (0, 1) for j in (0, 1) for k in (0, 1)])  # fmt: skip


def frame_box(lo, hi, fov: float, aspect: float, direction=VIEW_DIRECTION,
              margin: float = MARGIN) -> Framing:  # fmt: skip
    """The camera that shows the whole box [lo, hi] from ``direction``.

    Parameters
    ----------
    lo, hi : the box's corners (design units).
    fov : the view's vertical field of view (radians, in (0, pi)).
    aspect : its width / height (the narrower of the two half-angles must hold the box).
    direction : from the box's centre towards the camera.
    margin : the bounding sphere's share of the narrower half-angle is 1 / margin.
    """
    lo, hi = _box(lo, hi)
    fov, aspect = float(fov), float(aspect)
    if not 0.0 < fov < math.pi:
        raise InvalidParameterError(f"fov must be in (0, pi) radians, got {fov!r}")
    if not (math.isfinite(aspect) and aspect > 0.0):
        raise InvalidParameterError(f"aspect must be a positive number, got {aspect!r}")
    centre = 0.5 * (lo + hi)
    radius = max(0.5 * float(np.linalg.norm(hi - lo)), 1e-9 * max(1.0, float(np.abs(centre).max())))
    half = min(0.5 * fov, math.atan(math.tan(0.5 * fov) * aspect))
    distance = float(margin) * radius / math.sin(half)
    toward = np.asarray(direction, dtype=float)
    toward = toward / np.linalg.norm(toward)
    max_distance = ZOOM_OUT * distance
    return Framing(
        look_at=centre, position=centre + distance * toward, up=(0.0, 0.0, 1.0),
        radius=radius, distance=distance, near=NEAR_FRACTION * radius,
        far=max_distance + 2.0 * radius, min_distance=MIN_DISTANCE_FRACTION * radius,
        max_distance=max_distance,
    )  # fmt: skip


def nice_step(value: float) -> float:
    """The largest of 1, 2 and 5 times a power of ten that is at most ``value`` (> 0)."""
    value = float(value)
    if not (math.isfinite(value) and value > 0.0):
        raise InvalidParameterError(f"value must be a positive number, got {value!r}")
    power = 10.0 ** math.floor(math.log10(value))
    for factor in (5.0, 2.0, 1.0):
        if factor * power <= value * (1.0 + 1e-12):
            return factor * power
    return power  # pragma: no cover - factor 1 always fits


def grid_for_box(lo, hi) -> GridLayout:
    """A grid under the box [lo, hi]: about four sections across its larger horizontal side
    (or its size, for a box that is mostly tall), five or so cells a section, one and a half
    times as wide as the box, at the box's lowest z."""
    lo, hi = _box(lo, hi)
    size = max(float(hi[0] - lo[0]), float(hi[1] - lo[1]), 0.5 * float(np.linalg.norm(hi - lo)))
    size = max(size, 1e-9)
    section = nice_step(size / 4.0)
    cell = nice_step(section / 4.0)
    centre = 0.5 * (lo + hi)
    x, y = (round(float(v) / section) * section for v in centre[:2])
    reach = max(abs(x - lo[0]), abs(hi[0] - x), abs(y - lo[1]), abs(hi[1] - y)) + 0.25 * size
    width = 2.0 * section * math.ceil(reach / section)
    return GridLayout((x, y, float(lo[2])), width, cell, section)
