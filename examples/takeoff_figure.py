"""Draw the folded take-off junction's two sheet pieces (docs/theory/takeoff.md).

``python examples/takeoff_figure.py [file]`` writes ``docs/images/takeoff.png`` (or ``file``): for
n = 8 and n = 10 (r = 1), the branch sheet's skirt (fish-mouth, tab hinges, tab outlines, tube
edges up to y' = a) and the trunk sheet around the hole (hole, interrupted tube edges, where the
folded tabs land).
"""

from __future__ import annotations

import io
import sys
from pathlib import Path

import matplotlib

matplotlib.use("Agg")
import matplotlib.pyplot as plt  # noqa: E402
import numpy as np  # noqa: E402

from kinegami._atomic import write_atomic  # noqa: E402
from kinegami.pattern.takeoff import takeoff_junction  # noqa: E402

ROOT = Path(__file__).resolve().parent.parent
MOUNTAIN, VALLEY, CUT, GLUE = "tab:blue", "tab:red", "black", "0.85"


def draw_branch(ax, j) -> None:
    W, a = j.prism.W, j.prism.a
    for tab in j.tabs:
        ax.fill(*tab.polygon.T, color=GLUE, zorder=0)
    for (p, q), flush in zip(j.segments("fish_mouth"), j.flush, strict=True):
        ax.plot(*np.stack([p, q]).T, color=CUT if flush else VALLEY, lw=1.2)
    for seg in j.skirt_outline():
        ax.plot(*seg.T, color=CUT, lw=0.8)
    fm = j.fish_mouth
    for xk in j.prism.columns:
        y = fm[np.argmin(np.abs(fm[:, 0] - xk)), 1]
        ax.plot([xk, xk], [y, a + 0.3], color=MOUNTAIN, lw=1.0)
    ax.axhline(a, color="0.6", ls=":", lw=0.8)
    ax.set_xlim(-0.1, W + 0.6)
    ax.set_title(f"branch sheet, n = {j.numSides}: skirt (y' from O)")


def draw_trunk(ax, j) -> None:
    b = j.prism.b
    for tab in j.tabs:
        ax.fill(*tab.footprint.T, color=GLUE, zorder=0)
    hole = np.vstack([j.hole_unwrapped, j.hole_unwrapped[:1]])
    ax.plot(*hole.T, color=CUT, lw=1.2)
    gaps = {int(k): (lo, hi) for k, lo, hi in j.column_gaps()}
    y_lo, y_hi = j.trunk_span
    for k, xk in enumerate(j.prism.columns):
        xk += j.prism.W * round((j.face_centre - xk) / j.prism.W)
        if abs(xk - j.face_centre) > j.axial_half_extent + 2 * b:
            continue
        if k in gaps:
            lo, hi = gaps[k]
            ax.plot([xk, xk], [y_lo, lo], color=MOUNTAIN, lw=1.0)
            ax.plot([xk, xk], [hi, y_hi], color=MOUNTAIN, lw=1.0)
        else:
            ax.plot([xk, xk], [y_lo, y_hi], color=MOUNTAIN, lw=1.0)
    ax.set_title(f"trunk sheet, n = {j.numSides}: hole in face {j.face}")


def main(path: Path) -> None:
    fig, axes = plt.subplots(2, 2, figsize=(11, 5.6))
    for col, n in enumerate((8, 10)):
        j = takeoff_junction(n, 1.0, 1)
        draw_branch(axes[0, col], j)
        draw_trunk(axes[1, col], j)
    for ax in axes.flat:
        ax.set_aspect("equal")
        ax.tick_params(labelsize=7)
    fig.tight_layout()
    data = io.BytesIO()
    fig.savefig(data, format="png", dpi=90)
    plt.close(fig)
    write_atomic(path, data.getvalue())
    print(path)


if __name__ == "__main__":
    main(Path(sys.argv[1]) if len(sys.argv) > 1 else ROOT / "docs" / "images" / "takeoff.png")
