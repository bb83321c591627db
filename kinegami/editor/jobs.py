"""The editor's long jobs, as the view runs them in its job process (docs/editor.md,
Background jobs): what each computes, from picklable arguments, with a ``progress`` callback.

Compact and Fit junctions are :class:`~kinegami.editor.commands.LongCommand` objects: their
heavy part is ``command.compute(chain, progress=...)`` and the result comes back as one
:class:`~kinegami.editor.commands.Computed` command. The motion check changes nothing; it
returns its report as text for the panel (:func:`motion_check`).
"""

from __future__ import annotations

import numpy as np

__all__ = ["MOTION_SAMPLES", "TREE_MOTION_SAMPLES", "motion_check"]

#: Configurations a motion check samples for a chain (vectorised: about a second for the PUMA).
MOTION_SAMPLES = 2000
#: ... and for a tree (tested one configuration at a time: about 10 ms each for the hand).
TREE_MOTION_SAMPLES = 300
#: Pairs of parts listed in the motion report.
LISTED = 5
#: Joints whose free interval the motion report lists.
LISTED_JOINTS = 12


def motion_check(chain, names, samples: int, seed: int = 0, *, progress=None) -> str:
    """The motion check of ``chain`` (:func:`kinegami.clearance.sweep` of ``samples`` random
    configurations) as Markdown for the panel (:meth:`kinegami.clearance.SweepReport.markdown`);
    ``progress`` as docs/progress.md says."""
    from kinegami.clearance import sweep

    report = sweep(chain, samples=samples, seed=seed, names=names, progress=progress)
    return report.markdown(chain, names=names, seed=seed, listed=LISTED,
                           joints_listed=LISTED_JOINTS)  # fmt: skip


#: Configurations the editor's Workspace button samples.
WORKSPACE_SAMPLES = 20_000


def workspace_points(chain, samples: int, tip: int, seed: int = 0, *,
                     progress=None) -> tuple:  # fmt: skip
    """The editor's workspace cloud of ``chain``'s joint ``tip``: the tip positions of the
    clear configurations among ``samples`` random ones (:func:`kinegami.reach.workspace`),
    as ``(points (N, 3), summary in one line)``."""
    from kinegami.reach import workspace

    found = workspace(chain, samples, seed=seed, tip=tip, progress=progress)
    return np.asarray(found.points, dtype=float), found.summary()
