"""Regenerate every picture of the example gallery (docs/gallery.md) with one command.

    python examples/make_gallery.py [NAME ...] [--output FOLDER]

For every design file ``examples/designs/<name>.json`` (or only the names given), this loads the
chain or tree with the design loader and writes, into ``docs/images/gallery/`` (or FOLDER):

* ``<name>.png``: the 3D view, 640 x 560 pixels, the same camera for every entry, with a scale
  bar in the design's ``units``;
* for a chain, ``<name>_pattern.png``: its crease pattern (valley folds red, mountain folds
  blue), axes and scale bar in the design's ``units``; for a chain designed for a task (a
  ``task`` block), ``<name>_task.png``: the robot at each of its targets;
* for a tree, ``<name>_sheet_<k>_pattern.png``: the crease pattern of every sheet k, as
  ``kinegami build`` cuts the tree (one sheet per leaf, branch joints slid where their junction
  sockets need room), and ``<name>_<pose>.png``: the 3D view in every named configuration of
  the entry's script (its ``POSES``: the hand's grasps);
* for the entries of ``WORKSPACES`` (the PUMA and the hand's middle finger),
  ``<name>_workspace.png``: the sampled workspace of the tip (:func:`kinegami.reach.workspace`,
  seed 0), clear tip positions in blue and those that pass through themselves in red, three
  orthographic views in the design's ``units``.

The pictures are reproducible byte for byte: a second run, or a run on another machine with the
same versions of matplotlib and numpy, writes the same files (no version stamp in the PNGs, faces
in a fixed order and shaded from exact normals), so git shows a picture as changed only when its
chain changed (tests/test_gallery.py checks it under another OpenBLAS kernel).

Drawing uses matplotlib's Agg backend (no screen needed). A design whose placement or edits fail
stops the command with the loader's one-line error; nothing is half-written (each picture is
written to a temporary file and then renamed).
"""

from __future__ import annotations

import argparse
import copy
import importlib.util
import sys
import time
import warnings
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

from _common import (  # noqa: E402
    CHAIN_DPI,
    EXAMPLES,
    PATTERN_DPI,
    draw_chain,
    draw_pattern,
    draw_task,
    draw_tree,
    save_figure,
    tree_sheets,
)

from kinegami import ClearanceWarning, KinematicTree, PlacementWarning  # noqa: E402
from kinegami.design import DesignError, load_design_with_info  # noqa: E402

DESIGNS = EXAMPLES / "designs"
GALLERY = EXAMPLES.parent / "docs" / "images" / "gallery"
#: Entries whose workspace is drawn: name -> (tip joint, None for a chain's last; samples).
WORKSPACES = {"puma": (None, 20_000), "hand": (11, 10_000)}
#: Resolution of the workspace pictures (15 x 5 inch figures).
WORKSPACE_DPI = 80


def design_names() -> list[str]:
    """The gallery entries: one per design file, in name order."""
    return sorted(path.stem for path in DESIGNS.glob("*.json"))


def poses_of(name: str) -> dict:
    """The named configurations of the entry's script ``examples/<name>.py`` (its ``POSES``:
    pose name -> one state per joint), or none."""
    script = EXAMPLES / f"{name}.py"
    if not script.is_file():
        return {}
    spec = importlib.util.spec_from_file_location(f"gallery_{name}", script)
    module = importlib.util.module_from_spec(spec)
    spec.loader.exec_module(module)  # the scripts only define things unless run as programs
    return dict(getattr(module, "POSES", {}))


def draw_tree_entry(tree: KinematicTree, name: str, folder: Path, units: str) -> list[Path]:
    """The 3D view of a tree, every sheet's crease pattern and the script's poses (scale bars
    in the design's ``units``)."""
    fabrication, _ = tree_sheets(tree)
    written = [save_figure(draw_tree(tree, units), folder / f"{name}.png", CHAIN_DPI)]
    for sheet in fabrication.sheets:
        path = folder / f"{name}_sheet_{sheet.index}_pattern.png"
        picture = draw_pattern(sheet.pattern, units)
        written.append(save_figure(picture, path, PATTERN_DPI, tight=True))
    for pose, states in poses_of(name).items():
        posed = copy.copy(tree)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PlacementWarning)  # a refused state returns False
            moved = posed.setJointStates(states)
        if not moved:
            raise DesignError(f"pose {pose!r}: a state is outside its joint's range",
                              field="POSES", file=EXAMPLES / f"{name}.py")  # fmt: skip
        written.append(save_figure(draw_tree(posed, units), folder / f"{name}_{pose}.png",
                                   CHAIN_DPI))  # fmt: skip
    return written


def draw_entry(name: str, folder: Path) -> list[Path]:
    """Load ``examples/designs/<name>.json`` and write its pictures into ``folder``."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)
        warnings.simplefilter("ignore", ClearanceWarning)  # the gallery states the clearance
        chain, info = load_design_with_info(DESIGNS / f"{name}.json")
        if isinstance(chain, KinematicTree):
            return draw_tree_entry(chain, name, folder, info.units) + draw_workspace(
                chain, name, folder, info.units)  # fmt: skip
    return [
        *draw_task_entry(chain, info, name, folder),
        save_figure(draw_chain(chain, units=info.units), folder / f"{name}.png", CHAIN_DPI),
        save_figure(
            draw_pattern(chain.creasePattern(), info.units),
            folder / f"{name}_pattern.png",
            PATTERN_DPI,
            tight=True,
        ),
        *draw_workspace(chain, name, folder, info.units),
    ]


def draw_task_entry(chain, info, name: str, folder: Path) -> list[Path]:
    """``<name>_task.png`` for a chain designed for a task (its design file's ``task``): the
    robot at each target, as :func:`kinegami.reach.solve` (seed 0) reaches it; none without."""
    if info.task is None:
        return []
    from kinegami.design.task import task_from_dict
    from kinegami.reach import solve

    task = task_from_dict(info.task, DESIGNS / f"{name}.json", where=("task",))
    answers = [solve(chain, target, margin=task.margin) for target in task.targets]
    missed = [k for k, answer in enumerate(answers) if not answer.ok]
    if missed:
        raise DesignError(f"target {missed[0]} of the task is not reached: "
                          f"{answers[missed[0]].reason}", field="task",
                          file=DESIGNS / f"{name}.json")  # fmt: skip
    picture = draw_task(chain, [t.position for t in task.targets], answers, info.units)
    return [save_figure(picture, folder / f"{name}_task.png", CHAIN_DPI)]


def draw_workspace(design, name: str, folder: Path, units: str) -> list[Path]:
    """``<name>_workspace.png`` for the entries of ``WORKSPACES`` (none for the others)."""
    if name not in WORKSPACES:
        return []
    from kinegami.reach import workspace

    tip, samples = WORKSPACES[name]
    cloud = workspace(design, samples, seed=0, tip=tip)
    return [save_figure(cloud.show(design, units=units), folder / f"{name}_workspace.png",
                        WORKSPACE_DPI)]  # fmt: skip


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.splitlines()[0])
    parser.add_argument(
        "names",
        nargs="*",
        metavar="NAME",
        help="design names (default: every examples/designs/*.json)",
    )
    parser.add_argument(
        "--output", type=Path, default=GALLERY, help=f"folder for the pictures (default: {GALLERY})"
    )
    args = parser.parse_args(argv)
    known = design_names()
    unknown = [name for name in args.names if name not in known]
    if unknown:
        parser.error(f"no design file for {', '.join(unknown)}; known: {', '.join(known)}")
    start = time.perf_counter()
    for name in args.names or known:
        try:
            written = draw_entry(name, args.output)
        except DesignError as error:
            print(f"error: {error}", file=sys.stderr)
            return 1
        print("\n".join(f"wrote {path}" for path in written))
    print(f"{len(args.names or known)} gallery entries in {time.perf_counter() - start:.1f} s")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
