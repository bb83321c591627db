"""kinegami.reach side by side with Robotics Toolbox for Python (issue 31's goals).

RTB (``roboticstoolbox-python``) is a benchmark-only extra (``pip install -e .[bench]``), never
a test dependency: without it these rows say so. Its robot is built from our own joint poses
(the elementary transforms of :meth:`kinegami.geometry.screws.JointScrews.elementary`: a fixed
step to each joint's axis frame, then Rz or tz), so both solve the same kinematics; an RTB
configuration is ours minus the design's reference states, in the movable joints.

On the same targets (tip poses of random clear configurations) it measures the share each
reaches and, for RTB, how many of its answers the design's own clearance engine finds clear
(RTB knows nothing of a tube passing through itself), and the median wall time per target:
kinegami's ``solve`` (clearance included), RTB's C++ ``ik_LM`` and its Python ``ikine_LM``.
"""

from __future__ import annotations

import statistics
import time
from pathlib import Path

import numpy as np

DESIGNS = Path(__file__).resolve().parents[1] / "examples" / "designs"


def rtb_robot(compiled):
    """An RTB ``Robot`` of the compiled design's first tip, and the columns of our
    configuration its joints are (RTB q = ours[columns] - reference)."""
    import roboticstoolbox as rtb
    from spatialmath import SE3

    screws = compiled.screws
    tip = compiled.tips[0]
    tip_body, path = int(screws.body_of[tip]), compiled.path(tip).tolist()
    steps, inverse = screws.elementary()
    ets = rtb.ETS()
    columns = []
    for b in path:
        ets = ets * rtb.ET.SE3(SE3(steps[b - 1], check=False))
        ets = ets * (rtb.ET.Rz() if screws.revolute[b - 1] else rtb.ET.tz())
        columns.append(int(screws.moving[b - 1]))
    ets = ets * rtb.ET.SE3(SE3(inverse[tip_body] @ compiled.tip_frames[0], check=False))
    robot = rtb.Robot(ets)
    columns = np.array(columns)
    reference = screws.q_ref[columns]
    robot.qlim = (compiled.ranges[columns] - reference[:, None]).T
    return robot, columns, reference


def clear_targets(design, compiled, count: int, seed: int = 0):
    """(configurations, poses) of ``count`` random clear configurations."""
    rng = np.random.default_rng(seed)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    found = []
    while len(found) < count:
        q = low + (high - low) * rng.random(low.size)
        if design.clearance(q.tolist()).ok:
            found.append(q)
    return found, [compiled.fkine(q) for q in found]


def _median_ms(times) -> str:
    return f"{statistics.median(times) * 1e3:.2f} ms"


def batch_rows(names=("puma", "revolute_spiral", "spherical_series"),
               count: int = 1000) -> list[tuple[str, str, str]]:  # fmt: skip
    """``solve_many`` on ``count`` clear pose targets against RTB's ``ik_LM`` in a loop over the
    same targets: wall time per target and the share reached (ours exact and clear, checked
    by the design's kinematics and clearance; RTB's at 1e-5 r, and how many of those clear)."""
    from kinegami.design import load_design
    from kinegami.reach import kinematics, solve_many

    try:
        import roboticstoolbox  # noqa: F401
    except ImportError:
        return [("RTB batched side by side", "skipped: roboticstoolbox-python is not installed "
                 "(pip install -e .[bench])", "-")]  # fmt: skip
    goals = {"puma": "<= 1.5x RTB ik_LM loop", "revolute_spiral": "<= RTB ik_LM loop",
             "spherical_series": "<= RTB ik_LM loop"}  # fmt: skip
    out = []
    for name in names:
        design = load_design(DESIGNS / f"{name}.json")
        compiled = kinematics(design)
        robot, columns, reference = rtb_robot(compiled)
        _, targets = clear_targets(design, compiled, count, seed=1)
        r = float(design.r)
        t0 = time.perf_counter()
        answers = solve_many(design, targets)
        ours = (time.perf_counter() - t0) / count
        reached = sum(a.ok and _reaches(design, np.array(a.states), T, 1e-9 * r)
                      and design.clearance(list(a.states)).ok
                      for a, T in zip(answers, targets, strict=True))  # fmt: skip
        times, rtb_ok, rtb_clear = _rtb(design, robot.ik_LM, targets, columns, reference, r)
        theirs = sum(times) / count
        out += [
            (f"{name}: solve_many, {count} clear pose targets, per target (wall)",
             f"{ours * 1e3:.3f} ms, {reached}/{count} exact and clear",
             f"{goals.get(name, '-')} ({ours / theirs:.2f}x)"),
            (f"{name}: RTB ik_LM in a loop, same targets, per target (wall)",
             f"{theirs * 1e3:.3f} ms, {rtb_ok}/{count} at 1e-5 r, {rtb_clear} clear", "-"),
        ]  # fmt: skip
    return out


def rows(names=("puma", "revolute_spiral", "spherical_series"),
         count: int = 40) -> list[tuple[str, str, str]]:  # fmt: skip
    """The side-by-side rows (name, result, goal) for each design."""
    from kinegami.design import load_design
    from kinegami.reach import kinematics, solve

    try:
        import roboticstoolbox  # noqa: F401
    except ImportError:
        return [("RTB side by side", "skipped: roboticstoolbox-python is not installed "
                 "(pip install -e .[bench])", "-")]  # fmt: skip
    out = []
    goals = {"puma": ("0.25 ms", "14.5 ms"), "spherical_series": ("0.39 ms", "14.3 ms"),
             "revolute_spiral": ("-", "-")}  # fmt: skip
    for name in names:
        design = load_design(DESIGNS / f"{name}.json")
        compiled = kinematics(design)
        robot, columns, reference = rtb_robot(compiled)
        configurations, targets = clear_targets(design, compiled, count)
        r = float(design.r)
        # the RTB robot is the design: same tip at the same configurations
        gap = max(float(np.abs(robot.fkine(q[columns] - reference).A - T).max())
                  for q, T in zip(configurations, targets, strict=True))  # fmt: skip
        ours, answers = [], []
        for T in targets:  # timed alone: the checks load other designs (and their engines)
            t0 = time.perf_counter()
            answers.append(solve(design, T))
            ours.append(time.perf_counter() - t0)
        ours_ok = sum(answer.ok and _checked(DESIGNS / f"{name}.json", answer.states, T,
                                             1e-9 * r)
                      for answer, T in zip(answers, targets, strict=True))  # fmt: skip
        fast, fast_ok, fast_clear = _rtb(design, robot.ik_LM, targets, columns, reference, r)
        slow, slow_ok, slow_clear = _rtb(design, robot.ikine_LM, targets, columns, reference, r)
        ik_goal, ikine_goal = goals.get(name, ("-", "-"))
        out += [
            (f"{name}: RTB robot from our poses, tip gap over {count} configurations",
             f"{gap:.1e}", "<= 1e-9"),
            (f"{name}: kinegami solve, {count} clear pose targets (reached exact and clear, "
             "median)", f"{ours_ok}/{count}, {_median_ms(ours)}",
             "99.9%; <= 3x ik_LM, <= 1/5 ikine_LM"),
            (f"{name}: RTB ik_LM (C++): reached at 1e-5 r, of them clear, median",
             f"{fast_ok}/{count}, {fast_clear} clear, {_median_ms(fast)}",
             f"issue: {ik_goal}"),
            (f"{name}: RTB ikine_LM (Python): reached at 1e-5 r, of them clear, median",
             f"{slow_ok}/{count}, {slow_clear} clear, {_median_ms(slow)}",
             f"issue: {ikine_goal}"),
        ]  # fmt: skip
    return out


def _rtb(design, method, targets, columns, reference, r):
    times, reached, clear = [], 0, 0
    base = np.array([joint.state for joint in design.Joints], dtype=float)
    for T in targets:
        t0 = time.perf_counter()
        found = method(T)
        times.append(time.perf_counter() - t0)
        if not found.success:
            continue
        q = base.copy()
        q[columns] = reference + np.asarray(found.q, dtype=float)
        if _reaches(design, q, T, 1e-5 * r):
            reached += 1
            clear += bool(design.clearance(q.tolist()).ok)
    return times, reached, clear


def _reaches(design, q, T, tolerance: float) -> bool:
    from kinegami.reach import kinematics

    return float(np.abs(kinematics(design).fkine(q) - T).max()) <= tolerance


def _checked(path: Path, states, T, tolerance: float) -> bool:
    """The answer as the design takes it: setJointStates with requireClearance on, the tip on
    the target."""
    from kinegami.design import load_design

    check = load_design(path)
    check.requireClearance = True
    if not check.setJointStates(list(states)):
        return False
    return float(np.abs(check.Joints[-1].distal_dubins_frame() - T).max()) <= tolerance


#: One fresh process: the CPU time of the first use of the compiled kernels (numba compiles
#: them unless its cache has them), printed as JSON. The clearance engine's own kernel is
#: warmed first unless "all" is given, so that the reach kernels are measured alone.
_FIRST_USE = """
import json, sys, time
import numpy as np
start = time.process_time()
from kinegami.clearance.engine import engine_for
from kinegami.design import load_design
from kinegami.reach import kinematics, solve
from kinegami.reach import inverse
designs = {designs!r}
puma = load_design(designs + "/puma.json")
series = load_design(designs + "/spherical_series.json")
arm, nine = kinematics(puma), kinematics(series)
q = np.array([joint.state for joint in puma.Joints])
if sys.argv[1] != "all":
    engine_for(puma).closest_pairs(q, 0.0)
    engine_for(series).closest_pairs(np.array([joint.state for joint in series.Joints]), 0.0)
out = {{}}
T = arm.fkine(q + 0.05 * (np.arange(q.size) % 3 - 1) * (arm.kinds != 0))  # near q0
t0 = time.process_time()
assert solve(puma, T).ok
out["first solve"] = time.process_time() - t0
# the escape's kernels, on an exact 9R solution and its closest pairs
steps, path, revolute, reference, E, columns, low, high = inverse._tip_path(nine, nine.tips[0])
engine = engine_for(series)
q9 = np.array([joint.state for joint in series.Joints])
clearance, ends, bodies, s, t, _ = engine.closest_pairs(q9, 10.0 * float(series.r))
moves = inverse._moves(engine, nine, path)
from kinegami.reach.kernels import escape_step
t0 = time.process_time()
escape_step(steps, path, revolute, reference, E, low, high, 2, float(series.r), q9[columns],
            clearance, ends, bodies, s, t, moves, 10.0 * float(series.r), 0.3)
out["first escape"] = time.process_time() - t0
out["process"] = time.process_time() - start
print(json.dumps(out))
"""


def first_use_rows(repeat: int = 2) -> list[tuple[str, str, str]]:
    """What a fresh install pays once: the CPU time (process_time) of the first ``solve``
    (the compiled descent) and of the first escape of a redundant arm (its kernels), each in
    a fresh process whose numba cache is an empty folder (``NUMBA_CACHE_DIR``), so numba
    compiles them; the reach kernels alone (the clearance kernel compiled beforehand), then
    with the clearance kernel. Kinegami's side only: RTB is not needed."""
    import json
    import os
    import subprocess
    import sys
    import tempfile

    script = _FIRST_USE.format(designs=str(DESIGNS))
    found: dict[str, list[float]] = {}
    for which in ("reach", "all"):
        for _ in range(repeat):
            with tempfile.TemporaryDirectory() as cache:
                env = dict(os.environ, NUMBA_CACHE_DIR=cache)
                run = subprocess.run([sys.executable, "-c", script, which], env=env,
                                     capture_output=True, text=True, check=True)  # fmt: skip
            for key, value in json.loads(run.stdout.strip().splitlines()[-1]).items():
                found.setdefault(f"{which}: {key}", []).append(value)
    words = {"reach: first solve": "first solve, reach kernels (the descent) compiled, CPU",
             "reach: first escape": "first escape of a redundant arm, its kernels compiled, "
                                    "CPU",
             "all: first solve": "first solve on an empty numba cache, clearance kernel too, "
                                 "CPU"}  # fmt: skip
    return [(text, " / ".join(f"{v:.1f} s" for v in found[key]), "-")
            for key, text in words.items()]  # fmt: skip


if __name__ == "__main__":
    import sys

    if "--first-use" in sys.argv:
        for row in first_use_rows():
            print(" | ".join(row))
    else:
        for row in rows() + batch_rows():
            print(" | ".join(row))
