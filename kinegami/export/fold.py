"""FOLD 1.2 export: the flat sheet as a crease pattern, plus its folded form at joint state 0.

FOLD (https://github.com/edemaine/fold) is the JSON origami format read by Origami Simulator and
Rabbit Ear. The file written here has

* frame 0, class ``creasePattern``: the flattened sheet of docs/theory/patterns.md §5 (the sheet of
  the DXF and SVG files: x in [-b/2, W + b/2], y in [y0, y0 + H], the glue tab being the second copy
  of the starting panel) as a planar graph, drawn from the pattern's unsnapped geometry
  (:func:`kinegami.pattern.folded.unsnapped_form`: no vertex moved by the catalog's eps = 1e-4 b
  rules, so the folded form keeps every edge length; it differs from the DXF sheet by less than eps,
  or up to 2e-4 r next to an elbow column collapsed by fix B6). Every crease is cut where it meets
  the sheet's vertical edges, the outline is split at every vertex on it, and the faces are the
  faces of that planar graph, counter-clockwise, printed side up (+z). No vertex only splits a
  straight line: where two collinear edges with the same assignment and fold angle meet at a
  vertex with no other edge (a module boundary that is no crease, a point of the outline), they
  are one edge; and no face has a straight corner: a face with one (a crease ending on a
  straight crease) is split by flat ``F`` diagonals. Origami Simulator turns such corners into
  zero-area triangles, and its solver blows up on them;
* ``edges_assignment``: ``M`` and ``V`` for the creases, ``B`` for the sheet outline (including
  creases lying on the top or bottom edge, B10 of docs/theory/patterns.md §6, and the glue tab's
  outer edge), ``F`` for
  those diagonals (the catalog's patterns need none). The sheet has no slits, so ``C`` never
  occurs;
* ``edges_foldAngle`` in degrees, FOLD's sign convention (valley > 0, mountain < 0, 0 for
  ``B`` and ``F``): the magnitude is the dihedral angle of the crease in the folded form;
* ``file_frames[0]``, class ``foldedForm``, inheriting from frame 0: the 3D position of every
  vertex (:mod:`kinegami.pattern.folded`). Both copies of the glue tab land on the same place.

Lengths are written in millimetres: one pattern unit is one ``units`` (default ``"mm"``) times
``scale``, as in the DXF export. See docs/fold.md.
"""

from __future__ import annotations

import itertools
import json
import math
from typing import Any, TextIO

import numpy as np

from kinegami.errors import FoldExportError, InvalidParameterError, InvalidTypeError
from kinegami.export._options import unit_factor
from kinegami.pattern.planar import SheetGraph, fold_angles, straight_corners
from kinegami.pattern.sheet_graph import sheet_graph
from kinegami.validation import check_bool, check_options

__all__ = [
    "FOLD_SPEC",
    "SheetGraph",
    "FoldExportError",
    "sheet_graph",
    "fold_dict",
    "fold_data",
    "write_fold",
    "fold_angles",
    "file_fold_angles",
    "straight_corners",
]

#: FOLD specification version written.
FOLD_SPEC = 1.2

_OPTIONS = ("units", "scale", "folded", "frame", "twistPortion", "title")


def file_fold_angles(graph: SheetGraph) -> np.ndarray:
    """The ``edges_foldAngle`` of the file: degrees, rounded to 1e-9 degree, FOLD's signs.

    The magnitude is that of :func:`fold_angles` (at most 180); the sign is the assignment's:
    positive for ``V``, negative for ``M``, and 0 for ``B`` and ``F``.
    """
    angles = np.degrees(np.abs(fold_angles(graph)))
    sign = np.where(graph.assignment == "V", 1.0, np.where(graph.assignment == "M", -1.0, 0.0))
    return np.round(sign * np.minimum(angles, 180.0), 9) + 0.0


# ------------------------------------------------------------------------------------------------
# FOLD dictionary and writer


def _resolve_options(options: dict[str, Any]) -> dict[str, Any]:
    check_options(options, _OPTIONS, "FOLD export")
    factor = unit_factor(options.get("units", "mm"), options.get("scale", 1.0))
    folded = check_bool("folded", options.get("folded", True))
    title = options.get("title")
    if title is not None and not isinstance(title, str):
        raise InvalidTypeError(f"title must be a string, got {title!r}")
    return {
        "factor": factor,
        "folded": bool(folded),
        "frame": options.get("frame"),
        "twistPortion": options.get("twistPortion", 0.2),
        "title": title,
    }


def _rounded(values: np.ndarray, extent: float) -> list:
    digits = 12 - math.ceil(math.log10(extent)) if extent > 0 else 12
    return (np.round(values, digits) + 0.0).tolist()


def fold_dict(pattern_or_chain, **options: Any) -> dict:
    """The FOLD 1.2 content of a pattern (or of a chain's crease pattern) as a dict.

    Parameters
    ----------
    pattern_or_chain : TubularPattern or KinematicChain
        A pattern made of catalog modules (e.g. ``chain.creasePattern()``) or a chain. The folded
        form of a bare pattern is placed with its proximal end on ``frame`` (default: tube axis
        along z); a chain's is in the chain's world frame.
    units : {'mm', 'cm', 'm', 'in'}, optional
        Length of one pattern unit (default ``'mm'``); coordinates are written in millimetres.
    scale : float, optional
        Extra multiplier of the pattern unit (default 1).
    folded : bool, optional
        Include the ``foldedForm`` frame (default True). Fold angles are always computed.
    frame : SE3 or (4, 4) array, optional
        World Dubins frame of the pattern's proximal end (see
        :func:`kinegami.pattern.folded.folded_vertices`).
    twistPortion : float, optional
        For a chain: passed to ``creasePattern`` (default 0.2).
    title : str, optional
        ``file_title`` of the file.

    Returns
    -------
    dict
        Keys file_spec, file_creator, file_classes, frame_classes, frame_attributes, frame_unit,
        vertices_coords, edges_vertices, edges_assignment, edges_foldAngle, faces_vertices and
        (unless ``folded=False``) file_frames with the ``foldedForm`` frame.

    Raises
    ------
    InvalidTypeError, InvalidParameterError
        For unknown options or bad values.
    FoldedFormError
        For a pattern without module records.
    FoldExportError
        For a sheet of zero area or an invalid planar graph.
    """
    import kinegami

    opts = _resolve_options(options)
    graph = sheet_graph(
        pattern_or_chain, folded=True, frame=opts["frame"], twistPortion=opts["twistPortion"]
    )
    fold_angle = file_fold_angles(graph)
    f = opts["factor"]
    xmin, ymin, xmax, ymax = graph.bounds
    extent = max(abs(xmin), abs(xmax), abs(ymin), abs(ymax)) * f or 1.0
    data: dict[str, Any] = {
        "file_spec": FOLD_SPEC,
        "file_creator": f"kinegami {kinegami.__version__}",
        "file_classes": ["singleModel"],
    }
    if opts["title"] is not None:
        data["file_title"] = opts["title"]
    data.update(
        {
            "frame_title": "crease pattern (flattened sheet, printed side up)",
            "frame_classes": ["creasePattern"],
            "frame_attributes": ["2D"],
            "frame_unit": "mm",
            "vertices_coords": _rounded(graph.vertices * f, extent),
            "edges_vertices": graph.edges.tolist(),
            "edges_assignment": graph.assignment.tolist(),
            "edges_foldAngle": fold_angle.tolist(),
            "faces_vertices": [face.tolist() for face in graph.faces],
        }
    )
    if opts["folded"]:
        X = graph.vertices_3d * f
        data["file_frames"] = [
            {
                "frame_title": "folded form at joint state 0",
                "frame_classes": ["foldedForm"],
                "frame_attributes": ["3D"],
                "frame_inherit": True,
                "frame_parent": 0,
                "vertices_coords": _rounded(X, max(float(np.abs(X).max()), extent)),
            }
        ]
    return data


def fold_data(pattern_or_chain, **options: Any) -> str:
    """A pattern (or a chain's crease pattern) as FOLD 1.2 JSON text.

    Takes the options of :func:`fold_dict`; ``kinegami.export(obj, "name.fold")`` (or
    ``pattern.save("name.fold")``) writes it to a file atomically.
    """
    return _json_text(fold_dict(pattern_or_chain, **options)) + "\n"


def _json_text(value: Any, depth: int = 0) -> str:
    """``json.dumps(value, indent=1, allow_nan=False)``, the same text, several times as fast
    for a FOLD file's long lists: a list of scalars, or of non-empty lists of numbers, is
    written by json's C encoder in one call (its separators carry the indentation).

    Raises
    ------
    ValueError
        For a NaN or infinite float (as ``allow_nan=False``).
    TypeError
        For a value that json cannot write.
    """
    if type(value) is list and value:
        indent = "\n" + " " * depth
        inner = indent + " "
        kinds = set(map(type, value))
        if kinds <= _SCALARS:  # one level: the item separator holds the indentation
            body = json.dumps(value, separators=("," + inner, ": "), allow_nan=False)[1:-1]
            return "[" + inner + body + indent + "]"
        if kinds == {list} and all(value) and _NUMBERS.issuperset(
            map(type, itertools.chain.from_iterable(value))
        ):  # two levels of numbers: no "," or "]," but the separators' own
            deeper = inner + " "
            body = json.dumps(value, separators=(",", ":"), allow_nan=False)[2:-2]
            body = body.replace("],[", "\0").replace(",", "," + deeper)
            body = body.replace("\0", inner + "]," + inner + "[" + deeper)
            return "[" + inner + "[" + deeper + body + inner + "]" + indent + "]"
        items = [_json_text(item, depth + 1) for item in value]
        return "[" + inner + ("," + inner).join(items) + indent + "]"
    if type(value) is dict and value:
        indent = "\n" + " " * depth
        inner = indent + " "
        if not all(type(key) is str for key in value):
            raise TypeError(f"FOLD keys are str, got {sorted(map(repr, value))}")
        items = [f"{json.dumps(key)}: {_json_text(item, depth + 1)}"
                 for key, item in value.items()]  # fmt: skip
        return "{" + inner + ("," + inner).join(items) + indent + "}"
    return json.dumps(value, allow_nan=False)  # a scalar, [] or {}


_NUMBERS = frozenset({float, int, bool, type(None)})
_SCALARS = _NUMBERS | {str}


def write_fold(pattern_or_chain, stream: TextIO, **options: Any) -> None:
    """Write :func:`fold_data` to a text stream (computed first: a failure writes nothing)."""
    stream.write(fold_data(pattern_or_chain, **options))


def save_fold(pattern_or_chain, path, **options: Any):
    """Write a ``.fold`` file atomically (missing folders are created); returns the path.

    Works for chains too (``save_pattern`` only accepts patterns).
    """
    import os
    from pathlib import Path

    from kinegami._atomic import write_atomic

    if not isinstance(path, str | os.PathLike) or not os.fspath(path).strip():
        raise InvalidParameterError(f"path must be a non-empty file name, got {path!r}")
    text = fold_data(pattern_or_chain, **options)
    target = Path(os.fspath(path)).expanduser()
    write_atomic(target, text)
    return target
