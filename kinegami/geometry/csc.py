"""3D CSC Dubins paths of turning radius r between two frames.

See docs/theory/csc.md and docs/theory/chain.md §3.

A CSC path leaves ``p1`` along ``d1``, turns on a circle of radius r through ``theta1`` until
its tangent is ``u``, runs straight for ``tMag`` along ``u`` and turns through ``theta2`` onto
``d2``, ending at ``p2``. Only the (short, short) family matters to kinegami: links reject turns
of pi or more, and long turns are always more than pi (docs/theory/chain.md §3).

The solver. With the scaled tangent lengths a = tan(theta1/2) and b = tan(theta2/2), the
closure equation ``p2 - p1 = r a (d1 + u) + s u + r b (u + d2)`` says that ``u`` is the unit
vector of ``V(a, b) = (p2 - p1)/r - a d1 - b d2`` and that ``s = r (|V| - a - b)``. What is
left are two scalar equations in (a, b):

    angle(d1, u(a, b)) = 2 atan(a),    angle(u(a, b), d2) = 2 atan(b),

solved by Newton's method with the analytic Jacobian from the reference's initial guess
(u along p2 - p1), with a deterministic grid of restarts if that fails. Each link takes a few
Newton steps of scalar arithmetic (tens of microseconds).

``solve_csc_all`` returns every (short, short) path, sorted by length. It climbs a function of
``u`` whose critical points are exactly the paths, and whose paths with s > 0 are strict
maxima, from the summits of a fixed grid of directions (docs/theory/csc.md, which also says how
many paths there can be: in practice never more than one).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinegami.geometry.frames import any_perpendicular, cross3, rotation_matrix

#: Newton stops when both angle residuals are below this (radians).
ANGLE_TOLERANCE = 1e-13
#: A converged root is accepted only if its angle residuals are below this (radians).
ACCEPT_TOLERANCE = 1e-10
#: A path is returned only if it ends within this many r of the target (plus 1e-12 |p2 - p1|).
END_TOLERANCE = 1e-10
_MAX_ITERATIONS = 40
_MAX_TAN = 1e6  # tan(theta/2) cap: theta within 2e-6 of pi


@dataclass(frozen=True, eq=False)
class CSCPath:
    """A solved CSC path (world coordinates; lengths in the units of r, angles in radians).

    Attributes
    ----------
    r : turning radius.
    p1, d1, p2, d2 : start point and unit tangent, end point and unit tangent.
    theta1, theta2 : turn angles of the two arcs, in [0, pi).
    tMag : length s >= 0 of the straight segment.
    tUnit : unit direction u of the straight segment.
    q1, q2 : end of arc 1 / start of arc 2 (the straight segment runs q1 -> q2).
    w1, w2 : unit vectors from p1 (p2) to the centre of circle 1 (circle 2).
    k1, k2 : unit rotation axes: Rot(k1, theta1) d1 = u and Rot(k2, theta2) u = d2.
    """

    r: float
    p1: np.ndarray
    d1: np.ndarray
    p2: np.ndarray
    d2: np.ndarray
    theta1: float
    theta2: float
    tMag: float
    tUnit: np.ndarray
    q1: np.ndarray
    q2: np.ndarray
    w1: np.ndarray
    w2: np.ndarray
    k1: np.ndarray
    k2: np.ndarray

    @property
    def length(self) -> float:
        """Total centreline length r*theta1 + tMag + r*theta2."""
        return self.r * self.theta1 + self.tMag + self.r * self.theta2

    @property
    def c1(self) -> np.ndarray:
        """Centre of turning circle 1."""
        return self.p1 + self.r * self.w1

    @property
    def c2(self) -> np.ndarray:
        """Centre of turning circle 2."""
        return self.p2 + self.r * self.w2

    def transformed(self, T: np.ndarray) -> CSCPath:
        """The same path moved rigidly by the 4x4 transform ``T`` (no re-solve)."""
        R = T[:3, :3]
        t = T[:3, 3]
        return CSCPath(
            self.r,
            R @ self.p1 + t,
            R @ self.d1,
            R @ self.p2 + t,
            R @ self.d2,
            self.theta1,
            self.theta2,
            self.tMag,
            R @ self.tUnit,
            R @ self.q1 + t,
            R @ self.q2 + t,
            R @ self.w1,
            R @ self.w2,
            R @ self.k1,
            R @ self.k2,
        )

    def end_of_arc1(self) -> tuple[np.ndarray, np.ndarray]:
        """Point and tangent reached by rotating p1 about circle 1 through theta1."""
        R1 = rotation_matrix(self.k1, self.theta1)
        return self.c1 + R1 @ (self.p1 - self.c1), R1 @ self.d1

    def reconstruct_end(self) -> tuple[np.ndarray, np.ndarray]:
        """End point and tangent obtained by actually following arc 1, the straight and arc 2."""
        q1, u = self.end_of_arc1()
        q2 = q1 + self.tMag * u
        centre2 = q2 + self.r * cross3(self.k2, u)
        R2 = rotation_matrix(self.k2, self.theta2)
        return centre2 + R2 @ (q2 - centre2), R2 @ u

    def sample(self, points_per_arc: int = 16) -> np.ndarray:
        """Points along the centreline (arc 1, straight, arc 2) as an (m, 3) array."""
        pts = []
        for theta, k, p, centre in (
            (self.theta1, self.k1, self.p1, self.c1),
            (self.theta2, self.k2, self.q2, self.c2),
        ):
            for t in np.linspace(0.0, theta, points_per_arc):
                pts.append(centre + rotation_matrix(k, t) @ (p - centre))
        return np.array(pts)


def _newton(D, d1, d2, a, b):
    """Newton iteration on (a, b); returns (a, b, max residual, |V|) or None."""
    D0, D1, D2 = D
    x0, x1, x2 = d1
    y0, y1, y2 = d2
    d12 = x0 * y0 + x1 * y1 + x2 * y2
    # d1 x d2
    e0 = x1 * y2 - x2 * y1
    e1 = x2 * y0 - x0 * y2
    e2 = x0 * y1 - x1 * y0
    atan = math.atan
    atan2 = math.atan2
    sqrt = math.sqrt
    prev_norm = math.inf
    for _ in range(_MAX_ITERATIONS):
        V0 = D0 - a * x0 - b * y0
        V1 = D1 - a * x1 - b * y1
        V2 = D2 - a * x2 - b * y2
        nV = sqrt(V0 * V0 + V1 * V1 + V2 * V2)
        if nV < 1e-300:
            return None
        u0, u1, u2 = V0 / nV, V1 / nV, V2 / nV
        c1 = x0 * u0 + x1 * u1 + x2 * u2
        c2 = y0 * u0 + y1 * u1 + y2 * u2
        # w1 = d1 x u ; w2 = u x d2
        w10 = x1 * u2 - x2 * u1
        w11 = x2 * u0 - x0 * u2
        w12 = x0 * u1 - x1 * u0
        w20 = u1 * y2 - u2 * y1
        w21 = u2 * y0 - u0 * y2
        w22 = u0 * y1 - u1 * y0
        S1 = sqrt(w10 * w10 + w11 * w11 + w12 * w12)
        S2 = sqrt(w20 * w20 + w21 * w21 + w22 * w22)
        h1 = atan2(S1, c1) - 2.0 * atan(a)
        h2 = atan2(S2, c2) - 2.0 * atan(b)
        norm = max(abs(h1), abs(h2))
        if norm < ANGLE_TOLERANCE:
            return a, b, norm, nV
        # Jacobian (see module docstring); dgamma = c dS - S dc for unit vectors.
        we1 = (w10 * e0 + w11 * e1 + w12 * e2) / S1 if S1 > 0.0 else 0.0
        we2 = (w20 * e0 + w21 * e1 + w22 * e2) / S2 if S2 > 0.0 else 0.0
        dc1_db = -(d12 - c1 * c2) / nV
        dS1_db = (-we1 + c2 * S1) / nV
        dc2_da = dc1_db
        dS2_da = (-we2 + c1 * S2) / nV
        j11 = S1 / nV - 2.0 / (1.0 + a * a)
        j12 = c1 * dS1_db - S1 * dc1_db
        j21 = c2 * dS2_da - S2 * dc2_da
        j22 = S2 / nV - 2.0 / (1.0 + b * b)
        det = j11 * j22 - j12 * j21
        if det == 0.0 or not math.isfinite(det):
            return None
        da = -(j22 * h1 - j12 * h2) / det
        db = -(-j21 * h1 + j11 * h2) / det
        # Damped step: halve while the residual grows a lot (keeps far starts from diverging).
        step = 1.0
        if norm > 0.5 * prev_norm and norm > 1e-6:
            step = 0.5
        prev_norm = norm
        a_new = a + step * da
        b_new = b + step * db
        a = min(max(a_new, 0.0), _MAX_TAN)
        b = min(max(b_new, 0.0), _MAX_TAN)
    return None


_HALF_ANGLES = np.linspace(0.02, 1.52, 16)
_GRID_A, _GRID_B = (np.tan(g).ravel() for g in np.meshgrid(_HALF_ANGLES, _HALF_ANGLES))
#: Newton restarts tried from the best grid points when the reference's start fails.
_RESTARTS = 6


def _grid_starts(D: np.ndarray, d1: np.ndarray, d2: np.ndarray) -> list[tuple[float, float]]:
    """Grid points (a, b) ordered by residual, evaluated in one vectorised pass."""
    V = D[None, :] - _GRID_A[:, None] * d1[None, :] - _GRID_B[:, None] * d2[None, :]
    nV = np.linalg.norm(V, axis=1)
    nV[nV == 0.0] = 1e-300
    u = V / nV[:, None]
    g1 = np.arctan2(np.linalg.norm(np.cross(d1[None, :], u), axis=1), u @ d1)
    g2 = np.arctan2(np.linalg.norm(np.cross(u, d2[None, :]), axis=1), u @ d2)
    res = np.maximum(np.abs(g1 - 2 * np.arctan(_GRID_A)), np.abs(g2 - 2 * np.arctan(_GRID_B)))
    # a straight part of negative length cannot be a solution: push those points back
    res = res + np.where(nV - _GRID_A - _GRID_B < 0.0, 10.0, 0.0)
    best = np.argsort(res, kind="stable")[:_RESTARTS]
    return [(float(_GRID_A[i]), float(_GRID_B[i])) for i in best]


def _accepted(root):
    """(length / r, a, b, |V|) of a Newton root that is a path (s >= 0), else None."""
    if root is None:
        return None
    a, b, residual, nV = root
    s_over_r = nV - a - b
    if residual > ACCEPT_TOLERANCE or s_over_r < -1e-12:
        return None  # not converged, or a root of the reduced equations with s < 0
    return 2.0 * math.atan(a) + max(s_over_r, 0.0) + 2.0 * math.atan(b), a, b, nV


def solve_csc(p1, d1, p2, d2, r: float) -> CSCPath | None:
    """The (short, short) CSC path from (p1, d1) to (p2, d2) with turning radius ``r``.

    Returns None when no such path with both turns < pi and a straight part >= 0 exists (or none
    was found). Directions need not be normalised. Deterministic.
    """
    p1 = np.asarray(p1, dtype=float)
    p2 = np.asarray(p2, dtype=float)
    d1 = np.asarray(d1, dtype=float)
    d2 = np.asarray(d2, dtype=float)
    d1 = d1 / math.sqrt(float(d1 @ d1))
    d2 = d2 / math.sqrt(float(d2 @ d2))
    delta = p2 - p1
    D = delta / r
    nD = math.sqrt(float(D @ D))
    d1t = (float(d1[0]), float(d1[1]), float(d1[2]))
    d2t = (float(d2[0]), float(d2[1]), float(d2[2]))
    Dt = (float(D[0]), float(D[1]), float(D[2]))

    if nD < 1e-12 and float(d1 @ d2) > 1.0 - 1e-15:
        # Identical frames: the empty path (the root's link).
        return _build(r, p1, d1, p2, d2, 0.0, 0.0, d1.copy())

    # The reference's initial guess: u along p2 - p1 (docs/theory/chain.md §3). Its root is
    # unique in practice; only when it fails are the best points of a grid tried as restarts.
    u0 = D / nD if nD > 0.0 else d1
    g1 = math.atan2(float(np.linalg.norm(cross3(d1, u0))), float(d1 @ u0))
    g2 = math.atan2(float(np.linalg.norm(cross3(u0, d2))), float(u0 @ d2))
    best = _accepted(_newton(Dt, d1t, d2t, min(math.tan(g1 / 2), 1e3), min(math.tan(g2 / 2), 1e3)))
    if best is None:
        for a0, b0 in _grid_starts(D, d1, d2):
            found = _accepted(_newton(Dt, d1t, d2t, a0, b0))
            if found is not None and (best is None or found[0] < best[0] - 1e-12):
                best = found
    if best is None:
        return None
    _, a, b, nV = best
    V = D - a * d1 - b * d2
    u = V / nV
    path = _build(r, p1, d1, p2, d2, a, b, u)
    if path is None or not _closes(path, p2, d2, r, nD):
        return None
    return path


def _closes(path: CSCPath, p2: np.ndarray, d2: np.ndarray, r: float, nD: float) -> bool:
    """True if following the path really ends at (p2, d2).

    Near a U-turn (a or b ~ 1e6) a root with tiny angle residuals can still miss the end point:
    such a path is not one (the residual check of docs/theory/chain.md §3, in lengths).
    """
    end, tangent = path.reconstruct_end()
    miss = float(np.max(np.abs(end - p2)))
    return not (
        miss > END_TOLERANCE * r + 1e-12 * nD * r or float(np.max(np.abs(tangent - d2))) > 1e-10
    )


def _centre_direction(u: np.ndarray, d: np.ndarray, c: float) -> np.ndarray:
    """Unit part of ``u`` perpendicular to ``d`` (c = d.u); any perpendicular for a null turn.

    The subtraction loses relative accuracy as the turn vanishes, so the result is projected
    once more (w.d ~ 1e-16). The direction must stay the true one down to tiny turns: an
    arbitrary w would tilt the end tangent by about the turn angle, which a long straight
    segment turns into an end-point error.
    """
    perp = u - c * d
    perp = perp - float(perp @ d) * d
    n = float(np.linalg.norm(perp))
    return perp / n if n > 1e-12 else any_perpendicular(d)


def _build(r, p1, d1, p2, d2, a, b, u) -> CSCPath | None:
    c1 = float(d1 @ u)
    c2 = float(d2 @ u)
    cr1 = cross3(d1, u)
    cr2 = cross3(u, d2)
    theta1 = math.atan2(float(np.linalg.norm(cr1)), c1)
    theta2 = math.atan2(float(np.linalg.norm(cr2)), c2)
    if theta1 >= math.pi or theta2 >= math.pi:
        return None
    q1 = p1 + r * a * (d1 + u)
    q2 = p2 - r * b * (u + d2)
    s = float((q2 - q1) @ u)
    if s < 0.0:
        s = 0.0
    w1 = _centre_direction(u, d1, c1)
    w2 = -_centre_direction(u, d2, c2)
    k1 = cross3(d1, w1)
    k2 = cross3(d2, w2)
    return CSCPath(r, p1, d1, p2, d2, theta1, theta2, s, u, q1, q2, w1, w2, k1, k2)


# --- every (short, short) path: solve_csc_all --------------------------------------------------
#
# docs/theory/csc.md explains the search. In short: with F(u) = D.u + f(theta1(u)) + f(theta2(u)),
# f(t) = t - sin t, theta1(u) = angle(d1, u), theta2(u) = angle(u, d2), the paths are exactly the
# critical points of F on the unit sphere of straight directions u, and every path with s > 0
# is a strict local maximum (Hessian -s I - a T1 - b T2). So the search climbs F from every local
# maximum of a fixed geodesic grid and polishes each summit with the Newton iteration above.

#: Subdivision level of the icosahedral grid of directions (2562 points, ~4 degrees apart).
SPHERE_LEVEL = 4
#: Paths whose turns, straight lengths (/ r) and directions differ by less than this are one.
DUPLICATE_TOLERANCE = 1e-9
_ASCENT_ITERATIONS = 60
_ASCENT_MAX_STEP = 0.5  # radians of u per step
_CONE_LIMIT = 2.0 * math.atan(_MAX_TAN)  # a climb that reaches theta = pi - 2e-6 is a U-turn
_CONE_REACH = 0.2  # rad: paths farther than this from a cone point are left to the grid


def _icosphere(level: int) -> tuple[np.ndarray, np.ndarray]:
    """Vertices (n, 3) of the subdivided icosahedron and a (n, 6) array of their neighbours.

    The 12 vertices with five neighbours repeat their first neighbour in the sixth column.
    """
    t = (1.0 + math.sqrt(5.0)) / 2.0
    verts = [
        (-1, t, 0), (1, t, 0), (-1, -t, 0), (1, -t, 0), (0, -1, t), (0, 1, t),
        (0, -1, -t), (0, 1, -t), (t, 0, -1), (t, 0, 1), (-t, 0, -1), (-t, 0, 1),
    ]  # fmt: skip
    faces = [
        (0, 11, 5), (0, 5, 1), (0, 1, 7), (0, 7, 10), (0, 10, 11), (1, 5, 9), (5, 11, 4),
        (11, 10, 2), (10, 7, 6), (7, 1, 8), (3, 9, 4), (3, 4, 2), (3, 2, 6), (3, 6, 8),
        (3, 8, 9), (4, 9, 5), (2, 4, 11), (6, 2, 10), (8, 6, 7), (9, 8, 1),
    ]  # fmt: skip
    points = [
        np.array(v, dtype=float) / math.sqrt(v[0] ** 2 + v[1] ** 2 + v[2] ** 2) for v in verts
    ]
    midpoints: dict[tuple[int, int], int] = {}  # edge -> index of its midpoint

    def middle(i: int, j: int) -> int:
        key = (min(i, j), max(i, j))
        if key not in midpoints:
            m = points[i] + points[j]
            points.append(m / np.linalg.norm(m))
            midpoints[key] = len(points) - 1
        return midpoints[key]

    for _ in range(level):
        finer = []
        for i, j, k in faces:
            ij, jk, ki = middle(i, j), middle(j, k), middle(k, i)
            finer += [(i, ij, ki), (j, jk, ij), (k, ki, jk), (ij, jk, ki)]
        faces = finer
    neighbours: list[set[int]] = [set() for _ in points]
    for i, j, k in faces:
        neighbours[i] |= {j, k}
        neighbours[j] |= {i, k}
        neighbours[k] |= {i, j}
    rows = [sorted(n) for n in neighbours]
    table = np.array([row + row[:1] * (6 - len(row)) for row in rows], dtype=np.intp)
    return np.array(points), table


_SPHERE: tuple[np.ndarray, np.ndarray, np.ndarray] | None = None


def _sphere() -> tuple[np.ndarray, np.ndarray, np.ndarray]:
    """The grid (built once): points (n, 3), the same as (3, n), neighbours as (6, n)."""
    global _SPHERE
    if _SPHERE is None:
        points, neighbours = _icosphere(SPHERE_LEVEL)
        _SPHERE = (points, np.ascontiguousarray(points.T), np.ascontiguousarray(neighbours.T))
    return _SPHERE


def _grid_summits(D: np.ndarray, d1: np.ndarray, d2: np.ndarray) -> np.ndarray:
    """Grid directions where F is at least as high as at every grid neighbour (one pass)."""
    points, columns, neighbours = _sphere()
    dots = np.array((D, d1, d2)) @ columns  # D.u, d1.u, d2.u for every grid direction u
    c = np.clip(dots[1:], -1.0, 1.0)
    theta = np.arccos(c)
    F = dots[0] + (theta - np.sqrt(1.0 - c * c)).sum(axis=0)  # sin theta = sqrt(1 - c^2)
    summit = F >= F[neighbours].max(axis=0)
    # a summit next to u = -d1 or -d2 is the cone point of F there (theta = pi), not a path
    summit &= (theta < math.pi - 1e-3).all(axis=0)
    return points[summit]


def _cone_starts(D: np.ndarray, d1: np.ndarray, d2: np.ndarray) -> list[np.ndarray]:
    """Starts just beside the cone points u = -d1 and u = -d2 of F, where a summit can sit.

    At -d1, F is a smooth part S(u) = D.u + f(theta2(u)) plus f(theta1) ~ pi - 2 rho, a cone of
    slope 2 in the distance rho from -d1. When the gradient G of S there is longer than 2 the cone
    point is no summit and F rises away from it along G up to a path, possibly closer to -d1 than
    the grid spacing; a climb that starts on the far side of the cone could run into the cone, so
    one climb starts on the near side, at rho = 1e-3 along G (F rises from there to the path).
    """
    starts = []
    nD = float(np.linalg.norm(D))
    for cone, other in ((-d1, d2), (-d2, d1)):
        c = float(cone @ other)
        if c < -1.0 + 1e-9:
            continue  # d1 = d2: both cone points coincide; no smooth part to climb
        tan_half = math.sqrt(max(0.0, 1.0 - c * c)) / (1.0 + c)
        G = D - tan_half * other
        G = G - float(G @ cone) * cone
        nG = float(np.linalg.norm(G))
        # s = D.u - sin theta1 - sin theta2 changes by at most (|D| + 2) per radian of u, so
        # no path (s >= 0) lies within _CONE_REACH of the cone if s is too negative there
        s_cone = float(D @ cone) - math.sqrt(max(0.0, 1.0 - c * c))
        if nG > 1.99 and s_cone > -(nD + 2.0) * _CONE_REACH:
            v = cone * math.cos(1e-3) + (G / nG) * math.sin(1e-3)
            starts.append(v / np.linalg.norm(v))
    return starts


def _objective(D, d1, d2, u):
    """F(u) and what its gradient and Hessian need at the unit direction ``u`` (tuples).

    Returns (F, theta1, theta2, s, d1 x u, |d1 x u|, d2 x u, |d2 x u|), with
    s = D.u - sin theta1 - sin theta2 (the straight length / r if u is a path's).
    """
    u0, u1, u2 = u
    c1 = d1[0] * u0 + d1[1] * u1 + d1[2] * u2
    c2 = d2[0] * u0 + d2[1] * u1 + d2[2] * u2
    x1 = (d1[1] * u2 - d1[2] * u1, d1[2] * u0 - d1[0] * u2, d1[0] * u1 - d1[1] * u0)
    x2 = (d2[1] * u2 - d2[2] * u1, d2[2] * u0 - d2[0] * u2, d2[0] * u1 - d2[1] * u0)
    S1 = math.sqrt(x1[0] * x1[0] + x1[1] * x1[1] + x1[2] * x1[2])
    S2 = math.sqrt(x2[0] * x2[0] + x2[1] * x2[1] + x2[2] * x2[2])
    theta1 = math.atan2(S1, c1)
    theta2 = math.atan2(S2, c2)
    Du = D[0] * u0 + D[1] * u1 + D[2] * u2
    F = Du + (theta1 - S1) + (theta2 - S2)
    return F, theta1, theta2, Du - S1 - S2, x1, S1, x2, S2


def _climb(D, d1, d2, u) -> tuple[float, float] | None:
    """Climb F from the unit direction ``u`` to its summit; (a, b) there, or None at a cone.

    Newton's method on the sphere with the analytic gradient P_u (D - a d1 - b d2) and Hessian
    -s I - a t1 t1' - b t2 t2' (t_i the unit vector of d_i x u), shifted to stay negative
    definite, steps of at most 0.5 rad, and halving until F does not decrease.
    """
    sqrt = math.sqrt
    F, theta1, theta2, s, x1, S1, x2, S2 = _objective(D, d1, d2, u)
    for _ in range(_ASCENT_ITERATIONS):
        if theta1 >= _CONE_LIMIT or theta2 >= _CONE_LIMIT:
            return None
        a = math.tan(theta1 / 2.0)
        b = math.tan(theta2 / 2.0)
        u0, u1, u2 = u
        W = (D[0] - a * d1[0] - b * d2[0], D[1] - a * d1[1] - b * d2[1],
             D[2] - a * d1[2] - b * d2[2])  # fmt: skip
        Wu = W[0] * u0 + W[1] * u1 + W[2] * u2
        g = (W[0] - Wu * u0, W[1] - Wu * u1, W[2] - Wu * u2)
        # tangent basis e, f at u
        if abs(u0) < 0.9:
            e = (0.0, u2, -u1)  # (1, 0, 0) x u
        else:
            e = (-u2, 0.0, u0)  # (0, 1, 0) x u
        ne = sqrt(e[0] * e[0] + e[1] * e[1] + e[2] * e[2])
        e = (e[0] / ne, e[1] / ne, e[2] / ne)
        f = (u1 * e[2] - u2 * e[1], u2 * e[0] - u0 * e[2], u0 * e[1] - u1 * e[0])
        ge = g[0] * e[0] + g[1] * e[1] + g[2] * e[2]
        gf = g[0] * f[0] + g[1] * f[1] + g[2] * f[2]
        h11 = h22 = -s
        h12 = 0.0
        for w, S, x in ((a, S1, x1), (b, S2, x2)):
            if S > 0.0 and w > 0.0:
                te = (x[0] * e[0] + x[1] * e[1] + x[2] * e[2]) / S
                tf = (x[0] * f[0] + x[1] * f[1] + x[2] * f[2]) / S
                h11 -= w * te * te
                h12 -= w * te * tf
                h22 -= w * tf * tf
        # Newton step with the Hessian's eigenvalues made negative, -max(|lambda|, floor): a
        # step that climbs, long along flat ridges (then cut by the step limit and the halving)
        mean = 0.5 * (h11 + h22)
        half = sqrt(0.25 * (h11 - h22) ** 2 + h12 * h12)
        floor = 1e-9 * (abs(mean) + half + 1.0)
        xe = xf = 0.0
        for lam in (mean + half, mean - half):
            q1, q2 = (h12, lam - h11) if abs(lam - h11) >= abs(lam - h22) else (lam - h22, h12)
            nq = sqrt(q1 * q1 + q2 * q2)
            if nq == 0.0:  # a multiple of the identity: any basis is an eigenbasis
                q1, q2, nq = (1.0, 0.0, 1.0) if lam == mean + half else (0.0, 1.0, 1.0)
            q1 /= nq
            q2 /= nq
            weight = (ge * q1 + gf * q2) / max(abs(lam), floor)
            xe += weight * q1
            xf += weight * q2
        length = sqrt(xe * xe + xf * xf)
        if length > _ASCENT_MAX_STEP:
            xe *= _ASCENT_MAX_STEP / length
            xf *= _ASCENT_MAX_STEP / length
            length = _ASCENT_MAX_STEP
        if length < 1e-13:
            return a, b
        for _ in range(30):
            v = (u0 + xe * e[0] + xf * f[0], u1 + xe * e[1] + xf * f[1], u2 + xe * e[2] + xf * f[2])
            nv = sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2])
            v = (v[0] / nv, v[1] / nv, v[2] / nv)
            state = _objective(D, d1, d2, v)
            if state[0] >= F - 1e-15 * (abs(F) + 1.0):
                break
            xe *= 0.5
            xf *= 0.5
        else:
            return a, b  # no step climbs any more: at the summit to rounding
        u = v
        F, theta1, theta2, s, x1, S1, x2, S2 = state
    return math.tan(theta1 / 2.0), math.tan(theta2 / 2.0)


def _same_path(p: CSCPath, q: CSCPath, tol_length: float) -> bool:
    """True if two solved paths are one: equal turns, straight length and direction, or the same
    single arc split differently between the two turns (straight part 0, one circle)."""
    t = DUPLICATE_TOLERANCE
    if (
        abs(p.theta1 - q.theta1) <= t
        and abs(p.theta2 - q.theta2) <= t
        and abs(p.tMag - q.tMag) <= tol_length
        and float(np.max(np.abs(p.tUnit - q.tUnit))) <= t
    ):
        return True
    return (
        _single_arc(p, tol_length)
        and _single_arc(q, tol_length)
        and (
            abs((p.theta1 + p.theta2) - (q.theta1 + q.theta2)) <= t
            and float(np.max(np.abs(_arc_axis(p) - _arc_axis(q)))) <= 1e-6
        )
    )


def _single_arc(p: CSCPath, tol_length: float) -> bool:
    """The path is one circular arc: no straight part and both turns about one axis."""
    if p.tMag > tol_length:
        return False
    return (
        p.theta1 <= DUPLICATE_TOLERANCE
        or p.theta2 <= DUPLICATE_TOLERANCE
        or float(np.max(np.abs(p.k1 - p.k2))) <= 1e-6
    )


def _arc_axis(p: CSCPath) -> np.ndarray:
    return p.k1 if p.theta1 >= p.theta2 else p.k2


def solve_csc_all(p1, d1, p2, d2, r: float) -> list[CSCPath]:
    """Every (short, short) CSC path from (p1, d1) to (p2, d2) with turning radius ``r``.

    Both turns in [0, pi), straight part >= 0, each path checked like :func:`solve_csc`'s (it
    ends within ``END_TOLERANCE`` r of p2, its tangent within 1e-10 of d2). Paths that differ by
    less than ``DUPLICATE_TOLERANCE`` in theta1, theta2, tMag / r and u are merged, and so are
    the splits of one single arc. Sorted by length, then theta1, theta2 and u. The path
    :func:`solve_csc` returns, when it returns one, is in the list as the very same object.

    The search climbs the function F of docs/theory/csc.md from the summits of a fixed grid of
    2562 directions (~4 degrees apart) and from beside its two cone points (turns of pi):
    deterministic, and a few times the cost of solve_csc. Directions need not be normalised.
    In practice the list has one path or none (docs/theory/csc.md: no second path was ever
    seen, though none is proven impossible).

    Examples
    --------
    >>> paths = solve_csc_all((0, 0, 0), (1, 0, 0), (10, 4, 0), (1, 0, 0), 1.0)
    >>> [round(p.length, 6) for p in paths]
    [10.789582]
    """
    first = solve_csc(p1, d1, p2, d2, r)
    p1 = np.asarray(p1, dtype=float)
    p2 = np.asarray(p2, dtype=float)
    d1 = np.asarray(d1, dtype=float)
    d2 = np.asarray(d2, dtype=float)
    d1 = d1 / math.sqrt(float(d1 @ d1))
    d2 = d2 / math.sqrt(float(d2 @ d2))
    D = (p2 - p1) / r
    nD = math.sqrt(float(D @ D))
    paths = [] if first is None else [first]
    if nD < 1e-12 and float(d1 @ d2) > 1.0 - 1e-15:
        return paths  # identical frames: only the empty path (docs/theory/csc.md)
    tol_length = DUPLICATE_TOLERANCE * r + 1e-12 * nD * r
    d1t = (float(d1[0]), float(d1[1]), float(d1[2]))
    d2t = (float(d2[0]), float(d2[1]), float(d2[2]))
    Dt = (float(D[0]), float(D[1]), float(D[2]))
    for start in [*_grid_summits(D, d1, d2), *_cone_starts(D, d1, d2)]:
        summit = _climb(Dt, d1t, d2t, (float(start[0]), float(start[1]), float(start[2])))
        if summit is None:
            continue
        found = _accepted(_newton(Dt, d1t, d2t, *summit))
        if found is None:
            continue
        _, a, b, nV = found
        theta1, theta2, tMag = 2.0 * math.atan(a), 2.0 * math.atan(b), r * (nV - a - b)
        if any(
            abs(theta1 - p.theta1) <= 1e-12 + DUPLICATE_TOLERANCE
            and abs(theta2 - p.theta2) <= 1e-12 + DUPLICATE_TOLERANCE
            and abs(tMag - p.tMag) <= tol_length
            for p in paths
        ):
            continue  # a path found already (its u agrees too: u is fixed by a and b)
        path = _build(r, p1, d1, p2, d2, a, b, (D - a * d1 - b * d2) / nV)
        if path is None or not _closes(path, p2, d2, r, nD):
            continue
        if not any(_same_path(path, known, tol_length) for known in paths):
            paths.append(path)
    paths.sort(key=lambda p: (p.length, p.theta1, p.theta2, *p.tUnit.tolist()))
    return paths


# --- many lengths at once: csc_lengths ----------------------------------------------------------


def csc_lengths(p1, d1, p2, d2, r: float, restarts: bool = True) -> np.ndarray:
    """Lengths of the (short, short) CSC paths of N frame pairs at once (inf: none found).

    ``p1, d1, p2, d2`` are (N, 3) arrays (directions need not be normalised). The iteration is
    :func:`solve_csc`'s Newton method from the reference's start, run on all pairs together
    as numpy arrays (about 100x faster per pair than calling :func:`solve_csc` in a loop), so
    the lengths agree with ``solve_csc(...).length`` to about 1e-12 r wherever that start
    converges. Pairs where it does not (rare: :func:`solve_csc` then tries restarts) are
    solved one by one with :func:`solve_csc` (``restarts=False``: left at inf, which is much
    faster when many pairs have no path). Meant for searches that compare many candidate
    links; build the chosen link with the chain as usual.
    """
    p1 = np.atleast_2d(np.asarray(p1, dtype=float))
    p2 = np.atleast_2d(np.asarray(p2, dtype=float))
    d1 = np.atleast_2d(np.asarray(d1, dtype=float))
    d2 = np.atleast_2d(np.asarray(d2, dtype=float))
    d1 = d1 / np.sqrt(np.einsum("ij,ij->i", d1, d1))[:, None]
    d2 = d2 / np.sqrt(np.einsum("ij,ij->i", d2, d2))[:, None]
    D = (p2 - p1) / r
    nD = np.sqrt(np.einsum("ij,ij->i", D, D))
    n = D.shape[0]
    out = np.full(n, np.inf)
    same = (nD < 1e-12) & (np.einsum("ij,ij->i", d1, d2) > 1.0 - 1e-15)
    out[same] = 0.0
    u0 = np.where(nD[:, None] > 0.0, D / np.where(nD > 0.0, nD, 1.0)[:, None], d1)
    g1 = np.arctan2(np.linalg.norm(np.cross(d1, u0), axis=1), np.einsum("ij,ij->i", d1, u0))
    g2 = np.arctan2(np.linalg.norm(np.cross(u0, d2), axis=1), np.einsum("ij,ij->i", u0, d2))
    a = np.minimum(np.tan(g1 / 2.0), 1e3)
    b = np.minimum(np.tan(g2 / 2.0), 1e3)
    e = np.cross(d1, d2)
    d12 = np.einsum("ij,ij->i", d1, d2)
    active = ~same
    done = np.zeros(n, dtype=bool)
    prev = np.full(n, np.inf)
    nV_done = np.zeros(n)
    for _ in range(_MAX_ITERATIONS):
        idx = np.flatnonzero(active)
        if idx.size == 0:
            break
        A, B = a[idx], b[idx]
        x, y = d1[idx], d2[idx]
        V = D[idx] - A[:, None] * x - B[:, None] * y
        nV = np.sqrt(np.einsum("ij,ij->i", V, V))
        bad = nV < 1e-300
        nV = np.where(bad, 1.0, nV)
        u = V / nV[:, None]
        c1 = np.einsum("ij,ij->i", x, u)
        c2 = np.einsum("ij,ij->i", y, u)
        w1 = np.cross(x, u)
        w2 = np.cross(u, y)
        S1 = np.sqrt(np.einsum("ij,ij->i", w1, w1))
        S2 = np.sqrt(np.einsum("ij,ij->i", w2, w2))
        h1 = np.arctan2(S1, c1) - 2.0 * np.arctan(A)
        h2 = np.arctan2(S2, c2) - 2.0 * np.arctan(B)
        norm = np.maximum(np.abs(h1), np.abs(h2))
        converged = (norm < ANGLE_TOLERANCE) & ~bad
        ee = e[idx]
        with np.errstate(divide="ignore", invalid="ignore"):
            we1 = np.where(S1 > 0.0, np.einsum("ij,ij->i", w1, ee) / S1, 0.0)
            we2 = np.where(S2 > 0.0, np.einsum("ij,ij->i", w2, ee) / S2, 0.0)
        dc = -(d12[idx] - c1 * c2) / nV
        dS1_db = (-we1 + c2 * S1) / nV
        dS2_da = (-we2 + c1 * S2) / nV
        j11 = S1 / nV - 2.0 / (1.0 + A * A)
        j12 = c1 * dS1_db - S1 * dc
        j21 = c2 * dS2_da - S2 * dc
        j22 = S2 / nV - 2.0 / (1.0 + B * B)
        det = j11 * j22 - j12 * j21
        failed = bad | (~converged & ((det == 0.0) | ~np.isfinite(det)))
        with np.errstate(divide="ignore", invalid="ignore"):
            da = -(j22 * h1 - j12 * h2) / det
            db = -(-j21 * h1 + j11 * h2) / det
        step = np.where((norm > 0.5 * prev[idx]) & (norm > 1e-6), 0.5, 1.0)
        prev[idx] = norm
        moving = ~converged & ~failed
        a[idx[moving]] = np.clip(A[moving] + step[moving] * da[moving], 0.0, _MAX_TAN)
        b[idx[moving]] = np.clip(B[moving] + step[moving] * db[moving], 0.0, _MAX_TAN)
        ok = idx[converged]
        done[ok] = True
        nV_done[ok] = nV[converged]
        active[idx[converged | failed]] = False
    s_over_r = nV_done - a - b
    good = done & (s_over_r >= -1e-12)
    out[good] = r * (2.0 * np.arctan(a[good]) + np.maximum(s_over_r[good], 0.0)
                     + 2.0 * np.arctan(b[good]))  # fmt: skip
    for i in np.flatnonzero(~good & ~same) if restarts else ():
        path = solve_csc(p1[i], d1[i], p2[i], d2[i], r)
        if path is not None:
            out[i] = path.length
    return out
