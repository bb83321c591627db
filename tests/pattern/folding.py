"""3D positions of the module vertices from spec section 3, written independently of the package.

Each ``fold_*`` function takes a module pattern and its parameters and returns an (N, 3) array
of vertex positions in the proximal frame (e_u, e_v, e_a) = (x, y, z), plus the indices of the
vertices the spec leaves undetermined. Vertices are located by their flat coordinates.
"""

from __future__ import annotations

import math

import numpy as np

from .helpers import find_vertex, periodic, polygon_point, prism_numbers, rotation


class _Positions:
    """Collects 3D positions, checking that a vertex given twice gets the same point."""

    def __init__(self, pattern, tol: float = 1e-9):
        self.pattern = pattern
        self.tol = tol
        self.X = np.full((pattern.numVertices, 3), np.nan)

    def set(self, index: int, point) -> None:
        point = np.asarray(point, dtype=float)
        if not np.isnan(self.X[index, 0]):
            assert np.allclose(self.X[index], point, atol=self.tol), (index, self.X[index], point)
        self.X[index] = point

    def at(self, xy, point) -> int:
        # vertices moved by the eps rules (section 2.1 snapping, fix B6) are within eps
        tol = max(1e-6, 1.5e-4 * self.pattern.sideLength)
        index = find_vertex(self.pattern, xy, tol=tol, nearest=True)
        self.set(index, point)
        return index


def vertex_points(n: int, r: float) -> np.ndarray:
    beta = (np.arange(n) + 0.5) * 2 * np.pi / n
    return np.stack([r * np.cos(beta), r * np.sin(beta), np.zeros(n)], axis=1)


def fold_tube(pattern) -> np.ndarray:
    v = pattern.vertices_coords
    X = polygon_point(v[:, 0], pattern.numSides, pattern.r)
    X[:, 2] = v[:, 1]
    return X


def fold_twist(pattern, alpha: float, h: float) -> np.ndarray:
    n, r = pattern.numSides, pattern.r
    step = 2 * np.pi / n
    alpha_bar = (alpha % (2 * np.pi)) % step
    beta = (np.arange(n) + 0.5) * step
    pos = _Positions(pattern)
    p = vertex_points(n, r)
    for k in range(n):
        pos.set(pattern.proximalBase[k], p[k])
        pos.set(
            pattern.distalBase[k],
            [r * math.cos(beta[k] + alpha_bar), r * math.sin(beta[k] + alpha_bar), h],
        )
    return pos.X


def elbow_numbers(n: int, r: float, theta: float, phi: float) -> dict:
    """h_k, H_m, tuck angles, collapsed columns: section 3.3, computed from scratch."""
    theta = theta - 2 * math.pi * round(theta / (2 * math.pi))
    if theta < 0:
        theta, phi = -theta, phi + math.pi
    b, _, _ = prism_numbers(n, r)
    beta = (np.arange(n) + 0.5) * 2 * np.pi / n
    d_w = r * math.tan(theta / 2)
    h = d_w * (1 + np.sin(beta - phi))
    H_m = h.max()
    A = np.pi - np.arctan((np.roll(h, 1) - h) / b) - np.arctan((np.roll(h, -1) - h) / b)
    q = np.stack([r * np.cos(beta), r * np.sin(beta), h], axis=1)
    B = np.empty(n)
    for k in range(n):
        u, w = q[(k + 1) % n] - q[k], q[k - 1] - q[k]
        B[k] = math.acos(u @ w / (np.linalg.norm(u) * np.linalg.norm(w)))
    eps = 1e-4 * b
    tuck = (A - B) / 2
    collapsed = (h >= H_m - eps) | ((H_m - h) * np.tan(tuck) < eps)  # with the B6 extension
    low = (h < eps) & ~collapsed
    # exact: no column was moved by the eps rules (else lengths agree to within a few eps)
    moved = np.concatenate([H_m - h[collapsed], h[low]])
    # offset vertices within eps of the seam are snapped onto it (section 2.1)
    O_x = np.mod((np.arange(n) + 0.5) * b + (H_m - h) * np.tan(tuck), n * b)[~collapsed]
    seam = np.minimum(O_x, n * b - O_x)
    moved = np.concatenate([moved, seam[(seam < eps) & (seam > 1e-12)]])
    return {"theta": theta, "phi": phi, "d_w": d_w, "h": h, "H_m": H_m, "tuck": tuck, "q": q,
            "collapsed": collapsed, "low": low, "eps": eps,
            "exact": bool(moved.max(initial=0.0) < 1e-12),
            # a vertex moved by up to eps tilts the tucked strip: lever arm H_m / b
            "approx_tol": 10 * eps * (1 + H_m / b)}  # fmt: skip


def elbow_transform(r: float, theta: float, phi: float):
    """E: rotation by theta about the line through r w parallel to g (section 3.3)."""
    g = np.array([math.cos(phi), math.sin(phi), 0.0])
    w = np.cross(g, [0.0, 0.0, 1.0])
    R = rotation(g, theta)
    return (lambda p: (np.asarray(p) - r * w) @ R.T + r * w), R, g, w


def fold_elbow(pattern, theta: float, phi: float) -> np.ndarray:
    n, r = pattern.numSides, pattern.r
    b, _, _ = prism_numbers(n, r)
    e = elbow_numbers(n, r, theta, phi)
    theta, phi, h, H_m, q = e["theta"], e["phi"], e["h"], e["H_m"], e["q"]
    H = 2 * H_m
    E, _, g, _ = elbow_transform(r, theta, phi)
    n_pi = rotation(g, theta / 2) @ np.array([0.0, 0.0, 1.0])
    p = vertex_points(n, r)
    x = (np.arange(n) + 0.5) * b
    pos = _Positions(pattern, 1e-9 if e["exact"] else e["approx_tol"])
    L = [None] * n
    for k in range(n):
        pos.set(pattern.proximalBase[k], p[k])
        pos.set(pattern.distalBase[k], E(p[k]))
        if e["low"][k]:  # fix B6: L_k is P_k and U_k is D_k (an approximation by h_k < eps)
            L[k] = (x[k], 0.0)
            continue
        L[k] = (x[k], H_m if e["collapsed"][k] else h[k])
        pos.at(L[k], q[k])
        pos.at((x[k], H_m if e["collapsed"][k] else H - h[k]), q[k])
    for k in range(n):
        k1 = (k + 1) % n
        a, c = np.array(L[k]), np.array(L[k1])
        d = c - a
        d[0] = periodic(d[0], pattern.width)
        e1 = d / np.linalg.norm(d)
        e2 = np.array([-e1[1], e1[0]])
        f1 = (q[k1] - q[k]) / np.linalg.norm(q[k1] - q[k])
        f2 = np.cross(n_pi, f1)

        def F(xy, a=a, e1=e1, e2=e2, qk=q[k], f1=f1, f2=f2):
            rel = np.array(xy, dtype=float) - a
            rel[0] = periodic(rel[0], pattern.width)
            return qk + (rel @ e1) * f1 + (rel @ e2) * f2

        offset = 0.0 if e["collapsed"][k] else (H_m - h[k]) * math.tan(e["tuck"][k])
        O_k = ((x[k] + offset) % pattern.width, H_m)
        M1 = (x[k1], H_m)
        pos.at(O_k, F(O_k))
        pos.at(M1, F(M1))
    return pos.X


def revolute_numbers(n: int, r: float, h_r: float) -> dict:
    """Crimp data of section 3.4 with psi = arctan(b / (2 H)), computed from scratch."""
    b, a, _ = prism_numbers(n, r)
    H = math.hypot(a, h_r)
    psi = math.atan(b / (2 * H))
    beta = (np.arange(n) + 0.5) * 2 * np.pi / n
    lam = np.sqrt(h_r**2 + (r * np.cos(beta)) ** 2)
    gamma = np.arctan(lam / (r * np.abs(np.sin(beta))))
    t = lam / np.sin(gamma + psi)
    flap = {0, n // 2 - 1, n // 2, n - 1}
    crimped = [k for k in range(n) if k not in flap]
    s = r * np.sin(beta) - np.sign(np.sin(beta)) * np.sqrt(
        np.maximum(t**2 - h_r**2 - (r * np.cos(beta)) ** 2, 0.0)
    )
    return {"b": b, "a": a, "H": H, "beta": beta, "t": t, "s": s, "crimped": crimped,
            "flap": sorted(flap)}  # fmt: skip


def fold_revolute_half(pattern, h_r: float, with_distal: bool):
    """Revolute joint at state 0 (or the end tip when ``with_distal`` is False)."""
    n, r = pattern.numSides, pattern.r
    d = revolute_numbers(n, r, h_r)
    b, H, beta = d["b"], d["H"], d["beta"]
    centre = np.array([0.0, 0.0, h_r])
    ev = np.array([0.0, 1.0, 0.0])
    p = vertex_points(n, r)
    x = (np.arange(n) + 0.5) * b
    pos = _Positions(pattern)
    skipped = []
    for k in range(n):
        pos.set(pattern.proximalBase[k], p[k])
        if with_distal:
            pos.set(pattern.distalBase[k], p[k] + [0.0, 0.0, 2 * h_r])
        pos.at((((k + 1) * b) % pattern.width, H), centre)  # C_k
        if k in d["flap"]:
            pos.at((x[k], H), centre + np.sign(math.sin(beta[k])) * (b / 2) * ev)
        else:
            skipped.append(find_vertex(pattern, (x[k], H)))
            pos.at((x[k], d["t"][k]), centre + d["s"][k] * ev)
            if with_distal:
                pos.at((x[k], 2 * H - d["t"][k]), centre + d["s"][k] * ev)
    return pos.X, skipped
