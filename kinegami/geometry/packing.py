"""Packing rectangles onto as few equal bins as they fit (the pieces of a sheet onto laser beds).

:func:`pack_rectangles` is a greedy first-fit decreasing packing: the rectangles are taken
longest first, and each goes into the first bin (in the order the bins were opened) that has
room for it, a new bin when none has. Inside a bin the free space is kept as a list of
rectangles (guillotine cuts): a rectangle goes into the free rectangle, and the orientation
(as given, or turned a quarter turn), that leaves the least on its shorter side (best short
side fit); what remains of that free rectangle is split in two along the cut that keeps the
larger piece whole. It is simple and fast, not optimal (packing is NP-hard): strips of one
width fill a bin side by side, shorter ones going into what the longer ones left.

Every length is in one unit (millimetres for beds); nothing here knows about patterns.
"""

from __future__ import annotations

import math
from collections.abc import Sequence

from kinegami._record import Record
from kinegami.errors import InvalidParameterError

__all__ = ["Placement", "pack_rectangles", "fits"]


class Placement(Record):
    """Where one rectangle went.

    Attributes
    ----------
    bin : int
        Index of the bin (0 for the first).
    x, y : float
        Lower left corner of the rectangle as placed, in the bin's coordinates.
    width, height : float
        Its extent along x and y as placed (swapped from the input when ``rotated``).
    rotated : bool
        Whether it was turned a quarter turn (counter-clockwise) to fit.
    """

    bin: int
    x: float
    y: float
    width: float
    height: float
    rotated: bool


def fits(size: tuple[float, float], room: tuple[float, float]) -> bool:
    """Whether a rectangle ``size`` (w, h) fits in ``room`` (w, h), turned or not."""
    (w, h), (rw, rh) = size, room
    return (w <= rw and h <= rh) or (h <= rw and w <= rh)


def _check_size(name: str, value) -> tuple[float, float]:
    try:
        w, h = (float(v) for v in value)
    except (TypeError, ValueError):
        raise InvalidParameterError(
            f"{name} must be two numbers (width, height), got {value!r}"
        ) from None
    if not (math.isfinite(w) and math.isfinite(h) and w > 0.0 and h > 0.0):
        raise InvalidParameterError(f"{name} must be two finite numbers > 0, got ({w!r}, {h!r})")
    return w, h


def pack_rectangles(
    sizes: Sequence[tuple[float, float]],
    bin_size: tuple[float, float],
    *,
    margin: float = 0.0,
    gap: float = 0.0,
) -> tuple[Placement, ...]:
    """Place rectangles onto as few bins of ``bin_size`` as a first-fit decreasing packing does.

    Parameters
    ----------
    sizes : sequence of (width, height)
        The rectangles (> 0); each may be turned a quarter turn.
    bin_size : (width, height)
        The bins (> 0).
    margin : float, optional
        Distance kept between every rectangle and the bin's edges (>= 0; default 0).
    gap : float, optional
        Distance kept between two rectangles of a bin (>= 0; default 0).

    Returns
    -------
    tuple of Placement
        One per rectangle, in the order of ``sizes``; bins are numbered 0, 1, ... in the order
        they were opened, none empty.

    Raises
    ------
    InvalidParameterError
        For a rectangle that does not fit an empty bin within the margins, or bad sizes.

    Examples
    --------
    >>> [p.bin for p in pack_rectangles([(10, 50), (10, 50), (10, 50)], (25, 60))]
    [0, 0, 1]
    """
    bw, bh = _check_size("bin_size", bin_size)
    margin, gap = float(margin), float(gap)
    if not (math.isfinite(margin) and margin >= 0.0 and math.isfinite(gap) and gap >= 0.0):
        raise InvalidParameterError(
            f"margin and gap must be finite numbers >= 0, got {margin!r} and {gap!r}"
        )
    room = (bw - 2.0 * margin, bh - 2.0 * margin)
    checked = [_check_size(f"sizes[{i}]", s) for i, s in enumerate(sizes)]
    for i, size in enumerate(checked):
        if room[0] <= 0.0 or room[1] <= 0.0 or not fits(size, room):
            raise InvalidParameterError(
                f"sizes[{i}] = {size[0]:g} x {size[1]:g} does not fit a bin of {bw:g} x {bh:g} "
                f"within its margin {margin:g} (room {max(room[0], 0):g} x {max(room[1], 0):g})"
            )
    # longest side first, then the larger area; ties keep the given order
    order = sorted(range(len(checked)), key=lambda i: (-max(checked[i]), -checked[i][0] *
                                                        checked[i][1], i))  # fmt: skip
    bins: list[list[tuple[float, float, float, float]]] = []  # free rectangles (x, y, w, h)
    placed: list[Placement | None] = [None] * len(checked)
    for i in order:
        w, h = checked[i]
        # a rectangle with its gap around it; the bins' free space is the room plus one gap
        need = (w + gap, h + gap)
        k, spot = next(((k, spot) for k, free in enumerate(bins)
                        if (spot := _best_spot(free, need)) is not None), (len(bins), None))
        if spot is None:
            bins.append([(margin, margin, room[0] + gap, room[1] + gap)])
            spot = _best_spot(bins[k], need)
        j, turned = spot
        fx, fy, fw, fh = bins[k].pop(j)
        pw, ph = (need[1], need[0]) if turned else need
        bins[k].extend(_split(fx, fy, fw, fh, pw, ph))
        placed[i] = Placement(k, fx, fy, h if turned else w, w if turned else h, turned)
    return tuple(placed)


def _best_spot(free, need) -> tuple[int, bool] | None:
    """(index of the free rectangle, turned) of the best short side fit, or None."""
    best, best_key = None, None
    for j, (_, _, fw, fh) in enumerate(free):
        for turned, (w, h) in ((False, need), (True, (need[1], need[0]))):
            if w <= fw and h <= fh:
                key = (min(fw - w, fh - h), max(fw - w, fh - h), j, turned)
                if best_key is None or key < best_key:
                    best, best_key = (j, turned), key
    return best


def _split(fx, fy, fw, fh, w, h) -> list[tuple[float, float, float, float]]:
    """What is left of the free rectangle (fx, fy, fw, fh) once a w x h rectangle takes its
    lower left corner: two rectangles, cut so that the larger leftover stays whole."""
    right_w, top_h = fw - w, fh - h
    if right_w * fh >= fw * top_h:  # the strip on the right is the larger: keep it full height
        parts = [(fx + w, fy, right_w, fh), (fx, fy + h, w, top_h)]
    else:
        parts = [(fx, fy + h, fw, top_h), (fx + w, fy, right_w, h)]
    return [p for p in parts if p[2] > 0.0 and p[3] > 0.0]
