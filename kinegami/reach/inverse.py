"""Inverse kinematics that answers only with configurations in which the design does not pass
through itself (docs/reach.md).

:func:`solve` finds states that put a design's tip (or, for a tree, several tips at once) on a
target: a pose, a position, or a position with the direction of the tip's z axis. Damped least
squares (Levenberg-Marquardt) on the compiled kinematics (:mod:`kinegami.reach.forward`), the
residual in units of r and radians, every iterate projected onto the joints' ranges, several
starts iterated together (one numpy step for all), further starts when one stalls or its
answer passes through itself. An answer is ``ok`` only when it is exact (within ``tol``), in
range and clear by the design's own clearance engine. :func:`solve_many` solves a list of
targets, all starts of all targets in one batch, and spreads chunks over any
``concurrent.futures.Executor``.
"""

from __future__ import annotations

import math
import weakref
from collections.abc import Mapping, Sequence
from dataclasses import dataclass, field

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.reach.forward import Kinematics, kinematics

__all__ = ["Answer", "Target", "solve", "solve_many"]

#: Starts iterated together for one target (the first: q0 or the design's states).
STARTS = 8
#: Most starts tried for one target before it is given up.
MAX_STARTS = 64
#: Iterations of one start before it counts as stalled.
ITERATIONS = 200
#: Damping: first value, bounds (in units of the residual squared).
DAMPING, DAMPING_MIN, DAMPING_MAX = 1e-3, 1e-12, 1e8
#: Configurations of the seed table (per design, tips and seed), and how many of the nearest
#: to a target are tried after its first start, before random ones.
SEED_TABLE, SEEDED_STARTS = 8192, 63
#: Restarts taken from the seed table before random starts take every other turn: the
#: table's nearest configurations can all lie in one basin that a joint limit closes (the
#: PUMA's target 1137 of benchmarks/reach_success.py: its 63 nearest all stop at limits, 15%
#: of random starts reach it).
TABLE_FIRST = 8
#: The seed table's configurations nearest a target asked for at first (then four times as
#: many at a time).
FIRST_ROWS = 16


@dataclass(frozen=True, eq=False)
class Target:
    """Where a tip should be (the design's length units, world frame).

    Attributes
    ----------
    position : (3,) array
    axis : (3,) unit array or None
        The direction the tip's z axis must point along (rotation about it free).
    rotation : (3, 3) array or None
        The tip's orientation (a pose target); then ``axis`` is None.
    """

    position: np.ndarray
    axis: np.ndarray | None = None
    rotation: np.ndarray | None = None

    def __post_init__(self):
        position = _vector(self.position, "target position")
        object.__setattr__(self, "position", position)
        if self.axis is not None and self.rotation is not None:
            raise InvalidParameterError("a target has an axis or a rotation, not both")
        if self.axis is not None:
            axis = _vector(self.axis, "target axis")
            norm = float(np.linalg.norm(axis))
            if not norm > 1e-12:
                raise InvalidParameterError(f"target axis must not be zero, got {axis.tolist()}")
            object.__setattr__(self, "axis", axis / norm)
        if self.rotation is not None:
            R = np.asarray(self.rotation, dtype=float)
            rigid = R.shape == (3, 3) and np.isfinite(R).all() \
                and np.abs(R.T @ R - np.eye(3)).max() <= 1e-9 and np.linalg.det(R) > 0  # fmt: skip
            if not rigid:
                raise InvalidParameterError("target rotation must be a 3x3 rotation matrix")
            object.__setattr__(self, "rotation", R)

    @property
    def kind(self) -> str:
        """ "pose", "axis" or "position"."""
        return "pose" if self.rotation is not None else "axis" if self.axis is not None \
            else "position"  # fmt: skip

    @classmethod
    def of(cls, target) -> Target:
        """A Target from a Target, a 4x4 pose (array or SE3) or a 3-vector."""
        if isinstance(target, Target):
            return target
        A = getattr(target, "A", target)  # SE3
        try:
            A = np.asarray(A, dtype=float)
        except (TypeError, ValueError):
            raise InvalidTypeError(
                "target must be a 4x4 pose (array or SE3), a position (3 numbers) or a Target, "
                f"got {target!r}"
            ) from None
        if A.shape == (4, 4):
            from kinegami.chain.joints import pose_array

            T = pose_array(A, "target")  # finite and rigid: no second check of its rotation
            target = object.__new__(cls)
            for name, value in (("position", T[:3, 3].copy()), ("axis", None),
                                ("rotation", T[:3, :3].copy())):  # fmt: skip
                object.__setattr__(target, name, value)
            return target
        if A.shape == (3,):
            return cls(A)
        raise InvalidParameterError(
            f"target must be a 4x4 pose, a position (3 numbers) or a Target, got shape {A.shape}"
        )


def _vector(value, name: str) -> np.ndarray:
    try:
        v = np.asarray(value, dtype=float).reshape(-1)
    except (TypeError, ValueError):
        raise InvalidTypeError(f"{name} must be 3 numbers, got {value!r}") from None
    if v.shape != (3,) or not np.isfinite(v).all():
        raise InvalidParameterError(f"{name} must be 3 finite numbers, got {np.asarray(value)!r}")
    return v


@dataclass(frozen=True)
class Answer:
    """The answer to one target.

    Attributes
    ----------
    ok : bool
        Exact (within ``tol``), every state in its range and, unless ``clear=False`` was
        asked, the design clear of itself at ``states``.
    states : tuple of float
        A full configuration (one state per joint of ``design.Joints``) that
        ``setJointStates`` accepts: the answer when ok, else the nearest one found.
    position_error : float
        Distance of the tip from the target's position (design units; several tips: the
        largest).
    angle_error : float
        The tip's orientation error (rad; 0 for a position target).
    clearance : float
        The smallest clearance at ``states`` (design units; negative: overlap depth).
    pair : str
        The parts that bind (closest), in words ("" when nothing is tested).
    iterations, restarts : int
        Iterations over all starts, and starts beyond the first.
    reason : str
        Why not ok, in one sentence ("" when ok).
    """

    ok: bool
    states: tuple
    position_error: float
    angle_error: float
    clearance: float
    pair: str
    iterations: int
    restarts: int
    reason: str = ""
    tips: tuple = field(default=())


def solve(design, target, *, tip=None, tool=None, q0=None, seed: int = 0, clear: bool = True,
          tol=(1e-9, 1e-9), margin=None) -> Answer:  # fmt: skip
    """States that put ``design``'s tip on ``target``.

    Parameters
    ----------
    design : KinematicChain or KinematicTree
    target : 4x4 pose (array or SE3), 3-vector position, :class:`Target`; for a tree, a
        mapping of tip joint index to any of these (every tip at once).
    tip : int, optional
        The tip joint (default: a chain's last joint; a tree needs a mapping or ``tip``).
    tool : 4x4 array or SE3, optional
        A fixed frame on the tip.
    q0 : configuration, optional
        The first start (default: the design's current states).
    seed : int
        The other starts' random seed (the answer is the same for the same seed).
    clear : bool
        Require the design to be clear of itself at the answer (default True).
    tol : (position, angle)
        Exactness: position error in units of r, angle error in rad (default 1e-9 each).
    margin : float, optional
        The clearance required (design units; default: the design's margin).
    """
    return solve_many(design, [target], tip=tip, tool=tool, q0=q0, seed=seed, clear=clear,
                      tol=tol, margin=margin)[0]  # fmt: skip


def solve_many(design, targets, *, tip=None, tool=None, q0=None, seed: int = 0,
               clear: bool = True, tol=(1e-9, 1e-9), margin=None, executor=None,
               chunk: int = 256) -> list[Answer]:  # fmt: skip
    """:func:`solve` for every target of ``targets``, in order: the starts of all targets are
    iterated in one batch; with ``executor`` (any ``concurrent.futures.Executor``: threads,
    processes, a Dask cluster's), chunks of ``chunk`` targets run on it. A target's starts
    come from ``seed`` and the target itself, so ``chunk=1`` gives :func:`solve`'s answers;
    the same chunks give the same answers on any executor (larger batches may round the
    iterates otherwise and settle on another solution, as good)."""
    if not isinstance(targets, Sequence) or isinstance(targets, str):
        raise InvalidTypeError(f"targets must be a list of targets, got {type(targets).__name__}")
    tol_p, tol_a = _tolerance(tol)
    if isinstance(seed, bool) or not isinstance(seed, (int, np.integer)):
        raise InvalidTypeError(f"seed must be an int, got {seed!r}")
    if not isinstance(clear, bool):
        raise InvalidTypeError(f"clear must be True or False, got {clear!r}")
    if margin is not None:
        from kinegami.chain.bodies import check_margin

        margin = check_margin(margin)
    goals = _all_goals(design, targets, tip)
    tips = sorted({k for goal in goals for k in goal})
    compiled = kinematics(design, tips if tips else None, tool)
    states = [joint.state for joint in design.Joints] if q0 is None else q0
    start = compiled.configurations(states)[0][0]
    options = (tol_p, tol_a, int(seed), clear, margin)
    chunk = max(1, int(chunk))
    pieces = [list(range(a, min(a + chunk, len(goals)))) for a in range(0, len(goals), chunk)]
    if executor is None:
        results = [_solve_chunk(design, compiled, [goals[k] for k in piece], piece, start,
                                options) for piece in pieces]  # fmt: skip
    else:
        futures = [executor.submit(_solve_chunk, design, compiled, [goals[k] for k in piece],
                                   piece, start, options) for piece in pieces]  # fmt: skip
        results = [future.result() for future in futures]
    return [answer for part in results for answer in part]


def _tolerance(tol) -> tuple[float, float]:
    try:
        p, a = (float(x) for x in tol)
    except (TypeError, ValueError):
        raise InvalidTypeError(f"tol must be (position in r, angle in rad), got {tol!r}") from None
    if not (p > 0 and a > 0 and math.isfinite(p) and math.isfinite(a)):
        raise InvalidParameterError(f"tol must be two positive numbers, got {tol!r}")
    return p, a


def _goals(design, target, tip) -> dict[int, Target]:
    """The target as {tip joint: Target}."""
    n = len(design.Joints)
    if isinstance(target, Mapping):
        if tip is not None:
            raise InvalidParameterError("give tip or a mapping of tip to target, not both")
        out = {}
        for k, t in target.items():
            if isinstance(k, bool) or not isinstance(k, (int, np.integer)) or not 0 <= k < n:
                raise InvalidParameterError(f"target tip {k!r} is not a joint index: 0 to {n - 1}")
            out[int(k)] = Target.of(t)
        if not out:
            raise InvalidParameterError("a mapping of tips to targets must not be empty")
        return out
    return {_tip_of(design, tip): Target.of(target)}


def _tip_of(design, tip) -> int:
    """The tip joint of a target that is not a mapping: ``tip``, or a chain's only leaf."""
    n = len(design.Joints)
    if tip is None:
        parents = {p for p in design.Parents if p >= 0}
        leaves = [k for k in range(n) if k not in parents]
        if len(leaves) != 1:
            raise InvalidParameterError(
                f"the design has {len(leaves)} tips ({leaves}): give tip=J or a mapping "
                "{tip: target, ...}"
            )
        tip = leaves[0]
    if isinstance(tip, bool) or not isinstance(tip, (int, np.integer)) or not 0 <= tip < n:
        raise InvalidParameterError(f"tip {tip!r} is not a joint index: 0 to {n - 1}")
    return int(tip)


def _all_goals(design, targets: Sequence, tip) -> list[dict[int, Target]]:
    """:func:`_goals` of every target; a list of 4x4 float arrays (poses, the common batch)
    is checked at once, and any that the batch's check does not pass with room to spare
    goes through :func:`_goals` (which words the error)."""
    poses = _poses_at_once(targets)
    if poses is None:
        return [_goals(design, t, tip) for t in targets]
    k = _tip_of(design, tip)
    return [{k: target} for target in poses]


def _poses_at_once(targets: Sequence) -> list[Target] | None:
    """Pose targets of ``targets`` when every one is a (4, 4) float array that is finite and
    rigid well within :func:`kinegami.chain.joints.pose_array`'s tolerance (1e-8; here half
    of it, so that rounding cannot tell them apart), else None."""
    if not targets or not all(type(t) is np.ndarray and t.shape == (4, 4)
                              and t.dtype == np.float64 for t in targets):  # fmt: skip
        return None
    A = np.stack(targets)
    R = A[:, :3, :3]
    tol = 0.5e-8
    if not (np.isfinite(A).all()
            and np.abs(np.einsum("kji,kjl->kil", R, R) - np.eye(3)).max() <= tol
            and np.abs(np.linalg.det(R) - 1.0).max() <= tol
            and np.abs(A[:, 3] - [0.0, 0.0, 0.0, 1.0]).max() <= tol):  # fmt: skip
        return None
    out = []
    for T in A:
        target = object.__new__(Target)
        object.__setattr__(target, "position", T[:3, 3].copy())
        object.__setattr__(target, "axis", None)
        object.__setattr__(target, "rotation", T[:3, :3].copy())
        out.append(target)
    return out


def _rotation_vector(R: np.ndarray) -> np.ndarray:
    """(..., 3): the rotation vectors (axis times angle) of rotations R (..., 3, 3)."""
    w = np.stack([R[..., 2, 1] - R[..., 1, 2], R[..., 0, 2] - R[..., 2, 0],
                  R[..., 1, 0] - R[..., 0, 1]], axis=-1)  # fmt: skip
    s = 0.5 * np.linalg.norm(w, axis=-1)
    c = 0.5 * (np.trace(R, axis1=-2, axis2=-1) - 1.0)
    angle = np.arctan2(s, np.clip(c, -1.0, 1.0))
    small = s < 1e-12
    scale = np.where(small, 0.5, angle / (2.0 * np.where(small, 1.0, s)))
    out = w * scale[..., None]
    # near pi: the axis from the symmetric part
    near_pi = small & (c < 0.0)
    if near_pi.any():
        B = 0.5 * (R[near_pi] + np.eye(3))
        k = np.argmax(np.diagonal(B, axis1=-2, axis2=-1), axis=-1)
        axis = B[np.arange(k.size), :, k]
        axis /= np.linalg.norm(axis, axis=-1, keepdims=True)
        out[near_pi] = axis * math.pi
    return out


def _skew(v: np.ndarray) -> np.ndarray:
    out = np.zeros(v.shape[:-1] + (3, 3))
    out[..., 0, 1], out[..., 0, 2] = -v[..., 2], v[..., 1]
    out[..., 1, 0], out[..., 1, 2] = v[..., 2], -v[..., 0]
    out[..., 2, 0], out[..., 2, 1] = -v[..., 1], v[..., 0]
    return out


class _Problem:
    """Residuals and Jacobians of a batch of (target, start) rows: every row has the same tips
    and target kinds (a chunk's targets are grouped by them)."""

    def __init__(self, compiled: Kinematics, goals: list[dict[int, Target]], r: float):
        self.K = compiled
        self.r = r
        self.tip_index = {t: k for k, t in enumerate(compiled.tips)}
        self.keys = sorted(goals[0])
        self.kinds = [goals[0][k].kind for k in self.keys]
        self.position = np.array([[g[k].position for k in self.keys] for g in goals])  # (G,T,3)
        self.axis = np.array([[g[k].axis if g[k].axis is not None else np.zeros(3)
                               for k in self.keys] for g in goals])  # fmt: skip
        self.rotation = np.array([[g[k].rotation if g[k].rotation is not None else np.eye(3)
                                   for k in self.keys] for g in goals])  # fmt: skip
        self.movable = compiled.movable

    def evaluate(self, Q: np.ndarray, rows: np.ndarray, jacobian: bool):
        """Residual (m, E) in units of r and rad, errors (m,) position (design units) and
        angle (rad), and with ``jacobian`` the residual's Jacobian (m, E, movable)."""
        if jacobian:
            J, T = self.K.jacobians(Q)
        else:
            T = self.K.tip_poses(Q)
        parts, jparts = [], []
        pos_err = np.zeros(Q.shape[0])
        ang_err = np.zeros(Q.shape[0])
        for n, key in enumerate(self.keys):
            k = self.tip_index[key]
            p = T[:, k, :3, 3]
            dp = self.position[rows, n] - p
            parts.append(dp / self.r)
            pos_err = np.maximum(pos_err, np.linalg.norm(dp, axis=-1))
            if jacobian:
                jparts.append(J[:, k, :3][:, :, self.movable] / self.r)
            kind = self.kinds[n]
            if kind == "pose":
                R = T[:, k, :3, :3]
                w = _rotation_vector(self.rotation[rows, n] @ np.swapaxes(R, -1, -2))
                parts.append(w)
                ang_err = np.maximum(ang_err, np.linalg.norm(w, axis=-1))
                if jacobian:
                    jparts.append(J[:, k, 3:][:, :, self.movable])
            elif kind == "axis":
                z = T[:, k, :3, 2]
                a = self.axis[rows, n]
                parts.append(a - z)  # zero exactly when z points along a
                ang_err = np.maximum(ang_err, np.arctan2(np.linalg.norm(np.cross(z, a), axis=-1),
                                                         np.sum(z * a, axis=-1)))  # fmt: skip
                if jacobian:  # dz = w x z = -[z]x w
                    jparts.append(-_skew(z) @ J[:, k, 3:][:, :, self.movable])
        e = np.concatenate(parts, axis=-1)
        if not jacobian:
            return e, pos_err, ang_err
        return e, pos_err, ang_err, np.concatenate(jparts, axis=1)


def _solve_chunk(design, compiled: Kinematics, goals: list, indices: list, start: np.ndarray,
                 options: tuple) -> list[Answer]:  # fmt: skip
    """The answers to ``goals`` (target k of the whole list is ``indices[k]``: its starts'
    seed). Targets with the same tips and kinds are iterated together."""
    groups: dict[tuple, list[int]] = {}
    for k, goal in enumerate(goals):
        groups.setdefault(tuple((t, goal[t].kind) for t in sorted(goal)), []).append(k)
    answers: list[Answer | None] = [None] * len(goals)
    for key, members in groups.items():
        if len(key) == 1 and _kernel() is not None:  # one tip: each target compiled
            solver = _TipSolver(design, compiled, key[0][0], options)
            for k, answer in zip(members, solver.answers([goals[k] for k in members], start),
                                 strict=True):  # fmt: skip
                answers[k] = answer
            continue
        found = _solve_group(design, compiled, [goals[k] for k in members],
                             [indices[k] for k in members], start, options)  # fmt: skip
        for k, answer in zip(members, found, strict=True):
            answers[k] = answer
    return answers  # type: ignore[return-value]


def _solve_group(design, compiled, goals, indices, start, options) -> list[Answer]:
    tol_p, tol_a, seed, clear, margin = options
    r = float(design.r)
    problem = _Problem(compiled, goals, r)
    tips = tuple(problem.keys)
    G = len(goals)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    mov = compiled.movable
    rngs = [np.random.default_rng([seed, *_words(goal)]) for goal in goals]
    table = _seed_table(design, compiled, tuple(problem.keys), seed)
    kinds = tuple(problem.kinds)
    seeds: list = [None] * G

    def fresh(g: int, number: int) -> np.ndarray:
        """Start ``number`` of goal g: q0, then the table's nearest configurations (random
        ones taking every other turn after :data:`TABLE_FIRST`), then random ones."""
        if number == 0:
            return np.clip(start, low, high)
        if _table_turn(number):
            if seeds[g] is None:
                seeds[g] = table.starts(goals[g], kinds, SEEDED_STARTS)
            q = next(seeds[g], None)
            if q is not None:
                return q.copy()
        return low + (high - low) * rngs[g].random(low.size)

    # rows of the batch: (goal, start); STARTS rows per goal at first
    owner = np.repeat(np.arange(G), STARTS)
    Q = np.array([fresh(g, s) for g in range(G) for s in range(STARTS)])
    # a target a bound puts out of reach: one start, a few iterations for the nearest
    # configuration, no restarts (the verdict is known)
    hopeless = np.array([bool(_beyond_reach(compiled, goal)) for goal in goals])
    if hopeless.any():
        keep = ~hopeless[owner] | (np.arange(owner.size) % STARTS == 0)
        owner, Q = owner[keep], Q[keep]
    budget = np.where(hopeless, 1, MAX_STARTS)
    patience = np.where(hopeless, 12, ITERATIONS)
    damping = np.full(owner.size, DAMPING)
    age = np.zeros(owner.size, dtype=np.int64)
    started = np.where(hopeless, 1, STARTS)
    iterations = np.zeros(G, dtype=np.int64)
    done = np.zeros(G, dtype=bool)
    best: list[tuple | None] = [None] * G  # (score, q, pos, ang, clearance, pair, clear_ok)
    answers: list[Answer | None] = [None] * G
    collided: list[str] = [""] * G
    active = np.ones(owner.size, dtype=bool)
    while active.any():
        rows = np.flatnonzero(active)
        g_rows = owner[rows]
        e, pos, ang, J = problem.evaluate(Q[rows], g_rows, True)
        np.add.at(iterations, g_rows, 1)
        # converged rows: judged (range is kept by projection; clearance by the design)
        exact = (pos <= tol_p * r) & (ang <= tol_a)
        for i in np.flatnonzero(exact).tolist():
            row, g = rows[i], g_rows[i]
            if done[g]:
                active[row] = False
                continue
            verdict = _judge(design, Q[row], clear, margin)
            _keep(best, g, Q[row], pos[i], ang[i], verdict)
            if verdict[2]:
                done[g] = True
                answers[g] = _answer(best[g], iterations[g], started[g] - 1, "", tips)
            else:
                collided[g] = verdict[1]
            active[row] = False
        # a damped least-squares step for the others
        step_rows = np.flatnonzero(~exact)
        if step_rows.size:
            sr = rows[step_rows]
            Jr, er = J[step_rows], e[step_rows]
            lam = damping[sr]
            dq = _held_steps(Jr, er, lam, Q[sr][:, mov], low[mov], high[mov])
            trial = Q[sr].copy()
            trial[:, mov] = np.clip(trial[:, mov] + dq, low[mov], high[mov])
            e2, pos2, ang2 = problem.evaluate(trial, owner[sr], False)
            better = np.einsum("ke,ke->k", e2, e2) < np.einsum("ke,ke->k", er, er)
            Q[sr[better]] = trial[better]
            damping[sr] = np.clip(np.where(better, lam * 0.3, lam * 8.0), DAMPING_MIN,
                                  DAMPING_MAX)  # fmt: skip
            age[sr] += 1
            now_pos = np.where(better, pos2, pos[step_rows])
            now_ang = np.where(better, ang2, ang[step_rows])
            for i in range(sr.size):  # the nearest so far, for an answer that is not ok
                g = owner[sr[i]]
                if not done[g]:
                    _keep(best, g, Q[sr[i]], now_pos[i], now_ang[i], None)
            # stalled starts (too old, or damped to nothing): a new start, within the budget
            # (a start the step made exact is judged at the next iteration, never replaced)
            now_exact = (now_pos <= tol_p * r) & (now_ang <= tol_a)
            stalled = ((age[sr] >= patience[owner[sr]]) | (damping[sr] >= DAMPING_MAX)) \
                & ~now_exact  # fmt: skip
            for row in sr[stalled].tolist():
                g = owner[row]
                if done[g] or started[g] >= budget[g]:
                    active[row] = False
                    continue
                Q[row] = fresh(g, int(started[g]))
                started[g] += 1
                damping[row], age[row] = DAMPING, 0
        for row in np.flatnonzero(active).tolist():
            if done[owner[row]]:
                active[row] = False
    for g in range(G):
        if answers[g] is None:
            answers[g] = _failure(design, best[g], iterations[g], started[g] - 1, collided[g],
                                  options, compiled, goals[g], tips)  # fmt: skip
    return answers  # type: ignore[return-value]


def _damped_steps(J: np.ndarray, e: np.ndarray, lam: np.ndarray) -> np.ndarray:
    """(k, P): the damped least-squares steps J^T (J J^T + lambda I)^-1 e of k rows."""
    A = J @ np.swapaxes(J, -1, -2)
    A[:, np.arange(A.shape[1]), np.arange(A.shape[1])] += lam[:, None]
    return np.einsum("kej,ke->kj", J, np.linalg.solve(A, e[..., None])[..., 0])


def _held_steps(J: np.ndarray, e: np.ndarray, lam: np.ndarray, q: np.ndarray, low: np.ndarray,
                high: np.ndarray) -> np.ndarray:  # fmt: skip
    """(k, P): the damped steps of k rows (Jacobians J (k, E, P), residuals e, damping lam)
    from the states ``q`` (k, P) with ranges ``low``, ``high``, the joints at a limit that a
    step pushes beyond held (their columns left out, the step solved again: the others make
    up for them, as :func:`kinegami.reach.kernels.descend` does). Without it, a start whose
    solution lies along a limit is clipped there to a standstill."""
    dq = _damped_steps(J, e, lam)
    held = np.zeros(dq.shape, dtype=bool)
    at_high, at_low = q >= high, q <= low
    for _ in range(dq.shape[1]):
        new = ~held & (((dq > 0.0) & at_high) | ((dq < 0.0) & at_low))
        rows = np.flatnonzero(new.any(axis=1))
        if rows.size == 0:
            break
        held |= new
        Jh = J[rows] * ~held[rows][:, None, :]
        dq[rows] = _damped_steps(Jh, e[rows], lam[rows])
    return dq


_KERNEL: list = []  # [kinegami.reach.kernels.descend, or None where numba cannot run]


def _kernel():
    """The compiled descent (:mod:`kinegami.reach.kernels`), loaded on first use; None where
    numba cannot be imported or cannot keep its machine code (the numpy path then answers)."""
    if not _KERNEL:
        try:
            from kinegami.reach.kernels import descend
        except (ImportError, OSError, RuntimeError):
            descend = None
        _KERNEL.append(descend)
    return _KERNEL[0]


_KINDS = {"position": 0, "axis": 1, "pose": 2}


#: Per compiled design (while it lives), what each tip's solves share: (what, tip) -> value.
_PER_TIP: weakref.WeakKeyDictionary = weakref.WeakKeyDictionary()


def _per_tip(compiled: Kinematics, what: str, tip: int, make):
    """``make(compiled, tip)``, made once per compiled design and tip (a compiled design is
    immutable, so what is derived from it stays true)."""
    known = _PER_TIP.get(compiled)
    if known is None:
        known = _PER_TIP[compiled] = {}
    key = (what, tip)
    if key not in known:
        known[key] = make(compiled, tip)
    return known[key]


class _SeedTable:
    """Seeded random configurations of a design and its tips' poses there: those nearest to
    a target (by tip positions in units of the reach, and rotations or axes; a KD-tree per
    target kind) that are clear (a chain's; a tree's all count) are good starts.

    Whether a configuration is clear is asked of the design's clearance engine (its closest
    pairs, with the design's margin) the first time a target's starts reach it, and kept: a
    target checks only the few nearest it uses (the PUMA's 663 restarts over 1,000 targets
    about 1,300 configurations), not the whole table (8,192 checks, 0.25-0.6 s)."""

    def __init__(self, design, compiled: Kinematics, tips: tuple, seed: int):
        from kinegami.chain.model import KinematicChain

        low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
        rng = np.random.default_rng([seed, 0x5EED])
        self.Q = low + (high - low) * rng.random((SEED_TABLE, low.size))
        T = compiled.tip_poses(self.Q)  # (m, L, 4, 4), the compiled tips
        self.T = T[:, [compiled.tips.index(t) for t in tips]]
        # per configuration: 1 clear, 0 not, -1 not asked yet
        chain = isinstance(design, KinematicChain)
        self.clear = np.full(SEED_TABLE, -1 if chain else 1, dtype=np.int8)
        self.engine = _engine_of(design) if chain else None
        self.margin = float(getattr(design, "margin", 0.0))
        self.limit = _limit(design, self.margin)
        scale = max((_per_tip(compiled, "bound", t, reach_bound)[0] for t in tips), default=1.0)
        self.scale = scale if scale > 0 else 1.0
        self.trees: dict = {}

    def features(self, T: np.ndarray, kinds: tuple) -> np.ndarray:
        """(m, F): tip positions over the reach, and each tip's rotation (pose) or z (axis)."""
        parts = []
        for n, kind in enumerate(kinds):
            parts.append(T[:, n, :3, 3] / self.scale)
            if kind == "pose":
                parts.append(T[:, n, :3, :3].reshape(-1, 9) / 3.0)
            elif kind == "axis":
                parts.append(T[:, n, :3, 2] / 2.0)
        return np.concatenate(parts, axis=1)

    def is_clear(self, row: int) -> bool:
        """Whether configuration ``row`` is clear (asked of the engine once)."""
        if self.clear[row] < 0:
            self.record(row, self.engine.closest_pairs(self.Q[row], self.margin))
        return bool(self.clear[row])

    def record(self, row: int, pairs: tuple) -> bool:
        """Keep whether configuration ``row`` is clear from the engine's closest pairs there
        (with :attr:`margin`), and return it."""
        verdict = _is_clear(pairs, self.limit)
        self.clear[row] = verdict
        return verdict

    def next_clear(self, rows):
        """The next clear configuration of ``rows`` (an iterator of :meth:`rows`), or None
        when there is none: a generator that yields ``((_PAIRS, margin), configuration)``
        for a configuration not asked yet and is sent the engine's closest pairs there
        (:func:`_in_step`)."""
        for row in rows:
            verdict = self.clear[row]
            if verdict < 0:
                verdict = self.record(row, (yield (_PAIRS, self.margin), self.Q[row]))
            if verdict:
                return self.Q[row]
        return None

    def starts(self, goal: dict, kinds: tuple, count: int):
        """The clear configurations nearest to ``goal`` (tip -> Target), nearest first, at
        most ``count`` (a generator: each is checked when it is asked for)."""
        given = 0
        for row in self.rows(goal, kinds):
            if given >= count:
                return
            if self.is_clear(row):
                given += 1
                yield self.Q[row]

    def nearest(self, goal: dict, kinds: tuple, count: int) -> np.ndarray:
        """(k, n): :meth:`starts` at once, k <= ``count``."""
        return np.array(list(self.starts(goal, kinds, count))).reshape(-1, self.Q.shape[1])

    def tree(self, kinds: tuple):
        """The KD-tree of the configurations' features for target kinds ``kinds``."""
        tree = self.trees.get(kinds)
        if tree is None:
            from scipy.spatial import cKDTree

            tree = self.trees[kinds] = cKDTree(self.features(self.T, kinds))
        return tree

    def target_features(self, goal: dict, kinds: tuple) -> np.ndarray:
        """(F,): the target's features, as :meth:`features` makes them of tip poses."""
        parts = []
        for key, kind in zip(sorted(goal), kinds, strict=True):
            target = goal[key]
            parts.append(target.position / self.scale)
            if kind == "pose":
                parts.append(target.rotation.reshape(9) / 3.0)
            elif kind == "axis":
                parts.append(target.axis / 2.0)
        return np.concatenate(parts)

    def first_rows(self, X: np.ndarray, kinds: tuple) -> list:
        """For each target's features (rows of ``X``), the indices of the
        :data:`FIRST_ROWS` configurations nearest it, nearest first: one query of the
        KD-tree for all (a third of the cost of one query each), the same rows."""
        k = min(self.Q.shape[0], FIRST_ROWS)
        _, index = self.tree(kinds).query(X, k=k)
        return list(np.asarray(index).reshape(X.shape[0], k))

    def rows(self, goal: dict, kinds: tuple, first=None):
        """Every configuration's index, nearest to ``goal`` first: ``first`` (the nearest,
        :meth:`first_rows`, asked here when not given), then asked of the KD-tree four
        times as many at a time."""
        size = self.Q.shape[0]
        x = self.target_features(goal, kinds)
        if first is None:
            first = self.first_rows(x[None], kinds)[0]
        yield from first.tolist()
        done = first.size
        while done < size:
            k = min(size, 4 * done)
            _, index = self.tree(kinds).query(x, k=k)
            yield from np.atleast_1d(index)[done:k].tolist()
            done = k


def _seed_table(design, compiled: Kinematics, tips: tuple, seed: int) -> _SeedTable:
    """The seed table of ``compiled`` for ``tips`` and ``seed``, made once (:func:`_per_tip`)."""
    return _per_tip(compiled, "table", (tips, seed),
                    lambda c, key: _SeedTable(design, c, key[0], key[1]))  # fmt: skip


def _tip_path(compiled: Kinematics, tip: int) -> tuple:
    """What the compiled descent needs of one tip (made once per compiled design and tip,
    :func:`_per_tip`): the moving bodies from the root to it (in order), their joints'
    columns of a configuration, revolute flags, reference states and ranges, the steps
    between their axis frames and the tip's frame in its body's."""
    return _per_tip(compiled, "path", tip, _make_tip_path)


def _make_tip_path(compiled: Kinematics, tip: int) -> tuple:
    screws = compiled.screws
    tip_body = int(screws.body_of[tip])
    path = compiled.path(tip)
    steps, inverse = screws.elementary()
    moving = path - 1
    columns = screws.moving[moving]
    E = inverse[tip_body] @ compiled.tip_frames[compiled.tips.index(tip)]
    return (np.ascontiguousarray(np.stack(steps) if steps else np.zeros((0, 4, 4))),
            path, np.ascontiguousarray(screws.revolute[moving]),
            np.ascontiguousarray(screws.q_ref[columns]), np.ascontiguousarray(E), columns,
            np.ascontiguousarray(compiled.ranges[columns, 0]),
            np.ascontiguousarray(compiled.ranges[columns, 1]))  # fmt: skip


def _table_turn(number: int) -> bool:
    """Whether restart ``number`` (1, 2, ...) is the seed table's turn (while it has
    configurations left): the first :data:`TABLE_FIRST`, then every other one."""
    return number <= TABLE_FIRST or (number - TABLE_FIRST) % 2 == 0


class _TipSolver:
    """:func:`_solve_group`'s answers for targets of one tip, each start iterated by the
    compiled descent (:func:`kinegami.reach.kernels.descend`) in turn: the first from the
    start given, then the seed table's clear configurations nearest the target, then random
    ones from the target's own stream, until one is exact and clear or the budget is spent.
    What the targets share (the tip's path, the engine, the margins, the reach bound) is
    made once."""

    def __init__(self, design, compiled: Kinematics, tip: int, options: tuple):
        tol_p, tol_a, seed, clear, margin = options
        self.design, self.compiled, self.tip, self.options = design, compiled, tip, options
        self.tol_p, self.tol_a, self.seed, self.clear = tol_p, tol_a, seed, clear
        self.r = r = float(design.r)
        steps, path, revolute, reference, E, columns, low_p, high_p = _tip_path(compiled, tip)
        self.path, self.columns = path, columns
        self.head = (steps, path, revolute, reference, E, low_p, high_p)
        self.low, self.high = compiled.ranges[:, 0], compiled.ranges[:, 1]
        self.engine = _engine_of(design, margin)
        self.required = _margin_value(design, margin)
        self.limit = _limit(design, self.required)
        self.apart = self.required + ESCAPE_BUFFER * r  # an escape pushes pairs apart up to it
        self.bound = _per_tip(compiled, "bound", tip, reach_bound)
        self.descend = _kernel()
        self.table = None

    def answers(self, goals: list, start: np.ndarray) -> list[Answer]:
        """The answers to ``goals`` ({tip: Target} each) from ``start``: every target's
        search (:meth:`search`) runs in step with the others, and what they ask of the
        clearance engine at a step is asked in one call per margin
        (:meth:`kinegami.clearance.engine.ClearanceEngine.closest_pairs_many`: the same
        arrays as one by one, so a target's answer does not depend on the others)."""
        return _in_step([self.search(goal, start) for goal in goals], self.engine)

    def search(self, goal: dict, start: np.ndarray):
        """The answer to ``goal`` from ``start``, as a generator that yields what it needs
        of the engine (closest pairs) and of the seed table (the nearest configurations) and
        is sent them (:func:`_in_step`)."""
        ((tip, target),) = goal.items()
        r, tol_p, tol_a, columns = self.r, self.tol_p, self.tol_a, self.columns
        low, high = self.low, self.high
        rng = None  # the target's own random stream, made at the first restart (~70 us)
        hopeless = _outside(target.position, *self.bound)
        budget, patience = (1, 12) if hopeless else (MAX_STARTS, ITERATIONS)
        kind = _KINDS[target.kind]
        axis = target.axis if target.axis is not None else _NO_AXIS
        rotation = target.rotation if target.rotation is not None else _NO_ROTATION
        arguments = self.head + (kind, target.position, rotation, axis, r, tol_p, tol_a)
        redundant = self.path.size > (3 if kind == 0 else 6)
        best: list = [None]
        collided = ""  # the binding pair of the last exact solution that passes through itself
        iterations = escapes = 0
        q = np.clip(start, low, high)
        rows = None  # the seed table's configurations, nearest the target first
        seeded = 0
        for started in range(budget):
            if started:
                q = None
                if seeded < SEEDED_STARTS and _table_turn(started):  # the table's clear
                    if rows is None:  # configurations nearest the target
                        if self.table is None:
                            self.table = _seed_table(self.design, self.compiled, (tip,),
                                                     self.seed)  # fmt: skip
                        kinds = (target.kind,)
                        first = yield (_NEAREST, self.table, kinds), \
                            self.table.target_features(goal, kinds)  # fmt: skip
                        rows = self.table.rows(goal, kinds, first)
                    q = yield from self.table.next_clear(rows)
                    seeded = SEEDED_STARTS if q is None else seeded + 1
                if q is None:  # a random one
                    if rng is None:
                        rng = np.random.default_rng([self.seed, *_words(goal)])
                    q = low + (high - low) * rng.random(low.size)
                else:
                    q = q.copy()
            if self.path.size == 0:  # nothing moves the tip: one evaluation
                exact, count, pos, ang = _still(_Problem(self.compiled, [goal], r), q, tol_p,
                                                tol_a, r)  # fmt: skip
                near, near_pos, near_ang = q[columns], pos, ang
            else:
                exact, count, pos, ang, near, near_pos, near_ang = self.descend(
                    *arguments, q[columns], patience, DAMPING, DAMPING_MIN,
                    DAMPING_MAX)  # fmt: skip
            iterations += count
            found = q.copy()
            found[columns] = near
            if not exact:
                _keep(best, 0, found, near_pos, near_ang, None)
                continue
            # the engine's closest pairs (the report's verdict and words); a redundant arm
            # that passes through itself moves along its solutions, away from the binding pairs
            escape = self.clear and redundant and escapes < ESCAPES
            pairs = yield (_PAIRS, self.apart if escape else self.required), found
            if escape and not _is_clear(pairs, self.limit):
                escapes += 1
                found, pairs, count = yield from _escape_steps(
                    self.engine, self.compiled, tip, found, columns, arguments, pairs,
                    self.limit, self.apart)  # fmt: skip
                iterations += count
            verdict = _verdict(self.engine, pairs, self.limit, self.clear)
            _keep(best, 0, found, near_pos, near_ang, verdict)
            if verdict[2]:
                return _answer(best[0], iterations, started, "", (tip,))
            collided = verdict[1]
        return _failure(self.design, best[0], iterations, budget - 1, collided, self.options,
                        self.compiled, goal, (tip,))  # fmt: skip


#: What a search asks for (:func:`_in_step`).
_PAIRS, _NEAREST = "pairs", "nearest"


def _in_step(searches: list, engine) -> list:
    """Run generators until each returns, answering what they yield: ``((_PAIRS, margin),
    configuration)`` with the engine's closest pairs there, ``((_NEAREST, table, kinds),
    features)`` with the seed table's configurations nearest those features
    (:meth:`_SeedTable.first_rows`). At every step, what the generators ask with one key is
    asked in one call (:meth:`kinegami.clearance.engine.ClearanceEngine.closest_pairs_many`,
    one KD-tree query): the same values as one by one, so that each generator's value does
    not depend on the others. Returns their values, in order."""
    results: list = [None] * len(searches)
    waiting: dict[int, tuple] = {}

    def advance(k: int, value) -> None:
        try:
            waiting[k] = searches[k].send(value)
        except StopIteration as stop:
            waiting.pop(k, None)
            results[k] = stop.value

    for k in range(len(searches)):
        advance(k, None)
    while waiting:
        asked: dict[tuple, list[int]] = {}
        for k, (key, _) in waiting.items():
            asked.setdefault(key, []).append(k)
        for key, asking in asked.items():
            items = np.array([waiting[k][1] for k in asking])
            if key[0] == _PAIRS:
                found = engine.closest_pairs_many(items, key[1])
            else:
                found = key[1].first_rows(items, key[2])
            for k, value in zip(asking, found, strict=True):
                advance(k, value)
    return results


_NO_AXIS, _NO_ROTATION = np.zeros(3), np.eye(3)


#: Exact solutions that pass through themselves that one target moves away from (redundant
#: arms), and the most steps of each move: on 1,000 of the 9R's targets, 94% of the moves
#: that end clear do so within 8 steps, and the moves that do not took 62% of all steps
#: (16 at most); at 8, the same targets are reached on 5,000 of the 9R's and the 7R's
#: (three seeds each), 8% faster on the 9R.
ESCAPES, ESCAPE_STEPS = 16, 8
#: A move's pairs: those closer than the margin plus this (units of r) are pushed apart, up
#: to it; the longest step (rad, a slide in units of r), the shortest tried before giving up,
#: and the descent's iterations back onto the target after each step.
ESCAPE_BUFFER, ESCAPE_RADIUS, ESCAPE_SHORTEST, ESCAPE_PATIENCE = 0.2, 0.3, 1e-3, 12


def _escape_steps(engine, compiled: Kinematics, tip: int, q: np.ndarray, columns: np.ndarray,
            arguments: tuple, pairs: tuple, limit: float, apart: float) -> tuple:  # fmt: skip
    """For an arm with more joints on the tip's path than the target fixes: from the exact
    solution ``q`` that passes through itself (``pairs``: the engine's pairs closer than the
    margin ``apart`` there), steps along the solutions that push those pairs apart up to
    ``apart`` (:func:`kinegami.reach.kernels.escape_step`: their clearances' analytic
    gradients projected onto the Jacobian's null space, then the descent back onto the
    target). A step is kept when it lessens the overlap (the sum of the clearances'
    shortfalls below ``limit``), and the next may be twice as long; otherwise it is tried
    half as long. Returns (q, pairs, iterations): the first clear solution met, or the exact
    one that overlaps least. A generator: it yields ``((_PAIRS, margin), configuration)``
    for the engine's closest pairs there and is sent them (:func:`_in_step`);
    :func:`_escape` runs it alone."""
    from kinegami.reach.kernels import descend, escape_step

    path = arguments[1]
    moves = _per_tip(compiled, "moves", tip, lambda c, _: _moves(engine, c, path))
    shortfall = _shortfall(pairs[0], limit)
    radius = ESCAPE_RADIUS
    iterations = 0
    for _ in range(ESCAPE_STEPS):
        clearance, ends, bodies, s, t, _ = pairs
        step = escape_step(*arguments[:8], arguments[11], q[columns], clearance, ends, bodies,
                           s, t, moves, apart, radius)  # fmt: skip
        if np.array_equal(step, q[columns]):  # no step raises a pair
            break
        exact, count, _, _, near, _, _ = descend(*arguments, step, ESCAPE_PATIENCE, DAMPING,
                                                 DAMPING_MIN, DAMPING_MAX)  # fmt: skip
        iterations += count
        if exact:
            trial = q.copy()
            trial[columns] = near
            moved = yield (_PAIRS, apart), trial
            lack = _shortfall(moved[0], limit)
            if lack < shortfall:
                q, pairs, shortfall = trial, moved, lack
                if lack == 0.0:
                    break
                radius = min(ESCAPE_RADIUS, 2.0 * radius)
                continue
        radius *= 0.5
        if radius < ESCAPE_SHORTEST:
            break
    return q, pairs, iterations


def _escape(engine, compiled: Kinematics, tip: int, q: np.ndarray, columns: np.ndarray,
            arguments: tuple, pairs: tuple, limit: float, apart: float) -> tuple:  # fmt: skip
    """:func:`_escape_steps` run alone, asking ``engine`` for the closest pairs."""
    return _in_step([_escape_steps(engine, compiled, tip, q, columns, arguments, pairs, limit,
                                   apart)], engine)[0]  # fmt: skip


def _shortfall(clearance: np.ndarray, limit: float) -> float:
    """How far the pairs are from clear: the sum of their clearances' shortfalls below the
    limit (0 when clear)."""
    return float(np.maximum(limit - clearance, 0.0).sum())


def _moves(engine, compiled: Kinematics, path: np.ndarray) -> np.ndarray:
    """(P, bodies) bool: whether the tip path's joint m turns or slides the engine's body b
    (b is that joint's body or hangs from it)."""
    screws = engine.screws
    parent = screws.body_parent.tolist()
    own = screws.body_of[compiled.screws.moving[path - 1]].tolist()
    moves = np.zeros((len(own), screws.bodies), dtype=bool)
    for b in range(screws.bodies):
        above, x = set(), b
        while x > 0:
            above.add(x)
            x = parent[x]
        moves[:, b] = [o in above for o in own]
    return moves


def _margin_value(design, margin) -> float:
    """The clearance required: ``margin``, or the design's own."""
    return float(getattr(design, "margin", 0.0)) if margin is None else float(margin)


def _limit(design, margin: float) -> float:
    """The smallest clearance that is clear with ``margin`` (every verdict's limit)."""
    from kinegami.chain.bodies import clear_limit

    return clear_limit(float(design.r), margin)


def _is_clear(pairs: tuple, limit: float) -> bool:
    """Whether the closest pairs ``pairs`` (:meth:`ClearanceEngine.closest_pairs`) are clear:
    the smallest clearance at least ``limit`` (the report's verdict)."""
    return pairs[0].size == 0 or float(pairs[0][0]) >= limit


def _engine_of(design, margin=None):
    """The clearance engine of a chain or a tree (what ``design.clearance`` measures with)."""
    from kinegami.chain.model import KinematicChain
    from kinegami.clearance.engine import engine_for, tree_engine

    if isinstance(design, KinematicChain):
        return engine_for(design)
    return tree_engine(design, None, _margin_value(design, margin))


def _still(problem: _Problem, q: np.ndarray, tol_p: float, tol_a: float, r: float) -> tuple:
    """(exact, 1, position error, angle error) of a tip that no joint moves, at ``q``."""
    _, pos, ang = problem.evaluate(q[None, :], np.zeros(1, dtype=np.int64), False)
    return bool(pos[0] <= tol_p * r and ang[0] <= tol_a), 1, float(pos[0]), float(ang[0])


def _words(goal: dict) -> list[int]:
    """The target as 32-bit words: its starts' seed, so that a target gets the same starts
    wherever it is in a list (and solve_many's answers are solve's)."""
    parts = []
    for tip in sorted(goal):
        target = goal[tip]
        parts += [np.array([tip], dtype=float), target.position]
        parts += [x.reshape(-1) for x in (target.axis, target.rotation) if x is not None]
    return np.frombuffer(np.concatenate(parts).tobytes(), dtype=np.uint32).tolist()


def _judge(design, q: np.ndarray, clear: bool, margin) -> tuple[float, str, bool]:
    """(clearance, binding pair in words, acceptable) of the design at ``q``, as its
    clearance report (``design.clearance``) gives them."""
    engine = _engine_of(design, margin)
    required = _margin_value(design, margin)
    return _verdict(engine, engine.closest_pairs(q, required), _limit(design, required), clear)


def _verdict(engine, pairs: tuple, limit: float, clear: bool) -> tuple[float, str, bool]:
    """(clearance, binding pair in words, acceptable) from the engine's closest pairs
    (:meth:`ClearanceEngine.closest_pairs`, whose first is the report's closest pair: the
    report's smallest clearance, its closest pair's words and its verdict)."""
    clearance, _, _, s, t, capsules = pairs
    if clearance.size == 0:  # nothing is tested
        return math.inf, "", True
    first, second = capsules[0].tolist()
    words = f"{engine.label(first, float(s[0]))} and {engine.label(second, float(t[0]))}"
    return float(clearance[0]), words, float(clearance[0]) >= limit or not clear


def _keep(best: list, g: int, q, pos: float, ang: float, verdict) -> None:
    """Keep the nearest configuration of goal g (an exact clear one over everything)."""
    score = (0 if verdict is not None and verdict[2] else 1, float(pos), float(ang))
    if best[g] is None or score < best[g][0]:
        best[g] = (score, np.array(q, dtype=float), float(pos), float(ang), verdict)


def _answer(kept, iterations, restarts, reason, tips: tuple) -> Answer:
    _, q, pos, ang, verdict = kept
    clearance, pair, ok = verdict if verdict is not None else (math.nan, "", False)
    return Answer(ok and not reason, tuple(float(x) for x in q), pos, ang, float(clearance),
                  pair, int(iterations), int(restarts), reason, tips)  # fmt: skip


def _failure(design, kept, iterations, restarts, collided, options, compiled, goal,
             tips: tuple) -> Answer:  # fmt: skip
    """The answer when no start gave an exact, clear configuration: the nearest one, and
    why in one sentence."""
    tol_p, tol_a, _, clear, margin = options
    _, q, pos, ang, verdict = kept
    if verdict is None:
        verdict = _judge(design, q, clear, margin)
    r = float(design.r)
    reach = _beyond_reach(compiled, goal)
    if reach:
        reason = reach
    elif collided and pos <= tol_p * r and ang <= tol_a:
        reason = f"every solution found passes through itself ({collided})"
    elif collided:
        reason = f"every exact solution found passes through itself ({collided})"
    elif pos <= tol_p * r:
        reason = f"orientation not attainable: the nearest is {ang:.3g} rad off"
    else:
        at = _at_limit(compiled, q)
        reason = f"not reached: the nearest tip position is {pos:.4g} away" + \
            (f"; {at}" if at else "")  # fmt: skip
    kept = (kept[0], q, pos, ang, verdict)
    return _answer(kept, iterations, restarts, reason, tips)


def _at_limit(compiled: Kinematics, q: np.ndarray) -> str:
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    at = [k for k in compiled.movable.tolist()
          if q[k] <= low[k] + 1e-12 or q[k] >= high[k] - 1e-12]  # fmt: skip
    if not at:
        return ""
    k = at[0]
    return f"joint {k} is at its limit ({q[k]:.6g} of [{low[k]:.6g}, {high[k]:.6g}])"


def _beyond_reach(compiled: Kinematics, goal: dict) -> str:
    """A sentence when a bound proves a target position out of reach, else ""."""
    screws = compiled.screws
    if screws.moving.size == 0:
        return ""
    for tip, target in goal.items():
        radius, centre = _per_tip(compiled, "bound", tip, reach_bound)
        if _outside(target.position, radius, centre):
            distance = float(np.linalg.norm(target.position - centre))
            return (
                f"beyond reach: the target is {distance:.6g} from the first moving joint's "
                f"axis point, and the tip reaches at most {radius:.6g} from it"
            )
    return ""


def _outside(position: np.ndarray, radius: float, centre: np.ndarray) -> bool:
    """Whether ``position`` is beyond the reach bound (R, c) of :func:`reach_bound`."""
    return float(np.linalg.norm(position - centre)) > radius * (1.0 + 1e-9) + 1e-9


def reach_bound(compiled: Kinematics, tip: int) -> tuple[float, np.ndarray]:
    """(R, c): the tip of joint ``tip`` stays within R of c for every configuration; c is a
    point on the axis of the first moving joint on its path (fixed in the base). Along the
    path each revolute joint's axis point is fixed in the bodies on both sides, so the
    distances between consecutive axis points (and to the tip) do not change; a prismatic
    joint adds its stroke."""
    screws = compiled.screws
    k = compiled.tips.index(tip)
    path = (compiled.path(tip) - 1).tolist()
    tip_point = compiled.tip_frames[k, :3, 3]
    if not path:
        return 0.0, tip_point
    points = screws.points[path]
    ranges = compiled.ranges[screws.moving[path]]
    q_ref = screws.q_ref[screws.moving[path]]
    radius = 0.0
    for m in range(len(path)):
        following = points[m + 1] if m + 1 < len(path) else tip_point
        radius += float(np.linalg.norm(following - points[m]))
        if not screws.revolute[path[m]]:
            radius += float(np.abs(ranges[m] - q_ref[m]).max())
    return radius, points[0]
