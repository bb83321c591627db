"""Progress and cancellation of long work, one mechanism for every front end (docs/progress.md).

Long operations (:func:`kinegami.optimize.compact`, :func:`kinegami.clearance.sweep`, tree
builds, and later workspaces and task design) take a ``progress`` argument:

* a callable ``progress(done, total)``: called with the work done so far and the total (in the
  operation's own steps: starts, configurations, sheets), at the start, after each step and,
  for work that waits on other processes, a few times a second. Returning ``False`` (exactly
  ``False``; ``None`` and anything else go on) stops the work and raises :class:`Cancelled`;
  the operation then changes nothing;
* ``True``: a text progress bar on stderr (tqdm); ``False``: nothing;
* ``None`` (the default): a progress bar when stderr is a terminal.

The editor's progress bar and Cancel button sit on the callable form; the command line uses
the bar.
"""

from __future__ import annotations

import sys
from collections.abc import Callable

from kinegami.errors import Cancelled, InvalidTypeError

__all__ = ["Cancelled", "Progress", "ProgressCallback", "check_progress"]

#: ``progress(done, total)``; return False to stop the work.
ProgressCallback = Callable[[int, int], object]


def check_progress(progress) -> bool | None | ProgressCallback:
    """``progress`` itself when it is None, a bool or a callable; InvalidTypeError otherwise."""
    if progress is None or isinstance(progress, bool) or callable(progress):
        return progress
    raise InvalidTypeError(
        "progress must be None, True, False or a callable progress(done, total), got "
        f"{type(progress).__name__}"
    )


class Progress:
    """The progress of one long operation of ``total`` steps, reported as ``progress`` asks.

    Use as a context manager (the bar closes at the end)::

        with Progress(progress, total=100, desc="sweep") as bar:
            for chunk in chunks:
                ...
                bar.update(len(chunk))   # raises Cancelled when the callback says False
    """

    def __init__(self, progress, total: int, *, desc: str = "", unit: str = "it"):
        progress = check_progress(progress)
        self.total = int(total)
        self.done = 0
        self._callback: ProgressCallback | None = None
        self._bar = None
        if callable(progress) and not isinstance(progress, bool):
            self._callback = progress
        elif progress or (progress is None and sys.stderr is not None and sys.stderr.isatty()):
            try:
                from tqdm import tqdm
            except ImportError:  # pragma: no cover - tqdm is a dependency
                tqdm = None
            if tqdm is not None:
                self._bar = tqdm(total=self.total, desc=desc, unit=unit, leave=False)
        self.check()

    def check(self) -> None:
        """Report the current count again (a heartbeat while waiting); raise :class:`Cancelled`
        when the callback returns False."""
        if self._callback is not None and self._callback(self.done, self.total) is False:
            self.close()
            raise Cancelled(f"cancelled after {self.done} of {self.total} steps")

    def update(self, steps: int = 1) -> None:
        """``steps`` more steps done; raise :class:`Cancelled` when the callback says stop."""
        self.done = min(self.total, self.done + int(steps))
        if self._bar is not None:
            self._bar.update(int(steps))
        self.check()

    def close(self) -> None:
        """Close the bar (idempotent)."""
        if self._bar is not None:
            self._bar.close()
            self._bar = None

    def __enter__(self) -> Progress:
        return self

    def __exit__(self, *exc) -> None:
        self.close()
