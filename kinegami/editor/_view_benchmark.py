"""The cost of a drag step in the browser view: ``python -m kinegami.editor._view_benchmark``.

The 32-joint compact chain of benchmarks/run.py in an :class:`~kinegami.editor.view.EditorView`
drawn on a viser server with no tab connected: each step is a slide (the command, the
clearance report and the new meshes and poses, which the view's listener makes from the
Change) and then the crease pattern. Prints the medians in milliseconds and the meshes each
step sent. See docs/editor.md (The browser view).
"""

from __future__ import annotations

import statistics
import time

from kinegami.editor._benchmark import compact_chain
from kinegami.editor.model import EditorModel


def main() -> None:
    from kinegami.editor.server import EditorServer

    server = EditorServer(port=0, autosave=False)
    try:
        view = server.new_view(server.server)
        view.set_model(EditorModel(compact_chain()))
        view.model.pattern()
        print("drag step on a 32-joint chain, median ms: edit+clearance+meshes + pattern = total")
        for joint in (2, 16, 30):
            for propagate in (True, False):
                rows = []
                for k in range(11):
                    sent = view.meshes_sent
                    t0 = time.perf_counter()
                    result = view.act(lambda k=k, j=joint, p=propagate: view.model.slide(
                        j, 0.05 if k % 2 == 0 else -0.05, propagate=p))  # fmt: skip
                    t1 = time.perf_counter()
                    view.model.pattern()
                    t2 = time.perf_counter()
                    if result.ok:
                        rows.append((t1 - t0, t2 - t1, view.meshes_sent - sent))
                edit = statistics.median(r[0] for r in rows) * 1e3
                pattern = statistics.median(r[1] for r in rows) * 1e3
                total = statistics.median(r[0] + r[1] for r in rows) * 1e3
                meshes = statistics.median(r[2] for r in rows)
                print(f"  joint {joint:2d}, propagate={propagate!s:5}: {edit:5.1f} + "
                      f"{pattern:5.1f} = {total:5.1f} ({meshes:g} meshes sent)")  # fmt: skip
    finally:
        server.stop()


if __name__ == "__main__":
    main()
