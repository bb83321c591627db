"""What the gallery scripts share: axis poses, the output folder and the written files.

The gallery scripts (``python examples/<name>.py [folder]``) build one chain each, then call
:func:`save_outputs`, which writes into ``examples/output/<name>/`` (or the folder given on the
command line) the 3D view ``<name>.png``, the crease pattern drawing ``<name>_pattern.png`` and
the pattern for a laser cutter ``<name>.dxf``. Every file is written atomically (a temporary file
in the same folder, then ``os.replace``), so an interrupted run leaves no partial file.
``examples/make_gallery.py`` draws the gallery pictures with the same :func:`draw_chain` and
:func:`draw_pattern`, so every picture has the same view and size.
"""

from __future__ import annotations

import io
import os
import sys
from pathlib import Path

import numpy as np
from spatialmath import SE3

EXAMPLES = Path(__file__).resolve().parent
OUTPUT = EXAMPLES / "output"

#: Size (inches) and resolution of the 3D pictures: every gallery picture is 640 x 560 pixels.
CHAIN_FIGSIZE = (8.0, 7.0)
CHAIN_DPI = 80
#: Camera of the 3D pictures (matplotlib's default view, written out so that it stays fixed).
VIEW = {"elev": 30.0, "azim": -60.0}
#: Magnification of the 3D box (show() uses 1.15; the chains rarely fill the box's corners).
ZOOM = 1.5
PATTERN_DPI = 80
#: PNG text chunks: none, so that a new matplotlib version alone does not change the files.
PNG_METADATA = {"Software": None}


def axis_pose(point, axis, xhat) -> SE3:
    """The pose whose z axis (the axis of motion) is ``axis`` through ``point``, x along ``xhat``.

    The same construction as a design file's ``{"point", "axis", "xhat"}`` pose: z = axis/|axis|,
    x = xhat made perpendicular to z and normalised, y = z cross x. Lengths in the chain's unit.
    """
    z = np.asarray(axis, dtype=float)
    z = z / np.linalg.norm(z)
    x = np.asarray(xhat, dtype=float)
    x = x - (x @ z) * z
    x = x / np.linalg.norm(x)
    T = np.eye(4)
    T[:3, 0], T[:3, 1], T[:3, 2], T[:3, 3] = x, np.cross(z, x), z, point
    return SE3(T)


def output_folder(name: str, argv: list[str]) -> Path:
    """``argv[1]`` if given (the folder to write into), else ``examples/output/<name>``."""
    if len(argv) > 2:
        sys.exit(f"usage: python {Path(argv[0]).name} [output-folder]")
    return Path(argv[1]) if len(argv) == 2 else OUTPUT / name


def write_bytes_atomic(path: Path, data: bytes) -> Path:
    """Write ``data`` to ``path`` through a temporary file in the same folder (no partial file)."""
    path.parent.mkdir(parents=True, exist_ok=True)
    tmp = path.with_name(f".{path.name}.{os.getpid()}.tmp")
    try:
        tmp.write_bytes(data)
        os.replace(tmp, path)
    except BaseException:
        tmp.unlink(missing_ok=True)
        raise
    return path


def save_figure(fig, path: Path, dpi: int, tight: bool = False) -> Path:
    """Save a matplotlib figure as PNG atomically and close it (``tight``: crop the margins)."""
    import matplotlib.pyplot as plt

    buffer = io.BytesIO()
    try:
        fig.savefig(
            buffer,
            format="png",
            dpi=dpi,
            bbox_inches="tight" if tight else None,
            metadata=PNG_METADATA,
        )
    finally:
        plt.close(fig)
    return write_bytes_atomic(path, buffer.getvalue())


def draw_chain(chain):
    """The gallery's 3D view of a chain: fixed figure size and camera; returns the figure."""
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=CHAIN_FIGSIZE)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0), projection="3d")
    chain.show(ax=ax, showJointPoses=False)
    ax.view_init(**VIEW)
    box = [np.ptp(limits) for limits in (ax.get_xlim3d(), ax.get_ylim3d(), ax.get_zlim3d())]
    ax.set_box_aspect(box, zoom=ZOOM)
    return fig


def draw_pattern(pattern):
    """The crease pattern drawing (valley folds red, mountain folds blue); returns the figure.

    Sized like ``pattern.show()`` (6 inches wide, taller for longer sheets, at most 12 inches)
    but drawn into a figure made here, so that no window opens even on a screen.
    """
    import matplotlib.pyplot as plt

    side = pattern.width / pattern.numSides
    aspect = pattern.height / (pattern.width + side)  # the sheet includes half a glue tab each side
    fig, ax = plt.subplots(figsize=(6.0, min(max(2.5, 6.0 * aspect + 1.0), 12.0)))
    pattern.show(ax=ax)
    return fig


def save_outputs(chain, name: str, folder: Path) -> list[Path]:
    """Write ``<name>.png`` (3D), ``<name>_pattern.png`` and ``<name>.dxf`` into ``folder``."""
    folder = Path(folder)
    pattern = chain.creasePattern()
    return [
        save_figure(draw_chain(chain), folder / f"{name}.png", CHAIN_DPI),
        save_figure(draw_pattern(pattern), folder / f"{name}_pattern.png", PATTERN_DPI, tight=True),
        Path(pattern.save(dxfName=folder / f"{name}.dxf")),
    ]


def report(chain, name: str, written: list[Path], units: str = "mm") -> None:
    """Print the chain's size, the sizes of its crease pattern (without the glue tab) and of
    its sheet (with it), in ``units`` (the gallery's scripts use mm), and the files written."""
    from kinegami.pattern.sheet import flatten

    pattern = chain.creasePattern()
    xmin, ymin, xmax, ymax = flatten(pattern).bounds
    print(
        f"{name}: {len(chain.Joints)} joints, total path length "
        f"{chain.totalPathLength():.2f} {units}"
    )
    print(
        f"  crease pattern: {pattern.width:.1f} {units} x {pattern.height:.1f} {units}, without "
        f"the glue tab; sheet: {xmax - xmin:.1f} {units} x {ymax - ymin:.1f} {units} with it"
    )
    print("wrote:")
    for path in written:
        print(f"  {path}")
