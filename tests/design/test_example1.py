"""Example 1 of the paper as design files gives the chain of the paper's Python calls."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinegami import KinematicChain, RevoluteJoint
from kinegami.design import (
    DesignInfo,
    chain_from_dict,
    load_design,
    load_design_with_info,
    loads_design,
)

from . import DATA, PI, assert_same_chain, pose_error

EXAMPLE_1A = DATA / "example1a.json"
EXAMPLE_1B = DATA / "example1b.json"


def test_example_1a_matches_the_python_calls(example_1a):
    chain = load_design(EXAMPLE_1A)
    assert isinstance(chain, KinematicChain)
    assert_same_chain(chain, example_1a, pose_tol=1e-12)
    # the step spelling uses the same spatialmath products as the listing: bit-identical
    assert pose_error(chain, example_1a) == 0.0


def test_example_1a_crease_pattern_matches(example_1a):
    chain = load_design(EXAMPLE_1A)
    a, b = chain.creasePattern(), example_1a.creasePattern()
    np.testing.assert_allclose(a.vertices_coords, b.vertices_coords, rtol=0, atol=1e-12)
    np.testing.assert_array_equal(a.edges_vertices, b.edges_vertices)
    assert list(a.edges_assignment) == list(b.edges_assignment)


def test_example_1b_with_edits_and_state_in_degrees(example_1b):
    """Edits B1..B4 and the state of Example 1C, written in degrees."""
    expected = example_1b
    assert expected.setJointState(4, PI / 2)
    chain = load_design(EXAMPLE_1B)
    error = assert_same_chain(chain, expected, pose_tol=1e-12)
    assert error <= 1e-12
    assert chain.Joints[4].state == pytest.approx(PI / 2, abs=1e-15)


def test_example_1b_in_radians_equals_degrees():
    doc = json.loads(EXAMPLE_1B.read_text())
    doc["angleUnits"] = "rad"
    doc["joints"][1]["coneAngle"] = PI / 4
    doc["joints"][2]["totalBendingAngle"] = PI
    doc["joints"][2]["pose"] = [{"Ry": PI / 4}]
    doc["joints"][3]["pose"] = [{"Ry": PI / 2}]
    doc["edits"][2]["angle"] = -PI / 3
    doc["states"][4] = PI / 2
    assert_same_chain(chain_from_dict(doc), load_design(EXAMPLE_1B), pose_tol=1e-12)


def test_info_of_example_1b():
    chain, info = load_design_with_info(EXAMPLE_1B)
    assert isinstance(info, DesignInfo)
    assert info.name == "Example 1B"
    assert info.description.startswith("Example 1A followed by")
    assert info.units == "mm"
    assert info.twistPortion == 0.2
    assert info.file == str(EXAMPLE_1B)
    assert isinstance(chain.Joints[4], RevoluteJoint)
    with pytest.raises(AttributeError):
        info.units = "cm"  # frozen


def test_loaded_chain_is_an_ordinary_chain(example_1b_steps):
    """A loaded chain accepts further Python edits exactly like a built one."""
    chain = load_design(EXAMPLE_1A)
    ref_chain = load_design(EXAMPLE_1A)
    assert example_1b_steps(chain) == [True] * 4
    doc = json.loads(EXAMPLE_1B.read_text())
    doc.pop("states")
    assert_same_chain(chain, chain_from_dict(doc), pose_tol=1e-12)
    assert pose_error(ref_chain, chain) > 0.5  # the edits did move joints


def test_example_in_the_docs_is_example_1(example_1b):
    """The complete Example 1 file of docs/design-format.md loads as Example 1B + 1C."""
    page = (DATA.parents[2] / "docs" / "design-format.md").read_text(encoding="utf-8")
    block = page.split("```json\n")[-1].split("```")[0]
    assert example_1b.setJointState(4, PI / 2)
    assert_same_chain(loads_design(block), example_1b, pose_tol=1e-12)
    assert pose_error(loads_design(block), load_design(EXAMPLE_1B)) <= 1e-12
