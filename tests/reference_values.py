"""Reference numbers of spec/chain.md section 11 (r = 1, published to 6 decimals).

Every number the chain-core tests compare against lives here; the tests only say which
quantity is compared with which entry. Links are numbered as in the spec tables: link i joins
joint i - 1 to joint i (``chain.Links[i]``; ``Links[0]`` is the root's empty link).
"""

import math

PI = math.pi

#: Published values are rounded to 6 decimals.
ATOL = 1e-6
#: CSC unit cases of 11.7 are published to 9 decimals.
ATOL_CSC = 1e-9

# --- chain.md 1.3: joint geometry ------------------------------------------------------------
#: RevoluteJoint(n, r=1, B=pi): neutral length and bounding radius.
REVOLUTE_PI = {
    4: {"neutral_length": 1.414214},
    6: {"neutral_length": 1.732051, "bounding_radius": 1.322876},
}

# --- chain.md 11.2: Example 1A ---------------------------------------------------------------
EXAMPLE_1A_START = {"origin": (3, 3, 0), "length": 1.5}
EXAMPLE_1A_PRISMATIC = {
    "neutralLength": 3,
    "numLayers": 3,
    "coneAngle": PI / 4,
    "translation": (5, 5, 0),
}
EXAMPLE_1A_REVOLUTE = {"totalBendingAngle": PI, "ry": PI / 4}
EXAMPLE_1A_END = {"ry": PI / 2, "length": 1.5}
EXAMPLE_1A_APPEND_RESULTS = (2, 4, 6)

EXAMPLE_1A_JOINTS = (
    {"type": "StartTip", "parent": -1, "path_index": 2, "x": (1, 0, 0), "z": (0, 0, 1),
     "origin": (3, 3, 0)},
    {"type": "Waypoint", "parent": 0, "path_index": 2, "x": (1, 0, 0), "z": (0, 0, 1),
     "origin": (3, 3, 1.25)},
    {"type": "PrismaticJoint", "parent": 1, "path_index": 2, "x": (1, 0, 0), "z": (0, 0, 1),
     "origin": (8, 8, 7.052776)},
    {"type": "Waypoint", "parent": 2, "path_index": 2, "x": (1, 0, 0), "z": (0, 0, 1),
     "origin": (8, 8, 9.986952)},
    {"type": "RevoluteJoint", "parent": 3, "path_index": 0, "x": (0.707107, 0, -0.707107),
     "z": (0.707107, 0, 0.707107), "origin": (16.158921, 8, 15.211696)},
    {"type": "Waypoint", "parent": 4, "path_index": 0, "x": (0.707107, 0, -0.707107),
     "z": (0.707107, 0, 0.707107), "origin": (24.713209, 8, 6.657408)},
    {"type": "EndTip", "parent": 5, "path_index": 2, "x": (-0.707107, 0, -0.707107),
     "z": (0.707107, 0, -0.707107), "origin": (28.425520, 8, 2.945097)},
)  # fmt: skip

#: Links 1..6: (theta1, s, theta2, length, (elbows1, elbows2), (phi1, phi2) or None, twist).
EXAMPLE_1A_LINKS = (
    (0.0, 0.500000, 0.0, 0.500000, (0, 0), None, 0.0),
    (1.172632, 6.342681, 1.172632, 8.687946, (1, 1), (2.356194, -0.785398), 0.0),
    (0.0, 1.434176, 0.0, 1.434176, (0, 0), None, 0.0),
    (0.870355, 7.784650, 1.485840, 10.140845, (1, 1), (1.570796, 0.0), 1.570796),
    (0.0, 11.390484, 0.0, 11.390484, (0, 0), None, 0.0),
    (0.0, 4.500000, 0.0, 4.500000, (0, 0), None, -1.570796),
)
EXAMPLE_1A_TOTAL_LENGTH = 36.653451
EXAMPLE_1A_BALL = {"c": (13.407671, 6.997247, 7.043143), "r": 16.849207}
EXAMPLE_1A_BALL_RECOMPUTED = {"c": (13.577242, 6.856767, 6.911024), "r": 16.661259}

#: The derivation check under the 11.2 table.
EXAMPLE_1A_FIRST_BALL = {"c": (3, 3, 0), "r": 1.25}
EXAMPLE_1A_W1 = (3, 3, 1.25)
EXAMPLE_1A_FAR_PLANE_Z = 7.052776
EXAMPLE_1A_LINK2 = {
    "q1": (3.432943, 3.432943, 2.171774),
    "q2": (7.567057, 7.567057, 4.631001),
    "u": (0.651793, 0.651793, 0.387727),
    "arc1_ball": {"c": (3, 3, 1.914233), "r": 1.200502},
    "arc2_ball": {"c": (8, 8, 4.888542), "r": 1.200502},
}
#: joint index -> (proximal origin, distal origin) at state 0.
EXAMPLE_1A_PROXIMAL_DISTAL = {
    2: ((8, 8, 5.552776), (8, 8, 8.552776)),
    4: ((15.658921, 8, 15.711696), (16.658921, 8, 14.711696)),
    6: ((27.895190, 8, 3.475428), (28.955850, 8, 2.414767)),
}

# --- chain.md 11.3: Example 1B (edits on 1A, in sequence) ------------------------------------
#: (method, args, kwargs) of steps B1..B4.
EXAMPLE_1B_STEPS = (
    ("translateJointAlongAxisOfMotion", (4, -7), {}),
    ("translateJointAlongAxisOfMotion", (6, -10), {"applyToPreviousWaypoint": True}),
    ("rotateJointAboutAxisOfMotion", (4, -PI / 3), {}),
    ("translateJointAlongAxisOfMotion", (2, -2), {"propagate": False}),
)
#: After each step: total path length, ball radius, EndTip origin, revolute origin.
EXAMPLE_1B_RESULTS = (
    {"total_length": 29.873164, "ball_r": 14.137514, "end_origin": (23.475772, 8, -2.004650),
     "revolute_origin": (11.209173, 8, 10.261949)},
    {"total_length": 19.873164, "ball_r": 9.892266, "end_origin": (16.404705, 8, 5.066418),
     "revolute_origin": (11.209173, 8, 10.261949)},
    {"total_length": 20.661814, "ball_r": 9.289397, "end_origin": (13.806939, 1.636800, 7.664183),
     "revolute_origin": (11.209173, 8, 10.261949)},
    {"total_length": 22.195489, "ball_r": 9.360448, "end_origin": (13.806939, 1.636800, 7.664183),
     "revolute_origin": (11.209173, 8, 10.261949)},
)  # fmt: skip
EXAMPLE_1B_AFTER_B4 = {
    "prismatic_origin": (8, 8, 5.052776),
    "revolute_x": (0.353553, -0.866025, -0.353553),
    "waypoint5_origin": (11.950784, 6.183433, 9.520339),
    # link index -> (theta1, s, theta2, (elbows1, elbows2))
    "links": {
        2: (1.511845, 5.197933, 1.511845, (1, 1)),
        3: (0.0, 3.434176, 0.0, (0, 0)),
        4: (1.600818, 0.818588, 1.729801, (2, 2)),
        5: (0.0, 1.390484, 0.0, (0, 0)),
        6: (0.0, 4.5, 0.0, (0, 0)),
    },
}

# --- chain.md 11.4: Example 1C (states on 1B) ------------------------------------------------
EXAMPLE_1C_PRISMATIC_RANGE = (-0.878680, 1.242641)
EXAMPLE_1C_REVOLUTE_STATE = PI / 2
EXAMPLE_1C_REJECTED_REVOLUTE_STATE = PI
EXAMPLE_1C = {
    "waypoint3_origin": (8, 8, 11.229592),
    "revolute_origin": (11.209173, 8, 11.504590),
    "revolute_x": (0.353553, -0.866025, -0.353553),
    "waypoint5_origin": (12.493680, 9.048795, 10.220083),
    "waypoint5_x": (0.612372, 0.5, -0.612372),
    "end_origin": (15.708635, 11.673795, 7.005128),
    "end_z": (0.612372, 0.5, -0.612372),
    "prismatic_distal_origin": (8, 8, 7.795416),
    "revolute_distal_origin": (11.642186, 8.353553, 11.071577),
    "ball": {"c": (7.895792, 7.040880, 5.690796), "r": 10.427793},
}

# --- chain.md 11.5: safe placement with two waypoints (n = 6) --------------------------------
PLANAR_NUM_SIDES = 6
PLANAR_STEP = (4, 0, 0)
PLANAR_JOINTS = (
    {"type": "RevoluteJoint", "x": (1, 0, 0), "z": (0, 0, 1), "origin": (0, 0, 0)},
    {"type": "Waypoint", "path_index": 0, "x": (1, 0, 0), "z": (0, 0, 1),
     "origin": (1.322876, 0, 0)},
    {"type": "Waypoint", "path_index": 0, "x": (0, 0, 1), "z": (-1, 0, 0),
     "origin": (2.322876, 0, 1.322876)},
    {"type": "RevoluteJoint", "x": (1, 0, 0), "z": (0, 0, 1), "origin": (4, 0, 6.645751)},
    {"type": "Waypoint", "path_index": 0, "x": (1, 0, 0), "z": (0, 0, 1),
     "origin": (7.312070, 0, 6.645751)},
    {"type": "Waypoint", "path_index": 0, "x": (0, 0, 1), "z": (-1, 0, 0),
     "origin": (8.312070, 0, 8.568683)},
    {"type": "RevoluteJoint", "x": (1, 0, 0), "z": (0, 0, 1), "origin": (8, 0, 13.891558)},
)  # fmt: skip
#: Links 1..6: (theta1, s, theta2, (elbows1, elbows2)).
PLANAR_LINKS = (
    (0.0, 0.456850, 0.0, (0, 0)),
    (1.570796, 0.322876, 0.0, (1, 0)),
    (0.044120, 4.238789, 1.614916, (1, 2)),
    (0.0, 2.446044, 0.0, (0, 0)),
    (1.570796, 0.922931, 0.0, (1, 0)),
    (0.521720, 3.836531, 2.092517, (1, 2)),
)
PLANAR_TOTAL_LENGTH = 19.638888
PLANAR_BALL = {"c": (4.173333, 0, 6.433819), "r": 9.705074}
PLANAR_DELETE_INDICES = (1, 1, 2, 2)
#: Links 1, 2 after the deletes: (theta1, s, theta2).
PLANAR_AFTER_DELETE_LINKS = ((1.513880, 4.767242, 1.513880), (1.520248, 5.353698, 1.520248))
PLANAR_AFTER_DELETE_TOTAL = 16.189197
PLANAR_STRAIGHT_LINK = 2.267949
PLANAR_STRAIGHT_TOTAL = 4.535898

#: Cylindrical variant: PrismaticJoint(6, 1, 3, 3, pi/4, I) appended to RevoluteJoint(6,1,pi,I).
CYLINDRICAL_PRISMATIC = {"neutralLength": 3, "numLayers": 3, "coneAngle": PI / 4}
CYLINDRICAL_PRISMATIC_ORIGIN = (0, 0, 7.125651)
CYLINDRICAL_TOTAL_LENGTH = 7.287597

# --- chain.md 11.6: compact placement, prismatic spiral (n = 6, safe=False) ------------------
SPIRAL_NUM_SIDES = 6
SPIRAL_PRISMATIC = {"neutralLength": 3, "numLayers": 5, "coneAngle": PI / 4}
SPIRAL_RY = PI / 4
SPIRAL_APPENDS = 4
SPIRAL_ORIGINS = (
    (5.377937, 0, 5.377937),
    (13.775869, 0, 5.377937),
    (20.665221, 0, -1.511414),
    (20.665221, 0, -13.240251),
)
SPIRAL_Z = ((0.707107, 0, 0.707107), (1, 0, 0), (0.707107, 0, -0.707107), (0, 0, -1))
SPIRAL_X = ((0.707107, 0, -0.707107), (0, 0, -1), (-0.707107, 0, -0.707107), (-1, 0, 0))
SPIRAL_LINKS = (
    (1.110988, 3.903110, 0.325590),
    (1.057200, 4.768280, 0.271802),
    (0.998292, 6.192473, 0.212893),
    (0.947072, 8.246672, 0.161674),
)
SPIRAL_TOTAL_LENGTH = 28.196046
SPIRAL_BALL = {"c": (12.221380, 0, -0.581604), "r": 17.019208}

# --- chain.md 11.7: CSC unit cases (r = 1) ---------------------------------------------------
CSC_PLANAR_S = {
    "p1": (0, 0, 0), "d1": (1, 0, 0), "p2": (10, 4, 0), "d2": (1, 0, 0),
    "theta1": 0.394791120, "theta2": 0.394791120, "s": 10.000000000, "length": 10.789582239,
}  # fmt: skip
CSC_3D = {
    "p1": (0, 0, 0), "d1": (1, 0, 0), "p2": (0, 10, 5), "d2": (0, 0, 1),
    "theta1": 1.671956981, "s": 9.193964434, "theta2": 1.163340884, "length": 12.029262299,
    "u": (-0.100988, 0.912561, 0.396274),
}  # fmt: skip
#: The U-turn: no acceptable path (the reference's pick has theta2 = 3.343830 > pi).
CSC_U_TURN = {"p1": (0, 0, 0.75), "d1": (0, 0, 1), "p2": (0, 0, 10.707107), "d2": (0, 0, -1)}

# --- chain.md 11.1 item 7: rejections on Example 1A -----------------------------------------
REJECT_ROTATE = (4, PI)  # rotateJointAboutAxisOfMotion(4, pi, propagate=False)
REJECT_TRANSLATE = (2, 20)  # translateJointAlongAxisOfMotion(2, 20, propagate=False)
#: RevoluteJoint(4, 1, pi, Trans(0, 0, 10) Ry(pi/2)) after StartTip(4, 1, SE3(), 1.5).
REJECT_APPEND = {"start_length": 1.5, "translation": (0, 0, 10), "ry": PI / 2}

# --- the chain's crease pattern (patterns.md 4.3, informational values of example 1 after 1B)
EXAMPLE_1_PATTERN_HEIGHT = 52.767303
EXAMPLE_1_PATTERN_DISTAL_MARKER_X = 0.258638
