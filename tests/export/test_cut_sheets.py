"""The sheets of a folded take-off junction as the exporters write them: both nets folded in 3D
(the FOLD graphs of the trunk's sheet and of the branch's sheet) meet along one curve, the glue
tabs land on the trunk's paper, every face stays rigid; the DXF, SVG, FOLD and PDF files carry
the hole and the tabs."""

from __future__ import annotations

import json
import math
import xml.etree.ElementTree as ET

import numpy as np
import pytest
from numpy.testing import assert_allclose

from kinegami.export import export
from kinegami.export.fold import file_fold_angles, fold_dict, sheet_graph
from kinegami.export.pdf import pdf_layout
from kinegami.geometry.frames import rotation_matrix
from kinegami.pattern import (
    ElbowFittingPattern,
    TubeFittingPattern,
    TubularPattern,
    TwistFittingPattern,
)
from kinegami.pattern.cutout import CutPattern, SheetHole, points_in_polygon
from kinegami.pattern.folded import UVA_TO_DUBINS, unsnapped_form
from kinegami.pattern.takeoff import takeoff_junction

ALL_N = (4, 6, 8, 10, 12, 16)
#: Agreement of the two folded nets, relative to the size of the coordinates (measured: 1e-14).
NET_TOL = 1e-9
#: Hole height in the trunk's tube module, and the module's height (r = 1).
Y0, TUBE = 2.0, 4.0


def random_dubins_frame(seed: int) -> np.ndarray:
    rng = np.random.default_rng(seed)
    F = np.eye(4)
    F[:3, :3] = rotation_matrix(rng.normal(size=3), rng.uniform(0, 2 * math.pi))
    F[:3, 3] = rng.uniform(-5, 5, size=3)
    return F


def nets(n: int, face: int, seed: int = 0, stub: float = 0.0):
    """A trunk sheet (twist, tube with the hole, elbow) and the branch sheet that starts with
    the skirt (skirt, tube, elbow), both folding in the world frame of a random start frame."""
    F = random_dubins_frame(seed)
    j = takeoff_junction(n, 1.0, face, Y0, stub_length=stub)
    P = TubularPattern.concatenate([TwistFittingPattern(n, 1.0, 0.4, 0.5),
                                    TubeFittingPattern(n, 1.0, TUBE),
                                    ElbowFittingPattern(n, 1.0, 0.6, 0.3)])  # fmt: skip
    trunk = CutPattern(P, holes=[SheetHole("A", 1, j)], frame=F)
    tube_frame = unsnapped_form(P, frame=F).modules[1].proximal @ UVA_TO_DUBINS
    B = TubularPattern.concatenate([j.skirt_pattern(), TubeFittingPattern(n, 1.0, 1.5),
                                    ElbowFittingPattern(n, 1.0, 0.5, 0.2)])  # fmt: skip
    branch = CutPattern(B, skirt=j, frame=j.skirt_frame(tube_frame))
    return trunk, branch, j, tube_frame


def vertex_at(graph, xy, tol=1e-9) -> int:
    d = np.hypot(*(graph.vertices - xy).T)
    k = int(np.argmin(d))
    assert d[k] <= tol, (xy, d[k])
    return k


def seg_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance of each 3D point to the nearest of the segments a-b."""
    d = b - a
    t = np.clip(np.einsum("ijk,jk->ij", points[:, None] - a[None], d) / (d * d).sum(1), 0, 1)
    return np.linalg.norm(a[None] + t[..., None] * d[None] - points[:, None], axis=2).min(1)


def hole_edges_3d(graph, cut) -> tuple[np.ndarray, np.ndarray]:
    """The trunk graph's edges on its hole (paper's edge not on the outer rectangle), in 3D."""
    xmin, ymin, xmax, ymax = graph.bounds
    E = graph.edges[graph.assignment == "B"]
    mid = 0.5 * (graph.vertices[E[:, 0]] + graph.vertices[E[:, 1]])
    tol = 1e-9
    outer = ((np.abs(mid[:, 0] - xmin) < tol) | (np.abs(mid[:, 0] - xmax) < tol)
             | (np.abs(mid[:, 1] - ymin) < tol) | (np.abs(mid[:, 1] - ymax) < tol))  # fmt: skip
    E = E[~outer]
    return graph.vertices_3d[E[:, 0]], graph.vertices_3d[E[:, 1]]


def mouth_3d(graph, j) -> tuple[np.ndarray, np.ndarray]:
    """The fish-mouth of the branch graph in 3D, segment by segment (one turn)."""
    W = j.prism.W
    fm = j.fish_mouth - [0.0, j.skirt_base]
    nxt = np.roll(fm, -1, axis=0)
    nxt[-1, 0] += W
    a = np.array([graph.vertices_3d[vertex_at(graph, p)] for p in fm])
    b = np.array([graph.vertices_3d[vertex_at(graph, p)] for p in nxt])
    return a, b


def samples(a, b, fractions=(0.0, 0.25, 0.5, 0.75, 1.0)) -> np.ndarray:
    f = np.asarray(fractions)[None, :, None]
    return (a[:, None] + f * (b - a)[:, None]).reshape(-1, 3)


def tab_faces(graph, cut) -> list[np.ndarray]:
    regions = cut.regions()
    from kinegami.pattern.cut_graph import interior_point

    out = []
    for f in graph.faces:
        if regions.tab_index(interior_point(graph.vertices[f])[None])[0] >= 0:
            out.append(f)
    return out


# --- both nets folded: one boundary ----------------------------------------------------------


@pytest.mark.parametrize("n", ALL_N)
@pytest.mark.parametrize("where", ["middle", "seam", "other"])
def test_both_folded_nets_meet_along_one_curve(n, where):
    """The hole's edges of the folded trunk sheet and the fish-mouth of the folded branch sheet
    are the same closed curve in space: every point of either (vertices and points along every
    edge) lies on the other, to 1e-9 of the coordinates' size."""
    face = {"middle": n // 2 - 1, "seam": n - 1, "other": 1}[where]
    trunk, branch, j, _ = nets(n, face, seed=n + face)
    gT, gB = sheet_graph(trunk), sheet_graph(branch)
    ha, hb = hole_edges_3d(gT, trunk)
    ma, mb = mouth_3d(gB, j)
    scale = float(np.abs(gT.vertices_3d).max())
    assert seg_distance(samples(ha, hb), ma, mb).max() <= NET_TOL * scale
    assert seg_distance(samples(ma, mb), ha, hb).max() <= NET_TOL * scale
    # the hole's vertices are the fish-mouth's (each at least once)
    assert seg_distance(ma, ha, hb).max() <= NET_TOL * scale


@pytest.mark.parametrize("n", ALL_N)
def test_the_folded_tabs_land_on_the_trunks_paper_where_its_sheet_says(n):
    """Every glue tab corner, folded with the branch's sheet, is where the trunk's folded sheet
    puts the tab's footprint (the trunk face it is glued under), and lies on the trunk's surface;
    every hinge folds by the tab's valley angle."""
    face = n // 2 - 1
    trunk, branch, j, tube_frame = nets(n, face, seed=3 * n)
    gT, gB = sheet_graph(trunk), sheet_graph(branch)
    W, b, a = j.prism.W, j.prism.b, j.prism.a
    dx, dy = trunk.hole_offset(trunk.holes[0])
    scale = float(np.abs(gT.vertices_3d).max())
    angles = file_fold_angles(gB)
    for tab in j.tabs:
        corners = tab.polygon - [0.0, j.skirt_base]
        shift = -W * math.floor(float(corners[0, 0]) / W)
        corners = corners + [shift, 0.0]
        X_branch = np.array([gB.vertices_3d[vertex_at(gB, p)] for p in corners])
        # the footprint on the trunk's sheet, folded with the trunk's faces
        foot = tab.footprint + [dx, dy]
        foot[:, 0] -= W * math.floor(float(foot[:, 0].mean()) / W)
        X_trunk = []
        for q in foot:
            for f in gT.faces:
                inside = points_in_polygon(q[None], gT.vertices[f])[0]
                on_edge = seg_distance(np.append(q, 0.0)[None],
                                       np.c_[gT.vertices[f], np.zeros(len(f))],
                                       np.c_[np.roll(gT.vertices[f], -1, 0),
                                             np.zeros(len(f))])[0] < 1e-9  # fmt: skip
                if inside or on_edge:
                    A = np.c_[gT.vertices[f], np.ones(len(f))]
                    M, *_ = np.linalg.lstsq(A, gT.vertices_3d[f], rcond=None)
                    X_trunk.append(np.append(q, 1.0) @ M)
                    break
        assert len(X_trunk) == len(foot)
        assert_allclose(X_branch, np.array(X_trunk), atol=NET_TOL * scale, rtol=0)
        # on the trunk's surface: in the plane of a trunk face
        local = (X_branch - tube_frame[:3, 3]) @ tube_frame[:3, :3]
        normals = np.array([[math.cos(2 * math.pi * (k + 1) / n),
                             math.sin(2 * math.pi * (k + 1) / n)] for k in range(n)])  # fmt: skip
        gap = (local[:, :2] @ normals.T).max(axis=1) - a
        assert np.abs(gap).max() <= NET_TOL * scale
        if not tab.flush:
            u, w = vertex_at(gB, corners[0]), vertex_at(gB, corners[1])
            hinge = np.flatnonzero(((gB.edges[:, 0] == u) & (gB.edges[:, 1] == w))
                                   | ((gB.edges[:, 0] == w) & (gB.edges[:, 1] == u)))  # fmt: skip
            assert hinge.size == 1 and gB.assignment[hinge[0]] == "V"
            assert angles[hinge[0]] == pytest.approx(math.degrees(tab.foldAngle), abs=1e-6)
    assert b > 0


@pytest.mark.parametrize("n", (4, 6, 8, 12))
@pytest.mark.parametrize("stub", (0.0, 0.4))
def test_every_face_of_both_folded_sheets_is_rigid(n, stub):
    """Each face is planar and keeps its edge lengths (an isometric fold), holes and tabs
    included."""
    trunk, branch, _, _ = nets(n, 2, seed=7 + n, stub=stub)
    for graph in (sheet_graph(trunk), sheet_graph(branch)):
        for f in graph.faces:
            P2, P3 = graph.vertices[f], graph.vertices_3d[f]
            l2 = np.linalg.norm(np.roll(P2, -1, 0) - P2, axis=1)
            l3 = np.linalg.norm(np.roll(P3, -1, 0) - P3, axis=1)
            assert_allclose(l3, l2, atol=1e-9)
            centred = P3 - P3.mean(axis=0)
            assert np.linalg.svd(centred, compute_uv=False)[-1] <= 1e-9


@pytest.mark.parametrize("n", ALL_N)
def test_the_faces_cover_the_paper_and_nothing_else(n):
    """The trunk's faces cover the sheet less the hole; the branch's cover the sheet above the
    fish-mouth plus the tabs (areas computed independently)."""
    trunk, branch, j, _ = nets(n, n // 2 - 1, seed=n)
    W, b = j.prism.W, j.prism.b

    def shoelace(poly):
        x, y = poly[:, 0], poly[:, 1]
        return 0.5 * abs(float(np.dot(x, np.roll(y, -1)) - np.dot(y, np.roll(x, -1))))

    gT = sheet_graph(trunk)
    area = sum(shoelace(gT.vertices[f]) for f in gT.faces)
    assert area == pytest.approx((W + b) * trunk.height - j.hole_area, rel=1e-12)
    gB = sheet_graph(branch)
    area = sum(shoelace(gB.vertices[f]) for f in gB.faces)
    regions = branch.regions()
    xs = np.unique(np.concatenate([regions.fish_mouth[:, 0] + s for s in (-W, 0.0, W)]))
    xs = np.concatenate([[-0.5 * b], xs[(xs > -0.5 * b) & (xs < W + 0.5 * b)], [W + 0.5 * b]])
    below = float(np.trapezoid(regions.mouth_height(xs), xs))
    lo, hi = -0.5 * b - 1e-9, W + 0.5 * b + 1e-9
    tabs = sum(shoelace(t) for t in regions.tabs if t[:, 0].min() >= lo and t[:, 0].max() <= hi)
    expected = (W + b) * branch.height - below + tabs
    assert area == pytest.approx(expected, rel=1e-12)
    # every hinged tab is a face of its own (a flush tab is one face with the skirt above it)
    assert len(tab_faces(gB, branch)) >= int(np.count_nonzero(~j.flush))


# --- the files ---------------------------------------------------------------------------------


def hole_and_tab_lines(trunk, branch):
    """(hole edges in the trunk's sheet, tab free edges in the branch's sheet), in mm (units
    mm, r = 1 mm), only what lies in the strip."""
    W, b = trunk.width, trunk.sideLength
    [hole] = trunk.hole_polygons()
    edges = np.stack([hole, np.roll(hole, -1, axis=0)], axis=1)
    tabs = branch.regions().tab_outline_segments()
    keep = ((tabs[:, :, 0] >= -0.5 * b - 1e-9) & (tabs[:, :, 0] <= W + 0.5 * b + 1e-9)).all(1)
    return edges, tabs[keep]


def on_some_line(points, lines, tol=1e-6) -> np.ndarray:
    a, c = lines[None, :, 0], lines[None, :, 1]
    d = c - a
    t = np.clip(((points[:, None] - a) * d).sum(-1) / np.maximum((d * d).sum(-1), 1e-300), 0, 1)
    return np.linalg.norm(a + t[..., None] * d - points[:, None], axis=-1).min(axis=1) <= tol


def flat_samples(lines) -> np.ndarray:
    f = np.array([0.1, 0.5, 0.9])[None, :, None]
    return (lines[:, :1] + f * (lines[:, 1:] - lines[:, :1])).reshape(-1, 2)


@pytest.fixture(scope="module")
def files(tmp_path_factory):
    """Both sheets (n = 6, the hole in the middle face) as DXF, SVG (both flavours), FOLD and
    PDF."""
    pytest.importorskip("ezdxf")
    folder = tmp_path_factory.mktemp("cut_sheets")
    trunk, branch, j, _ = nets(6, 2, seed=5)
    out = {}
    for name, cut in (("trunk", trunk), ("branch", branch)):
        for suffix, options in ((".dxf", {"label": f"{name} sheet"}),
                                (".svg", {"label": f"{name} sheet", "flavour": "laser"}),
                                (".fold", {}), (".pdf", {})):  # fmt: skip
            path = folder / f"{name}{suffix}"
            export(cut, path, units="mm", **options)
            out[name, suffix] = path
        path = folder / f"{name}_simulator.svg"
        export(cut, path, units="mm")
        out[name, "simulator"] = path
    return trunk, branch, j, out


def test_the_dxf_files_cut_the_hole_and_the_tabs(files):
    import ezdxf

    trunk, branch, _, out = files
    hole, tabs = hole_and_tab_lines(trunk, branch)
    for name, wanted in (("trunk", hole), ("branch", tabs)):
        doc = ezdxf.readfile(out[name, ".dxf"])
        lines = np.array([[(e.dxf.start.x, e.dxf.start.y), (e.dxf.end.x, e.dxf.end.y)]
                          for e in doc.modelspace().query("LINE[layer=='Cut']")])  # fmt: skip
        assert on_some_line(flat_samples(wanted), lines).all(), name
        texts = [e.dxf.text for e in doc.modelspace().query("TEXT")]
        assert texts == [f"{name} sheet"]
    # the hinges are valleys in the branch's file
    doc = ezdxf.readfile(out["branch", ".dxf"])
    valleys = np.array([[(e.dxf.start.x, e.dxf.start.y), (e.dxf.end.x, e.dxf.end.y)]
                        for e in doc.modelspace().query("LINE[layer=='Valley']")])  # fmt: skip
    mouth, hinged = branch.regions().mouth_segments()
    mid = flat_samples(mouth[hinged])
    W, b = branch.width, branch.sideLength
    mid = mid[(mid[:, 0] > -0.5 * b) & (mid[:, 0] < W + 0.5 * b)]
    assert on_some_line(mid, valleys).all()


def svg_lines(path, group: str) -> np.ndarray:
    root = ET.parse(path).getroot()
    ns = {"s": "http://www.w3.org/2000/svg"}
    g = root.find(f".//s:g[@id='{group}']", ns)
    return np.array([[(float(e.get("x1")), -float(e.get("y1"))),
                      (float(e.get("x2")), -float(e.get("y2")))]
                     for e in g.findall("s:line", ns)])  # fmt: skip


def test_the_svg_files_cut_the_hole_and_the_tabs(files):
    trunk, branch, _, out = files
    hole, tabs = hole_and_tab_lines(trunk, branch)
    for name, wanted in (("trunk", hole), ("branch", tabs)):
        lines = svg_lines(out[name, ".svg"], "Cut")
        assert on_some_line(flat_samples(wanted), lines).all(), name
        assert f"{name} sheet" in out[name, ".svg"].read_text()
        # Origami Simulator's flavour: the hole and the tabs are the paper's border
        root = ET.parse(out[name, "simulator"]).getroot()
        unit = float(root.find("{http://www.w3.org/2000/svg}desc").text.split()[4])
        border = svg_lines(out[name, "simulator"], "Outline") * unit
        assert on_some_line(flat_samples(wanted), border).all(), name


def test_the_fold_files_hold_the_hole_the_tabs_and_their_fold(files):
    trunk, branch, j, out = files
    hole, tabs = hole_and_tab_lines(trunk, branch)
    for name, wanted in (("trunk", hole), ("branch", tabs)):
        data = json.loads(out[name, ".fold"].read_text())
        V = np.array(data["vertices_coords"])
        E = np.array(data["edges_vertices"])
        border = np.array(data["edges_assignment"]) == "B"
        lines = V[E[border]]
        assert on_some_line(flat_samples(wanted), lines).all(), name
        assert len(data["faces_vertices"]) > 0
    data = json.loads(out["branch", ".fold"].read_text())
    angles = np.array(data["edges_foldAngle"])[np.array(data["edges_assignment"]) == "V"]
    for tab in j.tabs:
        if not tab.flush:
            assert np.isclose(np.abs(angles), math.degrees(tab.foldAngle), atol=1e-6).any()
    # the two files, folded, meet along the hole (world frame, mm)
    folded = {}
    for name in ("trunk", "branch"):
        data = json.loads(out[name, ".fold"].read_text())
        folded[name] = np.array(data["file_frames"][0]["vertices_coords"])
    fm = j.fish_mouth - [0.0, j.skirt_base]
    Vb = np.array(json.loads(out["branch", ".fold"].read_text())["vertices_coords"])
    at = [int(np.argmin(np.hypot(*(Vb - p).T))) for p in fm]
    gap = np.linalg.norm(folded["branch"][at][:, None] - folded["trunk"][None], axis=2).min(1)
    assert gap.max() <= 1e-8


def test_the_pdf_cuts_the_hole_and_the_tabs(files):
    pytest.importorskip("matplotlib")
    trunk, branch, _, out = files
    hole, tabs = hole_and_tab_lines(trunk, branch)
    for name, cut, wanted in (("trunk", trunk, hole), ("branch", branch, tabs)):
        layout = pdf_layout(cut, units="mm")
        lines = layout.segments[layout.kinds == "C"]
        assert on_some_line(flat_samples(wanted), lines).all(), name
        assert out[name, ".pdf"].read_bytes().startswith(b"%PDF")


def test_fold_dict_of_a_cut_pattern_folds_at_its_frame():
    """Its folded form starts at the pattern's frame unless one is given."""
    trunk, _, _, _ = nets(6, 2, seed=9)
    at_frame = fold_dict(trunk)["file_frames"][0]["vertices_coords"]
    default = fold_dict(trunk, frame=np.eye(4))["file_frames"][0]["vertices_coords"]
    assert not np.allclose(at_frame, default)
