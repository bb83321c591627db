"""SVG export: parses as XML, Origami Simulator colours, counts, millimetres, flipped y."""

import xml.etree.ElementTree as ET

import numpy as np
import pytest
from numpy.testing import assert_allclose

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.export import save_pattern
from kinegami.pattern.sheet import flatten

from .conftest import build
from .helpers import lengths
from .reference_values import CLIPPED_COUNTS, OUTLINE_LINES, SVG_COLORS, UNITS_IN_MM

NS = {"svg": "http://www.w3.org/2000/svg"}
GROUP_KIND = {"Mountain": "M", "Valley": "V", "Boundary": "B", "Cut": "C"}


def read_svg(path):
    """The root element and {group id: (k, 2, 2) line ends, list of stroke colours}."""
    root = ET.parse(path).getroot()
    groups = {}
    for g in root.findall("svg:g", NS):
        lines = g.findall("svg:line", NS)
        coords = [[float(e.get(a)) for a in ("x1", "y1", "x2", "y2")] for e in lines]
        ends = np.array(coords, dtype=float).reshape(-1, 2, 2)
        groups[g.get("id")] = (ends, [e.get("stroke") for e in lines], g.get("stroke"))
    return root, groups


def test_parses_with_colours_counts_and_lengths(tmp_path, composite6):
    root, groups = read_svg(save_pattern(composite6, tmp_path / "c.svg"))
    assert root.tag == "{http://www.w3.org/2000/svg}svg"
    sheet = flatten(composite6)
    assert set(groups) == set(SVG_COLORS)
    for gid, color in SVG_COLORS.items():
        ends, strokes, group_stroke = groups[gid]
        kind = GROUP_KIND[gid]
        assert ends.shape[0] == sheet.count(kind)
        assert set(strokes) == {color} and group_stroke == color
        assert_allclose(lengths(ends).sum(), sheet.total_length(kind), rtol=1e-10)


def test_mountain_red_valley_blue_is_origami_simulator_convention(tmp_path, revolute6):
    _, groups = read_svg(save_pattern(revolute6, tmp_path / "r.svg"))
    assert set(groups["Mountain"][1]) == {"#ff0000"}
    assert set(groups["Valley"][1]) == {"#0000ff"}
    assert set(groups["Cut"][1]) == {"#00ff00"}
    assert set(groups["Boundary"][1]) == {"#000000"}


@pytest.mark.parametrize("name", list(CLIPPED_COUNTS))
def test_clipped_counts(tmp_path, name):
    spec, (mountains, valleys) = CLIPPED_COUNTS[name]
    _, groups = read_svg(save_pattern(build(spec), tmp_path / "p.svg"))
    counts = tuple(groups[g][0].shape[0] for g in ("Mountain", "Valley", "Boundary", "Cut"))
    assert counts == (mountains, valleys, OUTLINE_LINES, OUTLINE_LINES)


def test_size_in_millimetres_and_viewbox(tmp_path, revolute6):
    root, _ = read_svg(save_pattern(revolute6, tmp_path / "r.svg", units="cm"))
    W, b, H = revolute6.width, revolute6.sideLength, revolute6.height
    assert root.get("width").endswith("mm") and root.get("height").endswith("mm")
    assert_allclose(float(root.get("width")[:-2]), 10 * (W + b), rtol=1e-10)
    assert_allclose(float(root.get("height")[:-2]), 10 * H, rtol=1e-10)
    viewbox = [float(v) for v in root.get("viewBox").split()]
    assert_allclose(viewbox, 10 * np.array([-b / 2, -H, W + b, H]), rtol=1e-10)


def test_y_is_flipped_not_mirrored(tmp_path, revolute6):
    _, groups = read_svg(save_pattern(revolute6, tmp_path / "r.svg"))
    sheet = flatten(revolute6)
    expected = sheet.select("M").copy()
    expected[:, :, 1] *= -1
    assert_allclose(groups["Mountain"][0], expected, atol=1e-9)
    # x keeps its direction: the Cut's left edge is at x = -b/2 in the file too
    assert_allclose(groups["Cut"][0][:, :, 0].min(), -revolute6.sideLength / 2)


@pytest.mark.parametrize("units", list(UNITS_IN_MM))
def test_units(tmp_path, revolute6, units):
    _, base = read_svg(save_pattern(revolute6, tmp_path / "mm.svg"))
    _, scaled = read_svg(save_pattern(revolute6, tmp_path / f"{units}.svg", units=units))
    for gid in base:
        assert_allclose(scaled[gid][0], UNITS_IN_MM[units] * base[gid][0], rtol=1e-10, atol=1e-9)


def test_perforation(tmp_path, revolute6):
    _, groups = read_svg(save_pattern(revolute6, tmp_path / "p.svg", scale=4.0, dash=0.5, gap=0.5))
    sheet = flatten(revolute6)
    L = 4.0 * lengths(sheet.select("V"))
    assert groups["Valley"][0].shape[0] == np.ceil(L / 1.0).astype(int).sum()
    assert lengths(groups["Valley"][0]).max() <= 0.5 + 1e-9
    assert groups["Cut"][0].shape[0] == OUTLINE_LINES


def test_colour_override(tmp_path, revolute6):
    _, groups = read_svg(save_pattern(revolute6, tmp_path / "r.svg", colors={"B": "#ffff00"}))
    assert set(groups["Boundary"][1]) == {"#ffff00"}
    assert set(groups["Mountain"][1]) == {"#ff0000"}


@pytest.mark.parametrize(
    ("options", "error"),
    [
        ({"colors": {"X": "#ffffff"}}, InvalidParameterError),
        ({"colors": "red"}, InvalidTypeError),
        ({"stroke_width": -1.0}, InvalidParameterError),
        ({"stroke_width": "thin"}, InvalidTypeError),
        ({"linewidth": 1.0}, InvalidTypeError),
    ],
)
def test_bad_options(tmp_path, revolute6, options, error):
    with pytest.raises(error):
        save_pattern(revolute6, tmp_path / "p.svg", **options)
    assert not (tmp_path / "p.svg").exists()
