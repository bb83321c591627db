"""The editor's incremental crease patterns equal the chain's, bit for bit."""

from __future__ import annotations

import importlib.util
import sys
from pathlib import Path

import numpy as np

from kinegami.editor import PatternCache
from kinegami.editor.model import EditorModel
from tests.editor.helpers import example_model


def _benchmark_module(name: str):
    """benchmarks/<name>.py as a module (its folder on sys.path while it loads: it imports
    run.py beside it)."""
    folder = Path(__file__).resolve().parents[2] / "benchmarks"
    sys.path.insert(0, str(folder))
    try:
        spec = importlib.util.spec_from_file_location(f"benchmarks_{name}", folder / f"{name}.py")
        module = importlib.util.module_from_spec(spec)
        spec.loader.exec_module(module)
        return module
    finally:
        sys.path.remove(str(folder))


_drag = _benchmark_module("editor_drag")
compact_chain, drag = _drag.compact_chain, _drag.drag


def same(a, b) -> bool:
    return (
        all(
            np.array_equal(getattr(a, name), getattr(b, name))
            for name in ("vertices_coords", "edges_vertices", "edges_assignment")
        )
        and a.modules == b.modules
        and a.height == b.height
    )


def test_a_fresh_cache_gives_the_chains_pattern():
    chain = example_model().chain
    assert same(PatternCache().pattern(chain, 0.2), chain.creasePattern(0.2))


def test_reused_prefixes_and_link_modules_give_the_chains_pattern():
    model = EditorModel(compact_chain(12))
    model.pattern()
    for joint, propagate in ((6, True), (6, False), (2, True), (10, False)):
        drag(model, joint, propagate, steps=2)
        assert same(model.pattern(), model.chain.creasePattern(0.2))


def test_another_twist_portion_is_not_mixed_up():
    chain = example_model().chain
    cache = PatternCache()
    cache.pattern(chain, 0.2)
    assert same(cache.pattern(chain, 0.4), chain.creasePattern(0.4))


def test_the_link_cache_is_bounded():
    chain = compact_chain(8)
    cache = PatternCache(max_links=2)
    cache.pattern(chain, 0.2)
    assert len(cache._links) <= 2
    assert same(cache.pattern(chain, 0.3), chain.creasePattern(0.3))
