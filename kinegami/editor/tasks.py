"""A design's task in the editor (docs/editor.md, Tasks): which of its targets the design reaches.

A design file may carry the task it was made for, its ``"task"`` block
(docs/design-for-a-task.md). The editor draws every target beside the design, green when the
design's tip reaches it exactly, in range, clear of itself with the task's margin and outside
the task's keep-out boxes, red otherwise, with the reason (:func:`check_targets`). Design for
task and Compact use the same goals (:func:`task_goals`). Tasks are for chains for now.
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinegami.errors import InvalidTypeError

__all__ = ["ATTEMPTS", "TargetCheck", "TaskGoals", "check_targets", "labelled_targets",
           "task_goals"]

#: Solves per target before it counts as not reached (seeds 0, 1, ...; the first starts from
#: the design's states), as compaction with a task tries.
ATTEMPTS = 4


@dataclass(frozen=True)
class TaskGoals:
    """A task's targets, keep-out boxes and margin in a design's length units.

    Attributes
    ----------
    task : the :class:`~kinegami.design.task.Task` as read (its own units).
    targets : one :class:`~kinegami.reach.Target` per task target (world frame, design units);
        a tree task's as one tuple per leaf, as the task holds them.
    keep_out : the keep-out :class:`~kinegami.clearance.keep_out.Box` es (design units).
    margin : the clearance required (design units).
    scale : design units per task unit (1 when both are the same).
    """

    task: object
    targets: tuple
    keep_out: tuple
    margin: float
    scale: float


def task_goals(task_document: dict, units: str) -> TaskGoals:
    """The goals of a task document for a design whose lengths are in ``units`` (the task's
    lengths are in its own ``units``; they are converted when the two differ). Raises
    DesignError when the task is invalid."""
    from kinegami.clearance.keep_out import Box
    from kinegami.design.task import task_from_dict
    from kinegami.reach import Target
    from kinegami.validation import UNITS_IN_MM

    task = task_from_dict(task_document, where=("task",))
    scale = UNITS_IN_MM[task.units] / UNITS_IN_MM[units]
    if scale == 1.0:
        return TaskGoals(task, task.targets, task.keep_out, task.margin, 1.0)

    def scaled(targets) -> tuple:
        return tuple(Target(t.position * scale, axis=t.axis, rotation=t.rotation)
                     for t in targets)  # fmt: skip

    targets = tuple(scaled(leaf) for leaf in task.targets) if task.is_tree \
        else scaled(task.targets)  # fmt: skip
    boxes = tuple(Box(tuple(np.multiply(box.min, scale).tolist()),
                      tuple(np.multiply(box.max, scale).tolist()))
                  for box in task.keep_out)  # fmt: skip
    return TaskGoals(task, targets, boxes, task.margin * scale, scale)


def labelled_targets(goals: TaskGoals) -> tuple[tuple[str, object], ...]:
    """Every target of ``goals`` with its label, in the task's order: ``target 2 'C'`` (the
    name when the task gives one); a tree task's leaf by leaf, ``leaf 1, target 0 'A'``."""
    specs = goals.task.document["targets"]

    def label(k: int, spec: dict) -> str:
        return f"target {k}" + (f" '{spec['name']}'" if spec.get("name") else "")

    if not goals.task.is_tree:
        return tuple((label(k, specs[k]), t) for k, t in enumerate(goals.targets))
    return tuple((f"leaf {i}, {label(k, specs[i][k])}", t)
                 for i, leaf in enumerate(goals.targets)
                 for k, t in enumerate(leaf))  # fmt: skip


@dataclass(frozen=True)
class TargetCheck:
    """Whether a design reaches one target of its task.

    Attributes
    ----------
    index : the target's index in the task.
    name : its name in the task, or None.
    kind : ``"position"``, ``"axis"`` or ``"pose"``.
    position : where the tip must be (world frame, design units).
    rotation : the target's frame (3x3, rows; its z column is the axis of an axis target, the
        rotation of a pose target; the identity for a position target).
    reached : the tip is on it exactly (1e-9 r), every state in range, the design clear of
        itself with the task's margin and outside every keep-out box.
    reason : why not, in one sentence ("" when reached).
    states : the configuration found (one state per joint): the answer when reached, else the
        nearest one.
    clearance : the smallest clearance at ``states`` (design units; negative: overlap depth).
    """

    index: int
    name: str | None
    kind: str
    position: tuple
    rotation: tuple
    reached: bool
    reason: str
    states: tuple
    clearance: float

    @property
    def label(self) -> str:
        """``target 2 'C'`` (the name when the task gives one)."""
        return f"target {self.index}" + (f" '{self.name}'" if self.name else "")


def _frame_of(target) -> np.ndarray:
    """A rotation whose z column is the target's axis (pose: its rotation; position: I)."""
    if target.rotation is not None:
        return np.asarray(target.rotation, dtype=float)
    if target.axis is None:
        return np.eye(3)
    z = np.asarray(target.axis, dtype=float)
    helper = np.array([1.0, 0.0, 0.0]) if abs(z[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    x = np.cross(helper, z)
    x /= np.linalg.norm(x)
    return np.column_stack([x, np.cross(z, x), z])


def check_targets(chain, task_document: dict, units: str,
                  attempts: int = ATTEMPTS) -> tuple[TargetCheck, ...]:  # fmt: skip
    """Per target of ``task_document``, whether ``chain`` (a KinematicChain in ``units``)
    reaches it: :func:`kinegami.reach.solve` from the chain's states, then from ``attempts``
    - 1 other seeds, with clearance and the task's margin, and the answer outside the keep-out
    boxes (:func:`kinegami.clearance.keep_out.keep_out_violation`). Raises InvalidTypeError
    for a tree (tasks are for chains for now) and DesignError for an invalid task."""
    from kinegami.chain.model import KinematicChain
    from kinegami.clearance.keep_out import keep_out_violation
    from kinegami.reach import solve

    if not isinstance(chain, KinematicChain):
        raise InvalidTypeError(f"a task is checked on a chain (tasks are for chains for now), "
                               f"got a {type(chain).__name__}")  # fmt: skip
    goals = task_goals(task_document, units)
    if goals.task.is_tree:
        raise InvalidTypeError("a tree task (joints given per leaf) is for a tree, and this "
                               "design is a chain")  # fmt: skip
    specs = task_document["targets"]
    checks = []
    for k, target in enumerate(goals.targets):
        reached, reason = False, ""
        for seed in range(max(1, int(attempts))):
            answer = solve(chain, target, seed=seed, margin=goals.margin)
            if not answer.ok:
                reason = answer.reason or "not reached"
                continue
            hit = keep_out_violation(chain, answer.states, goals.keep_out, goals.margin)
            if hit is None:
                reached, reason = True, ""
                break
            reason = (f"where the tip is on it, the design enters keep-out box {hit[0]} (it "
                      f"comes {hit[1]:.3g} {units} too close)")  # fmt: skip
        checks.append(TargetCheck(
            k, specs[k].get("name"), target.kind, tuple(float(v) for v in target.position),
            tuple(map(tuple, _frame_of(target).tolist())), reached, reason,
            tuple(float(s) for s in answer.states), float(answer.clearance),
        ))  # fmt: skip
    return tuple(checks)
