"""``kinegami build`` interrupted while it publishes: the folder keeps the old build or gets the
whole new one, and a build after a SIGKILL recovers (kinegami.export.publish).

Real ``kinegami`` processes are paused before each publishing step by the documented test hook
(``KINEGAMI_TEST_PAUSE_BEFORE_STEP``) and sent SIGTERM, SIGINT or SIGKILL; in-process builds get
an exception at each move.
"""

from __future__ import annotations

import json
import os
import select
import signal
import subprocess
from pathlib import Path

import pytest

from kinegami.export import publish

from .helpers import DESIGN, command, main_in_process, source_env

pytestmark = pytest.mark.skipif(publish.fcntl is None, reason="needs POSIX flock")

#: An earlier build (contents that the new build surely differs from) and a user's file.
OLD = {"arm.dxf": b"old dxf", "arm.svg": b"old svg", "keep.txt": b"user's file"}
#: Steps of publishing arm.dxf and arm.svg over OLD: the journal, dxf aside and in, svg aside
#: and in, the commit.
STEPS = 6


def snapshot(folder: Path) -> dict[str, bytes | None]:
    """Every entry below ``folder``, hidden ones included (None for folders)."""
    found: dict[str, bytes | None] = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs:
            found[os.path.relpath(os.path.join(root, name), folder)] = None
        for name in files:
            path = os.path.join(root, name)
            found[os.path.relpath(path, folder)] = Path(path).read_bytes()
    return found


@pytest.fixture
def design(tmp_path) -> Path:
    path = tmp_path / "arm.json"
    path.write_text(json.dumps(DESIGN))
    return path


@pytest.fixture
def out(tmp_path) -> Path:
    folder = tmp_path / "out"
    folder.mkdir()
    for name, data in OLD.items():
        (folder / name).write_bytes(data)
    return folder


def is_new_build(folder: Path, also: tuple[str, ...] = ()) -> bool:
    """``folder`` holds a complete new build of arm.dxf and arm.svg, the user's file and the
    entries ``also``, and nothing else (no staging folder)."""
    here = snapshot(folder)
    return (
        sorted(here) == sorted([*OLD, *also])
        and here["keep.txt"] == OLD["keep.txt"]
        and here["arm.dxf"].startswith(b"  0\nSECTION")  # a DXF file, not the old bytes
        and b"<svg" in here["arm.svg"]
    )


def paused_build(design: Path, out: Path, step: int) -> subprocess.Popen:
    """A ``kinegami build`` process paused before publishing step ``step``."""
    env = source_env(**{publish.PAUSE_HOOK: str(step)})
    process = subprocess.Popen(
        [*command(), "build", str(design), "-o", str(out), "--formats", "dxf,svg"],
        stdout=subprocess.PIPE, stderr=subprocess.PIPE, env=env,
    )  # fmt: skip
    ready, _, _ = select.select([process.stderr], [], [], 300)
    line = process.stderr.readline().decode() if ready else ""
    if f"paused before publishing step {step}" not in line:
        process.kill()
        pytest.fail(f"the build did not pause: {line!r} {process.communicate()}")
    return process


@pytest.mark.parametrize(
    ("step", "name"), [(step, "SIGTERM") for step in range(STEPS)] + [(3, "SIGINT")]
)  # SIGINT at every step: tests/export/test_publish.py
def test_a_signal_while_publishing_leaves_the_old_build(design, out, step, name):
    process = paused_build(design, out, step)
    process.send_signal(getattr(signal, name))
    _, err = process.communicate(timeout=120)
    assert process.returncode == 128 + getattr(signal, name)
    assert b"Traceback" not in err
    assert snapshot(out) == OLD  # exactly the old files, and no staging folder


@pytest.mark.parametrize("step", range(STEPS))
def test_sigkill_while_publishing_is_recovered_by_the_next_build(design, out, step, capsys):
    process = paused_build(design, out, step)
    process.kill()
    process.communicate(timeout=120)
    assert process.returncode == -signal.SIGKILL
    assert any(name.startswith(publish.PREFIX) for name in os.listdir(out))
    # a later build of another format: puts the old files back, and says so in one line
    assert main_in_process("build", design, "-o", out, "--formats", "fold") == 0
    err = capsys.readouterr().err.strip().splitlines()
    assert len(err) == 1 and err[0].startswith("kinegami build: note: ") and "interrupted" in err[0]
    if step >= 2:  # arm.dxf had been moved aside
        assert "put back the earlier arm.dxf" in err[0]
    here = snapshot(out)
    assert here.pop("arm.fold").startswith(b"{")
    assert here == OLD
    # and the next build of the same formats publishes normally, with nothing to recover
    assert main_in_process("build", design, "-o", out, "--formats", "dxf,svg") == 0
    assert "note:" not in capsys.readouterr().err
    assert is_new_build(out, also=("arm.fold",))


@pytest.mark.parametrize("index", range(STEPS))
def test_an_interrupt_at_any_move_in_process(design, out, monkeypatch, index, capsys):
    real = publish._move
    calls = []

    def interrupted(src, dst):
        calls.append(dst)
        if len(calls) - 1 == index:
            raise KeyboardInterrupt
        real(src, dst)

    monkeypatch.setattr(publish, "_move", interrupted)
    assert main_in_process("build", design, "-o", out, "--formats", "dxf,svg") == 130
    assert snapshot(out) == OLD
    monkeypatch.setattr(publish, "_move", real)
    assert main_in_process("build", design, "-o", out, "--formats", "dxf,svg") == 0
    assert "note:" not in capsys.readouterr().err  # nothing was left to recover
    assert is_new_build(out)
