"""Reference numbers of spec/patterns.md (sections 1.1, 3 and 7.4), r = 1 unless stated.

Where a fix of section 6.2 changes a reference value, both are given: ``*_REF`` is what the
reference implementation produces, the plain name is what kinegami must produce.
"""

import math

PI = math.pi

# Section 1.1: b, W, a and the columns / panel centres
PRISM = {
    4: {
        "b": 1.414214,
        "W": 5.656854,
        "a": 0.707107,
        "columns": (0.707107, 2.121320, 3.535534, 4.949747),
        "panel_centres": (1.414214, 2.828427, 4.242641, 0.0),
    },
    6: {
        "b": 1.0,
        "W": 6.0,
        "a": 0.866025,
        "columns": (0.5, 1.5, 2.5, 3.5, 4.5, 5.5),
        "panel_centres": (1.0, 2.0, 3.0, 4.0, 5.0, 0.0),
    },
}

# Published values are rounded to 6 decimals
ATOL = 1e-6

# Section 3.2 worked values: twist alpha = 0.5, h = 0.5
TWIST_ALPHA, TWIST_H = 0.5, 0.5
TWIST = {
    4: {"K": 0, "s": 0.425567, "e": 0.252442, "H": 0.560114, "marker_x": 0.425567,
        "D0": (1.132674, 0.560114)},
    6: {"K": 0, "s": 0.476403, "e": 0.133697, "H": 0.517566, "marker_x": 0.476403,
        "D0": (0.976403, 0.517566)},
}  # fmt: skip

# Section 3.3 worked example A: n = 4, theta = pi/2, phi = 0
ELBOW_A = {
    "n": 4,
    "theta": PI / 2,
    "phi": 0.0,
    "d_w": 1.0,
    "h": (1.707107, 1.707107, 0.292893, 0.292893),
    "H_m": 1.707107,
    "H": 3.414214,
    "collapsed": (0, 1),
    "tuck": (3 * PI / 8, 3 * PI / 8, PI / 8, PI / 8),
    "Q": ((0.707107, 1.707107), (2.121320, 1.707107)),
    # column -> (L, M, O, U)
    "columns": {
        2: ((3.535534, 0.292893), (3.535534, 1.707107), (4.121320, 1.707107),
            (3.535534, 3.121320)),
        3: ((4.949747, 0.292893), (4.949747, 1.707107), (5.535534, 1.707107),
            (4.949747, 3.121320)),
    },
    "V": 18,
    "E": 28,
    "distal_centre": (0.0, -1.0, 1.0),
    "distal_axis": (0.0, -1.0, 0.0),
    "D0_3d": (0.707107, -1.0, 1.707107),
}  # fmt: skip

# Section 3.3 worked example B: n = 6, theta = pi/2, phi = 0 (column 4 has h_4 = 0: fix B6)
ELBOW_B = {
    "n": 6,
    "theta": PI / 2,
    "phi": 0.0,
    "h": (1.5, 2.0, 1.5, 0.5, 0.0, 0.5),
    "H": 4.0,
    "collapsed": (1,),
    "tan_tuck": (0.689898, 2.224745, 0.689898, 0.289898, 0.224745, 0.289898),
    "O": {0: (0.844949, 2.0), 2: (2.844949, 2.0), 3: (3.934847, 2.0), 4: (4.949490, 2.0),
          5: (5.934847, 2.0)},
    "V_REF": 33,
    "E_REF": 55,
    "V": 31,  # fix B6: L_4 = P_4 and U_4 = D_4
    "E": 53,
}  # fmt: skip
ELBOW_B_PHI_30_HEIGHT = 3.732051  # n = 6, theta = pi/2, phi = pi/6

# Section 3.4 worked example: revolute n = 6, theta_m = pi, N = 1
REVOLUTE_6 = {
    "n": 6,
    "theta_m": PI,
    "h_r": 0.866025,
    "neutral_length": 1.732051,
    "H": 1.224745,
    "height": 2.449490,
    "psi": 0.387597,
    "mp": 2,
    "ep": 5,
    "flap_columns": (0, 2, 3, 5),
    "crimped": (1, 4),
    "t": 0.971092,
    "upper_crimp_y": 1.478398,
    "V": 28,
    "E": 64,
    "M": 36,
    "Vv": 28,
}
REVOLUTE_4 = {"n": 4, "theta_m": PI, "h_r": 0.707107, "neutral_length": 1.414214,
              "height": 2.0, "V": 16, "E": 32}  # fmt: skip

# Section 3.5 counts (theta_m = pi): n -> {N: (V, E_ref)}; the fixed E is E_ref - 4 for N >= 2
SINK_COUNTS_REF = {
    4: {1: (16, 32), 2: (28, 60), 3: (40, 84)},
    6: {1: (28, 64), 2: (60, 132), 3: (92, 196)},
    8: {1: (40, 96), 2: (92, 204), 3: (144, 308)},
    10: {1: (52, 128), 2: (124, 276), 3: (196, 420)},
}
SINK_B2_REMOVED = 4

# Section 3.6: tips
TIP_6 = {"n": 6, "length": 0.5, "theta_eq": 2 * PI / 3, "H": 1.0, "crimped": (1, 4),
         "t_REF": 0.527046, "t": 0.625, "V": 20, "E": 38}  # fmt: skip
TIP_4 = {"n": 4, "length": 0.5, "H": 0.866025, "V": 12, "E": 20}

# Section 3.7 worked example: REBO n = 4, d = 2, N = 2, beta = pi/4
REBO_4 = {
    "n": 4,
    "d": 2.0,
    "N": 2,
    "beta": PI / 4,
    "l1": 0.707107,
    "alpha_f": 1.015436,
    "o": 0.438763,
    "H": 2.828427,
    "rows_y": (0.0, 1.414214, 2.828427),
    "mid_y": (0.707107, 2.121320),
    "offset_x": (0.268344, 1.682557, 3.096771, 4.510984),
    "V": 28,
    "E": 60,
    "M": 36,
}

# Section 3.8 worked example: prismatic d = 2, N = 2, beta = pi/4
PRISMATIC = {
    "d": 2.0,
    "N": 2,
    "beta": PI / 4,
    "L": 2.828427,
    "height": 11.313708,
    "min_length": 1.414214,
    "max_length": 2.828427,
    "state_range": (-0.585786, 0.828427),
    "counts": {4: (40, 76), 6: (60, 114)},
}

# Section 7.4 composite: Tube(1) + Twist(0.5, 0.5) + Elbow(pi/2, pi/3) + Revolute(pi) + Tube(1)
COMPOSITE_SPEC = (("tube", 1.0), ("twist", 0.5, 0.5), ("elbow", PI / 2, PI / 3),
                  ("revolute", PI), ("tube", 1.0))  # fmt: skip
COMPOSITE = {
    # n = 6: the elbow (phi = pi/3) has a column with h_k = 0; fix B6 removes 2 vertices,
    # 2 creases (both mountains) from the reference's 73 / 155 / 94
    6: {"V_REF": 73, "E_REF": 155, "M_REF": 94, "V": 71, "E": 153, "M": 92,
        "height": 8.967056, "marker_x": 0.476403},
    4: {"V": 45, "E": 91, "M": 58, "height": 8.491965, "marker_x": 0.425567},
}  # fmt: skip

# Section 7.4: revolute n = 6 (+) twist (0.5, 0.5) in either order
REVOLUTE_TWIST_MERGED_E = 82
REVOLUTE_TWIST_MERGED_RINGS = 6
MERGED_RING_LABEL = {"revolute_first": "M", "twist_first": "V"}
