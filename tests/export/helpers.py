"""Independent checks of a flattened sheet (brute force, for small sheets)."""

from __future__ import annotations

import numpy as np


def duplicate_pairs(segments: np.ndarray, kinds: np.ndarray, tol: float) -> list[tuple[int, int]]:
    """Pairs (i, j), i < j, of lines of equal kind with equal ends (either orientation)."""
    k = segments.shape[0]
    flat = segments.reshape(k, 4)
    rev = segments[:, ::-1].reshape(k, 4)
    same = np.abs(flat[:, None] - flat[None]).max(axis=2) <= tol
    same |= np.abs(flat[:, None] - rev[None]).max(axis=2) <= tol
    same &= kinds[:, None] == kinds[None]
    i, j = np.nonzero(np.triu(same, 1))
    return list(zip(i.tolist(), j.tolist(), strict=True))


def lengths(segments: np.ndarray) -> np.ndarray:
    d = segments[:, 1] - segments[:, 0]
    return np.hypot(d[:, 0], d[:, 1])


def point_segment_distance(points: np.ndarray, a: np.ndarray, b: np.ndarray) -> np.ndarray:
    """Distance from each point to the segment a-b."""
    d = b - a
    t = np.clip(((points - a) @ d) / (d @ d), 0.0, 1.0)
    return np.hypot(*(points - (a + t[:, None] * d)).T)


def reference_lines(pattern) -> tuple[np.ndarray, np.ndarray]:
    """The creases drawn by the reference rule of spec 5.2, then clipped as recommended (B8).

    A slow, literal re-implementation (one crease at a time) to compare ``flatten`` against.
    """
    W, b, eps = pattern.width, pattern.sideLength, pattern.eps
    tol = 1e-9 * pattern.r
    xmin, xmax = -b / 2, W + b / 2
    drawn = []
    for (i, j), label in zip(pattern.edges_vertices.tolist(), pattern.edges_assignment.tolist(),
                             strict=True):  # fmt: skip
        (x0, y0), (x1, y1) = pattern.vertices_coords[i], pattern.vertices_coords[j]
        dx = x0 - x1
        if abs(dx) > W / 2 - eps:  # wrapping crease (|dx| = W/2 never occurs in the catalog)
            if x0 < x1:
                drawn += [((x0 + W, y0), (x1, y1), label), ((x0, y0), (x1 - W, y1), label)]
            else:
                drawn += [((x0, y0), (x1 + W, y1), label), ((x0 - W, y0), (x1, y1), label)]
            continue
        drawn.append(((x0, y0), (x1, y1), label))
        if min(x0, x1) <= b + eps:
            drawn.append(((x0 + W, y0), (x1 + W, y1), label))
        if max(x0, x1) >= W - b - eps:
            drawn.append(((x0 - W, y0), (x1 - W, y1), label))
    segments, labels = [], []
    snap = {True: xmin, False: xmax}
    for (ax, ay), (bx, by), label in drawn:
        # ends within eps of a cut edge are put on it (as flatten does)
        if min(abs(ax - xmin), abs(ax - xmax)) <= eps:
            ax = snap[abs(ax - xmin) <= eps]
        if min(abs(bx - xmin), abs(bx - xmax)) <= eps:
            bx = snap[abs(bx - xmin) <= eps]
        if abs(bx - ax) <= tol:
            if xmin + tol < ax < xmax - tol and abs(by - ay) > tol:
                segments.append(((ax, ay), (bx, by)))
                labels.append(label)
            continue
        ts = sorted([(xmin - ax) / (bx - ax), (xmax - ax) / (bx - ax)])
        t0, t1 = max(0.0, ts[0]), min(1.0, ts[1])
        p = (ax + t0 * (bx - ax), ay + t0 * (by - ay))
        q = (ax + t1 * (bx - ax), ay + t1 * (by - ay))
        on_edge = max(p[0], q[0]) <= xmin + tol or min(p[0], q[0]) >= xmax - tol
        if t1 > t0 and np.hypot(q[0] - p[0], q[1] - p[1]) > tol and not on_edge:
            segments.append((p, q))
            labels.append(label)
    return np.array(segments, dtype=float).reshape(-1, 2, 2), np.array(labels, dtype="<U1")


def same_line_sets(a, ka, b, kb, tol) -> bool:
    """True when every line of each set has an equal line in the other (either orientation,
    labels included; lines equal within ``tol`` may be repeated in one set)."""
    if a.shape[0] == 0 or b.shape[0] == 0:
        return a.shape[0] == b.shape[0]
    fa, fb, rb = a.reshape(-1, 4), b.reshape(-1, 4), b[:, ::-1].reshape(-1, 4)
    close = np.abs(fa[:, None] - fb[None]).max(axis=2) <= tol
    close |= np.abs(fa[:, None] - rb[None]).max(axis=2) <= tol
    close &= ka[:, None] == kb[None]
    return bool(close.any(axis=1).all() and close.any(axis=0).all())
