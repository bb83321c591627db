"""Bounds of design files, numeric safety (no RuntimeWarning, no overflow) and file reading."""

from __future__ import annotations

import copy
import json
import math
import os
import sys
import warnings

import numpy as np
import pytest
from hypothesis import HealthCheck, given, settings
from hypothesis import strategies as st

from kinegami import ClearanceWarning
from kinegami.design import (
    DesignError,
    chain_from_dict,
    design_schema,
    limits,
    load_design,
    loads_design,
    pose_from_json,
    read_design,
    validate_design,
)

from . import DATA

BASE = json.loads((DATA / "example1a.json").read_text(encoding="utf-8"))
ROTATION = [[0, -1, 0], [1, 0, 0], [0, 0, 1]]


def _mutated(change, base=BASE) -> dict:
    document = copy.deepcopy(base)
    change(document)
    return document


def _error(document, check=chain_from_dict) -> DesignError:
    """The DesignError of ``document``; no warning of any kind may be emitted on the way."""
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        np_settings = np.geterr()
        with pytest.raises(DesignError) as info:
            check(document, "d.json")
        assert np.geterr() == np_settings  # numpy's error state is restored
    error = info.value
    assert "\n" not in str(error) and error.file == "d.json"
    return error


def _loads_quietly(document):
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        return chain_from_dict(document)


def _validate_dict(document, file=None) -> None:
    from kinegami.design import check_document

    check_document(document, file)


def _dh(**options) -> dict:
    dh = {"rows": [[0, 0, 4, 0], [0, 0, 4, 0]], "placement": "safe", **options}
    return {"format": "kinegami-design", "version": 1, "numSides": 4, "r": 1, "dh": dh}


# --- the bounds as constants, in the schema and in the messages ------------------------------
def test_schema_states_the_bounds_of_limits():
    schema = design_schema()
    defs = schema["$defs"]
    assert schema["properties"]["numSides"]["maximum"] == limits.NUM_SIDES_MAX == 64
    assert defs["numSinkLayers"]["maximum"] == limits.NUM_SINK_LAYERS_MAX == 32
    assert defs["numLayers"]["maximum"] == limits.NUM_LAYERS_MAX == 200
    assert schema["properties"]["r"]["minimum"] == limits.R_MIN == 1e-6
    assert schema["properties"]["r"]["maximum"] == limits.R_MAX == 1e6
    assert defs["length"]["maximum"] == limits.LENGTH_FACTOR * limits.R_MAX
    assert defs["coordinate"]["minimum"] == -limits.LENGTH_FACTOR * limits.R_MAX
    rad = defs["angleRangesRad"]["properties"]["maxAnglePerElbow"]["minimum"]
    assert rad == limits.MIN_ANGLE_PER_ELBOW == math.pi / 180
    assert defs["angleRangesDeg"]["properties"]["maxAnglePerElbow"]["minimum"] == 1
    assert limits.MAX_FILE_BYTES == 16 * 2**20


def _joint(i, key, value):
    return lambda d: d["joints"][i].update({key: value})


# (document, field, value, fragment of the reason)
OUT_OF_BOUNDS = {
    "numSides 10**30": (
        _mutated(lambda d: d.update(numSides=10**30)),
        "numSides",
        10**30,
        "even integer in [4, 64]",
    ),
    "numSides 66": (_mutated(lambda d: d.update(numSides=66)), "numSides", 66, "[4, 64]"),
    "numSinkLayers 33": (
        _mutated(_joint(2, "numSinkLayers", 33)),
        "joints[2].numSinkLayers",
        33,
        "an integer in [1, 32]",
    ),
    "numSinkLayers 100000": (
        _mutated(_joint(2, "numSinkLayers", 100000)),
        "joints[2].numSinkLayers",
        100000,
        "[1, 32]",
    ),
    "numLayers 1e6": (
        _mutated(_joint(1, "numLayers", 1000000)),
        "joints[1].numLayers",
        1000000,
        "an integer in [1, 200]",
    ),
    "numLayers 201": (_mutated(_joint(1, "numLayers", 201)), "joints[1].numLayers", 201, "200"),
    "dh numSinkLayers": (_dh(numSinkLayers=1000), "dh.numSinkLayers", 1000, "[1, 32]"),
    "dh numLayers": (_dh(numLayers=1000, jointTypes="RP"), "dh.numLayers", 1000, "[1, 200]"),
    "r 1e-300": (_mutated(lambda d: d.update(r=1e-300)), "r", 1e-300, "in [1e-6, 1e6]"),
    "r 2e6": (_mutated(lambda d: d.update(r=2e6)), "r", 2e6, "in [1e-6, 1e6]"),
    "maxAnglePerElbow 1e-4 rad": (
        _mutated(lambda d: d.update(maxAnglePerElbow=1e-4)),
        "maxAnglePerElbow",
        1e-4,
        "[pi/180, pi] radians",
    ),
    "maxAnglePerElbow 0.5 deg": (
        _mutated(
            lambda d: (
                d.update(angleUnits="deg", maxAnglePerElbow=0.5)
                or d["joints"][1].update(coneAngle=45)
                or d["joints"][2].update(totalBendingAngle=180, pose=[{"Ry": 45}])
            )
        ),
        "maxAnglePerElbow",
        0.5,
        "[1, 180] degrees",
    ),
    "dh a = 1e200": (
        {**_dh(), "dh": {"rows": [[0, 0, 1e200, 0], [0, 1.57, 1, 0]]}},
        "dh.rows[0][2]",
        1e200,
        "within +-1e6 r",
    ),
    "edit translating by 1e300": (
        _mutated(lambda d: d.update(edits=[{"op": "transformAll", "transform": [{"Tx": 1e300}]}])),
        "edits[0].transform[0].Tx",
        1e300,
        "within +-1e6 r",
    ),
    "edit distance 1e300": (
        _mutated(
            lambda d: d.update(
                edits=[{"op": "translateJointAlongAxisOfMotion", "joint": 2, "distance": 1e300}]
            )
        ),
        "edits[0].distance",
        1e300,
        "within +-1e6 r",
    ),
    "point 1e300": (
        _mutated(_joint(1, "pose", {"point": [0, 1e300, 0], "axis": [0, 0, 1]})),
        "joints[1].pose.point[1]",
        1e300,
        "within +-1e6 r",
    ),
    "length 1e13": (_mutated(_joint(0, "length", 1e13)), "joints[0].length", 1e13, "<= 1e6 r"),
}


@pytest.mark.parametrize("case", list(OUT_OF_BOUNDS))
def test_values_beyond_the_bounds_are_rejected_before_building(case, monkeypatch):
    document, field, value, fragment = OUT_OF_BOUNDS[case]
    import kinegami.chain

    def refuse(*args, **kwargs):
        raise AssertionError("nothing may be built")

    monkeypatch.setattr(kinegami.chain.KinematicChain, "__init__", refuse)
    error = _error(document, _validate_dict)
    assert (error.field, error.value) == (field, value)
    assert fragment in error.reason, str(error)
    assert "out of range" in error.reason or "must be" in error.reason


def test_the_bounds_themselves_are_accepted():
    document = _mutated(lambda d: d.update(numSides=64, r=1e6))
    document["joints"][1]["numLayers"] = 200
    document["joints"][2]["numSinkLayers"] = 32
    _validate_dict(document)
    tiny = _dh()
    tiny["r"] = 1e-6
    tiny["dh"]["rows"] = [[0, 0, 4e-6, 0], [0, 0, 4e-6, 1]]
    _validate_dict(tiny)
    _validate_dict(_mutated(lambda d: d.update(maxAnglePerElbow=math.pi / 180)))
    _validate_dict(_dh(numSinkLayers=32, numLayers=200, jointTypes="RP"))


# Places of lengths and translation coordinates: (change with value v, field)
LENGTH_PLACES = {
    "tip length": (lambda v: _joint(0, "length", abs(v)), "joints[0].length"),
    "neutralLength": (lambda v: _joint(1, "neutralLength", abs(v)), "joints[1].neutralLength"),
    "tubeLength": (
        lambda v: (
            lambda d: d["joints"].insert(
                3, {"type": "ExtendedRevoluteJoint", "totalBendingAngle": 1, "tubeLength": abs(v)}
            )
        ),
        "joints[3].tubeLength",
    ),
    "Trans": (lambda v: _joint(1, "pose", [{"Trans": [0, v, 0]}]), "joints[1].pose[0].Trans[1]"),
    "Tz": (lambda v: _joint(2, "pose", [{"Ry": 1}, {"Tz": v}]), "joints[2].pose[1].Tz"),
    "matrix": (
        lambda v: _joint(
            1,
            "pose",
            [[*row, t] for row, t in zip(ROTATION, (0, 0, v), strict=True)] + [[0] * 3 + [1]],
        ),
        "joints[1].pose[2][3]",
    ),
    "axis point": (
        lambda v: _joint(1, "pose", {"point": [v, 0, 0], "axis": [0, 0, 1]}),
        "joints[1].pose.point[0]",
    ),
    "edit distance": (
        lambda v: (
            lambda d: d.update(
                edits=[{"op": "translateJointAlongAxisOfMotion", "joint": 2, "distance": v}]
            )
        ),
        "edits[0].distance",
    ),
    "edit transform": (
        lambda v: (
            lambda d: d.update(
                edits=[{"op": "transformJoint", "joint": 1, "transform": [{"Trans": [v, 0, 0]}]}]
            )
        ),
        "edits[0].transform[0].Trans[0]",
    ),
}


@pytest.mark.parametrize("place", list(LENGTH_PLACES))
@pytest.mark.parametrize("r", [1.0, 0.001])
def test_lengths_are_bounded_relative_to_r(place, r):
    make, field = LENGTH_PLACES[place]
    beyond = -2e6 * r
    document = _mutated(make(beyond))
    document["r"] = r
    error = _error(document, _validate_dict)
    assert error.field == field
    assert error.value == abs(beyond) or error.value == beyond
    assert f"= {1e6 * r:g} (r = {r:g})" in error.reason, str(error)
    assert error.reason.startswith("out of range: lengths and translation coordinates must be")
    within = _mutated(make(-0.5e6 * r))
    within["r"] = r
    _validate_dict(within)  # at the bound's scale, but inside it


@pytest.mark.parametrize(("column", "field"), [(2, "dh.rows[1][2]"), (3, "dh.rows[1][3]")])
def test_dh_lengths_are_bounded_relative_to_r(column, field):
    document = _dh()
    document["r"] = 0.5
    document["dh"]["rows"][1][column] = 6e5
    error = _error(document, _validate_dict)
    assert (error.field, error.value) == (field, 6e5)
    for key in ("neutralLength", "tipLength"):
        error = _error(_dh(**{key: 2e6}), _validate_dict)
        assert error.field == f"dh.{key}" and "> 0 and <= 1e6 r" in error.reason


def test_numSides_10_to_the_30_fails_cleanly_when_loading(tmp_path):
    path = tmp_path / "d.json"
    path.write_text(json.dumps(_mutated(lambda d: d.update(numSides=10**30))), encoding="utf-8")
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        with pytest.raises(DesignError, match=r"numSides: out of range: .*\[4, 64\]"):
            load_design(path)


# --- numeric safety --------------------------------------------------------------------------
def test_huge_axis_is_normalised_without_overflow():
    with warnings.catch_warnings():
        warnings.simplefilter("error")
        T = pose_from_json({"axis": [1e308, 1e308, 0]})
        tiny = pose_from_json({"axis": [0, 5e-324, 0], "xhat": [1e-320, 0, 1e-320]})
    np.testing.assert_allclose(T[:3, 2], [math.sqrt(0.5), math.sqrt(0.5), 0], rtol=0, atol=1e-15)
    np.testing.assert_allclose(T[:3, :3].T @ T[:3, :3], np.eye(3), rtol=0, atol=1e-15)
    np.testing.assert_array_equal(tiny[:3, 2], [0, 1, 0])
    np.testing.assert_allclose(tiny[:3, 0], [math.sqrt(0.5), 0, math.sqrt(0.5)], atol=1e-15)


def test_huge_axis_in_a_design_loads():
    document = _mutated(_joint(1, "pose", {"axis": [1e308, 1e308, 0]}))
    document["joints"][1].update(relative=False, safe=False)
    chain = _loads_quietly(document)
    z = chain.Joints[-5].pose_matrix[:3, 2]  # the axis line is kept (compact placement may flip z)
    assert abs(float(z @ [math.sqrt(0.5), math.sqrt(0.5), 0])) == pytest.approx(1, abs=1e-15)


@settings(max_examples=60, deadline=None)
@given(
    axis=st.lists(st.floats(-10, 10, allow_nan=False), min_size=3, max_size=3).filter(
        lambda v: max(map(abs, v)) > 1e-3
    ),
    xhat=st.lists(st.floats(-10, 10, allow_nan=False), min_size=3, max_size=3),
    power=st.integers(-1000, 1000),
)
def test_axis_scaling_is_exact(axis, xhat, power):
    """Scaling axis and xhat by a power of two gives the same pose bit for bit."""
    spec = {"axis": axis, "xhat": xhat}
    scaled = {"axis": [math.ldexp(v, power) for v in axis]}
    scaled["xhat"] = [math.ldexp(v, power) for v in xhat]
    if not all(math.isfinite(v) for v in scaled["axis"] + scaled["xhat"]):
        return
    if any(v != 0 and math.ldexp(math.ldexp(v, power), -power) != v for v in axis + xhat):
        return  # a subnormal lost bits
    try:
        expected = pose_from_json(spec)
    except DesignError:
        with pytest.raises(DesignError):
            pose_from_json(scaled)
        return
    np.testing.assert_array_equal(pose_from_json(scaled), expected)


def test_huge_rotation_entries_are_not_rigid_without_warnings():
    pose = [[1e300, 0, 0, 0], [0, 1e300, 0, 0], [0, 0, 1, 0], [0, 0, 0, 1]]
    error = _error(_mutated(_joint(1, "pose", pose)), _validate_dict)
    assert error.field == "joints[1].pose"
    assert "orthonormal" in error.reason and "magnitude 1e+300 > 1" in error.reason


def test_a_numeric_error_while_building_names_the_joint(monkeypatch):
    """Should the library ever overflow, the FloatingPointError names the joint being placed."""
    import kinegami.chain

    original = kinegami.chain.KinematicChain.append

    def overflowing(self, joint, **options):
        if type(joint).__name__ == "RevoluteJoint":
            return np.float64(1e308) * 10.0  # would be a RuntimeWarning and inf
        return original(self, joint, **options)

    monkeypatch.setattr(kinegami.chain.KinematicChain, "append", overflowing)
    error = _error(BASE)
    assert error.field == "joints[2]"
    assert "numeric error" in error.reason and "overflow" in error.reason


def test_a_runtime_warning_while_editing_becomes_an_error(monkeypatch):
    import kinegami.chain

    def warning(self, *args, **kwargs):
        warnings.warn("invalid value encountered somewhere", RuntimeWarning, stacklevel=2)
        return True

    monkeypatch.setattr(kinegami.chain.KinematicChain, "delete", warning)
    document = _mutated(lambda d: d.update(edits=[{"op": "delete", "joint": 1}]))
    error = _error(document)
    assert error.field == "edits[0]"
    assert error.reason == "numeric problem: invalid value encountered somewhere"


_MAGNITUDE = st.sampled_from([1e-6, 1e-3, 1.0, 1e3, 1e6])
_FRACTION = st.floats(-1.0, 1.0, allow_nan=False)


@st.composite
def _extreme_designs(draw) -> dict:
    """Designs with lengths and coordinates anywhere within the bounds, of any r."""
    r = draw(_MAGNITUDE)
    reach = 1e6 * r

    def coord():
        return draw(_FRACTION) * reach * draw(st.sampled_from([1e-9, 1e-3, 1.0]))

    def length():
        return max(abs(coord()), 1e-3 * r)

    def pose():
        kind = draw(st.sampled_from(["steps", "axis", "matrix"]))
        if kind == "steps":
            return [{"Trans": [coord(), coord(), coord()]}, {"Ry": draw(_FRACTION) * 1e300}]
        if kind == "axis":
            axis = [draw(_FRACTION) * 1e308 for _ in range(3)]
            return {"point": [coord(), coord(), coord()], "axis": [*axis[:2], 1e-300]}
        return [[*row, t] for row, t in zip(ROTATION, (coord(), coord(), coord()), strict=True)] + [
            [0, 0, 0, 1]
        ]

    joints = [{"type": "StartTip", "length": length(), "pose": pose()}]
    for _ in range(draw(st.integers(1, 3))):
        kind = draw(st.sampled_from(["RevoluteJoint", "PrismaticJoint", "Waypoint"]))
        joint = {"type": kind, "pose": pose(), "relative": draw(st.booleans())}
        if kind == "RevoluteJoint":
            joint.update(totalBendingAngle=draw(st.floats(1e-300, 6.28)), numSinkLayers=1)
        elif kind == "PrismaticJoint":
            joint.update(neutralLength=length(), numLayers=3, coneAngle=0.8)
        joints.append(joint)
    edits = [
        {"op": "translateJointAlongAxisOfMotion", "joint": -1, "distance": coord()},
        {"op": "rotateJointAboutAxisOfMotion", "joint": 1, "angle": draw(_FRACTION) * 1e300},
        {"op": "transformAll", "transform": pose()},
    ]
    return {
        "format": "kinegami-design",
        "version": 1,
        "numSides": draw(st.sampled_from([4, 64])),
        "r": r,
        "joints": joints,
        "edits": draw(st.lists(st.sampled_from(edits), max_size=3)),
    }


@settings(max_examples=40, deadline=None, suppress_health_check=[HealthCheck.too_slow])
@given(document=_extreme_designs())
def test_designs_within_the_bounds_never_warn_or_crash(document):
    """Loading and pattern-checking any in-bounds design gives a chain or a DesignError."""
    from kinegami.design import check_pattern

    with warnings.catch_warnings():
        warnings.simplefilter("error")
        # a design that passes through itself is reported, not a crash
        warnings.simplefilter("ignore", ClearanceWarning)
        try:
            chain = chain_from_dict(document)
            check_pattern(chain)
        except DesignError as error:
            assert "\n" not in str(error)


# --- file reading ------------------------------------------------------------------------------
def test_a_directory_is_refused(tmp_path):
    with pytest.raises(DesignError) as info:
        validate_design(tmp_path)
    assert info.value.reason == "cannot read the design file: it is a directory, not a regular file"
    assert info.value.file == str(tmp_path)


@pytest.mark.skipif(not os.path.exists("/dev/zero"), reason="needs /dev/zero")
def test_a_device_is_refused_without_reading():
    with pytest.raises(DesignError) as info:
        validate_design("/dev/zero")
    assert str(info.value) == (
        "/dev/zero: cannot read the design file: it is a character device, not a regular file"
    )


@pytest.mark.skipif(not hasattr(os, "mkfifo"), reason="needs FIFOs")
def test_a_fifo_without_writer_is_refused_without_blocking(tmp_path):
    fifo = tmp_path / "pipe.json"
    os.mkfifo(fifo)
    with pytest.raises(DesignError, match="it is a FIFO \\(named pipe\\), not a regular file"):
        read_design(fifo)


def test_a_file_over_16_mib_is_refused(tmp_path):
    path = tmp_path / "big.json"
    with open(path, "wb") as stream:  # sparse: no disk space used
        stream.truncate(limits.MAX_FILE_BYTES + 1)
    with pytest.raises(DesignError) as info:
        load_design(path)
    assert info.value.reason == (
        f"the design file is too large ({limits.MAX_FILE_BYTES + 1} bytes); "
        f"design files are at most 16 MiB ({limits.MAX_FILE_BYTES} bytes)"
    )


def test_a_file_of_exactly_16_mib_is_read(tmp_path):
    path = tmp_path / "padded.json"
    text = json.dumps(BASE)
    path.write_bytes(text.encode() + b" " * (limits.MAX_FILE_BYTES - len(text)))
    assert path.stat().st_size == limits.MAX_FILE_BYTES
    assert read_design(path) == BASE


def test_a_file_growing_past_the_cap_while_read_is_refused(tmp_path, monkeypatch):
    """The read itself is capped (the size from stat may be stale or 0 for special files)."""
    import kinegami.design.reader as reader

    path = tmp_path / "d.json"
    path.write_text(json.dumps(BASE), encoding="utf-8")
    real_fstat = os.fstat

    class Small:
        def __init__(self, result):
            self.st_mode = result.st_mode
            self.st_size = 10

    monkeypatch.setattr(reader.os, "fstat", lambda fd: Small(real_fstat(fd)))
    monkeypatch.setattr(reader, "MAX_FILE_BYTES", 100)
    with pytest.raises(DesignError, match=r"too large \(more than design files are at most"):
        read_design(path)


def test_reading_a_missing_file_or_a_bad_name():
    with pytest.raises(DesignError, match="cannot read the design file: No such file"):
        read_design("/nonexistent/design.json")
    with pytest.raises(DesignError, match="must be a str or a path"):
        read_design(42)


def test_the_home_folder_is_expanded(tmp_path, monkeypatch):
    monkeypatch.setenv("HOME", str(tmp_path))
    if sys.platform == "win32":
        monkeypatch.setenv("USERPROFILE", str(tmp_path))
    (tmp_path / "d.json").write_text(json.dumps(BASE), encoding="utf-8")
    assert read_design("~/d.json") == BASE
    assert len(loads_design(json.dumps(BASE)).Joints) == 7
