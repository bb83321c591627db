"""Parameter checks used only by the pattern catalog (shared ones: kinegami.validation)."""

from __future__ import annotations

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError


def check_bool(name: str, value) -> bool:
    """A Python or numpy boolean."""
    if not isinstance(value, bool | np.bool_):
        raise InvalidTypeError(f"{name} must be a bool, got {value!r}")
    return bool(value)


def check_at_least(name: str, value: float, minimum: float, range_text: str) -> float:
    """Raise unless ``value >= minimum``; ``range_text`` describes the valid range."""
    if not value >= minimum:
        raise InvalidParameterError(f"{name} must be {range_text}, got {value!r}")
    return value
