"""The browser view of the editor: one :class:`EditorView` binds an EditorModel to a viser
scene and side panel (``kinegami edit``, :mod:`kinegami.editor.server`; docs/editor.md).

The view holds no design state: every widget calls a model command, and the view redraws what
the model's :class:`~kinegami.editor.model.Change` says changed. Meshes are built in their
own frame (a joint's Pose, a link's start frame), so a part that only moved rigidly gets a new
pose and no new mesh. viser is imported by the caller (the server); this module only uses the
handles it is given, so tests can drive it with a server and no browser.
"""

from __future__ import annotations

import contextlib
import functools
import io
import itertools
import math
import tempfile
import threading
import time
import zipfile
from collections.abc import Callable
from dataclasses import dataclass, field
from pathlib import Path
from typing import Any

import numpy as np

from kinegami.editor import sheet_drawing
from kinegami.editor.background import Debounced, JobProcess, ProcessWorker
from kinegami.editor.commands import (
    JOINT_TYPES,
    Compact,
    Computed,
    DesignForTask,
    FitJunctions,
    LongCommand,
    ReplaceDocument,
    RollJoint,
    SetJointStates,
    SlideJoint,
)
from kinegami.editor.document import Document
from kinegami.editor.framing import Framing, box_corners, frame_box, grid_for_box, nice_step
from kinegami.editor.jobs import (
    MOTION_SAMPLES,
    TREE_MOTION_SAMPLES,
    WORKSPACE_SAMPLES,
    motion_check,
    workspace_points,
)
from kinegami.editor.keys import keys_script, shortcuts_markdown
from kinegami.editor.model import Change, CommandResult, EditorModel
from kinegami.editor.page_script import run_javascript, unsaved_changes_script
from kinegami.editor.tasks import TargetCheck, check_targets, labelled_targets, task_goals
from kinegami.editor.units import (
    DEGREE,
    angle_text,
    length_text,
    parameter_from_display,
    parameter_to_display,
    parameter_unit,
    pose_from_display,
    pose_to_display,
    state_from_display,
    state_text,
    state_to_display,
    state_unit,
)
from kinegami.errors import Cancelled, InvalidParameterError, InvalidTypeError, KinegamiError
from kinegami.geometry.screws import FIXED, REVOLUTE
from kinegami.limits import MAX_FILE_BYTES

__all__ = ["EditorView", "DOWNLOADS", "SHEET_FORMATS", "MAX_UPLOAD_BYTES", "gallery",
           "download_data"]  # fmt: skip

#: The largest design file a browser may upload (bytes): that of any design file
#: (kinegami.limits.MAX_FILE_BYTES, 16 MiB; docs/limits.md).
MAX_UPLOAD_BYTES = MAX_FILE_BYTES
#: Download buttons: label -> file suffix (through the export registry).
DOWNLOADS = {"DXF": ".dxf", "SVG": ".svg", "FOLD": ".fold", "PDF": ".pdf", "STL": ".stl",
             "URDF": ".urdf"}  # fmt: skip
#: What a tree's downloads are made of (kinegami.export.tree_build.write_tree_files formats):
#: a sheet each for these suffixes, every sheet in one PDF, the junction connectors.
SHEET_FORMATS = {".dxf": "dxf", ".svg": "svg", ".fold": "fold"}
#: The Sheet menu's entry for every sheet at once (a zip).
ALL_SHEETS = "all sheets (zip)"
GALLERY_DIR = Path(__file__).resolve().parents[2] / "examples" / "designs"

JOINT_COLOR = (70, 140, 220)
LINK_COLOR = (200, 200, 190)
SELECTED_COLOR = (250, 180, 40)
COLLIDING_COLOR = (220, 40, 40)
#: The kinds the "New joint" menu offers: every registered joint kind but the root-only ones
#: (a StartTip), the moving kinds first.
NEW_JOINT_KINDS = tuple(sorted(
    (name for name, kind in JOINT_TYPES.items() if not kind.closes_start),
    key=lambda name: JOINT_TYPES[name].motion == FIXED,
))
#: Seconds without a change before the crease-pattern panel is drawn again.
PATTERN_DELAY = 0.2
#: Width of the crease-pattern panel (pixels).
PATTERN_PANEL_WIDTH = 460
#: The animation: seconds of one back-and-forth sweep, and the most frames a second.
ANIMATION_PERIOD = 4.0
ANIMATION_FPS = 20.0
#: The vertical field of view assumed when the tab has not reported its camera (radians;
#: three.js's and viser's default).
DEFAULT_FOV = math.radians(75.0)
#: Seconds each start of the Compact button's compaction may search.
COMPACT_TIME_LIMIT = 30.0
#: Seconds without a change before the targets of the design's task are checked again.
TASK_DELAY = 0.3
#: The colours of a task's targets: reached clear, not reached, not checked (yet).
REACHED_COLOR = (40, 160, 80)
MISSED_COLOR = COLLIDING_COLOR
UNCHECKED_COLOR = (150, 150, 150)
#: The Task panel's text: as the panel's Markdown is set.
TASK_STYLE = "padding:0 0.6em;font-size:0.875rem;line-height:1.45"


def gallery(folder: Path = GALLERY_DIR) -> dict[str, Path]:
    """The gallery's design files by stem (examples/designs; empty when not installed)."""
    if not folder.is_dir():
        return {}
    return {p.stem: p for p in sorted(folder.glob("*.json"))}


def download_data(model: EditorModel, suffix: str, sheet: int | None = None,
                  sheets=None) -> tuple[str, bytes]:  # fmt: skip
    """(file name, bytes) of the current design in the format of ``suffix`` (``.json``: the
    design file; ``.urdf``: a zip of the URDF and its meshes). Raises the registry's errors.

    For a tree, ``.dxf``, ``.svg`` and ``.fold`` give sheet ``sheet`` (None: every sheet, in a
    zip), ``.pdf`` every sheet and ``"junctions"`` the printed junction connectors (STL and
    3MF, in a zip): the files ``kinegami build`` writes
    (:func:`kinegami.export.tree_build.write_tree_files`) of ``sheets`` (default:
    ``model.sheets()``). STL and URDF are the tree as drawn, through the registry.
    """
    from kinegami.export.registry import FORMATS

    stem = _file_stem(model)
    if suffix == ".json":
        return f"{stem}.json", model.to_design_text().encode()
    if model.is_tree and (suffix in SHEET_FORMATS or suffix in (".pdf", "junctions")):
        return _tree_files(model, suffix, sheet, model.sheets() if sheets is None else sheets,
                           stem)  # fmt: skip
    if suffix == "junctions":
        raise InvalidTypeError("junctions: a chain has none (a tree has one at every joint with "
                               "several children)")  # fmt: skip
    fmt = FORMATS[suffix]
    name = f"{stem}{suffix}"
    subject = model.chain if fmt.accepts == "chain" else model.pattern()
    data = fmt.render(subject, Path(name))
    if fmt.kind == "files":
        return f"{stem}_urdf.zip", _zipped(data)
    return name, data.encode() if isinstance(data, str) else bytes(data)


def _zipped(files) -> bytes:
    """A zip of ``{relative path: bytes or text}``."""
    buffer = io.BytesIO()
    with zipfile.ZipFile(buffer, "w", zipfile.ZIP_DEFLATED) as archive:
        for path, content in sorted(files.items()):
            archive.writestr(str(path), content)
    return buffer.getvalue()


def _tree_files(model: EditorModel, suffix: str, sheet: int | None, sheets,
                stem: str) -> tuple[str, bytes]:  # fmt: skip
    """A tree's sheets, PDF or junctions as ``kinegami build`` writes them (written into a
    private temporary folder, read back and removed)."""
    import dataclasses

    from kinegami.export.tree_build import write_tree_files

    fabrication = sheets.fabrication
    fmt = SHEET_FORMATS.get(suffix, suffix.lstrip("."))
    if sheet is not None:
        if fmt not in SHEET_FORMATS.values():
            raise InvalidParameterError(f"sheet: only DXF, SVG and FOLD are made per sheet, not "
                                        f"{suffix!r}")  # fmt: skip
        if (
            isinstance(sheet, bool)
            or not isinstance(sheet, int)
            or not (0 <= sheet < len(fabrication.sheets))
        ):
            raise InvalidParameterError(f"sheet must be in [0, {len(fabrication.sheets) - 1}] "
                                        f"(the tree's sheets), got {sheet!r}")  # fmt: skip
        fabrication = dataclasses.replace(fabrication, sheets=(fabrication.sheets[sheet],))
    if fmt == "junctions" and not fabrication.junctions:
        raise InvalidParameterError("junctions: this tree has none (no joint has several "
                                    "children)")  # fmt: skip
    document = model.document
    with tempfile.TemporaryDirectory(prefix="kinegami-edit-") as folder:
        written = write_tree_files(fabrication, folder, stem, [fmt], units=document.units,
                                   twistPortion=document.twist_portion,
                                   names=document.names)  # fmt: skip
        files = {path.name: path.read_bytes() for path in written if path.is_file()}
    if len(files) == 1:
        ((name, data),) = files.items()
        return name, data
    label = "junctions" if fmt == "junctions" else f"sheets_{fmt}"
    return f"{stem}_{label}.zip", _zipped(files)


def _file_stem(model: EditorModel) -> str:
    name = model.document.name or (model.path.stem if model.path else "") or "design"
    stem = "".join(c if c.isalnum() or c in "-_" else "_" for c in str(name)).strip("_")
    return stem[:64] or "design"


def _locked(method):
    """Run a view method under the view's lock."""

    @functools.wraps(method)
    def wrapper(self, *args, **kwargs):
        with self.lock:
            return method(self, *args, **kwargs)

    return wrapper


def _local_pieces(joint) -> list[np.ndarray]:
    """A joint's convex pieces' points in its own frame (its pose's)."""
    P = np.asarray(joint.pose_matrix, dtype=float)
    return [(np.asarray(piece.points, dtype=float) - P[:3, 3]) @ P[:3, :3]
            for piece in joint.body_pieces()]  # fmt: skip


def _wxyz(R: np.ndarray) -> tuple[float, float, float, float]:
    """Unit quaternion (w, x, y, z) of a rotation matrix (Shepperd's method; called for every
    moved part of a drag step, so plain floats rather than scipy)."""
    (m00, m01, m02), (m10, m11, m12), (m20, m21, m22) = np.asarray(R, dtype=float).tolist()
    trace = m00 + m11 + m22
    if trace > 0.0:
        s = 2.0 * math.sqrt(trace + 1.0)
        q = (0.25 * s, (m21 - m12) / s, (m02 - m20) / s, (m10 - m01) / s)
    elif m00 > m11 and m00 > m22:
        s = 2.0 * math.sqrt(1.0 + m00 - m11 - m22)
        q = ((m21 - m12) / s, 0.25 * s, (m01 + m10) / s, (m02 + m20) / s)
    elif m11 > m22:
        s = 2.0 * math.sqrt(1.0 + m11 - m00 - m22)
        q = ((m02 - m20) / s, (m01 + m10) / s, 0.25 * s, (m12 + m21) / s)
    else:
        s = 2.0 * math.sqrt(1.0 + m22 - m00 - m11)
        q = ((m10 - m01) / s, (m02 + m20) / s, (m12 + m21) / s, 0.25 * s)
    n = math.sqrt(sum(v * v for v in q))
    return tuple(v / n for v in q)


def _task_box(content: str) -> str:
    """The Task panel's HTML around ``content`` (escaped already)."""
    return f'<div style="{TASK_STYLE}">{content}</div>'


def _target_colour(reached: bool | None) -> tuple[int, int, int]:
    """A task target's colour: green reached, red not, grey not checked (None)."""
    return UNCHECKED_COLOR if reached is None else REACHED_COLOR if reached else MISSED_COLOR


def _matrix(wxyz) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    w, x, y, z = wxyz
    return Rotation.from_quat([x, y, z, w]).as_matrix()


@dataclass
class Job:
    """A long job of a tab (Compact, a motion check, Fit junctions) while it runs: what it
    is, the document it started from, its progress and its cancel flag."""

    label: str  # "compact", "motion check", "fit junctions"
    title: str  # what the panel says while it runs: "Compacting"
    unit: str  # its steps: "starts", "configurations", "sockets"
    model: EditorModel
    source: Document
    cancel: threading.Event = field(default_factory=threading.Event)
    finished: threading.Event = field(default_factory=threading.Event)
    started: float = field(default_factory=time.monotonic)
    done: int = 0
    total: int = 0
    #: How it ended: "done", "cancelled", "failed" or "dropped" (None while it runs).
    outcome: str | None = None


@dataclass
class _Node:
    """The scene nodes of one joint or link: its meshes in its own frame."""

    uid: int
    obj: Any  # the joint or link drawn (an immutable value)
    handles: list = field(default_factory=list)
    frame: Any = None
    sent: int = 0  # how many times its meshes were sent
    lo: Any = None  # its meshes' box in its own frame (3-vectors; None before any mesh)
    hi: Any = None
    matrix: Any = None  # its frame now (4x4, world)
    turn: Any = None  # a revolute joint's: the frame its distal half hangs from (see _joint_node)
    shape: Any = None  # with ``turn``: the joint's pieces at state 0 in its own frame


class EditorView:
    """One document in one browser tab: an EditorModel drawn with a viser client's ``scene``
    and ``gui`` (or a server's, in tests).

    Parameters
    ----------
    target : a viser ClientHandle (or ViserServer): its ``scene``, ``gui``,
        ``send_file_download`` and ``add_notification`` are used.
    model : the model to edit (default: the starter design).
    autosave_for : ``autosave_for(path)`` gives the
        :class:`~kinegami.editor.autosave.Autosaver` of a design file (None: a design with no
        file); None: no autosave.
    recovery : an autosave found on start (:class:`~kinegami.editor.autosave.Recovery`) to
        offer back in a dialog; ``on_recovery(choice)`` is called with ``"recover"`` or
        ``"discard"`` once the user chose.
    pattern_delay : seconds without a change before the crease-pattern panel is drawn again.
    worker : a :class:`~kinegami.editor.background.ProcessWorker` that fits a tree's junctions
        for the pattern panel (seconds of work) away from the tab's lock and the interpreter
        lock; None: fitted in the panel's thread, holding the tab's lock.
    background : run long jobs (Compact, the motion check, Fit junctions) in the tab's own
        :class:`~kinegami.editor.background.JobProcess` (False: in a thread of this process,
        which holds the interpreter lock meanwhile; tests).
    """

    def __init__(self, target: Any, model: EditorModel | None = None, *,
                 autosave_for: Callable | None = None, recovery=None,
                 on_recovery: Callable[[str], None] | None = None,
                 pattern_delay: float = PATTERN_DELAY,
                 worker: ProcessWorker | None = None, background: bool = True):  # fmt: skip
        self.target = target
        self.scene = target.scene
        self.gui = target.gui
        self.model = model if model is not None else EditorModel()
        self.message = ""  # the last reason or warning shown
        self.meshes_sent = 0  # meshes sent since the view started (tests read it)
        self._uids = 0
        self._joints: list[_Node] = []
        self._links: list[_Node] = []
        self._colliding: set[tuple[str, int]] = set()
        self._syncing = False
        #: Held while a callback edits the model (viser runs callbacks in a thread pool).
        self.lock = threading.RLock()
        self._sliders: list = []
        self._gizmo = None
        self._gizmo_pose: np.ndarray | None = None
        self._dragging = False  # a handle drag is previewed (the handle is the user's)
        self._drags = itertools.count(1)
        self._drag_latest = 0
        self._autosave_for = autosave_for
        self.autosave = None if autosave_for is None else autosave_for(self.model.path)
        self._animation: threading.Event | None = None
        #: How many times the crease-pattern panel was sent (tests read it).
        self.pattern_draws = 0
        self.animation_frames = 0  # frames the running or last animation showed
        self._closed = False
        self._pattern_lines = None  # (pattern, units, SheetLines) last drawn
        self._pattern_key = None
        self._worker = worker
        self._sheet_lines: dict = {}  # id of a tree sheet's pattern -> (pattern, SheetLines)
        self._pattern_redraw = Debounced(self.redraw_pattern, pattern_delay,
                                         name="kinegami-pattern")  # fmt: skip
        self._jobs = JobProcess() if background else None
        self._task_check = Debounced(self.check_task, TASK_DELAY, name="kinegami-task")
        self._task_handles: list = []  # the scene nodes of the task's targets
        self._task_key: Any = None  # (task, units, states shown) the nodes were drawn for
        self._task_goals: Any = None  # ((task, units), TaskGoals or the error)
        #: The targets' checks shown (one TargetCheck each; an exception when the task could
        #: not be checked; None: not checked) and the document they are of.
        self.task_checks: tuple[TargetCheck, ...] | Exception | None = None
        self.task_checked: Document | None = None
        #: How many times the targets' checks were shown (tests read it).
        self.task_draws = 0
        self._target_handle = None  # the reach target's handle (made when first shown)
        self._target_marker = None
        self._reach_point: np.ndarray | None = None
        self.reach_answer = None  # the last answer of reach_to (tests read it)
        self._workspace_cloud = None
        self.workspace_points: np.ndarray | None = None  # the last workspace drawn
        self._job: Job | None = None
        #: A finished job's command waiting for an answer (the design changed meanwhile).
        self.pending_result: Computed | None = None
        self._motion_document: Document | None = None
        self._stale_modal = None  # asks whether a result for an older document applies
        self._unsaved_modal = None  # asks what to do with unsaved changes before an open
        #: The open waiting for an answer about unsaved changes: (document, message), or None.
        self.pending_open: tuple[Document, str] | None = None
        self._unsaved_shown: bool | None = None  # what the page was last told
        #: The camera framing last computed (:class:`~kinegami.editor.framing.Framing`) and
        #: the grid (:class:`~kinegami.editor.framing.GridLayout`), sized to the design.
        self.framing: Framing | None = None
        self.grid = None
        self._grid_handle = None
        self._world_axes = None
        self._drag_cancelled = False  # Escape during a handle drag: its end applies nothing
        #: What Escape does to an open dialog, the latest last (it calls and removes it).
        self.dialog_cancels: list[Callable[[], None]] = []
        self._joint_fields: dict = {}  # the Selected joint folder's typed fields
        self._joint_fields_key: Any = ()  # () until the folder is first filled
        self._filled_for: int | None = None  # the joint the fields were last filled for
        self._shown_fields: dict = {}  # field -> (value shown, exact value)
        self._build_panel()
        self._build_pattern_panel()
        self._build_help_panel()
        self.send_shortcuts()
        self._unsubscribe = self.model.subscribe(self._on_change)
        self._redraw_all()
        self._size_scene()
        self.frame_camera()
        self._pattern_redraw.trigger()
        self._task_check.trigger()
        self._recovery_modal = None
        self._sync_unsaved()
        if recovery is not None:
            self.offer_recovery(recovery, on_recovery)

    # --- model binding ------------------------------------------------------------------------
    @property
    def _r(self) -> float:
        return float(self.model.chain.Joints[0].r)

    @_locked
    def set_model(self, model: EditorModel) -> None:
        """Edit another model (a loaded example or upload): everything is drawn again."""
        self.stop_animation()
        self._unsubscribe()
        self.model = model
        self.model.propagate = bool(self._propagate.value)
        self._unsubscribe = model.subscribe(self._on_change)
        if self._autosave_for is not None:
            self.autosave = self._autosave_for(model.path)
        self._save_file.visible = model.path is not None
        self._clear_scene()
        self._redraw_all()
        self._drag_cancelled = False
        self._size_scene()
        self.frame_camera()
        self._pattern_redraw.trigger()
        self._task_check.trigger()
        self._sync_unsaved()

    def frame_camera(self) -> Framing:
        """Point a browser tab's camera at the whole design (every mesh drawn) and set its
        clipping planes and zoom limits to the design's size (docs/editor.md, Framing).
        Returns the framing (kept in :attr:`framing`); a server target (tests) has no camera
        and only gets it computed for a 75° view of aspect 1."""
        lo, hi = self.design_box()
        camera = getattr(self.target, "camera", None)
        fov, aspect = DEFAULT_FOV, 1.0
        if camera is not None:
            with contextlib.suppress(AssertionError, AttributeError, TypeError, ValueError):
                fov = float(camera.fov) if 0.0 < float(camera.fov) < math.pi else DEFAULT_FOV
                width, height = float(camera.image_width), float(camera.image_height)
                if width > 0.0 and height > 0.0:
                    aspect = width / height
        framing = frame_box(lo, hi, fov, aspect)
        self.framing = framing
        if camera is not None:
            # in an order that never has near > far or min > max (viser refuses min > max)
            if framing.far >= camera.near:
                camera.far, camera.near = framing.far, framing.near
            else:
                camera.near, camera.far = framing.near, framing.far
            if framing.max_distance >= camera.min_orbit_distance:
                camera.max_orbit_distance = framing.max_distance
                camera.min_orbit_distance = framing.min_distance
            else:
                camera.min_orbit_distance = framing.min_distance
                camera.max_orbit_distance = framing.max_distance
            camera.up_direction = framing.up
            camera.position = framing.position
            camera.look_at = framing.look_at
        return framing

    @_locked
    def frame_all(self) -> Framing:
        """The Frame all button (and the F key): the whole design in view."""
        framing = self.frame_camera()
        units = self.model.document.units
        self._say(f"framed all: {length_text(2.0 * framing.radius, units)} across, seen from "
                  f"{length_text(framing.distance, units)}")  # fmt: skip
        return framing

    def design_box(self) -> tuple[np.ndarray, np.ndarray]:
        """The box around every mesh drawn (world coordinates, in the design's units)."""
        points = []
        for node in self._joints + self._links:
            if node is None or node.lo is None or node.matrix is None:
                continue
            M = np.asarray(node.matrix, dtype=float)
            points.append(box_corners(node.lo, node.hi) @ M[:3, :3].T + M[:3, 3])
        targets = self.task_positions()
        if points and len(targets):  # the task's targets are drawn beside the design
            points += [targets - self._r, targets + self._r]
        if not points:  # nothing drawn: the joints' origins, a tube radius around them
            origins = np.array([j.pose_matrix[:3, 3] for j in self.model.chain.Joints])
            return origins.min(0) - self._r, origins.max(0) + self._r
        corners = np.concatenate(points)
        return corners.min(0), corners.max(0)

    def _size_scene(self) -> None:
        """Size the grid, the world axes and the joint handle to the design (on start and
        whenever another design is opened): a grid under the design, its lines at round
        numbers of the design's units; axes one grid section long."""
        grid = grid_for_box(*self.design_box())
        self.grid = grid
        if self._grid_handle is not None:
            self._grid_handle.remove()
        if self._world_axes is not None:
            self._world_axes.remove()
        self._grid_handle = self.scene.add_grid(
            "/grid", width=grid.width, height=grid.width, plane="xy", cell_size=grid.cell,
            section_size=grid.section, position=grid.centre, cell_color=(210, 210, 210),
            section_color=(150, 150, 150), fade_distance=20.0 * grid.width,
        )  # fmt: skip
        self._world_axes = self.scene.add_frame("/world", axes_length=grid.section,
                                                axes_radius=0.01 * grid.section)  # fmt: skip
        if self._gizmo is not None:
            self._gizmo.scale = 3.0 * self._r
        step = nice_step(0.5 * self._r)
        self._step.value, self._step.step = step, nice_step(0.1 * self._r)
        self._update_units()

    def close(self) -> None:
        """Stop listening to the model (the tab closed); a pending autosave is written and a
        running job is stopped (its result dropped)."""
        with self.lock:
            self.stop_animation()
            self._unsubscribe()
            self._closed = True
            job = self._job
        if job is not None:
            job.cancel.set()
        if self._jobs is not None:
            self._jobs.close()
        self._pattern_redraw.close()
        self._task_check.close()
        if self.autosave is not None:
            self.autosave.flush()

    def flush(self) -> None:
        """Do now what waits for a pause: draw the crease-pattern panel and check the task's
        targets if they are due."""
        self._pattern_redraw.flush()
        self._task_check.flush()

    def act(self, action) -> CommandResult:
        """Run ``action()`` (a model call returning a CommandResult) under the view's lock and
        show its outcome (widget callbacks run in viser's thread pool). A running animation
        stops first."""
        with self.lock:
            self.stop_animation()
            return self.run(action())

    def run(self, result: CommandResult) -> CommandResult:
        """Show a command's outcome: the reason when refused, else its warnings."""
        if not result.ok:
            self._say(f"**Refused:** {result.reason}")
        elif result.warnings:
            self._say("**Warning:** " + "; ".join(result.warnings))
        else:
            self._say(f"{result.action}: done")
        return result

    def _say(self, text: str) -> None:
        self.message = text
        self._message.content = text

    def _on_change(self, change: Change) -> None:
        self._pattern_redraw.trigger()
        if change.kind != "select" and self.model.document.task is not None:
            self._task_check.trigger()
        atomic = getattr(self.target, "atomic", None)
        # one batch: the tab applies the step at once, and the server wakes its sender once
        with atomic() if atomic is not None else contextlib.nullcontext():
            if change.kind == "select":
                self._recolour()
                self._update_gizmo()
                self._update_panel()
                return
            self._update_scene(change)
            self._update_panel(structure=change.structure)
            self._update_task()
        if self.autosave is not None:
            if change.kind == "save":
                self.autosave.discard()
            elif change.kind != "preview":
                self.autosave.record(self.model.base_document, self.model.dirty, self)
        if (change.kind != "preview" and self._motion.visible
                and self.model.base_document is not self._motion_document):  # fmt: skip
            self._motion.visible = False  # the motion check was of another document
        self._sync_unsaved()

    def _sync_unsaved(self) -> None:
        """Tell the page whether closing it now would lose unsaved changes (it then warns)."""
        dirty = self.model.dirty
        if dirty != self._unsaved_shown:
            self._unsaved_shown = dirty
            run_javascript(self.target, unsaved_changes_script(dirty))

    # --- scene --------------------------------------------------------------------------------
    def _new_uid(self) -> int:
        self._uids += 1
        return self._uids

    def _clear_scene(self) -> None:
        for node in self._joints + self._links:
            if node is not None:
                self._remove(node)
        self._joints, self._links = [], []

    def _remove(self, node: _Node) -> None:
        for handle in node.handles:
            handle.remove()
        if node.turn is not None:
            node.turn.remove()
            node.turn = None
        if node.frame is not None:
            node.frame.remove()
        node.handles = []

    def _redraw_all(self) -> None:
        chain = self.model.chain
        self._joints = [self._joint_node(j, i) for i, j in enumerate(chain.Joints)]
        self._links = [self._link_node(chain.Links[i], i) if i else None
                       for i in range(len(chain.Joints))]  # fmt: skip
        self._refresh_clearance()
        self._recolour()
        self._update_gizmo()
        self._update_panel(structure=True)
        self._update_task()

    def _joint_node(self, joint, i: int) -> _Node:
        """A joint's meshes under a frame at its pose. A revolute joint's are made at state 0,
        its distal half under a frame of its own turned by the state (the half turns rigidly
        about the axis): a change of state, as in a drag, then turns that frame
        (:meth:`_turn`) instead of making and sending new meshes."""
        from kinegami.clearance.solids import joint_parts

        node = _Node(self._new_uid(), joint)
        pose = np.asarray(joint.pose_matrix, dtype=float)
        node.frame = self._add_frame(f"/chain/joint{node.uid}", pose, axes=joint.r)
        turns = joint.motion == REVOLUTE
        shape = joint.with_state(0.0) if turns else joint
        for part in joint_parts(shape, i):
            name = f"/chain/joint{node.uid}/{part.side or 'body'}"
            vertices = part.vertices
            if turns and part.side == "distal":
                node.turn = self.scene.add_frame(f"/chain/joint{node.uid}/turn", show_axes=False)
                name = f"/chain/joint{node.uid}/turn/distal"
                G = joint.state_transform(float(joint.state))
                vertices = vertices @ G[:3, :3].T + G[:3, 3]  # where it is drawn
            node.handles.append(self._add_mesh(name, part, pose, JOINT_COLOR, node))
            self._grow(node, vertices, pose)
        if turns:
            node.shape = _local_pieces(shape)
            self._turn(node, joint)
        node.sent += 1
        return node

    def _turn(self, node: _Node, joint) -> None:
        """Turn a revolute joint's distal half to the joint's state (its frame, in the joint's
        frame: P^-1 G(state) P, G the joint's world motion and P its pose)."""
        if node.turn is None:
            return
        P = np.asarray(joint.pose_matrix, dtype=float)
        local = np.linalg.inv(P) @ joint.state_transform(float(joint.state)) @ P
        node.turn.wxyz, node.turn.position = _wxyz(local[:3, :3]), local[:3, 3]

    @staticmethod
    def _same_shape(node: _Node, joint) -> bool:
        """Whether ``joint`` is the node's revolute joint but for its state and a rigid move:
        its pieces at state 0, in its own frame, are the node's (1e-9 r)."""
        if node.turn is None or joint.motion != REVOLUTE or type(joint) is not type(node.obj):
            return False
        pieces = _local_pieces(joint.with_state(0.0))
        return len(pieces) == len(node.shape) and all(
            a.shape == b.shape and np.abs(a - b).max() <= 1e-9 * joint.r
            for a, b in zip(pieces, node.shape, strict=True))  # fmt: skip

    def _link_node(self, link, i: int) -> _Node:
        from kinegami.clearance.solids import link_parts

        node = _Node(self._new_uid(), link)
        frame = np.asarray(link.start_frame, dtype=float)
        node.frame = self._add_frame(f"/chain/link{node.uid}", frame, axes=None)
        chain = self.model.chain
        for part in link_parts(link, i, chain.numSides, self.model.document.twist_portion):
            name = f"/chain/link{node.uid}/{part.side}"
            node.handles.append(self._add_mesh(name, part, frame, LINK_COLOR, None))
            self._grow(node, part.vertices, frame)
        node.sent += 1
        return node

    def _add_frame(self, name: str, frame: np.ndarray, axes: float | None):
        """The node a part's meshes hang from, at ``frame`` (a joint's shows its axes): a
        rigid move sets its pose only."""
        return self.scene.add_frame(
            name, show_axes=axes is not None, axes_length=1.5 * (axes or 1.0),
            axes_radius=0.03 * (axes or 1.0), wxyz=_wxyz(frame[:3, :3]), position=frame[:3, 3],
        )  # fmt: skip

    def _add_mesh(self, name: str, part, frame: np.ndarray, color, joint_node):
        """A part's mesh under its node, in the node's frame."""
        R, t = frame[:3, :3], frame[:3, 3]
        local = (part.vertices - t) @ R
        handle = self.scene.add_mesh_simple(name, local, part.faces, color=color,
                                            flat_shading=True)  # fmt: skip
        self.meshes_sent += 1
        if joint_node is not None:
            handle.on_click(lambda event, node=joint_node: self._click(node))
        return handle

    @_locked
    def _click(self, node: _Node) -> None:
        if node in self._joints:
            self.model.select(self._joints.index(node))

    def click_joint(self, index: int) -> None:
        """What a click on joint ``index``'s mesh does (select it)."""
        self._click(self._joints[index])

    def _move(self, node: _Node, frame: np.ndarray) -> None:
        node.frame.wxyz, node.frame.position = _wxyz(frame[:3, :3]), frame[:3, 3]
        node.matrix = frame

    @staticmethod
    def _grow(node: _Node, vertices: np.ndarray, frame: np.ndarray) -> None:
        """Widen a node's box (in its own frame) by a mesh's world ``vertices``."""
        if not len(vertices):
            return
        local = (np.asarray(vertices, dtype=float) - frame[:3, 3]) @ frame[:3, :3]
        lo, hi = local.min(0), local.max(0)
        node.lo = lo if node.lo is None else np.minimum(node.lo, lo)
        node.hi = hi if node.hi is None else np.maximum(node.hi, hi)
        node.matrix = frame

    def _update_scene(self, change: Change) -> None:
        chain = self.model.chain
        joints, links = chain.Joints, chain.Links
        old_joints, old_links = self._joints, self._links
        if change.structure or len(joints) != len(old_joints):
            sources = change.joint_sources or (None,) * len(joints)
            used = set()
            new_joints, new_links = [], []
            for i, joint in enumerate(joints):
                s = sources[i] if i < len(sources) else None
                if s is not None and s < len(old_joints) and old_joints[s].obj is joint:
                    new_joints.append(old_joints[s])
                    used.add(("j", s))
                else:
                    new_joints.append(self._joint_node(joint, i))
                if i == 0:
                    new_links.append(None)
                    continue
                old = next((k for k, n in enumerate(old_links)
                            if n is not None and n.obj is links[i] and ("l", k) not in used),
                           None)  # fmt: skip
                if old is not None:
                    new_links.append(old_links[old])
                    used.add(("l", old))
                else:
                    new_links.append(self._link_node(links[i], i))
            for k, node in enumerate(old_joints):
                if ("j", k) not in used:
                    self._remove(node)
            for k, node in enumerate(old_links):
                if node is not None and ("l", k) not in used:
                    self._remove(node)
            self._joints, self._links = new_joints, new_links
        else:
            reshaped = set(change.reshaped_joints)
            for i in change.joints:
                if i in reshaped and self._same_shape(old_joints[i], joints[i]):
                    self._joints[i].obj = joints[i]  # turned: its distal half's frame only
                    self._move(self._joints[i], np.asarray(joints[i].pose_matrix, dtype=float))
                    self._turn(self._joints[i], joints[i])
                elif i in reshaped:
                    self._remove(old_joints[i])
                    self._joints[i] = self._joint_node(joints[i], i)
                else:
                    self._joints[i].obj = joints[i]
                    self._move(self._joints[i], np.asarray(joints[i].pose_matrix, dtype=float))
            reshaped = set(change.reshaped_links)
            for i in change.links:
                if i == 0:
                    continue
                if i in reshaped or self._links[i] is None:
                    if self._links[i] is not None:
                        self._remove(self._links[i])
                    self._links[i] = self._link_node(links[i], i)
                else:
                    self._links[i].obj = links[i]
                    self._move(self._links[i], np.asarray(links[i].start_frame, dtype=float))
            # the unchanged parts are equal values; keep the current objects (a later insertion
            # or delete matches nodes to parts by identity)
            for i, node in enumerate(self._joints):
                node.obj = joints[i]
            for i, node in enumerate(self._links):
                if node is not None:
                    node.obj = links[i]
        self._refresh_clearance()
        self._recolour()
        self._update_gizmo()

    def _refresh_clearance(self) -> None:
        report = self.model.clearance()
        self._colliding = set()
        for pair in report.pairs:
            for element in pair.elements:
                if element < 0:
                    continue
                kind = "joint" if element % 2 == 0 else "link"
                self._colliding.add((kind, (element + 1) // 2))
        # the verdict kinegami build and check print, in bold with the first pairs when not clear
        self._clearance_text = report.markdown(self.model.document.units, listed=8)

    def colour_of(self, kind: str, index: int) -> tuple[int, int, int]:
        """The colour a joint or link is drawn in (selected, colliding or plain)."""
        if kind == "joint" and index == self.model.selected:
            return SELECTED_COLOR
        if (kind, index) in self._colliding:
            return COLLIDING_COLOR
        return JOINT_COLOR if kind == "joint" else LINK_COLOR

    def _recolour(self) -> None:
        for kind, nodes in (("joint", self._joints), ("link", self._links)):
            for i, node in enumerate(nodes):
                if node is None:
                    continue
                color = self.colour_of(kind, i)
                for handle in node.handles:
                    if tuple(handle.color) != color:
                        handle.color = color

    # --- handles ------------------------------------------------------------------------------
    def _update_gizmo(self) -> None:
        if self._dragging:
            return  # the handle follows the mouse; its start pose is what the drag measures from
        index = self.model.selected
        if index is None or index >= len(self.model.chain.Joints):
            if self._gizmo is not None:
                self._gizmo.visible = False
            self._gizmo_pose = None
            return
        pose = np.asarray(self.model.chain.Joints[index].pose_matrix, dtype=float)
        self._gizmo_pose = pose
        if self._gizmo is None:
            self._gizmo = self.scene.add_transform_controls(
                "/gizmo", scale=3.0 * self._r, active_axes=(False, False, True),
                disable_sliders=True, depth_test=False,
            )  # fmt: skip
            self._gizmo.on_update(self._on_gizmo)
        self._gizmo.visible = True
        self._gizmo.wxyz, self._gizmo.position = _wxyz(pose[:3, :3]), pose[:3, 3]

    def _on_gizmo(self, event) -> None:
        phase = getattr(event, "phase", "end")
        if phase == "start":
            self._drag_cancelled = False
        elif self._drag_cancelled:  # Escape cancelled this drag: the rest of it is ignored
            if phase == "end":
                with self.lock:
                    self._drag_cancelled = False
                    self._update_gizmo()  # the handle goes back to the joint
            return
        position = np.asarray(self._gizmo.position, dtype=float)
        wxyz = tuple(self._gizmo.wxyz)
        self._drag_latest = drag = next(self._drags)  # later events make earlier ones stale
        if phase == "end":
            self.drag_to(position, wxyz)
        elif phase == "update":
            self.drag_preview(position, wxyz, drag)

    def _axis_motion(self, position, wxyz) -> tuple[float, float]:
        """(slide along, roll about) the selected joint's axis from the drag's start pose."""
        R0, p0 = self._gizmo_pose[:3, :3], self._gizmo_pose[:3, 3]
        distance = float(np.dot(np.asarray(position, dtype=float) - p0, R0[:, 2]))
        relative = R0.T @ _matrix(wxyz)
        return distance, math.atan2(relative[1, 0], relative[0, 0])

    @_locked
    def drag_preview(self, position, wxyz, drag: int | None = None) -> CommandResult | None:
        """Show a handle drag in progress: the slide (or roll) to ``position``/``wxyz`` as a
        preview, so the chain follows the handle without entering the history; the drag's
        end (:meth:`drag_to`) makes it a command. An event overtaken by a later one of the
        same drag (``drag``) is skipped; a refused step shows the reason and keeps the last
        good one."""
        if drag is not None and drag != self._drag_latest:
            return None
        self.stop_animation()
        if self._gizmo_pose is None or self.model.selected is None:
            return None
        self._dragging = True
        distance, angle = self._axis_motion(position, wxyz)
        joint, propagate = self.model.selected, bool(self.model.propagate)
        if abs(distance) > 1e-9 * self._r:
            command = SlideJoint(joint, distance, propagate)
        elif abs(angle) > 1e-9:
            command = RollJoint(joint, angle, propagate)
        else:
            self.model.end_preview()
            return None
        result = self.model.preview(command)
        if not result.ok:
            self._say(f"**Refused:** {result.reason}")
        return result

    @_locked
    def drag_to(self, position, wxyz) -> CommandResult | None:
        """Apply a finished handle drag: the slide along the selected joint's axis and the
        roll about it that take its Pose to ``position``/``wxyz`` (other motion is ignored).
        A refused move snaps the handle back and shows the reason."""
        self._dragging = False
        self.stop_animation()
        if self._gizmo_pose is None or self.model.selected is None:
            self.model.end_preview()
            return None
        distance, angle = self._axis_motion(position, wxyz)
        result = None
        if abs(distance) > 1e-9 * self._r:
            result = self.run(self.model.slide(None, distance))
        if (result is None or result.ok) and abs(angle) > 1e-9:
            result = self.run(self.model.roll(None, angle))
        self.model.end_preview()  # a drag back to where it began applies nothing
        self._update_gizmo()  # snaps back when refused
        return result

    # --- side panel ---------------------------------------------------------------------------
    def _build_panel(self) -> None:
        gui = self.gui
        self._message = gui.add_markdown("")
        # a running job: what it does, its progress and its Cancel button (hidden otherwise)
        self._job_text = gui.add_markdown("", visible=False)
        self._job_bar = gui.add_progress_bar(0.0, animated=True, visible=False)
        self._job_cancel = gui.add_button("Cancel", color="red", visible=False,
                                          hint="stop the running job; nothing changes")  # fmt: skip
        self._job_cancel.on_click(lambda _: self.cancel_job())
        # the task the design is made for: its targets and the design search (docs/editor.md)
        self._task_folder = gui.add_folder("Task", visible=self.model.document.task is not None)
        with self._task_folder:
            self._task_html = gui.add_html("")
            self._design_button = gui.add_button(
                "Design for task", hint="search a design whose tip (a tree: every leaf's tip, "
                "grasp by grasp) reaches every target exactly, clear of itself, as kinegami "
                "design does (runs in the background: Cancel stops it, Undo takes it back)",
            )  # fmt: skip
            self._design_button.on_click(lambda _: self.design_for_task())
        with gui.add_folder("View"):
            self._frame_button = gui.add_button("Frame all", hint="F: the whole design in view")
            self._frame_button.on_click(lambda _: self.frame_all())
            self._view_text = gui.add_markdown("")
        with gui.add_folder("Edit"):
            self._undo_button = gui.add_button("Undo", hint="Ctrl+Z")
            self._undo_button.on_click(lambda _: self.act(self._undo))
            self._redo_button = gui.add_button("Redo", hint="Ctrl+Shift+Z or Ctrl+Y")
            self._redo_button.on_click(lambda _: self.act(self._redo))
            self._propagate = gui.add_checkbox(
                "Propagate",
                initial_value=self.model.propagate,
                hint="moves carry the later joints along",
            )
            self._propagate.on_update(
                lambda _: setattr(self.model, "propagate", bool(self._propagate.value))
            )
            self._joint_list = gui.add_dropdown("Joint", ("(none)",))
            self._joint_list.on_update(self._on_joint_list)
            self._joint_info = gui.add_markdown("")
            self._step = gui.add_number(
                f"Slide by ({self.model.document.units})", initial_value=0.5, step=0.1,
                hint="the distance of - slide and + slide, in the design's units",
            )  # fmt: skip
            slide = gui.add_button_group("Slide", ("- slide", "+ slide"))
            slide.on_click(
                lambda e: self.act(
                    lambda: self.model.slide(
                        None, (1 if e.target.value == "+ slide" else -1) * float(self._step.value)
                    )
                )
            )
            self._angle = gui.add_number("Roll by (deg)", initial_value=15.0, step=5.0)
            roll = gui.add_button_group("Roll", ("- roll", "+ roll"))
            roll.on_click(lambda e: self.act(lambda: self.model.roll(
                None, (1 if e.target.value == "+ roll" else -1)
                * math.radians(float(self._angle.value)))))  # fmt: skip
            self._kind = gui.add_dropdown("New joint", NEW_JOINT_KINDS)
            add = gui.add_button("Add joint after selected")
            add.on_click(lambda _: self.act(lambda: self.model.add_joint(str(self._kind.value))))
            branch = gui.add_button(
                "Add branch at selected",
                hint="a new child of the selected joint, beside its children (on a chain, "
                "a branch makes it a tree)",
            )  # fmt: skip
            branch.on_click(lambda _: self.add_branch(str(self._kind.value)))
            self._delete_button = gui.add_button("Delete selected joint", color="red",
                                                 hint="Delete")  # fmt: skip
            self._delete_button.on_click(lambda _: self.act(self.model.delete))
            self._escape_button = gui.add_button(
                "Deselect", hint="Escape: close a dialog, else cancel a handle drag, else "
                "deselect",
            )  # fmt: skip
            self._escape_button.on_click(lambda _: self.escape())
        #: The selected joint's pose, parameters and state as typed fields (filled per joint)
        self._joint_folder = gui.add_folder("Selected joint")
        self._config = gui.add_folder("Configuration")
        with self._config:
            self._animate = gui.add_button(
                "Animate", hint="sweep every joint through its range and back; click again to "
                "stop (the states come back as they were)",
            )  # fmt: skip
            self._animate.on_click(lambda _: self.toggle_animation())
        with gui.add_folder("Clearance"):
            self._clearance = gui.add_markdown("")
            compact = gui.add_button(
                "Compact", hint="a shorter design with the same kinematics, clear of itself; "
                "a design with a task still reaches every target (runs in the background: "
                "Cancel stops it, Undo takes it back)",
            )  # fmt: skip
            compact.on_click(lambda _: self.compact())
            check = gui.add_button(
                "Check motion", hint="sample random configurations of the joints and report "
                "how often the design passes through itself (runs in the background)",
            )  # fmt: skip
            check.on_click(lambda _: self.check_motion())
            self._motion = gui.add_markdown("", visible=False)
            self._fit = gui.add_button(
                "Fit junctions", visible=self.model.is_tree,
                hint="slide the joints whose junction socket does not fit along their axes, "
                "as kinegami build does (the kinematics stay)",
            )  # fmt: skip
            self._fit.on_click(lambda _: self.fit_junctions())
        with gui.add_folder("Reach"):
            units = self.model.document.units
            self._reach_target = gui.add_vector3(
                f"Target ({units})", initial_value=tuple(self.tip_position().tolist()),
                step=0.1, hint="where the tip should go, in the design's units (world frame)",
            )  # fmt: skip
            reach = gui.add_button(
                "Reach target", hint="states that put the tip on the target, clear of "
                "itself, found from the current states (Undo takes them back)",
            )  # fmt: skip
            reach.on_click(lambda _: self.reach_to(self._reach_target.value))
            self._reach_handle = gui.add_checkbox(
                "Target handle", initial_value=False,
                hint="drag the target in the scene: the design follows it",
            )  # fmt: skip
            self._reach_handle.on_update(lambda _: self.show_target(bool(self._reach_handle.value)))
            self._reach_status = gui.add_markdown("")
            space = gui.add_button(
                "Workspace", hint=f"sample {WORKSPACE_SAMPLES:,} configurations in the "
                "background and show the tip positions that are clear of the design",
            )  # fmt: skip
            space.on_click(lambda _: self.show_workspace())
            self._hide_space = gui.add_button("Hide workspace", visible=False)
            self._hide_space.on_click(lambda _: self.hide_workspace())
        with gui.add_folder("File"):
            self._save_file = gui.add_button(
                "Save to " + (self.model.path.name if self.model.path else "file"),
                visible=self.model.path is not None,
                hint="write the design file this editor was started with",
            )  # fmt: skip
            self._save_file.on_click(lambda _: self.save_file())
            save = gui.add_button("Save design (download)")
            save.on_click(lambda _: self.download(".json"))
            self._download_design = save
            self._sheet = gui.add_dropdown(
                "Sheet", self._sheet_options(), visible=self.model.is_tree,
                hint="which sheet of the tree Download DXF, SVG and FOLD give",
            )  # fmt: skip
            for label, suffix in DOWNLOADS.items():
                button = gui.add_button(f"Download {label}")
                button.on_click(lambda _, s=suffix: self.download(s))
            self._junctions = gui.add_button(
                "Download junctions (STL/3MF)", visible=self.model.is_tree,
                hint="the printed connector of every junction, in mm (a zip)",
            )  # fmt: skip
            self._junctions.on_click(lambda _: self.download("junctions"))
            names = tuple(gallery()) or ("(none)",)
            self._example = gui.add_dropdown("Example", names)
            open_example = gui.add_button("Open example")
            open_example.on_click(lambda _: self.open_example(str(self._example.value)))
            upload = gui.add_upload_button("Upload design", mime_type="application/json")
            upload.on_upload(lambda e: self.upload(e.target.value.name, e.target.value.content))

    # --- task ---------------------------------------------------------------------------------
    def _goals(self, document: Document):
        """The TaskGoals of ``document``'s task in its units (an exception when the task cannot
        be read so; None without a task), computed once per task and units."""
        if document.task is None:
            return None
        cached = self._task_goals
        if cached is not None and cached[0][0] is document.task and \
                cached[0][1] == document.units:  # fmt: skip
            return cached[1]
        try:
            goals = task_goals(document.task, document.units)
        except (KinegamiError, ValueError) as error:
            goals = error
        self._task_goals = ((document.task, document.units), goals)
        return goals

    def task_positions(self) -> np.ndarray:
        """Where the targets of the shown design's task are ((n, 3), world frame, design
        units; empty without a task)."""
        goals = self._goals(self.model.document)
        if goals is None or isinstance(goals, Exception):
            return np.zeros((0, 3))
        return np.array([t.position for _, t in labelled_targets(goals)],
                        dtype=float).reshape(-1, 3)  # fmt: skip

    def _checks_of(self, document: Document):
        """The targets' checks of ``document`` (computed once per document, in the worker
        process when the view has one): a tuple of TargetCheck, or the exception that stopped
        the check."""
        cached = document.__dict__.get("_task_checks")
        if cached is not None:
            return cached
        args = (document.chain, document.task, document.units)
        checks = None
        if self._worker is not None:
            try:
                checks = self._worker.run(check_targets, *args)
            except (KinegamiError, ValueError) as error:
                checks = error
            except Exception:  # noqa: BLE001, S110 - the worker process failed: check here instead
                pass
        if checks is None:
            try:
                checks = check_targets(*args)
            except (KinegamiError, ValueError) as error:
                checks = error
        document.__dict__["_task_checks"] = checks
        return checks

    def check_task(self) -> bool:
        """Check every target of the shown design's task (the view calls it after a pause;
        see :meth:`flush`): reached exactly, in range, clear and outside the keep-out boxes,
        or why not (:func:`~kinegami.editor.tasks.check_targets`; a tree task grasp by grasp,
        every leaf at once), drawn green or red in the scene and listed in the Task panel.
        Returns whether a new result was shown (nothing is shown when another document has
        replaced the one checked meanwhile)."""
        with self.lock:
            if self._closed:
                return False
            model, document = self.model, self.model.document
            if document.task is None:
                return False
        checks = self._checks_of(document)
        with self.lock:
            if self._closed or self.model is not model or model.document is not document:
                return False  # a later change has triggered another check
            self.task_checks, self.task_checked = checks, document
            self._update_task()
            self.task_draws += 1
            return True

    def _update_task(self) -> None:
        """The Task panel and the targets in the scene, for the shown design and the latest
        checks (of it, or of the design before it until the new ones come)."""
        document = self.model.document
        has_task = document.task is not None
        if self._task_folder.visible != has_task:
            self._task_folder.visible = has_task
        if self._design_button.visible != has_task:
            self._design_button.visible = has_task
        checks = self.task_checks if has_task else None
        if checks is not None and self.task_checked is not None and \
                self.task_checked.task is not document.task:  # fmt: skip
            checks = None  # of another task
        self._draw_targets(document, checks)
        html_text = self.task_html(document, checks)
        if self._task_html.content != html_text:
            self._task_html.content = html_text

    def target_colours(self) -> tuple[tuple[int, int, int], ...]:
        """The colour each target of the task is drawn in (green reached, red not, grey not
        checked)."""
        key = self._task_key
        return () if key is None else tuple(_target_colour(state) for state in key[2])

    def _draw_targets(self, document: Document, checks) -> None:
        """The targets in the scene: a ball at each (a frame for a pose target, an arrow along
        an axis target's axis) in the colour of its check, and its name; drawn again only
        when the task, the units or a colour changed."""
        goals = self._goals(document)
        if goals is None or isinstance(goals, Exception):
            key, targets = None, ()
        else:
            targets = labelled_targets(goals)
            states = tuple(None if not isinstance(checks, tuple) else checks[k].reached
                           for k in range(len(targets)))  # fmt: skip
            key = (document.task, document.units, states)
        old = self._task_key
        if key is not None and old is not None and key[0] is old[0] and key[1:] == old[1:]:
            return
        for handle in self._task_handles:
            handle.remove()
        self._task_handles = []
        self._task_key = key
        if key is None:
            return
        size = self._r
        for k, ((label, target), state) in enumerate(zip(targets, key[2], strict=True)):
            colour = _target_colour(state)
            position = tuple(float(v) for v in target.position)
            name = f"/task/target{k}"
            self._task_handles.append(self.scene.add_icosphere(
                name, radius=0.5 * size, color=colour, position=position))  # fmt: skip
            if target.rotation is not None:
                self._task_handles.append(self.scene.add_frame(
                    f"{name}_frame", axes_length=2.5 * size, axes_radius=0.08 * size,
                    wxyz=_wxyz(target.rotation), position=position))  # fmt: skip
            elif target.axis is not None:
                tip = np.asarray(target.position) + 2.5 * size * np.asarray(target.axis)
                self._task_handles.append(self.scene.add_arrows(
                    f"{name}_axis", points=np.array([[target.position, tip]], dtype=np.float32),
                    colors=colour, shaft_radius=0.1 * size, head_radius=0.25 * size,
                    head_length=0.6 * size))  # fmt: skip
            self._task_handles.append(self.scene.add_label(
                f"{name}_label", label, position=position))  # fmt: skip

    def task_html(self, document: Document, checks) -> str:
        """The Task panel: the task's name and joints, then one line per target (a tree
        task's leaf by leaf, each leaf's tip joint named), its colour and whether the design
        reaches it (or why not)."""
        from html import escape

        task = document.task
        if task is None:
            return ""
        title = escape(str(task.get("name") or "task"))
        count = len(task.get("targets", ()))
        joints = task.get("joints")
        tree_task = isinstance(joints, list)  # one joint string and target list per leaf
        if tree_task:
            grasps = len(task["targets"][0]) if task.get("targets") else 0
            head = (f"<b>{title}</b>: {len(joints)} leaves, {grasps} "
                    f"grasp{'s' if grasps != 1 else ''}, joints "
                    f"{escape(', '.join(map(str, joints)))}")  # fmt: skip
        else:
            head = (f"<b>{title}</b>: {count} target{'s' if count != 1 else ''}, joints "
                    f"{escape(str(joints))}")  # fmt: skip
        goals = self._goals(document)
        if isinstance(goals, Exception):
            return _task_box(f"{head}.<br><b>The task cannot be read:</b> {escape(str(goals))}")
        if isinstance(checks, Exception):
            return _task_box(f"{head}.<br><b>The targets could not be checked:</b> "
                             f"{escape(str(checks))}")  # fmt: skip
        targets = labelled_targets(goals)
        units = document.units
        if checks is None:
            summary = "checking the targets..."
        else:
            reached = sum(1 for c in checks if c.reached)
            summary = f"{reached} of {len(checks)} reached"
            if tree_task:
                whole = sum(1 for k in range(grasps)
                            if all(c.reached for c in checks if c.index == k))  # fmt: skip
                summary += f" ({whole} of {grasps} grasp{'s' if grasps != 1 else ''})"
                tips = sorted({(c.leaf, c.tip) for c in checks})
                head += "; leaf tips: joints " + ", ".join(str(tip) for _, tip in tips)
            if self.task_checked is not document:
                summary += " (checking the design as changed...)"
        rows = []
        for k, (label, _) in enumerate(targets):
            if checks is None:
                state, text, colour = "unchecked", "not checked yet", UNCHECKED_COLOR
            elif checks[k].reached:
                state, colour = "reached", REACHED_COLOR
                text = (f"reached, exactly and clear (clearance "
                        f"{length_text(checks[k].clearance, units)})")  # fmt: skip
            else:
                state, colour = "missed", MISSED_COLOR
                reason = checks[k].reason.removeprefix("not reached").removeprefix(": ")
                text = f"<b>not reached</b>: {escape(reason)}"
            where = ""
            if tree_task and checks is not None:
                where = f' data-leaf="{checks[k].leaf}" data-grasp="{checks[k].index}"'
            dot = "#{:02x}{:02x}{:02x}".format(*colour)
            rows.append(f'<li data-target="{k}"{where} data-state="{state}" '
                        f'style="margin:0.2em 0"><span style="color:{dot}">&#9679;</span> '
                        f"{escape(label)}: {text}</li>")  # fmt: skip
        return _task_box(f"{head}; {summary}.<ul style=\"list-style:none;padding-left:0;"
                         f"margin:0.3em 0\">{''.join(rows)}</ul>")  # fmt: skip

    # --- reach --------------------------------------------------------------------------------
    def reach_tip(self) -> int:
        """The tip the target is for: a chain's last joint; on a tree, the selected joint when
        it is a leaf, else the first leaf."""
        chain = self.model.chain
        parents = {int(p) for p in chain.Parents if p is not None and int(p) >= 0}
        leaves = [k for k in range(len(chain.Joints)) if k not in parents]
        selected = self.model.selected
        return selected if selected in leaves else leaves[0]

    def tip_position(self) -> np.ndarray:
        """Where the reach tip is now (world, design units)."""
        joint = self.model.chain.Joints[self.reach_tip()]
        return np.asarray(joint.distal_dubins_frame(), dtype=float)[:3, 3].copy()

    @_locked
    def reach_to(self, position, *, preview: bool = False):
        """Put the tip on ``position`` (3 numbers, design units, world frame) by inverse
        kinematics warm-started from the current states (:func:`kinegami.reach.solve`: exact,
        in range and clear of itself). Reached: the states are set (one command; with
        ``preview``, a preview, as a handle drag shows). Not reached: the design stays, the
        target turns red and the panel says why. Returns the solver's answer (None for a
        position that is not three finite numbers)."""
        from kinegami.reach import solve

        self.stop_animation()
        try:
            point = np.asarray(position, dtype=float).reshape(3)
        except (TypeError, ValueError):
            point = None
        if point is None or not np.isfinite(point).all():
            self._say(f"**Refused:** reach: the target must be three finite numbers, got "
                      f"{position!r}")  # fmt: skip
            return None
        document = self.model.document
        q0 = [float(joint.state) for joint in document.chain.Joints]
        # a drag's previews are the same chain at other states: solve on the chain they share,
        # whose kinematics and clearance engine are then built once for the whole drag
        shared = (document.shape_of or document).chain
        answer = solve(shared, point, tip=self.reach_tip(), q0=q0)
        self.reach_answer = answer
        self._draw_target(point, answer.ok)
        units = self.model.document.units
        if not answer.ok:
            self._reach_status.content = f"**Cannot reach:** {answer.reason}"
            return answer
        if preview:
            self.model.preview(SetJointStates(list(answer.states)))
        else:
            result = self.run(self.model.set_states(list(answer.states)))
            if not result.ok:
                self._reach_status.content = f"**Cannot reach:** {result.reason}"
                return answer
        self._reach_status.content = (
            f"reached: tip {answer.position_error:.1e} {units} from the target, clearance "
            f"{answer.clearance:.3g} {units}")  # fmt: skip
        return answer

    def _draw_target(self, point: np.ndarray, ok: bool) -> None:
        """The target's marker: a small ball, the tip's colour when reached, red when not."""
        self._reach_point = point
        color = (40, 160, 80) if ok else COLLIDING_COLOR
        self._target_marker = self.scene.add_icosphere(
            "/reach/target", radius=0.4 * self._r, color=color, position=tuple(point.tolist()))

    @_locked
    def show_target(self, visible: bool = True) -> None:
        """Show (or hide) the target's handle: dragging it makes the design follow, previewed
        while it moves, one command when it is let go."""
        if not visible:
            if self._target_handle is not None:
                self._target_handle.visible = False
            return
        point = np.asarray(self._reach_target.value, dtype=float)
        if self._target_handle is None:
            self._target_handle = self.scene.add_transform_controls(
                "/reach/handle", scale=3.0 * self._r, disable_rotations=True,
                disable_sliders=True, depth_test=False, translation_limits=((-1e9, 1e9),) * 3,
            )  # fmt: skip
            self._target_handle.on_update(self._on_target_handle)
        self._target_handle.visible = True
        self._target_handle.position = tuple(point.tolist())
        self._draw_target(point, True)

    def _on_target_handle(self, event) -> None:
        phase = getattr(event, "phase", "end")
        position = tuple(float(x) for x in self._target_handle.position)
        self._reach_target.value = position
        if phase == "update":
            self.reach_to(position, preview=True)
        elif phase == "end":
            self.reach_to(position)

    def show_workspace(self, samples: int = None) -> Job | None:
        """Sample the workspace in the background (the Workspace button): ``samples``
        configurations (default :data:`WORKSPACE_SAMPLES`), and the tip positions of the clear
        ones drawn as a cloud. Nothing changes in the design."""
        with self.lock:
            document = self.model.base_document
            tip = self.reach_tip()
        count = WORKSPACE_SAMPLES if samples is None else int(samples)

        def finish(job: Job, found) -> None:
            points, summary = found
            self.workspace_points = points
            self._workspace_cloud = self.scene.add_point_cloud(
                "/reach/workspace", points=points.astype(np.float32), colors=(90, 120, 220),
                point_size=0.3 * self._r, precision="float32")  # fmt: skip
            self._hide_space.visible = True
            self._say(f"workspace: {summary}")

        return self.start_job("workspace", "Sampling the workspace", "configurations",
                              workspace_points, (document.chain, count, tip), finish)  # fmt: skip

    @_locked
    def hide_workspace(self) -> None:
        """Remove the workspace cloud."""
        if self._workspace_cloud is not None:
            self._workspace_cloud.remove()
            self._workspace_cloud = None
        self._hide_space.visible = False

    def _undo(self) -> CommandResult:
        return self.model.undo()

    def _redo(self) -> CommandResult:
        return self.model.redo()

    def _labels(self) -> tuple[str, ...]:
        tree = self.model.is_tree
        return tuple(f"{row.index}: {row.type}" + (f" '{row.name}'" if row.name else "")
                     + (f" (on {row.parent})" if tree and row.parent >= 0 else "")
                     for row in self.model.joint_table())  # fmt: skip

    @_locked
    def _on_joint_list(self, _event) -> None:
        if self._syncing:
            return
        value = str(self._joint_list.value)
        if value == "(none)":
            self.model.select(None)
        else:
            self.model.select(int(value.split(":", 1)[0]))

    def _update_panel(self, structure: bool = False) -> None:
        self._syncing = True
        try:
            labels = ("(none)",) + self._labels()
            if tuple(self._joint_list.options) != labels:
                self._joint_list.options = labels
            selected = self.model.selected
            self._joint_list.value = labels[selected + 1] if selected is not None else "(none)"
            self._joint_info.content = self._joint_text()
            self._clearance.content = self._clearance_text
            self._update_sliders(structure)
            self._update_joint_fields()
            self._update_units()
            tree = self.model.is_tree
            for widget in (self._fit, self._sheet, self._junctions):
                if widget.visible != tree:
                    widget.visible = tree
            options = self._sheet_options()
            if tuple(self._sheet.options) != options:
                value = self._sheet.value
                self._sheet.options = options
                self._sheet.value = value if value in options else ALL_SHEETS
        finally:
            self._syncing = False

    def _sheet_options(self) -> tuple[str, ...]:
        """The Sheet menu: every sheet at once, then one entry per sheet (one per leaf)."""
        if not self.model.is_tree:
            return (ALL_SHEETS,)
        leaves = sum(1 for row in self.model.joint_table() if not row.children)
        return (ALL_SHEETS, *(f"sheet {k}" for k in range(leaves)))

    @_locked
    def add_branch(self, kind: str) -> CommandResult:
        """Add a joint of type ``kind`` as a new child of the selected joint (the Add branch
        button)."""
        return self.act(lambda: self.model.add_branch(kind))

    def _joint_text(self) -> str:
        selected = self.model.selected
        if selected is None:
            return "No joint selected: click one."
        row = self.model.joint_table()[selected]
        units = self.model.document.units
        if row.movable:
            lo, hi = (state_text(row.type, v, units) for v in row.state_range)
            motion = f"state {state_text(row.type, row.state, units)} in [{lo}, {hi}]"
        else:
            motion = "no motion of its own"
        lines = [f"**{selected}: {row.type}** {row.name or ''}", "", motion, ""]
        if self.model.is_tree:
            kids = ", ".join(map(str, row.children)) or "none (a leaf)"
            parent = "none (the root)" if row.parent < 0 else str(row.parent)
            lines[4:4] = [f"parent {parent}; children {kids}", ""]
        lines += [f"- {k}: {self._parameter_text(k, v)}" for k, v in row.parameters.items()]
        return "\n".join(lines)

    def _parameter_text(self, key: str, value) -> str:
        unit = parameter_unit(key, self.model.document.units)
        if unit == "deg":
            return angle_text(value)
        if unit:
            return length_text(value, unit)
        return str(value)

    def _update_sliders(self, structure: bool) -> None:
        """The Configuration sliders: one per movable joint, a revolute joint's in degrees,
        a prismatic joint's in the design's units (the ends are marked with their unit)."""
        rows = [row for row in self.model.joint_table() if row.movable]
        units = self.model.document.units
        keys = [(row.index, row.type, row.state_range, units) for row in rows]
        if structure or [s[0] for s in self._sliders] != keys:
            for _, handle in self._sliders:
                handle.remove()
            self._sliders = []
            with self._config:
                for key, row in zip(keys, rows, strict=True):
                    lo, hi = (state_to_display(row.type, v) for v in row.state_range)
                    marks = [(lo, state_text(row.type, row.state_range[0], units)),
                             (hi, state_text(row.type, row.state_range[1], units))]  # fmt: skip
                    if lo < 0.0 < hi:
                        marks.insert(1, (0.0, "0"))
                    handle = self.gui.add_slider(
                        f"{row.index}: {row.name or row.type}", min=lo, max=hi,
                        step=(hi - lo) / 200.0, marks=tuple(marks),
                        initial_value=min(max(state_to_display(row.type, row.state), lo), hi),
                        hint=f"the state of joint {row.index}, in "
                        f"{'degrees' if state_unit(row.type, units) == 'deg' else units}",
                    )  # fmt: skip
                    handle.on_update(lambda _, i=row.index, h=handle: self._on_slider(i, h))
                    self._sliders.append((key, handle))
            return
        table = self.model.joint_table()
        for (index, kind, _, _), handle in self._sliders:
            shown = state_to_display(kind, table[index].state)
            if abs(float(handle.value) - shown) > 1e-9:
                handle.value = shown

    @_locked
    def _on_slider(self, index: int, handle) -> None:
        if self._syncing or self._animation is not None:
            return
        row = self.model.joint_table()[index]
        state = state_from_display(row.type, float(handle.value))
        if abs(state - float(row.state)) > 1e-12:
            self.set_state(index, state)

    @_locked
    def set_state(self, index: int, state: float) -> CommandResult:
        """Set a joint's state (what its Configuration slider does)."""
        self.stop_animation()
        return self.run(self.model.set_state(index, state))

    # --- typed values -------------------------------------------------------------------------
    def _input_digits(self) -> int:
        """Decimals of a typed length: a thousandth of the tube radius, at least."""
        return max(0, 3 - math.floor(math.log10(self._r)))

    def _update_joint_fields(self) -> None:
        """The Selected joint folder: the selected joint's pose (position in the design's
        units, fixed-axis XYZ angles in degrees), its parameters and its state as typed
        fields, each group with its Set button. Rebuilt when the joint's type or the units
        change, refilled after every change."""
        selected = self.model.selected
        row = None if selected is None else self.model.joint_table()[selected]
        units = self.model.document.units
        key = None if row is None else (row.type, tuple(row.parameters), row.movable, units,
                                        self._input_digits())  # fmt: skip
        if key != self._joint_fields_key:
            for handle in self._joint_fields.values():
                handle.remove()
            self._joint_fields, self._shown_fields = {}, {}
            self._joint_fields_key = key
            with self._joint_folder:
                if row is None:
                    self._joint_fields["none"] = self.gui.add_markdown(
                        "Select a joint to type its pose, parameters and state."
                    )
                else:
                    self._build_joint_fields(row, units)
                self._filled_for = None  # new fields: filled in
        if row is not None:
            force = row.index != self._filled_for
            self._filled_for = row.index
            self._fill_joint_fields(row, force)
        else:
            self._filled_for = None

    def _build_joint_fields(self, row, units: str) -> None:
        gui, fields = self.gui, self._joint_fields
        digits = self._input_digits()
        fields["position"] = gui.add_vector3(
            f"Position ({units})", (0.0, 0.0, 0.0), step=10.0 ** -digits,
            hint="the joint's origin in world coordinates, in the design's units",
        )  # fmt: skip
        fields["orientation"] = gui.add_vector3(
            f"Orientation ({DEGREE})", (0.0, 0.0, 0.0), step=1e-4,
            hint="fixed-axis XYZ angles in degrees: roll about x, then pitch about y, then yaw "
            "about z (world axes); for a revolute or prismatic joint z is its axis of motion",
        )  # fmt: skip
        fields["set pose"] = gui.add_button(
            "Set pose", hint="put the joint at the typed pose (undoable); Propagate moves the "
            "later joints with it; for a revolute or prismatic joint this changes its axis, "
            "i.e. the kinematics",
        )  # fmt: skip
        fields["set pose"].on_click(lambda _: self.set_typed_pose())
        for key in row.parameters:
            unit = parameter_unit(key, units)
            label = f"{key} ({unit})" if unit and unit != "deg" else key
            if unit == "deg":
                label = f"{key} ({DEGREE})"
            step = 1 if not unit else (1e-4 if unit == "deg" else 10.0 ** -digits)
            fields[f"parameter {key}"] = gui.add_number(label, 0.0, step=step)
        if row.parameters:
            fields["set parameters"] = gui.add_button(
                "Set parameters", hint="the joint's new parameters (undoable); its pose and "
                "state stay, its links are solved again",
            )  # fmt: skip
            fields["set parameters"].on_click(lambda _: self.set_typed_parameters())
        if row.movable:
            unit = state_unit(row.type, units)
            fields["state"] = gui.add_number(
                f"State ({DEGREE if unit == 'deg' else unit})", 0.0,
                step=1e-4 if unit == "deg" else 10.0 ** -digits,
            )  # fmt: skip
            fields["set state"] = gui.add_button("Set state", hint="the joint's new state "
                                                 "(undoable)")  # fmt: skip
            fields["set state"].on_click(lambda _: self.set_typed_state())

    def _show(self, name: str, exact, digits: int, force: bool) -> None:
        """Fill a field with ``exact`` (a number or a triple) rounded to ``digits``, and
        remember both (a typed value equal to the one shown means: keep the exact one). A
        field whose value did not change keeps what the user is typing, unless ``force``
        (another joint)."""
        if isinstance(exact, tuple | list | np.ndarray):
            shown = tuple(round(float(v), digits) + 0.0 for v in exact)
        else:
            shown = round(float(exact), digits) + 0.0 if digits else exact
        handle = self._joint_fields[name]
        before = self._shown_fields.get(name, (None, None))[0]
        if (force or before != shown) and handle.value != shown:
            handle.value = shown
        self._shown_fields[name] = (shown, exact)

    def _fill_joint_fields(self, row, force: bool) -> None:
        digits = self._input_digits()
        position, angles = pose_to_display(row.pose)
        self._show("position", position, digits, force)
        self._show("orientation", angles, 4, force)
        for key, value in row.parameters.items():
            unit = parameter_unit(key, self.model.document.units)
            self._show(f"parameter {key}", parameter_to_display(key, value),
                       0 if not unit else (4 if unit == "deg" else digits), force)  # fmt: skip
        if row.movable:
            unit = state_unit(row.type, self.model.document.units)
            self._show("state", state_to_display(row.type, row.state),
                       4 if unit == "deg" else digits, force)  # fmt: skip

    def _typed(self, name: str, value=None):
        """A field's typed value; where it still shows what was filled in, the exact value
        (so an untouched field does not round the design)."""
        value = self._joint_fields[name].value if value is None else value
        shown, exact = self._shown_fields.get(name, (None, None))
        if isinstance(value, tuple | list | np.ndarray):
            if shown is None:
                return tuple(value)
            return tuple(e if float(v) == s else v for v, s, e in zip(value, shown, exact,
                                                                      strict=True))  # fmt: skip
        return exact if shown is not None and value == shown else value

    def _no_selection(self, action: str) -> CommandResult | None:
        if self.model.selected is None or not self._joint_fields.get("set pose"):
            return self.run(CommandResult(False, action, f"{action}: no joint is selected; "
                                          "select one first"))  # fmt: skip
        return None

    @_locked
    def set_typed_pose(self, position=None, angles=None) -> CommandResult:
        """Put the selected joint at a typed pose (the Set pose button): ``position`` in the
        design's units and fixed-axis XYZ ``angles`` in degrees (default: the fields). A
        field left as filled in keeps the exact value (an unchanged orientation keeps the
        joint's exact rotation). One undoable command; a refused pose changes nothing."""
        refused = self._no_selection("set pose")
        if refused is not None:
            return refused
        typed_position = self._typed("position", position)
        typed_angles = self._typed("orientation", angles)
        current = np.asarray(self.model.joint_table()[self.model.selected].pose, dtype=float)
        try:
            pose = pose_from_display(typed_position, typed_angles)
        except KinegamiError as error:
            return self.run(CommandResult(False, "set pose", f"set pose: {error}"))
        if self._shown_fields.get("orientation", (None, None))[1] == tuple(typed_angles):
            pose[:3, :3] = current[:3, :3]  # untouched: the exact rotation
        if np.array_equal(pose, current):
            self._say("set pose: the typed pose is the joint's pose; nothing to change")
            return CommandResult(False, "set pose", "the typed pose is the joint's pose")
        return self.act(lambda: self.model.set_pose(None, pose))

    @_locked
    def set_typed_parameters(self, values: dict | None = None) -> CommandResult:
        """Give the selected joint its typed parameters (the Set parameters button; angles in
        degrees, lengths in the design's units; ``values`` default: the fields). Only the
        fields that differ from the joint's are sent; one undoable command."""
        refused = self._no_selection("set parameters")
        if refused is not None:
            return refused
        row = self.model.joint_table()[self.model.selected]
        changed = {}
        for key in row.parameters:
            given = None if values is None or key not in values else values[key]
            if values is not None and key not in values:
                continue
            typed = self._typed(f"parameter {key}", given)
            shown, exact = self._shown_fields.get(f"parameter {key}", (None, None))
            if typed is exact:
                continue
            changed[key] = parameter_from_display(key, typed)
        if values is not None:  # unknown names go on: the command names them
            changed.update({k: v for k, v in values.items() if k not in row.parameters})
        if not changed:
            self._say("set parameters: every typed value is the joint's; nothing to change")
            return CommandResult(False, "set parameters", "no parameter differs")
        return self.act(lambda: self.model.set_parameters(None, **changed))

    @_locked
    def set_typed_state(self, value=None) -> CommandResult:
        """Set the selected joint's state to a typed value (the Set state button; degrees for
        a revolute joint, the design's units for a prismatic one). One undoable command."""
        refused = self._no_selection("set state")
        if refused is not None:
            return refused
        row = self.model.joint_table()[self.model.selected]
        if not row.movable:
            return self.run(CommandResult(False, "set state", f"set state: joint {row.index} "
                                          f"({row.type}) has no motion"))  # fmt: skip
        typed = self._typed("state", value)
        shown, exact = self._shown_fields.get("state", (None, None))
        state = row.state if typed is exact else state_from_display(row.type, typed)
        self.stop_animation()
        return self.run(self.model.set_state(None, state))

    def _update_units(self) -> None:
        """Labels that name the design's units (the slide step, the grid)."""
        units = self.model.document.units
        label = f"Slide by ({units})"
        if self._step.label != label:
            self._step.label = label
        grid = self.grid
        if grid is not None:
            text = (f"Lengths in **{units}**, angles in degrees. Grid: "
                    f"{length_text(grid.cell, units)} cells, {length_text(grid.section, units)} "
                    f"sections (the world axes are one section long: x red, y green, z "
                    f"blue).")  # fmt: skip
            if self._view_text.content != text:
                self._view_text.content = text

    # --- keys ---------------------------------------------------------------------------------
    def _build_help_panel(self) -> None:
        with self.gui.add_folder("Shortcuts", expand_by_default=False):
            self._shortcuts = self.gui.add_markdown(shortcuts_markdown())

    def send_shortcuts(self) -> bool:
        """Put the keyboard shortcuts in the tab (docs/editor.md, Keyboard shortcuts): each
        key clicks the button that does the same. False when the tab cannot run scripts."""
        from kinegami.editor.page_script import run_javascript

        targets = {
            "undo": [self._undo_button], "redo": [self._redo_button],
            "delete": [self._delete_button], "frame": [self._frame_button],
            "save": [self._save_file, self._download_design], "escape": [self._escape_button],
        }  # fmt: skip
        return run_javascript(self.target, keys_script(targets))

    @_locked
    def escape(self) -> str:
        """What Escape does (and the Deselect button): close the latest dialog (the one
        asking about unsaved changes answers Cancel; the recovery dialog leaves the autosave
        to be offered again), else cancel a handle drag in progress (the design stays as it
        was before it), else deselect. Returns ``"dialog"``, ``"drag"``, ``"deselect"`` or
        ``"nothing"``."""
        if self.dialog_cancels:
            self.dialog_cancels.pop()()
            return "dialog"
        if getattr(self, "_unsaved_modal", None) is not None and hasattr(self, "answer_unsaved"):
            self.answer_unsaved("cancel")
            return "dialog"
        if getattr(self, "_recovery_modal", None) is not None:
            self._recovery_modal.close()
            self._recovery_modal = None
            self._say("the autosave is kept: it is offered again when the editor starts")
            return "dialog"
        if self._dragging:
            self._dragging = False
            self._drag_cancelled = True
            self.model.end_preview()
            self._update_gizmo()
            self._say("drag cancelled: nothing changed")
            return "drag"
        if self.model.selected is not None:
            self.model.select(None)
            return "deselect"
        return "nothing"

    # --- background jobs ----------------------------------------------------------------------
    @property
    def job(self) -> Job | None:
        """The running job, or None."""
        return self._job

    def compact(self, **options) -> Job | None:
        """Compact the design in the background (the Compact button; ``options`` of
        :class:`~kinegami.editor.commands.Compact`, each start limited to
        :data:`COMPACT_TIME_LIMIT` seconds unless given): the result is one command."""
        options.setdefault("time_limit", COMPACT_TIME_LIMIT)
        try:
            command = Compact(**options)
        except TypeError as error:
            self._say(f"**Refused:** compact: {error}")
            return None
        document = self.model.base_document
        keeps = command.keep_task and document.task is not None and not document.is_tree
        return self.run_command_job(command, "Compacting (keeping the task)" if keeps
                                    else "Compacting", "starts")  # fmt: skip

    def design_for_task(self, **options) -> Job | None:
        """Design for the document's task in the background (the Design for task button;
        ``options`` of :class:`~kinegami.editor.commands.DesignForTask`): the designed chain
        (a tree for a tree task) replaces the design as one command, the task kept; a search
        that finds none shows its reason and changes nothing."""
        try:
            command = DesignForTask(**options)
        except TypeError as error:
            self._say(f"**Refused:** design for task: {error}")
            return None
        return self.run_command_job(command, "Designing for the task", "starts",
                                    then=self._designed)  # fmt: skip

    def _designed(self, result: CommandResult) -> None:
        """After Design for task: another design, maybe of another size (grid and camera
        follow)."""
        if result.ok:
            self._size_scene()
            self.frame_camera()

    def fit_junctions(self) -> Job | None:
        """Fit a tree's junction sockets in the background (the Fit junctions button)."""
        return self.run_command_job(FitJunctions(), "Fitting the junctions", "sockets")

    def check_motion(self, samples: int | None = None) -> Job | None:
        """Sample random configurations in the background and show how often the design
        passes through itself (the Check motion button; ``samples`` default
        :data:`~kinegami.editor.jobs.MOTION_SAMPLES`, for a tree
        :data:`~kinegami.editor.jobs.TREE_MOTION_SAMPLES`). Nothing changes."""
        with self.lock:
            document = self.model.base_document
        if samples is None:
            samples = TREE_MOTION_SAMPLES if document.is_tree else MOTION_SAMPLES

        def finish(job: Job, text: str) -> None:
            self._motion.content = text
            self._motion.visible = True
            self._motion_document = job.source
            self._say(f"motion check: {job.total} configurations tested")

        return self.start_job("motion check", "Checking the motion", "configurations",
                              motion_check, (document.chain, document.names, int(samples)),
                              finish)  # fmt: skip

    def run_command_job(self, command: LongCommand, title: str, unit: str,
                        then: Callable[[CommandResult], Any] | None = None,
                        ) -> Job | None:  # fmt: skip
        """Run a long command's heavy part in the background; its result is applied as one
        command (:class:`~kinegami.editor.commands.Computed`) when the design is still the
        one it started from (then ``then(result)``), else the tab asks first
        (:meth:`resolve_result`)."""
        with self.lock:
            self.stop_animation()
            document = self.model.base_document
            command = command.prepared(document)
            try:
                command.check(document)
            except KinegamiError as error:
                self._say(f"**Refused:** {error}")
                return None

        def finish(job: Job, computed) -> None:
            result = Computed(command, job.source, computed)
            if self.model.base_document is job.source:
                applied = self.act(lambda: self.model.apply(result))
                if then is not None:
                    then(applied)
            else:
                self._ask_result(job, result)

        return self.start_job(command.label, title, unit, command.compute, (document.chain,),
                              finish)  # fmt: skip

    def start_job(self, label: str, title: str, unit: str, func: Callable, args: tuple,
                  finish: Callable[[Job, Any], None]) -> Job | None:  # fmt: skip
        """Run ``func(*args, progress=...)`` in the tab's job process (docs/progress.md), with
        a progress bar and a Cancel button; ``finish(job, result)`` runs under the tab's lock
        when it is done (not when it was cancelled or failed, or the tab opened another
        design meanwhile). One job at a time: None (and a reason shown) while one runs."""
        with self.lock:
            if self._closed:
                return None
            if self._job is not None:
                self._say(f"**Refused:** {self._job.label} is running: wait for it or Cancel it")
                return None
            self.stop_animation()
            job = Job(label, title, unit, self.model, self.model.base_document)
            self._job = job
            self._show_job(job)
        thread = threading.Thread(target=self._run_job, args=(job, func, args, finish),
                                  name=f"kinegami-{label.replace(' ', '-')}",
                                  daemon=True)  # fmt: skip
        thread.start()
        return job

    def cancel_job(self) -> bool:
        """Stop the running job (the Cancel button): nothing changes. False when none runs."""
        job = self._job
        if job is None:
            return False
        job.cancel.set()
        self._job_text.content = f"**{job.title}**: cancelling..."
        return True

    def _run_job(self, job: Job, func: Callable, args: tuple, finish: Callable) -> None:
        def progress(done: int, total: int) -> bool:
            self._job_progress(job, done, total)
            return not job.cancel.is_set()

        result = error = None
        try:
            if self._jobs is not None:
                result = self._jobs.run(func, args, progress, job.cancel)
            else:
                result = func(*args, progress=progress)
            outcome = "done"
        except Cancelled:
            outcome = "cancelled"
        except Exception as exc:  # noqa: BLE001 - a failed job is a message, not a crash
            outcome, error = "failed", exc
        try:
            with self.lock:
                if self._job is job:
                    self._job = None
                    self._hide_job()
                if self._closed or self.model is not job.model:
                    outcome = "dropped"  # the tab closed or opened another design
                elif outcome == "cancelled":
                    self._say(f"{job.label} cancelled: the design is unchanged")
                elif outcome == "failed":
                    reason = str(error) or type(error).__name__
                    if not reason.startswith(job.label):
                        reason = f"{job.label}: {reason}"
                    self._say(f"**Refused:** {reason}")
                else:
                    finish(job, result)
        finally:
            job.outcome = outcome
            job.finished.set()

    def _job_words(self, job: Job) -> str:
        seconds = int(time.monotonic() - job.started)
        if job.total:
            return f"**{job.title}**: {job.done} of {job.total} {job.unit}, {seconds} s"
        return f"**{job.title}**: {seconds} s"

    def _job_progress(self, job: Job, done: int, total: int) -> None:
        """A progress report of ``job`` (from its thread; widgets are sent only on change)."""
        job.done, job.total = int(done), int(total)
        if self._job is not job or job.cancel.is_set():
            return
        value = min(100.0, max(0.0, 100.0 * done / total)) if total > 0 else 0.0
        if abs(float(self._job_bar.value) - value) > 0.05:
            self._job_bar.value = value
        words = self._job_words(job)
        if self._job_text.content != words:
            self._job_text.content = words

    def _show_job(self, job: Job) -> None:
        self._job_text.content = f"**{job.title}**: starting..."
        self._job_bar.value = 0.0
        for widget in (self._job_text, self._job_bar, self._job_cancel):
            widget.visible = True
        self._say(f"{job.label}: running in the background (Cancel stops it)")

    def _hide_job(self) -> None:
        for widget in (self._job_text, self._job_bar, self._job_cancel):
            widget.visible = False

    def _ask_result(self, job: Job, command: Computed) -> None:
        """Ask whether a result computed for an earlier document replaces the current one."""
        self._close_result_question()
        gui = self.gui
        with gui.add_modal(f"{job.label.capitalize()} finished") as modal:
            gui.add_markdown(
                f"The design changed while {job.label} ran. **Apply** replaces it by the "
                f"result for the design as it was when {job.label} started (your later changes "
                "are one Undo away); **Discard** drops the result."
            )  # fmt: skip
            buttons = gui.add_button_group("Result", ("Apply", "Discard"))
        self._stale_modal = modal
        self.pending_result = command
        buttons.on_click(lambda event: self.resolve_result(str(event.target.value).lower()))
        self._say(f"{job.label} finished for an earlier version of the design: apply it?")

    def _close_result_question(self) -> None:
        if self._stale_modal is not None:
            self._stale_modal.close()
            self._stale_modal = None
        self.pending_result = None

    @_locked
    def resolve_result(self, choice: str) -> CommandResult | None:
        """Answer the question of :meth:`run_command_job`: ``"apply"`` (one command, undoable)
        or ``"discard"``."""
        command = self.pending_result
        self._close_result_question()
        if command is None:
            return None
        if choice == "apply":
            return self.act(lambda: self.model.apply(command))
        self._say(f"{command.label}: the result was dropped; the design is as you left it")
        return None

    # --- files --------------------------------------------------------------------------------
    @_locked
    def download(self, suffix: str) -> tuple[str, bytes] | None:
        """Send the design (``.json``) or an export to the browser; returns (name, data)."""
        self.stop_animation()
        try:
            sheet = sheets = None
            if self.model.is_tree and (suffix in SHEET_FORMATS or suffix in (".pdf", "junctions")):
                if suffix in SHEET_FORMATS and self._sheet.value != ALL_SHEETS:
                    sheet = int(str(self._sheet.value).split()[-1])
                sheets = self._sheets(self.model, self.model.document)
            name, data = download_data(self.model, suffix, sheet, sheets)
        except Exception as error:  # noqa: BLE001 - any exporter failure is shown, not raised
            self._say(f"**Download failed:** {error}")
            return None
        self.target.send_file_download(name, data, save_immediately=True)
        self._say(f"downloaded {name} ({len(data)} bytes)")
        if suffix == ".json" and self.model.path is None and self.autosave is not None:
            self.autosave.discard()  # with no file on the server, the download is the save
        return name, data

    @_locked
    def open_example(self, stem: str) -> bool:
        """Edit a gallery design (by its stem; only files of the gallery can be opened). With
        unsaved changes the tab asks first (:meth:`answer_unsaved`) and returns False."""
        path = gallery().get(stem)
        if path is None:
            self._say(f"**Refused:** no gallery design named {stem!r}")
            return False
        try:
            document = Document.load(path)
        except Exception as error:  # noqa: BLE001 - e.g. a gallery design the editor cannot edit
            self._say(f"**Refused:** the example {stem!r} cannot be opened here: {error}")
            return False
        return self._open(document, f"opened example {stem}")

    @_locked
    def upload(self, name: str, content: bytes) -> bool:
        """Edit an uploaded design file (parsed as a design only; at most MAX_UPLOAD_BYTES).
        With unsaved changes the tab asks first (:meth:`answer_unsaved`) and returns False."""
        if len(content) > MAX_UPLOAD_BYTES:
            self._say(f"**Refused:** {name!r} is {len(content)} bytes; the limit is "
                      f"{MAX_UPLOAD_BYTES} (16 MiB)")  # fmt: skip
            return False
        try:
            document = Document.loads(content.decode("utf-8-sig"))  # as files are read
        except Exception as error:  # noqa: BLE001 - a bad upload is a message, not a crash
            self._say(f"**Refused:** {name!r} is not a design file: {error}")
            return False
        return self._open(document, f"opened {name}")

    def _open(self, document: Document, text: str) -> bool:
        if self.model.dirty:
            self._ask_unsaved(document, text)
            return False
        self._replace_model(document, text)
        return True

    def _replace_model(self, document: Document, text: str) -> None:
        job = self._job
        if job is not None:
            job.cancel.set()  # its result is of the design being closed: dropped
            text += f" ({job.label} stopped)"
        self._close_result_question()
        self.set_model(EditorModel(document))
        self._say(text)

    def _ask_unsaved(self, document: Document, text: str) -> None:
        """Ask what to do with the unsaved changes before opening ``document``."""
        self._close_unsaved_question()
        self.pending_open = (document, text)
        what = text.removeprefix("opened ")
        where = (f"to {self.model.path.name}" if self.model.path is not None
                 else "as a download (Save design)")  # fmt: skip
        gui = self.gui
        with gui.add_modal("Unsaved changes") as modal:
            gui.add_markdown(
                f"This design has unsaved changes. Before opening {what}: **Save** them "
                f"({where}), **Discard** them, or **Cancel** (nothing is opened)."
            )  # fmt: skip
            buttons = gui.add_button_group("Unsaved changes", ("Save", "Discard", "Cancel"))
        self._unsaved_modal = modal
        buttons.on_click(lambda event: self.answer_unsaved(str(event.target.value).lower()))
        self._say(f"unsaved changes: save, discard or cancel before opening {what}")

    def _close_unsaved_question(self) -> None:
        if self._unsaved_modal is not None:
            self._unsaved_modal.close()
            self._unsaved_modal = None
        self.pending_open = None

    @_locked
    def answer_unsaved(self, choice: str) -> bool:
        """Answer the question an open with unsaved changes asked: ``"save"`` (to the design
        file, or as a download for a design with no file on the server; the open goes on
        only when that worked), ``"discard"`` (the changes and their autosave are dropped)
        or ``"cancel"`` (nothing is opened). Returns whether the design was opened."""
        pending = self.pending_open
        self._close_unsaved_question()
        if pending is None:
            return False
        if choice == "cancel":
            self._say(f"nothing opened: the design with its unsaved changes stays "
                      f"({pending[1].removeprefix('opened ')} was not opened)")  # fmt: skip
            return False
        if choice == "save":
            if self.model.path is not None:
                if not self.save_file().ok:
                    return False  # the reason is shown; the design stays
            elif self.download(".json") is None:
                return False
        elif choice == "discard":
            if self.autosave is not None:  # removed when this tab wrote it last
                self.autosave.record(self.model.base_document, False, self)
        else:
            raise InvalidParameterError(f"choice must be 'save', 'discard' or 'cancel', got "
                                        f"{choice!r}")  # fmt: skip
        self._replace_model(*pending)
        return True

    @_locked
    def save_file(self) -> CommandResult:
        """Write the design file the editor was started with (atomically); the autosave is
        removed. Only that file: a design opened in the browser has no file on the server."""
        self.stop_animation()
        if self.model.path is None:
            return self.run(CommandResult(False, "save", "this design has no file on the "
                                          "server: use Save design (download)"))  # fmt: skip
        return self.run(self.model.save())

    # --- crease pattern -----------------------------------------------------------------------
    def _build_pattern_panel(self) -> None:
        self._pattern_panel = self.gui.add_panel()
        with self._pattern_panel.add_tab("Crease pattern"):
            self._pattern_html = self.gui.add_html("<div>drawing the crease pattern...</div>")
        self._pattern_panel.dock_left()
        self._pattern_panel.set_width(PATTERN_PANEL_WIDTH)
        self.gui.main_panel.dock_right()  # the 3D view between the two panels, uncovered

    @property
    def pattern_html(self) -> str:
        """The crease-pattern panel's HTML (an inline SVG of the sheet)."""
        return self._pattern_html.content

    def redraw_pattern(self) -> bool:
        """Draw the crease-pattern panel if the pattern, its units or the selection changed
        since it was last drawn (the view calls it after a pause; see :meth:`flush`).
        Returns whether it sent a new drawing. A tree's panel shows its sheets
        (:meth:`redraw_sheets`)."""
        with self.lock:
            if self._closed:
                return False
            if not self.model.is_tree:
                return self._redraw_chain_pattern()
            model, document = self.model, self.model.document
        return self.redraw_sheets(model, document)

    def _remote_fit(self, tree):
        from kinegami.fabrication.sheets import fit_junctions

        return self._worker.run(fit_junctions, tree)

    def _sheets(self, model: EditorModel, document: Document):
        """``model.sheets(document)``, fitted by the worker process when the view has one
        (without holding the tab's lock), else here under the lock."""
        if self._worker is not None:
            try:
                return model.sheets(document, fit=self._remote_fit)
            except (KinegamiError, ValueError):
                raise
            except Exception:  # noqa: BLE001, S110 - the worker process failed: fit here instead
                pass
        with self.lock:
            return model.sheets(document)

    def redraw_sheets(self, model: EditorModel | None = None,
                      document: Document | None = None) -> bool:  # fmt: skip
        """Draw a tree's sheets in the crease-pattern panel (``document``: the document to draw,
        default the current one; nothing is drawn when another has replaced it meanwhile).
        Returns whether it sent a new drawing."""
        if model is None or document is None:
            with self.lock:
                model, document = self.model, self.model.document
        try:
            sheets = self._sheets(model, document)
        except (KinegamiError, ValueError) as error:
            sheets = error
        with self.lock:
            if self._closed or self.model is not model or model.document is not document:
                return False  # a later change has triggered another drawing
            if isinstance(sheets, Exception):
                return self._show_pattern_error(sheets)
            return self._draw_sheets(model, document, sheets)

    def _show_pattern_error(self, error: Exception) -> bool:
        key = ("error", str(error))
        if key == self._pattern_key:
            return False
        self._pattern_key = key
        self._pattern_html.content = (
            f"<div><b>No crease pattern:</b> {sheet_drawing.html.escape(str(error))}</div>"
        )
        self.pattern_draws += 1
        return True

    def _joint_label(self, index: int) -> str:
        row = self.model.joint_table()[index]
        return f"joint {index} ({row.type}" + (f" '{row.name}'" if row.name else "") + ")"

    def _draw_sheets(self, model: EditorModel, document: Document, sheets) -> bool:
        units = document.units
        drawn = {}
        entries = []
        for sheet, label in zip(sheets.sheets, sheets.labels, strict=True):
            key = (id(sheet.pattern), units)
            cached = self._sheet_lines.get(key)
            if cached is None or cached[0] is not sheet.pattern:
                cached = (sheet.pattern, sheet_drawing.sheet_lines(sheet.pattern, units))
            drawn[key] = cached
            entries.append((cached[1], label))
        self._sheet_lines = drawn  # only the current sheets' drawings are kept
        notes = [self._junction_note(document, sheets, junction)
                 for junction in sheets.fabrication.junctions]  # fmt: skip
        notes += [self._slide_note(document, joint, slide) for joint, slide in sheets.slides]
        selected = model.selected
        where = span = label = None
        if selected is not None and selected < len(sheets.places):
            where, records = sheets.places[selected]
            span = sheet_drawing.joint_span(sheets.sheets[where].pattern, records)
            label = self._joint_label(selected)
            if not len(records):
                label += ": no modules of its own; the line marks where its links meet"
        content = sheet_drawing.sheets_html(entries, where, span, label, notes)
        key = ("sheets", content)
        if key == self._pattern_key:
            return False
        self._pattern_key = key
        self._pattern_html.content = content
        self.pattern_draws += 1
        return True

    def _junction_note(self, document: Document, sheets, junction) -> str:
        def joint(k: int) -> str:
            name = document.names[k]
            return f"{k} '{name}'" if name else str(k)

        kids = ", ".join(joint(c) for c in junction.children)
        return (f"Junction {junction.index} (a printed connector) at joint "
                f"{joint(junction.joint)}: children {kids}; the sheet of {joint(junction.trunk)} "
                "runs through it")  # fmt: skip

    def _slide_note(self, document: Document, joint: int, slide: float) -> str:
        from kinegami.validation import UNITS_IN_MM

        name = document.names[joint]
        what = f"joint {joint}" + (f" '{name}'" if name else "")
        mm = slide * UNITS_IN_MM[document.units]
        return (
            f"The sheets are of the tree with {what} slid {mm:.1f} mm along its axis, so "
            "that its socket fits (as kinegami build does; the kinematics stay): Fit "
            "junctions makes that slide in the design"
        )

    def _redraw_chain_pattern(self) -> bool:
        model = self.model
        units = model.document.units
        try:
            pattern = model.pattern()
        except (KinegamiError, ValueError) as error:
            return self._show_pattern_error(error)
        cached = self._pattern_lines
        if cached is None or cached[0] is not pattern or cached[1] != units:
            cached = (pattern, units, sheet_drawing.sheet_lines(pattern, units))
            self._pattern_lines = cached
        lines = cached[2]
        selected = model.selected
        span = label = None
        if selected is not None:
            records = model.joint_modules()[selected]
            span = sheet_drawing.joint_span(pattern, records)
            label = self._joint_label(selected)
            if not len(records):
                label += ": no modules of its own; the line marks where its links meet"
        key = (id(lines), span, label)
        if key == self._pattern_key:
            return False
        self._pattern_key = key
        self._pattern_html.content = sheet_drawing.sheet_html(lines, span, label)
        self.pattern_draws += 1
        return True

    # --- animation ----------------------------------------------------------------------------
    @property
    def animating(self) -> bool:
        """Whether the animation runs."""
        return self._animation is not None

    @_locked
    def toggle_animation(self) -> bool:
        """Start the animation, or stop it when it runs; returns whether it runs now."""
        if self._animation is not None:
            self.stop_animation()
            return False
        return self.animate()

    @_locked
    def animate(self, period: float = ANIMATION_PERIOD, fps: float = ANIMATION_FPS) -> bool:
        """Sweep every movable joint through its state range and back, smoothly, every
        ``period`` seconds, until :meth:`stop_animation` (or any edit) stops it.

        Each frame is a preview (``EditorModel.preview``), not a command: nothing enters the
        undo history, the design does not become dirty, and stopping gives back the states the
        joints had. Each joint starts where it is. Frames that the chain refuses (e.g. it would
        pass through itself with requireClearance) are skipped.
        """
        rows = [row for row in self.model.joint_table() if row.movable]
        if not rows or self._animation is not None:
            return self._animation is not None
        states = [float(row.state) for row in self.model.joint_table()]
        sweeps = []
        for row in rows:
            lo, hi = (float(v) for v in row.state_range)
            mid, half = 0.5 * (lo + hi), 0.5 * (hi - lo)
            start = math.asin(min(1.0, max(-1.0, (float(row.state) - mid) / half)))
            sweeps.append((row.index, mid, half, start))
        stop = threading.Event()
        self._animation = stop
        self._animate.label = "Stop animation"
        self.animation_frames = 0
        thread = threading.Thread(
            target=self._animation_loop, args=(stop, states, sweeps, float(period), float(fps)),
            name="kinegami-animation", daemon=True,
        )  # fmt: skip
        thread.start()
        self._say("animating: every joint sweeps its range (click Stop animation to stop)")
        return True

    def _animation_loop(self, stop: threading.Event, states: list, sweeps: list,
                        period: float, fps: float) -> None:  # fmt: skip
        begin = time.monotonic()
        while not stop.is_set():
            frame_start = time.monotonic()
            phase = 2.0 * math.pi * (frame_start - begin) / period
            values = list(states)
            for index, mid, half, start in sweeps:
                values[index] = min(max(mid + half * math.sin(start + phase), mid - half),
                                    mid + half)  # fmt: skip
            with self.lock:
                if stop.is_set():
                    return
                if self.model.preview(SetJointStates(values)).ok:
                    self.animation_frames += 1
            stop.wait(max(0.0, 1.0 / fps - (time.monotonic() - frame_start)))

    @_locked
    def stop_animation(self) -> bool:
        """Stop the animation: the joints get back the states they had. False when none ran."""
        stop = self._animation
        if stop is None:
            return False
        stop.set()
        self._animation = None
        self._animate.label = "Animate"
        self.model.end_preview()
        self._say("animation stopped: the states are back as they were")
        return True

    # --- recovery -----------------------------------------------------------------------------
    def offer_recovery(self, recovery, on_choice: Callable[[str], None] | None = None) -> None:
        """Ask, in a dialog, whether to edit the autosave ``recovery`` (newer than the file)
        instead of the file; ``on_choice("recover" | "discard")`` after the user chose."""
        gui = self.gui
        with gui.add_modal("Recover unsaved changes?") as modal:
            gui.add_markdown(
                f"An autosave with {recovery.describe()} was found (`{recovery.path.name}`), "
                "newer than the file. **Recover** edits it (undo gives the file back); "
                "**Discard** removes it."
            )  # fmt: skip
            buttons = gui.add_button_group("Autosave", ("Recover", "Discard"))
        self._recovery_modal = modal

        def chosen(event) -> None:
            choice = "recover" if event.target.value == "Recover" else "discard"
            self.choose_recovery(recovery, choice)
            if on_choice is not None:
                on_choice(choice)

        buttons.on_click(chosen)

    @_locked
    def choose_recovery(self, recovery, choice: str) -> CommandResult | None:
        """``"recover"``: edit the autosave's document (one undoable step from the file);
        ``"discard"``: remove the autosave file. Closes the dialog."""
        if self._recovery_modal is not None:
            self._recovery_modal.close()
            self._recovery_modal = None
        if choice == "recover":
            command = ReplaceDocument(recovery.document, f"recover the autosave "
                                                         f"({recovery.describe()})")  # fmt: skip
            result = self.act(lambda: self.model.apply(command))
            if result.ok:  # another design, maybe of another size: grid and camera follow
                self._size_scene()
                self.frame_camera()
            if result.ok and recovery.legacy and self.autosave is not None:
                self.autosave.flush()  # now in the data folder: the old one beside the design goes
                if self.autosave.path.exists():
                    recovery.path.unlink(missing_ok=True)
            return result
        try:
            recovery.path.unlink()
        except FileNotFoundError:
            pass
        self._say(f"discarded the autosave {recovery.path.name}")
        return None
