"""Compaction of a tree keeps its tree task (issue 32): ``compact(tree, targets=...)`` with one
target list per leaf, grasp k every leaf's k-th target at once.

The tree is the starter tree task's design (two three-joint fingers, r = 10 mm):
tests/data/task_fingers.json, what ``kinegami design`` wrote for the task of ``kinegami new
--task --tree`` (the editor's tree-task tests use it too). Every grasp of a compacted tree
is checked as a user would: a fresh kinegami.reach.solve of the grasp, its states set on a
fresh copy (no warning), every leaf's tip on its target to 1e-9 r, and the tree's own
clearance report."""

from __future__ import annotations

import concurrent.futures
import copy
import time
import warnings
from pathlib import Path

import numpy as np
import pytest

from kinegami import KinematicTree
from kinegami.design import load_design_with_info
from kinegami.design.task import task_from_dict
from kinegami.errors import CompactionError, InvalidParameterError, InvalidTypeError
from kinegami.optimize import compact, compact_for_task, tube_length
from kinegami.reach import solve

DATA = Path(__file__).resolve().parents[1] / "data"
TREE_FILE = DATA / "task_fingers.json"


def leaf_tips(tree: KinematicTree) -> list[int]:
    return [k for k, children in enumerate(tree.Children) if not children]


@pytest.fixture(scope="module")
def designed():
    """(tree, its task's targets: one list per leaf, the task) of the fixture file."""
    tree, info = load_design_with_info(TREE_FILE)
    task = task_from_dict(info.task)
    return tree, [list(leaf) for leaf in task.targets], task


@pytest.fixture(scope="module")
def compacted(designed):
    """The fixture tree compacted with its task, the answers, and the seconds it took."""
    tree, targets, _ = designed
    start = time.perf_counter()
    with concurrent.futures.ProcessPoolExecutor(2) as pool:
        shorter, answers = compact_for_task(tree, targets, executor=pool, starts=2)
    seconds = time.perf_counter() - start
    print(f"tree tube {tube_length(tree):.4f} -> {tube_length(shorter):.4f} mm in {seconds:.1f} s")
    return shorter, answers, seconds


def check_grasps(tree: KinematicTree, targets: list, margin: float = 0.0) -> None:
    """Every grasp solved afresh from the home states (seeds 0 to 3), its states set on a fresh
    copy without a warning, every tip on its target to 1e-9 r, the tree's clearance clear."""
    tips = leaf_tips(tree)
    assert len(tips) == len(targets)
    for k in range(len(targets[0])):
        mapping = {tip: leaf[k] for tip, leaf in zip(tips, targets, strict=True)}
        answers = [solve(tree, mapping, seed=seed, margin=margin) for seed in range(4)]
        answer = next((a for a in answers if a.ok), answers[0])
        assert answer.ok, f"grasp {k}: {answer.reason}"
        posed = copy.copy(tree)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no ClearanceWarning, no PlacementWarning
            assert posed.setJointStates(list(answer.states)) is True
        report = posed.clearance()
        assert report.ok, f"grasp {k}: {report}"
        for tip, leaf in zip(tips, targets, strict=True):
            where = posed.Joints[tip].DistalDubinsFrame().A[:3, 3]
            np.testing.assert_allclose(where, leaf[k].position, rtol=0, atol=1e-9 * tree.r)


def test_the_fixture_tree_reaches_its_task(designed):
    tree, targets, _ = designed
    check_grasps(tree, targets)


def test_compaction_with_a_tree_task_shortens_and_keeps_every_grasp(designed, compacted):
    tree, targets, _ = designed
    shorter, answers, seconds = compacted
    assert isinstance(shorter, KinematicTree)
    assert tube_length(shorter) < tube_length(tree)
    assert len(answers) == len(targets[0]) and all(a.ok for a in answers)
    check_grasps(shorter, targets)
    # the same joints, the root and every leaf tip where they were (their frames on their
    # leaves' last movable joints do not change)
    assert [type(j) for j in shorter.Joints if j.has_body] == \
        [type(j) for j in tree.Joints if j.has_body]  # fmt: skip
    np.testing.assert_allclose(shorter.Joints[0].pose_matrix, tree.Joints[0].pose_matrix,
                               rtol=0, atol=1e-12 * tree.r)  # fmt: skip
    for old, new in zip(leaf_tips(tree), leaf_tips(shorter), strict=True):
        np.testing.assert_allclose(shorter.Joints[new].pose_matrix, tree.Joints[old].pose_matrix,
                                   rtol=0, atol=1e-12 * tree.r)  # fmt: skip
    assert seconds < 30.0


def movable(design) -> list[int]:
    return [k for k, joint in enumerate(design.Joints) if joint.stateRange() != (0.0, 0.0)]


def tip_errors(design, states: np.ndarray, targets: list, k: int) -> list[float]:
    """Each leaf tip's distance from its k-th target with the movable joints at ``states``
    (in order), on a copy of ``design``."""
    q = np.zeros(len(design.Joints))
    q[movable(design)] = states
    posed = copy.copy(design)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")  # the plain result may collide at these states
        posed.setJointStates(list(q))
    return [float(np.linalg.norm(posed.Joints[tip].DistalDubinsFrame().A[:3, 3] - leaf[k].position))
            for tip, leaf in zip(leaf_tips(design), targets, strict=True)]  # fmt: skip


def test_plain_compaction_moves_a_tip_off_its_target_the_task_does_not(designed, compacted):
    """Without the task, compaction slides the leaf tips along their axes: at the grasps'
    states the tips miss their targets. With it, every tip is on its target there."""
    tree, targets, _ = designed
    shorter, answers, _ = compacted
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        plain = compact(tree, executor=pool, starts=1)  # its first start: about 4 s
    moved = max(float(np.abs(plain.Joints[new].pose_matrix - tree.Joints[old].pose_matrix).max())
                for old, new in zip(leaf_tips(tree), leaf_tips(plain), strict=True))  # fmt: skip
    assert moved > 0.1 * tree.r
    missed = 0.0
    for k, answer in enumerate(answers):
        states = np.asarray(answer.states)[movable(shorter)]
        assert max(tip_errors(shorter, states, targets, k)) <= 1e-9 * tree.r
        missed = max(missed, *tip_errors(plain, states, targets, k))
    assert missed > 0.1 * tree.r


def test_no_shorter_tree_in_the_time_allowed_returns_the_tree_itself(designed):
    """A search cut short before it finds anything: the tree itself, unchanged, with its
    grasps' answers."""
    tree, targets, _ = designed
    before = [j.pose_matrix.copy() for j in tree.Joints]
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        same, answers = compact_for_task(tree, targets, executor=pool, time_limit=1e-9,
                                         starts=1)  # fmt: skip
    assert same is tree
    assert [a.ok for a in answers] == [True] * len(targets[0])
    for old, joint in zip(before, tree.Joints, strict=True):
        np.testing.assert_array_equal(old, joint.pose_matrix)


def test_a_tree_task_by_tip_index_and_bad_tree_tasks(designed):
    tree, targets, _ = designed
    tips = leaf_tips(tree)
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        same, _ = compact_for_task(tree, dict(zip(tips, targets, strict=True)), executor=pool,
                                   time_limit=1e-9, starts=1)  # fmt: skip
    assert same is tree
    with pytest.raises(InvalidParameterError, match="one list of targets per leaf"):
        compact(tree, targets=targets[:1])
    with pytest.raises(InvalidParameterError, match="same number"):
        compact(tree, targets=[targets[0], targets[1][:1]])
    with pytest.raises(InvalidParameterError, match="every leaf tip"):
        compact(tree, targets={tips[0]: targets[0], 99: targets[1]})
    with pytest.raises(InvalidTypeError, match=r"targets\[1\]"):
        compact(tree, targets=[targets[0], "far"])
    with pytest.raises(CompactionError, match="does not reach its task"):
        far = [[(0.0, 0.0, 5000.0)] * 2, targets[1]]
        compact(tree, targets=far)
    # a keep-out box around leaf 1's first target: grasp 0 is not reached outside it
    point = targets[1][0].position
    box = {"min": (point - 2 * tree.r).tolist(), "max": (point + 2 * tree.r).tolist()}
    with pytest.raises(CompactionError, match="grasp 0: it enters keep-out box 0"):
        compact(tree, targets=targets, keep_out=[box])


def test_kinegami_compact_keeps_a_tree_task(tmp_path, capsys):
    """``kinegami compact`` of a tree design file that carries its tree task: exit 0, the task
    kept (no note that it is not checked), the written tree reaches every grasp."""
    from kinegami.cli import main

    out = tmp_path / "compact.json"
    code = main(["compact", str(TREE_FILE), "-o", str(out), "--time-limit", "1"])
    captured = capsys.readouterr()
    assert code == 0, captured.err
    assert "task kept" in captured.out
    assert "not checked" not in captured.err and "Traceback" not in captured.err
    tree, info = load_design_with_info(out)
    original, before = load_design_with_info(TREE_FILE)
    assert info.task == before.task
    assert tube_length(tree) <= tube_length(original)
    check_grasps(tree, [list(leaf) for leaf in task_from_dict(info.task).targets])


def test_kinegami_compact_of_a_tree_that_misses_its_task_exits_3(tmp_path, capsys):
    import json

    from kinegami.cli import main

    document = json.loads(TREE_FILE.read_text())
    document["task"]["targets"][0][0]["position"] = [0, 0, 900]
    moved = tmp_path / "moved.json"
    moved.write_text(json.dumps(document))
    code = main(["compact", str(moved), "-o", str(tmp_path / "out.json")])
    captured = capsys.readouterr()
    assert code == 3
    assert "does not reach its task before compaction: grasp 0" in captured.err
    assert not (tmp_path / "out.json").exists()
