"""Folded take-off junctions in a tree: where each side branch leaves its trunk
(docs/junctions.md, "Folded take-off junctions").

At a branching joint B built with take-offs, the trunk child t's tube runs on uninterrupted and
every other child c leaves the plain tube part of t's link (after its twist fitting) through one
of its faces, at right angles (:mod:`kinegami.pattern.takeoff`). The branch's first link is then
a new CSC path from the take-off frame T (on the trunk's face, rigidly attached to link t) to
c's proximal frame: c and everything after it stay where they are, so the kinematics are
unchanged; only the tube between the trunk and c is routed anew.

For each branch the face p and the hole's height y0 are chosen among every face and
``TakeoffOptions.heights`` heights spread over the part of the tube that holds the hole and its
margin: those from which a CSC path to c exists, preferring the placement whose body passes
least through itself (the deepest overlap of the tree with the new links, by the rules of
:func:`kinegami.bodies.tree_worst_overlap`), then the shortest new link; the branches of one
joint are placed together, their holes (with margins) apart.
"""

from __future__ import annotations

import itertools
import math
from dataclasses import dataclass, field

import numpy as np

from kinegami.bodies import tree_worst_overlap
from kinegami.errors import InvalidParameterError, InvalidTypeError, NoPathError
from kinegami.links import LinkCSC
from kinegami.pattern.takeoff import TakeoffJunction, takeoff_junction
from kinegami.validation import check_in_range, check_int, check_radius

__all__ = [
    "JUNCTION_KINDS",
    "TakeoffOptions",
    "Takeoff",
    "TakeoffPlacement",
    "hole_name",
    "place_takeoffs",
]

#: How a branching joint's children are joined: a printed connector, folded take-offs, or
#: take-offs where they can be made and a connector elsewhere.
JUNCTION_KINDS = ("connector", "takeoff", "auto")

#: Candidates kept per branch for the joint search (the best by overlap, then length).
CANDIDATES_PER_BRANCH = 6
#: Largest number of combinations searched jointly; beyond it branches are placed one by one.
MAX_COMBINATIONS = 256
#: Overlap depths closer than this many r count as equal when placements are compared.
DEPTH_TOLERANCE = 1e-6


@dataclass(frozen=True)
class TakeoffOptions:
    """Dimensions of the folded take-off junctions (lengths in the units of r; ``None`` is the
    default for the tube radius, filled in by ``resolved(r)``).

    Attributes
    ----------
    tab_width : height of the glue tabs, in (0, r] (default 0.2 r).
    stub_length : straight tube h0 between the skirt and the take-off frame, in [0, 10 r]
        (default 0).
    heights : how many hole heights to try along the trunk's tube, an integer in [1, 50]
        (default 5).
    """

    tab_width: float | None = None
    stub_length: float | None = None
    heights: int = 5

    def resolved(self, r: float) -> TakeoffOptions:
        """The options with every default filled in for the tube radius ``r``, checked."""
        r = check_radius(r)
        tab = 0.2 * r if self.tab_width is None else self.tab_width
        stub = 0.0 if self.stub_length is None else self.stub_length
        tab = check_in_range("tab_width", tab, 0.0, r, high_inclusive=True,
                             range_text=f"(0, r] = (0, {r:g}] (r = {r:g})")  # fmt: skip
        stub = check_in_range("stub_length", stub, 0.0, 10.0 * r, low_inclusive=True,
                              high_inclusive=True,
                              range_text=f"[0, 10 r] = [0, {10.0 * r:g}] (r = {r:g})")  # fmt: skip
        heights = check_int("heights", self.heights, minimum=1)
        if heights > 50:
            raise InvalidParameterError(f"heights must be an integer in [1, 50], got {heights}")
        return TakeoffOptions(tab, stub, heights)


@dataclass(frozen=True, eq=False)
class TakeoffPlacement:
    """Where one branch leaves the trunk's tube (what :func:`place_takeoffs` chooses).

    Attributes
    ----------
    child : the branch child (tree index).
    junction : the take-off geometry; its ``face`` is numbered and its ``y0`` measured in the
        trunk tube module's own coordinates.
    frame : the take-off frame T (4x4 world Dubins frame: x along the branch, y = s).
    link : the branch's first link, from T to the child's proximal Dubins frame.
    depth : the deepest overlap of the tree with this branch's new link (units of r, >= 0).
    """

    child: int
    junction: TakeoffJunction
    frame: np.ndarray = field(repr=False)
    link: LinkCSC = field(repr=False)
    depth: float = 0.0


@dataclass(frozen=True, eq=False)
class Takeoff:
    """A folded take-off junction of a fabricated tree (:func:`kinegami.tree.sheets.fabricate`).

    Attributes
    ----------
    name : its name in the drawings (``"A"``, ``"B"``, ...): hole ``name`` of the trunk's sheet
        takes the skirt of the branch's sheet.
    joint : the branching joint.
    child : the branch child whose sheet starts here.
    trunk : the trunk child, whose link's plain tube holds the hole.
    sheet : the trunk's sheet (it has the hole).
    branch_sheet : the branch's sheet (it starts with the skirt).
    module : index of the trunk tube module in the trunk sheet's pattern.
    arc : arc length along the trunk's link from joint ``joint`` to the hole's centre (units
        of r).
    junction : the take-off geometry (face and height in the tube module's coordinates).
    frame : the take-off frame T (4x4 world Dubins frame).
    link : the branch's first link, from T to the child's proximal Dubins frame.
    """

    name: str
    joint: int
    child: int
    trunk: int
    sheet: int
    branch_sheet: int
    module: int
    arc: float
    junction: TakeoffJunction
    frame: np.ndarray = field(repr=False)
    link: LinkCSC = field(repr=False)

    @property
    def face(self) -> int:
        """The trunk face the branch leaves through (numbered in the trunk's tube module)."""
        return self.junction.face

    @property
    def tabs(self) -> int:
        """Number of glue tabs on the branch's skirt."""
        return len(self.junction.tabs)


def hole_name(k: int) -> str:
    """The k-th take-off's name: A, B, ..., Z, AA, AB, ..."""
    k = int(k)
    name = ""
    while True:
        name = chr(ord("A") + k % 26) + name
        k = k // 26 - 1
        if k < 0:
            return name


def _keep_out(junction: TakeoffJunction) -> tuple[float, float, float, float]:
    """The part of the trunk's sheet a hole and its margin take: (x_lo, x_hi, y_lo, y_hi) in
    the tube module's coordinates (x continuous)."""
    hole = junction.hole_unwrapped
    m = junction.margin
    y_lo, y_hi = junction.trunk_span
    return (float(hole[:, 0].min()) - m, float(hole[:, 0].max()) + m, y_lo, y_hi)


def _apart(first: TakeoffJunction, second: TakeoffJunction, W: float) -> bool:
    """Whether two holes (with margins) on one tube leave each other room."""
    a, b = _keep_out(first), _keep_out(second)
    if a[3] <= b[2] or b[3] <= a[2]:
        return True
    # x intervals on a circle of length W
    for shift in (-W, 0.0, W):
        if a[0] < b[1] + shift and b[0] + shift < a[1]:
            return False
    return True


def _depth(overlap) -> float:
    return 0.0 if overlap is None else max(0.0, -float(overlap.clearance))


def place_takeoffs(
    tree,
    joint: int,
    trunk: int,
    tube_frame: np.ndarray,
    tube_height: float,
    options: TakeoffOptions,
    links=None,
) -> tuple[list[TakeoffPlacement] | None, str]:
    """Where every branch child of ``joint`` leaves the trunk ``trunk``'s plain tube.

    Parameters
    ----------
    tree : the KinematicTree.
    joint, trunk : the branching joint and its trunk child.
    tube_frame : 4x4 frame (e_u, e_v, e_a, origin) of the trunk's plain tube module at its
        proximal end, in the convention of :meth:`TakeoffJunction.fold_trunk` (the folded form
        of the trunk's sheet gives it).
    tube_height : the tube module's height (its length along the trunk).
    options : resolved :class:`TakeoffOptions`.
    links : the tree's links with the take-offs placed so far (default: ``tree.Links``).

    Returns
    -------
    (placements, "") with one :class:`TakeoffPlacement` per branch child in child order, or
    (None, reason) when no placement exists.
    """
    if not isinstance(options, TakeoffOptions):
        raise InvalidTypeError(f"options must be TakeoffOptions, got {options!r}")
    n, r = tree.numSides, tree.r
    links = list(tree.Links) if links is None else list(links)
    branches = [c for c in tree.Children[joint] if c != trunk]
    probe = takeoff_junction(n, r, 0, 0.0, stub_length=options.stub_length,
                             tab_width=options.tab_width)  # fmt: skip
    e = probe.axial_half_extent + probe.margin
    if tube_height < 2.0 * e - 1e-12 * r:
        return None, (
            f"the plain tube of the trunk's link (to joint {trunk}) is {tube_height:.3g} r long; a "
            f"take-off hole with its margin needs {2.0 * e:.3g} r (n = {n})"
        )
    span = max(0.0, tube_height - 2.0 * e)
    count = 1 if span <= 1e-9 * r else options.heights
    heights = [e + span * (0.5 if count == 1 else k / (count - 1)) for k in range(count)]
    W = probe.prism.W
    candidates: dict[int, list[TakeoffPlacement]] = {}
    for c in branches:
        end = tree.Joints[c].proximal_dubins_frame()
        found = []
        for p in range(n):
            for y0 in heights:
                J = takeoff_junction(n, r, p, y0, stub_length=options.stub_length,
                                     tab_width=options.tab_width)  # fmt: skip
                T = J.takeoff_frame(tube_frame)
                try:
                    link = LinkCSC(r, T, end, tree.maxAnglePerElbow)
                except NoPathError:
                    continue
                trial = list(links)
                trial[c] = link
                depth = _depth(tree_worst_overlap(tree.Joints, trial, tree.Parents, r))
                found.append(TakeoffPlacement(c, J, T, link, depth))
        if not found:
            return None, (
                f"no face of the trunk's link (to joint {trunk}) gives a CSC path with turns "
                f"below pi to joint {c}"
            )
        found.sort(key=lambda q: (round(q.depth / (DEPTH_TOLERANCE * r)), q.link.length,
                                  q.junction.face, q.junction.y0))  # fmt: skip
        candidates[c] = found
    return _combine(tree, branches, candidates, links, W, r)


def _combine(tree, branches, candidates, links, W, r):
    """The best set of placements, one per branch, whose holes are apart."""
    pools = [candidates[c][:CANDIDATES_PER_BRANCH] for c in branches]
    if math.prod(len(p) for p in pools) <= MAX_COMBINATIONS:
        best, best_key = None, None
        for combo in itertools.product(*pools):
            if not all(_apart(a.junction, b.junction, W)
                       for a, b in itertools.combinations(combo, 2)):  # fmt: skip
                continue
            trial = list(links)
            for q in combo:
                trial[q.child] = q.link
            depth = _depth(tree_worst_overlap(tree.Joints, trial, tree.Parents, r))
            key = (round(depth / (DEPTH_TOLERANCE * r)), sum(q.link.length for q in combo))
            if best_key is None or key < best_key:
                best, best_key = combo, key
        if best is not None:
            return list(best), ""
    # one by one, each the best that leaves the earlier ones room
    chosen: list[TakeoffPlacement] = []
    for c in branches:
        for q in candidates[c]:
            if all(_apart(q.junction, other.junction, W) for other in chosen):
                chosen.append(q)
                break
        else:
            return None, (
                f"the trunk's link has no room for the holes of every branch (joint {c} finds "
                "no face and height clear of its siblings' holes)"
            )
    return chosen, ""
