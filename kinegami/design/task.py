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
    """A checked task file: :meth:`options` are :func:`kinegami.optimize.design_for`'s
    arguments; ``document`` the task as read (what a design's ``"task"`` block holds)."""

    name: str | None
    description: str | None
    units: str
    r: float
    numSides: int
    joints: str | int
    targets: tuple
    base: np.ndarray
    keep_out: tuple
    max_tube_length: float | None
    margin: float
    seed: int
    starts: int | None
    document: dict
    path: bool = False

    def options(self) -> dict:
        """Keyword arguments of ``design_for(targets, joints, **options)``."""
        out = {"r": self.r, "numSides": self.numSides, "base": self.base,
               "keep_out": self.keep_out, "max_tube_length": self.max_tube_length,
               "margin": self.margin, "seed": self.seed}  # fmt: skip
        if self.starts is not None:
            out["starts"] = self.starts
        if self.path:
            out["path"] = True
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
    from kinegami.reach import Target

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
        error = translate(errors[0], document, file)
        field = json_path((*where, *errors[0].absolute_path))
        if error.has_value:
            raise DesignError(error.reason, field=field, value=error.value, file=file)
        raise DesignError(error.reason, field=field, file=file)
    units = document.get("units", "mm")
    angle_units = document.get("angleUnits", "rad")
    r = float(document["r"])
    targets = []
    for k, spec in enumerate(document["targets"]):
        path = (*where, "targets", k)
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
    base = np.eye(4) if "base" not in document else \
        pose_from_json(document["base"], (*where, "base"), angle_units)  # fmt: skip
    boxes = []
    for k, spec in enumerate(document.get("keepOut", [])):
        try:
            boxes.append(Box.of(spec, f"keepOut[{k}]"))
        except ValueError as exc:
            raise DesignError(str(exc), field=json_path((*where, "keepOut", k)),
                              file=file) from None  # fmt: skip
    return Task(
        name=document.get("name"), description=document.get("description"), units=units, r=r,
        numSides=int(document["numSides"]), joints=document["joints"], targets=tuple(targets),
        base=base, keep_out=tuple(boxes), max_tube_length=document.get("maxTubeLength"),
        margin=float(document.get("margin", 0.0)), seed=int(document.get("seed", 0)),
        starts=document.get("starts"), document=copy.deepcopy(dict(document)),
        path=bool(document.get("path", False)),
    )  # fmt: skip


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


def starter_task() -> dict:
    """A small task that ``kinegami design`` solves in seconds (what ``kinegami new --task``
    writes): a four-joint arm on a square tube of radius 10 mm that touches four points above a
    table it must stay clear of."""
    text = resources.files("kinegami.design").joinpath("starter_task.json").read_text("utf-8")
    return json.loads(text)
