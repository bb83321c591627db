"""Design for a task (issue 32): ``python benchmarks/design_task.py [--full] [--workers W]``.

Position tasks: 4 targets, each the tip position of a hidden random robot at a clear
configuration (4 revolute joints from a DH table with theta 0, alpha uniform in (-pi, pi], a and
d uniform in [0, 4r]; base at the identity; the same tube, r = 1, square); ``design_for`` is
given ``"RRRR"``. Pose tasks: 2 to 6 full tip poses of a hidden random 6R robot, given
``"RRRRRR"``. Every designed robot is checked as a user would: each target solved again from the
design's home states by :func:`kinegami.reach.solve` (exact, in range, clear by the design's
own clearance), its crease pattern built, its tube measured against the same kinematics
compacted without the task (:func:`kinegami.optimize.compact_for_task` with no targets: the
joints slide and roll along their axes, the tip's frame stays on the last joint's body) and,
for comparison, against :func:`kinegami.optimize.compact`, whose end tip may slide along its
axis (which moves the tip, so other kinematics).
Infeasible tasks: a target beyond any reach of the budget, timed to the certificate. Compaction
with targets: the PUMA and 5 of its clear tip poses.

20 tasks of each kind by default, 100 with ``--full``; ``--workers`` runs tasks in parallel
(each task's time is its own wall time in its process).
"""

from __future__ import annotations

import argparse
import concurrent.futures
import math
import time
import warnings
from pathlib import Path

import numpy as np

DESIGNS = Path(__file__).resolve().parents[1] / "examples" / "designs"


def hidden_task(seed: int, joints: int, count: int, poses: bool, r: float = 1.0) -> list:
    """Targets: tip positions (or poses) of a hidden random revolute robot at ``count`` clear
    configurations."""
    from kinegami import KinematicChain
    from kinegami.clearance.engine import engine_for
    from kinegami.errors import ClearanceWarning, PlacementWarning
    from kinegami.reach import kinematics

    rng = np.random.default_rng([seed, joints, count])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlacementWarning)
        warnings.simplefilter("ignore", ClearanceWarning)
        while True:
            table = [(0.0, rng.uniform(-math.pi, math.pi), rng.uniform(0, 4 * r),
                      rng.uniform(0, 4 * r)) for _ in range(joints)]  # fmt: skip
            robot = KinematicChain.from_dh(table, 4, r, placement="safe")
            K = kinematics(robot)
            low, high = K.ranges[:, 0], K.ranges[:, 1]
            Q = low + (high - low) * rng.random((50 * count, low.size))
            Q = Q[~engine_for(robot).colliding(Q, 0.0)]
            if len(Q) >= count:
                T = [K.fkine(q) for q in Q[:count]]
                return T if poses else [t[:3, 3] for t in T]


def one_task(kind: str, seed: int) -> dict:
    """Design one task and check the result; a dict of what was measured."""
    from kinegami.errors import InfeasibleTaskError
    from kinegami.optimize import compact, compact_for_task, design_for, tube_length
    from kinegami.reach import solve

    warnings.simplefilter("ignore")
    if kind == "position":
        targets, joints = hidden_task(seed, 4, 4, False), "RRRR"
    elif kind == "pose":
        count = 2 + seed % 5  # 2 to 6 poses
        targets, joints = hidden_task(seed, 6, count, True), "RRRRRR"
    else:  # infeasible: one target 150 r away, beyond the 100 r tube
        targets = hidden_task(seed, 4, 3, False) + [np.array([150.0, 0.0, 0.0])]
        joints = "RRRR"
    t0 = time.perf_counter()
    # a hidden 6R robot's own tube, placed safely, is 136-188 r long: allow 300 r
    longest = 300.0 if kind == "pose" else None
    try:
        design, answers = design_for(targets, joints, r=1.0, numSides=4, seed=0,
                                     max_tube_length=longest, return_answers=True)  # fmt: skip
    except InfeasibleTaskError as error:
        return {"ok": False, "seconds": time.perf_counter() - t0, "proven": error.proven,
                "why": str(error)}  # fmt: skip
    seconds = time.perf_counter() - t0
    # checked as a user would, not by the search's numbers: the answer's states taken by
    # setJointStates on a copy, its tip on the target, the design's own clearance report
    reached = all(_holds(design, a.states, t) for a, t in zip(answers, targets, strict=True))
    fresh = sum(solve(design, t).ok for t in targets)  # a new solve, from the home states
    design.creasePattern()
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        plain = tube_length(compact(design, executor=pool, seed=0))
        # the same kinematics compacted: the tip's frame kept on the last joint's body (the
        # tool), no target to keep clear
        kept = tube_length(compact_for_task(design, [], executor=pool, seed=0)[0])
    return {"ok": reached, "seconds": seconds, "tube": tube_length(design), "plain": plain,
            "kept": kept, "proven": False, "why": "", "fresh": fresh,
            "targets": len(targets)}  # fmt: skip


def _holds(design, states, target) -> bool:
    """Whether ``states`` put ``design``'s tip on ``target`` (1e-9 r, 1e-9 rad) in range and
    clear, by the design's own setJointStates, frames and clearance report."""
    import copy

    from kinegami.reach import Target

    goal = Target.of(target)
    posed = copy.copy(design)
    if not posed.setJointStates(list(states)):
        return False
    tip = posed.Joints[-1].DistalDubinsFrame()
    T = np.asarray(getattr(tip, "A", tip))
    r = float(design.r)
    if np.linalg.norm(T[:3, 3] - goal.position) > 1e-9 * r:
        return False
    if goal.rotation is not None and np.abs(T[:3, :3] - goal.rotation).max() > 1e-9:
        return False
    return bool(design.clearance(list(states)).ok)


def puma_compaction() -> tuple[str, str, str]:
    """The PUMA compacted with 5 of its clear tip poses as targets."""
    from kinegami.clearance.engine import engine_for
    from kinegami.design import load_design
    from kinegami.optimize import compact_for_task, tube_length
    from kinegami.reach import kinematics, solve

    design = load_design(DESIGNS / "puma.json")
    K = kinematics(design)
    rng = np.random.default_rng(5)
    low, high = K.ranges[:, 0], K.ranges[:, 1]
    Q = low + (high - low) * rng.random((100, low.size))
    Q = Q[~engine_for(design).colliding(Q, float(design.margin))][:5]
    targets = [K.fkine(q) for q in Q]
    t0 = time.perf_counter()
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        shorter, _ = compact_for_task(design, targets, executor=pool)
    seconds = time.perf_counter() - t0
    reached = sum(solve(shorter, t).ok for t in targets)
    before, after = tube_length(design), tube_length(shorter)
    return ("PUMA compacted with 5 clear pose targets",
            f"{reached}/5 reached clear, tube {after:.1f} (before {before:.1f}), {seconds:.0f} s",
            "every target clear, tube no longer")  # fmt: skip


def rows(count: int = 20, workers: int = 1, pose_count: int | None = None,
         print_rows: bool = False, first_seed: int = 0) -> list[tuple[str, str, str]]:  # fmt: skip
    """The benchmark's rows (what, result, goal); ``pose_count`` pose tasks (default
    ``count``: each may take minutes); ``print_rows``: each row printed as it is measured,
    and one line per task; ``first_seed``: the tasks' seeds start there (default 0)."""
    out = _Rows(print_rows)
    goals = {"position": ("95%", 60.0), "pose": ("90%", 300.0), "infeasible": ("-", 1.0)}
    for kind in ("position", "pose", "infeasible"):
        number = pose_count if kind == "pose" and pose_count is not None else count
        if number <= 0:
            continue
        jobs = [(kind, seed) for seed in range(first_seed, first_seed + number)]
        if workers > 1:
            with concurrent.futures.ProcessPoolExecutor(workers) as pool:
                results = list(pool.map(one_task, *zip(*jobs, strict=True)))
        else:
            results = [one_task(*job) for job in jobs]
        if print_rows and kind != "infeasible":
            for (_, seed), r in zip(jobs, results, strict=True):
                ratio = ""
                if r["ok"] and r["plain"] > 0:
                    ratio = f", tube {r['tube']:.2f} r; / {r['kept']:.2f} r (tip kept) = " \
                        f"{r['tube'] / r['kept']:.3f}; / {r['plain']:.2f} r (tip free) = " \
                        f"{r['tube'] / r['plain']:.3f}"  # fmt: skip
                why = "" if r["ok"] else f": {r['why']}"
                print(f"  {kind} task {seed}: {'designed' if r['ok'] else 'not designed'}, "
                      f"{r['seconds']:.1f} s{ratio}{why}", flush=True)  # fmt: skip
        seconds = [r["seconds"] for r in results]
        if kind == "infeasible":
            proven = sum(r["proven"] for r in results)
            out.append((f"design_for: {number} infeasible tasks (a target 150 r away), "
                        "certificate", f"{proven}/{number} proven, max {max(seconds) * 1e3:.1f} ms",
                        "<= 1 s each"))  # fmt: skip
            continue
        ok = [r for r in results if r["ok"]]
        fresh = sum(r.get("fresh", 0) for r in results)
        asked = sum(r.get("targets", 0) for r in results)
        ratio = [r["tube"] / r["kept"] for r in ok if r["kept"] > 0]
        free = [r["tube"] / r["plain"] for r in ok if r["plain"] > 0]
        share, limit = goals[kind]
        what = "4 positions of a hidden 4R robot, RRRR" if kind == "position" \
            else "2-6 poses of a hidden 6R robot, RRRRRR"  # fmt: skip
        out += [
            (f"design_for: {number} {kind} tasks ({what}), designed and checked",
             f"{len(ok)}/{number} = {100 * len(ok) / number:.0f}%", f">= {share}"),
            (f"design_for: {kind} tasks, targets a fresh solve (home start) also reaches",
             f"{fresh}/{asked}", "-"),
            (f"design_for: {kind} tasks, seconds per task (median, max)",
             f"{np.median(seconds):.1f} s, {max(seconds):.1f} s", f"<= {limit:.0f} s each"),
            (f"design_for: {kind} tasks, tube / the same kinematics compacted (its tip's "
             "frame kept on the last joint; max)", f"{max(ratio):.2f}" if ratio else "-",
             "<= 1.2"),
            (f"design_for: {kind} tasks, tube / compacted with the end tip free to slide "
             "(which moves the tip: other kinematics; max)",
             f"{max(free):.2f}" if free else "-", "-"),
        ]  # fmt: skip
    out.append(puma_compaction())
    return list(out)


class _Rows(list):
    """A list of rows that prints each row added (when asked)."""

    def __init__(self, show: bool):
        super().__init__()
        self.show = show

    def append(self, row) -> None:
        super().append(row)
        if self.show:
            print(f"{row[0]}  |  {row[1]}  |  {row[2]}", flush=True)

    def __iadd__(self, rows):
        for row in rows:
            self.append(row)
        return self


def main() -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--full", action="store_true", help="100 tasks of each kind (not 20)")
    parser.add_argument("--tasks", type=int, default=None, help="tasks of each kind")
    parser.add_argument(
        "--pose-tasks",
        type=int,
        default=None,
        help="pose tasks (default: as many as --tasks; each may take minutes)",
    )
    parser.add_argument("--workers", type=int, default=1, help="tasks run in parallel")
    parser.add_argument(
        "--first-seed",
        type=int,
        default=0,
        help="the tasks' seeds start here (other tasks than the default ones)",
    )
    args = parser.parse_args()
    count = args.tasks if args.tasks is not None else 100 if args.full else 20
    rows(count, args.workers, args.pose_tasks, print_rows=True, first_seed=args.first_seed)


if __name__ == "__main__":
    main()
