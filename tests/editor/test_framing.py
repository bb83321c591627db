"""Framing without a browser (kinegami.editor.framing): for designs from r = 0.5 mm to
r = 50 mm, chains and trees, every drawn vertex is inside the camera's view and between its
clipping planes, also after the farthest zoom; the grid's spacing is a round number near the
design's size (docs/editor.md, Framing)."""

from __future__ import annotations

import math
import re

import numpy as np
import pytest

from kinegami.clearance.solids import chain_parts
from kinegami.editor import EditorModel
from kinegami.editor.framing import box_corners, frame_box, grid_for_box, nice_step
from kinegami.errors import InvalidParameterError

from .helpers import EXAMPLE1, HAND, ROOT

PUMA = ROOT / "examples" / "designs" / "puma.json"


def _camera(framing):
    """The camera's axes: forward, right, up (world)."""
    forward = framing.look_at - framing.position
    forward = forward / np.linalg.norm(forward)
    right = np.cross(forward, framing.up)
    right /= np.linalg.norm(right)
    return forward, right, np.cross(right, forward)


def _in_view(points, framing, fov, aspect, position=None):
    """Per point: (inside the view's cone, between the clipping planes)."""
    forward, right, up = _camera(framing)
    rel = np.asarray(points) - (framing.position if position is None else position)
    depth = rel @ forward
    tan_v = math.tan(0.5 * fov)
    inside = (np.abs(rel @ right) <= depth * tan_v * aspect) & (np.abs(rel @ up) <= depth * tan_v)
    clipped = (depth >= framing.near) & (depth <= framing.far)
    return inside, clipped


def _scaled(path, factor: float) -> np.ndarray:
    """The vertices of a design's meshes, scaled by ``factor`` (a design of another size)."""
    import warnings

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain = EditorModel.open(path).chain
    return factor * np.concatenate([part.vertices for part in chain_parts(chain)])


@pytest.mark.filterwarnings("ignore::kinegami.errors.ClearanceWarning")
@pytest.mark.parametrize(
    ("path", "factor"),
    [(PUMA, 1.0), (PUMA, 2.0), (HAND, 0.5), (HAND, 50.0), (EXAMPLE1, 1.0), (EXAMPLE1, 0.05)],
)
@pytest.mark.parametrize(("fov", "aspect"), [(math.radians(75), 1.0), (math.radians(50), 0.4),
                                             (math.radians(75), 2.5)])  # fmt: skip
def test_every_vertex_is_in_view_and_inside_the_clipping_planes(path, factor, fov, aspect):
    points = _scaled(path, factor)
    framing = frame_box(points.min(0), points.max(0), fov, aspect)
    inside, clipped = _in_view(points, framing, fov, aspect)
    assert inside.all() and clipped.all()
    # zoomed out as far as allowed, the far plane still holds all of it
    toward = (framing.position - framing.look_at) / framing.distance
    far = framing.look_at + framing.max_distance * toward
    depth = (points - far) @ -toward
    assert depth.max() <= framing.far and depth.min() >= framing.near
    assert framing.min_distance < framing.distance < framing.max_distance


def test_the_puma_is_framed_about_two_radii_away_and_the_far_plane_covers_it():
    points = _scaled(PUMA, 1.0)
    framing = frame_box(points.min(0), points.max(0), math.radians(75), 1.2)
    assert 600.0 < framing.radius < 630.0  # mm: the arm is 1.2 m long
    assert framing.far > framing.distance + framing.radius > 1000.0  # viser's default far: 1000
    assert framing.near < 1.0


def test_a_box_fills_about_one_over_the_margin_of_the_narrower_angle():
    framing = frame_box((-1, -1, -1), (1, 1, 1), math.radians(60), 0.5)
    half = math.atan(math.tan(math.radians(30)) * 0.5)
    assert math.asin(framing.radius / framing.distance) == pytest.approx(half / 1.1, rel=0.1)


@pytest.mark.parametrize(
    ("args", "message"),
    [(((0, 0, 0), (1, 1, float("nan")), 1.0, 1.0), "a box needs finite corners"),
     (((0, 0, 0), (-1, 1, 1), 1.0, 1.0), "a box needs finite corners with lo <= hi"),
     (((0, 0, 0), (1, 1, 1), 0.0, 1.0), "fov must be in (0, pi) radians, got 0.0"),
     (((0, 0, 0), (1, 1, 1), 1.0, -2.0), "aspect must be a positive number, got -2.0")],
)  # fmt: skip
def test_bad_framing_input_is_refused(args, message):
    with pytest.raises(InvalidParameterError, match="^" + re.escape(message)):
        frame_box(*args)


@pytest.mark.parametrize(("value", "step"), [(7.3, 5.0), (0.019, 0.01), (250.0, 200.0),
                                             (1.0, 1.0), (0.5, 0.5), (3e-4, 2e-4)])  # fmt: skip
def test_nice_steps(value, step):
    assert nice_step(value) == pytest.approx(step)


@pytest.mark.parametrize(("lo", "hi", "section"), [
    ((-174.1, -76.8, -59.3), (122.4, 1106.2, 99.6), 200.0),   # the PUMA, mm
    ((-3.0, -1.0, 0.0), (9.0, 1.0, 16.5), 2.0),               # the hand, cm
    ((-0.15, -0.05, 0.0), (0.45, 0.05, 0.8), 0.1),            # the hand at r = 0.5 mm, in cm
])  # fmt: skip
def test_the_grid_is_under_the_design_and_wider_than_it(lo, hi, section):
    grid = grid_for_box(lo, hi)
    assert grid.section == pytest.approx(section)
    assert grid.cell in (pytest.approx(grid.section / 5), pytest.approx(grid.section / 4))
    assert grid.centre[2] == lo[2]
    for axis in (0, 1):
        assert grid.centre[axis] - grid.width / 2 <= lo[axis]
        assert grid.centre[axis] + grid.width / 2 >= hi[axis]
        assert grid.centre[axis] / grid.section == pytest.approx(round(grid.centre[axis]
                                                                       / grid.section))  # fmt: skip
    assert grid.width / grid.section == pytest.approx(round(grid.width / grid.section))


def test_box_corners():
    corners = box_corners((0, 0, 0), (1, 2, 3))
    assert corners.shape == (8, 3)
    assert {tuple(c) for c in corners} == {(x, y, z) for x in (0, 1) for y in (0, 2)
                                           for z in (0, 3)}  # fmt: skip
