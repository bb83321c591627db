"""The editor model: a document, its undo history, the selection, and listeners.

Every user action is a command (:mod:`kinegami.editor.commands`) run by
:meth:`EditorModel.apply`: it either applies completely or leaves the document exactly as it
was and returns the reason. Undo and redo swap whole documents (which never change), so
undoing everything gives back the original bit for bit. A view subscribes with
:meth:`EditorModel.subscribe` and is told, after every change, which joints and links changed.
Nothing here draws or serves anything: the browser view binds its widgets to these calls.
See docs/editor.md.
"""

from __future__ import annotations

import os
from collections.abc import Callable
from dataclasses import dataclass
from pathlib import Path

import numpy as np

from kinegami.chain.model import KinematicChain
from kinegami.design.limits import position_problem
from kinegami.editor import commands as cmd
from kinegami.editor.commands import Command, CommandError, Outcome
from kinegami.editor.document import Document, JointRow, joint_parameters
from kinegami.editor.patterns import PatternCache, TreeSheets, link_shape_key, tree_sheets
from kinegami.errors import InvalidTypeError, KinegamiError
from kinegami.tree import KinematicTree

__all__ = ["EditorModel", "CommandResult", "Change"]


@dataclass(frozen=True)
class Change:
    """What changed in the document (sent to listeners and returned in results).

    Attributes
    ----------
    kind : ``"command"``, ``"undo"``, ``"redo"``, ``"load"``, ``"save"``, ``"select"``,
        ``"new"`` or ``"preview"`` (a preview shown or ended; see :meth:`EditorModel.preview`).
    joints : indices (in the new document) of the joints whose pose, state or parameters
        changed, or that are new.
    links : indices of the links that changed (``Links[i]`` leads into joint i).
    reshaped_joints, reshaped_links : those of ``joints`` and ``links`` whose shape changed
        (a new mesh is needed); the others only moved rigidly (a new pose is enough).
    joint_sources : per joint of the new document, the index of the identical joint in the
        old one (same pose, state and parameters), or None.
    removed : indices (in the old document) of the joints that are gone.
    structure : the number of joints changed (joints were added or deleted).
    names : the joint names changed.
    options : the chain options, the design's texts or its task changed.
    selected : the selected joint after the change (None: nothing selected).
    dirty : the document differs from the saved one.
    """

    kind: str
    joints: tuple[int, ...] = ()
    links: tuple[int, ...] = ()
    reshaped_joints: tuple[int, ...] = ()
    reshaped_links: tuple[int, ...] = ()
    joint_sources: tuple = ()
    removed: tuple[int, ...] = ()
    structure: bool = False
    names: bool = False
    options: bool = False
    selected: int | None = None
    dirty: bool = False

    @property
    def document_changed(self) -> bool:
        """Whether anything of the document changed (not only the selection)."""
        return bool(self.joints or self.links or self.removed or self.structure or self.names
                    or self.options)  # fmt: skip


@dataclass(frozen=True)
class CommandResult:
    """The result of a command, undo, redo, save, load or selection.

    ``ok`` is False when nothing happened; ``reason`` then says why (the parameter, the value
    and what is allowed). ``warnings`` lists what a successful command wants the user to know
    (e.g. that the chain now passes through itself). ``change`` is what listeners were told
    (None when nothing changed).
    """

    ok: bool
    action: str
    reason: str | None = None
    warnings: tuple[str, ...] = ()
    change: Change | None = None

    def __bool__(self) -> bool:
        return self.ok


# --- comparing documents ----------------------------------------------------------------------
def _value_bits(value):
    if isinstance(value, np.ndarray):
        return (value.shape, value.tobytes())
    if isinstance(value, float):
        return np.float64(value).tobytes()
    return value


def _joint_keys(joint) -> tuple[tuple, bytes]:
    """(shape key, pose key) of a joint: the shape is its type, parameters and state."""
    parameters = tuple(
        (key, _value_bits(value)) for key, value in sorted(joint_parameters(joint).items())
    )
    shape = (
        type(joint).__name__,
        parameters,
        _value_bits(float(joint.r)),
        _value_bits(float(joint.neutralLength)),
        _value_bits(float(joint.state)),
    )
    return shape, joint.pose_matrix.tobytes()


def _link_keys(link) -> tuple[tuple, bytes]:
    return (
        tuple(
            _value_bits(float(v)) if isinstance(v, float) else v
            for v in _flatten(link_shape_key(link))
        )
        + (np.float64(link.path.length).tobytes(),),
        link.start_frame.tobytes() + link.end_frame.tobytes(),
    )


def _flatten(values):
    for v in values:
        if isinstance(v, tuple):
            yield from _flatten(v)
        else:
            yield v


def _options(document: Document) -> tuple:
    c = document.chain
    return (document.name, document.description, document.units, document.twistPortion,
            c.requireClearance, c.maxAnglePerElbow, document.task)  # fmt: skip


def compare(old: Document, new: Document, kind: str, sources=None) -> Change:
    """The :class:`Change` from ``old`` to ``new`` (``sources``: a command's guess of each new
    joint's old index, checked against the values)."""
    oj, nj = old.chain.Joints, new.chain.Joints
    ol, nl = old.chain.Links, new.chain.Links
    okeys = [_joint_keys(j) for j in oj]
    nkeys = [_joint_keys(j) for j in nj]
    olinks = [_link_keys(k) for k in ol]
    nlinks = [_link_keys(k) for k in nl]
    structure = len(oj) != len(nj)
    if sources is None or len(sources) != len(nj):
        sources = range(len(nj)) if not structure else [None] * len(nj)
    guess = list(sources)
    joint_sources: list = []
    used: set = set()
    # exact matches first at the guessed index, then anywhere (in order)
    by_key: dict = {}
    for i, key in enumerate(okeys):
        by_key.setdefault(key, []).append(i)
    for i, key in enumerate(nkeys):
        g = guess[i]
        if g is not None and 0 <= g < len(okeys) and okeys[g] == key and g not in used:
            joint_sources.append(g)
            used.add(g)
            continue
        joint_sources.append(None)
    for i, key in enumerate(nkeys):
        if joint_sources[i] is None:
            for k in by_key.get(key, ()):
                if k not in used:
                    joint_sources[i] = k
                    used.add(k)
                    break

    def near(i: int) -> set:
        return {g for g in (joint_sources[i], guess[i]) if g is not None}

    joints, reshaped_joints = [], []
    for i, key in enumerate(nkeys):
        if joint_sources[i] is not None:
            continue
        joints.append(i)
        if not any(0 <= g < len(okeys) and okeys[g][0] == key[0] for g in near(i)):
            reshaped_joints.append(i)
    links, reshaped_links = [], []
    for i, key in enumerate(nlinks):
        if any(0 <= g < len(olinks) and olinks[g] == key for g in near(i)):
            continue
        links.append(i)
        if not any(0 <= g < len(olinks) and olinks[g][0] == key[0] for g in near(i)):
            reshaped_links.append(i)
    kept = used | {g for g in guess if g is not None}
    removed = tuple(i for i in range(len(oj)) if i not in kept)
    names = old.names != new.names
    return Change(
        kind, tuple(joints), tuple(links), tuple(reshaped_joints), tuple(reshaped_links),
        tuple(joint_sources), removed, structure, names, _options(old) != _options(new),
    )  # fmt: skip


# --- the model --------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Step:
    command: Command
    before: Document
    after: Document
    selected_before: int | None
    selected_after: int | None


class EditorModel:
    """The state of an editor session: a document, its history, selection and file.

    Parameters
    ----------
    document : the document to edit: a :class:`Document`, a KinematicChain or KinematicTree
        (copied), or None for the starter design of ``kinegami new``
        (kinegami/design/starter.json).
    path : the design file it belongs to (where :meth:`save` writes by default).

    Examples
    --------
    >>> model = EditorModel.open("examples/designs/example1.json")  # doctest: +SKIP
    >>> model.slide(4, -1.0).ok, model.dirty  # doctest: +SKIP
    (True, True)
    >>> model.undo().ok, model.dirty  # doctest: +SKIP
    (True, False)
    """

    def __init__(self, document: Document | KinematicChain | KinematicTree | None = None,
                 path: str | os.PathLike | None = None):  # fmt: skip
        if document is None:
            from kinegami.design.starter import starter_text

            document = Document.loads(starter_text())
        elif isinstance(document, KinematicChain | KinematicTree):
            document = Document.from_chain(document)
        elif not isinstance(document, Document):
            raise InvalidTypeError(
                f"document must be a Document, a KinematicChain, a KinematicTree or None, got "
                f"{type(document).__name__}"
            )
        self._document = document
        self._saved: Document | None = document
        self._path = None if path is None else Path(os.fspath(path))
        self._undo: list[_Step] = []
        self._redo: list[_Step] = []
        self._selected: int | None = None
        self._listeners: list[Callable[[Change], None]] = []
        self._patterns = PatternCache()
        self._preview_base: Document | None = None  # the document under a preview
        self._shown: Document | None = None  # what listeners saw, after _leave_preview
        #: Default of ``propagate`` for the move helpers (:meth:`slide`, :meth:`roll`,
        #: :meth:`transform`): move the later joints too. A view's toggle sets it.
        self.propagate = True

    @classmethod
    def open(cls, path: str | os.PathLike) -> EditorModel:
        """A model editing the design file ``path`` (raises DesignError when it cannot be
        loaded; :meth:`load` returns the reason instead)."""
        return cls(Document.load(path), path)

    # --- state --------------------------------------------------------------------------------
    @property
    def document(self) -> Document:
        """The current document (a value: commands replace it, never change it)."""
        return self._document

    @property
    def chain(self) -> KinematicChain | KinematicTree:
        """The current chain or tree (read it; change it only through commands)."""
        return self._document.chain

    @property
    def is_tree(self) -> bool:
        """Whether the current design is a tree (see :meth:`sheets`)."""
        return self._document.is_tree

    @property
    def path(self) -> Path | None:
        """The design file of the document (None until saved or loaded)."""
        return self._path

    @property
    def dirty(self) -> bool:
        """Whether the document differs from the last one saved or loaded (or the one the
        model was made with)."""
        return self.base_document is not self._saved

    @property
    def base_document(self) -> Document:
        """The document commands act on: :attr:`document`, or the one under a preview."""
        return self._document if self._preview_base is None else self._preview_base

    @property
    def previewing(self) -> bool:
        """Whether :attr:`document` is a preview (see :meth:`preview`)."""
        return self._preview_base is not None

    @property
    def selected(self) -> int | None:
        """The selected joint's index, or None."""
        return self._selected

    @property
    def can_undo(self) -> bool:
        """Whether there is a command to undo."""
        return bool(self._undo)

    @property
    def can_redo(self) -> bool:
        """Whether there is an undone command to redo."""
        return bool(self._redo)

    @property
    def undo_labels(self) -> tuple[str, ...]:
        """The commands :meth:`undo` would undo, most recent last."""
        return tuple(step.command.describe() for step in self._undo)

    @property
    def redo_labels(self) -> tuple[str, ...]:
        """The commands :meth:`redo` would redo, next first."""
        return tuple(step.command.describe() for step in reversed(self._redo))

    # --- derived values -----------------------------------------------------------------------
    def clearance(self):
        """The current chain's (or tree's) ClearanceReport (computed once per document)."""
        return self._document.clearance

    def _chain_only(self, what: str) -> None:
        if self._document.is_tree:
            raise InvalidTypeError(
                f"{what}: a tree is folded from several sheets, one per leaf; use sheets()"
            )

    def pattern(self):
        """The current chain's crease pattern (a TubularPattern, equal to
        ``chain.creasePattern(twistPortion)``), computed once per document and built from
        the parts the last pattern shares with it. A tree has a sheet per leaf instead
        (:meth:`sheets`; InvalidTypeError here)."""
        self._chain_only("pattern")
        document = self._document
        cached = document.__dict__.get("_pattern")
        if cached is None:
            cached = self._patterns.pattern(document.chain, document.twist_portion)
            document.__dict__["_pattern"] = cached
        return cached

    def joint_modules(self) -> tuple[range, ...]:
        """Per joint, which records of ``pattern().modules`` (and of its ``module_vertices``)
        are the joint's own modules: a range of indices, empty for a joint without a pattern
        of its own (a waypoint). Computed once per document. Chains only (a tree's joints are
        in :attr:`TreeSheets.places <kinegami.editor.patterns.TreeSheets.places>`)."""
        self._chain_only("joint_modules")
        document = self._document
        cached = document.__dict__.get("_joint_modules")
        if cached is None:
            cached = self._patterns.joint_records(document.chain, document.twist_portion)
            document.__dict__["_joint_modules"] = cached
        return cached

    def sheets(self, document: Document | None = None, fit: Callable | None = None) -> TreeSheets:
        """The sheets of the current tree (or of ``document``, a tree's), one per leaf, with
        its junctions, as ``kinegami build`` makes them (the tree fitted by
        :func:`~kinegami.fabrication.sheets.fit_junctions` first, or by ``fit``, which computes the
        same elsewhere): a :class:`~kinegami.editor.patterns.TreeSheets`. Computed once per
        document (a failure too: the same error is raised again); any thread may ask.
        InvalidTypeError for a chain (its one sheet is :meth:`pattern`)."""
        document = self._document if document is None else document
        if not document.is_tree:
            raise InvalidTypeError("sheets: a chain is folded from one sheet; use pattern()")
        cached = document.__dict__.get("_sheets")
        if cached is None:
            try:
                cached = tree_sheets(document.chain, document.twist_portion, document.names,
                                     document.units, fit=fit)  # fmt: skip
            except (KinegamiError, ValueError) as error:
                cached = error
            document.__dict__["_sheets"] = cached
        if isinstance(cached, Exception):
            raise cached
        return cached

    def joint_table(self) -> tuple[JointRow, ...]:
        """One row per joint: index, type, name, pose, state, state range, parameters, parent
        and children."""
        return self._document.joint_table

    def to_design_text(self) -> str:
        """The design file text of the current document (raises InvalidParameterError when
        the chain cannot be written as a design)."""
        return self._document.design_text

    # --- listeners ----------------------------------------------------------------------------
    def subscribe(self, listener: Callable[[Change], None]) -> Callable[[], None]:
        """Call ``listener(change)`` after every change; returns a function that unsubscribes."""
        self._listeners.append(listener)

        def unsubscribe() -> None:
            if listener in self._listeners:
                self._listeners.remove(listener)

        return unsubscribe

    def _notify(self, change: Change) -> None:
        for listener in list(self._listeners):
            listener(change)

    # --- selection ----------------------------------------------------------------------------
    def _clamped(self, index: int | None, document: Document) -> int | None:
        if index is None:
            return None
        n = len(document.chain.Joints)
        return min(max(index, 0), n - 1)

    def select(self, joint: int | str | None) -> CommandResult:
        """Select a joint (an index, negative from the end, or a name), or nothing (None)."""
        if joint is None:
            index = None
        else:
            try:
                index = cmd.resolve_joint(self._document, joint)
            except CommandError as error:
                return CommandResult(False, "select", str(error))
        self._selected = index
        change = Change("select", selected=index, dirty=self.dirty)
        self._notify(change)
        return CommandResult(True, "select", change=change)

    # --- commands -----------------------------------------------------------------------------
    def apply(self, command: Command) -> CommandResult:
        """Run ``command``: all of it, or nothing (then ``reason`` says why)."""
        if not isinstance(command, Command):
            return CommandResult(
                False, "command", f"command must be an editor Command, got {command!r}"
            )
        self._leave_preview()
        before = self._document
        try:
            outcome = command.apply(before)
        except CommandError as error:
            return self._refused(CommandResult(False, command.label, str(error)))
        except (KinegamiError, ValueError, TypeError, IndexError, ArithmeticError) as error:
            return self._refused(CommandResult(False, command.label, f"{command.label}: {error}"))
        if not isinstance(outcome, Outcome):  # pragma: no cover - a broken command class
            return self._refused(CommandResult(False, command.label, "the command returned no "
                                               "document"))  # fmt: skip
        after = outcome.document
        far = position_problem(after.chain)
        if far is not None and position_problem(before.chain) is None:
            # a design file could not hold the result (docs/limits.md): refused, not saved later
            return self._refused(CommandResult(False, command.label,
                                               f"{command.label}: {far[1]}"))  # fmt: skip
        selected = self._selection_after(before, after, outcome)
        self._undo.append(_Step(command, before, after, self._selected, selected))
        self._redo.clear()
        return self._switch(after, selected, "command", command.label, outcome.warnings,
                            outcome.sources)  # fmt: skip

    def _selection_after(self, before: Document, after: Document, outcome: Outcome):
        if outcome.selected is not None:
            return self._clamped(outcome.selected, after)
        if self._selected is None:
            return None
        if outcome.sources is not None:
            for i, source in enumerate(outcome.sources):
                if source == self._selected:
                    return i
        return self._clamped(self._selected, after)

    def _leave_preview(self) -> None:
        """Stop a preview without telling the listeners: the next change they hear is from
        the preview they saw to the new document (one redraw, not two)."""
        if self._preview_base is not None:
            self._shown = self._document
            self._document, self._preview_base = self._preview_base, None

    def _refused(self, result: CommandResult) -> CommandResult:
        """A refused command after :meth:`_leave_preview`: the listeners see the base again."""
        if self._shown is not None:
            self._switch(self._document, self._selected, "preview", "end preview")
        return result

    def _switch(self, document: Document, selected, kind: str, action: str,
                warnings=(), sources=None) -> CommandResult:  # fmt: skip
        shown, self._shown = self._shown, None
        change = compare(self._document if shown is None else shown, document, kind, sources)
        self._document = document
        self._selected = selected
        change = Change(**{**change.__dict__, "selected": selected, "dirty": self.dirty})
        self._notify(change)
        return CommandResult(True, action, None, tuple(warnings), change)

    def undo(self) -> CommandResult:
        """Undo the last command (the document and selection before it come back exactly)."""
        self._leave_preview()
        if not self._undo:
            return self._refused(CommandResult(False, "undo", "there is nothing to undo"))
        step = self._undo.pop()
        self._redo.append(step)
        return self._switch(step.before, step.selected_before, "undo", "undo")

    def redo(self) -> CommandResult:
        """Redo the last undone command (its document comes back exactly)."""
        self._leave_preview()
        if not self._redo:
            return self._refused(CommandResult(False, "redo", "there is nothing to redo"))
        step = self._redo.pop()
        self._undo.append(step)
        return self._switch(step.after, step.selected_after, "redo", "redo")

    # --- previews -----------------------------------------------------------------------------
    def preview(self, command: Command) -> CommandResult:
        """Show what ``command`` would make of the document, without recording it.

        :attr:`document` becomes the command's result (listeners get a ``"preview"`` change)
        while :attr:`base_document` stays the document before the first preview: the history,
        :attr:`dirty` and what :meth:`save` writes do not change. Each preview applies to the
        base document (previews do not pile up); :meth:`end_preview` gives the base back, and
        so does any command, undo, redo, save or load before it runs. An animation is a stream
        of previews.
        """
        if not isinstance(command, Command):
            return CommandResult(
                False, "preview", f"command must be an editor Command, got {command!r}"
            )
        base = self.base_document
        try:
            outcome = command.apply(base)
        except CommandError as error:
            return CommandResult(False, command.label, str(error))
        except (KinegamiError, ValueError, TypeError, IndexError, ArithmeticError) as error:
            return CommandResult(False, command.label, f"{command.label}: {error}")
        self._preview_base = base
        return self._switch(outcome.document, self._selected, "preview", command.label,
                            outcome.warnings, outcome.sources)  # fmt: skip

    def end_preview(self) -> CommandResult:
        """Give back the document under the preview (nothing happens when not previewing)."""
        base = self._preview_base
        if base is None:
            return CommandResult(False, "end preview", "there is no preview to end")
        self._preview_base = None
        return self._switch(base, self._selected, "preview", "end preview")

    # --- files --------------------------------------------------------------------------------
    def save(self, path: str | os.PathLike | None = None) -> CommandResult:
        """Write the design file (default: the model's path) atomically; the model is then
        clean and belongs to that file."""
        self.end_preview()
        target = self._path if path is None else path
        if target is None:
            return CommandResult(False, "save", "path: the document has no file yet; give one")
        try:
            written = self._document.save(target)
        except (KinegamiError, ValueError, TypeError) as error:
            return CommandResult(False, "save", f"save: {error}")
        except OSError as error:
            return CommandResult(False, "save", f"save: cannot write {os.fspath(target)!r}: "
                                                f"{error.strerror or error}")  # fmt: skip
        self._path = written
        self._saved = self._document
        change = Change("save", selected=self._selected, dirty=False)
        self._notify(change)
        return CommandResult(True, "save", change=change)

    def load(self, path: str | os.PathLike) -> CommandResult:
        """Open the design file ``path`` in place of the document (the history is cleared);
        on failure nothing changes and the reason is the loader's message."""
        try:
            document = Document.load(path)
        except (KinegamiError, ValueError, TypeError, OSError) as error:
            return CommandResult(False, "load", f"load: {error}")
        self.end_preview()
        self._undo.clear()
        self._redo.clear()
        self._path = Path(os.fspath(path))
        self._saved = document
        return self._switch(document, None, "load", "load")

    # --- one helper per command ---------------------------------------------------------------
    def _propagate(self, propagate: bool | None) -> bool:
        return self.propagate if propagate is None else propagate

    def _target(self, joint):
        return self._selected if joint is None else joint

    def add_joint(self, kind: str, parameters=None, pose=None, *, after=None,
                  placement: str = "safe", relative: bool = True,
                  name: str | None = None) -> CommandResult:  # fmt: skip
        """Add a joint after ``after`` (default: the selected joint, else the last one); see
        :class:`~kinegami.editor.commands.AddJoint`."""
        after = self._target(after)
        return self.apply(cmd.AddJoint(kind, parameters or {}, pose, after, placement,
                                       relative, name))  # fmt: skip

    def add_branch(self, kind: str, parameters=None, pose=None, *, parent=None,
                   placement: str = "safe", relative: bool = True,
                   name: str | None = None) -> CommandResult:  # fmt: skip
        """Add a joint as a new child of ``parent`` (default: the selected joint, else the
        last one), beside its children; see :class:`~kinegami.editor.commands.AddBranch`."""
        parent = self._target(parent)
        return self.apply(cmd.AddBranch(kind, parameters or {}, pose, parent, placement,
                                        relative, name))  # fmt: skip

    def fit_junctions(self) -> CommandResult:
        """Slide the tree's joints whose junction socket does not fit (see
        :class:`~kinegami.editor.commands.FitJunctions`)."""
        return self.apply(cmd.FitJunctions())

    def delete(self, joint=None) -> CommandResult:
        """Delete a joint (default: the selected one)."""
        return self.apply(cmd.DeleteJoint(self._target(joint)))

    def slide(self, joint, distance: float, *, propagate: bool | None = None,
              applyToPreviousWaypoint: bool = False) -> CommandResult:  # fmt: skip
        """Slide a joint along its axis (``joint`` None: the selected one)."""
        return self.apply(
            cmd.SlideJoint(
                self._target(joint), distance, self._propagate(propagate), applyToPreviousWaypoint
            )
        )

    def roll(self, joint, angle: float, *, propagate: bool | None = None,
             applyToPreviousWaypoint: bool = False) -> CommandResult:  # fmt: skip
        """Turn a joint about its axis by ``angle`` radians."""
        return self.apply(
            cmd.RollJoint(
                self._target(joint), angle, self._propagate(propagate), applyToPreviousWaypoint
            )
        )

    def transform(self, joint, transform, *, propagate: bool | None = None,
                  kinematic: bool = False) -> CommandResult:  # fmt: skip
        """Move a waypoint or tip by a world transform (see TransformJoint)."""
        return self.apply(
            cmd.TransformJoint(
                self._target(joint), transform, self._propagate(propagate), kinematic
            )
        )

    def set_pose(self, joint, pose, *, propagate: bool | None = None) -> CommandResult:
        """Put a joint at a world pose (4x4; see :class:`~kinegami.editor.commands.
        SetJointPose`)."""
        return self.apply(cmd.SetJointPose(self._target(joint), pose, self._propagate(propagate)))

    def transform_all(self, transform) -> CommandResult:
        """Move the whole chain rigidly."""
        return self.apply(cmd.TransformAll(transform))

    def set_parameters(self, joint, **parameters) -> CommandResult:
        """Change a joint's parameters, e.g. ``set_parameters(3, numSinkLayers=2)``."""
        return self.apply(cmd.SetJointParameters(self._target(joint), parameters))

    def rename(self, joint, name: str | None) -> CommandResult:
        """Name a joint (None removes the name)."""
        return self.apply(cmd.RenameJoint(self._target(joint), name))

    def set_state(self, joint, state: float) -> CommandResult:
        """Set one joint's state."""
        return self.apply(cmd.SetJointState(self._target(joint), state))

    def set_states(self, states) -> CommandResult:
        """Set every joint's state."""
        return self.apply(cmd.SetJointStates(states))

    def compact(self, **options) -> CommandResult:
        """Compact the chain (options of :class:`~kinegami.editor.commands.Compact`; a chain
        with a task keeps it)."""
        try:
            command = cmd.Compact(**options)
        except TypeError as error:
            return CommandResult(False, "compact", f"compact: {error}")
        return self.apply(command)

    def design_for_task(self, **options) -> CommandResult:
        """Replace the chain (or tree) by one designed for the document's task (a tree for a
        tree task; options of :class:`~kinegami.editor.commands.DesignForTask`); one undoable
        step, the task kept."""
        try:
            command = cmd.DesignForTask(**options)
        except TypeError as error:
            return CommandResult(False, "design for task", f"design for task: {error}")
        return self.apply(command)

    def set_options(self, **options) -> CommandResult:
        """Change design options (see :class:`~kinegami.editor.commands.SetOptions`)."""
        try:
            command = cmd.SetOptions(**options)
        except TypeError as error:
            return CommandResult(False, "set options", f"set options: {error}")
        return self.apply(command)
