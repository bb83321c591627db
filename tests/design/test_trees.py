"""Trees in design files (version 2): parents, loading as a KinematicTree, saving, errors,
the paper's hand (tests/design/data/papers_hand.json; the gallery's hand.json with its fitting)
and joint specifications."""

from __future__ import annotations

import copy
import json
import warnings
from pathlib import Path

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st
from spatialmath import SE3

from kinegami import EndTip, KinematicChain, PlacementWarning, RevoluteJoint, Waypoint
from kinegami.design import (
    DesignError,
    DesignInfo,
    chain_from_dict,
    check_pattern,
    design_to_dict,
    dumps_design,
    joint_table,
    load_design,
    load_design_with_info,
    origin_of,
    read_design,
    save_design,
    validate_design,
)
from kinegami.design.reader import check_document
from kinegami.design.trees import TreeSpecification, construction_available
from kinegami.errors import ClearanceWarning
from kinegami.tree import KinematicTree

from . import _MIDDLE, DATA, PI, _joint, _pose, joint_parameters, located, pose_error
from . import reference_values as ref

#: The paper's hand as published, and the gallery's hand: the same with the palm slid -3 r
#: along its axis, the slide kinegami build's fitting makes so that its socket fits.
HAND = DATA / "papers_hand.json"
GALLERY_HAND = Path(__file__).resolve().parents[2] / "examples" / "designs" / "hand.json"
ALGORITHMIC_HAND = DATA / "algorithmic_hand.json"
FIXED = dict(relative=True, safe=False, fixedPosition=True, fixedOrientation=True)


def _document(path: Path) -> dict:
    return json.loads(path.read_text(encoding="utf-8"))


def _quietly(call, *args, **kwargs):
    """Call ignoring ClearanceWarnings (the paper's hand passes through itself at the palm)."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        return call(*args, **kwargs)


def _hand_document() -> dict:
    return _document(HAND)


def _small_tree(**changes) -> dict:
    """A root waypoint with two revolute joints added to it, and an end tip on the second."""
    document = {
        "format": "kinegami-design", "version": 2, "numSides": 4, "r": 1,
        "joints": [
            {"type": "Waypoint", "name": "root", "pose": []},
            {"type": "RevoluteJoint", "name": "a", "totalBendingAngle": PI, "safe": False,
             "fixedPosition": True, "fixedOrientation": True,
             "pose": [{"Trans": [3, 0, 4]}, {"Ry": PI / 2}]},
            {"type": "RevoluteJoint", "name": "b", "parent": "root", "totalBendingAngle": PI,
             "safe": False, "fixedPosition": True, "fixedOrientation": True,
             "pose": [{"Trans": [-3, 0, 4]}, {"Ry": -PI / 2}]},
            {"type": "EndTip", "name": "tip", "length": 1, "safe": False,
             "fixedPosition": True, "fixedOrientation": True, "pose": [{"Tx": 4}]},
        ],
    }  # fmt: skip
    document.update(changes)
    return document


# --- identical trees -------------------------------------------------------------------------
def assert_same_tree_bits(a, b) -> None:
    """Same class, parents, joints (types, parameters, states, pose bits) and links (bits)."""
    assert type(a) is type(b)
    assert a.Parents == b.Parents
    assert (a.numSides, a.r, a.maxAnglePerElbow) == (b.numSides, b.r, b.maxAnglePerElbow)
    assert [joint_parameters(j) for j in a.Joints] == [joint_parameters(j) for j in b.Joints]
    for ja, jb in zip(a.Joints, b.Joints, strict=True):
        assert np.array_equal(ja.pose_matrix, jb.pose_matrix)
    for la, lb in zip(a.Links, b.Links, strict=True):
        assert np.array_equal(la.start_frame, lb.start_frame)
        assert np.array_equal(la.end_frame, lb.end_frame)
        pa, pb = la.path, lb.path
        assert (pa.theta1, pa.tMag, pa.theta2) == (pb.theta1, pb.tMag, pb.theta2)


def hand_listing() -> KinematicTree:
    """The paper's hand as the Python calls that build it (every pose relative to the
    parent's, placed exactly)."""
    tree = KinematicTree(Waypoint(4, 1, SE3()))

    def revolute(parent, pose):
        return tree.addJoint(parent, RevoluteJoint(4, 1, PI, pose, numSinkLayers=1), **FIXED)

    def tip(parent, x):
        pose = SE3.Trans(x, 0, 0) * SE3.Ry(PI / 2) * SE3.Rz(PI / 2)
        return tree.addJoint(parent, EndTip(4, 1, pose, 1), **FIXED)

    palm = revolute(0, SE3.Trans(2.25, 0, 3) * SE3.Ry(-PI / 4) * SE3.Rx(PI / 4))
    thumb0 = revolute(palm, SE3.Trans(1.5, 0, 0) * SE3.Rx(PI / 2))
    tip(revolute(thumb0, SE3.Trans(4, 0, 0)), 3)
    pointer1 = revolute(0, SE3.Trans(0, 0, 8) * SE3.Ry(-PI / 2) * SE3.Rx(PI))
    tip(revolute(pointer1, SE3.Trans(4, 0, 0)), 4)
    middle0 = revolute(0, SE3.Trans(-2.25, 0, 4) * SE3.Ry(-PI / 2) * SE3.Rx(PI / 2))
    middle1 = revolute(middle0, SE3.Trans(4, 0, 0) * SE3.Rx(PI / 2))
    tip(revolute(middle1, SE3.Trans(4, 0, 0)), 4)
    return tree


# --- the paper's hand ------------------------------------------------------------------------
def test_the_hand_loads_as_a_tree_with_the_papers_numbers():
    tree, info = _quietly(load_design_with_info, HAND)
    assert type(tree) is KinematicTree
    assert info.structure == "tree" and info.units == "cm"
    assert tree.Parents == ref.HAND_PARENTS
    assert tree.Children[0] == ref.HAND_CHILDREN_OF_ROOT
    assert tree.totalPathLength() == pytest.approx(
        ref.HAND_TOTAL_LINK_LENGTH, abs=ref.HAND_TOLERANCE
    )


def test_the_hand_is_its_python_listing_bit_for_bit():
    assert_same_tree_bits(_quietly(load_design, HAND), _quietly(hand_listing))


def test_the_gallery_hand_is_the_papers_hand_as_build_fits_it():
    """One design, one verdict: the gallery's hand.json is the tree kinegami build makes of
    the paper's hand (fit_junctions slides the palm by -3 r), so build, check, the editor and
    the library judge the tree that is fabricated."""
    from kinegami.fabrication.sheets import fit_junctions, junction_problems

    paper, gallery = _quietly(load_design, HAND), _quietly(load_design, GALLERY_HAND)
    fitted, moves = _quietly(fit_junctions, paper)
    assert moves == [(1, -3.0)]
    assert pose_error(gallery, fitted) <= 1e-12
    assert gallery.Parents == fitted.Parents
    assert junction_problems(gallery) == [] and fit_junctions(gallery)[1] == []
    assert gallery.clearance().ok and not paper.clearance().ok
    assert paper.clearance().min_clearance == pytest.approx(-0.25, abs=1e-9)
    assert origin_of(gallery).names == origin_of(paper).names


def test_the_hand_keeps_its_names():
    tree = _quietly(load_design, HAND)
    names = [name for _, _, name in joint_table(tree, _hand_document())]
    assert names[:5] == ["root", "palm", "thumb0", "thumb1", "thumbEnd"]
    assert origin_of(tree).names == tuple(names)


def test_the_hand_passes_through_itself_at_the_palm():
    """As published: with requireClearance, adding the pointer finger is refused."""
    document = {**_hand_document(), "requireClearance": True}
    with pytest.raises(DesignError) as caught:
        chain_from_dict(document, "hand.json")
    assert caught.value.field == "joints[5]"
    assert "addJoint failed" in caught.value.reason and "a tree that passes" in caught.value.reason


def test_edits_and_states_of_a_tree_design_use_names_and_tree_indices():
    document = _hand_document()
    document["edits"] = [
        {"op": "setJointState", "joint": "palm", "state": -90},
        {"op": "rotateJointAboutAxisOfMotion", "joint": "middle0", "angle": 10},
    ]
    tree = _quietly(chain_from_dict, document)
    python = _quietly(hand_listing)
    assert _quietly(python.setJointState, 1, -PI / 2)
    assert _quietly(python.rotateJointAboutAxisOfMotion, 8, np.radians(10))
    assert pose_error(tree, python) <= 1e-12
    states = [0.0] * 12
    states[2] = 60
    tree = _quietly(chain_from_dict, {**_hand_document(), "states": states})
    assert tree.Joints[2].state == pytest.approx(PI / 3, abs=1e-15)
    assert tree.totalPathLength() == pytest.approx(ref.HAND_TOTAL_LINK_LENGTH, abs=1e-6)


def test_a_tree_has_a_crease_pattern_per_sheet():
    tree, info = _quietly(load_design_with_info, HAND)
    with pytest.raises(DesignError, match="one per sheet: kinegami.fabrication.sheets.fabricate"):
        check_pattern(tree, info)


def test_validate_design_and_read_design_accept_trees():
    assert validate_design(HAND) is None
    document = read_design(HAND)
    assert DesignInfo.of(document).structure == "tree"


def test_the_command_line_validates_a_tree(capsys):
    from kinegami.cli import main

    assert main(["validate", str(HAND)]) == 0
    assert "valid (12 joints, a tree;" in capsys.readouterr().out
    assert main(["validate", "--build", str(HAND)]) == 0
    out = capsys.readouterr().out
    assert "builds a tree of 12 joints, 3 sheets and 1 junction(s); 1 joint(s) slid" in out
    assert "RevoluteJoint 'pointer1', parent 0" in out


# --- parents ---------------------------------------------------------------------------------
def test_a_parent_by_name_or_by_index_is_the_same_tree():
    by_name = chain_from_dict(_small_tree())
    document = _small_tree()
    document["joints"][2]["parent"] = 0
    document["joints"][3]["parent"] = 2
    by_index = chain_from_dict(document)
    assert by_name.Parents == (-1, 0, 0, 2)
    assert_same_tree_bits(by_name, by_index)


def test_without_parents_a_version_2_design_is_a_chain():
    document = _small_tree()
    del document["joints"][2]["parent"]
    document["joints"][2]["pose"] = [{"Trans": [0, 0, 6]}, {"Ry": -PI / 2}]
    chain = chain_from_dict(document)
    assert type(chain) is KinematicChain
    document["structure"] = "tree"
    tree = chain_from_dict(document)
    assert type(tree) is KinematicTree and tree.Parents == chain.Parents


def test_parents_name_entries_not_indices_of_the_built_tree():
    """Safe placement adds waypoints; a parent is an entry of 'joints', wherever it ends up."""
    document = _small_tree()
    for entry in document["joints"][1:3]:
        for key in ("safe", "fixedPosition", "fixedOrientation"):
            entry.pop(key)
    document["joints"][3]["parent"] = 1  # the tip on joint "a"
    document["joints"][3]["safe"] = True
    for key in ("fixedPosition", "fixedOrientation"):
        document["joints"][3].pop(key)
    tree = chain_from_dict(document)
    origin = origin_of(tree)
    a, b, tip = (origin.sources.index(k) for k in (1, 2, 3))
    assert len(tree.Joints) > 4  # waypoints were added
    up = tree.Parents[tip]
    while origin.sources[up] is None:
        up = tree.Parents[up]
    assert up == a
    up = tree.Parents[b]
    while origin.sources[up] is None:
        up = tree.Parents[up]
    assert up == 0


def _error(document, file="tree.json") -> DesignError:
    with pytest.raises(DesignError) as caught:
        chain_from_dict(document, file)
    error = caught.value
    assert str(error).startswith(f"{file}: {located(error)}") and "\n" not in str(error)
    return error


def _with_parent(index: int, parent) -> dict:
    document = _small_tree()
    document["joints"][index]["parent"] = parent
    return document


def _tip_in_the_middle(*more) -> dict:
    """root, a, an EndTip "early" on a, b (on the root), the tip (on b), then ``more``."""
    document = _small_tree()
    document["joints"].insert(2, {"type": "EndTip", "name": "early", "length": 1, "pose": []})
    document["joints"].extend(more)
    return document


def _three_roots() -> dict:
    return _with_parent(2, -1)


BAD = {
    "unknown parent name": (
        _with_parent(2, "ruut"), "joints[2].parent", '"ruut"',
        ["no joint is named 'ruut'", "'root', 'a', 'b', 'tip'"],
    ),
    "parent after the joint (name)": (
        _with_parent(2, "tip"), "joints[2].parent", '"tip"',
        ["must come before the joint", "joints[3] (EndTip 'tip')", "cycles impossible"],
    ),
    "parent after the joint (index)": (
        _with_parent(2, 3), "joints[2].parent", "3",
        ["earlier entry", "joints[0] to joints[1]", "cycles impossible"],
    ),
    "own parent (name)": (_with_parent(2, "b"), "joints[2].parent", '"b"', ["its own parent"]),
    "own parent (index)": (_with_parent(2, 2), "joints[2].parent", "2", ["its own parent"]),
    "a second root": (
        _three_roots(), "joints[2].parent", "-1", ["one root, joints[0]", "cannot be a root"]
    ),
    "null parent": (_with_parent(2, None), "joints[2].parent", "null", ["one root"]),
    "parent true": (_with_parent(2, True), "joints[2].parent", "true", ["an integer"]),
    "empty parent name": (_with_parent(2, ""), "joints[2].parent", '""', ["must not be empty"]),
    "parent of the root": (
        _with_parent(0, 1), "joints[0].parent", None, ["root joint (joints[0]) cannot have"]
    ),
    "an EndTip as parent": (
        {**_small_tree(), "joints": [*_small_tree()["joints"], {
            "type": "Waypoint", "parent": 3, "pose": []}]},
        "joints[4].parent", "3", ["an EndTip cannot be a parent", "joints[3] (EndTip 'tip')"],
    ),
    "an EndTip named as parent": (
        _tip_in_the_middle({"type": "Waypoint", "parent": "early", "pose": []}),
        "joints[5].parent", '"early"', ["an EndTip cannot be a parent", "joints[2] (EndTip"],
    ),
    "an EndTip as default parent": (
        {**_tip_in_the_middle(), "joints": [
            *_tip_in_the_middle()["joints"][:3], {"type": "Waypoint", "pose": []},
            {"type": "Waypoint", "parent": 0, "pose": []}]},
        "joints[3]", None,
        ["follows the previous entry, joints[2] (EndTip 'early')", 'give it a "parent"'],
    ),
    "a StartTip below the root": (
        {**_small_tree(), "joints": [*_small_tree()["joints"][:3],
                                     {"type": "StartTip", "length": 1, "parent": 0}]},
        "joints[3].type", '"StartTip"', ["only be the root"],
    ),
    "branches in a chain": (
        _small_tree(structure="chain"), "joints[2].parent", '"root"',
        ['a chain ("structure": "chain") has no branches', "joints[1]"],
    ),
    "unknown structure": (
        _small_tree(structure="forest"), "structure", '"forest"', ["'chain', 'tree'"]
    ),
    "a DH tree": (
        {"format": "kinegami-design", "version": 2, "numSides": 4, "r": 1,
         "structure": "tree", "dh": {"rows": [[0, 0, 8, 0]]}},
        "structure", '"tree"', ["a DH table gives a chain"],
    ),
    "placement with a DH table": (
        {"format": "kinegami-design", "version": 2, "numSides": 4, "r": 1,
         "placement": {"method": "wafr2024"}, "dh": {"rows": [[0, 0, 8, 0]]}},
        "joints", None, ["missing required field 'joints'"],
    ),
    "unknown placement method": (
        _small_tree(placement={"method": "wafr2025"}), "placement.method", '"wafr2025"',
        ["unknown placement method", "wafr2024"],
    ),
    "unknown placement key": (
        _small_tree(placement={"method": "wafr2024", "growth_direction": [0, 0, 1]}),
        "placement.growth_direction", None, ["did you mean 'growthDirection'"],
    ),
    "zero growth direction": (
        _small_tree(placement={"method": "wafr2024", "growthDirection": [0, 0, 0]}),
        "placement.growthDirection", "[0, 0, 0]", ["non-zero"],
    ),
    "a specification with safe": (
        _small_tree(placement={"method": "wafr2024"}), "joints[1].safe", "false",
        ["a joint specification", "has no 'safe'"],
    ),
    "a specification with maxAnglePerElbow": (
        _small_tree(placement={"method": "wafr2024"}, maxAnglePerElbow=1), "maxAnglePerElbow",
        "1", ["pi/10", "leave it out"],
    ),
    "an unknown construction option": (
        _small_tree(placement={"method": "wafr2024", "extraroll": True}),
        "placement.extraroll", None, ["did you mean 'extraRoll'"],
    ),
    "extra roll not a flag": (
        _small_tree(placement={"method": "wafr2024", "extraRoll": 1}),
        "placement.extraRoll", "1", ["true or false"],
    ),
    "a specification that is a chain": (
        _small_tree(placement={"method": "wafr2024"}, structure="chain"), "structure",
        '"chain"', ['"structure" must be "tree"'],
    ),
}  # fmt: skip


@pytest.mark.parametrize("case", sorted(BAD))
def test_bad_trees_are_reported_with_path_value_and_what_is_allowed(case):
    document, field, shown, words = BAD[case]
    error = _error(copy.deepcopy(document))
    assert error.field == field, str(error)
    if shown is not None:
        assert str(error).endswith(f"(got {shown})"), str(error)
    for word in words:
        assert word in error.reason, (word, str(error))


def test_a_design_with_a_bad_parent_validates_like_it_loads(tmp_path):
    path = tmp_path / "tree.json"
    path.write_text(json.dumps(_with_parent(2, "nobody")), encoding="utf-8")
    with pytest.raises(DesignError, match=r"joints\[2\]\.parent: no joint is named 'nobody'"):
        validate_design(path)


def test_the_caps_hold_for_trees():
    """A tree counts its joints like a chain: at most MAX_JOINTS entries."""
    from kinegami.design import limits

    document = _small_tree()
    document["joints"] = [document["joints"][0]] + [
        {"type": "Waypoint", "parent": 0, "pose": [{"Tz": 1 + k}], "safe": False}
        for k in range(limits.MAX_JOINTS)
    ]
    error = _error(document)
    assert error.field == "joints" and "MAX_JOINTS" in error.reason


# --- saving ----------------------------------------------------------------------------------
def test_a_saved_tree_is_version_2_with_parents(tmp_path):
    tree = _quietly(load_design, HAND)
    path = save_design(tree, tmp_path / "hand.json", name="hand", units="cm")
    document = _document(path)
    assert document["version"] == 2 and document["structure"] == "tree"
    parents = [entry.get("parent") for entry in document["joints"]]
    assert parents[:6] == [None, "root", "palm", "thumb0", "thumb1", "root"]
    again = _quietly(load_design, path)
    assert_same_tree_bits(again, tree)
    assert design_to_dict(again, name="hand", units="cm") == document


def test_a_tree_without_names_is_saved_with_parent_indices():
    tree = _quietly(hand_listing)
    document = design_to_dict(tree)
    assert [entry.get("parent") for entry in document["joints"]] == [None, *ref.HAND_PARENTS[1:]]
    assert_same_tree_bits(_quietly(chain_from_dict, document), tree)


def test_a_tree_that_is_a_path_stays_a_tree():
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    assert tree.addJoint(0, RevoluteJoint(4, 1, PI, SE3.Trans(0, 0, 5)), safe=False)
    document = design_to_dict(tree)
    assert document["structure"] == "tree"
    assert type(chain_from_dict(document)) is KinematicTree


def test_a_tree_whose_root_is_an_end_tip_is_saved_with_a_deleting_edit():
    tree = KinematicTree(Waypoint(4, 1, SE3()))
    assert tree.addJoint(0, EndTip(4, 1, SE3.Trans(0, 0, 5), 1), safe=False)
    assert tree.delete(0)
    document = design_to_dict(tree)
    assert [e["type"] for e in document["joints"]] == ["Waypoint", "EndTip"]
    assert document["joints"][1]["parent"] == 0
    assert document["edits"] == [{"op": "delete", "joint": 0}]
    again = chain_from_dict(document)
    assert type(again) is KinematicTree and again.Parents == (-1,)
    assert np.array_equal(again.Joints[0].pose_matrix, tree.Joints[0].pose_matrix)


def test_a_tree_with_states_saves_them_and_its_state_zero_poses():
    tree = _quietly(hand_listing)
    assert _quietly(tree.setJointState, 1, -PI / 2)
    document = _quietly(design_to_dict, tree)
    assert document["states"][1] == -PI / 2
    rest = _quietly(hand_listing)
    for entry, joint in zip(document["joints"], rest.Joints, strict=True):
        np.testing.assert_allclose(entry["pose"], joint.pose_matrix, rtol=0, atol=1e-12)
    again = _quietly(chain_from_dict, document)
    assert pose_error(again, tree) <= 1e-12 and again.Parents == tree.Parents


# --- random trees ----------------------------------------------------------------------------
def _add(tree, *args, **kwargs):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", PlacementWarning)
        warnings.simplefilter("ignore", ClearanceWarning)
        return tree.addJoint(*args, **kwargs)


@st.composite
def random_trees(draw, max_joints: int = 5) -> KinematicTree:
    """Small trees: random joints added to random earlier joints in every placement mode."""
    n = draw(st.sampled_from([4, 6]))
    r = draw(st.floats(0.5, 3.0))
    tree = KinematicTree(
        _joint(draw, draw(st.sampled_from(["StartTip", *_MIDDLE])), n, r, _pose(draw, r)),
        maxAnglePerElbow=draw(st.sampled_from([PI / 2, PI / 3, PI])),
    )
    for _ in range(draw(st.integers(1, max_joints))):
        parents = [i for i, j in enumerate(tree.Joints) if type(j) is not EndTip]
        parent = draw(st.sampled_from(parents))
        kind = draw(st.sampled_from([*_MIDDLE, "EndTip"]))
        safe = draw(st.booleans())
        fixed = (False, False) if safe else (draw(st.booleans()), draw(st.booleans()))
        _add(tree, parent, _joint(draw, kind, n, r, _pose(draw, r)),
             relative=draw(st.booleans()), safe=safe, fixedPosition=fixed[0],
             fixedOrientation=fixed[1])  # fmt: skip
    return tree


TREES = settings(
    max_examples=25, deadline=None, suppress_health_check=[HealthCheck.too_slow]
)


@TREES
@given(random_trees())
def test_tree_to_file_to_tree_is_bit_for_bit(tree):
    document = json.loads(dumps_design(_quietly(design_to_dict, tree)))
    assert document["version"] == 2
    again = _quietly(chain_from_dict, document)
    assert_same_tree_bits(again, tree)
    assert design_to_dict(again) == document


@TREES
@given(random_trees(), st.data())
def test_edited_trees_with_states_round_trip(tree, data):
    for _ in range(data.draw(st.integers(0, 2))):
        index = data.draw(st.integers(0, len(tree.Joints) - 1))
        with warnings.catch_warnings():
            warnings.simplefilter("ignore", PlacementWarning)
            warnings.simplefilter("ignore", ClearanceWarning)
            tree.translateJointAlongAxisOfMotion(index, data.draw(st.floats(-2, 2)) * tree.r)
    states = []
    for joint in tree.Joints:
        lo, hi = joint.stateRange()
        states.append(lo + data.draw(st.sampled_from([0.5, 0.25, 0.9])) * (hi - lo))
    assert _quietly(tree.setJointStates, states)
    document = json.loads(dumps_design(_quietly(design_to_dict, tree)))
    again = _quietly(chain_from_dict, document)
    assert type(again) is KinematicTree and again.Parents == tree.Parents
    assert [joint_parameters(j) for j in again.Joints] == [joint_parameters(j) for j in tree.Joints]
    assert pose_error(again, tree) <= 1e-12
    twice = _quietly(chain_from_dict, _quietly(design_to_dict, again))
    assert twice.Parents == tree.Parents and pose_error(twice, tree) <= 1e-12


# --- joint specifications --------------------------------------------------------------------
def test_a_joint_specification_reads_into_a_plain_description():
    document = _document(ALGORITHMIC_HAND)
    plan = check_document(document, ALGORITHMIC_HAND)
    spec = plan.specification
    assert isinstance(spec, TreeSpecification) and plan.tree
    assert spec.method == "wafr2024"
    assert spec.growth_direction == (0.5, 0.7071067811865475, 0.5)
    assert (spec.extra_roll, spec.sibling_azimuth) == (None, None)
    assert spec.names[:3] == ("root", "palm", "thumb0")
    assert spec.parents == (-1, 0, 1, 2, 3, 0, 5, 6, 0, 8, 9, 10)
    # relative poses are composed with the parent's specified pose: the axis lines are global
    palm, thumb0 = spec.joints[1], spec.joints[2]
    np.testing.assert_allclose(palm.pose_matrix[:3, 3], [4, 0, 3], atol=1e-15)
    np.testing.assert_allclose(thumb0.pose_matrix, palm.pose_matrix @ np.asarray(
        SE3.Trans(1.836734693877551, 0, 0) * SE3.Rx(PI / 2)), atol=1e-15)  # fmt: skip
    assert [type(j).__name__ for j in spec.joints].count("EndTip") == 3
    assert DesignInfo.of(document).structure == "tree"


def test_a_specification_without_growth_direction_leaves_it_to_the_construction():
    document = _document(ALGORITHMIC_HAND)
    del document["placement"]["growthDirection"]
    document["placement"].update(extraRoll=True, siblingAzimuth=90)
    spec = check_document(document).specification
    assert spec.growth_direction is None
    assert spec.extra_roll is True and spec.sibling_azimuth == PI / 2


def test_a_specification_without_the_construction_is_a_clear_error(monkeypatch):
    """Until kinegami.tree.construction exists (or if it fails to import), loading a joint
    specification says so, naming the field."""
    import sys

    import kinegami.tree

    monkeypatch.setitem(sys.modules, "kinegami.tree.construction", None)
    monkeypatch.delattr(kinegami.tree, "construction", raising=False)
    error = _error(_document(ALGORITHMIC_HAND))
    assert error.field == "placement"
    assert "tree construction" in error.reason and "not available" in error.reason


needs_construction = pytest.mark.skipif(
    not construction_available(), reason="kinegami.tree.construction is not available"
)


@needs_construction
@pytest.mark.parametrize("extra_roll", [False, True])
def test_the_algorithmic_hand_is_built_by_the_published_construction(extra_roll):
    document = _document(ALGORITHMIC_HAND)
    document["placement"].update(extraRoll=extra_roll, siblingAzimuth=0)
    tree = _quietly(chain_from_dict, document)
    assert type(tree) is KinematicTree
    assert tree.Parents == ref.ALGORITHMIC_HAND_PARENTS
    assert tree.totalPathLength() == pytest.approx(
        ref.ALGORITHMIC_HAND_TOTAL_LINK_LENGTH[extra_roll], abs=ref.ALGORITHMIC_HAND_TOLERANCE
    )
    origin = origin_of(tree)
    assert tuple(origin.sources.index(k) for k in range(12)) == ref.ALGORITHMIC_HAND_NODES


@needs_construction
def test_a_joint_specification_loads_as_the_constructed_tree():
    """The file gives the tree of from_specification on the same joints, bit for bit; names
    and edits find the specified joints in it."""
    from kinegami.tree import JointSpecificationTree, from_specification

    tree = _quietly(load_design, ALGORITHMIC_HAND)
    spec = check_document(_document(ALGORITHMIC_HAND)).specification
    python = JointSpecificationTree(spec.joints[0])
    for joint, parent in zip(spec.joints[1:], spec.parents[1:], strict=True):
        python.addJoint(parent, joint, relative=False)
    assert_same_tree_bits(
        tree, _quietly(from_specification, python, growth_direction=spec.growth_direction)
    )
    origin = origin_of(tree)
    nodes = tuple(origin.sources.index(k) for k in range(12))
    assert origin.names[nodes[5]] == "pointer1"
    document = _document(ALGORITHMIC_HAND)
    document["edits"] = [{"op": "setJointState", "joint": "pointer1", "state": 30}]
    edited = _quietly(chain_from_dict, document)
    assert edited.Joints[nodes[5]].state == pytest.approx(PI / 6, abs=1e-15)
    # the constructed tree saves as an ordinary tree design and loads back the same
    assert_same_tree_bits(_quietly(chain_from_dict, design_to_dict(tree)), tree)
