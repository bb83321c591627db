"""A tree task in the editor (docs/editor.md, Tasks), without a browser: every grasp checked at
once (the k-th target of every leaf in one configuration of the whole tree), each target green
or red with its reason naming the leaf and target; a tree whose leaves are not as many as its
task's gets one reason; Design for task runs design_for for the tree task in the background as
one undoable step that keeps the task, and Cancel leaves the design bit for bit as it was.

tests/data/task_fingers.json is what ``kinegami design`` wrote for the starter tree task of
``kinegami new --task --tree`` (two three-joint fingers, each touching two points, seed 0): a
tree of 9 joints whose leaf tips are joints 4 (leaf 0, the left finger) and 8 (leaf 1)."""

from __future__ import annotations

import copy
import json
import shutil
import time
import warnings

import numpy as np
import pytest

pytest.importorskip("viser")

from kinegami import KinematicChain, KinematicTree  # noqa: E402
from kinegami.editor import Document, EditorModel  # noqa: E402
from kinegami.editor.commands import ReplaceDocument  # noqa: E402
from kinegami.editor.server import EditorServer  # noqa: E402
from kinegami.editor.tasks import check_targets, leaf_tips, task_goals  # noqa: E402
from kinegami.editor.view import MISSED_COLOR, REACHED_COLOR, UNCHECKED_COLOR  # noqa: E402
from kinegami.errors import InvalidParameterError  # noqa: E402
from kinegami.reach import solve  # noqa: E402

from .helpers import GRIPPER, ROOT, snapshot  # noqa: E402

FINGERS = ROOT / "tests" / "data" / "task_fingers.json"
TASK_ARM = ROOT / "tests" / "data" / "task_arm.json"
#: The leaf tips of task_fingers.json, in the task's leaf order (kinegami design's report).
FINGER_TIPS = (4, 8)
LABELS = ["leaf 0, target 0 'left 0'", "leaf 0, target 1 'left 1'",
          "leaf 1, target 0 'right 0'", "leaf 1, target 1 'right 1'"]  # fmt: skip
#: Beyond the right finger's reach (it reaches at most 257 mm from its first axis).
FAR = [1000.0, 0.0, 130.0]
#: Seconds for a background job (a spawned process imports numpy, scipy and kinegami first).
LIVE = 120.0


def _moved(task: dict, leaf: int, k: int, position) -> dict:
    task = copy.deepcopy(task)
    task["targets"][leaf][k]["position"] = list(position)
    return task


def _verify_reached(tree, checks, margin: float = 0.0) -> None:
    """Each reached grasp, independently: its states set on a copy of the tree (no warning) put
    every leaf's tip on its target (1e-9 r), and the tree's own clearance report is clear with
    ``margin`` and gives the check's clearance."""
    for c in checks:
        if not c.reached:
            continue
        posed = copy.copy(tree)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no ClearanceWarning, no PlacementWarning
            assert posed.setJointStates(list(c.states)) is True
        tip = posed.Joints[c.tip].DistalDubinsFrame().A[:3, 3]
        np.testing.assert_allclose(tip, c.position, rtol=0, atol=1e-9 * tree.r)
        report = posed.clearance(margin=margin)
        assert report.ok and report.min_clearance >= margin
        assert report.min_clearance == pytest.approx(c.clearance, abs=1e-9 * tree.r)


# --- the checks ---------------------------------------------------------------------------------
def test_every_grasp_is_reached_at_once_as_an_independent_check_confirms():
    document = Document.load(FINGERS)
    tree = document.chain
    assert isinstance(tree, KinematicTree) and leaf_tips(tree) == FINGER_TIPS
    checks = check_targets(tree, document.task, document.units)
    assert [c.label for c in checks] == LABELS  # leaf by leaf, as the targets are drawn
    assert [(c.leaf, c.index, c.tip) for c in checks] == [(0, 0, 4), (0, 1, 4), (1, 0, 8),
                                                          (1, 1, 8)]  # fmt: skip
    assert all(c.reached and c.reason == "" for c in checks)
    for k in range(2):  # one configuration per grasp, shared by both leaves
        assert checks[k].states == checks[2 + k].states
    _verify_reached(tree, checks)


def test_a_target_out_of_reach_is_red_and_its_grasp_partner_names_it():
    document = Document.load(FINGERS)
    task = _moved(document.task, 1, 1, FAR)
    checks = check_targets(document.chain, task, document.units)
    assert [c.reached for c in checks] == [True, False, True, False]
    assert checks[3].reason.startswith("beyond reach: the target is 977.412 from")
    assert checks[1].reason == ("its tip reaches it, but not at once with leaf 1, target 1 "
                                "'right 1', which is not reached")  # fmt: skip
    _verify_reached(document.chain, checks)  # grasp 0 still, every leaf at once


def test_targets_each_leaf_reaches_alone_but_not_at_once_give_the_grasps_reason():
    """Fingertips 10 mm apart on tubes of radius 10 mm: each finger reaches its point alone,
    and the two tips cannot be there at once without overlapping."""
    document = Document.load(FINGERS)
    task = _moved(_moved(document.task, 0, 1, [0, 0, 120]), 1, 1, [0, -10, 120])
    checks = check_targets(document.chain, task, document.units, attempts=1)
    assert [c.reached for c in checks] == [True, False, True, False]
    for c in (checks[1], checks[3]):
        assert c.reason == ("each leaf reaches its target 1 alone, but not every leaf at once: "
                            "every solution found passes through itself (joint 4, EndTip and "
                            "joint 8, EndTip)")  # fmt: skip
    for tip, position in zip(FINGER_TIPS, ([0, 0, 120], [0, -10, 120]), strict=True):
        assert solve(document.chain, {tip: position}, margin=0.0).ok


def test_a_chains_task_on_a_tree_of_one_leaf_is_checked_on_that_leaf():
    arm = Document.load(TASK_ARM)
    tree = KinematicTree.from_chain(arm.chain)  # the same joints, bit for bit
    as_chain, as_tree = (check_targets(d, arm.task, "mm") for d in (arm.chain, tree))
    assert [c.reached for c in as_tree] == [True, True, False]
    assert [(c.reason, c.states, c.tip) for c in as_tree] == \
        [(c.reason, c.states, c.tip) for c in as_chain]  # fmt: skip


def test_keep_out_boxes_and_the_margin_are_respected():
    document = Document.load(FINGERS)
    left_1 = np.array(document.task["targets"][0][1]["position"])
    boxed = copy.deepcopy(document.task)
    boxed["keepOut"] = [{"min": (left_1 - 1.0).tolist(), "max": (left_1 + 1.0).tolist()}]
    checks = check_targets(document.chain, boxed, document.units)
    assert [c.reached for c in checks] == [True, False, True, False]
    for c in (checks[1], checks[3]):
        assert c.reason.startswith("where every leaf is on its target 1 at once, the design "
                                   "enters keep-out box 0")  # fmt: skip
    # the designed configurations are clear by 0.0069 mm at grasp 1: a smaller margin holds,
    # a larger one does not (every solution the solver finds passes within it)
    small = dict(document.task, margin=0.005)
    checks = check_targets(document.chain, small, document.units, attempts=1)
    assert all(c.reached for c in checks)
    _verify_reached(document.chain, checks, margin=0.005)
    large = dict(document.task, margin=0.5)
    checks = check_targets(document.chain, large, document.units, attempts=1)
    assert not any(c.reached for c in checks)
    assert "passes through itself" in checks[0].reason


def test_a_tree_task_in_other_units_is_converted_to_the_designs():
    task = Document.load(FINGERS).task
    mm, cm = task_goals(task, "mm"), task_goals(task, "cm")
    np.testing.assert_allclose(cm.targets[1][0].position, mm.targets[1][0].position / 10.0)
    np.testing.assert_allclose(cm.targets[1][0].position, [6.0, -2.0, 12.0])


def test_a_tree_with_other_leaves_than_its_task_gets_one_reason():
    document = Document.load(FINGERS)
    three = copy.deepcopy(document.task)
    three["joints"].append("RRR")
    three["targets"].append([{"position": [0, 60, 120]}, {"position": [0, 50, 130]}])
    with pytest.raises(InvalidParameterError, match=r"^task: a task for 3 leaves \(joints "
                       r"\['RRR', 'RRR', 'RRR'\]\) is checked on a tree of as many leaves, and "
                       r"this tree has 2 \(tip joints 4, 8\)"):  # fmt: skip
        check_targets(document.chain, three, document.units)
    arm_task = Document.load(TASK_ARM).task  # a chain's task: one leaf
    with pytest.raises(InvalidParameterError, match=r"a task for 1 leaf \(joints 'RRR'\)"):
        check_targets(Document.load(GRIPPER).chain, arm_task, "mm")


def test_design_for_a_chain_task_on_a_tree_designs_a_chain():
    """The task decides the kind: task_arm.json's task on the gripper (a tree) designs an arm."""
    gripper = Document.load(GRIPPER)
    model = EditorModel(gripper.replaced(task=Document.load(TASK_ARM).task))
    before = model.document
    result = model.design_for_task()
    assert result.ok, result.reason
    designed = model.document
    assert isinstance(designed.chain, KinematicChain) and designed.task is before.task
    assert all(c.reached for c in check_targets(designed.chain, designed.task, "mm"))
    assert model.undo().ok and model.document is before


# --- the view -------------------------------------------------------------------------------------
@pytest.fixture
def server(tmp_path):
    path = tmp_path / FINGERS.name
    shutil.copyfile(FINGERS, path)
    server = EditorServer(path, port=0)
    yield server
    server.stop()


def _finished(job) -> str:
    assert job is not None
    assert job.finished.wait(LIVE), "the job did not finish"
    return job.outcome


def test_the_view_draws_every_leaf_target_green_or_red_and_lists_it_per_leaf(view):
    view.flush()
    document = view.model.document
    assert view.task_checked is document and view._design_button.visible
    assert view.target_colours() == (REACHED_COLOR,) * 4
    html = view._task_html.content
    assert "2 leaves, 2 grasps, joints RRR, RRR; leaf tips: joints 4, 8" in html
    assert "4 of 4 reached (2 of 2 grasps)" in html
    positions = view.task_positions()
    np.testing.assert_allclose(positions, [[-60, 20, 120], [-40, 30, 130], [60, -20, 120],
                                           [40, -30, 130]])  # fmt: skip
    labels = sorted(h.name for h in view._task_handles if h.name.endswith("_label"))
    assert labels == [f"/task/target{k}_label" for k in range(4)]
    # the right finger's second point out of reach: checked again after the change
    moved = document.replaced(task=_moved(document.task, 1, 1, FAR))
    assert view.act(lambda: view.model.apply(ReplaceDocument(moved))).ok
    view.flush()
    assert view.target_colours() == (REACHED_COLOR, MISSED_COLOR, REACHED_COLOR, MISSED_COLOR)
    html = view._task_html.content
    assert "2 of 4 reached (1 of 2 grasps)" in html
    for k, (leaf, grasp, state) in enumerate([(0, 0, "reached"), (0, 1, "missed"),
                                              (1, 0, "reached"), (1, 1, "missed")]):  # fmt: skip
        assert f'data-target="{k}" data-leaf="{leaf}" data-grasp="{grasp}" ' \
               f'data-state="{state}"' in html  # fmt: skip
    assert ("leaf 1, target 1 &#x27;right 1&#x27;: <b>not reached</b>: beyond reach: the "
            "target is 977.412") in html  # fmt: skip
    assert ("leaf 0, target 1 &#x27;left 1&#x27;: <b>not reached</b>: its tip reaches it, but "
            "not at once with leaf 1, target 1 &#x27;right 1&#x27;") in html  # fmt: skip


def test_a_leaf_count_the_task_does_not_have_is_one_reason_in_the_panel(view):
    three = copy.deepcopy(view.model.document.task)
    three["joints"].append("RRR")
    three["targets"].append([{"position": [0, 60, 120]}, {"position": [0, 50, 130]}])
    view.set_model(EditorModel(view.model.document.replaced(task=three)))
    view.flush()
    html = view._task_html.content
    assert "<b>The targets could not be checked:</b> task: a task for 3 leaves" in html
    assert "data-state" not in html  # one reason, no rows
    assert view.target_colours() == (UNCHECKED_COLOR,) * 6 and view._design_button.visible


def test_design_for_a_tree_task_is_one_undo_step_that_keeps_the_task(view):
    before = view.model.document
    job = view.design_for_task()
    assert view.job is job and view._job_cancel.visible and job.title == "Designing for the task"
    assert _finished(job) == "done", view.message
    assert job.total > 0 and job.done == job.total  # its progress was reported
    assert view.model.undo_labels == ("design for task",)
    designed = view.model.document
    assert designed is not before and isinstance(designed.chain, KinematicTree)
    assert designed.task is before.task and designed.units == "mm"
    assert json.loads(designed.design_text)["task"] == before.task  # saved with the design
    view.flush()
    assert view.task_checked is designed and view.target_colours() == (REACHED_COLOR,) * 4
    _verify_reached(designed.chain, view.task_checks)
    view.act(view.model.undo)
    assert view.model.document is before


def test_cancel_of_design_for_a_tree_task_leaves_the_design_bit_for_bit(view):
    document = view.model.document
    before = snapshot(document)
    job = view.design_for_task()
    deadline = time.monotonic() + LIVE
    while job.total == 0 and time.monotonic() < deadline:  # the search has begun
        time.sleep(0.02)
    assert job.total > 0
    assert view.cancel_job()
    assert _finished(job) == "cancelled"
    assert view.model.document is document and snapshot(document) == before
    assert not view.model.can_undo and not view.model.dirty
    assert "design for task cancelled: the design is unchanged" in view.message


def test_compact_of_a_tree_keeps_its_tree_task():
    """Compact of a tree with a tree task (docs/editor.md, Tasks) keeps the task: the shorter
    tree reaches every grasp exactly and clear (checked by the editor's own check, then each
    grasp's states set on a copy and the tips put on their targets to 1e-9 r), as one command
    that keeps the task; a chain's task on a tree is not given to compaction."""
    from kinegami.editor.commands import Compact
    from kinegami.optimize import tube_length

    document = Document.load(FINGERS)
    command = Compact(starts=2).prepared(document)
    assert command.task is document.task
    model = EditorModel(document)
    result = model.apply(command)
    assert result.ok, result.reason
    shorter = model.document
    assert shorter.task is document.task and model.can_undo
    assert tube_length(shorter.chain) < tube_length(document.chain)
    checks = check_targets(shorter.chain, shorter.task, shorter.units)
    assert all(check.reached for check in checks), [c.reason for c in checks]
    goals = task_goals(shorter.task, shorter.units)
    tips = leaf_tips(shorter.chain)
    for check in checks:
        moved = copy.deepcopy(shorter.chain)
        moved.requireClearance = True
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            assert moved.setJointStates(list(check.states))
        tip = moved.Joints[tips[check.leaf]].distal_dubins_frame()[:3, 3]
        target = goals.targets[check.leaf][check.index].position
        assert np.abs(tip - target).max() <= 1e-9 * shorter.chain.r
    chain_task = {**document.task, "joints": "RRR",
                  "targets": document.task["targets"][0]}  # fmt: skip
    assert Compact().prepared(document.replaced(task=chain_task)).task is None
