"""A writable matplotlib folder for the ``kinegami`` command, chosen before matplotlib is imported.

Without a writable home folder (``HOME`` read-only, or missing, as in some containers and CI
jobs) matplotlib falls back to a throwaway folder and logs two warning lines at every start, so
that the command's own one-line error came third. When the command runs and matplotlib would do
that, :func:`use_private_folder_if_needed` sets ``MPLCONFIGDIR`` to a private folder in the
temporary directory instead: ``kinegami-matplotlib-<uid>``, made with mode 0700 and kept, so
the font cache survives between runs; a fresh folder (removed at exit) if that one is not a
directory of this user that only they can use. A library import never changes the environment:
only the ``kinegami`` console script and ``python -m kinegami`` do this. Standard library only,
since it runs before anything else in the package.
"""

from __future__ import annotations

import atexit
import os
import stat
import sys
from pathlib import Path

__all__ = ["running_the_command", "matplotlib_folders", "use_private_folder_if_needed"]

COMMAND_NAMES = ("kinegami", "kinegami.exe", "kinegami-script.py")
MODULE_NAMES = ("kinegami", "kinegami.cli")


def running_the_command() -> bool:
    """True while the ``kinegami`` console script or ``python -m kinegami`` starts up."""
    if sys.argv and Path(sys.argv[0]).name in COMMAND_NAMES:
        return True
    # python -m kinegami: while the package is imported, argv[0] is "-m"
    original = list(getattr(sys, "orig_argv", ()))
    if not sys.argv or sys.argv[0] != "-m" or "-m" not in original:
        return False
    index = original.index("-m")
    return index + 1 < len(original) and original[index + 1] in MODULE_NAMES


def matplotlib_folders() -> list[Path] | None:
    """The config and cache folders matplotlib would use when ``MPLCONFIGDIR`` is unset (its
    ``get_configdir``/``get_cachedir``), or None when it could not find a home folder."""
    try:
        home = Path.home()
    except (RuntimeError, KeyError):
        home = None
    if sys.platform.startswith(("linux", "freebsd")):
        folders = []
        for variable, default in (("XDG_CONFIG_HOME", ".config"), ("XDG_CACHE_HOME", ".cache")):
            base = os.environ.get(variable) or (home / default if home else None)
            if base is None:
                return None
            folders.append(Path(base) / "matplotlib")
        return folders
    if sys.platform == "win32":
        local = os.environ.get("LOCALAPPDATA")
        if home is not None and (home / ".matplotlib").is_dir():
            return [home / ".matplotlib"]
        return [Path(local) / "matplotlib"] if local else None
    return [home / ".matplotlib"] if home else None


def _writable_folder(path: Path) -> bool:
    """Whether matplotlib would accept ``path``: it can be made, is a folder and is writable."""
    try:
        path = path.resolve()
        path.mkdir(parents=True, exist_ok=True)
    except OSError:
        return False
    return path.is_dir() and os.access(path, os.W_OK)


def _private_folder() -> Path | None:
    """``<tmp>/kinegami-matplotlib-<uid>`` if it is (or can be made) this user's own folder, mode
    0700; else a fresh temporary folder removed at exit; None if neither can be made."""
    import shutil  # here, not at the top: importing kinegami should not pay for them
    import tempfile

    getuid = getattr(os, "getuid", None)
    if getuid is not None:
        path = Path(tempfile.gettempdir()) / f"kinegami-matplotlib-{getuid()}"
        try:
            try:
                path.mkdir(mode=0o700)
            except FileExistsError:
                pass
            info = os.lstat(path)
            if (
                stat.S_ISDIR(info.st_mode)
                and info.st_uid == getuid()
                and not info.st_mode & 0o077
                and os.access(path, os.W_OK)
            ):
                return path
        except OSError:
            pass
    try:
        path = Path(tempfile.mkdtemp(prefix="kinegami-matplotlib-"))
    except OSError:
        return None
    atexit.register(shutil.rmtree, path, ignore_errors=True)
    return path


def use_private_folder_if_needed() -> Path | None:
    """Set ``MPLCONFIGDIR`` to a private folder if matplotlib would otherwise warn that it has no
    writable folder; returns the folder, or None when nothing was changed.

    Does nothing if ``MPLCONFIGDIR`` is set (the user's choice stands) or matplotlib is already
    imported (too late to matter).
    """
    if os.environ.get("MPLCONFIGDIR") or "matplotlib" in sys.modules:
        return None
    folders = matplotlib_folders()
    if folders is not None and all(_writable_folder(folder) for folder in folders):
        return None
    folder = _private_folder()
    if folder is not None:
        os.environ["MPLCONFIGDIR"] = str(folder)
    return folder
