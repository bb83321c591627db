"""Design for a task (docs/design-for-a-task.md): targets in, a foldable chain that reaches every
one of them exactly, in range and without passing through itself, out.

The search works on the kinematics alone: a standard Denavit-Hartenberg table (theta, alpha, a,
d per joint, the root joint on the base pose) and one configuration per target are fitted
together by bounded least squares (:func:`scipy.optimize.least_squares`), from seeded random
starts, until every target's residual is below 1e-11 r. Such a table is then built by
kinegami's own placement (the joints slide along their axes, which keeps the kinematics; the end
tip is placed exactly where the table puts the tip), and every target is solved again on the
built chain by :func:`kinegami.reach.solve` with clearance, the margin and the keep-out boxes:
only a chain that passes those checks is an answer, and only one whose folded form needs no
isometry repair is returned. Compaction with the targets (:func:`kinegami.optimize.compact`)
then shortens its tube.

Before any search, bounds that prove a task impossible raise :class:`InfeasibleTaskError` (the
certificate): a target farther from the base than the longest tube allowed; orientations that
the joint types cannot give (no revolute joint, or one).
"""

from __future__ import annotations

import concurrent.futures
import itertools
import math
import warnings
from collections.abc import Sequence
from dataclasses import dataclass, replace

import numpy as np

from kinegami.clearance.keep_out import Box, keep_out_violation
from kinegami.errors import (
    InfeasibleTaskError,
    InvalidParameterError,
    InvalidTypeError,
    KinegamiError,
)
from kinegami.progress import Progress, check_progress
from kinegami.validation import check_int, check_num_sides, check_positive, check_radius

__all__ = ["MAX_TASK_JOINTS", "MAX_TASK_TARGETS", "design_for", "task_certificate"]

#: The most joints a task's design may have (each joint adds four table entries and one state
#: per target to the fit).
MAX_TASK_JOINTS = 8
#: The most targets one task may name (each adds a configuration to the fit).
MAX_TASK_TARGETS = 64
#: Largest residual of a fitted table (units of r and rad) that is built and checked.
FIT_TOLERANCE = 1e-11
#: Starts of the fit run together (a round): the search stops after the first round that gives
#: a design, so the answer does not depend on the executor.
ROUND = 8
#: Default number of starts per joint-type string.
STARTS = 64
#: The fit's bounds, tried in order until one gives an exact fit: (share of each revolute
#: joint's range kept free at either end, largest distance of the tip from the last joint's
#: axis in r (position targets; None: no bound)). A joint near its limit folds the elbows beside
#: it into each other: with 0.2 of the range kept (within 54 deg of the middle of a revolute
#: joint's), 5 of 8 starts of a benchmark pose task gave a design, against 1 of 23 without.
#: The last link spans the tip's distance from the last axis, which no placement shortens.
FIT_STAGES = ((0.2, 5.0), (0.2, None), (0.0, None))
#: The default longest tube, in units of r.
MAX_TUBE_LENGTH_R = 100.0


# --- the task ------------------------------------------------------------------------------------
@dataclass(frozen=True)
class _Task:
    """A checked task: targets (reach Targets), base pose, boxes, bounds, tube."""

    targets: tuple
    r: float
    numSides: int
    base: np.ndarray
    boxes: tuple
    max_tube_length: float
    margin: float
    oriented: bool  # some target fixes an orientation or an axis
    path: bool = False  # the moves from each target to the next must be clear too
    region: Box | None = None  # where the base's origin may be (world); None: at base

    @property
    def origin(self) -> np.ndarray:
        """The base's origin, or the centre of its region."""
        if self.region is None:
            return self.base[:3, 3]
        return 0.5 * (np.asarray(self.region.min) + np.asarray(self.region.max))

    @property
    def scale(self) -> float:
        """The largest distance of a target from the base's origin (its region's centre)."""
        return max(float(np.linalg.norm(t.position - self.origin)) for t in self.targets)

    def base_distance(self, point: np.ndarray) -> float:
        """The distance of ``point`` from the base's origin (from its region, when given)."""
        if self.region is None:
            return float(np.linalg.norm(point - self.base[:3, 3]))
        return float(np.linalg.norm(point - np.clip(point, self.region.min, self.region.max)))


def _joint_strings(joints) -> list[str]:
    """The joint-type strings to try, in order: the given one, or for a budget every string of
    1 to k joints, fewest first (then fewest prismatic joints)."""
    if isinstance(joints, str):
        types = joints.upper()
        if not types or set(types) - {"R", "P"}:
            raise InvalidParameterError(
                f"joints must be a string of 'R' (revolute) and 'P' (prismatic), got {joints!r}"
            )
        if len(types) > MAX_TASK_JOINTS:
            raise InvalidParameterError(
                f"joints {joints!r} has {len(types)} joints; at most {MAX_TASK_JOINTS} "
                "(MAX_TASK_JOINTS: each adds a table row and a state per target to the search)"
            )
        return [types]
    budget = check_int("joints", joints, minimum=1, floats=False)
    if budget > MAX_TASK_JOINTS:
        raise InvalidParameterError(
            f"joints (a budget) must be at most {MAX_TASK_JOINTS} (MAX_TASK_JOINTS), got {budget}"
        )
    out = []
    for k in range(1, budget + 1):
        strings = ["".join(s) for s in itertools.product("RP", repeat=k)]
        out += sorted(strings, key=lambda s: (s.count("P"), s))
    return out


def _task(targets, r, numSides, base, keep_out, max_tube_length, margin,
          base_region=None) -> _Task:  # fmt: skip
    from kinegami.chain.bodies import check_margin
    from kinegami.chain.joints import pose_array
    from kinegami.reach import Target

    r = check_radius(r)
    n = check_num_sides(numSides)
    if isinstance(targets, np.ndarray) and targets.ndim >= 2:
        targets = list(targets)
    if (
        isinstance(targets, (str, bytes))
        or not isinstance(targets, Sequence)
        or (len(targets) and all(isinstance(v, (int, float, np.number)) for v in targets))
    ):
        # one position given alone is not a list of targets
        raise InvalidTypeError(
            "targets must be a list of targets (3-vectors, 4x4 poses or reach Targets), got "
            f"{targets!r}"
        )
    if not 1 <= len(targets) <= MAX_TASK_TARGETS:
        raise InvalidParameterError(
            f"a task needs 1 to {MAX_TASK_TARGETS} targets (MAX_TASK_TARGETS), got {len(targets)}"
        )
    found = tuple(Target.of(t) for t in targets)
    limit = 1e6 * r
    for k, t in enumerate(found):
        if np.abs(t.position).max() > limit:
            raise InvalidParameterError(
                f"target {k} position {t.position.tolist()} is beyond 1e6 r = {limit:g} "
                "(the coordinate limit, docs/limits.md)"
            )
    B = np.eye(4) if base is None else pose_array(getattr(base, "A", base), "base")
    boxes = tuple(Box.of(b, f"keep_out box {k}") for k, b in enumerate(keep_out or ()))
    L = MAX_TUBE_LENGTH_R * r if max_tube_length is None \
        else check_positive("max_tube_length", max_tube_length)  # fmt: skip
    margin = check_margin(margin)
    oriented = any(t.kind != "position" for t in found)
    region = None
    if base_region is not None:
        region = Box.of(base_region, "base_region")
        if np.any(np.abs(np.r_[region.min, region.max]) > limit):
            raise InvalidParameterError(
                f"base_region {_fmt(region.min)} to {_fmt(region.max)} reaches beyond 1e6 r = "
                f"{limit:g} (the coordinate limit, docs/limits.md)"
            )
        B = B.copy()
        B[:3, 3] = 0.0  # the origin is an unknown of the fit, within the region
    return _Task(found, r, n, B, boxes, float(L), margin, oriented, region=region)


def task_certificate(task: _Task, types: str) -> tuple[int, str] | None:
    """(target index, why) when a bound proves that no chain of the joint types ``types`` can
    reach every target, else None (docs/design-for-a-task.md, Certificates)."""
    L = task.max_tube_length
    where = f"at {_fmt(task.origin)}" if task.region is None else \
        f"region {_fmt(task.region.min)} to {_fmt(task.region.max)}"  # fmt: skip
    for k, t in enumerate(task.targets):
        D = task.base_distance(t.position)
        if D > L:
            return k, (
                f"target {k} at {_fmt(t.position)} is {D:.6g} from the base {where}, "
                f"farther than the longest tube allowed (max_tube_length {L:.6g}): the tip of a "
                f"tube of length L stays within L of its base"
            )
    for k, t in enumerate(task.targets):  # the tube's centreline passes through the target
        for j, box in enumerate(task.boxes):
            inside = np.clip(t.position, box.min, box.max)
            gap = float(np.linalg.norm(t.position - inside))
            if gap < task.r + task.margin:
                return k, (
                    f"target {k} at {_fmt(t.position)} is {gap:.6g} from keep-out box {j}, "
                    f"closer than the tube's radius plus the margin ({task.r + task.margin:.6g}): "
                    "the tip's tube would enter the box"
                )
    revolute = types.count("R")
    posed = [(k, t) for k, t in enumerate(task.targets) if t.kind == "pose"]
    axes = [(k, t) for k, t in enumerate(task.targets) if t.kind == "axis"]
    if revolute == 0:  # the tip never turns
        z = [(k, t.rotation[:, 2]) for k, t in posed] + [(k, t.axis) for k, t in axes]
        for (k0, t0), (k, t) in itertools.combinations(posed, 2):
            angle = _angle(t.rotation @ t0.rotation.T)
            if angle > 1e-9:
                return k, (
                    f"target {k}'s orientation differs from target {k0}'s by {angle:.6g} rad, "
                    f"but prismatic joints alone ({types}) never turn the tip"
                )
        for (k0, z0), (k, zk) in itertools.combinations(z, 2):
            angle = math.atan2(float(np.linalg.norm(np.cross(z0, zk))), float(z0 @ zk))
            if angle > 1e-9:
                return k, (
                    f"target {k}'s axis differs from target {k0}'s by {angle:.6g} rad, but "
                    f"prismatic joints alone ({types}) never turn the tip"
                )
    if revolute == 1 and len(posed) >= 2:  # the tip turns about one fixed direction
        (k0, t0) = posed[0]
        direction = None
        for k, t in posed[1:]:
            w = _rotation_vector(t.rotation @ t0.rotation.T)
            angle = float(np.linalg.norm(w))
            if angle <= 1e-9:
                continue
            u = w / angle  # (at pi its sign is arbitrary: the cross product below ignores it)
            if direction is None:
                direction = (k, u)
                continue
            cross = float(np.linalg.norm(np.cross(direction[1], u)))
            if cross > 1e-9:
                return k, (
                    f"target {k} turns from target {k0} about {_fmt(u)} but target "
                    f"{direction[0]} about {_fmt(direction[1])}: one revolute joint ({types}) "
                    "turns the tip about one direction only"
                )
    return None


def _fmt(v) -> str:
    return "(" + ", ".join(f"{float(x):.6g}" for x in v) + ")"


def _angle(R: np.ndarray) -> float:
    return float(np.linalg.norm(_rotation_vector(R)))


def _rotation_vector(R: np.ndarray) -> np.ndarray:
    from scipy.spatial.transform import Rotation

    return Rotation.from_matrix(R).as_rotvec()


# --- the model: a DH table with one configuration per target -------------------------------------
def _dh(theta, alpha, a, d) -> np.ndarray:
    """(..., 4, 4) standard DH transforms Rz(theta) Tz(d) Tx(a) Rx(alpha)."""
    ct, st, ca, sa = np.cos(theta), np.sin(theta), np.cos(alpha), np.sin(alpha)
    theta = np.broadcast_to(theta, np.broadcast_shapes(np.shape(theta), np.shape(d)))
    out = np.zeros(theta.shape + (4, 4))
    out[..., 0, 0], out[..., 0, 1], out[..., 0, 2], out[..., 0, 3] = ct, -st * ca, st * sa, a * ct
    out[..., 1, 0], out[..., 1, 1], out[..., 1, 2], out[..., 1, 3] = st, ct * ca, -ct * sa, a * st
    out[..., 2, 1], out[..., 2, 2], out[..., 2, 3] = sa, ca, d
    out[..., 3, 3] = 1.0
    return out


def _elementary(kind: str, axis: int, value) -> np.ndarray:
    """(..., 4, 4): a turn ("R") about or a slide ("P") along coordinate axis 0, 1 or 2."""
    value = np.asarray(value, dtype=float)
    out = np.zeros(value.shape + (4, 4))
    out[..., 0, 0] = out[..., 1, 1] = out[..., 2, 2] = out[..., 3, 3] = 1.0
    if kind == "P":
        out[..., axis, 3] = value
        return out
    i, j = (axis + 1) % 3, (axis + 2) % 3
    c, s = np.cos(value), np.sin(value)
    out[..., i, i], out[..., i, j], out[..., j, i], out[..., j, j] = c, -s, s, c
    return out


def _tool(tool: np.ndarray) -> np.ndarray:
    """The tool frame on the last DH frame: Trans(tx, ty, tz) Rz(c) Ry(b) Rx(a) of
    ``tool`` = (tx, ty, tz, c, b, a)."""
    E = np.eye(4)
    for kind, axis, value in _TOOL_STEPS:
        E = E @ _elementary(kind, axis, tool[value])
    return E


def _cross(a: np.ndarray, b: np.ndarray, axis: int = -1) -> np.ndarray:
    """The cross product of a and b (broadcast) along ``axis`` (numpy's cross, without its
    overhead on small arrays)."""
    a, b = np.moveaxis(a, axis, 0), np.moveaxis(b, axis, 0)
    out = np.stack([a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2],
                    a[0] * b[1] - a[1] * b[0]])  # fmt: skip
    return np.moveaxis(out, 0, axis)


#: The elementary steps of one DH row: Rz(theta) Tz(d) Tx(a) Rx(alpha), as (kind, axis, column
#: of the row (theta, alpha, a, d)).
_ROW_STEPS = (("R", 2, 0), ("P", 2, 3), ("P", 0, 2), ("R", 0, 1))
#: The tool's steps, as (kind, axis, index in the tool's six numbers).
_TOOL_STEPS = (("P", 0, 0), ("P", 1, 1), ("P", 2, 2), ("R", 2, 3), ("R", 1, 4), ("R", 0, 5))
_UNIT = np.eye(3)


class _Model:
    """The fit's unknowns and residuals for one joint-type string: x = (table (n, 4) flattened,
    the tool (translation, ZYX angles) when a target is oriented, the configurations
    (targets, n)). The tip is a product of elementary turns and slides, so the residual's
    Jacobian is exact: a step's unit twist, moved to the world by the product before it."""

    def __init__(self, task: _Task, types: str):
        self.task, self.types = task, types
        self.n, self.T = len(types), len(task.targets)
        self.revolute = np.array([c == "R" for c in types])
        r = task.r
        ranges = {kind: _joint(task, kind).stateRange() for kind in "RP"}
        self.low = np.array([ranges[c][0] for c in types])
        self.high = np.array([ranges[c][1] for c in types])
        self.tool_size = 6 if task.oriented else 0
        self.base_size = 0 if task.region is None else 3  # the base's origin, when free
        self.first_q = 4 * self.n + self.tool_size + self.base_size
        self.size = self.first_q + self.T * self.n
        # lengths of the table and the tool: within half the longest tube, and about the
        # task's spread
        self.span = min(0.5 * task.max_tube_length, max(4.0 * r, 1.5 * task.scale))
        self.position = np.array([t.position for t in task.targets])
        self.kinds = [t.kind for t in task.targets]
        self.rotation = np.array([t.rotation if t.rotation is not None else np.eye(3)
                                  for t in task.targets])  # fmt: skip
        self.axis = np.array([t.axis if t.axis is not None else np.zeros(3)
                              for t in task.targets])  # fmt: skip
        # columns of x: per step of the product, the table's or the tool's entry, and the
        # configuration's entry that adds to it (-1: none)
        steps, columns, joint_of = [], [], []
        for axis in range(self.base_size):  # the base's origin: slides along the world's axes
            steps.append(("P", axis))
            columns.append(4 * self.n + self.tool_size + axis)
            joint_of.append(-1)
        for i in range(self.n):
            for kind, axis, c in _ROW_STEPS:
                steps.append((kind, axis))
                columns.append(4 * i + c)
                moves = (c == 0 and self.revolute[i]) or (c == 3 and not self.revolute[i])
                joint_of.append(i if moves else -1)
        for kind, axis, c in _TOOL_STEPS[: len(_TOOL_STEPS) if self.tool_size else 0]:
            steps.append((kind, axis))
            columns.append(4 * self.n + c)
            joint_of.append(-1)
        self.steps, self.columns, self.joint_of = steps, np.array(columns), np.array(joint_of)
        rows = [3 + (9 if k == "pose" else 3 if k == "axis" else 0) for k in self.kinds]
        self.row_start = np.r_[0, np.cumsum(rows)[:-1]].astype(int)
        self.rows = int(sum(rows))
        self.penalty = 0.0  # weight of the lengths' rows (a first, short-tube stage)
        self.reserve = 0.0  # share of a revolute joint's range kept free at each end
        self.tip_reach = None  # the largest |a| of the last row (the tip from the last axis)

    def split(self, x: np.ndarray):
        n, T = self.n, self.T
        table = x[: 4 * n].reshape(n, 4)
        tool = x[4 * n : 4 * n + self.tool_size]
        Q = x[self.first_q :].reshape(T, n)
        return table, tool, Q

    def base_pose(self, x: np.ndarray) -> np.ndarray:
        """The base pose (4x4, world) of the unknowns ``x``: its origin in the region, when
        the task gives one."""
        B = self.task.base.copy()
        if self.base_size:
            B[:3, 3] = x[4 * self.n + self.tool_size : self.first_q]
        return B

    def _values(self, x: np.ndarray) -> np.ndarray:
        """(T, steps): every step's value for every target."""
        table, tool, Q = self.split(x)
        values = np.broadcast_to(x[self.columns], (self.T, len(self.steps))).copy()
        moving = np.flatnonzero(self.joint_of >= 0)
        values[:, moving] += Q[:, self.joint_of[moving]]
        return values

    def _products(self, x: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
        """(T, steps, 4, 4) the product before each step, and (T, 4, 4) the tips."""
        values = self._values(x)
        # with a region, the base's origin is the first steps (along the world's axes), then
        # comes its rotation
        G = np.broadcast_to(np.eye(4) if self.base_size else self.task.base,
                            (self.T, 4, 4)).copy()  # fmt: skip
        before = np.empty((self.T, len(self.steps), 4, 4))
        for k, (kind, axis) in enumerate(self.steps):
            if self.base_size and k == self.base_size:
                G = G @ self.task.base  # its rotation (its translation is the steps')
            before[:, k] = G
            G = G @ _elementary(kind, axis, values[:, k])
        return before, G

    def tips(self, table: np.ndarray, tool: np.ndarray, Q: np.ndarray,
             base: np.ndarray | None = None) -> np.ndarray:  # fmt: skip
        """(K, 4, 4) tip frames at the configurations Q (K, n), from ``base`` (4x4; default
        the task's)."""
        G = np.broadcast_to(self.task.base if base is None else base, (Q.shape[0], 4, 4))
        for i in range(self.n):
            th, al, a, d = table[i]
            q = Q[:, i]
            G = G @ (_dh(th + q, al, a, d) if self.revolute[i] else _dh(th, al, a, d + q))
        if self.tool_size:
            G = G @ _tool(tool)
        return G

    def errors(self, tips: np.ndarray) -> np.ndarray:
        """The targets' residuals (units of r for positions; rotation matrix entries, or the
        tip's z minus the axis)."""
        parts = []
        for k, kind in enumerate(self.kinds):
            parts.append((tips[k, :3, 3] - self.position[k]) / self.task.r)
            if kind == "pose":
                parts.append((tips[k, :3, :3] - self.rotation[k]).reshape(9))
            elif kind == "axis":
                parts.append(tips[k, :3, 2] - self.axis[k])
        return np.concatenate(parts)

    def residual(self, x: np.ndarray) -> np.ndarray:
        _, tips = self._products(x)
        e = self.errors(tips)
        if self.penalty:
            e = np.r_[e, self.penalty * self._lengths(x)]
        return e

    def _length_columns(self) -> np.ndarray:
        """The columns of x that the first stage keeps short: every row's a and d, and the
        tool's translation (which the last link has to span) when there is a tool."""
        rows = 4 * np.arange(self.n)
        tool = 4 * self.n + np.arange(3 if self.tool_size else 0)
        return np.r_[rows + 2, rows + 3, tool]

    def _lengths(self, x: np.ndarray) -> np.ndarray:
        return x[self._length_columns()] / self.task.r

    def jacobian(self, x: np.ndarray) -> np.ndarray:
        before, tips = self._products(x)
        S = len(self.steps)
        axes = np.array([axis for _, axis in self.steps])
        turns = np.array([kind == "R" for kind, _ in self.steps])
        columns = before[:, :, :3, :3].transpose(1, 3, 0, 2)  # (S, column, T, 3)
        U = columns[np.arange(S), axes].transpose(1, 0, 2)  # (T, S, 3): the steps' axes
        lever = tips[:, None, :3, 3] - before[:, :, :3, 3]
        dp = np.where(turns[None, :, None], _cross(U, lever), U)  # (T, S, 3)
        R = tips[:, None, :3, :3]  # (T, 1, 3, 3)
        dR = _cross(U[..., None], R, axis=2) * turns[None, :, None, None]  # u x each column
        J = np.zeros((self.rows, self.size))
        moving = np.flatnonzero(self.joint_of >= 0)
        first_q = self.first_q
        for t, kind in enumerate(self.kinds):
            parts = [dp[t] / self.task.r]
            if kind == "pose":
                parts.append(dR[t].reshape(S, 9))
            elif kind == "axis":
                parts.append(dR[t][:, :, 2])
            block = np.concatenate(parts, axis=1).T  # (rows of t, S)
            a = self.row_start[t]
            J[a : a + block.shape[0], self.columns] = block  # one column per step
            J[a : a + block.shape[0], first_q + t * self.n + self.joint_of[moving]] = \
                block[:, moving]  # the configuration moves this target's tip only  # fmt: skip
        if self.penalty:
            columns = self._length_columns()
            L = np.zeros((columns.size, self.size))
            L[np.arange(columns.size), columns] = self.penalty / self.task.r
            J = np.vstack([J, L])
        return J

    def bounds(self) -> tuple[np.ndarray, np.ndarray]:
        n, s = self.n, self.span
        lo = np.tile([-2 * math.pi, -2 * math.pi, -s, -s], n)
        hi = np.tile([2 * math.pi, 2 * math.pi, s, s], n)
        if self.tool_size:
            lo = np.r_[lo, [-s] * 3, [-2 * math.pi] * 3]
            hi = np.r_[hi, [s] * 3, [2 * math.pi] * 3]
        if self.tip_reach is not None:
            reach = min(s, self.tip_reach)
            lo[4 * n - 2], hi[4 * n - 2] = -reach, reach
        if self.base_size:
            region = self.task.region
            lo, hi = np.r_[lo, region.min], np.r_[hi, region.max]
        inset = np.where(self.revolute, max(1e-6, self.reserve), 1e-6) * (self.high - self.low)
        lo = np.r_[lo, np.tile(self.low + inset, self.T)]
        hi = np.r_[hi, np.tile(self.high - inset, self.T)]
        return lo, hi

    def start(self, rng: np.random.Generator) -> np.ndarray:
        n, r = self.n, self.task.r
        s = min(self.span, max(2.0 * r, 1.5 * self.task.scale / n))
        table = np.column_stack([rng.uniform(-math.pi, math.pi, n),
                                 rng.uniform(-math.pi, math.pi, n),
                                 rng.uniform(0.0, s, n), rng.uniform(-s, s, n)])  # fmt: skip
        parts = [table.reshape(-1)]
        if self.tool_size:
            parts += [rng.uniform(-r, r, 3), rng.uniform(-math.pi, math.pi, 3) * 0.5]
        if self.base_size:
            parts.append(rng.uniform(self.task.region.min, self.task.region.max))
        parts.append((self.low + (self.high - self.low) * rng.random((self.T, n))).reshape(-1))
        return np.concatenate(parts)


#: Weight of the table's lengths (over r) in the fit's first stage: it keeps the tube short; the
#: second stage, without it, makes the residual exact.
LENGTH_PENALTY = 1e-1
#: Iterations of the fit's first stage (lengths kept short) and of its exact stage.
SHORT_ITERATIONS, EXACT_ITERATIONS = 200, 300


def _fit(model: _Model, seed: int, start: int) -> np.ndarray | None:
    """The fitted unknowns of start ``start`` (every residual <= FIT_TOLERANCE), or None.

    Tried under bounds that give a better robot first (:data:`FIT_STAGES`), then wider ones
    when no exact fit is found so. Each time a first stage that also keeps the table's lengths
    small, then the exact fit from there; when that stage led where no exact fit is near (a task
    of many poses, whose joints' ranges leave a short table no room), the exact fit from the
    start itself."""
    rng = np.random.default_rng([seed, start, len(model.types), *map(ord, model.types)])
    x0 = model.start(rng)
    stages = [(reserve, None if reach is None or model.tool_size else reach * model.task.r)
              for reserve, reach in FIT_STAGES]  # fmt: skip
    with np.errstate(all="ignore"):
        for model.reserve, model.tip_reach in dict.fromkeys(stages):
            lo, hi = model.bounds()
            start_x = np.clip(x0, lo, hi)
            model.penalty = LENGTH_PENALTY
            x = _descend(model, start_x, lo, hi, SHORT_ITERATIONS, exact=False)
            model.penalty = 0.0
            x = _descend(model, x, lo, hi, EXACT_ITERATIONS, exact=True)
            if not _exact(model, x):
                x = _descend(model, start_x, lo, hi, EXACT_ITERATIONS, exact=True)
            if _exact(model, x):
                break
        else:
            x = None
    model.reserve, model.tip_reach = 0.0, None
    return x


def _exact(model: _Model, x: np.ndarray) -> bool:
    """Whether every residual of ``x`` (without the lengths' rows) is below FIT_TOLERANCE."""
    return bool(np.all(np.isfinite(x)) and np.abs(model.residual(x)).max() <= FIT_TOLERANCE)


def _descend(model: _Model, x: np.ndarray, lo: np.ndarray, hi: np.ndarray, iterations: int,
             exact: bool) -> np.ndarray:  # fmt: skip
    """Bounded Levenberg-Marquardt on ``model``'s residual from ``x``: the damped normal
    equations with Marquardt's scaling (the diagonal of J^T J, so lengths and angles need no
    units), a variable at a bound that the gradient pushes beyond held there, the step projected
    into the bounds. ``exact``: until every residual is a tenth of FIT_TOLERANCE; otherwise
    until a step lowers the cost by less than 1e-8 of it. Returns the best unknowns met.

    Written out rather than :func:`scipy.optimize.least_squares`: its trust region reflective
    method takes a singular value decomposition per iteration, which a threaded BLAS on a
    loaded two-core machine made 10 to 30 times slower (3 to 22 s a fit, 0.6 s on one thread);
    a 66-unknown normal equation is solved in a fifth of a millisecond either way."""
    e = model.residual(x)
    cost = float(e @ e)
    damping = 1e-3
    span = hi - lo
    for _ in range(iterations):
        if not np.isfinite(cost) or (exact and np.abs(e).max() <= 0.1 * FIT_TOLERANCE):
            break
        J = model.jacobian(x)
        g = J.T @ e
        free = ~(((x <= lo + 1e-12 * span) & (g > 0)) | ((x >= hi - 1e-12 * span) & (g < 0)))
        Jf = J[:, free]
        H = Jf.T @ Jf
        scale = np.diagonal(H).copy()
        scale = np.maximum(scale, 1e-12 * max(float(scale.max(initial=0.0)), 1.0))
        moved = False
        while damping < 1e12:
            try:
                step = np.linalg.solve(H + damping * np.diag(scale), -g[free])
            except np.linalg.LinAlgError:
                damping *= 4.0
                continue
            trial = x.copy()
            trial[free] += step
            trial = np.clip(trial, lo, hi)
            trial_e = model.residual(trial)
            trial_cost = float(trial_e @ trial_e)
            if np.isfinite(trial_cost) and trial_cost < cost:
                drop = (cost - trial_cost) / cost
                x, e, cost = trial, trial_e, trial_cost
                damping = max(damping / 3.0, 1e-12)
                moved = True
                break
            damping *= 4.0
        if not moved or (not exact and drop < 1e-8):
            break
    return x


# --- building and checking a fitted table ---------------------------------------------------------
#: The length of a designed chain's end tip, in units of r.
END_TIP_LENGTH_R = 1.5


def _end_tips(model: _Model, tip: np.ndarray) -> list:
    """End tips (END_TIP_LENGTH_R r long) whose distal frame is ``tip`` (4x4), to try in turn:
    a position task's tip frame may also turn about its point (:data:`TIP_TURNS`)."""
    from kinegami.optimize.compaction import TIP_TURNS, end_tips_at

    turns = (np.eye(3),) if model.tool_size else TIP_TURNS
    return end_tips_at(tip, model.task.numSides, model.task.r, END_TIP_LENGTH_R * model.task.r,
                       turns)  # fmt: skip


def _model_joints(model: _Model, x: np.ndarray) -> tuple[list, np.ndarray]:
    """The joints of the fitted unknowns ``x`` on their DH axes (world frame), and the tip frame
    (4x4) the table and the tool put the tip on."""
    task = model.task
    table, tool, _ = model.split(x)
    frames = [model.base_pose(x)]
    for i in range(model.n):
        th, al, a, d = table[i]
        frames.append(frames[-1] @ _dh(th, al, a, d))
    tip = frames[-1] @ (_tool(tool) if model.tool_size else np.eye(4))
    joints = [_joint(task, kind).with_pose(frames[i]) for i, kind in enumerate(model.types)]
    return joints, tip


def _joint(task: _Task, kind: str):
    """A joint of the task's tube at the identity: "R" revolute (turning pi), "P" prismatic."""
    from kinegami.chain.joints import PrismaticJoint, RevoluteJoint

    if kind == "R":
        return RevoluteJoint(task.numSides, task.r, math.pi, np.eye(4))
    return PrismaticJoint(task.numSides, task.r, 3.0 * task.r, 3, math.pi / 4, np.eye(4))


def _build(model: _Model, x: np.ndarray):
    """The chain of the fitted unknowns ``x`` (joints slid along their axes by placement, the end
    tip exactly at the table's tip), with its states per target (full configurations), or
    (None, reason)."""
    from kinegami.chain.model import KinematicChain
    from kinegami.errors import ClearanceWarning, NoPathError, PlacementWarning

    task, n = model.task, model.n
    _, _, Q = model.split(x)
    joints, tip = _model_joints(model, x)
    reason = "no link reaches the end tip"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlacementWarning)
        warnings.simplefilter("ignore", ClearanceWarning)
        try:
            chain = KinematicChain(joints[0])
        except (NoPathError, InvalidParameterError) as exc:
            return None, str(exc)
        chain.margin = task.margin
        for joint in joints[1:]:
            index = chain.append(joint, relative=False, safe=False, fixedOrientation=True)
            if index is None:
                index = chain.append(joint, relative=False, safe=True)
            if index is None:
                return None, "a joint could not be placed"
        for end in _end_tips(model, tip):
            if chain.append(end, relative=False, safe=False, fixedPosition=True,
                            fixedOrientation=True) is not None:  # fmt: skip
                break
        else:
            return None, reason
    movable = [k for k, joint in enumerate(chain.Joints) if joint.stateRange() != (0.0, 0.0)]
    if len(movable) != n:  # pragma: no cover - placement adds waypoints and the tip only
        return None, "placement changed the joints"
    states = np.zeros((model.T, len(chain.Joints)))
    states[:, movable] = Q
    return (chain, states), ""


def _answers(chain, states: np.ndarray, task: _Task) -> tuple[list | None, str]:
    """One reach answer per target on the built chain, each exact, in range, clear with the
    margin and outside every box (solved again from the fit's states, then from other seeds),
    or (None, why)."""
    from kinegami.optimize.compaction import reach_clear

    answers = []
    for k, target in enumerate(task.targets):
        answer, why = reach_clear(chain, target, states[k], 4, task.margin, task.boxes)
        if answer is None:
            return None, f"target {k}: {why}"
        answers.append(answer)
    return answers, ""


def _attempt(task: _Task, types: str, seed: int, start: int, thorough: bool = True,
             fitted: np.ndarray | None = None, repair: bool = True) -> tuple:  # fmt: skip
    """One start: ((table unknowns, tube length, smallest clearance, chain, answers), "", x) of
    a design that reaches every target (answers: one reach answer per target), or (None,
    why, x): x the fitted unknowns (None when the fit failed), which a thorough attempt of the
    same start takes as ``fitted``. Not ``thorough``: only when the fit's own configurations
    are clear and outside the boxes (one batch of the clearance engine, about a millisecond);
    ``thorough``: the placement is searched again so that the fitted configurations are clear
    (``repair``: :func:`_repaired`, a few seconds), then other configurations of the same table
    for the targets whose fitted one is not (about a second), and the placement again for
    those. Without ``repair`` (a tree's leaves, which the tree builds again from x) the chain is
    the one :func:`_build` makes of x."""
    from kinegami.clearance.engine import engine_for
    from kinegami.optimize.compaction import tube_length

    model = _Model(task, types)
    x = _fit(model, seed, start) if fitted is None else fitted
    if x is None:
        return None, "the fit did not reach every target", None
    fitted = x
    built, why = _build(model, x)
    if built is None:
        return None, why, fitted
    chain, states = built
    length = tube_length(chain)
    if length > task.max_tube_length:
        return None, f"tube {length:.6g} longer than max_tube_length", fitted
    engine = engine_for(chain)
    bad = _blocked(engine, chain, states, task)
    if bad and not thorough:
        k, why = bad[0]
        return None, f"target {k}: the fitted configuration {why}", fitted
    if bad and repair:
        found = _repaired(chain, states, task, seed + start)
        if found is not None:
            return (x, *found), "", fitted
    if bad:  # other configurations of the same table for those targets, a batch at a time
        movable = [m for m, joint in enumerate(chain.Joints) if joint.stateRange() != (0.0, 0.0)]
        rng = np.random.default_rng([seed, start, 0x0C0F])
        first_q = model.first_q
        blocked = []  # the targets with no clear configuration on this placement
        for k, _ in bad:
            nearest = None  # (clearance, configuration) of the least overlapping one found
            for count in OTHER_CONFIGURATIONS:  # more starts only when none is clear
                found = _other_configurations(model, x, k, count, rng)
                trial = np.zeros((len(found), states.shape[1]))
                trial[:, movable] = np.reshape(found, (len(found), model.n))
                worst = engine.worst_arrays(trial, task.margin)[0]
                clear = [
                    m
                    for m in np.flatnonzero(~np.isfinite(worst))
                    if keep_out_violation(chain, trial[m], task.boxes, task.margin) is None
                ]
                if clear:
                    states[k] = trial[clear[0]]
                    x = x.copy()
                    x[first_q + k * model.n : first_q + (k + 1) * model.n] = found[clear[0]]
                    break
                if len(found) and (nearest is None or worst.max() > nearest[0]):
                    nearest = (float(worst.max()), trial[int(np.argmax(worst))])
            else:
                blocked.append(k)
                if nearest is not None:
                    states[k] = nearest[1]
        if blocked and repair:  # the placement again, for the least overlapping ones
            found = _repaired(chain, states, task, seed + start)
            if found is not None:
                return (x, *found), "", fitted
        if blocked:
            # the solver's escapes along a redundant arm's solutions rarely find what these
            # starts did not (1 of 14 thorough attempts of a benchmark task, at 1-12 s each)
            k = blocked[0]
            return None, f"target {k}: every configuration found {dict(bad)[k]}", fitted
    answers, why = _answers(chain, states, task)
    if answers is None:
        return None, why, fitted
    if task.path:
        paths, why = _paths(chain, answers, task)
        if paths is None:
            return None, why, fitted
    return (x, length, min(a.clearance for a in answers), chain, answers), "", fitted


#: Starts of the compaction search that places a fitted table again so that its
#: configurations at the targets are clear (:func:`_repaired`).
REPAIR_STARTS = 2


def _repaired(chain, states: np.ndarray, task: _Task, seed: int) -> tuple | None:
    """(tube length, smallest clearance, chain, answers) of the same kinematics placed again so
    that every target's configuration in ``states`` (full configurations, one per target) is
    clear with the margin and outside the boxes, or None.

    A 6R arm at an exact pose has no freedom left to move away from itself, and placing each
    joint compactly puts elbows beside the joints, which a large turn folds into each other:
    compaction that keeps the task (:func:`kinegami.optimize.compact_for_task`, its search
    banning the placements that collide at these configurations; the tip's frame stays on the
    last movable joint's body) slides and rolls the joints along their axes until none does,
    and solves every target again from these states on the result (exact, in range, clear,
    outside the boxes; a design whose folded form needs the isometry repair passed over)."""
    from kinegami.optimize.compaction import compact_for_task, tube_length
    from kinegami.reach import Answer

    # the states to start from, in the form compaction takes a task's answers in: they pass
    # through the chain itself (or enter a box), which the search is to undo
    starts = [Answer(False, tuple(q), 0.0, 0.0, -math.inf, "", 0, 0,
                     "the fitted configuration passes through itself") for q in states]  # fmt: skip
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        shorter, answers = compact_for_task(
            chain, list(task.targets), starts, keep_out=task.boxes, margin=task.margin,
            seed=seed, executor=pool, starts=REPAIR_STARTS, exact_fold=True)  # fmt: skip
    if shorter is chain:
        return None
    if task.path and _paths(shorter, answers, task)[0] is None:
        return None
    return tube_length(shorter), min(a.clearance for a in answers), shorter, answers


def _fold_refusal(chain) -> str:
    """Why a designed chain is refused for its folded form: its crease pattern folds only
    after the isometry repair moves vertices (a nearly degenerate module, whose folded form is
    not the one its creases give exactly; gallery designs may not need it); "" when it folds
    exactly."""
    from kinegami.optimize.compaction import repaired_vertices

    count = repaired_vertices(chain)
    if not count:
        return ""
    return (f"the design's folded form needs the isometry repair for {count} vertices (a "
            "nearly degenerate module)")  # fmt: skip


def _paths(chain, answers, task: _Task) -> tuple[list | None, str]:
    """The certified straight joint-space moves from each target's answer to the next
    (:func:`kinegami.clearance.paths.check_path`), as their measured configurations, or
    (None, why)."""
    from kinegami.clearance.paths import check_path

    out = []
    for k in range(len(answers) - 1):
        found = check_path(chain, answers[k].states, answers[k + 1].states, task.margin)
        if not found.ok:
            return None, f"the move from target {k} to target {k + 1}: {found.reason}"
        out.append(found.configurations)
    return out, ""


#: Starts of the fit of one target's configuration alone (the table kept) when the fitted one
#: passes through itself or enters a box (a 6R arm has up to 16 configurations per pose), then
#: more when none of those is clear.
OTHER_CONFIGURATIONS = (24, 96)


def _blocked(engine, chain, states: np.ndarray, task: _Task) -> list[tuple[int, str]]:
    """The targets whose configuration passes through itself or enters a box, and why."""
    out = [(int(k), "passes through itself")
           for k in np.flatnonzero(engine.colliding(states, task.margin))]  # fmt: skip
    colliding = {k for k, _ in out}
    for k in range(len(states)):
        if k not in colliding:
            box = keep_out_violation(chain, states[k], task.boxes, task.margin)
            if box is not None:
                out.append((k, f"enters keep-out box {box[0]}"))
    return sorted(out)


def _other_configurations(model: _Model, x: np.ndarray, k: int, count: int,
                          rng: np.random.Generator) -> list[np.ndarray]:  # fmt: skip
    """Configurations (movable joints) of the fitted table that put the tip exactly on target
    ``k``, from ``count`` random starts (duplicates dropped): a Levenberg-Marquardt iteration
    run on every start at once (one model of ``count`` copies of the target), each start's
    damping adapted on its own, steps projected into the joints' ranges."""
    n = model.n
    sub = _Model(replace(model.task, targets=(model.task.targets[k],) * count), model.types)
    fixed = x[: model.first_q]
    rows = sub.rows // count
    inset = 1e-6 * (model.high - model.low)
    lo, hi = model.low + inset, model.high - inset
    columns = model.first_q + np.arange(count)[:, None] * n + np.arange(n)[None, :]
    starts, lines = np.arange(count)[:, None, None], np.arange(rows)[None, :, None]

    def errors(Q: np.ndarray) -> np.ndarray:
        return sub.residual(np.r_[fixed, Q.reshape(-1)]).reshape(count, rows)

    Q = lo + (hi - lo) * rng.random((count, n))
    damping = np.full(count, 1e-3)
    e = errors(Q)
    cost = (e * e).sum(axis=1)
    with np.errstate(all="ignore"):
        for _ in range(OTHER_ITERATIONS):
            if np.abs(e).max() <= 0.1 * FIT_TOLERANCE:
                break
            J = sub.jacobian(np.r_[fixed, Q.reshape(-1)]).reshape(count, rows, -1)
            J = J[starts, lines, columns[:, None, :]]  # (count, rows, n): each start's own
            H = J.transpose(0, 2, 1) @ J
            g = (J.transpose(0, 2, 1) @ e[:, :, None])[:, :, 0]
            scale = np.diagonal(H, axis1=1, axis2=2) + 1e-12
            A = H + damping[:, None, None] * (scale[:, :, None] * np.eye(n))
            step = np.linalg.solve(A, -g[:, :, None])[:, :, 0]
            trial = np.clip(Q + step, lo, hi)
            trial_e = errors(trial)
            trial_cost = (trial_e * trial_e).sum(axis=1)
            better = np.isfinite(trial_cost) & (trial_cost < cost)
            Q[better], e[better], cost[better] = trial[better], trial_e[better], trial_cost[better]
            damping = np.where(better, np.maximum(damping / 3.0, 1e-12),
                               np.minimum(damping * 4.0, 1e12))  # fmt: skip
    found: list[np.ndarray] = []
    for q, err in zip(Q, e, strict=True):
        if np.abs(err).max() <= FIT_TOLERANCE and \
                all(np.abs(q - other).max() > 1e-6 for other in found):  # fmt: skip
            found.append(q.copy())
    return found


#: Iterations of the batched Levenberg-Marquardt search for other configurations.
OTHER_ITERATIONS = 100


# --- the search -----------------------------------------------------------------------------------
def design_for(
    targets,
    joints,
    *,
    r: float,
    numSides: int,
    seed: int = 0,
    executor: concurrent.futures.Executor | None = None,
    base=None,
    base_region=None,
    keep_out=(),
    max_tube_length: float | None = None,
    margin: float = 0.0,
    starts: int = STARTS,
    compact: bool = True,
    path: bool = False,
    return_answers: bool = False,
    progress=None,
):
    """A :class:`~kinegami.KinematicChain` whose tip (its end tip's distal frame) reaches every
    target exactly (1e-9 r, 1e-9 rad), in range, without passing through itself
    (docs/design-for-a-task.md).

    Parameters
    ----------
    targets : sequence of targets, each a position (3 numbers), a pose (4x4 or SE3) or a
        :class:`kinegami.reach.Target` (a position with an axis); world frame, units of r.
    joints : str or int
        The joint types in order (``"RRRR"``, ``"RPRR"``; the end tip and any waypoints are
        added by placement), or a budget: at most that many joints of any type, tried from the
        fewest up. A list of strings, one per leaf, designs a
        :class:`~kinegami.KinematicTree` instead: ``targets`` is then one list of targets per
        leaf, all of the same length, and the k-th targets of every leaf are reached at once
        (a grasp); the root is a start tip at ``base`` and each leaf's first joint sits on a
        ring 4 r above it (docs/design-for-a-task.md, Trees).
    r, numSides : the tube.
    seed : the search's seed (the answer depends only on it, not on the executor).
    executor : runs the starts of each round (any ``concurrent.futures.Executor``; default: in
        this process).
    base : the root joint's pose (4x4 or SE3; default the identity): the first joint turns or
        slides along its z axis.
    base_region : a box (``{"min": [x, y, z], "max": [x, y, z]}`` or :class:`Box`, world)
        where the base's origin may be instead (chains): its position is fitted too, its
        orientation is ``base``'s. (Placement may then slide the root joint along that axis,
        as for a fixed base.)
    keep_out : boxes (``{"min": [x, y, z], "max": [x, y, z]}`` or :class:`Box`) that no part
        may come within ``margin`` of at any target's configuration.
    max_tube_length : the longest tube allowed (default 100 r).
    margin : the clearance required between parts and from the boxes (>= 0).
    starts : the fit's starts per joint-type string (>= 1).
    compact : shorten the found design by compaction that keeps the task
        (:func:`kinegami.optimize.compact_for_task`; a tree keeps every grasp, its root and
        leaf tips where they are and its junction sockets fitted).
    path : (chains) also require that the robot moves from each target's configuration to the
        next along the straight line in joint space without passing through itself (certified
        by :func:`kinegami.clearance.paths.check_path`).
    return_answers : return ``(design, answers)``: one reach answer per target (a tree: per
        target index, every leaf at once); with ``path``,
        ``(design, answers, paths)``, each path the configurations (m, joints) measured along a
        move, from one target's states to the next's.
    progress : ``progress(done, total)`` per start (False from it cancels), True for a bar.

    Among designs that reach every target: fewer joints first, then a shorter tube, then a
    larger smallest clearance over the targets' configurations. A chain whose folded form needs
    the isometry repair (:func:`kinegami.optimize.compaction.repaired_vertices` above 0: a
    nearly degenerate module) is skipped for the next best one, and compaction passes over such
    designs too (``exact_fold``); a tree's sheets are not checked.

    Raises
    ------
    InfeasibleTaskError
        ``proven`` True: a bound shows no design of the budget reaches a target (which one and
        why); ``proven`` False: the search found none in its starts (the last reason given).

    Examples
    --------
    >>> from kinegami.reach import solve
    >>> points = [(6, 2, 3), (3, 5, 4), (-2, 4, 6)]
    >>> arm = design_for(points, "RRR", r=1, numSides=4)
    >>> all(solve(arm, p).ok for p in points)
    True
    """
    from kinegami.optimize.compaction import tube_length

    if not isinstance(path, bool):
        raise InvalidTypeError(f"path must be True or False, got {path!r}")
    seed = check_int("seed", seed, minimum=0, floats=False)
    starts = check_int("starts", starts, minimum=1, floats=False)
    if starts > 10_000:
        raise InvalidParameterError(f"starts must be at most 10000, got {starts}")
    progress = check_progress(progress)
    if executor is not None and not isinstance(executor, concurrent.futures.Executor):
        raise InvalidTypeError(
            f"executor must be a concurrent.futures.Executor, got {type(executor).__name__}"
        )
    if isinstance(joints, (list, tuple)):  # a tree: one joint string and target list per leaf
        if path:
            raise InvalidParameterError("path=True is for chains; a tree task gives poses only")
        if base_region is not None:
            raise InvalidParameterError("base_region is for chains; a tree's root is at base")
        leaves, rooted, strings = _tree_tasks(targets, joints, r, numSides, base, keep_out,
                                              max_tube_length, margin)  # fmt: skip
        return _design_tree(leaves, rooted, strings, seed, starts, executor, progress,
                            return_answers, compact)  # fmt: skip
    task = _task(targets, r, numSides, base, keep_out, max_tube_length, margin, base_region)
    task = replace(task, path=path)
    strings = _joint_strings(joints)
    certificates = [task_certificate(task, types) for types in strings]
    if all(c is not None for c in certificates):
        k, why = certificates[-1] if len(strings) > 1 else certificates[0]
        raise InfeasibleTaskError(f"no design of {_budget(joints)} can reach every target: {why}",
                                  target=k, proven=True)  # fmt: skip
    last = ""
    found = None
    live = [types for types, c in zip(strings, certificates, strict=True) if c is None]
    with Progress(progress, starts * len(live), desc="design", unit="start") as bar:
        for types in live:
            best = None
            for first in range(0, starts, ROUND):
                batch = range(first, min(starts, first + ROUND))
                # first the fits whose own configurations are clear: the best of them (a
                # shorter tube, then a larger clearance); one whose folded form needs the
                # isometry repair is refused and the next one tried
                results = _run(executor, task, types, seed, batch, False)
                passed = []
                for result, why, _ in results:
                    if result is None:
                        last = why
                        continue
                    passed.append(result)
                for result in sorted(passed, key=lambda res: (res[1], -res[2])):
                    why = _fold_refusal(result[3])
                    if why:
                        last = why
                        continue
                    best = result
                    break
                if best is None:
                    # when none is, the same fits placed again and their other
                    # configurations: the first start in order that gives a design
                    again = [(k, x) for k, (_, why, x) in zip(batch, results, strict=True)
                             if "fitted configuration" in why]  # fmt: skip
                    best, why = _first_design(executor, task, types, seed, again)
                    last = why or last
                bar.update(len(batch))
                if best is not None:
                    bar.update(starts - batch.stop)
                    break
            if best is not None:
                found = (types, best)
                break
    if found is None:
        raise InfeasibleTaskError(
            f"no design of {_budget(joints)} found that reaches every target in {starts} "
            f"start(s) per joint string (not proven impossible; last: {last}); try more starts, "
            "another seed, more joints or a longer max_tube_length", target=_named(last),
            proven=False,
        )  # fmt: skip
    _, (_, _, _, chain, answers) = found
    if compact:
        from kinegami.optimize.compaction import compact_for_task

        with concurrent.futures.ThreadPoolExecutor(1) as own:
            shorter, shorter_answers = compact_for_task(
                chain, list(task.targets), answers, keep_out=task.boxes, margin=task.margin,
                seed=seed, executor=executor or own, exact_fold=True)  # fmt: skip
        if tube_length(shorter) <= tube_length(chain) and \
                (not path or _paths(shorter, shorter_answers, task)[0] is not None):  # fmt: skip
            chain, answers = shorter, shorter_answers
    if not return_answers:
        return chain
    if path:
        return chain, answers, _paths(chain, answers, task)[0]
    return chain, answers


def _run(executor, task: _Task, types: str, seed: int, starts, thorough: bool,
         fitted=None, repair: bool = True) -> list:  # fmt: skip
    """The attempts of ``starts``, in order (on ``executor`` when given); ``fitted``: each
    start's fitted unknowns from a first attempt; ``repair`` as :func:`_attempt`'s."""
    fitted = [None] * len(starts) if fitted is None else fitted
    if executor is None:
        return [_attempt(task, types, seed, k, thorough, x, repair)
                for k, x in zip(starts, fitted, strict=True)]  # fmt: skip
    futures = [executor.submit(_attempt, task, types, seed, k, thorough, x, repair)
               for k, x in zip(starts, fitted, strict=True)]  # fmt: skip
    return [future.result() for future in futures]


def _first_design(executor, task: _Task, types: str, seed: int, fitted: list) -> tuple:
    """(result, "") of the first of the thorough attempts of ``fitted`` ((start, fitted
    unknowns) in order) that gives a design whose folded form needs no isometry repair, or
    (None, the last reason). With an executor every attempt is submitted at once and the ones
    after the first design are cancelled (those not yet running); the design is the same as
    without one."""
    last = ""
    if executor is None:
        attempts = (_attempt(task, types, seed, k, True, x) for k, x in fitted)
    else:
        futures = [executor.submit(_attempt, task, types, seed, k, True, x) for k, x in fitted]
        attempts = (future.result() for future in futures)
    try:
        for result, why, _ in attempts:
            if result is None:
                last = why
                continue
            why = _fold_refusal(result[3])
            if why:
                last = why
                continue
            return result, ""
    finally:
        if executor is not None:
            for future in futures:
                future.cancel()
    return None, last


def _budget(joints) -> str:
    return f"joints {joints!r}" if isinstance(joints, str) else f"at most {joints} joint(s)"


def _named(why: str) -> int | None:
    if why.startswith("target "):
        head = why.split(":")[0].split()
        if len(head) == 2 and head[1].isdigit():
            return int(head[1])
    return None


# --- trees: one target set per leaf ---------------------------------------------------------------
#: A tree task's leaves start on a ring around the root's z axis: each leaf's first joint sits
#: this many r above the root, at least LEAF_RING_R r from the axis (farther for many leaves, so
#: that neighbours stay 4 r apart); its axis is the root's z.
LEAF_HEIGHT_R = 4.0
LEAF_RING_R = 3.0
#: Combinations of the leaves' fits built and checked per round (shortest first).
TREE_COMBINATIONS = 16


def _leaf_bases(base: np.ndarray, centres: np.ndarray, r: float) -> list[np.ndarray]:
    """The frame (4x4, world) of each leaf's first joint: on the ring above the root, the leaves
    in the order of the directions (about the root's z) of their targets' centres (``centres``
    (leaves, 3), world), the first leaf's slot towards its centre."""
    count = len(centres)
    ring = 0.0 if count == 1 else max(LEAF_RING_R, 2.0 / math.sin(math.pi / count)) * r
    local = (centres - base[:3, 3]) @ base[:3, :3]  # in the root's frame
    directions = np.arctan2(local[:, 1], local[:, 0])
    order = np.argsort(directions, kind="stable")
    out = [None] * count
    for slot, i in enumerate(order):
        angle = float(directions[order[0]]) + 2.0 * math.pi * slot / count
        M = np.eye(4)
        M[:3, 3] = [ring * math.cos(angle), ring * math.sin(angle), LEAF_HEIGHT_R * r]
        out[i] = base @ M
    return out


def _tree_tasks(targets, joints, r, numSides, base, keep_out, max_tube_length, margin):
    """(leaf tasks with their ring bases, leaf tasks with the root's base (for certificates),
    joint strings): one per leaf, each leaf's targets in order; the k-th targets of all leaves
    are reached at once."""
    strings = []
    for i, types in enumerate(joints):
        if not isinstance(types, str):
            raise InvalidTypeError(
                f"joints[{i}] must be a string of 'R' and 'P' (a tree task gives one joint "
                f"string per leaf), got {types!r}"
            )
        strings.append(_joint_strings(types)[0])
    if not strings:
        raise InvalidParameterError("a tree task needs at least one leaf: joints is empty")
    if isinstance(targets, (str, bytes)) or not isinstance(targets, Sequence) \
            or len(targets) != len(strings):  # fmt: skip
        raise InvalidParameterError(
            f"a tree task (joints given per leaf: {len(strings)} leaves) needs one list of "
            f"targets per leaf, got {targets!r}"
        )
    counts = {len(leaf) if isinstance(leaf, Sequence) else -1 for leaf in targets}
    if len(counts) != 1:
        raise InvalidParameterError(
            "every leaf of a tree task needs the same number of targets (the k-th target of "
            f"every leaf is reached at once), got {[len(leaf) for leaf in targets]}"
        )
    root = _task(targets[0], r, numSides, base, keep_out, max_tube_length, margin)
    if sum(len(leaf) for leaf in targets) > MAX_TASK_TARGETS:
        raise InvalidParameterError(
            f"a task may name at most {MAX_TASK_TARGETS} targets (MAX_TASK_TARGETS), got "
            f"{sum(len(leaf) for leaf in targets)}"
        )
    rooted = [_task(leaf, r, numSides, root.base, keep_out, max_tube_length, margin)
              for leaf in targets]  # fmt: skip
    centres = np.array([np.mean([t.position for t in task.targets], axis=0) for task in rooted])
    bases = _leaf_bases(root.base, centres, root.r)
    placed = [replace(task, base=bases[i]) for i, task in enumerate(rooted)]
    return placed, rooted, strings


def _tree_search(leaves: list, strings: list[str], root: np.ndarray, seed: int, starts: int,
                 executor, bar) -> tuple:  # fmt: skip
    """((tree, answers, states), "") of the shortest tree found in the first round that gives
    one, or (None, last reason)."""
    last = "the fit did not reach every target"
    models = [_Model(task, types) for task, types in zip(leaves, strings, strict=True)]
    found = [[] for _ in models]  # per leaf: (unknowns, tube length) of clear leaf chains
    tried: set[tuple] = set()  # combinations of the leaves' designs already checked
    for first in range(0, starts, ROUND):
        batch = range(first, min(starts, first + ROUND))
        for i, (task, types) in enumerate(zip(leaves, strings, strict=True)):
            # each leaf alone, as a chain from its ring frame: first the fits whose own
            # configurations are clear, then other configurations of the same fits
            results = _run(executor, task, types, seed + 7919 * i, batch, False, repair=False)
            if all(result is None for result, _, _ in results):
                again = [(k, x) for k, (_, why, x) in zip(batch, results, strict=True)
                         if "fitted configuration" in why]  # fmt: skip
                results += _run(executor, task, types, seed + 7919 * i, [k for k, _ in again],
                                True, [x for _, x in again], repair=False)  # fmt: skip
            for result, why, _ in results:
                if result is None:
                    last = f"leaf {i}: {why}"
                else:
                    found[i].append(result[:2])
        bar.update(len(batch))
        if not all(found):
            continue
        sizes = [[length for _, length in leaf] for leaf in found]
        found_x = [[x for x, _ in leaf] for leaf in found]
        combos = sorted(itertools.product(*[range(len(f)) for f in found]),
                        key=lambda c: (sum(sizes[i][j] for i, j in enumerate(c)), c))  # fmt: skip
        best = None
        for combo in [c for c in combos if c not in tried][:TREE_COMBINATIONS]:
            tried.add(combo)
            xs = [found_x[i][j] for i, j in enumerate(combo)]
            result, why = _check_tree(models, xs, root)
            if result is None:
                last = why
                continue
            from kinegami.optimize.compaction import tube_length

            key = (tube_length(result[0]), -min(a.clearance for a in result[1]))
            if best is None or key < best[0]:
                best = (key, result)
        if best is not None:
            bar.update(starts - batch.stop)  # the progress is complete
            return best[1], ""
    return None, last


def _check_tree(models: list, xs: list, root: np.ndarray) -> tuple:
    """The tree of the leaves' fitted unknowns ``xs`` and one reach answer per target index
    (every leaf at its k-th target at once, exact, in range, clear, outside the boxes), or
    (None, why). ``root``: the root start tip's pose (the task's base)."""
    from kinegami.chain.joints import StartTip
    from kinegami.errors import ClearanceWarning, NoPathError, PlacementWarning
    from kinegami.fabrication.sheets import fit_junctions
    from kinegami.optimize.compaction import reach_clear, tube_length
    from kinegami.tree.model import KinematicTree

    task = models[0].task
    r, margin = task.r, task.margin
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlacementWarning)
        warnings.simplefilter("ignore", ClearanceWarning)
        try:
            tree = KinematicTree(StartTip(task.numSides, r, np.eye(4), r).with_pose(root))
        except (NoPathError, InvalidParameterError) as exc:
            return None, str(exc)
        tree.margin = margin
        tips = []
        for model, x in zip(models, xs, strict=True):
            joints, tip = _model_joints(model, x)
            parent = 0
            for joint in joints:  # exactly on the fit's frame when a link reaches it
                index = tree.addJoint(parent, joint, relative=False, safe=False,
                                      fixedPosition=True, fixedOrientation=True)  # fmt: skip
                if index is None:
                    index = tree.addJoint(parent, joint, relative=False, safe=False,
                                          fixedOrientation=True)  # fmt: skip
                if index is None:
                    index = tree.addJoint(parent, joint, relative=False, safe=True)
                if index is None:
                    return None, "a joint could not be placed"
                parent = index
            for end in _end_tips(model, tip):
                index = tree.addJoint(parent, end, relative=False, safe=False,
                                      fixedPosition=True, fixedOrientation=True)  # fmt: skip
                if index is not None:
                    break
            else:
                return None, "no link reaches a leaf's end tip"
            tips.append(index)
    # the junctions' sockets need room on their links: the slides kinegami build would make
    # (along the joints' own axes: the kinematics stay) are made here, so the tree returned is
    # the one that is cut
    try:
        fitted, slides = fit_junctions(tree)
    except KinegamiError as exc:
        return None, f"a junction does not fit: {exc}"
    if slides:
        tree = fitted
    if tube_length(tree) > task.max_tube_length:
        return None, f"tube {tube_length(tree):.6g} longer than max_tube_length"
    parents = tree.Parents
    Q = np.zeros((models[0].T, len(tree.Joints)))
    for model, x, tip in zip(models, xs, tips, strict=True):
        path, joint = [], tip
        while joint != 0:  # the leaf's movable joints, root to tip
            joint = parents[joint]
            if tree.Joints[joint].stateRange() != (0.0, 0.0):
                path.append(joint)
        Q[:, path[::-1]] = model.split(x)[2]
    answers = []
    for k in range(models[0].T):
        mapping = {tip: model.task.targets[k] for model, tip in zip(models, tips, strict=True)}
        answer, why = reach_clear(tree, mapping, Q[k], 2, margin, task.boxes)
        if answer is None:
            return None, f"target {k}: {why}"
        answers.append(answer)
    return (tree, answers, Q), ""


def _design_tree(leaves: list, rooted: list, strings: list[str], seed: int, starts: int,
                 executor, progress, return_answers: bool, compact: bool):  # fmt: skip
    """:func:`design_for` of a tree task (checked leaf tasks); ``compact``: the tree found
    compacted with its task kept (:func:`kinegami.optimize.compact_for_task`)."""
    for i, (task, types) in enumerate(zip(rooted, strings, strict=True)):
        certificate = task_certificate(task, types)
        if certificate is not None:
            k, why = certificate
            raise InfeasibleTaskError(
                f"no design with joints {types!r} on leaf {i} can reach every target of that "
                f"leaf: {why}", target=k, proven=True,
            )  # fmt: skip
    with Progress(progress, starts, desc="design", unit="start") as bar:
        found, last = _tree_search(leaves, strings, rooted[0].base, seed, starts, executor, bar)
    if found is None:
        raise InfeasibleTaskError(
            f"no tree with joints {strings!r} found that reaches every leaf's targets in "
            f"{starts} start(s) (not proven impossible; last: {last}); try more starts, another "
            "seed, more joints or a longer max_tube_length", target=_named(last), proven=False,
        )  # fmt: skip
    tree, answers, _ = found
    if compact:
        from kinegami.optimize.compaction import compact_for_task, tube_length

        task = leaves[0]
        with concurrent.futures.ThreadPoolExecutor(1) as own:
            shorter, shorter_answers = compact_for_task(
                tree, [list(leaf.targets) for leaf in leaves], answers, keep_out=task.boxes,
                margin=task.margin, seed=seed, executor=executor or own)  # fmt: skip
        if tube_length(shorter) <= tube_length(tree):
            tree, answers = shorter, shorter_answers
    return (tree, answers) if return_answers else tree
