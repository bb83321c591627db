"""Hostile design files: huge numbers, deep nesting, huge lists, long texts. Each is a one-line
DesignError naming the field (never a ValueError, RecursionError or OverflowError), found fast."""

from __future__ import annotations

import copy
import json
import time
import warnings

import pytest

from kinegami.design import (
    DesignError,
    chain_from_dict,
    limits,
    load_design,
    loads_design,
    validate_design,
)
from kinegami.design.errors import format_value
from kinegami.design.reader import parse_design_text

from . import DATA, located

BASE_TEXT = (DATA / "example1a.json").read_text(encoding="utf-8")
BASE = json.loads(BASE_TEXT)
TEXT = json.dumps(BASE)  # one line: fragments below are replaced in it
LONG = "7" * 5000  # an integer literal too long for int() (more than 4300 digits)


def _error(text_or_document, file="d.json") -> DesignError:
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(DesignError) as info:
            if isinstance(text_or_document, str):
                loads_design(text_or_document, file)
            else:
                chain_from_dict(text_or_document, file)
    error = info.value
    text = str(error)
    assert "\n" not in text and len(text) < 500, text
    assert text.startswith(f"{file}: {located(error)}")
    return error


def _replaced(old: str, new: str) -> str:
    assert old in TEXT, old
    return TEXT.replace(old, new, 1)


def _nested(depth: int, inner: str = "1") -> str:
    return "[" * depth + inner + "]" * depth


# --- numbers -----------------------------------------------------------------------------------
LONG_NUMBERS = {
    "r": ('"r": 1', f'"r": {LONG}', "r"),
    "negative r": ('"r": 1', f'"r": -{LONG}', "r"),
    "version": ('"version": 1', f'"version": {LONG}', "version"),
    "numSides": ('"numSides": 4', f'"numSides": {LONG}', "numSides"),
    "length": ('"length": 1.5', f'"length": {LONG}', "joints[0].length"),
    "Trans": ('"Trans": [5, 5, 0]', f'"Trans": [5, {LONG}, 0]', "joints[1].pose[0].Trans[1]"),
    "numLayers": ('"numLayers": 3', f'"numLayers": {LONG}', "joints[1].numLayers"),
    "name": ('"name": "Example 1A"', f'"name": {LONG}', "name"),
    "unknown key": ('"r": 1', f'"r": 1, "extra": [{LONG}]', "extra[0]"),
}


@pytest.mark.parametrize("case", LONG_NUMBERS)
def test_integer_literals_too_long_for_int_name_their_field(case):
    old, new, field = LONG_NUMBERS[case]
    error = _error(_replaced(old, new))
    assert error.field == field
    assert "5000 digits" in str(error)


@pytest.mark.parametrize(
    "literal, what",
    [("1" * 400, "number too large"), ("-" + "9" * 400, "number too large"),
     ("1" * 5000 + ".5", "finite"), ("1e999", "finite"), ("-1e400", "finite")],
    ids=["400 digits", "-400 digits", "5000-digit float", "1e999", "-1e400"],
)  # fmt: skip
def test_numbers_beyond_the_float_range_name_their_field(literal, what):
    error = _error(_replaced('"length": 1.5', f'"length": {literal}'))
    assert error.field == "joints[0].length" and what in error.reason


def test_python_ints_beyond_the_float_range_in_a_dict():
    document = copy.deepcopy(BASE)
    document["joints"][1]["neutralLength"] = 10**5000
    error = _error(document)
    assert error.field == "joints[1].neutralLength" and "digits" in str(error)


# --- nesting -----------------------------------------------------------------------------------
@pytest.mark.parametrize("depth", [limits.MAX_DEPTH, 500, 980, 990, 1000, 100_000])
@pytest.mark.parametrize(
    "old, prefix",
    [('"r": 1', "r"), ('"name": "Example 1A"', "name"), ('"length": 1.5', "joints[0]")],
    ids=["r", "name", "joints"],
)
def test_deep_nesting_is_a_design_error(depth, old, prefix):
    key = old.split(":")[0]
    error = _error(_replaced(old, f"{key}: {_nested(depth)}"))
    assert error.field.startswith(prefix)
    assert "nested too deeply" in error.reason and str(limits.MAX_DEPTH) in error.reason


@pytest.mark.parametrize("key", ["joints", "edits", "states", "dh"])
def test_deep_nesting_in_a_bulky_field_of_the_wrong_type(key):
    document = {**BASE, key: "PLACE"}
    text = json.dumps(document).replace('"PLACE"', '{"a": ' + _nested(950, "") + "}")
    error = _error(text)
    assert error.field.startswith(key) and "nested too deeply" in error.reason


@pytest.mark.parametrize("depth", [980, 100_000])
def test_deeply_nested_objects(depth):
    inner = '{"a": ' * depth + "1" + "}" * depth
    error = _error(_replaced('"name": "Example 1A"', f'"name": {inner}'))
    assert error.field.startswith("name") and "nested too deeply" in error.reason


def test_nesting_up_to_the_cap_is_checked_as_usual():
    # "name" at level 2 holding lists nested to exactly MAX_DEPTH: only the type is wrong
    error = _error(_replaced('"name": "Example 1A"', f'"name": {_nested(limits.MAX_DEPTH - 1)}'))
    assert error.field == "name" and "must be a string" in error.reason
    error = _error(_replaced('"name": "Example 1A"', f'"name": {_nested(limits.MAX_DEPTH)}'))
    assert "nested too deeply" in error.reason


def test_a_document_containing_itself():
    document = copy.deepcopy(BASE)
    document["joints"][0]["pose"] = [document]
    error = _error(document)
    assert "nested too deeply" in error.reason


def test_design_error_of_a_deep_value_prints():
    deep: list = []
    for _ in range(100_000):
        deep = [deep]
    error = DesignError("must be a number", field="r", value=deep)
    assert str(error).startswith("r: must be a number (got [[[[")
    assert len(str(error)) < 200


@pytest.mark.parametrize(
    "value",
    [10**5000, -(10**400), list(range(10**6)), {str(k): k for k in range(10**5)}, "é" * 10**6],
    ids=["10**5000", "-10**400", "long list", "big dict", "long text"],
)
def test_format_value_is_bounded(value):
    start = time.perf_counter()
    text = format_value(value)
    assert len(text) <= 100 and time.perf_counter() - start < 0.1


# --- sizes -------------------------------------------------------------------------------------
def _with_joints(count: int) -> dict:
    document = copy.deepcopy(BASE)
    waypoint = {"type": "Waypoint", "pose": [{"Trans": [1, 2, 3]}]}
    document["joints"] = [BASE["joints"][0], *[waypoint] * (count - 2), BASE["joints"][-1]]
    return document


CAPS = {
    "joints": (lambda n: _with_joints(n), limits.MAX_JOINTS, "joints", "too many joints"),
    "edits": (
        lambda n: {**BASE, "edits": [{"op": "delete", "joint": 1}] * n},
        limits.MAX_EDITS, "edits", "too many edits",
    ),
    "states": (lambda n: {**BASE, "states": [0] * n}, limits.MAX_STATES, "states",
               "too many states"),
    "dh rows": (
        lambda n: {**{k: v for k, v in BASE.items() if k != "joints"},
                   "dh": {"rows": [[0, 0, 1, 0]] * n}},
        limits.MAX_DH_ROWS, "dh.rows", "too many DH rows",
    ),
    "pose steps": (
        lambda n: {**BASE, "joints": [{**BASE["joints"][0], "pose": [{"Tx": 0}] * n},
                                      *BASE["joints"][1:]]},
        limits.MAX_POSE_STEPS, "joints[0].pose", "too many pose steps",
    ),
}  # fmt: skip


@pytest.mark.parametrize("as_text", [True, False], ids=["text", "dict"])
@pytest.mark.parametrize("case", CAPS)
def test_lists_beyond_their_cap(case, as_text):
    make, cap, field, words = CAPS[case]
    document = make(cap + 1)
    error = _error(json.dumps(document) if as_text else document)
    assert error.field == field and words in error.reason and str(cap) in error.reason


@pytest.mark.parametrize("case", ["joints", "edits", "states", "dh rows"])
def test_lists_at_their_cap_parse(case):
    make, cap, _, _ = CAPS[case]
    parse_design_text(json.dumps(make(cap)))  # no error while parsing


def test_pose_steps_at_their_cap_load():
    make, cap, _, _ = CAPS["pose steps"]
    assert len(chain_from_dict(make(cap))) == 7


def test_the_huge_design_of_the_issue_fails_fast(tmp_path):
    """243,001 joints in 15 MiB (below the file size cap): rejected in well under a second
    (measured 0.1 s, mostly reading the file; was 551 s)."""
    joint = '{"type": "Waypoint", "pose": [{"Trans": [1.25, 2.5, 3.75]}]}, '
    head, tail = TEXT.split('"joints": [', 1)
    text = head + '"joints": [' + joint * 243_000 + tail
    path = tmp_path / "huge.json"
    path.write_text(text, encoding="utf-8")
    assert 14 * 2**20 < path.stat().st_size < limits.MAX_FILE_BYTES
    for check in (validate_design, load_design):
        start = time.perf_counter()
        with pytest.raises(DesignError) as info:
            check(path)
        assert time.perf_counter() - start < 1.0
        assert info.value.field == "joints" and "too many joints" in info.value.reason


def test_cheap_fields_are_checked_before_the_joints():
    document = _with_joints(100_000)
    document["units"] = "furlong"
    start = time.perf_counter()
    error = _error(document)
    assert error.field == "units" and time.perf_counter() - start < 0.5
    document = copy.deepcopy(BASE)
    document["joints"][2]["totalBendingAngle"] = "wide"  # a joint error comes later
    document["r"] = -1
    assert _error(document).field == "r"


# --- long texts are shortened in messages --------------------------------------------------------
LONG_TEXT = "ж" * 10_000
ECHOES = {
    "joint type": lambda d: d["joints"][1].update(type=LONG_TEXT),
    "edit op": lambda d: d.update(edits=[{"op": LONG_TEXT}]),
    "unknown key": lambda d: d.update({LONG_TEXT: 1}),
    "unknown joint key": lambda d: d["joints"][1].update({LONG_TEXT: 1}),
    "duplicate name": lambda d: [d["joints"][k].update(name=LONG_TEXT) for k in (1, 2)],
    "edit joint name": lambda d: d.update(edits=[{"op": "delete", "joint": LONG_TEXT}]),
    "units": lambda d: d.update(units=LONG_TEXT),
}


@pytest.mark.parametrize("case", ECHOES)
def test_long_texts_are_shortened_in_messages(case):
    document = copy.deepcopy(BASE)
    ECHOES[case](document)
    error = _error(document)
    assert "ж" * 70 in str(error) and "ж" * 101 not in str(error)
    assert "..." in str(error)


def test_duplicate_keys_are_found_before_the_rest():
    text = _replaced('"units": "mm"', '"units": "mm", "units": "furlong"')
    error = _error(text)
    assert error.field == "units" and "duplicate key" in error.reason


@pytest.mark.parametrize(
    "text",
    ["", "{", "[", '{"a": 1,}', "[1,]", '{"joints": [1, 2', '{"joints": [1 2]}', "{} x",
     '{"dh": {"rows": [[1]', '{"a" 1}', '\ufeff{}', '{"joints": [1,, 2]}', "nul", '"\\x"'],
)  # fmt: skip
def test_invalid_json_is_reported_like_the_json_module(text):
    with pytest.raises(json.JSONDecodeError) as expected:
        json.loads(text)
    with pytest.raises(DesignError) as info:
        parse_design_text(text)
    reason = info.value.reason
    assert reason.startswith(f"invalid JSON at line {expected.value.lineno}, column ")
    assert expected.value.msg in reason
