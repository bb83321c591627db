"""Tree tasks in task files (docs/design-for-a-task.md, Task files): ``"joints"`` an array of
joint strings, one per leaf, and ``"targets"`` one array of targets per leaf, all of the same
length. Read as a Task whose targets are one tuple per leaf; every invalid form is one
DesignError line naming the field; a chain task reads as before; a design file carries a tree
task on a tree and refuses it on a chain."""

from __future__ import annotations

import copy
import json
import re
import time
from pathlib import Path

import jsonschema
import numpy as np
import pytest

from kinegami.design import load_design_with_info
from kinegami.design.task import read_task, starter_task, task_from_dict, task_schema
from kinegami.design.writer import design_to_dict, dumps_design
from kinegami.errors import DesignError, InfeasibleTaskError
from kinegami.optimize import design_for
from kinegami.reach import Target

ROOT = Path(__file__).resolve().parents[2]
GRIPPER = ROOT / "examples" / "designs" / "gripper.json"  # a tree

#: A tree task of every target form: two leaves, two grasps (lengths in mm, angles in degrees).
TREE_TASK = {
    "format": "kinegami-task",
    "version": 1,
    "name": "pinch",
    "angleUnits": "deg",
    "numSides": 4,
    "r": 1,
    "joints": ["RRR", "rrp"],
    "targets": [
        [{"name": "A", "position": [-6, 2, 12]}, {"position": [-4, 3, 13], "axis": [0, 0, 2]}],
        [{"pose": [{"Trans": [6, -2, 12]}, {"Rz": 90}]}, {"name": "D", "position": [4, -3, 13]}],
    ],
    "starts": 16,
}  # fmt: skip


def test_a_tree_task_reads_as_one_target_tuple_per_leaf():
    task = task_from_dict(TREE_TASK)
    assert task.is_tree and task.leaves == 2 and task.grasps == 2
    assert task.joints == ("RRR", "rrp")
    assert [[t.kind for t in leaf] for leaf in task.targets] == [["position", "axis"],
                                                                 ["pose", "position"]]
    assert all(isinstance(t, Target) for leaf in task.targets for t in leaf)
    np.testing.assert_allclose(task.targets[0][1].axis, [0, 0, 1])
    np.testing.assert_allclose(task.targets[1][0].rotation, [[0, -1, 0], [1, 0, 0], [0, 0, 1]],
                               atol=1e-15)  # fmt: skip
    assert task.document == TREE_TASK and task.document is not TREE_TASK
    options = task.options()
    assert options["starts"] == 16 and "path" not in options


def test_a_tree_task_is_what_design_for_takes():
    """``design_for(list(task.targets), task.joints, **task.options())`` reads it as a tree
    task: a leaf target beyond the longest tube is proven infeasible for that leaf at once."""
    far = copy.deepcopy(TREE_TASK)
    far["targets"][1][0] = {"position": [0, 0, 500]}
    task = task_from_dict(far)
    start = time.perf_counter()
    with pytest.raises(InfeasibleTaskError, match="leaf 1") as caught:
        design_for(list(task.targets), task.joints, **task.options())
    assert caught.value.proven and time.perf_counter() - start < 5.0


def test_a_chain_task_reads_as_before():
    task = task_from_dict(starter_task())
    assert not task.is_tree and task.leaves == 1 and task.grasps == 4
    assert task.joints == "RRRR" and len(task.targets) == 4
    assert all(isinstance(t, Target) for t in task.targets)
    budget = task_from_dict({**starter_task(), "joints": 3, "path": True})
    assert budget.joints == 3 and budget.options()["path"] is True


def test_the_starter_tree_task_is_valid_against_the_schema(tmp_path):
    document = starter_task(tree=True)
    jsonschema.Draft202012Validator(task_schema()).validate(document)
    path = tmp_path / "hand.json"
    path.write_text(dumps_design(document), "utf-8")
    task = read_task(path)
    assert task.is_tree and task.leaves == 2 and task.grasps == 2 and task.r == 10


@pytest.mark.parametrize(
    ("change", "field", "words"),
    [
        ({"targets": TREE_TASK["targets"][:1]}, "targets", ("one array of targets per leaf",
                                                            "2 leaves")),
        ({"targets": [TREE_TASK["targets"][0], TREE_TASK["targets"][1][:1]]}, "targets[1]",
         ("same number of targets", "targets[0] has 2, targets[1] has 1")),
        ({"joints": ["RRR", 3]}, "joints[1]", ("joint string",)),
        ({"joints": ["RRR", "RXR"]}, "joints[1]", ("letters R and P",)),
        ({"joints": []}, "joints", ("at least 1",)),
        ({"path": True}, "path", ("for chains",)),
        ({"targets": [{"position": [1, 2, 3]}, {"position": [1, 2, 3]}]}, "targets[0]",
         ("one array of targets per leaf",)),
        ({"targets": [[{"position": [1, 2]}], [{"position": [1, 2, 3]}]]},
         "targets[0][0].position", ("3 numbers",)),
        ({"targets": [[{"position": [1, 2, 3], "axis": [0, 0, 0]}], [{"position": [1, 2, 3]}]]},
         "targets[0][0]", ("axis",)),
        ({"targets": [[], []]}, "targets[0]", ("at least 1",)),
        ({"joints": "RRR"}, "targets[0]", ("tree task", "joints")),
    ],
)  # fmt: skip
def test_every_invalid_tree_task_is_one_line_naming_the_field(change, field, words):
    with pytest.raises(DesignError) as caught:
        task_from_dict({**TREE_TASK, **change}, "hand.json")
    message = str(caught.value)
    assert "\n" not in message
    assert message.startswith(f"hand.json: {field}: "), message
    for word in words:
        assert word in message, (word, message)


def test_at_most_64_targets_in_all():
    leaf = [{"position": [1, 2, 3]}] * 33
    with pytest.raises(DesignError, match=r"targets: a task names at most 64 targets in all"):
        task_from_dict({**TREE_TASK, "targets": [leaf, leaf]})


def test_a_tree_design_carries_its_tree_task(tmp_path):
    tree, _ = load_design_with_info(GRIPPER)
    path = tmp_path / "gripper.json"
    path.write_text(dumps_design(design_to_dict(tree, task=TREE_TASK)), "utf-8")
    loaded, info = load_design_with_info(path)
    assert info.structure == "tree" and info.task == TREE_TASK
    assert len(loaded.Joints) == len(tree.Joints)


def test_a_chain_design_refuses_a_tree_task(tmp_path):
    chain, _ = load_design_with_info(ROOT / "examples" / "designs" / "example1.json")
    path = tmp_path / "arm.json"
    path.write_text(dumps_design(design_to_dict(chain, task=TREE_TASK)), "utf-8")
    with pytest.raises(DesignError, match=r"task\.joints: a tree task .* this design is a chain"):
        load_design_with_info(path)


def test_the_json_examples_of_the_task_page_read_as_tasks():
    """docs/design-for-a-task.md: its chain and tree task files read as tasks."""
    page = (ROOT / "docs" / "design-for-a-task.md").read_text(encoding="utf-8")
    blocks = re.findall(r"^```json\n(.*?)^```", page, re.S | re.M)
    tasks = [task_from_dict(json.loads(block)) for block in blocks]
    assert [task.is_tree for task in tasks] == [False, True]
    assert tasks[1].document == {key: value for key, value in starter_task(tree=True).items()
                                 if key in tasks[1].document}  # fmt: skip
