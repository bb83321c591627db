"""Checks of user-supplied parameters that raise clear :mod:`kinegami.errors`.

Every check names the parameter, the value received and the valid range, so a user sees
``numSides must be an even integer >= 4, got 5`` rather than a traceback from numpy.
"""

from __future__ import annotations

import math
import numbers

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError


def check_real(name: str, value) -> float:
    """Return ``value`` as a float, or raise if it is not a finite real number."""
    if isinstance(value, bool) or not isinstance(value, numbers.Real | np.floating | np.integer):
        raise InvalidTypeError(f"{name} must be a real number, got {value!r}")
    value = float(value)
    if not math.isfinite(value):
        raise InvalidParameterError(f"{name} must be a finite number, got {value!r}")
    return value


def check_positive(name: str, value) -> float:
    """A finite real number > 0."""
    value = check_real(name, value)
    if value <= 0:
        raise InvalidParameterError(f"{name} must be > 0, got {value!r}")
    return value


def check_nonnegative(name: str, value) -> float:
    """A finite real number >= 0."""
    value = check_real(name, value)
    if value < 0:
        raise InvalidParameterError(f"{name} must be >= 0, got {value!r}")
    return value


def check_in_range(
    name: str,
    value,
    low: float,
    high: float,
    low_inclusive: bool = False,
    high_inclusive: bool = False,
    range_text: str | None = None,
) -> float:
    """A finite real number in the interval between ``low`` and ``high``."""
    value = check_real(name, value)
    above = value >= low if low_inclusive else value > low
    below = value <= high if high_inclusive else value < high
    if not (above and below):
        if range_text is None:
            range_text = (
                f"{'[' if low_inclusive else '('}{low:.6g}, {high:.6g}"
                f"{']' if high_inclusive else ')'}"
            )
        raise InvalidParameterError(f"{name} must lie in {range_text}, got {value!r}")
    return value


def check_int(name: str, value, minimum: int | None = None) -> int:
    """An integer (bools rejected), optionally >= ``minimum``."""
    if isinstance(value, bool) or not isinstance(value, numbers.Integral | np.integer):
        if isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise InvalidTypeError(f"{name} must be an integer, got {value!r}")
    value = int(value)
    if minimum is not None and value < minimum:
        raise InvalidParameterError(f"{name} must be an integer >= {minimum}, got {value}")
    return value


def check_num_sides(value) -> int:
    """The number of polygon sides: an even integer >= 4."""
    try:
        n = check_int("numSides", value)
    except InvalidTypeError:
        raise InvalidTypeError(f"numSides must be an even integer >= 4, got {value!r}") from None
    if n < 4 or n % 2:
        raise InvalidParameterError(f"numSides must be an even integer >= 4, got {n}")
    return n


def check_radius(value, name: str = "r") -> float:
    """The tube radius: finite and > 0."""
    return check_positive(name, value)


def check_max_angle_per_elbow(value) -> float:
    """maxAnglePerElbow in (0, pi]."""
    return check_in_range(
        "maxAnglePerElbow", value, 0.0, math.pi, high_inclusive=True, range_text="(0, pi]"
    )


def check_twist_portion(value) -> float:
    """twistPortion (share of a link's straight part given to its twist) in [0, 1)."""
    return check_in_range("twistPortion", value, 0.0, 1.0, low_inclusive=True, range_text="[0, 1)")
