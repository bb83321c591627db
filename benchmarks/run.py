"""Speed and scale measurements for kinegami. Run: ``python benchmarks/run.py``.

Prints one table: what was measured, the median time (and the scale numbers for the 48-joint
safe chains). Goals (from the issues) are printed beside the measurements; they are goals,
not assertions: tests never time anything.

The whole run takes minutes; a line on stderr names each group of measurements as it starts
and its seconds when it ends (``[8/10] compact, 16-joint safe chains ... 95.1 s``), so the
table on stdout stays as it is. ``--only WORD`` runs the groups whose name contains WORD.
"""

from __future__ import annotations

import argparse
import contextlib
import io
import statistics
import sys
import tempfile
import time
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import TextIO

import numpy as np
from scipy.spatial.transform import Rotation

from kinegami import (
    KinematicChain,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
)
from kinegami.chain.joints import _catalog_pattern
from kinegami.geometry.csc import solve_csc, solve_csc_all

DESIGNS = Path(__file__).resolve().parents[1] / "examples" / "designs"


def _median_seconds(fn, repeat: int) -> float:
    times = []
    for _ in range(repeat):
        t0 = time.perf_counter()
        fn()
        times.append(time.perf_counter() - t0)
    return statistics.median(times)


def random_pose(rng: np.random.Generator, r: float, reach: float = 4.0) -> np.ndarray:
    """A random rotation and a translation uniform in [-reach r, reach r]^3."""
    T = np.eye(4)
    T[:3, :3] = Rotation.random(random_state=int(rng.integers(1 << 31))).as_matrix()
    T[:3, 3] = rng.uniform(-reach * r, reach * r, 3)
    return T


def random_joint(i: int, T: np.ndarray, numSides: int = 4, r: float = 1.0):
    """Alternating revolute and prismatic joints (the issue's test case)."""
    if i % 2 == 0:
        return RevoluteJoint(numSides, r, np.pi, T)
    return PrismaticJoint(numSides, r, 3 * r, 3, np.pi / 4, T)


def safe_chain(seed: int, n: int = 48, r: float = 1.0) -> tuple[KinematicChain, int]:
    """A random n-joint chain built with safe placement; returns it and the failure count."""
    rng = np.random.default_rng(seed)
    chain = KinematicChain(StartTip(4, r, np.eye(4), r))
    failures = 0
    for i in range(n):
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            if chain.append(random_joint(i, random_pose(rng, r), r=r)) is None:
                failures += 1
    return chain, failures


def compact_chain(n: int = 32, seed: int = 0, r: float = 1.0) -> KinematicChain:
    """A 32-joint chain built with compact placement (joints whose link fails are skipped)."""
    rng = np.random.default_rng(seed)
    chain = KinematicChain(StartTip(4, r, np.eye(4), r))
    while len(chain.Joints) < n:
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            chain.append(random_joint(len(chain.Joints), random_pose(rng, r)), safe=False)
    return chain


def chain_pair(seed: int, n: int = 16, r: float = 1.0) -> tuple[KinematicChain, KinematicChain]:
    """The issue's random chain built twice from the same joints: with safe placement, and
    with compact placement (safe placement for a joint compact placement cannot reach)."""
    rng = np.random.default_rng(seed)
    joints = [random_joint(i, random_pose(rng, r), r=r) for i in range(n)]
    safe = KinematicChain(StartTip(4, r, np.eye(4), r))
    tight = KinematicChain(StartTip(4, r, np.eye(4), r))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for joint in joints:
            safe.append(joint)
            if tight.append(joint, safe=False) is None:
                tight.append(joint)
    return safe, tight


def same_axes_compact(chain: KinematicChain) -> KinematicChain:
    """``chain``'s joints (waypoints dropped) placed again by compact placement, in world
    coordinates: the compact-placement design of the same robot (same axis lines)."""
    joints = [j for i, j in enumerate(chain.Joints) if i == 0 or not isinstance(j, Waypoint)]
    out = KinematicChain(joints[0], chain.maxAnglePerElbow)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for joint in joints[1:]:
            if out.append(joint, relative=False, safe=False) is None:
                out.append(joint, relative=False)
    return out


def clearance_rows(compact_seeds: int) -> list[tuple[str, str, str]]:
    """Clearance engine speed; safe placement clear at scale; with ``compact_seeds`` > 0 also
    :func:`compaction_rows`."""
    from kinegami.clearance import engine_for, sweep

    rows: list[tuple[str, str, str]] = []
    chain = compact_chain(32)
    states = [j.state for j in chain.Joints]
    engine_for(chain)  # built once per chain shape, then cached
    t = _median_seconds(lambda: chain.clearance(states), 20)
    rows.append(("clearance, one configuration, 32 joints", f"{t * 1e3:.2f} ms", "<= 2 ms"))
    other = compact_chain(32, seed=1)
    t0 = time.perf_counter()
    engine_for(other)
    build = (time.perf_counter() - t0) * 1e3
    rows.append(("  clearance engine build, 32 joints", f"{build:.1f} ms", "-"))
    rng = np.random.default_rng(0)
    engine = engine_for(chain)
    lo, hi = engine.ranges[:, 0], engine.ranges[:, 1]
    Q = lo + (hi - lo) * rng.random((1000, lo.size))
    t = _median_seconds(lambda: engine.worst(Q), 3)
    rows.append(("clearance, 1000 configurations, 32 joints", f"{t:.2f} s", "<= 1 s"))
    t = _median_seconds(lambda: sweep(chain, 1000), 1)
    rows.append(("  sweep (1000 samples + free intervals)", f"{t:.2f} s", "-"))

    bad = {}
    for n in (8, 16, 32, 48):
        bad[n] = sum(not safe_chain(seed, n)[0].clearance().ok for seed in range(20))
    rows.append(("safe chains self-intersecting (8/16/32/48 joints, 20 seeds)",
                 "/".join(str(bad[n]) for n in (8, 16, 32, 48)), "0/0/0/0"))  # fmt: skip

    if compact_seeds <= 0:
        return rows
    return rows + compaction_rows(compact_seeds)


def compaction_rows(compact_seeds: int) -> list[tuple[str, str, str]]:
    """Compaction of random 16-joint safe chains against its goals, and of the gallery's
    designs."""
    from kinegami.optimize import compact, tube_length

    rows: list[tuple[str, str, str]] = []
    ratios_safe, ratios_tight, ratios_same, times, clear = [], [], [], [], 0
    for seed in range(compact_seeds):
        safe, tight = chain_pair(seed)
        same = same_axes_compact(safe)
        t0 = time.perf_counter()
        out = compact(safe, seed=0, progress=False)
        times.append(time.perf_counter() - t0)
        clear += out.clearance().ok
        ratios_safe.append(out.totalPathLength() / safe.totalPathLength())
        ratios_tight.append(out.totalPathLength() / tight.totalPathLength())
        ratios_same.append(out.totalPathLength() / same.totalPathLength())

    def spread(values):
        return f"{max(values):.2f}, {statistics.median(values):.2f}, {min(values):.2f}"

    rows.append((f"compact, 16-joint safe chains ({compact_seeds} seeds), time (max, median)",
                 f"{max(times):.1f} s, {statistics.median(times):.1f} s", "<= 10 s"))  # fmt: skip
    rows.append(("  link length / safe chain's (max, median, min)", spread(ratios_safe),
                 "<= 0.5"))  # fmt: skip
    rows.append(("  / compact placement, same relative spec (max, median, min)",
                 spread(ratios_tight), "<= 0.8"))  # fmt: skip
    rows.append(("  / compact placement, same axes (max, median, min)", spread(ratios_same),
                 "-"))  # fmt: skip
    rows.append(("  clear after compaction", f"{clear}/{compact_seeds}", "all"))
    from kinegami.design import load_design

    for path in sorted(DESIGNS.glob("*.json")):
        with warnings.catch_warnings():  # the paper's hand as designed touches itself (docs)
            warnings.simplefilter("ignore")
            design = load_design(path)
        out = compact(design, seed=0, progress=False)
        change = f"{tube_length(design):.4g} -> {tube_length(out):.4g}"
        rows.append((f"  gallery {path.stem}: tube length", change, "not longer"))
    return rows


def tree_rows() -> list[tuple[str, str, str]]:
    """The algorithmic hand (examples/designs/algorithmic_hand.json, docs/trees.md): the tree
    construction's output, then compacted on 2 processes, twice (the same seed must give the
    same tree)."""
    import concurrent.futures

    from kinegami.design import load_design
    from kinegami.optimize import compact

    path = DESIGNS / "algorithmic_hand.json"
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        hand = load_design(path)
    built = time.perf_counter() - t0
    rows = [("algorithmic hand, tree construction (12 joints)", f"{built * 1e3:.0f} ms", "-"),
            ("  link length, bounding-ball radius",
             f"{hand.totalPathLength():.1f} r, {hand.boundingBall.r:.1f} r",
             "published: 762.7 r (756.0 r without its extra roll), 116 r")]  # fmt: skip
    results = []
    for _ in range(2):
        with concurrent.futures.ProcessPoolExecutor(2) as executor:
            t0 = time.perf_counter()
            small = compact(hand, seed=0, executor=executor, progress=False)
            results.append((time.perf_counter() - t0, small))
    (t, small), (_, again) = results
    same = all(np.array_equal(a.pose_matrix, b.pose_matrix)
               for a, b in zip(small.Joints, again.Joints, strict=True))  # fmt: skip
    rows += [
        ("compact, algorithmic hand (2 processes), time", f"{t:.1f} s", "<= 60 s"),
        ("  total link length", f"{small.totalPathLength():.2f} r",
         "<= 30 r (published optimiser: 36-70 r)"),
        ("  bounding-ball radius", f"{small.boundingBall.r:.2f} r", "-"),
        ("  clear; the same tree again for the seed",
         f"{'yes' if small.clearance().ok else 'NO'}; {'yes' if same else 'NO'}", "yes; yes"),
    ]  # fmt: skip
    return rows


def csc_rows() -> list[tuple[str, str, str]]:
    """CSC Dubins paths: one solve, every path, the most paths of one frame pair."""
    rows: list[tuple[str, str, str]] = []
    rng = np.random.default_rng(1)
    pairs = []
    while len(pairs) < 200:
        p2 = rng.uniform(-8, 8, 3)
        d1, d2 = rng.normal(size=3), rng.normal(size=3)
        if solve_csc(np.zeros(3), d1, p2, d2, 1.0) is not None:
            pairs.append((p2, d1, d2))
    t = _median_seconds(
        lambda: [solve_csc(np.zeros(3), d1, p2, d2, 1.0) for p2, d1, d2 in pairs], 5
    ) / len(pairs)
    rows.append(("CSC solve, one link", f"{t * 1e6:.0f} us", "well under 1 ms"))
    t = _median_seconds(
        lambda: [solve_csc_all(np.zeros(3), d1, p2, d2, 1.0) for p2, d1, d2 in pairs], 5
    ) / len(pairs)
    rows.append(("CSC solve_csc_all (every path), one link", f"{t * 1e6:.0f} us", "<= 1 ms"))
    most = max(len(solve_csc_all(np.zeros(3), d1, p2, d2, 1.0)) for p2, d1, d2 in pairs)
    rows.append(("  most paths for one of those frame pairs", str(most), "-"))
    return rows


def edit_rows() -> list[tuple[str, str, str]]:
    """A 32-joint compact chain: its build, propagated edits and state changes."""
    rows: list[tuple[str, str, str]] = []
    t = _median_seconds(lambda: compact_chain(), 3)
    rows.append(("32-joint compact build", f"{t * 1e3:.1f} ms", "-"))

    chain = compact_chain()
    movable = [i for i, j in enumerate(chain.Joints) if j.stateRange() != (0.0, 0.0)]
    mid = len(chain.Joints) // 2

    def edits():
        for k in range(10):
            chain.translateJointAlongAxisOfMotion(mid, 0.5 if k % 2 == 0 else -0.5)
            chain.rotateJointAboutAxisOfMotion(mid, 0.1 if k % 2 == 0 else -0.1)

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t = _median_seconds(edits, 5) / 20
    rows.append(("propagated edit, 32 joints (mean of 20)", f"{t * 1e3:.2f} ms", "< 5 ms"))

    def states():
        for k in range(20):
            j = movable[k % len(movable)]
            lo, hi = chain.Joints[j].stateRange()
            chain.setJointState(j, lo + (hi - lo) * ((k * 0.37) % 1.0))

    with warnings.catch_warnings():  # random states of a compact chain may touch (timed only)
        warnings.simplefilter("ignore")
        t = _median_seconds(states, 5) / 20
    rows.append(("state change, 32 joints (mean of 20)", f"{t * 1e3:.2f} ms", "< 5 ms"))
    return rows


def pattern_rows(fresh: list[KinematicChain]) -> list[tuple[str, str, str]]:
    """The first creasePattern() of chains never patterned, and DXF, SVG, FOLD saves."""
    rows: list[tuple[str, str, str]] = []
    # each call on a chain never patterned before, with the joint-pattern cache emptied
    first_calls = []
    for built in fresh:
        _catalog_pattern.cache_clear()
        t0 = time.perf_counter()
        built.creasePattern()
        first_calls.append(time.perf_counter() - t0)
    t = statistics.median(first_calls)
    rows.append(
        ("creasePattern(), 32-joint compact chain", f"{t * 1e3:.1f} ms",
         "<= 8.2 ms (10x the reference's 82 ms)")
    )  # fmt: skip
    pattern = fresh[0].creasePattern()
    with tempfile.TemporaryDirectory() as folder:
        target = Path(folder) / "chain.dxf"
        t0 = time.perf_counter()
        pattern.save(dxfName=str(target))
        rows.append(("  first DXF save (includes importing ezdxf)",
                     f"{(time.perf_counter() - t0) * 1e3:.1f} ms", "-"))  # fmt: skip
        t = _median_seconds(lambda: pattern.save(dxfName=str(target)), 5)
        rows.append(("DXF save, same pattern", f"{t * 1e3:.1f} ms", "<= 93 ms (10x the reference)"))
        target = Path(folder) / "chain.svg"
        t = _median_seconds(lambda: pattern.save(dxfName=str(target)), 5)
        rows.append(("SVG save, same pattern", f"{t * 1e3:.1f} ms", "-"))
        target = Path(folder) / "chain.fold"
        t = _median_seconds(lambda: pattern.save(str(target)), 5)
        rows.append(("FOLD save, same pattern", f"{t * 1e3:.1f} ms", "-"))
    return rows


def design_rows(chain: KinematicChain) -> list[tuple[str, str, str]]:
    """Design files (``chain``: a 32-joint chain), the PUMA's DH table and its shortening."""
    from kinegami.design import load_design, save_design
    from kinegami.optimize import shorten_by_axis_translations

    rows: list[tuple[str, str, str]] = []
    t = _median_seconds(lambda: load_design(DESIGNS / "example1.json"), 5)
    rows.append(("load examples/designs/example1.json", f"{t * 1e3:.1f} ms", "-"))
    with tempfile.TemporaryDirectory() as folder:
        target = Path(folder) / "chain.json"
        t = _median_seconds(lambda: save_design(chain, target), 5)
        rows.append(("save_design, 32-joint chain", f"{t * 1e3:.1f} ms", "-"))
        t = _median_seconds(lambda: load_design(target), 5)
        rows.append(("load_design, 32-joint chain (fixed poses)", f"{t * 1e3:.1f} ms", "-"))
    puma_rows = [(np.pi / 2, -np.pi / 2, 0, 0), (0, 0, 431.8, 149.09),
                 (np.pi / 2, np.pi / 2, -20.32, 0), (0, -np.pi / 2, 0, 433.07),
                 (0, np.pi / 2, 0, 0), (0, 0, 0, 56.25)]  # fmt: skip
    t = _median_seconds(lambda: KinematicChain.from_dh(puma_rows, 6, 100), 5)
    rows.append(("PUMA 560 from its DH table (compact)", f"{t * 1e3:.1f} ms", "-"))
    puma = KinematicChain.from_dh(puma_rows, 6, 100)
    before = puma.totalPathLength()
    t0 = time.perf_counter()
    shorten_by_axis_translations(puma)
    rows.append((f"  shortened {before:.0f} -> {puma.totalPathLength():.0f} mm",
                 f"{(time.perf_counter() - t0) * 1e3:.0f} ms", "-"))  # fmt: skip
    return rows


def export_rows(chain: KinematicChain) -> list[tuple[str, str, str]]:
    """The registry's exporters on ``chain`` (a 32-joint chain) and ``kinegami build``."""
    from kinegami import export

    rows: list[tuple[str, str, str]] = []
    with tempfile.TemporaryDirectory() as folder:
        for suffix in (".fold", ".pdf", ".stl", ".obj", ".urdf"):
            target = Path(folder) / f"chain{suffix}"
            export(chain, target)  # first call imports the exporter
            t = _median_seconds(lambda target=target: export(chain, target), 3)
            rows.append((f"export {suffix}, 32-joint chain", f"{t * 1e3:.1f} ms", "-"))
        from kinegami.cli import main as cli_main

        with contextlib.redirect_stdout(io.StringIO()):
            t0 = time.perf_counter()
            cli_main(["build", str(DESIGNS / "example1.json"), "-o", folder])
        rows.append(("kinegami build example1.json (DXF, SVG, 2 PNGs)",
                     f"{(time.perf_counter() - t0) * 1e3:.0f} ms", "-"))  # fmt: skip
    return rows


def safe_chain_rows(seeds: int) -> list[tuple[str, str, str]]:
    """48-joint safe chains: their build time, failed appends, size per joint."""
    balls, paths, fails, times = [], [], 0, []
    for seed in range(seeds):
        t0 = time.perf_counter()
        built, failures = safe_chain(seed)
        times.append(time.perf_counter() - t0)
        fails += failures
        balls.append(built.boundingBall.r / 48)
        paths.append(built.totalPathLength() / 48)
    return [
        (f"48-joint safe chain ({seeds} seeds), time",
         f"{statistics.median(times) * 1e3:.0f} ms", "-"),
        ("  failed appends", str(fails), "0"),
        ("  ball radius per joint (max)", f"{max(balls):.2f} r", "<= 10 r"),
        ("  path length per joint (max)", f"{max(paths):.2f} r", "<= 60 r"),
    ]  # fmt: skip


def random_dh_table(n: int, seed: int = 1, r: float = 1.0) -> list[tuple[float, ...]]:
    """n random DH rows (theta 0, alpha uniform in (-pi, pi], a and d uniform in [0, 4r])."""
    rng = np.random.default_rng(seed)
    return [(0.0, float(rng.uniform(-np.pi, np.pi)), float(rng.uniform(0, 4 * r)),
             float(rng.uniform(0, 4 * r))) for _ in range(n)]  # fmt: skip


def scale_rows() -> list[tuple[str, str, str]]:
    """How builds grow with the design: safe random chains of 100, 200 and 400 joints (three
    seeds), the
    CPU time of one append early and late in a 400-joint chain, and a 1,000-row DH table
    (from_dh, and kinegami build of a design file holding it)."""
    # three seeds; wall time per size (median) and, per seed, the CPU-time ratio 400 / 200
    # (one run of one seed swings between 1.9x and 2.9x on a shared machine)
    wall: dict[int, list[float]] = {100: [], 200: [], 400: []}
    cpu: dict[int, list[float]] = {100: [], 200: [], 400: []}
    for seed in range(3):
        for n in (100, 200, 400):
            t0, c0 = time.perf_counter(), time.process_time()
            safe_chain(seed, n)
            wall[n].append(time.perf_counter() - t0)
            cpu[n].append(time.process_time() - c0)
    times = {n: statistics.median(values) for n, values in wall.items()}
    ratios = sorted(c400 / c200 for c400, c200 in zip(cpu[400], cpu[200], strict=True))
    # CPU time per append over joints 1-50 and 351-400 of one safe chain
    rng = np.random.default_rng(0)
    chain = KinematicChain(StartTip(4, 1.0, np.eye(4), 1.0))
    marks = [time.process_time()]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        for i in range(400):
            chain.append(random_joint(i, random_pose(rng, 1.0)))
            if i + 1 in (50, 350, 400):
                marks.append(time.process_time())
    early, late = (marks[1] - marks[0]) / 50, (marks[3] - marks[2]) / 50
    t0 = time.perf_counter()
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        KinematicChain.from_dh(random_dh_table(1000), 4, 1.0)
    dh = time.perf_counter() - t0
    build = _dh_build_seconds(random_dh_table(1000))
    return [
        ("safe random chain, 100 / 200 / 400 joints (median of 3 seeds)",
         f"{times[100]:.1f} / {times[200]:.1f} / {times[400]:.1f} s", "400 joints <= 10 s"),
        ("  400 joints / 200 joints (CPU, 3 seeds)",
         f"{statistics.median(ratios):.2f}x ({ratios[0]:.2f}-{ratios[-1]:.2f})",
         "<= 2.5x (near-linear)"),
        ("  CPU per append: joints 1-50 / 351-400", f"{early * 1e3:.1f} / {late * 1e3:.1f} ms",
         "late ~ early (no growth with length)"),
        ("KinematicChain.from_dh, 1,000 random rows", f"{dh:.1f} s", "<= 30 s"),
        ("kinegami build of that table's design file", f"{build:.1f} s", "<= 30 s"),
    ]  # fmt: skip


def _dh_build_seconds(rows: list[tuple[float, ...]]) -> float:
    """Wall seconds of ``kinegami build`` (a fresh process, its default outputs: DXF, SVG,
    pictures) of a design file holding the DH table ``rows`` (numSides 4, r 1)."""
    import json
    import subprocess

    with tempfile.TemporaryDirectory() as folder:
        design = Path(folder) / "dh.json"
        design.write_text(json.dumps({"format": "kinegami-design", "version": 1, "numSides": 4,
                                      "r": 1, "dh": {"rows": [list(row) for row in rows]}}))
        t0 = time.perf_counter()
        subprocess.run([sys.executable, "-m", "kinegami", "build", str(design), "-o",
                        str(Path(folder) / "out")], check=True, capture_output=True)
        return time.perf_counter() - t0


def _cpu_median(fn, repeat: int) -> float:
    """Median CPU seconds of this process over ``repeat`` calls (time.process_time: the
    machine's other jobs do not count, its 2 shared cores still slow memory and caches)."""
    times = []
    for _ in range(repeat):
        t0 = time.process_time()
        fn()
        times.append(time.process_time() - t0)
    return statistics.median(times)


def reach_rows() -> list[tuple[str, str, str]]:
    """Issue 31: forward kinematics batched on a 6-joint arm (the PUMA), configurations per
    second (median of 5 batches of 100,000: wall time, the throughput a user gets, and CPU
    time, which counts both cores where the matrix products run on two BLAS threads), and
    jacob0 per configuration (CPU)."""
    from kinegami.design import load_design
    from kinegami.reach import kinematics

    puma = load_design(DESIGNS / "puma.json")
    arm = kinematics(puma)
    rng = np.random.default_rng(0)
    low, high = arm.ranges[:, 0], arm.ranges[:, 1]
    Q = low + (high - low) * rng.random((100_000, low.size))
    arm.fkine(Q[:100])
    walls = []
    for _ in range(5):
        t0 = time.perf_counter()
        arm.fkine(Q)
        walls.append(time.perf_counter() - t0)
    t = _cpu_median(lambda: arm.fkine(Q), 5)
    j = _cpu_median(lambda: arm.jacob0(Q[:20_000]), 5) / 20_000
    ik = _ik_rows(puma, arm)
    space = []
    from kinegami.reach import workspace

    for samples, goal in ((20_000, "<= 10 s"), (1_000_000, "<= 120 s")):
        t0 = time.perf_counter()
        cloud = workspace(puma, samples, seed=0)
        took = time.perf_counter() - t0
        space.append((f"workspace, PUMA, {samples:,} samples (wall)",
                      f"{took:.1f} s; volume {cloud.volume / 1e9:.4g} dm^3, half-sample "
                      f"{cloud.convergence:.1%}, lost {cloud.lost_share:.1%}", goal))  # fmt: skip
    rtb = __import__("reach_rtb")
    side_by_side = rtb.rows() + rtb.batch_rows()  # RTB's rows, or ones saying it is absent
    return ik + side_by_side + space + [
        ("forward kinematics, PUMA, batches of 100,000 (wall / CPU)",
         f"{Q.shape[0] / statistics.median(walls):,.0f} / {Q.shape[0] / t:,.0f} /s",
         ">= 1,000,000 /s"),
        ("jacob0, PUMA, batches of 20,000, per configuration", f"{j * 1e6:.2f} us", "-"),
    ]  # fmt: skip


def _ik_rows(puma, arm) -> list[tuple[str, str, str]]:
    """Inverse kinematics on the PUMA: 40 targets that are tip poses of random clear
    configurations (wall time per solve, clearance included, median) and the share reached
    (checked through setJointStates and the design's clearance); a target beyond reach."""
    from kinegami.design import load_design
    from kinegami.reach import solve

    rng = np.random.default_rng(0)
    low, high = arm.ranges[:, 0], arm.ranges[:, 1]
    targets = []
    while len(targets) < 40:
        q = low + (high - low) * rng.random(low.size)
        if puma.clearance(q.tolist()).ok:
            targets.append(arm.fkine(q))
    times, answers, reached = [], [], 0
    for T in targets:  # timed alone: the checks load other designs (and their engines)
        t0 = time.perf_counter()
        answers.append(solve(puma, T))
        times.append(time.perf_counter() - t0)
    for answer, T in zip(answers, targets, strict=True):
        if answer.ok:
            check = load_design(DESIGNS / "puma.json")
            check.requireClearance = True
            tip = check.Joints[-1].distal_dubins_frame() if check.setJointStates(
                list(answer.states)) else None  # fmt: skip
            reached += tip is not None and np.abs(tip - T).max() <= 1e-9 * puma.r
    far_times = []
    for x in (1e5, 2e5, 3e5, 4e5, 5e5):  # the median of five (a single call met a collection)
        t0 = time.perf_counter()
        solve(puma, [x, 0.0, 0.0])
        far_times.append(time.perf_counter() - t0)
    far = statistics.median(far_times)
    return [
        ("solve, PUMA, 40 clear pose targets: reached / median per target (wall)",
         f"{reached}/40, {statistics.median(times) * 1e3:.1f} ms",
         "99.9% reached; <= 0.75 ms (3x RTB ik_LM 0.25 ms on the issue's machine)"),
        ("solve, PUMA, a target beyond reach (wall, median of 5)", f"{far * 1e3:.1f} ms",
         "<= 5 ms"),
    ]  # fmt: skip


def engine_rows() -> list[tuple[str, str, str]]:
    """Issue 29 section 4: the clearance engine fast enough to sample workspaces. CPU time
    (process_time, median of repeats) of sweep per configuration on the PUMA, the 9-joint
    spherical series and the trees, one configuration (design.clearance(q)), a tree's
    setJointStates, and the engine of a 1,000-row DH table."""
    from kinegami.clearance import ClearanceEngine, sweep
    from kinegami.design import load_design

    rows: list[tuple[str, str, str]] = []
    for name, goal in (("puma", "<= 50 us (>= 20,000/s)"), ("spherical_series", "<= 100 us")):
        design = load_design(DESIGNS / f"{name}.json")
        sweep(design, samples=200)
        t = _cpu_median(lambda d=design: sweep(d, samples=10000), 3) / 10000
        rows.append((f"sweep, 10,000 samples, {name}, per configuration", f"{t * 1e6:.0f} us",
                     goal))  # fmt: skip
    puma = load_design(DESIGNS / "puma.json")
    q = [joint.state for joint in puma.Joints]
    puma.clearance(q)
    t = _cpu_median(lambda: [puma.clearance(q) for _ in range(100)], 5) / 100
    rows.append(("design.clearance(q), PUMA, one configuration", f"{t * 1e6:.0f} us",
                 "<= 100 us"))  # fmt: skip
    for name, goal in (("hand", "-"), ("quadruped", "-"),
                       ("algorithmic_hand", "<= 1 ms")):  # fmt: skip
        tree = load_design(DESIGNS / f"{name}.json")
        sweep(tree, samples=10)
        t = _cpu_median(lambda d=tree: sweep(d, samples=300), 1) / 300
        rows.append((f"sweep, 300 samples, {name}, per configuration", f"{t * 1e3:.2f} ms", goal))
    hand = load_design(DESIGNS / "algorithmic_hand.json")
    ranges = np.array([joint.stateRange() for joint in hand.Joints])
    rng = np.random.default_rng(0)
    states = [list(ranges[:, 0] + (ranges[:, 1] - ranges[:, 0]) * rng.random(len(ranges)))
              for _ in range(5)]  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        t = _cpu_median(lambda: [hand.setJointStates(s) for s in states], 3) / len(states)
    rows.append(("setJointStates, algorithmic hand", f"{t * 1e3:.1f} ms", "<= 5 ms"))
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain = KinematicChain.from_dh(random_dh_table(1000), 4, 1.0)
    t0 = time.process_time()
    engine = ClearanceEngine(chain)
    built = time.process_time() - t0
    t0 = time.process_time()
    engine.report([joint.state for joint in chain.Joints])
    reported = time.process_time() - t0
    rows.append(("ClearanceEngine, 1,000-row DH table: build / report",
                 f"{built:.2f} / {reported:.1f} s", "near-linear, bounded memory"))  # fmt: skip
    return rows


Rows = list[tuple[str, str, str]]


def run_steps(steps: list[tuple[str, Callable[[], Rows]]], stream: TextIO | None = None) -> Rows:
    """Run every ``(name, rows function)`` in order and return all their rows; report on
    ``stream`` (default stderr) each step as it starts (``[3/12] name ...``) and the seconds it
    took when it ends, so that a long run is not silent."""
    stream = sys.stderr if stream is None else stream
    rows: Rows = []
    for k, (name, step) in enumerate(steps, start=1):
        print(f"[{k}/{len(steps)}] {name} ...", end="", file=stream, flush=True)
        t0 = time.perf_counter()
        try:
            rows += step()
        except BaseException:
            print(" failed", file=stream, flush=True)
            raise
        print(f" {time.perf_counter() - t0:.1f} s", file=stream, flush=True)
    return rows


def steps(seeds: int, compact_seeds: int,
          reach_targets: int = 5000) -> list[tuple[str, Callable[[], Rows]]]:
    """The measurements of the table, in its order: (what is measured, its rows function)."""
    shared: dict[str, list[KinematicChain]] = {}

    def fresh() -> list[KinematicChain]:  # 32-joint compact chains, built once
        if "fresh" not in shared:
            shared["fresh"] = [compact_chain(seed=seed) for seed in range(5)]
        return shared["fresh"]

    out: list[tuple[str, Callable[[], Rows]]] = [
        ("CSC paths", csc_rows),
        ("32-joint compact chain: build, edits, states", edit_rows),
        ("crease patterns and DXF, SVG, FOLD saves", lambda: pattern_rows(fresh())),
        ("design files, DH table", lambda: design_rows(fresh()[0])),
        ("exporters and kinegami build", lambda: export_rows(fresh()[0])),
        (f"48-joint safe chains ({seeds} seeds)", lambda: safe_chain_rows(seeds)),
        ("scale: 100-400-joint safe chains, a 1,000-row DH table", scale_rows),
        ("clearance engine and safe chains' clearance", lambda: clearance_rows(0)),
        ("clearance engine for workspaces: sweeps, one configuration, trees", engine_rows),
        ("reach: kinematics, inverse kinematics, workspaces", reach_rows),
        ("reach in the editor: the target's drag steps, PUMA",
         lambda: __import__("editor_reach").rows()),
    ]
    if compact_seeds > 0:
        out += [
            (f"compact, 16-joint safe chains ({compact_seeds} seeds) and the gallery",
             lambda: compaction_rows(compact_seeds)),
            ("algorithmic hand: construction and compaction", tree_rows),
        ]  # fmt: skip
    if reach_targets > 0:
        out.append((f"reach: success on {reach_targets:,} clear targets per gallery chain and "
                    f"{max(1, reach_targets // 5):,} per tree",
                    lambda: __import__("reach_success").rows(reach_targets,
                                                             max(1, reach_targets // 5))))
    out.append(("start-up, fresh processes", lambda: __import__("startup").rows()))
    return out


def main(argv: list[str] | None = None) -> None:
    parser = argparse.ArgumentParser(description=__doc__)
    parser.add_argument("--seeds", type=int, default=10, help="random 48-joint safe chains")
    parser.add_argument("--compact-seeds", type=int, default=20,
                        help="random 16-joint chains compacted (0 skips compaction)")  # fmt: skip
    parser.add_argument("--only", action="append", default=[], metavar="WORD",
                        help="run only the measurements whose name (as the progress lines "
                             "show it) contains WORD (repeatable)")  # fmt: skip
    parser.add_argument("--reach-targets", type=int, default=5000,
                        help="clear targets per gallery chain for the success rates (a fifth "
                             "of it per hand; 0 skips them: several minutes)")  # fmt: skip
    args = parser.parse_args(argv)
    chosen = steps(args.seeds, args.compact_seeds, args.reach_targets)
    if args.only:
        chosen = [s for s in chosen if any(w.lower() in s[0].lower() for w in args.only)]
        if not chosen:
            parser.error(f"--only {' '.join(args.only)}: no measurement has that in its name")
    rows = run_steps(chosen)

    width = max(len(r[0]) for r in rows)
    print(f"{'measurement':<{width}}  {'result':>12}  goal")
    print("-" * (width + 28))
    for name, value, goal in rows:
        print(f"{name:<{width}}  {value:>12}  {goal}")


if __name__ == "__main__":
    main()
