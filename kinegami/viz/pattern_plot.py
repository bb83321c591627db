"""2D matplotlib view of a crease pattern's flat sheet: ``TubularPattern.show``.

Draws what :func:`kinegami.pattern.sheet.flatten` computes, as in Figure 5(g) of the paper:
valley folds red, mountain folds blue, the boundary of the nominal tube (x in [0, W]), the two
copies of the starting panel (the glue tab, lightly shaded) and the cut outline of the sheet
(x in [-b/2, W + b/2]). Each kind of line is one ``LineCollection`` with a ``gid`` (see
:data:`PATTERN_ARTIST_GIDS`). matplotlib is imported only when a pattern is drawn.
"""

from __future__ import annotations

from types import MappingProxyType
from typing import TYPE_CHECKING, Any

from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.validation import (
    check_bool,
    check_in_range,
    check_positive,
    resolve_options,
)
from kinegami.viz._backend import show_if_interactive
from kinegami.viz.scale import check_units, length_text, nice_length, unit_text

if TYPE_CHECKING:  # pragma: no cover
    from matplotlib.axes import Axes
    from matplotlib.figure import Figure

    from kinegami.pattern.tubular import TubularPattern

__all__ = ["show_pattern", "PATTERN_PLOT_DEFAULTS", "PATTERN_ARTIST_GIDS"]

#: Every option of ``show_pattern`` (and ``TubularPattern.show``) with its default.
PATTERN_PLOT_DEFAULTS = MappingProxyType(
    {
        "valleyColor": "red",
        "mountainColor": "blue",
        "boundaryColor": "black",
        "cutColor": "green",
        "glueTabColor": "lightgray",
        "glueTabOpacity": 0.5,
        "showGlueTab": True,
        "showBoundary": True,
        "showCut": True,
        "showCreasesOnCut": True,
        "linewidth": 1.0,
        "title": None,
        "units": None,
        "showScaleBar": True,
        "ax": None,
        "block": None,
    }
)

#: The ``gid`` of each artist drawn.
PATTERN_ARTIST_GIDS = {
    "mountain": "mountain folds (LineCollection)",
    "valley": "valley folds (LineCollection)",
    "boundary": "the nominal tube x in [0, W] (LineCollection)",
    "cut": "the sheet outline x in [-b/2, W + b/2] (LineCollection)",
    "glue-tab": "the two copies of the starting panel (Rectangle patches)",
    "scale-bar": "a bar of a round length under the sheet's right end (Line2D, showScaleBar)",
    "scale-bar-label": "its length and unit, under it (Annotation)",
}

_COLOR_OPTIONS = ("valleyColor", "mountainColor", "boundaryColor", "cutColor", "glueTabColor")
_BOOL_OPTIONS = ("showGlueTab", "showBoundary", "showCut", "showCreasesOnCut", "showScaleBar")


def _resolve_options(options: dict[str, Any]) -> dict[str, Any]:
    opts = resolve_options(options, PATTERN_PLOT_DEFAULTS, "show()")
    from matplotlib.colors import is_color_like

    for name in _COLOR_OPTIONS:
        if not is_color_like(opts[name]):
            raise InvalidParameterError(f"{name} must be a matplotlib colour, got {opts[name]!r}")
    for name in _BOOL_OPTIONS:
        opts[name] = check_bool(name, opts[name])
    check_positive("linewidth", opts["linewidth"])
    check_in_range("glueTabOpacity", opts["glueTabOpacity"], 0.0, 1.0, True, True)
    opts["block"] = check_bool("block", opts["block"], none=True)
    opts["units"] = check_units(opts["units"])
    if opts["title"] is not None and not isinstance(opts["title"], str):
        raise InvalidTypeError(f"title must be None or a string, got {opts['title']!r}")
    ax = opts["ax"]
    if ax is not None:
        from matplotlib.axes import Axes

        if not isinstance(ax, Axes) or getattr(ax, "name", None) == "3d":
            raise InvalidTypeError(f"ax must be a 2D matplotlib Axes, got {type(ax).__name__}")
    return opts


def show_pattern(pattern: TubularPattern, **options: Any) -> tuple[Figure, Axes]:
    """Plot the flat sheet of a crease pattern with matplotlib (paper Figure 5(g)).

    Parameters
    ----------
    pattern : TubularPattern
        The pattern (a module or a whole chain); coordinates are drawn in pattern units.
    valleyColor, mountainColor : colour, optional
        Fold colours; default red valleys and blue mountains, as in the paper.
    boundaryColor, cutColor : colour, optional
        The nominal tube outline x in [0, W] (default black) and the sheet outline
        x in [-b/2, W + b/2] (default green).
    glueTabColor : colour, optional
        Fill of the two copies of the starting panel (default light gray).
    glueTabOpacity : float, optional
        Alpha of that fill, in [0, 1] (default 0.5).
    showGlueTab, showBoundary, showCut : bool, optional
        Draw the glue tab shading, the boundary and the cut outline (default True).
    showCreasesOnCut : bool, optional
        Draw creases lying on the top or bottom edge of the sheet (B10 of
        docs/theory/patterns.md §6; default True).
    linewidth : float, optional
        Line width in points (default 1).
    title : str, optional
        Axes title.
    units : {'mm', 'cm', 'm', 'in'}, optional
        The unit of the pattern's lengths (a design file's ``units``), named in the axis labels
        and on the scale bar; None (default) says ``units of r``.
    showScaleBar : bool, optional
        Draw a bar of a round length (1, 2 or 5 times a power of ten, at most 0.4 of the
        sheet's width) under the sheet's right end, its length written under it (default
        True).
    ax : matplotlib.axes.Axes, optional
        Draw into this 2D axes instead of a new figure.
    block : bool, optional
        Passed to ``plt.show``.

    Returns
    -------
    (fig, ax) : the matplotlib Figure and Axes drawn into. ``plt.show`` is called only when this
        function created the figure and the backend is interactive.

    Raises
    ------
    InvalidTypeError
        For an unknown option (the message names it) or a value of the wrong type.
    InvalidParameterError
        For a value out of range or an invalid colour.

    Examples
    --------
    >>> from kinegami.pattern import RevoluteJointPattern
    >>> fig, ax = show_pattern(RevoluteJointPattern(6, 1.0, np.pi))  # doctest: +SKIP
    >>> fig.savefig("revolute.png")  # doctest: +SKIP
    """
    from kinegami.pattern.cutout import CutPattern
    from kinegami.pattern.sheet import flatten
    from kinegami.pattern.tubular import TubularPattern

    if not isinstance(pattern, TubularPattern | CutPattern):
        raise InvalidTypeError(f"pattern must be a TubularPattern, got {type(pattern).__name__}")
    opts = _resolve_options(options)
    import matplotlib.pyplot as plt
    from matplotlib.collections import LineCollection
    from matplotlib.patches import Rectangle

    sheet = flatten(pattern, skip_creases_on_cut=not opts["showCreasesOnCut"])
    created = opts["ax"] is None
    if created:
        xmin, ymin, xmax, ymax = sheet.bounds
        aspect = (ymax - ymin) / max(xmax - xmin, 1e-12)
        height = min(max(2.5, 6.0 * aspect + 1.0), 12.0)
        fig, ax = plt.subplots(figsize=(6.0 if aspect > 1.5 else 9.0, height))
    else:
        ax = opts["ax"]
        fig = ax.figure

    lw = opts["linewidth"]
    if opts["showGlueTab"]:
        for i, (x0, x1) in enumerate(sheet.glueTabs):
            ax.add_patch(
                Rectangle(
                    (x0, sheet.y0),
                    x1 - x0,
                    sheet.height,
                    facecolor=opts["glueTabColor"],
                    edgecolor="none",
                    alpha=opts["glueTabOpacity"],
                    gid="glue-tab",
                    label="glue tab" if i == 0 else None,
                    zorder=0,
                )
            )
    layers = [
        ("C", "cut", opts["cutColor"], opts["showCut"], "cut", "-", 1),
        ("B", "boundary", opts["boundaryColor"], opts["showBoundary"], "boundary", "--", 1),
        ("M", "mountain", opts["mountainColor"], True, "mountain fold", "-", 2),
        ("V", "valley", opts["valleyColor"], True, "valley fold", "-", 2),
    ]
    for kind, gid, color, visible, label, style, zorder in layers:
        if not visible:
            continue
        lines = LineCollection(
            sheet.select(kind),
            colors=color,
            linewidths=lw,
            linestyles=style,
            gid=gid,
            label=label,
            zorder=zorder,
        )
        ax.add_collection(lines)
    xmin, ymin, xmax, ymax = sheet.bounds
    pad = 0.05 * (xmax - xmin)  # a margin of a few percent of the sheet's width
    bottom = ymin - pad
    if opts["showScaleBar"]:
        bottom = _draw_scale_bar(ax, sheet.bounds, pad, opts["units"])
    ax.set_xlim(xmin - pad, xmax + pad)
    ax.set_ylim(bottom, ymax + pad)
    ax.set_aspect("equal")
    unit = unit_text(opts["units"])
    ax.set_xlabel(f"x around the tube ({unit})")
    ax.set_ylabel(f"y along the tube ({unit})")
    if opts["title"] is not None:
        ax.set_title(opts["title"])
    show_if_interactive(created, opts["block"])
    return fig, ax


def _draw_scale_bar(ax, bounds, pad: float, units: str | None) -> float:
    """A bar of a round length, its right end under the sheet's right edge, in a strip added
    below the sheet, with its length written under it (right-aligned with it: the text may be
    longer than the bar); returns the new lower y limit."""
    xmin, ymin, xmax, ymax = bounds
    length = nice_length(0.4 * (xmax - xmin))
    strip = 0.06 * max(xmax - xmin, ymax - ymin)  # room for the bar and a line of text
    y = ymin - pad - 0.2 * strip
    ax.plot([xmax - length, xmax], [y, y], color="black", linewidth=2.0, solid_capstyle="butt",
            gid="scale-bar")  # fmt: skip
    ax.annotate(length_text(length, units), (xmax, y), xytext=(0.0, -3.0),
                textcoords="offset points", ha="right", va="top", fontsize=9,
                gid="scale-bar-label")  # fmt: skip
    return ymin - pad - strip
