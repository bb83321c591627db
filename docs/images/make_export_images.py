"""Make the pictures of docs/urdf.md, docs/mesh.md and docs/pdf.md.

Run from the repository root::

    python docs/images/make_export_images.py

It exports the paper's Example 1A to a temporary folder (STL, URDF, PDF), reads the files back
with the same independent readers the tests use (trimesh, yourdfpy) and draws:

* ``export_mesh.png``: the STL's triangles, shaded, joints in dark blue and tubes in grey;
* ``export_urdf.png``: the URDF at the zero configuration (faint) and at a random configuration,
  posed by yourdfpy's forward kinematics;
* ``export_pdf_page.png``: page 2 of the PDF at 10 mm per unit, drawn by the exporter's own
  page drawing (:func:`kinegami.export.pdf.draw_page`, the function that makes every PDF page)
  at 100 dpi, since rasterising the PDF itself would need a tool outside the Python environment.
"""

from __future__ import annotations

import tempfile
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402
import trimesh  # noqa: E402
import yourdfpy  # noqa: E402
from mpl_toolkits.mplot3d.art3d import Poly3DCollection  # noqa: E402

from kinegami import (  # noqa: E402
    SE3,
    EndTip,
    KinematicChain,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
)
from kinegami.export.pdf import draw_page, pdf_layout  # noqa: E402
from kinegami.export.registry import export  # noqa: E402

HERE = Path(__file__).resolve().parent
JOINT_COLOR = np.array([0.0, 0.0, 0.545])
LINK_COLOR = np.array([0.83, 0.83, 0.83])
LIGHT = np.array([0.4, -0.5, 0.77])


def example_1a() -> KinematicChain:
    """The paper's Example 1A (r = 1, n = 4)."""
    chain = KinematicChain(StartTip(4, 1, Pose=SE3.Trans(3, 3, 0), length=1.5))
    chain.append(PrismaticJoint(4, 1, neutralLength=3, numLayers=3, coneAngle=np.pi / 4,
                                Pose=SE3.Trans([5, 5, 0])))  # fmt: skip
    chain.append(RevoluteJoint(4, 1, np.pi, SE3.Ry(np.pi / 4)))
    chain.append(EndTip(4, 1, Pose=SE3.Ry(np.pi / 2), length=1.5))
    return chain


def shaded(triangles: np.ndarray, color: np.ndarray, alpha: float = 1.0) -> Poly3DCollection:
    normals = np.cross(triangles[:, 1] - triangles[:, 0], triangles[:, 2] - triangles[:, 0])
    normals /= np.maximum(np.linalg.norm(normals, axis=1, keepdims=True), 1e-300)
    light = LIGHT / np.linalg.norm(LIGHT)
    intensity = 0.45 + 0.55 * np.clip(normals @ light, 0.0, 1.0)
    colors = np.clip(color[None, :] * intensity[:, None] + 0.08, 0.0, 1.0)
    rgba = np.hstack([colors, np.full((len(colors), 1), alpha)])
    return Poly3DCollection(triangles, facecolors=rgba, edgecolors=(0, 0, 0, 0.15 * alpha),
                            linewidths=0.2)  # fmt: skip


def equal_axes(ax, points: np.ndarray) -> None:
    lo, hi = points.min(axis=0), points.max(axis=0)
    centre, half = (lo + hi) / 2, (hi - lo).max() / 2
    for setter, c in zip((ax.set_xlim, ax.set_ylim, ax.set_zlim), centre, strict=True):
        setter(c - half, c + half)
    ax.set_box_aspect((1, 1, 1))


def mesh_picture(folder: Path) -> None:
    chain = example_1a()
    export(chain, folder / "example1.obj")
    scene = trimesh.load(folder / "example1.obj", split_objects=True, group_material=False)
    fig = plt.figure(figsize=(6, 6))
    ax = fig.add_subplot(projection="3d")
    points = []
    for name, mesh in scene.geometry.items():
        color = JOINT_COLOR if name.startswith("joint_") else LINK_COLOR
        ax.add_collection3d(shaded(mesh.triangles, color))
        points.append(mesh.vertices)
    equal_axes(ax, np.vstack(points))
    ax.view_init(elev=22, azim=-58)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    ax.set_title("Example 1A as OBJ/STL: 17 closed parts (mm)", fontsize=10)
    fig.tight_layout()
    fig.savefig(HERE / "export_mesh.png", dpi=110)
    plt.close(fig)


def urdf_picture(folder: Path) -> None:
    chain = example_1a()
    path = export(chain, folder / "example1.urdf")
    robot = yourdfpy.URDF.load(str(path))
    assert robot.validate()
    q = {"joint_2": 0.8e-3, "joint_4": 1.1}  # prismatic in metres, revolute in radians
    fig = plt.figure(figsize=(6, 6))
    ax = fig.add_subplot(projection="3d")
    points = []
    for config, alpha in (({"joint_2": 0.0, "joint_4": 0.0}, 0.12), (q, 1.0)):
        robot.update_cfg(config)
        for link_name, link in robot.link_map.items():
            T = robot.get_transform(link_name)
            for visual in link.visuals:
                mesh = trimesh.load(folder / visual.geometry.mesh.filename, file_type="stl")
                triangles = (mesh.triangles @ T[:3, :3].T + T[:3, 3]) * 1000.0  # mm
                color = JOINT_COLOR if visual.name.startswith("joint_") else LINK_COLOR
                ax.add_collection3d(shaded(triangles, color, alpha))
                points.append(triangles.reshape(-1, 3))
    equal_axes(ax, np.vstack(points))
    ax.view_init(elev=22, azim=-58)
    ax.set_xlabel("x (mm)")
    ax.set_ylabel("y (mm)")
    ax.set_zlabel("z (mm)")
    ax.set_title("URDF in yourdfpy: joint_2 = 0.8 mm, joint_4 = 1.1 rad\n"
                 "(faint: zero configuration)", fontsize=10)  # fmt: skip
    fig.tight_layout()
    fig.savefig(HERE / "export_urdf.png", dpi=110)
    plt.close(fig)


def pdf_picture(folder: Path) -> None:
    pattern = example_1a().creasePattern()
    export(pattern, folder / "example1.pdf", scale=10)
    layout = pdf_layout(pattern, scale=10)
    figure = draw_page(layout, 1)
    figure.patch.set_facecolor("white")
    figure.savefig(HERE / "export_pdf_page.png", dpi=100, facecolor="white")


def main() -> None:
    with tempfile.TemporaryDirectory() as tmp:
        folder = Path(tmp)
        mesh_picture(folder)
        urdf_picture(folder)
        pdf_picture(folder)
    for name in ("export_mesh.png", "export_urdf.png", "export_pdf_page.png"):
        print(HERE / name)


if __name__ == "__main__":
    main()
