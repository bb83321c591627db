"""Incremental crease patterns for the editor: reuse what an edit did not change.

``chain.creasePattern(twistPortion)`` composes the catalog modules of every joint and link in
order (``TubularPattern.concatenate``, a left fold). An edit usually changes a few links and
leaves the rest of the modules as they were, so :class:`PatternCache` keeps

* the modules of each link, keyed by the numbers ``LinkCSC.pattern_modules`` reads (the link's
  shape, not its place: a link moved rigidly has the same modules), and
* the composite after every joint of the last chain it built, so a chain sharing the first k
  parts with it starts from the composite of those k parts.

The result is the pattern ``chain.creasePattern(twistPortion)`` returns, bit for bit
(``concatenate`` of a composite and more modules equals the fold of all of them).

A tree is folded from a sheet per leaf: :func:`tree_sheets` makes them as ``kinegami build``
does and says which sheet carries each joint and which of its records are the joint's own. See
docs/editor.md.
"""

from __future__ import annotations

from collections import OrderedDict
from collections.abc import Callable
from dataclasses import dataclass
from typing import Any

from kinegami.chain.links import LinkCSC
from kinegami.chain.model import KinematicChain
from kinegami.pattern import TubularPattern

__all__ = ["PatternCache", "link_shape_key", "joint_records", "TreeSheets", "tree_sheets",
           "sheet_records"]  # fmt: skip


def _arc_key(arc) -> tuple:
    return (float(arc.angle), int(arc.count), float(arc.elbowAngle), float(arc.rotationalAxisAngle))


def link_shape_key(link: LinkCSC) -> tuple:
    """The numbers a link's crease pattern depends on (its shape, not its place)."""
    return (
        float(link.r),
        _arc_key(link.elbows1),
        float(link.path.tMag),
        bool(link.hasTwist),
        float(link.twistAngle),
        _arc_key(link.elbows2),
    )


def joint_records(parts) -> tuple[range, ...]:
    """Per joint, the indices in the composite's ``modules`` of the joint's own module records.

    ``parts[i]`` is what joint i adds, in order: the modules of the link into it, then the
    joint's pattern (only the joint's pattern for joint 0). Composition keeps every record of
    the first pattern and of every later one that is not empty (a waypoint's pattern is only
    its base polygon and adds none), so the records of the composite follow the parts.
    """
    records, k = [], 0
    for i, part in enumerate(parts):
        for m, module in enumerate(part):
            count = len(module.modules) if (i == 0 and m == 0) or not module.isEmpty else 0
            if m == len(part) - 1:
                records.append(range(k, k + count))
            k += count
    return tuple(records)


class PatternCache:
    """Builds chains' crease patterns, reusing link modules and the last chain's composites.

    Parameters
    ----------
    max_links : how many distinct link shapes to remember (least recently used dropped).
    """

    def __init__(self, max_links: int = 4096):
        self._max_links = int(max_links)
        self._links: OrderedDict = OrderedDict()
        self._tube: tuple | None = None  # (numSides, r, twistPortion) of the checkpoints
        self._parts: list[tuple] = []  # per joint i: the module objects of link i and joint i
        self._composites: list[TubularPattern] = []  # composite after joint i

    def link_modules(self, link: LinkCSC, numSides: int, twistPortion: float) -> tuple:
        """``link.pattern_modules(numSides, twistPortion)``, remembered by the link's shape."""
        key = (int(numSides), float(twistPortion), link_shape_key(link))
        modules = self._links.get(key)
        if modules is None:
            modules = tuple(link.pattern_modules(numSides, twistPortion))
            self._links[key] = modules
            if len(self._links) > self._max_links:
                self._links.popitem(last=False)
        else:
            self._links.move_to_end(key)
        return modules

    def _parts_of(self, chain: KinematicChain, twistPortion: float) -> list[tuple]:
        joints, links = chain.Joints, chain.Links
        parts = [(joints[0].pattern,)]
        for link, joint in zip(links[1:], joints[1:], strict=True):
            parts.append(self.link_modules(link, chain.numSides, twistPortion) + (joint.pattern,))
        return parts

    def joint_records(self, chain: KinematicChain, twistPortion: float = 0.2) -> tuple[range, ...]:
        """Per joint of ``chain``, the indices of its own records in the ``modules`` of
        :meth:`pattern` (see :func:`joint_records`)."""
        return joint_records(self._parts_of(chain, twistPortion))

    def pattern(self, chain: KinematicChain, twistPortion: float = 0.2) -> TubularPattern:
        """The crease pattern of ``chain`` (equal to ``chain.creasePattern(twistPortion)``)."""
        tube = (int(chain.numSides), float(chain.r), float(twistPortion))
        parts = self._parts_of(chain, twistPortion)
        same = 0
        if tube == self._tube:
            for old, new in zip(self._parts, parts, strict=False):
                if len(old) != len(new) or any(a is not b for a, b in zip(old, new, strict=True)):
                    break
                same += 1
        composites = self._composites[:same]
        if not composites:
            composites.append(parts[0][0])
            same = 1
        for part in parts[same:]:
            composites.append(TubularPattern.concatenate([composites[-1], *part]))
        self._tube, self._parts, self._composites = tube, parts, composites
        return composites[-1]


# --- trees: a sheet per leaf ------------------------------------------------------------------
def _record_count(pattern, first: bool) -> int:
    """How many module records ``pattern`` adds to a composite (all of the first pattern's;
    none of a later empty one's)."""
    return len(pattern.modules) if first or not pattern.isEmpty else 0


def sheet_records(tree, sheet, twistPortion: float = 0.2,
                  cache: PatternCache | None = None) -> tuple[range, ...]:  # fmt: skip
    """Per joint of ``sheet`` (a :class:`~kinegami.fabrication.sheets.TreeSheet` of ``tree``), the
    indices of its own records in ``sheet.pattern.modules``.

    A sheet is the composite of, for each of its joints in order, the modules of the link into
    it and the joint's pattern; its first joint's link is only the part beyond the junction's
    socket (sheet 0 starts with the root's pattern alone). The records are counted from the
    sheet's end, so that part's modules need not be built again.
    """
    cache = PatternCache() if cache is None else cache
    n = tree.numSides
    end = len(sheet.pattern.modules)
    records: list[range] = []
    for k in reversed(sheet.joints[1:]):
        own = _record_count(tree.Joints[k].pattern, False)
        records.append(range(end - own, end))
        end -= own
        for module in cache.link_modules(tree.Links[k], n, twistPortion):
            end -= _record_count(module, False)
    first = tree.Joints[sheet.joints[0]]
    if sheet.junction is None:  # the root's pattern is the whole first part
        records.append(range(0, end))
    else:
        own = _record_count(first.pattern, False)
        records.append(range(end - own, end))
    return tuple(reversed(records))


@dataclass(frozen=True)
class TreeSheets:
    """A tree's sheets as the editor shows and downloads them (docs/trees.md, Fabrication).

    Attributes
    ----------
    fabrication : the :class:`~kinegami.fabrication.sheets.TreeFabrication` (sheets and junctions)
        of the tree after :func:`~kinegami.fabrication.sheets.fit_junctions`, as ``kinegami build``
        makes it.
    slides : ``(joint, distance)`` of every slide the fit made (lengths in the tree's units;
        empty when every socket fits as designed).
    labels : per sheet, its label (joints by name, lengths in mm; what the DXF, SVG and PDF
        carry).
    places : per joint, ``(sheet, records)``: the sheet that carries it and the indices of its
        own records in that sheet's ``pattern.modules``.
    """

    fabrication: Any
    slides: tuple
    labels: tuple[str, ...]
    places: tuple[tuple[int, range], ...]

    @property
    def sheets(self) -> tuple:
        """The :class:`~kinegami.fabrication.sheets.TreeSheet` of every leaf."""
        return self.fabrication.sheets


def tree_sheets(tree, twistPortion: float = 0.2, names=None, units: str = "mm",
                cache: PatternCache | None = None,
                fit: Callable | None = None) -> TreeSheets:  # fmt: skip
    """The :class:`TreeSheets` of ``tree`` (a KinematicTree): fitted and fabricated as
    ``kinegami build`` does (raises InvalidParameterError when some socket cannot be made to
    fit; the message names the joint).

    ``fit`` replaces :func:`~kinegami.fabrication.sheets.fit_junctions` (``fit(tree) -> (fitted,
    slides)``; the view runs it in a worker process); ``cache`` gives the links' modules.
    """
    from kinegami.export.tree_build import sheet_labels
    from kinegami.fabrication.sheets import fabricate, fit_junctions

    fitted, slides = (fit_junctions if fit is None else fit)(tree)
    fabrication = fabricate(fitted, twistPortion=twistPortion)
    labels = tuple(sheet_labels(fabrication, names, units))
    places: list = [None] * len(fitted.Joints)
    for sheet in fabrication.sheets:
        for joint, records in zip(sheet.joints, sheet_records(fitted, sheet, twistPortion, cache),
                                  strict=True):  # fmt: skip
            places[joint] = (sheet.index, records)
    return TreeSheets(fabrication, tuple(slides), labels, tuple(places))
