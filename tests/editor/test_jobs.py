"""Long jobs of the editor (docs/editor.md, Background jobs) and the unsaved-changes questions,
without a browser: the job process (progress, results, errors, Cancel, a stuck job stopped),
Compact, Check motion and Fit junctions in the background as one undoable command, a result
for a design edited meanwhile, and Open/Upload with unsaved changes."""

from __future__ import annotations

import copy
import shutil
import threading
import time
from dataclasses import dataclass
from typing import ClassVar

import pytest

pytest.importorskip("viser")

from kinegami.editor import Document  # noqa: E402
from kinegami.editor.autosave import autosave_path  # noqa: E402
from kinegami.editor.background import JobProcess  # noqa: E402
from kinegami.editor.commands import LongCommand, Outcome  # noqa: E402
from kinegami.editor.server import EditorServer  # noqa: E402
from kinegami.errors import Cancelled, InvalidParameterError  # noqa: E402
from kinegami.fabrication.sheets import junction_problems  # noqa: E402
from kinegami.optimize import tube_length  # noqa: E402

from .helpers import EXAMPLE1, HAND, ROOT, snapshot  # noqa: E402

PUMA = ROOT / "examples" / "designs" / "puma.json"

#: Generous: a spawned worker process imports numpy, scipy and kinegami first (seconds on a
#: busy 2-core machine), and compaction itself takes seconds.
LIVE = 120.0


# --- functions the job process runs (module level: sent by reference) -------------------------
def count_to(n: int, *, progress) -> int:
    for k in range(n + 1):
        if progress(k, n) is False:
            raise Cancelled(f"stopped at {k}")
        time.sleep(0.01)
    return n * n


def refuse(*, progress) -> None:
    raise InvalidParameterError("samples must be > 0, got -1")


def until_cancelled(*, progress) -> None:
    while progress(0, 1) is not False:
        time.sleep(0.01)
    raise Cancelled("stopped")


def stuck(seconds: float, *, progress) -> None:
    progress(0, 1)
    time.sleep(seconds)  # never asks again: only stopping the process ends it


# --- the job process ------------------------------------------------------------------------------
@pytest.fixture
def jobs():
    jobs = JobProcess(grace=0.5)
    yield jobs
    jobs.close()


def test_a_job_returns_its_result_and_relays_its_progress(jobs):
    seen = []
    assert jobs.run(count_to, (20,), lambda d, t: seen.append((d, t)), threading.Event()) == 400
    assert seen and seen[-1] == (20, 20) and all(t == 20 for _, t in seen)
    assert jobs.run(count_to, (3,), lambda d, t: None, threading.Event()) == 9
    assert jobs.started == 1  # one process for both


def test_a_jobs_error_is_raised_here(jobs):
    with pytest.raises(InvalidParameterError, match="samples must be > 0"):
        jobs.run(refuse, (), lambda d, t: None, threading.Event())
    assert jobs.run(count_to, (2,), lambda d, t: None, threading.Event()) == 4


def test_cancel_stops_a_job_through_its_progress_callback(jobs):
    cancel = threading.Event()  # set once the job has reported
    with pytest.raises(Cancelled, match="stopped"):
        jobs.run(until_cancelled, (), lambda d, t: cancel.set(), cancel)
    assert jobs.started == 1 and jobs.pid is not None  # it stopped by itself: the process stays


def test_a_job_that_does_not_stop_has_its_process_stopped(jobs):
    first = jobs.run(count_to, (1,), lambda d, t: None, threading.Event())
    pid = jobs.pid
    cancel = threading.Event()
    reported = threading.Event()
    begun = []

    def on_progress(done, total):
        begun.append(time.monotonic())
        reported.set()

    threading.Thread(target=lambda: (reported.wait(LIVE), cancel.set()), daemon=True).start()
    with pytest.raises(Cancelled):
        jobs.run(stuck, (600.0,), on_progress, cancel)
    assert time.monotonic() - begun[0] < 60.0  # not the 600 s of the job
    assert first == 1 and jobs.pid is None
    assert jobs.run(count_to, (2,), lambda d, t: None, threading.Event()) == 4
    assert jobs.started == 2 and jobs.pid != pid  # a fresh process


# --- the view's jobs ------------------------------------------------------------------------------
@pytest.fixture
def design(tmp_path):
    path = tmp_path / "arm.json"
    shutil.copyfile(EXAMPLE1, path)
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


def test_compact_runs_in_the_background_and_is_one_undo_step(view):
    before = view.model.document
    job = view.compact(starts=1, time_limit=5.0)
    assert view.job is job and view._job_cancel.visible and view._job_bar.visible
    # the tab answers while compaction runs in the job process
    started = time.monotonic()
    view.click_joint(4)
    assert view.model.selected == 4 and time.monotonic() - started < 5.0
    assert _finished(job) == "done"
    assert view.job is None and not view._job_cancel.visible
    assert view.model.undo_labels == ("compact",)
    assert tube_length(view.model.chain) <= tube_length(before.chain) + 1e-9
    assert job.total == 1 and job.done == 1
    view.act(view.model.undo)
    assert view.model.document is before


def test_cancel_leaves_the_design_unchanged(view):
    before = snapshot(view.model.document)
    document = view.model.document
    job = view.compact(starts=4, time_limit=30.0)
    deadline = time.monotonic() + LIVE
    while job.total == 0 and time.monotonic() < deadline:  # compaction has begun
        time.sleep(0.05)
    assert view.cancel_job()
    assert _finished(job) == "cancelled"
    assert view.model.document is document and snapshot(document) == before
    assert not view.model.can_undo and not view.model.dirty
    assert "cancelled: the design is unchanged" in view.message
    again = view.compact(starts=1, time_limit=2.0)  # the next job runs (a fresh process if need be)
    assert _finished(again) == "done" and view.model.undo_labels == ("compact",)


def test_one_job_at_a_time(view):
    job = view.compact(starts=1, time_limit=5.0)
    assert view.check_motion() is None and "compact is running" in view.message
    assert _finished(job) == "done"


def test_check_motion_reports_and_changes_nothing(view):
    document = view.model.document
    job = view.check_motion(samples=500)
    assert _finished(job) == "done"
    assert view.model.document is document and not view.model.can_undo
    assert view._motion.visible and "of 500 random configurations self-intersect" in \
        view._motion.content  # fmt: skip
    assert view.act(lambda: view.model.slide(4, 0.5, propagate=False)).ok
    assert not view._motion.visible  # the report was of the design before


def test_fit_junctions_of_the_hand_is_one_undo_step(tmp_path):
    path = tmp_path / "hand.json"
    shutil.copyfile(HAND, path)
    server = EditorServer(path, port=0)
    try:
        view = server.new_view(server.server)
        if not junction_problems(view.model.chain):  # the hand as built: slid back as designed
            assert view.act(lambda: view.model.slide("palm", 3.0, propagate=True)).ok
        before = view.model.document
        steps = len(view.model.undo_labels)
        assert _finished(view.fit_junctions()) == "done"
        assert view.model.undo_labels[steps:] == ("fit junctions",)
        assert view.model.document is not before and not junction_problems(view.model.chain)
        assert _finished(view.fit_junctions()) == "done"  # nothing left to fit: refused
        assert "fits already" in view.message and len(view.model.undo_labels) == steps + 1
        view.close()
    finally:
        server.stop()


# --- a result for a design edited meanwhile (a gated command, run in a thread) ------------------
GATE = threading.Event()


@dataclass(frozen=True)
class Shift(LongCommand):
    """A long command for tests: slides joint 4 by 0.25 once the gate opens."""

    label: ClassVar[str] = "shift"

    def _compute(self, chain, progress):
        while not GATE.wait(0.02):
            if progress(0, 1) is False:
                raise Cancelled("stopped")
        moved = copy.copy(chain)
        moved.translateJointAlongAxisOfMotion(4, 0.25, propagate=False)
        return moved

    def finish(self, document, computed) -> Outcome:
        chain, _ = computed
        return Outcome(document.replaced(chain=chain))


@pytest.fixture
def threaded(server):
    GATE.clear()
    view = server.new_view(server.server)
    view._jobs = None  # run jobs in a thread of this process (the gate is this process's)
    yield view
    GATE.set()
    view.close()


def test_a_result_for_an_unchanged_design_applies_at_once(threaded):
    view = threaded
    document = view.model.document
    job = view.run_command_job(Shift(), "Shifting", "steps")
    GATE.set()
    assert _finished(job) == "done" and view.model.undo_labels == ("shift",)
    assert view.act(view.model.undo).ok and view.model.document is document


@pytest.mark.parametrize("answer", ["apply", "discard"])
def test_a_result_for_an_edited_design_asks_first(threaded, answer):
    view = threaded
    job = view.run_command_job(Shift(), "Shifting", "steps")
    assert view.set_state(4, 0.3).ok  # an edit while the job runs: the tab answers
    edited = view.model.document
    GATE.set()
    assert _finished(job) == "done"
    assert view.pending_result is not None and view._stale_modal is not None
    assert view.model.document is edited  # nothing replaced before the answer
    view.resolve_result(answer)
    assert view.pending_result is None and view._stale_modal is None
    if answer == "discard":
        assert view.model.document is edited and len(view.model.undo_labels) == 1
        return
    assert view.model.undo_labels[-1] == "shift" and len(view.model.undo_labels) == 2
    assert view.model.document.chain.Joints[4].state == job.source.chain.Joints[4].state
    assert view.act(view.model.undo).ok and view.model.document is edited  # one step back


def test_opening_another_design_drops_a_running_job(threaded):
    view = threaded
    job = view.run_command_job(Shift(), "Shifting", "steps")
    assert view.open_example("puma")  # the design is clean: opens at once
    assert _finished(job) == "dropped"
    assert not view.model.can_undo and view.job is None


# --- open and upload with unsaved changes ---------------------------------------------------------
def _is_puma(document) -> bool:
    return snapshot(document) == snapshot(Document.load(PUMA))


def _edit(view) -> None:
    assert view.act(lambda: view.model.slide(4, 0.5, propagate=False)).ok
    assert view.model.dirty


def test_open_with_unsaved_changes_asks_and_cancel_keeps_them(view):
    _edit(view)
    edited = view.model.document
    assert not view.open_example("puma")
    assert view.pending_open is not None and view._unsaved_modal is not None
    assert view.model.document is edited  # nothing opened yet
    assert not view.answer_unsaved("cancel")
    assert view.model.document is edited and view.model.dirty and view.pending_open is None
    assert view._unsaved_modal is None


def test_open_with_unsaved_changes_save_writes_the_file_first(view, design):
    _edit(view)
    text = view.model.document.design_text
    assert not view.open_example("puma")
    assert view.answer_unsaved("save")
    assert design.read_text(encoding="utf-8") == text  # saved, then opened
    assert _is_puma(view.model.document) and view.model.path is None
    assert not view.model.dirty and not autosave_path(design).exists()


def test_open_with_unsaved_changes_discard_drops_them_and_their_autosave(view, design):
    _edit(view)
    view.autosave.flush()
    assert autosave_path(design).exists()
    original = design.read_bytes()
    assert not view.open_example("puma")
    assert view.answer_unsaved("discard")
    assert not autosave_path(design).exists() and design.read_bytes() == original
    assert not view.model.dirty and _is_puma(view.model.document)


def test_upload_with_unsaved_changes_asks_too(view):
    _edit(view)
    edited = view.model.document
    assert not view.upload("other.json", EXAMPLE1.read_bytes())
    assert view.pending_open is not None and view.model.document is edited
    assert view.answer_unsaved("discard")
    assert view.model.document is not edited and not view.model.dirty
    assert view.message == "opened other.json"


def test_a_design_with_no_file_is_saved_as_a_download_before_opening(data_home):
    server = EditorServer(port=0)
    try:
        view = server.new_view(server.server)
        _edit(view)
        sent = []
        view.target.send_file_download = lambda name, data, **kw: sent.append(name)
        assert not view.open_example("puma")
        assert view.answer_unsaved("save")
        assert sent and sent[0].endswith(".json") and not view.model.dirty
        view.close()
    finally:
        server.stop()


def test_the_page_is_told_when_closing_it_would_lose_changes(view, monkeypatch):
    sent = []
    interface = view.target.gui._websock_interface
    queue = interface.queue_message

    def capture(message):
        if hasattr(message, "source"):
            sent.append(message.source)
        return queue(message)

    monkeypatch.setattr(interface, "queue_message", capture)
    assert view._unsaved_shown is False
    _edit(view)
    assert view._unsaved_shown is True and "window.__kinegami.unsaved = true" in sent[-1]
    assert "beforeunload" in sent[-1]
    view.act(view.model.undo)
    assert view._unsaved_shown is False and sent[-1].endswith("unsaved = false;\n")
