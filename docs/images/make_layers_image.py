"""Make docs/images/layers.png: the package's layers as .importlinter states them, top to
bottom, each box with its modules and lines of code, and the lazy one-line delegates (the only
imports that point up) as dashed arrows.

Run from the repository root::

    python docs/images/make_layers_image.py
"""

from __future__ import annotations

import configparser
from pathlib import Path

import matplotlib

matplotlib.use("Agg")

import matplotlib.pyplot as plt  # noqa: E402
from matplotlib.patches import FancyArrowPatch, FancyBboxPatch  # noqa: E402

ROOT = Path(__file__).resolve().parents[2]
PACKAGE = ROOT / "kinegami"


def layers() -> tuple[list[list[str]], list[tuple[str, str]]]:
    """The layer contract of .importlinter: layers top to bottom (each a list of modules) and
    the ignored imports (the lazy delegates), as (importer, imported)."""
    config = configparser.ConfigParser()
    config.read(ROOT / ".importlinter")
    contract = config["importlinter:contract:layers"]
    rows = [[m.strip() for m in line.split("|")] for line in contract["layers"].split("\n")
            if line.strip()]  # fmt: skip
    ignored = [tuple(p.strip() for p in line.split("->"))
               for line in contract["ignore_imports"].split("\n") if line.strip()]  # fmt: skip
    return rows, ignored


def size(module: str) -> tuple[int, int]:
    """Python files and lines of a module or package."""
    path = PACKAGE.joinpath(*module.split(".")[1:])
    files = sorted(path.rglob("*.py")) if path.is_dir() else [path.with_suffix(".py")]
    files = [f for f in files if f.exists()]
    return len(files), sum(len(f.read_text(encoding="utf-8").splitlines()) for f in files)


def main() -> Path:
    rows, ignored = layers()
    fig, ax = plt.subplots(figsize=(9, 0.62 * len(rows) + 0.8))
    height, gap = 0.46, 0.16
    y_of: dict[str, float] = {}
    for k, row in enumerate(rows):
        y = -(height + gap) * k
        width = 6.0 / len(row)
        for m, module in enumerate(row):
            x = 0.3 + m * width
            files, lines = size(module)
            name = module.removeprefix("kinegami.")
            folder = (PACKAGE / name.replace(".", "/")).is_dir()
            label = f"{name}/" if folder else f"{name}.py"
            ax.add_patch(FancyBboxPatch((x, y), width - 0.12, height, boxstyle="round,pad=0.02",
                                        facecolor="#dbe8f6" if folder else "#eeeeee",
                                        edgecolor="#44546a"))  # fmt: skip
            ax.text(x + 0.12, y + height / 2, label, va="center", fontsize=10, weight="bold")
            ax.text(x + width - 0.24, y + height / 2, f"{files} files, {lines:,} lines"
                    if files > 1 else f"{lines:,} lines", va="center", ha="right",
                    fontsize=8, color="#44546a")  # fmt: skip
            y_of[module] = y + height / 2
    pairs: list[tuple[str, str]] = []
    for importer, imported in ignored:
        start = next((m for m in y_of if importer == m or importer.startswith(m + ".")), None)
        end = next((m for m in y_of if imported == m or imported.startswith(m + ".")), None)
        if start is not None and end is not None and (start, end) not in pairs:
            pairs.append((start, end))
    for n, (start, end) in enumerate(pairs):
        x = 6.55 + 0.32 * n
        ax.add_patch(FancyArrowPatch((x, y_of[start]), (x, y_of[end]), arrowstyle="-|>",
                                     mutation_scale=10, linestyle="--", color="#c0504d"))
        ax.plot([6.3, x], [y_of[start]] * 2, ":", color="#c0504d", linewidth=0.8)
    ax.text(6.3, 0.72, "dashed: the lazy one-line delegates\n(show, save, clearance)",
            fontsize=8, color="#c0504d")  # fmt: skip
    ax.text(0.3, 0.72, "each layer imports only the layers below it", fontsize=9)
    ax.set_xlim(0.1, 8.2)
    ax.set_ylim(-(height + gap) * len(rows) + gap - 0.1, 1.15)
    ax.axis("off")
    out = ROOT / "docs" / "images" / "layers.png"
    fig.savefig(out, dpi=110, bbox_inches="tight")
    plt.close(fig)
    return out


if __name__ == "__main__":
    print(main())
