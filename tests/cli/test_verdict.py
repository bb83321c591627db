"""One design, one verdict: ``kinegami build``'s summary, ``kinegami check``, the editor's
document and the library say the same thing of every gallery design (same ok, the same
minimum clearance printed the same way, the margin stated), with the design's margin or
``--margin``; and each distinct warning is said once per command."""

from __future__ import annotations

import contextlib
import io
import json
import warnings

import pytest
from gallery_designs import GALLERY

from kinegami.clearance import clearance_report
from kinegami.design import load_design, load_design_with_info
from kinegami.design.reader import origin_of
from kinegami.errors import ClearanceWarning

from .helpers import EXAMPLE1, ROOT, assert_clean_failure, main_in_process, run

PAPERS_HAND = ROOT / "tests" / "design" / "data" / "papers_hand.json"


def _quiet_load(path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        return load_design_with_info(path)


def _in_process(*args) -> tuple[int, str, str]:
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main_in_process(*args)
    return code, out.getvalue(), err.getvalue()


def _clearance_line(text: str) -> str:
    (line,) = [line for line in text.splitlines() if line.startswith("  clearance: ")]
    return line.removeprefix("  clearance: ")


def _library(path, margin=None) -> tuple:
    chain, info = _quiet_load(path)
    report = clearance_report(chain, names=origin_of(chain).names, margin=margin)
    return report, report.verdict(info.units)


@pytest.mark.parametrize("design", GALLERY, ids=[p.stem for p in GALLERY])
def test_build_check_the_editor_and_the_library_agree(design, tmp_path):
    from kinegami.editor import EditorModel

    report, verdict = _library(design)
    code, out, err = _in_process("check", design)
    assert code == (0 if report.ok else 3) and err == ""
    assert _clearance_line(out) == verdict
    code, out, err = _in_process("build", design, "-o", tmp_path, "--formats", "dxf")
    assert code == 0, err
    assert _clearance_line(out) == verdict
    assert "slid" not in out  # the tree judged is the tree built
    document = EditorModel.open(design).document
    assert document.clearance.ok == report.ok
    assert document.clearance.min_clearance == report.min_clearance
    assert document.verdict == verdict
    assert verdict.startswith("clear with margin 0 mm")  # every gallery design is clear


def test_a_margin_changes_every_verdict_alike(tmp_path):
    """Example 1's parts are 9.9 mm apart: with --margin 1.5 (cm) check and build both say
    they are closer than the margin, as the library and the editor do."""
    report, verdict = _library(EXAMPLE1, margin=1.5)
    assert not report.ok
    assert verdict.startswith("parts closer than the margin 15 mm (1.5 cm): minimum clearance "
                              "9.9 mm (0.99 cm), between")  # fmt: skip
    code, out, _ = _in_process("check", EXAMPLE1, "--margin", "1.5")
    assert code == 3 and _clearance_line(out) == verdict
    assert out.splitlines()[0].endswith(f"not clear at its states ({len(report.pairs)} pairs of "
                                        "parts closer than the margin 15 mm (1.5 cm))")  # fmt: skip
    code, out, err = _in_process("check", EXAMPLE1, "--margin", "1.5", "--json")
    data = json.loads(out)
    assert (data["ok"], data["margin"], data["verdict"]) == (False, 1.5, verdict)
    code, out, err = _in_process("build", EXAMPLE1, "-o", tmp_path, "--formats", "dxf",
                                 "--margin", "1.5")  # fmt: skip
    assert code == 0 and _clearance_line(out) == verdict
    assert err.count("warning:") == 1 and verdict in " ".join(err.split())
    # the editor judges a design with that margin the same way
    from kinegami.editor import EditorModel

    document = json.loads(EXAMPLE1.read_text())
    document.update(version=3, margin=1.5)
    design = tmp_path / "margin.json"
    design.write_text(json.dumps(document))
    assert EditorModel.open(design).document.verdict == verdict
    code, out, _ = _in_process("check", design)  # the file's margin, without --margin
    assert code == 3 and _clearance_line(out) == verdict


@pytest.mark.parametrize("text", ["-1", "nan", "inf", "wide", ""])
def test_a_bad_margin_is_a_one_line_error(text):
    result = run("check", EXAMPLE1, "--margin", text)
    assert_clean_failure(result, "--margin: must be a number >= 0")


def test_compact_with_a_margin_writes_it_into_the_design(tmp_path):
    out = tmp_path / "compact.json"
    result = run("compact", EXAMPLE1, "-o", out, "--margin", "0.5", "--seed", "1")
    assert result.returncode == 0, result.stderr
    assert "margin 5 mm (0.5 cm)" in result.stdout.splitlines()[0]
    document = json.loads(out.read_text())
    assert (document["version"], document["margin"]) == (3, 0.5)
    chain = load_design(out)
    assert chain.margin == 0.5
    assert chain.clearance().ok and chain.clearance().min_clearance >= 0.5


def test_a_build_that_slides_names_both_verdicts(tmp_path):
    """The paper's hand as published: build judges the tree it makes (the palm slid) and says
    what check and the editor say of the file as written."""
    report, verdict = _library(PAPERS_HAND)
    assert not report.ok
    code, out, _ = _in_process("check", PAPERS_HAND)
    assert code == 3 and _clearance_line(out) == verdict
    code, out, _ = _in_process("build", PAPERS_HAND, "-o", tmp_path, "--formats", "dxf")
    assert code == 0
    assert _clearance_line(out) == _library(ROOT / "examples" / "designs" / "hand.json")[1]
    assert f"judge the design file as written: {verdict}" in " ".join(out.split())


def test_each_warning_is_said_once(tmp_path):
    """A joint name with a character the font lacks: the sheets' pictures and the PDF draw it
    (the PDF of a tree drew it twice, each time warning); the command says so once."""
    document = json.loads((ROOT / "examples" / "designs" / "gripper.json").read_text())
    (tip,) = [j for j in document["joints"] if j.get("name") == "rightTip"]  # no one refers to it
    tip["name"] += "\N{RAISED HAND}"
    design = tmp_path / "glyph.json"
    design.write_text(json.dumps(document), encoding="utf-8")
    code, _, err = _in_process("build", design, "-o", tmp_path / "out", "--formats",
                               "dxf,pdf,png")  # fmt: skip
    assert code == 0
    lines = err.strip().splitlines()
    assert lines == [
        "kinegami build: warning: the font DejaVu Sans has no '\N{RAISED HAND}' (U+270B): the "
        "PDF and the pictures draw it as an empty box"
    ], lines


def test_the_editor_keeps_the_designs_margin_through_its_commands(tmp_path):
    """A design with a margin, edited: every command's chain keeps it (the rebuild that a new
    maxAnglePerElbow makes too), and the verdict states it; saving writes it back."""
    from kinegami.editor import EditorModel

    document = json.loads(EXAMPLE1.read_text())
    document.update(version=3, margin=0.05)
    design = tmp_path / "margin.json"
    design.write_text(json.dumps(document))
    model = EditorModel.open(design)
    assert model.chain.margin == 0.05
    assert model.set_options(maxAnglePerElbow=1.0).ok
    assert model.chain.margin == 0.05
    assert model.document.verdict.startswith("clear with margin 0.5 mm (0.05 cm): ")
    assert model.slide(4, 0.5).ok and model.chain.margin == 0.05
    assert model.save(tmp_path / "saved.json").ok
    saved = json.loads((tmp_path / "saved.json").read_text())
    assert (saved["version"], saved["margin"]) == (3, 0.05)
