"""save_design / design_to_dict: saved chains load back as the same chain."""

from __future__ import annotations

import json
import os
import tempfile
from pathlib import Path

import jsonschema
import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings

from kinegami import SE3, EndTip, KinematicChain, PrismaticJoint, RevoluteJoint, StartTip
from kinegami.design import (
    chain_from_dict,
    design_schema,
    design_to_dict,
    dumps_design,
    load_design,
    load_design_with_info,
    loads_design,
    save_design,
)
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.export import ExportError

from . import DATA, PI, assert_same_chain, random_chains


def _files(folder: Path) -> list[str]:
    return sorted(p.name for p in folder.iterdir())


@pytest.fixture
def example_1c(example_1b):
    """Example 1B with the revolute joint at pi/2 and the prismatic joint extended."""
    assert example_1b.setJointState(4, PI / 2)
    assert example_1b.setJointState(2, 1.0)
    return example_1b


def test_round_trip_of_an_edited_chain_with_states(tmp_path, example_1c):
    path = save_design(example_1c, tmp_path / "c.json", name="1C", units="cm", twistPortion=0.3)
    assert path == tmp_path / "c.json"
    assert _files(tmp_path) == ["c.json"]
    chain, info = load_design_with_info(path)
    error = assert_same_chain(chain, example_1c, pose_tol=1e-12)
    assert error <= 1e-12
    assert [j.state for j in chain.Joints] == [j.state for j in example_1c.Joints]
    assert (info.name, info.units, info.twistPortion) == ("1C", "cm", 0.3)


def test_saved_poses_are_the_state_zero_poses(example_1c, example_1b_steps, example_1a):
    """Poses in the file are those of the chain at state 0; the states are listed apart."""
    document = design_to_dict(example_1c)
    example_1b_steps(example_1a)  # the same chain, never moved
    for entry, joint in zip(document["joints"], example_1a.Joints, strict=True):
        np.testing.assert_allclose(entry["pose"], joint.pose_matrix, rtol=0, atol=1e-12)
    assert document["states"] == [0.0, 0.0, 1.0, 0.0, PI / 2, 0.0, 0.0]
    assert example_1c.Joints[4].state == PI / 2  # saving does not change the chain


def test_saved_joints_use_fixed_absolute_placement(example_1b):
    document = design_to_dict(example_1b)
    root, *rest = document["joints"]
    assert not {"relative", "safe", "fixedPosition", "fixedOrientation"} & set(root)
    for entry in rest:
        assert entry["relative"] is False and entry["safe"] is False
        assert entry["fixedPosition"] is True and entry["fixedOrientation"] is True
    assert "states" not in document
    assert document["angleUnits"] == "rad"
    assert document["maxAnglePerElbow"] == PI / 2


def test_joint_parameters_are_saved():
    chain = KinematicChain(StartTip(6, 2.0, Pose=SE3(), length=1.25))
    assert chain.append(RevoluteJoint(6, 2.0, 2.5, SE3.Tz(9), numSinkLayers=3))
    assert chain.append(PrismaticJoint(6, 2.0, 4.5, 2, 1.0, SE3.Tx(9)))
    joints = design_to_dict(chain)["joints"]
    assert joints[0]["type"] == "StartTip" and joints[0]["length"] == 1.25
    revolute = next(j for j in joints if j["type"] == "RevoluteJoint")
    assert (revolute["totalBendingAngle"], revolute["numSinkLayers"]) == (2.5, 3)
    prismatic = next(j for j in joints if j["type"] == "PrismaticJoint")
    assert (prismatic["neutralLength"], prismatic["numLayers"], prismatic["coneAngle"]) == (
        4.5,
        2,
        1.0,
    )
    assert all(j["pathIndex"] in (0, 1, 2) for j in joints if j["type"] == "Waypoint")


def test_saved_file_is_schema_valid_readable_json(tmp_path, example_1c):
    """An independent reader (json + jsonschema) accepts the file; matrix rows are one line."""
    path = save_design(example_1c, tmp_path / "c.json", description="edited")
    text = path.read_text(encoding="utf-8")
    document = json.loads(text)
    jsonschema.Draft202012Validator(design_schema()).validate(document)
    assert document["format"] == "kinegami-design" and document["version"] == 1
    lines = text.splitlines()
    assert lines[1].startswith('  "format"')  # indent 2
    row = next(line for line in lines if line.strip().startswith("[1.0, 0.0, 0.0,"))
    assert row.rstrip(",").strip().endswith("]")  # a whole matrix row on one line
    assert text.endswith("}\n")


def test_floats_keep_full_precision(example_1c):
    document = design_to_dict(example_1c)
    again = json.loads(dumps_design(document))
    assert again == document
    pose = again["joints"][4]["pose"]
    assert any(len(repr(v)) > 15 for row in pose for v in row)


def test_dict_round_trip_is_exact_at_state_zero(example_1b):
    document = design_to_dict(example_1b, name="B")
    chain = chain_from_dict(json.loads(dumps_design(document)))
    assert design_to_dict(chain, name="B") == document


def test_save_creates_folders_and_replaces(tmp_path, example_1a):
    target = tmp_path / "a" / "b" / "x.json"
    save_design(example_1a, target)
    save_design(example_1a, str(target), name="again")
    assert load_design_with_info(target)[1].name == "again"
    assert _files(target.parent) == ["x.json"]


def test_save_failure_leaves_nothing(tmp_path, example_1a):
    (tmp_path / "file").write_text("not a folder")
    with pytest.raises(ExportError):
        save_design(example_1a, tmp_path / "file" / "x.json")
    assert _files(tmp_path) == ["file"]


@pytest.mark.parametrize(
    ("kwargs", "error", "match"),
    [
        ({"units": "km"}, InvalidParameterError, "units must be one of 'mm', 'cm', 'm', 'in'"),
        ({"twistPortion": 1.0}, InvalidParameterError, r"twistPortion must lie in \[0, 1\)"),
        ({"name": 3}, InvalidTypeError, "name must be a string"),
    ],
)
def test_save_rejects_bad_options(tmp_path, example_1a, kwargs, error, match):
    with pytest.raises(error, match=match):
        save_design(example_1a, tmp_path / "x.json", **kwargs)
    assert _files(tmp_path) == []


def test_save_rejects_bad_targets(tmp_path, example_1a):
    with pytest.raises(InvalidParameterError, match=r"must end in \.json"):
        save_design(example_1a, tmp_path / "x.txt")
    (tmp_path / "d.json").mkdir()
    with pytest.raises(InvalidParameterError, match="is a directory"):
        save_design(example_1a, tmp_path / "d.json")
    with pytest.raises(InvalidTypeError, match="chain must be a KinematicChain"):
        save_design("chain", tmp_path / "x.json")
    assert _files(tmp_path) == ["d.json"]


def test_example_file_round_trip(tmp_path):
    """The Example 1B fixture (degrees, edits, states) survives save -> load."""
    chain = load_design(DATA / "example1b.json")
    again = load_design(save_design(chain, tmp_path / "b.json"))
    assert assert_same_chain(again, chain, pose_tol=1e-12) <= 1e-12


@settings(
    max_examples=60,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(chain=random_chains())
def test_random_chains_round_trip_through_files(chain):
    with tempfile.TemporaryDirectory() as folder:
        path = save_design(chain, os.path.join(folder, "chain.json"))
        loaded = load_design(path)
        assert os.listdir(folder) == ["chain.json"]
    assert_same_chain(loaded, chain, pose_tol=1e-12)
    again = design_to_dict(loaded)
    first = design_to_dict(chain)
    assert again.keys() == first.keys()
    assert again.get("states") == first.get("states")
    for a, b in zip(again["joints"], first["joints"], strict=True):
        assert {k: v for k, v in a.items() if k != "pose"} == {
            k: v for k, v in b.items() if k != "pose"
        }
        np.testing.assert_allclose(a["pose"], b["pose"], rtol=0, atol=1e-12 * _scale(b["pose"]))


def _scale(pose) -> float:
    return max(1.0, float(np.max(np.abs(pose))))


@settings(
    max_examples=40,
    deadline=None,
    suppress_health_check=[HealthCheck.too_slow, HealthCheck.data_too_large],
)
@given(chain=random_chains(states=False))
def test_random_chains_at_state_zero_give_identical_documents(chain):
    document = design_to_dict(chain)
    loaded = loads_design(dumps_design(document))
    assert design_to_dict(loaded) == document
    assert_same_chain(loaded, chain, pose_tol=0.0)


def test_chain_whose_root_became_an_end_tip(tmp_path):
    """Deleting joint 0 of [StartTip, EndTip] leaves an EndTip root; it still round-trips."""
    chain = KinematicChain(StartTip(4, 1, Pose=SE3(), length=1.5))
    assert chain.append(EndTip(4, 1, Pose=SE3.Rx(0.3) * SE3.Tz(5), length=2.0), safe=False)
    assert chain.delete(0)
    assert isinstance(chain.Joints[0], EndTip)
    document = design_to_dict(chain)
    assert [j["type"] for j in document["joints"]] == ["Waypoint", "EndTip"]
    assert document["edits"] == [{"op": "delete", "joint": 0}]
    loaded = load_design(save_design(chain, tmp_path / "tip.json"))
    assert assert_same_chain(loaded, chain, pose_tol=0.0) == 0.0
