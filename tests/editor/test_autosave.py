"""Autosave and crash recovery (kinegami.editor.autosave) and the debounced background work
it runs on (kinegami.editor.background), without a browser."""

from __future__ import annotations

import os
import shutil
import threading
import time

import pytest

from kinegami.editor import Document
from kinegami.editor.autosave import (
    Autosaver,
    autosave_path,
    data_folder,
    find_recovery,
    legacy_autosave_path,
)
from kinegami.editor.background import Debounced
from tests.editor.helpers import EXAMPLE1, example_model


@pytest.fixture
def design(tmp_path):
    """A copy of examples/designs/example1.json to edit (its autosave's folder exists)."""
    path = tmp_path / "arm.json"
    shutil.copyfile(EXAMPLE1, path)
    autosave_path(path).parent.mkdir(parents=True, exist_ok=True)
    return path


def _age(path, seconds: float) -> None:
    stat = path.stat()
    os.utime(path, (stat.st_atime - seconds, stat.st_mtime - seconds))


# --- where ------------------------------------------------------------------------------------
def test_the_autosave_goes_to_the_data_folder_keyed_by_the_designs_path(design, data_home):
    path = autosave_path(design)
    assert path.parent == data_home / "kinegami" / "autosaves"
    assert path.name.startswith("arm.json-") and path.name.endswith(".autosave")
    other = design.parent / "copy" / "arm.json"  # the same name in another folder
    assert autosave_path(other) != path and autosave_path(other).parent == path.parent
    assert autosave_path(os.path.relpath(design)) == path  # the absolute path is the key


def test_a_design_with_no_file_autosaves_in_the_data_folder(monkeypatch, tmp_path):
    monkeypatch.setenv("XDG_DATA_HOME", str(tmp_path / "data"))
    assert data_folder() == tmp_path / "data" / "kinegami"
    assert autosave_path(None) == tmp_path / "data" / "kinegami" / "untitled.json.autosave"
    monkeypatch.delenv("XDG_DATA_HOME")
    monkeypatch.setenv("HOME", str(tmp_path / "home"))
    assert data_folder() == tmp_path / "home" / ".local" / "share" / "kinegami"


# --- writing ----------------------------------------------------------------------------------
def test_a_dirty_document_is_written_as_a_design_file(design):
    model = example_model()
    model.slide("revolute", 0.5)
    saver = Autosaver(autosave_path(design), delay=60.0)
    saver.record(model.document, model.dirty)
    assert not autosave_path(design).exists()  # not before the pause
    saver.flush()
    assert Document.load(autosave_path(design)).design_text == model.document.design_text
    assert sorted(os.listdir(design.parent)) == ["arm.json"]  # nothing beside the design


def test_many_changes_make_one_write_after_the_pause(design):
    model = example_model()
    saver = Autosaver(autosave_path(design), delay=2.0)  # far longer than a slide
    for _ in range(10):
        model.slide("revolute", 0.1)
        saver.record(model.document, model.dirty)
    deadline = time.monotonic() + 10.0
    while saver.writes == 0 and time.monotonic() < deadline:
        time.sleep(0.05)
    time.sleep(0.3)
    assert saver.writes == 1
    assert Document.load(autosave_path(design)).design_text == model.document.design_text


def test_clean_again_removes_the_autosave_it_wrote(design):
    model = example_model()
    saver = Autosaver(autosave_path(design), delay=60.0)
    model.slide("revolute", 0.5)
    saver.record(model.document, model.dirty, owner="tab 1")
    saver.flush()
    saver.record(model.document, False, owner="tab 2")  # another tab's clean document
    assert autosave_path(design).exists()
    model.undo()
    saver.record(model.document, model.dirty, owner="tab 1")
    assert not autosave_path(design).exists()


def test_discard_drops_a_pending_write(design):
    model = example_model()
    model.slide("revolute", 0.5)
    saver = Autosaver(autosave_path(design), delay=60.0)
    saver.record(model.document, True)
    saver.discard()
    saver.flush()
    assert not autosave_path(design).exists() and saver.writes == 0


def test_the_autosave_is_written_atomically(design, monkeypatch):
    model = example_model()
    model.slide("revolute", 0.5)
    saver = Autosaver(autosave_path(design), delay=60.0)
    autosave_path(design).write_text("the last autosave", encoding="utf-8")

    def full_disk(source, destination):
        raise OSError(28, "No space left on device")

    monkeypatch.setattr(os, "replace", full_disk)
    saver.record(model.document, True)
    saver.flush()
    assert "No space left" in saver.error
    assert autosave_path(design).read_text(encoding="utf-8") == "the last autosave"
    assert sorted(os.listdir(autosave_path(design).parent)) == [autosave_path(design).name]


# --- recovery ---------------------------------------------------------------------------------
def test_an_autosave_newer_than_the_design_is_offered(design):
    model = example_model()
    model.slide("revolute", 0.5)
    _age(design, 60.0)
    autosave_path(design).write_text(model.document.design_text, encoding="utf-8")
    recovery = find_recovery(design)
    assert recovery is not None and recovery.path == autosave_path(design)
    assert recovery.document.design_text == model.document.design_text
    assert "unsaved changes to arm.json from " in recovery.describe()


def test_an_autosave_older_than_the_design_is_not_offered(design):
    autosave_path(design).write_text(example_model().document.design_text, encoding="utf-8")
    _age(autosave_path(design), 60.0)
    assert find_recovery(design) is None


@pytest.mark.parametrize("text", ["", "{not json", '{"joints": 3}'])
def test_an_unreadable_autosave_is_not_offered(design, text):
    _age(design, 60.0)
    autosave_path(design).write_text(text, encoding="utf-8")
    assert find_recovery(design) is None


def test_no_autosave_no_recovery(design):
    assert find_recovery(design) is None


def test_an_autosave_an_earlier_version_left_beside_the_design_is_offered(design):
    model = example_model()
    model.slide("revolute", 0.5)
    _age(design, 60.0)
    legacy = legacy_autosave_path(design)
    assert legacy == design.parent / ".arm.json.autosave"
    legacy.write_text(model.document.design_text, encoding="utf-8")
    recovery = find_recovery(design)
    assert recovery is not None and recovery.path == legacy and recovery.legacy
    autosave_path(design).write_text(example_model().document.design_text, encoding="utf-8")
    assert find_recovery(design).path == autosave_path(design)  # the data folder's first


# --- debounced work ---------------------------------------------------------------------------
def test_debounced_runs_once_after_the_last_trigger():
    calls = []
    done = threading.Event()
    debounced = Debounced(lambda: (calls.append(time.monotonic()), done.set()), 0.15)
    start = time.monotonic()
    for _ in range(5):
        debounced.trigger()
        time.sleep(0.02)
    last = time.monotonic()
    assert done.wait(10.0)
    time.sleep(0.3)
    assert len(calls) == 1 and calls[0] >= last + 0.1 > start
    debounced.close()


def test_debounced_flush_runs_now_and_only_when_due():
    calls = []
    debounced = Debounced(lambda: calls.append(1), 60.0)
    assert not debounced.flush()
    debounced.trigger()
    assert debounced.pending and debounced.flush()
    assert calls == [1] and not debounced.pending
    debounced.close()


def test_debounced_close_waits_for_a_call_in_progress():
    """Nothing runs after close: a view closed while its sheets are being fitted in the
    background has finished fitting when close returns (and a later view counts only its own)."""
    started, release, finished = threading.Event(), threading.Event(), []

    def slow():
        started.set()
        release.wait(10.0)
        finished.append(time.monotonic())

    debounced = Debounced(slow, 0.0)
    debounced.trigger()
    assert started.wait(10.0)
    threading.Timer(0.2, release.set).start()
    begun = time.monotonic()
    debounced.close()
    assert finished and finished[0] >= begun  # the call ended before close returned
    debounced.trigger()  # closed: nothing runs any more
    time.sleep(0.1)
    assert len(finished) == 1
