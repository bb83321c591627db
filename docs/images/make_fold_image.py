"""Make docs/images/fold_example1.png: the folded form of the paper's Example 1A.

Run from the repository root::

    python docs/images/make_fold_image.py

It builds Example 1A (r = 1, n = 4), computes the sheet of its crease pattern as the FOLD
exporter writes it (:func:`kinegami.export.fold.sheet_graph`: faces of the flat sheet and the
folded 3D position of every vertex) and draws every face in 3D with matplotlib, shaded by a
fixed light: joint modules in dark blue, link modules in grey. Mountain creases are drawn in
blue and valley creases in red, as in the paper's pattern plots.
"""

from __future__ import annotations

from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Line3DCollection, Poly3DCollection  # noqa: E402

from kinegami import SE3, EndTip, KinematicChain, PrismaticJoint, RevoluteJoint, StartTip  # noqa: E402
from kinegami.export.fold import sheet_graph  # noqa: E402
from kinegami.pattern.folded import folded_form  # noqa: E402

HERE = Path(__file__).resolve().parent
JOINT_COLOR = np.array([0.1, 0.15, 0.55])
LINK_COLOR = np.array([0.85, 0.85, 0.85])
LIGHT = np.array([0.4, -0.5, 0.77]) / np.linalg.norm([0.4, -0.5, 0.77])
JOINT_KINDS = {"revolute", "prismatic", "start_tip", "end_tip", "rebo"}


def example_1a() -> KinematicChain:
    """The paper's Example 1A (r = 1, n = 4)."""
    chain = KinematicChain(StartTip(4, 1, Pose=SE3.Trans(3, 3, 0), length=1.5))
    chain.append(PrismaticJoint(4, 1, neutralLength=3, numLayers=3, coneAngle=np.pi / 4,
                                Pose=SE3.Trans([5, 5, 0])))  # fmt: skip
    chain.append(RevoluteJoint(4, 1, np.pi, SE3.Ry(np.pi / 4)))
    chain.append(EndTip(4, 1, Pose=SE3.Ry(np.pi / 2), length=1.5))
    return chain


def main(path: Path = HERE / "fold_example1.png") -> Path:
    chain = example_1a()
    form = folded_form(chain)
    graph = sheet_graph(chain)
    X = graph.vertices_3d
    # sized by the sheet's (unsnapped) pattern: vertices that fix B6 merged in the catalog come
    # after the catalog's and count as link vertices
    joint = np.zeros(graph.pattern.numVertices, dtype=bool)
    for module in form.modules:
        if module.kind in JOINT_KINDS:
            joint[module.vertices] = True
    polygons, colors = [], []
    for face in graph.faces:
        pts = X[face]
        normal = np.cross(pts[1] - pts[0], pts[2] - pts[0])
        for k in range(3, len(pts)):  # a robust normal for faces with collinear first corners
            if np.linalg.norm(normal) > 1e-9:
                break
            normal = np.cross(pts[1] - pts[0], pts[k] - pts[0])
        normal = normal / (np.linalg.norm(normal) or 1.0)
        src = graph.source[face]
        src = src[src >= 0]
        base = JOINT_COLOR if src.size and joint[src].all() else LINK_COLOR
        shade = 0.35 + 0.65 * abs(float(normal @ LIGHT))
        polygons.append(pts)
        colors.append(np.clip(base * shade, 0.0, 1.0))
    fig = plt.figure(figsize=(8.0, 7.0), dpi=80)
    ax = fig.add_subplot(projection="3d")
    ax.add_collection3d(Poly3DCollection(polygons, facecolors=colors, edgecolors="none"))
    for label, color in (("M", "#1f3fbf"), ("V", "#d02020")):
        edges = graph.edges[graph.assignment == label]
        ax.add_collection3d(Line3DCollection(X[edges], colors=color, linewidths=0.5))
    lo, hi = X.min(axis=0), X.max(axis=0)
    centre, half = (lo + hi) / 2, (hi - lo).max() / 2
    ax.set_xlim(centre[0] - half, centre[0] + half)
    ax.set_ylim(centre[1] - half, centre[1] + half)
    ax.set_zlim(centre[2] - half, centre[2] + half)
    ax.set_box_aspect((1, 1, 1))
    ax.view_init(elev=22, azim=-60)
    ax.set_xlabel("x")
    ax.set_ylabel("y")
    ax.set_zlabel("z")
    ax.set_title("Example 1A folded from its crease pattern (FOLD foldedForm frame)")
    fig.tight_layout()
    fig.savefig(path)
    plt.close(fig)
    return path


if __name__ == "__main__":
    print(main())
