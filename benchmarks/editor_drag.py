"""The cost of a drag step in the editor: ``python benchmarks/editor_drag.py``.

One step is a slide command on a 32-joint chain (the compact chain of benchmarks/run.py),
then the clearance report and the crease pattern of the new document, as a view asks for
them. Prints the median of each part for joints near the start, middle and end, with and
without propagation. See docs/editor.md (Measured).
"""

from __future__ import annotations

import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run.py beside this file

from run import compact_chain  # noqa: E402

from kinegami.editor.model import EditorModel  # noqa: E402


def drag(model: EditorModel, joint: int, propagate: bool, steps: int = 11) -> list[tuple]:
    """(command, clearance, pattern) seconds of each step of a drag of ``joint``."""
    times = []
    for k in range(steps):
        t0 = time.perf_counter()
        result = model.slide(joint, 0.05 if k % 2 == 0 else -0.05, propagate=propagate)
        t1 = time.perf_counter()
        model.clearance()
        t2 = time.perf_counter()
        model.pattern()
        t3 = time.perf_counter()
        if result.ok:
            times.append((t1 - t0, t2 - t1, t3 - t2))
    return times


def main() -> None:
    model = EditorModel(compact_chain())
    model.pattern()  # the first pattern builds every module once
    print("slide command on a 32-joint chain, median ms: command + clearance + pattern = total")
    for joint in (2, 16, 30):
        for propagate in (True, False):
            times = drag(model, joint, propagate)
            parts = [statistics.median(t[i] for t in times) * 1e3 for i in range(3)]
            total = statistics.median(sum(t) for t in times) * 1e3
            sums = " + ".join(f"{p:5.1f}" for p in parts)
            print(f"  joint {joint:2d}, propagate={propagate!s:5}: {sums} = {total:5.1f}")


if __name__ == "__main__":
    main()
