"""The reference CSC algorithm, implemented literally, as an oracle for ``solve_csc``.

Four sign candidates, scipy ``fsolve`` with default settings from the reference's initial guess,
convergence at 0.001 r, the shortest converged candidate, the (+,+) candidate if none converged
(docs/theory/csc.md, "The reference solver").
"""

from __future__ import annotations

import math
import warnings

import numpy as np
from scipy.optimize import fsolve

#: Candidate order of the reference: (circle1sign, circle2sign) = (+,+), (+,-), (-,+), (-,-),
#: i.e. (sigma1, sigma2) = (short, long), (short, short), (long, long), (long, short).
REFERENCE_SIGNS = ((1, -1), (1, 1), (-1, -1), (-1, 1))
EPS_SELECT = 1e-3  # x r: a candidate counts as converged
EPS_LINK = 1e-2  # x r: a link accepts a candidate


def _angle(a, b) -> float:
    return math.atan2(float(np.linalg.norm(np.cross(a, b))), float(a @ b))


def _wrap(angle: float) -> float:
    w = angle % (2 * math.pi)
    return 0.0 if 2 * math.pi - w < 1e-5 else w


def _closure(p1, d1, p2, d2, r, signs):
    """The closure residual F(x) for one sign pair, and a decoder of x."""
    sigma1, sigma2 = signs

    def decode(x):
        v = x[:3]
        norm = float(np.linalg.norm(v))
        u = v / norm
        g1, g2 = _angle(d1, u), _angle(u, d2)
        q1 = p1 + sigma1 * r * math.tan(g1 / 2) * (d1 + u)
        q2 = p2 - sigma2 * r * math.tan(g2 / 2) * (u + d2)
        return u, abs(x[3]), g1, g2, q1, q2, norm

    def F(x):
        u, s, _, _, q1, q2, norm = decode(x)
        return np.concatenate([s * u - (q2 - q1), [norm - 1.0]])

    return F, decode


def reference_csc(p1, d1, p2, d2, r) -> dict:
    """The candidate the reference selects, with its residual |F|."""
    p1, p2 = np.asarray(p1, float), np.asarray(p2, float)
    d1 = np.asarray(d1, float) / np.linalg.norm(d1)
    d2 = np.asarray(d2, float) / np.linalg.norm(d2)
    delta = p2 - p1
    distance = float(np.linalg.norm(delta))
    if distance == 0.0:
        v0, s0 = d1.copy(), r
    else:
        v0, s0 = delta / distance, distance
    x0 = np.concatenate([v0, [s0]])
    candidates = []
    for signs in REFERENCE_SIGNS:
        F, decode = _closure(p1, d1, p2, d2, r, signs)
        with warnings.catch_warnings():
            warnings.simplefilter("ignore")  # fsolve's "not making progress"
            x = fsolve(F, x0)
            residual = float(np.linalg.norm(F(x)))
        u, s, g1, g2, _, _, _ = decode(x)
        theta1 = g1 if signs[0] > 0 else _wrap(2 * math.pi - g1)
        theta2 = g2 if signs[1] > 0 else _wrap(2 * math.pi - g2)
        candidates.append({
            "signs": signs, "theta1": theta1, "theta2": theta2, "tMag": s, "u": u,
            "residual": residual, "length": r * theta1 + s + r * theta2, "x": x,
        })  # fmt: skip
    converged = [c for c in candidates if c["residual"] <= EPS_SELECT * r]
    if not converged:
        return candidates[0]
    return min(converged, key=lambda c: c["length"])  # min keeps the first of ties


def reference_accepts(candidate: dict, r: float) -> bool:
    """The link accepts the selected candidate (residual within 0.01 r, both turns below pi)."""
    return (
        candidate["residual"] <= EPS_LINK * r
        and candidate["theta1"] < math.pi
        and candidate["theta2"] < math.pi
    )


def polish(p1, d1, p2, d2, r, candidate) -> dict:
    """fsolve restarted from the selected iterate (same sign family).

    fsolve stops once its step is below 1.49e-8 relative, so the reference's own values are
    accurate to ~1e-8 only; restarting once brings the residual to round-off, which makes a
    1e-9 comparison meaningful.
    """
    p1, p2 = np.asarray(p1, float), np.asarray(p2, float)
    d1 = np.asarray(d1, float) / np.linalg.norm(d1)
    d2 = np.asarray(d2, float) / np.linalg.norm(d2)
    F, decode = _closure(p1, d1, p2, d2, r, candidate["signs"])
    with warnings.catch_warnings():
        warnings.simplefilter("ignore")
        x = fsolve(F, candidate["x"])
    u, s, g1, g2, _, _, _ = decode(x)
    return {"theta1": g1, "theta2": g2, "tMag": s, "residual": float(np.linalg.norm(F(x)))}
