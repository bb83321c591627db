"""3D matplotlib view of a kinematic chain or tree: ``KinematicChain.show`` and
``KinematicTree.show`` (docs/theory/chain.md §6).

Nothing here assumes that joint i follows joint i - 1: every joint is drawn at its own frames
and every link ``Links[i]`` along its own path, which runs from the distal frame of joint
``Parents[i]`` (i - 1 in a chain) to joint i, so a tree's branches are drawn from the joint
they leave. ``showCollisions`` asks the object for its own ``clearance()`` (the tree's pair
rule for a tree) and names parts by their index (:func:`kinegami.clearance.solids.chain_parts`).

The geometry comes from :mod:`kinegami.viz.chain_geometry`; this module only turns it into
matplotlib artists, one collection per kind of thing (joint bodies, elbows, tubes, ...), each
tagged with a ``gid`` (see :data:`ARTIST_GIDS`) so scripts and tests can find it. Defaults come
from :mod:`kinegami.viz.style`. matplotlib is imported only when a chain is drawn.
"""

from __future__ import annotations

import re
from typing import TYPE_CHECKING, Any

import numpy as np

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.validation import (
    check_bool,
    check_in_range,
    check_positive,
    resolve_options,
)
from kinegami.viz import chain_geometry as geo
from kinegami.viz import style
from kinegami.viz._backend import show_if_interactive
from kinegami.viz.scale import check_units, length_text, nice_length, unit_text

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.axes3d import Axes3D

    from kinegami.chain.model import KinematicChain
    from kinegami.tree.model import KinematicTree

__all__ = [
    "show_chain",
    "show_fabrication",
    "resolve_chain_options",
    "ARTIST_GIDS",
    "CHAIN_PLOT_OPTIONS",
]

#: Names of all options accepted by ``show_chain`` (and ``KinematicChain.show``).
CHAIN_PLOT_OPTIONS = tuple(style.CHAIN_PLOT_DEFAULTS)

#: The ``gid`` given to each kind of artist drawn.
ARTIST_GIDS = {
    "joint-bodies": "joint surfaces (revolute hulls, prismatic prisms, tips)",
    "joint-axes": "dashed axes of motion of revolute and prismatic joints",
    "joint-frame-x": "x arrows of joint frames",
    "joint-frame-y": "y arrows of joint frames",
    "joint-frame-z": "z arrows of joint frames",
    "joint-origins-proximal": "proximal frame origins",
    "joint-origins-center": "Pose origins",
    "joint-origins-distal": "distal frame origins",
    "link-elbows": "elbow surfaces (2 * sides quadrilaterals per elbow)",
    "link-tubes": "straight tubes (sides quadrilaterals per tube)",
    "link-path": "link centrelines, each from its parent joint (NaN between links)",
    "link-path-markers": "q1, q2 of every link",
    "path-circles-start": "turning circles of arc 1",
    "path-circles-end": "turning circles of arc 2",
    "link-pose-a": "a arrows of elbow frames",
    "link-pose-b": "b arrows of elbow frames",
    "link-pose-c": "c arrows of elbow frames",
    "link-rotation-axes": "rotation axes of the elbows",
    "link-tangents": "start and end tangents of each link",
    "joint-spheres": "bounding balls of the joints",
    "chain-sphere": "bounding ball of the chain or tree (wireframe)",
    "junctions": "a tree's printed junction connectors (showJunctions)",
    "global-frame-x": "world x arrow",
    "global-frame-y": "world y arrow",
    "global-frame-z": "world z arrow",
    "ground-plane": "the plane z = 0",
    "collision-parts": "the colliding parts (showCollisions): their mesh parts, in red",
    "collision-lines": "closest points of every colliding pair, joined (NaN between pairs)",
    "collision-points": "the closest points themselves (showCollisions)",
    "scale-bar": "a bar of a round length with end ticks, on the floor of the drawing's box "
    "(showScaleBar, without showAxisGrids)",
}

_BOOL_OPTIONS = (
    "showJointPoses",
    "showJointSurface",
    "showLinkSurface",
    "showLinkPath",
    "showPathCircles",
    "showLinkPoses",
    "showSpheres",
    "showGlobalFrame",
    "showGroundPlane",
    "showAxisGrids",
    "showCollisions",
    "showJunctions",
    "showScaleBar",
)
_COLOR_OPTIONS = (
    "xColor",
    "yColor",
    "zColor",
    "proximalColor",
    "centerColor",
    "distalColor",
    "jointColor",
    "linkColor",
    "junctionColor",
    "pathColor",
    "sphereColor",
    "groundPlaneColor",
)
_SCALE_OPTIONS = ("jointAxisScale", "globalAxisScale", "groundPlaneScale")


def resolve_chain_options(options: dict[str, Any]) -> dict[str, Any]:
    """All options of ``show_chain``: the defaults of :mod:`kinegami.viz.style` updated by
    ``options``, checked.

    Raises InvalidTypeError for an unknown option name or a value of the wrong type, and
    InvalidParameterError for a value out of range.
    """
    opts = resolve_options(options, style.CHAIN_PLOT_DEFAULTS, "show()")
    for name in _BOOL_OPTIONS:
        opts[name] = check_bool(name, opts[name])
    opts["block"] = check_bool("block", opts["block"], none=True)
    from matplotlib.colors import is_color_like

    for name in _COLOR_OPTIONS:
        if not is_color_like(opts[name]):
            raise InvalidParameterError(f"{name} must be a matplotlib colour, got {opts[name]!r}")
    for name in _SCALE_OPTIONS:
        check_positive(name, opts[name])
    check_in_range("surfaceOpacity", opts["surfaceOpacity"], 0.0, 1.0, True, True)
    opts["units"] = check_units(opts["units"])
    ax = opts["ax"]
    if ax is not None and getattr(ax, "name", None) != "3d":
        raise InvalidTypeError(
            f"ax must be a 3D matplotlib Axes (projection='3d'), got {type(ax).__name__}"
        )
    return opts


#: Direction towards the light of shaded faces: mplot3d's own (azimuth 225, altitude 19.4712 deg).
_LIGHT_AZIMUTH, _LIGHT_ALTITUDE = 225.0, 19.4712


def _shading(normals: np.ndarray) -> np.ndarray:
    """(q,) brightness of faces with these normals, as mplot3d shades them: 0.3 facing away from
    the light, 1 facing it; 0.65 for a face without a normal."""
    from matplotlib.colors import LightSource

    light = LightSource(azdeg=_LIGHT_AZIMUTH, altdeg=_LIGHT_ALTITUDE).direction
    length = np.linalg.norm(normals, axis=1)
    with np.errstate(invalid="ignore", divide="ignore"):
        cosine = np.where(length > 0.0, (normals @ light) / length, 0.0)
    return 0.3 + 0.7 * (cosine + 1.0) / 2.0


def _shaded(rgba, shading):
    """``rgba`` with its colour (not its alpha) scaled by each face's ``shading``."""
    if np.isscalar(shading):
        return rgba
    colours = np.tile(np.asarray(rgba, dtype=float), (len(shading), 1))
    colours[:, :3] *= shading[:, None]
    return colours


class _Scene:
    """Adds artists to a 3D axes and remembers the extent of everything added."""

    def __init__(self, ax):
        from mpl_toolkits.mplot3d import art3d

        self.ax = ax
        self.art3d = art3d
        self.points: list[np.ndarray] = []
        self.gids: list[str] = []  # the gid of the artist of each entry of points

    def _extent(self, pts, gid: str) -> None:
        pts = np.asarray(pts, dtype=float).reshape(-1, 3)
        pts = pts[np.all(np.isfinite(pts), axis=1)]
        if len(pts):
            self.points.append(np.stack([pts.min(axis=0), pts.max(axis=0)]))
            self.gids.append(gid)

    def polygons(self, polys, gid, facecolor, alpha, edgecolor="none", linewidth=0.0, shade=False):
        """One Poly3DCollection of a list of (k, 3) polygons (or a (q, k, 3) array)."""
        from matplotlib.colors import to_rgba

        if len(polys) == 0:
            return None
        for poly in polys if isinstance(polys, list) else [polys]:
            self._extent(poly, gid)
        shading = _shading(geo.face_normals(polys)) if shade else 1.0
        kwargs = {
            "facecolors": _shaded(to_rgba(facecolor, alpha), shading),
            "linewidths": linewidth,
        }
        if edgecolor != "none":
            kwargs["edgecolors"] = _shaded(to_rgba(edgecolor, min(1.0, 2.0 * alpha)), shading)
        elif not shade:
            kwargs["edgecolors"] = "none"
        # shaded here, not by matplotlib: its normal from three vertices is noise on a face with
        # two coincident vertices (so the colour changed with the CPU's rounding)
        collection = self.art3d.Poly3DCollection(list(polys), shade=False, **kwargs)
        collection.set_gid(gid)
        self.ax.add_collection3d(collection)
        return collection

    def segments(self, segs, gid, color, linewidth=1.0, linestyle="-"):
        """One Line3DCollection of (k, 3) polylines."""
        if len(segs) == 0:
            return None
        for seg in segs:
            self._extent(seg, gid)
        collection = self.art3d.Line3DCollection(
            list(segs), colors=color, linewidths=linewidth, linestyles=linestyle
        )
        collection.set_gid(gid)
        self.ax.add_collection3d(collection)
        return collection

    def polyline(self, pieces, gid, color, **kwargs):
        """One Line3D through the (k, 3) pieces, separated by NaN rows."""
        pieces = [np.asarray(p, dtype=float) for p in pieces if p is not None and len(p)]
        if not pieces:
            return None
        gap = np.full((1, 3), np.nan)
        pts = np.vstack([row for p in pieces for row in (p, gap)][:-1])
        self._extent(pts, gid)
        (line,) = self.ax.plot(pts[:, 0], pts[:, 1], pts[:, 2], color=color, **kwargs)
        line.set_gid(gid)
        return line

    def arrows(self, origins, vectors, gid, color, linewidth=1.0):
        """One quiver of arrows from ``origins`` (k, 3) along ``vectors`` (k, 3)."""
        if len(origins) == 0:
            return None
        self._extent(origins, gid)
        self._extent(origins + vectors, gid)
        o, v = origins, vectors
        quiver = self.ax.quiver(
            o[:, 0],
            o[:, 1],
            o[:, 2],
            v[:, 0],
            v[:, 1],
            v[:, 2],
            color=color,
            arrow_length_ratio=0.25,
            linewidths=linewidth,
        )
        quiver.set_gid(gid)
        return quiver

    def markers(self, pts, gid, color, marker="o", size=4.0):
        """One Line3D of unconnected markers."""
        pts = np.asarray(pts, dtype=float).reshape(-1, 3)
        if len(pts) == 0:
            return None
        self._extent(pts, gid)
        (line,) = self.ax.plot(
            pts[:, 0],
            pts[:, 1],
            pts[:, 2],
            linestyle="",
            marker=marker,
            color=color,
            markersize=size,
        )
        line.set_gid(gid)
        return line


# --- the parts of the picture ---
def _draw_joint_bodies(scene, chain, opts):
    faces = [face for joint in chain.Joints for face in geo.joint_body_faces(joint)]
    scene.polygons(
        faces,
        "joint-bodies",
        opts["jointColor"],
        opts["surfaceOpacity"],
        edgecolor=opts["jointColor"],
        linewidth=0.5,
        shade=True,
    )
    axes = [
        seg
        for joint in chain.Joints
        if (seg := geo.joint_axis_segment(joint, opts["jointAxisScale"])) is not None
    ]
    scene.segments(
        axes, "joint-axes", style.jointAxisColor, linewidth=1.0, linestyle=style.jointAxisLineStyle
    )


def _draw_junctions(scene, chain, opts):
    """A tree's printed junction connectors (kinegami.fabrication.sheets.fabricate), shaded; nothing
    for a chain. A connector that cannot be made (a socket that does not fit its link, or
    manifold3d missing) is left out with a warning saying why."""
    import warnings

    from kinegami.chain.model import KinematicChain

    if isinstance(chain, KinematicChain) or not any(len(c) > 1 for c in chain.Children):
        return
    from kinegami.errors import KinegamiError
    from kinegami.fabrication.sheets import fabricate

    try:
        fabrication = fabricate(chain)
        meshes = [fabrication.connector(k) for k in range(len(fabrication.junctions))]
    except KinegamiError as error:
        warnings.warn(f"showJunctions: the junctions are not drawn: {error}", stacklevel=4)
        return
    _draw_meshes(scene, meshes, opts)


def _draw_meshes(scene, meshes, opts):
    """Junction connector meshes (trimeshes, world frame), shaded, as the ``junctions`` artist."""
    faces = [mesh.vertices[mesh.faces] for mesh in meshes]
    scene.polygons(np.concatenate(faces), "junctions", opts["junctionColor"],
                   min(1.0, opts["surfaceOpacity"] + 0.3), shade=True)  # fmt: skip


def _draw_joint_poses(scene, chain, opts):
    kinds = ("proximal", "center", "distal")
    frames: dict[str, list[np.ndarray]] = {kind: [] for kind in kinds}
    lengths: dict[str, list[float]] = {kind: [] for kind in kinds}
    for joint in chain.Joints:
        for kind, frame in geo.joint_frames(joint).items():
            frames[kind].append(frame)
            lengths[kind].append(joint.r)
    all_frames = np.array([f for kind in kinds for f in frames[kind]])
    all_lengths = np.array([v for kind in kinds for v in lengths[kind]])
    origins, arrows = geo.frame_axes(all_frames, 1.0)
    arrows = arrows * all_lengths[None, :, None]
    for axis, name in enumerate("xyz"):
        scene.arrows(origins, arrows[axis], f"joint-frame-{name}", opts[f"{name}Color"])
    for kind in kinds:
        if frames[kind]:
            pts = np.array(frames[kind])[:, :3, 3]
            scene.markers(pts, f"joint-origins-{kind}", opts[f"{kind}Color"])


def _drawn_links(chain):
    """Links with a non-empty path (the root's empty link is skipped), in index order; link i
    starts at the distal frame of joint ``Parents[i]``."""
    return [link for link in chain.Links if link.path.length > 0.0]


def _draw_link_surfaces(scene, chain, opts):
    sides = style.linkSurfaceSides
    links = _drawn_links(chain)
    grids = [geo.link_elbow_grids(link, sides) for link in links]
    grids = [g for g in grids if len(g)]
    if grids:
        quads = geo.grid_quads(np.concatenate(grids))
        scene.polygons(quads, "link-elbows", opts["linkColor"], opts["surfaceOpacity"], shade=True)
    tubes = [t for link in links if (t := geo.tube_grid(link, sides)) is not None]
    if tubes:
        quads = geo.grid_quads(np.stack(tubes))
        scene.polygons(quads, "link-tubes", opts["linkColor"], opts["surfaceOpacity"], shade=True)


def _draw_link_path(scene, chain, opts):
    links = _drawn_links(chain)
    scene.polyline(
        [geo.link_centreline(link) for link in links], "link-path", opts["pathColor"], linewidth=1.0
    )
    ends = [q for link in links for q in (link.path.q1, link.path.q2)]
    scene.markers(ends, "link-path-markers", opts["pathColor"], marker=style.pathMarker, size=6)


def _draw_path_circles(scene, chain):
    circles = [geo.turning_circles(link) for link in _drawn_links(chain)]
    start_color, end_color = style.pathCircleColors
    scene.polyline([c[0] for c in circles], "path-circles-start", start_color, linewidth=0.8)
    scene.polyline([c[1] for c in circles], "path-circles-end", end_color, linewidth=0.8)


def _draw_link_poses(scene, chain, opts) -> bool:
    """Elbow frames, rotation axes and tangents; True if any elbow frame was drawn."""
    links = _drawn_links(chain)
    arcs = [arc for link in links for arc in (link.elbows1, link.elbows2) if arc.count]
    if arcs:
        frames = np.concatenate([geo.elbow_pose_frames(arc) for arc in arcs])
        lengths = np.concatenate([np.full(4 * arc.count, arc.r) for arc in arcs])
        origins, arrows = geo.frame_axes(frames, 1.0)
        arrows = arrows * lengths[None, :, None]
        for axis, (name, color) in enumerate(zip("abc", style.linkPoseColors, strict=True)):
            scene.arrows(origins, arrows[axis], f"link-pose-{name}", color)
        axes = np.concatenate([geo.elbow_rotation_axes(arc) for arc in arcs])
        scene.segments(
            list(axes), "link-rotation-axes", style.rotationAxisColor, linewidth=1.0, linestyle=":"
        )
    if links:
        origins = np.array([p for link in links for p in (link.path.p1, link.path.p2)])
        tangents = np.array([link.r * d for link in links for d in (link.path.d1, link.path.d2)])
        scene.arrows(origins, tangents, "link-tangents", opts["pathColor"])
    return bool(arcs)


def _draw_spheres(scene, chain, opts):
    grids = [geo.sphere_grid(ball.c, ball.r) for ball in (j.boundingBall() for j in chain.Joints)]
    scene.polygons(
        geo.grid_quads(np.stack(grids)),
        "joint-spheres",
        opts["sphereColor"],
        style.jointSphereOpacity,
    )
    ball = chain.boundingBall
    grid = geo.sphere_grid(ball.c, ball.r, parallels=12, meridians=24)
    parallels = [np.vstack([row, row[:1]]) for row in grid[1:-1]]
    meridians = [grid[:, j] for j in range(grid.shape[1])]
    scene.segments(parallels + meridians, "chain-sphere", opts["sphereColor"], linewidth=0.3)


def _draw_global_frame(scene, chain, opts):
    length = opts["globalAxisScale"] * chain.r
    origin = np.zeros((1, 3))
    for axis, name in enumerate("xyz"):
        vector = np.zeros((1, 3))
        vector[0, axis] = length
        scene.arrows(origin, vector, f"global-frame-{name}", opts[f"{name}Color"], linewidth=1.5)


def _draw_ground_plane(scene, chain, opts):
    half = opts["groundPlaneScale"] * chain.r
    quads = geo.ground_plane_quads(half, chain.r)
    alpha = opts["surfaceOpacity"] * style.groundPlaneOpacityFactor
    scene.polygons(
        quads,
        "ground-plane",
        opts["groundPlaneColor"],
        alpha,
        edgecolor=opts["groundPlaneColor"],
        linewidth=0.2,
    )


_JOINT_LABEL = re.compile(r"joint (\d+), ")
_LINK_LABEL = re.compile(r"link (\d+), (.*)")
_ELBOW_ORDINAL = re.compile(r"(\d+)(st|nd|rd|th) elbow|(\w+) elbow")


def _labelled_parts(chain, label: str, parts) -> list:
    """The mesh parts (:func:`kinegami.clearance.solids.chain_parts`) of a part named in words by
    the clearance engine ("link 3, second elbow", "joint 5, RevoluteJoint, distal half"): the
    arc that holds the elbow, the twist or tube, the joint or its half. Falls back to every
    part of the chain element when the named piece has no mesh part of its own (an arc too
    small to be modelled)."""
    from kinegami.chain.bodies import ORDINALS

    link = _LINK_LABEL.match(label)
    if link:
        index, piece = int(link.group(1)), link.group(2)
        mine = [p for p in parts if not p.is_joint and p.index == index]
        side = {"twist": "twist", "straight tube": "tube"}.get(piece)
        if side is None and (elbow := _ELBOW_ORDINAL.match(piece)):
            if elbow.group(1):
                k = int(elbow.group(1))
            else:
                k = ORDINALS.index(elbow.group(3)) + 1
            side = "arc1" if k <= chain.Links[index].elbows1.count else "arc2"
    else:
        joint = _JOINT_LABEL.match(label)
        if joint is None:
            return []
        index = int(joint.group(1))
        mine = [p for p in parts if p.is_joint and p.index == index]
        side = next((h for h in ("proximal", "distal") if label.endswith(f", {h} half")), "")
    chosen = [p for p in mine if p.side == side]
    return chosen or mine


def _clearance_title(report) -> str:
    if report.closest is None:
        return "clearance: no parts far enough apart along the tube to collide"
    if report.ok:
        return f"clearance: {report.min_clearance:.3g} (clear)"
    count = report.pair_count
    return (
        f"clearance: {report.min_clearance:.3g} ({count} colliding pair{'s' if count != 1 else ''})"
    )


def _draw_collisions(scene, chain) -> str:
    """The colliding pairs of ``chain.clearance()`` (a tree's: ``tree.clearance()``) in red;
    returns the title text."""
    report = chain.clearance()
    if report.pairs:
        from kinegami.clearance.solids import chain_parts

        parts = chain_parts(chain)
        chosen: dict[str, object] = {}
        for pair in report.pairs:
            for label in (pair.first, pair.second):
                for part in _labelled_parts(chain, label, parts):
                    chosen[part.name] = part
        faces = [mesh.vertices[mesh.faces] for mesh in chosen.values()]
        if faces:
            triangles = np.concatenate(faces)
            scene.polygons(
                triangles,
                "collision-parts",
                style.collisionColor,
                style.collisionOpacity,
                shade=True,
            )
        segments = [np.array(pair.points, dtype=float) for pair in report.pairs]
        scene.polyline(segments, "collision-lines", style.collisionColor, linewidth=2.5)
        scene.markers(np.concatenate(segments), "collision-points", style.collisionColor, size=6.0)
    return _clearance_title(report)


def _legend(ax, opts, frame_axes: bool, link_axes: bool):
    from matplotlib.lines import Line2D

    handles = []
    if frame_axes:
        handles += [Line2D([], [], color=opts[f"{n}Color"], label=rf"$\hat{{{n}}}$") for n in "xyz"]
    if link_axes:
        handles += [
            Line2D([], [], color=color, label=rf"$\hat{{{n}}}$")
            for n, color in zip("abc", style.linkPoseColors, strict=True)
        ]
    if handles:
        ax.legend(handles=handles, loc="upper right")


#: Artists that reach past the robot (lines of reference, balls, the plane): the scale bar is
#: placed under the rest.
_NOT_THE_ROBOT = ("joint-axes", "link-rotation-axes", "joint-spheres", "chain-sphere",
                  "global-frame-x", "global-frame-y", "global-frame-z", "ground-plane")  # fmt: skip


def _draw_scale_bar(scene, units: str | None) -> None:
    """A bar of a round length (1, 2 or 5 times a power of ten, at most 0.3 of the robot's
    largest extent) under the robot, centred below the box around its drawn parts, along that
    box's longer horizontal side, with end ticks and its length written past its end."""
    boxes = [b for b, gid in zip(scene.points, scene.gids, strict=True)
             if gid not in _NOT_THE_ROBOT] or scene.points  # fmt: skip
    if not boxes:
        return
    stacked = np.vstack(boxes)
    low, high = stacked.min(axis=0), stacked.max(axis=0)
    span = float((high - low).max())
    if span <= 0.0:
        return
    length = nice_length(0.3 * span)
    axis = 0 if high[0] - low[0] >= high[1] - low[1] else 1
    start = 0.5 * (low + high)
    start[2] = low[2]
    start[axis] -= 0.5 * length
    start[1 - axis] = low[1] if axis == 0 else high[0]  # the front edge in the default view
    end = start.copy()
    end[axis] += length
    tick = np.array([0.0, 0.0, 0.08 * length])
    pieces = [np.array([start, end]), np.array([start, start + tick]), np.array([end, end + tick])]
    scene.polyline(pieces, "scale-bar", "black", linewidth=1.5)
    beyond = end.copy()
    beyond[axis] += 0.1 * length
    label = scene.ax.text(*beyond, length_text(length, units), ha="left", va="center",
                          fontsize=9)  # fmt: skip
    label.set_gid("scale-bar-label")


def _set_equal_limits(ax, scene, had_data: bool, r: float):
    """Limits around everything drawn and a box aspect equal to the data ranges."""
    boxes = list(scene.points)
    if had_data:
        limits = np.array([ax.get_xlim3d(), ax.get_ylim3d(), ax.get_zlim3d()]).T
        boxes.append(limits)
    if not boxes:
        return
    stacked = np.vstack(boxes)
    low, high = stacked.min(axis=0), stacked.max(axis=0)
    pad = 0.02 * float((high - low).max()) + 0.1 * r
    low, high = low - pad, high + pad
    ax.set_xlim3d(low[0], high[0])
    ax.set_ylim3d(low[1], high[1])
    ax.set_zlim3d(low[2], high[2])
    ax.set_box_aspect(tuple(high - low), zoom=1.15)


def show_chain(chain: KinematicChain | KinematicTree, **options) -> tuple[Figure, Axes3D]:
    """Draw a chain or a tree in 3D with matplotlib (docs/theory/chain.md §6).

    Parameters
    ----------
    chain : the KinematicChain or KinematicTree to draw (a tree's links from their parents;
        ``showCollisions`` uses ``tree.clearance()``).
    **options : see :data:`kinegami.viz.style.CHAIN_PLOT_DEFAULTS` for names and defaults.
        Lengths scale with the tube radius r: frames are r long, axes of motion
        p -+ jointAxisScale r z, the world frame globalAxisScale r, the ground plane
        [-groundPlaneScale r, groundPlaneScale r]^2 in cells of r. ``ax`` draws into an existing
        3D axes; ``block`` is passed to ``plt.show``. ``units`` (``'mm'``, ``'cm'``, ``'m'``,
        ``'in'``; a design file's ``units``) names the unit of the lengths in the axis labels
        (``"x (mm)"``) and on the scale bar; None (default) says ``units of r``. The scale bar
        (``showScaleBar``, default True) is drawn when the axes are not (``showAxisGrids``
        False): a bar of a round length on the floor of the drawing's box, labelled
        ``"20 mm"``.

    Returns
    -------
    (fig, ax) : the matplotlib Figure and the Axes3D drawn into. ``plt.show`` is called only
        when this function created the figure and the backend is interactive.

    Examples
    --------
    >>> fig, ax = chain.show(showGlobalFrame=True)  # doctest: +SKIP
    >>> fig.savefig("chain.png")  # doctest: +SKIP
    >>> fig, ax = hand.show(showCollisions=True)  # a KinematicTree  # doctest: +SKIP
    """
    return _show(chain, resolve_chain_options(options))


def show_fabrication(fabrication, **options) -> tuple[Figure, Axes3D]:
    """Draw a tree as it is made
    (:meth:`kinegami.fabrication.sheets.TreeFabrication.show`): the tree as
    folded (take-off branches leaving their trunk's face) and this fabrication's own printed
    connectors, whichever kind each junction is. ``options`` as for :func:`show_chain`
    (``showJunctions`` defaults to True here)."""
    import warnings

    from kinegami.errors import KinegamiError

    options = {"showJunctions": True, **options}
    opts = resolve_chain_options(options)
    meshes = []
    if opts["showJunctions"] and fabrication.junctions:
        try:
            meshes = [fabrication.connector(k) for k in range(len(fabrication.junctions))]
        except KinegamiError as error:
            warnings.warn(f"showJunctions: the junctions are not drawn: {error}", stacklevel=3)
    opts["showJunctions"] = False  # drawn from these meshes, not made again
    return _show(fabrication.folded_tree(), opts, meshes)


def _show(chain, opts, junction_meshes=()) -> tuple[Figure, Axes3D]:
    """:func:`show_chain` with resolved options, plus ``junction_meshes`` (trimeshes) drawn as
    the junctions."""
    import matplotlib.pyplot as plt

    ax = opts["ax"]
    created = ax is None
    if created:
        fig = plt.figure(figsize=(8, 7))
        if opts["showAxisGrids"]:
            ax = fig.add_subplot(projection="3d")
        else:  # no tick labels to make room for: use the whole figure
            ax = fig.add_axes((0.0, 0.0, 1.0, 1.0), projection="3d")
    fig = ax.figure
    had_data = ax.has_data()
    ax.set_autoscale_on(False)  # the limits are set once, from everything drawn
    scene = _Scene(ax)

    if opts["showJointSurface"]:
        _draw_joint_bodies(scene, chain, opts)
    if opts["showLinkSurface"]:
        _draw_link_surfaces(scene, chain, opts)
    if opts["showLinkPath"]:
        _draw_link_path(scene, chain, opts)
    if opts["showPathCircles"]:
        _draw_path_circles(scene, chain)
    if opts["showJointPoses"]:
        _draw_joint_poses(scene, chain, opts)
    link_axes = opts["showLinkPoses"] and _draw_link_poses(scene, chain, opts)
    if opts["showSpheres"]:
        _draw_spheres(scene, chain, opts)
    if opts["showGlobalFrame"]:
        _draw_global_frame(scene, chain, opts)
    if opts["showGroundPlane"]:
        _draw_ground_plane(scene, chain, opts)
    if opts["showJunctions"]:
        _draw_junctions(scene, chain, opts)
    if junction_meshes:
        _draw_meshes(scene, junction_meshes, opts)
    if opts["showCollisions"]:
        title = _draw_collisions(scene, chain)
        # inside the figure when the axes fill it (no axis grids)
        ax.set_title(title, y=1.0 if opts["showAxisGrids"] else 0.95)

    _legend(ax, opts, opts["showJointPoses"] or opts["showGlobalFrame"], link_axes)
    if opts["showScaleBar"] and not opts["showAxisGrids"]:
        _draw_scale_bar(scene, opts["units"])
    _set_equal_limits(ax, scene, had_data, chain.r)
    if opts["showAxisGrids"]:
        ax.set_axis_on()
        unit = unit_text(opts["units"])
        ax.set_xlabel(f"x ({unit})")
        ax.set_ylabel(f"y ({unit})")
        ax.set_zlabel(f"z ({unit})")
    else:
        ax.set_axis_off()
    show_if_interactive(created, opts["block"])
    return fig, ax
