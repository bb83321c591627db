"""The pictures name their unit and carry a scale: the 3D view of a chain or tree
(``show(units=...)``: axis labels, a scale bar) and the crease pattern (axis labels, a scale bar
whose length in data coordinates is the length it says)."""

from __future__ import annotations

import math
import re
import warnings

import numpy as np
import pytest

from kinegami import KinematicTree
from kinegami.errors import InvalidParameterError
from kinegami.pattern.sheet import flatten
from kinegami.viz import chain_geometry as geo
from kinegami.viz import style

try:  # tests/ is not a package: reachable as tests.tree from the checkout, else as tree
    from tests.tree.helpers import hand_tree
except ImportError:  # pragma: no cover
    from tree.helpers import hand_tree


def _gids(ax) -> set:
    return {a.get_gid() for a in (*ax.collections, *ax.lines, *ax.texts)}


def _one(artists, gid):
    found = [a for a in artists if a.get_gid() == gid]
    assert len(found) == 1, f"expected one artist with gid {gid!r}, found {len(found)}"
    return found[0]


def _pieces(line) -> list[np.ndarray]:
    """The NaN-separated pieces of a Line3D (data coordinates)."""
    points = np.stack([np.asarray(v, dtype=float) for v in line.get_data_3d()], axis=1)
    gaps = np.flatnonzero(np.isnan(points[:, 0]))
    return [p[~np.isnan(p[:, 0])] for p in np.split(points, gaps) if (~np.isnan(p[:, 0])).any()]


def _said_length(text: str, unit: str) -> float:
    """The number of a scale bar's label, checking that the unit follows it."""
    match = re.fullmatch(rf"([0-9.e+-]+) {re.escape(unit)}", text)
    assert match, (text, unit)
    return float(match.group(1))


def _is_round(length: float) -> bool:
    mantissa = length / 10.0 ** math.floor(math.log10(length))
    return any(math.isclose(mantissa, m) for m in (1.0, 2.0, 5.0))


def _robot_box(chain) -> np.ndarray:
    """(2, 3) box around the robot's drawn parts: joint bodies, link surfaces, centrelines."""
    sides = style.linkSurfaceSides
    points = [face for joint in chain.Joints for face in geo.joint_body_faces(joint)]
    for link in chain.Links:
        if link.path.length > 0.0:
            points.append(geo.link_centreline(link))
            grid = geo.link_elbow_grids(link, sides)
            if len(grid):
                points.append(np.asarray(grid).reshape(-1, 3))
            tube = geo.tube_grid(link, sides)
            if tube is not None:
                points.append(np.asarray(tube).reshape(-1, 3))
    stacked = np.vstack([np.asarray(p, dtype=float).reshape(-1, 3) for p in points])
    return np.stack([stacked.min(axis=0), stacked.max(axis=0)])


# --- the 3D view -------------------------------------------------------------------------------


@pytest.mark.parametrize(("units", "unit"), [("mm", "mm"), ("in", "in"), (None, "units of r")])
def test_axis_labels_name_the_unit(example_1a, units, unit):
    _, ax = example_1a.show(showAxisGrids=True, units=units)
    assert (ax.get_xlabel(), ax.get_ylabel(), ax.get_zlabel()) == (
        f"x ({unit})",
        f"y ({unit})",
        f"z ({unit})",
    )
    assert "scale-bar" not in _gids(ax)  # the axes' ticks are the scale


@pytest.mark.parametrize(("units", "unit"), [("cm", "cm"), (None, "(units of r)")])
def test_scale_bar_under_the_chain_is_as_long_as_it_says(example_1a, units, unit):
    # the joint frames off: what is drawn is the robot (the axes of motion do not count)
    _, ax = example_1a.show(units=units, showJointPoses=False)
    bar = _one(ax.lines, "scale-bar")
    label = _one(ax.texts, "scale-bar-label")
    length = _said_length(label.get_text(), unit)
    main, *ticks = _pieces(bar)
    assert np.linalg.norm(main[1] - main[0]) == pytest.approx(length, rel=1e-12)
    assert len(ticks) == 2
    direction = (main[1] - main[0]) / length
    assert np.allclose(np.abs(direction), [1, 0, 0]) or np.allclose(np.abs(direction), [0, 1, 0])
    low, high = _robot_box(example_1a)
    span = (high - low).max()
    assert _is_round(length) and 0.3 * span / 2.5 < length <= 0.3 * span
    assert main[:, 2] == pytest.approx(low[2])  # on the robot's floor
    middle = main.mean(axis=0)
    axis = int(np.argmax(np.abs(direction)))
    assert middle[axis] == pytest.approx(0.5 * (low[axis] + high[axis]))  # centred under it


def test_scale_bar_can_be_left_out(example_1a):
    _, ax = example_1a.show(showScaleBar=False)
    assert not {"scale-bar", "scale-bar-label"} & _gids(ax)


def test_a_trees_view_names_its_unit():
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the paper's hand touches its palm (tests/tree)
        hand = hand_tree()
    assert isinstance(hand, KinematicTree)
    _, ax = hand.show(units="cm", showJointPoses=False)
    length = _said_length(_one(ax.texts, "scale-bar-label").get_text(), "cm")
    main = _pieces(_one(ax.lines, "scale-bar"))[0]
    assert np.linalg.norm(main[1] - main[0]) == pytest.approx(length)
    _, ax = hand.show(units="cm", showAxisGrids=True)
    assert ax.get_zlabel() == "z (cm)"


@pytest.mark.parametrize("units", ["ft", "", 1.0, "MM"])
def test_unknown_units_are_refused(example_1a, units):
    with pytest.raises(InvalidParameterError, match="units must be None .* 'mm', 'cm'"):
        example_1a.show(units=units)


# --- the crease pattern ------------------------------------------------------------------------


@pytest.fixture(scope="module")
def pattern(example_1a):
    return example_1a.creasePattern()


@pytest.mark.parametrize(("units", "unit"), [("mm", "mm"), (None, "units of r")])
def test_pattern_axes_name_the_unit(pattern, units, unit):
    _, ax = pattern.show(units=units)
    assert ax.get_xlabel() == f"x around the tube ({unit})"
    assert ax.get_ylabel() == f"y along the tube ({unit})"


@pytest.mark.parametrize(("units", "unit"), [("cm", "cm"), (None, "(units of r)")])
def test_pattern_scale_bar_is_as_long_as_it_says(pattern, units, unit):
    fig, ax = pattern.show(units=units)
    bar = _one(ax.lines, "scale-bar")
    label = _one(ax.texts, "scale-bar-label")
    length = _said_length(label.get_text(), unit)
    x, y = (np.asarray(v, dtype=float) for v in bar.get_data())
    assert x[1] - x[0] == pytest.approx(length, rel=1e-12) and y[0] == y[1]
    xmin, ymin, xmax, ymax = flatten(pattern).bounds
    assert _is_round(length) and 0.4 * (xmax - xmin) / 2.5 < length <= 0.4 * (xmax - xmin)
    assert x[1] == pytest.approx(xmax)  # under the sheet's right end
    assert ax.get_ylim()[0] < y[0] < ymin  # below the sheet, inside the axes
    fig.canvas.draw()  # the label is drawn whole inside the axes, under the bar
    box, frame = label.get_window_extent(), ax.get_window_extent()
    assert frame.x0 <= box.x0 and box.x1 <= frame.x1 and frame.y0 <= box.y0
    assert box.y1 <= ax.transData.transform((x[0], y[0]))[1]


def test_pattern_scale_bar_can_be_left_out(pattern):
    _, ax = pattern.show(showScaleBar=False)
    assert not {"scale-bar", "scale-bar-label"} & _gids(ax)
    xmin, ymin, xmax, ymax = flatten(pattern).bounds
    assert ax.get_ylim()[0] == pytest.approx(ymin - 0.05 * (xmax - xmin))


def test_pattern_refuses_unknown_units(pattern):
    with pytest.raises(InvalidParameterError, match="units"):
        pattern.show(units="furlong")
