"""The three spellings of a pose in a design file, turned into 4x4 rigid transforms.

1. A 4x4 matrix (list of 4 rows of 4 numbers), used exactly as written (what saving writes);
   it must be rigid to within :data:`RIGID_TOL`.
2. A list of steps composed left to right like spatialmath products:
   ``[{"Trans": [5, 5, 0]}, {"Ry": 45}]`` is ``SE3.Trans(5, 5, 0) * SE3.Ry(pi/4)``, computed with
   spatialmath's arithmetic (the same cos/sin and matrix products, without importing it:
   tests/design/test_poses.py checks it bit for bit), so a design reproduces the Python listing
   exactly.
3. An axis ``{"point": p, "axis": z, "xhat": x}``: origin p, z = axis / |axis|, x = xhat made
   perpendicular to z (Gram-Schmidt; default :func:`default_xhat`), y = z cross x.

The input has already passed the JSON schema (shapes and types); these functions check what the
schema cannot (rigidity, zero and parallel vectors) and raise :class:`DesignError`.
"""

from __future__ import annotations

import math

import numpy as np

from kinegami.design.errors import DesignError, json_path, numeric_errors

__all__ = ["RIGID_TOL", "PARALLEL_TOL", "pose_from_json", "default_xhat", "rigidity_problem"]

#: Largest deviation of a matrix pose from a rigid transform (orthonormality, det, last row).
RIGID_TOL = 1e-9
#: ``xhat`` is parallel to ``axis`` when its perpendicular part is below this times |xhat|.
PARALLEL_TOL = 1e-9

def _rotation(axis: int, angle: float) -> np.ndarray:
    """spatialmath's ``SE3.Rx/Ry/Rz(angle)`` (math.cos and math.sin, the same matrix)."""
    c, s = math.cos(angle), math.sin(angle)
    T = np.eye(4)
    if axis == 0:
        T[:3, :3] = [[1, 0, 0], [0, c, -s], [0, s, c]]
    elif axis == 1:
        T[:3, :3] = [[c, 0, s], [0, 1, 0], [-s, 0, c]]
    else:
        T[:3, :3] = [[c, -s, 0], [s, c, 0], [0, 0, 1]]
    return T


def _translation(x: float, y: float, z: float) -> np.ndarray:
    """spatialmath's ``SE3.Trans(x, y, z)``."""
    T = np.eye(4)
    T[:3, 3] = (x, y, z)
    return T


_STEPS = {
    "Trans": lambda v: _translation(float(v[0]), float(v[1]), float(v[2])),
    "Tx": lambda v: _translation(float(v), 0.0, 0.0),
    "Ty": lambda v: _translation(0.0, float(v), 0.0),
    "Tz": lambda v: _translation(0.0, 0.0, float(v)),
    "Rx": lambda a: _rotation(0, a),
    "Ry": lambda a: _rotation(1, a),
    "Rz": lambda a: _rotation(2, a),
}
_ROTATIONS = ("Rx", "Ry", "Rz")


def to_radians(value: float, angle_units: str) -> float:
    """An angle of the file in radians (``angle_units`` is ``"rad"`` or ``"deg"``)."""
    value = float(value)
    return math.radians(value) if angle_units == "deg" else value


def rigidity_problem(T: np.ndarray, tol: float = RIGID_TOL) -> str | None:
    """Why ``T`` is not a proper rigid transform (None if it is one within ``tol``)."""
    if not np.all(np.isfinite(T)):
        return "the matrix must be finite"
    bottom = float(np.max(np.abs(T[3] - (0.0, 0.0, 0.0, 1.0))))
    if bottom > tol:
        return "the last row must be [0, 0, 0, 1]"
    R = T[:3, :3]
    largest = float(np.max(np.abs(R)))
    if largest > 1.0 + tol:  # also keeps R^T R far from overflow
        return (
            f"the rotation part (first 3 rows and columns) must be orthonormal to {tol:g} "
            f"(it has an entry of magnitude {largest:.3g} > 1)"
        )
    ortho = float(np.max(np.abs(R.T @ R - np.eye(3))))
    if ortho > tol:
        return (
            f"the rotation part (first 3 rows and columns) must be orthonormal to {tol:g} "
            f"(max |R^T R - I| is {ortho:.3g})"
        )
    det = float(np.linalg.det(R))
    if abs(det - 1.0) > tol:
        return f"the rotation part must have determinant +1 (a reflection has -1), got {det:.6g}"
    return None


def default_xhat(axis: np.ndarray) -> np.ndarray:
    """The x direction used when an axis pose has no ``xhat``.

    The world axis (x, then y, then z on ties) least aligned with ``axis``, before Gram-Schmidt;
    for ``axis = z`` this is world x, giving the identity rotation.
    """
    k = int(np.argmin(np.abs(axis)))
    e = np.zeros(3)
    e[k] = 1.0
    return e


def _matrix_pose(rows, path) -> np.ndarray:
    T = np.array(rows, dtype=float)
    problem = rigidity_problem(T)
    if problem is not None:
        raise DesignError(f"not a rigid transform: {problem}", field=json_path(path), value=rows)
    return T


def _steps_pose(steps, angle_units: str) -> np.ndarray:
    pose = None
    for step in steps:
        ((key, value),) = step.items()
        if key in _ROTATIONS:
            value = to_radians(value, angle_units)
        factor = _STEPS[key](value)
        pose = factor if pose is None else pose @ factor
    if pose is None:
        return np.eye(4)
    return pose


def rescaled_exactly(vector) -> np.ndarray | None:
    """``vector`` times a power of two bringing its largest entry into [0.5, 1) (exact, so
    normalising it gives the same bits as normalising ``vector``); None for a zero vector."""
    v = np.array(vector, dtype=float)
    largest = float(np.max(np.abs(v)))
    if largest == 0.0:
        return None
    return np.ldexp(v, -math.frexp(largest)[1])


def _axis_pose(spec, path) -> np.ndarray:
    point = np.array(spec.get("point", (0.0, 0.0, 0.0)), dtype=float)
    axis = rescaled_exactly(spec["axis"])
    if axis is None:
        raise DesignError(
            "the axis must be a non-zero vector", field=json_path([*path, "axis"]),
            value=spec["axis"],
        )  # fmt: skip
    z = axis / math.sqrt(float(axis @ axis))
    if "xhat" in spec:
        xhat = rescaled_exactly(spec["xhat"])
        if xhat is None:
            xhat = np.zeros(3)
    else:
        xhat = default_xhat(z)
    x = xhat - float(xhat @ z) * z
    size = math.sqrt(float(x @ x))
    if not size > PARALLEL_TOL * math.sqrt(float(xhat @ xhat)):
        raise DesignError(
            f"xhat must not be zero or parallel to the axis {_format_vector(spec['axis'])}",
            field=json_path([*path, "xhat"]),
            value=spec.get("xhat"),
        )
    x = x / size
    T = np.eye(4)
    T[:3, 0] = x
    T[:3, 1] = np.cross(z, x)
    T[:3, 2] = z
    T[:3, 3] = point
    return T


def _format_vector(v) -> str:
    return "[" + ", ".join(repr(float(c)) if isinstance(c, float) else repr(c) for c in v) + "]"


def pose_from_json(spec, path=(), angle_units: str = "rad") -> np.ndarray:
    """The 4x4 transform of a schema-valid pose ``spec`` found at JSON ``path``.

    Parameters
    ----------
    spec : a 4x4 matrix (rows), a list of steps, or an axis object (see the module docstring).
    path : JSON path of ``spec`` (a sequence of keys and indices), used in error messages.
    angle_units : ``"rad"`` or ``"deg"``, the unit of the ``Rx``/``Ry``/``Rz`` steps.

    Raises
    ------
    DesignError
        For a matrix that is not rigid, a zero axis or an ``xhat`` parallel to the axis, or a
        floating point overflow (only possible for translations beyond the design bounds,
        which :func:`kinegami.design.limits.check_lengths` rejects first).
    """
    path = tuple(path)
    with numeric_errors(json_path(path), what="numeric error computing the pose"):
        if isinstance(spec, dict):
            return _axis_pose(spec, path)
        if spec and isinstance(spec[0], list):
            return _matrix_pose(spec, path)
        return _steps_pose(spec, angle_units)
