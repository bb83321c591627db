"""Regenerate every picture of the example gallery (docs/gallery.md) with one command.

    python examples/make_gallery.py [NAME ...] [--output FOLDER]

For every design file ``examples/designs/<name>.json`` (or only the names given), this loads the
chain with the design loader and writes, into ``docs/images/gallery/`` (or FOLDER):

* ``<name>.png``: the 3D view of the chain, 640 x 560 pixels, the same camera for every entry;
* ``<name>_pattern.png``: its crease pattern (valley folds red, mountain folds blue).

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
    save_figure,
)

from kinegami import PlacementWarning  # noqa: E402
from kinegami.design import DesignError, load_design  # noqa: E402

DESIGNS = EXAMPLES / "designs"
GALLERY = EXAMPLES.parent / "docs" / "images" / "gallery"


def design_names() -> list[str]:
    """The gallery entries: one per design file, in name order."""
    return sorted(path.stem for path in DESIGNS.glob("*.json"))


def draw_entry(name: str, folder: Path) -> list[Path]:
    """Load ``examples/designs/<name>.json`` and write its two pictures into ``folder``."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)
        chain = load_design(DESIGNS / f"{name}.json")
    return [
        save_figure(draw_chain(chain), folder / f"{name}.png", CHAIN_DPI),
        save_figure(
            draw_pattern(chain.creasePattern()),
            folder / f"{name}_pattern.png",
            PATTERN_DPI,
            tight=True,
        ),
    ]


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
