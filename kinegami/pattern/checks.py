"""Parameter checks used only by the pattern catalog (shared ones: kinegami.validation)."""

from __future__ import annotations

import math

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.validation import check_nonnegative, check_real


def check_bool(name: str, value) -> bool:
    """A Python or numpy boolean."""
    if not isinstance(value, bool | np.bool_):
        raise InvalidTypeError(f"{name} must be a bool, got {value!r}")
    return bool(value)


def real(name: str, value) -> float:
    """:func:`kinegami.validation.check_real`, with a fast path for a finite Python float."""
    if type(value) is float and math.isfinite(value):
        return value
    return check_real(name, value)


def nonnegative(name: str, value) -> float:
    """:func:`kinegami.validation.check_nonnegative`, fast for a finite Python float >= 0."""
    if type(value) is float and value >= 0.0 and math.isfinite(value):
        return value
    return check_nonnegative(name, value)


def check_at_least(name: str, value: float, minimum: float, range_text: str) -> float:
    """Raise unless ``value >= minimum``; ``range_text`` describes the valid range."""
    if not value >= minimum:
        raise InvalidParameterError(f"{name} must be {range_text}, got {value!r}")
    return value
