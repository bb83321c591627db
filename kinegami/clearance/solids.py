"""The solid parts of a chain (or a tree) in its current configuration (docs/mesh.md), which
meshes, views, URDF and the editor draw.

The model is made of closed triangle meshes, one per *part*, built from the shapes of the
body model (:mod:`kinegami.chain.bodies`) that ``KinematicChain.show()`` also draws, but with the
tube as the n-gon prism it really is (``numSides`` sides, circumradius r) instead of a round
cylinder:

==========================  ========================================================  ==========
part name                   shape                                                     convex
==========================  ========================================================  ==========
``joint_i``                 tip: hull of the n-gon at the open end and a segment of   yes
                            one side's length at the closed end; prismatic joint:
                            the n-gon prism from the proximal frame, length L + state
``joint_i_proximal``,       revolute joint: hull of the proximal (distal) n-gon and   yes
``joint_i_distal``          the hinge segment (extended revolute: with its tube)
``link_i_arc1``,            the elbows of arc 1 (arc 2) of link i: the n-gon swept    no
``link_i_arc2``             along each elbow's two straight halves, mitred at the
                            plane that bisects the turn
``link_i_twist``            the twist fitting: a twisted n-gon prism of length        no
                            ``twistPortion`` tMag turning by the twist's residual
                            angle in [0, 2 pi / n) (the rest is a relabelling)
``link_i_tube``             the rest of the straight part: an n-gon prism             yes
==========================  ========================================================  ==========

A :class:`~kinegami.tree.KinematicTree` has the same parts for every joint i and for the link
into it (``Links[i]``, from the distal frame of joint ``Parents[i]``), named by the tree index;
a chain is the tree whose parents are i - 1, and gives the same parts as before, byte for byte.

Waypoints have no part. Features below ``MESH_TOLERANCE`` r (1e-4 r) are not modelled:
straight parts shorter than that are left out, and the vertices of a swept part closer than
that along the sweep are merged (an elbow whose polygon vertex lies on, or within 1e-4 r of,
the mitre plane has a vanishing side edge). An arc turning less than ``MIN_ARC_ANGLE``
(1e-3 rad) has no part of its own: the neighbouring straight part is stretched to the arc's
far polygon (the surface moves by less than r theta^2 < 1e-6 r). Without a straight part such
an arc is swept on its own, or left out if no vertex moves more than 1e-4 r, so parts with no
straight part between them may be up to 2e-4 r apart.

Every part is a closed, consistently oriented surface (outward normals), so
``trimesh.Trimesh.is_watertight`` and ``is_volume`` hold for each; the link parts have no edge
shorter than 1e-4 r, so they stay closed when a reader merges close vertices. Parts touch (a
link's arc ends on the joint's polygon) but are not merged, so the model as a whole is a set of
closed shells, not one.
"""

from __future__ import annotations

import math
from dataclasses import dataclass
from typing import TYPE_CHECKING, Any

import numpy as np

from kinegami.chain.assembly import JointAssembly
from kinegami.chain.bodies import elbow_rings
from kinegami.chain.joints import Joint
from kinegami.errors import InvalidTypeError
from kinegami.geometry.shapes import regular_polygon
from kinegami.validation import check_twist_portion

if TYPE_CHECKING:  # pragma: no cover
    import trimesh

    from kinegami.chain.links import LinkCSC
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
    "check_assembly",
    "is_tree",
]

#: Smallest feature of the mesh, in units of r: swept vertices closer than this are merged.
#: 1e-4 r keeps every edge well above float32 STL resolution and readers' merge distance
#: (trimesh: 1e-8) for tubes down to r = 1 mm written in metres.
MESH_TOLERANCE = 1e-4
#: Straight segments shorter than this many r get no part.
MIN_SEGMENT_LENGTH = MESH_TOLERANCE
#: Arcs turning less than this (radians) are merged into the neighbouring straight part. An
#: elbow of at least this turn moves its outermost polygon vertex by more than 5e-4 r (five
#: times ``MESH_TOLERANCE``) on each side of its mitre.
MIN_ARC_ANGLE = 1e-3


@dataclass(frozen=True, eq=False)
class MeshPart:
    """One closed triangle mesh of the chain model.

    Attributes
    ----------
    name : str
        ``joint_i``, ``joint_i_proximal``, ``joint_i_distal``, ``link_i_arc1``,
        ``link_i_twist``, ``link_i_tube`` or ``link_i_arc2`` (i = index in the chain).
    vertices : numpy.ndarray, shape (k, 3)
        World coordinates in chain units, at the chain's current configuration.
    faces : numpy.ndarray of int, shape (m, 3)
        Triangles, counter-clockwise seen from outside (outward normals).
    index : int
        The joint index (``joint_*`` parts) or link index (``link_*`` parts).
    side : str
        ``'proximal'``/``'distal'`` for joint halves, ``''`` for a whole joint, or the piece of
        the link: ``'arc1'``, ``'twist'``, ``'tube'``, ``'arc2'``.
    rings : numpy.ndarray or None, shape (m, n, 3)
        For link parts, the n-gons the surface is swept through, in order (world, chain
        units); None for joints (convex hulls).
    """

    name: str
    vertices: np.ndarray
    faces: np.ndarray
    index: int
    side: str
    rings: np.ndarray | None = None

    @property
    def is_joint(self) -> bool:
        """True for joint parts, False for link parts."""
        return self.name.startswith("joint_")

    def transformed(self, T: np.ndarray, factor: float = 1.0) -> MeshPart:
        """The part moved by the 4x4 rigid transform ``T`` and then scaled by ``factor``."""

        def move(points):
            return (points @ T[:3, :3].T + T[:3, 3]) * factor

        rings = None if self.rings is None else move(self.rings)
        return MeshPart(self.name, move(self.vertices), self.faces, self.index, self.side, rings)

    def to_trimesh(self, factor: float = 1.0) -> trimesh.Trimesh:
        """The part as a ``trimesh.Trimesh`` (vertices times ``factor``, not processed)."""
        import trimesh

        return trimesh.Trimesh(self.vertices * factor, self.faces, process=False)


# --- building blocks -----------------------------------------------------------------------


def _signed_volume(vertices: np.ndarray, faces: np.ndarray) -> float:
    tri = vertices[faces]
    return float(np.einsum("ij,ij->i", tri[:, 0], np.cross(tri[:, 1], tri[:, 2])).sum() / 6.0)


def _outward(vertices: np.ndarray, faces: np.ndarray) -> np.ndarray:
    """``faces`` reversed if they enclose a negative volume (consistent winding assumed)."""
    if _signed_volume(vertices, faces) < 0.0:
        return np.ascontiguousarray(faces[:, ::-1])
    return faces


def _weld_along_sweep(rings: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """Vertex ids of ``rings`` (m, n, 3) after merging each vertex into the last kept one of its
    column (vertex k of every ring) while they are at most ``tol`` apart.

    Returns ``(vertices, ids)``, ids of shape (m, n). Only vertices of the same column are
    merged, and every kept vertex is at most ``tol`` from the ones merged into it. Merging
    vertex k of ring i into ring i - 1 collapses a side edge of the sweep; the triangles
    between two columns then zip two polylines, so the surface stays a closed 2-manifold.
    """
    m, n = rings.shape[0], rings.shape[1]
    ids = np.empty((m, n), dtype=np.int64)
    ids[0] = np.arange(n)
    kept = [rings[0]]
    last = rings[0].copy()
    count = n
    for i in range(1, m):
        new = np.linalg.norm(rings[i] - last, axis=1) > tol
        ids[i] = ids[i - 1]
        k = int(np.count_nonzero(new))
        if k:
            ids[i, new] = np.arange(count, count + k)
            last[new] = rings[i, new]
            kept.append(rings[i, new])
            count += k
    return np.vstack(kept).astype(float), ids


def _sweep(rings: np.ndarray, tol: float) -> tuple[np.ndarray, np.ndarray] | None:
    """Closed surface through polygons ``rings`` (m, n, 3): sides and both end caps.

    Vertex i of every ring is joined to vertex i of the next; vertices of one column closer
    than ``tol`` along the sweep are merged (:func:`_weld_along_sweep`) and the triangles
    that collapse are dropped. The caps are fans from the column that moves farthest, which
    is never merged into a single point, so no fan diagonal is shared by both caps. Returns
    None when every column stays within ``tol`` of its first vertex (no volume).
    """
    n = rings.shape[1]
    travel = np.linalg.norm(rings - rings[0], axis=2).max(axis=0)
    apex = int(np.argmax(travel))
    if travel[apex] <= tol:
        return None
    vertices, idx = _weld_along_sweep(rings, tol)
    nxt = np.roll(idx, -1, axis=1)
    a, b = idx[:-1], nxt[:-1]
    c, d = nxt[1:], idx[1:]
    sides = np.concatenate(
        [np.stack([a, b, c], axis=-1).reshape(-1, 3), np.stack([a, c, d], axis=-1).reshape(-1, 3)]
    )
    order = (apex + np.arange(n)) % n
    k = np.arange(1, n - 1)
    head, tail = idx[0, order], idx[-1, order]
    first = np.stack([np.full_like(k, head[0]), head[k + 1], head[k]], axis=1)
    last = np.stack([np.full_like(k, tail[0]), tail[k], tail[k + 1]], axis=1)
    faces = np.concatenate([sides, first, last]).astype(np.int64)
    distinct = (faces[:, 0] != faces[:, 1]) & (faces[:, 1] != faces[:, 2])
    distinct &= faces[:, 0] != faces[:, 2]
    faces = faces[distinct]
    return vertices, _outward(vertices, faces)


def _hull(points: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    """Convex hull of ``points`` as (vertices, outward faces)."""
    from trimesh.convex import convex_hull

    hull = convex_hull(np.asarray(points, dtype=float))
    vertices = np.array(hull.vertices, dtype=float)
    faces = np.array(hull.faces, dtype=np.int64)
    return vertices, _outward(vertices, faces)


# --- joints --------------------------------------------------------------------------------


def joint_parts(joint: Joint, index: int, split: bool = False) -> list[MeshPart]:
    """The parts of one joint at its current state (world coordinates, chain units).

    Parameters
    ----------
    joint : Joint
    index : int
        Its index in the chain (used in the part names).
    split : bool
        Also split a prismatic joint into two halves that move with the bodies on either
        side (``joint_i_proximal``: proximal frame to the centre, length L/2;
        ``joint_i_distal``: centre + state to the distal frame, length L/2), as the URDF needs.
        Revolute joints are always two halves.
    """
    name = f"joint_{index}"
    return [MeshPart(f"{name}_{piece.side}" if piece.side else name, *_hull(piece.points), index,
                     piece.side)
            for piece in joint.body_pieces(split)]  # fmt: skip


# --- links ---------------------------------------------------------------------------------


def _roll_count(twist: float, n: int, nearest: bool) -> int:
    """Whole 2 pi / n steps of ``twist``: floor (twist fitting, residual in [0, 2 pi / n)) or
    nearest (a straight tube whose end polygon is the start polygon up to round-off)."""
    step = 2.0 * math.pi / n
    if nearest:
        return int(round(twist / step)) % n
    alpha = twist % (2.0 * math.pi)
    return min(int(math.floor(alpha / step)), n - 1)


def link_parts(
    link: LinkCSC, index: int, numSides: int, twistPortion: float = 0.2
) -> list[MeshPart]:
    """The parts of one link (world coordinates, chain units): arc 1, twist, tube, arc 2.

    The straight part from q1 to q2 gets a twist of length ``twistPortion * tMag`` first when
    the link has a twist fitting (|twistAngle| > 0.01), as in the crease pattern; the twisted
    prism joins vertex k of the start polygon to the end polygon's vertex that is vertex k
    turned by the residual angle in [0, 2 pi / n). A twist that leaves less than
    ``MIN_SEGMENT_LENGTH`` r of tube takes the whole straight part.

    An arc turning less than ``MIN_ARC_ANGLE`` has no part when the link has a straight part:
    that part then starts (ends) on the link's start (end) polygon instead of the arc's other
    end. Without a straight part such an arc is swept on its own, or left out when no vertex
    moves more than ``MESH_TOLERANCE`` r.
    """
    n, r = numSides, link.r
    tol = MESH_TOLERANCE * r
    arc1, arc2 = link.elbows1, link.elbows2
    u = np.asarray(link.path.tUnit, dtype=float)
    length = float(link.path.tMag)
    merge1 = length > tol and arc1.angle < MIN_ARC_ANGLE
    merge2 = length > tol and arc2.angle < MIN_ARC_ANGLE
    near = regular_polygon(link.start_frame if merge1 else link.arc1_end_frame, r, n)
    end = regular_polygon(link.arc2_start_frame, r, n)
    far = regular_polygon(link.end_frame, r, n) if merge2 else end
    twist_length = twistPortion * length if link.hasTwist else 0.0
    straight = []  # (side, near polygon, far polygon, roll of the far polygon)
    if twist_length > tol:
        K = _roll_count(link.twistAngle, n, nearest=False)
        rest = length - twist_length
        if rest > tol:
            mid = end - rest * u
            straight = [("twist", near, mid, K), ("tube", mid, far, 0)]
        else:
            straight = [("twist", near, far, K)]
    elif length > tol:
        K = _roll_count(link.twistAngle, n, nearest=not link.hasTwist)
        straight = [("tube", near, far, K)]

    parts = []

    def add(side: str, rings: np.ndarray | None) -> None:
        mesh = None if rings is None else _sweep(rings, tol)
        if mesh is not None:
            parts.append(MeshPart(f"link_{index}_{side}", *mesh, index, side, rings))

    if not merge1:
        add("arc1", elbow_rings(arc1, n))
    for side, first, last, K in straight:
        add(side, np.stack([first, np.roll(last, K, axis=0)]))
    if not merge2:
        add("arc2", elbow_rings(arc2, n))
    return parts


# --- whole chain ---------------------------------------------------------------------------


def check_assembly(chain: Any, fmt: str) -> KinematicChain | KinematicTree:
    """``chain`` if it is a KinematicChain or a KinematicTree, else an InvalidTypeError."""
    if not isinstance(chain, JointAssembly):
        raise InvalidTypeError(
            f"the {fmt} exporter needs a KinematicChain or a KinematicTree, got "
            f"{type(chain).__name__}"
        )
    return chain


def is_tree(obj: Any) -> bool:
    """True for a tree that branches somewhere (a tree whose parents are i - 1 is a chain and
    gives the chain's files)."""
    parents = tuple(obj.Parents)
    return parents != tuple(range(-1, len(parents) - 1))


def chain_parts(
    chain: KinematicChain | KinematicTree,
    *,
    twistPortion: float = 0.2,
    split_joints: bool = False,
) -> list[MeshPart]:
    """All parts of the chain (or tree) in its current configuration, in order along the tube
    (for a tree: in index order, each joint after the link into it from its parent).

    Parameters
    ----------
    chain : KinematicChain or KinematicTree
    twistPortion : float, optional
        Fraction of each straight part taken by its twist fitting, in [0, 1] (as for
        ``creasePattern``); default 0.2.
    split_joints : bool, optional
        Split prismatic joints into two halves (see :func:`joint_parts`).

    Returns
    -------
    list of MeshPart
        World coordinates, chain units: joint 0, link 1, joint 1, link 2, ... (link i runs
        from joint ``Parents[i]`` to joint i).
    """
    chain = check_assembly(chain, "mesh")
    twistPortion = check_twist_portion(twistPortion)
    parts = joint_parts(chain.Joints[0], 0, split_joints)
    for i in range(1, len(chain.Joints)):
        parts += link_parts(chain.Links[i], i, chain.numSides, twistPortion)
        parts += joint_parts(chain.Joints[i], i, split_joints)
    return parts
