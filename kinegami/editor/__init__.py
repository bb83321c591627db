"""The design editor's model: a design as a document, commands with undo, and change events.

Plain Python, no web code: the browser view (``kinegami edit``: kinegami.editor.view and
kinegami.editor.server, on viser) binds its widgets to these calls. See docs/editor.md.

>>> from kinegami.editor import EditorModel
>>> model = EditorModel()                      # the starter design of `kinegami new`
>>> model.slide(1, 0.5).ok, model.dirty
(True, True)
>>> model.undo().ok, model.can_redo
(True, True)
"""

from kinegami.editor import commands
from kinegami.editor.commands import *  # noqa: F403 - the names of commands.__all__
from kinegami.editor.document import Document, JointRow, joint_parameters
from kinegami.editor.model import Change, CommandResult, EditorModel
from kinegami.editor.patterns import PatternCache

__all__ = [
    "EditorModel",
    "CommandResult",
    "Change",
    "Document",
    "JointRow",
    "joint_parameters",
    "PatternCache",
    *commands.__all__,
]
