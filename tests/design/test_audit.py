"""audit_design: every problem of a design file, not only the first (kinegami validate)."""

from __future__ import annotations

import copy
import json
import subprocess
import sys
from pathlib import Path

import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kinegami.design import DesignError, audit_design, check_document, validate_design

ROOT = Path(__file__).resolve().parents[2]
GALLERY = sorted((ROOT / "examples" / "designs").glob("*.json"))

#: A chain whose joints hold two problems the schema finds (a range in joint 1, a length in
#: joint 2).
TWO_PROBLEMS = {
    "format": "kinegami-design",
    "version": 1,
    "numSides": 4,
    "r": 1,
    "joints": [
        {"type": "StartTip", "name": "a", "length": 1.5, "pose": [{"Trans": [0, 0, 0]}]},
        {"type": "RevoluteJoint", "name": "b", "numSinkLayers": 40, "totalBendingAngle": 3.1,
         "pose": [{"Trans": [5, 0, 0]}]},
        {"type": "PrismaticJoint", "name": "c", "neutralLength": -2, "numLayers": 3,
         "coneAngle": 0.7, "pose": [{"Trans": [9, 0, 0]}]},
        {"type": "EndTip", "length": 1.5, "pose": [{"Trans": [14, 0, 0]}]},
    ],
}


def _write(path: Path, document) -> Path:
    path.write_text(json.dumps(document))
    return path


def _first_error(path: Path) -> str:
    with pytest.raises(DesignError) as caught:
        validate_design(path)
    return str(caught.value)


@pytest.mark.parametrize("design", GALLERY, ids=lambda p: p.stem)
def test_the_gallery_has_no_problem(design):
    report = audit_design(design)
    assert report.ok and report.problems == ()
    assert str(report) == f"{design}: valid"


def test_every_schema_problem_is_listed_and_the_first_is_validate_designs(tmp_path):
    path = _write(tmp_path / "bad.json", TWO_PROBLEMS)
    report = audit_design(path)
    assert not report.ok
    fields = [problem.field for problem in report.problems]
    assert fields == ["joints[1].numSinkLayers", "joints[2].neutralLength"]
    assert {problem.code for problem in report.problems} <= {"schema", "design"}
    assert str(report.problems[0]) == _first_error(path)
    assert str(report).splitlines()[0] == f"{path}: 2 problems"


def test_checks_beyond_the_schema_are_listed_together(tmp_path):
    document = copy.deepcopy(TWO_PROBLEMS)
    document["joints"][1]["numSinkLayers"] = 2
    document["joints"][2]["neutralLength"] = 3
    document["joints"][2]["name"] = "a"  # a name used twice
    document["joints"].insert(2, {"type": "EndTip", "length": 1.5,
                                  "pose": [{"Trans": [7, 0, 0]}]})  # fmt: skip
    path = _write(tmp_path / "bad.json", document)
    report = audit_design(path)
    assert [(p.code, p.field) for p in report.problems] == [
        ("names", "joints[3].name"), ("joint-order", "joints[2].type")]
    assert "named 'a'" in str(report.problems[0]) and "EndTip" in str(report.problems[1])
    assert str(report.problems[0]) == _first_error(path)


def test_an_unreadable_file_is_one_problem(tmp_path):
    path = tmp_path / "bad.json"
    path.write_text("{ not json")
    report = audit_design(path)
    assert [problem.code for problem in report.problems] == ["file"]
    assert str(report.problems[0]) == _first_error(path)
    assert [p.code for p in audit_design(tmp_path / "missing.json").problems] == ["file"]


def test_kinegami_validate_prints_every_problem_one_line_each(tmp_path):
    path = _write(tmp_path / "bad.json", TWO_PROBLEMS)
    result = subprocess.run([sys.executable, "-m", "kinegami", "validate", str(path)],
                            capture_output=True, text=True)  # fmt: skip
    assert result.returncode == 1
    assert "Traceback" not in result.stderr
    lines = result.stderr.strip().splitlines()
    assert len(lines) == 2
    assert all(line.startswith("kinegami validate: error: ") for line in lines)
    assert "joints[1].numSinkLayers" in lines[0] and "joints[2].neutralLength" in lines[1]
    assert result.stdout == ""


#: Values that break a field: wrong types, out of range, unknown names.
BAD_VALUES = st.sampled_from([-1, 0, 1e9, "x", None, [], {}, 1.5, 40, True, "Bogus"])


@settings(max_examples=150, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(data=st.data())
def test_audit_agrees_with_check_document(data):
    """For designs with a few fields broken at random: no problem exactly when
    check_document passes, and then the first problem is the error it raises."""
    document = json.loads(GALLERY[[p.stem for p in GALLERY].index("example1")].read_text())
    for _ in range(data.draw(st.integers(1, 3))):
        joint = data.draw(st.integers(0, len(document["joints"]) - 1))
        spec = document["joints"][joint]
        key = data.draw(st.sampled_from(sorted(spec) + ["numSinkLayers", "extra"]))
        spec[key] = data.draw(BAD_VALUES)
    from kinegami.design.reader import audit_document

    problems = audit_document(document, "d.json")
    try:
        check_document(document, "d.json")
    except DesignError as error:
        assert problems and str(problems[0]) == str(error)
        assert len({str(p) for p in problems}) == len(problems)  # each problem once
    else:
        assert problems == []
