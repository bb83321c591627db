"""docs/design-format.md: every JSON example parses and builds; the bounds are documented."""

from __future__ import annotations

import json
import re
import warnings

import pytest

from kinegami.design import chain_from_dict, check_pattern, joint_table, limits

from . import DATA

PAGE = (DATA.parents[2] / "docs" / "design-format.md").read_text(encoding="utf-8")
BLOCKS = re.findall(r"^ *```json\n(.*?)^ *```", PAGE, re.S | re.M)
TUBE = {"format": "kinegami-design", "version": 1, "numSides": 4, "r": 1}


def _example(start: str):
    """The JSON example whose text starts with ``start``."""
    (block,) = [b for b in BLOCKS if b.lstrip().startswith(start)]
    return json.loads(block)


def test_code_blocks_are_json_or_other_languages():
    fences = re.findall(r"^ *```(\w*)$", PAGE, re.M)
    opening = fences[0::2]
    assert "jsonc" not in opening and "" not in opening, opening
    assert set(opening) <= {"json", "python", "bash", "text"}
    assert len(BLOCKS) == opening.count("json") >= 6


@pytest.mark.parametrize("index", range(len(BLOCKS)))
def test_every_json_example_parses(index):
    json.loads(BLOCKS[index])


def test_the_joints_and_edits_examples_build_together():
    joints = _example('[\n  {"type": "StartTip"')
    edits = _example('[\n  {"op"')
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        chain = chain_from_dict({**TUBE, "joints": joints})
        edited = chain_from_dict({**TUBE, "joints": joints, "edits": edits})
        check_pattern(edited)
    names = [row[2] for row in joint_table(chain, {**TUBE, "joints": joints})]
    assert [name for name in names if name] == ["base", "shoulder", "slide", "tool"]
    assert {type(joint).__name__ for joint in chain.Joints} == {
        "StartTip", "RevoluteJoint", "ExtendedRevoluteJoint", "PrismaticJoint", "Waypoint",
        "EndTip",
    }  # fmt: skip


def test_the_pose_examples_are_joints():
    for block in BLOCKS:
        value = json.loads(block)
        if isinstance(value, dict) and "type" in value:
            chain_from_dict({**TUBE, "joints": [{"type": "StartTip", "length": 1}, value]})


def test_the_dh_example_is_a_complete_design():
    document = _example('{\n  "format": "kinegami-design",\n  "version": 1,\n  "name": "RRP')
    assert set(document["dh"]) == {
        "convention", "rows", "jointTypes", "placement", "totalBendingAngle", "numSinkLayers",
        "neutralLength", "numLayers", "coneAngle", "endTip", "tipLength",
    }  # fmt: skip
    check_pattern(chain_from_dict(document))


def test_the_bounds_are_documented():
    section = PAGE.split("## Bounds")[1].split("\n## ")[0]
    for text in (
        f"4 to {limits.NUM_SIDES_MAX}",
        f"1 to {limits.NUM_SINK_LAYERS_MAX}",
        f"1 to {limits.NUM_LAYERS_MAX}",
        "1e-6 to 1e6",
        "≤ 1e6 r",
        "16 MiB",
        "1° to 180°",
    ):
        assert text in section, text
    for name in ("check_pattern(chain", "joint_table(chain, document)", "origin_of(chain)"):
        assert name in PAGE


def test_the_tree_example_is_the_python_listing():
    from spatialmath import SE3

    from kinegami import EndTip, KinematicTree, RevoluteJoint, Waypoint

    from .test_trees import assert_same_tree_bits

    document = _example('{\n  "format": "kinegami-design",\n  "version": 2,\n  "name": "two')
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        tree = chain_from_dict(document)
    assert type(tree) is KinematicTree and tree.Parents == (-1, 0, 0, 2, 3)
    fixed = dict(safe=False, fixedPosition=True, fixedOrientation=True)
    listing = KinematicTree(Waypoint(4, 1, SE3()))
    pi = 3.141592653589793
    listing.addJoint(0, RevoluteJoint(4, 1, pi, SE3.Trans(-3, 0, 4) * SE3.Ry(-pi / 2)), **fixed)
    right = listing.addJoint(
        0, RevoluteJoint(4, 1, pi, SE3.Trans(3, 0, 4) * SE3.Ry(-pi / 2)), **fixed
    )
    tip = listing.addJoint(right, RevoluteJoint(4, 1, pi, SE3.Tx(4)), **fixed)
    listing.addJoint(tip, EndTip(4, 1, SE3.Tx(4) * SE3.Ry(pi / 2), 1), **fixed)
    assert_same_tree_bits(tree, listing)


def test_the_joint_specification_example_reads_and_builds():
    from kinegami.design.reader import check_document
    from kinegami.design.trees import construction_available

    document = _example('{\n  "format": "kinegami-design",\n  "version": 2,\n  "name": "spec')
    spec = check_document(document).specification
    assert spec.parents == (-1, 0, 0) and spec.growth_direction == (1.0, 0.0, 1.0)
    if construction_available():
        with warnings.catch_warnings():
            warnings.simplefilter("error")
            tree = chain_from_dict(document)
        assert tree.construction.node_of == (0, 1, 4)


def test_the_version_2_fields_are_documented():
    for text in ('`parent`', '`structure`', '`placement`', '`growthDirection`', '`extraRoll`',
                 '`siblingAzimuth`', "examples/designs/hand.json"):  # fmt: skip
        assert text in PAGE, text
