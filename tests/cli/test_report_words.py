"""The reports word themselves: what ``kinegami check`` and ``kinegami build`` print of a
clearance or a sweep is, line for line, what :meth:`ClearanceReport.summary` and
:meth:`SweepReport.summary` return for the same design, and the editor's clearance panel and
motion check show :meth:`ClearanceReport.markdown` and :meth:`SweepReport.markdown` of the
same reports. Should either front end word a report on its own again, these fail."""

from __future__ import annotations

import contextlib
import io
import math
import warnings
from pathlib import Path

import numpy as np
import pytest

from kinegami.chain.joints import RevoluteJoint
from kinegami.clearance import clearance_report, sweep
from kinegami.design import load_design, load_design_with_info, read_design
from kinegami.design.reader import origin_of
from kinegami.errors import ClearanceWarning

from .helpers import EXAMPLE1, ROOT, fold_back, main_in_process, write

DOUBLING_BACK = ROOT / "examples" / "designs" / "doubling_back.json"  # mm, named joints
PUMA = ROOT / "examples" / "designs" / "puma.json"  # 27 pairs closer than a 50 mm margin
LISTED_PAIRS = 20  # kinegami.cli.LISTED_PAIRS: what check lists in words


def _check(*args) -> tuple[int, list[str]]:
    out = io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(io.StringIO()):
        code = main_in_process("check", *args)
    return code, out.getvalue().splitlines()


def _library(path: Path, margin: float | None = None):
    """The design's chain, info, joint names and clearance report, from the library."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        chain, info = load_design_with_info(path)
    names = origin_of(chain).names
    return chain, info, names, clearance_report(chain, names=names, margin=margin)


def _title(info, path: Path) -> str:
    return f"{info.name} ({path})" if info.name else str(path)


@pytest.fixture
def colliding_moving(tmp_path) -> Path:
    """The gallery's "Doubling back" at states where it self-intersects (its joints move)."""
    document = read_design(DOUBLING_BACK)
    chain = load_design(DOUBLING_BACK)
    ranges = np.array([joint.stateRange() for joint in chain.Joints])
    rng = np.random.default_rng(1)
    for _ in range(200):
        states = ranges[:, 0] + (ranges[:, 1] - ranges[:, 0]) * rng.random(len(ranges))
        if not chain.clearance(states).ok:
            break
    else:  # pragma: no cover - the design collides in about a fifth of its configurations
        raise AssertionError("no colliding configuration found")
    document["states"] = [
        math.degrees(s) if isinstance(joint, RevoluteJoint) else float(s)
        for s, joint in zip(states, chain.Joints, strict=True)
    ]  # the design's angleUnits are degrees
    return write(tmp_path / "doubling_back_colliding.json", document)


@pytest.mark.parametrize(
    "design, samples, seed, anchors",
    [
        (EXAMPLE1, 200, 1, ["clear at its states", "mm (", " cm)", " deg", "free intervals ("]),
        (DOUBLING_BACK, 150, 3, ["clear at its states", "'out: about z'", "its whole range"]),
    ],
    ids=["example1-cm", "doubling-back-mm"],
)
def test_check_motion_prints_the_summaries(design, samples, seed, anchors):
    code, printed = _check(design, "--motion", samples, "--seed", seed)
    chain, info, names, report = _library(design)
    motion = sweep(chain, samples, seed, names=names)
    expected = report.summary(info.units, title=_title(info, design))
    expected += motion.summary(chain, info.units, names=names, seed=seed)
    assert code == 0 and printed == expected
    assert printed[2].startswith(f"  motion: {motion.colliding} of {samples} sampled")
    for anchor in anchors:  # the summaries worded what they are meant to
        assert anchor in "\n".join(printed), anchor


def test_check_of_a_design_that_self_intersects(colliding_moving):
    code, printed = _check(colliding_moving, "--motion", 100)
    chain, info, names, report = _library(colliding_moving)
    motion = sweep(chain, 100, 0, names=names)
    expected = report.summary(info.units, title=_title(info, colliding_moving))
    expected += motion.summary(chain, info.units, names=names, seed=0)
    assert code == 3 and printed == expected
    assert "self-intersects at its states" in printed[0]
    assert printed[2] == "  parts closer than the margin (closest first):"
    assert len(printed) == 3 + len(report.pairs) + len(motion.summary(chain, info.units))
    assert printed[-1] == "  free intervals: none (the design self-intersects at its states)"


def test_check_of_a_chain_without_moving_joints(tmp_path):
    path = write(tmp_path / "fold_back.json", fold_back(1.9))
    code, printed = _check(path, "--motion", 20)
    chain, info, names, report = _library(path)
    expected = report.summary(info.units, title=_title(info, path))
    expected += sweep(chain, 20, 0, names=names).summary(chain, info.units, names=names)
    assert code == 3 and printed == expected
    pairs = printed[3 : 3 + len(report.pairs)]
    assert pairs and all(": overlap " in line and " mm" in line for line in pairs)
    assert printed[-1] == "  free intervals: none (no joint moves)"


def test_check_lists_the_first_pairs_and_says_json_lists_all():
    code, printed = _check(PUMA, "--margin", 50)
    _, info, _, report = _library(PUMA, margin=50.0)
    assert len(report.pairs) > LISTED_PAIRS  # else this tests nothing
    expected = report.summary(info.units, title=_title(info, PUMA), listed=LISTED_PAIRS)
    more = len(report.pairs) - LISTED_PAIRS
    assert expected[-1] == f"    ... and {more} more"
    assert code == 3 and printed == [*expected[:-1], f"{expected[-1]} (--json lists them all)"]
    assert "not clear at its states" in printed[0] and "closer than the margin 50 mm" in printed[0]


@pytest.mark.parametrize("design", [EXAMPLE1, "fold_back"])
def test_build_prints_the_verdict_line_of_the_summary(design, tmp_path):
    if design == "fold_back":
        design = write(tmp_path / "fold_back.json", fold_back(1.9))
    out, err = io.StringIO(), io.StringIO()
    with contextlib.redirect_stdout(out), contextlib.redirect_stderr(err):
        code = main_in_process("build", design, "-o", tmp_path / "out", "--formats", "svg")
    _, info, _, report = _library(design)
    (line,) = report.summary(info.units, listed=0)
    assert code == 0 and line in out.getvalue().splitlines()
    assert line.startswith("  clearance: ")


def test_the_editor_shows_the_verdict_check_prints(colliding_moving):
    """The editor's clearance panel and motion check word the reports check prints."""
    pytest.importorskip("viser")
    from kinegami.editor.jobs import LISTED, LISTED_JOINTS, motion_check
    from kinegami.editor.server import EditorServer

    _, printed = _check(colliding_moving, "--motion", 100, "--seed", 2)
    chain, info, names, report = _library(colliding_moving)
    server = EditorServer(colliding_moving, port=0, autosave=False)
    try:
        view = server.new_view(server.server)
        panel = view._clearance.content
        view.close()
    finally:
        server.stop()
    assert panel == report.markdown(info.units, listed=8)
    first, blank, *pairs = panel.splitlines()
    assert first == f"**{printed[1].removeprefix('  clearance: ')}**" and blank == ""
    assert pairs == [f"- {pair}" for pair in report.pairs[:8]]

    text = motion_check(chain, names, 100, 2)
    motion = sweep(chain, 100, 2, names=names)
    assert text == motion.markdown(chain, names=names, seed=2, listed=LISTED,
                                   joints_listed=LISTED_JOINTS)  # fmt: skip
    (line,) = [line for line in printed if line.startswith("  motion: ")]
    assert line.startswith(f"  motion: {motion.colliding} of 100 sampled configurations")
    assert text.startswith(f"**Motion check:** {motion.colliding} of 100 random configurations")
