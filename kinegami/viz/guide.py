"""The folding guide: a PDF that takes a maker from the cut sheet to the folded robot
(docs/fabrication.md, "Folding guide"; ``kinegami build --formats guide`` writes
``<stem>_guide.pdf``).

Pages (A4 landscape), in order:

1. a cover: the robot in 3D and the bill of materials
   (:class:`~kinegami.fabrication.bom.BillOfMaterials`);
2. one step per module of every sheet, in folding order (along the sheet from its start): where
   it is on the sheet (highlighted on a thumbnail of the whole sheet, the pieces' cuts dashed),
   its crease pattern enlarged with the mountain/valley legend, the module folded in 3D, and
   one line on how that kind folds. A step is named by the joint or the link the module belongs
   to, with the joint numbers of the design file and the editor (waypoints included);
3. joining the tube along its glue tab;
4. joining the pieces (when a laser bed cut a sheet into pieces);
5. for a tree, which sheet goes to which junction.

Drawing stays bounded: every sheet's thumbnail and the cover's 3D view are drawn once, as
raster images, and each step draws one module only.
"""

from __future__ import annotations

import io
import textwrap
from collections.abc import Sequence
from dataclasses import dataclass
from typing import Any

import numpy as np

from kinegami.errors import KinegamiError
from kinegami.fabrication.bom import BillOfMaterials
from kinegami.pattern.catalog import module_kind
from kinegami.pattern.sheet import flatten

__all__ = [
    "FOLDING_HINTS",
    "GuideSheet",
    "GuideStep",
    "chain_guide_data",
    "folding_steps",
    "tree_guide_data",
]

#: One line on how each module kind folds (docs/fold.md).
FOLDING_HINTS = {
    "start_tip": "Tip: fold the triangular flaps inward, mountains first, until they close the "
    "tube's end to a point.",
    "end_tip": "Tip: fold the triangular flaps inward, mountains first, until they close the "
    "tube's end to a point.",
    "tube": "Tube: fold only the long creases, one per side of the prism; nothing else folds.",
    "elbow": "Elbow: fold the slanted ring of mountains and valleys together so that the tube "
    "turns by the elbow's angle.",
    "twist": "Twist: fold the diagonal creases while turning one end of the tube against the "
    "other about its axis.",
    "revolute": "Revolute joint: sink the layered flaps inward along the hinge line and press "
    "them flat; the two halves then turn about the hinge.",
    "prismatic": "Prismatic REBO joint: collapse the bellows layer by layer like an accordion, "
    "mountains and valleys alternating; it slides along the tube.",
    "rebo": "REBO bellows: collapse the layers one by one like an accordion, mountains and "
    "valleys alternating.",
    "waypoint": "Waypoint: nothing to fold; the tube starts here.",
    "takeoff_skirt": "Take-off skirt: fold the glue tabs inward and glue them inside the hole "
    "of the trunk's sheet.",
}
_KIND_WORDS = {"start_tip": "start tip", "end_tip": "end tip", "rebo": "bellows",
               "takeoff_skirt": "take-off skirt"}  # fmt: skip
_PAGE = (11.69, 8.27)  # A4 landscape, inches
_MOUNTAIN, _VALLEY = "#1f4fd1", "#d62020"  # blue mountains, red valleys (the paper's)


@dataclass(frozen=True)
class GuideStep:
    """One folding step: module ``module`` of sheet ``sheet`` (indices from 0), its ``kind``
    and its ``title`` (e.g. "joint 4 (RevoluteJoint 'revolute')")."""

    sheet: int
    module: int
    kind: str
    title: str


@dataclass(frozen=True)
class GuideSheet:
    """A sheet to fold: its ``name`` ("sheet 1", or "" for a chain's only sheet), its
    ``pattern`` (TubularPattern or CutPattern), the ``joints`` it carries (root end first) and
    its ``layout`` on a laser bed (a BedLayout, or None)."""

    name: str
    pattern: Any
    joints: tuple[int, ...]
    layout: Any = None


def _joint_title(assembly, j: int, names) -> str:
    name = names[j] if names is not None and j < len(names) else None
    kind = type(assembly.Joints[j]).__name__
    return f"joint {j} ({kind}" + (f" '{name}'" if name else "") + ")"


def _owners(assembly, joints: Sequence[int], pattern, twistPortion: float) -> list | None:
    """The joint or link ("joint"/"link", index) every module of ``pattern`` belongs to, or
    None when they cannot be told apart (the composition keeps an empty module only first)."""
    n = assembly.numSides
    first = joints[0]
    parts = [(("joint", first), assembly.Joints[first].pattern)]
    for t in joints[1:]:
        parts += [(("link", t), p) for p in assembly.Links[t].pattern_modules(n, twistPortion)]
        parts.append((("joint", t), assembly.Joints[t].pattern))
    owners: list = []
    records: list = []
    for i, (owner, part) in enumerate(parts):
        if (first == 0 and i == 0) or not part.isEmpty:
            owners += [owner] * len(part.modules)
            records += list(part.modules)
    modules = list(pattern.modules)
    prefix = len(modules) - len(owners)  # a tree sheet's start: the rest of its first link
    if prefix < 0 or modules[prefix:] != records:
        return None
    return [("link", first)] * prefix + owners


def folding_steps(assembly, sheets: Sequence[GuideSheet], names=None,
                  twistPortion: float = 0.2) -> list[GuideStep]:  # fmt: skip
    """Every module of every sheet in folding order, named by its joint or link (joint numbers
    as in the design file; ``names``: the joints' names)."""
    steps = []
    for s, sheet in enumerate(sheets):
        pattern = getattr(sheet.pattern, "pattern", sheet.pattern)
        owners = _owners(assembly, sheet.joints, pattern, twistPortion)
        kinds = [record.kind for record in pattern.modules]
        prefix = f"{sheet.name}, " if sheet.name else ""
        for m, kind in enumerate(kinds):
            word = _KIND_WORDS.get(kind, kind)
            if owners is None:
                steps.append(GuideStep(s, m, kind, f"{prefix}module {m + 1}: {word}"))
                continue
            owner = owners[m]
            same = [k for k, o in enumerate(owners) if o == owner]
            part = f", module {same.index(m) + 1} of {len(same)}: {word}" if len(same) > 1 else ""
            if owner[0] == "joint":
                title = _joint_title(assembly, owner[1], names) + part
            else:
                t = owner[1]
                parent = assembly.Parents[t] if hasattr(assembly, "Parents") else t - 1
                title = (f"link {t} (joint {parent} to joint {t})"
                         + (part or f", {word}"))  # fmt: skip
            steps.append(GuideStep(s, m, kind, prefix + title))
    return steps


# --- drawing ------------------------------------------------------------------------------------


def _raster(fig, dpi: float) -> np.ndarray:
    """The figure drawn to an RGBA array (then closed)."""
    import matplotlib.pyplot as plt

    try:
        fig.set_dpi(dpi)
        fig.canvas.draw()
        return np.asarray(fig.canvas.buffer_rgba())[:, :, :3].copy()
    finally:
        plt.close(fig)


def _thumbnail(pattern) -> tuple[np.ndarray, tuple[float, float, float, float]]:
    """The flat sheet drawn lying down (y along the page), as an image, and its extent
    (ymin, ymax, xmin, xmax) in pattern units."""
    from matplotlib.collections import LineCollection
    from matplotlib.figure import Figure

    sheet = flatten(pattern)
    xmin, ymin, xmax, ymax = sheet.bounds
    fig = Figure(figsize=(10.0, 1.0))
    ax = fig.add_axes((0, 0, 1, 1))
    for kind, color, width in (("C", "black", 0.6), ("M", _MOUNTAIN, 0.3),
                               ("V", _VALLEY, 0.3)):  # fmt: skip
        segments = sheet.select(kind)[:, :, ::-1]  # (y, x): the strip lies down
        ax.add_collection(LineCollection(segments, colors=color, linewidths=width,
                                         antialiaseds=False))  # compresses well
    ax.set_xlim(ymin, ymax)
    ax.set_ylim(xmin, xmax)
    ax.set_axis_off()
    from matplotlib.backends.backend_agg import FigureCanvasAgg

    FigureCanvasAgg(fig)
    fig.set_dpi(80)  # 800 x 80 pixels: every step's page embeds it
    fig.canvas.draw()
    image = np.asarray(fig.canvas.buffer_rgba())[:, :, :3].copy()  # RGB: smaller pages
    return image, (ymin, ymax, xmin, xmax)


def _module_extents(pattern) -> list[tuple[float, float]]:
    """Where every module runs along the sheet: (y0, y1) of its vertices."""
    ys = pattern.vertices_coords[:, 1]
    placed = pattern.module_vertices
    if placed is None:
        return [(float(ys.min()), float(ys.max()))] * len(pattern.modules)
    return [(float(ys[v].min()), float(ys[v].max())) if len(v) else (0.0, 0.0) for v in placed]


#: Lines of text on a text page (10 pt, 1.5 spacing, under the title).
_TEXT_LINES = 32


def _text_page(pdf, title: str, paragraphs: Sequence[str]) -> None:
    """Pages of text (wrapped), as many as it needs: the title, then "(continued)"."""
    from matplotlib.figure import Figure

    lines: list[str] = []
    for paragraph in paragraphs:
        lines += textwrap.wrap(paragraph, 120, subsequent_indent="    ") or [""]
    for first in range(0, max(len(lines), 1), _TEXT_LINES):
        fig = Figure(figsize=_PAGE)
        heading = title if first == 0 else f"{title} (continued)"
        fig.text(0.05, 0.94, heading, fontsize=18, weight="bold", va="top")
        fig.text(0.05, 0.87, "\n".join(lines[first:first + _TEXT_LINES]), fontsize=10,
                 va="top", linespacing=1.5)  # fmt: skip
        pdf.savefig(fig)


def _draw_step(pdf, step: GuideStep, number: int, total: int, sheet: GuideSheet, thumb,
               extents, form, units: str | None, unit: float) -> None:  # fmt: skip
    from matplotlib.figure import Figure
    from mpl_toolkits.mplot3d.art3d import Line3DCollection

    from kinegami.viz.pattern_plot import show_pattern

    pattern = getattr(sheet.pattern, "pattern", sheet.pattern)
    fig = Figure(figsize=_PAGE)
    fig.text(0.04, 0.955, f"Step {number} of {total}: {step.title}", fontsize=15,
             weight="bold", va="top")  # fmt: skip
    y0, y1 = extents[step.module]
    start = float(pattern.proximalMarker[1])
    where = (f"{(y0 - start) * unit:,.0f} to {(y1 - start) * unit:,.0f} mm along "
             f"{sheet.name or 'the sheet'}")  # fmt: skip
    if sheet.layout is not None and len(sheet.layout.pieces) > 1:
        middle = 0.5 * (y0 + y1)
        for k, piece in enumerate(sheet.layout.pieces):
            if piece.start <= middle <= piece.end or k == len(sheet.layout.pieces) - 1:
                bed = sheet.layout.placements[k].bin + 1
                where += f", on piece {piece.index} of {piece.count} (bed sheet {bed})"
                break
    hint = FOLDING_HINTS.get(step.kind, f"{step.kind}: fold its mountains and valleys.")
    fig.text(0.04, 0.905, where, fontsize=10, va="top")
    fig.text(0.04, 0.875, hint, fontsize=10, va="top", style="italic")
    # where it is on the sheet
    image, extent = thumb
    ax = fig.add_axes((0.04, 0.68, 0.92, 0.13))
    ax.imshow(image, extent=extent, aspect="auto", interpolation="none")
    ax.axvspan(y0, max(y1, y0 + 1e-3 * (extent[1] - extent[0])), color="orange", alpha=0.45)
    if sheet.layout is not None:
        for piece in sheet.layout.pieces[1:]:
            ax.axvline(piece.start, color="black", linestyle="--", linewidth=0.8)
    ax.set_yticks([])
    ax.set_xticks([])
    ax.set_title("where it is on the sheet (start at the left)", fontsize=9, loc="left")
    # its crease pattern, enlarged
    ax = fig.add_axes((0.05, 0.06, 0.42, 0.58))
    record = pattern.modules[step.module]
    local = module_kind(record.kind).rebuild(pattern.numSides, pattern.r, record.params)
    show_pattern(local, ax=ax, showGlueTab=False, units=units, mountainColor=_MOUNTAIN,
                 valleyColor=_VALLEY, linewidth=0.8)  # fmt: skip
    ax.legend(loc="upper right", fontsize=7, framealpha=0.9)
    ax.set_title("its crease pattern", fontsize=9, loc="left")
    # folded, in 3D
    ax = fig.add_axes((0.52, 0.06, 0.44, 0.58), projection="3d")
    ax.set_title("folded", fontsize=9, loc="left")
    if form is None:
        ax.text2D(0.1, 0.5, "(no folded form for this sheet)", transform=ax.transAxes)
    else:
        vertices = np.asarray(form.modules[step.module].vertices)
        edges = pattern.edges_vertices
        inside = np.isin(edges, vertices).all(axis=1)
        assignment = pattern.edges_assignment
        points = form.vertices
        for mask, color, width in ((inside & (assignment == "M"), _MOUNTAIN, 0.8),
                                   (inside & (assignment == "V"), _VALLEY, 0.8),
                                   (inside & ~np.isin(assignment, ["M", "V"]), "black", 1.0)):
            if mask.any():  # fmt: skip
                ax.add_collection3d(Line3DCollection(points[edges[mask]], colors=color,
                                                     linewidths=width))  # fmt: skip
        shown = points[vertices] if len(vertices) else points
        low, high = shown.min(axis=0), shown.max(axis=0)
        centre, half = 0.5 * (low + high), 0.5 * float((high - low).max() or 1.0)
        ax.set_xlim(centre[0] - half, centre[0] + half)
        ax.set_ylim(centre[1] - half, centre[1] + half)
        ax.set_zlim(centre[2] - half, centre[2] + half)
        ax.set_box_aspect((1, 1, 1))
        ax.set_axis_off()
    pdf.savefig(fig)


def _cover(pdf, title: str, picture: np.ndarray | None, bom: BillOfMaterials, steps: int,
           extra: Sequence[str] = ()) -> None:  # fmt: skip
    from matplotlib.figure import Figure

    fig = Figure(figsize=_PAGE)
    fig.text(0.05, 0.93, title, fontsize=22, weight="bold", va="top")
    fig.text(0.05, 0.86, f"Folding guide: {steps} steps, one per module, in folding order",
             fontsize=12, va="top")  # fmt: skip
    lines = ["Bill of materials", *(f"  {line}" for line in bom.lines()), "", *extra]
    wrapped: list[str] = []
    for line in lines:
        wrapped += textwrap.wrap(line, 60, subsequent_indent="      ") or [""]
    fig.text(0.05, 0.78, "\n".join(wrapped[:36]), fontsize=10, va="top", linespacing=1.5,
             family="monospace")  # fmt: skip
    if picture is not None:
        ax = fig.add_axes((0.52, 0.06, 0.45, 0.78))
        ax.imshow(picture, interpolation="none")
        ax.set_axis_off()
    pdf.savefig(fig)


def _picture(draw) -> np.ndarray | None:
    """The figure ``draw()`` returns (fig, ax), as an image; None when it cannot be drawn."""
    try:
        fig, _ = draw()
    except KinegamiError:
        return None
    image = _raster(fig, 100)
    rows, cols = np.nonzero((image < 245).any(axis=2))  # crop the white around the drawing
    if rows.size:
        image = image[max(rows.min() - 5, 0):rows.max() + 6, max(cols.min() - 5, 0):cols.max() + 6]
    return image


def _folded(pattern):
    from kinegami.pattern.folded import folded_form

    try:
        return folded_form(pattern)
    except KinegamiError:
        return None


def _guide(assembly, sheets: list[GuideSheet], *, bom: BillOfMaterials, title: str,
           picture, units: str | None, unit: float, names, twistPortion: float,
           closing: Sequence[tuple[str, list[str]]]) -> bytes:  # fmt: skip
    from matplotlib.backends.backend_pdf import PdfPages

    steps = folding_steps(assembly, sheets, names, twistPortion)
    stream = io.BytesIO()
    metadata = {"Title": f"{title}: folding guide", "Creator": "kinegami", "CreationDate": None}
    with PdfPages(stream, metadata=metadata) as pdf:
        _cover(pdf, title, picture, bom, len(steps))
        for s, sheet in enumerate(sheets):
            pattern = getattr(sheet.pattern, "pattern", sheet.pattern)
            thumb = _thumbnail(sheet.pattern)
            extents = _module_extents(pattern)
            form = _folded(pattern)
            for step in steps:
                if step.sheet == s:
                    number = steps.index(step) + 1
                    _draw_step(pdf, step, number, len(steps), sheet, thumb, extents, form,
                               units, unit)  # fmt: skip
        _text_page(pdf, "Join the tube along its glue tab", [
            "Every sheet rolls into a tube: bring its two long edges together so that the two "
            "copies of the first panel (shaded in the crease pattern, the glue tab) lie face to "
            "face, and glue them along the whole sheet "
            f"({bom.glue_tab:,.0f} mm of glue tab in all). Fold the long creases first, then "
            "glue, pressing a short stretch at a time; tape holds the seam while the glue sets.",
            "Then fold the steps in order from the start of the sheet (the left of the "
            "thumbnails).",
        ])  # fmt: skip
        for heading, paragraphs in closing:
            _text_page(pdf, heading, paragraphs)
    return stream.getvalue()


def _pieces_page(sheets: Sequence[GuideSheet], unit: float) -> list[tuple[str, list[str]]]:
    """The page on joining pieces, when a laser bed cut a sheet into pieces."""
    paragraphs = []
    for sheet in sheets:
        layout = sheet.layout
        if layout is None or len(layout.pieces) < 2:
            continue
        start = layout.pieces[0].start
        name = sheet.name.capitalize() or "The sheet"
        for piece in layout.pieces[:-1]:
            paragraphs.append(
                f"{name}: glue the {piece.tab * unit:g} mm tab of piece {piece.index} of "
                f"{piece.count} (bed sheet {layout.placements[piece.index - 1].bin + 1}) inside "
                f"piece {piece.index + 1}, its edge on the join line at "
                f"{(piece.end - start) * unit:,.0f} mm along the strip, the alignment ticks "
                "continuing each other; tape around the join."
            )
    if not paragraphs:
        return []
    return [("Join the pieces", [
        "A laser bed cut the sheet into pieces (their cuts are dashed on the thumbnails). Join "
        "them before rolling the tube, each tab inside the next piece:", *paragraphs])]


def chain_guide_data(chain, *, bom: BillOfMaterials, pattern=None, layout=None,
                     title: str = "kinegami robot", units: str | None = None,
                     names: Sequence[str | None] | None = None,
                     twistPortion: float = 0.2) -> bytes:  # fmt: skip
    """The folding guide of a chain, as PDF bytes.

    Parameters
    ----------
    chain : KinematicChain
    bom : BillOfMaterials
        Its bill of materials (:func:`kinegami.fabrication.bom.bill_of_materials`).
    pattern : TubularPattern, optional
        Its crease pattern (default ``chain.creasePattern(twistPortion)``).
    layout : BedLayout, optional
        The pattern laid out on a laser bed.
    title : str
        The design's name, on the cover.
    units : str, optional
        The design's length unit (``'mm'``, ``'cm'``, ...); None: units of r (and 1 mm each).
    names : sequence of str or None, optional
        The joints' names (the design file's).

    Examples
    --------
    >>> from kinegami.design import load_design_with_info
    >>> from kinegami.fabrication.bom import bill_of_materials
    >>> chain, info = load_design_with_info("examples/designs/example1.json")  # doctest: +SKIP
    >>> pattern = chain.creasePattern()  # doctest: +SKIP
    >>> bom = bill_of_materials([pattern], 10.0)  # cm: 10 mm per unit  # doctest: +SKIP
    >>> data = chain_guide_data(chain, bom=bom, pattern=pattern, title=info.name,
    ...                         units=info.units)  # doctest: +SKIP
    """
    from kinegami.validation import UNITS_IN_MM

    pattern = chain.creasePattern(twistPortion) if pattern is None else pattern
    unit = UNITS_IN_MM[units] if units is not None else 1.0
    sheets = [GuideSheet("", pattern, tuple(range(len(chain.Joints))), layout)]
    picture = _picture(lambda: chain.show(block=False, units=units))
    return _guide(chain, sheets, bom=bom, title=title, picture=picture, units=units,
                  unit=unit, names=names, twistPortion=twistPortion,
                  closing=_pieces_page(sheets, unit))  # fmt: skip


def tree_guide_data(fabrication, *, bom: BillOfMaterials, layouts=None,
                    title: str = "kinegami robot", units: str | None = None,
                    names: Sequence[str | None] | None = None, labels: Sequence[str] = (),
                    twistPortion: float = 0.2) -> bytes:  # fmt: skip
    """The folding guide of a tree (its :class:`~kinegami.fabrication.sheets.TreeFabrication`),
    as PDF bytes: every sheet's steps, one after the other, then which sheet goes to which
    junction (``labels``: each sheet's one-line label). Other parameters as for
    :func:`chain_guide_data` (``layouts``: one BedLayout per sheet)."""
    from kinegami.validation import UNITS_IN_MM
    from kinegami.viz.chain_plot import show_fabrication

    unit = UNITS_IN_MM[units] if units is not None else 1.0
    tree = fabrication.tree
    sheets = [GuideSheet(sheet.name, sheet.pattern, sheet.joints,
                         None if layouts is None else layouts[k])
              for k, sheet in enumerate(fabrication.sheets)]  # fmt: skip
    picture = _picture(lambda: show_fabrication(fabrication, units=units))
    joins = []
    for sheet in fabrication.sheets:
        name = sheet.name.capitalize()
        if sheet.junction is not None:
            junction = next(j for j in fabrication.junctions if j.index == sheet.junction)
            joins.append(f"{name} (joints {sheet.joints[0]} to {sheet.leaf}) goes into "
                         f"junction {junction.index} at joint {junction.joint}: push its start "
                         f"into the socket of joint {sheet.joints[0]} and tape it.")  # fmt: skip
        elif sheet.takeoff is not None:
            joins.append(f"{name} starts at take-off {sheet.takeoff}: glue its skirt "
                         f"inside hole {sheet.takeoff} of sheet {sheet.takeoff_sheet}.")
        else:
            joins.append(f"{name} (joints {sheet.joints[0]} to {sheet.leaf}) starts at "
                         "the root.")  # fmt: skip
    for junction in fabrication.junctions:
        trunk = next(s.name for s in fabrication.sheets if junction.trunk in s.joints)
        joins.append(f"Junction {junction.index} (printed connector) at joint {junction.joint}: "
                     f"{trunk} runs through it (child {junction.trunk}); children "
                     f"{', '.join(str(c) for c in junction.children)}.")  # fmt: skip
    closing = _pieces_page(sheets, unit) + [("Sheets and junctions", [
        "Fold every sheet, then join them: thread each sheet through or into its junction's "
        "printed connector.", *joins, *labels])]  # fmt: skip
    return _guide(tree, sheets, bom=bom, title=title, picture=picture, units=units, unit=unit,
                  names=names, twistPortion=twistPortion, closing=closing)
