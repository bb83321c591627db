"""STL and OBJ of a chain's (or a tree's) 3D model in its current configuration (docs/mesh.md).

The model is the closed meshes of :mod:`kinegami.clearance.solids`, one per part (its table names
them).

Files are in millimetres: one chain unit (the unit of r) is ``units`` (default ``'mm'``) times
``scale``. STL is binary (one solid, all parts); OBJ has one object (``o`` line) per part, named
as above. Both are written from numpy; trimesh reads them back (``trimesh.load(path,
split_objects=True)`` gives one geometry per OBJ part).
"""

from __future__ import annotations

from typing import TYPE_CHECKING, Any, BinaryIO, TextIO

import numpy as np

from kinegami.clearance.solids import (
    MESH_TOLERANCE,
    MIN_ARC_ANGLE,
    MIN_SEGMENT_LENGTH,
    MeshPart,
    chain_parts,
    check_assembly,
    is_tree,
    joint_parts,
    link_parts,
)
from kinegami.export._options import unit_factor
from kinegami.validation import resolve_options

if TYPE_CHECKING:  # pragma: no cover
    import trimesh

    from kinegami.chain.model import KinematicChain
    from kinegami.tree.model import KinematicTree

__all__ = [
    "MeshPart",
    "MESH_TOLERANCE",
    "MIN_ARC_ANGLE",
    "MIN_SEGMENT_LENGTH",
    "chain_parts",
    "joint_parts",
    "link_parts",
    "chain_mesh",
    "mesh_factor",
    "stl_data",
    "obj_data",
    "write_stl",
    "write_obj",
    "stl_bytes",
    "shell_mass_properties",
]

_STL_HEADER = b"kinegami chain mesh, millimetres"
_TREE_STL_HEADER = b"kinegami tree mesh, millimetres"


def mesh_factor(units: Any = "mm", scale: Any = 1.0) -> float:
    """Millimetres per chain unit for the ``units`` and ``scale`` options (checked)."""
    return unit_factor(units, scale, "chain unit")


_MESH_DEFAULTS = {"units": "mm", "scale": 1.0, "twistPortion": 0.2}


def _scaled_parts(chain: Any, options: dict[str, Any], fmt: str) -> list[MeshPart]:
    chain = check_assembly(chain, fmt)
    opts = resolve_options(options, _MESH_DEFAULTS, f"{fmt} export")
    factor = mesh_factor(opts["units"], opts["scale"])
    parts = chain_parts(chain, twistPortion=opts["twistPortion"])
    return [p.transformed(np.eye(4), factor) for p in parts]


def chain_mesh(chain: KinematicChain | KinematicTree, **options: Any) -> trimesh.Trimesh:
    """All parts in one ``trimesh.Trimesh`` (millimetres; options as for :func:`write_stl`).

    The parts are concatenated, not merged: the result is a set of closed shells.
    """
    import trimesh

    parts = _scaled_parts(chain, options, "mesh")
    vertices, faces = _concatenate(parts)
    return trimesh.Trimesh(vertices, faces, process=False)


def _concatenate(parts: list[MeshPart]) -> tuple[np.ndarray, np.ndarray]:
    if not parts:
        return np.zeros((0, 3)), np.zeros((0, 3), dtype=np.int64)
    offsets = np.cumsum([0] + [p.vertices.shape[0] for p in parts[:-1]])
    vertices = np.vstack([p.vertices for p in parts])
    faces = np.vstack([p.faces + o for p, o in zip(parts, offsets, strict=True)])
    return vertices, faces


def stl_bytes(vertices: np.ndarray, faces: np.ndarray, header: bytes = _STL_HEADER) -> bytes:
    """Binary STL of a triangle mesh (float32, unit face normals, zero attribute bytes)."""
    tri = np.asarray(vertices, dtype=float)[np.asarray(faces, dtype=np.int64)]
    normals = np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0])
    norm = np.linalg.norm(normals, axis=1, keepdims=True)
    normals = np.divide(normals, norm, out=np.zeros_like(normals), where=norm > 0)
    record = np.dtype([("normal", "<f4", (3,)), ("vertices", "<f4", (3, 3)), ("attributes", "<u2")])
    data = np.zeros(tri.shape[0], dtype=record)
    data["normal"] = normals
    data["vertices"] = tri
    head = header[:80].ljust(80, b" ")
    return head + np.uint32(tri.shape[0]).astype("<u4").tobytes() + data.tobytes()


def stl_data(chain: KinematicChain | KinematicTree, **options: Any) -> bytes:
    """The chain's (or tree's) model as one binary STL (millimetres, current configuration).

    Parameters
    ----------
    chain : KinematicChain or KinematicTree
    units : {'mm', 'cm', 'm', 'in'}, optional
        Length of one chain unit (the unit of r); default ``'mm'``.
    scale : float, optional
        Extra multiplier (> 0); default 1.
    twistPortion : float, optional
        Fraction of a straight part taken by its twist, in [0, 1]; default 0.2.

    Raises
    ------
    InvalidTypeError
        For an object that is not a KinematicChain or KinematicTree, or an unknown option.
    InvalidParameterError
        For a bad option value.
    """
    parts = _scaled_parts(chain, options, "STL")
    return stl_bytes(*_concatenate(parts), _TREE_STL_HEADER if is_tree(chain) else _STL_HEADER)


def write_stl(chain: KinematicChain | KinematicTree, stream: BinaryIO, **options: Any) -> None:
    """Write :func:`stl_data` of ``chain`` to a binary stream (options as there)."""
    stream.write(stl_data(chain, **options))


def obj_data(chain: KinematicChain | KinematicTree, **options: Any) -> str:
    """The chain's (or tree's) model as Wavefront OBJ text, one object per part (millimetres).

    Options as for :func:`stl_data`. Vertices are written with 12 significant digits.
    """
    parts = _scaled_parts(chain, options, "OBJ")
    out = [
        f"# kinegami {'tree' if is_tree(chain) else 'chain'} mesh: one object per part, "
        "millimetres, current configuration\n",
        f"# {len(parts)} parts\n",
    ]
    offset = 1
    for part in parts:
        out.append(f"o {part.name}\n")
        out.extend(f"v {x:.12g} {y:.12g} {z:.12g}\n" for x, y, z in part.vertices.tolist())
        out.extend(f"f {a} {b} {c}\n" for a, b, c in (part.faces + offset).tolist())
        offset += part.vertices.shape[0]
    return "".join(out)


def write_obj(chain: KinematicChain | KinematicTree, stream: TextIO, **options: Any) -> None:
    """Write :func:`obj_data` of ``chain`` to a text stream (options as there)."""
    stream.write(obj_data(chain, **options))


def shell_mass_properties(
    vertices: np.ndarray, faces: np.ndarray, mass_per_area: float
) -> tuple[float, np.ndarray, np.ndarray]:
    """Mass, centre of mass and inertia tensor of a thin shell of uniform areal density.

    Every triangle is a sheet of density ``mass_per_area``; exact for the triangles (second
    moment of a triangle with vertices a, b, c and area A: A/12 (a a' + b b' + c c' + s s'),
    s = a + b + c).

    Returns
    -------
    mass : float
    com : numpy.ndarray, shape (3,)
    inertia : numpy.ndarray, shape (3, 3)
        About the centre of mass, axes of the input coordinates.
    """
    tri = np.asarray(vertices, dtype=float)[np.asarray(faces, dtype=np.int64)]
    if tri.shape[0] == 0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    area = 0.5 * np.linalg.norm(np.cross(tri[:, 1] - tri[:, 0], tri[:, 2] - tri[:, 0]), axis=1)
    mass = float(mass_per_area * area.sum())
    if mass <= 0.0:
        return 0.0, np.zeros(3), np.zeros((3, 3))
    s = tri.sum(axis=1)
    com = mass_per_area * (area[:, None] * s).sum(axis=0) / 3.0 / mass
    second = np.einsum("fki,fkj->fij", tri, tri) + np.einsum("fi,fj->fij", s, s)
    C = mass_per_area * np.einsum("f,fij->ij", area / 12.0, second)
    C -= mass * np.outer(com, com)
    inertia = np.trace(C) * np.eye(3) - C
    return mass, com, 0.5 * (inertia + inertia.T)
