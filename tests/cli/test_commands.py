"""The ``kinegami`` command, run as a subprocess: exit codes, outputs, clean errors."""

from __future__ import annotations

import json
import os
import shutil
import subprocess
import sys
from pathlib import Path

import pytest

from .helpers import (
    DESIGN,
    EXAMPLE1,
    GALLERY,
    ROOT,
    assert_clean_failure,
    main_in_process,
    run,
    source_env,
    write,
)


@pytest.fixture
def design(tmp_path) -> Path:
    return write(tmp_path / "arm.json", DESIGN)


# --- help and version ----------------------------------------------------------------------
@pytest.mark.parametrize("args", [[], ["--help"], ["build", "--help"], ["show", "--help"],
                                  ["validate", "--help"], ["new", "--help"]])  # fmt: skip
def test_help_everywhere(args):
    result = run(*args)
    assert result.returncode == 0
    assert "usage: kinegami" in result.stdout
    if args[:1] == ["build"]:
        for word in ("--output", "--formats", "dxf", "svg", "png"):
            assert word in result.stdout


def test_version():
    result = run("--version")
    assert result.returncode == 0
    assert result.stdout.startswith("kinegami ")


def test_the_command_runs_this_source_tree(tmp_path):
    """From any folder, the command the tests run imports the package of this checkout."""
    probe = [sys.executable, "-c", "import kinegami; print(kinegami.__file__)"]
    done = subprocess.run(probe, capture_output=True, text=True, cwd=tmp_path, env=source_env())
    assert Path(done.stdout.strip()) == ROOT / "kinegami" / "__init__.py"


def test_unknown_command_is_a_usage_error():
    result = run("frobnicate")
    assert result.returncode == 2
    assert "invalid choice" in result.stderr
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()  # one line: the error, then the usage
    assert len(lines) == 1 and lines[0].startswith("kinegami: error: argument COMMAND"), lines
    assert "usage: kinegami [-h] [--version] COMMAND ..." in lines[0]


@pytest.mark.parametrize("args", [["build"], ["build", "x.json"], ["build", "x", "-o", "y",
                                  "--formats"], ["compact", "x.json", "--seed"]])  # fmt: skip
def test_a_command_line_that_cannot_be_parsed_is_one_line(args):
    result = run(*args)
    assert result.returncode == 2
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 1 and lines[0].startswith(f"kinegami {args[0]}: error: "), lines
    assert f"usage: kinegami {args[0]} " in lines[0]


# --- build ---------------------------------------------------------------------------------
def test_build_writes_files_and_prints_a_summary(design, tmp_path):
    out = tmp_path / "out" / "nested"
    result = run("build", design, "-o", out)
    assert result.returncode == 0, result.stderr
    names = sorted(p.name for p in out.iterdir())
    assert names == ["arm.dxf", "arm.svg", "arm_3d.png", "arm_pattern.png"]
    for path in out.iterdir():
        assert path.stat().st_size > 0
        assert str(path) in result.stdout
    assert (out / "arm_3d.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    assert (out / "arm.dxf").read_text().lstrip().startswith("0")
    text = result.stdout
    assert "Example 1A" in text
    # safe placement adds waypoints (one before each joint here); counted in order of appearance
    kinds = "1 StartTip, 3 Waypoint, 1 PrismaticJoint, 1 RevoluteJoint, 1 EndTip"
    assert f"joints: 7 ({kinds})" in text
    assert "links: 6" in text
    assert "sheet:" in text and " mm x " in text
    assert "total tube length:" in text
    # no staging folders left behind
    assert not [p for p in tmp_path.rglob(".kinegami-build-*")]


def test_summary_numbers_match_the_library(design, tmp_path):
    from kinegami.design import load_design
    from kinegami.pattern.sheet import flatten

    chain = load_design(design)
    sheet = flatten(chain.creasePattern())
    xmin, ymin, xmax, ymax = sheet.bounds
    tube = chain.totalPathLength() + sum(j.neutralLength for j in chain.Joints)
    result = run("build", design, "-o", tmp_path / "o", "--formats", "dxf")
    pattern = chain.creasePattern()
    assert (
        f"sheet: {xmax - xmin:.1f} mm x {ymax - ymin:.1f} mm with the glue tab (the crease "
        f"pattern alone: {pattern.width:.1f} mm x {pattern.height:.1f} mm)"
    ) in result.stdout
    assert xmax - xmin > pattern.width + 0.05  # the two sizes differ by the tab
    assert f"total tube length: {tube:.1f} mm" in result.stdout


def test_units_scale_the_summary(tmp_path):
    data = dict(DESIGN, units="cm")
    path = write(tmp_path / "cm.json", data)
    mm = run("build", write(tmp_path / "mm.json", DESIGN), "-o", tmp_path / "a", "--formats",
             "dxf")  # fmt: skip
    cm = run("build", path, "-o", tmp_path / "b", "--formats", "dxf")
    assert "r = 1 mm" in mm.stdout and "r = 10 mm" in cm.stdout


def test_formats_and_name(design, tmp_path):
    result = run("build", design, "-o", tmp_path / "o", "--formats", "svg", "--name", "x")
    assert result.returncode == 0, result.stderr
    assert [p.name for p in (tmp_path / "o").iterdir()] == ["x.svg"]


def test_unknown_format(design, tmp_path):
    result = run("build", design, "-o", tmp_path / "o", "--formats", "dxf,gif")
    assert_clean_failure(result, "'gif'", "dxf", "svg")
    assert not (tmp_path / "o").exists()


def test_output_is_a_file(design, tmp_path):
    blocker = write(tmp_path / "file.txt", "x")
    result = run("build", design, "-o", blocker)
    assert_clean_failure(result, "not a folder")
    result = run("build", design, "-o", blocker / "sub")
    assert result.returncode == 1 and "Traceback" not in result.stderr
    assert blocker.read_text() == "x"


BROKEN = {
    "invalid JSON": ('{"format": "kinegami-design", "version": 1,,}', ["line 1"]),
    "empty file": ("", ["the design file is empty", "JSON object"]),
    "missing field": ({k: v for k, v in DESIGN.items() if k != "numSides"}, ["numSides"]),
    "wrong type": (dict(DESIGN, r="one"), ["r:", '"one"', "number"]),
    "out of range": (dict(DESIGN, numSides=2), ["numSides", "2"]),
    "unknown joint type": (
        dict(DESIGN, joints=[*DESIGN["joints"][:2], {"type": "BallJoint"}]),
        ["joints[2]", "BallJoint", "RevoluteJoint"],
    ),
    "wrong version": (dict(DESIGN, version=9), ["version", "9", "newer"]),
    "infeasible edit": (
        dict(DESIGN, edits=[{"op": "setJointState", "joint": 2, "state": 9}]),
        ["edits[0]"],
    ),
}


@pytest.mark.parametrize("case", sorted(BROKEN))
def test_bad_design_gives_one_clean_line_and_no_files(case, tmp_path):
    data, words = BROKEN[case]
    path = write(tmp_path / "bad.json", data)
    out = tmp_path / "out"
    result = run("build", path, "-o", out)
    assert_clean_failure(result, "bad.json", *words)
    assert not out.exists()
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.json"]


def test_missing_design_file(tmp_path):
    result = run("build", tmp_path / "nope.json", "-o", tmp_path / "out")
    assert_clean_failure(result, "nope.json")
    assert not (tmp_path / "out").exists()


# --- validate ------------------------------------------------------------------------------
def test_validate(design, tmp_path):
    result = run("validate", design)
    assert result.returncode == 0, result.stderr
    assert "valid" in result.stdout and "4 joints" in result.stdout  # as written
    result = run("validate", design, "--build")
    assert result.returncode == 0, result.stderr
    assert "builds 7 joints" in result.stdout  # waypoints added
    table = result.stdout.splitlines()[2:]
    assert [line.split()[:2] for line in table] == [
        ["0", "StartTip"], ["1", "Waypoint"], ["2", "PrismaticJoint"], ["3", "Waypoint"],
        ["4", "RevoluteJoint"], ["5", "Waypoint"], ["6", "EndTip"],
    ]  # fmt: skip
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.json"]


@pytest.mark.parametrize("case", ["missing field", "unknown joint type", "wrong version"])
def test_validate_rejects(case, tmp_path):
    data, words = BROKEN[case]
    result = run("validate", write(tmp_path / "bad.json", data))
    assert_clean_failure(result, "bad.json", *words)


@pytest.mark.parametrize("text", ["", "\n", " \t\r\n  \n"])
def test_validate_an_empty_file_says_it_is_empty(text, tmp_path):
    result = run("validate", write(tmp_path / "bad.json", text))
    empty = "empty (only whitespace)" if text else "empty"
    reason = f'the design file is {empty}: a design is a JSON object {{...}} with "format": '
    assert_clean_failure(result, f"bad.json: {reason}", '"kinegami-design"', "kinegami new")
    assert "invalid JSON" not in result.stderr


def test_validate_does_not_build_unless_asked(tmp_path):
    data, _ = BROKEN["infeasible edit"]
    path = write(tmp_path / "bad.json", data)
    assert run("validate", path).returncode == 0
    assert_clean_failure(run("validate", path, "--build"), "edits[0]")


# --- new --------------------------------------------------------------------------------------
def test_new_writes_a_starter_that_validates_and_builds(tmp_path):
    result = run("new", "my_robot.json", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert "wrote my_robot.json" in result.stdout
    assert "kinegami validate --build my_robot.json" in result.stdout
    assert sorted(p.name for p in tmp_path.iterdir()) == ["my_robot.json"]
    result = run("validate", "--build", "my_robot.json", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    result = run("build", "my_robot.json", "-o", "out", "--formats", "dxf", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert result.stdout.startswith("my_robot (my_robot.json)")
    assert (tmp_path / "out" / "my_robot.dxf").stat().st_size > 0


def test_new_keeps_an_existing_file_unless_forced(tmp_path):
    path = write(tmp_path / "arm.json", "my own design")
    result = run("new", path)
    assert_clean_failure(result, "arm.json", "exists", "--force")
    assert path.read_text() == "my own design"
    result = run("new", path, "--force")
    assert result.returncode == 0, result.stderr
    assert json.loads(path.read_text())["name"] == "arm"
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.json"]


def test_new_needs_a_json_name(tmp_path):
    assert_clean_failure(run("new", tmp_path / "arm.txt"), ".json", "arm.txt")
    assert list(tmp_path.iterdir()) == []


# --- start-up without a writable home folder -------------------------------------------------
def homeless_env(tmp_path) -> dict[str, str]:
    """HOME where matplotlib cannot make its folders (``.config`` and ``.cache`` are files, which
    even root cannot write into), no XDG or MPLCONFIGDIR variables, and a TMPDIR of its own."""
    home = tmp_path / "home"
    home.mkdir()
    for name in (".config", ".cache"):
        (home / name).write_text("")
    home.chmod(0o500)
    (tmp_path / "tmp").mkdir()
    return source_env(
        HOME=str(home), XDG_CONFIG_HOME=None, XDG_CACHE_HOME=None, MPLCONFIGDIR=None,
        TMPDIR=str(tmp_path / "tmp"),
    )  # fmt: skip


def private_folder(tmp_path) -> Path:
    return tmp_path / "tmp" / f"kinegami-matplotlib-{os.getuid()}"


@pytest.mark.skipif(not hasattr(os, "getuid"), reason="POSIX user ids")
def test_without_a_writable_home_only_kinegamis_error_is_printed(tmp_path):
    result = run("validate", tmp_path / "nope.json", env=homeless_env(tmp_path))
    assert_clean_failure(result, "nope.json")  # no matplotlib cache warning before it
    folder = private_folder(tmp_path)
    assert folder.is_dir() and folder.stat().st_mode & 0o777 == 0o700


@pytest.mark.skipif(not hasattr(os, "getuid"), reason="POSIX user ids")
def test_without_a_writable_home_the_font_cache_is_kept(design, tmp_path):
    env = homeless_env(tmp_path)
    result = run("build", design, "-o", tmp_path / "o", "--formats", "png", env=env)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
    assert list(private_folder(tmp_path).glob("fontlist-*.json"))  # for the next run


@pytest.mark.skipif(not hasattr(os, "getuid"), reason="POSIX user ids")
def test_a_private_folder_that_others_can_use_is_not_used(design, tmp_path):
    env = homeless_env(tmp_path)
    folder = private_folder(tmp_path)
    folder.mkdir()
    folder.chmod(0o777)
    result = run("build", design, "-o", tmp_path / "o", "--formats", "png", env=env)
    assert result.returncode == 0 and result.stderr == ""
    assert list(folder.iterdir()) == []  # a fresh folder was used instead, and removed
    assert sorted(p.name for p in (tmp_path / "tmp").iterdir()) == [folder.name]


def test_a_library_import_does_not_change_matplotlibs_folder(tmp_path):
    """Only the command picks a folder: ``import kinegami`` leaves the environment alone."""
    probe = "import os, kinegami; print(os.environ.get('MPLCONFIGDIR', ''))"
    done = subprocess.run(
        [sys.executable, "-c", probe], capture_output=True, text=True,
        env=homeless_env(tmp_path), cwd=tmp_path,
    )  # fmt: skip
    assert done.returncode == 0, done.stderr
    assert "kinegami-matplotlib" not in done.stdout
    assert not private_folder(tmp_path).exists()


# --- show ----------------------------------------------------------------------------------
def test_show_without_a_display_says_so(design):
    result = run("show", design)
    assert_clean_failure(result, "no interactive backend")


def test_show_bad_design(tmp_path):
    data, words = BROKEN["wrong type"]
    assert_clean_failure(run("show", write(tmp_path / "bad.json", data)), *words)


# --- the gallery's main job (README Quick start) -------------------------------------------
def test_quick_start_command(tmp_path):
    shutil.copy(EXAMPLE1, tmp_path / "example1.json")
    result = run("build", "example1.json", "-o", "out/", cwd=tmp_path)
    assert result.returncode == 0, result.stderr
    assert sorted(p.name for p in (tmp_path / "out").iterdir()) == [
        "example1.dxf", "example1.svg", "example1_3d.png", "example1_pattern.png"
    ]  # fmt: skip


def test_chain_formats_through_the_export_registry(design, tmp_path):
    """--formats reaches kinegami.export: a URDF comes with its mesh folder, moved in whole."""
    import trimesh
    import yourdfpy

    out = tmp_path / "o"
    for _ in range(2):  # a second build replaces the mesh folder
        result = run("build", design, "-o", out, "--formats", "stl,urdf,pdf")
        assert result.returncode == 0, result.stderr
    names = sorted(p.name for p in out.iterdir())
    assert names == ["arm.pdf", "arm.stl", "arm.urdf", "arm_meshes"]
    assert f"{out / 'arm_meshes'}{os.sep}" in result.stdout
    robot = yourdfpy.URDF.load(str(out / "arm.urdf"))
    assert robot.validate()
    assert len(trimesh.load(out / "arm.stl").faces) > 0
    assert not [p for p in tmp_path.rglob(".kinegami-build-*")]


@pytest.mark.parametrize("path", GALLERY, ids=[p.stem for p in GALLERY])
def test_every_gallery_design_builds_from_the_command_line(path, tmp_path, capsys):
    """In-process (the subprocess path is covered above): exit 0 and the four files."""
    import matplotlib

    matplotlib.use("Agg")
    from kinegami.cli import main

    assert main(["build", str(path), "-o", str(tmp_path)]) == 0
    stem = path.stem
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        [f"{stem}.dxf", f"{stem}.svg", f"{stem}_3d.png", f"{stem}_pattern.png"]
    )
    assert "total tube length" in capsys.readouterr().out


def test_gallery_is_not_empty():
    assert len(GALLERY) >= 10


# --- all or nothing, in-process (failures injected) ----------------------------------------
def test_failed_publish_restores_the_previous_build(design, tmp_path, monkeypatch, capsys):
    out = tmp_path / "o"
    assert main_in_process("build", design, "-o", out, "--formats", "dxf,svg") == 0
    before = {p.name: p.read_bytes() for p in out.iterdir()}
    (out / "keep.txt").write_text("user file")
    real_replace = os.replace
    calls = []

    def failing_replace(src, dst):
        calls.append((src, dst))
        if len(calls) == 4:  # after arm.dxf was swapped in, while swapping arm.svg
            raise PermissionError(13, "Permission denied", str(dst))
        return real_replace(src, dst)

    monkeypatch.setattr(os, "replace", failing_replace)
    assert main_in_process("build", design, "-o", out, "--formats", "dxf,svg") == 1
    monkeypatch.setattr(os, "replace", real_replace)
    err = capsys.readouterr().err
    assert "Permission denied" in err and "Traceback" not in err
    after = {p.name: p.read_bytes() for p in out.iterdir() if p.name != "keep.txt"}
    assert after == before
    assert (out / "keep.txt").read_text() == "user file"
    assert not list(tmp_path.rglob(".kinegami-build-*"))


def test_build_replaces_a_folder_in_the_way(design, tmp_path):
    out = tmp_path / "o"
    (out / "arm.dxf").mkdir(parents=True)
    assert main_in_process("build", design, "-o", out, "--formats", "dxf") == 0
    assert (out / "arm.dxf").is_file()


def test_exporter_errors_name_the_design_and_format(design, tmp_path, monkeypatch, capsys):
    from kinegami.errors import InvalidParameterError
    from kinegami.export import registry

    def refuse(*args, **kwargs):
        raise InvalidParameterError("needs 761 A4 pages, more than max_pages=200")

    monkeypatch.setattr(registry, "export", refuse)
    assert main_in_process("build", design, "-o", tmp_path / "o", "--formats", "pdf") == 1
    err = capsys.readouterr().err.strip()
    assert "arm.json: pdf export: needs 761 A4 pages" in err
    assert not (tmp_path / "o").exists()


def test_pattern_errors_are_design_errors(design, tmp_path, monkeypatch, capsys):
    from kinegami.chain import KinematicChain
    from kinegami.errors import InvalidParameterError

    def broken(self, twistPortion=0.2):
        raise InvalidParameterError("bendingAngle too small to resolve")

    monkeypatch.setattr(KinematicChain, "creasePattern", broken)
    assert main_in_process("validate", design, "--build") == 1
    assert main_in_process("build", design, "-o", tmp_path / "o") == 1
    lines = capsys.readouterr().err.strip().splitlines()
    assert len(lines) == 2
    assert all("arm.json" in line and "bendingAngle too small" in line for line in lines)
    assert not (tmp_path / "o").exists()


def test_internal_errors_are_one_line(design, tmp_path, monkeypatch, capsys):
    from kinegami import cli

    def bug(*args, **kwargs):
        raise ZeroDivisionError("oops\nsecond line")

    monkeypatch.setattr(cli, "_summary", bug)
    assert main_in_process("build", design, "-o", tmp_path / "o") == 1
    err = capsys.readouterr().err
    assert err.count("\n") == 1
    assert "internal error" in err and "ZeroDivisionError: oops second line" in err
    assert not (tmp_path / "o").exists()


def test_sigterm_during_a_build_leaves_nothing(design, tmp_path, monkeypatch):
    import signal

    from kinegami.export import registry

    real = registry.export

    def killed(obj, path, **options):
        real(obj, path, **options)
        os.kill(os.getpid(), signal.SIGTERM)

    monkeypatch.setattr(registry, "export", killed)  # what every --formats writer calls
    previous = signal.getsignal(signal.SIGTERM)
    with pytest.raises(SystemExit) as info:
        main_in_process("build", design, "-o", tmp_path / "o", "--formats", "dxf")
    assert info.value.code == 128 + signal.SIGTERM
    assert sorted(p.name for p in tmp_path.iterdir()) == ["arm.json"]
    assert signal.getsignal(signal.SIGTERM) is previous


@pytest.mark.parametrize("name", [".", "..", ".hidden", "a/b", "tab\tname"])
def test_bad_output_names(design, tmp_path, name, capsys):
    assert main_in_process("build", design, "-o", tmp_path / "o", "--name", name) == 1
    assert "--name" in capsys.readouterr().err
    assert not (tmp_path / "o").exists()


def test_control_characters_in_the_design_name_are_escaped(tmp_path, capsys):
    path = write(tmp_path / "n.json", dict(DESIGN, name="a\nb\x1b[31mRED"))
    assert main_in_process("build", path, "-o", tmp_path / "o", "--formats", "dxf") == 0
    out = capsys.readouterr().out
    assert "\x1b" not in out
    assert out.splitlines()[0].startswith("a\\nb\\x1b[31mRED")


def test_formats_all(design, tmp_path):
    """Every registered format builds (the README's --formats all)."""
    from kinegami.cli import output_formats

    assert main_in_process("build", design, "-o", tmp_path / "o", "--formats", "all") == 0
    names = sorted(p.name for p in (tmp_path / "o").iterdir())
    assert names == sorted(
        ["arm.dxf", "arm.svg", "arm_3d.png", "arm_pattern.png", "arm.fold", "arm.pdf",
         "arm.stl", "arm.obj", "arm.urdf", "arm_meshes", "arm_guide.pdf"]
    )  # fmt: skip
    assert set(output_formats()) == {"dxf", "svg", "png", "fold", "pdf", "stl", "obj", "urdf",
                                     "guide"}  # fmt: skip


def test_every_registered_suffix_is_a_build_format(design, tmp_path):
    """build --formats takes each format of the exporter registry by its suffix's name."""
    from kinegami.export import known_formats

    for suffix in known_formats():
        out = tmp_path / suffix.lstrip(".")
        assert main_in_process("build", design, "-o", out, "--formats", suffix.lstrip(".")) == 0
        assert (out / f"arm{suffix}").is_file()


def test_missing_exporter_library_is_one_line(design, tmp_path, monkeypatch, capsys):
    """ExporterUnavailableError: one line naming the extra to install, exit 1, no files."""
    import sys

    monkeypatch.setitem(sys.modules, "matplotlib.backends.backend_pdf", None)
    assert main_in_process("build", design, "-o", tmp_path / "o", "--formats", "dxf,pdf") == 1
    err = capsys.readouterr().err
    assert len(err.strip().splitlines()) == 1
    assert "pdf export" in err and "pip install 'kinegami[pdf]'" in err
    assert "internal error" not in err and "Traceback" not in err
    assert not (tmp_path / "o").exists()


def test_a_build_never_replaces_a_folder_of_the_user_with_a_file(design, tmp_path):
    """docs/cli.md: files the build does not write are never touched; a folder with the name
    of an output file is the user's, so the build stops in one line and writes nothing."""
    out = tmp_path / "o"
    (out / "arm.dxf" / "sub").mkdir(parents=True)
    (out / "arm.dxf" / "sub" / "data.txt").write_text("mine")
    (out / "arm.svg").write_text("earlier")
    result = run("build", design, "-o", out, "--formats", "dxf,svg")
    assert_clean_failure(result, "arm.dxf", "is a folder", "move or rename")
    assert (out / "arm.dxf" / "sub" / "data.txt").read_text() == "mine"
    assert (out / "arm.svg").read_text() == "earlier"
    assert sorted(p.name for p in out.iterdir()) == ["arm.dxf", "arm.svg"]
