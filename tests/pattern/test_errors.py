"""Bad input: every catalog function raises a clear KinegamiError that is also a builtin."""

import math

import pytest

from kinegami.errors import InvalidParameterError, InvalidTypeError, KinegamiError
from kinegami.pattern import (
    ElbowFittingPattern,
    EndTipPattern,
    PrismaticJointPattern,
    REBOPattern,
    RevoluteJointPattern,
    StartTipPattern,
    TubeFittingPattern,
    TwistFittingPattern,
    WaypointPattern,
)

NAN, INF = float("nan"), float("inf")

GOOD = {
    TubeFittingPattern: (6, 1.0, 1.0),
    TwistFittingPattern: (6, 1.0, 0.5, 0.5),
    ElbowFittingPattern: (6, 1.0, 1.0, 0.0),
    RevoluteJointPattern: (6, 1.0, math.pi),
    PrismaticJointPattern: (6, 1.0, 1.0, 2, math.pi / 4),
    REBOPattern: (6, 1.0, 1.0, 2, math.pi / 4),
    StartTipPattern: (6, 1.0, 0.5),
    EndTipPattern: (6, 1.0, 0.5),
    WaypointPattern: (6, 1.0),
}


def _call(fn, index, value):
    args = list(GOOD[fn])
    args[index] = value
    return fn(*args)


@pytest.mark.parametrize("fn", list(GOOD))
def test_good_arguments_build(fn):
    assert fn(*GOOD[fn]).validate().ok


@pytest.mark.parametrize("fn", list(GOOD))
@pytest.mark.parametrize("n", [3, 5, 2, 0])
def test_bad_num_sides(fn, n):
    with pytest.raises(
        InvalidParameterError, match=rf"numSides must be an even integer >= 4, got {n}"
    ):
        _call(fn, 0, n)


@pytest.mark.parametrize("fn", list(GOOD))
@pytest.mark.parametrize("n", [1026, 10**30])
def test_too_many_sides(fn, n):
    """Was numpy's 'Maximum allowed size exceeded' (10**30) or minutes of work."""
    with pytest.raises(
        InvalidParameterError, match=r"numSides must be an even integer in \[4, 1024\], got "
    ):
        _call(fn, 0, n)


@pytest.mark.parametrize("fn", list(GOOD))
def test_num_sides_of_wrong_type(fn):
    with pytest.raises(InvalidTypeError, match="numSides"):
        _call(fn, 0, "6")


@pytest.mark.parametrize("fn", list(GOOD))
@pytest.mark.parametrize("r", [0.0, -1.0, NAN, INF])
def test_bad_radius(fn, r):
    with pytest.raises(InvalidParameterError, match="r must"):
        _call(fn, 1, r)


@pytest.mark.parametrize("fn", list(GOOD))
def test_radius_of_wrong_type(fn):
    with pytest.raises(InvalidTypeError, match="r must be a real number"):
        _call(fn, 1, "1")


@pytest.mark.parametrize(
    "fn, index, value, match",
    [
        (TubeFittingPattern, 2, -0.1, r"height must be >= 0, got -0.1"),
        (TubeFittingPattern, 2, NAN, "height must be a finite number"),
        (TwistFittingPattern, 2, INF, "twistAngle must be a finite number"),
        (TwistFittingPattern, 3, -0.5, r"moduleHeight must be >= 0, got -0.5"),
        (ElbowFittingPattern, 2, 0.0, "bendingAngle must satisfy"),
        (ElbowFittingPattern, 2, math.pi, "bendingAngle must satisfy"),
        (ElbowFittingPattern, 2, NAN, "bendingAngle must be a finite number"),
        (ElbowFittingPattern, 3, INF, "rotationalAxisAngle must be a finite number"),
        (RevoluteJointPattern, 2, 0.0, r"totalBendingAngle must lie in \(0, 2 pi\), got 0.0"),
        (RevoluteJointPattern, 2, -1.0, r"totalBendingAngle must lie in \(0, 2 pi\)"),
        (RevoluteJointPattern, 2, 2 * math.pi, r"totalBendingAngle must lie in \(0, 2 pi\)"),
        (StartTipPattern, 2, 0.0, r"length must be > 0, got 0.0"),
        (EndTipPattern, 2, -0.5, r"length must be > 0, got -0.5"),
        (REBOPattern, 2, 0.0, r"neutralLength must be > 0"),
        (REBOPattern, 3, 0, r"numLayers must be an integer >= 1, got 0"),
        (REBOPattern, 4, math.pi / 2, r"coneAngle must lie in \(0, pi/2\)"),
        (PrismaticJointPattern, 2, -1.0, r"neutralLength must be > 0"),
        (PrismaticJointPattern, 3, 0, r"numLayers must be an integer >= 1"),
        (PrismaticJointPattern, 4, 0.4, r"coneAngle must lie in \[pi/6, pi/2\), got 0.4"),
    ],
)
def test_bad_parameter_names_value_and_range(fn, index, value, match):
    with pytest.raises(InvalidParameterError, match=match) as info:
        _call(fn, index, value)
    assert isinstance(info.value, KinegamiError) and isinstance(info.value, ValueError)


def test_bad_num_sink_layers():
    with pytest.raises(InvalidParameterError, match="numSinkLayers must be an integer >= 1"):
        RevoluteJointPattern(6, 1.0, math.pi, 0)
    with pytest.raises(InvalidTypeError, match="numSinkLayers must be an integer"):
        RevoluteJointPattern(6, 1.0, math.pi, 1.5)


def test_bad_proximal_valleys_type():
    with pytest.raises(InvalidTypeError, match="proximalValleys must be a bool"):
        REBOPattern(6, 1.0, 1.0, 2, math.pi / 4, proximalValleys="yes")


@pytest.mark.parametrize("fn, index", [(TubeFittingPattern, 2), (ElbowFittingPattern, 2),
                                       (RevoluteJointPattern, 2), (EndTipPattern, 2)])  # fmt: skip
def test_wrong_type_is_type_error(fn, index):
    with pytest.raises(TypeError):
        _call(fn, index, "1.0")
    with pytest.raises(InvalidTypeError):
        _call(fn, index, None)


def test_zero_height_allowed_for_tube_and_twist_only():
    assert TubeFittingPattern(6, 1.0, 0.0).numEdges == 0
    assert TwistFittingPattern(6, 1.0, 0.5, 0.0).numEdges == 24
    with pytest.raises(InvalidParameterError):
        EndTipPattern(6, 1.0, 0.0)
    with pytest.raises(InvalidParameterError):
        REBOPattern(6, 1.0, 0.0, 1, 1.0)
