"""The README as a newcomer follows it: CI runs its Quick start commands as written, they install
in editable mode (so the command runs the clone's code), and every design file its commands name
exists or is made by an earlier command."""

from __future__ import annotations

import re
import shlex
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]
README = (ROOT / "README.md").read_text(encoding="utf-8")
CI = (ROOT / ".ci" / "run").read_text(encoding="utf-8")


def bash_blocks(text: str) -> list[list[str]]:
    """The lines of every ```bash block, comments after ``#`` removed, blank lines dropped."""
    blocks = re.findall(r"^```bash\n(.*?)^```", text, flags=re.S | re.M)
    return [
        [line.split("  #")[0].strip() for line in block.splitlines() if line.strip()]
        for block in blocks
    ]


def quick_start() -> list[str]:
    section = README[README.index("## Quick start") :]
    return bash_blocks(section)[0]


def test_quick_start_has_the_two_commands():
    lines = quick_start()
    assert len(lines) == 2
    assert "kinegami build examples/designs/example1.json" in lines[0]
    assert lines[1].endswith("-m pytest")


def test_ci_runs_the_quick_start_as_written():
    ci_lines = [line.strip() for line in CI.splitlines()]
    for line in quick_start():
        assert line in ci_lines, line


def test_quick_start_installs_in_editable_mode():
    for line in quick_start():
        installs = re.findall(r"pip install (\S+ ?\S*)", line)
        assert installs and all(args.startswith("-e ") for args in installs), line


def test_readme_names_only_design_files_that_exist_or_are_made():
    made: set[str] = set()
    for block in bash_blocks(README):
        for line in block:
            for command in line.split("&&"):
                words = shlex.split(command)
                if not words or not words[0].endswith("kinegami") or len(words) < 3:
                    continue
                design = next(w for w in words[2:] if w.endswith(".json"))
                if words[1] == "new":
                    made.add(design)
                else:
                    assert design in made or (ROOT / design).is_file(), line
    assert made  # the README shows how to start a design of one's own


def test_pytest_q_still_prints_how_many_tests_passed():
    """The README's test command takes the options of pyproject.toml; a ``-q`` there would make
    ``pytest -q`` a ``-qq``, which prints no "N passed" line."""
    import os
    import subprocess
    import sys
    import tomllib

    options = tomllib.loads((ROOT / "pyproject.toml").read_text("utf-8"))["tool"]["pytest"]
    assert not {"-q", "--quiet"} & set(shlex.split(options["ini_options"]["addopts"]))
    env = {k: v for k, v in os.environ.items() if k != "PYTEST_ADDOPTS"}
    command = [sys.executable, "-m", "pytest", "-q", "-n", "0", "-p", "no:cacheprovider",
               "tests/test_readme.py::test_quick_start_has_the_two_commands"]  # fmt: skip
    done = subprocess.run(command, capture_output=True, text=True, env=env, cwd=ROOT)
    assert done.returncode == 0, done.stdout + done.stderr
    assert re.search(r"^1 passed\b", done.stdout, flags=re.M), done.stdout
