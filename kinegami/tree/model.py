"""KinematicTree: joints with any number of children, joined by CSC links (docs/trees.md).

A tree holds its joints in world coordinates, in the order they were added (a parent's index is
always smaller than its children's, so index order is a topological order), the parent of every
joint (``Parents``; -1 for the root) and, for every joint i >= 1, the link ``Links[i]`` from its
parent's distal Dubins frame to its own proximal Dubins frame. One bounding ball covers the whole
tree, so a safe or compact placement puts a new joint beyond everything built so far.

Everything a chain does, a tree does on subtrees: a moved joint takes its descendants along, a
state change moves the subtrees beyond the joint. Every operation computes the new lists first
and swaps them in only when all exist, so a refused one leaves the tree bit-identical. A
:class:`~kinegami.chain.KinematicChain` is the tree in which joint i's parent is joint i - 1:
the same calls on both give the same joints, links and ball, bit for bit (tested).
"""

from __future__ import annotations

from collections.abc import Iterable, Sequence

import numpy as np

from kinegami.chain.assembly import RADIAL_VARIANTS, JointAssembly
from kinegami.chain.bodies import Overlap, link_polyline
from kinegami.chain.joints import Joint, check_same_tube
from kinegami.chain.model import KinematicChain
from kinegami.clearance.tree_bodies import TreeGrowth, tree_worst_overlap
from kinegami.errors import InvalidParameterError, InvalidTypeError, KinegamiError, NoPathError
from kinegami.validation import check_int, shown

__all__ = ["KinematicTree", "SIBLING_OUTWARD"]

#: How much farther out (in r) the last variants of safe placement put a later sibling on its
#: axis, when no route to the usual place is clear (docs/trees.md).
SIBLING_OUTWARD = 4.0


class KinematicTree(JointAssembly):
    """A tree of tubular origami joints joined by CSC links.

    Parameters
    ----------
    root : the root joint (copied; world coordinates).
    maxAnglePerElbow : largest turn of a single elbow fitting, in (0, pi] (default pi/2).
    requireClearance : refuse additions, edits and state changes that would make the tree pass
        through itself (default False: apply them and emit a ClearanceWarning).

    Examples
    --------
    >>> tree = KinematicTree(Waypoint(4, 1, SE3()))
    >>> tree.addJoint(0, RevoluteJoint(4, 1, np.pi, SE3.Trans(4, 0, 4) * SE3.Ry(np.pi / 2)),
    ...               safe=False, fixedPosition=True, fixedOrientation=True)
    1
    >>> tree.addJoint(0, RevoluteJoint(4, 1, np.pi, SE3.Trans(-4, 0, 4) * SE3.Ry(np.pi / 2)),
    ...               safe=False, fixedPosition=True, fixedOrientation=True)
    2
    >>> tree.Parents, tree.Children
    ((-1, 0, 0), ((1, 2), (), ()))
    """

    _noun = "tree"

    def __init__(
        self,
        root: Joint,
        maxAnglePerElbow: float = np.pi / 2,
        requireClearance: bool = False,
        margin: float = 0.0,
    ):
        super().__init__(root, maxAnglePerElbow, requireClearance, margin)
        self._parents: list[int] = [-1]

    @classmethod
    def _from_parts(cls, joints, links, parents, maxAnglePerElbow: float) -> KinematicTree:
        """A tree holding exactly ``joints``, ``links`` and ``parents`` (nothing re-solved; for
        a folded body whose links need not start at their parent's distal frame, such as a
        take-off branch: kinegami.fabrication.sheets.TreeFabrication.folded_tree)."""
        tree = cls(joints[0], maxAnglePerElbow)
        tree._commit(list(joints), list(links), None, [int(p) for p in parents])
        return tree

    @classmethod
    def from_joints(
        cls,
        joints: Sequence[Joint],
        parents: Sequence[int],
        maxAnglePerElbow: float = np.pi / 2,
    ) -> KinematicTree:
        """A tree of ``joints`` at exactly their poses (world coordinates), joint k the child of
        joint ``parents[k]`` (``parents[0] = -1``, every other parent an earlier joint).

        The same tree as adding them one by one with exact poses, bit for bit, but checked for
        clearance once (a ClearanceWarning when it passes through itself).

        Raises
        ------
        NoPathError
            When no link reaches joint k; the error's ``joint`` attribute is k.
        InvalidTypeError
            When ``joints`` is not a sequence of Joint objects, ``parents`` not a sequence
            (or one-dimensional array) of integers (numpy integers are; bools, floats, strings
            and None are not), or a joint is of another tube.
        InvalidParameterError
            For parents that do not describe a tree (not one per joint, ``parents[0]`` not -1,
            a parent that is not an earlier joint), or joints of another tube.
        """
        joints = _joint_list(joints)
        parents = _parent_list(parents, len(joints))
        tree = cls(joints[0], maxAnglePerElbow)
        placed, links, ball = [tree._joints[0]], [tree._links[0]], tree._ball
        for k in range(1, len(joints)):
            check_same_tube(joints[k], tree.numSides, tree.r)
            if joints[k].closes_start:
                raise InvalidParameterError(f"joint {k}: a StartTip can only be the root")
            if placed[parents[k]].closes_end:
                raise InvalidParameterError(
                    f"joint {k}: its parent {parents[k]} is an EndTip, which nothing can follow"
                )
            joint = joints[k]._copy()
            try:
                link = tree._link(placed[parents[k]], joint)
            except NoPathError as error:
                failure = NoPathError(f"joint {k}: {error}")
                failure.joint = k
                raise failure from None
            ball = tree._merge_link_and_joint(ball, link, joint)
            placed.append(joint)
            links.append(link)
        tree._accept("from_joints", placed, links, ball, parents)
        return tree

    @classmethod
    def from_chain(cls, chain) -> KinematicTree:
        """The tree that is ``chain``: the same joints, links and ball (shared: they are
        immutable values), joint i the child of joint i - 1, the same options. Nothing is solved
        again, so every joint, link and the ball are the chain's bit for bit; ``chain`` is not
        changed. A chain whose root is an EndTip (left by deleting its first joint) has no
        tree: InvalidParameterError, as for ``KinematicTree(EndTip(...))``."""
        if not isinstance(chain, KinematicChain):
            raise InvalidTypeError(f"chain must be a KinematicChain, got {type(chain).__name__}")
        tree = cls(chain.Joints[0], chain.maxAnglePerElbow, chain.requireClearance, chain.margin)
        tree._commit(list(chain.Joints), list(chain.Links), chain.boundingBall,
                     list(chain.Parents))  # fmt: skip
        return tree

    # --- published read-only views -----------------------------------------------------------
    @property
    def Parents(self) -> tuple[int, ...]:
        """Parent index of every joint (-1 for the root)."""
        return tuple(self._parents)

    @property
    def Children(self) -> tuple[tuple[int, ...], ...]:
        """The children of every joint, in the order they were added."""
        children: list[list[int]] = [[] for _ in self._joints]
        for k, p in enumerate(self._parents):
            if p >= 0:
                children[p].append(k)
        return tuple(tuple(c) for c in children)

    def __repr__(self) -> str:
        leaves = sum(1 for c in self.Children if not c)
        return (
            f"KinematicTree({len(self._joints)} joints, {leaves} leaves; "
            f"path length {self.totalPathLength():.6g})"
        )

    def branchingParametersFrom(self, jointIndex: int) -> list[list[float]]:
        """The branching parameters of the links to each child of ``jointIndex``
        (``LinkCSC.branchingParameters``: degrees and lengths), in the order of ``Children``."""
        j = self._index(jointIndex)
        return [self._links[k].branchingParameters() for k in self.Children[j]]

    def subtree(self, jointIndex: int) -> tuple[int, ...]:
        """``jointIndex`` and all its descendants, in index order."""
        j = self._index(jointIndex)
        return tuple(self._subtree(j))

    # --- the hooks of the shared part ----------------------------------------------------------
    def _parent_list(self) -> list[int]:
        return list(self._parents)

    #: A new sibling changes the junction its older siblings share: placement tests all pairs.
    _placement_adds_pairs_only = False

    def _overlap(self, joints, links, parents, since: int = 0):
        known = self.__dict__.get("_states_overlap")  # set by setJointStates for its lists
        if known is not None and known[0] is joints and known[1] is links and since == 0 \
                and parents is None:  # fmt: skip
            return known[2]
        parents = self._parents if parents is None else parents
        if since > 0 and since == len(self._joints):
            growth = self._growth()
            if growth.extends(joints, links, parents):
                # a placement candidate: only what the new joints change is measured
                return growth.overlap(joints, links, parents)
        return tree_worst_overlap(joints, links, parents, self.r, since=since,
                                  margin=self.margin)  # fmt: skip

    def _clear_of(self, joints, links, parents, since: int) -> bool:
        if since == len(self._joints):
            growth = self._growth()
            if growth.extends(joints, links, parents):
                return growth.clear(joints, links, parents)
        return super()._clear_of(joints, links, parents, since)

    def _growth(self) -> TreeGrowth:
        """The overlap test of extensions of the tree as it is (TreeGrowth), made once per
        committed set of lists and margin (they are replaced, never changed)."""
        memo = self.__dict__.get("_growth_memo")
        if (memo is None or memo[0] is not self._joints or memo[1] is not self._links
                or memo[2] is not self._parents or memo[3] != self._margin):  # fmt: skip
            growth = TreeGrowth(self._joints, self._links, self._parents, self.r, self._margin)
            memo = (self._joints, self._links, self._parents, self._margin, growth)
            self._growth_memo = memo
        return memo[4]

    def _commit(self, joints, links, ball=None, parents=None):
        self.__dict__.pop("_growth_memo", None)  # it measured extensions of the old lists
        super()._commit(joints, links, ball)
        if parents is not None:
            self._parents = list(parents)

    def _published_placement_allowed(self, p: int) -> bool:
        # the published rule puts every child's first waypoint on the parent's path ray, so a
        # later sibling would run through the earlier ones (docs/trees.md)
        return not self._children_of(p)

    def _radial_variants(self, distal: np.ndarray, k: int, p: int):
        """For a parent that already has children: the radial construction escaping first
        away from the directions in which they leave, then sideways; then the chain's; then
        the escapes again with the joint farther out."""
        if not self._children_of(p):
            yield from super()._radial_variants(distal, k, p)
            return
        d1 = distal[:3, k]
        A = distal[:3, 3]
        away = np.zeros(3)
        for child in self._children_of(p):
            # where the child's tube (followed through waypoints) first leaves the parent's ray
            node = child
            while True:
                points = link_polyline(self._links[node]) - A
                sides = points - np.outer(points @ d1, d1)
                norms = np.sqrt((sides**2).sum(axis=1))
                off = np.flatnonzero(norms > 1e-6 * self.r)
                if off.size or self._joints[node].has_body:
                    break
                kids = self._children_of(node)
                if len(kids) != 1:
                    break
                node = kids[0]
            if off.size:
                away -= sides[off[0]] / norms[off[0]]
        if float(np.linalg.norm(away)) < 1e-9:
            away = distal[:3, (k + 1) % 3]  # any direction across the parent's path
        away = away - float(away @ d1) * d1
        away /= float(np.linalg.norm(away))
        side = np.cross(d1, away)
        # away first, then sideways, then back; then the diagonals between them (a parent with
        # three or more children may have the four main directions taken)
        diagonals = [
            (a * away + b * side) / np.sqrt(2.0) for a, b in ((1, 1), (1, -1), (-1, 1), (-1, -1))
        ]
        escapes = (away, side, -side, -away, *diagonals)
        for escape in escapes:
            for variant in RADIAL_VARIANTS:
                yield {**variant, "escape": escape}
        yield from super()._radial_variants(distal, k, p)
        # last, the same escapes with the joint SIBLING_OUTWARD r farther out on its axis: a
        # sibling on the same or a nearby axis line can sit where the joint would go, and
        # every route into that place runs beside it (docs/trees.md)
        for escape in escapes:
            for variant in RADIAL_VARIANTS:
                yield {**variant, "escape": escape, "outward": SIBLING_OUTWARD}

    def _subtree(self, j: int, parents: Sequence[int] | None = None) -> list[int]:
        """j and its descendants in index order (children always follow their parent)."""
        parents = self._parents if parents is None else parents
        inside = {j}
        for k in range(j + 1, len(parents)):
            if parents[k] in inside:
                inside.add(k)
        return sorted(inside)

    def _children_of(self, j: int) -> list[int]:
        return [k for k, p in enumerate(self._parents) if p == j]

    def _parent_of(self, j: int) -> int:
        return self._parents[j]

    # --- building ----------------------------------------------------------------------------
    def addJoint(
        self,
        parentIndex: int,
        newJoint: Joint,
        relative: bool = True,
        safe: bool = True,
        fixedPosition: bool = False,
        fixedOrientation: bool = False,
    ) -> int | None:
        """Add ``newJoint`` as a child of joint ``parentIndex`` and return its index.

        Parameters
        ----------
        parentIndex : the parent joint (negative counts from the end).
        newJoint : the joint; its Pose gives the axis of motion (z). It is copied.
        relative : the Pose is relative to the parent's Pose (True) or global (False).
        safe : place with the safe algorithm (waypoints from the parent, beyond the whole
            tree's ball) rather than compact (docs/placement.md). Safe placement of a later
            sibling never runs through an earlier one: candidates that would are passed over
            (docs/trees.md).
        fixedPosition, fixedOrientation : keep the given position / orientation (safe=False).

        Returns the new joint's index (waypoints that safe placement adds take the indices just
        before it), or None with a PlacementWarning (tree unchanged) when no link reaches it.
        """
        p = self._index(parentIndex, "parentIndex")
        return self._place("addJoint", p, newJoint, relative, safe, fixedPosition,
                           fixedOrientation)  # fmt: skip

    # --- edits ---------------------------------------------------------------------------------
    def delete(self, jointIndex: int) -> bool:
        """Remove joint ``jointIndex`` and link its children to its parent.

        Each child's link is re-solved from the removed joint's parent; deleting the root is
        possible when it has exactly one child (that child becomes the root). Returns True, or
        False with a PlacementWarning (tree unchanged) when a new link cannot be built.
        """
        j = self._index(jointIndex)
        kids = self._children_of(j)
        if j == 0 and len(kids) != 1:
            self._reject(
                "delete failed: the root can be deleted only when it has exactly one child "
                f"(it has {len(kids)})"
            )
            return False
        up = self._parents[j]
        parents = []
        for k, p in enumerate(self._parents):
            if k != j:
                q = up if p == j else p
                parents.append(q - 1 if q > j else q)

        def build():
            joints = self._joints[:j] + self._joints[j + 1 :]
            links = self._links[:j] + self._links[j + 1 :]
            for child in kids:
                k = child - 1  # its index after the deletion
                if parents[k] < 0:
                    links[k] = self._root_link(joints[k])
                else:
                    links[k] = self._link(joints[parents[k]], joints[k])
            return joints, links

        try:
            joints, links = build()
            ball = self._ball_of(joints, links)
        except KinegamiError as error:
            self._reject(f"delete failed: {error}")
            return False
        return self._accept("delete", joints, links, ball, parents)

    # --- states --------------------------------------------------------------------------------
    def setJointState(self, jointIndex: int, newState: float) -> bool:
        """Set joint ``jointIndex`` to ``newState`` (radians or length): the subtrees beyond it
        move; the joint itself, its siblings and every other branch stay. Returns False with a
        PlacementWarning (tree unchanged) if ``newState`` is outside ``stateRange()``."""
        j = self._index(jointIndex)
        s = self._state_value(j, newState)
        if s is None:
            return False
        values = [joint.state for joint in self._joints]
        values[j] = s
        joints, links = self._configured(values)  # one motion from home: no drift
        return self._accept("setJointState", joints, links)

    def setJointStates(self, states: Sequence[float]) -> bool:
        """Set every joint's state at once (one value per joint, in index order); all or
        nothing (``states`` as for a chain)."""
        values = self._state_values(states)
        if values is None:
            return False
        joints, links = self._configured(values)
        # the tree's clearance engine answers any states of this design; it stays the
        # engine of the tree at the new states (docs/clearance.md)
        from kinegami.clearance import TreeMotion, keep_tree_engine

        engine = TreeMotion(self, margin=self._margin).engine
        self._states_overlap = (joints, links, _engine_overlap(engine, values, self._margin))
        try:
            accepted = self._accept("setJointStates", joints, links)
        finally:
            del self._states_overlap
        if accepted:
            keep_tree_engine(self, engine, self._margin)
        return accepted

    # --- output --------------------------------------------------------------------------------
    def clearance(self, states=None, margin=None):
        """Self-intersection at the current states or at ``states`` (one per joint), with
        ``margin`` (default: :attr:`margin`): a ClearanceReport (``.ok``, ``.min_clearance``,
        ``.pairs``, ``.verdict()``); see docs/trees.md."""
        from kinegami.clearance import tree_clearance

        return tree_clearance(self, states, margin=margin)

    def show(self, **options):
        """Draw the tree in 3D with matplotlib; returns (figure, axes). See kinegami.viz."""
        from kinegami.viz.chain_plot import show_chain

        return show_chain(self, **options)


def _engine_overlap(engine, values, margin: float) -> Overlap | None:
    """The deepest pair closer than ``margin`` at the states ``values`` as the engine's
    report finds it, as an Overlap (None when clear): what tree_worst_overlap gives for the
    configured lists (the same verdict; equal depths to rounding; where two parts are equally
    close, the one the tree's clearance report names)."""
    report = engine.report(list(values), margin)
    if report.ok:
        return None
    pair = report.pairs[0]
    return Overlap(pair.clearance, pair.first, pair.second, pair.elements, margin)


def _joint_list(joints) -> list[Joint]:
    """``joints`` of :meth:`KinematicTree.from_joints` as a non-empty list of Joint objects."""
    if isinstance(joints, str | bytes | Joint) or not isinstance(joints, Iterable):
        raise InvalidTypeError(f"joints must be a sequence of Joint objects, got {shown(joints)}")
    joints = list(joints)
    if not joints:
        raise InvalidParameterError("joints must hold at least one joint (the root), got []")
    for k, joint in enumerate(joints):
        if not isinstance(joint, Joint):
            raise InvalidTypeError(f"joints[{k}] must be a Joint, got {shown(joint)}")
    return joints


def _parent_list(parents, n: int) -> list[int]:
    """``parents`` of :meth:`KinematicTree.from_joints` for ``n`` joints as a list of ints:
    ``parents[0] = -1`` and every other parent an earlier joint."""
    if isinstance(parents, str | bytes) or not (
        isinstance(parents, Sequence) or (isinstance(parents, np.ndarray) and parents.ndim == 1)
    ):
        raise InvalidTypeError(
            "parents must be a sequence of integers (one per joint, -1 for the root), "
            f"got {shown(parents)}"
        )
    if len(parents) != n:
        raise InvalidParameterError(
            f"parents must have one entry per joint ({n}), got {len(parents)}: {shown(parents)}"
        )
    checked = []
    for k, p in enumerate(parents):
        p = check_int(f"parents[{k}]", p, floats=False)
        if (k == 0 and p != -1) or (k > 0 and not 0 <= p < k):
            raise InvalidParameterError(
                f"parents[{k}] must be {'-1 (the root)' if k == 0 else f'in [0, {k - 1}]'}, "
                f"got {shown(p)}"
            )
        checked.append(p)
    return checked
