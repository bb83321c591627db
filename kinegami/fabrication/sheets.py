"""How a tree is made: sheets, printed junctions and folded take-offs (docs/trees.md,
docs/junctions.md).

A tree is folded from several sheets joined by printed connectors or by folded take-off
junctions. At every joint with k >= 2 children one child, the *trunk*, continues the joint's
sheet; each of the other k - 1 starts a sheet of its own at a junction. Every sheet therefore
ends at exactly one leaf and every leaf ends one sheet: a tree has as many sheets as leaves.

* **Trunk rule.** By default the trunk is the child whose longest path to a leaf (links plus
  joints) is longest (ties: the smaller index), unless the socket of one other child does not
  fit on its link: that child is then the trunk (its tube needs no socket). ``trunks``
  overrides the choice per joint.
* **Sheet order.** Breadth first: sheet 0 starts at the root; then come the sheets that start
  along sheet 0 (joint by joint from the root, longest first), then those along sheet 1, ...
* **Where a branch sheet starts.** The connector of the joint holds the tubes of its children
  over the first part of their links, where they still run within reach of each other, plus a
  socket (:func:`kinegami.fabrication.connector.junction_sockets`). A branch child's sheet starts at
  its socket, on its link: its first modules are the rest of that link (the same CSC path from
  there on), then its joint, and so on to its leaf. The trunk's tube runs through the
  connector's sleeve, so the trunk's sheet simply continues.
* **Folded take-offs** (``junction="takeoff"``): no connector; each side branch leaves a face of
  the trunk's link (its plain tube part) at right angles (:mod:`kinegami.fabrication.takeoffs`). The
  trunk's sheet gets a hole there; the branch's sheet starts with a skirt cut to the trunk's
  shape, with glue tabs that fold in and are glued inside the trunk around the hole, then a new
  link to the branch child (the joints stay where they are).

Each sheet is a chain crease pattern (a :class:`~kinegami.pattern.TubularPattern`), or, with
take-offs, one with cut-outs (a :class:`~kinegami.pattern.cutout.CutPattern`): everything that
exports or folds a chain's pattern exports or folds a sheet.
"""

from __future__ import annotations

from collections.abc import Mapping
from dataclasses import dataclass, field

import numpy as np

from kinegami.chain.links import LinkCSC
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.fabrication.connector import ConnectorOptions, JunctionSocket, junction_sockets
from kinegami.fabrication.takeoffs import (
    JUNCTION_KINDS,
    Takeoff,
    TakeoffOptions,
    TakeoffWork,
    hole_name,
    place_takeoffs,
)
from kinegami.pattern import TubularPattern
from kinegami.pattern.catalog import check_pattern_size
from kinegami.pattern.cutout import CutPattern, SheetHole
from kinegami.tree.model import KinematicTree
from kinegami.validation import check_int, check_twist_portion, shown

__all__ = [
    "TreeSheet",
    "Junction",
    "Takeoff",
    "TakeoffOptions",
    "JUNCTION_KINDS",
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
    sockets : one :class:`~kinegami.fabrication.connector.JunctionSocket` per child, in ``children``
        order (lengths along each child's link, in the tree's length units, those of r).
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
    junction : the :class:`Junction` (printed connector) number it starts at, or None (sheet 0
        starts at the root; a take-off sheet at its take-off).
    start_arc : where on its first link the sheet starts (arc length from the junction, units of
        r; 0 for sheet 0 and for take-off sheets).
    pattern : the sheet's crease pattern: a TubularPattern, or a CutPattern when the sheet has
        take-off holes or starts with a skirt.
    frame : world Dubins frame (4x4) where the sheet's pattern starts: its folded form lies on
        the tree from there.
    takeoff : the name of the :class:`~kinegami.fabrication.takeoffs.Takeoff` it starts at, or None.
    takeoff_sheet : the sheet holding that take-off's hole, or None.
    holes : ``(name, branch sheet)`` of every take-off hole in this sheet.
    tabs : number of glue tabs of its skirt (0 without one).
    """

    index: int
    joints: tuple[int, ...]
    junction: int | None
    start_arc: float
    pattern: object = field(repr=False)
    frame: np.ndarray | None = field(default=None, repr=False, compare=False)
    takeoff: str | None = None
    takeoff_sheet: int | None = None
    holes: tuple[tuple[str, int], ...] = ()
    tabs: int = 0

    @property
    def leaf(self) -> int:
        """The leaf the sheet ends at."""
        return self.joints[-1]

    @property
    def name(self) -> str:
        return f"sheet {self.index}"

    def label(self, tree: KinematicTree, names=None, length=None) -> str:
        """One line for the drawings: the sheet, its joints, where it starts, where it is glued
        (``names``: the joint names; ``length``: formats a length given in the tree's length
        units; default: as a multiple of r)."""
        length = (lambda v: f"{v / tree.r:.3g} r") if length is None else length

        def joint(k: int) -> str:
            if names is not None and k < len(names) and names[k]:
                return f"{k} '{names[k]}'"
            return str(k)

        span = f"joints {joint(self.joints[0])} to {joint(self.leaf)}"
        if self.takeoff is not None:
            start = (f"starts at take-off {self.takeoff} (joint "
                     f"{joint(tree.Parents[self.joints[0]])}): fold its {self.tabs} skirt tabs in "
                     f"and glue them inside hole {self.takeoff} of sheet {self.takeoff_sheet}"
                     )  # fmt: skip
        elif self.junction is None:
            start = "starts at the root"
        else:
            start = (f"starts in junction {self.junction} (at joint "
                     f"{joint(tree.Parents[self.joints[0]])}), {length(self.start_arc)} along "
                     "its link")  # fmt: skip
        holes = ""
        if self.holes:
            holes = "; cut out " + ", ".join(f"hole {name} (sheet {k}'s skirt glues in)"
                                             for name, k in self.holes)  # fmt: skip
        return f"{self.name}: {span}; {start}{holes}; glue the tab along the long edge"


@dataclass(frozen=True)
class TreeFabrication:
    """The sheets and junctions of a tree (:func:`fabricate`).

    Attributes
    ----------
    tree : the tree.
    sheets : one :class:`TreeSheet` per leaf.
    junctions : the printed connectors (:class:`Junction`).
    options : the connector options.
    takeoffs : the folded take-off junctions
        (:class:`~kinegami.fabrication.takeoffs.Takeoff`), one per
        side branch that leaves its trunk through a face.
    notes : what the fabrication chose on its own (a joint given a connector because no
        take-off could be made there).
    links : the links as folded: the tree's, except that every take-off branch's first link
        starts at its take-off frame.
    """

    tree: KinematicTree = field(repr=False)
    sheets: tuple[TreeSheet, ...]
    junctions: tuple[Junction, ...]
    options: ConnectorOptions = field(repr=False)
    takeoffs: tuple[Takeoff, ...] = ()
    notes: tuple[str, ...] = ()
    links: tuple = field(default=(), repr=False)

    def overlap(self, names=None):
        """The deepest overlap of the folded body (the tree's joints, :attr:`links`, every
        trunk link cut at its take-off points: :func:`~kinegami.fabrication.takeoffs.takeoff_body`),
        by the tree's clearance rules, or None when it does not pass through itself (``names``:
        the joints' names for the labels)."""
        from kinegami.fabrication.takeoffs import takeoff_overlap

        return takeoff_overlap(self.tree, self._body_takeoffs(), names=names)

    def _body_takeoffs(self) -> list[tuple]:
        """The take-offs as :func:`~kinegami.fabrication.takeoffs.takeoff_body` takes them."""
        return [(t.trunk, t.arc, t.child, t.link) for t in self.takeoffs]

    def folded_tree(self) -> KinematicTree:
        """The tree as it is folded: :attr:`tree` itself, or, with take-offs, the tree whose
        take-off branches leave through their trunk's face (their :attr:`links`), every trunk
        link cut at its take-off points by a zero-length waypoint
        (:func:`~kinegami.fabrication.takeoffs.takeoff_body`). What the whole-tree STL, OBJ and URDF
        and the 3D picture of ``kinegami build`` show."""
        if not self.takeoffs:
            return self.tree
        from kinegami.fabrication.takeoffs import takeoff_body

        joints, links, parents, _ = takeoff_body(self.tree, self._body_takeoffs())
        return KinematicTree._from_parts(joints, links, parents, self.tree.maxAnglePerElbow)

    def show(self, **options):
        """Draw the tree as it is made: :meth:`folded_tree` with this fabrication's printed
        connectors; returns (figure, axes). Options as for ``KinematicTree.show``."""
        from kinegami.viz.chain_plot import show_fabrication

        return show_fabrication(self, **options)

    def connector(self, k: int):
        """The printed connector of junction ``k`` as a watertight trimesh (world frame, units
        of r; needs manifold3d, ``pip install 'kinegami[print]'``)."""
        from kinegami.fabrication.connector import junction_connector

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
    """Per joint: the longest path (link into it, itself, then on to a leaf), in the tree's
    length units."""
    children = tree.Children
    longest = [0.0] * len(tree.Joints)
    for k in range(len(tree.Joints) - 1, -1, -1):
        below = max((longest[c] for c in children[k]), default=0.0)
        link = tree.Links[k].path.length if k > 0 else 0.0
        longest[k] = link + tree.Joints[k].neutralLength + below
    return longest


def _check_tree(tree) -> KinematicTree:
    """``tree``, or InvalidTypeError unless it is a KinematicTree (a chain says how to get one)."""
    if not isinstance(tree, KinematicTree):
        from kinegami.chain.model import KinematicChain

        hint = (" (KinematicTree.from_chain(chain) is the tree of a chain)"
                if isinstance(tree, KinematicChain) else "")  # fmt: skip
        raise InvalidTypeError(f"tree must be a KinematicTree{hint}, got {type(tree).__name__}")
    return tree


def _check_connector_options(options) -> ConnectorOptions:
    """``options``, the default ConnectorOptions for None, or InvalidTypeError."""
    options = ConnectorOptions() if options is None else options
    if not isinstance(options, ConnectorOptions):
        raise InvalidTypeError(f"options must be ConnectorOptions, got {shown(options)}")
    return options


def default_trunks(tree: KinematicTree) -> dict[int, int]:
    """The trunk of every joint with several children: the child with the longest path to a
    leaf (ties: the smaller index)."""
    _check_tree(tree)
    longest = _downstream(tree)
    return {k: max(kids, key=lambda c: (longest[c], -c))
            for k, kids in enumerate(tree.Children) if len(kids) > 1}  # fmt: skip


def _check_trunks(tree: KinematicTree, trunks) -> dict[int, int]:
    """``trunks`` (None, or a mapping from branching joints to one of their children) checked
    and merged over the default trunks; indices are integers (numpy's too), never bools."""
    chosen = default_trunks(tree)
    if trunks is None:
        return chosen
    if not isinstance(trunks, Mapping):
        raise InvalidTypeError(f"trunks must map joints to children, got {shown(trunks)}")
    children = tree.Children
    for key, value in trunks.items():
        joint = check_int("trunks: a joint", key, floats=False)
        if joint not in chosen:
            raise InvalidParameterError(
                f"trunks: joint {shown(joint)} does not branch (joints with several children: "
                f"{sorted(chosen)})"
            )
        child = check_int(f"trunks[{joint}]", value, floats=False)
        if child not in children[joint]:
            raise InvalidParameterError(
                f"trunks: {shown(child)} is not a child of joint {joint} (its children: "
                f"{list(children[joint])})"
            )
        chosen[joint] = child
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
    _check_tree(tree)
    options = _check_connector_options(options)
    chosen = _check_trunks(tree, trunks)
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
    junction: str | Mapping[int, str] = "connector",
    takeoff: TakeoffOptions | None = None,
) -> TreeFabrication:
    """The sheets and junctions of ``tree`` at its current states.

    Parameters
    ----------
    tree : KinematicTree (one without branches gives one sheet and no junction; a
        KinematicChain is refused: its tree is ``KinematicTree.from_chain(chain)``).
    trunks : ``{joint: child}`` for the joints whose trunk is not the default one.
    options : connector options (wall, clearance, socket depth; docs/junctions.md).
    twistPortion : fraction of each straight part taken by its twist fitting (default 0.2).
    junction : how the children of a branching joint are joined: ``"connector"`` (default, a
        printed connector), ``"takeoff"`` (every side branch leaves the trunk's link through a
        face, folded: the trunk's sheet gets a hole, the branch's sheet starts with a skirt and
        glue tabs), ``"auto"`` (take-offs where they can be made, else a connector, with a note
        in ``notes``), or ``{joint: kind}`` for some joints (the others: connectors).
    takeoff : dimensions of the take-offs (:class:`~kinegami.fabrication.takeoffs.TakeoffOptions`).

    Raises
    ------
    InvalidParameterError
        When a branch child's socket does not fit on its link (its link is shorter than the
        stretch it runs with its siblings plus the socket): slide or compact the tree first;
        when a joint asked to be made with take-offs cannot be (the message names the joint and
        why); for a bad ``junction`` value.
    """
    _check_tree(tree)
    twistPortion = check_twist_portion(twistPortion)
    options = _check_connector_options(options)
    takeoff = TakeoffOptions() if takeoff is None else takeoff
    if not isinstance(takeoff, TakeoffOptions):
        raise InvalidTypeError(f"takeoff must be TakeoffOptions, got {takeoff!r}")
    takeoff = takeoff.resolved(tree.r)
    requested = _junction_kinds(tree, junction)
    check_pattern_size(  # the sheets hold every link and joint (take-offs add a skirt each)
        [p for link in tree.Links[1:] for p in link.pattern_pieces(tree.numSides, twistPortion)]
        + [p for joint in tree.Joints for p in joint.pattern_pieces()], "the tree's sheets")
    kinds = {k: ("connector" if kind == "connector" else "takeoff")
             for k, kind in requested.items()}  # fmt: skip
    notes: list[str] = []
    work = TakeoffWork()  # TAKEOFF_WORK for the whole tree, every attempt included
    while True:
        try:
            return _fabricate(tree, kinds, trunks, options, twistPortion, takeoff, tuple(notes),
                              work)  # fmt: skip
        except _NoTakeoffError as failure:
            if requested[failure.joint] != "auto":
                raise InvalidParameterError(
                    f"junction at joint {failure.joint}: no folded take-off can be made: "
                    f"{failure.reason}; use junction='connector' (or 'auto') for it"
                ) from None
            kinds[failure.joint] = "connector"
            notes.append(f"joint {failure.joint} has a printed connector: no folded take-off "
                         f"can be made ({failure.reason})")  # fmt: skip


def _junction_kinds(tree: KinematicTree, junction) -> dict[int, str]:
    """The kind asked for at every branching joint."""
    branching = [k for k, kids in enumerate(tree.Children) if len(kids) > 1]
    choices = ", ".join(map(repr, JUNCTION_KINDS))
    if isinstance(junction, str):
        if junction not in JUNCTION_KINDS:
            raise InvalidParameterError(f"junction must be one of {choices} or a mapping "
                                        f"{{joint: kind}}, got {junction!r}")  # fmt: skip
        return dict.fromkeys(branching, junction)
    if not isinstance(junction, Mapping):
        raise InvalidTypeError(
            f"junction must be one of {choices} or a mapping {{joint: kind}}, got {junction!r}"
        )
    kinds = dict.fromkeys(branching, "connector")
    for joint, kind in junction.items():
        if joint not in kinds:
            raise InvalidParameterError(
                f"junction: joint {joint!r} does not branch (joints with several children: "
                f"{branching})"
            )
        if kind not in JUNCTION_KINDS:
            raise InvalidParameterError(
                f"junction[{joint}] must be one of {choices}, got {kind!r}"
            )
        kinds[joint] = kind
    return kinds


class _NoTakeoffError(Exception):
    """Raised inside :func:`_fabricate` when a joint's take-offs cannot be placed."""

    def __init__(self, joint: int, reason: str):
        super().__init__(joint, reason)
        self.joint, self.reason = joint, reason


def _record_count(patterns) -> int:
    """How many module records ``TubularPattern.concatenate(patterns)`` keeps (an empty
    pattern after the first adds none)."""
    return sum(len(p.modules) for i, p in enumerate(patterns) if i == 0 or not p.isEmpty)


def _trunk_candidates(tree, joint: int, trunks, longest) -> list[int]:
    if trunks is not None and joint in trunks:
        return [int(trunks[joint])]
    return sorted(tree.Children[joint], key=lambda c: (-longest[c], c))


def _fabricate(tree, kinds, trunks, options, twistPortion, takeoff, notes,
               work: TakeoffWork) -> TreeFabrication:  # fmt: skip
    from kinegami.pattern.folded import UVA_TO_DUBINS, unsnapped_form

    connector_kinds = {k for k, kind in kinds.items() if kind == "connector"}
    chosen, problems = choose_trunks(tree, trunks, options)
    problems = [(c, p) for c, p in problems if tree.Parents[c] in connector_kinds]
    if problems:
        raise InvalidParameterError(
            "the tree cannot be made with printed junctions: " + "; ".join(p for _, p in problems)
            + ". Slide those joints along their axes (or compact the tree: kinegami compact) "
            "so that their links get longer"
        )
    trunk_of = {k: chosen[k] for k in sorted(connector_kinds)}
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
    built: list[dict] = []
    placed: dict[int, dict] = {}  # branch child -> its take-off (placement, trunk sheet, ...)
    fabricated_links = list(tree.Links)
    body: list = []  # the take-offs as the folded body needs them (takeoffs.takeoff_body)
    # the take-off search's work (``work``: TAKEOFF_WORK for the whole tree): each take-off
    # joint gets what is left over the joints still to place (docs/limits.md)
    takeoff_joints = sum(1 for kind in kinds.values() if kind != "connector")
    starts = [0]
    while starts:
        first = starts.pop(0)
        sheet_index = len(built)
        start = placed.get(first)
        if first == 0:
            modules = [tree.Joints[0].pattern]
            arc, junction, frame = 0.0, None, tree.Joints[0].proximal_dubins_frame()
        elif start is None:
            socket = socket_of[first]
            arc = float(socket.sheet_start)
            junction = junction_at[tree.Parents[first]]
            frame = np.asarray(socket.frame)
            rest = LinkCSC(r, frame, tree.Joints[first].proximal_dubins_frame(),
                           tree.maxAnglePerElbow)  # fmt: skip
            modules = rest.pattern_modules(n, twistPortion) + [tree.Joints[first].pattern]
        else:
            J = start["placement"].junction
            arc, junction = 0.0, None
            frame = J.skirt_frame(start["tube_frame"])
            link = start["placement"].link
            modules = ([J.skirt_pattern()] + link.pattern_modules(n, twistPortion)
                       + [tree.Joints[first].pattern])  # fmt: skip
            start["branch_sheet"] = sheet_index
        path = [first]
        holes = []
        branches = []
        while children[path[-1]]:
            k = path[-1]
            kids = children[k]
            if len(kids) == 1:
                t = kids[0]
                link_modules = tree.Links[t].pattern_modules(n, twistPortion)
            elif kinds[k] == "connector":
                t = trunk_of[k]
                link_modules = tree.Links[t].pattern_modules(n, twistPortion)
                branches += [c for c in kids if c != t]
            else:
                reasons = []
                share = TakeoffWork(max(0, work.left) // max(1, takeoff_joints))
                for t in _trunk_candidates(tree, k, trunks, longest):
                    link = tree.Links[t]
                    link_modules = link.pattern_modules(n, twistPortion)
                    at = next(i for i, m in enumerate(link_modules) if m.modules[0].kind == "tube")
                    if link_modules[at].isEmpty:  # a link without a straight part
                        reasons.append(f"trunk {t}: its link has no straight part")
                        continue
                    index = _record_count(modules + link_modules[:at])
                    prefix = TubularPattern.concatenate(modules + link_modules[: at + 1])
                    form = unsnapped_form(prefix, frame=frame)
                    tube = form.modules[index]
                    height = float(tube.record.params["height"])
                    tube_frame = tube.proximal @ UVA_TO_DUBINS
                    twist = twistPortion * link.path.tMag if link.hasTwist else 0.0
                    before = r * link.path.theta1 + twist  # arc length to the tube's start
                    before_search = share.left
                    found, reason = place_takeoffs(tree, k, t, tube_frame, height, before,
                                                   takeoff, body, share)  # fmt: skip
                    work.spend(before_search - share.left)
                    if found is not None:
                        break
                    reasons.append(f"trunk {t}: {reason}")
                else:
                    raise _NoTakeoffError(k, "; ".join(reasons))
                takeoff_joints -= 1
                for placement in found:
                    name = hole_name(len(placed))
                    placed[placement.child] = {
                        "name": name, "placement": placement, "tube_frame": tube_frame,
                        "joint": k, "trunk": t, "sheet": sheet_index, "module": index,
                        "arc": before + placement.junction.y0,
                    }  # fmt: skip
                    fabricated_links[placement.child] = placement.link
                    body.append((t, before + placement.junction.y0, placement.child,
                                 placement.link))  # fmt: skip
                    holes.append(SheetHole(name, index, placement.junction))
                    branches.append(placement.child)
            modules += link_modules + [tree.Joints[t].pattern]
            path.append(t)
        # the sheets starting along this one, joint by joint, longest first (breadth first)
        starts += sorted(branches, key=lambda c: (path.index(tree.Parents[c]), -longest[c], c))
        pattern = TubularPattern.concatenate(modules)
        if holes or start is not None:
            pattern = CutPattern(pattern, holes=tuple(holes),
                                 skirt=None if start is None else start["placement"].junction,
                                 skirt_name=None if start is None else start["name"],
                                 frame=frame)  # fmt: skip
        built.append({"joints": tuple(path), "junction": junction, "arc": arc,
                      "pattern": pattern, "frame": frame, "start": start})  # fmt: skip

    takeoffs = tuple(
        Takeoff(info["name"], info["joint"], child, info["trunk"], info["sheet"],
                info["branch_sheet"], info["module"], info["arc"],
                info["placement"].junction, info["placement"].frame, info["placement"].link)
        for child, info in placed.items()
    )  # fmt: skip
    sheets = []
    for k, info in enumerate(built):
        start = info["start"]
        holes = tuple((t.name, t.branch_sheet) for t in takeoffs if t.sheet == k)
        sheets.append(TreeSheet(
            k, info["joints"], info["junction"], info["arc"], info["pattern"],
            frame=_readonly_frame(info["frame"]),
            takeoff=None if start is None else start["name"],
            takeoff_sheet=None if start is None else start["sheet"],
            holes=holes,
            tabs=0 if start is None else len(start["placement"].junction.tabs),
        ))  # fmt: skip
    return TreeFabrication(tree, tuple(sheets), tuple(junctions), options, takeoffs, notes,
                           tuple(fabricated_links))  # fmt: skip


def _readonly_frame(frame) -> np.ndarray:
    frame = np.array(frame, dtype=float)
    frame.flags.writeable = False
    return frame


#: Slides tried (in r, smallest first) to give a branch child's socket room (fit_junctions).
FIT_SLIDES = tuple(s * sign for s in (0.25, 0.5, 0.75, 1.0, 1.5, 2.0, 3.0, 4.0, 6.0, 8.0)
                   for sign in (1.0, -1.0))  # fmt: skip


def fit_junctions(
    tree: KinematicTree,
    *,
    trunks: Mapping[int, int] | None = None,
    options: ConnectorOptions | None = None,
    progress=False,
) -> tuple[KinematicTree, list[tuple[int, float]]]:
    """A copy of ``tree`` in which every branch child's socket fits, and the slides made.

    A child whose socket does not fit is slid along its own axis of motion (its subtree
    follows), by the smallest of :data:`FIT_SLIDES` that makes it fit without making the tree
    pass through itself more than before: the axes, hence the kinematics, stay as they were.
    ``tree`` is not changed. Returns ``(tree, [(joint, slide in the tree's length units), ...])``.
    ``progress`` (docs/progress.md): ``progress(done, total)`` as the sockets that did not fit
    are fitted (total: their count so far), and after each slide tried; returning False
    stops with :class:`~kinegami.errors.Cancelled` (default False: no report; True: a bar on
    stderr).

    Raises
    ------
    InvalidTypeError
        When ``tree`` is not a KinematicTree (a chain: ``KinematicTree.from_chain``), or
        ``options`` not ConnectorOptions.
    InvalidParameterError
        When no slide makes some socket fit (the message names the joint).
    """
    import copy
    import warnings

    from kinegami.errors import ClearanceWarning, PlacementWarning
    from kinegami.progress import Progress, check_progress

    _check_tree(tree)
    options = _check_connector_options(options)
    progress = check_progress(progress)
    fitted = copy.copy(tree)
    moves: list[tuple[int, float]] = []

    def depth(t: KinematicTree) -> float:
        report = t.clearance()
        return 0.0 if report.ok else -report.min_clearance

    with warnings.catch_warnings(), Progress(progress, 0, desc="fit junctions",
                                             unit="socket") as bar:  # fmt: skip
        warnings.simplefilter("ignore", ClearanceWarning)
        warnings.simplefilter("ignore", PlacementWarning)
        for _ in range(len(tree.Joints)):
            problems = junction_problems(fitted, trunks=trunks, options=options)
            bar.total = max(bar.total, len(moves) + len(problems))
            bar.check()
            if not problems:
                return fitted, moves
            child, reason = problems[0]
            before = depth(fitted)
            for slide in FIT_SLIDES:
                bar.check()
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
                bar.update()
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
