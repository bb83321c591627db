"""Work the editor does after a pause rather than on every change: :class:`Debounced`, and
:class:`ProcessWorker` and :class:`JobProcess` for work too slow to share the server's process.

A drag or an animation changes the document many times a second. What is not needed for each
step (the crease-pattern drawing, the autosave) is triggered on every change and runs once, in
a background thread, when no change came for ``delay`` seconds. Fitting a tree's junctions
takes seconds of pure Python; it runs in a worker process, so that it holds neither a tab's
lock nor the interpreter lock meanwhile. Long commands the user starts (Compact, a motion
check, Fit junctions) run in a :class:`JobProcess`, which relays their progress and stops
them on Cancel. See docs/editor.md.
"""

from __future__ import annotations

import atexit
import os
import signal
import threading
import time
import weakref
from collections.abc import Callable
from typing import Any

from kinegami.errors import Cancelled

__all__ = ["Debounced", "JobProcess", "ProcessWorker"]

#: Seconds between two progress reports a job process sends (the last one always goes).
PROGRESS_INTERVAL = 0.1
#: Seconds a cancelled job may take to stop by itself before its process is stopped.
CANCEL_GRACE = 1.0
#: How much lower the job process's CPU priority is (Unix ``nice``; the processes it starts,
#: e.g. compaction's, inherit it).
JOB_NICENESS = 5


class Debounced:
    """Call ``func()`` in a background thread ``delay`` seconds after the last :meth:`trigger`.

    ``func`` takes its own locks. An exception it raises is kept in :attr:`error` (the thread
    goes on). :meth:`flush` runs a pending call at once in the caller's thread, after waiting
    for a call in progress (so call it without holding a lock that ``func`` takes).
    """

    def __init__(self, func: Callable[[], object], delay: float, name: str = "debounced"):
        self._func = func
        self.delay = float(delay)
        self._name = name
        self._cond = threading.Condition()
        self._due: float | None = None  # when the pending call runs; None: none pending
        self._closed = False
        self._thread: threading.Thread | None = None
        self._running = threading.Lock()  # held while func runs (one call at a time)
        #: The last exception ``func`` raised in the background thread, or None.
        self.error: BaseException | None = None

    @property
    def pending(self) -> bool:
        """Whether a call is waiting to run."""
        return self._due is not None

    def trigger(self) -> None:
        """Ask for a call ``delay`` seconds from now (a later trigger moves it later)."""
        with self._cond:
            if self._closed:
                return
            self._due = time.monotonic() + self.delay
            if self._thread is None:
                self._thread = threading.Thread(target=self._loop, name=self._name, daemon=True)
                self._thread.start()
            self._cond.notify()

    def flush(self) -> bool:
        """Run the pending call now, in this thread, once a call in progress has finished;
        False when none was pending."""
        with self._cond:
            due, self._due = self._due, None
        with self._running:
            if due is None:
                return False
            self._func()
        return True

    def close(self, flush: bool = False) -> None:
        """Stop the thread (after running a pending call when ``flush``); a call in progress
        finishes before this returns (unless ``func`` itself closes), so nothing runs after."""
        if flush:
            self.flush()
        with self._cond:
            self._closed = True
            self._due = None
            self._cond.notify()
        if threading.current_thread() is not self._thread:
            with self._running:  # wait for a call in progress
                pass

    def _loop(self) -> None:
        while True:
            with self._cond:
                while not self._closed:
                    if self._due is None:
                        self._cond.wait()
                        continue
                    left = self._due - time.monotonic()
                    if left <= 0.0:
                        break
                    self._cond.wait(left)
                if self._closed:
                    return
                self._due = None
            try:
                with self._running:
                    if self._closed:  # closed while this call was about to start
                        return
                    self._func()
            except Exception as error:  # noqa: BLE001 - kept for the owner; the thread goes on
                self.error = error


class ProcessWorker:
    """Runs functions in a separate process, started on first use and shared by its callers.

    ``run(func, *args)`` sends ``func`` (by reference) and ``args`` (pickled) to the process
    and waits for its result, or its exception, raised again here. The process is a fresh
    interpreter (``"spawn"``, not a fork of the threaded server), so its warnings filters are
    its own: ``warnings.catch_warnings``, which the library uses, changes them for the whole
    process and is not thread-safe. A process that died is started again once.
    """

    def __init__(self, processes: int = 1):
        self._processes = int(processes)
        self._lock = threading.Lock()
        self._executor = None
        self._closed = False
        #: How many calls ran in the process (tests read it).
        self.calls = 0

    def _pool(self):
        import concurrent.futures
        import multiprocessing

        with self._lock:
            if self._closed:
                raise RuntimeError("the worker process was closed")
            if self._executor is None:
                self._executor = concurrent.futures.ProcessPoolExecutor(
                    self._processes, mp_context=multiprocessing.get_context("spawn")
                )
            return self._executor

    def run(self, func: Callable[..., Any], *args) -> Any:
        """``func(*args)`` computed in the worker process."""
        from concurrent.futures.process import BrokenProcessPool

        for attempt in range(2):
            pool = self._pool()
            try:
                result = pool.submit(func, *args).result()
            except BrokenProcessPool:
                with self._lock:
                    if self._executor is pool:
                        self._executor = None
                pool.shutdown(wait=False)
                if attempt:
                    raise
                continue
            self.calls += 1
            return result
        raise AssertionError("unreachable")  # pragma: no cover

    def close(self) -> None:
        """Stop the process (a call in progress is abandoned)."""
        with self._lock:
            executor, self._executor, self._closed = self._executor, None, True
        if executor is not None:
            executor.shutdown(wait=False, cancel_futures=True)


def _job_main(conn, cancel) -> None:
    """The loop of a :class:`JobProcess`: run each ``(job, func, args)`` received as
    ``func(*args, progress=...)``, send back ``("progress", job, done, total)`` reports and one
    ``("done" | "cancelled" | "error", job, value)``; return when the server end closes."""
    if hasattr(os, "setsid"):
        os.setsid()  # its own process group: stopping it stops the processes it started too
    if hasattr(os, "nice"):
        os.nice(JOB_NICENESS)  # the server and the browser come first when cores are busy
    while True:
        try:
            job, func, args = conn.recv()
        except (EOFError, OSError):
            return
        last = [0.0]

        def progress(done: int, total: int, job=job, last=last) -> bool:
            if cancel.is_set():
                return False
            now = time.monotonic()
            if now - last[0] >= PROGRESS_INTERVAL or (total and done >= total):
                last[0] = now
                try:
                    conn.send(("progress", job, int(done), int(total)))
                except OSError:  # the server is gone: stop
                    return False
            return True

        try:
            reply = ("done", job, func(*args, progress=progress))
        except Cancelled as stop:
            reply = ("cancelled", job, str(stop))
        except Exception as error:  # noqa: BLE001 - sent to the server, raised there
            reply = ("error", job, error)
        try:
            conn.send(reply)
        except OSError:  # the server is gone
            return
        except Exception as error:  # noqa: BLE001 - e.g. a result that cannot be pickled
            conn.send(("error", job, RuntimeError(f"the job's result cannot be sent: {error}")))


#: Every JobProcess with a process, stopped at exit (multiprocessing waits for its non-daemon
#: processes then, and a job process only ends when told to).
_RUNNING: weakref.WeakSet = weakref.WeakSet()


@atexit.register
def _stop_running() -> None:
    for jobs in list(_RUNNING):
        jobs.stop()


class JobProcess:
    """A worker process for long jobs, one at a time, with progress and cancelling.

    ``run(func, args, on_progress, cancel)`` calls ``func(*args, progress=callback)`` in the
    process (``func`` by reference, ``args`` pickled) and returns its result, or raises its
    exception here. ``callback(done, total)`` is the library's progress callback
    (docs/progress.md): each report goes to ``on_progress(done, total)`` in this process (at
    most every :data:`PROGRESS_INTERVAL` seconds), and once the ``cancel`` event is set it
    returns False, so the library stops and :class:`~kinegami.errors.Cancelled` is raised
    here. A job that does not stop within ``grace`` seconds of the cancel has its process
    (and the processes it started) stopped; the next job starts a fresh one. The process is
    started on first use (``"spawn"``: a fresh interpreter, not a fork of the threaded
    server) and ends when the server's end of its pipe closes; it is not a daemon, since
    compaction starts processes of its own, and is stopped at exit.
    """

    def __init__(self, grace: float = CANCEL_GRACE):
        self.grace = float(grace)
        self._lock = threading.Lock()  # one job at a time
        self._state = threading.Lock()  # the process's handles
        self._process = None
        self._conn = None
        self._cancel = None
        self._jobs = 0
        self._closed = False
        #: How many processes were started (tests read it: a stopped one is replaced).
        self.started = 0

    @property
    def pid(self) -> int | None:
        """The process id of the running worker process, or None."""
        process = self._process
        return None if process is None or not process.is_alive() else process.pid

    def _start(self):
        import multiprocessing

        with self._state:
            if self._closed:
                raise RuntimeError("the job process was closed")
            if self._process is not None and self._process.is_alive():
                return self._conn
            context = multiprocessing.get_context("spawn")
            ours, theirs = context.Pipe()
            self._cancel = context.Event()
            process = context.Process(target=_job_main, args=(theirs, self._cancel),
                                      name="kinegami-job", daemon=False)  # fmt: skip
            process.start()
            theirs.close()  # the process sees the pipe close when this end does
            self._process, self._conn = process, ours
            self.started += 1
            _RUNNING.add(self)
            return ours

    def run(self, func: Callable[..., Any], args: tuple, on_progress: Callable[[int, int], Any],
            cancel: threading.Event) -> Any:  # fmt: skip
        """``func(*args, progress=...)`` computed in the job process (see the class)."""
        with self._lock:
            conn = self._start()
            self._jobs += 1
            job = self._jobs
            self._cancel.clear()
            conn.send((job, func, args))
            cancelled_at = None
            while True:
                if cancel.is_set() and cancelled_at is None:
                    cancelled_at = time.monotonic()
                    self._cancel.set()
                if cancelled_at is not None and time.monotonic() - cancelled_at > self.grace:
                    self.stop()
                    raise Cancelled("cancelled (the job process was stopped)")
                try:
                    ready = conn.poll(0.05)
                    message = conn.recv() if ready else None
                except (EOFError, OSError) as error:
                    self.stop()
                    if cancel.is_set():
                        raise Cancelled("cancelled (the job process was stopped)") from None
                    raise RuntimeError("the job process ended unexpectedly") from error
                if message is None or message[1] != job:
                    continue
                kind, _, value = message[0], message[1], message[2:]
                if kind == "progress":
                    on_progress(*value)
                elif kind == "done":
                    return value[0]
                elif kind == "cancelled":
                    raise Cancelled(value[0])
                else:
                    raise value[0]

    def stop(self) -> None:
        """Stop the process and the processes it started (a job in progress is abandoned)."""
        with self._state:
            process, conn = self._process, self._conn
            self._process = self._conn = None
        if conn is not None:
            conn.close()
        if process is None:
            return
        if process.is_alive():
            if hasattr(os, "killpg"):
                try:
                    os.killpg(process.pid, signal.SIGKILL)
                except OSError:  # not (yet) a group leader: the process alone
                    process.kill()
            else:  # pragma: no cover - Windows
                process.kill()
        process.join(5.0)

    def close(self) -> None:
        """Stop the process; no job runs after."""
        with self._state:
            self._closed = True
        self.stop()
