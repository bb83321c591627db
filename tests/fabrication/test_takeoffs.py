"""A tree made with folded take-off junctions (kinegami.fabrication.sheets.fabricate(junction=...),
kinegami.fabrication.takeoffs): the sheets, where each branch leaves its trunk, the two nets
folded in the tree's world frame, the kinematics unchanged, and what cannot be made."""

from __future__ import annotations

import math
import warnings

import numpy as np
import pytest
from numpy.testing import assert_allclose
from spatialmath import SE3

from kinegami import ClearanceWarning, EndTip, KinematicTree, RevoluteJoint, Waypoint
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.export.fold import sheet_graph
from kinegami.fabrication.sheets import fabricate
from kinegami.fabrication.takeoffs import TakeoffOptions, hole_name, takeoff_body
from kinegami.geometry.csc_centreline import csc_transported_frame
from kinegami.pattern import TubularPattern
from kinegami.pattern.cutout import CutPattern
from kinegami.pattern.folded import UVA_TO_DUBINS, unsnapped_form
from tests.tree.helpers import hand_tree, quiet_hand

#: The paper's hand's sheets (the same as with printed connectors: the trunk rule).
HAND_SHEETS = [(0, 8, 9, 10, 11), (5, 6, 7), (1, 2, 3, 4)]
#: Agreement of the two folded nets and of frames, in units of r (measured: 1e-15).
TOL = 1e-9
FIXED = {"relative": False, "safe": False, "fixedPosition": True, "fixedOrientation": True}


@pytest.fixture(scope="module")
def hand():
    return quiet_hand()


@pytest.fixture(scope="module")
def made(hand):
    return fabricate(hand, junction="takeoff")


def tee(n: int) -> KinematicTree:
    """A trunk straight up from a root waypoint, two side branches leaving it sideways."""
    tree = KinematicTree(Waypoint(n, 1, SE3()))
    top = tree.addJoint(0, RevoluteJoint(n, 1, math.pi, SE3.Trans(0, 0, 9) * SE3.Ry(-math.pi / 2)),
                        **FIXED)  # fmt: skip
    tree.addJoint(top, EndTip(n, 1, SE3.Trans(0, 0, 13), 1), **FIXED)
    side = tree.addJoint(0, RevoluteJoint(n, 1, math.pi, SE3.Trans(5, 0, 4) * SE3.Rx(math.pi / 2)),
                         **FIXED)  # fmt: skip
    tree.addJoint(side, EndTip(n, 1, SE3.Trans(9, 0, 4) * SE3.Ry(math.pi / 2), 1), **FIXED)
    tree.addJoint(0, EndTip(n, 1, SE3.Trans(-5, 1, 6) * SE3.Ry(-math.pi / 2), 1), **FIXED)
    return tree


def fish_mouth_points(graph, j):
    fm = j.fish_mouth - [0.0, j.skirt_base]
    at = [int(np.argmin(np.hypot(*(graph.vertices - p).T))) for p in fm]
    assert np.hypot(*(graph.vertices[at] - fm).T).max() <= 1e-9
    return graph.vertices_3d[at]


# --- the paper's hand ------------------------------------------------------------------------


def test_the_hand_is_three_sheets_joined_by_two_takeoffs(made):
    assert [s.joints for s in made.sheets] == HAND_SHEETS
    assert made.junctions == ()  # no printed connector
    assert [(t.name, t.child, t.joint, t.trunk, t.sheet) for t in made.takeoffs] == [
        ("A", 1, 0, 8, 0), ("B", 5, 0, 8, 0)]  # fmt: skip
    trunk, *branches = made.sheets
    assert isinstance(trunk.pattern, CutPattern) and trunk.pattern.skirt is None
    assert [h.name for h in trunk.pattern.holes] == ["A", "B"]
    assert trunk.holes == (("A", 2), ("B", 1))
    for sheet in branches:
        assert isinstance(sheet.pattern, CutPattern) and sheet.pattern.holes == ()
        takeoff = next(t for t in made.takeoffs if t.branch_sheet == sheet.index)
        assert sheet.takeoff == takeoff.name and sheet.takeoff_sheet == 0
        assert sheet.pattern.skirt is takeoff.junction
        assert sheet.tabs == len(takeoff.junction.tabs) == 4
    for sheet in made.sheets:
        assert sheet.pattern.validate().ok, sheet.pattern.validate()
    assert made.notes == ()


def test_the_labels_say_which_tabs_glue_into_which_hole(made, hand):
    labels = [s.label(hand) for s in made.sheets]
    assert labels[0] == ("sheet 0: joints 0 to 11; starts at the root; cut out hole A (sheet 2's "
                         "skirt glues in), hole B (sheet 1's skirt glues in); glue the tab along "
                         "the long edge")  # fmt: skip
    assert labels[1] == ("sheet 1: joints 5 to 7; starts at take-off B (joint 0): fold its 4 "
                         "skirt tabs in and glue them inside hole B of sheet 0; glue the tab along "
                         "the long edge")  # fmt: skip
    assert "hole A of sheet 0" in labels[2]


def test_each_branch_leaves_a_face_of_the_trunks_straight_tube(made, hand):
    """The take-off point O is on the trunk link's straight part after its twist, at the arc
    length reported; T is a apothem out along a face normal, perpendicular to the trunk; the
    hole with its margin lies in the plain tube."""
    link = hand.Links[8]
    r, a = hand.r, math.cos(math.pi / hand.numSides)
    straight_from = r * link.path.theta1 + 0.2 * link.path.tMag  # after the twist fitting
    straight_to = r * link.path.theta1 + link.path.tMag
    for t in made.takeoffs:
        e = t.junction.axial_half_extent + t.junction.margin
        assert straight_from + e - TOL <= t.arc <= straight_to - e + TOL
        at = csc_transported_frame(link.path, link.start_frame, t.arc)
        out = t.frame[:3, 3] - at[:3, 3]
        assert np.linalg.norm(out) == pytest.approx(a, abs=TOL)
        assert abs(float(out @ at[:3, 0])) <= TOL  # across the trunk
        assert_allclose(t.frame[:3, 0], out / a, atol=TOL)  # the branch leaves along it
        assert_allclose(t.frame[:3, 2], at[:3, 0], atol=TOL)  # e_a: the trunk's direction


def test_the_kinematics_are_unchanged(made, hand):
    """Every joint stays; every take-off branch's first link runs from its take-off frame to
    the child's proximal frame; all other links are the tree's."""
    for k in range(1, len(hand.Joints)):
        link = made.links[k]
        takeoff = next((t for t in made.takeoffs if t.child == k), None)
        if takeoff is None:
            assert link is hand.Links[k]
            continue
        assert link is takeoff.link
        assert_allclose(link.start_frame, takeoff.frame, atol=TOL)
        assert_allclose(link.end_frame, hand.Joints[k].proximal_dubins_frame(), atol=TOL)


def test_the_trunk_sheet_folds_onto_the_trunk_link(made, hand):
    """The trunk sheet's tube module, folded from the sheet's frame, is the trunk link's
    straight part: its proximal frame is the link's frame at the tube's start."""
    sheet = made.sheets[0]
    t = made.takeoffs[0]
    form = unsnapped_form(sheet.pattern.pattern, frame=sheet.frame)
    tube = form.modules[t.module]
    assert tube.kind == "tube"
    link = hand.Links[8]
    start = hand.r * link.path.theta1 + 0.2 * link.path.tMag
    F = csc_transported_frame(link.path, link.start_frame, start)
    G = tube.proximal  # a Dubins frame: x along the tube
    assert_allclose(G[:3, 3], F[:3, 3], atol=TOL)
    assert_allclose(G[:3, 0], F[:3, 0], atol=TOL)
    assert_allclose((tube.proximal @ UVA_TO_DUBINS)[:3, 3] + t.junction.y0 * F[:3, 0],
                    csc_transported_frame(link.path, link.start_frame, t.arc)[:3, 3],
                    atol=TOL)  # fmt: skip


def test_both_nets_folded_in_the_world_meet_along_each_hole(made):
    """The trunk's FOLD graph (its hole's vertices) and each branch's (its fish-mouth), both
    folded in the tree's world frame, give the same points."""
    trunk = sheet_graph(made.sheets[0].pattern)
    for t in made.takeoffs:
        branch = sheet_graph(made.sheets[t.branch_sheet].pattern)
        X = fish_mouth_points(branch, t.junction)
        gap = np.linalg.norm(X[:, None] - trunk.vertices_3d[None], axis=2).min(axis=1)
        assert gap.max() <= TOL
        # and the fish-mouth is where the take-off geometry puts the hole on the trunk
        tube = unsnapped_form(made.sheets[0].pattern.pattern,
                              frame=made.sheets[0].frame).modules[t.module]  # fmt: skip
        hole = t.junction.fold_trunk(t.junction.hole_unwrapped, tube.proximal @ UVA_TO_DUBINS)
        assert_allclose(X, hole, atol=TOL)


def test_the_folded_body_passes_through_itself_less_than_the_tree(made, hand):
    """The take-off links leave the root's crowd: the deepest overlap of the folded body is
    smaller than the hand's own (the palm's joint in the pointer's link)."""
    before = hand.clearance()
    after = made.overlap()
    assert not before.ok
    assert after is None or -after.clearance < -before.min_clearance
    joints, links, parents, original = takeoff_body(
        hand, [(t.trunk, t.arc, t.child, t.link) for t in made.takeoffs])
    assert all(p < k for k, p in enumerate(parents))
    assert len(joints) == len(hand.Joints) + 1  # one cut: both holes at the same height
    assert sorted(set(original)) == list(range(len(hand.Joints)))
    assert sum(link.length for link, k in zip(links, original, strict=True) if k == 8) == (
        pytest.approx(hand.Links[8].length, abs=1e-9))  # the cut pieces are the trunk's link


def test_printed_connectors_stay_the_default(hand):
    """fabricate(tree) is fabricate(tree, junction='connector'): plain sheets, same labels."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        slid = hand_tree()
        assert slid.translateJointAlongAxisOfMotion(1, -3.0)
    a, b = fabricate(slid), fabricate(slid, junction="connector")
    assert a.takeoffs == b.takeoffs == () and len(a.junctions) == 1
    for s, t in zip(a.sheets, b.sheets, strict=True):
        assert type(s.pattern) is TubularPattern
        assert s.label(slid) == t.label(slid)
        assert np.array_equal(s.pattern.vertices_coords, t.pattern.vertices_coords)
    assert a.sheets[1].label(slid) == ("sheet 1: joints 5 to 7; starts in junction 0 (at joint "
                                       "0), 4.07 r along its link; glue the tab along the long "
                                       "edge")  # fmt: skip


# --- other trees -----------------------------------------------------------------------------


@pytest.mark.parametrize("n", (4, 6, 8, 12))
def test_a_tee_is_made_clear_with_takeoffs(n):
    """Two side branches leave the trunk through faces at heights where their holes (with
    margins) are apart; the folded body does not pass through itself; the nets meet."""
    tree = tee(n)
    made = fabricate(tree, junction="takeoff")
    assert [t.child for t in made.takeoffs] == [3, 5] and made.overlap() is None
    assert made.sheets[0].pattern.validate().ok
    first, second = (t.junction for t in made.takeoffs)
    x1, x2 = first.hole_unwrapped[:, 0], second.hole_unwrapped[:, 0]
    apart_axially = (abs(made.takeoffs[0].arc - made.takeoffs[1].arc)
                     >= first.trunk_span[1] - first.y0 + second.y0 - second.trunk_span[0] - TOL)
    W = first.prism.W
    apart_around = all(x1.min() - first.margin >= x2.max() + second.margin + s
                       or x2.min() - second.margin + s >= x1.max() + first.margin
                       for s in (-W, 0.0, W))  # fmt: skip
    assert apart_axially or apart_around
    trunk = sheet_graph(made.sheets[0].pattern)
    for t in made.takeoffs:
        X = fish_mouth_points(sheet_graph(made.sheets[t.branch_sheet].pattern), t.junction)
        assert np.linalg.norm(X[:, None] - trunk.vertices_3d[None], axis=2).min(1).max() <= TOL


def test_auto_uses_a_connector_where_no_takeoff_can_be_made():
    """With tabs of r the hole's margin does not fit on either link: 'takeoff' fails naming the
    joint and why, 'auto' makes a printed connector and says so."""
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    tree.addJoint(0, EndTip(4, 1, SE3.Trans(1.5, 0, 4) * SE3.Ry(math.pi / 2), 1), **FIXED)
    tree.addJoint(0, EndTip(4, 1, SE3.Trans(-3, 0, 2) * SE3.Ry(-math.pi / 2), 1), **FIXED)
    wide = TakeoffOptions(tab_width=1.0)
    with pytest.raises(InvalidParameterError, match=r"junction at joint 0: no folded take-off "
                       r"can be made: trunk 1: the plain tube .* needs 3\.41 r"):  # fmt: skip
        fabricate(tree, junction="takeoff", takeoff=wide)
    made = fabricate(tree, junction="auto", takeoff=wide)
    assert made.takeoffs == () and len(made.junctions) == 1
    assert made.notes and made.notes[0].startswith("joint 0 has a printed connector")
    # with the default tabs the take-off fits
    assert len(fabricate(tree, junction="auto").takeoffs) == 1


def test_a_junction_can_be_chosen_per_joint(hand):
    made = fabricate(hand, junction={0: "takeoff"})
    assert len(made.takeoffs) == 2
    with pytest.raises(InvalidParameterError, match="cannot be made with printed junctions"):
        fabricate(hand, junction={0: "connector"})


# --- bad input -------------------------------------------------------------------------------


@pytest.mark.parametrize(
    "junction, error, words",
    [
        ("bogus", InvalidParameterError, r"junction must be one of 'connector', 'takeoff', "
                                         r"'auto' .*got 'bogus'"),
        (3, InvalidTypeError, r"junction must be one of .* got 3"),
        ({3: "takeoff"}, InvalidParameterError, r"junction: joint 3 does not branch .*\[0\]"),
        ({0: "glue"}, InvalidParameterError, r"junction\[0\] must be one of .* got 'glue'"),
    ],
)  # fmt: skip
def test_bad_junction_values_are_named(hand, junction, error, words):
    with pytest.raises(error, match=words):
        fabricate(hand, junction=junction)


@pytest.mark.parametrize(
    "options, error, words",
    [
        (TakeoffOptions(tab_width=0.0), InvalidParameterError, r"tab_width .*\(0, r\]"),
        (TakeoffOptions(tab_width=1.5), InvalidParameterError, r"tab_width .*1\.5"),
        (TakeoffOptions(stub_length=-1.0), InvalidParameterError, r"stub_length .*\[0, 10 r\]"),
        (TakeoffOptions(heights=0), InvalidParameterError, r"heights"),
        (TakeoffOptions(heights=51), InvalidParameterError, r"heights must be an integer in "
                                                            r"\[1, 50\], got 51"),
        ("wide", InvalidTypeError, r"takeoff must be TakeoffOptions"),
    ],
)  # fmt: skip
def test_bad_takeoff_options_are_named(hand, options, error, words):
    with pytest.raises(error, match=words):
        fabricate(hand, junction="takeoff", takeoff=options)


def test_hole_names_run_past_z():
    assert [hole_name(k) for k in (0, 1, 25, 26, 27, 51, 52)] == [
        "A", "B", "Z", "AA", "AB", "AZ", "BA"]  # fmt: skip


def test_a_branch_sheet_can_hold_the_hole_of_the_next_takeoff():
    """A branch that starts with a skirt branches again: its own sheet gets the next hole, and
    both pairs of nets meet."""
    n = 6
    tree = KinematicTree(Waypoint(n, 1, SE3()))
    up = tree.addJoint(0, RevoluteJoint(n, 1, math.pi, SE3.Trans(0, 0, 9) * SE3.Ry(-math.pi / 2)),
                       **FIXED)  # fmt: skip
    tree.addJoint(up, EndTip(n, 1, SE3.Trans(0, 0, 13), 1), **FIXED)
    side = tree.addJoint(0, RevoluteJoint(n, 1, math.pi, SE3.Trans(5, 0, 4) * SE3.Rx(math.pi / 2)),
                         **FIXED)  # fmt: skip
    far = tree.addJoint(side, RevoluteJoint(n, 1, math.pi,
                                            SE3.Trans(14, 0, 4) * SE3.Rx(math.pi / 2)), **FIXED)
    tree.addJoint(far, EndTip(n, 1, SE3.Trans(18, 0, 4) * SE3.Ry(math.pi / 2), 1), **FIXED)
    tree.addJoint(side, EndTip(n, 1, SE3.Trans(10, 5, 6) * SE3.Rx(-math.pi / 2), 1), **FIXED)
    made = fabricate(tree, junction="takeoff", trunks={0: 1})
    assert [s.joints for s in made.sheets] == [(0, 1, 2), (3, 4, 5), (6,)]
    middle = made.sheets[1]
    assert middle.takeoff == "A" and middle.holes == (("B", 2),)
    assert middle.pattern.skirt is not None and [h.name for h in middle.pattern.holes] == ["B"]
    assert "cut out hole B (sheet 2's skirt glues in)" in middle.label(tree)
    assert made.overlap() is None
    graphs = {s.index: sheet_graph(s.pattern) for s in made.sheets}
    for t in made.takeoffs:
        X = fish_mouth_points(graphs[t.branch_sheet], t.junction)
        trunk = graphs[t.sheet].vertices_3d
        assert np.linalg.norm(X[:, None] - trunk[None], axis=2).min(1).max() <= TOL


def test_a_trunk_without_a_straight_part_holds_no_hole():
    """Two links that are only arcs: neither can be the trunk of a take-off."""
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    tree.addJoint(0, EndTip(4, 1, SE3.Trans(1.5, 0, 1) * SE3.Ry(math.pi / 2), 1), **FIXED)
    tree.addJoint(0, EndTip(4, 1, SE3.Trans(-1.5, 0, 1) * SE3.Ry(-math.pi / 2), 1), **FIXED)
    assert all(link.path.tMag < 1e-9 for link in tree.Links[1:])
    with pytest.raises(InvalidParameterError, match=r"junction at joint 0: .*trunk 1: its link has "
                       r"no straight part; trunk 2: its link has no straight part"):  # fmt: skip
        fabricate(tree, junction="takeoff")


# --- the tree as folded (what the whole-tree STL, OBJ, URDF and the 3D picture show) ----------


def test_the_folded_tree_of_printed_connectors_is_the_tree(hand):
    from kinegami.fabrication.sheets import fit_junctions

    fitted, _ = fit_junctions(hand)
    fabrication = fabricate(fitted)
    assert fabrication.folded_tree() is fabrication.tree


def test_the_folded_tree_has_the_takeoff_links(made, hand):
    folded = made.folded_tree()
    tree = made.tree
    assert isinstance(folded, KinematicTree)
    # every joint of the tree, in order, at its pose; plus one zero-length waypoint per cut
    where = [next(i for i, j in enumerate(folded.Joints) if j is joint) for joint in tree.Joints]
    assert where == sorted(where)
    cuts = [i for i in range(len(folded.Joints)) if i not in where]
    assert len(cuts) == len({(t.trunk, round(t.arc, 9)) for t in made.takeoffs})
    for i in cuts:
        assert isinstance(folded.Joints[i], Waypoint) and folded.Joints[i].neutralLength == 0.0
    for takeoff in made.takeoffs:
        k = where[takeoff.child]
        link = folded.Links[k]
        assert link is takeoff.link
        # it ends at the child's proximal Dubins frame, starts at the take-off point on the
        # trunk's link, and its parent is the waypoint that cuts the trunk's link there
        assert_allclose(link.end_frame, tree.Joints[takeoff.child].proximal_dubins_frame(),
                        atol=1e-9)  # fmt: skip
        trunk = tree.Links[takeoff.trunk]
        F = csc_transported_frame(trunk.path, trunk.start_frame, takeoff.arc)
        assert_allclose(link.start_frame, takeoff.frame, atol=1e-12)
        # on the trunk's face there: an apothem from its axis, square to it
        offset = link.start_frame[:3, 3] - F[:3, 3]
        assert abs(np.linalg.norm(offset) - tree.r * math.cos(math.pi / tree.numSides)) < 1e-9
        assert abs(offset @ F[:3, 0]) < 1e-9
        assert folded.Parents[k] in cuts
    # the trunk links are cut, not changed: their pieces add up to the whole
    for trunk in {t.trunk for t in made.takeoffs}:
        pieces, node = 0.0, where[trunk]
        while True:
            pieces += folded.Links[node].path.length
            node = folded.Parents[node]
            if node not in cuts:
                break
        assert abs(pieces - tree.Links[trunk].path.length) < 1e-9
    new = sum(t.link.path.length - tree.Links[t.child].path.length for t in made.takeoffs)
    assert abs(folded.totalPathLength() - tree.totalPathLength() - new) < 1e-9


def test_a_takeoff_refusal_gives_lengths_in_r_for_a_tree_in_mm():
    """The quadruped (r = 10 mm): its front trunk's plain tube is 2.11 r, a hole needs 2.5 r
    (the message printed the millimetres followed by "r": 21.1 r and 25 r)."""
    from pathlib import Path

    from kinegami.design import load_design
    from kinegami.fabrication.sheets import fit_junctions

    design = Path(__file__).resolve().parents[2] / "examples" / "designs" / "quadruped.json"
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        tree, _ = fit_junctions(load_design(design))
    with pytest.raises(InvalidParameterError, match=r"is 2\.11 r long; .* needs 2\.5 r \(n = 6\)"):
        fabricate(tree, junction="takeoff")
