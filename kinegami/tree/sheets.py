"""How a tree is made: sheets and printed junctions (docs/trees.md).

A tree is folded from several sheets joined by printed connectors. At every joint with k >= 2
children one child, the *trunk*, continues the joint's sheet; each of the other k - 1 starts a
sheet of its own at a junction. Every sheet therefore ends at exactly one leaf and every leaf
ends one sheet: a tree has as many sheets as leaves.

* **Trunk rule.** By default the trunk is the child whose longest path to a leaf (links plus
  joints) is longest (ties: the smaller index), unless the socket of one other child does not
  fit on its link: that child is then the trunk (its tube needs no socket). ``trunks``
  overrides the choice per joint.
* **Sheet order.** Breadth first: sheet 0 starts at the root; then come the sheets that start
  along sheet 0 (joint by joint from the root, longest first), then those along sheet 1, ...
* **Where a branch sheet starts.** The connector of the joint holds the tubes of its children
  over the first part of their links, where they still run within reach of each other, plus a
  socket (:func:`kinegami.tree.connector.junction_sockets`). A branch child's sheet starts at
  its socket, on its link: its first modules are the rest of that link (the same CSC path from
  there on), then its joint, and so on to its leaf. The trunk's tube runs through the
  connector's sleeve, so the trunk's sheet simply continues.

Each sheet is an ordinary chain crease pattern (a :class:`~kinegami.pattern.TubularPattern`):
everything that exports or folds a chain's pattern exports or folds a sheet.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.links import LinkCSC
from kinegami.pattern import TubularPattern
from kinegami.tree.connector import ConnectorOptions, JunctionSocket, junction_sockets
from kinegami.tree.model import KinematicTree
from kinegami.validation import check_twist_portion

__all__ = [
    "TreeSheet",
    "Junction",
    "TreeFabrication",
    "fabricate",
    "default_trunks",
    "junction_problems",
    "choose_trunks",
    "fit_junctions",
]


@dataclass(frozen=True)
class Junction:
    """A printed junction: the connector at a joint with several children.

    Attributes
    ----------
    index : the junction's number k (files ``<stem>_junction_<k>``).
    joint : the branching joint (tree index).
    children : its children (tree indices, in order).
    trunk : the child whose sheet runs through the connector.
    sockets : one :class:`~kinegami.tree.connector.JunctionSocket` per child, in ``children``
        order (lengths along each child's link, units of r).
    parent_side : how the connector meets the joint behind it (``"base"`` for the root,
        ``"flange"`` otherwise; docs/junctions.md).
    """

    index: int
    joint: int
    children: tuple[int, ...]
    trunk: int
    sockets: tuple[JunctionSocket, ...]
    parent_side: str


@dataclass(frozen=True)
class TreeSheet:
    """One sheet of a tree.

    Attributes
    ----------
    index : the sheet's number k (files ``<stem>_sheet_<k>``).
    joints : the tree joints the sheet carries, root end first, ending at its leaf.
    junction : the :class:`Junction` number it starts at, or None (sheet 0 starts at the root).
    start_arc : where on its first link the sheet starts (arc length from the junction, units of
        r; 0 for sheet 0).
    pattern : the sheet's crease pattern.
    """

    index: int
    joints: tuple[int, ...]
    junction: int | None
    start_arc: float
    pattern: object = field(repr=False)

    @property
    def leaf(self) -> int:
        """The leaf the sheet ends at."""
        return self.joints[-1]

    @property
    def name(self) -> str:
        return f"sheet {self.index}"

    def label(self, tree: KinematicTree, names=None, length=None) -> str:
        """One line for the drawings: the sheet, its joints, where it starts, where it is glued
        (``names``: the joint names; ``length``: formats a length, default in units of r)."""
        length = (lambda v: f"{v:.3g} r") if length is None else length

        def joint(k: int) -> str:
            if names is not None and k < len(names) and names[k]:
                return f"{k} '{names[k]}'"
            return str(k)

        span = f"joints {joint(self.joints[0])} to {joint(self.leaf)}"
        if self.junction is None:
            start = "starts at the root"
        else:
            start = (f"starts in junction {self.junction} (at joint "
                     f"{joint(tree.Parents[self.joints[0]])}), {length(self.start_arc)} along "
                     "its link")  # fmt: skip
        return f"{self.name}: {span}; {start}; glue the tab along the long edge"


@dataclass(frozen=True)
class TreeFabrication:
    """The sheets and junctions of a tree (:func:`fabricate`)."""

    tree: KinematicTree = field(repr=False)
    sheets: tuple[TreeSheet, ...]
    junctions: tuple[Junction, ...]
    options: ConnectorOptions = field(repr=False)

    def connector(self, k: int):
        """The printed connector of junction ``k`` as a watertight trimesh (world frame, units
        of r; needs manifold3d, ``pip install 'kinegami[print]'``)."""
        from kinegami.tree.connector import junction_connector

        if isinstance(k, bool) or not isinstance(k, int | np.integer):
            raise InvalidTypeError(f"k must be a junction number, got {k!r}")
        if not 0 <= k < len(self.junctions):
            raise InvalidParameterError(
                f"k must be in [0, {len(self.junctions) - 1}] (the junctions), got {k}"
            )
        junction = self.junctions[k]
        tree = self.tree
        D = tree.Joints[junction.joint].distal_dubins_frame()
        links = [tree.Links[c] for c in junction.children]
        trunk = junction.children.index(junction.trunk)
        return junction_connector(tree.r, tree.numSides, D, links, parent_side=junction.parent_side,
                                  trunk=trunk, options=self.options)  # fmt: skip


def _downstream(tree: KinematicTree) -> list[float]:
    """Per joint: the longest path (link into it, itself, then on to a leaf), units of r."""
    children = tree.Children
    longest = [0.0] * len(tree.Joints)
    for k in range(len(tree.Joints) - 1, -1, -1):
        below = max((longest[c] for c in children[k]), default=0.0)
        link = tree.Links[k].path.length if k > 0 else 0.0
        longest[k] = link + tree.Joints[k].neutralLength + below
    return longest


def default_trunks(tree: KinematicTree) -> dict[int, int]:
    """The trunk of every joint with several children: the child with the longest path to a
    leaf (ties: the smaller index)."""
    longest = _downstream(tree)
    return {k: max(kids, key=lambda c: (longest[c], -c))
            for k, kids in enumerate(tree.Children) if len(kids) > 1}  # fmt: skip


def _check_trunks(tree: KinematicTree, trunks) -> dict[int, int]:
    chosen = default_trunks(tree)
    if trunks is None:
        return chosen
    if not isinstance(trunks, Mapping):
        raise InvalidTypeError(f"trunks must map joints to children, got {trunks!r}")
    children = tree.Children
    for joint, child in trunks.items():
        if joint not in chosen:
            raise InvalidParameterError(
                f"trunks: joint {joint!r} does not branch (joints with several children: "
                f"{sorted(chosen)})"
            )
        if child not in children[joint]:
            raise InvalidParameterError(
                f"trunks: {child!r} is not a child of joint {joint} (its children: "
                f"{list(children[joint])})"
            )
        chosen[joint] = int(child)
    return chosen


def _sockets(tree: KinematicTree, joint: int, trunk: int | None, options) -> tuple:
    kids = tree.Children[joint]
    links = [tree.Links[c] for c in kids]
    return junction_sockets(links, tree.r, tree.numSides,
                            trunk=None if trunk is None else kids.index(trunk), options=options,
                            strict=False)  # fmt: skip


def choose_trunks(
    tree: KinematicTree,
    trunks: Mapping[int, int] | None = None,
    options: ConnectorOptions | None = None,
) -> tuple[dict[int, int], list[tuple[int, str]]]:
    """The trunk of every branching joint, and the problems left (:func:`junction_problems`).

    A joint's trunk is the one given in ``trunks``, else :func:`default_trunks`' choice, unless
    a sibling's socket would not fit with it and does fit as the trunk (the trunk needs no
    socket: its tube runs through the connector), in which case that sibling is the trunk.
    """
    chosen = _check_trunks(tree, trunks)
    options = ConnectorOptions() if options is None else options
    depth = options.resolved(tree.r).socket_depth
    problems: list[tuple[int, str]] = []
    for joint in sorted(chosen):
        kids = tree.Children[joint]
        sockets = _sockets(tree, joint, None, options)
        misfits = [c for c, socket in zip(kids, sockets, strict=True) if not socket.fits]
        given = trunks is not None and joint in trunks
        if not given and len(misfits) == 1:
            chosen[joint] = misfits[0]
        for c, socket in zip(kids, sockets, strict=True):
            if not socket.fits and c != chosen[joint]:
                problems.append((c, (
                    f"joint {c} (a child of joint {joint}) runs with its siblings for "
                    f"{socket.start:.3g} r of its {socket.link_length:.3g} r link, leaving no "
                    f"room for its {depth:.3g} r socket"
                )))  # fmt: skip
    return chosen, problems


def junction_problems(
    tree: KinematicTree,
    *,
    trunks: Mapping[int, int] | None = None,
    options: ConnectorOptions | None = None,
) -> list[tuple[int, str]]:
    """``(child, reason)`` for every branch child whose socket does not fit on its link (it
    runs with its siblings for longer than its link minus the socket depth) with the trunks of
    :func:`choose_trunks`; empty when the tree can be made with printed junctions."""
    return choose_trunks(tree, trunks, options)[1]


def fabricate(
    tree: KinematicTree,
    *,
    trunks: Mapping[int, int] | None = None,
    options: ConnectorOptions | None = None,
    twistPortion: float = 0.2,
) -> TreeFabrication:
    """The sheets and printed junctions of ``tree`` at its current states.

    Parameters
    ----------
    tree : KinematicTree (a chain gives one sheet and no junction).
    trunks : ``{joint: child}`` for the joints whose trunk is not the default one.
    options : connector options (wall, clearance, socket depth; docs/junctions.md).
    twistPortion : fraction of each straight part taken by its twist fitting (default 0.2).

    Raises
    ------
    InvalidParameterError
        When a branch child's socket does not fit on its link (its link is shorter than the
        stretch it runs with its siblings plus the socket): slide or compact the tree first.
    """
    if not isinstance(tree, KinematicTree):
        raise InvalidTypeError(f"tree must be a KinematicTree, got {type(tree).__name__}")
    twistPortion = check_twist_portion(twistPortion)
    options = ConnectorOptions() if options is None else options
    if not isinstance(options, ConnectorOptions):
        raise InvalidTypeError(f"options must be ConnectorOptions, got {options!r}")
    trunk_of, problems = choose_trunks(tree, trunks, options)
    if problems:
        raise InvalidParameterError(
            "the tree cannot be made with printed junctions: " + "; ".join(p for _, p in problems)
            + ". Slide those joints along their axes (or compact the tree: kinegami compact) "
            "so that their links get longer"
        )
    longest = _downstream(tree)
    children = tree.Children
    n, r = tree.numSides, tree.r

    junctions: list[Junction] = []
    socket_of: dict[int, JunctionSocket] = {}
    for joint in sorted(trunk_of):
        kids = children[joint]
        links = [tree.Links[c] for c in kids]
        sockets = junction_sockets(links, r, n, trunk=kids.index(trunk_of[joint]), options=options)
        for c, socket in zip(kids, sockets, strict=True):
            socket_of[c] = socket
        side = "base" if joint == 0 else "flange"
        junctions.append(Junction(len(junctions), joint, kids, trunk_of[joint], sockets, side))
    junction_at = {j.joint: j.index for j in junctions}

    # sheets: follow trunks from each start to a leaf; branch children start later sheets
    sheets: list[TreeSheet] = []
    starts = [0]
    while starts:
        first = starts.pop(0)
        path = [first]
        while children[path[-1]]:
            k = path[-1]
            path.append(trunk_of.get(k, children[k][0]))
        branches = []
        for k in path:
            for c in children[k]:
                if k in trunk_of and c != trunk_of[k]:
                    branches.append(c)
        # the sheets starting along this one, joint by joint, longest first (breadth first)
        starts += sorted(branches, key=lambda c: (path.index(tree.Parents[c]), -longest[c], c))
        if first == 0:
            modules = [tree.Joints[0].pattern]
            arc, junction = 0.0, None
        else:
            socket = socket_of[first]
            arc = float(socket.sheet_start)
            junction = junction_at[tree.Parents[first]]
            rest = LinkCSC(r, np.asarray(socket.frame), tree.Joints[first].proximal_dubins_frame(),
                           tree.maxAnglePerElbow)  # fmt: skip
            modules = rest.pattern_modules(n, twistPortion) + [tree.Joints[first].pattern]
        for k in path[1:]:
            modules += tree.Links[k].pattern_modules(n, twistPortion)
            modules.append(tree.Joints[k].pattern)
        pattern = TubularPattern.concatenate(modules)
        sheets.append(TreeSheet(len(sheets), tuple(path), junction, arc, pattern))
    return TreeFabrication(tree, tuple(sheets), tuple(junctions), options)


#: Slides tried (in r, smallest first) to give a branch child's socket room (fit_junctions).
FIT_SLIDES = tuple(s * sign for s in (0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0)
                   for sign in (1.0, -1.0))  # fmt: skip


def fit_junctions(
    tree: KinematicTree,
    *,
    trunks: Mapping[int, int] | None = None,
    options: ConnectorOptions | None = None,
) -> tuple[KinematicTree, list[tuple[int, float]]]:
    """A copy of ``tree`` in which every branch child's socket fits, and the slides made.

    A child whose socket does not fit is slid along its own axis of motion (its subtree
    follows), by the smallest of :data:`FIT_SLIDES` that makes it fit without making the tree
    pass through itself more than before: the axes, hence the kinematics, stay as they were.
    ``tree`` is not changed. Returns ``(tree, [(joint, slide in units of r), ...])``.

    Raises
    ------
    InvalidParameterError
        When no slide makes some socket fit (the message names the joint).
    """
    import copy
    import warnings

    from kinegami.errors import ClearanceWarning, PlacementWarning

    fitted = copy.copy(tree)
    moves: list[tuple[int, float]] = []

    def depth(t: KinematicTree) -> float:
        report = t.clearance()
        return 0.0 if report.ok else -report.min_clearance

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        warnings.simplefilter("ignore", PlacementWarning)
        for _ in range(len(tree.Joints)):
            problems = junction_problems(fitted, trunks=trunks, options=options)
            if not problems:
                return fitted, moves
            child, reason = problems[0]
            before = depth(fitted)
            for slide in FIT_SLIDES:
                trial = copy.copy(fitted)
                if not trial.translateJointAlongAxisOfMotion(child, slide * tree.r):
                    continue
                if child in [c for c, _ in junction_problems(trial, trunks=trunks,
                                                            options=options)]:  # fmt: skip
                    continue
                if depth(trial) > before + 1e-9 * tree.r:
                    continue
                fitted = trial
                moves.append((child, slide * tree.r))
                break
            else:
                raise InvalidParameterError(
                    f"the tree cannot be made with printed junctions: {reason}, and no slide of "
                    f"joint {child} along its axis within +-{max(FIT_SLIDES):g} r makes room "
                    "without a new collision; re-place it (or compact the tree)"
                )
    raise InvalidParameterError(  # pragma: no cover - each round fixes one child
        "fit_junctions did not converge"
    )
