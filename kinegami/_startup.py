"""Ctrl-C while the ``kinegami`` command starts up: one line and exit status 130, no traceback.

Importing the package (numpy, spatialmath, matplotlib) takes most of the command's start-up.
A KeyboardInterrupt raised there would reach the console script outside :func:`kinegami.cli.main`
and print a traceback. So the package's very first lines call :func:`quiet_interrupts` when
the command runs, which makes Ctrl-C exit quietly; :func:`kinegami.cli.main` calls
:func:`restore_interrupts` once it handles KeyboardInterrupt itself. A library import changes
nothing. It imports only modules Python has already loaded at start-up (``os``, ``signal``,
``sys``), so that it takes effect as early as possible.
"""

from __future__ import annotations

import os
import signal
import sys

__all__ = ["quiet_interrupts", "restore_interrupts", "INTERRUPTED"]

#: Exit status of a command ended by Ctrl-C (128 + SIGINT, as shells report it).
INTERRUPTED = 130


def _interrupted(signum, frame) -> None:
    try:
        sys.stderr.write("kinegami: interrupted\n")
        sys.stderr.flush()
    except (OSError, ValueError):  # stderr closed: the exit status still says it
        pass
    raise SystemExit(INTERRUPTED)


#: How the command is started: the console script, or ``python -m kinegami`` (while the package
#: is imported, ``sys.argv[0]`` is then "-m"), as :mod:`kinegami._mplconfig` recognises it.
COMMAND_NAMES = ("kinegami", "kinegami.exe", "kinegami-script.py")
MODULE_NAMES = ("kinegami", "kinegami.cli")


def running_the_command() -> bool:
    """True while the ``kinegami`` command starts up (not for a library import)."""
    if sys.argv and os.path.basename(sys.argv[0]) in COMMAND_NAMES:
        return True
    original = list(getattr(sys, "orig_argv", ()))
    if not sys.argv or sys.argv[0] != "-m" or "-m" not in original:
        return False
    index = original.index("-m")
    return index + 1 < len(original) and original[index + 1] in MODULE_NAMES


def quiet_interrupts() -> None:
    """Make Ctrl-C end the process with one line on stderr and status 130 (no traceback).

    For the command's start-up only (the package calls it when :func:`running_the_command`).
    Only replaces Python's default handler (an ignored SIGINT, e.g. under ``nohup`` or in a
    background job, stays ignored).
    """
    try:
        if signal.getsignal(signal.SIGINT) is signal.default_int_handler:
            signal.signal(signal.SIGINT, _interrupted)
    except ValueError:  # not the main thread
        pass


def restore_interrupts() -> None:
    """Give Ctrl-C back to Python (a KeyboardInterrupt), if :func:`quiet_interrupts` took it."""
    try:
        if signal.getsignal(signal.SIGINT) is _interrupted:
            signal.signal(signal.SIGINT, signal.default_int_handler)
    except ValueError:  # not the main thread
        pass
