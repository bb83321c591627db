"""The gallery's design files, split into chains and trees (a tree has a crease pattern per
sheet, so tests of a chain's single pattern take the chains; tests/tree and the tree tests of
the command line take the trees)."""

from __future__ import annotations

import json
from pathlib import Path

from kinegami.design import DesignInfo

DESIGN_DIR = Path(__file__).resolve().parents[1] / "examples" / "designs"
GALLERY = sorted(DESIGN_DIR.glob("*.json"))


def is_tree(path: Path) -> bool:
    """Whether the design file loads as a KinematicTree."""
    with open(path, encoding="utf-8") as f:
        return DesignInfo.of(json.load(f)).structure == "tree"


CHAIN_DESIGNS = [p for p in GALLERY if not is_tree(p)]
TREE_DESIGNS = [p for p in GALLERY if is_tree(p)]
