"""What the command-line tests share: the command as they run it (this source tree, never an
installed copy), a small design, and the checks of a clean one-line failure."""

from __future__ import annotations

import json
import os
import subprocess
import sys
from pathlib import Path

from gallery_designs import CHAIN_DESIGNS

ROOT = Path(__file__).resolve().parents[2]
EXAMPLE1 = ROOT / "examples" / "designs" / "example1.json"  # in cm, r = 1 cm
GALLERY = CHAIN_DESIGNS  # the chains (trees: TREE_DESIGNS)

DESIGN = {
    "format": "kinegami-design",
    "version": 1,
    "name": "Example 1A",
    "units": "mm",
    "numSides": 4,
    "r": 1,
    "joints": [
        {"type": "StartTip", "length": 1.5, "pose": [{"Trans": [3, 3, 0]}]},
        {"type": "PrismaticJoint", "neutralLength": 3, "numLayers": 3,
         "coneAngle": 0.7853981633974483, "pose": [{"Trans": [5, 5, 0]}]},
        {"type": "RevoluteJoint", "totalBendingAngle": 3.141592653589793,
         "pose": [{"Ry": 0.7853981633974483}]},
        {"type": "EndTip", "length": 1.5, "pose": [{"Ry": 1.5707963267948966}]},
    ],
    "edits": [
        {"op": "rotateJointAboutAxisOfMotion", "joint": 4, "angle": 0.5},
    ],
}  # fmt: skip


def command() -> list[str]:
    """The command as the tests run it: ``python -m kinegami`` from this source tree (see
    :func:`source_env`), never an installed copy that may predate the last edit."""
    return [sys.executable, "-m", "kinegami"]


def source_env(**changes) -> dict[str, str]:
    """The environment of a subprocess that imports kinegami from this checkout: the repository
    first on PYTHONPATH, no display, the Agg backend; ``changes`` on top (None removes)."""
    env = dict(os.environ, MPLBACKEND="Agg")
    env.pop("DISPLAY", None)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [env.get("PYTHONPATH")])])
    for name, value in changes.items():
        if value is None:
            env.pop(name, None)
        else:
            env[name] = value
    return env


def run(*args, cwd=None, env=None) -> subprocess.CompletedProcess:
    """``kinegami args`` as a subprocess of this source tree, its output captured as text."""
    return subprocess.run(
        [*command(), *map(str, args)], capture_output=True, text=True, cwd=cwd,
        env=env or source_env(), timeout=300,
    )  # fmt: skip


def write(path: Path, data) -> Path:
    """``data`` (a string, or JSON-able) written to ``path``."""
    path.write_text(data if isinstance(data, str) else json.dumps(data, indent=2))
    return path


def assert_clean_failure(result, *words):
    """Exit code 1, no traceback, and one line on stderr holding every one of ``words``."""
    assert result.returncode == 1, result
    assert "Traceback" not in result.stderr + result.stdout
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1, result.stderr
    for word in words:
        assert word in lines[0], (word, lines[0])


def main_in_process(*args) -> int:
    """``kinegami args`` in this process (Agg backend), its exit code."""
    import matplotlib

    matplotlib.use("Agg")
    from kinegami.cli import main

    return main([str(a) for a in args])


#: Every joint exactly where it is put.
FIXED = {"relative": False, "safe": False, "fixedPosition": True, "fixedOrientation": True}


def fold_back(d: float) -> dict:
    """A design whose tube goes out along +x, over the top and back along -x, ``d`` r to the
    side of its way out and past its start tip (every joint exactly where it is put)."""

    def waypoint(point, xhat):
        pose = {"point": point, "axis": [0, 0, 1], "xhat": xhat}
        return {"type": "Waypoint", "pathIndex": 0, "pose": pose, **FIXED}

    return {
        "format": "kinegami-design",
        "version": 1,
        "name": "Fold back",
        "units": "mm",
        "numSides": 4,
        "r": 1,
        "joints": [
            {"type": "StartTip", "name": "base", "length": 1.5,
             "pose": {"point": [-10, 0, 0], "axis": [1, 0, 0]}},
            waypoint([0, 0, 0], [1, 0, 0]),
            waypoint([0, d, 6], [-1, 0, 0]),
            waypoint([-10, d, 0], [-1, 0, 0]),
            {"type": "EndTip", "name": "tool", "length": 1.5,
             "pose": {"point": [-15.75, d, 0], "axis": [-1, 0, 0]}, **FIXED},
        ],
    }  # fmt: skip
