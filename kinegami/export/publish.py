"""Publishing a build into a folder as one transaction that no interrupt can tear.

``kinegami build DESIGN -o OUT`` writes every output into a hidden staging folder inside
``OUT`` and then publishes it: the entries of ``OUT`` with the same names are moved aside into
the staging folder and the new ones moved in. This module makes that step all or nothing,
whatever stops it (an error, Ctrl-C, SIGTERM, SIGHUP, SIGKILL or a crash).

Layout of a staging folder::

    OUT/.kinegami-build-<pid>-<random>/
        new/           the outputs, as the exporters wrote them
        old/           entries of OUT with the same names, moved aside while publishing
        journal.json   the plan, written before the first move: the names in order, and
                       which of them existed in OUT (so had to be moved aside)

Publishing is a list of steps, each one :func:`os.replace` (atomic): step 0 writes the
journal; then for each name in order the old entry (if the journal says there is one) goes
into ``old/`` and the new one into ``OUT``; the last step renames the journal to
``journal.done``, which is the commit. After any prefix of these steps, where the files are
tells which moves were done: a name is moved aside if it is in ``old/``, moved in if it is no
longer in ``new/``. Rolling back undoes the done moves in reverse order, so a rollback that is
itself cut short again leaves a prefix of the plan.

* An error, Ctrl-C, SIGTERM or SIGHUP before the commit: signals are deferred while the steps
  run (the Python handlers only record them); the steps stop, the done moves are undone, and
  then the signal is delivered (Ctrl-C raises :class:`KeyboardInterrupt`, a signal with the
  default action ends the process). ``OUT`` is exactly as before.
* SIGKILL or a crash of the process: the staging folder stays. The next build into ``OUT``
  (:func:`recover`, run when a staging folder is opened) rolls back every staging folder left
  with a journal, and removes those without one: before the journal they hold only new files,
  after the commit only the replaced old ones.
* Builds running at the same time: each build holds an exclusive ``flock`` on its own staging
  folder for as long as it runs, and on ``OUT`` itself while it recovers, creates its staging
  folder or publishes. A leftover is touched only once its lock can be taken, that is when its
  build is gone (the kernel drops the locks of a dead process); two builds into one folder
  publish one after the other. Where ``flock`` is unavailable (Windows, some network file
  systems) leftovers are never touched.
* A crash of the whole machine is not covered: nothing is flushed to disk (no ``fsync``), so
  the file system may not keep the order of the moves.

Entries of ``OUT`` that the new build does not write are never touched, except those it names
to remove (``publish(remove=...)``: files an earlier build wrote that this one replaces by
others, such as ``arm_bed_3.dxf`` when the new build needs two beds): they are moved aside like
the replaced entries, in the same transaction, and come back on a rollback. A folder of
``OUT`` with anything in it is replaced only by a folder of the same name (a URDF's meshes):
where the build would put a file in its place, publishing is refused before anything moves (an
empty folder in the way is replaced: nothing is lost).

Test hook: if the environment variable ``KINEGAMI_TEST_PAUSE_BEFORE_STEP`` is set to a step
number k, publishing writes ``kinegami: test hook: paused before publishing step k`` to
standard error and waits (at most 60 s) until a signal arrives, so that tests can interrupt a
real process at each step. It changes nothing else and is meant for tests only.
"""

from __future__ import annotations

import errno
import json
import os
import re
import signal
import tempfile
import threading
import time
from collections.abc import Iterable, Iterator
from contextlib import contextmanager
from pathlib import Path

from kinegami._atomic import discard_tree
from kinegami.errors import ExportError, PublishError

try:
    import fcntl
except ImportError:  # pragma: no cover - Windows: no flock, leftovers are left alone
    fcntl = None

__all__ = [
    "PublishError",
    "Staging",
    "deferred_signals",
    "open_staging",
    "recover",
    "staging_folder",
]

#: Name prefix of the staging folders.
PREFIX = ".kinegami-build-"
_STAGING_NAME = re.compile(re.escape(PREFIX) + r"[0-9]+-[a-z0-9_]+\Z")
JOURNAL = "journal.json"
#: Environment variable of the test hook (see the module docstring).
PAUSE_HOOK = "KINEGAMI_TEST_PAUSE_BEFORE_STEP"
#: Signals deferred while files move; SIGKILL cannot be caught.
DEFERRED_SIGNALS = tuple(
    getattr(signal, name) for name in ("SIGINT", "SIGTERM", "SIGHUP") if hasattr(signal, name)
)


# --- deferring signals -------------------------------------------------------------------------
_received: list[int] | None = None  # signals held back by the active deferred_signals()


def _deliver(signum: int, handler, frame) -> None:
    """Run what ``signum`` would have done under ``handler``."""
    if callable(handler):
        handler(signum, frame)
    elif handler == signal.SIG_DFL:
        signal.signal(signum, signal.SIG_DFL)
        signal.raise_signal(signum)


@contextmanager
def deferred_signals() -> Iterator[list[int]]:
    """Hold back SIGINT, SIGTERM and SIGHUP inside the block and deliver them on leaving it.

    Yields the list of the signal numbers received so far, so that the block can stop early.
    On exit the earlier handlers are back in place and the first signal received is handed to
    its handler: Ctrl-C raises :class:`KeyboardInterrupt`, a signal with the default action ends
    the process, an ignored signal stays ignored. Nested blocks share the outer one. Outside
    the main thread (where Python cannot set handlers) nothing is deferred.
    """
    global _received
    if _received is not None:
        yield _received
        return
    if threading.current_thread() is not threading.main_thread():
        yield []
        return
    received: list[int] = []
    previous: dict[int, object] = {}
    holding = True

    def hold(signum, frame):
        if holding:
            received.append(signum)
        else:  # left the block while this handler was still installed
            _deliver(signum, previous[signum], frame)

    try:
        for signum in DEFERRED_SIGNALS:
            handler = signal.getsignal(signum)
            if handler is None or handler == signal.SIG_IGN:
                continue  # not set from Python, or ignored: leave it
            previous[signum] = handler
            signal.signal(signum, hold)
        _received = received
        yield received
    finally:
        _received = None
        holding = False
        for signum, handler in previous.items():
            signal.signal(signum, handler)
        if received:
            _deliver(received[0], previous[received[0]], None)


def _pause_for_test(step: int, received: list[int]) -> None:
    """The test hook: wait before ``step`` if KINEGAMI_TEST_PAUSE_BEFORE_STEP names it."""
    if os.environ.get(PAUSE_HOOK, "").strip() != str(step):
        return
    os.write(2, f"kinegami: test hook: paused before publishing step {step}\n".encode())
    deadline = time.monotonic() + 60.0
    while not received and time.monotonic() < deadline:
        time.sleep(0.01)


# --- locks -------------------------------------------------------------------------------------
def _open_folder(path: Path) -> int:
    return os.open(path, os.O_RDONLY | getattr(os, "O_DIRECTORY", 0))


def _flock(fd: int, block: bool) -> bool | None:
    """Take an exclusive lock on ``fd``: True if taken, False if another process holds it,
    None if this file system (or platform) has no locks."""
    if fcntl is None:  # pragma: no cover - Windows
        return None
    try:
        fcntl.flock(fd, fcntl.LOCK_EX | (0 if block else fcntl.LOCK_NB))
    except BlockingIOError:
        return False
    except OSError as exc:
        if exc.errno in (errno.ENOLCK, errno.EOPNOTSUPP, errno.ENOSYS, errno.EINVAL):
            return None
        raise
    return True


@contextmanager
def _folder_lock(folder: Path) -> Iterator[None]:
    """Hold the lock on ``folder`` itself (waits for another build's publish to finish)."""
    if fcntl is None:  # pragma: no cover - Windows: folders cannot be opened or locked
        yield
        return
    fd = _open_folder(folder)
    try:
        _flock(fd, block=True)
        yield
    finally:
        os.close(fd)


# --- moves -------------------------------------------------------------------------------------
def _move(src: Path, dst: Path) -> None:
    """Every move of publishing and recovery goes through here (one :func:`os.replace`)."""
    os.replace(src, dst)


#: A journal entry: the name, whether ``OUT`` holds an entry of that name (moved aside), and
#: whether the build writes one (moved in; False for a file the build removes).
Entry = tuple[str, bool, bool]


def _plan_steps(entries: list[Entry]) -> list[tuple[str, str]]:
    """The moves of a journal, in order: ("aside", name) and ("in", name)."""
    steps = []
    for name, old, new in entries:
        if old:
            steps.append(("aside", name))
        if new:
            steps.append(("in", name))
    return steps


def _rollback(out: Path, staging: Path, entries: list[Entry]) -> tuple[list, list]:
    """Undo the done moves of ``entries`` in reverse order; return (withdrawn, restored)
    names. Which moves were done is read from where the files are."""
    new, old = staging / "new", staging / "old"
    withdrawn: list[str] = []
    restored: list[str] = []
    for kind, name in reversed(_plan_steps(entries)):
        if kind == "in" and not os.path.lexists(new / name):
            _move(out / name, new / name)
            withdrawn.append(name)
        elif kind == "aside" and os.path.lexists(old / name):
            _move(old / name, out / name)
            restored.append(name)
    return withdrawn, restored


def _read_journal(staging: Path) -> list[Entry] | None:
    """The plan in ``staging``'s journal, or None if there is no journal."""
    try:
        text = (staging / JOURNAL).read_text(encoding="utf-8")
    except FileNotFoundError:
        return None
    try:
        data = json.loads(text)
        entries = [(str(item["name"]), bool(item["old"]), bool(item.get("new", True)))
                   for item in data["entries"]]  # fmt: skip
    except (ValueError, KeyError, TypeError) as exc:
        raise PublishError(
            f"cannot read the journal of an interrupted build in {str(staging)!r} ({exc}); "
            "move its old/ entries back by hand, then delete the folder"
        ) from None
    for name, _, _ in entries:
        if not name or name in (".", "..") or "/" in name or (os.sep in name):
            raise PublishError(f"the journal in {str(staging)!r} names {name!r}: not a file name")
    return entries


def _retire(staging: Path) -> None:
    """Mark a rolled back or committed staging folder as garbage, then remove it."""
    if os.path.lexists(staging / JOURNAL):
        _move(staging / JOURNAL, staging / "journal.done")
    discard_tree(staging)


def _is_folder(path: Path) -> bool:
    """Whether ``path`` is a folder itself (not a symbolic link to one)."""
    return path.is_dir() and not path.is_symlink()


def _holds_files(path: Path) -> bool:
    """Whether ``path`` is a folder itself (not a symbolic link) with anything in it."""
    if not _is_folder(path):
        return False
    with os.scandir(path) as entries:
        return next(entries, None) is not None


def _names(names: list[str], limit: int = 4) -> str:
    shown = ", ".join(names[:limit])
    return shown + (f" and {len(names) - limit} more" if len(names) > limit else "")


# --- recovery ----------------------------------------------------------------------------------
def _recover_locked(out: Path) -> str | None:
    """:func:`recover` with ``out``'s lock held and signals deferred."""
    try:
        leftovers = sorted(
            entry.name
            for entry in os.scandir(out)
            if _STAGING_NAME.match(entry.name) and entry.is_dir(follow_symlinks=False)
        )
    except FileNotFoundError:
        return None
    withdrawn: list[str] = []
    restored: list[str] = []
    removed = 0
    if fcntl is None:  # pragma: no cover - Windows: no way to tell a running build
        leftovers = []
    for name in leftovers:
        staging = out / name
        try:
            fd = _open_folder(staging)
        except FileNotFoundError:
            continue  # its build removed it meanwhile
        try:
            if not _flock(fd, block=False):
                continue  # a build that is still running, or no locks here: leave it
            entries = _read_journal(staging)
            try:
                if entries is not None:
                    undone = _rollback(out, staging, entries)
                    withdrawn += undone[0]
                    restored += undone[1]
                _retire(staging)
            except OSError as exc:
                raise PublishError(
                    exc.errno,
                    f"cannot put back the files of an interrupted build into {str(out)!r} "
                    f"({exc.strerror or exc}); they are in {str(staging / 'old')!r}",
                    exc.filename,
                ) from None
            removed += 1
        finally:
            os.close(fd)
    if not removed:
        return None
    parts = []
    if restored:
        parts.append(f"put back the earlier {_names(sorted(restored))}")
    new_only = sorted(set(withdrawn) - set(restored))
    if new_only:
        parts.append(f"took out the half-published {_names(new_only)}")
    if removed == 1:
        what = f"an earlier build into {str(out)!r} was interrupted"
        parts.append("removed its hidden staging folder")
    else:
        what = f"{removed} earlier builds into {str(out)!r} were interrupted"
        parts.append("removed their hidden staging folders")
    return "; ".join([what, *parts])


def recover(out: str | os.PathLike) -> str | None:
    """Undo what builds into ``out`` that were killed (SIGKILL, a crash) left behind.

    Every ``.kinegami-build-*`` staging folder in ``out`` whose build is no longer running is
    rolled back from its journal (the earlier files go back in place, half-published new
    ones come out) or, without a journal, removed. Folders of builds still running are left
    alone. Runs with ``out`` locked and signals deferred.

    Returns
    -------
    str or None
        One line saying what was recovered, or None if there was nothing to do.

    Raises
    ------
    PublishError
        If a leftover cannot be rolled back (its files stay where they are, for the next try).
    """
    out = Path(out)
    if not out.is_dir() or fcntl is None:
        return None
    with _folder_lock(out), deferred_signals():
        return _recover_locked(out)


# --- publishing --------------------------------------------------------------------------------
class Staging:
    """A build's staging folder inside ``out``; made by :func:`staging_folder`.

    Attributes
    ----------
    out : Path
        The output folder.
    path : Path
        The staging folder (``out/.kinegami-build-<pid>-<random>``).
    new : Path
        Where the outputs are written before :meth:`publish`.
    note : str or None
        What recovering earlier interrupted builds did (see :func:`recover`).
    """

    def __init__(self, out: Path, path: Path, fd: int | None, note: str | None):
        self.out = out
        self.path = path
        self.new = path / "new"
        self.note = note
        self.published = False
        self._fd = fd
        self._keep = False  # a rollback was cut short: the backups must stay
        self._created: list[Path] = []  # folders open_staging created, innermost first

    def publish(self, remove: Iterable[str] = ()) -> list[Path]:
        """Move every entry of :attr:`new` into :attr:`out`, all or nothing.

        Parameters
        ----------
        remove : iterable of str, optional
            Names of files in :attr:`out` to remove in the same transaction (files of an
            earlier build that this one does not write again); names the build writes, and
            names not in :attr:`out`, are skipped. Folders are never removed.

        Returns
        -------
        list of Path
            The published entries, by name.

        Raises
        ------
        PublishError
            If a move failed or a signal stopped publishing; ``out`` is as before (or, if even
            putting it back failed, the message says where the earlier files are; the next
            build puts them back).
        """
        if self.published:
            raise PublishError(f"{str(self.path)!r} is already published")
        out, staging = self.out, self.path
        names = sorted(os.listdir(self.new))
        removed = sorted(set(remove) - set(names))
        for name in removed:
            if not isinstance(name, str) or not name or name in (".", "..") or "/" in name or (
                    os.sep in name):  # fmt: skip
                raise PublishError(f"cannot remove {name!r} from {str(out)!r}: not a file name")
        with _folder_lock(out), deferred_signals() as received:
            for name in names:  # a file of the build never replaces a folder of the user's
                if _holds_files(out / name) and not _is_folder(self.new / name):
                    raise PublishError(
                        f"{str(out / name)!r} is a folder with files in it, and the build would "
                        f"replace it with a file of the same name; move or rename the folder "
                        f"(nothing was written, {str(out)!r} is as before)"
                    )
            entries = [(name, os.path.lexists(out / name), True) for name in names]
            entries += [(name, True, False) for name in removed
                        if os.path.lexists(out / name) and not _is_folder(out / name)]
            steps = _plan_steps(entries)
            try:
                self._step(0, received)
                journal = {
                    "format": "kinegami-build-journal",
                    "version": 1,
                    "entries": [{"name": name, "old": old, "new": new}
                                for name, old, new in entries],  # fmt: skip
                }
                (staging / "journal.tmp").write_text(json.dumps(journal), encoding="utf-8")
                _move(staging / "journal.tmp", staging / JOURNAL)
                for index, (kind, name) in enumerate(steps, start=1):
                    self._step(index, received)
                    if kind == "aside":
                        _move(out / name, staging / "old" / name)
                    else:
                        _move(self.new / name, out / name)
                self._step(len(steps) + 1, received)
                _move(staging / JOURNAL, staging / "journal.done")  # the commit
            except BaseException as exc:
                self._undo(entries)
                if isinstance(exc, _Interrupted):
                    # the signal itself is delivered when deferred_signals() ends
                    name = signal.Signals(exc.signum).name
                    raise PublishError(
                        f"publishing into {str(out)!r} was interrupted ({name}); "
                        "the folder is as before"
                    ) from None
                if isinstance(exc, OSError) and not isinstance(exc, ExportError):
                    where = exc.filename or out
                    raise PublishError(
                        exc.errno,
                        f"cannot write {str(where)!r}: {exc.strerror or exc}; "
                        f"{str(out)!r} is as before",
                        exc.filename,
                    ) from None
                raise
            self.published = True
        return [out / name for name in names]

    def _step(self, index: int, received: list[int]) -> None:
        _pause_for_test(index, received)
        if received:
            raise _Interrupted(received[0])

    def _undo(self, entries: list[Entry]) -> None:
        """Roll back, then retire the journal (so that removing the folder, even cut short,
        cannot leave a journal that no longer matches the files)."""
        try:
            _rollback(self.out, self.path, entries)
            if os.path.lexists(self.path / JOURNAL):
                _move(self.path / JOURNAL, self.path / "journal.done")
        except BaseException as exc:
            self._keep = True
            if isinstance(exc, OSError):
                raise PublishError(
                    exc.errno,
                    f"publishing into {str(self.out)!r} failed and the earlier files could not "
                    f"all be put back ({exc.strerror or exc}); they are in "
                    f"{str(self.path / 'old')!r}, and the next build into the folder puts "
                    "them back",
                    exc.filename,
                ) from None
            raise

    def close(self) -> None:
        """Remove the staging folder (unless it still holds earlier files that could not be
        put back) and release its lock; if nothing was published, also remove the folders
        :func:`open_staging` created, when empty."""
        with deferred_signals():
            if not self._keep:
                discard_tree(self.path)
            if self._fd is not None:
                os.close(self._fd)
                self._fd = None
            if not self.published:
                _remove_empty(self._created)
            self._created = []


class _Interrupted(BaseException):
    """A deferred signal stops publishing (internal; turned into a PublishError)."""

    def __init__(self, signum: int):
        super().__init__(signum)
        self.signum = signum


def _make_folder(out: Path) -> list[Path]:
    """Create ``out`` and its missing parents; return the created folders, innermost first."""
    missing = []
    path = out.absolute()
    while not os.path.lexists(path):
        missing.append(path)
        path = path.parent
    out.mkdir(parents=True, exist_ok=True)
    return missing


def _create_staging(out: Path, note: str | None) -> Staging:
    path = Path(tempfile.mkdtemp(prefix=f"{PREFIX}{os.getpid()}-", dir=out))
    fd = None
    try:
        if fcntl is not None:
            fd = _open_folder(path)
            _flock(fd, block=False)
        (path / "new").mkdir()
        (path / "old").mkdir()
    except BaseException:
        if fd is not None:
            os.close(fd)
        discard_tree(path)
        raise
    return Staging(out, path, fd, note)


def open_staging(out: str | os.PathLike) -> Staging:
    """Create ``out`` (and missing parents) and a locked staging folder in it.

    Earlier interrupted builds into ``out`` are recovered first (:attr:`Staging.note` says
    what was done). :meth:`Staging.close` removes the staging folder again, and the folders
    this call created if nothing was published and they are empty.

    Raises
    ------
    OSError
        If ``out`` cannot be created or written.
    PublishError
        If an earlier interrupted build cannot be recovered.
    """
    out = Path(out)
    created = _make_folder(out)
    try:
        with _folder_lock(out), deferred_signals():
            note = _recover_locked(out)
            staging = _create_staging(out, note)
            staging._created = created
            return staging
    except BaseException:
        _remove_empty(created)
        raise


def _remove_empty(folders: list[Path]) -> None:
    for folder in folders:  # innermost first
        try:
            folder.rmdir()
        except OSError:
            break


@contextmanager
def staging_folder(out: str | os.PathLike) -> Iterator[Staging]:
    """:func:`open_staging` as a context manager: the staging folder is closed on leaving.

    Examples
    --------
    >>> with staging_folder("out") as staging:  # doctest: +SKIP
    ...     (staging.new / "arm.txt").write_text("new")
    ...     staging.publish()
    """
    staging = open_staging(out)
    try:
        yield staging
    finally:
        staging.close()
