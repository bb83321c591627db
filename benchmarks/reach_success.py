"""How often inverse kinematics reaches targets it can reach: ``python benchmarks/reach_success.py``
(issue 31: >= 99.9% on every gallery chain, >= 99% on every fingertip of the hands at once).

For each gallery chain, ``--targets`` (default 5,000) seeded random configurations that are
clear by the design's own clearance engine; their tip poses are the targets, solved with
:func:`kinegami.reach.solve_many` on a process pool (``--workers``, default 2). Every answer is
checked as a user would: the design loaded again with ``requireClearance`` on takes the states
(``setJointStates``) and its tip is on the target within 1e-9 r; the solver's own numbers are
not trusted. For each tree (the hands, the quadruped, the gripper), ``--tree-targets`` (default
1,000) targets each of which is every tip's pose at one clear configuration, all at once.
Prints, per design, the share reached, the failures' reasons, and the wall time per target.
"""

from __future__ import annotations

import argparse
import collections
import time
from concurrent.futures import ProcessPoolExecutor
from pathlib import Path

import numpy as np

DESIGNS = Path(__file__).resolve().parents[1] / "examples" / "designs"


def clear_configurations(design, compiled, count: int, seed: int) -> np.ndarray:
    """``count`` random configurations (seeded) in which ``design`` is clear, (count, n)."""
    from kinegami.chain.model import KinematicChain
    from kinegami.clearance.engine import TreeMotion, engine_for

    rng = np.random.default_rng(seed)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    found = []
    have = 0
    while have < count:
        Q = low + (high - low) * rng.random((4 * count, low.size))
        if isinstance(design, KinematicChain):
            colliding = engine_for(design).colliding(Q, float(design.margin))
        else:
            colliding = TreeMotion(design, None, float(design.margin)).colliding(Q)
        found.append(Q[~colliding])
        have += int((~colliding).sum())
    return np.concatenate(found)[:count]


def checked(path: Path, answers, goals, r: float) -> list[bool]:
    """Each answer as the design takes it: ``setJointStates`` with requireClearance on, then
    every target tip within 1e-9 r of its target pose (position, and the rotation where the
    target has one)."""
    from kinegami.design import load_design

    design = load_design(path)
    design.requireClearance = True
    out = []
    for answer, goal in zip(answers, goals, strict=True):
        if not answer.ok:
            out.append(False)
            continue
        if not design.setJointStates(list(answer.states)):
            out.append(False)
            continue
        good = True
        for tip, T in goal.items():
            frame = np.asarray(design.Joints[tip].distal_dubins_frame(), dtype=float)
            good &= float(np.abs(frame[:3, 3] - T[:3, 3]).max()) <= 1e-9 * r
            good &= float(np.abs(frame[:3, :3] - T[:3, :3]).max()) <= 1e-9
        out.append(bool(good))
    return out


def measure(name: str, count: int, executor, seed: int = 0) -> dict:
    """Targets from ``count`` clear configurations of design ``name``, solved and checked."""
    from kinegami.design import load_design
    from kinegami.reach import kinematics, solve_many

    path = DESIGNS / f"{name}.json"
    design = load_design(path)
    compiled = kinematics(design)
    Q = clear_configurations(design, compiled, count, seed)
    poses = compiled.fkine(Q)  # (m, 4, 4) or (m, L, 4, 4)
    if poses.ndim == 3:
        goals = [{compiled.tips[0]: T} for T in poses]
        targets = list(poses)
    else:
        goals = [dict(zip(compiled.tips, P, strict=True)) for P in poses]
        targets = goals
    t0 = time.perf_counter()
    answers = solve_many(design, targets, seed=seed, executor=executor, chunk=64)
    took = time.perf_counter() - t0
    ok = checked(path, answers, goals, float(design.r))
    reasons = collections.Counter(
        a.reason.split(":")[0].split("(")[0].strip()
        for a, good in zip(answers, ok, strict=True)
        if not good
    )
    return {"name": name, "targets": count, "reached": sum(ok), "reasons": reasons,
            "seconds": took, "tips": len(compiled.tips)}  # fmt: skip


def rows(targets: int = 5000, tree_targets: int = 1000, workers: int = 2,
         names=None) -> list[tuple[str, str, str]]:  # fmt: skip
    """(figure, result, goal) rows for benchmarks/run.py."""
    import json

    from kinegami.design import DesignInfo

    def is_tree(name: str) -> bool:
        data = json.loads((DESIGNS / f"{name}.json").read_text(encoding="utf-8"))
        return DesignInfo.of(data).structure == "tree"

    if names is None:
        names = sorted(p.stem for p in DESIGNS.glob("*.json"))
    out = []
    with ProcessPoolExecutor(workers) as executor:
        for name in names:
            tree = is_tree(name)
            found = measure(name, tree_targets if tree else targets, executor)
            share = found["reached"] / found["targets"]
            why = ", ".join(f"{k} {v}" for k, v in found["reasons"].most_common(3))
            what = f"every tip ({found['tips']}) at once" if tree else "tip pose"
            out.append((
                f"solve_many, {name}: {found['targets']:,} clear {what} targets, reached exact "
                "and clear (checked by setJointStates)",
                f"{found['reached']}/{found['targets']} = {share:.2%}"
                f"{'; ' + why if why else ''}; {found['seconds'] / found['targets'] * 1e3:.2f} "
                "ms/target (wall)",
                ">= 99%" if tree else ">= 99.9%",
            ))  # fmt: skip
    return out


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--targets", type=int, default=5000, help="targets per gallery chain")
    parser.add_argument("--tree-targets", type=int, default=1000, help="targets per tree")
    parser.add_argument("--workers", type=int, default=2, help="processes")
    parser.add_argument("names", nargs="*", help="gallery designs (default: all)")
    args = parser.parse_args()
    for figure, result, goal in rows(args.targets, args.tree_targets, args.workers,
                                     args.names or None):  # fmt: skip
        print(f"{figure}: {result} (goal {goal})", flush=True)


if __name__ == "__main__":
    main()
