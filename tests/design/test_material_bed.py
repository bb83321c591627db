"""Version 4 of the design format: the sheet material and the laser bed (docs/design-format.md,
docs/fabrication.md "Material" and "Laser bed")."""

from __future__ import annotations

import copy
import json
import warnings
from pathlib import Path

import jsonschema
import pytest

from kinegami.design import (
    DesignError,
    chain_from_dict,
    design_schema,
    design_to_dict,
    load_design_with_info,
    reader,
    save_design,
    schema,
)
from kinegami.errors import ClearanceWarning
from kinegami.fabrication.beds import Bed, Material

GALLERY = Path(__file__).resolve().parents[2] / "examples" / "designs"


def _document(name: str = "example1.json", **fields) -> dict:
    document = json.loads((GALLERY / name).read_text(encoding="utf-8"))
    document.update(fields)
    return document


def _load(document, file="arm.json"):
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        return chain_from_dict(document, file)


def _with_info(tmp_path, document):
    path = tmp_path / "arm.json"
    path.write_text(json.dumps(document), encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        return load_design_with_info(path)


def test_material_and_bed_load_into_the_info(tmp_path):
    document = _document(version=4, material={"name": "pet", "thickness": 0.2},
                         bed={"width": 600, "height": 400, "tab": 12})  # fmt: skip
    jsonschema.Draft202012Validator(design_schema()).validate(document)
    _, info = _with_info(tmp_path, document)
    assert info.material == Material("PET", 0.2)  # a known name in its own spelling
    assert info.bed == Bed(600.0, 400.0, 5.0, 12.0)
    assert info.margin is None


@pytest.mark.parametrize(("name", "units", "margin"), [
    ("puma.json", "mm", 0.25), ("example1.json", "cm", 0.025),
])  # fmt: skip
def test_the_thickness_is_the_default_margin_in_the_designs_units(name, units, margin):
    document = _document(name, version=4, material={"name": "PET"})  # PET: 0.25 mm
    assert document["units"] == units
    assert _load(document).margin == pytest.approx(margin, rel=1e-15)


def test_a_margin_of_the_file_wins_over_the_thickness():
    document = _document(version=4, material={"name": "paper", "thickness": 0.1}, margin=0.5)
    assert _load(document).margin == 0.5


def test_saving_keeps_material_and_bed_as_version_4(tmp_path):
    document = _document(version=4, material={"name": "PET", "thickness": 0.18},
                         bed={"width": 1000, "height": 600})  # fmt: skip
    chain, info = _with_info(tmp_path, document)
    written = design_to_dict(chain, units=info.units, material=info.material, bed=info.bed)
    assert written["version"] == 4
    assert written["material"] == {"name": "PET", "thickness": 0.18}
    assert written["bed"] == {"width": 1000.0, "height": 600.0, "margin": 5.0, "tab": 10.0}
    assert "margin" not in written  # the thickness is the margin a loaded file gets anyway
    path = save_design(chain, tmp_path / "again.json", units=info.units, material=info.material,
                       bed=info.bed)  # fmt: skip
    again, info_again = load_design_with_info(path)
    assert (info_again.material, info_again.bed) == (info.material, info.bed)
    assert again.margin == chain.margin == pytest.approx(0.018)


def test_saving_without_them_writes_the_versions_as_before():
    chain = _load(_document())
    assert design_to_dict(chain, units="cm")["version"] == 1
    chain.margin = 0.1
    assert design_to_dict(chain, units="cm")["version"] == 3


@pytest.mark.parametrize("version", [1, 2, 3])
@pytest.mark.parametrize("key", ["material", "bed"])
def test_older_versions_with_a_version_4_field_are_refused(version, key):
    value = {"name": "PET"} if key == "material" else {"width": 600, "height": 400}
    document = _document(version=version, **{key: value})
    with pytest.raises(DesignError) as info:
        _load(document)
    assert info.value.field == key and "\n" not in str(info.value)
    assert f"'{key}' is a field of version 4" in info.value.reason
    with pytest.raises(jsonschema.ValidationError):
        jsonschema.Draft202012Validator(design_schema()).validate(document)


def test_a_reader_of_versions_1_to_3_refuses_version_4_in_one_line(monkeypatch, tmp_path):
    """Readers since version 3 refuse a newer version with this one line (checked against the
    reader of the commit before version 4 when it was added; here the same code with its
    versions)."""
    monkeypatch.setattr(reader, "VERSIONS", (1, 2, 3))
    monkeypatch.setattr(schema, "VERSIONS", (1, 2, 3))
    document = _document(version=4, material={"name": "PET"}, bed={"width": 600, "height": 400})
    path = tmp_path / "arm.json"
    path.write_text(json.dumps(document), encoding="utf-8")
    with pytest.raises(DesignError) as info:
        load_design_with_info(path)
    text = str(info.value)
    assert "\n" not in text and info.value.field == "version"
    assert ("version 4 is newer than this kinegami reads (versions 1, 2, 3); upgrade kinegami "
            "to read it") in text


@pytest.mark.parametrize(("fields", "where", "words"), [
    ({"material": {"name": "kapton"}}, "material.thickness", "give the thickness of kapton"),
    ({"material": {"name": "PET", "thickness": 0}}, "material.thickness", "> 0"),
    ({"material": {"name": "PET", "colour": "clear"}}, "material.colour", "unknown key"),
    ({"bed": {"width": 600, "height": 400, "margin": 250}}, "bed.margin", "less than half"),
    ({"bed": {"width": -600, "height": 400}}, "bed.width", "> 0"),
    ({"bed": {"width": 600, "height": 400, "tab": 0}}, "bed.tab", "> 0"),
])  # fmt: skip
def test_bad_material_or_bed_is_one_line_naming_the_field(fields, where, words):
    document = copy.deepcopy(_document(version=4, **fields))
    with pytest.raises(DesignError) as info:
        _load(document)
    assert info.value.field == where and words in str(info.value) and "\n" not in str(info.value)
