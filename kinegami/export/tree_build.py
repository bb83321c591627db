"""The files of a tree's build (docs/trees.md): a sheet per leaf, the junction connectors and
the whole tree.

``kinegami build TREE.json`` writes, for the stem ``hand``:

* ``hand_sheet_<k>.dxf``, ``.svg``, ``.fold``: every sheet's crease pattern, labelled (which
  sheet, its joints, the junction it starts in); with a laser bed, ``hand_sheet_<k>_bed_<m>.dxf``
  and ``.svg`` instead: every sheet cut into pieces that fit the bed and nested onto bed sheets
  of its own (:func:`sheet_layouts`, docs/fabrication.md "Laser bed");
* ``hand.pdf``: every sheet at 1:1, one after the other, each titled with its label;
* ``hand_junction_<k>.stl`` and ``.3mf``: the printed connector of every junction (mm);
* ``hand.stl``, ``hand.obj``, ``hand.urdf`` (with ``hand_meshes/``): the whole tree.

Each format is a name of ``--formats``; :data:`TREE_FORMATS` lists them. Every file goes
through the exporter registry or the one atomic writer.
"""

from __future__ import annotations

from collections.abc import Sequence
from pathlib import Path

from kinegami._atomic import write_atomic
from kinegami.errors import InvalidParameterError
from kinegami.export._reproducible import reproducible_3mf
from kinegami.validation import UNITS_IN_MM

__all__ = [
    "TREE_FORMATS",
    "DEFAULT_TREE_FORMATS",
    "FORMAT_LIBRARIES",
    "write_tree_files",
    "sheet_labels",
    "sheet_layouts",
]

#: ``--formats`` names for trees and what each writes.
TREE_FORMATS = {
    "dxf": "DXF of every sheet (<stem>_sheet_<k>.dxf), labelled",
    "svg": "SVG of every sheet (<stem>_sheet_<k>.svg; Origami Simulator flavour), labelled",
    "fold": "FOLD of every sheet (<stem>_sheet_<k>.fold)",
    "pdf": "one PDF with every sheet at 1:1 (<stem>.pdf), each titled with its label",
    "junctions": "the printed junction connectors (<stem>_junction_<k>.stl and .3mf, mm)",
    "stl": "binary STL of the whole tree (<stem>.stl, mm)",
    "obj": "Wavefront OBJ of the whole tree (<stem>.obj, mm)",
    "urdf": "URDF of the whole tree (<stem>.urdf, metres, meshes in <stem>_meshes/)",
}
DEFAULT_TREE_FORMATS = ("dxf", "svg", "fold", "pdf", "junctions", "urdf")
#: The optional libraries a tree format needs and the ``pip install 'kinegami[extra]'`` that
#: installs them (``kinegami build`` leaves a default format out when one is missing).
FORMAT_LIBRARIES = {
    "junctions": (("manifold3d", "trimesh", "lxml", "networkx"), "print"),  # 3MF: lxml, networkx
    "stl": (("trimesh",), "mesh"),
    "obj": (("trimesh",), "mesh"),
    "urdf": (("trimesh",), "mesh"),
}


def sheet_labels(fabrication, names: Sequence[str | None] | None = None,
                 units: str | None = None) -> list[str]:  # fmt: skip
    """The label of every sheet (:meth:`kinegami.fabrication.sheets.TreeSheet.label`; lengths in mm
    when the design's ``units`` are given)."""
    length = None
    if units is not None:
        factor = UNITS_IN_MM[units]
        length = lambda v: f"{v * factor:.1f} mm"  # noqa: E731
    return [sheet.label(fabrication.tree, names, length) for sheet in fabrication.sheets]


def sheet_layouts(fabrication, bed, units: str = "mm", name: str | None = None) -> list:
    """Every sheet of a tree laid out on ``bed`` (a :class:`~kinegami.fabrication.beds.Bed`),
    one :class:`~kinegami.fabrication.beds.BedLayout` per sheet, in order; the pieces' labels
    say "NAME, sheet k, piece i of n ...".

    Raises
    ------
    BedTooSmallError
        For the first sheet that cannot be cut into pieces that fit (the message names it).
    """
    from kinegami.errors import BedTooSmallError
    from kinegami.fabrication.beds import lay_out

    layouts = []
    for sheet in fabrication.sheets:
        label = f"sheet {sheet.index}" if not name else f"{name}, sheet {sheet.index}"
        try:
            layouts.append(lay_out(sheet.pattern, bed, unit=UNITS_IN_MM[units], name=label))
        except BedTooSmallError as error:
            raise BedTooSmallError(f"sheet {sheet.index}: {error}", error.smallest,
                                   error.stretch, error.needed) from None  # fmt: skip
    return layouts


def write_tree_files(
    fabrication,
    folder: str | Path,
    stem: str,
    formats: Sequence[str],
    *,
    units: str = "mm",
    twistPortion: float = 0.2,
    names: Sequence[str | None] | None = None,
    layouts: Sequence | None = None,
) -> list[Path]:
    """Write the files of ``formats`` for a :class:`~kinegami.fabrication.sheets.TreeFabrication`
    into ``folder`` and return their paths (in the order written).

    ``layouts`` (:func:`sheet_layouts`, one per sheet): the DXF and SVG go one file per bed
    sheet, ``<stem>_sheet_<k>_bed_<m>.dxf`` (the SVG in the laser flavour).

    Raises
    ------
    InvalidParameterError
        For an unknown format name.
    ExporterUnavailableError
        When a format's library is missing (the message names the ``pip install`` extra).
    """
    from kinegami.export import registry

    unknown = [f for f in formats if f not in TREE_FORMATS]
    if unknown:
        raise InvalidParameterError(
            f"formats: unknown tree format {unknown[0]!r}; known: {', '.join(TREE_FORMATS)}"
        )
    folder = Path(folder)
    labels = sheet_labels(fabrication, names, units)
    for fmt in formats:  # before writing anything: every library the formats need
        if fmt == "junctions" and not fabrication.junctions:  # folded take-offs: none printed
            continue
        modules, extra = FORMAT_LIBRARIES.get(fmt, ((), None))
        for module in modules:
            registry.import_library(module, TREE_FORMATS[fmt].partition(" (")[0], extra)
    folded = fabrication.folded_tree()
    written: list[Path] = []
    for fmt in formats:
        if fmt in ("dxf", "svg") and layouts is not None:
            from kinegami.export.beds import bed_files

            for sheet, layout in zip(fabrication.sheets, layouts, strict=True):
                files = bed_files(layout, f"{stem}_sheet_{sheet.index}", f".{fmt}")
                for file_name, text in files.items():
                    written.append(write_atomic(folder / file_name, text))
        elif fmt in ("dxf", "svg", "fold"):
            for sheet, label in zip(fabrication.sheets, labels, strict=True):
                path = folder / f"{stem}_sheet_{sheet.index}.{fmt}"
                extra = {} if fmt == "fold" else {"label": label}
                if fmt == "fold" and getattr(sheet.pattern, "frame", None) is None:
                    extra["frame"] = sheet.frame  # folded in the tree's world frame
                registry.export(sheet.pattern, path, units=units, **extra)
                written.append(path)
        elif fmt == "pdf":
            registry.import_library("matplotlib", "the PDF of a tree's sheets", "pdf")
            from kinegami.export.pdf import sheets_pdf_data

            path = folder / f"{stem}.pdf"
            data = sheets_pdf_data([s.pattern for s in fabrication.sheets], labels, units=units,
                                   title=f"{stem}: {len(labels)} sheets")  # fmt: skip
            written.append(write_atomic(path, data))
        elif fmt == "junctions":
            factor = UNITS_IN_MM[units]
            for junction in fabrication.junctions:
                mesh = fabrication.connector(junction.index).copy()
                mesh.apply_scale(factor)
                for suffix in ("stl", "3mf"):
                    path = folder / f"{stem}_junction_{junction.index}.{suffix}"
                    data = mesh.export(file_type=suffix)
                    if suffix == "3mf":
                        data = reproducible_3mf(data)
                    written.append(write_atomic(path, data))
        else:  # the whole tree as folded (take-off branches from their faces): stl, obj, urdf
            path = folder / f"{stem}.{fmt}"
            registry.export(folded, path, units=units, twistPortion=twistPortion)
            written.append(path)
            if fmt == "urdf":
                written.append(folder / f"{stem}_meshes")
    return written
