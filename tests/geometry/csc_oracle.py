"""A brute-force oracle for every (short, short) CSC path, independent of kinegami's solver.

It parametrises the path by the first turn alone: the direction phi of its centre about d1 and
its angle theta1. These fix the straight direction u, hence the second turn (the short rotation
from u to d2) and the point q2 where the straight part must end. What is left is the part of
q2 - q1 perpendicular to u, a tangent vector field R(phi, theta1) whose zeros are the paths. The
oracle samples R on a fine (phi, theta1) grid, keeps every cell around which R winds (a zero of
R inside, by the argument principle), solves R = 0 from the cell centre with scipy's hybrid
Powell method and keeps the roots with both turns below pi and a straight part >= 0.
"""

from __future__ import annotations

import math

import numpy as np
from scipy.optimize import root


def _basis(d: np.ndarray) -> tuple[np.ndarray, np.ndarray]:
    helper = np.array([1.0, 0.0, 0.0]) if abs(d[0]) < 0.9 else np.array([0.0, 1.0, 0.0])
    e1 = np.cross(d, helper)
    e1 /= np.linalg.norm(e1)
    return e1, np.cross(d, e1)


def _field(D, d1, d2, e1, e2, phi, theta):
    """R = (g . e_theta, g . e_phi) with g = q2 - q1 (units of r), and s = g . u, theta2."""
    phi, theta = np.asarray(phi, float), np.asarray(theta, float)
    c, s = np.cos(phi)[..., None], np.sin(phi)[..., None]
    w = c * e1 + s * e2
    e_phi = -s * e1 + c * e2
    ct, st = np.cos(theta)[..., None], np.sin(theta)[..., None]
    u = ct * d1 + st * w
    e_theta = -st * d1 + ct * w
    a = np.tan(theta / 2)[..., None]
    theta2 = np.arctan2(np.linalg.norm(np.cross(u, d2), axis=-1), u @ d2)
    b = np.tan(theta2 / 2)[..., None]
    g = D - b * (u + d2) - a * (d1 + u)
    R = np.stack([np.sum(g * e_theta, axis=-1), np.sum(g * e_phi, axis=-1)], axis=-1)
    return R, np.sum(g * u, axis=-1), theta2, u


def oracle_paths(p1, d1, p2, d2, r, n_phi: int = 480, n_theta: int = 240) -> list[tuple]:
    """Every path the grid sees: (theta1, theta2, tMag, u) tuples, tMag in the units of r."""
    d1 = np.asarray(d1, float) / np.linalg.norm(d1)
    d2 = np.asarray(d2, float) / np.linalg.norm(d2)
    D = (np.asarray(p2, float) - np.asarray(p1, float)) / r
    e1, e2 = _basis(d1)
    phi = np.linspace(0.0, 2 * math.pi, n_phi + 1)  # closed: the last column repeats the first
    # plus rows closing in on theta1 = 0 and pi, where paths can sit between the even rows
    ends = np.logspace(-7, math.log10(0.5 * math.pi / n_theta), 6)
    theta = np.concatenate([ends, np.linspace(0.0, math.pi, n_theta + 1)[1:-1], math.pi - ends])
    theta.sort()
    P, T = np.meshgrid(phi, theta, indexing="ij")
    R, _, _, _ = _field(D, d1, d2, e1, e2, P, T)
    angle = np.arctan2(R[..., 1], R[..., 0])

    def turn(x, y):
        return (y - x + math.pi) % (2 * math.pi) - math.pi

    winding = (
        turn(angle[:-1, :-1], angle[1:, :-1])
        + turn(angle[1:, :-1], angle[1:, 1:])
        + turn(angle[1:, 1:], angle[:-1, 1:])
        + turn(angle[:-1, 1:], angle[:-1, :-1])
    )
    cells = np.argwhere(np.abs(winding) > math.pi)
    found: list[tuple] = []
    for i, j in cells:
        x0 = [0.5 * (phi[i] + phi[i + 1]), 0.5 * (theta[j] + theta[j + 1])]
        sol = root(
            lambda x: _field(D, d1, d2, e1, e2, x[0], x[1])[0], x0, method="hybr",
            options={"xtol": 1e-14},
        )  # fmt: skip
        ph, th = sol.x
        if th < 0:
            ph, th = ph + math.pi, -th
        if not 0.0 <= th < math.pi:
            continue
        R1, s1, theta2, u = _field(D, d1, d2, e1, e2, ph, th)
        if np.max(np.abs(R1)) > 1e-9 * (1.0 + np.linalg.norm(D)) or s1 < -1e-9 or theta2 >= math.pi:
            continue
        candidate = (float(th), float(theta2), max(float(s1), 0.0) * r, np.asarray(u))
        if not any(
            abs(candidate[0] - o[0]) < 1e-7
            and abs(candidate[1] - o[1]) < 1e-7
            and abs(candidate[2] - o[2]) < 1e-7 * r
            for o in found
        ):
            found.append(candidate)
    return found
