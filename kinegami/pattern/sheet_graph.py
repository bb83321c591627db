"""The sheet of a crease pattern, a chain's pattern or a cut-out sheet as a planar graph:
:func:`sheet_graph`, which the FOLD and Origami Simulator SVG exports write (docs/fold.md)."""

from __future__ import annotations

from kinegami.pattern.planar import SheetGraph, planar_graph

__all__ = ["sheet_graph", "SheetGraph"]


def sheet_graph(pattern_or_chain, *, folded: bool = True, frame=None, twistPortion=0.2):
    """The sheet of a pattern (or of a chain's crease pattern) as a planar graph with faces.

    The sheet is that of the pattern's unsnapped geometry
    (:func:`kinegami.pattern.folded.unsnapped_form`): where the catalog moved vertices (fix B6, seam
    snapping) they stay where the module formulas put them, so the folded form keeps every edge
    length; the sheet differs from the DXF sheet by less than eps = 1e-4 b, or up to 2e-4 r next to
    an elbow column collapsed by B6 (docs/fold.md). ``source`` indexes the vertices of that
    unsnapped pattern (``pattern`` attribute of the result), whose vertex i is vertex i of the given
    pattern for every i below its vertex count. Vertices that only split a straight line are
    merged away and straight face corners split by flat diagonals (module docstring); without
    ``folded`` (a pattern made by hand) the fold angles are not compared when merging.

    Parameters
    ----------
    pattern_or_chain : TubularPattern, CutPattern or KinematicChain
        A :class:`~kinegami.pattern.cutout.CutPattern` (a sheet with take-off holes or a skirt)
        is cut as :mod:`kinegami.pattern.cut_graph` says; its folded form starts at its
        ``frame`` unless ``frame`` is given.
    folded : bool, optional
        Also compute the folded 3D position of every sheet vertex (default True).
    frame, twistPortion
        As for :func:`kinegami.pattern.folded.folded_form`.

    Returns
    -------
    SheetGraph

    Raises
    ------
    FoldExportError
        If the sheet has zero area, or its creases cross or overlap so that the faces do not
        tile the sheet.
    """
    # imported here: exporting a plain pattern does not load the cut-out and fold modules
    from kinegami.pattern.cutout import CutPattern
    from kinegami.pattern.folded import pattern_and_frame, unsnapped_form

    if isinstance(pattern_or_chain, CutPattern):  # a sheet with take-off holes or a skirt
        from kinegami.pattern.cut_graph import cut_sheet_graph

        return cut_sheet_graph(pattern_or_chain, folded=folded, frame=frame)
    pattern, base = pattern_and_frame(pattern_or_chain, twistPortion)
    if not pattern.modules and not folded:  # a hand-made pattern: its own geometry
        return planar_graph(pattern, None)
    form = unsnapped_form(pattern, frame=base if frame is None else frame)
    return planar_graph(form.pattern, form.vertices if folded else None)
