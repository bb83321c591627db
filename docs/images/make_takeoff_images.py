"""Make docs/images/takeoff_hand_sheets.png and docs/images/takeoff_tee_folded.png.

Run from the repository root::

    python docs/images/make_takeoff_images.py

The first is the paper's hand (r = 1, n = 4) made with folded take-off junctions
(``fabricate(tree, junction="takeoff")``): its three sheets as the DXF draws them, the trunk's
two holes and the branches' skirts with their glue tabs, each hole and skirt named. The second
is a tee (n = 8: a trunk straight up, two side branches) folded from its three sheets as the
FOLD files write them (:func:`kinegami.export.fold.sheet_graph`, in the tree's world frame):
the trunk in grey, the branches in blue and orange, their glue tabs darker.
"""

from __future__ import annotations

import math
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

from kinegami import SE3, ClearanceWarning, EndTip, KinematicTree, RevoluteJoint, Waypoint  # noqa: E402
from kinegami.design import load_design_with_info  # noqa: E402
from kinegami.export.fold import sheet_graph  # noqa: E402
from kinegami.fabrication.sheets import fabricate  # noqa: E402
from kinegami.pattern.cut_graph import interior_point  # noqa: E402

HERE = Path(__file__).resolve().parent
ROOT = HERE.parent.parent
COLORS = [np.array([0.8, 0.8, 0.8]), np.array([0.35, 0.55, 0.9]), np.array([0.95, 0.6, 0.25])]
LIGHT = np.array([0.4, -0.5, 0.77]) / np.linalg.norm([0.4, -0.5, 0.77])
FIXED = {"relative": False, "safe": False, "fixedPosition": True, "fixedOrientation": True}


def hand_sheets(path: Path) -> Path:
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        tree, _ = load_design_with_info(ROOT / "examples" / "designs" / "hand.json")
    made = fabricate(tree, junction="takeoff")
    fig, axes = plt.subplots(1, 3, figsize=(12.0, 7.5), dpi=80)
    for sheet, ax in zip(made.sheets, axes, strict=True):
        sheet.pattern.show(ax=ax, title=f"sheet {sheet.index}: joints {sheet.joints[0]} to "
                                        f"{sheet.leaf}", showGlueTab=False)  # fmt: skip
        cut = sheet.pattern
        for hole, polygon in zip(cut.holes, cut.hole_polygons(), strict=True):
            x, y = polygon.mean(axis=0)
            ax.text(x, y, f"hole {hole.name}", ha="center", va="center", fontsize=9)
        if cut.skirt is not None:
            name = cut.skirt_name
            ax.text(0.5 * cut.width, -0.9, f"skirt {name}: glue the tabs inside hole {name}",
                    ha="center", fontsize=8)
        ax.set_xlabel("")
        ax.set_ylabel("")
    fig.suptitle("The paper's hand with folded take-offs: the trunk's sheet (hole A: the palm's "
                 "branch, hole B: the pointer's) and the two branch sheets",
                 fontsize=10)  # fmt: skip
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


def tee(n: int) -> KinematicTree:
    tree = KinematicTree(Waypoint(n, 1, SE3()))
    up = SE3.Trans(0, 0, 9) * SE3.Ry(-math.pi / 2)
    top = tree.addJoint(0, RevoluteJoint(n, 1, math.pi, up), **FIXED)
    tree.addJoint(top, EndTip(n, 1, SE3.Trans(0, 0, 13), 1), **FIXED)
    side = tree.addJoint(0, RevoluteJoint(n, 1, math.pi, SE3.Trans(5, 0, 4) * SE3.Rx(math.pi / 2)),
                         **FIXED)  # fmt: skip
    tree.addJoint(side, EndTip(n, 1, SE3.Trans(9, 0, 4) * SE3.Ry(math.pi / 2), 1), **FIXED)
    tree.addJoint(0, EndTip(n, 1, SE3.Trans(-5, 1, 6) * SE3.Ry(-math.pi / 2), 1), **FIXED)
    return tree


def tee_folded(path: Path) -> Path:
    made = fabricate(tee(8), junction="takeoff")
    polygons, colors = [], []
    for sheet in made.sheets:
        graph = sheet_graph(sheet.pattern)
        regions = sheet.pattern.regions()
        for face in graph.faces:
            pts = graph.vertices_3d[face]
            centred = pts - pts.mean(axis=0)
            normal = np.linalg.svd(centred)[2][-1]
            tab = regions.tab_index(interior_point(graph.vertices[face])[None])[0] >= 0
            base = COLORS[sheet.index] * (0.6 if tab else 1.0)
            shade = 0.4 + 0.6 * abs(float(normal @ LIGHT))
            polygons.append(pts)
            colors.append(np.clip(base * shade, 0.0, 1.0))
    fig = plt.figure(figsize=(7.0, 7.0), dpi=80)
    ax = fig.add_subplot(projection="3d")
    ax.add_collection3d(Poly3DCollection(polygons, facecolors=colors, edgecolors=(0, 0, 0, 0.25),
                                         linewidths=0.2))  # fmt: skip
    X = np.concatenate(polygons)
    lo, hi = X.min(axis=0), X.max(axis=0)
    centre, half = (lo + hi) / 2, (hi - lo).max() / 2
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=18, azim=-75)
    ax.set_title("A tee (n = 8) folded from its three sheets (FOLD folded forms)")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


if __name__ == "__main__":
    print(hand_sheets(HERE / "takeoff_hand_sheets.png"))
    print(tee_folded(HERE / "takeoff_tee_folded.png"))
