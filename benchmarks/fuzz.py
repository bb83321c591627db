"""Fuzzing kinegami for bounded time and memory (issue 29, docs/limits.md).

Two kinds of case, each made from its seed alone:

* ``design``: a random design file (chains, trees, DH tables; sizes, poses up to and past 1e6 r,
  every parameter near and beyond its limits; sometimes a value replaced by a hostile one) is
  loaded, and the chain it gives is asked for its crease pattern, its clearance, a short motion
  sweep, a compaction or an export to a random format.
* ``operations``: a small random chain or tree is built through the API, then edited by a random
  sequence of operations (append / addJoint with random joints and poses, delete, translate,
  rotate, transformJoint, transformAll, states, requireClearance, margin, patterns, clearance,
  sweeps, exports). Every operation that fails (False, None or an exception) must leave the
  chain bit-identical.

Every failure must be a :class:`~kinegami.errors.KinegamiError` whose message is one line; any
other exception, a MemoryError included, is a violation. Cases run in worker processes with an
address-space cap (``resource.setrlimit``, default 2 GiB); a case still running after
``--timeout`` seconds (default 20) is a hang: its worker is killed and the run goes on with the
next seed.

Run::

    python benchmarks/fuzz.py                     # 10,000 designs and 10,000 sequences
    python benchmarks/fuzz.py --designs 300 --operations 0 --seed 5 --workers 2

It prints one line per violation, hang or crash as found and a summary at the end; the exit
status is 1 if anything was found. ``tests/design/test_fuzz_bounded.py`` runs a few hundred
cases of each kind in CI through :func:`run`.
"""

from __future__ import annotations

import argparse
import json
import math
import os
import random
import selectors
import subprocess
import sys
import tempfile
import time
import traceback
import warnings
from pathlib import Path

#: Per-case time limit (seconds) and address-space cap (bytes) of the long run.
TIMEOUT = 20.0
MEMORY = 2 * 2**30

JOINT_KINDS = ("RevoluteJoint", "ExtendedRevoluteJoint", "PrismaticJoint", "Waypoint")
#: Translation scales, in units of r: everyday, long, at the limit (1e6 r) and just past it.
SCALES = (0.5, 3.0, 6.0, 10.0, 40.0, 1e3, 1e5, 999_999.0, 999_999.0)
SUFFIXES = (".dxf", ".svg", ".fold", ".pdf", ".stl", ".obj", ".urdf")
HOSTILE = (None, True, -1, 0, 1e308, -1e308, 1e-320, 2**70, "x", [], {}, [[1]], 1e6, 1e7, 33,
           201, 65, 0.5, -0.0, "1e999")  # fmt: skip


class Violation(AssertionError):  # noqa: N818 - a finding, not an error of the code
    """A case broke a rule: not a one-line KinegamiError, or a failed edit changed the chain."""


# --- designs ---------------------------------------------------------------------------------
def _edge(rng: random.Random, values: tuple, beyond):
    """One of ``values`` (at or within a limit), or ``beyond`` it one time in twenty."""
    return beyond if rng.random() < 0.05 else rng.choice(values)


def _translation(rng: random.Random, r: float) -> list[float]:
    scale = rng.choice(SCALES) if rng.random() < 0.25 else rng.choice(SCALES[:4])
    scale = _edge(rng, (scale,), 1_000_001.0) if rng.random() < 0.2 else scale
    direction = [rng.gauss(0, 1) for _ in range(3)]
    norm = math.sqrt(sum(x * x for x in direction)) or 1.0
    if rng.random() < 0.3:  # along one axis: the coordinate itself reaches the scale
        axis = rng.randrange(3)
        return [scale * r if k == axis else 0.0 for k in range(3)]
    return [scale * r * x / norm for x in direction]


def _pose(rng: random.Random, r: float, degrees: bool) -> list:
    steps: list = []
    if rng.random() < 0.8:
        steps.append({"Trans": _translation(rng, r)})
    for _ in range(rng.randrange(3)):
        angle = rng.uniform(-math.pi, math.pi)
        steps.append({rng.choice(("Rx", "Ry", "Rz")): math.degrees(angle) if degrees else angle})
    return steps


def _joint(rng: random.Random, kind: str, r: float, degrees: bool) -> dict:
    def angle(radians: float) -> float:
        return math.degrees(radians) if degrees else radians

    spec: dict = {"type": kind, "pose": _pose(rng, r, degrees)}
    if kind in ("RevoluteJoint", "ExtendedRevoluteJoint"):
        spec["totalBendingAngle"] = angle(rng.choice((math.pi, math.pi / 2, rng.uniform(0.1, 6.2))))
        if rng.random() < 0.3:
            spec["numSinkLayers"] = _edge(rng, (1, 2, 3, 32), 33)
        if kind == "ExtendedRevoluteJoint":
            spec["tubeLength"] = rng.choice((0.2, 1.0, 5.0, 1e3, 1e6 * 0.999)) * r
    elif kind == "PrismaticJoint":
        spec["neutralLength"] = rng.choice((1.0, 3.0, 10.0, 1e5)) * r
        spec["numLayers"] = _edge(rng, (1, 2, 3, 5, 200), 201)
        spec["coneAngle"] = rng.choice((45.0, 30.0, 70.0)) if degrees else rng.choice(
            (math.pi / 4, math.pi / 6, 1.2))  # fmt: skip
    elif kind in ("StartTip", "EndTip"):
        spec["length"] = _edge(rng, (0.5, 1.5, 3.0, 1e6 * 0.999), 1.1e6) * r
    if kind == "StartTip":
        return spec
    for flag in ("relative", "fixedPosition", "fixedOrientation"):
        if rng.random() < 0.15:
            spec[flag] = rng.random() < 0.5
    if spec.get("fixedPosition") or spec.get("fixedOrientation") or rng.random() < 0.1:
        spec["safe"] = False
    return spec


def random_design(rng: random.Random, small: bool = False) -> dict:
    """A random design document: mostly valid, often at or past a limit (``small``: at most
    five joints, as the quick run in the tests uses)."""
    r = rng.choice((1.0, 1.0, 10.0, 0.5, 1e-3, 1e3, 10 ** rng.uniform(-6, 6)))
    degrees = rng.random() < 0.5
    document: dict = {"format": "kinegami-design", "version": 2, "units": "mm",
                      "numSides": rng.choice((4, 4, 4, 6, 8, 64)), "r": r}  # fmt: skip
    if degrees:
        document["angleUnits"] = "deg"
    if rng.random() < 0.15:
        document["maxAnglePerElbow"] = _edge(rng, (1.0, 5.0, 90.0, 180.0), 0.5)
        if not degrees:
            document["maxAnglePerElbow"] = math.radians(document["maxAnglePerElbow"])
    if rng.random() < 0.1:
        document["version"] = 3
        document["margin"] = rng.choice((0.1, 1.0, 5.0)) * r
    if rng.random() < 0.1:
        document["requireClearance"] = True
    if rng.random() < 0.1:  # a DH table
        rows = [[rng.uniform(-3, 3), rng.uniform(-3, 3), rng.choice((0.0, 2.0, 5.0, 1e5)) * r,
                 rng.choice((0.0, 3.0, 1e3)) * r] for _ in range(rng.choice((1, 2, 4, 12)))]
        if degrees:
            rows = [[math.degrees(a), math.degrees(b), c, d] for a, b, c, d in rows]
        document["dh"] = {"rows": rows}
        return document
    tree = rng.random() < 0.35
    count = rng.choice((2, 3, 4, 5, 6, 8)) if rng.random() < 0.9 else rng.choice((15, 30))
    if small:
        count = min(count, 5)
    joints: list[dict] = []
    if tree:
        joints.append({"type": "Waypoint", "name": "j0", "pose": [], "pathIndex": 2})
    else:
        joints.append(_joint(rng, "StartTip", r, degrees))
        joints[0]["name"] = "j0"
    for k in range(1, count):
        last = k == count - 1
        kind = "EndTip" if (last and rng.random() < 0.6) else rng.choice(JOINT_KINDS)
        spec = _joint(rng, kind, r, degrees)
        spec["name"] = f"j{k}"
        if tree and k > 1 and rng.random() < 0.4:
            parents = [j["name"] for j in joints if j["type"] != "EndTip"]
            spec["parent"] = rng.choice(parents)
        joints.append(spec)
    document["joints"] = joints
    if rng.random() < 0.3:
        edits = []
        for _ in range(rng.randrange(1, 4)):
            op = rng.choice(("translateJointAlongAxisOfMotion", "rotateJointAboutAxisOfMotion",
                             "transformJoint", "delete", "setJointState", "transformAll"))
            edit: dict = {"op": op}
            if op != "transformAll":
                edit["joint"] = rng.randrange(-2, 2 * count)
            if op == "translateJointAlongAxisOfMotion":
                edit["distance"] = rng.choice((-2.0, 3.0, 1e5, 999_999.0)) * r
            elif op == "rotateJointAboutAxisOfMotion":
                edit["angle"] = rng.uniform(-3, 3)
            elif op in ("transformJoint", "transformAll"):
                edit["transform"] = _pose(rng, r, degrees)
            elif op == "setJointState":
                edit["state"] = rng.uniform(-2, 2)
            edits.append(edit)
        document["edits"] = edits
    return document


def _mutate(rng: random.Random, document: dict) -> str:
    """A hostile value somewhere in the document (a fifth of the cases)."""
    places: list = []
    stack: list = [document]
    while stack:
        node = stack.pop()
        items = node.items() if isinstance(node, dict) else enumerate(node)
        for key, value in items:
            places.append((node, key))
            if isinstance(value, dict | list):
                stack.append(value)
    node, key = rng.choice(places)
    node[key] = rng.choice(HOSTILE)
    return json.dumps(document)


def design_text(seed: int, small: bool = False) -> str:
    """The design file of case ``seed``."""
    rng = random.Random(seed)
    document = random_design(rng, small)
    if rng.random() < 0.2:
        return _mutate(rng, document)
    return json.dumps(document)


# --- checks ----------------------------------------------------------------------------------
def _refusal(error: BaseException) -> str:
    """The message of an allowed failure, or raise Violation."""
    from kinegami.errors import KinegamiError

    text = str(error)
    if not isinstance(error, KinegamiError):
        where = "".join(traceback.format_exception(error, limit=-3)).strip().splitlines()
        raise Violation(f"{type(error).__name__}: {text[:300]} | {' / '.join(where[-4:])}")
    if "\n" in text or not text.strip():
        raise Violation(f"{type(error).__name__} of {len(text.splitlines())} lines: {text[:300]!r}")
    return text


def snapshot(chain) -> bytes:
    """Everything a chain or tree stores, as bytes (two equal snapshots: bit-identical)."""
    import numpy as np

    parts: list = [len(chain.Joints), tuple(chain.Parents), chain.r, chain.numSides,
                   chain.maxAnglePerElbow, chain.margin, chain.requireClearance]  # fmt: skip
    for joint in chain.Joints:
        parts += [type(joint).__name__, np.asarray(joint.pose_matrix).tobytes(), joint.state,
                  joint.neutralLength, joint.stateRange()]  # fmt: skip
    for link in chain.Links:
        parts += [np.asarray(link.start_frame).tobytes(), np.asarray(link.end_frame).tobytes(),
                  link.length]  # fmt: skip
    ball = chain.boundingBall
    parts += [np.asarray(ball.c).tobytes(), ball.r]
    return repr(parts).encode()


def _use(rng: random.Random, chain, folder: Path, what: str) -> str:
    """Ask ``chain`` for one random thing (pattern, clearance, sweep, compact, an export)."""
    from kinegami.tree import KinematicTree

    if what == "pattern":
        if isinstance(chain, KinematicTree):  # its sheets and junctions (the tree's patterns)
            from kinegami.fabrication.sheets import fabricate

            fabricate(chain, junction=rng.choice(("connector", "takeoff", "auto")))
        else:
            chain.creasePattern()
    elif what == "clearance":
        chain.clearance()
    elif what == "sweep":
        from kinegami.clearance import sweep

        sweep(chain, samples=rng.choice((1, 3, 10)), seed=rng.randrange(100), progress=False,
              resolution=4)  # fmt: skip
    elif what == "compact":
        from concurrent.futures import ThreadPoolExecutor

        from kinegami.optimize import compact

        with ThreadPoolExecutor(1) as pool:
            compact(chain, executor=pool, starts=1, time_limit=2.0, progress=False)
    else:
        from kinegami.export import export

        export(chain, folder / f"fuzz{what}")
    return what


# --- the two kinds of case -------------------------------------------------------------------
def design_case(seed: int, folder: Path, small: bool = False) -> str:
    """Load the design of ``seed`` and use its chain; the outcome in a few words."""
    from kinegami.design import loads_design

    rng = random.Random(seed ^ 0x5EED)
    text = design_text(seed, small)
    try:
        chain = loads_design(text, "fuzz.json")
    except Exception as error:  # noqa: BLE001 - judged by _refusal
        _refusal(error)
        return "refused"
    uses = ["pattern", "clearance", "sweep", *SUFFIXES] + (["compact"] if rng.random() < 0.05
                                                          and not small else [])  # fmt: skip
    done = []
    for what in rng.sample(uses, 2):
        before = snapshot(chain)
        try:
            done.append(_use(rng, chain, folder, what))
        except Exception as error:  # noqa: BLE001
            _refusal(error)
            done.append(f"{what} refused")
        if snapshot(chain) != before:
            raise Violation(f"{what} changed the chain")
    return "loaded; " + ", ".join(done)


def _random_joint(rng: random.Random, n: int, r: float, leaf: bool):
    from spatialmath import SE3

    from kinegami import (
        EndTip,
        ExtendedRevoluteJoint,
        PrismaticJoint,
        RevoluteJoint,
        Waypoint,
    )

    t = _translation(rng, r)
    pose = SE3.Trans(*t) * SE3.RPY(*(rng.uniform(-math.pi, math.pi) for _ in range(3)))
    kind = "EndTip" if leaf else rng.choice(JOINT_KINDS)
    if kind == "RevoluteJoint":
        return RevoluteJoint(n, r, rng.uniform(0.3, 6.0), pose,
                             numSinkLayers=_edge(rng, (1, 2, 32), 33))  # fmt: skip
    if kind == "ExtendedRevoluteJoint":
        return ExtendedRevoluteJoint(n, r, math.pi, _edge(rng, (0.5, 2.0), 1e6) * r, pose)
    if kind == "PrismaticJoint":
        return PrismaticJoint(n, r, rng.choice((2.0, 5.0)) * r, _edge(rng, (2, 3, 200), 201),
                              math.pi / 4, pose)  # fmt: skip
    if kind == "Waypoint":
        return Waypoint(n, r, pose)
    return EndTip(n, r, pose, _edge(rng, (1.0, 3.0, 1e6), 2e6) * r)


def operations_case(seed: int, folder: Path, small: bool = False) -> str:
    """A random chain or tree edited by random operations; the outcome in a few words."""
    from spatialmath import SE3

    from kinegami import KinematicChain, KinematicTree, StartTip, Waypoint

    rng = random.Random(seed)
    n = rng.choice((4, 4, 6, 8))
    r = rng.choice((1.0, 10.0, 1e-3, 1e4))
    tree = rng.random() < 0.4
    max_angle = _edge(rng, (math.pi / 2, math.pi / 4, math.pi / 180), rng.choice((1e-9, 0.0)))
    try:
        if tree:
            chain = KinematicTree(Waypoint(n, r, SE3()), maxAnglePerElbow=max_angle)
        else:
            chain = KinematicChain(StartTip(n, r, SE3(), 1.5 * r), maxAnglePerElbow=max_angle)
    except Exception as error:  # noqa: BLE001
        _refusal(error)
        return "refused at construction"
    counts = {"ok": 0, "refused": 0}
    growth = rng.randrange(1, 4 if small else 7)  # first some joints, then anything
    for step in range(growth + rng.randrange(3, 6 if small else 10)):
        size = len(chain.Joints)
        op = "add" if step < growth else rng.choice((
            "add", "delete", "translate", "rotate", "transform", "transformAll", "state",
            "states", "require", "margin", "pattern", "clearance", "sweep", "export"))
        k = rng.randrange(-1, size + 1)
        before = snapshot(chain)
        result = True
        try:
            if op == "add":
                leaf = rng.random() < 0.15
                joint = _random_joint(rng, n, r, leaf)
                flags = {"relative": rng.random() < 0.8, "safe": rng.random() < 0.7,
                         "fixedPosition": rng.random() < 0.2,
                         "fixedOrientation": rng.random() < 0.2}  # fmt: skip
                if tree:
                    result = chain.addJoint(rng.randrange(size), joint, **flags)
                else:
                    result = chain.append(joint, **flags)
            elif op == "delete":
                result = chain.delete(k)
            elif op == "translate":
                result = chain.translateJointAlongAxisOfMotion(
                    k, rng.choice((-3.0, 2.0, 1e5, 1e6, 2e6)) * r, propagate=rng.random() < 0.7,
                    applyToPreviousWaypoint=rng.random() < 0.3)  # fmt: skip
            elif op == "rotate":
                result = chain.rotateJointAboutAxisOfMotion(k, rng.uniform(-7, 7),
                                                            propagate=rng.random() < 0.7)
            elif op == "transform":
                T = SE3.Trans(*_translation(rng, r)) * SE3.Rx(rng.uniform(-3, 3))
                result = chain.transformJoint(k, T, propagate=rng.random() < 0.7)
            elif op == "transformAll":
                result = chain.transformAll(SE3.Trans(*_translation(rng, r)))
            elif op == "state":
                result = chain.setJointState(k, rng.uniform(-4, 4) * rng.choice((1.0, r)))
            elif op == "states":
                states = [rng.uniform(-1, 1) for _ in range(size + rng.choice((0, 0, 1)))]
                result = chain.setJointStates(states)
            elif op == "require":
                chain.requireClearance = rng.random() < 0.5
            elif op == "margin":
                chain.margin = rng.choice((0.0, 0.1 * r, r, -1.0, float("nan"), 1e7 * r))
            elif op in ("pattern", "clearance", "sweep"):
                _use(rng, chain, folder, op)
            else:
                _use(rng, chain, folder, rng.choice(SUFFIXES))
        except Exception as error:  # noqa: BLE001
            _refusal(error)
            result = False
        if result is False or result is None:
            counts["refused"] += 1
            if snapshot(chain) != before:
                raise Violation(f"a refused {op} changed the chain")
        else:
            counts["ok"] += 1
        if op in ("pattern", "clearance", "sweep", "export") and snapshot(chain) != before:
            raise Violation(f"{op} changed the chain")
    return f"{'tree' if tree else 'chain'} of {len(chain.Joints)}: {counts['ok']} done, " \
           f"{counts['refused']} refused"


#: Command lines of the ``cli`` cases (DESIGN and OUT are filled in).
COMMANDS = (
    ("validate", "DESIGN"),
    ("validate", "--build", "DESIGN"),
    ("check", "DESIGN"),
    ("check", "DESIGN", "--json"),
    ("check", "DESIGN", "--motion", "5"),
    ("build", "DESIGN", "-o", "OUT", "--formats", "dxf,svg,fold"),
    ("build", "DESIGN", "-o", "OUT", "--formats", "stl,urdf"),
    ("build", "DESIGN", "-o", "OUT", "--formats", "pdf"),
    ("compact", "DESIGN", "-o", "OUT/compact.json", "--time-limit", "1"),
)


def cli_case(seed: int, folder: Path) -> str:
    """``kinegami COMMAND`` on the design of ``seed``: exit status 0, 1 or 3; on stderr only
    lines ``kinegami COMMAND: error|warning|note: ...``, exactly one error line when the status
    is 1 and none otherwise."""
    import contextlib
    import io

    from kinegami.cli import main as kinegami

    rng = random.Random(seed ^ 0xC11)
    design = folder / f"fuzz{seed}.json"
    design.write_text(design_text(seed), encoding="utf-8")
    out = folder / f"out{seed}"
    args = [a.replace("DESIGN", str(design)).replace("OUT", str(out))
            for a in rng.choice(COMMANDS)]  # fmt: skip
    if args[0] == "build" and rng.random() < 0.1:
        args[args.index("--formats") + 1] = "all"
    if args[0] == "compact" and rng.random() < 0.5:  # a compaction takes long: a few only
        args = ["validate", str(design)]
    stdout, stderr = io.StringIO(), io.StringIO()
    # what reaches file descriptor 2 directly (worker processes, C libraries) is caught too
    with tempfile.TemporaryFile() as raw, contextlib.redirect_stdout(stdout), \
            contextlib.redirect_stderr(stderr):
        saved = os.dup(2)
        os.dup2(raw.fileno(), 2)
        try:
            status = kinegami(args)
        except SystemExit as exit:  # argparse
            status = exit.code
        finally:
            os.dup2(saved, 2)
            os.close(saved)
        raw.seek(0)
        direct = raw.read().decode("utf-8", "replace")
    lines = stderr.getvalue().splitlines() + direct.splitlines()
    prefix = f"kinegami {args[0]}: "
    kinds = [line[len(prefix):].split(":")[0] if line.startswith(prefix) else "?"
             for line in lines]  # fmt: skip
    if status not in (0, 1, 3) or "?" in kinds or kinds.count("error") != (status == 1):
        shown = " / ".join(line[:200] for line in lines[:6])
        raise Violation(f"kinegami {' '.join(args[:1])}: status {status}, stderr {shown!r}")
    if any("internal error" in line for line in lines):
        raise Violation(f"kinegami {args[0]}: {lines[-1][:300]}")
    return f"{args[0]}: status {status}"


def editor_case(seed: int, folder: Path) -> str:
    """A random design opened in the editor's model (kinegami.editor.EditorModel) and edited
    by random commands: a refused command (``ok`` False) gives one line of reason and leaves
    the design text and the chain bit-identical."""
    import numpy as np

    from kinegami.editor import EditorModel
    from kinegami.editor.document import Document

    rng = random.Random(seed ^ 0xED17)
    try:
        model = EditorModel(Document.loads(design_text(seed, small=True), "fuzz.json"))
    except Exception as error:  # noqa: BLE001
        _refusal(error)
        return "refused"
    r = model.chain.r
    counts = {"ok": 0, "refused": 0}
    for _ in range(rng.randrange(3, 9)):
        size = len(model.chain.Joints)
        k = rng.randrange(-1, size + 1)
        pose = np.eye(4)
        pose[:3, 3] = _translation(rng, r)
        kind = rng.choice(("RevoluteJoint", "PrismaticJoint", "ExtendedRevoluteJoint",
                           "Waypoint", "EndTip"))  # fmt: skip
        parameters = rng.choice(({}, {"numSinkLayers": 33}, {"numLayers": 201},
                                 {"tubeLength": 2e6 * r}, {"totalBendingAngle": 7.0},
                                 {"numSinkLayers": 2}, {"neutralLength": 4 * r}))  # fmt: skip
        if not set(parameters) <= {"RevoluteJoint": {"numSinkLayers", "totalBendingAngle"},
                                   "PrismaticJoint": {"numLayers", "neutralLength"},
                                   "ExtendedRevoluteJoint": {"numSinkLayers", "tubeLength",
                                                             "totalBendingAngle"},
                                   }.get(kind, set()) and rng.random() < 0.7:  # fmt: skip
            parameters = {}
        command = rng.choice(("add", "add", "branch", "delete", "slide", "roll", "state",
                              "states", "parameters", "options", "all", "undo"))  # fmt: skip
        before_text, before = model.to_design_text(), snapshot(model.chain)
        try:
            if command == "add":
                result = model.add_joint(kind, parameters, pose, after=max(k, 0) % size)
            elif command == "branch":
                result = model.add_branch(kind, parameters, pose, parent=max(k, 0) % size)
            elif command == "delete":
                result = model.delete(k)
            elif command == "slide":
                result = model.slide(k, rng.choice((-2.0, 3.0, 1e6, 2e6)) * r)
            elif command == "roll":
                result = model.roll(k, rng.uniform(-7, 7))
            elif command == "state":
                result = model.set_state(k, rng.uniform(-4, 4))
            elif command == "states":
                result = model.set_states([rng.uniform(-1, 1) for _ in range(size)])
            elif command == "parameters":
                result = model.set_parameters(k, **(parameters or {"numSinkLayers": 40}))
            elif command == "options":
                result = model.set_options(maxAnglePerElbow=rng.choice((0.5, 1e-9, 0.0, 3.2)))
            elif command == "all":
                result = model.transform_all(pose)
            else:
                result = model.undo()
        except Exception as error:  # noqa: BLE001
            raise Violation(f"editor {command} raised {type(error).__name__}: "
                            f"{str(error)[:300]}") from None  # fmt: skip
        if result.ok:
            counts["ok"] += 1
            continue
        counts["refused"] += 1
        reason = result.reason or ""
        if "\n" in reason:
            raise Violation(f"editor {command}: a reason of several lines: {reason[:300]!r}")
        if model.to_design_text() != before_text or snapshot(model.chain) != before:
            raise Violation(f"a refused editor {command} changed the design ({reason[:200]})")
    return f"edited: {counts['ok']} done, {counts['refused']} refused"


def selftest_case(seed: int, folder: Path) -> str:
    """What the runner must catch (tests/design/test_fuzz_bounded.py): seed 0 passes, 1 hangs,
    2 runs out of memory, 3 fails with an error that is not a KinegamiError, 4 with a
    KinegamiError, 5 kills its process."""
    from kinegami.errors import InvalidParameterError

    if seed == 1:
        end = time.monotonic() + 3600
        while time.monotonic() < end:  # busy: a hang is judged by CPU time
            pass
    elif seed == 2:
        try:
            bytearray(64 * 2**30)
        except MemoryError as error:
            _refusal(error)
    elif seed == 3:
        try:
            raise ValueError("line one\nline two")
        except ValueError as error:
            _refusal(error)
    elif seed == 4:
        try:
            raise InvalidParameterError("a one-line refusal")
        except InvalidParameterError as error:
            return f"refused: {_refusal(error)}"
    elif seed == 5:
        os._exit(9)
    return "fine"


CASES = {
    "design": design_case,
    "design:small": lambda seed, folder: design_case(seed, folder, small=True),
    "operations": operations_case,
    "operations:small": lambda seed, folder: operations_case(seed, folder, small=True),
    "cli": cli_case,
    "editor": editor_case,
    "selftest": selftest_case,
}


# --- workers ---------------------------------------------------------------------------------
def worker(kind: str, seeds: list[int], memory: int) -> None:
    """Run cases in this process (address space capped), one JSON line per event on stdout."""
    import resource

    if memory > 0:
        resource.setrlimit(resource.RLIMIT_AS, (memory, memory))
    os.environ.setdefault("MPLBACKEND", "Agg")
    warnings.simplefilter("ignore")  # warnings are not failures (the CLI prints them one line)
    out = sys.stdout
    with tempfile.TemporaryDirectory(prefix="kinegami-fuzz-") as tmp:
        folder = Path(tmp)
        for seed in seeds:
            print(json.dumps({"start": seed}), file=out, flush=True)
            try:
                outcome = CASES[kind](seed, folder)
                event = {"seed": seed, "status": "ok", "detail": outcome}
            except Violation as error:
                event = {"seed": seed, "status": "violation", "detail": str(error)}
            except MemoryError as error:  # outside a case's own handler (e.g. in a check)
                event = {"seed": seed, "status": "violation", "detail": f"MemoryError {error}"}
            print(json.dumps(event), file=out, flush=True)


def _spawn(kind: str, seeds: list[int], memory: int, nice: int) -> subprocess.Popen:
    code = ("import sys; sys.path.insert(0, sys.argv[1]); import fuzz; "
            "fuzz.worker(sys.argv[2], [int(s) for s in sys.argv[3].split(',')], int(sys.argv[4]))")
    return subprocess.Popen(
        [sys.executable, "-c", code, str(Path(__file__).parent), kind,
         ",".join(map(str, seeds)), str(memory)],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, text=True,
        preexec_fn=(lambda: os.nice(nice)) if nice else None,
    )  # fmt: skip


def run(kind: str, seeds: list[int], *, workers: int = 1, timeout: float = TIMEOUT,
        memory: int = MEMORY, nice: int = 0, report=None, every: int = 500) -> dict:
    """Run the cases ``seeds`` of ``kind`` in ``workers`` processes; return the counts and
    every problem: ``{"cases", "ok", "problems": [(seed, status, detail)], "slowest"}``.

    A case that uses more than ``timeout`` seconds of CPU (or runs for more than five times as
    long, wall clock: the machine may be shared) is a "hang" (its worker is killed and
    restarted after it); a worker that dies is a "crash" on the case it was running. Every
    ``every`` cases ``report`` gets a progress line with the next seed (to resume from)."""
    pending = list(seeds)
    per_worker = max(1, math.ceil(len(pending) / max(1, workers)))
    queues = [pending[i:i + per_worker] for i in range(0, len(pending), per_worker)]
    result = {"cases": 0, "ok": 0, "problems": [], "slowest": (0.0, None), "outcomes": {}}
    selector = selectors.DefaultSelector()
    running: dict = {}

    def start(queue: list[int]) -> None:
        if not queue:
            return
        proc = _spawn(kind, queue, memory, nice)
        state = {"queue": queue, "current": None, "since": time.monotonic(), "cpu": 0.0,
                 "pending": b""}  # fmt: skip
        running[proc] = state
        selector.register(proc.stdout, selectors.EVENT_READ, proc)

    def problem(seed, status, detail) -> None:
        result["problems"].append((seed, status, detail))
        if report:
            report(f"{kind} seed {seed}: {status}: {detail}")

    def finish_case(state, seed) -> None:
        elapsed = time.monotonic() - state["since"]
        if elapsed > result["slowest"][0]:
            result["slowest"] = (elapsed, seed)
        state["queue"] = state["queue"][state["queue"].index(seed) + 1:]
        state["current"] = None
        result["cases"] += 1
        if report and every > 0 and result["cases"] % every == 0:
            report(f"{kind}: {result['cases']} cases done, {result['ok']} passed, "
                   f"{len(result['problems'])} problems; resume with --seed "
                   f"{max(seeds[:result['cases']]) + 1 if workers == 1 else '(see problems)'}")

    def stop(proc, status: str) -> None:
        state = running.pop(proc)
        selector.unregister(proc.stdout)
        if proc.poll() is None:
            proc.kill()
        proc.wait()
        err = proc.stderr.read() if proc.stderr else ""
        seed = state["current"]
        if seed is not None:
            problem(seed, status, err.strip().splitlines()[-1][:300] if err.strip() and
                    status == "crash" else f"more than {timeout:g} s of CPU")  # fmt: skip
            finish_case(state, seed)
        start(state["queue"])

    for queue in queues:
        start(queue)
    while running:
        for key, _ in selector.select(timeout=0.5):
            proc = key.data
            state = running[proc]
            # read what the pipe holds, not one line: a buffered readline may take two lines
            # from the pipe and leave the second in its buffer, where the selector never
            # sees it (a case's "start" lost that way was never judged a hang)
            data = os.read(proc.stdout.fileno(), 1 << 16)
            if not data:
                stop(proc, "crash")
                continue
            *lines, state["pending"] = (state["pending"] + data).split(b"\n")
            for line in lines:
                event = json.loads(line)
                if "start" in event:
                    state["current"], state["since"] = event["start"], time.monotonic()
                    state["cpu"] = _cpu_seconds(proc.pid)
                    continue
                if event["status"] == "ok":
                    result["ok"] += 1
                    head = event["detail"].split(";")[0].split(":")[0].split(" of ")[0]
                    result["outcomes"][head] = result["outcomes"].get(head, 0) + 1
                else:
                    problem(event["seed"], event["status"], event["detail"])
                finish_case(state, event["seed"])
        now = time.monotonic()
        for proc, state in list(running.items()):
            if state["current"] is None:
                continue
            wall = now - state["since"]
            if wall > 5 * timeout or (wall > timeout
                                      and _cpu_seconds(proc.pid) - state["cpu"] > timeout):
                stop(proc, "hang")
    return result


def _cpu_seconds(pid: int) -> float:
    """CPU seconds (user and system) process ``pid`` has used (0 where /proc is missing)."""
    try:
        fields = Path(f"/proc/{pid}/stat").read_text().rsplit(")", 1)[1].split()
    except OSError:
        return 0.0
    return (int(fields[11]) + int(fields[12])) / os.sysconf("SC_CLK_TCK")


def _seeds(start: int, count: int) -> list[int]:
    return list(range(start, start + count))


def main(argv: list[str] | None = None) -> int:
    parser = argparse.ArgumentParser(description=__doc__.split("\n\n")[0])
    parser.add_argument("--designs", type=int, default=10_000)
    parser.add_argument("--operations", type=int, default=10_000)
    parser.add_argument("--cli", type=int, default=0, help="command lines on random designs")
    parser.add_argument("--editor", type=int, default=0, help="editor sessions")
    parser.add_argument("--seed", type=int, default=0, help="first seed")
    parser.add_argument("--workers", type=int, default=2)
    parser.add_argument("--timeout", type=float, default=TIMEOUT)
    parser.add_argument("--memory", type=int, default=MEMORY, help="bytes of address space")
    parser.add_argument("--nice", type=int, default=10)
    parser.add_argument("--progress", type=int, default=500,
                        help="a progress line every N cases (0: none)")
    args = parser.parse_args(argv)
    found = 0
    kinds = (("design", args.designs), ("operations", args.operations), ("cli", args.cli),
             ("editor", args.editor))
    for kind, count in kinds:
        if count <= 0:
            continue
        started = time.monotonic()
        result = run(kind, _seeds(args.seed, count), workers=args.workers, timeout=args.timeout,
                     memory=args.memory, nice=args.nice, every=args.progress,
                     report=lambda line: print(line, flush=True))  # fmt: skip
        found += len(result["problems"])
        slowest, seed = result["slowest"]
        print(f"{kind}: {result['cases']} cases, {result['ok']} passed, "
              f"{len(result['problems'])} problems, in {time.monotonic() - started:.0f} s; "
              f"slowest case {slowest:.1f} s (seed {seed}); outcomes {result['outcomes']}",
              flush=True)  # fmt: skip
    return 1 if found else 0


if __name__ == "__main__":
    sys.exit(main())
