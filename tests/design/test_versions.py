"""Versions 1 and 2 of the format: version-1 designs load and save exactly as before version 2
existed, and version-2 fields in a version-1 file are reported.

The fingerprints (tests/design/data/version1_fingerprints.json) were computed before version 2
existed, by :func:`fingerprint` on every version-1 design of the gallery and of tests/design/data,
on two kinds of machine (their last bits differ; see :func:`known`).
"""

from __future__ import annotations

import copy
import hashlib
import json
import warnings
from pathlib import Path

import jsonschema
import numpy as np
import pytest

from kinegami import KinematicChain
from kinegami.design import (
    DesignError,
    chain_from_dict,
    design_schema,
    design_to_dict,
    dumps_design,
    load_design,
)
from kinegami.errors import ClearanceWarning
from kinegami.tree import KinematicTree

from . import DATA

GALLERY = Path(__file__).resolve().parents[2] / "examples" / "designs"
FINGERPRINTS = json.loads((DATA / "version1_fingerprints.json").read_text(encoding="utf-8"))


def known(kind: str, name: str) -> set[str]:
    """The fingerprints of design ``name`` (``kind`` "loaded" or "saved") computed before
    version 2 existed, one per kind of machine: the last bits of a chain depend on the CPU
    (numpy and OpenBLAS pick their SIMD code by it), so each machine kind has its own."""
    return {FINGERPRINTS[kind][name]} | {
        machine[kind][name] for machine in FINGERPRINTS.get("other_machines", ())
    }


def _hex(values) -> str:
    return ",".join(float(v).hex() for v in np.ravel(np.asarray(values, dtype=float)))


def fingerprint(assembly, with_class: bool = True) -> str:
    """SHA-256 of everything a loaded design is made of, bit for bit: its class (unless not
    ``with_class``), parents, tube, joint types, poses, states, lengths and path axes, link
    frames and paths, and the ball."""
    h = hashlib.sha256()

    def put(text: str) -> None:
        h.update(text.encode())
        h.update(b";")

    put(type(assembly).__name__ if with_class else "")
    put(repr(tuple(assembly.Parents)))
    put(_hex([assembly.r, assembly.maxAnglePerElbow, assembly.numSides]))
    for joint in assembly.Joints:
        put(type(joint).__name__)
        put(_hex(joint.pose_matrix))
        put(_hex([joint.state, joint.neutralLength, joint.pathIndex()]))
    for link in assembly.Links:
        p = link.path
        put(_hex(link.start_frame))
        put(_hex(link.end_frame))
        put(_hex([p.theta1, p.tMag, p.theta2]))
    ball = assembly.boundingBall
    put(_hex([*ball.c, ball.r]))
    return h.hexdigest()


def _path(name: str) -> Path:
    return DATA / name.removeprefix("tests/") if name.startswith("tests/") else GALLERY / name


def _quiet_load(path: Path):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)  # example 1B's state overlaps
        return load_design(path)


#: Designs whose states are set when they load: since setJointStates moves the chain by the
#: one forward kinematics (kinegami.geometry.screws, products in another order), their last bits
#: changed. They are compared to the chain they loaded as before, number by number, to 1e-12 r.
STATES_SET = {"tests/example1b.json": "example1b_loaded_before_screws.json"}


def assert_loaded_as_before(chain, name: str) -> None:
    """``chain`` is the design ``name`` as it loaded before: bit for bit, or (for a design
    with states) within 1e-12 r of every number it was made of."""
    if name not in STATES_SET:
        assert fingerprint(chain) in known("loaded", name)
        return
    before = json.loads((DATA / STATES_SET[name]).read_text(encoding="utf-8"))
    r = chain.r
    assert [j.state for j in chain.Joints] == before["states"]
    for got, want in [([j.pose_matrix for j in chain.Joints], before["poses"]),
                      ([j.distal_frame() for j in chain.Joints], before["distal"]),
                      ([link.start_frame for link in chain.Links], before["link_start"]),
                      ([link.end_frame for link in chain.Links], before["link_end"])]:  # fmt: skip
        assert np.abs(np.array(got, dtype=float) - np.array(want)).max() <= 1e-12 * r
    ball = chain.boundingBall
    assert np.abs(np.array([*ball.c, ball.r]) - np.array(before["ball"])).max() <= 1e-12 * r


@pytest.mark.parametrize("name", sorted(FINGERPRINTS["loaded"]))
def test_version_1_designs_load_bit_for_bit_as_before(name):
    chain = _quiet_load(_path(name))
    assert type(chain) is KinematicChain
    assert_loaded_as_before(chain, name)


@pytest.mark.parametrize("name", sorted(FINGERPRINTS["saved"]))
def test_version_1_designs_save_the_same_text_as_before(name):
    text = dumps_design(design_to_dict(load_design(GALLERY / name), name="x"))
    assert hashlib.sha256(text.encode()).hexdigest() in known("saved", name)
    assert json.loads(text)["version"] == 1 and "structure" not in text


#: Version-1 gallery designs written after version 2 existed (no fingerprint from before).
ADDED_LATER = {"pick_and_place.json"}


def test_every_version_1_gallery_design_is_fingerprinted():
    ones = [p.name for p in GALLERY.glob("*.json") if json.loads(p.read_text())["version"] == 1]
    assert sorted(ones) == sorted({*FINGERPRINTS["saved"], *ADDED_LATER})


@pytest.mark.parametrize("name", sorted(FINGERPRINTS["saved"]))
def test_a_version_1_design_written_as_version_2_is_the_same_chain(name):
    document = json.loads((GALLERY / name).read_text(encoding="utf-8"))
    document["version"] = 2
    chain = chain_from_dict(document)
    assert type(chain) is KinematicChain
    assert_loaded_as_before(chain, name)


def _joints_design(name: str) -> dict:
    document = json.loads((GALLERY / name).read_text(encoding="utf-8"))
    assert "joints" in document
    return document


def test_a_chain_as_structure_tree_is_the_same_tree_bit_for_bit():
    """"structure": "tree" loads a chain design as a KinematicTree whose joints and links are
    the chain's (the tree in which every parent is the previous joint), edits included."""
    document = _joints_design("example1.json")
    chain = chain_from_dict(document)
    tree = chain_from_dict({**document, "version": 2, "structure": "tree"})
    assert type(tree) is KinematicTree
    assert tree.Parents == chain.Parents
    assert fingerprint(tree, with_class=False) == fingerprint(chain, with_class=False)


def _v1_with(change) -> dict:
    document = copy.deepcopy(_joints_design("example1.json"))
    change(document)
    return document


@pytest.mark.parametrize(
    ("change", "field", "words"),
    [
        (lambda d: d["joints"][2].update(parent=0), "joints[2].parent", "version 2"),
        (lambda d: d["joints"][2].update(parent="start"), "joints[2].parent", "version 2"),
        (lambda d: d.update(structure="tree"), "structure", "version 2"),
        (lambda d: d.update(structure="chain"), "structure", "version 2"),
        (lambda d: d.update(placement={"method": "wafr2024"}), "placement", "version 2"),
    ],
)
def test_version_2_fields_in_a_version_1_file_are_errors(change, field, words):
    document = _v1_with(change)
    with pytest.raises(DesignError) as caught:
        chain_from_dict(document, "arm.json")
    error = caught.value
    assert error.field == field, str(error)
    assert words in error.reason and '"version": 2' in error.reason
    assert str(error).startswith(f"arm.json: {field}: ")
    # an independent validator also refuses it
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.Draft202012Validator(design_schema()).validate(document)


def test_version_2_designs_are_valid_for_a_plain_validator():
    validator = jsonschema.Draft202012Validator(design_schema())
    for path in (GALLERY / "hand.json", DATA / "algorithmic_hand.json"):
        validator.validate(json.loads(path.read_text(encoding="utf-8")))


# --- version 3: the margin --------------------------------------------------------------------
def test_a_margin_is_written_as_version_3_and_read_back():
    chain = _quiet_load(GALLERY / "example1.json")
    plain = design_to_dict(chain, name="x", units="cm")
    chain.margin = 0.05
    document = design_to_dict(chain, name="x", units="cm")
    assert (document["version"], document["margin"]) == (3, 0.05)
    assert {k: v for k, v in document.items() if k not in ("version", "margin")} == {
        k: v for k, v in plain.items() if k != "version"
    }
    again = chain_from_dict(document)
    assert type(again) is KinematicChain and again.margin == 0.05
    # the same chain as without the margin, bit for bit
    assert fingerprint(again) == fingerprint(chain_from_dict(plain))
    assert design_to_dict(again, name="x", units="cm") == document
    jsonschema.Draft202012Validator(design_schema()).validate(document)


def test_a_tree_with_a_margin_is_version_3_and_stays_a_tree():
    tree = _quiet_load(GALLERY / "gripper.json")
    plain = design_to_dict(tree, name="x")
    tree.margin = 0.2
    document = design_to_dict(tree, name="x")
    assert (document["version"], document["structure"], document["margin"]) == (3, "tree", 0.2)
    again = chain_from_dict(document)
    assert type(again) is KinematicTree and again.margin == 0.2
    assert fingerprint(again) == fingerprint(chain_from_dict(plain))
    jsonschema.Draft202012Validator(design_schema()).validate(document)


def test_margin_0_writes_the_version_as_before():
    """Old files round-trip unchanged: margin 0 (the default, or set) writes no margin and the
    version of before (1 for chains, 2 for trees)."""
    for name, version in (("example1.json", 1), ("gripper.json", 2)):
        chain = _quiet_load(GALLERY / name)
        chain.margin = 0.0
        document = design_to_dict(chain, name="x")
        assert document["version"] == version and "margin" not in document


@pytest.mark.parametrize("version", [1, 2])
def test_a_margin_in_an_older_version_is_refused_by_both_validators(version):
    document = copy.deepcopy(_joints_design("example1.json"))
    document.update(version=version, margin=0.1)
    with pytest.raises(DesignError) as info:
        chain_from_dict(document, "arm.json")
    assert info.value.field == "margin"
    assert "'margin' is a field of version 3" in info.value.reason
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.Draft202012Validator(design_schema()).validate(document)


def test_version_2_fields_are_allowed_in_version_3():
    document = json.loads((GALLERY / "gripper.json").read_text(encoding="utf-8"))
    document.update(version=3, margin=0.0)
    tree = _quiet_load_dict(document)
    assert type(tree) is KinematicTree and tree.margin == 0.0
    jsonschema.Draft202012Validator(design_schema()).validate(document)


def _quiet_load_dict(document):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        return chain_from_dict(document)


def test_a_newer_version_is_refused_in_one_line():
    document = copy.deepcopy(_joints_design("example1.json"))
    document["version"] = 9
    with pytest.raises(DesignError) as info:
        chain_from_dict(document, "arm.json")
    text = str(info.value)
    assert "\n" not in text and info.value.field == "version"
    assert "version 9 is newer than this kinegami" in text and "(versions 1, 2, 3, 4)" in text
