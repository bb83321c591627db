"""Design for a task with a tree (issue 32, item 5): one target list and one joint string per
leaf, the k-th targets of all leaves reached at once, the result a KinematicTree.

The designed tree is checked as a user would: its answers' states set on a copy (no warning),
every leaf's tip on its target to 1e-9 r, the tree's own clearance report, a fresh solve of
every grasp from the home states, and the tree's sheets."""

from __future__ import annotations

import copy
import time
import warnings

import numpy as np
import pytest

from kinegami import KinematicTree
from kinegami.errors import InfeasibleTaskError, InvalidParameterError, InvalidTypeError
from kinegami.optimize import design_for
from kinegami.reach import solve

#: Two fingers, each touching two points: grasp 0 and grasp 1 (units of r).
LEFT = [(-6.0, 2.0, 12.0), (-4.0, 3.0, 13.0)]
RIGHT = [(6.0, -2.0, 12.0), (4.0, -3.0, 13.0)]


@pytest.fixture(scope="module")
def fingers():
    start = time.perf_counter()
    tree, answers = design_for([LEFT, RIGHT], ["RRR", "RRR"], r=1, numSides=4, starts=16,
                               return_answers=True)  # fmt: skip
    print(f"two-finger tree designed in {time.perf_counter() - start:.1f} s")
    return tree, answers


def leaf_tips(tree: KinematicTree) -> list[int]:
    return [k for k, children in enumerate(tree.Children) if not children]


def test_every_leaf_reaches_its_targets_at_once_clear(fingers):
    tree, answers = fingers
    assert isinstance(tree, KinematicTree)
    tips = leaf_tips(tree)
    assert len(tips) == 2 and len(answers) == 2
    types = [type(j).__name__ for j in tree.Joints]
    assert types[0] == "StartTip" and types.count("RevoluteJoint") == 6
    for k, answer in enumerate(answers):
        assert answer.ok, answer.reason
        posed = copy.copy(tree)
        with warnings.catch_warnings():
            warnings.simplefilter("error")  # no ClearanceWarning, no PlacementWarning
            assert posed.setJointStates(list(answer.states)) is True
        assert posed.clearance().ok
        reached = sorted(posed.Joints[t].DistalDubinsFrame().A[:3, 3].tolist() for t in tips)
        wanted = sorted([list(LEFT[k]), list(RIGHT[k])])
        np.testing.assert_allclose(reached, wanted, rtol=0, atol=1e-9)


def test_a_fresh_solve_of_every_grasp_reaches_it(fingers):
    tree, answers = fingers
    tips = leaf_tips(tree)
    # which leaf took which target list: the one whose tip is on LEFT at grasp 0
    posed = copy.copy(tree)
    posed.setJointStates(list(answers[0].states))
    left = min(tips, key=lambda t: np.linalg.norm(
        posed.Joints[t].DistalDubinsFrame().A[:3, 3] - LEFT[0]))  # fmt: skip
    right = next(t for t in tips if t != left)
    for k in range(2):
        answer = solve(tree, {left: LEFT[k], right: RIGHT[k]}, q0=answers[k].states)
        assert answer.ok, answer.reason


def test_the_tree_builds_its_sheets_as_it_is(fingers):
    """Its junctions already have room (fit_junctions slides nothing): the tree returned is
    the one that is cut, one sheet per leaf."""
    from kinegami.fabrication.sheets import fabricate, fit_junctions

    tree, _ = fingers
    fitted, slides = fit_junctions(tree)
    assert slides == []
    fabrication = fabricate(fitted)
    assert len(fabrication.sheets) == 2
    for sheet in fabrication.sheets:
        assert sheet.pattern.height > 0.0


def test_tree_tasks_refuse_bad_input_with_one_clear_error():
    with pytest.raises(InvalidTypeError, match=r"joints\[1\] must be a string"):
        design_for([LEFT, RIGHT], ["RRR", 3], r=1, numSides=4)
    with pytest.raises(InvalidParameterError, match="one list of targets per leaf"):
        design_for([LEFT], ["RRR", "RRR"], r=1, numSides=4)
    with pytest.raises(InvalidParameterError, match="same number of targets"):
        design_for([LEFT, RIGHT[:1]], ["RRR", "RRR"], r=1, numSides=4)
    with pytest.raises(InvalidParameterError, match="path=True is for chains"):
        design_for([LEFT, RIGHT], ["RRR", "RRR"], r=1, numSides=4, path=True)
    with pytest.raises(InvalidParameterError, match="at least one leaf"):
        design_for([], [], r=1, numSides=4)


def test_a_leaf_target_beyond_the_longest_tube_is_proven_infeasible_fast():
    start = time.perf_counter()
    with pytest.raises(InfeasibleTaskError, match="leaf 1") as caught:
        design_for([LEFT, [(0, 0, 200), (0, 0, 12)]], ["RRR", "RRR"], r=1, numSides=4)
    assert time.perf_counter() - start < 1.0
    assert caught.value.proven and caught.value.target == 0


def test_the_tree_found_is_compacted_keeping_its_task(fingers):
    """design_for compacts the tree it finds with the task kept (compact=True, the default):
    the same search without compaction gives a longer tree, and the compacted one is what
    compact(tree, targets=...) of that tree gives (every grasp checked above)."""
    import concurrent.futures

    from kinegami.optimize import compact_for_task, tube_length

    tree, _ = fingers
    plain, answers = design_for([LEFT, RIGHT], ["RRR", "RRR"], r=1, numSides=4, starts=16,
                                compact=False, return_answers=True)  # fmt: skip
    assert tube_length(tree) < tube_length(plain)
    with concurrent.futures.ThreadPoolExecutor(1) as pool:
        again, _ = compact_for_task(plain, [LEFT, RIGHT], answers, executor=pool)
    assert tube_length(again) == pytest.approx(tube_length(tree), abs=1e-9)
