"""check_pattern: the crease pattern of a loaded chain, or a DesignError naming joint or link."""

from __future__ import annotations

import copy
import json
import warnings

import numpy as np
import pytest

from kinegami.design import (
    DesignError,
    DesignInfo,
    chain_from_dict,
    check_pattern,
    load_design_with_info,
)
from kinegami.errors import InvalidParameterError
from kinegami.pattern import TubularPattern

from . import DATA

EXAMPLE_1B = DATA / "example1b.json"
DOC_1B = json.loads(EXAMPLE_1B.read_text(encoding="utf-8"))


def _document(change) -> dict:
    document = copy.deepcopy(DOC_1B)
    document.pop("states")
    change(document)
    return document


def _failure(chain, *args, **kwargs) -> DesignError:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(DesignError) as info:
            check_pattern(chain, *args, **kwargs)
    assert "\n" not in str(info.value)
    return info.value


def _same_pattern(a: TubularPattern, b: TubularPattern) -> None:
    np.testing.assert_array_equal(a.vertices_coords, b.vertices_coords)
    np.testing.assert_array_equal(a.edges_vertices, b.edges_vertices)
    assert list(a.edges_assignment) == list(b.edges_assignment)


def test_returns_the_chains_crease_pattern_with_the_designs_twist_portion():
    document = copy.deepcopy(DOC_1B)
    document["twistPortion"] = 0.5
    chain = chain_from_dict(document)
    info = DesignInfo.of(document)
    pattern = check_pattern(chain, info)
    assert isinstance(pattern, TubularPattern)
    _same_pattern(pattern, chain.creasePattern(twistPortion=0.5))
    default = check_pattern(chain)  # 0.2 without info
    _same_pattern(default, chain.creasePattern())
    assert not np.array_equal(pattern.vertices_coords, default.vertices_coords)


def _too_many_sink_layers(d):
    d["numSides"] = 8
    d["joints"][2]["numSinkLayers"] = 16


def test_a_joint_whose_pattern_fails_is_named():
    _, info = load_design_with_info(EXAMPLE_1B)
    document = _document(_too_many_sink_layers)
    chain = chain_from_dict(document, "arm.json")
    error = _failure(chain)
    assert error.file == "arm.json"  # remembered from loading
    assert error.field == "joints[2]"
    assert error.reason.startswith(
        "the crease pattern of chain joint 4 (RevoluteJoint 'elbow') cannot be built: "
        "numSinkLayers=16 cannot be folded"
    )
    assert _failure(chain, info).file == str(EXAMPLE_1B)  # info names the file
    assert _failure(chain, info, "other.json").file == "other.json"


def _tiny_elbows(d):
    d["numSides"] = 64
    d["maxAnglePerElbow"] = 1  # degrees: elbows of 1 degree cannot be resolved with 64 sides


def test_a_link_whose_pattern_fails_is_named():
    chain = chain_from_dict(_document(_tiny_elbows))
    error = _failure(chain)
    assert error.field == "joints[1]"
    assert error.reason.startswith(
        "the crease pattern of link 2 (into chain joint 2 (PrismaticJoint 'slider')) cannot be "
        "built: bendingAngle"
    )
    assert "too small to resolve for numSides=64" in error.reason
    assert "fewer numSides, a larger maxAnglePerElbow" in error.reason


def test_a_waypoint_added_by_placement_has_no_field(monkeypatch):
    chain = chain_from_dict(_document(lambda d: None))
    broken = type(chain.Joints[3])

    def fail(self):
        raise InvalidParameterError("waypoint pattern failed")

    monkeypatch.setattr(broken, "pattern", property(fail))
    error = _failure(chain)
    assert error.field == "$"
    assert error.reason == (
        "the crease pattern of chain joint 1 (Waypoint, added by safe placement) cannot be "
        "built: waypoint pattern failed"
    )


def test_chains_not_from_a_design_name_the_chain_index():
    document = _document(_too_many_sink_layers)
    chain = chain_from_dict(document)
    assert chain.delete(1)  # its origin is forgotten
    error = _failure(chain)
    assert (error.field, error.file) == ("$", None)
    assert error.reason.startswith("the crease pattern of chain joint 3 (RevoluteJoint) cannot")


def test_a_dh_design_names_the_table():
    document = {
        "format": "kinegami-design",
        "version": 1,
        "numSides": 8,
        "r": 1,
        "dh": {"rows": [[0, 0, 6, 0], [0, 0, 6, 0]], "placement": "safe", "numSinkLayers": 16},
    }
    error = _failure(chain_from_dict(document, "dh.json"))
    assert (error.field, error.file) == ("dh", "dh.json")
    assert "chain joint 0 (RevoluteJoint)" in error.reason


def test_a_failure_joining_the_modules_is_reported(monkeypatch):
    chain = chain_from_dict(_document(lambda d: None))

    def refuse(cls, patterns):
        raise InvalidParameterError("patterns do not fit")

    monkeypatch.setattr(TubularPattern, "concatenate", classmethod(refuse))
    error = _failure(chain)
    assert (error.field, error.reason) == (
        "$",
        "the crease pattern cannot be built: patterns do not fit",
    )


def test_a_numeric_error_in_the_pattern_code_is_reported(monkeypatch):
    chain = chain_from_dict(_document(lambda d: None))
    revolute = type(chain.Joints[4])

    def overflow(self):
        return np.float64(1e308) * 10.0

    monkeypatch.setattr(revolute, "pattern", property(overflow))
    error = _failure(chain)
    assert error.field == "joints[2]"
    assert "chain joint 4 (RevoluteJoint 'elbow')" in error.reason
    assert "FloatingPointError" in error.reason and "overflow" in error.reason


def test_bad_arguments():
    chain = chain_from_dict(copy.deepcopy(DOC_1B))
    with pytest.raises(TypeError, match="chain must be a KinematicChain"):
        check_pattern(DOC_1B)
    with pytest.raises(TypeError, match="info must be a DesignInfo"):
        check_pattern(chain, {"twistPortion": 0.2})
