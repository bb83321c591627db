"""The model's previews (what the view's animation shows), its joints' modules in the crease
pattern, and ReplaceDocument (what recovering an autosave does)."""

from __future__ import annotations

import pytest

from kinegami.editor import Document, EditorModel, ReplaceDocument, SetJointStates
from kinegami.errors import InvalidTypeError
from tests.editor.helpers import EXAMPLE1, ROOT, example_model, snapshot

GALLERY = sorted((ROOT / "examples" / "designs").glob("*.json"))


@pytest.fixture
def model() -> EditorModel:
    return example_model()


def _states(model: EditorModel, revolute: float) -> list[float]:
    states = [float(j.state) for j in model.chain.Joints]
    states[4] = revolute
    return states


# --- previews ---------------------------------------------------------------------------------
def test_a_preview_shows_the_command_without_recording_it(model):
    base = model.document
    changes = []
    model.subscribe(changes.append)
    result = model.preview(SetJointStates(_states(model, 0.7)))
    assert result.ok and model.previewing
    assert model.chain.Joints[4].state == pytest.approx(0.7)
    assert model.base_document is base
    assert not model.can_undo and not model.dirty
    assert [c.kind for c in changes] == ["preview"]


def test_previews_do_not_pile_up_and_ending_gives_the_base_back(model):
    base = model.document
    for state in (0.2, 0.5, -0.4):
        assert model.preview(SetJointStates(_states(model, state))).ok
    assert model.base_document is base
    assert model.end_preview().ok
    assert model.document is base and not model.previewing and not model.can_undo


def test_a_command_during_a_preview_acts_on_the_base(model):
    base = model.document
    model.preview(SetJointStates(_states(model, 0.7)))
    assert model.slide("revolute", 0.5).ok
    assert not model.previewing
    assert model.chain.Joints[4].state == 0.0
    assert model.undo().ok and model.document is base


def test_undo_during_a_preview_ends_it_first(model):
    model.slide("revolute", 0.5)
    slid = model.document
    model.preview(SetJointStates(_states(model, 0.7)))
    assert model.undo().ok and model.redo().ok
    assert model.document is slid


def test_a_refused_preview_changes_nothing(model):
    base = model.document
    result = model.preview(SetJointStates(_states(model, 99.0)))
    assert not result.ok and "must be in" in result.reason
    assert model.document is base and not model.previewing
    assert not model.end_preview().ok


def test_save_during_a_preview_writes_the_base(model, tmp_path):
    model.preview(SetJointStates(_states(model, 0.7)))
    assert model.save(tmp_path / "arm.json").ok
    assert Document.load(tmp_path / "arm.json").chain.Joints[4].state == 0.0


# --- the joints' modules ------------------------------------------------------------------------
def _own_records(joint, pattern, mine) -> None:
    if joint.pattern.isEmpty and mine.start > 0:
        assert len(mine) == 0  # a waypoint adds no records
    else:
        kinds = [r.kind for r in joint.pattern.modules]
        assert [pattern.modules[k].kind for k in mine] == kinds


@pytest.mark.parametrize("path", GALLERY, ids=lambda p: p.stem)
def test_each_joints_modules_are_its_own_pattern_records(path):
    model = EditorModel.open(path)
    if model.is_tree:  # each joint is on one sheet; the sheets carry every joint once
        sheets = model.sheets()
        tree = sheets.fabrication.tree
        assert [s for s, _ in sheets.places] == [
            next(s.index for s in sheets.sheets if k in s.joints) for k in range(len(tree.Joints))
        ]
        for joint, (s, mine) in zip(tree.Joints, sheets.places, strict=True):
            _own_records(joint, sheets.sheets[s].pattern, mine)
        for sheet in sheets.sheets:
            last = sheets.places[sheet.leaf][1]
            assert last.stop == len(sheet.pattern.modules)
        return
    with pytest.raises(InvalidTypeError, match="a chain is folded from one sheet"):
        model.sheets()
    pattern = model.pattern()
    records = model.joint_modules()
    assert len(records) == len(model.chain.Joints)
    assert records[-1].stop == len(pattern.modules)
    for joint, mine in zip(model.chain.Joints, records, strict=True):
        _own_records(joint, pattern, mine)


def test_the_joints_modules_follow_an_insertion(model):
    assert model.add_joint("RevoluteJoint", after=4).ok  # safe placement may add waypoints
    new = model.selected
    pattern = model.pattern()
    records = model.joint_modules()
    assert [pattern.modules[k].kind for k in records[new]] == ["revolute"]
    assert [pattern.modules[k].kind for k in records[4]] == ["revolute"]
    assert records[4].stop <= records[new].start


# --- replacing the whole document ----------------------------------------------------------------
def test_replace_document_is_one_undoable_step(model, tmp_path):
    other = Document.load(ROOT / "examples" / "designs" / "puma.json")
    first = model.document
    result = model.apply(ReplaceDocument(other, "recover the autosave"))
    assert result.ok and model.document is other and model.dirty
    assert model.undo_labels == ("recover the autosave",)
    assert result.change.structure or result.change.joints
    assert model.undo().ok and model.document is first and not model.dirty
    assert snapshot(model.document) == snapshot(Document.load(EXAMPLE1))


def test_replace_document_refuses_what_is_not_a_document(model):
    result = model.apply(ReplaceDocument("not a document"))
    assert not result.ok and "document must be an editor Document" in result.reason


def test_a_state_preview_measures_its_clearance_with_the_shared_engine(model):
    """A document that is its base at other states (set states, a drag's or an animation's
    previews) remembers the base (``shape_of``) and measures its clearance with the base's
    engine: the same report as the chain's own, at every step; an edit forgets the base."""
    import numpy as np

    from kinegami.clearance import clearance_report

    base = model.document
    rng = np.random.default_rng(3)
    for _ in range(5):
        states = [lo + (hi - lo) * rng.random() for lo, hi in
                  (j.stateRange() for j in base.chain.Joints)]  # fmt: skip
        assert model.preview(SetJointStates(states)).ok
        shown = model.document
        assert shown.shape_of is base
        own = clearance_report(shown.chain, names=shown.names)
        shared = shown.clearance
        assert shared.ok == own.ok
        assert abs(shared.min_clearance - own.min_clearance) <= 1e-9 * base.chain.r
        assert [p.elements for p in shared.pairs] == [p.elements for p in own.pairs]
    model.end_preview()
    assert model.set_states(states).ok
    assert model.document.shape_of is base
    assert model.slide(4, 0.5).ok
    assert model.document.shape_of is None
