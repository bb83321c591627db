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
least through itself (:func:`takeoff_overlap`), then the shortest new link; the branches of one
joint are placed together, their holes (with margins) apart. Each candidate is a clearance test
of the whole body, so one tree's search (every joint's together) measures at most
``kinegami.limits.TAKEOFF_WORK / capsules`` candidates (:class:`TakeoffWork`, docs/limits.md):
a body of many capsules tries fewer heights, then fewer faces (evenly spread); ordinary trees
try them all.

The folded body is measured as a tree of its own (:func:`takeoff_body`): the trunk's link is
cut at every take-off point O (the trunk's axis point at the hole's centre) by a zero-length
waypoint whose children are the rest of the trunk and the branches leaving there. So the
clearance rules of :func:`kinegami.clearance.tree_bodies.tree_worst_overlap` treat the trunk
and a branch
like the tubes leaving one joint: not where they still run together next to the take-off, and
as any two branches beyond.
"""

from __future__ import annotations

import itertools
import math
import re
from collections.abc import Sequence
from dataclasses import dataclass, field, replace

import numpy as np

from kinegami.chain.bodies import Overlap, link_polyline
from kinegami.chain.joints import Waypoint
from kinegami.chain.links import LinkCSC
from kinegami.clearance.tree_bodies import tree_worst_overlap
from kinegami.errors import InvalidParameterError, InvalidTypeError, NoPathError
from kinegami.geometry.csc_centreline import csc_transported_frame
from kinegami.limits import TAKEOFF_WORK
from kinegami.pattern.takeoff import TakeoffJunction, takeoff_junction
from kinegami.validation import check_in_range, check_int, check_radius

__all__ = [
    "JUNCTION_KINDS",
    "TakeoffOptions",
    "TakeoffWork",
    "Takeoff",
    "TakeoffPlacement",
    "hole_name",
    "place_takeoffs",
    "takeoff_body",
    "takeoff_overlap",
]

#: How a branching joint's children are joined: a printed connector, folded take-offs, or
#: take-offs where they can be made and a connector elsewhere.
JUNCTION_KINDS = ("connector", "takeoff", "auto")

#: Candidates kept per branch for the joint search (the best by overlap, then length).
CANDIDATES_PER_BRANCH = 6
#: Largest number of combinations searched jointly; beyond it branches are placed one by one.
MAX_COMBINATIONS = 20000
#: How many of the best-ranked combinations are measured together.
EVALUATED_SETS = 48
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


@dataclass
class TakeoffWork:
    """The capsule tests a take-off search may still measure (a candidate measured on a body
    of S capsules costs S, and its junction extents more: :func:`candidate_cost`): ``left`` of
    them, spent by :func:`place_takeoffs` as it measures.
    :func:`~kinegami.fabrication.sheets.fabricate` gives each take-off joint its share of
    ``TAKEOFF_WORK`` (what is left over the joints still to place), so the work of one tree
    is bounded whatever its number of joints (docs/limits.md)."""

    left: int = field(default_factory=lambda: TAKEOFF_WORK)

    def spend(self, capsules: int) -> None:
        """Charge one candidate measured on a body of ``capsules`` capsules."""
        self.left -= capsules


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
    depth : the deepest overlap of the folded body with this branch's new link (and the
        take-offs placed before; units of r, >= 0).
    """

    child: int
    junction: TakeoffJunction
    frame: np.ndarray = field(repr=False)
    link: LinkCSC = field(repr=False)
    depth: float = 0.0


@dataclass(frozen=True, eq=False)
class Takeoff:
    """A folded take-off junction of a fabricated tree
    (:func:`kinegami.fabrication.sheets.fabricate`).

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


#: A take-off as the folded body needs it: (trunk child, arc length along the trunk's link of the
#: take-off point O, branch child, the branch's first link from T).
BodyTakeoff = tuple[int, float, int, LinkCSC]


def takeoff_body(tree, takeoffs: Sequence[BodyTakeoff], cache: dict | None = None):
    """The folded body with take-offs as a tree: ``(joints, links, parents, original)``.

    Every trunk link with take-offs is cut at each take-off point O (arc length ``sigma``
    along it) by a zero-length :class:`~kinegami.chain.joints.Waypoint` whose Dubins frame is the
    link's frame there; the branches leaving at O are its children, with their take-off links;
    the rest of the trunk's link goes on to the trunk child. The cut pieces are the same CSC
    path. Nodes are in a topological order; ``original[k]`` is the tree index of node k (for
    a waypoint: the trunk child whose link it cuts). ``cache`` (a dict) keeps the cut pieces
    between calls on the same tree.
    """
    cache = {} if cache is None else cache

    def piece(k: int, start: np.ndarray, end: np.ndarray, key: tuple) -> LinkCSC:
        found = cache.get((k,) + key)
        if found is None:
            found = cache[(k,) + key] = LinkCSC(r, start, end, tree.maxAnglePerElbow)
        return found

    n, r = tree.numSides, tree.r
    parents_in = tree.Parents
    cuts: dict[int, list[float]] = {}
    branch_at: dict[int, tuple[int, float]] = {}
    new_link: dict[int, LinkCSC] = {}
    for trunk, sigma, child, link in takeoffs:
        if not any(abs(sigma - s) <= 1e-9 * r for s in cuts.get(trunk, [])):
            cuts.setdefault(trunk, []).append(float(sigma))
        branch_at[child] = (trunk, float(sigma))
        new_link[child] = link
    for values in cuts.values():
        values.sort()
    order: list[tuple[str, int, float]] = []  # ("joint", k, 0) or ("cut", trunk, sigma)
    for k in range(len(tree.Joints)):
        order.append(("joint", k, 0.0))
        for t in tree.Children[k]:
            for sigma in cuts.get(t, []):
                order.append(("cut", t, sigma))
    position = {(kind, k, s): i for i, (kind, k, s) in enumerate(order)}
    joints, links, parents, original = [], [], [], []
    for kind, k, sigma in order:
        if kind == "cut":
            base = tree.Links[k]
            F = csc_transported_frame(base.path, base.start_frame, sigma)
            joints.append(Waypoint(n, r, F, pathIndex=0))
            before = [s for s in cuts[k] if s < sigma]
            parent = (position[("cut", k, before[-1])] if before
                      else position[("joint", parents_in[k], 0.0)])  # fmt: skip
            start = joints[parent].distal_dubins_frame()
            links.append(piece(k, start, F, (before[-1] if before else None, sigma)))
            parents.append(parent)
            original.append(k)
            continue
        joints.append(tree.Joints[k])
        original.append(k)
        if k == 0:
            links.append(tree.Links[0])
            parents.append(-1)
        elif k in branch_at:
            trunk, s = branch_at[k]
            links.append(new_link[k])
            parents.append(position[("cut", trunk, s)])
        elif k in cuts:
            parent = position[("cut", k, cuts[k][-1])]
            links.append(piece(k, joints[parent].distal_dubins_frame(),
                               tree.Joints[k].proximal_dubins_frame(), (cuts[k][-1], None)))
            parents.append(parent)
        else:
            links.append(tree.Links[k])
            parents.append(position[("joint", parents_in[k], 0.0)])
    return joints, links, parents, original


def takeoff_overlap(tree, takeoffs: Sequence[BodyTakeoff], names=None,
                    cache: dict | None = None, measured: list | None = None,
                    ) -> Overlap | None:  # fmt: skip
    """The closest pair of parts of the folded body with ``takeoffs`` (:func:`takeoff_body`, by
    the rules of :func:`kinegami.clearance.tree_bodies.tree_worst_overlap`) closer than the
    tree's ``margin``
    (0: the deepest overlap), its parts named by the tree's joint and link numbers (a cut trunk
    link's pieces as that link), or None when it is clear. ``measured``, when given, gets the
    number of capsule pairs the test measured appended."""
    margin = tree.margin
    if not takeoffs:
        return tree_worst_overlap(tree.Joints, tree.Links, tree.Parents, tree.r, names=names,
                                  margin=margin, measured=measured)  # fmt: skip
    joints, links, parents, original = takeoff_body(tree, takeoffs, cache)
    if names is not None:
        names = [names[k] if k < len(names) else None for k in original]
    found = tree_worst_overlap(joints, links, parents, tree.r, names=names, margin=margin,
                               measured=measured)  # fmt: skip
    if found is None:
        return None

    def renamed(text: str) -> str:
        return re.sub(r"\b(joint|link) (\d+)\b",
                      lambda m: f"{m.group(1)} {original[int(m.group(2))]}", text)  # fmt: skip

    return replace(found, first=renamed(found.first), second=renamed(found.second),
                   elements=(-1, -1))  # fmt: skip


def place_takeoffs(
    tree,
    joint: int,
    trunk: int,
    tube_frame: np.ndarray,
    tube_height: float,
    tube_arc: float,
    options: TakeoffOptions,
    placed: Sequence[BodyTakeoff] = (),
    work: TakeoffWork | None = None,
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
    tube_arc : arc length along the trunk's link where the tube module starts.
    options : resolved :class:`TakeoffOptions`.
    placed : the take-offs placed so far elsewhere in the tree (:data:`BodyTakeoff`).
    work : the capsule tests this search may measure, spent as it measures (default: a fresh
        ``TakeoffWork()``, all of ``TAKEOFF_WORK``); at least one candidate per branch and
        one set are measured whatever is left.

    Returns
    -------
    (placements, "") with one :class:`TakeoffPlacement` per branch child in child order, or
    (None, reason) when no placement exists.
    """
    if not isinstance(options, TakeoffOptions):
        raise InvalidTypeError(f"options must be TakeoffOptions, got {options!r}")
    n, r = tree.numSides, tree.r
    work = TakeoffWork() if work is None else work
    placed = list(placed)
    cache: dict = {}  # the trunk's cut pieces, shared by every candidate
    branches = [c for c in tree.Children[joint] if c != trunk]
    probe = takeoff_junction(n, r, 0, 0.0, stub_length=options.stub_length,
                             tab_width=options.tab_width)  # fmt: skip
    e = probe.axial_half_extent + probe.margin
    if tube_height < 2.0 * e - 1e-12 * r:
        return None, (
            f"the plain tube of the trunk's link (to joint {trunk}) is {tube_height / r:.3g} r "
            f"long; a take-off hole with its margin needs {2.0 * e / r:.3g} r (n = {n})"
        )
    span = max(0.0, tube_height - 2.0 * e)
    count = 1 if span <= 1e-9 * r else options.heights
    capsules = body_capsules(tree)
    cost = {c: candidate_cost(tree, trunk, c, capsules) for c in branches}
    set_cost = capsules + sum(cost[c] - capsules for c in branches)
    tests, sets = search_budget(tree, len(branches), work.left, max(cost.values()))
    count = min(count, max(1, tests // n))
    faces = range(n) if n <= tests else sorted({round(k * n / tests) for k in range(tests)})
    heights = [e + span * (0.5 if count == 1 else k / (count - 1)) for k in range(count)]
    W = probe.prism.W
    candidates: dict[int, list[TakeoffPlacement]] = {}
    for c in branches:
        end = tree.Joints[c].proximal_dubins_frame()
        found = []
        for p, y0 in ((p, y0) for p in faces for y0 in heights):
            if found and work.left <= 0:  # spent (each branch measures one at least)
                break
            J = takeoff_junction(n, r, p, y0, stub_length=options.stub_length,
                                 tab_width=options.tab_width)  # fmt: skip
            T = J.takeoff_frame(tube_frame)
            try:
                link = LinkCSC(r, T, end, tree.maxAnglePerElbow)
            except NoPathError:
                continue
            trial = placed + [(trunk, tube_arc + y0, c, link)]
            pairs: list = []
            depth = _depth(takeoff_overlap(tree, trial, cache=cache, measured=pairs))
            # a body folded onto itself costs per near pair, not per capsule
            work.spend(max(cost[c], sum(pairs) // NEAR_PAIRS_PER_TEST))
            found.append(TakeoffPlacement(c, J, T, link, depth))
        if not found:
            return None, (
                f"no face of the trunk's link (to joint {trunk}) gives a CSC path with turns "
                f"below pi to joint {c}"
            )
        found.sort(key=lambda q: (round(q.depth / (DEPTH_TOLERANCE * r)), q.link.length,
                                  q.junction.face, q.junction.y0))  # fmt: skip
        candidates[c] = found
    sets = max(1, min(sets, work.left // max(1, set_cost)))  # what the branches left
    return _combine(tree, trunk, tube_arc, branches, candidates, placed, W, r, cache, sets,
                    lambda: work.spend(set_cost))  # fmt: skip


#: Near capsule pairs of a candidate's body test that cost about one capsule test (a body of
#: S capsules costs S; a body folded onto itself measures millions of pairs per candidate:
#: fuzz operations seed 409604 spent 165 s in its take-off search).
NEAR_PAIRS_PER_TEST = 16

#: Pairs of capsules of the two tubes at a take-off's junction whose extent measuring costs
#: about one capsule test of the body (a junction extent measures each tube's capsules against
#: the other's: 600,000 pairs took 80 ms, a body test about 17 us per capsule).
JUNCTION_PAIRS_PER_TEST = 128


def candidate_cost(tree, trunk: int, child: int, capsules: int | None = None) -> int:
    """The capsule tests one take-off candidate of branch ``child`` off ``trunk`` costs: the
    body's ``capsules`` (default :func:`body_capsules`), plus the junction extents of the two
    tubes leaving the take-off, each tube's capsules against the other's (estimated from the
    child's and the trunk's links as they are; long tubes of one-degree elbows made a
    candidate cost 20 times its capsules)."""
    capsules = body_capsules(tree) if capsules is None else capsules
    branch = 2 * (len(link_polyline(tree.Links[child])) - 1)
    stem = 2 * (len(link_polyline(tree.Links[trunk])) - 1)
    return capsules + (2 * branch * stem) // JUNCTION_PAIRS_PER_TEST


def body_capsules(tree) -> int:
    """About how many capsules a clearance test of ``tree``'s folded body measures: two per
    elbow and two per joint."""
    return 2 * len(tree.Joints) + sum(2 * (len(link_polyline(link)) - 1)
                                      for link in tree.Links[1:])  # fmt: skip


def search_budget(tree, branches: int, work: int = TAKEOFF_WORK,
                  capsules: int | None = None) -> tuple[int, int]:  # fmt: skip
    """How many placements of one branch (faces times heights) and how many sets of
    placements the take-off search at a joint with ``branches`` branches measures: within
    ``work`` capsule tests in all (docs/limits.md), each test measuring the whole body
    (``capsules``, default :func:`body_capsules`), at least one of each."""
    capsules = body_capsules(tree) if capsules is None else capsules
    total = max(2, work // max(1, capsules))
    sets = max(1, min(EVALUATED_SETS, total // 4))
    return max(1, (total - sets) // max(1, branches)), sets


def _combine(tree, trunk, tube_arc, branches, candidates, placed, W, r, cache,
             evaluated: int = EVALUATED_SETS, measured=None):  # fmt: skip
    """The best set of placements, one per branch, whose holes are apart.

    Each branch contributes its best candidates and its best one at every height; the sets
    whose holes are apart are ranked by their worst single depth and total length, and the
    first ``evaluated`` (at most :data:`EVALUATED_SETS`) are measured together (the depth of
    the tree with all their links; ``measured()``, when given, after each). Without such a
    set (or with too many), branches are placed one by one. One branch: its best candidate,
    whose body was measured with the same placements already (fuzz operations seed 502287
    measured each of three such bodies twice, 3.3 s a time).
    """
    pools = []
    for c in branches:
        pool = list(candidates[c][:CANDIDATES_PER_BRANCH])
        for q in candidates[c]:
            if all(abs(q.junction.y0 - other.junction.y0) > 1e-9 * r for other in pool):
                pool.append(q)
        pools.append(pool)
    if len(branches) == 1:  # each set is one candidate, measured with the same placements
        scale = DEPTH_TOLERANCE * r
        return [min(pools[0], key=lambda q: (round(q.depth / scale), q.link.length))], ""
    if math.prod(len(p) for p in pools) <= MAX_COMBINATIONS:
        scale = DEPTH_TOLERANCE * r
        sets = [combo for combo in itertools.product(*pools)
                if all(_apart(a.junction, b.junction, W)
                       for a, b in itertools.combinations(combo, 2))]  # fmt: skip
        sets.sort(key=lambda combo: (round(max(q.depth for q in combo) / scale),
                                     sum(q.link.length for q in combo)))  # fmt: skip
        best, best_key = None, None
        for combo in sets[:evaluated]:
            trial = placed + [(trunk, tube_arc + q.junction.y0, q.child, q.link) for q in combo]
            depth = _depth(takeoff_overlap(tree, trial, cache=cache))
            if measured is not None:
                measured()
            key = (round(depth / scale), sum(q.link.length for q in combo))
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
