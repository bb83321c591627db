"""Searches over designs that keep what a design does (docs/clearance.md, Compaction).

:mod:`kinegami.optimize.compaction`: :func:`compact`, a multi-start local search that slides
and rolls joints along their axes (the kinematics stay the same) to shorten the tube or shrink
the design's ball, never accepting a design that passes through itself;
:func:`shorten_by_axis_translations`, its slide-only, in-place form; :func:`tube_length`.
Design for a task (targets in, a robot that reaches them out) will live here too.
"""

from kinegami.optimize.compaction import (
    CompactionError,
    compact,
    shorten_by_axis_translations,
    tube_length,
)

__all__ = ["compact", "CompactionError", "shorten_by_axis_translations", "tube_length"]
