"""A clone of the repository is complete: no file reads the reference folder beside it.

The project is developed next to a folder ``../shared`` (reference material and outside tools)
that a user's clone does not have. Tests keep their reference data in the repository
(tests/data/, tests/design/data/), and the outside programs the browser tests drive are located
in one place only, ``.ci/run`` (it points ``KINEGAMI_ORIGAMI_SIMULATOR`` at its copy of Origami
Simulator; without the variable those tests skip). This test fails when any other file of the
repository (tests and conftest files included) names that folder as a path.
"""

from __future__ import annotations

import os
import re
import subprocess
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
#: the one file that may locate the outside tools in ../shared
ALLOWED = {".ci/run"}
#: ``../shared``, ``/work/shared``, a path component ``"shared"`` (``parent / "shared"``,
#: ``"shared/tools/..."``) or ``shared/tools``, ``shared/fixtures``, ``shared/spec``
SHARED_PATH = re.compile(
    r"""\.\./shared\b|/work/shared\b|["']shared["'/\\]|\bshared/(?:tools|fixtures|spec)\b"""
)
#: folders that are not part of the repository (used when git is not available)
SKIP = {".git", ".venv", "venv", "build", "dist", "out", "__pycache__", ".pytest_cache",
        ".hypothesis", ".ruff_cache", "node_modules", "examplePatterns"}  # fmt: skip


def repository_files() -> list[str]:
    """Every file of the repository, tracked or new (not those git ignores), relative."""
    try:
        done = subprocess.run(
            ["git", "ls-files", "-z", "--cached", "--others", "--exclude-standard"],
            capture_output=True, text=True, cwd=ROOT, check=True,
        )  # fmt: skip
        return sorted({name for name in done.stdout.split("\0") if (ROOT / name).is_file()})
    except (OSError, subprocess.CalledProcessError):  # no git: walk the folder
        found = []
        for folder, dirs, files in os.walk(ROOT):
            dirs[:] = [d for d in dirs if d not in SKIP and not d.endswith(".egg-info")]
            found += [(Path(folder) / f).relative_to(ROOT).as_posix() for f in files]
        return sorted(found)


def shared_paths(text: str) -> list[tuple[int, str]]:
    """(line number, line) of every line of ``text`` that names the shared folder as a path."""
    return [
        (number, line.strip())
        for number, line in enumerate(text.splitlines(), 1)
        if SHARED_PATH.search(line)
    ]


def test_the_pattern_finds_the_ways_tests_named_the_folder():
    for line in (
        'FIXTURES = Path(__file__).resolve().parents[2].parent / "shared" / "fixtures"',
        'FIXTURES = ROOT.parent / "shared" / "fixtures"',
        'os.environ.get("X", REPO.parent / "shared/tools/OrigamiSimulator")',
        "os.path.join('..', 'shared', 'fixtures', 'hand.json')",
        "see ../shared/spec/trees.md",
        "open('/work/shared/fixtures/hand.json')",
        "the copy in shared/tools/OrigamiSimulator",
    ):
        assert shared_paths(line), line
    for line in (
        "# shared items: like JSON copies",
        "shared = set(a.distalBase.tolist())",
        "def test_shared_cached_patterns_cannot_be_changed_through_their_records():",
        '"""Headless Chromium, shared with the editor\'s browser tests."""',
    ):
        assert not shared_paths(line), line


def test_the_files_looked_at_include_the_tests_and_their_conftest():
    files = set(repository_files())
    for name in ("tests/conftest.py", "tests/export/origami_simulator.py",
                 "tests/tree/helpers.py", "tests/test_gallery.py", "README.md"):  # fmt: skip
        assert name in files, name


def test_no_file_but_ci_names_the_shared_folder():
    me = Path(__file__).resolve().relative_to(ROOT).as_posix()
    found = []
    for name in repository_files():
        if name in ALLOWED or name == me:
            continue
        data = (ROOT / name).read_bytes()
        if b"\0" in data[:8192]:  # binary (pictures)
            continue
        text = data.decode("utf-8", "replace")
        found += [f"{name}:{n}: {line}" for n, line in shared_paths(text)]
    assert not found, "files that need ../shared, which a clone does not have:\n" + "\n".join(found)


def test_ci_locates_the_outside_tools_and_requires_the_browser_tests():
    lines = [line.strip() for line in (ROOT / ".ci" / "run").read_text("utf-8").splitlines()]
    tests = next(i for i, line in enumerate(lines) if line.endswith("-m pytest"))
    exports = {line.split("=")[0].removeprefix("export ") for line in lines[:tests]
               if line.startswith("export ")}  # fmt: skip
    assert {"KINEGAMI_ORIGAMI_SIMULATOR", "KINEGAMI_REQUIRE_BROWSER"} <= exports
