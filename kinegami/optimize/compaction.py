"""Making placed chains compact without changing their kinematics (docs/clearance.md).

Sliding a joint along its axis of motion or rolling it about that axis keeps every axis line,
so the robot's kinematics are unchanged; only the tube between the joints changes. Waypoints
carry no kinematics: they may move, appear (placement adds them) or disappear.

:func:`compact` is a multi-start local search over those moves that never accepts a design
that passes through itself (:mod:`kinegami.clearance`). :func:`shorten_by_axis_translations`
is its slide-only, in-place form (the original greedy shortening, now clearance-aware).
"""

from __future__ import annotations

import concurrent.futures
import copy
import math
import os
import time
import warnings
from dataclasses import dataclass

import numpy as np

from kinegami.chain.bodies import check_margin, worst_overlap
from kinegami.chain.joints import EndTip
from kinegami.chain.model import KinematicChain
from kinegami.clearance.tree_bodies import tree_worst_overlap
from kinegami.errors import (
    ClearanceWarning,
    CompactionError,
    InvalidParameterError,
    InvalidTypeError,
    NoPathError,
    PlacementWarning,
)
from kinegami.fabrication.sheets import junction_problems
from kinegami.geometry.csc import csc_lengths
from kinegami.geometry.frames import rotation_about_line
from kinegami.progress import Progress, ProgressCallback, check_progress
from kinegami.tree import KinematicTree
from kinegami.validation import (
    check_bool,
    check_int,
    check_positive,
    check_samples,
    check_starts,
)

__all__ = [
    "compact",
    "compact_for_task",
    "CompactionError",
    "repaired_vertices",
    "shorten_by_axis_translations",
    "tube_length",
]


def tube_length(chain: KinematicChain) -> float:
    """Total tube length: every link's centreline plus every joint's neutral length."""
    return chain.totalPathLength() + float(sum(j.neutralLength for j in chain.Joints))


def _objective(chain: KinematicChain, kind: str) -> float:
    return chain.boundingBall.r if kind == "ball" else tube_length(chain)


def _worst(chain: KinematicChain | KinematicTree):
    """The closest pair of parts of a chain or a tree closer than its ``margin`` (an
    Overlap), or None when it is clear with that margin."""
    if isinstance(chain, KinematicTree):
        return tree_worst_overlap(chain.Joints, chain.Links, chain.Parents, chain.r,
                                  margin=chain.margin)  # fmt: skip
    return worst_overlap(chain.Joints, chain.Links, chain.r, margin=chain.margin)


def _overlap(chain: KinematicChain | KinematicTree) -> float:
    """How much closer than its margin the closest pair of parts is (the overlap depth with
    margin 0; 0 when the chain is clear)."""
    found = _worst(chain)
    return 0.0 if found is None else chain.margin - found.clearance


def _neighbours(chain, j: int) -> list[int]:
    """The joints joined to joint j by a link: the one before and after it in a chain; the
    parent and the children in a tree."""
    if isinstance(chain, KinematicTree):
        parent = chain.Parents[j]
        return ([parent] if parent >= 0 else []) + list(chain.Children[j])
    return [k for k in (j - 1, j + 1) if 0 <= k < len(chain.Joints)]


@dataclass
class _State:
    chain: KinematicChain
    overlap: float
    value: float

    def better_than(self, other: _State, tol: float) -> bool:
        if self.overlap < other.overlap - tol:
            return True
        return self.overlap <= other.overlap + tol and self.value < other.value - tol


def _evaluate(
    chain: KinematicChain, overlap: float, kind: str, current: _State, tol: float
) -> _State | None:
    """The trial's state if it beats ``current``."""
    state = _State(chain, overlap, _objective(chain, kind))
    return state if state.better_than(current, tol) else None


def _trial(
    chain: KinematicChain, edit, *args, clear_only: bool = False
) -> tuple[KinematicChain | None, float]:
    """A copy of ``chain`` with one edit applied and its overlap depth (0: clear), or
    (None, inf) if the edit was rejected.

    Edits replace the chain's joint and link lists, never change them in place, so a shallow
    copy is an independent snapshot. With ``clear_only`` the copy requires clearance, so the
    chain's own check rejects a colliding edit and nothing is measured twice; otherwise the
    overlap is measured here, not read from the chain's ClearanceWarning (recording warnings
    is not thread-safe, and starts may run in threads).
    """
    new = copy.copy(chain)
    if clear_only:
        new.requireClearance = True
    if not getattr(new, edit)(*args):
        return None, math.inf
    if clear_only:
        new.requireClearance = chain.requireClearance
        return new, 0.0
    return new, _overlap(new)


def _moves(chain: KinematicChain, j: int, slide: float, roll: float, rolls: bool):
    """Candidate edits of joint j: slides by +-slide, slides to the points of its axis nearest
    its neighbours, rolls by +-roll (propagate=False: only its two links change)."""
    joints = chain.Joints
    T = joints[j].pose_matrix
    p, z = T[:3, 3], T[:3, 2]
    out = [("translateJointAlongAxisOfMotion", j, slide, False),
           ("translateJointAlongAxisOfMotion", j, -slide, False)]  # fmt: skip
    targets = [float((joints[k].pose_matrix[:3, 3] - p) @ z) for k in _neighbours(chain, j)]
    if len(targets) == 2:
        targets.append(0.5 * (targets[0] + targets[1]))
    for t in targets:
        if abs(t) > 1e-6 * chain.r:
            out.append(("translateJointAlongAxisOfMotion", j, t, False))
    if rolls:
        out += [("rotateJointAboutAxisOfMotion", j, roll, False),
                ("rotateJointAboutAxisOfMotion", j, -roll, False)]  # fmt: skip
    return out


def _descend(
    chain: KinematicChain,
    rng: np.random.Generator,
    kind: str,
    deadline: float | None,
    *,
    rolls: bool = True,
    delete_waypoints: bool = True,
    slide: float | None = None,
    min_slide: float | None = None,
    history: list | None = None,
) -> tuple[_State, list]:
    """Greedy descent from ``chain``: the best state found and the accepted edits."""
    r = chain.r
    tol = 1e-9 * r
    state = _State(chain, _overlap(chain), _objective(chain, kind))
    edits: list = []
    slide = 4.0 * r if slide is None else slide
    min_slide = r / 16.0 if min_slide is None else min_slide
    roll = math.pi / 2.0

    def out_of_time() -> bool:
        return deadline is not None and time.monotonic() > deadline

    def accept(new: _State, edit) -> None:
        nonlocal state
        state = new
        edits.append(edit)
        if history is not None:
            history.append(new.chain)

    if delete_waypoints:
        for j in range(len(state.chain.Joints) - 1, 0, -1):
            if out_of_time():
                break
            if state.chain.Joints[j].has_body:
                continue
            if isinstance(state.chain, KinematicTree) and len(state.chain.Children[j]) > 1:
                continue  # a branching waypoint holds its children's junction
            trial, overlap = _trial(state.chain, "delete", j, clear_only=state.overlap == 0.0)
            new = None if trial is None else _evaluate(trial, overlap, kind, state, tol)
            if new is not None:
                accept(new, ("delete", j))
    while slide >= min_slide and not out_of_time():
        improved = False
        order = rng.permutation(len(state.chain.Joints))
        for j in order:
            if out_of_time():
                break
            for name, *args in _moves(state.chain, int(j), slide, roll, rolls):
                trial, overlap = _trial(state.chain, name, *args,
                                        clear_only=state.overlap == 0.0)  # fmt: skip
                new = None if trial is None else _evaluate(trial, overlap, kind, state, tol)
                if new is not None:
                    accept(new, (name, *args))
                    improved = True
                    break
        if not improved:
            slide /= 2.0
            roll /= 2.0
    return state, edits


# --- the search over slides and rolls: dynamic programming with bans ----------------------------
#
# The tube length is a sum over links, and link k depends only on joints k - 1 and k. Over a
# finite set of candidate poses per joint (slides along and rolls about its axis), the shortest
# chain is therefore a shortest path through a layered graph (Viterbi), whose edge weights are
# the CSC lengths of all candidate pairs, computed at once by csc_lengths. Clearance is not a
# sum over links: the chosen chain is built and checked, and a collision bans the candidate of
# one of the joints it involves (the ban that costs least) before the next shortest path. The
# result then seeds finer and finer candidate sets around it (docs/clearance.md).

#: Slides (in r) around the points of a joint's axis nearest its neighbours' axes.
_COARSE_OFFSETS = (0.0, 1.0, -1.0, 2.0, -2.0, 4.0, -4.0)
#: Refinement: slide steps (in r) and roll steps (rad), one level each.
_FINE_SLIDES = (1.0, 0.5, 0.25, 0.125, 0.0625)
_FINE_ROLLS = (math.pi / 8, math.pi / 16, math.pi / 32, math.pi / 64, math.pi / 128)
#: Bans tried per level before the level gives up (keeping the previous level's chain).
_MAX_BANS = 60


def _axis_foot(p: np.ndarray, z: np.ndarray, q: np.ndarray, w: np.ndarray) -> float:
    """Parameter t of the point p + t z of line (p, z) nearest the line (q, w)."""
    c = float(z @ w)
    d = q - p
    den = 1.0 - c * c
    if den < 1e-9:  # parallel axes: the foot of q
        return float(d @ z)
    return float((d @ z - c * (d @ w)) / den)


class _Layers:
    """Candidate poses of every joint (slide t, roll theta from the joint's pose) and the CSC
    length of every candidate link."""

    def __init__(self, chain, joints: list, options: list, restarts: bool, parents=None):
        self.r = chain.r
        self.max_angle = chain.maxAnglePerElbow
        self.margin = chain.margin
        self.base = joints
        self.parents = parents  # None: a chain; else the parent of every joint (a tree)
        self.junctions = False  # trees: also require every junction's sockets to fit
        self.options = options  # per joint: (K, 2) array of (t, theta)
        self.joints = [[self._pose(j, t, th) for t, th in opts] for j, opts in enumerate(options)]
        self.costs = []  # chain: link j -> j + 1; tree: link parents[c] -> c at index c - 1
        for j in range(len(joints) - 1):
            a, b = (j, j + 1) if parents is None else (parents[j + 1], j + 1)
            A, B = self.joints[a], self.joints[b]
            Fa = np.array([c.distal_dubins_frame() for c in A])
            Fb = np.array([c.proximal_dubins_frame() for c in B])
            nA, nB = len(A), len(B)
            lengths = csc_lengths(
                np.repeat(Fa[:, :3, 3], nB, axis=0), np.repeat(Fa[:, :3, 0], nB, axis=0),
                np.tile(Fb[:, :3, 3], (nA, 1)), np.tile(Fb[:, :3, 0], (nA, 1)),
                self.r, restarts=restarts,
            )  # fmt: skip
            self.costs.append(lengths.reshape(nA, nB))

    def _pose(self, j: int, t: float, theta: float):
        joint = self.base[j]
        if t != 0.0:
            joint = joint.translated_along_z(t)
        if theta != 0.0:
            T = joint.pose_matrix
            joint = joint.transformed(rotation_about_line(T[:3, 2], T[:3, 3], theta))
        return joint

    def shortest(self, bans: set) -> tuple[float, list[int]]:
        """The shortest choice of one candidate per joint avoiding the banned (joint,
        candidate) pairs (Viterbi; ties go to the lower index)."""
        if self.parents is not None:
            return self._shortest_tree(bans)
        best = np.zeros(len(self.joints[0]))
        for bj, bc in bans:
            if bj == 0:
                best[bc] = np.inf
        back = []
        for j, cost in enumerate(self.costs):
            C = cost + best[:, None]
            for bj, bc in bans:
                if bj == j + 1:
                    C[:, bc] = np.inf
            k = np.argmin(C, axis=0)
            back.append(k)
            best = C[k, np.arange(C.shape[1])]
        last = int(np.argmin(best))
        total = float(best[last])
        choice = [last]
        for k in reversed(back):
            choice.append(int(k[choice[-1]]))
        return total, choice[::-1]

    def _shortest_tree(self, bans: set) -> tuple[float, list[int]]:
        """:meth:`shortest` on a tree: each subtree's best cost per candidate of its root,
        from the leaves up (children have larger indices than their parents)."""
        parents = self.parents
        best = [np.zeros(len(candidates)) for candidates in self.joints]
        for bj, bc in bans:
            best[bj][bc] = np.inf
        back: dict[int, np.ndarray] = {}
        for c in range(len(self.joints) - 1, 0, -1):
            C = self.costs[c - 1] + best[c][None, :]
            k = np.argmin(C, axis=1)
            back[c] = k
            best[parents[c]] = best[parents[c]] + C[np.arange(C.shape[0]), k]
        root = int(np.argmin(best[0]))
        choice = [root]
        for c in range(1, len(self.joints)):
            choice.append(int(back[c][choice[parents[c]]]))
        return float(best[0][root]), choice

    def build(self, choice: list[int], require: bool):
        """The chain (or tree) of the chosen candidates (exactly those poses), or (None, j)
        when the link into joint j cannot be built."""
        if self.parents is not None:
            chosen = [self.joints[j][c] for j, c in enumerate(choice)]
            try:
                tree = KinematicTree.from_joints(chosen, self.parents, self.max_angle)
            except NoPathError as error:
                return None, error.joint
            tree.margin = self.margin
            tree.requireClearance = require
            return tree, 0
        chain = KinematicChain(self.joints[0][choice[0]], self.max_angle, margin=self.margin)
        for j in range(1, len(choice)):
            if chain.append(self.joints[j][choice[j]], False, False, True, True) is None:
                return None, j
        chain.requireClearance = require
        return chain, 0


def _involved(elements: tuple[int, int], count: int, parents=None) -> list[int]:
    """The joints whose candidates decide the two parts' poses (``parents``: of a tree)."""
    out = set()
    for e in elements:
        if e < 0:
            continue
        if e % 2 == 0:
            out.add(e // 2)
        elif parents is None:
            out.update(((e - 1) // 2, (e + 1) // 2))
        else:
            out.update((parents[(e + 1) // 2], (e + 1) // 2))
    return sorted(j for j in out if 0 <= j < count)


def _clear_choice(layers: _Layers, motion, require: bool, deadline: float | None, keep=None):
    """The shortest clear chain over ``layers`` (bans on collisions), or None.

    ``keep``: a choice that must stay reachable (its candidates are never banned).
    """
    bans: set = set()
    protected = set() if keep is None else set(enumerate(keep))
    # a tree's branches crowd each other and its junctions add a constraint: more bans
    limit = _MAX_BANS if layers.parents is None else max(_MAX_BANS, 8 * len(layers.joints))
    for _ in range(limit):
        if deadline is not None and time.monotonic() > deadline:
            return None
        total, choice = layers.shortest(bans)
        if not math.isfinite(total):
            return None
        chain, failed = layers.build(choice, require)
        if chain is None:  # the chain's own solver found no link where the estimate did
            before = failed - 1 if layers.parents is None else layers.parents[failed]
            culprits = [before, failed]
        else:
            found = _worst(chain)
            elements = None if found is None else found.elements
            if elements is None and motion is not None:
                elements = _motion_collision(chain, motion)
            if elements is None and layers.junctions:
                problems = junction_problems(chain)
                if problems:  # a socket does not fit: that child must sit elsewhere
                    elements = (2 * problems[0][0], -1)
            if elements is None:
                return chain, choice
            culprits = _involved(elements, len(choice), layers.parents)
        options = []
        for j in culprits:
            ban = (j, choice[j])
            if ban in protected:
                continue
            value, _ = layers.shortest(bans | {ban})
            options.append((value, j, ban))
        if not options:
            return None
        value, _, ban = min(options)
        if not math.isfinite(value):
            return None
        bans.add(ban)
    return None


def _motion_collision(chain: KinematicChain | KinematicTree, motion) -> tuple[int, int] | None:
    """The most frequent colliding pair of parts (elements) when the chain (or tree) collides
    in more of the configurations of ``motion`` than allowed, else None."""
    from kinegami.clearance.engine import engine_for, tree_engine

    movable_states, limit = motion
    movable = [i for i, j in enumerate(chain.Joints) if j.stateRange() != (0.0, 0.0)]
    if not movable or movable_states.shape[1] != len(movable):
        return None
    Q = np.tile([j.state for j in chain.Joints], (movable_states.shape[0], 1))
    Q[:, movable] = movable_states
    engine = tree_engine(chain, margin=chain.margin) if isinstance(chain, KinematicTree) \
        else engine_for(chain)  # fmt: skip
    clearance, pairs = engine.worst(Q, chain.margin)
    if float(np.mean(np.isfinite(clearance))) <= limit + 1e-12:
        return None
    counts: dict = {}
    for pair in pairs:
        if pair is not None:
            counts[pair.elements] = counts.get(pair.elements, 0) + 1
    return max(counts, key=lambda e: (counts[e], e))


def _coarse_options(
    joints: list, r: float, rng: np.random.Generator | None, parents=None, fixed=frozenset()
) -> list:
    """Per joint, the first candidate set: slides around the feet of the common normals with
    its neighbours' axes (and the point itself), times four rolls when rolling matters. With
    ``rng``, the offsets are scaled and the rolls turned at random. ``fixed``: the indices (in
    ``joints``) of the joints that stay where they are (a task's end tips, a tree task's
    root)."""
    options = []
    for j in range(len(joints)):
        if (not joints[j].has_body and j > 0) or j in fixed:
            options.append(np.zeros((1, 2)))
            continue
        T = joints[j].pose_matrix
        p, z = T[:3, 3], T[:3, 2]
        feet = []
        if parents is None:
            neighbours = [k for k in (j - 1, j + 1) if 0 <= k < len(joints)]
        else:
            neighbours = [k for k in range(len(joints)) if k == parents[j] or parents[k] == j]
        for k in neighbours:
            U = joints[k].pose_matrix
            feet.append(_axis_foot(p, z, U[:3, 3], U[:3, 2]))
        scale = 1.0 if rng is None else float(rng.uniform(0.6, 1.4))
        slides = {0.0}
        for foot in feet:
            slides.update(round(foot + scale * o * r, 12) for o in _COARSE_OFFSETS)
        if len(feet) == 2:
            slides.add(round(0.5 * (feet[0] + feet[1]), 12))
        if joints[j].pathIndex() != 2:  # the path crosses the axis: rolling turns it
            phase = 0.0 if rng is None else float(rng.uniform(0.0, math.pi / 2))
            rolls = [phase + k * math.pi / 2 for k in range(4)]
            if rng is not None:
                rolls.append(0.0)  # the joint as given stays a candidate
        else:
            rolls = [0.0]
        options.append(np.array([(t, th) for t in sorted(slides) for th in rolls]))
    return options


def _fine_options(layers: _Layers, choice: list[int], level: int, fixed=frozenset()) -> list:
    """Candidates around the chosen ones: slides of 0, +-h, +-2h and rolls of 0, +-delta."""
    h = _FINE_SLIDES[level] * layers.r
    delta = _FINE_ROLLS[level]
    options = []
    for j in range(len(choice)):
        t, th = layers.options[j][choice[j]]
        if (not layers.base[j].has_body and j > 0) or j in fixed:
            options.append(np.array([(t, th)]))
            continue
        rolls = [th] if layers.base[j].pathIndex() == 2 else [th, th - delta, th + delta]
        slides = [t, t - h, t + h, t - 2 * h, t + 2 * h]
        options.append(np.array([(a, b) for a in slides for b in rolls]))
    return options


def _dp_search(chain, rng: np.random.Generator | None, motion, deadline, junctions=False,
               fixed: tuple[int, ...] = ()):  # fmt: skip
    """The shortest clear chain the layered search finds from ``chain``'s joints, or None.

    The waypoints are dropped; when no clear chain is found without them, they are tried
    where they are. ``fixed``: the indices of the joints (of ``chain``, none a waypoint but the
    root) that stay where they are.
    """
    if isinstance(chain, KinematicTree):
        kept, parents = _without_waypoints(chain)
    else:
        kept = [i for i, j in enumerate(chain.Joints) if i == 0 or j.has_body]
        parents = None
    joints = [chain.Joints[k] for k in kept]
    inside = frozenset(kept.index(k) for k in fixed if k in kept)
    found = _dp_search_joints(chain, joints, rng, motion, deadline, parents, junctions, inside)
    if found is None and len(joints) < len(chain.Joints):
        found = _dp_search_joints(chain, list(chain.Joints), rng, motion, deadline,
                                  None if parents is None else list(chain.Parents), junctions,
                                  frozenset(fixed))  # fmt: skip
    return found


def _without_waypoints(tree: KinematicTree) -> tuple[list[int], list[int]]:
    """The joints of ``tree`` to keep (the root, every joint that is not a waypoint, and the
    waypoints where the tree branches) and the parent of each among them."""
    children = tree.Children
    kept = [k for k, joint in enumerate(tree.Joints)
            if k == 0 or joint.has_body or len(children[k]) > 1]  # fmt: skip
    where = {k: i for i, k in enumerate(kept)}
    parents = []
    for k in kept:
        p = tree.Parents[k]
        while p >= 0 and p not in where:
            p = tree.Parents[p]
        parents.append(where[p] if p >= 0 else -1)
    return kept, parents


def _dp_search_joints(chain, joints: list, rng, motion, deadline, parents=None,
                      junctions=False, fixed=frozenset()):  # fmt: skip
    if len(joints) < 2:
        return None
    require = chain.requireClearance
    layers = _Layers(chain, joints, _coarse_options(joints, chain.r, rng, parents, fixed),
                     restarts=False, parents=parents)  # fmt: skip
    layers.junctions = junctions
    found = _clear_choice(layers, motion, require, deadline)
    if found is None and fixed:
        # a task's search: when no coarse choice is clear, the finer levels refine the joints
        # as given (clear where the task needs them, when the task's design is)
        layers = _Layers(chain, joints, [np.zeros((1, 2))] * len(joints), restarts=False,
                         parents=parents)  # fmt: skip
        layers.junctions = junctions
        found = _clear_choice(layers, motion, require, deadline)
    if found is None:
        return None
    best, choice = found
    for level in range(len(_FINE_SLIDES)):
        if deadline is not None and time.monotonic() > deadline:
            break
        fine = _Layers(chain, joints, _fine_options(layers, choice, level, fixed),
                       restarts=False, parents=parents)  # fmt: skip
        fine.junctions = junctions
        keep = [0] * len(choice)  # candidate 0 of every layer is the current one
        found = _clear_choice(fine, motion, require, deadline, keep=keep)
        if found is None:
            continue
        candidate, fine_choice = found
        if candidate.totalPathLength() < best.totalPathLength():
            best, choice, layers = candidate, fine_choice, fine
    return best


def _motion_configurations(chain: KinematicChain, samples: int, seed: int) -> np.ndarray:
    """(samples, movable joints) states drawn in the movable joints' ranges."""
    ranges = np.array([j.stateRange() for j in chain.Joints if j.stateRange() != (0.0, 0.0)])
    rng = np.random.default_rng([seed, 7919])
    if ranges.size == 0:
        return np.zeros((samples, 0))
    return ranges[:, 0] + (ranges[:, 1] - ranges[:, 0]) * rng.random((samples, ranges.shape[0]))


def _colliding_fraction(chain: KinematicChain, movable_states: np.ndarray) -> float:
    from kinegami.clearance import engine_for

    movable = [i for i, j in enumerate(chain.Joints) if j.stateRange() != (0.0, 0.0)]
    Q = np.tile([j.state for j in chain.Joints], (movable_states.shape[0], 1))
    Q[:, movable] = movable_states
    engine = engine_for(chain)
    return float(np.mean(engine.colliding(Q, chain.margin))) if Q.shape[0] else 0.0


def _run_start(task: tuple) -> tuple[float, float, int, KinematicChain | None]:
    """One start of :func:`compact` (a top-level function, so any executor can run it):
    (objective, overlap, start, chain), chain None when the start found no clear design."""
    chain, k, seed, kind, deadline_seconds, motion, junctions, fixed = task
    deadline = None if deadline_seconds is None else time.monotonic() + deadline_seconds
    rng = np.random.default_rng([seed, k])
    # trial builds and edits that fail or collide warn; nobody wants thousands of those. Not a
    # catch_warnings block: it is not thread-safe, and starts may run in threads (compact
    # restores the caller's filters around the whole search; worker processes keep these).
    warnings.filterwarnings("ignore", category=PlacementWarning)
    warnings.filterwarnings("ignore", category=ClearanceWarning)
    found = _dp_search(chain, None if k == 0 else rng, motion, deadline, junctions, fixed)
    if kind == "length" and found is not None:
        return tube_length(found), 0.0, k, found
    if fixed:  # the descent below may slide any joint
        return math.inf, math.inf, k, None
    # the ball (or no clear design found): greedy descent from the shortest design (or the
    # input)
    start = found if found is not None else copy.copy(chain)
    history: list = [start]
    state, _ = _descend(start, rng, kind, deadline, history=history)
    if motion is not None:

        def acceptable(candidate) -> bool:
            return _overlap(candidate) == 0.0 and _motion_collision(candidate, motion) is None

        # the last accepted design (by bisection over the descent's history) whose motion
        # collides no more often than the input's
        if acceptable(history[-1]):
            best = history[-1]
        elif not acceptable(history[0]):
            return math.inf, math.inf, k, None
        else:
            good, bad = 0, len(history) - 1
            while bad - good > 1:
                mid = (good + bad) // 2
                if acceptable(history[mid]):
                    good = mid
                else:
                    bad = mid
            best = history[good]
        return _objective(best, kind), 0.0, k, best
    return state.value, state.overlap, k, state.chain


def _check_executor(executor):
    if executor is not None and not isinstance(executor, concurrent.futures.Executor):
        raise InvalidTypeError(
            "executor must be a concurrent.futures.Executor (for example a "
            "ProcessPoolExecutor, or a Dask distributed Client's get_executor()), got "
            f"{type(executor).__name__}"
        )


def _input_problem(chain, motion_task, junctions: bool) -> tuple[str, str] | None:
    """Why the input cannot compete with the starts' results: (what the result needs, what
    the input does), or None when it is a valid result itself."""
    if _overlap(chain) != 0.0:
        found = _worst(chain)
        if found is not None and found.clearance >= 0.0:
            return "", "has parts closer than the margin"
        return "", "passes through itself"
    if motion_task is not None and _motion_collision(chain, motion_task) is not None:
        return (" and collides no more often in motion",
                "collides in more sampled configurations than allowed")  # fmt: skip
    if junctions:
        problems = junction_problems(chain)
        if problems:
            return (" and whose junctions can be made",
                    f"has a junction that cannot be made: {problems[0][1]};")  # fmt: skip
    return None


def compact(
    chain: KinematicChain | KinematicTree,
    *,
    seed: int = 0,
    motion: bool = False,
    executor: concurrent.futures.Executor | None = None,
    time_limit: float | None = None,
    progress: bool | ProgressCallback | None = None,
    objective: str = "length",
    starts: int = 4,
    samples: int = 200,
    junctions: bool = True,
    margin: float | None = None,
    targets=None,
    keep_out=(),
) -> KinematicChain | KinematicTree:
    """A shorter chain (or tree) with the same kinematics that does not pass through itself.

    Every joint keeps its type, parameters and axis line (joints only slide along and roll
    about their axes); waypoints may move, appear or disappear. The result is clear with the
    margin at the chain's current states (its closest parts at least ``margin`` apart), and
    never longer than the input when the input is clear with that margin.

    Parameters
    ----------
    chain : KinematicChain or KinematicTree
        Not changed. For a tree, every link depends on a joint and its parent, so the same
        search runs from the leaves up (docs/trees.md); waypoints where the tree branches stay
        (they hold the junction).
    seed : int
        Seed of the search (>= 0); the result depends only on it (and on ``time_limit``, when the
        limit cuts the search short), not on the executor (up to the last bit of rounding,
        which numpy may do differently in another process).
    motion : bool
        Also require that the fraction of ``samples`` random configurations in which the
        chain collides is no larger than the input's (chains only).
    executor : concurrent.futures.Executor, optional
        Runs the starts (default: a local process pool). A Dask cluster works unchanged:
        ``distributed.Client(...).get_executor()``.
    time_limit : float, optional
        Seconds each start may search (> 0); default: until no move improves.
    progress : bool or callable, optional
        ``progress(done, total)`` after each finished start (and a few times a second while
        waiting); returning False stops the search, raises :class:`~kinegami.errors.Cancelled`
        and stops the local worker processes. True or None: a progress bar on stderr (None:
        when stderr is a terminal). See docs/progress.md.
    objective : {"length", "ball"}
        Minimise the total tube length (links plus joints) or the bounding-ball radius.
    starts : int
        Number of starts (>= 1) of the layered search: the first from the joints as given,
        the others with candidate slides and rolls drawn from the seed. The input itself
        competes too when it is clear.
    samples : int
        Configurations sampled for ``motion`` (>= 1).
    junctions : bool
        Trees only: also require that every printed junction can be made, i.e. each branch
        child's socket fits on its link (:func:`kinegami.fabrication.sheets.junction_problems`).
    margin : float, optional
        The clearance required between the parts (chain units, >= 0; folded sheets have a
        thickness); default: ``chain.margin``. The result's ``margin`` is this value.
    targets : sequence of targets, optional
        A task to keep (:func:`compact_for_task`): the end tip keeps its place on the last
        movable joint's body, and a shorter design is accepted only when every target is still
        reached exactly, in range, clear with the margin and outside ``keep_out``; otherwise
        the input itself is returned. A tree's task: one list of targets per leaf (the leaves
        in the order of their tip joints), grasp k every leaf's k-th target at once; every
        leaf tip and the root stay where they are.
    keep_out : boxes no part may come near at the targets' configurations (with ``targets``).

    Raises
    ------
    CompactionError
        When the input passes through itself (or, for a tree, a socket does not fit) and no
        start found a design without the problem.
    Cancelled
        When ``progress`` returned False.

    Examples
    --------
    >>> chain = KinematicChain.from_dh([(0, np.pi / 2, 0, 0), (0, 0, 4, 0)], 4, 1)
    >>> shorter = compact(chain, executor=concurrent.futures.ThreadPoolExecutor(1))
    >>> tube_length(shorter) <= tube_length(chain)
    True
    """
    if not isinstance(chain, KinematicChain | KinematicTree):
        raise InvalidTypeError(
            f"chain must be a KinematicChain or a KinematicTree, got {type(chain).__name__}"
        )
    if targets is not None:
        return compact_for_task(chain, targets, keep_out=keep_out, margin=margin, seed=seed,
                                executor=executor, starts=starts, time_limit=time_limit,
                                progress=progress)[0]  # fmt: skip
    seed = check_int("seed", seed, minimum=0, floats=False)  # numpy seeds: ints >= 0, as sweep
    motion = check_bool("motion", motion)
    if motion and isinstance(chain, KinematicTree):
        raise InvalidParameterError(
            "motion=True is available for chains only (a tree's configurations are tested one "
            "at a time, too slowly to sweep every candidate); compact the tree with "
            "motion=False, then check its motion with kinegami.clearance.sweep"
        )
    _check_executor(executor)
    if time_limit is not None:
        time_limit = check_positive("time_limit", time_limit)
    if objective not in ("length", "ball"):
        raise InvalidParameterError(f"objective must be 'length' or 'ball', got {objective!r}")
    starts = check_starts(starts)
    samples = check_samples("samples", samples, len(chain.Joints))
    progress = check_progress(progress)
    if margin is not None:
        margin = check_margin(margin)
        if margin != chain.margin:
            chain = copy.copy(chain)  # the caller's chain keeps its own margin
            chain.margin = margin
    motion_task = None
    if motion:
        movable_states = _motion_configurations(chain, samples, seed)
        motion_task = (movable_states, _colliding_fraction(chain, movable_states))
    junctions = isinstance(chain, KinematicTree) and check_bool("junctions", junctions)
    return _search(chain, seed, executor, time_limit, progress, objective, starts, motion_task,
                   junctions)  # fmt: skip


def _search(chain, seed: int, executor, time_limit, progress, objective: str, starts: int,
            motion_task, junctions: bool, fixed: tuple[int, ...] = (),
            every: bool = False):  # fmt: skip
    """:func:`compact`'s search of checked arguments; ``motion_task``: (movable joints' states
    (S, m), the largest colliding fraction allowed) or None; ``fixed``: the indices of the
    joints that stay where they are (none a waypoint but the root). The best design, or with
    ``every`` every design found (the starts' and the input's when it is valid), best first."""
    tasks = [(chain, k, seed, objective, time_limit, motion_task, junctions, fixed)
             for k in range(starts)]  # fmt: skip
    own = executor is None
    if own:
        workers = min(starts, os.cpu_count() or 1)
        executor = concurrent.futures.ProcessPoolExecutor(max_workers=workers)
    with warnings.catch_warnings():  # the caller's filters, back after the search
        with Progress(progress, starts, desc="compact", unit="start") as bar:
            results = _run_all(executor, own, tasks, bar)
    found = [res for res in results if res[3] is not None and res[1] == 0.0
             and not (junctions and junction_problems(res[3]))]  # fmt: skip
    problem = _input_problem(chain, motion_task, junctions)
    if problem is None:
        found.append((_objective(chain, objective), 0.0, starts, copy.copy(chain)))
    if not found:
        with_margin = f" with margin {chain.margin:g}" if chain.margin else ""
        raise CompactionError(
            f"compact found no design that is clear of itself{with_margin}{problem[0]} (the input "
            f"{problem[1]} and {starts} start(s) could not fix it); try more starts or another "
            "seed"
        )
    found.sort(key=lambda res: (res[0], res[2]))
    return [res[3] for res in found] if every else found[0][3]


#: Rotations of a position target's tip frame about its point (the end tip's tube leaves
#: along the frame's x axis): the identity first, then the other five directions of x.
TIP_TURNS = (np.eye(3), np.diag([-1.0, -1.0, 1.0]), np.array([[0, -1, 0], [1, 0, 0], [0, 0, 1.0]]),
             np.array([[0, 1, 0], [-1, 0, 0], [0, 0, 1.0]]),
             np.array([[0, 0, 1], [0, 1, 0], [-1, 0, 0.0]]),
             np.array([[0, 0, -1], [0, 1, 0], [1, 0, 0.0]]))  # fmt: skip
#: The end tip's distal frame in its Pose's axes: x = Pose z (along the tube), y = Pose x,
#: z = Pose y; its origin half the tip's length along Pose z (kinegami.chain.joints.EndTip).
TIP_AXES = np.array([[0.0, 1.0, 0.0], [0.0, 0.0, 1.0], [1.0, 0.0, 0.0]])


def end_tips_at(frame: np.ndarray, numSides: int, r: float, length: float,
                turns=TIP_TURNS) -> list[EndTip]:  # fmt: skip
    """End tips of ``length`` whose distal frame is ``frame`` (4x4, world) turned by each of
    ``turns`` (3x3, in the frame's axes) about its origin, in order."""
    out = []
    for turn in turns:
        F = np.array(frame, dtype=float)
        F[:3, :3] = F[:3, :3] @ turn
        P = F.copy()
        P[:3, :3] = F[:3, :3] @ TIP_AXES.T
        P[:3, 3] = F[:3, 3] - 0.5 * length * P[:3, 2]
        out.append(EndTip(numSides, r, np.eye(4), length).with_pose(P))
    return out


def reach_clear(design, target, q0, seeds: int, margin: float, boxes=()) -> tuple:
    """``(answer, "")``: the first :func:`kinegami.reach.solve` answer of seeds 0 to
    ``seeds - 1`` (from ``q0``) that is exact, in range, clear with ``margin`` and outside the
    keep-out ``boxes``; or ``(None, why)`` with the last reason."""
    from kinegami.clearance.keep_out import keep_out_violation
    from kinegami.reach import solve

    why = ""
    for seed in range(seeds):
        answer = solve(design, target, q0=q0, seed=seed, margin=margin)
        if not answer.ok:
            why = answer.reason
            continue
        hit = keep_out_violation(design, answer.states, boxes, margin)
        if hit is None:
            return answer, ""
        why = f"it enters keep-out box {hit[0]}"
    return None, why


def repaired_vertices(design, twistPortion: float = 0.2) -> int:
    """How many vertices of ``design``'s folded form the isometry repair moves
    (:attr:`kinegami.pattern.folded.FoldedForm.repairedVertices`; a tree: summed over its
    sheets): 0 when every module folds exactly as its crease pattern says, more near a nearly
    degenerate module (an elbow that barely turns its plane, say). ``twistPortion`` as for the
    crease pattern (design files' default 0.2)."""
    from kinegami.pattern.folded import folded_form

    if isinstance(design, KinematicTree):
        from kinegami.fabrication.sheets import fabricate

        sheets = fabricate(design, twistPortion=twistPortion).sheets
        patterns = [getattr(sheet.pattern, "pattern", sheet.pattern) for sheet in sheets]
        return sum(folded_form(pattern).repairedVertices for pattern in patterns)
    return folded_form(design, twistPortion=twistPortion).repairedVertices


def _last_body(chain: KinematicChain) -> int:
    """The index of the chain's last joint that is not a waypoint (the root when none is)."""
    return max(k for k, joint in enumerate(chain.Joints) if k == 0 or joint.has_body)


def compact_for_task(chain: KinematicChain | KinematicTree, targets, answers=None, *,
                     keep_out=(), margin: float | None = None, seed: int = 0, executor=None,
                     starts: int = 4, time_limit: float | None = None, progress=None,
                     exact_fold: bool = False) -> tuple:  # fmt: skip
    """``(design, answers)``: :func:`compact` that keeps a task (docs/design-for-a-task.md).

    Compaction slides and rolls joints along their axes, which keeps each joint's motion but
    would move an end tip. Here the joints up to the last movable one are compacted, and the
    joints after it (the end tip; waypoints go) are placed again exactly where they were: on the
    last movable joint's body, so the tip's motion is unchanged (when every target is a point,
    the end tip may leave its point along any of the six axis directions: the shortest that
    keeps the task wins). The search bans choices whose joints collide at a target's
    configuration. The result is solved again for every target (from the states of
    ``answers``, one reach answer per target, or of a first solve) and accepted only when each
    is reached exactly, in range, clear with ``margin`` (default the chain's) and outside the
    ``keep_out`` boxes, with a tube no longer than the input's; otherwise the input itself is
    returned. With no targets (``[]``) this compacts the chain's kinematics as they are, its
    tip's frame kept on the last joint's body (:func:`compact` may slide the end tip, which
    moves that frame).

    A :class:`~kinegami.KinematicTree` keeps a tree task: ``targets`` is one list of targets per
    leaf (the leaves in the order of their tip joints' indices; or a mapping {tip joint index:
    list}), all of the same length, and grasp k puts every leaf's tip on its k-th target at
    once, in one configuration of the whole tree (``answers``: one reach answer per grasp).
    Every leaf tip stays where it is in the world at the tree's home states, so its frame on
    its leaf's last movable joint, and the tree's kinematics, do not change; the root stays at
    its pose (the task's base); every junction's sockets must fit. The search bans choices that
    collide at a grasp, and a shorter tree is accepted only when every grasp is still reached
    so; otherwise the input itself is returned.

    ``exact_fold``: accept only a design whose folded form needs no isometry repair
    (:func:`repaired_vertices` 0), as design for a task requires.

    Raises
    ------
    CompactionError
        When the input itself does not reach a target (a tree: a grasp) so.
    """
    from kinegami.clearance.keep_out import Box

    if not isinstance(chain, KinematicChain | KinematicTree):
        raise InvalidTypeError(
            "compaction with targets takes a KinematicChain or a KinematicTree, got a "
            f"{type(chain).__name__}"
        )
    margin = float(chain.margin) if margin is None else check_margin(margin)
    if isinstance(targets, (str, bytes)) or not isinstance(targets, (list, tuple, dict)) or \
            (isinstance(targets, dict) and isinstance(chain, KinematicChain)):  # fmt: skip
        raise InvalidTypeError(f"targets must be a list of targets, got {targets!r}")
    boxes = tuple(Box.of(b, f"keep_out box {k}") for k, b in enumerate(keep_out or ()))
    exact_fold = check_bool("exact_fold", exact_fold)
    _check_executor(executor)
    search = (check_int("seed", seed, minimum=0, floats=False), executor,
              None if time_limit is None else check_positive("time_limit", time_limit),
              check_progress(progress), "length", check_starts(starts))  # fmt: skip
    if isinstance(chain, KinematicTree):
        return _compact_tree_for_task(chain, targets, answers, boxes, margin, search,
                                      exact_fold)  # fmt: skip
    return _compact_chain_for_task(chain, targets, answers, boxes, margin, search, exact_fold)


def _compact_chain_for_task(chain: KinematicChain, targets, answers, boxes: tuple,
                            margin: float, search: tuple, exact_fold: bool) -> tuple:  # fmt: skip
    """:func:`compact_for_task` of a chain (checked arguments; ``search``: the first six
    arguments of :func:`_search` after the design)."""
    from kinegami.reach import Target

    goals = [Target.of(t) for t in targets]

    def reached(design, start) -> tuple[list | None, str]:
        found = []
        for k, goal in enumerate(goals):
            answer, why = reach_clear(design, goal, None if start is None else start[k], 4,
                                      margin, boxes)  # fmt: skip
            if answer is None:
                return None, f"target {k}: {why}"
            found.append(answer)
        return found, ""

    if answers is None:
        answers, why = reached(chain, None)
        if answers is None:
            raise CompactionError(f"the design does not reach its task before compaction: {why}")
    movable = [k for k, joint in enumerate(chain.Joints) if joint.stateRange() != (0.0, 0.0)]
    if not movable:
        return chain, answers
    last = movable[-1]
    tail = [joint for joint in chain.Joints[last + 1 :] if type(joint).__name__ != "Waypoint"]
    head = copy.copy(chain)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlacementWarning)
        warnings.simplefilter("ignore", ClearanceWarning)
        while len(head.Joints) > last + 1:
            if not head.delete(len(head.Joints) - 1):  # pragma: no cover - dropping the last
                return chain, answers
        head.margin = margin
        # the search bans the choices whose head collides at a target's configuration (as
        # compact(motion=True) does with sampled ones), so the task's configurations stay clear
        # (no targets: the tip's frame is kept on the last body, and nothing is banned)
        at_targets = np.array([np.asarray(answer.states)[movable] for answer in answers])
        search = (*search, (at_targets, 0.0) if len(answers) else None, False)
        # every start's design competes (best first), not only the best: a shorter one may
        # not keep the task, or (exact_fold) fold only after the repair
        candidates = []
        if len(tail) == 1:  # the whole chain, its end tip kept: the last link counts too
            whole = copy.copy(chain)
            whole.margin = margin
            try:
                candidates += _search(whole, *search, fixed=(_last_body(whole),), every=True)
            except CompactionError:
                pass
        try:
            heads = _search(head, *search, every=True)
        except CompactionError:
            heads = []
        tails = [tail]
        if len(tail) == 1 and isinstance(tail[0], EndTip) and \
                all(goal.kind == "position" for goal in goals):  # fmt: skip
            # a point's tip frame may turn about it: the end tip may leave in any direction
            frame = np.asarray(getattr(tail[0].DistalDubinsFrame(), "A",
                                       tail[0].DistalDubinsFrame()))  # fmt: skip
            tails = [[end] for end in end_tips_at(frame, chain.numSides, chain.r,
                                                  tail[0].neutralLength)]  # fmt: skip
        for shorter in heads:
            for joints in tails:
                trial = copy.copy(shorter)
                placed = (trial.append(joint, relative=False, safe=False, fixedPosition=True,
                                       fixedOrientation=True) for joint in joints)  # fmt: skip
                if all(index is not None for index in placed):
                    candidates.append(trial)
    for trial in sorted(candidates, key=tube_length):  # the shortest that keeps the task
        if tube_length(trial) > tube_length(chain):
            break
        if exact_fold and repaired_vertices(trial) != 0:
            continue
        new_movable = [k for k, j in enumerate(trial.Joints) if j.stateRange() != (0.0, 0.0)]
        starts_q = []
        for answer in answers:
            q = np.zeros(len(trial.Joints))
            q[new_movable] = np.asarray(answer.states)[movable]
            starts_q.append(q)
        found, _ = reached(trial, starts_q)
        if found is not None:
            return trial, found
    return chain, answers


def _leaves(tree: KinematicTree) -> list[int]:
    """The tree's leaf tips (joints without children), in index order."""
    return [k for k, children in enumerate(tree.Children) if not children]


def _tree_goals(tree: KinematicTree, targets) -> list[tuple]:
    """A tree task's targets as one tuple of reach Targets per leaf of ``tree`` (the leaves in
    index order), checked: one list per leaf (or a mapping {leaf tip: list}), all as long."""
    from kinegami.reach import Target

    leaves = _leaves(tree)
    if isinstance(targets, dict):
        if sorted(targets) != leaves:
            raise InvalidParameterError(
                f"a tree task's targets map every leaf tip {leaves} to its targets, got the "
                f"keys {sorted(targets, key=str)}"
            )
        targets = [targets[k] for k in leaves]
    if len(targets) != len(leaves):
        raise InvalidParameterError(
            f"a tree task gives one list of targets per leaf: the tree has {len(leaves)} leaves "
            f"(tips {leaves}), got {len(targets)} list(s)"
        )
    goals = []
    for i, leaf in enumerate(targets):
        if isinstance(leaf, (str, bytes)) or not isinstance(leaf, (list, tuple)):
            raise InvalidTypeError(
                f"targets[{i}] must be the list of leaf {i}'s targets (tip {leaves[i]}), got "
                f"{leaf!r}"
            )
        goals.append(tuple(Target.of(t) for t in leaf))
    counts = [len(leaf) for leaf in goals]
    if len(set(counts)) != 1 or counts[0] == 0:
        raise InvalidParameterError(
            "every leaf of a tree task needs the same number (>= 1) of targets (grasp k puts "
            f"every leaf on its k-th target at once), got {counts}"
        )
    return goals


def _compact_tree_for_task(tree: KinematicTree, targets, answers, boxes: tuple, margin: float,
                           search: tuple, exact_fold: bool) -> tuple:  # fmt: skip
    """:func:`compact_for_task` of a tree (checked arguments; ``search``: the first six
    arguments of :func:`_search` after the design)."""
    goals = _tree_goals(tree, targets)
    grasps = len(goals[0])
    if answers is not None and len(answers) != grasps:
        raise InvalidParameterError(
            f"answers must be one reach answer per grasp ({grasps}), got {len(answers)}"
        )

    def reached(design, start) -> tuple[list | None, str]:
        tips = _leaves(design)
        found = []
        for k in range(grasps):
            mapping = {tip: leaf[k] for tip, leaf in zip(tips, goals, strict=True)}
            answer, why = reach_clear(design, mapping, None if start is None else start[k], 4,
                                      margin, boxes)  # fmt: skip
            if answer is None:
                return None, f"grasp {k}: {why}"
            found.append(answer)
        return found, ""

    if answers is None:
        answers, why = reached(tree, None)
        if answers is None:
            raise CompactionError(f"the design does not reach its task before compaction: {why}")
    movable = [k for k, joint in enumerate(tree.Joints) if joint.stateRange() != (0.0, 0.0)]
    if not movable:
        return tree, answers
    whole = copy.copy(tree)
    whole.margin = margin
    # the leaf tips stay where they are (their frames on their leaves' last movable joints do
    # not change) and so does the root; the search bans the choices that collide at a grasp
    at_grasps = np.array([np.asarray(answer.states)[movable] for answer in answers])
    try:
        trials = _search(whole, *search, (at_grasps, 0.0), True, fixed=(0, *_leaves(tree)),
                         every=True)  # fmt: skip
    except CompactionError:
        return tree, answers
    for trial in trials:  # the shortest that keeps the task
        # not shorter (the input itself may win the search): the input, unchanged
        if tube_length(trial) >= tube_length(tree):
            break
        new_movable = [k for k, j in enumerate(trial.Joints) if j.stateRange() != (0.0, 0.0)]
        if len(_leaves(trial)) != len(goals) or len(new_movable) != len(movable) or \
                (exact_fold and repaired_vertices(trial) != 0):  # fmt: skip
            continue
        starts_q = []
        for answer in answers:
            q = np.zeros(len(trial.Joints))
            q[new_movable] = np.asarray(answer.states)[movable]
            starts_q.append(q)
        found, _ = reached(trial, starts_q)
        if found is not None:
            return trial, found
    return tree, answers


def _run_all(executor, own: bool, tasks: list, bar: Progress) -> list:
    """Run every start on ``executor``, reporting to ``bar``; cancel the rest and re-raise on
    any error, Ctrl-C or :class:`Cancelled` (stopping our own pool's workers at once)."""
    results = []
    futures = []
    try:
        futures = [executor.submit(_run_start, task) for task in tasks]
        pending = set(futures)
        while pending:
            finished, pending = concurrent.futures.wait(
                pending, timeout=0.1, return_when=concurrent.futures.FIRST_COMPLETED
            )
            for future in finished:
                results.append(future.result())
            if finished:
                bar.update(len(finished))
            else:
                bar.check()  # a heartbeat: the callback may cancel while starts run
    except BaseException:
        for future in futures:
            future.cancel()
        if own:
            _stop_workers(executor)
        raise
    finally:
        if own:
            executor.shutdown(wait=True, cancel_futures=True)
    return results


def _stop_workers(executor: concurrent.futures.Executor) -> None:
    """Stop the worker processes of our own process pool now (their starts are abandoned)."""
    if hasattr(executor, "terminate_workers"):  # Python >= 3.14
        executor.terminate_workers()
        return
    for process in list((getattr(executor, "_processes", None) or {}).values()):
        process.terminate()


def shorten_by_axis_translations(
    chain: KinematicChain,
    step: float | None = None,
    rounds: int = 6,
    minStep: float | None = None,
) -> list[tuple[int, float]]:
    """Shorten the chain's tube by sliding joints along their axes (greedy, in place).

    The slide-only, single-start form of :func:`compact`, kept under its original name: each
    round tries, for every joint, slides by +-step and to the points of its axis nearest its
    neighbours (only that joint moves; ``propagate=False``) and keeps the first that shortens
    the tube without making the chain pass through itself. The step halves after a round
    that improves nothing, ``rounds`` times or down to ``minStep``.

    Parameters
    ----------
    chain : the chain, edited in place.
    step : first slide length (chain units; default 4 r).
    rounds : number of halvings of the step (>= 0).
    minStep : stop below this step (default r / 8).

    Returns the accepted edits as (joint index, distance) pairs, in order; replaying them with
    ``translateJointAlongAxisOfMotion(j, d, propagate=False)`` rebuilds the result.
    """
    if not isinstance(chain, KinematicChain):
        raise InvalidTypeError(f"chain must be a KinematicChain, got {type(chain).__name__}")
    step = 4.0 * chain.r if step is None else check_positive("step", step)
    minStep = chain.r / 8.0 if minStep is None else check_positive("minStep", minStep)
    rounds = check_int("rounds", rounds, minimum=0)
    min_slide = max(minStep, step / 2.0**rounds)
    with warnings.catch_warnings():  # trial edits: rejected ones and colliding ones warn
        warnings.simplefilter("ignore", PlacementWarning)
        warnings.simplefilter("ignore", ClearanceWarning)
        state, edits = _descend(
            chain, np.random.default_rng(0), "length", None, rolls=False,
            delete_waypoints=False, slide=step, min_slide=min_slide,
        )  # fmt: skip
    if state.chain is not chain:
        with warnings.catch_warnings():  # the intermediate designs were measured already
            warnings.simplefilter("ignore", ClearanceWarning)
            for _, j, distance, _ in edits:
                chain.translateJointAlongAxisOfMotion(j, distance, propagate=False)
        if state.overlap > 0.0:
            found = worst_overlap(chain.Joints, chain.Links, chain.r)
            warnings.warn(
                ClearanceWarning(
                    f"shorten_by_axis_translations: the chain still passes through itself "
                    f"({found})", found.clearance, found.first, found.second,
                ),
                stacklevel=2,
            )  # fmt: skip
    return [(int(j), float(distance)) for _, j, distance, _ in edits]
