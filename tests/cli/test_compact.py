"""``kinegami compact``, run as subprocesses: the compacted design loads, keeps every joint's axis
line and is clear; the summary; one-line errors (exit 1) that write nothing; OUT = DESIGN only
with --force; CompactionError (exit 3) and Ctrl-C (exit 130) write nothing."""

from __future__ import annotations

import json
import shutil

import numpy as np
import pytest

from kinegami import ClearanceWarning, cli
from kinegami.chain.joints import Waypoint
from kinegami.design import load_design, load_design_with_info
from kinegami.optimize import CompactionError, tube_length

from .helpers import ROOT, assert_clean_failure, fold_back, run, write

EXAMPLE1 = ROOT / "examples" / "designs" / "example1.json"  # 6 joints and 3 waypoints, cm
#: Seconds each start of the search may take in these tests (the search itself is not tested).
TIME_LIMIT = "1"


def axis_lines(chain):
    """(point, direction) of every joint's axis of motion (z), waypoints left out."""
    return [
        (joint.pose_matrix[:3, 3], joint.pose_matrix[:3, 2])
        for joint in chain.Joints
        if type(joint) is not Waypoint
    ]


def assert_same_axis_lines(a, b, tol: float) -> None:
    lines_a, lines_b = axis_lines(a), axis_lines(b)
    assert len(lines_a) == len(lines_b)
    for (p, z), (q, w) in zip(lines_a, lines_b, strict=True):
        np.testing.assert_allclose(w, z, rtol=0, atol=tol)
        offset = q - p
        np.testing.assert_allclose(offset - (offset @ z) * z, 0.0, rtol=0, atol=tol)


@pytest.fixture(scope="module")
def compacted(tmp_path_factory):
    """Example 1 compacted into a new folder: (result, the written file)."""
    out = tmp_path_factory.mktemp("compact") / "new" / "example1_compact.json"
    result = run("compact", EXAMPLE1, "-o", out, "--seed", "3", "--time-limit", TIME_LIMIT)
    return result, out


def test_compact_writes_a_clear_design_with_the_same_axis_lines(compacted):
    result, out = compacted
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""
    before, info = load_design_with_info(EXAMPLE1)
    after, out_info = load_design_with_info(out)
    assert json.loads(out.read_text())["version"] == 1
    assert_same_axis_lines(before, after, tol=1e-9 * before.r)
    assert [type(j).__name__ for j in after.Joints if type(j) is not Waypoint] == [
        type(j).__name__ for j in before.Joints if type(j) is not Waypoint
    ]
    assert after.clearance().ok
    assert tube_length(after) <= tube_length(before) + 1e-9
    assert (out_info.name, out_info.units, out_info.twistPortion) == (
        info.name, info.units, info.twistPortion,
    )  # fmt: skip
    assert sorted(p.name for p in out.parent.iterdir()) == [out.name]  # no temporary file left


def test_compact_prints_before_and_after(compacted):
    result, out = compacted
    lines = result.stdout.splitlines()
    assert lines[0] == f"Example 1 ({EXAMPLE1}): compacted (seed 3, margin 0 mm (0 cm))"
    assert lines[1] == "  before:" and lines[6] == "  after:"
    before, after = load_design(EXAMPLE1), load_design(out)
    # lengths as `check` prints them: mm, then the design's cm
    assert lines[3] == f"    total tube length: {tube_length(before) * 10:.1f} mm " \
                       f"({tube_length(before):.2f} cm)"  # fmt: skip
    assert lines[8].startswith(f"    total tube length: {tube_length(after) * 10:.1f} mm ")
    assert lines[8].endswith("% shorter")
    for k in (4, 9):
        assert lines[k].startswith("    sheet: ") and "mm with the glue tab" in lines[k]
    for k in (5, 10):
        assert lines[k].startswith("    clearance: clear with margin 0 mm (0 cm): minimum ")
    assert lines[-1] == f"  written: {out}"


def test_a_colliding_design_is_compacted_clear_and_force_overwrites_it(tmp_path):
    design = write(tmp_path / "fold_back.json", fold_back(1.9))
    original = design.read_text()
    with pytest.warns(ClearanceWarning):
        assert not load_design(design).clearance().ok
    result = run("compact", design, "-o", design)  # without --force: refused
    assert_clean_failure(result, "is the design itself", "--force")
    assert design.read_text() == original
    result = run("compact", design, "-o", tmp_path / "." / "fold_back.json")  # the same file
    assert_clean_failure(result, "is the design itself")
    result = run("compact", design, "-o", design, "--force", "--time-limit", TIME_LIMIT)
    assert result.returncode == 0, result.stderr
    assert result.stderr == ""  # the summary says it self-intersects, no Python warning
    assert "self-intersects" in result.stdout.splitlines()[5]
    chain = load_design(design)
    assert chain.clearance().ok
    assert [p.name for p in tmp_path.iterdir()] == ["fold_back.json"]
    # the named tips keep their names
    assert '"name": "base"' in design.read_text() and '"name": "tool"' in design.read_text()


@pytest.mark.parametrize(
    ("options", "words"),
    [
        (["--time-limit", "0"], ["--time-limit", "> 0", "'0'"]),
        (["--time-limit", "nan"], ["--time-limit", "'nan'"]),
        (["--time-limit", "soon"], ["--time-limit", "'soon'"]),
        (["--seed", "-1"], ["--seed", "an integer >= 0", "-1"]),
    ],
)
def test_bad_options_are_one_line_and_write_nothing(tmp_path, options, words):
    out = tmp_path / "out.json"
    assert_clean_failure(run("compact", EXAMPLE1, "-o", out, *options), *words)
    assert list(tmp_path.iterdir()) == []


def test_a_malformed_design_is_one_line_and_writes_nothing(tmp_path):
    design = write(tmp_path / "bad.json", '{"format": "kinegami-design", "version": 1,')
    assert_clean_failure(run("compact", design, "-o", tmp_path / "out.json"), "bad.json",
                         "invalid JSON")  # fmt: skip
    broken = write(tmp_path / "broken.json", dict(fold_back(2.5), numSides=5))
    assert_clean_failure(run("compact", broken, "-o", tmp_path / "out.json"), "numSides")
    assert sorted(p.name for p in tmp_path.iterdir()) == ["bad.json", "broken.json"]


def test_an_output_that_cannot_be_written_is_one_line(tmp_path):
    (tmp_path / "folder.json").mkdir()
    write(tmp_path / "file.txt", "not a folder")
    for out, words in [
        (tmp_path / "out.txt", ["-o", "must end in .json"]),
        (tmp_path / "folder.json", ["-o", "is a folder"]),
        (tmp_path / "file.txt" / "out.json", ["-o", "file.txt", "is not a folder"]),
    ]:
        assert_clean_failure(run("compact", EXAMPLE1, "-o", out), *words)
    assert sorted(p.name for p in tmp_path.iterdir()) == ["file.txt", "folder.json"]
    assert (tmp_path / "file.txt").read_text() == "not a folder"


@pytest.fixture
def small_design(tmp_path):
    return write(tmp_path / "fold_back.json", fold_back(2.5))


def test_no_clear_design_found_is_exit_3_and_writes_nothing(small_design, monkeypatch, capsys):
    """The exit code and the line of a CompactionError (a design compact cannot clear is not
    cheap to make, so compact itself is replaced here)."""

    def fails(chain, **options):
        raise CompactionError("compact found no design that is clear of itself")

    monkeypatch.setattr("kinegami.optimize.compact", fails)
    out = small_design.parent / "out.json"
    assert cli.main(["compact", str(small_design), "-o", str(out)]) == cli.COMPACTION_FAILED == 3
    captured = capsys.readouterr()
    assert captured.out == ""
    assert captured.err == (f"kinegami compact: error: {small_design}: compact found no design "
                            "that is clear of itself\n")  # fmt: skip
    assert not out.exists()


def test_ctrl_c_during_the_search_writes_nothing(small_design, monkeypatch, capsys):
    def interrupted(chain, **options):
        raise KeyboardInterrupt

    monkeypatch.setattr("kinegami.optimize.compact", interrupted)
    out = small_design.parent / "out.json"
    shutil.copy(small_design, out)
    before = out.read_text()
    assert cli.main(["compact", str(small_design), "-o", str(out)]) == 130
    assert capsys.readouterr().err == "kinegami compact: interrupted\n"
    assert out.read_text() == before  # an existing OUT is left as it was
    assert sorted(p.name for p in small_design.parent.iterdir()) == ["fold_back.json", "out.json"]


def test_require_clearance_and_names_are_kept(tmp_path):
    design = write(tmp_path / "clear.json", dict(fold_back(2.5), requireClearance=True))
    out = tmp_path / "out.json"
    result = run("compact", design, "-o", out, "--seed", "1", "--time-limit", TIME_LIMIT)
    assert result.returncode == 0, result.stderr
    document = json.loads(out.read_text())
    assert document["requireClearance"] is True
    assert [entry.get("name") for entry in document["joints"]][::len(document["joints"]) - 1] \
        == ["base", "tool"]  # fmt: skip
    assert load_design(out).requireClearance is True
