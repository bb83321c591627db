"""Make docs/images/simulator_*.png: gallery designs folded by Origami Simulator.

Run from the repository root, with a copy of Origami Simulator
(https://github.com/amandaghassaei/OrigamiSimulator), Debian's chromium and the dev extra
(playwright)::

    python docs/images/make_simulator_images.py PATH_TO_ORIGAMI_SIMULATOR

It exports Example 1 as FOLD and as SVG and the PUMA arm as FOLD (as ``kinegami build`` does),
imports each through the simulator's file input in headless Chromium, folds it to 100 % and
runs the simulator's solver (Example 1: 36 000 steps for both files, so the two pictures show
the same moment; the PUMA arm: until the average vertex error is below 1 %, at most 60 000
steps), and saves a screenshot of the page, the SVG's model turned to the FOLD's way up
(tests/export/origami_simulator.py drives the browser). It prints the error reached.
"""

from __future__ import annotations

import math
import sys
import tempfile
from pathlib import Path

HERE = Path(__file__).resolve().parent
sys.path.insert(0, str(HERE.parents[1]))

from kinegami.design import load_design_with_info  # noqa: E402
from kinegami.export.registry import export  # noqa: E402
from tests.export.origami_simulator import OrigamiSimulator  # noqa: E402

#: (design, file suffix, error to reach in percent, steps at most)
PICTURES = (
    ("example1", ".fold", 0.0, 36_000),
    ("example1", ".svg", 0.0, 36_000),
    ("puma", ".fold", 1.0, 60_000),
)


def main(folder: str) -> None:
    designs = HERE.parents[1] / "examples" / "designs"
    with tempfile.TemporaryDirectory() as tmp, OrigamiSimulator(Path(folder)) as simulator:
        for design, suffix, below, steps in PICTURES:
            chain, info = load_design_with_info(designs / f"{design}.json")
            path = Path(tmp) / f"{design}{suffix}"
            export(chain, path, units=info.units, twistPortion=info.twistPortion)
            shot = HERE / f"simulator_{design}_{suffix[1:]}.png"
            result = simulator.fold(
                path, below=below, within=math.inf, max_steps=steps, screenshot=shot
            )
            print(
                f"{shot.name}: {result.steps} steps, average vertex error {result.error} %, "
                f"creases {result.deviation:.1f} degrees off their targets on average"
            )


if __name__ == "__main__":
    if len(sys.argv) != 2:
        sys.exit(__doc__)
    main(sys.argv[1])
