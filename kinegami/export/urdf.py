"""URDF of a kinematic chain or tree, for robot simulators (docs/urdf.md).

Bodies
    One URDF ``<link>`` per rigid body: ``body_0`` holds everything before the first revolute
    or prismatic joint, ``body_b`` everything after the b-th one up to the next. Waypoints,
    tips and the links (tubes) are fixed parts of the body they lie in; a revolute or prismatic
    joint's proximal half belongs to the body before it and its distal half to the body after.
    A chain without movable joints gives one URDF link per chain joint (with the link into
    it), joined by fixed joints ``joint_k``; a single-joint chain is a single link.

Trees
    A :class:`~kinegami.tree.KinematicTree` is split the same way along every path from the
    root: the body "before" joint i is the one its parent's distal side belongs to (the link
    into i, from joint ``Parents[i]``, lies in it), and the b-th movable joint in index order
    starts ``body_b``. The URDF is then one kinematic tree: the joints of sibling branches have
    the same parent body (a URDF link with several child joints). Without movable joints every
    tree joint is a link, fixed to its parent's. A chain is the tree whose parents are i - 1 and
    gives the same file as before, byte for byte.

Joints
    Chain joint i, if revolute or prismatic, is the URDF ``<joint name="joint_i">`` of that type
    from the body before it to the body after it, with ``<limit lower upper>`` =
    ``stateRange()`` (radians, or metres for prismatic joints) and the given ``effort`` (N m or
    N) and ``velocity`` (rad/s or m/s).

Frames
    Every body frame is, when all joint states are 0, the Pose of the joint that starts the body
    (its origin the joint's centre, its z axis the joint's axis; ``body_0``: the world frame).
    A joint's ``<origin>`` is that Pose seen from its parent body's frame (``xyz`` and ``rpy``,
    fixed-axis roll, pitch, yaw in radians) and its ``<axis>`` is ``0 0 1``: every reader takes
    the axis the same way (Robotics Toolbox 1.5 misreads an axis other than z). Forward
    kinematics at a configuration q (one value per URDF joint, i.e. per movable chain joint in
    chain order) reproduces the chain (tree) after ``setJointStates`` with those states: a
    revolute joint turns everything after it about its z axis through its centre, a prismatic
    joint slides it along z (docs/theory/chain.md §1). The exported zero configuration is the
    chain with all states 0, whatever the chain's current states are.

Geometry
    With ``meshes=True`` (default) every part of :mod:`kinegami.export.mesh` (prismatic joints
    split into halves) is a binary STL file in the folder ``<name>_meshes/`` beside the URDF,
    in metres and in its body's frame, referenced by a relative path as both ``<visual>`` and
    ``<collision>`` of its body. Each part is a closed convex or tube-shaped mesh, which suits
    simulators that take the convex hull of every collision mesh. The URDF and its meshes are
    written as one set: if anything fails nothing is left behind, and an existing
    ``<name>_meshes/`` folder is replaced as a whole.

Inertia
    Each body's ``<inertial>`` is that of a thin shell over the surfaces of its parts with
    density ``mass_per_area`` (kg/m^2; default 0.08, 80 g/m^2 paper): a rough estimate (the
    inner end faces of the parts count as paper too).

Units
    URDF lengths are metres: one chain unit (the unit of r) is ``units`` (``'mm'`` default,
    ``'cm'``, ``'m'``, ``'in'``) times ``scale``.
"""

from __future__ import annotations

import math
import xml.etree.ElementTree as ET
from dataclasses import dataclass
from pathlib import Path
from typing import TYPE_CHECKING, Any, TextIO

import numpy as np

from kinegami.clearance.solids import chain_parts, check_assembly, is_tree
from kinegami.errors import InvalidParameterError
from kinegami.export.mesh import mesh_factor, shell_mass_properties, stl_bytes
from kinegami.geometry.frames import inverse
from kinegami.geometry.screws import FIXED, PRISMATIC, REVOLUTE
from kinegami.validation import (
    check_bool,
    check_nonnegative,
    check_positive,
    check_twist_portion,
    resolve_options,
)

if TYPE_CHECKING:  # pragma: no cover
    from kinegami.chain.model import KinematicChain
    from kinegami.tree.model import KinematicTree

__all__ = [
    "URDF_DEFAULTS",
    "UrdfModel",
    "ChainBodies",
    "chain_bodies",
    "urdf_model",
    "urdf_files",
    "write_urdf",
]

#: Options of the URDF exporter and their defaults.
URDF_DEFAULTS = {
    "name": None,
    "units": "mm",
    "scale": 1.0,
    "effort": 1.0,
    "velocity": 1.0,
    "meshes": True,
    "mesh_folder": None,
    "mass_per_area": 0.08,
    "twistPortion": 0.2,
}

_JOINT_RGBA = "0.0 0.0 0.545 1.0"  # darkblue, as show()
_LINK_RGBA = "0.827 0.827 0.827 1.0"  # lightgray, as show()


@dataclass(frozen=True)
class ChainBodies:
    """How a chain (or tree) splits into rigid bodies (world coordinates, chain units).

    Attributes
    ----------
    movable : tuple of int
        Indices of the revolute and prismatic joints; joint ``movable[b - 1]`` starts body b.
    proximal_body, distal_body : tuple of int
        Per joint: the body holding its Pose and proximal side (the distal body of its parent;
        0 for the root), and the body holding its distal side (different only for movable
        joints).
    zero_poses : numpy.ndarray, shape (J, 4, 4)
        Every joint's Pose with all states 0.
    motions : numpy.ndarray, shape (B, 4, 4)
        Per body, the world motion from the all-zero configuration to the current one.
    """

    movable: tuple[int, ...]
    proximal_body: tuple[int, ...]
    distal_body: tuple[int, ...]
    zero_poses: np.ndarray
    motions: np.ndarray

    @property
    def count(self) -> int:
        """Number of bodies (movable joints + 1)."""
        return len(self.movable) + 1

    def origin(self, body: int) -> np.ndarray:
        """Origin of a body frame at the zero configuration (world, chain units)."""
        if body == 0:
            return np.zeros(3)
        return self.zero_poses[self.movable[body - 1], :3, 3].copy()

    def zero_frame(self, body: int) -> np.ndarray:
        """A body frame at the zero configuration (world, chain units): the Pose of the joint
        that starts the body (its z axis the joint's axis), the world frame for body 0."""
        if body == 0:
            return np.eye(4)
        return self.zero_poses[self.movable[body - 1]].copy()

    def frame(self, body: int) -> np.ndarray:
        """Current world pose of a body frame (4x4, chain units)."""
        return self.motions[body] @ self.zero_frame(body)


def _joint_motion(joint, state: float) -> np.ndarray:
    """J(state) in the joint's own frame: Rz(state) or Trans(0, 0, state)."""
    T = np.eye(4)
    if joint.motion == REVOLUTE:
        c, s = math.cos(state), math.sin(state)
        T[:2, :2] = [[c, -s], [s, c]]
    else:
        T[2, 3] = state
    return T


def _parents(chain: KinematicChain | KinematicTree) -> tuple[int, ...]:
    """Parent of every joint (-1 for the root): ``Parents`` of a tree, i - 1 in a chain."""
    return tuple(int(p) for p in chain.Parents)


def chain_bodies(chain: KinematicChain | KinematicTree) -> ChainBodies:
    """Split ``chain`` (or a tree) into rigid bodies at its revolute and prismatic joints (see
    module doc). A joint's proximal side lies in the body of its parent's distal side."""
    chain = check_assembly(chain, "URDF")
    parents = _parents(chain)
    movable, proximal, distal = [], [], []
    zero = np.empty((len(chain.Joints), 4, 4))
    motions = [np.eye(4)]
    for k, joint in enumerate(chain.Joints):
        body = distal[parents[k]] if parents[k] >= 0 else 0
        pose = joint.pose_matrix
        zero[k] = inverse(motions[body]) @ pose
        proximal.append(body)
        if joint.motion != FIXED:
            movable.append(k)
            motions.append(pose @ _joint_motion(joint, joint.state) @ inverse(zero[k]))
            body = len(motions) - 1
        distal.append(body)
    return ChainBodies(tuple(movable), tuple(proximal), tuple(distal), zero, np.stack(motions))


@dataclass(frozen=True)
class UrdfModel:
    """A URDF document and its mesh files.

    Attributes
    ----------
    text : str
        The URDF (XML).
    files : dict of str to bytes
        Mesh files by their path relative to the URDF's folder (POSIX separators).
    """

    text: str
    files: dict[str, bytes]


def _number(value: float) -> str:
    value = float(value) + 0.0  # -0.0 -> 0.0
    return repr(value)


def _vector(values) -> str:
    return " ".join(_number(v) for v in values)


def roll_pitch_yaw(R: np.ndarray) -> tuple[float, float, float]:
    """URDF's ``rpy`` of a rotation matrix: (roll, pitch, yaw) in radians with R = Rz(yaw)
    Ry(pitch) Rx(roll) (fixed axes x, y, z); at pitch +-pi/2 the roll is 0."""
    R = np.asarray(R, dtype=float)
    pitch = math.atan2(-R[2, 0], math.hypot(R[0, 0], R[1, 0]))
    roll = math.atan2(R[2, 1], R[2, 2]) if math.hypot(R[2, 1], R[2, 2]) > 1e-12 else 0.0
    # the yaw from what is left, R Rx(roll)^T Ry(pitch)^T = Rz(yaw): near pitch +-pi/2 the
    # roll is ill-conditioned, but the yaw taken this way absorbs its error (the rotation is
    # rebuilt to rounding)
    cr, sr, cp, sp = math.cos(roll), math.sin(roll), math.cos(pitch), math.sin(pitch)
    Rx = np.array([[1.0, 0.0, 0.0], [0.0, cr, -sr], [0.0, sr, cr]])
    Ry = np.array([[cp, 0.0, sp], [0.0, 1.0, 0.0], [-sp, 0.0, cp]])
    M = R @ Rx.T @ Ry.T
    return roll, pitch, math.atan2(M[1, 0], M[0, 0])


def _check_name(name: Any, what: str) -> str:
    if not isinstance(name, str) or not name.strip():
        raise InvalidParameterError(f"{what} must be a non-empty string, got {name!r}")
    if any(c in name for c in "\\\0") or name.startswith("/") or ".." in name.split("/"):
        raise InvalidParameterError(
            f"{what} must be a plain name or a relative folder inside the URDF's folder, got "
            f"{name!r}"
        )
    return name


def urdf_model(chain: KinematicChain | KinematicTree, **options: Any) -> UrdfModel:
    """The URDF of ``chain`` (or of a tree: one kinematic tree) and its mesh files, in memory.

    Parameters
    ----------
    chain : KinematicChain or KinematicTree
    name : str, optional
        Robot name (default ``'kinegami_chain'``, ``'kinegami_tree'`` for a tree); also names
        the mesh folder.
    units : {'mm', 'cm', 'm', 'in'}, optional
        Length of one chain unit; default ``'mm'``. The URDF is in metres.
    scale : float, optional
        Extra multiplier (> 0); default 1.
    effort, velocity : float, optional
        ``<limit>`` values of every joint (> 0): N m or N, and rad/s or m/s; default 1 and 1.
    meshes : bool, optional
        Write visual and collision meshes (default True); False gives a single-file URDF
        with the kinematics and inertias only.
    mesh_folder : str, optional
        Folder of the meshes relative to the URDF (default ``'<name>_meshes'``).
    mass_per_area : float, optional
        Areal density of the shell for ``<inertial>``, kg/m^2 (>= 0; default 0.08). 0 leaves
        the inertials out.
    twistPortion : float, optional
        Fraction of a straight part taken by its twist, in [0, 1]; default 0.2.

    Returns
    -------
    UrdfModel

    Raises
    ------
    InvalidTypeError
        If ``chain`` is not a KinematicChain or KinematicTree, or an option is unknown or of
        the wrong type.
    InvalidParameterError
        For a bad option value.
    """
    chain = check_assembly(chain, "URDF")
    parents = _parents(chain)
    tree = is_tree(chain)
    opts = resolve_options(options, URDF_DEFAULTS, "URDF export")
    default_name = "kinegami_tree" if tree else "kinegami_chain"
    name = _check_name(default_name if opts["name"] is None else opts["name"], "name")
    metres = mesh_factor(opts["units"], opts["scale"]) / 1000.0
    effort = check_positive("effort", opts["effort"])
    velocity = check_positive("velocity", opts["velocity"])
    with_meshes = check_bool("meshes", opts["meshes"])
    folder = opts["mesh_folder"]
    folder = _check_name(f"{name}_meshes" if folder is None else folder, "mesh_folder")
    folder = folder.strip("/")
    density = check_nonnegative("mass_per_area", opts["mass_per_area"])
    twist_portion = check_twist_portion(opts["twistPortion"])

    bodies = chain_bodies(chain)
    parts = chain_parts(chain, twistPortion=twist_portion, split_joints=True)
    # Without movable joints, each joint (and the link into it) is its own URDF link, fixed
    # to its parent's (the previous joint's in a chain); otherwise one URDF link per rigid body.
    fixed = not bodies.movable and len(chain.Joints) > 1
    if fixed:
        origins = [bodies.zero_poses[k][:3, 3] for k in range(len(chain.Joints))]
        frames = [np.eye(4) for _ in origins]
        for frame, origin in zip(frames, origins, strict=True):
            frame[:3, 3] = origin
    else:
        frames = [bodies.frame(b) for b in range(bodies.count)]
    to_body = [inverse(frame) for frame in frames]
    body_parts: list[list] = [[] for _ in frames]
    for part in parts:
        if fixed:
            b = part.index
        elif part.is_joint:
            b = (bodies.distal_body if part.side == "distal" else bodies.proximal_body)[part.index]
        else:  # link i lies between joint i-1's distal side and joint i's proximal side
            b = bodies.proximal_body[part.index]
        body_parts[b].append(part.transformed(to_body[b], metres))

    robot = ET.Element("robot", name=name)
    if tree:
        leaves = sum(1 for kids in chain.Children if not kids)
        what = f"tree: {len(chain.Joints)} joints ({leaves} leaves)"
    else:
        what = f"chain: {len(chain.Joints)} joints"
    robot.append(
        ET.Comment(
            f" kinegami {what}, {len(bodies.movable)} movable; "
            f"metres (1 chain unit = {_number(metres)} m); each body frame the Pose of the "
            f"joint that starts it at zero configuration, z along its axis "
        )
    )
    # MuJoCo's URDF importer (in older releases) keeps only the file name of a mesh path
    # unless told not to
    ET.SubElement(ET.SubElement(robot, "mujoco"), "compiler", strippath="false")
    for material, rgba in (("kinegami_joint", _JOINT_RGBA), ("kinegami_link", _LINK_RGBA)):
        ET.SubElement(ET.SubElement(robot, "material", name=material), "color", rgba=rgba)
    files: dict[str, bytes] = {}
    for b in range(len(frames)):
        link = ET.SubElement(robot, "link", name=f"body_{b}")
        if density > 0.0 and body_parts[b]:
            _inertial(link, body_parts[b], density)
        if not with_meshes:
            continue
        for part in body_parts[b]:
            filename = f"{folder}/{part.name}.stl"
            files[filename] = stl_bytes(part.vertices, part.faces, b"kinegami part, metres")
            material = "kinegami_joint" if part.is_joint else "kinegami_link"
            for tag in ("visual", "collision"):
                element = ET.SubElement(link, tag, name=part.name)
                ET.SubElement(element, "origin", xyz="0 0 0", rpy="0 0 0")
                geometry = ET.SubElement(element, "geometry")
                ET.SubElement(geometry, "mesh", filename=filename)
                if tag == "visual":
                    ET.SubElement(element, "material", name=material)
    if fixed:
        for k in range(1, len(frames)):
            element = ET.SubElement(robot, "joint", name=f"joint_{k}", type="fixed")
            ET.SubElement(element, "parent", link=f"body_{parents[k]}")
            ET.SubElement(element, "child", link=f"body_{k}")
            offset = (origins[k] - origins[parents[k]]) * metres
            ET.SubElement(element, "origin", xyz=_vector(offset), rpy="0 0 0")
    for b, k in enumerate(bodies.movable, start=1):
        joint = chain.Joints[k]
        parent = bodies.proximal_body[k]
        pose = bodies.zero_poses[k]
        element = ET.SubElement(
            robot,
            "joint",
            name=f"joint_{k}",
            type="revolute" if joint.motion == REVOLUTE else "prismatic",
        )
        ET.SubElement(element, "parent", link=f"body_{parent}")
        ET.SubElement(element, "child", link=f"body_{b}")
        # the joint frame is the joint's Pose, seen from its parent body's frame: its z is
        # the axis (RTB reads an axis other than z as a rotation: its issues #253, #441)
        relative = inverse(bodies.zero_frame(parent)) @ pose
        ET.SubElement(element, "origin", xyz=_vector(relative[:3, 3] * metres),
                      rpy=_vector(roll_pitch_yaw(relative[:3, :3])))  # fmt: skip
        ET.SubElement(element, "axis", xyz="0 0 1")
        lo, hi = joint.stateRange()
        if joint.motion == PRISMATIC:
            lo, hi = lo * metres, hi * metres
        ET.SubElement(
            element,
            "limit",
            lower=_number(lo),
            upper=_number(hi),
            effort=_number(effort),
            velocity=_number(velocity),
        )
    ET.indent(robot, space="  ")
    text = '<?xml version="1.0" encoding="utf-8"?>\n' + ET.tostring(robot, encoding="unicode")
    return UrdfModel(text + "\n", files)


def _inertial(link: ET.Element, parts: list, density: float) -> None:
    vertices = np.vstack([p.vertices for p in parts])
    offsets = np.cumsum([0] + [p.vertices.shape[0] for p in parts[:-1]])
    faces = np.vstack([p.faces + o for p, o in zip(parts, offsets, strict=True)])
    mass, com, inertia = shell_mass_properties(vertices, faces, density)
    if mass <= 0.0:
        return
    element = ET.SubElement(link, "inertial")
    ET.SubElement(element, "origin", xyz=_vector(com), rpy="0 0 0")
    ET.SubElement(element, "mass", value=_number(mass))
    ET.SubElement(
        element,
        "inertia",
        ixx=_number(inertia[0, 0]),
        ixy=_number(inertia[0, 1]),
        ixz=_number(inertia[0, 2]),
        iyy=_number(inertia[1, 1]),
        iyz=_number(inertia[1, 2]),
        izz=_number(inertia[2, 2]),
    )


def urdf_files(
    chain: KinematicChain | KinematicTree, path: Path, **options: Any
) -> dict[str, bytes]:
    """All files of the URDF export to ``path``, relative to its folder (for the registry).

    The robot name defaults to the file's stem, the mesh folder to ``<stem>_meshes``.
    """
    options = dict(options)
    if options.get("name") is None:
        options["name"] = path.stem
    if options.get("mesh_folder") is None:
        options["mesh_folder"] = f"{path.stem}_meshes"
    model = urdf_model(chain, **options)
    files = {path.name: model.text.encode("utf-8")}
    files.update(model.files)
    return files


def write_urdf(chain: KinematicChain | KinematicTree, stream: TextIO, **options: Any) -> None:
    """Write the URDF text of ``chain`` (or a tree) to ``stream`` (options as for
    :func:`urdf_model`).

    Mesh files cannot go to a stream, so ``meshes`` defaults to False here; use
    ``kinegami.export(chain, "robot.urdf")`` (or :func:`urdf_model`) to get them too.
    """
    options = dict(options)
    options.setdefault("meshes", False)
    stream.write(urdf_model(chain, **options).text)
