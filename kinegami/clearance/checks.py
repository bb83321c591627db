"""The clearance checks users call: a chain or tree at one configuration (``clearance_report``,
``chain_clearance``, ``tree_clearance``) and over sampled motion (``sweep``); see
docs/clearance.md."""

from __future__ import annotations

import dataclasses
from collections.abc import Sequence

import numpy as np

from kinegami.chain.bodies import (
    check_margin,
)
from kinegami.clearance.engine import (
    ChainMotion,
    TreeMotion,
    current_states,
    engine_for,
    tree_engine,
)
from kinegami.clearance.reports import ClearanceReport, CollidingPair, SweepReport
from kinegami.errors import InvalidParameterError, InvalidTypeError
from kinegami.limits import MAX_SAMPLED_STATES, MAX_SAMPLES
from kinegami.validation import (
    check_int,
    check_samples,
    shorten,
    shown,
)

__all__ = ["clearance_report", "chain_clearance", "tree_clearance", "sweep"]


def clearance_report(assembly, names=None, margin=None, states=None) -> ClearanceReport:
    """The one clearance verdict of a chain or a tree: what ``kinegami build``, ``kinegami
    check``, ``kinegami compact`` and the editor report (:meth:`ClearanceReport.verdict` words
    it).

    Parameters
    ----------
    assembly : KinematicChain or KinematicTree
    names : sequence of str or None, optional
        Joint names for the parts (each shown on one line, at most 80 characters).
    margin : float, optional
        The clearance required (chain units, >= 0); default: ``assembly.margin``.
    states : sequence of float, optional
        A configuration; default: the current states.
    """
    from kinegami.chain.model import KinematicChain

    if names is not None:
        names = tuple(None if name is None else shorten(name) for name in names)
    if isinstance(assembly, KinematicChain):
        return chain_clearance(assembly, states, names, margin)
    return tree_clearance(assembly, states, names, margin)


def _margin_of(chain, margin) -> float:
    """``margin`` checked, or the chain's (or tree's) own ``margin`` when None."""
    if margin is None:
        return float(getattr(chain, "margin", 0.0))
    return check_margin(margin)


def chain_clearance(chain, states=None, names=None, margin=None) -> ClearanceReport:
    """The clearance of ``chain`` at its current states, or at ``states`` (one per joint).

    Parameters
    ----------
    chain : KinematicChain
    states : sequence of float, optional
        A configuration (absolute states, each within its joint's ``stateRange()``); default:
        the chain's current states. The chain is not changed.
    names : sequence of str or None, optional
        Joint names for the report.
    margin : float, optional
        The clearance required (chain units, >= 0); default: ``chain.margin``.

    Raises
    ------
    InvalidParameterError
        For ``states`` of the wrong length or outside a joint's range, or a negative margin.
    """
    margin = _margin_of(chain, margin)
    engine = engine_for(chain, names)
    return engine.report(current_states(chain) if states is None else states, margin)


def sweep(
    chain,
    samples: int = 1000,
    seed: int = 0,
    configurations=None,
    *,
    names=None,
    resolution: int = 64,
    progress=None,
    margin=None,
) -> SweepReport:
    """Clearance over the range of motion of a chain or a tree.

    Parameters
    ----------
    chain : KinematicChain or KinematicTree
        A tree is tested configuration by configuration with the pair rule of trees
        (:class:`TreeMotion`, docs/trees.md); a chain with its vectorised engine.
    samples : int
        Number of configurations drawn uniformly from the joints' state ranges (> 0, at most
        kinegami.limits.MAX_SAMPLES, and samples x joints at most MAX_SAMPLED_STATES, as every
        count of configurations here; ignored when ``configurations`` is given).
    seed : int
        Seed of the random configurations (numpy ``default_rng``; >= 0; ignored when
        ``configurations`` is given).
    configurations : sequence of sequences of float, optional
        The configurations to test instead (absolute states, one per joint).
    names : joint names for the report, optional.
    resolution : int
        Grid steps per joint and direction when searching the free intervals (1 to
        kinegami.limits.MAX_SAMPLES).
    progress : bool or callable, optional
        ``progress(done, total)`` as configurations are tested (total: their count);
        returning False stops the sweep with :class:`~kinegami.errors.Cancelled`. True or
        None: a progress bar on stderr (None: when stderr is a terminal). docs/progress.md.
    margin : float, optional
        The clearance required (chain units, >= 0): a configuration whose parts come closer
        counts as colliding; default: ``chain.margin``.

    Returns
    -------
    SweepReport
        The colliding fraction, the worst pairs, and each joint's free interval around the
        chain's current states.
    """
    from kinegami.chain.assembly import JointAssembly
    from kinegami.chain.model import KinematicChain

    margin = _margin_of(chain, margin)
    if isinstance(chain, JointAssembly) and not isinstance(chain, KinematicChain):
        engine = TreeMotion(chain, names, margin)  # a KinematicTree (a layer above this one)
    else:
        engine = ChainMotion(engine_for(chain, names), margin)
    if isinstance(resolution, bool) or not isinstance(resolution, int | np.integer):
        raise InvalidTypeError(f"resolution must be an integer >= 1, got {shown(resolution)}")
    if resolution < 1:
        raise InvalidParameterError(f"resolution must be an integer >= 1, got {shown(resolution)}")
    J = len(engine.ranges)
    _check_scan(int(resolution))
    if configurations is None:
        if isinstance(samples, bool) or not isinstance(samples, int | np.integer):
            raise InvalidTypeError(f"samples must be an integer > 0, got {shown(samples)}")
        if samples <= 0:
            raise InvalidParameterError(f"samples must be an integer > 0, got {shown(samples)}")
        samples = check_samples("samples", samples, J)
        seed = check_int("seed", seed, minimum=0, floats=False)
        rng = np.random.default_rng(seed)
        lo, hi = engine.ranges[:, 0], engine.ranges[:, 1]
        Q = lo + (hi - lo) * rng.random((int(samples), lo.size))
    else:
        if isinstance(configurations, str | bytes) or not isinstance(
            configurations, Sequence | np.ndarray
        ):
            raise InvalidTypeError(
                "configurations must be a list of configurations (one state per joint), got "
                f"{type(configurations).__name__}"
            )
        if len(configurations) == 0:
            raise InvalidParameterError("configurations must not be empty")
        count = len(configurations)
        if count > MAX_SAMPLES or count * J > MAX_SAMPLED_STATES:
            raise InvalidParameterError(
                f"configurations: {count} configurations of {J} joints, more than "
                f"{min(MAX_SAMPLES, MAX_SAMPLED_STATES // max(J, 1))} (each is a clearance "
                "test of the whole chain; kinegami.limits.MAX_SAMPLES and MAX_SAMPLED_STATES)"
            )
        Q = np.array(
            [engine.check_states(c, f"configurations[{k}]") for k, c in enumerate(configurations)]
        )
    found = _worst_with_progress(engine, Q, progress)
    clearance, worst = engine.tally(Q, found)
    current = current_states(chain)
    return SweepReport(
        samples=int(Q.shape[0]),
        colliding=int(np.count_nonzero(np.isfinite(clearance))),
        worst_pairs=worst,
        free_intervals=engine.free_intervals(current, int(resolution)),
        states=tuple(float(x) for x in current),
        margin=margin,
    )


def _check_scan(resolution: int) -> None:
    """The free intervals scan ``resolution`` states of every joint and side: a motion check
    of that many configurations each, at most MAX_SAMPLES (docs/limits.md)."""
    if resolution > MAX_SAMPLES:
        raise InvalidParameterError(
            f"resolution must be an integer in [1, {MAX_SAMPLES}] (grid steps per joint and "
            f"side of the free intervals; kinegami.limits.MAX_SAMPLES), got {shown(resolution)}"
        )


def _worst_with_progress(engine, Q: np.ndarray, progress) -> tuple:
    """``engine.worst_arrays(Q)`` in chunks, reporting each chunk to ``progress`` (may
    cancel)."""
    from kinegami.progress import Progress

    chunk = 4096
    parts = []
    with Progress(progress, Q.shape[0], desc="sweep", unit="configuration") as bar:
        for start in range(0, Q.shape[0], chunk):
            found = engine.worst_arrays(Q[start : start + chunk])
            parts.append(found)
            bar.update(found[0].shape[0])
    return tuple(np.concatenate(column) for column in zip(*parts, strict=True))


def tree_clearance(tree, states=None, names=None, margin=None) -> ClearanceReport:
    """The clearance of a :class:`~kinegami.tree.KinematicTree` at its current states or at
    ``states`` (one per joint, in index order), with ``margin`` (chain units, >= 0; default:
    ``tree.margin``); the tree is not changed.

    The pair rule of trees (docs/trees.md): parts on one path from the root are tested as in a
    chain; parts on different branches always, except where two tubes leaving the same
    branching joint run together inside the junction that joins them (until they are the
    margin apart). A tree that is a chain gets the chain's report. When the closest parts of a
    clear tree are two tubes leaving one junction, the report's ``note`` says so.

    Raises
    ------
    InvalidParameterError, InvalidTypeError
        For ``states`` of the wrong length or type, or outside a joint's range, or a negative
        margin.
    """
    margin = _margin_of(tree, margin)
    engine = tree_engine(tree, names, margin)
    report = engine.report(current_states(tree) if states is None else states, margin)
    if report.ok and report.closest is not None:
        note = _junction_note(tree, report.closest)
        if note:
            report = dataclasses.replace(report, note=note)
    return report


def _junction_note(tree, pair: CollidingPair) -> str:
    """When ``pair`` (the closest parts of a clear tree) are two tubes leaving the same
    branching joint: "; closest where the tubes leaving joint J come out of its junction"
    (they touch there by construction: the junction covers them up to where they are the
    margin apart), else ""."""

    if any(e < 1 or e % 2 == 0 for e in pair.elements):
        return ""
    parents, joints = tree.Parents, tree.Joints
    children = [0] * len(parents)
    for p in parents:
        if p >= 0:
            children[p] += 1

    def top(k: int) -> int | None:  # the child of a branching joint whose tube k continues
        while k > 0:
            parent = parents[k]
            if children[parent] > 1:
                return k
            if joints[parent].has_body:
                return None
            k = parent
        return None

    a, b = (top((e + 1) // 2) for e in pair.elements)
    if a is None or b is None or a == b or parents[a] != parents[b]:
        return ""
    return f"; closest where the tubes leaving joint {parents[a]} come out of its junction"
