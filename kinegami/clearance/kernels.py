"""Compiled kernels (numba) of the clearance engine's one-configuration query.

:meth:`kinegami.clearance.engine.ClearanceEngine.report` at one configuration spends its time
in the fixed cost of some sixty small numpy calls (about 1 us each), not in arithmetic. An
engine asked many times (inverse kinematics, the editor, a loop over configurations) runs
:func:`one_configuration` instead: the same end points, bounds and exact distances as the
numpy path, with the same arithmetic in the same order (no fused multiply-adds: numba's
default ``fastmath=False``), so the same bits. The body motions stay numpy's
(:meth:`kinegami.geometry.screws.JointScrews.body_motions_one`: its 4x4 products are BLAS's).

Compiled once per machine (``cache=True``: the machine code is kept beside this file, or in
numba's per-user cache when the package cannot be written); the engine loads this module only
once it has been asked :data:`~kinegami.clearance.engine.COMPILED_AFTER` times.
"""

from __future__ import annotations

import math

import numpy as np
from numba import njit

__all__ = ["body_motions", "one_configuration", "segment_distance_compiled"]

#: A squared segment length below which a segment is a point (geometry.segments' _DEGENERATE).
DEGENERATE = 1e-30


@njit(cache=True)
def _unit(x: float) -> float:
    """``x`` clamped to [0, 1] as numpy.clip does it (-0.0 stays -0.0; NaN gives 0)."""
    if x >= 0.0:
        return x if x <= 1.0 else 1.0
    return 0.0


@njit(cache=True)
def segment_distance_compiled(ax, ay, az, bx, by, bz, cx, cy, cz, ex, ey, ez):
    """:func:`kinegami.geometry.segments.segment_distance` of the segments (a, b) and (c, e),
    compiled: the same arithmetic step by step (the guarded form where a segment is a point).
    Returns ``(distance, s, t)``."""
    ux, uy, uz = bx - ax, by - ay, bz - az
    vx, vy, vz = ex - cx, ey - cy, ez - cz
    wx, wy, wz = ax - cx, ay - cy, az - cz
    A = (ux * ux + uz * uz) + uy * uy
    E = (vx * vx + vz * vz) + vy * vy
    B = (ux * vx + uz * vz) + uy * vy
    C = (ux * wx + uz * wz) + uy * wy
    F = (vx * wx + vz * wz) + vy * wy
    ok1 = A > DEGENERATE
    ok2 = E > DEGENERATE
    A_safe = A if ok1 else 1.0
    E_safe = E if ok2 else 1.0
    denom = A * E - B * B
    if ok1 and ok2:
        s = _unit((B * F - C * E) / denom) if denom > 1e-14 * A * E else 0.0
    else:
        s = 0.0
    t = _unit((B * s + F) / E_safe) if ok2 else 0.0
    s = _unit((B * t - C) / A_safe) if ok1 else 0.0
    t = _unit((B * s + F) / E_safe) if ok2 else 0.0
    u0 = _unit(((wx * vx + wz * vz) + wy * vy) / E_safe) if ok2 else 0.0
    px, py, pz = bx - cx, by - cy, bz - cz
    u1 = _unit(((px * vx + pz * vz) + py * vy) / E_safe) if ok2 else 0.0
    px, py, pz = cx - ax, cy - ay, cz - az
    u2 = _unit(((px * ux + pz * uz) + py * uy) / A_safe) if ok1 else 0.0
    px, py, pz = ex - ax, ey - ay, ez - az
    u3 = _unit(((px * ux + pz * uz) + py * uy) / A_safe) if ok1 else 0.0
    best, bp, bq = math.inf, 0.0, 0.0
    for k in range(5):  # the first smallest, as numpy.argmin
        if k == 0:
            p, q = s, t
        elif k == 1:
            p, q = 0.0, u0
        elif k == 2:
            p, q = 1.0, u1
        elif k == 3:
            p, q = u2, 0.0
        else:
            p, q = u3, 1.0
        gx = (ax + p * ux) - (cx + q * vx)
        gy = (ay + p * uy) - (cy + q * vy)
        gz = (az + p * uz) - (cz + q * vz)
        d = math.sqrt((gx * gx + gy * gy) + gz * gz)
        if d < best:
            best, bp, bq = d, p, q
    return best, bp, bq


@njit(cache=True)
def body_motions(delta, sine, versine, K1, K2, points, axes, revolute, parent):
    """:meth:`kinegami.geometry.screws.JointScrews.body_motions_one` compiled: (NB, 4, 4)
    every body's motion for the moving joints' state changes ``delta`` (M,), with ``sine`` and
    ``versine`` (sin, 1 - cos: numpy's, passed in), each joint's cross-product matrix ``K1``
    and its square ``K2`` (M, 3, 3), its axis's point and direction (M, 3), whether it turns,
    and each body's parent (M + 1,). The same sums in the same order as the numpy path
    (:meth:`~kinegami.geometry.screws.JointScrews.local_motions`,
    :func:`~kinegami.geometry.screws.rigid_product`), so the same bits."""
    M = delta.shape[0]
    B = np.empty((M + 1, 4, 4))
    for i in range(4):
        for j in range(4):
            B[0, i, j] = 1.0 if i == j else 0.0
    R = np.empty((3, 3))
    t = np.empty(3)
    for b in range(1, M + 1):
        m = b - 1
        s = sine[m] if revolute[m] else 0.0
        c = versine[m] if revolute[m] else 0.0
        for i in range(3):
            for j in range(3):
                R[i, j] = ((1.0 if i == j else 0.0) + s * K1[m, i, j]) + c * K2[m, i, j]
        px, py, pz = points[m, 0], points[m, 1], points[m, 2]
        for i in range(3):
            if revolute[m]:
                t[i] = (points[m, i]) - ((R[i, 0] * px + R[i, 1] * py) + R[i, 2] * pz)
            else:
                t[i] = delta[m] * axes[m, i]
        out = B[b]
        out[3, 0], out[3, 1], out[3, 2], out[3, 3] = 0.0, 0.0, 0.0, 1.0
        if parent[b] == 0:
            for i in range(3):
                for j in range(3):
                    out[i, j] = R[i, j]
                out[i, 3] = t[i]
            continue
        P = B[parent[b]]
        for i in range(3):
            for j in range(3):
                out[i, j] = (P[i, 0] * R[0, j] + P[i, 1] * R[1, j]) + P[i, 2] * R[2, j]
            out[i, 3] = ((P[i, 0] * t[0] + P[i, 1] * t[1]) + P[i, 2] * t[2]) + P[i, 3]
    return B


@njit(cache=True)
def _sift_down(heap, key, root, size):
    """Restore the min-heap order of ``heap[:size]`` (indices into ``key``) below ``root``."""
    item = heap[root]
    while True:
        child = 2 * root + 1
        if child >= size:
            break
        if child + 1 < size and key[heap[child + 1]] < key[heap[child]]:
            child += 1
        if key[heap[child]] < key[item]:
            heap[root] = heap[child]
            root = child
        else:
            break
    heap[root] = item


@njit(cache=True)
def one_configuration(B, rows, points, pair_i, pair_j, twice_half, sure, maybe_turn, maybe_bi,
                      maybe_bj, kink_joints, kink_parents, values, turn_max, limit, static_min,
                      slack, r2):  # fmt: skip
    """The exact clearances the one-configuration report needs, and the moved end points.

    ``B`` (NB, 4, 4): the body motions; ``rows`` (2S,): each capsule end point's body (starts,
    then ends); ``points`` (2S, 3): the end points at the reference configuration; the listed
    pairs ``pair_i``, ``pair_j`` (P,) with ``twice_half`` (twice their half lengths added
    up), the first ``sure`` of them tested always, the others (``maybe_*``: their turning at
    the reference and their bodies) where the turning the revolute hinges add
    (``kink_joints``: each body's hinge joint or -1; ``kink_parents``: each body's parent,
    empty for a chain; ``values``: the states) reaches ``turn_max``.

    Every tested pair is bounded below by its centres' distance less both half lengths; the
    pairs are measured exactly in the order of their bounds until the next bound exceeds both
    ``limit`` and the smallest clearance found (and ``static_min``), so every pair closer than
    the limit and the closest tested pair are measured (chain units; twice the bounds, with
    ``slack`` for rounding). Returns ``(clearance, pair, s, t, W)``: of the measured pairs,
    those closer than the limit and the closest ones, their clearances (distance less
    ``r2``), indices and closest points' parameters; and the end points W (2S, 3) moved
    (``((B0 x + B1 y) + B2 z) + B3``, the numpy path's order)."""
    n2 = rows.shape[0]
    S = n2 // 2
    W = np.empty((n2, 3))
    for p in range(n2):
        b = rows[p]
        x, y, z = points[p, 0], points[p, 1], points[p, 2]
        for c in range(3):
            W[p, c] = ((B[b, c, 0] * x + B[b, c, 1] * y) + B[b, c, 2] * z) + B[b, c, 3] * 1.0
    P = pair_i.shape[0]
    low = np.empty(P)
    top = math.inf
    for n in range(P):
        i, j = pair_i[n], pair_j[n]
        dx = (W[i, 0] + W[S + i, 0]) - (W[j, 0] + W[S + j, 0])
        dy = (W[i, 1] + W[S + i, 1]) - (W[j, 1] + W[S + j, 1])
        dz = (W[i, 2] + W[S + i, 2]) - (W[j, 2] + W[S + j, 2])
        g = math.sqrt((dx * dx + dy * dy) + dz * dz)  # twice the centres' distance
        low[n] = g - twice_half[n]  # twice (a lower bound of the clearance + 2r)
        if n < sure and g < top:
            top = g
    # the turning the hinges add up to every body (ClearanceEngine._kinks, same sums)
    NB = kink_joints.shape[0] + 1
    kinks = np.zeros(NB)
    total = 0.0
    for b in range(1, NB):
        m = kink_joints[b - 1]
        add = abs(values[m]) if m >= 0 else 0.0
        if kink_parents.shape[0] == 0:
            total += add
            kinks[b] = total
        else:
            kinks[b] = kinks[kink_parents[b]] + add
    bound = max(limit, min(0.5 * top - r2, static_min))
    cut = 2.0 * (bound + slack + r2)
    chosen = np.empty(P, dtype=np.int64)
    count = 0
    for n in range(P):
        if low[n] <= cut or not math.isfinite(bound):
            if n >= sure:
                k = n - sure
                if abs((maybe_turn[k] + kinks[maybe_bj[k]]) - kinks[maybe_bi[k]]) < turn_max:
                    continue  # the turning rule does not test it here
            chosen[count] = n
            count += 1
    # the chosen pairs in the order of their bounds, taken from a binary heap one at a time
    # (numba's argsort costs seconds of compilation; the loop usually stops after a few)
    heap = chosen[:count].copy()
    for root in range(count // 2 - 1, -1, -1):
        _sift_down(heap, low, root, count)
    clearance = np.empty(count)
    pair = np.empty(count, dtype=np.int64)
    s_out = np.empty(count)
    t_out = np.empty(count)
    best = math.inf
    measured = 0
    size = count
    while size > 0:
        n = heap[0]
        size -= 1
        heap[0] = heap[size]
        _sift_down(heap, low, 0, size)
        if low[n] > 2.0 * (max(limit, min(best, static_min)) + slack + r2):
            break
        i, j = pair_i[n], pair_j[n]
        d, s, t = segment_distance_compiled(W[i, 0], W[i, 1], W[i, 2],
                                            W[S + i, 0], W[S + i, 1], W[S + i, 2],
                                            W[j, 0], W[j, 1], W[j, 2],
                                            W[S + j, 0], W[S + j, 1], W[S + j, 2])  # fmt: skip
        clearance[measured] = d - r2
        pair[measured] = n
        s_out[measured] = s
        t_out[measured] = t
        measured += 1
        if d - r2 < best:
            best = d - r2
    # the report needs the pairs closer than the limit and the closest (all of them on a tie)
    kept = 0
    for k in range(measured):
        if clearance[k] < limit or clearance[k] == best:
            clearance[kept], pair[kept] = clearance[k], pair[k]
            s_out[kept], t_out[kept] = s_out[k], t_out[k]
            kept += 1
    return clearance[:kept], pair[:kept], s_out[:kept], t_out[:kept], W
