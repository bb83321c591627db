"""The editor's Reach panel without a browser (docs/editor.md, Reach): a typed target is
reached by inverse kinematics warm-started from the current states (one undoable command), a
target the design cannot reach leaves it as it was and says why, a handle drag previews, a
tree's target is for the selected leaf, and the workspace cloud is sampled in the background."""

from __future__ import annotations

import numpy as np
import pytest

pytest.importorskip("viser")

from kinegami.editor.server import EditorServer  # noqa: E402
from kinegami.reach import kinematics  # noqa: E402

from .helpers import ROOT  # noqa: E402

PUMA = ROOT / "examples" / "designs" / "puma.json"
HAND = ROOT / "examples" / "designs" / "hand.json"
LIVE = 120.0


@pytest.fixture
def server():
    server = EditorServer(PUMA, port=0, autosave=False)
    yield server
    server.stop()


def _clear_tip(design, seed: int) -> tuple[np.ndarray, np.ndarray]:
    """A clear configuration of ``design`` and its tip position."""
    compiled = kinematics(design)
    rng = np.random.default_rng(seed)
    low, high = compiled.ranges[:, 0], compiled.ranges[:, 1]
    for _ in range(2_000):
        q = low + (high - low) * rng.random(low.size)
        if design.clearance(q.tolist()).ok:
            return q, compiled.fkine(q)[:3, 3]
    raise AssertionError("no clear configuration in 2,000 draws")


def test_a_typed_target_is_reached_in_one_undoable_command(view):
    before = view.model.document
    _, target = _clear_tip(view.model.chain, seed=1)
    view._reach_target.value = tuple(target.tolist())
    answer = view.reach_to(view._reach_target.value)
    assert answer.ok, answer.reason
    chain = view.model.chain
    tip = np.asarray(chain.Joints[-1].distal_dubins_frame())[:3, 3]
    assert np.abs(tip - target).max() <= 1e-9 * chain.r  # the design's own tip, not the solver's
    assert chain.clearance().ok and view.model.dirty
    assert view._reach_status.content.startswith("reached: tip")
    assert view.act(view._undo).ok and view.model.document is before


def test_a_target_out_of_reach_leaves_the_design_and_says_why(view):
    before = view.model.document
    answer = view.reach_to((1e6, 0.0, 0.0))
    assert not answer.ok and view.model.document is before and not view.model.dirty
    assert view._reach_status.content.startswith("**Cannot reach:** beyond reach")
    assert view.reach_to(("x", 1, 2)) is None and "three finite numbers" in view.message


def test_a_handle_drag_previews_and_its_end_is_one_command(view):
    before = view.model.document
    view.show_target(True)
    assert view._target_handle.visible
    _, first = _clear_tip(view.model.chain, seed=2)
    answer = view.reach_to(first, preview=True)
    assert answer.ok and view.model.base_document is before and not view.model.dirty
    shown = np.asarray(view.model.chain.Joints[-1].distal_dubins_frame())[:3, 3]
    assert np.abs(shown - first).max() <= 1e-9 * view.model.chain.r
    assert view.reach_to(first).ok and view.model.dirty and len(view.model._undo) == 1


def test_a_tree_target_is_for_the_selected_leaf(tmp_path):
    server = EditorServer(HAND, port=0, autosave=False)
    try:
        view = server.new_view(server.server)
        hand = view.model.chain
        leaves = [k for k in range(len(hand.Joints)) if k not in set(hand.Parents)]
        view.model.select(leaves[1])
        assert view.reach_tip() == leaves[1]
        compiled = kinematics(hand, leaves[1])
        q, _ = _clear_tip(hand, seed=4)
        target = compiled.fkine(q)[:3, 3]
        answer = view.reach_to(target)
        assert answer.ok, answer.reason
        tip = np.asarray(view.model.chain.Joints[leaves[1]].distal_dubins_frame())[:3, 3]
        assert np.abs(tip - target).max() <= 1e-9 * hand.r
        view.close()
    finally:
        server.stop()


def test_the_workspace_cloud_is_sampled_in_the_background(view):
    before = view.model.document
    job = view.show_workspace(samples=2_000)
    assert job is not None and job.finished.wait(LIVE) and job.outcome == "done"
    points = view.workspace_points
    assert points.ndim == 2 and points.shape[1] == 3 and 100 < points.shape[0] < 2_000
    assert view._workspace_cloud is not None and view._hide_space.visible
    assert view.model.document is before  # nothing changes in the design
    view.hide_workspace()
    assert view._workspace_cloud is None and not view._hide_space.visible
