"""The bill of materials of a build: what a maker needs to cut, glue and print (docs/fabrication.md,
"Bill of materials").

Computed once by :func:`bill_of_materials` and shown by the build summary and the folding
guide's cover (:meth:`BillOfMaterials.lines`). Every length is in mm, every area in mm².
"""

from __future__ import annotations

from collections.abc import Sequence
from dataclasses import dataclass

from kinegami.errors import InvalidParameterError
from kinegami.fabrication.beds import BedLayout, Material
from kinegami.pattern.sheet import flatten

__all__ = ["BillOfMaterials", "bill_of_materials"]


@dataclass(frozen=True)
class BillOfMaterials:
    """What a build needs (mm and mm²).

    Attributes
    ----------
    material : Material or None
        The sheet material (None: the design names none).
    sheets : int
        Crease pattern sheets (one for a chain, one per leaf for a tree).
    sheet_area : float
        Area of the sheets' rectangles, glue tab included, mm².
    pieces : int
        Pieces cut (the sheets themselves without a laser bed).
    bed_sheets : int or None
        Bed-sized sheets of material used (None without a laser bed).
    bed_area : float or None
        Their area, mm² (None without a laser bed).
    glue_tab : float
        Length of the glue tabs along the long seams, mm: every sheet's pattern height.
    joins : int
        Joins of two pieces (pieces less sheets), each glued with the next piece's tab.
    tube_perimeter : float
        One turn around the tube (the pattern's width), mm.
    sockets : int
        Sheets ending in a printed connector's socket (a tree's junction children).
    connectors : int
        Printed junction connectors (a tree's; 0 for a chain).
    """

    material: Material | None
    sheets: int
    sheet_area: float
    pieces: int
    bed_sheets: int | None
    bed_area: float | None
    glue_tab: float
    joins: int
    tube_perimeter: float
    sockets: int
    connectors: int

    @property
    def tape(self) -> float:
        """Estimated tape, mm: one turn around the tube at every join of two pieces and at every
        socket of a printed connector (to hold them while the glue sets)."""
        return self.tube_perimeter * (self.joins + self.sockets)

    def lines(self) -> list[str]:
        """The bill in words, one item a line (the summary indents them)."""
        material = "sheet material" if self.material is None else self.material.describe()
        area = f"{self.sheet_area / 1e6:.3f} m² of {material}"
        if self.bed_sheets is not None and self.bed_area is not None:
            area += (f", cut from {self.bed_sheets} bed sheet{'s' if self.bed_sheets != 1 else ''}"
                     f" ({self.bed_area / 1e6:.3f} m²)")  # fmt: skip
        joins = self.joins + self.sockets
        tape = (f"tape: about {self.tape:,.0f} mm (one turn of the {self.tube_perimeter:.0f} mm "
                f"tube at each of {_counted(joins, *_JOINS[self.sockets > 0])})"
                if joins else "tape: none needed (no joins of pieces, no sockets)")  # fmt: skip
        lines = [
            f"material: {area}",
            f"pieces: {self.pieces} ({_counted(self.sheets, 'sheet', 'sheets')}, "
            f"{_counted(self.joins, 'join', 'joins')})",
            f"glue tab: {self.glue_tab:,.0f} mm (the long seam of every sheet)",
            tape,
        ]
        if self.connectors:
            lines.append(f"printed connectors: {self.connectors} "
                         f"({_counted(self.sockets, 'socket', 'sockets')})")  # fmt: skip
        return lines


_JOINS = (("join", "joins"), ("join or socket", "joins and sockets"))


def _counted(count: int, one: str, many: str) -> str:
    return f"{count} {one if count == 1 else many}"


def bill_of_materials(
    patterns: Sequence,
    unit: float,
    *,
    material: Material | None = None,
    layouts: Sequence[BedLayout] | None = None,
    fabrication=None,
) -> BillOfMaterials:
    """The bill of materials of ``patterns`` (a chain's crease pattern, or a tree's sheets).

    Parameters
    ----------
    patterns : sequence of TubularPattern or CutPattern
        Every sheet, in order.
    unit : float
        Millimetres per pattern unit.
    material : Material, optional
    layouts : sequence of BedLayout, optional
        Each sheet laid out on a laser bed (:func:`kinegami.fabrication.beds.lay_out`).
    fabrication : TreeFabrication, optional
        A tree's fabrication: its printed connectors and their sockets.
    """
    patterns = list(patterns)
    if not patterns:
        raise InvalidParameterError("bill_of_materials needs at least one sheet, got none")
    if layouts is not None and len(layouts) != len(patterns):
        raise InvalidParameterError(
            f"layouts must have one entry per sheet ({len(patterns)}), got {len(layouts)}"
        )
    area = 0.0
    for pattern in patterns:
        xmin, ymin, xmax, ymax = flatten(pattern).bounds
        area += (xmax - xmin) * (ymax - ymin) * unit * unit
    plain = [getattr(p, "pattern", p) for p in patterns]
    pieces = len(patterns) if layouts is None else sum(len(lay.pieces) for lay in layouts)
    junctions = () if fabrication is None else fabrication.junctions
    return BillOfMaterials(
        material=material,
        sheets=len(patterns),
        sheet_area=area,
        pieces=pieces,
        bed_sheets=None if layouts is None else sum(lay.count for lay in layouts),
        bed_area=None if layouts is None else sum(lay.material_area for lay in layouts),
        glue_tab=sum(p.height for p in plain) * unit,
        joins=pieces - len(patterns),
        tube_perimeter=plain[0].width * unit,
        sockets=sum(len(j.children) - 1 for j in junctions),
        connectors=len(junctions),
    )
