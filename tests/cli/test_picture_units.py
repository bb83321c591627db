"""`kinegami build` and `kinegami show` label their pictures in the design's units."""

from __future__ import annotations

import pytest

from kinegami import cli
from kinegami.chain import KinematicChain
from kinegami.fabrication.sheets import TreeFabrication
from kinegami.pattern import TubularPattern


@pytest.fixture
def shown(monkeypatch):
    """The ``units`` option of every show() the command calls, in order."""
    seen = []

    def spy(cls):
        original = cls.show

        def show(self, **options):
            seen.append((cls.__name__, options.get("units")))
            return original(self, **options)

        monkeypatch.setattr(cls, "show", show)

    for cls in (KinematicChain, TubularPattern, TreeFabrication):
        spy(cls)
    return seen


def test_a_chain_build_draws_in_the_design_units(shown, tmp_path):
    assert cli.main(["build", "examples/designs/puma.json", "-o", str(tmp_path),
                     "--formats", "png"]) == 0  # fmt: skip
    assert shown == [("KinematicChain", "mm"), ("TubularPattern", "mm")]


def test_a_tree_build_draws_in_the_design_units(shown, tmp_path):
    assert cli.main(["build", "examples/designs/hand.json", "-o", str(tmp_path),
                     "--formats", "png"]) == 0  # fmt: skip
    assert shown[0] == ("TreeFabrication", "cm")
    assert shown[1:] and all(entry == ("TubularPattern", "cm") for entry in shown[1:])
