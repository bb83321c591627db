"""The cost of a drag step in the editor: ``python -m kinegami.editor._benchmark``.

One step is a slide command on a 32-joint chain (the compact chain of benchmarks/run.py),
then the clearance report and the crease pattern of the new document, as a view asks for
them. Prints the median of each part for joints near the start, middle and end, with and
without propagation. See docs/editor.md (Measured).
"""

from __future__ import annotations

import statistics
import time
import warnings

import numpy as np
from scipy.spatial.transform import Rotation

from kinegami.chain import KinematicChain
from kinegami.editor.model import EditorModel
from kinegami.joints import PrismaticJoint, RevoluteJoint, StartTip


def compact_chain(n: int = 32, seed: int = 0, r: float = 1.0) -> KinematicChain:
    """The 32-joint compact-placement chain of benchmarks/run.py (random poses, seed 0)."""
    rng = np.random.default_rng(seed)
    chain = KinematicChain(StartTip(4, r, np.eye(4), r))
    while len(chain.Joints) < n:
        T = np.eye(4)
        T[:3, :3] = Rotation.random(random_state=int(rng.integers(1 << 31))).as_matrix()
        T[:3, 3] = rng.uniform(-4 * r, 4 * r, 3)
        i = len(chain.Joints)
        joint = (RevoluteJoint(4, r, np.pi, T) if i % 2 == 0
                 else PrismaticJoint(4, r, 3 * r, 3, np.pi / 4, T))  # fmt: skip
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            chain.append(joint, safe=False)
    return chain


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
