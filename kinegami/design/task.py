"""Task files (docs/design-for-a-task.md): what a robot must reach, for
:func:`kinegami.optimize.design_for` and ``kinegami design``.

A task file is a JSON object ``{"format": "kinegami-task", "version": 1, ...}``: the tube
(``r``, ``numSides``), the joints (a string such as ``"RRRR"`` or a budget, an integer), the
targets, and optionally a base pose, keep-out boxes, ``maxTubeLength``, ``margin``, ``seed``
and ``starts``. Lengths are in ``units``, the angles of pose steps in ``angleUnits``. A target
is ``{"position": [x, y, z]}``, ``{"position": [...], "axis": [ax, ay, az]}`` (the tip's z
along the axis) or ``{"pose": POSE}`` with a pose spelled as in design files. Validated by a
JSON Schema (``task_schema.json``, which borrows the design format's pose definitions); every
error is one :class:`~kinegami.errors.DesignError` line naming the field.

A tree task (a hand: docs/design-for-a-task.md, Trees) gives ``joints`` as an array of joint
strings, one per leaf, and ``targets`` as one array of targets per leaf, all of the same length:
the k-th target of every leaf is reached at once (a grasp). Then :attr:`Task.joints` is a tuple
of strings and :attr:`Task.targets` a tuple of per-leaf tuples.

A design written by ``kinegami design`` carries its task in an optional ``"task"`` block (the
same object), which ``kinegami compact`` keeps.
"""

from __future__ import annotations

import copy
import functools
import json
import os
from dataclasses import dataclass
from importlib import resources
from pathlib import Path

import jsonschema
import numpy as np

from kinegami.design.errors import DesignError, json_path
from kinegami.design.poses import pose_from_json

__all__ = ["TASK_FORMAT", "TASK_VERSIONS", "Task", "read_task", "starter_task", "task_from_dict",
           "task_schema"]  # fmt: skip

TASK_FORMAT = "kinegami-task"
TASK_VERSIONS = (1,)
#: The largest task file read (bytes).
MAX_TASK_BYTES = 1_000_000


@dataclass(frozen=True)
class Task:
    """A checked task file: ``design_for(list(task.targets), task.joints, **task.options())``
    designs it (:func:`kinegami.optimize.design_for`); ``document`` is the task as read (what a
    design's ``"task"`` block holds).

    ``joints`` is a joint string or a budget (a chain), or a tuple of joint strings, one per
    leaf (a tree, :attr:`is_tree`). ``targets`` holds :class:`~kinegami.reach.Target` s (world
    frame, ``units``): a chain's in order; a tree's as one tuple per leaf, all of the same
    length (the k-th of every leaf reached at once)."""

    name: str | None
    description: str | None
    units: str
    r: float
    numSides: int
    joints: str | int | tuple[str, ...]
    targets: tuple
    base: np.ndarray
    keep_out: tuple
    max_tube_length: float | None
    margin: float
    seed: int
    starts: int | None
    document: dict
    path: bool = False
    base_region: object | None = None  # a keep-out Box where the base's origin may be

    @property
    def is_tree(self) -> bool:
        """Whether the task is for a tree (joints given per leaf)."""
        return isinstance(self.joints, tuple)

    @property
    def leaves(self) -> int:
        """The leaves of the robot the task is for (1 for a chain)."""
        return len(self.joints) if isinstance(self.joints, tuple) else 1

    @property
    def grasps(self) -> int:
        """How many configurations the task asks for: a chain's targets, a tree's targets per
        leaf (the k-th of every leaf reached at once)."""
        return len(self.targets[0]) if self.is_tree else len(self.targets)

    def options(self) -> dict:
        """Keyword arguments of ``design_for(targets, joints, **options)``."""
        out = {"r": self.r, "numSides": self.numSides, "base": self.base,
               "keep_out": self.keep_out, "max_tube_length": self.max_tube_length,
               "margin": self.margin, "seed": self.seed}  # fmt: skip
        if self.starts is not None:
            out["starts"] = self.starts
        if self.path:
            out["path"] = True
        if self.base_region is not None:
            out["base_region"] = self.base_region
        return out


@functools.cache
def task_schema() -> dict:
    """The task file's JSON Schema (with the design format's pose definitions)."""
    from kinegami.design.schema import design_schema

    text = resources.files("kinegami.design").joinpath("task_schema.json").read_text("utf-8")
    schema = json.loads(text)
    borrowed = design_schema()["$defs"]
    for name in schema.pop("$borrowedDefs"):
        schema["$defs"][name] = copy.deepcopy(borrowed[name])
    return schema


@functools.cache
def _validator():
    return jsonschema.Draft202012Validator(task_schema())


def task_from_dict(document, file=None, where: tuple = ()) -> Task:
    """The :class:`Task` of a parsed task document (``where``: its JSON path in a larger
    document, for messages); DesignError (one line, naming the field) when it is invalid."""
    from kinegami.clearance.keep_out import Box
    from kinegami.design.schema import translate

    if not isinstance(document, dict):
        raise DesignError('a task must be a JSON object {...} with "format": "kinegami-task"',
                          field=json_path(where), value=document, file=file)  # fmt: skip
    if document.get("format") != TASK_FORMAT:
        raise DesignError(f"not a kinegami task: format must be '{TASK_FORMAT}'",
                          field=json_path((*where, "format")), value=document.get("format"),
                          file=file)  # fmt: skip
    errors = sorted(_validator().iter_errors(document),
                    key=lambda e: (list(map(str, e.absolute_path)), len(e.absolute_schema_path)))
    if errors:
        first = _target_branch_error(errors[0])
        error = translate(first, document, file)
        reason = _task_reason(first, document) or error.reason
        at = ["baseRegion"] if reason.startswith("is for chains") else first.absolute_path
        field = json_path((*where, *at))
        if error.has_value:
            raise DesignError(reason, field=field, value=error.value, file=file)
        raise DesignError(reason, field=field, file=file)
    tree = isinstance(document["joints"], list)
    if tree:
        _check_tree_shape(document, file, where)
    units = document.get("units", "mm")
    angle_units = document.get("angleUnits", "rad")
    r = float(document["r"])
    if tree:
        targets = tuple(_targets(leaf, (*where, "targets", i), angle_units, file)
                        for i, leaf in enumerate(document["targets"]))  # fmt: skip
        joints = tuple(document["joints"])
    else:
        targets = _targets(document["targets"], (*where, "targets"), angle_units, file)
        joints = document["joints"]
    base = np.eye(4) if "base" not in document else \
        pose_from_json(document["base"], (*where, "base"), angle_units)  # fmt: skip
    boxes = []
    for k, spec in enumerate(document.get("keepOut", [])):
        try:
            boxes.append(Box.of(spec, f"keepOut[{k}]"))
        except ValueError as exc:
            raise DesignError(str(exc), field=json_path((*where, "keepOut", k)),
                              file=file) from None  # fmt: skip
    region = None
    if "baseRegion" in document:
        try:
            region = Box.of(document["baseRegion"], "baseRegion")
        except ValueError as exc:
            raise DesignError(str(exc), field=json_path((*where, "baseRegion")),
                              file=file) from None  # fmt: skip
    return Task(
        name=document.get("name"), description=document.get("description"), units=units, r=r,
        numSides=int(document["numSides"]), joints=joints, targets=targets,
        base=base, keep_out=tuple(boxes), max_tube_length=document.get("maxTubeLength"),
        margin=float(document.get("margin", 0.0)), seed=int(document.get("seed", 0)),
        starts=document.get("starts"), document=copy.deepcopy(dict(document)),
        path=bool(document.get("path", False)), base_region=region,
    )  # fmt: skip


def _targets(specs: list, where: tuple, angle_units: str, file) -> tuple:
    """The :class:`~kinegami.reach.Target` s of a checked list of target objects at JSON path
    ``where``."""
    from kinegami.reach import Target

    targets = []
    for k, spec in enumerate(specs):
        path = (*where, k)
        try:
            if "pose" in spec:
                targets.append(Target.of(pose_from_json(spec["pose"], (*path, "pose"),
                                                        angle_units)))  # fmt: skip
            else:
                targets.append(Target(spec["position"], axis=spec.get("axis")))
        except DesignError:
            raise
        except ValueError as exc:  # a zero axis, a pose that is not rigid
            raise DesignError(str(exc), field=json_path(path), file=file) from None
    return tuple(targets)


def _target_branch_error(error: jsonschema.ValidationError) -> jsonschema.ValidationError:
    """For a target object that fits neither form, the first error of the form it was meant as
    (a pose when it has ``"pose"``, else a position); any other error as it is."""
    path = list(error.absolute_path)
    if error.validator != "oneOf" or not path or path[0] != "targets" or \
            not isinstance(error.instance, dict) or not error.context:  # fmt: skip
        return error
    form = 1 if "pose" in error.instance else 0
    meant = [e for e in error.context if e.relative_schema_path and
             e.relative_schema_path[0] == form]  # fmt: skip
    if not meant:
        return error
    return min(meant, key=lambda e: (list(map(str, e.absolute_path)),
                                     len(e.absolute_schema_path)))  # fmt: skip


def _task_reason(error: jsonschema.ValidationError, document: dict) -> str | None:
    """A clearer reason than the design format's for a schema error of a task's own fields
    (None: the design format's reason is clear)."""
    path = list(error.absolute_path)
    tree = isinstance(document.get("joints"), list)
    if path and path[0] == "joints" and error.validator == "pattern":
        return "must be a string of the letters R and P, 1 to 8 of them (e.g. \"RRR\")"
    if path[:1] == ["joints"] and len(path) == 2 and error.validator == "type":
        return ("must be a joint string such as \"RRR\" (a tree task gives one joint string "
                "per leaf)")
    if path == ["joints"] and error.validator == "oneOf":
        return ("must be a joint string such as \"RRRR\", a budget (an integer, 1 to 8) or, "
                "for a tree, an array of joint strings, one per leaf")
    if path == ["path"] and error.validator == "const" and tree:
        return ("\"path\": true is for chains; a tree task (joints given per leaf) asks for "
                "grasps only")
    if tree and "baseRegion" in document and error.validator is None and \
            error.instance == document["baseRegion"]:  # fmt: skip
        return ("is for chains; a tree task's root is at \"base\" (its leaves start on a ring "
                "around it)")
    if len(path) == 2 and path[0] == "targets" and error.validator == "type":
        if tree:
            return (f"must be an array of targets: a tree task (joints given per leaf) gives "
                    f"one array of targets per leaf ({len(document['joints'])} leaves)")
        if isinstance(error.instance, list):
            return ("must be a target object; one array of targets per leaf is a tree task, "
                    "whose \"joints\" is an array of joint strings, one per leaf")
    if path == ["targets"] and error.validator == "maxItems" and tree:
        return (f"a tree task has at most {error.validator_value} leaves (one array of targets "
                f"per leaf); it has {len(error.instance)}")
    return None


#: The most targets a task names (a tree's over all its leaves), as design_for takes.
MAX_TASK_TARGETS = 64


def _check_tree_shape(document: dict, file, where: tuple) -> None:
    """The checks of a tree task that its schema cannot state: one target array per leaf, all
    of the same length, at most :data:`MAX_TASK_TARGETS` targets in all."""
    joints, targets = document["joints"], document["targets"]
    if len(targets) != len(joints):
        raise DesignError(
            f"a tree task needs one array of targets per leaf: \"joints\" names {len(joints)} "
            f"leaves, \"targets\" has {len(targets)} arrays",
            field=json_path((*where, "targets")), file=file,
        )  # fmt: skip
    for i, leaf in enumerate(targets[1:], start=1):
        if len(leaf) != len(targets[0]):
            raise DesignError(
                f"every leaf needs the same number of targets (the k-th target of every leaf "
                f"is reached at once): targets[0] has {len(targets[0])}, targets[{i}] has "
                f"{len(leaf)}", field=json_path((*where, "targets", i)), file=file,
            )  # fmt: skip
    total = sum(len(leaf) for leaf in targets)
    if total > MAX_TASK_TARGETS:
        raise DesignError(f"a task names at most {MAX_TASK_TARGETS} targets in all; this tree "
                          f"task names {total}", field=json_path((*where, "targets")),
                          file=file)  # fmt: skip


def read_task(path) -> Task:
    """The :class:`Task` of the task file at ``path`` (DesignError when it cannot be read or is
    invalid: one line naming the file and the field)."""
    if not isinstance(path, str | os.PathLike) or isinstance(os.fspath(path), bytes):
        raise DesignError(f"the task file name must be a str or a path, got {path!r}")
    name = os.fspath(path)
    file = Path(name)
    try:
        if not file.is_file():
            what = "does not exist" if not file.exists() else "is not a regular file"
            raise DesignError(f"the task file {what}", file=name)
        if file.stat().st_size > MAX_TASK_BYTES:
            raise DesignError(f"the task file is larger than {MAX_TASK_BYTES} bytes", file=name)
        data = file.read_bytes()
    except OSError as exc:
        raise DesignError(f"cannot read the task file: {exc.strerror or exc}", file=name) from None
    try:
        text = data.decode("utf-8-sig")
    except UnicodeDecodeError as exc:
        raise DesignError(f"the task file is not UTF-8 text (byte {exc.start})",
                          file=name) from None  # fmt: skip
    if not text.strip():
        raise DesignError('the task file is empty: a task is a JSON object {...} with "format": '
                          '"kinegami-task" (\'kinegami new --task FILE\' writes one)', file=name)
    try:
        document = json.loads(text, parse_constant=_no_constant)
    except json.JSONDecodeError as exc:
        raise DesignError(f"invalid JSON at line {exc.lineno}, column {exc.colno}: {exc.msg}",
                          file=name) from None  # fmt: skip
    except ValueError as exc:
        raise DesignError(str(exc), file=name) from None
    return task_from_dict(document, name)


def _no_constant(name: str):
    raise ValueError(f"{name} is not a number a task may hold (JSON has no {name})")


def starter_task(tree: bool = False) -> dict:
    """A small task that ``kinegami design`` solves in seconds (what ``kinegami new --task``
    writes): a four-joint arm on a square tube of radius 10 mm that touches four points above a
    table it must stay clear of. With ``tree``, a tree task (``kinegami new --task --tree``;
    designed in about 20 s): two three-joint fingers on that tube, each touching two points,
    the k-th points of both at once."""
    name = "starter_tree_task.json" if tree else "starter_task.json"
    return json.loads(resources.files("kinegami.design").joinpath(name).read_text("utf-8"))
