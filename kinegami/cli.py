"""The ``kinegami`` command line: a thin shell over the library.

Commands::

    kinegami build DESIGN -o DIR [--formats dxf,svg,png] [--name STEM]
    kinegami show DESIGN [--pattern]
    kinegami validate DESIGN
    kinegami new DESIGN [--force] [--task [--tree]]
    kinegami design TASK -o DIR [--seed S] [--name STEM] [--formats LIST]
    kinegami check DESIGN [--motion N] [--seed S] [--json]
    kinegami compact DESIGN -o OUT.json [--seed S] [--motion] [--time-limit T] [--force]

Exit codes: 0 success, 1 a design or export error (one line on stderr, no traceback, no file
written), 2 a usage error (argparse), 3 ``check``: the design self-intersects at its states;
``compact``: no clear design was found.
"""

from __future__ import annotations

import argparse
import errno
import functools
import os
import re
import signal
import stat
import sys
import warnings
from collections.abc import Callable
from pathlib import Path
from typing import TYPE_CHECKING

from kinegami import __version__, _startup
from kinegami._record import Record
from kinegami._startup import INTERRUPTED
from kinegami.errors import KinegamiError
from kinegami.limits import MAX_INTEGER_DIGITS, MAX_SAMPLES
from kinegami.validation import UNITS_IN_MM, shown, shown_path

if TYPE_CHECKING:
    import numpy as np


class CommandError(Exception):
    """A failure reported as one line on stderr with exit code 1."""


# --- outputs of `build` ------------------------------------------------------------------------
class OutputFormat(Record):
    """One ``--formats`` entry: the files it writes and how."""

    name: str
    description: str
    suffixes: tuple[str, ...]  # file name endings after the stem, e.g. ("_3d.png", ...)
    write: Callable[..., None]  # write(job, paths) with one path per suffix


class BuildJob:
    """What the writers need: the chain, its pattern and the design's metadata."""

    __slots__ = ("chain", "info", "_pattern", "_clearance")

    def __init__(self, chain, info, _pattern=None, _clearance=None):
        self.chain, self.info = chain, info
        self._pattern, self._clearance = _pattern, _clearance

    @property
    def pattern(self):
        if self._pattern is None:
            self._pattern = self.chain.creasePattern(twistPortion=self.info.twistPortion)
        return self._pattern

    @property
    def clearance(self):
        """The chain's ClearanceReport at its states (parts named with the joint names)."""
        if self._clearance is None:
            self._clearance = _clearance(self.chain)
        return self._clearance


def _png_data(job: BuildJob) -> tuple[bytes, bytes]:
    """The PNG files of the 3D chain and of its pattern (150 dpi)."""
    import io

    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    pictures = []
    for draw in (lambda: job.chain.show(block=False, units=job.info.units),
                 lambda: job.pattern.show(units=job.info.units)):  # fmt: skip
        fig, _ = draw()
        try:
            data = io.BytesIO()
            fig.savefig(data, format="png", dpi=150, bbox_inches="tight")
            pictures.append(data.getvalue())
        finally:
            plt.close(fig)
    return pictures[0], pictures[1]


def _write_pngs(job: BuildJob, paths: list[Path]) -> None:
    for path, data in zip(paths, _png_data(job), strict=True):
        path.write_bytes(data)


#: A chain with at least this many joints has its pictures drawn in a second process while
#: this one checks it and writes the other files (when the machine has two cores or more).
BACKGROUND_PICTURES_JOINTS = 200


class BackgroundPictures:
    """:func:`_png_data` of a job computed in a forked child process (the job is inherited,
    not copied through a pipe); :meth:`result` waits for the two files' bytes, :meth:`stop`
    ends the child if it still runs. Only where the ``fork`` start method exists."""

    def __init__(self, job: BuildJob):
        import multiprocessing

        context = multiprocessing.get_context("fork")
        self._receive, send = context.Pipe(duplex=False)
        self._process = context.Process(target=_send_png_data, args=(job, send), daemon=True)
        self._process.start()
        send.close()

    @staticmethod
    def wanted(job: BuildJob, formats) -> bool:
        """Whether drawing the pictures in the background pays for this build."""
        import multiprocessing

        return (any(fmt.name == "png" for fmt in formats) and len(formats) > 1
                and len(job.chain.Joints) >= BACKGROUND_PICTURES_JOINTS
                and (os.cpu_count() or 1) > 1
                and "fork" in multiprocessing.get_all_start_methods())  # fmt: skip

    def result(self) -> tuple[bytes, bytes]:
        """The two PNG files; the child's KinegamiError is raised here as a KinegamiError."""
        try:
            kind, payload = self._receive.recv()
        except EOFError:
            status = self._process.exitcode
            raise CommandError("png export: the process drawing the pictures ended without "
                               f"them (exit status {status})") from None  # fmt: skip
        finally:
            self._process.join()
        if kind != "ok":
            raise KinegamiError(payload) if kind == "error" else CommandError(payload)
        return payload

    def stop(self) -> None:
        if self._process.is_alive():
            self._process.terminate()
        self._process.join()
        self._receive.close()


def _send_png_data(job: BuildJob, send) -> None:
    """The child of :class:`BackgroundPictures`: draw, send the bytes or the error's line."""
    try:
        send.send(("ok", _png_data(job)))
    except KinegamiError as error:
        send.send(("error", str(error)))
    except Exception as error:  # a bug: its one line, as main() words one
        send.send(("bug", f"png export: internal error: {type(error).__name__}: {error}"))
    finally:
        send.close()


def _write_guide(job: BuildJob, paths: list[Path], layout=None, bom=None) -> None:
    """The folding guide of a chain (kinegami.viz.guide), with its layout on a laser bed."""
    import matplotlib

    matplotlib.use("Agg", force=True)
    from kinegami.viz.guide import chain_guide_data

    if bom is None:
        bom = _chain_bom(job, layout)
    paths[0].write_bytes(chain_guide_data(
        job.chain, bom=bom, pattern=job.pattern, layout=layout,
        title=job.info.name or paths[0].name.removesuffix("_guide.pdf"), units=job.info.units,
        names=_joint_names(job.chain), twistPortion=job.info.twistPortion))  # fmt: skip


def _chain_bom(job: BuildJob, layout=None):
    """The bill of materials of a chain's build (kinegami.fabrication.bom)."""
    from kinegami.fabrication.bom import bill_of_materials

    return bill_of_materials([job.pattern], UNITS_IN_MM[job.info.units],
                             material=job.info.material,
                             layouts=None if layout is None else [layout])  # fmt: skip


def _bom_lines(bom) -> list[str]:
    """The summary's bill of materials."""
    return ["  bill of materials:", *(f"    {_printable(line)}" for line in bom.lines())]


def _registry_writer(suffix: str) -> Callable[..., None]:
    """A writer through the exporter registry (:func:`kinegami.export`): pattern formats get
    the design's pattern, the others the chain (with the design's twistPortion); all get the
    design's units."""

    def write(job: BuildJob, paths: list[Path]) -> None:
        from kinegami.export import registry

        if registry.FORMATS[suffix].accepts == "pattern":
            registry.export(job.pattern, paths[0], units=job.info.units)
        else:
            registry.export(
                job.chain, paths[0], units=job.info.units, twistPortion=job.info.twistPortion
            )

    return write


def output_formats() -> dict[str, OutputFormat]:
    """The formats ``build --formats`` accepts, by name: every format of the exporter registry
    (dxf and svg first) and ``png`` (pictures)."""
    from kinegami.export import known_formats

    known = known_formats()
    png = OutputFormat("png", "pictures of the 3D chain and of the pattern",
                       ("_3d.png", "_pattern.png"), _write_pngs)  # fmt: skip
    guide = OutputFormat("guide", "folding guide PDF (<stem>_guide.pdf): a cover with the robot "
                         "and the bill of materials, one step per module in folding order",
                         ("_guide.pdf",), _write_guide)  # fmt: skip
    order = [".dxf", ".svg", "png"] + [s for s in known if s not in (".dxf", ".svg")] + ["guide"]
    formats = {}
    for suffix in order:
        if suffix == "png":
            formats["png"] = png
        elif suffix == "guide":
            formats["guide"] = guide
        elif suffix in known:
            name = suffix.lstrip(".")
            formats[name] = OutputFormat(name, known[suffix], (suffix,), _registry_writer(suffix))
    return formats


DEFAULT_FORMATS = ("dxf", "svg", "png")


def _parse_formats(text: str) -> list[OutputFormat]:
    known = output_formats()
    names = [item.strip().lower().lstrip(".") for item in text.split(",") if item.strip()]
    if not names:
        raise CommandError(f"--formats: no format given; known: {', '.join(known)}, all")
    unknown = [name for name in names if name not in known and name != "all"]
    if unknown:  # also next to "all": a typo is never silently ignored
        raise CommandError(
            f"--formats: unknown format {shown(unknown[0])}; known: {', '.join(known)}, all"
        )
    if "all" in names:
        return list(known.values())
    return [known[name] for name in dict.fromkeys(names)]


# --- helpers -----------------------------------------------------------------------------------
def _load(design: str):
    """The chain and info of a design; the chain's ClearanceWarnings are not printed (build,
    check and compact report the clearance themselves, in one line or in words)."""
    from kinegami.design import load_design_with_info
    from kinegami.errors import ClearanceWarning

    with warnings.catch_warnings():
        warnings.simplefilter("ignore", ClearanceWarning)
        return load_design_with_info(design)


def _check_pattern(job: BuildJob) -> None:
    """Build the crease pattern now, so that a pattern error is a design error naming the
    design file and the joint or link (kinegami.design.check_pattern)."""
    from kinegami.design import check_pattern

    job._pattern = check_pattern(job.chain, job.info)


def _printable(text: str) -> str:
    """``text`` with control characters (newlines, escapes) shown escaped."""
    return "".join(c if c.isprintable() else repr(c)[1:-1] for c in text)


def _sheet_size(job: BuildJob) -> str:
    """The sheet in mm: "310.2 mm x 94.2 mm with the glue tab (the crease pattern alone: ...)"."""
    from kinegami.pattern.sheet import flatten

    factor = UNITS_IN_MM[job.info.units]
    xmin, ymin, xmax, ymax = flatten(job.pattern).bounds
    return (
        f"{(xmax - xmin) * factor:.1f} mm x {(ymax - ymin) * factor:.1f} mm with the glue tab "
        f"(the crease pattern alone: {job.pattern.width * factor:.1f} mm x "
        f"{job.pattern.height * factor:.1f} mm)"
    )


def _summary(job: BuildJob, design: str) -> list[str]:
    from collections import Counter

    chain, info = job.chain, job.info
    factor = UNITS_IN_MM[info.units]
    counts = Counter(type(joint).__name__ for joint in chain.Joints)
    kinds = ", ".join(f"{count} {name}" for name, count in counts.items())
    links = len(chain.Joints) - 1
    joints_length = sum(joint.neutralLength for joint in chain.Joints)
    links_length = chain.totalPathLength()
    tube = links_length + joints_length
    title = f"{_printable(info.name)} ({design})" if info.name else design
    return [
        title,
        f"  joints: {len(chain.Joints)} ({kinds})",
        f"  links: {links}",
        f"  tube: {chain.numSides} sides, r = {chain.r * factor:g} mm",
        f"  sheet: {_sheet_size(job)}",
        f"  total tube length: {tube * factor:.1f} mm "
        f"(links {links_length * factor:.1f} mm, joints {joints_length * factor:.1f} mm)",
        *_material_lines(chain, info),
        _verdict_line(job.clearance, info),
    ]


# --- clearance (`check` and the build summary) -------------------------------------------------
#: Exit code of ``check`` when the design self-intersects at its states.
SELF_INTERSECTS = 3
#: Most configurations ``check --motion`` samples (also at most MAX_SAMPLED_STATES / joints:
#: docs/limits.md).
MAX_MOTION = MAX_SAMPLES
#: Most overlapping pairs ``check`` lists in words (``--json`` lists them all).
LISTED_PAIRS = 20


def _joint_names(chain) -> tuple | None:
    """The joint names of a chain loaded from a design (one line, shortened), or None."""
    from kinegami.design.reader import origin_of
    from kinegami.validation import shorten

    origin = origin_of(chain)
    if origin is None:
        return None
    return tuple(None if name is None else shorten(name) for name in origin.names)


def _clearance(chain):
    """The clearance report of a chain or a tree at its states with its own ``margin`` (which
    ``--margin`` sets), the parts named with the joint names: the one verdict build, check,
    compact, the editor and the library give (kinegami.clearance.ClearanceReport.verdict)."""
    from kinegami.clearance import clearance_report

    return clearance_report(chain, names=_joint_names(chain))


def _verdict_line(report, info) -> str:
    """The summary's clearance line, the same in build, check and compact: "  clearance: " and
    the report's verdict (lengths in mm and the design's unit; ClearanceReport.summary)."""
    (line,) = report.summary(info.units, listed=0)
    return _printable(line)


def _margin(args: argparse.Namespace, chain) -> None:
    """Apply ``--margin`` (the design's units; default: the design's own "margin") to the
    chain or tree, before anything is judged."""
    text = getattr(args, "margin", None)
    if text is None:
        return
    import math

    from kinegami.validation import shorten

    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value >= 0.0):
        raise CommandError(
            f"--margin: must be a number >= 0 (the clearance required between parts, in the "
            f"design's units), got {shorten(text)!r}"
        )
    chain.margin = value


def _millimetres(option: str, text: str | None) -> float | None:
    """A finite number of mm given to ``option`` (checked further by the library), or None."""
    if text is None:
        return None
    import math

    from kinegami.validation import shorten

    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not math.isfinite(value):
        raise CommandError(f"{option}: must be a number of millimetres, got {shorten(text)!r}")
    return value


def _fabrication(args: argparse.Namespace, chain, info):
    """The design's info with ``--material``/``--thickness`` and (build) ``--bed``,
    ``--bed-margin``, ``--tab`` applied; a new material's thickness becomes the chain's margin
    unless ``--margin`` or the design's own "margin" says otherwise (docs/fabrication.md)."""
    options = ("material", "thickness", "bed", "bed_margin", "tab")
    if all(getattr(args, option, None) is None for option in options):
        return info  # the design's (no import of the bed code: check stays quick)
    import dataclasses

    from kinegami.fabrication.beds import Bed, check_material, parse_bed

    name, thickness = getattr(args, "material", None), getattr(args, "thickness", None)
    material = info.material
    if name is not None or thickness is not None:
        thickness = _millimetres("--thickness", thickness)
        if name is None:
            if info.material is None:
                raise CommandError("--thickness: give the material too (--material NAME); the "
                                   "design names none")  # fmt: skip
            name = info.material.name
        try:
            material = check_material(name, thickness)
        except KinegamiError as error:
            option = "--thickness" if str(error).startswith("thickness") else "--material"
            raise CommandError(f"{option}: {str(error).removeprefix('thickness: ')}") from None
        if getattr(args, "margin", None) is None and info.margin is None:
            chain.margin = material.thickness / UNITS_IN_MM[info.units]
    bed = info.bed
    text = getattr(args, "bed", None)
    margin = _millimetres("--bed-margin", getattr(args, "bed_margin", None))
    tab = _millimetres("--tab", getattr(args, "tab", None))
    try:
        if text is not None and text.strip().lower() == "none":
            bed = None
        elif text is not None:
            width, height = parse_bed(text)
            bed = Bed.of(width, height, margin if margin is not None else
                         None if info.bed is None else info.bed.margin,
                         tab if tab is not None else None if info.bed is None else info.bed.tab)
        elif margin is not None or tab is not None:
            if info.bed is None:
                option = "--bed-margin" if margin is not None else "--tab"
                raise CommandError(f"{option}: give the bed too (--bed WxH, mm); the design "
                                   "names none")  # fmt: skip
            bed = Bed.of(info.bed.width, info.bed.height,
                         info.bed.margin if margin is None else margin,
                         info.bed.tab if tab is None else tab)  # fmt: skip
    except KinegamiError as error:
        words = str(error).split(" ")
        option = {"tab": "--tab", "margin": "--bed-margin"}.get(words[1] if words[0] == "bed"
                                                                  else words[0], "--bed")
        raise CommandError(f"{option}: {error}") from None
    return dataclasses.replace(info, material=material, bed=bed)


def _material_lines(chain, info) -> list[str]:
    """The summary's material line ("  material: PET, 0.25 mm thick, the clearance margin"),
    none without a material."""
    if info.material is None:
        return []
    thickness = info.material.thickness
    margin = chain.margin * UNITS_IN_MM[info.units]
    if abs(margin - thickness) <= 1e-9 * max(thickness, 1.0):
        return [f"  material: {_printable(info.material.describe())}, the clearance margin"]
    return [f"  material: {_printable(info.material.describe())} (the clearance margin is "
            f"{margin:g} mm)"]  # fmt: skip


def _square_metres(area: float) -> str:
    return f"{area / 1e6:.2f} square metres"


def _counted(count: int, one: str, many: str) -> str:
    return f"{count} {one if count == 1 else many}"


def _bed_summary(layouts, info, sheets=None) -> list[str]:
    """The summary's laser bed lines: the bed, then each piece (or, for a tree's sheets, each
    sheet's pieces and beds)."""
    bed = info.bed
    count = sum(layout.count for layout in layouts)
    pieces_area = sum(layout.pieces_area for layout in layouts)
    material = info.material.name if info.material is not None else "material"
    head = (f"  laser bed: {bed.describe()} (margin {bed.margin:g} mm), tab {bed.tab:g} mm (a "
            f"cut needs {bed.minimum_tube:g} mm of plain tube): "
            f"{_counted(sum(len(layout.pieces) for layout in layouts), 'piece', 'pieces')} on "
            f"{_counted(count, 'bed sheet', 'bed sheets')}, "
            f"{_square_metres(count * bed.width * bed.height)} of "
            f"{_printable(material)} (the pieces {_square_metres(pieces_area)})")  # fmt: skip
    lines = [head]
    for k, layout in enumerate(layouts):
        prefix = "    " if sheets is None else "      "
        if sheets is not None:
            lines.append(f"    sheet {sheets[k]}: "
                         f"{_counted(len(layout.pieces), 'piece', 'pieces')} on "
                         f"{_counted(layout.count, 'bed sheet', 'bed sheets')}")  # fmt: skip
        if len(layout.pieces) == 1:
            lines.append(f"{prefix}the sheet fits whole")
            continue
        start = layout.pieces[0].start
        for piece, place in zip(layout.pieces, layout.placements, strict=True):
            long_side, short_side = sorted((place.width, place.height), reverse=True)
            lines.append(
                f"{prefix}piece {piece.index}: {(piece.start - start) * layout.unit:,.0f} to "
                f"{(piece.end - start) * layout.unit:,.0f} mm along the strip"
                + (f", {piece.tab * layout.unit:g} mm tab" if piece.tab else "")
                + f" ({long_side:.0f} x {short_side:.0f} mm), bed sheet {place.bin + 1}"
            )
    return lines


def _bed_failure(label: str, error) -> CommandError:
    """The one line of a sheet that cannot be cut to fit the bed, with the --bed that works."""
    width, height = error.smallest
    return CommandError(f"{label}: {error} (--bed {width:g}x{height:g})")


# --- commands ----------------------------------------------------------------------------------
def _plain_stem(stem: str) -> str:
    if (
        not stem
        or stem.startswith(".")
        or os.sep in stem
        or (os.altsep and os.altsep in stem)
        or any(ord(c) < 32 for c in stem)
    ):
        raise CommandError(
            f"--name: {shown(stem)} is not a plain file name (no folders, no dot first)"
        )
    return stem


def _check_output(out: Path) -> None:
    """Fail before building when ``-o`` cannot become a folder: it, or a folder on the way to
    it, is a file, a symbolic link to nothing (dangling) or a symbolic link loop. A missing
    folder is fine (the build creates it)."""
    steps = [*reversed(out.parents), out]
    for path in steps:
        try:
            info = os.lstat(path)
        except FileNotFoundError:
            return  # the rest is created by the build
        except OSError:
            return  # not ours to judge (permissions...): the build reports what fails
        named = shown_path(path)
        if stat.S_ISLNK(info.st_mode):
            try:
                info = os.stat(path)
            except OSError as error:
                if error.errno == errno.ELOOP:
                    raise CommandError(
                        f"-o: {named} is a symbolic link loop (following it never ends); "
                        "give a folder"
                    ) from None
                if error.errno == errno.ENOENT:
                    target = shown_path(os.readlink(path))
                    raise CommandError(
                        f"-o: {named} is a symbolic link to {target}, which does not "
                        "exist (dangling); create that folder or give another"
                    ) from None
                return
        if not stat.S_ISDIR(info.st_mode):
            where = "exists and is not a folder" if path == out else "is not a folder"
            raise CommandError(f"-o: {named} {where}")


def _is_tree(chain) -> bool:
    from kinegami.tree import KinematicTree

    return isinstance(chain, KinematicTree)


def _parse_tree_formats(text: str | None) -> list[str]:
    """``--formats`` of a tree: the names of kinegami.export.tree_build.TREE_FORMATS and png."""
    from kinegami.export.tree_build import DEFAULT_TREE_FORMATS, TREE_FORMATS

    known = [*TREE_FORMATS, "png", "guide"]
    if text is None:
        return [*DEFAULT_TREE_FORMATS, "png"]
    names = [item.strip().lower().lstrip(".") for item in text.split(",") if item.strip()]
    if not names:
        raise CommandError(f"--formats: no format given; known for trees: {', '.join(known)}, all")
    unknown = [name for name in names if name not in known and name != "all"]
    if unknown:
        raise CommandError(
            f"--formats: unknown format for a tree {shown(unknown[0])}; known for trees: "
            f"{', '.join(known)}, all"
        )
    return known if "all" in names else list(dict.fromkeys(names))


def _write_tree_guide(fabrication, path: Path, info, stem: str, bom, layouts, names) -> None:
    """The folding guide of a tree (kinegami.viz.guide), every sheet's steps then its
    junctions."""
    import matplotlib

    matplotlib.use("Agg", force=True)
    from kinegami.export.tree_build import sheet_labels
    from kinegami.viz.guide import tree_guide_data

    labels = sheet_labels(fabrication, names, info.units)
    path.write_bytes(tree_guide_data(
        fabrication, bom=bom, layouts=layouts, title=info.name or stem, units=info.units,
        names=names, labels=labels, twistPortion=info.twistPortion))  # fmt: skip


def _write_tree_pictures(fabrication, folder: Path, stem: str, units: str | None = None
                         ) -> list[Path]:  # fmt: skip
    """The 3D picture of the tree and a picture of every sheet's pattern (PNG), lengths
    labelled in ``units`` (the design's)."""
    import matplotlib

    matplotlib.use("Agg", force=True)
    import matplotlib.pyplot as plt

    from kinegami._atomic import write_atomic

    def save(fig, path: Path) -> Path:
        import io

        buffer = io.BytesIO()
        try:
            fig.savefig(buffer, format="png", dpi=150, bbox_inches="tight")
        finally:
            plt.close(fig)
        return write_atomic(path, buffer.getvalue())

    # the tree as folded (take-off branches from their faces) with its connectors, when they
    # can be made here
    view = fabrication.show(block=False, units=units, showJunctions=_importable("manifold3d")
                            and _importable("trimesh"))  # fmt: skip
    written = [save(view[0], folder / f"{stem}_3d.png")]
    for sheet in fabrication.sheets:
        fig, _ = sheet.pattern.show(units=units)
        written.append(save(fig, folder / f"{stem}_sheet_{sheet.index}_pattern.png"))
    return written


def _stale_bed_files(out: Path, stem: str, fmt: str, new: Path) -> list[str]:
    """The ``<stem>_bed_<m>.<fmt>`` files in ``out`` that the build in ``new`` does not write
    again: what an earlier build with more beds (or with a bed) left."""
    from kinegami.export.beds import stale_bed_files

    return stale_bed_files(out, stem, f".{fmt}", set(os.listdir(new)))


def _tree_summary(tree, info, design: str, fabrication, moves, written=None) -> list[str]:
    """The summary of a tree's build; ``written``: the clearance report of the design file as
    written, when the build slid joints (then it is not the tree built)."""
    from collections import Counter

    from kinegami.export.tree_build import sheet_labels
    from kinegami.pattern.sheet import flatten

    factor = UNITS_IN_MM[info.units]
    counts = Counter(type(joint).__name__ for joint in tree.Joints)
    kinds = ", ".join(f"{count} {name}" for name, count in counts.items())
    joints_length = sum(joint.neutralLength for joint in tree.Joints)
    links_length = tree.totalPathLength()
    names = _joint_names(tree)
    title = f"{_printable(info.name)} ({design})" if info.name else design
    report = _clearance(tree)
    lines = [
        title,
        f"  joints: {len(tree.Joints)} ({kinds}), a tree with {len(fabrication.sheets)} leaves",
        f"  tube: {tree.numSides} sides, r = {tree.r * factor:g} mm",
        f"  total tube length: {(links_length + joints_length) * factor:.1f} mm "
        f"(links {links_length * factor:.1f} mm, joints {joints_length * factor:.1f} mm)",
        *_material_lines(tree, info),
        _verdict_line(report, info),
        f"  sheets: {len(fabrication.sheets)} (one per leaf)",
    ]  # fmt: skip
    labels = sheet_labels(fabrication, names, info.units)
    for sheet, label in zip(fabrication.sheets, labels, strict=True):
        xmin, ymin, xmax, ymax = flatten(sheet.pattern).bounds
        lines.append(
            f"    {_printable(label)}; "
            f"{(xmax - xmin) * factor:.1f} mm x {(ymax - ymin) * factor:.1f} mm"
        )
    lines.append(f"  junctions: {len(fabrication.junctions)} (printed connectors)")
    for junction in fabrication.junctions:
        kids = ", ".join(str(c) for c in junction.children)
        lines.append(f"    junction {junction.index}: at joint {junction.joint}, children "
                     f"{kids}, trunk {junction.trunk} (its sheet runs through)")  # fmt: skip
    for joint, slide in moves:
        lines.append(f"  note: joint {joint} slid {slide * factor:.1f} mm along its axis so that "
                     "its socket fits (the kinematics are unchanged)")  # fmt: skip
    if written is not None:
        lines.append("  note: the clearance above is that of the tree as built, with the slides; "
                     "'kinegami check' and the editor judge the design file as written: "
                     f"{_printable(written.verdict(info.units))} (write the slides into the "
                     "design, or let 'kinegami compact' write a design whose sockets fit, and "
                     "they judge the same tree)")  # fmt: skip
    return lines


def _importable(module: str) -> bool:
    """Whether ``module`` imports (an optional library is installed and works)."""
    import importlib

    try:
        importlib.import_module(module)
    except ImportError:
        return False
    return True


def _open_staging(command: str, out: Path):
    """The staging folder of a build into ``out`` (kinegami.export.publish): the files go there
    and are published as one transaction; a note says when a build killed earlier was
    recovered first."""
    from kinegami.export.publish import open_staging

    try:
        staging = open_staging(out)
    except OSError as error:
        if isinstance(error, KinegamiError):
            raise
        raise CommandError(f"-o: cannot write in {str(out)!r}: {error.strerror}") from None
    if staging.note:
        _note(command, staging.note)
    return staging


def _takeoff_summary(fabrication, info) -> list[str]:
    """The build summary's lines on folded take-offs (none for printed connectors only)."""
    if not fabrication.takeoffs and not fabrication.notes:
        return []
    from kinegami.clearance import Lengths

    lengths = Lengths(fabrication.tree.r, info.units)
    lines = [f"  take-offs: {len(fabrication.takeoffs)} (folded)"]
    for t in fabrication.takeoffs:
        lines.append(
            f"    take-off {t.name}: joint {t.child} leaves joint {t.trunk}'s link through face "
            f"{t.face}, {lengths.mm(t.arc)} from joint {t.joint}: hole {t.name} in sheet "
            f"{t.sheet}, sheet {t.branch_sheet} starts with its skirt ({t.tabs} glue tabs); "
            f"new link {lengths.mm(t.link.length)}"
        )
    if fabrication.takeoffs:
        overlap = fabrication.overlap(names=_joint_names(fabrication.tree))
        margin = f"the margin {lengths.exact(fabrication.tree.margin)}"
        body = f"clear with {margin}" if overlap is None else (
            f"{'self-intersects, ' if overlap.clearance < 0.0 else ''}parts closer than "
            f"{margin}: {lengths(overlap.clearance)}, between {overlap.first} and "
            f"{overlap.second}"
        )  # fmt: skip
        lines.append(f"    folded body with the take-off links: {_printable(body)}")
    lines += [f"  note: {_printable(note)}" for note in fabrication.notes]
    return lines


def _build_tree(args: argparse.Namespace, tree, info, stem: str, out: Path) -> int:
    """``kinegami build`` of a tree: a sheet per leaf, the junction connectors and the whole
    tree (kinegami.export.tree_build), published as one transaction."""
    lines = _write_tree_build(args.command, args.design, tree, info, stem, out, args.formats,
                              args.junctions)  # fmt: skip
    print("\n".join(lines))
    return 0


def _write_tree_build(command: str, label: str, tree, info, stem: str, out: Path,
                      formats_text: str | None, junctions: str | None,
                      extra=()) -> list[str]:  # fmt: skip
    """Write a tree's outputs (``formats_text``: ``--formats``; ``junctions``: ``--junctions``)
    and ``extra`` ((file name, writer(path)) pairs) into ``out`` as one transaction: a sheet per
    leaf, the junction connectors and the whole tree (kinegami.export.tree_build). The summary
    lines, with the files written."""
    from kinegami.design.reader import carry_origin
    from kinegami.errors import InvalidParameterError
    from kinegami.export.tree_build import FORMAT_LIBRARIES, write_tree_files
    from kinegami.fabrication.sheets import fabricate, fit_junctions
    from kinegami.fabrication.takeoffs import JUNCTION_KINDS

    kind = "connector" if junctions is None else junctions
    if kind not in JUNCTION_KINDS:
        raise CommandError(f"--junctions: unknown kind {shown(kind)}; known: "
                           f"{', '.join(JUNCTION_KINDS)}")  # fmt: skip
    formats = _parse_tree_formats(formats_text)
    if formats_text is None:  # the defaults: leave out what a missing optional library stops
        needs = dict(FORMAT_LIBRARIES)
        if kind == "takeoff":  # folded take-offs print no connector
            del needs["junctions"]
        for fmt, (modules, extra_name) in needs.items():
            missing = [m for m in modules if fmt in formats and not _importable(m)]
            if missing:
                formats.remove(fmt)
                _note(command, f"{fmt} not written: it needs {missing[0]} "
                               f"(pip install 'kinegami[{extra_name}]')")  # fmt: skip
    try:
        fitted, moves, fabrication = tree, [], None
        if kind != "connector":  # take-offs need no room for sockets: try the tree as it is
            try:
                fabrication = fabricate(tree, twistPortion=info.twistPortion, junction=kind)
            except InvalidParameterError:
                if kind == "takeoff":
                    raise
        if fabrication is None:  # slide the children whose socket does not fit
            fitted, moves = fit_junctions(tree)
            carry_origin(tree, fitted)  # the joint names
            fabrication = fabricate(fitted, twistPortion=info.twistPortion, junction=kind)
    except KinegamiError as error:
        raise CommandError(f"{label}: {error}") from None
    written = _clearance(tree) if moves else None
    lines = _tree_summary(fitted, info, label, fabrication, moves, written)
    lines += _takeoff_summary(fabrication, info)
    layouts = None
    if info.bed is not None:
        from kinegami.errors import BedTooSmallError
        from kinegami.export.tree_build import sheet_layouts

        try:
            layouts = sheet_layouts(fabrication, info.bed, info.units, info.name or stem)
        except BedTooSmallError as error:
            raise _bed_failure(label, error) from None
        lines += _bed_summary(layouts, info, [sheet.index for sheet in fabrication.sheets])
    from kinegami.fabrication.bom import bill_of_materials

    bom = bill_of_materials([sheet.pattern for sheet in fabrication.sheets],
                            UNITS_IN_MM[info.units], material=info.material, layouts=layouts,
                            fabrication=fabrication)  # fmt: skip
    lines += _bom_lines(bom)
    report = _clearance(fitted)
    if not report.ok:
        _warn(command, _overlap_warning(report, info, label))
    staging = _open_staging(command, out)
    try:
        try:
            data = [f for f in formats if f not in ("png", "guide")]
            write_tree_files(
                fabrication,
                staging.new,
                stem,
                data,
                units=info.units,
                twistPortion=info.twistPortion,
                names=_joint_names(fitted),
                layouts=layouts,
            )
            if "png" in formats:
                _write_tree_pictures(fabrication, staging.new, stem, info.units)
            if "guide" in formats:
                _write_tree_guide(fabrication, staging.new / f"{stem}_guide.pdf", info, stem,
                                  bom, layouts, _joint_names(fitted))  # fmt: skip
            for name, write in extra:
                write(staging.new / name)
        except KinegamiError as error:
            raise CommandError(f"{label}: {error}") from None
        except OSError as error:
            raise CommandError(f"cannot write {str(out)!r}: {error.strerror or error}") from None
        stale = [name for fmt in ("dxf", "svg") if fmt in formats
                 for sheet in fabrication.sheets
                 for name in _stale_bed_files(out, f"{stem}_sheet_{sheet.index}", fmt,
                                              staging.new)]  # fmt: skip
        written = staging.publish(remove=stale)
    finally:
        staging.close()
    lines.append("  files written:")
    lines.extend(f"    {path}{os.sep if path.is_dir() else ''}" for path in written)
    return lines


def cmd_build(args: argparse.Namespace) -> int:
    stem = _plain_stem(args.name if args.name is not None else Path(args.design).stem)
    out = Path(args.output)
    _check_output(out)
    chain, info = _load(args.design)
    _margin(args, chain)
    info = _fabrication(args, chain, info)
    if _is_tree(chain):
        return _build_tree(args, chain, info, stem, out)
    if args.junctions is not None:
        _note(args.command, f"--junctions {args.junctions} ignored: {args.design} is a chain "
                            "(junctions join the sheets of a tree)")  # fmt: skip
    formats = _parse_formats(",".join(DEFAULT_FORMATS) if args.formats is None else args.formats)
    lines = _write_chain_build(args.command, args.design, BuildJob(chain, info), stem, out,
                               formats)  # fmt: skip
    print("\n".join(lines))
    return 0


def _write_chain_build(command: str, label: str, job: BuildJob, stem: str, out: Path, formats,
                       extra=()) -> list[str]:  # fmt: skip
    """Write a chain's outputs ``formats`` (and ``extra``: (file name, writer(path)) pairs)
    into ``out`` as one transaction; the summary lines, with the files written."""
    # a large chain's pictures are drawn by a second process meanwhile (the longest output)
    pictures = BackgroundPictures(job) if BackgroundPictures.wanted(job, formats) else None
    try:
        _check_pattern(job)
        lines = _summary(job, label)
        layout = None
        if job.info.bed is not None:
            from kinegami.errors import BedTooSmallError
            from kinegami.fabrication.beds import lay_out

            try:
                layout = lay_out(job.pattern, job.info.bed, unit=UNITS_IN_MM[job.info.units],
                                 name=job.info.name or stem)  # fmt: skip
            except BedTooSmallError as error:
                raise _bed_failure(label, error) from None
            lines += _bed_summary([layout], job.info)
        bom = _chain_bom(job, layout)
        lines += _bom_lines(bom)
        if not job.clearance.ok:
            _warn(command, _overlap_warning(job.clearance, job.info, label))
        # write everything into a hidden staging folder in the target, then publish it as one
        # transaction (kinegami.export.publish): a failure or an interrupt leaves the folder as
        # it was, and a build killed earlier is recovered first
        staging = _open_staging(command, out)
        try:
            for fmt in formats:
                paths = [staging.new / f"{stem}{suffix}" for suffix in fmt.suffixes]
                try:
                    if pictures is not None and fmt.name == "png":
                        for path, data in zip(paths, pictures.result(), strict=True):
                            path.write_bytes(data)
                    elif layout is not None and fmt.name in ("dxf", "svg"):
                        from kinegami.export.beds import bed_files

                        for name, text in bed_files(layout, stem, f".{fmt.name}").items():
                            (staging.new / name).write_text(text, encoding="utf-8")
                    elif fmt.name == "guide":
                        _write_guide(job, paths, layout, bom)
                    else:
                        fmt.write(job, paths)
                except KinegamiError as error:
                    raise CommandError(f"{label}: {fmt.name} export: {error}") from None
                except OSError as error:
                    raise CommandError(
                        f"{fmt.name} export: cannot write {str(out)!r}: "
                        f"{error.strerror or error}"
                    ) from None
            for name, write in extra:
                try:
                    write(staging.new / name)
                except OSError as error:
                    raise CommandError(f"cannot write {name} in {str(out)!r}: "
                                       f"{error.strerror or error}") from None  # fmt: skip
            stale = [name for fmt in formats if fmt.name in ("dxf", "svg")
                     for name in _stale_bed_files(out, stem, fmt.name, staging.new)]
            written = staging.publish(remove=stale)  # all or nothing, whatever interrupts it
        finally:
            staging.close()
    finally:
        if pictures is not None:
            pictures.stop()
    lines.append("  files written:")
    lines.extend(f"    {path}{os.sep if path.is_dir() else ''}" for path in written)
    return lines


def cmd_show(args: argparse.Namespace) -> int:
    import matplotlib.pyplot as plt

    from kinegami.viz._backend import backend_is_interactive

    chain, info = _load(args.design)
    if not backend_is_interactive():
        raise CommandError(
            "cannot open a window: matplotlib has no interactive backend here (no display?); "
            "use 'kinegami build DESIGN -o DIR' to write pictures instead"
        )
    chain.show(block=False, units=info.units)
    if args.pattern:
        chain.creasePattern(twistPortion=info.twistPortion).show(units=info.units)
    plt.show()
    return 0


def cmd_new(args: argparse.Namespace) -> int:
    from kinegami.design.starter import DesignFileExistsError, write_starter_design

    if args.task:
        return _new_task(args)
    if args.tree:
        raise CommandError("--tree goes with --task: 'kinegami new --task --tree FILE' writes a "
                           "starter tree task (there is no starter tree design)")  # fmt: skip
    try:
        path = write_starter_design(args.design, overwrite=args.force)
    except DesignFileExistsError:
        raise CommandError(
            f"{_printable(repr(args.design))} exists already and was left as it is; "
            "--force replaces it"
        ) from None
    name = _printable(str(path))
    print(
        f"wrote {name}: a starter design (a start tip, a revolute joint, a prismatic joint, an "
        "end tip; units mm). Change it, then:"
    )
    print(f"  kinegami validate --build {name}")
    print(f"  kinegami build {name} -o out/")
    return 0


def _new_task(args: argparse.Namespace) -> int:
    """``kinegami new --task [--tree] FILE``: the starter task (a chain's, or with --tree a
    tree's), written atomically (kept if it exists, unless --force)."""
    import json

    from kinegami._atomic import write_atomic
    from kinegami.design.task import starter_task

    path = Path(args.design)
    if path.suffix.lower() != ".json":
        raise CommandError(
            f"a task file name must end in .json, got {_printable(repr(args.design))}"
        )
    if path.exists() and not args.force:
        raise CommandError(
            f"{_printable(repr(args.design))} exists already and was left as it is; "
            "--force replaces it"
        )
    if path.is_dir():
        raise CommandError(f"{_printable(repr(args.design))} is a directory, not a file name")
    write_atomic(path, json.dumps(starter_task(tree=args.tree), indent=2) + "\n")
    name = _printable(str(path))
    if args.tree:
        print(f"wrote {name}: a starter tree task (a hand of two three-joint fingers, each "
              "touching two points, the k-th points of both at once; units mm). Change it, "
              "then:")  # fmt: skip
    else:
        print(f"wrote {name}: a starter task (a four-joint arm that must touch four points "
              "above a table; units mm). Change it, then:")  # fmt: skip
    print(f"  kinegami design {name} -o out/")
    return 0


# --- design for a task --------------------------------------------------------------------------
#: Exit code of ``design`` when no design of the budget reaches every target.
INFEASIBLE = 3


def cmd_design(args: argparse.Namespace) -> int:

    from kinegami.design.reader import DesignInfo
    from kinegami.design.task import read_task
    from kinegami.design.writer import design_to_dict
    from kinegami.errors import InfeasibleTaskError
    from kinegami.optimize import design_for

    stem = _plain_stem(args.name if args.name is not None else Path(args.task).stem)
    out = Path(args.output)
    _check_output(out)
    task = read_task(args.task)
    options = task.options()
    if args.seed is not None:
        options["seed"] = _integer("--seed", args.seed, 0)
    targets, joints = list(task.targets), task.joints
    if task.is_tree:  # one list of targets and one joint string per leaf
        targets, joints = [list(leaf) for leaf in task.targets], list(task.joints)
    try:
        found = design_for(targets, joints, return_answers=True, progress=None, **options)
    except InfeasibleTaskError as error:
        kind = "infeasible" if error.proven else "no design found"
        _fail(args.command, f"{args.task}: {kind}: {error}")
        return INFEASIBLE
    if task.is_tree:
        return _write_tree_design(args, task, found[0], found[1], stem, out)
    chain, answers = found[0], found[1]
    paths = found[2] if len(found) > 2 else None
    info = DesignInfo(name=task.name, description=task.description, units=task.units,
                      twistPortion=0.2, file=None, structure="chain",
                      task=task.document)  # fmt: skip
    job = BuildJob(chain, info)
    report = _task_report(chain, task, answers, paths)
    document = design_to_dict(chain, name=task.name, description=task.description,
                              units=task.units, task=task.document)  # fmt: skip
    extra = _task_files(stem, document, report,
                        lambda path: _task_picture(chain, answers, task, path))  # fmt: skip
    formats = _parse_formats(",".join(DEFAULT_FORMATS) if args.formats is None else args.formats)
    lines = _write_chain_build(args.command, args.task, job, stem, out, formats, extra)
    print("\n".join([*report[0], *lines]))
    return 0


def _task_files(stem: str, document: dict, report: tuple, picture) -> list:
    """What ``kinegami design`` writes beside a build: ``(name, write(path))`` for the design
    file (with its task), the report as text and JSON, and the picture (``picture(path)``)."""
    import json

    from kinegami.design.writer import dumps_design

    text = "\n".join(report[0]) + "\n"
    data = json.dumps(report[1], indent=2) + "\n"
    return [
        (f"{stem}.json", lambda path: path.write_text(dumps_design(document), "utf-8")),
        (f"{stem}_task.txt", lambda path: path.write_text(text, "utf-8")),
        (f"{stem}_task.json", lambda path: path.write_text(data, "utf-8")),
        (f"{stem}_task.png", picture),
    ]


def _write_tree_design(args: argparse.Namespace, task, tree, answers, stem: str, out: Path
                       ) -> int:  # fmt: skip
    """``kinegami design`` of a tree task: the tree's design file (with its task), its build
    (as ``kinegami build`` writes a tree) and the report, published as one transaction."""

    from kinegami.design.reader import DesignInfo
    from kinegami.design.writer import design_to_dict

    info = DesignInfo(name=task.name, description=task.description, units=task.units,
                      twistPortion=0.2, file=None, structure="tree",
                      task=task.document)  # fmt: skip
    tips = _leaf_tips(tree, task, answers)
    report = _tree_task_report(tree, task, answers, tips)
    document = design_to_dict(tree, name=task.name, description=task.description,
                              units=task.units, task=task.document)  # fmt: skip
    extra = _task_files(stem, document, report,
                        lambda path: _task_picture(tree, answers, task, path))  # fmt: skip
    lines = _write_tree_build(args.command, args.task, tree, info, stem, out, args.formats,
                              None, extra)  # fmt: skip
    print("\n".join([*report[0], *lines]))
    return 0


def _leaf_tips(tree, task, answers) -> list[int]:
    """The tip joint of each leaf of a tree task (the task's order): the leaf tips of ``tree``
    matched to the task's leaves by where they are at the answers' states (world frame)."""
    import numpy as np
    from scipy.optimize import linear_sum_assignment

    from kinegami.reach import kinematics

    compiled = kinematics(tree)  # every leaf tip, in joint-index order
    Q, _ = compiled.configurations([list(answer.states) for answer in answers])
    places = compiled.tip_poses(Q)[..., :3, 3]  # (grasps, tips, 3)
    wanted = np.array([[target.position for target in leaf] for leaf in task.targets])
    if places.shape[1] != wanted.shape[0]:
        raise CommandError(f"{task.name or 'task'}: the designed tree has {places.shape[1]} "
                           f"leaves, the task {wanted.shape[0]}")  # fmt: skip
    cost = np.linalg.norm(places.transpose(1, 0, 2)[None] - wanted[:, None], axis=-1).sum(-1)
    _, columns = linear_sum_assignment(cost)
    return [compiled.tips[j] for j in columns]


def _target_errors(pose: np.ndarray, target) -> tuple[float, float]:
    """(position error, angle error in rad) of a tip at ``pose`` (4x4, world) for a
    :class:`kinegami.reach.Target`: the distance, and the angle between the tip's z and an axis
    target's axis or between the tip's and a pose target's orientations (0 for a position)."""
    import numpy as np

    position = float(np.linalg.norm(pose[:3, 3] - target.position))
    if target.axis is not None:
        z = pose[:3, 2]
        return position, float(np.arctan2(np.linalg.norm(np.cross(z, target.axis)),
                                          np.dot(z, target.axis)))  # fmt: skip
    if target.rotation is not None:
        E = pose[:3, :3].T @ target.rotation
        vee = np.array([E[2, 1] - E[1, 2], E[0, 2] - E[2, 0], E[1, 0] - E[0, 1]])
        return position, float(np.arctan2(np.linalg.norm(vee) / 2, (np.trace(E) - 1) / 2))
    return position, 0.0


def _target_json(target, name) -> dict:
    """A target of a task report: its name, kind, position and axis or rotation (world)."""
    out = {"name": name, "kind": target.kind, "position": target.position.tolist()}
    if target.axis is not None:
        out["axis"] = target.axis.tolist()
    if target.rotation is not None:
        out["rotation"] = target.rotation.tolist()
    return out


def _tree_task_report(tree, task, answers, tips: list[int]) -> tuple[list[str], dict]:
    """The report of a tree designed for a task: its leaves (joint strings, tip joints), then
    per grasp its states and clearance and, per leaf, the target and the tip's errors there
    (lines and a JSON-ready dict)."""
    from kinegami.optimize import tube_length
    from kinegami.reach import kinematics

    units = task.units
    compiled = kinematics(tree, tip=tips)  # the tips in joint-index order
    order = [compiled.tips.index(t) for t in tips]
    Q, _ = compiled.configurations([list(answer.states) for answer in answers])
    poses = compiled.tip_poses(Q)[:, order]  # (grasps, leaves, 4, 4), the task's leaf order
    lines = [f"{task.name or 'task'}: designed (a tree of {task.leaves} leaves, "
             f"{len(tree.Joints)} joints: {', '.join(type(j).__name__ for j in tree.Joints)}; "
             f"tube {tube_length(tree):.6g} {units})"]  # fmt: skip
    leaves = []
    for i, (types, tip) in enumerate(zip(task.joints, tips, strict=True)):
        lines.append(f"  leaf {i}: joints {types}, tip joint {tip}")
        leaves.append({"leaf": i, "joints": types, "tip": int(tip)})
    grasps = []
    for k, answer in enumerate(answers):
        state = "reached" if answer.ok else f"not reached: {answer.reason}"
        lines.append(f"  grasp {k}: {state}, clearance {answer.clearance:.6g} {units}")
        rows = []
        for i, leaf in enumerate(task.targets):
            name = task.document["targets"][i][k].get("name")
            target = leaf[k]
            position, angle = _target_errors(poses[k, i], target)
            where = ", ".join(f"{v:.6g}" for v in target.position)
            label = f"target ({name}) " if name else "target "
            lines.append(f"    leaf {i}: {label}[{where}], position error {position:.3g} "
                         f"{units}, angle error {angle:.3g} rad")  # fmt: skip
            rows.append({"leaf": i, "tip": int(tips[i]), "target": _target_json(target, name),
                         "position_error": position, "angle_error": angle})  # fmt: skip
        lines.append("    states: " + ", ".join(f"{s:.6g}" for s in answer.states))
        grasps.append({"grasp": k, "ok": bool(answer.ok), "reason": answer.reason,
                       "states": list(answer.states), "clearance": answer.clearance,
                       "position_error": answer.position_error,
                       "angle_error": answer.angle_error, "leaves": rows})  # fmt: skip
    summary = {"format": "kinegami-task-report", "version": 1, "name": task.name,
               "units": units, "structure": "tree",
               "joints": [type(j).__name__ for j in tree.Joints],
               "tube_length": tube_length(tree), "leaves": leaves, "grasps": grasps}  # fmt: skip
    return lines, summary


def _task_report(chain, task, answers, paths=None) -> tuple[list[str], dict]:
    """The report of a designed robot: per target its states, errors and clearance (lines and a
    JSON-ready dict)."""
    from kinegami.optimize import tube_length

    units = task.units
    lines = [f"{task.name or 'task'}: designed ({len(chain.Joints)} joints: "
             f"{', '.join(type(j).__name__ for j in chain.Joints)}; tube "
             f"{tube_length(chain):.6g} {units})"]  # fmt: skip
    rows = []
    for k, answer in enumerate(answers):
        name = task.document["targets"][k].get("name")
        label = f"target {k}" + (f" ({name})" if name else "")
        lines.append(f"  {label}: reached, position error {answer.position_error:.3g} {units}, "
                     f"angle error {answer.angle_error:.3g} rad, clearance "
                     f"{answer.clearance:.6g} {units}")  # fmt: skip
        lines.append("    states: " + ", ".join(f"{s:.6g}" for s in answer.states))
        rows.append({"target": k, "name": name, "ok": bool(answer.ok),
                     "states": list(answer.states), "position_error": answer.position_error,
                     "angle_error": answer.angle_error, "clearance": answer.clearance})  # fmt: skip
    summary = {"format": "kinegami-task-report", "version": 1, "name": task.name,
               "units": units, "joints": [type(j).__name__ for j in chain.Joints],
               "tube_length": tube_length(chain), "targets": rows}  # fmt: skip
    if paths is not None:
        summary["moves"] = []
        for k, configurations in enumerate(paths):
            lines.append(f"  move {k} -> {k + 1}: clear along the way (certified; "
                         f"{len(configurations)} configurations measured)")  # fmt: skip
            summary["moves"].append({"from": k, "to": k + 1, "clear": True,
                                     "configurations": configurations.tolist()})  # fmt: skip
    return lines, summary


def _task_picture(chain, answers, task, path: Path) -> None:
    """One sheet of small multiples: the robot at every target (the target a red point); a
    tree at every grasp (every leaf's target a red point)."""
    import copy
    import math

    import matplotlib
    import numpy as np

    matplotlib.use("Agg", force=False)
    import matplotlib.pyplot as plt

    count = len(answers)
    columns = min(4, count)
    rows = math.ceil(count / columns)
    fig = plt.figure(figsize=(3.2 * columns, 3.2 * rows))
    try:
        for k, answer in enumerate(answers):
            ax = fig.add_subplot(rows, columns, k + 1, projection="3d")
            posed = copy.copy(chain)
            posed.setJointStates(list(answer.states))
            posed.show(ax=ax, showJointPoses=False, showGlobalFrame=False, units=task.units)
            leaves = task.targets if task.is_tree else [task.targets]
            p = np.array([leaf[k].position for leaf in leaves])
            ax.scatter(p[:, 0], p[:, 1], p[:, 2], color="red", s=30, depthshade=False)
            ax.set_title(f"{'grasp' if task.is_tree else 'target'} {k}", fontsize=9)
        fig.tight_layout()
        fig.savefig(path, dpi=100)
    finally:
        plt.close(fig)


def cmd_edit(args: argparse.Namespace) -> int:
    import time

    try:
        port = int(args.port)
    except ValueError:
        port = -1
    if not 0 <= port <= 65535:
        raise CommandError(f"--port must be an integer in [0, 65535], got {_printable(args.port)}")
    from kinegami.editor.server import EditorServer, is_local

    server = EditorServer(args.design, host=args.host, port=port, recover=args.recover)
    try:
        what = _printable(str(args.design)) if args.design else "the starter design"
        if not is_local(args.host):
            saved = f"save {what}" if args.design else "download designs"
            _warn("edit", f"listening on {_printable(args.host)}: anyone who can reach port "
                          f"{server.port} of this machine and has the token can open the editor, "
                          f"edit and {saved} (plain HTTP: the token crosses the network "
                          "unencrypted); from another machine, open the address with this "
                          "machine's name in place of its host")  # fmt: skip
        print(f"kinegami edit: editing {what} at {server.url} (each tab edits its own copy; "
              "Ctrl-C stops)", flush=True)  # fmt: skip
        recovery = server.recovery
        if recovery is not None:
            where = _printable(str(recovery.path))
            if args.recover:
                print(f"kinegami edit: each tab starts from the autosave {where} "
                      f"({recovery.describe()})", flush=True)  # fmt: skip
            else:
                print(
                    f"kinegami edit: found the autosave {where} ({recovery.describe()}); "
                    "the editor offers it back (or start with --recover)",
                    flush=True,
                )
        elif args.recover:
            _note("edit", "--recover: there is no autosave newer than the design; starting "
                          "from the design")  # fmt: skip
        while True:
            time.sleep(3600)
    finally:
        server.stop()


def cmd_validate(args: argparse.Namespace) -> int:
    from kinegami.design import DesignInfo, audit_design, read_design

    report = audit_design(args.design)
    if not report.ok:  # every problem, one line each (the first is validate_design's)
        for problem in report.problems[:-1]:
            _fail(args.command, str(problem))
        raise CommandError(str(report.problems[-1]))
    data = read_design(args.design)
    tree = DesignInfo.of(data).structure == "tree"
    if args.build:
        from kinegami.design import joint_table

        chain, info = _load(args.design)
        if tree:  # a crease pattern per sheet, and the junctions
            from kinegami.fabrication.sheets import fabricate, fit_junctions

            try:
                fitted, moves = fit_junctions(chain)
                made = fabricate(fitted, twistPortion=info.twistPortion)
            except KinegamiError as error:
                raise CommandError(f"{args.design}: {error}") from None
            slid = f"; {len(moves)} joint(s) slid so that their sockets fit" if moves else ""
            print(
                f"{args.design}: valid; builds a tree of {len(chain.Joints)} joints, "
                f"{len(made.sheets)} sheets and {len(made.junctions)} junction(s){slid}"
            )
        else:
            _check_pattern(BuildJob(chain, info))
            print(f"{args.design}: valid; builds {len(chain.Joints)} joints and the crease pattern")
        print("  index  joint (the indices edits and states use)")
        for index, kind, name in joint_table(chain, data):
            label = f" {_printable(name)!r}" if name else ""
            parent = f", parent {chain.Parents[index]}" if tree and index > 0 else ""
            print(f"  {index:>5}  {kind}{label}{parent}")
        return 0
    if "joints" in data:
        what = f"{len(data['joints'])} joints" + (", a tree" if tree else "")
    else:
        what = f"a DH table of {len(data['dh']['rows'])} rows"
    print(f"{args.design}: valid ({what}; placement not checked, use --build)")
    return 0


def _overlap_warning(report, info, design: str) -> str:
    """The warning of a build whose design is not clear at its states: its verdict."""
    return (
        f"{design} at its states: {report.verdict(info.units)} (the files are written all the "
        "same; 'kinegami check' lists every pair)"
    )


def _integer(option: str, text: str, low: int, high: int | None = None, why: str = "") -> int:
    """The integer value of an option given as ``text``, within [low, high], or a
    CommandError naming the option, the value, the valid range and ``why`` (a limit's reason,
    docs/limits.md)."""
    import re

    from kinegami.validation import shorten

    valid = f"an integer >= {low}" if high is None else f"an integer in [{low}, {high}]"
    if why:
        valid += f" ({why})"
    if not re.fullmatch(rf"[+-]?[0-9]{{1,{MAX_INTEGER_DIGITS}}}", text.strip()):
        raise CommandError(f"{option}: must be {valid}, got {shorten(text)!r}")
    value = int(text)
    if value < low or (high is not None and value > high):
        raise CommandError(f"{option}: must be {valid}, got {value}")
    return value


def _pair_json(pair) -> dict:
    return {
        "first": pair.first,
        "second": pair.second,
        "clearance": pair.clearance,
        "points": [list(point) for point in pair.points],
    }


def _check_json(chain, info, design, report, motion, seed) -> dict:
    from kinegami.clearance.reports import moving_joints
    from kinegami.design.reader import origin_of
    from kinegami.geometry.screws import REVOLUTE

    origin = origin_of(chain)
    data = {
        "design": design,
        "name": info.name,
        "units": info.units,
        "r": chain.r,
        "ok": report.ok,
        "margin": report.margin,
        "material": None if info.material is None else {
            "name": info.material.name, "thickness": info.material.thickness},
        "verdict": report.verdict(info.units),
        "min_clearance": report.min_clearance if report.closest is not None else None,
        "closest": None if report.closest is None else _pair_json(report.closest),
        "pairs": [_pair_json(pair) for pair in report.pairs],
        "unlisted": report.unlisted,
        "states": list(report.states),
        "motion": None,
    }
    if motion is not None:
        intervals = []
        for i in moving_joints(chain.Joints):
            joint = chain.Joints[i]
            free = motion.free_intervals[i]
            intervals.append({
                "joint": i,
                "type": type(joint).__name__,
                "name": None if origin is None else origin.names[i],
                "kind": "revolute" if joint.motion == REVOLUTE else "prismatic",
                "state": motion.states[i],
                "range": list(joint.stateRange()),
                "free": None if free is None else list(free),
            })  # fmt: skip
        data["motion"] = {
            "samples": motion.samples,
            "seed": seed,
            "colliding": motion.colliding,
            "colliding_fraction": motion.colliding_fraction,
            "worst_pairs": [dict(_pair_json(pair), count=count)
                            for pair, count in motion.worst_pairs],
            "free_intervals": intervals,
        }  # fmt: skip
    return data


def _check_lines(chain, info, design, report, motion, seed) -> list[str]:
    """What ``check`` prints: the report's summary (ClearanceReport.summary, at most
    LISTED_PAIRS pairs) and the sweep's (SweepReport.summary)."""
    title = f"{_printable(info.name)} ({design})" if info.name else design
    lines = report.summary(info.units, title=title, listed=LISTED_PAIRS)
    lines[1:1] = _material_lines(chain, info)
    if not report.ok and report.pair_count > LISTED_PAIRS:  # the last line: "... and N more"
        lines[-1] += " (--json lists them all)" if not report.unlisted else \
            f" (--json lists the closest {len(report.pairs):,})"  # fmt: skip
    if motion is not None:
        lines += motion.summary(chain, info.units, names=_joint_names(chain), seed=seed)
    return [_printable(line) for line in lines]


def cmd_check(args: argparse.Namespace) -> int:
    import json

    from kinegami.clearance import sweep

    samples = None if args.motion is None else _integer(
        "--motion", args.motion, 1, MAX_MOTION,
        "each is a clearance test of the whole chain; kinegami.limits.MAX_SAMPLES",
    )  # fmt: skip
    seed = _integer("--seed", args.seed, 0)
    chain, info = _load(args.design)
    if samples is not None:
        from kinegami.validation import check_samples

        samples = check_samples("--motion", samples, len(chain.Joints))
    _margin(args, chain)
    info = _fabrication(args, chain, info)
    names = _joint_names(chain)
    report = _clearance(chain)
    motion = None if samples is None else sweep(chain, samples, seed, names=names)
    if args.json:
        data = _check_json(chain, info, args.design, report, motion, seed)
        print(json.dumps(data, indent=2, allow_nan=False))
    else:
        print("\n".join(_check_lines(chain, info, args.design, report, motion, seed)))
    return 0 if report.ok else SELF_INTERSECTS


#: Exit code of ``compact`` when no clear design was found (kinegami.optimize.CompactionError).
COMPACTION_FAILED = 3


def _seconds(option: str, text: str) -> float:
    """A positive, finite number of seconds given as ``text``, or a CommandError."""
    import math

    from kinegami.validation import shorten

    try:
        value = float(text)
    except ValueError:
        value = math.nan
    if not (math.isfinite(value) and value > 0):
        raise CommandError(f"{option}: must be a number of seconds > 0, got {shorten(text)!r}")
    return value


def _check_design_output(out: Path, design: str, force: bool) -> None:
    """Fail before the (long) compaction when ``-o`` cannot be written: not a .json name, a
    folder or a special file, a file or an unwritable folder on the way, or the design itself
    without --force."""
    shown_out = shown_path(out)
    if out.suffix.lower() != ".json":
        raise CommandError(f"-o: {shown_out}: a design file name must end in .json")
    try:
        info = os.stat(out)
    except (FileNotFoundError, NotADirectoryError):  # a file on the way: reported below
        info = None
    except OSError as error:
        raise CommandError(f"-o: cannot write {shown_out}: {error.strerror or error}") from None
    if info is not None:
        if stat.S_ISDIR(info.st_mode):
            raise CommandError(f"-o: {shown_out} is a folder; give a file name")
        if not stat.S_ISREG(info.st_mode):
            raise CommandError(f"-o: {shown_out} exists and is not a regular file")
        try:
            same = os.path.samefile(out, design)
        except OSError:
            same = False
        if same and not force:
            raise CommandError(
                f"-o: {shown_out} is the design itself; --force replaces it (atomically) with "
                "the compacted design"
            )
    folder = out.parent
    while not folder.exists() and folder != folder.parent:
        folder = folder.parent  # missing folders are created when writing
    if not folder.is_dir():
        raise CommandError(f"-o: {shown_path(folder)} is not a folder")
    if not os.access(folder, os.W_OK | os.X_OK):
        raise CommandError(f"-o: cannot write in {shown_path(folder)}: permission denied")


def _compaction_lines(job: BuildJob, before: BuildJob | None = None) -> list[str]:
    """The joints, tube length, sheet and clearance of a design (``before``: the input, for
    the change in length)."""
    from collections import Counter

    from kinegami.clearance import Lengths
    from kinegami.optimize import tube_length

    chain = job.chain
    lengths = Lengths(chain.r, job.info.units)
    counts = Counter(type(joint).__name__ for joint in chain.Joints)
    kinds = ", ".join(f"{count} {name}" for name, count in counts.items())
    if _is_tree(chain):
        from kinegami.fabrication.sheets import junction_problems

        problems = junction_problems(chain)
        leaves = sum(1 for c in chain.Children if not c)
        sheet = f"{leaves} sheets (one per leaf), " + (
            "every junction's sockets fit" if not problems
            else f"{len(problems)} socket(s) do not fit ({problems[0][1]})"
        )  # fmt: skip
    else:
        sheet = _sheet_size(job)
    tube = f"{lengths(tube_length(chain))}"
    if before is not None:
        old, new = tube_length(before.chain), tube_length(chain)
        change = 100.0 * (old - new) / old
        tube += f", {change:.1f}% shorter" if change >= 0 else f", {-change:.1f}% longer"
    return [
        f"    joints: {len(chain.Joints)} ({kinds})",
        f"    total tube length: {tube}",
        f"    sheet{'s' if _is_tree(chain) else ''}: {sheet}",
        "  " + _verdict_line(job.clearance, job.info),
    ]


def cmd_compact(args: argparse.Namespace) -> int:
    from kinegami.clearance import Lengths
    from kinegami.design import save_design
    from kinegami.design.reader import carry_origin
    from kinegami.optimize import CompactionError, compact

    seed = _integer("--seed", args.seed, 0)
    limit = None if args.time_limit is None else _seconds("--time-limit", args.time_limit)
    out = Path(args.output)
    _check_design_output(out, args.design, args.force)
    chain, info = _load(args.design)
    _margin(args, chain)
    info = _fabrication(args, chain, info)
    before = BuildJob(chain, info)
    if not _is_tree(chain):  # a tree's sheets are checked by build
        _check_pattern(before)
    task = None
    if info.task is not None:  # the task it was made for: kept
        from kinegami.design.task import task_from_dict

        task = task_from_dict(info.task, args.design, where=("task",))
        if args.motion:
            _note(args.command, "--motion ignored: the design's task is kept instead (every "
                                "target still reached, clear)")  # fmt: skip
    try:
        if task is not None:
            # a tree's task: one target list per leaf, the leaves in the order of their tip
            # joints (as kinegami design writes the tree), every grasp kept
            targets = [list(leaf) for leaf in task.targets] if task.is_tree \
                else list(task.targets)  # fmt: skip
            compacted = compact(chain, seed=seed, time_limit=limit, targets=targets,
                                keep_out=task.keep_out)  # fmt: skip
        else:
            compacted = compact(chain, seed=seed, motion=args.motion, time_limit=limit)
    except CompactionError as error:
        _fail(args.command, f"{args.design}: {error}")
        return COMPACTION_FAILED
    compacted.requireClearance = chain.requireClearance
    carry_origin(chain, compacted)  # the joint names, for the summary and the file
    after = BuildJob(compacted, info)
    if not _is_tree(compacted):
        _check_pattern(after)
    title = f"{_printable(info.name)} ({args.design})" if info.name else args.design
    kept = ", task kept" if task is not None else ", motion kept" if args.motion else ""
    lines = [
        f"{title}: compacted (seed {seed}{kept}, margin "
        f"{Lengths(chain.r, info.units).exact(chain.margin)})",
        *_material_lines(chain, info),
        "  before:",
        *_compaction_lines(before),
        "  after:",
        *_compaction_lines(after, before),
    ]
    written = save_design(
        compacted, out, name=info.name, description=info.description, units=info.units,
        twistPortion=info.twistPortion, task=info.task, material=info.material, bed=info.bed,
    )  # fmt: skip
    lines.append(f"  written: {written}")
    print("\n".join(_printable(line) for line in lines))
    return 0


# --- reach ---------------------------------------------------------------------------------------
#: Exit code of ``reach`` when the target is not reached (the reason is printed).
NOT_REACHED = 3


def _numbers(option: str, text: str, counts: tuple[int, ...]) -> list[float]:
    """The comma-separated finite numbers of an option (as many as one of ``counts``)."""
    import math

    from kinegami.validation import shorten

    parts = [part.strip() for part in text.split(",")]
    try:
        values = [float(part) for part in parts]
    except ValueError:
        values = []
    if len(values) not in counts or not all(math.isfinite(v) for v in values):
        spelled = " or ".join(str(c) for c in counts)
        raise CommandError(f"{option}: must be {spelled} finite numbers separated by commas, "
                           f"got {shorten(text)!r}")  # fmt: skip
    return values


def _reach_target(position: str, axis: str | None):
    """A Target from ``--target X,Y,Z[,RX,RY,RZ]`` (the design's units; fixed-axis XYZ angles
    in degrees: R = Rz(RZ) Ry(RY) Rx(RX)) and ``--axis AX,AY,AZ``."""
    import math

    import numpy as np

    from kinegami.reach import Target

    values = _numbers("--target", position, (3, 6))
    if axis is not None:
        if len(values) == 6:
            raise CommandError("--axis: a target with angles (X,Y,Z,RX,RY,RZ) has no --axis")
        return Target(values, axis=_numbers("--axis", axis, (3,)))
    if len(values) == 3:
        return Target(values)
    rx, ry, rz = (math.radians(v) for v in values[3:])
    cx, sx, cy, sy, cz, sz = (math.cos(rx), math.sin(rx), math.cos(ry), math.sin(ry),
                              math.cos(rz), math.sin(rz))  # fmt: skip
    Rx = np.array([[1, 0, 0], [0, cx, -sx], [0, sx, cx]])
    Ry = np.array([[cy, 0, sy], [0, 1, 0], [-sy, 0, cy]])
    Rz = np.array([[cz, -sz, 0], [sz, cz, 0], [0, 0, 1]])
    return Target(values[:3], rotation=Rz @ Ry @ Rx)


def cmd_reach(args: argparse.Namespace) -> int:
    import json
    import math

    from kinegami.clearance import Lengths
    from kinegami.design import save_design
    from kinegami.geometry.screws import REVOLUTE
    from kinegami.reach import solve

    seed = _integer("--seed", args.seed, 0)
    axes = args.axis or []
    if axes and len(axes) != len(args.target):
        raise CommandError(f"--axis: give one per --target ({len(args.target)}), or none; got "
                           f"{len(axes)}")  # fmt: skip
    targets = [_reach_target(t, axes[k] if axes else None) for k, t in enumerate(args.target)]
    out = None if args.output is None else Path(args.output)
    if out is not None:
        _check_design_output(out, args.design, args.force)
    chain, info = _load(args.design)
    _margin(args, chain)
    n = len(chain.Joints)
    tips = [_integer("--tip", t, 0, n - 1, "a joint index of the design") for t in args.tip]
    if tips and len(tips) != len(targets):
        raise CommandError(f"--tip: give one per --target ({len(targets)}); got {len(tips)}")
    if not tips and len(targets) > 1:
        raise CommandError("--target: several targets need one --tip each")
    if not tips:
        _one_tip(chain, per_target=True)
    goal = dict(zip(tips, targets, strict=True)) if tips else targets[0]
    answer = solve(chain, goal, seed=seed)
    length = Lengths(chain.r, info.units)
    names = _joint_names(chain) or (None,) * n
    if args.json:
        print(json.dumps({
            "design": args.design, "reached": answer.ok, "reason": answer.reason,
            "states": list(answer.states), "position_error": answer.position_error,
            "angle_error": answer.angle_error,
            "clearance": answer.clearance if math.isfinite(answer.clearance) else None,
            "pair": answer.pair, "iterations": answer.iterations, "restarts": answer.restarts,
            "tips": list(answer.tips), "seed": seed,
        }, indent=2, allow_nan=False))  # fmt: skip
    else:
        title = f"{_printable(info.name)} ({args.design})" if info.name else args.design
        verdict = "reached" if answer.ok else f"not reached: {answer.reason}"
        lines = [f"{title}: {verdict}", *_material_lines(chain, info), "  states:"]
        for k, (joint, state) in enumerate(zip(chain.Joints, answer.states, strict=True)):
            if joint.stateRange() == (0.0, 0.0):
                continue
            name = f" {names[k]!r}" if names[k] else ""
            value = f"{math.degrees(state):.6g} deg" if joint.motion == REVOLUTE \
                else length(state)  # fmt: skip
            lines.append(f"    joint {k}{name} ({type(joint).__name__}): {value}")
        lines.append(f"  position error: {length.mm(answer.position_error)}; angle error: "
                     f"{answer.angle_error:.3g} rad")  # fmt: skip
        clear = "" if not answer.pair else f" ({answer.pair})"
        lines.append(f"  clearance: {length(answer.clearance)}{clear}"
                     if math.isfinite(answer.clearance) else "  clearance: nothing tested")
        print("\n".join(_printable(line) for line in lines))
    if out is not None and answer.ok:
        chain.requireClearance = False  # judged above, with the design's margin
        chain.setJointStates(list(answer.states))
        written = save_design(chain, out, name=info.name, description=info.description,
                              units=info.units, twistPortion=info.twistPortion,
                              material=info.material, bed=info.bed)  # fmt: skip
        if not args.json:
            print(f"  written: {written}")
    elif out is not None:
        _note(args.command, f"{shown_path(out)} not written: the target was not reached")
    return 0 if answer.ok else NOT_REACHED


def _one_tip(design, per_target: bool = False) -> None:
    """Refuse, in the command line's words, a design with several tips and no ``--tip``
    (``per_target``: reach's, which takes one per --target)."""
    from kinegami.reach import kinematics

    tips = kinematics(design).tips
    if len(tips) != 1:
        listed = ", ".join(str(t) for t in tips)
        each = " (one --tip per --target)" if per_target else ""
        raise CommandError(f"--tip: the design has {len(tips)} tips (joints {listed}); give "
                           f"--tip J{each}")  # fmt: skip


def cmd_workspace(args: argparse.Namespace) -> int:
    import io
    import json

    import matplotlib

    from kinegami._atomic import write_atomic
    from kinegami.limits import MAX_WORKSPACE_SAMPLES
    from kinegami.reach import workspace

    samples = _integer("--samples", args.samples, 1, MAX_WORKSPACE_SAMPLES,
                       "each clear sample is kept; kinegami.limits.MAX_WORKSPACE_SAMPLES")
    seed = _integer("--seed", args.seed, 0)
    out = Path(args.output)
    _check_output(out)
    chain, info = _load(args.design)
    _margin(args, chain)
    voxel = None
    if args.voxel is not None:
        voxel = _numbers("--voxel", args.voxel, (1,))[0]
        if voxel <= 0:
            raise CommandError(f"--voxel: must be a length > 0 in the design's units, got "
                               f"{args.voxel!r}")  # fmt: skip
    if args.tip is None:
        _one_tip(chain)
    tip = None if args.tip is None else _integer("--tip", args.tip, 0, len(chain.Joints) - 1,
                                                 "a joint index of the design")  # fmt: skip
    cloud = workspace(chain, samples, seed=seed, voxel=voxel, tip=tip)
    stem = Path(args.design).stem
    written = [cloud.save(out / f"{stem}_workspace.npz"), cloud.save(out / f"{stem}_workspace.ply")]
    matplotlib.use("Agg")  # a file, never a window
    import matplotlib.pyplot as plt

    figure = cloud.show(chain, units=info.units)
    picture = out / f"{stem}_workspace.png"
    buffer = io.BytesIO()
    figure.savefig(buffer, format="png", dpi=120)
    plt.close(figure)
    write_atomic(picture, buffer.getvalue())
    written.append(str(picture))
    title = f"{_printable(info.name)} ({args.design})" if info.name else args.design
    summary = cloud.summary(info.units)
    if args.json:
        print(json.dumps({
            "design": args.design, "samples": cloud.samples, "clear": int(cloud.points.shape[0]),
            "voxel": cloud.voxel, "voxels": int(cloud.voxels.shape[0]), "volume": cloud.volume,
            "half_volume": cloud.half_volume, "convergence": cloud.convergence,
            "lost_share": cloud.lost_share, "seed": seed, "files": [str(f) for f in written],
        }, indent=2, allow_nan=False))  # fmt: skip
    else:
        print("\n".join([f"{title}: workspace", *_material_lines(chain, info), f"  {summary}",
                         "  files written:", *(f"    {f}" for f in written)]))  # fmt: skip
    return 0


# --- parser ------------------------------------------------------------------------------------
class _Parser(argparse.ArgumentParser):
    """argparse's parser, whose errors are one line as every other error of the command line
    (argparse prints the usage block, then the error): the error, then the usage, joined."""

    def error(self, message: str):
        usage = " ".join(self.format_usage().split())
        self.exit(2, f"{self.prog}: error: {_printable(message)}; {usage}\n")


def _add_margin_option(command: argparse.ArgumentParser, more: str = "") -> None:
    """The ``--margin M`` option every command that judges clearance takes (read by
    :func:`_margin`), its help ending with ``more``."""
    command.add_argument(
        "--margin", metavar="M", default=None,
        help="the clearance required between parts, in the design's units (a number >= 0; "
        "default: the design's \"margin\", or 0: parts that touch are clear)" + more,
    )  # fmt: skip


def _add_material_options(command: argparse.ArgumentParser) -> None:
    """``--material NAME`` and ``--thickness MM`` (read by :func:`_fabrication`)."""
    command.add_argument(
        "--material", metavar="NAME", default=None,
        help="the sheet material, e.g. PET, paper, cardstock (default: the design's "
        "\"material\"); its thickness is the clearance margin unless --margin or the design's "
        "\"margin\" says otherwise, and every report names it",
    )  # fmt: skip
    command.add_argument(
        "--thickness", metavar="MM", default=None,
        help="the material's thickness in mm (default: the design's, or the usual thickness "
        "of a known material: PET 0.25, paper 0.1, cardstock 0.3, polypropylene 0.3)",
    )  # fmt: skip


def make_parser() -> argparse.ArgumentParser:
    parser = _Parser(
        prog="kinegami",
        description="Design tubular origami kinematic chains and their crease patterns.",
        epilog="Design files: see docs/design-format.md. "
        "Example: kinegami build examples/designs/example1.json -o out/",
    )
    parser.add_argument("--version", action="version", version=f"kinegami {__version__}")
    commands = parser.add_subparsers(dest="command", metavar="COMMAND")

    build = commands.add_parser(
        "build",
        help="build a design: crease pattern files, pictures and a summary",
        description="Build the chain of a design file and write its crease pattern (DXF, SVG) "
        "and pictures (PNG of the 3D chain and of the pattern) to a folder; print a summary. "
        "Nothing is written if the design is invalid or infeasible.",
    )
    build.add_argument("design", metavar="DESIGN", help="design file (.json)")
    build.add_argument(
        "-o", "--output", metavar="DIR", required=True, help="output folder (created if missing)"
    )
    known = output_formats()
    build.add_argument(
        "--formats",
        default=None,
        metavar="LIST",
        help=f"comma-separated outputs (default: {','.join(DEFAULT_FORMATS)} for a chain, "
        "dxf,svg,fold,pdf,junctions,urdf,png for a tree; 'all' for every one): "
        + "; ".join(f"{name} = {fmt.description}" for name, fmt in known.items())
        + "; for a tree, junctions = the printed connectors (STL and 3MF), and dxf, svg, fold "
        "write one file per sheet",
    )
    build.add_argument(
        "--name", metavar="STEM", help="file name stem of the outputs (default: the design file's)"
    )
    build.add_argument(
        "--junctions", metavar="KIND", default=None,
        help="trees only: how the branches of a joint with several children are joined: "
        "connector (default; a printed connector, STL and 3MF), takeoff (folded: each side "
        "branch leaves a face of the trunk's tube, the trunk's sheet gets a hole and the "
        "branch's sheet a skirt with glue tabs), auto (take-offs where they can be made, "
        "connectors elsewhere)",
    )  # fmt: skip
    _add_margin_option(build)
    _add_material_options(build)
    build.add_argument(
        "--bed", metavar="WxH", default=None,
        help="the laser cutter's bed in mm whatever the design's units, e.g. 600x400 (default: "
        "the design's \"bed\"; none: the whole sheet): the sheet is cut across plain tube into "
        "pieces that fit, each with an overlap tab, alignment marks and a label, nested onto "
        "bed sheets; dxf and svg write one file per bed sheet, <name>_bed_<m>.dxf "
        "(<name>_sheet_<k>_bed_<m>.dxf for a tree), and files of an earlier build with more "
        "beds are removed; exit code 1 when a stretch without plain tube is longer than the bed "
        "(the message names it and the smallest bed that works)",
    )  # fmt: skip
    build.add_argument("--bed-margin", metavar="MM", default=None,
                       help="distance kept from the bed's edges and between pieces (default 5)")
    build.add_argument("--tab", metavar="MM", default=None,
                       help="height of the overlap tab of the pieces (default 10; a cut needs "
                       "1.5 times this much plain tube)")  # fmt: skip
    build.set_defaults(run=cmd_build)

    show = commands.add_parser(
        "show",
        help="open the 3D view of a design",
        description="Build a design and open its 3D view in a matplotlib window.",
    )
    show.add_argument("design", metavar="DESIGN", help="design file (.json)")
    show.add_argument("--pattern", action="store_true", help="also show the crease pattern")
    show.set_defaults(run=cmd_show)

    validate = commands.add_parser(
        "validate",
        help="check a design file without building it",
        description="Check a design file against the format (schema, types, ranges, rigid "
        "poses) without building the chain, and print every problem found, one line each. "
        "With --build, also place every joint and apply the edits.",
    )
    validate.add_argument("design", metavar="DESIGN", help="design file (.json)")
    validate.add_argument(
        "--build", action="store_true", help="also build the chain (every placement and edit)"
    )
    validate.set_defaults(run=cmd_validate)

    new = commands.add_parser(
        "new",
        help="write a starter design file to change",
        description="Write a small design file that validates and builds (a start tip, a "
        "revolute joint, a prismatic joint and an end tip on a square tube of radius 10 mm), "
        "named after the file. The file appears whole or not at all; an existing file is kept "
        "unless --force.",
    )
    new.add_argument("design", metavar="DESIGN", help="the design file to write (.json)")
    new.add_argument("--force", action="store_true", help="replace DESIGN if it exists")
    new.add_argument("--task", action="store_true",
                     help="write a starter task file instead (for 'kinegami design')")
    new.add_argument("--tree", action="store_true",
                     help="with --task: a starter tree task (two fingers, one target list "
                     "each)")  # fmt: skip
    new.set_defaults(run=cmd_new)

    design = commands.add_parser(
        "design",
        help="design a robot that reaches every target of a task file",
        description="Design for a task (kinegami.optimize.design_for, docs/design-for-a-task.md): "
        "find a chain of the task's joints whose tip reaches every target exactly, in range, "
        "without passing through itself or entering a keep-out box, then write into DIR the "
        "design file (with its task), the build's outputs, and a report: NAME_task.txt and "
        ".json (per target the states, the errors and the clearance) and NAME_task.png (the "
        "robot at every target). A tree task (joints given per leaf, one target list per "
        "leaf) designs a tree whose leaves reach their k-th targets at once (grasp k), built "
        "as 'kinegami build' builds a tree, and reports per grasp and leaf. Exit code 0: "
        "designed; 3: infeasible (the certificate, or that the search found no design, is "
        "printed); 1: a task or option error.",
    )
    design.add_argument("task", metavar="TASK", help="task file (.json; 'kinegami new --task' "
                        "writes one)")  # fmt: skip
    design.add_argument("-o", "--output", metavar="DIR", required=True,
                        help="output folder (created if missing)")  # fmt: skip
    design.add_argument("--name", metavar="STEM",
                        help="file name stem of the outputs (default: the task file's)")
    design.add_argument("--seed", metavar="S", default=None,
                        help="seed of the search (default: the task's, else 0)")
    design.add_argument("--formats", default=None, metavar="LIST",
                        help="comma-separated build outputs, as for 'kinegami build'")
    design.set_defaults(run=cmd_design)

    check = commands.add_parser(
        "check",
        help="check that a design does not pass through itself",
        description="Build a design and report its self-intersections: the minimum clearance "
        "between its parts (mm, and the design's units), every pair of parts that overlap, and "
        "with --motion the share of sampled configurations that self-intersect and the free "
        "interval of each joint. Exit code 0: clear at its states; 3: self-intersects; 1: a "
        "design error. Nothing is written.",
    )
    check.add_argument("design", metavar="DESIGN", help="design file (.json)")
    check.add_argument(
        "--motion",
        metavar="N",
        help=f"also sample N configurations within the joints' ranges (1 to {MAX_MOTION}) and "
        "find each joint's free interval",
    )
    check.add_argument(
        "--seed", metavar="S", default="0", help="seed of the sampled configurations (an "
        "integer >= 0, default: %(default)s)"
    )  # fmt: skip
    check.add_argument(
        "--json", action="store_true", help="print one JSON object instead (see docs/cli.md)"
    )
    _add_margin_option(check)
    _add_material_options(check)
    check.set_defaults(run=cmd_check)

    reach = commands.add_parser(
        "reach",
        help="find joint states that put a design's tip on a target, clear of itself",
        description="Inverse kinematics (kinegami.reach.solve, docs/reach.md): joint states "
        "that put the tip exactly on the target (1e-9 r, 1e-9 rad), every state in its range, "
        "the design clear of itself. Prints the states, the errors, the clearance and the "
        "verdict. Exit code 0: reached; 3: not reached (the reason is printed); 1: a design or "
        "option error.",
    )
    reach.add_argument("design", metavar="DESIGN", help="design file (.json)")
    reach.add_argument(
        "--target", metavar="X,Y,Z[,RX,RY,RZ]", action="append", required=True,
        help="the tip's position in the design's units, and optionally its orientation as "
        "fixed-axis XYZ angles in degrees (R = Rz Ry Rx); write --target=-1,2,3 when the first "
        "number is negative; repeat with --tip for a tree's tips",
    )  # fmt: skip
    reach.add_argument(
        "--axis", metavar="AX,AY,AZ", action="append",
        help="the direction the tip's z axis must point along (a position target; rotation "
        "about it free); one per --target",
    )  # fmt: skip
    reach.add_argument(
        "--tip", metavar="J", action="append", default=[],
        help="the tip joint of the --target at the same place (default: the chain's last "
        "joint); a tree names one per target",
    )  # fmt: skip
    reach.add_argument("-o", "--output", metavar="POSED", default=None,
                       help="write the design at the found states to POSED (.json) when reached")
    reach.add_argument("--force", action="store_true", help="let -o replace DESIGN itself")
    reach.add_argument("--seed", metavar="S", default="0",
                       help="seed of the solver's starts (an integer >= 0, default: %(default)s)")
    reach.add_argument("--json", action="store_true", help="print one JSON object instead")
    _add_margin_option(reach)
    reach.set_defaults(run=cmd_reach)

    space = commands.add_parser(
        "workspace",
        help="sample what a design's tip can reach without passing through itself",
        description="The sampled workspace (kinegami.reach.workspace, docs/reach.md): draws "
        "configurations from the joints' ranges, keeps the clear ones, and writes DIR/"
        "NAME_workspace.npz (every array), .ply (the clear tip positions, a point cloud) and "
        ".png (three views); prints the volume at the voxel size with its sample count, how "
        "much it grew over the second half of the samples, and the share lost to "
        "self-collision. Exit code 0, or 1 for a design or option error.",
    )
    space.add_argument("design", metavar="DESIGN", help="design file (.json)")
    space.add_argument("-o", "--output", metavar="DIR", required=True, help="output folder")
    space.add_argument("--samples", metavar="N", default="20000",
                       help="configurations to draw (default: %(default)s)")
    space.add_argument("--voxel", metavar="H", default=None,
                       help="voxel edge in the design's units (default: 2r)")
    space.add_argument("--tip", metavar="J", default=None,
                       help="the tip joint (default: the chain's last joint; a tree names one)")
    space.add_argument("--seed", metavar="S", default="0",
                       help="seed of the draw (an integer >= 0, default: %(default)s)")
    space.add_argument("--json", action="store_true", help="print one JSON object instead")
    _add_margin_option(space)
    space.set_defaults(run=cmd_workspace)

    compact = commands.add_parser(
        "compact",
        help="shorten a design without changing its kinematics or making it collide",
        description="Build a design, shorten its tube by sliding and rolling joints along and "
        "about their axes (kinegami.optimize.compact: same kinematics, clear of itself) and "
        "write the compacted design to OUT; print the tube length, sheet size and clearance "
        "before and after. Exit code 0: written; 3: no clear design was found; 1: a design or "
        "option error. Nothing is written unless it succeeds.",
    )
    compact.add_argument("design", metavar="DESIGN", help="design file (.json)")
    compact.add_argument(
        "-o", "--output", metavar="OUT", required=True,
        help="the compacted design file to write (.json; missing folders are created)",
    )  # fmt: skip
    compact.add_argument(
        "--seed", metavar="S", default="0", help="seed of the search (an integer >= 0, "
        "default: %(default)s); the same seed gives the same design"
    )  # fmt: skip
    compact.add_argument(
        "--motion", action="store_true", help="also keep the share of sampled configurations "
        "that self-intersect no larger than the design's"
    )  # fmt: skip
    compact.add_argument(
        "--time-limit", metavar="T", help="seconds each start of the search may take (> 0; "
        "default: until no move shortens the tube)"
    )  # fmt: skip
    compact.add_argument(
        "--force", action="store_true", help="allow OUT to be DESIGN itself (replaced atomically)"
    )
    _add_margin_option(compact, "; the compacted design keeps its closest parts at least this "
                       "far apart and is written with it")  # fmt: skip
    _add_material_options(compact)
    compact.set_defaults(run=cmd_compact)

    edit = commands.add_parser(
        "edit",
        help="edit a design in the browser",
        description="Serve the browser editor (needs pip install 'kinegami[gui]') and print its "
        "address. Each browser tab edits its own copy of DESIGN (default: the starter design); "
        "designs are saved to DESIGN or downloaded, and unsaved changes are autosaved beside "
        "DESIGN (or in the user's data folder) and offered back on the next start. Listens on "
        "127.0.0.1 unless --host says otherwise; the printed address carries a secret token, and "
        "requests without it, or from another site's page, are refused. Runs until Ctrl-C.",
    )
    edit.add_argument("design", metavar="DESIGN", nargs="?", help="design file (.json)")
    edit.add_argument("--port", metavar="P", default="8080", help="port (default: %(default)s; "
                      "0: a free one)")  # fmt: skip
    edit.add_argument("--host", metavar="H", default="127.0.0.1", help="address to listen on "
                      "(default: %(default)s, this machine only; any other prints a warning: "
                      "whoever can reach the port and has the token can edit)")  # fmt: skip
    edit.add_argument(
        "--recover",
        action="store_true",
        help="start from the autosave of "
        "DESIGN (.DESIGN.autosave beside it; without DESIGN, in the user's data "
        "folder) when it is newer than DESIGN, instead of asking in the browser",
    )
    edit.set_defaults(run=cmd_edit)
    return parser


def _check_source_date_epoch() -> None:
    """Refuse a malformed ``SOURCE_DATE_EPOCH`` before any command runs (docs/fabrication.md,
    "Reproducible builds"); an empty one is unset, as documented, for the whole process (numpy's
    f2py, which scipy imports, cannot read an empty one)."""
    from kinegami.export._reproducible import VARIABLE, source_date_epoch

    if VARIABLE in os.environ and not os.environ[VARIABLE].strip():
        del os.environ[VARIABLE]
    source_date_epoch()


def main(argv: list[str] | None = None) -> int:
    """Entry point of the ``kinegami`` console script; returns the exit code."""
    _encoding_safe_output()
    try:
        parser = make_parser()
        args = parser.parse_args(argv)
    except KeyboardInterrupt:  # a Ctrl-C while starting up (main called from Python)
        _interrupted("")
        return INTERRUPTED
    _startup.restore_interrupts()  # from here on Ctrl-C is a KeyboardInterrupt, handled below
    if args.command is None:
        parser.print_help()
        return 0
    handled = [s for s in (signal.SIGTERM, getattr(signal, "SIGHUP", None)) if s is not None]
    previous = {s: signal.getsignal(s) for s in handled}
    for signum in handled:  # clean up staging folders on kill (SIGKILL: the next build does)
        if previous[signum] != signal.SIG_IGN:  # nohup: stay ignored
            signal.signal(signum, _terminate)
    try:
        _check_source_date_epoch()
        with warnings.catch_warnings():
            # numerical warnings of plotting libraries are not the user's business; the
            # design checks reject the inputs that would make kinegami's own numbers overflow
            warnings.simplefilter("ignore", RuntimeWarning)
            # each distinct warning once per command (a picture, the PDF and every sheet may
            # each draw the same missing glyph, say)
            warnings.showwarning = functools.partial(_show_warning, args.command, set())
            return args.run(args)
    except (CommandError, KinegamiError) as error:
        _fail(args.command, str(error))
        return 1
    except OSError as error:  # e.g. the design file cannot be read
        where = f": {error.filename!r}" if error.filename else ""
        _fail(args.command, f"{error.strerror or error}{where}")
        return 1
    except KeyboardInterrupt:
        _interrupted(args.command)
        return INTERRUPTED
    except Exception as error:  # a bug: still one line, and how to report it
        _fail(
            args.command,
            f"internal error on {getattr(args, 'design', '?')}: {type(error).__name__}: "
            f"{error} (please report this with the design file)",
        )
        return 1
    finally:
        for signum, handler in previous.items():
            if handler is not None:
                signal.signal(signum, handler)


#: Longest error line (a safety net: messages shorten the values they echo themselves).
MAX_MESSAGE = 1000


def _fail(command: str, message: str) -> None:
    text = _printable(" ".join(message.split()))
    if len(text) > MAX_MESSAGE:
        text = text[: MAX_MESSAGE - 3] + "..."
    print(f"kinegami {command}: error: {text}", file=sys.stderr)


def _interrupted(command: str) -> None:
    """The one line of a command ended by Ctrl-C (exit status 130)."""
    try:
        print(f"kinegami{' ' if command else ''}{command}: interrupted", file=sys.stderr)
    except (OSError, ValueError):  # stderr closed
        pass


def _encoding_safe_output() -> None:
    """Characters the terminal cannot show (PYTHONIOENCODING=ascii, a C locale) are written
    as backslash escapes instead of failing: a design named "Bras à 3 axes" still prints."""
    for stream in (sys.stdout, sys.stderr):
        reconfigure = getattr(stream, "reconfigure", None)
        if reconfigure is None:  # replaced by a non-text stream (tests, embedding)
            continue
        try:
            reconfigure(errors="backslashreplace")
        except (ValueError, OSError):  # detached or closed
            pass


#: matplotlib's warning for a character its font cannot draw (it draws a box instead)
_MISSING_GLYPH = re.compile(r"Glyph (\d+) \(.*\) missing from font\(s\) (.+?)\.?$")


def _show_warning(command: str, shown_before: set, message, category, filename, lineno,
                  file=None, line=None):  # fmt: skip
    """A warning that reaches the command line (a library's, or one kinegami does not report
    itself): one line, ``kinegami COMMAND: warning: ...``, not Python's two-line form; each
    distinct line once per command (``shown_before``: the lines said so far)."""
    text = str(message)
    glyph = _MISSING_GLYPH.match(text)
    if glyph:
        char = chr(int(glyph.group(1)))
        text = (f"the font {glyph.group(2)} has no {char!r} (U+{ord(char):04X}): the PDF and the "
                "pictures draw it as an empty box")  # fmt: skip
    if text in shown_before:
        return
    shown_before.add(text)
    _warn(command, text)


def _warn(command: str, message: str) -> None:
    text = _printable(" ".join(message.split()))
    print(f"kinegami {command}: warning: {text}", file=sys.stderr)


def _note(command: str, message: str) -> None:
    print(f"kinegami {command}: note: {_printable(' '.join(message.split()))}", file=sys.stderr)


def _terminate(signum, frame) -> None:
    """SIGTERM and SIGHUP end the command like Ctrl-C does: ``finally`` blocks run (staging
    folders go away) and publishing, which defers them, first finishes its rollback."""
    raise SystemExit(128 + signum)


if __name__ == "__main__":
    raise SystemExit(main())
