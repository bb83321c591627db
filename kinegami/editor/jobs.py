"""The editor's long jobs, as the view runs them in its job process (docs/editor.md,
Background jobs): what each computes, from picklable arguments, with a ``progress`` callback.

Compact and Fit junctions are :class:`~kinegami.editor.commands.LongCommand` objects: their
heavy part is ``command.compute(chain, progress=...)`` and the result comes back as one
:class:`~kinegami.editor.commands.Computed` command. The motion check changes nothing; it
returns its report as text for the panel (:func:`motion_check`).
"""

from __future__ import annotations

import math

__all__ = ["MOTION_SAMPLES", "TREE_MOTION_SAMPLES", "motion_check", "motion_text"]

#: Configurations a motion check samples for a chain (vectorised: about a second for the PUMA).
MOTION_SAMPLES = 2000
#: ... and for a tree (tested one configuration at a time: about 10 ms each for the hand).
TREE_MOTION_SAMPLES = 300
#: Pairs of parts and joints listed in the motion report.
LISTED = 5


def motion_check(chain, names, samples: int, seed: int = 0, *, progress=None) -> str:
    """The motion check of ``chain`` (:func:`kinegami.clearance.sweep` of ``samples`` random
    configurations) as Markdown for the panel; ``progress`` as docs/progress.md says."""
    from kinegami.clearance import sweep

    report = sweep(chain, samples=samples, seed=seed, names=names, progress=progress)
    return motion_text(chain, report, names, seed)


def motion_text(chain, report, names=None, seed: int = 0) -> str:
    """A :class:`~kinegami.clearance.SweepReport` in words (Markdown)."""
    lines = [f"**Motion check:** {report.colliding} of {report.samples} random configurations "
             f"self-intersect ({100.0 * report.colliding_fraction:.1f}%, seed {seed})"]  # fmt: skip
    if report.worst_pairs:
        lines += ["", "Deepest overlaps over the motion:", ""]
        for pair, count in report.worst_pairs[:LISTED]:
            lines.append(f"- {pair.first} and {pair.second}: up to {-pair.clearance:.3g} "
                         f"({count} configuration{'s' if count > 1 else ''})")  # fmt: skip
    movable = [i for i, joint in enumerate(chain.Joints) if _moves(joint)]
    if movable and report.free_intervals[movable[0]] is None:
        lines += ["", "Free intervals: none (the design self-intersects at its states)."]
    elif movable:
        lines += ["", "Free interval of each joint moved alone from its state:", ""]
        for i in movable[:12]:
            low, high = report.free_intervals[i]
            lo, hi = (float(v) for v in chain.Joints[i].stateRange())
            name = names[i] if names is not None and names[i] else type(chain.Joints[i]).__name__
            whole = " (its whole range)" if low <= lo and high >= hi else ""
            lines.append(f"- {i} {name}: [{_state(chain.Joints[i], low)}, "
                         f"{_state(chain.Joints[i], high)}]{whole}")  # fmt: skip
        if len(movable) > 12:
            lines.append(f"- ... and {len(movable) - 12} more joints")
    return "\n".join(lines)


def _moves(joint) -> bool:
    lo, hi = (float(v) for v in joint.stateRange())
    return hi > lo


def _state(joint, value: float) -> str:
    from kinegami.chain.joints import RevoluteJoint

    if isinstance(joint, RevoluteJoint):
        return f"{math.degrees(value):.1f} deg"
    return f"{value:.3g}"
