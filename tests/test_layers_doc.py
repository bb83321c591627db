"""docs/architecture.md's layer table names the layers of .importlinter's contract, in its order
(the picture is drawn from the contract itself: docs/images/make_layers_image.py)."""

from __future__ import annotations

import configparser
import re
from pathlib import Path

ROOT = Path(__file__).resolve().parents[1]


def contract_layers() -> list[str]:
    config = configparser.ConfigParser()
    config.read(ROOT / ".importlinter")
    text = config["importlinter:contract:layers"]["layers"]
    return [m.strip().removeprefix("kinegami.") for line in text.split("\n") if line.strip()
            for m in line.split("|")]  # fmt: skip


def documented_layers() -> list[str]:
    text = (ROOT / "docs" / "architecture.md").read_text(encoding="utf-8")
    table = text[text.index("| layer (top to bottom) |"):]
    names = []
    for line in table.splitlines()[2:]:
        if not line.startswith("|"):
            break
        first = line.split("|")[1]
        names += [re.sub(r"(\.py|/)$", "", n) for n in re.findall(r"`([^`]+)`", first)]
    return names


def test_the_documented_layers_are_the_contract_s():
    assert documented_layers() == contract_layers()


def test_every_folder_of_the_package_is_a_layer():
    folders = {p.name for p in (ROOT / "kinegami").iterdir()
               if p.is_dir() and (p / "__init__.py").exists()}  # fmt: skip
    assert folders <= set(contract_layers())
