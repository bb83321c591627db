"""The example gallery (docs/gallery.md): design files, the scripts that build the same chains,
and the numbers the gallery states about them.

* every ``examples/designs/*.json`` loads without a PlacementWarning and gives a crease pattern
  n * b wide;
* every design equals the chain its script's ``build()`` returns (types, poses, parameters);
  Example 1's equals the paper's listing (tests/conftest.py builders);
* the geometric claims of the gallery (axes that meet, are parallel or coincide; reference
  numbers of spec chain.md 11.5 and 11.6 at r = 10 mm; the PUMA on its DH axes, shortened);
* every script runs as a subprocess into a temporary folder and writes its three files; the
  scripts run concurrently (one process each, started together) so the whole file stays fast;
* the trees (TREE_ENTRIES): each design equals its script's tree; the algorithmic hand is the
  joint specification of the reference (spec trees.md 3) placed by the construction; the
  quadruped's and the gripper's geometry; the paper's hand's grasps (spec trees.md 4, numbers
  from tests/data/hand_reference.json); each tree's script writes its 3D view and every sheet
  (pattern picture and DXF at true size); the gallery page and the README show every entry.
"""

from __future__ import annotations

import copy
import importlib.util
import json
import math
import os
import re
import subprocess
import sys
import warnings
from pathlib import Path

import ezdxf
import numpy as np
import pytest
from ezdxf import bbox

from kinegami import *
from kinegami.chain.bodies import link_polyline
from kinegami.chain.dh import dh_joint_frames, dh_tool_frame
from kinegami.design import chain_from_dict, load_design, load_design_with_info

ROOT = Path(__file__).resolve().parents[1]
EXAMPLES = ROOT / "examples"


def source_env(**changes) -> dict[str, str]:
    """A script's environment: kinegami imported from this checkout, the Agg backend."""
    env = dict(os.environ, MPLBACKEND="Agg", **changes)
    env["PYTHONPATH"] = os.pathsep.join([str(ROOT), *filter(None, [os.environ.get("PYTHONPATH")])])
    return env


DESIGNS = EXAMPLES / "designs"

#: gallery entry -> its script (None: Example 1, whose script is the paper's listing).
ENTRIES = {
    "example1": None,
    "cylindrical_joint": "cylindrical_joint.py",
    "planar_joint": "planar_joint.py",
    "spherical_joint": "spherical_joint.py",
    "puma": "puma.py",
    "revolute_spiral": "revolute_spiral.py",
    "prismatic_spiral": "prismatic_spiral.py",
    "spherical_limb": "spherical_limb.py",
    "spherical_series": "spherical_series.py",
    "doubling_back": "doubling_back.py",
    "pick_and_place": "pick_and_place.py",
}
SCRIPTS = sorted(name for name, script in ENTRIES.items() if script)
#: the gallery's trees (also tested in tests/tree, tests/design/test_trees.py and
#: tests/cli/test_gallery_trees.py): entry -> joints, leaves, total link length (design units).
#: Each has a script examples/<entry>.py.
TREE_ENTRIES = {
    "hand": (12, 3, 33.802712),  # as fabricated: the palm slid 3 cm (docs/gallery.md)
    "algorithmic_hand": (16, 3, 754.588015),
    "quadruped": (18, 4, 774.985756),
    "gripper": (10, 2, 285.281991),
}
TREE_SCRIPTS = sorted(TREE_ENTRIES)
#: The reference data (tests/data/<name>_reference.json): the joint specification of the
#: algorithmic hand, and the paper's hand with its grasps.
REFERENCE_DATA = ROOT / "tests" / "data"
#: trees.md 3.2: the algorithmic hand by the published construction (routes side by side) and
#: without the extra roll, in r.
ALGORITHMIC_HAND_PUBLISHED_TOTAL = 755.9963
ALGORITHMIC_HAND_TOLERANCE = 1e-3
#: The table of docs/gallery.md for trees: joints, leaves (= sheets), printed junctions, total
#: link length and the clearance at the design's states (None: it passes through itself), as
#: printed there (design units, 2 decimals).
TREE_TABLE = {
    "hand": (12, 3, 1, 33.80, 0.00),
    "algorithmic_hand": (16, 3, 1, 754.59, 0.00),
    "quadruped": (18, 4, 2, 774.99, 0.05),
    "gripper": (10, 2, 1, 285.28, 0.17),
}
#: The quadruped: the hip yaw joints (mm) and where the feet's tips end at the standing states.
QUADRUPED_HIPS = [(-45, -60, 0), (45, -60, 0), (-45, 60, 0), (45, 60, 0)]
QUADRUPED_FOOT_END = (161.806359, 114.467700, -53.090951)  # |x|, |y|, z of every foot's far end
#: The gripper: its fingertips (centres, mm) at the design's states, mirror images in x = 0.
GRIPPER_TIP = (27.035552, 0.0, 232.70705)

#: spec chain.md 11.5 and 11.6 (r = 1), and the PUMA 560 table of examples/puma.py.
SCALE = 10.0  # the gallery's r (mm) for the chain.md examples
CYLINDRICAL_PRISMATIC_ORIGIN = (0.0, 0.0, 7.125651)
CYLINDRICAL_TOTAL_WITHOUT_TIP = 7.287597
PLANAR_TOTAL = 4.535898
PLANAR_STRAIGHT_LINK = 2.267949
SPIRAL_ORIGINS = [
    (0.0, 0.0, 0.0),
    (5.377937, 0.0, 5.377937),
    (13.775869, 0.0, 5.377937),
    (20.665221, 0.0, -1.511414),
    (20.665221, 0.0, -13.240251),
]
SPIRAL_Z = [(0, 0, 1), (0.707107, 0, 0.707107), (1, 0, 0), (0.707107, 0, -0.707107), (0, 0, -1)]
SPIRAL_TOTAL = 28.196046
PI = math.pi
PUMA_560 = [
    (PI / 2, -PI / 2, 0, 0),
    (0, 0, 431.8, 149.09),
    (PI / 2, PI / 2, -20.32, 0),
    (0, -PI / 2, 0, 433.07),
    (0, PI / 2, 0, 0),
    (0, 0, 0, 56.25),
]
PUMA_COMPACT_LENGTH = 1714.666427  # from_dh(PUMA_560, 6, 25) before the slides (mm)
PUMA_SHORTENED_LENGTH = 1367.768999  # clearance-aware shortening (was 1367.768238)
LIMB_LENGTH = 143.839746  # the straight tube of the spherical limb (mm)

#: The table of docs/gallery.md: joints, structural joints, total path length, sheet w x h
#: (pattern width plus one side for the glue tab, pattern height), rounded as printed there.
GALLERY_TABLE = {
    "example1": (7, 2, 22.20, 7.07, 52.77),
    "cylindrical_joint": (4, 2, 72.88, 70, 302),
    "planar_joint": (3, 3, 45.36, 70, 119),
    "spherical_joint": (3, 3, 108.33, 70, 236),
    "puma": (7, 6, 1367.77, 175, 2435),
    "revolute_spiral": (7, 7, 648.26, 70, 1057),
    "prismatic_spiral": (5, 5, 281.96, 70, 1182),
    "spherical_limb": (5, 3, 276.01, 70, 438),
    "doubling_back": (8, 6, 304.45, 70, 823),
    "spherical_series": (11, 9, 475.52, 70, 985),
    "pick_and_place": (5, 4, 91.89, 70, 228),
}


def test_every_design_is_a_gallery_entry():
    assert sorted(p.stem for p in DESIGNS.glob("*.json")) == sorted([*ENTRIES, *TREE_ENTRIES])
    for script in SCRIPTS:
        assert (EXAMPLES / f"{script}.py").is_file()


@pytest.mark.parametrize("name", sorted(TREE_ENTRIES))
def test_tree_entries(name):
    from kinegami import ClearanceWarning, KinematicTree

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)  # the paper's hand: one near contact
        tree = load_design(DESIGNS / f"{name}.json")
    joints, leaves, length = TREE_ENTRIES[name]
    assert isinstance(tree, KinematicTree)
    assert len(tree.Joints) == joints
    assert sum(1 for c in tree.Children if not c) == leaves
    assert tree.totalPathLength() == pytest.approx(length, abs=1e-6)


# --- loading ----------------------------------------------------------------------------------
def load_strict(name: str) -> KinematicChain:
    """The chain of examples/designs/<name>.json; any warning (PlacementWarning or other) fails."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return load_design(DESIGNS / f"{name}.json")


@pytest.fixture(scope="module")
def designs() -> dict[str, KinematicChain]:
    return {name: load_strict(name) for name in ENTRIES}


@pytest.mark.parametrize("name", sorted(ENTRIES))
def test_design_builds_chain_and_pattern(name, designs):
    chain = designs[name]
    _, info = load_design_with_info(DESIGNS / f"{name}.json")
    assert info.name  # every entry has a display name
    pattern = chain.creasePattern()
    side = 2.0 * chain.r * math.sin(math.pi / chain.numSides)
    assert pattern.width == pytest.approx(chain.numSides * side, rel=1e-9)
    assert pattern.height > chain.totalPathLength() > 0.0
    for link in chain.Links[1:]:  # every link is a CSC path with turns below pi
        assert 0.0 <= link.path.theta1 < math.pi and 0.0 <= link.path.theta2 < math.pi


@pytest.mark.parametrize("name", sorted(ENTRIES))
def test_gallery_table(name, designs):
    joints, structural_joints, length, width, height = GALLERY_TABLE[name]
    chain = designs[name]
    pattern = chain.creasePattern()
    decimals = 2 if name == "example1" else 0
    assert len(chain.Joints) == joints
    assert len(structural(chain)) == structural_joints
    assert round(chain.totalPathLength(), 2) == length
    assert round(pattern.width * (1 + 1 / chain.numSides), decimals) == width
    assert round(pattern.height, decimals) == height


# --- each design is its script's chain ---------------------------------------------------------
@pytest.fixture(scope="module")
def scripts():
    """``scripts(name)``: the module examples/<name>.py, imported (its ``build`` not run)."""
    sys.path.insert(0, str(EXAMPLES))  # the scripts import examples/_common.py
    loaded = {}

    def load(name):
        if name not in loaded:
            spec = importlib.util.spec_from_file_location(
                f"gallery_{name}", EXAMPLES / f"{name}.py"
            )
            module = importlib.util.module_from_spec(spec)
            spec.loader.exec_module(module)
            loaded[name] = module
        return loaded[name]

    yield load
    sys.path.remove(str(EXAMPLES))


def assert_same_chain(actual: KinematicChain, expected: KinematicChain) -> None:
    assert (actual.numSides, actual.r) == (expected.numSides, expected.r)
    assert actual.maxAnglePerElbow == expected.maxAnglePerElbow
    assert [type(j).__name__ for j in actual.Joints] == [type(j).__name__ for j in expected.Joints]
    for k, (a, b) in enumerate(zip(actual.Joints, expected.Joints, strict=True)):
        np.testing.assert_allclose(
            a.pose_matrix, b.pose_matrix, rtol=0, atol=1e-9, err_msg=f"joint {k}"
        )
        assert a.state == b.state
        assert a.neutralLength == pytest.approx(b.neutralLength, rel=1e-12)
        assert a.stateRange() == pytest.approx(b.stateRange(), rel=1e-12)
    assert actual.totalPathLength() == pytest.approx(expected.totalPathLength(), rel=1e-12)


@pytest.mark.parametrize("name", SCRIPTS)
def test_design_equals_script(name, designs, scripts):
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)
        built = scripts(name).build()
    assert_same_chain(designs[name], built)


def test_example1_design_is_the_papers_example_1b(designs, example_1b):
    assert_same_chain(designs["example1"], example_1b)
    _, info = load_design_with_info(DESIGNS / "example1.json")
    assert info.units == "cm"  # r = 1 as in the paper; 1 cm makes a sheet one can fold


# --- what the gallery says about each chain ----------------------------------------------------
def axis_line(joint) -> tuple[np.ndarray, np.ndarray]:
    T = joint.pose_matrix
    return T[:3, 3], T[:3, 2]


def distance_to_line(point, joint) -> float:
    p, z = axis_line(joint)
    return float(np.linalg.norm(np.cross(np.asarray(point, float) - p, z)))


def structural(chain) -> list:
    return [j for j in chain.Joints if isinstance(j, RevoluteJoint | PrismaticJoint)]


def test_cylindrical_joint_shares_one_axis(designs):
    chain = designs["cylindrical_joint"]
    revolute, prismatic = structural(chain)
    assert isinstance(revolute, RevoluteJoint) and isinstance(prismatic, PrismaticJoint)
    np.testing.assert_allclose(axis_line(prismatic)[1], axis_line(revolute)[1], atol=1e-12)
    assert distance_to_line(axis_line(prismatic)[0], revolute) < 1e-9
    np.testing.assert_allclose(
        prismatic.pose_matrix[:3, 3], np.multiply(CYLINDRICAL_PRISMATIC_ORIGIN, SCALE), atol=1e-5
    )
    assert chain.totalPathLength() == pytest.approx(CYLINDRICAL_TOTAL_WITHOUT_TIP * SCALE, abs=1e-5)


def test_planar_joint_axes_parallel_and_joints_in_one_plane(designs):
    chain = designs["planar_joint"]
    joints = chain.Joints
    assert len(joints) == 3 and all(isinstance(j, RevoluteJoint) for j in joints)
    for joint, x in zip(joints, (0, 40, 80), strict=True):
        np.testing.assert_allclose(axis_line(joint)[1], (0, 0, 1), atol=1e-12)
        np.testing.assert_allclose(axis_line(joint)[0], (x, 0, 0), atol=1e-9)
    for link in chain.Links[1:]:
        assert link.path.theta1 == pytest.approx(0, abs=1e-9)
        assert link.path.theta2 == pytest.approx(0, abs=1e-9)
        assert link.path.length == pytest.approx(PLANAR_STRAIGHT_LINK * SCALE, abs=1e-5)
    assert chain.totalPathLength() == pytest.approx(PLANAR_TOTAL * SCALE, abs=1e-5)


def test_planar_script_follows_chain_md_11_5(scripts, capsys):
    scripts("planar_joint").build(verbose=True)
    out = capsys.readouterr().out
    assert "safe placement 196.38888" in out  # chain.md 11.5: 19.638888, 16.189197, 4.535898
    assert "waypoints deleted 161.89197" in out
    assert "joints in one plane 45.35898" in out


def assert_spherical(joints, centre) -> None:
    """Three revolute joints whose axes are orthogonal and pass through ``centre``."""
    assert len(joints) == 3 and all(isinstance(j, RevoluteJoint) for j in joints)
    for joint in joints:
        assert distance_to_line(centre, joint) < 1e-9
    z = np.array([axis_line(j)[1] for j in joints])
    np.testing.assert_allclose(z @ z.T, np.eye(3), atol=1e-12)


def test_spherical_joint_axes_meet_at_the_origin(designs):
    assert_spherical(list(designs["spherical_joint"].Joints), (0, 0, 0))


def test_spherical_limb(designs):
    chain = designs["spherical_limb"]
    assert isinstance(chain.Joints[0], StartTip) and isinstance(chain.Joints[-1], EndTip)
    assert_spherical(list(chain.Joints[1:4]), (0, 0, 0))
    limb = chain.Links[-1].path  # a straight tube from the last joint to the end tip
    assert limb.theta1 == pytest.approx(0, abs=1e-9) and limb.theta2 == pytest.approx(0, abs=1e-9)
    assert limb.tMag == pytest.approx(LIMB_LENGTH, abs=1e-5)


def test_spherical_series(designs):
    chain = designs["spherical_series"]
    joints = structural(chain)
    assert len(joints) == 9
    for k in range(3):
        assert_spherical(joints[3 * k : 3 * k + 3], (0, 80 * k, 40 * k))


def test_doubling_back(designs):
    chain = designs["doubling_back"]
    heights = [j.pose_matrix[2, 3] for j in chain.Joints]
    assert heights == pytest.approx([0, 0, 0, 0, 60, 60, 60, 60], abs=1e-9)
    x = [j.pose_matrix[0, 3] for j in chain.Joints]
    assert x[:4] == sorted(x[:4]) and x[4:] == sorted(x[4:], reverse=True)  # out, then back
    uturn = chain.Links[4].path
    assert uturn.theta1 == pytest.approx(math.pi / 2) and uturn.theta2 == pytest.approx(math.pi / 2)
    # the end tip comes back above the start tip, pointing the other way
    np.testing.assert_allclose(chain.Joints[-1].pose_matrix[:3, 3], (0, 0, 60), atol=1e-9)
    assert chain.Joints[-1].pose_matrix[:3, 2] @ chain.Joints[0].pose_matrix[:3, 2] == -1


def test_prismatic_spiral_is_chain_md_11_6(designs):
    chain = designs["prismatic_spiral"]
    for joint, origin, z in zip(chain.Joints, SPIRAL_ORIGINS, SPIRAL_Z, strict=True):
        assert isinstance(joint, PrismaticJoint)
        np.testing.assert_allclose(joint.pose_matrix[:3, 3], np.multiply(origin, SCALE), atol=1e-5)
        np.testing.assert_allclose(joint.pose_matrix[:3, 2], z, atol=1e-6)
    assert chain.totalPathLength() == pytest.approx(SPIRAL_TOTAL * SCALE, abs=1e-5)


def test_revolute_spiral_axes_turn_45_degrees(designs):
    chain = designs["revolute_spiral"]
    joints = chain.Joints
    assert len(joints) == 7 and all(isinstance(j, RevoluteJoint) for j in joints)
    for k, joint in enumerate(joints):
        angle = k * math.pi / 4  # about y, from z
        np.testing.assert_allclose(
            joint.pose_matrix[:3, 2], (math.sin(angle), 0, math.cos(angle)), atol=1e-12
        )
    # compact placement: each joint at least 4r beyond the ball of the chain before it
    r = chain.r
    partial = KinematicChain(RevoluteJoint(6, r, math.pi, SE3()))
    for joint in joints[1:]:
        ball = partial.boundingBall
        gap = np.linalg.norm(joint.pose_matrix[:3, 3] - ball.c)
        assert gap >= ball.r + 4 * r + joint.boundingBall().r - 1e-9 * r
        partial.append(RevoluteJoint(6, r, math.pi, SE3.Ry(math.pi / 4)), safe=False)
    assert_same_chain(partial, chain)


def test_pick_and_place_reaches_its_task(designs):
    """The arm designed for examples/tasks/pick_and_place.json, as its design file keeps it
    (with the task): every target reached exactly, in range and clear, checked by a fresh
    solve and by the design's own setJointStates and clearance, above the table (the keep-out
    box), and each move to the next target certified clear."""
    from kinegami.clearance.keep_out import keep_out_violation
    from kinegami.clearance.paths import check_path
    from kinegami.design.task import read_task, task_from_dict
    from kinegami.reach import solve

    arm = designs["pick_and_place"]
    _, info = load_design_with_info(DESIGNS / "pick_and_place.json")
    task = task_from_dict(info.task, DESIGNS / "pick_and_place.json", where=("task",))
    assert task.document == read_task(EXAMPLES / "tasks" / "pick_and_place.json").document
    assert task.path and len(task.targets) == 4 and len(task.keep_out) == 1
    answers = []
    for target in task.targets:
        answer = solve(arm, target)
        assert answer.ok, answer.reason
        posed = copy.copy(arm)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no ClearanceWarning, no PlacementWarning
            assert posed.setJointStates(list(answer.states)) is True
        tip = posed.Joints[-1].DistalDubinsFrame().A[:3, 3]
        assert np.linalg.norm(tip - target.position) <= 1e-9 * arm.r
        assert posed.clearance().ok
        assert keep_out_violation(arm, answer.states, task.keep_out) is None
        answers.append(answer)
    for a, b in zip(answers, answers[1:], strict=False):
        assert check_path(arm, a.states, b.states).ok


def test_puma_joints_on_the_dh_axes_and_shorter(designs):
    chain = designs["puma"]
    joints = chain.Joints
    assert len(joints) == 7 and isinstance(joints[-1], EndTip)
    frames = [*dh_joint_frames(PUMA_560), dh_tool_frame(PUMA_560)]
    for joint, G in zip(joints, frames, strict=True):
        np.testing.assert_allclose(joint.pose_matrix[:3, :3], G[:3, :3], atol=1e-12)
        assert distance_to_line(G[:3, 3], joint) < 1e-9 * 1000
    compact = KinematicChain.from_dh(PUMA_560, 6, 25)
    assert compact.totalPathLength() == pytest.approx(PUMA_COMPACT_LENGTH, abs=1e-5)
    assert chain.totalPathLength() == pytest.approx(PUMA_SHORTENED_LENGTH, abs=1e-5)
    document = json.loads((DESIGNS / "puma.json").read_text())
    assert len(document["edits"]) == 5  # the slides, one per joint moved
    assert all(edit["propagate"] is False for edit in document["edits"])


# --- the trees ---------------------------------------------------------------------------------
def fixture(name: str) -> dict:
    with open(REFERENCE_DATA / f"{name}_reference.json", encoding="utf-8") as f:
        return json.load(f)


def load_tree(name: str) -> KinematicTree:
    """The tree of examples/designs/<name>.json; a PlacementWarning fails (the paper's hand's
    own overlap at its junction is allowed: it is tested below)."""
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)
        warnings.simplefilter("ignore", ClearanceWarning)
        return load_design(DESIGNS / f"{name}.json")


@pytest.fixture(scope="module")
def trees() -> dict[str, KinematicTree]:
    return {name: load_tree(name) for name in TREE_ENTRIES}


@pytest.fixture(scope="module")
def folded_hand(trees, scripts):
    """The paper's hand (its script's build(), as published) cut into sheets as its script
    does (examples/_common.tree_sheets): (fabrication, slides)."""
    hand = scripts("hand")  # also puts examples/ on the path for _common
    from _common import tree_sheets

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        return tree_sheets(hand.build())


@pytest.mark.parametrize("name", TREE_SCRIPTS)
def test_tree_design_equals_script(name, trees, scripts):
    with warnings.catch_warnings():
        warnings.simplefilter("error", PlacementWarning)
        warnings.simplefilter("ignore", ClearanceWarning)  # the paper's hand, as designed
        built = scripts(name).build()
        if name == "hand":  # the file is the hand as fabricated: its junction fitted
            from kinegami.fabrication.sheets import fit_junctions

            built, _ = fit_junctions(built)
    assert isinstance(built, KinematicTree)
    assert built.Parents == trees[name].Parents
    assert_same_chain(trees[name], built)


@pytest.mark.parametrize("name", sorted(TREE_TABLE))
def test_tree_table(name, trees):
    joints, leaves, junctions, length, clearance = TREE_TABLE[name]
    tree = trees[name]
    assert len(tree.Joints) == joints
    assert sum(1 for c in tree.Children if not c) == leaves
    assert sum(1 for c in tree.Children if len(c) > 1) == junctions
    assert round(tree.totalPathLength(), 2) == length
    report = tree.clearance()
    if clearance is None:
        assert not report.ok
    else:
        assert report.ok and round(report.min_clearance, 2) == clearance


def test_algorithmic_hand_is_the_reference_specification(trees):
    """The design's joints are the reference's (type, parameters, parent, axis line), and the
    construction places each on its line with the growth direction of the reference."""
    from kinegami.design.reader import check_document

    reference = fixture("algorithmic_hand")
    document = json.loads((DESIGNS / "algorithmic_hand.json").read_text(encoding="utf-8"))
    spec = check_document(document).specification
    assert spec.parents == tuple(j["parent"] for j in reference["joints"])
    tree = trees["algorithmic_hand"]
    node_of = tree.construction.node_of
    for joint, expected, node in zip(spec.joints, reference["joints"], node_of, strict=True):
        assert type(joint).__name__ == expected["type"]
        for key, value in expected["params"].items():
            mine = getattr(joint, key)
            mine = mine() if callable(mine) else mine  # a Waypoint's pathIndex is a method
            assert mine == pytest.approx(value, abs=1e-15), (expected["name"], key)
        T = joint.pose_matrix
        np.testing.assert_allclose(T[:3, 3], expected["axis_point"], atol=1e-12)
        np.testing.assert_allclose(T[:3, 2], expected["axis_direction"], atol=1e-12)
        # placed on its line: the same line (either sense), through the same point
        placed = tree.Joints[node].pose_matrix
        assert np.linalg.norm(np.cross(placed[:3, 2], T[:3, 2])) < 1e-12
        assert np.linalg.norm(np.cross(placed[:3, 3] - T[:3, 3], T[:3, 2])) < 1e-9
    placement = reference["placement"]
    assert tree.construction.chosen  # the file leaves the growth direction to the construction
    np.testing.assert_allclose(tree.construction.growth_direction,
                               placement["growth_direction"], atol=1e-9)  # fmt: skip
    assert tree.construction.quality == pytest.approx(placement["min_abs_dot_f"], abs=1e-9)
    assert tree.maxAnglePerElbow == pytest.approx(placement["maxAnglePerElbow"], abs=1e-15)
    assert tree.Parents == tuple(reference["reference"]["tree_parents"])


def test_algorithmic_hand_with_the_published_routing_is_the_reference_tree():
    """With "siblingAzimuth": 0 the file gives the reference total of the published
    construction (without the extra roll), which passes through itself where the two routes
    leave the root side by side; the default routing (the gallery's) is clear."""
    document = json.loads((DESIGNS / "algorithmic_hand.json").read_text(encoding="utf-8"))
    document["placement"]["siblingAzimuth"] = 0
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        published = chain_from_dict(document)
    assert published.totalPathLength() == pytest.approx(ALGORITHMIC_HAND_PUBLISHED_TOTAL,
                                                        abs=ALGORITHMIC_HAND_TOLERANCE)  # fmt: skip
    report = published.clearance()
    assert not report.ok
    routes = {published.construction.waypoints[k][1] for k in range(2)}  # the links into W1
    assert {int(part.split()[1].rstrip(",")) for pair in report.pairs
            for part in (pair.first, pair.second)} == routes  # fmt: skip


def leg_paths(tree: KinematicTree) -> list[list[int]]:
    """Every leaf's joints from the root."""
    paths = []
    for leaf, children in enumerate(tree.Children):
        if not children:
            path = [leaf]
            while tree.Parents[path[-1]] >= 0:
                path.append(tree.Parents[path[-1]])
            paths.append(path[::-1])
    return paths


def test_quadruped_has_four_legs_of_three_revolute_joints(trees):
    tree = trees["quadruped"]
    legs = leg_paths(tree)
    assert len(legs) == 4
    for leg, hip in zip(legs, QUADRUPED_HIPS, strict=True):
        revolute = [k for k in leg if isinstance(tree.Joints[k], RevoluteJoint)]
        assert len(revolute) == 3 and isinstance(tree.Joints[leg[-1]], EndTip)
        assert all(isinstance(tree.Joints[k], Waypoint) for k in leg[: leg.index(revolute[0])])
        yaw, pitch, knee = (axis_line(tree.Joints[k]) for k in revolute)
        np.testing.assert_allclose(yaw[0], hip, atol=1e-9)
        np.testing.assert_allclose(yaw[1], (0, 0, 1), atol=1e-12)  # the hip yaw is vertical
        for _, z in (pitch, knee):  # hip pitch and knee: horizontal, parallel
            assert abs(z[2]) < 1e-12
        assert abs(abs(pitch[1] @ knee[1]) - 1) < 1e-12
        assert np.linalg.norm(np.cross(knee[0] - pitch[0], pitch[1])) > 50  # a thigh between


def test_quadruped_stands_on_four_feet_below_its_body(trees):
    tree = trees["quadruped"]
    ends = []
    for leg in leg_paths(tree):
        foot = tree.Joints[leg[-1]]
        ends.append(foot.pose_matrix[:3, 3] + foot.pose_matrix[:3, 2] * foot.neutralLength / 2)
        knee = tree.Joints[leg[-2]].pose_matrix[:3, 3]
        assert knee[2] > 0  # the knees above the body, the feet below: a standing spider
    ends = np.array(ends)
    np.testing.assert_allclose(np.abs(ends), np.tile(np.abs(QUADRUPED_FOOT_END), (4, 1)),
                               atol=1e-6)  # fmt: skip
    assert sorted(np.sign(ends[:, :2]).tolist()) == [[-1, -1], [-1, 1], [1, -1], [1, 1]]
    # the feet reach lowest: every link's centreline ends above the feet's far ends
    lowest = min(float(link_polyline(link)[:, 2].min()) for link in tree.Links[1:])
    assert lowest > ends[0, 2] + 0.5 * tree.r
    assert tree.clearance().ok


def test_gripper_wrist_and_fingers(trees):
    tree = trees["gripper"]
    joints = tree.Joints
    assert isinstance(joints[0], StartTip)
    fingers = leg_paths(tree)
    assert len(fingers) == 2
    wrist = [k for k in fingers[0] if isinstance(joints[k], RevoluteJoint)][:2]
    assert wrist == [k for k in fingers[1] if isinstance(joints[k], RevoluteJoint)][:2]
    (_, zp), (_, zy) = (axis_line(joints[k]) for k in wrist)
    mount = axis_line(joints[0])[1]
    np.testing.assert_allclose([zp @ zy, zp @ mount, zy @ mount], 0, atol=1e-12)  # orthogonal
    axes = []
    for finger in fingers:
        own = [k for k in finger if isinstance(joints[k], RevoluteJoint)][2:]
        assert len(own) == 2
        axes += [axis_line(joints[k])[1] for k in own]
    for z in axes[1:]:  # every finger joint about the same direction: they close in a plane
        assert np.linalg.norm(np.cross(z, axes[0])) < 1e-12
    left, right = (joints[finger[-1]].pose_matrix[:3, 3] for finger in fingers)
    np.testing.assert_allclose(left, np.multiply(GRIPPER_TIP, (-1, 1, 1)), atol=1e-6)
    np.testing.assert_allclose(right, GRIPPER_TIP, atol=1e-6)
    assert tree.clearance().ok


@pytest.mark.parametrize("grasp", ["spherical", "cylindrical", "pinch"])
def test_hand_grasps_are_the_references(grasp, trees, scripts, folded_hand):
    """The script's grasps are the reference's states; in them the fingertips and the ball are
    the reference's. As folded (the palm slid so that its socket fits) the spherical and
    cylindrical grasps are clear; the pinch folds the thumb onto the palm (its first joint turned
    by pi/2 right after the palm's -pi/2), which the tube cannot do without passing through
    itself: its only overlaps are between the palm and the thumb."""
    import copy

    reference = fixture("hand")["reference"]["grasps"][grasp]
    hand = scripts("hand")
    states = hand.POSES[grasp]
    np.testing.assert_allclose(states, reference["states"], rtol=0, atol=1e-12)
    names = list(hand.JOINT_NAMES)
    tree = hand.build()  # the paper's hand as published (the gallery file has its palm slid)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        assert tree.setJointStates(states)
    for name, origin in reference["fingertip_origins"].items():
        np.testing.assert_allclose(tree.Joints[names.index(name)].pose_matrix[:3, 3], origin,
                                   atol=1e-6)  # fmt: skip
    assert tree.recomputeBoundingBall().r == pytest.approx(
        reference["bounding_ball_radius_recomputed"], abs=1e-6
    )
    fabrication, slides = folded_hand
    assert [joint for joint, _ in slides] == [names.index("palm")]
    folded = copy.copy(fabrication.tree)
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        assert folded.setJointStates(states)
    report = folded.clearance()
    if grasp == "pinch":
        thumb = {"joint 1", "joint 2", "link 1", "link 3"}  # palm, thumb0 and the links into them
        parts = {" ".join(part.split()[:2]).rstrip(",") for pair in report.pairs
                 for part in (pair.first, pair.second)}  # fmt: skip
        assert not report.ok and parts <= thumb, str(report)
    else:
        assert report.ok, str(report)


# --- the gallery page and the README ---------------------------------------------------------
def anchors(markdown: str) -> set[str]:
    """GitHub's anchors of the headings of a markdown text."""
    headings = re.findall(r"^#+ (.+)$", markdown, flags=re.M)
    return {re.sub(r"[^\w\- ]", "", h.strip().lower()).replace(" ", "-") for h in headings}


def test_the_gallery_page_shows_every_entry_and_only_existing_pictures(scripts):
    page = (ROOT / "docs" / "gallery.md").read_text(encoding="utf-8")
    shown = set(re.findall(r'src="images/gallery/([^"]+)"', page))
    on_disk = {p.name for p in (ROOT / "docs" / "images" / "gallery").glob("*.png")}
    assert shown == on_disk  # every picture shown exists, and every picture is shown
    for name in ENTRIES:
        assert {f"{name}.png", f"{name}_pattern.png"} <= shown
    assert {"puma_workspace.png", "hand_workspace.png"} <= shown
    for name, (_, leaves, _) in TREE_ENTRIES.items():
        poses = getattr(scripts(name), "POSES", {})
        assert {f"{name}.png", *(f"{name}_sheet_{k}_pattern.png" for k in range(leaves)),
                *(f"{name}_{pose}.png" for pose in poses)} <= shown  # fmt: skip
        assert f"kinegami build examples/designs/{name}.json" in page
        assert f"python examples/{name}.py" in page


def test_the_readme_grid_shows_every_entry_and_links_to_its_section():
    readme = (ROOT / "README.md").read_text(encoding="utf-8")
    page_anchors = anchors((ROOT / "docs" / "gallery.md").read_text(encoding="utf-8"))
    links = re.findall(r'\[<img src="docs/images/gallery/([^"]+)\.png"[^]]*\]\(docs/gallery\.md'
                       r"#([\w-]+)\)", readme)  # fmt: skip
    assert {picture for picture, _ in links} >= {*ENTRIES, *TREE_ENTRIES}
    for picture, anchor in links:
        assert (ROOT / "docs" / "images" / "gallery" / f"{picture}.png").is_file()
        assert anchor in page_anchors, anchor


# --- the scripts, run as programs -------------------------------------------------------------
@pytest.fixture(scope="module")
def script_runs(tmp_path_factory):
    """Every script started at once (``python examples/<name>.py <tmp>/<name>``); waited on in
    the tests. Returns name -> (process, output folder)."""
    env = source_env()
    runs = {}
    for name in [*SCRIPTS, *TREE_SCRIPTS]:
        folder = tmp_path_factory.mktemp("gallery") / name
        process = subprocess.Popen(
            [sys.executable, str(EXAMPLES / f"{name}.py"), str(folder)],
            stdout=subprocess.PIPE,
            stderr=subprocess.PIPE,
            text=True,
            env=env,
            cwd=tmp_path_factory.getbasetemp(),
        )
        runs[name] = (process, folder)
    yield runs
    for process, _ in runs.values():
        if process.poll() is None:
            process.kill()
            process.wait()


@pytest.mark.parametrize("name", SCRIPTS)
def test_script_writes_its_files(name, script_runs, designs):
    process, folder = script_runs[name]
    out, err = process.communicate(timeout=300)
    assert process.returncode == 0, err
    files = [folder / f"{name}.png", folder / f"{name}_pattern.png", folder / f"{name}.dxf"]
    assert sorted(folder.iterdir()) == sorted(files)  # and no temporary file left over
    for path in files:
        assert str(path) in out
    for path in files[:2]:
        assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    # the DXF is the sheet: n b wide plus half a glue panel on each side, as long as the pattern
    chain = designs[name]
    pattern = chain.creasePattern()
    side = pattern.width / chain.numSides
    size = bbox.extents(ezdxf.readfile(files[2]).modelspace()).size
    assert size.x == pytest.approx(pattern.width + side, rel=1e-6)
    assert size.y == pytest.approx(pattern.height, rel=1e-6)


@pytest.mark.parametrize("name", TREE_SCRIPTS)
def test_tree_script_writes_its_files(name, script_runs, trees, scripts):
    """A tree's script writes its 3D view, every sheet's pattern picture and DXF (the sheets
    ``kinegami build`` cuts: the DXF is the sheet at true size) and a view of every pose."""
    from _common import tree_sheets

    process, folder = script_runs[name]
    out, err = process.communicate(timeout=300)
    assert process.returncode == 0, err
    leaves = TREE_ENTRIES[name][1]
    poses = getattr(scripts(name), "POSES", {})
    sheets = [folder / f"{name}_sheet_{k}{suffix}" for k in range(leaves)
              for suffix in ("_pattern.png", ".dxf")]  # fmt: skip
    files = [folder / f"{name}.png", *sheets, *(folder / f"{name}_{pose}.png" for pose in poses)]
    assert sorted(folder.iterdir()) == sorted(files)  # and no temporary file left over
    for path in files:
        assert str(path) in out
        if path.suffix == ".png":
            assert path.read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"
    units = json.loads((DESIGNS / f"{name}.json").read_text(encoding="utf-8"))["units"]
    mm = {"mm": 1.0, "cm": 10.0}[units]
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        fabrication, _ = tree_sheets(trees[name])
    assert len(fabrication.sheets) == leaves
    for sheet in fabrication.sheets:
        pattern = sheet.pattern
        size = bbox.extents(ezdxf.readfile(folder / f"{name}_sheet_{sheet.index}.dxf")
                            .modelspace()).size  # fmt: skip
        assert size.x == pytest.approx((pattern.width + pattern.width / pattern.numSides) * mm,
                                       rel=1e-6)  # fmt: skip
        assert size.y == pytest.approx(pattern.height * mm, rel=1e-6)


def test_hand_script_prints_the_grasps(script_runs):
    process, _ = script_runs["hand"]
    out, err = process.communicate(timeout=300)
    assert process.returncode == 0, err
    for grasp in ("spherical", "cylindrical"):
        line = next(line for line in out.splitlines() if line.startswith(f"{grasp} grasp"))
        assert "middleEnd" in line and "as folded: clear with margin 0: minimum clearance " \
            "0.00347, between link 5, straight tube and link 8, straight tube; closest where the " \
            "tubes leaving joint 0 come out of its junction" in line
    assert "joint 1 slid -3.00 cm along its axis" in out


def test_script_rejects_extra_arguments(tmp_path):
    result = subprocess.run(
        [sys.executable, str(EXAMPLES / "planar_joint.py"), "a", "b"],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=source_env(),
    )
    assert result.returncode != 0
    assert "usage: python planar_joint.py [output-folder]" in result.stderr
    assert not (tmp_path / "a").exists()


def test_make_gallery_writes_both_pictures(tmp_path):
    result = subprocess.run(
        [
            sys.executable,
            str(EXAMPLES / "make_gallery.py"),
            "planar_joint",
            "--output",
            str(tmp_path),
        ],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=source_env(),
    )
    assert result.returncode == 0, result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == [
        "planar_joint.png",
        "planar_joint_pattern.png",
    ]
    assert "1 gallery entries" in result.stdout


def test_make_gallery_draws_a_trees_sheets_and_poses(tmp_path):
    result = subprocess.run(
        [sys.executable, str(EXAMPLES / "make_gallery.py"), "hand", "--output", str(tmp_path)],
        capture_output=True, text=True, cwd=tmp_path, env=source_env(),
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    assert sorted(p.name for p in tmp_path.iterdir()) == sorted(
        ["hand.png", *(f"hand_sheet_{k}_pattern.png" for k in range(3)),
         *(f"hand_{grasp}.png" for grasp in ("spherical", "cylindrical", "pinch")),
         "hand_workspace.png"]
    )  # fmt: skip
    assert "1 gallery entries" in result.stdout
    assert result.stderr == ""  # no warning: the hand's overlap is the gallery's to state


def test_make_gallery_unknown_name(tmp_path):
    result = subprocess.run(
        [sys.executable, str(EXAMPLES / "make_gallery.py"), "nosuch", "--output", str(tmp_path)],
        capture_output=True,
        text=True,
        cwd=tmp_path,
        env=source_env(),
    )
    assert result.returncode == 2
    assert "no design file for nosuch" in result.stderr
    assert list(tmp_path.iterdir()) == []


def test_gallery_pictures_do_not_depend_on_the_process_or_the_cpu(tmp_path):
    """make_gallery.py writes byte-identical pictures in two fresh processes, the second with
    another hash seed and another OpenBLAS kernel (what another CPU picks): the tracked PNGs only
    change when the chain does. The PNGs carry no matplotlib version stamp either."""
    runs = {
        "a": {"PYTHONHASHSEED": "0"},
        "b": {"PYTHONHASHSEED": "7", "OPENBLAS_CORETYPE": "Prescott"},
    }
    processes = {
        key: subprocess.Popen(
            [sys.executable, str(EXAMPLES / "make_gallery.py"), "spherical_joint", "--output",
             str(tmp_path / key)],
            stdout=subprocess.DEVNULL, stderr=subprocess.PIPE, text=True,
            env=source_env(**extra),
        )
        for key, extra in runs.items()
    }  # fmt: skip
    for process in processes.values():
        _, err = process.communicate(timeout=600)
        assert process.returncode == 0, err
    pictures = [{p.name: p.read_bytes() for p in (tmp_path / key).iterdir()} for key in runs]
    assert sorted(pictures[0]) == ["spherical_joint.png", "spherical_joint_pattern.png"]
    assert pictures[0] == pictures[1]
    for data in pictures[0].values():
        assert b"Software" not in data and b"atplotlib" not in data


def test_example1_script_says_which_size_is_which(tmp_path):
    """examples/example1.py prints the crease pattern without the glue tab and the sheet with
    it, in cm, and the sheet in mm as ``kinegami build`` prints it for the design file."""
    from kinegami.pattern.sheet import flatten

    result = subprocess.run(
        [sys.executable, str(EXAMPLES / "example1.py"), str(tmp_path / "out")],
        capture_output=True, text=True, cwd=tmp_path, env=source_env(), timeout=600,
    )  # fmt: skip
    assert result.returncode == 0, result.stderr
    chain, info = load_design_with_info(DESIGNS / "example1.json")
    assert info.units == "cm"
    pattern = chain.creasePattern()
    xmin, ymin, xmax, ymax = flatten(pattern).bounds
    w, h, sw, sh = pattern.width, pattern.height, xmax - xmin, ymax - ymin
    text = result.stdout
    assert f"crease pattern: {w:.3f} cm x {h:.3f} cm, without the glue tab" in text
    assert f"sheet: {sw:.3f} cm x {sh:.3f} cm with the glue tab" in text
    assert f"{10 * sw:.1f} mm x {10 * sh:.1f} mm" in text
    assert (tmp_path / "out" / "examplePatterns" / "example1.dxf").is_file()
