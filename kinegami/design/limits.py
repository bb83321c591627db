"""Upper bounds of design files, and the check of lengths against the tube radius.

The bounds keep every design cheap to build and free of numeric overflow:

* ``numSides`` <= :data:`NUM_SIDES_MAX`, ``numSinkLayers`` <= :data:`NUM_SINK_LAYERS_MAX`,
  ``numLayers`` <= :data:`NUM_LAYERS_MAX` and ``maxAnglePerElbow`` >=
  :data:`MIN_ANGLE_PER_ELBOW`: one joint's crease pattern then has at most about 4e4 vertices
  and one link's about 6e4 (measured, see docs/design-format.md).
* ``r`` in [:data:`R_MIN`, :data:`R_MAX`] (file units), and every length and translation
  coordinate finite with ``|value| <= LENGTH_FACTOR * r``: products and squares of lengths stay
  far from the float range.
* A design file is a regular file of at most :data:`MAX_FILE_BYTES` bytes, with at most
  :data:`MAX_JOINTS` joints, :data:`MAX_DH_ROWS` DH rows, :data:`MAX_EDITS` edits,
  :data:`MAX_STATES` states and :data:`MAX_POSE_STEPS` steps per pose, lists and objects nested
  at most :data:`MAX_DEPTH` deep (a design needs 6), and numbers within the float range. These
  caps are checked while the file is parsed or before anything else is validated, so even a
  file of 16 MiB is rejected in a fraction of a second.

The numbers live in :mod:`kinegami.limits` (docs/limits.md has the whole table). The schema
(schema.json) states the same integer, radius and count bounds, and the absolute
length bound ``LENGTH_FACTOR * R_MAX``; :func:`check_lengths` checks the bound relative to
``r``. The radius and length bounds are those of the Python API (:mod:`kinegami.validation`).
"""

from __future__ import annotations

from kinegami.design.errors import DesignError, json_path
from kinegami.limits import (
    FILE_NUM_SIDES_MAX,
    LENGTH_FACTOR,
    MAX_DEPTH,
    MAX_DH_ROWS,
    MAX_EDITS,
    MAX_FILE_BYTES,
    MAX_JOINTS,
    MAX_POSE_STEPS,
    MAX_STATES,
    MIN_ANGLE_PER_ELBOW,
    NUM_LAYERS_MAX,
    NUM_SINK_LAYERS_MAX,
    R_MAX,
    R_MIN,
)

__all__ = [
    "NUM_SIDES_MAX",
    "NUM_SINK_LAYERS_MAX",
    "NUM_LAYERS_MAX",
    "MIN_ANGLE_PER_ELBOW",
    "R_MIN",
    "R_MAX",
    "LENGTH_FACTOR",
    "MAX_FILE_BYTES",
    "MAX_JOINTS",
    "MAX_DH_ROWS",
    "MAX_EDITS",
    "MAX_STATES",
    "MAX_POSE_STEPS",
    "MAX_DEPTH",
    "check_lengths",
    "position_problem",
    "too_many",
    "too_deep",
]

#: Largest number of polygon sides of the tube in a file (joint-specification files share it).
#: The other bounds are those of kinegami.limits (docs/limits.md), imported above.
NUM_SIDES_MAX = FILE_NUM_SIDES_MAX

#: Length fields of joints (positive) and of the dh object.
_JOINT_LENGTHS = ("length", "tubeLength", "neutralLength")
_DH_LENGTHS = ("neutralLength", "tipLength")
_TRANSLATION_STEPS = ("Tx", "Ty", "Tz")


def _checker(r: float, file):
    limit = LENGTH_FACTOR * r

    def check(value, path, positive: bool = False) -> None:
        if abs(value) <= limit and (value > 0 or not positive):
            return
        what = "> 0 and <= 1e6 r" if positive else "within +-1e6 r"
        raise DesignError(
            f"out of range: lengths and translation coordinates must be {what} "
            f"= {limit:g} (r = {r:g})",
            field=json_path(path),
            value=value,
            file=file,
        )

    return check


def _check_pose(spec, path, check) -> None:
    """The translation coordinates of a schema-valid pose (matrix, steps or axis)."""
    if isinstance(spec, dict):
        for k, value in enumerate(spec.get("point", ())):
            check(value, [*path, "point", k])
    elif spec and isinstance(spec[0], list):
        for row in range(3):
            check(spec[row][3], [*path, row, 3])
    else:
        for i, step in enumerate(spec):
            ((key, value),) = step.items()
            if key == "Trans":
                for k, v in enumerate(value):
                    check(v, [*path, i, key, k])
            elif key in _TRANSLATION_STEPS:
                check(value, [*path, i, key])


def check_lengths(document: dict, file=None) -> None:
    """Every length and translation coordinate of a schema-valid ``document`` within 1e6 r.

    Checked: joint lengths (``length``, ``tubeLength``, ``neutralLength``), the translations of
    every pose and edit transform (matrix column 4, ``Trans``/``Tx``/``Ty``/``Tz`` steps, axis
    ``point``), edit ``distance``, DH ``a`` and ``d`` and the DH lengths. Raises DesignError
    naming the first offending field.
    """
    r = float(document["r"])
    check = _checker(r, file)
    for i, spec in enumerate(document.get("joints", ())):
        for key in _JOINT_LENGTHS:
            if key in spec:
                check(spec[key], ["joints", i, key], positive=True)
        if "pose" in spec:
            _check_pose(spec["pose"], ["joints", i, "pose"], check)
    dh = document.get("dh")
    if dh is not None:
        for k, row in enumerate(dh["rows"]):
            check(row[2], ["dh", "rows", k, 2])
            check(row[3], ["dh", "rows", k, 3])
        for key in _DH_LENGTHS:
            if key in dh:
                check(dh[key], ["dh", key], positive=True)
    for i, spec in enumerate(document.get("edits", ())):
        if "distance" in spec:
            check(spec["distance"], ["edits", i, "distance"])
        if "transform" in spec:
            _check_pose(spec["transform"], ["edits", i, "transform"], check)


def position_problem(chain) -> tuple[int, str] | None:
    """``(joint index, reason)`` for the first joint of a built chain or tree that lies beyond
    +-LENGTH_FACTOR r of the origin in some coordinate, or None.

    Placement, edits and states compute positions from steps that each keep the bound, but
    steps add up; a design file holds every joint's position, so such a chain could not be
    saved as a design (docs/limits.md). The loader and the editor refuse it.
    """
    r = float(chain.r)
    limit = LENGTH_FACTOR * r
    for i, joint in enumerate(chain.Joints):
        t = joint.pose_matrix[:3, 3]
        k = max(range(3), key=lambda axis: abs(float(t[axis])))
        if not abs(float(t[k])) <= limit:
            return i, (
                f"joint {i} ({type(joint).__name__}) would lie at {'xyz'[k]} = "
                f"{float(t[k]):.6g}, beyond +-1e6 r = {limit:g} (r = {r:g}) from the origin, "
                "where a design file cannot hold it (kinegami.limits.LENGTH_FACTOR): place the "
                "joints closer together"
            )
    return None


def too_many(what: str, cap: int, name: str, count: int | None = None) -> str:
    """The reason of a DesignError for a list of ``what`` beyond its cap ``name``."""
    has = "more" if count is None else str(count)
    return (
        f"too many {what}: a design has at most {cap} "
        f"(kinegami.design.limits.{name}); this one has {has}"
    )


def too_deep() -> str:
    """The reason of a DesignError for nesting beyond :data:`MAX_DEPTH`."""
    return (
        f"nested too deeply: lists and objects nest at most {MAX_DEPTH} levels deep in a "
        "design (kinegami.design.limits.MAX_DEPTH; a design needs 6)"
    )
