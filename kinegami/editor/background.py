"""Work the editor does after a pause rather than on every change: :class:`Debounced`, and
:class:`ProcessWorker` for work too slow to share the server's process.

A drag or an animation changes the document many times a second. What is not needed for each
step (the crease-pattern drawing, the autosave) is triggered on every change and runs once, in
a background thread, when no change came for ``delay`` seconds. Fitting a tree's junctions
takes seconds of pure Python; it runs in a worker process, so that it holds neither a tab's
lock nor the interpreter lock meanwhile. See docs/editor.md.
"""

from __future__ import annotations

import threading
import time
from collections.abc import Callable
from typing import Any

__all__ = ["Debounced", "ProcessWorker"]


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
