"""A task file's "baseRegion" (issue 32: a region the base may sit in): read into the Task and
its design_for options, refused with one line naming the field when malformed or on a tree."""

from __future__ import annotations

import pytest

from kinegami.clearance.keep_out import Box
from kinegami.design import DesignError
from kinegami.design.task import starter_task, task_from_dict


def test_a_base_region_is_read_into_the_options():
    document = starter_task()
    document["baseRegion"] = {"min": [-10, -10, 0], "max": [10, 10, 5]}
    task = task_from_dict(document)
    assert task.base_region == Box((-10.0, -10.0, 0.0), (10.0, 10.0, 5.0))
    assert task.options()["base_region"] == task.base_region
    assert "base_region" not in task_from_dict(starter_task()).options()


@pytest.mark.parametrize("region, message", [
    ({"min": [0, 0, 0], "max": [-1, 1, 1]}, "baseRegion: baseRegion min .* must be <= max"),
    ({"min": [0, 0, 0]}, "baseRegion"),
    ([0, 0, 0], "baseRegion"),
])  # fmt: skip
def test_a_malformed_base_region_is_one_line_naming_the_field(region, message):
    document = starter_task()
    document["baseRegion"] = region
    with pytest.raises(DesignError, match=message) as caught:
        task_from_dict(document)
    assert "\n" not in str(caught.value)


def test_a_tree_task_refuses_a_base_region():
    document = starter_task(tree=True)
    document["baseRegion"] = {"min": [0, 0, 0], "max": [1, 1, 1]}
    with pytest.raises(DesignError, match=r"baseRegion: is for chains"):
        task_from_dict(document)
