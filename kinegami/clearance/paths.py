"""Whether a chain moves from one configuration to another without passing through itself
(docs/design-for-a-task.md, Paths): the straight line between them in joint space, certified by
bisection.

Between two configurations a and b of a segment of the line, no point of the chain moves more
than ``delta`` = sum over the joints of |b_i - a_i| times (the tube length plus r) for a revolute
joint (a point downstream of a joint is at most the tube length along the tube from its axis),
or |b_i - a_i| for a prismatic one. Two parts then come closer by at most 2 delta, so every
configuration of the segment has a clearance of at least (c_a + c_b) / 2 - delta, where c_a and
c_b are the clearances at its ends (the two bounds c_a - 2 delta u and c_b - 2 delta (1 - u)
cross there). A segment whose bound is at least the margin is certified; others are halved,
a batch of the clearance engine per level, until every piece is certified, a configuration on
the line is not clear (the path fails there), or the pieces are too many.
"""

from __future__ import annotations

import numpy as np

__all__ = ["MAX_PATH_CONFIGURATIONS", "PathCheck", "check_path"]

#: Configurations one path check may measure (the bisection stops there, uncertified).
MAX_PATH_CONFIGURATIONS = 200_000


class PathCheck:
    """The verdict of :func:`check_path`: ``ok`` (every configuration on the line is clear with
    the margin, certified), ``configurations`` (the measured ones, in order along the line,
    (m, joints)), ``clearance`` (the smallest measured), ``reason`` (why not, when not ok)."""

    def __init__(self, ok: bool, configurations: np.ndarray, clearance: float, reason: str):
        self.ok, self.configurations = ok, configurations
        self.clearance, self.reason = clearance, reason

    def __repr__(self) -> str:
        return (f"PathCheck(ok={self.ok}, configurations={len(self.configurations)}, "
                f"clearance={self.clearance:.6g}, reason={self.reason!r})")  # fmt: skip


def check_path(chain, start, end, margin: float | None = None) -> PathCheck:
    """Whether ``chain`` moves along the straight line in joint space from the configuration
    ``start`` to ``end`` (full configurations, as ``setJointStates`` takes them) without any two
    parts coming closer than ``margin`` (default ``chain.margin``), certified by the motion bound
    of the module docstring."""
    from kinegami.chain.bodies import check_margin, clear_limit
    from kinegami.clearance.engine import engine_for
    from kinegami.geometry.screws import REVOLUTE

    engine = engine_for(chain)
    a = engine.check_states(start, "start")
    b = engine.check_states(end, "end")
    margin = float(chain.margin) if margin is None else check_margin(margin)
    r = float(chain.r)
    length = float(chain.totalPathLength() + sum(j.neutralLength for j in chain.Joints))
    lever = np.array([(length + r) if joint.motion == REVOLUTE else 1.0
                      for joint in chain.Joints])  # fmt: skip
    limit = clear_limit(r, margin)
    # clearances are measured up to this far beyond the margin (further counts as this far)
    reach = margin + 2.0 * r

    def clearances(U: np.ndarray) -> np.ndarray:
        Q = a + U[:, None] * (b - a)
        c = engine.worst_arrays(Q, reach)[0]
        return np.minimum(c, reach)

    per_unit = float(np.abs(b - a) @ lever)  # the largest motion over the whole line
    u = np.array([0.0, 1.0])
    c = clearances(u)
    pending = [(0, 1)]  # segments (indices into u) not yet certified
    while pending:
        bad = np.flatnonzero(c < limit)
        if bad.size:
            k = int(bad[0])
            return PathCheck(False, a + u[:, None] * (b - a), float(c.min()),
                             f"the chain passes through itself at {u[k]:.6g} of the way "
                             f"(clearance {c[k]:.6g})")  # fmt: skip
        if u.size > MAX_PATH_CONFIGURATIONS:
            return PathCheck(False, a + u[:, None] * (b - a), float(c.min()),
                             f"not certified within {MAX_PATH_CONFIGURATIONS} configurations "
                             "(the path grazes: its clearance nears the margin)")  # fmt: skip
        split = [(i, j) for i, j in pending
                 if 0.5 * (c[i] + c[j]) - per_unit * (u[j] - u[i]) < margin]  # fmt: skip
        if not split:
            break
        middle = np.array([0.5 * (u[i] + u[j]) for i, j in split])
        cm = clearances(middle)
        u2 = np.concatenate([u, middle])
        c2 = np.concatenate([c, cm])
        order = np.argsort(u2, kind="stable")
        u, c = u2[order], c2[order]
        where = {float(x): n for n, x in enumerate(u)}
        halves = []  # pending segments are neighbours in u: a midpoint's are its segment's ends
        for m in middle.tolist():
            mid = where[m]
            halves += [(mid - 1, mid), (mid, mid + 1)]
        pending = halves
    return PathCheck(True, a + u[:, None] * (b - a), float(c.min()), "")
