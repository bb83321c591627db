"""Publishing a build (kinegami.export.publish): all or nothing under every interrupt.

The old build in the folder has a file and a folder that the new build replaces, plus a user
file the build does not write; the new build also adds a file. Every test checks that the
folder ends up holding exactly the old entries with their old contents, or exactly the new
ones, and that no hidden staging folder is left once the next build (or :func:`recover`) ran.
Interrupts are injected at every move (in-process: exceptions and OSErrors, also inside the
rollback) and sent as real signals (SIGINT, SIGTERM, SIGKILL) to a forked process paused
before each publishing step by the documented test hook.
"""

from __future__ import annotations

import errno
import os
import select
import signal
import sys
import threading
import time
from pathlib import Path

import pytest

from kinegami.errors import KinegamiError
from kinegami.export import publish
from kinegami.export.publish import (
    PAUSE_HOOK,
    PREFIX,
    PublishError,
    deferred_signals,
    open_staging,
    recover,
    staging_folder,
)

pytestmark = [
    pytest.mark.skipif(publish.fcntl is None, reason="needs POSIX flock"),
    # the forked children only move files (Python 3.12 warns about fork with BLAS threads)
    pytest.mark.filterwarnings("ignore:This process .* is multi-threaded:DeprecationWarning"),
]

OLD = {"a.txt": b"old a", "m/x.bin": b"old x", "m/sub/y.bin": b"old y", "keep.txt": b"user's"}
NEW = {"a.txt": b"new a", "m/z.bin": b"new z", "n.txt": b"new n"}
#: Steps of publishing NEW over OLD: the journal, a.txt aside and in, m aside and in, n.txt in,
#: the commit.
STEPS = 7
SIGNALS = {"SIGINT": signal.SIGINT, "SIGTERM": signal.SIGTERM, "SIGKILL": signal.SIGKILL}


def snapshot(folder: Path) -> dict[str, bytes | None]:
    """Every entry below ``folder`` (hidden ones included): file contents, None for folders."""
    found: dict[str, bytes | None] = {}
    for root, dirs, files in os.walk(folder):
        for name in dirs:
            found[os.path.relpath(os.path.join(root, name), folder)] = None
        for name in files:
            path = os.path.join(root, name)
            found[os.path.relpath(path, folder)] = Path(path).read_bytes()
    return found


def tree(files: dict[str, bytes]) -> dict[str, bytes | None]:
    """What :func:`snapshot` gives for a folder holding ``files``."""
    found: dict[str, bytes | None] = dict(files)
    for name in files:
        parts = name.split("/")[:-1]
        for i in range(1, len(parts) + 1):
            found[os.path.join(*parts[:i])] = None
    return found


def old_state() -> dict[str, bytes | None]:
    return tree(OLD)


def new_state() -> dict[str, bytes | None]:
    return tree({**NEW, "keep.txt": OLD["keep.txt"]})


def write_files(folder: Path, files: dict[str, bytes]) -> None:
    for name, data in files.items():
        path = folder / name
        path.parent.mkdir(parents=True, exist_ok=True)
        path.write_bytes(data)


@pytest.fixture
def out(tmp_path) -> Path:
    folder = tmp_path / "out"
    write_files(folder, OLD)
    return folder


def leftovers(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir() if p.name.startswith(PREFIX))


def build(out: Path, remove=()) -> list[Path]:
    """A whole build: stage NEW, publish (removing ``remove``), close."""
    with staging_folder(out) as staging:
        write_files(staging.new, NEW)
        return staging.publish(remove=remove)


class Moves:
    """Replaces publish._move: counts the calls and fails the ones listed."""

    def __init__(self, fail: dict[int, BaseException], after: bool = False, from_on=None):
        self.fail, self.after, self.from_on = fail, after, from_on
        self.calls = 0
        self.real = publish._move

    def __call__(self, src, dst):
        index = self.calls
        self.calls += 1
        error = self.fail.get(index)
        if error is None and self.from_on is not None and index >= self.from_on:
            error = PermissionError(errno.EACCES, "Permission denied", str(dst))
        if error is not None and not self.after:
            raise error
        self.real(src, dst)
        if error is not None:
            raise error


def test_publish_replaces_the_old_build(out):
    written = build(out)
    assert [p.name for p in written] == ["a.txt", "m", "n.txt"]
    assert snapshot(out) == new_state()


def test_publish_into_a_new_folder_creates_it(tmp_path):
    target = tmp_path / "a" / "b"
    build(target)
    assert snapshot(target) == tree(NEW)


def test_the_step_count_matches_the_plan(out, monkeypatch):
    moves = Moves({})
    monkeypatch.setattr(publish, "_move", moves)
    build(out)
    assert moves.calls == STEPS


# --- in-process: an exception at every move ----------------------------------------------------
@pytest.mark.parametrize("after", [False, True], ids=["before-move", "after-move"])
@pytest.mark.parametrize("kind", ["KeyboardInterrupt", "SystemExit", "OSError"])
@pytest.mark.parametrize("index", range(STEPS))
def test_an_exception_at_any_move_leaves_the_old_build(out, monkeypatch, index, kind, after):
    error = {
        "KeyboardInterrupt": KeyboardInterrupt(),
        "SystemExit": SystemExit(143),
        "OSError": PermissionError(errno.EACCES, "Permission denied", "x"),
    }[kind]
    monkeypatch.setattr(publish, "_move", Moves({index: error}, after=after))
    expected = PublishError if kind == "OSError" else type(error)
    with pytest.raises(expected) as info:
        build(out)
    if kind == "OSError":
        assert isinstance(info.value, KinegamiError) and isinstance(info.value, OSError)
        assert "Permission denied" in str(info.value) and "as before" in str(info.value)
    assert snapshot(out) == old_state()


@pytest.mark.parametrize("index", range(STEPS))
def test_a_rollback_that_fails_keeps_the_backups_for_the_next_build(out, monkeypatch, index):
    """Every move from ``index`` on fails, the rollback's too: the finally must not delete
    the old files still in the staging folder, and the next build puts them back."""
    monkeypatch.setattr(publish, "_move", Moves({}, from_on=index))
    with pytest.raises(PublishError) as info:
        build(out)
    monkeypatch.undo()
    kept = leftovers(out)
    if index == 0:  # the journal could not be written: nothing had moved
        assert not kept and "as before" in str(info.value)
    else:
        assert len(kept) == 1 and "put back" in str(info.value) and kept[0] in str(info.value)
    # every old entry is still somewhere: in the folder or in a staging folder's old/
    here = snapshot(out)
    for name, data in old_state().items():
        spots = [name] + [os.path.join(k, "old", name) for k in kept]
        assert any(here.get(spot, b"missing") == data for spot in spots), name
    note = recover(out)
    assert snapshot(out) == old_state()
    assert (note is not None) == bool(kept)
    build(out)
    assert snapshot(out) == new_state()


@pytest.mark.parametrize("index", range(STEPS))
def test_a_second_interrupt_inside_the_rollback_is_recovered(out, monkeypatch, index):
    """Interrupt the publish at ``index`` and then the rollback at each of its moves."""
    # how many moves the rollback of an interrupt at `index` makes
    counter = Moves({index: KeyboardInterrupt()})
    monkeypatch.setattr(publish, "_move", counter)
    with pytest.raises(KeyboardInterrupt):
        build(out)
    rollback_moves = counter.calls - index - 1
    assert snapshot(out) == old_state()
    for j in range(rollback_moves):
        monkeypatch.setattr(
            publish,
            "_move",
            Moves({index: KeyboardInterrupt(), index + 1 + j: KeyboardInterrupt()}),
        )
        with pytest.raises(KeyboardInterrupt):
            build(out)
        assert leftovers(out), "the staging folder with the backups must stay"
        monkeypatch.setattr(publish, "_move", counter.real)
        assert recover(out) is not None
        assert snapshot(out) == old_state()


@pytest.fixture
def sigterm_exits():
    """SIGTERM raises SystemExit(143) in this process, as under the kinegami command."""
    previous = signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
    yield
    signal.signal(signal.SIGTERM, previous)


class SignalAfterMove(Moves):
    """Sends a real signal to this process right after move ``at`` (and may first fail
    move ``fail_at`` with an exception, to start a rollback)."""

    def __init__(self, at: int, signum: int, fail_at: int | None = None):
        super().__init__({} if fail_at is None else {fail_at: KeyboardInterrupt()})
        self.at, self.signum = at, signum

    def __call__(self, src, dst):
        index = self.calls
        super().__call__(src, dst)
        if index == self.at:
            os.kill(os.getpid(), self.signum)


@pytest.mark.usefixtures("sigterm_exits")
@pytest.mark.parametrize("name", ["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("index", range(STEPS))
def test_a_signal_during_any_move_waits_for_the_moves(out, monkeypatch, index, name):
    """A real signal that arrives while a move runs: the moves stop and are undone (before the
    commit) or finish (the commit itself); the signal then takes effect; nothing is left."""
    monkeypatch.setattr(publish, "_move", SignalAfterMove(index, SIGNALS[name]))
    with pytest.raises(KeyboardInterrupt if name == "SIGINT" else SystemExit):
        build(out)
    committed = index == STEPS - 1
    assert snapshot(out) == (new_state() if committed else old_state())


@pytest.mark.usefixtures("sigterm_exits")
@pytest.mark.parametrize("name", ["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("index", range(1, STEPS))
def test_a_signal_during_the_rollback_lets_it_finish(out, monkeypatch, index, name):
    """Publishing fails at ``index``; a real signal arrives during each move of the rollback:
    the rollback still completes, and no staging folder is left."""
    probe = Moves({index: KeyboardInterrupt()})
    monkeypatch.setattr(publish, "_move", probe)
    with pytest.raises(KeyboardInterrupt):
        build(out)
    assert probe.calls > index + 1  # at least the journal is retired
    for at in range(index + 1, probe.calls):
        monkeypatch.setattr(publish, "_move", SignalAfterMove(at, SIGNALS[name], fail_at=index))
        with pytest.raises((KeyboardInterrupt, SystemExit)):
            build(out)
        assert snapshot(out) == old_state(), at


# --- real signals at every step (forked processes, the test hook) -------------------------------
def _child(out: Path, step: int, write_end: int, remove=()) -> None:
    """In a forked process: build NEW into ``out``, paused before ``step``; never returns."""
    code = 0
    try:
        os.dup2(write_end, 2)
        os.environ[PAUSE_HOOK] = str(step)
        signal.signal(signal.SIGINT, signal.default_int_handler)
        signal.signal(signal.SIGTERM, lambda signum, frame: sys.exit(128 + signum))
        build(out, remove)
    except KeyboardInterrupt:
        code = 130
    except SystemExit as stop:
        code = stop.code
    except BaseException:
        code = 99
    finally:
        os._exit(code)


def run_paused(out: Path, step: int, signum: int, remove=()) -> int:
    """Fork a build paused before ``step``, send ``signum`` and return its wait status."""
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        os.close(read_end)
        _child(out, step, write_end, remove)
    os.close(write_end)
    try:
        ready, _, _ = select.select([read_end], [], [], 60)
        assert ready, "the child did not pause"
        line = os.read(read_end, 200).decode()
        assert f"paused before publishing step {step}" in line
        os.kill(pid, signum)
        _, status = os.waitpid(pid, 0)
    finally:
        os.close(read_end)
    return status


@pytest.mark.parametrize("name", ["SIGINT", "SIGTERM"])
@pytest.mark.parametrize("step", range(STEPS))
def test_a_signal_at_any_step_leaves_the_old_build(out, step, name):
    status = run_paused(out, step, SIGNALS[name])
    assert os.WIFEXITED(status) and os.WEXITSTATUS(status) == 128 + SIGNALS[name]
    assert snapshot(out) == old_state()  # nothing left behind either


@pytest.mark.parametrize("step", range(STEPS))
def test_sigkill_at_any_step_is_recovered_by_the_next_build(out, step):
    status = run_paused(out, step, signal.SIGKILL)
    assert os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGKILL
    kept = leftovers(out)
    assert len(kept) == 1
    here = snapshot(out)
    for name, data in old_state().items():  # every old entry is somewhere
        assert data == here.get(name, b"-") or data == here.get(f"{kept[0]}/old/{name}", b"-")
    note = recover(out)
    assert note.startswith(f"an earlier build into {str(out)!r} was interrupted; ")
    assert note.endswith("; removed its hidden staging folder")
    if step >= 2:  # a.txt was moved aside
        assert "put back the earlier a.txt" in note
    assert snapshot(out) == old_state()
    build(out)
    assert snapshot(out) == new_state()


def test_a_recovery_that_fails_keeps_the_leftover(out, monkeypatch):
    run_paused(out, 4, signal.SIGKILL)  # a.txt replaced, m moved aside
    kept = leftovers(out)
    monkeypatch.setattr(publish, "_move", Moves({}, from_on=1))  # the first move back works
    with pytest.raises(PublishError, match="cannot put back the files") as info:
        build(out)
    assert f"{kept[0]}/old" in str(info.value)
    monkeypatch.undo()
    assert leftovers(out) == kept
    assert "put back the earlier a.txt;" in recover(out)  # m went back on the first try
    assert snapshot(out) == old_state()


def test_sigkill_of_a_first_build_is_recovered(tmp_path):
    target = tmp_path / "fresh"
    status = run_paused(target, 3, signal.SIGKILL)  # journal, n... : two entries are in
    assert os.WIFSIGNALED(status)
    note = recover(target)
    assert "took out the half-published a.txt, m;" in note
    assert snapshot(target) == {}


# --- builds running at the same time -----------------------------------------------------------
def test_a_running_build_is_left_alone(out):
    first = open_staging(out)
    try:
        write_files(first.new, NEW)
        assert recover(out) is None  # its staging folder is locked
        build(out)  # another build meanwhile
        assert first.path.is_dir() and sorted(snapshot(first.new)) == sorted(tree(NEW))
        first.publish()
    finally:
        first.close()
    assert snapshot(out) == new_state()


def test_a_build_waits_for_another_build_publishing(out):
    """A build paused while publishing holds the folder: recovery waits for it to finish."""
    read_end, write_end = os.pipe()
    pid = os.fork()
    if pid == 0:  # pragma: no cover - the child
        os.close(read_end)
        _child(out, 3, write_end)
    os.close(write_end)
    try:
        assert select.select([read_end], [], [], 60)[0]
        os.read(read_end, 200)
        result = []
        waiter = threading.Thread(target=lambda: result.append(recover(out)))
        waiter.start()
        time.sleep(0.3)
        assert waiter.is_alive() and not result  # blocked on the folder's lock
        os.kill(pid, signal.SIGTERM)
        os.waitpid(pid, 0)
        waiter.join(30)
    finally:
        os.close(read_end)
    assert result == [None]  # the other build rolled itself back and cleaned up
    assert snapshot(out) == old_state()


def test_leftovers_without_a_journal_are_removed(out):
    garbage = out / f"{PREFIX}99999999-abcd1234"
    write_files(garbage / "new", {"a.txt": b"half written"})
    note = recover(out)
    assert note.endswith("was interrupted; removed its hidden staging folder")
    assert snapshot(out) == old_state()


def test_other_hidden_folders_are_not_touched(out):
    (out / f"{PREFIX}notes").mkdir()
    (out / ".kinegami-build-123").write_text("a file")
    assert recover(out) is None
    assert (out / f"{PREFIX}notes").is_dir() and (out / ".kinegami-build-123").is_file()


def test_an_unreadable_journal_stops_the_build(out):
    staging = out / f"{PREFIX}99999999-abcd1234"
    write_files(staging, {"journal.json": b"{not json", "old/a.txt": b"older"})
    with pytest.raises(PublishError, match="cannot read the journal"):
        build(out)
    assert (staging / "old" / "a.txt").read_bytes() == b"older"


# --- deferred_signals ---------------------------------------------------------------------------
def test_signals_wait_for_the_end_of_the_block():
    previous = signal.getsignal(signal.SIGINT)
    reached = False
    with pytest.raises(KeyboardInterrupt):
        with deferred_signals() as received:
            os.kill(os.getpid(), signal.SIGINT)
            time.sleep(0.01)
            assert received == [signal.SIGINT]
            reached = True
    assert reached
    assert signal.getsignal(signal.SIGINT) is previous


def test_an_ignored_signal_stays_ignored():
    previous = signal.signal(signal.SIGHUP, signal.SIG_IGN)
    try:
        with deferred_signals() as received:
            os.kill(os.getpid(), signal.SIGHUP)
            time.sleep(0.01)
        assert received == []
    finally:
        signal.signal(signal.SIGHUP, previous)


def test_nested_blocks_deliver_once_at_the_outer_end():
    with pytest.raises(KeyboardInterrupt):
        with deferred_signals():
            with deferred_signals() as inner:
                os.kill(os.getpid(), signal.SIGINT)
                time.sleep(0.01)
            assert inner == [signal.SIGINT]  # not delivered yet


# --- write_atomic_files (the URDF and its mesh folder) ------------------------------------------
def test_write_atomic_files_rolls_back_on_a_signal(tmp_path, monkeypatch):
    from kinegami.export import registry

    main = tmp_path / "r.urdf"
    write_files(tmp_path, {"r.urdf": b"old urdf", "r_meshes/a.stl": b"old a"})
    before = snapshot(tmp_path)
    real = os.replace

    def replace_then_signal(src, dst):
        real(src, dst)
        if os.fspath(dst) == os.fspath(tmp_path / "r_meshes"):
            os.kill(os.getpid(), signal.SIGINT)  # arrives after the folder moved in

    monkeypatch.setattr(os, "replace", replace_then_signal)
    with pytest.raises(KeyboardInterrupt):
        registry.write_atomic_files(main, {"r.urdf": b"new", "r_meshes/b.stl": b"new b"})
    monkeypatch.undo()
    assert snapshot(tmp_path) == before


@pytest.mark.parametrize("link", [False, True])
def test_a_file_never_replaces_a_folder_of_the_user(tmp_path, link):
    """The build would put the file n.txt where the user has a folder n.txt: refused before
    anything moves, the folder and everything else as before. A symbolic link named n.txt
    is an entry like a file: replaced, and the folder it points to is not touched."""
    out = tmp_path / "out"
    write_files(out, OLD)
    if link:
        write_files(tmp_path / "elsewhere", {"data.txt": b"mine"})
        (out / "n.txt").symlink_to(tmp_path / "elsewhere", target_is_directory=True)
        build(out)
        assert (out / "n.txt").read_bytes() == NEW["n.txt"]
        assert (tmp_path / "elsewhere" / "data.txt").read_bytes() == b"mine"
        return
    write_files(out, {"n.txt/sub/data.txt": b"mine"})
    before = snapshot(out)
    with pytest.raises(PublishError, match=r"n\.txt' is a folder with files in it.*move or"):
        build(out)
    assert snapshot(out) == before
    assert leftovers(out) == []


def test_a_file_replaces_an_empty_folder(out):
    (out / "n.txt").mkdir()
    build(out)
    assert snapshot(out) == new_state()


def test_a_folder_replaces_a_folder(out):
    """As the URDF's meshes folder replaces the last build's: m/ is replaced whole."""
    build(out)
    assert not (out / "m" / "sub").exists() and (out / "m" / "z.bin").read_bytes() == b"new z"


# --- files of an earlier build removed in the same transaction -----------------------------------
#: A file an earlier build wrote that the new one replaces by others (arm_bed_3.dxf when the new
#: build needs two beds); the build also names a file it writes, a missing one and a folder.
STALE = {"arm_bed_3.dxf": b"old bed 3"}
REMOVE = ["arm_bed_3.dxf", "a.txt", "missing.txt", "m"]
#: The journal, a.txt aside and in, m aside and in, n.txt in, arm_bed_3.dxf aside, the commit.
REMOVE_STEPS = STEPS + 1


@pytest.fixture
def stale_out(out) -> Path:
    write_files(out, STALE)
    return out


def test_publish_removes_the_files_it_is_told_to(stale_out, monkeypatch):
    moves = Moves({})
    monkeypatch.setattr(publish, "_move", moves)
    written = build(stale_out, REMOVE)
    assert [p.name for p in written] == ["a.txt", "m", "n.txt"]
    assert snapshot(stale_out) == new_state()  # the stale file gone; the folder m is the new one
    assert moves.calls == REMOVE_STEPS


@pytest.mark.parametrize("index", range(REMOVE_STEPS))
def test_an_error_at_any_move_keeps_the_file_to_remove(stale_out, monkeypatch, index):
    error = PermissionError(errno.EACCES, "Permission denied", "x")
    monkeypatch.setattr(publish, "_move", Moves({index: error}))
    with pytest.raises(PublishError):
        build(stale_out, REMOVE)
    assert snapshot(stale_out) == tree({**OLD, **STALE})


@pytest.mark.parametrize("step", range(REMOVE_STEPS))
def test_sigkill_while_removing_is_recovered(stale_out, step):
    status = run_paused(stale_out, step, signal.SIGKILL, REMOVE)
    assert os.WIFSIGNALED(status) and os.WTERMSIG(status) == signal.SIGKILL
    assert recover(stale_out) is not None
    assert snapshot(stale_out) == tree({**OLD, **STALE})


def test_a_journal_of_an_earlier_version_is_still_recovered(out):
    """Journals written before removals existed have no "new" key: every entry was written."""
    staging = out / f"{PREFIX}1-old"
    (staging / "new").mkdir(parents=True)
    (staging / "old").mkdir()
    os.replace(out / "a.txt", staging / "old" / "a.txt")
    (out / "a.txt").write_bytes(b"half-published a")
    (staging / "journal.json").write_text(
        '{"format": "kinegami-build-journal", "version": 1, '
        '"entries": [{"name": "a.txt", "old": true}]}', encoding="utf-8")
    assert "put back the earlier a.txt" in recover(out)
    assert snapshot(out) == old_state()


def test_a_name_with_a_folder_is_not_removed(out):
    with pytest.raises(PublishError, match="not a file name"):
        build(out, ["m/x.bin"])
    assert snapshot(out) == old_state()
