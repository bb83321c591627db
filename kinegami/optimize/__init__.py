"""Searches over designs that keep what a design does (docs/clearance.md, Compaction).

:mod:`kinegami.optimize.compaction`: :func:`compact`, a multi-start local search that slides
and rolls joints along their axes (the kinematics stay the same) to shorten the tube or shrink
the design's ball, never accepting a design that passes through itself;
:func:`shorten_by_axis_translations`, its slide-only, in-place form; :func:`tube_length`;
:func:`repaired_vertices`, how many vertices a design's folded form needs the isometry repair
for.

:mod:`kinegami.optimize.synthesis`: :func:`design_for`, a chain made for a task (targets in, a
foldable robot that reaches every one of them out; docs/design-for-a-task.md), and
:func:`compact_for_task`, compaction that keeps such a task (a chain's, or a tree's: one target
list per leaf).
"""

from kinegami.optimize.compaction import (
    CompactionError,
    compact,
    compact_for_task,
    repaired_vertices,
    shorten_by_axis_translations,
    tube_length,
)
from kinegami.optimize.synthesis import design_for

__all__ = [
    "compact",
    "compact_for_task",
    "CompactionError",
    "design_for",
    "repaired_vertices",
    "shorten_by_axis_translations",
    "tube_length",
]
