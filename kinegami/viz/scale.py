"""Units and scale bars of the pictures: what the axes' lengths are measured in.

A chain, tree or crease pattern does not know its unit: its lengths are in the unit of its tube
radius r, whatever the user meant by it. A design file says it (``units``, see
docs/design-format.md), so whoever loaded the design passes it to ``show(units=...)``; without
it the pictures say ``units of r``.
"""

from __future__ import annotations

import math

from kinegami.errors import InvalidParameterError

__all__ = ["UNKNOWN_UNIT", "check_units", "unit_text", "length_text", "nice_length"]

#: What the pictures call the unit of a chain drawn without ``units``.
UNKNOWN_UNIT = "units of r"


def check_units(units: object) -> str | None:
    """The ``units`` option of the drawing functions: None or one of the design units."""
    from kinegami.design.reader import UNITS

    if units is None or (isinstance(units, str) and units in UNITS):
        return units
    raise InvalidParameterError(
        f"units must be None (lengths in units of r) or one of {', '.join(map(repr, UNITS))}, "
        f"got {units!r}"
    )


def unit_text(units: str | None) -> str:
    """The unit for an axis label: ``"mm"``, or ``"units of r"`` when ``units`` is None."""
    return UNKNOWN_UNIT if units is None else units


def length_text(length: float, units: str | None) -> str:
    """A length with its unit for a scale bar: ``"20 mm"``, ``"2 (units of r)"``."""
    return f"{length:g} {units}" if units is not None else f"{length:g} ({UNKNOWN_UNIT})"


def nice_length(limit: float) -> float:
    """The largest 1, 2 or 5 times a power of ten not above ``limit`` (> 0): a scale bar's
    length."""
    if not math.isfinite(limit) or limit <= 0.0:
        raise InvalidParameterError(f"limit must be a positive finite length, got {limit!r}")
    power = 10.0 ** math.floor(math.log10(limit))
    for step in (5.0, 2.0, 1.0):
        if step * power <= limit * (1.0 + 1e-12):
            return step * power
    return power  # pragma: no cover - step 1 always fits
