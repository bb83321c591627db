"""Putting the pieces of a cut sheet back together, independently of kinegami.pattern.pieces:
the creases of every piece's own sheet (its tab left out), with each crease that a cut split
joined again to its other half, compared with the whole sheet's creases."""

from __future__ import annotations

import numpy as np

from kinegami.pattern.sheet import flatten


def sheet_creases(pattern) -> tuple[np.ndarray, np.ndarray]:
    """The mountain and valley lines of a pattern's flat sheet, each from its lower end."""
    sheet = flatten(pattern)
    keep = np.isin(sheet.kinds, ("M", "V"))
    segments, kinds = sheet.segments[keep].copy(), sheet.kinds[keep]
    ys, xs = segments[:, :, 1], segments[:, :, 0]
    swap = (ys[:, 0] > ys[:, 1]) | ((ys[:, 0] == ys[:, 1]) & (xs[:, 0] > xs[:, 1]))
    segments[swap] = segments[swap][:, ::-1]
    return segments, kinds


def reassembled(pieces, tol: float) -> tuple[np.ndarray, np.ndarray]:
    """The creases of the pieces put back together: every piece's own part (below its join
    line), creases ending on a cut joined to the crease of the next piece that starts there
    in the same direction, with the same assignment."""
    segments, kinds = [], []
    for piece in pieces:
        s, k = sheet_creases(piece.pattern)
        own = (s[:, :, 1] <= piece.end + tol).all(axis=1)  # the tab is the next piece's copy
        segments.append(s[own])
        kinds.append(k[own])
    segments, kinds = np.concatenate(segments), np.concatenate(kinds)
    for piece in pieces[:-1]:
        cut = piece.end
        ending = np.flatnonzero(np.abs(segments[:, 1, 1] - cut) <= tol)
        starting = set(np.flatnonzero(np.abs(segments[:, 0, 1] - cut) <= tol).tolist())
        joined = []
        for i in ending.tolist():
            di = segments[i, 1] - segments[i, 0]
            di /= np.linalg.norm(di)
            for j in sorted(starting):
                dj = segments[j, 1] - segments[j, 0]
                dj /= np.linalg.norm(dj)
                if (kinds[j] == kinds[i] and np.abs(segments[j, 0] - segments[i, 1]).max() <= tol
                        and np.abs(di - dj).max() <= 1e-9):  # fmt: skip
                    segments[i, 1] = segments[j, 1]
                    starting.discard(j)
                    joined.append(j)
                    break
        keep = np.ones(segments.shape[0], dtype=bool)
        keep[joined] = False
        segments, kinds = segments[keep], kinds[keep]
    return segments, kinds


def _sorted(segments: np.ndarray, kinds: np.ndarray, grid: float):
    key = np.round(segments.reshape(-1, 4) / grid)
    order = np.lexsort((*key.T[::-1], kinds))
    return segments[order], kinds[order]


def reassembly_error(whole, pieces, tol: float = 1e-9) -> float:
    """Largest coordinate difference between the whole sheet's creases and the pieces' put
    back together (pattern units); AssertionError when their counts or assignments differ."""
    a, ka = _sorted(*sheet_creases(whole), grid=1e-6)
    b, kb = _sorted(*reassembled(pieces, tol), grid=1e-6)
    assert a.shape == b.shape, f"{a.shape[0]} creases on the sheet, {b.shape[0]} reassembled"
    assert (ka == kb).all(), "assignments differ"
    return float(np.abs(a - b).max()) if a.size else 0.0
