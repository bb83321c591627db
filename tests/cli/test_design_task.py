"""``kinegami new --task`` and ``kinegami design`` (issue 32), run as subprocesses: the starter
task designs a robot whose design file carries its task and reaches every target (checked by
kinegami.reach.solve on the loaded file); the report and picture; exit codes 0, 3 (infeasible,
the certificate printed), 1 (a task or option error: one line, nothing written), 2 (usage);
``kinegami compact`` keeps the task. Also the task file's reader."""

from __future__ import annotations

import json

import numpy as np
import pytest

from kinegami.design import load_design_with_info
from kinegami.design.task import read_task, starter_task, task_from_dict
from kinegami.errors import DesignError
from kinegami.optimize import tube_length
from kinegami.reach import kinematics, solve

from .helpers import assert_clean_failure, run, write


@pytest.fixture(scope="module")
def designed(tmp_path_factory):
    """The starter task written by ``kinegami new --task`` and designed into out/."""
    folder = tmp_path_factory.mktemp("task")
    made = run("new", "--task", folder / "arm.json")
    assert made.returncode == 0, made.stderr
    result = run("design", folder / "arm.json", "-o", folder / "out")
    return folder, made, result


def test_new_task_writes_the_starter_task(designed):
    folder, made, _ = designed
    assert "kinegami design" in made.stdout
    assert json.loads((folder / "arm.json").read_text()) == starter_task()
    again = run("new", "--task", folder / "arm.json")
    assert_clean_failure(again, "exists already", "--force")


def test_design_writes_a_design_that_reaches_every_target(designed):
    folder, _, result = designed
    assert result.returncode == 0, result.stderr
    out = folder / "out"
    names = {p.name for p in out.iterdir()}
    assert {"arm.json", "arm.dxf", "arm.svg", "arm_task.txt", "arm_task.json",
            "arm_task.png"} <= names  # fmt: skip
    chain, info = load_design_with_info(out / "arm.json")
    task = read_task(folder / "arm.json")
    assert info.task == task.document  # the design carries its task
    report = json.loads((out / "arm_task.json").read_text())
    assert report["format"] == "kinegami-task-report" and len(report["targets"]) == 4
    for k, target in enumerate(task.targets):
        answer = solve(chain, target)  # from the loaded file, not the search's numbers
        assert answer.ok, answer.reason
        assert report["targets"][k]["ok"] and report["targets"][k]["position_error"] <= 1e-9 * 10
    assert report["tube_length"] == pytest.approx(tube_length(chain), rel=1e-12)
    assert "target 3 (D): reached" in result.stdout
    assert (out / "arm_task.png").read_bytes()[:8] == b"\x89PNG\r\n\x1a\n"


def test_compact_keeps_the_task(designed):
    folder, _, _ = designed
    result = run("compact", folder / "out" / "arm.json", "-o", folder / "compacted.json")
    assert result.returncode == 0, result.stderr
    assert "task kept" in result.stdout
    chain, info = load_design_with_info(folder / "compacted.json")
    before, _ = load_design_with_info(folder / "out" / "arm.json")
    assert info.task is not None
    assert tube_length(chain) <= tube_length(before) + 1e-9
    for target in task_from_dict(info.task).targets:
        assert solve(chain, target).ok


def test_an_infeasible_task_exits_3_with_its_certificate(tmp_path):
    task = starter_task()
    task["targets"][1] = {"position": [5000, 0, 100]}
    write(tmp_path / "far.json", task)
    result = run("design", tmp_path / "far.json", "-o", tmp_path / "out")
    assert result.returncode == 3, result
    assert "Traceback" not in result.stderr
    assert "infeasible" in result.stderr and "target 1" in result.stderr
    assert "maxTubeLength" in result.stderr or "max_tube_length" in result.stderr
    assert not (tmp_path / "out").exists()


@pytest.mark.parametrize(
    ("change", "words"),
    [
        ({"format": "kinegami-design"}, ("format", "kinegami-task")),
        ({"joints": "RXR"}, ("joints",)),
        ({"targets": [{"position": [1, 2]}]}, ("targets[0]",)),
        ({"targets": []}, ("targets",)),
        ({"keepOut": [{"min": [0, 0, 0], "max": [1, -1, 1]}]}, ("keepOut[0]", "min")),
        ({"targets": [{"position": [1, 2, 3], "axis": [0, 0, 0]}]}, ("targets[0]", "axis")),
        ({"base": [[1, 0, 0, 0], [0, 2, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]}, ("base",)),
        ({"r": -1}, ("r",)),
    ],
)
def test_task_errors_are_one_line_naming_the_field(tmp_path, change, words):
    task = {**starter_task(), **change}
    write(tmp_path / "bad.json", task)
    result = run("design", tmp_path / "bad.json", "-o", tmp_path / "out")
    assert_clean_failure(result, *words)
    assert not (tmp_path / "out").exists()
    with pytest.raises(DesignError):
        read_task(tmp_path / "bad.json")


def test_usage_errors_exit_2(tmp_path):
    assert run("design").returncode == 2
    assert run("design", tmp_path / "t.json").returncode == 2  # no -o


def test_unreadable_task_files(tmp_path):
    assert_clean_failure(run("design", tmp_path / "missing.json", "-o", tmp_path / "o"),
                         "does not exist")  # fmt: skip
    write(tmp_path / "empty.json", "  ")
    assert_clean_failure(run("design", tmp_path / "empty.json", "-o", tmp_path / "o"), "empty")
    write(tmp_path / "broken.json", "{\"format\": ")
    assert_clean_failure(run("design", tmp_path / "broken.json", "-o", tmp_path / "o"),
                         "invalid JSON", "line 1")  # fmt: skip
    write(tmp_path / "nan.json", json.dumps(starter_task()).replace('"maxTubeLength": 1000',
                                                               '"maxTubeLength": NaN'))
    assert "NaN" in (tmp_path / "nan.json").read_text()
    assert_clean_failure(run("design", tmp_path / "nan.json", "-o", tmp_path / "o"), "NaN")


def test_task_forms_read_as_the_reach_targets():
    task = starter_task()
    task["angleUnits"] = "deg"
    task["targets"] = [
        {"position": [1, 2, 3]},
        {"position": [1, 2, 3], "axis": [0, 0, 2]},
        {"pose": [{"Trans": [1, 2, 3]}, {"Rz": 90}]},
    ]
    task["base"] = [{"Tz": 5}]
    read = task_from_dict(task)
    kinds = [t.kind for t in read.targets]
    assert kinds == ["position", "axis", "pose"]
    np.testing.assert_allclose(read.targets[1].axis, [0, 0, 1])
    np.testing.assert_allclose(read.targets[2].rotation, [[0, -1, 0], [1, 0, 0], [0, 0, 1]],
                               atol=1e-15)  # fmt: skip
    assert read.base[2, 3] == 5
    assert read.options()["keep_out"][0].max == (1000.0, 1000.0, -20.0)


def test_design_of_a_pose_task_reaches_every_pose(tmp_path):
    """A task of three full poses (4x4 matrices in the task file; a hidden 3R arm's tip at
    clear configurations, in mm with r = 10 mm) designed by ``kinegami design``: the design
    file it writes reaches every pose afresh (position to 1e-9 r, orientation to 1e-9), and its
    report says so."""
    from optimize.test_design_for import hidden_3r_arm

    _, poses = hidden_3r_arm(r=10.0)
    task = starter_task()
    task.update(joints="RRR", keepOut=[], name="three poses")
    task["targets"] = [{"name": f"P{k}", "pose": T.tolist()} for k, T in enumerate(poses)]
    write(tmp_path / "poses.json", task)
    result = run("design", tmp_path / "poses.json", "-o", tmp_path / "out")
    assert result.returncode == 0, result.stderr
    chain, _ = load_design_with_info(tmp_path / "out" / "poses.json")
    for T in poses:
        answer = solve(chain, T)
        assert answer.ok, answer.reason
        tip = kinematics(chain).fkine(np.asarray(answer.states))
        assert np.abs(tip[:3, 3] - T[:3, 3]).max() <= 1e-9 * 10
        assert np.abs(tip[:3, :3] - T[:3, :3]).max() <= 1e-9
    report = json.loads((tmp_path / "out" / "poses_task.json").read_text())
    assert [t["ok"] for t in report["targets"]] == [True, True, True]
