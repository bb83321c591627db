"""Default colours, opacities and scales of the drawings (docs/theory/chain.md §6).

One place for every visual default, so that ``KinematicChain.show`` and any other plotting
backend agree. Colours are matplotlib colour specifications; opacities are alphas in [0, 1];
scales are multiples of the tube radius r. The names of the ``show`` options keep the paper's
spelling (``xColor``, ``showJointPoses``, ...); :data:`CHAIN_PLOT_DEFAULTS` maps every option
of ``KinematicChain.show`` to its default.
"""

from __future__ import annotations

from types import MappingProxyType

__all__ = [
    "xColor",
    "yColor",
    "zColor",
    "proximalColor",
    "centerColor",
    "distalColor",
    "jointColor",
    "linkColor",
    "pathColor",
    "sphereColor",
    "groundPlaneColor",
    "surfaceOpacity",
    "jointAxisScale",
    "globalAxisScale",
    "groundPlaneScale",
    "jointAxisColor",
    "jointAxisLineStyle",
    "linkPoseColors",
    "rotationAxisColor",
    "pathCircleColors",
    "jointSphereOpacity",
    "groundPlaneOpacityFactor",
    "linkSurfaceSides",
    "pathMarker",
    "collisionColor",
    "collisionOpacity",
    "CHAIN_PLOT_DEFAULTS",
]

# --- frame axes (every drawn frame: joint frames and the world frame) ---
xColor = "orangered"
yColor = "lightgreen"
zColor = "darkblue"

# --- origin markers of a joint's frames ---
proximalColor = "c"
centerColor = "m"
distalColor = "y"

# --- bodies and surfaces ---
jointColor = "darkblue"
linkColor = "lightgray"
#: Colour of a tree's printed junction connectors (``showJunctions``).
junctionColor = "darkorange"
#: Alpha of joint and link surfaces.
surfaceOpacity = 0.5
#: Straight tubes and elbows are drawn with this many sides (smooth, independent of numSides).
linkSurfaceSides = 32

# --- axes of motion ---
#: Revolute and prismatic axes are drawn from p - jointAxisScale*r*z to p + jointAxisScale*r*z.
jointAxisScale = 10
jointAxisColor = "silver"
jointAxisLineStyle = "--"

# --- link centreline and construction geometry ---
pathColor = "black"
#: Marker at the ends q1, q2 of each straight segment.
pathMarker = "*"
#: Turning circles: (start-side circle, end-side circle).
pathCircleColors = ("red", "blue")
#: Elbow frame axes (a, b, c) drawn by showLinkPoses.
linkPoseColors = ("darkred", "darkblue", "darkgreen")
rotationAxisColor = "dimgray"

# --- bounding spheres ---
sphereColor = "black"
#: Alpha of each joint's bounding ball (the chain's ball is a wireframe).
jointSphereOpacity = 0.05

# --- collisions (showCollisions) ---
#: Colliding parts and the line joining their closest points.
collisionColor = "red"
#: Alpha of the colliding parts' surfaces.
collisionOpacity = 0.6

# --- world frame and ground plane ---
#: The world frame's arrows have length globalAxisScale*r.
globalAxisScale = 10
#: The ground plane z = 0 spans [-groundPlaneScale*r, groundPlaneScale*r] in x and y.
groundPlaneScale = 10
groundPlaneColor = "black"
#: The ground plane's alpha is surfaceOpacity times this.
groundPlaneOpacityFactor = 0.25

#: Every option of ``KinematicChain.show`` with its default (read-only).
CHAIN_PLOT_DEFAULTS = MappingProxyType(
    {
        "xColor": xColor,
        "yColor": yColor,
        "zColor": zColor,
        "proximalColor": proximalColor,
        "centerColor": centerColor,
        "distalColor": distalColor,
        "showJointPoses": True,
        "showJointSurface": True,
        "jointColor": jointColor,
        "jointAxisScale": jointAxisScale,
        "showLinkSurface": True,
        "linkColor": linkColor,
        "surfaceOpacity": surfaceOpacity,
        "showLinkPath": True,
        "pathColor": pathColor,
        "showPathCircles": False,
        "showLinkPoses": False,
        "showSpheres": False,
        "sphereColor": sphereColor,
        "showGlobalFrame": False,
        "globalAxisScale": globalAxisScale,
        "showGroundPlane": False,
        "groundPlaneScale": groundPlaneScale,
        "groundPlaneColor": groundPlaneColor,
        "showAxisGrids": False,
        "showCollisions": False,
        "showJunctions": False,
        "junctionColor": junctionColor,
        "units": None,
        "showScaleBar": True,
        "block": None,
        "ax": None,
    }
)
