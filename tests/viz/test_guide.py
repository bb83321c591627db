"""The folding guide's steps (kinegami.viz.guide.folding_steps) for every gallery design: every
module named once, in folding order, by its joint (the design file's numbers) or its link.
The PDF itself is tested in tests/cli/test_guide.py."""

from __future__ import annotations

import warnings

import pytest

from kinegami.design import load_design_with_info
from kinegami.fabrication.sheets import fabricate, fit_junctions
from kinegami.viz.guide import GuideSheet, folding_steps
from tests.gallery_designs import GALLERY, is_tree


def _sheets(path):
    """The assembly, its sheets to fold and its twistPortion, as kinegami build makes them."""
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        chain, info = load_design_with_info(path)
    if is_tree(path):
        fitted, _ = fit_junctions(chain)
        fabrication = fabricate(fitted, twistPortion=info.twistPortion)
        return fitted, [GuideSheet(s.name, s.pattern, s.joints)
                        for s in fabrication.sheets], info  # fmt: skip
    pattern = chain.creasePattern(info.twistPortion)
    return chain, [GuideSheet("", pattern, tuple(range(len(chain.Joints))))], info


@pytest.mark.parametrize("path", GALLERY, ids=lambda p: p.stem)
def test_every_module_is_named_once_in_folding_order(path):
    assembly, sheets, info = _sheets(path)
    steps = folding_steps(assembly, sheets, twistPortion=info.twistPortion)
    modules = [len(getattr(s.pattern, "pattern", s.pattern).modules) for s in sheets]
    assert [(st.sheet, st.module) for st in steps] == [
        (k, m) for k, count in enumerate(modules) for m in range(count)
    ]
    titles = [st.title for st in steps]
    assert len(set(titles)) == len(titles)
    for sheet_index, sheet in enumerate(sheets):
        prefix = f"{sheet.name}, " if sheet.name else ""
        mine = [st.title.removeprefix(prefix) for st in steps if st.sheet == sheet_index]
        # every module belongs to a joint or a link of this sheet (none left unnamed)
        assert all(t.startswith(("joint ", "link ")) for t in mine), mine
        order = []
        for j in sheet.joints:
            if assembly.Joints[j].pattern.isEmpty and j != 0:
                continue  # a waypoint: no module
            hits = [k for k, t in enumerate(mine) if t.startswith(f"joint {j} (")]
            assert hits, (j, mine)
            order.append(hits[0])
        assert order == sorted(order)
