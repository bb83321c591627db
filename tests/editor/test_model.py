"""The editor model: transactions, undo and redo, the dirty flag, selection, listeners,
derived values and files."""

from __future__ import annotations

import json
import os

import numpy as np
import pytest
from spatialmath import SE3

from kinegami.design import load_design
from kinegami.editor import (
    AddJoint,
    Change,
    DeleteJoint,
    Document,
    EditorModel,
    RenameJoint,
    SetJointState,
    SlideJoint,
)
from tests.editor.helpers import EXAMPLE1, example_model, snapshot


@pytest.fixture
def model() -> EditorModel:
    return example_model()


# --- undo and redo -----------------------------------------------------------------------------
def test_undo_returns_the_document_object_and_redo_the_next(model):
    first = model.document
    assert model.slide("revolute", 0.5).ok
    second = model.document
    assert model.set_state("revolute", 0.3).ok
    third = model.document
    assert model.undo().ok and model.document is second
    assert model.undo().ok and model.document is first
    assert not model.undo().ok
    assert model.redo().ok and model.document is second
    assert model.redo().ok and model.document is third
    assert not model.redo().ok


def test_nothing_to_undo_or_redo_is_a_reason_not_an_error(model):
    assert model.undo().reason == "there is nothing to undo"
    assert model.redo().reason == "there is nothing to redo"


def test_a_new_command_clears_the_redo_history(model):
    model.slide("revolute", 0.5)
    model.undo()
    assert model.can_redo
    model.slide("revolute", -0.5)
    assert not model.can_redo


def test_undo_has_no_fixed_limit(model):
    first = snapshot(model.document)
    for k in range(120):
        assert model.slide("revolute", 0.01 if k % 2 else -0.01).ok
    assert len(model.undo_labels) == 120
    while model.can_undo:
        model.undo()
    assert snapshot(model.document) == first


def test_undo_labels_describe_the_commands(model):
    model.slide("revolute", 0.5)
    model.rename(1, "w")
    assert model.undo_labels == ("slide joint 'revolute' by 0.5", "rename joint 1 to 'w'")
    model.undo()
    assert model.redo_labels == ("rename joint 1 to 'w'",)


def test_a_failed_command_leaves_the_history_alone(model):
    model.slide("revolute", 0.5)
    model.undo()
    assert not model.slide("revolute", float("nan")).ok
    assert model.can_redo and not model.can_undo


def test_apply_refuses_what_is_not_a_command(model):
    result = model.apply("slide")
    assert not result.ok and "Command" in result.reason


# --- dirty flag ----------------------------------------------------------------------------------
def test_dirty_after_a_command_and_clean_when_undone_to_the_saved_state(model):
    assert not model.dirty
    model.slide("revolute", 0.5)
    assert model.dirty
    model.undo()
    assert not model.dirty
    model.redo()
    assert model.dirty


def test_clean_after_save_and_dirty_when_undone_past_it(model, tmp_path):
    model.slide("revolute", 0.5)
    assert model.save(tmp_path / "a.json").ok
    assert not model.dirty and model.path == tmp_path / "a.json"
    model.undo()
    assert model.dirty
    model.redo()
    assert not model.dirty


def test_a_failed_command_keeps_the_model_clean(model):
    assert not model.slide(99, 1.0).ok
    assert not model.dirty


def test_clean_after_load(model, tmp_path):
    model.slide("revolute", 0.5)
    assert model.load(EXAMPLE1).ok
    assert not model.dirty and not model.can_undo and model.selected is None


def test_a_new_model_is_clean():
    assert not EditorModel().dirty


# --- selection -----------------------------------------------------------------------------------
def test_select_by_index_name_or_nothing(model):
    assert model.select("revolute").ok and model.selected == 4
    assert model.select(-1).ok and model.selected == 6
    assert model.select(None).ok and model.selected is None
    result = model.select(7)
    assert not result.ok and "[-7, 6]" in result.reason and model.selected is None


def test_selection_follows_the_joint_through_a_delete_before_it(model):
    model.select("revolute")
    assert model.apply(DeleteJoint(1)).ok
    assert model.selected == 0  # the delete selects the joint before the deleted one
    model.undo()
    assert model.selected == 4


def test_commands_on_a_joint_select_it(model):
    model.slide("revolute", 0.5)
    assert model.selected == 4
    model.set_state("prismatic", 0.5)
    assert model.selected == 2


def test_deleting_the_selected_joint_selects_the_one_before(model):
    model.select(4)
    assert model.delete().ok
    assert model.selected == 3 and len(model.chain.Joints) == 6


def test_deleting_the_root_selects_the_new_root(model):
    assert model.delete(0).ok and model.selected == 0


def test_undo_and_redo_restore_the_selection(model):
    model.select(2)
    assert model.apply(AddJoint("Waypoint", {}, SE3.Tz(3), after=1, placement="pose")).ok
    assert model.selected == 2
    model.select(5)
    model.undo()
    assert model.selected == 2
    model.redo()
    assert model.selected == 2


def test_selection_is_kept_by_commands_that_do_not_name_a_joint(model):
    model.select("end")
    states = [0.0] * 7
    states[4] = 0.2
    assert model.set_states(states).ok and model.selected == 6


def test_the_helpers_act_on_the_selected_joint(model):
    model.select("revolute")
    before = model.chain.Joints[4].pose_matrix.copy()
    assert model.slide(None, 0.5).ok
    assert not np.array_equal(model.chain.Joints[4].pose_matrix, before)
    assert model.rename(None, "hinge").ok and model.document.names[4] == "hinge"


def test_adding_after_the_selection(model):
    model.select(1)
    assert model.add_joint("Waypoint", pose=SE3.Tz(3), placement="pose").ok
    assert model.selected == 2 and type(model.chain.Joints[2]).__name__ == "Waypoint"


# --- listeners -----------------------------------------------------------------------------------
def test_listeners_hear_every_change_until_they_unsubscribe(model):
    heard: list[Change] = []
    unsubscribe = model.subscribe(heard.append)
    model.slide("revolute", 0.5)
    model.select(2)
    model.undo()
    model.redo()
    assert not model.slide(99, 1).ok  # a failed command says nothing
    assert [c.kind for c in heard] == ["command", "select", "undo", "redo"]
    unsubscribe()
    model.undo()
    assert len(heard) == 4


def test_a_slide_without_propagation_changes_one_joint_and_its_two_links(model):
    result = model.apply(SlideJoint("revolute", 0.5, propagate=False))
    change = result.change
    assert change.joints == (4,) and change.links == (4, 5)
    assert change.reshaped_joints == () and change.reshaped_links == (4, 5)
    assert change.joint_sources == (0, 1, 2, 3, None, 5, 6) and not change.structure


def test_a_propagated_slide_moves_the_later_parts_without_reshaping_them(model):
    change = model.apply(SlideJoint("revolute", 0.5)).change
    assert change.joints == (4, 5, 6) and change.links == (4, 5, 6)
    assert change.reshaped_joints == () and change.reshaped_links == (4,)


def test_a_state_change_reshapes_only_the_joint(model):
    change = model.apply(SetJointState("revolute", 0.3)).change
    assert change.joints == (4, 5, 6) and change.reshaped_joints == (4,)
    assert change.links == (5, 6) and change.reshaped_links == ()


def test_a_delete_reports_the_removed_joint_and_the_shift(model):
    change = model.apply(DeleteJoint(3)).change
    assert change.structure and change.removed == (3,)
    assert change.joint_sources == (0, 1, 2, 4, 5, 6)
    assert change.joints == () and change.links == (3,)


def test_a_rename_changes_names_only(model):
    change = model.apply(RenameJoint(1, "w")).change
    assert change.names and change.joints == () and change.links == ()
    assert change.document_changed


def test_an_undo_reports_the_reverse_change(model):
    model.apply(SlideJoint("revolute", 0.5, propagate=False))
    change = model.undo().change
    assert change.kind == "undo" and change.joints == (4,) and change.links == (4, 5)


def test_options_changes_are_reported(model):
    assert model.set_options(units="mm").change.options
    assert not model.set_options(units="mm").change.document_changed


# --- derived values ------------------------------------------------------------------------------
def test_the_joint_table(model):
    rows = model.joint_table()
    assert [(r.index, r.type, r.name) for r in rows] == [
        (0, "StartTip", "start"), (1, "Waypoint", None), (2, "PrismaticJoint", "prismatic"),
        (3, "Waypoint", None), (4, "RevoluteJoint", "revolute"), (5, "Waypoint", None),
        (6, "EndTip", "end"),
    ]  # fmt: skip
    revolute = rows[4]
    assert revolute.state_range == pytest.approx((-np.pi / 2, np.pi / 2))
    assert revolute.movable and not rows[1].movable
    assert revolute.parameters == {"totalBendingAngle": np.pi, "numSinkLayers": 1}
    assert np.array_equal(revolute.pose, model.chain.Joints[4].pose_matrix)
    model.set_state("revolute", 0.25)
    assert model.joint_table()[4].state == 0.25


def test_derived_values_are_computed_once_per_document(model):
    assert model.clearance() is model.clearance()
    assert model.pattern() is model.pattern()
    assert model.joint_table() is model.joint_table()
    report = model.clearance()
    model.slide("revolute", 0.5)
    assert model.clearance() is not report
    model.undo()
    assert model.clearance() is report


def test_the_pattern_is_the_chains_pattern_bit_for_bit(model):
    for command in (SlideJoint("revolute", 0.5), SetJointState("revolute", 0.3),
                    SlideJoint("prismatic", -0.5, propagate=False), DeleteJoint(3)):  # fmt: skip
        assert model.apply(command).ok
        mine = model.pattern()
        theirs = model.chain.creasePattern(model.document.twist_portion)
        for name in ("vertices_coords", "edges_vertices", "edges_assignment"):
            assert np.array_equal(getattr(mine, name), getattr(theirs, name)), name
        assert mine.modules == theirs.modules


def test_the_clearance_report_is_the_chains(model):
    report = model.clearance()
    assert report.ok == model.chain.clearance().ok
    assert report.min_clearance == model.chain.clearance().min_clearance


# --- files ---------------------------------------------------------------------------------------
def test_save_and_load_round_trip_at_state_zero_is_exact(model, tmp_path):
    model.slide("revolute", 0.5)
    model.rename(1, "w")
    text = model.to_design_text()
    target = tmp_path / "arm.json"
    assert model.save(target).ok
    assert target.read_text(encoding="utf-8") == text
    other = EditorModel.open(target)
    assert other.document.names == model.document.names
    assert other.to_design_text() == text
    for a, b in zip(other.chain.Joints, model.chain.Joints, strict=True):
        assert a.pose_matrix.tobytes() == b.pose_matrix.tobytes()


def test_save_and_load_round_trip_with_states(model, tmp_path):
    model.slide("revolute", 0.5)
    model.set_state("revolute", 0.3)
    model.set_state("prismatic", -0.5)
    target = tmp_path / "arm.json"
    assert model.save(target).ok
    other = EditorModel.open(target)
    assert other.document.names == model.document.names
    for a, b in zip(other.chain.Joints, model.chain.Joints, strict=True):
        np.testing.assert_allclose(a.pose_matrix, b.pose_matrix, rtol=0, atol=1e-12)
        assert a.state == b.state
    assert len(load_design(target).Joints) == 7


def test_the_design_text_keeps_names_texts_and_options(model):
    document = json.loads(model.to_design_text())
    assert document["name"] == "Example 1" and document["units"] == "cm"
    assert [j.get("name") for j in document["joints"]] == [
        "start",
        None,
        "prismatic",
        None,
        "revolute",
        None,
        "end",
    ]


def test_a_document_of_the_text_is_the_same_document(model):
    again = Document.loads(model.to_design_text())
    assert snapshot(again)[0] == snapshot(model.document)[0]


def test_save_writes_atomically_and_leaves_no_temporary_file(model, tmp_path):
    target = tmp_path / "arm.json"
    target.write_text("old", encoding="utf-8")
    assert model.save(target).ok
    assert sorted(os.listdir(tmp_path)) == ["arm.json"]


def test_a_failed_write_keeps_the_old_file(model, tmp_path, monkeypatch):
    target = tmp_path / "arm.json"
    target.write_text("old", encoding="utf-8")

    def broken(source, destination):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", broken)
    model.slide("revolute", 0.5)
    result = model.save(target)
    assert not result.ok and "No space left" in result.reason
    assert target.read_text(encoding="utf-8") == "old"
    assert sorted(os.listdir(tmp_path)) == ["arm.json"]
    assert model.dirty


@pytest.mark.parametrize(("name", "words"), [("arm.txt", ".json"), ("d.json", "directory")])
def test_bad_save_targets_are_reasons(model, tmp_path, name, words):
    (tmp_path / "d.json").mkdir()
    result = model.save(tmp_path / name)
    assert not result.ok and words in result.reason


def test_save_without_a_path_needs_one():
    result = EditorModel().save()
    assert not result.ok and "path" in result.reason


def test_save_defaults_to_the_opened_file(tmp_path):
    target = tmp_path / "arm.json"
    target.write_text(EXAMPLE1.read_text(encoding="utf-8"), encoding="utf-8")
    model = EditorModel.open(target)
    model.slide("revolute", 0.5)
    assert model.save().ok and not model.dirty
    assert EditorModel.open(target).to_design_text() == model.to_design_text()


def test_loading_a_bad_file_is_a_reason_and_changes_nothing(model, tmp_path):
    bad = tmp_path / "bad.json"
    bad.write_text('{"format": "kinegami-design", "version": 9}', encoding="utf-8")
    before = model.document
    result = model.load(bad)
    assert not result.ok and "version" in result.reason and "bad.json" in result.reason
    assert model.document is before
    assert not model.load(tmp_path / "missing.json").ok


def test_a_model_of_a_chain_copies_it():
    chain = load_design(EXAMPLE1)
    model = EditorModel(chain)
    assert model.document.names == (None,) * 7 or model.document.names[0] == "start"
    chain.translateJointAlongAxisOfMotion(4, 1.0)
    assert not np.array_equal(model.chain.Joints[4].pose_matrix, chain.Joints[4].pose_matrix)
