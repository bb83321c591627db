"""What the gallery scripts share: axis poses, the output folder and the written files.

The gallery scripts (``python examples/<name>.py [folder]``) build one chain or tree each. A
chain's script calls :func:`save_outputs`, which writes into ``examples/output/<name>/`` (or the
folder given on the command line) the 3D view ``<name>.png``, the crease pattern drawing
``<name>_pattern.png`` and the pattern for a laser cutter ``<name>.dxf``. A tree is folded from
one sheet per leaf joined by printed junctions (:func:`tree_sheets`); its script calls
:func:`save_tree_outputs`, which writes the 3D view ``<name>.png`` and, for every sheet k,
``<name>_sheet_<k>_pattern.png`` and ``<name>_sheet_<k>.dxf`` (and a 3D view
``<name>_<pose>.png`` of every named configuration it is given, such as the hand's grasps).
Every file is written atomically (a temporary file in the same folder, then ``os.replace``), so
an interrupted run leaves no partial file. ``examples/make_gallery.py`` draws the gallery
pictures with the same :func:`draw_chain`, :func:`draw_tree` and :func:`draw_pattern`, so every
picture has the same view and size.
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
#: Magnification of a tree's 3D box: branches reach into the corners (legs, fingers), so less.
TREE_ZOOM = 1.15
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


def draw_chain(chain, zoom: float = ZOOM, units: str | None = None):
    """The gallery's 3D view of a chain: fixed figure size and camera, a scale bar in ``units``
    (the design's; None: units of r); returns the figure."""
    import matplotlib.pyplot as plt

    fig = plt.figure(figsize=CHAIN_FIGSIZE)
    ax = fig.add_axes((0.0, 0.0, 1.0, 1.0), projection="3d")
    chain.show(ax=ax, showJointPoses=False, units=units)
    ax.view_init(**VIEW)
    box = [np.ptp(limits) for limits in (ax.get_xlim3d(), ax.get_ylim3d(), ax.get_zlim3d())]
    ax.set_box_aspect(box, zoom=zoom)
    return fig


def draw_tree(tree, units: str | None = None):
    """The gallery's 3D view of a tree: the chains' view, magnified by TREE_ZOOM."""
    return draw_chain(tree, zoom=TREE_ZOOM, units=units)


def draw_task(chain, positions, answers, units: str | None = None):
    """The robot at each target of a task, side by side (the gallery's camera): ``answers``
    one reach answer per target (its states), ``positions`` the targets' points, drawn red;
    returns the figure."""
    import copy

    import matplotlib.pyplot as plt

    count = len(answers)
    fig = plt.figure(figsize=(4.0 * count, 3.2))
    axes = []
    for k, (point, answer) in enumerate(zip(positions, answers, strict=True)):
        ax = fig.add_axes((k / count, 0.0, 1.0 / count, 0.92), projection="3d")
        posed = copy.copy(chain)
        posed.setJointStates(list(answer.states))
        posed.show(ax=ax, showJointPoses=False, showGlobalFrame=False, units=units)
        ax.scatter(*np.reshape(point, (3, 1)), color="red", s=30, depthshade=False)
        ax.view_init(**VIEW)
        ax.set_title(f"target {k}", fontsize=9)
        axes.append(ax)
    # one scale for every panel: the box around all of them
    limits = [(min(getattr(ax, f"get_{c}lim3d")()[0] for ax in axes),
               max(getattr(ax, f"get_{c}lim3d")()[1] for ax in axes)) for c in "xyz"]  # fmt: skip
    for ax in axes:
        ax.set_xlim3d(*limits[0])
        ax.set_ylim3d(*limits[1])
        ax.set_zlim3d(*limits[2])
        ax.set_box_aspect([hi - lo for lo, hi in limits], zoom=1.15)
    return fig


def draw_pattern(pattern, units: str | None = None):
    """The crease pattern drawing (valley folds red, mountain folds blue, a scale bar in
    ``units``); returns the figure.

    Sized like ``pattern.show()`` (6 inches wide, taller for longer sheets, at most 12 inches)
    but drawn into a figure made here, so that no window opens even on a screen.
    """
    import matplotlib.pyplot as plt

    side = pattern.width / pattern.numSides
    aspect = pattern.height / (pattern.width + side)  # the sheet includes half a glue tab each side
    fig, ax = plt.subplots(figsize=(6.0, min(max(2.5, 6.0 * aspect + 1.0), 12.0)))
    pattern.show(ax=ax, units=units)
    return fig


def save_outputs(chain, name: str, folder: Path, units: str = "mm") -> list[Path]:
    """Write ``<name>.png`` (3D), ``<name>_pattern.png`` and ``<name>.dxf`` into ``folder``;
    ``units``: the chain's length unit (the pictures' scale bars; the DXF at true size)."""
    folder = Path(folder)
    pattern = chain.creasePattern()
    return [
        save_figure(draw_chain(chain, units=units), folder / f"{name}.png", CHAIN_DPI),
        save_figure(
            draw_pattern(pattern, units), folder / f"{name}_pattern.png", PATTERN_DPI, tight=True
        ),
        Path(pattern.save(dxfName=folder / f"{name}.dxf", units=units)),
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


# --- trees -------------------------------------------------------------------------------------
def tree_sheets(tree):
    """The sheets and junctions of a tree as ``kinegami build`` makes them: first every branch
    joint whose socket has no room on its link slides along its own axis (the kinematics stay;
    ``kinegami.fabrication.sheets.fit_junctions``), then the tree is cut into one sheet per leaf.

    Returns ``(fabrication, slides)``: the ``TreeFabrication`` (``.sheets``, ``.junctions``)
    and the slides made, ``[(joint, distance), ...]`` in the tree's units.
    """
    from kinegami.fabrication.sheets import fabricate, fit_junctions

    fitted, slides = fit_junctions(tree)
    return fabricate(fitted), slides


def save_tree_outputs(tree, name: str, folder: Path, poses=None, fabrication=None,
                      units: str = "mm") -> list[Path]:  # fmt: skip
    """Write ``<name>.png`` (3D), ``<name>_sheet_<k>_pattern.png`` and ``<name>_sheet_<k>.dxf``
    for every sheet k of ``tree`` into ``folder``, and ``<name>_<pose>.png`` for every entry of
    ``poses`` (pose name -> one state per joint; the tree is not changed).
    ``fabrication``: the tree's sheets if already made (default: :func:`tree_sheets`);
    ``units``: the tree's length unit, so that the DXF sheets are true size (and the pictures'
    scale bars name it)."""
    import copy
    import warnings

    from kinegami import ClearanceWarning

    folder = Path(folder)
    if fabrication is None:
        fabrication, _ = tree_sheets(tree)
    written = [save_figure(draw_tree(tree, units), folder / f"{name}.png", CHAIN_DPI)]
    for sheet in fabrication.sheets:
        stem = folder / f"{name}_sheet_{sheet.index}"
        written.append(save_figure(draw_pattern(sheet.pattern, units),
                                   Path(f"{stem}_pattern.png"), PATTERN_DPI, tight=True))  # fmt: skip
        written.append(Path(sheet.pattern.save(dxfName=Path(f"{stem}.dxf"), units=units)))
    for pose, states in (poses or {}).items():
        posed = copy.copy(tree)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", ClearanceWarning)  # drawn as it is; checked apart
            if not posed.setJointStates(states):
                raise ValueError(f"pose {pose!r}: a state is outside its joint's range")
        written.append(save_figure(draw_tree(posed, units), folder / f"{name}_{pose}.png",
                                   CHAIN_DPI))  # fmt: skip
    return written


def report_tree(tree, name: str, fabrication, slides, written: list[Path],
                units: str = "mm") -> None:  # fmt: skip
    """Print the tree's size and clearance, its sheets (pattern sizes without the glue tab),
    its junctions and the slides that made room for their sockets, and the files written."""
    leaves = sum(1 for children in tree.Children if not children)
    print(
        f"{name}: {len(tree.Joints)} joints, {leaves} leaves, total link length "
        f"{tree.totalPathLength():.2f} {units}; clearance in {units}: {tree.clearance()}"
    )
    for sheet in fabrication.sheets:
        start = (
            "the root"
            if sheet.junction is None
            else f"junction {sheet.junction}, {sheet.start_arc:.1f} {units} along its link"
        )
        print(
            f"  sheet {sheet.index}: joints {sheet.joints[0]} to {sheet.leaf}, starts at "
            f"{start}; crease pattern {sheet.pattern.width:.1f} {units} x "
            f"{sheet.pattern.height:.1f} {units}"
        )  # fmt: skip
    for junction in fabrication.junctions:
        children = ", ".join(map(str, junction.children))
        print(f"  junction {junction.index}: at joint {junction.joint}, children {children}, "
              f"trunk {junction.trunk}")  # fmt: skip
    for joint, distance in slides:
        print(f"  joint {joint} slid {distance:+.2f} {units} along its axis (its socket's room)")
    print("wrote:")
    for path in written:
        print(f"  {path}")
