"""The cost of a step of the reach target's drag in the editor:
``python benchmarks/editor_reach.py`` (issue 31: each step answered within 50 ms on the PUMA).

The PUMA (examples/designs/puma.json) in an :class:`~kinegami.editor.view.EditorView` on a viser
server with no tab connected (so sending over the network is not counted). The target starts
at the tip and moves along a circle of radius 2r (on the side towards the base, inside the
workspace) in small steps, as a hand drags it; each step
is :meth:`EditorView.reach_to` with ``preview=True``, what the handle's update does: inverse
kinematics warm-started from the current states (clearance included), the preview of the found
states and its meshes. Every few steps the drag ends (one command). Prints the median and the
95th percentile of the steps, how many were reached, and a target beyond reach.
"""

from __future__ import annotations

import math
import statistics
import time
from pathlib import Path

import numpy as np

PUMA = Path(__file__).resolve().parents[1] / "examples" / "designs" / "puma.json"

#: Steps of the drag, and the steps between two ends of a drag (commands).
STEPS, PER_DRAG = 60, 10


def measure(steps: int = STEPS) -> dict:
    """Seconds of each preview step, of each drag's end, and the share reached."""
    from kinegami.editor.server import EditorServer

    server = EditorServer(PUMA, port=0, autosave=False)
    try:
        view = server.new_view(server.server)
        view.flush()
        r = float(view.model.chain.r)
        start = view.tip_position()
        base = np.asarray(view.model.chain.Joints[0].pose_matrix, dtype=float)[:3, 3]
        inward = (base - start) / np.linalg.norm(base - start)
        side = np.cross(inward, (0.0, 0.0, 1.0))
        side = side / np.linalg.norm(side) if np.linalg.norm(side) > 1e-9 else np.array((1, 0, 0))
        previews, ends, reached = [], [], 0
        for k in range(steps):  # a circle of radius 2r through the tip, on its inner side
            angle = 2.0 * math.pi * (k + 1) / steps
            point = start + 2.0 * r * ((1.0 - math.cos(angle)) * inward + math.sin(angle) * side)
            t0 = time.perf_counter()
            answer = view.reach_to(point, preview=True)
            previews.append(time.perf_counter() - t0)
            reached += bool(answer is not None and answer.ok)
            if (k + 1) % PER_DRAG == 0:  # let go: one command
                t0 = time.perf_counter()
                view.reach_to(point)
                ends.append(time.perf_counter() - t0)
                view.flush()
        t0 = time.perf_counter()
        far = view.reach_to(start + 1e4 * r)
        beyond = time.perf_counter() - t0
        return {"previews": previews, "ends": ends, "reached": reached, "steps": steps,
                "beyond": beyond, "beyond_reason": far.reason}  # fmt: skip
    finally:
        server.stop()


def rows() -> list[tuple[str, str, str]]:
    """(figure, result, goal) rows for benchmarks/run.py."""
    found = measure()
    previews = sorted(found["previews"])
    p95 = previews[min(len(previews) - 1, int(0.95 * len(previews)))]
    return [
        (f"editor reach drag step, PUMA ({found['reached']}/{found['steps']} reached): "
         "median / 95th percentile (wall)",
         f"{statistics.median(previews) * 1e3:.1f} / {p95 * 1e3:.1f} ms", "<= 50 ms"),
        ("editor reach drag end (one command), PUMA, median (wall)",
         f"{statistics.median(found['ends']) * 1e3:.1f} ms", "-"),
        ("editor reach, a target beyond reach (wall)", f"{found['beyond'] * 1e3:.1f} ms",
         "<= 50 ms"),
    ]  # fmt: skip


if __name__ == "__main__":
    for figure, result, goal in rows():
        print(f"{figure}: {result} (goal {goal})")
