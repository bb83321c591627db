"""A design's task in the editor (docs/editor.md, Tasks): which of its targets the design reaches.

A design file may carry the task it was made for, its ``"task"`` block
(docs/design-for-a-task.md). The editor draws every target beside the design, green when the
design's tip reaches it exactly, in range, clear of itself with the task's margin and outside
the task's keep-out boxes, red otherwise, with the reason (:func:`check_targets`). A tree task
is checked grasp by grasp: the k-th target of every leaf at once, in one configuration of the
whole tree, the task's leaf i on the tree's i-th leaf (:func:`leaf_tips`). Design for task and
Compact use the same goals (:func:`task_goals`).
"""

from __future__ import annotations

from dataclasses import dataclass

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError

__all__ = ["ATTEMPTS", "TargetCheck", "TaskGoals", "check_targets", "labelled_targets",
           "leaf_tips", "task_goals"]  # fmt: skip

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
    if not goals.task.is_tree:
        return tuple((_label(None, k, specs[k].get("name")), t)
                     for k, t in enumerate(goals.targets))  # fmt: skip
    return tuple((_label(i, k, specs[i][k].get("name")), t)
                 for i, leaf in enumerate(goals.targets)
                 for k, t in enumerate(leaf))  # fmt: skip


@dataclass(frozen=True)
class TargetCheck:
    """Whether a design reaches one target of its task.

    Attributes
    ----------
    index : the target's index in the task (a tree task: in its leaf's list, which is also its
        grasp: the k-th targets of every leaf are reached at once).
    name : its name in the task, or None.
    kind : ``"position"``, ``"axis"`` or ``"pose"``.
    position : where the tip must be (world frame, design units).
    rotation : the target's frame (3x3, rows; its z column is the axis of an axis target, the
        rotation of a pose target; the identity for a position target).
    reached : the tip is on it exactly (1e-9 r), every state in range, the design clear of
        itself with the task's margin and outside every keep-out box; a tree task's target only
        when its whole grasp is (every leaf on its k-th target in the same configuration).
    reason : why not, in one sentence ("" when reached); a tree task's names the leaf and
        target that keeps the grasp from being reached when it is another one.
    states : the configuration found (one state per joint): the answer when reached, else the
        nearest one (a tree task's: its grasp's, the same for every leaf).
    clearance : the smallest clearance at ``states`` (design units; negative: overlap depth).
    leaf : the task's leaf the target belongs to (a tree task), else None.
    tip : the tip joint checked on it (the joint whose distal frame must be on the target).
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
    leaf: int | None = None
    tip: int | None = None

    @property
    def label(self) -> str:
        """``target 2 'C'`` (the name when the task gives one); a tree task's
        ``leaf 1, target 0 'A'``."""
        return _label(self.leaf, self.index, self.name)


def _label(leaf: int | None, index: int, name: str | None) -> str:
    head = "" if leaf is None else f"leaf {leaf}, "
    return head + f"target {index}" + (f" '{name}'" if name else "")


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


def leaf_tips(design) -> tuple[int, ...]:
    """The tip joints a task's leaves are checked on: the joints of ``design`` (a chain or a
    tree) without children, in joint-index order (a chain: its last joint). A tree task's leaf
    i is the tree's i-th leaf: :func:`kinegami.optimize.design_for` adds each leaf's joints and
    end tip in the task's order, and design files keep the joints' order."""
    parents = {int(p) for p in design.Parents if p is not None and int(p) >= 0}
    return tuple(k for k in range(len(design.Joints)) if k not in parents)


def _reach(design, goal, attempts: int, margin: float, boxes) -> tuple:
    """``(answer, reached, box)``: :func:`kinegami.reach.solve` of ``goal`` (a target, or a tree's
    mapping {tip joint: target}) from the design's states, then from ``attempts`` - 1 other
    seeds, until an answer is exact, in range, clear with ``margin`` and outside the keep-out
    ``boxes``. ``answer`` is that one, else the last; ``box`` is ``(index, depth)`` of the
    keep-out box the last answer entered when it was exact (None otherwise)."""
    from kinegami.clearance.keep_out import keep_out_violation
    from kinegami.reach import solve

    for seed in range(max(1, int(attempts))):
        answer = solve(design, goal, seed=seed, margin=margin)
        box = None
        if not answer.ok:
            if answer.reason.startswith("beyond reach"):  # a bound: no other start reaches it
                break
            continue
        box = keep_out_violation(design, answer.states, boxes, margin)
        if box is None:
            return answer, True, None
    return answer, False, box


def _row(index: int, name, target, answer, reached: bool, reason: str, leaf=None,
         tip=None) -> TargetCheck:  # fmt: skip
    return TargetCheck(
        index, name, target.kind, tuple(float(v) for v in target.position),
        tuple(map(tuple, _frame_of(target).tolist())), reached, reason,
        tuple(float(s) for s in answer.states), float(answer.clearance), leaf, tip,
    )  # fmt: skip


def check_targets(design, task_document: dict, units: str,
                  attempts: int = ATTEMPTS) -> tuple[TargetCheck, ...]:  # fmt: skip
    """Per target of ``task_document``, whether ``design`` (a KinematicChain or KinematicTree
    in ``units``) reaches it: :func:`kinegami.reach.solve` from the design's states, then from
    ``attempts`` - 1 other seeds, with clearance and the task's margin, and the answer outside
    the keep-out boxes (:func:`kinegami.clearance.keep_out.keep_out_violation`).

    A tree task is checked grasp by grasp: its leaf i on the tree's i-th leaf
    (:func:`leaf_tips`), the k-th targets of every leaf solved at once (one configuration of the
    whole tree); the rows come leaf by leaf, as :func:`labelled_targets` lists them. When a
    grasp is not reached, each leaf's target is solved alone too, to say which of them keeps
    the grasp from being reached. A chain task on a tree is checked on its one leaf.

    Raises InvalidTypeError for a tree task on a chain, InvalidParameterError when a tree's
    leaves are not as many as its task's, and DesignError for an invalid task."""
    from kinegami.chain.model import KinematicChain
    from kinegami.tree.model import KinematicTree

    if not isinstance(design, KinematicChain | KinematicTree):
        raise InvalidTypeError(f"a task is checked on a KinematicChain or a KinematicTree, got "
                               f"a {type(design).__name__}")  # fmt: skip
    goals = task_goals(task_document, units)
    task = goals.task
    if isinstance(design, KinematicChain):
        if task.is_tree:
            raise InvalidTypeError("a tree task (joints given per leaf) is for a tree, and this "
                                   "design is a chain")  # fmt: skip
        tips = (len(design.Joints) - 1,)
    else:
        tips = leaf_tips(design)
        if len(tips) != task.leaves:
            joints = list(task.joints) if task.is_tree else task.joints
            leaves = f"{task.leaves} lea{'f' if task.leaves == 1 else 'ves'}"
            raise InvalidParameterError(
                f"task: a task for {leaves} (joints {joints!r}) is checked on a tree of as many "
                f"leaves, and this tree has {len(tips)} (tip joints "
                f"{', '.join(map(str, tips))}): the task's leaf i is the tree's i-th leaf in "
                "joint order"
            )  # fmt: skip
    specs = task_document["targets"]
    if not task.is_tree:
        checks = []
        for k, target in enumerate(goals.targets):
            goal = target if isinstance(design, KinematicChain) else {tips[0]: target}
            answer, reached, box = _reach(design, goal, attempts, goals.margin, goals.keep_out)
            reason = "" if reached else _missed(answer, box, units)
            checks.append(_row(k, specs[k].get("name"), target, answer, reached, reason,
                               tip=tips[0]))  # fmt: skip
        return tuple(checks)
    rows: dict[tuple[int, int], TargetCheck] = {}
    for k in range(task.grasps):
        grasp = {tip: goals.targets[i][k] for i, tip in enumerate(tips)}
        answer, reached, box = _reach(design, grasp, attempts, goals.margin, goals.keep_out)
        if reached:
            reasons = [""] * len(tips)
        elif box is not None:
            reasons = [f"where every leaf is on its target {k} at once, the design enters "
                       f"keep-out box {box[0]} (it comes {box[1]:.3g} {units} too close)"
                       ] * len(tips)  # fmt: skip
        else:
            reasons = _grasp_reasons(design, goals, tips, k, answer, attempts, units, specs)
        for i, tip in enumerate(tips):
            rows[i, k] = _row(k, specs[i][k].get("name"), goals.targets[i][k], answer, reached,
                              reasons[i], leaf=i, tip=tip)  # fmt: skip
    return tuple(rows[i, k] for i in range(len(tips)) for k in range(task.grasps))


def _missed(answer, box, units: str) -> str:
    """Why one tip's target is not reached: the solver's reason, or the keep-out box entered."""
    if box is not None:
        return (f"where the tip is on it, the design enters keep-out box {box[0]} (it comes "
                f"{box[1]:.3g} {units} too close)")  # fmt: skip
    return answer.reason or "not reached"


def _grasp_reasons(design, goals: TaskGoals, tips: tuple, k: int, answer, attempts: int,
                   units: str, specs) -> list[str]:  # fmt: skip
    """Per leaf, why its target of grasp ``k`` is not reached when the grasp is not (no
    keep-out box to blame): each leaf's target solved alone (the other leaves free); a target
    not reached alone gives its own reason, the others name those targets; when every target
    is reached alone, the grasp's reason (``answer``'s)."""
    alone = [_reach(design, {tip: goals.targets[i][k]}, attempts, goals.margin, goals.keep_out)
             for i, tip in enumerate(tips)]  # fmt: skip
    missing = [i for i, (_, reached, _) in enumerate(alone) if not reached]
    if not missing:
        why = answer.reason or "not reached"
        return [f"each leaf reaches its target {k} alone, but not every leaf at once: {why}"
                ] * len(tips)  # fmt: skip
    names = [_label(i, k, specs[i][k].get("name")) for i in missing]
    blocked = ", ".join(names[:-1]) + (" and " if len(names) > 1 else "") + names[-1]
    verb = "is" if len(names) == 1 else "are"
    return [_missed(alone[i][0], alone[i][2], units) if i in missing else
            f"its tip reaches it, but not at once with {blocked}, which {verb} not reached"
            for i in range(len(tips))]  # fmt: skip
