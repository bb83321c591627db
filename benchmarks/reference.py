"""The same workload on kinegami and on the published KinegamiPython, side by side.

Usage::

    python benchmarks/reference.py --reference PATH/TO/KinegamiPython

``PATH`` is a checkout of SungRoboticsGroup/KinegamiPython (the published code, measured at
commit d3dc867). The reference runs in a child process with that folder first on its path; it
needs only numpy, scipy, spatialmath-python, matplotlib and ezdxf, which kinegami installs too.
Both sides get the same joints (the same seeded random poses) and do the same work:

* the 32-joint compact build (``append(..., safe=False)``, joints whose link fails skipped);
* 20 propagated edits of the middle joint (slides and rolls), 20 state changes;
* the chain's crease pattern and its first DXF save.

Each figure is the median of ``--repeat`` runs; the table prints both wall times, their ratio
and the ratio of CPU times (process_time, which other jobs on a shared machine sway least)
beside the goal. CI does not run this (it needs the reference's checkout); the README says how.
"""

from __future__ import annotations

import argparse
import json
import os
import statistics
import subprocess
import sys
import tempfile
import textwrap
from pathlib import Path

#: The workload, run in one process against whichever library the path provides. ``API`` is
#: "kinegami" (our package) or "reference" (KinegamiPython's modules on sys.path).
WORKLOAD = textwrap.dedent(
    r'''
    import json, statistics, sys, tempfile, time, warnings
    from pathlib import Path
    import numpy as np
    from scipy.spatial.transform import Rotation
    from spatialmath import SE3

    API, REPEAT, N = sys.argv[1], int(sys.argv[2]), int(sys.argv[3])
    warnings.simplefilter("ignore")
    if API == "kinegami":
        from kinegami import KinematicChain, PrismaticJoint, RevoluteJoint, StartTip
    else:
        import matplotlib
        matplotlib.use("Agg")
        from KinematicChain import KinematicChain
        from Joint import PrismaticJoint, RevoluteJoint, StartTip

    def random_pose(rng, r, reach=4.0):
        T = np.eye(4)
        T[:3, :3] = Rotation.random(random_state=int(rng.integers(1 << 31))).as_matrix()
        T[:3, 3] = rng.uniform(-reach * r, reach * r, 3)
        return SE3(T, check=False)

    def random_joint(i, T, r=1.0):
        if i % 2 == 0:
            return RevoluteJoint(4, r, np.pi, T)
        return PrismaticJoint(4, r, 3 * r, 3, np.pi / 4, T)

    def build():
        rng = np.random.default_rng(0)
        chain = KinematicChain(StartTip(4, 1.0, SE3(), 1.0))
        attempts = 0
        while len(chain.Joints) < N and attempts < 20 * N:
            attempts += 1
            joint = random_joint(len(chain.Joints), random_pose(rng, 1.0))
            try:
                chain.append(joint, safe=False)
            except Exception:
                pass  # the reference raises where kinegami returns None: skipped alike
        return chain

    CPU = {}

    def median(fn, key):
        times, cpu = [], []
        for _ in range(REPEAT):
            t0, c0 = time.perf_counter(), time.process_time()
            fn()
            times.append(time.perf_counter() - t0)
            cpu.append(time.process_time() - c0)
        CPU[key] = statistics.median(cpu)
        return statistics.median(times)

    out = {"build": median(build, "build")}
    chain = build()
    out["joints"] = len(chain.Joints)
    mid = len(chain.Joints) // 2
    movable = [i for i, j in enumerate(chain.Joints) if type(j).__name__ in
               ("RevoluteJoint", "PrismaticJoint")]

    def edits():
        for k in range(10):
            try:
                chain.translateJointAlongAxisOfMotion(mid, 0.5 if k % 2 == 0 else -0.5)
                chain.rotateJointAboutAxisOfMotion(mid, 0.1 if k % 2 == 0 else -0.1)
            except Exception:
                pass

    def states():
        for k in range(20):
            j = movable[k % len(movable)]
            lo, hi = chain.Joints[j].stateRange()
            try:
                chain.setJointState(j, lo + (hi - lo) * ((k * 0.37) % 1.0))
            except Exception:
                pass

    out["edit"] = median(edits, "edit") / 20
    CPU["edit"] /= 20
    out["state"] = median(states, "state") / 20
    CPU["state"] /= 20
    out["pattern"] = median(lambda: chain.creasePattern(), "pattern")
    pattern = chain.creasePattern()
    with tempfile.TemporaryDirectory() as folder:
        target = str(Path(folder) / "chain.dxf")
        t0, c0 = time.perf_counter(), time.process_time()
        pattern.save(dxfName=target)
        out["first_dxf"] = time.perf_counter() - t0
        CPU["first_dxf"] = time.process_time() - c0
    out.update({key + "_cpu": value for key, value in CPU.items()})
    print(json.dumps(out))
    '''
)

#: (key, what, goal ratio reference/kinegami, what the goal says)
FIGURES = [
    ("build", "32-joint compact build", 20.0, ">= 20x"),
    ("edit", "propagated edit (mean of 20)", 20.0, "keep ~23x"),
    ("state", "state change (mean of 20)", 20.0, "keep ~22x"),
    ("pattern", "creasePattern()", 10.0, ">= 10x"),
    ("first_dxf", "first DXF save (with its imports)", 10.0, ">= 10x"),
]


def run(api: str, path: Path | None, repeat: int, joints: int) -> dict:
    """The workload's figures (seconds) in a fresh process of ``api``."""
    env = dict(os.environ, MPLBACKEND="Agg")
    with tempfile.TemporaryDirectory() as folder:
        script = Path(folder) / "workload.py"
        script.write_text(WORKLOAD)
        cwd = path if path is not None else Path(__file__).resolve().parents[1]
        if path is not None:
            env["PYTHONPATH"] = str(path)
        done = subprocess.run(
            [sys.executable, str(script), api, str(repeat), str(joints)],
            cwd=cwd, env=env, capture_output=True, text=True, check=False,
        )  # fmt: skip
    if done.returncode != 0:
        raise SystemExit(f"{api} workload failed:\n{done.stderr[-2000:]}")
    return json.loads(done.stdout.strip().splitlines()[-1])


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--reference", type=Path, required=True,
                        help="a checkout of SungRoboticsGroup/KinegamiPython (d3dc867)")
    parser.add_argument("--repeat", type=int, default=3, help="runs per figure (median)")
    parser.add_argument("--joints", type=int, default=32, help="joints of the compact chain")
    parser.add_argument("--rounds", type=int, default=3,
                        help="fresh processes per side, alternating (median of the rounds)")
    args = parser.parse_args(argv)
    if not (args.reference / "KinematicChain.py").is_file():
        parser.error(f"{args.reference} holds no KinematicChain.py (not a KinegamiPython checkout)")
    print(f"running the workload on kinegami and on {args.reference} ...", file=sys.stderr)
    # the two sides alternate, round by round and in turn first, so that a change in the
    # machine's load during the run weighs on both alike
    rounds: dict[str, list[dict]] = {"kinegami": [], "reference": []}
    for k in range(max(1, args.rounds)):
        order = ("kinegami", "reference") if k % 2 == 0 else ("reference", "kinegami")
        for api in order:
            path = None if api == "kinegami" else args.reference.resolve()
            rounds[api].append(run(api, path, args.repeat, args.joints))
    ours, theirs = ({key: statistics.median(r[key] for r in rounds[api]) for key in rounds[api][0]}
                    for api in ("kinegami", "reference"))  # fmt: skip
    # wall time, and CPU time (process_time: what another job on the shared machine slows
    # least; both use one core but for BLAS threads, which process_time counts too)
    print(f"{'figure':40} {'kinegami':>12} {'reference':>12} {'ratio':>8} {'CPU ratio':>10}  goal")
    for key, what, _, goal in FIGURES:
        ratio = theirs[key] / ours[key] if ours[key] > 0 else float("inf")
        cpu = key + "_cpu"
        cpu_ratio = theirs[cpu] / ours[cpu] if ours[cpu] > 0 else float("inf")
        print(f"{what:40} {ours[key] * 1e3:>9.2f} ms {theirs[key] * 1e3:>9.2f} ms "
              f"{ratio:>7.1f}x {cpu_ratio:>9.1f}x  {goal}")  # fmt: skip
    print(f"joints built: kinegami {ours['joints']:.0f}, reference {theirs['joints']:.0f}")
    return 0


if __name__ == "__main__":
    raise SystemExit(main())
