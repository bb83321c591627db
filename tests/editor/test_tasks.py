"""A design's task in the editor (docs/editor.md, Tasks), without a browser: the task kept
through edits, undo, save and autosave; each target checked green or red with its reason (the
model's check and the view's scene and Task panel); Design for task in the background as one
undoable step (Cancel and a search that finds nothing leave the design as it was); Compact of
a design with a task keeps every target reached.

tests/data/task_arm.json is a three-joint arm that ``kinegami design`` made for three points
above a table; its task then had target C moved out of its reach, so the arm reaches A and B
and not C, and Design for task finds an arm that reaches all three in seconds."""

from __future__ import annotations

import copy
import json
import shutil
import time

import numpy as np
import pytest

pytest.importorskip("viser")

from kinegami.design.task import starter_task  # noqa: E402
from kinegami.editor import Document, EditorModel  # noqa: E402
from kinegami.editor.commands import DesignForTask, ReplaceDocument  # noqa: E402
from kinegami.editor.server import EditorServer  # noqa: E402
from kinegami.editor.tasks import check_targets, task_goals  # noqa: E402
from kinegami.editor.view import MISSED_COLOR, REACHED_COLOR  # noqa: E402
from kinegami.errors import InvalidTypeError  # noqa: E402
from kinegami.optimize import tube_length  # noqa: E402
from kinegami.reach import solve  # noqa: E402

from .helpers import ROOT, snapshot  # noqa: E402

TASK_ARM = ROOT / "tests" / "data" / "task_arm.json"
#: Where target C was when the arm was designed (it reaches it there).
DESIGNED_C = [103.5, 219.2, 117.7]
#: Seconds for a background job (a spawned process imports numpy, scipy and kinegami first).
LIVE = 120.0


def _task_moved(document: Document, k: int, position) -> dict:
    task = copy.deepcopy(document.task)
    task["targets"][k]["position"] = list(position)
    return task


def _reached_exactly(chain, goals) -> None:
    """Every target of ``goals`` is reached by ``chain``: the solver's states, set on a copy,
    put the tip on the target (1e-9 r), clear."""
    for target in goals.targets:
        answer = solve(chain, target, margin=goals.margin)
        assert answer.ok, answer.reason
        posed = copy.copy(chain)
        assert posed.setJointStates(list(answer.states))
        tip = np.asarray(posed.Joints[-1].distal_dubins_frame(), dtype=float)[:3, 3]
        np.testing.assert_allclose(tip, target.position, rtol=0, atol=1e-9 * chain.r)
        assert posed.clearance().ok


# --- the model ------------------------------------------------------------------------------------
def test_the_task_is_kept_through_edits_undo_save_and_autosave(tmp_path):
    model = EditorModel.open(TASK_ARM)
    task = json.loads(TASK_ARM.read_text(encoding="utf-8"))["task"]
    assert model.document.task == task
    assert model.slide(1, 5.0, propagate=False).ok and model.document.task == task
    saved = tmp_path / "arm.json"
    assert model.save(saved).ok
    assert json.loads(saved.read_text(encoding="utf-8"))["task"] == task
    assert Document.load(saved).task == task
    assert model.undo().ok and model.document.task == task
    assert json.loads(model.document.design_text)["task"] == task  # what the autosave writes


def test_check_targets_says_which_targets_are_reached_and_why_not():
    document = Document.load(TASK_ARM)
    checks = check_targets(document.chain, document.task, document.units)
    assert [c.reached for c in checks] == [True, True, False]
    assert [c.label for c in checks] == ["target 0 'A'", "target 1 'B'", "target 2 'C'"]
    assert checks[2].reason.startswith("not reached") and not checks[0].reason
    designed = _task_moved(document, 2, DESIGNED_C)  # the task it was made for: all reached
    assert all(c.reached for c in check_targets(document.chain, designed, "mm"))
    far = _task_moved(document, 0, [5000.0, 0.0, 0.0])
    assert check_targets(document.chain, far, "mm")[0].reason.startswith("beyond reach")


def test_a_target_reached_inside_a_keep_out_box_is_not_reached():
    document = Document.load(TASK_ARM)
    task = _task_moved(document, 2, DESIGNED_C)
    b = np.array(task["targets"][1]["position"])
    task["keepOut"].append({"min": (b - 1.0).tolist(), "max": (b + 1.0).tolist()})
    checks = check_targets(document.chain, task, "mm")
    assert [c.reached for c in checks] == [True, False, True]
    assert "enters keep-out box 1" in checks[1].reason


def test_a_task_in_other_units_is_converted_to_the_designs():
    task = Document.load(TASK_ARM).task
    mm, cm = task_goals(task, "mm"), task_goals(task, "cm")
    np.testing.assert_allclose(cm.targets[0].position, mm.targets[0].position / 10.0)
    assert cm.scale == 0.1 and cm.keep_out[0].max[2] == pytest.approx(mm.keep_out[0].max[2] / 10)


def test_design_for_task_without_a_task_is_refused():
    plain = EditorModel(Document.load(TASK_ARM).replaced(task=None))
    result = plain.design_for_task()
    assert not result.ok and "this design has no task" in result.reason


def test_a_task_no_design_can_reach_is_refused_with_its_reason():
    model = EditorModel.open(TASK_ARM)
    before = model.document
    task = _task_moved(before, 2, [5000.0, 0.0, 0.0])
    result = model.apply(DesignForTask(task=task))
    assert not result.ok and result.reason.startswith("design for task: no design of joints")
    assert model.document is before and not model.can_undo


def test_compact_of_a_design_that_misses_its_task_is_refused():
    model = EditorModel.open(TASK_ARM)
    before = model.document
    result = model.compact(starts=1, time_limit=5.0)
    assert not result.ok and "does not reach its task before compaction: target 2" in result.reason
    assert model.document is before


# --- the view -------------------------------------------------------------------------------------
@pytest.fixture
def design(tmp_path):
    path = tmp_path / "arm.json"
    shutil.copyfile(TASK_ARM, path)
    return path


@pytest.fixture
def server(design):
    server = EditorServer(design, port=0)
    yield server
    server.stop()


def _finished(job) -> str:
    assert job is not None
    assert job.finished.wait(LIVE), "the job did not finish"
    return job.outcome


def test_the_view_draws_each_target_green_or_red_and_lists_why(view):
    view.flush()
    assert view.task_checked is view.model.document
    assert view.target_colours() == (REACHED_COLOR, REACHED_COLOR, MISSED_COLOR)
    assert view._task_folder.visible and view._design_button.visible
    html = view._task_html.content
    assert html.count('data-state="reached"') == 2 and 'data-state="missed"' in html
    assert "2 of 3 reached" in html and "target 2 &#x27;C&#x27;: <b>not reached</b>" in html
    assert view.task_checks[2].reason.removeprefix("not reached: ").split(";")[0] in html
    positions = view.task_positions()
    np.testing.assert_allclose(positions[2], view.model.document.task["targets"][2]["position"])
    lo, hi = view.design_box()  # the targets are framed with the design
    assert np.all(lo <= positions.min(0)) and np.all(positions.max(0) <= hi)
    # another task (C where the arm was designed for it): checked again after the change
    moved = view.model.document.replaced(task=_task_moved(view.model.document, 2, DESIGNED_C))
    assert view.act(lambda: view.model.apply(ReplaceDocument(moved))).ok
    view.flush()
    assert view.target_colours() == (REACHED_COLOR,) * 3 and "3 of 3 reached" in \
        view._task_html.content  # fmt: skip
    assert view.act(view.model.undo).ok
    view.flush()  # the undone document's checks were kept: shown again at once
    assert view.target_colours() == (REACHED_COLOR, REACHED_COLOR, MISSED_COLOR)


def test_axis_and_pose_targets_are_drawn_with_their_direction(view):
    task = copy.deepcopy(view.model.document.task)
    task["targets"][1]["axis"] = [0.0, 0.0, 1.0]
    task["targets"][2] = {"name": "C", "pose": [{"Trans": DESIGNED_C}, {"Rx": 180}]}
    view.set_model(EditorModel(view.model.document.replaced(task=task)))
    view.flush()
    assert [c.kind for c in view.task_checks] == ["position", "axis", "pose"]
    names = sorted(handle.name for handle in view._task_handles)
    assert names == ["/task/target0", "/task/target0_label", "/task/target1",
                     "/task/target1_axis", "/task/target1_label", "/task/target2",
                     "/task/target2_frame", "/task/target2_label"]  # fmt: skip
    np.testing.assert_allclose(np.asarray(view.task_checks[2].rotation)[:, 2], [0, 0, -1],
                               atol=1e-12)  # fmt: skip
    assert len(view.target_colours()) == 3


def test_a_tree_task_is_not_checked_on_a_chain():
    document = Document.load(TASK_ARM)
    with pytest.raises(InvalidTypeError, match="a tree task"):
        check_targets(document.chain, starter_task(tree=True), document.units)


def test_design_for_task_is_one_undo_step_that_keeps_the_task(view):
    before = view.model.document
    job = view.design_for_task()
    assert view.job is job and view._job_cancel.visible and job.title == "Designing for the task"
    assert _finished(job) == "done", view.message
    assert job.total > 0 and job.done == job.total  # its progress was reported
    assert view.model.undo_labels == ("design for task",)
    designed = view.model.document
    assert designed.task is before.task and designed.units == "mm"
    view.flush()
    assert view.task_checked is designed
    assert view.target_colours() == (REACHED_COLOR,) * 3
    _reached_exactly(designed.chain, task_goals(designed.task, designed.units))
    view.act(view.model.undo)
    assert view.model.document is before


def test_cancel_of_design_for_task_leaves_the_design_unchanged(view):
    before = snapshot(view.model.document)
    document = view.model.document
    job = view.design_for_task()
    deadline = time.monotonic() + LIVE
    while job.total == 0 and time.monotonic() < deadline:  # the search has begun
        time.sleep(0.02)
    assert view.cancel_job()
    assert _finished(job) == "cancelled"
    assert view.model.document is document and snapshot(document) == before
    assert not view.model.can_undo and not view.model.dirty
    assert "design for task cancelled: the design is unchanged" in view.message


def test_a_search_that_finds_nothing_is_shown_and_changes_nothing(view):
    view._jobs = None  # in a thread of this process: the certificate refuses at once
    task = _task_moved(view.model.document, 2, [5000.0, 0.0, 0.0])
    moved = view.model.document.replaced(task=task)
    view.set_model(EditorModel(moved))
    job = view.design_for_task()
    assert _finished(job) == "failed"
    assert view.message.startswith("**Refused:** design for task: no design of joints 'RRR' "
                                   "can reach every target")  # fmt: skip
    assert view.model.document is moved and not view.model.can_undo


def test_compact_keeps_every_target_of_the_task_reached(view):
    task = _task_moved(view.model.document, 2, DESIGNED_C)  # the task the arm was made for
    view.set_model(EditorModel(view.model.document.replaced(task=task)))
    # the second joint slid along its axis, the later ones left: the same motion, a longer tube
    assert view.act(lambda: view.model.slide(1, 30.0, propagate=False)).ok
    slid = view.model.document
    goals = task_goals(task, "mm")
    _reached_exactly(slid.chain, goals)
    job = view.compact(starts=1, time_limit=5.0)
    assert job.title == "Compacting (keeping the task)"
    assert _finished(job) == "done", view.message
    compacted = view.model.document
    assert view.model.undo_labels[-1] == "compact" and compacted.task is task
    assert tube_length(compacted.chain) < tube_length(slid.chain)
    _reached_exactly(compacted.chain, goals)
    view.flush()
    assert view.target_colours() == (REACHED_COLOR,) * 3
