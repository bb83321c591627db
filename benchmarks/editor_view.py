"""The cost of a drag step in the browser view: ``python benchmarks/editor_view.py``.

The 32-joint compact chain of benchmarks/run.py in an :class:`~kinegami.editor.view.EditorView`
drawn on a viser server with no tab connected (so sending over the network is not counted).
For joints near the start, middle and end, with and without propagation, 11 steps each of:

* a live handle drag (:meth:`EditorView.drag_preview`): the slide as a preview, the clearance
  report and the meshes and poses the listener makes, with the crease-pattern panel deferred
  to the pause after the drag;
* the pause after it: the crease pattern and its drawing (:meth:`EditorView.flush`);
* a slide as a command (the drag's end, or the Slide buttons), pattern deferred likewise.

Prints the medians in milliseconds and the meshes each step sent. Then the same for a tree,
the paper's hand (examples/designs/hand.json), on a server with its worker process: the pause
after a step there draws the tree's sheets, whose junctions the worker fits first (as designed,
and after Fit junctions has made the slides in the design). See docs/editor.md (The browser
view, Trees).
"""

from __future__ import annotations

import math
import statistics
import sys
import time
from pathlib import Path

sys.path.insert(0, str(Path(__file__).resolve().parent))  # run.py beside this file

from run import compact_chain  # noqa: E402

from kinegami.editor.model import EditorModel  # noqa: E402


def _median_ms(values) -> float:
    return statistics.median(values) * 1e3 if values else math.nan


def _drags(view, joint: int, steps: int):
    """``steps`` live drags of the selected ``joint`` along its axis, each followed by the pause
    (:meth:`EditorView.flush`): (drag seconds, pause seconds, meshes sent, last result)."""
    pose = view.model.chain.Joints[joint].pose_matrix.copy()
    drags, pauses, sent, result = [], [], [], None
    for k in range(steps):
        target = pose[:3, 3] + (0.05 if k % 2 == 0 else 0.1) * pose[:3, 2]
        before = view.meshes_sent
        t0 = time.perf_counter()
        result = view.drag_preview(target, view._gizmo.wxyz)
        t1 = time.perf_counter()
        view.flush()
        t2 = time.perf_counter()
        if result is not None and result.ok:
            drags.append(t1 - t0)
            pauses.append(t2 - t1)
            sent.append(view.meshes_sent - before)
    view.drag_to(pose[:3, 3], view._gizmo.wxyz)  # back where it began
    return drags, pauses, sent, result


def _slides(view, joint: int, propagate: bool, steps: int) -> list[float]:
    """Seconds of ``steps`` slide commands of ``joint`` (back and forth by 0.05)."""
    commands = []
    for k in range(steps):
        t0 = time.perf_counter()
        result = view.act(lambda k=k: view.model.slide(
            joint, 0.05 if k % 2 == 0 else -0.05, propagate=propagate))  # fmt: skip
        t1 = time.perf_counter()
        view.flush()
        if result.ok:
            commands.append(t1 - t0)
    return commands


def main() -> None:
    from kinegami.editor.server import EditorServer

    server = EditorServer(port=0, autosave=False)
    try:
        view = server.new_view(server.server)
        view.set_model(EditorModel(compact_chain()))
        view.flush()
        print("32-joint chain, median ms: live drag step | pattern panel after the pause | "
              "slide command (meshes sent per step)")  # fmt: skip
        for joint in (2, 16, 30):
            for propagate in (True, False):
                view.model.propagate = propagate
                view.act(lambda j=joint: view.model.select(j))
                drags, pauses, sent, _ = _drags(view, joint, 11)
                commands = _slides(view, joint, propagate, 11)
                print(f"  joint {joint:2d}, propagate={propagate!s:5}: drag "
                      f"{_median_ms(drags):5.1f} | pattern {_median_ms(pauses):5.1f} | "
                      f"command {_median_ms(commands):5.1f} "
                      f"({statistics.median(sent):g} meshes)")  # fmt: skip
    finally:
        server.stop()
    trees()


def trees(steps: int = 5) -> None:
    """The paper's hand: drag step, sheets after the pause, slide command (median ms)."""
    from pathlib import Path

    from kinegami.editor.server import EditorServer

    hand = Path(__file__).resolve().parents[1] / "examples" / "designs" / "hand.json"
    server = EditorServer(hand, port=0, autosave=False)
    try:
        view = server.new_view(server.server)
        view.flush()  # starts the worker process
        print("the paper's hand (12 joints, 3 sheets), median ms: live drag step | sheets after "
              "the pause | slide command (meshes sent per step)")  # fmt: skip
        for fitted in (False, True):
            if fitted:
                view.act(view.model.fit_junctions)
                view.flush()
            state = "after Fit junctions" if fitted else "as designed"
            for joint in (1, 5, 9):
                for propagate in (True, False):
                    view.model.propagate = propagate
                    view.act(lambda j=joint: view.model.select(j))
                    view.flush()
                    drags, pauses, sent, result = _drags(view, joint, steps)
                    if not drags:
                        print(f"  {state:19}, joint {joint}, propagate={propagate!s:5}: refused "
                              f"({result.reason})")  # fmt: skip
                        continue
                    view.flush()
                    commands = _slides(view, joint, propagate, steps)
                    print(f"  {state:19}, joint {joint}, propagate={propagate!s:5}: drag "
                          f"{_median_ms(drags):5.1f} | sheets {_median_ms(pauses):6.1f} | "
                          f"command {_median_ms(commands):5.1f} "
                          f"({statistics.median(sent):g} meshes)")  # fmt: skip
    finally:
        server.stop()


if __name__ == "__main__":
    main()
