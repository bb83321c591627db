"""3D CSC Dubins paths of turning radius r between two frames (chain.md section 2).

A CSC path leaves ``p1`` along ``d1``, turns on a circle of radius r through ``theta1`` until
its tangent is ``u``, runs straight for ``tMag`` along ``u`` and turns through ``theta2`` onto
``d2``, ending at ``p2``. Only the (short, short) family matters to kinegami: links reject turns
of pi or more, and long turns are always more than pi (chain.md 2.2 [FIX]).

The solver. With the scaled tangent lengths a = tan(theta1/2) and b = tan(theta2/2), the
closure equation ``p2 - p1 = r a (d1 + u) + s u + r b (u + d2)`` says that ``u`` is the unit
vector of ``V(a, b) = (p2 - p1)/r - a d1 - b d2`` and that ``s = r (|V| - a - b)``. What is
left are two scalar equations in (a, b):

    angle(d1, u(a, b)) = 2 atan(a),    angle(u(a, b), d2) = 2 atan(b),

solved by Newton's method with the analytic Jacobian from the reference's initial guess
(u along p2 - p1), with a deterministic grid of restarts if that fails. Each link takes a few
Newton steps of scalar arithmetic (tens of microseconds).
"""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinegami.geometry.frames import any_perpendicular, rotation_matrix

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
        centre2 = q2 + self.r * np.cross(self.k2, u)
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

    # The reference's initial guess: u along p2 - p1 (chain.md 2.2). Its root is unique in
    # practice; only when it fails are the best points of a grid tried as restarts.
    u0 = D / nD if nD > 0.0 else d1
    g1 = math.atan2(float(np.linalg.norm(np.cross(d1, u0))), float(d1 @ u0))
    g2 = math.atan2(float(np.linalg.norm(np.cross(u0, d2))), float(u0 @ d2))
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
    if path is None:
        return None
    # Near a U-turn (a or b ~ 1e6) a root with tiny angle residuals can still miss the end
    # point: such a path is not one (chain.md 2.3's residual check, in lengths).
    end, tangent = path.reconstruct_end()
    miss = float(np.max(np.abs(end - p2)))
    if miss > END_TOLERANCE * r + 1e-12 * nD * r or float(np.max(np.abs(tangent - d2))) > 1e-10:
        return None
    return path


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
    cr1 = np.cross(d1, u)
    cr2 = np.cross(u, d2)
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
    k1 = np.cross(d1, w1)
    k2 = np.cross(d2, w2)
    return CSCPath(r, p1, d1, p2, d2, theta1, theta2, s, u, q1, q2, w1, w2, k1, k2)
