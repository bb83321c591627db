"""The one-configuration report (``design.clearance(q)``: bounds on every listed pair, then the
few pairs the bounds cannot rule out measured exactly in the order of their bounds) against
the engine's other paths: the report of the general path (an engine that finds near groups
with a k-d tree, every pair near the closest measured), the batch (``worst_arrays``) and the
body motions of the batch. The answers must be the same bits: the verdict, the clearance, the
listed pairs in their order and the closest pair."""

from __future__ import annotations

import math
from pathlib import Path

import numpy as np
import pytest
from hypothesis import given, settings
from hypothesis import strategies as st

import kinegami.clearance.engine as clearance_module
from kinegami import KinematicChain
from kinegami.chain.bodies import clear_limit
from kinegami.clearance import ClearanceEngine, TreeEngine
from kinegami.design import load_design
from kinegami.errors import InvalidParameterError, InvalidTypeError

DESIGNS = Path(__file__).parents[2] / "examples" / "designs"
NAMES = ["puma", "spherical_series", "doubling_back", "prismatic_spiral", "hand", "quadruped"]
_ENGINES: dict[str, tuple] = {}


def engines(name: str) -> tuple:
    """The design's listed engine (the one-configuration path) and an engine of the general
    path (near groups found with a k-d tree), built once."""
    if name not in _ENGINES:
        design = load_design(DESIGNS / f"{name}.json")

        def build():
            if isinstance(design, KinematicChain):
                return ClearanceEngine(design)
            return TreeEngine(design)

        listed = build()
        saved = clearance_module._GROUP_PAIRS_LISTED
        clearance_module._GROUP_PAIRS_LISTED = 0
        try:
            general = build()
        finally:
            clearance_module._GROUP_PAIRS_LISTED = saved
        assert listed._listed and not general._listed
        _ENGINES[name] = (design, listed, general)
    return _ENGINES[name]


def configuration(engine, fractions) -> list:
    lo, hi = engine.ranges[:, 0], engine.ranges[:, 1]
    return (lo + (hi - lo) * np.asarray(fractions[: lo.size])).tolist()


@pytest.mark.filterwarnings("error::RuntimeWarning")
@settings(max_examples=60, deadline=None)
@given(name=st.sampled_from(NAMES),
       fractions=st.lists(st.floats(0.0, 1.0), min_size=18, max_size=18),
       margin=st.sampled_from([0.0, 0.05, 0.5, 3.0]))  # fmt: skip
def test_report_is_the_general_path_and_the_batch_bit_for_bit(name, fractions, margin):
    """At random configurations, with margins from 0 to 3r: the one-configuration report
    equals the general path's report field by field (every float the same bits), and its
    verdict, clearance and first pair are the batch's; numpy warns of nothing (no division
    by zero in the bounds)."""
    design, listed, general = engines(name)
    r = float(design.r)
    q = configuration(listed, fractions)
    report = listed.report(q, margin * r)
    assert report == general.report(q, margin * r)
    assert repr(report) == repr(general.report(q, margin * r))  # -0.0 and 0.0 told apart
    (worst,), (pair,) = listed.worst(np.array([q]), margin * r)
    if math.isfinite(worst):
        assert not report.ok
        assert report.min_clearance == worst == report.pairs[0].clearance
        assert (report.pairs[0].first, report.pairs[0].second) == (pair.first, pair.second)
    else:
        assert report.ok and report.pairs == ()
        assert report.min_clearance >= clear_limit(r, margin * r)


@pytest.mark.parametrize("name", NAMES)
def test_one_by_one_and_at_once_give_the_same_report(name, monkeypatch):
    """The pairs closer than the limit by their bounds are measured one by one in plain floats
    when few and at once with numpy when many: either way, the same report."""
    design, listed, _ = engines(name)
    rng = np.random.default_rng(4)
    Q = [configuration(listed, f) for f in rng.random((25, listed.ranges.shape[0]))]
    r = float(design.r)
    margins = (0.0, 0.5 * r, 1e3 * listed._extent())
    expected = [listed.report(q, m) for q in Q for m in margins]
    for count in (0, 10**9):
        monkeypatch.setattr(clearance_module, "_ONE_BY_ONE", count)
        found = [listed.report(q, m) for q in Q for m in margins]
        assert [repr(x) for x in found] == [repr(x) for x in expected], count
    assert any(not x.ok for x in expected) and any(x.ok for x in expected[::3])


@pytest.mark.parametrize("name", NAMES)
def test_body_motions_of_one_configuration_are_the_batch_bits(name):
    """JointScrews.body_motions_one gives the bits of body_motions for that configuration
    (revolute and prismatic joints, chains and trees)."""
    _, listed, _ = engines(name)
    screws = listed.screws
    rng = np.random.default_rng(5)
    lo, hi = listed.ranges[:, 0], listed.ranges[:, 1]
    Q = lo + (hi - lo) * rng.random((200, lo.size))
    for q in Q:
        assert np.array_equal(screws.body_motions_one(q), screws.body_motions(q[None])[0])


def test_states_are_checked_as_before():
    """The report's quick check of a list of plain numbers accepts what check_states accepts
    (ints, numpy floats, tuples) with the same values, and leaves everything else to
    check_states, which words the error."""
    design, listed, _ = engines("puma")
    q = [joint.state for joint in design.Joints]
    base = listed.report(q)
    assert listed.report(tuple(q)) == base
    assert listed.report([np.float64(v) for v in q]) == base
    assert listed.report(np.array(q)) == base
    whole = [0] * len(q)
    assert listed.report(whole) == listed.report([0.0] * len(q))
    lo, hi = listed.ranges[0]
    for bad, error in (
        (q[:-1], InvalidParameterError),
        ([hi + 1.0] + q[1:], InvalidParameterError),
        ([lo - 1.0] + q[1:], InvalidParameterError),
        ([math.nan] + q[1:], InvalidParameterError),
        ([True] + q[1:], InvalidTypeError),
        ([10**400] + q[1:], InvalidParameterError),
        ("states", InvalidTypeError),
    ):
        with pytest.raises(error) as raised:
            listed.report(bad)
        with pytest.raises(error) as checked:
            listed.check_states(bad)
        assert str(raised.value) == str(checked.value)
