"""JointAssembly, what a chain and a tree share: append joints, place them, edit them, set
their states.

See docs/theory/chain.md (frames, balls, edits) and docs/placement.md (placement).

The chain holds joints in world coordinates and, for every joint i >= 1, the link ``Links[i]``
from joint i-1's distal Dubins frame to joint i's proximal Dubins frame (``Links[0]`` is the
empty path at the root). Joints and links are values; every operation computes the new lists
and the new bounding ball first and swaps them in only when everything succeeded, so a failed
append, edit or state change leaves the chain bit-identical.
"""

from __future__ import annotations

import math
import os
import sys
import warnings
from collections.abc import Mapping, Sequence, Set

import numpy as np

from kinegami.chain.bodies import check_margin, link_capsule_ends, overlaps, worst_overlap
from kinegami.chain.joints import Joint, check_same_tube, pose_array
from kinegami.chain.links import LinkCSC
from kinegami.chain.placement import (
    compact_lambda,
    compact_lambda_other_side,
    orient_by_common_normal,
    published_safe_placement,
    radial_safe_placement,
)
from kinegami.errors import (
    ClearanceWarning,
    InvalidParameterError,
    InvalidTypeError,
    JointIndexError,
    KinegamiError,
    PlacementWarning,
)
from kinegami.geometry.balls import Ball, merge_balls
from kinegami.geometry.frames import rotation_about_line, translation
from kinegami.geometry.screws import JointScrews
from kinegami.validation import (
    check_bool,
    check_max_angle_per_elbow,
    check_real,
    check_translation,
    joint_count_refusal,
    shown,
)

__all__ = [
    "JointAssembly",
    "RADIAL_VARIANTS",
    "SAFE_GROWTH_LIMIT",
    "SAFE_PATH_LIMIT",
    "caller_stack_level",
    "propagate_flag",
    "PROPAGATE_DEFAULT",
]

#: The kinegami package folder: frames in files under it are not the user's.
_PACKAGE_DIR = os.path.dirname(os.path.dirname(os.path.abspath(__file__)))


def caller_stack_level() -> int:
    """Stack level of the first frame outside the kinegami package (for warnings)."""
    frame = sys._getframe(1)
    level = 1
    while frame is not None and frame.f_code.co_filename.startswith(_PACKAGE_DIR):
        frame = frame.f_back
        level += 1
    return level


class _DefaultTrue:
    """The default of ``propogate``: True, but distinguishable from an explicit True."""

    def __bool__(self) -> bool:
        return True

    def __repr__(self) -> str:
        return "True"


PROPAGATE_DEFAULT = _DefaultTrue()


def propagate_flag(propogate, propagate) -> bool:
    """Accept the paper's spelling ``propogate`` and the correct ``propagate`` (not both)."""
    if propagate is None:
        if propogate is PROPAGATE_DEFAULT:
            return True
        return check_bool("propogate", propogate)
    propagate = check_bool("propagate", propagate)
    if propogate is not PROPAGATE_DEFAULT:
        raise InvalidParameterError(
            f"give only one of propogate (the paper's spelling) and propagate, got "
            f"propogate={propogate!r} and propagate={propagate!r}"
        )
    return propagate


class JointAssembly:
    """What a chain and a tree share: the root, joints and links in world coordinates, one
    bounding ball, placement of new joints and the all-or-nothing commit of every change.

    ``Links[i]`` runs from the distal Dubins frame of joint i's parent to joint i's proximal
    Dubins frame (``Links[0]`` is the empty path at the root). Subclasses say who the parent is
    (:class:`KinematicChain`: joint i - 1; :class:`kinegami.tree.KinematicTree`: any earlier
    joint) and how clearance is measured.
    """

    def __init__(
        self,
        startJoint: Joint,
        maxAnglePerElbow: float = np.pi / 2,
        requireClearance: bool = False,
        margin: float = 0.0,
    ):
        if not isinstance(startJoint, Joint):
            raise InvalidTypeError(f"startJoint must be a Joint, got {type(startJoint).__name__}")
        if startJoint.closes_end:
            raise InvalidParameterError("startJoint cannot be an EndTip (nothing may follow it)")
        self.maxAnglePerElbow = check_max_angle_per_elbow(maxAnglePerElbow)
        self.requireClearance = requireClearance
        self.margin = margin
        self.numSides = startJoint.numSides
        self.r = startJoint.r
        root = startJoint._copy()
        self._joints: list[Joint] = [root]
        self._links: list[LinkCSC] = [self._root_link(root)]
        ball = root.boundingBall()
        if ball.r < self.r:
            ball = Ball(root.pose_matrix[:3, 3], self.r)
        self._ball = ball

    @property
    def requireClearance(self) -> bool:
        """Reject appends, edits and state changes that would make the chain pass through
        itself (False: apply them and emit a ClearanceWarning naming the parts)."""
        return self._require_clearance

    @requireClearance.setter
    def requireClearance(self, value: bool) -> None:
        self._require_clearance = check_bool("requireClearance", value)

    @property
    def margin(self) -> float:
        """The clearance the design requires between its parts (chain units, >= 0; default 0:
        parts that touch are clear): what :meth:`clearance`, placement's clearance test, edits
        under ``requireClearance`` and :func:`kinegami.optimize.compact` use (docs/clearance.md).
        """
        return self._margin

    @margin.setter
    def margin(self, value: float) -> None:
        self._margin = check_margin(value)

    # --- published read-only views -----------------------------------------------------------
    @property
    def Joints(self) -> tuple[Joint, ...]:
        """The joints, in order (world coordinates)."""
        return tuple(self._joints)

    @property
    def Links(self) -> tuple[LinkCSC, ...]:
        """``Links[i]`` joins joint i-1's distal frame to joint i's proximal frame."""
        return tuple(self._links)

    @property
    def boundingBall(self) -> Ball:
        """A ball (centre ``c``, radius ``r``) containing every joint and link."""
        return self._ball

    def __len__(self) -> int:
        return len(self._joints)

    def totalPathLength(self) -> float:
        """Sum of the centreline lengths of all links."""
        return float(sum(link.path.length for link in self._links))

    # --- helpers -----------------------------------------------------------------------------
    def _root_link(self, root: Joint) -> LinkCSC:
        frame = root.proximal_dubins_frame()
        return LinkCSC._between(self.r, self.maxAnglePerElbow, frame, frame)

    def _link(self, parent: Joint, child: Joint) -> LinkCSC:
        return LinkCSC._between(
            self.r,
            self.maxAnglePerElbow,
            parent.distal_dubins_frame(),
            child.proximal_dubins_frame(),
        )

    def _index(self, jointIndex, name: str = "jointIndex") -> int:
        if isinstance(jointIndex, bool) or not isinstance(jointIndex, int | np.integer):
            raise InvalidTypeError(f"{name} must be an integer, got {shown(jointIndex)}")
        n = len(self._joints)
        j = int(jointIndex)
        if not -n <= j < n:
            raise JointIndexError(
                f"{name} must be in [{-n}, {n - 1}] for a {self._noun} of {n} joints, "
                f"got {shown(j)}"
            )
        return j % n

    @staticmethod
    def _merge_link_and_joint(ball: Ball, link: LinkCSC, joint: Joint) -> Ball:
        ball = merge_balls(ball, link.arc2Ball)
        ball = merge_balls(ball, link.arc1Ball)
        return merge_balls(ball, joint.boundingBall())

    @staticmethod
    def _ball_of(joints: Sequence[Joint], links: Sequence[LinkCSC]) -> Ball:
        """The chain ball in the reference's recompute order (docs/theory/chain.md §2)."""
        ball = joints[0].boundingBall()
        for joint in joints[1:]:
            ball = merge_balls(ball, joint.boundingBall())
        for link in links:
            ball = merge_balls(ball, link.arc1Ball)
            ball = merge_balls(ball, link.arc2Ball)
        return ball

    def _overlap(self, joints, links, parents, since: int = 0):
        """The closest pair of the given lists closer than the margin (an Overlap) or None;
        with ``since`` = k only pairs with a part of joint k or later (docs/clearance.md).
        ``parents`` as :meth:`_extended` returns them (a chain ignores them).

        Placement tests its candidate (``since`` > 0) and then commits the same lists, which
        are built for it and never changed: the last such answer is kept for that commit.
        """
        if since > 0:
            last = self.__dict__.get("_placement_check")
            if (last is not None and last[0] is joints and last[1] is links
                    and last[2] == (since, self._margin)):  # fmt: skip
                return last[3]
        found = worst_overlap(joints, links, self.r, since=since, margin=self._margin)
        if since > 0:
            self._placement_check = (joints, links, (since, self._margin), found)
        return found

    def _clear_of(self, joints, links, parents, since: int) -> bool:
        """Whether the parts of joint ``since`` on are clear of everything (placement's test
        of a candidate): ``_overlap(..., since) is None``, told by
        :func:`~kinegami.chain.bodies.overlaps`, which stops at a colliding candidate's first
        overlapping pairs. A clear answer has measured every pair ``_overlap`` would: it is
        kept as ``_overlap``'s answer (None) for the commit of the same lists."""
        if overlaps(joints, links, self.r, since=since, margin=self._margin):
            return False
        if since > 0:
            self._placement_check = (joints, links, (since, self._margin), None)
        return True

    def _own_overlap(self):
        """The deepest overlap of the chain as it is (an Overlap) or None, computed once per
        committed set of lists (they are replaced, never changed, by every operation)."""
        memo = self.__dict__.get("_overlap_memo")
        if (memo is not None and memo[0] is self._joints and memo[1] is self._links
                and memo[3] == self._margin):  # fmt: skip
            return memo[2]
        found = self._overlap(self._joints, self._links, self._parent_list())
        self._overlap_memo = (self._joints, self._links, found, self._margin)
        return found

    def _accept(self, what: str, joints, links, ball: Ball | None = None, parents=None,
                extends: bool = False) -> bool:  # fmt: skip
        """Commit the new lists unless they pass through themselves and the chain requires
        clearance (then warn PlacementWarning, keep the chain, return False); a commit that
        leaves the chain self-intersecting emits a ClearanceWarning.

        ``extends``: the new lists are the chain's own followed by new joints (placement), so
        only pairs with a new part are measured, against the chain's known deepest overlap:
        the cost of a placement does not grow with the chain's length.
        """
        if extends and self._placement_adds_pairs_only:
            first_new = len(self._joints)
            found = self._overlap(joints, links, parents, first_new)
            before = self._own_overlap()
            if before is not None and (found is None or before.clearance < found.clearance):
                found = before
        else:
            found = self._overlap(joints, links, parents)
        if found is not None and self._require_clearance:
            self._reject(f"{what} failed: the {self._noun} would pass through itself ({found})")
            return False
        self._commit(joints, links, ball, parents)
        self.__dict__.pop("_placement_check", None)
        self._overlap_memo = (self._joints, self._links, found, self._margin)
        if found is not None:
            warnings.warn(
                ClearanceWarning(
                    f"{what}: the {self._noun} passes through itself ({found})",
                    found.clearance, found.first, found.second,
                ),
                stacklevel=caller_stack_level(),
            )  # fmt: skip
        return True

    def _commit(self, joints: list[Joint], links: list[LinkCSC], ball: Ball | None = None,
                parents=None):  # fmt: skip
        """Swap in new lists (``parents``: a tree's new parent list; a chain ignores it)."""
        if ball is None:
            ball = self._ball_of(joints, links)
        self._joints, self._links, self._ball = joints, links, ball
        home = self.__dict__.get("_home")
        if home is not None and home[4] is joints:  # a change of states from home
            home[3], home[4] = joints, None

    def recomputeBoundingBall(self) -> Ball:
        """Recompute the ball from every joint and link (docs/theory/chain.md §2) and return it."""
        self._ball = self._ball_of(self._joints, self._links)
        return self._ball

    #: What the messages call the assembly.
    _noun = "chain"
    #: Whether placing a joint only adds pairs of parts to test (true of a chain; in a tree a
    #: new sibling also changes the junction its older siblings share).
    _placement_adds_pairs_only = True

    def _reject(self, message: str) -> None:
        warnings.warn(
            f"{message}; the {self._noun} is unchanged", PlacementWarning,
            stacklevel=caller_stack_level(),
        )  # fmt: skip

    def _parent_list(self) -> list[int]:
        """The parent of every joint (-1 for the root)."""
        return list(range(-1, len(self._joints) - 1))

    def fkine(self, q=None, tip=None, tool=None):
        """The tip's pose at ``q`` (default: the current states): a 4x4 array, (m, 4, 4) for
        configurations (m, n); one state per joint of ``Joints``. See kinegami.reach."""
        from kinegami.reach.forward import kinematics

        return kinematics(self, tip, tool).fkine(self._states_or(q))

    def jacob0(self, q=None, tip=None, tool=None):
        """The tip's geometric Jacobian in the world frame at ``q`` (default: the current
        states), rows (v, ω), one column per joint of ``Joints``. See kinegami.reach."""
        from kinegami.reach.forward import kinematics

        return kinematics(self, tip, tool).jacob0(self._states_or(q))

    def ikine(self, target, **options):
        """States that put the tip on ``target`` (a pose, a position, a Target; a tree: a
        mapping of tip to target), clear of itself: ``kinegami.reach.solve(self, target,
        **options)``'s answer (``.ok``, ``.states``, ``.reason``). See kinegami.reach."""
        from kinegami.reach.inverse import solve

        return solve(self, target, **options)

    def _states_or(self, q):
        """``q``, or the current states when None."""
        return [joint.state for joint in self._joints] if q is None else q

    def joint_screws(self) -> JointScrews:
        """The joints as screws about their axes at the current states: the one forward
        kinematics of chains, trees and the clearance engine (kinegami.geometry.screws)."""
        joints = self._joints
        poses = np.array([joint.pose_matrix for joint in joints]).reshape(len(joints), 4, 4)
        return JointScrews([joint.motion for joint in joints], poses[:, :3, 2], poses[:, :3, 3],
                           self._parent_list(), [joint.state for joint in joints])  # fmt: skip

    def _configured(self, values: Sequence[float]) -> tuple[list, list]:
        """Joint and link lists at the (checked) states ``values``, one per joint, moved from
        the home lists (:meth:`_home_lists`) by the forward kinematics of their screws: every
        joint and link beyond a state that differs from home moves, the others are the home
        objects. Each configuration is one motion from home, never a motion from the last
        one, so rounding does not build up over many state changes (it did: 300 random
        setJointStates of the 9-joint spherical series had moved its tip 0.1 r)."""
        home = self._home_lists()
        if all(float(v) == joint.state for v, joint in zip(values, self._joints, strict=True)):
            joints = list(self._joints)
            home[4] = joints  # the same configuration: still made from home
            return joints, list(self._links)
        joints, links = list(home[0]), list(home[1])
        changed = [float(v) != joint.state for v, joint in zip(values, joints, strict=True)]
        A = home[2].joint_motions(np.asarray(values, dtype=float))
        moved = [False] * len(joints)  # whether joint k's distal side moves
        for k, p in enumerate(self._parent_list()):
            upstream = p >= 0 and moved[p]
            if upstream:
                joints[k] = joints[k].transformed(A[p])
                links[k] = links[k].transformed(A[p])
            if changed[k]:
                joints[k] = joints[k].with_state(values[k])
            moved[k] = upstream or changed[k]
        home[4] = joints  # committed, these lists are still home's (:meth:`_commit`)
        return joints, links

    def _home_lists(self) -> list:
        """[joints, links, screws, committed, candidate]: the lists as the last operation that
        was not a change of states left them, with their screws; ``committed`` is the chain's
        current joint list when it was made from home by states, ``candidate`` the last list
        :meth:`_configured` made. Any other operation makes the current lists home."""
        home = self.__dict__.get("_home")
        if home is None or home[3] is not self._joints:
            home = [self._joints, self._links, self.joint_screws(), self._joints, None]
            self._home = home
        return home

    def _parent_of(self, j: int) -> int:
        """The parent of joint j > 0 (a chain: j - 1)."""
        return j - 1

    def _children_of(self, j: int) -> list[int]:
        """The children of joint j (a chain: j + 1, if there is one)."""
        return [j + 1] if j + 1 < len(self._joints) else []

    def _subtree(self, j: int) -> list[int]:
        """j and every joint that moves with it, in index order (a chain: j to the end)."""
        return list(range(j, len(self._joints)))

    # --- edits shared by chains and trees (docs/theory/chain.md §5, docs/trees.md) -------------
    def _moved(self, j: int, T: np.ndarray, propagate: bool):
        """New joint and link lists with joint j moved by world transform T: with propagation
        its subtree moves along and only the link into j is re-solved; without, the links into
        j and to its children are re-solved."""
        joints = list(self._joints)
        links = list(self._links)
        joints[j] = joints[j].transformed(T)
        if propagate:
            for k in self._subtree(j)[1:]:
                joints[k] = joints[k].transformed(T)
                links[k] = links[k].transformed(T)
        else:
            for k in self._children_of(j):
                links[k] = self._link(joints[j], joints[k])
        if j > 0:
            links[j] = self._link(joints[self._parent_of(j)], joints[j])
        else:
            links[0] = links[0].transformed(T)
        return joints, links

    def transformJoint(
        self,
        jointIndex: int,
        Transformation,
        propogate: bool = PROPAGATE_DEFAULT,
        *,
        propagate: bool | None = None,
    ) -> bool:
        """Move joint ``jointIndex`` by the world transform ``Transformation``.

        With propagation everything after it moves with it (a chain: every later joint; a
        tree: its subtree) and only the link into the joint is re-solved; without, only this
        joint moves (the link into it and the links to its children are re-solved). Returns
        True, or False with a PlacementWarning (nothing changed) when a link cannot be built.
        The translation of ``Transformation`` lies within +-1e6 r (InvalidParameterError
        otherwise).
        """
        j = self._index(jointIndex)
        T = pose_array(Transformation, "Transformation", r=self.r)
        prop = propagate_flag(propogate, propagate)
        return self._try_edit("transformJoint", lambda: self._moved(j, T, prop))

    def _axis_edit(
        self, what: str, jointIndex, T_of_joint, propogate, propagate, applyToPreviousWaypoint
    ) -> bool:
        """Move joint ``jointIndex`` by ``T_of_joint(joint)``; with applyToPreviousWaypoint a
        Waypoint parent moves too, when j is its only child (otherwise j's siblings would)."""
        j = self._index(jointIndex)
        prop = propagate_flag(propogate, propagate)
        applyToPreviousWaypoint = check_bool("applyToPreviousWaypoint", applyToPreviousWaypoint)
        T = T_of_joint(self._joints[j])
        w = self._parent_of(j) if j > 0 else -1
        if (
            applyToPreviousWaypoint
            and w >= 0
            and not self._joints[w].has_body
            and self._children_of(w) == [j]
        ):
            if prop:
                return self._try_edit(what, lambda: self._moved(w, T, True))

            def both():
                joints = list(self._joints)
                joints[w] = joints[w].transformed(T)
                joints[j] = joints[j].transformed(T)
                links = list(self._links)
                for k in [w, j, *self._children_of(j)]:
                    if k == 0:
                        links[0] = links[0].transformed(T)
                    else:
                        links[k] = self._link(joints[self._parent_of(k)], joints[k])
                return joints, links

            return self._try_edit(what, both)
        return self._try_edit(what, lambda: self._moved(j, T, prop))

    # --- placement ----------------------------------------------------------------------------
    def _place(
        self, what: str, p: int, newJoint: Joint, relative, safe, fixedPosition, fixedOrientation
    ) -> int | None:
        """Add ``newJoint`` as a child of joint ``p`` (append / addJoint; docs/placement.md):
        the new joint's index, or None with a PlacementWarning (nothing changed)."""
        if (full := joint_count_refusal(len(self._joints), self._noun)) is not None:
            self._reject(f"{what} failed: {full}")
            return None
        relative = check_bool("relative", relative)
        safe = check_bool("safe", safe)
        fixedPosition = check_bool("fixedPosition", fixedPosition)
        fixedOrientation = check_bool("fixedOrientation", fixedOrientation)
        if safe and fixedPosition:
            raise InvalidParameterError(
                "safe=True and fixedPosition=True cannot be combined: safe placement moves the "
                "joint along its axis; pass safe=False to keep the given position"
            )
        if safe and fixedOrientation:
            raise InvalidParameterError(
                "safe=True and fixedOrientation=True cannot be combined; pass safe=False to "
                "keep the given orientation"
            )
        check_same_tube(newJoint, self.numSides, self.r)
        if newJoint.closes_start:
            raise InvalidParameterError(f"a StartTip can only be the first joint of a {self._noun}")
        parent = self._joints[p]
        if parent.closes_end:
            raise InvalidParameterError(
                "nothing can be appended after an EndTip" if self._noun == "chain"
                else f"joint {p} is an EndTip: nothing can follow it"
            )  # fmt: skip

        joint = newJoint._copy()
        if relative:
            joint = joint.with_pose(parent.pose_matrix @ joint.pose_matrix)

        try:
            if safe:
                joints, links, ball, parents = self._safe_extension(p, joint)
            elif fixedPosition:
                if not fixedOrientation:
                    joint = orient_by_common_normal(joint, parent.pose_matrix)
                joints, links, ball, parents = self._extended([joint], p)
            else:
                joints, links, ball, parents = self._compact_extension(p, joint, fixedOrientation)
        except KinegamiError as error:
            self._reject(f"{what} failed: {error}")
            return None
        if not self._accept(what, joints, links, ball, parents, extends=True):
            return None
        return len(joints) - 1

    def _compact_extension(self, p: int, joint: Joint, fixedOrientation: bool):
        """Compact placement (docs/placement.md): the extended lists and ball; raises on failure.

        The joint slides along its axis to the point the published rule picks. If no link
        reaches it there, or its link passes through the chain, the clearance boundary on the
        other side of the ball is tried (the rule's side choice is arbitrary in the tie case);
        a self-intersecting result is kept only when neither side is clear.
        """
        parent = self._joints[p]
        at = joint.pose_matrix[:3, 3]
        z = joint.pose_matrix[:3, 2]
        clearance = 4.0 * self.r + self._ball.r + joint.bounding_radius()
        lam = compact_lambda(parent.pose_matrix[:3, 3], at, z, self._ball, clearance, self.r)
        other = compact_lambda_other_side(at, z, self._ball, clearance, self.r)
        error = None
        first = None
        for slide in (lam, other):
            if slide is None:
                continue
            placed = joint.translated_along_z(slide)
            if not fixedOrientation:
                placed = orient_by_common_normal(placed, parent.pose_matrix)
            try:
                extended = self._extended([placed], p)
            except KinegamiError as failure:
                error = error or failure
                continue
            # the rule's choice if it is clear of the chain, else the other side if that is
            if self._clear_of(extended[0], extended[1], extended[3], len(self._joints)):
                return extended
            first = first or extended
        if first is not None:
            return first  # nothing clear: kept, and append warns (ClearanceWarning)
        raise error

    def _extended(self, new_joints: list[Joint], p: int):
        """Lists, ball and parents with ``new_joints`` appended as a sub-chain from joint ``p``
        (links solved); raises on failure."""
        joints = list(self._joints)
        links = list(self._links)
        parents = self._parent_list()
        ball = self._ball
        previous = p
        for joint in new_joints:
            link = self._link(joints[previous], joint)
            ball = self._merge_link_and_joint(ball, link, joint)
            parents.append(previous)
            previous = len(joints)
            joints.append(joint)
            links.append(link)
        return joints, links, ball, parents

    def _safe_extension(self, p: int, joint: Joint):
        """Safe placement: the extended lists and ball (docs/placement.md).

        Candidates, in order: the published rule with the joint's path direction as given, then
        reversed (docs/placement.md). The first that succeeds, stays close (ball growth at
        most SAFE_GROWTH_LIMIT r, new links at most SAFE_PATH_LIMIT r long) and does not pass
        through the chain (its new parts clear of every part before them, docs/clearance.md)
        is kept, so the published results are reproduced wherever the published rule works.
        Otherwise the radial construction, which always succeeds and grows the ball by a
        bounded amount, is used (its first variant that is clear, see RADIAL_VARIANTS) unless
        a clear published candidate is no worse on both counts.
        """
        parent = self._joints[p]
        distal = parent.distal_frame()
        k = parent.pathIndex()
        limits = (SAFE_GROWTH_LIMIT * self.r, SAFE_PATH_LIMIT * self.r)
        first_new = len(self._joints)

        def clear(extended) -> bool:
            joints, links, _, parents = extended
            return self._clear_of(joints, links, parents, first_new)

        fallbacks = []
        for reverse in (False, True) if self._published_placement_allowed(p) else ():
            try:
                extended = self._extended(
                    published_safe_placement(distal, k, joint, self._ball, reverse=reverse), p
                )
            except KinegamiError:
                continue
            cost = self._cost(extended)
            ok = clear(extended)
            if ok and cost[0] <= limits[0] and cost[1] <= limits[1]:
                return extended
            fallbacks.append((cost, ok, extended))
        radial = None
        error = None
        for variant in self._radial_variants(distal, k, p):
            try:
                candidate = self._extended(
                    radial_safe_placement(distal, k, joint, self._ball, **variant), p
                )
            except KinegamiError as failure:
                error = error or failure
                continue
            radial = radial or candidate
            if clear(candidate):
                radial = candidate
                break
        else:
            # no radial variant is clear: a clear published candidate, if any, else the first
            for _, ok, extended in fallbacks:
                if ok:
                    return extended
            if radial is None:
                if fallbacks:
                    return fallbacks[0][2]
                raise error
            return radial
        growth_r, path_r = self._cost(radial)
        for (growth, path), ok, extended in fallbacks:
            if ok and growth <= max(growth_r, limits[0]) and path <= max(path_r, limits[1]):
                return extended
        return radial

    def _published_placement_allowed(self, p: int) -> bool:
        """Whether safe placement may try the published rule under joint ``p`` (a tree says
        no for a parent that already has a child: the rule would reuse that child's ray)."""
        return True

    def _radial_variants(self, distal: np.ndarray, k: int, p: int):
        """RADIAL_VARIANTS, then the same escaping sideways first: away from the tube that
        arrived at the parent (for a parent reached by a U-turn), then out of the plane of
        that U-turn on either side; then RADIAL_VARIANTS again, holding straight on until past
        every capsule of that tube before turning towards the joint (its U-turn fitting can
        reach far behind the parent, where the joint may be); last, escaping sideways and then
        holding (the joint's axis runs beside the parent and the arriving tube crosses it)."""
        yield from RADIAL_VARIANTS
        A, d1 = distal[:3, 3], distal[:3, k]
        arrived = self._links[p]
        path = arrived.path
        if path.length <= 0.0:
            return
        away = A - 0.5 * (np.asarray(path.q1) + np.asarray(path.q2))
        away = away - float(away @ d1) * d1
        escapes = ()
        if float(np.linalg.norm(away)) >= 1e-9 * self.r:
            side = np.cross(d1, away)
            escapes = (away, side, -side)
        for escape in escapes:
            for variant in RADIAL_VARIANTS:
                yield {**variant, "escape": escape}
        past = link_capsule_ends(arrived)
        for variant in RADIAL_VARIANTS:
            yield {**variant, "hold_past": past}
        for escape in escapes:
            for variant in RADIAL_VARIANTS[:2]:  # a lead would only lengthen the hold
                yield {**variant, "escape": escape, "hold_past": past}

    def _state_value(self, j: int, newState) -> float | None:
        """``newState`` of setJointState checked for joint ``j``: a real number (else
        InvalidTypeError) in the joint's range (else rejected with a PlacementWarning: None)."""
        s = check_real("newState", newState)
        return None if self._rejected_state("setJointState", j, s) else s

    def _rejected_state(self, operation: str, j: int, s: float) -> bool:
        """Whether ``s`` lies outside joint ``j``'s range; if so, the operation is rejected
        (PlacementWarning naming the joint, the state and the range)."""
        joint = self._joints[j]
        lo, hi = joint.stateRange()
        if lo <= s <= hi:
            return False
        self._reject(
            f"{operation} failed: state {s!r} of joint {j} ({type(joint).__name__}) "
            f"is outside its range [{lo:.6g}, {hi:.6g}]"
        )
        return True

    def _state_values(self, states) -> list[float] | None:
        """``states`` of setJointStates checked: a sequence (list, tuple, 1-D numpy array) of
        one real number per joint, each in its joint's range. Anything else (a number, None, a
        string, a generator, a dict or a set, whose order is not the joints') raises
        InvalidTypeError; a state out of range is rejected (PlacementWarning) and gives None."""
        try:
            if isinstance(states, str | bytes | Mapping | Set):
                raise TypeError
            count = len(states)  # a 0-d numpy array has __len__ but raises TypeError
        except TypeError:
            raise InvalidTypeError(
                f"states must be a sequence of numbers, got {shown(states)}"
            ) from None
        if count != len(self._joints):
            raise InvalidParameterError(
                f"states must have one value per joint ({len(self._joints)}), got {count}"
            )
        values = [check_real(f"states[{i}]", s) for i, s in enumerate(states)]
        if any(self._rejected_state("setJointStates", i, s) for i, s in enumerate(values)):
            return None
        return values

    def _cost(self, extended) -> tuple[float, float]:
        """(growth of the ball radius, length of the new links) of an extension."""
        links, ball = extended[1], extended[2]
        added = links[len(self._links) :]
        return ball.r - self._ball.r, sum(link.path.length for link in added)

    # --- edits ---------------------------------------------------------------------------------
    def _try_edit(self, what: str, build) -> bool:
        try:
            joints, links = build()
            ball = self._ball_of(joints, links)
        except KinegamiError as error:
            self._reject(f"{what} failed: {error}")
            return False
        return self._accept(what, joints, links, ball)

    def transformAll(self, Transformation) -> bool:
        """Move the whole chain rigidly by ``Transformation`` (no link is re-solved)."""
        T = pose_array(Transformation, "Transformation", r=self.r)
        joints = [joint.transformed(T) for joint in self._joints]
        links = [link.transformed(T) for link in self._links]
        self._commit(joints, links, self._ball.transformed(T))
        return True

    def translateJointAlongAxisOfMotion(
        self,
        jointIndex: int,
        distance: float,
        propogate: bool = PROPAGATE_DEFAULT,
        applyToPreviousWaypoint: bool = False,
        *,
        propagate: bool | None = None,
    ) -> bool:
        """Slide joint ``jointIndex`` by ``distance`` along its axis of motion (z).

        The axis line is kept, so the kinematics are unchanged. With
        ``applyToPreviousWaypoint`` the waypoint the joint follows moves with it (in a tree:
        its parent, when that is a waypoint whose only child is this joint).
        ``distance`` lies within +-1e6 r (an InvalidParameterError names it otherwise, and the
        chain is unchanged).
        """
        d = check_translation("distance", distance, self.r)
        return self._axis_edit(
            "translateJointAlongAxisOfMotion",
            jointIndex,
            lambda joint: translation(d * joint.pose_matrix[:3, 2]),
            propogate,
            propagate,
            applyToPreviousWaypoint,
        )

    def rotateJointAboutAxisOfMotion(
        self,
        jointIndex: int,
        angle: float,
        propogate: bool = PROPAGATE_DEFAULT,
        applyToPreviousWaypoint: bool = False,
        *,
        propagate: bool | None = None,
    ) -> bool:
        """Turn joint ``jointIndex`` by ``angle`` (radians) about its axis of motion."""
        a = check_real("angle", angle)
        return self._axis_edit(
            "rotateJointAboutAxisOfMotion",
            jointIndex,
            lambda joint: rotation_about_line(
                joint.pose_matrix[:3, 2], joint.pose_matrix[:3, 3], a
            ),
            propogate,
            propagate,
            applyToPreviousWaypoint,
        )


#: Safe placement keeps the published result when all new joints stay within this many r of
#: the current ball's surface and its new links are at most SAFE_PATH_LIMIT r long.
SAFE_GROWTH_LIMIT = 10.0
SAFE_PATH_LIMIT = 40.0

#: Variants of the radial safe placement, tried in order until one is clear of the chain
#: (keyword arguments of :func:`kinegami.chain.placement.radial_safe_placement`).
RADIAL_VARIANTS = (
    {},
    {"two_arcs_above": math.pi / 2.0, "bend_straight": 2.0},
    {"lead": 4.0},
    {"lead": 4.0, "two_arcs_above": math.pi / 2.0, "bend_straight": 2.0},
    {"lead": 8.0, "two_arcs_above": 0.0, "bend_straight": 4.0},
)
