"""Twist fitting: a band of triangles that rotates the tube about its axis (spec section 3.2)."""

from __future__ import annotations

import math
from dataclasses import dataclass

import numpy as np

from kinegami.pattern._build import assemble, crease_block
from kinegami.pattern._prism import Prism, make_prism, wrap_x
from kinegami.pattern.tubular import ModuleRecord, TubularPattern
from kinegami.validation import check_nonnegative, check_real

__all__ = ["TwistFittingPattern", "TwistGeometry", "twist_geometry"]


@dataclass(frozen=True)
class TwistGeometry:
    """Derived quantities of a twist (section 3.2); lengths in units of r, angles in radians.

    Attributes
    ----------
    K : int
        Whole columns of the rotation (relabelling only), in 0 .. n-1.
    residual : float
        The folded part of the rotation, alpha_bar in [0, 2 pi / n).
    shift : float
        Side shift s of the distal base in x, in [0, b).
    excess : float
        Radial excess e of a rotated vertex beyond the original side.
    height : float
        Pattern height H = sqrt(h^2 + e^2).
    degenerate : bool
        True when H < eps: the module is only a relabelling by round(n alpha' / 2 pi) columns.
    """

    K: int
    residual: float
    shift: float
    excess: float
    height: float
    degenerate: bool


def twist_geometry(prism: Prism, twistAngle: float, moduleHeight: float) -> TwistGeometry:
    """Decompose ``twistAngle`` into whole columns and the folded residual (section 3.2)."""
    n, r = prism.numSides, prism.r
    step = 2.0 * math.pi / n
    alpha = twistAngle % (2.0 * math.pi)
    if alpha >= 2.0 * math.pi:  # float rounding of tiny negative angles
        alpha = 0.0
    K = min(int(math.floor(alpha / step)), n - 1)
    residual = max(alpha - K * step, 0.0)
    shift = r * (math.sin(math.pi / n) + math.sin(residual - math.pi / n))
    excess = r * (math.cos(math.pi / n - residual) - math.cos(math.pi / n))
    height = math.hypot(moduleHeight, excess)
    return TwistGeometry(K, residual, shift, excess, height, height < prism.eps)


def TwistFittingPattern(
    numSides: int, r: float, twistAngle: float, moduleHeight: float
) -> TubularPattern:
    """A twist by ``twistAngle`` about the tube axis over axial length ``moduleHeight``.

    The rotation is split into K whole columns (a relabelling, no folds) and a residual
    alpha_bar in [0, 2 pi/n) that is folded as a band of 2n triangles: right diagonals
    P_k-D_k and left diagonals D_{k-1}-P_k (mountain), both rings valley. The distal base is
    shifted by s in x and the distal marker by K b + s (section 3.2).

    Parameters
    ----------
    numSides : int
        Number of sides n (even, >= 4).
    r : float
        Tube circumradius (> 0).
    twistAngle : float
        Rotation alpha about the forward tube axis, radians, any real value (alpha and
        alpha + 2 pi give the same pattern). Positive alpha turns e_u towards e_v.
    moduleHeight : float
        Axial length h of the twist in 3D, >= 0. h = 0 is allowed but folds a band lying in one
        cross-section plane (note B13). If the pattern height sqrt(h^2 + e^2) is below
        eps = 1e-4 b the twist is only a relabelling: the result has no creases, height 0 and a
        distal marker shifted by the nearest whole number of columns.
    """
    prism = make_prism(numSides, r)
    alpha = check_real("twistAngle", twistAngle)
    h = check_nonnegative("moduleHeight", moduleHeight)
    geo = twist_geometry(prism, alpha, h)
    record = ModuleRecord("twist", {"twistAngle": alpha, "moduleHeight": h})
    n, b = prism.numSides, prism.b
    k = np.arange(n)
    x = prism.columns
    if geo.degenerate:
        columns = round(n * ((alpha % (2.0 * math.pi)) / (2.0 * math.pi))) % n
        vertices = np.stack([x, np.zeros(n)], axis=1)
        return assemble(
            prism, vertices, [(np.zeros((0, 2), int), "M")], k, k, 0.0, record,
            distal_marker_x=float(wrap_x(np.array([columns * b]), prism.W, prism.eps)[0]),
        )  # fmt: skip
    H = geo.height
    distal_x = wrap_x(x + geo.shift, prism.W, prism.eps)
    vertices = np.concatenate(
        [np.stack([x, np.zeros(n)], axis=1), np.stack([distal_x, np.full(n, H)], axis=1)]
    )
    P, D = k, n + k
    prev = (k - 1) % n
    blocks = [
        crease_block(P, D, "M"),  # right diagonals
        crease_block(D[prev], P, "M"),  # left diagonals
        crease_block(P[prev], P, "V"),  # proximal ring
        crease_block(D[prev], D, "V"),  # distal ring
    ]
    marker_x = float(wrap_x(np.array([geo.K * b + geo.shift]), prism.W, prism.eps)[0])
    return assemble(prism, vertices, blocks, P, D, H, record, distal_marker_x=marker_x)
