"""Limits on work that the counts of a design multiply (issue 29, docs/limits.md): joints added
through the API (MAX_API_JOINTS), the vertices of a crease pattern (MAX_PATTERN_VERTICES) and
the candidates of a tree's take-off search (TAKEOFF_WORK). Each refusal is one line naming the
value, the limit and why, given before the work starts, and leaves the design bit-identical."""

from __future__ import annotations

import math
import warnings

import pytest
from gallery_designs import TREE_DESIGNS
from spatialmath import SE3

from kinegami import (
    EndTip,
    InvalidParameterError,
    KinegamiError,
    KinematicChain,
    KinematicTree,
    PlacementWarning,
    PrismaticJoint,
    RevoluteJoint,
    StartTip,
    Waypoint,
    limits,
)
from kinegami.design import load_design
from kinegami.fabrication import takeoffs
from kinegami.pattern import catalog
from kinegami.pattern.catalog import check_pattern_size, module_kind, module_vertices


# --- joints through the API -------------------------------------------------------------------
def _full(monkeypatch, limit: int) -> None:
    monkeypatch.setattr("kinegami.validation.MAX_API_JOINTS", limit)


def test_append_to_a_chain_with_max_api_joints_returns_none_and_warns(monkeypatch, snapshot):
    chain = KinematicChain(StartTip(4, 1, SE3(), 1))
    for k in range(2):
        assert chain.append(Waypoint(4, 1, SE3.Trans(0, 0, 5)), safe=False) == k + 1
    _full(monkeypatch, 3)
    before = snapshot(chain)
    with pytest.warns(PlacementWarning) as caught:
        assert chain.append(Waypoint(4, 1, SE3.Trans(0, 0, 5)), safe=False) is None
    text = str(caught[0].message)
    assert "\n" not in text
    for word in ("append failed", "has 3 joints", "MAX_API_JOINTS = 3", "unchanged"):
        assert word in text, (word, text)
    assert snapshot(chain) == before
    _full(monkeypatch, 4)  # one more fits
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)
        assert chain.append(Waypoint(4, 1, SE3.Trans(0, 0, 5)), safe=False) == 3


def test_add_joint_to_a_full_tree_returns_none_and_warns(monkeypatch, snapshot):
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    assert tree.addJoint(0, Waypoint(4, 1, SE3.Trans(0, 0, 5)), safe=False) == 1
    _full(monkeypatch, 2)
    before = snapshot(tree)
    with pytest.warns(PlacementWarning, match=r"addJoint failed: the tree has 2 joints"):
        assert tree.addJoint(0, EndTip(4, 1, SE3.Trans(5, 0, 0), 1), safe=False) is None
    assert snapshot(tree) == before


def test_max_api_joints_leaves_room_for_every_design_file():
    # a file's MAX_JOINTS entries with the waypoints safe placement adds (up to four each)
    assert limits.MAX_API_JOINTS >= limits.MAX_STATES == 5 * limits.MAX_JOINTS


# --- crease-pattern vertices ------------------------------------------------------------------
@pytest.mark.parametrize("piece", [
    ("revolute", (4, 1.0, math.pi, 1)), ("revolute", (8, 1.0, math.pi, 4)),
    ("revolute", (64, 1.0, 6.0, 32)), ("revolute", (256, 1.0, math.pi, 1)),
    ("prismatic", (4, 1.0, 2.0, 1, math.pi / 4)), ("prismatic", (64, 1.0, 2.0, 10, math.pi / 4)),
    ("prismatic", (256, 1.0, 2.0, 200, math.pi / 4)), ("elbow", (4, 1.0, 0.5, 0.3)),
    ("elbow", (64, 1.0, 0.5, 0.0)), ("twist", (64, 1.0, 0.5, 1.0)), ("tube", (256, 1.0, 1.0)),
    ("end_tip", (64, 1.0, 1.0)), ("start_tip", (8, 1.0, 1.0)),
])  # fmt: skip
def test_the_estimate_bounds_every_module_and_is_close(piece):
    kind, args = piece
    built = len(module_kind(kind).build(*args).vertices_coords)
    assert built <= module_vertices(kind, args) <= 4 * built + 8


def test_the_estimate_bounds_a_whole_chain(example_1a):
    pattern = example_1a.creasePattern()
    pieces = [link.pattern_pieces(4, 0.2) for link in example_1a.Links[1:]]
    recipe = [piece for joint in example_1a.Joints for piece in joint.pattern_pieces()]
    estimate = check_pattern_size([p for link in pieces for p in link] + recipe)
    assert len(pattern.vertices_coords) <= estimate <= 4 * len(pattern.vertices_coords)


def test_a_chain_whose_pattern_would_be_too_large_is_refused_before_building(
        monkeypatch, snapshot):  # fmt: skip
    chain = KinematicChain(StartTip(64, 1, SE3(), 1), maxAnglePerElbow=math.pi / 180)
    for _k in range(3):
        chain.append(PrismaticJoint(64, 1, 4, 200, math.pi / 4, SE3.Trans(0, 0, 30)), safe=False)
        chain.append(RevoluteJoint(64, 1, math.pi, SE3.Rx(3.0) * SE3.Trans(0, 0, 30)))
    before = snapshot(chain)
    built = []
    monkeypatch.setattr(catalog, "build_pieces", lambda pieces: built.append(1))
    monkeypatch.setattr("kinegami.pattern.catalog.MAX_PATTERN_VERTICES", 20_000)
    with pytest.raises(InvalidParameterError) as excinfo:
        chain.creasePattern()
    text = str(excinfo.value)
    assert "\n" not in text
    for word in ("crease-pattern vertices", "more than the limit 20,000", "MAX_PATTERN_VERTICES",
                 "250 bytes"):  # fmt: skip
        assert word in text, (word, text)
    assert not built  # refused before any module was built
    assert snapshot(chain) == before


def test_the_default_limit_builds_ordinary_and_large_patterns():
    chain = KinematicChain(StartTip(256, 1, SE3(), 1))
    chain.append(PrismaticJoint(256, 1, 4, 200, math.pi / 4, SE3.Trans(0, 0, 30)), safe=False)
    assert 150_000 < len(chain.creasePattern().vertices_coords) < limits.MAX_PATTERN_VERTICES


def test_a_tree_whose_sheets_would_be_too_large_is_refused(monkeypatch):
    from kinegami.fabrication.sheets import fabricate

    tree = KinematicTree(Waypoint(8, 1, SE3()))
    tree.addJoint(0, PrismaticJoint(8, 1, 4, 200, math.pi / 4, SE3.Trans(0, 0, 30)), safe=False)
    tree.addJoint(0, EndTip(8, 1, SE3.Trans(20, 0, 5) * SE3.Ry(math.pi / 2), 1), safe=False)
    monkeypatch.setattr("kinegami.pattern.catalog.MAX_PATTERN_VERTICES", 2_000)
    with pytest.raises(InvalidParameterError, match="MAX_PATTERN_VERTICES"):
        fabricate(tree, junction="connector")


# --- the take-off search ----------------------------------------------------------------------
@pytest.mark.parametrize("path", TREE_DESIGNS, ids=lambda p: p.stem)
def test_the_takeoff_search_measures_everything_for_ordinary_trees(path):
    tree = load_design(path)
    for branches in (1, 2, 3):
        per_branch, sets = takeoffs.search_budget(tree, branches)
        assert per_branch >= tree.numSides * takeoffs.TakeoffOptions().heights
        assert sets == takeoffs.EVALUATED_SETS


def test_the_takeoff_search_of_a_tree_of_many_capsules_is_bounded():
    tree = KinematicTree(Waypoint(8, 1, SE3()), maxAnglePerElbow=math.pi / 180)
    for k in range(6):
        tree.addJoint(0 if k < 3 else k, RevoluteJoint(8, 1, math.pi, SE3.Trans(3 * k - 6, 4, 9)
                                                       * SE3.Rx(2.5)), safe=False)  # fmt: skip
    per_branch, sets = takeoffs.search_budget(tree, 2)
    capsules = limits.TAKEOFF_WORK // (2 * per_branch + sets)
    assert capsules > 500  # many capsules: fewer candidates than every face at 5 heights
    assert per_branch < 8 * 5 and 1 <= sets < takeoffs.EVALUATED_SETS
    assert (2 * per_branch + sets) * capsules <= limits.TAKEOFF_WORK


def test_the_takeoff_search_of_a_tree_of_many_branching_joints_shares_one_budget(monkeypatch):
    """TAKEOFF_WORK bounds the whole tree's search, not each joint's: three take-off joints
    measure about TAKEOFF_WORK / capsules candidates in all (each attempt at least one per
    branch and one set), where a budget per joint measured three times as many."""
    tree = KinematicTree(Waypoint(4, 1, SE3()), maxAnglePerElbow=math.pi / 60)
    for parent, x, y in ((0, -6, 0), (0, 6, 0), (1, -9, 4), (1, -3, 4), (2, 3, 4), (2, 9, 4)):
        pose = SE3.Trans(x, y, 10 if parent == 0 else 22) * SE3.Rx(2.0)
        tree.addJoint(parent, RevoluteJoint(4, 1, math.pi, pose), safe=False)
    capsules = takeoffs.body_capsules(tree)
    monkeypatch.setattr(takeoffs, "TAKEOFF_WORK", 10 * capsules)  # ten whole-body tests
    measured = []
    overlap = takeoffs.takeoff_overlap

    def counted(*args, **kwargs):
        measured.append(1)
        return overlap(*args, **kwargs)

    monkeypatch.setattr(takeoffs, "takeoff_overlap", counted)
    from kinegami.fabrication.sheets import fabricate

    made = fabricate(tree, junction="takeoff")
    assert len(made.takeoffs) == 3
    assert len(measured) <= 10 + 3 * 2  # the budget, and each joint's one candidate and set


def test_a_single_branch_is_not_measured_again_as_a_set(monkeypatch):
    """A take-off joint with one branch: its set is its best candidate, whose body was measured
    already with the same placements (fuzz operations seed 502287 measured three such bodies
    twice each, 3.3 s a time): every body measured is a candidate's, and the choice is the
    one the sets' measure made."""
    tree = KinematicTree(Waypoint(4, 1, SE3()), maxAnglePerElbow=math.pi / 60)
    for parent, x, y in ((0, -6, 0), (0, 6, 0), (1, -9, 4), (1, -3, 4)):
        pose = SE3.Trans(x, y, 10 if parent == 0 else 22) * SE3.Rx(2.0)
        tree.addJoint(parent, RevoluteJoint(4, 1, math.pi, pose), safe=False)
    from kinegami.fabrication.sheets import fabricate

    combine = takeoffs._combine
    inside = []

    def counted_combine(*args, **kwargs):
        overlap = takeoffs.takeoff_overlap
        monkeypatch.setattr(takeoffs, "takeoff_overlap",
                            lambda *a, **k: (inside.append(1), overlap(*a, **k))[1])
        try:
            return combine(*args, **kwargs)
        finally:
            monkeypatch.setattr(takeoffs, "takeoff_overlap", overlap)

    monkeypatch.setattr(takeoffs, "_combine", counted_combine)
    made = fabricate(tree, junction="takeoff")
    assert inside == []
    # the take-offs the sets' measure chose before (face, height along the trunk's tube)
    assert [(t.junction.face, t.junction.y0) for t in made.takeoffs] == \
        [(1, 3.6103849214667867), (0, 9.196849167737891)]  # fmt: skip


def test_a_takeoff_candidate_is_charged_for_its_junction_extents(monkeypatch):
    """A take-off candidate costs its body's capsules and its junction's extents (the two
    tubes leaving it, each one's capsules against the other's): a tree of long one-degree-
    elbow links (fuzz operations seed 412685: 56 candidates at 0.35 s each, 0.23 s of it the
    junctions) measures fewer candidates, and their costs stay within TAKEOFF_WORK but for
    each branch's first candidate and set."""
    tree = KinematicTree(Waypoint(8, 1, SE3()), maxAnglePerElbow=math.pi / 180)
    tree.addJoint(0, RevoluteJoint(8, 1, math.pi, SE3.Trans(0, 0, 40)), safe=False)
    tree.addJoint(0, RevoluteJoint(8, 1, math.pi, SE3.Trans(-30, 25, 30) * SE3.Rx(2.5)),
                  safe=False)  # fmt: skip
    tree.addJoint(0, RevoluteJoint(8, 1, math.pi, SE3.Trans(30, -25, 30) * SE3.Rx(-2.5)),
                  safe=False)  # fmt: skip
    capsules = takeoffs.body_capsules(tree)
    trunk = max(tree.Children[0], key=lambda c: takeoffs.candidate_cost(tree, 0, c))
    costs = [takeoffs.candidate_cost(tree, trunk, c) for c in tree.Children[0] if c != trunk]
    assert all(cost > 2 * capsules for cost in costs)  # the junctions cost more than the body
    spent = []
    spend = takeoffs.TakeoffWork.spend
    monkeypatch.setattr(takeoffs.TakeoffWork, "spend",
                        lambda self, c: (spent.append(c), spend(self, c)))  # fmt: skip
    from kinegami.fabrication.sheets import fabricate

    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        try:
            fabricate(tree, junction="takeoff", trunks={0: trunk})
        except KinegamiError:
            pass  # no placement: the search measured all the same
    assert spent and min(spent) > capsules
    assert sum(spent) <= limits.TAKEOFF_WORK + sum(costs) + max(spent)


def test_a_takeoff_candidate_is_charged_the_pairs_it_measured(monkeypatch):
    """A body folded onto itself costs per near pair, not per capsule (fuzz operations seed
    409604 spent 165 s in its take-off search; now 25 s): each candidate is charged
    max(its capsule cost, pairs measured / NEAR_PAIRS_PER_TEST), and a branch stops measuring
    once the budget is spent (after its first candidate)."""
    tree = KinematicTree(Waypoint(4, 1, SE3()), maxAnglePerElbow=math.pi / 60)
    for parent, x, y in ((0, -6, 0), (0, 6, 0), (1, -9, 4), (1, -3, 4)):
        pose = SE3.Trans(x, y, 10 if parent == 0 else 22) * SE3.Rx(2.0)
        tree.addJoint(parent, RevoluteJoint(4, 1, math.pi, pose), safe=False)
    from kinegami.fabrication.sheets import fabricate

    def run(per_test: int) -> tuple[list, list]:
        monkeypatch.setattr(takeoffs, "NEAR_PAIRS_PER_TEST", per_test)
        spent, pairs = [], []
        spend, overlap = takeoffs.TakeoffWork.spend, takeoffs.takeoff_overlap

        def counted(*args, measured=None, **kwargs):
            found = overlap(*args, measured=measured, **kwargs)
            if measured is not None:
                pairs.append(sum(measured))
            return found

        monkeypatch.setattr(takeoffs.TakeoffWork, "spend",
                            lambda self, c: (spent.append(c), spend(self, c)))  # fmt: skip
        monkeypatch.setattr(takeoffs, "takeoff_overlap", counted)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")
            fabricate(tree, junction="takeoff")
        return spent, pairs

    spent, pairs = run(16)
    assert sum(pairs) > 0
    charged, counted_pairs = run(1)  # every pair a capsule test: the budget is spent sooner
    assert len(counted_pairs) < len(pairs)
    assert sum(charged) >= sum(counted_pairs)
