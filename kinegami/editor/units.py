"""What the editor shows and reads, in the design's units: lengths in ``document.units`` with
the unit's name, angles in degrees (docs/editor.md, Units).

The model and the library work in radians and in the chain's lengths, which are the design's
units (a design written in mm with r = 25 builds a chain with r = 25). Everything a person
reads or types in the editor goes through these helpers: a length is ``"2.2 mm"``, an angle
``"90°"``, a revolute joint's state is in degrees and a prismatic joint's in the unit. One
place for the wording, so every panel (the joint, its state sliders, the clearance verdict)
says it the same way.
"""

from __future__ import annotations

import math
import warnings

import numpy as np

from kinegami.errors import InvalidParameterError
from kinegami.validation import shown

__all__ = [
    "ANGLE_PARAMETERS",
    "LENGTH_PARAMETERS",
    "INTEGER_PARAMETERS",
    "DEGREE",
    "number_text",
    "length_text",
    "angle_text",
    "parameter_unit",
    "parameter_to_display",
    "parameter_from_display",
    "parameters_from_display",
    "state_unit",
    "state_to_display",
    "state_from_display",
    "state_text",
    "pose_to_display",
    "pose_from_display",
]

#: The parameters that are angles (radians in the library, degrees in the editor).
ANGLE_PARAMETERS = ("totalBendingAngle", "coneAngle")
#: The parameters that are lengths (in the design's units).
LENGTH_PARAMETERS = ("tubeLength", "neutralLength", "length")
#: The parameters that are whole numbers.
INTEGER_PARAMETERS = ("numSinkLayers", "numLayers", "pathIndex")
#: The name of the editor's angle unit.
DEGREE = "°"

#: Joint types whose state is an angle; a PrismaticJoint's is a length, the others have none.
_ANGLE_STATE_TYPES = ("RevoluteJoint", "ExtendedRevoluteJoint")


def number_text(value: float, digits: int = 3) -> str:
    """``value`` with at least ``digits`` significant digits and no exponent (at most 6
    decimals), trailing zeros dropped: 2.223 -> ``"2.22"``, 1367.77 -> ``"1368"``."""
    value = float(value)
    if not math.isfinite(value):
        return str(value)
    if value == 0.0:
        return "0"
    decimals = min(6, max(0, digits - 1 - math.floor(math.log10(abs(value)))))
    text = f"{value:.{decimals}f}"
    if "." in text:
        text = text.rstrip("0").rstrip(".")
    return "0" if text in ("-0", "") else text


def length_text(value: float, units: str, digits: int = 3) -> str:
    """A length with its unit's name: ``length_text(2.223, "mm")`` is ``"2.22 mm"``."""
    return f"{number_text(value, digits)} {units}"


def angle_text(radians: float, digits: int = 3) -> str:
    """An angle (given in radians) in degrees: ``angle_text(pi / 2)`` is ``"90°"``."""
    return f"{number_text(math.degrees(float(radians)), digits)}{DEGREE}"


# --- joint parameters -------------------------------------------------------------------------
def parameter_unit(key: str, units: str) -> str:
    """The unit a parameter is shown and typed in: ``"deg"`` for angles, the design's units
    for lengths, ``""`` for whole numbers."""
    if key in ANGLE_PARAMETERS:
        return "deg"
    if key in LENGTH_PARAMETERS:
        return units
    return ""


def parameter_to_display(key: str, value):
    """A parameter's value as the editor shows it (degrees for angles)."""
    if key in ANGLE_PARAMETERS:
        return math.degrees(float(value))
    return value


def parameter_from_display(key: str, value):
    """A typed parameter value as the library takes it: degrees to radians for angles; a
    whole-number parameter typed as 2.0 becomes 2 (2.5 stays 2.5, so the command's own check
    refuses it and says why). Anything else is passed on unchanged for the command to check."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        return value
    if key in ANGLE_PARAMETERS:
        return math.radians(float(value))
    if key in INTEGER_PARAMETERS and math.isfinite(float(value)) and float(value).is_integer():
        return int(value)
    return value


def parameters_from_display(values: dict) -> dict:
    """:func:`parameter_from_display` of every entry of ``{name: typed value}``."""
    return {key: parameter_from_display(key, value) for key, value in values.items()}


# --- joint states -----------------------------------------------------------------------------
def state_unit(joint_type: str, units: str) -> str:
    """The unit of a joint type's state: ``"deg"`` for revolute joints, the design's units
    for a prismatic joint, ``""`` for joints that do not move."""
    if joint_type in _ANGLE_STATE_TYPES:
        return "deg"
    if joint_type == "PrismaticJoint":
        return units
    return ""


def state_to_display(joint_type: str, state: float) -> float:
    """A joint's state as the editor shows it (degrees for revolute joints)."""
    return math.degrees(float(state)) if joint_type in _ANGLE_STATE_TYPES else float(state)


def state_from_display(joint_type: str, value):
    """A typed state as the library takes it (degrees to radians for revolute joints);
    anything but a number is passed on unchanged for the command to refuse."""
    if isinstance(value, bool) or not isinstance(value, int | float | np.integer | np.floating):
        return value
    return math.radians(float(value)) if joint_type in _ANGLE_STATE_TYPES else float(value)


def state_text(joint_type: str, state: float, units: str, digits: int = 3) -> str:
    """A joint's state with its unit: ``"45°"``, ``"1.5 cm"``."""
    if joint_type in _ANGLE_STATE_TYPES:
        return angle_text(state, digits)
    if joint_type == "PrismaticJoint":
        return length_text(state, units, digits)
    return number_text(state, digits)


# --- poses ------------------------------------------------------------------------------------
def pose_to_display(pose) -> tuple[tuple[float, float, float], tuple[float, float, float]]:
    """A 4x4 pose as ``(position, angles)``: the position in the design's units and the
    orientation as fixed-axis XYZ angles in degrees ``(roll, pitch, yaw)``: the rotation is
    roll about the world x axis, then pitch about y, then yaw about z (R = Rz Ry Rx).
    At pitch +-90° (gimbal lock) roll and yaw share one angle; the pair returned gives the
    same rotation."""
    from scipy.spatial.transform import Rotation

    T = np.asarray(pose, dtype=float)
    with warnings.catch_warnings():  # scipy warns at gimbal lock; the angles are still right
        warnings.simplefilter("ignore", UserWarning)
        angles = Rotation.from_matrix(T[:3, :3]).as_euler("xyz", degrees=True)
    position = tuple(float(v) for v in T[:3, 3])
    return position, tuple(float(a) for a in angles)  # type: ignore[return-value]


def pose_from_display(position, angles) -> np.ndarray:
    """The 4x4 pose of a typed ``position`` (design units) and fixed-axis XYZ ``angles``
    ``(roll, pitch, yaw)`` in degrees (see :func:`pose_to_display`). Raises
    InvalidParameterError naming the field when a value is not a finite number."""
    from scipy.spatial.transform import Rotation

    values = []
    for field, triple in (("position", position), ("orientation", angles)):
        try:
            items = list(triple)
        except TypeError:
            raise InvalidParameterError(
                f"{field} must be three numbers, got {shown(triple)}"
            ) from None
        if len(items) != 3:
            raise InvalidParameterError(f"{field} must be three numbers, got {len(items)}")
        for axis, value in zip("xyz", items, strict=True):
            if isinstance(value, bool) or not isinstance(
                value, int | float | np.integer | np.floating
            ) or not math.isfinite(float(value)):  # fmt: skip
                raise InvalidParameterError(
                    f"{field} {axis} must be a finite number, got {shown(value)}"
                )
        values.append([float(v) for v in items])
    T = np.eye(4)
    T[:3, :3] = Rotation.from_euler("xyz", values[1], degrees=True).as_matrix()
    T[:3, 3] = values[0]
    return T
