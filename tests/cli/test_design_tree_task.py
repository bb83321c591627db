"""``kinegami new --task --tree`` and ``kinegami design`` of a tree task (issue 32), run as
subprocesses: the starter tree task (two three-joint fingers, two grasps) designs a tree whose
design file carries its task and whose every grasp the loaded file reaches (its report's states
set on a copy, the tips on the targets; kinegami.reach.solve of every grasp); the tree's build,
report and picture; ``build``, ``validate``, ``compact`` and the editor read the design file; an
infeasible tree task exits 3 at once writing nothing; tree task errors are one line, exit 1.

The design takes about 20 s on the 2-core machine: it is made once, for the module."""

from __future__ import annotations

import copy
import json
import time
import warnings

import numpy as np
import pytest

from kinegami import KinematicTree
from kinegami.design import load_design_with_info
from kinegami.design.task import read_task, starter_task
from kinegami.reach import solve

from .helpers import assert_clean_failure, run, write

#: Absolute tolerance of a tip on its target, in the task's units (mm; r = 10 mm).
AT = 1e-9


@pytest.fixture(scope="module")
def designed(tmp_path_factory):
    """The starter tree task written by ``kinegami new --task --tree`` and designed into out/;
    also the seconds the design took."""
    folder = tmp_path_factory.mktemp("tree_task")
    made = run("new", "--task", "--tree", folder / "hand.json")
    assert made.returncode == 0, made.stderr
    start = time.perf_counter()
    result = run("design", folder / "hand.json", "-o", folder / "out")
    print(f"kinegami design of the starter tree task: {time.perf_counter() - start:.1f} s")
    assert result.returncode == 0, result.stderr
    return folder, made, result


def test_new_task_tree_writes_the_starter_tree_task(designed, tmp_path):
    folder, made, _ = designed
    assert "tree task" in made.stdout and "kinegami design" in made.stdout
    assert json.loads((folder / "hand.json").read_text()) == starter_task(tree=True)
    assert_clean_failure(run("new", "--tree", tmp_path / "t.json"), "--tree", "--task")
    assert not (tmp_path / "t.json").exists()


def test_design_writes_the_tree_its_build_and_its_report(designed):
    folder, _, result = designed
    out = folder / "out"
    names = {p.name for p in out.iterdir()}
    assert {"hand.json", "hand_task.txt", "hand_task.json", "hand_task.png", "hand_3d.png",
            "hand_sheet_0.dxf", "hand_sheet_1.dxf", "hand_sheet_0.svg", "hand_sheet_1.svg",
            "hand_sheet_0_pattern.png", "hand_sheet_1_pattern.png"} <= names  # fmt: skip
    assert not any(name.startswith("hand_sheet_2") for name in names)  # one sheet per leaf
    assert (out / "hand_task.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    text = (out / "hand_task.txt").read_text()
    assert text.splitlines() == result.stdout.splitlines()[: len(text.splitlines())]
    for words in ("a tree of 2 leaves", "leaf 0: joints RRR", "grasp 1: reached",
                  "leaf 1: target (right 1) [40, -30, 130]", "sheets: 2 (one per leaf)"):
        assert words in result.stdout, words
    report = json.loads((out / "hand_task.json").read_text())
    assert report["format"] == "kinegami-task-report" and report["structure"] == "tree"
    assert [leaf["joints"] for leaf in report["leaves"]] == ["RRR", "RRR"]
    assert len(report["grasps"]) == 2
    for grasp in report["grasps"]:
        assert grasp["ok"] and grasp["clearance"] >= 0.0
        assert [row["leaf"] for row in grasp["leaves"]] == [0, 1]
        assert all(row["position_error"] <= AT for row in grasp["leaves"])


def test_the_design_file_is_a_tree_that_reaches_every_grasp(designed):
    folder, _, _ = designed
    tree, info = load_design_with_info(folder / "out" / "hand.json")
    task = read_task(folder / "hand.json")
    assert isinstance(tree, KinematicTree) and info.structure == "tree"
    assert info.task == task.document  # the design carries its task
    report = json.loads((folder / "out" / "hand_task.json").read_text())
    tips = [leaf["tip"] for leaf in report["leaves"]]
    leaves = [k for k, children in enumerate(tree.Children) if not children]
    assert sorted(tips) == leaves
    for k, grasp in enumerate(report["grasps"]):
        posed = copy.copy(tree)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no ClearanceWarning, no PlacementWarning
            assert posed.setJointStates(grasp["states"]) is True
        assert posed.clearance().ok
        for tip, leaf in zip(tips, task.targets, strict=True):
            place = posed.Joints[tip].DistalDubinsFrame().A[:3, 3]
            np.testing.assert_allclose(place, leaf[k].position, rtol=0, atol=AT)
        answer = solve(tree, {tip: leaf[k] for tip, leaf in zip(tips, task.targets, strict=True)},
                       q0=grasp["states"])  # fmt: skip
        assert answer.ok, answer.reason


def test_build_and_validate_read_the_design_file_as_the_same_tree(designed):
    folder, _, _ = designed
    out = folder / "out"
    checked = run("validate", "--build", out / "hand.json")
    assert checked.returncode == 0, checked.stderr
    assert "builds a tree of 9 joints, 2 sheets" in checked.stdout
    built = run("build", out / "hand.json", "-o", folder / "built", "--formats", "fold")
    assert built.returncode == 0, built.stderr
    for k in range(2):  # the same sheets as kinegami design wrote
        again = json.loads((folder / "built" / f"hand_sheet_{k}.fold").read_text())
        first = json.loads((out / f"hand_sheet_{k}.fold").read_text())
        assert again == first


def test_compact_and_the_editor_read_a_tree_with_its_tree_task(designed):
    folder, _, _ = designed
    result = run("compact", folder / "out" / "hand.json", "-o", folder / "compact.json",
                 "--time-limit", "1")  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert "task kept" in result.stdout and "Traceback" not in result.stderr
    _, info = load_design_with_info(folder / "compact.json")
    assert info.task == starter_task(tree=True)  # written as it was
    pytest.importorskip("viser")
    from kinegami.editor import EditorModel
    from kinegami.editor.commands import Compact

    model = EditorModel.open(folder / "out" / "hand.json")
    assert model.is_tree and model.document.task == starter_task(tree=True)
    assert Compact().prepared(model.document).task == starter_task(tree=True)  # kept


def test_an_infeasible_tree_task_exits_3_at_once_writing_nothing(tmp_path):
    task = starter_task(tree=True)
    task["targets"][1][0] = {"position": [0, 0, 5000]}  # beyond maxTubeLength (1000 mm)
    write(tmp_path / "far.json", task)
    start = time.perf_counter()
    result = run("design", tmp_path / "far.json", "-o", tmp_path / "out")
    assert time.perf_counter() - start < 15.0  # the certificate; the rest is the start-up
    assert result.returncode == 3, result
    assert "Traceback" not in result.stderr
    assert "infeasible" in result.stderr and "leaf 1" in result.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("change", "words"),
    [
        ({"targets": starter_task(tree=True)["targets"][:1]}, ("targets:", "per leaf")),
        ({"targets": [starter_task(tree=True)["targets"][0],
                      starter_task(tree=True)["targets"][1][:1]]},
         ("targets[1]:", "same number of targets")),
        ({"joints": ["RRR", 3]}, ("joints[1]:", "joint string")),
        ({"path": True}, ("path:", "for chains")),
    ],
)  # fmt: skip
def test_tree_task_errors_are_one_line_exit_1_writing_nothing(tmp_path, change, words):
    write(tmp_path / "bad.json", {**starter_task(tree=True), **change})
    result = run("design", tmp_path / "bad.json", "-o", tmp_path / "out")
    assert_clean_failure(result, "bad.json", *words)
    assert not (tmp_path / "out").exists()
