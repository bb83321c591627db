"""The kinegami exception and warning hierarchy, in one place (docs/errors.md).

Every error raised on purpose by kinegami is a :class:`KinegamiError`. The subclasses also
inherit the matching builtin, so ``except ValueError`` keeps working (as ezdxf does with
``DXFValueError``)::

    KinegamiError(Exception)
    +-- InvalidParameterError(ValueError)    a value outside its valid range
    |   +-- FoldedFormError                  a pattern that cannot be folded
    |   +-- UnknownModuleKindError(KeyError) no catalog entry for a module kind
    |   +-- SplitError                       a sheet cannot be cut into short enough pieces
    |       +-- BedTooSmallError             ... nor into pieces that fit the laser bed
    +-- InvalidTypeError(TypeError)          a value of the wrong type, an unknown option
    +-- ReadOnlyError(AttributeError)        assignment to a joint's or link's attribute
    +-- JointIndexError(IndexError)          no joint with that index
    +-- NoPathError(ValueError)              no CSC link joins two frames
    +-- IncompatibleJointError(ValueError)   another numSides or r than the chain's
    +-- CompactionError(ValueError)          compaction found no clear design
    +-- InfeasibleTaskError(ValueError)      no design of the budget reaches every target
    +-- EditorCommandError(ValueError)       an editor command that cannot be applied
    +-- DesignError(ValueError)              a design file is unreadable or invalid
    +-- DesignFileExistsError(FileExistsError)
    +-- FoldExportError(ValueError)          a pattern FOLD export cannot write
    +-- ExporterUnavailableError(ImportError)
    +-- ExportError(OSError)                 a file could not be written
    |   +-- PublishError                     a build could not be published
    +-- Cancelled                            long work stopped by its progress callback
    +-- GuardError(RuntimeError)             the editor could not guard its server

    UserWarning
    +-- PlacementWarning                     a placement, edit or state change was rejected
    +-- ClearanceWarning                     an operation left the chain passing through itself

The classes keep their old import locations too (``kinegami.chain.PlacementWarning``,
``kinegami.design.DesignError``, ``kinegami.export.ExportError``, ...).
"""

from __future__ import annotations

import os

__all__ = [
    "KinegamiError",
    "InvalidParameterError",
    "InvalidTypeError",
    "ReadOnlyError",
    "JointIndexError",
    "NoPathError",
    "IncompatibleJointError",
    "CompactionError",
    "InfeasibleTaskError",
    "SplitError",
    "BedTooSmallError",
    "EditorCommandError",
    "FoldedFormError",
    "UnknownModuleKindError",
    "DesignError",
    "DesignFileExistsError",
    "ExportError",
    "PublishError",
    "ExporterUnavailableError",
    "FoldExportError",
    "Cancelled",
    "GuardError",
    "PlacementWarning",
    "ClearanceWarning",
]


class KinegamiError(Exception):
    """Base class of every error kinegami raises on purpose.

    ``str(error)`` is one line (docs/errors.md): a message that holds a line break (the repr of
    a numpy array, say) is shown with each run of whitespace as one space.
    """

    def __str__(self) -> str:
        text = super().__str__()
        return text if text.splitlines() == [text] else " ".join(text.split())


# --- parameters ----------------------------------------------------------------------------
class InvalidParameterError(KinegamiError, ValueError):
    """A parameter has a value outside its valid range (the message names both)."""


class InvalidTypeError(KinegamiError, TypeError):
    """A parameter has the wrong type (or an option name is unknown)."""


class ReadOnlyError(KinegamiError, AttributeError):
    """An attribute of a value (a joint, a link) was assigned or deleted.

    Joints and links are values: build a new one, or edit the chain (its edit methods swap in
    new joints and links).
    """


# --- chains --------------------------------------------------------------------------------
class JointIndexError(KinegamiError, IndexError):
    """A joint index does not name a joint of the chain."""


class NoPathError(KinegamiError, ValueError):
    """No acceptable CSC link (all turns < pi) joins two frames."""


class IncompatibleJointError(KinegamiError, ValueError):
    """A joint's ``numSides`` or ``r`` differs from the chain's."""


class CompactionError(KinegamiError, ValueError):
    """No clear design was found (the input passes through itself and no move fixed it)."""


class InfeasibleTaskError(KinegamiError, ValueError):
    """No design of the joint budget reaches every target of a task
    (:func:`kinegami.optimize.design_for`). ``target`` is the index of the target the message
    names (or None), ``proven`` whether a bound proves it (a certificate) rather than the
    search not finding a design."""

    def __init__(self, message: str, target: int | None = None, proven: bool = True):
        super().__init__(message)
        self.target = target
        self.proven = proven


class SplitError(InvalidParameterError):
    """A sheet cannot be cut into pieces no longer than asked: a stretch without plain tube to
    cut across is too long (kinegami.pattern.pieces). ``stretch`` says which (a
    ``kinegami.pattern.pieces.Stretch``, or None), ``needed`` the shortest piece length that
    would work (pattern units)."""

    def __init__(self, message: str, stretch=None, needed: float = float("nan")):
        super().__init__(message)
        self.stretch = stretch
        self.needed = needed


class BedTooSmallError(SplitError):
    """A sheet does not fit the laser bed and cannot be cut into pieces that do (a stretch
    without plain tube to cut across is too long, or the strip is wider than the bed).

    ``smallest`` is the smallest bed that would work, (long side, short side) in mm; the message
    names the stretch and that bed (docs/fabrication.md, "Laser bed").
    """

    def __init__(self, message: str, smallest: tuple[float, float] = (0.0, 0.0), stretch=None,
                 needed: float = float("nan")):  # fmt: skip
        super().__init__(message, stretch, needed)
        self.smallest = smallest


class EditorCommandError(KinegamiError, ValueError):
    """An editor command that cannot be applied; the message says why (parameter, value,
    range). Also ``kinegami.editor.CommandError``."""


# --- patterns ------------------------------------------------------------------------------
class FoldedFormError(InvalidParameterError):
    """A pattern cannot be folded (no module records, or records that do not rebuild it)."""


class UnknownModuleKindError(InvalidParameterError, KeyError):
    """No catalog entry is registered under a module kind."""

    def __str__(self) -> str:  # KeyError would quote the message
        return str(self.args[0]) if self.args else ""


# --- long work -----------------------------------------------------------------------------
class Cancelled(KinegamiError):  # noqa: N818 - the name users catch (as asyncio)
    """Long work (compaction, a motion sweep, a build) was stopped because its ``progress``
    callback returned False (docs/progress.md). Nothing the work would have changed was
    changed."""


# --- the editor ------------------------------------------------------------------------------
class GuardError(KinegamiError, RuntimeError):
    """The editor's access check could not be put in front of viser's requests (a viser or
    websockets version that does not start its server through
    ``websockets.asyncio.server.serve``); the editor then does not serve at all. Also
    ``kinegami.editor.access.GuardError``."""


# --- design files --------------------------------------------------------------------------
#: Marker for "no offending value" (``None`` is a valid JSON value: ``null``).
_NO_VALUE = object()


def _one_line(text: str) -> str:
    return " ".join(str(text).split())


class DesignError(KinegamiError, ValueError):
    """A design file cannot be read, is invalid, or describes an infeasible chain.

    Attributes
    ----------
    file : str or None
        The design file (None for a design given as text or as a dict without a file name).
    field : str
        JSON path of the problem, e.g. ``joints[2].totalBendingAngle``; ``$`` is the document.
    value : object
        The offending value (None if there is none; see ``has_value``).
    reason : str
        What is wrong and what is allowed.

    ``str(error)`` is one line: ``<file>: <field>: <reason> (got <value>)``; the field is left
    out when the problem is the document as a whole (``$``).
    """

    def __init__(
        self,
        reason: str,
        *,
        field: str = "$",
        value=_NO_VALUE,
        file: str | os.PathLike | None = None,
    ):
        self.reason = _one_line(reason)
        self.field = field
        self.has_value = value is not _NO_VALUE
        self.value = value if self.has_value else None
        self.file = None if file is None else os.fspath(file)
        super().__init__(str(self))

    def with_file(self, file) -> DesignError:
        """The same error attributed to ``file`` (used when a file name becomes known)."""
        value = self.value if self.has_value else _NO_VALUE
        return DesignError(self.reason, field=self.field, value=value, file=file)

    def __str__(self) -> str:
        from kinegami._format import format_value  # a leaf module, imported when needed

        text = self.reason if self.field == "$" else f"{self.field}: {self.reason}"
        if self.has_value:
            text += f" (got {format_value(self.value)})"
        if self.file is not None:
            text = f"{self.file}: {text}"
        return text if text.splitlines() == [text] else " ".join(text.split())

    def __reduce__(self):
        return (_rebuild, (self.reason, self.field, self.has_value, self.value, self.file))


def _rebuild(reason, field, has_value, value, file):
    return DesignError(reason, field=field, value=value if has_value else _NO_VALUE, file=file)


class DesignFileExistsError(KinegamiError, FileExistsError):
    """The file to write a new design to exists already (and was left as it was)."""


# --- export --------------------------------------------------------------------------------
class ExportError(KinegamiError, OSError):
    """A pattern could not be written (folder not writable, disk full, ...).

    ``errno`` and ``filename`` are those of the underlying :class:`OSError`.
    """


class PublishError(ExportError):
    """A build could not be published, or an earlier interrupted one not recovered.

    The message says what failed and where the earlier files are.
    """


class ExporterUnavailableError(KinegamiError, ImportError):
    """The exporter of a registered format cannot be imported (its module is missing)."""


class FoldExportError(KinegamiError, ValueError):
    """The pattern's sheet is not a valid planar crease pattern (crossing or overlapping creases,
    or a sheet of zero area)."""


# --- warnings ------------------------------------------------------------------------------
class PlacementWarning(UserWarning):
    """A placement, edit or state change was rejected; the chain is unchanged."""


class ClearanceWarning(UserWarning):
    """An operation left the chain passing through itself (it was applied; the message names
    the two parts). ``clearance`` is the overlap (negative, chain units); ``first`` and
    ``second`` name the parts."""

    def __init__(self, message: str, clearance: float = float("nan"), first: str = "",
                 second: str = ""):  # fmt: skip
        super().__init__(message)
        self.clearance = clearance
        self.first = first
        self.second = second
