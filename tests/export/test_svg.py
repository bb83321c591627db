"""SVG export, both flavours.

Laser flavour: parses as XML, colours, counts, millimetres, flipped y, perforation (the DXF's
sheet). Simulator flavour (the default): the FOLD export's graph in Origami Simulator's import
convention (js/pattern.js: black outline, red mountains, blue valleys, yellow flat lines,
stroke opacity = |fold angle| / 180), no point that only splits a straight line, and a user unit
small enough that the simulator's 3-unit vertex merge tolerance merges no two vertices; on the
paper's examples and on every gallery design.
"""

import math
import re
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from gallery_designs import CHAIN_DESIGNS
from numpy.testing import assert_allclose

from kinegami import pattern as catalog
from kinegami.design import load_design_with_info
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.export import save_pattern
from kinegami.export.fold import fold_dict
from kinegami.export.registry import export
from kinegami.export.svg import simulator_unit
from kinegami.pattern import TubularPattern
from kinegami.pattern.folded import FoldedFormError
from kinegami.pattern.sheet import flatten

from .conftest import build
from .helpers import lengths
from .reference_values import (
    CLIPPED_COUNTS,
    OUTLINE_LINES,
    SIMULATOR_STROKES,
    SIMULATOR_VERTEX_TOLERANCE,
    SVG_COLORS,
    UNITS_IN_MM,
)

DESIGNS = CHAIN_DESIGNS  # one crease pattern each (a tree's sheets: tests/tree)
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
    root, groups = read_svg(save_pattern(composite6, tmp_path / "c.svg", flavour="laser"))
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
    _, groups = read_svg(save_pattern(revolute6, tmp_path / "r.svg", flavour="laser"))
    assert set(groups["Mountain"][1]) == {"#ff0000"}
    assert set(groups["Valley"][1]) == {"#0000ff"}
    assert set(groups["Cut"][1]) == {"#00ff00"}
    assert set(groups["Boundary"][1]) == {"#000000"}


@pytest.mark.parametrize("name", list(CLIPPED_COUNTS))
def test_clipped_counts(tmp_path, name):
    spec, (mountains, valleys) = CLIPPED_COUNTS[name]
    _, groups = read_svg(save_pattern(build(spec), tmp_path / "p.svg", flavour="laser"))
    counts = tuple(groups[g][0].shape[0] for g in ("Mountain", "Valley", "Boundary", "Cut"))
    assert counts == (mountains, valleys, OUTLINE_LINES, OUTLINE_LINES)


def test_size_in_millimetres_and_viewbox(tmp_path, revolute6):
    root, _ = read_svg(save_pattern(revolute6, tmp_path / "r.svg", units="cm", flavour="laser"))
    W, b, H = revolute6.width, revolute6.sideLength, revolute6.height
    assert root.get("width").endswith("mm") and root.get("height").endswith("mm")
    assert_allclose(float(root.get("width")[:-2]), 10 * (W + b), rtol=1e-10)
    assert_allclose(float(root.get("height")[:-2]), 10 * H, rtol=1e-10)
    viewbox = [float(v) for v in root.get("viewBox").split()]
    assert_allclose(viewbox, 10 * np.array([-b / 2, -H, W + b, H]), rtol=1e-10)


def test_y_is_flipped_not_mirrored(tmp_path, revolute6):
    _, groups = read_svg(save_pattern(revolute6, tmp_path / "r.svg", flavour="laser"))
    sheet = flatten(revolute6)
    expected = sheet.select("M").copy()
    expected[:, :, 1] *= -1
    assert_allclose(groups["Mountain"][0], expected, atol=1e-9)
    # x keeps its direction: the Cut's left edge is at x = -b/2 in the file too
    assert_allclose(groups["Cut"][0][:, :, 0].min(), -revolute6.sideLength / 2)


@pytest.mark.parametrize("units", list(UNITS_IN_MM))
def test_units(tmp_path, revolute6, units):
    _, base = read_svg(save_pattern(revolute6, tmp_path / "mm.svg", flavour="laser"))
    _, scaled = read_svg(
        save_pattern(revolute6, tmp_path / f"{units}.svg", units=units, flavour="laser")
    )
    for gid in base:
        assert_allclose(scaled[gid][0], UNITS_IN_MM[units] * base[gid][0], rtol=1e-10, atol=1e-9)


def test_perforation(tmp_path, revolute6):
    _, groups = read_svg(
        save_pattern(revolute6, tmp_path / "p.svg", scale=4.0, dash=0.5, gap=0.5, flavour="laser")
    )
    sheet = flatten(revolute6)
    L = 4.0 * lengths(sheet.select("V"))
    assert groups["Valley"][0].shape[0] == np.ceil(L / 1.0).astype(int).sum()
    assert lengths(groups["Valley"][0]).max() <= 0.5 + 1e-9
    assert groups["Cut"][0].shape[0] == OUTLINE_LINES


def test_colour_override(tmp_path, revolute6):
    _, groups = read_svg(
        save_pattern(revolute6, tmp_path / "r.svg", colors={"B": "#ffff00"}, flavour="laser")
    )
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
        save_pattern(revolute6, tmp_path / "p.svg", flavour="laser", **options)
    assert not (tmp_path / "p.svg").exists()


# --- simulator flavour (the default) --------------------------------------------------------


def read_simulator_svg(path):
    """(root, unit in mm, lines): every line as (kind, group stroke, stroke, opacity,
    (x1, y1, x2, y2) in mm with y up)."""
    root = ET.parse(path).getroot()
    viewbox = [float(v) for v in root.get("viewBox").split()]
    assert root.get("width").endswith("mm")
    unit = float(root.get("width")[:-2]) / viewbox[2]
    lines = []
    for g in root.findall("svg:g", NS):
        for e in g.findall("svg:line", NS):
            x1, y1, x2, y2 = (float(e.get(a)) for a in ("x1", "y1", "x2", "y2"))
            opacity = e.get("stroke-opacity")
            lines.append(
                (
                    g.get("id"),
                    g.get("stroke"),
                    e.get("stroke"),
                    None if opacity is None else float(opacity),
                    (x1 * unit, -y1 * unit, x2 * unit, -y2 * unit),
                )
            )
    return root, unit, lines


def _key(point, unit) -> tuple:
    return (round(point[0] / unit), round(point[1] / unit))


def fold_edges_by_position(data: dict, unit: float) -> dict:
    """{frozenset of the two end points (rounded to the SVG unit): (assignment, fold angle)}."""
    V = data["vertices_coords"]
    out = {}
    for (a, c), label, angle in zip(
        data["edges_vertices"], data["edges_assignment"], data["edges_foldAngle"], strict=True
    ):
        out[frozenset((_key(V[a], unit), _key(V[c], unit)))] = (label, angle)
    return out


def simulator_kind(label: str, angle: float) -> str:
    """The simulator's kind of a FOLD edge: flat (F) for a crease folded by 0 degrees."""
    return "F" if label == "F" or (label in "MV" and angle == 0.0) else label


def check_simulator_svg(path, data: dict) -> None:
    """Every check of the issue on one simulator-flavour SVG against its FOLD data."""
    root, unit, lines = read_simulator_svg(path)
    kinds = {"Outline": "B", "Mountain": "M", "Valley": "V", "Flat": "F"}
    edges = fold_edges_by_position(data, unit)
    assert len(lines) == len(edges)  # the FOLD's edges, each once
    seen = set()
    for gid, group_stroke, stroke, opacity, (x1, y1, x2, y2) in lines:
        kind = kinds[gid]
        assert stroke == group_stroke == SIMULATOR_STROKES[kind]
        key = frozenset((_key((x1, y1), unit), _key((x2, y2), unit)))
        label, angle = edges[key]
        seen.add(key)
        assert simulator_kind(label, angle) == kind
        if kind in ("M", "V"):
            assert opacity == pytest.approx(abs(angle) / 180.0, abs=1e-9)
            assert 0.0 < opacity <= 1.0
        else:
            assert opacity is None  # full opacity: the simulator's 180 for M/V, ignored else
    assert seen == set(edges)
    # no degree-2 point on a straight line
    ends = np.array([line[4] for line in lines]).reshape(-1, 2, 2) / unit
    P, index = np.unique(np.round(ends.reshape(-1, 2)), axis=0, return_inverse=True)
    E = index.reshape(-1, 2)
    degree = np.bincount(E.ravel(), minlength=P.shape[0])
    for v in np.flatnonzero(degree == 2):
        a, c = (int(e[0] if e[1] == v else e[1]) for e in E[(E == v).any(axis=1)])
        u, w = P[a] - P[v], P[c] - P[v]
        cosine = u @ w / np.linalg.norm(u) / np.linalg.norm(w)
        assert cosine > -1.0 + 1e-9, f"point {P[v]} only splits a straight line"
    # the simulator's merge tolerance (user units) merges no two points and puts no point on
    # an edge it does not end on
    limit = 10 * SIMULATOR_VERTEX_TOLERANCE
    distances = np.linalg.norm(P[:, None] - P[None], axis=2)
    np.fill_diagonal(distances, np.inf)
    assert distances.min() >= limit
    a, c = P[E[:, 0]], P[E[:, 1]]
    for i in range(E.shape[0]):
        t = np.clip((P - a[i]) @ (c[i] - a[i]) / np.sum((c[i] - a[i]) ** 2), 0.0, 1.0)
        gap = np.linalg.norm(P - (a[i] + t[:, None] * (c[i] - a[i])), axis=1)
        gap[E[i]] = np.inf
        assert gap.min() >= limit
    # true size: width and height in mm are the sheet's
    V = np.array(data["vertices_coords"])
    assert_allclose(float(root.get("width")[:-2]), np.ptp(V[:, 0]), rtol=1e-9)
    assert_allclose(float(root.get("height")[:-2]), np.ptp(V[:, 1]), rtol=1e-9)
    viewbox = [float(v) for v in root.get("viewBox").split()]
    assert_allclose(np.array(viewbox[2:]) * unit, np.ptp(V, axis=0), rtol=1e-9)
    assert 10.0 ** round(math.log10(unit)) == pytest.approx(unit, rel=1e-12)


def test_default_flavour_is_for_origami_simulator(tmp_path, composite6):
    root, _, lines = read_simulator_svg(save_pattern(composite6, tmp_path / "c.svg"))
    groups = {gid for gid, *_ in lines}
    assert groups == {"Outline", "Mountain", "Valley", "Flat"} or groups == {
        "Outline", "Mountain", "Valley"
    }  # fmt: skip
    outline = [stroke for gid, _, stroke, _, _ in lines if gid == "Outline"]
    assert outline and set(outline) == {"#000000"}
    assert "Origami Simulator" in root.find("svg:title", NS).text


def test_simulator_svg_is_the_fold_graph(tmp_path, composite6):
    path = save_pattern(composite6, tmp_path / "c.svg")
    check_simulator_svg(path, fold_dict(composite6))


def test_simulator_svg_units(tmp_path, revolute6):
    path = save_pattern(revolute6, tmp_path / "r.svg", units="cm", scale=2.0)
    check_simulator_svg(path, fold_dict(revolute6, units="cm", scale=2.0))
    root, _, _ = read_simulator_svg(path)
    W, b, H = revolute6.width, revolute6.sideLength, revolute6.height
    assert_allclose(float(root.get("width")[:-2]), 20 * (W + b), rtol=1e-10)
    assert_allclose(float(root.get("height")[:-2]), 20 * H, rtol=1e-10)


def test_simulator_svg_of_a_chain_through_the_registry(tmp_path, example_1a):
    path = export(example_1a, tmp_path / "chain.svg", units="cm")
    check_simulator_svg(path, fold_dict(example_1a, units="cm"))


def test_flat_creases_are_drawn_as_flat_lines(tmp_path, composite6):
    """A crease that the folded form leaves flat (angle 0) would have opacity 0, which the
    simulator reads as no target at all; it is drawn yellow, the simulator's flat line."""
    data = fold_dict(composite6)
    flat = sum(
        1 for a, f in zip(data["edges_assignment"], data["edges_foldAngle"], strict=True)
        if a in "MV" and f == 0.0
    )  # fmt: skip
    _, _, lines = read_simulator_svg(save_pattern(composite6, tmp_path / "c.svg"))
    drawn = sum(1 for gid, *_ in lines if gid == "Flat")
    assert drawn == flat + data["edges_assignment"].count("F")


@pytest.mark.parametrize(
    ("options", "error", "words"),
    [
        ({"perforate": True}, InvalidParameterError, "flavour='laser'"),
        ({"dash": 1.0}, InvalidParameterError, "flavour='laser'"),
        ({"colors": {"M": "#ff0000"}}, InvalidParameterError, "flavour='laser'"),
        ({"skip_creases_on_cut": True}, InvalidParameterError, "flavour='laser'"),
        ({"flavour": "inkscape"}, InvalidParameterError, "'simulator', 'laser'"),
        ({"flavour": None}, InvalidParameterError, "'simulator', 'laser'"),
        ({"units": "furlong"}, InvalidParameterError, "units"),
        ({"scale": -1.0}, InvalidParameterError, "scale"),
        ({"stroke_width": 0.0}, InvalidParameterError, "stroke_width"),
        ({"linewidth": 1.0}, InvalidTypeError, "linewidth"),
    ],
)
def test_simulator_flavour_bad_options(tmp_path, revolute6, options, error, words):
    with pytest.raises(error, match=re.escape(words)):
        save_pattern(revolute6, tmp_path / "p.svg", **options)
    assert not (tmp_path / "p.svg").exists()


def test_hand_made_pattern_needs_the_laser_flavour(tmp_path):
    tube = catalog.TubeFittingPattern(4, 1.0, 1.0)
    custom = TubularPattern(
        4, 1.0, tube.vertices_coords, tube.edges_vertices, tube.edges_assignment,
        tube.proximalBase, tube.distalBase, tube.proximalMarker, tube.distalMarker, tube.height,
    )  # fmt: skip
    with pytest.raises(FoldedFormError, match=re.escape("flavour='laser'")):
        save_pattern(custom, tmp_path / "p.svg")
    assert not (tmp_path / "p.svg").exists()
    root, groups = read_svg(save_pattern(custom, tmp_path / "p.svg", flavour="laser"))
    assert set(groups) == set(SVG_COLORS)


def test_user_unit_is_the_largest_power_of_ten_that_keeps_vertices_apart():
    # two vertices 0.5 mm apart on a 10 mm edge: 0.5 / 30 = 0.0167 -> 0.01 mm
    P = np.array([[0.0, 0.0], [10.0, 0.0], [0.5, 0.0]])
    E = np.array([[0, 2], [2, 1]])
    assert simulator_unit(P, E) == pytest.approx(0.01)
    # a vertex 0.02 mm off an edge it is not on: 0.02 / 30 -> 0.0001 mm
    P = np.array([[0.0, 0.0], [10.0, 0.0], [5.0, 0.02], [5.0, 3.0]])
    E = np.array([[0, 1], [2, 3]])
    assert simulator_unit(P, E) == pytest.approx(1e-4)
    # everything far apart: at most 1 mm
    P = np.array([[0.0, 0.0], [1000.0, 0.0], [0.0, 1000.0]])
    assert simulator_unit(P, np.array([[0, 1], [1, 2], [2, 0]])) == 1.0


@pytest.mark.parametrize("path", DESIGNS, ids=[p.stem for p in DESIGNS])
def test_gallery_svg_for_origami_simulator(tmp_path, path):
    """Every gallery design written as the CLI writes it: black outline, opacities equal to
    |fold angle| / 180 of the FOLD file, no point splitting a straight line, nothing the
    simulator's merge tolerance could merge."""
    chain, info = load_design_with_info(path)
    svg = export(chain, tmp_path / "p.svg", units=info.units, twistPortion=info.twistPortion)
    data = fold_dict(chain, units=info.units, twistPortion=info.twistPortion)
    check_simulator_svg(svg, data)
