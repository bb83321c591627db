"""The editor keeps a design's sheet material and laser bed (design format version 4) through
its commands and writes them back when it saves."""

from __future__ import annotations

import json
import warnings

from kinegami.design import load_design_with_info
from kinegami.editor.document import Document
from kinegami.fabrication.beds import Bed, Material

from .helpers import EXAMPLE1


def test_a_saved_design_keeps_its_material_and_bed(tmp_path):
    document = json.loads(EXAMPLE1.read_text(encoding="utf-8"))
    document.update(version=4, material={"name": "PET", "thickness": 0.2},
                    bed={"width": 600, "height": 400, "tab": 8})  # fmt: skip
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        doc = Document.loads(json.dumps(document))
    assert doc.material == Material("PET", 0.2) and doc.bed == Bed(600.0, 400.0, 5.0, 8.0)
    assert doc.chain.margin == 0.02  # 0.2 mm in the design's cm
    renamed = doc.replaced(name="renamed")
    assert (renamed.material, renamed.bed) == (doc.material, doc.bed)
    path = renamed.save(tmp_path / "arm.json")
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain, info = load_design_with_info(path)
    assert (info.material, info.bed, info.margin) == (doc.material, doc.bed, None)
    assert chain.margin == 0.02
