"""Checks of user-supplied parameters that raise clear :mod:`kinegami.errors`.

Every check names the parameter, the value received and the valid range, so a user sees
``numSides must be an even integer >= 4, got 5`` rather than a traceback from numpy.

Bounds of the API (the same as those of design files, docs/design-format.md):

* the tube radius r lies in [:data:`R_MIN`, :data:`R_MAX`] = [1e-6, 1e6];
* every length (tip ``length``, ``tubeLength``, ``neutralLength``) lies in (0, 1e6 r] and every
  distance or translation given to the API (``translateJointAlongAxisOfMotion``'s distance,
  the translation of a joint's ``Pose``, of a ``Transformation``, of a link's Dubins poses, DH
  ``a`` and ``d``) within +-1e6 r (:data:`LENGTH_FACTOR`);
* numbers are finite; a Python int beyond the float range is an InvalidParameterError.

Positions the library computes itself (placement, composed DH frames, the result of several
edits) are not re-checked against these bounds: each step stays within them, so nothing
overflows.
"""

from __future__ import annotations

import math
import numbers
from collections.abc import Iterable, Mapping
from types import MappingProxyType
from typing import Any

import numpy as np

from kinegami._format import (  # noqa: F401  (also importable from here, their old home)
    SHOWN_LIMIT,
    format_value,
    shorten,
    shown,
    shown_path,
)
from kinegami.errors import InvalidParameterError, InvalidTypeError, ReadOnlyError

# The bounds themselves live in kinegami.limits (docs/limits.md); they are importable from here
# too, their old home.
from kinegami.limits import (  # noqa: F401
    FILE_NUM_SIDES_MAX,
    LENGTH_FACTOR,
    MAX_API_JOINTS,
    MAX_SAMPLED_STATES,
    MAX_SAMPLES,
    MAX_STARTS,
    MIN_ANGLE_PER_ELBOW,
    NUM_LAYERS_MAX,
    NUM_SIDES_MAX,
    NUM_SINK_LAYERS_MAX,
    R_MAX,
    R_MIN,
)

#: Millimetres per length unit of a design (its ``units``): the one table every layer uses
#: (files, exports, reports, the editor, pictures).
UNITS_IN_MM: Mapping[str, float] = MappingProxyType(
    {"mm": 1.0, "cm": 10.0, "m": 1000.0, "in": 25.4}
)
#: The length units a design may be written in.
LENGTH_UNITS: tuple[str, ...] = tuple(UNITS_IN_MM)


def check_bool(name: str, value, none: bool = False) -> bool | None:
    """``value`` as a bool, or InvalidTypeError unless it is True or False (numpy's too).

    Integers are refused: ``endTip=1`` is more likely a mistake than a choice. With
    ``none=True``, None is accepted too (and returned), e.g. ``block`` of ``show()``.
    """
    if none and value is None:
        return None
    if not isinstance(value, bool | np.bool_):
        allowed = "None, True or False" if none else "True or False"
        raise InvalidTypeError(f"{name} must be {allowed}, got {shown(value)}")
    return bool(value)


def check_options(options: Mapping[str, Any], valid: Iterable[str], what: str) -> None:
    """Raise InvalidTypeError if ``options`` has a name not in ``valid``.

    The message is ``<what> got unknown option(s) 'a', 'b'; valid options are: x, y`` (the
    unknown names sorted, the valid ones in their order), e.g. with ``what="DXF export"``.
    """
    valid = tuple(valid)
    unknown = sorted(set(options) - set(valid))
    if unknown:
        raise InvalidTypeError(
            f"{what} got unknown option{'s' if len(unknown) > 1 else ''} "
            f"{', '.join(map(repr, unknown))}; valid options are: {', '.join(valid)}"
        )


def resolve_options(
    options: Mapping[str, Any], defaults: Mapping[str, Any], what: str
) -> dict[str, Any]:
    """``defaults`` updated by ``options`` (a new dict), after :func:`check_options`."""
    check_options(options, defaults, what)
    values = dict(defaults)
    values.update(options)
    return values


#: Types whose values are real numbers (bool, an int subclass, is refused separately).
REAL_NUMBER_TYPES = (numbers.Real, np.floating, np.integer)


def check_real(name: str, value) -> float:
    """Return ``value`` as a float, or raise if it is not a finite real number."""
    if isinstance(value, bool) or not isinstance(value, REAL_NUMBER_TYPES):
        raise InvalidTypeError(f"{name} must be a real number, got {shown(value)}")
    try:
        value = float(value)
    except OverflowError:  # a Python int (or Fraction) beyond the float range
        raise InvalidParameterError(
            f"{name} must be a finite number (within +-1.8e308), got {shown(value)}"
        ) from None
    if not math.isfinite(value):
        raise InvalidParameterError(f"{name} must be a finite number, got {value!r}")
    return value


def _limit_text(r: float) -> str:
    return f"1e6 r = {LENGTH_FACTOR * r:g} (r = {r:g})"


def check_length(name: str, value, r: float) -> float:
    """A length: a finite real number in (0, LENGTH_FACTOR * r]."""
    value = check_real(name, value)
    if not 0.0 < value <= LENGTH_FACTOR * r:
        raise InvalidParameterError(
            f"{name} must be > 0 and <= {_limit_text(r)}, got {value!r}"
        )
    return value


def check_translation(name: str, value, r: float) -> float:
    """A distance or translation coordinate: a finite real number within +-LENGTH_FACTOR * r."""
    value = check_real(name, value)
    if not abs(value) <= LENGTH_FACTOR * r:
        raise InvalidParameterError(f"{name} must be within +-{_limit_text(r)}, got {value!r}")
    return value


def check_translation_part(name: str, T: np.ndarray, r: float) -> None:
    """The translation column of the 4x4 array ``T`` within +-LENGTH_FACTOR * r."""
    t = T[:3, 3]
    k = int(np.argmax(np.abs(t)))
    if not abs(t[k]) <= LENGTH_FACTOR * r:
        raise InvalidParameterError(
            f"{name} translation must be within +-{_limit_text(r)} in each coordinate, "
            f"got {float(t[k])!r} in {'xyz'[k]}"
        )


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


def check_int(name: str, value, minimum: int | None = None, *, floats: bool = True) -> int:
    """An integer (bools rejected), optionally >= ``minimum``.

    A float with an integral value (``2.0``) is taken as that integer unless ``floats=False``
    (for indices, where a float is more likely a mistake: ``parents`` of a tree).
    """
    if isinstance(value, bool) or not isinstance(value, numbers.Integral | np.integer):
        if floats and isinstance(value, float) and value.is_integer():
            value = int(value)
        else:
            raise InvalidTypeError(f"{name} must be an integer, got {shown(value)}")
    value = int(value)
    if minimum is not None and value < minimum:
        raise InvalidParameterError(f"{name} must be an integer >= {minimum}, got {shown(value)}")
    return value


def check_num_sides(value, maximum: int = NUM_SIDES_MAX) -> int:
    """The number of polygon sides: an even integer >= 4, at most ``maximum``."""
    try:
        n = check_int("numSides", value)
    except InvalidTypeError:
        raise InvalidTypeError(
            f"numSides must be an even integer >= 4, got {shown(value)}"
        ) from None
    if n < 4 or n % 2:
        raise InvalidParameterError(f"numSides must be an even integer >= 4, got {shown(n)}")
    if n > maximum:
        raise InvalidParameterError(
            f"numSides must be an even integer in [4, {maximum}], got {shown(n)}"
        )
    return n


def check_radius(value, name: str = "r") -> float:
    """The tube radius: a finite number in [R_MIN, R_MAX] = [1e-6, 1e6]."""
    value = check_positive(name, value)
    if not R_MIN <= value <= R_MAX:
        raise InvalidParameterError(
            f"{name} must lie in [{R_MIN:g}, {R_MAX:g}] (the tube radius, in the chain's "
            f"length unit), got {value!r}"
        )
    return value


def check_max_angle_per_elbow(value) -> float:
    """maxAnglePerElbow in [pi/180, pi] (radians): a link has ceil(turn / maxAnglePerElbow)
    elbows, so a tiny value would ask for billions (kinegami.limits.MIN_ANGLE_PER_ELBOW)."""
    value = check_real("maxAnglePerElbow", value)
    if not MIN_ANGLE_PER_ELBOW <= value <= math.pi:
        raise InvalidParameterError(
            f"maxAnglePerElbow must lie in [pi/180, pi] (one degree to half a turn: each link "
            f"has ceil(turn / maxAnglePerElbow) elbows, kinegami.limits.MIN_ANGLE_PER_ELBOW), "
            f"got {value!r}"
        )
    return value


def check_num_sink_layers(value) -> int:
    """numSinkLayers of a revolute joint: an integer in [1, NUM_SINK_LAYERS_MAX] = [1, 32]."""
    return _check_count(
        "numSinkLayers", value, NUM_SINK_LAYERS_MAX, "NUM_SINK_LAYERS_MAX",
        "the joint's pattern grows with every layer",
    )  # fmt: skip


def check_num_layers(value) -> int:
    """numLayers of a prismatic joint: an integer in [1, NUM_LAYERS_MAX] = [1, 200]."""
    return _check_count(
        "numLayers", value, NUM_LAYERS_MAX, "NUM_LAYERS_MAX",
        "the joint's pattern has about 3 numSides vertices per layer",
    )  # fmt: skip


def check_samples(name: str, value, joints: int) -> int:
    """A number of sampled configurations of a chain of ``joints`` joints: an integer in
    [1, MAX_SAMPLES], with ``value * joints <= MAX_SAMPLED_STATES`` (docs/limits.md)."""
    n = _check_count(name, value, MAX_SAMPLES, "MAX_SAMPLES",
                     "each is a clearance test of the whole chain")  # fmt: skip
    if n * joints > MAX_SAMPLED_STATES:
        raise InvalidParameterError(
            f"{name}: {n} configurations of {joints} joints are {n * joints} sampled states, "
            f"more than {MAX_SAMPLED_STATES} (they are held in memory at once; "
            f"kinegami.limits.MAX_SAMPLED_STATES): use at most {MAX_SAMPLED_STATES // joints}"
        )
    return n


def check_starts(value) -> int:
    """The number of starts of a compaction: an integer in [1, MAX_STARTS]."""
    return _check_count("starts", value, MAX_STARTS, "MAX_STARTS", "each is a whole search")


def joint_count_refusal(count: int, noun: str = "chain") -> str | None:
    """Why a chain or tree of ``count`` joints takes no more (it has ``MAX_API_JOINTS``), in one
    line; None while it may grow. Append and addJoint report it as any failed placement does
    (None with a PlacementWarning, nothing changed)."""
    if count < MAX_API_JOINTS:
        return None
    return (f"the {noun} has {count} joints, the most it may have (kinegami.limits."
            f"MAX_API_JOINTS = {MAX_API_JOINTS}: each placement tests the whole {noun}, "
            "so its cost grows with every joint)")  # fmt: skip


def _check_count(name: str, value, maximum: int, constant: str, why: str) -> int:
    """An integer in [1, maximum], or an error naming the value, the limit and ``why``."""
    n = check_int(name, value, minimum=1)
    if n > maximum:
        raise InvalidParameterError(
            f"{name} must be an integer in [1, {maximum}] ({why}; "
            f"kinegami.limits.{constant}), got {shown(n)}"
        )
    return n


def check_twist_portion(value) -> float:
    """twistPortion (share of a link's straight part given to its twist) in [0, 1)."""
    return check_in_range("twistPortion", value, 0.0, 1.0, low_inclusive=True, range_text="[0, 1)")


# --- values in messages ------------------------------------------------------------------


class ReadOnlyAttributes:
    """Mixin of value classes (joints, links) whose public attributes cannot be changed.

    Assigning or deleting a public attribute (one whose name does not start with ``_``)
    raises :class:`~kinegami.errors.ReadOnlyError`, whose message ends with the class's
    ``_READ_ONLY_ADVICE`` (what to do instead). Construction sets public attributes with
    :meth:`_set_attribute`; private ones (``_T``, ``_state``) are set as usual, which is how
    ``with_pose`` and ``with_state`` build their copies.
    """

    __slots__ = ()

    #: What to do instead of assigning; subclasses say it for their kind of value.
    _READ_ONLY_ADVICE = "build a new object instead"

    def _set_attribute(self, name: str, value) -> None:
        """Set a public attribute during construction."""
        object.__setattr__(self, name, value)

    def __setattr__(self, name: str, value) -> None:
        if name.startswith("_"):
            object.__setattr__(self, name, value)
            return
        raise ReadOnlyError(
            f"{type(self).__name__}.{name} is read-only: {self._READ_ONLY_ADVICE}"
        )

    def __delattr__(self, name: str) -> None:
        if name.startswith("_"):
            object.__delattr__(self, name)
            return
        raise ReadOnlyError(
            f"{type(self).__name__}.{name} is read-only and cannot be deleted: "
            f"{self._READ_ONLY_ADVICE}"
        )
