"""The command's error reporting: output that survives any terminal encoding, ``-o`` checked
before the build, ``--formats`` typos, shortened echoes, Ctrl-C at start-up (exit 130, one line)."""

from __future__ import annotations

import json
import os
import signal
import subprocess
import sys
import textwrap
from pathlib import Path

import pytest

from .helpers import EXAMPLE1, assert_clean_failure, command, source_env

NAME = "Bras \u00e0 3 axes \u2014 \u00fc"


def run(*args, cwd=None, **env) -> subprocess.CompletedProcess:
    """``kinegami args`` as a subprocess of this source tree, ``env`` added to its environment;
    undecodable output replaced rather than raising (the tests pick the terminal's encoding)."""
    return subprocess.run(
        [*command(), *map(str, args)], capture_output=True, text=True,
        cwd=cwd, env=source_env(**env), timeout=300, errors="replace",
    )  # fmt: skip


def one_line_failure(result, *words) -> str:
    """A clean failure (helpers.assert_clean_failure) that is no internal error; its line."""
    assert_clean_failure(result, *words)
    assert "internal error" not in result.stderr
    return result.stderr.strip()


@pytest.fixture
def unicode_design(tmp_path) -> Path:
    document = json.loads(EXAMPLE1.read_text(encoding="utf-8"))
    document["name"] = NAME
    document["joints"][2]["name"] = "\u00e9paule"
    path = tmp_path / "bras.json"
    path.write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")
    return path


# --- encodings ---------------------------------------------------------------------------------
@pytest.mark.parametrize("encoding", ["ascii", "ascii:strict"])
def test_non_ascii_names_print_on_an_ascii_terminal(tmp_path, unicode_design, encoding):
    result = run("build", unicode_design, "-o", tmp_path / "out", "--formats", "dxf",
                 PYTHONIOENCODING=encoding)  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("Bras \\xe0 3 axes \\u2014 \\xfc (")
    assert (tmp_path / "out" / "bras.dxf").is_file()
    result = run("validate", "--build", unicode_design, PYTHONIOENCODING=encoding)
    assert result.returncode == 0, result.stderr
    assert "'\\xe9paule'" in result.stdout


def test_non_ascii_errors_are_one_line_on_an_ascii_terminal(tmp_path, unicode_design):
    document = json.loads(unicode_design.read_text(encoding="utf-8"))
    document["joints"][1]["type"] = "Gelenk-\u00e4"
    unicode_design.write_text(json.dumps(document, ensure_ascii=False), encoding="utf-8")
    line = one_line_failure(run("validate", unicode_design, PYTHONIOENCODING="ascii"))
    assert "Gelenk-\\xe4" in line and "joints[1].type" in line


# --- -o ----------------------------------------------------------------------------------------
@pytest.mark.skipif(not hasattr(os, "symlink"), reason="symbolic links")
@pytest.mark.parametrize(
    "make, output, words",
    [
        (lambda d: os.symlink(d / "nowhere", d / "link"), "link", ["'link'", "dangling"]),
        (lambda d: os.symlink(d / "nowhere", d / "link"), "link/sub", ["'link'", "dangling"]),
        (lambda d: (os.symlink(d / "b", d / "a"), os.symlink(d / "a", d / "b")), "a",
         ["'a'", "symbolic link loop"]),
        (lambda d: os.symlink(d / "loop", d / "loop"), "loop/sub/deeper",
         ["'loop'", "symbolic link loop"]),
        (lambda d: (d / "file").write_text("x"), "file", ["'file'", "not a folder"]),
        (lambda d: (d / "file").write_text("x"), "file/sub", ["'file'", "not a folder"]),
    ],
    ids=["dangling", "under dangling", "loop", "under a loop", "file", "under a file"],
)  # fmt: skip
def test_unusable_output_folders_fail_before_the_build(tmp_path, make, output, words):
    make(tmp_path)
    before = sorted(os.listdir(tmp_path))
    # the design does not even exist: the -o check comes first
    result = run("build", tmp_path / "missing.json", "-o", output, cwd=tmp_path)
    line = one_line_failure(result, "-o:", *words)
    assert "missing.json" not in line
    assert sorted(os.listdir(tmp_path)) == before  # nothing created, no staging folder


# --- --formats and echoed values -----------------------------------------------------------------
@pytest.mark.parametrize("formats", ["all,bogus", "bogus,all", "dxf,,all, bogus"])
def test_unknown_formats_next_to_all_are_rejected(tmp_path, formats):
    result = run("build", EXAMPLE1, "-o", tmp_path / "out", "--formats", formats)
    one_line_failure(result, "--formats", "'bogus'", "known: dxf, svg, png", ", all")
    assert not (tmp_path / "out").exists()


def test_echoed_values_are_shortened(tmp_path):
    long_name = "x" * 10_000
    line = one_line_failure(run("build", EXAMPLE1, "-o", tmp_path, "--formats", long_name))
    assert len(line) < 300 and "x" * 70 in line and "..." in line
    line = one_line_failure(run("build", EXAMPLE1, "-o", tmp_path, "--name", "." + long_name))
    assert len(line) < 300 and "..." in line
    document = json.loads(EXAMPLE1.read_text(encoding="utf-8"))
    document["joints"][1][long_name] = 1
    path = tmp_path / "bad.json"
    path.write_text(json.dumps(document), encoding="utf-8")
    line = one_line_failure(run("validate", path), "unknown key")
    assert len(line) < 600 + len(str(path)), line


# --- Ctrl-C --------------------------------------------------------------------------------------
INTERRUPT_AT = textwrap.dedent(
    """
    import importlib.abc, os, signal, sys

    trigger, sys.argv = sys.argv[1], ["kinegami", *sys.argv[2:]]

    class Interrupt(importlib.abc.MetaPathFinder):  # Ctrl-C the moment `trigger` is imported
        def find_spec(self, name, path=None, target=None):
            if name == trigger:
                sys.meta_path.remove(self)
                os.kill(os.getpid(), signal.SIGINT)
            return None

    sys.meta_path.insert(0, Interrupt())
    from kinegami.cli import main  # as the console script does

    raise SystemExit(main())
    """
)


@pytest.mark.skipif(not hasattr(signal, "SIGINT") or os.name == "nt", reason="POSIX signals")
@pytest.mark.parametrize(
    "trigger, message",
    [
        ("numpy", "kinegami: interrupted"),  # importing the package, before main()
        ("jsonschema", "kinegami validate: interrupted"),  # the command imports it
        ("kinegami.design", "kinegami validate: interrupted"),  # in the command
    ],
)
def test_ctrl_c_during_start_up_is_one_line_and_exit_130(trigger, message):
    result = subprocess.run(
        [sys.executable, "-c", INTERRUPT_AT, trigger, "validate", "--build", EXAMPLE1],
        capture_output=True, text=True, env=source_env(), timeout=300,
    )  # fmt: skip
    assert result.returncode == 130, result
    assert result.stderr == message + "\n"
    assert result.stdout == ""


def test_importing_the_library_keeps_ctrl_c_as_keyboard_interrupt():
    code = (
        "import signal, kinegami, kinegami.cli; "
        "assert signal.getsignal(signal.SIGINT) is signal.default_int_handler"
    )
    result = subprocess.run([sys.executable, "-c", code], env=source_env(), capture_output=True)
    assert result.returncode == 0, result.stderr
