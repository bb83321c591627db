"""The shipped JSON Schema: valid, packaged, in step with the loader."""

from __future__ import annotations

import inspect
import json
from importlib import resources

import jsonschema
import pytest

import kinegami.design as design
from kinegami.design.schema import EDIT_OPS, JOINT_TYPES, PLACEMENT_KEYS

from . import DATA


def test_schema_is_valid_draft_2020_12():
    schema = design.design_schema()
    assert schema["$schema"] == "https://json-schema.org/draft/2020-12/schema"
    jsonschema.Draft202012Validator.check_schema(schema)


def test_schema_ships_as_package_data():
    text = resources.files("kinegami.design").joinpath("schema.json").read_text("utf-8")
    assert json.loads(text) == design.design_schema()


@pytest.mark.parametrize("name", ["example1a.json", "example1b.json"])
def test_fixtures_are_valid_for_a_plain_validator(name):
    document = json.loads((DATA / name).read_text(encoding="utf-8"))
    jsonschema.Draft202012Validator(design.design_schema()).validate(document)


def test_schema_and_loader_agree_on_names():
    defs = design.design_schema()["$defs"]
    assert tuple(defs["joint"]["properties"]["type"]["enum"]) == JOINT_TYPES
    assert tuple(defs["edit"]["properties"]["op"]["enum"]) == EDIT_OPS
    for kind in JOINT_TYPES:
        properties = defs[kind]["properties"]
        assert {"type", "name", "pose", "parent", *PLACEMENT_KEYS} <= set(properties)
    top = design.design_schema()["properties"]
    assert set(top) == {
        "format", "version", "name", "description", "units", "angleUnits", "numSides", "r",
        "maxAnglePerElbow", "twistPortion", "joints", "dh", "edits", "states", "requireClearance",
        "structure", "placement", "margin", "task", "material", "bed",
    }  # fmt: skip
    assert top["version"]["enum"] == list(design.VERSIONS)
    assert top["units"]["enum"] == list(design.UNITS)


def test_public_functions():
    either = "KinematicChain | KinematicTree"
    signatures = {
        "load_design": f"(path: 'str | os.PathLike') -> '{either}'",
        "loads_design": f"(text: 'str', file: 'str | os.PathLike | None' = None) -> '{either}'",
        "chain_from_dict": (
            f"(data: 'dict', file: 'str | os.PathLike | None' = None) -> '{either}'"
        ),
        "read_design": "(path: 'str | os.PathLike') -> 'dict'",
        "validate_design": "(path: 'str | os.PathLike') -> 'None'",
        "load_design_with_info": (
            f"(path: 'str | os.PathLike') -> 'tuple[{either}, DesignInfo]'"
        ),
        "check_pattern": (
            f"(chain: '{either}', info: 'DesignInfo | None' = None, "
            "file: 'str | os.PathLike | None' = None) -> 'TubularPattern'"
        ),
        "joint_table": (
            f"(chain: '{either}', document: 'dict') -> 'list[tuple[int, str, str | None]]'"
        ),
        "origin_of": "(chain: 'KinematicChain') -> 'DesignOrigin | None'",
    }
    for name, signature in signatures.items():
        assert str(inspect.signature(getattr(design, name))) == signature, name
    save = inspect.signature(design.save_design)
    assert list(save.parameters) == [
        "chain", "path", "name", "description", "units", "twistPortion", "task", "material",
        "bed",
    ]  # fmt: skip
    assert save.parameters["units"].default == "mm"
    assert save.parameters["name"].kind is inspect.Parameter.KEYWORD_ONLY
    assert set(design.__all__) <= set(dir(design))
